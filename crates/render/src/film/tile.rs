//! Film tiles: a rectangle of pixels with its own accumulators, filled by one worker and
//! merged into the `Film` afterwards. Because every sample counts for one pixel only (see
//! `filter_sampler`), tiles are disjoint and a pixel's sums depend only on its own samples
//! in the order they were added — never on threads.

use std::sync::Arc;

use glam::{DVec3, UVec2, Vec2, Vec3A};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::filter_sampler::FilterSampler;
use super::filter_table::FilterTable;
use super::spectral_bins::SpectralBins;
use super::xyz::{xyz_of_sample, XyzWeights};
use super::AovSelection;

/// A half-open pixel rectangle [min, max).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileBounds {
    pub min: UVec2,
    pub max: UVec2,
}

impl TileBounds {
    pub fn size(&self) -> UVec2 {
        self.max - self.min
    }

    pub fn pixel_count(&self) -> usize {
        let s = self.size();
        s.x as usize * s.y as usize
    }

    pub fn contains(&self, pixel: UVec2) -> bool {
        pixel.cmpge(self.min).all() && pixel.cmplt(self.max).all()
    }

    /// Pixels in row-major order.
    pub fn pixels(&self) -> impl Iterator<Item = UVec2> {
        let (min, max) = (self.min, self.max);
        (min.y..max.y).flat_map(move |y| (min.x..max.x).map(move |x| UVec2::new(x, y)))
    }
}

/// What the first surface hit of a camera sample contributes to the AOVs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceAov {
    /// Distance from the camera ray's origin to the hit, metres.
    pub depth_m: f32,
    /// Shading normal (world space, unit).
    pub normal: Vec3A,
    /// Albedo as linear Rec.709 RGB.
    pub albedo_rgb: [f32; 3],
}

/// Colour sums of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PixelAccum {
    /// Σ wᵢ XYZᵢ.
    pub xyz_sum: DVec3,
    /// Σ wᵢ.
    pub weight_sum: f64,
    /// Number of samples added.
    pub sample_count: u32,
    /// Σ wᵢ of the pixel's own samples (equals `weight_sum` unless the film splats); the
    /// spectral bins are normalised by it.
    pub own_weight_sum: f64,
}

impl PixelAccum {
    /// Σ wᵢ XYZᵢ / Σ wᵢ (black when no weight landed).
    #[inline]
    pub fn mean_xyz(&self) -> DVec3 {
        if self.weight_sum != 0.0 {
            self.xyz_sum / self.weight_sum
        } else {
            DVec3::ZERO
        }
    }
}

/// AOV sums of one pixel (plain sample means, not filter-weighted, so negative filter
/// lobes cannot push a depth or normal outside its range).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct AovAccum {
    pub hit_count: u32,
    pub depth_sum: f64,
    pub normal_sum: DVec3,
    pub albedo_sum: DVec3,
    /// Σ XYZ of the illumination spectra (`FilmTile::add_illumination`).
    pub illumination_sum: DVec3,
    /// Σ Y and Σ Y² of the camera samples (`AovSelection::variance`; f64 sums of values of
    /// order 1 over at most millions of samples keep ~10 significant digits).
    pub y_sum: f64,
    pub y_sq_sum: f64,
}

impl PixelAccum {
    pub fn merge(&mut self, other: &PixelAccum) {
        self.xyz_sum += other.xyz_sum;
        self.weight_sum += other.weight_sum;
        self.sample_count += other.sample_count;
        self.own_weight_sum += other.own_weight_sum;
    }
}

impl AovAccum {
    pub fn merge(&mut self, other: &AovAccum) {
        self.hit_count += other.hit_count;
        self.depth_sum += other.depth_sum;
        self.normal_sum += other.normal_sum;
        self.albedo_sum += other.albedo_sum;
        self.illumination_sum += other.illumination_sum;
        self.y_sum += other.y_sum;
        self.y_sq_sum += other.y_sq_sum;
    }
}

/// Splatting (Mitsuba 3's `ImageBlock`): a tile's samples also reach pixels up to the
/// filter radius outside it, so it keeps Σ f·XYZ and Σ f over its bounds grown by the
/// radius (clipped to the film); `Film::merge_tile` adds them in a fixed order.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SplatBuffer {
    pub bounds: TileBounds,
    /// Per pixel [Σ f·X, Σ f·Y, Σ f·Z, Σ f]: four f64 in a row, so that one splat tap is
    /// two packed multiply-adds (SSE2) instead of four scalar ones and a separate weight.
    pub sums: Vec<[f64; 4]>,
    pub radius_px: f32,
    /// The widest kernels to run (`prism_cpu::active()` when the tile was made): where it
    /// allows AVX2, a tap is one 256-bit multiply and add (same bits as SSE2's two) and
    /// the filter profile's table reads are gathers.
    simd: prism_cpu::Simd,
}

impl SplatBuffer {
    pub fn new(tile: TileBounds, film_size: UVec2, radius_px: f32) -> Self {
        let pad = radius_px.ceil() as u32;
        let bounds = TileBounds {
            min: tile.min.saturating_sub(UVec2::splat(pad)),
            max: (tile.max + UVec2::splat(pad)).min(film_size),
        };
        Self {
            bounds,
            sums: vec![[0.0; 4]; bounds.pixel_count()],
            radius_px,
            simd: prism_cpu::active(),
        }
    }

    /// Adds `xyz` at film point `p` to every pixel whose centre is within the radius, with
    /// the weights of the tabulated profile (`FilterTable`).
    #[inline]
    pub fn splat(&mut self, p: Vec2, xyz: DVec3, table: &FilterTable) {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 (and AVX) only on a CPU that has it.
            return unsafe { self.splat_avx2(p, xyz, table) };
        }
        self.splat_with::<false, false>(p, xyz, table)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    unsafe fn splat_avx2(&mut self, p: Vec2, xyz: DVec3, table: &FilterTable) {
        self.splat_with::<true, true>(p, xyz, table)
    }

    /// `splat`'s body; `AVX`: the taps as 256-bit operations, `GATHER`: up to 4 × 4 taps'
    /// profile values in one `FilterTable::eval8_avx2` (both only inside `splat_avx2`;
    /// the AVX-only form the AVX CPUs without AVX2 ran is gone with `prism_cpu`'s ladder).
    #[inline(always)]
    fn splat_with<const AVX: bool, const GATHER: bool>(
        &mut self,
        p: Vec2,
        xyz: DVec3,
        table: &FilterTable,
    ) {
        let r = self.radius_px;
        // Pixel centres x + ½ within r of p: x from ⌈p − ½ − r⌉ to ⌊p − ½ + r⌋, clipped to
        // the buffer (integer floor/ceil: `f32::floor` is a library call on baseline x86-64).
        let (min, max) = (self.bounds.min.as_ivec2(), self.bounds.max.as_ivec2() - 1);
        let x0 = ceil_i32(p.x - (0.5 + r)).max(min.x);
        let x1 = floor_i32(p.x - 0.5 + r).min(max.x);
        let y0 = ceil_i32(p.y - (0.5 + r)).max(min.y);
        let y1 = floor_i32(p.y - 0.5 + r).min(max.y);
        if x0 > x1 || y0 > y1 {
            return;
        }
        // Separable filters (f = f₁(x) f₁(y)): one profile value per row and column.
        const MAX_TAPS: usize = 16;
        if (x1 - x0) as usize >= MAX_TAPS || (y1 - y0) as usize >= MAX_TAPS {
            return self.splat_wide(p, xyz, table, (x0, x1, y0, y1));
        }
        let (columns, rows) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
        // Profile values: a radius-2 filter's 4 + 4 in one gather call with AVX2
        // (`FilterTable::eval8_avx2`), else four at a time (`FilterTable::eval4`); the
        // lanes past `columns`/`rows` are computed and not used.
        let mut wx = [0.0f32; MAX_TAPS];
        let mut wy = [0.0f32; MAX_TAPS];
        if GATHER && columns <= 4 && rows <= 4 {
            let x: [f32; 8] = std::array::from_fn(|k| {
                let (first, p) = if k < 4 { (x0, p.x) } else { (y0, p.y) };
                (first + (k % 4) as i32) as f32 + 0.5 - p
            });
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `GATHER` is true only inside `splat_avx2`, on an AVX2 CPU.
            let w = unsafe { table.eval8_avx2(x) };
            #[cfg(not(target_arch = "x86_64"))]
            let w = x.map(|x| table.eval(x));
            wx[..4].copy_from_slice(&w[..4]);
            wy[..4].copy_from_slice(&w[4..]);
        } else {
            for (w, first, p, count) in [(&mut wx, x0, p.x, columns), (&mut wy, y0, p.y, rows)] {
                for (k, chunk) in w[..count.next_multiple_of(4)]
                    .chunks_exact_mut(4)
                    .enumerate()
                {
                    let c = first + 4 * k as i32;
                    let x = [c, c + 1, c + 2, c + 3].map(|c| c as f32 + 0.5 - p);
                    chunk.copy_from_slice(&table.eval4(x));
                }
            }
        }
        let width = self.bounds.size().x as usize;
        let first_column = (x0 - min.x) as usize;
        // The weight's own sum rides along as a fourth component of value 1: w · 1 = w
        // exactly, so the sums are those of separate colour and weight accumulators. A tap
        // of weight 0 adds ±0 to a sum that starts at +0 — no change — so no test for it.
        let value = [xyz.x, xyz.y, xyz.z, 1.0];
        for (y, &wy) in (y0..=y1).zip(&wy[..rows]) {
            let row = (y - min.y) as usize * width + first_column;
            if let Ok(sums) = <&mut [[f64; 4]; 4]>::try_from(&mut self.sums[row..row + columns]) {
                // Four columns (every sample of a radius-2 filter not exactly on a pixel
                // edge): unrolled, the same products in the same order.
                for (s, &wxk) in sums.iter_mut().zip(&wx[..4]) {
                    add_scaled::<AVX>(s, f64::from(wxk * wy), &value);
                }
                continue;
            }
            for (s, &wxk) in self.sums[row..row + columns].iter_mut().zip(&wx[..columns]) {
                add_scaled::<AVX>(s, f64::from(wxk * wy), &value);
            }
        }
    }

    /// `splat` for filters wider than 16 taps (not reached by the shipped filters' radii).
    fn splat_wide(
        &mut self,
        p: Vec2,
        xyz: DVec3,
        table: &FilterTable,
        (x0, x1, y0, y1): (i32, i32, i32, i32),
    ) {
        let width = self.bounds.size().x as usize;
        let min = self.bounds.min.as_ivec2();
        for y in y0..=y1 {
            let wy = table.eval(y as f32 + 0.5 - p.y);
            for x in x0..=x1 {
                let w = f64::from(table.eval(x as f32 + 0.5 - p.x) * wy);
                if w == 0.0 {
                    continue;
                }
                let i = (y - min.y) as usize * width + (x - min.x) as usize;
                add_scaled::<false>(&mut self.sums[i], w, &[xyz.x, xyz.y, xyz.z, 1.0]);
            }
        }
    }
}

/// sum += w · value, lane by lane (a multiply, then an add: the same bits as the scalar
/// loop). On x86-64 two packed SSE2 multiply-adds — SSE2 is part of the x86-64 baseline — or,
/// with `AVX` (called only from `SplatBuffer::splat_avx`), one 256-bit multiply and add;
/// left to itself LLVM interleaves two taps and spends more on shuffles than on the
/// arithmetic.
#[inline(always)]
fn add_scaled<const AVX: bool>(sum: &mut [f64; 4], w: f64, value: &[f64; 4]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_storeu_pd,
            _mm_add_pd, _mm_loadu_pd, _mm_mul_pd, _mm_set1_pd, _mm_storeu_pd,
        };
        let (s, v) = (sum.as_mut_ptr(), value.as_ptr());
        if AVX {
            // SAFETY: `AVX` is true only in code running on an AVX CPU (`splat_avx`); both
            // pointers address four f64 of the arrays borrowed here, `sum` uniquely.
            unsafe {
                let r = _mm256_add_pd(
                    _mm256_loadu_pd(s),
                    _mm256_mul_pd(_mm256_set1_pd(w), _mm256_loadu_pd(v)),
                );
                _mm256_storeu_pd(s, r);
            }
            return;
        }
        // SAFETY: SSE2 is always present on x86-64; both pointers address four f64 of the
        // arrays borrowed here (unaligned loads and stores), and `sum` is borrowed uniquely.
        unsafe {
            let w = _mm_set1_pd(w);
            let lo = _mm_add_pd(_mm_loadu_pd(s), _mm_mul_pd(w, _mm_loadu_pd(v)));
            let hi = _mm_add_pd(
                _mm_loadu_pd(s.add(2)),
                _mm_mul_pd(w, _mm_loadu_pd(v.add(2))),
            );
            _mm_storeu_pd(s, lo);
            _mm_storeu_pd(s.add(2), hi);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (s, v) in sum.iter_mut().zip(value) {
        *s += w * v;
    }
}

/// ⌊x⌋ for |x| ≤ 2³⁰ without a library call (truncation, then one step down for negative
/// non-integers); clamped to ±2³⁰ beyond.
#[inline(always)]
fn floor_i32(x: f32) -> i32 {
    // Clamped first (NaN becomes −2³⁰: `f32::max` returns the other operand), so that the
    // conversion needs none of the saturation `as` adds.
    let x = x.max(-(1 << 30) as f32).min((1 << 30) as f32);
    // SAFETY: x is finite and within ±2³⁰, inside i32.
    let i = unsafe { x.to_int_unchecked::<i32>() };
    i - i32::from((i as f32) > x)
}

/// ⌈x⌉ for |x| ≤ 2³⁰ without a library call.
#[inline(always)]
fn ceil_i32(x: f32) -> i32 {
    -floor_i32(-x)
}

/// The accumulators of one tile.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmTile {
    bounds: TileBounds,
    pub(crate) pixels: Vec<PixelAccum>,
    /// Empty when the film records no surface AOVs.
    pub(crate) aovs: Vec<AovAccum>,
    /// Σ w · L̂_b per pixel and bin (pixel-major, `bins.count()` per pixel); empty without
    /// spectral bins.
    pub(crate) spectral: Vec<f64>,
    spectral_bins: Option<SpectralBins>,
    /// Whether `add_illumination` records anything.
    record_illumination: bool,
    /// Whether samples add to the `variance.Y` sums.
    record_variance: bool,
    filter_sampler: Arc<FilterSampler>,
    /// `Some` when the film splats (then `sample_film_point` jitters within the pixel and
    /// colour goes here instead of into the own pixel's sums).
    pub(crate) splat: Option<SplatBuffer>,
}

impl FilmTile {
    pub(crate) fn new(
        bounds: TileBounds,
        aov_selection: AovSelection,
        spectral_bins: Option<SpectralBins>,
        filter_sampler: Arc<FilterSampler>,
    ) -> Self {
        let n = bounds.pixel_count();
        Self {
            bounds,
            pixels: vec![PixelAccum::default(); n],
            aovs: if aov_selection.any() {
                vec![AovAccum::default(); n]
            } else {
                Vec::new()
            },
            spectral: spectral_bins.map_or_else(Vec::new, |b| vec![0.0; n * b.count() as usize]),
            spectral_bins,
            record_illumination: aov_selection.illumination,
            record_variance: aov_selection.variance,
            filter_sampler,
            splat: None,
        }
    }

    /// The spectral bins this tile accumulates, if any.
    pub fn spectral_bins(&self) -> Option<SpectralBins> {
        self.spectral_bins
    }

    /// The film point (px) of a camera sample of `pixel` with filter variate `u`, and the
    /// weight to pass to `add_sample` (see `FilterSampler`).
    #[inline]
    pub fn sample_film_point(&self, pixel: UVec2, u: Vec2) -> (Vec2, f32) {
        if self.splat.is_some() {
            // Splatting: a uniform position in the pixel, weight 1 (the filter weights are
            // applied per receiving pixel).
            return (pixel.as_vec2() + u, 1.0);
        }
        self.filter_sampler.sample_film_point(pixel, u)
    }

    pub fn bounds(&self) -> TileBounds {
        self.bounds
    }

    #[inline]
    fn index(&self, pixel: UVec2) -> Option<usize> {
        self.bounds.contains(pixel).then(|| {
            let local = pixel - self.bounds.min;
            local.y as usize * self.bounds.size().x as usize + local.x as usize
        })
    }

    /// Adds one camera sample of `pixel`: its radiance at the sampled wavelengths, the
    /// filter weight f/p of its film offset (`FilterSampler`), and the first hit's AOVs
    /// (`None` for a miss). When the film has spectral bins the radiance also goes into them
    /// (`spectral_bins` module). Non-finite radiance is dropped (counted as a sample with
    /// zero radiance) so one bad path cannot poison a pixel. Returns false, adding nothing,
    /// when `pixel` is outside the tile.
    #[inline]
    pub fn add_sample(
        &mut self,
        pixel: UVec2,
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        filter_weight: f32,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let centre = pixel.as_vec2() + Vec2::splat(0.5);
        self.add_sample_at(pixel, centre, radiance, wavelengths, filter_weight, aov)
    }

    /// Adds the illumination AOV of one camera sample of `pixel`: `radiance` is the
    /// spectral radiance a neutral white Lambertian surface (albedo 1) would reflect
    /// towards the camera at the sample's first hit, at `wavelengths` (the integrator
    /// computes it). Its XYZ (same normalisation as the beauty) is summed; `finish` divides
    /// by the pixel's sample count (from `add_sample`), so misses count as zero, like the
    /// normal and albedo AOVs. Does nothing (returns true) when the film does not record
    /// `illumination`; returns false when `pixel` is outside the tile. Non-finite radiance
    /// is dropped.
    #[inline]
    pub fn add_illumination(
        &mut self,
        pixel: UVec2,
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
    ) -> bool {
        self.add_illumination_with(pixel, radiance, &XyzWeights::new(wavelengths))
    }

    /// `add_illumination` with the sample's `XyzWeights` (built once per camera sample for
    /// the beauty and this AOV).
    #[inline]
    pub fn add_illumination_with(
        &mut self,
        pixel: UVec2,
        radiance: SampledSpectrum,
        weights: &XyzWeights,
    ) -> bool {
        let Some(i) = self.index(pixel) else {
            debug_assert!(false, "pixel {pixel} outside tile {:?}", self.bounds);
            return false;
        };
        if let (true, Some(a)) = (self.record_illumination, self.aovs.get_mut(i)) {
            if !radiance.has_non_finite() {
                a.illumination_sum += weights.xyz(radiance);
            }
        }
        true
    }

    /// Adds one camera sample whose colour is already CIE 1931 XYZ in the output
    /// normalisation (`xyz::xyz_of_sample`): the diagnostic integrators, whose outputs are
    /// known exactly (a flat spectrum, or an RGB value) and need no wavelength sampling.
    /// A non-finite XYZ is dropped like non-finite radiance in `add_sample`.
    #[inline]
    pub fn add_sample_xyz(
        &mut self,
        pixel: UVec2,
        xyz: DVec3,
        filter_weight: f32,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let centre = pixel.as_vec2() + Vec2::splat(0.5);
        self.add_sample_xyz_at(pixel, centre, xyz, filter_weight, aov)
    }

    /// `add_sample` for a sample at `film_point` (px): a splatting film spreads it over the
    /// pixels within the filter radius; otherwise it is `add_sample`.
    #[inline]
    pub fn add_sample_at(
        &mut self,
        pixel: UVec2,
        film_point: Vec2,
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        filter_weight: f32,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let Some(i) = self.index(pixel) else {
            debug_assert!(false, "pixel {pixel} outside tile {:?}", self.bounds);
            return false;
        };
        let finite = !radiance.has_non_finite();
        let xyz = if finite {
            xyz_of_sample(radiance, wavelengths)
        } else {
            DVec3::ZERO
        };
        if let (Some(bins), true) = (self.spectral_bins, finite && filter_weight.is_finite()) {
            let n = bins.count() as usize;
            bins.accumulate(
                &mut self.spectral[i * n..(i + 1) * n],
                radiance,
                wavelengths,
                f64::from(filter_weight),
            );
        }
        self.add_sample_xyz_at(pixel, film_point, xyz, filter_weight, aov)
    }

    /// `add_sample_at` with the sample's `XyzWeights` for `wavelengths` (the path tracer
    /// builds them once per camera sample for the beauty and the illumination AOV).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn add_sample_with(
        &mut self,
        pixel: UVec2,
        film_point: Vec2,
        radiance: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        weights: &XyzWeights,
        filter_weight: f32,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let Some(i) = self.index(pixel) else {
            debug_assert!(false, "pixel {pixel} outside tile {:?}", self.bounds);
            return false;
        };
        let finite = !radiance.has_non_finite();
        let xyz = if finite {
            weights.xyz(radiance)
        } else {
            DVec3::ZERO
        };
        if let (Some(bins), true) = (self.spectral_bins, finite && filter_weight.is_finite()) {
            let n = bins.count() as usize;
            bins.accumulate(
                &mut self.spectral[i * n..(i + 1) * n],
                radiance,
                wavelengths,
                f64::from(filter_weight),
            );
        }
        self.add_sample_xyz_at(pixel, film_point, xyz, filter_weight, aov)
    }

    /// `add_sample_xyz` for a sample at `film_point` (px) (see `add_sample_at`).
    #[inline]
    pub fn add_sample_xyz_at(
        &mut self,
        pixel: UVec2,
        film_point: Vec2,
        xyz: DVec3,
        filter_weight: f32,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let Some(i) = self.index(pixel) else {
            debug_assert!(false, "pixel {pixel} outside tile {:?}", self.bounds);
            return false;
        };
        let xyz = if xyz.is_finite() { xyz } else { DVec3::ZERO };
        let w = if filter_weight.is_finite() {
            f64::from(filter_weight)
        } else {
            0.0
        };
        self.accumulate(i, film_point, xyz, w, aov)
    }

    /// Own-pixel counts and AOVs, and the colour: into the own pixel with weight `w`, or
    /// splatted from `film_point` (then `w` only counts for the spectral bins' normaliser).
    #[inline]
    fn accumulate(
        &mut self,
        i: usize,
        film_point: Vec2,
        xyz: DVec3,
        w: f64,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let p = &mut self.pixels[i];
        p.sample_count += 1;
        p.own_weight_sum += w;
        match &mut self.splat {
            Some(buffer) => buffer.splat(film_point, xyz, self.filter_sampler.table()),
            None => {
                p.xyz_sum += w * xyz;
                p.weight_sum += w;
            }
        }
        if self.record_variance {
            if let Some(a) = self.aovs.get_mut(i) {
                a.y_sum += xyz.y;
                a.y_sq_sum += xyz.y * xyz.y;
            }
        }
        if let (Some(a), Some(hit)) = (self.aovs.get_mut(i), aov) {
            a.hit_count += 1;
            a.depth_sum += f64::from(hit.depth_m);
            a.normal_sum += hit.normal.as_dvec3();
            a.albedo_sum += DVec3::from(hit.albedo_rgb.map(f64::from));
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Filter;

    /// Every ISA's splat gives the SSE2 taps' bits: the AVX taps (one 256-bit multiply and
    /// add per tap against two 128-bit ones, no fused multiply-add in either) and the
    /// AVX2 gathers (each ISA the machine runs, `prism_cpu::each_isa`).
    #[test]
    fn every_isa_splats_the_sse2_sums() {
        // Radius 2 px, σ = ½ px (α = 2 px⁻²): the Cornell box's filter, 4 × 4 taps.
        let filter = Filter::Gaussian(crate::film::filter::GaussianFilter::new(2.0, 2.0).unwrap());
        let table = FilterTable::new(&filter);
        let tile = TileBounds {
            min: UVec2::new(16, 16),
            max: UVec2::new(32, 32),
        };
        let mut sse2 = SplatBuffer::new(tile, UVec2::new(64, 64), 2.0);
        sse2.simd = prism_cpu::Simd::SCALAR;
        let mut wide: Vec<SplatBuffer> = prism_cpu::each_isa()
            .into_iter()
            .map(|simd| SplatBuffer {
                simd,
                ..sse2.clone()
            })
            .collect();
        for k in 0..500u32 {
            let f = k as f32;
            let p = Vec2::new(
                16.0 + (f * 0.618_034).fract() * 16.0,
                16.0 + (f * 0.414_214).fract() * 16.0,
            );
            let xyz = DVec3::new(0.1 + f64::from(k % 7), 1.0 / (1.0 + f64::from(k)), 0.25);
            sse2.splat(p, xyz, &table);
            for w in &mut wide {
                w.splat(p, xyz, &table);
            }
        }
        for w in &wide {
            assert_eq!(sse2.sums, w.sums, "{}", w.simd);
        }
        assert!(sse2.sums.iter().any(|s| s[3] > 0.0));
    }
}

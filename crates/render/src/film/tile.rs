//! Film tiles: a rectangle of pixels with its own accumulators, filled by one worker and
//! merged into the `Film` afterwards. Because every sample counts for one pixel only (see
//! `filter_sampler`), tiles are disjoint and a pixel's sums depend only on its own samples
//! in the order they were added — never on threads.

use std::sync::Arc;

use glam::{DVec3, UVec2, Vec2, Vec3A};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, WavelengthDensity};

use super::filter_sampler::FilterSampler;
use super::filter_table::FilterTable;
use super::fixed_sum::{split_limbs, FixedSum, FixedSum3, HIGH_LIMB_SCALE, MAGIC};
use super::spectral_bins::SpectralBins;
use super::xyz::xyz_of_sample;
use super::AovSelection;
use prism_spectrum::XyzWeights;

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

/// Colour sums of one pixel (exact: `fixed_sum`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PixelAccum {
    /// Σ wᵢ XYZᵢ.
    pub xyz_sum: FixedSum3,
    /// Σ wᵢ.
    pub weight_sum: FixedSum,
    /// Number of samples added.
    pub sample_count: u32,
    /// Σ wᵢ of the pixel's own samples (equals `weight_sum` unless the film splats); the
    /// spectral bins are normalised by it.
    pub own_weight_sum: FixedSum,
}

impl PixelAccum {
    /// Σ wᵢ XYZᵢ / Σ wᵢ (black when no weight landed).
    #[inline]
    pub fn mean_xyz(&self) -> DVec3 {
        let w = self.weight_sum.to_f64();
        if w != 0.0 {
            self.xyz_sum.to_dvec3() / w
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
    /// Σ depth, normal and albedo of the first hits.
    pub surface: SurfaceSums,
    /// Σ XYZ of the illumination spectra (`FilmTile::add_illumination`).
    pub illumination_sum: FixedSum3,
    /// Σ Y and Σ Y² of the camera samples (`AovSelection::variance`).
    pub y_sum: FixedSum,
    pub y_sq_sum: FixedSum,
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
        self.surface.merge(&other.surface);
        self.illumination_sum += other.illumination_sum;
        self.y_sum += other.y_sum;
        self.y_sq_sum += other.y_sq_sum;
    }
}

/// Σ depth (m), Σ normal (X, Y, Z) and Σ albedo (R, G, B) of a pixel's first hits, exact
/// (`fixed_sum`) as limbs like `SplatBuffer::sums`: lanes 0–6 the high limbs (units of
/// 2⁻²⁰), 8–14 the low ones (2⁻⁶⁰), lanes 7 and 15 unused. Limbs, so that the seven values
/// of a sample split and add as a few packed operations (every sample of every render
/// records them). `merge` carries the low limbs into the high ones, which keeps a film's
/// low limbs below 2⁴⁰; a high limb holds sums below 2⁴³ (m of depth, or samples).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct SurfaceSums(pub [i64; 16]);

impl SurfaceSums {
    /// Depth, normal and albedo sums as `FixedSum`s (lanes 0–6).
    #[inline]
    pub fn get(&self, lane: usize) -> FixedSum {
        FixedSum::from_limbs(self.0[lane], self.0[lane + 8])
    }

    pub fn set(&mut self, lane: usize, value: FixedSum) {
        (self.0[lane], self.0[lane + 8]) = value.to_limbs();
    }

    pub fn depth(&self) -> FixedSum {
        self.get(0)
    }

    pub fn normal(&self) -> FixedSum3 {
        FixedSum3([self.get(1), self.get(2), self.get(3)])
    }

    pub fn albedo(&self) -> FixedSum3 {
        FixedSum3([self.get(4), self.get(5), self.get(6)])
    }

    /// Adds one hit's depth, normal and albedo (lane 7 is zero).
    #[inline(always)]
    pub fn add(&mut self, values: [f64; 8]) {
        let most = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if most < (1u64 << 31) as f64 {
            // |v · 2²⁰| < 2⁵¹: the magic-number split, lane by lane (LLVM packs it).
            for (lane, v) in values.iter().enumerate() {
                let (high, low) = split_limbs(v * HIGH_LIMB_SCALE);
                self.0[lane] = self.0[lane].wrapping_add(high);
                self.0[lane + 8] = self.0[lane + 8].wrapping_add(low);
            }
        } else {
            for (lane, v) in values.iter().enumerate() {
                let (high, low) = FixedSum::from_f64(*v).to_limbs();
                self.0[lane] = self.0[lane].wrapping_add(high);
                self.0[lane + 8] = self.0[lane + 8].wrapping_add(low);
            }
        }
    }

    /// Adds `other` and carries the low limbs into the high ones.
    pub fn merge(&mut self, other: &SurfaceSums) {
        for lane in 0..8 {
            let sum = FixedSum::from_limbs(
                self.0[lane].wrapping_add(other.0[lane]),
                self.0[lane + 8].wrapping_add(other.0[lane + 8]),
            );
            (self.0[lane], self.0[lane + 8]) = sum.to_limbs();
        }
    }
}

/// Splatting (Mitsuba 3's `ImageBlock`): a tile's samples also reach pixels up to the
/// filter radius outside it, so it keeps Σ f·XYZ and Σ f over its bounds grown by the
/// radius (clipped to the film); `Film::merge_tile` adds them into the pixels' exact sums.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SplatBuffer {
    pub bounds: TileBounds,
    /// Per pixel Σ f·X, Σ f·Y, Σ f·Z, Σ f in fixed point (`fixed_sum`) as two limbs each:
    /// lanes 0–3 the high limbs (units of 2⁻²⁰), lanes 4–7 the low ones (units of 2⁻⁶⁰).
    /// Limbs, not i128, so that one tap is a few packed operations: the product f·value
    /// splits into limbs with two magic-number roundings (`fixed_sum::split_limbs`) and
    /// adds with 64-bit integer lanes (SSE2 or AVX2). A limb sum is exact while it stays
    /// in i64: the low limbs take 2²⁴ taps per pixel, the high ones Σ|f·value| < 2⁴³,
    /// within one tile pass.
    pub sums: Vec<[i64; 8]>,
    pub radius_px: f32,
    /// The widest kernels to run (`prism_cpu::active()` when the tile was made): where it
    /// allows AVX2, a tap is 256-bit operations and the filter profile's table reads are
    /// gathers.
    simd: prism_cpu::Simd,
    /// Per film pixel (row-major, `film_width` wide), the weight of the samples taken for
    /// it (`SamplePlan::splat_weights`: 1 / its relative sample density); `None`: 1.
    sample_weights: Option<(Arc<[f32]>, u32)>,
}

/// |f · value| below this (2³¹) takes the packed limb split (|f · value · 2²⁰| < 2⁵¹).
const FAST_SPLIT_LIMIT: f64 = 2_147_483_648.0;
/// |f · value| below this (2⁴³) fits the high limb at all.
const LIMB_LIMIT: f64 = 8_796_093_022_208.0;

impl SplatBuffer {
    pub fn new(tile: TileBounds, film_size: UVec2, radius_px: f32) -> Self {
        let pad = radius_px.ceil() as u32;
        let bounds = TileBounds {
            min: tile.min.saturating_sub(UVec2::splat(pad)),
            max: (tile.max + UVec2::splat(pad)).min(film_size),
        };
        Self {
            bounds,
            sums: vec![[0; 8]; bounds.pixel_count()],
            radius_px,
            simd: prism_cpu::active(),
            sample_weights: None,
        }
    }

    /// The weight of a sample taken for film pixel `pixel` (see `sample_weights`).
    #[inline]
    fn sample_weight(&self, pixel: UVec2) -> f64 {
        match &self.sample_weights {
            None => 1.0,
            Some((w, width)) => w
                .get(pixel.y as usize * *width as usize + pixel.x as usize)
                .map_or(1.0, |&w| f64::from(w)),
        }
    }

    /// Whether a sample of colour `xyz` and weight `weight` can be splatted with
    /// `table`'s weights (every tap within the limbs' range); `Film` drops it like a
    /// non-finite one otherwise.
    #[inline]
    pub fn admits(xyz: DVec3, weight: f64, table: &FilterTable) -> bool {
        (xyz.abs().max_element() * weight).max(weight) * table.max_weight() < LIMB_LIMIT
    }

    /// The sums of buffer pixel `i`: Σ f·X, Σ f·Y, Σ f·Z, Σ f.
    #[inline]
    pub fn pixel_sums(&self, i: usize) -> [FixedSum; 4] {
        let s = &self.sums[i];
        std::array::from_fn(|k| FixedSum::from_limbs(s[k], s[k + 4]))
    }

    /// Adds `xyz` at film point `p` to every pixel whose centre is within the radius, with
    /// the weights of the tabulated profile (`FilterTable`) times the sample's own
    /// `weight` (1 but for plans of varying density). `xyz` must be admitted (`admits`).
    #[inline]
    pub fn splat(&mut self, p: Vec2, xyz: DVec3, weight: f64, table: &FilterTable) {
        let value = [xyz.x * weight, xyz.y * weight, xyz.z * weight, weight];
        let bound = (xyz.abs().max_element() * weight).max(weight) * table.max_weight();
        if bound >= FAST_SPLIT_LIMIT {
            return self.splat_with::<false, false, true>(p, value, table);
        }
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 (and AVX) only on a CPU that has it.
            return unsafe { self.splat_avx2(p, value, table) };
        }
        self.splat_with::<false, false, false>(p, value, table)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    unsafe fn splat_avx2(&mut self, p: Vec2, value: [f64; 4], table: &FilterTable) {
        self.splat_with::<true, true, false>(p, value, table)
    }

    /// `splat`'s body; `AVX`: the taps as 256-bit operations, `GATHER`: up to 4 × 4 taps'
    /// profile values in one `FilterTable::eval8_avx2` (both only inside `splat_avx2`),
    /// `WIDE`: taps of |f · value| ≥ 2³¹, split through `FixedSum::from_f64` one by one.
    #[inline(always)]
    fn splat_with<const AVX: bool, const GATHER: bool, const WIDE: bool>(
        &mut self,
        p: Vec2,
        value: [f64; 4],
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
        if WIDE || (x1 - x0) as usize >= MAX_TAPS || (y1 - y0) as usize >= MAX_TAPS {
            return self.splat_wide(p, value, table, (x0, x1, y0, y1));
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
        // The weight's own sum rides along as a fourth component (the sample's weight, 1
        // but for plans of varying density: w · 1 = w exactly), so the sums are those of
        // separate colour and weight accumulators. A tap of weight 0 adds zero limbs — no
        // change — so no test for it.
        for (y, &wy) in (y0..=y1).zip(&wy[..rows]) {
            let row = (y - min.y) as usize * width + first_column;
            if let Ok(sums) = <&mut [[i64; 8]; 4]>::try_from(&mut self.sums[row..row + columns]) {
                // Four columns (every sample of a radius-2 filter not exactly on a pixel
                // edge): unrolled.
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

    /// `splat` for filters wider than 16 taps (not reached by the shipped filters' radii)
    /// and for taps too bright for the packed limb split: each product f · value through
    /// `FixedSum::from_f64` (the same rounding, so the same sums).
    fn splat_wide(
        &mut self,
        p: Vec2,
        value: [f64; 4],
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
                let s = &mut self.sums[(y - min.y) as usize * width + (x - min.x) as usize];
                for (k, v) in value.iter().enumerate() {
                    let (high, low) = FixedSum::from_f64(w * v).to_limbs();
                    s[k] = s[k].wrapping_add(high);
                    s[k + 4] = s[k + 4].wrapping_add(low);
                }
            }
        }
    }
}

/// sum += w · value in limbs (see `SplatBuffer::sums`), lane by lane: the product w · value
/// (scaled by 2²⁰, a power of two, so the same rounding as the unscaled product), split
/// with `fixed_sum::split_limbs`' two magic-number roundings, added as 64-bit integers. On
/// x86-64 packed SSE2 operations — SSE2 is part of the x86-64 baseline — or, with `AVX`
/// (only in code running on an AVX2 CPU), 256-bit ones; the caller keeps
/// |w · value| < 2³¹.
#[inline(always)]
fn add_scaled<const AVX: bool>(sum: &mut [i64; 8], w: f64, value: &[f64; 4]) {
    let w = w * HIGH_LIMB_SCALE;
    #[cfg(target_arch = "x86_64")]
    {
        use super::fixed_sum::LOW_LIMB_SCALE;
        use std::arch::x86_64::{
            _mm256_add_epi64, _mm256_add_pd, _mm256_castpd_si256, _mm256_loadu_pd,
            _mm256_loadu_si256, _mm256_mul_pd, _mm256_set1_epi64x, _mm256_set1_pd,
            _mm256_storeu_si256, _mm256_sub_epi64, _mm256_sub_pd, _mm_add_epi64, _mm_add_pd,
            _mm_castpd_si128, _mm_loadu_pd, _mm_loadu_si128, _mm_mul_pd, _mm_set1_epi64x,
            _mm_set1_pd, _mm_storeu_si128, _mm_sub_epi64, _mm_sub_pd,
        };
        let (s, v) = (sum.as_mut_ptr(), value.as_ptr());
        let magic_bits = MAGIC.to_bits() as i64;
        if AVX {
            // SAFETY: `AVX` is true only in code running on an AVX2 CPU (`splat_avx2`);
            // `v` addresses four f64 of `value`, `s` eight i64 of `sum` (borrowed uniquely),
            // all with unaligned loads and stores.
            unsafe {
                let magic = _mm256_set1_pd(MAGIC);
                let x = _mm256_mul_pd(_mm256_set1_pd(w), _mm256_loadu_pd(v));
                let t = _mm256_add_pd(x, magic);
                let high = _mm256_sub_epi64(_mm256_castpd_si256(t), _mm256_set1_epi64x(magic_bits));
                let rest = _mm256_mul_pd(
                    _mm256_sub_pd(x, _mm256_sub_pd(t, magic)),
                    _mm256_set1_pd(LOW_LIMB_SCALE),
                );
                let low = _mm256_sub_epi64(
                    _mm256_castpd_si256(_mm256_add_pd(rest, magic)),
                    _mm256_set1_epi64x(magic_bits),
                );
                let hs = s.cast::<std::arch::x86_64::__m256i>();
                _mm256_storeu_si256(hs, _mm256_add_epi64(_mm256_loadu_si256(hs), high));
                let ls = s.add(4).cast::<std::arch::x86_64::__m256i>();
                _mm256_storeu_si256(ls, _mm256_add_epi64(_mm256_loadu_si256(ls), low));
            }
            return;
        }
        // SAFETY: SSE2 is always present on x86-64; `v` addresses four f64 of `value`, `s`
        // eight i64 of `sum` (borrowed uniquely), with unaligned loads and stores.
        unsafe {
            let (magic, mb) = (_mm_set1_pd(MAGIC), _mm_set1_epi64x(magic_bits));
            let (wv, scale) = (_mm_set1_pd(w), _mm_set1_pd(LOW_LIMB_SCALE));
            for half in 0..2 {
                let x = _mm_mul_pd(wv, _mm_loadu_pd(v.add(2 * half)));
                let t = _mm_add_pd(x, magic);
                let high = _mm_sub_epi64(_mm_castpd_si128(t), mb);
                let rest = _mm_mul_pd(_mm_sub_pd(x, _mm_sub_pd(t, magic)), scale);
                let low = _mm_sub_epi64(_mm_castpd_si128(_mm_add_pd(rest, magic)), mb);
                let hs = s.add(2 * half).cast::<std::arch::x86_64::__m128i>();
                _mm_storeu_si128(hs, _mm_add_epi64(_mm_loadu_si128(hs), high));
                let ls = s.add(4 + 2 * half).cast::<std::arch::x86_64::__m128i>();
                _mm_storeu_si128(ls, _mm_add_epi64(_mm_loadu_si128(ls), low));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (k, v) in value.iter().enumerate() {
        let (high, low) = split_limbs(w * v);
        sum[k] = sum[k].wrapping_add(high);
        sum[k + 4] = sum[k + 4].wrapping_add(low);
    }
}

/// Whether a sample colour can be added: finite and representable in the fixed-point sums
/// (`fixed_sum`); the callers count others as black.
#[inline(always)]
fn admissible(xyz: DVec3) -> bool {
    FixedSum::is_representable(xyz.abs().max_element())
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
    pub(crate) spectral: Vec<FixedSum>,
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
    /// On a splatting film, weights each sample by `plan`'s `splat_weights` entry of the
    /// pixel it was taken for (1 / its relative sample density), so that where the density
    /// varies a pixel's sum Σ f·w·L / Σ f·w is not pulled towards its denser neighbours.
    /// Nothing changes for a film that does not splat (each sample stays in its pixel).
    pub fn set_sample_weights(&mut self, plan: &prism_bandwidth::SamplePlan) {
        if let Some(buffer) = &mut self.splat {
            buffer.sample_weights = plan
                .splat_weights()
                .map(|w| (Arc::clone(w), plan.resolution().x));
        }
    }

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
            spectral: spectral_bins
                .map_or_else(Vec::new, |b| vec![FixedSum::ZERO; n * b.count() as usize]),
            spectral_bins,
            record_illumination: aov_selection.illumination,
            record_variance: aov_selection.variance,
            filter_sampler,
            splat: None,
        }
    }

    /// The density the camera samples of this tile draw their wavelengths from
    /// (`film_wavelength_density`).
    pub fn wavelength_density(&self) -> WavelengthDensity {
        super::film_wavelength_density(self.spectral_bins.is_some())
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
            let xyz = weights.xyz(radiance);
            if admissible(xyz) {
                a.illumination_sum.add_f64(xyz);
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
        let xyz = if admissible(xyz) { xyz } else { DVec3::ZERO };
        let w = if filter_weight.is_finite() {
            f64::from(filter_weight)
        } else {
            0.0
        };
        self.accumulate(i, pixel, film_point, xyz, w, aov)
    }

    /// Own-pixel counts and AOVs, and the colour: into the own pixel with weight `w`, or
    /// splatted from `film_point` (then `w` only counts for the spectral bins' normaliser).
    #[inline]
    fn accumulate(
        &mut self,
        i: usize,
        pixel: UVec2,
        film_point: Vec2,
        xyz: DVec3,
        w: f64,
        aov: Option<&SurfaceAov>,
    ) -> bool {
        let p = &mut self.pixels[i];
        p.sample_count += 1;
        p.own_weight_sum += FixedSum::from_f64(w);
        match &mut self.splat {
            Some(buffer) => {
                let table = self.filter_sampler.table();
                let weight = buffer.sample_weight(pixel);
                // A colour whose taps would not fit the buffer's limbs counts as black, like
                // a non-finite one (≥ 2⁴³ / max f: far above any physical radiance).
                let xyz = if SplatBuffer::admits(xyz, weight, table) {
                    xyz
                } else {
                    DVec3::ZERO
                };
                buffer.splat(film_point, xyz, weight, table)
            }
            None => {
                p.xyz_sum.add_f64(w * xyz);
                p.weight_sum += FixedSum::from_f64(w);
            }
        }
        if self.record_variance {
            if let Some(a) = self.aovs.get_mut(i) {
                a.y_sum += FixedSum::from_f64(xyz.y);
                a.y_sq_sum += FixedSum::from_f64(xyz.y * xyz.y);
            }
        }
        if let (Some(a), Some(hit)) = (self.aovs.get_mut(i), aov) {
            a.hit_count += 1;
            let (n, c) = (hit.normal, hit.albedo_rgb);
            a.surface
                .add([hit.depth_m, n.x, n.y, n.z, c[0], c[1], c[2], 0.0].map(f64::from));
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Filter;

    /// 500 film points spread over a 16 × 16 tile at (16, 16), with colours of several
    /// magnitudes.
    fn splat_points() -> impl Iterator<Item = (Vec2, DVec3)> {
        (0..500u32).map(|k| {
            let f = k as f32;
            let p = Vec2::new(
                16.0 + (f * 0.618_034).fract() * 16.0,
                16.0 + (f * 0.414_214).fract() * 16.0,
            );
            let xyz = DVec3::new(0.1 + f64::from(k % 7), 1.0 / (1.0 + f64::from(k)), 0.25);
            (p, xyz)
        })
    }

    /// Every ISA's splat gives the SSE2 taps' limbs: the AVX2 taps (256-bit operations
    /// against two 128-bit ones, no fused multiply-add in either) and the AVX2 gathers (each
    /// ISA the machine runs, `prism_cpu::each_isa`); and the limbs hold the sums of each
    /// tap's exact conversion (`FixedSum::from_f64`, the path of bright taps).
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
        for (p, xyz) in splat_points() {
            sse2.splat(p, xyz, 1.0, &table);
            for w in &mut wide {
                w.splat(p, xyz, 1.0, &table);
            }
        }
        for w in &wide {
            assert_eq!(sse2.sums, w.sums, "{}", w.simd);
        }
        assert!(sse2.sums.iter().any(|s| s[3] > 0));
        // The limbs hold the same sums as the exact conversion of each tap.
        let mut wide_path = SplatBuffer {
            simd: prism_cpu::Simd::SCALAR,
            ..SplatBuffer::new(tile, UVec2::new(64, 64), 2.0)
        };
        for (p, xyz) in splat_points() {
            wide_path.splat_with::<false, false, true>(p, [xyz.x, xyz.y, xyz.z, 1.0], &table);
        }
        for i in 0..sse2.sums.len() {
            assert_eq!(sse2.pixel_sums(i), wide_path.pixel_sums(i), "pixel {i}");
        }
    }

    /// A plan whose right pixel takes 4× the left's samples: with the plan's weights, the
    /// splatted film equals the uniform plan's (the 4 copies of each sample weigh ¼ each);
    /// without them the dark left pixel is pulled towards its bright neighbour.
    #[test]
    fn sample_weights_undo_a_plans_varying_density() {
        use crate::film::{AovSelection, Film};
        use prism_bandwidth::SamplePlan;
        let resolution = UVec2::new(2, 1);
        let filter = Filter::Gaussian(crate::film::filter::GaussianFilter::new(1.5, 2.0).unwrap());
        let offsets: Vec<Vec2> = (0..16)
            .map(|k| Vec2::new((k % 4) as f32 + 0.5, (k / 4) as f32 + 0.5) / 4.0)
            .collect();
        let render = |copies_right: usize, plan: Option<&SamplePlan>| -> Vec<[f32; 3]> {
            let mut film = Film::new(resolution, filter, AovSelection::NONE)
                .unwrap()
                .with_splatting(true);
            let mut tile = film.new_tile(film.bounds());
            if let Some(plan) = plan {
                tile.set_sample_weights(plan);
            }
            for (x, copies, value) in [(0u32, 1, 0.0), (1, copies_right, 1.0)] {
                let pixel = UVec2::new(x, 0);
                for _ in 0..copies {
                    for &o in &offsets {
                        let point = pixel.as_vec2() + o;
                        tile.add_sample_xyz_at(pixel, point, DVec3::splat(value), 1.0, None);
                    }
                }
            }
            film.merge_tile(&tile);
            film.rgb()
        };
        let uniform = render(1, None);
        let plan = SamplePlan::from_counts(resolution, vec![16, 64], vec![1, 1])
            .unwrap()
            .with_relative_density(&[0.4, 1.6])
            .unwrap();
        let weighted = render(4, Some(&plan));
        let unweighted = render(4, None);
        assert!(
            uniform[0][1] > 0.01,
            "the filter reaches across: {uniform:?}"
        );
        for (u, w) in uniform.iter().zip(&weighted) {
            for c in 0..3 {
                assert!((u[c] - w[c]).abs() < 1e-5, "{uniform:?} vs {weighted:?}");
            }
        }
        assert!(
            unweighted[0][1] > 1.5 * uniform[0][1],
            "{unweighted:?} vs {uniform:?}"
        );
    }
}

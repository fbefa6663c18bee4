//! Film tiles: a rectangle of pixels with its own accumulators, filled by one worker and
//! merged into the `Film` afterwards. Because every sample counts for one pixel only (see
//! `filter_sampler`), tiles are disjoint and a pixel's sums depend only on its own samples
//! in the order they were added — never on threads.

use std::sync::Arc;

use glam::{DVec3, UVec2, Vec2, Vec3A};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::filter_sampler::FilterSampler;
use super::spectral_bins::SpectralBins;
use super::xyz::xyz_of_sample;
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
}

impl PixelAccum {
    pub fn merge(&mut self, other: &PixelAccum) {
        self.xyz_sum += other.xyz_sum;
        self.weight_sum += other.weight_sum;
        self.sample_count += other.sample_count;
    }
}

impl AovAccum {
    pub fn merge(&mut self, other: &AovAccum) {
        self.hit_count += other.hit_count;
        self.depth_sum += other.depth_sum;
        self.normal_sum += other.normal_sum;
        self.albedo_sum += other.albedo_sum;
        self.illumination_sum += other.illumination_sum;
    }
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
    filter_sampler: Arc<FilterSampler>,
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
            filter_sampler,
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
        self.add_sample_xyz(pixel, xyz, filter_weight, aov)
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
        let Some(i) = self.index(pixel) else {
            debug_assert!(false, "pixel {pixel} outside tile {:?}", self.bounds);
            return false;
        };
        if let (true, Some(a)) = (self.record_illumination, self.aovs.get_mut(i)) {
            if !radiance.has_non_finite() {
                a.illumination_sum += xyz_of_sample(radiance, wavelengths);
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
        let p = &mut self.pixels[i];
        p.xyz_sum += w * xyz;
        p.weight_sum += w;
        p.sample_count += 1;
        if let (Some(a), Some(hit)) = (self.aovs.get_mut(i), aov) {
            a.hit_count += 1;
            a.depth_sum += f64::from(hit.depth_m);
            a.normal_sum += hit.normal.as_dvec3();
            a.albedo_sum += DVec3::from(hit.albedo_rgb.map(f64::from));
        }
        true
    }
}

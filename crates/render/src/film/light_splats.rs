//! Light-side contributions: light-path vertices connected to the camera (light tracing,
//! BDPT's t = 1 strategies) land at a film point anywhere on the film, not at the pixel of
//! the camera sample being rendered (Veach 1997 §10.2; pbrt-v4 `RGBFilm::AddSplat`).
//!
//! Each work item collects its splats in a `LightSplats` list (XYZ converted, the filter's
//! separable weights evaluated: one row and one column of weights per splat, not every tap);
//! the driver merges the lists into the film's `LightPlane` one after another in work-item
//! order, so the image is bit-identical for any
//! thread count (floating-point sums in one fixed order) without locks or atomics on the
//! film.
//!
//! Normalisation. A pixel j measures I_j = ∫ f̂_j(x) L(x) dx over film points x in px,
//! with f̂_j the filter around the pixel centre c_j normalised to integrate to 1 over where
//! camera samples reach — the value the film's camera samples converge to. Filter
//! importance sampling puts a pixel's samples at c_j plus an offset drawn from the whole
//! filter, so f̂_j = f(x − c_j) / ∫f (and connections may land up to the filter radius
//! outside the film, `CameraFrame::film_margin_px`); a splatting film (Mitsuba 3's
//! `ImageBlock`) draws samples uniformly over the film and divides each pixel by its own
//! Σ f, so f̂_j = f(x − c_j) / ∫_film f(x − c_j) dx, renormalised at the borders. Both are
//! separable: one normaliser per column and per row. With the camera's importance W_e normalised
//! to 1 over a film area A (px², `Camera::importance_area_px2`), a light path's
//! connection C = β · f_s · G · W_e / pdf (W_e included) estimates I_j as
//! A · f̂(x − c_j) · C per light path; over N light paths the pixel is
//! Σ A · f̂ · C / N. Estimators splat A · C (`splat`'s `value`), the film keeps Σ f̂ · A · C
//! and divides by N (`LightPlane::paths`) when it finishes.

use std::sync::Arc;

use glam::{DVec3, UVec2, Vec2};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::filter_sampler::FilterSampler;
use super::fixed_sum::{FixedSum, FixedSum3};
use super::spectral_bins::SpectralBins;
use prism_spectrum::XyzWeights;

/// A splat: its XYZ and the rectangle of pixels its filter reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SplatRecord {
    xyz: [f32; 3],
    x0: u32,
    y0: u32,
    nx: u32,
    ny: u32,
    /// Index of its first weight in `LightSplats::weights`.
    first: u32,
}

/// One bin's share of a splat.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SpectralTap {
    pixel: u32,
    bin: u32,
    value: f32,
}

/// The splats of one work item, in the order they were made.
#[derive(Clone, Debug)]
pub struct LightSplats {
    resolution: UVec2,
    filter: Arc<FilterSampler>,
    /// 1 / ∫ f₁ per film column and per film row (see the module docs).
    inverse_norm_x: Arc<Vec<f32>>,
    inverse_norm_y: Arc<Vec<f32>>,
    bins: Option<SpectralBins>,
    /// One record per splat; its weights are `weights[first..first + nx + ny]`.
    records: Vec<SplatRecord>,
    /// The splats' column weights then row weights, normalised (f̂ = f_x · f_y).
    weights: Vec<f32>,
    spectral: Vec<SpectralTap>,
    /// Light paths traced by the work item.
    paths: u64,
}

impl LightSplats {
    pub(crate) fn new(
        resolution: UVec2,
        filter: Arc<FilterSampler>,
        splatting_film: bool,
        bins: Option<SpectralBins>,
    ) -> Self {
        let f = filter.filter();
        let full = filter_integral_1d(f, None);
        let r = f64::from(f.radius_px());
        let norms = |n: u32| -> Arc<Vec<f32>> {
            Arc::new(
                (0..n)
                    .map(|i| {
                        let c = i as f64 + 0.5;
                        // Only columns within the radius of an edge lose part of the filter.
                        let integral = if splatting_film && (c < r || c > f64::from(n) - r) {
                            filter_integral_1d(f, Some((c, f64::from(n))))
                        } else {
                            full
                        };
                        if integral > 0.0 {
                            (1.0 / integral) as f32
                        } else {
                            0.0
                        }
                    })
                    .collect(),
            )
        };
        Self {
            resolution,
            inverse_norm_x: norms(resolution.x),
            inverse_norm_y: norms(resolution.y),
            filter,
            bins,
            records: Vec::new(),
            weights: Vec::new(),
            spectral: Vec::new(),
            paths: 0,
        }
    }

    /// A list for estimators that do not splat (`Estimator::splats_light_paths` false): it
    /// skips the per-column and per-row normalisation `new` computes, and refuses every
    /// splat (`splat_with` returns false).
    pub(crate) fn unused(resolution: UVec2, filter: Arc<FilterSampler>) -> Self {
        Self {
            resolution,
            inverse_norm_x: Arc::new(Vec::new()),
            inverse_norm_y: Arc::new(Vec::new()),
            filter,
            bins: None,
            records: Vec::new(),
            weights: Vec::new(),
            spectral: Vec::new(),
            paths: 0,
        }
    }

    /// Counts `n` light paths traced (the normaliser N).
    #[inline]
    pub fn count_paths(&mut self, n: u64) {
        self.paths += n;
    }

    /// Splats `value` (radiance at `wavelengths`, already multiplied by the importance area
    /// A; see the module docs) at `film_point_px` into every pixel whose centre is within
    /// the filter radius. Non-finite values are dropped; returns false for them.
    pub fn splat(
        &mut self,
        film_point_px: Vec2,
        value: SampledSpectrum,
        wavelengths: &SampledWavelengths,
    ) -> bool {
        self.splat_with(
            film_point_px,
            value,
            wavelengths,
            &XyzWeights::new(wavelengths),
        )
    }

    /// `splat` with the `XyzWeights` of `wavelengths` (built once for all the splats of one
    /// light path, which share its wavelengths).
    pub fn splat_with(
        &mut self,
        film_point_px: Vec2,
        value: SampledSpectrum,
        wavelengths: &SampledWavelengths,
        weights: &XyzWeights,
    ) -> bool {
        if value.has_non_finite() || !film_point_px.is_finite() || self.inverse_norm_x.is_empty() {
            return false;
        }
        if value.is_black() {
            return true;
        }
        let xyz = weights.xyz(value);
        let table = self.filter.table();
        let r = self.filter.filter().radius_px();
        // Pixels whose centre (i + ½) lies within r of the point.
        let lo = (film_point_px - Vec2::splat(r + 0.5))
            .ceil()
            .max(Vec2::ZERO);
        let hi = (film_point_px + Vec2::splat(r - 0.5))
            .floor()
            .min(self.resolution.as_vec2() - Vec2::ONE);
        if lo.x > hi.x || lo.y > hi.y {
            return true;
        }
        let (x0, x1, y0, y1) = (lo.x as u32, hi.x as u32, lo.y as u32, hi.y as u32);
        // The separable weights: columns then rows (a radius-2 filter touches up to 5 × 5
        // pixels; the film multiplies them out when it merges).
        let first = self.weights.len() as u32;
        self.weights.extend((x0..=x1).map(|px| {
            table.eval(px as f32 + 0.5 - film_point_px.x) * self.inverse_norm_x[px as usize]
        }));
        self.weights.extend((y0..=y1).map(|py| {
            table.eval(py as f32 + 0.5 - film_point_px.y) * self.inverse_norm_y[py as usize]
        }));
        let (nx, ny) = (x1 - x0 + 1, y1 - y0 + 1);
        self.records.push(SplatRecord {
            xyz: [xyz.x as f32, xyz.y as f32, xyz.z as f32],
            x0,
            y0,
            nx,
            ny,
            first,
        });
        if let Some(bins) = self.bins {
            let w = &self.weights[first as usize..];
            for j in 0..ny {
                for i in 0..nx {
                    let wd = f64::from(w[i as usize] * w[(nx + j) as usize]);
                    if wd == 0.0 {
                        continue;
                    }
                    let pixel = (y0 + j) * self.resolution.x + x0 + i;
                    let spectral = &mut self.spectral;
                    bins.for_each_lane_share(value, wavelengths, |bin, share| {
                        spectral.push(SpectralTap {
                            pixel,
                            bin: bin as u32,
                            value: (share * wd) as f32,
                        });
                    });
                }
            }
        }
        true
    }

    /// Splats made so far.
    pub fn splat_count(&self) -> usize {
        self.records.len()
    }
}

/// The film's sums of light-side contributions.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct LightPlane {
    /// Σ f̂ · A · C per pixel, XYZ (exact: `fixed_sum`).
    pub xyz_sum: Vec<FixedSum3>,
    /// Per pixel and bin, pixel-major (empty without bins).
    pub spectral_sum: Vec<FixedSum>,
    /// Light paths traced (N).
    pub paths: u64,
}

impl LightPlane {
    pub fn new(pixels: usize, bins: Option<SpectralBins>) -> Self {
        Self {
            xyz_sum: vec![FixedSum3::default(); pixels],
            spectral_sum: bins.map_or(Vec::new(), |b| {
                vec![FixedSum::ZERO; pixels * b.count() as usize]
            }),
            paths: 0,
        }
    }

    /// Adds one work item's splats (the driver calls this in work-item order).
    pub fn merge(&mut self, splats: &LightSplats) {
        self.paths += splats.paths;
        let width = splats.resolution.x as usize;
        for r in &splats.records {
            let w = &splats.weights[r.first as usize..(r.first + r.nx + r.ny) as usize];
            let (columns, rows) = w.split_at(r.nx as usize);
            let xyz = DVec3::new(
                f64::from(r.xyz[0]),
                f64::from(r.xyz[1]),
                f64::from(r.xyz[2]),
            );
            for (j, &wy) in rows.iter().enumerate() {
                let row = (r.y0 as usize + j) * width + r.x0 as usize;
                let xyz_row = xyz * f64::from(wy);
                for (i, &wx) in columns.iter().enumerate() {
                    self.xyz_sum[row + i].add_f64(xyz_row * f64::from(wx));
                }
            }
        }
        if let Some(bins) = splats.bins {
            let n = bins.count() as usize;
            for t in &splats.spectral {
                self.spectral_sum[t.pixel as usize * n + t.bin as usize] +=
                    FixedSum::from_f64(f64::from(t.value));
            }
        }
    }

    /// The light-side XYZ of pixel `i` (Σ / N; zero before any light path).
    #[inline]
    pub fn xyz(&self, i: usize) -> DVec3 {
        if self.paths == 0 {
            DVec3::ZERO
        } else {
            self.xyz_sum[i].to_dvec3() / self.paths as f64
        }
    }

    /// The light-side mean spectral radiance of pixel `i` in bin `b` of `n`.
    #[inline]
    pub fn spectral(&self, i: usize, b: usize, n: usize) -> f64 {
        if self.paths == 0 || self.spectral_sum.is_empty() {
            0.0
        } else {
            self.spectral_sum[i * n + b].to_f64() / self.paths as f64
        }
    }
}

/// ∫ f₁(x − c) dx of `filter`'s 1-D profile over its support [c − r, c + r], or, with
/// `Some((c, n))`, over its part inside the film's [0, n], by the composite Simpson rule
/// (the profiles are smooth inside their support; 4096 intervals put the error far below
/// f32).
pub(crate) fn filter_integral_1d(filter: &super::Filter, within: Option<(f64, f64)>) -> f64 {
    let r = f64::from(filter.radius_px());
    let (lo, hi) = match within {
        None => (-r, r),
        Some((c, n)) => ((-c).max(-r), (n - c).min(r)),
    };
    if hi <= lo {
        return 0.0;
    }
    let n = 4096usize;
    let h = (hi - lo) / n as f64;
    let f = |k: usize| f64::from(filter.eval_1d((lo + k as f64 * h) as f32));
    let mut sum = f(0) + f(n);
    for k in 1..n {
        sum += if k % 2 == 1 { 4.0 } else { 2.0 } * f(k);
    }
    sum * h / 3.0
}

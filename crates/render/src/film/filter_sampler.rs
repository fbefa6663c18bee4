//! Filter importance sampling (pbrt-v4 §8.8.1 `FilterSampler`): film sample offsets are
//! drawn with density p ∝ |f| and each sample carries the weight f/p; the film divides the
//! weighted sum by the sum of weights (pbrt-v4 `RGBFilm::AddSample`). Each sample then
//! counts for exactly one pixel — no splatting across pixels — so tiles never share
//! pixels and their accumulation is deterministic and independent (the choice the design
//! asks for; pbrt-v4 makes it for the same reasons). For filters without negative lobes
//! the weights are nearly constant, so they add almost no variance.
//!
//! Our filters are separable, so |f| = |f₁(x)| |f₁(y)| is sampled one axis at a time from a
//! piecewise-constant table of |f₁| (pbrt-v4 tabulates the 2D |f| the same way, 32 cells
//! per pixel of radius; we use 64 per pixel in 1D).

use glam::Vec2;

use super::filter::Filter;
use super::filter_table::FilterTable;

/// Cells per pixel of filter radius in the table.
const CELLS_PER_PX: f32 = 64.0;

/// A tabulated sampler of |f₁| over [−r, r].
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSampler {
    filter: Filter,
    radius_px: f32,
    cell_width_px: f32,
    /// |f₁| at the cell centres, normalised to a density (∫ = 1).
    pdf: Vec<f32>,
    /// CDF at the cell boundaries, cdf[0] = 0, cdf[n] = 1.
    cdf: Vec<f32>,
    /// f₁ tabulated for splatting films.
    table: FilterTable,
}

/// A sampled film offset and its weight f/p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// Offset from the pixel centre in pixels.
    pub offset_px: Vec2,
    /// f(offset) / p(offset): ≈ 1 for filters without negative lobes.
    pub weight: f32,
}

impl FilterSampler {
    pub fn new(filter: Filter) -> Self {
        let radius_px = filter.radius_px();
        let n = ((2.0 * radius_px * CELLS_PER_PX).ceil() as usize).clamp(8, 4096);
        let cell_width_px = 2.0 * radius_px / n as f32;
        let values: Vec<f64> = (0..n)
            .map(|i| {
                let x = -radius_px + (i as f32 + 0.5) * cell_width_px;
                f64::from(filter.eval_1d(x).abs())
            })
            .collect();
        let total: f64 = values.iter().sum::<f64>() * f64::from(cell_width_px);
        let mut cdf = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0f32);
        for v in &values {
            acc += v * f64::from(cell_width_px) / total;
            cdf.push(acc as f32);
        }
        cdf[n] = 1.0;
        let pdf = values.iter().map(|v| (v / total) as f32).collect();
        Self {
            table: FilterTable::new(&filter),
            filter,
            radius_px,
            cell_width_px,
            pdf,
            cdf,
        }
    }

    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// The filter's 1D profile tabulated for splatting.
    pub(crate) fn table(&self) -> &FilterTable {
        &self.table
    }

    /// Samples one axis: (x, p(x)).
    #[inline]
    fn sample_1d(&self, u: f32) -> (f32, f32) {
        // The cell i with cdf[i] ≤ u < cdf[i+1], skipping zero-probability cells.
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .clamp(1, self.pdf.len())
            - 1;
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let t = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
        let x = -self.radius_px + (i as f32 + t.clamp(0.0, 1.0)) * self.cell_width_px;
        (x, self.pdf[i])
    }

    /// The film point (px) of a camera sample of `pixel`: its centre plus an offset drawn
    /// from the filter with `u`, and the sample's weight f/p.
    #[inline]
    pub fn sample_film_point(&self, pixel: glam::UVec2, u: Vec2) -> (Vec2, f32) {
        let s = self.sample(u);
        (pixel.as_vec2() + Vec2::splat(0.5) + s.offset_px, s.weight)
    }

    /// A film offset for `u` ∈ [0, 1)² and its weight f/p.
    #[inline]
    pub fn sample(&self, u: Vec2) -> FilterSample {
        let (x, px) = self.sample_1d(u.x);
        let (y, py) = self.sample_1d(u.y);
        let offset_px = Vec2::new(x, y);
        let p = px * py;
        let weight = if p > 0.0 {
            self.filter.eval(offset_px) / p
        } else {
            0.0
        };
        FilterSample { offset_px, weight }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::filter::{BoxFilter, GaussianFilter, MitchellFilter};

    #[test]
    fn box_filter_samples_uniformly_with_unit_weight() {
        let s = FilterSampler::new(Filter::Box(BoxFilter::default()));
        for i in 0..100 {
            let u = Vec2::new(i as f32 / 100.0, 1.0 - (i as f32 + 0.5) / 100.0);
            let fs = s.sample(u);
            assert!((fs.weight - 1.0).abs() < 1e-5, "{fs:?}");
            assert!((fs.offset_px.x - (u.x - 0.5)).abs() < 1e-5);
            assert!(fs.offset_px.abs().max_element() <= 0.5);
        }
    }

    #[test]
    fn weighted_estimate_of_the_filter_integral_is_one() {
        // E[f/p] = ∫ f = 1 under p. Separable, so check each axis: E[f₁/p₁] = ∫ f₁ = 1,
        // with finely stratified u (cells around the Mitchell filter's zero crossings have
        // small p and large f/p, so a coarse grid shows their variance).
        for filter in [
            Filter::Gaussian(GaussianFilter::default()),
            Filter::Mitchell(MitchellFilter::default()),
            Filter::BlackmanHarris(crate::film::filter::BlackmanHarrisFilter::default()),
        ] {
            let s = FilterSampler::new(filter);
            let n = 200_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let (x, p) = s.sample_1d((i as f32 + 0.5) / n as f32);
                assert!(x.abs() <= filter.radius_px());
                sum += f64::from(filter.eval_1d(x) / p);
            }
            let mean = sum / n as f64;
            assert!((mean - 1.0).abs() < 1e-3, "{filter:?}: {mean}");
            // And the 2D weight is the product of the axes' weights.
            let fs = s.sample(Vec2::new(0.3, 0.7));
            let (x, px) = s.sample_1d(0.3);
            let (y, py) = s.sample_1d(0.7);
            assert_eq!(fs.offset_px, Vec2::new(x, y));
            assert!((fs.weight - filter.eval_1d(x) * filter.eval_1d(y) / (px * py)).abs() < 1e-5);
        }
    }
}

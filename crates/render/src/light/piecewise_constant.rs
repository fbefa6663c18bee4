//! Piecewise-constant distributions on [0, 1) and [0, 1)² (pbrt-v4 §A.4.2
//! `PiecewiseConstant1D` and §A.5 `PiecewiseConstant2D`; Pharr, Jakob & Humphreys 2023):
//! sampling by inverting the running sum, the density of a point, and discrete selection
//! of a cell with the sample reused. The environment map samples texels with the 2-D form,
//! mesh emitters pick instances and triangles with the 1-D form.

use glam::Vec2;

/// f(x) = `func[⌊x n⌋]` on [0, 1), n = `func.len()`.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant1D {
    func: Vec<f32>,
    /// cdf[0] = 0, cdf[n] = 1: running sums of func / (n · integral).
    cdf: Vec<f32>,
    /// ∫₀¹ f(x) dx = Σ func / n.
    integral: f64,
    /// Per bucket k of n equal buckets of [0, 1), the cell that k/n falls in: the search
    /// starts there (the cutpoint method, Chen & Asau 1974), one or two steps from its cell
    /// instead of a binary search's log₂ n dependent loads.
    guide: Vec<u32>,
}

impl PiecewiseConstant1D {
    /// From cell values; negative or non-finite values count as 0. When every value is 0
    /// the cdf is uniform (sampling still works) and every density is 0.
    pub fn new(values: &[f32]) -> Self {
        let func: Vec<f32> = values
            .iter()
            .map(|&v| if v.is_finite() && v > 0.0 { v } else { 0.0 })
            .collect();
        let n = func.len().max(1);
        let mut running = Vec::with_capacity(func.len() + 1);
        let mut sum = 0.0f64;
        running.push(0.0f64);
        for &v in &func {
            sum += f64::from(v);
            running.push(sum);
        }
        let integral = sum / n as f64;
        let cdf: Vec<f32> = if sum > 0.0 {
            running.iter().map(|&c| (c / sum) as f32).collect()
        } else {
            (0..=func.len()).map(|i| i as f32 / n as f32).collect()
        };
        let buckets = func.len().max(1);
        let guide = (0..buckets)
            .map(|k| {
                let start = k as f32 / buckets as f32;
                cdf.partition_point(|&c| c <= start).saturating_sub(1) as u32
            })
            .collect();
        Self {
            func,
            cdf,
            integral,
            guide,
        }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// ∫₀¹ f(x) dx.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The value of cell `index`.
    #[inline]
    pub fn func(&self, index: usize) -> f32 {
        self.func.get(index).copied().unwrap_or(0.0)
    }

    /// Probability of picking cell `index` in `sample_discrete`.
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        if self.integral > 0.0 {
            (f64::from(self.func(index)) / (self.integral * self.func.len() as f64)) as f32
        } else {
            0.0
        }
    }

    /// The cell that `u` ∈ [0, 1) falls in: the last `i` with cdf[i] ≤ u, never an empty
    /// cell of a non-zero distribution.
    #[inline]
    fn find_cell(&self, u: f32) -> usize {
        let last = self.func.len().saturating_sub(1);
        // `as usize` saturates: negative u and NaN take bucket 0.
        let bucket = ((u * self.guide.len() as f32) as usize).min(self.guide.len() - 1);
        let mut i = self.guide[bucket] as usize;
        // Walk to the end of the prefix where cdf ≤ u (the cdf is non-decreasing): the same
        // cell as a binary search, whatever rounding put u in this bucket.
        while i > 0 && (self.cdf[i] > u || u.is_nan()) {
            i -= 1;
        }
        while i + 1 < self.cdf.len() && self.cdf[i + 1] <= u {
            i += 1;
        }
        let mut i = i.min(last);
        // Rounding can leave u on a zero-width cell at the end; step back to a live one.
        while i > 0 && self.cdf[i + 1] <= self.cdf[i] && self.integral > 0.0 {
            i -= 1;
        }
        i
    }

    /// (x, density f(x)/∫f, cell) for `u` ∈ [0, 1): continuous sampling by inversion.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        if self.func.is_empty() {
            return (u, 0.0, 0);
        }
        let i = self.find_cell(u);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let du = if c1 > c0 {
            ((u - c0) / (c1 - c0)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let n = self.func.len() as f32;
        // Keep x inside cell i (and below 1) despite rounding.
        let x = ((i as f32 + du) / n).min(((i + 1) as f32 / n).next_down());
        let pdf = if self.integral > 0.0 {
            (f64::from(self.func[i]) / self.integral) as f32
        } else {
            0.0
        };
        (x, pdf, i)
    }

    /// (cell, its probability, `u` rescaled to [0, 1) within the cell) for `u` ∈ [0, 1).
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        if self.func.is_empty() {
            return (0, 0.0, u);
        }
        let i = self.find_cell(u);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let remapped = if c1 > c0 {
            ((u - c0) / (c1 - c0)).clamp(0.0, 1.0f32.next_down())
        } else {
            0.5
        };
        (i, self.pmf(i), remapped)
    }

    /// Density f(x)/∫f at x ∈ [0, 1].
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        if self.func.is_empty() || self.integral <= 0.0 {
            return 0.0;
        }
        let n = self.func.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        (f64::from(self.func[i]) / self.integral) as f32
    }
}

/// f(u, v) = `values[⌊v n_v⌋ · n_u + ⌊u n_u⌋]` on [0, 1)²: a marginal distribution over the
/// rows v and one conditional distribution over u per row.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseConstant2D {
    conditional: Vec<PiecewiseConstant1D>,
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// `values` row-major, `nv` rows of `nu` (v = 0 is the first row).
    pub fn new(values: &[f32], nu: usize, nv: usize) -> Self {
        let conditional: Vec<PiecewiseConstant1D> = (0..nv)
            .map(|v| PiecewiseConstant1D::new(&values[v * nu..(v + 1) * nu]))
            .collect();
        let row_integrals: Vec<f32> = conditional.iter().map(|c| c.integral() as f32).collect();
        Self {
            marginal: PiecewiseConstant1D::new(&row_integrals),
            conditional,
        }
    }

    /// ∫∫ f du dv.
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// The value of cell (u, v) as given (negative and non-finite ones as 0).
    #[inline]
    pub fn value(&self, u: usize, v: usize) -> f32 {
        self.conditional.get(v).map_or(0.0, |c| c.func(u))
    }

    /// (u, v), their joint density and the cell (column, row).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32, [usize; 2]) {
        let (v, pdf_v, row) = self.marginal.sample(u.y);
        let Some(c) = self.conditional.get(row) else {
            return (Vec2::new(u.x, v), 0.0, [0, row]);
        };
        let (x, pdf_u, column) = c.sample(u.x);
        (Vec2::new(x, v), pdf_u * pdf_v, [column, row])
    }

    /// Joint density at (u, v) ∈ [0, 1]².
    #[inline]
    pub fn pdf(&self, uv: Vec2) -> f32 {
        let integral = self.marginal.integral();
        let nv = self.conditional.len();
        if nv == 0 || integral <= 0.0 {
            return 0.0;
        }
        let row = ((uv.y * nv as f32) as usize).min(nv - 1);
        let c = &self.conditional[row];
        let nu = c.len();
        if nu == 0 {
            return 0.0;
        }
        let column = ((uv.x * nu as f32) as usize).min(nu - 1);
        (f64::from(c.func(column)) / integral) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_d_sampling_inverts_the_cdf_and_reports_the_density() {
        let d = PiecewiseConstant1D::new(&[1.0, 0.0, 3.0, 0.0]);
        assert!((d.integral() - 1.0).abs() < 1e-12);
        // cdf: 0, .25, .25, 1, 1.
        let (x, pdf, i) = d.sample(0.1);
        assert_eq!(i, 0);
        assert!((x - 0.1).abs() < 1e-6 && (pdf - 1.0).abs() < 1e-6);
        let (x, pdf, i) = d.sample(0.625);
        assert_eq!(i, 2);
        assert!((x - 0.625).abs() < 1e-6 && (pdf - 3.0).abs() < 1e-6);
        // u at the very end never lands on the empty last cell.
        let (_, pdf, i) = d.sample(1.0f32.next_down());
        assert_eq!(i, 2);
        assert!(pdf > 0.0);
        assert_eq!(d.pdf(0.3), 0.0);
        assert!((d.pmf(0) - 0.25).abs() < 1e-6 && (d.pmf(2) - 0.75).abs() < 1e-6);
        let (i, p, r) = d.sample_discrete(0.625);
        assert_eq!(i, 2);
        assert!((p - 0.75).abs() < 1e-6 && (r - 0.5).abs() < 1e-6);
    }

    #[test]
    fn the_guided_search_finds_the_binary_searchs_cell() {
        // Peaked (one cell with most of the mass, as a sun in a sky), sparse (runs of empty
        // cells) and smooth distributions; u on every cdf value, just beside them, on a fine
        // grid and outside [0, 1).
        let peaked: Vec<f32> = (0..256)
            .map(|i| if i == 77 { 5e4 } else { 1.0 + (i % 5) as f32 })
            .collect();
        let sparse: Vec<f32> = (0..97)
            .map(|i| if i % 7 == 3 { i as f32 } else { 0.0 })
            .collect();
        let smooth: Vec<f32> = (0..300)
            .map(|i| (i as f32 * 0.05).sin().abs() + 1e-3)
            .collect();
        for values in [peaked, sparse, smooth, vec![2.0], vec![0.0, 1.0]] {
            let d = PiecewiseConstant1D::new(&values);
            let binary = |u: f32| {
                let last = d.func.len().saturating_sub(1);
                let mut i = d
                    .cdf
                    .partition_point(|&c| c <= u)
                    .saturating_sub(1)
                    .min(last);
                while i > 0 && d.cdf[i + 1] <= d.cdf[i] && d.integral > 0.0 {
                    i -= 1;
                }
                i
            };
            let mut us: Vec<f32> = (0..4096).map(|k| k as f32 / 4096.0).collect();
            for &c in &d.cdf {
                us.extend([c, c.next_down(), c.next_up()]);
            }
            us.extend([-0.5, 1.0, 1.5, 1.0f32.next_down(), f32::NAN]);
            for u in us {
                assert_eq!(d.find_cell(u), binary(u), "u = {u}");
            }
        }
    }

    #[test]
    fn all_zero_distributions_sample_uniformly_with_zero_density() {
        let d = PiecewiseConstant1D::new(&[0.0, 0.0]);
        let (x, pdf, _) = d.sample(0.7);
        assert!((x - 0.7).abs() < 1e-6 && pdf == 0.0);
        let d2 = PiecewiseConstant2D::new(&[0.0; 6], 3, 2);
        assert_eq!(d2.sample(Vec2::new(0.3, 0.3)).1, 0.0);
        assert_eq!(d2.pdf(Vec2::new(0.3, 0.3)), 0.0);
    }

    #[test]
    fn two_d_density_matches_sampling_frequencies() {
        // 3×2 cells; each cell's sampling frequency equals pdf × cell area.
        let values = [1.0, 2.0, 0.0, 4.0, 0.5, 2.5];
        let d = PiecewiseConstant2D::new(&values, 3, 2);
        let total: f32 = values.iter().sum();
        let n = 300;
        let mut counts = [0usize; 6];
        for i in 0..n {
            for j in 0..n {
                let u = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                let (uv, pdf, [c, r]) = d.sample(u);
                assert!((pdf - d.pdf(uv)).abs() < 1e-5 * pdf.max(1.0));
                assert_eq!((c, r), ((uv.x * 3.0) as usize, (uv.y * 2.0) as usize));
                counts[r * 3 + c] += 1;
            }
        }
        for (k, &c) in counts.iter().enumerate() {
            let expected = values[k] / total;
            let got = c as f32 / (n * n) as f32;
            assert!(
                (got - expected).abs() < 2e-3,
                "cell {k}: {got} vs {expected}"
            );
        }
    }
}

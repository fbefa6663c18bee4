//! Hierarchical shading and bilateral up-sampling (Bagher et al. 2013 §3.2, Fig. 8).
//!
//! Eq. 11's level ℓ_p says that the image around pixel p varies slowly enough to be
//! shaded on a lattice of spacing 2^ℓ_p and interpolated in between. Here a pixel takes its
//! value from the (up to) four corners of its lattice cell, which are shaded; the corners'
//! camera samples grow by the share of the pixels they stand for, so the budget is
//! unchanged and each shaded sample serves several pixels. Level-0 pixels (and pixels at
//! the image's last row or column that a cell cannot reach) are shaded.
//!
//! The lattice of a pixel is the coarsest level ℓ ≤ ℓ_p − 1 (and ≤ `max_level`) whose cell
//! holds no pixel of a lower level: the paper's min-filtered pyramid (§3.1), so that a
//! pixel beside a shadow edge is not interpolated from a corner across it, and one level
//! finer than eq. 11, because bilinear interpolation at Nyquist's two samples per cycle
//! loses most of a sinusoid (linear interpolation's error is about (π f h)²/2 of its
//! amplitude at f cycles per sample spacing h).
//!
//! The paper weights a parent by w_i = g_z(z − z_i)·g_a(p − p_i)·α_i (α_i bilinear, g_a an
//! anisotropic Gaussian stretched along the screen-projected normal by 1/cos θ_x). Here
//! w_i = g_z·α_i, and a pixel with any parent of another material, facing elsewhere
//! (normals > 60° apart) or off its plane (g_z < 0.1) is shaded itself instead of being
//! blended from the rest. g_z compares the parent's hit with p's tangent plane instead of
//! depths (a floor at grazing view changes depth fast but stays in its plane). g_a is left
//! out: eq. 6's footprint already holds the 1/cos θ_x stretch, and with normalised weights
//! g_a turns the interpolation at grazing angles into nearest-row steps (measured in
//! docs/bandwidth.md). The result is biased where the prediction misses variation: it is
//! a separate plan (`predicted-hier`), measured against `predicted` in docs/bandwidth.md,
//! and `max_level` bounds how far one sample reaches.

use glam::{UVec2, Vec3A};

use crate::allocation::{counts_for_density, Allocated};
use crate::error::{check_lengths, pixel_count, BandwidthError};
use crate::sample_plan::{SamplePlan, DEFAULT_LIGHT_SAMPLES};
use crate::variance_pooling::PixelClass;

/// The default coarsest lattice: one shaded pixel per 8×8 at most.
pub const DEFAULT_MAX_LEVEL: u32 = 3;

/// Two centre hits whose normals are further apart than 60° lie across a crease: the
/// up-sampling does not blend across it, and `geometric_edges` marks it.
pub(crate) const CREASE_MIN_COS: f32 = 0.5;

/// The centre hit of a pixel, as the up-sampling compares it with its parents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub position_m: Vec3A,
    /// Unit shading normal.
    pub normal: Vec3A,
}

impl SurfacePoint {
    /// The sine of the angle between this point's tangent plane and the chord to `other`
    /// (0 for coincident points): how far `other` lies off the plane, whatever the depths.
    pub fn off_plane_sine(&self, other: &SurfacePoint) -> f32 {
        let chord = other.position_m - self.position_m;
        let length = chord.length();
        if length > 0.0 {
            self.normal.dot(chord).abs() / length
        } else {
            0.0
        }
    }
}

/// What the hierarchy is built from, per pixel (row-major).
#[derive(Clone, Copy, Debug)]
pub struct HierarchyInputs<'a> {
    /// Eq. 11's level (`BandwidthBuffer`'s finest level).
    pub shading_level: &'a [i32],
    pub class: &'a [PixelClass],
    /// The centre hit (`None` where the centre ray escapes or nothing was predicted).
    pub surface: &'a [Option<SurfacePoint>],
    /// Levels above this are lowered to it (≥ 1; 0 shades every pixel).
    pub max_level: u32,
}

/// One interpolated pixel: its parents (shaded pixels) with normalised weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpsampledPixel {
    pub index: u32,
    parents: [(u32, f32); 4],
    parent_count: u8,
}

impl UpsampledPixel {
    /// (pixel index, weight) of each parent; the weights sum to 1.
    pub fn parents(&self) -> &[(u32, f32)] {
        &self.parents[..usize::from(self.parent_count)]
    }
}

/// A value the up-sampling can blend: Σ wᵢ vᵢ.
pub trait Blend: Copy {
    fn weighted_sum(parents: &[(Self, f32)]) -> Self;
}

impl Blend for f32 {
    fn weighted_sum(parents: &[(Self, f32)]) -> Self {
        parents.iter().map(|(v, w)| v * w).sum()
    }
}

impl<const N: usize> Blend for [f32; N] {
    fn weighted_sum(parents: &[(Self, f32)]) -> Self {
        let mut out = [0.0; N];
        for (v, w) in parents {
            for (o, x) in out.iter_mut().zip(v) {
                *o += x * w;
            }
        }
        out
    }
}

/// Which pixels are shaded and how the others are up-sampled from them.
#[derive(Clone, Debug, PartialEq)]
pub struct Upsampling {
    resolution: UVec2,
    shaded: Vec<bool>,
    upsampled: Vec<UpsampledPixel>,
}

/// Per pixel the coarsest level ℓ ≤ min(its own − 1, `max_level`) whose lattice cell around
/// it holds no pixel of a lower level (0: shaded; see the module documentation).
fn effective_levels(resolution: UVec2, inputs: HierarchyInputs<'_>) -> Vec<u32> {
    let (w, h) = (resolution.x, resolution.y);
    let own: Vec<u32> = inputs
        .shading_level
        .iter()
        .map(|&l| (l.saturating_sub(1)).clamp(0, inputs.max_level.min(30) as i32) as u32)
        .collect();
    let mut effective = vec![0u32; own.len()];
    for level in 1..=inputs.max_level.min(30) {
        let spacing = 1u32 << level;
        // Cells [c·s, (c + 1)·s] on each axis, corners included (they border two cells).
        let cells_x = (w - 1).div_ceil(spacing).max(1);
        let cells_y = (h - 1).div_ceil(spacing).max(1);
        let mut cell_min = vec![u32::MAX; (cells_x * cells_y) as usize];
        let cells_of = |c: u32, cells: u32| {
            let main = (c / spacing).min(cells - 1);
            let also =
                (c.is_multiple_of(spacing) && c > 0 && main == c / spacing).then(|| main - 1);
            [Some(main), also]
        };
        for y in 0..h {
            for x in 0..w {
                let l = own[(y * w + x) as usize];
                for cy in cells_of(y, cells_y).into_iter().flatten() {
                    for cx in cells_of(x, cells_x).into_iter().flatten() {
                        let m = &mut cell_min[(cy * cells_x + cx) as usize];
                        *m = (*m).min(l);
                    }
                }
            }
        }
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let cell =
                    (y / spacing).min(cells_y - 1) * cells_x + (x / spacing).min(cells_x - 1);
                if own[i] >= level && cell_min[cell as usize] >= level {
                    effective[i] = level;
                }
            }
        }
    }
    effective
}

/// The lattice-`spacing` cell corners along one axis for coordinate `c` in [0, len):
/// (low, high, t) with c = low + t·(high − low); high == low when `c` is on the lattice.
fn cell_axis(c: u32, spacing: u32, len: u32) -> (u32, u32, f32) {
    let low = c / spacing * spacing;
    if low == c {
        return (c, c, 0.0);
    }
    let high = (low + spacing).min(len - 1);
    (low, high, (c - low) as f32 / (high - low) as f32)
}

/// g_z: how far the parent's hit lies off p's tangent plane, as the sine of the angle
/// between the plane and the chord to it (σ = 0.25).
fn plane_weight(p: &SurfacePoint, parent: &SurfacePoint) -> f32 {
    (-(p.off_plane_sine(parent) / 0.25).powi(2)).exp()
}

impl Upsampling {
    /// The shaded lattice and the interpolation weights for `inputs`.
    pub fn plan(resolution: UVec2, inputs: HierarchyInputs<'_>) -> Result<Self, BandwidthError> {
        let n = pixel_count("hierarchical shading", resolution)?;
        check_lengths(
            resolution,
            n,
            &[
                ("hierarchical shading level", inputs.shading_level.len()),
                ("hierarchical shading class", inputs.class.len()),
                ("hierarchical shading surface", inputs.surface.len()),
            ],
        )?;
        let (w, h) = (resolution.x, resolution.y);
        let index = |x: u32, y: u32| (y * w + x) as usize;
        let levels = effective_levels(resolution, inputs);
        let level = |i: usize| levels[i];
        // The corners every interpolated pixel needs are shaded.
        let mut shaded = vec![false; n];
        for y in 0..h {
            for x in 0..w {
                let i = index(x, y);
                let spacing = 1u32 << level(i).min(30);
                let (x0, x1, _) = cell_axis(x, spacing, w);
                let (y0, y1, _) = cell_axis(y, spacing, h);
                for (cx, cy) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                    shaded[index(cx, cy)] = true;
                }
            }
        }
        // Each pixel not on its lattice: bilateral weights over its corners, or shaded when
        // a corner is another surface.
        let mut upsampled = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let i = index(x, y);
                if shaded[i] {
                    continue;
                }
                let spacing = 1u32 << level(i).min(30);
                let (x0, x1, tx) = cell_axis(x, spacing, w);
                let (y0, y1, ty) = cell_axis(y, spacing, h);
                let mut parents = [(0u32, 0.0f32); 4];
                let mut count = 0u8;
                let mut total = 0.0f32;
                let mut compatible = true;
                for (cx, cy, alpha) in [
                    (x0, y0, (1.0 - tx) * (1.0 - ty)),
                    (x1, y0, tx * (1.0 - ty)),
                    (x0, y1, (1.0 - tx) * ty),
                    (x1, y1, tx * ty),
                ] {
                    if alpha <= 0.0 {
                        continue;
                    }
                    let j = index(cx, cy);
                    let g_z = match (inputs.class[i], inputs.class[j]) {
                        (PixelClass::Material(a), PixelClass::Material(b)) if a == b => {
                            match (&inputs.surface[i], &inputs.surface[j]) {
                                (Some(p), Some(q)) if p.normal.dot(q.normal) >= CREASE_MIN_COS => {
                                    plane_weight(p, q)
                                }
                                _ => 0.0,
                            }
                        }
                        (PixelClass::Background, PixelClass::Background) => 1.0,
                        (PixelClass::Material(_), _)
                        | (PixelClass::Background, _)
                        | (PixelClass::Unpredicted, _) => 0.0,
                    };
                    if g_z < 0.1 {
                        compatible = false;
                        break;
                    }
                    let weight = g_z * alpha;
                    parents[usize::from(count)] = (j as u32, weight);
                    count += 1;
                    total += weight;
                }
                if !compatible || total <= 0.0 {
                    shaded[i] = true;
                    continue;
                }
                for p in &mut parents[..usize::from(count)] {
                    p.1 /= total;
                }
                upsampled.push(UpsampledPixel {
                    index: i as u32,
                    parents,
                    parent_count: count,
                });
            }
        }
        // Parents are corners, all shaded by the first loop; a pixel the second loop shades
        // is nobody's corner, so no parent is ever itself up-sampled.
        Ok(Self {
            resolution,
            shaded,
            upsampled,
        })
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// True where the pixel gets camera samples.
    pub fn is_shaded(&self, index: usize) -> bool {
        self.shaded[index]
    }

    pub fn shaded_count(&self) -> usize {
        self.shaded.iter().filter(|&&s| s).count()
    }

    /// The interpolated pixels, in row-major order.
    pub fn upsampled(&self) -> &[UpsampledPixel] {
        &self.upsampled
    }

    /// Fills the interpolated pixels of `plane` (row-major, one value per pixel) from their
    /// parents; shaded pixels are left as they are.
    pub fn apply<T: Blend>(&self, plane: &mut [T]) -> Result<(), BandwidthError> {
        check_lengths(
            self.resolution,
            self.shaded.len(),
            &[("up-sampled plane", plane.len())],
        )?;
        let mut parents = [(plane[0], 0.0); 4];
        for u in &self.upsampled {
            for (slot, &(j, w)) in parents.iter_mut().zip(u.parents()) {
                *slot = (plane[j as usize], w);
            }
            plane[u.index as usize] = T::weighted_sum(&parents[..u.parents().len()]);
        }
        Ok(())
    }

    /// `allocated` with each interpolated pixel's sample density moved to its parents in
    /// proportion to its weights (the total is kept: `mean_spp` stays the mean), counts
    /// rounded as [`Allocated::cumulative_counts`] rounds them.
    pub fn concentrate(
        &self,
        allocated: &Allocated,
        mean_spp: f64,
        seed: u64,
    ) -> Result<Allocated, BandwidthError> {
        check_lengths(
            self.resolution,
            self.shaded.len(),
            &[("sample densities", allocated.relative_density.len())],
        )?;
        let mut density: Vec<f64> = allocated
            .relative_density
            .iter()
            .map(|&d| f64::from(d))
            .collect();
        for u in &self.upsampled {
            let d = std::mem::take(&mut density[u.index as usize]);
            for &(j, w) in u.parents() {
                density[j as usize] += d * f64::from(w);
            }
        }
        let relative_density: Vec<f32> = density.iter().map(|&d| d as f32).collect();
        let plan = SamplePlan::from_counts(
            self.resolution,
            counts_for_density(&relative_density, mean_spp, seed),
            vec![DEFAULT_LIGHT_SAMPLES; self.shaded.len()],
        )?
        .with_relative_density(&relative_density)?;
        Ok(Allocated {
            plan,
            relative_density,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane_point(x: u32, y: u32) -> Option<SurfacePoint> {
        Some(SurfacePoint {
            position_m: Vec3A::new(x as f32 * 0.01, y as f32 * 0.01, 0.0),
            normal: Vec3A::Z,
        })
    }

    fn inputs_for(
        resolution: UVec2,
        level: i32,
        class: impl Fn(u32, u32) -> PixelClass,
    ) -> (Vec<i32>, Vec<PixelClass>, Vec<Option<SurfacePoint>>) {
        let mut levels = Vec::new();
        let mut classes = Vec::new();
        let mut surfaces = Vec::new();
        for y in 0..resolution.y {
            for x in 0..resolution.x {
                levels.push(level);
                let c = class(x, y);
                classes.push(c);
                surfaces.push(match c {
                    PixelClass::Material(_) => plane_point(x, y),
                    PixelClass::Background | PixelClass::Unpredicted => None,
                });
            }
        }
        (levels, classes, surfaces)
    }

    fn plan(
        r: UVec2,
        levels: &[i32],
        class: &[PixelClass],
        surface: &[Option<SurfacePoint>],
        max_level: u32,
    ) -> Upsampling {
        Upsampling::plan(
            r,
            HierarchyInputs {
                shading_level: levels,
                class,
                surface,
                max_level,
            },
        )
        .unwrap()
    }

    #[test]
    fn levels_up_to_one_shade_every_pixel_and_interpolate_none() {
        let r = UVec2::new(7, 5);
        let (l, c, s) = inputs_for(r, 1, |_, _| PixelClass::Material(0));
        let u = plan(r, &l, &c, &s, 3);
        assert_eq!(u.shaded_count(), 35);
        assert!(u.upsampled().is_empty());
    }

    #[test]
    fn a_smooth_plane_at_level_three_shades_one_pixel_in_sixteen_and_reproduces_a_linear_ramp() {
        // Eq. 11's level 3 → lattice level 2: 0, 4, …, 16 on both axes = 25 shaded pixels.
        let r = UVec2::new(17, 17);
        let (l, c, s) = inputs_for(r, 3, |_, _| PixelClass::Material(0));
        let u = plan(r, &l, &c, &s, 3);
        assert_eq!(u.shaded_count(), 25);
        assert_eq!(u.upsampled().len(), 17 * 17 - 25);
        for p in u.upsampled() {
            let total: f32 = p.parents().iter().map(|(_, w)| w).sum();
            assert!((total - 1.0).abs() < 1e-5);
            for &(j, _) in p.parents() {
                assert!(u.is_shaded(j as usize));
            }
        }
        // A ramp along x is reproduced exactly: facing the camera the weights are bilinear.
        let ramp: Vec<f32> = (0..17 * 17).map(|i| (i % 17) as f32).collect();
        let mut plane: Vec<f32> = ramp
            .iter()
            .enumerate()
            .map(|(i, &v)| if u.is_shaded(i) { v } else { -1.0 })
            .collect();
        u.apply(&mut plane).unwrap();
        for (got, want) in plane.iter().zip(&ramp) {
            assert!((got - want).abs() < 1e-4, "{got} vs {want}");
        }
    }

    #[test]
    fn max_level_bounds_the_lattice_spacing() {
        let r = UVec2::new(33, 1);
        let (l, c, s) = inputs_for(r, 7, |_, _| PixelClass::Material(0));
        let u = plan(r, &l, &c, &s, 2);
        // Lattice 0, 4, …, 32.
        let shaded: Vec<usize> = (0..33).filter(|&i| u.is_shaded(i)).collect();
        assert_eq!(shaded, (0..=32).step_by(4).collect::<Vec<_>>());
    }

    #[test]
    fn pixels_next_to_another_material_are_shaded_not_blended_across_the_edge() {
        // Two materials meeting at x = 5 on a level-2 lattice (0, 4, 8): pixels 5–7 have
        // corner 4 of the other material; 1–3 have both corners on their own.
        let r = UVec2::new(9, 1);
        let (l, c, s) = inputs_for(r, 3, |x, _| PixelClass::Material(u32::from(x >= 5)));
        let u = plan(r, &l, &c, &s, 3);
        let shaded: Vec<usize> = (0..9).filter(|&i| u.is_shaded(i)).collect();
        assert_eq!(shaded, vec![0, 4, 5, 6, 7, 8]);
        // The background is only blended with the background.
        let (l, c, s) = inputs_for(r, 3, |x, _| {
            if x < 4 {
                PixelClass::Background
            } else {
                PixelClass::Material(0)
            }
        });
        let u = plan(r, &l, &c, &s, 3);
        let shaded: Vec<usize> = (0..9).filter(|&i| u.is_shaded(i)).collect();
        assert_eq!(shaded, vec![0, 1, 2, 3, 4, 8]);
    }

    #[test]
    fn a_parent_off_the_tangent_plane_makes_the_pixel_shaded() {
        let r = UVec2::new(5, 1);
        let (l, c, mut s) = inputs_for(r, 3, |_, _| PixelClass::Material(0));
        // The corner at x = 4 sits 2 cm above the plane, 2 cm further along: 45° off it.
        s[4] = Some(SurfacePoint {
            position_m: Vec3A::new(0.04, 0.0, 0.04),
            ..s[4].unwrap()
        });
        let u = plan(r, &l, &c, &s, 3);
        assert!((0..5).all(|i| u.is_shaded(i)));
    }

    #[test]
    fn concentrating_keeps_the_total_and_moves_density_to_the_parents() {
        let r = UVec2::new(5, 1);
        let (l, c, s) = inputs_for(r, 3, |_, _| PixelClass::Material(0));
        let u = plan(r, &l, &c, &s, 3);
        let uniform = Allocated {
            plan: SamplePlan::uniform(r, 4).unwrap(),
            relative_density: vec![1.0; 5],
        };
        let a = u.concentrate(&uniform, 4.0, 1).unwrap();
        // Pixels 1, 2, 3 give ¾+¼, ½+½, ¼+¾ to 0 and 4: each corner gets 1 + 1.5.
        let d = &a.relative_density;
        assert!(
            (d[0] - 2.5).abs() < 1e-5 && (d[4] - 2.5).abs() < 1e-5,
            "{d:?}"
        );
        assert_eq!(&d[1..4], &[0.0, 0.0, 0.0]);
        assert_eq!(a.plan.total_camera_samples(), 20);
    }

    #[test]
    fn a_cell_holding_a_finer_pixel_is_refined_on_both_sides_of_it() {
        // Level 7 everywhere (lattice 3 with max_level 3: 0, 8, 16) but one level-0 pixel
        // (a shadow edge) at x = 11: cell [8, 16] may not be interpolated at spacing 8;
        // at spacing 4 its cell [8, 12] still holds it, [12, 16] does not; at spacing 2,
        // [10, 12] holds it. Cell [0, 8] keeps spacing 8.
        let r = UVec2::new(17, 1);
        let (mut l, c, s) = inputs_for(r, 7, |_, _| PixelClass::Material(0));
        l[11] = 0;
        let u = plan(r, &l, &c, &s, 3);
        let shaded: Vec<usize> = (0..17).filter(|&i| u.is_shaded(i)).collect();
        assert_eq!(shaded, vec![0, 8, 10, 11, 12, 16]);
    }
}

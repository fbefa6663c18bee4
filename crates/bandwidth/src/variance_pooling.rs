//! Pooling V̂_p over neighbouring pixels of the same surface (beyond the paper).
//!
//! Eq. 9's V̂_p is a Monte Carlo mean over n_b probe directions, and its terms are heavy
//! tailed: a probe sample that meets the sun of an environment map carries a bandwidth
//! thousands of times the sky's, so two neighbouring pixels of one Lambertian floor differ
//! by 10⁴ (measured on the fig. 9 scene). Allocating on such an estimate spreads samples at
//! random. Pooling the estimate over the (2r+1)² window around a pixel, among pixels that
//! see the same material (or, for pixels that see the background, among those), gives it
//! (2r+1)²·n_b samples; the shading variance of one surface changes slowly apart from its
//! edges, which the material classes keep apart. Measured (docs/bandwidth.md): with r = 2
//! the allocation's expected relMSE beats uniform sampling's on the three benchmark scenes,
//! where per-pixel V̂ lost to it. The best radius grows with the image ([`PoolRadius::Auto`]),
//! so each class's window sums are separable (a row pass, then a column pass within the
//! class's bounding box, O(1) per pixel) wherever that costs less than summing each window,
//! (2r+1)² reads per pixel.

use std::collections::HashMap;

use glam::UVec2;

use crate::error::{check_lengths, pixel_count, BandwidthError};

/// The default pooling radius: [`PoolRadius::Auto`].
pub const DEFAULT_POOL_RADIUS: PoolRadius = PoolRadius::Auto;

/// Image pixels per pixel of automatic pooling radius: r = min(W, H)/32, at least 1.
const AUTO_POOL_PX_PER_RADIUS_PX: u32 = 32;

/// The pooling radius r (`--plan-pool-px`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoolRadius {
    /// In proportion to the image, r = min(W, H)/32 rounded, at least 1: a window that
    /// covers the same share of the scene at every resolution. Measured best among fixed
    /// radii at 64², 128² and 256² (r = 2, 4, 8; docs/bandwidth.md).
    Auto,
    /// A fixed radius in pixels; 0 = the paper's per-pixel V̂_p.
    Px(u32),
}

impl PoolRadius {
    /// The radius in pixels for an image of `resolution`.
    pub fn px(self, resolution: UVec2) -> u32 {
        match self {
            PoolRadius::Auto => ((resolution.x.min(resolution.y) + AUTO_POOL_PX_PER_RADIUS_PX / 2)
                / AUTO_POOL_PX_PER_RADIUS_PX)
                .max(1),
            PoolRadius::Px(r) => r,
        }
    }
}

impl std::fmt::Display for PoolRadius {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PoolRadius::Auto => f.write_str("auto"),
            PoolRadius::Px(r) => write!(f, "{r}"),
        }
    }
}

/// The surface class of a pixel: pooling only mixes pixels of one class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PixelClass {
    /// The centre ray hits a surface of this material.
    Material(u32),
    /// The centre ray escapes to the infinite lights.
    Background,
    /// No prediction (no footprint, or nothing hit and no infinite light): kept as it is and
    /// never pooled into a neighbour.
    Unpredicted,
}

/// V̂ pooled per pixel: the mean of `variance` over the (2r+1)² window around each pixel
/// (clipped at the image border) among the pixels of the same [`PixelClass`];
/// `Unpredicted` pixels keep their own value. `radius_px` = 0 returns the input.
pub fn pool_variance(
    resolution: UVec2,
    variance: &[f32],
    class: &[PixelClass],
    radius_px: u32,
) -> Result<Vec<f32>, BandwidthError> {
    pool_scaled(
        resolution,
        variance,
        &vec![1.0; variance.len()],
        class,
        &vec![true; variance.len()],
        radius_px,
    )
}

/// [`pool_variance`] of values that scale with a known per-pixel factor (V̂ and L̂ of a
/// textured surface go as ρ² and ρ): pixel p gets scale_p · Σ_q value_q / Σ_q scale_q over
/// its same-class window, the least-squares fit of value = c · scale there, so a texture's
/// pattern survives the pooling that removes the probe's noise. Where the window's scales
/// sum to 0 the plain mean is kept. All scales 1 is [`pool_variance`].
///
/// Only pixels marked in `probed` lend their value (`sparse_probing`: the others were not
/// sampled and carry none); a pixel with no probed pixel of its class in its window keeps
/// its own value. All true pools every pixel.
pub fn pool_scaled(
    resolution: UVec2,
    values: &[f32],
    scale: &[f32],
    class: &[PixelClass],
    probed: &[bool],
    radius_px: u32,
) -> Result<Vec<f32>, BandwidthError> {
    let [pooled] = pool_scaled_each(resolution, [values], scale, class, probed, radius_px)?;
    Ok(pooled)
}

/// [`pool_scaled`] of `N` images that share one scale, in one pass over the windows: each
/// the same values as its own [`pool_scaled`] call.
pub fn pool_scaled_each<const N: usize>(
    resolution: UVec2,
    values: [&[f32]; N],
    scale: &[f32],
    class: &[PixelClass],
    probed: &[bool],
    radius_px: u32,
) -> Result<[Vec<f32>; N], BandwidthError> {
    let count = pixel_count("pooled V̂", resolution)?;
    for v in values {
        check_lengths(resolution, count, &[("V̂ to pool", v.len())])?;
    }
    check_lengths(
        resolution,
        count,
        &[
            ("pooling scales", scale.len()),
            ("pixel classes", class.len()),
            ("probed mask", probed.len()),
        ],
    )?;
    if radius_px == 0 {
        return Ok(values.map(<[f32]>::to_vec));
    }
    let image = PoolImage {
        resolution,
        values,
        scale,
        class,
        probed,
    };
    Ok(image.pool(radius_px, |extent| {
        WindowSummation::cheaper(extent, radius_px as usize)
    }))
}

/// Where one class's pixels lie: their bounding box (inclusive) and their count. No
/// pixel of the class lies outside the box, so neither do the windows' members.
#[derive(Clone, Copy, Debug)]
struct ClassExtent {
    class: PixelClass,
    min: (usize, usize),
    max: (usize, usize),
    pixels: usize,
}

impl ClassExtent {
    fn size(&self) -> (usize, usize) {
        (self.max.0 - self.min.0 + 1, self.max.1 - self.min.1 + 1)
    }
}

/// The extents of the pooled classes (all but `Unpredicted`), in the order they are first
/// met: each class writes only its own pixels.
fn class_extents(resolution: UVec2, class: &[PixelClass]) -> Vec<ClassExtent> {
    let w = resolution.x as usize;
    // Classes come in long runs along a row: the class met last is checked first, and the
    // map is asked only where a run changes (hashing every pixel was several per cent of
    // the predictor at 128², fig17).
    let mut extents: Vec<ClassExtent> = Vec::new();
    let mut index: HashMap<PixelClass, usize> = HashMap::new();
    let mut last = 0;
    for (i, &c) in class.iter().enumerate() {
        match c {
            PixelClass::Unpredicted => continue,
            PixelClass::Material(_) | PixelClass::Background => {}
        }
        let (x, y) = (i % w, i / w);
        let found = if extents.get(last).is_some_and(|e| e.class == c) {
            Some(last)
        } else {
            index.get(&c).copied()
        };
        match found {
            Some(k) => {
                let e = &mut extents[k];
                e.min = (e.min.0.min(x), e.min.1.min(y));
                e.max = (e.max.0.max(x), e.max.1.max(y));
                e.pixels += 1;
                last = k;
            }
            None => {
                last = extents.len();
                index.insert(c, last);
                extents.push(ClassExtent {
                    class: c,
                    min: (x, y),
                    max: (x, y),
                    pixels: 1,
                });
            }
        }
    }
    extents
}

/// How one class's window sums are taken; both give the same sums up to rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum WindowSummation {
    /// (2r+1)² reads per pixel of the class: cheaper for a class whose pixels are few in
    /// its bounding box (scattered, or thin and diagonal).
    PerWindow,
    /// A row pass, then a column pass, over the bounding box, each O(1) per pixel
    /// ([`BlockSums`]): a few reads per box pixel whatever the radius.
    Separable,
}

impl WindowSummation {
    fn cheaper(extent: &ClassExtent, radius_px: usize) -> Self {
        let side = 2 * radius_px + 1;
        let (bw, bh) = extent.size();
        let per_window = extent.pixels.saturating_mul(side * side);
        // Measured: the two passes cost about as much as 8 reads per box pixel.
        let separable = (bw * bh).saturating_mul(8);
        if separable < per_window {
            WindowSummation::Separable
        } else {
            WindowSummation::PerWindow
        }
    }
}

/// Σ value (per image), Σ scale and the count of a window's lending pixels.
#[derive(Clone, Copy, Debug)]
struct WindowSum<const N: usize> {
    value: [f64; N],
    scale: f64,
    count: u32,
}

impl<const N: usize> Default for WindowSum<N> {
    fn default() -> Self {
        Self {
            value: [0.0; N],
            scale: 0.0,
            count: 0,
        }
    }
}

impl<const N: usize> WindowSum<N> {
    fn add(&mut self, other: WindowSum<N>) {
        for (v, o) in self.value.iter_mut().zip(other.value) {
            *v += o;
        }
        self.scale += other.scale;
        self.count += other.count;
    }

    /// `pool_scaled`'s value of image `k` for a pixel of `own_value` and `own_scale` whose
    /// window sums to `self`.
    fn pooled(&self, k: usize, own_value: f32, own_scale: f32) -> f32 {
        let value = if self.count == 0 {
            f64::from(own_value)
        } else if self.scale > 0.0 {
            f64::from(own_scale) * (self.value[k] / self.scale)
        } else {
            self.value[k] / f64::from(self.count)
        };
        value as f32
    }

    /// Pixel `i`'s pooled value of every image into `pooled`.
    fn write(&self, i: usize, values: [&[f32]; N], scale: &[f32], pooled: &mut [Vec<f32>; N]) {
        for (k, out) in pooled.iter_mut().enumerate() {
            out[i] = self.pooled(k, values[k][i], scale[i]);
        }
    }
}

/// What `pool_scaled` pools, checked to one length.
struct PoolImage<'a, const N: usize> {
    resolution: UVec2,
    values: [&'a [f32]; N],
    scale: &'a [f32],
    class: &'a [PixelClass],
    probed: &'a [bool],
}

impl<const N: usize> PoolImage<'_, N> {
    /// Every class pooled, each summed as `summation` picks for its extent.
    fn pool(
        &self,
        radius_px: u32,
        summation: impl Fn(&ClassExtent) -> WindowSummation,
    ) -> [Vec<f32>; N] {
        let mut pooled = self.values.map(<[f32]>::to_vec);
        for extent in class_extents(self.resolution, self.class) {
            self.pool_class(radius_px, &extent, summation(&extent), &mut pooled);
        }
        pooled
    }

    /// Writes the pooled values of `extent`'s class into `pooled`.
    fn pool_class(
        &self,
        radius_px: u32,
        extent: &ClassExtent,
        summation: WindowSummation,
        pooled: &mut [Vec<f32>; N],
    ) {
        let (values, scale, class, probed) = (self.values, self.scale, self.class, self.probed);
        let w = self.resolution.x as usize;
        let r = radius_px as usize;
        let own = extent.class;
        // A pixel's contribution to its class's windows: nothing unless it is of the class and
        // was probed (a non-finite value elsewhere never reaches this class's sums).
        let lend = |j: usize| {
            if class[j] == own && probed[j] {
                WindowSum {
                    value: values.map(|v| f64::from(v[j])),
                    scale: f64::from(scale[j]),
                    count: 1,
                }
            } else {
                WindowSum::default()
            }
        };
        let (x0, y0) = extent.min;
        let (x1, y1) = extent.max;
        match summation {
            WindowSummation::PerWindow => {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = y * w + x;
                        if class[i] != own {
                            continue;
                        }
                        let mut sum = WindowSum::default();
                        for yy in y.saturating_sub(r).max(y0)..=(y + r).min(y1) {
                            for xx in x.saturating_sub(r).max(x0)..=(x + r).min(x1) {
                                sum.add(lend(yy * w + xx));
                            }
                        }
                        sum.write(i, values, scale, pooled);
                    }
                }
            }
            WindowSummation::Separable => {
                let (bw, bh) = extent.size();
                let mut sums: Vec<WindowSum<N>> = (0..bw * bh)
                    .map(|k| lend((y0 + k / bw) * w + x0 + k % bw))
                    .collect();
                let mut line = Vec::with_capacity(bw.max(bh));
                let mut scratch = BlockSums::default();
                for row in sums.chunks_exact_mut(bw) {
                    line.clear();
                    line.extend_from_slice(row);
                    scratch.window_sums(&line, r, row);
                }
                let mut column = vec![WindowSum::default(); bh];
                for bx in 0..bw {
                    line.clear();
                    line.extend((0..bh).map(|by| sums[by * bw + bx]));
                    scratch.window_sums(&line, r, &mut column);
                    for (by, sum) in column.iter().enumerate() {
                        let i = (y0 + by) * w + x0 + bx;
                        if class[i] == own {
                            sum.write(i, values, scale, pooled);
                        }
                    }
                }
            }
        }
    }
}

/// Window sums along a line in O(1) per element without subtracting (so without the
/// cancellation of running sums on values that span many decades): the van Herk / Gil–Werman
/// scheme. The line is cut into blocks of the window's length k = 2r+1; a window then covers
/// a suffix of one block and a prefix of the next, or (clipped at an end of the line) one
/// block's prefix or suffix.
struct BlockSums<const N: usize> {
    prefix: Vec<WindowSum<N>>,
    suffix: Vec<WindowSum<N>>,
}

impl<const N: usize> Default for BlockSums<N> {
    fn default() -> Self {
        Self {
            prefix: Vec::new(),
            suffix: Vec::new(),
        }
    }
}

impl<const N: usize> BlockSums<N> {
    /// `out[i]` = Σ `line[j]` over |j − i| ≤ r within the line.
    fn window_sums(&mut self, line: &[WindowSum<N>], r: usize, out: &mut [WindowSum<N>]) {
        let n = line.len();
        let k = 2 * r + 1;
        self.prefix.clear();
        self.prefix.extend_from_slice(line);
        self.suffix.clear();
        self.suffix.extend_from_slice(line);
        for i in 1..n {
            if i % k != 0 {
                let before = self.prefix[i - 1];
                self.prefix[i].add(before);
            }
        }
        for i in (0..n.saturating_sub(1)).rev() {
            if (i + 1) % k != 0 {
                let after = self.suffix[i + 1];
                self.suffix[i].add(after);
            }
        }
        for (i, out) in out.iter_mut().enumerate().take(n) {
            let (a, b) = (i.saturating_sub(r), (i + r).min(n - 1));
            *out = if a / k != b / k {
                let mut sum = self.suffix[a];
                sum.add(self.prefix[b]);
                sum
            } else if a % k == 0 {
                // From its block's start (the line's start when clipped there).
                self.prefix[b]
            } else {
                // To its block's end: b is the line's end, where the last block ends.
                self.suffix[a]
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_zero_is_the_identity() {
        let v = [1.0, 5.0, 0.0, 2.0];
        let c = [PixelClass::Material(0); 4];
        assert_eq!(pool_variance(UVec2::new(2, 2), &v, &c, 0).unwrap(), v);
    }

    #[test]
    fn pools_within_a_class_only() {
        // 4×1: two materials, then the background.
        let v = [1.0, 3.0, 100.0, 7.0];
        let c = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(1),
            PixelClass::Background,
        ];
        let p = pool_variance(UVec2::new(4, 1), &v, &c, 2).unwrap();
        assert_eq!(p, vec![2.0, 2.0, 100.0, 7.0]);
    }

    #[test]
    fn unpredicted_pixels_keep_their_value_and_are_not_pooled() {
        let v = [4.0, 1000.0, 8.0];
        let c = [
            PixelClass::Material(2),
            PixelClass::Unpredicted,
            PixelClass::Material(2),
        ];
        let p = pool_variance(UVec2::new(3, 1), &v, &c, 1).unwrap();
        assert_eq!(p, vec![4.0, 1000.0, 8.0]);
        let p = pool_variance(UVec2::new(3, 1), &v, &c, 2).unwrap();
        assert_eq!(p, vec![6.0, 1000.0, 6.0]);
    }

    #[test]
    fn window_is_clipped_at_the_border_and_keeps_the_mean() {
        // A 5×5 image of one class: the pooled image's corner is the mean of its 3×3 corner
        // window (r = 2), and a spike's total is spread, not lost.
        let mut v = vec![0.0f32; 25];
        v[12] = 25.0;
        let c = vec![PixelClass::Material(0); 25];
        let p = pool_variance(UVec2::new(5, 5), &v, &c, 2).unwrap();
        assert_eq!(p[0], 25.0 / 9.0);
        assert_eq!(p[12], 1.0);
        assert!(p.iter().all(|x| *x > 0.0));
    }

    /// A texture's pattern survives: values that are exactly c · scale come back unchanged,
    /// and noise on them is averaged in proportion to the scale.
    #[test]
    fn scaled_pooling_keeps_a_pattern_proportional_to_the_scale() {
        let scale = [0.2, 1.0, 0.5, 0.8, 0.1];
        let values: Vec<f32> = scale.iter().map(|s| 3.0 * s).collect();
        let c = [PixelClass::Material(0); 5];
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &[true; 5], 2).unwrap();
        for (got, want) in p.iter().zip(&values) {
            assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        }
        // One pixel twice too high: its excess is shared by scale, not evenly.
        let mut noisy = values.clone();
        noisy[2] *= 2.0;
        let p = pool_scaled(UVec2::new(5, 1), &noisy, &scale, &c, &[true; 5], 4).unwrap();
        let ratio: Vec<f32> = p.iter().zip(&scale).map(|(v, s)| v / s).collect();
        assert!(
            ratio.iter().all(|r| (r - ratio[0]).abs() < 1e-5),
            "{ratio:?}"
        );
        // A window whose scales are all 0 keeps the plain mean.
        let p = pool_scaled(
            UVec2::new(2, 1),
            &[1.0, 3.0],
            &[0.0, 0.0],
            &c[..2],
            &[true; 2],
            1,
        )
        .unwrap();
        assert_eq!(p, vec![2.0, 2.0]);
    }

    /// Sparse probing: pixels that were not probed lend nothing and take their probed
    /// neighbours' mean, scaled by their own texture.
    #[test]
    fn only_probed_pixels_lend_their_value() {
        let values = [2.0, 0.0, 4.0, 0.0, 9.0];
        let scale = [1.0, 0.5, 1.0, 1.0, 1.0];
        let c = [
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(0),
            PixelClass::Material(1),
        ];
        let probed = [true, false, true, false, true];
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &probed, 1).unwrap();
        // Pixel 1: (2 + 4)/(1 + 1) × 0.5; pixel 3: its only probed neighbour of class 0 is
        // pixel 2; pixel 4 is alone in its class.
        assert_eq!(p, vec![2.0, 1.5, 4.0, 4.0, 9.0]);
        // A pixel with no probed pixel of its class in the window keeps its own value.
        let p = pool_scaled(UVec2::new(5, 1), &values, &scale, &c, &[false; 5], 1).unwrap();
        assert_eq!(p, values.to_vec());
    }

    /// Pools with every class summed one way, whatever costs less.
    fn pool_forced(
        resolution: UVec2,
        values: &[f32],
        scale: &[f32],
        class: &[PixelClass],
        probed: &[bool],
        radius_px: u32,
        summation: WindowSummation,
    ) -> Vec<f32> {
        let image = PoolImage {
            resolution,
            values: [values],
            scale,
            class,
            probed,
        };
        let [pooled] = image.pool(radius_px, |_| summation);
        pooled
    }

    /// The definition, pixel by pixel over the whole image's clipped window.
    fn pool_by_definition(
        resolution: UVec2,
        values: &[f32],
        scale: &[f32],
        class: &[PixelClass],
        probed: &[bool],
        r: usize,
    ) -> Vec<f32> {
        let (w, h) = (resolution.x as usize, resolution.y as usize);
        (0..w * h)
            .map(|i| {
                if class[i] == PixelClass::Unpredicted {
                    return values[i];
                }
                let mut sum = WindowSum::default();
                for (xx, yy) in crate::pixel_neighbours::window((i % w, i / w), r, (w, h)) {
                    let j = yy * w + xx;
                    if class[j] == class[i] && probed[j] {
                        sum.add(WindowSum {
                            value: [f64::from(values[j])],
                            scale: f64::from(scale[j]),
                            count: 1,
                        });
                    }
                }
                sum.pooled(0, values[i], scale[i])
            })
            .collect()
    }

    /// Images pooled together are each pooled as alone, to the bit, whichever summation
    /// their classes take (a large radius picks the separable one, a small one windows).
    #[test]
    fn images_pooled_together_are_each_pooled_alone() {
        let resolution = UVec2::new(29, 17);
        let n = (resolution.x * resolution.y) as usize;
        let class: Vec<PixelClass> = (0..n)
            .map(|i| match (i * 7919) % 11 {
                0 => PixelClass::Unpredicted,
                1 | 2 => PixelClass::Background,
                k => PixelClass::Material((k % 3) as u32),
            })
            .collect();
        let a: Vec<f32> = (0..n).map(|i| ((i * 37) % 101) as f32 * 1e-3).collect();
        let b: Vec<f32> = (0..n).map(|i| 10f32.powi((i % 9) as i32 - 4)).collect();
        let scale: Vec<f32> = (0..n).map(|i| ((i * 13) % 7) as f32 / 6.0).collect();
        let probed: Vec<bool> = (0..n).map(|i| i % 3 != 1).collect();
        for r in [0u32, 1, 3, 20] {
            let [pa, pb] =
                pool_scaled_each(resolution, [&a, &b], &scale, &class, &probed, r).unwrap();
            let alone = |v: &[f32]| pool_scaled(resolution, v, &scale, &class, &probed, r).unwrap();
            assert_eq!(pa, alone(&a), "r = {r}");
            assert_eq!(pb, alone(&b), "r = {r}");
        }
    }

    /// Both summations give the definition's pooled values (to f32 rounding) on random
    /// images of four materials, the background and unpredicted pixels, with values over
    /// eight decades (the probe's heavy tail), sparse probing and radii up to past the
    /// image; a non-finite value spoils only its own class's windows that hold it.
    #[test]
    fn separable_and_per_window_sums_agree_with_the_definition() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let resolution = UVec2::new(37, 23);
        let n = (resolution.x * resolution.y) as usize;
        for round in 0..6 {
            let class: Vec<PixelClass> = (0..n)
                .map(|i| {
                    // Blocks of materials with noise, so classes have both compact and
                    // scattered members.
                    let u = next();
                    let (x, y) = (i % 37, i / 37);
                    if u < 0.05 {
                        PixelClass::Unpredicted
                    } else if u < 0.15 {
                        PixelClass::Material(3)
                    } else if y < 8 {
                        PixelClass::Background
                    } else {
                        PixelClass::Material((x / 12) as u32)
                    }
                })
                .collect();
            let mut values: Vec<f32> = (0..n)
                .map(|_| 10f64.powf(8.0 * next() - 4.0) as f32)
                .collect();
            let scale: Vec<f32> = (0..n).map(|_| next() as f32).collect();
            let probed: Vec<bool> = (0..n).map(|_| round % 2 == 0 || next() < 0.3).collect();
            if round == 5 {
                values[0] = f32::INFINITY;
            }
            for r in [1u32, 2, 5, 40] {
                let want =
                    pool_by_definition(resolution, &values, &scale, &class, &probed, r as usize);
                // Each way, and the one `pool_scaled` picks per class. The sums are f64 in
                // different orders, the result f32: they agree to a few f32 ulps (≈ 1e-7).
                let candidates = [
                    (
                        "per window",
                        pool_forced(
                            resolution,
                            &values,
                            &scale,
                            &class,
                            &probed,
                            r,
                            WindowSummation::PerWindow,
                        ),
                    ),
                    (
                        "separable",
                        pool_forced(
                            resolution,
                            &values,
                            &scale,
                            &class,
                            &probed,
                            r,
                            WindowSummation::Separable,
                        ),
                    ),
                    (
                        "pool_scaled",
                        pool_scaled(resolution, &values, &scale, &class, &probed, r).unwrap(),
                    ),
                ];
                for (name, got) in candidates {
                    assert_eq!(got.len(), n);
                    for i in 0..n {
                        let (g, w) = (got[i], want[i]);
                        let same =
                            g == w || (g.is_nan() && w.is_nan()) || (g - w).abs() <= 1e-6 * w.abs();
                        assert!(same, "round {round} r {r} {name} pixel {i}: {g} vs {w}");
                    }
                }
            }
        }
    }

    #[test]
    fn summation_is_separable_where_that_costs_less() {
        let compact = ClassExtent {
            class: PixelClass::Background,
            min: (0, 0),
            max: (99, 99),
            pixels: 10_000,
        };
        assert_eq!(
            WindowSummation::cheaper(&compact, 1),
            WindowSummation::Separable
        );
        assert_eq!(
            WindowSummation::cheaper(&compact, 8),
            WindowSummation::Separable
        );
        // 50 pixels scattered over the same box: summing their windows costs less.
        let scattered = ClassExtent {
            pixels: 50,
            ..compact
        };
        assert_eq!(
            WindowSummation::cheaper(&scattered, 8),
            WindowSummation::PerWindow
        );
    }

    #[test]
    fn the_automatic_radius_follows_the_image() {
        let r = |w, h| PoolRadius::Auto.px(UVec2::new(w, h));
        assert_eq!((r(64, 64), r(128, 128), r(256, 256)), (2, 4, 8));
        assert_eq!((r(64, 36), r(16, 16), r(1920, 1080)), (1, 1, 34));
        assert_eq!(PoolRadius::Px(0).px(UVec2::new(512, 512)), 0);
        assert_eq!(PoolRadius::Auto.to_string(), "auto");
        assert_eq!(PoolRadius::Px(5).to_string(), "5");
    }

    #[test]
    fn wrong_sizes_are_refused_by_name() {
        let e = pool_variance(UVec2::new(2, 2), &[1.0; 3], &[PixelClass::Background; 4], 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("V̂ to pool"), "{e}");
    }
}

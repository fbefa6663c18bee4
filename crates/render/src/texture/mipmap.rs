//! Image pyramid with nearest, bilinear and trilinear lookups (Williams 1983, "Pyramidal
//! parametrics"; pbrt-v4 §10.4.3 `MIPMap`). Texels are RGBA f32, row 0 at v = 0 (the
//! image's bottom row), texel (i, j) centred at ((i + ½)/w, (j + ½)/h) in st.
//!
//! Level ℓ + 1 is level ℓ box-filtered to ⌈w/2⌉ × ⌈h/2⌉: each new texel averages the
//! source area it covers (fractional overlap at odd sizes), so every level keeps the
//! image's mean exactly. The trilinear footprint convention: one pixel step covers
//! `w = max(|∂s/∂x|, |∂t/∂x|, |∂s/∂y|, |∂t/∂y|) × resolution` texels, and the level is
//! log₂ w (a texel of level ℓ spans 2^ℓ level-0 texels); pbrt-v4 uses twice that width
//! for its wider default pixel filter, we match a one-pixel box.

use glam::Vec2;
use prism_scene::WrapMode;

/// One level's texels.
#[derive(Clone, Debug, PartialEq)]
struct Level {
    width: usize,
    height: usize,
    texels: Vec<[f32; 4]>,
}

/// A MIP-mapped RGBA image.
#[derive(Clone, Debug, PartialEq)]
pub struct MipMap {
    levels: Vec<Level>,
    wrap: WrapMode,
}

impl MipMap {
    /// The pyramid of `texels` (`width × height`, row 0 at v = 0). Panics if the size is
    /// zero or does not match (the loader checks both).
    pub fn new(width: usize, height: usize, texels: Vec<[f32; 4]>, wrap: WrapMode) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        while let Some(last) = levels.last() {
            if last.width == 1 && last.height == 1 {
                break;
            }
            let next = downsample(last);
            levels.push(next);
        }
        Self { levels, wrap }
    }

    /// Number of levels (1 for a 1×1 image).
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Width and height of level `level`.
    pub fn level_size(&self, level: usize) -> (usize, usize) {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        (l.width, l.height)
    }

    /// Texel (x, y) of `level` with the wrap mode applied to out-of-range indices.
    #[inline]
    pub fn texel(&self, level: usize, x: i64, y: i64) -> [f32; 4] {
        let l = &self.levels[level];
        let x = wrap(x, l.width, self.wrap);
        let y = wrap(y, l.height, self.wrap);
        l.texels[y * l.width + x]
    }

    /// The texel containing `st` (level 0).
    #[inline]
    pub fn nearest(&self, st: Vec2) -> [f32; 4] {
        let l = &self.levels[0];
        let x = (st.x * l.width as f32).floor() as i64;
        let y = (st.y * l.height as f32).floor() as i64;
        self.texel(0, x, y)
    }

    /// Bilinear interpolation of `level` at `st` (pbrt-v4 `Image::Bilerp`): exact at texel
    /// centres.
    #[inline]
    pub fn bilinear(&self, level: usize, st: Vec2) -> [f32; 4] {
        let l = &self.levels[level];
        let x = st.x * l.width as f32 - 0.5;
        let y = st.y * l.height as f32 - 0.5;
        let (xf, yf) = (x.floor(), y.floor());
        let (dx, dy) = (x - xf, y - yf);
        // The two columns and rows, wrapped once each (not per texel).
        let (x0, x1) = wrap_pair(xf as i64, l.width, self.wrap);
        let (y0, y1) = wrap_pair(yf as i64, l.height, self.wrap);
        let (r0, r1) = (y0 * l.width, y1 * l.width);
        let t = &l.texels;
        let (t00, t10, t01, t11) = (t[r0 + x0], t[r0 + x1], t[r1 + x0], t[r1 + x1]);
        std::array::from_fn(|c| {
            (1.0 - dx) * (1.0 - dy) * t00[c]
                + dx * (1.0 - dy) * t10[c]
                + (1.0 - dx) * dy * t01[c]
                + dx * dy * t11[c]
        })
    }

    /// The continuous MIP level for st-derivatives `dst0` (one pixel in x) and `dst1` (one
    /// pixel in y): log₂ of the footprint in level-0 texels (see the module notes).
    /// −∞ for a zero footprint.
    #[inline]
    pub fn level_for(&self, dst0: Vec2, dst1: Vec2) -> f32 {
        let l = &self.levels[0];
        let w = (dst0.x.abs() * l.width as f32)
            .max(dst0.y.abs() * l.height as f32)
            .max(dst1.x.abs() * l.width as f32)
            .max(dst1.y.abs() * l.height as f32);
        w.log2()
    }

    /// Trilinear lookup (pbrt-v4 `MIPMap::Filter` with `FilterFunction::Trilinear`):
    /// bilinear in the two levels around `level_for`, blended linearly; level 0 below it,
    /// the 1×1 mean above the pyramid.
    #[inline]
    pub fn trilinear(&self, st: Vec2, dst0: Vec2, dst1: Vec2) -> [f32; 4] {
        let level = self.level_for(dst0, dst1);
        let top = (self.levels.len() - 1) as f32;
        // `level > 0.0` is false for NaN too: a degenerate footprint magnifies.
        if level.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return self.bilinear(0, st);
        }
        if level >= top {
            return self.levels[self.levels.len() - 1].texels[0];
        }
        let i = level.floor();
        let f = level - i;
        let i = i as usize;
        let a = self.bilinear(i, st);
        let b = self.bilinear(i + 1, st);
        std::array::from_fn(|c| a[c] + f * (b[c] - a[c]))
    }

    /// Mean of every texel (the top level).
    pub fn mean(&self) -> [f32; 4] {
        self.levels[self.levels.len() - 1].texels[0]
    }
}

/// Indices i and i + 1 wrapped into `0..n`; no division when both are inside.
#[inline]
fn wrap_pair(i: i64, n: usize, mode: WrapMode) -> (usize, usize) {
    if i >= 0 && i + 1 < n as i64 {
        (i as usize, i as usize + 1)
    } else {
        (wrap(i, n, mode), wrap(i + 1, n, mode))
    }
}

/// An index into `0..n` under the wrap mode.
#[inline]
fn wrap(i: i64, n: usize, mode: WrapMode) -> usize {
    let n = n as i64;
    (match mode {
        WrapMode::Repeat => i.rem_euclid(n),
        WrapMode::Clamp => i.clamp(0, n - 1),
        WrapMode::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m >= n {
                2 * n - 1 - m
            } else {
                m
            }
        }
    }) as usize
}

/// 1D box weights from `n` source texels to `m = ⌈n/2⌉` (n > 1) or 1: for each output,
/// (source index, weight) pairs with weights summing to 1.
fn box_weights(n: usize) -> (usize, Vec<Vec<(usize, f32)>>) {
    let m = if n == 1 { 1 } else { n.div_ceil(2) };
    let ratio = n as f64 / m as f64;
    let weights = (0..m)
        .map(|i| {
            let (lo, hi) = (i as f64 * ratio, (i + 1) as f64 * ratio);
            let mut taps = Vec::new();
            let mut j = lo.floor() as usize;
            while (j as f64) < hi && j < n {
                let overlap = (hi.min(j as f64 + 1.0) - lo.max(j as f64)).max(0.0);
                if overlap > 0.0 {
                    taps.push((j, (overlap / ratio) as f32));
                }
                j += 1;
            }
            taps
        })
        .collect();
    (m, weights)
}

fn downsample(l: &Level) -> Level {
    let (nw, wx) = box_weights(l.width);
    let (nh, wy) = box_weights(l.height);
    // Rows first, then columns (separable box).
    let mut rows = vec![[0.0f32; 4]; nw * l.height];
    for y in 0..l.height {
        for (x, taps) in wx.iter().enumerate() {
            let mut acc = [0.0f32; 4];
            for &(sx, w) in taps {
                let t = l.texels[y * l.width + sx];
                for c in 0..4 {
                    acc[c] += w * t[c];
                }
            }
            rows[y * nw + x] = acc;
        }
    }
    let mut texels = vec![[0.0f32; 4]; nw * nh];
    for (y, taps) in wy.iter().enumerate() {
        for x in 0..nw {
            let mut acc = [0.0f32; 4];
            for &(sy, w) in taps {
                let t = rows[sy * nw + x];
                for c in 0..4 {
                    acc[c] += w * t[c];
                }
            }
            texels[y * nw + x] = acc;
        }
    }
    Level {
        width: nw,
        height: nh,
        texels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize) -> Vec<[f32; 4]> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                [x, y, x * y, 1.0]
            })
            .collect()
    }

    #[test]
    fn bilinear_is_exact_at_texel_centres_and_linear_between() {
        let (w, h) = (8, 4);
        let m = MipMap::new(w, h, ramp(w, h), WrapMode::Clamp);
        for y in 0..h {
            for x in 0..w {
                let st = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                assert_eq!(m.bilinear(0, st), m.texel(0, x as i64, y as i64));
                assert_eq!(m.nearest(st), m.texel(0, x as i64, y as i64));
            }
        }
        // Halfway between texel centres (2, 1) and (3, 2): the mean of the four.
        let st = Vec2::new(3.0 / w as f32, 2.0 / h as f32);
        let v = m.bilinear(0, st);
        assert!((v[0] - 2.5).abs() < 1e-6 && (v[1] - 1.5).abs() < 1e-6);
        assert!((v[2] - (2.0 + 3.0 + 4.0 + 6.0) / 4.0).abs() < 1e-6);
    }

    #[test]
    fn wrap_modes_repeat_clamp_and_mirror() {
        assert_eq!(wrap(-1, 4, WrapMode::Repeat), 3);
        assert_eq!(wrap(9, 4, WrapMode::Repeat), 1);
        assert_eq!(wrap(-1, 4, WrapMode::Clamp), 0);
        assert_eq!(wrap(9, 4, WrapMode::Clamp), 3);
        // Mirror: … 1 0 | 0 1 2 3 | 3 2 1 0 | 0 1 …
        let mirrored: Vec<usize> = (-2..10).map(|i| wrap(i, 4, WrapMode::Mirror)).collect();
        assert_eq!(mirrored, vec![1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1]);
    }

    #[test]
    fn every_level_keeps_the_mean_including_odd_sizes() {
        for (w, h) in [(8, 8), (7, 5), (13, 1), (1, 6)] {
            let texels = ramp(w, h);
            let mean0: f64 = texels.iter().map(|t| t[2] as f64).sum::<f64>() / (w * h) as f64;
            let m = MipMap::new(w, h, texels, WrapMode::Repeat);
            assert_eq!(m.level_size(m.levels() - 1), (1, 1));
            for l in 0..m.levels() {
                let (lw, lh) = m.level_size(l);
                let mut s = 0.0f64;
                for y in 0..lh {
                    for x in 0..lw {
                        s += m.texel(l, x as i64, y as i64)[2] as f64;
                    }
                }
                let mean = s / (lw * lh) as f64;
                assert!(
                    (mean - mean0).abs() < 1e-4 * mean0.max(1.0),
                    "{w}×{h} level {l}"
                );
            }
        }
    }

    #[test]
    fn level_is_log2_of_the_texel_footprint() {
        let m = MipMap::new(256, 256, vec![[0.5; 4]; 256 * 256], WrapMode::Repeat);
        assert_eq!(m.levels(), 9);
        // One pixel step covers 4 texels in s → level 2; anisotropic: the larger axis.
        let l = m.level_for(Vec2::new(4.0 / 256.0, 0.0), Vec2::new(0.0, 1.0 / 256.0));
        assert!((l - 2.0).abs() < 1e-6);
        let l = m.level_for(
            Vec2::new(1.0 / 256.0, 0.5 / 256.0),
            Vec2::new(0.0, 8.0 / 256.0),
        );
        assert!((l - 3.0).abs() < 1e-6);
    }

    #[test]
    fn trilinear_blends_adjacent_levels() {
        // Checkerboard of single texels: level 0 alternates 0/1, level 1 is 0.5 flat.
        let (w, h) = (16, 16);
        let texels = (0..w * h)
            .map(|i| {
                let v = ((i % w + i / w) % 2) as f32;
                [v, v, v, 1.0]
            })
            .collect();
        let m = MipMap::new(w, h, texels, WrapMode::Repeat);
        let st = Vec2::new(0.5 / 16.0, 0.5 / 16.0); // texel (0, 0) = 0
        let d = |texels: f32| Vec2::new(texels / 16.0, 0.0);
        assert_eq!(m.trilinear(st, d(0.5), Vec2::ZERO)[0], 0.0);
        // Level 0.5: halfway between 0 (texel value) and level 1's 0.5.
        let v = m.trilinear(st, d(2f32.sqrt()), Vec2::ZERO)[0];
        assert!((v - 0.25).abs() < 1e-5, "{v}");
        assert!((m.trilinear(st, d(64.0), Vec2::ZERO)[0] - 0.5).abs() < 1e-6);
    }
}

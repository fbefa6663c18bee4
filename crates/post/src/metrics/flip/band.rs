//! LDR-FLIP of a pair of images, band by band: every band of rows is filtered with a halo
//! of source rows (clamped at the image edges, as the reference implementation's filters
//! are), so memory stays a few rows of planes per thread and the bands run in parallel.
//! Each source pixel goes through a transform first (a clip to [0, 1], or HDR-FLIP's tone
//! curve at one exposure), so tone-mapped copies of the images never exist.
//!
//! A band is split into column tiles (with the horizontal halo) so that the window of
//! source rows the vertical filters read stays in a core's L2 cache; on a 4K image the
//! planes of a whole band did not, and both cores waited on the shared L3.
//!
//! HDR-FLIP runs every exposure of a tile before the next tile, in the same buffers: the
//! tile's planes are still in cache and nothing is allocated or cleared per exposure. The
//! exposures cannot share filtered planes: the tone curve comes before the (linear)
//! filters and is not linear, so each exposure is filtered from its own tone-mapped
//! pixels, as the reference implementation does.
//!
//! The filters run vertically first, on four planes per image (Yy, Cx, Cz and the grey
//! the feature detectors see), into padded rows; then horizontally, straight into the
//! per-pixel colour and feature terms of one output row. Every kernel is symmetric or
//! antisymmetric about its centre, so each pair of taps costs one fused multiply-add
//! ([`Folded`]); the sums run 16 pixels at a time in registers ([`correlate`]).

use prism_cpu::Simd;
use rayon::prelude::*;

use super::colour::{filtered_to_hunt_lab, hyab, rgb_to_hunt_lab, rgb_to_ycxcz, ycxcz_grey};
use super::kernels::Kernels;
use super::pow::pow_non_negative;
use super::Rows;

/// Colour error exponent q_c, redistribution break p_c and target p_t (Andersson et al.
/// 2020, sec. 3). The feature exponent q_f is ½: a square root in [`combine_row`].
const QC: f32 = 0.7;
const PC: f32 = 0.4;
const PT: f32 = 0.95;

/// Output rows per band: the halo (2 × 10 rows at 67 ppd) costs ~30 % more filtering.
pub(super) const BAND_ROWS: usize = 64;

/// Output columns per tile of a band: the vertical filters' window (2 × 10 + 1 rows of
/// four planes per image) stays in L2, at ~8 % more filtering for the tiles' halo.
const TILE_COLS: usize = 256;

/// Pixels summed at once in [`correlate`]: one AVX-512 register, two AVX2 ones.
const LANES: usize = 16;

/// Groups of [`LANES`] pixels [`correlate`] sums side by side (independent chains of
/// additions), and [`correlate_many`] per kernel.
const BLOCKS: usize = 4;
const MANY_BLOCKS: usize = 2;

/// Defines `$name(simd, args)`: `$body_fn(args)` compiled for the widest ISA `simd`
/// allows. The same operations run at every ISA (multiply-adds are fused only where the
/// code says `mul_add`, which is exact everywhere), so the bits are the same; `$body_fn`
/// must be `#[inline(always)]`.
macro_rules! dispatch {
    ($(#[$doc:meta])* fn $name:ident <$($g:ident: $bound:path),*> ($($arg:ident: $ty:ty),* $(,)?) => $body_fn:ident) => {
        $(#[$doc])*
        #[allow(clippy::too_many_arguments)]
        fn $name<$($g: $bound),*>(simd: Simd, $($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw,avx2,fma")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx512<$($g: $bound),*>($($arg: $ty),*) {
                    $body_fn($($arg),*)
                }
                #[target_feature(enable = "avx2,fma")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx2<$($g: $bound),*>($($arg: $ty),*) {
                    $body_fn($($arg),*)
                }
                if simd.avx512() {
                    // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
                    return unsafe { avx512($($arg),*) };
                }
                if simd.avx2() {
                    // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
                    return unsafe { avx2($($arg),*) };
                }
            }
            let _ = simd;
            $body_fn($($arg),*)
        }
    };
}

/// The largest colour error: HyAB between Hunt-adjusted green and blue, to the power q_c.
fn c_max() -> f32 {
    hyab(
        rgb_to_hunt_lab([0.0, 1.0, 0.0]),
        rgb_to_hunt_lab([0.0, 0.0, 1.0]),
    )
    .powf(QC)
}

/// A kernel of odd length 2 r + 1, symmetric (k[r − t] = k[r + t]) or antisymmetric
/// (k[r − t] = −k[r + t], k[r] = 0), as its right half.
#[derive(Debug, Clone)]
pub(super) struct Folded {
    centre: f32,
    /// k[r + t] for t = 1..=r.
    taps: Vec<f32>,
    antisymmetric: bool,
}

impl Folded {
    /// `None` unless `k` is exactly symmetric or antisymmetric about its centre.
    pub(super) fn new(k: &[f32]) -> Option<Self> {
        let r = k.len() / 2;
        if k.len().is_multiple_of(2) {
            return None;
        }
        let symmetric = (1..=r).all(|t| k[r - t] == k[r + t]);
        let antisymmetric = k[r] == 0.0 && (1..=r).all(|t| k[r - t] == -k[r + t]);
        (symmetric || antisymmetric).then(|| Self {
            centre: k[r],
            taps: k[r + 1..].to_vec(),
            antisymmetric: !symmetric,
        })
    }

    pub(super) fn radius(&self) -> usize {
        self.taps.len()
    }

    /// Without the outer taps whose weights (both sides) sum to less than 2⁻²⁵ of the
    /// kernel's absolute sum: on inputs in [0, 1] they move a response by less than a
    /// quarter of an f32 ulp of 1. The narrow Yy and Cx kernels at 67 ppd (σ ≈ 1 px, read
    /// out to the widest kernel's radius, 10 px) lose 4 of their 10 taps each.
    fn without_negligible_tail(mut self) -> Self {
        let total = self.centre.abs() + 2.0 * self.taps.iter().map(|t| t.abs()).sum::<f32>();
        let mut tail = 0.0;
        while let Some(&last) = self.taps.last() {
            tail += 2.0 * last.abs();
            if tail >= total * 2f32.powi(-25) {
                break;
            }
            self.taps.pop();
        }
        self
    }
}

/// `out[x] = k[r] s[c + x] + Σₜ k[r + t] (s[c + x + t·stride] ± s[c + x − t·stride])`:
/// the correlation of `k` with `s` along rows (stride 1) or columns (stride = width).
/// Every pixel gets the same operations in the same order whatever its position or the
/// ISA (each tap one `mul_add`: the FMA instruction where the ISA has one, the exact
/// fused libm call elsewhere), so strips and whole images agree bit for bit.
fn correlate(simd: Simd, s: &[f32], c: usize, stride: usize, k: &Folded, out: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    {
        if simd.avx512() {
            // SAFETY: a `Simd` allows AVX-512 only on a CPU that has it.
            unsafe { correlate_avx512(s, c, stride, k, out) };
            return;
        }
        if simd.avx2() {
            // SAFETY: a `Simd` allows AVX2 only on a CPU that has it.
            unsafe { correlate_avx2(s, c, stride, k, out) };
            return;
        }
    }
    let _ = simd;
    correlate_any(s, c, stride, k, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw,avx2,fma")]
unsafe fn correlate_avx512(s: &[f32], c: usize, stride: usize, k: &Folded, out: &mut [f32]) {
    correlate_any(s, c, stride, k, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn correlate_avx2(s: &[f32], c: usize, stride: usize, k: &Folded, out: &mut [f32]) {
    correlate_any(s, c, stride, k, out);
}

#[inline(always)]
fn correlate_any(s: &[f32], c: usize, stride: usize, k: &Folded, out: &mut [f32]) {
    if k.antisymmetric {
        correlate_folded::<true>(s, c, stride, k, out);
    } else {
        correlate_folded::<false>(s, c, stride, k, out);
    }
}

#[inline(always)]
fn correlate_folded<const ODD: bool>(
    s: &[f32],
    c: usize,
    stride: usize,
    k: &Folded,
    out: &mut [f32],
) {
    let n = out.len();
    let mut x = 0;
    while x + BLOCKS * LANES <= n {
        correlate_block::<ODD, { BLOCKS * LANES }>(s, c + x, stride, k, &mut out[x..]);
        x += BLOCKS * LANES;
    }
    while x + LANES <= n {
        correlate_block::<ODD, LANES>(s, c + x, stride, k, &mut out[x..]);
        x += LANES;
    }
    for (x, o) in out.iter_mut().enumerate().skip(x) {
        let mut acc = if ODD { 0.0 } else { k.centre * s[c + x] };
        for (t, &kt) in k.taps.iter().enumerate() {
            let d = (t + 1) * stride;
            let (a, b) = (s[c + x + d], s[c + x - d]);
            acc = kt.mul_add(if ODD { a - b } else { a + b }, acc);
        }
        *o = acc;
    }
}

/// `W` outputs of [`correlate_folded`] from `s[c..]`, summed side by side: `W` / [`LANES`]
/// independent chains of additions hide their latency.
#[inline(always)]
fn correlate_block<const ODD: bool, const W: usize>(
    s: &[f32],
    c: usize,
    stride: usize,
    k: &Folded,
    out: &mut [f32],
) {
    let mut acc = [0.0f32; W];
    if !ODD {
        let centre: &[f32; W] = s[c..c + W].try_into().unwrap();
        acc = centre.map(|v| k.centre * v);
    }
    for (t, &kt) in k.taps.iter().enumerate() {
        let d = (t + 1) * stride;
        let hi: &[f32; W] = s[c + d..c + d + W].try_into().unwrap();
        let lo: &[f32; W] = s[c - d..c - d + W].try_into().unwrap();
        for j in 0..W {
            acc[j] = kt.mul_add(if ODD { hi[j] - lo[j] } else { hi[j] + lo[j] }, acc[j]);
        }
    }
    out[..W].copy_from_slice(&acc);
}

/// [`correlate`] of one source with `N` kernels of one radius at once: each pair of
/// source samples is read once for all of them. Each output gets exactly the operations
/// [`correlate`] would give it.
#[inline(always)]
fn correlate_many<const N: usize>(
    s: &[f32],
    c: usize,
    stride: usize,
    ks: [&Folded; N],
    outs: [&mut [f32]; N],
) {
    let r = ks[0].radius();
    assert!(ks.iter().all(|k| k.radius() == r), "kernels of one radius");
    let n = outs[0].len();
    let mut outs = outs;
    let mut x = 0;
    while x + MANY_BLOCKS * LANES <= n {
        correlate_many_block::<N, { MANY_BLOCKS * LANES }>(s, c + x, stride, ks, &mut outs, x);
        x += MANY_BLOCKS * LANES;
    }
    while x + LANES <= n {
        correlate_many_block::<N, LANES>(s, c + x, stride, ks, &mut outs, x);
        x += LANES;
    }
    for x in x..n {
        for (o, k) in outs.iter_mut().zip(&ks) {
            let mut acc = if k.antisymmetric {
                0.0
            } else {
                k.centre * s[c + x]
            };
            for (t, &kt) in k.taps.iter().enumerate() {
                let d = (t + 1) * stride;
                let (a, b) = (s[c + x + d], s[c + x - d]);
                acc = kt.mul_add(if k.antisymmetric { a - b } else { a + b }, acc);
            }
            o[x] = acc;
        }
    }
}

/// `W` outputs from `s[c..]` of each of [`correlate_many`]'s kernels, into
/// `outs[…][x..]`, summed side by side as in [`correlate_block`].
#[inline(always)]
fn correlate_many_block<const N: usize, const W: usize>(
    s: &[f32],
    c: usize,
    stride: usize,
    ks: [&Folded; N],
    outs: &mut [&mut [f32]; N],
    x: usize,
) {
    let r = ks[0].radius();
    let mut acc = [[0.0f32; W]; N];
    let centre: &[f32; W] = s[c..c + W].try_into().unwrap();
    for (a, k) in acc.iter_mut().zip(&ks) {
        if !k.antisymmetric {
            *a = centre.map(|v| k.centre * v);
        }
    }
    for t in 0..r {
        let d = (t + 1) * stride;
        let hi: &[f32; W] = s[c + d..c + d + W].try_into().unwrap();
        let lo: &[f32; W] = s[c - d..c - d + W].try_into().unwrap();
        let mut sum = [0.0f32; W];
        let mut diff = [0.0f32; W];
        for j in 0..W {
            sum[j] = hi[j] + lo[j];
            diff[j] = hi[j] - lo[j];
        }
        for (acc, k) in acc.iter_mut().zip(&ks) {
            let (kt, v) = (k.taps[t], if k.antisymmetric { &diff } else { &sum });
            for j in 0..W {
                acc[j] = kt.mul_add(v[j], acc[j]);
            }
        }
    }
    for (o, a) in outs.iter_mut().zip(&acc) {
        o[x..x + W].copy_from_slice(a);
    }
}

dispatch! {
    /// [`correlate_many`] with two kernels.
    fn correlate2<>(
        s: &[f32],
        c: usize,
        stride: usize,
        ks: [&Folded; 2],
        outs: [&mut [f32]; 2],
    ) => correlate_many
}

dispatch! {
    /// [`correlate_many`] with three kernels.
    fn correlate3<>(
        s: &[f32],
        c: usize,
        stride: usize,
        ks: [&Folded; 3],
        outs: [&mut [f32]; 3],
    ) => correlate_many
}

/// The filters of [`Kernels`], folded.
pub(super) struct Filters {
    halo: usize,
    y: Folded,
    cx: Folded,
    cz1: Folded,
    cz2: Folded,
    gauss: Folded,
    d1: Folded,
    d2: Folded,
}

impl Filters {
    pub(super) fn new(k: &Kernels) -> Self {
        let fold = |v: &[f32]| Folded::new(v).expect("FLIP's kernels are (anti)symmetric");
        let f = Self {
            halo: k.spatial_radius_px.max(k.feature_radius_px),
            // Only the kernels filtered alone: those summed together (Cz's two, the
            // feature detector's three) share their source reads and must keep one radius.
            y: fold(&k.y).without_negligible_tail(),
            cx: fold(&k.cx).without_negligible_tail(),
            cz1: fold(&k.cz1),
            cz2: fold(&k.cz2),
            gauss: fold(&k.gauss),
            d1: fold(&k.d1),
            d2: fold(&k.d2),
        };
        debug_assert!(f.y.radius() <= f.halo && f.gauss.radius() <= f.halo);
        f
    }

    /// Rows above and below a band (and pixels left and right of a row) the filters read.
    pub(super) fn halo(&self) -> usize {
        self.halo
    }
}

/// The columns of one tile of a band: output columns `x0..x1` and the source columns
/// `lo..hi` its filters read (the halo around them, clamped to the image).
#[derive(Debug, Clone, Copy)]
struct Tile {
    x0: usize,
    x1: usize,
    lo: usize,
    hi: usize,
}

impl Tile {
    fn width(&self) -> usize {
        self.x1 - self.x0
    }
}

/// The tiles a row of `w` pixels splits into: about [`TILE_COLS`] wide each, a multiple of
/// [`LANES`] but the last.
fn tiles(w: usize, halo: usize) -> Vec<Tile> {
    let n = w.div_ceil(TILE_COLS);
    let tw = w.div_ceil(n).next_multiple_of(LANES);
    (0..w)
        .step_by(tw)
        .map(|x0| {
            let x1 = (x0 + tw).min(w);
            Tile {
                x0,
                x1,
                lo: x0.saturating_sub(halo),
                hi: (x1 + halo).min(w),
            }
        })
        .collect()
}

/// One image's buffers for a tile of a band: the transformed planes (Yy, Cx, Cz, grey;
/// `band_h` rows of the tile's source columns each), the vertically filtered rows padded
/// by the halo (Yy, Cx, Cz twice, grey with the Gaussian, d1 and d2) and the output row's
/// Hunt-adjusted CIELAB, edge and point terms.
struct Side {
    planes: [Vec<f32>; 4],
    vertical: [Vec<f32>; 7],
    horizontal: [Vec<f32>; 8],
    lab: [Vec<f32>; 3],
    edge: Vec<f32>,
    point: Vec<f32>,
}

impl Side {
    /// For tiles up to `tw` pixels wide.
    fn new(tw: usize, band_h: usize, halo: usize) -> Self {
        Self {
            planes: std::array::from_fn(|_| vec![0.0; band_h * (tw + 2 * halo)]),
            vertical: std::array::from_fn(|_| vec![0.0; tw + 2 * halo]),
            horizontal: std::array::from_fn(|_| vec![0.0; tw]),
            lab: std::array::from_fn(|_| vec![0.0; tw]),
            edge: vec![0.0; tw],
            point: vec![0.0; tw],
        }
    }

    /// The planes of the band's `band_h` source rows from image row `y0 − halo` (clamped),
    /// columns `tile.lo..tile.hi`, after `transform`.
    #[allow(clippy::too_many_arguments)]
    fn fill_planes(
        &mut self,
        simd: Simd,
        image: Rows<'_>,
        (w, h): (usize, usize),
        y0: usize,
        band_h: usize,
        halo: usize,
        tile: Tile,
        transform: &impl Fn([f32; 3]) -> [f32; 3],
    ) {
        let pw = tile.hi - tile.lo;
        let [py, pcx, pcz, pg] = self.planes.each_mut().map(|p| &mut p[..band_h * pw]);
        let rows = py
            .chunks_exact_mut(pw)
            .zip(pcx.chunks_exact_mut(pw))
            .zip(pcz.chunks_exact_mut(pw).zip(pg.chunks_exact_mut(pw)));
        for (j, ((ry, rcx), (rcz, rg))) in rows.enumerate() {
            let sy = (y0 + j).saturating_sub(halo).min(h - 1);
            let src = &image.row(sy, w)[tile.lo..tile.hi];
            planes_row(simd, src, transform, ry, rcx, rcz, rg);
        }
    }

    /// Lab, edge and point of band row `i` (plane row `i + halo`) in `tile`.
    fn filter_row(&mut self, simd: Simd, f: &Filters, tile: Tile, i: usize) {
        let halo = f.halo;
        let (pw, tw) = (tile.hi - tile.lo, tile.width());
        // The planes start `pad` columns right of the padded rows' start (the halo that
        // lies beyond the image's left edge).
        let pad = halo - (tile.x0 - tile.lo);
        let c = (i + halo) * pw;
        let [py, pcx, pcz, pg] = &self.planes;
        let [vy, vcx, vcz1, vcz2, vg, vd1, vd2] = &mut self.vertical;
        let inner = pad..pad + pw;
        correlate(simd, py, c, pw, &f.y, &mut vy[inner.clone()]);
        correlate(simd, pcx, c, pw, &f.cx, &mut vcx[inner.clone()]);
        correlate2(
            simd,
            pcz,
            c,
            pw,
            [&f.cz1, &f.cz2],
            [&mut vcz1[inner.clone()], &mut vcz2[inner.clone()]],
        );
        correlate3(
            simd,
            pg,
            c,
            pw,
            [&f.gauss, &f.d1, &f.d2],
            [
                &mut vg[inner.clone()],
                &mut vd1[inner.clone()],
                &mut vd2[inner],
            ],
        );
        let end = tw + 2 * halo;
        for row in &mut self.vertical {
            // Clamp-to-edge padding commutes with the separable filter.
            let (left, right) = (row[pad], row[pad + pw - 1]);
            row[..pad].fill(left);
            row[pad + pw..end].fill(right);
        }
        let [vy, vcx, vcz1, vcz2, vg, vd1, vd2] = &self.vertical;
        let [hy, hcx, hcz1, hcz2, ex, ey, px, py] =
            self.horizontal.each_mut().map(|v| &mut v[..tw]);
        // Edges: ∂x = d1 ⊗ g, ∂y = g ⊗ d1; points likewise with d2.
        correlate(simd, vy, halo, 1, &f.y, hy);
        correlate(simd, vcx, halo, 1, &f.cx, hcx);
        correlate(simd, vcz1, halo, 1, &f.cz1, hcz1);
        correlate(simd, vcz2, halo, 1, &f.cz2, hcz2);
        correlate2(simd, vg, halo, 1, [&f.d1, &f.d2], [ex, px]);
        correlate(simd, vd1, halo, 1, &f.gauss, ey);
        correlate(simd, vd2, halo, 1, &f.gauss, py);
        let [l, a, b] = self.lab.each_mut().map(|v| &mut v[..tw]);
        let (edge, point) = (&mut self.edge[..tw], &mut self.point[..tw]);
        let [hy, hcx, hcz1, hcz2, ex, ey, px, py] = self.horizontal.each_ref().map(|v| &v[..tw]);
        terms_row(
            simd, hy, hcx, hcz1, hcz2, ex, ey, px, py, l, a, b, edge, point,
        );
    }
}

dispatch! {
    /// One source row through `transform` into the planes' rows.
    fn planes_row<T: Fn([f32; 3]) -> [f32; 3]>(
        src: &[[f32; 3]],
        transform: &T,
        ry: &mut [f32],
        rcx: &mut [f32],
        rcz: &mut [f32],
        rg: &mut [f32],
    ) => planes_row_any
}

#[inline(always)]
fn planes_row_any<T: Fn([f32; 3]) -> [f32; 3]>(
    src: &[[f32; 3]],
    transform: &T,
    ry: &mut [f32],
    rcx: &mut [f32],
    rcz: &mut [f32],
    rg: &mut [f32],
) {
    let n = src.len();
    let (ry, rcx, rcz, rg) = (&mut ry[..n], &mut rcx[..n], &mut rcz[..n], &mut rg[..n]);
    for x in 0..n {
        let [y, cx, cz] = rgb_to_ycxcz(transform(src[x]));
        (ry[x], rcx[x], rcz[x], rg[x]) = (y, cx, cz, ycxcz_grey(y));
    }
}

dispatch! {
    /// The filtered rows → Hunt-adjusted CIELAB (l, a, b) and edge and point magnitudes.
    fn terms_row<>(
        hy: &[f32],
        hcx: &[f32],
        hcz1: &[f32],
        hcz2: &[f32],
        ex: &[f32],
        ey: &[f32],
        px: &[f32],
        py: &[f32],
        l: &mut [f32],
        a: &mut [f32],
        b: &mut [f32],
        edge: &mut [f32],
        point: &mut [f32],
    ) => terms_row_any
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn terms_row_any(
    hy: &[f32],
    hcx: &[f32],
    hcz1: &[f32],
    hcz2: &[f32],
    ex: &[f32],
    ey: &[f32],
    px: &[f32],
    py: &[f32],
    l: &mut [f32],
    a: &mut [f32],
    b: &mut [f32],
    edge: &mut [f32],
    point: &mut [f32],
) {
    let n = l.len();
    let (hy, hcx, hcz1, hcz2) = (&hy[..n], &hcx[..n], &hcz1[..n], &hcz2[..n]);
    let (ex, ey, px, py) = (&ex[..n], &ey[..n], &px[..n], &py[..n]);
    let (a, b, edge, point) = (&mut a[..n], &mut b[..n], &mut edge[..n], &mut point[..n]);
    for x in 0..n {
        [l[x], a[x], b[x]] = filtered_to_hunt_lab([hy[x], hcx[x], hcz1[x] + hcz2[x]]);
        // Filter responses are O(1): plain sqrt, not hypot.
        edge[x] = (ex[x] * ex[x] + ey[x] * ey[x]).sqrt();
        point[x] = (px[x] * px[x] + py[x] * py[x]).sqrt();
    }
}

dispatch! {
    /// One output row from both sides' terms (CIELAB l, a, b, edge, point of the
    /// reference, then of the test): written, or with `keep_max` each value the larger of
    /// the old and the new.
    fn combine_row<>(
        r: [&[f32]; 5],
        t: [&[f32]; 5],
        cmax: f32,
        out: &mut [f32],
        keep_max: bool,
    ) => combine_row_any
}

#[inline(always)]
fn combine_row_any(r: [&[f32]; 5], t: [&[f32]; 5], cmax: f32, out: &mut [f32], keep_max: bool) {
    let n = out.len();
    let [rl, ra, rb, re, rp] = r.map(|v| &v[..n]);
    let [tl, ta, tb, te, tp] = t.map(|v| &v[..n]);
    let pccmax = PC * cmax;
    // Loop-invariant quotients as factors: no division per pixel.
    let (below, above) = (PT / pccmax, (1.0 - PT) / (cmax - pccmax));
    let inv_fourth_root_2 = 0.5f32.powf(0.25);
    for x in 0..n {
        let de = pow_non_negative(hyab([rl[x], ra[x], rb[x]], [tl[x], ta[x], tb[x]]), QC);
        let colour = if de < pccmax {
            below * de
        } else {
            PT + (de - pccmax) * above
        };
        let feature_diff = (re[x] - te[x]).abs().max((rp[x] - tp[x]).abs());
        // (feature_diff / √2)^q_f with q_f = ½.
        let feature = feature_diff.sqrt() * inv_fourth_root_2;
        let v = pow_non_negative(colour, 1.0 - feature);
        out[x] = if keep_max { out[x].max(v) } else { v };
    }
}

impl Side {
    /// The terms [`combine_row`] reads.
    fn terms(&self) -> [&[f32]; 5] {
        let [l, a, b] = &self.lab;
        [l, a, b, &self.edge, &self.point]
    }
}

/// The LDR-FLIP map of `test` against `reference` (linear Rec.709, `w × h`, row-major)
/// after each of `transforms`, for the image rows from `first_row` on that `out` covers,
/// written into `out` (one value per pixel): with one transform its map, with several
/// the per-pixel maximum of their maps (HDR-FLIP's maximum over exposures). `test` and
/// `reference` must hold the rows of `out` and the filters' halo around them (clamped to
/// the image).
#[allow(clippy::too_many_arguments)]
pub(super) fn flip_map_into<T: Fn([f32; 3]) -> [f32; 3] + Sync>(
    test: Rows<'_>,
    reference: Rows<'_>,
    (w, h): (usize, usize),
    first_row: usize,
    f: &Filters,
    transforms: &[T],
    out: &mut [f32],
    simd: Simd,
) {
    let cmax = c_max();
    let tiles = tiles(w, f.halo);
    let tw = tiles[0].width();
    out.par_chunks_mut(BAND_ROWS * w)
        .enumerate()
        .for_each(|(b, out)| {
            let y0 = first_row + b * BAND_ROWS;
            let rows = out.len() / w;
            let band_h = rows + 2 * f.halo;
            let mut r = Side::new(tw, band_h, f.halo);
            let mut t = Side::new(tw, band_h, f.halo);
            for &tile in &tiles {
                for (e, transform) in transforms.iter().enumerate() {
                    let fill = |s: &mut Side, image| {
                        s.fill_planes(simd, image, (w, h), y0, band_h, f.halo, tile, transform)
                    };
                    fill(&mut r, reference);
                    fill(&mut t, test);
                    for (i, out) in out.chunks_exact_mut(w).enumerate() {
                        r.filter_row(simd, f, tile, i);
                        t.filter_row(simd, f, tile, i);
                        let out = &mut out[tile.x0..tile.x1];
                        combine_row(simd, r.terms(), t.terms(), cmax, out, e > 0);
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kernel folds at several viewing conditions, and the folded correlation
    /// equals the plain sum over the whole kernel (to rounding) at every ISA, bit for bit
    /// across ISAs.
    #[test]
    fn kernels_fold_and_folded_correlation_matches_the_plain_sum() {
        for ppd in [10.0, 31.3, super::super::DEFAULT_PPD, 140.0] {
            let k = Kernels::new(ppd);
            let f = Filters::new(&k);
            assert!(f.d1.antisymmetric && !f.d2.antisymmetric && !f.y.antisymmetric);
            let n = 3 * LANES + 5;
            let halo = f.halo();
            let s: Vec<f32> = (0..n + 2 * halo)
                .map(|i| ((i * 7919) % 101) as f32 / 50.0 - 1.0)
                .collect();
            for (full, folded) in [(&k.y, &f.y), (&k.d1, &f.d1), (&k.d2, &f.d2)] {
                let r = full.len() / 2;
                let plain: Vec<f32> = (0..n)
                    .map(|x| (0..full.len()).map(|t| full[t] * s[halo + x + t - r]).sum())
                    .collect();
                let mut first: Option<Vec<f32>> = None;
                for simd in prism_cpu::each_isa() {
                    let mut out = vec![0.0; n];
                    correlate(simd, &s, halo, 1, folded, &mut out);
                    for (a, b) in out.iter().zip(&plain) {
                        assert!((a - b).abs() < 1e-5, "{ppd}: {a} {b}");
                    }
                    match &first {
                        None => first = Some(out),
                        Some(v) => assert_eq!(v, &out, "{simd}"),
                    }
                }
            }
        }
        let f = Filters::new(&Kernels::new(super::super::DEFAULT_PPD));
        assert_eq!((f.y.radius(), f.cx.radius(), f.cz1.radius()), (6, 6, 10));
        assert!(Folded::new(&[1.0, 2.0, 3.0]).is_none());
        assert!(Folded::new(&[1.0, 2.0]).is_none());
    }
}

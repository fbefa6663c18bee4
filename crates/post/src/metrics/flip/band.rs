//! LDR-FLIP of a pair of images, band by band: every band of rows is filtered with a halo
//! of source rows (clamped at the image edges, as the reference implementation's filters
//! are), so memory stays a few rows of planes per thread and the bands run in parallel.
//! Each source pixel goes through a transform first (a clip to [0, 1], or HDR-FLIP's tone
//! curve at one exposure), so tone-mapped copies of the images never exist.
//!
//! HDR-FLIP runs every exposure of a band before the next band, in the same buffers: the
//! band's planes are still in cache and nothing is allocated or cleared per exposure. The
//! exposures cannot share filtered planes: the tone curve comes before the (linear)
//! filters and is not linear, so each exposure is filtered from its own tone-mapped
//! pixels, as the reference implementation does.
//!
//! The filters run vertically first, on four planes per image (Yy, Cx, Cz and the grey
//! the feature detectors see), into padded rows; then horizontally, straight into the
//! per-pixel colour and feature terms of one output row. Every kernel is symmetric or
//! antisymmetric about its centre, so each pair of taps costs one multiply
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

/// Pixels summed at once in [`correlate`]: one AVX-512 register, two AVX2 ones.
const LANES: usize = 16;

/// Defines `$name(simd, args)`: `$body_fn(args)` compiled for the widest ISA `simd`
/// allows. The same operations run at every ISA (no fused multiply-adds), so the bits
/// are the same; `$body_fn` must be `#[inline(always)]`.
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
}

/// `out[x] = k[r] s[c + x] + Σₜ k[r + t] (s[c + x + t·stride] ± s[c + x − t·stride])`:
/// the correlation of `k` with `s` along rows (stride 1) or columns (stride = width).
/// Every pixel gets the same operations in the same order whatever its position or the
/// ISA (no fused multiply-adds), so strips and whole images agree bit for bit.
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
    while x + LANES <= n {
        let centre: &[f32; LANES] = s[c + x..c + x + LANES].try_into().unwrap();
        let mut acc = if ODD {
            [0.0; LANES]
        } else {
            centre.map(|v| k.centre * v)
        };
        for (t, &kt) in k.taps.iter().enumerate() {
            let d = (t + 1) * stride;
            let a: &[f32; LANES] = s[c + x + d..c + x + d + LANES].try_into().unwrap();
            let b: &[f32; LANES] = s[c + x - d..c + x - d + LANES].try_into().unwrap();
            for j in 0..LANES {
                acc[j] += kt * if ODD { a[j] - b[j] } else { a[j] + b[j] };
            }
        }
        out[x..x + LANES].copy_from_slice(&acc);
        x += LANES;
    }
    for (x, o) in out.iter_mut().enumerate().skip(x) {
        let mut acc = if ODD { 0.0 } else { k.centre * s[c + x] };
        for (t, &kt) in k.taps.iter().enumerate() {
            let d = (t + 1) * stride;
            let (a, b) = (s[c + x + d], s[c + x - d]);
            acc += kt * if ODD { a - b } else { a + b };
        }
        *o = acc;
    }
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
    while x + LANES <= n {
        let centre: &[f32; LANES] = s[c + x..c + x + LANES].try_into().unwrap();
        let mut acc = [[0.0f32; LANES]; N];
        for (a, k) in acc.iter_mut().zip(&ks) {
            if !k.antisymmetric {
                *a = centre.map(|v| k.centre * v);
            }
        }
        for t in 0..r {
            let d = (t + 1) * stride;
            let a: &[f32; LANES] = s[c + x + d..c + x + d + LANES].try_into().unwrap();
            let b: &[f32; LANES] = s[c + x - d..c + x - d + LANES].try_into().unwrap();
            let mut sum = [0.0f32; LANES];
            let mut diff = [0.0f32; LANES];
            for j in 0..LANES {
                sum[j] = a[j] + b[j];
                diff[j] = a[j] - b[j];
            }
            for (acc, k) in acc.iter_mut().zip(&ks) {
                let (kt, v) = (k.taps[t], if k.antisymmetric { &diff } else { &sum });
                for j in 0..LANES {
                    acc[j] += kt * v[j];
                }
            }
        }
        for (o, a) in outs.iter_mut().zip(&acc) {
            o[x..x + LANES].copy_from_slice(a);
        }
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
                acc += kt * if k.antisymmetric { a - b } else { a + b };
            }
            o[x] = acc;
        }
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
            y: fold(&k.y),
            cx: fold(&k.cx),
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

/// One image's buffers for a band: the transformed planes (Yy, Cx, Cz, grey; `band_h × w`
/// each), the vertically filtered rows padded by the halo (Yy, Cx, Cz twice, grey with the
/// Gaussian, d1 and d2) and the output row's Hunt-adjusted CIELAB, edge and point terms.
struct Side {
    planes: [Vec<f32>; 4],
    vertical: [Vec<f32>; 7],
    horizontal: [Vec<f32>; 8],
    lab: [Vec<f32>; 3],
    edge: Vec<f32>,
    point: Vec<f32>,
}

impl Side {
    fn new(w: usize, band_h: usize, halo: usize) -> Self {
        Self {
            planes: std::array::from_fn(|_| vec![0.0; band_h * w]),
            vertical: std::array::from_fn(|_| vec![0.0; w + 2 * halo]),
            horizontal: std::array::from_fn(|_| vec![0.0; w]),
            lab: std::array::from_fn(|_| vec![0.0; w]),
            edge: vec![0.0; w],
            point: vec![0.0; w],
        }
    }

    /// The planes of the band's `band_h` source rows from image row `y0 − halo` (clamped)
    /// after `transform`.
    #[allow(clippy::too_many_arguments)]
    fn fill_planes(
        &mut self,
        simd: Simd,
        image: Rows<'_>,
        (w, h): (usize, usize),
        y0: usize,
        halo: usize,
        transform: &impl Fn([f32; 3]) -> [f32; 3],
    ) {
        let [py, pcx, pcz, pg] = &mut self.planes;
        let rows = py
            .chunks_exact_mut(w)
            .zip(pcx.chunks_exact_mut(w))
            .zip(pcz.chunks_exact_mut(w).zip(pg.chunks_exact_mut(w)));
        for (j, ((ry, rcx), (rcz, rg))) in rows.enumerate() {
            let sy = (y0 + j).saturating_sub(halo).min(h - 1);
            let src = image.row(sy, w);
            planes_row(simd, src, transform, ry, rcx, rcz, rg);
        }
    }

    /// Lab, edge and point of band row `i` (plane row `i + halo`).
    fn filter_row(&mut self, simd: Simd, f: &Filters, w: usize, i: usize) {
        let halo = f.halo;
        let c = (i + halo) * w;
        let [py, pcx, pcz, pg] = &self.planes;
        let [vy, vcx, vcz1, vcz2, vg, vd1, vd2] = &mut self.vertical;
        let inner = halo..halo + w;
        correlate(simd, py, c, w, &f.y, &mut vy[inner.clone()]);
        correlate(simd, pcx, c, w, &f.cx, &mut vcx[inner.clone()]);
        correlate2(
            simd,
            pcz,
            c,
            w,
            [&f.cz1, &f.cz2],
            [&mut vcz1[inner.clone()], &mut vcz2[inner.clone()]],
        );
        correlate3(
            simd,
            pg,
            c,
            w,
            [&f.gauss, &f.d1, &f.d2],
            [
                &mut vg[inner.clone()],
                &mut vd1[inner.clone()],
                &mut vd2[inner],
            ],
        );
        for row in &mut self.vertical {
            // Clamp-to-edge padding commutes with the separable filter.
            let (left, right) = (row[halo], row[halo + w - 1]);
            row[..halo].fill(left);
            row[halo + w..].fill(right);
        }
        let [vy, vcx, vcz1, vcz2, vg, vd1, vd2] = &self.vertical;
        let [hy, hcx, hcz1, hcz2, ex, ey, px, py] = &mut self.horizontal;
        // Edges: ∂x = d1 ⊗ g, ∂y = g ⊗ d1; points likewise with d2.
        correlate(simd, vy, halo, 1, &f.y, hy);
        correlate(simd, vcx, halo, 1, &f.cx, hcx);
        correlate(simd, vcz1, halo, 1, &f.cz1, hcz1);
        correlate(simd, vcz2, halo, 1, &f.cz2, hcz2);
        correlate2(simd, vg, halo, 1, [&f.d1, &f.d2], [ex, px]);
        correlate(simd, vd1, halo, 1, &f.gauss, ey);
        correlate(simd, vd2, halo, 1, &f.gauss, py);
        let [l, a, b] = &mut self.lab;
        let (edge, point) = (&mut self.edge, &mut self.point);
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
    for x in 0..n {
        let de = pow_non_negative(hyab([rl[x], ra[x], rb[x]], [tl[x], ta[x], tb[x]]), QC);
        let colour = if de < pccmax {
            PT / pccmax * de
        } else {
            PT + (de - pccmax) / (cmax - pccmax) * (1.0 - PT)
        };
        let feature_diff = (re[x] - te[x]).abs().max((rp[x] - tp[x]).abs());
        // (feature_diff / √2)^q_f with q_f = ½.
        let feature = (feature_diff / std::f32::consts::SQRT_2).sqrt();
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
    out.par_chunks_mut(BAND_ROWS * w)
        .enumerate()
        .for_each(|(b, out)| {
            let y0 = first_row + b * BAND_ROWS;
            let rows = out.len() / w;
            let band_h = rows + 2 * f.halo;
            let mut r = Side::new(w, band_h, f.halo);
            let mut t = Side::new(w, band_h, f.halo);
            for (e, transform) in transforms.iter().enumerate() {
                r.fill_planes(simd, reference, (w, h), y0, f.halo, transform);
                t.fill_planes(simd, test, (w, h), y0, f.halo, transform);
                for (i, out) in out.chunks_exact_mut(w).enumerate() {
                    r.filter_row(simd, f, w, i);
                    t.filter_row(simd, f, w, i);
                    combine_row(simd, r.terms(), t.terms(), cmax, out, e > 0);
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
        assert!(Folded::new(&[1.0, 2.0, 3.0]).is_none());
        assert!(Folded::new(&[1.0, 2.0]).is_none());
    }
}

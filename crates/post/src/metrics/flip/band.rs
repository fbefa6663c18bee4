//! LDR-FLIP of a pair of images, band by band: every band of rows is filtered with a halo
//! of source rows (clamped at the image edges, as the reference implementation's filters
//! are), so memory stays a few rows of planes per thread and the bands run in parallel.
//! Each source pixel goes through a transform first (a clip to [0, 1], or HDR-FLIP's tone
//! curve at one exposure), so tone-mapped copies of the images never exist.

use rayon::prelude::*;

use super::colour::{filtered_to_hunt_lab, hyab, rgb_to_hunt_lab, rgb_to_ycxcz, ycxcz_grey};
use super::kernels::Kernels;
use super::Rows;

/// Colour error exponent q_c, redistribution break p_c and target p_t, feature exponent
/// q_f (Andersson et al. 2020, sec. 3).
const QC: f32 = 0.7;
const PC: f32 = 0.4;
const PT: f32 = 0.95;
const QF: f32 = 0.5;

/// Output rows per band: the halo (2 × 10 rows at 67 ppd) costs ~30 % more filtering.
pub(super) const BAND_ROWS: usize = 64;

/// The largest colour error: HyAB between Hunt-adjusted green and blue, to the power q_c.
fn c_max() -> f32 {
    hyab(
        rgb_to_hunt_lab([0.0, 1.0, 0.0]),
        rgb_to_hunt_lab([0.0, 0.0, 1.0]),
    )
    .powf(QC)
}

/// `out[x] = Σ_t k[t] · pad[x + offset + t]` over a row padded by `halo` on each side.
fn correlate_row(pad: &[f32], halo: usize, k: &[f32], out: &mut [f32]) {
    let offset = halo - k.len() / 2;
    out.fill(0.0);
    for (t, &kt) in k.iter().enumerate() {
        let src = &pad[offset + t..offset + t + out.len()];
        for (o, s) in out.iter_mut().zip(src) {
            *o += kt * s;
        }
    }
}

/// `out = Σ_t k[t] · plane row (centre − r + t)`, rows of width `out.len()`.
fn correlate_column(plane: &[f32], centre: usize, k: &[f32], out: &mut [f32]) {
    let w = out.len();
    let first = centre - k.len() / 2;
    out.fill(0.0);
    for (t, &kt) in k.iter().enumerate() {
        let src = &plane[(first + t) * w..(first + t + 1) * w];
        for (o, s) in out.iter_mut().zip(src) {
            *o += kt * s;
        }
    }
}

/// One image's share of a band: Hunt-adjusted CIELAB of the filtered colours and the
/// edge and point feature magnitudes, `rows × w` each.
struct BandSide {
    lab: Vec<[f32; 3]>,
    edge: Vec<f32>,
    point: Vec<f32>,
}

fn band_side(
    image: Rows<'_>,
    (w, h): (usize, usize),
    (y0, y1): (usize, usize),
    k: &Kernels,
    transform: &(impl Fn([f32; 3]) -> [f32; 3] + Sync),
) -> BandSide {
    let halo = k.spatial_radius_px.max(k.feature_radius_px);
    let rows = y1 - y0;
    let band_h = rows + 2 * halo;
    // Horizontal passes: spatial filters on Yy, Cx, Cz (two terms), feature filters on grey.
    let mut planes: [Vec<f32>; 7] = std::array::from_fn(|_| vec![0.0; band_h * w]);
    let mut pad: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; w + 2 * halo]);
    for j in 0..band_h {
        let sy = (y0 + j).saturating_sub(halo).min(h - 1);
        let row = image.row(sy, w);
        let [pad_y, pad_cx, pad_cz, pad_grey] = &mut pad;
        let pads = pad_y
            .iter_mut()
            .zip(pad_cx.iter_mut())
            .zip(pad_cz.iter_mut().zip(pad_grey.iter_mut()));
        for (i, ((y, cx), (cz, grey))) in pads.enumerate() {
            let sx = i.saturating_sub(halo).min(w - 1);
            [*y, *cx, *cz] = rgb_to_ycxcz(transform(row[sx]));
            *grey = ycxcz_grey(*y);
        }
        let [py, pcx, pcz1, pcz2, pg, pd1, pd2] = &mut planes;
        let r = j * w..(j + 1) * w;
        correlate_row(&pad[0], halo, &k.y, &mut py[r.clone()]);
        correlate_row(&pad[1], halo, &k.cx, &mut pcx[r.clone()]);
        correlate_row(&pad[2], halo, &k.cz1, &mut pcz1[r.clone()]);
        correlate_row(&pad[2], halo, &k.cz2, &mut pcz2[r.clone()]);
        correlate_row(&pad[3], halo, &k.gauss, &mut pg[r.clone()]);
        correlate_row(&pad[3], halo, &k.d1, &mut pd1[r.clone()]);
        correlate_row(&pad[3], halo, &k.d2, &mut pd2[r]);
    }
    // Vertical passes, a row at a time.
    let [py, pcx, pcz1, pcz2, pg, pd1, pd2] = &planes;
    let mut side = BandSide {
        lab: vec![[0.0; 3]; rows * w],
        edge: vec![0.0; rows * w],
        point: vec![0.0; rows * w],
    };
    let mut t: [Vec<f32>; 5] = std::array::from_fn(|_| vec![0.0; w]);
    let mut u = vec![0.0f32; w];
    for i in 0..rows {
        let centre = i + halo;
        correlate_column(py, centre, &k.y, &mut t[0]);
        correlate_column(pcx, centre, &k.cx, &mut t[1]);
        correlate_column(pcz1, centre, &k.cz1, &mut t[2]);
        correlate_column(pcz2, centre, &k.cz2, &mut u);
        for x in 0..w {
            side.lab[i * w + x] = filtered_to_hunt_lab([t[0][x], t[1][x], t[2][x] + u[x]]);
        }
        // Edges: ∂x = d1 ⊗ g, ∂y = g ⊗ d1; points likewise with d2.
        correlate_column(pd1, centre, &k.gauss, &mut t[0]);
        correlate_column(pg, centre, &k.d1, &mut t[1]);
        correlate_column(pd2, centre, &k.gauss, &mut t[2]);
        correlate_column(pg, centre, &k.d2, &mut t[3]);
        let row = i * w..(i + 1) * w;
        let outs = side.edge[row.clone()].iter_mut().zip(&mut side.point[row]);
        let ins = t[0].iter().zip(&t[1]).zip(t[2].iter().zip(&t[3]));
        for ((edge, point), ((ex, ey), (px, py))) in outs.zip(ins) {
            // Filter responses are O(1): plain sqrt, not hypot.
            *edge = (ex * ex + ey * ey).sqrt();
            *point = (px * px + py * py).sqrt();
        }
    }
    side
}

/// The LDR-FLIP map of `test` against `reference` (linear Rec.709, `w × h`, row-major)
/// after `transform`, for the image rows from `first_row` on that `out` covers, written
/// into `out` (one value per pixel) or, with `keep_max`, each value the larger of the old
/// and the new (HDR-FLIP's maximum over exposures). `test` and `reference` must hold the
/// rows of `out` and the filters' halo around them (clamped to the image).
#[allow(clippy::too_many_arguments)]
pub(super) fn flip_map_into(
    test: Rows<'_>,
    reference: Rows<'_>,
    (w, h): (usize, usize),
    first_row: usize,
    k: &Kernels,
    transform: &(impl Fn([f32; 3]) -> [f32; 3] + Sync),
    out: &mut [f32],
    keep_max: bool,
) {
    let cmax = c_max();
    let pccmax = PC * cmax;
    out.par_chunks_mut(BAND_ROWS * w)
        .enumerate()
        .for_each(|(b, out)| {
            let y0 = first_row + b * BAND_ROWS;
            let y1 = y0 + out.len() / w;
            let r = band_side(reference, (w, h), (y0, y1), k, transform);
            let t = band_side(test, (w, h), (y0, y1), k, transform);
            for (i, o) in out.iter_mut().enumerate() {
                let de = hyab(r.lab[i], t.lab[i]).powf(QC);
                let colour = if de < pccmax {
                    PT / pccmax * de
                } else {
                    PT + (de - pccmax) / (cmax - pccmax) * (1.0 - PT)
                };
                let feature_diff = (r.edge[i] - t.edge[i])
                    .abs()
                    .max((r.point[i] - t.point[i]).abs());
                let feature = (feature_diff / std::f32::consts::SQRT_2).powf(QF);
                let v = colour.powf(1.0 - feature);
                *o = if keep_max { o.max(v) } else { v };
            }
        });
}

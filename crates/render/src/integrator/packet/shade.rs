//! The arithmetic of one path vertex for all lanes at once: the light sample of a
//! rectangle emitter (or one the scalar `Light` code took), its MIS weight and shadow ray,
//! the cosine-weighted BSDF sample, the throughput and Russian roulette — each lane the
//! scalar path tracer's formulas (`integrator::path`, `light::area`, `bsdf::lambert`,
//! `sampling`), written without branches so that the lane loop becomes vector code.
//!
//! One deviation in bits: sin and cos of the concentric disk mapping come from the minimax
//! polynomials of Cephes' `sinf`/`cosf` on [−π/4, π/4] (≈ 1e-7 relative) instead of libm,
//! so a direction may differ from the scalar tracer's in its last bits.

// Lanes index several arrays at once: `for l in 0..N` is the clearest form.
#![allow(clippy::needless_range_loop)]

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4};

use prism_geometry::ray::SPAWN_T_MIN_REL;
use prism_scene::MisHeuristic;

/// How a lane's light sample is made.
pub(crate) const LIGHT_NONE: u8 = 0;
/// A rectangle emitter, sampled here.
pub(crate) const LIGHT_RECTANGLE: u8 = 1;
/// Sampled by the scalar `Light` code before: `given_*` hold the sample.
pub(crate) const LIGHT_GIVEN: u8 = 2;

/// What one vertex of each lane starts from (structure of arrays).
#[derive(Clone, Copy)]
pub(crate) struct VertexIn<const N: usize> {
    /// The lane has a vertex to shade.
    pub active: [bool; N],
    pub o: [[f32; N]; 3],
    pub d: [[f32; N]; 3],
    pub t: [f32; N],
    /// Shading frame x, y, z axes and the geometric normal.
    pub fx: [[f32; N]; 3],
    pub fy: [[f32; N]; 3],
    pub fz: [[f32; N]; 3],
    pub beta: [[f32; N]; 4],
    /// R(λ)/π of the Lambertian.
    pub f_lambert: [[f32; N]; 4],
    /// The chosen light's L(λ) at the lane's wavelengths.
    pub le: [[f32; N]; 4],
    pub u_light: [[f32; N]; 2],
    pub u_bsdf: [[f32; N]; 2],
    pub u_roulette: [f32; N],
    pub roulette: [bool; N],
    pub record_white: [bool; N],
    pub light_kind: [u8; N],
    /// Selection probability of the chosen light.
    pub pmf: [f32; N],
    /// Rectangle emitter: `to_world` columns and translation, half extents, normal, 1/area.
    pub rx: [[f32; N]; 3],
    pub ry: [[f32; N]; 3],
    pub rz: [[f32; N]; 3],
    pub rt: [[f32; N]; 3],
    pub half_w: [f32; N],
    pub half_h: [f32; N],
    pub rn: [[f32; N]; 3],
    pub inv_area: [f32; N],
    pub two_sided: [bool; N],
    /// A light sample taken by the scalar code (`LIGHT_GIVEN`).
    pub given_p: [[f32; N]; 3],
    pub given_wi: [[f32; N]; 3],
    pub given_pdf: [f32; N],
    pub given_distance: [f32; N],
    pub given_delta: [bool; N],
}

/// What the vertex gives (structure of arrays).
#[derive(Clone, Copy)]
pub(crate) struct VertexOut<const N: usize> {
    pub p: [[f32; N]; 3],
    /// A shadow ray to trace, with the light it brings if unblocked (f·L·w/p, before β).
    pub has_shadow: [bool; N],
    pub shadow_d: [[f32; N]; 3],
    pub shadow_t_min: [f32; N],
    pub shadow_t_max: [f32; N],
    pub direct: [[f32; N]; 4],
    pub white: [[f32; N]; 4],
    /// The path goes on along `next_d` (unit) from `p`.
    pub continues: [bool; N],
    pub next_d: [[f32; N]; 3],
    pub next_t_min: [f32; N],
    pub weight: [[f32; N]; 4],
    pub pdf: [f32; N],
    pub wi_z: [f32; N],
    pub beta: [[f32; N]; 4],
    pub weight_non_finite: [bool; N],
    pub killed_by_roulette: [bool; N],
}

impl<const N: usize> VertexIn<N> {
    pub fn new() -> Self {
        let z = [0.0f32; N];
        Self {
            active: [false; N],
            o: [z; 3],
            d: [z; 3],
            t: z,
            fx: [z; 3],
            fy: [z; 3],
            fz: [z; 3],
            beta: [z; 4],
            f_lambert: [z; 4],
            le: [z; 4],
            u_light: [z; 2],
            u_bsdf: [z; 2],
            u_roulette: z,
            roulette: [false; N],
            record_white: [false; N],
            light_kind: [LIGHT_NONE; N],
            pmf: z,
            rx: [z; 3],
            ry: [z; 3],
            rz: [z; 3],
            rt: [z; 3],
            half_w: z,
            half_h: z,
            rn: [z; 3],
            inv_area: z,
            two_sided: [false; N],
            given_p: [z; 3],
            given_wi: [z; 3],
            given_pdf: z,
            given_distance: z,
            given_delta: [false; N],
        }
    }
}

impl<const N: usize> VertexOut<N> {
    pub fn new() -> Self {
        let z = [0.0f32; N];
        Self {
            p: [z; 3],
            has_shadow: [false; N],
            shadow_d: [z; 3],
            shadow_t_min: z,
            shadow_t_max: z,
            direct: [z; 4],
            white: [z; 4],
            continues: [false; N],
            next_d: [z; 3],
            next_t_min: z,
            weight: [z; 4],
            pdf: z,
            wi_z: z,
            beta: [z; 4],
            weight_non_finite: [false; N],
            killed_by_roulette: [false; N],
        }
    }
}

/// `if c { a } else { b }`, a vector select in the lane loops.
#[inline(always)]
pub(super) fn select(c: bool, a: f32, b: f32) -> f32 {
    if c {
        a
    } else {
        b
    }
}

/// `Ray::spawn`'s offset for a ray from `o` along `d` (`geometry::ray::spawn_t_min`).
#[inline(always)]
fn spawn_t_min(o: [f32; 3], d: [f32; 3]) -> f32 {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let extent = o[0].abs().max(o[1].abs()).max(o[2].abs());
    select(len > 0.0, SPAWN_T_MIN_REL * (1.0 + extent) / len, 0.0)
}

/// sin and cos on [−π/4, π/4] (Cephes `sinf`/`cosf` minimax polynomials).
#[inline(always)]
fn sin_cos_quarter(a: f32) -> (f32, f32) {
    let z = a * a;
    let s = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * a + a;
    let c = (((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z) + 1.0;
    (s, c)
}

#[inline(always)]
fn mis(heuristic: MisHeuristic, a: f32, b: f32) -> f32 {
    match heuristic {
        MisHeuristic::Balance => select(a + b > 0.0, a / (a + b), 0.0),
        MisHeuristic::Power => {
            let (a2, b2) = (a * a, b * b);
            select(a2 + b2 > 0.0, a2 / (a2 + b2), 0.0)
        }
    }
}

/// Shades every active lane of `v` into `out`.
#[inline(always)]
pub(crate) fn shade<const N: usize>(
    v: &VertexIn<N>,
    heuristic: MisHeuristic,
    out: &mut VertexOut<N>,
) {
    for l in 0..N {
        let d = [v.d[0][l], v.d[1][l], v.d[2][l]];
        let t = v.t[l];
        let p = [
            v.o[0][l] + t * d[0],
            v.o[1][l] + t * d[1],
            v.o[2][l] + t * d[2],
        ];
        let fx = [v.fx[0][l], v.fx[1][l], v.fx[2][l]];
        let fy = [v.fy[0][l], v.fy[1][l], v.fy[2][l]];
        let fz = [v.fz[0][l], v.fz[1][l], v.fz[2][l]];
        let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let wo = [-d[0], -d[1], -d[2]];
        let wo_z = dot(wo, fz);
        let upper_wo = wo_z > 0.0;
        let fl = [
            v.f_lambert[0][l],
            v.f_lambert[1][l],
            v.f_lambert[2][l],
            v.f_lambert[3][l],
        ];
        let beta = [v.beta[0][l], v.beta[1][l], v.beta[2][l], v.beta[3][l]];
        let le = [v.le[0][l], v.le[1][l], v.le[2][l], v.le[3][l]];

        // Light sample: a rectangle emitter's uniform point (`RectangleEmitter::sample`,
        // `AreaLight::sample_li_with`), or the one given.
        let rect = v.light_kind[l] == LIGHT_RECTANGLE;
        let lx = (2.0 * v.u_light[0][l] - 1.0) * v.half_w[l];
        let ly = (2.0 * v.u_light[1][l] - 1.0) * v.half_h[l];
        let mut p_light = [0.0f32; 3];
        for a in 0..3 {
            // `Affine3A::transform_point3a`: x·X + y·Y + 0·Z, then + translation.
            let rect_p = ((v.rx[a][l] * lx + v.ry[a][l] * ly) + v.rz[a][l] * 0.0) + v.rt[a][l];
            p_light[a] = select(rect, rect_p, v.given_p[a][l]);
        }
        let to = [p_light[0] - p[0], p_light[1] - p[1], p_light[2] - p[2]];
        let d2 = dot(to, to);
        let dist = d2.sqrt();
        let rn = [v.rn[0][l], v.rn[1][l], v.rn[2][l]];
        // `area_to_solid_angle`.
        let cos_light = dot(rn, to).abs() / d2.sqrt();
        let pdf_area = v.inv_area[l] * d2 / cos_light;
        let pdf_rect = select(
            d2 > 0.0 && cos_light > 0.0 && pdf_area.is_finite(),
            pdf_area,
            0.0,
        );
        let rect_valid =
            dist > 0.0 && dist < f32::INFINITY && pdf_rect > 0.0 && pdf_rect < f32::INFINITY;
        let rect_wi = [to[0] / dist, to[1] / dist, to[2] / dist];
        // `AreaLight::emits_towards(n, −wi)`.
        let cos_emit = dot(rn, [-rect_wi[0], -rect_wi[1], -rect_wi[2]]);
        let emits = (v.two_sided[l] & (cos_emit != 0.0)) | (!v.two_sided[l] & (cos_emit > 0.0));
        let wi = [
            select(rect, rect_wi[0], v.given_wi[0][l]),
            select(rect, rect_wi[1], v.given_wi[1][l]),
            select(rect, rect_wi[2], v.given_wi[2][l]),
        ];
        let light_pdf_sa = select(rect, pdf_rect, v.given_pdf[l]);
        let distance = select(rect, dist, v.given_distance[l]);
        let delta = !rect && v.given_delta[l];
        let sampled = match v.light_kind[l] {
            LIGHT_RECTANGLE => rect_valid && emits,
            LIGHT_GIVEN => true,
            _ => false,
        };
        let le_black = (le[0] == 0.0) & (le[1] == 0.0) & (le[2] == 0.0) & (le[3] == 0.0);
        let wi_z = dot(wi, fz);
        let upper = upper_wo && wi_z > 0.0;
        let cos_abs = wi_z.abs();
        let f = fl.map(|x| select(upper, x, 0.0) * cos_abs);
        let white_cos = select(v.record_white[l], wi_z.max(0.0) * FRAC_1_PI, 0.0);
        let f_black = (f[0] == 0.0) & (f[1] == 0.0) & (f[2] == 0.0) & (f[3] == 0.0);
        let has_shadow = v.active[l]
            && sampled
            && light_pdf_sa > 0.0
            && !le_black
            && !(f_black && white_cos <= 0.0);
        let light_pdf = v.pmf[l] * light_pdf_sa;
        let bsdf_pdf = select(upper, wi_z * FRAC_1_PI, 0.0);
        let w = select(delta, 1.0, mis(heuristic, light_pdf, bsdf_pdf));
        let scale = w / light_pdf;
        let white_scale = white_cos / light_pdf;
        for k in 0..4 {
            out.direct[k][l] = f[k] * le[k] * scale;
            out.white[k][l] = le[k] * white_scale;
        }
        // `Ray::spawn_to(p, p_light)`, or `Ray::spawn(p, wi)` towards an infinite light.
        let finite = distance.is_finite();
        let to_eps = spawn_t_min(p, to).max(spawn_t_min(p_light, to));
        for a in 0..3 {
            out.shadow_d[a][l] = select(finite, to[a], wi[a]);
        }
        out.shadow_t_min[l] = select(finite, to_eps, spawn_t_min(p, wi));
        out.shadow_t_max[l] = select(finite, 1.0 - to_eps, f32::INFINITY);
        out.has_shadow[l] = has_shadow;

        // BSDF sample: Malley's method on the concentric disk (`sample_cosine_hemisphere`).
        let ox = 2.0 * v.u_bsdf[0][l] - 1.0;
        let oy = 2.0 * v.u_bsdf[1][l] - 1.0;
        let centre = ox == 0.0 && oy == 0.0;
        let wide = ox.abs() > oy.abs();
        let r = select(wide, ox, oy);
        let a = FRAC_PI_4 * select(wide, oy / ox, ox / oy);
        let (s, c) = sin_cos_quarter(a);
        // θ = a, or π/2 − a: cos and sin swap.
        let (cos_t, sin_t) = (select(wide, c, s), select(wide, s, c));
        let x = select(centre, 0.0, r * cos_t);
        let y = select(centre, 0.0, r * sin_t);
        let z = (1.0 - (x * x + y * y)).max(0.0).sqrt();
        let pdf = select(z > 0.0, z * FRAC_1_PI, 0.0);
        let sample_ok = upper_wo && z > 0.0 && pdf > 0.0;
        let weight = fl.map(|x| x * (z.abs() / pdf));
        let weight_black =
            (weight[0] == 0.0) & (weight[1] == 0.0) & (weight[2] == 0.0) & (weight[3] == 0.0);
        let weight_non_finite = !(weight[0].is_finite()
            & weight[1].is_finite()
            & weight[2].is_finite()
            & weight[3].is_finite());
        let wi_world = [
            fx[0] * x + fy[0] * y + fz[0] * z,
            fx[1] * x + fy[1] * y + fz[1] * z,
            fx[2] * x + fy[2] * y + fz[2] * z,
        ];
        // glam `normalize`: v · (1/|v|).
        let inv_len = 1.0 / dot(wi_world, wi_world).sqrt();
        let next_d = wi_world.map(|c| c * inv_len);
        let mut beta_new = [0.0f32; 4];
        for k in 0..4 {
            beta_new[k] = beta[k] * weight[k];
        }
        let q = (1.0
            - beta_new[0]
                .max(beta_new[1])
                .max(beta_new[2].max(beta_new[3])))
        .max(0.0);
        let killed = v.roulette[l] && v.u_roulette[l] < q;
        let survive = 1.0 / (1.0 - q);
        for k in 0..4 {
            out.beta[k][l] = select(v.roulette[l], beta_new[k] * survive, beta_new[k]);
            out.weight[k][l] = weight[k];
        }
        let goes_on = sample_ok && !weight_black && !weight_non_finite;
        out.continues[l] = v.active[l] && goes_on && !killed;
        out.killed_by_roulette[l] = v.active[l] && goes_on && killed;
        out.weight_non_finite[l] = v.active[l] && sample_ok && weight_non_finite;
        for a in 0..3 {
            out.p[a][l] = p[a];
            out.next_d[a][l] = next_d[a];
        }
        out.next_t_min[l] = spawn_t_min(p, next_d);
        out.pdf[l] = pdf;
        out.wi_z[l] = z;
    }
}

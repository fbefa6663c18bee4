//! CIELAB and CIEDE2000 for the per-pixel comparison kernel ([`super::prepared`]): the
//! same quantities as prism-spectrum's [`xyz_to_lab`](prism_spectrum::colorimetry::xyz_to_lab)
//! and [`delta_e_2000`](prism_spectrum::colorimetry::delta_e_2000) (the reference
//! implementation, which follows Sharma, Wu & Dalal 2005 step by step), rewritten so that a
//! block of pixels runs in loops the compiler vectorises: no library calls (six cube roots,
//! two atan2, six sines/cosines, an exp and four hypot per pair in the reference) and no
//! branches, only selects:
//!
//! - the cube root of CIELAB's f(t) (CIE 15:2018 eq. 8.5), atan2, exp and sin are the
//!   branch-free versions of [`super::fast_f64`] (≤ 2–4 ulp against the standard library);
//! - the hue terms use unit vectors instead of angles. With u = (a′, b)/C′ per colour:
//!   Δh′ has the sign of u₁ × u₂ and |2 sin(Δh′/2)| = |u₂ − u₁| (the chord), so
//!   ΔH′ = 2 √(C′₁C′₂) sin(Δh′/2) (Sharma eq. 11) = sign(u₁ × u₂) √(C′₁C′₂) |u₂ − u₁|;
//!   the mean hue h̄′ of eq. 14 (the mid-point of the shorter arc, with its ±360° rules) is
//!   the direction of u₁ + u₂, so cos h̄′ and sin h̄′ are its components and T (eq. 15)
//!   follows from the multiple-angle identities; only Δθ (eq. 16, a Gaussian in h̄′ − 275°
//!   with h̄′ in [0°, 360°)) needs the angle itself, one atan2;
//! - Sharma's edge cases hold: h′ = 0 and ΔH′ = 0 when a chroma is zero (then h̄′ is the
//!   other colour's hue, or 0° if both are zero); the one configuration the vector form
//!   does not decide — hues exactly 180° apart, where CIEDE2000 itself is discontinuous —
//!   goes to the reference implementation.
//!
//! Tested against the reference implementation on random and near-equal pairs and against
//! Sharma et al.'s table (the fixture of prism-spectrum's test).

use glam::{DMat3, DVec3};
use prism_spectrum::colorimetry::{LAB_EPSILON, LAB_KAPPA};

use super::fast_f64::{atan2_deg, cbrt, exp, sin_small};

/// Pixels per block of the vectorised loops ([`lab_block`], [`delta_e_2000_block`]).
pub const BLOCK: usize = 64;

/// 25⁷ (Sharma eqs. 4 and 21).
const POW25_7: f64 = 6_103_515_625.0;

/// CIELAB's f(t) (CIE 15:2018 eq. 8.5): ∛t above ε, the linear segment below.
#[inline(always)]
fn lab_f(t: f64) -> f64 {
    // Both branches computed, then selected (vectorisable); cbrt's argument kept > ε.
    let root = cbrt(t.max(LAB_EPSILON));
    let linear = (LAB_KAPPA * t + 16.0) / 116.0;
    if t > LAB_EPSILON {
        root
    } else {
        linear
    }
}

/// Linear RGB → CIELAB of one colour space (the white's Y = 1, so RGB (1, 1, 1) has
/// L* = 100, like [`crate::colour::cielab_lch::CielabConverter`]).
#[derive(Debug, Clone, Copy)]
pub struct LabConverter {
    /// RGB → XYZ with row i divided by the white's component i (XYZ / white in one step).
    rgb_to_xyz_over_white: DMat3,
}

impl LabConverter {
    pub fn new(rgb_to_xyz: DMat3, white_xyz: DVec3) -> Self {
        let inv = DVec3::ONE / white_xyz;
        Self {
            // Column-major: scaling each column by inv scales row i by inv[i].
            rgb_to_xyz_over_white: DMat3::from_cols(
                rgb_to_xyz.x_axis * inv,
                rgb_to_xyz.y_axis * inv,
                rgb_to_xyz.z_axis * inv,
            ),
        }
    }

    /// [L*, a*, b*] of an RGB triple (CIE 15:2018 eqs. 8.1–8.5).
    #[inline(always)]
    pub fn lab(&self, rgb: [f32; 3]) -> [f64; 3] {
        let t = self.rgb_to_xyz_over_white
            * DVec3::new(f64::from(rgb[0]), f64::from(rgb[1]), f64::from(rgb[2]));
        let (fx, fy, fz) = (lab_f(t.x), lab_f(t.y), lab_f(t.z));
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }
}

/// One block of colours in planes (structure of arrays), the layout the vectorised loops
/// read: L*, a*, b*, C*ab.
#[derive(Clone, Copy, Debug)]
pub struct LabBlock {
    pub l: [f64; BLOCK],
    pub a: [f64; BLOCK],
    pub b: [f64; BLOCK],
    pub c: [f64; BLOCK],
}

impl Default for LabBlock {
    fn default() -> Self {
        Self {
            l: [0.0; BLOCK],
            a: [0.0; BLOCK],
            b: [0.0; BLOCK],
            c: [0.0; BLOCK],
        }
    }
}

/// CIELAB (with chroma) of a block of sanitised RGB pixels given as planes.
// Indexing all planes by one lane index is the form the loop vectoriser recognises.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub fn lab_block(conv: &LabConverter, rgb: &[[f64; BLOCK]; 3], out: &mut LabBlock) {
    let m = conv.rgb_to_xyz_over_white.to_cols_array();
    for i in 0..BLOCK {
        let (r, g, b) = (rgb[0][i], rgb[1][i], rgb[2][i]);
        // Column-major m: row k is (m[k], m[3 + k], m[6 + k]); the same sums as DMat3 * DVec3.
        let tx = m[0] * r + m[3] * g + m[6] * b;
        let ty = m[1] * r + m[4] * g + m[7] * b;
        let tz = m[2] * r + m[5] * g + m[8] * b;
        let (fx, fy, fz) = (lab_f(tx), lab_f(ty), lab_f(tz));
        let (a, bb) = (500.0 * (fx - fy), 200.0 * (fy - fz));
        out.l[i] = 116.0 * fy - 16.0;
        out.a[i] = a;
        out.b[i] = bb;
        out.c[i] = (a * a + bb * bb).sqrt();
    }
}

/// ΔE₀₀ of a block of colour pairs (the first `len` lanes); each lane as
/// [`delta_e_2000`], the rare reference-implementation lanes (hues exactly 180° apart)
/// patched after the vectorised loop.
#[inline(always)]
pub fn delta_e_2000_block(p: &LabBlock, q: &LabBlock, len: usize, out: &mut [f64; BLOCK]) {
    let mut fallback = [false; BLOCK];
    for i in 0..BLOCK {
        let (de, ok) = delta_e_2000_lane(
            LabC {
                l: p.l[i],
                a: p.a[i],
                b: p.b[i],
                c: p.c[i],
            },
            LabC {
                l: q.l[i],
                a: q.a[i],
                b: q.b[i],
                c: q.c[i],
            },
        );
        out[i] = de;
        fallback[i] = !ok;
    }
    for i in 0..len {
        if fallback[i] {
            out[i] = prism_spectrum::colorimetry::delta_e_2000(
                DVec3::new(p.l[i], p.a[i], p.b[i]),
                DVec3::new(q.l[i], q.a[i], q.b[i]),
            );
        }
    }
}

/// A colour prepared for CIEDE2000: L*, a*, b* and C*ab = √(a*² + b*²) (computed once for
/// a reference pixel that is compared many times).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LabC {
    pub l: f64,
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl LabC {
    #[inline(always)]
    pub fn new(lab: [f64; 3]) -> Self {
        Self {
            l: lab[0],
            a: lab[1],
            b: lab[2],
            c: (lab[1] * lab[1] + lab[2] * lab[2]).sqrt(),
        }
    }
}

/// ΔE₀₀ of one pair without branches (selects only, so that a loop of it vectorises), and
/// `false` for hues exactly 180° apart, where the value is not CIEDE2000's and the caller
/// must use the reference implementation.
#[inline(always)]
pub fn delta_e_2000_lane(p: LabC, q: LabC) -> (f64, bool) {
    // Eqs. 2–7: a′ rescaling and C′.
    let c_bar = 0.5 * (p.c + q.c);
    let c_bar2 = c_bar * c_bar;
    let c_bar7 = c_bar2 * c_bar2 * c_bar2 * c_bar;
    let g1 = 1.0 + 0.5 * (1.0 - (c_bar7 / (c_bar7 + POW25_7)).sqrt());
    let (a1, a2) = (g1 * p.a, g1 * q.a);
    let (b1, b2) = (p.b, q.b);
    let c1 = (a1 * a1 + b1 * b1).sqrt();
    let c2 = (a2 * a2 + b2 * b2).sqrt();
    // Unit hue vectors (zero for a zero chroma: Sharma's h′ = 0 case).
    let inv1 = if c1 > 0.0 { 1.0 / c1 } else { 0.0 };
    let inv2 = if c2 > 0.0 { 1.0 / c2 } else { 0.0 };
    let (u1x, u1y) = (a1 * inv1, b1 * inv1);
    let (u2x, u2y) = (a2 * inv2, b2 * inv2);
    let cross = a1 * b2 - b1 * a2;
    let dot = a1 * a2 + b1 * b2;
    let product = c1 * c2;
    let ok = !(product != 0.0 && cross == 0.0 && dot < 0.0);

    // Eqs. 8–11: ΔL′, ΔC′, ΔH′ (chord form; √(C′₁C′₂) = 0 gives ΔH′ = 0 when a chroma is 0).
    let dl = q.l - p.l;
    let dc = c2 - c1;
    let (chord_x, chord_y) = (u2x - u1x, u2y - u1y);
    let chord = (chord_x * chord_x + chord_y * chord_y).sqrt();
    let sign = if cross > 0.0 {
        1.0
    } else if cross < 0.0 {
        -1.0
    } else {
        0.0
    };
    let d_big_h = sign * product.sqrt() * chord;

    // Eqs. 12–14: means; h̄′ is the direction of u₁ + u₂ (0° when both chromas are 0).
    let l_bar = 0.5 * (p.l + q.l);
    let cp_bar = 0.5 * (c1 + c2);
    let (wx, wy) = (u1x + u2x, u1y + u2y);
    let wx = if wx == 0.0 && wy == 0.0 { 1.0 } else { wx };
    let inv_w = 1.0 / (wx * wx + wy * wy).sqrt();
    let (ch, sh) = (wx * inv_w, wy * inv_w);
    let h_bar_deg = atan2_deg(wy, wx);

    // Eq. 15: T from cos/sin of h̄′ by the double- and triple-angle identities.
    const COS30: f64 = 0.866_025_403_784_438_6; // cos 30°
    const SIN30: f64 = 0.5;
    const COS6: f64 = 0.994_521_895_368_273_3; // cos 6°
    const SIN6: f64 = 0.104_528_463_267_653_47; // sin 6°
    const COS63: f64 = 0.453_990_499_739_546_8; // cos 63°
    const SIN63: f64 = 0.891_006_524_188_367_9; // sin 63°
    let c2h = ch * ch - sh * sh;
    let s2h = 2.0 * sh * ch;
    let c3h = ch * c2h - sh * s2h;
    let s3h = sh * c2h + ch * s2h;
    let c4h = c2h * c2h - s2h * s2h;
    let s4h = 2.0 * s2h * c2h;
    let t = 1.0 - 0.17 * (ch * COS30 + sh * SIN30) + 0.24 * c2h + 0.32 * (c3h * COS6 - s3h * SIN6)
        - 0.20 * (c4h * COS63 + s4h * SIN63);

    // Eqs. 16–22.
    let z = (h_bar_deg - 275.0) / 25.0;
    let d_theta_deg = 30.0 * exp(-(z * z));
    let cp_bar2 = cp_bar * cp_bar;
    let cp_bar7 = cp_bar2 * cp_bar2 * cp_bar2 * cp_bar;
    let r_c = 2.0 * (cp_bar7 / (cp_bar7 + POW25_7)).sqrt();
    let l50 = (l_bar - 50.0) * (l_bar - 50.0);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * cp_bar;
    let s_h = 1.0 + 0.015 * cp_bar * t;
    // 2Δθ ≤ 60°: within sin_small's range.
    let r_t = -sin_small((2.0 * d_theta_deg).to_radians()) * r_c;

    // Eq. 23 (kL = kC = kH = 1).
    let tl = dl / s_l;
    let tc = dc / s_c;
    let th = d_big_h / s_h;
    (
        (tl * tl + tc * tc + th * th + r_t * tc * th)
            .max(0.0)
            .sqrt(),
        ok,
    )
}

/// ΔE₀₀ of two prepared colours: [`delta_e_2000_lane`], or the reference implementation
/// for hues exactly 180° apart.
#[inline(always)]
pub fn delta_e_2000(p: LabC, q: LabC) -> f64 {
    match delta_e_2000_lane(p, q) {
        (de, true) => de,
        _ => prism_spectrum::colorimetry::delta_e_2000(
            DVec3::new(p.l, p.a, p.b),
            DVec3::new(q.l, q.a, q.b),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_spectrum::colorimetry::{delta_e_2000 as reference, xyz_to_lab};
    use prism_spectrum::rgb_space::RgbColorSpace;

    /// A small deterministic generator (SplitMix64) for test inputs.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn lab_matches_the_reference_conversion() {
        let space = RgbColorSpace::srgb();
        let conv = LabConverter::new(space.rgb_to_xyz, space.white_xyz());
        let mut rng = Rng(11);
        for _ in 0..50_000 {
            let rgb = [0, 1, 2].map(|_| (10f64.powf(-6.0 + 9.0 * rng.next())) as f32);
            let xyz = space.rgb_to_xyz * DVec3::new(rgb[0] as f64, rgb[1] as f64, rgb[2] as f64);
            let want = xyz_to_lab(xyz, space.white_xyz());
            let got = conv.lab(rgb);
            // The only differences are the rounding of XYZ/white (one division folded into
            // the matrix) and of the cube root: a few ulp of the f values (~1e-16 · 500).
            for (g, w) in got.iter().zip(want.to_array()) {
                assert!(
                    (g - w).abs() <= 1e-12 * w.abs().max(1.0),
                    "{rgb:?}: {got:?} vs {want}"
                );
            }
        }
    }

    fn check(p: [f64; 3], q: [f64; 3]) -> f64 {
        let got = delta_e_2000(LabC::new(p), LabC::new(q));
        let want = reference(DVec3::from(p), DVec3::from(q));
        let err = (got - want).abs();
        // Different rounding of the same formula: ~1e-14 absolute; the bound leaves room
        // for the hue terms' conditioning at tiny chroma.
        assert!(err <= 1e-10 * want.max(1.0), "{p:?} {q:?}: {got} vs {want}");
        err
    }

    #[test]
    fn delta_e_2000_matches_the_reference_on_random_and_close_pairs() {
        let mut rng = Rng(3);
        let mut worst = 0.0f64;
        let lab = |rng: &mut Rng, scale: f64| {
            [
                100.0 * rng.next(),
                scale * (2.0 * rng.next() - 1.0),
                scale * (2.0 * rng.next() - 1.0),
            ]
        };
        for i in 0..200_000 {
            let scale = [128.0, 10.0, 1.0, 1e-3][i % 4];
            let p = lab(&mut rng, scale);
            let q = if i % 2 == 0 {
                lab(&mut rng, scale)
            } else {
                // Close pairs: the regime of a converging render.
                let d = 10f64.powf(-6.0 + 6.0 * rng.next());
                [0, 1, 2].map(|k| p[k] + d * (2.0 * rng.next() - 1.0))
            };
            worst = worst.max(check(p, q));
        }
        // Special hues: zero chromas, the axes, hue mean at 0°/360°, near 275°, mirror pairs.
        let specials = [
            ([50.0, 0.0, 0.0], [50.0, 0.0, 0.0]),
            ([50.0, 0.0, 0.0], [60.0, 0.0, 0.0]),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0]),
            ([50.0, 3.0, 0.0], [50.0, 5.0, 0.0]),
            ([50.0, 3.0, 1.0], [50.0, 3.0, -1.0]),
            ([50.0, 3.0, 1e-9], [55.0, 3.0, -1e-9]),
            ([40.0, 0.5, -5.0], [42.0, 0.8, -6.0]),
            ([50.0, 2.5, 0.0], [50.0, 0.0, -2.5]),
            ([50.0, -2.0, 1.0], [50.0, 2.0, -1.0]), // exactly opposite: reference path
        ];
        for (p, q) in specials {
            worst = worst.max(check(p, q)).max(check(q, p));
        }
        assert_eq!(
            delta_e_2000(LabC::new([50.0, 3.0, 4.0]), LabC::new([50.0, 3.0, 4.0])),
            0.0
        );
        println!("worst |ΔE00 - reference| {worst:.2e}");
    }

    #[test]
    fn the_block_form_equals_the_pair_form_lane_by_lane() {
        // Blocks mixing random pairs, zero chromas and exactly opposite hues (the lanes
        // patched with the reference implementation), with a short last block.
        let mut rng = Rng(5);
        for len in [BLOCK, 17] {
            let (mut p, mut q) = (LabBlock::default(), LabBlock::default());
            let mut pairs = Vec::new();
            for i in 0..BLOCK {
                let a = [
                    100.0 * rng.next(),
                    80.0 * rng.next() - 40.0,
                    80.0 * rng.next() - 40.0,
                ];
                let b = match i % 4 {
                    0 => [a[0], -a[1], -a[2]],   // opposite hue
                    1 => [a[0] + 1.0, 0.0, 0.0], // zero chroma
                    _ => [a[0] + rng.next(), a[1] + rng.next(), a[2] - rng.next()],
                };
                for (block, lab) in [(&mut p, a), (&mut q, b)] {
                    let c = LabC::new(lab);
                    (block.l[i], block.a[i], block.b[i], block.c[i]) = (c.l, c.a, c.b, c.c);
                }
                pairs.push((a, b));
            }
            let mut out = [f64::NAN; BLOCK];
            delta_e_2000_block(&p, &q, len, &mut out);
            for (i, (a, b)) in pairs.iter().enumerate().take(len) {
                assert_eq!(
                    out[i],
                    delta_e_2000(LabC::new(*a), LabC::new(*b)),
                    "lane {i}"
                );
                check(*a, *b);
            }
        }
    }

    #[test]
    fn delta_e_2000_matches_sharma_2005() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/fixtures/ciede2000.json"
        ))
        .unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let pairs = v["data"]["pairs"].as_array().unwrap();
        assert_eq!(pairs.len(), 34);
        for p in pairs {
            let lab = |k: &str| -> [f64; 3] { [0, 1, 2].map(|i| p[k][i].as_f64().unwrap()) };
            let de = delta_e_2000(LabC::new(lab("lab1")), LabC::new(lab("lab2")));
            let paper = p["delta_e00_published"].as_f64().unwrap();
            assert!(
                (de - paper).abs() < 1e-4,
                "pair {}: {de} vs {paper}",
                p["pair"]
            );
            check(lab("lab1"), lab("lab2"));
        }
    }
}

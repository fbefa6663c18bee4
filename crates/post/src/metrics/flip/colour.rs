//! FLIP's colour spaces (Andersson et al. 2020, sec. 3.1): linear Rec.709 RGB → XYZ (the
//! exact sRGB/D65 matrix the reference implementation uses) → the opponent space YyCxCz
//! (Johnson & Fairchild) where the contrast sensitivity filters run, and back → CIELAB
//! with the Hunt adjustment, compared with the HyAB distance.

/// Linear Rec.709 → XYZ (rational entries, Y of white = 1).
const RGB_TO_XYZ: [[f32; 3]; 3] = [
    [
        10135552.0 / 24577794.0,
        8788810.0 / 24577794.0,
        4435075.0 / 24577794.0,
    ],
    [
        2613072.0 / 12288897.0,
        8788810.0 / 12288897.0,
        887015.0 / 12288897.0,
    ],
    [
        1425312.0 / 73733382.0,
        8788810.0 / 73733382.0,
        70074185.0 / 73733382.0,
    ],
];

/// XYZ → linear Rec.709 (the inverse of [`RGB_TO_XYZ`] as the reference prints it).
const XYZ_TO_RGB: [[f32; 3]; 3] = [
    [3.241_003_2, -1.537_399, -0.498_615_9],
    [-0.969_224_3, 1.875_93, 0.041_554_226],
    [0.055_639_42, -0.204_011_2, 1.057_149],
];

/// The white (RGB (1, 1, 1)) in XYZ: the reference white of YyCxCz and CIELAB.
const WHITE_XYZ: [f32; 3] = [23359437.0 / 24577794.0, 1.0, 80288307.0 / 73733382.0];

/// `[f(v₀), f(v₁), f(v₂)]`, always inlined (`<[T; 3]>::map` may not be, which keeps the
/// per-pixel loops that call it from being vectorised).
#[inline(always)]
pub(super) fn map3<T: Copy, U>(v: [T; 3], f: impl Fn(T) -> U) -> [U; 3] {
    [f(v[0]), f(v[1]), f(v[2])]
}

#[inline(always)]
fn mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    map3([0, 1, 2], |r| {
        m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2]
    })
}

/// Linear RGB → YyCxCz: Yy = 116 Y/Yn − 16, Cx = 500 (X/Xn − Y/Yn), Cz = 200 (Y/Yn − Z/Zn).
#[inline(always)]
pub(super) fn rgb_to_ycxcz(rgb: [f32; 3]) -> [f32; 3] {
    let xyz = mul(&RGB_TO_XYZ, rgb);
    let [x, y, z] = map3([0, 1, 2], |c| xyz[c] / WHITE_XYZ[c]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// The achromatic channel of YyCxCz on [0, 1] (Y / Yn): what the feature detectors see.
#[inline(always)]
pub(super) fn ycxcz_grey(yy: f32) -> f32 {
    (yy + 16.0) / 116.0
}

#[inline(always)]
fn ycxcz_to_rgb(c: [f32; 3]) -> [f32; 3] {
    let y = ycxcz_grey(c[0]);
    let xyz = [
        WHITE_XYZ[0] * (c[1] / 500.0 + y),
        WHITE_XYZ[1] * y,
        WHITE_XYZ[2] * (y - c[2] / 200.0),
    ];
    mul(&XYZ_TO_RGB, xyz)
}

/// ∛t for t > 0 without a libm call (the per-pixel colour conversion's hot spot): a
/// bit-level first guess (within ~5 %) and two Halley steps, each cubing the relative
/// error, to f32 rounding.
#[inline(always)]
fn cbrt_positive(t: f32) -> f32 {
    let mut y = f32::from_bits(t.to_bits() / 3 + 0x2A51_37A0);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * t) / (2.0 * y3 + t);
    }
    y
}

#[inline(always)]
fn lab_f(t: f32) -> f32 {
    const DELTA: f32 = 6.0 / 29.0;
    if t > DELTA * DELTA * DELTA {
        cbrt_positive(t)
    } else {
        t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
    }
}

/// Linear RGB → CIELAB (white = RGB (1, 1, 1)) with the Hunt adjustment a, b ← 0.01 L a, b.
#[inline(always)]
pub(super) fn rgb_to_hunt_lab(rgb: [f32; 3]) -> [f32; 3] {
    let xyz = mul(&RGB_TO_XYZ, rgb);
    let [fx, fy, fz] = map3([0, 1, 2], |c| lab_f(xyz[c] / WHITE_XYZ[c]));
    let l = 116.0 * fy - 16.0;
    [
        l,
        0.01 * l * 500.0 * (fx - fy),
        0.01 * l * 200.0 * (fy - fz),
    ]
}

/// A filtered YyCxCz colour → linear RGB clamped to the unit cube (the filtered colour may
/// leave it) → Hunt-adjusted CIELAB.
#[inline(always)]
pub(super) fn filtered_to_hunt_lab(c: [f32; 3]) -> [f32; 3] {
    rgb_to_hunt_lab(map3(ycxcz_to_rgb(c), |v| v.clamp(0.0, 1.0)))
}

/// HyAB distance (Abasi et al. 2020): |ΔL| + ‖(Δa, Δb)‖.
#[inline(always)]
pub(super) fn hyab(p: [f32; 3], q: [f32; 3]) -> f32 {
    let (da, db) = (p[1] - q[1], p[2] - q[2]);
    // No overflow or underflow to guard against at CIELAB magnitudes: plain sqrt, not hypot.
    (p[0] - q[0]).abs() + (da * da + db * db).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_is_l_100_and_round_trips() {
        let w = rgb_to_hunt_lab([1.0; 3]);
        assert!((w[0] - 100.0).abs() < 1e-4 && w[1].abs() < 1e-3 && w[2].abs() < 1e-3);
        for rgb in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]] {
            let back = ycxcz_to_rgb(rgb_to_ycxcz(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-5, "{rgb:?} → {back:?}");
            }
        }
        assert!((ycxcz_grey(rgb_to_ycxcz([1.0; 3])[0]) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn fast_cube_root_is_exact_to_rounding() {
        let mut t = 0.008_856f32;
        while t < 1e4 {
            let (fast, libm) = (cbrt_positive(t), t.cbrt());
            assert!(
                (fast - libm).abs() <= 2.0 * f32::EPSILON * libm,
                "{t}: {fast} {libm}"
            );
            t *= 1.013;
        }
    }
}

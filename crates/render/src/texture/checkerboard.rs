//! The checkerboard: unit cells in st alternating between `a` (⌊s⌋ + ⌊t⌋ even) and `b`
//! (odd), box-filtered in closed form over the pixel footprint (Apodaca & Gritz 2000,
//! "Advanced RenderMan", §11.4; pbrt-v3 `Checkerboard2DTexture` with `AAMethod::ClosedForm`).
//! The filter is the st bounding box of the one-pixel footprint parallelogram spanned by
//! (∂s/∂x, ∂t/∂x) and (∂s/∂y, ∂t/∂y): half-widths ½(|∂s/∂x| + |∂s/∂y|) and
//! ½(|∂t/∂x| + |∂t/∂y|). (pbrt-v3 uses the larger derivative instead of the sum; at
//! grazing angles the footprint is sheared in st and the narrower box leaves a visible
//! residual pattern where a pixel spans about one check.)

use glam::Vec2;

/// ∫₀ˣ c(x′) dx′ of the 1D "odd cell" indicator c(x) = ⌊x⌋ mod 2 (pbrt-v3 `BUMPINT`).
#[inline]
fn odd_integral(x: f64) -> f64 {
    let half = x / 2.0;
    half.floor() + 2.0 * (half - half.floor() - 0.5).max(0.0)
}

/// Fraction of `[x0, x1]` covered by odd cells (the point value when the interval is
/// empty).
#[inline]
fn odd_fraction(x0: f64, x1: f64) -> f64 {
    if x1 > x0 {
        (odd_integral(x1) - odd_integral(x0)) / (x1 - x0)
    } else {
        (x0.floor().rem_euclid(2.0) != 0.0) as u8 as f64
    }
}

/// The weight of `b` at `st`: the fraction of the box footprint lying in odd cells
/// (0 or 1 for a point; ½ once the box spans many cells). The value is
/// (1 − w)·a + w·b. Computed in f64 so large st keep their cell parity.
#[inline]
pub fn checkerboard_weight(st: Vec2, dst0: Vec2, dst1: Vec2) -> f32 {
    let ds = 0.5 * f64::from(dst0.x.abs() + dst1.x.abs());
    let dt = 0.5 * f64::from(dst0.y.abs() + dst1.y.abs());
    let (s, t) = (f64::from(st.x), f64::from(st.y));
    let fs = odd_fraction(s - ds, s + ds);
    let ft = odd_fraction(t - dt, t + dt);
    // The cell is odd when exactly one of its s and t indices is: P(s odd xor t odd) for
    // the separable box.
    (fs + ft - 2.0 * fs * ft) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_values_alternate() {
        let z = Vec2::ZERO;
        assert_eq!(checkerboard_weight(Vec2::new(0.5, 0.5), z, z), 0.0);
        assert_eq!(checkerboard_weight(Vec2::new(1.5, 0.5), z, z), 1.0);
        assert_eq!(checkerboard_weight(Vec2::new(1.5, 1.5), z, z), 0.0);
        assert_eq!(checkerboard_weight(Vec2::new(-0.5, 0.5), z, z), 1.0);
        assert_eq!(checkerboard_weight(Vec2::new(-0.5, -0.5), z, z), 0.0);
    }

    #[test]
    fn closed_form_matches_numerical_box_average() {
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..200 {
            let st = Vec2::new(next() * 20.0 - 10.0, next() * 20.0 - 10.0);
            let d0 = Vec2::new(next() * 3.0, 0.0);
            let d1 = Vec2::new(0.0, next() * 3.0);
            let w = checkerboard_weight(st, d0, d1);
            // Midpoint rule over the same box.
            let n = 400;
            let mut acc = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let s = st.x as f64 + (((i as f64 + 0.5) / n as f64) - 0.5) * d0.x as f64;
                    let t = st.y as f64 + (((j as f64 + 0.5) / n as f64) - 0.5) * d1.y as f64;
                    acc += ((s.floor() + t.floor()).rem_euclid(2.0) != 0.0) as u8 as f64;
                }
            }
            let reference = acc / (n * n) as f64;
            assert!(
                (w as f64 - reference).abs() < 6e-3,
                "{st} {d0} {d1}: {w} vs {reference}"
            );
        }
    }

    #[test]
    fn wide_footprints_give_the_mean() {
        let w = checkerboard_weight(
            Vec2::new(0.3, 0.7),
            Vec2::new(100.0, 0.0),
            Vec2::new(0.0, 100.0),
        );
        assert!((w - 0.5).abs() < 1e-3);
    }
}

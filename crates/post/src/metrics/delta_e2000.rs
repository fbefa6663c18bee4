//! CIELAB and the CIEDE2000 colour difference (CIE 142-2001), written as in Sharma, Wu &
//! Dalal 2005, "The CIEDE2000 Color-Difference Formula: Implementation Notes, Supplementary
//! Test Data, and Mathematical Observations", Color Res. Appl. 30(1), eqs. 1–22.
//! Kept private to prism-post until prism-spectrum exports `colorimetry::delta_e2000`;
//! then this file should give way to that function.

/// CIE 1976 L*a*b* of `xyz` relative to the white `white_xyz` (same scale).
pub(crate) fn xyz_to_lab(xyz: [f64; 3], white_xyz: [f64; 3]) -> [f64; 3] {
    // CIE 15:2004 eq. 8.x: f(t) = t^(1/3) above (6/29)³, else the linear toe.
    const EPSILON: f64 = 216.0 / 24389.0; // (6/29)³
    const KAPPA: f64 = 24389.0 / 27.0; // (29/3)³
    let f = |t: f64| {
        if t > EPSILON {
            t.cbrt()
        } else {
            (KAPPA * t + 16.0) / 116.0
        }
    };
    let fx = f(xyz[0] / white_xyz[0]);
    let fy = f(xyz[1] / white_xyz[1]);
    let fz = f(xyz[2] / white_xyz[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// ΔE*00 between two L*a*b* colours with k_L = k_C = k_H = 1.
pub(crate) fn delta_e2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    const POW25_7: f64 = 6_103_515_625.0; // 25^7
                                          // Eqs. 2–6: a' stretched by G, C', h'.
    let c_bar = ((a1 * a1 + b1 * b1).sqrt() + (a2 * a2 + b2 * b2).sqrt()) / 2.0;
    let c_bar7 = c_bar.powi(7);
    let g = 0.5 * (1.0 - (c_bar7 / (c_bar7 + POW25_7)).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = ((a1p * a1p + b1 * b1).sqrt(), (a2p * a2p + b2 * b2).sqrt());
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            b.atan2(a).to_degrees().rem_euclid(360.0)
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));
    // Eqs. 8–11: differences.
    let dl = l2 - l1;
    let dc = c2p - c1p;
    let dh_angle = if c1p * c2p == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d.abs() <= 180.0 {
            d
        } else if d > 180.0 {
            d - 360.0
        } else {
            d + 360.0
        }
    };
    let dh = 2.0 * (c1p * c2p).sqrt() * (dh_angle.to_radians() / 2.0).sin();
    // Eqs. 12–22: weights.
    let l_bar = (l1 + l2) / 2.0;
    let cp_bar = (c1p + c2p) / 2.0;
    let h_bar = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        (h1p + h2p) / 2.0
    } else if h1p + h2p < 360.0 {
        (h1p + h2p + 360.0) / 2.0
    } else {
        (h1p + h2p - 360.0) / 2.0
    };
    let cos_deg = |d: f64| d.to_radians().cos();
    let t = 1.0 - 0.17 * cos_deg(h_bar - 30.0)
        + 0.24 * cos_deg(2.0 * h_bar)
        + 0.32 * cos_deg(3.0 * h_bar + 6.0)
        - 0.20 * cos_deg(4.0 * h_bar - 63.0);
    let d_theta = 30.0 * (-((h_bar - 275.0) / 25.0).powi(2)).exp();
    let cp_bar7 = cp_bar.powi(7);
    let r_c = 2.0 * (cp_bar7 / (cp_bar7 + POW25_7)).sqrt();
    let l50 = (l_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * cp_bar;
    let s_h = 1.0 + 0.015 * cp_bar * t;
    let r_t = -(2.0 * d_theta).to_radians().sin() * r_c;
    let (tl, tc, th) = (dl / s_l, dc / s_c, dh / s_h);
    (tl * tl + tc * tc + th * th + r_t * tc * th).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_sharma_2005_test_data() {
        // Pairs 1, 2, 3, 7, 8, 17, 18, 25 of Sharma et al. 2005, Table 1; ΔE printed to 4
        // decimals, so the tolerance is half the last digit.
        let pairs = [
            ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
            ([50.0, 3.1571, -77.2803], [50.0, 0.0, -82.7485], 2.8615),
            ([50.0, 2.8361, -74.0200], [50.0, 0.0, -82.7485], 3.4412),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
            ([50.0, -1.0, 2.0], [50.0, 0.0, 0.0], 2.3669),
            ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
            ([50.0, 2.5, 0.0], [61.0, -5.0, 29.0], 22.8977),
            (
                [60.2574, -34.0099, 36.2677],
                [60.4626, -34.1751, 39.4387],
                1.2644,
            ),
        ];
        for (lab1, lab2, want) in pairs {
            let got = delta_e2000(lab1, lab2);
            assert!(
                (got - want).abs() <= 5e-5,
                "{lab1:?} {lab2:?}: {got} vs {want}"
            );
        }
        assert_eq!(delta_e2000([40.0, 10.0, -3.0], [40.0, 10.0, -3.0]), 0.0);
    }

    #[test]
    fn lab_of_white_and_mid_grey() {
        let white = [0.9505, 1.0, 1.089];
        let lab = xyz_to_lab(white, white);
        assert!((lab[0] - 100.0).abs() < 1e-12 && lab[1].abs() < 1e-12 && lab[2].abs() < 1e-12);
        // Y = 0.18 → L* = 116 · 0.18^(1/3) − 16 = 49.496.
        let grey = xyz_to_lab(white.map(|v| v * 0.18), white);
        assert!((grey[0] - (116.0 * 0.18f64.cbrt() - 16.0)).abs() < 1e-12);
    }
}

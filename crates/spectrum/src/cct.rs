//! Correlated colour temperature (CCT) and Duv by Ohno's method (Ohno 2014, "Practical Use
//! and Calculation of CCT and Duv", LEUKOS 10(1):47–55, presented 2013), computed as
//! colour-science 0.4.7's `uv_to_CCT_Ohno2013` computes it so that the numbers agree:
//! a Planckian table with geometric spacing 1.001 (tightening to 1.0001 towards 100 000 K),
//! the nearest table entry, then the triangular solution, or the parabolic one when
//! |Duv| ≥ 0.002. CCT and Duv are defined in the CIE 1960 UCS (u, v) from CIE 1931
//! chromaticities (CIE 15:2018 §9.5).
//!
//! The Planckian locus is integrated from Planck's law with the CIE 1931 observer on the
//! 1 nm grid 360–830 nm (Prism's grid; colour-science's default CMFs stop at 780 nm, which
//! moves blackbody CCTs by up to 2.6 K at 100 000 K, so the fixtures pass it these CMFs).
//! Planck's second radiation constant is c₂ = 1.4388 × 10⁻² m·K, colour-science's and CIE
//! 15's value (that of ITS-90); temperatures are on that scale.

use std::sync::OnceLock;

use glam::{DVec2, DVec3};

use crate::blackbody::blackbody_radiance;
use crate::colorimetry::{tristimulus_sums, xyz_to_uv_1960};
use crate::data::Observer;
use crate::table::DenseSpectrum;

/// Lowest temperature of the Planckian table in K.
pub const CCT_MIN_K: f64 = 1000.0;
/// Highest temperature of the Planckian table in K.
pub const CCT_MAX_K: f64 = 100_000.0;
/// |Duv| up to which a CCT is meaningful (Ohno 2013's range; ANSI C78.377 uses less).
pub const DUV_MAX: f64 = 0.05;
/// Geometric spacing of the Planckian table at its low end (Ohno 2013; colour-science default).
const TABLE_SPACING: f64 = 1.001;
/// |Duv| from which the parabolic solution replaces the triangular one (Ohno 2013).
const PARABOLIC_DUV_THRESHOLD: f64 = 0.002;

/// A correlated colour temperature and the signed distance from the Planckian locus in
/// the CIE 1960 UCS (positive above the locus, towards green).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CctDuv {
    pub cct_k: f64,
    pub duv: f64,
}

/// A blackbody's spectral radiance on the 1 nm grid, W·m⁻²·sr⁻¹·nm⁻¹.
pub fn blackbody_dense(temperature_k: f64) -> DenseSpectrum {
    DenseSpectrum::from_fn(|wl| blackbody_radiance(wl, temperature_k))
}

/// CIE 1960 (u, v) of a blackbody at `temperature_k` with the CIE 1931 observer
/// (colour-science `CCT_to_uv_Planck1900` with the 360–830 nm CMFs). `None` for
/// non-positive or non-finite temperatures.
pub fn planck_uv_1960(temperature_k: f64) -> Option<DVec2> {
    if !(temperature_k > 0.0 && temperature_k.is_finite()) {
        return None;
    }
    xyz_to_uv_1960(tristimulus_sums(
        &blackbody_dense(temperature_k),
        Observer::Cie1931,
    ))
}

/// One Planckian table row: temperature in K and its (u, v).
#[derive(Debug, Clone, Copy)]
struct PlanckRow {
    t_k: f64,
    uv: DVec2,
}

/// The table temperatures, generated with colour-science's `planckian_table` recurrence
/// (same floating-point operations, so the same temperatures): 1000, 1001, then ×spacing,
/// the spacing shrinking linearly from 1.001 to 1.0001 between 1000 K and 100 000 K, and
/// finally 99 999 and 100 000 K.
fn table_temperatures() -> Vec<f64> {
    let (start, end, spacing) = (CCT_MIN_K, CCT_MAX_K, TABLE_SPACING);
    let mut temps = vec![start, start + 1.0];
    let mut next_t = start + 1.0;
    let mut next_spacing = spacing;
    loop {
        next_t *= next_spacing;
        if next_t >= end {
            break;
        }
        temps.push(next_t);
        let d = ((next_t - CCT_MIN_K) / (CCT_MAX_K - CCT_MIN_K)).clamp(0.0, 1.0);
        next_spacing = spacing * (1.0 - d) + (1.0 + (spacing - 1.0) / 10.0) * d;
    }
    temps.push(end - 1.0);
    temps.push(end);
    temps
}

fn planck_table() -> &'static [PlanckRow] {
    static TABLE: OnceLock<Vec<PlanckRow>> = OnceLock::new();
    TABLE.get_or_init(|| {
        table_temperatures()
            .into_iter()
            .map(|t_k| PlanckRow {
                t_k,
                uv: planck_uv_1960(t_k).unwrap_or(DVec2::ZERO),
            })
            .collect()
    })
}

/// CCT and Duv of CIE 1960 (u, v) by Ohno (2013), as colour-science 0.4.7
/// `uv_to_CCT_Ohno2013` with 360–830 nm CIE 1931 CMFs. Valid for 1000–100 000 K and
/// |Duv| ≲ 0.05; outside the table the nearest end segment is extrapolated (as
/// colour-science does, with a warning there). `None` for non-finite input.
pub fn uv_to_cct_ohno2013(uv: DVec2) -> Option<CctDuv> {
    if !uv.is_finite() {
        return None;
    }
    let table = planck_table();
    // Nearest table entry (first minimum, like numpy.argmin), kept off both ends.
    let mut index = 0;
    let mut best = f64::INFINITY;
    for (i, row) in table.iter().enumerate() {
        let d = row.uv.distance_squared(uv);
        if d < best {
            best = d;
            index = i;
        }
    }
    let index = index.clamp(1, table.len() - 2);
    let (p, i, n) = (table[index - 1], table[index], table[index + 1]);
    let (dp, di, dn) = (p.uv.distance(uv), i.uv.distance(uv), n.uv.distance(uv));

    // Triangular solution (Ohno 2014, eqs. 4–8; no 0.99991 correction, as colour-science).
    let l = p.uv.distance(n.uv);
    let x = (dp * dp - dn * dn + l * l) / (2.0 * l);
    let t_triangular = p.t_k + (n.t_k - p.t_k) * (x / l);
    let v_tx = p.uv.y + (n.uv.y - p.uv.y) * (x / l);
    let sign = signum_or_zero(uv.y - v_tx);
    // colour-science takes the square root of a tiny negative (NaN) when uv lies on the
    // locus beyond the chord; clamping gives the limit, Duv = 0.
    let duv_triangular = (dp * dp - x * x).max(0.0).sqrt() * sign;
    if duv_triangular.abs() < PARABOLIC_DUV_THRESHOLD {
        return Some(CctDuv {
            cct_k: t_triangular,
            duv: duv_triangular,
        });
    }

    // Parabolic solution (Ohno 2014, eqs. 9–12) through (T, d) of the three rows.
    let (tp, ti, tn) = (p.t_k, i.t_k, n.t_k);
    let big_x = (tn - ti) * (tp - tn) * (ti - tp);
    let a = (tp * (dn - di) + ti * (dp - dn) + tn * (di - dp)) / big_x;
    let b = -(tp * tp * (dn - di) + ti * ti * (dp - dn) + tn * tn * (di - dp)) / big_x;
    let c =
        -(dp * (tn - ti) * ti * tn + di * (tp - tn) * tp * tn + dn * (ti - tp) * tp * ti) / big_x;
    let t_parabolic = -b / (2.0 * a);
    let duv_parabolic = (a * t_parabolic * t_parabolic + b * t_parabolic + c) * sign;
    Some(CctDuv {
        cct_k: t_parabolic,
        duv: duv_parabolic,
    })
}

impl CctDuv {
    /// Whether the result is within the method's valid range ([`CCT_MIN_K`]–[`CCT_MAX_K`],
    /// |Duv| ≤ [`DUV_MAX`]); outside it the number is an extrapolation, not a temperature.
    pub fn in_valid_range(&self) -> bool {
        (CCT_MIN_K..=CCT_MAX_K).contains(&self.cct_k) && self.duv.abs() <= DUV_MAX
    }
}

/// CCT and Duv of CIE 1931 XYZ (via CIE 1960 uv). `None` for black or non-finite input.
pub fn xyz_to_cct_ohno2013(xyz: DVec3) -> Option<CctDuv> {
    uv_to_cct_ohno2013(xyz_to_uv_1960(xyz)?)
}

/// CIE 1960 (u, v) at `cct_k` and `duv` (Ohno 2013 inverse, as colour-science
/// `CCT_to_uv_Ohno2013`): the Planckian point moved by Duv along the normal estimated from
/// the locus at T and T + 0.01 K. `None` for non-positive or non-finite input.
pub fn cct_to_uv_ohno2013(cct_k: f64, duv: f64) -> Option<DVec2> {
    if !duv.is_finite() {
        return None;
    }
    let uv0 = planck_uv_1960(cct_k)?;
    if duv == 0.0 {
        return Some(uv0);
    }
    let uv1 = planck_uv_1960(cct_k + 0.01)?;
    let d = uv0 - uv1;
    let h = d.length();
    if h == 0.0 {
        return Some(uv0);
    }
    Some(DVec2::new(uv0.x - duv * d.y / h, uv0.y + duv * d.x / h))
}

/// numpy.sign: −1, 0 or +1.
fn signum_or_zero(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_has_colour_science_shape() {
        let temps = table_temperatures();
        assert_eq!(temps[0], 1000.0);
        assert_eq!(temps[1], 1001.0);
        assert!((temps[2] - 1002.001).abs() < 1e-9);
        assert_eq!(temps[temps.len() - 1], 100_000.0);
        assert_eq!(temps[temps.len() - 2], 99_999.0);
    }

    #[test]
    fn cct_round_trips_through_uv() {
        for &t in &[
            1000.0, 1234.5, 2856.0, 4000.0, 6504.0, 10_000.0, 33_333.0, 99_000.0,
        ] {
            for &duv in &[-0.02, -0.001, 0.0, 0.001, 0.02] {
                let uv = cct_to_uv_ohno2013(t, duv).unwrap();
                let r = uv_to_cct_ohno2013(uv).unwrap();
                // Ohno's method with 1.001 spacing is good to well under 0.1 % and 1e-5 Duv.
                assert!((r.cct_k - t).abs() < 1e-4 * t, "{t} {duv}: {:?}", r);
                assert!((r.duv - duv).abs() < 1e-5, "{t} {duv}: {:?}", r);
            }
        }
    }

    #[test]
    fn locus_sign_convention_and_bad_input() {
        let above = uv_to_cct_ohno2013(DVec2::new(0.1978, 0.3122)).unwrap();
        // colour-science docstring: 6507.47 K, Duv 3.22334e-3 (360–780 nm CMFs there).
        assert!((above.cct_k - 6507.5).abs() < 1.0, "{above:?}");
        assert!((above.duv - 0.003223).abs() < 1e-5, "{above:?}");
        assert!(uv_to_cct_ohno2013(DVec2::new(f64::NAN, 0.3)).is_none());
        assert!(cct_to_uv_ohno2013(-5.0, 0.0).is_none());
        assert!(xyz_to_cct_ohno2013(DVec3::ZERO).is_none());
    }
}

//! A point luminaire with a measured luminous intensity distribution (IES LM-63 or
//! EULUMDAT, read by prism-scene): I(λ, ω) = I_v(ω) · s(λ), with I_v in cd interpolated
//! over the file's angle grid and s(λ) = S(λ) / (K_m Σ S ȳ Δλ) the relative spectrum made
//! to carry exactly 1 cd per cd (so the photometric intensity is the file's, times the
//! strength's factor). Irradiance at distance d on a surface facing it: I(ω)/d².
//!
//! Interpolation (smooth, never overshooting, so no negative intensities and no ringing
//! near cut-offs): separable monotone piecewise-cubic Hermite (Fritsch & Carlson 1980, with
//! the Fritsch & Butland 1984 weighted harmonic-mean slopes — SciPy's `PchipInterpolator`)
//! along γ (V) on the four neighbouring planes, then along C (H), C¹ everywhere, periodic
//! in C. Outside the measured vertical range the intensity is 0.
//!
//! Flux Φ = ∮ I_v dω of the interpolated distribution is integrated once at build time
//! (midpoint rule on a 0.25° × 0.25° grid in (C, γ), or over (H, V) with cos V) and used for
//! `power_lm` and for light selection.

use std::f64::consts::PI;

use glam::{DVec3, Vec2, Vec3A};
use prism_scene::photometric::{IntensityDistribution, PhotometryType};
use prism_spectrum::{SampledWavelengths, Spectrum};

use super::point::point_emitter_sample;
use super::{LightSample, LightSampleContext};

/// The distribution in the luminaire's frame, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct IntensityTable {
    pub photometry: PhotometryType,
    /// C or H angles, radians, increasing (Type C: 0…2π inclusive, or one plane).
    pub horizontal_rad: Vec<f64>,
    /// γ or V angles, radians, increasing.
    pub vertical_rad: Vec<f64>,
    /// cd at (h, v), row-major by h.
    pub candela: Vec<f64>,
}

/// Monotone cubic Hermite slope at the middle of three points (Fritsch–Butland): 0 at an
/// extremum, else the weighted harmonic mean of the secants.
fn pchip_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    if d0 * d1 <= 0.0 {
        return 0.0;
    }
    let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
    (w1 + w2) / (w1 / d0 + w2 / d1)
}

/// Interpolates y over the segment [x1, x2] at x with neighbours x0, x3 (`None` past an end:
/// the end slope is then the segment's secant, limited as in Fritsch–Carlson).
#[allow(clippy::too_many_arguments)]
fn pchip(
    x0: Option<(f64, f64)>,
    (x1, y1): (f64, f64),
    (x2, y2): (f64, f64),
    x3: Option<(f64, f64)>,
    x: f64,
) -> f64 {
    let h = x2 - x1;
    if h <= 0.0 {
        return y1;
    }
    let d = (y2 - y1) / h;
    let m1 = match x0 {
        Some((xa, ya)) if x1 - xa > 0.0 => pchip_slope(x1 - xa, h, (y1 - ya) / (x1 - xa), d),
        _ => d,
    };
    let m2 = match x3 {
        Some((xb, yb)) if xb - x2 > 0.0 => pchip_slope(h, xb - x2, d, (yb - y2) / (xb - x2)),
        _ => d,
    };
    let t = ((x - x1) / h).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    let v = (2.0 * t3 - 3.0 * t2 + 1.0) * y1
        + (t3 - 2.0 * t2 + t) * h * m1
        + (-2.0 * t3 + 3.0 * t2) * y2
        + (t3 - t2) * h * m2;
    v.max(0.0)
}

/// The segment of sorted `xs` holding x: index i with xs[i] ≤ x ≤ xs[i+1] (len ≥ 2).
fn segment(xs: &[f64], x: f64) -> usize {
    xs.partition_point(|&a| a <= x).clamp(1, xs.len() - 1) - 1
}

impl IntensityTable {
    pub fn from_distribution(d: &IntensityDistribution) -> Self {
        Self {
            photometry: d.photometry,
            horizontal_rad: d.horizontal_deg.iter().map(|a| a.to_radians()).collect(),
            vertical_rad: d.vertical_deg.iter().map(|a| a.to_radians()).collect(),
            candela: d.candela.clone(),
        }
    }

    fn value(&self, h: usize, v: usize) -> f64 {
        self.candela[h * self.vertical_rad.len() + v]
    }

    /// Intensity along plane `h` at vertical angle `v` (0 outside the measured range).
    fn along_vertical(&self, h: usize, v: f64) -> f64 {
        let vs = &self.vertical_rad;
        let n = vs.len();
        let eps = 1e-9;
        if v < vs[0] - eps || v > vs[n - 1] + eps {
            return 0.0;
        }
        if n == 1 {
            return self.value(h, 0);
        }
        let i = segment(vs, v);
        let at = |k: usize| (vs[k], self.value(h, k));
        pchip(
            (i > 0).then(|| at(i - 1)),
            at(i),
            at(i + 1),
            (i + 2 < n).then(|| at(i + 2)),
            v,
        )
    }

    /// Intensity in cd at horizontal angle `hz` (C or H) and vertical angle `v` (γ or V),
    /// radians.
    pub fn eval_angles(&self, hz: f64, v: f64) -> f64 {
        let hs = &self.horizontal_rad;
        let n = hs.len();
        if n == 1 {
            return self.along_vertical(0, v);
        }
        let periodic = self.photometry == PhotometryType::C;
        let hz = if periodic {
            hz.rem_euclid(2.0 * PI)
        } else {
            if hz < hs[0] - 1e-9 || hz > hs[n - 1] + 1e-9 {
                return 0.0;
            }
            hz
        };
        let i = segment(hs, hz);
        let at = |k: usize| (hs[k], self.along_vertical(k, v));
        // Periodic neighbours: the first and last planes are the same (0 and 2π).
        let before = if i > 0 {
            Some(at(i - 1))
        } else if periodic && n > 2 {
            let (x, y) = at(n - 2);
            Some((x - 2.0 * PI, y))
        } else {
            None
        };
        let after = if i + 2 < n {
            Some(at(i + 2))
        } else if periodic && n > 2 {
            let (x, y) = at(1);
            Some((x + 2.0 * PI, y))
        } else {
            None
        };
        pchip(before, at(i), at(i + 1), after, hz)
    }

    /// Intensity in cd towards `d` (unit) given in the luminaire frame as components
    /// (along the length axis l, along the width axis w, along the aim a).
    pub fn eval_local(&self, dl: f64, dw: f64, da: f64) -> f64 {
        match self.photometry {
            PhotometryType::C => {
                let gamma = da.clamp(-1.0, 1.0).acos();
                self.eval_angles(dw.atan2(dl), gamma)
            }
            PhotometryType::B => self.eval_angles(dl.atan2(da), dw.clamp(-1.0, 1.0).asin()),
            PhotometryType::A => self.eval_angles(dw.atan2(da), dl.clamp(-1.0, 1.0).asin()),
        }
    }

    /// Φ = ∮ I dω in lm (for cd values), midpoint rule on 0.25° cells.
    pub fn flux(&self) -> f64 {
        let step = 0.25f64.to_radians();
        let mut sum = 0.0;
        match self.photometry {
            PhotometryType::C => {
                let (nc, ng) = ((2.0 * PI / step) as usize, (PI / step) as usize);
                let single = self.horizontal_rad.len() == 1;
                for j in 0..ng {
                    let g = (j as f64 + 0.5) * step;
                    let w = g.sin() * step * step;
                    if single {
                        sum += self.eval_angles(0.0, g) * w * nc as f64;
                        continue;
                    }
                    for i in 0..nc {
                        sum += self.eval_angles((i as f64 + 0.5) * step, g) * w;
                    }
                }
            }
            _ => {
                // d = cos V (…) + sin V p: dω = cos V dV dH, H ∈ [−π, π], V ∈ [−π/2, π/2].
                let (nh, nv) = ((2.0 * PI / step) as usize, (PI / step) as usize);
                for j in 0..nv {
                    let v = -PI / 2.0 + (j as f64 + 0.5) * step;
                    let w = v.cos() * step * step;
                    for i in 0..nh {
                        sum += self.eval_angles(-PI + (i as f64 + 0.5) * step, v) * w;
                    }
                }
            }
        }
        sum
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct GoniometricLight {
    pub position_m: Vec3A,
    /// Luminaire frame in the world: length axis (C = 0), width axis (C = 90°), aim (γ = 0).
    pub axes: [DVec3; 3],
    pub table: IntensityTable,
    /// Radiant intensity per cd of the table: W·sr⁻¹·nm⁻¹ (includes the strength's factor
    /// and the TILT factor).
    pub spectrum: Spectrum,
    /// Luminous flux of the light as built, lm.
    pub flux_lm: f64,
    /// Radiant power, W (for light selection).
    pub power_w: f64,
}

impl GoniometricLight {
    /// Candela of the table (before the spectrum's scale) towards world direction `d`
    /// leaving the luminaire.
    pub fn table_candela(&self, d: DVec3) -> f64 {
        let [l, w, a] = self.axes;
        self.table.eval_local(d.dot(l), d.dot(w), d.dot(a))
    }

    #[inline]
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        point_emitter_sample(ctx, self.position_m, |out| {
            let cd = self.table_candela(out.as_dvec3()) as f32;
            (cd > 0.0).then(|| self.spectrum.eval(wavelengths) * cd)
        })
    }

    pub fn power_w(&self) -> f64 {
        self.power_w
    }
}

/// The TILT factor for a luminaire whose aim makes `tilt_deg` with the straight-down
/// direction it was measured in (LM-63 §3.9: linear in the tabulated angles, the end values
/// beyond them).
pub fn tilt_factor(tilt: &prism_scene::photometric::Tilt, tilt_deg: f64) -> f64 {
    let a = &tilt.angles_deg;
    let f = &tilt.factors;
    if tilt_deg <= a[0] {
        return f[0];
    }
    if tilt_deg >= a[a.len() - 1] {
        return f[f.len() - 1];
    }
    let i = segment(a, tilt_deg);
    let t = (tilt_deg - a[i]) / (a[i + 1] - a[i]);
    f[i] + t * (f[i + 1] - f[i])
}

#[cfg(test)]
#[path = "goniometric_tests.rs"]
mod tests;

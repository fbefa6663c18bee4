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
//!
//! Emitted rays: directions from a piecewise-constant table over the equal-area map of the
//! sphere about the aim, (u, v) = (φ / 2π, (1 − cos γ) / 2) with φ from the length axis
//! towards the width axis (`EMISSION_NU` × `EMISSION_NV` cells, each holding the largest
//! candela of its 3 × 3 corner, edge and centre points, and never less than 10⁻³ of the
//! mean so every direction that might emit can be sampled), uniform in solid angle within
//! a cell: pdf_dir = pdf(u, v) / 4π (pbrt-v4 §12.2.4 `GoniometricLight::SampleLe` samples
//! its image the same way).

use std::f64::consts::PI;

use glam::{DVec3, Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
use prism_scene::photometric::{IntensityDistribution, PhotometryType};
use prism_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

use super::environment::azimuth_fraction;
use super::piecewise_constant::PiecewiseConstant2D;
use super::point::{point_emission, point_emitter_sample};
use super::scene_sphere::SceneSphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};

/// Columns (φ) and rows (cos γ) of the emission table.
const EMISSION_NU: usize = 64;
const EMISSION_NV: usize = 64;

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
            PhotometryType::B | PhotometryType::A => {
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
    /// Direction table of `sample_le` (module docs).
    emission: PiecewiseConstant2D,
}

/// The luminaire-frame direction (along length, width, aim) of emission-table coordinates.
#[inline]
fn emission_local_direction(uv: Vec2) -> Vec3A {
    let cos_g = (1.0 - 2.0 * uv.y).clamp(-1.0, 1.0);
    let sin_g = (1.0 - cos_g * cos_g).max(0.0).sqrt();
    let (sin_p, cos_p) = (2.0 * std::f32::consts::PI * uv.x).sin_cos();
    Vec3A::new(sin_g * cos_p, sin_g * sin_p, cos_g)
}

impl GoniometricLight {
    /// The luminaire at `position_m` with frame `axes` (length, width, aim), its table and
    /// spectrum; builds the emission table.
    pub fn new(
        position_m: Vec3A,
        axes: [DVec3; 3],
        table: IntensityTable,
        spectrum: Spectrum,
        flux_lm: f64,
        power_w: f64,
    ) -> Self {
        let mut light = Self {
            position_m,
            axes,
            table,
            spectrum,
            flux_lm,
            power_w,
            emission: PiecewiseConstant2D::new(&[1.0], 1, 1),
        };
        // Candela on the (2 NU + 1) × (2 NV + 1) grid of cell corners, edge midpoints and
        // centres; a cell takes the largest of its nine.
        let (gu, gv) = (2 * EMISSION_NU + 1, 2 * EMISSION_NV + 1);
        let mut grid = vec![0.0f64; gu * gv];
        for j in 0..gv {
            for i in 0..gu {
                let uv = Vec2::new(i as f32 / (gu - 1) as f32, j as f32 / (gv - 1) as f32);
                let d = emission_local_direction(uv).as_dvec3();
                grid[j * gu + i] = light.table.eval_local(d.x, d.y, d.z).max(0.0);
            }
        }
        let mut values = vec![0.0f32; EMISSION_NU * EMISSION_NV];
        for y in 0..EMISSION_NV {
            for x in 0..EMISSION_NU {
                let mut m = 0.0f64;
                for j in 0..3 {
                    for i in 0..3 {
                        m = m.max(grid[(2 * y + j) * gu + 2 * x + i]);
                    }
                }
                values[y * EMISSION_NU + x] = m as f32;
            }
        }
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
        let floor = (1e-3 * mean) as f32;
        for v in &mut values {
            *v = v.max(floor);
        }
        light.emission = PiecewiseConstant2D::new(&values, EMISSION_NU, EMISSION_NV);
        light
    }

    /// Candela of the table (before the spectrum's scale) towards world direction `d`
    /// leaving the luminaire.
    pub fn table_candela(&self, d: DVec3) -> f64 {
        let [l, w, a] = self.axes;
        self.table.eval_local(d.dot(l), d.dot(w), d.dot(a))
    }

    /// The world direction of emission-table coordinates.
    #[inline]
    fn emission_direction(&self, uv: Vec2) -> Vec3A {
        let local = emission_local_direction(uv);
        let [l, w, a] = self.axes.map(|v| v.as_vec3a());
        (l * local.x + w * local.y + a * local.z).normalize()
    }

    /// pdf_dir of `sample_le` along the unit world `direction`: pdf(u, v) / 4π.
    #[inline]
    fn direction_pdf(&self, direction: Vec3A) -> f32 {
        let d = direction.as_dvec3();
        let [l, w, a] = self.axes;
        let local = Vec3A::new(d.dot(l) as f32, d.dot(w) as f32, d.dot(a) as f32);
        // azimuth_fraction measures from −z towards +x; (w, −l) puts φ = 0 on l, φ = ¼ on w.
        let u = azimuth_fraction(Vec3A::new(local.y, 0.0, -local.x));
        let v = ((1.0 - local.z) * 0.5).clamp(0.0, 1.0);
        self.emission.pdf(Vec2::new(u, v)) * (0.25 / std::f32::consts::PI)
    }
}

impl LightSource for GoniometricLight {
    #[inline]
    fn sample_li(
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

    #[inline]
    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        0.0
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    #[inline]
    fn infinite_radiance(&self, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    fn sample_le(
        &self,
        _scene: &SceneSphere,
        _u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (uv, pdf_uv, _) = self.emission.sample(u_dir);
        if !(pdf_uv > 0.0 && pdf_uv.is_finite()) {
            return None;
        }
        let w = self.emission_direction(uv);
        // The density of the cell the direction maps back to (`pdf_le`'s function).
        let pdf_dir = self.direction_pdf(w);
        if !(pdf_dir > 0.0 && pdf_dir.is_finite()) {
            return None;
        }
        let cd = self.table_candela(w.as_dvec3()).max(0.0) as f32;
        Some(point_emission(
            self.position_m,
            w,
            self.spectrum.eval(wavelengths) * cd,
            pdf_dir,
        ))
    }

    fn pdf_le(&self, _: &SceneSphere, _origin: Vec3A, _n: Vec3A, direction: Vec3A) -> (f32, f32) {
        (1.0, self.direction_pdf(direction))
    }

    /// Φ = ∮ I dω from the build-time quadrature of the table, times ∫ s(λ) dλ, W.
    fn power_w(&self, _scene_radius_m: f32) -> f64 {
        self.power_w
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::point_like()
    }

    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    #[inline]
    fn is_infinite(&self) -> bool {
        false
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

//! pbrt-v4 `LightSource "goniometric"` → a Prism `luminaire` with an IES LM-63 side file.
//!
//! pbrt-v4 (`GoniometricLight`): I(λ, ω) = scale · I_e(λ) · Y(ω), where
//! - Y is the image texel nearest to the light-space direction in the equal-area
//!   octahedral square (octahedral.rs); an RGB image is first averaged to one channel;
//! - light space is the CTM's space with y and z swapped (the square's pole, light-space
//!   +z, is the CTM's +y), the light at its origin;
//! - I_e is normalised to luminance 1 (as for point lights, spectra.rs), and `power` > 0
//!   multiplies the scale by power / (4π · mean Y).
//!
//! Prism's luminaire reads candela over Type C angles: γ from `aim`, C from
//! `c0_direction` towards w = c0 × aim (docs/lighting.md). The importer takes aim = the
//! CTM's +y and c0 = its +x (made perpendicular), and samples Y at every (C, γ) grid
//! direction mapped back into light space, on a grid at least twice as fine as the
//! image's texels (0.5° at the finest). The IES file holds Y; the luminaire's `scale` is
//! the candela per unit Y: pbrt's scale × K_m Σȳ Δλ (luminance 1 in Prism's units, as the
//! point light import gives) × the luminance of an RGB `I`. Prism interpolates the table
//! smoothly where pbrt takes the nearest texel; the two agree texel by texel on average.

use std::f64::consts::PI;
use std::fmt::Write;

use glam::{DMat4, DVec3};
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::K_M_PHOTOPIC_LM_PER_W;
use serde_json::{json, Value};

use crate::error::{ImportError, Location};
use crate::pbrt::octahedral::{read_square, sphere_to_square};
use crate::pbrt::spectra::unit_luminance_sum;

/// The finest and coarsest grid steps, degrees; each divides 90.
const STEPS_DEG: [f64; 6] = [0.5, 1.0, 1.5, 2.5, 3.0, 5.0];

/// pbrt's one-channel goniometric image: N × N values, row-major, top row first.
pub struct GoniometricImage {
    pub size: usize,
    pub values: Vec<f32>,
}

impl GoniometricImage {
    /// Reads `path` (square; RGB averaged per texel as pbrt does; no colour conversion).
    pub fn read(path: &std::path::Path, at: &Location) -> Result<Self, ImportError> {
        let image = read_square(path, at, "LightSource goniometric")?;
        let values: Vec<f32> = image
            .pixels()
            .iter()
            .map(|p| (p[0] + p[1] + p[2]) / 3.0)
            .collect();
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(ImportError::at(
                at,
                format!(
                    "LightSource goniometric \"filename\" {}: texel ({}, {}) averages to {}; \
                     expected finite values ≥ 0 (an intensity)",
                    path.display(),
                    i % image.width(),
                    i / image.width(),
                    values[i]
                ),
            ));
        }
        Ok(Self {
            size: image.width(),
            values,
        })
    }

    /// pbrt's `LookupNearestChannel` at the light-space direction `d`.
    pub fn nearest(&self, d: DVec3) -> f32 {
        let (u, v) = sphere_to_square(d);
        let n = self.size;
        let x = ((u * n as f64) as usize).min(n - 1);
        let y = ((v * n as f64) as usize).min(n - 1);
        self.values[y * n + x]
    }

    pub fn mean(&self) -> f64 {
        self.values.iter().map(|&v| f64::from(v)).sum::<f64>() / self.values.len() as f64
    }

    /// The grid step: the coarsest of [`STEPS_DEG`] at most half a texel's angular size
    /// (√(4π) / N rad), or the finest.
    fn step_deg(&self) -> f64 {
        let texel_deg = (4.0 * PI).sqrt() / self.size as f64 * 180.0 / PI;
        STEPS_DEG
            .iter()
            .rev()
            .copied()
            .find(|&s| s <= texel_deg / 2.0)
            .unwrap_or(STEPS_DEG[0])
    }
}

/// The luminaire's frame in world space: aim (γ = 0), the C = 0 direction, and the map
/// from a world direction to pbrt's light space.
pub struct LuminaireFrame {
    pub position_m: DVec3,
    pub aim: DVec3,
    pub c0: DVec3,
    light_from_world: glam::DMat3,
}

impl LuminaireFrame {
    /// For pbrt's CTM at the `LightSource` (world from object); `None` when it is singular.
    pub fn new(ctm: &DMat4) -> Option<Self> {
        let linear = glam::DMat3::from_mat4(*ctm);
        if linear.determinant().abs() < 1e-300 {
            return None;
        }
        // pbrt: render-from-light = CTM · swapYZ.
        let swap_yz = glam::DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::Y);
        let world_from_light = linear * swap_yz;
        let aim = world_from_light.mul_vec3(DVec3::Z).normalize();
        let x = world_from_light.mul_vec3(DVec3::X);
        let c0 = (x - x.dot(aim) * aim).try_normalize()?;
        Some(Self {
            position_m: ctm.transform_point3(DVec3::ZERO),
            aim,
            c0,
            light_from_world: world_from_light.inverse(),
        })
    }

    /// The world direction at Type C angles (C, γ), degrees (docs/lighting.md).
    fn direction(&self, c_deg: f64, gamma_deg: f64) -> DVec3 {
        let w = self.c0.cross(self.aim);
        let (c, g) = (c_deg.to_radians(), gamma_deg.to_radians());
        g.cos() * self.aim + g.sin() * (c.cos() * self.c0 + c.sin() * w)
    }

    fn to_light(&self, world: DVec3) -> DVec3 {
        self.light_from_world.mul_vec3(world).normalize()
    }
}

/// The IES LM-63-2002 text of `image` seen through `frame`: absolute photometry, Type C,
/// C 0…360°, γ 0…180°, candela = the image's values.
pub fn ies_text(image: &GoniometricImage, frame: &LuminaireFrame, source: &str) -> String {
    let step = image.step_deg();
    let n_gamma = (180.0 / step).round() as usize + 1;
    let n_c = (360.0 / step).round() as usize + 1;
    let angles = |n: usize| -> Vec<f64> { (0..n).map(|i| i as f64 * step).collect() };
    let (gammas, cs) = (angles(n_gamma), angles(n_c));
    let mut text = String::from("IESNA:LM-63-2002\n");
    let _ = writeln!(text, "[TEST] written by prism import from {source}");
    text.push_str("[MANUFAC] pbrt-v4 goniometric light\nTILT=NONE\n");
    // lamps, lumens per lamp (−1: absolute), multiplier, vertical and horizontal angle
    // counts, photometric type (1 = C), units (2 = metres), width, length, height.
    let _ = writeln!(text, "1 -1 1 {n_gamma} {n_c} 1 2 0 0 0");
    text.push_str("1 1 0\n");
    let mut line = |values: &mut dyn Iterator<Item = String>| {
        let items: Vec<String> = values.collect();
        for chunk in items.chunks(10) {
            text.push_str(&chunk.join(" "));
            text.push('\n');
        }
    };
    line(&mut gammas.iter().map(|g| format!("{g}")));
    line(&mut cs.iter().map(|c| format!("{c}")));
    for &c in &cs {
        line(&mut gammas.iter().map(|&g| {
            let v = image.nearest(frame.to_light(frame.direction(c, g)));
            format!("{v}")
        }));
    }
    text
}

/// Candela per unit image value of pbrt's light: `scale` (with `power` applied) × the
/// luminance Prism gives pbrt's unit-luminance spectrum, K_m Σȳ Δλ, × an RGB `I`'s
/// luminance (pbrt normalises the illuminant of an RGB spectrum, not its RGB).
pub fn candela_per_unit(scale: f64, spectrum: &Value) -> f64 {
    let unit = K_M_PHOTOPIC_LM_PER_W * unit_luminance_sum();
    let rgb_luminance = spectrum
        .get("rgb")
        .and_then(Value::as_array)
        .map(|rgb| {
            let c = |i: usize| rgb.get(i).and_then(Value::as_f64).unwrap_or(0.0);
            // In pbrt's default colour space, sRGB.
            RgbColorSpace::srgb()
                .rgb_to_xyz
                .row(1)
                .dot(glam::DVec3::new(c(0), c(1), c(2)))
        })
        .unwrap_or(1.0);
    scale * unit * rgb_luminance
}

/// The luminaire's JSON (without strength fields).
pub fn luminaire_json(frame: &LuminaireFrame, file: &str) -> serde_json::Map<String, Value> {
    let mut l = serde_json::Map::new();
    l.insert("type".into(), json!("luminaire"));
    l.insert("file".into(), json!(file));
    l.insert("position_m".into(), json!(frame.position_m.to_array()));
    l.insert("aim".into(), json!(frame.aim.to_array()));
    l.insert("c0_direction".into(), json!(frame.c0.to_array()));
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(size: usize, v: f32) -> GoniometricImage {
        GoniometricImage {
            size,
            values: vec![v; size * size],
        }
    }

    #[test]
    fn the_frame_puts_pbrt_light_space_z_on_the_ctm_y_axis() {
        let f = LuminaireFrame::new(&DMat4::IDENTITY).unwrap();
        assert!((f.aim - DVec3::Y).length() < 1e-12);
        assert!((f.c0 - DVec3::X).length() < 1e-12);
        // γ = 0 looks along light-space +z, the square's centre.
        let d = f.to_light(f.direction(0.0, 0.0));
        assert!((d - DVec3::Z).length() < 1e-12);
        // Every grid direction maps back to a unit light-space direction.
        for (c, g) in [(0.0, 90.0), (90.0, 90.0), (200.0, 135.0), (360.0, 180.0)] {
            let world = f.direction(c, g);
            assert!((world.length() - 1.0).abs() < 1e-12);
            assert!((f.to_light(world).length() - 1.0).abs() < 1e-12);
        }
        // A rotated CTM carries the aim with it.
        let r = DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let f = LuminaireFrame::new(&r).unwrap();
        assert!((f.aim - DVec3::Z).length() < 1e-12, "{}", f.aim);
        assert!(LuminaireFrame::new(&DMat4::ZERO).is_none());
    }

    #[test]
    fn the_table_reads_each_direction_from_its_own_texel() {
        // A square whose texels hold the light-space z of their centres (+ 1): the table's
        // value at (C, γ) must be 1 + cos γ to within a texel.
        let size = 128;
        let values = (0..size * size)
            .map(|i| {
                let (x, y) = (i % size, i / size);
                let d = crate::pbrt::octahedral::square_to_sphere(
                    (x as f64 + 0.5) / size as f64,
                    (y as f64 + 0.5) / size as f64,
                );
                (1.0 + d.z) as f32
            })
            .collect();
        let image = GoniometricImage { size, values };
        let frame = LuminaireFrame::new(&DMat4::IDENTITY).unwrap();
        let step = image.step_deg();
        assert_eq!(step, 0.5, "texel {:.2}°", 3.545 / 128.0 * 57.3);
        let text = ies_text(&image, &frame, "test");
        let numbers: Vec<f64> = text
            .lines()
            .skip(5)
            .flat_map(|l| l.split_whitespace().map(|t| t.parse::<f64>().unwrap()))
            .collect();
        let (n_gamma, n_c) = (361, 721);
        assert_eq!(numbers.len(), 3 + n_gamma + n_c + n_gamma * n_c);
        let candela = &numbers[3 + n_gamma + n_c..];
        let texel_rad = (4.0 * PI).sqrt() / size as f64;
        for (ci, row) in candela.chunks(n_gamma).enumerate().step_by(37) {
            for (gi, v) in row.iter().enumerate() {
                let expected = 1.0 + (gi as f64 * step).to_radians().cos();
                assert!(
                    (v - expected).abs() < 1.5 * texel_rad,
                    "C {} γ {}: {v} against {expected}",
                    ci as f64 * step,
                    gi as f64 * step
                );
            }
        }
        assert_eq!(uniform(8, 1.0).step_deg(), 5.0);
    }

    #[test]
    fn an_rgb_spectrum_scales_by_its_luminance() {
        let unit = candela_per_unit(1.0, &json!("spectrum-1.csv"));
        assert!((unit / 72983.0 - 1.0).abs() < 2e-3, "{unit}");
        let grey = candela_per_unit(2.0, &json!({"rgb": [0.5, 0.5, 0.5]}));
        assert!((grey / unit - 1.0).abs() < 1e-4);
        let green = candela_per_unit(1.0, &json!({"rgb": [0.0, 1.0, 0.0]}));
        // IEC 61966-2-1 prints the weight as 0.7152; the matrix agrees to its digits.
        assert!((green / unit - 0.7152).abs() < 6e-5);
    }
}

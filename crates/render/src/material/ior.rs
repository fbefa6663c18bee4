//! Index of refraction of a dielectric relative to vacuum, evaluated per wavelength
//! (dispersion), from the scene's `ior` (prism-scene `Ior`). λ is in µm in the formulas,
//! as in the scene format and the glass catalogues.
//!
//! - Constant n.
//! - Sellmeier: n² = 1 + Σᵢ Bᵢ λ²/(λ² − Cᵢ) (Sellmeier 1871; Schott's catalogue form, Cᵢ in
//!   µm²). Schott N-BK7: B = (1.03961212, 0.231792344, 1.01046945), C = (0.00600069867,
//!   0.0200179144, 103.560653) µm², n_d(587.56 nm) = 1.5168. Fused silica (Malitson 1965,
//!   JOSA 55, 1205): B = (0.6961663, 0.4079426, 0.8974794), C = (0.0684043², 0.1162414²,
//!   9.896161²) µm², n_d = 1.4585.
//! - Cauchy: n = A + B/λ² (Cauchy 1836), B in µm².
//!
//! `validate` checks the formula over the whole spectral range 360–830 nm at build time:
//! a Sellmeier pole (λ² = Cᵢ) inside it, n² ≤ 0, n ≤ 0 or a non-finite n is an error.

use prism_scene::Ior as SceneIor;
use prism_spectrum::constants::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

/// A dielectric's index of refraction n(λ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ior {
    Constant(f32),
    /// n² = 1 + Σ Bᵢλ²/(λ² − Cᵢ), λ in µm, Cᵢ in µm².
    Sellmeier {
        b: [f32; 3],
        c_um2: [f32; 3],
    },
    /// n = A + B/λ², λ in µm, B in µm².
    Cauchy {
        a: f32,
        b_um2: f32,
    },
}

impl Ior {
    /// From the scene description, checked over 360–830 nm (`validate`); the error is a
    /// message for `materials.<name>.ior`.
    pub fn from_scene(ior: &SceneIor) -> Result<Self, String> {
        let out = match *ior {
            SceneIor::Constant(n) => Ior::Constant(n as f32),
            SceneIor::Sellmeier { b, c_um2 } => Ior::Sellmeier {
                b: b.map(|v| v as f32),
                c_um2: c_um2.map(|v| v as f32),
            },
            SceneIor::Cauchy { a, b_um2 } => Ior::Cauchy {
                a: a as f32,
                b_um2: b_um2 as f32,
            },
        };
        validate(ior)?;
        Ok(out)
    }

    /// n at one wavelength in nm (f64, for validation, tests and docs).
    pub fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        eval_scene_f64(&self.to_scene(), wavelength_nm)
    }

    fn to_scene(self) -> SceneIor {
        match self {
            Ior::Constant(n) => SceneIor::Constant(f64::from(n)),
            Ior::Sellmeier { b, c_um2 } => SceneIor::Sellmeier {
                b: b.map(f64::from),
                c_um2: c_um2.map(f64::from),
            },
            Ior::Cauchy { a, b_um2 } => SceneIor::Cauchy {
                a: f64::from(a),
                b_um2: f64::from(b_um2),
            },
        }
    }

    /// n at the four sampled wavelengths (each lane its own).
    #[inline]
    pub fn eval(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        let lambda_nm = wavelengths.lambda();
        match *self {
            Ior::Constant(n) => SampledSpectrum::splat(n),
            Ior::Sellmeier { b, c_um2 } => SampledSpectrum::from_fn(|l| {
                let l2 = (lambda_nm[l] * 1e-3).powi(2);
                let n2 = 1.0
                    + b[0] * l2 / (l2 - c_um2[0])
                    + b[1] * l2 / (l2 - c_um2[1])
                    + b[2] * l2 / (l2 - c_um2[2]);
                n2.sqrt()
            }),
            Ior::Cauchy { a, b_um2 } => SampledSpectrum::from_fn(|l| {
                let l_um = lambda_nm[l] * 1e-3;
                a + b_um2 / (l_um * l_um)
            }),
        }
    }

    /// True iff n varies with wavelength: a Cauchy B ≠ 0, or a Sellmeier term with both
    /// Bᵢ ≠ 0 and Cᵢ ≠ 0 (a term with Cᵢ = 0 adds the constant Bᵢ).
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        match *self {
            Ior::Constant(_) => false,
            Ior::Sellmeier { b, c_um2 } => (0..3).any(|i| b[i] != 0.0 && c_um2[i] != 0.0),
            Ior::Cauchy { b_um2, .. } => b_um2 != 0.0,
        }
    }
}

fn eval_scene_f64(ior: &SceneIor, wavelength_nm: f64) -> f64 {
    let l_um = wavelength_nm * 1e-3;
    match *ior {
        SceneIor::Constant(n) => n,
        SceneIor::Sellmeier { b, c_um2 } => {
            let l2 = l_um * l_um;
            (1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c_um2[i])).sum::<f64>()).sqrt()
        }
        SceneIor::Cauchy { a, b_um2 } => a + b_um2 / (l_um * l_um),
    }
}

/// Checks that n(λ) is a finite positive number at every wavelength of 360–830 nm (every
/// 0.5 nm, plus an exact test for Sellmeier poles between the samples) and in f32 range.
pub fn validate(ior: &SceneIor) -> Result<(), String> {
    let (lo, hi) = (f64::from(LAMBDA_MIN_NM), f64::from(LAMBDA_MAX_NM));
    if let SceneIor::Sellmeier { b, c_um2 } = ior {
        for i in 0..3 {
            if !(b[i].is_finite() && c_um2[i].is_finite()) {
                return Err(format!(
                    "Sellmeier coefficient B{} = {} or C{} = {} µm² is not a finite number",
                    i + 1,
                    b[i],
                    i + 1,
                    c_um2[i]
                ));
            }
            let pole_nm = c_um2[i].max(0.0).sqrt() * 1e3;
            if b[i] != 0.0 && (lo..=hi).contains(&pole_nm) {
                return Err(format!(
                    "the Sellmeier term {} has a pole at λ = √C{} = {pole_nm:.1} nm, inside the \
                     rendered range {lo}–{hi} nm (n² is unbounded there; check that C is in µm², \
                     not µm)",
                    i + 1,
                    i + 1
                ));
            }
        }
    }
    let steps = ((hi - lo) * 2.0) as usize;
    for s in 0..=steps {
        let wl = lo + s as f64 * 0.5;
        let n = eval_scene_f64(ior, wl);
        if !(n.is_finite() && n > 0.0 && n < f64::from(f32::MAX).sqrt()) {
            let why = match ior {
                SceneIor::Sellmeier { .. } => "n² = 1 + Σ Bλ²/(λ² − C) must be > 0",
                SceneIor::Cauchy { .. } => "n = A + B/λ² must be > 0",
                SceneIor::Constant(_) => "n must be > 0",
            };
            return Err(format!(
                "the index of refraction is {n} at {wl} nm ({why} over {lo}–{hi} nm)"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bk7() -> SceneIor {
        SceneIor::Sellmeier {
            b: [1.039_612_12, 0.231_792_344, 1.010_469_45],
            c_um2: [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
        }
    }

    fn fused_silica() -> SceneIor {
        SceneIor::Sellmeier {
            b: [0.696_166_3, 0.407_942_6, 0.897_479_4],
            c_um2: [
                0.068_404_3f64.powi(2),
                0.116_241_4f64.powi(2),
                9.896_161f64.powi(2),
            ],
        }
    }

    #[test]
    fn catalogue_glasses_at_the_helium_d_line() {
        // Schott datasheet N-BK7: n_d = 1.5168 at 587.56 nm; n_F (486.13) = 1.52238,
        // n_C (656.27) = 1.51432.
        let bk7 = Ior::from_scene(&bk7()).unwrap();
        assert!(
            (bk7.eval_nm(587.56) - 1.5168).abs() < 5e-5,
            "{}",
            bk7.eval_nm(587.56)
        );
        assert!((bk7.eval_nm(486.13) - 1.52238).abs() < 5e-5);
        assert!((bk7.eval_nm(656.27) - 1.51432).abs() < 5e-5);
        // Malitson 1965: fused silica n(587.6 nm) = 1.4585.
        let silica = Ior::from_scene(&fused_silica()).unwrap();
        assert!(
            (silica.eval_nm(587.6) - 1.4585).abs() < 1e-4,
            "{}",
            silica.eval_nm(587.6)
        );
        assert!(bk7.is_dispersive() && silica.is_dispersive());
        // The f32 per-lane path agrees with the f64 formula.
        let wl = SampledWavelengths::new([587.56, 400.0, 500.0, 800.0], SampledSpectrum::one());
        let lanes = bk7.eval(&wl);
        for (l, &nm) in wl.lambda().iter().enumerate() {
            assert!((f64::from(lanes[l]) - bk7.eval_nm(f64::from(nm))).abs() < 2e-6);
        }
    }

    #[test]
    fn cauchy_and_constant() {
        let c = Ior::from_scene(&SceneIor::Cauchy {
            a: 1.5,
            b_um2: 0.0042,
        })
        .unwrap();
        assert!((c.eval_nm(500.0) - (1.5 + 0.0042 / 0.25)).abs() < 1e-6); // f32 coefficients
        assert!(c.is_dispersive());
        let k = Ior::from_scene(&SceneIor::Constant(1.33)).unwrap();
        assert!(!k.is_dispersive());
        assert_eq!(
            k.eval(&SampledWavelengths::sample_uniform(0.3)),
            SampledSpectrum::splat(1.33)
        );
        // Sellmeier terms without a pole (C = 0) or without weight (B = 0) are constants.
        let flat = SceneIor::Sellmeier {
            b: [1.25, 0.0, 0.0],
            c_um2: [0.0, 0.5, 0.0],
        };
        let flat = Ior::from_scene(&flat).unwrap();
        assert!(!flat.is_dispersive());
        assert!((flat.eval_nm(400.0) - 1.5).abs() < 1e-6);
    }

    #[test]
    fn formulas_that_break_inside_the_visible_range_are_rejected() {
        // C given in µm instead of µm² puts the pole of term 3 at √10.17 µm… fine, but a
        // C₁ of 0.25 µm² puts it at 500 nm.
        let pole = SceneIor::Sellmeier {
            b: [1.0, 0.0, 0.0],
            c_um2: [0.25, 0.0, 0.0],
        };
        let e = Ior::from_scene(&pole).unwrap_err();
        assert!(e.contains("pole") && e.contains("500.0 nm"), "{e}");
        // n² < 0 without a pole in range: a large negative B.
        let negative = SceneIor::Sellmeier {
            b: [-3.0, 0.0, 0.0],
            c_um2: [0.01, 0.0, 0.0],
        };
        let e = Ior::from_scene(&negative).unwrap_err();
        assert!(e.contains("NaN") && e.contains("360 nm"), "{e}");
        // Cauchy going negative in the blue.
        let e = Ior::from_scene(&SceneIor::Cauchy {
            a: 0.1,
            b_um2: -0.2,
        })
        .unwrap_err();
        assert!(e.contains("must be > 0"), "{e}");
        let nan = SceneIor::Sellmeier {
            b: [f64::NAN, 0.0, 0.0],
            c_um2: [0.01, 0.0, 0.0],
        };
        assert!(Ior::from_scene(&nan).unwrap_err().contains("finite"));
    }
}

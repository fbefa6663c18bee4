//! Participating media (parsed now, rendered later): homogeneous, with absorption and
//! scattering coefficients and a Henyey–Greenstein phase function.

use crate::reader::{Result, V};
use crate::schema::schema;
use crate::spectrum_ref::{parse_spectrum, NamedSpectra, SpectrumRef, SpectrumUse};

#[derive(Debug, Clone, PartialEq)]
pub struct Medium {
    pub name: String,
    pub kind: MediumKind,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MediumKind {
    Homogeneous {
        /// Absorption coefficient σₐ in m⁻¹.
        sigma_a_per_m: SpectrumRef,
        /// Scattering coefficient σₛ in m⁻¹.
        sigma_s_per_m: SpectrumRef,
        /// Henyey–Greenstein asymmetry g in (−1, 1); 0 is isotropic.
        g: f64,
    },
}

pub(crate) fn parse_media(v: &V, spectra: &NamedSpectra) -> Result<Vec<Medium>> {
    let mut out = Vec::new();
    for (name, entry) in v.map()? {
        entry.tag("medium", &["homogeneous"], Some("homogeneous"))?;
        let o = entry.object(schema!("media.*<homogeneous>"))?;
        let coefficient = |key: &str| match o.get(key) {
            None => Ok(SpectrumRef::Constant(0.0)),
            Some(c) => parse_spectrum(&c, spectra, SpectrumUse::NonNegative),
        };
        let g = match o.get("g") {
            None => 0.0,
            Some(g_v) => {
                let g = g_v.f64()?;
                if g <= -1.0 || g >= 1.0 {
                    return Err(g_v.err(format!(
                        "expected a Henyey–Greenstein g in (-1, 1), found {g}"
                    )));
                }
                g
            }
        };
        out.push(Medium {
            name: name.to_string(),
            kind: MediumKind::Homogeneous {
                sigma_a_per_m: coefficient("sigma_a_per_m")?,
                sigma_s_per_m: coefficient("sigma_s_per_m")?,
                g,
            },
        });
    }
    Ok(out)
}

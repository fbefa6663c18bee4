//! A tile pyramid on disk (the cache of `prism tile-brdf`): the magic `PRISMBTF`, a version,
//! the layout (levels, rings, sectors, bands) and the arrays (Γ, its variance, τ, τ̄) as
//! little-endian f32. A file of another layout or a damaged one is an error, never a wrong
//! pyramid.

use super::bins::{RINGS, SECTORS};
use super::TilePyramid;
use crate::integrator::radiosity::patches::BANDS;

const MAGIC: &[u8; 8] = b"PRISMBTF";
const VERSION: u32 = 2;

impl TilePyramid {
    /// The pyramid as bytes (see the module).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(
            32 + 4
                * (self.gamma.len()
                    + self.gamma_variance.len()
                    + self.transparency.len()
                    + self.view_transparency.len()),
        );
        out.extend_from_slice(MAGIC);
        for v in [
            VERSION,
            self.levels,
            RINGS as u32,
            SECTORS as u32,
            BANDS as u32,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for x in self
            .gamma
            .iter()
            .chain(&self.gamma_variance)
            .chain(&self.transparency)
            .chain(&self.view_transparency)
        {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out
    }

    /// Reads what [`Self::to_bytes`] wrote; errors say what does not match.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        let header = 8 + 5 * 4;
        if bytes.len() < header || &bytes[..8] != MAGIC {
            return Err("not a Prism tile pyramid (no PRISMBTF header)".into());
        }
        let word = |k: usize| u32::from_le_bytes(bytes[8 + 4 * k..12 + 4 * k].try_into().unwrap());
        let (version, levels) = (word(0), word(1));
        if version != VERSION {
            return Err(format!(
                "pyramid file version {version}; this Prism reads {VERSION}"
            ));
        }
        if (word(2), word(3), word(4)) != (RINGS as u32, SECTORS as u32, BANDS as u32) {
            return Err(format!(
                "the file's bins ({} rings × {} sectors, {} bands) are not this Prism's ({RINGS} × \
                 {SECTORS}, {BANDS})",
                word(2),
                word(3),
                word(4)
            ));
        }
        if levels == 0 || levels > prism_scene::material::MAX_TILE_LEVELS {
            return Err(format!("{levels} levels"));
        }
        let cells = prism_radiosity::tile_cells::pyramid_cells(levels);
        let n_gamma = cells * super::SPHERE_BINS * super::SPHERE_BINS * BANDS;
        let n_tau = cells * super::SPHERE_BINS;
        let floats = 2 * n_gamma + 2 * n_tau;
        if bytes.len() != header + 4 * floats {
            return Err(format!(
                "{} bytes, expected {} for {levels} levels (truncated or damaged)",
                bytes.len(),
                header + 4 * floats
            ));
        }
        let values: Vec<f32> = bytes[header..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err("a value is negative or not finite (damaged)".into());
        }
        Ok(Self {
            levels,
            gamma: values[..n_gamma].to_vec(),
            gamma_variance: values[n_gamma..2 * n_gamma].to_vec(),
            transparency: values[2 * n_gamma..2 * n_gamma + n_tau].to_vec(),
            view_transparency: values[2 * n_gamma + n_tau..].to_vec(),
        })
    }
}

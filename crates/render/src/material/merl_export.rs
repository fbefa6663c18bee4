//! Writing any of our BSDFs as a MERL table (`prism merl-export`), so measured and analytic
//! paths can be compared on the same material.
//!
//! Each bin's midpoint (θ_h, θ_d, φ_d) becomes a pair of directions (`merl_directions`);
//! the material's BSDF (built at a neutral hit: normal +z, tangent +x) is evaluated there at
//! 48 wavelengths, the centres of 10 nm bands over 360–830 nm, and projected onto linear
//! sRGB with the reflectance weights of prism-spectrum (CIE 1931 × the sRGB white D65,
//! `RgbGamut::reflectance_rgb_weights`) summed over each band and renormalised so a flat
//! spectrum gives equal R = G = B exactly. A wavelength-independent material therefore
//! exports exactly; a coloured one goes through RGB (what the MERL format stores).

use glam::{Vec2, Vec3A};
use prism_geometry::SurfaceInteraction;
use prism_spectrum::{RgbGamut, SampledSpectrum, SampledWavelengths, LAMBDA_MIN_NM};

use super::Material;
use crate::bsdf::{merl_directions, MerlTable, TransportMode};

/// Width of the wavelength bands, nm.
const BAND_NM: usize = 10;
/// Bands over 360–830 nm (the last one is 830 alone, weighted by its 1 nm).
const BANDS: usize = 48;

/// A neutral hit for materials without textures: at the origin, normal +z, dP/du = +x.
pub fn neutral_hit() -> SurfaceInteraction {
    SurfaceInteraction {
        p: Vec3A::ZERO,
        t: 1.0,
        n_geometric: Vec3A::Z,
        n_shading: Vec3A::Z,
        uv: Vec2::ZERO,
        dpdu: Vec3A::X,
        dpdv: Vec3A::Y,
        dndu: Vec3A::ZERO,
        dndv: Vec3A::ZERO,
        curvature: Default::default(),
        differentials: Default::default(),
        primitive_id: 0,
        material_id: 0,
        object_id: 0,
        instance_id: 0,
    }
}

/// (band centre wavelengths, per-band RGB weights with each channel summing to 1).
fn bands() -> ([f32; BANDS], [[f64; 3]; BANDS]) {
    let dense = RgbGamut::Srgb.reflectance_rgb_weights();
    let mut centres = [0.0f32; BANDS];
    let mut weights = [[0.0f64; 3]; BANDS];
    for (i, w) in dense.iter().enumerate() {
        let b = (i / BAND_NM).min(BANDS - 1);
        for c in 0..3 {
            weights[b][c] += w[c];
        }
    }
    for (b, centre) in centres.iter_mut().enumerate() {
        let first = b * BAND_NM;
        let last = ((b + 1) * BAND_NM).min(dense.len()) - 1;
        *centre = LAMBDA_MIN_NM + 0.5 * (first + last) as f32;
    }
    for c in 0..3 {
        let sum: f64 = weights.iter().map(|w| w[c]).sum();
        for w in weights.iter_mut() {
            w[c] /= sum;
        }
    }
    (centres, weights)
}

/// The MERL table of `material` (its BSDF in radiance mode).
pub fn export_material(material: &Material) -> MerlTable {
    let hit = neutral_hit();
    let (centres, weights) = bands();
    let groups: Vec<SampledWavelengths> = centres
        .chunks_exact(4)
        .map(|l| SampledWavelengths::new([l[0], l[1], l[2], l[3]], SampledSpectrum::splat(1.0)))
        .collect();
    let bsdfs: Vec<_> = groups.iter().map(|g| material.bsdf(&hit, g)).collect();
    MerlTable::from_fn(|theta_h, theta_d, phi_d| {
        let (wi, wo) = merl_directions(theta_h, theta_d, phi_d);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return [0.0; 3];
        }
        let mut rgb = [0.0f64; 3];
        for (g, bsdf) in bsdfs.iter().enumerate() {
            let f = bsdf.eval(wo, wi, TransportMode::Radiance);
            for lane in 0..4 {
                let w = weights[4 * g + lane];
                for c in 0..3 {
                    rgb[c] += f64::from(f[lane]) * w[c];
                }
            }
        }
        rgb
    })
}

//! Direction bins over the sphere of a surface's frame (z = its normal): the paper's
//! "discrete decomposition of the hemisphere into bins" (Mostefaoui et al. §3), one set above
//! the surface and one below it for transmission. A tile's BRDF/BTDF pyramid and the
//! solution's directional patches (`directional.rs`) share them. Each hemisphere has `RINGS` rings of
//! equal solid angle (cos θ uniform) × `SECTORS` azimuth sectors, so every bin spans
//! 2π/(RINGS·SECTORS) sr.

use glam::{Vec2, Vec3A};

/// Rings per hemisphere (equal solid angle: cos θ steps of 1/RINGS).
pub const RINGS: usize = 4;
/// Azimuth sectors per ring.
pub const SECTORS: usize = 8;
/// Bins per hemisphere.
pub const HEMISPHERE_BINS: usize = RINGS * SECTORS;
/// Bins over the sphere: `0..HEMISPHERE_BINS` above the carrier (z > 0), the rest below.
pub const SPHERE_BINS: usize = 2 * HEMISPHERE_BINS;

/// The bin of a unit direction in the carrier's frame; z = 0 counts as above.
pub fn bin_of(w: Vec3A) -> usize {
    let below = w.z < 0.0;
    let mu = w.z.abs().min(1.0);
    // Ring 0 is the one around the normal (cos θ in (1 − 1/RINGS, 1]).
    let ring = (((1.0 - mu) * RINGS as f32) as usize).min(RINGS - 1);
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let sector = ((phi / std::f32::consts::TAU * SECTORS as f32) as usize).min(SECTORS - 1);
    usize::from(below) * HEMISPHERE_BINS + ring * SECTORS + sector
}

/// Whether a bin is above the carrier.
pub fn is_above(bin: usize) -> bool {
    bin < HEMISPHERE_BINS
}

/// A direction in `bin` from `u` ∈ [0, 1)², uniform in solid angle over the bin.
pub fn sample_in(bin: usize, u: Vec2) -> Vec3A {
    let (ring, sector) = ((bin % HEMISPHERE_BINS) / SECTORS, bin % SECTORS);
    let mu = 1.0 - (ring as f32 + u.x) / RINGS as f32;
    let phi = std::f32::consts::TAU * (sector as f32 + u.y) / SECTORS as f32;
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let z = if is_above(bin) { mu } else { -mu };
    Vec3A::new(s * phi.cos(), s * phi.sin(), z)
}

/// The bin's central direction (its cos θ and φ midpoints).
pub fn centre(bin: usize) -> Vec3A {
    sample_in(bin, Vec2::splat(0.5))
}

/// Solid angle of every bin, sr.
pub fn solid_angle_sr() -> f32 {
    2.0 * std::f32::consts::PI / HEMISPHERE_BINS as f32
}

/// ∫ |cos θ| dω over the bin, sr: (π/SECTORS)(μ_top² − μ_bottom²).
pub fn projected_solid_angle_sr(bin: usize) -> f32 {
    let ring = (bin % HEMISPHERE_BINS) / SECTORS;
    let top = 1.0 - ring as f32 / RINGS as f32;
    let bottom = 1.0 - (ring + 1) as f32 / RINGS as f32;
    std::f32::consts::PI / SECTORS as f32 * (top * top - bottom * bottom)
}

/// The bin a direction falls in after mirroring through the carrier plane (z → −z): the
/// bin of the same direction on the other side.
pub fn mirrored(bin: usize) -> usize {
    (bin + HEMISPHERE_BINS) % SPHERE_BINS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_fall_in_their_bin_and_bins_cover_the_sphere() {
        for bin in 0..SPHERE_BINS {
            for (a, b) in [(0.01, 0.01), (0.5, 0.5), (0.99, 0.99), (0.2, 0.8)] {
                let w = sample_in(bin, Vec2::new(a, b));
                assert!((w.length() - 1.0).abs() < 1e-5);
                assert_eq!(bin_of(w), bin, "{w}");
            }
        }
        let total: f32 = (0..HEMISPHERE_BINS).map(projected_solid_angle_sr).sum();
        assert!((total - std::f32::consts::PI).abs() < 1e-5, "{total}");
        assert_eq!(mirrored(mirrored(5)), 5);
        assert_eq!(
            bin_of(-centre(3) * Vec3A::new(-1.0, -1.0, 1.0)),
            mirrored(3)
        );
    }
}

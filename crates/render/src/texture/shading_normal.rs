//! Normal maps and bump maps: they replace the hit's shading normal (the BSDF frame is then
//! `Frame::from_zx(n_shading, dpdu)`, which re-projects dP/du onto the new tangent plane).
//!
//! Tangents: the tangent frame is (dP/du, n × dP/du, n) of the shading geometry. Meshes
//! give dP/du from their uv per triangle (pbrt-v4 `Triangle::InteractionFromIntersection`;
//! a mesh without uv gets pbrt's default parameterisation), analytic shapes their analytic
//! dP/du (sphere: along φ), so a tangent-space map is consistent across shapes.
//!
//! Shading-normal correction (what keeps energy and reciprocity sane): the integrator
//! refuses a scattered or light direction whose side of the *geometric* surface disagrees
//! with the BSDF's reflection/transmission choice in the shading frame (pbrt-v3 `BSDF::f`,
//! Veach 1997 §5.3), so no light leaks through the surface and a white Lambertian
//! under a normal map reflects at most what it receives (tested by the white furnace in
//! tests/textures.rs). For importance transport (light tracing, photons) Veach's adjoint
//! correction |ωo·ns||ωi·ng| / (|ωo·ng||ωi·ns|) would apply; Prism's path tracer carries
//! radiance only, so it is not needed yet. We did not implement the microfacet-based normal
//! mapping of Schüßler et al. 2017, which also removes the energy lost to black fringes.

use glam::{Vec2, Vec3A};
use prism_geometry::{Frame, SurfaceInteraction};

use super::{FloatTexture, TexelValue, Texture, TextureContext};

/// Sets `si.n_shading` from a tangent-space normal map: n_ts = 2·rgb − 1 (normalised) in the
/// frame (dP/du, n × dP/du, n) (pbrt-v4 `NormalMap`). A flat texel (0.5, 0.5, 1) leaves
/// the normal unchanged exactly. A map texel that is all zeros keeps the normal.
#[inline]
pub fn apply_normal_map(texture: &Texture, si: &mut SurfaceInteraction) {
    let TexelValue::Rgba(rgba) = texture.value(&TextureContext::from_interaction(si)) else {
        return;
    };
    let n_ts = Vec3A::new(
        2.0 * rgba[0] - 1.0,
        2.0 * rgba[1] - 1.0,
        2.0 * rgba[2] - 1.0,
    );
    let Some(n_ts) = n_ts.try_normalize() else {
        return;
    };
    let frame = Frame::from_zx(si.n_shading, si.dpdu);
    let n = frame.from_local(n_ts);
    if let Some(n) = n.try_normalize() {
        si.n_shading = n;
    }
}

/// Sets `si.n_shading` from the height field d = `scale_m` × texture (metres along the
/// shading normal) by forward differences in u and v (pbrt-v4 §10.5.2 `BumpMap`,
/// eq. 10.12): ∂p′/∂u ≈ ∂p/∂u + (d(u + Δu) − d(u))/Δu · n + d · ∂n/∂u, likewise in v,
/// n′ = ∂p′/∂u × ∂p′/∂v turned to the side of n. Δu is half the pixel footprint in u
/// (or 0.0005 without differentials).
#[inline]
pub fn apply_bump_map(height: &FloatTexture, scale_m: f32, si: &mut SurfaceInteraction) {
    let ctx = TextureContext::from_interaction(si);
    let d = &si.differentials;
    // Zero (no differentials) or NaN: pbrt-v4's fixed step.
    let step = |x: f32| if x > 0.0 { x } else { 0.0005 };
    let du = step(0.5 * (d.dudx.abs() + d.dudy.abs()));
    let dv = step(0.5 * (d.dvdx.abs() + d.dvdy.abs()));
    let texture = &height.texture;
    let shifted = |dp: Vec3A, duv: Vec2| {
        let c = TextureContext {
            p: ctx.p + dp,
            uv: ctx.uv + duv,
            ..ctx
        };
        scale_m * texture.scalar(&c)
    };
    let displace = scale_m * texture.scalar(&ctx);
    let u_displace = shifted(du * si.dpdu, Vec2::new(du, 0.0));
    let v_displace = shifted(dv * si.dpdv, Vec2::new(0.0, dv));
    let n = si.n_shading;
    let dpdu = si.dpdu + (u_displace - displace) / du * n + displace * si.dndu;
    let dpdv = si.dpdv + (v_displace - displace) / dv * n + displace * si.dndv;
    let Some(mut bumped) = dpdu.cross(dpdv).try_normalize() else {
        return;
    };
    if bumped.dot(n) < 0.0 {
        bumped = -bumped;
    }
    si.n_shading = bumped;
    si.dpdu = dpdu;
    si.dpdv = dpdv;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{ImageSource, MipMap, TextureSource, UvMapping};
    use prism_geometry::{LocalGeometry, Transform};
    use prism_scene::{ImageChannel, TextureFilter, WrapMode};
    use prism_spectrum::Spectrum;
    use std::sync::Arc;

    fn image(width: usize, texels: Vec<[f32; 4]>) -> Texture {
        Texture {
            mapping: UvMapping::identity(),
            source: TextureSource::Image(ImageSource {
                mip: MipMap::new(width, 1, texels, WrapMode::Clamp),
                filter: TextureFilter::Bilinear,
                channel: ImageChannel::R,
            }),
            a: Spectrum::constant(0.0),
            b: Spectrum::constant(0.0),
            a_scalar: 0.0,
            b_scalar: 0.0,
            place: "test".into(),
        }
    }

    /// A unit plane z = 0 with u along +x, v along +y, at uv.
    fn plane(uv: Vec2) -> SurfaceInteraction {
        let local = LocalGeometry {
            p: Vec3A::new(uv.x, uv.y, 0.0),
            n_geometric: Vec3A::Z,
            n_shading: Vec3A::Z,
            uv,
            dpdu: Vec3A::X,
            dpdv: Vec3A::Y,
            dndu: Vec3A::ZERO,
            dndv: Vec3A::ZERO,
        };
        SurfaceInteraction::from_local(&local, &Transform::IDENTITY, 1.0)
    }

    #[test]
    fn normal_map_x_follows_dpdu_and_flat_texels_change_nothing() {
        // Tangent-space normal (0.5, 0, √0.75): tilted 30° towards +u.
        let n = Vec3A::new(0.5, 0.0, 0.75f32.sqrt());
        let texel = [0.5 * (n.x + 1.0), 0.5 * (n.y + 1.0), 0.5 * (n.z + 1.0), 1.0];
        let mut si = plane(Vec2::splat(0.5));
        apply_normal_map(&image(1, vec![texel]), &mut si);
        assert!((si.n_shading - n).length() < 1e-6, "{}", si.n_shading);
        let mut flat = plane(Vec2::splat(0.5));
        let before = flat.n_shading;
        apply_normal_map(&image(1, vec![[0.5, 0.5, 1.0, 1.0]]), &mut flat);
        assert_eq!(flat.n_shading, before);
    }

    #[test]
    fn bump_map_of_a_ramp_tilts_the_normal_against_the_slope() {
        // Two texels 0 and 1, bilinear: between the texel centres (u ∈ [¼, ¾]) the height
        // is 2(u − ¼) × scale, slope 2·scale per unit u; n′ ∝ (−2·scale, 0, 1).
        let height = FloatTexture {
            texture: Arc::new(image(2, vec![[0.0; 4], [1.0, 1.0, 1.0, 1.0]])),
        };
        let scale = 0.1;
        let mut si = plane(Vec2::new(0.4, 0.5));
        apply_bump_map(&height, scale, &mut si);
        let expected = Vec3A::new(-2.0 * scale, 0.0, 1.0).normalize();
        assert!(
            (si.n_shading - expected).length() < 1e-4,
            "{}",
            si.n_shading
        );
        // A negative scale inverts the bumps.
        let mut si = plane(Vec2::new(0.4, 0.5));
        apply_bump_map(&height, -scale, &mut si);
        let expected = Vec3A::new(2.0 * scale, 0.0, 1.0).normalize();
        assert!(
            (si.n_shading - expected).length() < 1e-4,
            "{}",
            si.n_shading
        );
    }
}

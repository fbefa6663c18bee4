//! Importance and projection Jacobian shared by the perspective models, pinhole and thin
//! lens (pbrt-v3 §16.1.1 "Sampling cameras"; pbrt-v4 `PerspectiveCamera::We`, `PDF_We`).
//!
//! A ray from lens point L (camera space, on the lens plane z = 0) in direction ω, at angle
//! θ from the axis, meets the plane of sharp focus z = −d at L + ω (d + L_z)/cos θ; that
//! point scaled by f_px/d is the film offset (px, y up). For the pinhole L = 0 and any d
//! works (d = 1). Seen from L, a film patch dA (px²) spans dω = dA cos³θ / f_px² (the patch
//! is (d/f_px)² dA on the plane, at distance d/cos θ and tilted by θ), independent of L. So
//! the importance of every film point being equal, W_e |cos θ| = (dA/dω)/(W H A_lens) gives
//! pbrt-v4's W_e = f_px² / (W H · A_lens · cos⁴θ) (W H / f_px² is its image-plane area A
//! at distance 1), and `generate_ray`'s densities are pdf_pos = 1/A_lens (the concentric
//! disk map is area-preserving) and pdf_dir = f_px² / (W H cos³θ).

use glam::{Vec2, Vec3A};

use super::{CameraFrame, CameraImportance};

/// The film point (px, on the film) of the ray from `lens_point_m` in unit `direction`
/// through the plane z = −`plane_distance_m`, and cos θ; `None` off the film or backwards.
fn film_point(
    frame: &CameraFrame,
    focal_px: f32,
    plane_distance_m: f32,
    lens_point_m: Vec3A,
    direction: Vec3A,
) -> Option<(Vec2, f32)> {
    let cos_theta = -direction.z;
    if cos_theta.is_nan() || cos_theta <= 0.0 {
        return None;
    }
    let on_plane = lens_point_m + direction * ((plane_distance_m + lens_point_m.z) / cos_theta);
    let s = focal_px / plane_distance_m;
    let film = frame.film_from_offset_up_px(Vec2::new(on_plane.x * s, on_plane.y * s));
    frame.reaches(film).then_some((film, cos_theta))
}

/// W_e = f_px² / (W H · A_lens · cos⁴θ) and the film point (pbrt-v4 `PerspectiveCamera::We`).
pub(super) fn importance(
    frame: &CameraFrame,
    focal_px: f32,
    plane_distance_m: f32,
    lens_area_m2: f32,
    lens_point_m: Vec3A,
    direction: Vec3A,
) -> Option<CameraImportance> {
    let (film_point_px, cos_theta) =
        film_point(frame, focal_px, plane_distance_m, lens_point_m, direction)?;
    let size = frame.size_px();
    let cos2 = cos_theta * cos_theta;
    let importance = focal_px * focal_px / (size.x * size.y * lens_area_m2 * cos2 * cos2);
    importance.is_finite().then_some(CameraImportance {
        importance,
        film_point_px,
    })
}

/// (1/A_lens, f_px² / (W H cos³θ)) (pbrt-v4 `PerspectiveCamera::PDF_We`).
pub(super) fn pdf_we(
    frame: &CameraFrame,
    focal_px: f32,
    plane_distance_m: f32,
    lens_area_m2: f32,
    lens_point_m: Vec3A,
    direction: Vec3A,
) -> Option<(f32, f32)> {
    let (_, cos_theta) = film_point(frame, focal_px, plane_distance_m, lens_point_m, direction)?;
    let size = frame.size_px();
    let pdf_dir = focal_px * focal_px / (size.x * size.y * cos_theta * cos_theta * cos_theta);
    pdf_dir.is_finite().then_some((1.0 / lens_area_m2, pdf_dir))
}

/// Rows ∂(film x)/∂p, ∂(film y)/∂p of film = centre + f_px (p_x, −p_y)/(−p_z).
pub(super) fn project_jacobian(focal_px: f32, p: Vec3A) -> Option<[Vec3A; 2]> {
    (p.z < 0.0).then(|| {
        let inv_depth = 1.0 / -p.z;
        let s = focal_px * inv_depth;
        [
            s * Vec3A::new(1.0, 0.0, p.x * inv_depth),
            -s * Vec3A::new(0.0, 1.0, p.y * inv_depth),
        ]
    })
}

//! Surface interaction records (pbrt-v4 §6.1.4 / §4.3 `SurfaceInteraction`) with curvature and
//! ray-differential propagation (pbrt-v4 §10.1.1 `SurfaceInteraction::ComputeDifferentials`).

use glam::{Vec2, Vec3A};

use crate::curvature::{unit_normal_derivative, Curvature};
use crate::ray::RayDifferential;
use crate::transform::Transform;

/// Local differential geometry of a hit, as a shape computes it in its own (object) space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalGeometry {
    pub p: Vec3A,
    /// Geometric normal (unit).
    pub n_geometric: Vec3A,
    /// Shading normal, *not* normalised (interpolated vertex normal or analytic normal); the
    /// normal derivatives below are derivatives of this field.
    pub n_shading: Vec3A,
    pub uv: Vec2,
    pub dpdu: Vec3A,
    pub dpdv: Vec3A,
    pub dndu: Vec3A,
    pub dndv: Vec3A,
}

/// Screen-space derivatives of position and uv (pbrt-v4 `ComputeDifferentials`); zero when
/// the ray carries no differentials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Differentials {
    pub dpdx: Vec3A,
    pub dpdy: Vec3A,
    pub dudx: f32,
    pub dvdx: f32,
    pub dudy: f32,
    pub dvdy: f32,
}

/// Everything the renderer and the bandwidth predictor need at a hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// Hit position, m.
    pub p: Vec3A,
    /// Ray parameter of the hit (a distance in m when the ray direction is unit length).
    pub t: f32,
    /// Unit geometric normal (outward for closed shapes; faces the shading normal on meshes
    /// with vertex normals).
    pub n_geometric: Vec3A,
    /// Unit shading normal.
    pub n_shading: Vec3A,
    pub uv: Vec2,
    pub dpdu: Vec3A,
    pub dpdv: Vec3A,
    /// Derivatives of the (unnormalised) shading normal field, pbrt-v4 convention.
    pub dndu: Vec3A,
    pub dndv: Vec3A,
    /// Principal curvatures of the shading-normal field (see [`crate::curvature`]).
    pub curvature: Curvature,
    pub differentials: Differentials,
    /// Triangle index within its mesh (0 for analytic shapes).
    pub primitive_id: u32,
    /// Material index ([`crate::mesh::NO_MATERIAL`] when neither face nor instance names one).
    pub material_id: u32,
    /// Object index within the mesh (OBJ object/group), 0 for analytic shapes.
    pub object_id: u32,
    /// Instance index in the [`crate::Geometry`].
    pub instance_id: u32,
}

impl SurfaceInteraction {
    /// World-space interaction from object-space local geometry under `to_world`.
    pub fn from_local(local: &LocalGeometry, to_world: &Transform, t: f32) -> Self {
        Self::from_local_with(local, to_world, t, true)
    }

    /// As `from_local`; `with_curvature = false` leaves `curvature` at its default (zero)
    /// for callers that never read it (the path tracer's vertices after the first).
    pub fn from_local_with(
        local: &LocalGeometry,
        to_world: &Transform,
        t: f32,
        with_curvature: bool,
    ) -> Self {
        let (p, dpdu, dpdv, ng, ns, dndu, dndv) = if to_world.is_identity() {
            (
                local.p,
                local.dpdu,
                local.dpdv,
                local.n_geometric,
                local.n_shading,
                local.dndu,
                local.dndv,
            )
        } else {
            // pbrt-v4 §3.10.6: normals and their derivatives by the inverse transpose.
            let nm = to_world.normal_matrix();
            (
                to_world.point(local.p),
                to_world.vector(local.dpdu),
                to_world.vector(local.dpdv),
                nm * local.n_geometric,
                nm * local.n_shading,
                nm * local.dndu,
                nm * local.dndv,
            )
        };
        let n_geometric = ng.normalize_or_zero();
        let n_shading = ns.try_normalize().unwrap_or(n_geometric);
        let curvature = if with_curvature {
            Curvature::from_derivatives(
                dpdu,
                dpdv,
                unit_normal_derivative(ns, dndu),
                unit_normal_derivative(ns, dndv),
                n_shading,
            )
        } else {
            Curvature::default()
        };
        Self {
            p,
            t,
            n_geometric,
            n_shading,
            uv: local.uv,
            dpdu,
            dpdv,
            dndu,
            dndv,
            curvature,
            differentials: Differentials::default(),
            primitive_id: 0,
            material_id: crate::mesh::NO_MATERIAL,
            object_id: 0,
            instance_id: 0,
        }
    }

    /// Propagate the ray's differentials to the surface (pbrt-v4 §10.1.1): intersect the
    /// offset rays with the tangent plane for dp/dx, dp/dy, then solve the least-squares
    /// system `dp/dx = dp/du·du/dx + dp/dv·dv/dx` via its normal equations.
    pub fn compute_differentials(&mut self, ray: &RayDifferential) {
        let n = self.n_geometric;
        let (dx, dy) = (n.dot(ray.rx_direction), n.dot(ray.ry_direction));
        if dx == 0.0 || dy == 0.0 {
            self.differentials = Differentials::default();
            return;
        }
        let d = -n.dot(self.p);
        let tx = (-n.dot(ray.rx_origin) - d) / dx;
        let ty = (-n.dot(ray.ry_origin) - d) / dy;
        let px = ray.rx_origin + tx * ray.rx_direction;
        let py = ray.ry_origin + ty * ray.ry_direction;
        let dpdx = px - self.p;
        let dpdy = py - self.p;
        if !(dpdx.is_finite() && dpdy.is_finite()) {
            self.differentials = Differentials::default();
            return;
        }
        let ata00 = self.dpdu.dot(self.dpdu);
        let ata01 = self.dpdu.dot(self.dpdv);
        let ata11 = self.dpdv.dot(self.dpdv);
        let inv_det = 1.0 / (ata00 * ata11 - ata01 * ata01);
        let inv_det = if inv_det.is_finite() { inv_det } else { 0.0 };
        let (atb0x, atb1x) = (self.dpdu.dot(dpdx), self.dpdv.dot(dpdx));
        let (atb0y, atb1y) = (self.dpdu.dot(dpdy), self.dpdv.dot(dpdy));
        // Clamp as pbrt-v4 does so nearly degenerate parameterisations stay finite.
        let clamp = |x: f32| {
            if x.is_finite() {
                x.clamp(-1e8, 1e8)
            } else {
                0.0
            }
        };
        self.differentials = Differentials {
            dpdx,
            dpdy,
            dudx: clamp((ata11 * atb0x - ata01 * atb1x) * inv_det),
            dvdx: clamp((ata00 * atb1x - ata01 * atb0x) * inv_det),
            dudy: clamp((ata11 * atb0y - ata01 * atb1y) * inv_det),
            dvdy: clamp((ata00 * atb1y - ata01 * atb0y) * inv_det),
        };
    }
}

//! Differential geometry of a hit on a mesh triangle (pbrt-v4 §6.5.3
//! `Triangle::InteractionFromIntersection`).

use glam::{Vec2, Vec3A};

use crate::frame::Frame;
use crate::interaction::LocalGeometry;
use crate::mesh::TriangleMesh;

/// Local geometry of triangle `tri` of `mesh` at barycentrics `(b0, b1, b2)`.
///
/// Deviation from pbrt-v4: when the mesh's uvs are degenerate on this triangle, the
/// derivatives use pbrt's default parameterisation (0,0), (1,0), (1,1) instead of an
/// arbitrary tangent frame, so ∂n/∂u, ∂n/∂v (and thus curvature) remain true derivatives.
pub fn triangle_local_geometry(mesh: &TriangleMesh, tri: usize, b: [f32; 3]) -> LocalGeometry {
    let idx = mesh.indices[tri].map(|i| i as usize);
    let p = idx.map(|i| mesh.positions[i]);
    let default_uv = [Vec2::ZERO, Vec2::X, Vec2::ONE];
    let mesh_uv = mesh.uvs.as_ref().map(|uv| idx.map(|i| uv[i]));
    let uv = mesh_uv.unwrap_or(default_uv);

    let dp02 = p[0] - p[2];
    let dp12 = p[1] - p[2];
    let ng = dp02.cross(dp12).normalize_or_zero();

    // Solve [dp02 dp12] = [dpdu dpdv]·[duv02 duv12] (pbrt-v4 eq. 6.7).
    let solve = |uv: [Vec2; 3]| {
        let duv02 = uv[0] - uv[2];
        let duv12 = uv[1] - uv[2];
        let det = duv02.x * duv12.y - duv02.y * duv12.x;
        (det.abs() >= 1e-9).then(|| (duv02, duv12, 1.0 / det))
    };
    // The default parameterisation has duv02 = (−1, −1), duv12 = (0, −1), det = 1.
    let (duv02, duv12, inv_det) =
        solve(uv).unwrap_or((Vec2::new(-1.0, -1.0), Vec2::new(0.0, -1.0), 1.0));
    let mut dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv_det;
    let mut dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv_det;
    if dpdu.cross(dpdv).length_squared() == 0.0 {
        let f = Frame::from_z(if ng == Vec3A::ZERO { Vec3A::Z } else { ng });
        dpdu = f.x;
        dpdv = f.y;
    }
    let p_hit = b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
    let uv_hit = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];

    let (n_geometric, n_shading, dndu, dndv) = match &mesh.normals {
        Some(normals) => {
            let n = idx.map(|i| normals[i]);
            let ns = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
            if ns.length_squared() > 0.0 {
                let dn1 = n[0] - n[2];
                let dn2 = n[1] - n[2];
                let dndu = (duv12.y * dn1 - duv02.y * dn2) * inv_det;
                let dndv = (duv02.x * dn2 - duv12.x * dn1) * inv_det;
                // Geometric normal on the shading normal's side (pbrt-v4 FaceForward).
                let ng = if ng.dot(ns) < 0.0 { -ng } else { ng };
                (ng, ns, dndu, dndv)
            } else {
                (ng, ng, Vec3A::ZERO, Vec3A::ZERO)
            }
        }
        None => (ng, ng, Vec3A::ZERO, Vec3A::ZERO),
    };
    LocalGeometry {
        p: p_hit,
        n_geometric,
        n_shading,
        uv: uv_hit,
        dpdu,
        dpdv,
        dndu,
        dndv,
    }
}

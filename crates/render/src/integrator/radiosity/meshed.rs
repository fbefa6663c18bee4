//! Spheres and disks as radiosity patches: a sphere as a latitude–longitude triangle mesh,
//! a disk as a fan, both scaled to the shape's true area, and the map from a hit on the
//! analytic shape back to its triangle. A sphere's triangles lie partly inside it, so the
//! solution's rays start from their points lifted radially onto the surface.

use glam::Vec3A;
use prism_geometry::{Instance, Shape, Transform};
use prism_radiosity::ElementShape;

/// Latitude rings and longitude segments of a meshed sphere; segments of a disk's fan.
const SPHERE_RINGS: u32 = 12;
const SPHERE_SEGMENTS: u32 = 24;
const DISK_SEGMENTS: u32 = 32;

/// How an analytic instance is meshed.
#[derive(Clone, Debug, PartialEq)]
pub enum Meshing {
    /// `triangle[(ring · SPHERE_SEGMENTS + segment) · 2 + half]`: the primitive of each
    /// half of each latitude–longitude cell (`u32::MAX` where a pole collapses it).
    Sphere {
        triangle: Vec<u32>,
        to_world: Transform,
    },
    Disk {
        to_world: Transform,
    },
}

impl Meshing {
    /// The triangle holding world point `p` of the shape.
    pub fn primitive_at(&self, p: Vec3A) -> u32 {
        match self {
            Meshing::Sphere { triangle, to_world } => {
                let q = to_world.inverse_point(p).normalize_or_zero();
                let (theta, phi) = spherical(q);
                let rings = SPHERE_RINGS as f32;
                let segments = SPHERE_SEGMENTS as f32;
                let v = theta / std::f32::consts::PI * rings;
                let u = phi / std::f32::consts::TAU * segments;
                let ring = (v as u32).min(SPHERE_RINGS - 1);
                let segment = (u as u32).min(SPHERE_SEGMENTS - 1);
                // The cell's diagonal runs from (ring, segment) to (ring + 1, segment + 1).
                let below_diagonal = v.fract() >= u.fract();
                let cell = ((ring * SPHERE_SEGMENTS + segment) * 2) as usize;
                let (a, b) = (triangle[cell], triangle[cell + 1]);
                match (below_diagonal, a, b) {
                    (true, a, _) if a != u32::MAX => a,
                    (false, _, b) if b != u32::MAX => b,
                    (_, a, b) => a.min(b),
                }
            }
            Meshing::Disk { to_world } => {
                let q = to_world.inverse_point(p);
                let phi = q.y.atan2(q.x).rem_euclid(std::f32::consts::TAU);
                ((phi / std::f32::consts::TAU * DISK_SEGMENTS as f32) as u32).min(DISK_SEGMENTS - 1)
            }
        }
    }
}

/// A meshed sphere in world space, for lifting its patches' points onto it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiftSphere {
    pub centre: Vec3A,
    pub radius_m: f32,
}

impl LiftSphere {
    /// `p` (a point of one of the sphere's triangles, normal `n`) moved radially onto the
    /// surface, just outside it; `None` when `p` is not such a point.
    pub fn lift(&self, p: Vec3A, n: Vec3A) -> Option<Vec3A> {
        let d = p - self.centre;
        let r = d.length();
        let radial = d / r.max(1e-30);
        (r > 0.8 * self.radius_m && r < 1.05 * self.radius_m && radial.dot(n) > 0.9)
            .then(|| self.centre + radial * self.radius_m * (1.0 + 1e-4))
    }
}

/// Polar angle from +z and azimuth in [0, 2π) of unit `q`.
fn spherical(q: Vec3A) -> (f32, f32) {
    (
        q.z.clamp(-1.0, 1.0).acos(),
        q.y.atan2(q.x).rem_euclid(std::f32::consts::TAU),
    )
}

/// The world triangles of `instance` (a sphere or a disk) with their object-space outward
/// normals, how a hit finds its triangle, and the sphere to lift points onto; an error
/// for a sphere under a non-uniform scale (an ellipsoid).
#[allow(clippy::type_complexity)]
pub fn mesh_analytic(
    instance_id: usize,
    instance: &Instance,
) -> Result<(Vec<(ElementShape, Vec3A)>, Meshing, Option<LiftSphere>), String> {
    let t = instance.to_world;
    let world = |p: Vec3A| t.point(p);
    match instance.shape {
        Shape::Sphere(s) => {
            let scale = [Vec3A::X, Vec3A::Y, Vec3A::Z].map(|a| t.vector(a).length());
            if (scale[0] - scale[1]).abs() > 1e-4 * scale[0]
                || (scale[0] - scale[2]).abs() > 1e-4 * scale[0]
            {
                return Err(format!(
                    "instance {instance_id} is a sphere under a non-uniform scale (an \
                     ellipsoid): `radiosity` meshes spheres under a uniform scale only"
                ));
            }
            let vertex = |ring: u32, segment: u32| {
                let theta = std::f32::consts::PI * ring as f32 / SPHERE_RINGS as f32;
                let phi = std::f32::consts::TAU * segment as f32 / SPHERE_SEGMENTS as f32;
                Vec3A::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ) * s.radius_m
            };
            let mut triangles: Vec<[Vec3A; 3]> = Vec::new();
            let mut triangle = vec![u32::MAX; (SPHERE_RINGS * SPHERE_SEGMENTS * 2) as usize];
            for ring in 0..SPHERE_RINGS {
                for segment in 0..SPHERE_SEGMENTS {
                    let (a, b) = (vertex(ring, segment), vertex(ring, segment + 1));
                    let (c, d) = (vertex(ring + 1, segment), vertex(ring + 1, segment + 1));
                    let cell = ((ring * SPHERE_SEGMENTS + segment) * 2) as usize;
                    // Below the diagonal a–d (towards the next ring): a, c, d; above: a, d, b.
                    if ring + 1 < SPHERE_RINGS {
                        triangle[cell] = triangles.len() as u32;
                        triangles.push([a, c, d]);
                    }
                    if ring > 0 {
                        triangle[cell + 1] = triangles.len() as u32;
                        triangles.push([a, d, b]);
                    }
                }
            }
            // Scaled about the centre to the sphere's area 4πr² (the inscribed mesh has less).
            let area: f32 = triangles
                .iter()
                .map(|p| 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length())
                .sum();
            let k = (4.0 * std::f32::consts::PI * s.radius_m * s.radius_m / area).sqrt();
            let pieces = triangles
                .iter()
                .map(|p| {
                    let w = p.map(|v| world(v * k));
                    let outward = (p[0] + p[1] + p[2]).normalize_or_zero();
                    let shape = ElementShape::Triangle {
                        p0: w[0],
                        e1: w[1] - w[0],
                        e2: w[2] - w[0],
                    };
                    (shape, outward)
                })
                .collect();
            let lift = LiftSphere {
                centre: world(Vec3A::ZERO),
                radius_m: s.radius_m * scale[0],
            };
            Ok((
                pieces,
                Meshing::Sphere {
                    triangle,
                    to_world: t,
                },
                Some(lift),
            ))
        }
        Shape::Disk(d) => {
            // A regular polygon of the disk's area πr².
            let n = DISK_SEGMENTS as f32;
            let polygon_area = 0.5 * n * (std::f32::consts::TAU / n).sin();
            let r = d.radius_m * (std::f32::consts::PI / polygon_area).sqrt();
            let rim = |k: u32| {
                let phi = std::f32::consts::TAU * k as f32 / n;
                Vec3A::new(phi.cos(), phi.sin(), 0.0) * r
            };
            let pieces = (0..DISK_SEGMENTS)
                .map(|k| {
                    let w = [Vec3A::ZERO, rim(k), rim(k + 1)].map(world);
                    let shape = ElementShape::Triangle {
                        p0: w[0],
                        e1: w[1] - w[0],
                        e2: w[2] - w[0],
                    };
                    (shape, Vec3A::Z)
                })
                .collect();
            Ok((pieces, Meshing::Disk { to_world: t }, None))
        }
        Shape::Rectangle(_) | Shape::Mesh(_) | Shape::Tiled(_) => Err(format!(
            "instance {instance_id}: internal error: only spheres and disks are meshed here"
        )),
    }
}

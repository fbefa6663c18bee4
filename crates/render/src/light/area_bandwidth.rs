//! ν_s of an area light over its emitting surface (Bagher et al. 2013 §2.3, "area
//! lights"): eq. 7 of the emission over the emitter, zero-padded to twice its size so that
//! the outline is an edge (`Boundary::ZeroPadDouble`). Prism's emitters radiate uniformly, so
//! the signal is the outline's coverage on a grid of [`GRID_TEXELS`] texels along its longer
//! side (4 × 4 coverage samples per texel). ν_s is then highest at the outline (the grid's
//! limit β/Δ) and falls with the distance to it: ≈ 0.98/L at the centre of a square of side L.
//! Built only when the predictor runs, once per area light. Per shape:
//! - rectangle and disk: the outline in their local plane; a world point is mapped back by
//!   the inverse placement, texels scaled by the placement's √(area scale);
//! - a planar mesh (every triangle within 2° of one plane): the plane of its triangles in
//!   mesh space, per instance;
//! - a sphere placed by a similarity: its silhouette, a disk of its radius across the
//!   direction it is seen from;
//! - a curved mesh or an ellipsoid: none here, the closed form 1/√A (`bandwidth.rs`).

use glam::{Vec2, Vec3A};
use prism_bandwidth::local_bandwidth::{Boundary, LocalBandwidth};
use prism_geometry::Transform;

use super::area::{AreaShape, MeshEmitter};
use super::AreaLight;

/// Texels along the outline's longer side (the zero-padded field is twice as wide).
pub const GRID_TEXELS: u32 = 64;
/// Coverage samples per texel side.
const COVERAGE_SAMPLES: u32 = 4;
/// A mesh is planar when every triangle's normal is within this of the mean (cos 2°).
const PLANAR_COS: f32 = 0.999_39;

/// Per point of an area light, its spatial bandwidth in cycles/m.
#[derive(Clone, Debug)]
pub struct AreaLightBandwidth {
    grid: OutlineGrid,
    placement: OutlinePlacement,
}

/// Eq. 7 over the outline's coverage, in the outline's own 2-D coordinates.
#[derive(Clone, Debug)]
struct OutlineGrid {
    /// The grid's lower corner, outline units.
    min: Vec2,
    /// Outline units per texel.
    texel: f32,
    width: u32,
    height: u32,
    cycles_per_texel: Vec<f32>,
}

#[derive(Clone, Debug)]
enum OutlinePlacement {
    /// A flat outline placed once per instance (one for a rectangle or a disk).
    Planar(Vec<PlaneMap>),
    /// A sphere's silhouette disk, centred on `centre_m`; outline units are metres.
    Silhouette { centre_m: Vec3A },
}

/// World → the outline's 2-D coordinates for one placement.
#[derive(Clone, Debug)]
struct PlaneMap {
    world_to_local: Transform,
    /// The outline plane in local space: a point on it and its axes (unit, orthogonal).
    origin: Vec3A,
    axis_u: Vec3A,
    axis_v: Vec3A,
    normal: Vec3A,
    /// Metres per outline unit: √ of the placement's area scale in the plane.
    metres_per_unit: f32,
}

impl PlaneMap {
    fn new(to_world: &Transform, origin: Vec3A, axis_u: Vec3A, axis_v: Vec3A) -> Option<Self> {
        let area_scale = to_world
            .vector(axis_u)
            .cross(to_world.vector(axis_v))
            .length();
        (area_scale.is_finite() && area_scale > 0.0).then(|| Self {
            world_to_local: to_world.inverse(),
            origin,
            axis_u,
            axis_v,
            normal: axis_u.cross(axis_v),
            metres_per_unit: area_scale.sqrt(),
        })
    }

    /// The point's outline coordinates and its distance off the plane (local units).
    fn project(&self, p_world: Vec3A) -> (Vec2, f32) {
        let q = self.world_to_local.point(p_world) - self.origin;
        (
            Vec2::new(q.dot(self.axis_u), q.dot(self.axis_v)),
            q.dot(self.normal).abs(),
        )
    }
}

impl AreaLightBandwidth {
    /// Eq. 7 over `light`'s outline; `None` where the closed form stands (module docs).
    pub fn new(light: &AreaLight) -> Result<Option<Self>, String> {
        let built = match &light.shape {
            AreaShape::Rectangle(r) => {
                let half = Vec2::new(r.rectangle.half_width_m, r.rectangle.half_height_m);
                planar_outline(&r.to_world, -half, half, |p| {
                    p.x.abs() <= half.x && p.y.abs() <= half.y
                })?
            }
            AreaShape::Disk(d) => {
                let r = d.disk.radius_m;
                planar_outline(&d.to_world, Vec2::splat(-r), Vec2::splat(r), |p| {
                    p.length_squared() <= r * r
                })?
            }
            AreaShape::Sphere(s) => match s.world_centre_and_radius_m() {
                Some((centre_m, r)) => {
                    OutlineGrid::rasterise(Vec2::splat(-r), Vec2::splat(r), |p| {
                        p.length_squared() <= r * r
                    })?
                    .map(|grid| (grid, OutlinePlacement::Silhouette { centre_m }))
                }
                None => None,
            },
            AreaShape::Mesh(m) => planar_mesh(m)?,
        };
        Ok(built.map(|(grid, placement)| Self { grid, placement }))
    }

    /// ν_s at `p_m` on the emitter, seen along `wi` (towards the light), cycles/m; `None`
    /// when the point lies on no placement of the outline (off the emitter).
    pub fn at(&self, p_m: Vec3A, wi: Vec3A) -> Option<f32> {
        match &self.placement {
            OutlinePlacement::Planar(maps) => {
                let tolerance = 1e-3 * self.grid.extent();
                maps.iter()
                    .map(|map| (map, map.project(p_m)))
                    .filter(|(_, (uv, off))| *off <= tolerance && self.grid.contains(*uv))
                    .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
                    .map(|(map, (uv, _))| self.grid.cycles_per_unit(uv) / map.metres_per_unit)
            }
            OutlinePlacement::Silhouette { centre_m } => {
                let (u, v) = wi.normalize_or_zero().any_orthonormal_pair();
                let q = p_m - *centre_m;
                Some(self.grid.cycles_per_unit(Vec2::new(q.dot(u), q.dot(v))))
            }
        }
    }
}

/// A rectangle's or a disk's outline in its local plane z = 0, placed once.
fn planar_outline(
    to_world: &Transform,
    min: Vec2,
    max: Vec2,
    inside: impl Fn(Vec2) -> bool,
) -> Result<Option<(OutlineGrid, OutlinePlacement)>, String> {
    let Some(map) = PlaneMap::new(to_world, Vec3A::ZERO, Vec3A::X, Vec3A::Y) else {
        return Ok(None);
    };
    Ok(OutlineGrid::rasterise(min, max, inside)?
        .map(|grid| (grid, OutlinePlacement::Planar(vec![map]))))
}

/// A mesh emitter whose triangles lie in one plane (in mesh space): the grid over their
/// projection and one map per instance; `None` for a curved mesh.
fn planar_mesh(m: &MeshEmitter) -> Result<Option<(OutlineGrid, OutlinePlacement)>, String> {
    let mesh = m.mesh();
    let triangles: Vec<[Vec3A; 3]> = (0..mesh.indices.len()).map(|i| mesh.triangle(i)).collect();
    let Some(first) = triangles.first() else {
        return Ok(None);
    };
    // Area-weighted normal with each triangle turned to the first one's side (an
    // inconsistently wound panel is still flat).
    let reference = (first[1] - first[0]).cross(first[2] - first[0]);
    let crosses: Vec<Vec3A> = triangles
        .iter()
        .map(|t| (t[1] - t[0]).cross(t[2] - t[0]))
        .map(|c| if c.dot(reference) < 0.0 { -c } else { c })
        .collect();
    let normal = crosses.iter().copied().sum::<Vec3A>().normalize_or_zero();
    if normal == Vec3A::ZERO {
        return Ok(None);
    }
    let origin = first[0];
    let (lo, hi) = triangles.iter().flatten().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let flatness = 1e-4 * (hi - lo).length();
    let planar = crosses
        .iter()
        .filter(|c| c.length_squared() > 0.0)
        .all(|c| c.normalize().dot(normal) >= PLANAR_COS)
        && triangles
            .iter()
            .flatten()
            .all(|&p| (p - origin).dot(normal).abs() <= flatness);
    if !planar {
        return Ok(None);
    }
    let (axis_u, axis_v) = normal.any_orthonormal_pair();
    let flat: Vec<[Vec2; 3]> = triangles
        .iter()
        .map(|t| t.map(|p| Vec2::new((p - origin).dot(axis_u), (p - origin).dot(axis_v))))
        .collect();
    let (min, max) = flat.iter().flatten().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let maps: Vec<PlaneMap> = m
        .instance_transforms()
        .filter_map(|t| PlaneMap::new(t, origin, axis_u, axis_v))
        .collect();
    if maps.is_empty() {
        return Ok(None);
    }
    let Some(grid) = OutlineGrid::rasterise_triangles(min, max, &flat)? else {
        return Ok(None);
    };
    Ok(Some((grid, OutlinePlacement::Planar(maps))))
}

impl OutlineGrid {
    /// A grid over [min, max] of [`GRID_TEXELS`] along the longer side, square texels.
    fn layout(min: Vec2, max: Vec2) -> Option<(f32, u32, u32)> {
        let size = max - min;
        let longer = size.max_element();
        if !(longer.is_finite() && longer > 0.0) {
            return None;
        }
        let texel = longer / GRID_TEXELS as f32;
        let cells = |extent: f32| ((extent / texel).ceil() as u32).clamp(1, GRID_TEXELS);
        Some((texel, cells(size.x), cells(size.y)))
    }

    /// The coverage of `inside` (sampled 4 × 4 per texel) reduced by eq. 7.
    fn rasterise(
        min: Vec2,
        max: Vec2,
        inside: impl Fn(Vec2) -> bool,
    ) -> Result<Option<Self>, String> {
        let Some((texel, width, height)) = Self::layout(min, max) else {
            return Ok(None);
        };
        let step = texel / COVERAGE_SAMPLES as f32;
        let (sw, sh) = (width * COVERAGE_SAMPLES, height * COVERAGE_SAMPLES);
        let covered: Vec<bool> = (0..sh)
            .flat_map(|y| (0..sw).map(move |x| (x, y)))
            .map(|(x, y)| inside(min + step * Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
            .collect();
        Self::from_samples(min, texel, width, height, &covered).map(Some)
    }

    /// The coverage of 2-D triangles (their union) reduced by eq. 7.
    fn rasterise_triangles(
        min: Vec2,
        max: Vec2,
        triangles: &[[Vec2; 3]],
    ) -> Result<Option<Self>, String> {
        let Some((texel, width, height)) = Self::layout(min, max) else {
            return Ok(None);
        };
        let step = texel / COVERAGE_SAMPLES as f32;
        let (sw, sh) = (width * COVERAGE_SAMPLES, height * COVERAGE_SAMPLES);
        let mut covered = vec![false; (sw * sh) as usize];
        let edge = |a: Vec2, b: Vec2, p: Vec2| (b - a).perp_dot(p - a);
        for &[a, b, c] in triangles {
            let doubled_area = edge(a, b, c);
            if doubled_area == 0.0 {
                continue;
            }
            let lo = ((a.min(b).min(c) - min) / step).floor().max(Vec2::ZERO);
            let hi = ((a.max(b).max(c) - min) / step).ceil();
            for y in lo.y as u32..(hi.y as u32).min(sh) {
                for x in lo.x as u32..(hi.x as u32).min(sw) {
                    let p = min + step * Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let w = [edge(b, c, p), edge(c, a, p), edge(a, b, p)];
                    if w.iter().all(|&w| w * doubled_area >= 0.0) {
                        covered[(y * sw + x) as usize] = true;
                    }
                }
            }
        }
        Self::from_samples(min, texel, width, height, &covered).map(Some)
    }

    fn from_samples(
        min: Vec2,
        texel: f32,
        width: u32,
        height: u32,
        covered: &[bool],
    ) -> Result<Self, String> {
        let sw = (width * COVERAGE_SAMPLES) as usize;
        let per_texel = (COVERAGE_SAMPLES * COVERAGE_SAMPLES) as f32;
        let coverage: Vec<f32> = (0..height as usize)
            .flat_map(|y| (0..width as usize).map(move |x| (x, y)))
            .map(|(x, y)| {
                let s = COVERAGE_SAMPLES as usize;
                (0..s)
                    .flat_map(|j| (0..s).map(move |i| (y * s + j) * sw + x * s + i))
                    .filter(|&k| covered[k])
                    .count() as f32
                    / per_texel
            })
            .collect();
        let local = LocalBandwidth::estimate(
            &coverage,
            glam::UVec2::new(width, height),
            1.0,
            Boundary::ZeroPadDouble,
        )
        .map_err(|e| format!("area light bandwidth: {e}"))?;
        Ok(Self {
            min,
            texel,
            width,
            height,
            cycles_per_texel: local.cycles_per_unit().to_vec(),
        })
    }

    /// The longer side, outline units.
    fn extent(&self) -> f32 {
        self.texel * self.width.max(self.height) as f32
    }

    /// Inside the grid, with one texel of slack for round-off at the outline.
    fn contains(&self, uv: Vec2) -> bool {
        let t = (uv - self.min) / self.texel;
        t.x >= -1.0
            && t.y >= -1.0
            && t.x <= (self.width + 1) as f32
            && t.y <= (self.height + 1) as f32
    }

    /// Cycles per outline unit at `uv` (clamped to the grid).
    fn cycles_per_unit(&self, uv: Vec2) -> f32 {
        let t = (uv - self.min) / self.texel;
        let x = (t.x.max(0.0) as u32).min(self.width - 1);
        let y = (t.y.max(0.0) as u32).min(self.height - 1);
        self.cycles_per_texel[(y * self.width + x) as usize] / self.texel
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::area::{DiskEmitter, EmitterMesh, RectangleEmitter, SphereEmitter};
    use prism_geometry::{Disk, Rectangle, Sphere};
    use prism_spectrum::Spectrum;
    use std::sync::Arc;

    fn light(shape: AreaShape) -> AreaLight {
        AreaLight {
            shape,
            radiance: Spectrum::constant(1.0),
            two_sided: false,
        }
    }

    fn square(side_m: f32, to_world: Transform) -> AreaLight {
        light(AreaShape::Rectangle(RectangleEmitter::new(
            Rectangle {
                half_width_m: 0.5 * side_m,
                half_height_m: 0.5 * side_m,
            },
            to_world,
        )))
    }

    #[test]
    fn a_square_is_one_over_its_side_at_the_centre_and_sharpest_at_its_outline() {
        for side_m in [0.25f32, 2.0] {
            let map = AreaLightBandwidth::new(&square(side_m, Transform::IDENTITY))
                .unwrap()
                .unwrap();
            let centre = map.at(Vec3A::ZERO, -Vec3A::Z).unwrap() * side_m;
            // Eq. 7 answers the centre with the level whose half-width reaches the outline.
            assert!(
                (0.9..1.1).contains(&centre),
                "centre {centre} cycles per side"
            );
            let edge = map
                .at(Vec3A::new(0.499 * side_m, 0.0, 0.0), -Vec3A::Z)
                .unwrap()
                * side_m;
            let beta = prism_bandwidth::local_bandwidth::HAAR_BETA_CYCLES_PER_TEXEL;
            assert!(
                (edge - beta * GRID_TEXELS as f32).abs() < 1e-3 * edge,
                "edge {edge} cycles per side"
            );
            // Between the two from the outline inwards (not strictly monotone: eq. 7's
            // levels are octaves, refined by a parabola), and far below the outline's
            // value once a quarter side in.
            let along: Vec<f32> = (0..=10)
                .map(|k| {
                    let x = side_m * (0.499 - 0.049 * k as f32);
                    map.at(Vec3A::new(x, 0.0, 0.0), -Vec3A::Z).unwrap() * side_m
                })
                .collect();
            assert!(
                along.iter().all(|&v| v <= edge && v >= 0.99 * centre)
                    && along[5..].iter().all(|&v| v < 0.1 * edge),
                "{along:?}"
            );
            // Off the emitter: no answer.
            assert!(map.at(Vec3A::new(0.0, 0.0, 0.1), -Vec3A::Z).is_none());
        }
    }

    #[test]
    fn placement_scales_and_moves_the_map() {
        let base = AreaLightBandwidth::new(&square(1.0, Transform::IDENTITY))
            .unwrap()
            .unwrap();
        let placed = Transform::translate(Vec3A::new(1.0, 2.0, 3.0))
            .compose(&Transform::rotate(Vec3A::X, 1.0).unwrap())
            .compose(&Transform::scale(Vec3A::new(3.0, 3.0, 1.0)).unwrap());
        let map = AreaLightBandwidth::new(&square(1.0, placed))
            .unwrap()
            .unwrap();
        for local in [
            Vec3A::ZERO,
            Vec3A::new(0.3, -0.2, 0.0),
            Vec3A::new(0.49, 0.1, 0.0),
        ] {
            let a = base.at(local, -Vec3A::Z).unwrap();
            let b = map.at(placed.point(local), -Vec3A::Z).unwrap();
            assert!((b * 3.0 - a).abs() < 1e-4 * a, "{local}: {a} vs 3 × {b}");
        }
    }

    #[test]
    fn a_disk_a_flat_mesh_and_a_sphere_have_their_outlines() {
        let disk = AreaLightBandwidth::new(&light(AreaShape::Disk(DiskEmitter::new(
            Disk { radius_m: 0.5 },
            Transform::IDENTITY,
        ))))
        .unwrap()
        .unwrap();
        let centre = disk.at(Vec3A::ZERO, -Vec3A::Z).unwrap();
        let rim = disk.at(Vec3A::new(0.0, 0.499, 0.0), -Vec3A::Z).unwrap();
        assert!(
            (0.8..1.2).contains(&centre) && rim > 20.0 * centre,
            "{centre} {rim}"
        );

        // The unit square as two triangles (opposite windings) in the plane y = 2.
        let positions = [
            [0.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
            [1.0, 2.0, 1.0],
            [0.0, 2.0, 1.0],
        ]
        .map(Vec3A::from_array)
        .to_vec();
        let mesh = Arc::new(EmitterMesh {
            positions,
            indices: vec![[0, 1, 2], [0, 3, 2]],
            normals: None,
        });
        let shift = Transform::translate(Vec3A::new(5.0, 0.0, 0.0));
        let flat = AreaLightBandwidth::new(&light(AreaShape::Mesh(MeshEmitter::new(
            mesh,
            &[Transform::IDENTITY, shift],
        ))))
        .unwrap()
        .expect("a flat mesh has a map");
        let square = AreaLightBandwidth::new(&square(1.0, Transform::IDENTITY))
            .unwrap()
            .unwrap();
        for (x, z) in [(0.5, 0.5), (0.2, 0.7), (0.999, 0.5)] {
            let expected = square
                .at(Vec3A::new(x - 0.5, z - 0.5, 0.0), -Vec3A::Z)
                .unwrap();
            for dx in [0.0, 5.0] {
                let got = flat.at(Vec3A::new(x + dx, 2.0, z), Vec3A::Y).unwrap();
                assert!(
                    (got - expected).abs() < 0.05 * expected,
                    "{x},{z}+{dx}: {got} {expected}"
                );
            }
        }

        let sphere = AreaLightBandwidth::new(&light(AreaShape::Sphere(SphereEmitter::new(
            Sphere { radius_m: 0.5 },
            Transform::translate(Vec3A::new(0.0, 0.0, 4.0)),
        ))))
        .unwrap()
        .unwrap();
        // Seen from the origin: the point facing the viewer is the silhouette's centre, a
        // point on the limb its outline.
        let facing = sphere.at(Vec3A::new(0.0, 0.0, 3.5), Vec3A::Z).unwrap();
        let limb = sphere.at(Vec3A::new(0.4995, 0.0, 4.0), Vec3A::Z).unwrap();
        assert!((facing - centre).abs() < 0.05 * centre && limb > 20.0 * facing);
    }

    #[test]
    fn a_curved_mesh_keeps_the_closed_form() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ]
        .map(Vec3A::from_array)
        .to_vec();
        let mesh = Arc::new(EmitterMesh {
            positions,
            indices: vec![[0, 1, 2], [0, 1, 3]],
            normals: None,
        });
        let curved = light(AreaShape::Mesh(MeshEmitter::new(
            mesh,
            &[Transform::IDENTITY],
        )));
        assert!(AreaLightBandwidth::new(&curved).unwrap().is_none());
    }
}

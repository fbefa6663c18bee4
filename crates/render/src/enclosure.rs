//! Scenes that render black without an error, found by tracing a few rays before the
//! render: the camera inside a closed shape whose one-sided material faces away from it
//! (it sees the back of every face, which reflects nothing), and a light inside a closed
//! opaque shape that the camera is outside of (nothing it emits can leave): a point-like
//! light at its position, an area light at a few points just off its emitting surface.
//!
//! "Inside" is tested by parity: along each of [`DIRECTIONS`] fixed directions the ray is
//! followed through every surface until it escapes, and a point is inside a shape when
//! every direction crosses that shape's surface an odd number of times. A direction that
//! grazes an edge may count a crossing twice; requiring every direction to agree keeps
//! such a miscount from producing a warning (it can only hide one).

use glam::Vec3A;
use prism_geometry::{Geometry, Ray};
use prism_scene::{LightKind, SceneDescription};

use crate::material::{Material, SurfaceMaterial};
use crate::scene_build::{shape_instance_ranges, RenderScene};

/// Directions per point: a Fibonacci sphere, away from the axes so that the rays do not run
/// along the faces and edges of axis-aligned boxes.
pub const DIRECTIONS: usize = 26;

/// Surfaces followed along one ray at most (a ray through a dense mesh stops counting).
const MAX_CROSSINGS: usize = 512;

/// One crossing of a shape's surface along a ray.
#[derive(Clone, Copy)]
struct Crossing {
    shape: usize,
    /// The ray meets the back of the face (along its geometric normal).
    back_face: bool,
    material_id: u32,
}

fn directions() -> [Vec3A; DIRECTIONS] {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    std::array::from_fn(|i| {
        let z = 1.0 - (i as f32 + 0.5) * 2.0 / DIRECTIONS as f32;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f32 + 0.3;
        Vec3A::new(r * phi.cos(), r * phi.sin(), z).normalize()
    })
}

/// Every surface crossed from `origin` along `direction`, in order.
fn crossings(
    geometry: &Geometry,
    shape_of: &[usize],
    origin: Vec3A,
    direction: Vec3A,
) -> Vec<Crossing> {
    let mut out = Vec::new();
    let mut ray = Ray::new(origin, direction, 0.0, f32::INFINITY);
    while out.len() < MAX_CROSSINGS {
        let Some(hit) = geometry.intersect(&ray) else {
            break;
        };
        let interaction = geometry.interaction(&ray, &hit);
        let instance = hit.instance_id as usize;
        out.push(Crossing {
            shape: shape_of.get(instance).copied().unwrap_or(usize::MAX),
            back_face: interaction.n_geometric.dot(direction) > 0.0,
            material_id: geometry.instances()[instance].material.unwrap_or(u32::MAX),
        });
        ray = Ray::spawn_off_surface(interaction.p, interaction.n_geometric, direction);
    }
    out
}

/// Per direction, the crossings from `point`.
fn rays_from(geometry: &Geometry, shape_of: &[usize], point: Vec3A) -> Vec<Vec<Crossing>> {
    directions()
        .iter()
        .map(|d| crossings(geometry, shape_of, point, *d))
        .collect()
}

/// The shapes every direction crosses an odd number of times.
fn enclosing(rays: &[Vec<Crossing>], shapes: usize) -> Vec<usize> {
    (0..shapes)
        .filter(|&s| {
            rays.iter()
                .all(|r| r.iter().filter(|c| c.shape == s).count() % 2 == 1)
        })
        .collect()
}

/// The material under wrappers that do not change which side reflects.
fn core(material: &Material) -> Option<&SurfaceMaterial> {
    match material {
        Material::Surface(s) => Some(s),
        Material::NormalMap { material, .. } | Material::BumpMap { material, .. } => core(material),
        Material::TwoSided { .. } | Material::Mask { .. } => None,
    }
}

/// Reflects on the front only and lets nothing through (a back face is black).
fn one_sided_opaque(material: &Material) -> bool {
    core(material).is_some_and(|s| !transmits(s))
}

/// Lets light through (so a light inside it is not shut in).
fn transmits(s: &SurfaceMaterial) -> bool {
    match s {
        SurfaceMaterial::Dielectric { .. } | SurfaceMaterial::ThinDielectric { .. } => true,
        SurfaceMaterial::Mix { materials, .. } => materials.iter().any(transmits),
        _ => false,
    }
}

/// Nothing passes through it: neither transmissive nor masked.
fn opaque(material: &Material) -> bool {
    match material {
        Material::Surface(s) => !transmits(s),
        Material::TwoSided { material }
        | Material::NormalMap { material, .. }
        | Material::BumpMap { material, .. } => opaque(material),
        Material::Mask { .. } => false,
    }
}

/// Points just off an area light's emitting surface: where `sample_le` starts light paths
/// for a few fixed samples, moved a little along the emitted direction (so a point is
/// outside the emitter's own surface and on the side light leaves from).
fn emitting_points(scene: &RenderScene, instances: &std::ops::Range<u32>) -> Vec<Vec3A> {
    let lights = &scene.lights;
    let Some(l) = instances
        .clone()
        .find_map(|instance| lights.area_light_of_instance(instance))
    else {
        return Vec::new();
    };
    let light = lights.light(l);
    let sphere = lights.scene_sphere();
    let step_m = 1e-4 * sphere.radius_m.max(1e-3);
    let wavelengths = prism_spectrum::SampledWavelengths::sample_visible(0.5);
    [(0.1, 0.2), (0.6, 0.4), (0.35, 0.8), (0.85, 0.65)]
        .iter()
        .filter_map(|&(a, b)| {
            let le = light.sample_le(
                sphere,
                glam::Vec2::new(a, b),
                glam::Vec2::new(b, a),
                &wavelengths,
            )?;
            Some(le.ray.origin + le.ray.direction * step_m)
        })
        .collect()
}

/// `shapes[i]` with its name, for messages.
fn shape_path(description: &SceneDescription, i: usize) -> String {
    match description.shapes.get(i).and_then(|s| s.name.as_deref()) {
        Some(name) => format!("shapes[{i}] (`{name}`)"),
        None => format!("shapes[{i}]"),
    }
}

/// The warnings (one line each, without the scene file's name) for `scene`, built from
/// `description`.
pub fn enclosure_warnings(scene: &RenderScene, description: &SceneDescription) -> Vec<String> {
    let geometry = &scene.geometry;
    let ranges = shape_instance_ranges(description);
    let mut shape_of = vec![usize::MAX; geometry.instances().len()];
    for (s, range) in ranges.iter().enumerate() {
        for id in range.clone() {
            if let Some(slot) = shape_of.get_mut(id as usize) {
                *slot = s;
            }
        }
    }
    let shapes = ranges.len();
    let all_of = |rays: &[Vec<Crossing>], s: usize, test: &dyn Fn(&Crossing) -> bool| {
        rays.iter()
            .flat_map(|r| r.iter().filter(|c| c.shape == s))
            .all(test)
    };
    let mut warnings = Vec::new();

    let camera = scene.camera.frame().camera_to_world.point(Vec3A::ZERO);
    let camera_rays = rays_from(geometry, &shape_of, camera);
    let camera_inside = enclosing(&camera_rays, shapes);
    for &s in &camera_inside {
        // The first crossing of s along each direction is the face the camera sees.
        let seen_back = camera_rays.iter().all(|r| {
            r.iter()
                .find(|c| c.shape == s)
                .is_some_and(|c| c.back_face && one_sided_opaque(scene.material(c.material_id)))
        });
        if seen_back {
            warnings.push(format!(
                "the camera is inside {}, a closed shape whose one-sided material faces away \
                 from it: it sees the backs of the faces, which are black (wrap the material \
                 in `two_sided`, or turn the faces inward)",
                shape_path(description, s)
            ));
        }
    }

    for (i, light) in description.lights.iter().enumerate() {
        // The points light leaves from, and the light's own shape (not its enclosure).
        let (points, own_shape) = match &light.kind {
            LightKind::Point { position_m }
            | LightKind::Spot { position_m, .. }
            | LightKind::Luminaire { position_m, .. } => {
                (vec![Vec3A::from(position_m.map(|v| v as f32))], None)
            }
            LightKind::Area { shape, .. } => {
                (emitting_points(scene, &ranges[*shape]), Some(*shape))
            }
            // Directional and sky lights come from outside the scene.
            LightKind::Directional { .. }
            | LightKind::Environment { .. }
            | LightKind::UniformSky
            | LightKind::Daylight(_) => continue,
        };
        let rays: Vec<Vec<Vec<Crossing>>> = points
            .iter()
            .map(|&p| rays_from(geometry, &shape_of, p))
            .collect();
        let Some(first) = rays.first() else {
            continue;
        };
        // Shut in: every point of the light is inside the same closed opaque shape.
        let shut_in = enclosing(first, shapes).into_iter().filter(|&s| {
            Some(s) != own_shape
                && !camera_inside.contains(&s)
                && rays.iter().all(|r| {
                    enclosing(r, shapes).contains(&s)
                        && all_of(r, s, &|c| opaque(scene.material(c.material_id)))
                })
        });
        for s in shut_in {
            warnings.push(format!(
                "lights[{i}] is inside {}, a closed opaque shape that the camera is outside \
                 of: nothing it emits leaves the shape (move the light, or give the shape a \
                 transmissive material)",
                shape_path(description, s)
            ));
        }
    }
    warnings
}

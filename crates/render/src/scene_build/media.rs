//! The scene's media for transport (`MediaScene`): each medium built from its description,
//! which medium the camera starts in, and per instance the media on the two sides of its
//! surface. A shape with `interior_medium` or `exterior_medium` is a medium boundary
//! (pbrt-v4 `MediumInterface`); any other surface leaves a ray in the medium it was in.
//! Checked here, with the JSON path: the `.vol` files, closed meshes around an interior
//! medium, and the camera's medium against the first boundary along its view axis.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use prism_geometry::{Geometry, Ray};
use prism_scene::{MaterialKind, MediumKind, Phase, SceneDescription, ShapeKind};
use prism_spectrum::{ReradiationMatrix, Spectrum};

use super::error::SceneBuildError;
use super::spectrum::{build_spectrum, SpectrumRole};
use crate::camera::Camera;
use crate::medium::{
    DensityGrid, Fluorophore, GridMedium, HomogeneousMedium, Medium, MediumOptics, PhaseFunction,
    TabulatedPhase, VolGrid,
};

/// The media on the two sides of a boundary surface (`None`: vacuum).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MediumInterface {
    /// Inside: the side the geometric normal points away from.
    pub interior: Option<u32>,
    pub exterior: Option<u32>,
}

impl MediumInterface {
    /// The medium a ray along `direction` leaving (or crossing) a surface with geometric
    /// normal `n` is in.
    #[inline]
    pub fn medium_towards(&self, direction: glam::Vec3A, n: glam::Vec3A) -> Option<u32> {
        if direction.dot(n) > 0.0 {
            self.exterior
        } else {
            self.interior
        }
    }
}

/// What transport needs of a scene's media.
#[derive(Clone, Debug)]
pub struct MediaScene {
    pub media: Vec<Medium>,
    /// Medium names, in `media` order (messages, `--explain`).
    pub names: Vec<String>,
    /// The medium camera rays start in.
    pub camera: Option<u32>,
    /// The medium outside all shapes.
    pub world: Option<u32>,
    /// Per light (scene order), the medium it sits in.
    pub light_media: Vec<Option<u32>>,
    /// Per instance id: the boundary it is, if any.
    pub boundaries: Vec<Option<MediumInterface>>,
    /// Per material id: `interface` (scatters nothing; crossing it is not a bounce).
    pub interface_material: Vec<bool>,
}

impl MediaScene {
    #[inline]
    pub fn medium(&self, index: u32) -> &Medium {
        &self.media[index as usize]
    }

    /// The boundary instance `instance_id` is, if any.
    #[inline]
    pub fn boundary(&self, instance_id: u32) -> Option<&MediumInterface> {
        self.boundaries
            .get(instance_id as usize)
            .and_then(Option::as_ref)
    }

    /// True for a material id whose material is `interface`.
    #[inline]
    pub fn is_interface(&self, material_id: u32) -> bool {
        self.interface_material
            .get(material_id as usize)
            .copied()
            .unwrap_or(false)
    }

    /// True when the boundary hit at `instance_id` (geometric normal `n`, reached along
    /// `direction`) says the ray arrives from another medium than `current`: the scene's
    /// media nest inconsistently there (counted in `PathCounters::medium_mismatches`).
    #[inline]
    pub fn arrives_mismatched(
        &self,
        current: Option<u32>,
        instance_id: u32,
        direction: glam::Vec3A,
        n: glam::Vec3A,
    ) -> bool {
        self.boundary(instance_id)
            .is_some_and(|b| b.medium_towards(-direction, n) != current)
    }

    /// The medium of a ray that leaves a hit on `instance_id` (geometric normal `n`) along
    /// `direction`, having arrived in `current`.
    #[inline]
    pub fn after_surface(
        &self,
        current: Option<u32>,
        instance_id: u32,
        direction: glam::Vec3A,
        n: glam::Vec3A,
    ) -> Option<u32> {
        match self.boundary(instance_id) {
            Some(b) => b.medium_towards(direction, n),
            None => current,
        }
    }
}

fn build_phase(phase: &Phase) -> Result<PhaseFunction, String> {
    Ok(match phase {
        Phase::Isotropic => PhaseFunction::Isotropic,
        Phase::HenyeyGreenstein { g } => PhaseFunction::HenyeyGreenstein { g: *g as f32 },
        Phase::Rayleigh => PhaseFunction::Rayleigh,
        Phase::Tabulated {
            cos_theta, values, ..
        } => PhaseFunction::Tabulated(Arc::new(TabulatedPhase::new(cos_theta, values)?)),
    })
}

/// σf and M of a medium's fluorophore: the dye at peak absorptance 1 scaled by the peak
/// absorption coefficient (both linear between the 5 nm excitation nodes, so σf(λi) is
/// what row λi of M re-emits from).
fn build_fluorophore(f: &prism_scene::MediumFluorescence) -> Result<Fluorophore, String> {
    let peak = f.peak_absorption_per_m;
    let matrix = f.dye.matrix();
    let (ex, em) = (*matrix.excitation(), *matrix.emission());
    let mut values = Vec::with_capacity(ex.count() * em.count());
    for row in 0..ex.count() {
        for column in 0..em.count() {
            values.push((f64::from(matrix.node(row, column)) * peak) as f32);
        }
    }
    let nodes_nm: Vec<f64> = (0..ex.count())
        .map(|k| f64::from(ex.wavelength_nm(k)))
        .collect();
    let sigma_f: Vec<f64> = nodes_nm
        .iter()
        .map(|&nm| f.dye.absorptance(nm) * peak)
        .collect();
    Ok(Fluorophore {
        sigma_f: Spectrum::piecewise_linear(&nodes_nm, &sigma_f).map_err(|e| e.to_string())?,
        matrix: ReradiationMatrix::from_dense(ex, em, values).map_err(|e| e.message)?,
    })
}

/// The media of `scene` (`None` when it declares none). `ranges`: each shape's instance
/// ids; `geometry` and `camera` for the camera-medium check.
pub(crate) fn build_media(
    scene: &SceneDescription,
    ranges: &[Range<u32>],
    geometry: &Geometry,
    camera: &Camera,
    resolution: glam::UVec2,
) -> Result<Option<MediaScene>, SceneBuildError> {
    if scene.media.is_empty() {
        return Ok(None);
    }
    let file = &scene.file;
    if !scene.sensors.is_empty() {
        // Their estimator samples lights at the sensor point as in vacuum.
        return Err(SceneBuildError::new(
            file,
            "sensors[0]",
            "illuminance sensors are not measured in scenes with participating media yet",
        ));
    }
    let mut media = Vec::with_capacity(scene.media.len());
    for m in &scene.media {
        let place = |key: &str| format!("media.{}{key}", m.name);
        let spectrum = |s, role, key: &str| {
            build_spectrum(s, role).map_err(|e| SceneBuildError::new(file, place(key), e))
        };
        let optics = MediumOptics {
            sigma_a: spectrum(&m.sigma_a_per_m, SpectrumRole::Unbounded, ".sigma_a_per_m")?,
            sigma_s: spectrum(&m.sigma_s_per_m, SpectrumRole::Unbounded, ".sigma_s_per_m")?,
            emission: m
                .emission
                .as_ref()
                .map(|e| spectrum(e, SpectrumRole::Illuminant, ".emission"))
                .transpose()?,
            phase: build_phase(&m.phase)
                .map_err(|e| SceneBuildError::new(file, place(".phase"), e))?,
            fluorescence: m
                .fluorescence
                .as_ref()
                .map(build_fluorophore)
                .transpose()
                .map_err(|e| SceneBuildError::new(file, place(".fluorescence"), e))?,
        };
        media.push(match &m.kind {
            MediumKind::Homogeneous => Medium::Homogeneous(HomogeneousMedium { optics }),
            MediumKind::Grid { density, bounds_m } => {
                let err = |e: String| SceneBuildError::new(file, place(".density"), e);
                let vol = VolGrid::read(density).map_err(|e| err(e.to_string()))?;
                let bounds = bounds_m.map(|[lo, hi]| {
                    (
                        Vec3::from(lo.map(|x| x as f32)),
                        Vec3::from(hi.map(|x| x as f32)),
                    )
                });
                let grid = DensityGrid::from_vol(vol, bounds).ok_or_else(|| {
                    SceneBuildError::new(file, place(".bounds_m"), "the grid's box is empty")
                })?;
                Medium::Grid(GridMedium {
                    optics,
                    density: grid,
                })
            }
        });
    }

    let instance_count = ranges.last().map_or(0, |r| r.end) as usize;
    let mut boundaries = vec![None; instance_count];
    for (i, shape) in scene.shapes.iter().enumerate() {
        if shape.interior_medium.is_none() && shape.exterior_medium.is_none() {
            continue;
        }
        if shape.interior_medium.is_some() {
            check_closed(scene, i)?;
        }
        let interface = MediumInterface {
            interior: shape.interior_medium.map(|m| m as u32),
            exterior: shape.exterior_medium.map(|m| m as u32),
        };
        for id in ranges[i].clone() {
            boundaries[id as usize] = Some(interface);
        }
    }
    let mut interface_material: Vec<bool> = scene
        .materials
        .iter()
        .map(|m| matches!(m.kind, MaterialKind::Interface))
        .collect();
    interface_material.push(false); // the default material
    let built = MediaScene {
        media,
        names: scene.media.iter().map(|m| m.name.clone()).collect(),
        camera: scene.camera_medium.map(|m| m as u32),
        world: scene.world_medium.map(|m| m as u32),
        light_media: scene
            .light_media
            .iter()
            .map(|m| m.map(|m| m as u32))
            .collect(),
        boundaries,
        interface_material,
    };
    check_camera_medium(scene, &built, ranges, geometry, camera, resolution)?;
    Ok(Some(built))
}

/// A mesh around an interior medium must be closed: every edge shared by two triangles
/// (vertices matched by position, so split seams count as shared).
fn check_closed(scene: &SceneDescription, shape_index: usize) -> Result<(), SceneBuildError> {
    let shape = &scene.shapes[shape_index];
    let mesh = match &shape.kind {
        ShapeKind::Mesh { mesh } | ShapeKind::Instances { mesh, .. } => *mesh,
        ShapeKind::Sphere { .. } | ShapeKind::Cuboid { .. } => return Ok(()),
        // Refused by the scene reader.
        ShapeKind::Rectangle { .. } | ShapeKind::Disk { .. } => return Ok(()),
    };
    let place = format!("shapes[{shape_index}].interior_medium");
    let asset = &scene.meshes[mesh];
    let tri = super::geometry::load_mesh(asset)
        .map_err(|e| SceneBuildError::new(&scene.file, place.clone(), e))?;
    let mut vertex_of_position: HashMap<[u32; 3], u32> = HashMap::new();
    let canonical: Vec<u32> = tri
        .positions
        .iter()
        .map(|p| {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            let next = vertex_of_position.len() as u32;
            *vertex_of_position.entry(key).or_insert(next)
        })
        .collect();
    let mut edge_uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &tri.indices {
        for k in 0..3 {
            let (a, b) = (canonical[t[k] as usize], canonical[t[(k + 1) % 3] as usize]);
            if a != b {
                *edge_uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
    }
    let open = edge_uses.values().filter(|&&n| n == 1).count();
    if open > 0 {
        return Err(SceneBuildError::new(
            &scene.file,
            place,
            format!(
                "the mesh {} is open ({open} boundary edges, each used by one triangle), so \
                 it has no inside for a medium: close it or give only `exterior_medium`",
                asset.path.display()
            ),
        ));
    }
    Ok(())
}

/// Where a declared medium is checked: the first medium boundary along a ray from the
/// camera or a light must have that medium on the ray's side.
struct MediumClaim<'a> {
    ray: Ray,
    declared: Option<u32>,
    /// The JSON path of the claim (`camera.medium`, `lights[2].medium`).
    place: String,
    /// "the camera", "the light".
    who: &'a str,
    /// "along its view axis", "straight below it".
    along: &'a str,
}

/// The camera's medium (`camera.medium`, else `world_medium`) and each point, spot and
/// goniometric light's (`medium`, else `world_medium`) must be the one on their side of
/// the first medium boundary along the view axis (a light: along its beam axis or aim, or
/// straight down).
fn check_camera_medium(
    scene: &SceneDescription,
    media: &MediaScene,
    ranges: &[Range<u32>],
    geometry: &Geometry,
    camera: &Camera,
    resolution: glam::UVec2,
) -> Result<(), SceneBuildError> {
    let centre = Vec2::new(resolution.x as f32, resolution.y as f32) * 0.5;
    if let Some(ray) = camera.generate_ray_only(centre, Vec2::splat(0.5)) {
        check_claim(
            scene,
            media,
            ranges,
            geometry,
            &MediumClaim {
                ray,
                declared: media.camera,
                place: "camera.medium".into(),
                who: "the camera",
                along: "along its view axis",
            },
        )?;
    }
    for (i, light) in scene.lights.iter().enumerate() {
        let down = [0.0, -1.0, 0.0];
        let (position, direction, along) = match &light.kind {
            prism_scene::LightKind::Point { position_m } => {
                (position_m, &down, "straight below it")
            }
            prism_scene::LightKind::Spot {
                position_m,
                direction,
                ..
            } => (position_m, direction, "along its beam axis"),
            prism_scene::LightKind::Luminaire {
                position_m, aim, ..
            } => (position_m, aim, "along its aim"),
            prism_scene::LightKind::Directional { .. }
            | prism_scene::LightKind::Area { .. }
            | prism_scene::LightKind::Environment { .. }
            | prism_scene::LightKind::UniformSky
            | prism_scene::LightKind::Daylight(_) => continue,
        };
        let to_vec = |v: &[f64; 3]| glam::Vec3A::new(v[0] as f32, v[1] as f32, v[2] as f32);
        check_claim(
            scene,
            media,
            ranges,
            geometry,
            &MediumClaim {
                ray: Ray::infinite(to_vec(position), to_vec(direction).normalize()),
                declared: media.light_media.get(i).copied().flatten(),
                place: format!("lights[{i}].medium"),
                who: "the light",
                along,
            },
        )?;
    }
    Ok(())
}

fn check_claim(
    scene: &SceneDescription,
    media: &MediaScene,
    ranges: &[Range<u32>],
    geometry: &Geometry,
    claim: &MediumClaim,
) -> Result<(), SceneBuildError> {
    let mut ray = claim.ray;
    for _ in 0..1024 {
        let Some(hit) = geometry.intersect(&ray) else {
            return Ok(());
        };
        let si = geometry.shading_interaction(&ray, &hit);
        if let Some(b) = media.boundary(hit.instance_id) {
            // The claimant's side is the one the ray arrives from.
            let facing = -ray.direction;
            let expected = b.medium_towards(facing, si.n_geometric);
            if expected == claim.declared {
                return Ok(());
            }
            let shape = ranges
                .iter()
                .position(|r| r.contains(&hit.instance_id))
                .unwrap_or_default();
            let name = |m: Option<u32>| match m {
                Some(m) => format!("`{}`", media.names[m as usize]),
                None => "vacuum".to_string(),
            };
            let shape_name = match &scene.shapes[shape].name {
                Some(n) => format!("shapes[{shape}] (`{n}`)"),
                None => format!("shapes[{shape}]"),
            };
            let side = if facing.dot(si.n_geometric) > 0.0 {
                "outside"
            } else {
                "inside"
            };
            return Err(SceneBuildError::new(
                &scene.file,
                claim.place.clone(),
                format!(
                    "{} is in {} but sits {side} {shape_name}, the first medium boundary {}, \
                     where the medium is {}",
                    claim.who,
                    name(claim.declared),
                    claim.along,
                    name(expected)
                ),
            ));
        }
        ray = Ray::spawn(si.p, ray.direction);
    }
    Ok(())
}

/// σt at 360, 365, …, 830 nm as the sum of `terms` (σa, σs and a fluorophore's σf): the
/// (min, max) of the sum over that grid.
pub fn coefficient_range(terms: &[&Spectrum]) -> (f32, f32) {
    let mut range = (f32::INFINITY, f32::NEG_INFINITY);
    for k in 0..=94 {
        let wl = 360.0 + 5.0 * k as f32;
        let w = prism_spectrum::SampledWavelengths::new(
            [wl; 4],
            prism_spectrum::SampledSpectrum::splat(1.0),
        );
        let v: f32 = terms.iter().map(|t| t.eval(&w)[0]).sum();
        range = (range.0.min(v), range.1.max(v));
    }
    range
}

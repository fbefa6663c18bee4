//! A `SceneDescription` (prism-scene) turned into what the integrators need: geometry with
//! its BVH, the camera, the film and the albedo of every material. What the description
//! asks for but render does not do yet is refused here (`fields`), and what a fast path may
//! not support is summed up once as the scene's `SceneFeatures` (`features`).

mod albedo;
mod camera;
mod error;
pub mod features;
pub mod fields;
mod filter;
mod geometry;
pub mod media;
pub mod spectrum;
mod tiles;
mod transform;

pub use albedo::{material_albedo, reflectance_rgb, DEFAULT_ALBEDO};
pub use camera::{build_camera, horizontal_fov_rad};
pub use error::SceneBuildError;
pub use features::{SceneFeature, SceneFeatures};
pub use filter::build_filter;
pub use geometry::{
    build_geometry, build_geometry_with_instances, shape_instance_ranges, small_scene_not_used,
    SMALL_SCENE_SUPPORTS,
};

use std::path::PathBuf;

use glam::{UVec2, Vec3A};
use prism_geometry::{Geometry, NO_MATERIAL};
use prism_scene::SceneDescription;

use crate::camera::Camera;
use crate::film::{AovSelection, Film};
use crate::integrator::Integrator;
use crate::light::LightSet;
use crate::material::{build_materials, Material};

/// Everything a render needs, built from a scene description.
pub struct RenderScene {
    /// The scene file it came from (for messages).
    pub file: PathBuf,
    pub geometry: Geometry,
    pub camera: Camera,
    pub integrator: Integrator,
    /// Film resolution in pixels.
    pub resolution: UVec2,
    pub filter: crate::Filter,
    /// Samples per pixel and seed from the scene (`prism render` may override them).
    pub spp: u32,
    pub seed: u64,
    /// Albedo (linear Rec.709) per scene material, then one for the default material.
    pub albedo_rgb: Vec<[f32; 3]>,
    /// Material names in `materials` order, then `default` (for messages and the plan).
    pub material_names: Vec<String>,
    /// Runtime materials indexed by `material_id` (the default material last).
    pub materials: Vec<Material>,
    pub lights: LightSet,
    /// The film splats samples over the filter radius (`film.reconstruction`).
    pub splat: bool,
    /// Some material has an opacity mask: shadow rays must look through masked surfaces.
    pub has_masks: bool,
    /// Some material is a thin glazing pane (`thin_dielectric`): shadow rays cross it with
    /// its transmittance, and paths pass it straight as a null event (material/glazing.rs).
    pub has_glazing: bool,
    /// Some material has a dispersive index of refraction: a path's hit there keeps only
    /// its hero wavelength. Lets the path tracer skip the per-hit test.
    pub has_dispersion: bool,
    /// Some material re-radiates (`fluorescent`): path vertices reserve the two
    /// re-radiation dimensions (`ReradiationDimensions`) and ask `Material::fluorescent`.
    pub has_reradiation: bool,
    /// Some material reads a texture: hits compute ray differentials, from the camera ray
    /// or (after a bounce) from this camera footprint. `None` when no material is textured.
    pub texture_footprint: Option<crate::texture::CameraFootprint>,
    /// The scene as flat diffuse patches for the packet tracer (`integrator::packet`), when
    /// it is one and packet tracing is on (the default).
    pub packet: Option<crate::integrator::packet::PacketScene>,
    /// Whether packet tracing is asked for (`set_packet_tracing`); `packet` is then the
    /// packet form where the scene allows one, re-evaluated when the light selection changes.
    packet_tracing: bool,
    /// What the scene uses that a fast path may not support, computed once here; the
    /// packet tracer and the small-scene intersector run only where it is within their
    /// allow-lists (`PacketScene::SUPPORTS`, `SMALL_SCENE_SUPPORTS`).
    pub features: SceneFeatures,
    /// The scene's participating media (`None` when it declares none): `path` then walks
    /// its paths through `integrator::medium_transport`.
    pub media: Option<media::MediaScene>,
    /// The `radiosity` method's solution, solved once for the scene's own integrator
    /// (`radiosity_solution`): the render's gathers and the illuminance sensors share it.
    radiosity: std::sync::OnceLock<
        Result<std::sync::Arc<crate::integrator::radiosity::SolvedScene>, String>,
    >,
    /// The description, kept when the scene has tiled surfaces: `radiosity` computes their
    /// pyramids from it (`tiled_surfaces`), whichever method the scene was built for
    /// (`prism converge` swaps methods on one scene).
    tile_description: Option<Box<SceneDescription>>,
    /// Per material id, the radiosity surface of a `tiled` material, computed by
    /// the first `tiled_surfaces` call.
    tiled_surfaces:
        std::sync::OnceLock<Result<Vec<Option<crate::tile_pyramid::TiledSurface>>, String>>,
}

impl RenderScene {
    /// Builds the runtime scene. `resolution` overrides the scene's film resolution
    /// (tests and previews).
    pub fn build(
        scene: &SceneDescription,
        resolution: Option<UVec2>,
    ) -> Result<Self, SceneBuildError> {
        fields::refuse_unrendered(scene)?;
        let file = scene.file.clone();
        let resolution = resolution.unwrap_or(UVec2::new(
            scene.film.resolution[0],
            scene.film.resolution[1],
        ));
        let integrator = Integrator::from_description(&scene.integrator)
            .map_err(|message| SceneBuildError::new(&file, "integrator", message))?;
        let filter = build_filter(&scene.film.filter)
            .map_err(|e| SceneBuildError::new(&file, "film.filter", e.to_string()))?;
        // Camera samples reach the filter radius outside the film under filter importance
        // sampling, not on a splatting film (its samples stay on the film).
        let splatting = scene.film.reconstruction == prism_scene::Reconstruction::Splat;
        let film_margin_px = if splatting { 0.0 } else { filter.radius_px() };
        let camera = build_camera(&file, &scene.camera, resolution, film_margin_px)?;
        let mut albedo_rgb: Vec<[f32; 3]> = (0..scene.materials.len())
            .map(|i| material_albedo(&scene.materials, i))
            .collect();
        albedo_rgb.push(DEFAULT_ALBEDO);
        let placed = geometry::place_shapes(scene)?;
        let materials = build_materials(scene)?;
        let features = SceneFeatures::of_scene(
            scene,
            &integrator,
            &camera,
            &materials,
            placed.vertex_normals,
        );
        let ranges = placed.ranges.clone();
        let geometry = placed.builder.build_with(geometry::build_options(features));
        let media = media::build_media(scene, &ranges, &geometry, &camera, resolution)?;
        if let Some(m) = &media {
            integrator
                .refuse_media(&m.names)
                .map_err(|message| SceneBuildError::new(&file, "integrator", message))?;
        }
        let lights = LightSet::build(scene, &geometry)?;
        let tile_description = features
            .contains(SceneFeature::TiledSurfaces)
            .then(|| Box::new(scene.clone()));
        let has_masks = materials.iter().any(|m| m.has_mask());
        let has_glazing = materials.iter().any(|m| m.has_thin_glazing());
        let has_dispersion = materials.iter().any(|m| m.is_dispersive());
        let has_reradiation = materials.iter().any(|m| m.fluorescent().is_some());
        let texture_footprint = if materials.iter().any(|m| m.has_textures()) {
            // A camera without a ray at the film centre (a circular fisheye's corner is
            // never the centre) would leave textures unfiltered: point lookups.
            Some(
                crate::texture::CameraFootprint::from_camera(&camera, resolution).unwrap_or(
                    crate::texture::CameraFootprint {
                        origin: Vec3A::ZERO,
                        direction: Vec3A::Z,
                        direction_spread: 0.0,
                        position_spread_m: 0.0,
                    },
                ),
            )
        } else {
            None
        };
        let mut built = Self {
            file,
            geometry,
            camera,
            integrator,
            resolution,
            filter,
            spp: scene.film.spp,
            seed: scene.film.seed,
            albedo_rgb,
            material_names: scene
                .materials
                .iter()
                .map(|m| m.name.clone())
                .chain(std::iter::once("default".to_string()))
                .collect(),
            materials,
            lights,
            has_masks,
            has_glazing,
            has_dispersion,
            has_reradiation,
            texture_footprint,
            splat: scene.film.reconstruction == prism_scene::Reconstruction::Splat,
            packet: None,
            packet_tracing: true,
            features,
            media,
            radiosity: std::sync::OnceLock::new(),
            tile_description,
            tiled_surfaces: std::sync::OnceLock::new(),
        };
        built.set_packet_tracing(true);
        built.integrator.refuse_scene(&built)?;
        Ok(built)
    }

    /// Per material id, the surface (Γ, τ̄, slab) `radiosity` holds a `tiled`
    /// material by (`None` for other materials; empty without tiled surfaces), computed
    /// from the tiles' pyramids by the first call.
    pub fn tiled_surfaces(&self) -> Result<&[Option<crate::tile_pyramid::TiledSurface>], String> {
        let Some(description) = &self.tile_description else {
            return Ok(&[]);
        };
        self.tiled_surfaces
            .get_or_init(|| tiles::radiosity_surfaces(description, &self.geometry))
            .as_ref()
            .map(Vec::as_slice)
            .map_err(|e| format!("{}: tiles: {e}", self.file.display()))
    }

    /// The `levels` of `tiled` material `material` (the most its pyramid may have) and its
    /// tile's name; `None` for another material.
    pub fn tiled_material_levels(&self, material: u32) -> Option<(u32, &str)> {
        let description = self.tile_description.as_ref()?;
        match description.materials.get(material as usize)?.kind {
            prism_scene::MaterialKind::Tiled { levels, tile, .. } => {
                Some((levels, description.tiles.get(tile)?.name.as_str()))
            }
            _ => None,
        }
    }

    /// `tiled` material `material`'s surface with a pyramid of `levels` levels (at most the
    /// material's `levels`), computed anew: what the solution asks for once its elements
    /// get smaller than a period. `None` for another material.
    pub fn tiled_surface_with_levels(
        &self,
        material: u32,
        levels: u32,
    ) -> Result<Option<crate::tile_pyramid::TiledSurface>, String> {
        let Some(description) = &self.tile_description else {
            return Ok(None);
        };
        tiles::radiosity_surface(description, &self.geometry, material as usize, levels)
            .map_err(|e| format!("{}: tiles: {e}", self.file.display()))
    }

    /// The solution of the scene's `radiosity` integrator (`None` for other methods),
    /// solved by the first call with its statistics on stderr; an error when it cannot be
    /// built (the memory limit).
    pub fn radiosity_solution(
        &self,
    ) -> Option<Result<std::sync::Arc<crate::integrator::radiosity::SolvedScene>, String>> {
        let Integrator::Radiosity(method) = self.integrator else {
            return None;
        };
        Some(
            self.radiosity
                .get_or_init(|| {
                    crate::integrator::radiosity::solve_and_report(self, &method)
                        .map(std::sync::Arc::new)
                })
                .clone(),
        )
    }

    /// Sets the `radiosity` solution (a loaded one) before anything solves it; an error
    /// when the scene renders with another method or already has its solution.
    pub fn set_radiosity_solution(
        &self,
        solved: crate::integrator::radiosity::SolvedScene,
    ) -> Result<(), String> {
        if !matches!(self.integrator, Integrator::Radiosity(_)) {
            return Err(format!(
                "{} renders with `{}`, not `radiosity`: a radiosity solution does not apply",
                self.file.display(),
                self.integrator.name()
            ));
        }
        self.radiosity
            .set(Ok(std::sync::Arc::new(solved)))
            .map_err(|_| "the scene's radiosity solution is already solved".to_string())
    }

    /// Packet tracing on (where the scene allows it, `PacketScene::new`) or off (every
    /// path through the scalar tracer; for tests and comparisons).
    pub fn set_packet_tracing(&mut self, on: bool) {
        self.packet_tracing = on;
        self.packet = None;
        if on {
            self.packet = crate::integrator::packet::PacketScene::new(self).ok();
        }
    }

    /// Light samples each hit of a camera path takes where the plan asks for
    /// `plan_light_samples` (at least 1): that many for each light at infinity and for the
    /// other lights where the lights at infinity are chosen apart
    /// (`LightSet::samples_per_light_sample`).
    #[inline]
    pub fn light_samples_per_hit(&self, plan_light_samples: u32) -> u32 {
        plan_light_samples
            .max(1)
            .saturating_mul(self.lights.samples_per_light_sample())
    }

    /// How light samples at shading points choose a light; `false` (nothing changed) for
    /// the light BVH where the scene has no light with bounds. The packet form is decided
    /// again (whether its tiles take one light sample per hit depends on the choice).
    pub fn set_light_selection(&mut self, selection: crate::light::ShadingSelection) -> bool {
        let done = self.lights.set_shading_selection(selection);
        self.set_packet_tracing(self.packet_tracing);
        done
    }

    /// The name of material `material_id` as `material` resolves it (`default` for
    /// `NO_MATERIAL` and ids past the scene's materials).
    pub fn material_name(&self, material_id: u32) -> &str {
        let last = self.material_names.len() - 1;
        &self.material_names[(material_id as usize).min(last)]
    }

    /// The name of the first material that re-radiates (fluorescence), if any.
    pub fn reradiating_material(&self) -> Option<&str> {
        self.materials
            .iter()
            .position(|m| m.fluorescent().is_some())
            .map(|i| self.material_names[i].as_str())
    }

    /// An error for estimators that carry one wavelength set along a path (`method`: the
    /// light tracer, BDPT) when some material re-radiates.
    pub fn refuse_reradiation(&self, method: &str) -> Result<(), String> {
        match self.reradiating_material() {
            None => Ok(()),
            Some(name) => Err(format!(
                "{}: materials.{name}: material '{name}' re-radiates (fluorescence): `{method}` \
                 carries one wavelength set along its light paths and cannot shift it; use path",
                self.file.display()
            )),
        }
    }

    /// An empty film for this scene recording the surface AOVs (depth, normal, albedo).
    pub fn new_film(&self) -> Film {
        // The resolution was checked when the camera frame was built.
        Film::new(self.resolution, self.filter, AovSelection::SURFACE)
            .expect("resolution checked by CameraFrame::new")
            .with_splatting(self.splat)
    }

    /// The runtime material of a hit's `material_id` (the default material for ids
    /// without one).
    #[inline]
    pub fn material(&self, material_id: u32) -> &Material {
        let last = self.materials.len() - 1;
        &self.materials[(material_id as usize).min(last)]
    }

    /// The texture-filtering differentials of a hit in a textured scene: the ray's own
    /// (`ray`, while the path is specular from the camera) or the camera footprint
    /// approximation scaled by `scale` (pbrt-v4 §10.1.2). Untextured scenes skip it.
    #[inline]
    pub fn set_texture_differentials(
        &self,
        si: &mut prism_geometry::SurfaceInteraction,
        ray: Option<&prism_geometry::RayDifferential>,
        scale: f32,
    ) {
        if let Some(footprint) = &self.texture_footprint {
            match ray {
                Some(rd) => si.compute_differentials(rd),
                None => si.compute_differentials(&footprint.approximate(si.p, scale)),
            }
        }
    }

    /// Albedo of a hit's `material_id`.
    #[inline]
    pub fn albedo(&self, material_id: u32) -> [f32; 3] {
        if material_id == NO_MATERIAL {
            return DEFAULT_ALBEDO;
        }
        self.albedo_rgb
            .get(material_id as usize)
            .copied()
            .unwrap_or(DEFAULT_ALBEDO)
    }
}

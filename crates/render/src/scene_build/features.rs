//! What a scene asks of the renderer, as a closed set of features that a fast path may not
//! support. `RenderScene::build` computes the set once; each fast path states the features
//! it handles as an allow-list constant (`PacketScene::SUPPORTS`,
//! `scene_build::SMALL_SCENE_SUPPORTS`) and runs only where `features ⊆ allow-list` (plus
//! its own numeric limits). A feature added here is outside every allow-list until someone
//! who has read that fast path adds it, so a new capability can never reach a fast path
//! that silently ignores it.

use std::fmt;

use prism_scene::{LightKind, SceneDescription, ShapeKind};

use crate::camera::Camera;
use crate::integrator::Integrator;
use crate::material::{Material, SurfaceMaterial};

/// One thing a scene may use that a fast path may not handle. Append new variants last,
/// and to `ALL`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum SceneFeature {
    DiagnosticIntegrator,
    ParticipatingMedia,
    OpacityMasks,
    ThinGlazing,
    Dispersion,
    Textures,
    NonLambertianBsdfs,
    TwoSidedMaterials,
    ShadingNormalMaps,
    VertexNormals,
    Quadrics,
    InfiniteLights,
    DeltaLights,
    NonRectangleAreaLights,
    ThinLensCamera,
    LightPaths,
    Reradiation,
    RadiositySolution,
    TiledSurfaces,
}

impl SceneFeature {
    /// Every feature, in declaration order (bit `i` of `SceneFeatures` is `ALL[i]`).
    pub const ALL: [SceneFeature; 19] = [
        SceneFeature::DiagnosticIntegrator,
        SceneFeature::ParticipatingMedia,
        SceneFeature::OpacityMasks,
        SceneFeature::ThinGlazing,
        SceneFeature::Dispersion,
        SceneFeature::Textures,
        SceneFeature::NonLambertianBsdfs,
        SceneFeature::TwoSidedMaterials,
        SceneFeature::ShadingNormalMaps,
        SceneFeature::VertexNormals,
        SceneFeature::Quadrics,
        SceneFeature::InfiniteLights,
        SceneFeature::DeltaLights,
        SceneFeature::NonRectangleAreaLights,
        SceneFeature::ThinLensCamera,
        SceneFeature::LightPaths,
        SceneFeature::Reradiation,
        SceneFeature::RadiositySolution,
        SceneFeature::TiledSurfaces,
    ];

    /// Short name, as `--explain` lists it.
    pub fn name(self) -> &'static str {
        match self {
            SceneFeature::DiagnosticIntegrator => "diagnostic integrator",
            SceneFeature::ParticipatingMedia => "participating media",
            SceneFeature::OpacityMasks => "opacity masks",
            SceneFeature::ThinGlazing => "thin glazing",
            SceneFeature::Dispersion => "dispersion",
            SceneFeature::Textures => "textures",
            SceneFeature::NonLambertianBsdfs => "non-Lambertian BSDFs",
            SceneFeature::TwoSidedMaterials => "two-sided materials",
            SceneFeature::ShadingNormalMaps => "normal/bump maps",
            SceneFeature::VertexNormals => "vertex normals",
            SceneFeature::Quadrics => "spheres and disks",
            SceneFeature::InfiniteLights => "infinite lights",
            SceneFeature::DeltaLights => "delta lights",
            SceneFeature::NonRectangleAreaLights => "non-rectangle area lights",
            SceneFeature::ThinLensCamera => "thin-lens camera",
            SceneFeature::LightPaths => "light tracing, BDPT or photon mapping",
            SceneFeature::Reradiation => "re-radiation (fluorescence)",
            SceneFeature::RadiositySolution => "radiosity",
            SceneFeature::TiledSurfaces => "tiled surfaces",
        }
    }

    /// One line on what it is and what it asks of a renderer.
    pub fn description(self) -> &'static str {
        match self {
            SceneFeature::DiagnosticIntegrator => {
                "the depth, normal, albedo or ambient-occlusion integrator instead of the path \
                 tracer"
            }
            SceneFeature::ParticipatingMedia => {
                "a medium inside or around shapes: light is absorbed and scattered between \
                 surfaces"
            }
            SceneFeature::OpacityMasks => {
                "a `mask` material: part of a surface lets rays through, and shadow rays \
                 multiply 1 − α"
            }
            SceneFeature::ThinGlazing => {
                "a `thin_dielectric` pane: shadow rays cross it with its transmittance, paths \
                 pass it as a null event"
            }
            SceneFeature::Dispersion => {
                "an index of refraction that varies with wavelength: paths that refract keep \
                 only the hero wavelength"
            }
            SceneFeature::Textures => {
                "a material parameter read from an image or procedural texture at each hit, \
                 filtered by ray differentials"
            }
            SceneFeature::NonLambertianBsdfs => {
                "a BSDF other than a constant Lambertian R(λ)/π: glossy, specular, measured or \
                 a mix"
            }
            SceneFeature::TwoSidedMaterials => {
                "a `two_sided` material: the BSDF reflects on both sides of the surface"
            }
            SceneFeature::ShadingNormalMaps => {
                "a `normal_map` or `bump_map` material: the shading normal changes at every hit"
            }
            SceneFeature::VertexNormals => {
                "a mesh with vertex normals: the shading normal is interpolated across each \
                 triangle"
            }
            SceneFeature::Quadrics => {
                "a sphere or disk: intersected in its object space (pbrt-v4 §6.2, §6.4), not \
                 as a flat patch"
            }
            SceneFeature::InfiniteLights => {
                "a directional light, environment map or sky: shadow rays go to infinity and \
                 escaping rays see it"
            }
            SceneFeature::DeltaLights => {
                "a point, spot, luminaire or ideal parallel light: reached by light samples \
                 only (MIS weight 1)"
            }
            SceneFeature::NonRectangleAreaLights => {
                "an emitting sphere, disk or mesh: sampled through the general area-light code"
            }
            SceneFeature::ThinLensCamera => {
                "a thin-lens camera: every camera ray needs a lens sample (depth of field)"
            }
            SceneFeature::LightPaths => {
                "the light tracer, BDPT or a photon integrator: paths also start at the \
                 lights (connected to the camera and splatted onto the film, or stored as \
                 photons)"
            }
            SceneFeature::Reradiation => {
                "a `fluorescent` material: a lane absorbs at one wavelength and re-emits at \
                 another, so spectra are evaluated again along the path"
            }
            SceneFeature::RadiositySolution => {
                "the `radiosity` method: a hierarchical radiosity solution, then a final \
                 gather per camera sample that ends on it"
            }
            SceneFeature::TiledSurfaces => {
                "a `tiled` material: rays that reach the carrier continue into a periodic \
                 tile's geometry, repeated over a grid (virtual ray tracing)"
            }
        }
    }

    const fn bit(self) -> u32 {
        1 << self as u32
    }
}

/// A set of `SceneFeature`s.
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures(u32);

impl SceneFeatures {
    pub const EMPTY: SceneFeatures = SceneFeatures(0);

    /// The set of `list` (usable in constants: `PacketScene::SUPPORTS`).
    pub const fn of(list: &[SceneFeature]) -> Self {
        let mut bits = 0;
        let mut i = 0;
        while i < list.len() {
            bits |= list[i].bit();
            i += 1;
        }
        SceneFeatures(bits)
    }

    pub fn insert(&mut self, feature: SceneFeature) {
        self.0 |= feature.bit();
    }

    pub const fn contains(self, feature: SceneFeature) -> bool {
        self.0 & feature.bit() != 0
    }

    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every feature of `self` is in `allowed`.
    pub const fn is_subset_of(self, allowed: SceneFeatures) -> bool {
        self.0 & !allowed.0 == 0
    }

    /// The features of `self` that `allowed` lacks.
    pub const fn outside(self, allowed: SceneFeatures) -> SceneFeatures {
        SceneFeatures(self.0 & !allowed.0)
    }

    pub fn iter(self) -> impl Iterator<Item = SceneFeature> {
        SceneFeature::ALL
            .into_iter()
            .filter(move |f| self.contains(*f))
    }

    /// "a, b, c" of the names, in declaration order.
    pub fn names(self) -> String {
        self.iter()
            .map(SceneFeature::name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The features of a scene being built: its integrator, camera and runtime materials
    /// (`materials[i]` for material id `i`, the default last), the shapes, lights and media
    /// of its description, and whether a mesh its shapes place has vertex normals. Materials
    /// count only where a shape uses them (wrappers and mixes with their inner materials).
    pub(crate) fn of_scene(
        scene: &SceneDescription,
        integrator: &Integrator,
        camera: &Camera,
        materials: &[Material],
        vertex_normals: bool,
    ) -> Self {
        let mut f = SceneFeatures::EMPTY;
        match integrator {
            Integrator::Depth
            | Integrator::Normal
            | Integrator::Albedo
            | Integrator::AmbientOcclusion(_) => f.insert(SceneFeature::DiagnosticIntegrator),
            Integrator::Light(_) | Integrator::Bdpt(_) | Integrator::Photon(_) => {
                f.insert(SceneFeature::LightPaths)
            }
            Integrator::Radiosity(_) => f.insert(SceneFeature::RadiositySolution),
            Integrator::Path(_) => {}
        }
        match camera {
            Camera::ThinLens(_) => f.insert(SceneFeature::ThinLensCamera),
            Camera::Pinhole(_)
            | Camera::Fisheye(_)
            | Camera::Orthographic(_)
            | Camera::Spherical(_) => {}
        }
        let media_on_shapes = scene
            .shapes
            .iter()
            .any(|s| s.interior_medium.is_some() || s.exterior_medium.is_some());
        if !scene.media.is_empty() || media_on_shapes {
            f.insert(SceneFeature::ParticipatingMedia);
        }
        if vertex_normals {
            f.insert(SceneFeature::VertexNormals);
        }
        let default_material = materials.len() - 1;
        let mut used = vec![false; materials.len()];
        for shape in &scene.shapes {
            // A tiled carrier is never shaded: its tile's face materials are.
            if let Some(tile) = super::tiles::tile_of(scene, shape.material) {
                f.insert(SceneFeature::TiledSurfaces);
                for &(_, m) in &scene.tiles[tile].materials {
                    used[m.min(default_material)] = true;
                }
            } else {
                used[shape
                    .material
                    .unwrap_or(default_material)
                    .min(default_material)] = true;
            }
            match shape.kind {
                ShapeKind::Sphere { .. } | ShapeKind::Disk { .. } => {
                    f.insert(SceneFeature::Quadrics)
                }
                ShapeKind::Mesh { .. }
                | ShapeKind::Instances { .. }
                | ShapeKind::Rectangle { .. }
                | ShapeKind::Cuboid { .. } => {}
            }
        }
        for (m, _) in materials.iter().zip(&used).filter(|(_, u)| **u) {
            material_features(m, &mut f);
        }
        for light in &scene.lights {
            match &light.kind {
                LightKind::Point { .. } | LightKind::Spot { .. } | LightKind::Luminaire { .. } => {
                    f.insert(SceneFeature::DeltaLights)
                }
                LightKind::Directional {
                    angular_diameter_rad,
                    ..
                } => {
                    f.insert(SceneFeature::InfiniteLights);
                    if *angular_diameter_rad == 0.0 {
                        f.insert(SceneFeature::DeltaLights);
                    }
                }
                LightKind::Environment { .. } | LightKind::UniformSky | LightKind::Daylight(_) => {
                    f.insert(SceneFeature::InfiniteLights)
                }
                LightKind::Area { shape, .. } => {
                    let rectangle = scene
                        .shapes
                        .get(*shape)
                        .is_some_and(|s| matches!(s.kind, ShapeKind::Rectangle { .. }));
                    if !rectangle {
                        f.insert(SceneFeature::NonRectangleAreaLights);
                    }
                }
            }
        }
        f
    }
}

/// The features of material `m` and of the materials it wraps.
fn material_features(m: &Material, f: &mut SceneFeatures) {
    match m {
        Material::Surface(surface) => surface_features(surface, f),
        Material::TwoSided { material } => {
            f.insert(SceneFeature::TwoSidedMaterials);
            material_features(material, f);
        }
        Material::Mask {
            material,
            opacity_texture,
            ..
        } => {
            f.insert(SceneFeature::OpacityMasks);
            if opacity_texture.is_some() {
                f.insert(SceneFeature::Textures);
            }
            material_features(material, f);
        }
        Material::NormalMap { material, .. } | Material::BumpMap { material, .. } => {
            f.insert(SceneFeature::ShadingNormalMaps);
            f.insert(SceneFeature::Textures);
            material_features(material, f);
        }
    }
}

/// The features of surface `s` and of the surfaces it mixes.
fn surface_features(s: &SurfaceMaterial, f: &mut SceneFeatures) {
    match s {
        SurfaceMaterial::Lambert { reflectance } => {
            if reflectance.constant().is_none() {
                f.insert(SceneFeature::Textures);
            }
        }
        SurfaceMaterial::Conductor {
            roughness_texture, ..
        } => {
            f.insert(SceneFeature::NonLambertianBsdfs);
            if roughness_texture.is_some() {
                f.insert(SceneFeature::Textures);
            }
        }
        SurfaceMaterial::Dielectric {
            ior,
            roughness_texture,
            ..
        } => {
            f.insert(SceneFeature::NonLambertianBsdfs);
            if ior.is_dispersive() {
                f.insert(SceneFeature::Dispersion);
            }
            if roughness_texture.is_some() {
                f.insert(SceneFeature::Textures);
            }
        }
        SurfaceMaterial::ThinDielectric { .. } => {
            f.insert(SceneFeature::NonLambertianBsdfs);
            f.insert(SceneFeature::ThinGlazing);
        }
        SurfaceMaterial::Mix { materials, .. } => {
            f.insert(SceneFeature::NonLambertianBsdfs);
            for inner in materials.iter() {
                surface_features(inner, f);
            }
        }
        SurfaceMaterial::Library(_) => f.insert(SceneFeature::NonLambertianBsdfs),
        SurfaceMaterial::Fluorescent(_) => f.insert(SceneFeature::Reradiation),
    }
}

impl fmt::Debug for SceneFeatures {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_lists_every_feature_in_declaration_order_with_distinct_names() {
        for (i, f) in SceneFeature::ALL.iter().enumerate() {
            assert_eq!(*f as usize, i, "{f:?} is not ALL[{i}]");
            assert!(!f.description().is_empty());
            assert!(
                SceneFeature::ALL[..i].iter().all(|g| g.name() != f.name()),
                "{f:?}: name used twice"
            );
        }
        assert!(SceneFeature::ALL.len() <= 32, "SceneFeatures is a u32");
    }

    #[test]
    fn set_operations() {
        use SceneFeature::*;
        let s = SceneFeatures::of(&[Textures, Quadrics]);
        let allowed = SceneFeatures::of(&[Quadrics, DeltaLights]);
        assert!(s.contains(Textures) && !s.contains(DeltaLights));
        assert!(!s.is_subset_of(allowed));
        assert_eq!(s.outside(allowed), SceneFeatures::of(&[Textures]));
        assert!(SceneFeatures::of(&[Quadrics]).is_subset_of(allowed));
        assert!(SceneFeatures::EMPTY.is_subset_of(SceneFeatures::EMPTY));
        assert_eq!(s.names(), "textures, spheres and disks");
        assert_eq!(format!("{s:?}"), "{Textures, Quadrics}");
    }
}

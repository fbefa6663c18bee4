//! The path tracer for scenes of flat diffuse patches, many paths at once.
//!
//! The scalar path tracer (`integrator::path`) follows one camera path at a time through
//! general code: a BSDF dispatch, a shading record built per hit, one ray query after
//! another. For the Cornell box that is ≈ 9 800 instructions per camera sample, ≈ 45 % of
//! them in ray queries whose 8-wide primitive tests still run one ray at a time. Scenes
//! made only of flat patches (triangles of meshes without vertex normals, rectangles) with
//! constant Lambertian materials — the Cornell box, plain rooms — need none of that
//! generality: the shading record of a patch is a constant (`FlatLeaf`), the BSDF is
//! R(λ)/π, and `N` paths can share every ray query (`intersect`), `N` = 16 where the ISA
//! the scene was built with is AVX-512 (`prism_cpu::active()`), 8 otherwise.
//!
//! The estimator is the scalar path tracer's, step for step (`trace`): the same sample
//! dimensions from the same streams, the same light sampling (the `Light` code itself),
//! the same MIS, roulette, statistics, AOVs and film calls, so each camera sample gives the
//! scalar tracer's value up to the last bits of the ray tests (Möller–Trumbore here,
//! watertight there) and of the hit point (o + t·d here). Lanes that finish a path take
//! the tile's next camera sample at once, so every query runs with all lanes busy until the
//! tile runs out; the order of the film's additions stays fixed per tile, so images stay
//! bit-identical for any thread count.
//!
//! The render plan switches it on where the scene allows: its features are within
//! `PacketScene::SUPPORTS` and its geometry is a small scene of flat patches
//! (`PacketScene::new` says why not otherwise); `RenderScene::set_packet_tracing` turns it
//! off (tests, comparisons).

mod intersect;
mod shade;
mod trace;

pub(crate) use trace::{render_tile, TileJob};

use glam::{Vec2, Vec3A};
use prism_geometry::fast_path::PatchKind;
use prism_geometry::Frame;

use intersect::{BoxSet, PatchSet};

use prism_spectrum::Spectrum;

use crate::light::area::{AreaLight, AreaShape, SolidAngleSampling};
use crate::light::Light;
use crate::scene_build::{small_scene_not_used, RenderScene, SceneFeature, SceneFeatures};

/// What a ray that hits patch `i` finds there (constant over the patch).
#[derive(Clone, Copy, Debug)]
struct LeafShading {
    /// The shading frame `Frame::from_zx(n_shading, dpdu)` the scalar tracer builds per hit.
    frame: Frame,
    n_geometric: Vec3A,
    n_shading: Vec3A,
    uv: Vec2,
    material_id: u32,
    /// Its reflectance's slot in `PacketScene::reflectances` (evaluated for every camera
    /// sample up front), or `None` past the first `REFLECTANCE_SLOTS` materials.
    reflectance_slot: Option<usize>,
    /// The area light this patch's instance carries.
    light: Option<u32>,
}

/// Materials whose reflectance every camera sample evaluates up front, for 16 samples at
/// once (`Spectrum::eval_many`); later ones through the per-path cache.
pub(crate) const REFLECTANCE_SLOTS: usize = 4;

/// Distinct rectangle-emitter radiances whose L(λ) every camera sample evaluates up front,
/// as the reflectances; emitters with another, later radiance through the per-path cache.
pub(crate) const LIGHT_SLOTS: usize = 4;

/// A rectangle emitter as the lanes sample it (`light::area::RectangleEmitter`).
#[derive(Clone, Debug)]
struct RectangleLight {
    /// `to_world`'s linear columns x, y, z and its translation.
    axes: [Vec3A; 4],
    half_width_m: f32,
    half_height_m: f32,
    normal: Vec3A,
    inv_area_m2: f32,
    two_sided: bool,
    radiance: Spectrum,
    /// Its radiance's slot in `PacketScene::light_radiances` (emitters with equal radiances
    /// share one), or `None` past the first `LIGHT_SLOTS` distinct radiances.
    radiance_slot: Option<usize>,
    /// Where the emitter samples in solid angle (`RectangleEmitter::solid_angle_sampling`):
    /// lanes whose vertex lies there take the scalar `Light` code's sample.
    solid_angle: Option<SolidAngleSampling>,
}

/// A scene the packet tracer can render: its patches and their shading.
#[derive(Clone, Debug)]
pub struct PacketScene {
    triangles: PatchSet,
    parallelograms: PatchSet,
    boxes: BoxSet,
    leaves: Vec<LeafShading>,
    /// The reflectances of the first `REFLECTANCE_SLOTS` materials.
    reflectances: Vec<Spectrum>,
    /// Per light of the scene's `LightSet`: its rectangle form, or `None` for lights the
    /// scalar `Light` code samples.
    lights: Vec<Option<RectangleLight>>,
    /// The first `LIGHT_SLOTS` distinct radiances of the rectangle emitters.
    light_radiances: Vec<Spectrum>,
    /// The kernels that run (`trace::render_tile`): 16 lanes with AVX-512, 8 with AVX2 and
    /// FMA, 8 baseline (SSE2) for scalar; `prism_cpu::active()` when the scene was built
    /// (tests set each ISA).
    simd: prism_cpu::Simd,
}

impl PacketScene {
    /// The features the packet tracer handles; a scene with any other runs the scalar
    /// tracer. It is the path tracer for flat patches (triangles without vertex normals,
    /// rectangles) with constant Lambertian materials, so every other integrator, shape,
    /// material and medium is left out. Lights of every kind are in: it samples them with
    /// the scalar `Light` code (rectangles in lanes) and escapes through
    /// `PathTracer::escape_terms`; so is the thin lens, whose lens samples it draws.
    pub const SUPPORTS: SceneFeatures = SceneFeatures::of(&[
        SceneFeature::InfiniteLights,
        SceneFeature::DeltaLights,
        SceneFeature::NonRectangleAreaLights,
        SceneFeature::ThinLensCamera,
    ]);

    /// The packet form of `scene`, or why it has none (for `--explain`): the names of its
    /// features outside [`Self::SUPPORTS`], else the limit it is past (the small-scene
    /// intersector's, or a mesh kept instanced).
    pub fn new(scene: &RenderScene) -> Result<Self, String> {
        if let Some(name) = scene.reradiating_material() {
            return Err(format!(
                "material '{name}' re-radiates (fluorescence): lanes change wavelength along a \
                 path, but the packet tracer evaluates reflectances once per camera sample"
            ));
        }
        if let Some(media) = &scene.media {
            return Err(format!(
                "the scene has participating media ({}): the packet tracer samples no media",
                media.names.join(", ")
            ));
        }
        let outside = scene.features.outside(Self::SUPPORTS);
        if !outside.is_empty() {
            return Err(outside.names());
        }
        // Lanes test every patch of the scene: only a small scene has few enough.
        if let Some(why) = small_scene_not_used(&scene.geometry, scene.features) {
            return Err(why);
        }
        let Some(flat) = scene.geometry.flat_leaves() else {
            return Err(
                "a mesh is kept instanced (shared by several instances and too large to bake \
                 into world-space patches)"
                    .into(),
            );
        };
        if flat.is_empty() {
            return Err("the scene has no geometry".into());
        }
        let mut leaves = Vec::with_capacity(flat.len());
        let mut reflectances: Vec<(u32, Spectrum)> = Vec::new();
        for leaf in &flat {
            let r = &leaf.record;
            let constant = scene.material(r.material_id).constant_lambert();
            // Guaranteed by the features (`NonLambertianBsdfs`, `Textures`, …): a guard.
            let Some(constant) = constant else {
                return Err(format!(
                    "material '{}' is not a constant Lambertian",
                    scene.material_name(r.material_id)
                ));
            };
            let slot = match reflectances.iter().position(|(id, _)| *id == r.material_id) {
                Some(k) => Some(k),
                None if reflectances.len() < REFLECTANCE_SLOTS => {
                    reflectances.push((r.material_id, constant.clone()));
                    Some(reflectances.len() - 1)
                }
                None => None,
            };
            leaves.push(LeafShading {
                frame: Frame::from_zx(r.n_shading, r.dpdu),
                n_geometric: r.n_geometric,
                n_shading: r.n_shading,
                uv: r.uv,
                material_id: r.material_id,
                reflectance_slot: slot,
                light: scene.lights.area_light_of_instance(r.instance_id),
            });
        }
        let mut light_radiances = Vec::new();
        let lights = scene
            .lights
            .lights()
            .iter()
            .map(|light| match light {
                Light::Area(AreaLight {
                    shape: AreaShape::Rectangle(r),
                    radiance,
                    two_sided,
                }) if r.area_m2() > 0.0 => {
                    let m = r.to_world.matrix();
                    // Lamps of one kind share a slot (an office of identical luminaires).
                    let radiance_slot =
                        light_radiances
                            .iter()
                            .position(|s| s == radiance)
                            .or_else(|| {
                                (light_radiances.len() < LIGHT_SLOTS).then(|| {
                                    light_radiances.push(radiance.clone());
                                    light_radiances.len() - 1
                                })
                            });
                    Some(RectangleLight {
                        axes: [m.x_axis, m.y_axis, m.z_axis, m.w_axis].map(Vec3A::from_vec4),
                        half_width_m: r.rectangle.half_width_m,
                        half_height_m: r.rectangle.half_height_m,
                        normal: r.normal(),
                        inv_area_m2: 1.0 / r.area_m2() as f32,
                        two_sided: *two_sided,
                        radiance: radiance.clone(),
                        radiance_slot,
                        solid_angle: r.solid_angle_sampling().copied(),
                    })
                }
                // Other emitters (and empty rectangles) go through the scalar `Light` code.
                Light::Area(_)
                | Light::Point(_)
                | Light::Spot(_)
                | Light::Directional(_)
                | Light::Environment(_)
                | Light::Sky(_)
                | Light::Daylight(_)
                | Light::Goniometric(_) => None,
            })
            .collect();
        let flat_boxes = scene.geometry.flat_boxes(&flat);
        let mut in_box = vec![false; flat.len()];
        for b in &flat_boxes {
            for &(leaf, _) in b.faces.iter().flatten() {
                in_box[leaf as usize] = true;
            }
        }
        Ok(Self {
            triangles: PatchSet::new(&flat, PatchKind::Triangle, &in_box),
            parallelograms: PatchSet::new(&flat, PatchKind::Parallelogram, &in_box),
            boxes: BoxSet::new(&flat_boxes),
            leaves,
            reflectances: reflectances.into_iter().map(|(_, s)| s).collect(),
            lights,
            light_radiances,
            simd: prism_cpu::active(),
        })
    }

    /// Patches tested one by one (triangles and parallelograms not in a box).
    pub fn patch_count(&self) -> usize {
        self.triangles.len() + self.parallelograms.len()
    }

    /// Parallelepipeds tested as boxes.
    pub fn box_count(&self) -> usize {
        self.boxes.len()
    }

    /// The ISA its kernels run.
    pub fn simd(&self) -> prism_cpu::Simd {
        self.simd
    }

    /// Paths per ray query: 16 with AVX-512, else 8.
    pub fn lane_count(&self) -> usize {
        if self.simd.avx512() {
            16
        } else {
            8
        }
    }
}

#[cfg(test)]
mod tests;

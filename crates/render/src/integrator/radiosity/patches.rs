//! The scene as radiosity input: one patch per side that reflects or emits of every
//! rectangle and mesh triangle (spheres and disks meshed, `meshed.rs`), with band-averaged Lambertian reflectance and emission,
//! and the map from a hit (instance, primitive, side) back to its patch.

use glam::Vec3A;
use prism_geometry::triangle_geometry::triangle_local_geometry;
use prism_geometry::{Geometry, Shape, NO_MATERIAL};
use prism_radiosity::directional::DirectionalSide;
use prism_radiosity::{ElementShape, InputPatch};
use prism_spectrum::Spectrum;

use super::meshed::{mesh_analytic, LiftSphere, Meshing};
use super::tiled::TiledCarriers;
use crate::film::spectral_bins::SpectralBins;
use crate::light::Light;
use crate::material::Material;
use crate::scene_build::RenderScene;

/// The default bands of the solution, and those of every tile pyramid: 16 of 25 nm over
/// 380–780 nm.
pub const BANDS: usize = 16;
pub const FIRST_BAND_NM: f64 = 380.0;
pub const BAND_WIDTH_NM: f64 = 25.0;

/// The wavelength bands a solution is carried in: equal bands from `first_nm`, the end
/// bands extending beyond the range. The default, 16 of 25 nm over 380–780 nm, or the
/// render's spectral bins (`--spectral-bins N`: N over 360–830 nm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolutionBands {
    pub count: usize,
    pub first_nm: f64,
    pub width_nm: f64,
}

impl Default for SolutionBands {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl SolutionBands {
    pub const DEFAULT: Self = Self {
        count: BANDS,
        first_nm: FIRST_BAND_NM,
        width_nm: BAND_WIDTH_NM,
    };

    /// The bands of the render's spectral bins (`--spectral-bins N`: N equal bins over
    /// 360–830 nm).
    pub fn of_spectral_bins(bins: SpectralBins) -> Self {
        Self {
            count: bins.count() as usize,
            first_nm: bins.lower_edge_nm(0),
            width_nm: bins.width_nm(),
        }
    }

    /// The band holding `wavelength_nm` (the end bands extend beyond the range).
    #[inline]
    pub fn band_of(&self, wavelength_nm: f32) -> usize {
        (((f64::from(wavelength_nm) - self.first_nm) / self.width_nm)
            .floor()
            .max(0.0) as usize)
            .min(self.count - 1)
    }

    /// Wavelength `k` of `count` evenly spaced midpoints in band `band`, nm.
    pub fn point_nm(&self, band: usize, k: usize, count: usize) -> f64 {
        self.first_nm + self.width_nm * (band as f64 + (k as f64 + 0.5) / count as f64)
    }

    /// A spectrum's mean over each band (5 points per band), times `scale`.
    pub fn means(&self, spectrum: &Spectrum, scale: f64) -> Vec<f32> {
        (0..self.count)
            .map(|b| {
                let mean = (0..5)
                    .map(|k| spectrum.eval_nm(self.point_nm(b, k, 5)))
                    .sum::<f64>()
                    / 5.0;
                (mean * scale) as f32
            })
            .collect()
    }

    /// Values in runs of `BANDS` per default band (a tile pyramid's) carried into these
    /// bands, run by run: each band takes the mean of the default bands over its
    /// wavelengths, the end default bands standing for what lies beyond 380–780 nm. The
    /// values themselves where these are the default bands.
    pub fn from_default_bands(&self, values: &[f32]) -> Vec<f32> {
        if *self == Self::DEFAULT {
            return values.to_vec();
        }
        const SUB: usize = 8;
        // The default band of each of a band's SUB wavelengths, once for every run.
        let source: Vec<usize> = (0..self.count * SUB)
            .map(|i| Self::DEFAULT.band_of(self.point_nm(i / SUB, i % SUB, SUB) as f32))
            .collect();
        values
            .chunks_exact(BANDS)
            .flat_map(|run| {
                source
                    .chunks_exact(SUB)
                    .map(move |bands| bands.iter().map(|&k| run[k]).sum::<f32>() / SUB as f32)
            })
            .collect()
    }
}

/// Where each instance's patches start.
pub struct PatchMap {
    /// Per instance: its first patch, `None` when it has none.
    pub first_patch: Vec<Option<u32>>,
    /// Per instance: patches per primitive (1 one-sided, 2 when both sides reflect or emit;
    /// the front — the geometric normal's side — first).
    pub sides: Vec<u8>,
    /// Per patch: its normal.
    pub normals: Vec<Vec3A>,
    /// Per instance: its index in `carriers` when it is a tiled carrier, whose one patch
    /// per side stands for all its primitives (its tile's faces).
    pub carrier: Vec<Option<u32>>,
    /// The tiled carriers (`tiled.rs`).
    pub carriers: TiledCarriers,
    /// Per instance: how a sphere or disk was meshed (`meshed.rs`).
    pub meshing: Vec<Option<Meshing>>,
    /// The meshed spheres, whose patches' points rays start from lifted onto them.
    pub spheres: Vec<LiftSphere>,
    /// The bands the patches' values are in.
    pub bands: SolutionBands,
}

impl PatchMap {
    /// The patch seen by a ray arriving at point `p` of primitive `primitive` of instance
    /// `instance` from direction `wo` (pointing away from the surface).
    pub fn patch_of(&self, instance: u32, primitive: u32, p: Vec3A, wo: Vec3A) -> Option<usize> {
        let first = (*self.first_patch.get(instance as usize)?)?;
        let sides = u32::from(self.sides[instance as usize]);
        let primitive = if self.carrier[instance as usize].is_some() {
            0
        } else if let Some(m) = &self.meshing[instance as usize] {
            m.primitive_at(p)
        } else {
            primitive
        };
        let front = (first + primitive * sides) as usize;
        if self.normals.get(front)?.dot(wo) > 0.0 {
            Some(front)
        } else if sides == 2 {
            Some(front + 1)
        } else {
            None
        }
    }
}

impl PatchMap {
    /// The tiled carrier (an index into `carriers`) that input patch `patch` is a side of.
    pub fn carrier_of_patch(&self, patch: u32) -> Option<usize> {
        self.carriers.0.iter().position(|c| {
            self.first_patch[c.instance as usize]
                .is_some_and(|first| (first..first + 2).contains(&patch))
        })
    }

    /// Where rays of the patch point `p` (normal `n`) start when not just off its plane:
    /// above a tiled carrier's slab, or on the sphere a meshed sphere's triangle stands for.
    pub fn lift(&self, p: Vec3A, n: Vec3A) -> Option<Vec3A> {
        self.carriers
            .lift(p, n)
            .or_else(|| self.spheres.iter().find_map(|s| s.lift(p, n)))
    }
}

/// A material's diffuse reflectance and whether it reflects on both sides; what radiosity
/// cannot represent is an error naming it.
fn lambertian(material: &Material) -> Result<(&Spectrum, bool), String> {
    let (inner, two_sided) = match material {
        Material::TwoSided { material } => (&**material, true),
        m @ (Material::Surface(_)
        | Material::Mask { .. }
        | Material::NormalMap { .. }
        | Material::BumpMap { .. }) => (m, false),
    };
    inner
        .constant_lambert()
        .map(|s| (s, two_sided))
        .ok_or_else(|| {
            "not a constant `lambert` (or `two_sided` of one): radiosity transfers diffuse light \
         only, from untextured reflectances (the paper's directional transfers and textured \
         patches are not built yet)"
                .into()
        })
}

/// The patches of `scene` in `bands` and their map; an error names what the solution cannot
/// hold.
pub fn scene_patches(
    scene: &RenderScene,
    bands: SolutionBands,
) -> Result<(Vec<InputPatch>, PatchMap), String> {
    let geometry: &Geometry = &scene.geometry;
    let mut patches = Vec::new();
    let mut map = PatchMap {
        first_patch: Vec::with_capacity(geometry.instances().len()),
        sides: Vec::with_capacity(geometry.instances().len()),
        normals: Vec::new(),
        carrier: Vec::with_capacity(geometry.instances().len()),
        carriers: TiledCarriers::of_geometry(geometry, scene.tiled_surfaces()?, bands)?,
        bands,
        meshing: Vec::with_capacity(geometry.instances().len()),
        spheres: Vec::new(),
    };
    for (instance_id, inst) in geometry.instances().iter().enumerate() {
        let carrier = map
            .carriers
            .0
            .iter()
            .position(|c| c.instance == instance_id as u32);
        map.carrier.push(carrier.map(|k| k as u32));
        map.meshing.push(None);
        if let Some(c) = carrier.map(|k| &map.carriers.0[k]) {
            // Front and back, each directional by the pyramid's top level (its diffuse
            // equivalent for the oracle).
            let shape = c.shape();
            let first = patches.len() as u32;
            map.first_patch.push(Some(first));
            map.sides.push(2);
            for (side, n) in [c.normal, -c.normal].into_iter().enumerate() {
                let oriented_shape = oriented(shape, n);
                patches.push(InputPatch {
                    shape: oriented_shape,
                    reflectance: c.reflectance[side].clone(),
                    emission: vec![0.0; bands.count],
                    surface: instance_id as u32,
                    directional: Some(DirectionalSide {
                        surface: c.surface.clone(),
                        front: side == 0,
                        partner: first + 1 - side as u32,
                    }),
                });
                map.normals.push(oriented_shape.normal());
            }
            continue;
        }
        let area_light = scene
            .lights
            .area_light_of_instance(instance_id as u32)
            .and_then(|l| {
                if let Light::Area(a) = scene.lights.light(l) {
                    Some(a)
                } else {
                    None
                }
            });
        let emission =
            area_light.map(|a| (bands.means(&a.radiance, std::f64::consts::PI), a.two_sided));
        // (world triangle or parallelogram, object-space geometric normal, material id)
        let mut pieces: Vec<(ElementShape, Vec3A, u32)> = Vec::new();
        match inst.shape {
            Shape::Rectangle(r) => {
                let t = &inst.to_world;
                let (w, h) = (r.half_width_m, r.half_height_m);
                let p0 = t.point(Vec3A::new(-w, -h, 0.0));
                let e1 = t.point(Vec3A::new(w, -h, 0.0)) - p0;
                let e2 = t.point(Vec3A::new(-w, h, 0.0)) - p0;
                pieces.push((
                    ElementShape::Parallelogram { p0, e1, e2 },
                    Vec3A::Z,
                    inst.material.unwrap_or(NO_MATERIAL),
                ));
            }
            Shape::Mesh(id) => {
                let mesh = geometry.mesh(id);
                for (tri, idx) in mesh.indices.iter().enumerate() {
                    let p = idx.map(|i| mesh.positions[i as usize]);
                    // The renderer's own geometric normal (on the shading normal's side).
                    let ng = triangle_local_geometry(mesh, tri, [1.0 / 3.0; 3]).n_geometric;
                    let w = p.map(|v| inst.to_world.point(v));
                    pieces.push((
                        ElementShape::Triangle {
                            p0: w[0],
                            e1: w[1] - w[0],
                            e2: w[2] - w[0],
                        },
                        ng,
                        inst.material.unwrap_or(mesh.material_ids[tri]),
                    ));
                }
            }
            Shape::Tiled(_) => {
                return Err(format!(
                    "instance {instance_id}: internal error: a tiled carrier without its tile \
                     pyramid"
                ))
            }
            Shape::Sphere(_) | Shape::Disk(_) => {
                let (triangles, meshing, sphere) = mesh_analytic(instance_id, inst)?;
                let material = inst.material.unwrap_or(NO_MATERIAL);
                pieces.extend(triangles.into_iter().map(|(t, n)| (t, n, material)));
                map.meshing[instance_id] = Some(meshing);
                map.spheres.extend(sphere);
            }
        }
        let mut kinds = Vec::with_capacity(pieces.len());
        for &(_, _, material_id) in &pieces {
            kinds.push(
                lambertian(scene.material(material_id)).map_err(|e| {
                    format!("material `{}` is {e}", scene.material_name(material_id))
                })?,
            );
        }
        let emits_back = emission.as_ref().is_some_and(|(_, two)| *two);
        // Both sides get patches on every primitive of the instance when one needs them,
        // so that a hit's patch is first + primitive × sides.
        let both = emits_back || kinds.iter().any(|&(_, two_sided)| two_sided);
        let sides: u8 = if both { 2 } else { 1 };
        let first = patches.len() as u32;
        let none = vec![0.0; bands.count];
        let emitted = emission.as_ref().map_or(none.clone(), |(e, _)| e.clone());
        for ((shape, ng_object, _), (reflectance, two_sided)) in pieces.into_iter().zip(kinds) {
            let n = inst.to_world.normal(ng_object).normalize_or_zero();
            let front = oriented(shape, n);
            let rho = bands.means(reflectance, 1.0);
            patches.push(InputPatch {
                shape: front,
                reflectance: rho.clone(),
                emission: emitted.clone(),
                surface: instance_id as u32,
                directional: None,
            });
            map.normals.push(front.normal());
            if both {
                let back = oriented(shape, -n);
                patches.push(InputPatch {
                    shape: back,
                    reflectance: if two_sided { rho } else { none.clone() },
                    emission: if emits_back {
                        emitted.clone()
                    } else {
                        none.clone()
                    },
                    surface: instance_id as u32,
                    directional: None,
                });
                map.normals.push(back.normal());
            }
        }
        map.first_patch
            .push((patches.len() as u32 > first).then_some(first));
        map.sides.push(sides);
    }
    Ok((patches, map))
}

/// `shape` with its vertex order turned so that its normal points along `n`.
fn oriented(shape: ElementShape, n: Vec3A) -> ElementShape {
    if shape.normal().dot(n) >= 0.0 {
        return shape;
    }
    match shape {
        ElementShape::Parallelogram { p0, e1, e2 } => {
            ElementShape::Parallelogram { p0, e1: e2, e2: e1 }
        }
        ElementShape::Triangle { p0, e1, e2 } => ElementShape::Triangle { p0, e1: e2, e2: e1 },
    }
}

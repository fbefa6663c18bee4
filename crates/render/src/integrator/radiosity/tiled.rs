//! Tiled surfaces in the radiosity solution (Mostefaoui et al. §3): a tiled carrier is one
//! patch per side, directional by its tile pyramid's top level Γ
//! (`tile_pyramid::TiledSurface`, `prism_radiosity::directional`): light arriving on
//! either side leaves both by Γ, per direction bin, relative to the irradiance on the
//! carrier's plane. Light through the tile's holes is not in Γ: rays cross the carrier
//! through its virtual geometry, so the transfers behind it see exactly the transparency
//! (the paper's fourth kind of transfer). Points of a tiled patch therefore take their rays
//! from above the tile's slab on their side, where the whole macro-surface's irradiance
//! arrives: from the plane itself they would start inside the weave.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3A;
use prism_geometry::{Geometry, Shape};
use prism_radiosity::directional::{DirectionalSurface, FinerPyramids};
use prism_radiosity::tile_cells::TileLattice;
use prism_radiosity::ElementShape;

use super::patches::{PatchMap, SolutionBands};
use crate::scene_build::RenderScene;
use crate::tile_pyramid::{TilePyramid, TiledSurface};

impl TiledCarrier {
    /// The carrier's parallelogram, front along `normal`.
    pub fn shape(&self) -> ElementShape {
        ElementShape::Parallelogram {
            p0: self.p0,
            e1: self.e1,
            e2: self.e2,
        }
    }
}

/// One tiled carrier: its parallelogram, frame and slab.
#[derive(Clone, Debug)]
pub struct TiledCarrier {
    pub instance: u32,
    pub p0: Vec3A,
    pub e1: Vec3A,
    pub e2: Vec3A,
    /// Unit normal (the tile's +z).
    pub normal: Vec3A,
    /// The tile's heights along `normal`, metres.
    pub slab_m: (f32, f32),
    /// Reflectance per band, front then back (the diffuse equivalent the oracle reads).
    pub reflectance: [Vec<f32>; 2],
    /// Its pyramid's Γ and τ̄ in the tile's frame: the unit tangent along `e1` (the tile's
    /// x), the tile's y made orthogonal to it and the normal (−(n × t) under a mirroring
    /// transform, where the frame is left-handed), and `normal`; its lattice has a period
    /// corner at `p0`.
    pub surface: Arc<DirectionalSurface>,
}

/// Every tiled carrier of a scene.
#[derive(Clone, Debug, Default)]
pub struct TiledCarriers(pub Vec<TiledCarrier>);

impl TiledCarriers {
    /// The carriers of the `Shape::Tiled` instances of `geometry`, with the surfaces of
    /// their materials (`surfaces[material id]`), in the solution's `bands`.
    pub fn of_geometry(
        geometry: &Geometry,
        surfaces: &[Option<TiledSurface>],
        bands: SolutionBands,
    ) -> Result<Self, String> {
        let mut out = Vec::new();
        for (instance, inst) in geometry.instances().iter().enumerate() {
            let Shape::Tiled(tiling) = inst.shape else {
                continue;
            };
            let surface = inst
                .material
                .and_then(|m| surfaces.get(m as usize))
                .and_then(Option::as_ref)
                .ok_or_else(|| {
                    format!(
                        "instance {instance}: internal error: its tile pyramid was not computed"
                    )
                })?;
            let t = &inst.to_world;
            let e1 = t.vector(Vec3A::new(
                tiling.cells[0] as f32 * tiling.period_m[0],
                0.0,
                0.0,
            ));
            let e2 = t.vector(Vec3A::new(
                0.0,
                tiling.cells[1] as f32 * tiling.period_m[1],
                0.0,
            ));
            // The tile-to-world map keeps heights in metres along the unit normal.
            let normal = t.vector(Vec3A::Z).normalize();
            let tangent = e1.normalize();
            let y = t.vector(Vec3A::Y);
            let bitangent = (y - normal * normal.dot(y) - tangent * tangent.dot(y)).normalize();
            out.push(TiledCarrier {
                instance: instance as u32,
                p0: t.point(Vec3A::ZERO),
                e1,
                e2,
                normal,
                slab_m: surface.slab_m,
                reflectance: surface.reflectance.map(|r| bands.from_default_bands(&r)),
                surface: Arc::new(directional_surface(
                    [tangent, bitangent, normal],
                    TileLattice {
                        origin: t.point(Vec3A::ZERO),
                        period: [e1 / tiling.cells[0] as f32, e2 / tiling.cells[1] as f32],
                    },
                    surface,
                    bands,
                )),
            });
        }
        Ok(Self(out))
    }

    /// The carrier that `p` lies on (within 10⁻⁴ of its size from its plane and inside its
    /// parallelogram).
    fn carrier_at(&self, p: Vec3A) -> Option<&TiledCarrier> {
        self.0.iter().find(|c| {
            let size = c.e1.length().max(c.e2.length());
            if (p - c.p0).dot(c.normal).abs() > 1e-4 * size {
                return false;
            }
            let (u, v) = c.shape().parameters_of(p);
            (-1e-4..=1.0001).contains(&u) && (-1e-4..=1.0001).contains(&v)
        })
    }

    /// Where rays of the surface point `p` (normal `n`) start: above the tile's slab on the
    /// side `n` faces when `p` is on a tiled carrier; `None` otherwise.
    pub fn lift(&self, p: Vec3A, n: Vec3A) -> Option<Vec3A> {
        let c = self.carrier_at(p)?;
        let (lo, hi) = c.slab_m;
        let margin = 1e-3 * (hi - lo).max(1e-3);
        Some(if n.dot(c.normal) >= 0.0 {
            p + c.normal * (hi.max(0.0) + margin)
        } else {
            p + c.normal * (lo.min(0.0) - margin)
        })
    }

    /// τ̄ of carrier `carrier` (an index into the list) for light leaving along `wo`
    /// (world, unit): the share of its area that a viewer looking back along `wo` sees
    /// through (the whole period's).
    pub fn transparency_towards(&self, carrier: usize, wo: Vec3A) -> f32 {
        let c = &self.0[carrier];
        c.surface
            .see_through(&prism_radiosity::tile_cells::CellWeights::TOP, wo)
    }
}

/// The memory a finer pyramid may take without a memory limit, bytes.
const PYRAMID_BYTES_WITHOUT_LIMIT: u64 = 1 << 30;

/// Finer pyramids for the solution's tiled carriers: the tile simulated again with the
/// levels the carrier's elements read (at most its material's `levels`, and as many as
/// half the memory limit holds while the tile is simulated), once per material and depth.
/// Each pyramid made, or held back by the memory, adds a line of statistics.
pub struct TilePyramids<'a> {
    scene: &'a RenderScene,
    map: &'a PatchMap,
    /// What a pyramid may take while it is simulated, bytes.
    budget_bytes: u64,
    /// Per (material, levels): the surface of its finer pyramid.
    made: RefCell<HashMap<(u32, u32), Arc<TiledSurface>>>,
    /// (material, levels) pairs whose deeper pyramid the memory held back (said once).
    held_back: RefCell<HashSet<(u32, u32)>>,
    lines: RefCell<Vec<String>>,
}

impl<'a> TilePyramids<'a> {
    /// Pyramids for `scene`'s carriers (`map`) within half of `memory_limit_bytes` (1 GiB
    /// without a limit).
    pub fn new(scene: &'a RenderScene, map: &'a PatchMap, memory_limit_bytes: Option<u64>) -> Self {
        Self {
            scene,
            map,
            budget_bytes: memory_limit_bytes.map_or(PYRAMID_BYTES_WITHOUT_LIMIT, |m| m / 2),
            made: RefCell::default(),
            held_back: RefCell::default(),
            lines: RefCell::default(),
        }
    }

    /// The statistics lines of the pyramids made since the last call.
    pub fn take_lines(&self) -> Vec<String> {
        std::mem::take(&mut self.lines.borrow_mut())
    }
}

impl FinerPyramids for TilePyramids<'_> {
    fn with_levels(
        &self,
        patch: usize,
        surface: &DirectionalSurface,
        levels: u32,
    ) -> Result<Option<Arc<DirectionalSurface>>, String> {
        let Some(carrier) = self.map.carrier_of_patch(patch as u32) else {
            return Ok(None);
        };
        let instance = self.map.carriers.0[carrier].instance;
        let Some(material) = self.scene.geometry.instances()[instance as usize].material else {
            return Ok(None);
        };
        let Some((most, tile)) = self.scene.tiled_material_levels(material) else {
            return Ok(None);
        };
        let wanted = levels.min(most);
        // The deepest pyramid the memory allows.
        let levels = (1..=wanted)
            .rev()
            .find(|&l| TilePyramid::estimated_bytes(l) <= self.budget_bytes)
            .unwrap_or(1);
        let key = (material, levels);
        if levels < wanted && self.held_back.borrow_mut().insert(key) {
            self.lines.borrow_mut().push(format!(
                "radiosity: tile `{tile}`: elements down to 1/{} of a period would \
                 read a {wanted}-level pyramid, which needs {:.0} MiB while it is simulated, \
                 more than half the memory limit ({:.0} MiB): they read {levels} levels",
                1u32 << (wanted - 1),
                TilePyramid::estimated_bytes(wanted) as f64 / 1048576.0,
                self.budget_bytes as f64 / 1048576.0,
            ));
        }
        if levels <= surface.levels {
            return Ok(None);
        }
        let made = self.made.borrow().get(&key).cloned();
        let tiled = match made {
            Some(made) => made,
            None => {
                let start = Instant::now();
                let Some(tiled) = self.scene.tiled_surface_with_levels(material, levels)? else {
                    return Ok(None);
                };
                self.lines.borrow_mut().push(format!(
                    "radiosity: tile `{tile}`: a {levels}-level pyramid for elements down to \
                     1/{} of a period ({:.2} s)",
                    1u32 << (levels - 1),
                    start.elapsed().as_secs_f64()
                ));
                let tiled = Arc::new(tiled);
                self.made.borrow_mut().insert(key, tiled.clone());
                tiled
            }
        };
        Ok(Some(Arc::new(directional_surface(
            surface.frame,
            surface.lattice,
            &tiled,
            self.map.bands,
        ))))
    }
}

/// The solution's surface of a tile's pyramid `tiled` placed by `frame` and `lattice`, its
/// Γ carried from the pyramid's 16 bands into the solution's `bands` (each band the mean
/// of the pyramid's bands over it: finer solution bands see Γ in 25 nm steps).
fn directional_surface(
    frame: [Vec3A; 3],
    lattice: TileLattice,
    tiled: &TiledSurface,
    bands: SolutionBands,
) -> DirectionalSurface {
    DirectionalSurface {
        frame,
        lattice,
        levels: tiled.levels,
        gamma: bands.from_default_bands(&tiled.gamma),
        view_transparency: tiled.view_transparency.clone(),
    }
}

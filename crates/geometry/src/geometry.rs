//! All shapes of a scene under one BVH, flattened where that is cheap.
//!
//! Design: meshes are placed by instances (transform + shape). At build time every instance
//! of a mesh that is used once, or that is small and shared by a few instances
//! ([`FLATTEN_MAX_SHARED_MESH_TRIANGLES`], [`FLATTEN_SHARED_TRIANGLE_BUDGET`]), is *baked*:
//! its vertices are transformed to world space once each and its triangles become leaves of
//! the scene BVH, tested with the watertight test against the world ray. Everything else —
//! analytic shapes (sphere, disk, rectangle: exact; a rectangle baked as two world-space
//! triangles measured slower, docs/geometry.md), large shared meshes — is an *instance leaf*
//! of the same BVH, with the world box of the instance: the ray is taken into its object space
//! (direction not renormalised, so `t` is shared) and intersected in closed form or against
//! the mesh's own object-space BVH, which is stored once for all its instances. A scene that
//! is a single instance skips the BVH. Baked hits are re-tested on the object-space
//! triangle (once per closest-hit query) so that `t`, `b1`, `b2` carry the same bits as when
//! the mesh is traced as an instance; [`BuildOptions::flatten`] `= false` builds the
//! unflattened reference (every instance a leaf). Cuboids are 12-triangle meshes: their
//! faces are flat (zero curvature is exact), their shared edges get the same watertight
//! test as any closed mesh, and they need no separate intersector.

use glam::Vec3A;

use crate::bvh_build::{bvh_ray, BuildQuality};
use crate::disk::Disk;
use crate::interaction::SurfaceInteraction;
use crate::mesh::{TriangleMesh, NO_MATERIAL};
use crate::mesh_bvh::MeshBvh;
use crate::ray::{Ray, RayDifferential};
use crate::rectangle::Rectangle;
use crate::small_scene::{SmallScene, SmallSceneBuilder, NO_PRIMITIVE};
use crate::sphere::Sphere;
use crate::tiling::Tiling;
use crate::transform::Transform;
use crate::triangle::{TriangleHit, WatertightRay};
use crate::triangle_bvh::TriangleBvh;
use crate::triangle_geometry::triangle_local_geometry;

#[path = "geometry_stream.rs"]
mod stream;

/// Index of a mesh added to a [`GeometryBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub u32);

/// What an instance places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Mesh(MeshId),
    Sphere(Sphere),
    Disk(Disk),
    Rectangle(Rectangle),
    /// A periodic tile repeated over a grid (virtual ray tracing, [`crate::tiling`]); hits
    /// report the tile's faces, with their own materials.
    Tiled(Tiling),
}

/// A shape placed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub shape: Shape,
    /// Object → world.
    pub to_world: Transform,
    /// Material for analytic shapes and for mesh faces without one; when `Some`, it also
    /// overrides the mesh's per-face materials.
    pub material: Option<u32>,
}

/// The compact result of a closest-hit query; [`Geometry::interaction`] expands it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub instance_id: u32,
    /// Triangle index within the mesh (0 for analytic shapes); for a [`Shape::Tiled`]
    /// instance `cell · triangles + triangle` (cell `i + j·cells[0]`).
    pub primitive_id: u32,
    /// Barycentrics of vertices 1 and 2 (0 for analytic shapes).
    pub b1: f32,
    pub b2: f32,
}

/// Shared meshes (placed by more than one instance) with at most this many triangles are
/// baked into the world-space soup, one copy per instance (docs/geometry.md, "Flattening").
/// A mesh placed by exactly one instance is always baked: its copy replaces the mesh's own
/// BVH, so baking costs no memory.
pub const FLATTEN_MAX_SHARED_MESH_TRIANGLES: usize = 4096;

/// At most this many triangles are added to the soup by copies of shared meshes (≈ 70 bytes
/// each with leaf vertices, ids and BVH nodes, so ≈ 70 MiB); meshes are taken smallest first
/// until the budget is spent, the rest stay instanced.
pub const FLATTEN_SHARED_TRIANGLE_BUDGET: usize = 1 << 20;

/// Scenes of at most this many leaves (baked triangles + instance leaves) are traced without
/// a BVH, testing every leaf eight at a time ([`crate::small_scene`]; threshold measured in
/// docs/geometry.md, "Small scenes without a BVH").
pub const SMALL_SCENE_MAX_LEAVES: usize = 128;

/// How [`GeometryBuilder::build_with`] builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BuildOptions {
    pub quality: BuildQuality,
    /// Flatten (default `true`): one BVH over the whole scene whose leaves are the
    /// world-space triangles of small or single-use meshes and the remaining instances
    /// (analytic shapes, large shared meshes). `false` bakes nothing: the leaves are all
    /// instances, the two-level reference the flattened geometry is tested and benchmarked
    /// against.
    pub flatten: bool,
    /// Scenes of at most this many leaves skip the BVH and test every leaf, eight at a time
    /// (default [`SMALL_SCENE_MAX_LEAVES`]; 0 always builds the BVH, the reference the small
    /// path is tested and benchmarked against).
    pub small_scene_max_leaves: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            quality: BuildQuality::default(),
            flatten: true,
            small_scene_max_leaves: SMALL_SCENE_MAX_LEAVES,
        }
    }
}

impl From<BuildQuality> for BuildOptions {
    fn from(quality: BuildQuality) -> Self {
        Self {
            quality,
            ..Self::default()
        }
    }
}

/// Collects meshes and instances, then builds a [`Geometry`].
#[derive(Default)]
pub struct GeometryBuilder {
    meshes: Vec<TriangleMesh>,
    instances: Vec<Instance>,
}

impl GeometryBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn add_mesh(&mut self, mesh: TriangleMesh) -> MeshId {
        self.meshes.push(mesh);
        MeshId(self.meshes.len() as u32 - 1)
    }

    /// Place a shape; returns its instance id (the order of calls).
    /// Returns `None` if `shape` names a mesh that was not added, or a tiling whose grid
    /// is empty, whose period is not positive and finite, or whose cells × tile triangles
    /// do not fit the 32-bit primitive id of a [`Hit`].
    pub fn add_instance(
        &mut self,
        shape: Shape,
        to_world: Transform,
        material: Option<u32>,
    ) -> Option<u32> {
        match shape {
            Shape::Mesh(MeshId(m)) => {
                if m as usize >= self.meshes.len() {
                    return None;
                }
            }
            Shape::Tiled(tiling) => {
                let tile = self.meshes.get(tiling.mesh.0 as usize)?;
                let ids = u64::from(tiling.cells[0])
                    * u64::from(tiling.cells[1])
                    * tile.triangle_count() as u64;
                let period_ok = tiling.period_m.iter().all(|p| p.is_finite() && *p > 0.0);
                if ids == 0 || ids > u64::from(u32::MAX) || !period_ok {
                    return None;
                }
            }
            Shape::Sphere(_) | Shape::Disk(_) | Shape::Rectangle(_) => {}
        }
        self.instances.push(Instance {
            shape,
            to_world,
            material,
        });
        Some(self.instances.len() as u32 - 1)
    }

    /// Build with flattening (the default [`BuildOptions`]) at `quality`.
    pub fn build(self, quality: BuildQuality) -> Geometry {
        self.build_with(quality.into())
    }

    /// Bake the flattened mesh instances into world-space triangles, build the object-space
    /// BVHs of the meshes that stay instanced, and one BVH over the triangles and the
    /// remaining instances' world boxes (in parallel inside obvhs when its `parallel`
    /// feature is on).
    pub fn build_with(self, options: BuildOptions) -> Geometry {
        let quality = options.quality;
        let bake_mesh = if options.flatten {
            meshes_to_bake(&self.meshes, &self.instances)
        } else {
            vec![false; self.meshes.len()]
        };
        let mut leaves: Vec<[Vec3A; 3]> = Vec::new();
        let mut leaf_ids: Vec<Leaf> = Vec::new();
        let mut kept: Vec<u32> = Vec::new();
        let mut mesh_needs_bvh = vec![false; self.meshes.len()];
        for (i, inst) in self.instances.iter().enumerate() {
            let instance = i as u32;
            match inst.shape {
                Shape::Mesh(MeshId(m)) if bake_mesh[m as usize] => bake_mesh_instance(
                    &self.meshes[m as usize],
                    &inst.to_world,
                    instance,
                    &mut leaves,
                    &mut leaf_ids,
                ),
                Shape::Mesh(MeshId(m))
                | Shape::Tiled(Tiling {
                    mesh: MeshId(m), ..
                }) => {
                    mesh_needs_bvh[m as usize] = true;
                    kept.push(instance);
                }
                Shape::Sphere(_) | Shape::Disk(_) | Shape::Rectangle(_) => kept.push(instance),
            }
        }
        let triangles = leaves.len();
        let meshes: Vec<MeshBvh> = self
            .meshes
            .into_iter()
            .zip(mesh_needs_bvh)
            .map(|(m, needs_bvh)| {
                if needs_bvh {
                    MeshBvh::build(m, quality)
                } else {
                    MeshBvh::without_bvh(m)
                }
            })
            .collect();
        // Instance leaves carry their world box (min, max) in place of triangle vertices.
        for &i in &kept {
            if let Some((lo, hi)) = instance_bounds(&self.instances[i as usize], &meshes) {
                leaves.push([lo, hi, Vec3A::ZERO]);
                leaf_ids.push(Leaf {
                    instance: i,
                    primitive: Leaf::INSTANCE,
                });
            }
        }
        let instance_leaves = leaves.len() - triangles;
        let single = match leaf_ids.as_slice() {
            // One instance: its box test would only repeat its own root test.
            [only] if only.is_instance() => Some(only.instance),
            _ => None,
        };
        let small = (!leaves.is_empty()
            && single.is_none()
            && leaves.len() <= options.small_scene_max_leaves)
            .then(|| small_scene(&leaves, &leaf_ids, &self.instances));
        let scene = (!leaves.is_empty() && single.is_none() && small.is_none())
            .then(|| TriangleBvh::build_with_bounds(&leaves, &leaf_ids, leaf_bounds, quality));
        let flat_records = self.instances.iter().map(flat_record).collect();
        Geometry {
            meshes,
            flat_records,
            instances: self.instances,
            scene,
            small,
            single,
            simd: prism_cpu::active(),
            triangles,
            instance_leaves,
        }
    }
}

/// Which meshes get baked: every mesh placed exactly once, and shared meshes of at most
/// [`FLATTEN_MAX_SHARED_MESH_TRIANGLES`] triangles, smallest first, while their copies fit in
/// [`FLATTEN_SHARED_TRIANGLE_BUDGET`].
fn meshes_to_bake(meshes: &[TriangleMesh], instances: &[Instance]) -> Vec<bool> {
    let mut uses = vec![0usize; meshes.len()];
    for inst in instances {
        if let Shape::Mesh(MeshId(m)) = inst.shape {
            uses[m as usize] += 1;
        }
    }
    let mut bake: Vec<bool> = uses.iter().map(|&u| u == 1).collect();
    let mut shared: Vec<usize> = (0..meshes.len())
        .filter(|&m| uses[m] > 1 && meshes[m].triangle_count() <= FLATTEN_MAX_SHARED_MESH_TRIANGLES)
        .collect();
    shared.sort_by_key(|&m| (meshes[m].triangle_count(), m));
    let mut budget = FLATTEN_SHARED_TRIANGLE_BUDGET;
    for m in shared {
        let cost = meshes[m].triangle_count() * uses[m];
        if cost <= budget {
            budget -= cost;
            bake[m] = true;
        }
    }
    bake
}

/// The world-space triangles of one mesh instance. Each vertex is transformed once, so
/// triangles that share a vertex in the mesh share its world-space bits and the watertight
/// test keeps closed meshes closed; an identity transform copies the positions exactly.
fn bake_mesh_instance(
    mesh: &TriangleMesh,
    to_world: &Transform,
    instance: u32,
    leaves: &mut Vec<[Vec3A; 3]>,
    ids: &mut Vec<Leaf>,
) {
    let transformed: Vec<Vec3A>;
    let world: &[Vec3A] = if to_world.is_identity() {
        &mesh.positions
    } else {
        transformed = mesh.positions.iter().map(|&p| to_world.point(p)).collect();
        &transformed
    };
    leaves.extend(
        mesh.indices
            .iter()
            .map(|&[a, b, c]| [world[a as usize], world[b as usize], world[c as usize]]),
    );
    ids.extend((0..mesh.triangle_count() as u32).map(|primitive| Leaf {
        instance,
        primitive,
    }));
}

/// World bounds of an instance left as a leaf; `None` for an empty mesh (no ray reaches it).
fn instance_bounds(inst: &Instance, meshes: &[MeshBvh]) -> Option<(Vec3A, Vec3A)> {
    let (lo, hi) = match inst.shape {
        Shape::Mesh(MeshId(m)) => meshes[m as usize].bounds(),
        Shape::Sphere(s) => s.bounds(),
        Shape::Disk(d) => d.bounds(),
        Shape::Rectangle(r) => r.bounds(),
        Shape::Tiled(tiling) => {
            let tile = meshes[tiling.mesh.0 as usize].bounds();
            if tile.0.cmpgt(tile.1).any() {
                return None;
            }
            tiling.bounds(tile)
        }
    };
    if lo.cmpgt(hi).any() {
        return None;
    }
    Some(inst.to_world.bounds(lo, hi))
}

/// The shading record of a rectangle instance (`SurfaceInteraction::from_local_with`
/// without curvature) at its centre: a rectangle's normals and tangents are the same at
/// every point, so a hit only fills in `p`, `t` and `uv` (see `Geometry::interaction_with`).
/// `None` for other shapes.
fn flat_record(inst: &Instance) -> Option<Box<SurfaceInteraction>> {
    match inst.shape {
        Shape::Rectangle(r) => Some(Box::new(SurfaceInteraction::from_local_with(
            &r.local_geometry(Vec3A::ZERO),
            &inst.to_world,
            0.0,
            false,
        ))),
        _ => None,
    }
}

/// The leaves of a scene traced without a BVH: baked triangles and rectangles in batches,
/// other instances (boxes in `leaves`) one by one.
fn small_scene(leaves: &[[Vec3A; 3]], ids: &[Leaf], instances: &[Instance]) -> SmallScene {
    let mut b = SmallSceneBuilder::new();
    for (p, id) in leaves.iter().zip(ids) {
        if !id.is_instance() {
            b.triangle(*p, id.instance, id.primitive);
            continue;
        }
        let inst = &instances[id.instance as usize];
        match inst.shape {
            Shape::Rectangle(r) => b.rectangle(r, inst.to_world, id.instance),
            _ => b.other(p[0], p[1], id.instance),
        }
    }
    b.build()
}

/// Bounds of a leaf: a triangle's vertices, or the box an instance leaf carries.
#[inline]
fn leaf_bounds(p: &[Vec3A; 3], id: Leaf) -> (Vec3A, Vec3A) {
    if id.is_instance() {
        (p[0], p[1])
    } else {
        (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
    }
}

/// What a leaf of the scene BVH stands for.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    instance: u32,
    /// Triangle index in the instance's mesh (a baked triangle), or [`Leaf::INSTANCE`].
    primitive: u32,
}

impl crate::leaf_record::SlotId for Leaf {
    #[inline(always)]
    fn to_lanes(self) -> [u32; 3] {
        [self.instance, self.primitive, 0]
    }

    #[inline(always)]
    fn from_lanes(lanes: [u32; 3]) -> Self {
        Self {
            instance: lanes[0],
            primitive: lanes[1],
        }
    }
}

impl Leaf {
    /// The leaf is a whole instance, intersected in its object space.
    const INSTANCE: u32 = u32::MAX;

    #[inline(always)]
    fn is_instance(self) -> bool {
        self.primitive == Self::INSTANCE
    }
}

/// One ray's closest hit so far in the scene BVH: an instance leaf's, or a baked triangle's
/// (completed by `baked_hit` only once the traversal has ended). The one-ray traversal
/// (`intersect_scene_with`) and the ray stream (`intersect_stream`) share it.
struct SceneBest {
    watertight: WatertightRay,
    instance: Option<Hit>,
    triangle: Option<(TriangleHit, Leaf)>,
}

impl SceneBest {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        Self {
            watertight: WatertightRay::new(ray.origin, ray.direction, ray.t_min),
            instance: None,
            triangle: None,
        }
    }

    /// The scene traversal's leaf test for `ray`: the `t` of a hit on leaf `leaf` (stored
    /// vertices `p`) below `t_max`, kept as the best, or ∞.
    #[inline(always)]
    fn test(
        &mut self,
        geometry: &Geometry,
        ray: &Ray,
        p: &[Vec3A; 3],
        leaf: Leaf,
        t_max: f32,
    ) -> f32 {
        if leaf.is_instance() {
            match geometry.intersect_instance_any_isa(leaf.instance, ray, t_max) {
                Some(h) => {
                    self.instance = Some(h);
                    self.triangle = None;
                    h.t
                }
                None => f32::INFINITY,
            }
        } else {
            match self.watertight.intersect(p[0], p[1], p[2], t_max) {
                Some(h) => {
                    self.triangle = Some((h, leaf));
                    self.instance = None;
                    h.t
                }
                None => f32::INFINITY,
            }
        }
    }

    /// The closest hit of `ray` once its traversal has ended.
    #[inline(always)]
    fn hit(self, geometry: &Geometry, ray: &Ray) -> Option<Hit> {
        self.instance.or_else(|| {
            self.triangle
                .map(|(h, leaf)| geometry.baked_hit(ray, h.t, h.b1, h.b2, leaf))
        })
    }
}

/// Every shape of a scene with its acceleration structures; immutable and `Sync`, so many
/// threads can trace against it.
pub struct Geometry {
    meshes: Vec<MeshBvh>,
    instances: Vec<Instance>,
    /// Per instance: for a rectangle its constant world-space normals and tangents
    /// (`flat_record`), which `shading_interaction` copies instead of transforming them per
    /// hit (the same bits: every field is computed by the same expression).
    flat_records: Vec<Option<Box<SurfaceInteraction>>>,
    /// One BVH over baked world-space triangles and instance leaves; `None` when the scene
    /// is empty, is a single instance or is small.
    scene: Option<TriangleBvh<Leaf>>,
    /// The leaves of a scene of at most [`BuildOptions::small_scene_max_leaves`], tested
    /// without a BVH.
    small: Option<SmallScene>,
    /// The only leaf, an instance, traced without a box test.
    single: Option<u32>,
    /// The widest kernels the scene BVH's traversal runs (`prism_cpu::active()` at build).
    simd: prism_cpu::Simd,
    triangles: usize,
    instance_leaves: usize,
}

impl Geometry {
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// World-space bounds (min, max) of instance `instance_id`, metres; `None` for an empty
    /// mesh or an unknown id.
    pub fn instance_world_bounds(&self, instance_id: u32) -> Option<(Vec3A, Vec3A)> {
        let inst = self.instances.get(instance_id as usize)?;
        instance_bounds(inst, &self.meshes)
    }

    /// Number of distinct meshes stored (instances share them).
    pub fn mesh_count(&self) -> usize {
        self.meshes.len()
    }

    pub fn mesh(&self, id: MeshId) -> &TriangleMesh {
        &self.meshes[id.0 as usize].mesh
    }

    /// Number of world-space triangles the flattened mesh instances were baked into.
    pub fn flattened_triangle_count(&self) -> usize {
        self.triangles
    }

    /// Number of instances traced in their object space (analytic shapes, meshes that were
    /// not flattened).
    pub fn instance_leaf_count(&self) -> usize {
        self.instance_leaves
    }

    /// Whether the scene is traced without a BVH, every leaf tested eight at a time (at most
    /// [`BuildOptions::small_scene_max_leaves`] leaves).
    pub fn is_small_scene(&self) -> bool {
        self.small.is_some()
    }

    /// The same geometry with the kernels of `simd` (the tests that check every ISA's
    /// traversal agrees; `simd` must be one this CPU runs, as `prism_cpu::each_isa` gives).
    pub fn with_simd(mut self, simd: prism_cpu::Simd) -> Self {
        self.simd = simd;
        self.small = self.small.map(|s| s.with_simd(simd));
        self
    }

    /// A small scene with leaves other than baked triangles and rectangles (spheres,
    /// disks, instanced meshes), tested one by one after the batches.
    pub(crate) fn has_other_small_leaves(&self) -> bool {
        self.small.as_ref().is_some_and(|s| !s.others.is_empty())
    }

    /// Closest hit of `ray` in `(t_min, t_max)`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if let Some(small) = &self.small {
            return self.intersect_small(small, ray);
        }
        let Some(scene) = &self.scene else {
            return self
                .single
                .and_then(|i| self.intersect_instance_any_isa(i, ray, ray.t_max));
        };
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: `Simd::avx2` is true only where the CPU runs AVX2, FMA, BMI1/2, LZCNT
            // and POPCNT.
            return unsafe { self.intersect_scene_avx2(scene, ray) };
        }
        self.intersect_scene(scene, ray)
    }

    /// [`Self::intersect_scene`] compiled for x86-64-v3 (the `avx2` level): the same
    /// arithmetic (Rust never fuses `a * b + c` into an FMA, so the hits are the same bits)
    /// in VEX code, with one-instruction bit counts for the traversal's masks (docs/geometry.md).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn intersect_scene_avx2(&self, scene: &TriangleBvh<Leaf>, ray: &Ray) -> Option<Hit> {
        // SAFETY: this function runs only where the CPU has AVX2.
        unsafe { self.intersect_scene_with::<true>(scene, ray) }
    }

    /// Closest hit in the scene BVH.
    #[inline(always)]
    fn intersect_scene(&self, scene: &TriangleBvh<Leaf>, ray: &Ray) -> Option<Hit> {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.intersect_scene_with::<false>(scene, ray) }
    }

    /// [`Self::intersect_scene`] with the node test of `WIDE` (`TriangleBvh::traverse_with`).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn intersect_scene_with<const WIDE: bool>(
        &self,
        scene: &TriangleBvh<Leaf>,
        ray: &Ray,
    ) -> Option<Hit> {
        let mut best = SceneBest::new(ray);
        let test = |p: &[Vec3A; 3], leaf: Leaf, t_max: f32| best.test(self, ray, p, leaf, t_max);
        // SAFETY: the caller's contract for `WIDE`.
        unsafe {
            scene.traverse_with::<WIDE>(ray.origin, ray.direction, ray.t_min, ray.t_max, test)
        };
        best.hit(self, ray)
    }

    /// [`Self::intersect`] of a small scene: all triangle and rectangle leaves at once, then
    /// the other instance leaves one by one against the closest `t` so far.
    fn intersect_small(&self, small: &SmallScene, ray: &Ray) -> Option<Hit> {
        let (o, d) = (ray.origin, ray.direction);
        let wt = WatertightRay::new(o, d, ray.t_min);
        let candidate = small.closest(o, d, &wt, ray.t_max);
        let mut t_max = candidate.map_or(ray.t_max, |c| c.t);
        let mut best_other = None;
        if !small.others.is_empty() {
            let inv = bvh_ray(o, d, ray.t_min, ray.t_max).inv_direction;
            for leaf in &small.others {
                if slab_hit(leaf.lo, leaf.hi, o, inv, ray.t_min, t_max) {
                    if let Some(h) = self.intersect_instance_any_isa(leaf.instance, ray, t_max) {
                        t_max = h.t;
                        best_other = Some(h);
                    }
                }
            }
        }
        if best_other.is_some() {
            return best_other;
        }
        let c = candidate?;
        Some(if c.primitive == NO_PRIMITIVE {
            Hit {
                t: c.t,
                instance_id: c.instance,
                primitive_id: 0,
                b1: 0.0,
                b2: 0.0,
            }
        } else {
            self.baked_hit(
                ray,
                c.t,
                c.b1,
                c.b2,
                Leaf {
                    instance: c.instance,
                    primitive: c.primitive,
                },
            )
        })
    }

    /// The [`Hit`] of a baked triangle, with `t`, `b1` and `b2` recomputed by the watertight
    /// test on the object-space triangle and ray (one triangle test per closest-hit query),
    /// so that a flattened instance reports the same bits as when it is traced as an
    /// instance. The world-space triangles decide *whether* and *which* triangle is hit;
    /// should the object-space test round the other way at an edge, the world-space values
    /// are kept.
    #[inline]
    fn baked_hit(&self, ray: &Ray, t: f32, b1: f32, b2: f32, leaf: Leaf) -> Hit {
        let mut hit = Hit {
            t,
            instance_id: leaf.instance,
            primitive_id: leaf.primitive,
            b1,
            b2,
        };
        let inst = &self.instances[leaf.instance as usize];
        // Identity instances were baked with their own vertex bits: nothing to redo.
        if let (Shape::Mesh(MeshId(m)), false) = (inst.shape, inst.to_world.is_identity()) {
            let (o, d) = object_ray(inst, ray);
            let [a, b, c] = self.meshes[m as usize]
                .mesh
                .triangle(leaf.primitive as usize);
            if let Some(oh) = WatertightRay::new(o, d, ray.t_min).intersect(a, b, c, ray.t_max) {
                hit.t = oh.t;
                hit.b1 = oh.b1;
                hit.b2 = oh.b2;
            }
        }
        hit
    }

    /// Closest hit on one instance with `t` in `(ray.t_min, t_max)`.
    #[inline]
    fn intersect_instance(&self, instance_id: u32, ray: &Ray, t_max: f32) -> Option<Hit> {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.intersect_instance_with::<false>(instance_id, ray, t_max) }
    }

    /// [`Self::intersect_instance`] as x86-64-v3 code with the 8-wide node test where the
    /// CPU has it (`simd`), out of line: the scene traversal's loop stays small for the
    /// baked triangles it mostly tests; also for the paths without a scene BVH (a scene of
    /// one instance, the small scene's instance leaves).
    #[inline]
    fn intersect_instance_any_isa(&self, instance_id: u32, ray: &Ray, t_max: f32) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: `Simd::avx2` is true only where the CPU runs AVX2, FMA, BMI1/2, LZCNT
            // and POPCNT.
            return unsafe { self.intersect_instance_avx2(instance_id, ray, t_max) };
        }
        self.intersect_instance(instance_id, ray, t_max)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    unsafe fn intersect_instance_avx2(
        &self,
        instance_id: u32,
        ray: &Ray,
        t_max: f32,
    ) -> Option<Hit> {
        // SAFETY: this function runs only where the CPU has AVX2.
        unsafe { self.intersect_instance_with::<true>(instance_id, ray, t_max) }
    }

    /// [`Self::occludes`] as [`Self::intersect_instance_any_isa`].
    #[inline]
    fn occludes_any_isa(&self, instance_id: u32, ray: &Ray) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: `Simd::avx2` is true only where the CPU runs AVX2, FMA, BMI1/2, LZCNT
            // and POPCNT.
            return unsafe { self.occludes_avx2(instance_id, ray) };
        }
        self.occludes(instance_id, ray)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    unsafe fn occludes_avx2(&self, instance_id: u32, ray: &Ray) -> bool {
        // SAFETY: this function runs only where the CPU has AVX2.
        unsafe { self.occludes_with::<true>(instance_id, ray) }
    }

    /// [`Self::intersect_instance`] with the mesh BVHs' node test of `WIDE`.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn intersect_instance_with<const WIDE: bool>(
        &self,
        instance_id: u32,
        ray: &Ray,
        t_max: f32,
    ) -> Option<Hit> {
        let inst = &self.instances[instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        match inst.shape {
            // SAFETY (both arms): the caller's contract for `WIDE`.
            Shape::Mesh(MeshId(m)) => {
                unsafe { self.meshes[m as usize].intersect_with::<WIDE>(o, d, ray.t_min, t_max) }
                    .map(|h| h.in_instance(instance_id))
            }
            Shape::Tiled(tiling) => {
                let tile = &self.meshes[tiling.mesh.0 as usize];
                unsafe { tiling.intersect_with::<WIDE>(tile, o, d, ray.t_min, t_max) }.map(|h| {
                    Hit {
                        t: h.hit.t,
                        instance_id,
                        primitive_id: Tiling::primitive_id(
                            h.cell,
                            h.hit.triangle,
                            tile.mesh.triangle_count() as u32,
                        ),
                        b1: h.hit.b1,
                        b2: h.hit.b2,
                    }
                })
            }
            _ => analytic_intersect(&inst.shape, &Ray::new(o, d, ray.t_min, t_max)).map(|t| Hit {
                t,
                instance_id,
                primitive_id: 0,
                b1: 0.0,
                b2: 0.0,
            }),
        }
    }

    /// Whether anything blocks `ray` in `(t_min, t_max)` — the shadow-ray query; it stops at
    /// the first hit (obvhs `ray_traverse_miss`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        if let Some(small) = &self.small {
            let (o, d) = (ray.origin, ray.direction);
            let wt = WatertightRay::new(o, d, ray.t_min);
            if small.any(o, d, &wt, ray.t_max) {
                return true;
            }
            if small.others.is_empty() {
                return false;
            }
            let inv = bvh_ray(o, d, ray.t_min, ray.t_max).inv_direction;
            return small.others.iter().any(|leaf| {
                slab_hit(leaf.lo, leaf.hi, o, inv, ray.t_min, ray.t_max)
                    && self.occludes_any_isa(leaf.instance, ray)
            });
        }
        let Some(scene) = &self.scene else {
            return self.single.is_some_and(|i| self.occludes_any_isa(i, ray));
        };
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: `Simd::avx2` is true only where the CPU runs AVX2, FMA, BMI1/2, LZCNT
            // and POPCNT.
            return unsafe { self.occluded_scene_avx2(scene, ray) };
        }
        self.occluded_scene(scene, ray)
    }

    /// [`Self::occluded_scene`] compiled for x86-64-v3, as [`Self::intersect_scene_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn occluded_scene_avx2(&self, scene: &TriangleBvh<Leaf>, ray: &Ray) -> bool {
        // SAFETY: this function runs only where the CPU has AVX2.
        unsafe { self.occluded_scene_with::<true>(scene, ray) }
    }

    /// Whether anything in the scene BVH blocks `ray`.
    #[inline(always)]
    fn occluded_scene(&self, scene: &TriangleBvh<Leaf>, ray: &Ray) -> bool {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.occluded_scene_with::<false>(scene, ray) }
    }

    /// [`Self::occluded_scene`] with the node test of `WIDE` (`TriangleBvh::any_with`).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn occluded_scene_with<const WIDE: bool>(
        &self,
        scene: &TriangleBvh<Leaf>,
        ray: &Ray,
    ) -> bool {
        let (o, d) = (ray.origin, ray.direction);
        let wt = WatertightRay::new(o, d, ray.t_min);
        let test = |p: &[Vec3A; 3], leaf: Leaf, t_max: f32| {
            if leaf.is_instance() {
                self.occludes_any_isa(leaf.instance, ray)
            } else {
                wt.intersect(p[0], p[1], p[2], t_max).is_some()
            }
        };
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { scene.any_with::<WIDE>(o, d, ray.t_min, ray.t_max, test) }
    }

    #[inline]
    fn occludes(&self, instance_id: u32, ray: &Ray) -> bool {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.occludes_with::<false>(instance_id, ray) }
    }

    /// [`Self::occludes`] with the mesh BVHs' node test of `WIDE`.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn occludes_with<const WIDE: bool>(&self, instance_id: u32, ray: &Ray) -> bool {
        let inst = &self.instances[instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        match inst.shape {
            // SAFETY (both arms): the caller's contract for `WIDE`.
            Shape::Mesh(MeshId(m)) => unsafe {
                self.meshes[m as usize].occluded_with::<WIDE>(o, d, ray.t_min, ray.t_max)
            },
            Shape::Tiled(tiling) => unsafe {
                tiling.occluded_with::<WIDE>(
                    &self.meshes[tiling.mesh.0 as usize],
                    o,
                    d,
                    ray.t_min,
                    ray.t_max,
                )
            },
            _ => analytic_intersect(&inst.shape, &Ray::new(o, d, ray.t_min, ray.t_max)).is_some(),
        }
    }

    /// Full world-space record of `hit` (found for `ray`).
    pub fn interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        self.interaction_with(ray, hit, true)
    }

    /// The record of `hit` without the principal curvatures (left at zero): what shading
    /// needs, for less work per path vertex.
    pub fn shading_interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        self.interaction_with(ray, hit, false)
    }

    fn interaction_with(&self, ray: &Ray, hit: &Hit, with_curvature: bool) -> SurfaceInteraction {
        let inst = &self.instances[hit.instance_id as usize];
        let (o, d) = object_ray(inst, ray);
        let p_obj = o + hit.t * d;
        if let (false, Some(record), Shape::Rectangle(r)) = (
            with_curvature,
            &self.flat_records[hit.instance_id as usize],
            inst.shape,
        ) {
            // `from_local_with` of the rectangle's local geometry at `p_obj`: only the
            // position and uv vary over a rectangle.
            let local = r.local_geometry(p_obj);
            let mut si = **record;
            si.p = if inst.to_world.is_identity() {
                local.p
            } else {
                inst.to_world.point(local.p)
            };
            si.t = hit.t;
            si.uv = local.uv;
            si.primitive_id = 0;
            si.material_id = inst.material.unwrap_or(NO_MATERIAL);
            si.object_id = 0;
            si.instance_id = hit.instance_id;
            return si;
        }
        let (local, primitive_id, face_material, object_id) = match inst.shape {
            Shape::Mesh(MeshId(m)) => {
                let mesh = &self.meshes[m as usize].mesh;
                let tri = hit.primitive_id as usize;
                let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
                (
                    triangle_local_geometry(mesh, tri, b),
                    hit.primitive_id,
                    mesh.material_ids[tri],
                    mesh.object_ids[tri],
                )
            }
            Shape::Sphere(s) => (s.local_geometry(p_obj), 0, NO_MATERIAL, 0),
            Shape::Disk(dk) => (dk.local_geometry(p_obj), 0, NO_MATERIAL, 0),
            Shape::Rectangle(r) => (r.local_geometry(p_obj), 0, NO_MATERIAL, 0),
            Shape::Tiled(tiling) => {
                let mesh = &self.meshes[tiling.mesh.0 as usize].mesh;
                let (cell, tri) =
                    Tiling::cell_and_triangle(hit.primitive_id, mesh.triangle_count() as u32);
                let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
                let mut local = triangle_local_geometry(mesh, tri as usize, b);
                local.p += tiling.cell_offset(cell);
                (
                    local,
                    tri,
                    mesh.material_ids[tri as usize],
                    mesh.object_ids[tri as usize],
                )
            }
        };
        let mut si =
            SurfaceInteraction::from_local_with(&local, &inst.to_world, hit.t, with_curvature);
        si.primitive_id = primitive_id;
        // A tile's faces keep their own materials (the carrier's is the `tiled` one).
        si.material_id = match inst.shape {
            Shape::Tiled(_) => face_material,
            Shape::Mesh(_) | Shape::Sphere(_) | Shape::Disk(_) | Shape::Rectangle(_) => {
                inst.material.unwrap_or(face_material)
            }
        };
        si.object_id = object_id;
        si.instance_id = hit.instance_id;
        si
    }

    /// Closest hit of a ray differential with its interaction and propagated differentials.
    pub fn intersect_differential(&self, ray: &RayDifferential) -> Option<SurfaceInteraction> {
        let hit = self.intersect(&ray.ray)?;
        let mut si = self.interaction(&ray.ray, &hit);
        si.compute_differentials(ray);
        Some(si)
    }
}

/// Whether the ray `o + t·d` (`inv` its safe reciprocal direction, `bvh_ray`) enters the
/// padded box `lo..hi` within `(t_min, t_max)`.
#[inline]
fn slab_hit(lo: Vec3A, hi: Vec3A, o: Vec3A, inv: Vec3A, t_min: f32, t_max: f32) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element().max(t_min);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

#[inline]
fn object_ray(inst: &Instance, ray: &Ray) -> (Vec3A, Vec3A) {
    if inst.to_world.is_identity() {
        (ray.origin, ray.direction)
    } else {
        (
            inst.to_world.inverse_point(ray.origin),
            inst.to_world.inverse_vector(ray.direction),
        )
    }
}

fn analytic_intersect(shape: &Shape, local: &Ray) -> Option<f32> {
    match shape {
        Shape::Sphere(s) => s.intersect(local),
        Shape::Disk(d) => d.intersect(local),
        Shape::Rectangle(r) => r.intersect(local),
        Shape::Mesh(_) | Shape::Tiled(_) => None,
    }
}

//! A triangle mesh with its own object-space BVH (for the instance leaves of
//! [`crate::Geometry`] that place a mesh which was not flattened). Triangle
//! vertices are also stored in BVH leaf order (a private `TriangleBvh`); this costs 36 bytes
//! per triangle beyond the indexed mesh and is paid once per mesh, never per instance.

use glam::Vec3A;

use crate::bvh_build::BuildQuality;
use crate::mesh::TriangleMesh;
use crate::triangle::TriangleHit;
use crate::triangle_bvh::TriangleBvh;

/// Closest hit inside one mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    pub t: f32,
    /// Triangle index in the mesh (input order).
    pub triangle: u32,
    pub b0: f32,
    pub b1: f32,
    pub b2: f32,
}

impl MeshHit {
    /// From a hit of the mesh's BVH on `triangle`.
    #[inline(always)]
    fn new(h: TriangleHit, triangle: u32) -> Self {
        Self {
            t: h.t,
            triangle,
            b0: h.b0,
            b1: h.b1,
            b2: h.b2,
        }
    }

    /// The scene's record of this hit on instance `instance_id` of the mesh.
    #[inline(always)]
    pub(crate) fn in_instance(self, instance_id: u32) -> crate::geometry::Hit {
        crate::geometry::Hit {
            t: self.t,
            instance_id,
            primitive_id: self.triangle,
            b1: self.b1,
            b2: self.b2,
        }
    }
}

pub struct MeshBvh {
    pub mesh: TriangleMesh,
    /// Empty when the mesh has no triangles or when every instance of it was flattened into
    /// the scene's world-space soup (`MeshBvh::without_bvh`).
    bvh: TriangleBvh<u32>,
    bounds: (Vec3A, Vec3A),
}

impl MeshBvh {
    pub fn build(mesh: TriangleMesh, quality: BuildQuality) -> Self {
        let tris: Vec<[Vec3A; 3]> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i))
            .collect();
        let ids: Vec<u32> = (0..tris.len() as u32).collect();
        let bvh = TriangleBvh::build(&tris, &ids, quality);
        let bounds = mesh.bounds();
        Self { mesh, bvh, bounds }
    }

    /// The mesh with bounds but no BVH: its queries miss. For meshes whose every instance is
    /// baked into the world-space soup, where only `interaction` reads the mesh.
    pub(crate) fn without_bvh(mesh: TriangleMesh) -> Self {
        let bvh = TriangleBvh::build(&[], &[], BuildQuality::default());
        let bounds = mesh.bounds();
        Self { mesh, bvh, bounds }
    }

    /// Object-space bounds (min, max); inverted (∞, −∞) for an empty mesh.
    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        self.bounds
    }

    /// Closest hit with `t` in `(t_min, t_max)` of the object-space ray.
    #[inline]
    pub fn intersect(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<MeshHit> {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.intersect_with::<false>(origin, direction, t_min, t_max) }
    }

    /// [`Self::intersect`] with the BVH node test of `WIDE` (`TriangleBvh::intersect_with`).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(crate) unsafe fn intersect_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<MeshHit> {
        // SAFETY: the caller's contract for `WIDE`.
        let hit = unsafe {
            self.bvh
                .intersect_with::<WIDE>(origin, direction, t_min, t_max)
        };
        hit.map(|(h, triangle)| MeshHit::new(h, triangle))
    }

    /// Whether anything lies in `(t_min, t_max)` (stops at the first hit).
    #[inline]
    pub fn occluded(&self, origin: Vec3A, direction: Vec3A, t_min: f32, t_max: f32) -> bool {
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.occluded_with::<false>(origin, direction, t_min, t_max) }
    }

    /// [`Self::occluded`] with the BVH node test of `WIDE` (`TriangleBvh::occluded_with`).
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(crate) unsafe fn occluded_with<const WIDE: bool>(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> bool {
        // SAFETY: the caller's contract for `WIDE`.
        unsafe {
            self.bvh
                .occluded_with::<WIDE>(origin, direction, t_min, t_max)
        }
    }

    /// [`Self::intersect_with`] for `count` object-space rays, interleaved
    /// (`TriangleBvh::traverse_stream_with`): `ray(i)` gives ray `i` (origin, direction,
    /// `t_min`, `t_max`) and `hit(i, result)` receives its closest hit, the same bits as
    /// `intersect_with`'s, in any order of `i`.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(crate) unsafe fn intersect_stream_with<const WIDE: bool>(
        &self,
        count: usize,
        ray: impl FnMut(usize) -> (Vec3A, Vec3A, f32, f32),
        mut hit: impl FnMut(usize, Option<MeshHit>),
    ) {
        // SAFETY: the caller's contract for `WIDE`.
        unsafe {
            self.bvh.intersect_stream_with::<WIDE>(count, ray, |i, h| {
                hit(i, h.map(|(h, triangle)| MeshHit::new(h, triangle)))
            })
        }
    }
}

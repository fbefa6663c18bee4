//! Closest hits of many rays at once ([`Geometry::intersect_stream`]): the scene BVH or the
//! one mesh instance's BVH traversed as a ray stream (`TriangleBvh::traverse_stream_with`),
//! each ray's hit the same bits as [`Geometry::intersect`]'s.

use glam::Vec3A;

use super::{object_ray, Geometry, Hit, MeshId, SceneBest, Shape};
use crate::mesh_bvh::MeshHit;
use crate::ray::Ray;

impl Geometry {
    /// `hits[i] = self.intersect(&rays[i])` for every ray, the same bits. Scenes with a BVH
    /// (a scene BVH, or one mesh instance) trace the rays interleaved, a few in flight at
    /// once, so that one ray's cache misses overlap with the others' work
    /// (docs/geometry.md, "Ray streams"); small scenes and single analytic shapes, which
    /// miss no caches, trace them one by one.
    ///
    /// # Panics
    /// If `rays` and `hits` differ in length.
    pub fn intersect_stream(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        #[cfg(target_arch = "x86_64")]
        if self.simd.avx2() {
            // SAFETY: `Simd::avx2` is true only where the CPU runs AVX2, FMA, BMI1/2, LZCNT
            // and POPCNT.
            return unsafe { self.intersect_stream_avx2(rays, hits) };
        }
        // SAFETY: the 4-wide node test needs nothing beyond the target's baseline.
        unsafe { self.intersect_stream_with::<false>(rays, hits) }
    }

    /// [`Self::intersect_stream`] as x86-64-v3 code (see `intersect_scene_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    unsafe fn intersect_stream_avx2(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        // SAFETY: this function runs only where the CPU has AVX2.
        unsafe { self.intersect_stream_with::<true>(rays, hits) }
    }

    /// [`Self::intersect_stream`] with the node test of `WIDE`.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn intersect_stream_with<const WIDE: bool>(
        &self,
        rays: &[Ray],
        hits: &mut [Option<Hit>],
    ) {
        if let (None, Some(scene)) = (&self.small, &self.scene) {
            let start = |i: usize| {
                let r = &rays[i];
                (
                    r.origin,
                    r.direction,
                    r.t_min,
                    r.t_max,
                    (r, SceneBest::new(r)),
                )
            };
            let test = |(ray, best): &mut (&Ray, SceneBest), p: &[Vec3A; 3], leaf, t_max| {
                best.test(self, ray, p, leaf, t_max)
            };
            let finish = |i: usize, (ray, best): (&Ray, SceneBest)| hits[i] = best.hit(self, ray);
            // SAFETY: the caller's contract for `WIDE`.
            return unsafe {
                scene.traverse_stream_with::<WIDE, _>(rays.len(), start, test, finish)
            };
        }
        if let (None, None, Some(instance_id)) = (&self.small, &self.scene, self.single) {
            let inst = &self.instances[instance_id as usize];
            if let Shape::Mesh(MeshId(m)) = inst.shape {
                let ray = |i: usize| {
                    let (o, d) = object_ray(inst, &rays[i]);
                    (o, d, rays[i].t_min, rays[i].t_max)
                };
                let hit =
                    |i: usize, h: Option<MeshHit>| hits[i] = h.map(|h| h.in_instance(instance_id));
                // SAFETY: the caller's contract for `WIDE`.
                return unsafe {
                    self.meshes[m as usize].intersect_stream_with::<WIDE>(rays.len(), ray, hit)
                };
            }
        }
        for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
            *hit = self.intersect(ray);
        }
    }
}

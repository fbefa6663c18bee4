//! Closest hits of many rays at once ([`Geometry::intersect_stream`]): the scene BVH or the
//! one mesh instance's BVH traversed as a ray stream (`TriangleBvh::traverse_stream_with`),
//! each ray's hit the same bits as [`Geometry::intersect`]'s.

use super::{object_ray, Geometry, Hit, Leaf, MeshId, Shape};
use crate::ray::Ray;
use crate::triangle::{TriangleHit, WatertightRay};
use crate::triangle_bvh::STREAM_LANES;

/// A stream lane's closest hit so far in the scene BVH: an instance leaf's or a baked
/// triangle's (as `Geometry::intersect_scene_with` keeps them).
struct SceneBest {
    watertight: WatertightRay,
    index: usize,
    instance: Option<Hit>,
    triangle: Option<(TriangleHit, Leaf)>,
}

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
                let best = SceneBest {
                    watertight: WatertightRay::new(r.origin, r.direction, r.t_min),
                    index: i,
                    instance: None,
                    triangle: None,
                };
                (r.origin, r.direction, r.t_min, r.t_max, best)
            };
            let test = |best: &mut SceneBest, p: &[glam::Vec3A; 3], leaf: Leaf, t_max: f32| {
                if leaf.is_instance() {
                    let ray = &rays[best.index];
                    match self.intersect_instance_any_isa(leaf.instance, ray, t_max) {
                        Some(h) => {
                            best.instance = Some(h);
                            best.triangle = None;
                            h.t
                        }
                        None => f32::INFINITY,
                    }
                } else {
                    match best.watertight.intersect(p[0], p[1], p[2], t_max) {
                        Some(h) => {
                            best.triangle = Some((h, leaf));
                            best.instance = None;
                            h.t
                        }
                        None => f32::INFINITY,
                    }
                }
            };
            let finish = |i: usize, best: SceneBest| {
                hits[i] = best.instance.or_else(|| {
                    best.triangle
                        .map(|(h, leaf)| self.baked_hit(&rays[i], h.t, h.b1, h.b2, leaf))
                });
            };
            // SAFETY: the caller's contract for `WIDE`.
            return unsafe {
                scene.traverse_stream_with::<WIDE, STREAM_LANES, _>(rays.len(), start, test, finish)
            };
        }
        if let (None, None, Some(instance_id)) = (&self.small, &self.scene, self.single) {
            let inst = &self.instances[instance_id as usize];
            if let Shape::Mesh(MeshId(m)) = inst.shape {
                let ray = |i: usize| {
                    let (o, d) = object_ray(inst, &rays[i]);
                    (o, d, rays[i].t_min, rays[i].t_max)
                };
                let hit = |i: usize, h: Option<crate::mesh_bvh::MeshHit>| {
                    hits[i] = h.map(|h| Hit {
                        t: h.t,
                        instance_id,
                        primitive_id: h.triangle,
                        b1: h.b1,
                        b2: h.b2,
                    });
                };
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

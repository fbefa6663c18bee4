//! Closest-hit traversal of many rays interleaved (a ray stream): `STREAM_LANES` rays are in
//! flight at once and each takes one step of obvhs' `traverse!` loop in turn (the primitives
//! the last node test selected, then the next child node), so the cache misses of one ray's
//! node and leaf loads — requested ahead by the node test's prefetches — overlap with the other
//! rays' work instead of stalling the core (Kocberber et al. 2015, "Asynchronous memory
//! access chaining"). Each ray finds the closest hit, as the one-ray traversal does, though in
//! the octant order of obvhs' `traverse!` where the one-ray traversal goes nearest first
//! (triangle_bvh_nearest.rs): the hit is the same bits except where the ray meets the edge two
//! triangles share (both hit, at the same `t` or one ulp apart), where either may be kept. A lane whose ray ends takes the next
//! ray.

use glam::{UVec2, Vec3A};
use obvhs::cwbvh::{firstbithigh, CwBvh};
use obvhs::faststack::FastStack;

use super::{node_hits_on, Traversal, TriangleBest, TriangleBvh};
use crate::bvh_build::bvh_ray;
use crate::leaf_record::SlotId;
use crate::triangle::TriangleHit;

/// Rays in flight per stream: chosen on bench-bvh's 10⁶-triangle workload (docs/geometry.md,
/// "Ray streams").
const STREAM_LANES: usize = 8;

/// One ray of a stream in flight: its traversal state, its bounded ray, its index in the
/// stream and the caller's state for it (the best hit so far).
struct Lane<L> {
    state: Traversal,
    ray: obvhs::ray::Ray,
    index: usize,
    user: Option<L>,
}

impl<Id: SlotId> TriangleBvh<Id> {
    /// Closest-hit traversal of `count` rays, `STREAM_LANES` interleaved: `start(i)` gives
    /// ray `i` (origin, direction, `t_min`, `t_max`) and the caller's state for it,
    /// `test(state, primitive, id, t_max)` is [`TriangleBvh::traverse_with`]'s leaf test for
    /// that ray, and `finish(i, state)` receives the state once ray `i` has ended (in any
    /// order of `i`). The node test is `WIDE`'s.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn traverse_stream_with<const WIDE: bool, L>(
        &self,
        count: usize,
        mut start: impl FnMut(usize) -> (Vec3A, Vec3A, f32, f32, L),
        mut test: impl FnMut(&mut L, &[Vec3A; 3], Id, f32) -> f32,
        mut finish: impl FnMut(usize, L),
    ) {
        let Some(bvh) = self.bvh.as_ref() else {
            for i in 0..count {
                finish(i, start(i).4);
            }
            return;
        };
        let mut next = 0;
        let mut load = |lane: &mut Lane<L>, next: &mut usize| {
            if *next >= count {
                lane.user = None;
                return;
            }
            let (origin, direction, t_min, t_max, user) = start(*next);
            lane.state.reset(bvh, direction);
            lane.ray = bvh_ray(origin, direction, t_min, t_max);
            lane.index = *next;
            lane.user = Some(user);
            *next += 1;
        };
        let mut lanes: [Lane<L>; STREAM_LANES] = std::array::from_fn(|_| Lane {
            state: Traversal::new(bvh, Vec3A::X),
            ray: bvh_ray(Vec3A::ZERO, Vec3A::X, 0.0, 0.0),
            index: 0,
            user: None,
        });
        for lane in &mut lanes {
            load(lane, &mut next);
        }
        loop {
            let mut in_flight = false;
            for lane in &mut lanes {
                let Lane {
                    state, ray, user, ..
                } = lane;
                let Some(user) = user.as_mut() else {
                    continue;
                };
                in_flight = true;
                // SAFETY: the caller's contract for `WIDE`.
                let more = unsafe { self.step::<WIDE, L>(bvh, state, ray, user, &mut test) };
                if !more {
                    if let Some(user) = lane.user.take() {
                        finish(lane.index, user);
                    }
                    load(lane, &mut next);
                }
            }
            if !in_flight {
                break;
            }
        }
    }

    /// [`TriangleBvh::intersect_with`] for `count` rays, `STREAM_LANES` interleaved: `ray(i)`
    /// gives ray `i` (origin, direction, `t_min`, `t_max`) and `hit(i, result)` receives its
    /// closest hit, the same bits but at edges two triangles share (module comment), in any order
    /// of `i`.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub unsafe fn intersect_stream_with<const WIDE: bool>(
        &self,
        count: usize,
        mut ray: impl FnMut(usize) -> (Vec3A, Vec3A, f32, f32),
        mut hit: impl FnMut(usize, Option<(TriangleHit, Id)>),
    ) {
        let start = |i: usize| {
            let (o, d, t_min, t_max) = ray(i);
            (o, d, t_min, t_max, TriangleBest::new(o, d, t_min))
        };
        let test = |best: &mut TriangleBest<Id>, p: &[Vec3A; 3], id, t_max| best.test(p, id, t_max);
        let finish = |i: usize, best: TriangleBest<Id>| hit(i, best.hit);
        // SAFETY: the caller's contract for `WIDE`.
        unsafe { self.traverse_stream_with::<WIDE, _>(count, start, test, finish) }
    }

    /// One pass of `traverse!`'s loop for one lane (`TriangleBvh::traverse_with` is the
    /// whole loop): the primitive group's tests, then one child node's test and the
    /// prefetches it selects, then a pop when the groups are empty. `false` once the
    /// traversal has ended.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn step<const WIDE: bool, L>(
        &self,
        bvh: &CwBvh,
        state: &mut Traversal,
        ray: &mut obvhs::ray::Ray,
        user: &mut L,
        test: &mut impl FnMut(&mut L, &[Vec3A; 3], Id, f32) -> f32,
    ) -> bool {
        while state.primitive_group.y != 0 {
            let local = firstbithigh(state.primitive_group.y);
            state.primitive_group.y &= !(1u32 << local);
            let slot = (state.primitive_group.x + local) as usize;
            let leaf = &self.leaves[slot];
            let t = test(user, &leaf.vectors(), leaf.id(), ray.tmax);
            if t < ray.tmax {
                ray.tmax = t;
            }
        }
        state.primitive_group = UVec2::ZERO;
        if state.current_group.y & 0xff00_0000 != 0 {
            let hits_imask = state.current_group.y;
            let child_index_offset = firstbithigh(hits_imask);
            let child_index_base = state.current_group.x;
            state.current_group.y &= !(1u32 << child_index_offset);
            if state.current_group.y & 0xff00_0000 != 0 {
                state.stack.push(state.current_group);
            }
            let slot_index = (child_index_offset - 24) ^ (state.oct_inv4 & 0xff);
            let relative_index = (hits_imask & !(0xffff_ffffu32 << slot_index)).count_ones();
            let node = &bvh.nodes[(child_index_base + relative_index) as usize];
            // SAFETY: the caller's contract for `WIDE`.
            let hits = unsafe { node_hits_on::<WIDE>(node, ray, state.oct_inv4) };
            self.prefetch_hits(bvh, node, hits, state.oct_inv4);
            state.hitmask = hits;
            state.current_group.x = node.child_base_idx;
            state.primitive_group.x = node.primitive_base_idx;
            state.current_group.y = (hits & 0xff00_0000) | u32::from(node.imask);
            state.primitive_group.y = hits & 0x00ff_ffff;
        } else {
            state.current_group = UVec2::ZERO;
        }
        if state.primitive_group.y == 0 && (state.current_group.y & 0xff00_0000) == 0 {
            if state.stack.is_empty() {
                return false;
            }
            state.current_group = state.stack.pop_fast();
        }
        true
    }
}

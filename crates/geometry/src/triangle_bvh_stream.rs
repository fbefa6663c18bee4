//! Closest-hit traversal of many rays interleaved (a ray stream): `STREAM_LANES` rays are in
//! flight at once and each takes one step of the one-ray traversal in turn (the expansion of
//! the node it tested last, then the test of the next: triangle_bvh_nearest.rs), so the cache
//! misses of one ray's node and leaf loads — requested ahead by the node test's prefetches —
//! overlap with the other rays' work instead of stalling the core (Kocberber et al. 2015,
//! "Asynchronous memory access chaining"). Each ray visits the same nodes and primitives in the
//! same order as the one-ray traversal, so its hit is the same bits; a lane whose ray ends
//! takes the next ray.

use std::ops::ControlFlow;

use glam::Vec3A;
use obvhs::cwbvh::CwBvh;

use super::nearest::{Entered, Next, PendingStack};
use super::{TriangleBest, TriangleBvh};
use crate::bvh_build::bvh_ray;
use crate::leaf_record::SlotId;
use crate::triangle::TriangleHit;

/// Rays in flight per stream: chosen on bench-bvh's 10⁶-triangle workload (docs/geometry.md,
/// "Ray streams").
const STREAM_LANES: usize = 8;

/// One ray of a stream in flight: its stack, the node it tested last (`None` before the
/// root's test), its bounded ray, its index in the stream and the caller's state for it (the
/// best hit so far).
struct Lane<L> {
    stack: PendingStack,
    entered: Option<Entered>,
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
            lane.stack.clear();
            lane.entered = None;
            lane.ray = bvh_ray(origin, direction, t_min, t_max);
            lane.index = *next;
            lane.user = Some(user);
            *next += 1;
        };
        let mut lanes: [Lane<L>; STREAM_LANES] = std::array::from_fn(|_| Lane {
            stack: PendingStack::new(),
            entered: None,
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
                    stack,
                    entered,
                    ray,
                    user,
                    ..
                } = lane;
                let Some(user) = user.as_mut() else {
                    continue;
                };
                in_flight = true;
                // SAFETY: the caller's contract for `WIDE`.
                let more =
                    unsafe { self.step::<WIDE, L>(bvh, stack, entered, ray, user, &mut test) };
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
    /// closest hit, the same bits, in any order of `i`.
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

    /// One step of the one-ray traversal for one lane: the expansion of the node the lane
    /// tested last (its leaves' tests, then the choice of the next node), then that node's
    /// test and the prefetches it selects. `false` once the traversal has ended.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    unsafe fn step<const WIDE: bool, L>(
        &self,
        bvh: &CwBvh,
        stack: &mut PendingStack,
        entered: &mut Option<Entered>,
        ray: &mut obvhs::ray::Ray,
        user: &mut L,
        test: &mut impl FnMut(&mut L, &[Vec3A; 3], Id, f32) -> f32,
    ) -> bool {
        let next = match entered.take() {
            None => Next::Node(0),
            Some(tested) => {
                let mut test = |p: &[Vec3A; 3], id: Id, t_max: f32| {
                    ControlFlow::Continue(test(user, p, id, t_max))
                };
                self.expand(bvh, &tested, ray, stack, &mut test)
            }
        };
        match next {
            Next::Node(node) => {
                // SAFETY: the caller's contract for `WIDE`.
                *entered = Some(unsafe { self.enter::<WIDE>(bvh, node, ray) });
                true
            }
            Next::Done | Next::Stopped => false,
        }
    }
}

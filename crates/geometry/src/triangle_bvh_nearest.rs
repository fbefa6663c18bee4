//! Traversal of one ray in the order of the children's entry distances, with children culled
//! on the stack once a hit lies nearer than their entry (Embree's single-ray BVH8 traversal,
//! Wald et al. 2014, over obvhs' CWBVH nodes): the closest-hit and any-hit queries of one
//! ray, and the steps a ray stream interleaves (triangle_bvh_stream.rs). obvhs' own
//! `traverse!` visits children in the ray octant's order and keeps a node's entered children
//! as one bit mask: after a hit it still loads and tests every child it had entered, and a
//! near child can wait behind a far one.

use std::mem::MaybeUninit;
use std::ops::ControlFlow;

use glam::Vec3A;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;

use super::{node_entries_on, prefetch_object, TriangleBvh};
use crate::bvh_build::bvh_ray;
use crate::leaf_record::SlotId;

/// A child node still to visit and the ray's entry distance into its box.
#[derive(Clone, Copy)]
struct Pending {
    node: u32,
    t_entry: f32,
}

/// The primitive slots of leaf child `slot` of `node` (its meta byte: the offset from the
/// node's first primitive in the low five bits, the count in unary in the high three).
#[inline(always)]
fn leaf_slots(node: &CwBvhNode, slot: usize) -> std::ops::Range<usize> {
    let meta = u32::from(node.child_meta[slot]);
    let first = node.primitive_base_idx + (meta & 0b1_1111);
    first as usize..(first + (meta >> 5).count_ones()) as usize
}

/// The node index of internal child `slot` of `node`: the internal children are stored in
/// slot order from `child_base_idx`.
#[inline(always)]
fn child_node(node: &CwBvhNode, slot: u32) -> u32 {
    let before = u32::from(node.imask) & ((1u32 << slot) - 1);
    node.child_base_idx + before.count_ones()
}

/// Insert `item` at its entry distance `t` into the first `len` entries of `order`, sorted
/// nearest first; equal distances keep their insertion order (slot order), so every ISA
/// visits them alike.
#[inline(always)]
fn insert_nearest_first<T: Copy>(order: &mut [(T, f32); 8], len: usize, item: T, t: f32) {
    let mut at = len;
    while at > 0 && order[at - 1].1 > t {
        order[at] = order[at - 1];
        at -= 1;
    }
    order[at] = (item, t);
}

/// Entries kept without allocation; a deeper stack (a tree far from balanced: up to seven
/// entries per level) spills to the heap rather than losing a child.
const INLINE_ENTRIES: usize = 128;

/// A last-in first-out stack of [`Pending`] children without initialisation cost.
pub(super) struct PendingStack {
    inline: [MaybeUninit<Pending>; INLINE_ENTRIES],
    len: usize,
    spilled: Vec<Pending>,
}

impl PendingStack {
    #[inline(always)]
    pub(super) fn new() -> Self {
        Self {
            inline: [MaybeUninit::uninit(); INLINE_ENTRIES],
            len: 0,
            spilled: Vec::new(),
        }
    }

    /// Empty, its storage kept (a stream's lane takes its next ray with it).
    #[inline(always)]
    pub(super) fn clear(&mut self) {
        self.len = 0;
        self.spilled.clear();
    }

    #[inline(always)]
    fn push(&mut self, entry: Pending) {
        if self.len < INLINE_ENTRIES {
            self.inline[self.len] = MaybeUninit::new(entry);
            self.len += 1;
        } else {
            self.spilled.push(entry);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Pending> {
        if let Some(entry) = self.spilled.pop() {
            return Some(entry);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: slots below `len` were written by `push`.
        Some(unsafe { self.inline[self.len].assume_init() })
    }
}

/// A node's test, kept for its expansion: the node, its entered leaf and internal children
/// (bit i for slot i) and each slot's entry distance.
#[derive(Clone, Copy)]
pub(super) struct Entered {
    node: u32,
    leaves: u32,
    internal: u32,
    t_entry: [f32; 8],
}

/// Where a traversal goes after a node's expansion.
pub(super) enum Next {
    /// Test this node.
    Node(u32),
    /// Nothing is left within reach.
    Done,
    /// The leaf test broke off the traversal.
    Stopped,
}

impl<Id: SlotId> TriangleBvh<Id> {
    /// The traversal of [`TriangleBvh::traverse_with`] and [`TriangleBvh::any_with`]: each
    /// node is tested ([`Self::enter`]) and expanded ([`Self::expand`]) in turn, from the
    /// root. Whether `test` broke off.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(super) unsafe fn traverse_nearest_first<const WIDE: bool>(
        &self,
        bvh: &CwBvh,
        origin: Vec3A,
        direction: Vec3A,
        t_min: f32,
        t_max: f32,
        mut test: impl FnMut(&[Vec3A; 3], Id, f32) -> ControlFlow<(), f32>,
    ) -> bool {
        if bvh.nodes.is_empty() {
            return false;
        }
        let mut ray = bvh_ray(origin, direction, t_min, t_max);
        let mut stack = PendingStack::new();
        let mut node = 0u32;
        loop {
            // SAFETY: the caller's contract for `WIDE`.
            let entered = unsafe { self.enter::<WIDE>(bvh, node, &ray) };
            match self.expand(bvh, &entered, &mut ray, &mut stack, &mut test) {
                Next::Node(child) => node = child,
                Next::Done => return false,
                Next::Stopped => return true,
            }
        }
    }

    /// Node `node`'s test against `ray`, with the prefetches of what it selects: the
    /// entered children's primitives and nodes.
    ///
    /// # Safety
    /// With `WIDE`, the CPU must run AVX2.
    #[inline(always)]
    pub(super) unsafe fn enter<const WIDE: bool>(
        &self,
        bvh: &CwBvh,
        node: u32,
        ray: &obvhs::ray::Ray,
    ) -> Entered {
        let tested = &bvh.nodes[node as usize];
        // SAFETY: the caller's contract for `WIDE`.
        let (entered, t_entry) = unsafe { node_entries_on::<WIDE>(tested, ray) };
        let internal_mask = u32::from(tested.imask);
        let entered = Entered {
            node,
            leaves: entered & !internal_mask,
            internal: entered & internal_mask,
            t_entry,
        };
        self.prefetch_entered(bvh, tested, entered.leaves, entered.internal);
        entered
    }

    /// A tested node's expansion: its entered leaf children's primitives are tested first,
    /// nearest first (`test(primitive, id, t_max)` continues with the primitive's `t`, which
    /// lowers `ray.tmax` where it is nearer, or breaks off the traversal), each leaf skipped
    /// once a hit lies nearer than its box; then its entered internal children whose entry
    /// lies within `ray.tmax` go on the stack nearest on top, and the nearest is next. With
    /// none, the stack is popped, skipping the children whose entry a hit now lies before.
    #[inline(always)]
    pub(super) fn expand(
        &self,
        bvh: &CwBvh,
        entered: &Entered,
        ray: &mut obvhs::ray::Ray,
        stack: &mut PendingStack,
        test: &mut impl FnMut(&[Vec3A; 3], Id, f32) -> ControlFlow<(), f32>,
    ) -> Next {
        let node = &bvh.nodes[entered.node as usize];
        let t_entry = &entered.t_entry;
        let mut leaves = entered.leaves;
        let mut leaf_order = [(0usize, 0.0f32); 8];
        let mut leaf_count = 0;
        while leaves != 0 {
            let slot = leaves.trailing_zeros() as usize;
            leaves &= leaves - 1;
            insert_nearest_first(&mut leaf_order, leaf_count, slot, t_entry[slot]);
            leaf_count += 1;
        }
        for &(slot, t) in &leaf_order[..leaf_count] {
            if t > ray.tmax {
                break;
            }
            for primitive in leaf_slots(node, slot) {
                let leaf = &self.leaves[primitive];
                let ControlFlow::Continue(t) = test(&leaf.vectors(), leaf.id(), ray.tmax) else {
                    return Next::Stopped;
                };
                if t < ray.tmax {
                    ray.tmax = t;
                }
            }
        }
        // The internal children within reach, nearest first.
        let mut internal = entered.internal;
        let mut order = [(0u32, 0.0f32); 8];
        let mut count = 0;
        while internal != 0 {
            let slot = internal.trailing_zeros();
            internal &= internal - 1;
            let t = t_entry[slot as usize];
            if t <= ray.tmax {
                insert_nearest_first(&mut order, count, child_node(node, slot), t);
                count += 1;
            }
        }
        if count > 0 {
            for &(node, t_entry) in order[1..count].iter().rev() {
                stack.push(Pending { node, t_entry });
            }
            return Next::Node(order[0].0);
        }
        while let Some(pending) = stack.pop() {
            if pending.t_entry <= ray.tmax {
                return Next::Node(pending.node);
            }
        }
        Next::Done
    }

    /// Start loading the primitives (vertex and id records) of the entered leaf children and
    /// the entered child nodes, so that their cache misses overlap.
    #[inline(always)]
    fn prefetch_entered(&self, bvh: &CwBvh, node: &CwBvhNode, leaves: u32, internal: u32) {
        let mut leaves = leaves;
        while leaves != 0 {
            let slot = leaves.trailing_zeros() as usize;
            leaves &= leaves - 1;
            for primitive in leaf_slots(node, slot) {
                prefetch_object(self.leaves.as_ptr().wrapping_add(primitive));
            }
        }
        let mut internal = internal;
        while internal != 0 {
            let slot = internal.trailing_zeros();
            internal &= internal - 1;
            prefetch_object(
                bvh.nodes
                    .as_ptr()
                    .wrapping_add(child_node(node, slot) as usize),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Beyond its inline entries the stack spills to the heap and still pops last in,
    /// first out, every entry once.
    #[test]
    fn the_pending_stack_spills_and_keeps_its_order() {
        let mut stack = PendingStack::new();
        let count = 3 * INLINE_ENTRIES as u32 + 5;
        for node in 0..count {
            stack.push(Pending {
                node,
                t_entry: node as f32,
            });
        }
        assert!(!stack.spilled.is_empty());
        for node in (0..count).rev() {
            let entry = stack.pop().expect("an entry per push");
            assert_eq!((entry.node, entry.t_entry), (node, node as f32));
        }
        assert!(stack.pop().is_none());
    }
}

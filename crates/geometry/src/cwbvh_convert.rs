//! BVH2 → compressed 8-wide BVH on every core (Ylitie, Karras & Laine 2017, "Efficient
//! incoherent ray traversal on GPUs through compressed wide BVHs", §3.1: the SAH dynamic
//! programme over "distribute" decisions, then §3.2's quantised child boxes in ray-octant
//! order). It takes the same decisions and writes the same nodes in the same order as obvhs'
//! serial `bvh2_to_cwbvh` (`converts_exactly_as_obvhs` compares them node for node); on a
//! 10⁶-triangle mesh that serial conversion took ≈ 0.3 s, twice the parallel PLOC build.
//!
//! Three passes over the binary tree, each splitting the top levels' subtrees across
//! threads: the decision table (bottom-up), the size of each wide subtree (so every subtree
//! knows where its nodes and primitives go), then the nodes themselves into disjoint
//! slices. Below those levels each pass walks with a work list, not recursion: coincident
//! boxes make PLOC's tree a chain as deep as it has primitives, which overflowed the stack
//! of obvhs' recursive conversion (a mesh of 2·10⁵ duplicate triangles aborted `prism
//! render`).

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering::Relaxed};

use glam::{UVec3, Vec3A};
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;
use rayon::prelude::*;

/// SAH cost of a primitive relative to a node's (obvhs' and the paper's 0.3).
const PRIM_COST: f32 = 0.3;
/// 1 / (2⁸ − 1): child boxes are quantised to 8 bits per axis (Ylitie et al. §3.2).
const QUANTISATION_DENOM: f32 = 1.0 / 255.0;
/// Decisions per BVH2 node: for covering 1 to 7 of its wide parent's 8 child slots (its
/// sibling takes at least one).
const SLOTS: usize = 7;
/// Subtrees with fewer primitives are converted on the calling thread: below this, splitting
/// costs more than it spreads.
const PARALLEL_MIN_PRIMITIVES: u32 = 8192;
/// The decision pass splits the top levels of the binary tree: at most 2¹² tasks.
const PARALLEL_COST_DEPTH: u32 = 12;
/// The counting and writing passes split the top levels of the wide tree: at most 8⁵ tasks.
const PARALLEL_WIDE_DEPTH: u32 = 5;

/// No split found yet (a slot count − 1 is at most 6).
const UNSET: u8 = u8::MAX;

/// What becomes of a BVH2 node when it is to cover `i + 1` slots of its wide parent.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum DecisionKind {
    /// A wide leaf holding every primitive below.
    Leaf,
    /// A wide internal node.
    Internal,
    /// Its two children share the slots.
    Distribute,
}

/// A decision: its SAH cost and what it does.
#[derive(Clone, Copy, Debug)]
struct Decision {
    cost: f32,
    choice: Choice,
}

/// A decision's kind and slot split, stored apart from its cost in one byte.
#[derive(Clone, Copy, Debug)]
struct Choice {
    kind: DecisionKind,
    /// Slots given to the left and right child (as slot counts − 1) when distributing.
    distribute_left: u8,
    distribute_right: u8,
}

impl Choice {
    /// A wide leaf's (a BVH2 leaf's, whatever the slots).
    const LEAF: Choice = Choice {
        kind: DecisionKind::Leaf,
        distribute_left: 0,
        distribute_right: 0,
    };

    /// Kind and split in one byte (2 + 3 + 3 bits; a split gives at most 6 slots).
    fn to_byte(self) -> u8 {
        let kind = match self.kind {
            DecisionKind::Leaf => 0,
            DecisionKind::Internal => 1,
            DecisionKind::Distribute => 2,
        };
        debug_assert!(self.distribute_left < 8 && self.distribute_right < 8);
        kind | (self.distribute_left & 7) << 2 | (self.distribute_right & 7) << 5
    }

    fn from_byte(byte: u8) -> Self {
        let kind = match byte & 3 {
            0 => DecisionKind::Leaf,
            1 => DecisionKind::Internal,
            2 => DecisionKind::Distribute,
            other => unreachable!("decision kind {other} was never packed"),
        };
        Choice {
            kind,
            distribute_left: (byte >> 2) & 7,
            distribute_right: byte >> 5,
        }
    }
}

/// The converter's tables, indexed by BVH2 node. Each pass writes only the entries of the
/// subtree it owns; atomics (relaxed: `rayon::join` orders a subtree's writes before its
/// parent's reads) let disjoint subtrees write through a shared reference.
struct Converter<'a> {
    bvh2: &'a Bvh2,
    max_prims_per_leaf: u32,
    /// `SLOTS` decision costs per node (f32 bits).
    costs: Vec<AtomicU32>,
    /// The `SLOTS` decisions' kinds and splits per node, a byte each
    /// ([`Choice::to_byte`]): 36 bytes per node with the costs, where obvhs' table
    /// takes 56.
    choices: Vec<AtomicU64>,
    /// Primitives below each node.
    primitives: Vec<AtomicU32>,
    /// Wide nodes below each node that becomes a wide internal node (itself not counted).
    wide_nodes_below: Vec<AtomicU32>,
    direction_lut: [Vec3A; 8],
}

/// Convert `bvh2` (one primitive per leaf, as PLOC builds it) with at most
/// `max_prims_per_leaf` (1–3) primitives per wide leaf, children ordered by ray octant.
pub fn bvh2_to_cwbvh_parallel(bvh2: &Bvh2, max_prims_per_leaf: u32) -> CwBvh {
    if bvh2.nodes.is_empty() {
        return CwBvh::default();
    }
    let n = bvh2.nodes.len();
    let converter = Converter {
        bvh2,
        max_prims_per_leaf: max_prims_per_leaf.clamp(1, 3),
        costs: zeroed(n * SLOTS),
        choices: zeroed(n),
        primitives: zeroed(n),
        wide_nodes_below: zeroed(n),
        direction_lut: std::array::from_fn(|s| {
            let sign = |bit: usize| if s & bit != 0 { -1.0 } else { 1.0 };
            Vec3A::new(sign(0b100), sign(0b010), sign(0b001))
        }),
    };
    let total_primitives = converter.costs(0, 0);
    let below = converter.count_wide_nodes(0, 0);
    let mut nodes = vec![CwBvhNode::default(); 1 + below as usize];
    let mut primitive_indices = vec![0u32; total_primitives as usize];
    let (root, rest) = nodes.split_first_mut().expect("one root node");
    let region = Region {
        below_base: 1,
        below: rest,
        primitive_base: 0,
        primitives: &mut primitive_indices,
    };
    converter.emit(0, root, region, 0);
    CwBvh {
        nodes,
        primitive_indices,
        total_aabb: *bvh2.nodes[0].aabb(),
        exact_node_aabbs: None,
        uses_spatial_splits: bvh2.uses_spatial_splits,
    }
}

/// `len` zeroed atomics, written on every core.
fn zeroed<T: Default + Send>(len: usize) -> Vec<T> {
    (0..len).into_par_iter().map(|_| T::default()).collect()
}

impl Converter<'_> {
    fn cost(&self, node: usize, slot: usize) -> f32 {
        f32::from_bits(self.costs[node * SLOTS + slot].load(Relaxed))
    }

    fn choice(&self, node: usize, slot: usize) -> Choice {
        Choice::from_byte((self.choices[node].load(Relaxed) >> (8 * slot)) as u8)
    }

    fn store_decisions(&self, node: usize, decisions: &[Decision; SLOTS]) {
        let mut choices = 0u64;
        for (slot, d) in decisions.iter().enumerate() {
            self.costs[node * SLOTS + slot].store(d.cost.to_bits(), Relaxed);
            choices |= u64::from(d.choice.to_byte()) << (8 * slot);
        }
        self.choices[node].store(choices, Relaxed);
    }

    /// Fills the decision table below `node` (Ylitie et al. eqs. 1–3: cost of a wide leaf, a
    /// wide internal node, or distributing i slots between the two children); returns the
    /// primitives below it. Subtree sizes are not known yet: the top `PARALLEL_COST_DEPTH`
    /// levels split across threads, the rest is an iterative post-order walk (a BVH2 of
    /// coincident boxes is a chain as deep as it has primitives).
    fn costs(&self, node: usize, depth: u32) -> u32 {
        let bvh_node = &self.bvh2.nodes[node];
        if bvh_node.is_leaf() || depth >= PARALLEL_COST_DEPTH {
            return self.costs_serial(node);
        }
        let first = bvh_node.first_index as usize;
        rayon::join(
            || self.costs(first, depth + 1),
            || self.costs(first + 1, depth + 1),
        );
        self.node_decisions(node)
    }

    fn costs_serial(&self, root: usize) -> u32 {
        // (node, its children are done)
        let mut stack = vec![(root, false)];
        while let Some((node, children_done)) = stack.pop() {
            let bvh_node = &self.bvh2.nodes[node];
            if bvh_node.is_leaf() || children_done {
                self.node_decisions(node);
            } else {
                let first = bvh_node.first_index as usize;
                stack.extend([(node, true), (first + 1, false), (first, false)]);
            }
        }
        self.primitives[root].load(Relaxed)
    }

    /// The decisions of one node, its children's already made; returns its primitives.
    fn node_decisions(&self, node: usize) -> u32 {
        let bvh_node = &self.bvh2.nodes[node];
        let half_area = bvh_node.aabb().half_area();
        if bvh_node.prim_count != 0 {
            assert_eq!(
                bvh_node.prim_count, 1,
                "the wide conversion expects one primitive per BVH2 leaf"
            );
            let leaf = Decision {
                cost: half_area * PRIM_COST,
                choice: Choice::LEAF,
            };
            self.store_decisions(node, &[leaf; SLOTS]);
            self.primitives[node].store(1, Relaxed);
            return 1;
        }
        let (left, right) = (
            bvh_node.first_index as usize,
            bvh_node.first_index as usize + 1,
        );
        let primitives = self.primitives[left].load(Relaxed) + self.primitives[right].load(Relaxed);
        let left_cost = |k: usize| self.cost(left, k);
        let right_cost = |k: usize| self.cost(right, k);

        // One slot (the paper's i = 1): a wide leaf, or a wide internal node whose slots the
        // two children share.
        let cost_leaf = if primitives <= self.max_prims_per_leaf {
            primitives as f32 * half_area * PRIM_COST
        } else {
            f32::INFINITY
        };
        let mut cost_distribute = f32::INFINITY;
        let (mut distribute_left, mut distribute_right) = (UNSET, UNSET);
        for k in 0..SLOTS {
            let c = left_cost(k) + right_cost(SLOTS - 1 - k);
            if c < cost_distribute {
                cost_distribute = c;
                distribute_left = k as u8;
                distribute_right = (SLOTS - 1 - k) as u8;
            }
        }
        let cost_internal = cost_distribute + half_area;
        let (kind, cost) = if cost_leaf < cost_internal {
            (DecisionKind::Leaf, cost_leaf)
        } else {
            (DecisionKind::Internal, cost_internal)
        };
        let mut decisions = [Decision {
            cost,
            choice: Choice {
                kind,
                distribute_left,
                distribute_right,
            },
        }; SLOTS];
        // i + 1 slots (the paper's i = 2…8): the best of i slots, or a split between children.
        for i in 1..SLOTS {
            let previous = decisions[i - 1];
            let mut cost_distribute = previous.cost;
            let (mut distribute_left, mut distribute_right) = (UNSET, UNSET);
            for k in 0..i {
                let c = left_cost(k) + right_cost(i - k - 1);
                if c < cost_distribute {
                    cost_distribute = c;
                    distribute_left = k as u8;
                    distribute_right = (i - k - 1) as u8;
                }
            }
            let decision = if distribute_left != UNSET {
                Decision {
                    cost: cost_distribute,
                    choice: Choice {
                        kind: DecisionKind::Distribute,
                        distribute_left,
                        distribute_right,
                    },
                }
            } else {
                previous
            };
            decisions[i] = decision;
        }
        self.store_decisions(node, &decisions);
        self.primitives[node].store(primitives, Relaxed);
        primitives
    }

    /// The BVH2 nodes that become the wide children of `node` when it covers `slot + 1`
    /// slots, appended to `children`.
    fn children_of(&self, node: usize, slot: usize, children: &mut [u32; 8], count: &mut usize) {
        let bvh_node = &self.bvh2.nodes[node];
        if bvh_node.is_leaf() {
            children[*count] = node as u32;
            *count += 1;
            return;
        }
        let d = self.choice(node, slot);
        for (child, child_slot) in [
            (bvh_node.first_index as usize, d.distribute_left),
            (bvh_node.first_index as usize + 1, d.distribute_right),
        ] {
            if self.choice(child, child_slot as usize).kind == DecisionKind::Distribute {
                self.children_of(child, child_slot as usize, children, count);
            } else {
                children[*count] = child as u32;
                *count += 1;
            }
        }
    }

    /// The wide children of `node`, placed in the slots whose octant direction their centre
    /// lies furthest along (greedy assignment, as obvhs and Ylitie et al. §3.2 suggest);
    /// `u32::MAX` marks an empty slot.
    fn ordered_children(&self, node: usize) -> [u32; 8] {
        let mut children = [u32::MAX; 8];
        let mut count = 0;
        self.children_of(node, 0, &mut children, &mut count);
        let centre = self.bvh2.nodes[node].aabb().center();
        let mut cost = [[f32::MAX; 8]; 8];
        for (s, direction) in self.direction_lut.iter().enumerate() {
            for c in 0..count {
                let offset = self.bvh2.nodes[children[c] as usize].aabb().center() - centre;
                cost[c][s] = direction.dot(offset);
            }
        }
        let mut assignment = [usize::MAX; 8];
        let mut slot_filled = [false; 8];
        loop {
            let mut best = (f32::MAX, usize::MAX, usize::MAX);
            for c in 0..count {
                if assignment[c] != usize::MAX {
                    continue;
                }
                for (s, &filled) in slot_filled.iter().enumerate() {
                    if !filled && cost[c][s] < best.0 {
                        best = (cost[c][s], s, c);
                    }
                }
            }
            let (_, slot, child) = best;
            if slot == usize::MAX {
                break;
            }
            slot_filled[slot] = true;
            assignment[child] = slot;
        }
        let mut ordered = [u32::MAX; 8];
        for c in 0..count {
            ordered[assignment[c]] = children[c];
        }
        ordered
    }

    fn is_wide_internal(&self, node: u32) -> bool {
        self.choice(node as usize, 0).kind == DecisionKind::Internal
    }

    /// The wide internal nodes among `node`'s wide children (BVH2 indices), in any order.
    fn internal_children(&self, node: usize) -> UpToEight<u32> {
        let mut children = [u32::MAX; 8];
        let mut count = 0;
        self.children_of(node, 0, &mut children, &mut count);
        let mut internal = UpToEight::default();
        for &c in &children[..count] {
            if self.is_wide_internal(c) {
                internal.push(c);
            }
        }
        internal
    }

    /// Whether a wide subtree is split across threads: large, and near enough the root that
    /// the splitting stays shallow whatever the tree's depth.
    fn splits(&self, node: usize, wide_depth: u32) -> bool {
        wide_depth < PARALLEL_WIDE_DEPTH
            && self.primitives[node].load(Relaxed) >= PARALLEL_MIN_PRIMITIVES
    }

    /// Wide nodes below `node` (a wide internal node, or the root), recorded per node.
    fn count_wide_nodes(&self, node: usize, wide_depth: u32) -> u32 {
        if !self.splits(node, wide_depth) {
            return self.count_wide_nodes_serial(node);
        }
        let internal = self.internal_children(node);
        let below_children: u32 = internal
            .as_slice()
            .par_iter()
            .map(|&c| self.count_wide_nodes(c as usize, wide_depth + 1))
            .sum();
        let below = internal.as_slice().len() as u32 + below_children;
        self.wide_nodes_below[node].store(below, Relaxed);
        below
    }

    fn count_wide_nodes_serial(&self, root: usize) -> u32 {
        // (node, its internal children once they are counted)
        let mut stack: Vec<(usize, Option<UpToEight<u32>>)> = vec![(root, None)];
        while let Some((node, counted)) = stack.pop() {
            match counted {
                None => {
                    let internal = self.internal_children(node);
                    stack.push((node, Some(internal)));
                    stack.extend(internal.as_slice().iter().map(|&c| (c as usize, None)));
                }
                Some(internal) => {
                    let below = internal.as_slice().len() as u32
                        + internal
                            .as_slice()
                            .iter()
                            .map(|&c| self.wide_nodes_below[c as usize].load(Relaxed))
                            .sum::<u32>();
                    self.wide_nodes_below[node].store(below, Relaxed);
                }
            }
        }
        self.wide_nodes_below[root].load(Relaxed)
    }

    /// Appends the BVH2 primitives below `node` (a wide leaf: at most 3) in depth-first
    /// order, left child first.
    fn leaf_primitives(&self, node: usize, out: &mut [u32], at: &mut usize) {
        let bvh_node = &self.bvh2.nodes[node];
        if bvh_node.is_leaf() {
            out[*at] = self.bvh2.primitive_indices[bvh_node.first_index as usize];
            *at += 1;
            return;
        }
        self.leaf_primitives(bvh_node.first_index as usize, out, at);
        self.leaf_primitives(bvh_node.first_index as usize + 1, out, at);
    }

    /// The wide node of BVH2 node `node`, whose children's nodes start at global index
    /// `below_base` and whose leaves' primitives start at `primitive_base`; writes those
    /// primitives to the front of `primitives` and returns, per internal child in slot
    /// order, its BVH2 index, its node's global index, where its own children and primitives
    /// start, and how many it has below. This is the serial conversion's depth-first layout:
    /// a node's children's block, then each internal child's subtree in turn.
    fn wide_node(
        &self,
        node: usize,
        below_base: u32,
        primitive_base: u32,
        primitives: &mut [u32],
    ) -> (CwBvhNode, UpToEight<ChildPlacement>) {
        let aabb = self.bvh2.nodes[node].aabb();
        let origin = aabb.min;
        // Per-axis power-of-two scale so that 255 steps cover the box (Ylitie et al. §3.2).
        let scale = ((aabb.max - aabb.min).max(Vec3A::splat(1e-20)) * QUANTISATION_DENOM)
            .log2()
            .ceil()
            .exp2();
        let inv_scale = 1.0 / scale;
        let exponent = UVec3::new(
            scale.x.to_bits() >> 23,
            scale.y.to_bits() >> 23,
            scale.z.to_bits() >> 23,
        );
        let mut out = CwBvhNode {
            p: origin.into(),
            e: [exponent.x as u8, exponent.y as u8, exponent.z as u8],
            imask: 0,
            primitive_base_idx: primitive_base,
            child_base_idx: below_base,
            ..CwBvhNode::default()
        };

        let children = self.ordered_children(node);
        let mut internal = UpToEight::default();
        let mut leaf_primitive_count = 0usize;
        for (i, &child) in children.iter().enumerate() {
            if child == u32::MAX {
                continue;
            }
            let child_aabb = self.bvh2.nodes[child as usize].aabb();
            let lo = ((child_aabb.min - origin) * inv_scale)
                .floor()
                .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            let hi = ((child_aabb.max - origin) * inv_scale)
                .ceil()
                .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            out.child_min_x[i] = lo.x as u8;
            out.child_min_y[i] = lo.y as u8;
            out.child_min_z[i] = lo.z as u8;
            out.child_max_x[i] = hi.x as u8;
            out.child_max_y[i] = hi.y as u8;
            out.child_max_z[i] = hi.z as u8;
            match self.choice(child as usize, 0).kind {
                DecisionKind::Leaf => {
                    let first = leaf_primitive_count;
                    self.leaf_primitives(child as usize, primitives, &mut leaf_primitive_count);
                    // The top three bits count the primitives in unary; the low five are the
                    // offset from primitive_base_idx.
                    let unary = match leaf_primitive_count - first {
                        1 => 0b0010_0000,
                        2 => 0b0110_0000,
                        3 => 0b1110_0000,
                        n => unreachable!("a wide leaf of {n} primitives (at most 3)"),
                    };
                    out.child_meta[i] = first as u8 | unary;
                }
                DecisionKind::Internal => {
                    out.imask |= 1 << i;
                    out.child_meta[i] = (24 + i as u8) | 0b0010_0000;
                    internal.push(child);
                }
                DecisionKind::Distribute => {
                    unreachable!("children_of resolves every distributed slot")
                }
            }
        }

        let mut next_below = below_base + internal.as_slice().len() as u32;
        let mut next_primitive = primitive_base + leaf_primitive_count as u32;
        let mut placements = UpToEight::default();
        for (j, &child) in internal.as_slice().iter().enumerate() {
            let child = child as usize;
            let nodes_below = self.wide_nodes_below[child].load(Relaxed);
            let primitives_below = self.primitives[child].load(Relaxed);
            placements.push(ChildPlacement {
                node: child,
                index: below_base + j as u32,
                below_base: next_below,
                nodes_below,
                primitive_base: next_primitive,
                primitives_below,
            });
            next_below += nodes_below;
            next_primitive += primitives_below;
        }
        (out, placements)
    }

    /// Writes the wide node of `node` into `out` and its subtree into `region`: large
    /// subtrees near the root split across threads into disjoint slices, the rest is written
    /// by [`Converter::emit_serial`].
    fn emit(&self, node: usize, out: &mut CwBvhNode, region: Region<'_>, wide_depth: u32) {
        if !self.splits(node, wide_depth) {
            return self.emit_serial(node, out, region);
        }
        let Region {
            below_base,
            below,
            primitive_base,
            primitives,
        } = region;
        let placements;
        (*out, placements) = self.wide_node(node, below_base, primitive_base, primitives);
        let placements = placements.as_slice();
        let leaf_primitives = placements.first().map_or(primitives.len(), |p| {
            (p.primitive_base - primitive_base) as usize
        });
        let (block, mut rest) = below.split_at_mut(placements.len());
        let (_, mut rest_primitives) = primitives.split_at_mut(leaf_primitives);
        let mut jobs = Vec::with_capacity(placements.len());
        for (placement, child_out) in placements.iter().zip(block.iter_mut()) {
            let (child_below, tail) =
                std::mem::take(&mut rest).split_at_mut(placement.nodes_below as usize);
            rest = tail;
            let (child_primitives, tail) = std::mem::take(&mut rest_primitives)
                .split_at_mut(placement.primitives_below as usize);
            rest_primitives = tail;
            let child_region = Region {
                below_base: placement.below_base,
                below: child_below,
                primitive_base: placement.primitive_base,
                primitives: child_primitives,
            };
            jobs.push((placement.node, child_out, child_region));
        }
        jobs.into_par_iter()
            .for_each(|(child, child_out, child_region)| {
                self.emit(child, child_out, child_region, wide_depth + 1)
            });
    }

    /// [`Converter::emit`] on one thread, with a work list instead of recursion.
    fn emit_serial(&self, root: usize, root_out: &mut CwBvhNode, region: Region<'_>) {
        let Region {
            below_base,
            below,
            primitive_base,
            primitives,
        } = region;
        let (wide, first) = self.wide_node(root, below_base, primitive_base, primitives);
        *root_out = wide;
        let mut work = first.as_slice().to_vec();
        while let Some(p) = work.pop() {
            let at = (p.primitive_base - primitive_base) as usize;
            let (wide, placements) = self.wide_node(
                p.node,
                p.below_base,
                p.primitive_base,
                &mut primitives[at..],
            );
            below[(p.index - below_base) as usize] = wide;
            work.extend_from_slice(placements.as_slice());
        }
    }
}

/// Where a wide subtree's nodes below its root go (global indices from `below_base`) and
/// where its primitives go (from `primitive_base`).
struct Region<'a> {
    below_base: u32,
    below: &'a mut [CwBvhNode],
    primitive_base: u32,
    primitives: &'a mut [u32],
}

/// Up to eight items (a wide node's children, or some of them) without a heap allocation:
/// one per wide node would be on the conversion's hot path.
#[derive(Clone, Copy, Default)]
struct UpToEight<T> {
    items: [T; 8],
    count: usize,
}

impl<T: Copy> UpToEight<T> {
    fn push(&mut self, item: T) {
        self.items[self.count] = item;
        self.count += 1;
    }

    fn as_slice(&self) -> &[T] {
        &self.items[..self.count]
    }
}

/// Where an internal wide child and its subtree go (global indices).
#[derive(Clone, Copy, Default)]
struct ChildPlacement {
    /// Its BVH2 node.
    node: usize,
    /// Its own wide node.
    index: u32,
    /// Its children's block, followed by their subtrees.
    below_base: u32,
    nodes_below: u32,
    /// Its leaves' primitives, followed by its internal children's.
    primitive_base: u32,
    primitives_below: u32,
}

//! BVH construction with obvhs (PLOC build, Meister & Bittner 2018, "Parallel locally-ordered
//! clustering for bounding volume hierarchy construction", + reinsertion optimisation,
//! Meister & Bittner 2017; converted to an 8-wide compressed BVH, Ylitie et al. 2017,
//! "Efficient incoherent ray traversal on GPUs through compressed wide BVHs", on every core:
//! [`crate::cwbvh_convert`]).

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::ploc::PlocBuilder;
use obvhs::BvhBuildParams;

use crate::coincident_boxes::coincident_groups;
use crate::cwbvh_convert::bvh2_to_cwbvh_parallel;

/// Quality/speed trade-off of the build: the obvhs presets. obvhs' `pre_split` (spatial
/// splits of large triangles) applies only to its triangle-specific builder, which we do not
/// use because we build over padded boxes (see [`padded_aabb`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildQuality {
    Fastest,
    VeryFast,
    /// Default: measured in tools/bench-bvh (docs/geometry.md) as the best build/trace trade.
    #[default]
    Fast,
    Medium,
    Slow,
    VerySlow,
}

impl BuildQuality {
    pub const ALL: [BuildQuality; 6] = [
        BuildQuality::Fastest,
        BuildQuality::VeryFast,
        BuildQuality::Fast,
        BuildQuality::Medium,
        BuildQuality::Slow,
        BuildQuality::VerySlow,
    ];

    pub fn params(self) -> BvhBuildParams {
        match self {
            BuildQuality::Fastest => BvhBuildParams::fastest_build(),
            BuildQuality::VeryFast => BvhBuildParams::very_fast_build(),
            BuildQuality::Fast => BvhBuildParams::fast_build(),
            BuildQuality::Medium => BvhBuildParams::medium_build(),
            BuildQuality::Slow => BvhBuildParams::slow_build(),
            BuildQuality::VerySlow => BvhBuildParams::very_slow_build(),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            BuildQuality::Fastest => "fastest",
            BuildQuality::VeryFast => "very_fast",
            BuildQuality::Fast => "fast",
            BuildQuality::Medium => "medium",
            BuildQuality::Slow => "slow",
            BuildQuality::VerySlow => "very_slow",
        }
    }
}

/// A box enlarged by a few ulps of its coordinates, so that the compressed child boxes and the
/// slab test can never cull a ray that grazes a primitive lying exactly on a box face — part
/// of keeping the watertight triangle test watertight through the BVH.
pub fn padded_aabb(min: Vec3A, max: Vec3A) -> Aabb {
    let pad = (min.abs().max(max.abs()) * (8.0 * f32::EPSILON)) + Vec3A::splat(f32::MIN_POSITIVE);
    Aabb::new(min - pad, max + pad)
}

/// Build a CWBVH over boxes; `None` for an empty list. The steps of obvhs' `build_cwbvh`
/// (PLOC, reinsertion, conversion), with the conversion on every core.
pub fn build_bvh(boxes: &[Aabb], quality: BuildQuality) -> Option<CwBvh> {
    if boxes.is_empty() {
        return None;
    }
    Some(bvh2_to_cwbvh_parallel(
        &build_bvh2(boxes, quality),
        quality.params().max_prims_per_leaf,
    ))
}

/// The binary BVH that [`build_bvh`] converts: PLOC with one primitive per leaf, then
/// reinsertion. Large groups of identical boxes go to PLOC as one box each and get a
/// balanced subtree under its leaf ([`crate::coincident_boxes`]): PLOC alone makes them a
/// chain, in time quadratic in its length.
pub fn build_bvh2(boxes: &[Aabb], quality: BuildQuality) -> obvhs::bvh2::Bvh2 {
    let groups = coincident_groups(boxes);
    if groups.is_empty() {
        return ploc_with_reinsertion(boxes, (0..boxes.len() as u32).collect(), quality);
    }
    // PLOC sees every box outside the groups and each group's first member; `group_led`
    // names the group a first member leads.
    const OUTSIDE: u32 = u32::MAX;
    const STAND_IN: u32 = u32::MAX - 1;
    let mut group_led = vec![OUTSIDE; boxes.len()];
    for (g, members) in groups.iter().enumerate() {
        group_led[members[0] as usize] = g as u32;
        for &m in &members[1..] {
            group_led[m as usize] = STAND_IN;
        }
    }
    let (kept_boxes, kept): (Vec<Aabb>, Vec<u32>) = boxes
        .iter()
        .zip(0u32..)
        .filter(|&(_, i)| group_led[i as usize] != STAND_IN)
        .map(|(b, i)| (*b, i))
        .unzip();
    // PLOC writes a leaf's label into its `first_index`, which the conversion reads as a
    // slot of `primitive_indices`: positions as labels, then the slots map them back.
    let mut bvh2 = ploc_with_reinsertion(&kept_boxes, (0..kept.len() as u32).collect(), quality);
    debug_assert_eq!(bvh2.primitive_indices.len(), kept.len());
    bvh2.primitive_indices = kept;
    for node in 0..bvh2.nodes.len() {
        let leaf = bvh2.nodes[node];
        if !leaf.is_leaf() {
            continue;
        }
        debug_assert_eq!(leaf.prim_count, 1, "PLOC builds one primitive per leaf");
        let first = bvh2.primitive_indices[leaf.first_index as usize];
        let g = group_led[first as usize];
        if g != OUTSIDE {
            hang_balanced_subtree(&mut bvh2, node, &groups[g as usize]);
        }
    }
    // The optional maps reinsertion may have filled no longer cover the new nodes.
    bvh2.parents.clear();
    bvh2.primitives_to_nodes.clear();
    bvh2
}

fn ploc_with_reinsertion(
    boxes: &[Aabb],
    indices: Vec<u32>,
    quality: BuildQuality,
) -> obvhs::bvh2::Bvh2 {
    let params = quality.params();
    let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        boxes,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// Turns leaf `node` (one primitive, `members[0]`) into a balanced binary subtree with a
/// leaf per member; all share the leaf's box. New nodes go at the end in sibling pairs
/// (children after their parent, as obvhs lays a tree out), new primitives likewise.
fn hang_balanced_subtree(bvh2: &mut obvhs::bvh2::Bvh2, node: usize, members: &[u32]) {
    let aabb = *bvh2.nodes[node].aabb();
    let first_slot = bvh2.nodes[node].first_index;
    // (node to fill, members it holds); a leaf's primitive slot is appended, except the
    // first member's, which keeps the slot PLOC gave it.
    let mut work = vec![(node, 0..members.len())];
    while let Some((at, range)) = work.pop() {
        if range.len() == 1 {
            let slot = if range.start == 0 {
                first_slot
            } else {
                bvh2.primitive_indices.push(members[range.start]);
                (bvh2.primitive_indices.len() - 1) as u32
            };
            bvh2.nodes[at] = Bvh2Node::new(aabb, 1, slot);
            continue;
        }
        let children = bvh2.nodes.len();
        bvh2.nodes
            .extend([Bvh2Node::new(aabb, 0, 0), Bvh2Node::new(aabb, 0, 0)]);
        bvh2.nodes[at] = Bvh2Node::new(aabb, 0, children as u32);
        let mid = range.start + range.len() / 2;
        work.push((children + 1, mid..range.end));
        work.push((children, range.start..mid));
    }
}

/// Largest reciprocal used for a zero (or sub-1e-18) direction component in the slab test.
const MAX_INV_DIRECTION: f32 = 1.0e18;

/// The obvhs ray for a traversal. obvhs' own `Ray::new` clamps `1/d` to `±1/ε` (≈8·10⁶) for
/// tiny components and takes the sign of `-0.0` as negative while its node test takes the
/// traversal side from `d < 0`: a ray travelling exactly along a box face then "drifts" out of
/// the slab after `t ≈ 8·10⁶ × margin`, and one with a `-0.0` component is culled outright.
/// Here a zero component gets `±10¹⁸` with the sign the node test expects, which keeps the
/// drift below any scene scale and the products finite (no `0·∞`/`∞−∞` NaNs).
#[inline]
pub fn bvh_ray(origin: Vec3A, direction: Vec3A, t_min: f32, t_max: f32) -> obvhs::ray::Ray {
    let inv = |d: f32| {
        if d.abs() < 1.0 / MAX_INV_DIRECTION {
            if d < 0.0 {
                -MAX_INV_DIRECTION
            } else {
                MAX_INV_DIRECTION
            }
        } else {
            1.0 / d
        }
    };
    obvhs::ray::Ray {
        origin,
        direction,
        inv_direction: Vec3A::new(inv(direction.x), inv(direction.y), inv(direction.z)),
        tmin: t_min,
        tmax: t_max,
    }
}

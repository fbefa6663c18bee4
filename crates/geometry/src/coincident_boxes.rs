//! Large groups of bit-identical boxes (a mesh with many duplicate triangles, or triangles
//! collapsed onto one point), which the BVH build takes apart from PLOC.
//!
//! PLOC (Meister & Bittner 2018) merges two clusters when each is the other's cheapest
//! neighbour. Among k identical boxes every merge costs the same, obvhs breaks the tie
//! towards the right-hand neighbour, and only the last pair agrees: one merge per pass,
//! k passes, O(k²) time (0.7 s for 10⁴ boxes, 56 s for 10⁵) and a chain k deep. Any binary
//! tree over identical boxes is as good as another, so [`crate::bvh_build::build_bvh2`] gives
//! PLOC one box per group and hangs a balanced subtree of the group under its leaf.
//!
//! Finding the groups must cost ordinary meshes almost nothing: a group can only slow PLOC
//! down once it holds thousands of boxes, and so many land in any sample of the input. The
//! boxes of a pseudo-random sixty-fourth of the input are counted; only the keys seen twice
//! or more there are looked for in the whole input.

use obvhs::aabb::Aabb;
use rustc_hash::FxHashMap;

/// Groups smaller than this stay with PLOC: their k² merges take well under a millisecond,
/// and a pair of triangles sharing a rectangle's box keeps the tree obvhs would build.
pub const GROUP_MIN: usize = 64;
/// Up to this many boxes every box is counted; above it, one in `SAMPLE_STRIDE`.
const COUNT_ALL_UP_TO: usize = 1 << 16;
const SAMPLE_STRIDE: usize = 64;

/// A box by the bits of its corners: equal keys, identical boxes.
type BoxKey = [u32; 6];

fn key(b: &Aabb) -> BoxKey {
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].map(f32::to_bits)
}

/// The boxes counted: one in each run of `stride`, at an offset hashed from the run's
/// index, so that no period in the input's layout can hide a group (every box for
/// `stride` 1).
fn sample(len: usize, stride: usize) -> impl Iterator<Item = usize> {
    (0..len.div_ceil(stride)).filter_map(move |run| {
        let mut h = (run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        h ^= h >> 29;
        let offset = (h.wrapping_mul(0xbf58_476d_1ce4_e5b9) >> 32) as usize % stride;
        Some(run * stride + offset).filter(|&i| i < len)
    })
}

/// The groups of at least [`GROUP_MIN`] bit-identical boxes among `boxes`, each as its
/// members' indices in ascending order; groups in the order of their first member.
/// A group of a few thousand or more is always found; a smaller one may be left to PLOC,
/// which it costs little.
pub fn coincident_groups(boxes: &[Aabb]) -> Vec<Vec<u32>> {
    let count_all = boxes.len() <= COUNT_ALL_UP_TO;
    let stride = if count_all { 1 } else { SAMPLE_STRIDE };
    let mut seen: FxHashMap<BoxKey, u32> = FxHashMap::default();
    seen.reserve(boxes.len().div_ceil(stride));
    for i in sample(boxes.len(), stride) {
        *seen.entry(key(&boxes[i])).or_default() += 1;
    }
    let enough = if count_all { GROUP_MIN as u32 } else { 2 };
    let mut candidates: FxHashMap<BoxKey, Vec<u32>> = seen
        .into_iter()
        .filter(|&(_, n)| n >= enough)
        .map(|(k, _)| (k, Vec::new()))
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    for (i, b) in boxes.iter().enumerate() {
        if let Some(members) = candidates.get_mut(&key(b)) {
            members.push(i as u32);
        }
    }
    let mut groups: Vec<Vec<u32>> = candidates
        .into_values()
        .filter(|members| members.len() >= GROUP_MIN)
        .collect();
    groups.sort_unstable_by_key(|members| members[0]);
    groups
}

#[cfg(test)]
mod tests {
    use glam::Vec3A;

    use super::*;

    fn unit_box_at(x: f32) -> Aabb {
        Aabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 1.0, 1.0, 1.0))
    }

    #[test]
    fn finds_large_groups_in_small_and_large_inputs_and_ignores_small_ones() {
        for distinct in [100usize, 200_000] {
            // A group of 5000 spread through the input, one of 70 at its end, one of 10.
            let every = distinct / 50;
            let mut boxes: Vec<Aabb> = (0..distinct)
                .flat_map(|i| {
                    let copies = if i % every == 0 { 100 } else { 0 };
                    std::iter::once(unit_box_at(i as f32))
                        .chain(std::iter::repeat_n(unit_box_at(-7.0), copies))
                })
                .collect();
            boxes.extend((0..70).map(|_| unit_box_at(-9.0)));
            boxes.extend((0..10).map(|_| unit_box_at(-11.0)));
            let groups = coincident_groups(&boxes);
            let sizes: Vec<usize> = groups.iter().map(Vec::len).collect();
            if distinct <= COUNT_ALL_UP_TO {
                assert_eq!(sizes, [5000, 70], "{distinct}");
            } else {
                // The group of 70 has about one box in the sample: found or not, never split.
                assert!(
                    sizes == [5000, 70] || sizes == [5000],
                    "{distinct}: {sizes:?}"
                );
            }
            for group in &groups {
                assert!(group.windows(2).all(|w| w[0] < w[1]));
                assert!(group
                    .iter()
                    .all(|&i| key(&boxes[i as usize]) == key(&boxes[group[0] as usize])));
            }
        }
    }

    #[test]
    fn distinct_boxes_make_no_group() {
        let boxes: Vec<Aabb> = (0..300_000).map(|i| unit_box_at(i as f32)).collect();
        assert!(coincident_groups(&boxes).is_empty());
    }
}

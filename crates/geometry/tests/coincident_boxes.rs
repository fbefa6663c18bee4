//! `build_bvh2` over inputs with large groups of identical boxes (a mesh with duplicate
//! triangles, or triangles collapsed onto one point): a shallow tree that holds every
//! primitive once, where PLOC alone builds a chain as deep as the group (and takes 56 s
//! for 10⁵ boxes).

mod support;

use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use prism_geometry::bvh_build::{build_bvh2, padded_aabb, BuildQuality};
use prism_geometry::cwbvh_convert::bvh2_to_cwbvh_parallel;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use support::triangle_soup;

/// (depth, primitives in leaf order); panics where a node's box does not hold a child's.
fn walk(bvh2: &Bvh2) -> (usize, Vec<u32>) {
    let mut depth = 0;
    let mut primitives = Vec::new();
    let mut stack = vec![(0usize, 1usize)];
    while let Some((node, d)) = stack.pop() {
        depth = depth.max(d);
        let n = &bvh2.nodes[node];
        if n.is_leaf() {
            let first = n.first_index as usize;
            primitives.extend(&bvh2.primitive_indices[first..first + n.prim_count as usize]);
            continue;
        }
        let first = n.first_index as usize;
        for child in [first, first + 1] {
            let c = bvh2.nodes[child].aabb();
            assert!(
                n.aabb().min.cmple(c.min).all() && n.aabb().max.cmpge(c.max).all(),
                "node {node} does not hold child {child}"
            );
            stack.push((child, d + 1));
        }
    }
    (depth, primitives)
}

#[test]
fn groups_of_identical_boxes_build_shallow_trees_with_every_primitive_once() {
    let mut rng = Pcg64::seed_from_u64(7);
    let soup = triangle_soup(20_000, 10.0, 0.01..0.8, &mut rng);
    let soup_boxes: Vec<_> = soup
        .indices
        .iter()
        .map(|&[a, b, c]| {
            let p = [a, b, c].map(|i| soup.positions[i as usize]);
            padded_aabb(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
        })
        .collect();
    // 10⁵ copies of one triangle's box spread through the soup (five after each of its
    // boxes), 3000 of a point (triangles collapsed onto it) at the end, and 20 copies of
    // another box, which PLOC keeps.
    let duplicate = soup_boxes[11];
    let mut boxes: Vec<_> = soup_boxes
        .iter()
        .flat_map(|&b| std::iter::once(b).chain(std::iter::repeat_n(duplicate, 5)))
        .collect();
    let point = padded_aabb(Vec3A::splat(3.0), Vec3A::splat(3.0));
    boxes.extend(std::iter::repeat_n(point, 3000));
    boxes.extend(std::iter::repeat_n(boxes[500], 20));
    let n = boxes.len();
    for quality in [BuildQuality::Fastest, BuildQuality::Fast] {
        let bvh2 = build_bvh2(&boxes, quality);
        let (depth, mut primitives) = walk(&bvh2);
        assert!(depth <= 64, "{quality:?}: {depth} levels for {n} boxes");
        primitives.sort_unstable();
        assert!(
            primitives.iter().copied().eq(0..n as u32),
            "{quality:?}: not every primitive once"
        );
        let serial = bvh2_to_cwbvh(&bvh2, 3, true, false);
        assert!(
            bvh2_to_cwbvh_parallel(&bvh2, 3) == serial,
            "{quality:?}: the conversions differ"
        );
    }
}

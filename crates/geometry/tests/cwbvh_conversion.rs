//! The parallel BVH2 → CWBVH conversion (`cwbvh_convert`) against obvhs' serial
//! `bvh2_to_cwbvh`, node for node: same decisions, same child order, same layout.

mod support;

use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use prism_geometry::bvh_build::{build_bvh2, padded_aabb, BuildQuality};
use prism_geometry::cwbvh_convert::bvh2_to_cwbvh_parallel;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use support::triangle_soup;

fn boxes_of(n: usize, seed: u64) -> Vec<obvhs::aabb::Aabb> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mesh = triangle_soup(n, 10.0, 0.01..0.8, &mut rng);
    mesh.indices
        .iter()
        .map(|&[a, b, c]| {
            let p = [a, b, c].map(|i| mesh.positions[i as usize]);
            padded_aabb(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
        })
        .collect()
}

#[test]
fn converts_exactly_as_obvhs() {
    // 1–40 primitives take the serial paths only; 60 000 splits across threads at every pass.
    for (n, seed) in [(1, 1), (2, 2), (3, 3), (9, 4), (40, 5), (60_000, 6)] {
        let boxes = boxes_of(n, seed);
        for quality in [
            BuildQuality::Fastest,
            BuildQuality::Fast,
            BuildQuality::Slow,
        ] {
            let bvh2 = build_bvh2(&boxes, quality);
            for max_prims_per_leaf in 1..=3 {
                let serial = bvh2_to_cwbvh(&bvh2, max_prims_per_leaf, true, false);
                let parallel = bvh2_to_cwbvh_parallel(&bvh2, max_prims_per_leaf);
                assert_eq!(
                    parallel.nodes.len(),
                    serial.nodes.len(),
                    "{n} boxes, {quality:?}, {max_prims_per_leaf} per leaf: node count"
                );
                assert!(
                    parallel == serial,
                    "{n} boxes, {quality:?}, {max_prims_per_leaf} per leaf: the conversions differ"
                );
            }
        }
    }
}

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

/// Coincident or nested boxes (a mesh exported with many duplicate or collapsed triangles)
/// make PLOC's BVH2 a chain as deep as it has primitives (`build_bvh2` takes large groups
/// of coincident boxes apart, so the chains here are PLOC's own). The conversion walks it without
/// recursion: here on threads of 64 KiB of stack, which a recursion that deep overflows
/// (obvhs' recursive conversion runs on a thread with 512 MiB, for the comparison).
#[test]
fn chains_as_deep_as_their_primitives_convert_without_recursion() {
    use glam::Vec3A;
    // PLOC itself takes time quadratic in a chain's length (0.7 s for 10⁴, 56 s for 10⁵).
    const N: usize = 10_000;
    let coincident: Vec<_> = (0..N)
        .map(|_| padded_aabb(Vec3A::ZERO, Vec3A::ONE))
        .collect();
    let nested: Vec<_> = (0..N)
        .map(|i| {
            let half = 1.001f32.powi(i as i32);
            padded_aabb(Vec3A::splat(-half), Vec3A::splat(half))
        })
        .collect();
    let small_stacks = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .stack_size(64 << 10)
        .build()
        .unwrap();
    for (name, boxes) in [("coincident", coincident), ("nested", nested)] {
        let params = BuildQuality::Fast.params();
        let bvh2 = obvhs::ploc::PlocBuilder::with_capacity(N).build(
            params.ploc_search_distance,
            &boxes,
            (0..N as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        let mut depth = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((node, d)) = stack.pop() {
            depth = depth.max(d);
            let n = &bvh2.nodes[node];
            if !n.is_leaf() {
                let first = n.first_index as usize;
                stack.extend([(first, d + 1), (first + 1, d + 1)]);
            }
        }
        assert!(
            depth > N / 2,
            "{name}: the BVH2 is {depth} deep, not a chain"
        );
        let parallel = small_stacks.install(|| bvh2_to_cwbvh_parallel(&bvh2, 3));
        let serial = std::thread::Builder::new()
            .stack_size(512 << 20)
            .spawn(move || bvh2_to_cwbvh(&bvh2, 3, true, false))
            .unwrap()
            .join()
            .unwrap();
        assert!(parallel == serial, "{name}: the conversions differ");
    }
}

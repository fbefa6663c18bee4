//! Random scenes and targets shared by the geometry test binaries (each binary uses a part).
#![allow(dead_code)]

use glam::Vec3A;
use prism_geometry::TriangleMesh;
use rand::Rng;
use rand_pcg::Pcg64;

/// A uniformly distributed unit vector (rejection sampling in the unit ball).
pub fn random_unit(rng: &mut Pcg64) -> Vec3A {
    loop {
        let v = Vec3A::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

/// An open soup of `n` random triangles with centres in `[-half_extent_m, half_extent_m]³`
/// and vertex distances from the centre in `size_m`.
pub fn triangle_soup(
    n: usize,
    half_extent_m: f32,
    size_m: std::ops::Range<f32>,
    rng: &mut Pcg64,
) -> TriangleMesh {
    let mut positions = Vec::with_capacity(3 * n);
    let mut indices = Vec::with_capacity(n);
    for i in 0..n {
        let c = Vec3A::new(
            rng.gen_range(-half_extent_m..half_extent_m),
            rng.gen_range(-half_extent_m..half_extent_m),
            rng.gen_range(-half_extent_m..half_extent_m),
        );
        let size = rng.gen_range(size_m.clone());
        for _ in 0..3 {
            positions.push(c + random_unit(rng) * size);
        }
        let k = 3 * i as u32;
        indices.push([k, k + 1, k + 2]);
    }
    TriangleMesh::new(positions, indices)
}

/// Points on the edges (midpoints and quarter points) and at the vertices of a mesh: the
/// targets of the leak tests.
pub fn edge_and_vertex_targets(mesh: &TriangleMesh) -> Vec<Vec3A> {
    let mut targets: Vec<Vec3A> = mesh.positions.clone();
    for tri in &mesh.indices {
        for k in 0..3 {
            let (a, b) = (
                mesh.positions[tri[k] as usize],
                mesh.positions[tri[(k + 1) % 3] as usize],
            );
            targets.push(0.5 * (a + b));
            targets.push(a + 0.25 * (b - a));
        }
    }
    targets
}

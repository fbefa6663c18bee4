//! Virtual ray tracing of periodic tiles ([`prism_geometry::tiling`]) against the same tiles
//! modelled explicitly: every copy written out as one mesh.

use std::path::PathBuf;

use glam::Vec3A;
use prism_geometry::{
    load_obj, open_seam_edges, BuildQuality, Geometry, GeometryBuilder, MeshId, Ray, Shape, Tiling,
    Transform, TriangleMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

mod support;
use support::random_unit;

const PERIOD_M: f32 = 0.1;

fn wicker() -> TriangleMesh {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/tiled/tiles/wicker.obj");
    load_obj(path).expect("scenes/tiled/tiles/wicker.obj (tools/make_wicker_tile.py)")
}

/// The tile copied to every cell of a `cells` grid, as one mesh.
fn explicit(tile: &TriangleMesh, cells: [u32; 2]) -> TriangleMesh {
    let mut out = tile.clone();
    out.positions.clear();
    out.indices.clear();
    out.material_ids.clear();
    out.object_ids.clear();
    let mut normals = Vec::new();
    for j in 0..cells[1] {
        for i in 0..cells[0] {
            let offset = Vec3A::new(i as f32 * PERIOD_M, j as f32 * PERIOD_M, 0.0);
            let base = out.positions.len() as u32;
            out.positions
                .extend(tile.positions.iter().map(|&p| p + offset));
            if let Some(n) = &tile.normals {
                normals.extend_from_slice(n);
            }
            out.indices
                .extend(tile.indices.iter().map(|t| t.map(|k| k + base)));
            out.material_ids.extend_from_slice(&tile.material_ids);
            out.object_ids.extend_from_slice(&tile.object_ids);
        }
    }
    out.normals = tile.normals.as_ref().map(|_| normals);
    out.uvs = None;
    out
}

fn place() -> Transform {
    Transform::translate(Vec3A::new(0.3, -0.2, 1.0))
        .compose(&Transform::rotate(Vec3A::new(1.0, 2.0, 0.5).normalize(), 0.7).unwrap())
}

fn tiled_geometry(tile: TriangleMesh, cells: [u32; 2]) -> Geometry {
    let mut b = GeometryBuilder::new();
    let mesh = b.add_mesh(tile);
    b.add_instance(
        Shape::Tiled(Tiling {
            mesh,
            period_m: [PERIOD_M; 2],
            cells,
        }),
        place(),
        None,
    )
    .unwrap();
    b.build(BuildQuality::default())
}

fn explicit_geometry(tile: &TriangleMesh, cells: [u32; 2]) -> Geometry {
    let mut b = GeometryBuilder::new();
    let mesh = b.add_mesh(explicit(tile, cells));
    b.add_instance(Shape::Mesh(mesh), place(), None).unwrap();
    b.build(BuildQuality::default())
}

/// Random rays through the grid's box: from points around it towards points inside it,
/// and from points inside the slab in random directions.
fn rays(cells: [u32; 2], n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let size = Vec3A::new(cells[0] as f32 * PERIOD_M, cells[1] as f32 * PERIOD_M, 0.02);
    let to_world = place();
    (0..n)
        .map(|k| {
            let inside = Vec3A::new(
                rng.gen_range(-0.05..1.05) * size.x,
                rng.gen_range(-0.05..1.05) * size.y,
                rng.gen_range(-0.6..0.6) * size.z,
            );
            let (o, d) = if k % 2 == 0 {
                let o = 0.5 * size + random_unit(&mut rng) * (size.length() + 0.1);
                (o, inside - o)
            } else {
                (inside, random_unit(&mut rng))
            };
            Ray::new(to_world.point(o), to_world.vector(d), 0.0, f32::INFINITY)
        })
        .collect()
}

/// Fraction of rays on which the two geometries agree: both miss, or both hit at the same
/// point (1 µm) with the same material and the same geometric normal; and `occluded`
/// agrees with `intersect` on the tiled geometry.
fn agreement(tiled: &Geometry, reference: &Geometry, rays: &[Ray]) -> (f64, usize) {
    let mut agree = 0usize;
    let mut hits = 0usize;
    for ray in rays {
        let a = tiled.intersect(ray);
        let b = reference.intersect(ray);
        assert_eq!(
            tiled.occluded(ray),
            a.is_some(),
            "occluded and intersect disagree on {ray:?}"
        );
        let same = match (a, b) {
            (None, None) => true,
            (Some(ha), Some(hb)) => {
                hits += 1;
                let (sa, sb) = (tiled.interaction(ray, &ha), reference.interaction(ray, &hb));
                (sa.p - sb.p).length() < 1e-6
                    && sa.material_id == sb.material_id
                    && sa.n_geometric.dot(sb.n_geometric) > 0.9999
                    && sa.n_shading.dot(sb.n_shading) > 0.9999
            }
            _ => false,
        };
        agree += usize::from(same);
    }
    (agree as f64 / rays.len() as f64, hits)
}

#[test]
fn virtual_ray_tracing_finds_the_hits_of_the_explicit_mesh() {
    let tile = wicker();
    let cells = [7, 4];
    let rays = rays(cells, 40_000, 7);
    let (fraction, hits) = agreement(
        &tiled_geometry(tile.clone(), cells),
        &explicit_geometry(&tile, cells),
        &rays,
    );
    println!(
        "wicker 7×4: {fraction:.6} of {} rays agree ({hits} hits)",
        rays.len()
    );
    assert!(hits > 10_000, "too few rays hit the weave: {hits}");
    // Rays grazing the seam between two copies may round to the other copy.
    assert!(fraction > 0.9995, "agreement {fraction}");
}

#[test]
fn copies_reaching_into_neighbouring_cells_are_found() {
    // The same weave shifted off its period box by (0.37, −0.61) periods: every strand
    // reaches into the neighbouring cells, which the walk must test too.
    let mut tile = wicker();
    let shift = Vec3A::new(0.37 * PERIOD_M, -0.61 * PERIOD_M, 0.0);
    for p in &mut tile.positions {
        *p += shift;
    }
    let cells = [3, 5];
    let rays = rays(cells, 30_000, 11);
    let (fraction, hits) = agreement(
        &tiled_geometry(tile.clone(), cells),
        &explicit_geometry(&tile, cells),
        &rays,
    );
    println!("shifted wicker 3×5: {fraction:.6} agree ({hits} hits)");
    assert!(hits > 5_000);
    assert!(fraction > 0.9995, "agreement {fraction}");
}

#[test]
fn a_hit_reports_the_tile_face_and_its_material_not_the_carrier() {
    let tile = wicker();
    let g = tiled_geometry(tile.clone(), [2, 2]);
    // Straight down onto the weft strand at (0.125, 0.025) in the second cell.
    let to_world = place();
    let above = to_world.point(Vec3A::new(0.1 + 0.025, 0.025, 0.5));
    let down = to_world.vector(Vec3A::new(0.0, 0.0, -1.0));
    let ray = Ray::new(above, down, 0.0, f32::INFINITY);
    let hit = g.intersect(&ray).expect("the strand is below");
    let si = g.interaction(&ray, &hit);
    let weft = tile
        .material_names
        .iter()
        .position(|n| n == "strand_weft")
        .unwrap() as u32;
    assert_eq!(si.material_id, weft);
    assert!((si.primitive_id as usize) < tile.triangle_count());
    let local = to_world.inverse_point(si.p);
    // The weft strand is at its top (z = A + half thickness) over x = 0.025 of each period.
    assert!((local.z - 0.010).abs() < 2e-4, "{local}");
    assert!((local.x - 0.125).abs() < 1e-5 && (local.y - 0.025).abs() < 1e-5);
    // Through a hole (between the strands) the ray passes.
    let hole = to_world.point(Vec3A::new(0.05, 0.05, 0.5));
    assert!(g
        .intersect(&Ray::new(hole, down, 0.0, f32::INFINITY))
        .is_none());
}

#[test]
fn seams_of_a_tile_that_does_not_continue_are_counted() {
    let tile = wicker();
    assert_eq!(open_seam_edges(&tile, [PERIOD_M; 2]), 0);
    // Cut the first segment off one strand: its ring at x = 0.1 m loses its partner at
    // x = 0 (12 edges round the strand); the new end at x = 3 mm is not on a period plane.
    let mut cut = tile.clone();
    let first_segment: Vec<usize> = (0..24).collect();
    let mut keep = vec![true; cut.indices.len()];
    for k in first_segment {
        keep[k] = false;
    }
    let mut k = 0;
    cut.indices.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    let mut k = 0;
    cut.material_ids.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    cut.object_ids.truncate(cut.indices.len());
    assert_eq!(open_seam_edges(&cut, [PERIOD_M; 2]), 12);
    // A period that is not the tile's: nothing matches across it.
    assert!(open_seam_edges(&tile, [0.09, 0.1]) > 0);
}

#[test]
fn grids_whose_ids_do_not_fit_are_refused() {
    let tile = wicker();
    let mut b = GeometryBuilder::new();
    let mesh: MeshId = b.add_mesh(tile);
    let too_many = Tiling {
        mesh,
        period_m: [PERIOD_M; 2],
        cells: [100_000, 100_000],
    };
    assert!(b
        .add_instance(Shape::Tiled(too_many), Transform::IDENTITY, None)
        .is_none());
    let empty = Tiling {
        cells: [0, 3],
        ..too_many
    };
    assert!(b
        .add_instance(Shape::Tiled(empty), Transform::IDENTITY, None)
        .is_none());
}

//! Directional patches (`prism_radiosity::directional`): a two-sided surface whose light
//! leaves by its Γ, per direction bin, reflected and transmitted.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::Vec3A;
use prism_radiosity::bins::{self, HEMISPHERE_BINS, SECTORS, SPHERE_BINS};
use prism_radiosity::directional::{DirectionalSide, DirectionalSurface};
use prism_radiosity::tile_cells::{cell_index, pyramid_cells, TileLattice};
use prism_radiosity::{
    ElementShape, InputPatch, NoDirectLight, Radiosity, RadiositySettings, Unoccluded, Visibility,
};

fn patch(
    p0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    reflectance: f32,
    emission: f32,
    surface: u32,
) -> InputPatch {
    InputPatch {
        shape: ElementShape::Parallelogram { p0, e1, e2 },
        reflectance: vec![reflectance],
        emission: vec![emission],
        surface,
        directional: None,
    }
}

/// A square panel (side `size_m`, centred at `centre`, front normal +z) as two patches
/// (front first) with Γ `gamma(i, o)`, appended to `patches`; its diffuse equivalents are
/// `reflectance` (front, back).
fn panel(
    patches: &mut Vec<InputPatch>,
    centre: Vec3A,
    size_m: f32,
    reflectance: [f32; 2],
    gamma: impl Fn(usize, usize) -> f32,
) {
    pyramid_panel(patches, centre, size_m, reflectance, 1, |_, i, o| {
        gamma(i, o)
    });
}

/// `panel` with a pyramid of `levels` levels over one period (the panel): Γ
/// `gamma(cell, i, o)`, cells numbered as `tile_cells::cell_index` does.
fn pyramid_panel(
    patches: &mut Vec<InputPatch>,
    centre: Vec3A,
    size_m: f32,
    reflectance: [f32; 2],
    levels: u32,
    gamma: impl Fn(usize, usize, usize) -> f32,
) {
    let p0 = centre - Vec3A::new(size_m, size_m, 0.0) * 0.5;
    let (x, y) = (Vec3A::X * size_m, Vec3A::Y * size_m);
    let pairs = SPHERE_BINS * SPHERE_BINS;
    let cells = pyramid_cells(levels);
    let surface = Arc::new(DirectionalSurface {
        frame: [Vec3A::X, Vec3A::Y, Vec3A::Z],
        lattice: TileLattice {
            origin: p0,
            period: [x, y],
        },
        levels,
        gamma: (0..cells * pairs)
            .map(|k| gamma(k / pairs, (k % pairs) / SPHERE_BINS, k % SPHERE_BINS))
            .collect(),
        view_transparency: vec![0.0; cells * SPHERE_BINS],
    });
    let first = patches.len() as u32;
    for (front, e1, e2) in [(true, x, y), (false, y, x)] {
        let mut p = patch(
            p0,
            e1,
            e2,
            reflectance[usize::from(!front)],
            0.0,
            100 + first,
        );
        p.directional = Some(DirectionalSide {
            surface: surface.clone(),
            front,
            partner: if front { first + 1 } else { first },
        });
        patches.push(p);
    }
}

fn solve(patches: &[InputPatch], error_bound_rel: f32) -> Radiosity {
    solve_seeing(patches, error_bound_rel, &Unoccluded)
}

fn solve_seeing(patches: &[InputPatch], error_bound_rel: f32, vis: &dyn Visibility) -> Radiosity {
    let settings = RadiositySettings {
        error_bound_rel,
        ..RadiositySettings::default()
    };
    let mut solution = Radiosity::new(patches, 1, settings).unwrap();
    for _ in 0..3 {
        solution.iterate(vis, &NoDirectLight).unwrap();
    }
    solution
}

/// Only lines with an end on the plane z = 0 are free: the surfaces around it see each
/// other only by way of what lies there.
struct ThroughThePlane;

impl Visibility for ThroughThePlane {
    fn visible(&self, from: Vec3A, _: Vec3A, to: Vec3A, _: Vec3A) -> bool {
        from.z.abs() < 1e-3 || to.z.abs() < 1e-3
    }
}

/// Σ radiosity × area and Σ irradiance × area over the leaves of `patch`.
fn powers(solution: &Radiosity, patch: usize) -> (f32, f32) {
    solution
        .leaves()
        .filter(|l| l.patch == patch)
        .fold((0.0, 0.0), |(b, e), l| {
            let a = l.shape.area_m2();
            (b + l.radiosity[0] * a, e + l.irradiance[0] * a)
        })
}

/// A square facing `towards` from `centre` (side `size_m`).
fn facing(centre: Vec3A, towards: Vec3A, size_m: f32, emission: f32, surface: u32) -> InputPatch {
    let n = (towards - centre).normalize();
    let u = n.cross(Vec3A::Z).normalize_or(Vec3A::X);
    let v = n.cross(u);
    // e1 × e2 = v × u… turned so that the normal is n.
    let (e1, e2) = if u.cross(v).dot(n) > 0.0 {
        (u, v)
    } else {
        (v, u)
    };
    let p0 = centre - (e1 + e2) * size_m * 0.5;
    patch(p0, e1 * size_m, e2 * size_m, 0.0, emission, surface)
}

/// Γ = ρ/π on the light's side and 0 through: the diffuse patches it stands for, in a
/// closed box where every face emits and reflects.
#[test]
fn a_lambertian_gamma_solves_as_the_diffuse_patches_it_equals() {
    let (o, x, y, z) = (Vec3A::ZERO, Vec3A::X, Vec3A::Y, Vec3A::Z);
    let cube = vec![
        patch(o, x, y, 0.5, 1.0, 0),
        patch(z, y, x, 0.5, 1.0, 1),
        patch(o, z, x, 0.5, 1.0, 2),
        patch(y, x, z, 0.5, 1.0, 3),
        patch(o, y, z, 0.5, 1.0, 4),
        patch(x, z, y, 0.5, 1.0, 5),
    ];
    let rho = 0.6;
    let mut directional = cube.clone();
    panel(
        &mut directional,
        Vec3A::splat(0.5),
        0.5,
        [rho, rho],
        |i, o| {
            if bins::is_above(i) == bins::is_above(o) {
                rho / PI
            } else {
                0.0
            }
        },
    );
    let mut diffuse = directional.clone();
    diffuse[6].directional = None;
    diffuse[7].directional = None;
    let (a, b) = (solve(&directional, 0.001), solve(&diffuse, 0.001));
    for (patch, input) in directional.iter().enumerate() {
        let shape = input.shape;
        for (u, v) in [(0.1, 0.1), (0.5, 0.5), (0.9, 0.3)] {
            let p = shape.point(u, v);
            let (da, db) = (a.radiosity_at(patch, p)[0], b.radiosity_at(patch, p)[0]);
            assert!(
                (da / db - 1.0).abs() < 1e-4,
                "patch {patch} at ({u}, {v}): {da} {db}"
            );
        }
    }
    // Towards any direction on its side the panel sends its radiosity.
    let p = Vec3A::splat(0.5);
    let front = a.radiosity_at(6, p)[0];
    for w in [Vec3A::Z, Vec3A::new(0.9, 0.2, 0.1).normalize()] {
        let m = a.exitance_towards(6, p, w).unwrap()[0];
        assert!((m / front - 1.0).abs() < 1e-5, "{m} {front}");
    }
}

/// A panel that reflects ρ and transmits τ_s (Lambertian both ways) over a lamp: its far
/// side sends τ_s of what its near side receives, its near side ρ of it, and the lamp gets
/// back what it gets from a diffuse ρ panel.
#[test]
fn a_transmitting_panel_passes_its_scattered_transmittance_to_its_far_side() {
    let (rho, transmittance) = (0.3, 0.5);
    // The lamp at z = 0 facing up, the panel's front facing it from z = 1.
    let lamp = patch(Vec3A::ZERO, Vec3A::X, Vec3A::Y, 0.0, 1.0, 0);
    let mut patches = vec![lamp];
    // The frame's z is the front's normal (up): the lamp lights the panel's back.
    panel(
        &mut patches,
        Vec3A::new(0.5, 0.5, 1.0),
        1.0,
        [0.0, rho],
        |i, o| match (bins::is_above(i), bins::is_above(o)) {
            (false, false) => rho / PI,
            (false, true) => transmittance / PI,
            (true, _) => 0.0,
        },
    );
    let solution = solve(&patches, 0.0005);
    let (lit_b, lit_e) = powers(&solution, 2);
    let (far_b, far_e) = powers(&solution, 1);
    eprintln!("near side: E·A {lit_e}, B·A {lit_b}; far side: E·A {far_e}, B·A {far_b}");
    assert_eq!(far_e, 0.0);
    // Unit squares one apart: F = 0.199 82 (Howell C-11).
    assert!((lit_e / 0.19982 - 1.0).abs() < 0.01, "{lit_e}");
    assert!((lit_b / (rho * lit_e) - 1.0).abs() < 1e-4, "{lit_b}");
    // The far side, never refined (nothing is in front of it), transmits the near
    // side's area average.
    assert!(
        (far_b / (transmittance * lit_e) - 1.0).abs() < 0.01,
        "{far_b}"
    );

    let mut diffuse = patches.clone();
    diffuse[1].directional = None;
    diffuse[2].directional = None;
    let d = solve(&diffuse, 0.0005);
    let (lamp_directional, lamp_diffuse) = (powers(&solution, 0).1, powers(&d, 0).1);
    assert!(
        (lamp_directional / lamp_diffuse - 1.0).abs() < 1e-3,
        "{lamp_directional} {lamp_diffuse}"
    );
}

/// A panel that reflects like a mirror at the bins' resolution, Γ(i → o) = ρ/Ω⊥(o) for o
/// the bin mirrored about the normal: a receiver in the mirror direction of a lamp gets
/// its light, one as far at another azimuth nothing. A diffuse panel lights both alike.
/// The lamp and the receivers do not see each other.
#[test]
fn light_leaves_a_directional_panel_by_its_gamma() {
    let rho = 0.8;
    let mirror_bin = |i: usize| {
        let (ring, sector) = ((i % HEMISPHERE_BINS) / SECTORS, i % SECTORS);
        (i / HEMISPHERE_BINS) * HEMISPHERE_BINS + ring * SECTORS + (sector + SECTORS / 2) % SECTORS
    };
    // Directions at 45° elevation, at sector centres' azimuths.
    let at = |sector: f32| {
        let phi = (sector + 0.5) * std::f32::consts::TAU / SECTORS as f32;
        Vec3A::new(phi.cos(), phi.sin(), 1.0) * 2.0f32.sqrt()
    };
    let centre = Vec3A::ZERO;
    let mut patches = vec![
        facing(at(4.0), centre, 0.3, 1.0, 0),
        facing(at(0.0), centre, 0.3, 0.0, 1),
        facing(at(2.0), centre, 0.3, 0.0, 2),
    ];
    panel(&mut patches, centre, 0.4, [rho, 0.0], |i, o| {
        if bins::is_above(i) && o == mirror_bin(i) {
            rho / bins::projected_solid_angle_sr(o)
        } else {
            0.0
        }
    });
    let solution = solve_seeing(&patches, 0.0005, &ThroughThePlane);
    let (mirror, side) = (powers(&solution, 1).1, powers(&solution, 2).1);
    let (panel_b, panel_e) = powers(&solution, 3);
    eprintln!("mirror receiver {mirror}, side receiver {side}, panel E·A {panel_e}");
    assert!(
        (panel_b / (rho * panel_e) - 1.0).abs() < 1e-4,
        "{panel_b} {panel_e}"
    );
    assert!(mirror > 20.0 * side && mirror > 0.0, "{mirror} {side}");

    let mut diffuse = patches.clone();
    diffuse[3].directional = None;
    diffuse[4].directional = None;
    let d = solve_seeing(&diffuse, 0.0005, &ThroughThePlane);
    let (mirror_d, side_d) = (powers(&d, 1).1, powers(&d, 2).1);
    assert!(
        (mirror_d / side_d - 1.0).abs() < 0.02,
        "{mirror_d} {side_d}"
    );
    // The mirror gathers what the diffuse panel spreads over the hemisphere into one bin
    // (π/Ω⊥ = 16/3 at 45°, less where the panel's points see the receiver off the bin).
    assert!(mirror > 2.0 * mirror_d, "{mirror} {mirror_d}");
}

/// A directional side whose partner is not the other side of its surface is refused.
#[test]
fn a_directional_side_must_pair_with_its_other_side() {
    let mut patches = Vec::new();
    panel(&mut patches, Vec3A::ZERO, 1.0, [0.5, 0.5], |_, _| 0.1);
    let mut wrong = patches.clone();
    wrong[1].directional.as_mut().unwrap().partner = 1;
    let error = Radiosity::new(&wrong, 1, RadiositySettings::default())
        .err()
        .unwrap();
    assert!(error.to_string().contains("not the other side"), "{error}");
    let mut flipped = patches.clone();
    flipped[0].directional.as_mut().unwrap().front = false;
    flipped[1].directional.as_mut().unwrap().front = true;
    let error = Radiosity::new(&flipped, 1, RadiositySettings::default())
        .err()
        .unwrap();
    assert!(error.to_string().contains("normal"), "{error}");
    let mut short = patches;
    let surface = Arc::new(DirectionalSurface {
        frame: [Vec3A::X, Vec3A::Y, Vec3A::Z],
        lattice: TileLattice {
            origin: Vec3A::ZERO,
            period: [Vec3A::X, Vec3A::Y],
        },
        levels: 1,
        gamma: vec![0.1; 7],
        view_transparency: vec![0.0; SPHERE_BINS],
    });
    for p in &mut short {
        p.directional.as_mut().unwrap().surface = surface.clone();
    }
    let error = Radiosity::new(&short, 1, RadiositySettings::default())
        .err()
        .unwrap();
    assert!(error.to_string().contains("expected 4096"), "{error}");
}

/// The solution file keeps the directional values: a loaded solution sends the same
/// exitance in every bin.
#[test]
fn a_saved_directional_solution_reads_back_the_same() {
    let mut patches = vec![patch(
        Vec3A::new(0.0, 0.0, -1.0),
        Vec3A::X,
        Vec3A::Y,
        0.0,
        1.0,
        0,
    )];
    panel(
        &mut patches,
        Vec3A::new(0.5, 0.5, 0.0),
        1.0,
        [0.4, 0.1],
        |i, o| 0.01 * (1 + (i * 7 + o * 3) % 11) as f32,
    );
    let solution = solve(&patches, 0.004);
    let loaded = Radiosity::from_bytes(&solution.to_bytes()).unwrap();
    assert!(loaded.matches_patches(&patches));
    for bin in 0..SPHERE_BINS {
        let w = bins::centre(bin);
        let patch = if bins::is_above(bin) { 1 } else { 2 };
        let p = Vec3A::new(0.3, 0.6, 0.0);
        assert_eq!(
            solution.exitance_towards(patch, p, w),
            loaded.exitance_towards(patch, p, w)
        );
    }
    let mut other = patches.clone();
    other[2].directional.as_mut().unwrap().front = true;
    assert!(!loaded.matches_patches(&other));
}

/// Per-level Γ (Mostefaoui et al. §3): a panel that is one period of a tile whose left
/// half reflects 0.8 and right half 0.2 (Lambertian on the light's side). Its elements no
/// wider than half a period reflect their half's albedo; larger ones the period's mean.
#[test]
fn sub_patches_read_the_pyramid_level_of_their_size() {
    let (left, right) = (0.8f32, 0.2f32);
    let lambert = |cell: usize, i: usize, o: usize| -> f32 {
        if !(bins::is_above(i) && bins::is_above(o)) {
            return 0.0;
        }
        let rho = match cell {
            0 => 0.5 * (left + right),
            // Level 1: u = 0 is the left half.
            c if c == cell_index(1, 0, 0) || c == cell_index(1, 0, 1) => left,
            c if c < pyramid_cells(2) => right,
            _ => unreachable!("two levels"),
        };
        rho / PI
    };
    let mut patches = vec![patch(
        Vec3A::new(-1.0, -1.0, 0.6),
        Vec3A::Y * 2.0,
        Vec3A::X * 2.0,
        0.0,
        1.0,
        0,
    )];
    pyramid_panel(
        &mut patches,
        Vec3A::ZERO,
        1.0,
        [0.5 * (left + right), 0.0],
        2,
        lambert,
    );
    let solution = solve(&patches, 0.0005);
    let (mut halves, mut whole) = (0, 0);
    for leaf in solution.leaves().filter(|l| l.patch == 1) {
        let (lo, hi) = leaf.shape.bounds();
        let ratio = leaf.radiosity[0] / leaf.irradiance[0];
        let expected = if hi.x - lo.x > 0.5 + 1e-4 {
            whole += 1;
            0.5 * (left + right)
        } else {
            halves += 1;
            if hi.x <= 1e-4 {
                left
            } else {
                assert!(lo.x >= -1e-4, "{lo} {hi}");
                right
            }
        };
        assert!(
            (ratio - expected).abs() < 1e-4,
            "leaf {lo}..{hi}: B/E {ratio}, expected {expected}"
        );
    }
    eprintln!("{halves} leaves in a half, {whole} over the whole period");
    assert!(halves >= 8, "{halves}");
    let loaded = Radiosity::from_bytes(&solution.to_bytes()).unwrap();
    assert!(loaded.matches_patches(&patches));
}

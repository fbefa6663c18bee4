//! A far cluster source's internal visibility (its software Z-buffer, Mostefaoui et al.
//! §3) against the closed form: a stack of plates whose lower ones hide the middles of the
//! upper ones.

use glam::Vec3A;
use prism_radiosity::form_factor::point_to_polygon;
use prism_radiosity::{
    ElementShape, InputPatch, NoDirectLight, Radiosity, RadiositySettings, Unoccluded, Visibility,
};

/// Five plates facing down, stacked 0.1 m apart from 10 m up, each 0.2 m wider than the one
/// below: from the floor each shows a ring around the one below it.
const PLATES: usize = 5;

fn plate_height_m(k: usize) -> f32 {
    10.0 + 0.1 * k as f32
}

fn plate_half_m(k: usize) -> f32 {
    0.2 + 0.1 * k as f32
}

fn plate_exitance(k: usize) -> f32 {
    1.0 + k as f32
}

/// The plate's corners, counter-clockwise seen from below (its emitting side).
fn plate_corners(k: usize) -> [Vec3A; 4] {
    let (h, z) = (plate_half_m(k), plate_height_m(k));
    [
        Vec3A::new(-h, -h, z),
        Vec3A::new(-h, h, z),
        Vec3A::new(h, h, z),
        Vec3A::new(h, -h, z),
    ]
}

/// Five receivers 0.15 m wide on the floor, facing up, along x.
fn receiver(j: usize) -> ElementShape {
    let x = -0.4 + 0.2 * j as f32;
    ElementShape::Parallelogram {
        p0: Vec3A::new(x - 0.075, -0.075, 0.0),
        e1: Vec3A::X * 0.15,
        e2: Vec3A::Y * 0.15,
    }
}

fn patches() -> Vec<InputPatch> {
    let mut patches: Vec<InputPatch> = (0..5)
        .map(|j| InputPatch {
            shape: receiver(j),
            reflectance: vec![0.0],
            emission: vec![0.0],
            surface: j as u32,
            directional: None,
        })
        .collect();
    for k in 0..PLATES {
        let c = plate_corners(k);
        patches.push(InputPatch {
            shape: ElementShape::Parallelogram {
                p0: c[0],
                e1: c[1] - c[0],
                e2: c[3] - c[0],
            },
            reflectance: vec![0.0],
            emission: vec![plate_exitance(k)],
            surface: (5 + k) as u32,
            directional: None,
        });
    }
    patches
}

/// Rays blocked by any of the scene's patches (both sides).
struct Patches(Vec<ElementShape>);

impl Visibility for Patches {
    fn visible(&self, from: Vec3A, n_from: Vec3A, to: Vec3A, n_to: Vec3A) -> bool {
        let (a, b) = (from + n_from * 1e-4, to + n_to * 1e-4);
        let d = b - a;
        !self.0.iter().any(|shape| {
            let n = shape.normal();
            let p0 = shape.point(0.0, 0.0);
            let denominator = n.dot(d);
            if denominator.abs() < 1e-12 {
                return false;
            }
            let t = n.dot(p0 - a) / denominator;
            if !(1e-6..1.0 - 1e-6).contains(&t) {
                return false;
            }
            let (u, v) = shape.parameters_of(a + d * t);
            (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)
        })
    }
}

/// E at the receiver's points, exact: each plate's square less the shadow of the one below
/// it (which holds the shadows of those below it), projected from the point onto the
/// plate's plane.
fn exact_irradiance(j: usize) -> f64 {
    let shape = receiver(j);
    let grid = 12;
    let mut sum = 0.0f64;
    for a in 0..grid {
        for b in 0..grid {
            let x = shape.point(
                (a as f32 + 0.5) / grid as f32,
                (b as f32 + 0.5) / grid as f32,
            );
            for k in 0..PLATES {
                let mut f = point_to_polygon(x, Vec3A::Z, &plate_corners(k), -Vec3A::Z);
                if k > 0 {
                    let scale = plate_height_m(k) / plate_height_m(k - 1);
                    let shadow = plate_corners(k - 1).map(|c| x + (c - x) * scale);
                    f -= point_to_polygon(x, Vec3A::Z, &shadow, -Vec3A::Z);
                }
                sum += f64::from(f * plate_exitance(k));
            }
        }
    }
    sum / (grid * grid) as f64
}

fn solved_irradiance(visibility: &dyn Visibility) -> Vec<f64> {
    let patches = patches();
    // A bound loose enough that each receiver links the stack as one cluster.
    let settings = RadiositySettings {
        error_bound_rel: 0.01,
        ..RadiositySettings::default()
    };
    let mut r = Radiosity::new(&patches, 1, settings).unwrap();
    r.iterate(visibility, &NoDirectLight).unwrap();
    let mut power = [0.0f64; 5];
    for leaf in r.leaves().filter(|l| l.patch < 5) {
        power[leaf.patch] += f64::from(leaf.irradiance[0] * leaf.shape.area_m2());
    }
    (0..5)
        .map(|j| power[j] / f64::from(receiver(j).area_m2()))
        .collect()
}

/// Each receiver links the stack as one cluster ten metres away, whose plates hide each
/// other's middles. The cluster's Z-buffer shows each plate's ring; the links read what
/// the rings send within 1 %, with the scene's rays and without any (the Z-buffer alone
/// holds the cluster's own occlusion). Measured: −0.34 … +0.29 %. Sampling the cluster at
/// 16 area-weighted points with rays between them, as near clusters are, read +10.0 …
/// +10.3 % (which points land on hidden middles is chance), and without rays +195 %, every
/// plate counted whole.
#[test]
fn a_far_cluster_shows_only_what_its_plates_leave_in_view() {
    let shapes: Vec<ElementShape> = patches().iter().map(|p| p.shape).collect();
    let traced = solved_irradiance(&Patches(shapes));
    let unoccluded = solved_irradiance(&Unoccluded);
    let mut worst = 0.0f64;
    for j in 0..5 {
        let exact = exact_irradiance(j);
        for (name, solved) in [("traced", traced[j]), ("unoccluded", unoccluded[j])] {
            let error = solved / exact - 1.0;
            eprintln!(
                "receiver {j} ({name}): {solved:.6} against {exact:.6} ({:+.2} %)",
                100.0 * error
            );
            worst = worst.max(error.abs());
        }
    }
    assert!(worst < 0.01, "largest error {:.2} %", 100.0 * worst);
}

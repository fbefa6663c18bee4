//! Thin-lens depth of field against the textbook circle of confusion: a point at depth d,
//! with the lens (focal length f, f-number N) focused at d_f, images to a disk of diameter
//! c = (f/N) · f · |d − d_f| / (d (d_f − f)) on the sensor, i.e. c · W / s pixels for a
//! sensor s wide imaged onto W pixels (e.g. Ray, "Applied Photographic Optics", §3; pbrt-v4
//! §5.2.3, eq. 5.7). A point on the focus plane stays a point.

use glam::{UVec2, Vec2, Vec3A};
use prism_render::{ApertureSpec, Camera, CameraFrame, FocalSpec, ThinLensCamera};

const RES: UVec2 = UVec2::new(1200, 800);
const F_MM: f64 = 50.0;
const N: f64 = 2.0;
const FOCUS_M: f64 = 2.0;
const SENSOR_MM: f64 = 36.0;

fn eye() -> Vec3A {
    Vec3A::new(0.3, 1.5, 4.0)
}

fn camera() -> (ThinLensCamera, Camera) {
    // Looking down world −Z: right = +X, up = +Y, forward = −Z.
    let frame = CameraFrame::look_at(eye(), Vec3A::new(0.3, 1.5, 0.0), Vec3A::Y, RES).unwrap();
    let lens = ThinLensCamera::new(
        frame,
        FocalSpec::FocalLengthMm(F_MM as f32),
        ApertureSpec::FNumber(N as f32),
        FOCUS_M as f32,
        SENSOR_MM as f32,
    )
    .unwrap();
    (lens.clone(), Camera::ThinLens(lens))
}

/// The textbook circle of confusion in pixels.
fn coc_px(depth_m: f64) -> f64 {
    let f = F_MM * 1e-3;
    let c_m = (f / N) * f * (depth_m - FOCUS_M).abs() / (depth_m * (FOCUS_M - f));
    c_m * f64::from(RES.x) / (SENSOR_MM * 1e-3)
}

/// A world point at `depth_m` in front of the lens, `lateral_m` off the axis (right, up).
fn point(depth_m: f32, lateral_m: Vec2) -> Vec3A {
    eye() + Vec3A::new(lateral_m.x, lateral_m.y, -depth_m)
}

/// Lens samples on an n × n grid including the square's edges (which map to the rim).
fn lens_grid(n: u32) -> impl Iterator<Item = Vec2> {
    (0..n).flat_map(move |i| (0..n).map(move |j| Vec2::new(i as f32, j as f32) / (n - 1) as f32))
}

fn distance_to_ray(x: Vec3A, origin: Vec3A, dir: Vec3A) -> f32 {
    (x - origin).cross(dir).length()
}

const CASES: [(f32, [f32; 2]); 4] = [
    (1.0, [0.0, 0.0]),
    (1.0, [0.12, -0.05]),
    (6.0, [0.0, 0.0]),
    (6.0, [0.6, 0.35]),
];

#[test]
fn formula_of_the_camera_matches_the_textbook() {
    let (lens, _) = camera();
    for (d, _) in CASES {
        let px = f64::from(lens.circle_of_confusion_m(d)) * f64::from(RES.x)
            / f64::from(lens.sensor_width_m());
        assert!(
            (px - coc_px(d.into())).abs() < 1e-3 * px,
            "{px} vs {}",
            coc_px(d.into())
        );
    }
}

#[test]
fn out_of_focus_point_images_to_the_circle_of_confusion_through_the_lens() {
    let (lens, camera) = camera();
    for (d, lateral) in CASES {
        let x = point(d, Vec2::from(lateral));
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for u in lens_grid(65) {
            let p = lens
                .project_through_lens(x, u)
                .expect("the image lies on the film");
            lo = lo.min(p);
            hi = hi.max(p);
            // generate_ray from that film point through that lens point passes through x.
            let r = camera.generate_ray(p, u).unwrap().ray;
            assert!(distance_to_ray(x, r.origin, r.direction) < 1e-4, "{d} {u}");
        }
        let expected = coc_px(d.into()) as f32;
        let extent = hi - lo;
        assert!(expected > 10.0, "the test needs a disk several pixels wide");
        for e in [extent.x, extent.y] {
            assert!(
                (e - expected).abs() < 1.0,
                "depth {d}: diameter {e} px vs {expected} px"
            );
        }
    }
}

/// Which pixel centres see `x` through some lens sample: the ray from the pixel centre
/// through the lens sample passes within `tolerance_m` of `x` on the plane at its depth.
fn pixels_seeing(
    camera: &Camera,
    x: Vec3A,
    lens_n: u32,
    tolerance_m: f32,
    half_window_px: i32,
) -> Vec<Vec2> {
    let centre = camera.project(x).unwrap();
    let half = half_window_px;
    let forward = Vec3A::NEG_Z;
    let depth = (x - eye()).dot(forward);
    let mut seen = Vec::new();
    for j in -half..=half {
        for i in -half..=half {
            let pixel = (centre.floor() + Vec2::new(i as f32, j as f32)).max(Vec2::ZERO);
            let p = pixel + 0.5;
            let hit = (0..lens_n).any(|a| {
                (0..lens_n).any(|b| {
                    let u = (Vec2::new(a as f32, b as f32) + 0.5) / lens_n as f32;
                    let r = camera.generate_ray(p, u).unwrap().ray;
                    let t = (depth - (r.origin - eye()).dot(forward)) / r.direction.dot(forward);
                    (r.at(t) - x).length() < tolerance_m
                })
            });
            if hit {
                seen.push(p);
            }
        }
    }
    seen
}

#[test]
fn traced_pixels_seeing_an_out_of_focus_point_fill_the_circle_of_confusion() {
    let (lens, camera) = camera();
    let lens_n = 96;
    for (d, lateral) in CASES {
        let x = point(d, Vec2::from(lateral));
        // On the plane at depth d, rays of one pixel are spread by a lens step δL times
        // |1 − d/d_f|; a concentric-grid cell is at most ≈ 2.6 A / n across, so every
        // pixel whose centre sees x has a ray within half that of x.
        let step = 1.3 * lens.aperture_radius_m() / lens_n as f32;
        let tolerance = step * (1.0 - d / FOCUS_M as f32).abs();
        let window = (0.5 * coc_px(d.into())).ceil() as i32 + 2;
        let seen = pixels_seeing(&camera, x, lens_n, tolerance, window);
        let measured = 2.0 * (seen.len() as f64 / std::f64::consts::PI).sqrt();
        let expected = coc_px(d.into());
        assert!(
            (measured - expected).abs() < 1.0,
            "depth {d}, lateral {lateral:?}: {} pixels ⇒ diameter {measured:.2} px vs {expected:.2} px",
            seen.len()
        );
        eprintln!("depth {d}: measured {measured:.3} px, expected {expected:.3} px");
        // The disk is centred on the chief ray's image.
        let centroid = seen.iter().copied().sum::<Vec2>() / seen.len() as f32;
        assert!((centroid - camera.project(x).unwrap()).length() < 1.0);
    }
}

#[test]
fn in_focus_point_stays_within_one_pixel() {
    let (lens, camera) = camera();
    for lateral in [[0.0f32, 0.0], [0.3, -0.2], [-0.5, 0.4]] {
        let x = point(FOCUS_M as f32, Vec2::from(lateral));
        let chief = camera.project(x).unwrap();
        for u in lens_grid(33) {
            let p = lens.project_through_lens(x, u).unwrap();
            assert!((p - chief).length() < 1e-2, "{lateral:?}: {p} vs {chief}");
        }
        // Traced: pixel centres whose rays pass within half a pixel's footprint of x.
        let footprint_m =
            FOCUS_M as f32 / (lens.image_distance_m() * RES.x as f32 / lens.sensor_width_m());
        let seen = pixels_seeing(&camera, x, 12, 0.5 * footprint_m * 2f32.sqrt(), 3);
        assert!(!seen.is_empty());
        for p in &seen {
            assert!((*p - chief).length() <= 1.0, "{lateral:?}: {p} vs {chief}");
        }
    }
}

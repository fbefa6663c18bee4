//! Camera models against their projection formulas (Kannala & Brandt 2006 for the fisheyes),
//! field-of-view edges, parallel and spherical mappings, `project ∘ generate_ray` round
//! trips, ray differentials and parameter validation.

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{UVec2, Vec2, Vec3A};
use prism_render::{
    ApertureSpec, Camera, CameraFrame, FisheyeCamera, FisheyeCoverage, FisheyeProjection,
    FocalSpec, OrthographicCamera, PinholeCamera, PixelSampler, SphericalCamera, ThinLensCamera,
};

const RES: UVec2 = UVec2::new(400, 300);

/// A camera pose away from the origin and tilted, so the transforms are exercised.
fn frame() -> CameraFrame {
    CameraFrame::look_at(
        Vec3A::new(1.0, 2.0, 3.0),
        Vec3A::new(-2.0, 1.5, -1.0),
        Vec3A::Y,
        RES,
    )
    .unwrap()
}

/// World-space camera axes (right, up, forward).
fn axes(f: &CameraFrame) -> (Vec3A, Vec3A, Vec3A) {
    let t = &f.camera_to_world;
    (
        t.vector(Vec3A::X).normalize(),
        t.vector(Vec3A::Y).normalize(),
        t.vector(Vec3A::NEG_Z).normalize(),
    )
}

/// Angle between unit vectors, accurate near 0 and π.
fn angle(a: Vec3A, b: Vec3A) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

fn grid(n: u32, m: u32) -> impl Iterator<Item = Vec2> {
    (0..=n).flat_map(move |i| {
        (0..=m).map(move |j| {
            // Film corners inclusive, nudged inside [0, W) × [0, H).
            let s = RES.as_vec2() - 2e-3;
            Vec2::splat(1e-3) + Vec2::new(i as f32 / n as f32 * s.x, j as f32 / m as f32 * s.y)
        })
    })
}

#[test]
fn fisheye_rays_follow_their_projection_formulas() {
    let fovs_deg = |p: FisheyeProjection| match p {
        FisheyeProjection::Orthographic => vec![60.0, 150.0, 180.0],
        FisheyeProjection::Stereographic => vec![60.0, 180.0, 300.0],
        _ => vec![60.0, 180.0, 270.0, 360.0],
    };
    for projection in FisheyeProjection::ALL {
        for coverage in [FisheyeCoverage::Circular, FisheyeCoverage::Cropped] {
            for fov_deg in fovs_deg(projection) {
                let fov = (fov_deg as f32).to_radians();
                let cam = FisheyeCamera::new(frame(), projection, coverage, fov).unwrap();
                let camera = Camera::Fisheye(cam.clone());
                let size = RES.as_vec2();
                let radius = match coverage {
                    FisheyeCoverage::Circular => 0.5 * size.min_element(),
                    FisheyeCoverage::Cropped => 0.5 * size.length(),
                };
                // f from the formula r(θ_max) = R, written out per projection.
                let half = 0.5 * fov;
                let f = match projection {
                    FisheyeProjection::Equidistant => radius / half,
                    FisheyeProjection::Equisolid => radius / (2.0 * (half / 2.0).sin()),
                    FisheyeProjection::Orthographic => radius / half.sin(),
                    FisheyeProjection::Stereographic => radius / (2.0 * (half / 2.0).tan()),
                };
                let (right, up, forward) = axes(camera.frame());
                let mut checked = 0;
                for p in grid(40, 30).chain([0.5 * size, 0.5 * size + Vec2::new(0.3, -0.2)]) {
                    let offset = p - 0.5 * size;
                    let r = offset.length();
                    let ray = camera.generate_ray(p, Vec2::splat(0.5));
                    if r > radius * 1.0001 {
                        assert!(
                            ray.is_none(),
                            "{projection:?} {coverage:?}: ray beyond circle"
                        );
                        continue;
                    }
                    if r > radius * 0.9999 {
                        continue; // on the circle edge: either answer is fine
                    }
                    let d = ray
                        .expect("film point inside the image circle has a ray")
                        .ray
                        .direction;
                    let theta = angle(d, forward);
                    let expected_r = match projection {
                        FisheyeProjection::Equidistant => f * theta,
                        FisheyeProjection::Equisolid => 2.0 * f * (theta / 2.0).sin(),
                        FisheyeProjection::Orthographic => f * theta.sin(),
                        FisheyeProjection::Stereographic => 2.0 * f * (theta / 2.0).tan(),
                    };
                    // Near θ = 180° (360° lenses) the angle is ill-conditioned in f32.
                    let tol = if theta > 3.0 { 0.05 } else { 0.01 };
                    assert!(
                        (r - expected_r).abs() < tol,
                        "{projection:?} {coverage:?} fov {fov_deg}°: r {r} vs {expected_r}"
                    );
                    // Azimuth: the ray leans the way the film point lies (y down on film).
                    if r > 1.0 && theta < 3.0 {
                        let lean = Vec2::new(d.dot(right), d.dot(up)).normalize();
                        let film_dir = Vec2::new(offset.x, -offset.y) / r;
                        assert!((lean - film_dir).length() < 1e-3, "{lean} vs {film_dir}");
                    }
                    checked += 1;
                }
                assert!(checked > 500, "{checked}");
            }
        }
    }
}

#[test]
fn circular_fisheye_has_no_ray_outside_its_image_circle_and_cropped_covers_the_film() {
    let fov = PI;
    let circular = Camera::Fisheye(
        FisheyeCamera::new(
            frame(),
            FisheyeProjection::Equidistant,
            FisheyeCoverage::Circular,
            fov,
        )
        .unwrap(),
    );
    let cropped = Camera::Fisheye(
        FisheyeCamera::new(
            frame(),
            FisheyeProjection::Equidistant,
            FisheyeCoverage::Cropped,
            fov,
        )
        .unwrap(),
    );
    assert!(circular
        .generate_ray(Vec2::new(1.0, 1.0), Vec2::ZERO)
        .is_none());
    assert!(circular
        .generate_ray(Vec2::new(200.0, 1.0), Vec2::ZERO)
        .is_some());
    for p in grid(20, 20) {
        assert!(cropped.generate_ray(p, Vec2::ZERO).is_some());
    }
    // The cropped lens's corners see the edge of its field of view.
    let (_, _, forward) = axes(cropped.frame());
    let corner = cropped
        .generate_ray(Vec2::ZERO, Vec2::ZERO)
        .unwrap()
        .ray
        .direction;
    assert!((angle(corner, forward) - 0.5 * fov).abs() < 1e-3);
}

#[test]
fn fisheye_fov_limits_are_validated_per_projection() {
    let deg = |d: f32| d.to_radians();
    let make = |p, fov| FisheyeCamera::new(frame(), p, FisheyeCoverage::Circular, fov);
    use FisheyeProjection::*;
    // The largest accepted field of each projection is kept as given.
    let accepted = |p, fov| {
        let camera = make(p, fov).unwrap_or_else(|e| panic!("{p:?} at {fov} rad: {e}"));
        assert_eq!((camera.projection(), camera.fov_rad()), (p, fov));
    };
    accepted(Orthographic, PI);
    assert!(make(Orthographic, deg(181.0)).is_err());
    accepted(Stereographic, deg(359.0));
    assert!(make(Stereographic, TAU).is_err());
    for p in [Equidistant, Equisolid] {
        accepted(p, TAU);
        assert!(make(p, deg(361.0)).is_err());
    }
    for p in FisheyeProjection::ALL {
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = make(p, bad).unwrap_err();
            assert_eq!(e.parameter, "fov_rad");
            assert!(e.to_string().contains("fov_rad"), "{e}");
        }
    }
    let e = make(Orthographic, deg(200.0)).unwrap_err().to_string();
    assert!(e.contains("180") && e.contains("orthographic"), "{e}");
}

#[test]
fn pinhole_fov_spans_the_film_width_and_height_follows_the_aspect() {
    let fov = 70f32.to_radians();
    let camera = Camera::Pinhole(PinholeCamera::new(frame(), fov).unwrap());
    let (_, _, forward) = axes(camera.frame());
    let size = RES.as_vec2();
    let dir = |p: Vec2| camera.generate_ray(p, Vec2::ZERO).unwrap().ray.direction;
    let left = dir(Vec2::new(0.0, 0.5 * size.y));
    let right = dir(Vec2::new(size.x, 0.5 * size.y));
    assert!((angle(left, right) - fov).abs() < 1e-5);
    assert!((angle(left, forward) - 0.5 * fov).abs() < 1e-5);
    let top = dir(Vec2::new(0.5 * size.x, 0.0));
    let vfov = 2.0 * ((size.y / size.x) * (0.5 * fov).tan()).atan();
    assert!((angle(top, forward) - 0.5 * vfov).abs() < 1e-5);
    // Top of the film looks up.
    let (_, up, _) = axes(camera.frame());
    assert!(top.dot(up) > 0.0);
    let centre = camera.generate_ray(0.5 * size, Vec2::ZERO).unwrap().ray;
    assert!(angle(centre.direction, forward) < 1e-5);
    assert!((centre.origin - Vec3A::new(1.0, 2.0, 3.0)).length() < 1e-5);
    for bad in [0.0, PI, -0.1, f32::NAN] {
        assert_eq!(
            PinholeCamera::new(frame(), bad).unwrap_err().parameter,
            "fov_rad"
        );
    }
}

#[test]
fn orthographic_rays_are_parallel_and_span_the_film_width() {
    let camera = Camera::Orthographic(OrthographicCamera::new(frame(), 2.5).unwrap());
    let (right, up, forward) = axes(camera.frame());
    for p in grid(10, 10) {
        let r = camera.generate_ray(p, Vec2::ZERO).unwrap();
        assert!((r.ray.direction - forward).length() < 1e-6);
        assert!((r.rx_direction - forward).length() < 1e-6);
        // Differentials step one pixel pitch sideways.
        assert!(((r.rx_origin - r.ray.origin).dot(right) - 2.5 / 400.0).abs() < 1e-5);
        assert!(((r.ry_origin - r.ray.origin).dot(up) + 2.5 / 400.0).abs() < 1e-5);
    }
    let o = |x: f32| {
        camera
            .generate_ray(Vec2::new(x, 150.0), Vec2::ZERO)
            .unwrap()
            .ray
            .origin
    };
    assert!(((o(400.0) - o(0.0)).dot(right) - 2.5).abs() < 1e-5);
    assert!(OrthographicCamera::new(frame(), 0.0).is_err());
}

#[test]
fn spherical_camera_maps_film_to_azimuth_and_polar_angle_and_covers_the_sphere() {
    let f =
        CameraFrame::look_at(Vec3A::ZERO, Vec3A::NEG_Z, Vec3A::Y, UVec2::new(360, 180)).unwrap();
    let cam = SphericalCamera::new(f).unwrap();
    let camera = Camera::Spherical(cam.clone());
    for i in 0..=36 {
        for j in 0..=18 {
            let p = Vec2::new(i as f32 * 10.0, j as f32 * 10.0).min(Vec2::new(359.999, 179.999));
            let phi = p.x / 360.0 * TAU - PI;
            let theta = p.y / 180.0 * PI;
            let d = camera.generate_ray(p, Vec2::ZERO).unwrap().ray.direction;
            let expected = Vec3A::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            assert!((d - expected).length() < 1e-5, "{p}: {d} vs {expected}");
        }
    }
    // Landmarks: centre forward, top up, bottom down, quarter width left.
    let d = |x: f32, y: f32| {
        camera
            .generate_ray(Vec2::new(x, y), Vec2::ZERO)
            .unwrap()
            .ray
            .direction
    };
    assert!((d(180.0, 90.0) - Vec3A::NEG_Z).length() < 1e-6);
    assert!((d(180.0, 0.0) - Vec3A::Y).length() < 1e-6);
    assert!((d(90.0, 90.0) - Vec3A::NEG_X).length() < 1e-6);
    // Every direction on the sphere projects onto the film and comes back.
    let sampler = PixelSampler::new(3);
    for i in 0..5000 {
        let mut s = sampler.stream(UVec2::ZERO, i);
        let (u, v) = (s.get_1d(), s.get_1d());
        let z = 1.0 - 2.0 * u;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let dir = Vec3A::new(r * (TAU * v).cos(), z, r * (TAU * v).sin());
        let p = camera
            .project(dir * 5.0)
            .expect("every direction is on the film");
        let back = camera.generate_ray(p, Vec2::ZERO).unwrap().ray.direction;
        assert!((back - dir).length() < 1e-4, "{dir} → {p} → {back}");
    }
    // Solid angle: Σ over pixels of sin θ Δθ Δφ = 4π.
    let (w, h) = (360, 180);
    let mut omega = 0.0f64;
    for j in 0..h {
        let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
        omega += w as f64
            * theta.sin()
            * (std::f64::consts::PI / h as f64)
            * (std::f64::consts::TAU / w as f64);
    }
    assert!((omega - 4.0 * std::f64::consts::PI).abs() < 1e-3);
}

fn all_cameras() -> Vec<Camera> {
    let mut cams = vec![
        Camera::Pinhole(PinholeCamera::new(frame(), 1.2).unwrap()),
        Camera::ThinLens(
            ThinLensCamera::new(
                frame(),
                FocalSpec::FocalLengthMm(35.0),
                ApertureSpec::FNumber(2.8),
                2.0,
                36.0,
            )
            .unwrap(),
        ),
        Camera::Orthographic(OrthographicCamera::new(frame(), 3.0).unwrap()),
        Camera::Spherical(SphericalCamera::new(frame()).unwrap()),
    ];
    for p in FisheyeProjection::ALL {
        for c in [FisheyeCoverage::Circular, FisheyeCoverage::Cropped] {
            let fov = if p == FisheyeProjection::Orthographic {
                PI
            } else {
                1.5 * PI
            };
            cams.push(Camera::Fisheye(
                FisheyeCamera::new(frame(), p, c, fov).unwrap(),
            ));
        }
    }
    cams
}

#[test]
fn project_inverts_generate_ray_for_every_camera() {
    for camera in all_cameras() {
        let mut n = 0;
        for p in grid(23, 17) {
            // Lens centre: the thin lens's `project` follows the chief ray.
            let Some(r) = camera.generate_ray(p, Vec2::splat(0.5)) else {
                continue;
            };
            for t in [0.5f32, 3.0, 40.0] {
                let q = camera
                    .project(r.ray.at(t))
                    .unwrap_or_else(|| panic!("{camera:?} {p} {t}"));
                if matches!(camera, Camera::Spherical(_)) {
                    // Near the poles azimuth (film x) is ill-conditioned: compare directions.
                    let back = camera.generate_ray(q, Vec2::splat(0.5)).unwrap().ray;
                    assert!(
                        (back.direction - r.ray.direction).length() < 1e-4,
                        "{p} → {q}"
                    );
                } else {
                    assert!((q - p).length() < 2e-3 * (1.0 + t), "{camera:?}: {p} → {q}");
                }
            }
            n += 1;
        }
        assert!(n > 100);
    }
}

#[test]
fn project_rejects_points_behind_or_outside() {
    // Outside a 90° pinhole's field, and far off the film of a narrow orthographic view.
    let pin = Camera::Pinhole(PinholeCamera::new(frame(), FRAC_PI_2).unwrap());
    let (right, _, forward) = axes(pin.frame());
    let eye = Vec3A::new(1.0, 2.0, 3.0);
    assert!(pin.project(eye + forward + 1.01 * right).is_none());
    assert!(pin.project(eye + forward + 0.99 * right).is_some());
    let ortho = Camera::Orthographic(OrthographicCamera::new(frame(), 1.0).unwrap());
    assert!(ortho.project(eye + forward + 0.51 * right).is_none());
    assert!(ortho.project(eye + forward + 0.49 * right).is_some());
    let f = frame();
    let (_, _, forward) = axes(&f);
    let behind = Vec3A::new(1.0, 2.0, 3.0) - forward;
    for camera in all_cameras() {
        match &camera {
            Camera::Spherical(_) => assert!(camera.project(behind).is_some()),
            // Straight behind: outside every fov below 360° (and ambiguous at 360°).
            _ => assert!(camera.project(behind).is_none(), "{camera:?}"),
        }
    }
}

#[test]
fn differentials_are_the_rays_one_pixel_over() {
    for camera in all_cameras() {
        for p in grid(9, 7) {
            let lens = Vec2::new(0.3, 0.8);
            let Some(r) = camera.generate_ray(p, lens) else {
                continue;
            };
            if let Some(rx) = camera.generate_ray(p + Vec2::X, lens) {
                assert!(
                    (r.rx_direction - rx.ray.direction).length() < 1e-5,
                    "{camera:?}"
                );
                assert!((r.rx_origin - rx.ray.origin).length() < 1e-5);
            }
            if let Some(ry) = camera.generate_ray(p + Vec2::Y, lens) {
                assert!(
                    (r.ry_direction - ry.ray.direction).length() < 1e-5,
                    "{camera:?}"
                );
                assert!((r.ry_origin - ry.ray.origin).length() < 1e-5);
            }
            // Never degenerate where a neighbour exists on either side (except along the
            // spherical camera's top row, the pole, where azimuth changes nothing).
            assert!(
                (r.rx_direction - r.ray.direction).length() > 0.0
                    || matches!(camera, Camera::Orthographic(_))
                    || (matches!(camera, Camera::Spherical(_)) && p.y < 0.01),
                "{camera:?} {p}"
            );
        }
    }
    // At a circular fisheye's rim the outer neighbour is missing: reflected from inside.
    let cam = Camera::Fisheye(
        FisheyeCamera::new(
            frame(),
            FisheyeProjection::Equidistant,
            FisheyeCoverage::Circular,
            PI,
        )
        .unwrap(),
    );
    let rim = Vec2::new(349.8, 150.0);
    let r = cam.generate_ray(rim, Vec2::ZERO).unwrap();
    assert!(cam.generate_ray(rim + Vec2::X, Vec2::ZERO).is_none());
    let inner = cam
        .generate_ray(rim - Vec2::X, Vec2::ZERO)
        .unwrap()
        .ray
        .direction;
    let step_out = angle(r.ray.direction, r.rx_direction);
    let step_in = angle(r.ray.direction, inner);
    assert!((step_out - step_in).abs() < 1e-3 * step_in.max(1e-3) + 1e-5);
    assert!(step_out > 0.0);
}

#[test]
fn constructors_reject_bad_parameters_with_their_names() {
    let e = CameraFrame::look_at(Vec3A::ZERO, Vec3A::ZERO, Vec3A::Y, RES).unwrap_err();
    assert!(e.to_string().contains("eye_m"), "{e}");
    let e = CameraFrame::look_at(Vec3A::ZERO, Vec3A::Y, Vec3A::Y, RES).unwrap_err();
    assert!(e.to_string().contains("up"), "{e}");
    let e = CameraFrame::look_at(Vec3A::ZERO, Vec3A::Z, Vec3A::Y, UVec2::new(0, 10)).unwrap_err();
    assert_eq!(e.parameter, "resolution");
    let thin = |focal, aperture, focus, sensor| {
        ThinLensCamera::new(frame(), focal, aperture, focus, sensor).map(|_| ())
    };
    let mm50 = FocalSpec::FocalLengthMm(50.0);
    let f2 = ApertureSpec::FNumber(2.0);
    // Valid parameters are kept, in metres: f/2 at 50 mm is a 12.5 mm aperture radius.
    let valid = ThinLensCamera::new(frame(), mm50, f2, 2.0, 36.0).unwrap();
    assert!((valid.focal_length_m() - 0.05).abs() < 1e-7);
    assert!((valid.aperture_radius_m() - 0.0125).abs() < 1e-7);
    assert_eq!(valid.focus_distance_m(), 2.0);
    assert!((valid.sensor_width_m() - 0.036).abs() < 1e-7);
    assert_eq!(
        thin(mm50, f2, 0.04, 36.0).unwrap_err().parameter,
        "focus_distance_m"
    );
    assert_eq!(
        thin(mm50, f2, 2.0, 0.0).unwrap_err().parameter,
        "sensor_width_mm"
    );
    assert_eq!(
        thin(FocalSpec::FocalLengthMm(-1.0), f2, 2.0, 36.0)
            .unwrap_err()
            .parameter,
        "focal_length_mm"
    );
    assert_eq!(
        thin(FocalSpec::FovRad(PI), f2, 2.0, 36.0)
            .unwrap_err()
            .parameter,
        "fov_rad"
    );
    assert_eq!(
        thin(mm50, ApertureSpec::FNumber(0.0), 2.0, 36.0)
            .unwrap_err()
            .parameter,
        "f_number"
    );
    assert_eq!(
        thin(mm50, ApertureSpec::RadiusM(-0.01), 2.0, 36.0)
            .unwrap_err()
            .parameter,
        "aperture_radius_m"
    );
    // A zero aperture is a pinhole, not an error.
    let pinhole = ThinLensCamera::new(frame(), mm50, ApertureSpec::RadiusM(0.0), 2.0, 36.0)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(pinhole.aperture_radius_m(), 0.0);
}

#[test]
fn thin_lens_focal_length_and_fov_specs_agree() {
    // 50 mm on 36 mm: fov at infinity focus 2 atan(18/50) ≈ 39.6°.
    let fov = 2.0 * (18.0f32 / 50.0).atan();
    let a = ThinLensCamera::new(
        frame(),
        FocalSpec::FocalLengthMm(50.0),
        ApertureSpec::FNumber(4.0),
        3.0,
        36.0,
    )
    .unwrap();
    let b = ThinLensCamera::new(
        frame(),
        FocalSpec::FovRad(fov),
        ApertureSpec::FNumber(4.0),
        3.0,
        36.0,
    )
    .unwrap();
    assert!((a.focal_length_m() - 0.05).abs() < 1e-7);
    assert!((b.focal_length_m() - 0.05).abs() < 1e-6);
    assert!((a.aperture_radius_m() - 0.05 / 8.0).abs() < 1e-7);
    // Focused at 3 m the sensor sits at v = f d_f / (d_f − f) and the fov narrows.
    let v = 0.05 * 3.0 / (3.0 - 0.05);
    assert!((a.image_distance_m() - v).abs() < 1e-7);
    assert!((a.fov_rad() - 2.0 * (0.018 / v).atan()).abs() < 1e-6);
    assert!(a.fov_rad() < fov);
    // A zero aperture is a pinhole with that fov.
    let pin = ThinLensCamera::new(
        frame(),
        FocalSpec::FocalLengthMm(50.0),
        ApertureSpec::RadiusM(0.0),
        3.0,
        36.0,
    )
    .unwrap();
    let pinhole = PinholeCamera::new(frame(), pin.fov_rad()).unwrap();
    for p in grid(5, 5) {
        let a = Camera::ThinLens(pin.clone())
            .generate_ray(p, Vec2::new(0.9, 0.1))
            .unwrap()
            .ray;
        let b = Camera::Pinhole(pinhole.clone())
            .generate_ray(p, Vec2::ZERO)
            .unwrap()
            .ray;
        assert!((a.direction - b.direction).length() < 1e-5);
        assert!((a.origin - b.origin).length() < 1e-6);
    }
    let _ = FRAC_PI_2;
}

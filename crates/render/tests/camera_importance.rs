//! Camera importance for light tracing and BDPT (pbrt-v3 §16.1.1 "Sampling cameras";
//! pbrt-v4 `PerspectiveCamera::We`, `PDF_We`, `SampleWi`; Veach 1997 ch. 10):
//!
//! - normalisation: ∫_lens ∫ W_e |cos θ| dω dA = 1 by deterministic quadrature over the
//!   sphere of directions (and the aperture disk), not through the code's own pdf;
//! - consistency: a `generate_ray` ray's importance names its film point, and `pdf_we`
//!   obeys pdf_pos = 1/A_lens, pdf_dir = W_e |cos θ| · A_lens · A_imp/(W H) (A_imp =
//!   `importance_area_px2`, the film area with rays), which follows from the film point
//!   being uniform over W × H while W_e spreads unit importance over A_imp;
//! - `pdf_we`'s pdf_dir is the density of `generate_ray`'s directions (χ²);
//! - `sample_wi`: point-like cameras connect exactly to the camera position; the thin lens's
//!   connection directions follow pdf_per_sr (χ² against the aperture's solid angle,
//!   computed here from the lens geometry);
//! - `project_with_jacobian` against central differences of `project`, every camera;
//! - orthographic and spherical cameras refuse importance.

use std::f64::consts::PI;

use glam::{DVec3, UVec2, Vec2, Vec3A};
use prism_geometry::Ray;
use prism_render::camera::{
    ApertureSpec, Camera, CameraFrame, FisheyeCamera, FisheyeCoverage, FisheyeProjection,
    FocalSpec, OrthographicCamera, PinholeCamera, SphericalCamera, ThinLensCamera,
};
use prism_testkit::chi2::{chi2_test_adaptive, sidak, Chi2Config, SplitMix64};

const RES: UVec2 = UVec2::new(400, 300);

fn eye() -> Vec3A {
    Vec3A::new(1.0, 2.0, 3.0)
}

/// A pose away from the origin and tilted, so the transforms are exercised.
fn frame() -> CameraFrame {
    CameraFrame::look_at(eye(), Vec3A::new(-2.0, 1.5, -1.0), Vec3A::Y, RES).unwrap()
}

/// World-space camera axes (right, up, forward), in f64.
fn axes(camera: &Camera) -> [DVec3; 3] {
    let t = &camera.frame().camera_to_world;
    [Vec3A::X, Vec3A::Y, Vec3A::NEG_Z].map(|v| t.vector(v).normalize().as_dvec3())
}

/// Thin lens with a large aperture (f/0.58) focused at 1.5 m.
fn thin_lens() -> ThinLensCamera {
    ThinLensCamera::new(
        frame(),
        FocalSpec::FocalLengthMm(35.0),
        ApertureSpec::RadiusM(0.03),
        1.5,
        36.0,
    )
    .unwrap()
}

/// The fisheyes under test: every projection with both coverages; the equidistant one
/// sees 270° (beyond 180°).
fn fisheyes() -> Vec<(String, FisheyeCamera)> {
    let mut out = Vec::new();
    for projection in FisheyeProjection::ALL {
        let fov_deg: f32 = match projection {
            FisheyeProjection::Equidistant => 270.0,
            FisheyeProjection::Equisolid => 180.0,
            FisheyeProjection::Orthographic => 170.0,
            FisheyeProjection::Stereographic => 120.0,
        };
        for coverage in [FisheyeCoverage::Circular, FisheyeCoverage::Cropped] {
            let cam =
                FisheyeCamera::new(frame(), projection, coverage, fov_deg.to_radians()).unwrap();
            out.push((
                format!("fisheye {projection:?} {coverage:?} {fov_deg}°"),
                cam,
            ));
        }
    }
    out
}

/// Every camera with importance: name, camera, largest θ (rad) with importance.
fn cameras_with_importance() -> Vec<(String, Camera, f64)> {
    let mut out = vec![
        (
            "pinhole 70°".to_owned(),
            Camera::Pinhole(PinholeCamera::new(frame(), 70f32.to_radians()).unwrap()),
            0.5 * PI,
        ),
        (
            "thin lens f/0.58".to_owned(),
            Camera::ThinLens(thin_lens()),
            0.5 * PI,
        ),
    ];
    for (name, cam) in fisheyes() {
        let theta_max = (0.5 * f64::from(cam.fov_rad()) + 0.02).min(PI);
        out.push((name, Camera::Fisheye(cam), theta_max));
    }
    out
}

/// The direction at (θ, φ) about the camera's forward axis, world space.
fn direction(axes: &[DVec3; 3], theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    st * cp * axes[0] + st * sp * axes[1] + ct * axes[2]
}

/// ∫ g(θ, φ) dω over θ ∈ [0, θ_max], φ ∈ [0, 2π): midpoint rule on n × 2n cells with the
/// exact ∫ sin θ dθ of each, a cell split in four (up to `depth` times) while the nine
/// values of its corners, edge midpoints and centre mix zero and non-zero (the film's
/// outline crosses it), as `prism_testkit::chi2`'s adaptive bins.
fn sphere_integral(g: &impl Fn(f64, f64) -> f64, theta_max: f64, n: usize, depth: u32) -> f64 {
    fn cell(g: &impl Fn(f64, f64) -> f64, t0: f64, p0: f64, dt: f64, dp: f64, depth: u32) -> f64 {
        let centre = g(t0 + 0.5 * dt, p0 + 0.5 * dp);
        let value = || centre * (t0.cos() - (t0 + dt).cos()) * dp;
        if depth == 0 {
            return value();
        }
        let mut zero = centre == 0.0;
        let mut nonzero = centre != 0.0;
        for a in [0.0, 0.5, 1.0] {
            for b in [0.0, 0.5, 1.0] {
                let v = g(t0 + a * dt, p0 + b * dp);
                zero |= v == 0.0;
                nonzero |= v != 0.0;
            }
        }
        if !(zero && nonzero) {
            return value();
        }
        let (ht, hp) = (0.5 * dt, 0.5 * dp);
        [(0.0, 0.0), (ht, 0.0), (0.0, hp), (ht, hp)]
            .iter()
            .map(|&(a, b)| cell(g, t0 + a, p0 + b, ht, hp, depth - 1))
            .sum()
    }
    let (dt, dp) = (theta_max / n as f64, PI / n as f64);
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..2 * n {
            sum += cell(g, i as f64 * dt, j as f64 * dp, dt, dp, depth);
        }
    }
    sum
}

/// ∫ W_e(p, ω) |cos θ| dω for a ray origin `p` (world).
fn directional_integral(camera: &Camera, p: Vec3A, theta_max: f64, n: usize) -> f64 {
    let axes = axes(camera);
    let g = |theta: f64, phi: f64| {
        let w = direction(&axes, theta, phi).as_vec3a();
        camera
            .importance(&Ray::infinite(p, w))
            .map_or(0.0, |i| f64::from(i.importance) * theta.cos().abs())
    };
    sphere_integral(&g, theta_max, n, 6)
}

/// ∫_lens ∫ W_e |cos θ| dω dA of `camera` (the lens only for the thin lens).
fn importance_integral(camera: &Camera, theta_max: f64) -> f64 {
    let Camera::ThinLens(lens) = camera else {
        return directional_integral(camera, eye(), theta_max, 180);
    };
    // The aperture disk by the midpoint rule in (r², φ) (equal-area cells), each lens
    // point's directional integral weighted by its cell's area.
    let (rings, sectors) = (3, 4);
    let r = f64::from(lens.aperture_radius_m());
    let cell_area = PI * r * r / f64::from(rings * sectors);
    let a = axes(camera);
    let mut sum = 0.0;
    for i in 0..rings {
        for j in 0..sectors {
            let rho = r * ((f64::from(i) + 0.5) / f64::from(rings)).sqrt();
            let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(sectors);
            let p = eye().as_dvec3() + rho * (phi.cos() * a[0] + phi.sin() * a[1]);
            sum += cell_area * directional_integral(camera, p.as_vec3a(), theta_max, 90);
        }
    }
    sum
}

fn check_importance_integral(perspective: bool) {
    for (name, camera, theta_max) in cameras_with_importance() {
        if perspective_focal_px(&camera).is_some() != perspective {
            continue;
        }
        let integral = importance_integral(&camera, theta_max);
        println!("{name}: ∫ W_e |cos θ| dω dA = {integral:.6}");
        assert!((integral - 1.0).abs() < 1e-3, "{name}: {integral}");
    }
}

#[test]
fn importance_integrates_to_one_pinhole_and_thin_lens() {
    check_importance_integral(true);
}

#[test]
fn importance_integrates_to_one_fisheyes() {
    check_importance_integral(false);
}

/// A_lens: the aperture area for the thin lens, 1 for point-like cameras.
fn lens_area_m2(camera: &Camera) -> f64 {
    if let Camera::ThinLens(lens) = camera {
        f64::from(lens.lens_area_m2())
    } else {
        1.0
    }
}

#[test]
fn generated_rays_carry_their_film_point_and_pdf_we_follows_from_importance() {
    let film_area = f64::from(RES.x * RES.y);
    for (name, camera, _) in cameras_with_importance() {
        let forward = axes(&camera)[2];
        let a_lens = lens_area_m2(&camera);
        let a_imp = f64::from(camera.importance_area_px2());
        let mut rng = SplitMix64(7);
        let (mut checked, mut worst_px, mut worst_rel) = (0, 0.0f32, 0.0f64);
        for _ in 0..4000 {
            let film = Vec2::new(rng.next_f32(), rng.next_f32()) * RES.as_vec2();
            let lens = Vec2::new(rng.next_f32(), rng.next_f32());
            let Some(ray) = camera.generate_ray_only(film, lens) else {
                continue;
            };
            let imp = camera
                .importance(&ray)
                .unwrap_or_else(|| panic!("{name}: no importance for the ray of {film}"));
            let (pdf_pos, pdf_dir) = camera.pdf_we(&ray).expect("pdf_we where importance is");
            worst_px = worst_px.max((imp.film_point_px - film).length());
            // pdf_pos = 1/A_lens; pdf_dir = W_e |cos θ| A_lens · A_imp/(W H).
            let cos = ray.direction.as_dvec3().dot(forward).abs();
            let expected_dir = f64::from(imp.importance) * cos * a_lens * a_imp / film_area;
            // f32 round-off of cos θ is relative 1e-7/|cos θ| (W_e ∝ 1/|cos θ| past 90°).
            let rel_dir = (f64::from(pdf_dir) / expected_dir - 1.0).abs() * cos / (cos + 1e-2);
            let rel_pos = (f64::from(pdf_pos) * a_lens - 1.0).abs();
            worst_rel = worst_rel.max(rel_dir).max(rel_pos);
            checked += 1;
        }
        println!(
            "{name}: {checked} rays, film point within {worst_px:.2e} px, pdf_we relation \
             within {worst_rel:.2e}"
        );
        assert!(checked > 2000, "{name}: {checked}");
        assert!(worst_px < 1e-3, "{name}: film point off by {worst_px} px");
        assert!(worst_rel < 1e-4, "{name}: pdf_we off by {worst_rel}");
    }
}

/// Lens-to-film distance in pixels of the perspective cameras.
fn perspective_focal_px(camera: &Camera) -> Option<f64> {
    match camera {
        Camera::Pinhole(p) => Some(f64::from(p.focal_px())),
        Camera::ThinLens(l) => {
            Some(f64::from(l.image_distance_m() / l.sensor_width_m()) * f64::from(RES.x))
        }
        Camera::Fisheye(_) | Camera::Orthographic(_) | Camera::Spherical(_) => None,
    }
}

#[test]
fn rays_that_reach_no_film_point_have_no_importance() {
    for (name, camera, _) in cameras_with_importance() {
        let [right, up, forward] = axes(&camera);
        let origin = eye();
        let none = |d: DVec3| {
            let ray = Ray::infinite(origin, d.normalize().as_vec3a());
            camera.importance(&ray).is_none() && camera.pdf_we(&ray).is_none()
        };
        // Straight back: outside every field of view here (the widest is 270°).
        assert!(none(-forward), "{name}: backwards");
        if let Camera::Fisheye(f) = &camera {
            // Just beyond the edge of the field of view, along the film's long axis.
            let t = 0.5 * f64::from(f.fov_rad()) + 0.01;
            assert!(
                t >= PI || none(t.sin() * right + t.cos() * forward),
                "{name}: beyond fov"
            );
            let t = t - 0.02;
            assert!(
                !none(t.sin() * up + t.cos() * forward) || f.coverage() == FisheyeCoverage::Cropped,
                "{name}: just inside the image circle"
            );
        }
        if let Some(focal_px) = perspective_focal_px(&camera) {
            // 10% past the right edge of the film, through the lens centre, and 10% inside.
            let edge = 0.5 * f64::from(RES.x) / focal_px;
            assert!(
                none(1.1 * edge * right + forward),
                "{name}: past the film edge"
            );
            assert!(!none(0.9 * edge * right + forward), "{name}: inside");
        }
    }
}

/// χ² tests in this file (10 cameras' `pdf_we`, 2 thin-lens `sample_wi`), for the
/// Šidák-corrected significance (family-wise 1%).
const CHI2_TESTS: usize = 12;

/// `v`'s components in the orthonormal basis `basis` (x, y, z), and back.
fn to_basis(basis: &[DVec3; 3], w: DVec3) -> Vec3A {
    Vec3A::new(
        w.dot(basis[0]) as f32,
        w.dot(basis[1]) as f32,
        w.dot(basis[2]) as f32,
    )
}

fn from_basis(basis: &[DVec3; 3], v: Vec3A) -> DVec3 {
    let v = v.as_dvec3();
    v.x * basis[0] + v.y * basis[1] + v.z * basis[2]
}

/// Film points uniform over W × H (and, for the thin lens, a fixed lens point): the
/// directions, in the camera's frame (forward = the harness's +Z), against pdf_dir.
fn check_pdf_we_chi2(select: impl Fn(&Camera) -> bool) {
    let lens_sample = Vec2::new(0.3, 0.8);
    for (k, (name, camera, _)) in cameras_with_importance().into_iter().enumerate() {
        if !select(&camera) {
            continue;
        }
        let basis = axes(&camera);
        let origin = camera
            .generate_ray_only(Vec2::new(200.0, 150.0), lens_sample)
            .unwrap()
            .origin;
        let config = Chi2Config {
            // 7.8° bins: no bin edge on a field of view's edge (θ = 60°, 85°, 90°, 135°).
            theta_bins: 23,
            sample_count: 200_000,
            significance: sidak(0.01, CHI2_TESTS),
            seed: 11 + k as u64,
            ..Chi2Config::default()
        };
        let r = chi2_test_adaptive(
            &config,
            |_, u| {
                let ray = camera.generate_ray_only(u * RES.as_vec2(), lens_sample)?;
                Some(to_basis(&basis, ray.direction.as_dvec3()))
            },
            |v| {
                let w = from_basis(&basis, v).normalize().as_vec3a();
                camera
                    .pdf_we(&Ray::infinite(origin, w))
                    .map_or(0.0, |(_, pdf_dir)| f64::from(pdf_dir))
            },
        );
        println!("{name}: {}", r.message);
        assert!(r.passed, "{name}: {}", r.message);
        // The pdf integrates to the fraction of the film with rays.
        let fraction = f64::from(camera.importance_area_px2()) / f64::from(RES.x * RES.y);
        assert!(
            (r.pdf_integral - fraction).abs() < 2e-3,
            "{name}: {}",
            r.message
        );
    }
}

#[test]
fn pdf_we_is_the_density_of_generate_ray_directions_pinhole_and_thin_lens() {
    check_pdf_we_chi2(|c| perspective_focal_px(c).is_some());
}

/// The fisheye's coverage, `None` for other cameras.
fn coverage(camera: &Camera) -> Option<FisheyeCoverage> {
    match camera {
        Camera::Fisheye(f) => Some(f.coverage()),
        Camera::Pinhole(_)
        | Camera::ThinLens(_)
        | Camera::Orthographic(_)
        | Camera::Spherical(_) => None,
    }
}

#[test]
fn pdf_we_is_the_density_of_generate_ray_directions_circular_fisheyes() {
    check_pdf_we_chi2(|c| coverage(c) == Some(FisheyeCoverage::Circular));
}

#[test]
fn pdf_we_is_the_density_of_generate_ray_directions_cropped_fisheyes() {
    check_pdf_we_chi2(|c| coverage(c) == Some(FisheyeCoverage::Cropped));
}

#[test]
fn point_like_cameras_connect_exactly_to_their_position() {
    for (name, camera, _) in cameras_with_importance() {
        if !camera.is_delta_position() {
            continue;
        }
        let forward = axes(&camera)[2];
        let mut rng = SplitMix64(3);
        let (mut some, mut worst_px) = (0, 0.0f32);
        for _ in 0..3000 {
            let z = 2.0 * f64::from(rng.next_f32()) - 1.0;
            let phi = 2.0 * PI * f64::from(rng.next_f32());
            let s = (1.0 - z * z).max(0.0).sqrt();
            let dist = 0.5 + 4.5 * f64::from(rng.next_f32());
            let offset = dist * DVec3::new(s * phi.cos(), s * phi.sin(), z);
            let reference = (eye().as_dvec3() + offset).as_vec3a();
            let projected = camera.project(reference);
            let sample = camera.sample_wi(reference, Vec2::new(rng.next_f32(), rng.next_f32()));
            let Some(sample) = sample else {
                // Only points on the film's outline may disagree with `project`.
                if let Some(p) = projected {
                    let size = RES.as_vec2();
                    let margin = p.min(size - p).min_element();
                    assert!(
                        margin < 1e-2,
                        "{name}: no sample for {reference} imaged at {p}"
                    );
                }
                continue;
            };
            let p = projected.unwrap_or_else(|| panic!("{name}: sample for unimaged {reference}"));
            some += 1;
            let to_eye = eye().as_dvec3() - reference.as_dvec3();
            let wi = sample.wi.as_dvec3();
            assert!((sample.p_lens_m - eye()).length() < 1e-6, "{name}");
            assert!((wi - to_eye.normalize()).length() < 1e-6, "{name}: wi {wi}");
            assert!((f64::from(sample.distance_m) / to_eye.length() - 1.0).abs() < 1e-6);
            let cos = wi.dot(forward).abs();
            let pdf = to_eye.length_squared() / cos;
            assert!(
                (f64::from(sample.pdf_per_sr) / pdf - 1.0).abs() < 1e-4,
                "{name}: pdf {} vs {pdf}",
                sample.pdf_per_sr
            );
            let reversed = camera
                .importance(&Ray::infinite(sample.p_lens_m, -sample.wi))
                .unwrap();
            assert_eq!(sample.importance, reversed.importance, "{name}");
            assert_eq!(sample.film_point_px, reversed.film_point_px, "{name}");
            assert!(
                (sample.n_lens.as_dvec3() - forward).length() < 1e-6,
                "{name}"
            );
            worst_px = worst_px.max((sample.film_point_px - p).length());
        }
        println!("{name}: {some} connections, film point = project within {worst_px:.2e} px");
        assert!(some > 150, "{name}: {some}");
        assert!(worst_px < 2e-3, "{name}: {worst_px}");
    }
}

/// Near-focused thin lens with a wide aperture for `sample_wi`: f = 20 mm, aperture radius
/// 4 cm, focused at 8 cm.
const NEAR_F_M: f64 = 0.02;
const NEAR_FOCUS_M: f64 = 0.08;
const NEAR_APERTURE_M: f64 = 0.04;

fn near_thin_lens() -> Camera {
    Camera::ThinLens(
        ThinLensCamera::new(
            frame(),
            FocalSpec::FocalLengthMm((NEAR_F_M * 1e3) as f32),
            ApertureSpec::RadiusM(NEAR_APERTURE_M as f32),
            NEAR_FOCUS_M as f32,
            36.0,
        )
        .unwrap(),
    )
}

/// The solid-angle density, at `reference`, of directions towards a uniform point of the
/// aperture disk, zero where that lens point images `reference` off the film: derived
/// here from the thin-lens geometry (thin_lens.rs module docs), not from the camera code.
fn aperture_pdf(camera: &Camera, reference: DVec3, w: DVec3) -> f64 {
    let [right, up, forward] = axes(camera);
    let centre = eye().as_dvec3();
    let cos = w.dot(forward);
    if cos >= 0.0 {
        return 0.0;
    }
    let t = (centre - reference).dot(forward) / cos;
    let lateral = reference + t * w - centre;
    let lens = glam::DVec2::new(lateral.dot(right), lateral.dot(up));
    if t <= 0.0 || lens.length() > NEAR_APERTURE_M {
        return 0.0;
    }
    // Camera-space reference point q; its ray through lens point L meets the focus plane at
    // L + (q − L)·d_f/(−q_z), which maps to the film at f_px/d_f per metre.
    let q = reference - centre;
    let (qx, qy, depth) = (q.dot(right), q.dot(up), q.dot(forward));
    let k = NEAR_FOCUS_M / depth;
    let focus = glam::DVec2::new(lens.x + (qx - lens.x) * k, lens.y + (qy - lens.y) * k);
    let image_distance = NEAR_F_M * NEAR_FOCUS_M / (NEAR_FOCUS_M - NEAR_F_M);
    let focal_px = image_distance * f64::from(RES.x) / 0.036;
    let offset = focus * focal_px / NEAR_FOCUS_M;
    let (x, y) = (
        0.5 * f64::from(RES.x) + offset.x,
        0.5 * f64::from(RES.y) - offset.y,
    );
    if !(0.0..f64::from(RES.x)).contains(&x) || !(0.0..f64::from(RES.y)).contains(&y) {
        return 0.0;
    }
    t * t / (-cos * PI * NEAR_APERTURE_M * NEAR_APERTURE_M)
}

#[test]
fn thin_lens_connections_follow_pdf_per_sr() {
    let camera = near_thin_lens();
    let [right, up, forward] = axes(&camera);
    let lens = match &camera {
        Camera::ThinLens(l) => l.clone(),
        Camera::Pinhole(_)
        | Camera::Fisheye(_)
        | Camera::Orthographic(_)
        | Camera::Spherical(_) => {
            unreachable!("near_thin_lens is a thin lens")
        }
    };
    // On the focus plane (every lens point images it to one film point; the aperture
    // subtends ±27°), and at half that depth (±45°; the image is a blur disk that the film
    // edges clip, so some connections fail).
    let cases = [
        (NEAR_FOCUS_M, 0.01, 0.005, 1.0),
        (0.5 * NEAR_FOCUS_M, 0.015, -0.01, 0.0),
    ];
    for (k, (depth, x, y, expected_success)) in cases.into_iter().enumerate() {
        let reference = eye().as_dvec3() + depth * forward + x * right + y * up;
        let axis = (eye().as_dvec3() - reference).normalize();
        let t1 = axis.cross(up).normalize();
        let basis = [t1, axis.cross(t1), axis];
        let config = Chi2Config {
            theta_bins: 36,
            sample_count: 400_000,
            significance: sidak(0.01, CHI2_TESTS),
            seed: 5 + k as u64,
            ..Chi2Config::default()
        };
        let r = chi2_test_adaptive(
            &config,
            |_, u| {
                let s = camera.sample_wi(reference.as_vec3a(), u)?;
                Some(to_basis(&basis, s.wi.as_dvec3()))
            },
            |v| aperture_pdf(&camera, reference, from_basis(&basis, v).normalize()),
        );
        println!("thin lens, reference at depth {depth} m: {}", r.message);
        assert!(r.passed, "{}", r.message);
        if expected_success == 1.0 {
            assert_eq!(r.success_fraction, 1.0, "{}", r.message);
        } else {
            assert!(
                r.success_fraction > 0.2 && r.success_fraction < 0.95,
                "{}",
                r.message
            );
        }
        // Each connection: the density formula, W_e of the reversed ray, and the film point
        // of `project_through_lens` with the same lens sample.
        let mut rng = SplitMix64(9);
        for _ in 0..2000 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let Some(s) = camera.sample_wi(reference.as_vec3a(), u) else {
                continue;
            };
            let pdf = aperture_pdf(&camera, reference, s.wi.as_dvec3());
            assert!(
                (f64::from(s.pdf_per_sr) / pdf - 1.0).abs() < 1e-3,
                "{} vs {pdf}",
                s.pdf_per_sr
            );
            let reversed = camera
                .importance(&Ray::infinite(s.p_lens_m, -s.wi))
                .unwrap();
            assert!((s.importance / reversed.importance - 1.0).abs() < 1e-5);
            let through = lens.project_through_lens(reference.as_vec3a(), u).unwrap();
            assert!(
                (s.film_point_px - through).length() < 1e-2,
                "{} vs {through}",
                s.film_point_px
            );
            let to_lens = s.p_lens_m.as_dvec3() - reference;
            assert!((f64::from(s.distance_m) / to_lens.length() - 1.0).abs() < 1e-5);
        }
    }
}

#[test]
fn project_with_jacobian_matches_central_differences() {
    let mut cameras = cameras_with_importance();
    cameras.push((
        "orthographic".to_owned(),
        Camera::Orthographic(OrthographicCamera::new(frame(), 6.0).unwrap()),
        0.5 * PI,
    ));
    cameras.push((
        "spherical".to_owned(),
        Camera::Spherical(SphericalCamera::new(frame()).unwrap()),
        PI,
    ));
    for (name, camera, theta_max) in cameras {
        let basis = axes(&camera);
        let (mut checked, mut worst) = (0, 0.0f64);
        for i in 0..24 {
            for j in 0..24 {
                let theta = theta_max * (f64::from(i) + 0.5) / 24.0;
                let phi = 2.0 * PI * (f64::from(j) + 0.3) / 24.0;
                let dist = 2.5;
                let p = (eye().as_dvec3() + dist * direction(&basis, theta, phi)).as_vec3a();
                let Some((film, rows)) = camera.project_with_jacobian(p) else {
                    continue;
                };
                assert_eq!(Some(film), camera.project(p), "{name}");
                // Away from the film edges (the spherical camera's seam and clamp).
                if film.min(RES.as_vec2() - film).min_element() < 4.0 {
                    continue;
                }
                let h = 1e-3 * dist as f32;
                for (k, axis) in [Vec3A::X, Vec3A::Y, Vec3A::Z].into_iter().enumerate() {
                    let (Some(plus), Some(minus)) =
                        (camera.project(p + h * axis), camera.project(p - h * axis))
                    else {
                        continue;
                    };
                    let fd = (plus - minus).as_dvec2() / (2.0 * f64::from(h));
                    for (row, fd) in rows.iter().zip([fd.x, fd.y]) {
                        let analytic = f64::from(row[k]);
                        let scale = f64::from(row.length()).max(1e-6);
                        worst = worst.max((analytic - fd).abs() / scale);
                    }
                }
                checked += 1;
            }
        }
        println!("{name}: {checked} points, Jacobian within {worst:.2e} of its row norm");
        assert!(checked > 20, "{name}: {checked}");
        assert!(worst < 2e-3, "{name}: {worst}");
    }
}

#[test]
fn orthographic_and_spherical_cameras_have_no_importance() {
    let cameras = [
        (
            "orthographic",
            Camera::Orthographic(OrthographicCamera::new(frame(), 2.0).unwrap()),
        ),
        (
            "spherical",
            Camera::Spherical(SphericalCamera::new(frame()).unwrap()),
        ),
    ];
    for (name, camera) in cameras {
        let message = camera.importance_support().unwrap_err();
        assert!(
            message.contains(name) && message.contains("use path"),
            "{message}"
        );
        assert_eq!(camera.importance_area_px2(), 0.0);
        let ray = camera
            .generate_ray_only(Vec2::new(123.4, 56.7), Vec2::ZERO)
            .unwrap();
        assert!(camera.importance(&ray).is_none(), "{name}");
        assert!(camera.pdf_we(&ray).is_none(), "{name}");
        let ahead = ray.at(3.0);
        assert!(
            camera.sample_wi(ahead, Vec2::splat(0.5)).is_none(),
            "{name}"
        );
        assert!((camera.forward().as_dvec3() - axes(&camera)[2]).length() < 1e-6);
    }
}

#[test]
fn importance_support_and_lens_kinds() {
    for (name, camera, _) in cameras_with_importance() {
        assert_eq!(camera.importance_support(), Ok(()), "{name}");
        assert!(camera.importance_area_px2() > 0.0, "{name}");
        assert_eq!(
            camera.is_delta_position(),
            !matches!(camera, Camera::ThinLens(_)),
            "{name}"
        );
        assert!((camera.forward().as_dvec3() - axes(&camera)[2]).length() < 1e-6);
    }
    // A thin lens with no aperture is a pinhole: a point lens of area 1.
    let pinhole_lens = Camera::ThinLens(
        ThinLensCamera::new(
            frame(),
            FocalSpec::FocalLengthMm(35.0),
            ApertureSpec::RadiusM(0.0),
            2.0,
            36.0,
        )
        .unwrap(),
    );
    assert!(pinhole_lens.is_delta_position());
    let ray = pinhole_lens
        .generate_ray_only(Vec2::new(10.0, 20.0), Vec2::splat(0.9))
        .unwrap();
    assert_eq!(pinhole_lens.pdf_we(&ray).unwrap().0, 1.0);
    // Circular fisheye: the image circle inscribed in the 300 px side.
    let circular = fisheyes()
        .into_iter()
        .find(|(_, f)| f.coverage() == FisheyeCoverage::Circular)
        .unwrap()
        .1;
    let area = Camera::Fisheye(circular).importance_area_px2();
    assert!(
        (f64::from(area) / (PI * 150.0 * 150.0) - 1.0).abs() < 1e-6,
        "{area}"
    );
}

#[test]
fn fisheye_area_ratio_is_r_r_prime_over_sin() {
    // J(θ) = g g'/sin θ with g = r/f (fisheye.rs module docs), g' by central differences.
    for projection in FisheyeProjection::ALL {
        let limit = 0.5 * projection.max_fov_rad().0;
        for i in 1..40 {
            let theta = limit * i as f32 / 40.0;
            let h = 1e-3;
            let g = |t: f32| f64::from(projection.radius_over_focal(t));
            let fd = (g(theta + h) - g(theta - h)) / (2.0 * f64::from(h));
            let derivative = f64::from(projection.radius_over_focal_derivative(theta));
            assert!(
                (derivative - fd).abs() < 1e-3 * fd.abs().max(1.0),
                "{projection:?} θ {theta}: {derivative} vs {fd}"
            );
            let j = g(theta) * fd / f64::from(theta).sin();
            let area = f64::from(projection.area_per_solid_angle_over_focal2(theta));
            assert!(
                (area / j - 1.0).abs() < 1e-3,
                "{projection:?} θ {theta}: {area} vs {j}"
            );
        }
        assert_eq!(projection.area_per_solid_angle_over_focal2(0.0), 1.0);
    }
}

//! The packet tracer against the scalar path tracer on the Cornell box: the same camera
//! samples, so the images agree far inside their Monte Carlo noise (paths part only where a
//! ray meets an edge and the two ray tests round differently); and its lane widths against
//! each other.

use super::*;
use crate::integrator::{render, RenderSettings, RenderStats};
use crate::sampler::SamplerKind;
use crate::FilmImage;

fn cornell_with(resolution: u32, extra_light: Option<&str>) -> RenderScene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("scenes/cornell-box.json");
    let mut text = std::fs::read_to_string(&path).unwrap();
    if let Some(light) = extra_light {
        text = text.replacen("\"lights\": [", &format!("\"lights\": [{light},"), 1);
    }
    let description = prism_scene::parse_scene_str(&text, &path).unwrap();
    RenderScene::build(&description, Some(glam::UVec2::splat(resolution))).unwrap()
}

fn cornell(resolution: u32) -> RenderScene {
    cornell_with(resolution, None)
}

/// The Cornell box with parts of its text replaced (camera, film).
fn cornell_edited(resolution: u32, edits: &[(&str, &str)]) -> RenderScene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("scenes/cornell-box.json");
    let mut text = std::fs::read_to_string(&path).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    let description = prism_scene::parse_scene_str(&text, &path).unwrap();
    RenderScene::build(&description, Some(glam::UVec2::splat(resolution))).unwrap()
}

fn settings(spp: u32) -> RenderSettings {
    settings_with(spp, SamplerKind::Independent)
}

fn settings_with(spp: u32, sampler: SamplerKind) -> RenderSettings {
    RenderSettings {
        spp,
        seed: 7,
        sampler,
        illumination_aov: true,
        ..RenderSettings::default()
    }
}

fn plane<'a>(film: &'a FilmImage, name: &str) -> &'a [f32] {
    &film.aov(name).unwrap_or_else(|| panic!("no {name}")).values
}

/// Largest |a − b| over a plane, relative to the plane's largest |b|.
fn max_relative_difference(a: &[f32], b: &[f32]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, &v| m.max(f64::from(v).abs()));
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs() / scale)
        .fold(0.0, f64::max)
}

fn render_both(
    mut scene: RenderScene,
    settings: &RenderSettings,
) -> ((FilmImage, RenderStats), (FilmImage, RenderStats)) {
    assert!(scene.packet.is_some(), "the scene qualifies");
    let packet = render(&scene, settings, &|_| {});
    scene.set_packet_tracing(false);
    assert!(scene.packet.is_none());
    let scalar = render(&scene, settings, &|_| {});
    (packet, scalar)
}

#[test]
fn packet_tracer_gives_the_scalar_tracers_image_sample_for_sample() {
    agrees_with_the_scalar_tracer(cornell(48), &settings(8));
}

/// Sobol streams draw their variates per lane, not hashed for all lanes at once.
#[test]
fn packet_tracer_agrees_with_the_sobol_sampler() {
    agrees_with_the_scalar_tracer(cornell(40), &settings_with(8, SamplerKind::Sobol));
}

/// A point light besides the rectangle: light choice by power, the point light sampled by
/// the scalar `Light` code (a delta light, MIS weight 1) and shaded with the lanes.
#[test]
fn packet_tracer_agrees_with_a_point_light_beside_the_rectangle() {
    let point = r#"{"type": "point", "position_m": [0.3, 0.6, 0.2], "power_lm": 40,
                    "spectrum": {"blackbody_k": 3000}}"#;
    let scene = cornell_with(40, Some(point));
    assert_eq!(scene.lights.len(), 2);
    agrees_with_the_scalar_tracer(scene, &settings(8));
}

/// A ceiling lamp added to the Cornell box ([`cornell_with_lamps`]): its material's
/// reflectance (JSON), square side, position under the ceiling and emission.
struct Lamp {
    reflectance: String,
    side_m: f32,
    x_m: f32,
    z_m: f32,
    luminance_cd_m2: u32,
    blackbody_k: u32,
}

/// The Cornell box with one-sided rectangle `lamps` under its ceiling (a material each) and
/// `extra_lights` (JSON objects, each followed by a comma) before its own light.
fn cornell_with_lamps(lamps: &[Lamp], extra_lights: &str) -> RenderScene {
    let mut materials = String::new();
    let mut shapes = String::new();
    let mut lights = String::new();
    for (k, lamp) in lamps.iter().enumerate() {
        let Lamp {
            reflectance,
            side_m,
            x_m,
            z_m,
            luminance_cd_m2,
            blackbody_k,
        } = lamp;
        materials.push_str(&format!(
            r#""lamp-{k}": {{"type": "lambert", "reflectance": {reflectance}}},"#
        ));
        shapes.push_str(&format!(
            r#"{{"type": "rectangle", "name": "lamp-{k}", "size_m": [{side_m}, {side_m}],
                 "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}},
                               {{"translate": [{x_m}, 0.97, {z_m}]}}],
                 "material": "lamp-{k}"}},"#
        ));
        lights.push_str(&format!(
            r#"{{"type": "area", "shape": "lamp-{k}", "luminance_cd_m2": {luminance_cd_m2},
                 "two_sided": false, "spectrum": {{"blackbody_k": {blackbody_k}}}}},"#
        ));
    }
    lights.push_str(extra_lights);
    cornell_edited(
        40,
        &[
            ("\"materials\": {", &format!("\"materials\": {{{materials}")),
            ("\"shapes\": [", &format!("\"shapes\": [{shapes}")),
            ("\"lights\": [", &format!("\"lights\": [{lights}")),
        ],
    )
}

/// More materials than reflectance slots and more rectangle emitters than light slots
/// (those through the per-path caches), and a uniform sky that escaping rays see and the
/// light sampler picks (the scalar `Light` code) — the passes that run lane by lane.
#[test]
fn packet_tracer_agrees_past_its_slots_and_with_a_sky() {
    let lamps: Vec<Lamp> = (0..6)
        .map(|k| Lamp {
            reflectance: format!(r#"{{"rgb": [0.{k}5, 0.5, 0.3]}}"#),
            side_m: 0.12,
            x_m: -0.75 + 0.3 * k as f32,
            z_m: 0.5,
            luminance_cd_m2: 1_000_000 + 400_000 * k,
            blackbody_k: 2700 + 300 * k,
        })
        .collect();
    let sky = r#"{"type": "sky", "luminance_cd_m2": 300, "spectrum": "D65"},"#;
    let scene = cornell_with_lamps(&lamps, sky);
    assert_eq!(scene.lights.len(), 8);
    let packet = scene.packet.as_ref().expect("the scene qualifies");
    assert_eq!(packet.reflectances.len(), REFLECTANCE_SLOTS);
    assert_eq!(packet.light_radiances.len(), LIGHT_SLOTS);
    assert!(packet.leaves.iter().any(|l| l.reflectance_slot.is_none()));
    assert!(packet
        .lights
        .iter()
        .flatten()
        .any(|r| r.radiance_slot.is_none()));
    assert!(packet.lights.iter().any(Option::is_none), "the sky");
    agrees_with_the_scalar_tracer(scene, &settings(8));
}

/// Eight or more lights with bounds: each lane descends the light BVH at its own hit
/// point, and BSDF-sampled hits on the lamps weigh by the BVH's pmf at the previous
/// vertex, as in the scalar tracer. Lamps of one kind share a radiance slot.
#[test]
fn packet_tracer_agrees_when_lights_are_chosen_through_the_light_bvh() {
    let lamps: Vec<Lamp> = (0..12)
        .map(|k| Lamp {
            reflectance: "0.2".into(),
            side_m: 0.1,
            x_m: -0.75 + 0.3 * (k % 6) as f32,
            z_m: 0.3 + 0.4 * (k / 6) as f32,
            // Two kinds of lamp, and four of their own.
            luminance_cd_m2: if k < 8 {
                500_000 + 200_000 * (k % 2)
            } else {
                300_000 * k
            },
            blackbody_k: if k < 8 {
                2700 + 1000 * (k % 2)
            } else {
                2000 + 200 * k
            },
        })
        .collect();
    let scene = cornell_with_lamps(&lamps, "");
    assert_eq!(scene.lights.len(), 13);
    assert!(scene.lights.light_bvh().is_some(), "the light BVH chooses");
    let packet = scene.packet.as_ref().expect("the scene qualifies");
    // The two kinds and the first two lamps of their own; the box's light has its own.
    assert_eq!(packet.light_radiances.len(), LIGHT_SLOTS);
    let slots: Vec<Option<usize>> = packet.lights[..12]
        .iter()
        .map(|r| r.as_ref().unwrap().radiance_slot)
        .collect();
    assert_eq!(&slots[..8], &[Some(0), Some(1)].repeat(4)[..]);
    assert_eq!(&slots[8..], &[Some(2), Some(3), None, None]);
    agrees_with_the_scalar_tracer(scene, &settings(8));
}

fn agrees_with_the_scalar_tracer(scene: RenderScene, settings: &RenderSettings) {
    let ((packet, ps), (scalar, ss)) = render_both(scene, settings);
    assert_eq!(ps.samples, ss.samples);
    assert_eq!(ps.non_finite_samples + ps.non_finite_contributions, 0);
    // Rays, bounces and roulette differ only by the few paths that part at an edge.
    for (a, b, what) in [
        (ps.rays_traced, ss.rays_traced, "rays"),
        (ps.bounces, ss.bounces, "bounces"),
        (
            ps.roulette_terminations,
            ss.roulette_terminations,
            "roulette",
        ),
    ] {
        let rel = (a as f64 - b as f64).abs() / b as f64;
        assert!(rel < 2e-3, "{what}: packet {a}, scalar {b}");
    }
    // Per pixel: the image's own noise at 8 spp is ≈ 10 % of the brightest walls; paths
    // that part at an edge move single pixels by far less than that. Almost all pixels
    // agree to float rounding.
    let y_p = &packet.y;
    let y_s = &scalar.y;
    let scale = y_s.iter().fold(0.0f32, |m, &v| m.max(v));
    let parted = y_p
        .iter()
        .zip(y_s)
        .filter(|(a, b)| (*a - *b).abs() > 1e-4 * scale)
        .count();
    assert!(
        parted * 50 <= y_p.len(),
        "{parted} of {} pixels differ by more than 1e-4 of the peak",
        y_p.len()
    );
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let rel_mean = (mean(y_p) - mean(y_s)).abs() / mean(y_s);
    assert!(rel_mean < 1e-3, "mean Y differs by {rel_mean:e}");
    // Surface AOVs and the illumination AOV come from the same first hits and light
    // samples.
    for name in ["spp.Y", "depth.Z", "albedo.R", "albedo.G", "normal.Z"] {
        let d = max_relative_difference(plane(&packet, name), plane(&scalar, name));
        assert!(d < 1e-3, "{name}: {d:e}");
    }
    for name in ["illumination.X", "illumination.Y", "illumination.Z"] {
        let (a, b) = (plane(&packet, name), plane(&scalar, name));
        let rel = (mean(a) - mean(b)).abs() / mean(b);
        assert!(rel < 1e-3, "{name}: mean differs by {rel:e}");
    }
}

/// Every ISA's kernels render the baseline (SSE2) kernels' image bit for bit: at 8 lanes
/// (AVX2 and FMA: the same operations, `mul_add` fused on both) and at 16 (AVX-512), whose
/// finished samples reach the film in another order — which the film's exact sums
/// (`film::fixed_sum`) do not see. Each ISA the machine runs (`prism_cpu::each_isa`).
#[test]
fn every_isa_renders_the_baseline_image() {
    let mut scene = cornell(32);
    scene.packet.as_mut().unwrap().simd = prism_cpu::Simd::SCALAR;
    let reference = render(&scene, &settings(4), &|_| {}).0;
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
    for simd in prism_cpu::each_isa() {
        scene.packet.as_mut().unwrap().simd = simd;
        assert_eq!(
            scene.packet.as_ref().unwrap().lane_count(),
            if simd.avx512() { 16 } else { 8 }
        );
        let image = render(&scene, &settings(4), &|_| {}).0;
        assert!(
            bits(image.rgb.as_flattened()) == bits(reference.rgb.as_flattened()),
            "{simd} RGB"
        );
        assert!(bits(&image.y) == bits(&reference.y), "{simd} Y");
        for name in ["illumination.Y", "spp.Y", "depth.Z"] {
            assert!(
                bits(plane(&image, name)) == bits(plane(&reference, name)),
                "{simd} {name}"
            );
        }
    }
}

#[test]
fn plan_says_why_a_scene_has_no_packet_tracer() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // The glossy environment scene has spheres, conductors and an environment map.
    let description = prism_scene::load_scene(root.join("scenes/glossy-env.json")).unwrap();
    let scene = RenderScene::build(&description, Some(glam::UVec2::splat(8))).unwrap();
    assert!(scene.packet.is_none());
    let why = PacketScene::new(&scene).unwrap_err();
    assert!(!why.is_empty());
    let mut cornell = cornell(8);
    let request = crate::plan::PlanRequest {
        spp: 1,
        spectral_bins: None,
        aov_output: true,
        sampler: "independent",
        sample_plan: Default::default(),
    };
    let plan = crate::plan::RenderPlan::new(&cornell, &request);
    let choice = plan
        .choices
        .iter()
        .find(|c| c.feature == "packet tracing")
        .expect("the plan lists packet tracing");
    assert!(choice.setting.starts_with("on"), "{choice:?}");
    cornell.set_packet_tracing(false);
    let plan = crate::plan::RenderPlan::new(&cornell, &request);
    let choice = plan
        .choices
        .iter()
        .find(|c| c.feature == "packet tracing")
        .unwrap();
    assert_eq!(choice.setting, "off");
}

#[test]
fn packet_ray_queries_agree_with_the_scenes_own() {
    use super::intersect::{closest, occluded, RayLanes};
    use prism_geometry::Ray;
    let scene = cornell(8);
    let packet = scene.packet.as_ref().unwrap();
    // The two cuboids are tested as boxes, the five walls and the light as patches.
    assert_eq!((packet.box_count(), packet.patch_count()), (2, 6));
    // A fixed pseudo-random set of rays from points inside the box (hash of the index).
    let unit = |i: u64, k: u64| {
        let h = crate::sampler::hash::mix64(i.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ k);
        (h >> 40) as f32 / (1u64 << 24) as f32
    };
    let (mut mismatched, mut total) = (0, 0);
    for batch in 0..512u64 {
        let mut rays = RayLanes::<16>::idle();
        let mut shadow = RayLanes::<16>::idle();
        let mut scalar = Vec::new();
        for l in 0..16 {
            let i = batch * 16 + l as u64;
            let o = Vec3A::new(
                1.8 * unit(i, 1) - 0.9,
                1.8 * unit(i, 2) - 0.9,
                1.8 * unit(i, 3) - 0.9,
            );
            let d = Vec3A::new(
                2.0 * unit(i, 4) - 1.0,
                2.0 * unit(i, 5) - 1.0,
                unit(i, 6) - 0.5,
            )
            .normalize();
            let ray = Ray::spawn(o, d);
            let to = o + 1.5 * unit(i, 7) * d;
            let shadow_ray = Ray::spawn_to(o, to);
            rays.set(l, ray.origin, ray.direction, ray.t_min, ray.t_max);
            shadow.set(
                l,
                shadow_ray.origin,
                shadow_ray.direction,
                shadow_ray.t_min,
                shadow_ray.t_max,
            );
            scalar.push((ray, shadow_ray));
        }
        let (t, leaf) = closest(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &rays,
        );
        let blocked = occluded(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &shadow,
        );
        for (l, (ray, shadow_ray)) in scalar.iter().enumerate() {
            total += 1;
            let expected = scene.geometry.intersect(ray);
            let got = packet.leaves.get(leaf[l] as usize);
            let same = match (expected, got) {
                (None, None) => true,
                // (The scalar query recomputes t in the object space of a cuboid, which
                // rounds differently by ≈ 1e-7 m.) Another leaf at the same distance is a
                // coincident surface (a cuboid's
                // bottom face on the floor, met by rays from inside the cuboid): either
                // answer is right.
                (Some(h), Some(_)) => (h.t - t[l]).abs() <= 1e-5 * (1.0 + h.t),
                _ => false,
            };
            let occl_same = scene.geometry.occluded(shadow_ray) == blocked[l];
            if !(same && occl_same) {
                mismatched += 1;
                if std::env::var_os("PACKET_TEST_VERBOSE").is_some() {
                    eprintln!(
                        "ray {ray:?}: scalar {:?}, packet t {} leaf {}; occluded scalar {} packet {}",
                        expected,
                        t[l],
                        leaf[l],
                        scene.geometry.occluded(shadow_ray),
                        blocked[l]
                    );
                }
            }
        }
    }
    // Same leaf where the surfaces differ: the shading each query reports.
    let mut checked = 0;
    for i in 0..4096u64 {
        let o = Vec3A::new(0.0, 0.5, 0.9);
        let d =
            Vec3A::new(2.0 * unit(i, 8) - 1.0, 2.0 * unit(i, 9) - 1.0, -unit(i, 10)).normalize();
        let ray = Ray::spawn(o, d);
        let mut rays = RayLanes::<8>::idle();
        rays.set(0, ray.origin, ray.direction, ray.t_min, ray.t_max);
        let (_, leaf) = closest(
            &packet.triangles,
            &packet.parallelograms,
            &packet.boxes,
            &rays,
        );
        if let (Some(h), Some(s)) = (
            scene.geometry.intersect(&ray),
            packet.leaves.get(leaf[0] as usize),
        ) {
            let si = scene.geometry.shading_interaction(&ray, &h);
            if si.material_id != s.material_id || si.n_geometric != s.n_geometric {
                mismatched += 1;
            }
            checked += 1;
        }
    }
    assert!(checked > 4000);
    // Only rays through an edge may differ (either neighbour, or the widened patch).
    assert!(
        mismatched * 2000 <= total + checked,
        "{mismatched} of {} rays differ",
        total + checked
    );
}

/// Spectral bins (the predictive users' EXR layout) come from the same film calls: their
/// planes agree as the XYZ does.
#[test]
fn packet_tracer_fills_the_spectral_bins_as_the_scalar_tracer() {
    let settings = RenderSettings {
        spectral_bins: Some(crate::film::SpectralBins::new(8).unwrap()),
        ..settings(4)
    };
    let ((packet, _), (scalar, _)) = render_both(cornell(32), &settings);
    let (a, b) = (packet.spectral.unwrap(), scalar.spectral.unwrap());
    assert_eq!(a.centres_nm, b.centres_nm);
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    for (k, (pa, pb)) in a.planes.iter().zip(&b.planes).enumerate() {
        let rel = (mean(pa) - mean(pb)).abs() / mean(pb);
        assert!(rel < 1e-3, "bin {k}: means differ by {rel:e}");
    }
}

/// A thin-lens camera (the lens dimensions are used) and a film that samples its filter
/// (each sample to its own pixel with weight f/p) instead of splatting.
#[test]
fn packet_tracer_agrees_with_a_thin_lens_and_filter_sampling() {
    let scene = cornell_edited(
        40,
        &[
            (
                r#""type": "pinhole","#,
                r#""type": "thin_lens", "focal_length_mm": 50, "f_number": 2.8, "focus_distance_m": 3.9,"#,
            ),
            (
                r#""reconstruction": "splat""#,
                r#""reconstruction": "importance""#,
            ),
            (r#""fov_deg": 39.3077,"#, ""),
            (r#""fov_axis": "horizontal","#, ""),
        ],
    );
    assert!(!scene.splat);
    assert!(scene.camera.uses_lens_sample());
    agrees_with_the_scalar_tracer(scene, &settings(8));
}

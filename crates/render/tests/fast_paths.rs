//! The fast paths' decisions over the example scenes (scenes/*.json, scenes/*/*.json):
//! packet tracing and small-scene intersection as they were before the paths stated their
//! allow-lists (`PacketScene::SUPPORTS`, `SMALL_SCENE_SUPPORTS`), the features each scene
//! has, the light features against the built lights, and the `--explain` lines.

use std::path::{Path, PathBuf};

use glam::UVec2;
use prism_render::light::{AreaShape, Light};
use prism_render::scene_build::{SceneFeature, SceneFeatures};
use prism_render::{PlanRequest, RenderPlan, RenderScene};

/// (scene, packet tracing, small-scene intersection, features), the decisions recorded on
/// main before this change (the same for every scene).
#[rustfmt::skip]
const DECISIONS: &[(&str, bool, bool, &[SceneFeature])] = {
    use SceneFeature::*;
    &[
        ("bandwidth/curved-diffuse-windows.json", false, true, &[Quadrics, InfiniteLights]),
        ("bandwidth/fig17-curved-area.json", false, true, &[NonLambertianBsdfs, Quadrics]),
        ("bandwidth/fig9-spheres.json", false, true, &[Textures, NonLambertianBsdfs, Quadrics, InfiniteLights]),
        ("bandwidth/merl-sources.json", false, true, &[NonLambertianBsdfs, Quadrics]),
        ("cameras/fisheye-equidistant.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/fisheye-equisolid.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/fisheye-orthographic.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/fisheye-stereographic.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/orthographic.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/pinhole.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/spherical.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics]),
        ("cameras/thin-lens.json", false, true, &[DiagnosticIntegrator, NonLambertianBsdfs, Quadrics, ThinLensCamera]),
        ("cornell-box-fog.json", false, false, &[ParticipatingMedia, OpacityMasks]),
        ("cornell-box.json", true, true, &[]),
        ("daylight-room.json", false, true, &[ThinGlazing, NonLambertianBsdfs, InfiniteLights]),
        ("fluorescence.json", false, true, &[DeltaLights, Reradiation]),
        ("glossy-env.json", false, true, &[Dispersion, NonLambertianBsdfs, Quadrics, InfiniteLights]),
        ("import/room.json", false, true, &[NonLambertianBsdfs, Quadrics, InfiniteLights]),
        // 120 luminaires: light samples choose through the light BVH, which the packet
        // tracer serves (each lane descends it at its own hit point).
        ("many-lights/open-office.json", true, true, &[DeltaLights]),
        ("material-gallery.json", false, true, &[ThinGlazing, NonLambertianBsdfs, Quadrics, InfiniteLights]),
        ("merl/sources.json", false, true, &[NonLambertianBsdfs, Quadrics]),
        ("minimal.json", false, false, &[DiagnosticIntegrator, Quadrics]),
        ("office/office.json", true, true, &[DeltaLights]),
        ("radiosity/cornell-box.json", false, true, &[RadiositySolution]),
        ("radiosity/crate-hall.json", false, false, &[RadiositySolution]),
        ("stress/bulb-in-glass-fog.json", false, false, &[ParticipatingMedia, NonLambertianBsdfs, Quadrics, DeltaLights]),
        ("stress/caustic-glass-sphere.json", false, true, &[NonLambertianBsdfs, Quadrics, NonRectangleAreaLights]),
        ("stress/chromatic-smoke.json", false, false, &[ParticipatingMedia, OpacityMasks, InfiniteLights]),
        ("stress/dispersion-prism.json", false, true, &[Dispersion, NonLambertianBsdfs, Quadrics, InfiniteLights, NonRectangleAreaLights]),
        ("stress/door-ajar.json", true, true, &[]),
        ("stress/extreme-dynamic-range.json", false, true, &[Quadrics, NonRectangleAreaLights]),
        ("stress/glossy-interreflection.json", false, true, &[NonLambertianBsdfs, Quadrics]),
        ("stress/grazing-rough-conductor.json", false, true, &[NonLambertianBsdfs, InfiniteLights]),
        ("stress/haze-valley.json", false, false, &[ParticipatingMedia, OpacityMasks, Quadrics, InfiniteLights]),
        ("stress/hdr-sun-env.json", false, true, &[NonLambertianBsdfs, Quadrics, InfiniteLights]),
        ("stress/milk.json", false, false, &[ParticipatingMedia, OpacityMasks]),
        ("stress/small-source.json", false, true, &[Quadrics, NonRectangleAreaLights]),
        ("stress/spiky-spectrum.json", false, true, &[Quadrics]),
        ("stress/spot-fog-glass.json", false, false, &[ParticipatingMedia, NonLambertianBsdfs, Quadrics, NonRectangleAreaLights]),
        ("textures.json", false, true, &[OpacityMasks, Textures, NonLambertianBsdfs, TwoSidedMaterials, ShadingNormalMaps, Quadrics, InfiniteLights]),
        ("tiled/louvre-room.json", false, true, &[TwoSidedMaterials, DeltaLights, RadiositySolution, TiledSurfaces]),
        ("tiled/wicker-room.json", false, true, &[VertexNormals, RadiositySolution, TiledSurfaces]),
        ("tiled/wicker-wall.json", false, true, &[VertexNormals, DeltaLights, TiledSurfaces]),
    ]
};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The example scenes: scenes/*.json and scenes/*/*.json, relative to scenes/.
fn example_scenes() -> Vec<String> {
    let root = scenes_dir();
    let mut out = Vec::new();
    let json = |p: &Path| p.extension().is_some_and(|e| e == "json");
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            for inner in std::fs::read_dir(&path).unwrap() {
                let inner = inner.unwrap().path();
                if json(&inner) {
                    out.push(inner);
                }
            }
        } else if json(&path) {
            out.push(path);
        }
    }
    let mut names: Vec<String> = out
        .iter()
        .map(|p| {
            p.strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/")
        })
        .collect();
    names.sort();
    names
}

fn build(name: &str) -> RenderScene {
    let description = prism_scene::load_scene(scenes_dir().join(name)).unwrap();
    RenderScene::build(&description, Some(UVec2::new(8, 8))).unwrap()
}

fn plan_text(scene: &RenderScene) -> String {
    let request = PlanRequest {
        spp: 1,
        spectral_bins: None,
        aov_output: false,
        sampler: "independent",
        sample_plan: Default::default(),
    };
    RenderPlan::new(scene, &request).to_string()
}

#[test]
fn every_example_scene_keeps_its_fast_path_decisions() {
    let listed: Vec<&str> = DECISIONS.iter().map(|d| d.0).collect();
    assert_eq!(
        example_scenes(),
        listed,
        "the table lists every example scene, in order"
    );
    let mut wrong = Vec::new();
    for &(name, packet, small, features) in DECISIONS {
        let scene = build(name);
        let got = (
            scene.packet.is_some(),
            scene.geometry.is_small_scene(),
            scene.features,
        );
        if got != (packet, small, SceneFeatures::of(features)) {
            wrong.push(format!(
                "{name}: packet {} small {} {:?}",
                got.0, got.1, got.2
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The light features come from the description (they must be known before the geometry,
/// and so the lights, are built); here they are checked against the built lights.
#[test]
fn light_features_agree_with_the_built_lights() {
    for name in example_scenes() {
        let scene = build(&name);
        let lights = scene.lights.lights();
        let area_non_rectangle = lights.iter().any(|l| match l {
            Light::Area(a) => !matches!(a.shape, AreaShape::Rectangle(_)),
            _ => false,
        });
        let f = scene.features;
        assert_eq!(
            f.contains(SceneFeature::DeltaLights),
            lights.iter().any(Light::is_delta),
            "{name}"
        );
        assert_eq!(
            f.contains(SceneFeature::InfiniteLights),
            lights.iter().any(Light::is_infinite),
            "{name}"
        );
        assert_eq!(
            f.contains(SceneFeature::NonRectangleAreaLights),
            area_non_rectangle,
            "{name}"
        );
    }
}

/// The line of `feature` in a plan's text: "feature : setting" and its "why:" line.
fn plan_line(text: &str, feature: &str) -> (String, String) {
    let lines: Vec<&str> = text.lines().collect();
    let i = lines
        .iter()
        .position(|l| l.starts_with(feature))
        .unwrap_or_else(|| panic!("no `{feature}` line in:\n{text}"));
    let setting = lines[i].split_once(" : ").unwrap().1.to_string();
    let why = lines[i + 1]
        .trim()
        .strip_prefix("why: ")
        .unwrap()
        .to_string();
    (setting, why)
}

#[test]
fn explain_says_used_or_names_the_features_outside_each_allow_list() {
    let cornell = build("cornell-box.json");
    let text = plan_text(&cornell);
    let (setting, why) = plan_line(&text, "packet tracing");
    assert!(setting.starts_with("on, "), "{setting}");
    assert!(why.starts_with("used: "), "{why}");
    let (setting, why) = plan_line(&text, "small-scene intersection");
    assert!(setting.starts_with("on, "), "{setting}");
    assert!(why.starts_with("used: "), "{why}");
    // The fast paths' ISA and why: `avx512 (CPU has AVX-512 F/DQ/VL/BW)` and the like.
    let choice = prism_cpu::choice();
    let line = format!("simd: {} ({})", choice.simd, choice.reason);
    assert_eq!(text.lines().last(), Some(line.as_str()), "{text}");

    let glossy = build("glossy-env.json");
    let text = plan_text(&glossy);
    let (setting, why) = plan_line(&text, "packet tracing");
    assert_eq!(setting, "off");
    assert_eq!(
        why,
        "not used: dispersion, non-Lambertian BSDFs, spheres and disks"
    );
    let (_, why) = plan_line(&text, "small-scene intersection");
    assert!(why.starts_with("used: "), "{why}");

    // A diagnostic integrator still gets both lines; one sphere alone is past a limit.
    let minimal = build("minimal.json");
    let text = plan_text(&minimal);
    let (_, why) = plan_line(&text, "packet tracing");
    assert_eq!(why, "not used: diagnostic integrator, spheres and disks");
    let (setting, why) = plan_line(&text, "small-scene intersection");
    assert_eq!(setting, "off");
    assert_eq!(why, "not used: a single instance, tested directly");

    let mut off = build("cornell-box.json");
    off.set_packet_tracing(false);
    let (setting, why) = plan_line(&plan_text(&off), "packet tracing");
    assert_eq!(
        (setting.as_str(), why.as_str()),
        ("off", "not used: switched off for this render")
    );
}

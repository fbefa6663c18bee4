//! The bandwidth predictor on scenes whose answer is known (issue 19, test f): a Lambertian
//! plane under a uniform sky is smooth everywhere (b_p < 0.05 cycles/px); the edge of a
//! hard shadow (a point light and a box) is sharp (b_p ≥ 0.25) along the edge and nowhere
//! else on the floor but the box's own outline; `--plan-visibility off` (the paper, which ignores
//! visibility) misses it. And the plan keeps its budget.

use prism_bandwidth::PixelClass;
use prism_render::predictor::{predict, Prediction, PredictorSettings};
use prism_render::RenderScene;
use prism_scene::parse_scene_str;

fn build(json: &str) -> RenderScene {
    RenderScene::build(&parse_scene_str(json, "predictor.json").unwrap(), None).unwrap()
}

fn run(scene: &RenderScene, visibility: bool) -> Prediction {
    let settings = PredictorSettings {
        visibility,
        ..PredictorSettings::defaults(16.0, 1)
    };
    predict(scene, &settings, 1).unwrap()
}

const CAMERA: &str = r#""camera": {"type": "pinhole", "fov_deg": 40,
    "transform": {"look_at": {"eye": [0, 4, 0.01], "target": [0, 0, 0], "up": [0, 0, -1]}}},
    "film": {"resolution": [48, 48]}"#;

#[test]
fn a_lambertian_plane_under_a_uniform_sky_is_smooth() {
    let scene = build(&format!(
        r#"{{{CAMERA},
        "materials": {{"white": {{"type": "lambert", "reflectance": 0.7}}}},
        "shapes": [{{"type": "rectangle", "size_m": [20, 20], "material": "white",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
        "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
    ));
    let p = run(&scene, true);
    let worst = p
        .pixels
        .iter()
        .map(|x| x.image_bandwidth_cycles_per_px)
        .fold(0.0f32, f32::max);
    eprintln!("Lambertian plane under a uniform sky: b_p at most {worst}");
    assert!(worst < 0.05, "b_p up to {worst}");
    let total = p.allocated.plan.total_camera_samples() as f64;
    assert!((total / (48.0 * 48.0) - 16.0).abs() < 0.5, "{total}");
}

/// A floor under a point light with a box between them: a hard shadow.
fn hard_shadow_scene() -> RenderScene {
    hard_shadow_scene_seen_by(CAMERA)
}

/// [`hard_shadow_scene`] with `camera` (the scene's `camera` and `film` entries).
fn hard_shadow_scene_seen_by(camera: &str) -> RenderScene {
    build(&format!(
        r#"{{{camera},
        "materials": {{"white": {{"type": "lambert", "reflectance": 0.7}}}},
        "shapes": [
          {{"type": "rectangle", "size_m": [20, 20], "material": "white",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
          {{"type": "cuboid", "size_m": [0.8, 0.1, 0.8], "material": "white",
            "transform": {{"translate": [0.3, 0.5, 0]}}}}],
        "lights": [{{"type": "point", "position_m": [0.3, 2.5, 0], "spectrum": 1.0, "scale": 10}}]}}"#
    ))
}

#[test]
fn a_hard_shadow_edge_is_sharp_and_only_visibility_sees_it() {
    let scene = hard_shadow_scene();
    let with = run(&scene, true);
    // The pixels that see a surface lit by the light (floor and box top).
    let lit: Vec<usize> = (0..48 * 48)
        .filter(|&i| with.pixels[i].visibility.traced > 0)
        .collect();
    assert!(lit.len() > 48 * 40, "{} lit pixels", lit.len());
    let floor_pixels = |p: &Prediction| {
        lit.iter()
            .map(|&i| p.pixels[i].image_bandwidth_cycles_per_px)
            .collect::<Vec<f32>>()
    };
    let sharp = floor_pixels(&with).iter().filter(|&&b| b >= 0.25).count();
    let smooth = floor_pixels(&with).iter().filter(|&&b| b < 0.05).count();
    // The shadow's outline is ≈ 4 × 10 pixels long at this size; most of the floor is
    // smooth (a point light on a Lambertian plane: ν = 0).
    assert!(sharp >= 20, "{sharp} sharp pixels");
    assert!(smooth > 48 * 48 / 2, "{smooth} smooth pixels");
    let without = run(&scene, false);
    let sharp_without = floor_pixels(&without)
        .iter()
        .filter(|&&b| b >= 0.25)
        .count();
    eprintln!(
        "{} lit pixels: {sharp} sharp and {smooth} smooth with visibility, {sharp_without} sharp \
         without",
        lit.len()
    );
    // Without visibility (the paper's predictor) only the box's outline is sharp, a
    // geometric edge that both see where it is lit; the shadow's outline is what the shadow
    // rays add. In the umbra the box's foot is no edge with visibility: both sides are
    // dark there, a step only the paper's L̂, which ignores occlusion, sees.
    let sharp_only_without: Vec<usize> = lit
        .iter()
        .zip(floor_pixels(&with).iter().zip(floor_pixels(&without)))
        .filter(|(_, (b_with, b_without))| *b_without >= 0.25 && **b_with < 0.25)
        .map(|(&i, _)| i)
        .collect();
    for &i in &sharp_only_without {
        assert_eq!(
            with.pixels[i].visibility.visible, 0,
            "pixel {i}: sharp without visibility only, yet lit"
        );
    }
    assert!(
        sharp >= sharp_without + 20,
        "the shadow rays add {} sharp pixels to the paper's {sharp_without}",
        sharp - sharp_without
    );
}

/// The probe reads a material's textures where each pixel sees them (its G-buffer hit
/// carries the uv): a checkerboard of reflectance 0.1 / 0.7 in 4 × 4 cells on a plane
/// under a uniform sky gives L̂ ≈ a·L_sky per cell, 0.1 on even cells and 0.7 on odd ones
/// (within the estimate's spread), not one value everywhere.
#[test]
fn the_probe_reads_uv_textures_at_each_pixel() {
    let scene = build(&format!(
        r#"{{{CAMERA},
        "materials": {{"checks": {{"type": "lambert", "reflectance":
            {{"texture": {{"type": "checkerboard", "a": 0.1, "b": 0.7, "uv_scale": [4, 4]}}}}}}}},
        "shapes": [{{"type": "rectangle", "size_m": [3, 3], "material": "checks",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
        "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
    ));
    let p = run(&scene, true);
    let (mut dark, mut bright) = (Vec::new(), Vec::new());
    for pixel in &p.pixels {
        if pixel.mean_y <= 0.0 {
            continue;
        }
        if pixel.mean_y < 0.4 {
            dark.push(f64::from(pixel.mean_y));
        } else {
            bright.push(f64::from(pixel.mean_y));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!(
        "checkerboard: {} dark pixels (mean L̂ {:.3}), {} bright (mean L̂ {:.3})",
        dark.len(),
        mean(&dark),
        bright.len(),
        mean(&bright)
    );
    assert!(dark.len() > 200 && bright.len() > 200);
    assert!((mean(&dark) - 0.1).abs() < 0.02, "{}", mean(&dark));
    assert!((mean(&bright) - 0.7).abs() < 0.05, "{}", mean(&bright));
}

/// A plane under a uniform sky whose reflectance is `texture` (a JSON texture object).
fn textured_plane(texture: &str) -> RenderScene {
    build(&format!(
        r#"{{{CAMERA},
        "materials": {{"tex": {{"type": "lambert", "reflectance": {{"texture": {texture}}}}}}},
        "shapes": [{{"type": "rectangle", "size_m": [3, 3], "material": "tex",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
        "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
    ))
}

/// Median b_p over the pixels that see the plane.
fn median_b_p(p: &Prediction) -> f32 {
    let mut b: Vec<f32> = p
        .pixels
        .iter()
        .filter(|x| x.mean_y > 0.0)
        .map(|x| x.image_bandwidth_cycles_per_px)
        .collect();
    b.sort_by(f32::total_cmp);
    b[b.len() / 2]
}

/// Test f's texture case: the texture term t (texture/bandwidth.rs) makes a checkerboard
/// whose fundamental is 0.4 cycles/px sharp (b_p ≥ 0.25) on a plane that is smooth
/// (b_p < 0.05) without it, and a board of equal cells (a = b) stays smooth. The fine
/// board's t is its fundamental alone (the pixel's box filter removes the harmonics): b_p
/// 0.4. A board 16× coarser keeps harmonics up to the 7th: b_p 7·0.4/16 = 0.175.
#[test]
fn a_texture_at_0_4_cycles_per_pixel_is_sharp() {
    // The view is 2·4·tan 20° = 2.91 m over 48 px; 0.4 cycles/px is a period of 2.5 px =
    // 0.152 m, two cells of 0.076 m: uv_scale 3 m / 0.076 m = 39.6 on the 3 m plane.
    let fine = run(
        &textured_plane(r#"{"type": "checkerboard", "a": 0.1, "b": 0.7, "uv_scale": 39.6}"#),
        true,
    );
    let flat = run(
        &textured_plane(r#"{"type": "checkerboard", "a": 0.4, "b": 0.4, "uv_scale": 39.6}"#),
        true,
    );
    let coarse = run(
        &textured_plane(r#"{"type": "checkerboard", "a": 0.1, "b": 0.7, "uv_scale": 2.475}"#),
        true,
    );
    let (b_fine, b_flat, b_coarse) = (median_b_p(&fine), median_b_p(&flat), median_b_p(&coarse));
    eprintln!("checkerboard b_p (median): 0.4 cycles/px {b_fine}, equal cells {b_flat}, 16× coarser {b_coarse}");
    assert!(b_fine >= 0.25, "{b_fine}");
    assert!(b_flat < 0.05, "{b_flat}");
    assert!((b_fine / 0.4 - 1.0).abs() < 0.2, "{b_fine}");
    assert!((b_coarse / 0.175 - 1.0).abs() < 0.2, "{b_coarse}");
}

/// fBm in world space on the same plane: 4 octaves, 2 noise units per metre, gain 0.5,
/// lacunarity 2. A pixel spans 0.0607 m = 0.121 noise units; the lookup keeps octave i while
/// 2·0.121·2ⁱ ≤ 1, so octaves 0–2 (energies 1, ¼, 1/16); octaves 0–1 hold 95.2 % of that:
/// t = β·2·2 cycles/m and b_p = t·0.0607 m/px.
#[test]
fn world_space_noise_gives_its_finest_resolved_octave() {
    let p = run(
        &textured_plane(
            r#"{"type": "noise", "noise": "fbm", "space": "world", "frequency": 2,
                "octaves": 4, "gain": 0.5, "lacunarity": 2, "a": 0.1, "b": 0.8}"#,
        ),
        true,
    );
    let b = median_b_p(&p);
    let expected =
        prism_render::texture::bandwidth::PERLIN_BETA_CYCLES_PER_UNIT * 2.0 * 2.0 * 0.0607;
    eprintln!("world fBm: b_p median {b}, expected {expected}");
    assert!((b / expected - 1.0).abs() < 0.25, "{b} vs {expected}");
}

/// Test f's mirror case: a mirror sphere reflecting the sun (0.53°) is sharp (b_p ≥ 0.25)
/// in the pixels whose reflected footprint reaches the sun's disk — the highlight covers a
/// fraction of one pixel here, and the probe's mirror direction from the centre ray misses
/// it — and smooth where the sphere reflects only the uniform sky; with the sun behind the
/// sphere only the rim is sharp, where the mirror shows what lies behind it.
#[test]
fn a_mirror_sphere_reflecting_the_sun_is_sharp_at_the_highlight() {
    let scene_with_sun = |material: &str, travel: &str| {
        build(&format!(
            r#"{{"camera": {{"type": "pinhole", "fov_deg": 30,
                "transform": {{"look_at": {{"eye": [0, 0, 4], "target": [0, 0, 0]}}}}}},
            "film": {{"resolution": [48, 48]}},
            "materials": {{"ball": {material}}},
            "shapes": [{{"type": "sphere", "radius_m": 0.5, "material": "ball"}}],
            "lights": [{{"type": "directional", "direction": {travel},
                        "angular_diameter_deg": 0.53, "illuminance_lx": 100000}},
                       {{"type": "sky", "spectrum": 1.0}}]}}"#
        ))
    };
    let mirror = run(
        &scene_with_sun(
            r#"{"type": "conductor", "metal": "Ag"}"#,
            "[-0.3, -0.4, -1]",
        ),
        true,
    );
    // Pixels on the sphere (not background).
    let on_sphere: Vec<usize> = (0..48 * 48)
        .filter(|&i| mirror.class[i] != prism_bandwidth::PixelClass::Background)
        .collect();
    let b = |p: &Prediction, i: usize| p.pixels[i].image_bandwidth_cycles_per_px;
    let sharp: Vec<usize> = on_sphere
        .iter()
        .copied()
        .filter(|&i| b(&mirror, i) >= 0.25)
        .collect();
    let smooth = on_sphere.iter().filter(|&&i| b(&mirror, i) < 0.05).count();
    eprintln!(
        "mirror sphere: {} pixels, {} sharp ({:?}), {smooth} smooth",
        on_sphere.len(),
        sharp.len(),
        sharp.iter().map(|i| (i % 48, i / 48)).collect::<Vec<_>>()
    );
    assert!(
        !sharp.is_empty() && sharp.len() <= 12,
        "{} sharp pixels",
        sharp.len()
    );
    assert!(
        smooth >= on_sphere.len() * 3 / 4,
        "{smooth} of {}",
        on_sphere.len()
    );
    // The highlight sits where the sphere's normal halves the view and sun directions.
    let half = (glam::Vec3A::new(0.3, 0.4, 1.0).normalize() + glam::Vec3A::Z).normalize();
    let highlight = 0.5 * half;
    let px = |i: usize| glam::Vec2::new((i % 48) as f32 + 0.5, (i / 48) as f32 + 0.5);
    // Projected: 48 px over 2·4·tan 15° m at the sphere's depth (≈ 3.55 m for the cap).
    let scale = 48.0 / (2.0 * (4.0 - highlight.z) * 15f32.to_radians().tan());
    let expected = glam::Vec2::new(24.0 + highlight.x * scale, 24.0 - highlight.y * scale);
    assert!(
        sharp.iter().any(|&i| px(i).distance(expected) < 2.0),
        "no sharp pixel near the highlight at {expected}"
    );
    // The sun behind the sphere: a mirror sphere reflects every direction, those behind it
    // squeezed into a thin ring at the silhouette, so the sun's image moves to the rim.
    let behind = run(
        &scene_with_sun(r#"{"type": "conductor", "metal": "Ag"}"#, "[0.3, 0.4, 1]"),
        true,
    );
    let rim: Vec<usize> = on_sphere
        .iter()
        .copied()
        .filter(|&i| b(&behind, i) >= 0.25)
        .collect();
    eprintln!(
        "sun behind: sharp pixels {:?}",
        rim.iter().map(|i| (i % 48, i / 48)).collect::<Vec<_>>()
    );
    let radius_px = 0.5 * 48.0 / (2.0 * 4.0 * 15f32.to_radians().tan());
    assert!(!rim.is_empty());
    for &i in &rim {
        let r = px(i).distance(glam::Vec2::splat(24.0));
        assert!(
            r > 0.8 * radius_px,
            "pixel {:?} at {r} px from the centre",
            px(i)
        );
    }
}

/// Pixels that see the sky directly take the bandwidth of what they look at: the sun's
/// disk (0.53°) is sharp (b_p ≥ 0.25) in the pixels whose footprint reaches it, the uniform
/// sky around it smooth (b_p < 0.05). Before, every background pixel took the largest ν_a
/// of all infinite lights, so a sun anywhere made the whole sky "sharp" (b_p 1.66 here).
#[test]
fn the_sun_disk_is_sharp_and_the_sky_beside_it_smooth() {
    let scene = build(
        r#"{"camera": {"type": "pinhole", "fov_deg": 30,
            "transform": {"look_at": {"eye": [0, 0, 0], "target": [0.3, 1, 0.4], "up": [0, 0, 1]}}},
        "film": {"resolution": [33, 33]},
        "materials": {"white": {"type": "lambert", "reflectance": 0.5}},
        "shapes": [{"type": "sphere", "radius_m": 0.1, "material": "white",
                    "transform": {"translate": [0, -5, 0]}}],
        "lights": [{"type": "directional", "direction": [-0.3, -1, -0.4],
                    "angular_diameter_deg": 0.53, "illuminance_lx": 100000},
                   {"type": "sky", "spectrum": 1.0}]}"#,
    );
    let p = run(&scene, true);
    let b = |x: usize, y: usize| p.pixels[y * 33 + x].image_bandwidth_cycles_per_px;
    assert!(
        b(16, 16) >= 0.25,
        "the pixel looking at the sun: b_p {}",
        b(16, 16)
    );
    let mut sharp = 0;
    for (i, (class, pixel)) in p.class.iter().zip(&p.pixels).enumerate() {
        assert_eq!(*class, prism_bandwidth::PixelClass::Background, "pixel {i}");
        let (x, y) = ((i % 33) as i32 - 16, (i / 33) as i32 - 16);
        if x.abs() > 3 || y.abs() > 3 {
            assert!(
                pixel.image_bandwidth_cycles_per_px < 0.05,
                "sky pixel ({x}, {y}) from the sun: b_p {}",
                pixel.image_bandwidth_cycles_per_px
            );
        } else {
            sharp += usize::from(pixel.image_bandwidth_cycles_per_px >= 0.25);
        }
    }
    eprintln!("{sharp} pixels around the sun with b_p ≥ 0.25");
}

/// A sphere on a grey floor under a uniform sky, seen from a little above: a mirror or
/// smooth glass shows the floor's horizon inside its outline, a step the G-buffer alone
/// does not see (one material, a smooth surface). The pixels along it are edges (eq. 11's
/// finest level, b_p = 2); a rough metal shows no step, and no interior pixel is one.
#[test]
fn a_horizon_seen_in_a_mirror_or_through_glass_is_an_edge() {
    let interior_edges = |material: &str| {
        let scene = build(&format!(
            r#"{{"camera": {{"type": "pinhole", "fov_deg": 20,
                "transform": {{"look_at": {{"eye": [0, 0.9, 6], "target": [0, 0.5, 0]}}}}}},
            "film": {{"resolution": [48, 48]}},
            "materials": {{"ball": {material},
                           "grey": {{"type": "lambert", "reflectance": 0.2}}}},
            "shapes": [{{"type": "sphere", "radius_m": 0.5, "material": "ball",
                         "transform": {{"translate": [0, 0.5, 0]}}}},
                       {{"type": "rectangle", "size_m": [400, 400], "material": "grey",
                         "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
            "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
        ));
        let p = run(&scene, true);
        let sphere = p.class[24 * 48 + 24];
        assert!(matches!(sphere, PixelClass::Material(_)), "{sphere:?}");
        // Sphere pixels whose four neighbours are on the sphere too (not its outline).
        (1..47)
            .flat_map(|y| (1..47).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                [(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)]
                    .iter()
                    .all(|&(dx, dy)| p.class[((y + dy) * 48 + x + dx) as usize] == sphere)
            })
            .filter(|&(x, y)| {
                p.pixels[(y * 48 + x) as usize].image_bandwidth_cycles_per_px
                    >= prism_bandwidth::pixel_prediction::MAX_IMAGE_BANDWIDTH_CYCLES_PER_PX
            })
            .count()
    };
    let mirror = interior_edges(r#"{"type": "conductor", "metal": "Ag"}"#);
    let glass = interior_edges(r#"{"type": "dielectric", "ior": 1.5}"#);
    let rough = interior_edges(r#"{"type": "conductor", "metal": "Ag", "roughness": 0.3}"#);
    eprintln!("interior edge pixels: mirror {mirror}, glass {glass}, rough metal {rough}");
    // The horizon crosses the sphere's image, about 14 px wide here.
    assert!(mirror >= 8, "mirror: {mirror}");
    assert!(glass >= 8, "glass: {glass}");
    assert_eq!(rough, 0);
}

/// Hierarchical shading (§3.2) on the hard-shadow scene: the floor is interpolated from a
/// lattice, but no interpolated pixel takes a parent on the other side of the shadow edge
/// (the min-filtered cells), and the plan's budget is unchanged.
#[test]
fn hierarchical_shading_never_interpolates_across_a_shadow_edge() {
    let scene = hard_shadow_scene();
    let mut p = run(&scene, true);
    let before = p.allocated.relative_density.iter().sum::<f32>();
    let upsampling = p.make_hierarchical(3, 16.0, 1).unwrap();
    let after = p.allocated.relative_density.iter().sum::<f32>();
    assert!((before - after).abs() < 1e-3 * before, "{before} → {after}");
    let interpolated = upsampling.upsampled();
    assert!(
        interpolated.len() > 48 * 48 / 2,
        "{} pixels interpolated",
        interpolated.len()
    );
    let lit = |i: usize| p.pixels[i].visibility.visible_share().map(|s| s > 0.5);
    for u in interpolated {
        for &(parent, _) in u.parents() {
            assert_eq!(
                lit(u.index as usize),
                lit(parent as usize),
                "pixel {} interpolated from {parent} across the shadow edge",
                u.index
            );
        }
        let pixel = glam::UVec2::new(u.index % 48, u.index / 48);
        assert_eq!(p.allocated.plan.camera_samples(pixel), 0);
    }
}

/// The hard-shadow scene seen from 4 m above through a 50 mm f/1.0 lens focused at
/// `focus_m` (the floor is 4 m away), 48 × 48 px.
fn hard_shadow_through_a_lens_focused_at(focus_m: f32) -> RenderScene {
    hard_shadow_scene_seen_by(&format!(
        r#""camera": {{"type": "thin_lens", "focal_length_mm": 50, "f_number": 1.0,
            "focus_distance_m": {focus_m},
            "transform": {{"look_at": {{"eye": [0, 4, 0], "target": [0, 0, 0],
                "up": [0, 0, -1]}}}}}},
        "film": {{"resolution": [48, 48]}}"#
    ))
}

/// A thin lens low-passes what lies out of focus (Soler et al. 2009): b_p on the edge of a
/// hard shadow (sharp, b_p ≥ 0.25, in focus) is capped by the circle of confusion's cut-off
/// (1.22 / CoC cycles/px) when the floor is out of focus, so two defocus settings give b_p
/// in the inverse ratio of their CoCs (within ×1.5, the issue's test), and the floor in
/// focus keeps its own b_p.
#[test]
fn defocus_caps_b_p_by_the_circle_of_confusion() {
    let scene = hard_shadow_through_a_lens_focused_at;
    // The largest b_p on the floor (depth 4 m; the box top is nearer).
    let max_b = |focus_m: f32| -> (f32, f32) {
        let s = scene(focus_m);
        let prism_render::camera::Camera::ThinLens(lens) = &s.camera else {
            panic!("a thin lens");
        };
        let coc = lens.circle_of_confusion_px(glam::Vec3A::ZERO);
        let p = run(&s, true);
        let b = p
            .pixels
            .iter()
            .zip(&p.surface)
            .filter(|(_, s)| s.is_some_and(|s| s.position_m.y.abs() < 1e-3))
            .map(|(x, _)| x.image_bandwidth_cycles_per_px)
            .fold(0.0f32, f32::max);
        (b, coc)
    };
    let (focused, coc_focused) = max_b(4.0);
    let (near, coc_near) = max_b(1.0);
    let (nearer, coc_nearer) = max_b(0.5);
    eprintln!(
        "max b_p on the floor: in focus {focused:.3} (CoC {coc_focused:.2} px), focus 1 m \
         {near:.3} (CoC {coc_near:.2} px), focus 0.5 m {nearer:.3} (CoC {coc_nearer:.2} px)"
    );
    assert!(coc_focused < 1e-3 && coc_near > 2.0 && coc_nearer > coc_near * 2.0);
    assert!(
        focused >= 0.25 && focused > near && near > nearer,
        "{focused} {near} {nearer}"
    );
    let ratio = (near / nearer) / (coc_nearer / coc_near);
    assert!(
        (1.0 / 1.5..=1.5).contains(&ratio),
        "b_p ratio / CoC ratio {ratio}"
    );
}

/// A thin lens mixes what neighbouring pinhole pixels see (prism_bandwidth::defocus_mixing):
/// out of focus, floor pixels near the hard shadow's edge take lit and shadowed points (and
/// the brighter plate) through the lens, so their per-sample variance is that of the
/// radiances' mixture: at least a sixth of L_floor² where the window straddles the edge and
/// at most ¼ of the brightest pixel's L² (the largest variance of values in [0, L_max]) plus
/// what the pixels had. In focus the point light leaves the floor without shading variance.
#[test]
fn defocus_mixes_the_radiances_within_the_circle_of_confusion() {
    let scene = hard_shadow_through_a_lens_focused_at;
    // (floor pixels with V̂ ≥ 0.05 L_floor², their largest V̂, lit floor L, brightest L).
    let floor = |focus_m: f32| -> (usize, f32, f32, f32) {
        let p = run(&scene(focus_m), true);
        let on_floor: Vec<usize> = (0..p.pixels.len())
            .filter(|&i| p.surface[i].is_some_and(|s| s.position_m.y.abs() < 1e-3))
            .collect();
        let largest = |v: &mut dyn Iterator<Item = f32>| v.fold(0.0f32, f32::max);
        let lit = largest(&mut on_floor.iter().map(|&i| p.pixels[i].mean_y));
        let brightest = largest(&mut p.pixels.iter().map(|x| x.mean_y));
        let max_v = largest(&mut on_floor.iter().map(|&i| p.pixels[i].luminance_variance));
        let wide = on_floor
            .iter()
            .filter(|&&i| p.pixels[i].luminance_variance >= 0.05 * lit * lit)
            .count();
        (wide, max_v, lit, brightest)
    };
    let (focused_wide, focused_max, lit, brightest) = floor(4.0);
    let (defocused_wide, defocused_max, ..) = floor(1.0);
    eprintln!(
        "floor pixels with V̂ ≥ 0.05 L²: in focus {focused_wide} (max V̂ {focused_max:.3e}), \
         focus 1 m {defocused_wide} (max {defocused_max:.3e}); lit floor L̂ {lit:.3e}, \
         brightest {brightest:.3e}"
    );
    assert!(lit > 0.0 && focused_wide == 0);
    assert!(
        defocused_max >= lit * lit / 6.0
            && defocused_max <= 0.25 * brightest * brightest + focused_max,
        "{defocused_max}: L_floor² {}, L_max² {}",
        lit * lit,
        brightest * brightest
    );
    assert!(defocused_wide >= 24, "{defocused_wide} pixels mixed");
}

/// `--plan-colour off` leaves the colour noise out of V̂_p: under an F11 lamp (three narrow
/// lines) a red Lambertian plane's hero-wavelength estimates scatter in X, Y and Z alike,
/// so with the term every lit pixel's V̂_p is larger than its luminance part, and without
/// it V̂_p is the luminance part exactly.
#[test]
fn the_colour_term_adds_the_lanes_noise_and_can_be_left_out() {
    let scene = build(&format!(
        r#"{{{CAMERA}, "materials": {{"red": {{"type": "lambert", "reflectance": {{"rgb": [0.8, 0.1, 0.1]}}}},
            "black": {{"type": "lambert", "reflectance": 0.0}}}},
        "shapes": [{{"type": "rectangle", "size_m": [3, 3], "material": "red",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
            {{"type": "rectangle", "name": "lamp", "size_m": [0.5, 0.5], "material": "black",
            "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, 2, 0]}}]}}],
        "lights": [{{"type": "area", "shape": "lamp", "spectrum": "F11", "luminance_cd_m2": 1000}}]}}"#
    ));
    let with = predict(&scene, &PredictorSettings::defaults(16.0, 1), 1).unwrap();
    let without = predict(
        &scene,
        &PredictorSettings {
            colour_noise: false,
            ..PredictorSettings::defaults(16.0, 1)
        },
        1,
    )
    .unwrap();
    let lit: Vec<usize> = (0..with.pixels.len())
        .filter(|&i| with.pixels[i].mean_y > 0.0)
        .collect();
    assert!(lit.len() > 1000, "{} lit pixels", lit.len());
    for &i in &lit {
        let (a, b) = (&with.pixels[i], &without.pixels[i]);
        assert!(a.variance > 1.5 * a.luminance_variance, "pixel {i}: {a:?}");
        assert_eq!(b.variance, b.luminance_variance, "pixel {i}");
        assert_eq!(a.luminance_variance, b.luminance_variance, "pixel {i}");
    }
}

/// Pooling scales V̂ and L̂ by each pixel's texel (ρ_p): a checkerboard of 0.1 and 0.7 in
/// 3-px cells under a uniform sky (every 5 × 5 pooling window holds both) keeps V̂ ∝ ρ²,
/// where the plain window mean gave both cells one value; and with black cells (ρ = 0) a
/// dark pixel beside a bright one is not pooled to a noiseless 0: its scale is kept at a
/// tenth of the surface's mean.
#[test]
fn pooling_keeps_a_texture_s_pattern_and_no_texel_goes_dark() {
    let checks = |a: f32| {
        let scene = build(&format!(
            r#"{{{CAMERA},
            "materials": {{"checks": {{"type": "lambert", "reflectance":
                {{"texture": {{"type": "checkerboard", "a": {a}, "b": 0.7, "uv_scale": [8, 8]}}}}}}}},
            "shapes": [{{"type": "rectangle", "size_m": [3, 3], "material": "checks",
                "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}}],
            "lights": [{{"type": "sky", "spectrum": 1.0}}]}}"#
        ));
        run(&scene, true)
    };
    // The raw probe mean tells a pixel's cell; its pooled V̂ must follow the cell.
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let p = checks(0.1);
    let (mut dark, mut bright): (Vec<f32>, Vec<f32>) = (Vec::new(), Vec::new());
    for pixel in &p.pixels {
        if pixel.mean_y < 0.35 {
            dark.push(pixel.luminance_variance);
        } else {
            bright.push(pixel.luminance_variance);
        }
    }
    assert!(dark.len() > 200 && bright.len() > 200);
    let expected = (0.1f32 / 0.7).powi(2);
    let got = median(&mut dark) / median(&mut bright);
    assert!(
        got > expected / 2.0 && got < expected * 2.0,
        "V̂ dark/bright {got}, expected {expected}"
    );
    let p = checks(0.0);
    let w = p.resolution.x as usize;
    let bright_cell = |i: usize| p.pixels[i].mean_y > 0.35;
    let mut beside_bright = 0;
    for (i, pixel) in p.pixels.iter().enumerate() {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        let near_bright = (-2..=2).any(|dy| {
            (-2..=2).any(|dx| {
                let (xx, yy) = (x + dx, y + dy);
                (0..w as i64).contains(&xx)
                    && (0..p.resolution.y as i64).contains(&yy)
                    && bright_cell((yy * w as i64 + xx) as usize)
            })
        });
        if pixel.mean_y == 0.0 && near_bright {
            beside_bright += 1;
            assert!(
                pixel.luminance_variance > 0.0,
                "black texel {i} pooled to V̂ = 0"
            );
        }
    }
    assert!(
        beside_bright > 100,
        "{beside_bright} black pixels beside bright ones"
    );
}

/// `--plan-probe-stride 2`: a quarter of the floor's pixels are probed, the others borrow;
/// the shadow's edge stays sharp (within a pixel of where the full probe puts it) and the
/// pooled L̂ stays the full probe's.
#[test]
fn a_sparse_probe_keeps_the_shadow_edge_and_the_pooled_mean() {
    let scene = hard_shadow_scene();
    let full = run(&scene, true);
    let sparse = predict(
        &scene,
        &PredictorSettings {
            probe_stride: prism_bandwidth::ProbeStride::Px(2),
            ..PredictorSettings::defaults(16.0, 1)
        },
        1,
    )
    .unwrap();
    let probed = sparse
        .pixels
        .iter()
        .filter(|p| p.visibility.traced > 0 && p.measured_variance > 0.0)
        .count();
    let lit = full.pixels.iter().filter(|p| p.mean_y > 0.0).count();
    assert!(lit > 48 * 40, "{lit} lit pixels");
    // Every lit pixel has an answer, pooled from its probed neighbours.
    let dark = (0..48 * 48)
        .filter(|&i| full.pixels[i].mean_y > 0.0 && sparse.pixels[i].mean_y <= 0.0)
        .count();
    assert_eq!(dark, 0, "lit pixels the sparse probe left at L̂ = 0");
    // The probed pixels' L̂ are the full probe's (each pixel's samples are seeded by the
    // pixel), the others' are means of probed neighbours: the sparse image's mean L̂ over the
    // lit pixels estimates the full one's from a sample of `probed` of them, with standard
    // error σ·√(1/probed − 1/lit) (σ the full probe's spread over the lit pixels, which
    // holds the image's own variation too, so the bound is loose, not tight).
    let lit_values: Vec<f64> = full
        .pixels
        .iter()
        .filter(|p| p.mean_y > 0.0)
        .map(|p| f64::from(p.mean_y))
        .collect();
    let mean_full = lit_values.iter().sum::<f64>() / lit as f64;
    let sigma = (lit_values
        .iter()
        .map(|v| (v - mean_full).powi(2))
        .sum::<f64>()
        / (lit - 1) as f64)
        .sqrt();
    let mean_sparse = (0..48 * 48)
        .filter(|&i| full.pixels[i].mean_y > 0.0)
        .map(|i| f64::from(sparse.pixels[i].mean_y))
        .sum::<f64>()
        / lit as f64;
    let standard_error = sigma * (1.0 / probed as f64 - 1.0 / lit as f64).sqrt();
    eprintln!(
        "mean L̂ over the lit pixels: sparse {mean_sparse}, full {mean_full}, s.e. {standard_error}"
    );
    assert!(
        (mean_sparse - mean_full).abs() < 4.0 * standard_error,
        "mean L̂: sparse {mean_sparse}, full {mean_full}, 4 s.e. {}",
        4.0 * standard_error
    );
    // Sharp pixels of the sparse probe lie within a pixel of the full probe's.
    let sharp = |p: &Prediction| -> Vec<bool> {
        p.pixels
            .iter()
            .map(|x| x.image_bandwidth_cycles_per_px >= 0.25)
            .collect()
    };
    let (sharp_full, sharp_sparse) = (sharp(&full), sharp(&sparse));
    let near_full = |i: usize| {
        let (x, y) = ((i % 48) as i32, (i / 48) as i32);
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (xx, yy) = (x + dx, y + dy);
                (0..48).contains(&xx)
                    && (0..48).contains(&yy)
                    && sharp_full[(yy * 48 + xx) as usize]
            })
        })
    };
    let count_sparse = sharp_sparse.iter().filter(|b| **b).count();
    let stray = (0..48 * 48)
        .filter(|&i| sharp_sparse[i] && !near_full(i))
        .count();
    eprintln!(
        "sparse probe: {probed} probed of {lit} lit pixels; sharp pixels {count_sparse} (full {}), {stray} away from the full probe's",
        sharp_full.iter().filter(|b| **b).count()
    );
    assert!(probed * 3 < lit, "{probed} probed of {lit}");
    assert!(count_sparse > 20, "{count_sparse} sharp pixels");
    assert_eq!(stray, 0);
}

/// A fog box around the camera's view (an `interface` boundary, as
/// scenes/cornell-box-fog.json has): the predictor looks past it as the render's rays do.
/// Before, every pixel's "surface" was the boundary and every shadow ray stopped on it, so
/// nothing was predicted and the plan was uniform.
#[test]
fn the_predictor_looks_past_medium_interfaces() {
    let scene = build(&format!(
        r#"{{{CAMERA},
        "materials": {{"white": {{"type": "lambert", "reflectance": 0.7}},
                       "boundary": {{"type": "interface"}}}},
        "media": {{"fog": {{"type": "homogeneous", "sigma_a_per_m": 0.01, "sigma_s_per_m": 0.2}}}},
        "shapes": [
          {{"type": "rectangle", "size_m": [20, 20], "material": "white",
            "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
          {{"type": "cuboid", "size_m": [0.8, 0.1, 0.8], "material": "white",
            "transform": {{"translate": [0.3, 0.5, 0]}}}},
          {{"type": "cuboid", "size_m": [3, 3, 3], "material": "boundary",
            "interior_medium": "fog", "transform": {{"translate": [0, 1.4, 0]}}}}],
        "lights": [{{"type": "point", "position_m": [0.3, 2.5, 0], "spectrum": 1.0, "scale": 10, "medium": "fog"}}]}}"#
    ));
    let p = run(&scene, true);
    let boundary_id = scene
        .material_names
        .iter()
        .position(|n| n == "boundary")
        .unwrap() as u32;
    let on_boundary = p
        .class
        .iter()
        .filter(|c| **c == PixelClass::Material(boundary_id))
        .count();
    let lit = p.pixels.iter().filter(|x| x.mean_y > 0.0).count();
    let sharp = p
        .pixels
        .iter()
        .filter(|x| x.image_bandwidth_cycles_per_px >= 0.25)
        .count();
    eprintln!("fog box: {on_boundary} pixels on the boundary, {lit} lit, {sharp} sharp");
    assert_eq!(on_boundary, 0);
    // The floor and the box top are lit (the box's shadow is not), and the shadow's edge
    // is found through the boundary.
    assert!(lit > 48 * 40, "{lit} lit pixels");
    assert!(sharp > 20, "{sharp} sharp pixels");
}

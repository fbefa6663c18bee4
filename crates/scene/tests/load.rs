//! Scenes that load: defaults for a minimal scene, and every field kind coming through.

mod common;

use common::Dir;
use glam::DVec3;
use prism_scene::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn minimal_scene_loads_with_defaults() {
    let dir = Dir::new("minimal");
    let s = dir
        .load(r#"{ "shapes": [ { "type": "sphere" } ] }"#)
        .unwrap();
    assert_eq!(s.camera, Camera::default());
    let CameraKind::Pinhole { fov_rad, fov_axis } = s.camera.kind else {
        panic!()
    };
    assert!(close(fov_rad, 60f64.to_radians()));
    assert_eq!(fov_axis, FovAxis::Horizontal);
    assert_eq!(s.film.resolution, [640, 480]);
    assert_eq!(s.film.spp, 16);
    assert_eq!(s.film.seed, 0);
    assert_eq!(s.film.output, None);
    assert_eq!(
        s.film.filter,
        PixelFilter::Gaussian {
            radius_px: 1.5,
            sigma_px: 0.5
        }
    );
    assert!(matches!(
        s.integrator,
        Integrator::Path { max_depth: 8, .. }
    ));
    assert_eq!(s.shapes.len(), 1);
    assert_eq!(s.shapes[0].kind, ShapeKind::Sphere { radius_m: 1.0 });
    assert_eq!(s.shapes[0].material, None);
    assert_eq!(s.shapes[0].transform, Transform::IDENTITY);
    assert!(s.lights.is_empty() && s.materials.is_empty() && s.media.is_empty());
}

#[test]
fn empty_object_is_a_scene() {
    let dir = Dir::new("empty");
    let s = dir.load("{}").unwrap();
    assert!(s.shapes.is_empty());
}

const ALL_FIELDS: &str = r#"{
  "camera": {
    "type": "thin_lens",
    "transform": [{"look_at": {"eye": [0, 1, 5], "target": [0, 1, 0], "up": [0, 1, 0]}}],
    "focal_length_mm": 50, "sensor_width_mm": 36, "f_number": 2.8, "focus_distance_m": 5
  },
  "film": {
    "resolution": [320, 240], "spp": 64, "seed": 7, "output": "out/render.png",
    "filter": {"type": "mitchell", "radius_px": 2, "b": 0.5, "c": 0.25},
    "aovs": ["depth", "normal", "albedo", "position"]
  },
  "integrator": {"type": "path", "max_depth": 5, "sampler": "independent", "mis": "balance", "rr_depth": 2},
  "spectra": {
    "warm": {"blackbody_k": 2700},
    "paint": "spectra/paint.csv",
    "leaf": {"file": "spectra/two.csv", "column": "leaf"},
    "daylight": "d65",
    "pinkish": {"rgb": [0.9, 0.5, 0.6]},
    "flat": 0.25,
    "again": "warm"
  },
  "media": {
    "fog": {"type": "homogeneous", "sigma_a_per_m": 0.01, "sigma_s_per_m": "flat", "g": 0.3}
  },
  "materials": {
    "white": {"type": "lambert", "reflectance": "paint"},
    "gold": {"type": "conductor", "metal": "Au", "roughness": [0.1, 0.3], "distribution": "beckmann"},
    "custom_metal": {"type": "conductor", "eta": 0.2, "k": 3.0},
    "glass": {"type": "dielectric", "ior": {"sellmeier": {"b": [1.03961212, 0.231792344, 1.01046945], "c_um2": [0.00600069867, 0.0200179144, 103.560653]}}},
    "flint": {"type": "dielectric", "ior": {"cauchy": {"a": 1.67, "b_um2": 0.0074}}, "roughness": 0.05},
    "water": {"type": "dielectric", "ior": 1.333},
    "sheet": {"type": "two_sided", "material": "white"},
    "leafy": {"type": "mask", "material": "sheet", "opacity": 0.4}
  },
  "meshes": {"bunny": "meshes/bunny.ply", "teapot": {"file": "meshes/teapot.obj"}},
  "shapes": [
    {"type": "mesh", "file": "meshes/teapot.obj", "material": "gold"},
    {"type": "mesh", "mesh": "bunny"},
    {"type": "sphere", "radius_m": 0.5, "material": "glass", "interior_medium": "fog", "exterior_medium": "fog",
     "transform": {"translate": [1, 2, 3]}},
    {"type": "rectangle", "name": "lamp", "size_m": [2, 1]},
    {"type": "disk", "radius_m": 0.25},
    {"type": "cuboid", "size_m": [1, 2, 3], "transform": [{"scale": 2}, {"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}]},
    {"type": "instances", "mesh": "bunny", "instances": [{"translate": [1, 0, 0]}, [{"scale": [1, 2, 1]}]]}
  ],
  "lights": [
    {"type": "point", "position_m": [0, 2, 0], "power_lm": 800, "spectrum": "warm"},
    {"type": "spot", "position_m": [0, 3, 0], "target_m": [0, 0, 0], "cone_angle_deg": 20, "falloff_start_deg": 15, "intensity_cd": 1000},
    {"type": "directional", "direction": [0, -2, 0], "angular_diameter_deg": 0.53, "illuminance_lx": 100000},
    {"type": "area", "shape": "lamp", "luminance_cd_m2": 5000, "two_sided": true, "spectrum": "F11"},
    {"type": "environment", "file": "sky.exr", "scale": 2, "transform": {"rotate": {"axis": [0, 1, 0], "angle_deg": 45}}},
    {"type": "sky", "luminance_cd_m2": 3000, "spectrum": {"blackbody_k": 6500}}
  ]
}"#;

fn all_fields_dir() -> Dir {
    let dir = Dir::new("all-fields");
    dir.write(
        "spectra/paint.csv",
        "wavelength_nm,value\n400,0.7\n700,0.8\n",
    );
    dir.write(
        "spectra/two.csv",
        "wavelength_nm,bark,leaf\n400,0.1,0.05\n700,0.3,0.5\n",
    );
    dir.write("meshes/bunny.ply", "ply\n");
    dir.write("meshes/teapot.obj", "v 0 0 0\n");
    dir.write("sky.exr", "");
    dir
}

#[test]
fn every_field_kind_comes_through() {
    let dir = all_fields_dir();
    let s = dir.load(ALL_FIELDS).unwrap();

    // Camera: 50 mm on 36 mm → fov = 2·atan(18/50); f/2.8 → radius 50/5.6 mm.
    let CameraKind::ThinLens {
        focal_length_m,
        fov_rad,
        sensor_width_m,
        aperture_radius_m,
        f_number,
        focus_distance_m,
    } = s.camera.kind
    else {
        panic!("{:?}", s.camera.kind)
    };
    assert!(close(focal_length_m, 0.05));
    assert!(close(fov_rad, 2.0 * (18.0f64 / 50.0).atan()));
    assert!(close(sensor_width_m, 0.036));
    assert!(close(aperture_radius_m, 0.05 / 5.6));
    assert_eq!(f_number, Some(2.8));
    assert_eq!(focus_distance_m, 5.0);
    let eye = s.camera.transform.transform_point(DVec3::ZERO);
    assert!(eye.abs_diff_eq(DVec3::new(0.0, 1.0, 5.0), 1e-12));

    // Film.
    assert_eq!(s.film.resolution, [320, 240]);
    assert_eq!((s.film.spp, s.film.seed), (64, 7));
    assert_eq!(s.film.output, Some(dir.0.join("out/render.png")));
    assert_eq!(
        s.film.filter,
        PixelFilter::Mitchell {
            radius_px: 2.0,
            b: 0.5,
            c: 0.25
        }
    );
    assert_eq!(
        s.film.aovs,
        vec![Aov::Depth, Aov::Normal, Aov::Albedo, Aov::Position]
    );
    assert_eq!(
        s.integrator,
        Integrator::Path {
            max_depth: 5,
            sampler: SamplerKind::Independent,
            mis: MisHeuristic::Balance,
            rr_depth: 2,
            fluorescence_lanes: prism_scene::FluorescenceLanes::All,
            spectral_mis: true,
        }
    );

    // Every named file once (the teapot is named twice), resolved against the folder.
    let mut assets = s.asset_files.clone();
    assets.sort();
    let expected: Vec<_> = [
        "meshes/bunny.ply",
        "meshes/teapot.obj",
        "sky.exr",
        "spectra/paint.csv",
        "spectra/two.csv",
    ]
    .iter()
    .map(|f| dir.0.join(f))
    .collect();
    assert_eq!(assets, expected);

    // Spectra, in file order, references inlined.
    let names: Vec<&str> = s.spectra.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["warm", "paint", "leaf", "daylight", "pinkish", "flat", "again"]
    );
    assert_eq!(
        s.spectra[0].1,
        SpectrumRef::Blackbody {
            temperature_k: 2700.0
        }
    );
    let SpectrumRef::File { path, table, .. } = &s.spectra[1].1 else {
        panic!()
    };
    assert_eq!(path, &dir.0.join("spectra/paint.csv"));
    assert!(close(table.eval(550.0), 0.75));
    let SpectrumRef::File { column, table, .. } = &s.spectra[2].1 else {
        panic!()
    };
    assert_eq!(column, "leaf");
    assert!(close(table.eval(700.0), 0.5));
    assert!(matches!(
        s.spectra[3].1,
        SpectrumRef::Illuminant { name: "D65", .. }
    ));
    assert_eq!(
        s.spectra[4].1,
        SpectrumRef::Rgb {
            rgb: [0.9, 0.5, 0.6]
        }
    );
    assert_eq!(s.spectra[5].1, SpectrumRef::Constant(0.25));
    assert_eq!(s.spectra[6].1, s.spectra[0].1);

    // Media.
    assert_eq!(s.media.len(), 1);
    assert_eq!(s.media[0].kind, MediumKind::Homogeneous);
    assert_eq!(s.media[0].sigma_a_per_m, SpectrumRef::Constant(0.01));
    assert_eq!(s.media[0].sigma_s_per_m, SpectrumRef::Constant(0.25));
    assert_eq!(s.media[0].phase, Phase::HenyeyGreenstein { g: 0.3 });
    assert_eq!(s.media[0].emission, None);

    // Materials.
    let m: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        m,
        [
            "white",
            "gold",
            "custom_metal",
            "glass",
            "flint",
            "water",
            "sheet",
            "leafy"
        ]
    );
    assert_eq!(
        s.materials[0].kind,
        MaterialKind::Lambert {
            reflectance: prism_scene::SpectrumParam::Spectrum(s.spectra[1].1.clone())
        }
    );
    assert_eq!(
        s.materials[1].kind,
        MaterialKind::Conductor {
            optics: ConductorOptics::Named("Au"),
            roughness: Roughness {
                alpha_u: 0.1,
                alpha_v: 0.3
            },
            distribution: Microfacet::Beckmann,
            roughness_texture: None
        }
    );
    assert!(matches!(
        &s.materials[2].kind,
        MaterialKind::Conductor {
            optics: ConductorOptics::Spectra { .. },
            ..
        }
    ));
    assert!(matches!(
        s.materials[3].kind,
        MaterialKind::Dielectric {
            ior: Ior::Sellmeier { .. },
            ..
        }
    ));
    assert!(matches!(
        s.materials[4].kind,
        MaterialKind::Dielectric {
            ior: Ior::Cauchy { a: 1.67, .. },
            roughness: Roughness { alpha_u: 0.05, .. },
            distribution: Microfacet::Ggx,
            roughness_texture: None
        }
    ));
    assert!(matches!(
        s.materials[5].kind,
        MaterialKind::Dielectric {
            ior: Ior::Constant(1.333),
            ..
        }
    ));
    assert_eq!(s.materials[6].kind, MaterialKind::TwoSided { material: 0 });
    assert_eq!(
        s.materials[7].kind,
        MaterialKind::Mask {
            material: 6,
            opacity: 0.4,
            opacity_texture: None
        }
    );

    // Meshes: the section first, then files named on shapes.
    assert_eq!(s.meshes.len(), 3);
    assert_eq!(s.meshes[0].name.as_deref(), Some("bunny"));
    assert_eq!(s.meshes[0].format, MeshFormat::Ply);
    assert_eq!(s.meshes[0].path, dir.0.join("meshes/bunny.ply"));
    assert_eq!(s.meshes[2].name, None);
    assert_eq!(s.meshes[2].format, MeshFormat::Obj);

    // Shapes.
    assert_eq!(s.shapes[0].kind, ShapeKind::Mesh { mesh: 2 });
    assert_eq!(s.shapes[0].material, Some(1));
    assert_eq!(s.shapes[1].kind, ShapeKind::Mesh { mesh: 0 });
    assert_eq!(s.shapes[2].kind, ShapeKind::Sphere { radius_m: 0.5 });
    assert_eq!(
        (s.shapes[2].interior_medium, s.shapes[2].exterior_medium),
        (Some(0), Some(0))
    );
    assert_eq!(
        s.shapes[2].transform.transform_point(DVec3::ZERO),
        DVec3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(s.shapes[3].name.as_deref(), Some("lamp"));
    assert_eq!(
        s.shapes[3].kind,
        ShapeKind::Rectangle { size_m: [2.0, 1.0] }
    );
    assert_eq!(s.shapes[4].kind, ShapeKind::Disk { radius_m: 0.25 });
    assert_eq!(
        s.shapes[5].kind,
        ShapeKind::Cuboid {
            size_m: [1.0, 2.0, 3.0]
        }
    );
    // scale 2, then 90° about +Y: +X → −Z, doubled.
    let x = s.shapes[5].transform.transform_point(DVec3::X);
    assert!(x.abs_diff_eq(DVec3::new(0.0, 0.0, -2.0), 1e-12), "{x}");
    let ShapeKind::Instances { mesh, transforms } = &s.shapes[6].kind else {
        panic!()
    };
    assert_eq!(*mesh, 0);
    assert_eq!(transforms.len(), 2);
    assert_eq!(transforms[0].transform_point(DVec3::ZERO), DVec3::X);
    assert_eq!(
        transforms[1].transform_point(DVec3::ONE),
        DVec3::new(1.0, 2.0, 1.0)
    );

    // Lights.
    assert_eq!(s.lights.len(), 6);
    assert_eq!(
        s.lights[0].kind,
        LightKind::Point {
            position_m: [0.0, 2.0, 0.0]
        }
    );
    assert_eq!(s.lights[0].strength, Strength::LuminousFluxLm(800.0));
    assert_eq!(s.lights[0].spectrum, s.spectra[0].1);
    let LightKind::Spot {
        direction,
        cone_angle_rad,
        falloff_start_rad,
        ..
    } = s.lights[1].kind
    else {
        panic!()
    };
    assert_eq!(direction, [0.0, -1.0, 0.0]);
    assert!(close(cone_angle_rad, 20f64.to_radians()));
    assert!(close(falloff_start_rad, 15f64.to_radians()));
    assert_eq!(s.lights[1].strength, Strength::IntensityCd(1000.0));
    assert!(matches!(
        s.lights[1].spectrum,
        SpectrumRef::Illuminant { name: "D65", .. }
    ));
    let LightKind::Directional {
        direction,
        angular_diameter_rad,
    } = s.lights[2].kind
    else {
        panic!()
    };
    assert_eq!(direction, [0.0, -1.0, 0.0]);
    assert!(close(angular_diameter_rad, 0.53f64.to_radians()));
    assert_eq!(s.lights[2].strength, Strength::IlluminanceLx(1e5));
    assert_eq!(
        s.lights[3].kind,
        LightKind::Area {
            shape: 3,
            two_sided: true
        }
    );
    assert_eq!(s.lights[3].strength, Strength::LuminanceCdM2(5000.0));
    assert!(matches!(
        s.lights[3].spectrum,
        SpectrumRef::Illuminant { name: "F11", .. }
    ));
    let LightKind::Environment { path, filter, .. } = &s.lights[4].kind else {
        panic!()
    };
    assert_eq!(path, &dir.0.join("sky.exr"));
    assert_eq!(*filter, EnvironmentFilter::Nearest, "the default");
    assert_eq!(s.lights[4].strength, Strength::Scale(2.0));
    assert_eq!(s.lights[5].kind, LightKind::UniformSky);
}

#[test]
fn camera_kinds_and_their_parameters() {
    let dir = Dir::new("cameras");
    let kind = |camera: &str| {
        dir.load(&format!(r#"{{"camera": {camera}}}"#))
            .unwrap()
            .camera
            .kind
    };
    assert_eq!(
        kind(r#"{"type": "pinhole", "fov_deg": 90, "fov_axis": "vertical"}"#),
        CameraKind::Pinhole {
            fov_rad: std::f64::consts::FRAC_PI_2,
            fov_axis: FovAxis::Vertical
        }
    );
    // Thin lens from a field of view and an aperture radius: f = (w/2) / tan(fov/2).
    let CameraKind::ThinLens {
        focal_length_m,
        aperture_radius_m,
        f_number,
        ..
    } = kind(
        r#"{"type": "thin_lens", "fov_deg": 90, "aperture_radius_m": 0.01, "focus_distance_m": 2}"#,
    )
    else {
        panic!()
    };
    assert!(close(focal_length_m, 0.018));
    assert_eq!((aperture_radius_m, f_number), (0.01, None));
    for (projection, fov, expected) in [
        ("equidistant", 360.0, FisheyeProjection::Equidistant),
        ("equisolid", 360.0, FisheyeProjection::Equisolid),
        ("orthographic", 180.0, FisheyeProjection::Orthographic),
        ("stereographic", 359.0, FisheyeProjection::Stereographic),
    ] {
        assert_eq!(
            kind(&format!(
                r#"{{"type": "fisheye", "projection": "{projection}", "fov_deg": {fov}, "fit": "cropped"}}"#
            )),
            CameraKind::Fisheye {
                projection: expected,
                fov_rad: f64::to_radians(fov),
                fit: FisheyeFit::Cropped
            }
        );
    }
    assert_eq!(
        kind(r#""fisheye""#),
        CameraKind::Fisheye {
            projection: FisheyeProjection::Equidistant,
            fov_rad: std::f64::consts::PI,
            fit: FisheyeFit::Circular
        }
    );
    assert_eq!(
        kind(r#"{"type": "orthographic", "width_m": 4}"#),
        CameraKind::Orthographic { width_m: 4.0 }
    );
    assert_eq!(kind(r#""spherical""#), CameraKind::Spherical);
}

#[test]
fn filters_and_diagnostic_integrators() {
    let dir = Dir::new("filters");
    let film = |filter: &str| {
        dir.load(&format!(r#"{{"film": {{"filter": {filter}}}}}"#))
            .unwrap()
            .film
            .filter
    };
    assert_eq!(film(r#""box""#), PixelFilter::Box { radius_px: 0.5 });
    assert_eq!(
        film(r#"{"type": "blackman_harris", "radius_px": 3}"#),
        PixelFilter::BlackmanHarris { radius_px: 3.0 }
    );
    assert_eq!(
        film(r#"{"type": "gaussian", "sigma_px": 0.7}"#),
        PixelFilter::Gaussian {
            radius_px: 1.5,
            sigma_px: 0.7
        }
    );
    let integrator = |i: &str| {
        dir.load(&format!(r#"{{"integrator": {i}}}"#))
            .unwrap()
            .integrator
    };
    assert_eq!(integrator(r#""depth""#), Integrator::Depth);
    assert_eq!(integrator(r#"{"type": "normal"}"#), Integrator::Normal);
    assert_eq!(integrator(r#""albedo""#), Integrator::Albedo);
    assert_eq!(
        integrator(r#"{"type": "ambient_occlusion", "max_distance_m": 0.5, "samples": 4}"#),
        Integrator::AmbientOcclusion {
            max_distance_m: Some(0.5),
            samples: 4
        }
    );
    assert_eq!(
        integrator(r#""ambient_occlusion""#),
        Integrator::AmbientOcclusion {
            max_distance_m: None,
            samples: 1
        }
    );
}

#[test]
fn parse_scene_str_resolves_assets_against_the_given_path() {
    let dir = Dir::new("from-str");
    dir.write("sub/meshes/box.obj", "v 0 0 0\n");
    let s = parse_scene_str(
        r#"{"shapes": [{"type": "mesh", "file": "meshes/box.obj"}]}"#,
        dir.0.join("sub/scene.json"),
    )
    .unwrap();
    assert_eq!(s.meshes[0].path, dir.0.join("sub/meshes/box.obj"));
    assert_eq!(s.file, dir.0.join("sub/scene.json"));
}

//! Building materials from scene JSON: every kind, wrappers, and the errors (file and
//! JSON path) for parameters that parse but cannot be rendered.

use glam::Vec3A;
use prism_geometry::SurfaceInteraction;
use prism_scene::parse_scene_str;
use prism_spectrum::{SampledSpectrum, SampledWavelengths};

use super::*;
use crate::bsdf::TransportMode;

fn scene_with(materials: &str) -> SceneDescription {
    let json = format!(
        r#"{{
      "camera": {{"type": "pinhole", "fov_deg": 40,
                 "transform": {{"look_at": {{"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
      "film": {{"resolution": [4, 4]}},
      "materials": {{{materials}}},
      "shapes": [{{"type": "sphere", "radius_m": 1}}]
    }}"#
    );
    parse_scene_str(&json, "scenes/test.json").unwrap_or_else(|e| panic!("{e}"))
}

fn build(materials: &str) -> Result<Vec<Material>, SceneBuildError> {
    build_materials(&scene_with(materials))
}

fn hit() -> SurfaceInteraction {
    SurfaceInteraction {
        p: Vec3A::ZERO,
        t: 1.0,
        n_geometric: Vec3A::Z,
        n_shading: Vec3A::Z,
        uv: glam::Vec2::ZERO,
        dpdu: Vec3A::X,
        dpdv: Vec3A::Y,
        dndu: Vec3A::ZERO,
        dndv: Vec3A::ZERO,
        curvature: Default::default(),
        differentials: Default::default(),
        primitive_id: 0,
        material_id: 0,
        object_id: 0,
        instance_id: 0,
    }
}

fn wavelengths() -> SampledWavelengths {
    SampledWavelengths::new(
        [450.0, 550.0, 650.0, 750.0],
        SampledSpectrum::splat(1.0 / 470.0),
    )
}

#[test]
fn every_kind_builds_its_lobe() {
    let m = build(
        r#""white": {"type": "lambert", "reflectance": 0.8},
           "gold": {"type": "conductor", "metal": "Au", "roughness": 0.2},
           "mirror": {"type": "conductor", "metal": "Ag"},
           "brushed": {"type": "conductor", "eta": 1.2, "k": 3.5, "roughness": [0.05, 0.3],
                       "distribution": "beckmann"},
           "glass": {"type": "dielectric", "ior": 1.5},
           "bk7": {"type": "dielectric", "ior": {"sellmeier": {"b": [1.03961212, 0.231792344, 1.01046945],
                   "c_um2": [0.00600069867, 0.0200179144, 103.560653]}}, "roughness": 0.1},
           "paper": {"type": "two_sided", "material": "white"},
           "leaf": {"type": "mask", "material": "paper", "opacity": 0.4},
           "leaf2": {"type": "mask", "material": "leaf", "opacity": 0.5}"#,
    )
    .unwrap();
    assert_eq!(m.len(), 10);
    let wl = wavelengths();
    let bsdfs: Vec<Bsdf> = m.iter().map(|m| m.bsdf(&hit(), &wl)).collect();
    assert!(matches!(bsdfs[0].lobe, BsdfLobe::Lambert(_)));
    let BsdfLobe::Conductor(gold) = bsdfs[1].lobe else {
        panic!("{:?}", bsdfs[1])
    };
    // Named metal: η, k from spectra/metals/Au.csv at the four wavelengths.
    let au = metal_optics("Au").unwrap();
    for (l, &nm) in wl.lambda().iter().enumerate() {
        assert!((f64::from(gold.eta[l]) - au.eta.eval(f64::from(nm))).abs() < 1e-5);
        assert!((f64::from(gold.k[l]) - au.k.eval(f64::from(nm))).abs() < 1e-5);
    }
    assert!(!bsdfs[1].is_specular() && bsdfs[2].is_specular());
    let BsdfLobe::Conductor(brushed) = bsdfs[3].lobe else {
        panic!()
    };
    assert_eq!(brushed.distribution.model, MicrofacetModel::Beckmann);
    assert_eq!(
        (brushed.distribution.alpha_x, brushed.distribution.alpha_y),
        (0.05, 0.3)
    );
    assert!(bsdfs[4].is_specular() && !m[4].is_dispersive());
    let BsdfLobe::Dielectric(bk7) = bsdfs[5].lobe else {
        panic!()
    };
    assert!(m[5].is_dispersive() && bk7.eta[0] > bk7.eta[3]);
    // two_sided sets the flag; masks multiply and keep the inner lobe and flag.
    assert!(bsdfs[6].two_sided && !bsdfs[0].two_sided);
    assert!(bsdfs[7].two_sided && bsdfs[8].two_sided);
    assert_eq!(m[6].opacity(), 1.0);
    assert_eq!(m[7].opacity(), 0.4);
    assert!((m[8].opacity() - 0.2).abs() < 1e-7);
    assert_eq!(m[9], Material::default_material());
    // A two-sided lambert seen from below reflects like from above.
    let below = Vec3A::new(0.0, 0.0, -1.0);
    let f = bsdfs[7].eval(below, below, TransportMode::Radiance);
    assert!((f[0] - 0.8 / std::f32::consts::PI).abs() < 1e-6);
}

#[test]
fn two_sided_dielectric_stays_a_dielectric_and_wrappers_pass_dispersion_through() {
    let m = build(
        r#""flint": {"type": "dielectric", "ior": {"cauchy": {"a": 1.67, "b_um2": 0.0074}}},
           "both": {"type": "two_sided", "material": "flint"},
           "half": {"type": "mask", "material": "both", "opacity": 0.5}"#,
    )
    .unwrap();
    let b = m[1].bsdf(&hit(), &wavelengths());
    assert!(!b.two_sided && matches!(b.lobe, BsdfLobe::Dielectric(_)));
    assert!(m[0].is_dispersive() && m[1].is_dispersive() && m[2].is_dispersive());
}

#[test]
fn errors_name_the_file_and_the_json_path() {
    let e = build(
        r#""bad": {"type": "dielectric", "ior": {"sellmeier": {"b": [1.0, 0, 0], "c_um2": [0.25, 0, 0]}}}"#,
    )
    .unwrap_err();
    assert_eq!(e.place, "materials.bad.ior");
    assert!(e.file.ends_with("scenes/test.json"));
    assert!(e.message.contains("500.0 nm"), "{e}");
    assert!(
        e.to_string()
            .starts_with("scenes/test.json: materials.bad.ior: "),
        "{e}"
    );

    let e = build(r#""neg": {"type": "dielectric", "ior": {"cauchy": {"a": 0.2, "b_um2": -0.1}}}"#)
        .unwrap_err();
    assert_eq!(e.place, "materials.neg.ior", "{e}");

    // An η table that stops short of 360–830 nm is 0 outside: refused, naming the field.
    let dir = tempfile::tempdir().unwrap();
    let eta = dir.path().join("eta.csv");
    std::fs::write(&eta, "wavelength_nm,eta\n400,1.2\n700,1.4\n").unwrap();
    let k = dir.path().join("k.csv");
    std::fs::write(&k, "wavelength_nm,k\n300,3\n900,3.5\n").unwrap();
    let json = format!(
        r#""short": {{"type": "conductor", "eta": "{}", "k": "{}"}}"#,
        eta.display(),
        k.display()
    );
    let e = build(&json).unwrap_err();
    assert_eq!(e.place, "materials.short.eta", "{e}");
    assert!(e.message.contains("360 nm"), "{e}");

    // The error of an inner material names the inner material.
    let e = build(
        r#""wrap": {"type": "two_sided", "material": "inner"},
           "inner": {"type": "dielectric", "ior": {"cauchy": {"a": 0.2, "b_um2": -0.1}}}"#,
    )
    .unwrap_err();
    assert_eq!(e.place, "materials.inner.ior", "{e}");
}

#[test]
fn negative_k_in_a_data_file_is_refused_with_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let k = dir.path().join("k.csv");
    std::fs::write(&k, "wavelength_nm,k\n300,3\n600,-0.5\n900,3.5\n").unwrap();
    let json = format!(
        r#"{{
      "camera": {{"type": "pinhole", "fov_deg": 40,
                 "transform": {{"look_at": {{"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}}}}}},
      "materials": {{"m": {{"type": "conductor", "eta": 1.5, "k": "{}"}}}},
      "shapes": [{{"type": "sphere", "radius_m": 1}}]
    }}"#,
        k.display()
    );
    // Caught by the scene parser (value ≥ 0 per line) or, failing that, by the build.
    match parse_scene_str(&json, "scenes/test.json") {
        Err(e) => {
            eprintln!("negative k: {e}");
            assert!(e.to_string().contains("materials.m.k"), "{e}")
        }
        Ok(scene) => {
            let e = build_materials(&scene).unwrap_err();
            assert_eq!(e.place, "materials.m.k");
        }
    }
}

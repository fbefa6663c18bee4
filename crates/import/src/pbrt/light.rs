//! pbrt-v4 lights → Prism lights, with pbrt's photometric normalisation (spectra.rs).

use glam::DVec3;
use serde_json::{json, Map, Value};

use crate::error::{ImportError, Location};
use crate::pbrt::goniometric::{
    candela_per_unit, ies_text, luminaire_json, GoniometricImage, LuminaireFrame,
};
use crate::pbrt::params::Params;
use crate::pbrt::spectra::{emission_factor, spectrum};
use crate::pbrt::{AreaLight, Importer};

/// The light's spectrum parameter `name` (default: the colour space's illuminant, Prism's
/// RGB white) and Prism's scale for it. `k_e` is pbrt-v4's emitted power per unit scale for
/// `"power"` (the light's `Create`: 4π for a point, the cone's for a spot): with a positive
/// power the scale is multiplied by power / k_e, as pbrt does; for lights without a `k_e`
/// "power" is reported and ignored.
fn strength(
    im: &mut Importer,
    params: &Params,
    name: &str,
    at: &Location,
    k_e: Option<f64>,
) -> Result<(Value, f64), ImportError> {
    let mut scale = params.float_or("scale", 1.0)?;
    match (params.get("power"), k_e) {
        (Some(_), Some(k_e)) => {
            if let Some(power) = params.float("power")?.filter(|p| *p > 0.0) {
                scale *= power / k_e;
            }
        }
        (Some(p), None) => {
            im.out.unsupported.note(
                "light \"power\"",
                "ignored: the light keeps its spectrum × scale",
                &p.at,
            );
        }
        (None, _) => {}
    }
    let (spectrum, factor) = strength_spectrum(im, params, name, at)?;
    Ok((spectrum, scale * factor))
}

/// The light's spectrum parameter `name` (default Prism's RGB white, as pbrt's colour
/// space illuminant) and the factor that gives it pbrt's unit luminance in Prism.
fn strength_spectrum(
    im: &mut Importer,
    params: &Params,
    name: &str,
    at: &Location,
) -> Result<(Value, f64), ImportError> {
    match params.get(name) {
        None => Ok((json!({ "rgb": [1.0, 1.0, 1.0] }), 1.0)),
        Some(p) => {
            let s = spectrum(&mut im.out, p)?;
            let factor = emission_factor(&s).ok_or_else(|| {
                ImportError::at(
                    at,
                    format!(
                        "\"{} {}\": a light spectrum must have a luminance > 0",
                        p.ty, p.name
                    ),
                )
            })?;
            Ok((s.value, factor))
        }
    }
}

pub fn area_light(
    im: &mut Importer,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<Option<AreaLight>, ImportError> {
    if kind != "diffuse" {
        return Err(ImportError::at(
            at,
            format!("AreaLightSource \"{kind}\": expected diffuse"),
        ));
    }
    let (spectrum, scale) = strength(im, params, "L", at, None)?;
    let two_sided = params.boolean("twosided")?.unwrap_or(false);
    if let Some(p) = params.get("filename") {
        im.out.unsupported.note(
            "AreaLightSource filename (image emission)",
            "ignored: the light emits its L",
            &p.at,
        );
    }
    params.finish("AreaLightSource \"diffuse\"", &mut im.out.unsupported);
    Ok(Some(AreaLight {
        spectrum,
        scale,
        two_sided,
    }))
}

pub fn light(
    im: &mut Importer,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<(), ImportError> {
    let ctm = im.g.ctm;
    let point = |n: &str, d: DVec3| -> Result<DVec3, ImportError> {
        Ok(params
            .point3s(n)?
            .and_then(|v| v.first().copied())
            .unwrap_or(d))
    };
    let mut l = Map::new();
    match kind {
        "point" => {
            let from = point("from", DVec3::ZERO)?;
            let (s, scale) = strength(im, params, "I", at, Some(4.0 * std::f64::consts::PI))?;
            l.insert("type".into(), json!("point"));
            l.insert(
                "position_m".into(),
                json!(ctm.transform_point3(from).to_array()),
            );
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
        }
        "spot" => {
            let from = point("from", DVec3::ZERO)?;
            let to = point("to", DVec3::Z)?;
            let cone = params.float_or("coneangle", 30.0)?;
            let delta = params.float_or("conedeltaangle", 5.0)?;
            // pbrt-v4 `SpotLight::Create`: the power of a unit-intensity spot.
            let (cos_end, cos_start) = (cone.to_radians().cos(), (cone - delta).to_radians().cos());
            let k_e =
                2.0 * std::f64::consts::PI * ((1.0 - cos_start) + (cos_start - cos_end) / 2.0);
            let (s, scale) = strength(im, params, "I", at, Some(k_e))?;
            l.insert("type".into(), json!("spot"));
            l.insert(
                "position_m".into(),
                json!(ctm.transform_point3(from).to_array()),
            );
            l.insert(
                "direction".into(),
                json!(ctm.transform_vector3(to - from).to_array()),
            );
            l.insert("cone_angle_deg".into(), json!(cone));
            l.insert("falloff_start_deg".into(), json!(cone - delta));
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
        }
        "distant" => {
            let from = point("from", DVec3::ZERO)?;
            let to = point("to", DVec3::Z)?;
            let (s, scale) = strength(im, params, "L", at, None)?;
            l.insert("type".into(), json!("directional"));
            l.insert(
                "direction".into(),
                json!(ctm.transform_vector3(to - from).to_array()),
            );
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
        }
        "infinite" => {
            if let Some(file) = params.string("filename")? {
                let path = at
                    .file
                    .parent()
                    .unwrap_or(std::path::Path::new(""))
                    .join(&file);
                let (map, upper_illuminance) = environment_map(&path, at)?;
                let name = format!("environment-{}.exr", im.out.side_files.len() + 1);
                l.insert("type".into(), json!("environment"));
                l.insert("file".into(), json!(im.out.add_side_file(&name, map)));
                l.insert("transform".into(), crate::output::matrix_json(&ctm));
                let mut scale = params.float_or("scale", 1.0)?;
                if let Some(e_v) = params.float("illuminance")?.filter(|e| *e > 0.0) {
                    // pbrt-v4: the map's illuminance on an upward (light-space +z) patch.
                    if upper_illuminance <= 0.0 {
                        return Err(ImportError::at(
                            at,
                            format!("LightSource \"infinite\" \"illuminance\": {file} sends no light to an upward patch, so no scale gives it an illuminance"),
                        ));
                    }
                    scale *= e_v / upper_illuminance;
                }
                l.insert("scale".into(), json!(scale));
                params.finish("LightSource \"infinite\"", &mut im.out.unsupported);
                im.out.lights.push(Value::Object(l));
                return Ok(());
            }
            let (s, mut scale) = strength(im, params, "L", at, None)?;
            if let Some(e_v) = params.float("illuminance")?.filter(|e| *e > 0.0) {
                // pbrt-v4: a uniform sky of unit luminance gives π on an upward patch.
                scale *= e_v / std::f64::consts::PI;
            }
            l.insert("type".into(), json!("sky"));
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
        }
        "goniometric" => {
            let Some(file) = params.string("filename")? else {
                return Err(ImportError::at(
                    at,
                    "LightSource \"goniometric\": expected a \"string filename\" (pbrt-v4's \
                     equal-area octahedral intensity image); without one pbrt emits nothing",
                ));
            };
            let path = at
                .file
                .parent()
                .unwrap_or(std::path::Path::new(""))
                .join(&file);
            let image = GoniometricImage::read(&path, at)?;
            let frame = LuminaireFrame::new(&ctm).ok_or_else(|| {
                ImportError::at(
                    at,
                    "LightSource \"goniometric\": the current transform is singular",
                )
            })?;
            let (s, _) = strength_spectrum(im, params, "I", at)?;
            let mut scale = params.float_or("scale", 1.0)?;
            if let Some(power) = params.float("power")?.filter(|p| *p > 0.0) {
                // pbrt-v4: k_e = 4π · mean Y (equal-area texels).
                let k_e = 4.0 * std::f64::consts::PI * image.mean();
                if k_e <= 0.0 {
                    return Err(ImportError::at(
                        at,
                        format!("LightSource \"goniometric\" \"power\": {file} is black, so no scale gives it a power"),
                    ));
                }
                scale *= power / k_e;
            }
            let text = ies_text(&image, &frame, &file);
            let name = format!("goniometric-{}.ies", im.out.side_files.len() + 1);
            let written = im.out.add_side_file(&name, text.into_bytes());
            l = luminaire_json(&frame, &written);
            l.insert("scale".into(), json!(candela_per_unit(scale, &s)));
            l.insert("spectrum".into(), s);
            params.finish("LightSource \"goniometric\"", &mut im.out.unsupported);
            im.out.lights.push(Value::Object(l));
            return Ok(());
        }
        other => {
            im.out.unsupported.note(
                format!("LightSource \"{other}\""),
                "not imported (Prism reads point, spot, distant, goniometric and infinite lights, with or without an image, from pbrt)",
                at,
            );
            for q in &params.list {
                q.used.set(true);
            }
            return Ok(());
        }
    }
    params.finish(&format!("LightSource \"{kind}\""), &mut im.out.unsupported);
    im.out.lights.push(Value::Object(l));
    Ok(())
}

/// pbrt-v4's equal-area octahedral environment image at `path` as the bytes of an
/// equirectangular linear-sRGB EXR (`octahedral`), for an `environment` light, and the
/// illuminance it gives an upward (light-space +z) patch per unit scale, as pbrt-v4's
/// `"illuminance"` computes it (Σ over texels with z > 0 of Y · cos θ × 2π / N²).
fn environment_map(path: &std::path::Path, at: &Location) -> Result<(Vec<u8>, f64), ImportError> {
    let image = crate::pbrt::octahedral::read_square(path, at, "LightSource infinite")?;
    let srgb = prism_spectrum::rgb_space::RgbColorSpace::srgb();
    let mut pixels = image.pixels().to_vec();
    prism_image::io::convert_pixels(&mut pixels, &image.color_space, &srgb);
    let n = image.width();
    let luminance = srgb.rgb_to_xyz.row(1);
    let upper_illuminance = pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let w = crate::pbrt::octahedral::square_to_sphere(
                ((i % n) as f64 + 0.5) / n as f64,
                ((i / n) as f64 + 0.5) / n as f64,
            );
            if w.z <= 0.0 {
                return 0.0;
            }
            luminance.dot(glam::DVec3::new(
                f64::from(p[0]),
                f64::from(p[1]),
                f64::from(p[2]),
            )) * w.z
        })
        .sum::<f64>()
        * 2.0
        * std::f64::consts::PI
        / (n * n) as f64;
    let (width, height, map) = crate::pbrt::octahedral::octahedral_to_equirect(&pixels, n);
    let equirect = prism_image::Image::new(width, height, map, srgb)
        .map_err(|e| ImportError::at(at, format!("environment map: {e}")))?;
    // The EXR encoder writes files: through a private temporary file.
    let temp = std::env::temp_dir().join(format!(
        "prism-import-env-{}-{}.exr",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |t| t.as_nanos())
    ));
    let written = prism_image::io::exr::write_exr(
        &temp,
        &equirect,
        &prism_image::io::exr::ExrWriteOptions::default(),
    )
    .map_err(|e| ImportError::at(at, format!("environment map: {e}")))
    .and_then(|()| {
        std::fs::read(&temp)
            .map_err(|e| ImportError::at(at, format!("environment map {}: {e}", temp.display())))
    });
    let _ = std::fs::remove_file(&temp);
    written.map(|bytes| (bytes, upper_illuminance))
}

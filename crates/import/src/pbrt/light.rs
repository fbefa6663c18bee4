//! pbrt-v4 lights → Prism lights, with pbrt's photometric normalisation (spectra.rs).

use glam::DVec3;
use serde_json::{json, Map, Value};

use crate::error::{ImportError, Location};
use crate::pbrt::params::Params;
use crate::pbrt::spectra::{emission_factor, spectrum};
use crate::pbrt::{AreaLight, Importer};

/// The light's spectrum parameter `name` (default: the colour space's illuminant, Prism's
/// RGB white) and Prism's scale for it.
fn strength(
    im: &mut Importer,
    params: &Params,
    name: &str,
    at: &Location,
) -> Result<(Value, f64), ImportError> {
    let scale = params.float_or("scale", 1.0)?;
    if let Some(p) = params.get("power") {
        im.out.unsupported.note(
            "light \"power\"",
            "ignored: the light keeps its spectrum × scale",
            &p.at,
        );
    }
    match params.get(name) {
        None => Ok((json!({ "rgb": [1.0, 1.0, 1.0] }), scale)),
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
            Ok((s.value, scale * factor))
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
    let (spectrum, scale) = strength(im, params, "L", at)?;
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
            let (s, scale) = strength(im, params, "I", at)?;
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
            let delta = params.float_or("conedelta", 5.0)?;
            let (s, scale) = strength(im, params, "I", at)?;
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
            im.out.unsupported.note("LightSource spot", "imported with the same cone angles; pbrt's smoothstep falloff between them may differ from Prism's (docs/lights.md)", at);
        }
        "distant" => {
            let from = point("from", DVec3::ZERO)?;
            let to = point("to", DVec3::Z)?;
            let (s, scale) = strength(im, params, "L", at)?;
            l.insert("type".into(), json!("directional"));
            l.insert(
                "direction".into(),
                json!(ctm.transform_vector3(to - from).to_array()),
            );
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
        }
        "infinite" => {
            if let Some(p) = params.get("filename") {
                im.out.unsupported.note(
                    "LightSource infinite with an image",
                    "not imported: pbrt-v4's environment images are equal-area octahedral maps, Prism's are equirectangular (convert the image and add an `environment` light)",
                    &p.at,
                );
                for q in &params.list {
                    q.used.set(true);
                }
                return Ok(());
            }
            let (s, scale) = strength(im, params, "L", at)?;
            l.insert("type".into(), json!("sky"));
            l.insert("spectrum".into(), s);
            l.insert("scale".into(), json!(scale));
            if params.float("illuminance")?.is_some() {
                im.out.unsupported.note(
                    "infinite light illuminance",
                    "ignored: the light keeps L × scale",
                    at,
                );
            }
        }
        other => {
            im.out.unsupported.note(
                format!("LightSource \"{other}\""),
                "not imported (Prism reads point, spot, distant and infinite from pbrt; goniometric files are not pbrt's EXR format in Prism — use a `luminaire` with an IES file)",
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

//! Mitsuba emitters → Prism lights. With `scale`, Prism's spectrum is radiance (area,
//! constant), intensity (point, spot) or irradiance on a facing surface (directional): the
//! quantities Mitsuba's `radiance`, `intensity` and `irradiance` give.

use glam::{DMat4, DVec3};
use serde_json::{json, Map, Value};

use crate::error::ImportError;
use crate::mitsuba::props::Props;
use crate::mitsuba::spectra::{spectrum, SpectrumRole};
use crate::mitsuba::transform::parse_transform;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;
use crate::output::matrix_json;

/// The emitter's spectrum parameter `name` (required) as Prism's spectrum and scale.
fn strength(
    ctx: &mut Ctx,
    props: &Props,
    name: &str,
    light: &mut Map<String, Value>,
) -> Result<(), ImportError> {
    let c = props.child(name).ok_or_else(|| {
        ImportError::at(
            &props.el.at,
            format!(
                "emitter {}: needs `{name}` (a spectrum or rgb)",
                props.el.attr("type").unwrap_or("?")
            ),
        )
    })?;
    let s = spectrum(&mut ctx.out, c, SpectrumRole::Emission)?;
    light.insert("spectrum".into(), s.spectrum);
    light.insert("scale".into(), json!(s.scale));
    Ok(())
}

/// A nested `<emitter type="area">` on the shape named `shape`.
pub fn area_light(ctx: &mut Ctx, el: &Element, shape: &str) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    if kind != "area" {
        return Err(ImportError::at(
            &el.at,
            format!("an emitter inside a shape must be type=\"area\", found \"{kind}\""),
        ));
    }
    let mut light = Map::new();
    light.insert("type".into(), json!("area"));
    light.insert("shape".into(), json!(shape));
    light.insert("two_sided".into(), json!(false));
    strength(ctx, &props, "radiance", &mut light)?;
    props.finish("emitter area", &mut ctx.out.unsupported);
    ctx.out.lights.push(Value::Object(light));
    Ok(())
}

/// A top-level emitter.
pub fn emitter(ctx: &mut Ctx, el: &Element) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let to_world = match props.child("to_world") {
        Some(t) => parse_transform(t)?,
        None => DMat4::IDENTITY,
    };
    let mut light = Map::new();
    match kind {
        "point" => {
            let position = props
                .point("position")?
                .unwrap_or_else(|| to_world.transform_point3(DVec3::ZERO));
            light.insert("type".into(), json!("point"));
            light.insert("position_m".into(), json!(position.to_array()));
            strength(ctx, &props, "intensity", &mut light)?;
        }
        "spot" => {
            let cutoff = props.float_or("cutoff_angle", 20.0)?;
            let beam = props.float_or("beam_width", cutoff * 0.75)?;
            light.insert("type".into(), json!("spot"));
            light.insert(
                "position_m".into(),
                json!(to_world.transform_point3(DVec3::ZERO).to_array()),
            );
            light.insert(
                "direction".into(),
                json!(to_world.transform_vector3(DVec3::Z).to_array()),
            );
            light.insert("cone_angle_deg".into(), json!(cutoff));
            light.insert("falloff_start_deg".into(), json!(beam));
            strength(ctx, &props, "intensity", &mut light)?;
            ctx.out.unsupported.note(
                "emitter spot",
                "imported with the same cone and beam angles; the falloff curve between them may differ from Mitsuba's linear-in-angle ramp (docs/lights.md)",
                &el.at,
            );
        }
        "directional" => {
            let direction = props
                .point("direction")?
                .unwrap_or_else(|| to_world.transform_vector3(DVec3::Z));
            light.insert("type".into(), json!("directional"));
            light.insert("direction".into(), json!(direction.to_array()));
            strength(ctx, &props, "irradiance", &mut light)?;
        }
        "envmap" => {
            let file = props.string("filename")?.ok_or_else(|| {
                ImportError::at(&el.at, "emitter envmap: needs <string name=\"filename\">")
            })?;
            light.insert("type".into(), json!("environment"));
            light.insert(
                "file".into(),
                json!(ctx.out.asset_path(&el.base_dir().join(file))),
            );
            light.insert("scale".into(), json!(props.float_or("scale", 1.0)?));
            // Mitsuba interpolates its envmap bilinearly.
            light.insert("filter".into(), json!("bilinear"));
            if to_world != DMat4::IDENTITY {
                light.insert("transform".into(), matrix_json(&to_world));
            }
        }
        "constant" => {
            light.insert("type".into(), json!("sky"));
            strength(ctx, &props, "radiance", &mut light)?;
        }
        "sunsky" => {
            ctx.out.unsupported.note(
                "emitter type=\"sunsky\"",
                "not imported: Mitsuba's sunsky is the Hosek–Wilkie sky and sun model; Prism's daylight skies (cie_sky, perez_sky, preetham_sky) are other models, and none reproduces its radiance distribution or its sun's level — add one of them by hand (docs/daylight.md)",
                &el.at,
            );
            return Ok(());
        }
        other => {
            ctx.out.unsupported.note(
                format!("emitter type=\"{other}\""),
                "not imported (Prism reads area, point, spot, directional, envmap and constant from Mitsuba)",
                &el.at,
            );
            return Ok(());
        }
    }
    props.finish(&format!("emitter {kind}"), &mut ctx.out.unsupported);
    ctx.out.lights.push(Value::Object(light));
    Ok(())
}

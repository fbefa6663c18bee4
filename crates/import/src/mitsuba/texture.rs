//! Mitsuba textures → Prism textures: `bitmap` → `image`, `checkerboard` → `checkerboard`
//! (Mitsuba's cells are half a uv unit: Prism's uv_scale 2).

use serde_json::{json, Map, Value};

use crate::error::ImportError;
use crate::mitsuba::props::Props;
use crate::mitsuba::spectra::{spectrum, SpectrumRole};
use crate::mitsuba::transform::parse_transform;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;

/// Imports a `<texture>` (already resolved from a ref) once; returns its Prism name.
pub fn texture(ctx: &mut Ctx, el: &Element) -> Result<String, ImportError> {
    if let Some(name) = el.attr("id").and_then(|id| ctx.texture_by_id.get(id)) {
        return Ok(name.clone());
    }
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let mut t = Map::new();
    let mut uv_scale = 1.0;
    match kind {
        "bitmap" => {
            let file = props.string("filename")?.ok_or_else(|| {
                ImportError::at(&el.at, "texture bitmap: needs <string name=\"filename\">")
            })?;
            t.insert("type".into(), json!("image"));
            t.insert("file".into(), json!(ctx.out.asset_path(&el.base_dir().join(file))));
            if props.boolean("raw")? == Some(true) {
                t.insert("encoding".into(), json!("linear"));
            }
            let filter = match props.string("filter_type")?.unwrap_or("bilinear") {
                "bilinear" => "bilinear",
                "nearest" => "nearest",
                other => {
                    return Err(ImportError::at(
                        &el.at,
                        format!("bitmap filter_type \"{other}\": expected bilinear or nearest"),
                    ))
                }
            };
            t.insert("filter".into(), json!(filter));
            let wrap = match props.string("wrap_mode")?.unwrap_or("repeat") {
                "repeat" => "repeat",
                "mirror" => "mirror",
                "clamp" => "clamp",
                other => {
                    return Err(ImportError::at(
                        &el.at,
                        format!("bitmap wrap_mode \"{other}\": expected repeat, mirror or clamp"),
                    ))
                }
            };
            t.insert("wrap".into(), json!(wrap));
        }
        "checkerboard" => {
            t.insert("type".into(), json!("checkerboard"));
            for (mitsuba, prism, default) in [("color0", "a", 0.4), ("color1", "b", 0.2)] {
                let value = match props.child(mitsuba) {
                    Some(c) => spectrum(&mut ctx.out, c, SpectrumRole::Reflectance)?.spectrum,
                    None => json!(default),
                };
                t.insert(prism.into(), value);
            }
            uv_scale = 2.0;
        }
        other => {
            return Err(ImportError::at(
                &el.at,
                format!("texture type=\"{other}\": expected bitmap or checkerboard (Prism's image and checkerboard)"),
            ))
        }
    }
    if let Some(to_uv) = props.child("to_uv") {
        let m = parse_transform(to_uv)?;
        let (sx, sy) = (m.col(0)[0], m.col(1)[1]);
        let off = [m.col(3)[0], m.col(3)[1]];
        let skew = m.col(0)[1] != 0.0 || m.col(1)[0] != 0.0;
        if skew {
            ctx.out.unsupported.note(
                "texture to_uv with rotation or shear",
                "only its scale and offset are imported",
                &to_uv.at,
            );
        }
        t.insert("uv_scale".into(), json!([sx * uv_scale, sy * uv_scale]));
        if off != [0.0, 0.0] {
            t.insert(
                "uv_offset".into(),
                json!([off[0] * uv_scale, off[1] * uv_scale]),
            );
        }
    } else if uv_scale != 1.0 {
        t.insert("uv_scale".into(), json!(uv_scale));
    }
    props.finish(&format!("texture {kind}"), &mut ctx.out.unsupported);
    let name = ctx.out.unique_texture_name(el.attr("id").unwrap_or(kind));
    ctx.out.textures.insert(name.clone(), Value::Object(t));
    if let Some(id) = el.attr("id") {
        ctx.texture_by_id.insert(id.to_string(), name.clone());
    }
    Ok(name)
}

//! Mitsuba shapes → Prism shapes; a nested area emitter becomes an `area` light on it.
//! Mitsuba's rectangle is [-1, 1]² (normal +Z), its cube [-1, 1]³, its disk and sphere of
//! radius 1: Prism's rectangle, cuboid, disk and sphere with those sizes are the same.

use glam::DMat4;
use serde_json::{json, Map, Value};

use crate::error::ImportError;
use crate::mitsuba::bsdf::material;
use crate::mitsuba::emitter::area_light;
use crate::mitsuba::props::Props;
use crate::mitsuba::serialized::read_serialized;
use crate::mitsuba::transform::parse_transform;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;
use crate::output::matrix_json;

pub fn shape(ctx: &mut Ctx, el: &Element) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let mut s = Map::new();
    let mut to_world = match props.child("to_world") {
        Some(t) => parse_transform(t)?,
        None => DMat4::IDENTITY,
    };
    match kind {
        "obj" | "ply" => {
            let file = props.string("filename")?.ok_or_else(|| {
                ImportError::at(
                    &el.at,
                    format!("shape {kind}: needs <string name=\"filename\">"),
                )
            })?;
            s.insert("type".into(), json!("mesh"));
            s.insert(
                "file".into(),
                json!(ctx.out.asset_path(&el.base_dir().join(file))),
            );
            if props.boolean("face_normals")? == Some(true) {
                ctx.out.unsupported.note(
                    "shape face_normals",
                    "ignored: Prism shades meshes with the file's vertex normals when it has them",
                    &el.at,
                );
            }
        }
        "serialized" => {
            let file = props.string("filename")?.ok_or_else(|| {
                ImportError::at(&el.at, "shape serialized: needs <string name=\"filename\">")
            })?;
            let index = props.integer("shape_index")?.unwrap_or(0);
            let path = el.base_dir().join(file);
            let bytes = std::fs::read(&path).map_err(|e| {
                ImportError::at(&el.at, format!("shape serialized: {}: {e}", path.display()))
            })?;
            let mesh = usize::try_from(index)
                .map_err(|_| format!("shape_index {index}: expected ≥ 0"))
                .and_then(|i| read_serialized(&bytes, i))
                .map_err(|e| {
                    ImportError::at(&el.at, format!("shape serialized {}: {e}", path.display()))
                })?;
            let obj = crate::obj::obj_text(
                &mesh.positions,
                mesh.normals.as_deref(),
                mesh.uvs.as_deref(),
                &mesh.triangles,
                false,
            );
            let n = ctx.out.side_files.len();
            let side = ctx
                .out
                .add_side_file(&format!("serialized-{n}.obj"), obj.into_bytes());
            s.insert("type".into(), json!("mesh"));
            s.insert("file".into(), json!(side));
            if props.boolean("face_normals")? == Some(true) {
                ctx.out.unsupported.note(
                    "shape face_normals",
                    "ignored: Prism shades meshes with the file's vertex normals when it has them",
                    &el.at,
                );
            }
        }
        "rectangle" => {
            s.insert("type".into(), json!("rectangle"));
            s.insert("size_m".into(), json!([2, 2]));
        }
        "cube" => {
            s.insert("type".into(), json!("cuboid"));
            s.insert("size_m".into(), json!([2, 2, 2]));
        }
        "disk" => {
            s.insert("type".into(), json!("disk"));
            s.insert("radius_m".into(), json!(1));
        }
        "sphere" => {
            let center = props.point("center")?.unwrap_or(glam::DVec3::ZERO);
            let radius = props.float_or("radius", 1.0)?;
            s.insert("type".into(), json!("sphere"));
            s.insert("radius_m".into(), json!(radius));
            to_world *= DMat4::from_translation(center);
        }
        other => {
            ctx.out.unsupported.note(
                format!("shape type=\"{other}\""),
                "not imported (Prism reads obj, ply, serialized, rectangle, cube, sphere and disk from Mitsuba)",
                &el.at,
            );
            return Ok(());
        }
    }
    if props.boolean("flip_normals")? == Some(true) {
        ctx.out.unsupported.note(
            "shape flip_normals",
            "ignored: Prism has no normal flip (an area light emits towards the unflipped normal)",
            &el.at,
        );
    }
    let base = el.attr("id").unwrap_or(kind).to_string();
    let name = ctx.out.unique_shape_name(&base);
    let mut out = Map::new();
    out.insert(
        "type".into(),
        s.remove("type").expect("every branch sets the type"),
    );
    out.insert("name".into(), json!(name));
    out.extend(s);
    if to_world != DMat4::IDENTITY {
        out.insert("transform".into(), matrix_json(&to_world));
    }
    let bsdfs: Vec<&Element> = props
        .objects("bsdf")
        .into_iter()
        .chain(props.objects("ref").into_iter().filter(|r| is_bsdf_ref(r)))
        .collect();
    match bsdfs.as_slice() {
        [] => {}
        [one] => {
            let m = material(ctx, one)?;
            out.insert("material".into(), json!(m));
        }
        [_, second, ..] => {
            return Err(ImportError::at(
                &second.at,
                "a shape takes one <bsdf> (or <ref> to one)",
            ))
        }
    }
    for medium in ["interior", "exterior"] {
        if let Some(c) = props.child(medium) {
            ctx.out.unsupported.note(
                format!("shape {medium} medium"),
                "not imported: Mitsuba media are not translated",
                &c.at,
            );
        }
    }
    for m in props.objects("medium") {
        ctx.out.unsupported.note(
            "shape medium",
            "not imported: Mitsuba media are not translated",
            &m.at,
        );
    }
    ctx.out.shapes.push(Value::Object(out));
    for emitter in props.objects("emitter") {
        area_light(ctx, emitter, &name)?;
    }
    props.finish(&format!("shape {kind}"), &mut ctx.out.unsupported);
    Ok(())
}

/// A `<ref>` that names the shape's BSDF: unnamed or named `bsdf` (named refs such as
/// `interior` are media and are read by name).
fn is_bsdf_ref(r: &Element) -> bool {
    matches!(r.attr("name"), None | Some("bsdf"))
}

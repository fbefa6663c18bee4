//! pbrt-v4 shapes → Prism shapes. Inline meshes (trianglemesh, bilinearmesh) are written as
//! OBJ side files; bilinear patches as two triangles each (exact when a patch is planar).
//! Winding: pbrt flips a triangle's normal when the transform swaps handedness or under
//! ReverseOrientation; Prism takes the normal from the world-space winding, so the OBJ's
//! winding is reversed in exactly one of those cases.

use glam::{DMat4, DVec3};
use serde_json::{json, Map, Value};

use crate::error::{ImportError, Location};
use crate::output::matrix_json;
use crate::pbrt::params::Params;
use crate::pbrt::{Importer, ObjectShape};

pub fn shape(
    im: &mut Importer,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<(), ImportError> {
    let mut s = Map::new();
    let mut matrix = im.g.ctm;
    match kind {
        "sphere" => {
            s.insert("type".into(), json!("sphere"));
            s.insert("radius_m".into(), json!(params.float_or("radius", 1.0)?));
            for n in ["zmin", "zmax", "phimax"] {
                if params.float(n)?.is_some() {
                    im.out.unsupported.note(
                        "partial sphere (zmin/zmax/phimax)",
                        "imported as a whole sphere",
                        at,
                    );
                }
            }
        }
        "disk" => {
            s.insert("type".into(), json!("disk"));
            s.insert("radius_m".into(), json!(params.float_or("radius", 1.0)?));
            matrix *=
                DMat4::from_translation(DVec3::new(0.0, 0.0, params.float_or("height", 0.0)?));
            if params.float_or("innerradius", 0.0)? != 0.0 || params.float("phimax")?.is_some() {
                im.out
                    .unsupported
                    .note("disk innerradius/phimax", "imported as a whole disk", at);
            }
        }
        "plymesh" => {
            let file = params
                .string("filename")?
                .ok_or_else(|| ImportError::at(at, "plymesh: needs \"string filename\""))?;
            let path = at
                .file
                .parent()
                .unwrap_or(std::path::Path::new(""))
                .join(&file);
            s.insert("type".into(), json!("mesh"));
            s.insert("file".into(), json!(im.out.asset_path(&path)));
            for n in ["displacement", "edgelength"] {
                if let Some(p) = params.get(n) {
                    im.out.unsupported.note(
                        format!("plymesh {n}"),
                        "ignored: Prism does not displace meshes",
                        &p.at,
                    );
                }
            }
        }
        "trianglemesh" | "bilinearmesh" => {
            let p = params
                .point3s("P")?
                .ok_or_else(|| ImportError::at(at, format!("{kind}: needs \"point3 P\"")))?;
            let per_face = if kind == "trianglemesh" { 3 } else { 4 };
            let indices: Vec<usize> = match params.floats("indices")? {
                Some(xs) => xs
                    .iter()
                    .map(|x| {
                        if *x >= 0.0 && x.fract() == 0.0 && (*x as usize) < p.len() {
                            Ok(*x as usize)
                        } else {
                            Err(ImportError::at(
                                at,
                                format!(
                                    "{kind} indices: {x} is not a vertex index in [0, {})",
                                    p.len()
                                ),
                            ))
                        }
                    })
                    .collect::<Result<_, _>>()?,
                None if p.len() == per_face => (0..per_face).collect(),
                None => {
                    return Err(ImportError::at(
                        at,
                        format!(
                            "{kind}: needs \"integer indices\" (it has {} points)",
                            p.len()
                        ),
                    ))
                }
            };
            if indices.is_empty() || !indices.len().is_multiple_of(per_face) {
                return Err(ImportError::at(
                    at,
                    format!(
                        "{kind} indices: expected a multiple of {per_face}, found {}",
                        indices.len()
                    ),
                ));
            }
            let n = params.point3s("N")?;
            let uv = params.floats("uv")?;
            for len in [n.as_ref().map(Vec::len), uv.as_ref().map(|u| u.len() / 2)]
                .into_iter()
                .flatten()
            {
                {
                    if len != p.len() {
                        return Err(ImportError::at(
                            at,
                            format!(
                                "{kind}: N/uv need one entry per point ({}), found {len}",
                                p.len()
                            ),
                        ));
                    }
                }
            }
            let flip = (matrix.determinant() < 0.0) != im.g.reverse_orientation;
            let mut triangles: Vec<[usize; 3]> = Vec::new();
            for f in indices.chunks(per_face) {
                if per_face == 3 {
                    triangles.push([f[0], f[1], f[2]]);
                } else {
                    // Patch corners p00, p10, p01, p11.
                    triangles.push([f[0], f[1], f[3]]);
                    triangles.push([f[0], f[3], f[2]]);
                }
            }
            let obj = crate::obj::obj_text(&p, n.as_deref(), uv.as_deref(), &triangles, flip);
            im.mesh_count += 1;
            let file = im
                .out
                .add_side_file(&format!("mesh-{}.obj", im.mesh_count), obj.into_bytes());
            s.insert("type".into(), json!("mesh"));
            s.insert("file".into(), json!(file));
        }
        other => {
            im.out.unsupported.note(
                format!("Shape \"{other}\""),
                "not imported (Prism reads trianglemesh, bilinearmesh, plymesh, sphere and disk from pbrt)",
                at,
            );
            for q in &params.list {
                q.used.set(true);
            }
            return Ok(());
        }
    }
    if im.g.reverse_orientation && (kind == "sphere" || kind == "disk") && im.g.area_light.is_some()
    {
        im.out.unsupported.note(
            "ReverseOrientation on an emitting sphere or disk",
            "ignored: Prism's spheres and disks emit along their outward / +Z normal",
            at,
        );
    }
    for n in ["alpha", "emissionfilename"] {
        if let Some(p) = params.get(n) {
            im.out
                .unsupported
                .note(format!("Shape {n}"), "ignored", &p.at);
        }
    }
    params.finish(&format!("Shape \"{kind}\""), &mut im.out.unsupported);
    let material = match im.g.material.clone() {
        Some(m) => m,
        None => crate::pbrt::material::default_material(im),
    };
    s.insert("material".into(), json!(material));
    if let Some((_, shapes)) = im.current_object.as_mut() {
        if im.g.area_light.is_some() {
            im.out.unsupported.note(
                "area light inside ObjectBegin",
                "the instances do not emit (pbrt ignores it too)",
                at,
            );
        }
        shapes.push(ObjectShape { shape: s, matrix });
        return Ok(());
    }
    let name = im.out.unique_shape_name(kind);
    push_shape(im, &name, s, &matrix);
    if let Some(light) = im.g.area_light.clone() {
        im.out.lights.push(json!({
            "type": "area", "shape": name, "two_sided": light.two_sided,
            "spectrum": light.spectrum, "scale": light.scale
        }));
    }
    Ok(())
}

fn push_shape(im: &mut Importer, name: &str, mut s: Map<String, Value>, matrix: &DMat4) {
    let mut out = Map::new();
    out.insert("type".into(), s.remove("type").unwrap_or(json!("mesh")));
    out.insert("name".into(), json!(name));
    let material = s.remove("material");
    out.extend(s);
    if *matrix != DMat4::IDENTITY {
        out.insert("transform".into(), matrix_json(matrix));
    }
    if let Some(m) = material {
        out.insert("material".into(), m);
    }
    im.out.shapes.push(Value::Object(out));
}

/// `ObjectInstance`: the object's shapes placed by the current transform.
pub fn instance(im: &mut Importer, name: &str, at: &Location) -> Result<(), ImportError> {
    let shapes = im.objects.get(name).cloned().ok_or_else(|| {
        ImportError::at(
            at,
            format!("ObjectInstance \"{name}\": no ObjectBegin \"{name}\" before it"),
        )
    })?;
    for s in shapes {
        let kind = s
            .shape
            .get("type")
            .and_then(Value::as_str)
            .unwrap_or("mesh")
            .to_string();
        let shape_name = im.out.unique_shape_name(&format!("{name}-{kind}"));
        let matrix = im.g.ctm * s.matrix;
        push_shape(im, &shape_name, s.shape, &matrix);
    }
    Ok(())
}

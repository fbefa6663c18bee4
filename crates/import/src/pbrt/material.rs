//! pbrt-v4 materials and textures → Prism materials and textures (docs/import.md).

use serde_json::{json, Map, Value};

use crate::error::{ImportError, Location};
use crate::pbrt::params::{Param, ParamValue, Params};
use crate::pbrt::spectra::{spectrum, METALS};
use crate::pbrt::Importer;

/// pbrt's roughness → microfacet α: with `remaproughness` (the default) pbrt-v4 takes
/// α = √roughness (TrowbridgeReitzDistribution::RoughnessToAlpha).
fn roughness(params: &Params) -> Result<Option<Value>, ImportError> {
    let remap = params.boolean("remaproughness")?.unwrap_or(true);
    let to_alpha = |r: f64| if remap { r.sqrt() } else { r };
    let r = params.float("roughness")?;
    let u = params.float("uroughness")?;
    let v = params.float("vroughness")?;
    let value = match (u, v, r) {
        (Some(u), Some(v), _) if u != v => json!([to_alpha(u), to_alpha(v)]),
        (Some(u), _, _) | (None, Some(u), _) => json!(to_alpha(u)),
        (None, None, Some(r)) => json!(to_alpha(r)),
        (None, None, None) => return Ok(None),
    };
    Ok(if value == json!(0.0) {
        None
    } else {
        Some(value)
    })
}

/// A spectrum-or-texture parameter.
fn textured(im: &mut Importer, params: &Params, name: &str) -> Result<Option<Value>, ImportError> {
    let Some(p) = params.get(name) else {
        return Ok(None);
    };
    if p.ty == "texture" {
        let t = texture_ref(im, p)?;
        return Ok(Some(json!({ "texture": t })));
    }
    Ok(Some(spectrum(&mut im.out, p)?.value))
}

fn texture_ref(im: &Importer, p: &Param) -> Result<String, ImportError> {
    match p.values.as_slice() {
        [ParamValue::Str(n)] => im.textures.get(n).cloned().ok_or_else(|| {
            ImportError::at(
                &p.at,
                format!(
                    "\"texture {}\": no texture named \"{n}\" (define it with Texture first)",
                    p.name
                ),
            )
        }),
        _ => Err(ImportError::at(
            &p.at,
            format!("\"texture {}\": expected one texture name", p.name),
        )),
    }
}

fn eta(im: &mut Importer, params: &Params, default: f64) -> Result<Value, ImportError> {
    match params.get("eta") {
        None => Ok(json!(default)),
        Some(p) => Ok(spectrum(&mut im.out, p)?.value),
    }
}

/// The Prism JSON of a pbrt material; `None` for `interface` (no surface). `name` names
/// the one-sided material a `two_sided` wraps (`name-front`).
fn convert(
    im: &mut Importer,
    name: &str,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<Option<Value>, ImportError> {
    let mut m = Map::new();
    match kind {
        "diffuse" => {
            m.insert("type".into(), json!("lambert"));
            if let Some(r) = textured(im, params, "reflectance")? {
                m.insert("reflectance".into(), r);
            }
        }
        "conductor" | "coatedconductor" => {
            let prefix = if kind == "coatedconductor" {
                "conductor."
            } else {
                ""
            };
            m.insert("type".into(), json!("conductor"));
            let named = |p: Option<&Param>| -> Option<String> {
                match p?.values.as_slice() {
                    [ParamValue::Str(s)] => Some(s.clone()),
                    _ => None,
                }
            };
            let eta_p = params.get(&format!("{prefix}eta"));
            let k_p = params.get(&format!("{prefix}k"));
            if params.get("reflectance").is_some() {
                return Err(ImportError::at(at, format!("{kind} with \"reflectance\": Prism's conductors take eta and k (or a metal name)")));
            }
            match (eta_p, k_p) {
                (None, None) => {
                    m.insert("metal".into(), json!("Cu"));
                }
                (Some(e), Some(k)) => {
                    let metal = match (named(Some(e)), named(Some(k))) {
                        (Some(a), Some(b)) => {
                            let ma = a
                                .strip_prefix("metal-")
                                .and_then(|s| s.strip_suffix("-eta"));
                            let mb = b.strip_prefix("metal-").and_then(|s| s.strip_suffix("-k"));
                            match (ma, mb) {
                                (Some(x), Some(y)) if x == y && METALS.contains(&x) => {
                                    Some(x.to_string())
                                }
                                _ => None,
                            }
                        }
                        _ => None,
                    };
                    match metal {
                        Some(x) => {
                            m.insert("metal".into(), json!(x));
                        }
                        None => {
                            let e = spectrum(&mut im.out, e)?.value;
                            let k = spectrum(&mut im.out, k)?.value;
                            m.insert("eta".into(), e);
                            m.insert("k".into(), k);
                        }
                    }
                }
                _ => {
                    return Err(ImportError::at(
                        at,
                        format!("{kind}: give both {prefix}eta and {prefix}k, or neither (copper)"),
                    ))
                }
            }
            let r = if kind == "coatedconductor" {
                let remap = params.boolean("remaproughness")?.unwrap_or(true);
                let r = params.float("conductor.roughness")?.unwrap_or(0.0);
                let alpha = if remap { r.sqrt() } else { r };
                (alpha > 0.0).then(|| json!(alpha))
            } else {
                roughness(params)?
            };
            if let Some(r) = r {
                m.insert("roughness".into(), r);
                m.insert("distribution".into(), json!("ggx"));
            }
            if kind == "coatedconductor" {
                out_note(im, "Material coatedconductor", "imported as its conductor base: Prism has no dielectric coat over a conductor (the interface layer is dropped)", at);
                for n in [
                    "interface.eta",
                    "interface.roughness",
                    "interface.uroughness",
                    "interface.vroughness",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                    "conductor.uroughness",
                    "conductor.vroughness",
                ] {
                    params.get(n);
                }
            }
        }
        "dielectric" | "thindielectric" => {
            m.insert(
                "type".into(),
                json!(if kind == "dielectric" {
                    "dielectric"
                } else {
                    "thin_dielectric"
                }),
            );
            m.insert("ior".into(), eta(im, params, 1.5)?);
            if kind == "dielectric" {
                if let Some(r) = roughness(params)? {
                    m.insert("roughness".into(), r);
                    m.insert("distribution".into(), json!("ggx"));
                }
            }
        }
        "coateddiffuse" => {
            m.insert("type".into(), json!("coated"));
            if let Some(r) = textured(im, params, "reflectance")? {
                m.insert("diffuse".into(), r);
            }
            m.insert("ior".into(), eta(im, params, 1.5)?);
            m.insert("nonlinear".into(), json!(true));
            let r = roughness(params)?;
            out_note(
                im,
                "Material coateddiffuse",
                format!(
                    "imported as Prism's coated (smooth coat over Lambert, internal reflections as a series); pbrt's is a stochastic layered model{}: the two agree for a thin, clear, smooth coat",
                    if r.is_some() { " and this one's coat is rough (lost)" } else { "" }
                ),
                at,
            );
            for n in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                params.get(n);
            }
        }
        "mix" => {
            let p = params.get("materials").ok_or_else(|| {
                ImportError::at(at, "mix: needs \"string materials\" [ \"a\" \"b\" ]")
            })?;
            let names: Vec<String> = match p.values.as_slice() {
                [ParamValue::Str(a), ParamValue::Str(b)] => vec![a.clone(), b.clone()],
                _ => {
                    return Err(ImportError::at(
                        &p.at,
                        "mix \"materials\": expected two material names",
                    ))
                }
            };
            let mut prism = Vec::new();
            for n in &names {
                prism.push(im.named_materials.get(n).cloned().ok_or_else(|| {
                    ImportError::at(
                        &p.at,
                        format!("mix: no named material \"{n}\" (MakeNamedMaterial first)"),
                    )
                })?);
            }
            let amount = match params.get("amount") {
                Some(a) if a.ty == "texture" => {
                    out_note(
                        im,
                        "mix with a textured amount",
                        "Prism's mix takes one number: 0.5 used",
                        at,
                    );
                    0.5
                }
                Some(_) => params.float("amount")?.unwrap_or(0.5),
                None => 0.5,
            };
            m.insert("type".into(), json!("mix"));
            m.insert("materials".into(), json!(prism));
            m.insert("weight".into(), json!(amount));
        }
        "interface" => return Ok(None),
        "measured" => {
            out_note(
                im,
                "Material \"measured\"",
                "pbrt-v4's measured BSDFs are RGL tensor files (.bsdf, Dupuy & Jakob 2018); Prism reads MERL tables (material `merl`), not that format: imported as diffuse 0.5",
                at,
            );
            for q in &params.list {
                q.used.set(true);
            }
            m.insert("type".into(), json!("lambert"));
        }
        other => {
            out_note(
                im,
                &format!("Material \"{other}\""),
                "no Prism equivalent: imported as diffuse 0.5",
                at,
            );
            for q in &params.list {
                q.used.set(true);
            }
            m.insert("type".into(), json!("lambert"));
        }
    }
    for n in ["displacement", "normalmap"] {
        if let Some(p) = params.get(n) {
            out_note(im, &format!("Material {n}"), "not imported", &p.at);
        }
    }
    params.finish(&format!("Material \"{kind}\""), &mut im.out.unsupported);
    Ok(Some(both_sides(im, name, m)))
}

/// pbrt-v4's reflecting BxDFs (diffuse, conductor, the coated layers) scatter on whichever
/// side of the surface the ray arrives (`SameHemisphere` in the shading frame), while
/// Prism's lambert, conductor and coated are black from below: those become `two_sided`
/// of the material (stored once under its own name). Dielectrics already scatter on both
/// sides, and a mix's materials are wrapped themselves.
fn both_sides(im: &mut Importer, name: &str, m: Map<String, Value>) -> Value {
    let one_sided = match m.get("type").and_then(Value::as_str) {
        Some("lambert" | "conductor" | "coated") => true,
        Some(_) | None => false,
    };
    if !one_sided {
        return Value::Object(m);
    }
    let inner = shared_material(im, &format!("{name}-front"), Value::Object(m));
    json!({ "type": "two_sided", "material": inner })
}

/// The name of a material equal to `m` if the scene has one (the same parameters give the
/// same material), else of `m` stored under a new name from `base`.
fn shared_material(im: &mut Importer, base: &str, m: Value) -> String {
    if let Some((n, _)) = im.out.materials.iter().find(|(_, v)| **v == m) {
        return n.clone();
    }
    let name = im.out.unique_material_name(base);
    im.out.materials.insert(name.clone(), m);
    name
}

fn out_note(im: &mut Importer, kind: &str, consequence: impl Into<String>, at: &Location) {
    im.out.unsupported.note(kind, consequence, at);
}

/// `Material`: an anonymous material; returns its Prism name.
pub fn material(
    im: &mut Importer,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<Option<String>, ImportError> {
    let Some(m) = convert(im, kind, kind, params, at)? else {
        return Ok(None);
    };
    Ok(Some(shared_material(im, kind, m)))
}

/// The material of shapes before any `Material`: pbrt's default, diffuse 0.5 (Prism's
/// lambert default), on both sides like every pbrt diffuse.
pub fn default_material(im: &mut Importer) -> String {
    let mut inner = Map::new();
    inner.insert("type".into(), json!("lambert"));
    let m = both_sides(im, "diffuse", inner);
    shared_material(im, "diffuse", m)
}

/// `MakeNamedMaterial`.
pub fn named_material(
    im: &mut Importer,
    name: &str,
    kind: &str,
    params: &Params,
    at: &Location,
) -> Result<Option<String>, ImportError> {
    let Some(m) = convert(im, name, kind, params, at)? else {
        return Ok(None);
    };
    let prism = im.out.unique_material_name(name);
    im.out.materials.insert(prism.clone(), m);
    Ok(Some(prism))
}

/// `Texture "name" "spectrum"|"float" "class"`.
pub fn texture(
    im: &mut Importer,
    name: &str,
    ty: &str,
    class: &str,
    params: &Params,
    at: &Location,
) -> Result<(), ImportError> {
    if ty != "spectrum" && ty != "float" {
        return Err(ImportError::at(
            at,
            format!("Texture \"{name}\": value type \"{ty}\", expected spectrum or float"),
        ));
    }
    let mut t = Map::new();
    match class {
        "imagemap" => {
            let file = params
                .string("filename")?
                .ok_or_else(|| ImportError::at(at, "imagemap: needs \"string filename\""))?;
            let path = at
                .file
                .parent()
                .unwrap_or(std::path::Path::new(""))
                .join(&file);
            t.insert("type".into(), json!("image"));
            t.insert("file".into(), json!(im.out.asset_path(&path)));
            if let Some(enc) = params.string("encoding")? {
                match enc.as_str() {
                    "sRGB" => t.insert("encoding".into(), json!("srgb")),
                    "linear" => t.insert("encoding".into(), json!("linear")),
                    other => return Err(ImportError::at(at, format!("imagemap encoding \"{other}\": expected sRGB or linear (gamma is not imported)"))),
                };
            }
            if let Some(f) = params.string("filter")? {
                let f = match f.as_str() {
                    "point" => "nearest",
                    "bilinear" => "bilinear",
                    "trilinear" | "ewa" | "EWA" => "trilinear",
                    other => return Err(ImportError::at(at, format!("imagemap filter \"{other}\": expected point, bilinear, trilinear or ewa"))),
                };
                t.insert("filter".into(), json!(f));
            }
            if let Some(w) = params.string("wrap")? {
                let w = match w.as_str() {
                    "repeat" => "repeat",
                    "clamp" => "clamp",
                    "octahedralsphere" | "black" => {
                        out_note(
                            im,
                            &format!("imagemap wrap \"{w}\""),
                            "imported as clamp",
                            at,
                        );
                        "clamp"
                    }
                    other => {
                        return Err(ImportError::at(
                            at,
                            format!("imagemap wrap \"{other}\": expected repeat, clamp or black"),
                        ))
                    }
                };
                t.insert("wrap".into(), json!(w));
            }
            if let Some(s) = params.float("scale")? {
                t.insert("scale".into(), json!(s));
            }
            if params.boolean("invert")? == Some(true) {
                out_note(
                    im,
                    "imagemap invert",
                    "ignored: Prism's image textures are not inverted",
                    at,
                );
            }
        }
        "checkerboard" => {
            t.insert("type".into(), json!("checkerboard"));
            for (pbrt, prism, default) in [("tex1", "a", 1.0), ("tex2", "b", 0.0)] {
                let v = match params.get(pbrt) {
                    Some(p) if p.ty == "texture" => {
                        out_note(
                            im,
                            "checkerboard of textures",
                            "Prism's checkerboard cells are spectra: 0.5 used",
                            &p.at,
                        );
                        json!(0.5)
                    }
                    Some(p) => spectrum(&mut im.out, p)?.value,
                    None => json!(default),
                };
                t.insert(prism.into(), v);
            }
            if let Some(d) = params.float("dimension")? {
                if d != 2.0 {
                    return Err(ImportError::at(at, "checkerboard dimension 3: Prism's checkerboard is 2D (use a noise texture)"));
                }
            }
        }
        "scale" => {
            // tex × scale: an image texture with its `scale` multiplied.
            let base = match params.get("tex") {
                Some(p) if p.ty == "texture" => texture_ref(im, p)?,
                _ => return Err(ImportError::at(at, "scale texture: Prism imports it only as \"texture tex\" (an imagemap) times \"float scale\"")),
            };
            let factor = params.float_or("scale", 1.0)?;
            let mut copy = im.out.textures.get(&base).cloned().unwrap_or(Value::Null);
            match copy.get("type").and_then(Value::as_str) {
                Some("image") => {
                    let old = copy.get("scale").and_then(Value::as_f64).unwrap_or(1.0);
                    copy["scale"] = json!(old * factor);
                    t = copy.as_object().cloned().unwrap_or_default();
                }
                _ => {
                    return Err(ImportError::at(
                        at,
                        "scale texture: Prism imports it only over an imagemap texture",
                    ))
                }
            }
        }
        other => {
            return Err(ImportError::at(
                at,
                format!(
                    "Texture class \"{other}\": Prism imports imagemap, checkerboard and scale"
                ),
            ));
        }
    }
    if class != "scale" {
        let us = params.float_or("uscale", 1.0)?;
        let vs = params.float_or("vscale", 1.0)?;
        let ud = params.float_or("udelta", 0.0)?;
        let vd = params.float_or("vdelta", 0.0)?;
        if us != 1.0 || vs != 1.0 {
            t.insert("uv_scale".into(), json!([us, vs]));
        }
        if ud != 0.0 || vd != 0.0 {
            t.insert("uv_offset".into(), json!([ud, vd]));
        }
        if let Some(m) = params.string("mapping")?.filter(|m| m != "uv") {
            im.out.unsupported.note(
                format!("texture mapping \"{m}\""),
                "imported as uv mapping",
                at,
            );
        }
    }
    params.finish(&format!("Texture \"{class}\""), &mut im.out.unsupported);
    let prism = im.out.unique_texture_name(name);
    im.out.textures.insert(prism.clone(), Value::Object(t));
    im.textures.insert(name.to_string(), prism);
    Ok(())
}

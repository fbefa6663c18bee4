//! Mitsuba BSDFs → Prism materials (docs/import.md has the table and where models differ).

use serde_json::{json, Map, Value};

use crate::error::ImportError;
use crate::mitsuba::props::Props;
use crate::mitsuba::spectra::{spectrum, SpectrumRole};
use crate::mitsuba::texture::texture;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;

/// Mitsuba's named indices of refraction (src/core/spectrum: `lookup_ior`).
const NAMED_IORS: [(&str, f64); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// Mitsuba conductor names with a Prism metal table (Prism: docs/materials.md).
const METALS: [(&str, &str); 6] = [
    ("Ag", "Ag"),
    ("Al", "Al"),
    ("Au", "Au"),
    ("Cr", "Cr"),
    ("Cu", "Cu"),
    ("Ni_palik", "Ni"),
];

/// The Prism material name of a `<bsdf>` or `<ref>` to one, importing it on first use.
pub fn material(ctx: &mut Ctx, el: &Element) -> Result<String, ImportError> {
    let el = ctx.resolve(el, "bsdf")?;
    if let Some(name) = el.attr("id").and_then(|id| ctx.material_by_id.get(id)) {
        return Ok(name.clone());
    }
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let m = convert(ctx, &props, kind)?;
    props.finish(&format!("bsdf {kind}"), &mut ctx.out.unsupported);
    let name = ctx.out.unique_material_name(el.attr("id").unwrap_or(kind));
    ctx.out.materials.insert(name.clone(), m);
    if let Some(id) = el.attr("id") {
        ctx.material_by_id.insert(id.to_string(), name.clone());
    }
    Ok(name)
}

fn convert(ctx: &mut Ctx, props: &Props, kind: &str) -> Result<Value, ImportError> {
    let el = props.el;
    let mut m = Map::new();
    match kind {
        "diffuse" => {
            m.insert("type".into(), json!("lambert"));
            if let Some(r) = textured(ctx, props, "reflectance", SpectrumRole::Reflectance)? {
                m.insert("reflectance".into(), r);
            }
        }
        "conductor" | "roughconductor" => {
            m.insert("type".into(), json!("conductor"));
            let eta = props.child("eta");
            let k = props.child("k");
            match (eta, k) {
                (Some(eta), Some(k)) => {
                    let eta = spectrum(&mut ctx.out, eta, SpectrumRole::Coefficient)?.spectrum;
                    let k = spectrum(&mut ctx.out, k, SpectrumRole::Coefficient)?.spectrum;
                    m.insert("eta".into(), eta);
                    m.insert("k".into(), k);
                }
                (None, None) => {
                    let name = props.string("material")?.unwrap_or("none");
                    match METALS.iter().find(|(mi, _)| *mi == name) {
                        Some((mi, prism)) => {
                            if mi != prism {
                                ctx.out.unsupported.note(
                                    format!("conductor material \"{mi}\""),
                                    format!("imported as Prism's metal {prism} (a different measurement of the same metal)"),
                                    &el.at,
                                );
                            }
                            m.insert("metal".into(), json!(prism));
                        }
                        None if name == "none" => {
                            // Mitsuba's "none" is a perfect mirror; Fresnel with η = 1, κ = 10⁴ reflects 1 − 4·10⁻⁸.
                            m.insert("eta".into(), json!(1.0));
                            m.insert("k".into(), json!(10000.0));
                        }
                        None => {
                            let known: Vec<&str> = METALS.iter().map(|(m, _)| *m).collect();
                            return Err(ImportError::at(
                                &el.at,
                                format!(
                                    "conductor material \"{name}\": Prism has tables for {} (or give eta and k spectra)",
                                    known.join(", ")
                                ),
                            ));
                        }
                    }
                }
                _ => {
                    return Err(ImportError::at(
                        &el.at,
                        "conductor: give both `eta` and `k`, or neither (then `material`)",
                    ))
                }
            }
            if kind == "roughconductor" {
                roughness(ctx, props, &mut m)?;
            }
            specular_reflectance_is_one(ctx, props)?;
        }
        "dielectric" | "roughdielectric" | "thindielectric" => {
            m.insert(
                "type".into(),
                json!(if kind == "thindielectric" {
                    "thin_dielectric"
                } else {
                    "dielectric"
                }),
            );
            m.insert("ior".into(), json!(relative_ior(ctx, props, 1.5046)?));
            if kind == "roughdielectric" {
                roughness(ctx, props, &mut m)?;
            }
            specular_reflectance_is_one(ctx, props)?;
            if props.child("specular_transmittance").is_some() {
                ctx.out.unsupported.note(
                    format!("bsdf {kind}: specular_transmittance"),
                    "ignored: Prism's dielectrics transmit what Fresnel does not reflect",
                    &el.at,
                );
            }
        }
        "plastic" | "roughplastic" => {
            m.insert("type".into(), json!("coated"));
            if let Some(d) = textured(ctx, props, "diffuse_reflectance", SpectrumRole::Reflectance)?
            {
                m.insert("diffuse".into(), d);
            }
            m.insert("ior".into(), json!(relative_ior(ctx, props, 1.49)?));
            m.insert(
                "nonlinear".into(),
                json!(props.boolean("nonlinear")?.unwrap_or(false)),
            );
            specular_reflectance_is_one(ctx, props)?;
            if kind == "roughplastic" {
                let alpha = props.float_or("alpha", 0.1)?;
                props.string("distribution")?;
                ctx.out.unsupported.note(
                    "bsdf roughplastic",
                    format!("imported as Prism's coated, whose coat is smooth: the coat's roughness (alpha {alpha}) is lost, highlights are sharp"),
                    &el.at,
                );
            } else {
                ctx.out.unsupported.note(
                    "bsdf plastic",
                    "imported as Prism's coated (smooth coat over Lambert); Mitsuba's plastic and Prism's coated weigh the diffuse and specular parts alike, but Prism samples them differently (same mean)",
                    &el.at,
                );
            }
        }
        "twosided" => {
            let inner = props.objects("bsdf");
            let refs = props
                .objects("ref")
                .into_iter()
                .filter(|r| r.attr("name").is_none());
            let nested: Vec<&Element> = inner.into_iter().chain(refs).collect();
            match nested.as_slice() {
                [one] => {
                    let name = material(ctx, one)?;
                    m.insert("type".into(), json!("two_sided"));
                    m.insert("material".into(), json!(name));
                }
                [front, back] => {
                    ctx.out.unsupported.note(
                        "bsdf twosided with two different BSDFs",
                        "the front BSDF is used on both sides (Prism's two_sided takes one material)",
                        &back.at,
                    );
                    let name = material(ctx, front)?;
                    m.insert("type".into(), json!("two_sided"));
                    m.insert("material".into(), json!(name));
                }
                _ => {
                    return Err(ImportError::at(
                        &el.at,
                        format!(
                            "twosided: expected one or two nested <bsdf>, found {}",
                            nested.len()
                        ),
                    ))
                }
            }
        }
        "mask" | "blendbsdf" | "normalmap" | "bumpmap" => {
            let nested: Vec<&Element> = props
                .objects("bsdf")
                .into_iter()
                .chain(
                    props
                        .objects("ref")
                        .into_iter()
                        .filter(|r| r.attr("name").is_none()),
                )
                .collect();
            let mut names = Vec::new();
            for n in &nested {
                names.push(material(ctx, n)?);
            }
            let want = if kind == "blendbsdf" { 2 } else { 1 };
            if names.len() != want {
                return Err(ImportError::at(
                    &el.at,
                    format!(
                        "{kind}: expected {want} nested <bsdf>, found {}",
                        names.len()
                    ),
                ));
            }
            match kind {
                "mask" => {
                    m.insert("type".into(), json!("mask"));
                    m.insert("material".into(), json!(names[0]));
                    if let Some(o) = textured(ctx, props, "opacity", SpectrumRole::Reflectance)? {
                        m.insert("opacity".into(), scalar_of(ctx, el, o));
                    } else {
                        m.insert("opacity".into(), json!(0.5));
                    }
                }
                "blendbsdf" => {
                    m.insert("type".into(), json!("mix"));
                    m.insert("materials".into(), json!(names));
                    let w = match textured(ctx, props, "weight", SpectrumRole::Reflectance)? {
                        Some(Value::Number(n)) => json!(n),
                        Some(_) => {
                            ctx.out.unsupported.note(
                                "blendbsdf with a textured or spectral weight",
                                "Prism's mix takes one number: 0.5 used",
                                &el.at,
                            );
                            json!(0.5)
                        }
                        None => json!(0.5),
                    };
                    m.insert("weight".into(), w);
                }
                "normalmap" => {
                    let t = props.child("normalmap").ok_or_else(|| {
                        ImportError::at(
                            &el.at,
                            "normalmap: needs <texture name=\"normalmap\" type=\"bitmap\">",
                        )
                    })?;
                    let t = ctx.resolve(t, "texture")?;
                    let tex = texture(ctx, t)?;
                    m.insert("type".into(), json!("normal_map"));
                    m.insert("material".into(), json!(names[0]));
                    m.insert("texture".into(), json!(tex));
                }
                _ => {
                    let textures: Vec<&Element> = props.objects("texture");
                    let t = textures.first().ok_or_else(|| {
                        ImportError::at(
                            &el.at,
                            "bumpmap: needs a nested <texture> (the height field)",
                        )
                    })?;
                    let tex = texture(ctx, t)?;
                    let scale = props.float_or("scale", 1.0)?;
                    ctx.out.unsupported.note(
                        "bsdf bumpmap",
                        "imported as Prism's bump_map with scale_m = Mitsuba's scale: Mitsuba's height is in uv-space units, Prism's in metres, so the bump strength differs unless the uv map is 1 unit per metre",
                        &el.at,
                    );
                    m.insert("type".into(), json!("bump_map"));
                    m.insert("material".into(), json!(names[0]));
                    m.insert("texture".into(), json!(tex));
                    m.insert("scale_m".into(), json!(scale));
                }
            }
        }
        other => {
            ctx.out.unsupported.note(
                format!("bsdf type=\"{other}\""),
                "no Prism equivalent: imported as lambert 0.5",
                &el.at,
            );
            // Its parameters are part of that one report entry.
            for c in &el.children {
                props.child(c.attr("name").unwrap_or(""));
            }
            props.objects("bsdf");
            m.insert("type".into(), json!("lambert"));
        }
    }
    Ok(Value::Object(m))
}

/// A reflectance-like parameter: a spectrum, or a texture (nested or `<ref>`).
fn textured(
    ctx: &mut Ctx,
    props: &Props,
    name: &str,
    role: SpectrumRole,
) -> Result<Option<Value>, ImportError> {
    let Some(c) = props.child(name) else {
        return Ok(None);
    };
    let c = ctx.resolve(c, "texture")?;
    if c.tag == "texture" {
        let t = texture(ctx, c)?;
        return Ok(Some(json!({ "texture": t })));
    }
    Ok(Some(spectrum(&mut ctx.out, c, role)?.spectrum))
}

/// Prism's opacity is a number or a texture: an RGB opacity becomes its mean.
fn scalar_of(ctx: &mut Ctx, el: &Element, v: Value) -> Value {
    if let Some(rgb) = v.get("rgb").and_then(Value::as_array) {
        ctx.out.unsupported.note(
            "mask with an RGB opacity",
            "Prism's opacity is one number: the mean of the three used",
            &el.at,
        );
        let sum: f64 = rgb.iter().filter_map(Value::as_f64).sum();
        return json!(sum / 3.0);
    }
    v
}

fn roughness(ctx: &mut Ctx, props: &Props, m: &mut Map<String, Value>) -> Result<(), ImportError> {
    let el = props.el;
    let distribution = props.string("distribution")?.unwrap_or("beckmann");
    match distribution {
        "beckmann" | "ggx" => {
            m.insert("distribution".into(), json!(distribution));
        }
        other => {
            return Err(ImportError::at(
                &el.at,
                format!("distribution \"{other}\": expected beckmann or ggx"),
            ))
        }
    }
    let au = props.float("alpha_u")?;
    let av = props.float("alpha_v")?;
    let alpha = match props.child("alpha") {
        Some(c) => {
            let c = ctx.resolve(c, "texture")?;
            if c.tag == "texture" {
                json!({ "texture": texture(ctx, c)? })
            } else {
                json!(crate::mitsuba::props::number(c)?)
            }
        }
        None => json!(0.1),
    };
    let value = match (au, av) {
        (Some(u), Some(v)) => json!([u, v]),
        (None, None) => alpha,
        _ => {
            return Err(ImportError::at(
                &el.at,
                "rough BSDF: give both alpha_u and alpha_v, or `alpha`",
            ))
        }
    };
    m.insert("roughness".into(), value);
    // Mitsuba's `sample_visible` only changes sampling (Heitz 2018), not the mean.
    props.boolean("sample_visible")?;
    Ok(())
}

fn specular_reflectance_is_one(ctx: &mut Ctx, props: &Props) -> Result<(), ImportError> {
    if let Some(c) = props.child("specular_reflectance") {
        let s = spectrum(&mut ctx.out, c, SpectrumRole::Reflectance)?.spectrum;
        if s != json!(1.0) {
            ctx.out.unsupported.note(
                "specular_reflectance other than 1",
                "ignored: Prism's specular lobes are scaled by Fresnel alone",
                &c.at,
            );
        }
    }
    Ok(())
}

/// int_ior / ext_ior (numbers or Mitsuba's names): Prism's materials take the ratio.
fn relative_ior(ctx: &mut Ctx, props: &Props, default_int: f64) -> Result<f64, ImportError> {
    let read = |name: &str, default: f64| -> Result<f64, ImportError> {
        match props.child(name) {
            None => Ok(default),
            Some(c) if c.tag == "string" => {
                let v = c.require_attr("value")?;
                NAMED_IORS
                    .iter()
                    .find(|(n, _)| *n == v)
                    .map(|(_, x)| *x)
                    .ok_or_else(|| {
                        let names: Vec<&str> = NAMED_IORS.iter().map(|(n, _)| *n).collect();
                        ImportError::at(
                            &c.at,
                            format!(
                                "{name} \"{v}\": expected a number or one of {}",
                                names.join(", ")
                            ),
                        )
                    })
            }
            Some(c) => crate::mitsuba::props::number(c),
        }
    };
    let int = read("int_ior", default_int)?;
    let ext = read("ext_ior", 1.000277)?;
    let _ = ctx;
    Ok(int / ext)
}

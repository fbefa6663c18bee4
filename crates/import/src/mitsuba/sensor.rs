//! Mitsuba sensors, films, reconstruction filters and samplers → Prism's camera and film.
//! Mitsuba's cameras look down local +Z with +X to the left; Prism's down −Z with +X to the
//! right: the camera transform is Mitsuba's to_world · diag(−1, 1, −1).

use glam::{DMat4, DVec3};
use serde_json::{json, Map, Value};

use crate::error::ImportError;
use crate::mitsuba::props::Props;
use crate::mitsuba::transform::parse_transform;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;
use crate::output::matrix_json;

pub fn sensor(ctx: &mut Ctx, el: &Element) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let mitsuba_to_world = match props.child("to_world") {
        Some(t) => parse_transform(t)?,
        None => DMat4::IDENTITY,
    };
    let to_world = mitsuba_to_world * DMat4::from_scale(DVec3::new(-1.0, 1.0, -1.0));

    // Film first: the field-of-view axis depends on the aspect ratio.
    let (width, height) = match props.objects("film").first() {
        Some(f) => film(ctx, f)?,
        None => (768, 576),
    };
    if let Some(s) = props.objects("sampler").first() {
        sampler(ctx, s)?;
    }
    for c in ["near_clip", "far_clip"] {
        if let Some(c) = props.child(c) {
            ctx.out.unsupported.note(
                "sensor near_clip/far_clip",
                "ignored: Prism's cameras do not clip",
                &c.at,
            );
        }
    }
    let mut cam = Map::new();
    match kind {
        "perspective" | "thinlens" => {
            let (fov_deg, axis) = fov(&props, width, height)?;
            if kind == "perspective" {
                // Accepted by Mitsuba's perspective camera, used only by thinlens.
                props.float("focus_distance")?;
                cam.insert("type".into(), json!("pinhole"));
                cam.insert("fov_deg".into(), json!(fov_deg));
                cam.insert("fov_axis".into(), json!(axis.prism_name()));
            } else {
                // Prism's thin lens takes the horizontal field of view.
                let (w, h) = (width as f64, height as f64);
                let half = (fov_deg.to_radians() / 2.0).tan();
                let half_h = match axis {
                    FovAxis::Horizontal => half,
                    FovAxis::Vertical => half * w / h,
                    FovAxis::Diagonal => half * w / (w * w + h * h).sqrt(),
                };
                cam.insert("type".into(), json!("thin_lens"));
                cam.insert("fov_deg".into(), json!(2.0 * half_h.atan().to_degrees()));
                cam.insert(
                    "aperture_radius_m".into(),
                    json!(props.float_or("aperture_radius", 0.03)?),
                );
                cam.insert(
                    "focus_distance_m".into(),
                    json!(props.float_or("focus_distance", 0.0)?),
                );
            }
        }
        "orthographic" => {
            // Mitsuba's orthographic camera sees [-1, 1] along local x before to_world.
            let width_m = 2.0 * mitsuba_to_world.transform_vector3(DVec3::X).length();
            cam.insert("type".into(), json!("orthographic"));
            cam.insert("width_m".into(), json!(width_m));
        }
        other => {
            return Err(ImportError::at(
                &el.at,
                format!("sensor type=\"{other}\": expected perspective, thinlens or orthographic"),
            ))
        }
    }
    cam.insert("transform".into(), matrix_json(&to_world));
    props.finish(&format!("sensor {kind}"), &mut ctx.out.unsupported);
    ctx.out.camera = Some(Value::Object(cam));
    Ok(())
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FovAxis {
    Horizontal,
    Vertical,
    Diagonal,
}

impl FovAxis {
    fn prism_name(self) -> &'static str {
        match self {
            FovAxis::Horizontal => "horizontal",
            FovAxis::Vertical => "vertical",
            FovAxis::Diagonal => "diagonal",
        }
    }
}

/// `fov` + `fov_axis`, or `focal_length` (Mitsuba: on a 36 × 24 mm frame, diagonal).
fn fov(props: &Props, width: u32, height: u32) -> Result<(f64, FovAxis), ImportError> {
    let wider = width > height;
    let axis_name = props.string("fov_axis")?.unwrap_or("x");
    let axis = match axis_name {
        "x" => FovAxis::Horizontal,
        "y" => FovAxis::Vertical,
        "diagonal" => FovAxis::Diagonal,
        "smaller" if wider => FovAxis::Vertical,
        "smaller" => FovAxis::Horizontal,
        "larger" if wider => FovAxis::Horizontal,
        "larger" => FovAxis::Vertical,
        other => {
            return Err(ImportError::at(
                &props.el.at,
                format!("fov_axis \"{other}\": expected x, y, diagonal, smaller or larger"),
            ))
        }
    };
    if let Some(f) = props.float("fov")? {
        return Ok((f, axis));
    }
    let focal = props.string("focal_length")?.unwrap_or("50mm");
    let mm = focal
        .trim()
        .strip_suffix("mm")
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| *v > 0.0)
        .ok_or_else(|| {
            ImportError::at(
                &props.el.at,
                format!("focal_length \"{focal}\": expected millimetres such as \"50mm\""),
            )
        })?;
    let diagonal_mm = (36.0f64 * 36.0 + 24.0 * 24.0).sqrt();
    Ok((
        2.0 * (diagonal_mm / (2.0 * mm)).atan().to_degrees(),
        FovAxis::Diagonal,
    ))
}

/// `hdrfilm` (and its rfilter) → Prism's film; returns the resolution.
fn film(ctx: &mut Ctx, el: &Element) -> Result<(u32, u32), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    if kind != "hdrfilm" {
        ctx.out.unsupported.note(
            format!("film type=\"{kind}\""),
            "read as hdrfilm (resolution and filter only)",
            &el.at,
        );
    }
    let dim = |name: &str, default: i64| -> Result<u32, ImportError> {
        let v = props.integer(name)?.unwrap_or(default);
        u32::try_from(v).ok().filter(|v| *v >= 1).ok_or_else(|| {
            ImportError::at(
                &el.at,
                format!("film {name}: expected a whole number ≥ 1, found {v}"),
            )
        })
    };
    let width = dim("width", 768)?;
    let height = dim("height", 576)?;
    ctx.out
        .film
        .insert("resolution".into(), json!([width, height]));
    let filter = match props.objects("rfilter").first() {
        Some(f) => rfilter(ctx, f)?,
        None => json!({"type": "gaussian", "radius_px": 2.0, "sigma_px": 0.5}),
    };
    ctx.out.film.insert("filter".into(), filter);
    // Mitsuba adds each sample to every pixel within the filter's radius (ImageBlock).
    ctx.out.film.insert("reconstruction".into(), json!("splat"));
    // Output encodings do not change the image's values.
    for c in ["pixel_format", "component_format", "file_format"] {
        props.string(c)?;
    }
    for c in [
        "crop_width",
        "crop_height",
        "crop_offset_x",
        "crop_offset_y",
    ] {
        if let Some(c) = props.child(c) {
            ctx.out.unsupported.note(
                "film crop window",
                "ignored: Prism renders the whole film",
                &c.at,
            );
        }
    }
    props.finish(&format!("film {kind}"), &mut ctx.out.unsupported);
    Ok((width, height))
}

fn rfilter(ctx: &mut Ctx, el: &Element) -> Result<Value, ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let v = match kind {
        "box" => json!({"type": "box", "radius_px": 0.5}),
        "gaussian" => {
            let sigma = props.float_or("stddev", 0.5)?;
            // Mitsuba truncates its Gaussian at 4 standard deviations.
            json!({"type": "gaussian", "radius_px": 4.0 * sigma, "sigma_px": sigma})
        }
        "mitchell" => json!({
            "type": "mitchell", "radius_px": 2.0,
            "b": props.float_or("B", 1.0 / 3.0)?, "c": props.float_or("C", 1.0 / 3.0)?
        }),
        "tent" => {
            let radius = props.float_or("radius", 1.0)?;
            ctx.out.unsupported.note(
                "rfilter tent",
                format!("Prism has no tent filter: a Gaussian of radius {radius} px and σ {} px (the tent's standard deviation r/√6) is used", radius / 6f64.sqrt()),
                &el.at,
            );
            json!({"type": "gaussian", "radius_px": radius, "sigma_px": radius / 6f64.sqrt()})
        }
        other => {
            ctx.out.unsupported.note(
                format!("rfilter type=\"{other}\""),
                "Prism's filters are box, gaussian, mitchell and blackman_harris: Mitsuba's default Gaussian is used",
                &el.at,
            );
            json!({"type": "gaussian", "radius_px": 2.0, "sigma_px": 0.5})
        }
    };
    props.finish(&format!("rfilter {kind}"), &mut ctx.out.unsupported);
    Ok(v)
}

fn sampler(ctx: &mut Ctx, el: &Element) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    let spp = props.integer("sample_count")?.unwrap_or(4);
    if spp < 1 {
        return Err(ImportError::at(
            &el.at,
            format!("sampler sample_count: expected ≥ 1, found {spp}"),
        ));
    }
    ctx.out.film.insert("spp".into(), json!(spp));
    let seed = props.integer("seed")?.unwrap_or(0);
    if seed < 0 {
        return Err(ImportError::at(
            &el.at,
            format!("sampler seed: expected ≥ 0, found {seed}"),
        ));
    }
    ctx.out.film.insert("seed".into(), json!(seed));
    ctx.sampler = match kind {
        "independent" => "independent",
        _ => {
            ctx.out.unsupported.note(
                format!("sampler type=\"{kind}\""),
                "Prism's stratified sampler is sobol: used instead (same mean, different noise)",
                &el.at,
            );
            "sobol"
        }
    };
    props.finish(&format!("sampler {kind}"), &mut ctx.out.unsupported);
    Ok(())
}

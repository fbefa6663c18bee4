//! pbrt-v4 render options → Prism's camera, film and integrator. pbrt's camera looks down +Z
//! with image right = camera +X; Prism's looks down −Z: the camera transform is
//! world-from-camera · diag(1, 1, −1).

use glam::{DMat4, DVec3};
use serde_json::{json, Map, Value};

use crate::error::{ImportError, Location};
use crate::output::{matrix_json, SceneBuilder};
use crate::pbrt::params::Params;

#[derive(Debug, Default)]
pub struct RenderOptions {
    camera: Option<(String, Map<String, Value>, Location)>,
    resolution: Option<(u32, u32)>,
    integrator: Option<Value>,
    sampler: Option<&'static str>,
}

impl RenderOptions {
    pub fn camera(
        &mut self,
        out: &mut SceneBuilder,
        kind: &str,
        params: &Params,
        camera_from_world: DMat4,
        at: &Location,
    ) -> Result<(), ImportError> {
        let world_from_camera = camera_from_world.inverse();
        let to_world = world_from_camera * DMat4::from_scale(DVec3::new(1.0, 1.0, -1.0));
        let mut cam = Map::new();
        match kind {
            "perspective" => {
                cam.insert("fov_deg".into(), json!(params.float_or("fov", 90.0)?));
                let lens = params.float_or("lensradius", 0.0)?;
                let focus = params.float_or("focaldistance", 1e6)?;
                if lens > 0.0 {
                    cam.insert("type".into(), json!("thin_lens"));
                    cam.insert("aperture_radius_m".into(), json!(lens));
                    cam.insert("focus_distance_m".into(), json!(focus));
                } else {
                    cam.insert("type".into(), json!("pinhole"));
                }
            }
            "orthographic" => {
                cam.insert("type".into(), json!("orthographic"));
                if params.float("lensradius")?.unwrap_or(0.0) > 0.0 {
                    out.unsupported.note("orthographic camera lensradius", "ignored: Prism's orthographic camera has no lens", at);
                }
                params.float("focaldistance")?;
            }
            "spherical" => {
                cam.insert("type".into(), json!("spherical"));
                let mapping = params.string("mapping")?.unwrap_or_else(|| "equalarea".into());
                if mapping != "equirectangular" {
                    out.unsupported.note(
                        format!("spherical camera mapping \"{mapping}\""),
                        "imported as Prism's equirectangular spherical camera (a different image layout)",
                        at,
                    );
                }
            }
            other => {
                return Err(ImportError::at(
                    at,
                    format!("Camera \"{other}\": expected perspective, orthographic or spherical (realistic is not imported)"),
                ))
            }
        }
        cam.insert("transform".into(), matrix_json(&to_world));
        params.finish(&format!("Camera \"{kind}\""), &mut out.unsupported);
        self.camera = Some((kind.to_string(), cam, at.clone()));
        Ok(())
    }

    pub fn directive(
        &mut self,
        out: &mut SceneBuilder,
        directive: &str,
        kind: &str,
        params: &Params,
        at: &Location,
    ) -> Result<(), ImportError> {
        let context = format!("{directive} \"{kind}\"");
        match directive {
            "Film" => {
                if kind != "rgb" {
                    out.unsupported.note(
                        format!("Film \"{kind}\""),
                        "imported as an RGB film (prism render --spectral-bins writes spectral images)",
                        at,
                    );
                }
                let dim = |n: &str, d: f64| -> Result<u32, ImportError> {
                    let v = params.float_or(n, d)?;
                    if v >= 1.0 && v.fract() == 0.0 && v <= u32::MAX as f64 {
                        Ok(v as u32)
                    } else {
                        Err(ImportError::at(
                            at,
                            format!("Film {n}: expected a whole number ≥ 1, found {v}"),
                        ))
                    }
                };
                let (w, h) = (dim("xresolution", 1280.0)?, dim("yresolution", 720.0)?);
                self.resolution = Some((w, h));
                out.film.insert("resolution".into(), json!([w, h]));
                if let Some(f) = params.string("filename")? {
                    if f.ends_with(".exr") || f.ends_with(".png") {
                        out.film.insert("output".into(), json!(f));
                    } else {
                        out.unsupported.note(
                            "Film filename not .exr or .png",
                            "ignored: Prism writes EXR or PNG",
                            at,
                        );
                    }
                }
            }
            "PixelFilter" => {
                let mut r = |d: f64| -> Result<f64, ImportError> {
                    let x = params.float_or("xradius", d)?;
                    let y = params.float_or("yradius", d)?;
                    if x != y {
                        out_note(
                            out,
                            "PixelFilter with xradius ≠ yradius",
                            "Prism's filters are round: xradius used",
                            at,
                        );
                    }
                    Ok(x)
                };
                let filter = match kind {
                    "box" => json!({"type": "box", "radius_px": r(0.5)?}),
                    "gaussian" => {
                        json!({"type": "gaussian", "radius_px": r(1.5)?, "sigma_px": params.float_or("sigma", 0.5)?})
                    }
                    "mitchell" => {
                        json!({"type": "mitchell", "radius_px": r(2.0)?, "b": params.float_or("B", 1.0 / 3.0)?, "c": params.float_or("C", 1.0 / 3.0)?})
                    }
                    other => {
                        out.unsupported.note(
                            format!("PixelFilter \"{other}\""),
                            "Prism's filters are box, gaussian, mitchell and blackman_harris: pbrt's default Gaussian is used",
                            at,
                        );
                        for q in &params.list {
                            q.used.set(true);
                        }
                        json!({"type": "gaussian", "radius_px": 1.5, "sigma_px": 0.5})
                    }
                };
                out.film.insert("filter".into(), filter);
            }
            "Sampler" => {
                let spp = params.float_or("pixelsamples", 16.0)?;
                if !(spp >= 1.0 && spp.fract() == 0.0) {
                    return Err(ImportError::at(
                        at,
                        format!("Sampler pixelsamples: expected a whole number ≥ 1, found {spp}"),
                    ));
                }
                out.film.insert("spp".into(), json!(spp as u64));
                if let Some(seed) = params.float("seed")? {
                    if !(0.0..=9_007_199_254_740_992.0).contains(&seed) || seed.fract() != 0.0 {
                        return Err(ImportError::at(
                            at,
                            format!(
                                "Sampler seed: expected a whole number in [0, 2^53], found {seed}"
                            ),
                        ));
                    }
                    out.film.insert("seed".into(), json!(seed as u64));
                }
                self.sampler = Some(match kind {
                    "independent" => "independent",
                    "sobol" | "zsobol" | "paddedsobol" => "sobol",
                    other => {
                        out.unsupported.note(
                            format!("Sampler \"{other}\""),
                            "Prism's stratified sampler is sobol: used instead (same mean, different noise)",
                            at,
                        );
                        "sobol"
                    }
                });
                params.string("randomization")?;
            }
            "Integrator" => {
                let depth = params.float_or("maxdepth", 5.0)?;
                if !(depth >= 1.0 && depth.fract() == 0.0) {
                    return Err(ImportError::at(at, format!("Integrator maxdepth: expected a whole number ≥ 1 (Prism needs one bounce), found {depth}")));
                }
                // Both count scattering events: pbrt's maxdepth 1 is direct lighting, as is Prism's.
                let ty = match kind {
                    "path" | "volpath" => "path",
                    "bdpt" => "bdpt",
                    other => {
                        out.unsupported.note(
                            format!("Integrator \"{other}\""),
                            "imported as Prism's path",
                            at,
                        );
                        "path"
                    }
                };
                // Light sampling strategies change the noise, not the mean.
                params.string("lightsampler")?;
                if params.boolean("regularize")? == Some(true) {
                    out.unsupported.note(
                        "Integrator regularize",
                        "ignored: Prism does not regularise BSDFs",
                        at,
                    );
                }
                self.integrator = Some(json!({"type": ty, "max_depth": depth as u64}));
            }
            _ => {
                out.unsupported.note(
                    directive.to_string(),
                    "not imported: Prism chooses this itself",
                    at,
                );
                for q in &params.list {
                    q.used.set(true);
                }
            }
        }
        params.finish(&context, &mut out.unsupported);
        Ok(())
    }

    /// Writes the camera (its field-of-view axis needs the film) and the integrator.
    pub fn finish(&mut self, out: &mut SceneBuilder) {
        let (w, h) = self.resolution.unwrap_or((1280, 720));
        if let Some((kind, mut cam, _)) = self.camera.take() {
            match kind.as_str() {
                "perspective" => {
                    // pbrt's fov spans the shorter image axis.
                    let shorter_is_x = w < h;
                    let fov = cam.get("fov_deg").and_then(Value::as_f64).unwrap_or(90.0);
                    if cam.get("type") == Some(&json!("thin_lens")) {
                        // Prism's thin lens takes the horizontal field of view.
                        let half = (fov.to_radians() / 2.0).tan();
                        let half_h = if shorter_is_x {
                            half
                        } else {
                            half * w as f64 / h as f64
                        };
                        cam.insert("fov_deg".into(), json!(2.0 * half_h.atan().to_degrees()));
                    } else {
                        cam.insert(
                            "fov_axis".into(),
                            json!(if shorter_is_x {
                                "horizontal"
                            } else {
                                "vertical"
                            }),
                        );
                    }
                }
                "orthographic" => {
                    // pbrt's screen window spans [-1, 1] along the shorter axis.
                    let width_m = if w < h {
                        2.0
                    } else {
                        2.0 * w as f64 / h as f64
                    };
                    cam.insert("width_m".into(), json!(width_m));
                }
                _ => {}
            }
            let mut ordered = Map::new();
            if let Some(t) = cam.remove("type") {
                ordered.insert("type".into(), t);
            }
            ordered.extend(cam);
            out.camera = Some(Value::Object(ordered));
        }
        let mut integrator = self
            .integrator
            .take()
            .unwrap_or_else(|| json!({"type": "path", "max_depth": 5}));
        if let Some(map) = integrator.as_object_mut() {
            map.insert("sampler".into(), json!(self.sampler.unwrap_or("sobol")));
        }
        out.integrator = Some(integrator);
    }
}

fn out_note(out: &mut SceneBuilder, kind: &str, consequence: &str, at: &Location) {
    out.unsupported.note(kind, consequence, at);
}

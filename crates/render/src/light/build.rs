//! Scene light descriptions (prism-scene `Light`) → runtime emitters: the emission
//! spectrum, the strength made absolute (photometric conversions in docs/lights.md), the
//! emitting shape of area lights, and the environment map file. Every error names the
//! scene file and the JSON path of the offending field (`lights[3].file`, …).

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use glam::{DVec3, Vec3A};
use prism_geometry::{Geometry, Shape};
use prism_scene::{LightKind, SceneDescription, Strength};
use prism_spectrum::Spectrum;

use super::area::{
    AreaLight, AreaShape, DiskEmitter, EmitterMesh, MeshEmitter, RectangleEmitter, SphereEmitter,
};
use super::daylight::build_daylight;
use super::environment::{rotation_of, EnvironmentLight};
use super::photometry::{
    lambertian_luminance_from_flux, photometric_scale, point_intensity_from_flux,
};
use super::scene_sphere::SceneSphere;
use super::spot::solid_angle_of_falloff;
use super::{DirectionalLight, Light, PointLight, SpotLight, UniformSky, NO_LIGHT};
use crate::scene_build::spectrum::{build_spectrum, SpectrumRole};
use crate::scene_build::SceneBuildError;

/// What `LightSet::new` needs.
pub(super) struct BuiltLights {
    pub lights: Vec<Light>,
    pub instance_light: Vec<u32>,
    pub scene: SceneSphere,
}

/// The scene-file field of a strength.
fn strength_field(s: &Strength) -> &'static str {
    match s {
        Strength::LuminousFluxLm(_) => "power_lm",
        Strength::IntensityCd(_) => "intensity_cd",
        Strength::LuminanceCdM2(_) => "luminance_cd_m2",
        Strength::IlluminanceLx(_) => "illuminance_lx",
        Strength::Scale(_) => "scale",
    }
}

fn strength_value(s: &Strength) -> f64 {
    match *s {
        Strength::LuminousFluxLm(v)
        | Strength::IntensityCd(v)
        | Strength::LuminanceCdM2(v)
        | Strength::IlluminanceLx(v)
        | Strength::Scale(v) => v,
    }
}

/// How one light's strength becomes absolute.
enum Target {
    /// Multiply the spectrum by this factor.
    Scale(f64),
    /// Scale the spectrum so that its photometric value is this (cd, cd/m² or lx).
    Photometric(f64),
}

pub(super) struct LightBuilder<'a> {
    file: &'a Path,
    index: usize,
    kind_name: &'static str,
    strength: Strength,
}

impl LightBuilder<'_> {
    fn place(&self) -> String {
        format!("lights[{}]", self.index)
    }

    pub(super) fn err(&self, field: &str, message: impl Into<String>) -> SceneBuildError {
        let place = if field.is_empty() {
            self.place()
        } else {
            format!("{}.{field}", self.place())
        };
        SceneBuildError::new(self.file, place, message)
    }

    /// The strength's value, checked finite and ≥ 0.
    fn value(&self) -> Result<f64, SceneBuildError> {
        let v = strength_value(&self.strength);
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(
                strength_field(&self.strength),
                format!("expected a finite value ≥ 0, found {v}"),
            ))
        }
    }

    pub(super) fn unsupported(&self) -> SceneBuildError {
        self.err(
            strength_field(&self.strength),
            format!(
                "a {} light does not take `{}` (see docs/scene-format.md, lights)",
                self.kind_name,
                strength_field(&self.strength)
            ),
        )
    }

    /// `spectrum` made absolute.
    fn absolute(&self, spectrum: Spectrum, target: Target) -> Result<Spectrum, SceneBuildError> {
        let field = strength_field(&self.strength);
        let k = match target {
            Target::Scale(k) => k,
            Target::Photometric(v) => {
                photometric_scale(&spectrum, v).map_err(|e| self.err(field, e))?
            }
        };
        let k32 = k as f32;
        if !(k.is_finite() && k >= 0.0 && k32.is_finite()) {
            return Err(self.err(
                field,
                format!("the spectrum scaled by {k:e} is beyond single precision"),
            ));
        }
        Ok(spectrum.scaled(k32))
    }
}

fn vec3(v: &[f64; 3]) -> Vec3A {
    DVec3::from(*v).as_vec3a()
}

/// The emitting shape placed by the geometry instances `instances` (one analytic shape, or
/// every instance of one mesh).
fn area_shape(geometry: &Geometry, instances: Range<u32>) -> Result<AreaShape, &'static str> {
    let all = geometry.instances();
    let slice = all
        .get(instances.start as usize..instances.end as usize)
        .ok_or("internal error: the shape's instances are not in the geometry")?;
    let Some(first) = slice.first() else {
        return Err("the shape has no instances");
    };
    Ok(match first.shape {
        Shape::Mesh(id) => {
            if slice.iter().any(|i| i.shape != Shape::Mesh(id)) {
                return Err("internal error: a shape's instances place different meshes");
            }
            let transforms: Vec<_> = slice.iter().map(|i| i.to_world).collect();
            let mesh = Arc::new(EmitterMesh::from_triangle_mesh(geometry.mesh(id)));
            AreaShape::Mesh(MeshEmitter::new(mesh, &transforms))
        }
        Shape::Sphere(s) => AreaShape::Sphere(SphereEmitter::new(s, first.to_world)),
        Shape::Disk(d) => AreaShape::Disk(DiskEmitter::new(d, first.to_world)),
        Shape::Rectangle(r) => AreaShape::Rectangle(RectangleEmitter::new(r, first.to_world)),
        Shape::Tiled(_) => {
            return Err(
                "a shape with a `tiled` material cannot emit: its surface is the tile's faces, \
                 which take the tile's own materials (make a separate emitting shape)",
            )
        }
    })
}

/// Builds every light of `scene`; `ranges[i]` are the instance ids of `shapes[i]` in
/// `geometry`.
pub(super) fn build_lights(
    scene: &SceneDescription,
    geometry: &Geometry,
    ranges: &[Range<u32>],
) -> Result<BuiltLights, SceneBuildError> {
    let file: &Path = &scene.file;
    let scene_sphere = SceneSphere::of_geometry(geometry);
    let mut lights = Vec::with_capacity(scene.lights.len());
    let mut instance_light = vec![NO_LIGHT; geometry.instances().len()];
    for (index, l) in scene.lights.iter().enumerate() {
        let b = LightBuilder {
            file,
            index,
            kind_name: match l.kind {
                LightKind::Point { .. } => "point",
                LightKind::Spot { .. } => "spot",
                LightKind::Directional { .. } => "directional",
                LightKind::Area { .. } => "area",
                LightKind::Environment { .. } => "environment",
                LightKind::UniformSky => "sky",
                LightKind::Daylight(_) => "daylight sky",
                LightKind::Luminaire { .. } => "luminaire",
            },
            strength: l.strength,
        };
        let value = b.value()?;
        let spectrum = || {
            build_spectrum(&l.spectrum, SpectrumRole::Illuminant).map_err(|e| b.err("spectrum", e))
        };
        // A daylight sky brings its sun as a second emitter, pushed right after it.
        let mut extra: Option<Light> = None;
        let light = match &l.kind {
            LightKind::Point { position_m } => {
                let target = match l.strength {
                    Strength::Scale(_) => Target::Scale(value),
                    Strength::IntensityCd(_) => Target::Photometric(value),
                    Strength::LuminousFluxLm(_) => {
                        Target::Photometric(point_intensity_from_flux(value))
                    }
                    Strength::LuminanceCdM2(_) | Strength::IlluminanceLx(_) => {
                        return Err(b.unsupported())
                    }
                };
                Light::Point(PointLight {
                    position_m: vec3(position_m),
                    intensity: b.absolute(spectrum()?, target)?,
                })
            }
            LightKind::Spot {
                position_m,
                direction,
                cone_angle_rad,
                falloff_start_rad,
            } => {
                let start = falloff_start_rad.clamp(0.0, *cone_angle_rad);
                let target = match l.strength {
                    Strength::Scale(_) => Target::Scale(value),
                    Strength::IntensityCd(_) => Target::Photometric(value),
                    Strength::LuminousFluxLm(_) => Target::Photometric(
                        value
                            / solid_angle_of_falloff(
                                f64::from(cone_angle_rad.cos() as f32),
                                f64::from(start.cos() as f32),
                            ),
                    ),
                    Strength::LuminanceCdM2(_) | Strength::IlluminanceLx(_) => {
                        return Err(b.unsupported())
                    }
                };
                Light::Spot(SpotLight::new(
                    vec3(position_m),
                    vec3(direction),
                    *cone_angle_rad,
                    start,
                    b.absolute(spectrum()?, target)?,
                ))
            }
            LightKind::Directional {
                direction,
                angular_diameter_rad,
            } => {
                let target = match l.strength {
                    Strength::Scale(_) => Target::Scale(value),
                    Strength::IlluminanceLx(_) => Target::Photometric(value),
                    Strength::LuminousFluxLm(_)
                    | Strength::IntensityCd(_)
                    | Strength::LuminanceCdM2(_) => return Err(b.unsupported()),
                };
                Light::Directional(DirectionalLight::new(
                    vec3(direction),
                    *angular_diameter_rad,
                    b.absolute(spectrum()?, target)?,
                    scene_sphere,
                ))
            }
            LightKind::Area { shape, two_sided } => {
                let shape_place =
                    |k: usize| match scene.shapes.get(k).and_then(|s| s.name.as_deref()) {
                        Some(name) => format!("shape `{name}` (shapes[{k}])"),
                        None => format!("shapes[{k}]"),
                    };
                let range = ranges.get(*shape).cloned().ok_or_else(|| {
                    b.err(
                        "shape",
                        format!("{} is not in the scene", shape_place(*shape)),
                    )
                })?;
                let emitter = area_shape(geometry, range.clone())
                    .map_err(|e| b.err("shape", format!("{}: {e}", shape_place(*shape))))?;
                let area = emitter.area_m2();
                if !(area > 0.0 && area.is_finite()) {
                    return Err(b.err(
                        "shape",
                        format!(
                            "{} has zero area (after its transforms), so it cannot emit",
                            shape_place(*shape)
                        ),
                    ));
                }
                let sides = if *two_sided { 2.0 } else { 1.0 };
                let target = match l.strength {
                    Strength::Scale(_) => Target::Scale(value),
                    Strength::LuminanceCdM2(_) => Target::Photometric(value),
                    Strength::LuminousFluxLm(_) => {
                        Target::Photometric(lambertian_luminance_from_flux(value, area, sides))
                    }
                    Strength::IntensityCd(_) | Strength::IlluminanceLx(_) => {
                        return Err(b.unsupported())
                    }
                };
                let light_index = lights.len() as u32;
                for id in range {
                    let slot = &mut instance_light[id as usize];
                    if *slot != NO_LIGHT {
                        return Err(b.err(
                            "shape",
                            format!(
                                "{} already emits as another area light; a shape carries at most one",
                                shape_place(*shape)
                            ),
                        ));
                    }
                    *slot = light_index;
                }
                Light::Area(AreaLight {
                    shape: emitter.emitting_sides(*two_sided),
                    radiance: b.absolute(spectrum()?, target)?,
                    two_sided: *two_sided,
                })
            }
            LightKind::Environment {
                path,
                transform,
                filter,
            } => {
                let scale = match l.strength {
                    Strength::Scale(_) => value as f32,
                    Strength::LuminousFluxLm(_)
                    | Strength::IntensityCd(_)
                    | Strength::LuminanceCdM2(_)
                    | Strength::IlluminanceLx(_) => return Err(b.unsupported()),
                };
                if !scale.is_finite() {
                    return Err(b.err("scale", format!("{value} is beyond single precision")));
                }
                let rotation = rotation_of(&transform.matrix).map_err(|e| b.err("transform", e))?;
                let env = EnvironmentLight::load(path, rotation, scale, *filter, scene_sphere)
                    .map_err(|e| b.err("file", format!("cannot use the environment map: {e}")))?;
                Light::Environment(Box::new(env))
            }
            LightKind::UniformSky => {
                let target = match l.strength {
                    Strength::Scale(_) => Target::Scale(value),
                    Strength::LuminanceCdM2(_) => Target::Photometric(value),
                    Strength::LuminousFluxLm(_)
                    | Strength::IntensityCd(_)
                    | Strength::IlluminanceLx(_) => return Err(b.unsupported()),
                };
                Light::Sky(UniformSky {
                    radiance: b.absolute(spectrum()?, target)?,
                    scene: scene_sphere,
                })
            }
            LightKind::Daylight(desc) => {
                // Daylight reaches below 360 nm only where something is excited there.
                let ultraviolet = !scene.reradiation.is_empty();
                let built =
                    build_daylight(desc, scene_sphere, ultraviolet).map_err(|e| b.err("", e))?;
                extra = built.sun.map(Light::Directional);
                Light::Daylight(Box::new(built.sky))
            }
            LightKind::Luminaire {
                distribution,
                position_m,
                aim,
                c0_direction,
            } => super::goniometric_build::build(
                &b,
                l.strength,
                value,
                distribution,
                position_m,
                aim,
                c0_direction,
                spectrum()?,
            )?,
        };
        lights.push(light);
        lights.extend(extra);
    }
    Ok(BuiltLights {
        lights,
        instance_light,
        scene: scene_sphere,
    })
}

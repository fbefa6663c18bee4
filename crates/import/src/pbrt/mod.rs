//! pbrt-v4 scenes → Prism JSON: tokenizer, parser, graphics state (this file), and one file
//! each for spectra, render options (camera, film, sampler, integrator), materials and
//! textures, shapes and lights.

pub mod goniometric;
pub mod light;
pub mod material;
pub mod octahedral;
pub mod options;
pub mod params;
pub mod parser;
pub mod shape;
pub mod spectra;
pub mod tokenizer;

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3, DVec4};
use serde_json::Value;

use crate::error::{ImportError, Location};
use crate::output::{Imported, SceneBuilder};
use crate::ImportOptions;
use params::Params;
use parser::Parser;

/// `AreaLightSource "diffuse"` in effect: emitted by every shape that follows.
#[derive(Debug, Clone)]
pub struct AreaLight {
    pub spectrum: Value,
    pub scale: f64,
    pub two_sided: bool,
}

/// pbrt's graphics state (saved by AttributeBegin).
#[derive(Debug, Clone)]
pub struct GraphicsState {
    pub ctm: DMat4,
    /// Prism material name; None is pbrt's default (`material::default_material`).
    pub material: Option<String>,
    pub area_light: Option<AreaLight>,
    pub reverse_orientation: bool,
}

/// A shape recorded inside ObjectBegin/End: its JSON and its object-space matrix.
#[derive(Debug, Clone)]
pub struct ObjectShape {
    pub shape: serde_json::Map<String, Value>,
    pub matrix: DMat4,
}

pub struct Importer {
    pub out: SceneBuilder,
    pub g: GraphicsState,
    stack: Vec<(GraphicsState, Location)>,
    pub named_materials: HashMap<String, String>,
    pub textures: HashMap<String, String>,
    named_coordinate_systems: HashMap<String, DMat4>,
    pub objects: HashMap<String, Vec<ObjectShape>>,
    /// The object being defined (ObjectBegin) and its shapes.
    pub current_object: Option<(String, Vec<ObjectShape>)>,
    pub options: options::RenderOptions,
    pub mesh_count: usize,
}

pub fn import(path: &Path, import_options: &ImportOptions) -> Result<Imported, ImportError> {
    let mut parser = Parser::open(path)?;
    let mut im = Importer {
        out: SceneBuilder::new(&import_options.output_dir, &import_options.side_dir),
        g: GraphicsState {
            ctm: DMat4::IDENTITY,
            material: None,
            area_light: None,
            reverse_orientation: false,
        },
        stack: Vec::new(),
        named_materials: HashMap::new(),
        textures: HashMap::new(),
        named_coordinate_systems: HashMap::new(),
        objects: HashMap::new(),
        current_object: None,
        options: options::RenderOptions::default(),
        mesh_count: 0,
    };
    let mut in_world = false;
    while let Some((name, at)) = parser.directive()? {
        im.directive(&mut parser, &name, &at, &mut in_world)?;
    }
    if let Some((_, at)) = im.stack.last() {
        return Err(ImportError::at(
            at,
            "AttributeBegin without a matching AttributeEnd",
        ));
    }
    im.options.finish(&mut im.out);
    Ok(im.out.finish())
}

impl Importer {
    fn directive(
        &mut self,
        p: &mut Parser,
        name: &str,
        at: &Location,
        in_world: &mut bool,
    ) -> Result<(), ImportError> {
        let world_only = |what: &str| -> Result<(), ImportError> {
            if *in_world {
                Ok(())
            } else {
                Err(ImportError::at(
                    at,
                    format!("{what} is allowed only after WorldBegin"),
                ))
            }
        };
        match name {
            "Identity" => self.g.ctm = DMat4::IDENTITY,
            "Translate" => {
                let v = p.numbers(3, name)?;
                self.g.ctm *= DMat4::from_translation(DVec3::new(v[0], v[1], v[2]));
            }
            "Scale" => {
                let v = p.numbers(3, name)?;
                self.g.ctm *= DMat4::from_scale(DVec3::new(v[0], v[1], v[2]));
            }
            "Rotate" => {
                let v = p.numbers(4, name)?;
                let axis = DVec3::new(v[1], v[2], v[3])
                    .try_normalize()
                    .ok_or_else(|| ImportError::at(at, "Rotate: expected a non-zero axis"))?;
                self.g.ctm *= DMat4::from_axis_angle(axis, v[0].to_radians());
            }
            "LookAt" => {
                let v = p.numbers(9, name)?;
                let eye = DVec3::new(v[0], v[1], v[2]);
                let look = DVec3::new(v[3], v[4], v[5]);
                let up = DVec3::new(v[6], v[7], v[8]);
                let world_from_camera = look_at(eye, look, up).ok_or_else(|| {
                    ImportError::at(
                        at,
                        "LookAt: expected eye ≠ look and `up` not parallel to the view direction",
                    )
                })?;
                self.g.ctm *= world_from_camera.inverse();
            }
            "Transform" | "ConcatTransform" => {
                let v = p.numbers(16, name)?;
                // pbrt's matrices are written column by column (pbrt transposes them).
                let m = DMat4::from_cols(
                    DVec4::new(v[0], v[1], v[2], v[3]),
                    DVec4::new(v[4], v[5], v[6], v[7]),
                    DVec4::new(v[8], v[9], v[10], v[11]),
                    DVec4::new(v[12], v[13], v[14], v[15]),
                );
                if m.determinant() == 0.0 {
                    return Err(ImportError::at(
                        at,
                        format!("{name}: the matrix is not invertible"),
                    ));
                }
                if name == "Transform" {
                    self.g.ctm = m;
                } else {
                    self.g.ctm *= m;
                }
            }
            "CoordinateSystem" => {
                let n = p.string("a coordinate system name")?;
                self.named_coordinate_systems.insert(n, self.g.ctm);
            }
            "CoordSysTransform" => {
                let n = p.string("a coordinate system name")?;
                self.g.ctm = *self.named_coordinate_systems.get(&n).ok_or_else(|| {
                    ImportError::at(at, format!("CoordSysTransform \"{n}\": no such coordinate system (define it with CoordinateSystem, or use \"camera\" after Camera)"))
                })?;
            }
            "ReverseOrientation" => self.g.reverse_orientation = !self.g.reverse_orientation,
            "Camera" => {
                let kind = p.string("the camera type")?;
                let params = p.params()?;
                let camera_from_world = self.g.ctm;
                self.named_coordinate_systems
                    .insert("camera".into(), camera_from_world.inverse());
                self.options
                    .camera(&mut self.out, &kind, &params, camera_from_world, at)?;
            }
            "Film" | "Sampler" | "Integrator" | "PixelFilter" | "Accelerator" | "ColorSpace"
            | "Option" => {
                let kind = if name == "Option" {
                    // Option "type name" value: a parameter declaration without a type string.
                    String::new()
                } else {
                    p.string(&format!("the {name} type"))?
                };
                let params = p.params()?;
                self.options
                    .directive(&mut self.out, name, &kind, &params, at)?;
            }
            "WorldBegin" => {
                *in_world = true;
                self.g.ctm = DMat4::IDENTITY;
                self.named_coordinate_systems
                    .insert("world".into(), DMat4::IDENTITY);
            }
            "AttributeBegin" | "TransformBegin" => {
                self.stack.push((self.g.clone(), at.clone()));
            }
            "AttributeEnd" | "TransformEnd" => {
                let (saved, _) = self.stack.pop().ok_or_else(|| {
                    ImportError::at(at, format!("{name} without a matching AttributeBegin"))
                })?;
                if name == "TransformEnd" {
                    self.g.ctm = saved.ctm;
                } else {
                    self.g = saved;
                }
            }
            "Attribute" => {
                let target =
                    p.string("the attribute target (shape, light, material, medium, texture)")?;
                let params = p.params()?;
                params.finish(
                    &format!("Attribute \"{target}\""),
                    &mut self.out.unsupported,
                );
            }
            "Material" => {
                world_only(name)?;
                let kind = p.string("the material type")?;
                let params = p.params()?;
                let m = material::material(self, &kind, &params, at)?;
                self.g.material = m;
            }
            "MakeNamedMaterial" => {
                world_only(name)?;
                let n = p.string("the material name")?;
                let params = p.params()?;
                let kind = params.string("type")?.ok_or_else(|| {
                    ImportError::at(
                        at,
                        format!("MakeNamedMaterial \"{n}\": needs \"string type\""),
                    )
                })?;
                if let Some(prism) = material::named_material(self, &n, &kind, &params, at)? {
                    self.named_materials.insert(n, prism);
                }
            }
            "NamedMaterial" => {
                world_only(name)?;
                let n = p.string("the material name")?;
                let prism = self.named_materials.get(&n).ok_or_else(|| {
                    let mut known: Vec<&str> =
                        self.named_materials.keys().map(String::as_str).collect();
                    known.sort_unstable();
                    ImportError::at(
                        at,
                        format!(
                            "NamedMaterial \"{n}\": not defined by MakeNamedMaterial (defined: {})",
                            known.join(", ")
                        ),
                    )
                })?;
                self.g.material = Some(prism.clone());
            }
            "Texture" => {
                world_only(name)?;
                let n = p.string("the texture name")?;
                let ty = p.string("the texture value type (spectrum or float)")?;
                let class = p.string("the texture class")?;
                let params = p.params()?;
                material::texture(self, &n, &ty, &class, &params, at)?;
            }
            "Shape" => {
                world_only(name)?;
                let kind = p.string("the shape type")?;
                let params = p.params()?;
                shape::shape(self, &kind, &params, at)?;
            }
            "AreaLightSource" => {
                world_only(name)?;
                let kind = p.string("the area light type")?;
                let params = p.params()?;
                self.g.area_light = light::area_light(self, &kind, &params, at)?;
            }
            "LightSource" => {
                world_only(name)?;
                let kind = p.string("the light type")?;
                let params = p.params()?;
                light::light(self, &kind, &params, at)?;
            }
            "ObjectBegin" => {
                world_only(name)?;
                let n = p.string("the object name")?;
                if self.current_object.is_some() {
                    return Err(ImportError::at(
                        at,
                        "ObjectBegin inside another ObjectBegin",
                    ));
                }
                self.stack.push((self.g.clone(), at.clone()));
                self.current_object = Some((n, Vec::new()));
            }
            "ObjectEnd" => {
                let (n, shapes) = self
                    .current_object
                    .take()
                    .ok_or_else(|| ImportError::at(at, "ObjectEnd without ObjectBegin"))?;
                self.objects.insert(n, shapes);
                let (saved, _) = self
                    .stack
                    .pop()
                    .ok_or_else(|| ImportError::at(at, "ObjectEnd without ObjectBegin"))?;
                self.g = saved;
            }
            "ObjectInstance" => {
                world_only(name)?;
                let n = p.string("the object name")?;
                shape::instance(self, &n, at)?;
            }
            "MakeNamedMedium" | "MediumInterface" => {
                p.string("a medium name")?;
                if name == "MediumInterface" {
                    p.optional_word();
                }
                let params = p.params()?;
                self.out
                    .unsupported
                    .note(name, "not imported: pbrt media are not translated", at);
                // Their parameters belong to that one report entry.
                for q in &params.list {
                    q.used.set(true);
                }
            }
            other => {
                return Err(ImportError::at(
                    at,
                    format!("unknown directive `{other}` (pbrt-v4 scene grammar)"),
                ))
            }
        }
        Ok(())
    }
}

/// pbrt's LookAt: world-from-camera with columns (right, up, dir, eye); pbrt's camera looks
/// down +Z.
pub fn look_at(eye: DVec3, look: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (look - eye).try_normalize()?;
    let right = up.try_normalize()?.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    Some(DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    ))
}

/// Params helper for modules: report unread parameters.
pub fn finish(im: &mut Importer, params: &Params, context: &str) {
    params.finish(context, &mut im.out.unsupported);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Imports `text` as a scene file in a fresh folder (removed afterwards).
    fn import_text(text: &str) -> Imported {
        crate::test_support::import_text("scene.pbrt", text)
    }

    /// pbrt's LookAt with up +Y looking down −Z puts image right at world −X (pbrt's
    /// left-handed camera); `Scale -1 1 1` before it, as exporters write, undoes that.
    #[test]
    fn camera_handedness_follows_pbrt() {
        let plain = import_text("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n");
        let m = &plain.scene["camera"]["transform"]["matrix"];
        assert_eq!(m[0], json_row([-1.0, 0.0, 0.0, 0.0]));
        let flipped = import_text(
            "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n",
        );
        let m = &flipped.scene["camera"]["transform"]["matrix"];
        assert_eq!(m[0], json_row([1.0, 0.0, 0.0, 0.0]));
        assert_eq!(m[2], json_row([0.0, 0.0, 1.0, 5.0]));
    }

    fn json_row(r: [f64; 4]) -> Value {
        serde_json::json!(r)
    }

    /// pbrt-v4's photometric strengths: `power` of a point (k_e = 4π) and a spot (its
    /// cone's), a uniform sky's `illuminance` (k_e = π); the spot's `conedeltaangle`.
    #[test]
    fn power_and_illuminance_scale_as_pbrt_does() {
        use std::f64::consts::PI;
        let i = import_text(
            "WorldBegin\nLightSource \"point\" \"float power\" 100 \"float scale\" 2\n\
             LightSource \"spot\" \"float power\" 100 \"float coneangle\" 30 \"float conedeltaangle\" 10\n\
             LightSource \"infinite\" \"float illuminance\" 1000\n",
        );
        let lights = i.scene["lights"].as_array().unwrap();
        let scale = |k: usize| lights[k]["scale"].as_f64().unwrap();
        assert!(
            (scale(0) - 2.0 * 100.0 / (4.0 * PI)).abs() < 1e-9,
            "{}",
            scale(0)
        );
        let (cos_end, cos_start) = (30f64.to_radians().cos(), 20f64.to_radians().cos());
        let k_e = 2.0 * PI * ((1.0 - cos_start) + (cos_start - cos_end) / 2.0);
        assert!((scale(1) - 100.0 / k_e).abs() < 1e-9, "{}", scale(1));
        assert_eq!(lights[1]["falloff_start_deg"], 20.0);
        assert!((scale(2) - 1000.0 / PI).abs() < 1e-9, "{}", scale(2));
        // Everything is imported exactly (the spot's falloff is pbrt's smoothstep too).
        let kinds: Vec<&str> = i
            .unsupported
            .kinds
            .iter()
            .map(|k| k.kind.as_str())
            .collect();
        assert!(kinds.is_empty(), "{kinds:?}");
    }

    #[test]
    fn named_metals_roughness_remap_and_mix() {
        let i = import_text(
            "WorldBegin\nMakeNamedMaterial \"au\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.09\n\
             MakeNamedMaterial \"d\" \"string type\" \"diffuse\"\n\
             MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"au\" \"d\"] \"float amount\" 0.25\n",
        );
        // pbrt's conductor reflects on both sides: a two_sided of the conductor.
        let materials = &i.scene["materials"];
        assert_eq!(materials["au"]["type"], "two_sided");
        let au = &materials[materials["au"]["material"].as_str().unwrap()];
        assert_eq!(au["metal"], "Au");
        assert!((au["roughness"].as_f64().unwrap() - 0.3).abs() < 1e-12);
        assert_eq!(
            i.scene["materials"]["m"]["materials"],
            serde_json::json!(["au", "d"])
        );
        assert_eq!(i.scene["materials"]["m"]["weight"], 0.25);
    }

    #[test]
    fn instances_compose_transforms_and_meshes_become_side_files() {
        let i = import_text(
            "WorldBegin\nObjectBegin \"tri\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n\
             Translate 2 0 0\nObjectInstance \"tri\"\nTranslate 0 3 0\nObjectInstance \"tri\"\n",
        );
        let shapes = i.scene["shapes"].as_array().unwrap();
        assert_eq!(shapes.len(), 2);
        assert_eq!(shapes[1]["transform"]["matrix"][1][3], 3.0);
        assert_eq!(shapes[1]["transform"]["matrix"][0][3], 2.0);
        assert_eq!(i.side_files.len(), 1);
        assert_eq!(
            String::from_utf8_lossy(&i.side_files[0].contents)
                .lines()
                .last(),
            Some("f 1 2 3")
        );
    }
}

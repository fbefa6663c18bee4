//! Mitsuba 3 XML scenes → Prism JSON. One file per concept: the XML reader (parameters,
//! includes), properties, transforms, spectra, textures, BSDFs, shapes, emitters, sensors and
//! integrators.

pub mod bsdf;
pub mod emitter;
pub mod integrator;
pub mod props;
pub mod sensor;
pub mod serialized;
pub mod shape;
pub mod spectra;
pub mod texture;
pub mod transform;
pub mod xml;

use std::collections::HashMap;
use std::path::Path;

use crate::error::ImportError;
use crate::output::{Imported, SceneBuilder};
use crate::ImportOptions;
use xml::Element;

/// Import state: the scene under construction and what ids name.
pub struct Ctx<'a> {
    pub out: SceneBuilder,
    ids: HashMap<String, &'a Element>,
    pub material_by_id: HashMap<String, String>,
    pub texture_by_id: HashMap<String, String>,
    pub sampler: &'static str,
    pub integrator: Option<(i64, i64)>,
}

impl<'a> Ctx<'a> {
    /// `el` itself, or the object a `<ref id=…>` names (which must be a `<tag>`).
    pub fn resolve(&self, el: &'a Element, tag: &str) -> Result<&'a Element, ImportError> {
        if el.tag != "ref" {
            return Ok(el);
        }
        let id = el.require_attr("id")?;
        let target = self.ids.get(id).ok_or_else(|| {
            let mut known: Vec<&str> = self.ids.keys().map(String::as_str).collect();
            known.sort_unstable();
            ImportError::at(
                &el.at,
                format!(
                    "<ref id=\"{id}\">: no object has this id (ids: {})",
                    known.join(", ")
                ),
            )
        })?;
        if target.tag != tag && !(tag == "texture" && is_spectrum_tag(&target.tag)) {
            return Err(ImportError::at(
                &el.at,
                format!(
                    "<ref id=\"{id}\">: expected a <{tag}>, but the id names a <{}>",
                    target.tag
                ),
            ));
        }
        Ok(target)
    }
}

fn is_spectrum_tag(tag: &str) -> bool {
    matches!(tag, "spectrum" | "rgb" | "float")
}

fn collect_ids<'a>(
    el: &'a Element,
    ids: &mut HashMap<String, &'a Element>,
) -> Result<(), ImportError> {
    for c in &el.children {
        if c.tag != "ref" {
            if let Some(id) = c.attr("id") {
                if let Some(previous) = ids.insert(id.to_string(), c) {
                    return Err(ImportError::at(
                        &c.at,
                        format!("id \"{id}\" is already used at {}", previous.at),
                    ));
                }
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

pub fn import(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    let root = xml::read_scene(path, &options.defines)?;
    let mut ids = HashMap::new();
    collect_ids(&root, &mut ids)?;
    let mut ctx = Ctx {
        out: SceneBuilder::new(&options.output_dir, &options.side_dir),
        ids,
        material_by_id: HashMap::new(),
        texture_by_id: HashMap::new(),
        sampler: "independent",
        integrator: None,
    };
    let mut sensors = 0;
    for c in &root.children {
        match c.tag.as_str() {
            "sensor" => {
                sensors += 1;
                if sensors == 1 {
                    sensor::sensor(&mut ctx, c)?;
                } else {
                    ctx.out.unsupported.note(
                        "a second <sensor>",
                        "not imported: a Prism scene has one camera (the first sensor's)",
                        &c.at,
                    );
                }
            }
            "integrator" => integrator::integrator(&mut ctx, c)?,
            "bsdf" => {
                bsdf::material(&mut ctx, c)?;
            }
            "texture" => {
                texture::texture(&mut ctx, c)?;
            }
            "shape" => shape::shape(&mut ctx, c)?,
            "emitter" => emitter::emitter(&mut ctx, c)?,
            // Named spectra are used through <ref>.
            "spectrum" | "rgb" if c.attr("id").is_some() => {}
            other => ctx.out.unsupported.note(
                format!("<{other}> at the top level"),
                "not imported (Prism imports sensor, integrator, bsdf, texture, shape and emitter)",
                &c.at,
            ),
        }
    }
    if sensors == 0 {
        ctx.out.unsupported.note(
            "scene without <sensor>",
            "Prism's default camera and film are used",
            &root.at,
        );
    }
    ctx.out.integrator = Some(integrator::integrator_json(&ctx));
    Ok(ctx.out.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Imports `text` as a scene file in a fresh folder (removed afterwards).
    fn import_text(text: &str) -> Imported {
        crate::test_support::import_text("scene.xml", text)
    }

    #[test]
    fn fov_axis_smaller_and_larger_follow_the_aspect_ratio() {
        for (axis, expected) in [
            ("smaller", "vertical"),
            ("larger", "horizontal"),
            ("y", "vertical"),
            ("diagonal", "diagonal"),
        ] {
            let i = import_text(&format!(
                "<scene version=\"3.0.0\"><sensor type=\"perspective\"><string name=\"fov_axis\" value=\"{axis}\"/>\
                 <float name=\"fov\" value=\"30\"/><film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/>\
                 <integer name=\"height\" value=\"100\"/></film></sensor></scene>"
            ));
            assert_eq!(i.scene["camera"]["fov_axis"], expected, "{axis}");
        }
    }

    #[test]
    fn sphere_center_radius_conductor_names_and_plastic() {
        let i = import_text(
            "<scene version=\"3.0.0\"><shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/>\
             <float name=\"radius\" value=\"0.5\"/><bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/>\
             <float name=\"alpha\" value=\"0.2\"/><string name=\"distribution\" value=\"ggx\"/></bsdf></shape>\
             <bsdf type=\"plastic\" id=\"p\"><rgb name=\"diffuse_reflectance\" value=\"0.2, 0.3, 0.4\"/></bsdf></scene>",
        );
        let s = &i.scene["shapes"][0];
        assert_eq!(s["radius_m"], 0.5);
        assert_eq!(s["transform"]["matrix"][1][3], 2.0);
        let m = &i.scene["materials"][s["material"].as_str().unwrap()];
        assert_eq!(m["metal"], "Au");
        assert_eq!(m["roughness"], 0.2);
        let p = &i.scene["materials"]["p"];
        assert_eq!(p["type"], "coated");
        assert!((p["ior"].as_f64().unwrap() - 1.49 / 1.000277).abs() < 1e-12);
        assert!(i
            .unsupported
            .lines()
            .iter()
            .any(|l| l.contains("bsdf plastic")));
    }

    #[test]
    fn serialized_meshes_become_obj_side_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("tri.serialized"),
            serialized::tests::one_triangle(),
        )
        .unwrap();
        let i = crate::test_support::import_text_in(
            dir.path(),
            "scene.xml",
            "<scene version=\"3.0.0\"><shape type=\"serialized\"><string name=\"filename\" value=\"tri.serialized\"/></shape></scene>",
        );
        assert_eq!(i.scene["shapes"][0]["file"], "a/serialized-0.obj");
        let obj = String::from_utf8(i.side_files[0].contents.clone()).unwrap();
        assert!(
            obj.contains("v 0 1 0.5\n") && obj.ends_with("f 1/1 2/2 3/3\n"),
            "{obj}"
        );
    }

    #[test]
    fn unlimited_depth_and_the_depth_offset() {
        let i = import_text("<scene version=\"3.0.0\"><integrator type=\"path\"><integer name=\"max_depth\" value=\"-1\"/></integrator></scene>");
        assert_eq!(
            i.scene["integrator"]["max_depth"],
            integrator::UNLIMITED_BOUNCES
        );
        let i = import_text("<scene version=\"3.0.0\"><integrator type=\"path\"><integer name=\"max_depth\" value=\"3\"/></integrator></scene>");
        assert_eq!(i.scene["integrator"]["max_depth"], 2);
    }
}

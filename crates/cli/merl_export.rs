//! `prism merl-export`: writes a material of a scene file as a MERL BRDF table
//! (docs/materials.md, "Measured BRDFs"), so the measured path can be compared with the
//! analytic one on the same material.

use std::path::PathBuf;

use clap::Args;
use prism_render::material::{build_materials, merl_export::export_material};

#[derive(Args, Debug)]
pub struct MerlExportArgs {
    /// Scene file holding the material.
    pub scene: PathBuf,
    /// Name of the material in the scene's `materials` section.
    #[arg(long)]
    pub material: String,
    /// Output MERL file (33 MB; conventionally `.binary`).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

pub fn run(args: &MerlExportArgs) -> Result<(), String> {
    let description = prism_scene::load_scene(&args.scene).map_err(|e| e.to_string())?;
    let Some(index) = description
        .materials
        .iter()
        .position(|m| m.name == args.material)
    else {
        let names: Vec<String> = description
            .materials
            .iter()
            .map(|m| format!("`{}`", m.name))
            .collect();
        return Err(format!(
            "{}: no material `{}` (defined: {})",
            args.scene.display(),
            args.material,
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ));
    };
    let materials = build_materials(&description).map_err(|e| e.to_string())?;
    let material = &materials[index];
    if material.opacity() < 1.0 {
        return Err(format!(
            "{}: material `{}` is masked (opacity {}); a MERL table holds a BRDF only",
            args.scene.display(),
            args.material,
            material.opacity()
        ));
    }
    let table = export_material(material);
    table.write(&args.output).map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {} ({} bytes) from material `{}` of {}",
        args.output.display(),
        prism_render::bsdf::MERL_FILE_BYTES,
        args.material,
        args.scene.display()
    );
    Ok(())
}

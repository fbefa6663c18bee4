//! `prism import SCENE.xml|SCENE.pbrt -o SCENE.json`: Mitsuba 3 and pbrt-v4 scenes to Prism's
//! JSON (prism-import), checked by Prism's own scene reader before it is written; and the
//! loader `prism render` uses for .xml/.pbrt scenes. What maps to what: docs/import.md.

use std::path::{Path, PathBuf};

use clap::Args;
use prism_import::{import_file, ImportOptions, Imported};

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The scene to import: Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    pub scene: PathBuf,
    /// The Prism scene to write (.json). Files the importer must create (inline meshes,
    /// spectra) go to `<output stem>-assets/` beside it.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: PathBuf,
    #[command(flatten)]
    pub import: ImportFlags,
}

/// Options shared by `prism import` and `prism render` of an .xml/.pbrt scene.
#[derive(Args, Debug, Clone, Default)]
pub struct ImportFlags {
    /// A Mitsuba scene parameter, NAME=VALUE (overrides the scene's <default>); repeatable.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    pub defines: Vec<(String, String)>,
    /// Refuse the scene when anything in it is not imported exactly (instead of warning).
    #[arg(long)]
    pub strict: bool,
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value))
            if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') =>
        {
            Ok((name.to_string(), value.to_string()))
        }
        _ => Err(format!(
            "expected NAME=VALUE with NAME of letters, digits and `_`, found `{s}`"
        )),
    }
}

/// Imports, prints the report of what was not imported exactly (an error with --strict).
fn import_reporting(
    scene: &Path,
    flags: &ImportFlags,
    output_dir: &Path,
    side_dir: &str,
) -> Result<Imported, String> {
    let options = ImportOptions {
        defines: flags.defines.clone(),
        output_dir: output_dir.to_path_buf(),
        side_dir: side_dir.to_string(),
    };
    let imported = import_file(scene, &options).map_err(|e| e.to_string())?;
    if flags.strict {
        imported
            .unsupported
            .clone()
            .into_strict_error()
            .map_err(|e| e.to_string())?;
    }
    for line in imported.unsupported.lines() {
        eprintln!("warning: {line}");
    }
    Ok(imported)
}

fn absolute(path: &Path) -> Result<PathBuf, String> {
    std::path::absolute(path).map_err(|e| format!("{}: {e}", path.display()))
}

fn folder_of(path: &Path) -> Result<PathBuf, String> {
    let abs = absolute(path)?;
    Ok(abs.parent().map(Path::to_path_buf).unwrap_or(abs))
}

fn write_side_files(base: &Path, imported: &Imported) -> Result<(), String> {
    for f in &imported.side_files {
        let path = base.join(&f.relative_path);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        crate::atomic_write::write_atomic(&path, &f.contents, "imported asset")?;
    }
    Ok(())
}

pub fn run(args: &ImportArgs) -> Result<(), String> {
    if args.output.extension().and_then(|e| e.to_str()) != Some("json") {
        return Err(format!(
            "-o {}: expected a .json file (Prism's scene format)",
            args.output.display()
        ));
    }
    crate::atomic_write::check_parent("-o", &args.output)?;
    let output_dir = folder_of(&args.output)?;
    let stem = args
        .output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene");
    let imported = import_reporting(
        &args.scene,
        &args.import,
        &output_dir,
        &format!("{stem}-assets"),
    )?;
    write_side_files(&output_dir, &imported)?;
    let text = imported.to_json_text();
    // Prism's reader checks the result as it will be read, before it replaces anything.
    prism_scene::parse_scene_str(&text, &args.output)
        .map_err(|e| format!("the imported scene is not valid for Prism: {e}"))?;
    crate::atomic_write::write_atomic(&args.output, text.as_bytes(), "scene")?;
    eprintln!(
        "wrote {} ({} warnings)",
        args.output.display(),
        imported.unsupported.kinds.len()
    );
    Ok(())
}

/// Side files of a direct render live in a temporary folder removed when this is dropped
/// (after the render: meshes are read when the scene is built).
pub struct SideFolder(Option<PathBuf>);

impl Drop for SideFolder {
    fn drop(&mut self) {
        if let Some(dir) = &self.0 {
            // Best effort: a leftover temporary folder is harmless.
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// Loads any scene `prism render` accepts: Prism JSON, or (by extension) Mitsuba XML and
/// pbrt, imported in memory and read as if it were `<scene folder>/<stem>.json`.
pub fn load_any_scene(
    scene: &Path,
    flags: &ImportFlags,
) -> Result<(prism_scene::SceneDescription, SideFolder), String> {
    if prism_import::SourceFormat::of_path(scene).is_none() {
        if !flags.defines.is_empty() {
            return Err("-D/--define: only Mitsuba (.xml) scenes have parameters".into());
        }
        let d = prism_scene::load_scene(scene).map_err(|e| e.to_string())?;
        return Ok((d, SideFolder(None)));
    }
    let scene_dir = folder_of(scene)?;
    let temp = std::env::temp_dir().join(format!("prism-import-{}", std::process::id()));
    let side_dir = temp.to_string_lossy().into_owned();
    let imported = import_reporting(scene, flags, &scene_dir, &side_dir)?;
    let folder = SideFolder((!imported.side_files.is_empty()).then(|| temp.clone()));
    // Side-file paths are absolute (the side folder is), so they are written from "/".
    write_side_files(Path::new(""), &imported)?;
    let as_json = scene_dir.join(format!(
        "{}.json",
        scene
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
    ));
    let d = prism_scene::parse_scene_str(&imported.to_json_text(), &as_json).map_err(|e| {
        format!(
            "{} (imported from {}): {e}",
            as_json.display(),
            scene.display()
        )
    })?;
    Ok((d, folder))
}

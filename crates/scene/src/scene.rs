//! The whole scene: the top-level object and the order its sections are resolved in
//! (spectra → media → reradiation → materials → meshes → shapes → lights; camera, film, integrator).

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use crate::camera::{parse_camera, Camera};
use crate::error::{JsonPath, SceneError};
use crate::film::{parse_film, Film};
use crate::integrator::{parse_integrator, Integrator};
use crate::json::{self, Position};
use crate::light::{parse_light, Light};
use crate::material::{parse_materials, Material};
use crate::medium::{medium_index, parse_media, Medium};
use crate::reader::{Ctx, Result, V};
use crate::reradiation::{parse_reradiation, Reradiation};
use crate::schema::schema;
use crate::sensor::{parse_sensors, Sensor};
use crate::shape::{parse_meshes, parse_shape, MeshAsset, Shape, ShapeContext};
use crate::spectrum_ref::{parse_spectrum, SpectrumRef, SpectrumUse};
use crate::texture::{parse_textures, Texture, TextureTable};
use crate::tile::{parse_tiles, tile_names, Tile};

/// Everything render needs to build a scene, as plain data: angles in radians, lengths in
/// metres, asset paths resolved, spectra loaded, references turned into indices.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneDescription {
    /// The scene file this came from.
    pub file: PathBuf,
    pub camera: Camera,
    pub film: Film,
    pub integrator: Integrator,
    /// The `spectra` section, in file order (references to them are already inlined).
    pub spectra: Vec<(String, SpectrumRef)>,
    pub materials: Vec<Material>,
    /// Mesh files, each loaded once: the `meshes` section, then files named on shapes.
    pub meshes: Vec<MeshAsset>,
    pub shapes: Vec<Shape>,
    pub lights: Vec<Light>,
    pub media: Vec<Medium>,
    /// The medium that fills space outside all shapes (`world_medium`): the default of
    /// shapes' `exterior_medium`, of the camera and of the lights. `None`: vacuum.
    pub world_medium: Option<usize>,
    /// The medium the camera sits in (`camera.medium`, else `world_medium`).
    pub camera_medium: Option<usize>,
    /// Per light, the medium it sits in (its `medium`, else `world_medium`).
    pub light_media: Vec<Option<usize>>,
    /// Illuminance sensors (`sensors`), measured by `prism render` beside the image.
    pub sensors: Vec<Sensor>,
    /// The `textures` section, then textures defined inline in materials (materials refer
    /// to them by index).
    pub textures: Vec<Texture>,
    /// The `reradiation` section (fluorescent materials refer to it by index).
    pub reradiation: Vec<Reradiation>,
    /// The `tiles` section (`tiled` materials refer to it by index).
    pub tiles: Vec<Tile>,
    /// Every file the scene names (meshes, textures, spectra, environment maps, MERL
    /// tables, …), resolved against its folder, each once, in the order the scene names
    /// them: what a cache keyed on the scene must hash besides the scene file itself.
    pub asset_files: Vec<PathBuf>,
}

pub const TOP_LEVEL_FIELDS: [&str; 15] = [
    "camera",
    "film",
    "integrator",
    "spectra",
    "materials",
    "meshes",
    "shapes",
    "lights",
    "media",
    "world_medium",
    "sensors",
    "textures",
    "reradiation",
    "tiles",
    "$schema",
];

/// Reads and parses a scene file; assets resolve relative to its folder.
pub fn load_scene(path: impl AsRef<Path>) -> std::result::Result<SceneDescription, SceneError> {
    let path = path.as_ref();
    let text = prism_cpu::text_file::read_text(path).map_err(|e| SceneError {
        file: path.to_path_buf(),
        position: None,
        path: JsonPath::default(),
        message: format!("cannot read the scene file: {e}"),
    })?;
    parse_scene_str(&text, path)
}

/// Parses scene text as if it were the file `path` (used for messages and to resolve assets).
pub fn parse_scene_str(
    text: &str,
    path: impl AsRef<Path>,
) -> std::result::Result<SceneDescription, SceneError> {
    let path = path.as_ref();
    let cx = Ctx {
        file: path.to_path_buf(),
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        assets: RefCell::new(Vec::new()),
    };
    // serde_json's syntax errors are the reference: exact, and with line:column.
    if let Err(e) = serde_json::from_str::<serde_json::Value>(text) {
        let position = Position {
            line: e.line(),
            column: e.column(),
        };
        let full = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        let message = full.strip_suffix(&suffix).unwrap_or(&full).to_string();
        return Err(cx.error(
            position,
            &JsonPath::default(),
            format!("invalid JSON: {message}"),
        ));
    }
    let root = json::parse(text).map_err(|e| {
        cx.error(
            e.pos,
            &JsonPath::default(),
            format!("invalid JSON: {}", e.message),
        )
    })?;
    let v = V {
        node: &root,
        path: JsonPath::default(),
        cx: &cx,
    };
    parse_root(&v)
}

fn parse_root(v: &V) -> Result<SceneDescription> {
    let o = v.object(schema!(""))?;

    let mut spectra: Vec<(String, SpectrumRef)> = Vec::new();
    if let Some(section) = o.get("spectra") {
        for (name, entry) in section.map()? {
            // Entries may use the ones above them.
            let s = parse_spectrum(&entry, &spectra, SpectrumUse::NonNegative)?;
            spectra.push((name.to_string(), s));
        }
    }
    let media = o
        .get("media")
        .map_or(Ok(Vec::new()), |m| parse_media(&m, &spectra))?;
    let mut textures = match o.get("textures") {
        Some(t) => parse_textures(&t, &spectra)?,
        None => TextureTable::default(),
    };
    let reradiation = o
        .get("reradiation")
        .map_or(Ok(Vec::new()), |r| parse_reradiation(&r))?;
    let tiles_section = o.get("tiles");
    let tile_names = tiles_section.as_ref().map_or(Ok(Vec::new()), tile_names)?;
    let materials = o.get("materials").map_or(Ok(Vec::new()), |m| {
        parse_materials(&m, &spectra, &mut textures, &reradiation, &tile_names)
    })?;
    let mut meshes = o
        .get("meshes")
        .map_or(Ok(Vec::new()), |m| parse_meshes(&m))?;

    let material_names: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    let tiled: Vec<bool> = materials
        .iter()
        .map(|m| matches!(m.kind, crate::material::MaterialKind::Tiled { .. }))
        .collect();
    let tiles =
        tiles_section.map_or(Ok(Vec::new()), |t| parse_tiles(&t, &material_names, &tiled))?;
    let medium_names: Vec<&str> = media.iter().map(|m| m.name.as_str()).collect();
    let shape_cx = ShapeContext {
        materials: &material_names,
        media: &medium_names,
    };
    let mut shapes: Vec<Shape> = Vec::new();
    if let Some(list) = o.get("shapes") {
        for item in list.array()? {
            let shape = parse_shape(&item, &shape_cx, &mut meshes)?;
            if let Some(name) = &shape.name {
                if shapes.iter().any(|s| s.name.as_ref() == Some(name)) {
                    return Err(item.member("name").unwrap_or(item).err(format!(
                        "shape name `{name}` is used twice; names must be unique"
                    )));
                }
            }
            shapes.push(shape);
        }
    }
    let world_medium = o
        .get("world_medium")
        .map(|m| medium_index(&m, &medium_names))
        .transpose()?;
    // A shape's unnamed side outside it is the world medium.
    for shape in &mut shapes {
        if shape.interior_medium.is_some() && shape.exterior_medium.is_none() {
            shape.exterior_medium = world_medium;
        }
    }
    let mut lights = Vec::new();
    let mut light_media = Vec::new();
    if let Some(list) = o.get("lights") {
        for item in list.array()? {
            lights.push(parse_light(&item, &spectra, &shapes)?);
            light_media.push(match item.member("medium") {
                Some(m) => Some(medium_index(&m, &medium_names)?),
                None => world_medium,
            });
        }
    }
    let camera_medium = match o.get("camera").and_then(|c| c.member("medium")) {
        Some(m) => Some(medium_index(&m, &medium_names)?),
        None => world_medium,
    };
    let camera = o
        .get("camera")
        .map_or(Ok(Camera::default()), |c| parse_camera(&c))?;
    let film = o
        .get("film")
        .map_or(Ok(Film::default()), |f| parse_film(&f, &v.cx.base_dir))?;
    let integrator = o
        .get("integrator")
        .map_or(Ok(Integrator::default()), |i| parse_integrator(&i))?;
    let sensors = o
        .get("sensors")
        .map_or(Ok(Vec::new()), |s| parse_sensors(&s))?;
    Ok(SceneDescription {
        file: v.cx.file.clone(),
        camera,
        film,
        integrator,
        spectra,
        materials,
        meshes,
        shapes,
        lights,
        media,
        world_medium,
        camera_medium,
        light_media,
        sensors,
        textures: textures.textures,
        reradiation,
        tiles,
        asset_files: unique_in_order(v.cx.assets.take()),
    })
}

/// `paths` with repeats dropped, first occurrence kept.
fn unique_in_order(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    let mut seen = std::collections::HashSet::new();
    paths
        .into_iter()
        .filter(|p| seen.insert(p.clone()))
        .collect()
}

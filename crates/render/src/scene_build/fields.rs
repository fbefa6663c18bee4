//! What render does with every key the scene reader accepts: the code that reads it, or the
//! error that refuses it, so that nothing parsed is silently dropped.
//!
//! prism-scene lists each kind of object it accepts with its keys (`prism_scene::schema::
//! rows()`; its parsers can check an object against nothing else). [`field_uses`] is the
//! other half — [`FIELD_USES`] here, and the material library's rows next to the code that
//! reads them (`material::library::FIELD_USES`); the test below walks every accepted key
//! path and fails, naming it, when no row covers it. So a key added to the reader fails
//! that test until someone wires it into render (naming the code that reads it) or refuses
//! it in [`refuse_unrendered`].
//!
//! Refusals live here, in one place.

use prism_scene::{Aov, JsonPath, SceneDescription};

use super::SceneBuildError;

/// What render does with a key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldUse {
    /// Read by this code.
    Read(&'static str),
    /// Building a scene that gives it is an error, raised by this code.
    Refused(&'static str),
    /// Carries no meaning for a render (why).
    Annotation(&'static str),
}

/// Keys of objects and what render does with them: every key of every pattern listed.
#[derive(Clone, Copy, Debug)]
pub struct FieldRow {
    /// `prism_scene::schema::ObjectSchema::pattern`s (`shapes[]<sphere>`).
    pub patterns: &'static [&'static str],
    pub keys: &'static [&'static str],
    pub use_: FieldUse,
}

pub(crate) const fn read(
    patterns: &'static [&'static str],
    keys: &'static [&'static str],
    by: &'static str,
) -> FieldRow {
    FieldRow {
        patterns,
        keys,
        use_: FieldUse::Read(by),
    }
}

const fn refused(
    patterns: &'static [&'static str],
    keys: &'static [&'static str],
    by: &'static str,
) -> FieldRow {
    FieldRow {
        patterns,
        keys,
        use_: FieldUse::Refused(by),
    }
}

const CAMERAS: &[&str] = &[
    "camera<pinhole>",
    "camera<thin_lens>",
    "camera<fisheye>",
    "camera<orthographic>",
    "camera<spherical>",
];
const FILTERS: &[&str] = &[
    "film.filter<box>",
    "film.filter<gaussian>",
    "film.filter<blackman_harris>",
    "film.filter<mitchell>",
];
const INTEGRATORS: &[&str] = &[
    "integrator<depth>",
    "integrator<normal>",
    "integrator<albedo>",
    "integrator<ambient_occlusion>",
    "integrator<path>",
    "integrator<light>",
    "integrator<bdpt>",
    "integrator<photon>",
    "integrator<photon_progressive>",
    "integrator<radiosity>",
];
const TRANSPORT: &[&str] = &[
    "integrator<path>",
    "integrator<light>",
    "integrator<bdpt>",
    "integrator<photon>",
    "integrator<photon_progressive>",
];
const PHOTON: &[&str] = &["integrator<photon>", "integrator<photon_progressive>"];
const SHAPES: &[&str] = &[
    "shapes[]<mesh>",
    "shapes[]<sphere>",
    "shapes[]<rectangle>",
    "shapes[]<disk>",
    "shapes[]<cuboid>",
    "shapes[]<instances>",
];
/// Lights whose `spectrum` and `scale` (or photometric strength) `build_lights` reads.
const SPECTRAL_LIGHTS: &[&str] = &[
    "lights[]<point>",
    "lights[]<spot>",
    "lights[]<directional>",
    "lights[]<area>",
    "lights[]<sky>",
    "lights[]<luminaire>",
];
const DAYLIGHT: &[&str] = &[
    "lights[]<cie_sky>",
    "lights[]<perez_sky>",
    "lights[]<preetham_sky>",
];
/// The material types `build_one` reads; the library's are in `material::library::FIELD_USES`.
const MATERIALS: &[&str] = &[
    "materials.*<lambert>",
    "materials.*<conductor>",
    "materials.*<dielectric>",
    "materials.*<two_sided>",
    "materials.*<normal_map>",
    "materials.*<bump_map>",
    "materials.*<mask>",
    "materials.*<thin_dielectric>",
    "materials.*<mix>",
    "materials.*<fluorescent>",
];
const SENSORS: &[&str] = &["sensors[]<point>", "sensors[]<points>", "sensors[]<grid>"];
const TEXTURES: &[&str] = &[
    "@texture<image>",
    "@texture<checkerboard>",
    "@texture<noise>",
];

const BUILD_CAMERA: &str = "scene_build::camera::build_camera";
const BUILD_FILTER: &str = "scene_build::filter::build_filter";
const INTEGRATOR: &str = "Integrator::from_description";
const BUILD_GEOMETRY: &str = "scene_build::geometry::place_shapes";
const BUILD_LIGHTS: &str = "light::build::build_lights";
const BUILD_DAYLIGHT: &str = "light::daylight::build_daylight";
const BUILD_TILES: &str =
    "scene_build::tiles (TileMeshes::mesh, rectangle_carrier) via scene_build::geometry::place_shapes";
const BUILD_MATERIAL: &str = "material::build_materials (build_one)";
const SENSOR: &str = "sensor::measure_sensors (`prism render`)";
const LOAD_TEXTURE: &str = "texture::build_textures, texture::load";
const BUILD_FLUORESCENT: &str = "material::fluorescent::FluorescentSurface::build (the \
     matrix and R that prism-scene reradiation::parse_reradiation loaded)";
const TRANSFORM: &str = "prism-scene transform::parse_transform composes the matrix that \
                         scene_build::transform::to_geometry_transform reads";
const BUILD_MEDIA: &str = "scene_build::media::build_media";
const CAMERAS_AND_LIGHTS_MEDIUM: &str = "prism-scene scene::parse_root (SceneDescription::\
                                         camera_medium, light_media), read by \
                                         scene_build::media::build_media";

/// Every row: [`FIELD_USES`] and the material library's; together they name every key
/// path of `prism_scene::schema::rows()`, each in exactly one row.
pub fn field_uses() -> impl Iterator<Item = &'static FieldRow> {
    FIELD_USES
        .iter()
        .chain(crate::material::library::FIELD_USES)
}

pub const FIELD_USES: &[FieldRow] = &[
    // The top level.
    read(&[""], &["camera"], BUILD_CAMERA),
    read(&[""], &["film"], "RenderScene::build"),
    read(&[""], &["integrator"], INTEGRATOR),
    read(
        &[""],
        &["spectra"],
        "prism-scene spectrum_ref::parse_spectrum: references to a named spectrum are \
         replaced by it while parsing",
    ),
    read(&[""], &["materials"], BUILD_MATERIAL),
    read(&[""], &["meshes"], BUILD_GEOMETRY),
    read(&[""], &["shapes"], BUILD_GEOMETRY),
    read(&[""], &["lights"], BUILD_LIGHTS),
    read(&[""], &["media", "world_medium"], BUILD_MEDIA),
    read(&[""], &["sensors"], SENSOR),
    read(&[""], &["textures"], LOAD_TEXTURE),
    read(&[""], &["reradiation"], BUILD_FLUORESCENT),
    read(&[""], &["tiles"], BUILD_TILES),
    read(
        &["tiles.*"],
        &["mesh", "period_m", "materials"],
        BUILD_TILES,
    ),
    read(
        &["reradiation.*<bfc>"],
        &["bfc", "negatives"],
        BUILD_FLUORESCENT,
    ),
    read(
        &["reradiation.*<dye>"],
        &[
            "absorption",
            "emission",
            "quantum_yield",
            "peak_absorptance",
        ],
        BUILD_FLUORESCENT,
    ),
    FieldRow {
        patterns: &[""],
        keys: &["$schema"],
        use_: FieldUse::Annotation("the JSON Schema that editors check the file against"),
    },
    // camera
    read(CAMERAS, &["type", "transform"], BUILD_CAMERA),
    read(CAMERAS, &["medium"], CAMERAS_AND_LIGHTS_MEDIUM),
    read(&["camera<pinhole>"], &["fov_deg", "fov_axis"], BUILD_CAMERA),
    read(
        &["camera<thin_lens>"],
        &[
            "fov_deg",
            "focal_length_mm",
            "sensor_width_mm",
            "f_number",
            "aperture_radius_m",
            "focus_distance_m",
        ],
        "scene_build::camera::build_camera (fov_deg gives the focal length when \
         focal_length_mm is absent)",
    ),
    read(
        &["camera<fisheye>"],
        &["projection", "fov_deg", "fit"],
        BUILD_CAMERA,
    ),
    read(&["camera<orthographic>"], &["width_m"], BUILD_CAMERA),
    // film
    read(
        &["film"],
        &["resolution", "spp", "seed", "reconstruction"],
        "RenderScene::build",
    ),
    read(&["film"], &["filter"], BUILD_FILTER),
    read(
        &["film"],
        &["output"],
        "`prism render`: crates/cli/render.rs output_path",
    ),
    read(
        &["film"],
        &["aovs"],
        "Film (AovSelection::SURFACE): EXR outputs always hold depth, normal and albedo; \
         `position` is refused by scene_build::fields::refuse_unrendered",
    ),
    read(FILTERS, &["type", "radius_px"], BUILD_FILTER),
    read(&["film.filter<gaussian>"], &["sigma_px"], BUILD_FILTER),
    read(&["film.filter<mitchell>"], &["b", "c"], BUILD_FILTER),
    // integrator
    read(INTEGRATORS, &["type"], INTEGRATOR),
    read(
        &["integrator<ambient_occlusion>"],
        &["max_distance_m", "samples"],
        INTEGRATOR,
    ),
    read(TRANSPORT, &["max_depth", "rr_depth"], INTEGRATOR),
    read(
        &["integrator<path>", "integrator<bdpt>"],
        &["mis"],
        INTEGRATOR,
    ),
    read(
        &["integrator<path>"],
        &["fluorescence_lanes"],
        "Integrator::from_description (PathTracer::fluorescence_lanes)",
    ),
    read(
        TRANSPORT,
        &["sampler"],
        "`prism render`: crates/cli/render.rs run (RenderSettings::sampler)",
    ),
    read(
        &["integrator<radiosity>"],
        &["error_bound_rel", "iterations"],
        "Integrator::from_description (RadiosityMethod)",
    ),
    read(
        &["integrator<radiosity>"],
        &["sampler"],
        "`prism render`: crates/cli/render.rs run (RenderSettings::sampler)",
    ),
    read(
        &["integrator<radiosity>"],
        &["gather_epsilon"],
        "Integrator::from_description (RadiosityMethod::gather_epsilon)",
    ),
    read(
        &["integrator<path>"],
        &["spectral_mis"],
        "Integrator::from_description (PathTracer::spectral_mis)",
    ),
    read(
        PHOTON,
        &["photons_per_pass"],
        "Integrator::from_description (PhotonMapper::photons_per_pass)",
    ),
    read(
        &["integrator<photon>"],
        &["radius_m", "nearest_photons"],
        "Integrator::from_description (PhotonMapper::radius)",
    ),
    read(
        &["integrator<photon_progressive>"],
        &["initial_radius_m", "alpha"],
        "Integrator::from_description (PhotonMapper::radius, RadiusRule::Progressive)",
    ),
    // media
    read(
        &["media.*<homogeneous>", "media.*<grid>"],
        &[
            "type",
            "sigma_a_per_m",
            "sigma_s_per_m",
            "emission",
            "phase",
            "g",
            "fluorescence",
        ],
        BUILD_MEDIA,
    ),
    read(
        &["media.*.fluorescence"],
        &["absorption_per_m", "emission", "quantum_yield"],
        "prism-scene medium::parse_fluorescence, then scene_build::media::build_media \
         (integrator::medium_transport re-emits what it absorbs)",
    ),
    read(&["media.*<grid>"], &["density", "bounds_m"], BUILD_MEDIA),
    read(
        &[
            "@phase<isotropic>",
            "@phase<rayleigh>",
            "@phase<hg>",
            "@phase<tabulated>",
        ],
        &["type"],
        BUILD_MEDIA,
    ),
    read(&["@phase<hg>"], &["g"], BUILD_MEDIA),
    read(
        &["@phase<tabulated>"],
        &["file"],
        "prism-scene medium::read_phase_table, then scene_build::media::build_media",
    ),
    // meshes and shapes
    read(&["meshes.*"], &["file"], BUILD_GEOMETRY),
    read(SHAPES, &["type", "transform", "material"], BUILD_GEOMETRY),
    read(
        SHAPES,
        &["name"],
        "prism-scene light::parse_light (an area light names its shape) and \
         scene_build::geometry (error places)",
    ),
    read(SHAPES, &["interior_medium", "exterior_medium"], BUILD_MEDIA),
    read(&["shapes[]<mesh>"], &["file", "mesh"], BUILD_GEOMETRY),
    read(
        &["shapes[]<sphere>", "shapes[]<disk>"],
        &["radius_m"],
        BUILD_GEOMETRY,
    ),
    read(
        &["shapes[]<rectangle>", "shapes[]<cuboid>"],
        &["size_m"],
        BUILD_GEOMETRY,
    ),
    read(
        &["shapes[]<instances>"],
        &["mesh", "instances"],
        BUILD_GEOMETRY,
    ),
    // lights
    read(
        SPECTRAL_LIGHTS,
        &["type", "spectrum", "scale"],
        BUILD_LIGHTS,
    ),
    read(
        &[
            "lights[]<point>",
            "lights[]<spot>",
            "lights[]<directional>",
            "lights[]<area>",
            "lights[]<sky>",
            "lights[]<luminaire>",
            "lights[]<environment>",
            "lights[]<cie_sky>",
            "lights[]<perez_sky>",
            "lights[]<preetham_sky>",
        ],
        &["medium"],
        CAMERAS_AND_LIGHTS_MEDIUM,
    ),
    read(
        &["lights[]<point>"],
        &["position_m", "power_lm", "intensity_cd"],
        BUILD_LIGHTS,
    ),
    read(
        &["lights[]<spot>"],
        &[
            "position_m",
            "direction",
            "cone_angle_deg",
            "falloff_start_deg",
            "power_lm",
            "intensity_cd",
        ],
        BUILD_LIGHTS,
    ),
    read(
        &["lights[]<spot>"],
        &["target_m"],
        "prism-scene light::parse_light turns it into the `direction` build_lights reads",
    ),
    read(
        &["lights[]<directional>"],
        &["direction", "angular_diameter_deg", "illuminance_lx"],
        BUILD_LIGHTS,
    ),
    read(
        &["lights[]<area>"],
        &["shape", "two_sided", "power_lm", "luminance_cd_m2"],
        BUILD_LIGHTS,
    ),
    read(
        &["lights[]<environment>"],
        &["type", "file", "transform", "scale", "filter"],
        "light::build::build_lights → EnvironmentLight::load",
    ),
    read(&["lights[]<sky>"], &["luminance_cd_m2"], BUILD_LIGHTS),
    read(
        &["lights[]<luminaire>"],
        &["file", "position_m", "aim", "c0_direction", "power_lm"],
        "light::goniometric_build::build",
    ),
    read(
        DAYLIGHT,
        &[
            "type",
            "sun",
            "sky_cct_k",
            "sun_cct_k",
            "ground_albedo",
            "north_deg",
        ],
        BUILD_DAYLIGHT,
    ),
    refused(
        DAYLIGHT,
        &["spectrum", "scale"],
        "prism-scene daylight::parse_daylight: the sky model sets a daylight sky's spectrum \
         and level",
    ),
    read(
        &["lights[]<cie_sky>"],
        &[
            "sky_type",
            "zenith_luminance_cd_m2",
            "diffuse_horizontal_illuminance_lx",
            "sun_normal_illuminance_lx",
        ],
        BUILD_DAYLIGHT,
    ),
    read(
        &["lights[]<perez_sky>"],
        &[
            "diffuse_horizontal_irradiance_w_m2",
            "direct_normal_irradiance_w_m2",
            "dew_point_c",
            "diffuse_horizontal_illuminance_lx",
            "direct_normal_illuminance_lx",
        ],
        BUILD_DAYLIGHT,
    ),
    read(
        &["lights[]<preetham_sky>"],
        &[
            "turbidity",
            "diffuse_horizontal_illuminance_lx",
            "sun_normal_illuminance_lx",
        ],
        BUILD_DAYLIGHT,
    ),
    read(
        &["@sun"],
        &[
            "elevation_deg",
            "azimuth_deg",
            "date_time",
            "latitude_deg",
            "longitude_deg",
        ],
        "light::daylight::build_daylight (sun_position::solar_angles for a date_time)",
    ),
    // materials
    read(MATERIALS, &["type"], BUILD_MATERIAL),
    read(&["materials.*<lambert>"], &["reflectance"], BUILD_MATERIAL),
    read(
        &["materials.*<fluorescent>"],
        &["reradiation", "reflectance"],
        BUILD_FLUORESCENT,
    ),
    read(
        &["materials.*<conductor>"],
        &["metal", "eta", "k", "roughness", "distribution"],
        BUILD_MATERIAL,
    ),
    read(
        &["materials.*<dielectric>"],
        &["ior", "roughness", "distribution"],
        BUILD_MATERIAL,
    ),
    read(
        &[
            "materials.*<two_sided>",
            "materials.*<normal_map>",
            "materials.*<bump_map>",
            "materials.*<mask>",
        ],
        &["material"],
        BUILD_MATERIAL,
    ),
    read(
        &["materials.*<normal_map>", "materials.*<bump_map>"],
        &["texture"],
        BUILD_MATERIAL,
    ),
    read(&["materials.*<bump_map>"], &["scale_m"], BUILD_MATERIAL),
    read(&["materials.*<mask>"], &["opacity"], BUILD_MATERIAL),
    read(&["materials.*<thin_dielectric>"], &["ior"], BUILD_MATERIAL),
    read(
        &["materials.*<interface>"],
        &["type"],
        "material::build_materials (a mask of opacity 0) and scene_build::media::build_media \
         (MediaScene::interface_material)",
    ),
    read(
        &["materials.*<mix>"],
        &["materials", "weight"],
        BUILD_MATERIAL,
    ),
    read(&["materials.*<tiled>"], &["type", "tile"], BUILD_TILES),
    read(
        &["materials.*<tiled>"],
        &["self_shadowing", "interreflection"],
        "scene_build::tiles tiled_surfaces (PyramidOptions), `prism tile-brdf`",
    ),
    FieldRow {
        patterns: &["materials.*<tiled>"],
        keys: &["levels"],
        use_: FieldUse::Annotation(
            "the height of the tile's BRDF/BTDF pyramid: read by `prism tile-brdf` (its \
             default --levels); a render does not use it: `radiosity` holds tiled surfaces by \
             the pyramid's top level only, and `path` traces the tile's geometry exactly at \
             every scale",
        ),
    },
    read(
        &["@ior"],
        &["sellmeier", "cauchy"],
        "material::ior::Ior::from_scene",
    ),
    read(
        &["@ior.sellmeier"],
        &["b", "c_um2"],
        "material::ior::Ior::from_scene",
    ),
    read(
        &["@ior.cauchy"],
        &["a", "b_um2"],
        "material::ior::Ior::from_scene",
    ),
    // sensors
    read(SENSORS, &["type", "name"], SENSOR),
    read(
        SENSORS,
        &[
            "samples",
            "relative_error",
            "absolute_error_lx",
            "min_samples",
            "max_samples",
        ],
        SENSOR,
    ),
    read(&["sensors[]<point>"], &["position_m", "normal"], SENSOR),
    read(
        &["sensors[]<points>"],
        &["positions_m", "normal", "normals"],
        SENSOR,
    ),
    read(
        &["sensors[]<grid>"],
        &["origin_m", "u_m", "v_m", "resolution", "normal"],
        SENSOR,
    ),
    // spectra
    read(
        &["@spectrum"],
        &["blackbody_k", "rgb", "file"],
        "scene_build::spectrum::build_spectrum",
    ),
    read(
        &["@spectrum"],
        &["column"],
        "prism-scene spectrum_ref::load_file (the column it loads)",
    ),
    // textures
    read(
        TEXTURES,
        &["type", "uv_scale", "uv_offset", "uv_rotate_deg"],
        LOAD_TEXTURE,
    ),
    read(
        &["@texture<image>"],
        &["file", "encoding", "filter", "wrap", "scale", "channel"],
        LOAD_TEXTURE,
    ),
    read(&["@texture<checkerboard>"], &["a", "b"], LOAD_TEXTURE),
    read(
        &["@texture<noise>"],
        &[
            "noise",
            "space",
            "frequency",
            "octaves",
            "gain",
            "lacunarity",
            "a",
            "b",
        ],
        LOAD_TEXTURE,
    ),
    read(&["@texture_ref"], &["texture"], "texture::TextureSet::get"),
    // transforms
    read(
        &["@transform"],
        &["translate", "rotate", "scale", "matrix", "look_at"],
        TRANSFORM,
    ),
    read(&["@transform.rotate"], &["axis", "angle_deg"], TRANSFORM),
    read(&["@transform.look_at"], &["eye", "target", "up"], TRANSFORM),
];

/// Refuses what the scene reader accepts but render does not do yet, with the file and the
/// JSON path: the `position` AOV (`film.aovs[i]`).
pub fn refuse_unrendered(scene: &SceneDescription) -> Result<(), SceneBuildError> {
    let refuse = |path: JsonPath, message: &str| {
        Err(SceneBuildError::new(&scene.file, path.to_string(), message))
    };
    for (i, aov) in scene.film.aovs.iter().enumerate() {
        match aov {
            Aov::Depth | Aov::Normal | Aov::Albedo => {}
            Aov::Position => {
                return refuse(
                    JsonPath::default().key("film").key("aovs").index(i),
                    "the `position` AOV is not written yet (EXR outputs hold depth, normal \
                     and albedo)",
                )
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_scene::schema::rows;

    /// The walk over the scene reader's schema: every key path it accepts is in exactly
    /// one row of `field_uses()`, and every row names only accepted key paths.
    #[test]
    fn every_key_the_scene_reader_accepts_is_read_or_refused() {
        let (mut missing, mut twice, mut stale) = (Vec::new(), Vec::new(), Vec::new());
        for object in rows() {
            for key in object.keys() {
                let rows = field_uses()
                    .filter(|r| r.patterns.contains(&object.pattern) && r.keys.contains(&key))
                    .count();
                match rows {
                    0 => missing.push(object.key_path(key)),
                    1 => {}
                    _ => twice.push(object.key_path(key)),
                }
            }
        }
        for row in field_uses() {
            for pattern in row.patterns {
                for key in row.keys {
                    let accepted = rows().any(|o| o.pattern == *pattern && o.accepts(key));
                    if !accepted {
                        stale.push(format!("{pattern}.{key}"));
                    }
                }
            }
        }
        assert!(
            missing.is_empty(),
            "the scene reader accepts {missing:?}, which render neither reads nor refuses: \
             add each to scene_build::fields::FIELD_USES (material::library::FIELD_USES for a \
             library material) with the code that reads it, or refuse it in refuse_unrendered"
        );
        assert!(twice.is_empty(), "in two rows of field_uses(): {twice:?}");
        assert!(
            stale.is_empty(),
            "field_uses() names key paths the scene reader does not accept: {stale:?}"
        );
    }
}

//! Every kind of JSON object the reader accepts, where it appears and the keys it takes:
//! the one list of accepted keys, [`rows`]. Parsers check an object with
//! `V::object(schema!("…"))`, which takes one of its rows (found at compile time: an
//! unknown pattern does not build) and nothing else, so a key added to the format is a key
//! added to a row. The rows are [`SCHEMA`] here and the material library's
//! (`material::LIBRARY_SCHEMA`), kept next to the parser of the library kinds so that a new
//! library BSDF is one place in this crate (as render keeps the library's `FIELD_USES` rows
//! next to their builder).
//!
//! Render keeps the other half (prism-render `scene_build::fields`): what reads each key,
//! or the error that refuses it; its test walks [`rows`] and fails on any key path that
//! is neither, so a new key cannot be parsed and then silently dropped.

/// One kind of JSON object.
#[derive(Debug)]
pub struct ObjectSchema {
    /// Where it appears: a JSON path with `[]` for any array index, `*` for any name of a
    /// named section and `<type>` for the `type` it was given (`shapes[]<sphere>`);
    /// `@name` for objects written in many places (`@spectrum`, `@transform`); empty for
    /// the top level.
    pub pattern: &'static str,
    /// The accepted keys in groups (some shared between kinds), in the order error
    /// messages list them. Private: rows are made only in this table.
    key_groups: &'static [&'static [&'static str]],
}

impl ObjectSchema {
    /// The accepted keys, in order.
    pub fn keys(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.key_groups.iter().flat_map(|g| g.iter().copied())
    }

    pub fn accepts(&self, key: &str) -> bool {
        self.keys().any(|k| k == key)
    }

    /// The key path of `key` in this object: `shapes[]<sphere>.radius_m`, or `camera` at
    /// the top level.
    pub fn key_path(&self, key: &str) -> String {
        if self.pattern.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.pattern)
        }
    }
}

/// Every row: [`SCHEMA`] and the material library's.
pub fn rows() -> impl Iterator<Item = &'static ObjectSchema> {
    SCHEMA.iter().chain(crate::material::LIBRARY_SCHEMA)
}

/// Every key path the reader accepts (`ObjectSchema::key_path` of every key of every row).
pub fn key_paths() -> Vec<String> {
    rows()
        .flat_map(|row| row.keys().map(|k| row.key_path(k)))
        .collect()
}

/// A row; rows are made only in [`SCHEMA`] and `material::LIBRARY_SCHEMA`.
pub(crate) const fn row(
    pattern: &'static str,
    key_groups: &'static [&'static [&'static str]],
) -> ObjectSchema {
    ObjectSchema {
        pattern,
        key_groups,
    }
}

const SHAPE: &[&str] = &[
    "type",
    "name",
    "transform",
    "material",
    "interior_medium",
    "exterior_medium",
];
const LIGHT: &[&str] = &["type", "spectrum", "scale", "medium"];
/// `spectrum` and `scale` are accepted only to be refused with the reason (the sky model
/// sets both; `daylight::parse_daylight`).
const DAYLIGHT: &[&str] = &[
    "type",
    "sun",
    "sky_cct_k",
    "sun_cct_k",
    "ground_albedo",
    "north_deg",
    "spectrum",
    "scale",
    "medium",
];
const SENSOR: &[&str] = &["type", "name"];
const SENSOR_SAMPLING: &[&str] = &[
    "samples",
    "relative_error",
    "absolute_error_lx",
    "min_samples",
    "max_samples",
];
const TYPE: &[&str] = &["type"];
/// Keys of every medium type; `g` is the old spelling of `{"type": "hg", "g": …}`.
const MEDIUM: &[&str] = &[
    "type",
    "sigma_a_per_m",
    "sigma_s_per_m",
    "emission",
    "phase",
    "g",
    "fluorescence",
];
const TEXTURE_UV: &[&str] = &["uv_scale", "uv_offset", "uv_rotate_deg"];

/// The accepted objects but the material library's (all of them: [`rows`]). Keys of a row
/// that a parser refuses with a specific message are still listed (render's table names the
/// parser as what refuses them).
pub const SCHEMA: &[ObjectSchema] = &[
    row("", &[&crate::scene::TOP_LEVEL_FIELDS]),
    // camera.rs
    row(
        "camera<pinhole>",
        &[&["type", "transform", "medium", "fov_deg", "fov_axis"]],
    ),
    row(
        "camera<thin_lens>",
        &[&[
            "type",
            "transform",
            "medium",
            "fov_deg",
            "focal_length_mm",
            "sensor_width_mm",
            "f_number",
            "aperture_radius_m",
            "focus_distance_m",
        ]],
    ),
    row(
        "camera<fisheye>",
        &[&[
            "type",
            "transform",
            "medium",
            "projection",
            "fov_deg",
            "fit",
        ]],
    ),
    row(
        "camera<orthographic>",
        &[&["type", "transform", "medium", "width_m"]],
    ),
    row("camera<spherical>", &[&["type", "transform", "medium"]]),
    // film.rs
    row(
        "film",
        &[&[
            "resolution",
            "filter",
            "spp",
            "seed",
            "output",
            "aovs",
            "reconstruction",
        ]],
    ),
    row("film.filter<box>", &[&["type", "radius_px"]]),
    row(
        "film.filter<gaussian>",
        &[&["type", "radius_px", "sigma_px"]],
    ),
    row("film.filter<blackman_harris>", &[&["type", "radius_px"]]),
    row("film.filter<mitchell>", &[&["type", "radius_px", "b", "c"]]),
    // integrator.rs
    row("integrator<depth>", &[TYPE]),
    row("integrator<normal>", &[TYPE]),
    row("integrator<albedo>", &[TYPE]),
    row(
        "integrator<ambient_occlusion>",
        &[&["type", "max_distance_m", "samples"]],
    ),
    row(
        "integrator<path>",
        &[&[
            "type",
            "max_depth",
            "sampler",
            "mis",
            "rr_depth",
            "fluorescence_lanes",
            "spectral_mis",
        ]],
    ),
    // `mis` is refused before the keys are checked: light tracing has one strategy.
    row(
        "integrator<light>",
        &[&["type", "max_depth", "sampler", "rr_depth"]],
    ),
    row(
        "integrator<bdpt>",
        &[&["type", "max_depth", "sampler", "mis", "rr_depth"]],
    ),
    row(
        "integrator<photon>",
        &[&[
            "type",
            "max_depth",
            "sampler",
            "rr_depth",
            "photons_per_pass",
            "radius_m",
            "nearest_photons",
        ]],
    ),
    row(
        "integrator<radiosity>",
        &[&[
            "type",
            "error_bound_rel",
            "iterations",
            "gather_epsilon",
            "sampler",
        ]],
    ),
    row(
        "integrator<photon_progressive>",
        &[&[
            "type",
            "max_depth",
            "sampler",
            "rr_depth",
            "photons_per_pass",
            "initial_radius_m",
            "alpha",
        ]],
    ),
    // reradiation.rs: the entries have no `type`; `<bfc>` and `<dye>` name the two forms,
    // told apart by the `bfc` and `absorption`/`emission` keys.
    row("reradiation.*<bfc>", &[&["bfc", "negatives"]]),
    row(
        "reradiation.*<dye>",
        &[&[
            "absorption",
            "emission",
            "quantum_yield",
            "peak_absorptance",
        ]],
    ),
    // material.rs (the kinds outside the library: `material::LIBRARY_SCHEMA` has those)
    row(
        "materials.*<fluorescent>",
        &[&["type", "reradiation", "reflectance"]],
    ),
    // medium.rs
    row("media.*<homogeneous>", &[MEDIUM]),
    row("media.*<grid>", &[MEDIUM, &["density", "bounds_m"]]),
    row(
        "media.*.fluorescence",
        &[&["absorption_per_m", "emission", "quantum_yield"]],
    ),
    row("@phase<isotropic>", &[TYPE]),
    row("@phase<rayleigh>", &[TYPE]),
    row("@phase<hg>", &[&["type", "g"]]),
    row("@phase<tabulated>", &[&["type", "file"]]),
    // shape.rs
    row("meshes.*", &[&["file"]]),
    row("shapes[]<mesh>", &[SHAPE, &["file", "mesh"]]),
    row("shapes[]<sphere>", &[SHAPE, &["radius_m"]]),
    row("shapes[]<rectangle>", &[SHAPE, &["size_m"]]),
    row("shapes[]<disk>", &[SHAPE, &["radius_m"]]),
    row("shapes[]<cuboid>", &[SHAPE, &["size_m"]]),
    row("shapes[]<instances>", &[SHAPE, &["mesh", "instances"]]),
    // light.rs
    row(
        "lights[]<point>",
        &[LIGHT, &["position_m", "power_lm", "intensity_cd"]],
    ),
    row(
        "lights[]<spot>",
        &[
            LIGHT,
            &[
                "position_m",
                "direction",
                "target_m",
                "cone_angle_deg",
                "falloff_start_deg",
                "power_lm",
                "intensity_cd",
            ],
        ],
    ),
    row(
        "lights[]<directional>",
        &[
            LIGHT,
            &["direction", "angular_diameter_deg", "illuminance_lx"],
        ],
    ),
    row(
        "lights[]<area>",
        &[
            LIGHT,
            &["shape", "two_sided", "power_lm", "luminance_cd_m2"],
        ],
    ),
    row(
        "lights[]<environment>",
        &[&["type", "file", "transform", "scale", "medium", "filter"]],
    ),
    row("lights[]<sky>", &[LIGHT, &["luminance_cd_m2"]]),
    row(
        "lights[]<luminaire>",
        &[
            LIGHT,
            &["file", "position_m", "aim", "c0_direction", "power_lm"],
        ],
    ),
    // daylight.rs
    row(
        "lights[]<cie_sky>",
        &[
            DAYLIGHT,
            &[
                "sky_type",
                "zenith_luminance_cd_m2",
                "diffuse_horizontal_illuminance_lx",
                "sun_normal_illuminance_lx",
            ],
        ],
    ),
    row(
        "lights[]<perez_sky>",
        &[
            DAYLIGHT,
            &[
                "diffuse_horizontal_irradiance_w_m2",
                "direct_normal_irradiance_w_m2",
                "dew_point_c",
                "diffuse_horizontal_illuminance_lx",
                "direct_normal_illuminance_lx",
            ],
        ],
    ),
    row(
        "lights[]<preetham_sky>",
        &[
            DAYLIGHT,
            &[
                "turbidity",
                "diffuse_horizontal_illuminance_lx",
                "sun_normal_illuminance_lx",
            ],
        ],
    ),
    row(
        "@sun",
        &[&[
            "elevation_deg",
            "azimuth_deg",
            "date_time",
            "latitude_deg",
            "longitude_deg",
        ]],
    ),
    // material.rs (the library's rows: material::LIBRARY_SCHEMA)
    row("materials.*<lambert>", &[&["type", "reflectance"]]),
    row(
        "materials.*<conductor>",
        &[&["type", "metal", "eta", "k", "roughness", "distribution"]],
    ),
    row(
        "materials.*<dielectric>",
        &[&["type", "ior", "roughness", "distribution"]],
    ),
    row("materials.*<two_sided>", &[&["type", "material"]]),
    row(
        "materials.*<normal_map>",
        &[&["type", "material", "texture"]],
    ),
    row(
        "materials.*<bump_map>",
        &[&["type", "material", "texture", "scale_m"]],
    ),
    row("materials.*<mask>", &[&["type", "material", "opacity"]]),
    row("materials.*<thin_dielectric>", &[&["type", "ior"]]),
    row("materials.*<mix>", &[&["type", "materials", "weight"]]),
    row("materials.*<interface>", &[TYPE]),
    row(
        "materials.*<tiled>",
        &[&[
            "type",
            "tile",
            "levels",
            "self_shadowing",
            "interreflection",
        ]],
    ),
    // tile.rs
    row("tiles.*", &[&["mesh", "period_m", "materials"]]),
    row("@ior", &[&["sellmeier", "cauchy"]]),
    row("@ior.sellmeier", &[&["b", "c_um2"]]),
    row("@ior.cauchy", &[&["a", "b_um2"]]),
    // sensor.rs
    row(
        "sensors[]<point>",
        &[SENSOR, &["position_m", "normal"], SENSOR_SAMPLING],
    ),
    row(
        "sensors[]<points>",
        &[
            SENSOR,
            &["positions_m", "normal", "normals"],
            SENSOR_SAMPLING,
        ],
    ),
    row(
        "sensors[]<grid>",
        &[
            SENSOR,
            &["origin_m", "u_m", "v_m", "resolution", "normal"],
            SENSOR_SAMPLING,
        ],
    ),
    // spectrum_ref.rs
    row("@spectrum", &[&["blackbody_k", "rgb", "file", "column"]]),
    // texture.rs: the `textures` section and inline definitions alike.
    row(
        "@texture<image>",
        &[
            TYPE,
            &["file", "encoding", "filter", "wrap", "scale", "channel"],
            TEXTURE_UV,
        ],
    ),
    row("@texture<checkerboard>", &[TYPE, &["a", "b"], TEXTURE_UV]),
    row(
        "@texture<noise>",
        &[
            TYPE,
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
            TEXTURE_UV,
        ],
    ),
    row("@texture_ref", &[&["texture"]]),
    // transform.rs
    row("@transform", &[&crate::transform::STEPS]),
    row("@transform.rotate", &[&["axis", "angle_deg"]]),
    row("@transform.look_at", &[&["eye", "target", "up"]]),
];

const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The row of `pattern`; evaluated at compile time by `schema!`, where a pattern that is
/// in none of [`rows`]' tables stops the build.
pub(crate) const fn find(pattern: &str) -> &'static ObjectSchema {
    let tables: [&'static [ObjectSchema]; 2] = [SCHEMA, crate::material::LIBRARY_SCHEMA];
    let mut t = 0;
    while t < tables.len() {
        let rows = tables[t];
        let mut i = 0;
        while i < rows.len() {
            if same(rows[i].pattern, pattern) {
                return &rows[i];
            }
            i += 1;
        }
        t += 1;
    }
    panic!("no row of prism_scene::schema::rows() has this pattern")
}

/// `schema!("shapes[]<sphere>")`: the row of that pattern, checked at compile time.
macro_rules! schema {
    ($pattern:literal) => {
        const { $crate::schema::find($pattern) }
    };
}
pub(crate) use schema;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_are_unique_and_rows_list_each_key_once() {
        let all: Vec<&ObjectSchema> = rows().collect();
        for (i, r) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|s| s.pattern != r.pattern),
                "pattern `{}` twice",
                r.pattern
            );
            let keys: Vec<&str> = r.keys().collect();
            for (k, key) in keys.iter().enumerate() {
                assert!(
                    !keys[..k].contains(key),
                    "`{}` twice in `{}`",
                    key,
                    r.pattern
                );
            }
        }
        assert_eq!(find("@transform.rotate").pattern, "@transform.rotate");
        assert_eq!(find("materials.*<ward>").pattern, "materials.*<ward>");
    }
}

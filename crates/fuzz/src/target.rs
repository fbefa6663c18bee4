//! The fuzz targets: every parser and decoder a user can feed, each reading one input file
//! (the mutated bytes written under a name the error must repeat).

use std::path::{Path, PathBuf};

/// One parser or decoder under test.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The positioned JSON reader and the scene schema (`load_scene`).
    SceneJson,
    /// `load_scene` and then the scene builder (`RenderScene::build`: meshes, spectra,
    /// textures, lights, media).
    SceneBuild,
    /// Spectral CSV (`read_spectral_file`).
    SpectrumCsv,
    /// Labsphere BFC-450 bispectral data.
    Bfc,
    /// IES LM-63 photometric file.
    Ies,
    /// EULUMDAT photometric file.
    Ldt,
    Obj,
    Ply,
    /// MERL binary BRDF table.
    Merl,
    /// Mitsuba `.vol` grid.
    Vol,
    /// RGB OpenEXR.
    Exr,
    /// Spectral OpenEXR (Fichet et al. 2021 channel names).
    SpectralExr,
    /// Radiance RGBE `.hdr`.
    Rgbe,
    /// PNG (the texture path).
    Png,
    /// The command line's option values (`--resolution`, `--spp`, `--samples A..B`,
    /// durations, `--max-memory`, `--threads`, ranges, exposures, …): the input is one
    /// value, given to every parser.
    CliValues,
}

impl Target {
    pub const ALL: [Target; 15] = [
        Target::SceneJson,
        Target::SceneBuild,
        Target::SpectrumCsv,
        Target::Bfc,
        Target::Ies,
        Target::Ldt,
        Target::Obj,
        Target::Ply,
        Target::Merl,
        Target::Vol,
        Target::Exr,
        Target::SpectralExr,
        Target::Rgbe,
        Target::Png,
        Target::CliValues,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::SceneJson => "scene-json",
            Target::SceneBuild => "scene-build",
            Target::SpectrumCsv => "spectrum-csv",
            Target::Bfc => "bfc",
            Target::Ies => "ies",
            Target::Ldt => "ldt",
            Target::Obj => "obj",
            Target::Ply => "ply",
            Target::Merl => "merl",
            Target::Vol => "vol",
            Target::Exr => "exr",
            Target::SpectralExr => "spectral-exr",
            Target::Rgbe => "rgbe",
            Target::Png => "png",
            Target::CliValues => "cli-values",
        }
    }

    /// The input file's extension (parsers dispatch on it).
    pub fn extension(self) -> &'static str {
        match self {
            Target::SceneJson | Target::SceneBuild => "json",
            Target::SpectrumCsv => "csv",
            Target::Bfc => "bfc",
            Target::Ies => "ies",
            Target::Ldt => "ldt",
            Target::Obj => "obj",
            Target::Ply => "ply",
            Target::Merl => "binary",
            Target::Vol => "vol",
            Target::Exr | Target::SpectralExr => "exr",
            Target::Rgbe => "hdr",
            Target::Png => "png",
            Target::CliValues => "txt",
        }
    }

    /// Seed files of the repository (relative to its root) and built-in seeds.
    pub fn seeds(self, root: &Path) -> Vec<Vec<u8>> {
        let files: &[&str] = match self {
            Target::SceneJson | Target::SceneBuild => &[
                "scenes/minimal.json",
                "scenes/cornell-box.json",
                "scenes/glossy-env.json",
                "scenes/textures.json",
                "scenes/cornell-box-fog.json",
                "scenes/fluorescence.json",
                "scenes/material-gallery.json",
                // Sensors, daylight, media of every kind (a coverage run found the sensor
                // and daylight readers unreached by the seeds above).
                "scenes/daylight-room.json",
                "scenes/office/office.json",
                "scenes/stress/chromatic-smoke.json",
                "scenes/stress/spot-fog-glass.json",
                "scenes/stress/haze-valley.json",
            ],
            Target::SpectrumCsv => &[
                "spectra/D65.csv",
                "scenes/cornell-box/light-radiance.csv",
                "tests/fixtures/irregular_reflectance.csv",
            ],
            Target::Bfc => &[
                "tests/fixtures/bispectral-synthetic.bfc",
                "scenes/fluorescence/paper-oba.bfc",
            ],
            Target::Ies => &["scenes/office/linear.ies", "scenes/office/downlight.ies"],
            Target::Ldt | Target::Ply | Target::Merl => &[],
            Target::Obj => &["scenes/stress/prism.obj"],
            Target::Vol => &["scenes/stress/media/smoke.vol"],
            Target::Exr | Target::SpectralExr => &["tests/fixtures/cornell_mitsuba_reference.exr"],
            Target::Rgbe => &["scenes/envmaps/sky-512x256.hdr"],
            Target::Png => &[
                "scenes/textures/leaf-mask.png",
                "scenes/textures/roughness.png",
            ],
            Target::CliValues => &[],
        };
        let mut seeds: Vec<Vec<u8>> = files
            .iter()
            .filter_map(|f| std::fs::read(root.join(f)).ok())
            .collect();
        seeds.extend(built_in_seeds(self));
        seeds
    }

    /// Parses the file at `path`; `Err` carries the error's text as users see it.
    pub fn parse(self, path: &Path) -> Result<(), String> {
        let text = |e: &dyn std::fmt::Display| e.to_string();
        match self {
            Target::SceneJson => prism_scene::load_scene(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::SceneBuild => {
                let scene = prism_scene::load_scene(path).map_err(|e| text(&e))?;
                prism_render::RenderScene::build(&scene, None)
                    .map(drop)
                    .map_err(|e| text(&e))
            }
            Target::SpectrumCsv => prism_spectrum::spectrum_file::read_spectral_file(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Bfc => {
                prism_spectrum::bfc::load_bfc(path, prism_spectrum::bfc::NegativesPolicy::Clamp)
                    .map(drop)
                    .map_err(|e| text(&e))
            }
            Target::Ies | Target::Ldt => prism_scene::photometric::load_photometric_file(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Obj => prism_geometry::load_obj(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Ply => prism_geometry::load_ply(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Merl => prism_render::bsdf::merl::MerlTable::read(path, true)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Vol => prism_render::medium::vol_file::VolGrid::read(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Exr => prism_image::io::exr::read_exr(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::SpectralExr => prism_image::io::spectral_exr::read_spectral_exr(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Rgbe => prism_image::io::rgbe::read_hdr(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::Png => prism_image::io::png::read_png(path)
                .map(drop)
                .map_err(|e| text(&e)),
            Target::CliValues => cli_values(path),
        }
    }

    /// The file an input is written to inside `dir` (its name must appear in errors).
    /// Scenes go into a copy of the repository's `scenes/` (see [`Target::prepare`]), so
    /// that their meshes, spectra and textures resolve and the builder runs on them.
    pub fn input_path(self, dir: &Path) -> PathBuf {
        let name = format!("fuzz-input-{}.{}", self.name(), self.extension());
        match self {
            Target::SceneJson | Target::SceneBuild => dir.join("scenes").join(name),
            _ => dir.join(name),
        }
    }

    /// Readies `dir` for this target: the scene targets get a copy of `root/scenes`
    /// (without the cached reference renders).
    pub fn prepare(self, root: &Path, dir: &Path) -> std::io::Result<()> {
        match self {
            Target::SceneJson | Target::SceneBuild => {
                copy_tree(&root.join("scenes"), &dir.join("scenes"))
            }
            _ => Ok(()),
        }
    }
}

/// Small hand-written seeds for formats without a file in the repository, and the bad
/// inputs of the hardening issue (empty file, plain text, a UTF-8 BOM).
fn built_in_seeds(target: Target) -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = vec![Vec::new(), b"just some text\n".to_vec()];
    match target {
        Target::SceneJson | Target::SceneBuild => seeds.push(
            b"\xef\xbb\xbf{\"camera\": {\"type\": \"pinhole\", \"fov_deg\": 40}, \"film\": {\"resolution\": [8, 8]}, \"shapes\": [{\"type\": \"sphere\", \"radius_m\": 1}], \"lights\": [{\"type\": \"point\", \"position_m\": [0, 2, 0], \"intensity\": 1}]}".to_vec(),
        ),
        Target::Ldt => seeds.push(ldt_seed().into_bytes()),
        Target::Ply => {
            seeds.push(PLY_ASCII.as_bytes().to_vec());
            let mut binary = PLY_BINARY_HEADER.as_bytes().to_vec();
            for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
                for c in v {
                    binary.extend_from_slice(&c.to_le_bytes());
                }
            }
            binary.push(3);
            for i in 0u32..3 {
                binary.extend_from_slice(&i.to_le_bytes());
            }
            seeds.push(binary);
        }
        Target::Obj => seeds.push(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n".to_vec()),
        Target::Merl => {
            // Header (three i32 dims) and a few values: the size check's inputs.
            let mut merl = Vec::new();
            for d in [90i32, 90, 180] {
                merl.extend_from_slice(&d.to_le_bytes());
            }
            for k in 0..64 {
                merl.extend_from_slice(&(k as f64 * 1e-3).to_le_bytes());
            }
            seeds.push(merl);
        }
        Target::SpectrumCsv => seeds.push(b"wavelength_nm,value\n380,0.1\n780,0.9\n".to_vec()),
        Target::SpectralExr => seeds.extend(spectral_exr_seed()),
        Target::Exr => seeds.extend(small_rgb_exr_seeds()),
        Target::Rgbe => seeds.extend(small_rgbe_seed()),
        Target::CliValues => seeds.extend(CLI_VALUE_SEEDS.iter().map(|v| v.as_bytes().to_vec())),
        Target::Bfc | Target::Ies | Target::Vol | Target::Png => {}
    }
    seeds
}

/// Option values: valid ones of every form and the hardening issue's bad inputs.
const CLI_VALUE_SEEDS: &[&str] = &[
    "64x48",
    "100000x100000",
    "0x4",
    "64",
    "99999999999",
    "4294967296",
    "-1",
    "0",
    "256..512",
    "512..256",
    "0..4,8..16",
    "60s",
    "5m",
    "1h",
    "0s",
    "1.5m",
    "512M",
    "8G",
    "1.5T",
    "1e309",
    "0:500",
    "500:0",
    "auto",
    "-2.5",
    "key=0.18",
    "key=NaN",
    "100000",
    "2 ",
    " 7 ",
];

/// Every option-value parser of the command line on the text in `path`; `Err` naming the
/// file when one refuses it with a message that repeats the value (as a user sees it, so
/// the runner counts it as a named error), and `Err` without the file's name (a failure)
/// when a message does not repeat the value. Text that is not UTF-8 never reaches these
/// parsers (clap refuses it first).
fn cli_values(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let Ok(value) = std::str::from_utf8(&bytes) else {
        return Ok(());
    };
    let ok = |r: Result<(), String>| r;
    let parsers: [(&str, Result<(), String>); 12] = [
        (
            "--resolution",
            ok(prism_args::resolution::parse_resolution(value).map(drop)),
        ),
        ("--spp", ok(prism_args::numbers::parse_spp(value).map(drop))),
        (
            "--seed",
            ok(prism_args::numbers::parse_u64(value).map(drop)),
        ),
        (
            "--spectral-bins",
            ok(prism_args::numbers::parse_u32(value).map(drop)),
        ),
        (
            "--samples",
            ok(prism_args::sample_range::parse_range(value).map(drop)),
        ),
        (
            "ranges_done",
            ok(prism_args::sample_range::parse_ranges(value).map(drop)),
        ),
        (
            "--checkpoint-every",
            ok(prism_args::duration::parse_duration(value).map(drop)),
        ),
        (
            "--false-colour-range",
            ok(prism_args::value_range::parse_range(value).map(drop)),
        ),
        (
            "--exposure",
            ok(prism_args::tone_values::parse_exposure(value).map(drop)),
        ),
        (
            "--param",
            ok(prism_args::tone_values::parse_params(&[value.to_string()]).map(drop)),
        ),
        (
            "--max-memory",
            ok(prism_cpu::memory::parse_size(value).map(drop)),
        ),
        (
            "--threads",
            ok(prism_cpu::threads::parse_thread_count(value).map(drop)),
        ),
    ];
    let mut refused = None;
    for (option, result) in parsers {
        if let Err(message) = result {
            if !message.contains(value.trim()) {
                return Err(format!(
                    "{option} {value:?}: the message does not repeat the value: {message}"
                ));
            }
            refused.get_or_insert(format!("{}: {option} {value}: {message}", path.display()));
        }
    }
    refused.map_or(Ok(()), Err)
}

/// A small image (4×3, values across stops, a zero and a negative) for the decoders' seeds.
fn small_image() -> Option<prism_image::Image> {
    let pixels = (0..12)
        .map(|i| {
            let v = 0.001 * 4f32.powi(i % 7);
            [v, 0.5 * v, if i == 5 { -0.25 } else { 2.0 * v }]
        })
        .collect();
    prism_image::Image::new(
        4,
        3,
        pixels,
        prism_spectrum::rgb_space::RgbColorSpace::srgb(),
    )
    .ok()
}

/// The bytes `write` puts in a temporary file.
fn written(name: &str, write: impl FnOnce(&Path) -> bool) -> Option<Vec<u8>> {
    let dir = std::env::temp_dir().join(format!("prism-fuzz-seed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    let path = dir.join(name);
    let bytes = write(&path).then(|| std::fs::read(&path).ok()).flatten();
    let _ = std::fs::remove_dir_all(&dir);
    bytes
}

/// Small RGB EXRs by Prism's writer, one per compression and sample type: fast inputs whose
/// mutations reach every decompressor (the repository's EXR seed is 0.8 MB).
fn small_rgb_exr_seeds() -> Vec<Vec<u8>> {
    use prism_image::io::exr::{write_exr, ExrCompression, ExrSampleType, ExrWriteOptions};
    let Some(image) = small_image() else {
        return Vec::new();
    };
    let mut seeds = Vec::new();
    for compression in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ] {
        for sample_type in [ExrSampleType::F32, ExrSampleType::F16] {
            let options = ExrWriteOptions {
                sample_type,
                compression,
            };
            seeds.extend(written("seed.exr", |p| {
                write_exr(p, &image, &options).is_ok()
            }));
        }
    }
    seeds
}

/// A small Radiance RGBE file by Prism's writer.
fn small_rgbe_seed() -> Option<Vec<u8>> {
    let image = small_image()?;
    written("seed.hdr", |p| {
        prism_image::io::rgbe::write_hdr(p, &image).is_ok()
    })
}

/// A 4×3 spectral EXR of 8 bands, written by Prism's own writer (uncompressed, so that
/// mutations reach the samples).
fn spectral_exr_seed() -> Option<Vec<u8>> {
    use prism_image::io::exr::{ExrCompression, ExrWriteOptions};
    use prism_image::io::spectral_exr::{write_spectral_exr, SpectralImage};
    let (width, height, bands) = (4, 3, 8);
    let image = SpectralImage {
        width,
        height,
        wavelengths_nm: (0..bands).map(|b| 400.0 + 40.0 * b as f64).collect(),
        samples: (0..width * height * bands)
            .map(|i| 0.01 * i as f32)
            .collect(),
        emissive_units: "W.m^-2.sr^-1".into(),
    };
    let dir = std::env::temp_dir().join(format!("prism-fuzz-seed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    let path = dir.join("seed.exr");
    let options = ExrWriteOptions {
        compression: ExrCompression::None,
        ..ExrWriteOptions::default()
    };
    let bytes = write_spectral_exr(&path, &image, &options)
        .ok()
        .and_then(|()| std::fs::read(&path).ok());
    let _ = std::fs::remove_dir_all(&dir);
    bytes
}

/// A rotationally symmetric EULUMDAT file (5 γ angles, one C plane).
fn ldt_seed() -> String {
    let mut lines: Vec<String> = ["Prism fuzz seed", "1", "1", "1", "360", "5", "45"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    lines.extend(["R-001", "Panel", "P600", "panel.ldt", "2026-12-02"].map(String::from));
    lines.extend(["600", "600", "50", "580", "580", "0", "0", "0", "0"].map(String::from));
    lines.extend(
        [
            "100", "85,5", "1", "0", "1", "1", "LED", "4000", "4000", "80", "36",
        ]
        .map(String::from),
    );
    lines.extend((0..10).map(|k| format!("0.{}", 5 + k / 3)));
    lines.push("0".into());
    lines.extend((0..5).map(|j| format!("{}", j * 45)));
    lines.extend((0..5).map(|j| format!("{}", 100 - 20 * j)));
    lines.join("\r\n") + "\r\n"
}

const PLY_ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

const PLY_BINARY_HEADER: &str = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";

fn copy_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let (source, name) = (entry.path(), entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_tree(&source, &to.join(&name))?;
        } else if !name.to_string_lossy().contains(".reference-") {
            std::fs::copy(&source, to.join(&name))?;
        }
    }
    Ok(())
}

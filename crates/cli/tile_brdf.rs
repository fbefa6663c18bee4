//! `prism tile-brdf`: the BRDF/BTDF pyramid of a scene's periodic tile
//! (`prism_render::tile_pyramid`, docs/radiosity.md), computed by path tracing the repeated
//! tile and cached in the cache directory under a hash of everything it depends on. Prints
//! (or writes) a JSON summary: per incident bin the whole period's directional-hemispherical
//! reflectance, scattered transmittance and transparency per band.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use prism_cpu::memory::MemoryBudget;
use prism_render::tile_pyramid::bins::{self, RINGS, SECTORS, SPHERE_BINS};
use prism_render::tile_pyramid::{PyramidOptions, TilePyramid};
use serde_json::json;

use crate::atomic_write::write_atomic;
use crate::cache_dir::{fnv1a64, prepare_cache_dir};

#[derive(Args, Debug)]
pub struct TileBrdfArgs {
    /// Scene file holding the tile (its `tiles` section and the materials they map to).
    pub scene: PathBuf,
    /// Name of the tile in the scene's `tiles` section.
    #[arg(long)]
    pub tile: String,
    /// Levels of the pyramid (1–8; default: the `levels` of the first `tiled` material
    /// that repeats the tile, else 3).
    #[arg(long)]
    pub levels: Option<u32>,
    /// Camera samples per (incident bin, outgoing bin), at least 4^levels.
    #[arg(long, default_value_t = 256)]
    pub samples: u32,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Leave the tile's self-shadowing out: every face facing the beam is lit (the paper's
    /// Fig. 6 comparison; also the material's `"self_shadowing": false`).
    #[arg(long = "no-self-shadowing")]
    pub no_self_shadowing: bool,
    /// Leave the texture-scale inter-reflection out: single scattering only (the paper's
    /// F_i, Fig. 5–6; also the material's `"interreflection": false`).
    #[arg(long = "no-interreflection")]
    pub no_interreflection: bool,
    /// Cache directory (default: $XDG_CACHE_HOME/prism, else ~/.cache/prism).
    #[arg(long = "cache-dir", value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Write the JSON summary here instead of printing it.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
}

pub fn run(args: &TileBrdfArgs, budget: &MemoryBudget) -> Result<(), String> {
    let description = prism_scene::load_scene(&args.scene).map_err(|e| e.to_string())?;
    let scene = args.scene.display();
    let Some(tile) = description.tiles.iter().position(|t| t.name == args.tile) else {
        let names: Vec<String> = description
            .tiles
            .iter()
            .map(|t| format!("`{}`", t.name))
            .collect();
        return Err(format!(
            "{scene}: no tile `{}` (defined: {})",
            args.tile,
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        ));
    };
    // The first `tiled` material that repeats the tile gives the defaults.
    let (material_levels, self_shadowing, interreflection) = description
        .materials
        .iter()
        .find_map(|m| match m.kind {
            prism_scene::MaterialKind::Tiled {
                tile: t,
                levels,
                self_shadowing,
                interreflection,
            } if t == tile => Some((levels, self_shadowing, interreflection)),
            _ => None,
        })
        .unwrap_or((3, true, true));
    let levels = args.levels.unwrap_or(material_levels);
    let options = PyramidOptions {
        levels,
        samples_per_bin_pair: args.samples,
        seed: args.seed,
        self_shadowing: self_shadowing && !args.no_self_shadowing,
        interreflection: interreflection && !args.no_interreflection,
        ..PyramidOptions::default()
    };
    budget
        .check(
            &format!("a pyramid of {levels} levels of tile `{}`", args.tile),
            TilePyramid::estimated_bytes(levels),
        )
        .map_err(|e| e.to_string())?;
    let cache_dir = prepare_cache_dir(args.cache_dir.as_deref(), "the tile pyramid cache", "")?;
    let key = cache_key(&description, tile, &options)?;
    let cache_file = cache_dir.join(format!(
        "tile-{}-{key:016x}.prismbtf",
        crate::falsecolour::file_name_part(&args.tile)
    ));
    let start = Instant::now();
    let (pyramid, from_cache) = match std::fs::read(&cache_file) {
        Ok(bytes) => match TilePyramid::from_bytes(&bytes) {
            Ok(p) if p.levels == levels => (p, true),
            // A damaged or foreign file under our name is recomputed and replaced.
            Ok(_) | Err(_) => (simulate(&description, tile, &options, &scene)?, false),
        },
        Err(_) => (simulate(&description, tile, &options, &scene)?, false),
    };
    if !from_cache {
        write_atomic(&cache_file, &pyramid.to_bytes(), "tile pyramid cache")?;
    }
    let seconds = start.elapsed().as_secs_f64();
    eprintln!(
        "tile `{}`: {levels}-level pyramid ({} cells, {SPHERE_BINS}×{SPHERE_BINS} bins, 16 \
         bands) {} {} in {seconds:.2} s",
        args.tile,
        pyramid.cell_count(),
        if from_cache {
            "read from"
        } else {
            "computed and cached in"
        },
        cache_file.display()
    );
    let incident: Vec<serde_json::Value> = (0..SPHERE_BINS)
        .map(|i| {
            let w = bins::centre(i);
            let (albedo, albedo_se) = pyramid.albedo(i);
            let (transmitted, transmitted_se) = pyramid.scattered_transmittance(i);
            json!({
                "bin": i,
                "side": if bins::is_above(i) { "front" } else { "back" },
                "theta_deg": w.z.abs().acos().to_degrees(),
                "phi_deg": w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU).to_degrees(),
                "albedo": albedo,
                "albedo_se": albedo_se,
                "scattered_transmittance": transmitted,
                "scattered_transmittance_se": transmitted_se,
                "transparency": pyramid.transparency(0, 0, 0, i),
                "transparency_bin_mean": pyramid.view_transparency(0, 0, 0, i),
            })
        })
        .collect();
    let summary = json!({
        "scene": args.scene,
        "tile": args.tile,
        "levels": levels,
        "cells": pyramid.cell_count(),
        "bins": {"rings": RINGS, "sectors": SECTORS, "per_side": RINGS * SECTORS,
                 "rings_equal_solid_angle": true},
        "bands": {"first_nm": 380, "width_nm": 25, "count": 16},
        "samples_per_bin_pair": args.samples,
        "seed": args.seed,
        "self_shadowing": options.self_shadowing,
        "interreflection": options.interreflection,
        "cache_file": cache_file,
        "from_cache": from_cache,
        "seconds": seconds,
        "incident": incident,
    });
    let text = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())? + "\n";
    match &args.output {
        Some(path) => write_atomic(path, text.as_bytes(), "tile-brdf summary"),
        None => {
            print!("{text}");
            Ok(())
        }
    }
}

fn simulate(
    description: &prism_scene::SceneDescription,
    tile: usize,
    options: &PyramidOptions,
    scene: &impl std::fmt::Display,
) -> Result<TilePyramid, String> {
    TilePyramid::simulate(description, tile, options).map_err(|e| format!("{scene}: {e}"))
}

/// A hash of what the pyramid depends on: the tile's OBJ and MTL bytes, its period, the
/// descriptions of the materials it maps to, the options and Prism's version.
fn cache_key(
    description: &prism_scene::SceneDescription,
    tile: usize,
    options: &PyramidOptions,
) -> Result<u64, String> {
    let t = &description.tiles[tile];
    let obj = std::fs::read(&t.mesh).map_err(|e| format!("{}: {e}", t.mesh.display()))?;
    let mtl = mtl_bytes(&t.mesh, &obj);
    let materials: String = t
        .materials
        .iter()
        .map(|(name, m)| format!("{name}={:?};", description.materials[*m].kind))
        .collect();
    let settings = format!(
        "{}x{} {:?} {}",
        t.period_m[0],
        t.period_m[1],
        options,
        env!("CARGO_PKG_VERSION")
    );
    Ok(fnv1a64(&[
        &obj,
        &mtl,
        materials.as_bytes(),
        settings.as_bytes(),
    ]))
}

/// The MTL files an OBJ names (`mtllib`), concatenated; missing ones add nothing (the
/// scene load has already checked them).
fn mtl_bytes(obj_path: &Path, obj: &[u8]) -> Vec<u8> {
    let dir = obj_path.parent().unwrap_or(Path::new("."));
    String::from_utf8_lossy(obj)
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("mtllib "))
        .flat_map(|name| std::fs::read(dir.join(name.trim())).unwrap_or_default())
        .collect()
}

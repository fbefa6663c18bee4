//! The BRDF/BTDF MIP-map pyramid Γ(l, u, v, λ) of a periodic tile and its view-dependent
//! transparency (Mostefaoui et al. §2, Fig. 1–2): the mean reflectance and transmittance of
//! the tile's surface at scales from the whole period (level 0) down to 2^l × 2^l sub-cells,
//! in direction bins ([`bins`]) and the radiosity's 16 wavelength bands.
//!
//! The paper simulates the tile by radiosity; Prism renders the repeated tile with its own
//! path tracer, so every material path renders is measured as path renders it. For each
//! incident bin, the tile repeated over 257 × 257 periods is lit by a parallel beam of unit
//! irradiance (normal to the beam) from the bin's centre direction. Rays arrive from each
//! outgoing bin (directions uniform over the bin) and cross the carrier plane z = 0 at
//! points uniform over one period. The radiance L each brings back, divided by the
//! irradiance on the carrier |cos θ_i|, estimates Γ(i → o) = L/E (1/sr). It is a BRDF when
//! o is on the light's side and a BTDF otherwise. Light that passes through a hole
//! unscattered is not in the BTDF: it is the transparency τ(i), the fraction of straight
//! lines from direction i through the slab that meet no face. A sample belongs to the cell
//! of each level that holds its crossing point, so sub-cells describe the light leaving
//! their part of the carrier.

mod file;

/// The direction bins, shared with the radiosity solution's directional patches.
pub use prism_radiosity::bins;

use glam::{UVec2, Vec2, Vec3A};
use prism_geometry::Ray;
use prism_radiosity::tile_cells::{cell_index, pyramid_cells, MAX_PYRAMID_LEVELS};
use prism_scene::{
    FluorescenceLanes, Integrator as IntegratorDescription, Light, LightKind, MaterialKind,
    MisHeuristic, SamplerKind, SceneDescription, Shape, ShapeKind, SpectrumRef, Strength,
};
use prism_spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;

use crate::bsdf::TransportMode;
use crate::integrator::radiosity::patches::{SolutionBands, BANDS};
use crate::integrator::scatter_vertex::{ScatterVertex, SurfaceVertex};
use crate::integrator::{LaneWavelengths, PathCounters, PathTracer};
use crate::sampler::PixelSampler;
use crate::scene_build::RenderScene;
use bins::SPHERE_BINS;

/// Periods along each side of the repeated tile the simulation traces (odd: the sampled
/// period is the centre one). Rays at grazing angles cross many periods before they reach
/// the centre; 257 keeps 128 periods on every side, and one copy of the tile is stored.
pub const SIMULATION_PERIODS: u32 = 257;

/// How a pyramid is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PyramidOptions {
    /// Levels: 1 is the whole period only; level l has 4^l cells.
    pub levels: u32,
    /// Camera samples per (incident bin, outgoing bin) over the whole period, at least
    /// 4^levels: they are stratified over the cells of the finest level and over four
    /// groups of four bands (four wavelengths a sample), so a level-l cell gets 4^−l of
    /// them and each of its bands a quarter of those.
    pub samples_per_bin_pair: u32,
    /// Straight lines per incident bin for the transparency.
    pub transparency_samples: u32,
    /// Longest path, in bounces.
    pub max_depth: u32,
    pub seed: u64,
    /// Faces of the tile shadow each other from the beam (the paper's self-shadowing maps,
    /// Fig. 3); off, every face that faces the beam is lit, as in the paper's Fig. 6.
    pub self_shadowing: bool,
    /// Light scattered by one face reaches others (the paper's texture-scale
    /// inter-reflection F_i, Fig. 5); off, only single scattering leaves the tile.
    pub interreflection: bool,
}

impl Default for PyramidOptions {
    fn default() -> Self {
        Self {
            levels: 3,
            samples_per_bin_pair: 256,
            transparency_samples: 4096,
            max_depth: 32,
            seed: 0,
            self_shadowing: true,
            interreflection: true,
        }
    }
}

/// Γ and τ of one tile.
#[derive(Clone, Debug, PartialEq)]
pub struct TilePyramid {
    pub levels: u32,
    /// Mean Γ per (cell, incident bin, outgoing bin, band), 1/sr; cells of all levels in
    /// order (level 0 first, then level 1's four in row order, …).
    gamma: Vec<f32>,
    /// The variance of each mean in `gamma` (its squared standard error).
    gamma_variance: Vec<f32>,
    /// τ per (cell, incident bin).
    transparency: Vec<f32>,
    /// τ̄ per (cell, bin): τ averaged over the bin's directions (uniform in solid angle),
    /// as Γ averages its outgoing bins: the share a viewer looking back along a direction
    /// of the bin sees through, on average.
    view_transparency: Vec<f32>,
}

// The solution reads the pyramid's cells in the same order (`prism_radiosity::tile_cells`)
// and accepts as many levels as a `tiled` material may ask for.
const _: () = assert!(prism_scene::material::MAX_TILE_LEVELS == MAX_PYRAMID_LEVELS);

impl TilePyramid {
    /// Cells over all levels.
    pub fn cell_count(&self) -> usize {
        pyramid_cells(self.levels)
    }

    fn cell(&self, level: u32, u: u32, v: u32) -> usize {
        assert!(level < self.levels && u < 1 << level && v < 1 << level);
        cell_index(level, u, v)
    }

    fn at(&self, cell: usize, incident: usize, outgoing: usize) -> usize {
        ((cell * SPHERE_BINS + incident) * SPHERE_BINS + outgoing) * BANDS
    }

    /// Γ(l, u, v) from incident bin to outgoing bin, per band, 1/sr (cell (u, v) of level
    /// `level`, u along the tile's x).
    pub fn gamma(&self, level: u32, u: u32, v: u32, incident: usize, outgoing: usize) -> &[f32] {
        let i = self.at(self.cell(level, u, v), incident, outgoing);
        &self.gamma[i..i + BANDS]
    }

    /// The standard errors of [`Self::gamma`].
    pub fn gamma_standard_error(
        &self,
        level: u32,
        u: u32,
        v: u32,
        incident: usize,
        outgoing: usize,
    ) -> [f32; BANDS] {
        let i = self.at(self.cell(level, u, v), incident, outgoing);
        std::array::from_fn(|b| self.gamma_variance[i + b].sqrt())
    }

    /// The view-dependent transparency τ of cell (u, v) of `level` for light from
    /// `incident`: the fraction that passes through holes unscattered.
    pub fn transparency(&self, level: u32, u: u32, v: u32, incident: usize) -> f32 {
        self.transparency[self.cell(level, u, v) * SPHERE_BINS + incident]
    }

    /// τ̄ of cell (u, v) of `level` over the directions of `bin` (see the field).
    pub fn view_transparency(&self, level: u32, u: u32, v: u32, bin: usize) -> f32 {
        self.view_transparency[self.cell(level, u, v) * SPHERE_BINS + bin]
    }

    /// The directional-hemispherical reflectance of the whole period for light from
    /// `incident`, per band, with its standard error: Σ_o Γ(i → o)·∫_o |cos θ| dω over the
    /// outgoing bins on the light's side.
    pub fn albedo(&self, incident: usize) -> ([f32; BANDS], [f32; BANDS]) {
        self.hemisphere_sum(incident, bins::is_above(incident))
    }

    /// As [`Self::albedo`] for the scattered transmission (the BTDF's integral; the
    /// transparency τ comes on top).
    pub fn scattered_transmittance(&self, incident: usize) -> ([f32; BANDS], [f32; BANDS]) {
        self.hemisphere_sum(incident, !bins::is_above(incident))
    }

    fn hemisphere_sum(&self, incident: usize, above: bool) -> ([f32; BANDS], [f32; BANDS]) {
        let mut sum = [0.0f64; BANDS];
        let mut variance = [0.0f64; BANDS];
        for o in (0..SPHERE_BINS).filter(|&o| bins::is_above(o) == above) {
            let w = f64::from(bins::projected_solid_angle_sr(o));
            let i = self.at(0, incident, o);
            for b in 0..BANDS {
                sum[b] += w * f64::from(self.gamma[i + b]);
                variance[b] += w * w * f64::from(self.gamma_variance[i + b]);
            }
        }
        (sum.map(|s| s as f32), variance.map(|v| v.sqrt() as f32))
    }

    /// The memory a pyramid of `levels` levels takes while it is simulated, bytes: each
    /// incident bin's sums (three f64 per cell, outgoing bin and band, all 64 held until
    /// they are averaged), the result's Γ and its variance (f32), and one copy of both
    /// (the cache file's bytes, or the solution's surfaces). An upper bound of the peak's
    /// growth: 46 and 163 MiB measured for 3 and 4 levels against 1 (`prism tile-brdf`,
    /// the wicker), 52 and 210 MiB estimated.
    pub fn estimated_bytes(levels: u32) -> u64 {
        let per_cell = (SPHERE_BINS * SPHERE_BINS * BANDS) as u64 * (3 * 8 + 4 * 4);
        pyramid_cells(levels) as u64 * per_cell
    }

    /// Simulates tile `tile` of `description` (its materials as the scene defines them).
    pub fn simulate(
        description: &SceneDescription,
        tile: usize,
        options: &PyramidOptions,
    ) -> Result<Self, String> {
        if options.levels == 0 || options.levels > prism_scene::material::MAX_TILE_LEVELS {
            return Err(format!(
                "a pyramid has 1 to {} levels, not {}",
                prism_scene::material::MAX_TILE_LEVELS,
                options.levels
            ));
        }
        let least = 1u64 << (2 * options.levels);
        if u64::from(options.samples_per_bin_pair) < least {
            return Err(format!(
                "{} samples per bin pair leave cells of the finest level without a band: a \
                 pyramid of {} levels needs at least {least}",
                options.samples_per_bin_pair, options.levels
            ));
        }
        if tile >= description.tiles.len() {
            return Err(format!("the scene has no tile {tile}"));
        }
        let cells = pyramid_cells(options.levels);
        // One scene per worker (the tile's OBJ is read and its BVH built once each); each
        // incident bin only replaces the beam.
        let d = simulation_description(description, tile, options.max_depth);
        let per_incident: Vec<IncidentResult> = (0..SPHERE_BINS)
            .into_par_iter()
            .map_init(
                || RenderScene::build(&d, Some(UVec2::ONE)).map_err(|e| e.to_string()),
                |scene, incident| {
                    let scene = scene.as_mut().map_err(|e| e.clone())?;
                    simulate_incident(&d, scene, tile, incident, options)
                },
            )
            .collect::<Result<_, String>>()?;
        let mut gamma = vec![0.0f32; cells * SPHERE_BINS * SPHERE_BINS * BANDS];
        let mut gamma_variance = vec![0.0f32; gamma.len()];
        let mut transparency = vec![0.0f32; cells * SPHERE_BINS];
        let mut view_transparency = vec![0.0f32; cells * SPHERE_BINS];
        for (incident, r) in per_incident.iter().enumerate() {
            for cell in 0..cells {
                transparency[cell * SPHERE_BINS + incident] = r.transparency[cell];
                view_transparency[cell * SPHERE_BINS + incident] = r.view_transparency[cell];
                for o in 0..SPHERE_BINS {
                    for b in 0..BANDS {
                        let k = (cell * SPHERE_BINS + o) * BANDS + b;
                        let n = r.count[k];
                        let at = ((cell * SPHERE_BINS + incident) * SPHERE_BINS + o) * BANDS + b;
                        if n > 0.0 {
                            let mean = r.sum[k] / n;
                            let var = (r.sum_sq[k] / n - mean * mean).max(0.0) / (n - 1.0).max(1.0);
                            gamma[at] = mean as f32;
                            gamma_variance[at] = var as f32;
                        }
                    }
                }
            }
        }
        Ok(Self {
            levels: options.levels,
            gamma,
            gamma_variance,
            transparency,
            view_transparency,
        })
    }
}

/// What `radiosity` keeps of a tile's pyramid: Γ and τ̄ per cell and direction bin, the
/// whole period's diffuse-equivalent reflectance per side (Γ's albedo averaged over incident
/// directions by their projected solid angle: the reflectance under uniform diffuse light,
/// which the refinement oracle reads), with the slab the tile fills (metres along the
/// carrier's normal).
#[derive(Clone, Debug, PartialEq)]
pub struct TiledSurface {
    /// Per band, for light arriving on the front (+z) and on the back.
    pub reflectance: [[f32; BANDS]; 2],
    /// Levels of the pyramid below (1: the whole period only).
    pub levels: u32,
    /// τ̄ per (pyramid cell, direction bin): the share of the cell seen through along the
    /// bin's directions, averaged over them as Γ averages an outgoing bin.
    pub view_transparency: Vec<f32>,
    /// Γ(i → o) per (pyramid cell, incident bin, outgoing bin, band), 1/sr, cells of all
    /// levels in the pyramid's order: the solution's directional transfer
    /// (`prism_radiosity::directional`), each element by the cells it covers.
    pub gamma: Vec<f32>,
    /// The lowest and highest tile heights, metres.
    pub slab_m: (f32, f32),
}

impl TilePyramid {
    /// The pyramid as the solution holds it (see [`TiledSurface`]).
    pub fn tiled_surface(&self, slab_m: (f32, f32)) -> TiledSurface {
        let side = |front: bool| -> [f32; BANDS] {
            let mut r = [0.0f32; BANDS];
            for i in (0..SPHERE_BINS).filter(|&i| bins::is_above(i) == front) {
                let w = bins::projected_solid_angle_sr(i) / std::f32::consts::PI;
                let (albedo, _) = self.albedo(i);
                for b in 0..BANDS {
                    r[b] += w * albedo[b];
                }
            }
            r
        };
        TiledSurface {
            reflectance: [side(true), side(false)],
            levels: self.levels,
            view_transparency: self.view_transparency.clone(),
            gamma: self.gamma.clone(),
            slab_m,
        }
    }
}

/// Sums over the samples of one incident bin, per (cell, outgoing bin, band), and τ per
/// cell.
struct IncidentResult {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    count: Vec<f64>,
    transparency: Vec<f32>,
    view_transparency: Vec<f32>,
}

/// The simulation scene: tile `tile` repeated over `SIMULATION_PERIODS`² periods centred
/// on the origin (normal +z), lit by a parallel beam of unit irradiance (straight down
/// until [`with_beam`] turns it), rendered by `path` up to `max_depth` bounces.
fn simulation_description(
    description: &SceneDescription,
    tile: usize,
    max_depth: u32,
) -> SceneDescription {
    let mut d = description.clone();
    let material = match d
        .materials
        .iter()
        .position(|m| matches!(m.kind, MaterialKind::Tiled { tile: t, .. } if t == tile))
    {
        Some(m) => m,
        None => {
            d.materials.push(prism_scene::Material {
                name: format!("tile `{}`", d.tiles[tile].name),
                kind: MaterialKind::Tiled {
                    tile,
                    levels: 1,
                    self_shadowing: true,
                    interreflection: true,
                },
            });
            d.materials.len() - 1
        }
    };
    let period = d.tiles[tile].period_m;
    let n = f64::from(SIMULATION_PERIODS);
    d.shapes = vec![Shape {
        name: None,
        kind: ShapeKind::Rectangle {
            size_m: [n * period[0], n * period[1]],
        },
        transform: prism_scene::Transform::IDENTITY,
        material: Some(material),
        interior_medium: None,
        exterior_medium: None,
    }];
    d.lights = vec![beam_light(Vec3A::NEG_Z)];
    d.light_media = vec![None];
    d.sensors.clear();
    d.media.clear();
    d.world_medium = None;
    d.camera_medium = None;
    d.integrator = IntegratorDescription::Path {
        max_depth,
        sampler: SamplerKind::Independent,
        mis: MisHeuristic::Power,
        rr_depth: 3,
        fluorescence_lanes: FluorescenceLanes::All,
        spectral_mis: true,
    };
    d
}

/// A parallel beam of unit irradiance (normal to it) travelling along `beam`.
fn beam_light(beam: Vec3A) -> Light {
    Light {
        kind: LightKind::Directional {
            direction: [f64::from(beam.x), f64::from(beam.y), f64::from(beam.z)],
            angular_diameter_rad: 0.0,
        },
        spectrum: SpectrumRef::Constant(1.0),
        strength: Strength::Scale(1.0),
    }
}

/// The beam's light that other faces of the tile keep from the first face `ray` meets
/// (f · |cos θᵢ| · E⊥ with E⊥ = 1 where the shadow ray towards the beam is blocked): what
/// switching self-shadowing off adds back.
fn shadowed_beam(
    scene: &RenderScene,
    ray: &Ray,
    towards_light: Vec3A,
    lanes: &mut LaneWavelengths,
) -> SampledSpectrum {
    let none = SampledSpectrum::splat(0.0);
    let Some(hit) = scene.geometry.intersect(ray) else {
        return none;
    };
    let si = scene.geometry.shading_interaction(ray, &hit);
    let side = si.n_geometric.dot(towards_light).signum();
    let from = si.p + si.n_geometric * side * 1e-5 * (1.0 + si.p.abs().max_element());
    if !scene.geometry.occluded(&Ray::spawn(from, towards_light)) {
        return none;
    }
    let material = scene.material(si.material_id);
    let mut cache = crate::spectrum_cache::SpectrumCache::new();
    let bsdf = material.bsdf_cached(si.material_id, &si, lanes, &mut cache);
    let vertex = ScatterVertex::Surface(SurfaceVertex::new(&si, &bsdf, ray.direction, false));
    vertex
        .eval(towards_light, TransportMode::Radiance)
        .map_or(none, |e| e.f_cos)
}

/// The sums of incident bin `incident` on `scene` (built from `simulation`, the
/// simulation's description), whose beam it turns to come from that bin.
fn simulate_incident(
    simulation: &SceneDescription,
    scene: &mut RenderScene,
    tile: usize,
    incident: usize,
    options: &PyramidOptions,
) -> Result<IncidentResult, String> {
    let towards_light = bins::centre(incident);
    let mut d = simulation.clone();
    d.lights = vec![beam_light(-towards_light)];
    scene.lights = crate::light::LightSet::build(&d, &scene.geometry).map_err(|e| e.to_string())?;
    let scene = &*scene;
    let (lo, hi) = scene
        .geometry
        .instance_world_bounds(0)
        .ok_or("the tile has no geometry")?;
    let period = simulation.tiles[tile].period_m.map(|p| p as f32);
    let margin = 0.01 * period[0].max(period[1]);
    let (top, bottom) = (hi.z.max(0.0) + margin, lo.z.min(0.0) - margin);
    let cells = pyramid_cells(options.levels);
    let levels = options.levels;
    // The crossing point's cell at every level: u, v in [0, 1) over the centre period.
    let cell_indices = |uv: Vec2| -> Vec<usize> {
        (0..levels)
            .map(|l| {
                let side = 1u32 << l;
                let cu = ((uv.x * side as f32) as u32).min(side - 1);
                let cv = ((uv.y * side as f32) as u32).min(side - 1);
                cell_index(l, cu, cv)
            })
            .collect()
    };
    let crossing = |uv: Vec2| Vec3A::new((uv.x - 0.5) * period[0], (uv.y - 0.5) * period[1], 0.0);
    let sampler = PixelSampler::with_kind(SamplerKind::Independent, options.seed);
    let tracer = PathTracer {
        max_depth: if options.interreflection {
            options.max_depth
        } else {
            1
        },
        ..PathTracer::default()
    };
    let cos_incident = towards_light.z.abs();
    let mut sum = vec![0.0f64; cells * SPHERE_BINS * BANDS];
    let mut sum_sq = vec![0.0f64; sum.len()];
    let mut count = vec![0.0f64; sum.len()];
    let mut counters = PathCounters::default();
    let fine_side = 1u32 << (levels - 1);
    let fine_cells = fine_side * fine_side;
    for outgoing in 0..SPHERE_BINS {
        for s in 0..options.samples_per_bin_pair {
            let mut stream = sampler.stream(UVec2::new(incident as u32, outgoing as u32), s);
            // Stratified: sample s takes band group s mod 4 and, in turn, each cell of the
            // finest level (jittered inside it).
            let cell = (s / 4) % fine_cells;
            let corner = Vec2::new((cell % fine_side) as f32, (cell / fine_side) as f32);
            let uv = (corner + stream.get_2d()) / fine_side as f32;
            let w = bins::sample_in(outgoing, stream.get_2d());
            // Four bands a sample, one in each quarter of the range.
            let first = (s % 4) as usize;
            let jitter = stream.get_1d();
            let bands: [usize; 4] = std::array::from_fn(|k| first + 4 * k);
            let band = SolutionBands::DEFAULT;
            let lambda = bands
                .map(|b| band.point_nm(b, 0, 1) as f32 + (jitter - 0.5) * band.width_nm as f32);
            let wavelengths = SampledWavelengths::new(lambda, SampledSpectrum::splat(1.0));
            let mut lanes = LaneWavelengths::new(wavelengths);
            let p = crossing(uv);
            let height = if w.z > 0.0 { top } else { bottom };
            let origin = p + w * (height / w.z);
            let ray = Ray::infinite(origin, -w);
            let result = tracer.radiance(
                scene,
                &ray,
                &mut lanes,
                &mut stream,
                1,
                false,
                &mut counters,
            );
            let mut radiance = result.radiance;
            if !options.self_shadowing {
                radiance += shadowed_beam(scene, &ray, towards_light, &mut lanes);
            }
            let f = radiance.to_array().map(|l| f64::from(l / cos_incident));
            for cell in cell_indices(uv) {
                for (k, &b) in bands.iter().enumerate() {
                    let at = (cell * SPHERE_BINS + outgoing) * BANDS + b;
                    sum[at] += f[k];
                    sum_sq[at] += f[k] * f[k];
                    count[at] += 1.0;
                }
            }
        }
    }
    // τ: straight lines from the light's side through the slab, crossing z = 0 uniformly.
    let mut through = vec![0u32; cells];
    let mut lines = vec![0u32; cells];
    let beam = -towards_light;
    let (start, end) = if towards_light.z > 0.0 {
        (top, bottom)
    } else {
        (bottom, top)
    };
    // τ̄: the same over directions uniform in the bin.
    let mut through_bin = vec![0u32; cells];
    let blocked = |p: Vec3A, beam: Vec3A| {
        let from = p + beam * (start / beam.z);
        let to = p + beam * (end / beam.z);
        scene
            .geometry
            .occluded(&Ray::new(from, to - from, 0.0, 1.0))
    };
    for s in 0..options.transparency_samples {
        let mut stream = sampler.stream(UVec2::new(incident as u32, SPHERE_BINS as u32), s);
        let uv = stream.get_2d();
        let p = crossing(uv);
        let at_centre = blocked(p, beam);
        let in_bin = blocked(p, -bins::sample_in(incident, stream.get_2d()));
        for cell in cell_indices(uv) {
            lines[cell] += 1;
            through[cell] += u32::from(!at_centre);
            through_bin[cell] += u32::from(!in_bin);
        }
    }
    let fraction = |through: &[u32]| -> Vec<f32> {
        through
            .iter()
            .zip(&lines)
            .map(|(&t, &n)| if n > 0 { t as f32 / n as f32 } else { 0.0 })
            .collect()
    };
    Ok(IncidentResult {
        sum,
        sum_sq,
        count,
        transparency: fraction(&through),
        view_transparency: fraction(&through_bin),
    })
}

//! `prism.render`: a scene (file or dict in the JSON schema) rendered as `prism render`
//! renders it to an EXR — the same scene build, settings, uniform sample plan and
//! controlled pass (`prism_render::render_pass_controlled`) — so that the arrays equal the
//! CLI's EXR channels bit for bit.
//!
//! The render runs on a worker thread with the GIL released; the calling thread wakes
//! every `POLL_INTERVAL`, takes the GIL, runs Python's signal handlers
//! (`Python::check_signals`) and the progress callback. Ctrl-C (or an exception from the
//! callback) sets the pass's stop flag — the mechanism `prism render` uses for SIGINT: no
//! new work item starts, those in flight finish — and the exception is raised once the
//! worker has returned.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

use glam::UVec2;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use prism_bandwidth::SamplePlan;
use prism_cpu::memory::{format_bytes, parse_size, MemoryBudget};
use prism_cpu::threads::{max_threads, MAX_THREADS_PER_CPU};
use prism_render::film::spectral_bins::{MAX_SPECTRAL_BINS, MIN_SPECTRAL_BINS};
use prism_render::film::FilmMemory;
use prism_render::integrator::{Pass, DEFAULT_TILE_SIZE_PX};
use prism_render::sensor::{measure_sensors, SensorReading};
use prism_render::{
    film_for, render_pass_controlled, FilmImage, PassControl, PassOutcome, RenderScene,
    RenderSettings, SpectralBins,
};
use prism_scene::SceneDescription;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{pixels_to_array, plane_to_array};
use crate::errors::{argument, RenderError, SceneError};
use crate::image_io::planes_to_array;

/// How often the waiting thread takes the GIL to check for Ctrl-C and report progress.
const POLL_INTERVAL: Duration = Duration::from_millis(100);

/// The result of `prism.render`.
#[pyclass(module = "prism", frozen)]
pub struct Render {
    /// (H, W, 3) float32 linear Rec.709 RGB (the EXR's R, G, B).
    #[pyo3(get)]
    rgb: Py<PyAny>,
    /// (H, W, 3) float32 CIE 1931 XYZ (a flat spectral radiance of 1 has Y = 1).
    #[pyo3(get)]
    xyz: Py<PyAny>,
    /// The EXR's layers: name → (H, W) or (H, W, C) float32 (`luminance` in cd/m²,
    /// `depth`, `normal`, `albedo`, `illumination`, `spp`, … as the scene records them).
    #[pyo3(get)]
    aovs: Py<PyDict>,
    /// Each layer's channel names, in the order of the last axis of `aovs[name]`.
    #[pyo3(get)]
    aov_channels: Py<PyDict>,
    /// (H, W, N) float32 spectral radiance in N equal bins over 360–830 nm
    /// (W·m⁻²·sr⁻¹·nm⁻¹), or None when `spectral_bins` was not given.
    #[pyo3(get)]
    spectral: Option<Py<PyAny>>,
    /// The bins' centres in nm, or None.
    #[pyo3(get)]
    wavelengths_nm: Option<Py<PyAny>>,
    /// cd/m² of a pixel whose Y is 1 (the EXR's `prism:cd_m2_per_unit`).
    #[pyo3(get)]
    cd_m2_per_unit: f64,
    /// The statistics `prism render --stats-json` writes.
    #[pyo3(get)]
    stats: Py<PyAny>,
    /// One dict per sensor of the scene (docs/lighting.md): name, grid_resolution,
    /// uniformity, and per point position_m, normal, illuminance_lx, std_error_lx, samples.
    #[pyo3(get)]
    sensors: Py<PyList>,
}

#[pymethods]
impl Render {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let shape = self.rgb.bind(py).getattr("shape")?.str()?.to_string();
        Ok(format!("prism.Render(rgb {shape})"))
    }
}

/// A scene argument: a path (str or os.PathLike) or a dict in the JSON schema.
#[derive(FromPyObject)]
pub enum SceneSpec<'py> {
    Path(PathBuf),
    Dict(Bound<'py, PyDict>),
}

fn load(scene: &SceneSpec<'_>, base_dir: Option<PathBuf>) -> PyResult<(SceneDescription, String)> {
    match scene {
        SceneSpec::Path(path) => {
            let description =
                prism_scene::load_scene(path).map_err(|e| SceneError::new_err(e.to_string()))?;
            Ok((description, path.display().to_string()))
        }
        SceneSpec::Dict(dict) => {
            let py = dict.py();
            let text: String = py
                .import("json")?
                .call_method1("dumps", (dict,))
                .map_err(|e| {
                    argument(format!(
                        "scene: the dict is not JSON-serialisable: {}",
                        e.value(py)
                    ))
                })?
                .extract()?;
            // Messages name the dict as `<scene dict>`; assets resolve against `base_dir`
            // (default: the current directory).
            let path = base_dir.unwrap_or_default().join("<scene dict>");
            let description = prism_scene::parse_scene_str(&text, &path)
                .map_err(|e| SceneError::new_err(e.to_string()))?;
            Ok((description, path.display().to_string()))
        }
    }
}

fn spectral_bins_of(count: Option<u32>) -> PyResult<Option<SpectralBins>> {
    count
        .map(|n| {
            SpectralBins::new(n).map_err(|_| {
                argument(format!(
                    "--spectral-bins {n}: expected {MIN_SPECTRAL_BINS} to {MAX_SPECTRAL_BINS} equal bins over 360–830 nm"
                ))
            })
        })
        .transpose()
}

/// `max_memory=`: bytes, or a size with a unit as the CLI's `--max-memory` takes.
#[derive(FromPyObject)]
pub enum MemorySize {
    Bytes(u64),
    Text(String),
}

/// The film's estimated memory against `max_memory` (default: the CLI's), checked before
/// the scene is built.
fn check_memory(
    description: &SceneDescription,
    label: &str,
    resolution: Option<UVec2>,
    spectral_bins: Option<SpectralBins>,
    max_memory: Option<MemorySize>,
) -> PyResult<()> {
    let budget = match max_memory {
        None => MemoryBudget::machine_default(),
        Some(MemorySize::Bytes(bytes)) => MemoryBudget::given(bytes),
        Some(MemorySize::Text(text)) => MemoryBudget::given(
            parse_size(&text).map_err(|e| argument(format!("max_memory: {e}")))?,
        ),
    };
    let [w, h] = description.film.resolution;
    let resolution = resolution.unwrap_or(UVec2::new(w, h));
    let film = FilmMemory::for_integrator(
        &description.integrator,
        resolution,
        spectral_bins.map_or(0, |b| b.count()),
    );
    let what = format!("{label}: rendering {}×{} px", resolution.x, resolution.y);
    budget.check(&what, film.total_bytes()).map_err(|over| {
        argument(format!(
            "{what} needs about {}, more than the memory limit of {} (max_memory= changes it)",
            format_bytes(over.estimate_bytes),
            format_bytes(over.budget.limit_bytes)
        ))
    })
}

fn warn(py: Python<'_>, message: String) -> PyResult<()> {
    let text = std::ffi::CString::new(message).map_err(|e| argument(e.to_string()))?;
    PyErr::warn(py, &py.get_type::<PyUserWarning>(), &text, 1)
}

/// The warnings `prism render` prints before rendering, as Python warnings.
fn scene_warnings(
    py: Python<'_>,
    label: &str,
    scene: &RenderScene,
    description: &SceneDescription,
) -> PyResult<()> {
    if scene.integrator.is_spectral() && scene.lights.is_empty() {
        warn(
            py,
            format!(
                "{label}: the scene has no lights: the {} image is black (add a `lights` entry, or choose a diagnostic `integrator`)",
                scene.integrator.name()
            ),
        )?;
    }
    let radius_m = scene.lights.scene_sphere().radius_m;
    for (i, light) in scene.lights.lights().iter().enumerate() {
        let power_w = light.power_w(radius_m);
        if power_w.is_nan() || power_w <= 0.0 {
            warn(
                py,
                format!("{label}: lights[{i}] has zero power: it emits nothing (check its strength and spectrum)"),
            )?;
        }
    }
    if scene.integrator.is_spectral() {
        for warning in prism_render::enclosure::enclosure_warnings(scene, description) {
            warn(py, format!("{label}: {warning}"))?;
        }
    }
    Ok(())
}

/// Sets `done` when dropped, so that the waiting thread wakes even if the worker panics.
struct DoneOnDrop<'a>(&'a (Mutex<bool>, Condvar));

impl Drop for DoneOnDrop<'_> {
    fn drop(&mut self) {
        let (lock, wake) = self.0;
        // A poisoned lock only means another thread panicked while holding it; the flag
        // is still written.
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        wake.notify_all();
    }
}

/// `render(scene, spp=None, seed=0, threads=None, resolution=None, spectral_bins=None,
/// progress=None, base_dir=None, max_memory=None)`.
///
/// `scene`: a path or a dict in the JSON schema (docs/scene-format.md; relative asset paths
/// of a dict resolve against `base_dir`, default the current directory). `spp`: default the
/// scene's `film.spp`, as in the CLI. `seed`: the sampler's seed, 0 unless given (`None`:
/// the scene's `film.seed`, as the CLI without `--seed`). `resolution`: (width,
/// height). `spectral_bins`: N equal bins over 360–830 nm in `.spectral`. `progress`:
/// called as `progress(samples_done, samples_total)` about ten times a second (an
/// exception from it stops the render and is raised). Ctrl-C stops the render and raises
/// KeyboardInterrupt. `threads`: 1 to 4 per logical CPU, as the CLI's `--threads`.
/// `max_memory`: bytes (an int) or a size such as "8G", as the CLI's `--max-memory`
/// (default 75 % of physical memory): a render whose film is estimated above it is an
/// `ArgumentError` before anything is allocated.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, seed=Some(0), threads=None, resolution=None, spectral_bins=None, progress=None, base_dir=None, max_memory=None))]
#[allow(clippy::too_many_arguments)]
pub fn render(
    py: Python<'_>,
    scene: SceneSpec<'_>,
    spp: Option<u32>,
    seed: Option<u64>,
    threads: Option<usize>,
    resolution: Option<(u32, u32)>,
    spectral_bins: Option<u32>,
    progress: Option<Bound<'_, PyAny>>,
    base_dir: Option<PathBuf>,
    max_memory: Option<MemorySize>,
) -> PyResult<Render> {
    let (description, label) = load(&scene, base_dir)?;
    let spectral_bins = spectral_bins_of(spectral_bins)?;
    let resolution = match resolution {
        Some((w, h)) if w >= 1 && h >= 1 => Some(UVec2::new(w, h)),
        Some((w, h)) => {
            return Err(argument(format!(
                "resolution ({w}, {h}): expected (width, height) of at least 1 pixel each"
            )))
        }
        None => None,
    };
    if let Some(n) = threads {
        let max = max_threads();
        if n == 0 || n > max {
            return Err(argument(format!(
                "threads {n}: expected 1 to {max} worker threads ({MAX_THREADS_PER_CPU} per \
                 logical CPU)"
            )));
        }
    }
    check_memory(&description, &label, resolution, spectral_bins, max_memory)?;
    let render_scene = py
        .detach(|| RenderScene::build(&description, resolution))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    let settings = RenderSettings {
        spp: spp.unwrap_or(render_scene.spp),
        seed: seed.unwrap_or(render_scene.seed),
        tile_size_px: DEFAULT_TILE_SIZE_PX,
        // The scene's sampler for the integrators that take one, Sobol otherwise.
        sampler: description.integrator.render_sampler(),
        spectral_bins,
        // What `prism render` records in an EXR output.
        illumination_aov: true,
        variance_aov: true,
    };
    if settings.spp == 0 {
        return Err(argument("--spp must be at least 1"));
    }
    scene_warnings(py, &label, &render_scene, &description)?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n);
    }
    let pool = pool
        .build()
        .map_err(|e| RenderError::new_err(format!("cannot start the thread pool: {e}")))?;
    let thread_count = pool.current_num_threads();
    let plan = SamplePlan::uniform(render_scene.resolution, settings.spp)
        .map_err(|e| argument(e.to_string()))?;
    let total_samples = plan.total_camera_samples();
    let mut film = film_for(&render_scene, &settings);
    let stop = AtomicBool::new(false);
    let samples_done = AtomicU64::new(0);
    let done = (Mutex::new(false), Condvar::new());
    let control = PassControl {
        stop: &stop,
        resumed: false,
        items_done: 0,
        checkpoint: None,
    };
    let pass = Pass {
        index: 0,
        settings: &settings,
        plan: &plan,
        first_sample: 0,
        footprint_plan: Some(&plan),
    };
    let start = Instant::now();
    let mut raised: Option<PyErr> = None;
    let outcome: Option<Result<PassOutcome, prism_render::RenderError>> = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let _done = DoneOnDrop(&done);
            pool.install(|| {
                let mut estimator = render_scene.integrator.estimator();
                render_pass_controlled(
                    estimator.as_mut(),
                    &render_scene,
                    &pass,
                    &mut film,
                    &|n| {
                        samples_done.fetch_add(n, Ordering::Relaxed);
                    },
                    &control,
                )
            })
        });
        let mut reported = u64::MAX;
        loop {
            let finished = py.detach(|| {
                let (lock, wake) = &done;
                let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) = wake
                    .wait_timeout_while(guard, POLL_INTERVAL, |finished| !*finished)
                    .unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if finished {
                break;
            }
            if raised.is_some() {
                continue;
            }
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::SeqCst);
                raised = Some(e);
                continue;
            }
            if let Some(callback) = &progress {
                let now = samples_done.load(Ordering::Relaxed);
                if now != reported {
                    reported = now;
                    // A Ctrl-C sent from the callback itself is taken at once, not after
                    // the next wait.
                    if let Err(e) = callback
                        .call1((now, total_samples))
                        .and_then(|_| py.check_signals())
                    {
                        stop.store(true, Ordering::SeqCst);
                        raised = Some(e);
                    }
                }
            }
        }
        worker.join().ok()
    });
    if let Some(e) = raised {
        return Err(e);
    }
    // A Ctrl-C that came while the last items finished still raises.
    py.check_signals()?;
    let outcome = outcome
        .ok_or_else(|| RenderError::new_err(format!("{label}: the render thread panicked")))?
        .map_err(|e| RenderError::new_err(format!("{label}: {e}")))?;
    if let Some(callback) = &progress {
        callback.call1((samples_done.load(Ordering::Relaxed), total_samples))?;
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    let image = film.finish();
    let readings = if description.sensors.is_empty() {
        Vec::new()
    } else {
        py.detach(|| {
            pool.install(|| {
                measure_sensors(&render_scene, &description.sensors, settings.seed, &|_| {}).0
            })
        })
    };
    let stats = prism_render::stats_json::stats_json(
        &render_scene,
        &settings,
        thread_count,
        wall_time_s,
        &outcome.stats,
    );
    build_result(py, &image, &stats, &readings)
}

/// One layer being assembled: name, channel names, one plane per channel.
type LayerPlanes<'a> = (&'a str, Vec<&'a str>, Vec<&'a [f32]>);

fn build_result(
    py: Python<'_>,
    image: &FilmImage,
    stats: &serde_json::Value,
    readings: &[SensorReading],
) -> PyResult<Render> {
    let (w, h) = (image.width as usize, image.height as usize);
    let aovs = PyDict::new(py);
    let aov_channels = PyDict::new(py);
    // The layers as `prism render` writes them (crates/cli/render.rs `to_image`): the
    // luminance in cd/m², then the AOV planes grouped by the layer before their `.`.
    aovs.set_item(
        "luminance",
        plane_to_array(py, &image.luminance_cd_m2(), w, h)?,
    )?;
    aov_channels.set_item("luminance", vec!["Y"])?;
    let mut layers: Vec<LayerPlanes> = Vec::new();
    for plane in &image.aovs {
        let (layer, channel) = plane.name.split_once('.').unwrap_or(("", &plane.name));
        match layers.iter_mut().find(|(l, _, _)| *l == layer) {
            Some((_, channels, planes)) => {
                channels.push(channel);
                planes.push(&plane.values);
            }
            None => layers.push((layer, vec![channel], vec![&plane.values])),
        }
    }
    for (layer, channels, planes) in layers {
        let owned: Vec<Vec<f32>> = planes.iter().map(|p| p.to_vec()).collect();
        let array = if owned.len() == 1 {
            plane_to_array(py, &owned[0], w, h)?.into_any()
        } else {
            planes_to_array(py, &owned, w, h)?
        };
        aovs.set_item(layer, array)?;
        aov_channels.set_item(layer, channels)?;
    }
    let (spectral, wavelengths_nm) = match &image.spectral {
        Some(bins) => (
            Some(planes_to_array(py, &bins.planes, w, h)?.unbind()),
            Some(bins.centres_nm.clone().into_pyarray(py).into_any().unbind()),
        ),
        None => (None, None),
    };
    let sensors = PyList::empty(py);
    for reading in readings {
        sensors.append(sensor_dict(py, reading)?)?;
    }
    Ok(Render {
        rgb: pixels_to_array(py, &image.rgb, w, h)?.into_any().unbind(),
        xyz: pixels_to_array(py, &image.xyz, w, h)?.into_any().unbind(),
        aovs: aovs.unbind(),
        aov_channels: aov_channels.unbind(),
        spectral,
        wavelengths_nm,
        cd_m2_per_unit: image.cd_m2_per_unit,
        stats: crate::json::to_python(py, stats)?.unbind(),
        sensors: sensors.unbind(),
    })
}

/// One sensor's readings with per-point NumPy arrays.
fn sensor_dict<'py>(py: Python<'py>, reading: &SensorReading) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let n = reading.points.len();
    let rows = |f: &dyn Fn(&prism_render::sensor::PointReading) -> [f64; 3]| {
        let flat: Vec<f64> = reading.points.iter().flat_map(f).collect();
        Array2::from_shape_vec((n, 3), flat).map_err(|e| argument(e.to_string()))
    };
    let u = reading.uniformity();
    let uniformity = PyDict::new(py);
    uniformity.set_item("min_lx", u.min_lx)?;
    uniformity.set_item("max_lx", u.max_lx)?;
    uniformity.set_item("average_lx", u.average_lx)?;
    uniformity.set_item("min_over_average", u.min_over_average)?;
    uniformity.set_item("min_over_max", u.min_over_max)?;
    out.set_item("name", &reading.name)?;
    out.set_item("grid_resolution", reading.grid_resolution)?;
    out.set_item("uniformity", uniformity)?;
    out.set_item("position_m", rows(&|p| p.position_m)?.into_pyarray(py))?;
    out.set_item("normal", rows(&|p| p.normal)?.into_pyarray(py))?;
    let column = |f: &dyn Fn(&prism_render::sensor::PointReading) -> f64| {
        reading
            .points
            .iter()
            .map(f)
            .collect::<Vec<f64>>()
            .into_pyarray(py)
    };
    out.set_item("illuminance_lx", column(&|p| p.illuminance_lx))?;
    out.set_item("std_error_lx", column(&|p| p.std_error_lx))?;
    out.set_item(
        "samples",
        reading
            .points
            .iter()
            .map(|p| p.samples)
            .collect::<Vec<u64>>()
            .into_pyarray(py),
    )?;
    Ok(out)
}

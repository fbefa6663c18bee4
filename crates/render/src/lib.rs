//! prism-render: cameras, samplers, film, scene building (description → geometry, camera,
//! film, materials, lights), BSDFs, emitters, the render plan, the spectral path tracer and
//! the diagnostic integrators, and the `ShadingProbe` the bandwidth predictor uses. Media
//! follow.
//!
//! Conventions (docs/architecture.md, "Units and conventions"): metres, radians, right-handed with Y up.
//! Camera space looks down −Z with +X right and +Y up (`prism_geometry::Transform::look_at`).
//! Film coordinates are in pixels, continuous: (0, 0) is the top-left corner of the top-left
//! pixel, x grows right and y grows down, pixel (i, j) covers [i, i+1) × [j, j+1) and its
//! centre is (i + ½, j + ½) (pbrt-v4 §5.4 "Film and imaging", discrete vs continuous pixel
//! coordinates, §8.1.4).

pub mod adaptive;
pub mod bsdf;
pub mod bsdf_angular_table;
pub mod bsdf_table_cache;
pub mod camera;
pub mod enclosure;
pub mod error;
pub mod file_error;
pub mod film;
pub mod integrator;
pub mod light;
pub mod material;
pub mod medium;
mod medium_interfaces;
pub mod plan;
pub mod predictor;
pub mod probe;
pub mod sampler;
pub mod sampling;
pub mod scene_build;
pub mod sensor;
pub mod spectrum_cache;
pub mod stable_hash;
pub mod stats_json;
pub mod texture;
pub mod tile_pyramid;

pub use camera::{
    ApertureSpec, Camera, CameraFrame, CameraImportance, CameraModel, CameraWiSample,
    FisheyeCamera, FisheyeCoverage, FisheyeProjection, FocalSpec, OrthographicCamera,
    PinholeCamera, SphericalCamera, ThinLensCamera,
};
pub use error::InvalidParameter;
pub use film::{
    AovPlane, AovSelection, Film, FilmImage, FilmSums, FilmTile, Filter, FilterSample,
    FilterSampler, SpectralBins, SpectralPlanes, SurfaceAov, TileBounds,
};
pub use integrator::{
    film_for, render, render_pass, render_pass_controlled, render_pass_with, render_plan,
    total_samples, Estimator, Integrator, PassControl, PassOutcome, RenderError, RenderSettings,
    RenderStats,
};
pub use plan::{PlanChoice, PlanRequest, RenderPlan, SamplePlanKind};
pub use sampler::{PixelSampler, SampleStream, SamplerKind};
pub use scene_build::{RenderScene, SceneBuildError};

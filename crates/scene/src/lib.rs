//! prism-scene: the JSON scene format. `load_scene` reads a file, checks every field and
//! value, resolves and loads assets, and returns a `SceneDescription` of plain data for
//! render. Errors name the file, line:column, the JSON path and what was expected; the
//! format is documented in docs/scene-format.md.

pub mod camera;
pub mod daylight;
pub mod error;
pub mod film;
pub mod integrator;
mod json;
pub mod light;
pub mod material;
pub mod medium;
pub mod photometric;
mod reader;
pub mod reradiation;
pub mod scene;
pub mod schema;
pub mod sensor;
pub mod shape;
pub mod spectrum_ref;
pub mod texture;
pub mod tile;
pub mod transform;

pub use camera::{Camera, CameraKind, FisheyeFit, FisheyeProjection, FovAxis};
pub use daylight::{DateTime, DaylightSky, SkyModel, SkyNormalisation, SunPosition};
pub use error::{JsonPath, PathSegment, Position, SceneError};
pub use film::{Aov, Film, PixelFilter, Reconstruction};
pub use integrator::{
    FluorescenceLanes, Integrator, MisHeuristic, PhotonRadius, SamplerKind, DEFAULT_PHOTON_ALPHA,
};
pub use light::{EnvironmentFilter, Light, LightKind, Strength};
pub use material::{
    ConductorOptics, Ior, LafortuneLobe, LibraryKind, Material, MaterialKind, Microfacet, Roughness,
};
pub use medium::{Medium, MediumFluorescence, MediumKind, Phase, MEDIUM_TYPES, PHASE_TYPES};
pub use reradiation::{Reradiation, ReradiationKind};
pub use scene::{load_scene, parse_scene_str, SceneDescription};
pub use sensor::{Sensor, SensorKind, SensorSampling};
pub use shape::{MeshAsset, MeshFormat, Shape, ShapeKind};
pub use spectrum_ref::SpectrumRef;
pub use texture::{
    ImageChannel, ImageEncoding, ImageTexture, NoiseKind, NoiseSpace, NoiseTexture, SpectrumParam,
    Texture, TextureFilter, TextureKind, UvTransform, WrapMode,
};
pub use tile::Tile;
pub use transform::Transform;

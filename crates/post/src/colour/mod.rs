//! White balance and gamut mapping on slices of linear RGB pixels
//! (`&mut [[f32; 3]]` in a given [`RgbColorSpace`](prism_spectrum::rgb_space::RgbColorSpace)),
//! so that it plugs into any image type.
//!
//! Pipeline position (docs/architecture.md, "The data flow"): white balance ──► gamut mapping ──► tone operator.
//! See docs/gamut-and-white-balance.md for the methods, parameters, references and CLI syntax.

pub mod aces_rgc;
pub mod cielab_lch;
pub mod error;
pub mod gamut;
pub mod oklab;
pub mod scene_illumination;
pub mod white_balance;

pub use error::PostColourError;
pub use gamut::{map_gamut, map_gamut_to_space, GamutMethod, GamutReport, GamutTarget};
pub use scene_illumination::{illumination_white_xyz, ILLUMINATION_LAYER};
pub use white_balance::{
    apply as apply_white_balance, apply_with_source_white, estimate_source_white_xyz, SceneWhite,
    WhiteBalance, WhiteBalanceReport,
};

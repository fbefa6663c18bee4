//! prism-image: the image type shared by the renderer and the post-processing toolkit, and
//! every image file it reads or writes: OpenEXR (RGB, AOV layers, the spectral layout of
//! Fichet et al. 2021), Radiance RGBE and PNG. prism-render reads textures and environment
//! maps through it, prism-post tone-maps and compares its images, the CLI writes renders
//! with it; it depends on prism-spectrum only, so none of them depends on another for I/O.

pub mod error;
pub mod image;
pub mod io;
pub mod rgb_matrix;

pub use error::{ImageError, Result};
pub use image::{AovLayer, Image};

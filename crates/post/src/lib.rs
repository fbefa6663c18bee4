//! prism-post: the image type, EXR (RGB, AOV layers, spectral layout of Fichet et al. 2021),
//! Radiance RGBE and PNG I/O, tone operators and image metrics.
//!
//! File pipeline (`tonemap_file`): read → exposure → white balance → tone operator →
//! gamut mapping → display encoding.

pub mod auto_exposure;
pub mod colour;
pub mod error;
pub mod falsecolour;
pub mod image;
pub mod io;

pub use error::{PostError, Result};
pub use image::{AovLayer, Image};
pub mod metrics;
pub mod pipeline;
pub mod sheet;
pub mod tonemap;

pub use metrics::{compare, compare_with, CompareOptions, Comparison};
pub use pipeline::{
    compare_files, tonemap_file, OperatorChoice, TonemapFileReport, TonemapOptions, TonemapTimings,
};
pub use sheet::{contact_sheet, contact_sheet_with_reports, ContactSheet};
pub use tonemap::{ToneOperator, ToneParams, ToneReport, ToneResult};

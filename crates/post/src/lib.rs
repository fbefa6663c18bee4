//! prism-post: tone operators, white balance and gamut mapping, image metrics, false colour
//! and contact sheets, on the image type of prism-image (which also reads and writes the
//! files, and whose error type these operations return).
//!
//! File pipeline (`tonemap_file`): read → exposure → white balance → tone operator →
//! gamut mapping → display encoding.

pub mod auto_exposure;
pub mod colour;
pub mod falsecolour;
pub mod metrics;
pub mod pipeline;
pub mod report;
pub mod sheet;
pub mod tonemap;

pub use metrics::{compare, compare_with, CompareOptions, Comparison};
pub use pipeline::{
    compare_files, compare_files_with, tmqi_files, tonemap_file, OperatorChoice, TonemapFileReport,
    TonemapOptions, TonemapTimings,
};
pub use sheet::{contact_sheet, contact_sheet_with_reports, ContactSheet};
pub use tonemap::{ToneOperator, ToneParams, ToneReport, ToneResult};

//! prism-spectrum: wavelengths, spectra, CIE observers and illuminants, colorimetry,
//! RGB colour spaces, chromatic adaptation, RGB→spectrum upsampling (Jakob & Hanika 2019)
//! and re-radiation (Donaldson) matrices for fluorescence.
//!
//! Units: wavelengths in nm, spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹, luminance in cd/m².

pub mod adaptation;
pub mod bfc;
pub mod blackbody;
pub mod cct;
pub mod color_report;
pub mod colorimetry;
pub mod constants;
pub mod data;
pub mod daylight;
pub mod dye;
pub mod embedded_files;
pub mod error;
pub mod names;
pub mod photometry;
pub mod reradiation;
pub mod rgb_space;
pub mod rgb_upsample;
pub mod rgb_wavelength_density;
pub mod sampled_spectrum;
pub mod sampled_wavelengths;
pub mod spectrum;
pub mod spectrum_file;
pub mod table;
pub mod xyz_weights;

pub use adaptation::{adaptation_matrix, AdaptationMethod};
pub use bfc::{load_bfc, parse_bfc, BfcData, NegativesPolicy};
pub use cct::{cct_to_uv_ohno2013, uv_to_cct_ohno2013, xyz_to_cct_ohno2013, CctDuv};
pub use constants::*;
pub use data::Observer;
pub use dye::{Dye, EmissionUnits};
pub use error::SpectrumFileError;
pub use reradiation::{ReradiationError, ReradiationMatrix, WavelengthGrid};
pub use rgb_upsample::{
    RgbAlbedoSpectrum, RgbGamut, RgbIlluminantSpectrum, RgbToSpectrumTable, RgbUnboundedSpectrum,
    RgbUpsampleError, SigmoidPolynomial,
};
pub use sampled_spectrum::{SampledSpectrum, N_SPECTRUM_SAMPLES};
pub use sampled_wavelengths::{SampledWavelengths, WavelengthDensity};
pub use spectrum::{DenseTable, InvalidSpectrum, PiecewiseLinear, Spectrum};
pub use table::{DenseSpectrum, Tabulated};
pub use xyz_weights::XyzWeights;

//! prism-spectrum: wavelengths, spectra, CIE observers and illuminants, colorimetry,
//! RGB colour spaces, chromatic adaptation, RGB→spectrum upsampling (Jakob & Hanika 2019)
//! and re-radiation (Donaldson) matrices for fluorescence.
//!
//! Units: wavelengths in nm, spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹, luminance in cd/m².

pub mod constants;
pub mod data;
pub mod error;
pub mod spectrum_file;
pub mod table;

pub use constants::*;
pub use error::SpectrumFileError;
pub use table::{DenseSpectrum, Tabulated};
pub mod embedded_files;
pub mod names;
pub mod rgb_space;
pub use data::Observer;
pub mod rgb_upsample;
pub use rgb_upsample::{
    RgbAlbedoSpectrum, RgbGamut, RgbIlluminantSpectrum, RgbToSpectrumTable, RgbUnboundedSpectrum,
    RgbUpsampleError, SigmoidPolynomial,
};

//! The one error type of this crate: what was being built or looked up, and what was
//! expected (house rule: no panics on input).

use std::fmt;

use glam::UVec2;

/// Why a G-buffer, sample plan or bandwidth value was rejected.
#[derive(Clone, Debug, PartialEq)]
pub enum BandwidthError {
    /// A buffer of zero width or height.
    ZeroResolution {
        /// What was being built, e.g. "G-buffer".
        what: &'static str,
    },
    /// A per-pixel list whose length is not width × height.
    LengthMismatch {
        what: &'static str,
        resolution: UVec2,
        found: usize,
    },
    /// Two buffers (or a buffer and a film) that should have the same resolution.
    ResolutionMismatch {
        what: &'static str,
        expected: UVec2,
        found: UVec2,
    },
    /// A pixel outside the buffer.
    PixelOutside {
        what: &'static str,
        pixel: UVec2,
        resolution: UVec2,
    },
    /// A value outside its valid range.
    InvalidValue {
        /// What was being built, e.g. "G-buffer hit".
        context: &'static str,
        /// The parameter with its unit, e.g. `depth_m`.
        parameter: &'static str,
        /// The offending value, formatted.
        value: String,
        /// The valid range in words.
        valid: &'static str,
    },
}

impl BandwidthError {
    pub(crate) fn invalid(
        context: &'static str,
        parameter: &'static str,
        value: impl fmt::Debug,
        valid: &'static str,
    ) -> Self {
        Self::InvalidValue {
            context,
            parameter,
            value: format!("{value:?}"),
            valid,
        }
    }
}

impl fmt::Display for BandwidthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZeroResolution { what } => {
                write!(f, "{what}: the resolution must be at least 1×1 pixel")
            }
            Self::LengthMismatch {
                what,
                resolution,
                found,
            } => write!(
                f,
                "{what}: a {}×{} buffer needs {} entries (one per pixel), got {found}",
                resolution.x,
                resolution.y,
                u64::from(resolution.x) * u64::from(resolution.y)
            ),
            Self::ResolutionMismatch {
                what,
                expected,
                found,
            } => write!(
                f,
                "{what}: resolution {}×{} does not match the expected {}×{}",
                found.x, found.y, expected.x, expected.y
            ),
            Self::PixelOutside {
                what,
                pixel,
                resolution,
            } => write!(
                f,
                "{what}: pixel ({}, {}) is outside the {}×{} buffer",
                pixel.x, pixel.y, resolution.x, resolution.y
            ),
            Self::InvalidValue {
                context,
                parameter,
                value,
                valid,
            } => write!(
                f,
                "{context}: `{parameter}` = {value} is invalid; valid: {valid}"
            ),
        }
    }
}

impl std::error::Error for BandwidthError {}

/// Row-major index of `pixel` in a buffer of `resolution`, or an error naming `what`.
pub(crate) fn pixel_index(
    what: &'static str,
    pixel: UVec2,
    resolution: UVec2,
) -> Result<usize, BandwidthError> {
    if pixel.x < resolution.x && pixel.y < resolution.y {
        Ok(pixel.y as usize * resolution.x as usize + pixel.x as usize)
    } else {
        Err(BandwidthError::PixelOutside {
            what,
            pixel,
            resolution,
        })
    }
}

/// Width × height of a resolution that must be at least 1×1.
/// Every per-pixel list (name, length) is as long as the image (`n` pixels), else the
/// first that is not, by name.
pub(crate) fn check_lengths(
    resolution: UVec2,
    n: usize,
    lists: &[(&'static str, usize)],
) -> Result<(), BandwidthError> {
    match lists.iter().find(|(_, len)| *len != n) {
        Some(&(what, found)) => Err(BandwidthError::LengthMismatch {
            what,
            resolution,
            found,
        }),
        None => Ok(()),
    }
}

pub(crate) fn pixel_count(what: &'static str, resolution: UVec2) -> Result<usize, BandwidthError> {
    if resolution.x == 0 || resolution.y == 0 {
        return Err(BandwidthError::ZeroResolution { what });
    }
    Ok(resolution.x as usize * resolution.y as usize)
}

//! White balance: estimate the white of the scene illuminant from the image (or take it
//! from a named CIE illuminant or a colour temperature) and adapt every pixel from it to
//! the RGB space's own white with a chromatic adaptation transform of prism-spectrum
//! (full adaptation, D = 1).
//!
//! Only the chromaticity of the estimated white is used: it is normalised to Y = 1, so
//! exposure is left to the tone operator.
//!
//! CLI syntax (`--wb`), case-insensitive:
//! - `none` (default): pixels untouched.
//! - `grey-world` (or `gray-world`): the mean colour of all finite pixels is taken as
//!   grey (Buchsbaum 1980).
//! - `white-patch`: the brightest pixel (highest luminance Y; the mean of ties) is white
//!   (Land & McCann 1971, "max-RGB" in luminance form).
//! - `white-patch:P`, 0 < P ≤ 100: the mean colour of the pixels whose luminance is at or
//!   above the P-th percentile (nearest rank) is white; robust to a few clipped highlights.
//! - `illuminant:NAME` or a bare CIE name (`A`, `D50`, `F11`, `LED-B3`, …): the white of
//!   that illuminant, CIE 1931 2° observer (CIE 15:2018 §7).
//! - `cct:T` (T in kelvin, 1000–25000, optional `K`): below 4000 K the Planckian locus
//!   (prism-spectrum's Planck integration, c₂ = 1.4388 × 10⁻² m·K); from 4000 K the CIE
//!   daylight locus, as the CIE D-series illuminants are defined (CIE 15:2004 §3.1,
//!   eqs. 3.3–3.4; CIE 15:2018 §4.1). So `cct:2856` ≈ illuminant A and
//!   `cct:6504` ≈ D65.
//! - `scene`: the white of the light in the scene, from the image's `illumination` layer
//!   (`illumination.X/Y/Z`, written by `prism render`: the light a neutral white surface
//!   reflects at each pixel's first hit), not from its pixels; see `scene_illumination`.
//!   [`estimate_source_white_xyz`] cannot see layers, so it refuses `scene`: estimate with
//!   `scene_illumination::illumination_white_xyz` and apply with [`apply_with_source_white`].

use std::fmt;
use std::str::FromStr;

use glam::{DMat3, DVec2, DVec3};
use prism_spectrum::cct::{cct_to_uv_ohno2013, xyz_to_cct_ohno2013, CctDuv};
use prism_spectrum::colorimetry::{illuminant_white_xyz, uv_1960_to_xy, xyz_to_xy};
use prism_spectrum::data::{
    canonical_illuminant_name, illuminant, illuminant_suggestion, ILLUMINANT_NAMES,
};
use prism_spectrum::names::did_you_mean;
use prism_spectrum::rgb_space::{xy_to_xyz_unit_y, RgbColorSpace};
use prism_spectrum::{adaptation_matrix, AdaptationMethod, Observer};
use rayon::prelude::*;

use crate::colour::error::PostColourError;
use prism_image::rgb_matrix::{apply_rgb_matrix, CHUNK_PIXELS};

/// Lowest colour temperature accepted by `cct:` in K (the Planckian table's start).
pub const WB_CCT_MIN_K: f64 = 1000.0;
/// Highest colour temperature accepted by `cct:` in K (the daylight locus' end, CIE 15).
pub const WB_CCT_MAX_K: f64 = 25_000.0;
/// From this temperature in K the daylight locus is used instead of the Planckian one.
pub const DAYLIGHT_LOCUS_MIN_K: f64 = 4000.0;

/// The forms `--wb` accepts, for error messages.
pub const WHITE_BALANCE_SYNTAX: &str = "none, grey-world (or gray-world), white-patch, \
     white-patch:<percentile 0–100>, illuminant:<CIE name> or a bare CIE name (A, D50, F11, …), \
     cct:<kelvin 1000–25000>, scene (the illumination layer of a `prism render` EXR)";

/// How the scene white is found.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum WhiteBalance {
    /// No white balance (pixels untouched; the CLI default).
    #[default]
    None,
    /// Mean colour of the image is grey.
    GreyWorld,
    /// Brightest pixel (by luminance) is white.
    WhitePatchMax,
    /// Mean of the pixels at or above this luminance percentile (0 < P ≤ 100) is white.
    WhitePatchPercentile(f32),
    /// White of a CIE illuminant, by its canonical name (e.g. `A`, `D50`, `F11`).
    Illuminant(String),
    /// White at a colour temperature in K (Planckian below 4000 K, daylight from 4000 K).
    Cct(f64),
    /// The scene illuminant's white from the image's `illumination` layer.
    Scene,
}

fn invalid(given: &str, message: String) -> PostColourError {
    PostColourError::InvalidValue {
        option: "--wb",
        given: given.to_string(),
        message,
    }
}

impl WhiteBalance {
    /// Parses a `--wb` value (syntax in the module documentation); never panics.
    pub fn parse(value: &str) -> Result<Self, PostColourError> {
        let trimmed = value.trim();
        let lower = trimmed.to_ascii_lowercase();
        match lower.as_str() {
            "none" => return Ok(Self::None),
            "grey-world" | "gray-world" => return Ok(Self::GreyWorld),
            "white-patch" => return Ok(Self::WhitePatchMax),
            "scene" => return Ok(Self::Scene),
            _ => {}
        }
        if let Some((key, argument)) = trimmed.split_once(':') {
            let argument = argument.trim();
            return match key.trim().to_ascii_lowercase().as_str() {
                "white-patch" => parse_percentile(value, argument),
                "illuminant" => parse_illuminant(value, argument),
                "cct" => parse_cct(value, argument),
                other => Err(invalid(
                    value,
                    format!(
                        "unknown white-balance method `{other}`; valid: {WHITE_BALANCE_SYNTAX}{}",
                        did_you_mean(other, ["white-patch", "illuminant", "cct"])
                    ),
                )),
            };
        }
        if let Some(name) = canonical_illuminant_name(trimmed) {
            return Ok(Self::Illuminant(name.to_string()));
        }
        let candidates = ["none", "grey-world", "gray-world", "white-patch", "scene"]
            .into_iter()
            .chain(ILLUMINANT_NAMES.iter().copied());
        Err(invalid(
            value,
            format!(
                "unknown white-balance method; valid: {WHITE_BALANCE_SYNTAX}{}",
                did_you_mean(trimmed, candidates)
            ),
        ))
    }

    /// The canonical CLI form; [`WhiteBalance::parse`] gives back the same value.
    pub fn name(&self) -> String {
        match self {
            Self::None => "none".into(),
            Self::GreyWorld => "grey-world".into(),
            Self::WhitePatchMax => "white-patch".into(),
            Self::WhitePatchPercentile(p) => format!("white-patch:{p}"),
            Self::Illuminant(name) => format!("illuminant:{name}"),
            Self::Cct(t) => format!("cct:{t}"),
            Self::Scene => "scene".into(),
        }
    }
}

fn parse_percentile(value: &str, argument: &str) -> Result<WhiteBalance, PostColourError> {
    let number = argument.strip_suffix('%').unwrap_or(argument).trim();
    match number.parse::<f32>() {
        Ok(p) if p > 0.0 && p <= 100.0 => Ok(WhiteBalance::WhitePatchPercentile(p)),
        _ => Err(invalid(
            value,
            format!(
                "white-patch percentile must be a number in (0, 100], e.g. white-patch:99; \
                 got `{argument}`"
            ),
        )),
    }
}

fn parse_illuminant(value: &str, argument: &str) -> Result<WhiteBalance, PostColourError> {
    match canonical_illuminant_name(argument) {
        Some(name) => Ok(WhiteBalance::Illuminant(name.to_string())),
        None => Err(invalid(
            value,
            format!(
                "unknown CIE illuminant `{argument}`; known: {}{}",
                ILLUMINANT_NAMES.join(", "),
                illuminant_suggestion(argument)
            ),
        )),
    }
}

fn parse_cct(value: &str, argument: &str) -> Result<WhiteBalance, PostColourError> {
    let number = argument.strip_suffix(['K', 'k']).unwrap_or(argument).trim();
    match number.parse::<f64>() {
        Ok(t) if (WB_CCT_MIN_K..=WB_CCT_MAX_K).contains(&t) => Ok(WhiteBalance::Cct(t)),
        _ => Err(invalid(
            value,
            format!(
                "colour temperature must be a number of kelvin in [{WB_CCT_MIN_K}, \
                 {WB_CCT_MAX_K}], e.g. cct:3200; got `{argument}`"
            ),
        )),
    }
}

impl fmt::Display for WhiteBalance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl FromStr for WhiteBalance {
    type Err = PostColourError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse(s)
    }
}

/// CIE 1931 xy of the CIE daylight locus at `cct_k` (CIE 15:2004 eqs. 3.3–3.4,
/// 15:2018 §4.1): x_D is a cubic in 1/T (one set of coefficients for 4000–7000 K, another
/// for 7000–25 000 K) and y_D = −3.000 x_D² + 2.870 x_D − 0.275. `None` outside
/// 4000–25 000 K.
pub fn daylight_locus_xy(cct_k: f64) -> Option<DVec2> {
    if !(DAYLIGHT_LOCUS_MIN_K..=WB_CCT_MAX_K).contains(&cct_k) {
        return None;
    }
    let t = cct_k;
    let x = if t <= 7000.0 {
        -4.6070e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.237040
    };
    Some(DVec2::new(x, -3.000 * x * x + 2.870 * x - 0.275))
}

/// CIE 1931 XYZ (Y = 1) of the white at `cct_k`: the Planckian locus below 4000 K (via
/// prism-spectrum's `cct_to_uv_ohno2013(T, 0)`), the daylight locus from 4000 K to 25 000 K.
/// `None` outside 1000–25 000 K or for non-finite input.
pub fn cct_white_xyz(cct_k: f64) -> Option<DVec3> {
    if !(WB_CCT_MIN_K..=WB_CCT_MAX_K).contains(&cct_k) {
        return None;
    }
    let xy = if cct_k < DAYLIGHT_LOCUS_MIN_K {
        uv_1960_to_xy(cct_to_uv_ohno2013(cct_k, 0.0)?)?
    } else {
        daylight_locus_xy(cct_k)?
    };
    Some(xy_to_xyz_unit_y(xy.x, xy.y))
}

/// CIE 1931 XYZ (Y = 1) of a named CIE illuminant's white. `None` for an unknown name.
pub fn illuminant_white_xyz_unit_y(name: &str) -> Option<DVec3> {
    let spd = illuminant(name)?.to_dense();
    let white = illuminant_white_xyz(&spd, Observer::Cie1931);
    (white.y > 0.0).then(|| white / white.y)
}

/// An estimated scene white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneWhite {
    /// CIE 1931 XYZ normalised to Y = 1.
    pub xyz: DVec3,
    /// Pixels the estimate was taken from (0 for `none`, `illuminant:` and `cct:`).
    pub pixels_used: usize,
}

/// Estimates the white of the scene illuminant for `method` from linear RGB `pixels` in
/// `space`. Non-finite pixels are ignored. `none` gives the space's own white.
pub fn estimate_source_white_xyz(
    pixels: &[[f32; 3]],
    space: &RgbColorSpace,
    method: &WhiteBalance,
) -> Result<SceneWhite, PostColourError> {
    let no_white = |reason: &str| PostColourError::NoSceneWhite {
        method: method.name(),
        reason: reason.to_string(),
    };
    let luminance_row = space.rgb_to_xyz.row(1);
    let luminance = |p: &[f32; 3]| luminance_row.dot(to_dvec3(p));
    let (rgb_sum, pixels_used) = match method {
        WhiteBalance::None => {
            return Ok(SceneWhite {
                xyz: space.white_xyz(),
                pixels_used: 0,
            })
        }
        WhiteBalance::Illuminant(name) => {
            let xyz = illuminant_white_xyz_unit_y(name).ok_or_else(|| {
                invalid(
                    &method.name(),
                    format!(
                        "unknown CIE illuminant `{name}`{}",
                        illuminant_suggestion(name)
                    ),
                )
            })?;
            return Ok(SceneWhite {
                xyz,
                pixels_used: 0,
            });
        }
        WhiteBalance::Cct(cct_k) => {
            let xyz = cct_white_xyz(*cct_k).ok_or_else(|| {
                invalid(
                    &method.name(),
                    format!("colour temperature must be in [{WB_CCT_MIN_K}, {WB_CCT_MAX_K}] K"),
                )
            })?;
            return Ok(SceneWhite {
                xyz,
                pixels_used: 0,
            });
        }
        WhiteBalance::Scene => {
            return Err(no_white(
                "`scene` takes the white from the image's illumination layer, not from its \
                 pixels (scene_illumination::illumination_white_xyz)",
            ))
        }
        WhiteBalance::GreyWorld => sum_where(pixels, |_| true),
        WhiteBalance::WhitePatchMax => {
            let max = pixels
                .par_chunks(CHUNK_PIXELS)
                .map(|chunk| {
                    chunk
                        .iter()
                        .filter(|p| is_finite(p))
                        .map(luminance)
                        .fold(f64::NEG_INFINITY, f64::max)
                })
                .reduce(|| f64::NEG_INFINITY, f64::max);
            if max == f64::NEG_INFINITY {
                return Err(no_white("no finite pixel"));
            }
            sum_where(pixels, |p| luminance(p) >= max)
        }
        WhiteBalance::WhitePatchPercentile(percentile) => {
            if !(*percentile > 0.0 && *percentile <= 100.0) {
                return Err(invalid(
                    &method.name(),
                    "white-patch percentile must be in (0, 100]".to_string(),
                ));
            }
            let mut values: Vec<f64> = pixels
                .par_iter()
                .filter(|p| is_finite(p))
                .map(luminance)
                .collect();
            if values.is_empty() {
                return Err(no_white("no finite pixel"));
            }
            // Nearest-rank percentile: the ⌈P/100 · n⌉-th smallest luminance.
            let n = values.len();
            let rank = ((f64::from(*percentile) / 100.0 * n as f64).ceil() as usize).clamp(1, n);
            let (_, threshold, _) = values.select_nth_unstable_by(rank - 1, f64::total_cmp);
            let threshold = *threshold;
            sum_where(pixels, |p| luminance(p) >= threshold)
        }
    };
    if pixels_used == 0 {
        return Err(no_white("no finite pixel"));
    }
    let xyz = space.rgb_to_xyz * (rgb_sum / pixels_used as f64);
    if !(xyz.x > 0.0 && xyz.y > 0.0 && xyz.z > 0.0 && xyz.is_finite()) {
        return Err(no_white(&format!(
            "the estimate XYZ ({:.4}, {:.4}, {:.4}) is not a positive colour",
            xyz.x, xyz.y, xyz.z
        )));
    }
    Ok(SceneWhite {
        xyz: xyz / xyz.y,
        pixels_used,
    })
}

#[inline]
fn to_dvec3(p: &[f32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

#[inline]
fn is_finite(p: &[f32; 3]) -> bool {
    p.iter().all(|c| c.is_finite())
}

/// Sum of the finite pixels that pass `keep`, and their count. Chunk sums are added in
/// chunk order, so the result does not depend on the thread count.
fn sum_where(pixels: &[[f32; 3]], keep: impl Fn(&[f32; 3]) -> bool + Sync) -> (DVec3, usize) {
    let partial: Vec<(DVec3, usize)> = pixels
        .par_chunks(CHUNK_PIXELS)
        .map(|chunk| {
            chunk
                .iter()
                .filter(|p| is_finite(p) && keep(p))
                .fold((DVec3::ZERO, 0), |(s, n), p| (s + to_dvec3(p), n + 1))
        })
        .collect();
    partial
        .into_iter()
        .fold((DVec3::ZERO, 0), |(s, n), (ps, pn)| (s + ps, n + pn))
}

/// What white balance estimated and did.
#[derive(Debug, Clone, PartialEq)]
pub struct WhiteBalanceReport {
    /// The method in its CLI form.
    pub method: String,
    /// The chromatic adaptation transform used.
    pub adaptation: AdaptationMethod,
    /// Estimated scene white, CIE 1931 XYZ with Y = 1.
    pub source_white_xyz: [f64; 3],
    /// Its CIE 1931 chromaticity.
    pub source_white_xy: [f64; 2],
    /// Its CCT and Duv (Ohno 2013), when defined.
    pub source_cct: Option<CctDuv>,
    /// The RGB space's white it was adapted to, XYZ with Y = 1.
    pub destination_white_xyz: [f64; 3],
    /// The RGB → RGB matrix applied to every pixel, row-major.
    pub rgb_matrix: [[f64; 3]; 3],
    /// Pixels the estimate was taken from (0 for manual methods and `none`).
    pub pixels_used: usize,
}

/// White-balances `pixels` (linear RGB in `space`) in place: estimates the scene white
/// with `method` and applies `space.xyz_to_rgb · CAT(scene white → space white) ·
/// space.rgb_to_xyz`. `WhiteBalance::None` leaves the pixels bit-for-bit untouched.
/// Errors (never panics) when the white cannot be estimated; then pixels are untouched.
pub fn apply(
    pixels: &mut [[f32; 3]],
    space: &RgbColorSpace,
    method: &WhiteBalance,
    adaptation: AdaptationMethod,
) -> Result<WhiteBalanceReport, PostColourError> {
    let scene = estimate_source_white_xyz(pixels, space, method)?;
    Ok(apply_with_source_white(
        pixels, space, method, scene, adaptation,
    ))
}

/// White-balances `pixels` from an already estimated scene white `scene` (e.g. from the
/// illumination layer for `scene`) to the space's white, as [`apply`] does after its
/// estimate; `method` is reported (and `None` leaves the pixels untouched).
pub fn apply_with_source_white(
    pixels: &mut [[f32; 3]],
    space: &RgbColorSpace,
    method: &WhiteBalance,
    scene: SceneWhite,
    adaptation: AdaptationMethod,
) -> WhiteBalanceReport {
    let destination = space.white_xyz();
    let matrix = if *method == WhiteBalance::None {
        DMat3::IDENTITY
    } else {
        space.xyz_to_rgb * adaptation_matrix(adaptation, scene.xyz, destination) * space.rgb_to_xyz
    };
    if matrix != DMat3::IDENTITY {
        apply_rgb_matrix(pixels, matrix);
    }
    let xy = xyz_to_xy(scene.xyz).unwrap_or(DVec2::ZERO);
    let rows = matrix.transpose().to_cols_array_2d();
    WhiteBalanceReport {
        method: method.name(),
        adaptation,
        source_white_xyz: scene.xyz.to_array(),
        source_white_xy: xy.to_array(),
        source_cct: xyz_to_cct_ohno2013(scene.xyz),
        destination_white_xyz: destination.to_array(),
        rgb_matrix: rows,
        pixels_used: scene.pixels_used,
    }
}

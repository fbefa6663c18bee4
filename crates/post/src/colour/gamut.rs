//! Gamut mapping of linear RGB pixels into the unit cube of a display space (sRGB,
//! Display P3 or Rec.2020). Pixels come in a source space, are converted through CIE 1931
//! XYZ (with a chromatic adaptation transform when the whites differ) and leave as linear
//! RGB of the target space with every channel in [0, 1].
//!
//! A pixel is *outside* when, after conversion to the target, a channel is below 0, above 1
//! or not finite. Non-finite channels are clipped by every method (NaN → 0, +∞ → 1, −∞ → 0).
//!
//! Methods (docs/gamut-and-white-balance.md):
//! - [`GamutMethod::Clip`]: each channel clipped to [0, 1].
//! - [`GamutMethod::LocalLch`] / [`GamutMethod::LocalOklab`]: only outside pixels move, to
//!   the gamut boundary at constant lightness and hue, by bisection on chroma in CIELAB
//!   LCh (relative to the target white, Y = 1 ↔ L* = 100) or in Oklab (Ottosson 2020).
//!   Lightness outside [0, L_white] is clipped first (a colour brighter than white or
//!   darker than black has no in-gamut chroma at its own lightness), so such pixels become
//!   white or black.
//! - [`GamutMethod::GlobalChroma`]: one factor k ≤ 1 scales the CIELAB chroma of every
//!   pixel (a, b ← k·a, k·b at constant L*, h), with k the largest that brings every
//!   outside pixel inside. Chroma ratios, hence the ordering of chroma, are preserved.
//! - [`GamutMethod::AcesRgc`]: ACES Reference Gamut Compression 1.0 in ACEScg
//!   ([`crate::colour::aces_rgc`]) applied to every pixel as the reference does, then converted
//!   to the target and clipped (the RGC only compresses into AP1).

use std::fmt;
use std::str::FromStr;

use glam::{DMat3, DVec2, DVec3};
use prism_spectrum::names::did_you_mean;
use prism_spectrum::rgb_space::RgbColorSpace;
use prism_spectrum::AdaptationMethod;
use rayon::prelude::*;

use crate::colour::aces_rgc::{aces_rgc_acescg, AcesRgcParameters};
use crate::colour::cielab_lch::{CielabConverter, CIELAB_L_WHITE};
use crate::colour::error::PostColourError;
use crate::colour::oklab::OklabConverter;
use prism_image::rgb_matrix::{mul, rgb_to_rgb_matrix, same_colorimetry, to_pixel, CHUNK_PIXELS};

/// Bisection stops when the chroma interval is below this, in CIELAB C*ab units
/// (far below a just-noticeable difference, ΔE*ab ≈ 1).
pub const CIELAB_CHROMA_TOLERANCE: f64 = 1e-4;
/// Bisection stops when the chroma interval is below this, in Oklab chroma units
/// (Oklab C spans about 0–0.4 where CIELAB C*ab spans 0–150).
pub const OKLAB_CHROMA_TOLERANCE: f64 = 3e-7;
/// Upper bound on bisection steps (2⁻⁶⁰ of the chroma is far below f64 resolution).
const MAX_BISECTION_STEPS: usize = 60;

/// The display space to map into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GamutTarget {
    Srgb,
    DisplayP3,
    Rec2020,
}

/// `--target` values, in the order error messages list them.
const TARGET_NAMES: &[&str] = &["srgb", "p3", "rec2020"];

impl GamutTarget {
    /// Parses `srgb` (also `rec709`), `p3` (also `display-p3`), `rec2020` (also `bt2020`),
    /// case-insensitive.
    pub fn parse(value: &str) -> Result<Self, PostColourError> {
        match value.trim().to_ascii_lowercase().as_str() {
            "srgb" | "rec709" | "bt709" => Ok(Self::Srgb),
            "p3" | "display-p3" | "displayp3" => Ok(Self::DisplayP3),
            "rec2020" | "bt2020" | "rec.2020" => Ok(Self::Rec2020),
            _ => Err(PostColourError::InvalidValue {
                option: "--target",
                given: value.to_string(),
                message: format!(
                    "unknown target; valid: {}{}",
                    TARGET_NAMES.join(", "),
                    did_you_mean(value.trim(), TARGET_NAMES.iter().copied())
                ),
            }),
        }
    }

    /// The canonical CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Srgb => "srgb",
            Self::DisplayP3 => "p3",
            Self::Rec2020 => "rec2020",
        }
    }

    /// The accepted canonical names.
    pub fn names() -> &'static [&'static str] {
        TARGET_NAMES
    }

    /// The RGB colour space (linear; its transfer function is for display encoding later).
    pub fn space(self) -> RgbColorSpace {
        match self {
            Self::Srgb => RgbColorSpace::srgb(),
            Self::DisplayP3 => RgbColorSpace::display_p3(),
            Self::Rec2020 => RgbColorSpace::rec2020(),
        }
    }
}

impl fmt::Display for GamutTarget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for GamutTarget {
    type Err = PostColourError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse(s)
    }
}

/// How out-of-gamut colours are brought inside.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum GamutMethod {
    /// Per-channel clip to [0, 1] (the CLI default).
    #[default]
    Clip,
    /// Outside pixels to the boundary at constant L* and hue in CIELAB LCh.
    LocalLch,
    /// Outside pixels to the boundary at constant L and hue in Oklab.
    LocalOklab,
    /// One chroma factor for the whole image (CIELAB LCh), ordering of chroma preserved.
    GlobalChroma,
    /// ACES Reference Gamut Compression 1.0, then clip of the residue.
    AcesRgc,
}

/// `--gamut` values, in the order error messages list them.
const METHOD_NAMES: &[&str] = &["clip", "local-lch", "local-oklab", "global", "aces-rgc"];

impl GamutMethod {
    /// Parses `clip`, `local-lch` (also `local`, `lch`), `local-oklab` (also `oklab`),
    /// `global` (also `global-chroma`), `aces-rgc` (also `aces`, `rgc`), case-insensitive.
    pub fn parse(value: &str) -> Result<Self, PostColourError> {
        match value.trim().to_ascii_lowercase().as_str() {
            "clip" => Ok(Self::Clip),
            "local-lch" | "local" | "lch" => Ok(Self::LocalLch),
            "local-oklab" | "oklab" => Ok(Self::LocalOklab),
            "global" | "global-chroma" => Ok(Self::GlobalChroma),
            "aces-rgc" | "aces" | "rgc" => Ok(Self::AcesRgc),
            _ => Err(PostColourError::InvalidValue {
                option: "--gamut",
                given: value.to_string(),
                message: format!(
                    "unknown gamut mapping method; valid: {}{}",
                    METHOD_NAMES.join(", "),
                    did_you_mean(value.trim(), METHOD_NAMES.iter().copied())
                ),
            }),
        }
    }

    /// The canonical CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Clip => "clip",
            Self::LocalLch => "local-lch",
            Self::LocalOklab => "local-oklab",
            Self::GlobalChroma => "global",
            Self::AcesRgc => "aces-rgc",
        }
    }

    /// The accepted canonical names.
    pub fn names() -> &'static [&'static str] {
        METHOD_NAMES
    }
}

impl fmt::Display for GamutMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for GamutMethod {
    type Err = PostColourError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse(s)
    }
}

/// What gamut mapping found and did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GamutReport {
    /// Pixels outside the target gamut before mapping (after conversion to the target).
    pub pixels_outside: usize,
    /// `pixels_outside / pixel_count` (0 for an empty image).
    pub fraction_outside: f64,
    /// Pixels in the slice.
    pub pixel_count: usize,
    /// The chroma factor k applied by [`GamutMethod::GlobalChroma`] (1 for other methods
    /// and when nothing had to move).
    pub chroma_scale: f64,
}

/// True when every channel is in [0, 1] (false for NaN).
#[inline]
pub fn is_inside_unit_cube(rgb: [f32; 3]) -> bool {
    rgb.iter().all(|c| (0.0..=1.0).contains(c))
}

#[inline]
fn is_inside_f64(rgb: DVec3) -> bool {
    rgb.cmpge(DVec3::ZERO).all() && rgb.cmple(DVec3::ONE).all()
}

/// Each channel clipped to [0, 1]; NaN → 0.
#[inline]
pub fn clip_to_unit_cube(rgb: [f32; 3]) -> [f32; 3] {
    rgb.map(|c| if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) })
}

/// Maps `pixels` (linear RGB in `source`) into `target`'s gamut in place; afterwards they
/// are linear RGB of the target space with every channel in [0, 1]. Whites that differ
/// (e.g. an ACEScg source) are adapted with Bradford.
pub fn map_gamut(
    pixels: &mut [[f32; 3]],
    source: &RgbColorSpace,
    target: GamutTarget,
    method: GamutMethod,
) -> GamutReport {
    map_gamut_to_space(
        pixels,
        source,
        &target.space(),
        method,
        AdaptationMethod::Bradford,
    )
}

/// [`map_gamut`] into any RGB space (whose white should be D65 for
/// [`GamutMethod::LocalOklab`]), with a chosen adaptation for differing whites.
pub fn map_gamut_to_space(
    pixels: &mut [[f32; 3]],
    source: &RgbColorSpace,
    target: &RgbColorSpace,
    method: GamutMethod,
    white_adaptation: AdaptationMethod,
) -> GamutReport {
    let conversion = Conversion {
        matrix: (!same_colorimetry(source, target))
            .then(|| rgb_to_rgb_matrix(source, target, white_adaptation)),
    };
    let mut chroma_scale = 1.0;
    let pixels_outside = match method {
        GamutMethod::Clip => par_sum(pixels, |chunk| clip_chunk(chunk, &conversion)),
        GamutMethod::LocalLch => {
            let lab = CielabConverter::new(target);
            par_sum(pixels, |chunk| local_chunk(chunk, &conversion, &lab))
        }
        GamutMethod::LocalOklab => {
            let oklab = OklabConverter::new(target);
            par_sum(pixels, |chunk| local_chunk(chunk, &conversion, &oklab))
        }
        GamutMethod::GlobalChroma => {
            let lab = CielabConverter::new(target);
            let (outside, k) = global_chroma(pixels, &conversion, &lab);
            chroma_scale = k;
            outside
        }
        GamutMethod::AcesRgc => {
            let acescg = RgbColorSpace::acescg();
            let rgc = RgcConversion {
                to_target: conversion,
                source_to_ap1: rgb_to_rgb_matrix(source, &acescg, white_adaptation),
                ap1_to_target: rgb_to_rgb_matrix(&acescg, target, white_adaptation),
                params: AcesRgcParameters::REFERENCE,
            };
            par_sum(pixels, |chunk| aces_rgc_chunk(chunk, &rgc))
        }
    };
    let pixel_count = pixels.len();
    GamutReport {
        pixels_outside,
        fraction_outside: if pixel_count == 0 {
            0.0
        } else {
            pixels_outside as f64 / pixel_count as f64
        },
        pixel_count,
        chroma_scale,
    }
}

/// Source RGB → target RGB (None when the spaces are the same: pixels pass bit-for-bit).
struct Conversion {
    matrix: Option<DMat3>,
}

impl Conversion {
    #[inline]
    fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        match &self.matrix {
            None => rgb,
            Some(m) => to_pixel(mul(m, rgb)),
        }
    }
}

/// Runs `f` on fixed chunks in parallel and sums the counts (deterministic).
fn par_sum(pixels: &mut [[f32; 3]], f: impl Fn(&mut [[f32; 3]]) -> usize + Sync + Send) -> usize {
    pixels.par_chunks_mut(CHUNK_PIXELS).map(f).sum()
}

fn clip_chunk(chunk: &mut [[f32; 3]], conversion: &Conversion) -> usize {
    let mut outside = 0;
    for p in chunk {
        let t = conversion.apply(*p);
        if is_inside_unit_cube(t) {
            *p = t;
        } else {
            outside += 1;
            *p = clip_to_unit_cube(t);
        }
    }
    outside
}

/// A lightness–opponent space (CIELAB or Oklab) tied to the target RGB space.
trait OpponentSpace: Sync {
    fn rgb_to_lab(&self, rgb: DVec3) -> DVec3;
    fn lab_to_rgb(&self, lab: DVec3) -> DVec3;
    /// Lightness of the target white (top of the lightness range).
    fn l_white(&self) -> f64;
    /// Chroma resolution at which bisection stops.
    fn chroma_tolerance(&self) -> f64;
    /// (a, b) of the target space's grey at lightness `l` (the centre chroma shrinks to).
    fn neutral_ab(&self, l: f64) -> DVec2;
}

impl OpponentSpace for CielabConverter {
    #[inline]
    fn rgb_to_lab(&self, rgb: DVec3) -> DVec3 {
        CielabConverter::rgb_to_lab(self, rgb)
    }
    #[inline]
    fn lab_to_rgb(&self, lab: DVec3) -> DVec3 {
        CielabConverter::lab_to_rgb(self, lab)
    }
    fn l_white(&self) -> f64 {
        CIELAB_L_WHITE
    }
    fn chroma_tolerance(&self) -> f64 {
        CIELAB_CHROMA_TOLERANCE
    }
    fn neutral_ab(&self, _l: f64) -> DVec2 {
        // CIELAB is relative to the target white: its greys are exactly a* = b* = 0.
        DVec2::ZERO
    }
}

impl OpponentSpace for OklabConverter {
    #[inline]
    fn rgb_to_lab(&self, rgb: DVec3) -> DVec3 {
        self.rgb_to_oklab(rgb)
    }
    #[inline]
    fn lab_to_rgb(&self, lab: DVec3) -> DVec3 {
        self.oklab_to_rgb(lab)
    }
    fn l_white(&self) -> f64 {
        self.l_white
    }
    fn chroma_tolerance(&self) -> f64 {
        OKLAB_CHROMA_TOLERANCE
    }
    fn neutral_ab(&self, l: f64) -> DVec2 {
        DVec2::new(self.neutral_ab_per_l[0], self.neutral_ab_per_l[1]) * l
    }
}

/// (L, a, b) with its chroma about the space's neutral axis scaled by `s`.
#[inline]
fn scale_chroma<S: OpponentSpace>(space: &S, lab: DVec3, s: f64) -> DVec3 {
    let n = space.neutral_ab(lab.x);
    DVec3::new(lab.x, n.x + (lab.y - n.x) * s, n.y + (lab.z - n.y) * s)
}

/// The largest s in [0, 1] (to the space's chroma tolerance) with the chroma of `lab`
/// scaled by s inside the unit cube, by bisection; s = 0 (the grey of lightness L, inside
/// for L in [0, L_white]) is taken as inside. Returns 1 when `lab` itself is inside.
fn chroma_scale_to_boundary<S: OpponentSpace>(space: &S, lab: DVec3) -> f64 {
    if is_inside_f64(space.lab_to_rgb(lab)) {
        return 1.0;
    }
    let n = space.neutral_ab(lab.x);
    let chroma = (lab.y - n.x).hypot(lab.z - n.y);
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..MAX_BISECTION_STEPS {
        if (hi - lo) * chroma <= space.chroma_tolerance() {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if is_inside_f64(space.lab_to_rgb(scale_chroma(space, lab, mid))) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Lightness clipped to [0, L_white].
#[inline]
fn clip_lightness(lab: DVec3, l_white: f64) -> DVec3 {
    DVec3::new(lab.x.clamp(0.0, l_white), lab.y, lab.z)
}

fn all_finite(rgb: [f32; 3]) -> bool {
    rgb.iter().all(|c| c.is_finite())
}

fn local_chunk<S: OpponentSpace>(
    chunk: &mut [[f32; 3]],
    conversion: &Conversion,
    space: &S,
) -> usize {
    let mut outside = 0;
    for p in chunk {
        let t = conversion.apply(*p);
        if is_inside_unit_cube(t) {
            *p = t;
            continue;
        }
        outside += 1;
        if !all_finite(t) {
            *p = clip_to_unit_cube(t);
            continue;
        }
        let rgb = DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
        let lab = clip_lightness(space.rgb_to_lab(rgb), space.l_white());
        let s = chroma_scale_to_boundary(space, lab);
        let mapped = space.lab_to_rgb(scale_chroma(space, lab, s));
        *p = clip_to_unit_cube(to_pixel(mapped));
    }
    outside
}

/// Pass 1 converts to the target, counts outside pixels and finds k = min over outside
/// pixels with L* in (0, 100) of their chroma scale to the boundary. Pass 2 scales every
/// pixel's chroma by k (only when k < 1; otherwise only outside pixels, whose lightness
/// was out of range, are mapped locally).
fn global_chroma(
    pixels: &mut [[f32; 3]],
    conversion: &Conversion,
    lab: &CielabConverter,
) -> (usize, f64) {
    let l_white = lab.l_white();
    let (outside, k) = pixels
        .par_chunks_mut(CHUNK_PIXELS)
        .map(|chunk| {
            let mut outside = 0;
            let mut k = 1.0_f64;
            for p in chunk {
                let t = conversion.apply(*p);
                *p = t;
                if is_inside_unit_cube(t) {
                    continue;
                }
                outside += 1;
                if !all_finite(t) {
                    continue;
                }
                let rgb = DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
                let lab_value = lab.rgb_to_lab(rgb);
                if lab_value.x > 0.0 && lab_value.x < l_white {
                    k = k.min(chroma_scale_to_boundary(lab, lab_value));
                }
            }
            (outside, k)
        })
        .reduce(|| (0, 1.0), |a, b| (a.0 + b.0, a.1.min(b.1)));
    if outside == 0 {
        return (0, 1.0);
    }
    pixels.par_chunks_mut(CHUNK_PIXELS).for_each(|chunk| {
        for p in chunk {
            let inside = is_inside_unit_cube(*p);
            if k == 1.0 && inside {
                continue;
            }
            if !all_finite(*p) {
                *p = clip_to_unit_cube(*p);
                continue;
            }
            let rgb = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            let value = clip_lightness(lab.rgb_to_lab(rgb), l_white);
            let scaled = scale_chroma(lab, value, k);
            // Lightness-clipped pixels may still need a local step to reach the boundary.
            let s = if inside {
                1.0
            } else {
                chroma_scale_to_boundary(lab, scaled)
            };
            let mapped = lab.lab_to_rgb(scale_chroma(lab, scaled, s));
            *p = clip_to_unit_cube(to_pixel(mapped));
        }
    });
    (outside, k)
}

struct RgcConversion {
    to_target: Conversion,
    source_to_ap1: DMat3,
    ap1_to_target: DMat3,
    params: AcesRgcParameters,
}

fn aces_rgc_chunk(chunk: &mut [[f32; 3]], rgc: &RgcConversion) -> usize {
    let mut outside = 0;
    for p in chunk {
        if !is_inside_unit_cube(rgc.to_target.apply(*p)) {
            outside += 1;
        }
        if !all_finite(*p) {
            *p = clip_to_unit_cube(rgc.to_target.apply(*p));
            continue;
        }
        let ap1 = mul(&rgc.source_to_ap1, *p);
        let compressed = aces_rgc_acescg(ap1, &rgc.params);
        *p = clip_to_unit_cube(to_pixel(rgc.ap1_to_target * compressed));
    }
    outside
}

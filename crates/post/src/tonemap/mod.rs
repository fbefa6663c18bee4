//! Tone operators: each a documented function of relative or absolute luminance, in its own
//! file with its reference and equations. [`ToneOperator::apply`] maps a linear HDR image to
//! linear display values (nominally [0, 1]; clipping and gamut mapping come after), never
//! outputs NaN, ±∞ or negative values, and reports how many input pixels were non-finite or
//! negative ([`ToneReport`]). An operator's file keeps the operator (formula, parameters,
//! reference, scalar curve); its vector and register forms are in `kernels/`, one file per
//! ISA family, run at the ISA of `prism_cpu::active()` (`PRISM_SIMD`, `--simd`).

mod aces;
mod agx;
pub mod bilateral_grid;
pub(crate) mod curve_table;
mod drago03;
mod durand02;
mod exponential;
pub mod fast_math;
mod ferwerda96;
pub mod gaussian;
pub(crate) mod kernels;
mod linear;
mod logarithmic;
mod mean_value;
mod octave_curve;
pub mod pixels;
mod power_curve;
mod reinhard02;
mod reinhard02_local;
mod schlick94;
mod tumblin_rushmeier;
mod ward94;
mod ward97_histogram;

use std::collections::BTreeMap;

use serde::Serialize;

use pixels::Mapped;
use prism_image::Image;
use prism_image::{ImageError, Result};

/// One operator parameter: name, default (`None`: computed from the image) and meaning.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ParamSpec {
    pub name: &'static str,
    pub default: Option<f64>,
    /// Inclusive lower and upper bounds of accepted values.
    pub min: f64,
    pub max: f64,
    pub doc: &'static str,
}

/// What `prism tonemap --list` prints for one operator.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct OperatorInfo {
    pub name: &'static str,
    pub reference: &'static str,
    /// Needs absolute luminance (cd/m²).
    pub absolute: bool,
    pub params: &'static [ParamSpec],
}

/// The tone operators (CLI names in each file's `INFO`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToneOperator {
    Linear,
    MeanValue,
    Ward94,
    Exponential,
    Logarithmic,
    Drago03,
    Schlick94,
    TumblinRushmeier,
    Reinhard02,
    Reinhard02Local,
    Ferwerda96,
    Ward97Histogram,
    Durand02,
    Aces,
    Agx,
}

/// Settings shared by every operator, plus per-operator parameter overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct ToneParams {
    /// Exposure in stops applied before the operator (input × 2^EV).
    pub exposure_ev: f64,
    /// cd/m² per unit of relative luminance; overrides the image's `cd_m2_per_unit`.
    pub luminance_scale_cd_m2: Option<f64>,
    /// Operator parameters by name (`--param key=value`), checked against the operator's
    /// [`ParamSpec`]s.
    pub values: BTreeMap<String, f64>,
}

impl Default for ToneParams {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            luminance_scale_cd_m2: None,
            values: BTreeMap::new(),
        }
    }
}

/// What an operator met and derived; serialisable for `--json` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToneReport {
    pub operator: &'static str,
    /// Input pixels with a NaN or infinite component (mapped as black).
    pub non_finite_pixels: u64,
    /// Input pixels with a negative component (that component clamped to 0).
    pub negative_pixels: u64,
    /// Resolved parameters and image statistics the mapping used (L_avg, L_white, …).
    pub values: BTreeMap<String, f64>,
}

#[derive(Debug, Clone)]
pub struct ToneResult {
    pub image: Image,
    pub report: ToneReport,
}

/// Where an operator reads its input pixels, and where its mapping pass writes.
pub(crate) enum Input<'a> {
    /// The caller's pixels, read only; the output goes to a new (or reused) buffer.
    Borrowed(&'a [[f32; 3]]),
    /// The caller's pixels, owned (`ToneOperator::apply_in_place`): read by the statistics
    /// passes, then overwritten chunk by chunk by the mapping pass, so that input and
    /// output are never held together (`prism tonemap`'s bounded memory).
    Owned(std::sync::Mutex<Option<Vec<[f32; 3]>>>),
}

/// Everything an operator's `apply` needs: the image, exposure factor, luminance weights,
/// and resolved parameters.
pub(crate) struct Context<'a> {
    /// The image's size, colour space and scale (its pixels are `input`'s).
    pub image: &'a Image,
    pub input: Input<'a>,
    pub params: &'a ToneParams,
    pub info: &'static OperatorInfo,
    /// 2^EV.
    pub exposure: f32,
    /// Y = w · RGB in the image's colour space.
    pub weights: [f32; 3],
    /// An output buffer to reuse (from [`ToneOperator::apply_into`]).
    pub buffer: std::sync::Mutex<Option<Vec<[f32; 3]>>>,
    /// The widest kernels to run (module `kernels`): `prism_cpu::active()` when the call
    /// began, carried to every task.
    pub simd: prism_cpu::Simd,
}

impl Context<'_> {
    /// `read` of the input pixels (before the mapping pass: afterwards an owned input is
    /// gone and `read` sees none).
    pub fn read_pixels<R>(&self, read: impl FnOnce(&[[f32; 3]]) -> R) -> R {
        match &self.input {
            Input::Borrowed(pixels) => read(pixels),
            Input::Owned(pixels) => {
                let guard = pixels.lock().unwrap_or_else(|e| e.into_inner());
                read(guard.as_deref().unwrap_or(&[]))
            }
        }
    }

    /// The output pixel buffer, `n` long: the reused one when given, else a new one.
    /// Its contents are overwritten by the mapping pass.
    pub fn output_buffer(&self, n: usize) -> Vec<[f32; 3]> {
        let reused = self.buffer.lock().ok().and_then(|mut b| b.take());
        match reused {
            Some(mut v) => {
                v.resize(n, [0.0; 3]);
                v
            }
            None => vec![[0.0; 3]; n],
        }
    }

    /// The parameter's value: the override if given, else its default (`None` when the
    /// default is computed from the image).
    pub fn param(&self, name: &str) -> Option<f64> {
        self.params.values.get(name).copied().or_else(|| {
            self.info
                .params
                .iter()
                .find(|p| p.name == name)
                .and_then(|p| p.default)
        })
    }

    /// A parameter with a fixed default.
    pub fn value(&self, name: &str) -> f64 {
        self.param(name)
            .expect("parameters read with value() have a default in their ParamSpec")
    }

    /// cd/m² per unit: `--luminance-scale`, else the image's `prism:cd_m2_per_unit`.
    pub fn absolute_scale(&self) -> Result<f64> {
        self.params
            .luminance_scale_cd_m2
            .or(self.image.cd_m2_per_unit)
            .ok_or_else(|| {
                ImageError::invalid(format!(
                    "operator {} needs absolute luminance: the image has no \
                     prism:cd_m2_per_unit header; give --luminance-scale (cd/m² per unit)",
                    self.info.name
                ))
            })
    }
}

/// An operator's output before it is wrapped into a [`ToneResult`].
pub(crate) struct Output {
    pub mapped: Mapped,
    pub values: Vec<(&'static str, f64)>,
}

impl ToneOperator {
    pub const ALL: [ToneOperator; 15] = [
        ToneOperator::Linear,
        ToneOperator::MeanValue,
        ToneOperator::Ward94,
        ToneOperator::Exponential,
        ToneOperator::Logarithmic,
        ToneOperator::Drago03,
        ToneOperator::Schlick94,
        ToneOperator::TumblinRushmeier,
        ToneOperator::Reinhard02,
        ToneOperator::Reinhard02Local,
        ToneOperator::Ferwerda96,
        ToneOperator::Ward97Histogram,
        ToneOperator::Durand02,
        ToneOperator::Aces,
        ToneOperator::Agx,
    ];

    pub fn info(self) -> &'static OperatorInfo {
        match self {
            ToneOperator::Linear => &linear::INFO,
            ToneOperator::MeanValue => &mean_value::INFO,
            ToneOperator::Ward94 => &ward94::INFO,
            ToneOperator::Exponential => &exponential::INFO,
            ToneOperator::Logarithmic => &logarithmic::INFO,
            ToneOperator::Drago03 => &drago03::INFO,
            ToneOperator::Schlick94 => &schlick94::INFO,
            ToneOperator::TumblinRushmeier => &tumblin_rushmeier::INFO,
            ToneOperator::Reinhard02 => &reinhard02::INFO,
            ToneOperator::Reinhard02Local => &reinhard02_local::INFO,
            ToneOperator::Ward97Histogram => &ward97_histogram::INFO,
            ToneOperator::Durand02 => &durand02::INFO,
            ToneOperator::Ferwerda96 => &ferwerda96::INFO,
            ToneOperator::Aces => &aces::INFO,
            ToneOperator::Agx => &agx::INFO,
        }
    }

    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// Every operator's name, reference and parameters (for `--list`).
    pub fn catalogue() -> Vec<&'static OperatorInfo> {
        Self::ALL.iter().map(|op| op.info()).collect()
    }

    /// Looks an operator up by its CLI name (`reinhard02`, `tumblin-rushmeier`, …).
    pub fn from_name(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|op| op.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                ImageError::invalid(format!(
                    "unknown tone operator '{name}'{}; expected one of: {}",
                    prism_spectrum::names::did_you_mean(name, Self::ALL.iter().map(|o| o.name())),
                    Self::ALL.map(|o| o.name()).join(", ")
                ))
            })
    }

    /// Checks that every parameter in `params` exists for this operator and lies within
    /// its bounds, and that the exposure and luminance scale are usable.
    pub fn validate(self, params: &ToneParams) -> Result<()> {
        let info = self.info();
        if !params.exposure_ev.is_finite() {
            return Err(ImageError::invalid(format!(
                "exposure {} EV: expected a finite number of stops",
                params.exposure_ev
            )));
        }
        if let Some(s) = params.luminance_scale_cd_m2 {
            if !(s.is_finite() && s > 0.0) {
                return Err(ImageError::invalid(format!(
                    "luminance scale {s} cd/m² per unit: expected a positive number"
                )));
            }
        }
        for (name, value) in &params.values {
            let Some(spec) = info.params.iter().find(|p| p.name == name) else {
                let known: Vec<&str> = info.params.iter().map(|p| p.name).collect();
                return Err(ImageError::invalid(format!(
                    "operator {} has no parameter '{name}'{}; its parameters: {}",
                    info.name,
                    prism_spectrum::names::did_you_mean(name, known.iter().copied()),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                )));
            };
            if !(value.is_finite() && *value >= spec.min && *value <= spec.max) {
                return Err(ImageError::invalid(format!(
                    "{} {name} = {value}: expected a number in [{}, {}] ({})",
                    info.name, spec.min, spec.max, spec.doc
                )));
            }
        }
        Ok(())
    }

    /// Tone-maps `image` to linear display values in its own colour space.
    pub fn apply(self, image: &Image, params: &ToneParams) -> Result<ToneResult> {
        self.apply_into(image, params, Vec::new())
    }

    /// As [`ToneOperator::apply`], writing into `buffer` (resized to the pixel count; its
    /// old contents are ignored) instead of allocating: pass the pixels of a previous
    /// result (`result.image.into_pixels()`) to tone-map many frames or operators without
    /// allocating and page-faulting a new output each time.
    pub fn apply_into(
        self,
        image: &Image,
        params: &ToneParams,
        buffer: Vec<[f32; 3]>,
    ) -> Result<ToneResult> {
        self.apply_with(image, params, buffer, prism_cpu::active())
    }

    /// As [`ToneOperator::apply`], mapping `image`'s own pixels: the result is the same,
    /// bit for bit, and the input's memory holds the output (no second image).
    pub fn apply_in_place(self, mut image: Image, params: &ToneParams) -> Result<ToneResult> {
        let pixels = image.take_pixels();
        self.run(
            &image,
            Input::Owned(std::sync::Mutex::new(Some(pixels))),
            params,
            Vec::new(),
            prism_cpu::active(),
        )
    }

    /// As [`ToneOperator::apply_into`], with the kernels of `simd` (tests compare ISAs).
    pub(crate) fn apply_with(
        self,
        image: &Image,
        params: &ToneParams,
        buffer: Vec<[f32; 3]>,
        simd: prism_cpu::Simd,
    ) -> Result<ToneResult> {
        self.run(image, Input::Borrowed(image.pixels()), params, buffer, simd)
    }

    fn run(
        self,
        image: &Image,
        input: Input,
        params: &ToneParams,
        buffer: Vec<[f32; 3]>,
        simd: prism_cpu::Simd,
    ) -> Result<ToneResult> {
        self.validate(params)?;
        let ctx = Context {
            image,
            input,
            params,
            info: self.info(),
            exposure: 2f64.powf(params.exposure_ev) as f32,
            weights: image.luminance_weights(),
            buffer: std::sync::Mutex::new((buffer.capacity() > 0).then_some(buffer)),
            simd,
        };
        let output = match self {
            ToneOperator::Linear => linear::apply(&ctx),
            ToneOperator::MeanValue => mean_value::apply(&ctx),
            ToneOperator::Ward94 => ward94::apply(&ctx)?,
            ToneOperator::Exponential => exponential::apply(&ctx),
            ToneOperator::Logarithmic => logarithmic::apply(&ctx),
            ToneOperator::Drago03 => drago03::apply(&ctx),
            ToneOperator::Schlick94 => schlick94::apply(&ctx),
            ToneOperator::TumblinRushmeier => tumblin_rushmeier::apply(&ctx)?,
            ToneOperator::Reinhard02 => reinhard02::apply(&ctx),
            ToneOperator::Reinhard02Local => reinhard02_local::apply(&ctx),
            ToneOperator::Ward97Histogram => ward97_histogram::apply(&ctx)?,
            ToneOperator::Durand02 => durand02::apply(&ctx),
            ToneOperator::Ferwerda96 => ferwerda96::apply(&ctx)?,
            ToneOperator::Aces => aces::apply(&ctx),
            ToneOperator::Agx => agx::apply(&ctx),
        };
        let mut out = image.with_pixels(output.mapped.pixels)?;
        out.cd_m2_per_unit = None;
        out.metadata
            .insert("prism:tone_operator".into(), self.name().into());
        Ok(ToneResult {
            image: out,
            report: ToneReport {
                operator: self.name(),
                non_finite_pixels: output.mapped.non_finite_pixels,
                negative_pixels: output.mapped.negative_pixels,
                values: output
                    .values
                    .into_iter()
                    .map(|(k, v)| (k.to_string(), v))
                    .collect(),
            },
        })
    }
}

#[cfg(test)]
pub(crate) mod test_support;

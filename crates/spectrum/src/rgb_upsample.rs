//! RGB → spectrum upsampling after Jakob & Hanika 2019, "A Low-Dimensional Function Space for
//! Efficient Spectral Upsampling" (Computer Graphics Forum 38(2)), as pbrt-v4 uses it
//! (pbrt-v4 book §4.6.6 "RGB Spectra": `RGBToSpectrumTable`, `RGBAlbedoSpectrum`,
//! `RGBUnboundedSpectrum`, `RGBIlluminantSpectrum`).
//!
//! A reflectance is the sigmoid of a quadratic polynomial in wavelength,
//! s(λ) = S(c0 λ² + c1 λ + c2) with S(x) = 1/2 + x / (2 √(1 + x²)) (paper §3, eqs. 2–3).
//! The coefficients for each RGB are precomputed on a grid (paper §4, pbrt-v4's
//! rgb2spec_opt) by `tools/rgb2spec` and embedded from `crates/spectrum/data/`; at run time
//! they are interpolated trilinearly (paper §5). See docs/rgb-upsampling.md.
//!
//! Table layout (pbrt-v4): `[max component 0..3][z 0..res][y 0..res][x 0..res][c0, c1, c2]`,
//! little-endian f32, where z = the largest RGB component (nodes `z_nodes`, a
//! smoothstep-of-smoothstep spacing that is dense near 0 and 1) and x, y = the next two
//! components (in cyclic order) divided by z, on a uniform grid over [0, 1]. Coefficients
//! take λ in nm directly: no rescaling at evaluation.

use std::fmt;
use std::sync::OnceLock;

use crate::constants::{DENSE_SAMPLE_COUNT, LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use crate::data::{cmfs, illuminant, Observer};
use crate::rgb_space::RgbColorSpace;

/// First bytes of a coefficient table file.
pub const TABLE_MAGIC: &[u8; 13] = b"PRISMRGB2SPEC";
/// Version of the table file format this code reads and writes.
pub const TABLE_FORMAT_VERSION: u32 = 1;

/// Largest |x| the sigmoid is evaluated at: keeps x² finite in f32 (S(±1e18) is exactly
/// 1 or 0 in f32, as S(±∞) is), so infinite or huge polynomials never give NaN.
const SIGMOID_ARG_LIMIT: f32 = 1.0e18;
/// c2 standing in for ±∞ in the flat spectra 0 and 1 (S(±1e18) is exactly 1 or 0 in f32
/// and f64).
const FLAT_C2_LIMIT: f32 = SIGMOID_ARG_LIMIT;

/// The RGB spaces Prism ships coefficient tables for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RgbGamut {
    /// sRGB / Rec.709 primaries, D65 white.
    Srgb,
    /// ITU-R BT.2020 primaries, D65 white.
    Rec2020,
    /// ACEScg (AP1) primaries, D60 white.
    AcesCg,
}

impl RgbGamut {
    pub const ALL: [RgbGamut; 3] = [RgbGamut::Srgb, RgbGamut::Rec2020, RgbGamut::AcesCg];

    /// Short name used on the command line and in table file names (`srgb`, `rec2020`, `acescg`).
    pub fn name(self) -> &'static str {
        match self {
            RgbGamut::Srgb => "srgb",
            RgbGamut::Rec2020 => "rec2020",
            RgbGamut::AcesCg => "acescg",
        }
    }

    /// Parses `srgb`, `rec2020` or `acescg` (case-insensitive, `-`, `_`, `.` ignored).
    pub fn from_name(name: &str) -> Result<Self, RgbUpsampleError> {
        let key: String = name
            .chars()
            .filter(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase();
        match key.as_str() {
            "srgb" | "rec709" => Ok(RgbGamut::Srgb),
            "rec2020" | "bt2020" => Ok(RgbGamut::Rec2020),
            "acescg" | "ap1" => Ok(RgbGamut::AcesCg),
            _ => Err(RgbUpsampleError::new(format!(
                "unknown RGB gamut `{name}`: expected srgb, rec2020 or acescg"
            ))),
        }
    }

    /// The colour space (primaries, white, matrices).
    pub fn color_space(self) -> RgbColorSpace {
        match self {
            RgbGamut::Srgb => RgbColorSpace::srgb(),
            RgbGamut::Rec2020 => RgbColorSpace::rec2020(),
            RgbGamut::AcesCg => RgbColorSpace::acescg(),
        }
    }

    /// The embedded coefficient table of this gamut, parsed on first use.
    pub fn table(self) -> &'static RgbToSpectrumTable {
        static SRGB: OnceLock<RgbToSpectrumTable> = OnceLock::new();
        static REC2020: OnceLock<RgbToSpectrumTable> = OnceLock::new();
        static ACESCG: OnceLock<RgbToSpectrumTable> = OnceLock::new();
        let (cell, bytes): (_, &[u8]) = match self {
            RgbGamut::Srgb => (&SRGB, include_bytes!("../data/rgb2spec_srgb.bin")),
            RgbGamut::Rec2020 => (&REC2020, include_bytes!("../data/rgb2spec_rec2020.bin")),
            RgbGamut::AcesCg => (&ACESCG, include_bytes!("../data/rgb2spec_acescg.bin")),
        };
        cell.get_or_init(|| {
            // Embedded at build time and checked by the tests: failing here is a build bug.
            RgbToSpectrumTable::from_bytes(bytes)
                .unwrap_or_else(|e| panic!("embedded {} table is malformed: {e}", self.name()))
        })
    }

    /// The space's white illuminant (D65, or D60 for ACEScg) on the 1 nm grid 360–830 nm,
    /// scaled so that Σ I(λ) ȳ(λ) Δλ = Σ ȳ(λ) Δλ (CIE 1931, Δλ = 1 nm): with the
    /// Prism's convention Y = ∫L ȳ dλ / ∫ȳ dλ it has luminance Y = 1, as pbrt-v4's
    /// normalised standard illuminants do.
    pub fn white_illuminant(self) -> &'static [f32; DENSE_SAMPLE_COUNT] {
        static SRGB: OnceLock<[f32; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        static REC2020: OnceLock<[f32; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        static ACESCG: OnceLock<[f32; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        let cell = match self {
            RgbGamut::Srgb => &SRGB,
            RgbGamut::Rec2020 => &REC2020,
            RgbGamut::AcesCg => &ACESCG,
        };
        cell.get_or_init(|| {
            let dense = white_illuminant_dense(&self.color_space());
            let mut out = [0.0f32; DENSE_SAMPLE_COUNT];
            for (o, v) in out.iter_mut().zip(dense.iter()) {
                *o = *v as f32;
            }
            out
        })
    }
}

impl RgbGamut {
    /// Linear RGB (in this gamut) per unit reflectance at each whole nm 360–830: the white
    /// illuminant (normalised so that its own Y = 1) × the CIE 1931 CMFs, through the
    /// space's XYZ → RGB matrix. Σ weights·r is the RGB of reflectance r; a flat 1 gives
    /// RGB ≈ (1, 1, 1).
    pub fn reflectance_rgb_weights(self) -> &'static [[f64; 3]; DENSE_SAMPLE_COUNT] {
        static SRGB: OnceLock<[[f64; 3]; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        static REC2020: OnceLock<[[f64; 3]; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        static ACESCG: OnceLock<[[f64; 3]; DENSE_SAMPLE_COUNT]> = OnceLock::new();
        let cell = match self {
            RgbGamut::Srgb => &SRGB,
            RgbGamut::Rec2020 => &REC2020,
            RgbGamut::AcesCg => &ACESCG,
        };
        cell.get_or_init(|| {
            let space = self.color_space();
            let c = cmfs(Observer::Cie1931);
            let illum = white_illuminant_dense(&space);
            let y_sum: f64 = c.y_bar.values().iter().sum();
            let mut out = [[0.0; 3]; DENSE_SAMPLE_COUNT];
            for (i, o) in out.iter_mut().enumerate() {
                let w = illum[i] / y_sum;
                let xyz = glam::DVec3::new(
                    w * c.x_bar.values()[i],
                    w * c.y_bar.values()[i],
                    w * c.z_bar.values()[i],
                );
                *o = (space.xyz_to_rgb * xyz).to_array();
            }
            out
        })
    }
}

/// The space's white illuminant on the 1 nm grid, normalised to Σ I ȳ = Σ ȳ (f64).
pub fn white_illuminant_dense(space: &RgbColorSpace) -> Vec<f64> {
    let y_bar = &cmfs(Observer::Cie1931).y_bar;
    // The colour spaces name only D65/D60, both embedded.
    let spd = illuminant(space.white_illuminant)
        .expect("white illuminants of the built-in spaces are embedded")
        .to_dense();
    let scale = y_bar.values().iter().sum::<f64>() / spd.inner_product(y_bar);
    spd.values().iter().map(|v| v * scale).collect()
}

/// Why an RGB could not be upsampled or a table could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbUpsampleError {
    pub message: String,
}

impl RgbUpsampleError {
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }
}

impl fmt::Display for RgbUpsampleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RgbUpsampleError {}

/// S(x) = 1/2 + x / (2 √(1 + x²)) (Jakob & Hanika 2019, eq. 3), f32.
#[inline(always)]
fn sigmoid_f32(x: f32) -> f32 {
    let x = x.clamp(-SIGMOID_ARG_LIMIT, SIGMOID_ARG_LIMIT);
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// S(x) in f64 (same clamp, so f32 and f64 paths agree at the extremes).
#[inline(always)]
fn sigmoid_f64(x: f64) -> f64 {
    let x = x.clamp(-SIGMOID_ARG_LIMIT as f64, SIGMOID_ARG_LIMIT as f64);
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// s(λ) = S(c0 λ² + c1 λ + c2), λ in nm (Jakob & Hanika 2019, eq. 2; pbrt-v4
/// `RGBSigmoidPolynomial`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmoidPolynomial {
    /// Coefficient of λ² (per nm²).
    pub c0: f32,
    /// Coefficient of λ (per nm).
    pub c1: f32,
    /// Constant term.
    pub c2: f32,
    /// The same polynomial in u = λ − `EVAL_CENTRE_NM` (a u² + b u + c, computed in f64 and
    /// rounded once), which `eval` uses: large sigmoid coefficients make c0 λ² + c1 λ + c2
    /// cancel catastrophically in f32 (terms ~1e4 for x ~ 1), while |u| ≤ 235 nm keeps the
    /// terms 10–25× smaller.
    centred: [f32; 3],
}

/// Centre of the f32 evaluation variable u = λ − 595 nm (middle of 360–830 nm; the
/// subtraction is exact in f32 for λ in [297.5, 1190] nm).
const EVAL_CENTRE_NM: f32 = 595.0;

impl SigmoidPolynomial {
    pub fn new(c0: f32, c1: f32, c2: f32) -> Self {
        let (a, b, c, l) = (c0 as f64, c1 as f64, c2 as f64, EVAL_CENTRE_NM as f64);
        let centred = [
            a as f32,
            (b + 2.0 * a * l) as f32,
            (c + (b + a * l) * l) as f32,
        ];
        Self {
            c0,
            c1,
            c2,
            centred,
        }
    }

    /// The flat spectrum `value` ∈ [0, 1]: c0 = c1 = 0, S(c2) = value (pbrt-v4's special
    /// case for grey RGB; 0 and 1 use c2 = ∓1e18, whose sigmoid is exactly 0 and 1 in f32).
    pub fn constant(value: f32) -> Self {
        let v = value.clamp(0.0, 1.0);
        let c2 = (v - 0.5) / (v * (1.0 - v)).sqrt();
        // NaN cannot occur: v ∈ [0, 1]; ±∞ at v = 0, 1 is clamped.
        Self::new(0.0, 0.0, c2.clamp(-FLAT_C2_LIMIT, FLAT_C2_LIMIT))
    }

    /// s(λ) at one wavelength in nm (Horner form in λ − 595 nm, branch-free).
    #[inline(always)]
    pub fn eval(&self, wavelength_nm: f32) -> f32 {
        let [a, b, c] = self.centred;
        let u = wavelength_nm - EVAL_CENTRE_NM;
        sigmoid_f32((a * u + b) * u + c)
    }

    /// s(λ) at four wavelengths in nm (the hero wavelength and its three rotations).
    #[inline]
    pub fn eval4(&self, wavelengths_nm: [f32; 4]) -> [f32; 4] {
        wavelengths_nm.map(|l| self.eval(l))
    }

    /// s(λ) in f64 arithmetic from the f32 coefficients.
    #[inline]
    pub fn eval_f64(&self, wavelength_nm: f64) -> f64 {
        let (c0, c1, c2) = (self.c0 as f64, self.c1 as f64, self.c2 as f64);
        sigmoid_f64((c0 * wavelength_nm + c1) * wavelength_nm + c2)
    }

    /// The largest value over 360–830 nm: at an end, or at the parabola's vertex when it
    /// lies inside (S is monotonic; pbrt-v4 `RGBSigmoidPolynomial::MaxValue`).
    pub fn max_value(&self) -> f32 {
        let mut result = self.eval(LAMBDA_MIN_NM).max(self.eval(LAMBDA_MAX_NM));
        let vertex_nm = -self.c1 / (2.0 * self.c0);
        if (LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&vertex_nm) {
            result = result.max(self.eval(vertex_nm));
        }
        result
    }
}

/// The smoothstep-of-smoothstep spacing of the z (largest component) nodes:
/// z_k = smoothstep(smoothstep(k / (res − 1))), smoothstep(x) = x² (3 − 2x) (pbrt-v4
/// rgb2spec_opt).
pub fn z_nodes(resolution: usize) -> Vec<f32> {
    let smoothstep = |x: f64| x * x * (3.0 - 2.0 * x);
    (0..resolution)
        .map(|k| smoothstep(smoothstep(k as f64 / (resolution - 1) as f64)) as f32)
        .collect()
}

/// Sigmoid-polynomial coefficients on a grid over RGB ∈ [0, 1]³ (pbrt-v4
/// `RGBToSpectrumTable`).
#[derive(Debug, Clone, PartialEq)]
pub struct RgbToSpectrumTable {
    resolution: usize,
    gamut_name: String,
    /// The built-in gamut named by `gamut_name`, if any: its colorimetry drives
    /// [`RgbToSpectrumTable::coefficients_refined`].
    gamut: Option<RgbGamut>,
    z_nodes: Vec<f32>,
    /// `[3][res][res][res][3]` flattened: [max component][z][y][x][c0, c1, c2].
    coefficients: Vec<f32>,
}

impl RgbToSpectrumTable {
    /// Builds a table; checks the sizes, that the z nodes increase from 0 to 1 and that
    /// every number is finite.
    pub fn new(
        resolution: usize,
        gamut_name: &str,
        z_nodes: Vec<f32>,
        coefficients: Vec<f32>,
    ) -> Result<Self, RgbUpsampleError> {
        if !(2..=1024).contains(&resolution) {
            return Err(RgbUpsampleError::new(format!(
                "table resolution {resolution} is out of range: expected 2 to 1024"
            )));
        }
        if z_nodes.len() != resolution {
            return Err(RgbUpsampleError::new(format!(
                "{} z nodes for resolution {resolution}",
                z_nodes.len()
            )));
        }
        if z_nodes[0] != 0.0
            || z_nodes[resolution - 1] != 1.0
            || !z_nodes.windows(2).all(|w| w[0] < w[1])
        {
            return Err(RgbUpsampleError::new(
                "z nodes must increase strictly from 0 to 1",
            ));
        }
        let expected = 3 * resolution * resolution * resolution * 3;
        if coefficients.len() != expected {
            return Err(RgbUpsampleError::new(format!(
                "{} coefficients, expected 3 × {resolution}³ × 3 = {expected}",
                coefficients.len()
            )));
        }
        if let Some(i) = coefficients.iter().position(|c| !c.is_finite()) {
            return Err(RgbUpsampleError::new(format!(
                "coefficient {i} is not finite"
            )));
        }
        Ok(Self {
            resolution,
            gamut_name: gamut_name.to_string(),
            gamut: RgbGamut::from_name(gamut_name).ok(),
            z_nodes,
            coefficients,
        })
    }

    pub fn resolution(&self) -> usize {
        self.resolution
    }

    pub fn gamut_name(&self) -> &str {
        &self.gamut_name
    }

    /// The built-in gamut this table's name refers to (`None` for other names).
    pub fn gamut(&self) -> Option<RgbGamut> {
        self.gamut
    }

    pub fn z_nodes(&self) -> &[f32] {
        &self.z_nodes
    }

    /// All coefficients, `[3][res][res][res][3]` flattened.
    pub fn raw_coefficients(&self) -> &[f32] {
        &self.coefficients
    }

    /// The coefficients stored at one node.
    pub fn node(&self, max_component: usize, zi: usize, yi: usize, xi: usize) -> [f32; 3] {
        let r = self.resolution;
        let o = 3 * (((max_component * r + zi) * r + yi) * r + xi);
        [
            self.coefficients[o],
            self.coefficients[o + 1],
            self.coefficients[o + 2],
        ]
    }

    /// Serialises to the file format: magic "PRISMRGB2SPEC", u32 version, u32 resolution,
    /// u32 name length + UTF-8 gamut name, `res` f32 z nodes, then the coefficients
    /// (all little-endian).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(
            TABLE_MAGIC.len() + 12 + self.gamut_name.len() + 4 * self.coefficients.len(),
        );
        out.extend_from_slice(TABLE_MAGIC);
        out.extend_from_slice(&TABLE_FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(self.resolution as u32).to_le_bytes());
        out.extend_from_slice(&(self.gamut_name.len() as u32).to_le_bytes());
        out.extend_from_slice(self.gamut_name.as_bytes());
        for v in self.z_nodes.iter().chain(self.coefficients.iter()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Parses the format written by [`RgbToSpectrumTable::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RgbUpsampleError> {
        let mut rest = bytes
            .strip_prefix(TABLE_MAGIC.as_slice())
            .ok_or_else(|| RgbUpsampleError::new("not an RGB→spectrum table (bad magic)"))?;
        let mut read_u32 = |what: &str| -> Result<u32, RgbUpsampleError> {
            let (head, tail) = rest.split_at_checked(4).ok_or_else(|| {
                RgbUpsampleError::new(format!("table truncated before the {what}"))
            })?;
            rest = tail;
            Ok(u32::from_le_bytes([head[0], head[1], head[2], head[3]]))
        };
        let version = read_u32("version")?;
        if version != TABLE_FORMAT_VERSION {
            return Err(RgbUpsampleError::new(format!(
                "table format version {version}, this build reads {TABLE_FORMAT_VERSION}"
            )));
        }
        let resolution = read_u32("resolution")? as usize;
        let name_len = read_u32("gamut name length")? as usize;
        let (name, floats) = rest
            .split_at_checked(name_len)
            .ok_or_else(|| RgbUpsampleError::new("table truncated in the gamut name"))?;
        let gamut_name = std::str::from_utf8(name)
            .map_err(|_| RgbUpsampleError::new("gamut name is not UTF-8"))?;
        if floats.len() % 4 != 0 {
            return Err(RgbUpsampleError::new(
                "table body is not a whole number of f32",
            ));
        }
        let values: Vec<f32> = floats
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        if values.len() < resolution {
            return Err(RgbUpsampleError::new("table truncated in the z nodes"));
        }
        let (z, coefficients) = values.split_at(resolution);
        Self::new(resolution, gamut_name, z.to_vec(), coefficients.to_vec())
    }

    /// The sigmoid polynomial for a linear RGB in [0, 1]³ (components outside are clamped;
    /// NaN counts as 0): trilinear interpolation of the coefficients of the 8 surrounding
    /// nodes (pbrt-v4 `RGBToSpectrumTable::operator()`); grey gives a flat spectrum.
    pub fn coefficients(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        // `max` turns NaN into 0, then clamp to [0, 1].
        let rgb = rgb.map(|c| c.max(0.0).clamp(0.0, 1.0));
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return SigmoidPolynomial::constant(rgb[0]);
        }
        // Which component is largest; the other two, in cyclic order, over it.
        let max_c = if rgb[0] > rgb[1] {
            if rgb[0] > rgb[2] {
                0
            } else {
                2
            }
        } else if rgb[1] > rgb[2] {
            1
        } else {
            2
        };
        let res = self.resolution;
        let last = (res - 1) as f32;
        let z = rgb[max_c]; // > 0: not grey, so the max exceeds some component ≥ 0
        let x = rgb[(max_c + 1) % 3] * last / z;
        let y = rgb[(max_c + 2) % 3] * last / z;
        let xi = (x as usize).min(res - 2);
        let yi = (y as usize).min(res - 2);
        // Largest zi with z_nodes[zi] < z, within [0, res − 2] (pbrt-v4 FindInterval).
        let zi = self
            .z_nodes
            .partition_point(|&n| n < z)
            .saturating_sub(1)
            .min(res - 2);
        let dx = x - xi as f32;
        let dy = y - yi as f32;
        let dz = (z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi]);
        let lerp = |t: f32, a: f32, b: f32| a + t * (b - a);
        let mut c = [0.0f32; 3];
        for (i, ci) in c.iter_mut().enumerate() {
            let at = |dzi: usize, dyi: usize, dxi: usize| {
                self.coefficients
                    [3 * (((max_c * res + zi + dzi) * res + yi + dyi) * res + xi + dxi) + i]
            };
            *ci = lerp(
                dz,
                lerp(
                    dy,
                    lerp(dx, at(0, 0, 0), at(0, 0, 1)),
                    lerp(dx, at(0, 1, 0), at(0, 1, 1)),
                ),
                lerp(
                    dy,
                    lerp(dx, at(1, 0, 0), at(1, 0, 1)),
                    lerp(dx, at(1, 1, 0), at(1, 1, 1)),
                ),
            );
        }
        SigmoidPolynomial::new(c[0], c[1], c[2])
    }

    /// The table's coefficients ([`RgbToSpectrumTable::coefficients`]) polished by at most
    /// [`REFINE_MAX_ITERATIONS`] damped Newton steps on the linear-RGB residual of the
    /// reflectance under the gamut's white illuminant (1 nm sums, CIE 1931; see
    /// [`RgbGamut::reflectance_rgb_weights`]). Every accepted step lowers the residual, so
    /// the result is never worse than the lookup; colours outside the object-colour solid
    /// stop at the iteration or coefficient limit. A few µs: meant for constant colours
    /// (materials, lights), not per-texel lookups. Tables whose name is not a built-in
    /// gamut return the plain lookup.
    pub fn coefficients_refined(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        let start = self.coefficients(rgb);
        let Some(gamut) = self.gamut else {
            return start;
        };
        let rgb = rgb.map(|c| c.max(0.0).clamp(0.0, 1.0));
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return start; // flat, exact
        }
        refine_polynomial(
            gamut.reflectance_rgb_weights(),
            start,
            rgb.map(|c| c as f64),
        )
        .0
    }
}

/// Most Newton steps of [`RgbToSpectrumTable::coefficients_refined`].
pub const REFINE_MAX_ITERATIONS: usize = 24;
/// Most step halvings per Newton step.
const REFINE_MAX_HALVINGS: usize = 12;
/// Refinement stops once every RGB component is this close (f32 evaluation noise is
/// ~1e-7).
const REFINE_TOLERANCE: f64 = 2e-6;
/// Bound on the normalised coefficients (t = (λ − 360)/470) during refinement: larger
/// values only chase colours on or beyond the boundary of the object-colour solid.
const REFINE_COEFFICIENT_LIMIT: f64 = 1e5;
const NORMALISED_RANGE_NM: f64 = (LAMBDA_MAX_NM - LAMBDA_MIN_NM) as f64;

/// nm coefficients (c0, c1, c2) → normalised (A, B, C) of A t² + B t + C,
/// λ = 360 + 470 t.
fn to_normalised(p: &SigmoidPolynomial) -> [f64; 3] {
    let (c0, c1, c2) = (p.c0 as f64, p.c1 as f64, p.c2 as f64);
    let (l0, r) = (LAMBDA_MIN_NM as f64, NORMALISED_RANGE_NM);
    [
        c0 * r * r,
        r * (c1 + 2.0 * c0 * l0),
        c2 + c1 * l0 + c0 * l0 * l0,
    ]
}

/// Normalised (A, B, C) → nm coefficients, rounded to f32 (as `tools/rgb2spec` stores them).
fn from_normalised(c: [f64; 3]) -> SigmoidPolynomial {
    let (l0, inv) = (LAMBDA_MIN_NM as f64, 1.0 / NORMALISED_RANGE_NM);
    let [a, b, cc] = c;
    SigmoidPolynomial::new(
        (a * inv * inv) as f32,
        (b * inv - 2.0 * a * l0 * inv * inv) as f32,
        (cc - b * l0 * inv + a * (l0 * inv) * (l0 * inv)) as f32,
    )
}

/// Samples on the 1 nm grid, padded to whole groups of four.
const PADDED_SAMPLES: usize = DENSE_SAMPLE_COUNT.div_ceil(4) * 4;

/// s(λ) and S'(x(λ)) at every whole nm 360–830, in f32 groups of four (so the square roots
/// and divisions vectorise). s is computed exactly as `SigmoidPolynomial::eval` does, so
/// the residual is that of what the renderer evaluates.
struct SigmoidSamples {
    value: [f32; PADDED_SAMPLES],
    slope: [f32; PADDED_SAMPLES],
}

impl SigmoidSamples {
    fn new(p: &SigmoidPolynomial) -> Self {
        let [a, b, c] = p.centred;
        let mut out = Self {
            value: [0.0; PADDED_SAMPLES],
            slope: [0.0; PADDED_SAMPLES],
        };
        for (i, (v, d)) in out.value.iter_mut().zip(out.slope.iter_mut()).enumerate() {
            let u = LAMBDA_MIN_NM + i as f32 - EVAL_CENTRE_NM;
            let x = ((a * u + b) * u + c).clamp(-SIGMOID_ARG_LIMIT, SIGMOID_ARG_LIMIT);
            let q = (1.0 + x * x).sqrt();
            *v = 0.5 + 0.5 * x / q;
            // S'(x) = 1 / (2 (1 + x²)^{3/2}).
            *d = 0.5 / (q * q * q);
        }
        out
    }

    /// Linear RGB of the samples minus `target`.
    fn residual(&self, weights: &[[f64; 3]; DENSE_SAMPLE_COUNT], target: [f64; 3]) -> [f64; 3] {
        let mut rgb = [0.0; 3];
        for (w, &v) in weights.iter().zip(&self.value) {
            for k in 0..3 {
                rgb[k] += w[k] * v as f64;
            }
        }
        std::array::from_fn(|k| rgb[k] - target[k])
    }

    /// d(RGB)/d(A, B, C), (A, B, C) the normalised coefficients (row = RGB component):
    /// Σ w S'(x) (t², t, 1), t = (λ − 360)/470.
    fn jacobian(&self, weights: &[[f64; 3]; DENSE_SAMPLE_COUNT]) -> [[f64; 3]; 3] {
        let mut jac = [[0.0; 3]; 3];
        for (i, (w, &ds)) in weights.iter().zip(&self.slope).enumerate() {
            let t = i as f64 / NORMALISED_RANGE_NM;
            let ds = ds as f64;
            let d = [ds * t * t, ds * t, ds];
            for k in 0..3 {
                for p in 0..3 {
                    jac[k][p] += w[k] * d[p];
                }
            }
        }
        jac
    }
}

/// Linear RGB of the reflectance `p` as the renderer evaluates it (f32 `eval` at every
/// whole nm) minus `target`.
#[cfg(test)]
fn rgb_residual(
    weights: &[[f64; 3]; DENSE_SAMPLE_COUNT],
    p: &SigmoidPolynomial,
    target: [f64; 3],
) -> [f64; 3] {
    SigmoidSamples::new(p).residual(weights, target)
}

fn transpose3(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[c][r]))
}

fn mat_mul3(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn norm2(v: [f64; 3]) -> f64 {
    v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
}

fn max_abs(v: [f64; 3]) -> f64 {
    v[0].abs().max(v[1].abs()).max(v[2].abs())
}

/// Solves a x = b (3 × 3, partial pivoting); `None` if singular.
#[allow(clippy::needless_range_loop)] // 3 × 3 elimination reads best with indices
pub fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let mut pivot = col;
        for row in col + 1..3 {
            if a[row][col].abs() > a[pivot][col].abs() {
                pivot = row;
            }
        }
        // Also rejects NaN.
        if a[pivot][col].abs().partial_cmp(&1e-300) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Damped Newton on RGB(p) = target from `start` (see
/// [`RgbToSpectrumTable::coefficients_refined`]); returns the polynomial and its max |Δ|
/// in linear RGB.
pub fn refine_polynomial(
    weights: &[[f64; 3]; DENSE_SAMPLE_COUNT],
    start: SigmoidPolynomial,
    target: [f64; 3],
) -> (SigmoidPolynomial, f64) {
    let mut p = start;
    let mut c = to_normalised(&p);
    let mut samples = SigmoidSamples::new(&p);
    let mut r = samples.residual(weights, target);
    let mut cost = norm2(r);
    for _ in 0..REFINE_MAX_ITERATIONS {
        if max_abs(r) <= REFINE_TOLERANCE {
            break;
        }
        let jac = samples.jacobian(weights);
        let r0 = r;
        let mut accepted = false;
        let mut try_step = |step: [f64; 3], alpha: f64| {
            let trial: [f64; 3] = std::array::from_fn(|k| c[k] + alpha * step[k]);
            if !trial.iter().all(|v| v.abs() <= REFINE_COEFFICIENT_LIMIT) {
                return false;
            }
            let p_trial = from_normalised(trial);
            let samples_trial = SigmoidSamples::new(&p_trial);
            let r_trial = samples_trial.residual(weights, target);
            let cost_trial = norm2(r_trial);
            if cost_trial < cost {
                (c, p, r, cost) = (trial, p_trial, r_trial, cost_trial);
                samples = samples_trial;
                return true;
            }
            false
        };
        // Newton, backtracking: halve the step until the residual drops.
        if let Some(step) = solve3(jac, r0.map(|v| -v)) {
            let mut alpha = 1.0;
            for _ in 0..REFINE_MAX_HALVINGS {
                if try_step(step, alpha) {
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
        }
        // Near-singular Jacobians (large coefficients) can point Newton nowhere useful:
        // fall back to Levenberg–Marquardt steps (JᵀJ + μ·tr/3·I) δ = −Jᵀr, μ growing.
        if !accepted {
            let jt = transpose3(jac);
            let jtj = mat_mul3(jt, jac);
            let g: [f64; 3] = std::array::from_fn(|p| (0..3).map(|k| jt[p][k] * r0[k]).sum());
            let scale = (jtj[0][0] + jtj[1][1] + jtj[2][2]) / 3.0;
            let mut mu = 1e-6;
            for _ in 0..8 {
                let mut a = jtj;
                for (k, row) in a.iter_mut().enumerate() {
                    row[k] += mu * scale;
                }
                if let Some(step) = solve3(a, g.map(|v| -v)) {
                    if try_step(step, 1.0) {
                        accepted = true;
                        break;
                    }
                }
                mu *= 10.0;
            }
        }
        // No stall test: colours near the solid's boundary converge through many small
        // steps from a poor lookup (a 1 % stall test left 8 reachable grid points > 1e-3).
        if !accepted {
            break;
        }
    }
    (p, max_abs(r))
}

/// Checks that every component is finite (and ≥ `min`, ≤ `max`).
fn validate_rgb(kind: &str, rgb: [f32; 3], min: f32, max: f32) -> Result<(), RgbUpsampleError> {
    if let Some(c) = rgb
        .iter()
        .find(|c| !(c.is_finite() && **c >= min && **c <= max))
    {
        let range = if max.is_finite() {
            format!("[{min}, {max}]")
        } else {
            format!("≥ {min}")
        };
        return Err(RgbUpsampleError::new(format!(
            "{kind} RGB ({}, {}, {}) has component {c}: each must be finite and {range}",
            rgb[0], rgb[1], rgb[2]
        )));
    }
    Ok(())
}

/// Linear interpolation of a 1 nm grid table (index 0 = 360 nm) at `wavelength_nm`, zero
/// outside 360–830 nm.
#[inline]
fn dense_lookup(table: &[f32; DENSE_SAMPLE_COUNT], wavelength_nm: f32) -> f32 {
    let x = wavelength_nm - LAMBDA_MIN_NM;
    // Branch-free: clamped index (NaN gives 0), select zero outside.
    let last_segment = DENSE_SAMPLE_COUNT - 2;
    let (i, i_f32) = crate::spectrum::floor_index_and_value(x, last_segment);
    let t = x - i_f32;
    let v = table[i] + t * (table[i + 1] - table[i]);
    if x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f32 {
        v
    } else {
        0.0
    }
}

/// A reflectance (or transmittance) from an RGB in [0, 1]³: values in [0, 1]
/// (pbrt-v4 `RGBAlbedoSpectrum`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbAlbedoSpectrum {
    pub polynomial: SigmoidPolynomial,
}

impl RgbAlbedoSpectrum {
    /// `rgb` is linear in `gamut`; each component must be finite and in [0, 1]. Uses the
    /// refined coefficients ([`RgbToSpectrumTable::coefficients_refined`], a few µs): for
    /// constant colours such as material parameters.
    pub fn new(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        validate_rgb("albedo", rgb, 0.0, 1.0)?;
        Ok(Self {
            polynomial: gamut.table().coefficients_refined(rgb),
        })
    }

    /// As [`RgbAlbedoSpectrum::new`] with the pure table lookup (trilinear interpolation,
    /// ~20 ns): for per-texel colours. Less accurate for saturated wide-gamut colours (see
    /// docs/rgb-upsampling.md).
    pub fn from_table(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        validate_rgb("albedo", rgb, 0.0, 1.0)?;
        Ok(Self {
            polynomial: gamut.table().coefficients(rgb),
        })
    }

    #[inline]
    pub fn eval4(&self, wavelengths_nm: [f32; 4]) -> [f32; 4] {
        self.polynomial.eval4(wavelengths_nm)
    }

    pub fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        self.polynomial.eval_f64(wavelength_nm)
    }

    pub fn max_value(&self) -> f32 {
        self.polynomial.max_value()
    }
}

/// An unbounded spectrum (e.g. a scattering coefficient) from a non-negative RGB:
/// scale · s(λ) with scale = 2 · max component and s fitted to rgb / scale, whose largest
/// component is 1/2 (pbrt-v4 `RGBUnboundedSpectrum`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbUnboundedSpectrum {
    pub scale: f32,
    pub polynomial: SigmoidPolynomial,
}

impl RgbUnboundedSpectrum {
    /// `rgb` is linear in `gamut`; each component must be finite and ≥ 0.
    pub fn new(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        validate_rgb("unbounded", rgb, 0.0, f32::INFINITY)?;
        let (scale, polynomial) = scaled_polynomial(gamut, rgb, true);
        Ok(Self { scale, polynomial })
    }

    /// As [`RgbUnboundedSpectrum::new`] with the pure table lookup (for textures).
    pub fn from_table(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        validate_rgb("unbounded", rgb, 0.0, f32::INFINITY)?;
        let (scale, polynomial) = scaled_polynomial(gamut, rgb, false);
        Ok(Self { scale, polynomial })
    }

    #[inline]
    pub fn eval4(&self, wavelengths_nm: [f32; 4]) -> [f32; 4] {
        self.polynomial
            .eval4(wavelengths_nm)
            .map(|v| v * self.scale)
    }

    pub fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        self.scale as f64 * self.polynomial.eval_f64(wavelength_nm)
    }

    pub fn max_value(&self) -> f32 {
        self.scale * self.polynomial.max_value()
    }
}

/// scale = 2 · max(rgb) and the polynomial of rgb / scale (pbrt-v4), refined or looked up;
/// black → (0, flat 0).
fn scaled_polynomial(gamut: RgbGamut, rgb: [f32; 3], refined: bool) -> (f32, SigmoidPolynomial) {
    let scale = 2.0 * rgb[0].max(rgb[1]).max(rgb[2]);
    let normalised = if scale > 0.0 {
        rgb.map(|c| c / scale)
    } else {
        [0.0; 3]
    };
    let table = gamut.table();
    let polynomial = if refined {
        table.coefficients_refined(normalised)
    } else {
        table.coefficients(normalised)
    };
    (scale, polynomial)
}

/// An emission spectrum from a non-negative RGB: the unbounded spectrum times the space's
/// white illuminant (normalised to luminance Y = 1, see [`RgbGamut::white_illuminant`]), so
/// RGB (1, 1, 1) emits the white illuminant itself (pbrt-v4 `RGBIlluminantSpectrum`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbIlluminantSpectrum {
    pub scale: f32,
    pub polynomial: SigmoidPolynomial,
    illuminant: &'static [f32; DENSE_SAMPLE_COUNT],
}

impl RgbIlluminantSpectrum {
    /// `rgb` is linear in `gamut`; each component must be finite and ≥ 0.
    pub fn new(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        Self::build(gamut, rgb, true)
    }

    /// As [`RgbIlluminantSpectrum::new`] with the pure table lookup (for textures).
    pub fn from_table(gamut: RgbGamut, rgb: [f32; 3]) -> Result<Self, RgbUpsampleError> {
        Self::build(gamut, rgb, false)
    }

    fn build(gamut: RgbGamut, rgb: [f32; 3], refined: bool) -> Result<Self, RgbUpsampleError> {
        validate_rgb("illuminant", rgb, 0.0, f32::INFINITY)?;
        let (scale, polynomial) = scaled_polynomial(gamut, rgb, refined);
        Ok(Self {
            scale,
            polynomial,
            illuminant: gamut.white_illuminant(),
        })
    }

    /// This spectrum multiplied by `factor` (the scale absorbs it).
    pub fn scaled(self, factor: f32) -> Self {
        Self {
            scale: self.scale * factor,
            ..self
        }
    }

    /// The white illuminant on the 1 nm grid (360–830 nm).
    pub fn illuminant(&self) -> &'static [f32; DENSE_SAMPLE_COUNT] {
        self.illuminant
    }

    #[inline]
    pub fn eval4(&self, wavelengths_nm: [f32; 4]) -> [f32; 4] {
        let s = self.polynomial.eval4(wavelengths_nm);
        std::array::from_fn(|i| {
            self.scale * s[i] * dense_lookup(self.illuminant, wavelengths_nm[i])
        })
    }

    pub fn eval_nm(&self, wavelength_nm: f64) -> f64 {
        let x = wavelength_nm - LAMBDA_MIN_NM as f64;
        let illum = if x >= 0.0 && x <= (DENSE_SAMPLE_COUNT - 1) as f64 {
            let i = (x as usize).min(DENSE_SAMPLE_COUNT - 2);
            let t = x - i as f64;
            let (a, b) = (self.illuminant[i] as f64, self.illuminant[i + 1] as f64);
            a + t * (b - a)
        } else {
            0.0
        };
        self.scale as f64 * self.polynomial.eval_f64(wavelength_nm) * illum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigmoid_handles_extremes_without_nan() {
        assert_eq!(sigmoid_f32(f32::INFINITY), 1.0);
        assert_eq!(sigmoid_f32(f32::NEG_INFINITY), 0.0);
        assert_eq!(sigmoid_f32(0.0), 0.5);
        assert_eq!(SigmoidPolynomial::constant(1.0).eval(500.0), 1.0);
        assert_eq!(SigmoidPolynomial::constant(0.0).eval(500.0), 0.0);
        assert!((SigmoidPolynomial::constant(0.25).eval(700.0) - 0.25).abs() < 1e-6);
    }

    #[test]
    fn max_value_finds_an_interior_peak() {
        // Peak of a downward parabola at 550 nm: x(550) = 2.
        let c0 = -1e-4f32;
        let p = SigmoidPolynomial::new(c0, -2.0 * c0 * 550.0, 2.0 + c0 * 550.0 * 550.0);
        assert!((p.max_value() - sigmoid_f32(2.0)).abs() < 1e-4);
        assert!(p.max_value() > p.eval(360.0) && p.max_value() > p.eval(830.0));
    }

    #[test]
    fn z_nodes_run_from_0_to_1_densest_at_the_ends() {
        let z = z_nodes(32);
        assert_eq!((z[0], z[31]), (0.0, 1.0));
        assert!(z[1] - z[0] < z[16] - z[15]);
    }

    #[test]
    fn tables_round_trip_through_bytes_and_reject_damage() {
        let res = 2;
        let coeffs: Vec<f32> = (0..3 * 8 * 3).map(|i| i as f32).collect();
        let t = RgbToSpectrumTable::new(res, "test", z_nodes(res), coeffs).unwrap();
        let bytes = t.to_bytes();
        assert_eq!(RgbToSpectrumTable::from_bytes(&bytes).unwrap(), t);
        assert!(RgbToSpectrumTable::from_bytes(&bytes[..bytes.len() - 4]).is_err());
        assert!(RgbToSpectrumTable::from_bytes(&bytes[..20]).is_err());
        assert!(RgbToSpectrumTable::from_bytes(b"NOTATABLE").is_err());
        assert_eq!(t.node(1, 0, 1, 0), [30.0, 31.0, 32.0]);
    }

    #[test]
    fn embedded_tables_parse_and_name_their_gamut() {
        for gamut in RgbGamut::ALL {
            let t = gamut.table();
            assert_eq!(t.gamut_name(), gamut.name());
            assert_eq!(t.z_nodes(), z_nodes(t.resolution()).as_slice());
        }
    }

    #[test]
    fn constructors_reject_bad_input_with_a_message() {
        let e = RgbAlbedoSpectrum::new(RgbGamut::Srgb, [0.5, 1.5, 0.0]).unwrap_err();
        assert!(
            e.message.contains("1.5") && e.message.contains("[0, 1]"),
            "{e}"
        );
        assert!(RgbAlbedoSpectrum::new(RgbGamut::Srgb, [f32::NAN, 0.0, 0.0]).is_err());
        assert!(RgbUnboundedSpectrum::new(RgbGamut::Srgb, [-0.1, 0.0, 0.0]).is_err());
        assert!(RgbIlluminantSpectrum::new(RgbGamut::Srgb, [f32::INFINITY, 0.0, 0.0]).is_err());
        // Unbounded RGB above 1 is valid, scaled by 2 · max component (pbrt-v4's
        // RGBUnboundedSpectrum).
        let bright = RgbUnboundedSpectrum::new(RgbGamut::Srgb, [7.0, 0.0, 0.0]).unwrap();
        assert_eq!(bright.scale, 14.0);
        assert_eq!(RgbGamut::from_name("ACEScg"), Ok(RgbGamut::AcesCg));
        assert!(RgbGamut::from_name("p3")
            .unwrap_err()
            .message
            .contains("srgb"));
    }

    #[test]
    fn centred_f32_evaluation_matches_the_nm_polynomial() {
        // A saturated band-pass: normalised coefficients ~1e4.
        let p = from_normalised([-2.0e4, 2.1e4, -5.4e3]);
        for nm in [360.0f32, 480.0, 520.0, 525.5, 600.0, 830.0] {
            let reference = p.eval_f64(nm as f64);
            assert!(
                (p.eval(nm) as f64 - reference).abs() < 1e-4,
                "{nm}: {} vs {reference}",
                p.eval(nm)
            );
        }
        let back = to_normalised(&p);
        assert!((back[0] / -2.0e4 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn refinement_never_increases_the_rgb_error_and_reaches_saturated_colours() {
        // Reachable colours (LP-checked in tests/rgb_upsample.rs), the last two saturated
        // ones whose table lookup is off by 1e-2.
        for (gamut, saturated) in [
            (RgbGamut::Srgb, [[0.9f32, 0.1, 0.05], [0.05, 0.9, 0.1]]),
            (
                RgbGamut::Rec2020,
                [[0.5625, 0.0, 0.25], [0.0625, 0.8125, 0.1875]],
            ),
            (
                RgbGamut::AcesCg,
                [[0.0625, 0.8125, 0.25], [0.125, 0.8125, 0.8125]],
            ),
        ] {
            let weights = gamut.reflectance_rgb_weights();
            for rgb in [[0.6875f32, 0.1875, 0.125], [0.125, 0.125, 0.875]]
                .into_iter()
                .chain(saturated)
            {
                let target = rgb.map(|c| c as f64);
                let lookup = gamut.table().coefficients(rgb);
                let refined = gamut.table().coefficients_refined(rgb);
                let e_lookup = max_abs(rgb_residual(weights, &lookup, target));
                let e_refined = max_abs(rgb_residual(weights, &refined, target));
                assert!(e_refined <= e_lookup, "{} {rgb:?}", gamut.name());
                assert!(
                    e_refined < 1e-4,
                    "{} {rgb:?}: {e_refined:.2e}",
                    gamut.name()
                );
            }
        }
        // Light colours whose lookup lands in a steep basin (|A| ~ 1e4 where ~1e3 fits):
        // Newton needs more than 8 steps here (8 left 6.0e-4 and 3.2e-4).
        for (gamut, rgb) in [
            (RgbGamut::Rec2020, [0.9375f32, 0.25, 0.125]),
            (RgbGamut::AcesCg, [0.9375, 0.9375, 1.0]),
        ] {
            let weights = gamut.reflectance_rgb_weights();
            let refined = gamut.table().coefficients_refined(rgb);
            let e = max_abs(rgb_residual(weights, &refined, rgb.map(|c| c as f64)));
            assert!(e < 1e-5, "{} {rgb:?}: {e:.2e}", gamut.name());
        }
        // A table that names no built-in gamut has no colorimetry to refine against.
        let t = RgbToSpectrumTable::new(2, "test", z_nodes(2), vec![0.0; 3 * 8 * 3]).unwrap();
        assert_eq!(t.gamut(), None);
        assert_eq!(
            t.coefficients_refined([0.2, 0.5, 0.1]),
            t.coefficients([0.2, 0.5, 0.1])
        );
    }

    #[test]
    fn black_unbounded_and_illuminant_spectra_are_zero() {
        let u = RgbUnboundedSpectrum::new(RgbGamut::Srgb, [0.0; 3]).unwrap();
        assert_eq!(u.eval4([400.0, 500.0, 600.0, 700.0]), [0.0; 4]);
        let i = RgbIlluminantSpectrum::new(RgbGamut::AcesCg, [0.0; 3]).unwrap();
        assert_eq!(i.eval_nm(555.0), 0.0);
    }
}

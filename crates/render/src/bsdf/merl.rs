//! Measured isotropic BRDFs in the MERL format (W. Matusik, H. Pfister, M. Brand and
//! L. McMillan, "A data-driven reflectance model", SIGGRAPH 2003; the database's reference
//! reader `BRDFRead.cpp`).
//!
//! **File format.** Three little-endian `i32` dimensions (90, 90, 180), then
//! 3 × 90·90·180 little-endian `f64`: the red, green and blue tables one after the other.
//! Entry (i_h, i_d, i_φ) sits at i_φ + 180 i_d + 180·90 i_h of each table and holds the
//! BRDF (1/sr) divided by the channel's scale: red 1/1500, green 1.15/1500, blue 1.66/1500.
//!
//! **Parameterisation** (Rusinkiewicz 1998 half/difference angles): ω_h = (ωᵢ + ωₒ)/|·|
//! at (θ_h, φ_h); the difference vector is ωᵢ rotated by −φ_h about the normal and by −θ_h
//! about the bitangent, at (θ_d, φ_d). Indices as `BRDFRead.cpp`: i_h = ⌊√(θ_h/(π/2))·90⌋
//! (the square-root map packs bins near the specular peak), i_d = ⌊θ_d/(π/2)·90⌋,
//! (θ from a polynomial arccos accurate to 2·10⁻⁸ rad, `acos_fast`; φ_d from a polynomial
//! atan2 accurate to 5·10⁻⁷ rad, `atan2_upper`; 7 in 200 000 random pairs land in the
//! neighbour of the f64 reference's bin, all within 10⁻³ bins of an edge),
//! i_φ = ⌊φ_d/π·180⌋ after folding φ_d < 0 by +π (reciprocity), each clamped to the table.
//! The lookup is the reference code's: nearest bin, no interpolation, so the table is
//! piecewise constant; `MerlTable::from_fn` writes each bin's midpoint (in index space).
//!
//! **Reading** (`MerlTable::from_bytes`): the header must be (90, 90, 180), the body
//! exactly 3·90·90·180 doubles (a truncated or overlong file is refused with both sizes),
//! every value finite; negative entries (measurement artefacts in some database files) are
//! refused with their count and first bin unless the caller asks to clamp them to 0.
//!
//! **Spectral use** (`MerlBrdf`): each bin's linear sRGB triple is upsampled with the
//! Jakob–Hanika sigmoid table (`RgbUnboundedSpectrum` form: scale 2·max(RGB), the table's
//! coefficients for RGB/scale; grey gives an exactly flat spectrum). A bin stores the scale
//! (f32) and its chromaticity as the table's own (x, y) coordinates in 1/512 of a cell
//! (8 bytes per bin, 11.7 MB, on transparent huge pages where Linux offers them); an
//! evaluation looks up one bin, interpolates the sigmoid coefficients from the table's
//! z = ½ slice (256 KB, in cache) as the table lookup does, and evaluates the sigmoid at the
//! path's four wavelengths. Against the unpacked upsampling the packing changes the
//! spectrum by at most 2.7·10⁻⁴ relative (measured over the sRGB chromaticities,
//! 360–830 nm: `packed_chromaticity_error_is_as_stated`); grey bins are exact.
//!
//! **Sampling** by tabulated CDF inversion in half-vector space, per incident angle: for
//! 32 bins of θₒ a piecewise-constant density over (u, v) ∈ [0,1)², θ_h = (π/2)u² (the
//! table's own square-root map) and φ_h = φₒ + 2πv, proportional to the luminance of
//! f·cos θᵢ times the Jacobians (4 ωₒ·ω_h for reflection, sin θ_h·πu·2π for the map),
//! evaluated at each cell's centre with ωₒ at the bin's centre. A sample inverts the
//! marginal CDF over the 64 θ_h rows, then the row's conditional CDF over the 64 φ cells,
//! and reflects ωₒ about ω_h; its density is the cell's value over the Jacobians,
//! exact for any ωₒ (the bin only decides which table is used). A defensive 10 % of cosine
//! sampling (Hesterberg 1995) covers bins whose centre missed a thin lobe.

use std::fmt;
use std::path::Path;

use glam::{Vec2, Vec3A};
use prism_spectrum::{RgbGamut, SampledSpectrum};
use rayon::prelude::*;

use super::{bandwidth_from_alpha, estimate_albedo, BsdfSample, Bxdf, TransportMode};
use crate::sampling::sample_cosine_hemisphere;

/// θ_h bins.
pub const MERL_THETA_H: usize = 90;
/// θ_d bins.
pub const MERL_THETA_D: usize = 90;
/// φ_d bins (over [0, π)).
pub const MERL_PHI_D: usize = 180;
/// Entries per colour channel.
pub const MERL_ENTRIES: usize = MERL_THETA_H * MERL_THETA_D * MERL_PHI_D;
/// Scale of each channel (`BRDFRead.cpp` RED_SCALE, GREEN_SCALE, BLUE_SCALE).
pub const MERL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Bytes of a well-formed file.
pub const MERL_FILE_BYTES: usize = 12 + 3 * MERL_ENTRIES * 8;

/// θₒ bins of the sampling tables. The tables (32·64·64 cells, 0.5 MB of densities and
/// 0.5 MB of CDFs) stay in the processor's caches; the 90·180 resolution of the table itself
/// (6 MB) made sampling 3× slower through cache misses alone, for no visible gain (the pdf
/// is exact either way; only how closely it follows f·cos changes).
const SAMPLE_THETA_O: usize = 32;
/// θ_h rows (u) of a sampling table.
const SAMPLE_U: usize = 64;
/// φ_h columns (v) of a sampling table, over the full circle.
const SAMPLE_V: usize = 64;
/// Fraction of cosine-weighted samples (defensive mixture).
const COSINE_FRACTION: f32 = 0.1;

/// What went wrong reading or writing a MERL file.
pub type MerlError = crate::file_error::FileError;

/// (i_h, i_d, i_φ) of a flat index.
pub fn merl_bin(index: usize) -> (usize, usize, usize) {
    (
        index / (MERL_THETA_D * MERL_PHI_D),
        (index / MERL_PHI_D) % MERL_THETA_D,
        index % MERL_PHI_D,
    )
}

/// The angles (θ_h, θ_d, φ_d) in radians at the midpoint of a bin in index space.
pub fn merl_bin_centre(i_h: usize, i_d: usize, i_phi: usize) -> (f64, f64, f64) {
    use std::f64::consts::{FRAC_PI_2, PI};
    let u = (i_h as f64 + 0.5) / MERL_THETA_H as f64;
    (
        u * u * FRAC_PI_2,
        (i_d as f64 + 0.5) / MERL_THETA_D as f64 * FRAC_PI_2,
        (i_phi as f64 + 0.5) / MERL_PHI_D as f64 * PI,
    )
}

/// (ωᵢ, ωₒ) in the local frame for half/difference angles, φ_h = 0 (isotropy): the
/// difference vector and its mirror about the half vector, rotated by θ_h about y. A
/// direction the bin's centre puts below the horizon is lifted to z = 10⁻⁴ (renormalised):
/// such bins straddle the horizon and are looked up only by upper-hemisphere pairs near
/// that edge, so the nearest upper configuration is the value they need (a Lambertian
/// source then exports exactly 1/π·ρ in every bin).
pub fn merl_directions(theta_h: f64, theta_d: f64, phi_d: f64) -> (Vec3A, Vec3A) {
    let (wi, wo) = merl_directions_raw(theta_h, theta_d, phi_d);
    let lift = |w: Vec3A| {
        if w.z < 1e-4 {
            Vec3A::new(w.x, w.y, 1e-4).normalize()
        } else {
            w
        }
    };
    (lift(wi), lift(wo))
}

/// As [`merl_directions`] without lifting (may lie below the horizon).
pub fn merl_directions_raw(theta_h: f64, theta_d: f64, phi_d: f64) -> (Vec3A, Vec3A) {
    let (st_d, ct_d) = theta_d.sin_cos();
    let (sp_d, cp_d) = phi_d.sin_cos();
    let (st_h, ct_h) = theta_h.sin_cos();
    let d = [st_d * cp_d, st_d * sp_d, ct_d];
    let rot = |x: f64, y: f64, z: f64| {
        Vec3A::new(
            (ct_h * x + st_h * z) as f32,
            y as f32,
            (-st_h * x + ct_h * z) as f32,
        )
    };
    (rot(d[0], d[1], d[2]), rot(-d[0], -d[1], d[2]))
}

/// arccos for x ∈ [−1, 1] by Abramowitz & Stegun 4.4.46 (|error| ≤ 2·10⁻⁸ rad, below the
/// f32 rounding of the result): √(1 − x)·Σ aₖxᵏ on [0, 1], π − acos(−x) below. About 3×
/// faster than the library acosf, and the lookup needs two per evaluation.
#[inline]
// a₀ = 1.5707963050 is the published fit's coefficient, not π/2.
#[allow(clippy::approx_constant)]
fn acos_fast(x: f32) -> f32 {
    let a = x.abs().min(1.0);
    let p = 1.570_796_3
        + a * (-0.214_598_8
            + a * (0.088_978_99
                + a * (-0.050_174_304
                    + a * (0.030_891_88
                        + a * (-0.017_088_126 + a * (0.006_670_09 + a * -0.001_262_491))))));
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 {
        std::f32::consts::PI - r
    } else {
        r
    }
}

/// arctan on [0, 1]: the odd minimax polynomial of SLEEF's `xatanf` (|error| ≤ 4.5·10⁻⁸
/// rad in exact arithmetic, below the f32 rounding of the result).
#[inline]
fn atan_unit(s: f32) -> f32 {
    let t = s * s;
    let mut u = 0.002_823_639;
    u = u * t - 0.015_956_903;
    u = u * t + 0.042_504_99;
    u = u * t - 0.074_890_09;
    u = u * t + 0.106_347_93;
    u = u * t - 0.142_027_36;
    u = u * t + 0.199_926_96;
    u = u * t - 0.333_331_02;
    s + s * (t * u)
}

/// atan2(y, x) ∈ [0, π] for y ≥ 0 (0 for the zero vector, as `atan2(0, 0)`): octant
/// reduction to [0, 1] and [`atan_unit`], branch-free (selects), one division. Replaces
/// libm's atan2f (several times slower, with data-dependent branches) in the lookup.
#[inline]
fn atan2_upper(y: f32, x: f32) -> f32 {
    let ax = x.abs();
    let (lo, hi) = (y.min(ax), y.max(ax));
    let a = atan_unit(if hi > 0.0 { lo / hi } else { 0.0 });
    let a = if y > ax {
        std::f32::consts::FRAC_PI_2 - a
    } else {
        a
    };
    if x < 0.0 {
        std::f32::consts::PI - a
    } else {
        a
    }
}

/// The bin `BRDFRead.cpp` reads for a pair of upper-hemisphere directions, from the half
/// vector `h` (unit, upper) and ωᵢ, without forming the rotated difference vector: its z
/// is cos θ_d = ωᵢ·h, and its azimuth is taken from the rotated (x, y) scaled by sin θ_h > 0,
/// which leaves atan2 unchanged and saves the divisions by sin θ_h.
#[inline]
fn lookup_index(h: Vec3A, wi: Vec3A) -> usize {
    let cos_h = h.z.min(1.0);
    let sin_h2 = h.x * h.x + h.y * h.y;
    let sin_h = sin_h2.sqrt();
    // Rotating ωᵢ by −φ_h about z, then by −θ_h about y: with (cos φ_h, sin φ_h) =
    // (h.x, h.y)/sin θ_h, x₁ sin θ_h = h.x ωᵢ.x + h.y ωᵢ.y, y₁ sin θ_h = h.x ωᵢ.y − h.y ωᵢ.x,
    // d.x sin θ_h = cos θ_h x₁ sin θ_h − sin²θ_h ωᵢ.z. Along the normal φ_h = 0 (the reference
    // reader's convention).
    let (mut y, mut x) = if sin_h > 1e-7 {
        let x1 = h.x * wi.x + h.y * wi.y;
        (h.x * wi.y - h.y * wi.x, cos_h * x1 - sin_h2 * wi.z)
    } else {
        (wi.y, cos_h * wi.x - sin_h * wi.z)
    };
    // φ_d < 0 folds by +π (reciprocity): the same as negating both components.
    if y < 0.0 {
        y = -y;
        x = -x;
    }
    let phi_d = atan2_upper(y, x);
    let theta_h = acos_fast(cos_h);
    let theta_d = acos_fast(h.dot(wi).clamp(-1.0, 1.0));
    let i_h =
        ((theta_h * std::f32::consts::FRAC_2_PI).max(0.0).sqrt() * MERL_THETA_H as f32) as usize;
    let i_d = (theta_d * std::f32::consts::FRAC_2_PI * MERL_THETA_D as f32) as usize;
    let i_phi = (phi_d * std::f32::consts::FRAC_1_PI * MERL_PHI_D as f32) as usize;
    i_phi.min(MERL_PHI_D - 1)
        + MERL_PHI_D * (i_d.min(MERL_THETA_D - 1) + MERL_THETA_D * i_h.min(MERL_THETA_H - 1))
}

/// The raw table: BRDF values in 1/sr (channel scales applied), red, green, blue tables
/// in file order.
#[derive(Clone, PartialEq)]
pub struct MerlTable {
    /// 3 × `MERL_ENTRIES` values.
    pub values: Vec<f64>,
}

impl fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "MerlTable({} entries)", self.values.len() / 3)
    }
}

impl MerlTable {
    /// A table from each bin's RGB BRDF (1/sr) at `(θ_h, θ_d, φ_d)` (the bin midpoint,
    /// `merl_bin_centre`), filled in parallel.
    pub fn from_fn(f: impl Fn(f64, f64, f64) -> [f64; 3] + Sync) -> Self {
        let rgb: Vec<[f64; 3]> = (0..MERL_ENTRIES)
            .into_par_iter()
            .map(|index| {
                let (i_h, i_d, i_phi) = merl_bin(index);
                let (th, td, pd) = merl_bin_centre(i_h, i_d, i_phi);
                f(th, td, pd)
            })
            .collect();
        let mut values = vec![0.0; 3 * MERL_ENTRIES];
        for (index, v) in rgb.iter().enumerate() {
            for c in 0..3 {
                values[c * MERL_ENTRIES + index] = v[c];
            }
        }
        Self { values }
    }

    /// RGB of bin `index`, 1/sr.
    #[inline]
    pub fn rgb(&self, index: usize) -> [f64; 3] {
        [
            self.values[index],
            self.values[MERL_ENTRIES + index],
            self.values[2 * MERL_ENTRIES + index],
        ]
    }

    /// The table's value for a pair of local directions (0 when either is below the
    /// surface), by `BRDFRead.cpp`'s lookup.
    pub fn lookup(&self, wo: Vec3A, wi: Vec3A) -> [f64; 3] {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return [0.0; 3];
        }
        self.rgb(lookup_index((wo + wi).normalize(), wi))
    }

    /// Parses a file's bytes (see the module docs); `clamp_negative` turns negative
    /// entries into 0 instead of refusing them.
    pub fn from_bytes(bytes: &[u8], clamp_negative: bool) -> Result<Self, MerlError> {
        if bytes.len() < 12 {
            return Err(MerlError::new(format!(
                "not a MERL BRDF: {} bytes, shorter than the 12-byte header",
                bytes.len()
            )));
        }
        let dim = |k: usize| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
        let dims = [dim(0), dim(1), dim(2)];
        if dims != [90, 90, 180] {
            return Err(MerlError::new(format!(
                "header gives table dimensions {dims:?}; a MERL BRDF has [90, 90, 180] \
                 (θ_h, θ_d, φ_d)"
            )));
        }
        if bytes.len() != MERL_FILE_BYTES {
            let what = if bytes.len() < MERL_FILE_BYTES {
                "truncated"
            } else {
                "too long"
            };
            return Err(MerlError::new(format!(
                "{what}: {} bytes, a MERL BRDF has exactly {MERL_FILE_BYTES} (12-byte header \
                 + 3 × 90·90·180 doubles)",
                bytes.len()
            )));
        }
        let mut values: Vec<f64> = bytes[12..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let mut negative = 0usize;
        let mut first_negative = None;
        for (k, v) in values.iter_mut().enumerate() {
            let channel = k / MERL_ENTRIES;
            if !v.is_finite() {
                let (i_h, i_d, i_phi) = merl_bin(k % MERL_ENTRIES);
                return Err(MerlError::new(format!(
                    "value {v} in the {} table at bin (θ_h {i_h}, θ_d {i_d}, φ_d {i_phi}) is \
                     not finite",
                    ["red", "green", "blue"][channel]
                )));
            }
            if *v < 0.0 {
                negative += 1;
                first_negative.get_or_insert((k, *v));
                if clamp_negative {
                    *v = 0.0;
                }
            }
            *v *= MERL_SCALE[channel];
        }
        if let (Some((k, v)), false) = (first_negative, clamp_negative) {
            let (i_h, i_d, i_phi) = merl_bin(k % MERL_ENTRIES);
            return Err(MerlError::new(format!(
                "{negative} negative entries (first: {v} in the {} table at bin (θ_h {i_h}, \
                 θ_d {i_d}, φ_d {i_phi})); a BRDF is ≥ 0 — set \"clamp_negative\": true to \
                 read them as 0",
                ["red", "green", "blue"][k / MERL_ENTRIES]
            )));
        }
        Ok(Self { values })
    }

    /// Reads a file (see `from_bytes`).
    pub fn read(path: &Path, clamp_negative: bool) -> Result<Self, MerlError> {
        let bytes = std::fs::read(path)
            .map_err(|e| MerlError::new(format!("cannot read: {e}")).at(path))?;
        Self::from_bytes(&bytes, clamp_negative).map_err(|e| e.at(path))
    }

    /// The file's bytes (values divided by the channel scales).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(MERL_FILE_BYTES);
        for d in [90i32, 90, 180] {
            out.extend_from_slice(&d.to_le_bytes());
        }
        for (k, v) in self.values.iter().enumerate() {
            out.extend_from_slice(&(v / MERL_SCALE[k / MERL_ENTRIES]).to_le_bytes());
        }
        out
    }

    /// Writes the file through a temporary file in the same folder, renamed into place, so
    /// a failure never leaves a half-written table (`prism_image::io`'s atomic write, the
    /// one every output takes).
    pub fn write(&self, path: &Path) -> Result<(), MerlError> {
        prism_image::io::write_bytes_atomically(path, &self.to_bytes())
            .map_err(|e| MerlError::new(format!("cannot write the table: {e}")))
    }
}

/// One bin, 8 bytes: the spectrum scale (exact f32, as the RGB→spectrum step gives it) and
/// the bin's chromaticity in the sRGB sigmoid table's own coordinates (`ChromaSlice`), so
/// the 1.46 M-bin table is 11.7 MB instead of 23 MB of f32 coefficients and scale: the
/// lookup of incoherent directions is a cache and TLB miss, and its cost follows the size.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(8))]
struct PackedBin {
    scale: f32,
    /// Bits 30–31: the largest channel (0 R, 1 G, 2 B; 3 grey, a flat ½), bits 15–29 and
    /// 0–14: the table coordinates y and x of the other two channels over the largest,
    /// each in [0, res − 1], in steps of 1/`CHROMA_STEPS` of a table cell.
    chroma: u32,
}

/// Steps per table cell of the stored chromaticity coordinates (15 bits hold
/// 63 · 512 = 32 256 for the 64-node sRGB table).
const CHROMA_STEPS: u32 = 512;
/// log₂ `CHROMA_STEPS`.
const CHROMA_SHIFT: u32 = 9;
/// Chromaticity code of a grey (flat) bin.
const CHROMA_GREY: u32 = 3 << 30;
/// Centre and half-width (nm) of the evaluation variable t = (λ − 595 nm)/235 nm ∈ [−1, 1]
/// over 360–830 nm, in which the polynomial's terms stay of the order of its value.
const T_CENTRE_NM: f64 = 595.0;
const T_HALF_WIDTH_NM: f64 = 235.0;
/// The sigmoid's argument limit of `prism_spectrum` (x² stays finite in f32).
const SIGMOID_ARG_LIMIT: f32 = 1.0e18;

/// The Jakob–Hanika coefficient table at z = ½, the only brightness `MerlBrdf` asks it for
/// (each bin's RGB is divided by twice its largest channel): the two z slices around ½
/// blended as `RgbToSpectrumTable::coefficients` blends them, each node's polynomial
/// rewritten in t (in f64, rounded once; the map is linear, so bilinear interpolation in
/// (x, y) commutes with it), plus an all-zero slice for grey bins (S(0) = ½ exactly).
/// 4 × 64 × 64 nodes of 16 bytes: 256 KB, resident in the L2 cache.
struct ChromaSlice {
    resolution: usize,
    /// (largest channel, y, x) → (a, b, c, 0) of a t² + b t + c.
    nodes: Vec<[f32; 4]>,
}

impl ChromaSlice {
    fn new(table: &prism_spectrum::RgbToSpectrumTable) -> Self {
        let res = table.resolution();
        assert!(
            (res - 1) as u32 * CHROMA_STEPS < 1 << 15,
            "RGB→spectrum table resolution {res} too fine for 15-bit chromaticity codes"
        );
        let z_nodes = table.z_nodes();
        // As `coefficients`: the largest zi with z_nodes[zi] < z, within [0, res − 2].
        let z = 0.5f32;
        let zi = z_nodes
            .partition_point(|&n| n < z)
            .saturating_sub(1)
            .min(res - 2);
        let dz = (z - z_nodes[zi]) / (z_nodes[zi + 1] - z_nodes[zi]);
        let mut nodes = vec![[0.0f32; 4]; 4 * res * res];
        for m in 0..3 {
            for yi in 0..res {
                for xi in 0..res {
                    let (n0, n1) = (table.node(m, zi, yi, xi), table.node(m, zi + 1, yi, xi));
                    let c: [f64; 3] =
                        std::array::from_fn(|i| f64::from(n0[i] + dz * (n1[i] - n0[i])));
                    let (l, w) = (T_CENTRE_NM, T_HALF_WIDTH_NM);
                    // c₀λ² + c₁λ + c₂ with λ = L + W t.
                    nodes[(m * res + yi) * res + xi] = [
                        (c[0] * w * w) as f32,
                        ((2.0 * c[0] * l + c[1]) * w) as f32,
                        ((c[0] * l + c[1]) * l + c[2]) as f32,
                        0.0,
                    ];
                }
            }
        }
        Self {
            resolution: res,
            nodes,
        }
    }

    /// The chromaticity code of an RGB whose largest channel is ½ (not grey), with the
    /// channel choice and coordinates of `RgbToSpectrumTable::coefficients`.
    fn encode(&self, rgb: [f32; 3]) -> u32 {
        let rgb = rgb.map(|c| c.max(0.0).clamp(0.0, 1.0));
        let m = if rgb[0] > rgb[1] {
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
        let last = (self.resolution - 1) as f32;
        let z = rgb[m];
        let code = |v: f32| -> u32 {
            let x = (v * last / z).clamp(0.0, last);
            ((f64::from(x) * f64::from(CHROMA_STEPS)).round() as u32)
                .min((self.resolution as u32 - 1) * CHROMA_STEPS)
        };
        ((m as u32) << 30) | (code(rgb[(m + 2) % 3]) << 15) | code(rgb[(m + 1) % 3])
    }

    /// (a, b, c) of a code: bilinear interpolation of the four surrounding nodes.
    #[inline]
    fn coefficients(&self, chroma: u32) -> [f32; 4] {
        let res = self.resolution;
        let m = (chroma >> 30) as usize;
        let split = |c: u32| -> (usize, f32) {
            let i = ((c >> CHROMA_SHIFT) as usize).min(res - 2);
            let f = (c - ((i as u32) << CHROMA_SHIFT)) as f32 * (1.0 / CHROMA_STEPS as f32);
            (i, f)
        };
        let (xi, fx) = split(chroma & 0x7fff);
        let (yi, fy) = split((chroma >> 15) & 0x7fff);
        let base = (m * res + yi) * res + xi;
        let n = &self.nodes[base..base + res + 2];
        let lerp = |f: f32, a: [f32; 4], b: [f32; 4]| -> [f32; 4] {
            std::array::from_fn(|i| a[i] + f * (b[i] - a[i]))
        };
        lerp(fy, lerp(fx, n[0], n[1]), lerp(fx, n[res], n[res + 1]))
    }
}

/// scale × S(a t² + b t + c) at four wavelengths, S(x) = ½ + x/(2√(1 + x²)).
#[inline]
fn sigmoid_spectrum(coef: [f32; 4], scale: f32, lambda_nm: [f32; 4]) -> SampledSpectrum {
    let [a, b, c, _] = coef;
    SampledSpectrum::new(lambda_nm.map(|l| {
        let t = (l - T_CENTRE_NM as f32) * (1.0 / T_HALF_WIDTH_NM as f32);
        let x = ((a * t + b) * t + c).clamp(-SIGMOID_ARG_LIMIT, SIGMOID_ARG_LIMIT);
        scale * (0.5 + 0.5 * x / (1.0 + x * x).sqrt())
    }))
}

/// A measured BRDF ready to render: per-bin spectra and the sampling tables.
pub struct MerlBrdf {
    bins: Vec<PackedBin>,
    chroma: ChromaSlice,
    /// Per θₒ bin: the normalised density of each (u, v) cell, row-major (u rows).
    cell_pdf: Vec<f32>,
    /// Per θₒ bin: the CDF over rows, `SAMPLE_U + 1` values from 0 to 1.
    row_cdf: Vec<f32>,
    /// Per θₒ bin and row: the conditional CDF over cells, `SAMPLE_V + 1` values.
    cell_cdf: Vec<f32>,
    /// Per θₒ bin: true when the tabulated density has mass (else pure cosine sampling).
    has_table: Vec<bool>,
    /// Guide tables (`GUIDE` + 1 entries) of `row_cdf` and of each row of `cell_cdf`.
    row_guide: Vec<u8>,
    cell_guide: Vec<u8>,
    /// An equivalent Beckmann roughness of the specular peak (for the bandwidth predictor):
    /// √(mean tan²θ_h) of the f·cos-weighted half vectors at θₒ ≈ 0.
    pub equivalent_alpha: f32,
}

impl fmt::Debug for MerlBrdf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "MerlBrdf(α_eq {})", self.equivalent_alpha)
    }
}

impl PartialEq for MerlBrdf {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

/// One θₒ bin's sampling tables: cell densities, row CDF, per-row cell CDFs, has mass.
type ThetaOTables = (Vec<f32>, Vec<f32>, Vec<f32>, bool);

/// Luminance weights of linear sRGB (ITU-R BT.709 Y row).
const LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

impl MerlBrdf {
    /// Upsamples every bin and builds the sampling tables.
    pub fn new(table: &MerlTable) -> Self {
        let chroma = ChromaSlice::new(RgbGamut::Srgb.table());
        let mut bins = Vec::with_capacity(MERL_ENTRIES);
        advise_huge_pages(&bins);
        (0..MERL_ENTRIES)
            .into_par_iter()
            .map(|index| {
                let rgb = table.rgb(index).map(|v| v as f32);
                let max = rgb[0].max(rgb[1]).max(rgb[2]);
                if max <= 0.0 {
                    return PackedBin {
                        scale: 0.0,
                        chroma: CHROMA_GREY,
                    };
                }
                let min = rgb[0].min(rgb[1]).min(rgb[2]);
                // Grey within f32 rounding of the channel scales: exactly flat.
                if max - min <= 1e-6 * max {
                    PackedBin {
                        scale: 2.0 * (rgb[0] + rgb[1] + rgb[2]) / 3.0,
                        chroma: CHROMA_GREY,
                    }
                } else {
                    PackedBin {
                        scale: 2.0 * max,
                        chroma: chroma.encode(rgb.map(|c| c / (2.0 * max))),
                    }
                }
            })
            .collect_into_vec(&mut bins);
        let luminance = |wo: Vec3A, wi: Vec3A| -> f64 {
            let rgb = table.lookup(wo, wi);
            (0..3).map(|c| LUMINANCE[c] * rgb[c]).sum::<f64>().max(0.0)
        };
        let cells = SAMPLE_U * SAMPLE_V;
        let per_bin: Vec<ThetaOTables> = (0..SAMPLE_THETA_O)
            .into_par_iter()
            .map(|k| {
                let theta_o =
                    (k as f64 + 0.5) / SAMPLE_THETA_O as f64 * std::f64::consts::FRAC_PI_2;
                let wo = Vec3A::new(theta_o.sin() as f32, 0.0, theta_o.cos() as f32);
                let mut weight = vec![0.0f64; cells];
                for i in 0..SAMPLE_U {
                    let u = (i as f64 + 0.5) / SAMPLE_U as f64;
                    let theta_h = u * u * std::f64::consts::FRAC_PI_2;
                    let (st, ct) = theta_h.sin_cos();
                    for j in 0..SAMPLE_V {
                        let phi = (j as f64 + 0.5) / SAMPLE_V as f64 * std::f64::consts::TAU;
                        let h =
                            Vec3A::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                        let cos_oh = wo.dot(h);
                        if cos_oh <= 0.0 {
                            continue;
                        }
                        let wi = 2.0 * cos_oh * h - wo;
                        if wi.z <= 0.0 {
                            continue;
                        }
                        // f cos θᵢ · 4(ωₒ·ω_h) · sin θ_h · πu · 2π: the density in (u, v).
                        weight[i * SAMPLE_V + j] = luminance(wo, wi)
                            * f64::from(wi.z)
                            * 4.0
                            * f64::from(cos_oh)
                            * st
                            * std::f64::consts::PI
                            * u
                            * std::f64::consts::TAU;
                    }
                }
                let total: f64 = weight.iter().sum();
                let mut pdf = vec![0.0f32; cells];
                let mut row_cdf = vec![0.0f32; SAMPLE_U + 1];
                let mut cell_cdf = vec![0.0f32; SAMPLE_U * (SAMPLE_V + 1)];
                if !(total > 0.0 && total.is_finite()) {
                    return (pdf, row_cdf, cell_cdf, false);
                }
                let mut acc_rows = 0.0f64;
                for i in 0..SAMPLE_U {
                    let row = &weight[i * SAMPLE_V..(i + 1) * SAMPLE_V];
                    let row_sum: f64 = row.iter().sum();
                    let mut acc = 0.0f64;
                    for j in 0..SAMPLE_V {
                        // Density per unit (u, v) area: mass / (1/(U·V)).
                        pdf[i * SAMPLE_V + j] = (row[j] / total * cells as f64) as f32;
                        acc += row[j];
                        cell_cdf[i * (SAMPLE_V + 1) + j + 1] = if row_sum > 0.0 {
                            (acc / row_sum) as f32
                        } else {
                            (j + 1) as f32 / SAMPLE_V as f32
                        };
                    }
                    cell_cdf[i * (SAMPLE_V + 1) + SAMPLE_V] = 1.0;
                    acc_rows += row_sum;
                    row_cdf[i + 1] = (acc_rows / total) as f32;
                }
                row_cdf[SAMPLE_U] = 1.0;
                (pdf, row_cdf, cell_cdf, true)
            })
            .collect();
        let mut cell_pdf = Vec::with_capacity(SAMPLE_THETA_O * cells);
        let mut row_cdf = Vec::with_capacity(SAMPLE_THETA_O * (SAMPLE_U + 1));
        let mut cell_cdf = Vec::with_capacity(SAMPLE_THETA_O * SAMPLE_U * (SAMPLE_V + 1));
        let mut has_table = Vec::with_capacity(SAMPLE_THETA_O);
        for (p, r, c, h) in per_bin {
            cell_pdf.extend(p);
            row_cdf.extend(r);
            cell_cdf.extend(c);
            has_table.push(h);
        }
        // Equivalent roughness: f·cos-weighted tan²θ_h at normal incidence.
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for i in 0..SAMPLE_U {
            let u = (i as f64 + 0.5) / SAMPLE_U as f64;
            let theta_h = u * u * std::f64::consts::FRAC_PI_2;
            if theta_h >= std::f64::consts::FRAC_PI_4 {
                break;
            }
            let w: f64 = (0..SAMPLE_V)
                .map(|j| f64::from(cell_pdf[i * SAMPLE_V + j]))
                .sum();
            num += w * theta_h.tan().powi(2);
            den += w;
        }
        let equivalent_alpha = if den > 0.0 {
            (num / den).sqrt() as f32
        } else {
            1.0
        };
        let guides = |cdfs: &[f32], n: usize| -> Vec<u8> {
            cdfs.chunks_exact(n + 1).flat_map(guide_table).collect()
        };
        let row_guide = guides(&row_cdf, SAMPLE_U);
        let cell_guide = guides(&cell_cdf, SAMPLE_V);
        Self {
            bins,
            chroma,
            cell_pdf,
            row_cdf,
            cell_cdf,
            has_table,
            row_guide,
            cell_guide,
            equivalent_alpha,
        }
    }

    #[inline]
    fn spectrum(&self, index: usize, lambda_nm: [f32; 4]) -> SampledSpectrum {
        self.bin_spectrum(self.bins[index], lambda_nm)
    }

    #[inline]
    fn bin_spectrum(&self, bin: PackedBin, lambda_nm: [f32; 4]) -> SampledSpectrum {
        sigmoid_spectrum(self.chroma.coefficients(bin.chroma), bin.scale, lambda_nm)
    }

    #[inline]
    fn theta_o_bin(wo: Vec3A) -> usize {
        let theta_o = acos_fast(wo.z.clamp(0.0, 1.0));
        ((theta_o * std::f32::consts::FRAC_2_PI * SAMPLE_THETA_O as f32) as usize)
            .min(SAMPLE_THETA_O - 1)
    }

    /// (cos φₒ, sin φₒ) of ωₒ (1, 0 along the normal).
    #[inline]
    fn azimuth(wo: Vec3A) -> (f32, f32) {
        let r = (wo.x * wo.x + wo.y * wo.y).sqrt();
        if r > 1e-7 {
            (wo.x / r, wo.y / r)
        } else {
            (1.0, 0.0)
        }
    }

    /// Density (solid angle of ωᵢ) of the tabulated part for cell (i, j) of θₒ bin k, at a
    /// half vector with θ_h ↦ u, cos θ_h·… given.
    #[inline]
    fn cell_density(&self, k: usize, i: usize, j: usize, u: f32, sin_h: f32, cos_oh: f32) -> f32 {
        let p_uv = self.cell_pdf[(k * SAMPLE_U + i) * SAMPLE_V + j];
        let jacobian = sin_h * std::f32::consts::PI * u * std::f32::consts::TAU * 4.0 * cos_oh;
        if jacobian.is_nan() || jacobian <= 0.0 {
            return 0.0;
        }
        p_uv / jacobian
    }

    /// Density of the tabulated part for ωₒ and a half vector h (unit, upper), solid angle
    /// of ωᵢ.
    #[inline]
    fn table_pdf(&self, k: usize, wo: Vec3A, h: Vec3A) -> f32 {
        if !self.has_table[k] {
            return 0.0;
        }
        let cos_oh = wo.dot(h);
        let cos_h = h.z.min(1.0);
        if cos_oh <= 0.0 || cos_h <= 0.0 {
            return 0.0;
        }
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let u = (acos_fast(cos_h) * std::f32::consts::FRAC_2_PI).sqrt();
        // φ_h − φₒ from h rotated into ωₒ's azimuth (one atan2).
        let (c, s) = Self::azimuth(wo);
        let (y, x) = (c * h.y - s * h.x, c * h.x + s * h.y);
        let dphi = if y < 0.0 {
            std::f32::consts::TAU - atan2_upper(-y, x)
        } else {
            atan2_upper(y, x)
        };
        let v = dphi / std::f32::consts::TAU;
        let i = ((u * SAMPLE_U as f32) as usize).min(SAMPLE_U - 1);
        let j = ((v * SAMPLE_V as f32) as usize).min(SAMPLE_V - 1);
        self.cell_density(k, i, j, u, sin_h, cos_oh)
    }
}

/// Asks Linux to back `bins`' allocation with transparent huge pages (before it is
/// touched, so the first faults map 2 MB pages): random lookups into 11.7 MB then need 6
/// TLB entries instead of 2 900. Only the 2 MB-aligned interior is advised; a kernel
/// without THP (or another OS) refuses or ignores it, which changes nothing but speed.
// The capacity (not the length: still 0) is the allocation to advise, hence &Vec.
#[allow(clippy::ptr_arg)]
fn advise_huge_pages<T>(bins: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = bins.as_ptr() as usize;
        let end = start + bins.capacity() * std::mem::size_of::<T>();
        let (lo, hi) = (start.div_ceil(HUGE) * HUGE, end / HUGE * HUGE);
        if hi > lo {
            // SAFETY: [lo, hi) lies inside the Vec's own allocation (page-aligned, as
            // madvise requires); MADV_HUGEPAGE only changes how the kernel backs those
            // pages, never their contents or validity, and the result is ignored.
            unsafe {
                libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = bins;
}

/// Cells of a CDF's guide table (Chen & Asau 1974): 16 equal steps of the CDF's value.
const GUIDE: usize = 16;

/// guide[g] = `find_interval(cdf, g/GUIDE)` for g = 0 … GUIDE.
fn guide_table(cdf: &[f32]) -> [u8; GUIDE + 1] {
    std::array::from_fn(|g| find_interval(cdf, g as f32 / GUIDE as f32) as u8)
}

/// `find_interval(cdf, x)` for x ∈ [0, 1) through the guide table: the interval is
/// monotone in x, so it lies between those of ⌊16x⌋/16 and (⌊16x⌋ + 1)/16, and counting
/// the CDF entries ≤ x between them (usually none or one) finishes the search: two short
/// bisections instead of two 7-step chains of dependent loads per sample.
#[inline]
fn find_interval_guided(cdf: &[f32], guide: &[u8], x: f32) -> usize {
    let g = ((x * GUIDE as f32) as usize).min(GUIDE - 1);
    let (lo, hi) = (usize::from(guide[g]), usize::from(guide[g + 1]));
    // Entries 0 … lo are ≤ x and entry hi + 1 exceeds it (when it exists).
    lo + cdf[lo + 1..=hi].partition_point(|&c| c <= x)
}

/// Index of the CDF interval holding `x` (cdf[0] = 0, cdf[n] = 1), skipping empty ones.
#[inline]
fn find_interval(cdf: &[f32], x: f32) -> usize {
    let n = cdf.len() - 1;
    // partition_point: first index whose value exceeds x.
    let i = cdf.partition_point(|&c| c <= x);
    i.clamp(1, n) - 1
}

/// A measured lobe at four wavelengths.
#[derive(Clone, Copy)]
pub struct Measured<'a> {
    pub brdf: &'a MerlBrdf,
    /// The path's wavelengths, nm.
    pub lambda_nm: [f32; 4],
}

impl fmt::Debug for Measured<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Measured({:?}, λ {:?})", self.brdf, self.lambda_nm)
    }
}

impl PartialEq for Measured<'_> {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.brdf, other.brdf) && self.lambda_nm == other.lambda_nm
    }
}

impl Bxdf for Measured<'_> {
    #[inline]
    fn eval(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        let h = wo + wi;
        let len2 = h.length_squared();
        if len2 == 0.0 {
            return SampledSpectrum::zero();
        }
        self.brdf
            .spectrum(lookup_index(h / len2.sqrt(), wi), self.lambda_nm)
    }

    #[inline]
    fn pdf(&self, wo: Vec3A, wi: Vec3A, _mode: TransportMode) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let k = MerlBrdf::theta_o_bin(wo);
        let cosine = wi.z * std::f32::consts::FRAC_1_PI;
        if !self.brdf.has_table[k] {
            return cosine;
        }
        let h = (wo + wi).normalize();
        (1.0 - COSINE_FRACTION) * self.brdf.table_pdf(k, wo, h) + COSINE_FRACTION * cosine
    }

    #[inline]
    fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let b = self.brdf;
        let k = MerlBrdf::theta_o_bin(wo);
        let cosine_pdf = |wi: Vec3A| wi.z * std::f32::consts::FRAC_1_PI;
        if !b.has_table[k] || u_lobe < COSINE_FRACTION {
            let wi = sample_cosine_hemisphere(u);
            let pdf = self.pdf(wo, wi, mode);
            if wi.z <= 0.0 || pdf.is_nan() || pdf <= 0.0 {
                return None;
            }
            return Some(BsdfSample {
                wi,
                f: self.eval(wo, wi, mode),
                pdf,
                specular: false,
                transmission: false,
                eta: 1.0,
            });
        }
        let rows = &b.row_cdf[k * (SAMPLE_U + 1)..(k + 1) * (SAMPLE_U + 1)];
        let i = find_interval_guided(
            rows,
            &b.row_guide[k * (GUIDE + 1)..(k + 1) * (GUIDE + 1)],
            u.x,
        );
        let (r0, r1) = (rows[i], rows[i + 1]);
        let fu = if r1 > r0 { (u.x - r0) / (r1 - r0) } else { 0.5 };
        let row = k * SAMPLE_U + i;
        let cells = &b.cell_cdf[row * (SAMPLE_V + 1)..(row + 1) * (SAMPLE_V + 1)];
        let j = find_interval_guided(
            cells,
            &b.cell_guide[row * (GUIDE + 1)..(row + 1) * (GUIDE + 1)],
            u.y,
        );
        let (c0, c1) = (cells[j], cells[j + 1]);
        let fv = if c1 > c0 { (u.y - c0) / (c1 - c0) } else { 0.5 };
        let uu = (i as f32 + fu.clamp(0.0, 1.0)) / SAMPLE_U as f32;
        let vv = (j as f32 + fv.clamp(0.0, 1.0)) / SAMPLE_V as f32;
        let theta_h = uu * uu * std::f32::consts::FRAC_PI_2;
        let (st, ct) = theta_h.sin_cos();
        // φ_h = φₒ + 2πv, by rotating (cos 2πv, sin 2πv) by ωₒ's azimuth.
        let (sv, cv) = (vv * std::f32::consts::TAU).sin_cos();
        let (co, so) = MerlBrdf::azimuth(wo);
        let h = Vec3A::new(st * (co * cv - so * sv), st * (so * cv + co * sv), ct);
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return None;
        }
        let wi = 2.0 * cos_oh * h - wo;
        if wi.z <= 0.0 {
            return None;
        }
        // The bin first: its load (usually a cache miss) then overlaps the pdf arithmetic.
        let bin = b.bins[lookup_index(h, wi)];
        // The density of the cell just sampled (no second lookup), plus the cosine part.
        let pdf = (1.0 - COSINE_FRACTION) * b.cell_density(k, i, j, uu, st, cos_oh)
            + COSINE_FRACTION * cosine_pdf(wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: b.bin_spectrum(bin, self.lambda_nm),
            pdf,
            specular: false,
            transmission: false,
            eta: 1.0,
        })
    }

    /// No closed form (a table): `estimate_albedo`.
    fn albedo(&self, wo: Vec3A, mode: TransportMode) -> SampledSpectrum {
        estimate_albedo(self, wo, mode)
    }

    /// The table's equivalent microfacet roughness (fitted when it was loaded).
    fn angular_bandwidth_cycles_per_rad(&self) -> f32 {
        bandwidth_from_alpha(self.brdf.equivalent_alpha)
    }

    #[inline]
    fn is_specular(&self) -> bool {
        false
    }

    #[inline]
    fn has_specular(&self) -> bool {
        false
    }

    #[inline]
    fn is_reflection_only(&self) -> bool {
        true
    }

    /// The MERL format is isotropic (φ_h = 0).
    fn is_isotropic(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_arccos_matches_the_library() {
        for k in 0..=20_000 {
            let x = -1.0 + 2.0 * k as f32 / 20_000.0;
            let (a, b) = (super::acos_fast(x), x.acos());
            // A few f32 ulps (2.4·10⁻⁷ at π/2–π).
            assert!((a - b).abs() < 1e-6, "acos({x}): {a} vs {b}");
        }
    }

    #[test]
    fn guided_search_finds_the_bisected_interval() {
        // CDFs with empty intervals, jumps over several guide cells and a mass at the end;
        // every x on a fine grid and every CDF entry (and its f32 neighbours).
        let mut cdfs: Vec<Vec<f32>> = vec![(0..=64).map(|i| i as f32 / 64.0).collect()];
        let mut c = vec![0.0f32; 65];
        for (i, v) in c.iter_mut().enumerate() {
            *v = match i {
                0..=10 => 0.0,
                11..=20 => 0.3,
                21..=40 => 0.3 + 0.01 * (i - 20) as f32,
                41..=63 => 0.5 + 0.0001 * (i - 40) as f32,
                _ => 1.0,
            };
        }
        cdfs.push(c);
        for cdf in &cdfs {
            let guide = guide_table(cdf);
            let mut xs: Vec<f32> = (0..100_000).map(|k| k as f32 / 100_000.0).collect();
            for &e in cdf.iter() {
                for x in [
                    e,
                    f32::from_bits(e.to_bits().saturating_sub(1)),
                    e.next_up(),
                ] {
                    if (0.0..1.0).contains(&x) {
                        xs.push(x);
                    }
                }
            }
            xs.push(1.0 - f32::EPSILON / 2.0);
            for x in xs {
                assert_eq!(
                    find_interval_guided(cdf, &guide, x),
                    find_interval(cdf, x),
                    "x = {x}"
                );
            }
        }
    }

    #[test]
    fn fast_atan2_matches_the_library() {
        let mut worst = 0.0f64;
        for k in 0..=100_000 {
            let phi = std::f64::consts::PI * k as f64 / 100_000.0;
            for r in [1e-6f64, 0.3, 1.0, 7.0] {
                let (y, x) = ((r * phi.sin()) as f32, (r * phi.cos()) as f32);
                let exact = f64::from(y).atan2(f64::from(x));
                worst = worst.max((f64::from(atan2_upper(y, x)) - exact).abs());
            }
        }
        assert_eq!(atan2_upper(0.0, 0.0), 0.0);
        // 4.5·10⁻⁸ rad polynomial error plus f32 rounding of the reduction and result.
        assert!(worst < 5e-7, "atan2 error {worst} rad");
    }

    /// `BRDFRead.cpp`'s bin in f64 (rotations as the reference code writes them) and the
    /// distance of its three coordinates from the nearest bin edge, in bins.
    fn reference_bin(wo: Vec3A, wi: Vec3A) -> (usize, f64) {
        let (o, i) = (wo.as_dvec3(), wi.as_dvec3());
        let h = (o + i).normalize();
        let (theta_h, phi_h) = (h.z.min(1.0).acos(), h.y.atan2(h.x));
        let rot_z = |v: glam::DVec3, a: f64| {
            let (s, c) = a.sin_cos();
            glam::DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
        };
        let rot_y = |v: glam::DVec3, a: f64| {
            let (s, c) = a.sin_cos();
            glam::DVec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
        };
        let d = rot_y(rot_z(i, -phi_h), -theta_h);
        let theta_d = d.z.clamp(-1.0, 1.0).acos();
        let mut phi_d = d.y.atan2(d.x);
        if phi_d < 0.0 {
            phi_d += std::f64::consts::PI;
        }
        let coords = [
            (theta_h / std::f64::consts::FRAC_PI_2).sqrt() * MERL_THETA_H as f64,
            theta_d / std::f64::consts::FRAC_PI_2 * MERL_THETA_D as f64,
            phi_d / std::f64::consts::PI * MERL_PHI_D as f64,
        ];
        let edge = coords
            .iter()
            .map(|c| (c - c.round()).abs())
            .fold(f64::INFINITY, f64::min);
        let [a, b, c] = coords.map(|c| c as usize);
        let index = c.min(MERL_PHI_D - 1)
            + MERL_PHI_D * (b.min(MERL_THETA_D - 1) + MERL_THETA_D * a.min(MERL_THETA_H - 1));
        (index, edge)
    }

    #[test]
    fn lookup_index_matches_the_reference_reader_in_f64() {
        // 200 000 random upper-hemisphere pairs: every bin that differs from the f64
        // reference must have a coordinate within 10⁻³ bins of an edge (f32 rounding of
        // the directions and angles), and such pairs are rare.
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut upper = || {
            let z = next().max(1e-3);
            let phi = std::f32::consts::TAU * next();
            let r = (1.0 - z * z).sqrt();
            Vec3A::new(r * phi.cos(), r * phi.sin(), z)
        };
        let mut differ = 0;
        for _ in 0..200_000 {
            let (wo, wi) = (upper(), upper());
            let (reference, edge) = reference_bin(wo, wi);
            let got = lookup_index((wo + wi).normalize(), wi);
            if got != reference {
                assert!(
                    edge < 1e-3,
                    "bin {got} vs {reference}, {edge} bins from an edge"
                );
                differ += 1;
            }
        }
        eprintln!("{differ} of 200 000 bins differ from the f64 reference");
        assert!(differ < 200, "{differ} of 200 000 bins differ");
    }

    #[test]
    fn packed_chromaticity_error_is_as_stated() {
        // Every chromaticity the bins can hold (largest channel ½, the other two on a
        // 97 × 97 grid over [0, ½], each channel largest) at 360–830 nm every 2 nm: the
        // packed code + interpolated slice against `RgbToSpectrumTable::coefficients`
        // (the unpacked upsampling). docs/materials.md states the maximum relative error.
        let table = RgbGamut::Srgb.table();
        let slice = ChromaSlice::new(table);
        let lambda: Vec<f32> = (0..=235).map(|k| 360.0 + 2.0 * k as f32).collect();
        let (mut worst_rel, mut worst_abs) = (0.0f64, 0.0f64);
        let n = 96;
        for m in 0..3 {
            for iy in 0..=n {
                for ix in 0..=n {
                    let mut rgb = [0.0f32; 3];
                    rgb[m] = 0.5;
                    rgb[(m + 1) % 3] = 0.5 * ix as f32 / n as f32;
                    rgb[(m + 2) % 3] = 0.5 * iy as f32 / n as f32;
                    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
                        continue;
                    }
                    let exact = table.coefficients(rgb);
                    let coef = slice.coefficients(slice.encode(rgb));
                    for l in lambda.chunks(4) {
                        let mut l4 = [l[0]; 4];
                        l4[..l.len()].copy_from_slice(l);
                        let got = sigmoid_spectrum(coef, 1.0, l4);
                        for (k, &wl) in l.iter().enumerate() {
                            let want = exact.eval_f64(f64::from(wl));
                            let d = (f64::from(got[k]) - want).abs();
                            worst_abs = worst_abs.max(d);
                            worst_rel = worst_rel.max(d / want.max(1e-30));
                        }
                    }
                }
            }
        }
        eprintln!(
            "packed chromaticity: max relative error {worst_rel:.3e}, absolute {worst_abs:.3e}"
        );
        assert!(worst_rel < 4e-4, "relative {worst_rel}");
        assert!(worst_abs < 2e-5, "absolute {worst_abs}");
    }
}

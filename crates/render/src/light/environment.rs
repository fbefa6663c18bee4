//! An environment map: radiance from every direction read from an equirectangular
//! (latitude–longitude) RGB image (.exr or .hdr, read by prism-image).
//!
//! **Mapping** (Mitsuba 3 `envmap` orientation). In the light's local frame, image
//! coordinates (u, v) ∈ [0, 1)², u across from the left edge, v down from the top row, are
//! the direction
//!
//! ```text
//! θ = π v, φ = 2π u,   d = (sin φ sin θ, cos θ, −cos φ sin θ)
//! u = atan2(d.x, −d.z) / 2π (mod 1),   v = acos(d.y) / π
//! ```
//!
//! so the top row is +Y (zenith), the bottom row −Y, the left/right edge (u = 0) looks
//! towards −Z, u = ¼ towards +X, the centre column (u = ½) towards +Z, u = ¾ towards −X.
//! Texel (x, y) of a W × H image covers u ∈ [x/W, (x+1)/W), v ∈ [y/H, (y+1)/H), so texel
//! centres sit at ((x + ½)/W, (y + ½)/H). Mitsuba 3 uses the same axes and horizontal
//! placement but puts rows y at v = y/(H − 1) (first and last row on the poles) and
//! interpolates bilinearly, so its lookups differ by at most half a texel vertically. The
//! light's `transform` (a rotation, possibly a mirror; translations and uniform scales do
//! not change directions) maps local directions to the world.
//!
//! **Radiance.** `filter` `nearest` (the default): the texel a direction falls in. `bilinear`:
//! the four nearest texel centres' spectra blended bilinearly (exact: spectra add), wrapping
//! around in u and constant above the first row's and below the last row's centres, as
//! Mitsuba 3's `envmap` and Cycles' default interpolate; nearest draws a step at every texel
//! edge. Each texel's linear RGB (in the file's
//! colour space when it is sRGB/Rec.709, Rec.2020 or ACEScg, else converted to linear
//! sRGB; negative components clamped to 0) is upsampled once at load time to an RGB
//! illuminant spectrum (Jakob & Hanika 2019 sigmoid polynomial × the space's white
//! illuminant, pbrt-v4 `RGBIlluminantSpectrum`, table lookup without refinement): RGB
//! (1, 1, 1) is the white illuminant at Y = 1 in the output normalisation of docs/architecture.md, so
//! an EXR rendered by Prism used as an environment map gives back its own values. `scale`
//! multiplies everything.
//!
//! **Sampling.** A texel is chosen by a 2-D piecewise-constant distribution (pbrt-v4 §A.5
//! `PiecewiseConstant2D`) over its luminance × its solid angle ΔΩ = (2π/W)(cos θ_top −
//! cos θ_bottom) (∝ sin θ averaged over the row). Nearest: then a direction uniform in
//! solid angle inside the texel (φ uniform, cos θ uniform between the row's bounds); the
//! density is P(texel)/ΔΩ, constant over each texel and proportional to its luminance —
//! exactly the shape of the nearest-texel radiance. Bilinear: the texel's luminance is the
//! mean of the bilinear reconstruction over its cell, which weighs its 3 × 3 neighbourhood
//! by (⅛, ¾, ⅛) per axis (the first and last rows by (⅞, ⅛)), so every cell the radiance
//! reaches can be chosen (a black texel beside a bright one too: light sampling alone stays
//! unbiased). Inside the cell, which the texel centre splits into four quadrants on each of
//! which the reconstruction is one bilinear patch, a quadrant is chosen by its integral and
//! a point in it by inverting the patch's marginal and conditional, both linear (pbrt-v4
//! `SampleBilinear`). The density in image coordinates is then P(texel) · f(u, v) / ∫_cell f:
//! proportional to the bilinear luminance f inside each cell; per steradian it is that over
//! 2π² sin θ.
//!
//! **Emitted rays.** The same direction sampling, then an origin on the scene disk facing
//! it (pbrt-v4 §12.5.2 `ImageInfiniteLight::SampleLe`); the radiance and pdf_dir are those
//! of the texel the direction maps back to, as `pdf_le` finds them. The mean of the power
//! estimator is π r² Σ_texels ΔΩ ∫ L dλ; `power_w` estimates each texel's ∫ L dλ from its
//! luminance (exact for grey maps).

use std::f32::consts::PI;
use std::path::Path;

use glam::{DMat3, DMat4, Mat3A, Vec2, Vec3A};
use prism_bandwidth::Bandwidth;
pub use prism_scene::EnvironmentFilter;
use prism_spectrum::rgb_upsample::{RgbIlluminantSpectrum, SigmoidPolynomial};
use prism_spectrum::{DenseSpectrum, RgbGamut, SampledSpectrum, SampledWavelengths, Spectrum};
use rayon::prelude::*;

use super::piecewise_constant::PiecewiseConstant2D;
use super::scene_sphere::SceneSphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};
use crate::sampling::{sample_bilinear, ONE_MINUS_EPSILON};

/// The local direction of image coordinates (u, v) (see the module docs).
#[inline]
pub fn equirect_direction(uv: Vec2) -> Vec3A {
    let (sin_t, cos_t) = (PI * uv.y).sin_cos();
    let (sin_p, cos_p) = (2.0 * PI * uv.x).sin_cos();
    Vec3A::new(sin_p * sin_t, cos_t, -cos_p * sin_t)
}

/// The image coordinates (u, v) ∈ [0, 1)×[0, 1] of a local unit direction.
#[inline]
pub fn equirect_uv(d: Vec3A) -> Vec2 {
    Vec2::new(
        azimuth_fraction(d),
        d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI),
    )
}

/// The azimuth of a unit direction about +y as a fraction of a turn in [0, 1), 0 towards
/// −z and increasing towards +x (the u of the equirectangular and equal-area sphere maps).
#[inline]
pub fn azimuth_fraction(d: Vec3A) -> f32 {
    let mut u = d.x.atan2(-d.z) * (0.5 / PI);
    if u < 0.0 {
        u += 1.0;
    }
    if u >= 1.0 {
        u = 0.0;
    }
    u
}

/// The rotation (or rotation with mirror) in a scene transform: its linear part divided by
/// the uniform scale s = |det|^(1/3); an error message when the linear part is not s × an
/// orthogonal matrix (shear or non-uniform scale would distort solid angles).
pub fn rotation_of(matrix: &DMat4) -> Result<Mat3A, String> {
    let m = DMat3::from_mat4(*matrix);
    let det = m.determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err("the transform is singular".into());
    }
    let r = m * (1.0 / det.abs().cbrt());
    let off = (r.transpose() * r - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, &x| a.max(x.abs()));
    if off > 1e-6 {
        return Err(
            "an environment map can only be rotated (or mirrored): the transform has a \
             non-uniform scale or a shear"
                .into(),
        );
    }
    Ok(Mat3A::from_cols(
        r.x_axis.as_vec3().into(),
        r.y_axis.as_vec3().into(),
        r.z_axis.as_vec3().into(),
    ))
}

#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    width: usize,
    height: usize,
    /// Per texel (row-major, top row first): the sigmoid polynomial and scale of its RGB
    /// illuminant spectrum, side by side so that a sampled texel costs one cache line; the
    /// white illuminant is `white`.
    texels: Vec<(SigmoidPolynomial, f32)>,
    white: Spectrum,
    /// The user's `scale`.
    pub scale: f32,
    filter: EnvironmentFilter,
    /// Per texel, the luminance of its RGB (before `scale`; eq. 7's input and, bilinear, the
    /// sampling's f).
    luminance: Vec<f32>,
    /// Bilinear filter: per texel, P(texel) · W·H / (mean of f over its cell) / 2π², so that
    /// the density per steradian is this × f(u, v) / sin θ (0 where the cell is dark; empty
    /// for nearest).
    bilinear_pdf_factor: Vec<f32>,
    /// cos θ at the row boundaries: cos(π y / H), y = 0..=H.
    cos_rows: Vec<f32>,
    distribution: PiecewiseConstant2D,
    to_world: Mat3A,
    to_local: Mat3A,
    scene: SceneSphere,
    /// Σ_texels ΔΩ · Y (sr), for the power estimate.
    luminance_solid_angle_sr: f64,
    /// Σ_λ white(λ) Δλ (nm): ∫ L dλ of a texel of luminance Y = 1.
    white_integral_nm: f64,
}

impl EnvironmentLight {
    /// From linear RGB `texels`. `rotation` maps local directions to the world and must be
    /// orthogonal (see `rotation_of`). Errors name the first non-finite pixel.
    pub fn from_rgb(
        texels: RgbTexels<'_>,
        rotation: Mat3A,
        scale: f32,
        filter: EnvironmentFilter,
        scene: SceneSphere,
    ) -> Result<Self, String> {
        let RgbTexels {
            width,
            height,
            pixels,
            gamut,
        } = texels;
        if width == 0 || height == 0 || pixels.len() != width * height {
            return Err(format!(
                "expected {width}×{height} pixels, found {}",
                pixels.len()
            ));
        }
        if let Some(i) = pixels.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            let p = pixels[i];
            return Err(format!(
                "texel ({}, {}) is not finite: ({}, {}, {}); expected finite radiance",
                i % width,
                i / width,
                p[0],
                p[1],
                p[2]
            ));
        }
        let upsampled: Vec<(SigmoidPolynomial, f32)> = pixels
            .par_iter()
            .map(|p| {
                let rgb = p.map(|c| c.max(0.0));
                // Finite and ≥ 0, so the lookup cannot fail; black on the impossible error.
                RgbIlluminantSpectrum::from_table(gamut, rgb)
                    .map(|s| (s.polynomial, s.scale))
                    .unwrap_or((SigmoidPolynomial::constant(0.0), 0.0))
            })
            .collect();
        let cos_rows: Vec<f32> = (0..=height)
            .map(|y| (std::f64::consts::PI * y as f64 / height as f64).cos() as f32)
            .collect();
        let weights = {
            let m = gamut.color_space().rgb_to_xyz;
            [m.x_axis.y, m.y_axis.y, m.z_axis.y]
        };
        let luminance_f64: Vec<f64> = pixels
            .iter()
            .map(|p| {
                (0..3)
                    .map(|c| weights[c] * f64::from(p[c].max(0.0)))
                    .sum::<f64>()
                    .max(0.0)
            })
            .collect();
        let luminance: Vec<f32> = luminance_f64.iter().map(|&l| l as f32).collect();
        let per_texel: Vec<f64> = match filter {
            EnvironmentFilter::Nearest => luminance_f64,
            EnvironmentFilter::Bilinear => bilinear_texel_means(&luminance, width, height)
                .into_iter()
                .map(f64::from)
                .collect(),
        };
        let dphi = 2.0 * std::f64::consts::PI / width as f64;
        let mut values = vec![0.0f32; width * height];
        let mut luminance_solid_angle_sr = 0.0f64;
        for y in 0..height {
            let solid_angle = dphi * (f64::from(cos_rows[y]) - f64::from(cos_rows[y + 1]));
            for x in 0..width {
                let i = y * width + x;
                values[i] = (per_texel[i] * solid_angle) as f32;
                luminance_solid_angle_sr += per_texel[i] * solid_angle;
            }
        }
        let white_table = gamut.white_illuminant();
        let white_dense = DenseSpectrum::from_fn(|wl| {
            f64::from(white_table[((wl - 360.0).round() as usize).min(white_table.len() - 1)])
        });
        let white_integral_nm = white_dense.values().iter().sum();
        let white = Spectrum::from_dense(&white_dense).map_err(|e| e.to_string())?;
        let mut light = Self {
            width,
            height,
            texels: upsampled,
            white,
            scale,
            filter,
            luminance,
            bilinear_pdf_factor: Vec::new(),
            cos_rows,
            distribution: PiecewiseConstant2D::new(&values, width, height),
            to_world: rotation,
            to_local: rotation.transpose(),
            scene,
            luminance_solid_angle_sr,
            white_integral_nm,
        };
        if filter == EnvironmentFilter::Bilinear {
            let pixel_count = (width * height) as f32;
            light.bilinear_pdf_factor = (0..width * height)
                .map(|i| {
                    let (x, y) = (i % width, i / width);
                    let cell_mean = light.distribution.value(x, y) / light.texel_solid_angle(y);
                    if cell_mean > 0.0 {
                        light.texel_probability(x, y) * pixel_count / cell_mean / (2.0 * PI * PI)
                    } else {
                        0.0
                    }
                })
                .collect();
        }
        Ok(light)
    }

    /// Reads an .exr/.hdr file with prism-image (`prism_image::io::read_image`); errors name
    /// the file.
    pub fn load(
        path: &Path,
        rotation: Mat3A,
        scale: f32,
        filter: EnvironmentFilter,
        scene: SceneSphere,
    ) -> Result<Self, String> {
        let image = prism_image::io::read_image(path).map_err(|e| e.to_string())?;
        // Radiance is never negative: a negative texel is a broken or signed-difference
        // image, which clamping would hide (checked on the file's values, before a gamut
        // conversion that may legitimately leave out-of-gamut colours negative).
        let width = image.width();
        if let Some(i) = image
            .pixels()
            .iter()
            .position(|p| p.iter().any(|&c| c < 0.0))
        {
            let p = image.pixels()[i];
            return Err(format!(
                "{}: texel ({}, {}) (column, row from the top left) has a negative value \
                 ({}, {}, {}); expected radiance ≥ 0",
                path.display(),
                i % width,
                i / width,
                p[0],
                p[1],
                p[2]
            ));
        }
        let space = &image.color_space;
        let close =
            |a: &[f64; 2], b: &[f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) < 5e-4;
        let gamut = RgbGamut::ALL.into_iter().find(|g| {
            let s = g.color_space();
            close(&s.white_xy, &space.white_xy)
                && s.primaries_xy
                    .iter()
                    .zip(space.primaries_xy.iter())
                    .all(|(a, b)| close(a, b))
        });
        let (width, height) = (image.width(), image.height());
        let (gamut, pixels) = match gamut {
            Some(g) => (g, image.into_pixels()),
            None => {
                let from = image.color_space.clone();
                let mut pixels = image.into_pixels();
                prism_image::io::convert_pixels(&mut pixels, &from, &RgbGamut::Srgb.color_space());
                (RgbGamut::Srgb, pixels)
            }
        };
        let texels = RgbTexels {
            width,
            height,
            pixels: &pixels,
            gamut,
        };
        Self::from_rgb(texels, rotation, scale, filter, scene)
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    pub fn resolution(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Luminance of every texel (row-major, top row first) in the map's own units (Y of the
    /// RGB pixels, before `scale`).
    pub fn luminance_texels(&self) -> &[f32] {
        &self.luminance
    }

    /// Local image coordinates in [0, 1)² of a world direction (towards the light).
    pub fn local_uv(&self, wi: Vec3A) -> Vec2 {
        equirect_uv((self.to_local * wi).normalize())
    }

    /// Texel (column, row) of local image coordinates.
    #[inline]
    fn texel(&self, uv: Vec2) -> (usize, usize) {
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        (x, y)
    }

    /// Solid angle of a texel of row `y`, sr.
    #[inline]
    fn texel_solid_angle(&self, y: usize) -> f32 {
        (2.0 * PI / self.width as f32) * (self.cos_rows[y] - self.cos_rows[y + 1])
    }

    /// Radiance of texel (x, y) (nearest).
    #[inline]
    fn texel_radiance(
        &self,
        x: usize,
        y: usize,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        let i = y * self.width + x;
        let (polynomial, scale) = &self.texels[i];
        let s = polynomial.eval4(wavelengths.lambda());
        self.white.eval(wavelengths) * SampledSpectrum::new(s) * (scale * self.scale)
    }

    /// Radiance at local image coordinates `uv`, by `filter` (module docs).
    #[inline]
    fn radiance_at(&self, uv: Vec2, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        self.lookup_radiance(self.lookup(uv), wavelengths)
    }

    /// The texels `filter` reads at local image coordinates `uv`.
    #[inline]
    fn lookup(&self, uv: Vec2) -> TexelLookup {
        match self.filter {
            EnvironmentFilter::Nearest => {
                let (x, y) = self.texel(uv);
                TexelLookup::Nearest(x, y)
            }
            EnvironmentFilter::Bilinear => TexelLookup::Bilinear(self.bilinear_taps(uv)),
        }
    }

    /// The radiance of the texels `lookup` found.
    #[inline]
    fn lookup_radiance(
        &self,
        lookup: TexelLookup,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        match lookup {
            TexelLookup::Nearest(x, y) => self.texel_radiance(x, y, wavelengths),
            TexelLookup::Bilinear(taps) => {
                let mut sum = [0.0f32; 4];
                for (i, w) in taps {
                    if w > 0.0 {
                        let (polynomial, scale) = &self.texels[i];
                        let s = polynomial.eval4(wavelengths.lambda());
                        for (total, value) in sum.iter_mut().zip(s) {
                            *total += w * scale * value;
                        }
                    }
                }
                self.white.eval(wavelengths) * SampledSpectrum::new(sum) * self.scale
            }
        }
    }

    /// `infinite_radiance` along `direction` at each of `wavelength_sets`, added to `out`:
    /// the texel lookup once, the spectra per set.
    pub fn add_radiance_each(
        &self,
        direction: Vec3A,
        wavelength_sets: &[SampledWavelengths],
        out: &mut [SampledSpectrum],
    ) {
        let lookup = self.lookup(self.local_uv(direction));
        for (o, wavelengths) in out.iter_mut().zip(wavelength_sets) {
            *o += self.lookup_radiance(lookup, wavelengths);
        }
    }

    /// The four texels (row-major indices) whose centres bracket `uv`, with their bilinear
    /// weights.
    #[inline]
    fn bilinear_taps(&self, uv: Vec2) -> [(usize, f32); 4] {
        let ([x0, x1], fx) = wrapped_pair(uv.x, self.width);
        let ([y0, y1], fy) = clamped_pair(uv.y, self.height);
        let w = self.width;
        [
            (y0 * w + x0, (1.0 - fx) * (1.0 - fy)),
            (y0 * w + x1, fx * (1.0 - fy)),
            (y1 * w + x0, (1.0 - fx) * fy),
            (y1 * w + x1, fx * fy),
        ]
    }

    /// The bilinear luminance f at `uv` (the sampling's target, module docs).
    #[inline]
    fn bilinear_luminance(&self, uv: Vec2) -> f32 {
        self.bilinear_taps(uv)
            .iter()
            .map(|&(i, w)| w * self.luminance[i])
            .sum()
    }

    /// Bilinear filter: density per steradian at local image coordinates `uv` of local
    /// direction `local`, P(texel) · f(uv) / ∫_cell f / (2π² sin θ) (module docs).
    #[inline]
    fn bilinear_pdf(&self, uv: Vec2, local: Vec3A) -> f32 {
        let (x, y) = self.texel(uv);
        let factor = self.bilinear_pdf_factor[y * self.width + x];
        let sin_theta = (1.0 - local.y * local.y).max(0.0).sqrt();
        if !(factor > 0.0 && sin_theta > 0.0) {
            return 0.0;
        }
        factor * self.bilinear_luminance(uv) / sin_theta
    }

    /// Probability of choosing texel (x, y).
    #[inline]
    fn texel_probability(&self, x: usize, y: usize) -> f32 {
        let uv = Vec2::new(
            (x as f32 + 0.5) / self.width as f32,
            (y as f32 + 0.5) / self.height as f32,
        );
        self.distribution.pdf(uv) / (self.width * self.height) as f32
    }

    /// Bilinear filter: a point of cell (x, y) with density ∝ f, from `u` uniform in [0, 1)²
    /// (module docs: a quadrant by its integral, then a point of its bilinear patch).
    fn sample_in_cell(&self, x: usize, y: usize, u: Vec2) -> Vec2 {
        // f at the cell's 3 × 3 nodes (corners, edge midpoints, centre), cell-local (a, b) ∈
        // {0, ½, 1}²: the mean of the texels around each node, columns wrapping, rows clamped.
        let (w, h) = (self.width, self.height);
        let (left, right) = ((x + w - 1) % w, (x + 1) % w);
        let rows = [y.saturating_sub(1), y, (y + 1).min(h - 1)];
        // Per row, the texel and the means with its left and right neighbours.
        let across = rows.map(|r| {
            let g = &self.luminance[r * w..(r + 1) * w];
            [0.5 * (g[left] + g[x]), g[x], 0.5 * (g[x] + g[right])]
        });
        let nodes: [[f32; 3]; 3] = [
            std::array::from_fn(|i| 0.5 * (across[0][i] + across[1][i])),
            across[1],
            std::array::from_fn(|i| 0.5 * (across[1][i] + across[2][i])),
        ];
        let corners = |qx: usize, qy: usize| {
            [
                nodes[qy][qx],
                nodes[qy][qx + 1],
                nodes[qy + 1][qx],
                nodes[qy + 1][qx + 1],
            ]
        };
        let quadrants = [(0, 0), (1, 0), (0, 1), (1, 1)];
        let weights = quadrants.map(|(qx, qy)| corners(qx, qy).iter().sum::<f32>());
        let total: f32 = weights.iter().sum();
        // The quadrant from u.x, which is then rescaled to [0, 1) within it.
        let mut ux = u.x * total;
        let mut chosen = 3;
        for (k, &wk) in weights.iter().enumerate() {
            if ux < wk || k == 3 {
                chosen = k;
                ux = if wk > 0.0 {
                    (ux / wk).clamp(0.0, ONE_MINUS_EPSILON)
                } else {
                    0.5
                };
                break;
            }
            ux -= wk;
        }
        let (qx, qy) = quadrants[chosen];
        let st = sample_bilinear(Vec2::new(ux, u.y), corners(qx, qy));
        let a = 0.5 * (qx as f32 + st.x);
        let b = 0.5 * (qy as f32 + st.y);
        Vec2::new((x as f32 + a) / w as f32, (y as f32 + b) / h as f32)
    }

    /// Nearest filter: density of choosing texel (x, y) per steradian, P(texel)/ΔΩ.
    #[inline]
    fn texel_pdf(&self, x: usize, y: usize) -> f32 {
        let p_texel = self.texel_probability(x, y);
        let d_omega = self.texel_solid_angle(y);
        if d_omega > 0.0 {
            p_texel / d_omega
        } else {
            0.0
        }
    }

    /// A direction (world, towards the light), its density per steradian and where its
    /// radiance is read: the sampled texel (nearest; a direction on a texel edge may round
    /// into its neighbour) or the sampled image point (bilinear).
    #[inline]
    fn sample_direction(&self, u: Vec2) -> Option<(Vec3A, f32, SampledAt)> {
        let (uv, pdf_uv, [x, y]) = self.distribution.sample(u);
        if pdf_uv.is_nan() || pdf_uv <= 0.0 || x >= self.width || y >= self.height {
            return None;
        }
        let (wi, pdf, at) = match self.filter {
            EnvironmentFilter::Nearest => {
                // Uniform in solid angle within the texel: cos θ uniform between the row
                // bounds.
                let fv = (uv.y * self.height as f32 - y as f32).clamp(0.0, 1.0);
                let (c0, c1) = (self.cos_rows[y], self.cos_rows[y + 1]);
                let cos_theta = c0 + fv * (c1 - c0);
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let (sin_p, cos_p) = (2.0 * PI * uv.x).sin_cos();
                let local = Vec3A::new(sin_p * sin_theta, cos_theta, -cos_p * sin_theta);
                (
                    (self.to_world * local).normalize(),
                    self.texel_pdf(x, y),
                    SampledAt::Texel(x, y),
                )
            }
            EnvironmentFilter::Bilinear => {
                // The position inside the cell is uniform and independent of the cell.
                let within = Vec2::new(
                    (uv.x * self.width as f32 - x as f32).clamp(0.0, ONE_MINUS_EPSILON),
                    (uv.y * self.height as f32 - y as f32).clamp(0.0, ONE_MINUS_EPSILON),
                );
                let at = self.sample_in_cell(x, y, within);
                let local = equirect_direction(at);
                (
                    (self.to_world * local).normalize(),
                    self.bilinear_pdf(at, local),
                    SampledAt::Point(at),
                )
            }
        };
        (pdf > 0.0 && pdf.is_finite()).then_some((wi, pdf, at))
    }

    #[inline]
    fn sampled_radiance(&self, at: SampledAt, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        match at {
            SampledAt::Texel(x, y) => self.texel_radiance(x, y, wavelengths),
            SampledAt::Point(uv) => self.radiance_at(uv, wavelengths),
        }
    }

    /// The texel a world direction (towards the light) falls in.
    #[inline]
    fn texel_of(&self, wi: Vec3A) -> (usize, usize) {
        self.texel(equirect_uv((self.to_local * wi).normalize()))
    }

    /// Solid-angle density of `sample_li`'s directions at `wi`.
    #[inline]
    pub fn direction_pdf(&self, wi: Vec3A) -> f32 {
        match self.filter {
            EnvironmentFilter::Nearest => {
                let (x, y) = self.texel_of(wi);
                self.texel_pdf(x, y)
            }
            EnvironmentFilter::Bilinear => {
                let local = (self.to_local * wi).normalize();
                self.bilinear_pdf(equirect_uv(local), local)
            }
        }
    }
}

impl LightSource for EnvironmentLight {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (wi, pdf, at) = self.sample_direction(u)?;
        Some(LightSample {
            wi,
            radiance: self.sampled_radiance(at, wavelengths),
            pdf,
            p_light: self.scene.point_beyond(ctx.p, wi),
            distance_m: f32::INFINITY,
            delta: false,
            n_light: Vec3A::ZERO,
        })
    }

    #[inline]
    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3A, _hit: Option<&LightHit>) -> f32 {
        self.direction_pdf(wi)
    }

    #[inline]
    fn emitted_radiance(&self, _: &LightHit, _: Vec3A, _: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::splat(0.0)
    }

    #[inline]
    fn infinite_radiance(
        &self,
        direction: Vec3A,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.radiance_at(self.local_uv(direction), wavelengths)
    }

    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (wi, _, _) = self.sample_direction(u_dir)?;
        // The radiance and density the direction maps back to (the sampled texel's but on
        // a texel edge), so that the sample and `pdf_le` agree.
        scene.emission(
            wi,
            u_pos,
            self.radiance_at(self.local_uv(wi), wavelengths),
            self.direction_pdf(wi),
        )
    }

    fn pdf_le(
        &self,
        scene: &SceneSphere,
        _origin: Vec3A,
        _n: Vec3A,
        direction: Vec3A,
    ) -> (f32, f32) {
        (scene.disk_pdf(), self.direction_pdf(-direction))
    }

    /// Φ ≈ π r² · scale · Σ_texels ΔΩ · Y_texel · Σ_λ white(λ) Δλ, W: the flux into a disk
    /// of the scene's radius from the whole map, with each texel's ∫ L dλ estimated as its
    /// luminance Y times that of the white illuminant (exact for grey maps; only used to
    /// choose lights).
    fn power_w(&self, scene_radius_m: f32) -> f64 {
        let r = f64::from(scene_radius_m);
        std::f64::consts::PI
            * r
            * r
            * f64::from(self.scale)
            * self.luminance_solid_angle_sr
            * self.white_integral_nm
    }

    fn bandwidth(&self) -> Bandwidth {
        super::bandwidth::environment(self)
    }

    #[inline]
    fn is_delta(&self) -> bool {
        false
    }

    #[inline]
    fn is_infinite(&self) -> bool {
        true
    }
}

/// An environment map's pixels: linear RGB in `gamut`, row-major, top row first.
#[derive(Clone, Copy, Debug)]
pub struct RgbTexels<'a> {
    pub width: usize,
    pub height: usize,
    pub pixels: &'a [[f32; 3]],
    pub gamut: RgbGamut,
}

/// The texels the map's filter reads at one point of the image (`EnvironmentLight::lookup`):
/// texel (x, y), or the four bilinear taps (row-major index, weight).
#[derive(Clone, Copy, Debug)]
enum TexelLookup {
    Nearest(usize, usize),
    Bilinear([(usize, f32); 4]),
}

/// Where a sampled direction's radiance is read (`EnvironmentLight::sample_direction`).
#[derive(Clone, Copy, Debug)]
enum SampledAt {
    Texel(usize, usize),
    Point(Vec2),
}

/// The two texel columns whose centres bracket image coordinate `u` (wrapping around) and
/// the weight of the second.
#[inline]
fn wrapped_pair(u: f32, width: usize) -> ([usize; 2], f32) {
    let s = u * width as f32 - 0.5;
    let floor = s.floor();
    let x0 = (floor as i64).rem_euclid(width as i64) as usize;
    ([x0, (x0 + 1) % width], (s - floor).clamp(0.0, 1.0))
}

/// The two texel rows whose centres bracket image coordinate `v`, and the weight of the
/// second; above the first row's centre and below the last row's, that row alone.
#[inline]
fn clamped_pair(v: f32, height: usize) -> ([usize; 2], f32) {
    let t = (v * height as f32 - 0.5).clamp(0.0, (height - 1) as f32);
    let y0 = (t as usize).min(height - 1);
    ([y0, (y0 + 1).min(height - 1)], t - y0 as f32)
}

/// Per texel, the mean over its cell of the bilinear reconstruction of `values` (module
/// docs): (⅛, ¾, ⅛) over the row's neighbours (wrapping) times the same over the column's,
/// where the first and last rows, constant over their outer halves, weigh (⅞, ⅛).
fn bilinear_texel_means(values: &[f32], width: usize, height: usize) -> Vec<f32> {
    let mut across = vec![0.0f32; values.len()];
    for y in 0..height {
        let row = &values[y * width..(y + 1) * width];
        for x in 0..width {
            let (left, right) = (row[(x + width - 1) % width], row[(x + 1) % width]);
            across[y * width + x] = 0.75 * row[x] + 0.125 * (left + right);
        }
    }
    let mut out = vec![0.0f32; values.len()];
    for y in 0..height {
        for x in 0..width {
            let at = |y: usize| across[y * width + x];
            out[y * width + x] = match (y, height) {
                (_, 1) => at(0),
                (0, _) => 0.875 * at(0) + 0.125 * at(1),
                (y, h) if y == h - 1 => 0.875 * at(y) + 0.125 * at(y - 1),
                (y, _) => 0.75 * at(y) + 0.125 * (at(y - 1) + at(y + 1)),
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::test_support::{build_error, build_scene, chi2_config, photometric_sum};
    use crate::light::Light;
    use prism_spectrum::rgb_space::RgbColorSpace;
    use prism_testkit::chi2::chi2_test_adaptive;

    /// A 16 × 8 map: a dim gradient with one bright texel at (x, y) = (4, 3) — u ∈ [¼, 5/16),
    /// just above the horizon towards +X — and a black texel.
    fn synthetic_pixels() -> Vec<[f32; 3]> {
        let (w, h) = (16, 8);
        let mut p = vec![[0.0f32; 3]; w * h];
        for y in 0..h {
            for x in 0..w {
                let g = 0.05 + 0.1 * x as f32 / w as f32 + 0.02 * y as f32;
                p[y * w + x] = [g, 0.8 * g, 1.2 * g];
            }
        }
        p[3 * w + 4] = [40.0, 30.0, 10.0];
        p[6 * w + 9] = [0.0; 3];
        p
    }

    fn synthetic(rotation: Mat3A) -> EnvironmentLight {
        synthetic_with(rotation, EnvironmentFilter::Nearest)
    }

    fn synthetic_with(rotation: Mat3A, filter: EnvironmentFilter) -> EnvironmentLight {
        EnvironmentLight::from_rgb(
            RgbTexels {
                width: 16,
                height: 8,
                pixels: &synthetic_pixels(),
                gamut: RgbGamut::Srgb,
            },
            rotation,
            1.0,
            filter,
            SceneSphere::default(),
        )
        .unwrap()
    }

    #[test]
    fn radiance_for_many_wavelength_sets_is_each_sets_radiance() {
        let sets: Vec<SampledWavelengths> = (0..16)
            .map(|k| SampledWavelengths::sample_rgb_output((k as f32 + 0.5) / 16.0))
            .collect();
        let rotation = Mat3A::from_axis_angle(glam::Vec3::new(0.3, 1.0, -0.2).normalize(), 0.7);
        for filter in [EnvironmentFilter::Nearest, EnvironmentFilter::Bilinear] {
            let env = synthetic_with(rotation, filter);
            for k in 0..200 {
                let u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 + 0.5) / 200.0);
                let direction = crate::light::warp::sample_uniform_sphere(u);
                let mut each = vec![SampledSpectrum::splat(0.5); sets.len()];
                env.add_radiance_each(direction, &sets, &mut each);
                for (sum, wavelengths) in each.iter().zip(&sets) {
                    let one = env.infinite_radiance(direction, wavelengths);
                    assert_eq!(*sum, SampledSpectrum::splat(0.5) + one, "{filter:?} {k}");
                }
            }
        }
    }

    #[test]
    fn chi2_environment() {
        let rotations = [
            Mat3A::IDENTITY,
            Mat3A::from_axis_angle(glam::Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9),
        ];
        let filters = [EnvironmentFilter::Nearest, EnvironmentFilter::Bilinear];
        let config = chi2_config(rotations.len() * filters.len(), 71);
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::Y,
        };
        let wl = SampledWavelengths::sample_uniform(0.4);
        for (rotation, filter) in rotations.into_iter().flat_map(|r| filters.map(|f| (r, f))) {
            let env = synthetic_with(rotation, filter);
            let r = chi2_test_adaptive(
                &config,
                |_, u| env.sample_li(&ctx, u, &wl).map(|s| s.wi),
                |w| f64::from(env.direction_pdf(w)),
            );
            assert!(r.passed, "{}", r.message);
            assert!((r.pdf_integral - 1.0).abs() < 2e-3, "{}", r.message);
        }
    }

    #[test]
    fn density_is_proportional_to_texel_luminance_and_radiance_matches_sampling() {
        let env = synthetic(Mat3A::IDENTITY);
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::ZERO,
        };
        let wl = SampledWavelengths::sample_uniform(0.6);
        let weights = RgbColorSpace::srgb().rgb_to_xyz;
        let lum = |p: [f32; 3]| {
            weights.x_axis.y * f64::from(p[0])
                + weights.y_axis.y * f64::from(p[1])
                + weights.z_axis.y * f64::from(p[2])
        };
        let pixels = synthetic_pixels();
        let total: f64 = (0..8)
            .map(|y| {
                let d_omega = (2.0 * std::f64::consts::PI / 16.0)
                    * ((std::f64::consts::PI * y as f64 / 8.0).cos()
                        - (std::f64::consts::PI * (y + 1) as f64 / 8.0).cos());
                (0..16)
                    .map(|x| lum(pixels[y * 16 + x]) * d_omega)
                    .sum::<f64>()
            })
            .sum();
        // Variates away from texel edges and the poles, where the texel of a direction is
        // ambiguous (a set of measure zero).
        for i in 0..200 {
            let u = Vec2::new(
                ((i as f32 + 0.5) * 0.618_034).fract(),
                ((i as f32 + 0.5) * 0.414_213).fract(),
            );
            let s = env.sample_li(&ctx, u, &wl).unwrap();
            let uv = equirect_uv(s.wi);
            let (x, y) = env.texel(uv);
            // pdf = luminance / Σ luminance·ΔΩ, constant over the texel.
            let expected = lum(pixels[y * 16 + x]) / total;
            assert!(
                (f64::from(s.pdf) - expected).abs() < 1e-4 * expected,
                "{x},{y}"
            );
            assert_eq!(env.direction_pdf(s.wi), s.pdf);
            assert_eq!(env.infinite_radiance(s.wi, &wl), s.radiance);
            assert!(x != 9 || y != 6, "sampled the black texel");
        }
    }

    #[test]
    fn the_bright_texel_is_seen_towards_plus_x_and_rotates_with_the_transform() {
        let wl = SampledWavelengths::sample_uniform(0.6);
        // Centre of texel (4, 3): u = 4.5/16, v = 3.5/8.
        let d = equirect_direction(Vec2::new(4.5 / 16.0, 3.5 / 8.0));
        assert!(d.x > 0.9 && d.y > 0.0, "{d}");
        let env = synthetic(Mat3A::IDENTITY);
        let bright = env.infinite_radiance(d, &wl).to_array()[0];
        assert!(bright > 10.0, "{bright}");
        // Rotated by 90° about +Y: local +X goes to world −Z.
        let r = Mat3A::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let rotated = synthetic(r);
        let world = r * d;
        assert!(world.z < -0.9);
        assert_eq!(
            rotated.infinite_radiance(world, &wl),
            env.infinite_radiance(d, &wl)
        );
    }

    #[test]
    fn a_grey_texel_emits_the_white_illuminant_at_its_value() {
        // RGB (v, v, v) → v × the sRGB white (D65 at Y = 1): luminance v · K_m ∫ȳ dλ.
        let env = EnvironmentLight::from_rgb(
            RgbTexels {
                width: 2,
                height: 1,
                pixels: &[[0.25; 3], [2.0; 3]],
                gamut: RgbGamut::Srgb,
            },
            Mat3A::IDENTITY,
            3.0,
            EnvironmentFilter::Nearest,
            SceneSphere::default(),
        )
        .unwrap();
        let per_unit = crate::film::xyz::cd_m2_per_unit();
        for (u, v) in [(0.25f32, 0.25f64), (0.75, 2.0)] {
            let d = equirect_direction(Vec2::new(u, 0.5));
            let l = photometric_sum(|wl| env.infinite_radiance(d, wl));
            let exact = 3.0 * v * per_unit;
            assert!((l - exact).abs() < 2e-3 * exact, "{l} vs {exact}");
        }
    }

    #[test]
    fn environment_maps_load_from_exr_and_hdr_files() {
        let dir = tempfile::tempdir().unwrap();
        let pixels = synthetic_pixels();
        for ext in ["exr", "hdr"] {
            let image =
                prism_image::Image::new(16, 8, pixels.clone(), RgbColorSpace::srgb()).unwrap();
            let path = dir.path().join(format!("sky.{ext}"));
            prism_image::io::write_image(&path, &image).unwrap();
            let json = format!(
                r#"{{"lights": [{{"type": "environment", "file": "sky.{ext}", "scale": 2,
                    "transform": {{"rotate": {{"axis": [0, 1, 0], "angle_deg": 90}}}}}}]}}"#
            );
            let (_, lights) = build_scene(dir.path(), &json).unwrap();
            let Light::Environment(env) = lights.light(0) else {
                panic!()
            };
            assert_eq!(env.resolution(), (16, 8));
            assert_eq!(env.scale, 2.0);
            let wl = SampledWavelengths::sample_uniform(0.6);
            let d = equirect_direction(Vec2::new(4.5 / 16.0, 3.5 / 8.0));
            let world = Mat3A::from_rotation_y(std::f32::consts::FRAC_PI_2) * d;
            let expected = synthetic(Mat3A::IDENTITY)
                .infinite_radiance(d, &wl)
                .to_array()[0]
                * 2.0;
            let got = lights.light(0).infinite_radiance(world, &wl).to_array()[0];
            // RGBE keeps 8 bits of mantissa.
            assert!(
                (got - expected).abs() < 1e-2 * expected,
                "{ext}: {got} vs {expected}"
            );
            assert_eq!(lights.infinite_lights(), &[0]);
        }
    }

    #[test]
    fn bad_environment_maps_are_errors_naming_the_light_and_the_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("text.exr"), "not an image").unwrap();
        let e = build_error(
            dir.path(),
            r#"{"lights": [{"type": "environment", "file": "text.exr"}]}"#,
        );
        assert!(
            e.contains("scene.json: lights[0].file: cannot use the environment map: "),
            "{e}"
        );
        assert!(e.contains("text.exr"), "{e}");
        let mut pixels = synthetic_pixels();
        pixels[20] = [f32::NAN, 0.0, 0.0];
        let image = prism_image::Image::new(16, 8, pixels, RgbColorSpace::srgb()).unwrap();
        prism_image::io::write_image(&dir.path().join("nan.exr"), &image).unwrap();
        let e = build_error(
            dir.path(),
            r#"{"lights": [{"type": "environment", "file": "nan.exr"}]}"#,
        );
        assert!(
            e.contains("lights[0].file: cannot use the environment map: "),
            "{e}"
        );
        assert!(
            e.contains("nan.exr: texel (4, 1) is not finite: (NaN, 0, 0)"),
            "{e}"
        );
        let mut pixels = synthetic_pixels();
        pixels[19] = [0.5, -0.25, 0.0];
        let image = prism_image::Image::new(16, 8, pixels, RgbColorSpace::srgb()).unwrap();
        prism_image::io::write_image(&dir.path().join("negative.exr"), &image).unwrap();
        let e = build_error(
            dir.path(),
            r#"{"lights": [{"type": "environment", "file": "negative.exr"}]}"#,
        );
        assert!(
            e.contains("negative.exr: texel (3, 1)") && e.contains("(0.5, -0.25, 0)"),
            "{e}"
        );
        assert!(e.contains("expected radiance ≥ 0"), "{e}");
        let e = build_error(
            dir.path(),
            r#"{"lights": [{"type": "environment", "file": "nan.exr", "transform": {"scale": [1, 2, 1]}}]}"#,
        );
        assert!(
            e.contains("lights[0].transform: an environment map can only be rotated"),
            "{e}"
        );
    }

    /// Luminance of `synthetic_pixels` per texel.
    fn synthetic_luminance() -> Vec<f64> {
        let weights = RgbColorSpace::srgb().rgb_to_xyz;
        synthetic_pixels()
            .iter()
            .map(|p| {
                weights.x_axis.y * f64::from(p[0])
                    + weights.y_axis.y * f64::from(p[1])
                    + weights.z_axis.y * f64::from(p[2])
            })
            .collect()
    }

    #[test]
    fn bilinear_radiance_interpolates_between_texel_centres() {
        let env = synthetic_with(Mat3A::IDENTITY, EnvironmentFilter::Bilinear);
        let lum = synthetic_luminance();
        let per_unit = crate::film::xyz::cd_m2_per_unit();
        let luminance = |u: f32, v: f32| {
            photometric_sum(|wl| env.infinite_radiance(equirect_direction(Vec2::new(u, v)), wl))
                / per_unit
        };
        let centre = |x: usize, y: usize| ((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 8.0);
        // The sigmoid upsampling keeps a texel's luminance within 1 %.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-2 * b;
        for (x, y) in [(4, 3), (0, 0), (15, 7)] {
            let (u, v) = centre(x, y);
            assert!(close(luminance(u, v), lum[y * 16 + x]), "centre of {x},{y}");
        }
        let (u, v) = centre(2, 5);
        let between = 0.5 * (lum[5 * 16 + 2] + lum[5 * 16 + 3]);
        assert!(close(luminance(u + 0.5 / 16.0, v), between));
        let seam = 0.5 * (lum[2 * 16 + 15] + lum[2 * 16]);
        assert!(
            close(luminance(0.0, centre(0, 2).1), seam),
            "across the seam"
        );
        let above_first = luminance(5.3 / 16.0, 0.2 / 8.0);
        assert!(
            close(above_first, luminance(5.3 / 16.0, 0.5 / 8.0)),
            "constant to the pole"
        );
        assert_eq!(
            luminance(9.5 / 16.0, 6.5 / 8.0),
            0.0,
            "the black texel's centre"
        );
        assert!(
            luminance(9.9 / 16.0, 6.5 / 8.0) > 0.0,
            "towards its neighbour"
        );
    }

    #[test]
    fn bilinear_density_follows_the_bilinear_luminance_inside_a_texel() {
        // Inside one cell the density per unit image area is f(u, v) · const: the ratio
        // pdf · sin θ / f is the same at every point of the cell.
        let env = synthetic_with(Mat3A::IDENTITY, EnvironmentFilter::Bilinear);
        let ratio = |a: f32, b: f32| {
            let uv = Vec2::new((4.0 + a) / 16.0, (2.0 + b) / 8.0);
            let d = equirect_direction(uv);
            let sin_theta = (PI * uv.y).sin();
            env.direction_pdf(d) * sin_theta / env.bilinear_luminance(uv)
        };
        let reference = ratio(0.5, 0.5);
        for (a, b) in [(0.1, 0.1), (0.9, 0.2), (0.3, 0.8), (0.7, 0.6)] {
            let r = ratio(a, b);
            assert!(
                (r - reference).abs() < 1e-4 * reference,
                "{a},{b}: {r} vs {reference}"
            );
        }
        // The black texel's cell is reachable where its neighbours light it.
        assert!(env.direction_pdf(equirect_direction(Vec2::new(9.9 / 16.0, 6.5 / 8.0))) > 0.0);
    }

    #[test]
    fn light_sampling_alone_integrates_the_radiance() {
        // E[L/pdf] over sample_li = ∫ L dω only where the density covers every direction the
        // radiance reaches: with the bilinear filter, a lone bright texel puts 7/16 of its
        // light in the black cells around it.
        let mut lone = vec![[0.0f32; 3]; 8 * 4];
        lone[8 + 5] = [3.0, 2.0, 1.0];
        for filter in [EnvironmentFilter::Nearest, EnvironmentFilter::Bilinear] {
            let lone = EnvironmentLight::from_rgb(
                RgbTexels {
                    width: 8,
                    height: 4,
                    pixels: &lone,
                    gamut: RgbGamut::Srgb,
                },
                Mat3A::IDENTITY,
                1.0,
                filter,
                SceneSphere::default(),
            )
            .unwrap();
            integrates_by_light_sampling(&lone);
            integrates_by_light_sampling(&synthetic_with(Mat3A::IDENTITY, filter));
        }
    }

    fn integrates_by_light_sampling(env: &EnvironmentLight) {
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::ZERO,
        };
        let wl = SampledWavelengths::sample_uniform(0.3);
        let channel = |s: SampledSpectrum| f64::from(s.to_array()[0]);
        let n = 1 << 16;
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for i in 0..n {
            let u = Vec2::new(
                (i as f32 + 0.5) / n as f32,
                ((i as f64 * 0.618_033_988_749_895).fract()) as f32,
            );
            let f = env
                .sample_li(&ctx, u, &wl)
                .map_or(0.0, |s| channel(s.radiance) / f64::from(s.pdf));
            sum += f;
            sum_sq += f * f;
        }
        let mean = sum / f64::from(n);
        let standard_error = ((sum_sq / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
        // The integral by a fine midpoint rule over equal-area cells in (cos θ, φ). Its own
        // error, the 0.2 % allowed beside the standard errors, is the cells that straddle a
        // nearest map's row edges: one row of 512 per edge.
        let (cells_u, cells_v) = (1024, 512);
        let mut exact = 0.0;
        for j in 0..cells_v {
            let cos_theta = 1.0 - 2.0 * (j as f64 + 0.5) / cells_v as f64;
            let v = (cos_theta.acos() / std::f64::consts::PI) as f32;
            for k in 0..cells_u {
                let u = ((k as f64 + 0.5) / cells_u as f64) as f32;
                exact += channel(env.infinite_radiance(equirect_direction(Vec2::new(u, v)), &wl));
            }
        }
        exact *= 4.0 * std::f64::consts::PI / f64::from(cells_u * cells_v);
        assert!(
            (mean - exact).abs() < 4.0 * standard_error + 2e-3 * exact,
            "{:?}: {mean} vs {exact} (s.e. {standard_error})",
            env.filter
        );
    }

    #[test]
    fn mapping_round_trips_and_has_the_documented_axes() {
        let cases = [
            (Vec2::new(0.0, 0.5), Vec3A::NEG_Z),
            (Vec2::new(0.25, 0.5), Vec3A::X),
            (Vec2::new(0.5, 0.5), Vec3A::Z),
            (Vec2::new(0.75, 0.5), Vec3A::NEG_X),
        ];
        for (uv, d) in cases {
            assert!((equirect_direction(uv) - d).length() < 1e-6, "{uv}");
            assert!((equirect_uv(d) - uv).length() < 1e-6, "{d}");
        }
        assert!((equirect_direction(Vec2::new(0.3, 0.0)) - Vec3A::Y).length() < 1e-6);
        assert!((equirect_uv(Vec3A::NEG_Y).y - 1.0).abs() < 1e-6);
        for i in 0..50 {
            let uv = Vec2::new((i as f32 * 0.137).fract(), 0.01 + 0.98 * (i as f32 / 50.0));
            assert!((equirect_uv(equirect_direction(uv)) - uv).length() < 1e-5);
        }
    }

    #[test]
    fn rotations_pass_and_shears_fail() {
        let rot = DMat4::from_axis_angle(glam::DVec3::Y, 0.7)
            * DMat4::from_scale(glam::DVec3::splat(2.0));
        let r = rotation_of(&rot).unwrap();
        assert!((r.determinant() - 1.0).abs() < 1e-5);
        let shear = DMat4::from_scale(glam::DVec3::new(1.0, 2.0, 1.0));
        assert!(rotation_of(&shear).unwrap_err().contains("only be rotated"));
    }
}

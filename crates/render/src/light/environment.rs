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
//! **Radiance.** Nearest texel, no interpolation: each texel's linear RGB (in the file's
//! colour space when it is sRGB/Rec.709, Rec.2020 or ACEScg, else converted to linear
//! sRGB; negative components clamped to 0) is upsampled once at load time to an RGB
//! illuminant spectrum (Jakob & Hanika 2019 sigmoid polynomial × the space's white
//! illuminant, pbrt-v4 `RGBIlluminantSpectrum`, table lookup without refinement): RGB
//! (1, 1, 1) is the white illuminant at Y = 1 in the output normalisation of docs/architecture.md, so
//! an EXR rendered by Prism used as an environment map gives back its own values. `scale`
//! multiplies everything.
//!
//! **Sampling.** A texel is chosen by a 2-D piecewise-constant distribution (pbrt-v4 §A.5
//! `PiecewiseConstant2D`) over luminance × the texel's solid angle ΔΩ = (2π/W)(cos θ_top −
//! cos θ_bottom) (∝ sin θ averaged over the row), then a direction uniform in solid angle
//! inside the texel (φ uniform, cos θ uniform between the row's bounds). The density is
//! P(texel)/ΔΩ: constant over each texel and proportional to its luminance — exactly the
//! shape of the nearest-texel radiance.
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
use prism_spectrum::rgb_upsample::{RgbIlluminantSpectrum, SigmoidPolynomial};
use prism_spectrum::{DenseSpectrum, RgbGamut, SampledSpectrum, SampledWavelengths, Spectrum};
use rayon::prelude::*;

use super::piecewise_constant::PiecewiseConstant2D;
use super::scene_sphere::SceneSphere;
use super::{LightHit, LightLeSample, LightSample, LightSampleContext, LightSource};

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
    /// From linear RGB pixels in `gamut` (row-major, top row first). `rotation` maps local
    /// directions to the world and must be orthogonal (see `rotation_of`). Errors name the
    /// first non-finite pixel.
    pub fn from_rgb(
        width: usize,
        height: usize,
        pixels: &[[f32; 3]],
        gamut: RgbGamut,
        rotation: Mat3A,
        scale: f32,
        scene: SceneSphere,
    ) -> Result<Self, String> {
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
        let dphi = 2.0 * std::f64::consts::PI / width as f64;
        let mut values = vec![0.0f32; width * height];
        let mut luminance_solid_angle_sr = 0.0f64;
        for y in 0..height {
            let solid_angle = dphi * (f64::from(cos_rows[y]) - f64::from(cos_rows[y + 1]));
            for x in 0..width {
                let p = pixels[y * width + x];
                let lum: f64 = (0..3)
                    .map(|c| weights[c] * f64::from(p[c].max(0.0)))
                    .sum::<f64>()
                    .max(0.0);
                values[y * width + x] = (lum * solid_angle) as f32;
                luminance_solid_angle_sr += lum * solid_angle;
            }
        }
        let white_table = gamut.white_illuminant();
        let white_dense = DenseSpectrum::from_fn(|wl| {
            f64::from(white_table[((wl - 360.0).round() as usize).min(white_table.len() - 1)])
        });
        let white_integral_nm = white_dense.values().iter().sum();
        let white = Spectrum::from_dense(&white_dense).map_err(|e| e.to_string())?;
        Ok(Self {
            width,
            height,
            texels: upsampled,
            white,
            scale,
            cos_rows,
            distribution: PiecewiseConstant2D::new(&values, width, height),
            to_world: rotation,
            to_local: rotation.transpose(),
            scene,
            luminance_solid_angle_sr,
            white_integral_nm,
        })
    }

    /// Reads an .exr/.hdr file with prism-image (`prism_image::io::read_image`); errors name
    /// the file.
    pub fn load(
        path: &Path,
        rotation: Mat3A,
        scale: f32,
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
        Self::from_rgb(width, height, &pixels, gamut, rotation, scale, scene)
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    pub fn resolution(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Luminance of every texel (row-major, top row first) in the map's own units (Y of the
    /// RGB pixels, before `scale`): what the sampling distribution was built from.
    pub fn luminance_texels(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            let d_omega = self.texel_solid_angle(y);
            for x in 0..self.width {
                let v = self.distribution.value(x, y);
                out.push(if d_omega > 0.0 { v / d_omega } else { 0.0 });
            }
        }
        out
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

    /// Density of choosing texel (x, y) per steradian: P(texel)/ΔΩ.
    #[inline]
    fn texel_pdf(&self, x: usize, y: usize) -> f32 {
        let uv = Vec2::new(
            (x as f32 + 0.5) / self.width as f32,
            (y as f32 + 0.5) / self.height as f32,
        );
        let p_texel = self.distribution.pdf(uv) / (self.width * self.height) as f32;
        let d_omega = self.texel_solid_angle(y);
        if d_omega > 0.0 {
            p_texel / d_omega
        } else {
            0.0
        }
    }

    /// A direction from the texel distribution (world, towards the light) and its texel.
    #[inline]
    fn sample_direction(&self, u: Vec2) -> Option<(Vec3A, usize, usize)> {
        let (uv, pdf_uv, [x, y]) = self.distribution.sample(u);
        if pdf_uv.is_nan() || pdf_uv <= 0.0 || x >= self.width || y >= self.height {
            return None;
        }
        // Uniform in solid angle within the texel: cos θ uniform between the row bounds.
        let fv = (uv.y * self.height as f32 - y as f32).clamp(0.0, 1.0);
        let (c0, c1) = (self.cos_rows[y], self.cos_rows[y + 1]);
        let cos_theta = c0 + fv * (c1 - c0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_p, cos_p) = (2.0 * PI * uv.x).sin_cos();
        let local = Vec3A::new(sin_p * sin_theta, cos_theta, -cos_p * sin_theta);
        Some(((self.to_world * local).normalize(), x, y))
    }

    /// The texel a world direction (towards the light) falls in.
    #[inline]
    fn texel_of(&self, wi: Vec3A) -> (usize, usize) {
        self.texel(equirect_uv((self.to_local * wi).normalize()))
    }

    /// Solid-angle density of `sample_li`'s directions at `wi`.
    #[inline]
    pub fn direction_pdf(&self, wi: Vec3A) -> f32 {
        let (x, y) = self.texel_of(wi);
        self.texel_pdf(x, y)
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
        let (wi, x, y) = self.sample_direction(u)?;
        let pdf = self.texel_pdf(x, y);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(LightSample {
            wi,
            radiance: self.texel_radiance(x, y, wavelengths),
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
        let (x, y) = self.texel_of(direction);
        self.texel_radiance(x, y, wavelengths)
    }

    fn sample_le(
        &self,
        scene: &SceneSphere,
        u_pos: Vec2,
        u_dir: Vec2,
        wavelengths: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (wi, _, _) = self.sample_direction(u_dir)?;
        // The texel the direction maps back to (the sampled one but on a texel edge), so
        // that the sample and `pdf_le` agree.
        let (x, y) = self.texel_of(wi);
        scene.emission(
            wi,
            u_pos,
            self.texel_radiance(x, y, wavelengths),
            self.texel_pdf(x, y),
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
        EnvironmentLight::from_rgb(
            16,
            8,
            &synthetic_pixels(),
            RgbGamut::Srgb,
            rotation,
            1.0,
            SceneSphere::default(),
        )
        .unwrap()
    }

    #[test]
    fn chi2_environment() {
        let rotations = [
            Mat3A::IDENTITY,
            Mat3A::from_axis_angle(glam::Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9),
        ];
        let config = chi2_config(rotations.len(), 71);
        let ctx = LightSampleContext {
            p: Vec3A::ZERO,
            n: Vec3A::Y,
        };
        let wl = SampledWavelengths::sample_uniform(0.4);
        for rotation in rotations {
            let env = synthetic(rotation);
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
            2,
            1,
            &[[0.25; 3], [2.0; 3]],
            RgbGamut::Srgb,
            Mat3A::IDENTITY,
            3.0,
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

//! t of Bagher et al. 2013 eq. 3 (the texture term of B_{t,ρ}): a texture's spatial
//! bandwidth at a hit, in cycles per metre, as the lookup at that hit's footprint filters it.
//!
//! - **Image textures**: eq. 7's local bandwidth (prism-bandwidth `LocalBandwidth`) of the
//!   level-0 texels' scalar (the channel a scalar use reads; luminance for colours), in
//!   cycles per texel, times texels per st unit (the larger of width and height). A
//!   trilinear lookup reads MIP level ℓ = log₂ w (w = texels per pixel step), which holds
//!   nothing above ½·2^{−ℓ} cycles per level-0 texel: t is capped there. Nearest and
//!   bilinear lookups read level 0 whatever the footprint (they alias), so no cap.
//! - **Checkerboard**: a square wave of period 2 st units; its 95 %-energy bandwidth is its
//!   7th harmonic, 3.5 cycles per st unit (odd harmonics carry 8/(π²k²) of the energy:
//!   81.1 % in the fundamental, 94.96 % up to k = 7; a DFT of the sampled wave crosses 95 %
//!   there, the tests check). The lookup box-filters over the
//!   footprint w (st units per pixel step), which removes harmonics above ≈ 1/w: t is the
//!   highest odd harmonic k/2 ≤ 1/w (0 when even the fundamental is filtered out).
//! - **Noise**: octave i has frequency f·Lⁱ (L the lacunarity) in noise units and amplitude
//!   gainⁱ; Perlin noise's 95 %-energy bandwidth is [`PERLIN_BETA_CYCLES_PER_UNIT`] per unit
//!   of its own frequency (measured in the tests). Of the octaves the lookup keeps (it drops
//!   those finer than twice the footprint, `Octaves::fbm`), t is that of the coarsest octave
//!   up to which the octaves hold 95 % of the kept energy Σ gain^{2i} — the same 95 %-energy
//!   convention as eq. 7's β and the checkerboard's harmonic. Turbulence (|noise|) doubles
//!   every frequency. World-space noise is in cycles per metre already.
//! - A texture whose two values are equal (a blend of a with a) has t = 0.
//!
//! st per metre at the hit: the larger of |∂st/∂x|/|∂p/∂x| and |∂st/∂y|/|∂p/∂y| (the pixel
//! steps' ratio of texture to surface distance), from the G-buffer's differentials.

use std::sync::Arc;

use glam::{UVec2, Vec2};
use prism_bandwidth::local_bandwidth::{Boundary, LocalBandwidth};
use prism_image::image::luminance_weights;
use prism_scene::{ImageChannel, NoiseKind, NoiseSpace, TextureFilter};
use prism_spectrum::rgb_space::RgbColorSpace;

use super::{Texture, TextureContext, TextureSource};

/// 95 %-energy bandwidth of Prism's Perlin noise along a line, cycles per noise unit
/// (re-measured by a DFT in the tests).
pub const PERLIN_BETA_CYCLES_PER_UNIT: f32 = 0.69;

/// The checkerboard's 95 %-energy bandwidth: its 7th harmonic, cycles per st unit.
const CHECKERBOARD_BETA_CYCLES_PER_ST: f32 = 3.5;

/// The share of a signal's energy its bandwidth holds (eq. 7's β, the harmonics, octaves).
const ENERGY_SHARE: f64 = 0.95;

/// What a texture's bandwidth depends on, precomputed once per texture.
#[derive(Clone, Debug)]
enum Source {
    /// Constant (both blend values equal): t = 0.
    Flat,
    /// Per level-0 texel, eq. 7 in cycles per texel (row 0 at v = 0, as the MIP map).
    Image {
        width: u32,
        height: u32,
        cycles_per_texel: Vec<f32>,
        filter: TextureFilter,
    },
    Checkerboard,
    Noise {
        kind: NoiseKind,
        space: NoiseSpace,
        frequency: f32,
        octaves: super::Octaves,
    },
}

/// One texture's t, ready to answer per hit.
#[derive(Clone, Debug)]
pub struct TextureBandwidth {
    texture: Arc<Texture>,
    source: Source,
}

impl TextureBandwidth {
    /// Precomputes `texture`'s bandwidth (eq. 7 over an image's level 0).
    pub fn new(texture: Arc<Texture>) -> Result<Self, String> {
        let flat_blend = texture.a == texture.b && texture.a_scalar == texture.b_scalar;
        let source = match &texture.source {
            TextureSource::Image(image) => {
                let (w, h) = image.mip.level_size(0);
                // Textures hold linear Rec.709 RGB (sRGB primaries).
                let luminance = luminance_weights(&RgbColorSpace::srgb());
                let values: Vec<f32> = (0..h as i64)
                    .flat_map(|y| (0..w as i64).map(move |x| (x, y)))
                    .map(|(x, y)| scalar_of(image.channel, image.mip.texel(0, x, y), luminance))
                    .collect();
                let resolution = UVec2::new(w as u32, h as u32);
                let local =
                    LocalBandwidth::estimate(&values, resolution, 1.0, Boundary::InsideOnly)
                        .map_err(|e| format!("{}: texture bandwidth: {e}", texture.place))?;
                Source::Image {
                    width: w as u32,
                    height: h as u32,
                    cycles_per_texel: local.cycles_per_unit().to_vec(),
                    filter: image.filter,
                }
            }
            TextureSource::Checkerboard if flat_blend => Source::Flat,
            TextureSource::Checkerboard => Source::Checkerboard,
            TextureSource::Noise(_) if flat_blend => Source::Flat,
            TextureSource::Noise(n) => Source::Noise {
                kind: n.kind,
                space: n.space,
                frequency: n.frequency,
                octaves: n.octaves,
            },
        };
        Ok(Self { texture, source })
    }

    /// t at a hit seen through `ctx` (its uv and one-pixel derivatives), cycles/m.
    pub fn cycles_per_m(&self, ctx: &TextureContext) -> f32 {
        let (st, dst0, dst1) = self.texture.mapping.map(ctx);
        let st_per_m = st_per_metre(ctx, dst0, dst1);
        let footprint_st = dst0.length().max(dst1.length());
        match &self.source {
            Source::Flat => 0.0,
            Source::Image {
                width,
                height,
                cycles_per_texel,
                filter,
            } => {
                let (w, h) = (*width as f32, *height as f32);
                let x = (wrap01(st.x) * w).min(w - 1.0) as u32;
                let y = (wrap01(st.y) * h).min(h - 1.0) as u32;
                let mut cycles = cycles_per_texel[(y * width + x) as usize];
                if *filter == TextureFilter::Trilinear {
                    // Level log₂(texels per pixel step) holds nothing above ½·2^−ℓ.
                    let texels_per_px = footprint_st * w.max(h);
                    if texels_per_px > 1.0 {
                        cycles = cycles.min(0.5 / texels_per_px);
                    }
                }
                cycles * w.max(h) * st_per_m
            }
            Source::Checkerboard => {
                let passed = if footprint_st > 0.0 {
                    1.0 / footprint_st
                } else {
                    f32::INFINITY
                };
                // The highest odd harmonic k/2 (k ≤ 7) the box filter lets through.
                let harmonic = [7.0f32, 5.0, 3.0, 1.0]
                    .into_iter()
                    .map(|k| 0.5 * k)
                    .find(|&f| f <= passed)
                    .unwrap_or(0.0);
                harmonic.min(CHECKERBOARD_BETA_CYCLES_PER_ST) * st_per_m
            }
            Source::Noise {
                kind,
                space,
                frequency,
                octaves,
            } => {
                // Noise units per metre, and the footprint in noise units.
                let (units_per_m, footprint) = match space {
                    NoiseSpace::World => (
                        *frequency,
                        *frequency * ctx.dpdx.length().max(ctx.dpdy.length()),
                    ),
                    NoiseSpace::Uv => (*frequency * st_per_m, *frequency * footprint_st),
                };
                let max_octaves = match kind {
                    NoiseKind::Perlin => 1,
                    NoiseKind::Fbm | NoiseKind::Turbulence => octaves.max_octaves,
                };
                let finest = finest_octave(octaves, max_octaves, f64::from(footprint));
                let Some(finest) = finest else {
                    return 0.0;
                };
                let doubling = match kind {
                    NoiseKind::Turbulence => 2.0,
                    NoiseKind::Perlin | NoiseKind::Fbm => 1.0,
                };
                let octave_frequency = octaves.lacunarity.powi(finest as i32) as f32;
                doubling * PERLIN_BETA_CYCLES_PER_UNIT * octave_frequency * units_per_m
            }
        }
    }
}

/// Of the octaves the footprint (noise units per pixel) resolves, the coarsest up to which
/// they hold [`ENERGY_SHARE`] of their energy Σ gain^{2i}; `None` when none is resolved.
fn finest_octave(octaves: &super::Octaves, max_octaves: u32, footprint: f64) -> Option<u32> {
    // `Octaves::fbm` drops octaves with features smaller than twice the footprint.
    let resolved = (0..max_octaves)
        .take_while(|&i| {
            footprint <= 0.0 || 2.0 * footprint * octaves.lacunarity.powi(i as i32) <= 1.0
        })
        .count() as u32;
    let energy = |i: u32| octaves.gain.powi(2 * i as i32);
    let total: f64 = (0..resolved).map(energy).sum();
    let mut held = 0.0;
    (0..resolved).find(|&i| {
        held += energy(i);
        held >= ENERGY_SHARE * total
    })
}

/// st units per metre along the surface: the larger ratio of the pixel steps' st and
/// surface distances; 0 without differentials (no footprint known).
fn st_per_metre(ctx: &TextureContext, dst0: Vec2, dst1: Vec2) -> f32 {
    let ratio = |dst: Vec2, dp: f32| if dp > 0.0 { dst.length() / dp } else { 0.0 };
    ratio(dst0, ctx.dpdx.length()).max(ratio(dst1, ctx.dpdy.length()))
}

fn wrap01(x: f32) -> f32 {
    let f = x - x.floor();
    if f.is_finite() {
        f
    } else {
        0.0
    }
}

/// The scalar a texel contributes to shading variation: the channel of scalar uses, the
/// luminance (`weights`: Y of linear RGB) of colours (channel `average` is also what colour
/// uses default to).
fn scalar_of(channel: ImageChannel, rgba: [f32; 4], weights: [f32; 3]) -> f32 {
    match channel {
        ImageChannel::Average => weights[0] * rgba[0] + weights[1] * rgba[1] + weights[2] * rgba[2],
        ImageChannel::R => rgba[0],
        ImageChannel::G => rgba[1],
        ImageChannel::B => rgba[2],
        ImageChannel::A => rgba[3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{ImageSource, MipMap, NoiseSource, Octaves, UvMapping};
    use glam::Vec3A;
    use prism_scene::WrapMode;
    use prism_spectrum::Spectrum;

    fn texture(source: TextureSource, a: f32, b: f32) -> Arc<Texture> {
        Arc::new(Texture {
            mapping: UvMapping::identity(),
            source,
            a: Spectrum::constant(a),
            b: Spectrum::constant(b),
            a_scalar: a,
            b_scalar: b,
            place: "test".into(),
        })
    }

    /// A flat hit 1 m per uv unit, `st_per_px` uv units per pixel step.
    fn ctx(uv: Vec2, st_per_px: f32) -> TextureContext {
        TextureContext {
            p: Vec3A::ZERO,
            dpdx: Vec3A::new(st_per_px, 0.0, 0.0),
            dpdy: Vec3A::new(0.0, st_per_px, 0.0),
            uv,
            duvdx: Vec2::new(st_per_px, 0.0),
            duvdy: Vec2::new(0.0, st_per_px),
        }
    }

    /// 95 %-energy frequency of a real signal sampled `rate` times per unit (plain DFT).
    fn energy_bandwidth(samples: &[f64], rate: f64) -> f64 {
        let n = samples.len();
        let mean = samples.iter().sum::<f64>() / n as f64;
        let power: Vec<f64> = (1..n / 2)
            .map(|k| {
                let (mut re, mut im) = (0.0, 0.0);
                for (j, s) in samples.iter().enumerate() {
                    let a = -2.0 * std::f64::consts::PI * (k * j) as f64 / n as f64;
                    re += (s - mean) * a.cos();
                    im += (s - mean) * a.sin();
                }
                re * re + im * im
            })
            .collect();
        let total: f64 = power.iter().sum();
        let mut acc = 0.0;
        for (i, p) in power.iter().enumerate() {
            acc += p;
            if acc >= 0.95 * total {
                return (i + 1) as f64 * rate / n as f64;
            }
        }
        rate / 2.0
    }

    #[test]
    fn perlin_beta_is_the_measured_95_percent_energy_bandwidth() {
        // Lines through the noise at 16 samples per unit, 256 units each, averaged.
        let rate = 16.0;
        let measured: f64 = (0..4)
            .map(|line| {
                let samples: Vec<f64> = (0..4096)
                    .map(|j| {
                        let x = j as f64 / rate;
                        crate::texture::perlin_noise([x, 0.37 + line as f64 * 7.1, 0.61])
                    })
                    .collect();
                energy_bandwidth(&samples, rate)
            })
            .sum::<f64>()
            / 4.0;
        let beta = f64::from(PERLIN_BETA_CYCLES_PER_UNIT);
        assert!(
            (measured / beta - 1.0).abs() < 0.1,
            "measured {measured}, constant {beta}"
        );
    }

    #[test]
    fn checkerboard_beta_holds_95_percent_of_a_square_wave() {
        let samples: Vec<f64> = (0..4096)
            .map(|j| if (j / 64) % 2 == 0 { 1.0 } else { 0.0 })
            .collect();
        // 64 samples per st unit: period 2 st units.
        let measured = energy_bandwidth(&samples, 64.0);
        assert!((measured - 3.5).abs() < 0.05, "{measured}");
    }

    #[test]
    fn checkerboard_t_falls_as_the_footprint_filters_its_harmonics() {
        let t = TextureBandwidth::new(texture(TextureSource::Checkerboard, 0.1, 0.9)).unwrap();
        let at = |w: f32| t.cycles_per_m(&ctx(Vec2::splat(0.3), w));
        assert_eq!(at(0.01), 3.5);
        assert_eq!(at(0.25), 3.5);
        assert_eq!(at(0.3), 2.5);
        assert_eq!(at(1.0), 0.5);
        assert_eq!(at(3.0), 0.0);
        let flat = TextureBandwidth::new(texture(TextureSource::Checkerboard, 0.5, 0.5)).unwrap();
        assert_eq!(flat.cycles_per_m(&ctx(Vec2::ZERO, 0.01)), 0.0);
    }

    #[test]
    fn world_noise_t_is_its_finest_strong_resolved_octave() {
        let noise = |kind, octaves| {
            TextureSource::Noise(NoiseSource {
                kind,
                space: NoiseSpace::World,
                frequency: 2.0,
                octaves: Octaves {
                    max_octaves: octaves,
                    gain: 0.5,
                    lacunarity: 2.0,
                },
            })
        };
        let t = |kind, octaves, w| {
            TextureBandwidth::new(texture(noise(kind, octaves), 0.0, 1.0))
                .unwrap()
                .cycles_per_m(&ctx(Vec2::ZERO, w))
        };
        let beta = PERLIN_BETA_CYCLES_PER_UNIT;
        // Gain ½: octave energies 1, ¼, 1/16, 1/64…; octaves 0–2 hold 98.4 % of any longer
        // sum (≥ 95 %), octaves 0–1 only 93.75 %: octave 2 (frequency 2·2²) is t's.
        assert_eq!(t(NoiseKind::Fbm, 8, 1e-5), beta * 2.0 * 4.0);
        assert_eq!(t(NoiseKind::Turbulence, 8, 1e-5), 2.0 * beta * 2.0 * 4.0);
        assert_eq!(t(NoiseKind::Perlin, 8, 1e-5), beta * 2.0);
        // Two octaves: energies 1 and ¼, octave 0 holds 80 %: octave 1.
        assert_eq!(t(NoiseKind::Fbm, 2, 1e-5), beta * 2.0 * 2.0);
        // 0.1 m per pixel = 0.2 noise units: only octaves with 2·0.2·2ⁱ ≤ 1 (i ≤ 1) are kept.
        assert_eq!(t(NoiseKind::Fbm, 8, 0.1), beta * 2.0 * 2.0);
        // 0.3 m per pixel: not even octave 0 (2·0.6 > 1): the lookup returns the mean.
        assert_eq!(t(NoiseKind::Fbm, 8, 0.3), 0.0);
    }

    fn stripes(period_texels: usize, filter: TextureFilter) -> Arc<Texture> {
        let (w, h) = (64usize, 64usize);
        let texels = (0..w * h)
            .map(|i| {
                let v = if (i % w / (period_texels / 2)).is_multiple_of(2) {
                    0.0
                } else {
                    1.0
                };
                [v, v, v, 1.0]
            })
            .collect();
        let image = ImageSource {
            mip: MipMap::new(w, h, texels, WrapMode::Repeat),
            filter,
            channel: ImageChannel::Average,
        };
        texture(TextureSource::Image(image), 0.0, 0.0)
    }

    #[test]
    fn image_t_is_eq_7_in_texels_per_metre_and_trilinear_caps_it_at_its_mip_level() {
        // Hard stripes: eq. 7 answers its finest wavelet, β cycles per texel, at every texel.
        let bilinear = TextureBandwidth::new(stripes(8, TextureFilter::Bilinear)).unwrap();
        let fine = 1.0 / 256.0; // uv per pixel: a quarter texel
        let t = bilinear.cycles_per_m(&ctx(Vec2::new(0.51, 0.5), fine));
        let expected = prism_bandwidth::local_bandwidth::HAAR_BETA_CYCLES_PER_TEXEL * 64.0;
        assert!((t / expected - 1.0).abs() < 1e-5, "{t} vs {expected}");
        // Four texels per pixel: trilinear reads level 2, ½·¼ cycles per texel at most;
        // bilinear still reads level 0.
        let trilinear = TextureBandwidth::new(stripes(8, TextureFilter::Trilinear)).unwrap();
        let coarse = 4.0 / 64.0;
        let t_tri = trilinear.cycles_per_m(&ctx(Vec2::new(0.51, 0.5), coarse));
        assert!((t_tri - 0.125 * 64.0).abs() < 1e-3, "{t_tri}");
        let t_bi = bilinear.cycles_per_m(&ctx(Vec2::new(0.51, 0.5), coarse));
        assert!((t_bi / expected - 1.0).abs() < 1e-5, "{t_bi}");
    }
}

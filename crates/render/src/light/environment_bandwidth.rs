//! ν_a of an environment map per direction (Bagher et al. 2013 §2.3, "Distant
//! illumination"): eq. 7's local bandwidth of the lat-long luminance in cycles per texel,
//! divided by the texel's angular size — the largest singular value of the map's Jacobian,
//! max(π/H, 2π sin θ/W) rad per texel — so ν_a is in cycles per radian. Built only when the
//! predictor runs (`predictor::predict`), once per environment light.

use glam::{UVec2, Vec3A};
use prism_bandwidth::local_bandwidth::{Boundary, LocalBandwidth};

use super::EnvironmentLight;

/// Per texel of an environment map, its angular bandwidth in cycles/rad.
#[derive(Clone, Debug)]
pub struct EnvironmentBandwidth {
    width: usize,
    height: usize,
    cycles_per_rad: Vec<f32>,
}

impl EnvironmentBandwidth {
    /// Eq. 7 over `light`'s luminance.
    pub fn new(light: &EnvironmentLight) -> Result<Self, String> {
        let (width, height) = light.resolution();
        let resolution = UVec2::new(width as u32, height as u32);
        let local = LocalBandwidth::estimate(
            light.luminance_texels(),
            resolution,
            1.0,
            Boundary::InsideOnly,
        )
        .map_err(|e| format!("environment map bandwidth: {e}"))?;
        let per_texel = local.cycles_per_unit();
        let (w, h) = (width as f32, height as f32);
        let cycles_per_rad = (0..width * height)
            .map(|i| {
                let theta = std::f32::consts::PI * ((i / width) as f32 + 0.5) / h;
                let rad_per_texel =
                    (std::f32::consts::PI / h).max(2.0 * std::f32::consts::PI * theta.sin() / w);
                per_texel[i] / rad_per_texel
            })
            .collect();
        Ok(Self {
            width,
            height,
            cycles_per_rad,
        })
    }

    /// ν_a towards `wi` (world, towards the light), cycles/rad.
    pub fn at(&self, light: &EnvironmentLight, wi: Vec3A) -> f32 {
        let uv = light.local_uv(wi);
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        self.cycles_per_rad[y * self.width + x]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::scene_sphere::SceneSphere;
    use glam::Mat3A;
    use prism_spectrum::RgbGamut;

    fn env(pixels: &[[f32; 3]], w: usize, h: usize) -> EnvironmentLight {
        EnvironmentLight::from_rgb(
            crate::light::environment::RgbTexels {
                width: w,
                height: h,
                pixels,
                gamut: RgbGamut::Srgb,
            },
            Mat3A::IDENTITY,
            1.0,
            crate::light::environment::EnvironmentFilter::Nearest,
            SceneSphere::default(),
        )
        .unwrap()
    }

    #[test]
    fn a_uniform_map_has_no_bandwidth_and_stripes_have_their_frequency() {
        let (w, h) = (128, 64);
        let uniform = env(&vec![[0.5; 3]; w * h], w, h);
        let b = EnvironmentBandwidth::new(&uniform).unwrap();
        assert!(b.cycles_per_rad.iter().all(|&v| v == 0.0));
        // 16 periods around the equator: 16/(2π) ≈ 2.55 cycles/rad there.
        let stripes: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let x = (i % w) as f32;
                let v = 0.5 + 0.4 * (2.0 * std::f32::consts::PI * 16.0 * x / w as f32).sin();
                [v; 3]
            })
            .collect();
        let light = env(&stripes, w, h);
        let b = EnvironmentBandwidth::new(&light).unwrap();
        // The horizon, looking along −z (the map's centre column is +x or −z: any azimuth
        // works for stripes).
        let nu = b.at(&light, Vec3A::new(0.0, 0.0, -1.0));
        let expected = 16.0 / (2.0 * std::f32::consts::PI);
        assert!(
            nu > 0.5 * expected && nu < 2.0 * expected,
            "{nu} vs {expected}"
        );
    }
}

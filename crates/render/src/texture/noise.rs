//! Perlin's improved noise (Perlin 2002, "Improving noise", SIGGRAPH; the reference
//! implementation's permutation, gradients and quintic fade), fractional Brownian motion
//! and turbulence (Perlin 1985), antialiased by dropping the octaves finer than the
//! pixel footprint and fading the last one in (pbrt-v4 §10.6.2 `FBm`, `Turbulence`).

use glam::Vec3A;

/// Perlin's reference permutation of 0..=255 (Perlin 2002), repeated once so
/// `P[P[x] + y]` needs no wrap.
const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

#[inline]
fn perm(i: usize) -> usize {
    PERMUTATION[i & 255] as usize
}

#[inline]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// The 12 edge gradients of the cube (plus 4 repeats), Perlin 2002.
#[inline]
fn grad(hash: usize, x: f64, y: f64, z: f64) -> f64 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Improved noise at `p` (f64 inside so cells stay exact far from the origin); zero on
/// the integer lattice, in [−1, 1].
pub fn perlin_noise(p: [f64; 3]) -> f64 {
    let [x, y, z] = p;
    let (xf, yf, zf) = (x.floor(), y.floor(), z.floor());
    let (xi, yi, zi) = (
        (xf as i64 & 255) as usize,
        (yf as i64 & 255) as usize,
        (zf as i64 & 255) as usize,
    );
    let (x, y, z) = (x - xf, y - yf, z - zf);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = perm(xi) + yi;
    let (aa, ab) = (perm(a) + zi, perm(a + 1) + zi);
    let b = perm(xi + 1) + yi;
    let (ba, bb) = (perm(b) + zi, perm(b + 1) + zi);
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(perm(aa), x, y, z), grad(perm(ba), x - 1.0, y, z)),
            lerp(
                u,
                grad(perm(ab), x, y - 1.0, z),
                grad(perm(bb), x - 1.0, y - 1.0, z),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                grad(perm(aa + 1), x, y, z - 1.0),
                grad(perm(ba + 1), x - 1.0, y, z - 1.0),
            ),
            lerp(
                u,
                grad(perm(ab + 1), x, y - 1.0, z - 1.0),
                grad(perm(bb + 1), x - 1.0, y - 1.0, z - 1.0),
            ),
        ),
    )
}

#[inline]
fn smooth_step(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Octave parameters of a noise sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Octaves {
    pub max_octaves: u32,
    /// Amplitude ratio between octaves, in (0, 1).
    pub gain: f64,
    /// Frequency ratio between octaves, > 1.
    pub lacunarity: f64,
}

impl Octaves {
    /// How many octaves the footprint resolves (pbrt-v4 `FBm`): octave i has features of
    /// size lacunarity⁻ⁱ noise units; those smaller than twice the footprint `len` alias.
    /// Continuous, in [0, max_octaves]; `len = 0` keeps them all.
    fn resolved(&self, footprint: f64) -> f64 {
        // Zero, negative or NaN footprints keep every octave.
        if footprint.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return f64::from(self.max_octaves);
        }
        (-(1.0 + footprint.log2()) / self.lacunarity.log2()).clamp(0.0, f64::from(self.max_octaves))
    }

    /// Σ amplitudes (normalisation of the sums).
    fn amplitude_sum(&self) -> f64 {
        (0..self.max_octaves)
            .map(|i| self.gain.powi(i as i32))
            .sum()
    }

    /// fBm normalised to [−1, 1]: Σ gainⁱ n(lacunarityⁱ p) / Σ gainⁱ. Octaves finer than
    /// the footprint (noise units per pixel) are dropped (their mean, 0).
    pub fn fbm(&self, p: Vec3A, footprint: f64) -> f64 {
        let n = self.resolved(footprint);
        let whole = n.floor() as u32;
        let (mut sum, mut freq, mut amp) = (0.0, 1.0, 1.0);
        let p = [f64::from(p.x), f64::from(p.y), f64::from(p.z)];
        let at = |f: f64| perlin_noise([p[0] * f, p[1] * f, p[2] * f]);
        for _ in 0..whole {
            sum += amp * at(freq);
            freq *= self.lacunarity;
            amp *= self.gain;
        }
        if whole < self.max_octaves {
            sum += amp * smooth_step(0.3, 0.7, n - f64::from(whole)) * at(freq);
        }
        sum / self.amplitude_sum()
    }

    /// Turbulence normalised to [0, 1]: Σ gainⁱ |n(lacunarityⁱ p)| / Σ gainⁱ; dropped
    /// octaves contribute their mean |n| ≈ 0.2 (pbrt-v4 `Turbulence`).
    pub fn turbulence(&self, p: Vec3A, footprint: f64) -> f64 {
        const MEAN_ABS_NOISE: f64 = 0.2;
        let n = self.resolved(footprint);
        let whole = n.floor() as u32;
        let (mut sum, mut freq, mut amp) = (0.0, 1.0, 1.0);
        let p = [f64::from(p.x), f64::from(p.y), f64::from(p.z)];
        let at = |f: f64| perlin_noise([p[0] * f, p[1] * f, p[2] * f]).abs();
        for _ in 0..whole {
            sum += amp * at(freq);
            freq *= self.lacunarity;
            amp *= self.gain;
        }
        if whole < self.max_octaves {
            let fadein = smooth_step(0.3, 0.7, n - f64::from(whole));
            sum += amp * lerp(fadein, MEAN_ABS_NOISE, at(freq));
            amp *= self.gain;
            for _ in whole + 1..self.max_octaves {
                sum += amp * MEAN_ABS_NOISE;
                amp *= self.gain;
            }
        }
        (sum / self.amplitude_sum()).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutation_is_a_permutation() {
        let mut seen = [false; 256];
        for &p in &PERMUTATION {
            assert!(!seen[p as usize]);
            seen[p as usize] = true;
        }
    }

    #[test]
    fn reference_value_and_lattice_zeros() {
        // Perlin's Java reference `ImprovedNoise.noise(3.14, 42, 7)` (3.14 is his literal
        // argument, not π).
        #[allow(clippy::approx_constant)]
        let n = perlin_noise([3.14, 42.0, 7.0]);
        assert!((n - 0.136_919_958_784).abs() < 1e-9, "{n}");
        for p in [[0.0, 0.0, 0.0], [3.0, -7.0, 12.0], [255.0, 256.0, 1000.0]] {
            assert_eq!(perlin_noise(p), 0.0);
        }
    }

    #[test]
    fn noise_is_bounded_and_continuous() {
        let mut max = 0.0f64;
        let mut x = 0.1234f64;
        for _ in 0..20000 {
            x = (x * 9301.0 + 49297.0) % 233280.0;
            let p = [x / 1000.0, (x * 0.37) % 91.0, (x * 0.11) % 17.0];
            let n = perlin_noise(p);
            max = max.max(n.abs());
            let near = perlin_noise([p[0] + 1e-6, p[1], p[2]]);
            assert!((n - near).abs() < 1e-4);
        }
        assert!(max <= 1.0 && max > 0.5, "{max}");
    }

    #[test]
    fn wide_footprints_drop_octaves_to_their_mean() {
        let o = Octaves {
            max_octaves: 6,
            gain: 0.5,
            lacunarity: 2.0,
        };
        let p = Vec3A::new(1.3, 2.7, 0.4);
        assert_eq!(o.fbm(p, 100.0), 0.0);
        let t = o.turbulence(p, 100.0);
        assert!((t - 0.2).abs() < 1e-12);
        // Zero footprint keeps every octave.
        assert_eq!(o.fbm(p, 0.0), o.fbm(p, 1e-9));
    }
}

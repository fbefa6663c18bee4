//! Local bandwidth of a 2-D signal with a Haar wavelet pyramid (Bagher et al. 2013 §2.3,
//! eq. 7 and Fig. 6): the one estimator behind the bandwidths of textures, area lights,
//! environment maps and BSDF slices.
//!
//! The pyramid is amplitude-normalised: on a 2^{ℓ+1} × 2^{ℓ+1} block at level ℓ (ℓ = 0 the
//! finest, 2×2 texels) the signal is avg + d_h ψ_h + d_v ψ_v + d_d ψ_d with |ψ| = 1, so a
//! coefficient is an amplitude in the signal's units. Per texel, λ_ℓ is the largest |d| of
//! the level-ℓ wavelets covering it. The pyramid is undecimated (blocks at every offset, not
//! only at multiples of 2^{ℓ+1}): the decimated one misses an edge that falls on a block
//! boundary and answers a sinusoid according to its phase.
//!
//! Choosing the level (a deviation from eq. 7, measured): eq. 7 takes the finest level ℓ*
//! whose cumulative Σ_{k≤ℓ} λ_k reaches ε·max_k λ_k, ε = 0.01. A Haar wavelet of half-width
//! h answers a sinusoid of frequency f ≪ 1/h with λ ≈ π h f · amplitude, only linearly
//! small, so level 0 passes ε = 0.01 for every period below ≈ 440 texels: ℓ* = 0 and
//! ν = β/Δ whatever the signal (a test checks the level-0 claim; measured on 256²
//! sinusoids: 1.2× to 31× the true frequency for periods 2.5 to 64 texels; band-limited
//! noise: median 2× to 7× the windowed-FFT value for cut-offs 0.25 to 0.06 cycles/texel). Here ℓ* is the level of the largest λ_ℓ
//! (the finest of equal maxima, so a step edge keeps level 0), refined to a fraction of a
//! level by a parabola through log λ at ℓ* − 1, ℓ*, ℓ* + 1. Where every λ_ℓ is below a
//! round-off floor (10⁻⁶ of the signal's largest |value|) the signal is constant: ν = 0.
//!
//! Bandwidth: ν = β / (2^{ℓ*} Δ), β = [`HAAR_BETA_CYCLES_PER_TEXEL`] the 95 %-energy
//! bandwidth of the finest wavelet (two texels, +1 and −1), Δ the texel size in units of the
//! signal's coordinate (metres per texel for a texture or an area light, radians per texel
//! for an angular map): ν is in cycles per that unit (cycles/m, cycles/rad; `bandwidth`
//! module). Where Δ varies over the map (a lat-long environment map, whose Δ per texel is
//! the largest singular value of the mapping's Jacobian), pass Δ = 1 and divide each
//! texel's cycles/texel by its own Δ.
//!
//! Borders and sizes: any width and height; no power of two is needed because the pyramid
//! is undecimated. Only wavelets lying inside the image count (no extension: with the
//! border replicated, coarse blocks are mostly copies of one border row, a false edge, and
//! 5 % of the noise test's windows came out ≈ 50× too low), so the coarsest level has
//! blocks as large as the smaller side allows, and a texel near a border is judged by the
//! fewer blocks that fit (the tests measure it). [`Boundary::ZeroPadDouble`]
//! is Bagher's treatment of area lights: the image is centred in a field of zeros twice its
//! size, so the emitter's outline is an edge, and the result is cropped back.

use glam::UVec2;

use crate::error::{pixel_count, pixel_index, BandwidthError};

/// β: the 95 %-energy bandwidth of the finest Haar wavelet (+1, −1 on two texels), cycles
/// per texel. Its energy spectrum is 4 sin²(πf) on |f| ≤ ½; 95 % of it lies in |f| ≤ β
/// (re-measured by a DFT in the tests).
pub const HAAR_BETA_CYCLES_PER_TEXEL: f32 = 0.4875;

/// How the signal continues outside the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Boundary {
    /// Only the wavelets inside the image count: textures, environment maps, BSDF slices.
    InsideOnly,
    /// Zeros around the image, which is centred in a field twice its size: area lights
    /// (Bagher §2.3), whose outline is a real edge.
    ZeroPadDouble,
}

/// Per-texel local bandwidth of a 2-D signal (cycles per unit of the texel coordinates),
/// row-major like the input.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalBandwidth {
    resolution: UVec2,
    cycles_per_unit: Vec<f32>,
}

impl LocalBandwidth {
    /// Bagher eq. 7 (with the level choice above) on `values` (row-major, `resolution`),
    /// texels `texel_size` units wide (m or rad per texel; > 0, finite).
    pub fn estimate(
        values: &[f32],
        resolution: UVec2,
        texel_size: f32,
        boundary: Boundary,
    ) -> Result<Self, BandwidthError> {
        const WHAT: &str = "local bandwidth";
        let count = pixel_count(WHAT, resolution)?;
        if values.len() != count {
            return Err(BandwidthError::LengthMismatch {
                what: WHAT,
                resolution,
                found: values.len(),
            });
        }
        if !(texel_size.is_finite() && texel_size > 0.0) {
            return Err(BandwidthError::invalid(
                WHAT,
                "texel_size",
                texel_size,
                "finite, > 0 (units per texel)",
            ));
        }
        if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
            return Err(BandwidthError::invalid(WHAT, "values", bad, "finite"));
        }
        let (field, field_resolution, offset) = match boundary {
            Boundary::InsideOnly => (values.to_vec(), resolution, UVec2::ZERO),
            Boundary::ZeroPadDouble => {
                let big = resolution * 2;
                let offset = resolution / 2;
                let mut field = vec![0f32; big.x as usize * big.y as usize];
                for y in 0..resolution.y {
                    let from = (y * resolution.x) as usize;
                    let to = ((y + offset.y) * big.x + offset.x) as usize;
                    field[to..to + resolution.x as usize]
                        .copy_from_slice(&values[from..from + resolution.x as usize]);
                }
                (field, big, offset)
            }
        };
        let floor = 1e-6 * values.iter().fold(0f32, |m, v| m.max(v.abs()));
        let levels: Vec<Vec<f32>> = (0..)
            .map_while(|level| level_maxima(&field, field_resolution, level))
            .collect();
        let mut cycles_per_unit = vec![0f32; count];
        let mut lambda = vec![0f32; levels.len()];
        for y in 0..resolution.y {
            for x in 0..resolution.x {
                let at = pixel_index(WHAT, UVec2::new(x, y) + offset, field_resolution)?;
                for (l, level) in lambda.iter_mut().zip(&levels) {
                    *l = level[at];
                }
                cycles_per_unit[(y * resolution.x + x) as usize] = match peak_level(&lambda, floor)
                {
                    Some(level) => HAAR_BETA_CYCLES_PER_TEXEL / (level.exp2() * texel_size),
                    None => 0.0,
                };
            }
        }
        Ok(Self {
            resolution,
            cycles_per_unit,
        })
    }

    /// The image's resolution.
    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// All texels, row-major, cycles per unit.
    pub fn cycles_per_unit(&self) -> &[f32] {
        &self.cycles_per_unit
    }

    /// One texel's bandwidth, cycles per unit.
    pub fn at(&self, texel: UVec2) -> Result<f32, BandwidthError> {
        Ok(self.cycles_per_unit[pixel_index("local bandwidth", texel, self.resolution)?])
    }
}

/// ℓ* (fractional): the finest level of the largest λ_ℓ, refined by a parabola through
/// log λ of its neighbours; `None` when every λ_ℓ ≤ `floor` (a constant signal).
fn peak_level(lambda: &[f32], floor: f32) -> Option<f32> {
    let max = lambda.iter().fold(0f32, |m, &v| m.max(v));
    if max <= floor {
        return None;
    }
    // Equal maxima (a step edge answers λ = jump/2 at every level) keep the finest.
    let peak = lambda.iter().position(|&v| v >= max * (1.0 - 1e-4))?;
    let mut level = peak as f32;
    if peak > 0 && peak + 1 < lambda.len() && lambda[peak - 1] > 0.0 && lambda[peak + 1] > 0.0 {
        let (a, b, c) = (
            lambda[peak - 1].ln(),
            lambda[peak].ln(),
            lambda[peak + 1].ln(),
        );
        let curvature = a - 2.0 * b + c;
        if curvature < 0.0 {
            level += (0.5 * (a - c) / curvature).clamp(-0.5, 0.5);
        }
    }
    Some(level)
}

/// One level's per-texel λ_ℓ: the largest |Haar detail coefficient| (amplitude-normalised,
/// three orientations) over the level-ℓ blocks that cover the texel and lie inside the
/// image (at every offset).
/// `None` when the blocks (2^{ℓ+1} texels) do not fit the image.
fn level_maxima(values: &[f32], resolution: UVec2, level: u32) -> Option<Vec<f32>> {
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let half = 1usize << level;
    let block = 2 * half;
    if block > w || block > h {
        return None;
    }
    // Summed-area table, f64 so that a constant stays exactly constant.
    let mut sat = vec![0f64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0f64;
        for x in 0..w {
            row += f64::from(values[y * w + x]);
            sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + row;
        }
    }
    let area = (half * half) as f64;
    let mean = |x0: usize, y0: usize| {
        let at = |x: usize, y: usize| sat[y * (w + 1) + x];
        (at(x0 + half, y0 + half) - at(x0, y0 + half) - at(x0 + half, y0) + at(x0, y0)) / area
    };
    // Coefficients of the blocks with origins 0..=w-block, 0..=h-block.
    let (ow, oh) = (w - block + 1, h - block + 1);
    let mut coef = vec![0f32; ow * oh];
    for oy in 0..oh {
        for ox in 0..ow {
            let a = mean(ox, oy);
            let b = mean(ox + half, oy);
            let c = mean(ox, oy + half);
            let d = mean(ox + half, oy + half);
            let horizontal = ((a + c) - (b + d)) / 4.0;
            let vertical = ((a + b) - (c + d)) / 4.0;
            let diagonal = ((a + d) - (b + c)) / 4.0;
            coef[oy * ow + ox] = horizontal.abs().max(vertical.abs()).max(diagonal.abs()) as f32;
        }
    }
    // Texel x is covered by the origins x-block+1..=x; those inside the image count. The
    // coefficients are ≥ 0, so zeros stand for the origins outside and every window is one
    // sliding maximum of width `block` (O(1) per texel, however coarse the level).
    let mut padded = vec![0f32; ow.max(oh) + 2 * (block - 1)];
    let mut along_x = vec![0f32; w * oh];
    for oy in 0..oh {
        padded[block - 1..block - 1 + ow].copy_from_slice(&coef[oy * ow..(oy + 1) * ow]);
        sliding_max(
            &padded[..ow + 2 * (block - 1)],
            block,
            &mut along_x[oy * w..(oy + 1) * w],
        );
    }
    padded.fill(0.0);
    let mut out = vec![0f32; w * h];
    let mut column = vec![0f32; h];
    for x in 0..w {
        for oy in 0..oh {
            padded[block - 1 + oy] = along_x[oy * w + x];
        }
        sliding_max(&padded[..oh + 2 * (block - 1)], block, &mut column);
        for (y, &v) in column.iter().enumerate() {
            out[y * w + x] = v;
        }
    }
    Some(out)
}

/// out[i] = max(input[i..i + window]) for every i (monotone deque).
fn sliding_max(input: &[f32], window: usize, out: &mut [f32]) {
    debug_assert_eq!(input.len() + 1, out.len() + window);
    let mut deque = std::collections::VecDeque::with_capacity(window);
    for (i, &v) in input.iter().enumerate() {
        while deque.back().is_some_and(|&j: &usize| input[j] <= v) {
            deque.pop_back();
        }
        deque.push_back(i);
        if let Some(start) = (i + 1).checked_sub(window) {
            while deque.front().is_some_and(|&j| j < start) {
                deque.pop_front();
            }
            out[start] = input[deque[0]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::Rng;
    use prism_testkit::windowed_spectrum;

    fn image(resolution: UVec2, f: impl Fn(f32, f32) -> f32) -> Vec<f32> {
        let mut v = Vec::with_capacity((resolution.x * resolution.y) as usize);
        for y in 0..resolution.y {
            for x in 0..resolution.x {
                v.push(f(x as f32, y as f32));
            }
        }
        v
    }

    #[test]
    fn the_sliding_maximum_matches_a_plain_one() {
        let mut rng = Rng(99);
        let input: Vec<f32> = (0..200).map(|_| rng.next()).collect();
        for window in [1usize, 2, 7, 64, 200] {
            let mut out = vec![0f32; input.len() + 1 - window];
            sliding_max(&input, window, &mut out);
            for (i, &m) in out.iter().enumerate() {
                let plain = input[i..i + window].iter().fold(0f32, |a, &b| a.max(b));
                assert_eq!(m, plain, "window {window} at {i}");
            }
        }
    }

    #[test]
    fn beta_is_the_finest_wavelets_95_percent_energy_bandwidth() {
        // Direct DFT of (+1, −1) zero-padded to n samples; energy accumulated from f = 0.
        let n = 4096;
        let power = |k: usize| {
            let f = k as f64 / n as f64;
            let (re, im) = (
                1.0 - (2.0 * std::f64::consts::PI * f).cos(),
                (2.0 * std::f64::consts::PI * f).sin(),
            );
            re * re + im * im
        };
        let total: f64 = (0..n).map(power).sum();
        let mut inside = power(0);
        let mut k = 0;
        while inside < 0.95 * total {
            k += 1;
            inside += power(k) + power(n - k);
        }
        let beta = k as f64 / n as f64;
        assert!(
            (beta - HAAR_BETA_CYCLES_PER_TEXEL as f64).abs() < 1e-3,
            "measured β = {beta}"
        );
    }

    #[test]
    fn sinusoids_are_within_an_octave() {
        // Texel size 1 cm: the answer is in cycles/m. Periods 2.5 to 64 texels, along x and
        // along the diagonal (radial frequency √2/P), every texel of a 192×160 image: within
        // an octave of the radial frequency from 3 texels off the border on, within two
        // octaves on the border (fewer blocks fit there).
        let resolution = UVec2::new(192, 160);
        let texel_m = 0.01;
        let margin = 3;
        let (mut inner, mut border) = ((f32::MAX, 0f32), (f32::MAX, 0f32));
        for (along_y, radial) in [(0.0f32, 1.0f32), (1.0, std::f32::consts::SQRT_2)] {
            for period in [
                2.5f32, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0, 23.0, 32.0, 45.0, 64.0,
            ] {
                let v = image(resolution, |x, y| {
                    (std::f32::consts::TAU * (x + along_y * y) / period + 0.4).sin()
                });
                let map = LocalBandwidth::estimate(&v, resolution, texel_m, Boundary::InsideOnly)
                    .unwrap();
                let truth = radial / (period * texel_m);
                for (i, &nu) in map.cycles_per_unit().iter().enumerate() {
                    let (x, y) = (i as u32 % resolution.x, i as u32 / resolution.x);
                    let interior = (margin..resolution.x - margin).contains(&x)
                        && (margin..resolution.y - margin).contains(&y);
                    let ratio = nu / truth;
                    let (range, allowed) = if interior {
                        (&mut inner, 0.5..=2.0)
                    } else {
                        (&mut border, 0.25..=4.0)
                    };
                    *range = (range.0.min(ratio), range.1.max(ratio));
                    assert!(
                        allowed.contains(&ratio),
                        "period {period}, diagonal {along_y}, texel ({x}, {y}): ν = {nu} \
                         cycles/m, true {truth}"
                    );
                }
            }
        }
        eprintln!(
            "sinusoids: ν / f in [{:.2}, {:.2}] inside, [{:.2}, {:.2}] on the border",
            inner.0, inner.1, border.0, border.1
        );
    }

    #[test]
    fn eq7s_cumulative_rule_would_stop_at_level_0() {
        // Why the level is the peak, not eq. 7's ε-rule: a smooth sinusoid's finest level
        // already holds more than ε = 1 % of its largest λ, so eq. 7 answers β/Δ for all.
        let resolution = UVec2::splat(256);
        for period in [16.0f32, 64.0] {
            let v = image(resolution, |x, _| {
                (std::f32::consts::TAU * x / period).sin()
            });
            let levels: Vec<Vec<f32>> = (0..)
                .map_while(|level| level_maxima(&v, resolution, level))
                .collect();
            let texel = 128 * 256 + 128;
            let max = levels.iter().fold(0f32, |m, l| m.max(l[texel]));
            let finest = levels[0][texel];
            // λ_0 ≈ π/P · amplitude against max ≈ 0.64.
            assert!(finest >= 0.01 * max, "period {period}: {finest} vs {max}");
            assert!((finest - std::f32::consts::PI / period).abs() < 0.1 * finest);
        }
    }

    #[test]
    fn a_constant_has_zero_bandwidth() {
        let resolution = UVec2::new(37, 20);
        for value in [0.0f32, 0.7, -3.0] {
            let v = vec![value; 37 * 20];
            let map = LocalBandwidth::estimate(&v, resolution, 1.0, Boundary::InsideOnly).unwrap();
            assert!(map.cycles_per_unit().iter().all(|&nu| nu == 0.0), "{value}");
        }
        // A dark area light stays dark in its zero padding.
        let map =
            LocalBandwidth::estimate(&[0.0; 37 * 20], resolution, 1.0, Boundary::ZeroPadDouble)
                .unwrap();
        assert!(map.cycles_per_unit().iter().all(|&nu| nu == 0.0));
    }

    #[test]
    fn a_step_is_high_at_the_edge_only() {
        // Edge between x = 100 and x = 101 of a 256×64 image; texel 1 unit.
        let resolution = UVec2::new(256, 64);
        let v = image(resolution, |x, _| if x <= 100.0 { 0.2 } else { 1.0 });
        let map = LocalBandwidth::estimate(&v, resolution, 1.0, Boundary::InsideOnly).unwrap();
        let nu = |x: u32| map.at(UVec2::new(x, 32)).unwrap();
        // Next to the edge: the finest level (β cycles/texel).
        assert_eq!(nu(100), HAAR_BETA_CYCLES_PER_TEXEL);
        assert_eq!(nu(101), HAAR_BETA_CYCLES_PER_TEXEL);
        // Falling with the distance r to the edge (≈ β/r) and low far away.
        for r in [8u32, 16, 32, 64] {
            for x in [100 - r, 101 + r] {
                assert!(
                    nu(x) <= 2.0 * HAAR_BETA_CYCLES_PER_TEXEL / r as f32,
                    "r {r}: {}",
                    nu(x)
                );
            }
        }
        for x in (0..60).chain(142..256) {
            assert!(nu(x) < 0.02, "x {x}: {}", nu(x));
        }
        // Same along y: a row is constant.
        assert_eq!(map.at(UVec2::new(100, 0)).unwrap(), nu(100));
    }

    /// 95 %-energy radius (cycles/texel) of the Hann-windowed 32×32 spectrum at (cx, cy).
    fn windowed_fft_radius(v: &[f32], n: u32, cx: u32, cy: u32) -> f32 {
        let values: Vec<f64> = v.iter().map(|&x| f64::from(x)).collect();
        let origin = (cx as usize - 16, cy as usize - 16);
        let bins = windowed_spectrum::hann_power_spectrum(&values, n as usize, origin, 32);
        windowed_spectrum::energy_radius(&bins, 0.95).unwrap_or(0.5) as f32
    }

    #[test]
    fn band_limited_noise_matches_a_windowed_fft() {
        // 200 sinusoids with wave vectors uniform in the disc |k| ≤ f_c, random phases;
        // reference: the 95 %-energy radius of a 32×32 Hann-windowed DFT (mean removed) at
        // every window centre on a stride-16 grid (196 windows).
        let n = 256u32;
        let mut rng = Rng(7);
        for cutoff in [0.1f32, 0.15, 0.25, 0.4] {
            let mut waves = Vec::new();
            while waves.len() < 200 {
                let (kx, ky) = (2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0);
                if kx * kx + ky * ky <= 1.0 {
                    waves.push((kx * cutoff, ky * cutoff, std::f32::consts::TAU * rng.next()));
                }
            }
            let v = image(UVec2::splat(n), |x, y| {
                waves
                    .iter()
                    .map(|&(kx, ky, phase)| {
                        (std::f32::consts::TAU * (kx * x + ky * y) + phase).sin()
                    })
                    .sum()
            });
            let map =
                LocalBandwidth::estimate(&v, UVec2::splat(n), 1.0, Boundary::InsideOnly).unwrap();
            let mut ratios = Vec::new();
            for cy in (16..n - 16).step_by(16) {
                for cx in (16..n - 16).step_by(16) {
                    let reference = windowed_fft_radius(&v, n, cx, cy);
                    ratios.push(map.at(UVec2::new(cx, cy)).unwrap() / reference);
                }
            }
            let within = ratios.iter().filter(|r| (0.5..=2.0).contains(*r)).count() as f32
                / ratios.len() as f32;
            ratios.sort_by(|a, b| a.total_cmp(b));
            eprintln!(
                "noise f_c {cutoff}: ν / FFT p5 {:.2} median {:.2} p95 {:.2}, within ×2 in {:.0} %",
                ratios[ratios.len() / 20],
                ratios[ratios.len() / 2],
                ratios[ratios.len() * 19 / 20],
                100.0 * within
            );
            assert!(within >= 0.9, "f_c {cutoff}: {within}");
        }
    }

    #[test]
    fn zero_padding_makes_an_area_lights_outline_an_edge() {
        // A uniform 40×24 emitter: constant, so the image alone says 0 everywhere;
        // zero-padded, its border texels are edges and its centre is smooth.
        let resolution = UVec2::new(40, 24);
        let v = vec![5.0f32; 40 * 24];
        let flat = LocalBandwidth::estimate(&v, resolution, 0.01, Boundary::InsideOnly).unwrap();
        assert!(flat.cycles_per_unit().iter().all(|&nu| nu == 0.0));
        let padded =
            LocalBandwidth::estimate(&v, resolution, 0.01, Boundary::ZeroPadDouble).unwrap();
        let edge = HAAR_BETA_CYCLES_PER_TEXEL / 0.01;
        for texel in [UVec2::new(0, 0), UVec2::new(39, 12), UVec2::new(20, 23)] {
            assert_eq!(padded.at(texel).unwrap(), edge, "{texel}");
        }
        let centre = padded.at(UVec2::new(20, 12)).unwrap();
        assert!(centre > 0.0 && centre < edge / 8.0, "{centre}");
    }

    #[test]
    fn invalid_input_is_rejected_by_name() {
        let r = UVec2::new(4, 3);
        let e = LocalBandwidth::estimate(&[0.0; 11], r, 1.0, Boundary::InsideOnly);
        assert!(matches!(
            e,
            Err(BandwidthError::LengthMismatch { found: 11, .. })
        ));
        let e = LocalBandwidth::estimate(&[0.0; 12], r, 0.0, Boundary::InsideOnly)
            .unwrap_err()
            .to_string();
        assert!(e.contains("texel_size"), "{e}");
        let mut v = [0.0; 12];
        v[5] = f32::NAN;
        let e = LocalBandwidth::estimate(&v, r, 1.0, Boundary::InsideOnly)
            .unwrap_err()
            .to_string();
        assert!(e.contains("values"), "{e}");
        let e = LocalBandwidth::estimate(&[], UVec2::new(0, 3), 1.0, Boundary::InsideOnly);
        assert!(matches!(e, Err(BandwidthError::ZeroResolution { .. })));
        let map = LocalBandwidth::estimate(&[1.0; 12], r, 1.0, Boundary::InsideOnly).unwrap();
        assert!(map.at(UVec2::new(4, 0)).is_err());
    }
}

//! Deterministic per-pixel samplers: every value is a function of (seed, pixel, sample
//! index, dimension) only, so a pixel's samples never depend on which thread or tile draws
//! them: images are the same for any thread count.
//!
//! Two kinds (`prism_scene::SamplerKind`, the scene's `integrator.sampler`):
//!
//! - `Sobol` (the default): padded, Owen-scrambled Sobol (Burley 2020, "Practical
//!   Hash-based Owen Scrambling"; pbrt-v4 §8.7 `PaddedSobolSampler`). Each `get_2d` is the
//!   point of the shuffled sample index in Sobol dimensions (0, 1), each `get_1d` the
//!   coordinate in dimension 0, scrambled with seeds hashed from (seed, pixel, dimension).
//!   So the first 2^m samples of every `get_2d` pair form a (0, m, 2)-net and of every
//!   `get_1d` a stratified set of 2^m points, for every m; values of different calls (e.g.
//!   the x of one `get_2d` and the x of the next) are decorrelated by the hash, not
//!   stratified jointly. See `sobol.rs`.
//!   Dimensions from `SOBOL_DIMENSIONS` on (deep path vertices) are independent hashes of
//!   (seed, pixel, sample index, dimension): stratification matters most for the first
//!   dimensions (pixel, lens, wavelength, the first bounces) and a scrambled Sobol value
//!   costs about four hashes, so the tail of a long path is not worth it.
//! - `Independent`: every value an independent hash (SplitMix64 of the inputs), uniform
//!   and uncorrelated; the reference for tests and convergence studies.
//!
//! Values lie in [0, 1) with 24 bits, never 1.

pub(crate) mod hash;
pub(crate) mod independent;
mod lanes;
mod sobol;

pub(crate) use lanes::StreamLanes;

use glam::{UVec2, Vec2};
pub use prism_scene::SamplerKind;

use hash::{mix64, pixel_word, DIMENSION_SPREAD};

/// Seeds per-pixel sample streams.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelSampler {
    seed: u64,
    kind: SamplerKind,
}

/// The samples of one pixel sample (one camera path): consecutive dimensions.
#[derive(Clone, Copy, Debug)]
pub struct SampleStream {
    /// Hash of (seed, pixel) for Sobol; of (seed, pixel, sample index) for independent.
    key: u64,
    /// The sample index with its bits reversed (Sobol only; unused by independent).
    index_reversed: u32,
    /// Key of the independent values: of (seed, pixel, sample index) — the dimensions of
    /// an independent stream, and those from `sobol_dimensions` on of a Sobol stream.
    /// Computed once per stream: deriving it in `bits_1d_at` put a bit reversal and a hash
    /// on every path vertex's draws even for independent streams (LLVM hoists the Sobol
    /// tail's key computation above the sampler-kind branch).
    tail_key: u64,
    dimension: u32,
    /// Dimensions drawn from Sobol points (Sobol only); later ones are independent.
    sobol_dimensions: u32,
    kind: SamplerKind,
}

impl PixelSampler {
    /// An independent sampler (kept for existing callers; renders use `with_kind`).
    pub fn new(seed: u64) -> Self {
        Self::with_kind(SamplerKind::Independent, seed)
    }

    /// A sampler of `kind` seeded by `seed`.
    pub fn with_kind(kind: SamplerKind, seed: u64) -> Self {
        Self { seed, kind }
    }

    pub fn seed(&self) -> u64 {
        self.seed
    }

    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The stream of sample `sample_index` of `pixel`.
    #[inline]
    pub fn stream(&self, pixel: UVec2, sample_index: u32) -> SampleStream {
        let pixel_key = mix64(mix64(self.seed) ^ pixel_word(pixel));
        match self.kind {
            SamplerKind::Sobol => SampleStream {
                key: pixel_key,
                index_reversed: sample_index.reverse_bits(),
                tail_key: independent::sample_key(pixel_key, sample_index),
                dimension: 0,
                sobol_dimensions: SOBOL_DIMENSIONS,
                kind: SamplerKind::Sobol,
            },
            SamplerKind::Independent => SampleStream {
                key: independent::sample_key(pixel_key, sample_index),
                index_reversed: 0,
                tail_key: independent::sample_key(pixel_key, sample_index),
                dimension: 0,
                sobol_dimensions: 0,
                kind: SamplerKind::Independent,
            },
        }
    }
}

/// The hash of (seed, pixel, dimension) that scrambles one Sobol call.
#[inline(always)]
fn dimension_hash(key: u64, dimension: u32) -> u64 {
    mix64(key ^ u64::from(dimension).wrapping_mul(DIMENSION_SPREAD))
}

/// Dimensions drawn from Sobol points per camera sample: the path tracer's filter 2, lens
/// 2, wavelength 1 and 8 per vertex for its first three vertices. Later dimensions are
/// independent.
pub const SOBOL_DIMENSIONS: u32 = 5 + 3 * 8;

impl SampleStream {
    /// This stream with Sobol points for its first `dimensions` dimensions only (default
    /// `SOBOL_DIMENSIONS`) and independent values after: for estimators whose variance sits
    /// in a few leading dimensions, where a scrambled Sobol value (about four hashes) is
    /// not worth its cost further on. No effect on an independent stream.
    pub fn with_sobol_dimensions(mut self, dimensions: u32) -> Self {
        if self.kind == SamplerKind::Sobol {
            self.sobol_dimensions = dimensions;
        }
        self
    }

    /// Dimension `dimension` of this stream as 32 fraction bits: what a `get_1d` call
    /// reaching that dimension returns, computed without drawing the dimensions before it
    /// (every value is a function of (seed, pixel, sample index, dimension) alone).
    #[inline(always)]
    fn bits_1d_at(&self, dimension: u32) -> u32 {
        match self.kind {
            SamplerKind::Sobol if dimension >= self.sobol_dimensions => {
                independent::value(self.tail_key, dimension)
            }
            SamplerKind::Sobol => {
                let h = dimension_hash(self.key, dimension);
                let index = sobol::shuffle_reversed_index(self.index_reversed, h as u32);
                sobol::scrambled_dimension_0(index, (h >> 32) as u32)
            }
            SamplerKind::Independent => independent::value(self.tail_key, dimension),
        }
    }

    /// The value a `get_1d` call at `dimension` returns (see [`SampleStream::reserve`]).
    #[inline(always)]
    pub fn get_1d_at(&self, dimension: u32) -> f32 {
        hash::u32_to_unit_f32(self.bits_1d_at(dimension))
    }

    /// The value a `get_2d` call at `dimension` returns (dimensions `dimension` and
    /// `dimension + 1`; see [`SampleStream::reserve`]).
    #[inline(always)]
    pub fn get_2d_at(&self, dimension: u32) -> Vec2 {
        match self.kind {
            SamplerKind::Sobol if dimension + 1 < self.sobol_dimensions => {
                let h = dimension_hash(self.key, dimension);
                let index = sobol::shuffle_reversed_index(self.index_reversed, h as u32);
                let seed_y = (mix64(h) >> 32) as u32;
                Vec2::new(
                    hash::u32_to_unit_f32(sobol::scrambled_dimension_0(index, (h >> 32) as u32)),
                    hash::u32_to_unit_f32(sobol::scrambled_dimension_1(index, seed_y)),
                )
            }
            _ => Vec2::new(self.get_1d_at(dimension), self.get_1d_at(dimension + 1)),
        }
    }

    /// Skips the next `count` dimensions and returns the first of them: the caller draws
    /// the ones it needs with `get_1d_at`/`get_2d_at`, getting exactly the values the
    /// sequential `get_1d`/`get_2d` calls would have returned, and the stream continues
    /// after them as if all had been drawn. The path tracer reserves a vertex's 8
    /// dimensions this way and computes only those a hit uses (an opaque surface never
    /// reads its opacity-mask variate, a path before `rr_depth` never its roulette one).
    #[inline(always)]
    pub fn reserve(&mut self, count: u32) -> u32 {
        let first = self.dimension;
        self.dimension += count;
        first
    }

    /// The next dimension, uniform in [0, 1).
    #[inline(always)]
    pub fn get_1d(&mut self) -> f32 {
        let x = self.get_1d_at(self.dimension);
        self.dimension += 1;
        x
    }

    /// The next two dimensions: for Sobol one point of a (0, 2)-sequence.
    #[inline(always)]
    pub fn get_2d(&mut self) -> Vec2 {
        let p = self.get_2d_at(self.dimension);
        self.dimension += 2;
        p
    }

    /// A 64-bit hash of (seed, pixel, sample index, `dimension`): the seed of a
    /// generator for an unbounded number of variates that one reserved dimension stands
    /// for (a medium segment's collisions, `integrator::medium_transport`).
    #[inline]
    pub fn seed_at(&self, dimension: u32) -> u64 {
        mix64(self.tail_key ^ u64::from(dimension).wrapping_mul(DIMENSION_SPREAD))
    }

    /// Dimensions used so far.
    pub fn dimension(&self) -> u32 {
        self.dimension
    }

    /// The sampler kind this stream draws from.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [SamplerKind; 2] = [SamplerKind::Sobol, SamplerKind::Independent];

    #[test]
    fn same_inputs_same_values_and_values_in_unit_interval() {
        for kind in KINDS {
            let s = PixelSampler::with_kind(kind, 7);
            let mut a = s.stream(UVec2::new(3, 4), 5);
            let mut b = s.stream(UVec2::new(3, 4), 5);
            for _ in 0..100 {
                let (x, y) = (a.get_1d(), b.get_1d());
                assert_eq!(x.to_bits(), y.to_bits());
                assert!((0.0..1.0).contains(&x));
                let (p, q) = (a.get_2d(), b.get_2d());
                assert_eq!(p, q);
                assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
            }
            assert_eq!(a.dimension(), 300);
        }
    }

    #[test]
    fn reserved_dimensions_equal_the_sequential_draws() {
        // Random access must return the bits of the sequential calls, at every dimension
        // (Sobol pairs, the Sobol/independent boundary at `SOBOL_DIMENSIONS`, the tail),
        // and the stream must continue where the sequential one does.
        for kind in KINDS {
            let s = PixelSampler::with_kind(kind, 11);
            for index in [0, 1, 5, 63] {
                for offset in 0..3 {
                    let mut sequential = s.stream(UVec2::new(9, 2), index);
                    let mut reserved = s.stream(UVec2::new(9, 2), index);
                    for _ in 0..offset {
                        sequential.get_1d();
                        reserved.get_1d();
                    }
                    for _ in 0..6 {
                        // One vertex's pattern: 1d, 1d, 2d, 1d, 2d, 1d.
                        let base = reserved.reserve(8);
                        let expected = [
                            sequential.get_1d(),
                            sequential.get_1d(),
                            sequential.get_2d().x,
                            f32::NAN,
                            sequential.get_1d(),
                            sequential.get_2d().x,
                            f32::NAN,
                            sequential.get_1d(),
                        ];
                        let mut again = s.stream(UVec2::new(9, 2), index);
                        for _ in 0..base {
                            again.get_1d();
                        }
                        let got = [
                            reserved.get_1d_at(base),
                            reserved.get_1d_at(base + 1),
                            reserved.get_2d_at(base + 2).x,
                            f32::NAN,
                            reserved.get_1d_at(base + 4),
                            reserved.get_2d_at(base + 5).x,
                            f32::NAN,
                            reserved.get_1d_at(base + 7),
                        ];
                        for k in [0, 1, 2, 4, 5, 7] {
                            assert_eq!(got[k].to_bits(), expected[k].to_bits(), "{kind:?} {k}");
                        }
                        assert_eq!(
                            reserved.get_2d_at(base + 2),
                            {
                                again.get_1d();
                                again.get_1d();
                                again.get_2d()
                            },
                            "{kind:?}"
                        );
                        assert_eq!(reserved.dimension(), sequential.dimension());
                    }
                    assert_eq!(reserved.get_1d().to_bits(), sequential.get_1d().to_bits());
                }
            }
        }
    }

    #[test]
    fn largest_fraction_maps_below_one() {
        assert!(hash::u32_to_unit_f32(u32::MAX) < 1.0);
        assert_eq!(hash::u32_to_unit_f32(0), 0.0);
    }

    #[test]
    fn sobol_dimension_limit_keeps_leading_dimensions_and_makes_later_ones_independent() {
        // 64 samples: a stratified dimension puts exactly one in each 1/64 stratum; with the
        // limit at 1, dimension 0 still does and dimension 1 (independent) does not.
        let s = PixelSampler::with_kind(SamplerKind::Sobol, 3);
        let strata = |dim: usize, limit: u32| {
            let mut hit = [0u32; 64];
            for i in 0..64 {
                let mut st = s.stream(UVec2::new(1, 2), i).with_sobol_dimensions(limit);
                let v = (0..=dim).map(|_| st.get_1d()).last().unwrap();
                hit[(v * 64.0) as usize] += 1;
            }
            hit.iter().all(|&h| h == 1)
        };
        assert!(strata(0, 1) && strata(1, SOBOL_DIMENSIONS));
        assert!(!strata(1, 1));
        // The leading dimensions are the unlimited stream's.
        let mut a = s.stream(UVec2::new(1, 2), 9);
        let mut b = s.stream(UVec2::new(1, 2), 9).with_sobol_dimensions(3);
        assert_eq!(a.get_1d(), b.get_1d());
        assert_eq!(a.get_2d(), b.get_2d());
        // No effect on an independent stream.
        let ind = PixelSampler::with_kind(SamplerKind::Independent, 3);
        let mut c = ind.stream(UVec2::ZERO, 4);
        let mut d = ind.stream(UVec2::ZERO, 4).with_sobol_dimensions(0);
        assert!((0..40).all(|_| c.get_1d() == d.get_1d()));
    }

    #[test]
    fn streams_differ_by_pixel_index_and_seed() {
        for kind in KINDS {
            let v = |seed, px: u32, i| {
                PixelSampler::with_kind(kind, seed)
                    .stream(UVec2::new(px, 0), i)
                    .get_1d()
            };
            assert_ne!(v(1, 0, 0), v(1, 1, 0));
            assert_ne!(v(1, 0, 0), v(1, 0, 1));
            assert_ne!(v(1, 0, 0), v(2, 0, 0));
        }
    }

    #[test]
    fn new_is_the_independent_sampler() {
        let s = PixelSampler::new(3);
        assert_eq!(s.kind(), SamplerKind::Independent);
        assert_eq!(s, PixelSampler::with_kind(SamplerKind::Independent, 3));
    }

    #[test]
    fn mean_and_variance_are_uniform() {
        for kind in KINDS {
            let s = PixelSampler::with_kind(kind, 42);
            let n = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let mut stream = s.stream(UVec2::new(i % 317, i / 317), i % 3);
                stream.get_1d();
                let x = f64::from(stream.get_1d());
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / f64::from(n);
            let var = sum2 / f64::from(n) - mean * mean;
            // Standard error of the mean of U(0,1): sqrt(1/12 / n) ≈ 6.5e-4; allow 5σ
            // (for Sobol the streams of different pixels are independent scrambles, so the
            // i.i.d. bound holds).
            assert!((mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / f64::from(n)).sqrt());
            // Standard error of the sample variance of U(0,1): sqrt((μ₄ − σ⁴) / n) with
            // μ₄ = 1/80, σ⁴ = 1/144 (≈ 1.7e-4 here); allow 5σ.
            let variance_se = ((1.0 / 80.0 - 1.0 / 144.0) / f64::from(n)).sqrt();
            assert!(
                (var - 1.0 / 12.0).abs() < 5.0 * variance_se,
                "{kind:?}: {var}"
            );
        }
    }
}

//! Many streams' values at once: `SampleStream::get_1d_at` / `get_2d_at` of `N` streams, one
//! dimension each, computed with every step a loop over the lanes, so that the packet
//! tracer's AVX2/AVX-512 kernels run each hash as vector instructions instead of `N`
//! scalar calls (64-bit multiplies for SplitMix64, 32-bit ones for the Laine–Karras
//! permutations, `u32::reverse_bits` as a byte shuffle instead of table lookups). The
//! values are the same bits as the scalar calls (tested below).

use super::hash::{mix64, u32_to_unit_f32};
use super::independent;
use super::sobol::{laine_karras_permutation, pascal_digits};
use super::{dimension_hash, SampleStream};

/// The words of `N` streams (`SampleStream::words`), one per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StreamLanes<const N: usize> {
    key: [u64; N],
    index_reversed: [u32; N],
    tail_key: [u64; N],
    sobol_dimensions: [u32; N],
}

impl<const N: usize> StreamLanes<N> {
    pub(crate) fn new() -> Self {
        Self {
            key: [0; N],
            index_reversed: [0; N],
            tail_key: [0; N],
            sobol_dimensions: [0; N],
        }
    }

    /// Lane `lane` draws from `stream`.
    #[inline(always)]
    pub(crate) fn set(&mut self, lane: usize, stream: &SampleStream) {
        self.key[lane] = stream.key;
        self.index_reversed[lane] = stream.index_reversed;
        self.tail_key[lane] = stream.tail_key;
        self.sobol_dimensions[lane] = stream.sobol_dimensions;
    }

    /// What `get_1d_at(dimension[l])` of lane l's stream returns, for every lane.
    #[inline(always)]
    pub(crate) fn get_1d_at(&self, dimension: &[u32; N]) -> [f32; N] {
        let (x, _) = self.bits_2d_at(dimension, false);
        x.map(u32_to_unit_f32)
    }

    /// What `get_1d_at(dimension[l])` returns for the lanes whose streams are independent
    /// (`SamplerKind::Independent`): their hashes alone, without the Sobol arithmetic.
    #[inline(always)]
    pub(crate) fn independent_1d_at(&self, dimension: &[u32; N]) -> [f32; N] {
        std::array::from_fn(|l| u32_to_unit_f32(independent::value(self.tail_key[l], dimension[l])))
    }

    /// What `get_2d_at(dimension[l])` of lane l's stream returns, for every lane: (x, y).
    #[inline(always)]
    pub(crate) fn get_2d_at(&self, dimension: &[u32; N]) -> ([f32; N], [f32; N]) {
        let (x, y) = self.bits_2d_at(dimension, true);
        (x.map(u32_to_unit_f32), y.map(u32_to_unit_f32))
    }

    /// Fraction bits of `bits_1d_at(d)` (x) and, with `with_y`, of the y that `get_2d_at(d)`
    /// pairs with it: the Sobol pair's dimension 1 where d + 1 lies below the stream's Sobol
    /// dimensions, else the independent value at d + 1 (`SampleStream::get_2d_at`).
    #[inline(always)]
    fn bits_2d_at(&self, dimension: &[u32; N], with_y: bool) -> ([u32; N], [u32; N]) {
        let mut x = [0u32; N];
        let mut y = [0u32; N];
        for l in 0..N {
            let d = dimension[l];
            // `dimension_hash`, `shuffle_reversed_index`, `scrambled_dimension_0`.
            let h = dimension_hash(self.key[l], d);
            let index = laine_karras_permutation(self.index_reversed[l], h as u32).reverse_bits();
            let sobol_x = laine_karras_permutation(index, (h >> 32) as u32).reverse_bits();
            let tail_x = independent::value(self.tail_key[l], d);
            x[l] = if d >= self.sobol_dimensions[l] {
                tail_x
            } else {
                sobol_x
            };
            if with_y {
                let seed_y = (mix64(h) >> 32) as u32;
                let sobol_y = laine_karras_permutation(pascal_digits(index), seed_y).reverse_bits();
                let tail_y = independent::value(self.tail_key[l], d.wrapping_add(1));
                y[l] = if d.wrapping_add(1) < self.sobol_dimensions[l] {
                    sobol_y
                } else {
                    tail_y
                };
            }
        }
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use glam::UVec2;

    use super::*;
    use crate::sampler::{PixelSampler, SamplerKind, SOBOL_DIMENSIONS};

    #[test]
    fn lanes_give_the_scalar_streams_bits_at_every_dimension() {
        // Streams of both kinds and of different pixels and sample indices in the lanes,
        // each at its own dimension: every Sobol dimension, the boundary to the independent
        // tail (a pair straddling it), and the tail.
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            let sampler = PixelSampler::with_kind(kind, 0x5eed);
            let streams: Vec<SampleStream> = (0..8u32)
                .map(|l| sampler.stream(UVec2::new(3 * l, 7 + l), l * l + 5 * l))
                .collect();
            let mut lanes = StreamLanes::<8>::new();
            for (l, s) in streams.iter().enumerate() {
                lanes.set(l, s);
            }
            for base in 0..SOBOL_DIMENSIONS + 12 {
                let dims: [u32; 8] = std::array::from_fn(|l| base + l as u32 % 3);
                let one = lanes.get_1d_at(&dims);
                let (x, y) = lanes.get_2d_at(&dims);
                for (l, s) in streams.iter().enumerate() {
                    let pair = s.get_2d_at(dims[l]);
                    assert_eq!(one[l].to_bits(), s.get_1d_at(dims[l]).to_bits());
                    assert_eq!(
                        x[l].to_bits(),
                        pair.x.to_bits(),
                        "{kind:?} lane {l} dim {}",
                        dims[l]
                    );
                    assert_eq!(
                        y[l].to_bits(),
                        pair.y.to_bits(),
                        "{kind:?} lane {l} dim {}",
                        dims[l]
                    );
                }
            }
        }
    }
}

//! The first two dimensions of the Sobol sequence with hash-based Owen scrambling and
//! index shuffling (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//!
//! # Sobol points (dimensions 0 and 1)
//!
//! A Sobol coordinate is x = C · a over GF(2), where a are the bits of the index (a₀ least
//! significant) and the result's digit k is the (k+1)-th binary digit after the point
//! (Sobol 1967; Joe & Kuo 2008). Dimension 0 has C = I, the van der Corput sequence: the
//! index with its bits reversed. Dimension 1 has the Pascal matrix C[k][j] = binom(j, k)
//! mod 2, which by Lucas' theorem is 1 exactly when the bit set of k is contained in that of
//! j; so digit k = ⊕_{j ⊇ k} a_j, a "superset sum" over the 5-bit digit positions that five
//! shift-mask-xor steps compute (`pascal_digits`). Together the two dimensions are a
//! (0, 2)-sequence in base 2: every aligned block of 2^m consecutive indices is a
//! (0, m, 2)-net — each elementary interval [i/2^a, (i+1)/2^a) × [j/2^b, (j+1)/2^b) with
//! a + b = m holds exactly one point (Niederreiter 1992, §4).
//!
//! # Owen scrambling
//!
//! Owen (1995) scrambling flips each digit of a coordinate by a random bit that depends on
//! all the digits before it. Any such "nested" flip maps every elementary interval onto an
//! elementary interval of the same size, so nets stay nets, while the points become
//! uniformly distributed (randomised QMC: unbiased, with variance O(n⁻³ (log n)^(s−1)) for
//! smooth integrands, Owen 1997). Burley's hash (his §3, the improved Laine–Karras
//! permutation) does it in four multiply-xor steps: multiplying by an even constant makes
//! bit k depend only on bits below k, so applied to the bit-reversed value every digit
//! depends only on the digits before it — a nested flip, exactly net-preserving (tested).
//!
//! # Index shuffling (padding)
//!
//! Every pair of dimensions uses the same two Sobol dimensions, decorrelated by shuffling
//! the sample index with the same nested scramble applied to the index bits (Burley §4;
//! pbrt-v4's `PaddedSobolSampler` does this with a permutation of [0, spp)). Bit k of the
//! index is flipped depending on the bits above it only, so every aligned block of 2^m
//! indices goes to an aligned block of 2^m indices: the first 2^m samples of every pair of
//! dimensions are still a (0, m, 2)-net, for every m at once.

/// Each byte with its bits reversed.
static REVERSED_BYTES: [u8; 256] = {
    let mut table = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        table[i] = (i as u8).reverse_bits();
        i += 1;
    }
    table
};

/// `u32::reverse_bits` by four byte lookups in a 256-byte table (L1-resident): x86-64 has
/// no bit-reversal instruction, and LLVM's shift-and-mask sequence made a Sobol `get_1d`
/// ≈ 1.3× slower in `examples/sampler_bench.rs`. Equal to `u32::reverse_bits` (tested).
#[inline(always)]
fn reverse_bits(x: u32) -> u32 {
    let byte = |shift: u32| u32::from(REVERSED_BYTES[((x >> shift) & 0xff) as usize]);
    (byte(0) << 24) | (byte(8) << 16) | (byte(16) << 8) | byte(24)
}

/// Burley 2020's hash-based Laine–Karras permutation (his listing 2): each output bit k is
/// the input bit k flipped by a hash of the bits below k and `seed`.
#[inline(always)]
pub(crate) fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen scrambling of a 32-bit fixed-point fraction (digit 1 = most significant bit):
/// Burley's `nested_uniform_scramble` (the definition the shortcuts below are tested
/// against).
#[cfg(test)]
pub(crate) fn owen_scramble(value: u32, seed: u32) -> u32 {
    reverse_bits(laine_karras_permutation(reverse_bits(value), seed))
}

/// Shuffles a sample index by the same nested scramble: aligned blocks of 2^m indices map
/// onto aligned blocks of 2^m indices (see the module documentation).
#[cfg(test)]
pub(crate) fn shuffle_index(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed)
}

/// `shuffle_index` given the index with its bits already reversed (the stream reverses it
/// once, saving one of the three bit reversals of a call: x86-64 has no instruction for it).
#[inline(always)]
pub(crate) fn shuffle_reversed_index(index_reversed: u32, seed: u32) -> u32 {
    reverse_bits(laine_karras_permutation(index_reversed, seed))
}

/// Digits of Sobol dimension 1 in index-bit order (bit k = digit k + 1 after the point):
/// digit k = ⊕ over the index bits j whose bit set contains k (Pascal matrix mod 2).
#[inline(always)]
pub(crate) fn pascal_digits(index: u32) -> u32 {
    let mut w = index;
    w ^= (w >> 1) & 0x5555_5555;
    w ^= (w >> 2) & 0x3333_3333;
    w ^= (w >> 4) & 0x0f0f_0f0f;
    w ^= (w >> 8) & 0x00ff_00ff;
    w ^= (w >> 16) & 0x0000_ffff;
    w
}

/// Sobol dimension 0 (van der Corput) of `index` as a 32-bit fraction (unscrambled: the
/// reference the tests check the scrambled shortcuts against).
#[cfg(test)]
pub(crate) fn sobol_dimension_0(index: u32) -> u32 {
    index.reverse_bits()
}

/// Sobol dimension 1 of `index` as a 32-bit fraction (unscrambled, for the tests).
#[cfg(test)]
pub(crate) fn sobol_dimension_1(index: u32) -> u32 {
    pascal_digits(index).reverse_bits()
}

/// Owen-scrambled Sobol dimension 0 of `index`: `owen_scramble(sobol_dimension_0(index))`
/// with the double bit reversal cancelled.
#[inline(always)]
pub(crate) fn scrambled_dimension_0(index: u32, seed: u32) -> u32 {
    reverse_bits(laine_karras_permutation(index, seed))
}

/// Owen-scrambled Sobol dimension 1 of `index`.
#[inline(always)]
pub(crate) fn scrambled_dimension_1(index: u32, seed: u32) -> u32 {
    reverse_bits(laine_karras_permutation(pascal_digits(index), seed))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dimension 1 by the textbook loop over the index bits with the Pascal matrix's
    /// direction numbers v_j (column j of C, digit 1 in the top bit).
    fn sobol_dimension_1_reference(index: u32) -> u32 {
        let mut columns = [0u32; 32];
        for (j, column) in columns.iter_mut().enumerate() {
            for k in 0..32 {
                // binom(j, k) mod 2 = 1 iff k ⊆ j (Lucas).
                if k & j == k {
                    *column |= 1 << (31 - k);
                }
            }
        }
        (0..32)
            .filter(|j| index >> j & 1 == 1)
            .fold(0, |x, j| x ^ columns[j as usize])
    }

    #[test]
    fn table_bit_reversal_equals_the_library_one() {
        let mut x = 0x1234_5678u64;
        for _ in 0..100_000 {
            x = super::super::hash::mix64(x);
            let v = x as u32;
            assert_eq!(reverse_bits(v), v.reverse_bits());
        }
        for v in [0, 1, u32::MAX, 0x8000_0000, 0x0000_ffff] {
            assert_eq!(reverse_bits(v), v.reverse_bits());
        }
    }

    #[test]
    fn dimension_1_matches_the_direction_number_loop_and_known_values() {
        for i in (0..5000u32).chain([u32::MAX, 0x8000_0000, 0xdead_beef]) {
            assert_eq!(sobol_dimension_1(i), sobol_dimension_1_reference(i), "{i}");
        }
        // Indices 0..8 in natural order: 0, ½, ¾, ¼, ⅝, ⅛, ⅜, ⅞.
        let want = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, w) in want.iter().enumerate() {
            let got = f64::from(sobol_dimension_1(i as u32)) / 2f64.powi(32);
            assert_eq!(got, *w, "index {i}");
        }
    }

    /// True when bit k of `f(x)` equals bit k of x xor a function of the bits above k (a
    /// nested, net-preserving flip), checked on random pairs differing only at or below k.
    #[test]
    fn scramble_and_shuffle_are_nested_bijections() {
        let mut state = 1u64;
        let mut next = || {
            state = super::super::hash::mix64(state);
            state as u32
        };
        for _ in 0..2000 {
            let (x, seed) = (next(), next());
            // Owen scramble: digits (MSB first) depend only on digits before them; so two
            // values sharing their top t bits map to values sharing their top t bits, and
            // the (t+1)-th bit is flipped by the same amount.
            for t in 0..31 {
                let y = x ^ (next() >> (t + 1)) ^ (1 << (31 - t));
                let (fx, fy) = (owen_scramble(x, seed), owen_scramble(y, seed));
                let top = if t == 0 { 0 } else { u32::MAX << (32 - t) };
                assert_eq!(fx & top, fy & top);
                let bit = 1u32 << (31 - t);
                assert_ne!(fx & bit, fy & bit);
            }
        }
        // Bijective on a small block: the first 2^12 indices go to one aligned block of 2^12.
        let seed = 0x1234_5678;
        let mut seen = vec![false; 1 << 12];
        let block = shuffle_index(0, seed) >> 12;
        for i in 0..1u32 << 12 {
            let j = shuffle_index(i, seed);
            assert_eq!(j >> 12, block);
            assert!(!std::mem::replace(&mut seen[(j & 0xfff) as usize], true));
        }
    }

    /// Every elementary interval of area 2^-m holds exactly one of `points`.
    fn is_0_m_2_net(points: &[(u32, u32)], m: u32) -> bool {
        (0..=m).all(|a| {
            let b = m - a;
            let mut seen = vec![false; 1 << m];
            points.iter().all(|&(x, y)| {
                let cell = ((x >> (31 - a) >> 1) << b | (y >> (31 - b) >> 1)) as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn unscrambled_dimensions_0_and_1_are_a_0_2_sequence() {
        // The first 2^m points and later aligned blocks are (0, m, 2)-nets.
        for m in 0..=12 {
            for block in [0u32, 1, 5, 1000] {
                let points: Vec<_> = (0..1u32 << m)
                    .map(|i| i + (block << m))
                    .map(|i| (sobol_dimension_0(i), sobol_dimension_1(i)))
                    .collect();
                assert!(is_0_m_2_net(&points, m), "m = {m}, block {block}");
            }
        }
        // A set that is not a block is in general not a net (the test can fail).
        let shifted: Vec<_> = (1..17u32)
            .map(|i| (sobol_dimension_0(i * 3), sobol_dimension_1(i * 3)))
            .collect();
        assert!(!is_0_m_2_net(&shifted, 4));
    }

    #[test]
    fn scrambled_and_shuffled_points_stay_nets() {
        for m in 0..=12 {
            for seeds in [
                (0u32, 0u32, 0u32),
                (1, 2, 3),
                (0xdead_beef, 0x0bad_f00d, 77),
            ] {
                let points: Vec<_> = (0..1u32 << m)
                    .map(|i| shuffle_index(i, seeds.0))
                    .map(|i| {
                        (
                            scrambled_dimension_0(i, seeds.1),
                            scrambled_dimension_1(i, seeds.2),
                        )
                    })
                    .collect();
                assert!(is_0_m_2_net(&points, m), "m = {m}, seeds {seeds:?}");
            }
        }
    }

    #[test]
    fn scrambled_shortcuts_equal_scrambling_the_sobol_value() {
        for i in [0u32, 1, 2, 77, 4096, 0xffff_ffff] {
            for seed in [0u32, 1, 0xabcd_ef01] {
                assert_eq!(
                    scrambled_dimension_0(i, seed),
                    owen_scramble(sobol_dimension_0(i), seed)
                );
                assert_eq!(
                    scrambled_dimension_1(i, seed),
                    owen_scramble(sobol_dimension_1(i), seed)
                );
                assert_eq!(
                    shuffle_reversed_index(i.reverse_bits(), seed),
                    shuffle_index(i, seed)
                );
            }
        }
    }
}

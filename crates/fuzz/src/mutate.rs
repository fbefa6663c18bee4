//! Byte-level mutations of a seed (AFL's havoc stage in miniature): bit flips, interesting
//! values, random bytes, deletions, duplications, insertions of digits and structure
//! characters (parsers of text formats are deepest behind valid-looking tokens), splices
//! with another seed and truncation, 1–8 of them stacked per input.

use rand::{Rng, RngCore};

/// Bytes that sit on format boundaries.
const INTERESTING: [u8; 10] = [0, 1, 0x7f, 0x80, 0xff, b'\n', b'-', b'.', b'e', b'"'];
/// Text tokens worth inserting (numbers at the edges of their types, structure).
const TOKENS: [&[u8]; 14] = [
    b"0",
    b"-1",
    b"1e309",
    b"NaN",
    b"inf",
    b"4294967296",
    b"99999999999",
    b"{",
    b"}",
    b"[",
    b"]",
    b",",
    b"\"\"",
    b"\xef\xbb\xbf",
];

/// One mutated input from `seed` (`other` is a second seed for splicing).
pub fn mutate(rng: &mut impl RngCore, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut data = seed.to_vec();
    let stacked = rng.gen_range(1..=8);
    for _ in 0..stacked {
        let len = data.len();
        match rng.gen_range(0..9) {
            0 if len > 0 => {
                let i = rng.gen_range(0..len);
                data[i] ^= 1 << rng.gen_range(0..8);
            }
            1 if len > 0 => {
                let i = rng.gen_range(0..len);
                data[i] = INTERESTING[rng.gen_range(0..INTERESTING.len())];
            }
            2 if len > 0 => {
                let i = rng.gen_range(0..len);
                data[i] = rng.gen();
            }
            3 if len > 1 => {
                let start = rng.gen_range(0..len);
                let end = (start + rng.gen_range(1..=len.min(64))).min(len);
                data.drain(start..end);
            }
            4 if len > 1 => {
                let start = rng.gen_range(0..len);
                let end = (start + rng.gen_range(1..=len.min(64))).min(len);
                let copy = data[start..end].to_vec();
                let at = rng.gen_range(0..=len);
                data.splice(at..at, copy);
            }
            5 => {
                let token = TOKENS[rng.gen_range(0..TOKENS.len())];
                let at = rng.gen_range(0..=len);
                data.splice(at..at, token.iter().copied());
            }
            6 if !other.is_empty() => {
                let cut = rng.gen_range(0..=len);
                let from = rng.gen_range(0..other.len());
                data.truncate(cut);
                data.extend_from_slice(&other[from..]);
            }
            7 if len > 0 => data.truncate(rng.gen_range(0..len)),
            _ => {
                let at = rng.gen_range(0..=len);
                let digit = b'0' + rng.gen_range(0..10);
                data.insert(at, digit);
            }
        }
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn mutations_are_deterministic_and_change_the_input() {
        let seed = b"{\"film\": {\"resolution\": [32, 24]}}";
        let run = || {
            let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
            (0..100)
                .map(|_| mutate(&mut rng, seed, b"other"))
                .collect::<Vec<_>>()
        };
        let (a, b) = (run(), run());
        assert_eq!(a, b);
        assert!(a.iter().filter(|m| m.as_slice() != seed).count() > 90);
    }
}

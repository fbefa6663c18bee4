//! A sum of f64 terms indexed 0, 1, 2, … in an order that does not depend on how rayon
//! splits the work nor on how the terms arrive: fixed blocks of [`BLOCK`] terms, each
//! added from its first term to its last, and the block sums added in order. Terms may
//! arrive in consecutive ranges of any length (strips of an image): a block cut by a
//! range boundary continues from its partial sum, so the result is the same bits as one
//! range of all terms.

use rayon::prelude::*;

/// Terms per block.
const BLOCK: usize = 4096;

#[derive(Debug, Clone, Default)]
pub(crate) struct OrderedSum {
    /// Index of the next term.
    next: usize,
    /// Running sum of the block `next` is in (when `next` is not on a block boundary).
    partial: f64,
    blocks: Vec<f64>,
}

impl OrderedSum {
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// Adds the terms `f(0) … f(n − 1)`, which are terms `start … start + n − 1` of the
    /// sum; `start` must be where the previous range ended.
    pub(crate) fn add_range(&mut self, start: usize, n: usize, f: impl Fn(usize) -> f64 + Sync) {
        assert_eq!(start, self.next, "ranges must follow one another");
        let end = start + n;
        let mut i = start;
        if !i.is_multiple_of(BLOCK) {
            let stop = end.min(i.next_multiple_of(BLOCK));
            self.partial = (i..stop).fold(self.partial, |a, j| a + f(j - start));
            i = stop;
            if i.is_multiple_of(BLOCK) {
                self.blocks.push(self.partial);
            }
        }
        let full_end = i + (end - i) / BLOCK * BLOCK;
        let sums: Vec<f64> = (i / BLOCK..full_end / BLOCK)
            .into_par_iter()
            .map(|b| (b * BLOCK..(b + 1) * BLOCK).map(|j| f(j - start)).sum())
            .collect();
        self.blocks.extend(sums);
        if full_end < end {
            self.partial = (full_end..end).map(|j| f(j - start)).sum();
        }
        self.next = end;
    }

    /// The sum of every term added.
    pub(crate) fn finish(mut self) -> f64 {
        if !self.next.is_multiple_of(BLOCK) {
            self.blocks.push(self.partial);
        }
        self.blocks.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Terms whose sum depends on the order of addition (large and small values mixed).
    fn term(i: usize) -> f64 {
        let x = (i as f64 * 0.618_033_988_749).fract();
        if i.is_multiple_of(7) {
            1e12 * x
        } else {
            x * 1e-3 - 0.3
        }
    }

    #[test]
    fn ranges_of_any_length_give_the_bits_of_one_range() {
        for n in [0, 1, 4095, 4096, 4097, 20_000] {
            let mut whole = OrderedSum::new();
            whole.add_range(0, n, term);
            let want = whole.finish();
            for step in [1, 3, 1000, 4096, 5000, 9000] {
                let mut parts = OrderedSum::new();
                let mut at = 0;
                while at < n {
                    let len = step.min(n - at);
                    parts.add_range(at, len, |i| term(at + i));
                    at += len;
                }
                assert_eq!(
                    parts.finish().to_bits(),
                    want.to_bits(),
                    "n {n} step {step}"
                );
            }
        }
    }
}

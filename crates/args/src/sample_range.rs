//! Sample ranges (`--samples A..B`, and the `ranges_done` header of partial renders) as the
//! command line spells them, and how a range of the N-sample sequence maps to a pixel's
//! own samples under a per-pixel plan.

use std::fmt;

/// A half-open range [start, end) of sample indices: start < end as the command line and
/// headers give it; a pixel's share of one (`of_pixel`) may be empty.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SampleRange {
    pub start: u32,
    pub end: u32,
}

impl SampleRange {
    pub fn len(self) -> u32 {
        self.end - self.start
    }

    /// No samples (a pixel's share of a range can be empty).
    pub fn is_empty(self) -> bool {
        self.end <= self.start
    }

    /// Pixel p with N_p of the plan's N samples gets [⌊a·N_p/N⌋, ⌊b·N_p/N⌋) of its own
    /// sequence, so the ranges of any split of [0, N) give it exactly its N_p samples once.
    pub fn of_pixel(self, pixel_samples: u32, total: u32) -> SampleRange {
        let scale =
            |k: u32| (u64::from(k) * u64::from(pixel_samples) / u64::from(total.max(1))) as u32;
        SampleRange {
            start: scale(self.start),
            end: scale(self.end),
        }
    }

    pub fn overlaps(self, other: SampleRange) -> bool {
        self.start < other.end && other.start < self.end
    }
}

impl fmt::Display for SampleRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

/// `A..B` with A < B (clap's value parser for `--samples`; also the header's form).
pub fn parse_range(s: &str) -> Result<SampleRange, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("`{s}`: expected a sample range A..B, e.g. 256..512"))?;
    let number = |t: &str| {
        t.trim().parse::<u32>().map_err(|_| {
            format!("`{s}`: `{t}` is not a sample index (expected A..B, e.g. 256..512)")
        })
    };
    let (start, end) = (number(a)?, number(b)?);
    if start >= end {
        return Err(format!(
            "`{s}`: the range is empty; expected A..B with A < B (half-open: B is not rendered)"
        ));
    }
    Ok(SampleRange { start, end })
}

/// A list of ranges as `0..256,256..512` (empty: none).
pub fn format_ranges(ranges: &[SampleRange]) -> String {
    ranges
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// `0..256,256..512` (empty items skipped).
pub fn parse_ranges(s: &str) -> Result<Vec<SampleRange>, String> {
    s.split(',')
        .filter(|t| !t.trim().is_empty())
        .map(|t| parse_range(t.trim()).map_err(|e| format!("in the list `{s}`: {e}")))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_refuse_with_the_reason() {
        assert_eq!(
            parse_range("256..512"),
            Ok(SampleRange {
                start: 256,
                end: 512
            })
        );
        assert!(parse_range("512..256").unwrap_err().contains("A < B"));
        assert!(parse_range("5").unwrap_err().contains("A..B"));
        assert!(parse_range("a..4").unwrap_err().contains("`a`"));
        assert_eq!(
            parse_ranges("0..4,8..16").unwrap(),
            vec![
                SampleRange { start: 0, end: 4 },
                SampleRange { start: 8, end: 16 }
            ]
        );
    }

    #[test]
    fn a_split_of_the_sequence_gives_each_pixel_its_samples_once() {
        // Any split of [0, N) gives pixel p consecutive, disjoint ranges covering [0, N_p).
        let total = 512;
        let cuts = [0, 7, 100, 256, 300, 511, 512];
        for n_p in [0, 1, 3, 100, 511, 512, 2000] {
            let mut at = 0;
            for w in cuts.windows(2) {
                let r = SampleRange {
                    start: w[0],
                    end: w[1],
                }
                .of_pixel(n_p, total);
                assert_eq!(r.start, at);
                at = r.end;
            }
            assert_eq!(at, n_p);
        }
    }
}

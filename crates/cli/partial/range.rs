//! Sample ranges of a partial render: the type and its text form are prism-args'
//! (`--samples A..B`, and the partial file's header); here, what a set of done ranges
//! leaves to render.

pub use prism_args::sample_range::{format_ranges, parse_range, parse_ranges, SampleRange};

/// The ranges of [0, total) that `done` (sorted, disjoint) does not cover.
pub fn missing_ranges(done: &[SampleRange], total: u32) -> Vec<SampleRange> {
    let mut missing = Vec::new();
    let mut at = 0;
    for r in done {
        if r.start > at {
            missing.push(SampleRange {
                start: at,
                end: r.start,
            });
        }
        at = at.max(r.end);
    }
    if at < total {
        missing.push(SampleRange {
            start: at,
            end: total,
        });
    }
    missing
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_ranges_are_the_gaps() {
        let done = [
            SampleRange { start: 0, end: 4 },
            SampleRange { start: 8, end: 12 },
        ];
        assert_eq!(
            missing_ranges(&done, 16),
            vec![
                SampleRange { start: 4, end: 8 },
                SampleRange { start: 12, end: 16 }
            ]
        );
    }
}

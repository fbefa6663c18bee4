//! Test-only helpers shared by the Prism crates' tests (a `[dev-dependencies]` entry, never
//! a normal dependency): the chi-square goodness-of-fit harness of direction samplers
//! ([`chi2`]) and its deterministic variates ([`chi2::SplitMix64`]); Simpson's rule for
//! closed-form references ([`quadrature`]); the Hann-windowed spectrum and 95 %-energy
//! radius that local-bandwidth estimates are checked against ([`windowed_spectrum`]);
//! Spearman's rank correlation ([`rank_correlation`]).
//!
//! Generic over closures, so it depends on no prism crate and every crate — prism-render's
//! own unit tests included — can dev-depend on it without a cycle.

pub mod chi2;
pub mod quadrature;
pub mod rank_correlation;
pub mod windowed_spectrum;

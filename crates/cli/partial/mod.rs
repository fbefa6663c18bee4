//! Partial renders: sample ranges, checkpoints, resuming, and the file that carries a
//! film's exact state between processes (docs/rendering.md, docs/scale-out.md).

pub mod file;
pub mod identity;
pub mod job;
pub mod range;
pub mod sensor_sums;
pub mod signals;

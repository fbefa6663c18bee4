//! The values `prism`'s options take, parsed from the text the user typed: each parser is a
//! pure function (clap's `value_parser`) that returns the value or a message in the
//! project's words that repeats the text (`` `64y48`: expected WIDTHxHEIGHT, e.g. 64x48 ``).
//! They live in a library so that prism-fuzz's `cli-values` target can fuzz them
//! (docs/reliability.md); the memory size and thread count parsers are prism-cpu's
//! (`memory::parse_size`, `threads::parse_thread_count`), next to the limits they check.

pub mod duration;
pub mod numbers;
pub mod resolution;
pub mod sample_range;
pub mod tone_values;
pub mod value_range;

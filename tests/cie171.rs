//! CIE 171:2006 "Test cases to assess the accuracy of lighting computer programs" — the
//! artificial-lighting cases 5.2–5.8, each reference computed from first principles in
//! the test (the report's tables are not copied). Pass criterion (as the published
//! validations of Radiance and Iray): every point within 5 % and the average within 2 %.
//! Each test prints its table of reference, ours (± standard error) and error.
//!
//! Layout: one module per case under tests/cie171/, shared helpers (scene runner,
//! Lambert's polygon formula, the table) in tests/cie171/common.rs. The daylight cases
//! 5.9–5.14 go in further modules beside these.

#[path = "cie171/common.rs"]
mod common;

#[path = "cie171/case_5_2_point_sources.rs"]
mod case_5_2_point_sources;
#[path = "cie171/case_5_3_area_sources.rs"]
mod case_5_3_area_sources;
#[path = "cie171/case_5_4_flux_conservation.rs"]
mod case_5_4_flux_conservation;
#[path = "cie171/case_5_5_clear_glass.rs"]
mod case_5_5_clear_glass;
#[path = "cie171/case_5_6_diffuse_reflection.rs"]
mod case_5_6_diffuse_reflection;
#[path = "cie171/case_5_7_obstructions.rs"]
mod case_5_7_obstructions;
#[path = "cie171/case_5_8_internal_reflections.rs"]
mod case_5_8_internal_reflections;

//! Physical and colorimetric constants shared by every module.

/// Shortest wavelength Prism carries light at (CIE 015 colour-matching range).
pub const LAMBDA_MIN_NM: f32 = 360.0;
/// Longest wavelength Prism carries light at.
pub const LAMBDA_MAX_NM: f32 = 830.0;
/// Number of 1 nm samples in 360..=830 nm.
pub const DENSE_SAMPLE_COUNT: usize = 471;

/// Maximum photopic luminous efficacy K_m in lm/W (CIE 015, 683.002 for V(λ) at 555.016 nm).
pub const K_M_PHOTOPIC_LM_PER_W: f64 = 683.002;
/// Maximum scotopic luminous efficacy K'_m in lm/W (CIE, rounded as colour-science does).
pub const K_M_SCOTOPIC_LM_PER_W: f64 = 1700.0;

/// Planck constant in J·s (SI 2019, exact).
pub const PLANCK_J_S: f64 = 6.626_070_15e-34;
/// Speed of light in vacuum in m/s (exact).
pub const SPEED_OF_LIGHT_M_PER_S: f64 = 299_792_458.0;
/// Boltzmann constant in J/K (SI 2019, exact).
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;

//! The process-wide limit: PRISM_SIMD and `set_limit` (one test, its own process: both
//! change global state).

use prism_cpu::{active, choice, env_limit, set_limit, Isa, Simd, ENV_VAR};

#[test]
fn env_and_flag_limits_and_their_reasons() {
    let best = Isa::detected();
    // An invalid value: an error naming the variable and the valid values, and the
    // library goes on as if unset, saying so.
    std::env::set_var(ENV_VAR, "sse9");
    let err = env_limit().unwrap_err();
    assert!(
        err.contains("PRISM_SIMD=sse9") && err.contains("scalar, avx2 or avx512"),
        "{err}"
    );
    let c = choice();
    assert_eq!(c.simd, Simd::detected());
    assert!(c.reason.contains("ignored PRISM_SIMD=sse9"), "{}", c.reason);
    // Empty is unset.
    std::env::set_var(ENV_VAR, "");
    assert_eq!(env_limit(), Ok(None));
    // Scalar from the environment.
    std::env::set_var(ENV_VAR, "scalar");
    assert_eq!(env_limit(), Ok(Some(Isa::Scalar)));
    let c = choice();
    assert_eq!(
        (c.simd, c.reason.as_str()),
        (Simd::SCALAR, "PRISM_SIMD=scalar")
    );
    assert_eq!(format!("{c}"), "scalar (PRISM_SIMD=scalar)");
    assert_eq!(active(), Simd::SCALAR);
    // The flag wins over the environment; beyond the CPU it falls back with the reason.
    set_limit(Isa::Avx512);
    let c = choice();
    assert_eq!(c.simd.isa(), best);
    assert_eq!(active(), c.simd);
    match Isa::Avx512.missing() {
        None => assert_eq!(c.reason, "--simd avx512; PRISM_SIMD=scalar overridden"),
        Some(lacks) => assert_eq!(
            c.reason,
            format!("--simd avx512; PRISM_SIMD=scalar overridden; the CPU lacks {lacks}")
        ),
    }
    std::env::remove_var(ENV_VAR);
    set_limit(Isa::Avx2);
    let c = choice();
    assert_eq!(c.simd.isa(), best.min(Isa::Avx2));
    assert!(c.reason.starts_with("--simd avx2"), "{}", c.reason);
    set_limit(Isa::Scalar);
    assert_eq!(active(), Simd::SCALAR);
    assert_eq!(format!("{}", choice()), "scalar (--simd scalar)");
}

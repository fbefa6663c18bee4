//! Quadrature for closed-form references in tests.

/// Composite Simpson's rule on `n` (even) steps over [a, b].
pub fn simpson(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    debug_assert!(
        n.is_multiple_of(2),
        "Simpson's rule needs an even number of steps"
    );
    let h = (b - a) / n as f64;
    let mut sum = 0.0;
    for i in 0..=n {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        sum += w * f(a + i as f64 * h);
    }
    sum * h / 3.0
}

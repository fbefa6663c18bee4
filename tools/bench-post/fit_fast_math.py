#!/usr/bin/env python3
"""Fits the polynomials of crates/post/src/tonemap/fast_math.rs (numpy only).

Near-minimax by iteratively reweighted least squares on Chebyshev nodes (Lawson's
algorithm), then rounded to f32 and checked by an f32 Horner evaluation:
  log2(1 + u) ≈ u · q(u), u ∈ [√½ − 1, √2 − 1], q of degree 7 (absolute error);
  2^f ≈ 1 + f · r(f), f ∈ [−½, ½], r of degree 4 (relative error).
Prints the coefficients (highest degree first, as the Horner code uses them) and the
maximum f32 error on a dense grid. Run: python3 tools/bench-post/fit_fast_math.py
"""
import numpy as np


def lawson(x, y, basis, weight, iterations=40):
    w = np.ones_like(x)
    a = np.vstack([b(x) for b in basis]).T
    for _ in range(iterations):
        c, *_ = np.linalg.lstsq(a * (w * weight)[:, None], y * w * weight, rcond=None)
        err = (a @ c - y) * weight
        w *= np.sqrt(np.abs(err)) + 1e-30
        w /= w.max()
    return c


def nodes(lo, hi, n=4000):
    return np.cos(np.pi * (np.arange(n) + 0.5) / n) * (hi - lo) / 2 + (lo + hi) / 2


def horner32(coeffs_low_first, x):
    c = [np.float32(v) for v in coeffs_low_first]
    p = np.full_like(x, c[-1])
    for v in reversed(c[:-1]):
        p = p * x + v
    return p


lo, hi = np.sqrt(0.5) - 1, np.sqrt(2) - 1
x = nodes(lo, hi)
q = lawson(x, np.log2(1 + x), [lambda t, k=k: t ** (k + 1) for k in range(8)], np.ones_like(x))
u = np.linspace(lo, hi, 400001).astype(np.float32)
got = horner32(q, u) * u
err = np.abs(got.astype(np.float64) - np.log2(1 + u.astype(np.float64))).max()
print("log2 q (highest first):", [repr(np.float32(v)) for v in q[::-1]], "max abs error", err)

x = nodes(-0.5, 0.5)
r = lawson(x, 2 ** x - 1, [lambda t, k=k: t ** (k + 1) for k in range(5)], 2 ** -x)
f = np.linspace(-0.5, 0.5, 400001).astype(np.float32)
got = horner32(r, f) * f + np.float32(1)
err = np.abs(got.astype(np.float64) / 2 ** f.astype(np.float64) - 1).max()
print("exp2 r (highest first):", [repr(np.float32(v)) for v in r[::-1]], "max rel error", err)

#!/usr/bin/env python3
"""Export tests/fixtures/flip_reference.json: NVIDIA's reference FLIP (flip-evaluator from
the Python package index) on 7 image pairs, for crates/post/tests/flip_reference.rs.

Run (idempotent; installs flip-evaluator 1.7 and numpy with pip when missing):
    python3 tools/export_flip_fixture.py

The images are not stored: both this script and the Rust test build them from the same
formula (`scene`, `noise` below, mirrored in the test), in float64, stored as float32.
The file holds the tool and its version, the exact calls, the image size, and per pair
the LDR and HDR means, the HDR exposure range the tool chose and both per-pixel maps
(row-major, top row first, rounded to 6 decimals).
"""

import importlib.metadata
import json
import math
import pathlib
import subprocess
import sys

VERSION = "1.7"


def ensure(package, version=None):
    try:
        importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        spec = f"{package}=={version}" if version else package
        subprocess.check_call([sys.executable, "-m", "pip", "install", spec])


ensure("flip-evaluator", VERSION)
ensure("numpy")

import numpy as np  # noqa: E402

import flip_evaluator  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "fixtures" / "flip_reference.json"
W, H = 64, 48

LDR_CALL = "flip_evaluator.evaluate(reference, test, 'LDR', inputsRGB=False, applyMagma=False)"
HDR_CALL = "flip_evaluator.evaluate(reference, test, 'HDR', inputsRGB=False, applyMagma=False)"


def hash32(x):
    """lowbias32 (Chris Wellons): a 32-bit integer mix."""
    x &= 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


def noise(i, seed):
    """Uniform on [-1, 1) from pixel-sample index i and a seed."""
    return (hash32(i * 0x9E3779B9 + seed) >> 8) / float(1 << 23) - 1.0


def scene(highlight):
    """Linear Rec.709 HDR test scene: colour gradients under a horizontal exposure ramp
    (2^-1 .. 2^3), an 8-px checker at 30 %, and a disc of the given highlight value."""
    img = np.zeros((H, W, 3))
    for y in range(H):
        for x in range(W):
            u, v = x / W, y / H
            c = [0.05 + 0.9 * u, 0.05 + 0.9 * v, 0.3 + 0.25 * math.sin(2 * math.pi * (u + v))]
            gain = 2.0 ** (4.0 * u - 1.0)
            if ((x // 8) + (y // 8)) % 2 == 0:
                gain *= 0.3
            if (x - 48) ** 2 + (y - 12) ** 2 <= 16:
                c, gain = [highlight, 0.9 * highlight, 0.8 * highlight], 1.0
            img[y, x] = [ch * gain for ch in c]
    return img


def noisy(img, amount, seed):
    out = img.copy()
    for y in range(H):
        for x in range(W):
            for c in range(3):
                i = (y * W + x) * 3 + c
                out[y, x, c] *= 1.0 + amount * noise(i, seed)
    return out


def pairs():
    base = scene(50.0)
    bright = scene(1000.0)
    yield "noise-5%", noisy(base, 0.05, 1), base
    yield "noise-20%", noisy(base, 0.2, 2), base
    yield "noise-60%", noisy(base, 0.6, 3), base
    # Two tone mappings of the same scene: Reinhard x/(1+x) against a 0.5× linear clip.
    yield "tonemapped", np.clip(0.5 * base, 0, 1), base / (1.0 + base)
    # Extreme highlights: the reference disc at 1000, the test's at 800 with 10 % noise.
    yield "highlight", noisy(scene(800.0), 0.1, 5), bright
    yield "shift-1px", np.roll(base, 1, axis=1), base
    yield "colour-cast", base * np.array([1.1, 1.0, 0.85]), base


def as_f32(img):
    return np.ascontiguousarray(img.astype(np.float32))


def main():
    out = {
        "tool": f"flip-evaluator {importlib.metadata.version('flip-evaluator')}",
        "numpy": np.__version__,
        "ldr_call": LDR_CALL + " on np.clip(image, 0, 1)",
        "hdr_call": HDR_CALL,
        "width": W,
        "height": H,
        "pairs": [],
    }
    for name, test, reference in pairs():
        t, r = as_f32(test), as_f32(reference)
        ldr_map, ldr_mean, _ = flip_evaluator.evaluate(
            np.clip(r, 0, 1), np.clip(t, 0, 1), "LDR", inputsRGB=False, applyMagma=False
        )
        hdr_map, hdr_mean, params = flip_evaluator.evaluate(
            r, t, "HDR", inputsRGB=False, applyMagma=False
        )
        out["pairs"].append(
            {
                "name": name,
                "ldr_mean": float(ldr_mean),
                "hdr_mean": float(hdr_mean),
                "ppd": float(params["ppd"]),
                "hdr_start_exposure": float(params["startExposure"]),
                "hdr_stop_exposure": float(params["stopExposure"]),
                "hdr_num_exposures": int(params["numExposures"]),
                "ldr_map": [round(float(v), 6) for v in ldr_map.reshape(-1)],
                "hdr_map": [round(float(v), 6) for v in hdr_map.reshape(-1)],
            }
        )
        print(f"{name:12} LDR {ldr_mean:.5f}  HDR {hdr_mean:.5f}  exposures {params['numExposures']}")
    OUT.write_text(json.dumps(out, separators=(",", ":")) + "\n")
    print(f"wrote {OUT} ({OUT.stat().st_size} bytes)")


if __name__ == "__main__":
    main()

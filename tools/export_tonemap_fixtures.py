#!/usr/bin/env python3
"""Export tests/fixtures/tonemap_colour_hdri.json: outputs of colour-hdri's global tone
operators on a small hand-made HDR image, for crates/post/tests/tonemap_colour_hdri.rs.

Run (idempotent):
    python3 -m pip install -r tools/requirements.txt && python3 tools/export_tonemap_fixtures.py

The file holds "provenance" (colour-hdri, colour-science and numpy versions), "input"
(4x3 linear sRGB pixels, row-major, top row first), "luminance_weights" (the Y row colour
uses for sRGB, from RGB_luminance on the unit vectors) and "cases": one per call, with the
function name, its keyword arguments, the exact call as text and the output pixels.
Which cases match Prism's operators, and why the others do not, is stated in the Rust test.
"""

import json
import pathlib
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402

import colour  # noqa: E402
import colour_hdri  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "fixtures" / "tonemap_colour_hdri.json"

# Luminances from about 0.1 to 300 (no zeros: colour-hdri divides by L), saturated and
# neutral colours; exactly representable in f32 (multiples of 1/64).
INPUT = np.array(
    [
        [[0.125, 0.125, 0.125], [0.5, 0.25, 0.125], [1.0, 1.0, 1.0], [0.25, 0.75, 0.5]],
        [[2.0, 1.5, 0.75], [4.0, 4.0, 4.0], [0.75, 2.0, 6.0], [12.0, 8.0, 4.0]],
        [[20.0, 30.0, 10.0], [64.0, 48.0, 32.0], [150.0, 100.0, 60.0], [300.0, 300.0, 300.0]],
    ],
    dtype=np.float64,
)

CASES = [
    ("tonemapping_operator_simple", {}),
    ("tonemapping_operator_normalisation", {}),
    ("tonemapping_operator_gamma", {"gamma": 1.0, "EV": -2.0}),
    ("tonemapping_operator_gamma", {"gamma": 2.2, "EV": 0.0}),
    ("tonemapping_operator_logarithmic", {"q": 1.0, "k": 1.0}),
    ("tonemapping_operator_logarithmic", {"q": 4.0, "k": 2.0}),
    ("tonemapping_operator_exponential", {"q": 1.0, "k": 1.0}),
    ("tonemapping_operator_exponential", {"q": 2.0, "k": 3.0}),
    ("tonemapping_operator_logarithmic_mapping", {"p": 1.0, "q": 1.0}),
    ("tonemapping_operator_exponentiation_mapping", {"p": 1.0, "q": 1.0}),
    ("tonemapping_operator_Schlick1994", {"p": 1.0}),
    ("tonemapping_operator_Schlick1994", {"p": 20.0}),
    ("tonemapping_operator_Tumblin1999", {"L_da": 20.0, "C_max": 100.0, "L_max": 100.0}),
    ("tonemapping_operator_Reinhard2004", {"f": 0.0}),
    ("tonemapping_operator_filmic", {}),
]


def main():
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    weights = [
        float(colour.RGB_luminance(np.eye(3)[i], srgb.primaries, srgb.whitepoint))
        for i in range(3)
    ]
    cases = []
    for name, kwargs in CASES:
        out = getattr(colour_hdri, name)(INPUT, **kwargs)
        args = ", ".join(f"{k}={v!r}" for k, v in kwargs.items())
        cases.append(
            {
                "function": name,
                "kwargs": kwargs,
                "call": f"colour_hdri.{name}(INPUT{', ' + args if args else ''})",
                "output": np.asarray(out).reshape(-1, 3).tolist(),
            }
        )
    doc = {
        "provenance": {
            "colour_hdri": colour_hdri.__version__,
            "colour_science": colour.__version__,
            "numpy": np.__version__,
            "script": "tools/export_tonemap_fixtures.py",
            "note": "default colourspace (sRGB) for every luminance computation",
        },
        "width": 4,
        "height": 3,
        "input": INPUT.reshape(-1, 3).tolist(),
        "luminance_weights": weights,
        "cases": cases,
    }
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT} ({len(cases)} cases)")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Exports how Mitsuba 3's spectral variant turns the RGB values of its built-in Cornell box
(`mitsuba.cornell_box()`) into spectra: the three diffuse reflectances and the area light's
radiance, at 360, 365, ..., 830 nm, as Mitsuba evaluates them.

Writes tests/fixtures/mitsuba_cornell_spectra.json (read by tests/mitsuba_spectra.rs, which
needs no Python). Run: tools/mitsuba/.venv/bin/python tools/mitsuba/export_cornell_spectra.py

What Mitsuba does (3.6.4, spectral variants):
- a reflectance `{'type': 'rgb', 'value': c}` becomes the `srgb` plugin
  (SRGBReflectanceSpectrum): coefficients = srgb_model_fetch(c) (Jakob & Hanika 2019 table,
  resolution 64, trilinear lookup, no refinement); value(lambda) =
  srgb_model_eval(coeff, lambda) = sigmoid(c0 lambda^2 + c1 lambda + c2), lambda in nm;
- an emitter's `{'type': 'rgb', 'value': c}` becomes the `d65` plugin (D65Spectrum): scale =
  2 max(c), coefficients = srgb_model_fetch(c / scale), value(lambda) = scale *
  srgb_model_eval(coeff, lambda) * D65(lambda) * MI_CIE_D65_NORMALIZATION, D65 the CIE table at
  5 nm over 360-830 nm interpolated linearly, MI_CIE_D65_NORMALIZATION = 1 / 98.99744...
"""

import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from common import ROOT, import_mitsuba  # noqa: E402

OUT = ROOT / "tests" / "fixtures" / "mitsuba_cornell_spectra.json"
WAVELENGTHS = [360.0 + 5.0 * i for i in range(95)]  # 360..830 step 5 nm
MATERIALS = ["white", "green", "red"]


def eval4(mi, dr, fn, wavelengths):
    """Evaluates fn(si) (si carrying 4 wavelengths) over any list of wavelengths."""
    out = []
    for i in range(0, len(wavelengths), 4):
        chunk = wavelengths[i : i + 4]
        padded = chunk + [chunk[-1]] * (4 - len(chunk))
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wavelengths = mi.Spectrum(padded)
        si.n = mi.Vector3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        si.wi = mi.Vector3f(0, 0, 1)
        v = fn(si)
        out.extend(float(v[j]) for j in range(len(chunk)))
    return out


def emitter_radiance(mi, dr, cornell, wavelengths):
    """Radiance of the Cornell box light, seen along its normal, as its AreaLight evaluates it."""
    shape = mi.load_dict({"type": "rectangle", "emitter": cornell["light"]["emitter"]})
    emitter = shape.emitter()
    return eval4(mi, dr, lambda si: emitter.eval(si), wavelengths), emitter


def _flip(mi, si):
    """The same interaction seen from behind the surface."""
    si.wi = mi.Vector3f(0, 0, -1)
    return si


def main():
    mi = import_mitsuba()
    import drjit as dr

    mi.set_variant("scalar_spectral")
    cornell = mi.cornell_box()

    reflectances = {}
    checks = {}
    for name in MATERIALS:
        rgb = [float(x) for x in cornell[name]["reflectance"]["value"]]
        texture = mi.load_dict(cornell[name]["reflectance"])
        values = eval4(mi, dr, lambda si: texture.eval(si), WAVELENGTHS)
        coeff = mi.srgb_model_fetch(mi.ScalarColor3f(rgb))
        # Cross-checks: the BSDF as loaded from the dict (albedo = eval * pi / cos at normal
        # incidence) and the bare model functions give the same numbers.
        bsdf = mi.load_dict(cornell[name])
        ctx = mi.BSDFContext()
        via_bsdf = eval4(
            mi, dr, lambda si: bsdf.eval(ctx, si, mi.Vector3f(0, 0, 1)) * dr.pi, WAVELENGTHS
        )
        via_model = eval4(
            mi, dr, lambda si: mi.srgb_model_eval(coeff, si.wavelengths), WAVELENGTHS
        )
        checks[name] = {
            "max_abs_texture_minus_bsdf_times_pi": max(abs(a - b) for a, b in zip(values, via_bsdf)),
            "max_abs_texture_minus_srgb_model_eval": max(
                abs(a - b) for a, b in zip(values, via_model)
            ),
        }
        reflectances[name] = {
            "rgb": rgb,
            "coefficients": [float(coeff[i]) for i in range(3)],
            "values": values,
        }

    light_rgb = [float(x) for x in cornell["light"]["emitter"]["radiance"]["value"]]
    radiance, emitter = emitter_radiance(mi, dr, cornell, WAVELENGTHS)
    scale = 2.0 * max(light_rgb)
    coeff = mi.srgb_model_fetch(mi.ScalarColor3f([c / scale for c in light_rgb]))
    d65 = [mi.cie_d65(w) for w in WAVELENGTHS]
    # The D65Spectrum formula, rebuilt from its parts: must equal the emitter's own eval.
    rebuilt = eval4(
        mi,
        dr,
        lambda si: scale * mi.srgb_model_eval(coeff, si.wavelengths),
        WAVELENGTHS,
    )
    rebuilt = [r * d for r, d in zip(rebuilt, d65)]
    checks["emitter"] = {
        "max_rel_eval_minus_scale_sigmoid_d65": max(
            abs(a - b) / max(abs(a), 1e-30) for a, b in zip(radiance, rebuilt)
        ),
    }
    # Emission only on the front side (the light's normal), like every Mitsuba area light.
    back = eval4(mi, dr, lambda si: emitter.eval(_flip(mi, si)), WAVELENGTHS[:4])
    checks["emitter"]["back_side_radiance_max"] = max(back)

    # Mitsuba's luminance normalisation: Y = MI_CIE_Y_NORMALIZATION * sum(L ybar) dlambda.
    ybar_1nm = [mi.cie1931_y(float(w)) for w in range(360, 831)]
    d65_1nm = [mi.cie_d65(float(w)) for w in range(360, 831)]
    fixture = {
        "generator": (
            f"Mitsuba {mi.__version__} (Dr.Jit {dr.__version__}), variant scalar_spectral, "
            "tools/mitsuba/export_cornell_spectra.py. Scene: mi.cornell_box(). Reflectances: "
            "mi.load_dict(mi.cornell_box()[name]['reflectance']).eval(si) (plugin srgb, "
            "SRGBReflectanceSpectrum), si = dr.zeros(mi.SurfaceInteraction3f) with "
            "si.wavelengths set, 4 at a time; coefficients = mi.srgb_model_fetch(rgb). "
            "Emitter: mi.load_dict({'type': 'rectangle', 'emitter': "
            "mi.cornell_box()['light']['emitter']}).emitter().eval(si) with si.wi = (0, 0, 1) "
            "(plugin d65, D65Spectrum: scale = 2 max(rgb), coefficients = "
            "mi.srgb_model_fetch(rgb / scale), value = scale * mi.srgb_model_eval(coeff, "
            "lambda) * mi.cie_d65(lambda))."
        ),
        "mitsuba_version": mi.__version__,
        "drjit_version": dr.__version__,
        "variant": "scalar_spectral",
        "wavelengths_nm": WAVELENGTHS,
        "reflectances": reflectances,
        "emitter": {
            "rgb": light_rgb,
            "scale": scale,
            "coefficients": [float(coeff[i]) for i in range(3)],
            "values": radiance,
        },
        "d65_normalized": d65,
        "constants": {
            "MI_CIE_D65_NORMALIZATION": mi.MI_CIE_D65_NORMALIZATION,
            "MI_CIE_Y_NORMALIZATION": mi.MI_CIE_Y_NORMALIZATION,
            "one_over_MI_CIE_Y_NORMALIZATION": 1.0 / mi.MI_CIE_Y_NORMALIZATION,
            "sum_ybar_1nm_360_830": math.fsum(ybar_1nm),
            "luminance_of_normalized_d65": math.fsum(a * b for a, b in zip(ybar_1nm, d65_1nm))
            * mi.MI_CIE_Y_NORMALIZATION,
        },
        "checks": checks,
    }
    OUT.write_text(json.dumps(fixture, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    print(json.dumps(checks, indent=1))


if __name__ == "__main__":
    main()

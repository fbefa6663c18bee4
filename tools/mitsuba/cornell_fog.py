#!/usr/bin/env python3
"""Mitsuba 3's built-in Cornell box (`mitsuba.cornell_box()`) filled with fog: Mitsuba's
`volpathmis` against Prism's volumetric `path` (issue 20, test 8).

The fog is a homogeneous medium inside a cube scaled by 1.001 (it encloses every wall) whose
BSDF is Mitsuba's `null` (Prism: the `interface` material). sigma_t and the single-scattering
albedo are spectra (Mitsuba `regular` spectra, 11 values over 360-830 nm, linear between);
the phase function is Henyey-Greenstein, g 0.3. The camera stays outside the cube, in vacuum.

Writes
- scenes/cornell-box-fog.json: scenes/cornell-box.json (which tools/mitsuba/
  export_cornell_scene.py wrote from the same dict) plus the fog, at 128x128 px;
- scenes/cornell-box-fog/sigma-a.csv, sigma-s.csv: sigma_a = sigma_t (1 - albedo) and
  sigma_s = sigma_t albedo (m^-1) at every nm 360-830, from Mitsuba's own evaluation of the
  two spectra (Prism takes sigma_a and sigma_s; Mitsuba sigma_t and albedo);
- tests/fixtures/cornell_fog_mitsuba_reference.exr + .json: Mitsuba's render (mean of
  spp / pass_spp renders with seeds 0, 1, ...), as tools/mitsuba/render_reference.py does for
  the fog-free box.

Run (about 10 min at 4096 spp on 2 busy cores with llvm_ad_spectral):
  nice tools/mitsuba/.venv/bin/python tools/mitsuba/cornell_fog.py --spp 4096
  tools/mitsuba/.venv/bin/python tools/mitsuba/cornell_fog.py --scene-only
"""

import argparse
import json
import os
import pathlib
import platform
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from common import ROOT, find_libllvm, has_llvm_variant, import_mitsuba  # noqa: E402
from export_cornell_scene import compact_json, matrix_rows  # noqa: E402

BASE_SCENE = ROOT / "scenes" / "cornell-box.json"
SCENE = ROOT / "scenes" / "cornell-box-fog.json"
CSV_DIR_REL = "cornell-box-fog"
EXR = ROOT / "tests" / "fixtures" / "cornell_fog_mitsuba_reference.exr"
META = ROOT / "tests" / "fixtures" / "cornell_fog_mitsuba_reference.json"

RESOLUTION = 128
# Mitsuba counts path segments, Prism bounces (docs/mitsuba.md). Both stop by Russian
# roulette long before this depth (throughput < 0.9^63 there), so where each counts a medium
# scattering or a null crossing cannot matter.
MITSUBA_MAX_DEPTH = 64
HG_G = 0.3
CUBE_SCALE = 1.001
KNOTS_NM = np.linspace(360.0, 830.0, 11)
# Haze-like: sigma_t falls with wavelength (0.5 m^-1 at 550 nm, optical depth ~1 across the
# box), the albedo from 0.9 (blue) to 0.6 (red): a chromatic medium, so spectral MIS matters.
SIGMA_T_PER_M = [float(np.float32(0.5 * (550.0 / w) ** 1.3)) for w in KNOTS_NM]
ALBEDO = [float(np.float32(0.9 - 0.3 * (w - 360.0) / 470.0)) for w in KNOTS_NM]


def regular(values):
    return {
        "type": "regular",
        "wavelength_min": float(KNOTS_NM[0]),
        "wavelength_max": float(KNOTS_NM[-1]),
        "values": ", ".join(repr(v) for v in values),
    }


def fog_medium():
    return {
        "type": "homogeneous",
        "sigma_t": regular(SIGMA_T_PER_M),
        "albedo": regular(ALBEDO),
        "scale": 1.0,
        "phase": {"type": "hg", "g": HG_G},
    }


def mitsuba_dict(mi):
    d = mi.cornell_box()
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = RESOLUTION
    d["integrator"] = {"type": "volpathmis", "max_depth": MITSUBA_MAX_DEPTH}
    d["fog-box"] = {
        "type": "cube",
        "to_world": mi.ScalarTransform4f().scale(CUBE_SCALE),
        "bsdf": {"type": "null"},
        "interior": fog_medium(),
    }
    return d


def evaluate(mi, dr, spectrum, wavelengths):
    """The spectrum's values as Mitsuba evaluates them, 4 wavelengths at a time."""
    texture = mi.load_dict(spectrum)
    out = []
    for i in range(0, len(wavelengths), 4):
        chunk = wavelengths[i : i + 4]
        padded = chunk + [chunk[-1]] * (4 - len(chunk))
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wavelengths = mi.Spectrum(padded)
        v = texture.eval(si)
        out.extend(float(v[j]) for j in range(len(chunk)))
    return out


def write_csv(path, name, what, wavelengths, values, version):
    with open(path, "w") as f:
        f.write(
            f"# {name}: {what} (m^-1) of the fog in scenes/cornell-box-fog.json, from\n"
            f"# Mitsuba {version} (scalar_spectral) evaluating its homogeneous medium's\n"
            f"# regular spectra sigma_t {SIGMA_T_PER_M}\n"
            f"# and albedo {ALBEDO} (360-830 nm, linear between).\n"
            "# exported by tools/mitsuba/cornell_fog.py\n"
            "wavelength_nm,value\n"
        )
        for w, v in zip(wavelengths, values):
            f.write(f"{w:.0f},{str(np.float32(v))}\n")


def export_scene(mi, dr):
    mi.set_variant("scalar_spectral")
    wavelengths = [float(w) for w in range(360, 831)]
    sigma_t = evaluate(mi, dr, regular(SIGMA_T_PER_M), wavelengths)
    albedo = evaluate(mi, dr, regular(ALBEDO), wavelengths)
    # Mitsuba's HomogeneousMedium: sigma_s = albedo sigma_t, sigma_a = sigma_t - sigma_s.
    sigma_s = [t * a for t, a in zip(sigma_t, albedo)]
    sigma_a = [t - s for t, s in zip(sigma_t, sigma_s)]
    csv_dir = ROOT / "scenes" / CSV_DIR_REL
    csv_dir.mkdir(parents=True, exist_ok=True)
    write_csv(csv_dir / "sigma-a.csv", "sigma-a", "absorption coefficient", wavelengths, sigma_a,
              mi.__version__)
    write_csv(csv_dir / "sigma-s.csv", "sigma-s", "scattering coefficient", wavelengths, sigma_s,
              mi.__version__)

    scene = json.loads(BASE_SCENE.read_text())
    scene["film"]["resolution"] = [RESOLUTION, RESOLUTION]
    scene["integrator"]["max_depth"] = MITSUBA_MAX_DEPTH - 1
    scene["media"] = {
        "fog": {
            "type": "homogeneous",
            "sigma_a_per_m": f"{CSV_DIR_REL}/sigma-a.csv",
            "sigma_s_per_m": f"{CSV_DIR_REL}/sigma-s.csv",
            "phase": {"type": "hg", "g": HG_G},
        }
    }
    scene["materials"]["boundary"] = {"type": "interface"}
    scene["shapes"].append(
        {
            "type": "cuboid",
            "name": "fog-box",
            "size_m": [2, 2, 2],
            "transform": {"matrix": matrix_rows(mi.ScalarTransform4f().scale(CUBE_SCALE))},
            "material": "boundary",
            "interior_medium": "fog",
        }
    )
    SCENE.write_text(compact_json(scene) + "\n")
    print(f"wrote {SCENE.relative_to(ROOT)} and {CSV_DIR_REL}/sigma-{{a,s}}.csv", file=sys.stderr)


def render_reference(mi, dr, args):
    variant = args.variant
    if variant == "auto":
        variant = "llvm_ad_spectral" if has_llvm_variant(mi) else "scalar_spectral"
    mi.set_variant(variant)
    if args.threads:
        dr.set_thread_count(args.threads)
    threads = dr.thread_count()
    scene = mi.load_dict(mitsuba_dict(mi))
    passes = args.spp // args.pass_spp
    acc, render_s, t_start = None, 0.0, time.perf_counter()

    def write(done):
        img = (acc / done).astype(np.float32)
        mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(EXR))
        meta = {
            "generator": "tools/mitsuba/cornell_fog.py",
            "mitsuba_version": mi.__version__,
            "drjit_version": dr.__version__,
            "variant": variant,
            "libllvm": find_libllvm() if variant.startswith("llvm") else None,
            "scene": (
                f"mi.cornell_box() with film {RESOLUTION}x{RESOLUTION}, integrator "
                f"{{'type': 'volpathmis', 'max_depth': {MITSUBA_MAX_DEPTH}}} and shape 'fog-box': "
                f"{{'type': 'cube', 'to_world': T().scale({CUBE_SCALE}), 'bsdf': {{'type': 'null'}}, "
                f"'interior': {json.dumps(fog_medium())}}}"
            ),
            "spp": done * args.pass_spp,
            "spp_requested": args.spp,
            "complete": done == passes,
            "pass_spp": args.pass_spp,
            "seeds": [args.seed, args.seed + done - 1],
            "call": (
                "scene = mi.load_dict(d) (d as in 'scene'); image = mean over s in "
                f"range({args.seed}, {args.seed + done}) of "
                f"np.array(mi.render(scene, spp={args.pass_spp}, seed=s)); "
                "mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)"
                ".write(exr)"
            ),
            "threads": threads,
            "render_time_s": round(render_s, 3),
            "wall_time_s": round(time.perf_counter() - t_start, 3),
            "machine": f"{platform.machine()}, {os.cpu_count()} logical cores (shared), "
            f"load average at the end {os.getloadavg()[0]:.2f}",
            "output": {
                "file": str(EXR.relative_to(ROOT)),
                "channels": "R, G, B float32, linear sRGB; Mitsuba's film normalisation "
                "(values 1.0010003 x Prism's for the same radiance, see "
                "cornell_mitsuba_reference.json)",
                "mean_rgb": [float(x) for x in img.reshape(-1, 3).mean(0)],
            },
        }
        META.write_text(json.dumps(meta, indent=1) + "\n")

    for i in range(passes):
        t = time.perf_counter()
        img = np.array(mi.render(scene, spp=args.pass_spp, seed=args.seed + i), dtype=np.float64)
        render_s += time.perf_counter() - t
        acc = img if acc is None else acc + img
        print(f"pass {i + 1}/{passes}: render {render_s:.1f} s", file=sys.stderr, flush=True)
        if (i + 1) % args.checkpoint == 0 or i + 1 == passes:
            write(i + 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--pass-spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variant", default="auto")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--checkpoint", type=int, default=8)
    ap.add_argument("--scene-only", action="store_true", help="write the Prism scene and CSVs only")
    args = ap.parse_args()
    if args.spp % args.pass_spp:
        ap.error("--spp must be a multiple of --pass-spp")
    mi = import_mitsuba()
    import drjit as dr

    export_scene(mi, dr)
    if not args.scene_only:
        render_reference(mi, dr, args)


if __name__ == "__main__":
    main()

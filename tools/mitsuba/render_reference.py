#!/usr/bin/env python3
"""Renders Mitsuba 3's built-in Cornell box (`mitsuba.cornell_box()`, unchanged) at high spp:
the common reference of tools/bench-cornell.py.

Writes tests/fixtures/cornell_mitsuba_reference.exr (RGB float32, linear sRGB exactly as
Mitsuba writes it) and tests/fixtures/cornell_mitsuba_reference.json (version, variant, spp,
seeds, the exact call, wall time, and a check of Mitsuba's film normalisation).

The image is the mean of `spp / pass_spp` renders `mi.render(scene, spp=pass_spp, seed=s)`
with seeds s = seed, seed + 1, ... (LLVM variants hold a whole pass in memory, so one call at
4096 spp would need tens of GiB). A checkpoint (EXR + JSON with the spp done so far) is
written every `--checkpoint` passes, so an interrupted run still leaves a usable reference.

Run (about 15-30 min on 2 busy cores with llvm_ad_spectral):
  nice tools/mitsuba/.venv/bin/python tools/mitsuba/render_reference.py --spp 4096
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

EXR = ROOT / "tests" / "fixtures" / "cornell_mitsuba_reference.exr"
META = ROOT / "tests" / "fixtures" / "cornell_mitsuba_reference.json"


def film_convention_check(mi, dr, spp=1024, res=32):
    """Renders a constant environment of flat spectral radiance 1 and returns the mean XYZ
    of the image (through the inverse of Mitsuba's XYZ -> sRGB matrix). With the convention
    Y = int L ybar dl / int ybar dl this would be 1; Mitsuba multiplies by
    MI_CIE_Y_NORMALIZATION = 1 / 106.7502594 while int ybar dl = 106.857 over 360-830 nm."""
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path"},
            "env": {"type": "constant", "radiance": {"type": "uniform", "value": 1.0}},
            "sensor": {
                "type": "perspective",
                "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent"},
            },
        }
    )
    rgb = np.array(mi.render(scene, spp=spp, seed=12345), dtype=np.float64).reshape(-1, 3).mean(0)
    m = np.array([np.array(mi.xyz_to_srgb(mi.ScalarColor3f(*e))).reshape(3) for e in np.eye(3)]).T
    xyz = np.linalg.solve(m, rgb)
    return {
        "scene": "constant environment, radiance {'type': 'uniform', 'value': 1.0}, "
        f"{res}x{res} px, {spp} spp, box filter",
        "mean_rgb": rgb.tolist(),
        "mean_xyz": xyz.tolist(),
        "expected_Y_if_normalised_by_int_ybar": 1.0,
        "expected_Y_with_MI_CIE_Y_NORMALIZATION": 106.85702933647141 * mi.MI_CIE_Y_NORMALIZATION,
        "xyz_to_srgb_matrix": m.tolist(),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--pass-spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0, help="seed of the first pass")
    ap.add_argument("--variant", default="auto", help="auto: llvm_ad_spectral if it runs, else scalar_spectral")
    ap.add_argument("--threads", type=int, default=0, help="0: all cores")
    ap.add_argument("--checkpoint", type=int, default=8, help="write the image every N passes")
    ap.add_argument("--exr", type=pathlib.Path, default=EXR)
    ap.add_argument("--json", type=pathlib.Path, default=META)
    args = ap.parse_args()
    if args.spp % args.pass_spp:
        ap.error("--spp must be a multiple of --pass-spp")

    mi = import_mitsuba()
    import drjit as dr

    variant = args.variant
    if variant == "auto":
        variant = "llvm_ad_spectral" if has_llvm_variant(mi) else "scalar_spectral"
    mi.set_variant(variant)
    if args.threads:
        dr.set_thread_count(args.threads)
    threads = dr.thread_count()

    t_start = time.perf_counter()
    convention = film_convention_check(mi, dr)
    print(f"film convention check: mean XYZ {convention['mean_xyz']}", file=sys.stderr)

    scene = mi.load_dict(mi.cornell_box())
    passes = args.spp // args.pass_spp
    acc = None
    render_s = 0.0
    done = 0

    def write(done_passes):
        img = (acc / done_passes).astype(np.float32)
        args.exr.parent.mkdir(parents=True, exist_ok=True)
        mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(args.exr))
        seeds = list(range(args.seed, args.seed + done_passes))
        meta = {
            "generator": "tools/mitsuba/render_reference.py",
            "mitsuba_version": mi.__version__,
            "drjit_version": dr.__version__,
            "variant": variant,
            "libllvm": find_libllvm() if variant.startswith("llvm") else None,
            "scene": "mi.cornell_box() unchanged (256x256, gaussian rfilter stddev 0.5 radius 2, "
            "path max_depth 8 rr_depth 5, independent sampler)",
            "spp": done_passes * args.pass_spp,
            "spp_requested": args.spp,
            "complete": done_passes == passes,
            "pass_spp": args.pass_spp,
            "passes": done_passes,
            "seeds": [seeds[0], seeds[-1]],
            "call": (
                "scene = mi.load_dict(mi.cornell_box()); image = mean over s in "
                f"range({args.seed}, {args.seed + done_passes}) of "
                f"np.array(mi.render(scene, spp={args.pass_spp}, seed=s)); "
                "mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)"
                ".write(exr)"
            ),
            "threads": threads,
            "render_time_s": round(render_s, 3),
            "wall_time_s": round(time.perf_counter() - t_start, 3),
            "seconds_per_spp": round(render_s / (done_passes * args.pass_spp), 4),
            "machine": f"{platform.machine()}, {os.cpu_count()} logical cores (shared), "
            f"load average at the end {os.getloadavg()[0]:.2f}",
            "output": {
                "file": str(args.exr.relative_to(ROOT)) if args.exr.is_relative_to(ROOT) else str(args.exr),
                "channels": "R, G, B float32, linear sRGB (Rec.709 primaries, D65 white)",
                "convention": (
                    "RGB = Mitsuba's XYZ -> linear sRGB matrix applied to "
                    "XYZ = MI_CIE_Y_NORMALIZATION * int L(lambda) (xbar, ybar, zbar) dlambda over "
                    "360-830 nm (CIE 1931 2 deg), MI_CIE_Y_NORMALIZATION = 1/106.7502594. Prism "
                    "divides by int ybar dlambda = 106.857 instead, so for the same spectral "
                    "radiance Mitsuba's values are 106.857/106.7502594 = 1.0010003 times Prism's."
                ),
                "mean_rgb": [float(x) for x in img.reshape(-1, 3).mean(0)],
            },
            "film_convention_check": convention,
        }
        args.json.write_text(json.dumps(meta, indent=1) + "\n")

    for i in range(passes):
        t = time.perf_counter()
        img = mi.render(scene, spp=args.pass_spp, seed=args.seed + i)
        img = np.array(img, dtype=np.float64)
        render_s += time.perf_counter() - t
        acc = img if acc is None else acc + img
        done = i + 1
        print(
            f"pass {done}/{passes}: {done * args.pass_spp} spp, render {render_s:.1f} s",
            file=sys.stderr,
            flush=True,
        )
        if done % args.checkpoint == 0 or done == passes:
            write(done)
    print(f"wrote {args.exr} and {args.json}")


if __name__ == "__main__":
    main()

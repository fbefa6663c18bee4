#!/usr/bin/env python3
"""How much a predicted plan's allocation alone can gain (docs/bandwidth.md, "The variance
the allocation follows"): the expected relMSE ratio uniform ÷ plan,

    Σ v_p / Σ (v_p / a_p),

where v_p is pixel p's relative variance per camera sample (R, G and B summed, relMSE's
weighting 1/(mean² + 0.01)) from `--renders` independent uniform renders, and a_p the plan's
`plan.spp` over its mean. The uniform renders are shared by every plan variant, so the
variants compare by their allocation alone, without the noise of a converge run.

The oracle (a_p from the measured v_p itself) is scored honestly: fitted to one half of the
renders and scored on the other. Fitted and scored on the same renders it is rewarded for
the noise it fitted, which on scenes whose relative variance sits in a few pixels that move
from render to render (fireflies) is most of its apparent gain; both are reported, with
the share of v in the top 1 % of pixels and each plan's ratio on either half.

    bash tools/mitsuba/setup.sh    # numpy and OpenEXR
    cargo build --release
    tools/mitsuba/.venv/bin/python tools/bench_plan_allocation.py [--renders 20] [--spp 64]
        [--variant "--plan-variance eq9"] [--resolution WxH] [--no-file]
    (--scenes takes the names below or scene files, e.g. scenes/cornell-box-fog.json, at
    64x64 unless --resolution says otherwise)

Each `--variant` is extra `prism render --plan predicted` arguments ("" is the default plan,
always included). Prints JSON and writes tools/bench-results/plan-allocation.json
(`bench_results.write`).
"""

import argparse
import atexit
import os
import shlex
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import OpenEXR

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_results  # noqa: E402

ROOT = bench_results.ROOT
PRISM = os.path.join(ROOT, "target", "release", "prism")
SCENES = {
    "fig9-spheres": ("scenes/bandwidth/fig9-spheres.json", "64x64"),
    "fig17-curved-area": ("scenes/bandwidth/fig17-curved-area.json", "64x64"),
    "glossy-env": ("scenes/glossy-env.json", "64x36"),
}
RELMSE_EPSILON = 1e-2


def scaled_resolution(own, requested):
    """`requested` (WxH) for a square scene; for another aspect ratio the scene's own at width
    W, so that --resolution does not stretch glossy-env's 16:9 frame into a square."""
    if requested is None:
        return own
    try:
        w, h = (int(x) for x in requested.lower().split("x"))
        ow, oh = (int(x) for x in own.lower().split("x"))
    except ValueError:
        raise SystemExit(f"--resolution {requested!r}: expected WIDTHxHEIGHT, e.g. 128x128")
    if ow == oh:
        return f"{w}x{h}"
    return f"{w}x{max(1, round(w * oh / ow))}"


def channel(path, name):
    """One channel, or for "RGB" the colour as height × width × 3 (OpenEXR 3 groups R, G, B
    into one "RGB" channel)."""
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if name == "RGB" and "RGB" not in ch and all(c in ch for c in "RGB"):
            return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)
        if name not in ch:
            raise SystemExit(f"{path}: no channel {name} (has {sorted(ch)})")
        return np.asarray(ch[name].pixels, dtype=np.float64)


def render(scene, resolution, spp, seed, out, extra):
    command = [PRISM, "render", scene, "--spp", str(spp), "--seed", str(seed),
               "--resolution", resolution, "--threads", "2", "-o", out] + extra
    subprocess.run(command, cwd=ROOT, check=True, capture_output=True)


def uniform_renders(scene, resolution, renders, spp, work):
    images = []
    for k in range(renders):
        out = os.path.join(work, f"uniform-{k}.exr")
        render(scene, resolution, spp, 100 + k, out, [])
        images.append(channel(out, "RGB"))
    return np.array(images)


def relative_variance(images, spp, mean):
    """Per pixel, the relative variance per camera sample (R, G and B summed) of `images`,
    weighted by relMSE's 1/(mean² + ε) with the mean of all renders."""
    per_sample = images.var(axis=0, ddof=1) * spp
    return (per_sample / (mean ** 2 + RELMSE_EPSILON)).sum(axis=-1)


def expected_ratio(v, share):
    return float(v.sum() / (v / share).sum()) if (share > 0).all() else None


def oracle_share(v, floor=0.25):
    """The relative-error allocation fed the measured v: a_p = f + (1 − f)·√v_p/mean."""
    s = np.sqrt(v)
    return floor + (1.0 - floor) * s / s.mean()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--renders", type=int, default=20)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--variant", action="append", default=[])
    parser.add_argument("--resolution", default=None,
                        help="WxH for the square scenes; a scene of another aspect ratio in "
                             "SCENES keeps it at width W (default: each scene's own)")
    parser.add_argument("--no-file", action="store_true")
    opts = parser.parse_args()
    if opts.renders < 4:
        raise SystemExit("--renders must be at least 4 (two halves of two)")
    variants = [""] + [v for v in opts.variant if v != ""]
    work = tempfile.mkdtemp(prefix="prism-plan-allocation-")
    atexit.register(shutil.rmtree, work, ignore_errors=True)
    results = {}
    for name in opts.scenes.split(","):
        if name in SCENES:
            scene, resolution = SCENES[name]
        elif name.endswith(".json") and os.path.exists(os.path.join(ROOT, name)):
            scene, resolution = name, "64x64"
        else:
            raise SystemExit(f"--scenes: unknown scene {name!r} (known: {', '.join(SCENES)}, "
                             "or a scene file's path from the repository root)")
        resolution = scaled_resolution(resolution, opts.resolution)
        images = uniform_renders(scene, resolution, opts.renders, opts.spp, work)
        mean = images.mean(axis=0)
        v = relative_variance(images, opts.spp, mean)
        # Two halves of the renders: an oracle fitted to one half and scored on the other
        # (and on its own half, which rewards it for the noise it fitted).
        half = opts.renders // 2
        first = relative_variance(images[:half], opts.spp, mean)
        second = relative_variance(images[half:], opts.spp, mean)
        results[name] = {
            "scene": scene,
            "resolution": resolution,
            "oracle_from_half_scored_on_the_other": [
                expected_ratio(second, oracle_share(first)),
                expected_ratio(first, oracle_share(second))],
            "oracle_from_half_scored_on_the_same": [
                expected_ratio(first, oracle_share(first)),
                expected_ratio(second, oracle_share(second))],
            "relative_variance_share_of_the_top_1_percent_pixels": [
                float(np.sort(x.ravel())[-max(1, x.size // 100):].sum() / x.sum())
                for x in (first, second)],
        }
        for variant in variants:
            out = os.path.join(work, "plan.exr")
            render(scene, resolution, opts.spp, 3, out,
                   ["--plan", "predicted"] + shlex.split(variant))
            spp = channel(out, "plan.spp")
            share = spp / spp.mean()
            results[name][variant or "default"] = {
                "expected_relmse_ratio_uniform_over_plan": expected_ratio(v, share),
                "on_each_half": [expected_ratio(first, share), expected_ratio(second, share)],
                "pixels_without_samples": int((share <= 0).sum()),
            }
    result = {
        "command": "tools/bench_plan_allocation.py " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
        "renders": opts.renders,
        "spp": opts.spp,
        "machine": bench_results.machine(),
        "scenes": results,
    }
    bench_results.publish("plan-allocation", result, not opts.no_file)

if __name__ == "__main__":
    main()

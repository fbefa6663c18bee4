#!/usr/bin/env python3
"""How much a predicted plan's allocation alone can gain (docs/bandwidth.md, "The variance
the allocation follows"): the expected relMSE ratio uniform ÷ plan,

    Σ v_p / Σ (v_p / a_p),

where v_p is pixel p's relative variance per camera sample (R, G and B summed, relMSE's
weighting 1/(mean² + 0.01)) from `--renders` independent uniform renders, and a_p the plan's
`plan.spp` over its mean. The uniform renders are shared by every plan variant, so the
variants compare by their allocation alone, without the noise of a converge run.

    bash tools/mitsuba/setup.sh    # numpy and OpenEXR
    cargo build --release
    tools/mitsuba/.venv/bin/python tools/bench_plan_allocation.py [--renders 20] [--spp 64]
        [--variant "--plan-variance eq9"] [--no-file]

Each `--variant` is extra `prism render --plan predicted` arguments ("" is the default plan,
always included). Prints JSON and writes tools/bench-results/plan-allocation.json
(`bench_results.write`).
"""

import argparse
import json
import os
import platform
import shlex
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


def relative_variance(scene, resolution, renders, spp, work):
    images = []
    for k in range(renders):
        out = os.path.join(work, f"uniform-{k}.exr")
        render(scene, resolution, spp, 100 + k, out, [])
        images.append(channel(out, "RGB"))
    images = np.array(images)
    mean = images.mean(axis=0)
    per_sample = images.var(axis=0, ddof=1) * spp
    return (per_sample / (mean ** 2 + RELMSE_EPSILON)).sum(axis=-1)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--renders", type=int, default=20)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--variant", action="append", default=[])
    parser.add_argument("--no-file", action="store_true")
    opts = parser.parse_args()
    if opts.renders < 2:
        raise SystemExit("--renders must be at least 2")
    variants = [""] + [v for v in opts.variant if v != ""]
    work = tempfile.mkdtemp(prefix="prism-plan-allocation-")
    results = {}
    for name in opts.scenes.split(","):
        if name not in SCENES:
            raise SystemExit(f"--scenes: unknown scene {name!r} (known: {', '.join(SCENES)})")
        scene, resolution = SCENES[name]
        v = relative_variance(scene, resolution, opts.renders, opts.spp, work)
        results[name] = {"scene": scene, "resolution": resolution}
        for variant in variants:
            out = os.path.join(work, "plan.exr")
            render(scene, resolution, opts.spp, 3, out,
                   ["--plan", "predicted"] + shlex.split(variant))
            spp = channel(out, "plan.spp")
            share = spp / spp.mean()
            ratio = float(v.sum() / (v / share).sum()) if (share > 0).all() else None
            results[name][variant or "default"] = {
                "expected_relmse_ratio_uniform_over_plan": ratio,
                "pixels_without_samples": int((share <= 0).sum()),
            }
    result = {
        "command": "tools/bench_plan_allocation.py " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
        "renders": opts.renders,
        "spp": opts.spp,
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average_1min_at_end": os.getloadavg()[0]},
        "scenes": results,
    }
    if opts.no_file:
        print(json.dumps(result, indent=1))
    else:
        bench_results.write("plan-allocation", result)

if __name__ == "__main__":
    main()

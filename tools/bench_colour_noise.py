#!/usr/bin/env python3
"""Does the colour-noise term of V̂_p pay in ΔE2000? (docs/bandwidth.md, "Colour noise")

On a scene lit through spiky spectra (default scenes/stress/spiky-spectrum.json), renders
alternately, seed by seed, the uniform plan, the predicted plan with the colour term
(`--plan-colour on`, the default) and without it (`--plan-colour off`, luminance only), all at
the same mean spp, and measures each against one high-spp uniform reference with
`prism compare --json` (CIEDE2000 mean, relMSE). The CPU time is the whole `prism render`
process's (user + system, predictor included), so "ΔE2000 at equal time" is ΔE · √(t / t_off):
mean ΔE falls as 1/√spp, and at equal CPU time a plan that costs t/t_off as much would have had
t_off/t as many samples.

    cargo build --release
    python3 tools/bench_colour_noise.py [--scene S] [--spp 32] [--seeds 8]
        [--reference-spp 4096] [--no-file]

Prints JSON and writes tools/bench-results/colour-noise.json (`bench_results.write`).
"""

import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_results  # noqa: E402

ROOT = bench_results.ROOT
PRISM = os.path.join(ROOT, "target", "release", "prism")
PLANS = {
    "uniform": [],
    "predicted, colour on": ["--plan", "predicted", "--plan-colour", "on"],
    "predicted, colour off": ["--plan", "predicted", "--plan-colour", "off"],
}


def render(scene, spp, seed, out, extra):
    """CPU seconds (user + system) of one whole `prism render` process."""
    command = [PRISM, "render", scene, "--spp", str(spp), "--seed", str(seed),
               "--threads", "2", "-o", out] + extra
    proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    stderr = proc.stderr.read().decode()
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(command)} failed:\n{stderr}")
    return usage.ru_utime + usage.ru_stime


def compare(image, reference):
    out = subprocess.run([PRISM, "compare", image, reference, "--json"], cwd=ROOT,
                         check=True, capture_output=True, text=True).stdout
    metrics = json.loads(out)
    return metrics["delta_e2000_mean"], metrics["relmse"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scene", default="scenes/stress/spiky-spectrum.json")
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--no-file", action="store_true")
    opts = parser.parse_args()
    if opts.seeds < 2:
        raise SystemExit("--seeds must be at least 2")
    work = tempfile.mkdtemp(prefix="prism-colour-noise-")
    reference = os.path.join(work, "reference.exr")
    render(opts.scene, opts.reference_spp, 999, reference, [])
    rows = {name: {"delta_e2000_mean": [], "relmse": [], "cpu_s": []} for name in PLANS}
    for seed in range(1, opts.seeds + 1):
        for name, extra in PLANS.items():
            out = os.path.join(work, "image.exr")
            cpu_s = render(opts.scene, opts.spp, seed, out, extra)
            delta_e, relmse = compare(out, reference)
            rows[name]["delta_e2000_mean"].append(delta_e)
            rows[name]["relmse"].append(relmse)
            rows[name]["cpu_s"].append(cpu_s)
    off = rows["predicted, colour off"]
    t_off = statistics.median(off["cpu_s"])
    de_off = statistics.mean(off["delta_e2000_mean"])
    summary = {}
    for name, row in rows.items():
        de = row["delta_e2000_mean"]
        t = statistics.median(row["cpu_s"])
        summary[name] = {
            "delta_e2000_mean": statistics.mean(de),
            "delta_e2000_standard_error": statistics.stdev(de) / len(de) ** 0.5,
            "relmse_mean": statistics.mean(row["relmse"]),
            "cpu_s_median": t,
            "delta_e2000_at_equal_cpu_over_colour_off":
                statistics.mean(de) * (t / t_off) ** 0.5 / de_off,
            "per_seed": row,
        }
    # Paired by seed: the same seed's renders share the uniform floor's samples.
    on = rows["predicted, colour on"]["delta_e2000_mean"]
    differences = [a - b for a, b in zip(on, off["delta_e2000_mean"])]
    result = {
        "command": "tools/bench_colour_noise.py "
                   + " ".join(shlex.quote(a) for a in sys.argv[1:]),
        "scene": opts.scene,
        "spp": opts.spp,
        "seeds": opts.seeds,
        "reference_spp": opts.reference_spp,
        "machine": bench_results.machine(),
        "plans": summary,
        "colour_on_minus_off_delta_e2000": {
            "mean": statistics.mean(differences),
            "standard_error": statistics.stdev(differences) / len(differences) ** 0.5,
        },
    }
    bench_results.publish("colour-noise", result, not opts.no_file)


if __name__ == "__main__":
    main()

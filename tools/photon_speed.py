#!/usr/bin/env python3
"""The photon speed target of issue 20: on scenes/stress/spot-fog-glass.json at 128×128,
the render CPU time `photon_progressive` and `path` need to reach relMSE 0.05 (median of
three `prism converge --clock cpu` runs with different seeds), against a reference rendered
by `photon_progressive` at about 25× the budget's passes (`prism render --spp 1024`).

    python3 tools/photon_speed.py --prism target/release/prism        # renders and runs
    python3 tools/photon_speed.py --no-run                            # summarise the JSON

Writes the runs to tools/bench-results/photon-speed/run-N.json and the summary to
tools/bench-results/photon-speed.json. Standard library only.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tools", "bench-results", "photon-speed")
TARGET = 0.05


def first_crossing(checkpoints, target):
    """CPU time at which relMSE first falls to `target` (log–log interpolation)."""
    pts = [(c["cpu_time_s"], c["relmse"]) for c in checkpoints if c.get("cpu_time_s")]
    if pts and pts[0][1] <= target:
        return pts[0][0]
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 > target >= e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def extrapolated(checkpoints, target):
    """Where the last two checkpoints' power law reaches `target`."""
    (t0, e0), (t1, e1) = [(c["cpu_time_s"], c["relmse"]) for c in checkpoints[-2:]]
    slope = math.log(e1 / e0) / math.log(t1 / t0)
    if slope >= 0:
        return None
    return t1 * (target / e1) ** (1.0 / slope)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prism", default=os.path.join(ROOT, "target", "release", "prism"))
    ap.add_argument("--budget-s", type=float, default=40.0)
    ap.add_argument("--no-run", action="store_true")
    args = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    scene = os.path.join(ROOT, "scenes", "stress", "spot-fog-glass.json")
    if not args.no_run:
        with open(scene) as f:
            description = json.load(f)
        description["integrator"] = {"type": "photon_progressive", "max_depth": 8}
        ref_scene = os.path.join(OUT, "spot-fog-glass-photon.json")
        with open(ref_scene, "w") as f:
            json.dump(description, f)
        reference = os.path.join(OUT, "reference.exr")
        subprocess.run([args.prism, "render", ref_scene, "--resolution", "128x128", "--spp",
                        "1024", "--seed", "99", "-o", reference], check=True, cwd=ROOT)
        for i in (1, 2, 3):
            subprocess.run([args.prism, "converge", scene, "--reference", reference,
                            "--resolution", "128x128", "--method", "path", "--method",
                            "photon_progressive", "--budget-s", str(args.budget_s),
                            "--checkpoints", "12", "--clock", "cpu", "--seed",
                            str(i * 1000 + 7), "--json", os.path.join(OUT, f"run-{i}.json")],
                           check=True, cwd=ROOT)
    runs = []
    for i in (1, 2, 3):
        with open(os.path.join(OUT, f"run-{i}.json")) as f:
            runs.append(json.load(f))
    summary = {"scene": "scenes/stress/spot-fog-glass.json", "resolution": [128, 128],
               "target_relmse": TARGET, "clock": "cpu", "methods": {}}
    for name in ("path", "photon_progressive"):
        crossings, extrapolations, finals = [], [], []
        for run in runs:
            m = next(m for m in run["methods"] if m["method"] == name)
            crossings.append(first_crossing(m["checkpoints"], TARGET))
            extrapolations.append(extrapolated(m["checkpoints"], TARGET))
            finals.append((m["checkpoints"][-1]["cpu_time_s"], m["checkpoints"][-1]["relmse"]))
        reached = [c for c in crossings if c is not None]
        summary["methods"][name] = {
            "first_crossing_cpu_s": crossings,
            "median_first_crossing_cpu_s": (statistics.median(reached)
                                            if len(reached) == len(crossings) else None),
            "extrapolated_cpu_s": extrapolations,
            "median_extrapolated_cpu_s": statistics.median(
                [e if c is None else c for c, e in zip(crossings, extrapolations)]),
            "final_cpu_s_and_relmse": finals,
        }
    p, pp = summary["methods"]["path"], summary["methods"]["photon_progressive"]
    summary["speedup_lower_bound"] = (min(f[0] for f in p["final_cpu_s_and_relmse"])
                                      / pp["median_first_crossing_cpu_s"]
                                      if p["median_first_crossing_cpu_s"] is None
                                      else p["median_first_crossing_cpu_s"]
                                      / pp["median_first_crossing_cpu_s"])
    summary["speedup_extrapolated"] = (p["median_extrapolated_cpu_s"]
                                       / pp["median_first_crossing_cpu_s"])
    with open(os.path.join(ROOT, "tools", "bench-results", "photon-speed.json"), "w") as f:
        json.dump(summary, f, indent=1)
    json.dump(summary, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()

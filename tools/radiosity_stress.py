#!/usr/bin/env python3
"""Where radiosity is wrong: `prism converge --method path --method radiosity` on the
stress scenes radiosity accepts and on the Cornell box, each against a `path` reference
(Owen-scrambled Sobol, --reference-spp, rendered and cached by converge itself), at 64 x 64
with the same CPU-time budget per method. Radiosity's relMSE stops falling where its
solution's error dominates: that floor, and the time `path` needs to reach it, say where
the view-independent solution pays and where it is wrong. The stress scenes radiosity
refuses are listed with the reason its error gives. Prints JSON and writes
tools/bench-results/radiosity-stress.json.

Usage: python3 tools/radiosity_stress.py [--prism target/release/prism] [--budget-s 5]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bench_results  # noqa: E402


def scene_with_radiosity(path):
    """The scene as JSON with a `radiosity` integrator, written next to it (so that its
    relative file names resolve); the temporary file's path."""
    description = json.load(open(path))
    description["integrator"] = {"type": "radiosity"}
    tmp = os.path.join(os.path.dirname(path), "." + os.path.basename(path) + ".radiosity.json")
    json.dump(description, open(tmp, "w"))
    return tmp


def refusal(prism, scene):
    """The error `prism render` gives for the scene under `radiosity`, or None."""
    tmp = scene_with_radiosity(scene)
    try:
        with tempfile.TemporaryDirectory() as d:
            p = subprocess.run([prism, "render", tmp, "--resolution", "4x4", "--spp", "1",
                                "-o", os.path.join(d, "x.exr")], capture_output=True, text=True)
    finally:
        os.remove(tmp)
    if p.returncode == 0:
        return None
    text = p.stderr.strip().splitlines()[-1]
    return text.split("integrator: ", 1)[-1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prism", default=os.path.join(ROOT, "target/release/prism"))
    ap.add_argument("--budget-s", type=float, default=5.0)
    ap.add_argument("--reference-spp", type=int, default=1024)
    args = ap.parse_args()
    stress = sorted(f for f in os.listdir(os.path.join(ROOT, "scenes/stress")) if f.endswith(".json") and not f.startswith("."))
    scenes = [os.path.join(ROOT, "scenes/cornell-box.json")] + [
        os.path.join(ROOT, "scenes/stress", f) for f in stress]
    rows, refused = [], {}
    with tempfile.TemporaryDirectory() as d:
        for scene in scenes:
            name = os.path.basename(scene)[:-5]
            why = refusal(args.prism, scene)
            if why:
                refused[name] = why
                continue
            out = os.path.join(d, name + ".json")
            cmd = [args.prism, "converge", scene, "--method", "path", "--method", "radiosity",
                   "--budget-s", str(args.budget_s), "--clock", "cpu", "--resolution", "64x64",
                   "--reference-spp", str(args.reference_spp), "--cache-dir",
                   os.path.join(d, "cache"), "--json", out]
            print("+", " ".join(cmd), file=sys.stderr, flush=True)
            subprocess.run(cmd, check=True, capture_output=True)
            data = json.load(open(out))
            row = {"scene": name}
            for m in data["methods"]:
                last = m["checkpoints"][-1]
                row[m["method"]] = {
                    "relmse": last["relmse"],
                    "cpu_time_s": round(last["cpu_time_s"], 3),
                    "spp": last["spp"],
                    "relmse_slope": m.get("relmse_slope"),
                }
            path_points = next(m for m in data["methods"] if m["method"] == "path")["checkpoints"]
            floor = row["radiosity"]["relmse"]
            reach = next((c["cpu_time_s"] for c in path_points if c["relmse"] <= floor), None)
            row["path_cpu_s_to_radiosity_error"] = None if reach is None else round(reach, 3)
            rows.append(row)
    result = {
        "benchmark": "radiosity-stress",
        "command": "python3 tools/radiosity_stress.py --budget-s %g --reference-spp %d"
        % (args.budget_s, args.reference_spp),
        "resolution": "64x64",
        "reference": "path, Owen-scrambled Sobol, %d spp (prism converge)" % args.reference_spp,
        "load_average_1min": os.getloadavg()[0],
        "scenes": rows,
        "refused": refused,
    }
    bench_results.write("radiosity-stress", result)


if __name__ == "__main__":
    main()

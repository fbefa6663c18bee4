#!/usr/bin/env python3
"""The bandwidth predictor's benchmark (docs/bandwidth.md): one `prism converge --clock cpu`
run per scene with path, path+adaptive, path+predicted, path+predicted-hier and path+oracle
on one sampler, and the numbers the predictor issue asks for, from each run's `ratios`
block, for each of the two predicted plans:

- time to relMSE 1e-2: path ÷ the plan (speed-up; > 1 means the predictor helps);
- relMSE at equal CPU time: path+adaptive ÷ the plan at each of path's checkpoints
  from 4 spp on (> 1 means the predictor beats the variance-driven adaptive sampler);
- predict_cpu_s and its share of the plan's time to relMSE 1e-2;
- the share of the oracle's gain it captures: log(path ÷ plan) / log(path ÷ oracle) in time
  to relMSE 1e-2, where path+oracle is the same allocation fed with the measured
  `variance.Y` of a separate `--oracle-spp` uniform render (another seed than the
  reference's, so that the oracle does not know the reference's own noise).

    cargo build --release
    python3 tools/bench_bandwidth.py [--budget-s 20] [--reference-spp 2048] [--scenes a,b]
        [--seed 1] [--oracle-spp 512]

The paper's Fig. 9 spheres are measured materials: the benchmark renders
scenes/bandwidth/fig9-spheres.json with its three conductors replaced by MERL tables
`merl-export`ed from them (scenes/bandwidth/merl-sources.json; written to scenes/merl/ when
missing, 33 MB each, not committed), so that the predictor's MERL path is what runs. The
committed scene keeps the analytic materials, so that it builds on a clean checkout.
Writes tools/bench-results/bandwidth.json (per-scene converge JSON inside;
`bench_results.write`).
"""

import argparse
import atexit
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_results  # noqa: E402

ROOT = bench_results.ROOT
PRISM = os.path.join(ROOT, "target", "release", "prism")
SCENES = {
    "fig9-spheres": ("MERL", None),
    "fig17-curved-area": ("scenes/bandwidth/fig17-curved-area.json", None),
    "glossy-env": ("scenes/glossy-env.json", "160x90"),
}
MERL = ["gold-ggx", "sharp-copper", "rough-nickel"]
# fig9-spheres.json's material → the MERL table that replaces it.
MERL_FOR = {"gold": "gold-ggx", "copper": "sharp-copper", "nickel": "rough-nickel"}
METHODS = ["path", "path+adaptive", "path+predicted", "path+predicted-hier", "path+oracle"]
ORACLE_SEED = 4242
PREDICTED = ["path+predicted", "path+predicted-hier"]


def ensure_merl():
    for name in MERL:
        out = os.path.join(ROOT, "scenes", "merl", f"{name}.binary")
        if not os.path.exists(out):
            subprocess.run([PRISM, "merl-export", "scenes/bandwidth/merl-sources.json",
                            "--material", name, "-o", out], cwd=ROOT, check=True)


def merl_scene(work):
    """fig9-spheres.json with its conductors replaced by their MERL tables, written into
    `work` with absolute paths."""
    with open(os.path.join(ROOT, "scenes", "bandwidth", "fig9-spheres.json")) as f:
        scene = json.load(f)
    for material, table in MERL_FOR.items():
        scene["materials"][material] = {
            "type": "merl", "file": os.path.join(ROOT, "scenes", "merl", f"{table}.binary")}
    for light in scene["lights"]:
        if "file" in light:
            light["file"] = os.path.join(ROOT, "scenes", "bandwidth", light["file"])
    path = os.path.join(work, "fig9-spheres-merl.json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=2)
    return path


def summarise_plan(methods, name, clock):
    """One predicted method's rows: time to relMSE 1e-2 against path, relMSE against
    adaptive at equal CPU time (path's checkpoints from 4 spp on), the predictor's cost."""
    predicted, adaptive = methods[name], methods["path+adaptive"]
    time_to = {row["relmse"]: row for row in predicted["ratios"]["time_to_relmse"]}
    ahead = {row["time_s"]: row["ratio"] for row in predicted["ratios"]["relmse_at_equal_time"]}
    path_checkpoints = {c["time_s"] if clock == "wall" else c["cpu_time_s"]: c["spp"]
                        for c in methods["path"]["checkpoints"]}
    adaptive_vs_predicted = []
    for row in adaptive["ratios"]["relmse_at_equal_time"]:
        t = row["time_s"]
        if t in ahead and path_checkpoints.get(t, 0) >= 4:
            # (path ÷ predicted) ÷ (path ÷ adaptive) = adaptive ÷ predicted.
            adaptive_vs_predicted.append({"time_s": t, "path_spp": path_checkpoints[t],
                                          "ratio": ahead[t] / row["ratio"]})
    target = time_to.get(0.01, {})
    oracle = {row["relmse"]: row for row in methods["path+oracle"]["ratios"]["time_to_relmse"]}
    oracle_speedup = oracle.get(0.01, {}).get("speedup")
    speedup = target.get("speedup")
    share = None
    if speedup and oracle_speedup and oracle_speedup > 1.0:
        share = math.log(speedup) / math.log(oracle_speedup)
    return {
        "time_to_relmse_1e-2_path_over_this": target.get("speedup"),
        "time_to_relmse_1e-2_s": {"path": target.get("against_s"), name: target.get("this_s")},
        "relmse_adaptive_over_this_at_equal_cpu": adaptive_vs_predicted,
        "predict_cpu_s": predicted["predict_cpu_s"],
        "tables_cpu_s": predicted["tables_cpu_s"],
        "predict_cpu_fraction_of_time_to_target":
            predicted["predict_cpu_fraction_of_time_to_target"],
        "time_to_relmse_1e-2_path_over_oracle": oracle_speedup,
        "share_of_oracle_gain_captured": share,
    }


def summarise(data):
    methods = {m["method"]: m for m in data["methods"]}
    out = {name: summarise_plan(methods, name, data["clock"]) for name in PREDICTED}
    out["final_relmse"] = {m: methods[m]["final"]["relmse"] for m in METHODS}
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--budget-s", type=float, default=20.0)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--no-file", action="store_true")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--oracle-spp", type=int, default=512)
    opts = parser.parse_args()
    ensure_merl()
    work = tempfile.mkdtemp(prefix="prism-bandwidth-")
    atexit.register(shutil.rmtree, work, ignore_errors=True)
    results = {}
    for name in opts.scenes.split(","):
        scene, resolution = SCENES[name]
        if scene == "MERL":
            scene = merl_scene(work)
        oracle = os.path.join(work, f"{name}-oracle.exr")
        render = [PRISM, "render", scene, "--spp", str(opts.oracle_spp), "--seed",
                  str(ORACLE_SEED), "-o", oracle]
        if resolution:
            render += ["--resolution", resolution]
        subprocess.run(render, cwd=ROOT, check=True, capture_output=True)
        out = os.path.join(work, f"{name}.json")
        command = [PRISM, "converge", scene, "--clock", "cpu", "--budget-s",
                   str(opts.budget_s), "--reference-spp", str(opts.reference_spp),
                   "--seed", str(opts.seed), "--oracle-variance", oracle, "--json", out]
        for m in METHODS:
            command += ["--method", m]
        if resolution:
            command += ["--resolution", resolution]
        subprocess.run(command, cwd=ROOT, check=True)
        with open(out) as f:
            data = json.load(f)
        results[name] = {"command": " ".join(command[1:]), "summary": summarise(data),
                         "converge": data}
        print(name, json.dumps(results[name]["summary"], indent=2), flush=True)
    result = {
        "command": "python3 tools/bench_bandwidth.py " + " ".join(sys.argv[1:]),
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average_1min_at_end": os.getloadavg()[0]},
        "scenes": results,
    }
    if opts.no_file:
        print(json.dumps(result["machine"]))
    else:
        bench_results.write("bandwidth", result)
    return 0


if __name__ == "__main__":
    sys.exit(main())

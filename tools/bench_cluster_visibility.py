#!/usr/bin/env python3
"""Radiosity's far clusters (software Z-buffer, docs/radiosity.md "Cluster visibility")
against `path` at the sensors of scenes/radiosity/crate-hall.json: a 20 x 6 x 4 m hall of
24 crates under three ceiling lamps, where most cluster links are far. Solves it at each
`--bound` with `prism render --sensors-only`, measures the same sensors by `path`
(max_depth 64, `--reference-samples` per point), and prints per bound the solution time,
the links through Z-buffers and each point's difference from `path`. `--base PRISM` adds
another build, run alternately, for a same-run comparison. Prints JSON and writes
tools/bench-results/bench-cluster-visibility.json.

Usage: python3 tools/bench_cluster_visibility.py [--prism target/release/prism]
       [--base OTHER_PRISM] [--bound 0.004 --bound 0.0005] [--reference-samples 262144]
"""
import argparse
import json
import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bench_results  # noqa: E402
from bench_tiled_radiosity import lux, run  # noqa: E402

SCENE = os.path.join(ROOT, "scenes/radiosity/crate-hall.json")
KEPT = ("wall_s", "peak_mib", "solution_s", "elements", "links", "cluster_links",
        "z_buffer_links", "hierarchy_mib")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prism", default=os.path.join(ROOT, "target/release/prism"))
    ap.add_argument("--base", help="another prism build to compare in the same run")
    ap.add_argument("--bound", type=float, action="append")
    ap.add_argument("--reference-samples", type=int, default=262144)
    args = ap.parse_args()
    bounds = args.bound or [0.004, 0.0005]
    scene = json.load(open(SCENE))
    builds = {"prism": args.prism}
    if args.base:
        builds["base"] = args.base
    results = {}
    with tempfile.TemporaryDirectory() as d:
        reference = json.loads(json.dumps(scene))
        reference["integrator"] = {"type": "path", "max_depth": 64}
        for s in reference["sensors"]:
            s["samples"] = args.reference_samples
        json.dump(reference, open(os.path.join(d, "reference.json"), "w"))
        ref = run(args.prism, os.path.join(d, "reference.json"), os.path.join(d, "reference"))
        ref_lux = lux(ref["sensors"])
        for bound in bounds:
            solved = json.loads(json.dumps(scene))
            solved["integrator"] = {"type": "radiosity", "error_bound_rel": bound}
            path = os.path.join(d, "bound-%g.json" % bound)
            json.dump(solved, open(path, "w"))
            for name, prism in builds.items():
                solved_run = run(prism, path, os.path.join(d, "%s-%g" % (name, bound)))
                diff = [100 * (g / e - 1) for g, e in zip(lux(solved_run["sensors"]), ref_lux)]
                r = {k: solved_run[k] for k in KEPT}
                r["lux_vs_path_pct"] = [round(x, 2) for x in diff]
                r["mean_vs_path_pct"] = round(sum(diff) / len(diff), 3)
                results["%s, bound %g" % (name, bound)] = r
    bench_results.write("bench-cluster-visibility", {
        "benchmark": "bench-cluster-visibility",
        "command": "python3 tools/bench_cluster_visibility.py " + " ".join(sys.argv[1:]),
        "scene": "scenes/radiosity/crate-hall.json, 17 sensor points (16 384 samples each); "
                 "reference: path (max_depth 64, %d samples per point, %.1f s)"
                 % (args.reference_samples, ref["wall_s"]),
        "machine": bench_results.machine(),
        "results": results,
    })


if __name__ == "__main__":
    main()

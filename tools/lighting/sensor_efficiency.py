#!/usr/bin/env python3
"""Efficiency of Prism's illuminance sensors on the furnished room of bench_sensor_grid.py:
the observed variance of each point's reading over independent seeds (not the reported
standard error, so it is valid for any estimator, quasi-Monte Carlo included) times the
CPU seconds spent measuring. Lower is better; the ratio of two settings' products is their
speed ratio at equal error. Prints one JSON line per run.

  tools/lighting/.venv/bin/python tools/lighting/sensor_efficiency.py --samples 2048 --seeds 8
(`--env K=V` passes settings to prism; the CPU time of a 1-sample run, scene loading,
is subtracted.)
"""

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).parent))
import bench_sensor_grid as b  # noqa: E402


def scene_file(work, grid, block, samples):
    X, Y, Z = b.ROOM
    tris = b.furniture()
    obj = work / "furniture.obj"
    b.write_obj(obj, tris)
    m = block
    i0 = j0 = (grid - m) // 2
    mats = {k: {"type": "two_sided", "material": k + "_1s"} for k in b.RHO}
    for k, r in b.RHO.items():
        mats[k + "_1s"] = {"type": "lambert", "reflectance": r}
    shapes = []
    for name, mat, o, u, v in b.room_rects():
        o, u, v = np.array(o, float), np.array(u, float), np.array(v, float)
        p = [o, o + u, o + u + v, o + v]
        f = work / f"{name}.obj"
        b.write_obj(f, [(tuple(p[0]), tuple(p[1]), tuple(p[2])), (tuple(p[0]), tuple(p[2]), tuple(p[3]))])
        shapes.append({"type": "mesh", "file": f.name, "material": mat})
    shapes.append({"type": "mesh", "file": obj.name, "material": "furniture"})
    scene = {
        "materials": mats,
        "shapes": shapes,
        "integrator": {"type": "path", "max_depth": b.MAX_DEPTH, "rr_depth": 3},
        "lights": [{"type": "point", "position_m": list(p), "spectrum": 1, "scale": b.INTENSITY} for p in b.LIGHTS],
        "sensors": [{
            "type": "grid", "name": "floor",
            "origin_m": [i0 * X / grid, 0, j0 * Z / grid],
            "u_m": [m * X / grid, 0, 0], "v_m": [0, 0, m * Z / grid],
            "resolution": [m, m], "normal": [0, 1, 0], "samples": samples,
        }],
        "film": {"resolution": [8, 8], "spp": 1},
    }
    out = {}
    for n in (samples, 1):
        scene["sensors"][0]["samples"] = n
        f = work / f"scene_{n}.json"
        f.write_text(json.dumps(scene))
        out[n] = f
    return out


def run(exe, scene, seed, threads, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = scene.with_suffix(".exr")
    subprocess.run([exe, "render", str(scene), "--sensors-only", "--threads", str(threads),
                    "--seed", str(seed), "-o", str(out)], check=True, capture_output=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    doc = json.loads(out.with_name(out.stem + ".sensors.json").read_text())
    pts = doc["sensors"][0]["points"]
    return cpu, np.array([p["illuminance_lx"] for p in pts]), np.array([p["std_error_lx"] for p in pts])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=2048)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--grid", type=int, default=100)
    ap.add_argument("--block", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--prism", default=str(b.ROOT / "target" / "release" / "prism"))
    ap.add_argument("--env", action="append", default=[], help="K=V for prism's environment")
    ap.add_argument("--work", default="")
    args = ap.parse_args()
    work = pathlib.Path(args.work) if args.work else pathlib.Path(tempfile.mkdtemp(prefix="prism-sensor-eff-"))
    work.mkdir(parents=True, exist_ok=True)
    scenes = scene_file(work, args.grid, args.block, args.samples)
    env = dict(os.environ)
    for kv in args.env:
        k, v = kv.split("=", 1)
        env[k] = v
    base = min(run(args.prism, scenes[1], 1, args.threads, env)[0] for _ in range(2))
    print("baseline cpu", base, file=sys.stderr)
    cpus, es, ses = [], [], []
    for s in range(args.seeds):
        cpu, e, se = run(args.prism, scenes[args.samples], 100 + s, args.threads, env)
        cpus.append(cpu - base)
        print("run cpu", cpu, file=sys.stderr)
        es.append(e)
        ses.append(se)
    es, ses = np.array(es), np.array(ses)
    mean = es.mean(0)
    rel_var = es.var(0, ddof=1) / mean**2  # observed relative variance of one reading
    rel_se_reported = np.sqrt((ses**2).mean(0)) / mean
    cpu = float(np.mean(cpus))
    print(json.dumps({
        "env": args.env, "samples": args.samples, "seeds": args.seeds,
        "cpu_s_per_run": round(cpu, 3),
        "cpu_us_per_sample": round(1e6 * cpu / (args.samples * len(mean)), 3),
        "median_observed_rel_se": float(np.median(np.sqrt(rel_var))),
        "mean_observed_rel_var": float(rel_var.mean()),
        "median_reported_rel_se": float(np.median(rel_se_reported)),
        "reported_over_observed_var": float((rel_se_reported**2).mean() / rel_var.mean()),
        # CPU seconds per point to reach 1 % relative s.e. (mean relative variance).
        "cpu_s_per_point_at_1pct": float(cpu / len(mean) * rel_var.mean() / 1e-4),
        "mean_E": float(mean.mean()),
    }))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Textured against explicit surfaces in radiosity (Mostefaoui et al. Fig. 7): the wicker
room of scenes/tiled/wicker-room.json with its panel cut to COLS x ROWS tiles, solved by
`radiosity` once with the panel as a `tiled` rectangle (one patch per side, the pyramid's
diffuse equivalent) and once with every copy of the tile written out as triangles (one
patch per face side), and measured by `path` on the explicit panel as the reference.
Illuminance sensors on the floor and the walls facing the panel give the agreement; the
radiosity statistics and GNU time give the cost. Prints JSON and writes
tools/bench-results/bench-tiled-radiosity.json.

Usage: python3 tools/bench_tiled_radiosity.py [--prism target/release/prism] [--cols 4 --rows 3]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bench_results  # noqa: E402
from bench_tiled import read_tile  # noqa: E402

PERIOD_M = 0.1


def write_explicit(tile, material, cols, rows, path):
    """The copies of the tile's faces of `material` over cols x rows periods, centred on
    the origin (the carrier rectangle's own frame)."""
    v, vn, faces = tile
    corner = (-0.5 * cols * PERIOD_M, -0.5 * rows * PERIOD_M)
    with open(path, "w") as f:
        for j in range(rows):
            for i in range(cols):
                ox, oy = corner[0] + i * PERIOD_M, corner[1] + j * PERIOD_M
                for p, n in zip(v, vn):
                    f.write("v %.9g %.9g %.9g\nvn %.9g %.9g %.9g\n" % (p[0] + ox, p[1] + oy, p[2], *n))
        count = 0
        for k in range(cols * rows):
            base = k * len(v)
            for m, idx in faces:
                if m == material:
                    a, b, c = (x + base for x in idx)
                    f.write("f %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c))
                    count += 1
    return count


def run(prism, scene, out_stem):
    """`prism render --sensors-only` under GNU time: wall time, peak memory, the
    radiosity statistics it prints, and the sensor readings."""
    start = time.perf_counter()
    p = subprocess.run(
        ["/usr/bin/time", "-f", "peak_kib %M", prism, "render", scene, "--sensors-only",
         "-o", out_stem + ".exr"],
        capture_output=True, text=True,
    )
    wall = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(p.stderr)
    text = p.stdout + p.stderr
    stats = re.findall(
        r"iteration \d+: (\d+) patches, (\d+) elements, (\d+) links "
        r"\((\d+) from clusters, (\d+) through their Z-buffers\), ([0-9.]+) MiB",
        text,
    )
    solution = re.search(r"solution in ([0-9.]+) s", text)
    peak = re.search(r"peak_kib (\d+)", text)
    readings = json.load(open(out_stem + ".sensors.json"))
    return {
        "wall_s": round(wall, 3),
        "peak_mib": round(int(peak.group(1)) / 1024, 1) if peak else None,
        "solution_s": float(solution.group(1)) if solution else None,
        "patches": int(stats[-1][0]) if stats else None,
        "elements": int(stats[-1][1]) if stats else None,
        "links": int(stats[-1][2]) if stats else None,
        "cluster_links": int(stats[-1][3]) if stats else None,
        "z_buffer_links": int(stats[-1][4]) if stats else None,
        "hierarchy_mib": float(stats[-1][5]) if stats else None,
        "sensors": readings,
    }


def lux(readings):
    """Every point's illuminance, in order, from a sensors.json."""
    values = []
    for sensor in readings["sensors"]:
        values.extend(p["illuminance_lx"] for p in sensor["points"])
    return values


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prism", default=os.path.join(ROOT, "target/release/prism"))
    ap.add_argument("--cols", type=int, default=4)
    ap.add_argument("--rows", type=int, default=3)
    args = ap.parse_args()
    scene = json.load(open(os.path.join(ROOT, "scenes/tiled/wicker-room.json")))
    panel = next(s for s in scene["shapes"] if s.get("name") == "panel")
    panel["size_m"] = [args.cols * PERIOD_M, args.rows * PERIOD_M]
    scene["film"] = {"resolution": [8, 8], "spp": 1}
    scene["sensors"] = [{
        "type": "points", "name": "probes", "samples": 16384,
        "positions_m": [[0.0, -0.999, 0.6], [0.3, -0.999, 0.2], [-0.4, -0.999, 0.8]],
        "normal": [0, 1, 0],
    }, {
        "type": "points", "name": "facing wall", "samples": 16384,
        "positions_m": [[0.0, 0.0, 0.999], [0.5, 0.3, 0.999]], "normal": [0, 0, -1],
    }]
    with tempfile.TemporaryDirectory() as d:
        os.symlink(os.path.join(ROOT, "scenes/tiled/tiles"), os.path.join(d, "tiles"))
        for name in os.listdir(os.path.join(ROOT, "scenes/tiled")):
            if name.endswith(".csv") or name.endswith(".spd"):
                os.symlink(os.path.join(ROOT, "scenes/tiled", name), os.path.join(d, name))
        tile = read_tile(os.path.join(ROOT, "scenes/tiled/tiles/wicker.obj"))
        triangles = 0
        for m in ("strand_weft", "strand_warp"):
            triangles += write_explicit(tile, m, args.cols, args.rows, os.path.join(d, m + ".obj"))
        json.dump(scene, open(os.path.join(d, "tiled.json"), "w"))
        explicit = json.loads(json.dumps(scene))
        shapes = [s for s in explicit["shapes"] if s.get("name") != "panel"]
        for m, material in (("strand_weft", "cane"), ("strand_warp", "dark cane")):
            shapes.append({"type": "mesh", "file": m + ".obj", "material": material,
                           "transform": panel.get("transform", {})})
        explicit["shapes"] = shapes
        json.dump(explicit, open(os.path.join(d, "explicit.json"), "w"))
        reference = json.loads(json.dumps(explicit))
        reference["integrator"] = {"type": "path", "max_depth": 64}
        json.dump(reference, open(os.path.join(d, "reference.json"), "w"))
        results = {k: run(args.prism, os.path.join(d, k + ".json"), os.path.join(d, k))
                   for k in ("tiled", "explicit", "reference")}
    ref = lux(results["reference"]["sensors"])
    for k in ("tiled", "explicit"):
        got = lux(results[k]["sensors"])
        results[k]["lux_vs_path_pct"] = [round(100 * (g / r - 1), 2) for g, r in zip(got, ref)]
    for k in results:
        results[k]["lux"] = [round(x, 2) for x in lux(results[k]["sensors"])]
        del results[k]["sensors"]
    result = {
        "benchmark": "bench-tiled-radiosity",
        "command": "python3 tools/bench_tiled_radiosity.py --cols %d --rows %d" % (args.cols, args.rows),
        "scene": "scenes/tiled/wicker-room.json, panel %d x %d tiles (%d triangles explicit), "
                 "5 sensor points, 16384 samples each; reference: path (max_depth 64) on the "
                 "explicit panel" % (args.cols, args.rows, triangles),
        "load_average_1min": os.getloadavg()[0],
        "results": results,
    }
    bench_results.write("bench-tiled-radiosity", result)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Virtual ray tracing against explicit geometry: the wicker wall of
scenes/tiled/wicker-wall.json widened to a 2 m x 1.5 m panel (20 x 15 tiles of 3 072
triangles: 921 600 triangles when written out), rendered by `prism render` as a `tiled`
rectangle and as two explicit OBJ meshes (every copy written out), in alternating pairs.
Prints JSON and writes tools/bench-results/bench-tiled.json: per round the whole-process
wall time and peak resident memory of each, the render time `prism` reports, and the
relative MSE of the two images (same seed: they differ only by rounding).

Usage: python3 tools/bench_tiled.py [--prism target/release/prism] [--rounds 3]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_results  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELLS = (20, 15)
PERIOD_M = 0.1


def read_tile(path):
    v, vn, faces, material = [], [], [], None
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            v.append(tuple(map(float, t[1:4])))
        elif t[0] == "vn":
            vn.append(tuple(map(float, t[1:4])))
        elif t[0] == "usemtl":
            material = t[1]
        elif t[0] == "f":
            faces.append((material, [int(x.split("/")[0]) for x in t[1:]]))
    return v, vn, faces


def write_explicit(tile, material, path):
    v, vn, faces = tile
    corner = (-0.5 * CELLS[0] * PERIOD_M, -0.5 * CELLS[1] * PERIOD_M)
    with open(path, "w") as f:
        for j in range(CELLS[1]):
            for i in range(CELLS[0]):
                ox, oy = corner[0] + i * PERIOD_M, corner[1] + j * PERIOD_M
                for p, n in zip(v, vn):
                    f.write("v %.9g %.9g %.9g\nvn %.9g %.9g %.9g\n" % (p[0] + ox, p[1] + oy, p[2], *n))
        for k in range(CELLS[0] * CELLS[1]):
            base = k * len(v)
            for m, idx in faces:
                if m == material:
                    a, b, c = (x + base for x in idx)
                    f.write("f %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c))


def run(prism, scene, out):
    """One whole `prism render` under GNU time: wall time, peak resident memory, and the
    render time prism reports."""
    start = time.perf_counter()
    p = subprocess.run(
        ["/usr/bin/time", "-f", "peak_kib %M", prism, "render", scene, "-o", out],
        capture_output=True, text=True,
    )
    wall = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(p.stderr)
    render = re.search(r"spp, ([0-9.]+) s,", p.stdout + p.stderr)
    peak = re.search(r"peak_kib (\d+)", p.stderr)
    return {
        "wall_s": round(wall, 3),
        "render_s": float(render.group(1)) if render else None,
        "peak_mib": round(int(peak.group(1)) / 1024, 1) if peak else None,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prism", default=os.path.join(ROOT, "target/release/prism"))
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    scene = json.load(open(os.path.join(ROOT, "scenes/tiled/wicker-wall.json")))
    scene["shapes"][0]["size_m"] = [CELLS[0] * PERIOD_M, CELLS[1] * PERIOD_M]
    scene["shapes"][1]["size_m"] = [6, 6]
    scene["camera"]["transform"]["look_at"]["eye"] = [0.5, 0.3, 2.6]
    scene["film"]["spp"] = 32
    with tempfile.TemporaryDirectory() as d:
        os.symlink(os.path.join(ROOT, "scenes/tiled/tiles"), os.path.join(d, "tiles"))
        tile = read_tile(os.path.join(ROOT, "scenes/tiled/tiles/wicker.obj"))
        for m in ("strand_weft", "strand_warp"):
            write_explicit(tile, m, os.path.join(d, m + ".obj"))
        json.dump(scene, open(os.path.join(d, "tiled.json"), "w"))
        explicit = json.loads(json.dumps(scene))
        explicit["shapes"][0] = {"type": "mesh", "file": "strand_weft.obj", "material": "cane"}
        explicit["shapes"].insert(1, {"type": "mesh", "file": "strand_warp.obj", "material": "dark cane"})
        json.dump(explicit, open(os.path.join(d, "explicit.json"), "w"))
        rounds = []
        for _ in range(args.rounds):
            r = {}
            for kind in ("tiled", "explicit"):
                r[kind] = run(args.prism, os.path.join(d, kind + ".json"), os.path.join(d, kind + ".exr"))
            rounds.append(r)
        cmp = subprocess.run(
            [args.prism, "compare", os.path.join(d, "tiled.exr"), os.path.join(d, "explicit.exr")],
            capture_output=True, text=True,
        ).stdout
        rel = re.search(r"relMSE\s+([0-9.e+-]+)\s+([0-9.e+-]+)\s+([0-9.e+-]+)", cmp)
    median = lambda xs: sorted(xs)[len(xs) // 2]
    result = {
        "benchmark": "bench-tiled",
        "command": "python3 tools/bench_tiled.py --rounds %d" % args.rounds,
        "scene": "scenes/tiled/wicker-wall.json, panel %d x %d tiles (%d triangles explicit), 320x240, 32 spp"
        % (CELLS[0], CELLS[1], CELLS[0] * CELLS[1] * len(tile[2])),
        "load_average_1min": os.getloadavg()[0],
        "rounds": rounds,
        "median": {
            k: {
                "wall_s": median([r[k]["wall_s"] for r in rounds]),
                "render_s": median([r[k]["render_s"] for r in rounds]),
                "peak_mib": median([r[k]["peak_mib"] for r in rounds]),
            }
            for k in ("tiled", "explicit")
        },
        "image_relmse_rgb": [float(x) for x in rel.groups()] if rel else None,
    }
    bench_results.write("bench-tiled", result)


if __name__ == "__main__":
    main()

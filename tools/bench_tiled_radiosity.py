#!/usr/bin/env python3
"""Textured against explicit surfaces in radiosity (Mostefaoui et al. Fig. 7: a room with
wickerwork and a grid): the wicker room of scenes/tiled/wicker-room.json with its panel
cut to COLS x ROWS tiles and a welded wire grid (scenes/tiled/tiles/grid.obj) of
GRID_COLS x GRID_ROWS periods standing before its left wall, solved by `radiosity` once
with both as `tiled` rectangles (one directional patch per side) and once with every copy
of their tiles written out as triangles (one patch per face side), and measured by `path`
on the explicit scene as the reference. Illuminance sensors on the floor and the walls
give the agreement, the radiosity statistics and GNU time the cost; the camera's view
(IMAGE_SPP samples per pixel, radiosity's final gather) rendered from both solutions and
by `path` (REFERENCE_SPP) gives the image difference (`prism compare`). Prints JSON and
writes tools/bench-results/bench-tiled-radiosity.json.

Usage: python3 tools/bench_tiled_radiosity.py [--prism target/release/prism] [--cols 4 --rows 3]
       [--grid-cols 8 --grid-rows 6] [--image-spp 64] [--reference-spp 1024]
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
    """The copies of the tile's faces of `material` over cols x rows periods of PERIOD_M,
    centred on the origin (the carrier rectangle's own frame)."""
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
    # Finer tile pyramids the solution asked for (tile, levels).
    pyramids = re.findall(r"tile `([^`]+)`: a (\d+)-level pyramid", text)
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
        "finer_pyramids": {t: int(levels) for t, levels in pyramids},
        "sensors": readings,
    }


def render_image(prism, scene, out):
    """The camera's view of `scene` (its film), wall time."""
    start = time.perf_counter()
    p = subprocess.run([prism, "render", scene, "-o", out], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(p.stderr)
    return round(time.perf_counter() - start, 3)


def compare(prism, test, reference):
    """`prism compare --json` of two renders: relMSE and mean ΔE2000."""
    p = subprocess.run([prism, "compare", test, reference, "--json"], capture_output=True,
                       text=True)
    if p.returncode != 0:
        sys.exit(p.stderr)
    m = json.loads(p.stdout)
    return {"relmse": m["relmse"], "delta_e2000_mean": m["delta_e2000_mean"]}


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
    ap.add_argument("--grid-cols", type=int, default=8)
    ap.add_argument("--grid-rows", type=int, default=6)
    ap.add_argument("--image-spp", type=int, default=64)
    ap.add_argument("--reference-spp", type=int, default=1024)
    args = ap.parse_args()
    scene = json.load(open(os.path.join(ROOT, "scenes/tiled/wicker-room.json")))
    panel = next(s for s in scene["shapes"] if s.get("name") == "panel")
    panel["size_m"] = [args.cols * PERIOD_M, args.rows * PERIOD_M]
    # The grid: a vertical partition 0.45 m from the left wall, facing into the room.
    grid = {"type": "rectangle", "name": "grid",
            "size_m": [args.grid_cols * PERIOD_M, args.grid_rows * PERIOD_M],
            "material": "wire grid",
            "transform": [{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}},
                          {"translate": [-0.55, -0.6, 0.1]}]}
    scene["shapes"].append(grid)
    scene["tiles"]["grid"] = {"mesh": "tiles/grid.obj", "period_m": [PERIOD_M, PERIOD_M],
                              "materials": {"wire": "painted steel"}}
    scene["materials"]["painted steel"] = {"type": "lambert", "reflectance": 0.7}
    scene["materials"]["wire grid"] = {"type": "tiled", "tile": "grid"}
    film = scene["film"]
    scene["film"] = {"resolution": [8, 8], "spp": 1}
    scene["sensors"] = [{
        "type": "points", "name": "probes", "samples": 16384,
        "positions_m": [[0.0, -0.999, 0.6], [0.3, -0.999, 0.2], [-0.4, -0.999, 0.8]],
        "normal": [0, 1, 0],
    }, {
        "type": "points", "name": "facing wall", "samples": 16384,
        "positions_m": [[0.0, 0.0, 0.999], [0.5, 0.3, 0.999]], "normal": [0, 0, -1],
    }, {
        "type": "points", "name": "behind the grid", "samples": 16384,
        "positions_m": [[-0.999, -0.6, 0.1], [-0.999, -0.8, -0.2], [-0.8, -0.999, 0.1]],
        "normals": [[1, 0, 0], [1, 0, 0], [0, 1, 0]],
    }]
    with tempfile.TemporaryDirectory() as d:
        os.symlink(os.path.join(ROOT, "scenes/tiled/tiles"), os.path.join(d, "tiles"))
        for name in os.listdir(os.path.join(ROOT, "scenes/tiled")):
            if name.endswith(".csv") or name.endswith(".spd"):
                os.symlink(os.path.join(ROOT, "scenes/tiled", name), os.path.join(d, name))
        triangles = 0
        explicit_meshes = []
        for tile_name, shape, cols, rows, parts in (
                ("wicker", panel, args.cols, args.rows,
                 (("strand_weft", "cane"), ("strand_warp", "dark cane"))),
                ("grid", grid, args.grid_cols, args.grid_rows, (("wire", "painted steel"),))):
            tile = read_tile(os.path.join(ROOT, "scenes/tiled/tiles", tile_name + ".obj"))
            for m, material in parts:
                path = os.path.join(d, m + ".obj")
                triangles += write_explicit(tile, m, cols, rows, path)
                explicit_meshes.append({"type": "mesh", "file": m + ".obj", "material": material,
                                        "transform": shape.get("transform", {})})
        json.dump(scene, open(os.path.join(d, "tiled.json"), "w"))
        explicit = json.loads(json.dumps(scene))
        explicit["shapes"] = [s for s in explicit["shapes"]
                              if s.get("name") not in ("panel", "grid")] + explicit_meshes
        json.dump(explicit, open(os.path.join(d, "explicit.json"), "w"))
        reference = json.loads(json.dumps(explicit))
        reference["integrator"] = {"type": "path", "max_depth": 64}
        json.dump(reference, open(os.path.join(d, "reference.json"), "w"))
        results = {k: run(args.prism, os.path.join(d, k + ".json"), os.path.join(d, k))
                   for k in ("tiled", "explicit", "reference")}
        # The camera's view from each, at the scene's own resolution.
        for k, spp in (("tiled", args.image_spp), ("explicit", args.image_spp),
                       ("reference", args.reference_spp)):
            view = json.load(open(os.path.join(d, k + ".json")))
            view["film"] = dict(film, spp=spp)
            del view["sensors"]
            json.dump(view, open(os.path.join(d, k + "-view.json"), "w"))
            results[k]["image_wall_s"] = render_image(
                args.prism, os.path.join(d, k + "-view.json"), os.path.join(d, k + ".exr"))
        images = {
            "tiled_vs_path": compare(args.prism, os.path.join(d, "tiled.exr"),
                                     os.path.join(d, "reference.exr")),
            "explicit_vs_path": compare(args.prism, os.path.join(d, "explicit.exr"),
                                        os.path.join(d, "reference.exr")),
            "tiled_vs_explicit": compare(args.prism, os.path.join(d, "tiled.exr"),
                                         os.path.join(d, "explicit.exr")),
        }
    ref = lux(results["reference"]["sensors"])
    for k in ("tiled", "explicit"):
        got = lux(results[k]["sensors"])
        results[k]["lux_vs_path_pct"] = [round(100 * (g / r - 1), 2) for g, r in zip(got, ref)]
    for k in results:
        results[k]["lux"] = [round(x, 2) for x in lux(results[k]["sensors"])]
        del results[k]["sensors"]
    result = {
        "benchmark": "bench-tiled-radiosity",
        "command": "python3 tools/bench_tiled_radiosity.py --cols %d --rows %d --grid-cols %d "
                   "--grid-rows %d --image-spp %d --reference-spp %d"
                   % (args.cols, args.rows, args.grid_cols, args.grid_rows, args.image_spp,
                      args.reference_spp),
        "scene": "scenes/tiled/wicker-room.json, wicker panel %d x %d tiles and a wire grid %d x "
                 "%d tiles (%d triangles explicit), 8 sensor points, 16384 samples each; "
                 "reference: path (max_depth 64) on the explicit scene; images %dx%d, %d spp "
                 "(reference %d spp)"
                 % (args.cols, args.rows, args.grid_cols, args.grid_rows, triangles,
                    film["resolution"][0], film["resolution"][1], args.image_spp,
                    args.reference_spp),
        "load_average_1min": os.getloadavg()[0],
        "results": results,
        "images": images,
    }
    bench_results.write("bench-tiled-radiosity", result)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Sensor-grid benchmark: illuminance on a grid over the floor of a furnished room
(≈10⁵ triangles, indirect light included) to a per-point standard error, computed by
Prism (`prism render --sensors-only`, adaptive sensors), Radiance (`rtrace -I`, pure Monte
Carlo path tracing: -aa 0 -ad 1, each point repeated K times) and Mitsuba 3 (an
orthographic image of the Lambertian floor seen from 1.2 cm above it, E = πL/ρ; independent
renders give the per-pixel spread). Prints one JSON document.

All three see the same scene in flat-spectrum ("grey") radiometric units: four isotropic
point lights of intensity 10 W·sr⁻¹·nm⁻¹ (Radiance: spheres of 2 cm radius and radiance
I/(πr²), whose intensity is the same), grey Lambertian surfaces (floor 0.3, walls 0.5,
ceiling 0.7, furniture 0.4). Prism's lux are divided by its `lx_per_flat_irradiance`.

Setup:
  python3 -m venv tools/lighting/.venv && tools/lighting/.venv/bin/pip install pyradiance numpy
  bash tools/mitsuba/setup.sh
  cargo build --release
Run (2 threads each, as the issue asks):
  tools/lighting/.venv/bin/python tools/lighting/bench_sensor_grid.py --grid 100 --threads 2
The Mitsuba part runs in tools/mitsuba/.venv's Python (a subprocess).

Timings are wall-clock seconds and CPU seconds (user + system, all threads and child
processes) of each program's own run (scene loading included), on the same machine in one
run; on a shared machine the CPU times are the steadier comparison. Each program is run to a
per-point relative standard error of
--target (default 1 %): Prism by its adaptive sensors; Radiance and Mitsuba by a pilot run
that measures the per-sample variance and then the sample count that reaches the target
at the grid's median point (reported), whose run is timed.
"""

import argparse
import json
import math
import os
import pathlib
import resource
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]

ROOM = (6.0, 3.0, 4.0)  # x, y (height), z in metres
LIGHTS = [(1.5, 2.8, 1.0), (4.5, 2.8, 1.0), (1.5, 2.8, 3.0), (4.5, 2.8, 3.0)]
INTENSITY = 10.0  # W/sr/nm, flat spectrum
LIGHT_RADIUS = 0.02  # Radiance's spheres
RHO = {"floor": 0.3, "wall": 0.5, "ceiling": 0.7, "furniture": 0.4}
MAX_DEPTH = 8


# ----------------------------------------------------------------------------- timing


def timed(args, **kw):
    """subprocess.run(args, **kw) → (completed, wall seconds, CPU seconds of the child and
    its waited-for descendants, user + system). CPU time is the fairer measure on a shared
    machine: other jobs stretch wall time but not (much) the CPU a program needs."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(args, **kw)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return out, wall, cpu


# ----------------------------------------------------------------------------- geometry


def box(lo, hi):
    """12 triangles of an axis-aligned box."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = [
        (x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
        (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1),
    ]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2)]
    tris = []
    for a, b, c, d in quads:
        tris.append((v[a], v[b], v[c]))
        tris.append((v[a], v[c], v[d]))
    return tris


def uv_sphere(center, r, n_theta, n_phi):
    cx, cy, cz = center
    tris = []

    def p(i, j):
        t = math.pi * i / n_theta
        f = 2 * math.pi * j / n_phi
        return (cx + r * math.sin(t) * math.cos(f), cy + r * math.cos(t), cz + r * math.sin(t) * math.sin(f))

    for i in range(n_theta):
        for j in range(n_phi):
            a, b, c, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            if i > 0:
                tris.append((a, b, d))
            if i < n_theta - 1:
                tris.append((b, c, d))
    return tris


def furniture():
    """Tables with legs, chairs, two shelves and tessellated vases: ≈10⁵ triangles. Legs
    start 2 cm above the floor so Mitsuba's camera (1.2 cm above it) is never inside one."""
    tris = []
    lift = 0.02
    for tx, tz in [(1.5, 1.0), (4.5, 1.0), (1.5, 3.0), (4.5, 3.0)]:
        tris += box((tx - 0.7, 0.72, tz - 0.4), (tx + 0.7, 0.75, tz + 0.4))
        for lx in (-0.65, 0.6):
            for lz in (-0.35, 0.3):
                tris += box((tx + lx, lift, tz + lz), (tx + lx + 0.05, 0.72, tz + lz + 0.05))
        for side in (-1, 1):
            cz = tz + side * 0.65
            tris += box((tx - 0.22, 0.44, cz - 0.2), (tx + 0.22, 0.47, cz + 0.2))
            bz = cz + side * 0.18
            tris += box((tx - 0.22, 0.47, bz - 0.02), (tx + 0.22, 0.9, bz + 0.02))
            for lx in (-0.2, 0.16):
                for lz in (-0.18, 0.14):
                    tris += box((tx + lx, lift, cz + lz), (tx + lx + 0.04, 0.44, cz + lz + 0.04))
        tris += uv_sphere((tx + 0.3, 0.9, tz), 0.15, 90, 180)
    tris += box((0.05, lift, 1.6), (0.45, 2.0, 2.4))
    tris += box((5.55, lift, 1.6), (5.95, 2.0, 2.4))
    return tris


def write_obj(path, tris):
    with open(path, "w") as f:
        for t in tris:
            for v in t:
                f.write("v %.6f %.6f %.6f\n" % v)
        for k in range(len(tris)):
            f.write("f %d %d %d\n" % (3 * k + 1, 3 * k + 2, 3 * k + 3))


def room_rects():
    """(name, material, corner, u, v) of the six inner faces."""
    X, Y, Z = ROOM
    return [
        ("floor", "floor", (0, 0, 0), (X, 0, 0), (0, 0, Z)),
        ("ceiling", "ceiling", (0, Y, 0), (X, 0, 0), (0, 0, Z)),
        ("wall_x0", "wall", (0, 0, 0), (0, Y, 0), (0, 0, Z)),
        ("wall_x1", "wall", (X, 0, 0), (0, Y, 0), (0, 0, Z)),
        ("wall_z0", "wall", (0, 0, 0), (X, 0, 0), (0, Y, 0)),
        ("wall_z1", "wall", (0, 0, Z), (X, 0, 0), (0, Y, 0)),
    ]


def grid_points(n, block):
    """Cell centres of the n × n floor grid inside `block` = (i0, j0, size): cells
    i0…i0+size−1 along x and j0…j0+size−1 along z; row-major, x fastest."""
    X, _, Z = ROOM
    i0, j0, m = block
    xs = (np.arange(i0, i0 + m) + 0.5) / n * X
    zs = (np.arange(j0, j0 + m) + 0.5) / n * Z
    return [(x, 0.0, z) for z in zs for x in xs]


# ----------------------------------------------------------------------------- Prism


def run_prism(work, obj, n, block, threads, target, exe):
    X, Y, Z = ROOM
    i0, j0, m = block
    mats = {k: {"type": "two_sided", "material": k + "_1s"} for k in RHO}
    for k, r in RHO.items():
        mats[k + "_1s"] = {"type": "lambert", "reflectance": r}
    shapes = []
    # Room faces as meshes of two triangles (exact corners, inner side either way).
    for name, mat, o, u, v in room_rects():
        o, u, v = np.array(o, float), np.array(u, float), np.array(v, float)
        p = [o, o + u, o + u + v, o + v]
        f = work / f"{name}.obj"
        write_obj(f, [(tuple(p[0]), tuple(p[1]), tuple(p[2])), (tuple(p[0]), tuple(p[2]), tuple(p[3]))])
        shapes.append({"type": "mesh", "file": f.name, "material": mat})
    shapes.append({"type": "mesh", "file": obj.name, "material": "furniture"})
    scene = {
        "materials": mats,
        "shapes": shapes,
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "rr_depth": 3},
        "lights": [
            {"type": "point", "position_m": list(p), "spectrum": 1, "scale": INTENSITY}
            for p in LIGHTS
        ],
        "sensors": [
            {
                "type": "grid",
                "name": "floor",
                "origin_m": [i0 * X / n, 0, j0 * Z / n],
                "u_m": [m * X / n, 0, 0],
                "v_m": [0, 0, m * Z / n],
                "resolution": [m, m],
                "normal": [0, 1, 0],
                "relative_error": target,
                "min_samples": 64,
            }
        ],
        "film": {"resolution": [8, 8], "spp": 1},
    }
    sf = work / "prism_scene.json"
    sf.write_text(json.dumps(scene, indent=1))
    _, wall, cpu = timed(
        [str(exe), "render", str(sf), "--sensors-only", "--threads", str(threads), "-o", str(work / "prism.exr")],
        check=True,
        capture_output=True,
    )
    # Start-up CPU (scene loading, BVH): the same scene with one sample per point.
    one = json.loads(json.dumps(scene))
    one["sensors"][0] = {k: v for k, v in one["sensors"][0].items() if k not in ("relative_error", "min_samples")}
    one["sensors"][0]["samples"] = 1
    sf1 = work / "prism_scene_1.json"
    sf1.write_text(json.dumps(one))
    _, _, fixed_cpu = timed(
        [str(exe), "render", str(sf1), "--sensors-only", "--threads", str(threads), "-o", str(work / "prism1.exr")],
        check=True,
        capture_output=True,
    )
    doc = json.loads((work / "prism.sensors.json").read_text())
    k = doc["lx_per_flat_irradiance"]
    pts = doc["sensors"][0]["points"]
    e = np.array([p["illuminance_lx"] for p in pts]) / k
    se = np.array([p["std_error_lx"] for p in pts]) / k
    return {
        "wall_time_s": wall,
        "fixed_time_s": wall - doc["wall_time_s"],
        "cpu_time_s": cpu,
        "fixed_cpu_s": fixed_cpu,
        "measure_time_s": doc["wall_time_s"],
        "samples": doc["samples"],
        "E": e,
        "se": se,
    }


# ----------------------------------------------------------------------------- Radiance


def radiance_env():
    import pyradiance  # noqa: F401

    base = pathlib.Path(pyradiance.__file__).parent
    env = dict(os.environ)
    lib = base / "lib"
    env["RAYPATH"] = str(lib) + os.pathsep + env.get("RAYPATH", ".")
    binp = base / "bin"
    env["PATH"] = str(binp) + os.pathsep + env.get("PATH", "")
    return env, binp


def build_radiance(work, tris):
    X, Y, Z = ROOM
    lines = []
    for k, r in RHO.items():
        lines.append(f"void plastic {k}\n0\n0\n5 {r} {r} {r} 0 0\n")
    L = INTENSITY / (math.pi * LIGHT_RADIUS**2)
    lines.append(f"void light lamp\n0\n0\n3 {L} {L} {L}\n")
    for i, p in enumerate(LIGHTS):
        lines.append(f"lamp sphere bulb{i}\n0\n0\n4 {p[0]} {p[1]} {p[2]} {LIGHT_RADIUS}\n")
    for name, mat, o, u, v in room_rects():
        o, u, v = np.array(o, float), np.array(u, float), np.array(v, float)
        p = [o, o + u, o + u + v, o + v]
        coords = " ".join("%g %g %g" % tuple(q) for q in p)
        lines.append(f"{mat} polygon {name}\n0\n0\n12 {coords}\n")
    for i, t in enumerate(tris):
        coords = " ".join("%.6f %.6f %.6f" % v for v in t)
        lines.append(f"furniture polygon f{i}\n0\n0\n9 {coords}\n")
    rad = work / "room.rad"
    rad.write_text("".join(lines))
    env, binp = radiance_env()
    oct_path = work / "room.oct"
    with open(oct_path, "wb") as f:
        subprocess.run([str(binp / "oconv"), str(rad)], check=True, stdout=f, env=env)
    return oct_path


def rtrace(oct_path, points, repeats, threads, seed_offset=0):
    """Per-point mean, standard error and wall time of `repeats` one-path estimates."""
    env, binp = radiance_env()
    # Pure path tracing: one ambient division per bounce, no caching, Russian roulette by
    # weight (-lw), direct light sampled at the spheres' centres (-ds 0, -dj 0).
    args = [
        str(binp / "rtrace"), "-I", "-h", "-ov", "-n", str(threads),
        "-ab", str(MAX_DEPTH), "-ad", "1", "-as", "0", "-aa", "0", "-lw", "1e-4",
        "-ds", "0", "-dj", "0", "-dt", "0", "-dc", "1", "-dr", "0", "-ss", "0", "-st", "1",
        str(oct_path),
    ]
    rows = []
    for _ in range(repeats):
        for (x, y, z) in points:
            rows.append("%f %f %f 0 1 0\n" % (x, y + 1e-4, z))
    out, wall, cpu = timed(args, input="".join(rows).encode(), check=True, capture_output=True, env=env)
    vals = np.array([float(l.split()[1]) for l in out.stdout.decode().strip().splitlines()])
    vals = vals.reshape(repeats, len(points))
    return vals.mean(0), vals.std(0, ddof=1) / math.sqrt(repeats), wall, cpu


def run_radiance(work, tris, points, threads, target):
    oct_path = build_radiance(work, tris)
    # Pilot on a subset: per-path relative variance at the median point.
    sub = points[:: max(1, len(points) // 200)]
    m, se, _, _ = rtrace(oct_path, sub, 64, threads)
    rel_path_sd = np.median(se * math.sqrt(64) / np.maximum(m, 1e-30))
    repeats = int(math.ceil((rel_path_sd / target) ** 2))
    mean, se, wall, cpu = rtrace(oct_path, points, repeats, threads)
    # Start-up (octree load): one path at one point.
    _, _, fixed, fixed_cpu = rtrace(oct_path, points[:1], 2, threads)
    return {"wall_time_s": wall, "fixed_time_s": fixed, "cpu_time_s": cpu, "fixed_cpu_s": fixed_cpu,
            "paths_per_point": repeats, "E": mean, "se": se}


# ----------------------------------------------------------------------------- Mitsuba

MITSUBA_WORKER = r'''
import json, math, sys, time, os
sys.path.insert(0, sys.argv[1])
from common import import_mitsuba
mi = import_mitsuba()
cfg = json.loads(open(sys.argv[2]).read())
mi.set_variant("llvm_ad_rgb" if cfg["llvm"] else "scalar_rgb")
import numpy as np
import drjit as dr
X, Y, Z = cfg["room"]
def bsdf(r):
    return {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [r, r, r]}}}
scene = {"type": "scene",
  "integrator": {"type": "path", "max_depth": cfg["max_depth"] + 1, "rr_depth": 4},
  "sensor": {"type": "orthographic",
     "to_world": mi.ScalarTransform4f().look_at(origin=[X/2, 0.012, Z/2], target=[X/2, -1.0, Z/2], up=[0, 0, 1])
        .scale([X/2, Z/2, 1]),
     "film": {"type": "hdrfilm", "width": cfg["n"], "height": cfg["n"], "rfilter": {"type": "box"}, "pixel_format": "rgb",
              "crop_offset_x": cfg["crop"][0], "crop_offset_y": cfg["crop"][1], "crop_width": cfg["crop"][2], "crop_height": cfg["crop"][2]},
     "sampler": {"type": "independent", "sample_count": cfg["spp"]}}}
for i, (name, mat, path) in enumerate(cfg["meshes"]):
    scene["m%d" % i] = {"type": "obj", "filename": path, "bsdf": bsdf(cfg["rho"][mat])}
for i, p in enumerate(cfg["lights"]):
    scene["l%d" % i] = {"type": "point", "position": p, "intensity": {"type": "rgb", "value": [cfg["I"]] * 3}}
t0 = time.perf_counter()
c0 = time.process_time()
sc = mi.load_dict(scene)
load = time.perf_counter() - t0
load_cpu = time.process_time() - c0
imgs = []
for k in range(cfg["repeats"]):
    img = mi.render(sc, spp=cfg["spp"], seed=k + 1)
    imgs.append(np.array(img)[:, :, 1])
wall = time.perf_counter() - t0
cpu = time.process_time() - c0
json.dump({"wall_time_s": wall, "load_time_s": load, "cpu_time_s": cpu, "load_cpu_s": load_cpu,
           "images": [i.tolist() for i in imgs]}, open(sys.argv[3], "w"))
'''


def mitsuba_python():
    p = ROOT / "tools" / "mitsuba" / ".venv" / "bin" / "python"
    return str(p) if p.exists() else None


def mitsuba_render(work, meshes, n, block, spp, repeats, threads, llvm):
    i0, j0, m = block
    cfg = {
        # The block's pixels: image columns run along −x and rows along −z (see below).
        "crop": [n - i0 - m, n - j0 - m, m],
        "room": ROOM, "n": n, "spp": spp, "repeats": repeats, "max_depth": MAX_DEPTH,
        "meshes": meshes, "rho": RHO, "lights": LIGHTS, "I": INTENSITY, "llvm": llvm,
    }
    (work / "mi_cfg.json").write_text(json.dumps(cfg))
    (work / "mi_worker.py").write_text(MITSUBA_WORKER)
    env = dict(os.environ)
    env["DRJIT_NUM_THREADS"] = str(threads)
    subprocess.run(
        [mitsuba_python(), str(work / "mi_worker.py"), str(ROOT / "tools" / "mitsuba"), str(work / "mi_cfg.json"), str(work / "mi_out.json")],
        check=True, env=env, capture_output=True,
    )
    out = json.loads((work / "mi_out.json").read_text())
    imgs = np.array(out["images"])  # repeats × n × n; row 0 is the top of the image
    return imgs, out["wall_time_s"], out["load_time_s"], out["cpu_time_s"], out["load_cpu_s"]


def run_mitsuba(work, obj, n, block, threads, target):
    meshes = []
    for name, mat, o, u, v in room_rects():
        meshes.append((name, mat, str(work / f"{name}.obj")))
    meshes.append(("furniture", "furniture", str(obj)))
    # The LLVM (vectorised, JIT) variant when it runs here, else the scalar one.
    llvm = True
    try:
        imgs = mitsuba_render(work, meshes, n, block, 16, 8, threads, llvm)[0]
    except subprocess.CalledProcessError:
        llvm = False
        imgs = mitsuba_render(work, meshes, n, block, 16, 8, threads, llvm)[0]
    # (Pilot above: per-pixel relative spread of 8 independent 16-spp images.)
    m = imgs.mean(0)
    rel = np.median(imgs.std(0, ddof=1) / np.maximum(m, 1e-30))
    spp_total = int(math.ceil(16 * (rel / target) ** 2))
    # 16 independent renders: the per-pixel s.e. then has 15 degrees of freedom (with 4, its
    # median over pixels would read ~11 % low — the median of a χ₃-distributed s.e. — and
    # the time scaled to the target ~20 % short).
    repeats = 16
    spp = max(1, int(math.ceil(spp_total / repeats)))
    imgs, wall, load, cpu, load_cpu = mitsuba_render(work, meshes, n, block, spp, repeats, threads, llvm)
    radiance = imgs.mean(0)
    se = imgs.std(0, ddof=1) / math.sqrt(repeats)
    # E = π L / ρ; image row r (top first) looks at z: with up = +Z the top row is z = Z.
    E = math.pi * radiance / RHO["floor"]
    se = math.pi * se / RHO["floor"]
    if RHO["floor"] == 0:
        raise RuntimeError("Mitsuba measures E = πL/ρ on the floor: needs ρ_floor > 0")
    # To the grid's order: rows of z increasing, x fastest (flip the image vertically
    # and, with the camera looking down −Y with up +Z, x grows to the left).
    E = E[::-1, ::-1].reshape(-1)
    se = se[::-1, ::-1].reshape(-1)
    return {"wall_time_s": wall, "fixed_time_s": load, "cpu_time_s": cpu, "fixed_cpu_s": load_cpu, "spp": spp * repeats, "variant": "llvm_ad_rgb" if llvm else "scalar_rgb", "E": E, "se": se}


# ----------------------------------------------------------------------------- main


def agreement(a, b):
    z = (a["E"] - b["E"]) / np.sqrt(a["se"] ** 2 + b["se"] ** 2 + 1e-300)
    rel = a["E"].mean() / b["E"].mean() - 1.0
    return {
        "mean_ratio_minus_1": rel,
        "fraction_within_3_sigma": float(np.mean(np.abs(z) < 3.0)),
        "median_abs_z": float(np.median(np.abs(z))),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--grid", type=int, default=100)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target", type=float, default=0.01)
    ap.add_argument("--prism", default=str(ROOT / "target" / "release" / "prism"), help="the prism binary (release build for timings)")
    ap.add_argument("--rho-scale", type=float, default=1.0, help="multiply every reflectance (0: direct light only, a check)")
    ap.add_argument("--direct-only", action="store_true", help="black walls, ceiling and furniture (a check of the direct light)")
    ap.add_argument("--block", type=int, default=0, help="measure only a block of B × B cells of the grid (0: all); times are then per point × grid² for the whole grid")
    ap.add_argument("--block-shift", type=int, default=0, help="move the block along x by this many cells from the centre")
    ap.add_argument("--keep", action="store_true", help="keep the generated scenes")
    ap.add_argument("--skip", default="", help="comma list of peers to skip: radiance,mitsuba")
    args = ap.parse_args()
    for k in RHO:
        RHO[k] *= args.rho_scale
    if args.direct_only:
        # Only the floor reflects: every peer measures direct light alone (a check).
        for k in RHO:
            if k != "floor":
                RHO[k] = 0.0
    skip = set(filter(None, args.skip.split(",")))
    work = pathlib.Path(tempfile.mkdtemp(prefix="prism-lighting-bench-"))
    tris = furniture()
    obj = work / "furniture.obj"
    write_obj(obj, tris)
    m = args.block or args.grid
    block = ((args.grid - m) // 2 + args.block_shift, (args.grid - m) // 2, m)
    points = grid_points(args.grid, block)
    result = {
        "scene": {
            "room_m": ROOM, "triangles": len(tris) + 12, "lights": len(LIGHTS),
            "grid": [args.grid, args.grid], "target_relative_se": args.target,
            "block": {"first_cell_xz": [block[0], block[1]], "size": block[2], "points": len(points)},
            "threads": args.threads, "max_depth": MAX_DEPTH,
        }
    }
    runs = {}
    runs["prism"] = run_prism(work, obj, args.grid, block, args.threads, args.target, args.prism)
    if "radiance" not in skip:
        try:
            runs["radiance"] = run_radiance(work, tris, points, args.threads, args.target)
            import pyradiance

            result["radiance_version"] = getattr(pyradiance, "__version__", "?")
        except Exception as e:  # noqa: BLE001
            result["radiance_error"] = repr(e)
    if "mitsuba" not in skip and mitsuba_python():
        try:
            runs["mitsuba"] = run_mitsuba(work, obj, args.grid, block, args.threads, args.target)
            result["mitsuba_version"] = "3.6.4 (tools/mitsuba/requirements.txt)"
        except subprocess.CalledProcessError as e:
            result["mitsuba_error"] = (e.stderr or b"").decode(errors="replace")[-2000:]
        except Exception as e:  # noqa: BLE001
            result["mitsuba_error"] = repr(e)
    for name, r in runs.items():
        rel = r["se"] / np.maximum(r["E"], 1e-30)
        result[name] = {
            k: v for k, v in r.items() if k not in ("E", "se")
        }
        result[name].update({
            "mean_E": float(r["E"].mean()),
            "median_relative_se": float(np.median(rel)),
            "p95_relative_se": float(np.percentile(rel, 95)),
        })
    # Whole grid: start-up once plus the per-point part times the number of points; and
    # the same scaled to reach the target exactly at the median point (cost ∝ 1/se²).
    scale = (args.grid * args.grid) / len(points)
    for name, r in runs.items():
        fixed = max(0.0, min(r["fixed_time_s"], r["wall_time_s"]))
        per_points = r["wall_time_s"] - fixed
        med = result[name]["median_relative_se"]
        result[name]["whole_grid_time_s"] = fixed + per_points * scale
        result[name]["whole_grid_time_s_at_target"] = fixed + per_points * scale * (med / args.target) ** 2
        fixed_cpu = max(0.0, min(r["fixed_cpu_s"], r["cpu_time_s"]))
        result[name]["whole_grid_cpu_s_at_target"] = (
            fixed_cpu + (r["cpu_time_s"] - fixed_cpu) * scale * (med / args.target) ** 2
        )
    for name in runs:
        if name != "prism":
            result[f"prism_vs_{name}"] = agreement(runs["prism"], runs[name])
            result[f"prism_speedup_vs_{name}_at_target"] = (
                result[name]["whole_grid_time_s_at_target"] / result["prism"]["whole_grid_time_s_at_target"]
            )
            result[f"prism_cpu_speedup_vs_{name}_at_target"] = (
                result[name]["whole_grid_cpu_s_at_target"] / result["prism"]["whole_grid_cpu_s_at_target"]
            )
    result["load_average_1_5_15_min"] = os.getloadavg()
    print(json.dumps(result, indent=2, default=float))
    if args.keep:
        print(f"kept {work}", file=sys.stderr)
    else:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Issue 20's check (a) of the photon reference: on scenes/stress/spot-fog-glass.json at
128×128, the mean over the pixels below the glass sphere where its caustic cone lands, from
`photon_progressive` at the reference budget of tools/photon_speed.py (1024 passes, about
200× the passes it needs for relMSE 0.05) against a long `path` run, within 4 standard
errors. `path` finds that light only by a BSDF sample through the sphere that hits the small
lamp (fireflies), so its standard error comes from independent seeds; so does the photon
reference's (its pixels share each pass's photons).

    python3 tools/photon_reference_check.py --prism target/release/prism   # renders, checks
    python3 tools/photon_reference_check.py --no-run                       # print the JSON

Writes tools/bench-results/photon-reference-check.json. Renders go to a temporary folder as
Radiance .hdr (read here with the standard library; 8-bit mantissas: < 0.4 % per pixel,
unbiased enough for a mean over 256 pixels). crates/render/tests/photon.rs
(`spot_fog_glass_caustic_cone_agrees_with_a_long_path_run`) is the same check at 16×16.
"""
import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULT = os.path.join(ROOT, "tools", "bench-results", "photon-reference-check.json")
# The caustic cone's pixels, as fractions of the image (x0, y0, x1, y1): the test's 16×16
# window (7, 9, 9, 11).
WINDOW = (7 / 16, 9 / 16, 9 / 16, 11 / 16)


def read_hdr(path):
    """(width, height, [(r, g, b)] row-major) of a Radiance RGBE file (run-length scanlines
    or flat)."""
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end]
        pos = end + 1
        if line == b"":
            break
    end = data.index(b"\n", pos)
    parts = data[pos:end].split()
    pos = end + 1
    if parts[0] != b"-Y" or parts[2] != b"+X":
        raise ValueError(f"{path}: unsupported orientation {parts}")
    height, width = int(parts[1]), int(parts[3])
    pixels = []
    for _ in range(height):
        if data[pos] == 2 and data[pos + 1] == 2 and (data[pos + 2] << 8 | data[pos + 3]) == width:
            pos += 4
            channels = []
            for _c in range(4):
                row = bytearray()
                while len(row) < width:
                    count = data[pos]
                    pos += 1
                    if count > 128:
                        row.extend(bytes([data[pos]]) * (count - 128))
                        pos += 1
                    else:
                        row.extend(data[pos:pos + count])
                        pos += count
                channels.append(row)
            rgbe = zip(*channels)
        else:
            rgbe = [tuple(data[pos + 4 * i:pos + 4 * i + 4]) for i in range(width)]
            pos += 4 * width
        for r, g, b, e in rgbe:
            if e == 0:
                pixels.append((0.0, 0.0, 0.0))
            else:
                s = math.ldexp(1.0, e - 136)
                pixels.append(((r + 0.5) * s, (g + 0.5) * s, (b + 0.5) * s))
    return width, height, pixels


def window_mean_y(path):
    """Mean luminance (linear Rec.709 Y) over WINDOW."""
    w, h, px = read_hdr(path)
    x0, y0, x1, y1 = (round(WINDOW[0] * w), round(WINDOW[1] * h),
                      round(WINDOW[2] * w), round(WINDOW[3] * h))
    total = 0.0
    for y in range(y0, y1):
        for x in range(x0, x1):
            r, g, b = px[y * w + x]
            total += 0.2126 * r + 0.7152 * g + 0.0722 * b
    return total / ((x1 - x0) * (y1 - y0))


def mean_se(values):
    return statistics.fmean(values), statistics.stdev(values) / math.sqrt(len(values))


def render(prism, scene, integrator, spp, seed, resolution, out):
    with open(scene) as f:
        description = json.load(f)
    description["integrator"] = integrator
    path = os.path.join(os.path.dirname(out), os.path.basename(out) + ".json")
    with open(path, "w") as f:
        json.dump(description, f)
    subprocess.run([prism, "render", path, "--resolution", f"{resolution}x{resolution}",
                    "--spp", str(spp), "--seed", str(seed), "-o", out], check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)


def children_cpu_s():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prism", default=os.path.join(ROOT, "target", "release", "prism"))
    ap.add_argument("--resolution", type=int, default=128)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--reference-seeds", type=int, default=2)
    ap.add_argument("--path-spp", type=int, default=512)
    ap.add_argument("--path-seeds", type=int, default=8)
    ap.add_argument("--no-run", action="store_true")
    args = ap.parse_args()
    if args.no_run:
        with open(RESULT) as f:
            print(f.read())
        return
    scene = os.path.join(ROOT, "scenes", "stress", "spot-fog-glass.json")
    scratch = tempfile.mkdtemp(prefix="photon-reference-check-")
    started = time.time()
    try:
        runs = {}
        for name, integrator, spp, seeds in (
                ("photon_progressive", {"type": "photon_progressive", "max_depth": 8},
                 args.reference_spp, args.reference_seeds),
                ("path", {"type": "path", "max_depth": 8, "sampler": "independent"},
                 args.path_spp, args.path_seeds)):
            means = []
            cpu_start = children_cpu_s()
            for k in range(seeds):
                seed = 7000 + 100 * k + (1 if name == "path" else 0)
                out = os.path.join(scratch, f"{name}-{k}.hdr")
                render(args.prism, scene, integrator, spp, seed, args.resolution, out)
                means.append(window_mean_y(out))
            mean, se = mean_se(means)
            runs[name] = {"spp_per_seed": spp, "seeds": seeds, "window_means": means,
                          "mean": mean, "standard_error": se,
                          "render_cpu_s": children_cpu_s() - cpu_start}
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    p, r = runs["photon_progressive"], runs["path"]
    se = math.hypot(p["standard_error"], r["standard_error"])
    difference = p["mean"] - r["mean"]
    summary = {
        "scene": "scenes/stress/spot-fog-glass.json",
        "resolution": [args.resolution, args.resolution],
        "window_fraction": list(WINDOW),
        "methods": runs,
        "difference": difference,
        "combined_standard_error": se,
        "difference_in_standard_errors": difference / se if se > 0 else None,
        "within_4_se": abs(difference) <= 4 * se,
        "wall_s": time.time() - started,
        "binary": "target/debug/prism (test profile)" if "debug" in args.prism
                  else os.path.relpath(args.prism, ROOT),
        "options": {"reference_spp": args.reference_spp,
                    "reference_seeds": args.reference_seeds,
                    "path_spp": args.path_spp, "path_seeds": args.path_seeds},
    }
    tmp = RESULT + ".tmp"
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=1)
        f.write("\n")
    os.replace(tmp, RESULT)
    json.dump(summary, sys.stdout, indent=1)
    print()
    if not summary["within_4_se"]:
        sys.exit(1)


if __name__ == "__main__":
    main()

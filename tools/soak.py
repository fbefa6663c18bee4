#!/usr/bin/env python3
"""Soak run: many renders, tone maps and compares with random valid options, in one
process tree, checking that nothing accumulates.

    cargo build --release
    python3 tools/soak.py [--runs 200] [--seed 1] [--no-file]

Each run is one `prism` process (render of a small example scene, tonemap of a render with
a random operator/white balance/gamut/target, or compare of two renders, with or without
--report). Measured per run: the process's peak RSS (wait4's ru_maxrss) and its open file
descriptors just before exit are not observable from outside, so the driver checks what a
leak would leave: its own open descriptors after every run (inherited pipes, temp files),
files left in the output directory that the command did not name (temporaries
`.NAME.PID.tmp`), and the slope of peak RSS against the run index per command kind (a
leak inside one process would not show here; one across runs of a cache or a temp
directory would). Prints one JSON object and writes tools/bench-results/soak.json.
"""

import argparse
import json
import os
import platform
import random
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRISM = os.path.join(ROOT, "target", "release", "prism")

SCENES = ["scenes/cornell-box.json", "scenes/minimal.json", "scenes/glossy-env.json",
          "scenes/material-gallery.json", "scenes/textures.json"]
OPERATORS = ["linear", "reinhard02", "drago03", "aces", "agx", "durand02", "logarithmic"]
WB = ["none", "grey-world", "white-patch", "illuminant:D65", "cct:4500"]
GAMUT = ["clip", "local-lch", "local-oklab", "global", "aces-rgc"]
TARGETS = ["srgb", "p3", "rec2020"]


def open_fds():
    return len(os.listdir("/proc/self/fd"))


def slope(points):
    n = len(points)
    if n < 2:
        return None
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    return sum((p[0] - mx) * (p[1] - my) for p in points) / sxx if sxx else None


def run(args, expected_outputs, work):
    before = set(os.listdir(work))
    start = time.time()
    proc = subprocess.Popen([PRISM, *args], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    stderr = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    left = set(os.listdir(work)) - before - {os.path.basename(p) for p in expected_outputs}
    return {
        "status": os.waitstatus_to_exitcode(status),
        "wall_s": time.time() - start,
        "max_rss_kib": usage.ru_maxrss,
        "unexpected_files": sorted(left),
        "stderr_tail": stderr[-300:],
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-file", action="store_true", help="do not write bench-results")
    opts = parser.parse_args()
    rng = random.Random(opts.seed)
    work = tempfile.mkdtemp(prefix="prism-soak-")
    fds_start = open_fds()
    base = [os.path.join(work, f"base{i}.exr") for i in range(2)]
    for i, path in enumerate(base):
        r = run(["render", "scenes/cornell-box.json", "--resolution", "48x36", "--spp",
                 str(4 * (i + 1)), "--seed", str(i + 1), "-o", path], [path], work)
        if r["status"] != 0:
            sys.exit(f"cannot render the base images: {r}")
    records = []
    for k in range(opts.runs):
        kind = rng.choice(["render", "tonemap", "compare"])
        if kind == "render":
            out = os.path.join(work, f"r{k}.exr")
            args = ["render", rng.choice(SCENES), "--resolution",
                    f"{rng.randint(8, 48)}x{rng.randint(8, 36)}", "--spp", str(rng.randint(1, 8)),
                    "--seed", str(rng.randint(0, 1000)), "-o", out]
            outputs = [out, out.replace(".exr", ".sensors.json"),
                       out.replace(".exr", ".sensors.csv")]
        elif kind == "tonemap":
            out = os.path.join(work, f"t{k}.png")
            args = ["tonemap", base[0], "-o", out, "--op", rng.choice(OPERATORS),
                    "--wb", rng.choice(WB), "--gamut", rng.choice(GAMUT),
                    "--target", rng.choice(TARGETS), "--exposure", "auto"]
            outputs = [out]
        else:
            args = ["compare", base[0], base[1], "--json"]
            outputs = []
            if rng.random() < 0.3:
                report = os.path.join(work, f"c{k}.html")
                args += ["--report", report]
                outputs.append(report)
        r = run(args, outputs, work)
        r.update({"run": k, "kind": kind, "args": args, "driver_fds": open_fds()})
        for path in outputs:
            if os.path.exists(path):
                os.remove(path)
        records.append(r)
    failures = [r for r in records if r["status"] != 0 or r["unexpected_files"]]
    by_kind = {}
    for kind in ["render", "tonemap", "compare"]:
        pts = [(r["run"], r["max_rss_kib"]) for r in records if r["kind"] == kind]
        s = slope(pts)
        by_kind[kind] = {
            "runs": len(pts),
            "max_rss_kib_first": pts[0][1] if pts else None,
            "max_rss_kib_last": pts[-1][1] if pts else None,
            "max_rss_kib_max": max((p[1] for p in pts), default=None),
            "max_rss_slope_kib_per_run": s,
        }
    left_in_work = sorted(set(os.listdir(work)) - {os.path.basename(p) for p in base})
    result = {
        "command": "python3 tools/soak.py " + " ".join(sys.argv[1:]),
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average_1min_at_end": os.getloadavg()[0]},
        "runs": opts.runs,
        "seed": opts.seed,
        "by_kind": by_kind,
        "driver_fds_start": fds_start,
        "driver_fds_end": open_fds(),
        "files_left_in_work_dir": left_in_work,
        "failures": [{k: r[k] for k in ("run", "kind", "args", "status",
                                         "unexpected_files", "stderr_tail")}
                     for r in failures],
    }
    text = json.dumps(result, indent=2)
    print(text)
    if not opts.no_file:
        out = os.path.join(ROOT, "tools", "bench-results", "soak.json")
        with open(out + ".tmp", "w") as f:
            f.write(text + "\n")
        os.replace(out + ".tmp", out)
    return 1 if failures or left_in_work else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Time FLIP of a 4K pair: Prism (tools/bench-post's bench-flip, rayon) against NVIDIA's
reference implementation's CPU path (flip-evaluator, OpenMP), both on the same pixels and
the same thread count, in one run; writes tools/bench-results/flip.json.

    python3 tools/bench_flip.py [--threads 2] [--runs 3]

Installs flip-evaluator 1.7 and numpy with pip when missing. Builds bench-flip with
`cargo build --release` (CARGO_TARGET_DIR honoured). Wall times are medians; on a
shared machine the process CPU time divided by the threads is the load-robust figure.
"""
import argparse
import importlib.metadata
import json
import os
import pathlib
import platform
import resource
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tools" / "bench-results" / "flip.json"


def ensure(package, version=None):
    try:
        importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        spec = f"{package}=={version}" if version else package
        subprocess.check_call([sys.executable, "-m", "pip", "install", spec])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    # The reference parallelises with OpenMP: same thread count as Prism's pool.
    os.environ["OMP_NUM_THREADS"] = str(args.threads)
    ensure("flip-evaluator", "1.7")
    ensure("numpy")
    import numpy as np

    import flip_evaluator

    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.check_call(
        ["cargo", "build", "--release", "-p", "bench-post", "--bin", "bench-flip"], cwd=ROOT
    )
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [str(target / "release" / "bench-flip"), tmp, str(args.threads), str(args.runs)]
        prism = json.loads(subprocess.check_output(cmd))
        shape = (prism["height"], prism["width"], 3)
        reference = np.fromfile(os.path.join(tmp, "flip-ref.f32"), "<f4").reshape(shape)
        test = np.fromfile(os.path.join(tmp, "flip-test.f32"), "<f4").reshape(shape)

    def cpu_s():
        u = resource.getrusage(resource.RUSAGE_SELF)
        return u.ru_utime + u.ru_stime

    def timed(fn):
        """(median wall s, median process CPU s, last result)"""
        times, cpus, result = [], [], None
        for _ in range(args.runs):
            start, cpu = time.perf_counter(), cpu_s()
            result = fn()
            times.append(time.perf_counter() - start)
            cpus.append(cpu_s() - cpu)
        mid = len(times) // 2
        return sorted(times)[mid], sorted(cpus)[mid], result

    ref_clip, test_clip = np.clip(reference, 0, 1), np.clip(test, 0, 1)
    ldr_s, ldr_cpu, (ldr_map, ldr_mean, _) = timed(
        lambda: flip_evaluator.evaluate(ref_clip, test_clip, "LDR", inputsRGB=False, applyMagma=False)
    )
    hdr_s, hdr_cpu, (hdr_map, hdr_mean, params) = timed(
        lambda: flip_evaluator.evaluate(reference, test, "HDR", inputsRGB=False, applyMagma=False)
    )
    result = {
        "what": "FLIP of a synthetic 3840x2160 HDR pair (tools/bench-post/src/bin/bench-flip.rs), "
        "default viewing condition (67.02 px/deg), LDR on the pair clipped to [0, 1]",
        "command": f"python3 tools/bench_flip.py --threads {args.threads} --runs {args.runs}",
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "load_average_1min_at_end": os.getloadavg()[0],
        },
        "prism": prism,
        "reference": {
            "tool": f"flip-evaluator {importlib.metadata.version('flip-evaluator')} (CPU, OpenMP)",
            "threads": args.threads,
            "ldr_wall_s": ldr_s,
            "hdr_wall_s": hdr_s,
            "ldr_cpu_s": ldr_cpu,
            "hdr_cpu_s": hdr_cpu,
            "ldr_mean": float(ldr_mean),
            "hdr_mean": float(hdr_mean),
            "hdr_exposures": int(params["numExposures"]),
            # The tool's own mean against the mean of its map summed in float64.
            "ldr_map_mean_f64": float(np.mean(ldr_map, dtype=np.float64)),
            "hdr_map_mean_f64": float(np.mean(hdr_map, dtype=np.float64)),
        },
        "ratio_reference_over_prism": {
            "ldr_wall": ldr_s / prism["ldr_wall_s"],
            "hdr_wall": hdr_s / prism["hdr_wall_s"],
            "ldr_cpu": ldr_cpu / prism["ldr_cpu_s"],
            "hdr_cpu": hdr_cpu / prism["hdr_cpu_s"],
        },
        "mean_relative_difference": {
            "ldr": abs(prism["ldr_mean"] - ldr_mean) / ldr_mean,
            "hdr": abs(prism["hdr_mean"] - hdr_mean) / hdr_mean,
        },
        "mean_relative_difference_to_map_mean_f64": {
            "ldr": abs(prism["ldr_mean"] - float(np.mean(ldr_map, dtype=np.float64)))
            / ldr_mean,
            "hdr": abs(prism["hdr_mean"] - float(np.mean(hdr_map, dtype=np.float64)))
            / hdr_mean,
        },
    }
    OUT.write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()

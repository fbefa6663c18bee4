#!/usr/bin/env python3
"""Same-run speed of FLIP on a 4K pair: an old and a new build of tools/bench-post's
bench-flip, run in alternating pairs (old, new, old, new, ...) so that the load of a
shared machine falls on both alike, and NVIDIA's reference implementation's CPU path
(flip-evaluator, OpenMP) on the same pixels in the same run; writes
tools/bench-results/flip-speed.json.

    python3 tools/bench_flip_speed.py --old OLD_BENCH_FLIP --new NEW_BENCH_FLIP \\
        [--threads 2] [--pairs 2] [--no-reference]

Build each binary with `cargo build --release -p bench-post --bin bench-flip` at the
commit to compare and copy it aside. Reports every run's wall and process CPU time, the
medians, the new/old ratios and the machine's load average before and after (on a busy
2-core machine CPU time divided by the threads is the load-robust figure). Installs
flip-evaluator 1.7 and numpy with pip when missing (as tools/bench_flip.py does).
"""
import argparse
import importlib.metadata
import json
import os
import pathlib
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tools" / "bench-results" / "flip-speed.json"


def ensure(package, version=None):
    try:
        importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        spec = f"{package}=={version}" if version else package
        subprocess.check_call([sys.executable, "-m", "pip", "install", spec])


def run_bench(binary, tmp, threads):
    """One run of bench-flip (1 repetition): its JSON."""
    out = subprocess.check_output([binary, tmp, str(threads), "1"])
    return json.loads(out)


def summary(runs):
    keys = ["ldr_wall_s", "hdr_wall_s", "ldr_cpu_s", "hdr_cpu_s"]
    return {f"median_{k}": statistics.median(r[k] for r in runs) for k in keys}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--old", required=True, help="bench-flip built from the old commit")
    parser.add_argument("--new", required=True, help="bench-flip built from the new commit")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--pairs", type=int, default=2)
    parser.add_argument("--no-reference", action="store_true")
    args = parser.parse_args()
    for name in ("old", "new"):
        if not os.access(getattr(args, name), os.X_OK):
            sys.exit(f"--{name} {getattr(args, name)}: not an executable file")
    if args.pairs < 1 or args.threads < 1:
        sys.exit("--pairs and --threads must be at least 1")
    os.environ["OMP_NUM_THREADS"] = str(args.threads)
    load_before = os.getloadavg()
    runs = {"old": [], "new": []}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.pairs):
            for name in ("old", "new"):
                runs[name].append(run_bench(getattr(args, name), tmp, args.threads))
        reference = None
        if not args.no_reference:
            ensure("flip-evaluator", "1.7")
            ensure("numpy")
            import numpy as np

            import flip_evaluator

            last = runs["new"][-1]
            shape = (last["height"], last["width"], 3)
            ref = np.fromfile(os.path.join(tmp, "flip-ref.f32"), "<f4").reshape(shape)
            test = np.fromfile(os.path.join(tmp, "flip-test.f32"), "<f4").reshape(shape)

            def cpu_s():
                u = resource.getrusage(resource.RUSAGE_SELF)
                return u.ru_utime + u.ru_stime

            def timed(fn):
                start, cpu = time.perf_counter(), cpu_s()
                _, mean, _ = fn()
                return time.perf_counter() - start, cpu_s() - cpu, float(mean)

            ldr = timed(
                lambda: flip_evaluator.evaluate(
                    np.clip(ref, 0, 1), np.clip(test, 0, 1), "LDR", inputsRGB=False, applyMagma=False
                )
            )
            hdr = timed(
                lambda: flip_evaluator.evaluate(ref, test, "HDR", inputsRGB=False, applyMagma=False)
            )
            reference = {
                "tool": f"flip-evaluator {importlib.metadata.version('flip-evaluator')} (CPU, OpenMP)",
                "threads": args.threads,
                "ldr_wall_s": ldr[0],
                "ldr_cpu_s": ldr[1],
                "ldr_mean": ldr[2],
                "hdr_wall_s": hdr[0],
                "hdr_cpu_s": hdr[1],
                "hdr_mean": hdr[2],
            }
    old, new = summary(runs["old"]), summary(runs["new"])
    result = {
        "what": "FLIP of bench-flip's synthetic 3840x2160 HDR pair (±20 % noise), default "
        "viewing condition (67.02 px/deg); old and new builds in alternating pairs, then the "
        "reference implementation once, all in one run",
        "command": "python3 tools/bench_flip_speed.py --old OLD --new NEW "
        f"--threads {args.threads} --pairs {args.pairs}",
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "load_average_before": load_before,
            "load_average_after": os.getloadavg(),
        },
        "old": {"runs": runs["old"], **old},
        "new": {"runs": runs["new"], **new},
        "new_over_old": {
            k.removeprefix("median_"): new[k] / old[k] for k in old
        },
        "reference": reference,
    }
    if reference is not None:
        result["reference_over_new"] = {
            k: reference[k] / new[f"median_{k}"]
            for k in ["ldr_wall_s", "hdr_wall_s", "ldr_cpu_s", "hdr_cpu_s"]
        }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp_out = OUT.with_suffix(".json.tmp")
    tmp_out.write_text(json.dumps(result, indent=2) + "\n")
    tmp_out.replace(OUT)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()

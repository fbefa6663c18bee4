#!/usr/bin/env python3
"""Speed benchmark of issue 4: the Cornell box at 256x256, 64 spp, T threads, rendered by
Prism and by Mitsuba 3 (scalar_spectral and llvm_ad_spectral), runs alternating, with each
image's RMSE against the common high-spp reference tests/fixtures/cornell_mitsuba_reference.exr.

  tools/mitsuba/.venv/bin/python tools/bench-cornell.py [--spp 64] [--threads 2] [--rounds 3]

Timing:
- Prism: the whole process `prism render scenes/cornell-box.json --spp N --threads T --seed S
  -o OUT.exr`, from start to exit (EXR written); one untimed run first (page cache).
- Mitsuba: `img = mi.render(scene, spp=N, seed=S); dr.eval(img)` alone, in a worker process
  per variant that loaded `mi.cornell_box()` and made one untimed warm-up render (JIT) first;
  the workers stay alive, so rounds alternate Prism / scalar / llvm without reloading.
Also the CPU seconds (user + system, all threads) of the same spans: on a shared, loaded
machine they are steadier than wall times.
Prints JSON: median seconds per renderer, Prism/Mitsuba ratios (wall and CPU), RMSE against
the reference, the load average at the start and the end.

RMSE = sqrt(mean over pixels and R, G, B of (image - reference)^2), also without the pixels
of the directly visible light (`rmse_excluding_light`), which hold ~75 % of the squared error
at 64 spp. Mitsuba's film writes
1.0010003 x Prism's values for the same radiance (MI_CIE_Y_NORMALIZATION = 1/106.7502594
instead of 1/int ybar = 1/106.857; docs/mitsuba.md), so Prism's images are compared with the
reference divided by that factor (`rmse`), and also as they are (`rmse_raw`).

Setup: bash tools/mitsuba/setup.sh; Prism: cargo build --release (the `path` integrator).
"""

import argparse
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "mitsuba"))
from common import find_libllvm, import_mitsuba  # noqa: E402

REFERENCE = ROOT / "tests" / "fixtures" / "cornell_mitsuba_reference.exr"
SCENE = ROOT / "scenes" / "cornell-box.json"
PRISM = ROOT / "target" / "release" / "prism"
# int ybar dlambda (1 nm, 360-830 nm) * MI_CIE_Y_NORMALIZATION: Mitsuba's pixel values over
# Prism's for the same spectral radiance.
MITSUBA_FILM_FACTOR = 106.85702933647141 / 106.7502593994140625


def read_exr(path):
    import numpy as np
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        if "RGB" in ch:
            img = ch["RGB"].pixels
        else:
            img = np.stack([ch[c].pixels for c in ("R", "G", "B")], axis=-1)
    return np.asarray(img, dtype=np.float64)


def rmse(img, ref, mask=None):
    """sqrt(mean over pixels (where mask) and R, G, B of (img - ref)^2)."""
    import numpy as np

    if img.shape != ref.shape:
        raise ValueError(f"image {img.shape} vs reference {ref.shape}")
    se = (img - ref) ** 2
    return float(np.sqrt(np.mean(se if mask is None else se[mask])))


def light_mask(ref):
    """Pixels of the directly visible light (reference mean RGB > 5; the walls stay < 1)."""
    return ref.mean(axis=-1) > 5.0


# ----------------------------------------------------------------------------- worker


def worker(variant, threads):
    """Loads the Cornell box in `variant`, then serves renders (`serve`)."""
    serve(variant, threads, lambda mi: (mi.cornell_box(), {}))


def serve(variant, threads, scene_dict):
    """Loads `scene_dict(mi)` → (dict, extra ready info) in `variant`, prints one JSON ready
    line, then renders on request (stdin lines `SPP SEED OUT.exr`, one JSON reply line
    each: render and CPU seconds of `mi.render` + `dr.eval`)."""
    mi = import_mitsuba()
    import drjit as dr
    import numpy as np

    mi.set_variant(variant)
    if threads:
        dr.set_thread_count(threads)
    t = time.perf_counter()
    d, extra = scene_dict(mi)
    scene = mi.load_dict(d)
    load_s = time.perf_counter() - t
    ready = {"ready": True, "variant": variant, "threads": dr.thread_count(), "load_s": load_s,
             **extra}
    print(json.dumps(ready), flush=True)
    for line in sys.stdin:
        spp, seed, out = line.split(maxsplit=2)
        t = time.perf_counter()
        c = time.process_time()
        img = mi.render(scene, spp=int(spp), seed=int(seed))
        dr.eval(img)
        dr.sync_thread()
        render_s = time.perf_counter() - t
        cpu_s = time.process_time() - c
        mi.Bitmap(np.array(img, dtype=np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
            out.strip()
        )
        print(json.dumps({"render_s": render_s, "cpu_s": cpu_s, "file": out.strip()}), flush=True)


class Worker:
    def __init__(self, variant, threads, spp, warmup_out):
        cmd = [sys.executable, __file__, "--worker", variant, "--threads", str(threads)]
        self.variant = variant
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.info = self._reply()
        t = time.perf_counter()
        self.warmup = self.render(spp, 999, warmup_out)
        self.info["warmup_render_s"] = self.warmup["render_s"]
        self.info["warmup_wall_s"] = time.perf_counter() - t

    def _reply(self):
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"Mitsuba worker {self.variant} died (see its error above)")
        return json.loads(line)

    def render(self, spp, seed, out):
        self.proc.stdin.write(f"{spp} {seed} {out}\n")
        self.proc.stdin.flush()
        return self._reply()

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


# ----------------------------------------------------------------------------- Prism


class PrismError(RuntimeError):
    pass


def prism_render(prism, scene, spp, threads, seed, out):
    if not prism.exists():
        raise PrismError(
            f"{prism} not found: build it with `cargo build --release` (needs the `path` integrator)"
        )
    cmd = [str(prism), "render", str(scene), "--spp", str(spp), "--threads", str(threads),
           "--seed", str(seed), "-o", str(out)]
    t = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0 or not pathlib.Path(out).exists():
        tail = (p.stderr or p.stdout).strip().splitlines()[-5:]
        raise PrismError(
            f"`{' '.join(cmd)}` failed (exit {p.returncode}): {' | '.join(tail)}. "
            "The Cornell box needs Prism's spectral path tracer (integrator `path`, lambert "
            "BSDF, area lights); until it lands only the Mitsuba half of this benchmark runs."
        )
    return wall, cpu


# ----------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1000, help="seed of round 1 (the reference used 0..63)")
    ap.add_argument("--variants", default="scalar_spectral,llvm_ad_spectral")
    ap.add_argument("--prism", type=pathlib.Path, default=PRISM)
    ap.add_argument("--scene", type=pathlib.Path, default=SCENE)
    ap.add_argument("--reference", type=pathlib.Path, default=REFERENCE)
    ap.add_argument("--out-dir", type=pathlib.Path, default=ROOT / "target" / "bench-cornell")
    ap.add_argument("--no-prism", action="store_true", help="benchmark Mitsuba only")
    ap.add_argument("--json", type=pathlib.Path,
                    help="also write the JSON here (tools/bench-results/bench-cornell.json keeps the latest run)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker(args.worker, args.threads)

    args.out_dir.mkdir(parents=True, exist_ok=True)
    ref = read_exr(args.reference)
    light = light_mask(ref)
    ref_meta_path = args.reference.with_suffix(".json")
    ref_meta = json.loads(ref_meta_path.read_text()) if ref_meta_path.exists() else {}

    variants = [v for v in args.variants.split(",") if v]
    if "llvm_ad_spectral" in variants and find_libllvm() is None:
        print("libLLVM 19 not found (tools/mitsuba/setup.sh installs it): skipping llvm_ad_spectral",
              file=sys.stderr)
        variants.remove("llvm_ad_spectral")

    prism_error = None
    if not args.no_prism:
        try:  # untimed first run: page cache, and fails early with a clear message
            prism_render(args.prism, args.scene, args.spp, args.threads, args.seed - 1,
                         args.out_dir / "prism-warmup.exr")
        except PrismError as e:
            prism_error = str(e)
            print(f"Prism: {e}", file=sys.stderr)

    workers = {}
    for v in variants:
        print(f"starting {v} (load + warm-up render)…", file=sys.stderr, flush=True)
        workers[v] = Worker(v, args.threads, args.spp, args.out_dir / f"{v}-warmup.exr")
        print(f"  {json.dumps(workers[v].info)}", file=sys.stderr, flush=True)

    names = (["prism"] if not args.no_prism and prism_error is None else []) + variants
    load_start = os.getloadavg()[0]
    times = {n: [] for n in names}
    cpu_times = {n: [] for n in names}
    errors = {n: [] for n in names}
    for r in range(args.rounds):
        seed = args.seed + r
        order = names[r % len(names):] + names[: r % len(names)]  # rotate who goes first
        for n in order:
            out = args.out_dir / f"{n}-round{r + 1}.exr"
            if n == "prism":
                t, cpu = prism_render(args.prism, args.scene, args.spp, args.threads, seed, out)
                target = ref / MITSUBA_FILM_FACTOR
            else:
                reply = workers[n].render(args.spp, seed, out)
                t, cpu = reply["render_s"], reply["cpu_s"]
                target = ref
            cpu_times[n].append(cpu)
            img = read_exr(out)
            errors[n].append((rmse(img, target), rmse(img, ref), rmse(img, target, ~light)))
            times[n].append(t)
            print(f"round {r + 1}: {n} {t:.3f} s ({cpu:.3f} CPU-s), RMSE {errors[n][-1][0]:.5f}",
                  file=sys.stderr, flush=True)
    for w in workers.values():
        w.close()

    result = {
        "benchmark": "Cornell box (mitsuba.cornell_box() / scenes/cornell-box.json)",
        "resolution": [256, 256],
        "spp": args.spp,
        "threads": args.threads,
        "rounds": args.rounds,
        "seeds": [args.seed, args.seed + args.rounds - 1],
        "reference": {
            "file": str(args.reference),
            "spp": ref_meta.get("spp"),
            "variant": ref_meta.get("variant"),
            "mitsuba_version": ref_meta.get("mitsuba_version"),
            "mean_rgb": ref.reshape(-1, 3).mean(0).tolist(),
            "light_pixels": int(light.sum()),
        },
        "timing": {
            "prism": "whole process, start to EXR written",
            "mitsuba": "mi.render + dr.eval only, after a warm-up render",
            "cpu_s": "user + system CPU seconds of all threads over the same span (Prism: "
                     "getrusage of the child process; Mitsuba: time.process_time of the worker)",
        },
        "load_average": os.getloadavg()[0],
        "load_average_start": load_start,
        "renderers": {},
        "ratios_prism_over_mitsuba": {},
        "cpu_ratios_prism_over_mitsuba": {},
    }
    for n in names:
        entry = {
            "median_s": statistics.median(times[n]),
            "times_s": [round(t, 4) for t in times[n]],
            "median_cpu_s": statistics.median(cpu_times[n]),
            "cpu_s": [round(t, 4) for t in cpu_times[n]],
            "rmse": statistics.median(e[0] for e in errors[n]),
            "rmse_excluding_light": statistics.median(e[2] for e in errors[n]),
            "mean_rgb": read_exr(args.out_dir / f"{n}-round1.exr").reshape(-1, 3).mean(0).tolist(),
        }
        if n == "prism":
            entry["rmse_raw"] = statistics.median(e[1] for e in errors[n])
            entry["rmse_note"] = ("against the reference / 1.0010003 (Mitsuba's film normalisation "
                                  "converted to Prism's); rmse_raw: against the reference as is")
        else:
            entry["warmup_render_s"] = workers[n].info["warmup_render_s"]
            entry["load_s"] = workers[n].info["load_s"]
            entry["threads_reported"] = workers[n].info["threads"]
        result["renderers"][n] = entry
    if "prism" in names:
        for v in variants:
            result["ratios_prism_over_mitsuba"][v] = (
                result["renderers"]["prism"]["median_s"] / result["renderers"][v]["median_s"]
            )
            result["cpu_ratios_prism_over_mitsuba"][v] = (
                result["renderers"]["prism"]["median_cpu_s"] / result["renderers"][v]["median_cpu_s"]
            )
    if prism_error:
        result["prism_error"] = prism_error
    text = json.dumps(result, indent=1)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")
    return 0 if prism_error is None or args.no_prism else 2


if __name__ == "__main__":
    sys.exit(main())

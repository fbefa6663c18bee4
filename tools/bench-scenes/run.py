#!/usr/bin/env python3
"""The speed suite of issue 22: six scenes, each rendered by Prism and by Mitsuba 3
(`scalar_spectral`, `llvm_ad_spectral`) at equal spp, alternating, with every image's RMSE
against a common high-spp Mitsuba reference.

    tools/mitsuba/.venv/bin/python tools/bench-scenes/run.py [--spp 64] [--threads 2]
        [--rounds 3] [--ref-spp 4096] [--scenes glossy-glass,textured,...]

Scenes: scenes/cornell-box.json and tools/bench-scenes/*.json (written by make_scenes.py,
whose generated assets — the 10⁶-triangle mesh, the sky map — are made here if missing).
Mitsuba gets each scene through tools/mitsuba/prism_scene.py (same geometry, spectra,
materials, camera, max depth and filter; what differs is printed as the scene's notes).

Timing (as tools/bench-cornell.py):
- Prism: the whole process `prism render SCENE --spp N --threads T --seed S -o OUT.exr`,
  start to exit; one untimed run first (page cache).
- Mitsuba: `mi.render(scene, spp=N, seed=S)` + `dr.eval` alone, in one worker process per
  variant that translated and loaded the scene and rendered once untimed (JIT warm-up).
Rounds rotate who goes first; the median of the rounds is reported.

Per scene: the time ratio Prism / Mitsuba at equal spp and the equal-error ratio
(t_Prism · MSE_Prism) / (t_Mitsuba · MSE_Mitsuba): below 1 Prism reaches the same error
sooner (for unbiased estimators MSE ∝ 1/time). MSE = mean over pixels and R, G, B of
(image − reference)², Prism's against the reference / 1.0010003 (Mitsuba's film constant,
docs/mitsuba.md). Also each renderer's per-channel mean over the reference's.

The reference: Mitsuba (`llvm_ad_spectral`, or `scalar_spectral` without libLLVM) at
--ref-spp, rendered in passes of 256 spp with distinct seeds and averaged, cached in
tools/bench-scenes/generated/references/ under a hash of the translated scene and its assets.

Writes the JSON to tools/bench-results/bench-scenes.json (overwritten; git keeps history).
Setup: bash tools/mitsuba/setup.sh; cargo build --release.
"""

import argparse
import hashlib
import importlib.util
import json
import math
import os
import pathlib
import statistics
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tools" / "mitsuba"))
sys.path.insert(0, str(HERE))
from common import find_libllvm, import_mitsuba  # noqa: E402
import make_scenes  # noqa: E402

_spec = importlib.util.spec_from_file_location("bench_cornell", ROOT / "tools" / "bench-cornell.py")
bench_cornell = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bench_cornell)
read_exr, rmse, prism_render, PrismError = (bench_cornell.read_exr, bench_cornell.rmse,
                                             bench_cornell.prism_render, bench_cornell.PrismError)
MITSUBA_FILM_FACTOR = bench_cornell.MITSUBA_FILM_FACTOR

SCENES = {
    "cornell-box": ROOT / "scenes" / "cornell-box.json",
    "glossy-glass": HERE / "glossy-glass.json",
    "textured": HERE / "textured.json",
    "mesh-env-sun": HERE / "mesh-env-sun.json",
    "many-lights": HERE / "many-lights.json",
    "defocus": HERE / "defocus.json",
}
REFERENCES = make_scenes.GENERATED / "references"
REF_PASS_SPP = 256
RESULT = ROOT / "tools" / "bench-results" / "bench-scenes.json"


# ----------------------------------------------------------------------------- worker


def worker(variant, threads, scene_path):
    """Translates and loads one scene in `variant`, then serves renders (bench-cornell's
    `serve`); the ready line carries the translation notes."""
    from prism_scene import translate

    def scene_dict(mi):
        d, notes = translate(mi, scene_path)
        return d, {"notes": notes}

    bench_cornell.serve(variant, threads, scene_dict)


class Worker(bench_cornell.Worker):
    """bench-cornell's worker protocol, started on one suite scene."""

    def __init__(self, variant, threads, scene_path):
        import subprocess

        cmd = [sys.executable, __file__, "--worker", variant, "--threads", str(threads),
               "--worker-scene", str(scene_path)]
        self.variant = variant
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.info = self._reply()

    def warm_up(self, spp, out):
        t = time.perf_counter()
        self.info["warmup_render_s"] = self.render(spp, 999, out)["render_s"]
        self.info["warmup_wall_s"] = time.perf_counter() - t


# ----------------------------------------------------------------------------- reference


def reference_key(scene_path, ref_spp, variant):
    """Hash of what Mitsuba renders: the translated scene (so editing the translator
    without changing its output keeps the cache), the generated assets it names, the spp
    and the variant."""
    from prism_scene import translate

    mi = import_mitsuba()
    mi.set_variant("scalar_spectral")
    translated, _ = translate(mi, scene_path)
    h = hashlib.sha256(json.dumps(translated, sort_keys=True, default=repr).encode())
    text = pathlib.Path(scene_path).read_text()
    for asset in sorted(make_scenes.GENERATED.glob("*.*")):
        if asset.name in text:
            h.update(asset.read_bytes())
    h.update(f"{ref_spp} {variant}".encode())
    return h.hexdigest()[:12]


def reference(name, scene_path, ref_spp, variant, threads, out_dir):
    """(image, metadata) of the scene's Mitsuba reference, rendered if not cached."""
    import numpy as np

    REFERENCES.mkdir(parents=True, exist_ok=True)
    key = reference_key(scene_path, ref_spp, variant)
    exr = REFERENCES / f"{name}-{variant}-{ref_spp}spp-{key}.exr"
    meta_path = exr.with_suffix(".json")
    if exr.exists() and meta_path.exists():
        return read_exr(exr), json.loads(meta_path.read_text())
    passes = max(1, math.ceil(ref_spp / REF_PASS_SPP))
    print(f"{name}: rendering the reference ({variant}, {passes} × {REF_PASS_SPP} spp)…",
          file=sys.stderr, flush=True)
    w = Worker(variant, threads, scene_path)
    acc, t = None, time.perf_counter()
    for k in range(passes):
        part = out_dir / f"{name}-ref-pass.exr"
        w.render(REF_PASS_SPP, 1_000_000 + k, part)
        img = read_exr(part)
        acc = img if acc is None else acc + img
        print(f"  pass {k + 1}/{passes}", file=sys.stderr, flush=True)
    w.close()
    acc /= passes
    mi = import_mitsuba()
    mi.set_variant("scalar_rgb")
    tmp = exr.with_name(exr.stem + ".tmp.exr")
    mi.Bitmap(acc.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(tmp))
    tmp.replace(exr)
    meta = {"variant": variant, "spp": passes * REF_PASS_SPP, "passes": passes,
            "seeds": [1_000_000, 1_000_000 + passes - 1], "mitsuba_version": mi.__version__,
            "render_s": time.perf_counter() - t, "scene": str(scene_path.relative_to(ROOT))}
    meta_path.write_text(json.dumps(meta, indent=1) + "\n")
    return read_exr(exr), meta


# ----------------------------------------------------------------------------- one scene


def bench_scene(name, scene_path, args, variants, ref_variant):
    import numpy as np

    out_dir = args.out_dir / name
    out_dir.mkdir(parents=True, exist_ok=True)
    ref, ref_meta = reference(name, scene_path, args.ref_spp, ref_variant, args.threads, out_dir)
    ref_mean = ref.reshape(-1, 3).mean(0)

    prism_render(args.prism, scene_path, args.spp, args.threads, args.seed - 1,
                 out_dir / "prism-warmup.exr")
    workers = {}
    for v in variants:
        print(f"{name}: starting {v} (translate, load, warm-up render)…", file=sys.stderr, flush=True)
        workers[v] = Worker(v, args.threads, scene_path)
        workers[v].warm_up(args.spp, out_dir / f"{v}-warmup.exr")

    names = ["prism"] + variants
    times = {n: [] for n in names}
    cpu = {n: [] for n in names}
    mse = {n: [] for n in names}
    means = {n: [] for n in names}
    for r in range(args.rounds):
        seed = args.seed + r
        for n in names[r % len(names):] + names[: r % len(names)]:
            out = out_dir / f"{n}-round{r + 1}.exr"
            if n == "prism":
                t, c = prism_render(args.prism, scene_path, args.spp, args.threads, seed, out)
                target = ref / MITSUBA_FILM_FACTOR
            else:
                reply = workers[n].render(args.spp, seed, out)
                t, c = reply["render_s"], reply["cpu_s"]
                target = ref
            img = read_exr(out)
            times[n].append(t)
            cpu[n].append(c)
            mse[n].append(rmse(img, target) ** 2)
            means[n].append(img.reshape(-1, 3).mean(0) / target.reshape(-1, 3).mean(0))
            print(f"{name} round {r + 1}: {n} {t:.3f} s, RMSE {math.sqrt(mse[n][-1]):.4g}",
                  file=sys.stderr, flush=True)
    notes = workers[variants[0]].info["notes"] if variants else []
    for w in workers.values():
        w.close()

    entry = {
        "scene": str(scene_path.relative_to(ROOT)),
        "resolution": list(ref.shape[1::-1]),
        "reference": {**ref_meta, "mean_rgb": ref_mean.tolist()},
        "translation_notes": notes,
        "renderers": {},
        "time_ratio_at_equal_spp": {},
        "equal_error_ratio": {},
    }
    for n in names:
        e = {
            "median_s": statistics.median(times[n]),
            "times_s": [round(t, 4) for t in times[n]],
            "median_cpu_s": statistics.median(cpu[n]),
            "median_mse": statistics.median(mse[n]),
            "mse": [float(f"{m:.6g}") for m in mse[n]],
            "mean_over_reference_rgb": np.mean(means[n], axis=0).round(5).tolist(),
        }
        if n != "prism":
            e["load_s"] = workers[n].info["load_s"]
            e["warmup_render_s"] = workers[n].info["warmup_render_s"]
        entry["renderers"][n] = e
    p = entry["renderers"]["prism"]
    for v in variants:
        m = entry["renderers"][v]
        entry["time_ratio_at_equal_spp"][v] = p["median_s"] / m["median_s"]
        entry["equal_error_ratio"][v] = (p["median_s"] * p["median_mse"]) / (m["median_s"] * m["median_mse"])
    entry["prism_mean_within_1pct"] = bool(np.all(np.abs(np.array(p["mean_over_reference_rgb"]) - 1) <= 0.01))
    return entry


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1000)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated: " + ", ".join(SCENES))
    ap.add_argument("--variants", default="scalar_spectral,llvm_ad_spectral")
    ap.add_argument("--prism", type=pathlib.Path, default=bench_cornell.PRISM)
    ap.add_argument("--out-dir", type=pathlib.Path, default=ROOT / "target" / "bench-scenes")
    ap.add_argument("--json", type=pathlib.Path, default=RESULT)
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--worker-scene", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker(args.worker, args.threads, args.worker_scene)

    make_scenes.make_assets()
    names = [s for s in args.scenes.split(",") if s]
    unknown = [s for s in names if s not in SCENES]
    if unknown:
        ap.error(f"unknown scene(s) {unknown}; the suite has {list(SCENES)}")
    variants = [v for v in args.variants.split(",") if v]
    have_llvm = find_libllvm() is not None
    if "llvm_ad_spectral" in variants and not have_llvm:
        print("libLLVM 19 not found (tools/mitsuba/setup.sh installs it): skipping llvm_ad_spectral",
              file=sys.stderr)
        variants.remove("llvm_ad_spectral")
    ref_variant = "llvm_ad_spectral" if have_llvm else "scalar_spectral"
    if not args.prism.exists():
        raise PrismError(f"{args.prism} not found: cargo build --release")

    load_start = os.getloadavg()
    scenes = {}
    for n in names:
        scenes[n] = bench_scene(n, SCENES[n], args, variants, ref_variant)
    result = {
        "benchmark": "issue 22 speed suite (tools/bench-scenes/run.py)",
        "command": "tools/mitsuba/.venv/bin/python tools/bench-scenes/run.py " + " ".join(sys.argv[1:]),
        "spp": args.spp, "threads": args.threads, "rounds": args.rounds,
        "seeds": [args.seed, args.seed + args.rounds - 1],
        "timing": {
            "prism": "whole process `prism render`, start to EXR written",
            "mitsuba": "mi.render + dr.eval only, after translation, load and a warm-up render",
            "equal_error_ratio": "(t_prism · MSE_prism) / (t_mitsuba · MSE_mitsuba), medians of the rounds",
        },
        "machine": {"cpus": os.cpu_count(), "load_average_start": load_start,
                    "load_average_end": os.getloadavg()},
        "scenes": scenes,
        "summary": {},
    }
    for v in variants:
        ratios = [s["equal_error_ratio"][v] for s in scenes.values()]
        result["summary"][v] = {
            "equal_error_ratio_geometric_mean": math.exp(statistics.mean(math.log(r) for r in ratios)),
            "equal_error_ratio_worst": max(ratios),
            "time_ratio_at_equal_spp_geometric_mean": math.exp(statistics.mean(
                math.log(s["time_ratio_at_equal_spp"][v]) for s in scenes.values())),
        }
    targets = {"llvm_ad_spectral": 0.5, "scalar_spectral": 0.25}
    result["targets"] = {
        f"equal_error_geomean_vs_{v}_le_{t}": result["summary"][v]["equal_error_ratio_geometric_mean"] <= t
        for v, t in targets.items() if v in result["summary"]}
    if "llvm_ad_spectral" in result["summary"]:
        result["targets"]["equal_error_every_scene_vs_llvm_ad_spectral_le_1"] = (
            result["summary"]["llvm_ad_spectral"]["equal_error_ratio_worst"] <= 1)
    result["targets"]["prism_mean_within_1pct_every_scene"] = all(
        s["prism_mean_within_1pct"] for s in scenes.values())
    text = json.dumps(result, indent=1)
    print(text)
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        tmp = args.json.with_suffix(".tmp")
        tmp.write_text(text + "\n")
        tmp.replace(args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())

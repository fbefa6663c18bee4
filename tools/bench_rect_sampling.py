#!/usr/bin/env python3
"""Equal-error benchmark of a rectangle emitter seen from close by: this build (solid-angle
sampling near rectangles, docs/lights.md) against another build of Prism (`--baseline`,
e.g. one from before that change, which sampled rectangles uniformly in area). The scene,
written here into a temporary folder, is a 4 x 2.5 x 4 m room of Lambertian walls lit by a
1.2 x 0.6 m ceiling panel 0.4 m from the back wall (128 x 128, Gaussian splatting, max
depth 5). Renders a reference with this build at --reference-spp, then --rounds rounds of
both builds alternately at --spp (whole `prism render` process, seed = 1000 + round), each
scored by `prism compare`'s MSE against the reference. Prints and writes
tools/bench-results/rect-solid-angle.json: per round time and MSE, the medians and the
equal-error ratio (time x MSE) this build / baseline (below 1: this build reaches equal
error sooner).

    git worktree add /tmp/prism-before <commit> && (cd /tmp/prism-before && cargo build --release)
    python3 tools/bench_rect_sampling.py --baseline /tmp/prism-before/target/release/prism \\
        [--spp 64] [--rounds 5] [--reference-spp 4096]
"""
import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import tempfile
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_results  # noqa: E402

ROOT = pathlib.Path(bench_results.ROOT)


def rect(size, material, transform, name=None):
    shape = {"type": "rectangle", "size_m": size, "material": material, "transform": transform}
    if name:
        shape["name"] = name
    return shape


def rotate(axis, deg):
    return {"rotate": {"axis": axis, "angle_deg": deg}}


SCENE = {
    "camera": {"type": "pinhole", "fov_deg": 65,
               "transform": {"look_at": {"eye": [1.6, 1.3, 2.6], "target": [-0.8, 1.3, -1.2]}}},
    "film": {"resolution": [128, 128], "spp": 64, "reconstruction": "splat",
             "filter": {"type": "gaussian", "radius_px": 2, "sigma_px": 0.5}},
    "integrator": {"type": "path", "max_depth": 5, "rr_depth": 5},
    "materials": {
        "white": {"type": "lambert", "reflectance": 0.7},
        "wall": {"type": "lambert", "reflectance": {"rgb": [0.6, 0.55, 0.5]}},
        "black": {"type": "lambert", "reflectance": 0},
    },
    "shapes": [
        rect([4, 4], "white", [rotate([1, 0, 0], -90)]),
        rect([4, 2.5], "wall", [{"translate": [0, 1.25, -2]}]),
        rect([4, 2.5], "wall", [rotate([0, 1, 0], 90), {"translate": [-2, 1.25, 0]}]),
        rect([4, 4], "white", [rotate([1, 0, 0], 90), {"translate": [0, 2.5, 0]}]),
        rect([1.2, 0.6], "black", [rotate([1, 0, 0], 90), {"translate": [-1.2, 2.45, -1.6]}],
             name="panel"),
    ],
    "lights": [{"type": "area", "shape": "panel", "luminance_cd_m2": 2000, "spectrum": "D65"}],
}


def prism():
    subprocess.check_call(["cargo", "build", "--release", "-q"], cwd=ROOT)
    return str(ROOT / "target" / "release" / "prism")


def render(binary, scene, out, spp, seed, threads):
    """Wall time of the whole `prism render` process, s."""
    start = time.perf_counter()
    subprocess.check_call(
        [binary, "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", str(seed),
         "--threads", str(threads), "--progress", "none"],
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - start


def mse(binary, image, reference):
    out = json.loads(
        subprocess.check_output([binary, "compare", str(image), str(reference), "--json"])
    )
    return out["mse"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--baseline", required=True,
                        help="a prism binary of the build to compare against")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    if not os.access(args.baseline, os.X_OK):
        raise SystemExit(f"--baseline {args.baseline}: not an executable file")
    builds = {"this": prism(), "baseline": args.baseline}
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        scene = tmp / "near-panel.json"
        scene.write_text(json.dumps(SCENE))
        reference = tmp / "reference.exr"
        reference_s = render(builds["this"], scene, reference, args.reference_spp, 77,
                             args.threads)
        rounds = []
        for r in range(args.rounds):
            row = {"round": r}
            for name in ["baseline", "this"]:
                image = tmp / f"{name}-{r}.exr"
                t = render(builds[name], scene, image, args.spp, 1000 + r, args.threads)
                e = mse(builds["this"], image, reference)
                row[name] = {"wall_s": t, "mse": e, "time_x_mse": t * e}
            rounds.append(row)
            print(json.dumps(row))
    med = {name: {k: statistics.median(r[name][k] for r in rounds)
                  for k in ["wall_s", "mse", "time_x_mse"]}
           for name in ["baseline", "this"]}
    result = {
        "what": "a ceiling panel 0.4 m from a wall (128x128, Lambertian room): this build "
                "against --baseline at equal spp, MSE against a reference of this build; "
                "equal-error ratio = (time x MSE) this / baseline",
        "command": f"python3 tools/bench_rect_sampling.py --baseline BASELINE --spp {args.spp} "
                   f"--rounds {args.rounds} --reference-spp {args.reference_spp}",
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average_before": load_before, "load_average_after": os.getloadavg()},
        "spp": args.spp,
        "threads": args.threads,
        "reference_spp": args.reference_spp,
        "reference_wall_s": reference_s,
        "rounds": rounds,
        "medians": med,
        "equal_error_ratio_this_over_baseline":
            med["this"]["time_x_mse"] / med["baseline"]["time_x_mse"],
        "time_ratio_this_over_baseline": med["this"]["wall_s"] / med["baseline"]["wall_s"],
        "mse_ratio_this_over_baseline": med["this"]["mse"] / med["baseline"]["mse"],
    }
    bench_results.write("rect-solid-angle", result)
    print(json.dumps({k: result[k] for k in ["equal_error_ratio_this_over_baseline",
                                             "time_ratio_this_over_baseline",
                                             "mse_ratio_this_over_baseline"]}))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Equal-error benchmark of light selection (issue 22's scene 5): the light BVH against
choosing lights in proportion to power, on scenes/many-lights/open-office.json (120
luminaires). Renders a reference with the BVH at --reference-spp, then --rounds rounds of
`prism render --light-selection power` and `--light-selection bvh` alternately at --spp
(seed = round), each timed by its own wall_time_s and scored by `prism compare`'s MSE
against the reference. Prints and writes tools/bench-results/light-selection.json: per
round time, MSE and time × MSE, and the medians' ratio bvh / power (below 1: the BVH
reaches equal error sooner).

    python3 tools/bench_light_selection.py [--spp 16] [--rounds 3] [--reference-spp 512]
"""
import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "many-lights" / "open-office.json"
OUT = ROOT / "tools" / "bench-results" / "light-selection.json"


def prism():
    subprocess.check_call(["cargo", "build", "--release", "-q"], cwd=ROOT)
    return str(ROOT / "target" / "release" / "prism")


def render(binary, out, selection, spp, seed, threads):
    stats = out.with_suffix(".stats.json")
    subprocess.check_call(
        [binary, "render", str(SCENE), "-o", str(out), "--light-selection", selection,
         "--spp", str(spp), "--seed", str(seed), "--threads", str(threads),
         "--stats-json", str(stats), "--progress", "none"],
        stdout=subprocess.DEVNULL,
    )
    return json.loads(stats.read_text())["wall_time_s"]


def errors(binary, image, reference):
    """`prism compare`'s MSE and relMSE of `image` against `reference`."""
    out = json.loads(
        subprocess.check_output([binary, "compare", str(image), str(reference), "--json"])
    )
    return out["mse"], out["relmse"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--reference-spp", type=int, default=512)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    binary = prism()
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        reference = tmp / "reference.exr"
        reference_s = render(binary, reference, "bvh", args.reference_spp, 1000, args.threads)
        rounds = []
        for r in range(args.rounds):
            row = {"round": r}
            for selection in ["power", "bvh"]:
                image = tmp / f"{selection}-{r}.exr"
                t = render(binary, image, selection, args.spp, r, args.threads)
                e, rel = errors(binary, image, reference)
                row[selection] = {"wall_s": t, "mse": e, "relmse": rel, "time_x_mse": t * e,
                                  "time_x_relmse": t * rel}
            rounds.append(row)
            print(json.dumps(row))
    med = {
        s: {k: statistics.median(r[s][k] for r in rounds)
            for k in ["wall_s", "mse", "relmse", "time_x_mse", "time_x_relmse"]}
        for s in ["power", "bvh"]
    }
    result = {
        "what": "light selection on scenes/many-lights/open-office.json (320x180, 120 "
                "luminaires): the light BVH against power, equal spp, MSE against a BVH "
                "reference; equal-error ratio = (time x MSE) bvh / power, and with relMSE",
        "command": f"python3 tools/bench_light_selection.py --spp {args.spp} --rounds "
                   f"{args.rounds} --reference-spp {args.reference_spp}",
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "load_average_before": load_before,
                    "load_average_after": os.getloadavg()},
        "spp": args.spp,
        "threads": args.threads,
        "reference_spp": args.reference_spp,
        "reference_wall_s": reference_s,
        "rounds": rounds,
        "medians": med,
        "equal_error_ratio_bvh_over_power": med["bvh"]["time_x_mse"] / med["power"]["time_x_mse"],
        "equal_relmse_ratio_bvh_over_power":
            med["bvh"]["time_x_relmse"] / med["power"]["time_x_relmse"],
        "time_ratio_bvh_over_power": med["bvh"]["wall_s"] / med["power"]["wall_s"],
        "mse_ratio_bvh_over_power": med["bvh"]["mse"] / med["power"]["mse"],
    }
    OUT.write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps({k: result[k] for k in ["equal_error_ratio_bvh_over_power",
                                             "equal_relmse_ratio_bvh_over_power",
                                             "time_ratio_bvh_over_power",
                                             "mse_ratio_bvh_over_power"]}))


if __name__ == "__main__":
    main()

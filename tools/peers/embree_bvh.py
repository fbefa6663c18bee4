#!/usr/bin/env python3
"""Closest-hit rate of Prism's BVH against Intel Embree 4 (through `embreex`) on the same
10⁶-triangle mesh and the same 2²⁰ incoherent rays, one thread each, runs alternating in one
process tree (issue 22: Prism ≥ 0.9× Embree's rate per thread).

    bash tools/peers/setup.sh && cargo build --release -p bench-bvh
    tools/peers/.venv/bin/python tools/peers/embree_bvh.py [--rounds 5]

The workload is bench-bvh's (tools/bench-bvh: the displaced uv sphere 501 × 1000, rays with
origins uniform in a cube 3 r wide and directions uniform on the sphere, seed 1):
`bench-bvh --peer DIR` writes it to DIR, builds Prism's default BVH and then times, per
request, one single-thread pass over all rays one at a time (`Geometry::intersect`) and one
as a ray stream (`Geometry::intersect_stream`, eight rays in flight, interleaved; each hit
checked equal to the one-ray hit). Embree gets the same vertices, indices and
rays (`embreex.rtcore_scene.EmbreeScene.run`, a loop of `rtcIntersect1` over the rays on the
calling thread; t_near 0 and t_far ∞, as the rays'; Embree 4 has no stream API, and its
packets of 4–16 rays are for coherent rays). Build times are not compared (Embree
builds with its own thread pool). Both must report the same number of hits.

Prints JSON and writes tools/bench-results/bvh-embree.json (latest run; git keeps history).
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
BENCH_BVH = ROOT / "target" / "release" / "bench-bvh"
RESULT = ROOT / "tools" / "bench-results" / "bvh-embree.json"
TARGET_RATIO = 0.9


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--bench-bvh", type=pathlib.Path, default=BENCH_BVH)
    ap.add_argument("--workload", type=pathlib.Path, default=ROOT / "target" / "bvh-peer")
    ap.add_argument("--json", type=pathlib.Path, default=RESULT)
    args = ap.parse_args()

    import numpy as np
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    if not args.bench_bvh.exists():
        sys.exit(f"{args.bench_bvh} not found: cargo build --release -p bench-bvh")
    load_start = os.getloadavg()
    prism = subprocess.Popen([str(args.bench_bvh), "--peer", str(args.workload)],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    ready = json.loads(prism.stdout.readline())

    def prism_run():
        prism.stdin.write("go\n")
        prism.stdin.flush()
        return json.loads(prism.stdout.readline())

    vertices = np.fromfile(args.workload / "vertices.f32", dtype="<f4").reshape(-1, 3)
    indices = np.fromfile(args.workload / "indices.u32", dtype="<u4").reshape(-1, 3)
    rays = np.fromfile(args.workload / "rays.f32", dtype="<f4").reshape(-1, 8)
    if not (np.all(rays[:, 3] == 0) and np.all(np.isinf(rays[:, 7]))):
        sys.exit("the workload's rays must have t_min 0 and t_max ∞ (embreex fixes both)")
    origins = np.ascontiguousarray(rays[:, 0:3])
    directions = np.ascontiguousarray(rays[:, 4:7])

    t = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, vertices, indices.astype(np.int32))
    scene.run(origins[:1], directions[:1])  # commits the scene (builds the BVH)
    embree_build_s = time.perf_counter() - t

    def embree_run():
        t = time.perf_counter()
        ids = scene.run(origins, directions)
        return {"seconds": time.perf_counter() - t, "hits": int(np.count_nonzero(ids >= 0))}

    runs = {"prism": [], "prism_stream": [], "embree": []}
    hits = {"prism": set(), "prism_stream": set(), "embree": set()}
    stream_same = True
    for r in range(args.rounds):
        order = [("prism", prism_run), ("embree", embree_run)]
        for name, run in order if r % 2 == 0 else order[::-1]:
            out = run()
            results = [(name, out)]
            if name == "prism":
                results.append(("prism_stream", {"seconds": out["stream_seconds"],
                                                 "hits": out["stream_hits"]}))
                stream_same = stream_same and out["stream_same_hits"]
            for n, o in results:
                runs[n].append(o["seconds"])
                hits[n].add(o["hits"])
                print(f"round {r + 1}: {n} {len(rays) / o['seconds'] / 1e6:.2f} M rays/s",
                      file=sys.stderr, flush=True)
    prism.stdin.close()
    prism.wait()

    def rate(name):
        return len(rays) / statistics.median(runs[name]) / 1e6

    ratio = rate("prism") / rate("embree")
    stream_ratio = rate("prism_stream") / rate("embree")
    result = {
        "benchmark": "closest hit, 2^20 incoherent rays, 10^6-triangle displaced sphere, 1 thread each",
        "command": "tools/peers/.venv/bin/python tools/peers/embree_bvh.py " + " ".join(sys.argv[1:]),
        "peer": {"embreex": _version("embreex"), "embree": "4 (bundled with embreex)"},
        "prism_bvh": {"preset": ready["preset"], "build_s": round(ready["build_s"], 3)},
        "embree_build_s_all_threads": round(embree_build_s, 3),
        "rounds": args.rounds,
        "mrays_per_s_median": {k: round(rate(k), 3) for k in runs},
        "seconds": {k: [round(x, 4) for x in v] for k, v in runs.items()},
        "hits": {k: sorted(v) for k, v in hits.items()},
        "prism_over_embree": round(ratio, 3),
        "prism_stream_over_embree": round(stream_ratio, 3),
        "prism_stream_hits_equal_one_ray_hits": stream_same,
        "target_prism_over_embree": TARGET_RATIO,
        "target_met": {"one_ray_at_a_time": ratio >= TARGET_RATIO,
                       "stream": stream_ratio >= TARGET_RATIO},
        "load_average_start": load_start,
        "load_average_end": os.getloadavg(),
    }
    if not (hits["prism"] == hits["prism_stream"] == hits["embree"]) or not stream_same:
        result["warning"] = "the two found a different number of hits"
    text = json.dumps(result, indent=1)
    print(text)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.json.with_suffix(".tmp")
    tmp.write_text(text + "\n")
    tmp.replace(args.json)


def _version(package):
    from importlib.metadata import version

    return version(package)


if __name__ == "__main__":
    main()

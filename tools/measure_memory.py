#!/usr/bin/env python3
"""Peak memory per pixel of `prism compare` (plain, `--report`, `--tmqi`) and `prism
tonemap` on large float EXRs (needs numpy: `pip install numpy`).

    cargo build --release
    python3 tools/measure_memory.py [--large 8192] [--small 1024] [--prism PATH]
        [--tonemap-ops reinhard02,aces,durand02] [--skip-compare] [--skip-report]
        [--skip-tmqi]

Writes two float RGB EXRs per size (uncompressed scan lines, written here with numpy: a
smooth image with noise as the reference, the same with multiplicative noise as the test)
into a temporary folder (PRISM_MEASURE_DIR, else the system's), runs each command once per
size as its own process and reads its peak RSS from wait4's ru_maxrss. The figure per
pixel is the growth between the sizes, (peak(large) − peak(small)) / (large² − small²): the
baseline (the binary, its tables, thread stacks, a strip of rows) cancels. The images are
deleted at the end. Prints one JSON object and writes tools/bench-results/memory.json,
where commands not run this time keep their last result.
"""

import argparse
import json
import os
import platform
import struct
import subprocess
import sys
import tempfile
import time


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def exr_attribute(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def write_exr(path, rgb):
    """An uncompressed, one-part, scan-line OpenEXR of float channels B, G, R."""
    import numpy as np  # only in the child that makes the images
    h, w, _ = rgb.shape
    channels = b""
    for name in (b"B", b"G", b"R"):
        # name, pixel type 2 (float), pLinear + reserved, x/y sampling 1.
        channels += name + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1)
    channels += b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = b"".join([
        struct.pack("<ii", 20000630, 2),
        exr_attribute("channels", "chlist", channels),
        exr_attribute("compression", "compression", b"\0"),
        exr_attribute("dataWindow", "box2i", box),
        exr_attribute("displayWindow", "box2i", box),
        exr_attribute("lineOrder", "lineOrder", b"\0"),
        exr_attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        exr_attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        exr_attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)),
        b"\0",
    ])
    line_bytes = 8 + 3 * 4 * w
    first = len(header) + 8 * h
    offsets = np.arange(h, dtype=np.uint64) * line_bytes + first
    with open(path, "wb") as f:
        f.write(header)
        f.write(offsets.astype("<u8").tobytes())
        for y0 in range(0, h, 256):
            rows = rgb[y0:y0 + 256]
            n = rows.shape[0]
            block = np.empty((n, line_bytes), dtype=np.uint8)
            block[:, 0:4] = np.frombuffer(
                np.arange(y0, y0 + n, dtype="<i4").tobytes(), dtype=np.uint8).reshape(n, 4)
            block[:, 4:8] = np.frombuffer(struct.pack("<i", 3 * 4 * w), dtype=np.uint8)
            for k, c in enumerate((2, 1, 0)):
                plane = np.ascontiguousarray(rows[:, :, c], dtype="<f4")
                block[:, 8 + k * 4 * w:8 + (k + 1) * 4 * w] = plane.view(np.uint8)
            f.write(block.tobytes())


def make_pair(size, folder):
    """Writes test-SIZE.exr and reference-SIZE.exr into `folder`."""
    import numpy as np  # only in the child that makes the images
    rng = np.random.default_rng(size)
    reference_path = os.path.join(folder, f"reference-{size}.exr")
    test_path = os.path.join(folder, f"test-{size}.exr")
    x = np.linspace(0.0, 8.0, size, dtype=np.float32)
    for path, noise in ((reference_path, 0.0), (test_path, 0.2)):
        with open(path, "wb"):
            pass
        # Built in bands of rows so the generator itself stays small.
        rows = []
        for y0 in range(0, size, 1024):
            y = np.linspace(y0 / size * 8.0, min(y0 + 1024, size) / size * 8.0,
                            min(1024, size - y0), dtype=np.float32, endpoint=False)
            base = (0.6 + 0.5 * np.sin(x)[None, :] * np.cos(y)[:, None]).astype(np.float32)
            band = np.stack([base * 2.0, base, base * base * 4.0], axis=-1)
            band *= rng.uniform(0.9, 1.1, band.shape).astype(np.float32)
            if noise:
                band *= rng.uniform(1 - noise, 1 + noise, band.shape).astype(np.float32)
            rows.append(band)
        write_exr(path, np.concatenate(rows, axis=0))


def ldr_png(reference):
    """The tone-mapped PNG made from `reference` for the TMQI run."""
    return reference[: -len(".exr")] + "-ldr.png"


def peak_rss(command):
    start = time.time()
    proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    stderr = proc.stderr.read().decode(errors="replace")
    if status != 0:
        sys.exit(f"{' '.join(command)} failed ({status}):\n{stderr}")
    return usage.ru_maxrss * 1024, time.time() - start


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--large", type=int, default=8192)
    parser.add_argument("--small", type=int, default=1024)
    parser.add_argument("--prism", default=os.path.join(ROOT, "target", "release", "prism"))
    parser.add_argument("--tonemap-ops", default="reinhard02,aces,durand02")
    parser.add_argument("--skip-compare", action="store_true")
    parser.add_argument("--skip-tmqi", action="store_true")
    parser.add_argument("--skip-report", action="store_true")
    parser.add_argument("--generate", nargs=2, metavar=("SIZE", "FOLDER"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.generate:
        make_pair(int(args.generate[0]), args.generate[1])
        return
    folder = tempfile.mkdtemp(prefix="prism-memory-", dir=os.environ.get("PRISM_MEASURE_DIR"))
    results = []
    try:
        # The images are made by a child process: a forked child's ru_maxrss counts the
        # memory of the parent it was forked from, which must stay small.
        pairs = {}
        for size in (args.small, args.large):
            subprocess.run([sys.executable, __file__, "--generate", str(size), folder], check=True)
            pairs[size] = (os.path.join(folder, f"test-{size}.exr"),
                           os.path.join(folder, f"reference-{size}.exr"))
        jobs = []
        if not args.skip_compare:
            jobs.append(("compare", lambda t, r, o: ["compare", t, r, "--json"]))
        if not args.skip_report:
            jobs.append(("compare --report",
                         lambda t, r, o: ["compare", t, r, "--json", "--report", f"{o}.html"]))
        if not args.skip_tmqi:
            # A tone-mapped PNG of each reference, made before the measured runs.
            for size, (_, reference) in pairs.items():
                subprocess.run([args.prism, "tonemap", reference, "-o", ldr_png(reference),
                                "--op", "reinhard02"], check=True, stderr=subprocess.DEVNULL)
            jobs.append(("compare --tmqi",
                         lambda t, r, o: ["compare", ldr_png(r), r, "--tmqi", "--json"]))
        for op in filter(None, args.tonemap_ops.split(",")):
            for ext in ("png", "exr"):
                jobs.append((f"tonemap {op} → {ext}",
                             lambda t, r, o, op=op, ext=ext:
                             ["tonemap", r, "-o", f"{o}.{ext}", "--op", op]))
        for name, job in jobs:
            peaks = {}
            for size, (test, reference) in pairs.items():
                out = os.path.join(folder, f"out-{size}")
                peaks[size], seconds = peak_rss([args.prism, *job(test, reference, out)])
                for ext in ("png", "exr", "html"):
                    if os.path.exists(f"{out}.{ext}"):
                        os.remove(f"{out}.{ext}")
            growth = (peaks[args.large] - peaks[args.small]) / (args.large ** 2 - args.small ** 2)
            results.append({
                "command": name,
                "peak_rss_bytes": {str(k): v for k, v in peaks.items()},
                "bytes_per_pixel": round(growth, 2),
                "seconds_large": round(seconds, 1),
            })
            print(f"{name}: {growth:.2f} bytes per pixel", file=sys.stderr)
    finally:
        for name in os.listdir(folder):
            os.remove(os.path.join(folder, name))
        os.rmdir(folder)
    report = {
        "tool": "measure_memory",
        "large_px": args.large,
        "small_px": args.small,
        "input": "float RGB EXR, uncompressed scan lines",
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
        "results": results,
    }
    out = os.path.join(ROOT, "tools", "bench-results", "memory.json")
    # Commands not measured in this run keep their last result.
    measured = {r["command"] for r in results}
    if os.path.exists(out):
        with open(out) as f:
            previous = json.load(f)
        if (previous.get("large_px"), previous.get("small_px")) == (args.large, args.small):
            kept = [r for r in previous.get("results", []) if r["command"] not in measured]
            report["results"] = kept + results
    text = json.dumps(report, indent=2)
    print(text)
    with open(out, "w") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()

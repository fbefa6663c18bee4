#!/usr/bin/env python3
"""Renders Prism's HTML reports in a real browser (headless Chromium) and checks them.

    python3 tools/report_browser_check.py [REPORT.html ...]

Without arguments it builds prism (release), renders the Cornell box twice (4 and 64 spp,
160x120), writes `prism compare --report` of the pair and `prism converge --report` of a
short path/bdpt study into a temporary directory, and checks both pages. Each page is
loaded from a file:// URL with the network disabled, then:

- the DOM after the page's script ran (`--dump-dom`): <body data-ready="true"> (every
  image decoded and drawn), data-decoded-images equal to the number of <img> elements in
  the file, and the metrics table present;
- a screenshot (`--screenshot`): not blank (at least 10 % of the pixels differ from the
  page's grey background, at least 500 distinct colours).

Installs what it needs: Debian's `chromium` (apt-get, needs root) and Pillow (pip) when
missing. Prints one JSON object; exits 1 when a check fails. The test suite checks the
pages' structure without a browser (tests/support/html_report.rs).
"""

import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BACKGROUND = (0x30, 0x30, 0x30)
WINDOW = (1280, 2400)


def ensure_chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    subprocess.run(
        ["apt-get", "install", "-y", "--no-install-recommends", "chromium"], check=True
    )
    return shutil.which("chromium")


def ensure_pillow():
    try:
        import PIL  # noqa: F401
    except ImportError:
        subprocess.run([sys.executable, "-m", "pip", "install", "pillow"], check=True)


def chromium_version(chromium):
    out = subprocess.run([chromium, "--version"], capture_output=True, text=True)
    return out.stdout.strip()


def browser(chromium, *args):
    command = [
        chromium,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--virtual-time-budget=30000",
        f"--window-size={WINDOW[0]},{WINDOW[1]}",
        *args,
    ]
    return subprocess.run(command, capture_output=True, text=True, timeout=180)


def check_page(chromium, html_path, work):
    source = html_path.read_text(encoding="utf-8")
    img_count = len(re.findall(r"<img\b", source))
    url = html_path.resolve().as_uri()
    dom = browser(chromium, "--dump-dom", url).stdout
    body = re.search(r"<body([^>]*)>", dom)
    attributes = dict(re.findall(r'([\w-]+)="([^"]*)"', body.group(1))) if body else {}
    shot = work / (html_path.stem + ".screenshot.png")
    browser(chromium, f"--screenshot={shot}", url)
    from PIL import Image

    image = Image.open(shot).convert("RGB")
    raw = image.tobytes()
    pixels = [raw[i : i + 3] for i in range(0, len(raw), 3)]
    differing = sum(1 for p in pixels if max(abs(a - b) for a, b in zip(p, BACKGROUND)) > 8)
    colours = len(set(pixels))
    result = {
        "page": str(html_path),
        "bytes": html_path.stat().st_size,
        "ready": attributes.get("data-ready"),
        "error": attributes.get("data-error"),
        "decoded_images": int(attributes.get("data-decoded-images", "0")),
        "img_elements": img_count,
        "metrics_table": '<table class="metrics">' in dom,
        "screenshot": str(shot),
        "screenshot_non_background_fraction": round(differing / len(pixels), 4),
        "screenshot_colours": colours,
    }
    failures = []
    if result["ready"] != "true":
        failures.append(f"data-ready is {result['ready']!r} ({result['error']})")
    if result["decoded_images"] != img_count:
        failures.append(f"{result['decoded_images']} of {img_count} images decoded")
    if not result["metrics_table"]:
        failures.append("no metrics table in the DOM")
    if result["screenshot_non_background_fraction"] < 0.10 or colours < 500:
        failures.append("the screenshot is (nearly) blank")
    result["failures"] = failures
    return result


def make_reports(work):
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    prism = ROOT / "target" / "release" / "prism"
    scene = ROOT / "scenes" / "cornell-box.json"
    renders = []
    for spp in (4, 64):
        out = work / f"cornell-{spp}spp.exr"
        subprocess.run(
            [prism, "render", scene, "--resolution", "160x120", "--spp", str(spp), "-o", out],
            check=True,
            capture_output=True,
        )
        renders.append(out)
    compare = work / "compare.html"
    subprocess.run(
        [prism, "compare", renders[0], renders[1], "--report", compare],
        check=True,
        capture_output=True,
    )
    converge = work / "converge.html"
    subprocess.run(
        [prism, "converge", scene, "--resolution", "64x48", "--method", "path",
         "--method", "bdpt", "--max-spp", "32", "--reference-spp", "256",
         "--report", converge],
        check=True,
        capture_output=True,
    )
    return [compare, converge]


def main():
    chromium = ensure_chromium()
    ensure_pillow()
    work = Path(tempfile.mkdtemp(prefix="prism-report-check-"))
    pages = [Path(p) for p in sys.argv[1:]] or make_reports(work)
    results = [check_page(chromium, page, work) for page in pages]
    print(json.dumps({"browser": chromium_version(chromium), "pages": results}, indent=2))
    return 1 if any(r["failures"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())

"""prism.tonemap, prism.operators and prism.compare against `prism tonemap` and
`prism compare --json`."""

import json

import numpy as np
import pytest

import prism


@pytest.fixture(scope="module")
def rendered(cli, root, tmp_path_factory):
    """A small Cornell box render (EXR with every layer) and a noisier one."""
    folder = tmp_path_factory.mktemp("renders")
    paths = []
    for spp in (16, 2):
        out = folder / f"cornell-{spp}.exr"
        cli("render", "scenes/cornell-box.json", "--spp", spp, "--resolution", "48x40",
            "--threads", 2, "-o", out, "--progress", "none")
        paths.append(out)
    return paths


@pytest.mark.parametrize(
    "op,wb,gamut,params,extra",
    [
        ("reinhard02", "none", "clip", {}, []),
        ("durand02", "grey-world", "local-oklab", {}, []),
        ("aces", "scene", "aces-rgc", {}, ["--exposure", "auto"]),
        ("reinhard02", "none", "clip", {"key": 0.3}, ["--param", "key=0.3"]),
    ],
)
def test_tonemap_equals_the_cli_exr(op, wb, gamut, params, extra, rendered, cli, tmp_path):
    source = rendered[0]
    out = tmp_path / "out.exr"
    cli("tonemap", source, "-o", out, "--op", op, "--wb", wb, "--gamut", gamut, *extra)
    theirs = prism.read_image(out).rgb
    exposure = "auto" if "--exposure" in extra else None
    ours = prism.tonemap(prism.read_image(source), op=op, wb=wb, gamut=gamut,
                         exposure=exposure, **params)
    assert ours.dtype == np.float32 and ours.shape == (40, 48, 3)
    assert np.array_equal(ours, theirs)
    assert ours.min() >= 0.0 and ours.max() <= 1.0


def test_tonemap_of_a_path_and_report(rendered, cli, tmp_path):
    out = tmp_path / "out.exr"
    report_cli = json.loads(cli("tonemap", rendered[0], "-o", out, "--op", "reinhard02",
                                "--json").stdout)
    values, report = prism.tonemap(rendered[0], report=True)
    assert np.array_equal(values, prism.read_image(out).rgb)
    timing_free = lambda r: {k: v for k, v in r.items() if k not in ("timings", "output")}
    assert timing_free(report) == timing_free(report_cli)


def test_tonemap_encode_matches_the_png(rendered, cli, tmp_path):
    out = tmp_path / "out.png"
    cli("tonemap", rendered[0], "-o", out, "--op", "reinhard02")
    encoded = prism.tonemap(rendered[0], encode=True)
    png_linear = prism.read_image(out).rgb
    png_encoded = prism.tonemap(png_linear, op="linear", exposure=0.0, encode=True)
    assert np.all(np.abs(encoded - png_encoded) <= 1 / 65535 + 1e-6)


def test_operators_equal_the_cli_list(cli):
    assert prism.operators() == json.loads(cli("tonemap", "--list", "--json").stdout)
    names = [o["name"] for o in prism.operators()]
    assert "reinhard02" in names and all(o["reference"] for o in prism.operators())


def test_compare_equals_the_cli(rendered, cli):
    theirs = json.loads(cli("compare", rendered[1], rendered[0], "--json").stdout)
    from_paths = prism.compare(rendered[1], rendered[0])
    assert from_paths == theirs
    a, b = prism.read_image(rendered[1]), prism.read_image(rendered[0])
    assert prism.compare(a, b) == theirs
    assert prism.compare(a.rgb, b.rgb) == prism.compare(
        prism.Image(a.rgb), prism.Image(b.rgb)
    )
    assert set(theirs) >= {"mse", "relmse", "psnr_db", "ssim", "hdr_flip_mean"}


def test_compare_with_another_ppd_equals_the_cli(rendered, cli):
    theirs = json.loads(cli("compare", rendered[1], rendered[0], "--json", "--ppd", 30).stdout)
    assert prism.compare(rendered[1], rendered[0], ppd=30) == theirs

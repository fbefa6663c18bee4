"""One test per error kind: each is a prism.PrismError subclass carrying the CLI's message
(file, JSON path or argument, and what was expected)."""

import json
import os

import numpy as np
import pytest

import prism

KINDS = [prism.SceneError, prism.SpectrumError, prism.ImageError, prism.RenderError,
         prism.ArgumentError]


def cli_error(cli, *args):
    done = cli(*args, check=False)
    assert done.returncode != 0
    line = [l for l in done.stderr.splitlines() if l.startswith("error: ")][0]
    return line[len("error: "):]


def test_every_kind_is_a_prism_error():
    for kind in KINDS:
        assert issubclass(kind, prism.PrismError)
        assert issubclass(kind, Exception)
    assert len(set(KINDS)) == 5


def test_scene_error_names_file_and_json_path(tmp_path, cli):
    scene = tmp_path / "bad.json"
    scene.write_text('{"camera": {"type": "pinhole", "fov_deg": "wide"}}\n')
    with pytest.raises(prism.SceneError) as raised:
        prism.render(scene)
    message = str(raised.value)
    assert str(scene) in message
    assert message == cli_error(cli, "render", scene, "-o", tmp_path / "x.exr")


def test_scene_error_of_a_dict():
    with pytest.raises(prism.SceneError, match="<scene dict>"):
        prism.render({"camera": {"type": "pinhole", "fov_deg": "wide"}})


def test_scene_error_for_json_syntax(tmp_path, cli):
    scene = tmp_path / "syntax.json"
    scene.write_text('{"camera": }')
    with pytest.raises(prism.SceneError) as raised:
        prism.render(scene)
    assert str(raised.value) == cli_error(cli, "render", scene, "-o", tmp_path / "x.exr")


def test_spectrum_error_carries_the_cli_message(cli):
    with pytest.raises(prism.SpectrumError) as raised:
        prism.color("colorchecker:dark skn")
    assert str(raised.value) == cli_error(
        cli, "color", "--spectrum", "colorchecker:dark skn", "--illuminant", "D65"
    )


def test_spectrum_error_for_unsorted_array():
    with pytest.raises(prism.SpectrumError, match="strictly increasing"):
        prism.color(np.array([[500.0, 1.0], [400.0, 1.0]]))


def test_image_error_for_a_missing_file(tmp_path, cli):
    missing = tmp_path / "missing.exr"
    with pytest.raises(prism.ImageError) as raised:
        prism.read_image(missing)
    assert str(missing) in str(raised.value)
    with pytest.raises(prism.ImageError) as raised_compare:
        prism.compare(missing, missing)
    assert str(raised_compare.value) == cli_error(cli, "compare", missing, missing)


def test_image_error_for_a_file_that_is_not_an_image(tmp_path):
    bogus = tmp_path / "bogus.exr"
    bogus.write_text("not an exr")
    with pytest.raises(prism.ImageError, match="bogus.exr"):
        prism.read_image(bogus)


def test_render_error_when_the_integrator_refuses_the_scene(root, cli):
    # The light tracer carries one wavelength set along its paths: it refuses a
    # fluorescent material when the pass is prepared (a RenderError, not a scene error).
    scene = json.loads((root / "scenes/fluorescence.json").read_text())
    scene["integrator"] = {"type": "light"}
    # Beside the original, whose assets it names relative to its folder.
    path = root / "scenes" / f"python-test-render-error-{os.getpid()}.json"
    path.write_text(json.dumps(scene))
    try:
        with pytest.raises(prism.RenderError) as raised:
            prism.render(path, spp=1, resolution=(8, 8))
        message = str(raised.value)
        assert "re-radiates (fluorescence)" in message
        assert message == cli_error(
            cli, "render", path, "--spp", 1, "--resolution", "8x8", "-o",
            path.with_suffix(".exr"), "--progress", "none",
        )
    finally:
        path.unlink()
        path.with_suffix(".exr").unlink(missing_ok=True)


def test_argument_errors():
    with pytest.raises(prism.ArgumentError, match="unknown tone operator 'reinhard'"):
        prism.tonemap(np.ones((4, 4, 3), np.float32), op="reinhard")
    with pytest.raises(prism.ArgumentError, match=r"\(H, W, 3\)"):
        prism.tonemap(np.ones((4, 4), np.float32))
    with pytest.raises(prism.ArgumentError, match="spp must be at least 1"):
        prism.render("scenes/cornell-box.json", spp=0)
    with pytest.raises(prism.ArgumentError, match="equal sizes|size"):
        prism.compare(np.ones((4, 4, 3)), np.ones((5, 4, 3)))

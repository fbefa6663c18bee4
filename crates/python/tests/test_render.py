"""prism.render against `prism render` (EXR channels bit for bit), dict scenes, progress,
the GIL and Ctrl-C."""

import _thread
import json
import signal
import threading
import time

import numpy as np
import pytest

import prism

SCENE = "scenes/cornell-box.json"
SMALL = dict(spp=4, resolution=(40, 30), threads=2)


def assert_layers_equal(render, image):
    assert set(render.aovs) == set(image.layers)
    for name, values in render.aovs.items():
        ours = dict(zip(render.aov_channels[name], np.atleast_3d(values).transpose(2, 0, 1)))
        theirs = dict(
            zip(image.layer_channels[name], np.atleast_3d(image.layers[name]).transpose(2, 0, 1))
        )
        assert set(ours) == set(theirs), name
        for channel in ours:
            assert np.array_equal(ours[channel], theirs[channel]), f"{name}.{channel}"


def test_cornell_box_equals_the_cli_exr_bit_for_bit(cli, root, tmp_path, monkeypatch):
    monkeypatch.chdir(root)
    out = tmp_path / "cornell.exr"
    cli("render", SCENE, "--spp", 4, "--resolution", "40x30", "--threads", 2,
        "--spectral-bins", 5, "-o", out, "--progress", "none")
    exr = prism.read_image(out)
    render = prism.render(SCENE, spectral_bins=5, **SMALL)
    assert render.rgb.dtype == np.float32 and render.rgb.shape == (30, 40, 3)
    assert np.array_equal(render.rgb, exr.rgb)
    assert_layers_equal(render, exr)
    assert render.cd_m2_per_unit == exr.cd_m2_per_unit
    assert render.spectral.shape == (30, 40, 5)
    assert np.array_equal(render.spectral, exr.spectral)
    assert np.array_equal(render.wavelengths_nm, exr.wavelengths_nm)
    assert render.xyz.shape == (30, 40, 3)
    assert render.stats["spp"] == 4 and render.stats["resolution"] == [40, 30]
    assert render.sensors == []


def test_dict_scene_equals_the_file(root):
    scene = json.loads((root / SCENE).read_text())
    from_dict = prism.render(scene, base_dir=root / "scenes", **SMALL)
    from_file = prism.render(root / SCENE, **SMALL)
    assert np.array_equal(from_dict.rgb, from_file.rgb)
    scene["film"]["seed"] = 1
    # seed=None takes the scene's film.seed; the default seed is 0 whatever the scene says.
    other = prism.render(scene, base_dir=root / "scenes", seed=None, **SMALL)
    assert not np.array_equal(other.rgb, from_file.rgb)
    default = prism.render(scene, base_dir=root / "scenes", **SMALL)
    assert np.array_equal(default.rgb, from_file.rgb)


def test_progress_reaches_the_total(root):
    calls = []
    prism.render(root / SCENE, progress=lambda done, total: calls.append((done, total)), **SMALL)
    assert calls and calls[-1] == (40 * 30 * 4, 40 * 30 * 4)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))


def long_render(root, progress=None):
    # 256 work items (16 × 16 px tiles) of about 0.5 M samples each: minutes in all, and a
    # stop is honoured between items.
    return prism.render(root / SCENE, spp=2000, resolution=(256, 256), threads=2,
                        progress=progress)


def test_ctrl_c_stops_the_render_and_raises_keyboard_interrupt(root):
    # Ctrl-C as the signal handler sees it (`interrupt_main`), sent once samples are being
    # rendered: from the progress callback, so that it lands while the render runs whatever
    # the machine's load (a 0.5 s timer once landed outside the render on a busy CI machine).
    sent = []
    calls = []

    def interrupt_once(done, total):
        calls.append((time.monotonic(), done, total))
        if done > 0 and not sent:
            sent.append(time.monotonic())
            _thread.interrupt_main()

    # A process started in the background by a non-interactive shell (as a CI script may
    # be) inherits SIGINT ignored, and then Python installs no handler and
    # `interrupt_main` does nothing: the test installs Python's own handler.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    start = time.monotonic()
    try:
        long_render(root, progress=interrupt_once)
    except KeyboardInterrupt:
        pass
    else:
        # What the render reported, so that a failure on a loaded machine can be read.
        seen = [(round(t - start, 2), done, total) for t, done, total in calls]
        pytest.fail(f"no KeyboardInterrupt: Ctrl-C sent {bool(sent)}, "
                    f"{round(time.monotonic() - start, 2)} s, progress calls "
                    f"{seen[:3]} … {seen[-3:]} ({len(seen)})")
    finally:
        signal.signal(signal.SIGINT, previous)
    assert sent, "the render never reported progress"
    elapsed = time.monotonic() - sent[0]
    # The items in flight when Ctrl-C comes finish first (a few seconds at most).
    assert elapsed < 15, elapsed


def test_an_exception_from_the_callback_stops_the_render(root):
    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        long_render(root, progress=fail)


def test_the_gil_is_released_while_rendering(root):
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    thread = threading.Thread(target=count)
    thread.start()
    try:
        start = time.monotonic()
        prism.render(root / SCENE, spp=64, resolution=(64, 64), threads=1)
        elapsed = time.monotonic() - start
    finally:
        stop.set()
        thread.join()
    # A thread blocked on the GIL would tick a few times at most.
    assert len(ticks) > 0.1 * elapsed / 0.001, (len(ticks), elapsed)


def test_oversized_renders_and_thread_counts_are_refused_before_anything_is_allocated(root):
    # A film of 10¹⁰ pixels is refused from its estimate (the CLI's), not by the allocator.
    with pytest.raises(prism.ArgumentError,
                       match=r"rendering 100000×100000 px needs about .* more than the "
                             r"memory limit"):
        prism.render(root / SCENE, resolution=(100000, 100000))
    with pytest.raises(prism.ArgumentError, match="max_memory= changes it"):
        prism.render(root / SCENE, resolution=(256, 256), max_memory="1M")
    with pytest.raises(prism.ArgumentError, match="max_memory"):
        prism.render(root / SCENE, max_memory="lots")
    with pytest.raises(prism.ArgumentError, match="worker threads"):
        prism.render(root / SCENE, threads=100000)
    # A limit that fits renders as before.
    small = prism.render(root / SCENE, spp=1, resolution=(8, 8), max_memory=1 << 30)
    assert small.rgb.shape == (8, 8, 3)

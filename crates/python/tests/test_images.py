"""NumPy round trips of every image format through prism.write_image / prism.read_image."""

import pathlib

import numpy as np
import pytest

import prism


def hdr_pixels(h=7, w=5, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 4.0, size=(h, w, 3)).astype(np.float32)


def test_exr_round_trip_is_exact_with_layers_and_scale(tmp_path):
    rgb = hdr_pixels()
    depth = np.arange(35, dtype=np.float32).reshape(7, 5)
    normal = hdr_pixels(seed=2) - 2.0
    image = prism.Image(
        rgb,
        layers={"depth": depth, "normal": normal},
        cd_m2_per_unit=179.0,
        metadata={"comment": "round trip"},
    )
    path = tmp_path / "a.exr"
    prism.write_image(path, image)
    back = prism.read_image(path)
    assert back.rgb.dtype == np.float32 and back.rgb.shape == (7, 5, 3)
    assert np.array_equal(back.rgb, rgb)
    assert np.array_equal(np.asarray(back), rgb)
    assert np.array_equal(back.layers["depth"], depth)
    assert back.layer_channels["normal"] == ["X", "Y", "Z"]
    assert np.array_equal(back.layers["normal"], normal)
    assert back.cd_m2_per_unit == 179.0
    assert back.metadata["comment"] == "round trip"
    assert back.spectral is None


def test_spectral_exr_round_trip_is_exact(tmp_path):
    rgb = hdr_pixels()
    wavelengths = np.array([400.0, 500.0, 600.0, 700.0])
    bands = np.random.default_rng(3).uniform(0, 1, size=(7, 5, 4)).astype(np.float32)
    path = tmp_path / "s.exr"
    prism.write_image(path, rgb, spectral=bands, wavelengths_nm=wavelengths)
    back = prism.read_image(str(path))
    assert np.array_equal(back.rgb, rgb)
    assert np.array_equal(back.wavelengths_nm, wavelengths)
    assert np.array_equal(back.spectral, bands)
    again = tmp_path / "again.exr"
    prism.write_image(again, back)
    assert np.array_equal(prism.read_image(again).spectral, bands)


def test_hdr_round_trip_within_rgbe_precision(tmp_path):
    rgb = hdr_pixels()
    path = tmp_path / "a.hdr"
    prism.write_image(path, rgb)
    back = prism.read_image(path).rgb
    # RGBE: an 8-bit mantissa shared under the largest component's exponent.
    step = np.exp2(np.ceil(np.log2(rgb.max(axis=2, keepdims=True))) - 8)
    assert np.all(np.abs(back - rgb) <= step)


def test_png_round_trip_within_16_bit_quantisation(tmp_path):
    rgb = np.random.default_rng(4).uniform(0, 1, size=(6, 9, 3)).astype(np.float32)
    path = tmp_path / "a.png"
    prism.write_image(path, rgb)
    back = prism.read_image(path).rgb

    def encode(v):
        v = v.astype(np.float64)
        return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)

    assert np.all(np.abs(encode(back) - encode(rgb)) <= 0.5 / 65535 + 1e-9)


def test_float64_input_is_converted(tmp_path):
    rgb = hdr_pixels().astype(np.float64)
    path = tmp_path / "d.exr"
    prism.write_image(path, rgb)
    assert np.array_equal(prism.read_image(path).rgb, rgb.astype(np.float32))


def test_spectral_bands_need_an_exr(tmp_path):
    with pytest.raises(prism.ArgumentError, match="need an .exr"):
        prism.write_image(
            tmp_path / "s.png",
            hdr_pixels(),
            spectral=np.zeros((7, 5, 2), np.float32),
            wavelengths_nm=[500, 600],
        )


def test_path_types(tmp_path):
    path = tmp_path / "p.exr"
    prism.write_image(str(path), hdr_pixels())
    assert np.array_equal(prism.read_image(pathlib.Path(path)).rgb, hdr_pixels())

"""prism.color against `prism color --json` (same keys, same numbers) and colour-science."""

import math
import re
import warnings

import numpy as np
import pytest

import prism

CASES = [
    (["colorchecker:dark skin"], {}),
    (["colorchecker:cyan"], {"illuminant": "A", "observer": "cie1964", "adapt": "cat16"}),
    (["blackbody:2856"], {"illuminant": None}),
    (["D65"], {"illuminant": None, "observer": "cie1964"}),
    (["tests/fixtures/irregular_reflectance.csv"], {"illuminant": "F11", "adapt": "none"}),
]


def cli_args(spectrum, kwargs):
    args = ["color", "--spectrum", spectrum, "--json"]
    illuminant = kwargs.get("illuminant", "D65")
    if illuminant is not None:
        args += ["--illuminant", illuminant]
    if "observer" in kwargs:
        args += ["--observer", kwargs["observer"]]
    if "adapt" in kwargs:
        args += ["--adapt", kwargs["adapt"]]
    return args


@pytest.mark.parametrize("args,kwargs", CASES)
def test_color_equals_the_cli_report(args, kwargs, cli_json, root, monkeypatch):
    monkeypatch.chdir(root)
    ours = prism.color(*args, **kwargs)
    theirs = cli_json(*cli_args(args[0], kwargs))
    assert list(ours) == list(theirs)
    assert ours == theirs


def test_array_spectrum_equals_the_csv_file(root):
    path = root / "tests/fixtures/irregular_reflectance.csv"
    rows = [
        [float(v) for v in re.split(r"[,\s]+", line.strip())[:2]]
        for line in path.read_text().splitlines()
        if line.strip() and line.strip()[0].isdigit()
    ]
    from_file = prism.color(str(path))
    from_array = prism.color(np.array(rows))
    assert from_array["spectrum"] == "<array>"
    for key in ("XYZ", "xy", "CCT_K", "Duv", "Lab", "linear_sRGB", "sRGB"):
        assert from_array[key] == from_file[key], key


def test_vectorised_rows_equal_single_calls():
    grid = np.arange(380.0, 781.0, 5.0)
    rng = np.random.default_rng(7)
    values = rng.uniform(0.0, 1.0, size=(6, grid.size))
    for illuminant in ("D65", "A", None):
        xyz = prism.color(values, illuminant=illuminant, wavelengths_nm=grid)
        assert xyz.shape == (6, 3)
        for row, expected in zip(values, xyz):
            single = prism.color(np.column_stack([grid, row]), illuminant=illuminant)
            assert single["XYZ"] == list(expected)
    one = prism.color(values[0], wavelengths_nm=grid)
    assert one.shape == (3,)


def test_reflectance_without_illuminant_warns():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        prism.color("colorchecker:dark skin", illuminant=None)
    assert any("treated as spectral radiance" in str(w.message) for w in caught)


# The 24 patches: prism.color's XYZ (D65, CIE 1931) equals colour-science's integration of
# the same spectra prepared as Prism prepares them (tools/export_color_cli_fixture.py:
# linear interpolation onto 360-830 nm at 1 nm, zero outside), to 1e-6 relative as
# tests/color_cli.rs checks the CLI.
def test_colorchecker_equals_colour_science(capsys):
    try:
        with warnings.catch_warnings():
            # Its notices about optional SciPy and Matplotlib features.
            warnings.simplefilter("ignore")
            import colour
            from colour import LinearInterpolator, SpectralShape
    except ImportError as e:  # pragma: no cover - depends on the environment
        with capsys.disabled():
            print(f"\nskipped: colour-science is not importable ({e})")
        pytest.skip(f"colour-science is not importable ({e})")
    shape = SpectralShape(360, 830, 1)

    def prepare(sd):
        return sd.copy().align(
            shape,
            interpolator=LinearInterpolator,
            extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0},
        )

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    illuminant = prepare(colour.SDS_ILLUMINANTS["D65"])
    patches = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    assert len(patches) == 24
    checked = 0
    for name, sd in patches.items():
        ours = prism.color(np.column_stack([sd.wavelengths, sd.values]))
        theirs = colour.sd_to_XYZ(prepare(sd), cmfs, illuminant, method="Integration")
        for a, b in zip(ours["XYZ"], theirs):
            assert math.isclose(a, b, rel_tol=1e-6), (name, ours["XYZ"], list(theirs))
        checked += 1
    assert checked == 24


def test_unknown_observer_is_an_argument_error():
    with pytest.raises(prism.ArgumentError, match="observer"):
        prism.color("D65", illuminant=None, observer="cie2006")

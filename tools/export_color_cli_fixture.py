#!/usr/bin/env python3
"""Expected `prism color --json` objects, computed with colour-science, for the CLI tests.

    python3 -m pip install -r tools/requirements.txt
    python3 tools/export_color_cli_fixture.py

Writes tests/fixtures/color_cli.json (and the irregularly spaced test spectrum
tests/fixtures/irregular_reflectance.csv). Every spectrum is prepared as Prism prepares
it: linear interpolation onto 360-830 nm at 1 nm, zero outside its tabulated range.
"""

import json
import pathlib
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
import numpy as np  # noqa: E402
from colour import LinearInterpolator, SpectralDistribution, SpectralShape  # noqa: E402
from colour.temperature import uv_to_CCT_Ohno2013  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
FIXTURES = ROOT / "tests" / "fixtures"
SHAPE = SpectralShape(360, 830, 1)
OBSERVERS = {
    "cie1931": "CIE 1931 2 Degree Standard Observer",
    "cie1964": "CIE 1964 10 Degree Standard Observer",
}
ADAPT = {"bradford": "Bradford", "cat16": "CAT16", "cat02": "CAT02", "von-kries": "Von Kries"}
ILLUMINANT_KEYS = {"F2": "FL2", "F11": "FL11"}

CALLS = {
    "prepare": 'sd.copy().align(SpectralShape(360, 830, 1), interpolator=LinearInterpolator, '
    'extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})',
    "XYZ (reflectance)": 'colour.sd_to_XYZ(R, cmfs, I, method="Integration")',
    "XYZ (emission)": 'colour.sd_to_XYZ(L, cmfs, None, k=683.002, method="Integration")',
    "xy": "colour.XYZ_to_xy(XYZ)",
    "CCT_K, Duv": "colour.temperature.uv_to_CCT_Ohno2013(colour.xy_to_UCS_uv(colour.XYZ_to_xy(XYZ_cie1931)), colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer'].copy().align(SpectralShape(360, 830, 1)))",
    "Lab": "colour.XYZ_to_Lab(XYZ / 100, colour.XYZ_to_xy(XYZ_white))",
    "linear_sRGB (reflectance)": "normalised_primary_matrix(sRGB)^-1 @ matrix_chromatic_adaptation_VonKries("
    "XYZ_white_cie1931 / 100, xy_to_XYZ(sRGB.whitepoint), transform) @ XYZ_cie1931 / 100",
    "linear_sRGB (emission)": "normalised_primary_matrix(sRGB)^-1 @ XYZ_cie1931 (absolute)",
    "sRGB": 'colour.cctf_encoding(linear_sRGB, "sRGB")',
}


def prepare(sd):
    return sd.copy().align(
        SHAPE,
        interpolator=LinearInterpolator,
        extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0},
    )


def illuminant_sd(name):
    return prepare(colour.SDS_ILLUMINANTS[ILLUMINANT_KEYS.get(name, name)])


def srgb_matrices():
    space = colour.RGB_COLOURSPACES["sRGB"]
    npm = colour.normalised_primary_matrix(space.primaries, space.whitepoint)
    return np.linalg.inv(npm), colour.xy_to_XYZ(space.whitepoint)


def cct(xyz_1931):
    # colour-science's default locus stops at 780 nm; Prism's (and CIE 15's) spans 360-830 nm.
    cmfs = colour.MSDS_CMFS[OBSERVERS["cie1931"]].copy().align(SHAPE)
    uv = colour.xy_to_UCS_uv(colour.XYZ_to_xy(xyz_1931))
    t, duv = uv_to_CCT_Ohno2013(uv, cmfs)
    return float(t), float(duv)


def reflectance_case(args, sd, illuminant, observer, adapt):
    cmfs = colour.MSDS_CMFS[OBSERVERS[observer]]
    cmfs_1931 = colour.MSDS_CMFS[OBSERVERS["cie1931"]]
    R, I = prepare(sd), illuminant_sd(illuminant)
    xyz = colour.sd_to_XYZ(R, cmfs, I, method="Integration")
    white = colour.sd_to_XYZ(prepare(SpectralDistribution(dict(zip(I.wavelengths, np.ones(len(I.wavelengths)))))), cmfs, I, method="Integration")
    xyz_1931 = colour.sd_to_XYZ(R, cmfs_1931, I, method="Integration")
    white_1931 = colour.sd_to_XYZ(prepare(SpectralDistribution(dict(zip(I.wavelengths, np.ones(len(I.wavelengths)))))), cmfs_1931, I, method="Integration")
    lab = colour.XYZ_to_Lab(xyz / 100, colour.XYZ_to_xy(white))
    to_rgb, srgb_white = srgb_matrices()
    if adapt == "none":
        adapted = xyz_1931 / 100
    else:
        m = colour.adaptation.matrix_chromatic_adaptation_VonKries(white_1931 / 100, srgb_white, ADAPT[adapt])
        adapted = m @ (xyz_1931 / 100)
    linear = to_rgb @ adapted
    t, duv = cct(xyz_1931)
    return {
        "args": args,
        "expected": {
            "XYZ": list(map(float, xyz)),
            "xy": list(map(float, colour.XYZ_to_xy(xyz))),
            "CCT_K": t,
            "Duv": duv,
            "Lab": list(map(float, lab)),
            "linear_sRGB": list(map(float, linear)),
            "sRGB": list(map(float, colour.cctf_encoding(linear, "sRGB"))),
        },
    }


def emission_case(args, sd, observer):
    cmfs = colour.MSDS_CMFS[OBSERVERS[observer]]
    cmfs_1931 = colour.MSDS_CMFS[OBSERVERS["cie1931"]]
    L = prepare(sd)
    xyz = colour.sd_to_XYZ(L, cmfs, None, k=683.002, method="Integration")
    xyz_1931 = colour.sd_to_XYZ(L, cmfs_1931, None, k=683.002, method="Integration")
    to_rgb, _ = srgb_matrices()
    linear = to_rgb @ xyz_1931
    t, duv = cct(xyz_1931)
    return {
        "args": args,
        "expected": {
            "XYZ": list(map(float, xyz)),
            "xy": list(map(float, colour.XYZ_to_xy(xyz))),
            "CCT_K": t,
            "Duv": duv,
            "Lab": None,
            "linear_sRGB": list(map(float, linear)),
            "sRGB": list(map(float, colour.cctf_encoding(linear, "sRGB"))),
        },
    }


def main():
    FIXTURES.mkdir(parents=True, exist_ok=True)
    checker = colour.SDS_COLOURCHECKERS["BabelColor Average"]
    cases = []
    for patch, illum, observer, adapt in [
        ("dark skin", "D65", "cie1931", "bradford"),
        ("blue", "A", "cie1964", "cat16"),
        ("red", "F2", "cie1931", "von-kries"),
        ("yellow", "LED-B3", "cie1931", "cat02"),
        ("cyan", "A", "cie1931", "none"),
        ("white 9.5 (.05 D)", "F11", "cie1964", "bradford"),
    ]:
        args = ["--spectrum", f"colorchecker:{patch}", "--illuminant", illum, "--observer", observer, "--adapt", adapt]
        cases.append(reflectance_case(args, checker[patch], illum, observer, adapt))

    # An irregularly spaced reflectance file, inside 360-830 on one side only.
    wl = np.array([375.0, 401.5, 433.0, 470.0, 512.25, 555.0, 600.0, 648.0, 700.0, 790.0])
    values = np.array([0.05, 0.07, 0.12, 0.31, 0.55, 0.62, 0.48, 0.40, 0.38, 0.36])
    irregular = FIXTURES / "irregular_reflectance.csv"
    irregular.write_text(
        "# Hand-made reflectance at irregular spacing for tests (tools/export_color_cli_fixture.py)\n"
        "wavelength_nm,reflectance\n" + "".join(f"{w}\t{v}\n" for w, v in zip(wl, values))
    )
    sd = SpectralDistribution(dict(zip(wl, values)))
    args = ["--spectrum", "tests/fixtures/irregular_reflectance.csv", "--illuminant", "D50"]
    cases.append(reflectance_case(args, sd, "D50", "cie1931", "bradford"))

    # Emission: the CIE tables read as spectral radiance in W m^-2 sr^-1 nm^-1.
    for name, observer in [("A", "cie1931"), ("D65", "cie1964"), ("LED-B3", "cie1931")]:
        sd = colour.SDS_ILLUMINANTS[ILLUMINANT_KEYS.get(name, name)]
        cases.append(emission_case(["--spectrum", name, "--observer", observer], sd, observer))

    out = {
        "provenance": {
            "tool": f"colour-science {colour.__version__}",
            "script": "tools/export_color_cli_fixture.py",
            "colorchecker": 'colour.SDS_COLOURCHECKERS["BabelColor Average"]',
            "illuminants": 'colour.SDS_ILLUMINANTS[name] (F2 is "FL2", F11 is "FL11")',
            "calls": CALLS,
        },
        "cases": cases,
    }
    (FIXTURES / "color_cli.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Export the colorimetry reference fixtures in tests/fixtures/ from colour-science.

Run (idempotent; rewrites the same files with the same numbers):
    python3 -m pip install -r tools/requirements.txt && python3 tools/export_fixtures.py

Each JSON file holds a top-level "provenance" object (colour-science, numpy and scipy
versions, the exact calls) and "data". crates/spectrum/tests/colorimetry_fixtures.rs
reads them; tests never run Python.

Data are prepared exactly as Prism prepares them: every spectrum (reflectance, illuminant,
CMFs) is linearly interpolated onto 360-830 nm at 1 nm and is zero outside its tabulated
range (`prism_align` below, checked against numpy.interp before use), then integrated with
colour.sd_to_XYZ(..., method="Integration") whose dw is the shape interval, 1 nm.
"""

import json
import pathlib
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402
import scipy  # noqa: E402

import colour  # noqa: E402
from colour import SpectralShape  # noqa: E402
from colour.algebra import LinearInterpolator  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "fixtures"

SHAPE = SpectralShape(360, 830, 1)
GRID = np.arange(360, 831, 1, dtype=float)
OBSERVERS = {
    "cie1931": "CIE 1931 2 Degree Standard Observer",
    "cie1964": "CIE 1964 10 Degree Standard Observer",
}
# Prism name -> colour-science name.
ILLUMINANTS = {"D65": "D65", "A": "A", "F2": "FL2", "LED-B3": "LED-B3"}

ALIGN_CALL = (
    "sd.copy().align(SpectralShape(360, 830, 1), interpolator=LinearInterpolator, "
    'extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})'
)


def provenance(calls, notes=None):
    p = {
        "generator": "tools/export_fixtures.py",
        "colour-science": colour.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "calls": calls,
    }
    if notes:
        p["notes"] = notes
    return p


def write(name, prov, data):
    OUT.mkdir(parents=True, exist_ok=True)
    text = json.dumps({"provenance": prov, "data": data}, indent=1)
    (OUT / name).write_text(text + "\n")
    print(f"wrote {OUT / name}")


def prism_align(sd):
    """Linear on the tabulated samples, zero outside, on 360..=830 nm at 1 nm."""
    aligned = sd.copy().align(
        SHAPE,
        interpolator=LinearInterpolator,
        extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0},
    )
    # Verify that this really is piecewise-linear and zero-extended.
    expected = np.interp(GRID, sd.wavelengths, sd.values, left=0.0, right=0.0)
    assert np.array_equal(aligned.wavelengths, GRID), "grid mismatch"
    assert np.allclose(aligned.values, expected, rtol=0, atol=1e-12), (
        f"{sd.name}: align() is not linear/zero-extended"
    )
    return aligned


def prism_cmfs(key):
    msds = colour.MSDS_CMFS[OBSERVERS[key]]
    aligned = msds.copy().align(
        SHAPE,
        interpolator=LinearInterpolator,
        extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0},
    )
    for i in range(3):
        expected = np.interp(
            GRID, msds.wavelengths, msds.values[:, i], left=0.0, right=0.0
        )
        assert np.allclose(aligned.values[:, i], expected, rtol=0, atol=1e-15)
    return aligned


def illuminant(prism_name):
    return prism_align(colour.SDS_ILLUMINANTS[ILLUMINANTS[prism_name]])


def white_xyz(cmfs, illum):
    ones = colour.SpectralDistribution(np.ones(len(GRID)), GRID, name="perfect reflector")
    return colour.sd_to_XYZ(ones, cmfs, illum, method="Integration")


def fl(a):
    return [float(v) for v in np.ravel(a)]


def export_colorchecker():
    cc = colour.SDS_COLOURCHECKERS["BabelColor Average"]
    names = list(cc.keys())
    data = {"patch_names": names, "results": []}
    for obs in OBSERVERS:
        cmfs = prism_cmfs(obs)
        for prism_name in ILLUMINANTS:
            illum = illuminant(prism_name)
            w = white_xyz(cmfs, illum)
            w_xy = colour.XYZ_to_xy(w / 100)
            xyz, lab = [], []
            for name in names:
                sd = prism_align(cc[name])
                XYZ = colour.sd_to_XYZ(sd, cmfs, illum, method="Integration")
                xyz.append(fl(XYZ))
                lab.append(fl(colour.XYZ_to_Lab(XYZ / 100, w_xy)))
            data["results"].append(
                {
                    "observer": obs,
                    "illuminant": prism_name,
                    "colour_illuminant": ILLUMINANTS[prism_name],
                    "white_xyz": fl(w),
                    "white_xy": fl(w_xy),
                    "xyz": xyz,
                    "lab": lab,
                }
            )
    prov = provenance(
        [
            'cc = colour.SDS_COLOURCHECKERS["BabelColor Average"]',
            'cmfs = colour.MSDS_CMFS[observer].copy().align(SpectralShape(360, 830, 1), '
            'interpolator=LinearInterpolator, extrapolator_kwargs={"method": "Constant", '
            '"left": 0, "right": 0})',
            f"sd, illuminant = {ALIGN_CALL} (each)",
            'XYZ = colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration")',
            'white_xyz = colour.sd_to_XYZ(ones on 360-830 nm, cmfs, illuminant, method="Integration")',
            "Lab = colour.XYZ_to_Lab(XYZ / 100, colour.XYZ_to_xy(white_xyz / 100))",
        ],
        "Prism illuminant F2 is colour-science FL2. XYZ on the Y(white) = 100 scale.",
    )
    write("colorchecker_xyz.json", prov, data)


def export_cct():
    from colour.temperature import CCT_to_uv_Ohno2013, uv_to_CCT_Ohno2013

    cmfs = prism_cmfs("cie1931")
    default_cmfs = colour.MSDS_CMFS[OBSERVERS["cie1931"]].copy().align(
        colour.SPECTRAL_SHAPE_DEFAULT
    )

    temps = [float(t) for t in range(1000, 20001, 500)]
    temps += [25000.0, 30000.0, 40000.0, 50000.0, 70000.0, 100000.0]
    blackbodies = []
    for t in temps:
        sd = colour.sd_blackbody(t, SHAPE)
        XYZ = colour.sd_to_XYZ(sd, cmfs, method="Integration")
        uv = colour.UCS_to_uv(colour.XYZ_to_UCS(XYZ))
        cct, duv = uv_to_CCT_Ohno2013(uv, cmfs)
        cct_d, duv_d = uv_to_CCT_Ohno2013(uv, default_cmfs)
        blackbodies.append(
            {
                "temperature_k": t,
                "uv": fl(uv),
                "cct_k": float(cct),
                "duv": None if np.isnan(duv) else float(duv),
                "cct_k_default_cmfs_360_780": float(cct_d),
            }
        )

    illuminants = []
    for name, cs_name in [
        ("D50", "D50"),
        ("D55", "D55"),
        ("D65", "D65"),
        ("D75", "D75"),
        ("A", "A"),
        ("F2", "FL2"),
        ("F11", "FL11"),
        ("LED-B3", "LED-B3"),
    ]:
        sd = prism_align(colour.SDS_ILLUMINANTS[cs_name])
        XYZ = colour.sd_to_XYZ(sd, cmfs, method="Integration")
        uv = colour.UCS_to_uv(colour.XYZ_to_UCS(XYZ))
        cct, duv = uv_to_CCT_Ohno2013(uv, cmfs)
        illuminants.append(
            {"name": name, "uv": fl(uv), "cct_k": float(cct), "duv": float(duv)}
        )

    off_locus = []
    for t in [2000.0, 2856.0, 4000.0, 6500.0, 10000.0, 25000.0]:
        for d in [-0.02, 0.02]:
            uv = CCT_to_uv_Ohno2013(np.array([t, d]), cmfs)
            cct, duv = uv_to_CCT_Ohno2013(uv, cmfs)
            off_locus.append(
                {
                    "cct_k_in": t,
                    "duv_in": d,
                    "uv": fl(uv),
                    "cct_k": float(cct),
                    "duv": float(duv),
                }
            )

    prov = provenance(
        [
            'cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align('
            'SpectralShape(360, 830, 1), interpolator=LinearInterpolator, '
            'extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})',
            "blackbody: sd = colour.sd_blackbody(T, SpectralShape(360, 830, 1)); "
            'XYZ = colour.sd_to_XYZ(sd, cmfs, method="Integration"); '
            "uv = colour.UCS_to_uv(colour.XYZ_to_UCS(XYZ))",
            "cct_k, duv = colour.temperature.uv_to_CCT_Ohno2013(uv, cmfs)",
            "cct_k_default_cmfs_360_780 = uv_to_CCT_Ohno2013(uv) with its default CMFs "
            "(CIE 1931 aligned to SPECTRAL_SHAPE_DEFAULT = 360-780 nm), for information",
            f"illuminants: sd = {ALIGN_CALL}; same XYZ, uv and CCT calls",
            "off_locus: uv = colour.temperature.CCT_to_uv_Ohno2013([T, Duv], cmfs); "
            "cct_k, duv = uv_to_CCT_Ohno2013(uv, cmfs)",
        ],
        "The Planckian locus is built on the same 360-830 nm 1 nm CIE 1931 CMFs as the "
        "blackbody uv (colour-science's default 360-780 nm locus is off by up to 2.6 K at "
        "100 000 K for such uv). planck_law constants: c1 = "
        f"{colour.colorimetry.blackbody.CONSTANT_C1!r}, c2 = "
        f"{colour.colorimetry.blackbody.CONSTANT_C2!r} m K, n = 1. duv is null where "
        "colour-science returns NaN (the square root of a tiny negative at the table end).",
    )
    write(
        "cct.json",
        prov,
        {"blackbodies": blackbodies, "illuminants": illuminants, "off_locus": off_locus},
    )


# Sharma, Wu & Dalal (2005), Table 1: Lab1, Lab2, published Delta E00 (4 decimals).
SHARMA_2005 = [
    ([50.0000, 2.6772, -79.7751], [50.0000, 0.0000, -82.7485], 2.0425),
    ([50.0000, 3.1571, -77.2803], [50.0000, 0.0000, -82.7485], 2.8615),
    ([50.0000, 2.8361, -74.0200], [50.0000, 0.0000, -82.7485], 3.4412),
    ([50.0000, -1.3802, -84.2814], [50.0000, 0.0000, -82.7485], 1.0000),
    ([50.0000, -1.1848, -84.8006], [50.0000, 0.0000, -82.7485], 1.0000),
    ([50.0000, -0.9009, -85.5211], [50.0000, 0.0000, -82.7485], 1.0000),
    ([50.0000, 0.0000, 0.0000], [50.0000, -1.0000, 2.0000], 2.3669),
    ([50.0000, -1.0000, 2.0000], [50.0000, 0.0000, 0.0000], 2.3669),
    ([50.0000, 2.4900, -0.0010], [50.0000, -2.4900, 0.0009], 7.1792),
    ([50.0000, 2.4900, -0.0010], [50.0000, -2.4900, 0.0010], 7.1792),
    ([50.0000, 2.4900, -0.0010], [50.0000, -2.4900, 0.0011], 7.2195),
    ([50.0000, 2.4900, -0.0010], [50.0000, -2.4900, 0.0012], 7.2195),
    ([50.0000, -0.0010, 2.4900], [50.0000, 0.0009, -2.4900], 4.8045),
    ([50.0000, -0.0010, 2.4900], [50.0000, 0.0010, -2.4900], 4.8045),
    ([50.0000, -0.0010, 2.4900], [50.0000, 0.0011, -2.4900], 4.7461),
    ([50.0000, 2.5000, 0.0000], [50.0000, 0.0000, -2.5000], 4.3065),
    ([50.0000, 2.5000, 0.0000], [73.0000, 25.0000, -18.0000], 27.1492),
    ([50.0000, 2.5000, 0.0000], [61.0000, -5.0000, 29.0000], 22.8977),
    ([50.0000, 2.5000, 0.0000], [56.0000, -27.0000, -3.0000], 31.9030),
    ([50.0000, 2.5000, 0.0000], [58.0000, 24.0000, 15.0000], 19.4535),
    ([50.0000, 2.5000, 0.0000], [50.0000, 3.1736, 0.5854], 1.0000),
    ([50.0000, 2.5000, 0.0000], [50.0000, 3.2972, 0.0000], 1.0000),
    ([50.0000, 2.5000, 0.0000], [50.0000, 1.8634, 0.5757], 1.0000),
    ([50.0000, 2.5000, 0.0000], [50.0000, 3.2592, 0.3350], 1.0000),
    ([60.2574, -34.0099, 36.2677], [60.4626, -34.1751, 39.4387], 1.2644),
    ([63.0109, -31.0961, -5.8663], [62.8187, -29.7946, -4.0864], 1.2630),
    ([61.2901, 3.7196, -5.3901], [61.4292, 2.2480, -4.9620], 1.8731),
    ([35.0831, -44.1164, 3.7933], [35.0232, -40.0716, 1.5901], 1.8645),
    ([22.7233, 20.0904, -46.6940], [23.0331, 14.9730, -42.5619], 2.0373),
    ([36.4612, 47.8580, 18.3852], [36.2715, 50.5065, 21.2231], 1.4146),
    ([90.8027, -2.0831, 1.4410], [91.1528, -1.6435, 0.0447], 1.4441),
    ([90.9257, -0.5406, -0.9208], [88.6381, -0.8985, -0.7239], 1.5381),
    ([6.7747, -0.2908, -2.4247], [5.8714, -0.0985, -2.2286], 0.6377),
    ([2.0776, 0.0795, -1.1350], [0.9033, -0.0636, -0.5514], 0.9082),
]


def export_ciede2000():
    pairs = []
    for i, (lab1, lab2, published) in enumerate(SHARMA_2005, start=1):
        de = colour.difference.delta_E_CIE2000(np.array(lab1), np.array(lab2))
        pairs.append(
            {
                "pair": i,
                "lab1": lab1,
                "lab2": lab2,
                "delta_e00_published": published,
                "delta_e00_colour": float(de),
            }
        )
    prov = provenance(
        [
            "Lab pairs and published values: Sharma, Wu & Dalal (2005), Color Res. Appl. "
            "30(1), Table 1 (the dataset of colour/difference/tests/test_delta_e.py, "
            "test_delta_E_CIE2000_Sharma2004, which omits pair 14)",
            "delta_e00_colour = colour.difference.delta_E_CIE2000(lab1, lab2)",
        ],
        "Pair 14 has hue angles exactly 180 degrees apart; colour-science's float "
        "arithmetic lands on either side of the |dh| <= 180 rule depending on platform "
        "(its own test excludes it), so its value there may differ from the paper's 4.8045.",
    )
    write("ciede2000.json", prov, {"pairs": pairs})


def export_adaptation():
    cmfs = prism_cmfs("cie1931")
    src = white_xyz(cmfs, illuminant("A")) / 100
    dst = white_xyz(cmfs, illuminant("D65")) / 100
    matrices = {}
    for prism_name, cs_name in [
        ("von-kries", "Von Kries"),
        ("bradford", "Bradford"),
        ("cat02", "CAT02"),
        ("cat16", "CAT16"),
    ]:
        m = colour.adaptation.matrix_chromatic_adaptation_VonKries(src, dst, cs_name)
        matrices[prism_name] = {"colour_transform": cs_name, "matrix": m.tolist()}
    prov = provenance(
        [
            f"src_white = sd_to_XYZ(ones, cmfs_1931_360_830, A aligned, "
            'method="Integration") / 100, A aligned by ' + ALIGN_CALL,
            "dst_white = the same for D65",
            "matrix = colour.adaptation.matrix_chromatic_adaptation_VonKries("
            "src_white, dst_white, transform)",
        ],
        "Matrices are row-major (matrix[row][col]), acting on column vectors XYZ.",
    )
    write(
        "adaptation.json",
        prov,
        {"src_white_xyz": fl(src), "dst_white_xyz": fl(dst), "matrices": matrices},
    )


def export_rgb_spaces():
    spaces = []
    inputs = [-0.5, -0.01, 0.0, 0.001, 0.0031308, 0.01, 0.018, 0.1, 0.5, 1.0, 1.5, 4.0]
    for prism_name, cs_name, cctf in [
        ("sRGB", "sRGB", "sRGB"),
        ("Display P3", "Display P3", "sRGB"),
        ("Rec.2020", "ITU-R BT.2020", "ITU-R BT.2020"),
        ("ACES2065-1", "ACES2065-1", None),
        ("ACEScg", "ACEScg", None),
    ]:
        cs = colour.RGB_COLOURSPACES[cs_name]
        npm = colour.normalised_primary_matrix(cs.primaries, cs.whitepoint)
        entry = {
            "name": prism_name,
            "colour_name": cs_name,
            "primaries_xy": cs.primaries.tolist(),
            "white_xy": fl(cs.whitepoint),
            "npm": npm.tolist(),
        }
        if cctf is not None:
            xs = inputs if cctf == "sRGB" else [v for v in inputs if v >= 0]
            entry["cctf"] = cctf
            entry["encoding"] = [
                [x, float(colour.cctf_encoding(x, function=cctf))] for x in xs
            ]
            if cctf == "ITU-R BT.2020":
                # colour-science defaults to the 10-bit rounded constants (1.099, 0.018);
                # Prism uses the exact ones, closer to the 12-bit (1.0993, 0.0181) set.
                entry["encoding_12_bit"] = [
                    [
                        x,
                        float(
                            colour.cctf_encoding(
                                x, function=cctf, is_12_bits_system=True
                            )
                        ),
                    ]
                    for x in xs
                ]
        spaces.append(entry)
    prov = provenance(
        [
            "cs = colour.RGB_COLOURSPACES[colour_name]",
            "npm = colour.normalised_primary_matrix(cs.primaries, cs.whitepoint)",
            "encoding = [[x, colour.cctf_encoding(x, function=cctf)] for x in inputs]",
            "encoding_12_bit (BT.2020 only) = [[x, colour.cctf_encoding(x, function=cctf, "
            "is_12_bits_system=True)] for x in inputs]",
        ],
        "npm is row-major (npm[row][col]): linear RGB -> XYZ with white Y = 1. "
        "BT.2020 encodings only for x >= 0.",
    )
    write("rgb_spaces.json", prov, {"spaces": spaces})


def main():
    export_colorchecker()
    export_cct()
    export_ciede2000()
    export_adaptation()
    export_rgb_spaces()


if __name__ == "__main__":
    main()

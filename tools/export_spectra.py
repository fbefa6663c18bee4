#!/usr/bin/env python3
"""Export the CIE and ColorChecker tables in spectra/ from colour-science.

Run once (or when the pinned version changes):
    python3 -m pip install -r tools/requirements.txt
    python3 tools/export_spectra.py

Every CSV opens with a provenance header (source table, colour-science version,
the exact call) followed by a header line and `wavelength_nm,value...` rows at the
dataset's native spacing. Prism reads these files; it never runs Python.
"""

import pathlib
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "spectra"


def fmt(value):
    return repr(float(value))


def write(stem, source, call, columns, wavelengths, rows):
    lines = [
        f"# {stem}: {source}",
        f"# exported by tools/export_spectra.py with colour-science {colour.__version__}",
        f"# call: {call}",
        "# units: wavelength in nm; values as published (relative SPDs unnormalised)",
        ",".join(["wavelength_nm", *columns]),
    ]
    for wl, row in zip(wavelengths, rows):
        lines.append(",".join([fmt(wl), *(fmt(v) for v in row)]))
    (OUT / f"{stem}.csv").write_text("\n".join(lines) + "\n")


def export_single(stem, sd, source, call):
    write(stem, source, call, ["value"], sd.wavelengths, [[v] for v in sd.values])


def export_multi(stem, msds, source, call, columns):
    write(stem, source, call, columns, msds.wavelengths, msds.values)


def main():
    OUT.mkdir(exist_ok=True)
    cmfs = colour.MSDS_CMFS
    export_multi(
        "cie1931-2deg",
        cmfs["CIE 1931 2 Degree Standard Observer"],
        "CIE 1931 2 degree standard observer colour-matching functions (CIE 018:2019 / CIE 15:2004)",
        'colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]',
        ["x_bar", "y_bar", "z_bar"],
    )
    export_multi(
        "cie1964-10deg",
        cmfs["CIE 1964 10 Degree Standard Observer"],
        "CIE 1964 10 degree standard observer colour-matching functions (CIE 15:2004)",
        'colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"]',
        ["x_bar_10", "y_bar_10", "z_bar_10"],
    )
    export_single(
        "cie1924-photopic",
        colour.SDS_LEFS["CIE 1924 Photopic Standard Observer"],
        "CIE 1924 photopic luminous efficiency function V(lambda)",
        'colour.SDS_LEFS["CIE 1924 Photopic Standard Observer"]',
    )
    export_single(
        "cie1951-scotopic",
        colour.SDS_LEFS["CIE 1951 Scotopic Standard Observer"],
        "CIE 1951 scotopic luminous efficiency function V'(lambda)",
        'colour.SDS_LEFS["CIE 1951 Scotopic Standard Observer"]',
    )
    illuminants = ["A", "D50", "D55", "D60", "D65", "D75", "E"]
    illuminants += [f"FL{i}" for i in range(1, 13)]
    illuminants += ["LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1", "LED-V2"]
    for name in illuminants:
        # CIE names the fluorescent series F1..F12; colour-science calls them FL1..FL12.
        stem = name.replace("FL", "F") if name.startswith("FL") else name
        export_single(
            stem,
            colour.SDS_ILLUMINANTS[name],
            f"CIE illuminant {stem} relative spectral power distribution (CIE 15:2018 tables)",
            f'colour.SDS_ILLUMINANTS["{name}"]',
        )
    checker = colour.SDS_COLOURCHECKERS["BabelColor Average"]
    names = list(checker.keys())
    first = checker[names[0]]
    write(
        "colorchecker",
        "ColorChecker Classic 24 patch reflectances, BabelColor average of 30 charts (Pascale 2012)",
        'colour.SDS_COLOURCHECKERS["BabelColor Average"]',
        names,
        first.wavelengths,
        [[checker[n].values[i] for n in names] for i in range(len(first.wavelengths))],
    )


if __name__ == "__main__":
    main()

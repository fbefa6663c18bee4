#!/usr/bin/env python3
"""Export spectra/cie-daylight-basis.csv: the CIE daylight basis functions S0, S1, S2
(CIE 15:2018, Table 6) from which every D-series illuminant and the spectral daylight of
the Preetham sky are built, S(λ) = S0 + M1 S1 + M2 S2.

    python3 tools/export_daylight_basis.py

Prism reads the CSV (embedded at build time); it never runs Python.
"""

import pathlib
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
from colour.colorimetry.datasets.illuminants import (  # noqa: E402
    SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES as BASIS,
)

OUT = pathlib.Path(__file__).resolve().parent.parent / "spectra" / "cie-daylight-basis.csv"


def main():
    s0, s1, s2 = BASIS["S0"], BASIS["S1"], BASIS["S2"]
    lines = [
        "# cie-daylight-basis: CIE daylight basis functions S0, S1, S2 (CIE 15:2018, Table 6)",
        f"# exported by tools/export_daylight_basis.py with colour-science {colour.__version__}",
        "# call: colour.colorimetry.datasets.illuminants."
        'SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES["S0" | "S1" | "S2"]',
        "# units: wavelength in nm; relative values as published",
        "wavelength_nm,S0,S1,S2",
    ]
    for wl in s0.wavelengths:
        lines.append(",".join(repr(round(float(v), 6)) for v in (wl, s0[wl], s1[wl], s2[wl])))
    OUT.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

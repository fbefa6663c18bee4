#!/usr/bin/env python3
"""Synthetic BFC-450 file and the numbers `prism color --bispectral` must print for it.

    python3 tools/export_bispectral_fixture.py

Plain Python (standard library only), independent of Prism's code: it writes
tests/fixtures/bispectral-synthetic.bfc (an optically brightened white: R(λ) dips in the
violet, a UV-excited band re-radiates around 440 nm) and tests/fixtures/bispectral_cli.json
with, per illuminant, the band sums of docs/colour.md "Bispectral data" done directly on
the CSV tables in spectra/ (D65.csv, A.csv from 300 nm at 5 nm; cie1931-2deg.csv and
cie1964-10deg.csv at 1 nm), read at the file's 10 nm nodes without interpolation:

    XYZ_total = k Σ_λ cmf(λ) Σ_μ D(μ, λ) S(μ),   XYZ_reflected = k Σ_λ cmf(λ) R(λ) S(λ),
    k = 100 / Σ_λ S(λ) ȳ(λ),   βT(λ) = Σ_μ D(μ, λ) S(μ) / S(λ)   (D(λ, λ) = R(λ)),
    W = Y + 800 (x_n − x) + 1700 (y_n − y),   T_W = 900 (x_n − x) − 650 (y_n − y)
    (D65 total, CIE 1964 10° observer, x_n, y_n of the perfect diffuser on the same grid).
"""

import json
import math
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
SPECTRA = ROOT / "spectra"
FIXTURES = ROOT / "tests" / "fixtures"
BFC_NAME = "bispectral-synthetic.bfc"

EX = [300 + 10 * i for i in range(49)]  # excitation 300–780 nm
EM = [380 + 10 * i for i in range(41)]  # emission 380–780 nm


def read_csv(stem):
    """{nm: [values]} of spectra/<stem>.csv (comment and header lines skipped)."""
    table = {}
    for line in (SPECTRA / f"{stem}.csv").read_text().splitlines():
        fields = line.split(",")
        try:
            nm = float(fields[0])
        except ValueError:
            continue
        table[round(nm)] = [float(v) for v in fields[1:]]
    return table


def synthetic_bfc():
    """Radiance factors D[e][x] (emission row e, excitation column x), as written."""
    def reflectance(nm):
        # A white that yellows in the violet, as paper does before brightening.
        return 0.88 - 0.20 * math.exp(-((nm - 380) / 35.0) ** 2)

    def absorption(nm):
        return math.exp(-((nm - 350) / 25.0) ** 2)

    emission = [math.exp(-((nm - 440) / 20.0) ** 2) for nm in EM]
    total = sum(emission)
    rows = []
    for e, out_nm in enumerate(EM):
        row = []
        for in_nm in EX:
            if in_nm == out_nm:
                v = reflectance(out_nm)
            else:
                v = 0.5 * absorption(in_nm) * emission[e] / total
                # Tails below 1e-9 are written as 0 (Prism stores M in f32).
                v = v if v >= 1e-9 else 0.0
            # Written with 6 significant digits; the sums below use the written values.
            row.append(float(f"{v:.6g}"))
        rows.append(row)
    return rows


def write_bfc(rows):
    lines = ["VEC_01\t2009", "BFC-450 Matrix File", "; synthetic: tools/export_bispectral_fixture.py"]
    lines.append("380\t780\t10\t49\t300\t10")
    lines.append("r:c:\t" + "\t".join(str(nm) for nm in EX))
    for nm, row in zip(EM, rows):
        lines.append(f"{nm}\t" + "\t".join(f"{v:.6g}" for v in row))
    lines.append("EOD")
    (FIXTURES / BFC_NAME).write_text("\r\n".join(lines) + "\r\n")


def xy(xyz):
    s = sum(xyz)
    return [xyz[0] / s, xyz[1] / s]


def lab(xyz, white):
    def f(t):
        d = 6.0 / 29.0
        return t ** (1.0 / 3.0) if t > d ** 3 else t / (3 * d * d) + 4.0 / 29.0

    fx, fy, fz = (f(a / b) for a, b in zip(xyz, white))
    return [116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)]


def colorimetry(rows, illuminant, observer):
    spd = read_csv(illuminant)
    cmf = read_csv(observer)
    s = lambda nm: spd[nm][0]  # noqa: E731
    k = 100.0 / sum(s(nm) * cmf[nm][1] for nm in EM)
    excited = [sum(d * s(mu) for d, mu in zip(row, EX)) for row in rows]
    diag = [row[EX.index(nm)] for nm, row in zip(EM, rows)]
    white = [k * sum(cmf[nm][c] * s(nm) for nm in EM) for c in range(3)]
    total = [k * sum(cmf[nm][c] * excited[e] for e, nm in enumerate(EM)) for c in range(3)]
    reflected = [k * sum(cmf[nm][c] * diag[e] * s(nm) for e, nm in enumerate(EM)) for c in range(3)]
    beta_t = [[nm, excited[e] / s(nm)] for e, nm in enumerate(EM)]
    return white, reflected, total, beta_t, diag


def case(rows, illuminant):
    white, reflected, total, beta_t, diag = colorimetry(rows, illuminant, "cie1931-2deg")
    beta_l = [[nm, b - r] for (nm, b), r in zip(beta_t, diag)]
    peak = lambda pairs: max(pairs, key=lambda p: p[1])  # noqa: E731
    part = lambda xyz: {"XYZ": xyz, "xy": xy(xyz), "Lab": lab(xyz, white)}  # noqa: E731
    return {
        "illuminant": illuminant,
        "white_XYZ": white,
        "reflected": part(reflected),
        "total": part(total),
        "beta_t": beta_t,
        "beta_t_peak": peak(beta_t),
        "beta_l_peak": peak(beta_l),
    }


def main():
    rows = synthetic_bfc()
    write_bfc(rows)
    white10, _, total10, _, _ = colorimetry(rows, "D65", "cie1964-10deg")
    xn, yn = xy(white10)
    x, y = xy(total10)
    Y = total10[1]
    W = Y + 800 * (xn - x) + 1700 * (yn - y)
    T = 900 * (xn - x) - 650 * (yn - y)
    fixture = {
        "source": "tools/export_bispectral_fixture.py (standard library only)",
        "call": "python3 tools/export_bispectral_fixture.py",
        "data": "spectra/D65.csv, spectra/A.csv, spectra/cie1931-2deg.csv, spectra/cie1964-10deg.csv at the file's 10 nm nodes",
        "bfc": f"tests/fixtures/{BFC_NAME}",
        "args": ["--illuminant", "D65", "--compare-illuminant", "A"],
        "illuminants": [case(rows, "D65"), case(rows, "A")],
        "whiteness": {"XYZ": total10, "W": W, "T_W": T, "valid": 40 < W < 5 * Y - 280 and -4 < T < 2},
    }
    (FIXTURES / "bispectral_cli.json").write_text(json.dumps(fixture, indent=1) + "\n")
    print(json.dumps({"W": W, "T_W": T, "Y": Y, "valid": fixture["whiteness"]["valid"]}))
    for c in fixture["illuminants"]:
        print(c["illuminant"], c["total"]["XYZ"], c["beta_t_peak"], c["beta_l_peak"])


if __name__ == "__main__":
    main()

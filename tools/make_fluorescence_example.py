#!/usr/bin/env python3
"""Writes the synthetic data of scenes/fluorescence.json (no measured matrix goes into the
repository: the RIT bispectral files carry no data licence).

- highlighter-abs.csv, highlighter-em.csv: a yellow highlighter dye (pyranine-like):
  absorption bands at 440 nm and 370 nm, photon emission peaking at 515 nm.
- paper-oba.bfc: an optically brightened paper as a Labsphere BFC-450 file: a slightly
  yellowish base reflectance on the diagonal, and a brightener absorbing in the UV (peak
  350 nm) and re-emitting blue (peak 440 nm) off the diagonal (the dye model of
  crates/spectrum/src/dye.rs, D = M x 10 nm per band).
- paper-base.csv: the same paper without brightener (the BFC's diagonal).
- uv365.csv: a 365 nm UV LED, Gaussian, 10 nm full width at half maximum.

Run from the repository root: python3 tools/make_fluorescence_example.py
"""
import math
import os

OUT = os.path.join("scenes", "fluorescence")


def gaussian(l, centre, width):
    return math.exp(-((l - centre) ** 2) / (2 * width * width))


def paper_reflectance(l):
    # Base paper: 0.84 in the visible, falling towards the UV (lignin, fillers).
    return 0.84 - 0.30 * (1 - 1 / (1 + math.exp(-(l - 420) / 15)))


def write_csv(name, header, rows):
    with open(os.path.join(OUT, name), "w") as f:
        f.write(f"# synthetic, tools/make_fluorescence_example.py\nwavelength_nm,{header}\n")
        for l, v in rows:
            f.write(f"{l:g},{v:.6f}\n")


def main():
    os.makedirs(OUT, exist_ok=True)
    write_csv(
        "highlighter-abs.csv",
        "absorption",
        [(l, gaussian(l, 440, 30) + 0.6 * gaussian(l, 370, 20)) for l in range(300, 571, 5)],
    )
    write_csv(
        "highlighter-em.csv",
        "photons",
        [(l, gaussian(l, 515, 20)) for l in range(450, 701, 5)],
    )
    write_csv("paper-base.csv", "reflectance", [(l, paper_reflectance(l)) for l in range(360, 781, 10)])
    write_csv("uv365.csv", "value", [(l, gaussian(l, 365, 10 / 2.3548)) for l in range(340, 391)])

    # The brightener as a dye: M = a(li) * yield * li * n(lo) / sum(n * lo * step), n the
    # photon emission over lambda (photons per nm per lambda, as dye.rs).
    excitation = list(range(300, 781, 10))
    emission = list(range(360, 781, 10))
    quantum_yield, peak = 0.8, 0.7
    absorption = {l: peak * gaussian(l, 350, 25) for l in excitation}
    n = {l: gaussian(l, 440, 20) / l for l in emission}
    # Trapezoids of n * l (the stored rows are linear between nodes; close enough for a
    # synthetic sample, and energy stays below the absorbed fraction).
    norm = sum(0.5 * 10 * (n[a] * a + n[b] * b) for a, b in zip(emission, emission[1:]))
    lines = [
        "VEC_01\t1",
        "BFC-450 Matrix File",
        "; synthetic optically brightened paper, tools/make_fluorescence_example.py",
        f"{emission[0]}\t{emission[-1]}\t10\t{len(excitation)}\t{excitation[0]}\t10",
        "r:c:\t" + "\t".join(str(l) for l in excitation),
    ]
    for lo in emission:
        row = []
        for li in excitation:
            if li == lo:
                d = paper_reflectance(lo)
            else:
                m = absorption[li] * quantum_yield * li * n[lo] / norm
                d = m * 10
            row.append(f"{d:.6f}")
        lines.append(f"{lo}\t" + "\t".join(row))
    lines.append("EOD")
    with open(os.path.join(OUT, "paper-oba.bfc"), "w") as f:
        f.write("\r\n".join(lines) + "\r\n")


if __name__ == "__main__":
    main()

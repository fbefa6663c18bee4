#!/usr/bin/env python3
"""Writes scenes/tiled/tiles/grid.obj and grid.mtl: one period (0.1 m x 0.1 m) of a welded
wire grid, the paper's "grid" (Mostefaoui et al. Fig. 7): a square bar along x at
y = 0.05 m lying on the carrier (z from 0 to 8 mm) and one along y at x = 0.05 m welded on
top of it (z from 8 to 16 mm), both 8 mm square. The bars are open at the period planes,
where the next period's bar continues them (no open seams); the squares between the bars
are holes. Flat faces, vertex normals per face, as `tiles` in docs/scene-format.md
expects.

Usage: python3 tools/make_grid_tile.py [OUTPUT_DIR]   (default scenes/tiled/tiles)
"""
import os
import sys

PERIOD_M = 0.1
BAR_M = 0.008


def bar(along_x, z0, out):
    """A bar of square section BAR_M along x (or y) through the period's middle, from
    height z0 to z0 + BAR_M: its four long faces, each a quad of its own four vertices."""
    lo, hi = 0.5 * (PERIOD_M - BAR_M), 0.5 * (PERIOD_M + BAR_M)
    z1 = z0 + BAR_M

    def point(s, t, z):
        # s along the bar, t across it.
        return (s, t, z) if along_x else (t, s, z)

    # (across, height) corners of each face, counter-clockwise seen from outside, and the
    # outward normal in (across, height).
    faces = [
        (((lo, z0), (hi, z0)), (0.0, -1.0)),  # bottom
        (((hi, z0), (hi, z1)), (1.0, 0.0)),  # far side
        (((hi, z1), (lo, z1)), (0.0, 1.0)),  # top
        (((lo, z1), (lo, z0)), (-1.0, 0.0)),  # near side
    ]
    for (a, b), (nt, nz) in faces:
        base = len(out["v"]) + 1
        quad = [point(0.0, *a), point(PERIOD_M, *a), point(PERIOD_M, *b), point(0.0, *b)]
        normal = point(0.0, nt, nz)
        for p in quad:
            out["v"].append(p)
            out["vn"].append(normal)
        # Wound so that the right-hand normal is the outward one.
        i = [base, base + 1, base + 2, base + 3]
        if along_x:
            tris = [(i[0], i[3], i[2]), (i[0], i[2], i[1])]
        else:
            tris = [(i[0], i[1], i[2]), (i[0], i[2], i[3])]
        out["f"].extend(tris)


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scenes", "tiled", "tiles")
    out = {"v": [], "vn": [], "f": []}
    bar(True, 0.0, out)
    bar(False, BAR_M, out)
    with open(os.path.join(out_dir, "grid.obj"), "w") as f:
        f.write("# One period of a welded wire grid: tools/make_grid_tile.py\nmtllib grid.mtl\n")
        for p in out["v"]:
            f.write("v %.6g %.6g %.6g\n" % p)
        for n in out["vn"]:
            f.write("vn %.6g %.6g %.6g\n" % n)
        f.write("usemtl wire\n")
        for a, b, c in out["f"]:
            f.write("f %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c))
    with open(os.path.join(out_dir, "grid.mtl"), "w") as f:
        f.write("newmtl wire\nKd 0.6 0.6 0.6\n")


if __name__ == "__main__":
    main()

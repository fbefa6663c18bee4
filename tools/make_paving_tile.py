#!/usr/bin/env python3
"""Writes scenes/office/tiles/paving.obj and paving.mtl: one 0.2 m x 0.2 m period of a
paved floor, a square stone 0.18 m wide and 15 mm high with chamfered top edges, on a
grout bed. The period lies in the tile's x-y plane and z is the height above the carrier
(docs/scene-format.md, `tiles`); the grout bed's edges on the period planes meet the next
period's.

Usage: python3 tools/make_paving_tile.py [OUTPUT_DIR]   (default scenes/office/tiles)
"""
import os
import sys

PERIOD_M = 0.2
JOINT_M = 0.01  # grout between stones, on each side of a period
HEIGHT_M = 0.015
CHAMFER_M = 0.004


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "scenes/office/tiles"
    os.makedirs(out_dir, exist_ok=True)
    p, j, h, c = PERIOD_M, JOINT_M, HEIGHT_M, CHAMFER_M
    v = [
        # 1-4: the grout bed over the whole period
        (0, 0, 0), (p, 0, 0), (p, p, 0), (0, p, 0),
        # 5-8: the stone's foot
        (j, j, 0), (p - j, j, 0), (p - j, p - j, 0), (j, p - j, 0),
        # 9-12: top of the stone's sides (below the chamfer)
        (j, j, h - c), (p - j, j, h - c), (p - j, p - j, h - c), (j, p - j, h - c),
        # 13-16: the stone's top face
        (j + c, j + c, h), (p - j - c, j + c, h), (p - j - c, p - j - c, h), (j + c, p - j - c, h),
    ]
    grout = [(1, 2, 3), (1, 3, 4)]
    stone = [(13, 14, 15), (13, 15, 16)]  # top
    for a, b in [(0, 1), (1, 2), (2, 3), (3, 0)]:
        # side quad foot a,b -> top a,b (counter-clockwise seen from outside)
        fa, fb, ta, tb = 5 + a, 5 + b, 9 + a, 9 + b
        stone += [(fa, fb, tb), (fa, tb, ta)]
        # chamfer quad
        ca, cb = 13 + a, 13 + b
        stone += [(ta, tb, cb), (ta, cb, ca)]
    with open(os.path.join(out_dir, "paving.obj"), "w") as f:
        f.write("# One period of a paved floor; written by tools/make_paving_tile.py\n")
        f.write("mtllib paving.mtl\n")
        for x in v:
            f.write("v %.9g %.9g %.9g\n" % x)
        f.write("usemtl grout\n")
        for t in grout:
            f.write("f %d %d %d\n" % t)
        f.write("usemtl stone\n")
        for t in stone:
            f.write("f %d %d %d\n" % t)
    with open(os.path.join(out_dir, "paving.mtl"), "w") as f:
        f.write("# Names only: the scene's `tiles.*.materials` maps them to scene materials.\n")
        f.write("newmtl grout\nKd 0.15 0.15 0.15\nnewmtl stone\nKd 0.35 0.35 0.35\n")


if __name__ == "__main__":
    main()

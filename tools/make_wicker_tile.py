#!/usr/bin/env python3
"""Writes scenes/tiled/tiles/wicker.obj and wicker.mtl: one period (0.1 m x 0.1 m) of a plain
weave of four flat strands, two along x and two along y, passing over and under each
other. The period lies in the tile's x-y plane and z is the height above the carrier, as
`tiles` in docs/scene-format.md expects. The strand ends at x = 0 / 0.1 m (resp. y) are the
same rings shifted by one period, so the weave continues across tiles; the gaps between
strands are holes that light passes through.

Usage: python3 tools/make_wicker_tile.py [OUTPUT_DIR]   (default scenes/tiled/tiles)
"""
import math
import os
import sys

PERIOD_M = 0.1
AMPLITUDE_M = 0.006  # height of the weave's centre line above/below the carrier
HALF_WIDTH_M = 0.015  # strands are 30 mm wide: 20 mm holes between them
HALF_THICKNESS_M = 0.004
SEGMENTS = 32  # along a strand, per period
SIDES = 12  # around the strand's elliptical cross-section


def strand(along_x, offset_m, phase_sign, material, out):
    """A strand along x (or y) at y (or x) = offset_m, centre height
    phase_sign * A * cos(2 pi (s - 0.025) / P)."""
    verts, normals, faces = out["v"], out["vn"], out["f"]
    base = len(verts)
    for i in range(SEGMENTS + 1):
        s = PERIOD_M * i / SEGMENTS
        if i == SEGMENTS:
            s = PERIOD_M  # exactly the period, so the end ring is the start ring shifted
        z0 = phase_sign * AMPLITUDE_M * math.cos(2 * math.pi * (s - 0.025) / PERIOD_M)
        for k in range(SIDES):
            a = 2 * math.pi * k / SIDES
            across = offset_m + HALF_WIDTH_M * math.cos(a)
            z = z0 + HALF_THICKNESS_M * math.sin(a)
            # The ellipse's normal (the weave's slope is left out of the normal: shading only).
            n_across = math.cos(a) / HALF_WIDTH_M
            n_z = math.sin(a) / HALF_THICKNESS_M
            if along_x:
                verts.append((s, across, z))
                normals.append((0.0, n_across, n_z))
            else:
                verts.append((across, s, z))
                normals.append((n_across, 0.0, n_z))
    faces.append(("usemtl", material))
    for i in range(SEGMENTS):
        for k in range(SIDES):
            a = base + i * SIDES + k
            b = base + i * SIDES + (k + 1) % SIDES
            c = base + (i + 1) * SIDES + (k + 1) % SIDES
            d = base + (i + 1) * SIDES + k
            # Counter-clockwise seen from outside the strand.
            if along_x:
                faces.append((a, b, c))
                faces.append((a, c, d))
            else:
                faces.append((a, d, c))
                faces.append((a, c, b))


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "scenes/tiled/tiles"
    os.makedirs(out_dir, exist_ok=True)
    mesh = {"v": [], "vn": [], "f": []}
    strand(True, 0.025, +1, "strand_weft", mesh)
    strand(True, 0.075, -1, "strand_weft", mesh)
    strand(False, 0.025, -1, "strand_warp", mesh)
    strand(False, 0.075, +1, "strand_warp", mesh)
    with open(os.path.join(out_dir, "wicker.obj"), "w") as f:
        f.write("# One period of a plain wicker weave; written by tools/make_wicker_tile.py\n")
        f.write("mtllib wicker.mtl\n")
        for v in mesh["v"]:
            f.write("v %.9g %.9g %.9g\n" % v)
        for n in mesh["vn"]:
            f.write("vn %.9g %.9g %.9g\n" % n)
        for face in mesh["f"]:
            if face[0] == "usemtl":
                f.write("usemtl %s\n" % face[1])
            else:
                f.write("f %s\n" % " ".join("%d//%d" % (i + 1, i + 1) for i in face))
    with open(os.path.join(out_dir, "wicker.mtl"), "w") as f:
        f.write("# Names only: the scene's `tiles.*.materials` maps them to scene materials.\n")
        f.write("newmtl strand_weft\nKd 0.8 0.6 0.4\n")
        f.write("newmtl strand_warp\nKd 0.5 0.35 0.2\n")


if __name__ == "__main__":
    main()

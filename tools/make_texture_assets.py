#!/usr/bin/env python3
"""Writes the small texture assets of scenes/textures.json into scenes/textures/ (no
photographs, so no licence question; standard library only, deterministic):

- bricks-albedo.png   128×128 RGB 8-bit, sRGB-encoded: running-bond bricks (0.25 × 0.125 of
                      the tile) in slightly varying reds, light grey mortar.
- bricks-normal.png   128×128 RGB 8-bit, linear: the tangent-space normal map of the same
                      bricks' height field (mortar grooves, bevelled brick edges), by
                      central differences; (0.5, 0.5, 1) is flat, +x along u, +y along v.
- roughness.png       64×64 grey 8-bit, linear: GGX α from 0.05 (polished stripes) to 0.4.
- leaf-mask.png       64×64 grey+alpha 8-bit: an ellipse leaf with a notch, alpha = opacity.

    python3 tools/make_texture_assets.py
"""
import math
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "textures")


def write_png(path, width, height, channels, rows):
    """rows: list (top to bottom) of lists of 8-bit samples, `channels` per pixel."""
    colour_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9))
    png += chunk(b"IEND", b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def srgb_encode(x):
    x = min(max(x, 0.0), 1.0)
    return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055


def code(x):
    return int(round(min(max(x, 0.0), 1.0) * 255))


def hash01(i, j):
    h = (i * 374761393 + j * 668265263) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return (h & 0xFFFF) / 65535.0


N = 128
BRICKS_X, BRICKS_Y = 4, 8  # bricks per tile
MORTAR = 0.06  # mortar half-width in brick-height units


def brick(u, v):
    """(height in [0, 1], brick id or None) at tile coordinates u, v ∈ [0, 1)."""
    row = int(v * BRICKS_Y)
    x = u * BRICKS_X + (0.5 if row % 2 else 0.0)
    col = int(math.floor(x)) % BRICKS_X
    fx, fy = x - math.floor(x), v * BRICKS_Y - row
    # Distance to the brick's edge in brick-height units (bricks are twice as wide).
    edge = min(fx * 2.0, (1 - fx) * 2.0, fy, 1 - fy)
    if edge < MORTAR:
        return 0.0, None
    return min(1.0, (edge - MORTAR) / 0.12), (row, col)


def height(u, v):
    return brick(u % 1.0, v % 1.0)[0]


def main():
    os.makedirs(OUT, exist_ok=True)
    albedo_rows, normal_rows = [], []
    for y in range(N):
        v = 1.0 - (y + 0.5) / N  # top row is v = 1
        arow, nrow = [], []
        for x in range(N):
            u = (x + 0.5) / N
            h, b = brick(u, v)
            if b is None:
                rgb = (0.55, 0.54, 0.50)
            else:
                t = hash01(*b)
                rgb = (0.42 + 0.12 * t, 0.13 + 0.05 * t, 0.08 + 0.03 * t)
            arow += [code(srgb_encode(c)) for c in rgb]
            # Height field slope (heights in units of 0.02 tile) by central differences.
            d = 1.0 / N
            dhdu = (height(u + d, v) - height(u - d, v)) / (2 * d) * 0.02
            dhdv = (height(u, v + d) - height(u, v - d)) / (2 * d) * 0.02
            n = (-dhdu, -dhdv, 1.0)
            length = math.sqrt(sum(c * c for c in n))
            nrow += [code(0.5 * (c / length + 1.0)) for c in n]
        albedo_rows.append(arow)
        normal_rows.append(nrow)
    write_png(os.path.join(OUT, "bricks-albedo.png"), N, N, 3, albedo_rows)
    write_png(os.path.join(OUT, "bricks-normal.png"), N, N, 3, normal_rows)

    rough_rows = []
    for y in range(64):
        v = (y + 0.5) / 64
        rough_rows.append([code(0.05 + 0.35 * (0.5 + 0.5 * math.sin(2 * math.pi * 4 * v)))
                           for _ in range(64)])
    write_png(os.path.join(OUT, "roughness.png"), 64, 64, 1, rough_rows)

    leaf_rows = []
    for y in range(64):
        row = []
        for x in range(64):
            px, py = (x + 0.5) / 32 - 1, (y + 0.5) / 32 - 1
            inside = (px / 0.55) ** 2 + (py / 0.95) ** 2 < 1 and not (py < -0.7 and abs(px) < 0.12)
            row += [code(0.8), 255 if inside else 0]
        leaf_rows.append(row)
    write_png(os.path.join(OUT, "leaf-mask.png"), 64, 64, 2, leaf_rows)


if __name__ == "__main__":
    main()

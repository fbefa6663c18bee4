#!/usr/bin/env python3
"""Writes scenes/stress/media/smoke.vol, the density grid of the `chromatic-smoke` stress
scene: a rising, leaning plume of Gaussian puffs (deterministic, no randomness), peak
density 1, in Mitsuba's `.vol` format (VOL, version 3, float32, 1 channel, x fastest;
docs/scene-format.md, "Density grids").

Run: python3 tools/make_smoke_vol.py   (standard library only)
"""
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "scenes", "stress", "media", "smoke.vol")
RES = (24, 32, 24)  # x, y, z voxels: small enough to commit (72 KiB)
BOUNDS = ((-0.5, 0.0, -0.5), (0.5, 1.4, 0.5))  # metres, the file's own box


def density(x, y, z):
    """Puffs along a plume that rises from the floor and drifts towards +x."""
    total = 0.0
    for i in range(9):
        t = i / 8.0
        cx, cy, cz = -0.15 + 0.3 * t * t, 0.1 + 1.1 * t, 0.05 * math.sin(5.0 * t)
        radius = 0.08 + 0.12 * t
        weight = 1.0 - 0.5 * t
        d2 = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
        total += weight * math.exp(-d2 / (2.0 * radius * radius))
    # Small-scale structure: a product of sines, kept ≥ 0.
    swirl = 0.75 + 0.25 * math.sin(17.0 * x + 3.0 * y) * math.sin(13.0 * z - 5.0 * y)
    return total * swirl


def main():
    (x0, y0, z0), (x1, y1, z1) = BOUNDS
    nx, ny, nz = RES
    values = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                # Voxel centres span the box (Mitsuba's convention for .vol grids).
                x = x0 + (x1 - x0) * (i + 0.5) / nx
                y = y0 + (y1 - y0) * (j + 0.5) / ny
                z = z0 + (z1 - z0) * (k + 0.5) / nz
                values.append(density(x, y, z))
    peak = max(values)
    values = [v / peak for v in values]
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "wb") as f:
        f.write(b"VOL" + bytes([3]))
        f.write(struct.pack("<i", 1))
        f.write(struct.pack("<3i", nx, ny, nz))
        f.write(struct.pack("<i", 1))
        f.write(struct.pack("<6f", x0, y0, z0, x1, y1, z1))
        f.write(struct.pack(f"<{len(values)}f", *values))
    print(f"wrote {os.path.relpath(OUT, ROOT)}: {nx}×{ny}×{nz}, mean density "
          f"{sum(values) / len(values):.3f}")


if __name__ == "__main__":
    main()

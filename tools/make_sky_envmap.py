#!/usr/bin/env python3
"""Writes scenes/envmaps/sky-512x256.hdr: a procedural equirectangular sky for the example
scenes (no photograph, so no licence question). Radiance RGBE (Ward 1991), flat (not RLE)
scanlines, top row = +Y (docs/lights.md for Prism's orientation).

The sky: a vertical gradient from a saturated zenith blue to a pale horizon, a warm
brown ground below the horizon, and a small bright sun disc (0.6° wide, 40° above the
horizon, towards +X) carrying most of the energy, so the environment importance sampling
has something to find. Linear Rec.709 values, arbitrary units (scale them in the scene).

    python3 tools/make_sky_envmap.py   # needs only the standard library
"""
import math
import os
import struct

W, H = 512, 256
SUN_ELEVATION_DEG = 40.0
SUN_AZIMUTH_U = 0.25  # u = 1/4 is +X in Prism's (and Mitsuba's) equirect convention
SUN_RADIUS_DEG = 0.6
SUN_RGB = (4000.0, 3600.0, 3000.0)


def direction(u, v):
    theta, phi = math.pi * v, 2 * math.pi * u
    return (math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta))


def sky(u, v):
    d = direction(u, v)
    elev = math.asin(max(-1.0, min(1.0, d[1])))
    if elev < 0:
        t = min(1.0, -elev / (math.pi / 2))
        return tuple((1 - t) * a + t * b for a, b in zip((0.35, 0.30, 0.25), (0.12, 0.09, 0.07)))
    t = elev / (math.pi / 2)
    horizon, zenith = (0.85, 0.90, 1.00), (0.15, 0.35, 0.85)
    rgb = [(1 - t) ** 2 * h + (1 - (1 - t) ** 2) * z for h, z in zip(horizon, zenith)]
    s = direction(SUN_AZIMUTH_U, 0.5 - SUN_ELEVATION_DEG / 180.0)
    cos_angle = sum(a * b for a, b in zip(d, s))
    if cos_angle > math.cos(math.radians(SUN_RADIUS_DEG)):
        return SUN_RGB
    glow = math.exp(-(1 - cos_angle) * 60.0) * 3.0
    return tuple(c + glow * w for c, w in zip(rgb, (1.0, 0.9, 0.7)))


def rgbe(rgb):
    m = max(rgb)
    if m < 1e-32:
        return bytes((0, 0, 0, 0))
    e = math.frexp(m)[1]
    scale = 256.0 / (2.0 ** e)
    return bytes([min(255, int(c * scale)) for c in rgb] + [e + 128])


def write_envmap(name, radiance, width, height, supersamples, source):
    """Writes `radiance(u, v)` (linear RGB) as a flat RGBE file scenes/envmaps/`name`, each
    texel the mean of supersamples × supersamples points (edges that fall between texels
    stay smooth), through a temporary file and a rename. `source` names the script in the
    header."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = os.path.join(root, "scenes", "envmaps", name)
    n = supersamples
    rows = []
    for y in range(height):
        row = bytearray()
        for x in range(width):
            acc = [0.0, 0.0, 0.0]
            for a in range(n):
                for b in range(n):
                    c = radiance((x + (a + 0.5) / n) / width, (y + (b + 0.5) / n) / height)
                    acc = [p + q for p, q in zip(acc, c)]
            row += rgbe([c / (n * n) for c in acc])
        rows.append(bytes(row))
    header = f"#?RADIANCE\n# {source}\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n"
    os.makedirs(os.path.dirname(out), exist_ok=True)
    tmp = out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(header.encode("ascii"))
        for r in rows:
            f.write(r)
    os.replace(tmp, out)
    print(out)


def main():
    # The sun disc is tiny: 4 × 4 supersamples per texel for a smooth edge.
    write_envmap("sky-512x256.hdr", sky, W, H, 4, "tools/make_sky_envmap.py")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes scenes/envmaps/windows-512x256.hdr: a procedural equirectangular interior lit
through a few bright windows, for the bandwidth predictor's Fig. 9 scene
(scenes/bandwidth/fig9-spheres.json). Bagher et al. 2013 light Fig. 9 with measured
environment maps of interiors, where several small bright windows (not one sun) carry most
of the energy: every window casts its own shadow edge on the floor and its own highlight on
each sphere, so the image has the high-frequency detail and the shading noise the predictor
is for, and a uniform path tracer needs hundreds of samples per pixel to settle. No
photograph, so no licence question. Radiance RGBE (Ward 1991), flat scanlines, top row = +Y
(docs/lights.md for Prism's orientation); linear Rec.709 values, arbitrary units.

    python3 tools/make_windows_envmap.py   # needs only the standard library
"""
import math

from make_sky_envmap import direction, write_envmap

W, H = 512, 256
# (azimuth u, elevation in degrees, half-width in degrees, half-height in degrees, RGB):
# windows of different sizes and colours around the room, a few of them high up.
WINDOWS = [
    (0.10, 35.0, 0.8, 1.8, (2100.0, 2025.0, 1820.0)),
    (0.30, 20.0, 0.6, 1.2, (3150.0, 2800.0, 2170.0)),
    (0.46, 50.0, 0.5, 0.5, (5250.0, 5250.0, 5600.0)),
    (0.80, 15.0, 0.4, 0.8, (4200.0, 3500.0, 2800.0)),
]


def radiance(u, v):
    d = direction(u, v)
    elevation_deg = math.degrees(math.asin(max(-1.0, min(1.0, d[1]))))
    azimuth_deg = 360.0 * u
    for wu, we, half_w, half_h, rgb in WINDOWS:
        du = (azimuth_deg - 360.0 * wu + 180.0) % 360.0 - 180.0
        # Half-widths are measured along the horizon, so a window keeps its solid angle.
        if abs(du) * math.cos(math.radians(we)) <= half_w and abs(elevation_deg - we) <= half_h:
            return rgb
    # Dim walls: a warm floor below the horizon, a greyish ceiling above.
    if elevation_deg < 0:
        return (0.04, 0.032, 0.024)
    t = elevation_deg / 90.0
    return tuple(0.07 * (1 - t) + 0.04 * t for _ in range(3))


def main():
    # 4 × 4 supersamples per texel: window edges fall between texels.
    write_envmap("windows-512x256.hdr", radiance, W, H, 4, "tools/make_windows_envmap.py")


if __name__ == "__main__":
    main()

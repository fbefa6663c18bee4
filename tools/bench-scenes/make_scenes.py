#!/usr/bin/env python3
"""Writes the speed-suite scenes (issue 22) into tools/bench-scenes/: five Prism scene files
(the sixth, the Cornell box, is scenes/cornell-box.json) and, into the git-ignored
tools/bench-scenes/generated/, the assets no download provides — the 10⁶-triangle displaced
sphere (binary PLY with vertex normals and uv) and a smooth sky (EXR, no sun in the map: the
sun is a separate directional light, so both renderers sample it the same way).

Every scene is one Prism can render and tools/mitsuba/prism_scene.py translates for Mitsuba 3
without refusing anything; only numpy is needed (the EXR is written through Mitsuba's
Bitmap when run from tools/mitsuba/.venv, the tools/bench-scenes/run.py default).

    tools/mitsuba/.venv/bin/python tools/bench-scenes/make_scenes.py [--assets-only]
"""

import argparse
import json
import math
import pathlib
import struct
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
GENERATED = HERE / "generated"
MESH = GENERATED / "displaced-sphere-1m.ply"
SKY = GENERATED / "smooth-sky-256x128.exr"

# Splatting each sample into every pixel under the filter, as Mitsuba's film does: the same
# expected image as Prism's default (filter importance sampling) with less per-pixel noise
# (correlated between neighbours), so equal-error ratios compare like with like.
FILM = {"resolution": [256, 256], "spp": 64, "reconstruction": "splat",
        "filter": {"type": "gaussian", "radius_px": 2, "sigma_px": 0.5}}
INTEGRATOR = {"type": "path", "max_depth": 7, "rr_depth": 5}


def floor_rect(size, material, y=0.0, name=None):
    s = {"type": "rectangle", "size_m": size, "material": material,
         "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [0, y, 0]}]}
    if name:
        s["name"] = name
    return s


def wall(size, material, z):
    return {"type": "rectangle", "size_m": size, "material": material,
            "transform": {"translate": [0, size[1] / 2, z]}}


def ceiling_light(name, size, y, x=0.0, z=0.0):
    return {"type": "rectangle", "name": name, "size_m": size, "material": "black",
            "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [x, y, z]}]}


def sphere(r, material, x, y, z):
    return {"type": "sphere", "radius_m": r, "material": material,
            "transform": {"translate": [x, y, z]}}


def glossy_scene():
    """Scene 2: rough conductors (GGX, Beckmann, anisotropic GGX), a rough dielectric, a
    smooth glass sphere and a coated (plastic) sphere on a grey floor, lit by a ceiling panel
    and a dim uniform sky."""
    return {
        "camera": {"type": "pinhole", "fov_deg": 40,
                   "transform": {"look_at": {"eye": [0, 1.6, 5.2], "target": [0, 0.45, 0]}}},
        "film": FILM, "integrator": INTEGRATOR,
        "materials": {
            "floor": {"type": "lambert", "reflectance": 0.45},
            "backdrop": {"type": "lambert", "reflectance": {"rgb": [0.55, 0.6, 0.7]}},
            "black": {"type": "lambert", "reflectance": 0},
            "gold-ggx": {"type": "conductor", "metal": "Au", "roughness": 0.2},
            "aluminium-beckmann": {"type": "conductor", "metal": "Al", "roughness": 0.3,
                                   "distribution": "beckmann"},
            "copper-anisotropic": {"type": "conductor", "metal": "Cu", "roughness": [0.05, 0.4]},
            "frosted-glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.2},
            "glass": {"type": "dielectric", "ior": 1.5},
            "red-plastic": {"type": "coated", "diffuse": {"rgb": [0.7, 0.08, 0.06]}, "ior": 1.5},
        },
        "shapes": [
            floor_rect([12, 12], "floor"),
            wall([12, 6], "backdrop", -2.5),
            sphere(0.45, "gold-ggx", -1.6, 0.45, 0.2),
            sphere(0.45, "aluminium-beckmann", -0.55, 0.45, -0.6),
            sphere(0.45, "copper-anisotropic", 0.55, 0.45, -0.6),
            sphere(0.45, "frosted-glass", 1.6, 0.45, 0.2),
            sphere(0.4, "glass", -0.5, 0.4, 1.1),
            sphere(0.4, "red-plastic", 0.55, 0.4, 1.0),
            ceiling_light("panel", [2.0, 1.2], 3.2, 0.0, 0.6),
        ],
        "lights": [
            {"type": "area", "shape": "panel", "luminance_cd_m2": 8000, "spectrum": "D65"},
            {"type": "sky", "luminance_cd_m2": 150, "spectrum": "D65"},
        ],
    }


def textured_materials():
    return {
        "bricks": {"type": "lambert", "reflectance": {"texture": {
            "type": "image", "file": "../../scenes/textures/bricks-albedo.png",
            "filter": "bilinear", "uv_scale": 4}}},
        "bricks-bumped": {"type": "normal_map", "material": "bricks", "texture": {
            "type": "image", "file": "../../scenes/textures/bricks-normal.png",
            "filter": "bilinear", "uv_scale": 4}},
        "patchy-metal": {"type": "conductor", "metal": "Al", "roughness": {"texture": {
            "type": "image", "file": "../../scenes/textures/roughness.png",
            "filter": "bilinear", "uv_scale": 3}}},
        "checker-panel": {"type": "lambert", "reflectance": {"texture": {
            "type": "image", "file": "../../scenes/textures/bricks-albedo.png",
            "filter": "bilinear", "uv_scale": 1}}},
        "grey": {"type": "lambert", "reflectance": 0.5},
        "black": {"type": "lambert", "reflectance": 0},
    }


def textured_shapes():
    return [
        floor_rect([10, 10], "bricks-bumped"),
        wall([10, 5], "patchy-metal", -2.0),
        {"type": "rectangle", "size_m": [1.2, 1.2], "material": "checker-panel",
         "transform": [{"rotate": {"axis": [0, 1, 0], "angle_deg": 25}},
                       {"translate": [-0.9, 0.6, -0.4]}]},
        sphere(0.5, "grey", 0.9, 0.5, 0.3),
        ceiling_light("panel", [2.0, 2.0], 3.0, 0.0, 1.0),
    ]


def textured_scene():
    """Scene 3: image textures on a reflectance (bricks) and on a conductor's roughness, and a
    tangent-space normal map on the floor."""
    return {
        "camera": {"type": "pinhole", "fov_deg": 50,
                   "transform": {"look_at": {"eye": [0.3, 1.5, 3.6], "target": [0, 0.5, -0.5]}}},
        "film": FILM, "integrator": INTEGRATOR,
        "materials": textured_materials(),
        "shapes": textured_shapes(),
        "lights": [
            {"type": "area", "shape": "panel", "luminance_cd_m2": 6000, "spectrum": "D65"},
            {"type": "sky", "luminance_cd_m2": 200, "spectrum": "D65"},
        ],
    }


def defocus_scene():
    """Scene 6: the textured scene through a 50 mm f/0.7 thin lens (the aperture of Zeiss's
    Planar 50 mm f/0.7) focused on the floor 1.8 m away: the back wall and the near floor
    blur over circles of confusion of about 10 px (1.4 mm on the 36 mm sensor)."""
    scene = textured_scene()
    scene["camera"] = {"type": "thin_lens", "focal_length_mm": 50, "sensor_width_mm": 36,
                       "f_number": 0.7, "focus_distance_m": 1.8,
                       "transform": {"look_at": {"eye": [0.3, 1.5, 3.6], "target": [0, 0.5, -0.5]}}}
    return scene


def mesh_scene():
    """Scene 4: a displaced sphere of 10⁶ triangles with vertex normals (coated, blue) on a
    floor, under a smooth sky map and a sun (a directional light)."""
    return {
        "camera": {"type": "pinhole", "fov_deg": 40,
                   "transform": {"look_at": {"eye": [0, 1.4, 4.2], "target": [0, 0.9, 0]}}},
        "film": FILM, "integrator": INTEGRATOR,
        "meshes": {"blob": "generated/" + MESH.name},
        "materials": {
            "ground": {"type": "lambert", "reflectance": {"rgb": [0.4, 0.38, 0.35]}},
            "blue-plastic": {"type": "coated", "diffuse": {"rgb": [0.1, 0.25, 0.6]}, "ior": 1.5},
        },
        "shapes": [
            floor_rect([30, 30], "ground"),
            {"type": "mesh", "mesh": "blob", "material": "blue-plastic",
             "transform": {"translate": [0, 1.0, 0]}},
        ],
        "lights": [
            # Bilinear, as Mitsuba's envmap always interpolates: with Prism's default (nearest)
            # the two renderers' images differed by the texel steps of the directly seen sky,
            # 46 % of Prism's MSE at 64 spp and no noise at all.
            {"type": "environment", "file": "generated/" + SKY.name, "scale": 1.0,
             "filter": "bilinear"},
            {"type": "directional", "direction": [-0.5, -0.75, -0.45], "illuminance_lx": 60000,
             "spectrum": "D65"},
        ],
    }


def many_lights_scene():
    """Scene 5: the open-plan office of scenes/many-lights/open-office.json (96 ceiling panels
    and 24 desk lamps), at 384 × 216 with the suite's filter."""
    scene = json.loads((ROOT / "scenes" / "many-lights" / "open-office.json").read_text())
    scene["film"] = dict(FILM, resolution=[384, 216])
    return scene


SCENES = {
    "glossy-glass": glossy_scene,
    "textured": textured_scene,
    "mesh-env-sun": mesh_scene,
    "many-lights": many_lights_scene,
    "defocus": defocus_scene,
}


# ----------------------------------------------------------------------------- assets


def displaced_sphere(rows=500, cols=1000):
    """A unit sphere displaced by r = 1 + 0.06 sin(7θ) cos(9φ) + 0.02 sin(23θ) sin(17φ),
    rows × cols quads (2·rows·cols triangles), area-weighted vertex normals, uv = (φ/2π, θ/π)."""
    theta = np.linspace(1e-3, math.pi - 1e-3, rows + 1)
    phi = np.linspace(0.0, 2 * math.pi, cols + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1 + 0.06 * np.sin(7 * t) * np.cos(9 * p) + 0.02 * np.sin(23 * t) * np.sin(17 * p)
    pos = np.stack([r * np.sin(t) * np.sin(p), r * np.cos(t), r * np.sin(t) * np.cos(p)], -1)
    idx = np.arange((rows + 1) * (cols + 1)).reshape(rows + 1, cols + 1)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])
    v = pos.reshape(-1, 3)
    fn = np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]])
    normals = np.zeros_like(v)
    for k in range(3):
        np.add.at(normals, tris[:, k], fn)
    # The seam column repeats the first: give both the same normal.
    n = normals.reshape(rows + 1, cols + 1, 3)
    seam = n[:, 0] + n[:, -1]
    n[:, 0], n[:, -1] = seam, seam
    normals = n.reshape(-1, 3)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    uv = np.stack([p / (2 * math.pi), 1 - t / math.pi], -1).reshape(-1, 2)
    return v.astype(np.float32), normals.astype(np.float32), uv.astype(np.float32), tris.astype(np.int32)


def write_ply(path, v, n, uv, tris):
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment generated by tools/bench-scenes/make_scenes.py\n"
        f"element vertex {len(v)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float u\nproperty float v\n"
        f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    verts = np.concatenate([v, n, uv], axis=1).astype("<f4")
    faces = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"], faces["i"] = 3, tris
    tmp = path.with_suffix(".tmp")
    with open(tmp, "wb") as f:
        f.write(header.encode())
        f.write(verts.tobytes())
        f.write(faces.tobytes())
    tmp.replace(path)


def smooth_sky(w=256, h=128):
    """Linear Rec.709 radiance (arbitrary units, ~1): blue zenith to pale horizon, brown
    ground, blended over ±8° around the horizon; no sun disc. Smooth on purpose: Prism puts
    the rows at texel centres, Mitsuba the first and last on the poles (docs/lights.md), and
    a one-row horizon step would show that half-texel difference as error along the horizon
    in every image."""
    v = (np.arange(h) + 0.5) / h
    elev = (0.5 - v) * math.pi  # +π/2 at the top row
    up = np.clip(np.sin(elev), 0, 1)[:, None]
    sky = (1 - up) * np.array([0.9, 0.95, 1.0]) + up * np.array([0.25, 0.45, 0.9])
    ground = np.array([0.25, 0.2, 0.15])
    x = np.clip((elev + math.radians(8)) / math.radians(16), 0, 1)[:, None]
    blend = x * x * (3 - 2 * x)
    rows = blend * sky + (1 - blend) * ground
    return np.repeat(rows[:, None, :], w, axis=1).astype(np.float32)


def write_exr(path, img):
    sys.path.insert(0, str(ROOT / "tools" / "mitsuba"))
    from common import import_mitsuba

    mi = import_mitsuba()
    mi.set_variant("scalar_rgb")
    tmp = path.with_name(path.stem + ".tmp.exr")
    mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(tmp))
    tmp.replace(path)


def make_assets(force=False):
    GENERATED.mkdir(exist_ok=True)
    if force or not MESH.exists():
        print(f"writing {MESH.relative_to(ROOT)} (10⁶ triangles)…", file=sys.stderr)
        write_ply(MESH, *displaced_sphere())
    if force or not SKY.exists():
        write_exr(SKY, smooth_sky())


def compact(value):
    return json.dumps(value, indent=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--assets-only", action="store_true")
    ap.add_argument("--force", action="store_true", help="rewrite the generated assets")
    args = ap.parse_args()
    make_assets(args.force)
    if args.assets_only:
        return
    for name, build in SCENES.items():
        path = HERE / f"{name}.json"
        path.write_text(compact(build()) + "\n")
        print(f"wrote {path.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes scenes/many-lights/open-office.json: an open-plan office 40 m x 16 m x 3 m lit by
96 ceiling panels (0.6 m square area lights facing down) and 24 desk lamps (point lights),
120 luminaires of equal kinds, seen from one end. From any point most luminaires are far
away or behind it, so choosing lights in proportion to power wastes most light samples: the
light-selection benchmark scene (issue 22's scene 5).

    python3 tools/make_many_lights_office.py
"""
import json
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "scenes" / "many-lights" / "open-office.json"

LENGTH_M, WIDTH_M, HEIGHT_M = 40.0, 16.0, 3.0


def rect(name, size, material, transform):
    return {"type": "rectangle", "name": name, "size_m": size, "material": material,
            "transform": transform}


def face_down(x, y, z):
    return [{"rotate": {"axis": [1, 0, 0], "angle_deg": 90}}, {"translate": [x, y, z]}]


def face_up(x, y, z):
    return [{"rotate": {"axis": [1, 0, 0], "angle_deg": -90}}, {"translate": [x, y, z]}]


def main():
    shapes = [
        rect("floor", [LENGTH_M, WIDTH_M], "floor", face_up(0, 0, 0)),
        rect("ceiling", [LENGTH_M, WIDTH_M], "ceiling", face_down(0, HEIGHT_M, 0)),
        # Walls facing into the room.
        rect("wall_far", [WIDTH_M, HEIGHT_M], "wall",
             [{"rotate": {"axis": [0, 1, 0], "angle_deg": -90}},
              {"translate": [LENGTH_M / 2, HEIGHT_M / 2, 0]}]),
        rect("wall_near", [WIDTH_M, HEIGHT_M], "wall",
             [{"rotate": {"axis": [0, 1, 0], "angle_deg": 90}},
              {"translate": [-LENGTH_M / 2, HEIGHT_M / 2, 0]}]),
        rect("wall_left", [LENGTH_M, HEIGHT_M], "wall",
             [{"translate": [0, HEIGHT_M / 2, -WIDTH_M / 2]}]),
        rect("wall_right", [LENGTH_M, HEIGHT_M], "wall",
             [{"rotate": {"axis": [0, 1, 0], "angle_deg": 180}},
              {"translate": [0, HEIGHT_M / 2, WIDTH_M / 2]}]),
    ]
    lights = []
    # 12 x 8 ceiling panels, just below the ceiling.
    for i in range(12):
        for j in range(8):
            x = -LENGTH_M / 2 + (i + 0.5) * LENGTH_M / 12
            z = -WIDTH_M / 2 + (j + 0.5) * WIDTH_M / 8
            name = f"panel_{i}_{j}"
            shapes.append(rect(name, [0.6, 0.6], "panel", face_down(x, HEIGHT_M - 0.01, z)))
            lights.append({"type": "area", "shape": name, "luminance_cd_m2": 4000,
                           "spectrum": {"blackbody_k": 4000}})
    # 24 desks (6 x 4) with a lamp over each.
    for i in range(6):
        for j in range(4):
            x = -LENGTH_M / 2 + (i + 0.5) * LENGTH_M / 6
            z = -WIDTH_M / 2 + (j + 0.5) * WIDTH_M / 4
            shapes.append(rect(f"desk_{i}_{j}", [1.6, 0.8], "desk", face_up(x, 0.75, z)))
            lights.append({"type": "point", "position_m": [x + 0.5, 1.2, z],
                           "power_lm": 450, "spectrum": {"blackbody_k": 2700}})
    scene = {
        "camera": {"type": "pinhole", "fov_deg": 60,
                   "transform": {"look_at": {"eye": [-18.5, 1.7, -4.0],
                                             "target": [0.0, 0.8, 2.0]}}},
        "film": {"resolution": [320, 180], "spp": 16, "filter": "gaussian"},
        "integrator": {"type": "path", "max_depth": 4},
        "materials": {
            "floor": {"type": "lambert", "reflectance": 0.3},
            "ceiling": {"type": "lambert", "reflectance": 0.8},
            "wall": {"type": "lambert", "reflectance": 0.6},
            "desk": {"type": "lambert", "reflectance": {"rgb": [0.55, 0.42, 0.3]}},
            "panel": {"type": "lambert", "reflectance": 0.9},
        },
        "shapes": shapes,
        "lights": lights,
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(scene, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}: {len(lights)} lights, {len(shapes)} shapes")


if __name__ == "__main__":
    main()

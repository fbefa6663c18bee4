#!/usr/bin/env python3
"""Translates Mitsuba 3's built-in Cornell box (`mitsuba.cornell_box()`) into Prism's scene
format: writes scenes/cornell-box.json and the light's spectral radiance as Mitsuba evaluates
it, scenes/cornell-box/light-radiance.csv (1 nm, 360-830 nm).

Run: tools/mitsuba/.venv/bin/python tools/mitsuba/export_cornell_scene.py
The mapping of every parameter is explained in docs/mitsuba.md.
"""

import json
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from common import ROOT, import_mitsuba  # noqa: E402
from export_cornell_spectra import emitter_radiance  # noqa: E402

SCENE = ROOT / "scenes" / "cornell-box.json"
CSV_REL = "cornell-box/light-radiance.csv"
CSV = ROOT / "scenes" / CSV_REL

# Mitsuba's `rectangle` is [-1, 1]^2 in local z = 0 (normal +z) and its `cube` [-1, 1]^3:
# Prism's `rectangle` / `cuboid` centred with these sizes are the same local shapes.
SHAPE_TYPES = {"rectangle": ("rectangle", [2, 2]), "cube": ("cuboid", [2, 2, 2])}


def f32(x):
    """The shortest decimal that reads back as the same float32 (Mitsuba's scalar type)."""
    return float(str(np.float32(x)))


def matrix_rows(transform):
    m = np.array(transform.matrix, dtype=np.float32)
    return [[f32(m[r, c]) for c in range(4)] for r in range(4)]


def compact_json(value, indent=0):
    """JSON with short values on one line and every matrix row on one line."""
    pad = "  " * indent
    one_line = json.dumps(value, separators=(", ", ": "))
    if len(pad) + len(one_line) <= 96:
        return pad + one_line
    if isinstance(value, dict):
        items = [
            f'{pad}  {json.dumps(k)}: {compact_json(v, indent + 1).lstrip()}'
            for k, v in value.items()
        ]
        return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
        if all(all(isinstance(x, (int, float)) for x in row) for row in value):
            rows = [f"{pad}  {json.dumps(row)}" for row in value]
            return pad + "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    if isinstance(value, list) and all(isinstance(v, (int, float, str)) for v in value):
        return pad + json.dumps(value)
    if isinstance(value, list):
        items = [compact_json(v, indent + 1) for v in value]
        return pad + "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return pad + json.dumps(value)


def main():
    mi = import_mitsuba()
    import drjit as dr

    mi.set_variant("scalar_spectral")
    d = mi.cornell_box()

    sensor = d["sensor"]
    film = sensor["film"]
    assert sensor["type"] == "perspective" and film["width"] == film["height"] == 256
    # fov_axis 'smaller' on a square film is x (Mitsuba: aspect > 1 ? y : x).
    assert sensor["fov_axis"] == "smaller"
    assert film["rfilter"] == {"type": "gaussian"}  # stddev 0.5, radius 4 stddev = 2 px
    rfilter = mi.load_dict(film["rfilter"])
    assert abs(rfilter.radius() - 2.0) < 1e-6

    integ = d["integrator"]
    assert integ["type"] == "path"

    scene = {
        "camera": {
            "type": "pinhole",
            "fov_deg": sensor["fov"],
            "fov_axis": "horizontal",
            # T().look_at(origin=[0, 0, 3.9], target=[0, 0, 0], up=[0, 1, 0])
            "transform": {"look_at": {"eye": [0, 0, 3.9], "target": [0, 0, 0], "up": [0, 1, 0]}},
        },
        "film": {
            "resolution": [film["width"], film["height"]],
            "filter": {"type": "gaussian", "radius_px": 2.0, "sigma_px": 0.5},
            "spp": sensor["sampler"]["sample_count"],
            "seed": 0,
        },
        "integrator": {
            "type": "path",
            # Mitsuba's max_depth counts path segments (1 = emitters seen directly, 2 = direct
            # lighting); Prism's counts bounces (1 = direct lighting): Prism = Mitsuba - 1.
            "max_depth": integ["max_depth"] - 1,
            "sampler": sensor["sampler"]["type"],
            "mis": "power",
            "rr_depth": 5,
        },
        "materials": {},
        "shapes": [],
        "lights": [],
    }
    for name in ["white", "green", "red"]:
        bsdf = d[name]
        assert bsdf["type"] == "diffuse" and bsdf["reflectance"]["type"] == "rgb"
        scene["materials"][name] = {
            "type": "lambert",
            "reflectance": {"rgb": [float(x) for x in bsdf["reflectance"]["value"]]},
        }
    for key, value in d.items():
        if not (isinstance(value, dict) and value.get("type") in SHAPE_TYPES):
            continue
        ptype, size = SHAPE_TYPES[value["type"]]
        shape = {
            "type": ptype,
            "name": key,
            "size_m": size,
            "transform": {"matrix": matrix_rows(value["to_world"])},
            "material": value["bsdf"]["id"],
        }
        scene["shapes"].append(shape)
        if "emitter" in value:
            assert value["emitter"]["type"] == "area"
            scene["lights"].append(
                {"type": "area", "shape": key, "two_sided": False, "spectrum": CSV_REL, "scale": 1}
            )

    # The light's radiance, exactly as Mitsuba's AreaLight evaluates it, at every nm.
    wavelengths = [float(w) for w in range(360, 831)]
    radiance, _ = emitter_radiance(mi, dr, d, wavelengths)
    rgb = [float(x) for x in d["light"]["emitter"]["radiance"]["value"]]
    CSV.parent.mkdir(parents=True, exist_ok=True)
    with open(CSV, "w") as f:
        f.write(
            "# light-radiance: spectral radiance (W m^-2 sr^-1 nm^-1) of the Cornell box light as\n"
            f"# Mitsuba {mi.__version__} (variant scalar_spectral) evaluates mi.cornell_box()'s area\n"
            f"# emitter radiance {{'type': 'rgb', 'value': {rgb}}} (plugin d65: 2 max(rgb) *\n"
            "# srgb_model_eval(srgb_model_fetch(rgb / (2 max(rgb))), lambda) * mi.cie_d65(lambda)).\n"
            "# exported by tools/mitsuba/export_cornell_scene.py\n"
            "# call: mi.load_dict({'type': 'rectangle', 'emitter': mi.cornell_box()['light']['emitter']})"
            ".emitter().eval(si), si.wi = (0, 0, 1)\n"
            "wavelength_nm,value\n"
        )
        for w, v in zip(wavelengths, radiance):
            f.write(f"{w:.0f},{str(np.float32(v))}\n")
    SCENE.write_text(compact_json(scene) + "\n")
    print(f"wrote {SCENE.relative_to(ROOT)} and {CSV.relative_to(ROOT)}")


if __name__ == "__main__":
    main()

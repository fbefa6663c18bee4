#!/usr/bin/env python3
"""Translates a Prism scene (JSON) into a Mitsuba 3 scene dict, for the speed and accuracy
comparisons (tools/bench-scenes/). Everything the translation cannot map exactly is either
refused (`Untranslatable`, naming the JSON path) or, where the difference is known and
small, listed in `notes` (the benchmark prints them).

    from prism_scene import translate
    scene_dict, notes = translate(mi, "tools/bench-scenes/glossy.json")

    tools/mitsuba/.venv/bin/python tools/mitsuba/prism_scene.py SCENE.json   # prints notes

Conventions (docs/mitsuba.md): Mitsuba counts path segments (max_depth = Prism's + 1);
Mitsuba cameras look along local +Z with +X to the left, Prism's along −Z with +X to the
right (to_world = Prism's · diag(−1, 1, −1)); spectra go over as tabulated values (5 nm,
360–830 nm) computed here with Prism's own data files (illuminants, metals, CIE 1931 ȳ), so
photometric strengths (cd, lm, cd/m², lx) become the same absolute radiometric spectra
Prism derives; RGB reflectances stay RGB (both use the Jakob–Hanika sigmoid, docs/mitsuba.md).
"""

import json
import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
SPECTRA = ROOT / "spectra"
K_M_LM_PER_W = 683.002  # crates/spectrum/src/constants.rs
GRID_NM = np.arange(360.0, 830.0 + 1e-9, 5.0)


class Untranslatable(ValueError):
    """The scene uses something Mitsuba cannot render the same way."""


# ----------------------------------------------------------------------------- spectra


def read_csv_columns(path):
    """(wavelengths, {column: values}) of a Prism spectral CSV (`#` comments, a header)."""
    rows, header = [], None
    for line in pathlib.Path(path).read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        cells = [c.strip() for c in line.split(",")]
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            if header is not None or rows:
                raise Untranslatable(f"{path}: unexpected line {line!r}")
            header = cells
    data = np.array(rows)
    names = header[1:] if header else [f"value{i}" for i in range(1, data.shape[1])]
    return data[:, 0], {n: data[:, i + 1] for i, n in enumerate(names)}


def ybar():
    wl, cols = read_csv_columns(SPECTRA / "cie1931-2deg.csv")
    return wl, cols["y_bar"]


def planck(wl_nm, temperature_k):
    h, c, k = 6.62607015e-34, 2.99792458e8, 1.380649e-23
    lam = wl_nm * 1e-9
    return 2 * h * c * c / lam**5 / np.expm1(h * c / (lam * k * temperature_k))


class Spectrum:
    """A spectrum as a function of wavelength (nm), or an RGB triple left to Mitsuba."""

    def __init__(self, fn=None, rgb=None, constant=None):
        self.fn, self.rgb, self.constant = fn, rgb, constant

    def values(self, wl):
        if self.constant is not None:
            return np.full_like(wl, self.constant, dtype=float)
        if self.fn is None:
            raise Untranslatable("an RGB spectrum cannot be tabulated here")
        return self.fn(wl)

    def luminous(self):
        """K_m Σ S ȳ Δλ over Prism's 1 nm CIE table (the photometric normalisation)."""
        wl, y = ybar()
        return K_M_LM_PER_W * float(np.sum(self.values(wl) * y)) * float(wl[1] - wl[0])

    def scaled(self, k):
        if self.rgb is not None:
            raise Untranslatable("a photometric strength on an RGB light spectrum")
        if self.constant is not None:
            return Spectrum(constant=self.constant * k)
        return Spectrum(fn=lambda wl, f=self.fn: k * f(wl))

    def mitsuba(self):
        if self.rgb is not None:
            return {"type": "rgb", "value": list(self.rgb)}
        if self.constant is not None:
            return {"type": "uniform", "value": float(self.constant)}
        vals = self.values(GRID_NM)
        return {"type": "spectrum", "value": [(float(w), float(v)) for w, v in zip(GRID_NM, vals)]}


def tabulated(wl, vals):
    return Spectrum(fn=lambda x: np.interp(x, wl, vals, left=0.0, right=0.0))


class Translator:
    def __init__(self, mi, scene_path):
        self.mi = mi
        self.path = pathlib.Path(scene_path).resolve()
        self.dir = self.path.parent
        self.scene = json.loads(self.path.read_text())
        self.notes = []
        self.flip_v = True

    # ------------------------------------------------------------------ helpers

    def fail(self, where, what):
        raise Untranslatable(f"{self.path.name}: {where}: {what}")

    def file(self, rel):
        return self.dir / rel

    def spectrum(self, ref, where, default=None):
        if ref is None:
            ref = default
        if isinstance(ref, (int, float)):
            return Spectrum(constant=float(ref))
        if isinstance(ref, dict) and "rgb" in ref:
            return Spectrum(rgb=ref["rgb"])
        if isinstance(ref, dict) and "blackbody_k" in ref:
            t = float(ref["blackbody_k"])
            # Prism: B(λ, T) / B(λ_max, T), λ_max = b / T (Wien; Spectrum::blackbody_normalized).
            peak = planck(np.array([2.897771955e6 / t]), t)[0]
            return Spectrum(fn=lambda wl: planck(wl, t) / peak)
        if isinstance(ref, dict) and "file" in ref:
            wl, cols = read_csv_columns(self.file(ref["file"]))
            col = ref.get("column")
            return tabulated(wl, cols[col] if col else next(iter(cols.values())))
        if isinstance(ref, str):
            named = self.scene.get("spectra", {})
            if ref in named:
                return self.spectrum(named[ref], f"spectra.{ref}")
            if "." in ref or "/" in ref:
                wl, cols = read_csv_columns(self.file(ref))
                return tabulated(wl, next(iter(cols.values())))
            csv = SPECTRA / f"{ref}.csv"
            if csv.exists():
                wl, cols = read_csv_columns(csv)
                return tabulated(wl, next(iter(cols.values())))
        self.fail(where, f"spectrum {ref!r} is not translatable")

    # ------------------------------------------------------------------ transforms

    def matrix(self, steps, where):
        m = np.eye(4)
        if steps is None:
            return m
        if isinstance(steps, dict):
            steps = [steps]
        for i, step in enumerate(steps):
            (kind, arg), = step.items()
            if kind == "translate":
                s = np.eye(4)
                s[:3, 3] = arg
            elif kind == "scale":
                f = [arg] * 3 if isinstance(arg, (int, float)) else arg
                s = np.diag([f[0], f[1], f[2], 1.0])
            elif kind == "rotate":
                axis = np.array(arg["axis"], float)
                axis /= np.linalg.norm(axis)
                a = math.radians(arg["angle_deg"])
                k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
                s = np.eye(4)
                s[:3, :3] = np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * (k @ k)
            elif kind == "matrix":
                s = np.array(arg, float)
            elif kind == "look_at":
                eye = np.array(arg["eye"], float)
                fwd = np.array(arg["target"], float) - eye
                fwd /= np.linalg.norm(fwd)
                up = np.array(arg.get("up", [0, 1, 0]), float)
                right = np.cross(fwd, up)
                right /= np.linalg.norm(right)
                true_up = np.cross(right, fwd)
                s = np.eye(4)
                s[:3, 0], s[:3, 1], s[:3, 2], s[:3, 3] = right, true_up, -fwd, eye
            else:
                self.fail(f"{where}[{i}]", f"transform step {kind!r}")
            m = s @ m
        return m

    def transform(self, m):
        return self.mi.ScalarTransform4f(m.tolist())

    # ------------------------------------------------------------------ parts

    def camera(self, film_dict):
        cam = self.scene.get("camera", {"type": "pinhole"})
        if isinstance(cam, str):
            cam = {"type": cam}
        kind = cam.get("type", "pinhole")
        m = self.matrix(cam.get("transform"), "camera.transform") @ np.diag([-1.0, 1, -1, 1])
        out = {"to_world": self.transform(m), "film": film_dict, "near_clip": 1e-3}
        if kind == "pinhole":
            axis = {"horizontal": "x", "vertical": "y", "diagonal": "diagonal"}[cam.get("fov_axis", "horizontal")]
            out.update(type="perspective", fov=float(cam.get("fov_deg", 60)), fov_axis=axis)
        elif kind == "thin_lens":
            sensor_mm = float(cam.get("sensor_width_mm", 36))
            if "focal_length_mm" in cam:
                f_mm = float(cam["focal_length_mm"])
            else:
                f_mm = sensor_mm / (2 * math.tan(math.radians(float(cam.get("fov_deg", 60))) / 2))
            if "aperture_radius_m" in cam:
                radius = float(cam["aperture_radius_m"])
            else:
                radius = f_mm * 1e-3 / (2 * float(cam["f_number"]))
            # Prism's sensor sits at the image distance v = f·d_f/(d_f − f) of the focus plane
            # (crates/render/src/camera/thin_lens.rs), so its field of view is 2·atan(s / 2v).
            focus_m = float(cam["focus_distance_m"])
            v_mm = f_mm * focus_m * 1e3 / (focus_m * 1e3 - f_mm)
            fov = math.degrees(2 * math.atan(sensor_mm / (2 * v_mm)))
            out.update(type="thinlens", fov=fov, fov_axis="x", aperture_radius=radius,
                       focus_distance=focus_m)
        else:
            self.fail("camera.type", f"{kind!r} (translated: pinhole, thin_lens)")
        return out

    def film(self):
        film = self.scene.get("film", {})
        w, h = film.get("resolution", [640, 480])
        if film.get("reconstruction", "importance") != "splat":
            self.notes.append("film.reconstruction: Mitsuba splats every sample into the pixels "
                              "under its filter (Prism's 'splat'); Prism's 'importance' has the "
                              "same expected image and more per-pixel noise")
        flt = film.get("filter", "gaussian")
        if isinstance(flt, str):
            flt = {"type": flt}
        if flt["type"] == "gaussian":
            sigma = float(flt.get("sigma_px", 0.5))
            radius = float(flt.get("radius_px", 1.5))
            if abs(radius - 4 * sigma) > 1e-9:
                self.notes.append(f"film.filter: Mitsuba's gaussian is cut at 4σ = {4 * sigma} px, "
                                  f"Prism's at {radius} px")
            rfilter = {"type": "gaussian", "stddev": sigma}
        elif flt["type"] == "box":
            if float(flt.get("radius_px", 0.5)) != 0.5:
                self.fail("film.filter.radius_px", "Mitsuba's box filter is one pixel wide (0.5)")
            rfilter = {"type": "box"}
        else:
            self.fail("film.filter.type", f"{flt['type']!r} (translated: gaussian, box)")
        return {"type": "hdrfilm", "width": int(w), "height": int(h), "pixel_format": "rgb",
                "rfilter": rfilter}

    def integrator(self):
        integ = self.scene.get("integrator", {"type": "path"})
        if integ.get("type", "path") != "path":
            self.fail("integrator.type", f"{integ.get('type')!r} (translated: path)")
        if integ.get("mis", "power") != "power":
            self.fail("integrator.mis", "Mitsuba's path tracer uses the power heuristic")
        return {"type": "path", "max_depth": int(integ.get("max_depth", 5)) + 1,
                "rr_depth": int(integ.get("rr_depth", 3))}

    def texture(self, ref, where, use):
        tex = ref["texture"]
        if isinstance(tex, str):
            name = tex
            tex = self.scene.get("textures", {}).get(name)
            if tex is None:
                self.fail(where, f"no texture {name!r}")
        if tex.get("type") != "image":
            self.fail(where, f"texture type {tex.get('type')!r} (translated: image)")
        filt = tex.get("filter", "trilinear")
        if filt == "trilinear":
            self.notes.append(f"{where}: trilinear (MIP-mapped) in Prism, bilinear in Mitsuba")
            filt = "bilinear"
        for key, default in (("scale", 1), ("uv_rotate_deg", 0), ("uv_offset", [0, 0])):
            if tex.get(key, default) != default:
                self.fail(f"{where}.{key}", "not translated")
        encoding = tex.get("encoding", "auto")
        raw = encoding == "linear" or (encoding == "auto" and use == "normal")
        if use == "scalar" and tex.get("channel", "average") != "average":
            self.fail(f"{where}.channel", "only 'average' (of a one-channel image) is translated")
        s = tex.get("uv_scale", 1)
        su, sv = (s, s) if isinstance(s, (int, float)) else s
        to_uv = self.mi.ScalarTransform4f().scale([su, sv, 1])
        if self.flip_v:
            # Mitsuba 3's bitmap puts v = 0 on the image's top row, Prism (as pbrt) on the
            # bottom row; Mitsuba's OBJ loader flips v itself, its parametric shapes do not.
            to_uv = self.mi.ScalarTransform4f().translate([0, 1, 0]).scale([1, -1, 1]) @ to_uv
        return {"type": "bitmap", "filename": str(self.file(tex["file"])), "raw": raw,
                "filter_type": filt, "wrap_mode": tex.get("wrap", "repeat"), "to_uv": to_uv}

    def reflectance(self, ref, where, default=0.5):
        if isinstance(ref, dict) and "texture" in ref:
            return self.texture(ref, where, "colour")
        return self.spectrum(ref, where, default).mitsuba()

    def roughness(self, m, where):
        r = m.get("roughness", 0)
        dist = m.get("distribution", "ggx")
        if isinstance(r, dict) and "texture" in r:
            return {"distribution": dist, "alpha": self.texture(r, f"{where}.roughness", "scalar")}
        if isinstance(r, list):
            if r[0] == 0 and r[1] == 0:
                return None
            return {"distribution": dist, "alpha_u": float(r[0]), "alpha_v": float(r[1])}
        if r == 0:
            return None
        return {"distribution": dist, "alpha": float(r)}

    def single_ior(self, m, where):
        ior = m.get("ior", 1.5)
        if not isinstance(ior, (int, float)):
            self.fail(f"{where}.ior", "Mitsuba takes one index of refraction (no dispersion)")
        return float(ior)

    def smooth_or_rough(self, kind, params, m, where):
        """Mitsuba's `kind` (smooth) or `rough<kind>` with Prism's roughness."""
        rough = self.roughness(m, where)
        if rough is None:
            return {"type": kind, **params}
        return {"type": f"rough{kind}", **params, **rough}

    def material(self, name, where, depth=0):
        mats = self.scene.get("materials", {})
        if name is None:
            return {"type": "diffuse", "reflectance": {"type": "uniform", "value": 0.5}}
        m = mats.get(name)
        if m is None:
            self.fail(where, f"no material {name!r}")
        where = f"materials.{name}"
        kind = m.get("type")
        if kind == "lambert":
            return {"type": "diffuse", "reflectance": self.reflectance(m.get("reflectance"), f"{where}.reflectance")}
        if kind == "conductor":
            if "metal" in m or "eta" not in m:
                wl, cols = read_csv_columns(SPECTRA / "metals" / f"{m.get('metal', 'Al')}.csv")
                eta, k = tabulated(wl, cols["eta"]), tabulated(wl, cols["k"])
            else:
                eta, k = self.spectrum(m["eta"], f"{where}.eta"), self.spectrum(m["k"], f"{where}.k")
            return self.smooth_or_rough("conductor", {"eta": eta.mitsuba(), "k": k.mitsuba()}, m, where)
        if kind == "dielectric":
            ior = self.single_ior(m, where)
            return self.smooth_or_rough("dielectric", {"int_ior": ior, "ext_ior": 1.0}, m, where)
        if kind == "coated":
            ior = self.single_ior(m, where)
            self.notes.append(f"{where}: Prism integrates the coat's internal Fresnel reflectance "
                              "exactly, Mitsuba's plastic uses a polynomial fit")
            return {"type": "plastic", "diffuse_reflectance": self.reflectance(m.get("diffuse"), f"{where}.diffuse"),
                    "int_ior": ior, "ext_ior": 1.0, "nonlinear": bool(m.get("nonlinear", True))}
        if kind == "two_sided":
            return {"type": "twosided", "bsdf": self.material(m["material"], f"{where}.material", depth + 1)}
        if kind == "normal_map":
            self.notes.append(f"{where}: normal maps — both perturb the shading frame from the "
                              "tangent-space map; frame conventions at the mesh level may differ")
            return {"type": "normalmap", "normalmap": self.texture({"texture": m["texture"]}, f"{where}.texture", "normal"),
                    "bsdf": self.material(m["material"], f"{where}.material", depth + 1)}
        if kind == "mask":
            op = m.get("opacity", 1)
            opacity = (self.texture(op, f"{where}.opacity", "scalar") if isinstance(op, dict)
                       else float(op))
            return {"type": "mask", "opacity": opacity,
                    "bsdf": self.material(m["material"], f"{where}.material", depth + 1)}
        self.fail(f"{where}.type", f"{kind!r} (translated: lambert, conductor, dielectric, coated, "
                                   "two_sided, normal_map, mask)")

    def shape(self, s, where):
        kind = s.get("type")
        m = self.matrix(s.get("transform"), f"{where}.transform")
        if kind == "rectangle":
            w, h = s.get("size_m", [1, 1])
            local, out, area = np.diag([w / 2, h / 2, 1, 1]), {"type": "rectangle"}, w * h
        elif kind == "cuboid":
            x, y, z = s.get("size_m", [1, 1, 1])
            local, out, area = np.diag([x / 2, y / 2, z / 2, 1]), {"type": "cube"}, None
        elif kind == "sphere":
            r = float(s.get("radius_m", 1))
            local, out, area = np.diag([r, r, r, 1]), {"type": "sphere"}, 4 * math.pi * r * r
        elif kind == "disk":
            r = float(s.get("radius_m", 1))
            local, out, area = np.diag([r, r, 1, 1]), {"type": "disk"}, math.pi * r * r
        elif kind == "mesh":
            f = s.get("file") or self.scene.get("meshes", {}).get(s.get("mesh"))
            if isinstance(f, dict):
                f = f["file"]
            if f is None:
                self.fail(where, "mesh without a file")
            ext = pathlib.Path(f).suffix.lower()[1:]
            local, out, area = np.eye(4), {"type": ext, "filename": str(self.file(f))}, None
        else:
            self.fail(f"{where}.type", f"{kind!r} (translated: rectangle, cuboid, sphere, disk, mesh)")
        if s.get("interior_medium") or s.get("exterior_medium"):
            self.fail(where, "media are not translated")
        full = m @ local
        if area is not None:
            # Area in the world: the transform's linear part may scale the shape.
            lin = m[:3, :3]
            if kind in ("rectangle", "disk"):
                area *= np.linalg.norm(np.cross(lin[:, 0], lin[:, 1]))
            else:
                sv = np.linalg.svd(lin, compute_uv=False)
                if sv.max() - sv.min() > 1e-9 * sv.max():
                    area = None
                else:
                    area *= sv[0] ** 2
        out["to_world"] = self.transform(full)
        self.flip_v = out["type"] != "obj"
        out["bsdf"] = self.material(s.get("material"), f"{where}.material")
        return out, area

    def light_spectrum(self, light, where, luminous_scale=None):
        """The light's spectrum times its strength, as Prism's scene builder applies them:
        `scale` multiplies; a photometric strength P gives S · P / (K_m Σ S ȳ Δλ) · factor."""
        spec = self.spectrum(light.get("spectrum"), f"{where}.spectrum", "D65")
        if luminous_scale is not None:
            key, value, factor = luminous_scale
            return spec.scaled(value * factor / spec.luminous())
        return spec.scaled(float(light.get("scale", 1)))

    def translate(self):
        film = self.film()
        out = {"type": "scene", "integrator": self.integrator(), "sensor": self.camera(film)}
        areas = {}
        shapes = self.scene.get("shapes", [])
        emitting = {l.get("shape"): (i, l) for i, l in enumerate(self.scene.get("lights", []))
                    if l.get("type") == "area"}
        for i, s in enumerate(shapes):
            d, area = self.shape(s, f"shapes[{i}]")
            name = s.get("name")
            if name in emitting:
                li, light = emitting[name]
                lw = f"lights[{li}]"
                if light.get("two_sided", False):
                    self.fail(f"{lw}.two_sided", "Mitsuba's area emitters are one-sided")
                strength = None
                if "luminance_cd_m2" in light:
                    strength = ("luminance_cd_m2", float(light["luminance_cd_m2"]), 1.0)
                elif "power_lm" in light:
                    if area is None:
                        self.fail(lw, "power_lm on a shape whose area is not computed here")
                    strength = ("power_lm", float(light["power_lm"]), 1.0 / (math.pi * area))
                d["emitter"] = {"type": "area",
                                "radiance": self.light_spectrum(light, lw, strength).mitsuba()}
            out[f"shape_{i}"] = d
        for i, light in enumerate(self.scene.get("lights", [])):
            where = f"lights[{i}]"
            kind = light.get("type")
            if kind == "area":
                continue
            if kind == "point":
                strength = None
                if "intensity_cd" in light:
                    strength = ("intensity_cd", float(light["intensity_cd"]), 1.0)
                elif "power_lm" in light:
                    strength = ("power_lm", float(light["power_lm"]), 1.0 / (4 * math.pi))
                out[f"light_{i}"] = {"type": "point", "position": list(map(float, light["position_m"])),
                                     "intensity": self.light_spectrum(light, where, strength).mitsuba()}
            elif kind == "directional":
                if float(light.get("angular_diameter_deg", 0)) != 0:
                    self.fail(f"{where}.angular_diameter_deg", "Mitsuba's directional light is a delta (0)")
                strength = None
                if "illuminance_lx" in light:
                    strength = ("illuminance_lx", float(light["illuminance_lx"]), 1.0)
                d = np.array(light.get("direction", [0, -1, 0]), float)
                out[f"light_{i}"] = {"type": "directional", "direction": (d / np.linalg.norm(d)).tolist(),
                                     "irradiance": self.light_spectrum(light, where, strength).mitsuba()}
            elif kind == "environment":
                m = self.matrix(light.get("transform"), f"{where}.transform")
                if light.get("filter", "nearest") == "bilinear":
                    self.notes.append(f"{where}: both interpolate bilinearly; Prism puts the rows at "
                                      "texel centres, Mitsuba the first and last on the poles "
                                      "(half a texel apart)")
                else:
                    self.notes.append(f"{where}: Prism looks environment texels up nearest "
                                      "(`filter` nearest), Mitsuba bilinearly with rows on the "
                                      "poles (half a texel apart)")
                out[f"light_{i}"] = {"type": "envmap", "filename": str(self.file(light["file"])),
                                     "scale": float(light.get("scale", 1)), "to_world": self.transform(m)}
            elif kind == "sky":
                strength = None
                if "luminance_cd_m2" in light:
                    strength = ("luminance_cd_m2", float(light["luminance_cd_m2"]), 1.0)
                out[f"light_{i}"] = {"type": "constant",
                                     "radiance": self.light_spectrum(light, where, strength).mitsuba()}
            else:
                self.fail(f"{where}.type", f"{kind!r} (translated: area, point, directional, "
                                           "environment, sky)")
        for name, (li, _) in emitting.items():
            if name not in {s.get("name") for s in shapes}:
                self.fail(f"lights[{li}].shape", f"no shape {name!r}")
        return out


def translate(mi, scene_path):
    """(Mitsuba scene dict, notes) for a Prism scene file; mi's variant must be spectral."""
    t = Translator(mi, scene_path)
    return t.translate(), t.notes


def main():
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from common import import_mitsuba

    mi = import_mitsuba()
    mi.set_variant("scalar_spectral")
    for path in sys.argv[1:]:
        try:
            d, notes = translate(mi, path)
        except Untranslatable as e:
            print(f"{path}: not translatable: {e}")
            continue
        mi.load_dict(d)
        print(f"{path}: translated, {len(d) - 3} shapes and lights")
        for n in notes:
            print(f"  note: {n}")


if __name__ == "__main__":
    main()

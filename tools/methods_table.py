#!/usr/bin/env python3
"""Writes docs/methods.md: for the Cornell box (against Mitsuba 3's reference) and every
stress scene in scenes/stress/, runs `prism converge` with each method, commits the chart
(PNG) under docs/methods/ and its JSON under tools/bench-results/methods/, and tabulates per method the time to reach relMSE 1e-2
(or the error when the budget ran out), the fitted slopes and a one-line verdict.

Refresh it whenever an integrator changes:

    cargo build --release
    python3 tools/methods_table.py --budget-s 30            # the issue's 30 s per method
    python3 tools/methods_table.py --budget-s 3 --reference-spp 2048   # a quick pass

Standard library only. The verdict rules are stated in the generated page.
"""
import argparse
import datetime
import hashlib
import json
import os
import platform
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET_RELMSE = 1e-2

# (scene, what it is built to break)
STRESS = [
    ("small-source", "a 5 mm sphere light (1 Mlm) over a floor: the small-source problem, "
                     "BSDF sampling almost never hits the light"),
    ("caustic-glass-sphere", "a glass sphere under a small disk light: the caustic is only "
                             "reached through light → specular → diffuse paths"),
    ("glossy-interreflection", "two facing glossy metal plates (Ag α 0.04, Au α 0.12): "
                               "glossy-to-glossy transport"),
    ("door-ajar", "the light is in the next room behind a door ajar: almost every path "
                  "must find a narrow gap (difficult visibility)"),
    ("grazing-rough-conductor", "rough Al and anisotropic Cu seen at grazing angles "
                                "(microfacet shadowing, long tails)"),
    ("hdr-sun-env", "an equirectangular sky whose 0.6° sun carries most of the energy"),
    ("extreme-dynamic-range", "a 5·10¹⁰ cd/m² point-like sun and a 5·10⁴ cd/m² panel "
                              "(10⁶ : 1) in one view"),
    ("spiky-spectrum", "F11 and LED-RGB1 lights on saturated red, green, blue, cyan "
                       "spheres (spiky spectra × narrow reflectances)"),
    ("dispersion-prism", "a small light through an SF11 glass prism onto a screen "
                         "(dispersion: one wavelength per path, a caustic)"),
    # Participating media (issue 20): only `path` samples media so far, so these scenes get
    # the `path` methods only (MEDIA_SCENES); the photon integrators will add rows.
    ("spot-fog-glass", "caustic-glass-sphere in fog (σs 0.15 m⁻¹), the lamp in a black snoot: "
                       "the beam's caustic through the sphere lights the fog only via "
                       "light → specular → medium paths"),
    ("bulb-in-glass-fog", "a point light inside a glass globe in fog: path cannot sample it at "
                          "all (the glow is missing; `--explain` warns), a dim panel lights "
                          "the rest"),
    ("haze-valley", "a Preetham sky over 300 m of thin haze (σt 0.004–0.01 m⁻¹), seen through "
                    "a 12° view: most of the lit volume is outside the view"),
    ("milk", "a block of milk (σs 1000 m⁻¹, albedo 0.999, g 0.8) under a softbox: hundreds of "
             "scattering events per path, cut by max_depth 64"),
    ("chromatic-smoke", "a 24×32×24 .vol smoke plume with σt 2 / 6 / 9 m⁻¹ in three bands "
                        "(spectral MIS over the four wavelengths)"),
]

# Scenes with participating media: `light` and `bdpt` refuse them, so only methods whose
# integrator samples media (MEDIA_INTEGRATORS) run there.
MEDIA_SCENES = {"spot-fog-glass", "bulb-in-glass-fog", "haze-valley", "milk", "chromatic-smoke"}
MEDIA_INTEGRATORS = {"path", "photon", "photon_progressive"}

# The scenes the photon integrators were built for (caustics, dispersion onto a screen, a
# volumetric caustic): they also run PHOTON_METHODS.
PHOTON_SCENES = {"caustic-glass-sphere", "dispersion-prism", "spot-fog-glass",
                 "bulb-in-glass-fog"}
PHOTON_METHODS = ["photon_progressive", "photon"]

# Stress scenes where `path` fails: a reference from `path` itself would be mostly its own
# noise, which bounds every method's measured error. Their reference is rendered instead by
# a method that samples the scene's hard light paths (`prism render`, SPP samples, seed
# REFERENCE_SEED; cached next to the scene under a git-ignored name) and handed to
# `prism converge --reference`: BDPT (unbiased, its light-tracing strategies reach
# L S⁺ D E) where there are no media, `photon_progressive` (consistent; the only method
# here that renders the volumetric caustic) in spot-fog-glass and bulb-in-glass-fog. SPP is chosen for about
# 2–3 min of CPU each on a 2-core machine.
BETTER_REFERENCES = {
    "caustic-glass-sphere": ("bdpt", 16384),
    "dispersion-prism": ("bdpt", 16384),
    "spot-fog-glass": ("photon_progressive", 16384),
    "bulb-in-glass-fog": ("photon_progressive", 16384),
}
REFERENCE_SEED = 20201

# Measurement notes on rows of this page (which binary, which runs were repeated when):
# kept here so that rebuilding the page (`--no-run`) keeps them.
MEASUREMENT_NOTES = """Every row of this page comes from the one run above (release binary).
"""

# Consistent but biased methods: their error falls slower than t⁻¹ by design (the kernel's
# bias shrinks with the radius; Knaus & Zwicker 2011 give relMSE ∝ t^(−α) at best), so a
# slope in (−1, −0.5) is their normal rate, "slow" rather than "fails".
CONSISTENT_BIASED = {"photon_progressive"}


def integrator_of(method):
    return method.split(",")[0].split("+")[0].split(":")[0]


def better_reference(prism, name, method, spp):
    """The cached reference of stress scene `name` rendered by `method` at `spp` (renders
    it first when missing); its path relative to ROOT."""
    scene = os.path.join(ROOT, "scenes", "stress", f"{name}.json")
    with open(scene) as f:
        description = json.load(f)
    # The method's own parameters: the scene's depth and roulette, every photon default.
    old = description.get("integrator", {})
    integrator = {"type": method}
    for key in ("max_depth", "rr_depth"):
        if key in old:
            integrator[key] = old[key]
    description["integrator"] = integrator
    tag = json.dumps(description, sort_keys=True).encode()
    digest = hashlib.sha256(tag).hexdigest()[:12]
    ref = f"scenes/stress/{name}.reference-{method}-{spp}spp-{digest}.exr"
    if os.path.exists(os.path.join(ROOT, ref)):
        return ref
    # Next to the scene, so that its relative file names resolve.
    tmp_scene = os.path.join(ROOT, "scenes", "stress", f".{name}.reference-{method}.json")
    with open(tmp_scene, "w") as f:
        json.dump(description, f)
    try:
        run([prism, "render", tmp_scene, "--spp", str(spp), "--seed", str(REFERENCE_SEED),
             "-o", os.path.join(ROOT, ref)])
    finally:
        os.remove(tmp_scene)
    return ref


def run(cmd):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, cwd=ROOT)


def fit_time(fit, target):
    """Time at which the fitted power law reaches `target` (extrapolated)."""
    if not fit or fit["slope"] >= 0:
        return None
    return 10 ** ((__import__("math").log10(target) - fit["intercept_log10"]) / fit["slope"])


def tail_slope(checkpoints, key, clock):
    """relMSE slope of the last half of the checkpoints (bias shows as flattening)."""
    import math
    pts = [(c[clock], c[key]) for c in checkpoints if c[clock] and c[key] > 0]
    pts = pts[len(pts) // 2:]
    if len(pts) < 3:
        return None
    xs = [math.log10(p[0]) for p in pts]
    ys = [math.log10(p[1]) for p in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None


def verdict(m, clock_key):
    s = m["relmse_slope"]
    final = m["final"]["relmse"]
    reached = m["time_to_relmse_target_s"]
    tail = tail_slope(m["checkpoints"], "relmse", clock_key)
    if m["stats"]["non_finite_samples"] or m["stats"]["non_finite_contributions"]:
        return "fails — NaN/∞ samples"
    if s is None:
        return "fails — too few checkpoints to fit"
    num = lambda v: f"{v:.2f}".replace("-", "−")
    if final > 1.0:
        extra = fit_time(m["fits"]["relmse"], TARGET_RELMSE) if s <= -0.8 else None
        tail_text = (f"; it converges at t^{num(s)}, but the fit needs ≈ {fmt_time(extra)} "
                     f"for relMSE {TARGET_RELMSE:g}") if extra else f" (slope {num(s)})"
        return (f"fails — relMSE still {final:.3g} at the end, the error is larger than the "
                f"signal{tail_text}")
    if integrator_of(m["method"]) in CONSISTENT_BIASED and -1.0 < s < -0.5:
        if reached is not None:
            return "works"
        return (f"slow — consistent but biased: its error falls at t^{num(s)} (the kernel's "
                "bias shrinking with the radius), relMSE 1e-2 not reached within the budget")
    if s > -0.6:
        return (f"fails — relMSE falls at t^{num(s)}, far from t^−1: rare events (fireflies, "
                "or a feature too small for the samples) dominate the error")
    if tail is not None and tail > -0.4 and s < -0.7:
        return (f"biased? — converged at first, then flattens (last-half slope {num(tail)}); "
                "reference-limited or a bias")
    if reached is not None:
        return "works"
    return "slow — converges at the Monte Carlo rate but misses relMSE 1e-2 within the budget"


def fmt_time(t):
    if t is None:
        return None
    if t < 1:
        return f"{t * 1000:.0f} ms"
    if t < 120:
        return f"{t:.1f} s"
    if t < 7200:
        return f"{t / 60:.0f} min"
    if t > 3.6e9:  # a near-flat fit extrapolates to absurd times: only the order matters
        return "> 10⁶ h"
    return f"{t / 3600:.1f} h"


def table(data, clock_key):
    rows = ["| method | time to relMSE 1e-2 | relMSE at the end (spp) | RMSE slope | relMSE slope | "
            "verdict |", "|---|---|---|---|---|---|"]
    for m in data["methods"]:
        reached = m["time_to_relmse_target_s"]
        if reached is not None:
            t = fmt_time(reached)
        else:
            extra = fit_time(m["fits"]["relmse"], TARGET_RELMSE)
            shown = fmt_time(extra)
            approx = "" if shown and shown.startswith(">") else "≈ "
            t = f"not reached (fit: {approx}{shown})" if extra else "not reached"
        final = m["final"]
        slope = lambda v: "—" if v is None else f"{v:.2f}".replace("-", "−")
        rows.append(
            f"| `{m['method']}` | {t} | {final['relmse']:.3g} after "
            f"{fmt_time(final[clock_key])} ({final['spp']} spp) | {slope(m['rmse_slope'])} | "
            f"{slope(m['relmse_slope'])} | {verdict(m, clock_key)} |")
    return "\n".join(rows)


def time_to_target(m):
    """Time to relMSE 1e-2: reached, else the fit's extrapolation (None without a fit)."""
    if m["time_to_relmse_target_s"] is not None:
        return m["time_to_relmse_target_s"], True
    return fit_time(m["fits"]["relmse"], TARGET_RELMSE), False


def bdpt_summary(comparisons, clock_key):
    """Where BDPT beats the path tracer and where it does not, from the runs' JSON.

    The measure is Monte Carlo efficiency at the end of each run, 1 / (relMSE · time): at
    the t⁻¹ rate it does not depend on when the run stopped, so runs that stop at the same
    spp cap after different times still compare. Where a method's relMSE is still ≥ 1 its
    error is dominated by paths it has not found yet and the product is not meaningful.
    """
    rows = []
    for name, data in comparisons:
        by = {m["method"]: m for m in data["methods"]}
        path, bdpt = by.get("path"), by.get("bdpt")
        if not path or not bdpt:
            continue
        (tp, p_ok), (tb, b_ok) = time_to_target(path), time_to_target(bdpt)
        fp, fb = path["final"], bdpt["final"]
        ep, eb = fp["relmse"], fb["relmse"]
        cost_p, cost_b = ep * fp[clock_key], eb * fb[clock_key]
        gain = cost_p / cost_b if cost_b > 0 else None
        if ep >= 1 and eb < 1:
            verdict = "BDPT wins: path has not converged"
        elif eb >= 1 and ep < 1:
            verdict = "path wins: BDPT has not converged"
        elif ep >= 1 and eb >= 1:
            verdict = "neither has converged"
        elif gain is None:
            verdict = "no measure"
        else:
            verdict = ("BDPT wins" if gain > 1.25 else
                       "path wins" if gain < 0.8 else "about even")
        rows.append(f"| {name} | {ep:.3g} × {fmt_time(fp[clock_key])} | "
                    f"{eb:.3g} × {fmt_time(fb[clock_key])} | "
                    f"{'—' if gain is None else f'{gain:.2f}×'} | "
                    f"{fmt_time(tp) or '—'}{'' if p_ok else ' (fit)'} / "
                    f"{fmt_time(tb) or '—'}{'' if b_ok else ' (fit)'} | {verdict} |")
    if not rows:
        return ""
    return ("**BDPT against the path tracer**, per scene: the relMSE and time at the end of "
            "each run, BDPT's efficiency gain (path's relMSE × time over BDPT's; above 1 BDPT "
            f"reaches a given error sooner), the time to relMSE {TARGET_RELMSE:g} "
            "(\"fit\": extrapolated) and a verdict. BDPT pays for every connection of every "
            "sample, so it wins where paths from the camera rarely find the light by "
            "next-event estimation (caustics, glossy inter-reflection, light through a gap) "
            "and loses where next-event estimation already finds it (direct light, diffuse "
            "rooms — even a tiny source, which NEE samples directly).\n\n"
            "| scene | path: relMSE × time | bdpt: relMSE × time | BDPT efficiency gain | "
            f"time to {TARGET_RELMSE:g} (path / bdpt) | verdict |\n"
            "|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prism", default=None, help="the prism binary (default: target/release, "
                                                  "else target/debug)")
    ap.add_argument("--budget-s", type=float, default=30.0, help="time budget per method, s")
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--checkpoints", type=int, default=10)
    ap.add_argument("--max-spp", type=int, default=None,
                    help="also stop the stress scenes' methods at this spp (keep it ≤ 1/8 of "
                         "--reference-spp so the reference's noise stays negligible)")
    ap.add_argument("--clock", choices=["wall", "cpu"], default="cpu")
    ap.add_argument("--method", action="append", default=None,
                    help="methods (default: path, path:sobol, light, bdpt, path+predicted, "
                         "path+adaptive; the first renders "
                         "the stress scenes' references)")
    ap.add_argument("--scenes", nargs="*", default=None, help="subset of stress scene names")
    ap.add_argument("--skip-cornell", action="store_true")
    ap.add_argument("--no-run", action="store_true",
                    help="rebuild docs/methods.md from the JSON already in tools/bench-results/methods/ "
                         "(pass the options of the run that made them)")
    args = ap.parse_args()
    prism = args.prism
    if prism is None:
        for p in ("target/release/prism", "target/debug/prism"):
            if os.path.exists(os.path.join(ROOT, p)):
                prism = os.path.join(ROOT, p)
                break
    if prism is None:
        sys.exit("build prism first (cargo build --release)")
    methods = args.method or ["path", "path:sobol", "light", "bdpt", "path+predicted",
                              "path+adaptive"]
    for out_dir in (os.path.join(ROOT, "docs", "methods"),
                    os.path.join(ROOT, "tools", "bench-results", "methods")):
        os.makedirs(out_dir, exist_ok=True)
    clock_key = "cpu_time_s" if args.clock == "cpu" else "time_s"

    jobs = []
    if not args.skip_cornell:
        jobs.append(("cornell-box", "scenes/cornell-box.json",
                     ["--reference", "tests/fixtures/cornell_mitsuba_reference.exr"],
                     "Mitsuba 3's built-in Cornell box (256×256), against Mitsuba 3.6.4's 4096-spp "
                     "reference (tests/fixtures/cornell_mitsuba_reference.json): an independent "
                     "renderer, so bias would show", methods, "Mitsuba 3's reference"))
    for name, what in STRESS:
        if args.scenes and name not in args.scenes:
            continue
        cap = ["--max-spp", str(args.max_spp)] if args.max_spp else []
        scene_methods = list(methods)
        if name in PHOTON_SCENES:
            scene_methods += [m for m in PHOTON_METHODS if m not in scene_methods]
        if name in MEDIA_SCENES:
            scene_methods = [m for m in scene_methods if integrator_of(m) in MEDIA_INTEGRATORS]
        if name in BETTER_REFERENCES:
            method, spp = BETTER_REFERENCES[name]
            ref = (better_reference(prism, name, method, spp) if not args.no_run
                   else f"(`{method}`)")
            ref_args = ["--reference", ref]
            ref_text = (f"`{method}` at {spp} spp (`prism render`, seed {REFERENCE_SEED}; "
                        f"`path` fails here)")
        else:
            ref_args = ["--reference-spp", str(args.reference_spp)]
            ref_text = None
        jobs.append((name, f"scenes/stress/{name}.json", [*ref_args, *cap], what,
                     scene_methods, ref_text))

    sections = []
    loads = []
    comparisons = []
    for name, scene, ref_args, what, job_methods, given_ref_text in jobs:
        chart = f"docs/methods/{name}.png"
        data_path = f"tools/bench-results/methods/{name}.json"
        cmd = [prism, "converge", scene, *ref_args, "--budget-s", str(args.budget_s),
               "--checkpoints", str(args.checkpoints), "--clock", args.clock,
               "-o", chart, "--json", data_path]
        for m in job_methods:
            cmd += ["--method", m]
        if not args.no_run:
            run(cmd)
        with open(os.path.join(ROOT, data_path)) as f:
            data = json.load(f)
        loads += [data["machine_at_start"]["load_average_1m"],
                  data["machine_at_end"]["load_average_1m"]]
        ref = data["reference"]
        ref_text = (given_ref_text if ref["source"] == "given"
                    else f"Prism's own {ref['spp']}-spp Owen-scrambled Sobol render "
                         f"(seed {ref['seed']})")
        comparisons.append((name, data))
        sections.append(
            f"### {name}\n\n{what}. `{scene}`, {data['resolution'][0]}×{data['resolution'][1]} px; "
            f"reference: {ref_text}.\n\n{table(data, clock_key)}\n\n"
            f"![{name}](methods/{name}.png)\n")

    loads = [l for l in loads if l is not None]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cpus = os.cpu_count()
    clock_text = ("render CPU time (all render threads; the metric thread excluded)"
                  if args.clock == "cpu" else "wall time")
    cap_text = (f" or {args.max_spp} spp on the stress scenes, whichever comes first"
                if args.max_spp else "")
    cmd_text = (f"python3 tools/methods_table.py --budget-s {args.budget_s:g} "
                f"--reference-spp {args.reference_spp}"
                + (f" --max-spp {args.max_spp}" if args.max_spp else ""))
    head = f"""# Methods: speed against accuracy

Generated by `tools/methods_table.py` on {now} — do not edit by hand; refresh it whenever an
integrator changes (command below). Each scene is rendered progressively by
[`prism converge`](converge.md) with every method; each row gives the time to reach
relMSE {TARGET_RELMSE:g} (interpolated between checkpoints; when the budget ran out first,
the time the fitted power law predicts), the error at the end of the budget, the fitted
log–log slopes (Monte Carlo rate: RMSE −0.5, relMSE −1), and a verdict. Every checkpoint of
every run is in `tools/bench-results/methods/<scene>.json`.

**This run:** budget {args.budget_s:g} s per method ({clock_text}){cap_text}, {args.checkpoints}
checkpoints, stress-scene references at {args.reference_spp} spp, methods
{", ".join(f"`{m}`" for m in methods)}; machine: {platform.machine()}, {cpus} logical CPUs
shared with other jobs, 1-minute load average {min(loads):.1f}–{max(loads):.1f} during the
run. On a machine this busy, wall time is stretched by other processes; CPU time is not,
which is why the run uses `--clock {args.clock}`. Times are for this machine — compare rows,
not absolute numbers.

Command: `{cmd_text}`
(with `prism` built; the script prefers target/release/prism).

Methods (grammar `INTEGRATOR[+PLAN][:SAMPLER]`, [converge.md](converge.md)): `path` is the
spectral path tracer (next-event estimation + MIS) with the uniform plan and the independent
sampler; `path:sobol` the same with Owen-scrambled Sobol samples; `light` is light tracing
(one light path per camera sample, every vertex connected to the camera); `bdpt` is
bidirectional path tracing with power-heuristic MIS over all strategies; `path+predicted` is
the path tracer with the bandwidth predictor's per-pixel plan (Bagher et al. 2013,
[bandwidth.md](bandwidth.md); its time includes the predictor's, the BSDF tables read from
the cache directory after their first build) and `path+adaptive` the path tracer with
variance-driven passes after 4 spp (Cycles' adaptive sampling), the baseline the predictor
is measured against: on these scenes, which the predictor was not built for, their rows say
where per-pixel allocation pays and where it does not. All take the scene's
`max_depth` and `rr_depth`. A pinhole light tracer cannot reach pixels that see a specular
surface (glass, mirrors) first, nor point-like lights seen directly: on scenes with such
pixels `light`'s error stays at their missing value — a property of the method, not noise.
`light` and `bdpt` sample no participating media: the media scenes (spot-fog-glass,
bulb-in-glass-fog, haze-valley, milk, chromatic-smoke) have `path` rows and, where photons
were the point, photon rows. `photon_progressive` and `photon` (photon mapping, one photon
per pixel per pass, default radius; [rendering.md](rendering.md#photon-mapping)) run on the
scenes they were built for: caustic-glass-sphere, dispersion-prism, spot-fog-glass,
bulb-in-glass-fog. On those four `path` fails, so their references are not `path`'s: BDPT's
at 16384 spp (caustic-glass-sphere, dispersion-prism) and `photon_progressive`'s at 16384
passes (spot-fog-glass and bulb-in-glass-fog, whose fog BDPT does not sample; checked against a long `path` run where the
caustic cone lands, `tools/photon_reference_check.py` — but the photon rows there are
measured against their own method, so the kernel's bias they share with it does not show).
The photon speed target
(spot-fog-glass at 128², against `photon_progressive`'s own reference,
`tools/photon_speed.py`) is in [rendering.md](rendering.md#photon-mapping).
{MEASUREMENT_NOTES}

{{bdpt_summary}}

**Verdicts**, from the JSON (rules in the script): *works* — relMSE {TARGET_RELMSE:g} reached
within the budget, error falling at about the Monte Carlo rate; *slow* — converging at the
rate but {TARGET_RELMSE:g} not reached within the budget; *fails* — relMSE above 1 at the end
or falling much slower than t⁻¹ (slope > −0.6: rare, high-energy paths, i.e. fireflies,
dominate; for a consistent but biased method — `photon_progressive` — a slope in (−1, −0.5) is
its normal rate, so it is *slow*, not *fails*), or NaN/∞ samples; *biased?* — the error falls at first and then flattens (slope of
the last half > −0.4). The stress scenes' references come from Prism's own renderers (the
path tracer with another sampler and seed, or the method named in the section), so a bias
common to both is invisible there; only the Cornell box is checked against an independent
renderer.

relMSE is mean((a − b)² / (b² + 0.01)) over pixels and channels (`prism compare`); the stress
scenes are exposed so that lit surfaces have values around 0.1–1, where ε = 0.01 does not hide
their error.

"""
    head = head.replace("{bdpt_summary}", bdpt_summary(comparisons, clock_key))
    with open(os.path.join(ROOT, "docs", "methods.md"), "w") as f:
        f.write(head + "\n".join(sections))
    print("wrote docs/methods.md", file=sys.stderr)


if __name__ == "__main__":
    main()

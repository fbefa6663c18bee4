//! End-to-end checks of `prism converge` (issue 6): the Monte Carlo rate on the Cornell box
//! against Mitsuba 3's reference, chart and JSON agreeing, metrics equal to `prism compare`'s,
//! the cached reference, and bad references refused with nothing written.

use std::path::Path;

use serde_json::Value;

mod support;
use support::{prism, s, stderr};

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// Least-squares slope of log10 y on log10 x.
fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .map(|&(x, y)| (x.log10(), y.log10()))
        .collect();
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// A small lit scene (a sphere on a floor under an area light) written into `dir`.
fn small_scene(dir: &Path, name: &str, reflectance: f64) -> std::path::PathBuf {
    let path = dir.join(name);
    let json = format!(
        r#"{{
      "camera": {{"type": "pinhole", "fov_deg": 45, "transform": {{"look_at": {{"eye": [0, 1, 3], "target": [0, 0.4, 0]}}}}}},
      "film": {{"resolution": [24, 16], "seed": 1}},
      "integrator": {{"type": "path", "max_depth": 4, "sampler": "independent"}},
      "materials": {{"m": {{"type": "lambert", "reflectance": {reflectance}}}}},
      "shapes": [
        {{"type": "rectangle", "size_m": [4, 4], "material": "m", "transform": {{"rotate": {{"axis": [1, 0, 0], "angle_deg": -90}}}}}},
        {{"type": "sphere", "radius_m": 0.4, "material": "m", "transform": {{"translate": [0, 0.4, 0]}}}},
        {{"type": "rectangle", "name": "lamp", "size_m": [1, 1], "material": "m",
          "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle_deg": 90}}}}, {{"translate": [0, 2, 0]}}]}}
      ],
      "lights": [{{"type": "area", "shape": "lamp", "scale": 3}}]
    }}"#
    );
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn cornell_path_rmse_slope_is_the_monte_carlo_rate_and_chart_and_json_agree() {
    let dir = tempfile::tempdir().unwrap();
    let (svg, png, json) = (
        dir.path().join("cornell.svg"),
        dir.path().join("cornell.png"),
        dir.path().join("cornell.json"),
    );
    // CPU time as the clock: the test machine is shared, and other processes stretch wall
    // time, not the render's CPU time. 1 → 64 spp at 256×256 against Mitsuba 3's 4096-spp
    // reference (its noise and the two renderers' difference are ≪ the 64-spp error).
    let o = prism(&[
        "converge",
        "scenes/cornell-box.json",
        "--reference",
        "tests/fixtures/cornell_mitsuba_reference.exr",
        "--method",
        "path",
        "--max-spp",
        "64",
        "--checkpoints",
        "7",
        "--clock",
        "cpu",
        "-o",
        s(&svg),
        "-o",
        s(&png),
        "--json",
        s(&json),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = read_json(&json);
    let m = &v["methods"][0];
    assert_eq!(m["canonical"], "path+uniform:independent");
    let checkpoints = m["checkpoints"].as_array().unwrap();
    let spp: Vec<u64> = checkpoints
        .iter()
        .map(|c| c["spp"].as_u64().unwrap())
        .collect();
    assert_eq!(
        spp,
        [1, 2, 4, 8, 16, 32, 64],
        "deterministic schedule under --max-spp"
    );
    // The JSON's slope is the fit of its own checkpoints.
    let points: Vec<(f64, f64)> = checkpoints
        .iter()
        .map(|c| {
            (
                c["cpu_time_s"].as_f64().unwrap(),
                c["rmse"].as_f64().unwrap(),
            )
        })
        .collect();
    let slope = m["rmse_slope"].as_f64().unwrap();
    assert!((log_log_slope(&points) - slope).abs() < 1e-9);
    // Error ∝ time^−½ once time ∝ samples: from 8 spp on. Before that, the first pass's
    // fixed cost (film, threads; tens of ms) is a large part of a checkpoint's time with
    // the packet path tracer, where one spp of the box costs ≈ 30–50 ms of CPU.
    let tail: Vec<(f64, f64)> = points
        .iter()
        .zip(&spp)
        .filter(|(_, &n)| n >= 8)
        .map(|(p, _)| *p)
        .collect();
    let tail_slope = log_log_slope(&tail);
    eprintln!("RMSE slope against CPU time from 8 spp on: {tail_slope:.3} (all: {slope:.3})");
    assert!(
        (tail_slope + 0.5).abs() <= 0.1,
        "RMSE against CPU time from 8 spp on: slope {tail_slope}, the Monte Carlo rate is \
         −0.5 ± 0.1 ({checkpoints:?})"
    );
    // Against samples the rate does not depend on the machine at all.
    let per_spp = m["rmse_slope_vs_spp"].as_f64().unwrap();
    assert!((per_spp + 0.5).abs() <= 0.1, "rmse_slope_vs_spp {per_spp}");
    // The chart shows the same fit: its legend carries the JSON's slope.
    let legend = format!("path  slope {}", format!("{slope:.2}").replace('-', "−"));
    assert_eq!(m["legend"][0], legend.as_str());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(&legend), "the SVG legend shows `{legend}`");
    assert!(
        text.contains("render CPU time"),
        "the x axis names the clock"
    );
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    assert_eq!(m["stats"]["non_finite_samples"], 0);
}

#[test]
fn converge_metrics_agree_with_prism_compare_and_the_reference_is_cached() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    let finals = dir.path().join("finals");
    std::fs::create_dir(&finals).unwrap();
    let json = dir.path().join("run.json");
    let cache = dir.path().join("cache");
    let run = |json: &Path| {
        prism(&[
            "converge",
            s(&scene),
            "--cache-dir",
            s(&cache),
            "--reference-spp",
            "256",
            "--method",
            "path",
            "--method",
            "path+uniform:sobol",
            "--max-spp",
            "16",
            "--checkpoints",
            "3",
            "--json",
            s(json),
            "--save-final",
            s(&finals),
        ])
    };
    let o = run(&json);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("rendering one at 256 spp") && err.contains("caching it as"),
        "{err}"
    );
    let v = read_json(&json);
    let reference = v["reference"]["path"].as_str().unwrap().to_string();
    assert_eq!(v["reference"]["source"], "rendered");
    assert!(Path::new(&reference).starts_with(&cache), "in --cache-dir");
    assert!(reference.contains("small.reference-24x16-256spp-"));
    for (i, label) in ["path", "path_uniform_sobol"].iter().enumerate() {
        let image = finals.join(format!("{i}-{label}.exr"));
        let o = prism(&["compare", s(&image), &reference, "--json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let c: Value = serde_json::from_slice(&o.stdout).unwrap();
        let last = &v["methods"][i]["final"];
        for key in [
            "mse",
            "rmse",
            "relmse",
            "delta_e2000_mean",
            "delta_e2000_p95",
        ] {
            let (a, b) = (c[key].as_f64().unwrap(), last[key].as_f64().unwrap());
            // The same f32 pixels through the same code: equal to rounding of the sums.
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1e-300),
                "{label} {key}: compare {a} vs converge {b}"
            );
        }
    }
    // Second run: the cached reference is used; editing the scene invalidates it.
    let o = run(&dir.path().join("again.json"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("using the cached"), "{}", stderr(&o));
    small_scene(dir.path(), "small.json", 0.5);
    let o = run(&dir.path().join("edited.json"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("rendering one"), "{}", stderr(&o));
    let edited = read_json(&dir.path().join("edited.json"));
    assert_ne!(edited["reference"]["path"].as_str().unwrap(), reference);
}

#[test]
fn an_unwritable_reference_cache_is_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    // A cache "directory" under a regular file cannot be created, whoever runs the test
    // (a read-only folder would not stop root).
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, "").unwrap();
    let json = dir.path().join("run.json");
    let o = prism(&[
        "converge",
        s(&scene),
        "--cache-dir",
        s(&blocker.join("cache")),
        "--max-spp",
        "2",
        "--json",
        s(&json),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("--cache-dir") && err.contains("cannot create"),
        "{err}"
    );
    assert!(
        !err.contains("rendering one"),
        "refused before the reference renders: {err}"
    );
    assert!(!json.exists());
}

#[test]
fn bad_references_and_methods_exit_with_a_clear_message_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let not_image = dir.path().join("notes.exr");
    std::fs::write(&not_image, "these are notes, not pixels").unwrap();
    let cases: [(&str, &[&str], &str); 8] = [
        (
            "tests/fixtures/cornell_mitsuba_reference.exr",
            &[],
            "is 256×256 px but the render is 24×16 px",
        ),
        ("tests/fixtures/missing.exr", &[], "cannot open it"),
        (s(&not_image), &[], "not a readable image"),
        ("tests/fixtures/cct.json", &[], "not a readable image"),
        (
            "tests/fixtures/cornell_mitsuba_reference.exr",
            &["--resolution", "256x256", "--method", "vcm"],
            "unknown integrator `vcm`; known: INTEGRATOR[+PLAN][:SAMPLER]",
        ),
        (
            "tests/fixtures/cornell_mitsuba_reference.exr",
            &["--resolution", "256x256", "--method", "light+adaptive"],
            "the sample plan `adaptive` is for `path`, not `light`",
        ),
        (
            "tests/fixtures/cornell_mitsuba_reference.exr",
            &["--resolution", "256x256", "--method", "path+oracle"],
            "path+oracle needs --oracle-variance FILE.exr",
        ),
        (
            "tests/fixtures/cornell_mitsuba_reference.exr",
            &[
                "--resolution",
                "256x256",
                "--method",
                "path+oracle",
                "--oracle-variance",
                "tests/fixtures/cornell_mitsuba_reference.exr",
            ],
            "no `variance.Y` layer",
        ),
    ];
    for (reference, extra, says) in cases {
        let chart = out.join("chart.png");
        let json = out.join("data.json");
        let mut args = vec![
            "converge",
            s(&scene),
            "--reference",
            reference,
            "--max-spp",
            "4",
            "-o",
            s(&chart),
            "--json",
            s(&json),
        ];
        args.extend_from_slice(extra);
        let o = prism(&args);
        assert!(!o.status.success(), "{reference}: should fail");
        let err = stderr(&o);
        assert!(
            err.contains(says),
            "{reference}: `{err}` should say `{says}`"
        );
        assert!(err.starts_with("error: "), "{err}");
        let written: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
        assert!(written.is_empty(), "{reference}: wrote {written:?}");
        let beside: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("reference"))
            .collect();
        assert!(beside.is_empty(), "no reference was rendered: {beside:?}");
    }
}

/// The per-pixel plans run end to end: `path+predicted`, `path+predicted-hier`,
/// `path+adaptive` and `path+oracle` (fed the `variance.Y` layer of a `prism render` EXR)
/// reach the same final spp as `path` and are in the JSON.
#[test]
fn per_pixel_plans_converge_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    let reference = dir.path().join("reference.exr");
    let o = prism(&["render", s(&scene), "-o", s(&reference), "--spp", "64"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = dir.path().join("data.json");
    let o = prism(&[
        "converge",
        s(&scene),
        "--reference",
        s(&reference),
        "--oracle-variance",
        s(&reference),
        "--method",
        "path",
        "--method",
        "path+predicted",
        "--method",
        "path+predicted-hier",
        "--method",
        "path+adaptive",
        "--method",
        "path+oracle",
        "--max-spp",
        "16",
        "--checkpoints",
        "4",
        "--seed",
        "3",
        "-o",
        s(&dir.path().join("chart.png")),
        "--json",
        s(&json),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let data: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let methods = data["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 5);
    for (m, plan) in methods.iter().zip([
        "uniform",
        "predicted",
        "predicted-hier",
        "adaptive",
        "oracle",
    ]) {
        assert_eq!(m["plan"], plan, "{m}");
        let last = m["checkpoints"].as_array().unwrap().last().unwrap().clone();
        assert_eq!(last["spp"], 16, "{plan}: {last}");
        // The predictor's CPU time, tables apart, only where it ran.
        for key in ["tables_cpu_s", "predict_cpu_s"] {
            match plan {
                "predicted" | "predicted-hier" => {
                    assert!(m[key].as_f64().unwrap() > 0.0, "{key}: {m}")
                }
                _ => assert!(m[key].is_null(), "{plan} {key}"),
            }
        }
        // Ratios against the first method, at its checkpoints inside this one's range.
        match plan {
            "uniform" => assert!(m.get("ratios").is_none()),
            _ => {
                let r = &m["ratios"];
                assert_eq!(r["against"], "path");
                assert_eq!(r["time_to_relmse"].as_array().unwrap().len(), 3);
                for row in r["relmse_at_equal_time"].as_array().unwrap() {
                    let (a, t) = (
                        row["against"].as_f64().unwrap(),
                        row["this"].as_f64().unwrap(),
                    );
                    assert!((row["ratio"].as_f64().unwrap() - a / t).abs() <= 1e-12 * a / t);
                }
            }
        }
    }
}

/// `--report` writes one self-contained page: the chart inlined, the methods table with
/// each method's last checkpoint (the numbers of `--json`), and per method a viewer of its
/// image against the reference with three error maps. The light-path estimators (bdpt)
/// run through converge's planner too (pixels that share a start are one ordinary pass).
#[test]
fn report_holds_the_chart_the_table_and_every_method_s_images() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    let reference = dir.path().join("reference.exr");
    let o = prism(&["render", s(&scene), "-o", s(&reference), "--spp", "64"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (json, html) = (dir.path().join("data.json"), dir.path().join("study.html"));
    let o = prism(&[
        "converge",
        s(&scene),
        "--reference",
        s(&reference),
        "--method",
        "path",
        "--method",
        "bdpt",
        "--max-spp",
        "8",
        "--checkpoints",
        "3",
        "--json",
        s(&json),
        "--report",
        s(&html),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let page = support::html_report::check_report(&std::fs::read_to_string(&html).unwrap());
    assert_eq!(page.inline_svgs, 1, "the chart");
    assert_eq!((page.viewers, page.exposure_controls), (2, 2));
    // Per method: A and B as RGBE pairs (4 PNGs of 24×16), HDR-FLIP, LDR-FLIP, ΔE2000.
    assert_eq!(page.images.len(), 2 * 7, "{:?}", page.images);
    assert_eq!(page.images.iter().filter(|s| **s == (24, 16)).count(), 8);
    let data = read_json(&json);
    let table = &page.tables[0];
    assert_eq!(table[0][0], "method");
    for (row, method) in table[1..].iter().zip(data["methods"].as_array().unwrap()) {
        assert_eq!(row[0], method["method"].as_str().unwrap());
        assert_eq!(row[1], method["final"]["spp"].to_string());
        let relmse: f64 = row[4].parse().unwrap();
        let want = method["final"]["relmse"].as_f64().unwrap();
        assert!((relmse - want).abs() <= 1e-4 * want, "{relmse} vs {want}");
    }
    // Checked before anything renders.
    let o = prism(&[
        "converge",
        s(&scene),
        "--reference",
        s(&reference),
        "--report",
        s(&dir.path().join("study.txt")),
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("expected an .html file name"),
        "{}",
        stderr(&o)
    );
}

/// `--method photon_progressive` and `--method photon` run on a scene written for `path`
/// (every photon parameter has a default): the progressive method's error falls from the
/// first checkpoint to the last. `light` runs beside them: converge's uniform passes give
/// every pixel the same first sample index, which the splatting methods take as a moved
/// uniform plan.
#[test]
fn photon_methods_run_on_a_path_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path(), "small.json", 0.6);
    let json = dir.path().join("run.json");
    let o = prism(&[
        "converge",
        s(&scene),
        "--reference-spp",
        "64",
        "--method",
        "photon_progressive",
        "--method",
        "photon",
        "--method",
        "light",
        "--max-spp",
        "16",
        "--checkpoints",
        "3",
        "--json",
        s(&json),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = read_json(&json);
    assert_eq!(
        v["methods"][0]["canonical"],
        "photon_progressive+uniform:independent"
    );
    assert_eq!(v["methods"][1]["canonical"], "photon+uniform:independent");
    assert_eq!(v["methods"][2]["canonical"], "light+uniform:independent");
    let checkpoints = v["methods"][0]["checkpoints"].as_array().unwrap();
    let relmse: Vec<f64> = checkpoints
        .iter()
        .map(|c| c["relmse"].as_f64().unwrap())
        .collect();
    assert!(
        relmse.iter().all(|e| e.is_finite()) && relmse[relmse.len() - 1] < relmse[0],
        "{relmse:?}"
    );
}

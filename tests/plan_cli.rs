//! `prism render --plan uniform|predicted|predicted-hier|adaptive` end to end: the layers the plans write,
//! the budget they keep, and the errors of their flags (docs/bandwidth.md).

use prism_image::io::exr::read_exr;

mod support;
use support::{prism, s, stderr};

fn render(plan: &[&str], out: &std::path::Path) -> std::process::Output {
    let mut args = vec![
        "render",
        "scenes/glossy-env.json",
        "-o",
        s(out),
        "--resolution",
        "24x16",
        "--spp",
        "8",
    ];
    args.extend_from_slice(plan);
    prism(&args)
}

#[test]
fn predicted_and_adaptive_plans_write_their_layers_and_keep_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    for plan in ["predicted", "adaptive"] {
        let out = dir.path().join(format!("{plan}.exr"));
        let o = render(&["--plan", plan], &out);
        assert!(o.status.success(), "{plan}: {}", stderr(&o));
        let image = read_exr(&out).unwrap();
        let spp = &image.layer("spp").expect("spp layer").samples;
        let mean = spp.iter().map(|&v| f64::from(v)).sum::<f64>() / spp.len() as f64;
        // Stochastic rounding keeps the budget in expectation; each pixel's rounding has
        // variance ≤ ¼, so the mean's standard error is ≤ ½/√n: 4 of them.
        let tolerance = 4.0 * 0.5 / (spp.len() as f64).sqrt();
        assert!((mean - 8.0).abs() < tolerance, "{plan}: mean spp {mean}");
        assert!(
            spp.iter().any(|&v| v != spp[0]),
            "{plan}: the plan is not uniform"
        );
        let planned = image.layer("plan").expect("plan layer");
        assert!(planned.channels.iter().any(|c| c == "spp"), "{plan}");
        if plan == "predicted" {
            let mut channels = image
                .layer("bandwidth")
                .expect("bandwidth layer")
                .channels
                .clone();
            channels.sort();
            assert_eq!(channels, ["A", "B", "S"]);
            let mut channels = planned.channels.clone();
            channels.sort();
            assert_eq!(channels, ["level", "spp", "variance"]);
        }
    }
    // A uniform render writes none of them, and its statistics time no predictor.
    let out = dir.path().join("uniform.exr");
    let stats = dir.path().join("uniform.json");
    assert!(render(&["--stats-json", s(&stats)], &out).status.success());
    let image = read_exr(&out).unwrap();
    assert!(image.layer("plan").is_none() && image.layer("bandwidth").is_none());
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert!(stats.get("predictor").is_none(), "{stats}");
}

/// The BSDF angular tables (glossy-env's brushed copper) are written to --cache-dir once
/// and read back by the next render, which comes out the same.
#[test]
fn predicted_plans_keep_their_bsdf_tables_in_the_cache_dir() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let tables = |cache: &std::path::Path| -> Vec<std::path::PathBuf> {
        let mut files: Vec<_> = std::fs::read_dir(cache)
            .map(|d| d.map(|e| e.unwrap().path()).collect())
            .unwrap_or_default();
        files.retain(|f| {
            f.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("bsdf-angular-table-") && n.ends_with(".bin"))
        });
        files.sort();
        files
    };
    // A predicted render with the cache, writing NAME.exr and its statistics NAME.json.
    let render_cached = |name: &str| -> (std::path::PathBuf, std::path::PathBuf) {
        let (image, stats) = (
            dir.path().join(format!("{name}.exr")),
            dir.path().join(format!("{name}.json")),
        );
        let flags = ["--plan", "predicted", "--cache-dir", s(&cache)];
        let o = render(&[&flags[..], &["--stats-json", s(&stats)]].concat(), &image);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        (image, stats)
    };
    let (first, first_stats) = render_cached("first");
    let written = tables(&cache);
    assert!(
        !written.is_empty(),
        "no table written to {}",
        cache.display()
    );
    let modified: Vec<_> = written
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().modified().unwrap())
        .collect();
    let (second, second_stats) = render_cached("second");
    // The statistics time the predictor, tables apart: building the brushed copper's 256
    // slices costs far more than reading them back.
    let predictor = |path: &std::path::Path| -> serde_json::Value {
        let stats: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        stats["predictor"].clone()
    };
    let (built, read) = (predictor(&first_stats), predictor(&second_stats));
    for p in [&built, &read] {
        for key in [
            "tables_cpu_s",
            "predict_cpu_s",
            "tables_wall_s",
            "predict_wall_s",
        ] {
            let v = p[key].as_f64().unwrap_or_else(|| panic!("{key} in {p}"));
            assert!(v.is_finite() && v >= 0.0, "{key} = {v}");
        }
    }
    let (built_s, read_s) = (
        built["tables_cpu_s"].as_f64().unwrap(),
        read["tables_cpu_s"].as_f64().unwrap(),
    );
    assert!(
        built_s > 2.0 * read_s,
        "tables built in {built_s} s, read back in {read_s} s"
    );
    assert_eq!(
        tables(&cache),
        written,
        "the second render wrote other tables"
    );
    let again: Vec<_> = written
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().modified().unwrap())
        .collect();
    assert_eq!(again, modified, "the second render rewrote its tables");
    let (a, b) = (read_exr(&first).unwrap(), read_exr(&second).unwrap());
    for layer in ["plan", "bandwidth"] {
        assert_eq!(
            a.layer(layer).unwrap().samples,
            b.layer(layer).unwrap().samples,
            "{layer}"
        );
    }
}

#[test]
fn plan_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    for (flags, expected) in [
        (vec!["--plan-nb", "4"], "add --plan predicted"),
        (vec!["--plan-colour", "off"], "add --plan predicted"),
        (
            vec!["--plan", "predicted", "--plan-floor", "1.5"],
            "--plan-floor 1.5",
        ),
        (
            vec!["--plan", "predicted", "--plan-nb", "0"],
            "--plan-nb must be at least 1",
        ),
        (vec!["--plan-probe-stride", "2"], "add --plan predicted"),
        (vec!["--plan-pool-px", "3"], "add --plan predicted"),
        // An option given at its default value is still an option given without its plan.
        (vec!["--plan-nb", "16"], "add --plan predicted"),
        (vec!["--plan-pool-px", "auto"], "add --plan predicted"),
        (vec!["--plan-visibility", "on"], "add --plan predicted"),
        (
            vec!["--plan", "predicted", "--plan-max-level", "3"],
            "add --plan predicted-hier",
        ),
        (
            vec!["--plan", "predicted", "--plan-pool-px", "2.5"],
            "'2.5': expected `auto` or a radius in whole pixels",
        ),
        (
            vec!["--plan", "predicted", "--plan-probe-stride", "0"],
            "'0': expected `auto` or a stride in whole pixels, at least 1",
        ),
        (
            vec!["--plan", "predicted", "--plan-max-level", "2"],
            "add --plan predicted-hier",
        ),
        (
            vec!["--plan", "predicted-hier", "--plan-max-level", "9"],
            "--plan-max-level 9: expected a level from 1",
        ),
        (
            vec!["--plan", "predicted-hier", "--samples", "0..4"],
            "cannot render a sample range (--samples)",
        ),
    ] {
        let o = render(&flags, &out);
        assert!(!o.status.success(), "{flags:?}");
        assert!(stderr(&o).contains(expected), "{flags:?}: {}", stderr(&o));
    }
    let o = prism(&[
        "render",
        "scenes/cameras/pinhole.json",
        "-o",
        s(&out),
        "--resolution",
        "8x8",
        "--plan",
        "adaptive",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("per-pixel sample plans are for the `path` integrator"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "no output on error");
}

/// `--plan predicted-hier` (Bagher et al. 2013 §3.2): the smooth sky and floor of the
/// glossy-env scene are shaded on a lattice; the pixels in between get no samples (`spp.Y`
/// 0) and are filled from their shaded neighbours, so no pixel is left black, and the budget
/// is the same.
#[test]
fn the_hierarchical_plan_fills_the_pixels_it_does_not_shade() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hier.exr");
    let o = prism(&[
        "render",
        "scenes/glossy-env.json",
        "-o",
        s(&out),
        "--resolution",
        "64x36",
        "--spp",
        "8",
        "--plan",
        "predicted-hier",
        "--plan-max-level",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = read_exr(&out).unwrap();
    let spp = &image.layer("spp").expect("spp layer").samples;
    let unshaded = spp.iter().filter(|&&v| v == 0.0).count();
    assert!(
        unshaded > spp.len() / 10,
        "{unshaded} of {} pixels interpolated",
        spp.len()
    );
    let mean = spp.iter().map(|&v| f64::from(v)).sum::<f64>() / spp.len() as f64;
    // Only the shaded pixels are rounded (variance ≤ ¼ each): the mean's standard error is
    // ≤ ½·√(shaded)/n; 4 of them, as in the test above.
    let shaded = (spp.len() - unshaded) as f64;
    let tolerance = 4.0 * 0.5 * shaded.sqrt() / spp.len() as f64;
    assert!(
        (mean - 8.0).abs() < tolerance,
        "mean spp {mean} ± {tolerance}"
    );
    // Every interpolated pixel takes the values of its neighbours: the sky and the floor
    // are lit, so none is black.
    for (i, p) in image.pixels().iter().enumerate() {
        assert!(p.iter().all(|v| v.is_finite()), "pixel {i}: {p:?}");
        if spp[i] == 0.0 {
            assert!(p.iter().sum::<f32>() > 0.0, "pixel {i} left black: {p:?}");
        }
    }
}

/// `prism render scenes/glossy-env.json --explain` with `plan`'s flags: its stdout.
fn explain(plan: &[&str]) -> String {
    let mut args = vec!["render", "scenes/glossy-env.json", "--explain"];
    args.extend_from_slice(plan);
    let o = prism(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn explain_names_the_plan() {
    let text = explain(&["--plan", "predicted", "--plan-allocation", "variance"]);
    assert!(text.contains("predicted sample plan"), "{text}");
    assert!(text.contains("64 probe light samples"), "{text}");
    assert!(
        text.contains("predicted variance (the paper's rule)"),
        "{text}"
    );
    assert!(text.contains("plus the colour noise"), "{text}");
    let text = explain(&["--plan", "predicted", "--plan-colour", "off"]);
    assert!(
        text.contains("of the luminance alone (--plan-colour off)"),
        "{text}"
    );
    // glossy-env is 480×270: the automatic pooling radius is 270/32 ≈ 8 px, the automatic
    // probe stride half of it.
    assert!(
        text.contains(
            "64 probe light samples per probed pixel (n_b = 16 times S²/4, at least n_b, and \
             the indirect estimates likewise, at one pixel in 4×4 and each pixel of a \
             surface with none within 8 px; the others take the nearest probed pixel's \
             bandwidth and the pooled V̂: --plan-probe-stride auto, half the pooling radius \
             within 1 to 4; 1 probes every pixel, as the paper)"
        ),
        "{text}"
    );
    let text = explain(&["--plan", "predicted", "--plan-probe-stride", "1"]);
    assert!(
        text.contains(
            "16 probe light samples per probed pixel (every pixel, as the paper: \
             --plan-probe-stride 1)"
        ),
        "{text}"
    );
    let text = explain(&["--plan", "predicted-hier"]);
    assert!(
        text.contains(
            "16 probe light samples per probed pixel (every pixel, as the paper: \
             --plan-probe-stride auto is 1 for predicted-hier"
        ),
        "{text}"
    );
    let text = explain(&["--plan", "predicted", "--resolution", "64x36"]);
    assert!(
        text.contains(
            "per probed pixel (every pixel, as the paper: --plan-probe-stride auto is half the \
             pooling radius of 1 px, at least 1)"
        ),
        "{text}"
    );
    let text = explain(&["--plan", "predicted", "--plan-probe-stride", "3"]);
    assert!(
        text.contains("36 probe light samples per probed pixel (n_b = 16 times S²/4"),
        "{text}"
    );
    assert!(
        text.contains("at one pixel in 3×3 and each pixel of a surface with none within 8 px"),
        "{text}"
    );
    assert!(
        text.contains(
            "pooled over the pixels of the same material within 8 px (--plan-pool-px auto"
        ),
        "{text}"
    );
    let text = explain(&["--plan", "predicted", "--plan-pool-px", "0"]);
    assert!(
        text.contains("per pixel, not pooled, as the paper (--plan-pool-px 0)"),
        "{text}"
    );
    let text = explain(&["--plan", "predicted", "--plan-pool-px", "3"]);
    assert!(
        text.contains("same material within 3 px (--plan-pool-px)"),
        "{text}"
    );
    let text = explain(&["--plan", "predicted-hier"]);
    assert!(text.contains("predicted-hier sample plan"), "{text}");
    assert!(text.contains("at most 8 px apart"), "{text}");
}

//! `prism render --plan uniform|predicted|adaptive` end to end: the layers the plans write,
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
    // A uniform render writes none of them.
    let out = dir.path().join("uniform.exr");
    assert!(render(&[], &out).status.success());
    let image = read_exr(&out).unwrap();
    assert!(image.layer("plan").is_none() && image.layer("bandwidth").is_none());
}

#[test]
fn plan_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    for (flags, expected) in [
        (vec!["--plan-nb", "4"], "add --plan predicted"),
        (
            vec!["--plan", "predicted", "--plan-floor", "1.5"],
            "--plan-floor 1.5",
        ),
        (
            vec!["--plan", "predicted", "--plan-nb", "0"],
            "--plan-nb must be at least 1",
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

#[test]
fn explain_names_the_plan() {
    let o = prism(&[
        "render",
        "scenes/glossy-env.json",
        "--explain",
        "--plan",
        "predicted",
        "--plan-allocation",
        "variance",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("predicted sample plan"), "{text}");
    assert!(text.contains("16 probe light samples"), "{text}");
    assert!(
        text.contains("predicted variance (the paper's rule)"),
        "{text}"
    );
}

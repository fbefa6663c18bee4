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
    let o = prism(&[
        "render",
        "scenes/glossy-env.json",
        "--explain",
        "--plan",
        "predicted-hier",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("predicted-hier sample plan"), "{text}");
    assert!(text.contains("at most 8 px apart"), "{text}");
}

//! `prism tile-brdf`: the pyramid of the example wicker tile computed once, then read from
//! the cache; a switched pyramid (`--no-self-shadowing`) under its own key; the summary's
//! keys; the errors of a misnamed tile, of too few samples and of a pyramid above the
//! memory limit.

mod support;
use support::prism_in as prism;

fn wicker_scene() -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/tiled/wicker-wall.json")
        .display()
        .to_string()
}

#[test]
fn the_pyramid_is_computed_once_and_then_read_from_the_cache() {
    let dir = tempfile::tempdir().unwrap();
    let scene = wicker_scene();
    let args = [
        "tile-brdf",
        scene.as_str(),
        "--tile",
        "wicker",
        "--levels",
        "2",
        "--samples",
        "16",
        "--cache-dir",
        "cache",
        "-o",
        "summary.json",
    ];
    let first = prism(dir.path(), &args);
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(first.status.success(), "{stderr}");
    assert!(stderr.contains("computed and cached in"), "{stderr}");
    let text = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(summary["levels"], 2);
    assert_eq!(summary["cells"], 5);
    assert_eq!(summary["from_cache"], false);
    let incident = summary["incident"].as_array().unwrap();
    assert_eq!(incident.len(), 64);
    for bin in incident {
        let albedo = bin["albedo"].as_array().unwrap();
        assert_eq!(albedo.len(), 16);
        let tau = bin["transparency"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&tau));
        // The cane's reflectances are below 0.8: so is the weave's albedo.
        assert!(albedo
            .iter()
            .all(|a| (0.0..0.8).contains(&a.as_f64().unwrap())));
    }
    // Seen straight on, the weave's holes let ≈ 16 % through (4 of 25 cm² of each period,
    // narrowed by the strands' bulge).
    let tau = incident[0]["transparency"].as_f64().unwrap();
    assert!((0.1..0.2).contains(&tau), "τ {tau}");
    // τ̄, over the whole bin (θ up to 41°), is close to it; near grazing it is where the
    // bin's centre (83°) sees nothing through.
    let tau_mean = incident[0]["transparency_bin_mean"].as_f64().unwrap();
    assert!((tau_mean - tau).abs() < 0.03, "τ̄ {tau_mean}, τ {tau}");
    let grazing = &incident[31];
    let (tau, tau_mean) = (
        grazing["transparency"].as_f64().unwrap(),
        grazing["transparency_bin_mean"].as_f64().unwrap(),
    );
    assert!(tau <= tau_mean && tau_mean < 0.1, "τ̄ {tau_mean}, τ {tau}");

    let second = prism(dir.path(), &args);
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(
        second.status.success() && stderr.contains("read from"),
        "{stderr}"
    );
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(again["from_cache"], true);
    assert_eq!(again["incident"], summary["incident"]);

    // Leaving self-shadowing out is another pyramid: computed anew under its own key, and
    // brighter (every face facing the beam is lit).
    let mut unshadowed_args = args.to_vec();
    unshadowed_args.push("--no-self-shadowing");
    let third = prism(dir.path(), &unshadowed_args);
    let stderr = String::from_utf8_lossy(&third.stderr);
    assert!(
        third.status.success() && stderr.contains("computed and cached in"),
        "{stderr}"
    );
    let unshadowed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(unshadowed["self_shadowing"], false);
    assert_eq!(unshadowed["interreflection"], true);
    assert_ne!(unshadowed["cache_file"], summary["cache_file"]);
    let mean = |s: &serde_json::Value| {
        let bins = s["incident"].as_array().unwrap();
        bins.iter()
            .flat_map(|b| b["albedo"].as_array().unwrap().iter())
            .map(|a| a.as_f64().unwrap())
            .sum::<f64>()
    };
    assert!(mean(&unshadowed) > mean(&summary));
}

#[test]
fn misnamed_tiles_and_too_few_samples_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let scene = wicker_scene();
    let o = prism(
        dir.path(),
        &["tile-brdf", &scene, "--tile", "wickr", "--cache-dir", "c"],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("no tile `wickr` (defined: `wicker`)"),
        "{stderr}"
    );
    let o = prism(
        dir.path(),
        &[
            "tile-brdf",
            &scene,
            "--tile",
            "wicker",
            "--samples",
            "8",
            "--cache-dir",
            "c",
        ],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("at least 64"),
        "{stderr}"
    );
    // 8 levels would take 53 GiB while simulated: refused before anything is allocated.
    let o = prism(
        dir.path(),
        &[
            "--max-memory",
            "1G",
            "tile-brdf",
            &scene,
            "--tile",
            "wicker",
            "--levels",
            "8",
            "--samples",
            "65536",
            "--cache-dir",
            "c",
        ],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && stderr.contains("a pyramid of 8 levels of tile `wicker` needs about")
            && stderr.contains("more than the memory limit of 1.00 GiB set by --max-memory"),
        "{stderr}"
    );
}

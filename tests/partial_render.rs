//! Partial renders end to end: sample ranges and `prism merge`, checkpoints and
//! `--resume` (bit for bit against an uninterrupted render, any thread count), Ctrl-C and
//! SIGTERM at random moments (never a half-written or temporary file), and the refusals
//! with their messages (docs/rendering.md, docs/scale-out.md).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use prism_image::io::raw_exr::{read_raw_channels, RawChannels};

mod support;
use support::{prism, s, stderr};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

/// Every channel of an EXR: floats by their bits, raw channels as they are.
fn channels(path: &Path) -> (BTreeMap<String, Vec<u32>>, RawChannels) {
    let file = read_raw_channels(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut all: BTreeMap<String, Vec<u32>> = file
        .floats
        .iter()
        .map(|(k, v)| (k.clone(), v.iter().map(|x| x.to_bits()).collect()))
        .collect();
    all.extend(file.raw.clone());
    (all, file)
}

/// The picture's channels (R, G, B, layers, spectral bins) of two files agree bit for bit.
fn assert_same_picture(a: &Path, b: &Path) {
    assert_picture_within(a, b, 0);
}

/// The pictures of two files agree to `ulps` float32 units in the last place everywhere.
fn assert_picture_within(a: &Path, b: &Path, ulps: u32) -> usize {
    let (ca, _) = channels(a);
    let (cb, _) = channels(b);
    let picture = |c: &BTreeMap<String, Vec<u32>>| -> BTreeMap<String, Vec<u32>> {
        c.iter()
            .filter(|(k, _)| !k.starts_with("sums.") && !k.starts_with("counts."))
            .filter(|(k, _)| *k != "plan.spp")
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect()
    };
    let (pa, pb) = (picture(&ca), picture(&cb));
    assert_eq!(
        pa.keys().collect::<Vec<_>>(),
        pb.keys().collect::<Vec<_>>(),
        "{} and {} have different channels",
        a.display(),
        b.display()
    );
    let mut differing = 0;
    for (name, values) in &pa {
        let other = &pb[name];
        for (i, (x, y)) in values.iter().zip(other).enumerate() {
            if x == y {
                continue;
            }
            differing += 1;
            let (fx, fy) = (f32::from_bits(*x), f32::from_bits(*y));
            // Same sign: the distance of the bit patterns is the distance in ulps.
            let apart = if (fx >= 0.0) == (fy >= 0.0) {
                x.abs_diff(*y)
            } else {
                u32::MAX
            };
            assert!(
                apart <= ulps,
                "{} and {}: channel {name} pixel {i}: {fx} and {fy} ({apart} ulps apart, \
                 {ulps} allowed)",
                a.display(),
                b.display()
            );
        }
    }
    differing
}

fn render(args: &[&str]) -> std::process::Output {
    let mut all = vec!["render"];
    all.extend_from_slice(args);
    prism(&all)
}

struct Case {
    scene: &'static str,
    extra: &'static [&'static str],
}

/// Cornell box (path, independent sampler), a textured glossy scene (Sobol, spectral bins
/// and every AOV), and BDPT (light-path splats merged in item order).
const CASES: [Case; 3] = [
    Case {
        scene: "cornell-box.json",
        extra: &["--resolution", "40x36", "--spp", "16"],
    },
    Case {
        scene: "textures.json",
        extra: &[
            "--resolution",
            "48x27",
            "--spp",
            "8",
            "--spectral-bins",
            "4",
        ],
    },
    Case {
        scene: "bdpt-cornell.json",
        extra: &["--resolution", "36x20", "--spp", "8"],
    },
];

/// A BDPT variant of the Cornell box in `dir`.
fn bdpt_scene(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scene("cornell-box.json")).unwrap();
    let text = text.replace(
        r#""integrator": {"type": "path", "max_depth": 7, "sampler": "independent", "mis": "power", "rr_depth": 5}"#,
        r#""integrator": {"type": "bdpt", "max_depth": 4}"#,
    );
    assert!(
        text.contains("bdpt"),
        "the Cornell box's integrator line changed"
    );
    let text = text.replace(
        "\"cornell-box/",
        &format!("\"{}/", scene("cornell-box").display()),
    );
    let path = dir.join("bdpt-cornell.json");
    std::fs::write(&path, text).unwrap();
    path
}

fn case_scene(case: &Case, dir: &Path) -> PathBuf {
    if case.scene == "bdpt-cornell.json" {
        bdpt_scene(dir)
    } else {
        scene(case.scene)
    }
}

#[test]
fn resumed_renders_equal_uninterrupted_ones_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    for case in &CASES {
        let file = case_scene(case, dir.path());
        let full = dir.path().join("full.exr");
        let mut args = vec![s(&file), "-o", s(&full), "--threads", "2"];
        args.extend_from_slice(case.extra);
        let o = render(&args);
        assert!(o.status.success(), "{}: {}", case.scene, stderr(&o));

        // Stopped after a few work items (as Ctrl-C stops it), then resumed with another
        // thread count.
        let out = dir.path().join("long.exr");
        let checkpoint = dir.path().join("long.partial.exr");
        let mut args = vec![
            s(&file),
            "-o",
            s(&out),
            "--threads",
            "2",
            "--stop-after-items",
            "1",
        ];
        args.extend_from_slice(case.extra);
        let o = render(&args);
        assert!(
            !o.status.success(),
            "{}: the stop did not stop it",
            case.scene
        );
        let err = stderr(&o);
        assert!(err.contains("PARTIAL") && err.contains("--resume"), "{err}");
        let (_, header) = channels(&checkpoint);
        assert_eq!(header.text["prism:complete"], "false");
        let (_, output) = channels(&out);
        assert_eq!(
            output.text["prism:complete"], "false",
            "the output is marked partial"
        );

        let mut args = vec![
            s(&file),
            "-o",
            s(&out),
            "--threads",
            "1",
            "--resume",
            s(&checkpoint),
        ];
        args.extend_from_slice(case.extra);
        let o = render(&args);
        assert!(o.status.success(), "{}: {}", case.scene, stderr(&o));
        assert_same_picture(&full, &out);
        assert!(
            !checkpoint.exists(),
            "the finished render removes its checkpoint"
        );
    }
}

#[test]
fn merged_ranges_equal_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    for case in &CASES {
        let file = case_scene(case, dir.path());
        let spp: u32 = case.extra[case.extra.iter().position(|a| *a == "--spp").unwrap() + 1]
            .parse()
            .unwrap();
        let whole = dir.path().join("whole.exr");
        let mut args = vec![s(&file), "-o", s(&whole)];
        args.extend_from_slice(case.extra);
        assert!(render(&args).status.success());
        let mut parts = Vec::new();
        for (k, range) in [format!("{}..{spp}", spp / 2), format!("0..{}", spp / 2)]
            .iter()
            .enumerate()
        {
            let part = dir.path().join(format!("part{k}.exr"));
            let mut args = vec![s(&file), "-o", s(&part), "--samples", range];
            args.extend_from_slice(case.extra);
            let o = render(&args);
            assert!(o.status.success(), "{}: {}", case.scene, stderr(&o));
            parts.push(part);
        }
        let merged = dir.path().join("merged.exr");
        let o = prism(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
        let (_, header) = channels(&merged);
        assert_eq!(
            header.text["prism:ranges_done"],
            format!("0..{},{}..{spp}", spp / 2, spp / 2)
        );
        // The parts' sums start at zero where the whole render's continue, so an f64 sum
        // may differ in its last bit (addition is not associative); written as float32,
        // a value then differs by one ulp at most, and rarely.
        let differing = assert_picture_within(&whole, &merged, 1);
        let (all, _) = channels(&whole);
        let values: usize = all.values().map(Vec::len).sum();
        assert!(
            differing * 1000 <= values,
            "{}: {differing} of {values} values differ",
            case.scene
        );
    }
}

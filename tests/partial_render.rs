//! Partial renders end to end: sample ranges and `prism merge`, checkpoints and
//! `--resume` (bit for bit against an uninterrupted render, any thread count), Ctrl-C and
//! SIGTERM at random moments (never a half-written or temporary file), and the refusals
//! with their messages (docs/rendering.md, docs/scale-out.md).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Stdio;
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
    let (ca, _) = channels(a);
    let (cb, _) = channels(b);
    let picture = |c: &BTreeMap<String, Vec<u32>>| -> BTreeMap<String, Vec<u32>> {
        c.iter()
            .filter(|(k, _)| !k.starts_with("sums.") && !k.starts_with("counts."))
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
    for (name, values) in &pa {
        let other = &pb[name];
        for (i, (x, y)) in values.iter().zip(other).enumerate() {
            assert!(
                x == y,
                "{} and {}: channel {name} pixel {i}: {} and {}",
                a.display(),
                b.display(),
                f32::from_bits(*x),
                f32::from_bits(*y)
            );
        }
    }
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
        let whole = render_whole(&file, dir.path(), case.extra);
        let mut parts = Vec::new();
        for (k, range) in [format!("{}..{spp}", spp / 2), format!("0..{}", spp / 2)]
            .iter()
            .enumerate()
        {
            let part = dir.path().join(format!("part{k}.exr"));
            render_range(&file, &part, range, case.extra);
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
        // The film's sums are exact (fixed point), so the parts add up to the whole render
        // bit for bit, in whichever order they are given.
        assert_same_picture(&whole, &merged);
        let (whole_sums, _) = channels(&whole);
        assert_eq!(
            whole_sums["spp.Y"],
            channels(&merged).0["spp.Y"],
            "{}",
            case.scene
        );
    }
}

/// `photon_progressive` (per-pixel SPPM statistics, Hachisuka & Jensen 2009) on the
/// caustic under a glass sphere in thin fog, on a plain and on an image-textured floor (the
/// camera rays' differentials follow the whole render's pass count in every part): the
/// part 2..4 replays the statistics of passes 0 and 1 (and says so), so the parts 0..2 and
/// 2..4 merge into the 0..4 render bit for bit.
#[test]
fn photon_progressive_ranges_replay_the_passes_before_and_merge_exactly() {
    for textured in [false, true] {
        photon_progressive_ranges_merge_exactly(textured);
    }
}

fn photon_progressive_ranges_merge_exactly(textured: bool) {
    let dir = tempfile::tempdir().unwrap();
    let file = photon_progressive_scene(dir.path());
    if textured {
        let text = std::fs::read_to_string(&file).unwrap();
        let bricks = scene("textures/bricks-albedo.png");
        let edited = text.replace(
            r#""floor": {"type": "lambert", "reflectance": 0.7},"#,
            &format!(
                r#""floor": {{"type": "lambert", "reflectance": {{"texture": {{"type": "image", "file": "{}", "uv_scale": [8, 8]}}}}}},"#,
                bricks.display()
            ),
        );
        assert_ne!(edited, text, "the floor's line changed");
        std::fs::write(&file, edited).unwrap();
    }
    let extra = PHOTON_EXTRA;
    let whole = render_whole(&file, dir.path(), &extra);
    let mut parts = Vec::new();
    for (k, range) in ["2..4", "0..2"].iter().enumerate() {
        let part = dir.path().join(format!("part{k}.exr"));
        let o = render_range(
            &file,
            &part,
            range,
            &[&extra[..], &["--threads", "2"]].concat(),
        );
        let replays = stderr(&o).contains("replays the per-pixel statistics of passes 0..2");
        assert_eq!(replays, *range == "2..4", "{range}: {}", stderr(&o));
        parts.push(part);
    }
    let merged = dir.path().join("merged.exr");
    let o = prism(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_picture(&whole, &merged);
}

/// A photon_progressive render stopped between passes (as Ctrl-C stops it) leaves a
/// checkpoint of the passes done; resuming it replays their per-pixel statistics and
/// renders the rest, bit for bit the uninterrupted render.
#[test]
fn photon_progressive_checkpoints_resume_between_passes() {
    let dir = tempfile::tempdir().unwrap();
    let file = photon_progressive_scene(dir.path());
    let extra = PHOTON_EXTRA;
    let whole = render_whole(&file, dir.path(), &extra);
    let out = dir.path().join("long.exr");
    let checkpoint = dir.path().join("long.partial.exr");
    let mut args = vec![s(&file), "-o", s(&out), "--stop-after-items", "1"];
    args.extend_from_slice(&extra);
    let o = render(&args);
    assert!(!o.status.success(), "the stop did not stop it");
    let (counts, header) = channels(&checkpoint);
    assert_eq!(header.text["prism:complete"], "false");
    assert_eq!(
        header.text["prism:items_done"], "1",
        "one pass in the checkpoint"
    );
    assert!(counts["counts.samples"].iter().all(|&c| c == 1));
    let mut args = vec![
        s(&file),
        "-o",
        s(&out),
        "--threads",
        "1",
        "--resume",
        s(&checkpoint),
    ];
    args.extend_from_slice(&extra);
    let o = render(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_picture(&whole, &out);
}

/// `file`'s samples `range` rendered into the partial image `part`; returns the output.
fn render_range(file: &Path, part: &Path, range: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![s(file), "-o", s(part), "--samples", range];
    args.extend_from_slice(extra);
    let o = render(&args);
    assert!(
        o.status.success(),
        "{} {range}: {}",
        file.display(),
        stderr(&o)
    );
    o
}

/// The size and samples of the photon_progressive tests.
const PHOTON_EXTRA: [&str; 4] = ["--resolution", "24x24", "--spp", "4"];

/// `file` rendered whole (all its samples, no range) into `dir`/whole.exr.
fn render_whole(file: &Path, dir: &Path, extra: &[&str]) -> PathBuf {
    let whole = dir.join("whole.exr");
    let mut args = vec![s(file), "-o", s(&whole)];
    args.extend_from_slice(extra);
    let o = render(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    whole
}

/// caustic-glass-sphere in thin fog with `photon_progressive`, beside `dir`.
fn photon_progressive_scene(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scene("stress/caustic-glass-sphere.json")).unwrap();
    let text = text.replace(
        r#""integrator": {"type": "path", "max_depth": 8},"#,
        r#""integrator": {"type": "photon_progressive", "max_depth": 6, "photons_per_pass": 4000, "alpha": 0.7},
  "world_medium": "fog",
  "media": {"fog": {"sigma_a_per_m": 0.02, "sigma_s_per_m": 0.1}},"#,
    );
    assert!(
        text.contains("photon_progressive"),
        "the scene's integrator line changed"
    );
    let file = dir.join("caustic.json");
    std::fs::write(&file, text).unwrap();
    file
}

/// A copy of a scene beside `dir` with `edit` applied to its text (asset paths made
/// absolute so the copy finds them).
fn edited_scene(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(scene(name)).unwrap();
    let text = text.replace(
        "\"cornell-box/",
        &format!("\"{}/", scene("cornell-box").display()),
    );
    let edited = edit(text.clone());
    assert_ne!(edited, text, "the edit changed nothing");
    let path = dir.join(format!("edited-{name}"));
    std::fs::write(&path, edited).unwrap();
    path
}

#[test]
fn resuming_another_render_is_refused_naming_what_changed() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-box.json");
    let out = dir.path().join("r.exr");
    let checkpoint = dir.path().join("r.partial.exr");
    let base = ["--resolution", "48x32", "--spp", "8", "--threads", "2"];
    let mut args = vec![s(&cornell), "-o", s(&out), "--stop-after-items", "1"];
    args.extend_from_slice(&base);
    assert!(!render(&args).status.success());
    assert!(checkpoint.exists());

    let mut args = vec![s(&cornell), "-o", s(&out), "--resume", s(&checkpoint)];
    args.extend_from_slice(&["--resolution", "48x32", "--spp", "16"]);
    let o = render(&args);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("spp: 8 in the file, 16 now"), "{err}");

    let mut args = vec![s(&cornell), "-o", s(&out), "--resume", s(&checkpoint)];
    args.extend_from_slice(&["--resolution", "48x32", "--spp", "8", "--seed", "9"]);
    let err = stderr(&render(&args));
    assert!(err.contains("seed: 0 in the file, 9 now"), "{err}");

    let edited = edited_scene(dir.path(), "cornell-box.json", |t| {
        t.replace("\"max_depth\": 7", "\"max_depth\": 6")
    });
    let mut args = vec![s(&edited), "-o", s(&out), "--resume", s(&checkpoint)];
    args.extend_from_slice(&base);
    let err = stderr(&render(&args));
    assert!(err.contains("scene: its content changed"), "{err}");
    assert!(!err.contains("spp:"), "only the scene changed: {err}");

    // Options that do not change the image are not part of the identity.
    let other = dir.path().join("elsewhere.exr");
    let mut args = vec![
        s(&cornell),
        "-o",
        s(&other),
        "--resume",
        s(&checkpoint),
        "--threads",
        "1",
        "--checkpoint-every",
        "5m",
        "--progress",
        "none",
    ];
    args.extend_from_slice(&["--resolution", "48x32", "--spp", "8"]);
    let o = render(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn merge_refuses_overlaps_and_other_renders_and_warns_of_gaps() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-box.json");
    let part = |name: &str, range: &str, seed: &str| {
        let path = dir.path().join(name);
        let o = render(&[
            s(&cornell),
            "-o",
            s(&path),
            "--resolution",
            "16x12",
            "--spp",
            "16",
            "--samples",
            range,
            "--seed",
            seed,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        path
    };
    let a = part("a.exr", "0..8", "0");
    let b = part("b.exr", "4..12", "0");
    let c = part("c.exr", "12..16", "0");
    let foreign = part("foreign.exr", "8..12", "5");
    let out = dir.path().join("m.exr");

    let o = prism(&["merge", s(&a), s(&b), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("(samples 0..8) and"), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("(samples 4..12) overlap"),
        "{}",
        stderr(&o)
    );

    let o = prism(&["merge", s(&a), s(&a), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("the same file given twice"),
        "{}",
        stderr(&o)
    );

    let o = prism(&["merge", s(&a), s(&foreign), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("parts of different renders") && err.contains("seed"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written on a refusal");

    let o = prism(&["merge", s(&c), s(&a), "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: no part holds the samples 8..12"),
        "{}",
        stderr(&o)
    );
    let (all, header) = channels(&out);
    assert_eq!(header.text["prism:ranges_done"], "0..8,12..16");
    assert_eq!(header.text["prism:complete"], "false");
    // Weighted by sample counts: 12 samples per pixel.
    assert!(all["spp.Y"].iter().all(|&v| f32::from_bits(v) == 12.0));

    // An interrupted checkpoint is not a part.
    let stopped = dir.path().join("stopped.exr");
    let o = render(&[
        s(&cornell),
        "-o",
        s(&stopped),
        "--resolution",
        "48x32",
        "--spp",
        "16",
        "--samples",
        "8..12",
        "--threads",
        "2",
        "--stop-after-items",
        "1",
    ]);
    assert!(!o.status.success());
    let checkpoint = dir.path().join("stopped.partial.exr");
    let o = prism(&["merge", s(&checkpoint), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--resume"), "{}", stderr(&o));
    // Resumed with the checkpoint alone: its range and spp come from the file.
    let o = render(&[
        s(&cornell),
        "-o",
        s(&stopped),
        "--resolution",
        "48x32",
        "--resume",
        s(&checkpoint),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, header) = channels(&stopped);
    assert_eq!(header.text["prism:samples"], "8..12");
    assert_eq!(header.text["prism:complete"], "true");
}

#[test]
fn predicted_plan_ranges_split_each_pixels_own_samples() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-box.json");
    let common = ["--resolution", "24x16", "--spp", "8", "--plan", "predicted"];
    let whole = render_whole(&cornell, dir.path(), &common);
    let mut parts = Vec::new();
    for (k, range) in ["0..3", "3..8"].iter().enumerate() {
        let part = dir.path().join(format!("p{k}.exr"));
        render_range(&cornell, &part, range, &common);
        parts.push(part);
    }
    let (w, _) = channels(&whole);
    let n_p: Vec<u32> = w["spp.Y"]
        .iter()
        .map(|&v| f32::from_bits(v) as u32)
        .collect();
    assert!(n_p.iter().any(|&n| n != 8), "the plan is not uniform");
    // The part stores the plan, and pixel p gets [⌊a·N_p/N⌋, ⌊b·N_p/N⌋).
    let (p0, _) = channels(&parts[0]);
    assert_eq!(p0["counts.plan"], n_p);
    for (i, &n) in n_p.iter().enumerate() {
        assert_eq!(p0["counts.samples"][i], 3 * n / 8, "pixel {i}");
    }
    let merged = dir.path().join("merged.exr");
    let o = prism(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same_picture(&whole, &merged);
}

/// `kill(2)` of a child.
fn signal(child: &std::process::Child, sig: i32) {
    // SAFETY: sending a signal to a process this test started and has not reaped.
    unsafe {
        libc::kill(child.id() as i32, sig);
    }
}

#[test]
fn signals_at_random_moments_leave_only_whole_files() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-box.json");
    let out = dir.path().join("long.exr");
    let checkpoint = dir.path().join("long.partial.exr");
    // A fixed pseudo-random sequence (LCG) of moments: the same 50 every run.
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = |n: u64| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) % n
    };
    let mut stopped = 0;
    for run in 0..50 {
        let mut child = support::prism_command()
            .args([
                "render",
                s(&cornell),
                "-o",
                s(&out),
                "--resolution",
                "64x48",
                "--spp",
                "96",
                "--threads",
                "1",
                "--checkpoint-every",
                "1s",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let sig = if run % 2 == 0 {
            libc::SIGINT
        } else {
            libc::SIGTERM
        };
        std::thread::sleep(Duration::from_millis(next(200)));
        signal(&child, sig);
        let twice = run % 3 == 0;
        if twice {
            std::thread::sleep(Duration::from_millis(next(20)));
            signal(&child, sig);
        }
        let status = child.wait().unwrap();
        let code = status.code();
        assert!(
            status.success() || code == Some(128 + sig) || status.signal() == Some(sig),
            "run {run}: {status:?}"
        );
        if code == Some(128 + sig) {
            stopped += 1;
        }
        for entry in std::fs::read_dir(dir.path()).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            assert!(!name.ends_with(".tmp"), "run {run}: {name} left behind");
            // Every file that exists is whole: it reads back.
            let (_, file) = channels(&path);
            if path == out
                && file
                    .text
                    .get("prism:complete")
                    .is_some_and(|c| c == "false")
            {
                assert!(
                    checkpoint.exists(),
                    "run {run}: a partial output without checkpoint"
                );
            }
        }
        for f in [&out, &checkpoint] {
            let _ = std::fs::remove_file(f);
        }
    }
    // The moments reach into the render (how many depends on the machine's speed; here
    // most of them): the first signal's path was taken.
    eprintln!("{stopped} of 50 runs stopped mid-render by the first signal");
    assert!(stopped >= 1, "no run was stopped mid-render");
}

#[test]
fn sensor_ranges_merge_into_the_whole_measurement() {
    let dir = tempfile::tempdir().unwrap();
    let room = edited_scene(dir.path(), "daylight-room.json", |t| {
        t.replace(
            r#""relative_error": 0.03, "min_samples": 1024, "max_samples": 200000"#,
            r#""samples": 600"#,
        )
    });
    let common = ["--resolution", "12x8", "--spp", "4"];
    render_whole(&room, dir.path(), &common);
    let mut parts = Vec::new();
    for (k, range) in ["1..4", "0..1"].iter().enumerate() {
        let part = dir.path().join(format!("s{k}.exr"));
        render_range(&room, &part, range, &common);
        assert!(dir
            .path()
            .join(format!("s{k}.sensors.partial.json"))
            .exists());
        parts.push(part);
    }
    let merged = dir.path().join("merged.exr");
    let o = prism(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(p)).unwrap()).unwrap()
    };
    let (w, m) = (read("whole.sensors.json"), read("merged.sensors.json"));
    let points = |v: &serde_json::Value| v["sensors"][0]["points"].as_array().unwrap().clone();
    let (wp, mp) = (points(&w), points(&m));
    assert_eq!(wp.len(), 28);
    for (a, b) in wp.iter().zip(&mp) {
        assert_eq!(a["samples"], b["samples"]);
        let close = |key: &str, tol: f64| {
            let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
            assert!((x - y).abs() <= tol * x.abs(), "{key}: {x} and {y}");
        };
        // The same samples, in exact sums: the same readings bit for bit.
        close("illuminance_lx", 0.0);
        close("std_error_lx", 0.0);
    }
}

//! The stated limits of docs/reliability.md: a command refuses work above `--max-memory`
//! (default 75 % of the physical memory) before it allocates, thread counts and sample
//! counts are bounded with usage errors (status 2), and refusals exit with status 1 and a
//! message that names the size, the estimate and the option.

mod support;

use std::path::Path;

use support::{prism, s, stderr};

/// A normal-integrator sphere (renders in milliseconds) at `resolution`.
fn scene(dir: &Path, resolution: [u32; 2]) -> std::path::PathBuf {
    let path = dir.join("sphere.json");
    let text = format!(
        r#"{{"integrator": "normal", "film": {{"resolution": [{}, {}], "spp": 1}},
            "shapes": [{{"type": "sphere", "transform": {{"translate": [0, 0, -3]}}}}]}}"#,
        resolution[0], resolution[1]
    );
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_huge_film_is_refused_before_it_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let small = scene(dir.path(), [8, 8]);
    let out = dir.path().join("out.exr");
    // On the command line, under the default limit (no machine has terabytes).
    let o = prism(&[
        "render",
        s(&small),
        "--resolution",
        "100000x100000",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("100000×100000 px") && err.contains("TiB"),
        "{err}"
    );
    assert!(err.contains("--max-memory"), "{err}");
    assert!(!out.exists());
    // In the scene's JSON.
    let big = scene(dir.path(), [100000, 100000]);
    let o = prism(&["render", s(&big), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("100000×100000 px"), "{}", stderr(&o));
    // converge checks the same before it renders a reference.
    let o = prism(&[
        "converge",
        s(&big),
        "--cache-dir",
        s(&dir.path().join("cache")),
        "--json",
        s(&dir.path().join("c.json")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("converging 100000×100000 px"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn max_memory_is_honoured_and_parsed() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = scene(dir.path(), [64, 64]);
    let out = dir.path().join("out.exr");
    // 64² px need more than 1 MiB (film, layers, output); 64 MiB suffices.
    let o = prism(&["--max-memory", "1M", "render", s(&sphere), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("1.00 MiB set by --max-memory"), "{err}");
    let o = prism(&["render", s(&sphere), "-o", s(&out), "--max-memory", "64M"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for bad in ["8X", "-1", "0"] {
        let arg = format!("--max-memory={bad}");
        let o = prism(&["render", s(&sphere), &arg]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("expected a size"), "{}", stderr(&o));
    }
    // compare and tonemap estimate from the files' headers.
    let o = prism(&["--max-memory", "100K", "compare", s(&out), s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("comparing") && stderr(&o).contains("64×64 px"));
    let png = dir.path().join("t.png");
    let o = prism(&[
        "--max-memory",
        "100K",
        "tonemap",
        s(&out),
        "-o",
        s(&png),
        "--op",
        "linear",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("tone-mapping"), "{}", stderr(&o));
    assert!(!png.exists());
}

#[test]
fn thread_and_sample_counts_are_bounded_as_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = scene(dir.path(), [8, 8]);
    for command in ["render", "converge"] {
        let o = prism(&[command, s(&sphere), "--threads", "100000"]);
        assert_eq!(o.status.code(), Some(2), "{command}: {}", stderr(&o));
        assert!(stderr(&o).contains("per logical CPU"), "{}", stderr(&o));
        let o = prism(&[command, s(&sphere), "--threads", "0"]);
        assert_eq!(o.status.code(), Some(2), "{command}: {}", stderr(&o));
    }
    let o = prism(&["render", s(&sphere), "--spp", "99999999999"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("at most 4294967295 samples per pixel"),
        "{err}"
    );
    assert!(!err.contains("0..="), "{err}");
    // Every whole-number option says its bound in words.
    for (command, option) in [
        ("render", "--seed"),
        ("render", "--spectral-bins"),
        ("converge", "--checkpoints"),
        ("converge", "--max-spp"),
        ("converge", "--reference-spp"),
    ] {
        let o = prism(&[command, s(&sphere), option, "99999999999999999999999"]);
        assert_eq!(o.status.code(), Some(2), "{option}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains("at most") && !err.contains("0..="),
            "{option}: {err}"
        );
    }
}

//! The repository stands alone: no file refers to the founding documents that lived beside
//! it (their content is in docs/architecture.md). The pattern is built with `concat!` so
//! that this file does not match itself.

use std::path::Path;

const OUTSIDE: &str = concat!("..", "/shared");

fn walk(dir: &Path, hits: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if path.is_dir() {
            // Build outputs, git's store and local virtual environments are not the repository.
            if !matches!(name.as_ref(), "target" | ".git" | ".venv" | "node_modules") {
                walk(&path, hits);
            }
        } else if let Ok(text) = std::fs::read_to_string(&path) {
            for (i, line) in text.lines().enumerate() {
                if line.contains(OUTSIDE) {
                    hits.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
                }
            }
        }
    }
}

#[test]
fn nothing_in_the_repository_refers_outside_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut hits = Vec::new();
    walk(root, &mut hits);
    assert!(
        hits.is_empty(),
        "files refer to {OUTSIDE} (move what they need into docs/architecture.md):\n{}",
        hits.join("\n")
    );
    // The walk saw the repository (a wrong root would pass vacuously).
    assert!(root.join("docs/architecture.md").is_file());
}

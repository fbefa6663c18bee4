//! Every repository path that README.md and docs/**/*.md name exists: paths starting with
//! `docs/`, `crates/`, `tools/`, `scenes/`, `tests/` or `spectra/` anywhere in the text
//! (backticks, commands, prose), and the targets of markdown links, resolved from the page's
//! folder. Docs drift when files move; this names the page and line of each stale path.
//!
//! Not checked, because they are not files of the repository: placeholders (`<stem>`, `*`,
//! `{a,b}`, `…`, all-capitals stems such as `NAME.json`), paths written by the command they
//! appear in (after `-o`, `--output` or `>`), virtual environments the tools' setup scripts
//! make (`.venv`), web links, and paths inside ```json / ```jsonc blocks (scene snippets,
//! whose paths are relative to the scene file).

use std::path::{Component, Path, PathBuf};

const PREFIXES: [&str; 6] = [
    "docs/", "crates/", "tools/", "scenes/", "tests/", "spectra/",
];

/// A path as a page names it: repository-relative, or relative to the page (link targets).
#[derive(Debug, PartialEq)]
enum Mention {
    Repository(String),
    Link(String),
}

/// Characters that continue a path; a prefix preceded by one of them is inside a longer
/// word or path (`/work/main/tools/…`, `prism-docs/…`) and is not a repository path.
fn is_path_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '.' | '/' | '-' | '+')
}

/// Where a path mention ends: whitespace, quoting, brackets, a `:line` suffix, an anchor.
fn ends_path(c: char) -> bool {
    c.is_whitespace()
        || matches!(
            c,
            '`' | '"' | '\'' | '(' | ')' | '[' | ']' | ':' | '#' | '|' | ';' | '!' | '?'
        )
}

/// The last whitespace-separated word before byte `at` of `line`.
fn word_before(line: &str, at: usize) -> &str {
    line[..at]
        .trim_end_matches(['`', '"'])
        .split_whitespace()
        .next_back()
        .unwrap_or("")
}

/// The repository paths and link targets named on one line of a page.
fn mentions(line: &str) -> Vec<Mention> {
    let mut found = Vec::new();
    let mut previous: Option<char> = None;
    for (at, c) in line.char_indices() {
        let starts_here = previous.is_none_or(|p| !is_path_char(p))
            && PREFIXES.iter().any(|prefix| line[at..].starts_with(prefix));
        previous = Some(c);
        if !starts_here {
            continue;
        }
        let end = line[at..].find(ends_path).map_or(line.len(), |n| at + n);
        let path = line[at..end].trim_end_matches(['.', ',']);
        // Written by the command it appears in, not read from the repository.
        if matches!(word_before(line, at), "-o" | "--output" | ">") {
            continue;
        }
        found.push(Mention::Repository(path.to_string()));
    }
    let mut rest = line;
    while let Some(open) = rest.find("](") {
        let after = &rest[open + 2..];
        let Some(close) = after.find(')') else { break };
        let target = after[..close].split('#').next().unwrap_or("");
        let web = target.contains("://") || target.starts_with("mailto:");
        if !target.is_empty() && !web {
            found.push(Mention::Link(target.to_string()));
        }
        rest = &after[close..];
    }
    found
}

/// A stand-in rather than a file: `<stem>`, globs, `{a,b}`, `…`, an all-capitals name
/// (`NAME.json`, `FILE.csv`) or a one-letter piece (`soa-N.json`).
fn is_placeholder(path: &str) -> bool {
    if path.contains(['<', '>', '*', '{', '}', '…']) {
        return true;
    }
    path.split('/').any(|segment| {
        let stem = segment.split('.').next().unwrap_or("");
        let capitals = !stem.is_empty()
            && stem
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
            && stem.chars().any(|c| c.is_ascii_uppercase());
        let one_letter = stem
            .split(['-', '_'])
            .any(|piece| piece.len() == 1 && piece.chars().all(|c| c.is_ascii_uppercase()));
        capitals || one_letter
    })
}

/// Made by a tool's setup or generator script and git-ignored (tools/mitsuba/.venv,
/// tools/lighting/.venv, tools/bench-scenes/generated).
fn is_generated(path: &str) -> bool {
    Path::new(path)
        .components()
        .any(|c| matches!(c, Component::Normal(name) if name == ".venv" || name == "generated"))
}

/// `page_dir/target` with `..` and `.` resolved lexically (the target may not exist).
fn resolve(page_dir: &Path, target: &str) -> PathBuf {
    let mut out = PathBuf::new();
    for component in page_dir.join(target).components() {
        match component {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

fn pages(root: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut out = vec![root.join("README.md")];
    walk(&root.join("docs"), &mut out);
    out.sort();
    out
}

/// `(page:line: path, paths checked)` for every page under `root`.
fn stale_paths(root: &Path) -> (Vec<String>, usize) {
    let mut stale = Vec::new();
    let mut checked = 0;
    for page in pages(root) {
        let text = std::fs::read_to_string(&page).expect("a page is readable");
        let relative = page.strip_prefix(root).expect("pages are under the root");
        let page_dir = relative.parent().unwrap_or(Path::new(""));
        // The info string of the fenced block the line is in, if any.
        let mut fence: Option<String> = None;
        for (i, line) in text.lines().enumerate() {
            let trimmed = line.trim_start();
            if let Some(info) = trimmed.strip_prefix("```") {
                fence = match fence {
                    Some(_) => None,
                    None => Some(info.trim().to_string()),
                };
                continue;
            }
            if matches!(fence.as_deref(), Some("json" | "jsonc")) {
                continue;
            }
            for mention in mentions(line) {
                let (shown, path) = match &mention {
                    Mention::Repository(p) => (p.clone(), PathBuf::from(p)),
                    Mention::Link(t) => (t.clone(), resolve(page_dir, t)),
                };
                checked += 1;
                let missing = !root.join(&path).exists();
                if missing && !is_placeholder(&shown) && !is_generated(&path.to_string_lossy()) {
                    stale.push(format!("{}:{}: {shown}", relative.display(), i + 1));
                }
            }
        }
    }
    (stale, checked)
}

#[test]
fn every_path_the_docs_name_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (stale, checked) = stale_paths(root);
    assert!(
        stale.is_empty(),
        "README.md and docs/ name paths that do not exist (fix the path or cut the mention):\n{}",
        stale.join("\n")
    );
    // The walk saw the docs (a wrong root or a broken extractor would pass vacuously).
    assert!(checked > 200, "only {checked} paths checked");
}

#[test]
fn the_extractor_finds_paths_and_links_and_skips_the_rest() {
    let line = "Run `cargo run -p x -- scenes/a.json -o scenes/out.exr` (see docs/b.md#part, \
                [c](../tools/c.py), [web](https://x.org/docs/d.md), /work/main/tools/e.py, \
                `tests/f.rs:12`).";
    assert_eq!(
        mentions(line),
        vec![
            Mention::Repository("scenes/a.json".into()),
            Mention::Repository("docs/b.md".into()),
            Mention::Repository("tests/f.rs".into()),
            Mention::Link("../tools/c.py".into()),
        ]
    );
    assert!(is_placeholder("scenes/cameras/NAME.json"));
    assert!(is_placeholder("target/tmp/map_<gamut>.csv"));
    assert!(is_placeholder("docs/bench-cornell-soa-N.json"));
    assert!(!is_placeholder("spectra/LED-B1.csv"));
    assert!(!is_placeholder("crates/render/tests/light_bdpt.rs"));
    assert!(is_generated("tools/mitsuba/.venv/bin/python"));
    assert_eq!(
        resolve(Path::new("docs/history"), "../rendering.md"),
        PathBuf::from("docs/rendering.md")
    );
}

#[test]
fn a_missing_path_is_reported_with_its_page_and_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let root = dir.path();
    std::fs::create_dir_all(root.join("docs/history")).unwrap();
    std::fs::create_dir_all(root.join("tools")).unwrap();
    std::fs::write(root.join("tools/kept.py"), "").unwrap();
    std::fs::write(
        root.join("README.md"),
        "# R\n\n`tools/kept.py` and `tools/gone.py`, `scenes/<stem>.json`, tools/m/.venv/bin/python\n",
    )
    .unwrap();
    std::fs::write(
        root.join("docs/history/p.md"),
        "[up](../../tools/kept.py)\n[x](../missing.md)\n```json\n\"scenes/in-a-scene.csv\"\n```\n",
    )
    .unwrap();
    let (stale, checked) = stale_paths(root);
    assert_eq!(
        stale,
        vec![
            "README.md:3: tools/gone.py",
            "docs/history/p.md:2: ../missing.md"
        ]
    );
    assert_eq!(checked, 6);
}

//! The report of what an import could not carry over exactly: each kind once, with the first
//! place it occurs and how often. A warning by default, an error with `--strict`.

use crate::error::{ImportError, Location};

/// One kind of thing that was not imported (or imported differently).
#[derive(Debug, Clone, PartialEq)]
pub struct UnsupportedKind {
    /// What it is, e.g. `bsdf type="hair"`.
    pub kind: String,
    /// What the importer did instead and why.
    pub consequence: String,
    pub first: Location,
    pub count: usize,
}

/// Every kind in the order first met.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Unsupported {
    pub kinds: Vec<UnsupportedKind>,
}

impl Unsupported {
    /// Records one occurrence; the first one's place and consequence are kept.
    pub fn note(&mut self, kind: impl Into<String>, consequence: impl Into<String>, at: &Location) {
        let kind = kind.into();
        if let Some(k) = self.kinds.iter_mut().find(|k| k.kind == kind) {
            k.count += 1;
            return;
        }
        self.kinds.push(UnsupportedKind {
            kind,
            consequence: consequence.into(),
            first: at.clone(),
            count: 1,
        });
    }

    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// One line per kind: `file:line:column: KIND (N times): CONSEQUENCE`.
    pub fn lines(&self) -> Vec<String> {
        self.kinds
            .iter()
            .map(|k| {
                let times = if k.count == 1 {
                    String::new()
                } else {
                    format!(" ({} times)", k.count)
                };
                format!("{}: {}{times}: {}", k.first, k.kind, k.consequence)
            })
            .collect()
    }

    /// The report as an error (`--strict`): the first kind positions it, all are listed.
    pub fn into_strict_error(self) -> Result<(), ImportError> {
        match self.kinds.first() {
            None => Ok(()),
            Some(first) => Err(ImportError::at(
                &first.first,
                format!(
                    "not imported exactly (--strict):\n  {}",
                    self.lines().join("\n  ")
                ),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use std::sync::Arc;

    fn at(line: u32) -> Location {
        Location {
            file: Arc::new(PathBuf::from("a.xml")),
            line,
            column: 3,
        }
    }

    #[test]
    fn each_kind_is_listed_once_with_its_first_place_and_count() {
        let mut u = Unsupported::default();
        u.note("bsdf hair", "lambert 0.5 instead", &at(4));
        u.note("shape cylinder", "skipped", &at(7));
        u.note("bsdf hair", "lambert 0.5 instead", &at(9));
        assert_eq!(
            u.lines(),
            vec![
                "a.xml:4:3: bsdf hair (2 times): lambert 0.5 instead",
                "a.xml:7:3: shape cylinder: skipped"
            ]
        );
        let e = u.into_strict_error().unwrap_err().to_string();
        assert!(
            e.starts_with("a.xml:4:3: not imported exactly (--strict)"),
            "{e}"
        );
    }
}

//! Typed access to the positioned JSON tree. Every accessor knows its JSON path and the
//! position of its value, so each error says where it is and what was expected.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use prism_spectrum::names::did_you_mean;

use crate::error::{JsonPath, SceneError};
use crate::json::{Member, Node, Position, Value};
use crate::schema::ObjectSchema;

pub(crate) type Result<T> = std::result::Result<T, SceneError>;

/// What every error needs: the scene file, and the folder assets resolve against; and
/// the asset files resolved so far (`SceneDescription::asset_files`).
pub(crate) struct Ctx {
    pub file: PathBuf,
    pub base_dir: PathBuf,
    pub assets: RefCell<Vec<PathBuf>>,
}

impl Ctx {
    pub fn error(&self, pos: Position, path: &JsonPath, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.clone(),
            position: Some(pos),
            path: path.clone(),
            message: message.into(),
        }
    }
}

/// "`a`, `b`, `c`" for lists of valid names in messages.
pub(crate) fn quoted_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// " (did you mean …?)": the closest names by edit distance, or else names that the typo
/// starts with or is contained in (`equisolid_angle` → `equisolid`).
pub(crate) fn suggest<'n>(
    wanted: &str,
    names: impl IntoIterator<Item = &'n str> + Clone,
) -> String {
    let close = did_you_mean(wanted, names.clone());
    if !close.is_empty() || wanted.is_empty() {
        return close;
    }
    let lower = wanted.to_lowercase();
    let related: Vec<String> = names
        .into_iter()
        .filter(|n| {
            let n = n.to_lowercase();
            lower.starts_with(&n) || n.contains(&lower)
        })
        .take(3)
        .map(|n| format!("`{n}`"))
        .collect();
    if related.is_empty() {
        String::new()
    } else {
        format!(" (did you mean {}?)", related.join(", "))
    }
}

/// A value in the tree, with its path.
#[derive(Clone)]
pub(crate) struct V<'a> {
    pub node: &'a Node,
    pub path: JsonPath,
    pub cx: &'a Ctx,
}

impl<'a> V<'a> {
    pub fn err(&self, message: impl Into<String>) -> SceneError {
        self.cx.error(self.node.pos, &self.path, message)
    }

    /// "expected X, found Y".
    pub fn type_err(&self, expected: &str) -> SceneError {
        let found = match &self.node.value {
            Value::Number(n) => format!("the number {n}"),
            Value::String(s) => format!("the string {s:?}"),
            other => other.kind().to_string(),
        };
        self.err(format!("expected {expected}, found {found}"))
    }

    /// A member of this value if it is an object (no field check).
    pub fn member(&self, key: &str) -> Option<V<'a>> {
        match &self.node.value {
            Value::Object(members) => members.iter().find(|m| m.key == key).map(|m| V {
                node: &m.value,
                path: self.path.key(key),
                cx: self.cx,
            }),
            _ => None,
        }
    }

    pub fn is_object(&self) -> bool {
        matches!(self.node.value, Value::Object(_))
    }

    pub fn f64(&self) -> Result<f64> {
        match self.node.value {
            // The tree only holds finite numbers (1e999 is refused while parsing).
            Value::Number(n) => Ok(n),
            _ => Err(self.type_err("a number")),
        }
    }

    /// A number > 0.
    pub fn positive(&self) -> Result<f64> {
        let x = self.f64()?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(format!("expected a positive number, found {x}")))
        }
    }

    /// A number ≥ 0.
    pub fn non_negative(&self) -> Result<f64> {
        let x = self.f64()?;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(format!("expected a number ≥ 0, found {x}")))
        }
    }

    /// A number in the closed range [lo, hi].
    pub fn in_range(&self, lo: f64, hi: f64) -> Result<f64> {
        let x = self.f64()?;
        if (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            Err(self.err(format!("expected a number in [{lo}, {hi}], found {x}")))
        }
    }

    /// A whole number in [min, u32::MAX].
    pub fn u32_at_least(&self, min: u32) -> Result<u32> {
        let expected = format!("a whole number ≥ {min}");
        let x = self.f64().map_err(|_| self.type_err(&expected))?;
        if x.fract() == 0.0 && x >= f64::from(min) && x <= f64::from(u32::MAX) {
            Ok(x as u32)
        } else {
            Err(self.err(format!("expected {expected}, found {x}")))
        }
    }

    pub fn bool(&self) -> Result<bool> {
        match self.node.value {
            Value::Bool(b) => Ok(b),
            _ => Err(self.type_err("true or false")),
        }
    }

    pub fn str(&self) -> Result<&'a str> {
        match &self.node.value {
            Value::String(s) => Ok(s),
            _ => Err(self.type_err("a string")),
        }
    }

    pub fn array(&self) -> Result<Vec<V<'a>>> {
        match &self.node.value {
            Value::Array(items) => Ok(items
                .iter()
                .enumerate()
                .map(|(i, node)| V {
                    node,
                    path: self.path.index(i),
                    cx: self.cx,
                })
                .collect()),
            _ => Err(self.type_err("an array")),
        }
    }

    /// Exactly N numbers, e.g. `[0, 1, 0]`.
    pub fn numbers<const N: usize>(&self) -> Result<[f64; N]> {
        let expected = format!("an array of {N} numbers");
        let items = self.array().map_err(|_| self.type_err(&expected))?;
        if items.len() != N {
            return Err(self.err(format!("expected {expected}, found {}", items.len())));
        }
        let mut out = [0.0; N];
        for (o, item) in out.iter_mut().zip(&items) {
            *o = item.f64()?;
        }
        Ok(out)
    }

    /// A string that must be one of `names`; typos get the closest name.
    pub fn one_of(&self, what: &str, names: &[&'static str]) -> Result<&'static str> {
        let s = self.str()?;
        names.iter().copied().find(|n| *n == s).ok_or_else(|| {
            self.err(format!(
                "unknown {what} `{s}`, expected one of {}{}",
                quoted_list(names),
                suggest(s, names.iter().copied())
            ))
        })
    }

    /// An object whose keys must all be keys of `schema` (a row of `schema::rows()`,
    /// written `schema!("pattern")`).
    pub fn object(&self, schema: &'static ObjectSchema) -> Result<Obj<'a>> {
        match &self.node.value {
            Value::Object(members) => {
                let obj = Obj {
                    v: self.clone(),
                    members,
                };
                obj.check_fields(schema)?;
                Ok(obj)
            }
            _ => Err(self.type_err("an object")),
        }
    }

    /// The members of an object used as a name → value map (named spectra, materials, …).
    pub fn map(&self) -> Result<Vec<(&'a str, V<'a>)>> {
        match &self.node.value {
            Value::Object(members) => Ok(members
                .iter()
                .map(|m| {
                    (
                        m.key.as_str(),
                        V {
                            node: &m.value,
                            path: self.path.key(&m.key),
                            cx: self.cx,
                        },
                    )
                })
                .collect()),
            _ => Err(self.type_err("an object")),
        }
    }

    /// The `type` of a tagged object (`{"type": "sphere", …}`) or a bare string shorthand
    /// (`"gaussian"` for `{"type": "gaussian"}`). `default` applies when `type` is absent.
    pub fn tag(
        &self,
        what: &str,
        variants: &[&'static str],
        default: Option<&'static str>,
    ) -> Result<&'static str> {
        match &self.node.value {
            Value::String(_) => self.one_of(&format!("{what} type"), variants),
            Value::Object(members) => match members.iter().find(|m| m.key == "type") {
                Some(m) => V {
                    node: &m.value,
                    path: self.path.key("type"),
                    cx: self.cx,
                }
                .one_of(&format!("{what} type"), variants),
                None => default.ok_or_else(|| {
                    self.err(format!(
                        "missing field `type`: expected one of {}",
                        quoted_list(variants)
                    ))
                }),
            },
            _ => Err(self.type_err(&format!(
                "a {what} object with a `type` ({}) or a type name",
                quoted_list(variants)
            ))),
        }
    }

    /// The fields of a tagged value: an object, or nothing for the string shorthand.
    pub fn tagged_object(&self, schema: &'static ObjectSchema) -> Result<Obj<'a>> {
        match &self.node.value {
            Value::String(_) => Ok(Obj {
                v: self.clone(),
                members: &[],
            }),
            _ => self.object(schema),
        }
    }

    /// An asset path, resolved relative to the scene file's folder, that must exist and end
    /// in one of `extensions` (lower case, without the dot).
    pub fn asset(&self, what: &str, extensions: &[&str]) -> Result<PathBuf> {
        let given = self.str()?;
        if given.is_empty() {
            return Err(self.err(format!("expected a {what} path, found an empty string")));
        }
        let extension = Path::new(given)
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if !extensions.is_empty()
            && !extension
                .as_deref()
                .is_some_and(|e| extensions.contains(&e))
        {
            let dotted: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
            let dotted: Vec<&str> = dotted.iter().map(String::as_str).collect();
            return Err(self.err(format!(
                "expected a {what} file ending in {}, found `{given}`",
                quoted_list(&dotted)
            )));
        }
        let resolved = self.cx.base_dir.join(given);
        self.cx.assets.borrow_mut().push(resolved.clone());
        if resolved.is_dir() {
            return Err(self.err(format!(
                "{what} file `{given}` is a directory ({}); expected a file",
                resolved.display()
            )));
        }
        if !resolved.is_file() {
            return Err(self.err(format!(
                "{what} file `{given}` not found (looked for {})",
                resolved.display()
            )));
        }
        Ok(resolved)
    }
}

/// An object whose fields were checked against the allowed names.
pub(crate) struct Obj<'a> {
    pub v: V<'a>,
    members: &'a [Member],
}

impl<'a> Obj<'a> {
    fn check_fields(&self, schema: &ObjectSchema) -> Result<()> {
        for m in self.members {
            if !schema.accepts(&m.key) {
                let allowed: Vec<&str> = schema.keys().collect();
                return Err(self.v.cx.error(
                    m.key_pos,
                    &self.v.path.key(&m.key),
                    format!(
                        "unknown field `{}`, expected one of {}{}",
                        m.key,
                        quoted_list(&allowed),
                        suggest(&m.key, allowed.iter().copied())
                    ),
                ));
            }
        }
        Ok(())
    }

    pub fn get(&self, key: &str) -> Option<V<'a>> {
        self.members.iter().find(|m| m.key == key).map(|m| V {
            node: &m.value,
            path: self.v.path.key(key),
            cx: self.v.cx,
        })
    }

    /// A field that must be present.
    pub fn req(&self, key: &str, expected: &str) -> Result<V<'a>> {
        self.get(key).ok_or_else(|| {
            self.v
                .err(format!("missing field `{key}`: expected {expected}"))
        })
    }

    /// At most one of `keys` may be given; returns the one that was, if any.
    pub fn at_most_one(&self, keys: &[&'static str]) -> Result<Option<(&'static str, V<'a>)>> {
        let given: Vec<(&'static str, V<'a>)> = keys
            .iter()
            .filter_map(|k| self.get(k).map(|v| (*k, v)))
            .collect();
        match given.len() {
            0 => Ok(None),
            1 => Ok(given.into_iter().next()),
            _ => Err(given[1].1.err(format!(
                "give only one of {}, found both `{}` and `{}`",
                quoted_list(keys),
                given[0].0,
                given[1].0
            ))),
        }
    }

    pub fn f64_or(&self, key: &str, default: f64) -> Result<f64> {
        self.get(key).map_or(Ok(default), |v| v.f64())
    }

    pub fn positive_or(&self, key: &str, default: f64) -> Result<f64> {
        self.get(key).map_or(Ok(default), |v| v.positive())
    }

    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool> {
        self.get(key).map_or(Ok(default), |v| v.bool())
    }

    pub fn u32_or(&self, key: &str, min: u32, default: u32) -> Result<u32> {
        self.get(key).map_or(Ok(default), |v| v.u32_at_least(min))
    }

    pub fn one_of_or(
        &self,
        key: &str,
        what: &str,
        names: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str> {
        self.get(key).map_or(Ok(default), |v| v.one_of(what, names))
    }

    pub fn vec3_or(&self, key: &str, default: [f64; 3]) -> Result<[f64; 3]> {
        self.get(key).map_or(Ok(default), |v| v.numbers::<3>())
    }
}

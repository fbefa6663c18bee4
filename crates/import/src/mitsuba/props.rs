//! A Mitsuba plugin's properties (`<float name=… value=…/>`, `<rgb …/>`, nested objects):
//! typed access with positioned errors, and a record of which children were read so that
//! every parameter the importer did not use is reported, never dropped silently.

use std::cell::RefCell;

use glam::DVec3;

use crate::error::ImportError;
use crate::mitsuba::xml::Element;
use crate::unsupported::Unsupported;

/// Element tags that are named properties.
const PROPERTY_TAGS: [&str; 9] = [
    "float",
    "integer",
    "boolean",
    "string",
    "point",
    "vector",
    "rgb",
    "spectrum",
    "transform",
];

pub struct Props<'a> {
    pub el: &'a Element,
    used: RefCell<Vec<bool>>,
}

impl<'a> Props<'a> {
    pub fn new(el: &'a Element) -> Self {
        Props {
            el,
            used: RefCell::new(vec![false; el.children.len()]),
        }
    }

    /// The plugin's `type` attribute.
    pub fn plugin_type(&self) -> Result<&'a str, ImportError> {
        self.el.require_attr("type")
    }

    /// The child named `name` (any tag), marked as read.
    pub fn child(&self, name: &str) -> Option<&'a Element> {
        let i = self
            .el
            .children
            .iter()
            .position(|c| c.attr("name") == Some(name))?;
        self.used.borrow_mut()[i] = true;
        Some(&self.el.children[i])
    }

    /// Unnamed or named children with tag `tag` (nested objects and refs), marked as read.
    pub fn objects(&self, tag: &str) -> Vec<&'a Element> {
        let mut used = self.used.borrow_mut();
        self.el
            .children
            .iter()
            .enumerate()
            .filter(|(_, c)| c.tag == tag)
            .map(|(i, c)| {
                used[i] = true;
                c
            })
            .collect()
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, ImportError> {
        match self.child(name) {
            None => Ok(None),
            Some(c) => expect_tag(c, &["float", "integer"])
                .and_then(|()| number(c))
                .map(Some),
        }
    }

    pub fn float_or(&self, name: &str, default: f64) -> Result<f64, ImportError> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, ImportError> {
        match self.child(name) {
            None => Ok(None),
            Some(c) => {
                expect_tag(c, &["integer"])?;
                let v = c.require_attr("value")?;
                v.trim().parse::<i64>().map(Some).map_err(|_| {
                    ImportError::at(&c.at, format!("expected a whole number, found \"{v}\""))
                })
            }
        }
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, ImportError> {
        match self.child(name) {
            None => Ok(None),
            Some(c) => {
                expect_tag(c, &["boolean"])?;
                match c.require_attr("value")?.trim() {
                    "true" => Ok(Some(true)),
                    "false" => Ok(Some(false)),
                    v => Err(ImportError::at(
                        &c.at,
                        format!("expected `true` or `false`, found \"{v}\""),
                    )),
                }
            }
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>, ImportError> {
        match self.child(name) {
            None => Ok(None),
            Some(c) => {
                expect_tag(c, &["string"])?;
                c.require_attr("value").map(Some)
            }
        }
    }

    pub fn point(&self, name: &str) -> Result<Option<DVec3>, ImportError> {
        match self.child(name) {
            None => Ok(None),
            Some(c) => {
                expect_tag(c, &["point", "vector"])?;
                vector3(c).map(Some)
            }
        }
    }

    /// Reports every child not read, as `CONTEXT: parameter NAME`.
    pub fn finish(&self, context: &str, unsupported: &mut Unsupported) {
        let used = self.used.borrow();
        for (c, was_used) in self.el.children.iter().zip(used.iter()) {
            if *was_used {
                continue;
            }
            let what = match c.attr("name") {
                Some(n) => format!("{context}: parameter `{n}` (<{}>)", c.tag),
                None => format!("{context}: nested <{}>", c.tag),
            };
            unsupported.note(what, "ignored: Prism has no equivalent", &c.at);
        }
    }
}

pub fn is_property(tag: &str) -> bool {
    PROPERTY_TAGS.contains(&tag)
}

pub fn expect_tag(c: &Element, tags: &[&str]) -> Result<(), ImportError> {
    if tags.contains(&c.tag.as_str()) {
        Ok(())
    } else {
        let list: Vec<String> = tags.iter().map(|t| format!("<{t}>")).collect();
        Err(ImportError::at(
            &c.at,
            format!(
                "parameter `{}`: expected {}, found <{}>",
                c.attr("name").unwrap_or("?"),
                list.join(" or "),
                c.tag
            ),
        ))
    }
}

/// The `value` attribute as one number.
pub fn number(c: &Element) -> Result<f64, ImportError> {
    let v = c.require_attr("value")?;
    parse_number(v.trim()).ok_or_else(|| {
        ImportError::at(
            &c.at,
            format!(
                "parameter `{}`: expected a number, found \"{v}\"",
                c.attr("name").unwrap_or("?")
            ),
        )
    })
}

pub fn parse_number(s: &str) -> Option<f64> {
    s.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// Numbers separated by commas and/or white space.
pub fn number_list(c: &Element, text: &str) -> Result<Vec<f64>, ImportError> {
    text.split(|ch: char| ch == ',' || ch.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| {
            parse_number(t).ok_or_else(|| {
                ImportError::at(
                    &c.at,
                    format!("expected numbers separated by commas, found \"{t}\" in \"{text}\""),
                )
            })
        })
        .collect()
}

/// `x`, `y`, `z` attributes (default 0) or `value="x, y, z"`.
pub fn vector3(c: &Element) -> Result<DVec3, ImportError> {
    if let Some(v) = c.attr("value") {
        let xs = number_list(c, v)?;
        return match xs.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            [x] => Ok(DVec3::splat(*x)),
            _ => Err(ImportError::at(
                &c.at,
                format!(
                    "expected 3 numbers (x, y, z), found {} in \"{v}\"",
                    xs.len()
                ),
            )),
        };
    }
    let axis = |n: &str| -> Result<f64, ImportError> {
        match c.attr(n) {
            None => Ok(0.0),
            Some(v) => parse_number(v.trim()).ok_or_else(|| {
                ImportError::at(
                    &c.at,
                    format!("attribute {n}: expected a number, found \"{v}\""),
                )
            }),
        }
    };
    Ok(DVec3::new(axis("x")?, axis("y")?, axis("z")?))
}

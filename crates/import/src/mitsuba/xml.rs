//! Mitsuba 3 XML files → an owned element tree with file:line:column on every element:
//! `<default>` and `-D` parameters substituted (`$name`), `<include>` spliced in.
//! roxmltree parses; its errors carry the position of the malformed XML.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{ImportError, Location};

/// An XML element with its attributes (after substitution) and where it starts.
#[derive(Debug, Clone)]
pub struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub at: Location,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    pub fn require_attr(&self, name: &str) -> Result<&str, ImportError> {
        self.attr(name).ok_or_else(|| {
            ImportError::at(
                &self.at,
                format!("<{}> needs the attribute `{name}`", self.tag),
            )
        })
    }

    /// The folder of the file this element was read from (includes and assets resolve there).
    pub fn base_dir(&self) -> PathBuf {
        self.at
            .file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }
}

/// Reads `path` (a `<scene>`), with `defines` overriding its `<default>`s.
pub fn read_scene(path: &Path, defines: &[(String, String)]) -> Result<Element, ImportError> {
    let mut params: HashMap<String, String> = defines.iter().cloned().collect();
    let mut include_stack = Vec::new();
    read_file(path, &mut params, &mut include_stack)
}

fn read_file(
    path: &Path,
    params: &mut HashMap<String, String>,
    include_stack: &mut Vec<PathBuf>,
) -> Result<Element, ImportError> {
    if include_stack.iter().any(|p| p == path) {
        return Err(ImportError::file(
            path,
            "includes itself (through <include>): an include cycle",
        ));
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| ImportError::file(path, format!("cannot read the scene file: {e}")))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| {
        let pos = e.pos();
        let text = e.to_string();
        let suffix = format!(" at {}:{}", pos.row, pos.col);
        ImportError {
            file: path.to_path_buf(),
            position: Some((pos.row, pos.col)),
            message: format!(
                "malformed XML: {}",
                text.strip_suffix(&suffix).unwrap_or(&text)
            ),
        }
    })?;
    let file = Arc::new(path.to_path_buf());
    let root = doc.root_element();
    let at = location(&doc, &root, &file);
    if root.tag_name().name() != "scene" {
        return Err(ImportError::at(
            &at,
            format!(
                "expected <scene> as the root element of a Mitsuba scene, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    if let Some(version) = root.attribute("version") {
        let major = version.split('.').next().unwrap_or("");
        if major != "3" && major != "2" {
            return Err(ImportError::at(
                &at,
                format!(
                    "scene version \"{version}\": expected Mitsuba 2 or 3 (\"3.0.0\"); \
                     Mitsuba 0.x scenes use other plugin and parameter names"
                ),
            ));
        }
    }
    include_stack.push(path.to_path_buf());
    let mut scene = Element {
        tag: "scene".into(),
        attrs: Vec::new(),
        children: Vec::new(),
        at,
    };
    for child in root.children().filter(|n| n.is_element()) {
        let at = location(&doc, &child, &file);
        match child.tag_name().name() {
            "default" => {
                let element = convert(&doc, &child, &file, params)?;
                let name = element.require_attr("name")?.to_string();
                let value = element.require_attr("value")?.to_string();
                params.entry(name).or_insert(value);
            }
            "include" => {
                let element = convert(&doc, &child, &file, params)?;
                let filename = element.require_attr("filename")?;
                let included_path = element.base_dir().join(filename);
                if !included_path.is_file() {
                    return Err(ImportError::at(
                        &at,
                        format!("<include>: no file {}", included_path.display()),
                    ));
                }
                let included = read_file(&included_path, params, include_stack)?;
                scene.children.extend(included.children);
            }
            _ => scene.children.push(convert(&doc, &child, &file, params)?),
        }
    }
    include_stack.pop();
    Ok(scene)
}

fn location(doc: &roxmltree::Document, node: &roxmltree::Node, file: &Arc<PathBuf>) -> Location {
    let pos = doc.text_pos_at(node.range().start);
    Location {
        file: file.clone(),
        line: pos.row,
        column: pos.col,
    }
}

fn convert(
    doc: &roxmltree::Document,
    node: &roxmltree::Node,
    file: &Arc<PathBuf>,
    params: &HashMap<String, String>,
) -> Result<Element, ImportError> {
    let at = location(doc, node, file);
    let mut attrs = Vec::new();
    for a in node.attributes() {
        let value = substitute(a.value(), params).map_err(|name| {
            ImportError::at(
                &at,
                format!(
                    "attribute {}=\"{}\": undefined parameter ${name} (give it a \
                         <default name=\"{name}\" value=\"…\"/> or -D {name}=VALUE)",
                    a.name(),
                    a.value()
                ),
            )
        })?;
        attrs.push((a.name().to_string(), value));
    }
    let mut children = Vec::new();
    for child in node.children() {
        if child.is_element() {
            children.push(convert(doc, &child, file, params)?);
        } else if child.is_text() && !child.text().unwrap_or("").trim().is_empty() {
            let at = location(doc, &child, file);
            return Err(ImportError::at(
                &at,
                format!(
                    "unexpected text inside <{}>: Mitsuba scenes give values as attributes",
                    node.tag_name().name()
                ),
            ));
        }
    }
    Ok(Element {
        tag: node.tag_name().name().to_string(),
        attrs,
        children,
        at,
    })
}

/// Replaces every `$name` (letters, digits, `_`) by its parameter; `Err(name)` if undefined.
fn substitute(value: &str, params: &HashMap<String, String>) -> Result<String, String> {
    if !value.contains('$') {
        return Ok(value.to_string());
    }
    let mut out = String::new();
    let mut rest = value;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let end = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        let name = &after[..end];
        if name.is_empty() {
            out.push('$');
        } else {
            out.push_str(params.get(name).ok_or_else(|| name.to_string())?);
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_are_substituted_and_unknown_ones_named() {
        let params: HashMap<String, String> = [("spp".to_string(), "64".to_string())]
            .into_iter()
            .collect();
        assert_eq!(substitute("$spp", &params).unwrap(), "64");
        assert_eq!(substitute("a $spp b", &params).unwrap(), "a 64 b");
        assert_eq!(substitute("$res", &params), Err("res".to_string()));
    }
}

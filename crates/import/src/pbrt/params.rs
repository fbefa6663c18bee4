//! pbrt parameter lists (`"float radius" [ 2 ]`): typed lookups with positioned errors and a
//! record of what was read, so that every parameter not imported is reported.

use std::cell::Cell;

use glam::DVec3;

use crate::error::{ImportError, Location};
use crate::unsupported::Unsupported;

#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    Number(f64),
    Str(String),
    Bool(bool),
}

#[derive(Debug, Clone)]
pub struct Param {
    /// `float`, `integer`, `point3`, `rgb`, `spectrum`, `texture`, `string`, `bool`, …
    pub ty: String,
    pub name: String,
    pub values: Vec<ParamValue>,
    pub at: Location,
    pub used: Cell<bool>,
}

/// The parameters of one directive.
#[derive(Debug, Clone, Default)]
pub struct Params {
    pub list: Vec<Param>,
}

/// The value types pbrt-v4 declares.
pub const TYPES: [&str; 14] = [
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "normal",
    "point",
    "vector",
    "spectrum",
    "rgb",
    "blackbody",
    "bool",
];

impl Params {
    pub fn get(&self, name: &str) -> Option<&Param> {
        let p = self.list.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn numbers_of(p: &Param) -> Result<Vec<f64>, ImportError> {
        p.values
            .iter()
            .map(|v| match v {
                ParamValue::Number(x) => Ok(*x),
                other => Err(ImportError::at(
                    &p.at,
                    format!("\"{} {}\": expected numbers, found {other:?}", p.ty, p.name),
                )),
            })
            .collect()
    }

    pub fn floats(&self, name: &str) -> Result<Option<Vec<f64>>, ImportError> {
        self.get(name).map(Self::numbers_of).transpose()
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, ImportError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => {
                let xs = Self::numbers_of(p)?;
                match xs.as_slice() {
                    [x] => Ok(Some(*x)),
                    _ => Err(ImportError::at(
                        &p.at,
                        format!(
                            "\"{} {}\": expected one number, found {}",
                            p.ty,
                            p.name,
                            xs.len()
                        ),
                    )),
                }
            }
        }
    }

    pub fn float_or(&self, name: &str, default: f64) -> Result<f64, ImportError> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    pub fn string(&self, name: &str) -> Result<Option<String>, ImportError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.values.as_slice() {
                [ParamValue::Str(s)] => Ok(Some(s.clone())),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"{} {}\": expected one string", p.ty, p.name),
                )),
            },
        }
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, ImportError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.values.as_slice() {
                [ParamValue::Bool(b)] => Ok(Some(*b)),
                _ => Err(ImportError::at(
                    &p.at,
                    format!("\"{} {}\": expected true or false", p.ty, p.name),
                )),
            },
        }
    }

    pub fn point3s(&self, name: &str) -> Result<Option<Vec<DVec3>>, ImportError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => {
                let xs = Self::numbers_of(p)?;
                if xs.len() % 3 != 0 {
                    return Err(ImportError::at(
                        &p.at,
                        format!(
                            "\"{} {}\": expected a multiple of 3 numbers, found {}",
                            p.ty,
                            p.name,
                            xs.len()
                        ),
                    ));
                }
                Ok(Some(
                    xs.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect(),
                ))
            }
        }
    }

    /// Reports every parameter not read, as `CONTEXT: parameter "TYPE NAME"`.
    pub fn finish(&self, context: &str, unsupported: &mut Unsupported) {
        for p in self.list.iter().filter(|p| !p.used.get()) {
            unsupported.note(
                format!("{context}: parameter \"{} {}\"", p.ty, p.name),
                "ignored: Prism has no equivalent",
                &p.at,
            );
        }
    }
}

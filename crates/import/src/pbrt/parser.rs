//! The pbrt-v4 grammar: directives with their positional arguments and parameter lists;
//! `Include`/`Import` splice another file's tokens in place.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{ImportError, Location};
use crate::pbrt::params::{Param, ParamValue, Params, TYPES};
use crate::pbrt::tokenizer::{tokenize, Token, TokenKind};

/// More includes than this in one scene are refused (an include cycle).
const MAX_INCLUDES: usize = 10_000;

pub struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    includes: usize,
    /// The place of the last token read (for "unexpected end of file").
    last: Location,
}

impl Parser {
    pub fn open(path: &Path) -> Result<Parser, ImportError> {
        let tokens = read_tokens(path)?;
        Ok(Parser {
            tokens,
            pos: 0,
            includes: 0,
            last: Location {
                file: Arc::new(path.to_path_buf()),
                line: 1,
                column: 1,
            },
        })
    }

    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    fn next(&mut self, expected: &str) -> Result<Token, ImportError> {
        match self.tokens.get(self.pos) {
            Some(t) => {
                self.pos += 1;
                self.last = t.at.clone();
                Ok(t.clone())
            }
            None => Err(ImportError::at(
                &self.last,
                format!("unexpected end of file: expected {expected}"),
            )),
        }
    }

    /// The next directive's name and place; `None` at the end.
    pub fn directive(&mut self) -> Result<Option<(String, Location)>, ImportError> {
        let Some(t) = self.peek().cloned() else {
            return Ok(None);
        };
        self.pos += 1;
        self.last = t.at.clone();
        match t.kind {
            TokenKind::Ident(name) => {
                if name == "Include" || name == "Import" {
                    let file = self.string("the file name to include")?;
                    let path = t.at.file.parent().unwrap_or(Path::new("")).join(&file);
                    self.includes += 1;
                    if self.includes > MAX_INCLUDES {
                        return Err(ImportError::at(
                            &t.at,
                            format!("{name} \"{file}\": more than {MAX_INCLUDES} includes (an include cycle?)"),
                        ));
                    }
                    let included = read_tokens(&path).map_err(|e| {
                        if e.position.is_none() {
                            ImportError::at(&t.at, format!("{name} \"{file}\": {}", e.message))
                        } else {
                            e
                        }
                    })?;
                    self.tokens.splice(self.pos..self.pos, included);
                    return self.directive();
                }
                Ok(Some((name, t.at)))
            }
            _ => Err(ImportError::at(
                &t.at,
                format!(
                    "expected a directive (such as Shape, Material, WorldBegin), found {}",
                    t.describe()
                ),
            )),
        }
    }

    pub fn string(&mut self, expected: &str) -> Result<String, ImportError> {
        let t = self.next(expected)?;
        match t.kind {
            TokenKind::Str(s) => Ok(s),
            _ => Err(ImportError::at(
                &t.at,
                format!(
                    "expected {expected} (a quoted string), found {}",
                    t.describe()
                ),
            )),
        }
    }

    /// A string without spaces (a name, not a parameter declaration), if one comes next.
    pub fn optional_word(&mut self) -> Option<String> {
        match self.peek().map(|t| &t.kind) {
            Some(TokenKind::Str(s)) if !s.contains(char::is_whitespace) => {
                let s = s.clone();
                self.pos += 1;
                Some(s)
            }
            _ => None,
        }
    }

    /// `n` numbers, optionally in brackets (`Transform [ … ]`).
    pub fn numbers(&mut self, n: usize, directive: &str) -> Result<Vec<f64>, ImportError> {
        let bracketed = matches!(self.peek().map(|t| &t.kind), Some(TokenKind::Open));
        if bracketed {
            self.pos += 1;
        }
        let mut xs = Vec::with_capacity(n);
        for i in 0..n {
            let t = self.next(&format!("{n} numbers after {directive}"))?;
            match t.kind {
                TokenKind::Number(x) => xs.push(x),
                _ => {
                    return Err(ImportError::at(
                        &t.at,
                        format!(
                            "{directive}: expected {n} numbers, found {} after {i}",
                            t.describe()
                        ),
                    ))
                }
            }
        }
        if bracketed {
            let t = self.next("`]`")?;
            if t.kind != TokenKind::Close {
                return Err(ImportError::at(
                    &t.at,
                    format!(
                        "{directive}: expected `]` after {n} numbers, found {}",
                        t.describe()
                    ),
                ));
            }
        }
        Ok(xs)
    }

    /// The parameter list that follows a directive's positional arguments.
    pub fn params(&mut self) -> Result<Params, ImportError> {
        let mut list: Vec<Param> = Vec::new();
        while let Some(Token {
            kind: TokenKind::Str(decl),
            at,
        }) = self.peek().cloned()
        {
            self.pos += 1;
            self.last = at.clone();
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(ImportError::at(
                    &at,
                    format!("expected a parameter declaration \"TYPE NAME\", found \"{decl}\""),
                ));
            };
            if !TYPES.contains(&ty) && ty != "string" && ty != "texture" {
                return Err(ImportError::at(
                    &at,
                    format!("parameter \"{decl}\": unknown type `{ty}`, expected one of {}, string, texture", TYPES.join(", ")),
                ));
            }
            if list.iter().any(|p| p.name == name) {
                return Err(ImportError::at(
                    &at,
                    format!("parameter `{name}` is given twice"),
                ));
            }
            let mut values = Vec::new();
            let t = self.next(&format!("a value for \"{decl}\""))?;
            let push = |t: Token, values: &mut Vec<ParamValue>| -> Result<(), ImportError> {
                let v = match (t.kind, ty) {
                    (TokenKind::Number(x), _) => ParamValue::Number(x),
                    (TokenKind::Str(s), "bool") | (TokenKind::Ident(s), "bool") => match s.as_str()
                    {
                        "true" => ParamValue::Bool(true),
                        "false" => ParamValue::Bool(false),
                        _ => {
                            return Err(ImportError::at(
                                &t.at,
                                format!("\"{decl}\": expected true or false, found `{s}`"),
                            ))
                        }
                    },
                    (TokenKind::Str(s), _) => ParamValue::Str(s),
                    (kind, _) => {
                        return Err(ImportError::at(
                            &t.at,
                            format!(
                                "\"{decl}\": expected a value, found {}",
                                Token {
                                    kind,
                                    at: t.at.clone()
                                }
                                .describe()
                            ),
                        ))
                    }
                };
                values.push(v);
                Ok(())
            };
            if t.kind == TokenKind::Open {
                loop {
                    let v = self.next(&format!("values and `]` for \"{decl}\""))?;
                    if v.kind == TokenKind::Close {
                        break;
                    }
                    push(v, &mut values)?;
                }
            } else {
                push(t, &mut values)?;
            }
            list.push(Param {
                ty: ty.to_string(),
                name: name.to_string(),
                values,
                at,
                used: Cell::new(false),
            });
        }
        Ok(Params { list })
    }
}

fn read_tokens(path: &Path) -> Result<Vec<Token>, ImportError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ImportError::file(path, format!("cannot read the scene file: {e}")))?;
    tokenize(&text, &Arc::new(PathBuf::from(path)))
}

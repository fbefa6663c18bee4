//! pbrt-v4 scene text → tokens with file:line:column: identifiers (directives, `true`,
//! `false`), quoted strings, numbers, `[` and `]`; `#` starts a comment to the end of line.

use std::path::PathBuf;
use std::sync::Arc;

use crate::error::{ImportError, Location};

#[derive(Debug, Clone, PartialEq)]
pub enum TokenKind {
    Ident(String),
    Str(String),
    Number(f64),
    Open,
    Close,
}

#[derive(Debug, Clone)]
pub struct Token {
    pub kind: TokenKind,
    pub at: Location,
}

impl Token {
    pub fn describe(&self) -> String {
        match &self.kind {
            TokenKind::Ident(s) => format!("`{s}`"),
            TokenKind::Str(s) => format!("\"{s}\""),
            TokenKind::Number(x) => format!("the number {x}"),
            TokenKind::Open => "`[`".into(),
            TokenKind::Close => "`]`".into(),
        }
    }
}

pub fn tokenize(text: &str, file: &Arc<PathBuf>) -> Result<Vec<Token>, ImportError> {
    let mut tokens = Vec::new();
    let chars: Vec<char> = text.chars().collect();
    let (mut i, mut line, mut col) = (0usize, 1u32, 1u32);
    let at = |line: u32, col: u32| Location {
        file: file.clone(),
        line,
        column: col,
    };
    while i < chars.len() {
        let c = chars[i];
        let start = at(line, col);
        let advance = |i: &mut usize, line: &mut u32, col: &mut u32| {
            if chars[*i] == '\n' {
                *line += 1;
                *col = 1;
            } else {
                *col += 1;
            }
            *i += 1;
        };
        if c.is_whitespace() {
            advance(&mut i, &mut line, &mut col);
        } else if c == '#' {
            while i < chars.len() && chars[i] != '\n' {
                advance(&mut i, &mut line, &mut col);
            }
        } else if c == '[' || c == ']' {
            advance(&mut i, &mut line, &mut col);
            tokens.push(Token {
                kind: if c == '[' {
                    TokenKind::Open
                } else {
                    TokenKind::Close
                },
                at: start,
            });
        } else if c == '"' {
            advance(&mut i, &mut line, &mut col);
            let mut s = String::new();
            loop {
                if i >= chars.len() || chars[i] == '\n' {
                    return Err(ImportError::at(
                        &start,
                        "unterminated string: expected a closing `\"` on the same line",
                    ));
                }
                let ch = chars[i];
                advance(&mut i, &mut line, &mut col);
                match ch {
                    '"' => break,
                    '\\' if i < chars.len() => {
                        let e = chars[i];
                        advance(&mut i, &mut line, &mut col);
                        s.push(match e {
                            'n' => '\n',
                            't' => '\t',
                            other => other,
                        });
                    }
                    other => s.push(other),
                }
            }
            tokens.push(Token {
                kind: TokenKind::Str(s),
                at: start,
            });
        } else {
            let mut word = String::new();
            while i < chars.len()
                && !chars[i].is_whitespace()
                && !matches!(chars[i], '[' | ']' | '"' | '#')
            {
                word.push(chars[i]);
                advance(&mut i, &mut line, &mut col);
            }
            let first = word.chars().next().unwrap_or(' ');
            let kind = if first.is_ascii_digit() || matches!(first, '-' | '+' | '.') {
                match word.parse::<f64>() {
                    Ok(x) if x.is_finite() => TokenKind::Number(x),
                    _ => {
                        return Err(ImportError::at(
                            &start,
                            format!("expected a number, found `{word}`"),
                        ))
                    }
                }
            } else if first.is_ascii_alphabetic() {
                TokenKind::Ident(word)
            } else {
                return Err(ImportError::at(
                    &start,
                    format!("unexpected character `{first}`: expected a directive, string, number or bracket"),
                ));
            };
            tokens.push(Token { kind, at: start });
        }
    }
    Ok(tokens)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_carry_line_and_column() {
        let file = Arc::new(PathBuf::from("s.pbrt"));
        let t = tokenize("Shape \"sphere\" # c\n  \"float radius\" [ 2.5 ]", &file).unwrap();
        assert_eq!(t[0].kind, TokenKind::Ident("Shape".into()));
        assert_eq!(t[2].kind, TokenKind::Str("float radius".into()));
        assert_eq!((t[2].at.line, t[2].at.column), (2, 3));
        assert_eq!(t[4].kind, TokenKind::Number(2.5));
        let e = tokenize("Shape \"sphere", &file).unwrap_err().to_string();
        assert!(e.starts_with("s.pbrt:1:7: unterminated string"), "{e}");
    }
}

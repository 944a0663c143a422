//! pbrt's tokens: words (directives, `true`/`false`), quoted strings,
//! numbers, `[` and `]`; `#` starts a comment. Each token keeps its line.
//! Parameter lists (`"type name" value` or `"type name" [ values ]`) are
//! read here too.

use std::path::Path;

use crate::error::SceneError;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub line: usize,
}

/// The tokens of a file's text.
pub fn tokens(text: &[u8], file: &Path) -> Result<Vec<Token>, SceneError> {
    let mut out = Vec::new();
    let mut line = 1;
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        match c {
            b'\n' => {
                line += 1;
                i += 1;
            }
            c if c.is_ascii_whitespace() => i += 1,
            b'#' => {
                while i < text.len() && text[i] != b'\n' {
                    i += 1;
                }
            }
            b'[' | b']' => {
                let tok = if c == b'[' { Tok::Open } else { Tok::Close };
                out.push(Token { tok, line });
                i += 1;
            }
            b'"' => {
                let start = line;
                let (s, end) = string(text, i + 1, &mut line).ok_or_else(|| {
                    SceneError::new(
                        file,
                        start,
                        "(syntax)",
                        "a string is not closed with \"".into(),
                    )
                })?;
                out.push(Token {
                    tok: Tok::Str(s),
                    line: start,
                });
                i = end;
            }
            _ => {
                let end = (i..text.len())
                    .find(|&j| {
                        text[j].is_ascii_whitespace()
                            || matches!(text[j], b'[' | b']' | b'"' | b'#')
                    })
                    .unwrap_or(text.len());
                let word = String::from_utf8_lossy(&text[i..end]).into_owned();
                let first = word.as_bytes()[0];
                let tok = if first.is_ascii_digit() || matches!(first, b'-' | b'+' | b'.') {
                    match word.parse::<f64>() {
                        Ok(v) if v.is_finite() => Tok::Num(v),
                        _ => {
                            return Err(SceneError::new(
                                file,
                                line,
                                "(syntax)",
                                format!("`{word}` is not a number"),
                            ))
                        }
                    }
                } else if first.is_ascii_alphabetic() {
                    Tok::Word(word)
                } else {
                    return Err(SceneError::new(
                        file,
                        line,
                        "(syntax)",
                        format!("unexpected `{word}`"),
                    ));
                };
                out.push(Token { tok, line });
                i = end;
            }
        }
    }
    Ok(out)
}

/// A string's text from just after its opening quote, with escapes; the
/// index after its closing quote.
fn string(text: &[u8], mut i: usize, line: &mut usize) -> Option<(String, usize)> {
    let mut s = Vec::new();
    while i < text.len() {
        match text[i] {
            b'"' => return Some((String::from_utf8_lossy(&s).into_owned(), i + 1)),
            b'\n' => return None,
            b'\\' if i + 1 < text.len() => {
                i += 1;
                s.push(match text[i] {
                    b'n' => b'\n',
                    b't' => b'\t',
                    c => c,
                });
            }
            c => s.push(c),
        }
        i += 1;
    }
    let _ = line;
    None
}

/// One value of a parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    Num(f64),
    Str(String),
    Bool(bool),
}

/// A parameter: `"type name" values`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub ty: String,
    pub name: String,
    pub values: Vec<Val>,
    pub line: usize,
}

/// The parameter list starting at `toks[*i]`; stops at the first token that
/// is not a quoted `"type name"`.
pub fn params(toks: &[Token], i: &mut usize, file: &Path) -> Result<Vec<Param>, SceneError> {
    let mut out: Vec<Param> = Vec::new();
    while let Some(Token {
        tok: Tok::Str(decl),
        line,
    }) = toks.get(*i)
    {
        let mut words = decl.split_whitespace();
        let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
            break;
        };
        let line = *line;
        *i += 1;
        let mut values = Vec::new();
        let value = |t: &Token| -> Result<Val, SceneError> {
            Ok(match &t.tok {
                Tok::Num(v) => Val::Num(*v),
                Tok::Str(s) => Val::Str(s.clone()),
                Tok::Word(w) if w == "true" => Val::Bool(true),
                Tok::Word(w) if w == "false" => Val::Bool(false),
                _ => {
                    return Err(SceneError::new(
                        file,
                        t.line,
                        name,
                        format!("parameter \"{ty} {name}\" has no value"),
                    ))
                }
            })
        };
        match toks.get(*i) {
            Some(Token { tok: Tok::Open, .. }) => {
                *i += 1;
                loop {
                    match toks.get(*i) {
                        Some(Token {
                            tok: Tok::Close, ..
                        }) => break,
                        Some(t) => values.push(value(t)?),
                        None => {
                            return Err(SceneError::new(
                                file,
                                line,
                                name,
                                "the list of values is not closed with ]".into(),
                            ))
                        }
                    }
                    *i += 1;
                }
                *i += 1;
            }
            Some(t) => {
                values.push(value(t)?);
                *i += 1;
            }
            None => {
                return Err(SceneError::new(
                    file,
                    line,
                    name,
                    format!("parameter \"{ty} {name}\" has no value"),
                ))
            }
        }
        if out.iter().any(|p| p.name == name) {
            return Err(SceneError::new(
                file,
                line,
                name,
                format!("parameter `{name}` is given twice"),
            ));
        }
        out.push(Param {
            ty: ty.to_string(),
            name: name.to_string(),
            values,
            line,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_keep_their_lines_and_params_their_values() {
        let text = b"Shape \"sphere\" # c\n  \"float radius\" [ 2.5 ]\n \"bool x\" true \"string s\" \"a b\"";
        let t = tokens(text, Path::new("f")).unwrap();
        assert_eq!(
            t[0],
            Token {
                tok: Tok::Word("Shape".into()),
                line: 1
            }
        );
        let mut i = 2;
        let p = params(&t, &mut i, Path::new("f")).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!((p[0].line, &p[0].values), (2, &vec![Val::Num(2.5)]));
        assert_eq!(p[1].values, vec![Val::Bool(true)]);
        assert_eq!(p[2].values, vec![Val::Str("a b".into())]);
        let e = tokens(b"A \"open\n", Path::new("f")).unwrap_err();
        assert_eq!(e.line, 1);
        let e = tokens(b"\n1.2.3", Path::new("f")).unwrap_err();
        assert_eq!(e.line, 2);
    }
}

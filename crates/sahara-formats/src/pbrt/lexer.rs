//! The tokens of a pbrt file: bare words (directives, numbers, `true` /
//! `false`), quoted strings and brackets, each with its 1-based line and
//! column; `#` starts a comment that runs to the end of the line.

use std::sync::Arc;

use sahara_readers::FormatError;

use crate::common::position::Loc;

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum TokenKind {
    /// A bare word: a directive name, a number, `true` or `false`.
    Word(String),
    /// A quoted string, escapes resolved.
    Str(String),
    /// `[`.
    Open,
    /// `]`.
    Close,
}

/// A token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    /// The token.
    pub(crate) kind: TokenKind,
    /// Its first character.
    pub(crate) loc: Loc,
}

/// Splits one file's bytes into tokens.
pub(crate) struct Lexer {
    bytes: Vec<u8>,
    pos: usize,
    line: u32,
    col: u32,
    file: Arc<str>,
}

impl Lexer {
    /// A lexer over `bytes`, the contents of the file called `file`.
    pub(crate) fn new(bytes: Vec<u8>, file: Arc<str>) -> Self {
        Self {
            bytes,
            pos: 0,
            line: 1,
            col: 1,
            file,
        }
    }

    fn loc(&self) -> Loc {
        Loc {
            file: self.file.clone(),
            line: self.line,
            col: self.col,
        }
    }

    fn bump(&mut self) -> Option<u8> {
        let b = *self.bytes.get(self.pos)?;
        self.pos += 1;
        if b == b'\n' {
            self.line = self.line.saturating_add(1);
            self.col = 1;
        } else if b & 0xC0 != 0x80 {
            // Continuation bytes of UTF-8 do not start a column.
            self.col = self.col.saturating_add(1);
        }
        Some(b)
    }

    fn peek_byte(&self) -> Option<u8> {
        self.bytes.get(self.pos).copied()
    }

    /// The next token, or `None` at the end of the file.
    pub(crate) fn next_token(&mut self) -> Result<Option<Token>, FormatError> {
        loop {
            match self.peek_byte() {
                None => return Ok(None),
                Some(b'#') => {
                    while let Some(b) = self.peek_byte() {
                        if b == b'\n' {
                            break;
                        }
                        self.bump();
                    }
                }
                Some(b) if b.is_ascii_whitespace() => {
                    self.bump();
                }
                Some(_) => break,
            }
        }
        let loc = self.loc();
        let b = self.bump().expect("peeked");
        let kind = match b {
            b'[' => TokenKind::Open,
            b']' => TokenKind::Close,
            b'"' => TokenKind::Str(self.string(&loc)?),
            _ => {
                let start = self.pos - 1;
                while let Some(c) = self.peek_byte() {
                    if c.is_ascii_whitespace() || matches!(c, b'[' | b']' | b'"' | b'#') {
                        break;
                    }
                    self.bump();
                }
                TokenKind::Word(String::from_utf8_lossy(&self.bytes[start..self.pos]).into_owned())
            }
        };
        Ok(Some(Token { kind, loc }))
    }

    /// The rest of a quoted string whose opening quote was read at `loc`.
    fn string(&mut self, loc: &Loc) -> Result<String, FormatError> {
        let mut out = Vec::new();
        loop {
            match self.bump() {
                None => return Err(loc.error("the string starting here is not closed")),
                Some(b'\n') => {
                    return Err(loc.error("the string starting here runs past the end of its line"))
                }
                Some(b'"') => break,
                Some(b'\\') => {
                    let at = self.loc();
                    let c = match self.bump() {
                        Some(b'n') => b'\n',
                        Some(b't') => b'\t',
                        Some(b'r') => b'\r',
                        Some(b'b') => 8,
                        Some(b'f') => 12,
                        Some(c @ (b'\\' | b'"' | b'\'')) => c,
                        Some(c) => {
                            return Err(at.error(format!(
                                "unknown escape '\\{}' in a string",
                                char::from(c).escape_default()
                            )))
                        }
                        None => return Err(loc.error("the string starting here is not closed")),
                    };
                    out.push(c);
                }
                Some(c) => out.push(c),
            }
        }
        Ok(String::from_utf8_lossy(&out).into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Result<Vec<(TokenKind, u32, u32)>, FormatError> {
        let mut l = Lexer::new(text.as_bytes().to_vec(), "t.pbrt".into());
        let mut out = Vec::new();
        while let Some(t) = l.next_token()? {
            out.push((t.kind, t.loc.line, t.loc.col));
        }
        Ok(out)
    }

    #[test]
    fn words_strings_brackets_and_comments_with_positions() {
        let t = tokens("Shape \"sphere\" # a comment [\n  \"float radius\" [2.5]#x\n\"a\\\"b\"")
            .unwrap();
        let w = |s: &str| TokenKind::Word(s.into());
        let s = |s: &str| TokenKind::Str(s.into());
        assert_eq!(
            t,
            vec![
                (w("Shape"), 1, 1),
                (s("sphere"), 1, 7),
                (s("float radius"), 2, 3),
                (TokenKind::Open, 2, 18),
                (w("2.5"), 2, 19),
                (TokenKind::Close, 2, 22),
                (s("a\"b"), 3, 1),
            ]
        );
    }

    #[test]
    fn unclosed_string_and_bad_escape_are_errors_at_their_place() {
        let e = tokens("Shape\n  \"sphere").unwrap_err().to_string();
        assert_eq!(
            e,
            "t.pbrt: line 2: column 3: the string starting here is not closed"
        );
        let e = tokens("\"ab\ncd\"").unwrap_err().to_string();
        assert!(e.starts_with("t.pbrt: line 1: column 1: "), "{e}");
        let e = tokens("  \"a\\q\"").unwrap_err().to_string();
        assert_eq!(
            e,
            "t.pbrt: line 1: column 6: unknown escape '\\q' in a string"
        );
    }
}

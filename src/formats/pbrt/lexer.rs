//! Tokens of a pbrt-v4 file: bare words (directives, `true`, `false`), quoted strings,
//! numbers and brackets, each with its line. `#` starts a comment to the end of the line.

use crate::error::{Result, invalid_arg};

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Token<'a> {
    Word(&'a str),
    Str(String),
    Num(f64),
    Open,
    Close,
}

/// A token and the line it starts on (1-based).
pub(super) type Located<'a> = (Token<'a>, u32);

/// Reads tokens one at a time; errors name `origin` and the line.
pub(super) struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: u32,
    origin: &'a str,
    peeked: Option<Located<'a>>,
}

impl<'a> Lexer<'a> {
    pub(super) fn new(text: &'a str, origin: &'a str) -> Self {
        Lexer {
            text,
            pos: 0,
            line: 1,
            origin,
            peeked: None,
        }
    }

    pub(super) fn origin(&self) -> &'a str {
        self.origin
    }

    /// The line of the last token read (or of the end of the file).
    pub(super) fn line(&self) -> u32 {
        self.line
    }

    pub(super) fn error(&self, line: u32, message: impl std::fmt::Display) -> crate::Error {
        invalid_arg!("{}:{line}: {message}", self.origin)
    }

    pub(super) fn peek(&mut self) -> Result<Option<&Located<'a>>> {
        if self.peeked.is_none() {
            self.peeked = self.scan()?;
        }
        Ok(self.peeked.as_ref())
    }

    pub(super) fn next_token(&mut self) -> Result<Option<Located<'a>>> {
        match self.peeked.take() {
            Some(t) => Ok(Some(t)),
            None => self.scan(),
        }
    }

    fn scan(&mut self) -> Result<Option<Located<'a>>> {
        let bytes = self.text.as_bytes();
        loop {
            match bytes.get(self.pos) {
                None => return Ok(None),
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                Some(b'#') => {
                    self.pos = self.text[self.pos..]
                        .find('\n')
                        .map_or(self.text.len(), |i| self.pos + i);
                }
                Some(_) => break,
            }
        }
        let line = self.line;
        let start = self.pos;
        let token = match bytes[start] {
            b'[' => {
                self.pos += 1;
                Token::Open
            }
            b']' => {
                self.pos += 1;
                Token::Close
            }
            b'"' => Token::Str(self.string(line)?),
            c if c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.') => {
                let word = self.word();
                let value: f64 = word
                    .parse()
                    .map_err(|_| self.error(line, format_args!("{word:?} is not a number")))?;
                if !value.is_finite() {
                    return Err(self.error(line, format_args!("{word} is not a finite number")));
                }
                Token::Num(value)
            }
            c if c.is_ascii_alphabetic() => Token::Word(self.word()),
            _ => {
                let c = self.text[start..].chars().next().unwrap_or('?');
                return Err(self.error(line, format_args!("unexpected character {c:?}")));
            }
        };
        Ok(Some((token, line)))
    }

    /// A run of characters up to whitespace, a bracket, a quote or a comment.
    fn word(&mut self) -> &'a str {
        let rest = &self.text[self.pos..];
        let end = rest
            .find(|c: char| c.is_ascii_whitespace() || matches!(c, '[' | ']' | '"' | '#'))
            .unwrap_or(rest.len());
        self.pos += end;
        &rest[..end]
    }

    /// A quoted string, the opening quote at `pos`; escapes as in C.
    fn string(&mut self, line: u32) -> Result<String> {
        let mut out = String::new();
        let mut chars = self.text[self.pos + 1..].char_indices();
        while let Some((i, c)) = chars.next() {
            match c {
                '"' => {
                    self.pos += 1 + i + 1;
                    return Ok(out);
                }
                '\n' => break,
                '\\' => {
                    let escaped = match chars.next() {
                        Some((_, 'n')) => '\n',
                        Some((_, 't')) => '\t',
                        Some((_, 'b')) => '\u{8}',
                        Some((_, 'f')) => '\u{c}',
                        Some((_, 'r')) => '\r',
                        Some((_, c @ ('\\' | '\'' | '"'))) => c,
                        _ => return Err(self.error(line, "unknown escape in a string")),
                    };
                    out.push(escaped);
                }
                c => out.push(c),
            }
        }
        Err(self.error(line, "unterminated string"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Result<Vec<Located<'_>>> {
        let mut lexer = Lexer::new(text, "t.pbrt");
        let mut out = Vec::new();
        while let Some(t) = lexer.next_token()? {
            out.push(t);
        }
        Ok(out)
    }

    #[test]
    fn tokens_carry_their_lines() {
        let t =
            tokens("Shape \"curve\" # a comment [ 1\n  \"point3 P\" [ -1.5e1 .5 +2 ]\n").unwrap();
        assert_eq!(
            t,
            vec![
                (Token::Word("Shape"), 1),
                (Token::Str("curve".into()), 1),
                (Token::Str("point3 P".into()), 2),
                (Token::Open, 2),
                (Token::Num(-15.0), 2),
                (Token::Num(0.5), 2),
                (Token::Num(2.0), 2),
                (Token::Close, 2),
            ]
        );
    }

    #[test]
    fn bad_tokens_name_the_line() {
        for (text, message) in [
            ("\n\"open", "t.pbrt:2: unterminated string"),
            ("\n\n1e999", "t.pbrt:3: 1e999 is not a finite number"),
            ("1.2.3", "t.pbrt:1: \"1.2.3\" is not a number"),
            ("\n@", "t.pbrt:2: unexpected character '@'"),
            ("\"a\\q\"", "t.pbrt:1: unknown escape in a string"),
        ] {
            let e = tokens(text).unwrap_err().to_string();
            assert!(e.ends_with(message), "{text:?}: {e}");
        }
        // NaN and infinity can only be spelt as words, which are never numbers.
        assert_eq!(tokens("nan").unwrap(), vec![(Token::Word("nan"), 1)]);
    }
}

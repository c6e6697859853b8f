//! A cursor over the bytes of a text (or mixed text/binary) mesh file:
//! whitespace-separated tokens, `#` comments, numbers parsed without
//! allocating, and errors that carry the file and line.
//!
//! Line numbers are not tracked while parsing (that would cost on every
//! byte); an error computes its line by counting the newlines before it.

use std::path::Path;

use crate::error::{Error, ErrorKind, Location};

/// How many bytes of an offending token an error message quotes.
const QUOTE: usize = 40;

pub(crate) struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    path: &'a Path,
    /// The byte that starts a comment running to the end of the line.
    comment: Option<u8>,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(data: &'a [u8], path: &'a Path, comment: Option<u8>) -> Self {
        Self {
            data,
            pos: 0,
            path,
            comment,
        }
    }

    /// The file the data comes from.
    pub(crate) fn path(&self) -> &'a Path {
        self.path
    }

    /// The current byte offset.
    pub(crate) fn offset(&self) -> usize {
        self.pos
    }

    /// Bytes not yet consumed.
    pub(crate) fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// An error located at byte `offset`, reported by line.
    pub(crate) fn error_at(&self, offset: usize, kind: ErrorKind) -> Error {
        let offset = offset.min(self.data.len());
        let line = 1 + self.data[..offset].iter().filter(|&&b| b == b'\n').count();
        Error {
            path: self.path.to_path_buf(),
            location: Some(Location::Line(line)),
            kind,
        }
    }

    /// An error located at a byte offset of a binary section.
    pub(crate) fn error_at_byte(&self, offset: usize, kind: ErrorKind) -> Error {
        Error {
            path: self.path.to_path_buf(),
            location: Some(Location::Byte(offset)),
            kind,
        }
    }

    /// A syntax error at `offset` quoting `found`.
    pub(crate) fn syntax(&self, offset: usize, expected: &str, found: &[u8]) -> Error {
        let shown = &found[..found.len().min(QUOTE)];
        self.error_at(
            offset,
            ErrorKind::Syntax {
                expected: expected.to_string(),
                found: String::from_utf8_lossy(shown).into_owned(),
            },
        )
    }

    /// Skips whitespace and comments.
    #[inline]
    pub(crate) fn skip_space(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if b.is_ascii_whitespace() {
                self.pos += 1;
            } else if Some(b) == self.comment {
                while self.pos < self.data.len() && self.data[self.pos] != b'\n' {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    /// Whether only whitespace and comments are left.
    pub(crate) fn at_end(&mut self) -> bool {
        self.skip_space();
        self.pos == self.data.len()
    }

    /// The next token and its offset, or `None` at the end.
    #[inline]
    pub(crate) fn token(&mut self) -> Option<(usize, &'a [u8])> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.data.len() && !self.data[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| (start, &self.data[start..self.pos]))
    }

    /// The next token, or a truncation error naming what was expected.
    #[inline]
    pub(crate) fn expect_token(&mut self, what: &str) -> Result<(usize, &'a [u8]), Error> {
        match self.token() {
            Some(t) => Ok(t),
            None => Err(self.error_at(self.pos, ErrorKind::Truncated(what.to_string()))),
        }
    }

    /// The next token, which must be `word` (compared ignoring ASCII case).
    pub(crate) fn keyword(&mut self, word: &str) -> Result<(), Error> {
        let (at, tok) = self.expect_token(word)?;
        if tok.eq_ignore_ascii_case(word.as_bytes()) {
            Ok(())
        } else {
            Err(self.syntax(at, word, tok))
        }
    }

    /// The next token as a signed integer.
    #[inline]
    pub(crate) fn i64(&mut self, what: &str) -> Result<i64, Error> {
        let (at, tok) = self.expect_token(what)?;
        parse_i64(tok).ok_or_else(|| self.syntax(at, what, tok))
    }

    /// The next token as a non-negative integer.
    #[inline]
    pub(crate) fn u64(&mut self, what: &str) -> Result<u64, Error> {
        let (at, tok) = self.expect_token(what)?;
        match parse_i64(tok) {
            Some(v) if v >= 0 => Ok(v as u64),
            _ => Err(self.syntax(at, what, tok)),
        }
    }

    /// The next token as a floating-point number (any Rust `f64` syntax,
    /// including exponents; `nan` and `inf` parse, callers reject them).
    #[inline]
    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, Error> {
        let (at, tok) = self.expect_token(what)?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or_else(|| self.syntax(at, what, tok))
    }

    /// Three coordinates of node `index`, which must be finite.
    pub(crate) fn point(&mut self, index: usize) -> Result<glam::DVec3, Error> {
        self.skip_space();
        let at = self.pos;
        let p = glam::DVec3::new(
            self.f64("an x coordinate")?,
            self.f64("a y coordinate")?,
            self.f64("a z coordinate")?,
        );
        match p.to_array().into_iter().find(|v| !v.is_finite()) {
            None => Ok(p),
            Some(value) => Err(self.error_at(at, ErrorKind::NonFinite { index, value })),
        }
    }

    /// Checks that `declared` records of at least `min_bytes` each can fit in
    /// what is left, before the caller allocates for them.
    pub(crate) fn check_count(
        &self,
        what: &'static str,
        declared: u64,
        min_bytes: usize,
    ) -> Result<usize, Error> {
        let bytes_left = self.remaining();
        let fit = (bytes_left / min_bytes.max(1)) as u64;
        if declared > fit {
            return Err(self.error_at(
                self.pos,
                ErrorKind::CountTooLarge {
                    what,
                    declared,
                    bytes_left,
                    fit,
                },
            ));
        }
        Ok(declared as usize)
    }

    /// Skips to just after the next newline (or to the end).
    pub(crate) fn skip_line(&mut self) {
        while self.pos < self.data.len() {
            self.pos += 1;
            if self.data[self.pos - 1] == b'\n' {
                break;
            }
        }
    }

    /// The next `n` raw bytes (binary sections).
    pub(crate) fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Error> {
        if self.remaining() < n {
            return Err(self.error_at_byte(self.pos, ErrorKind::Truncated(what.to_string())));
        }
        let bytes = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(bytes)
    }
}

/// Parses an optionally signed decimal integer; `None` on anything else or
/// on overflow.
#[inline]
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    let (negative, digits) = match tok.first()? {
        b'-' => (true, &tok[1..]),
        b'+' => (false, &tok[1..]),
        _ => (false, tok),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &b in digits {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d))?;
    }
    Some(if negative { -value } else { value })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers() {
        assert_eq!(parse_i64(b"0"), Some(0));
        assert_eq!(parse_i64(b"-12"), Some(-12));
        assert_eq!(parse_i64(b"+7"), Some(7));
        assert_eq!(parse_i64(b"9223372036854775807"), Some(i64::MAX));
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"1.0"), None);
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b""), None);
    }

    #[test]
    fn tokens_comments_and_lines() {
        let data = b"# header\n 3 4.5e1 # tail\n\nx";
        let path = Path::new("t.node");
        let mut c = Cursor::new(data, path, Some(b'#'));
        assert_eq!(c.u64("a count").unwrap(), 3);
        assert_eq!(c.f64("a coordinate").unwrap(), 45.0);
        let err = c.f64("a coordinate").unwrap_err();
        assert_eq!(err.location, Some(Location::Line(4)));
        assert_eq!(
            err.to_string(),
            "t.node: line 4: expected a coordinate, found \"x\""
        );
        assert!(c.at_end());
        let err = c.u64("a count").unwrap_err();
        assert!(matches!(err.kind, ErrorKind::Truncated(_)));
    }

    #[test]
    fn counts_are_checked_against_the_bytes_left() {
        let data = b"1000000000 1 2 3";
        let path = Path::new("t.ele");
        let mut c = Cursor::new(data, path, None);
        let n = c.u64("a count").unwrap();
        let err = c.check_count("tetrahedra", n, 10).unwrap_err();
        assert!(matches!(err.kind, ErrorKind::CountTooLarge { fit: 0, .. }));
    }
}

//! Helpers shared by the text readers and writers: numbered lines, number tokens, and
//! shortest round-tripping float output.

use std::path::Path;

use crate::error::{Error, ErrorKind};

/// Iterates over the lines of a byte buffer with 1-based line numbers. Handles `\n`, `\r\n`
/// and lone `\r` endings. Lines are returned without their ending.
pub(crate) struct NumberedLines<'a> {
    rest: &'a [u8],
    line: u64,
}

impl<'a> NumberedLines<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self {
            rest: bytes,
            line: 0,
        }
    }

    /// The 1-based number of the last line returned (0 before the first).
    #[allow(dead_code)]
    pub(crate) fn line(&self) -> u64 {
        self.line
    }

    /// The bytes not yet returned.
    #[allow(dead_code)]
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.rest
    }
}

impl<'a> Iterator for NumberedLines<'a> {
    type Item = (u64, &'a [u8]);

    fn next(&mut self) -> Option<Self::Item> {
        if self.rest.is_empty() {
            return None;
        }
        self.line += 1;
        let end = self
            .rest
            .iter()
            .position(|&c| c == b'\n' || c == b'\r')
            .unwrap_or(self.rest.len());
        let line = &self.rest[..end];
        let mut skip = end;
        if skip < self.rest.len() {
            skip += if self.rest[skip] == b'\r' && self.rest.get(skip + 1) == Some(&b'\n') {
                2
            } else {
                1
            };
        }
        self.rest = &self.rest[skip..];
        Some((self.line, line))
    }
}

/// Splits a line into whitespace-separated tokens.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|c| c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

/// Parses a float token. Accepts what Rust's `f64::from_str` accepts (including `nan`, `inf`);
/// callers check finiteness and report [`ErrorKind::NonFinite`] themselves.
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

/// Parses a signed integer token.
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    std::str::from_utf8(tok).ok()?.parse::<i64>().ok()
}

/// A syntax error at a line, quoting the offending token (shortened).
pub(crate) fn syntax(path: &Path, line: u64, what: &str, tok: &[u8]) -> Error {
    let shown = String::from_utf8_lossy(&tok[..tok.len().min(40)]).into_owned();
    Error::at_line(
        path,
        line,
        ErrorKind::Syntax(format!("{what}: `{shown}`")),
    )
}

/// Appends the shortest decimal that parses back to exactly `v`.
pub(crate) fn push_f64(out: &mut Vec<u8>, v: f64) {
    if v == 0.0 {
        out.push(b'0');
        return;
    }
    let mut buf = ryu::Buffer::new();
    let s = buf.format(v);
    out.extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_endings() {
        let v: Vec<_> = NumberedLines::new(b"a\r\nb\rc\n\nd").collect();
        assert_eq!(
            v,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b"c"[..]),
                (4, &b""[..]),
                (5, &b"d"[..])
            ]
        );
    }

    #[test]
    fn floats_round_trip() {
        for v in [0.1, -1.0 / 3.0, 1e-300, 6.02e23, 12.5, -0.0, f64::MIN_POSITIVE] {
            let mut out = Vec::new();
            push_f64(&mut out, v);
            let back = parse_f64(&out).unwrap();
            assert_eq!(back, v, "{}", String::from_utf8_lossy(&out));
        }
    }
}

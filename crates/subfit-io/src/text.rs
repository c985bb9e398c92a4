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

/// A syntax error at a line, quoting the offending token (shortened). A token that is not
/// UTF-8 text is shown lossily and said to be so (binary data read as text).
pub(crate) fn syntax(path: &Path, line: u64, what: &str, tok: &[u8]) -> Error {
    let cut = &tok[..tok.len().min(40)];
    let shown = String::from_utf8_lossy(cut).into_owned();
    let note = if std::str::from_utf8(tok).is_err() {
        " (bytes that are not UTF-8 text: is this a binary file?)"
    } else {
        ""
    };
    Error::at_line(
        path,
        line,
        ErrorKind::Syntax(format!("{what}: `{shown}`{note}")),
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

/// The 1-based line that byte offset `at` lies on, counting line endings as [`NumberedLines`]
/// does (`\n`, `\r\n`, lone `\r`). Cost: O(at).
pub(crate) fn line_of(bytes: &[u8], at: usize) -> u64 {
    let head = &bytes[..at.min(bytes.len())];
    let mut line = 1;
    for (i, &c) in head.iter().enumerate() {
        if c == b'\n' || (c == b'\r' && bytes.get(i + 1) != Some(&b'\n')) {
            line += 1;
        }
    }
    line
}

/// Checks that a text file is valid UTF-8; otherwise a syntax error at the line of the first
/// invalid byte. Cost: O(file size), done once per file so that token parsing can rely on it.
pub(crate) fn check_utf8(bytes: &[u8], path: &Path) -> Result<(), Error> {
    match std::str::from_utf8(bytes) {
        Ok(_) => Ok(()),
        Err(e) => {
            let at = e.valid_up_to();
            let bad = &bytes[at..bytes.len().min(at + 4)];
            Err(Error::at_line(
                path,
                line_of(bytes, at),
                ErrorKind::Syntax(format!(
                    "not UTF-8 text (byte {at}: {bad:02x?}); is this a binary file?"
                )),
            ))
        }
    }
}

/// Parses a float token that must be finite: a [`ErrorKind::Syntax`] error quoting the token
/// when it is not a number, [`ErrorKind::NonFinite`] when it is NaN or infinite. `what` names
/// the value in messages (`vertex coordinate`, `normal component`…).
pub(crate) fn finite_f64(tok: &[u8], path: &Path, line: u64, what: &str) -> Result<f64, Error> {
    match parse_f64(tok) {
        Some(v) if v.is_finite() => Ok(v),
        Some(_) => Err(Error::at_line(
            path,
            line,
            ErrorKind::NonFinite(format!("{what} `{}`", String::from_utf8_lossy(tok))),
        )),
        None => Err(syntax(
            path,
            line,
            &format!("expected a number ({what})"),
            tok,
        )),
    }
}

/// Cuts a line at the first `#` (the comment character of OBJ, OFF and XYZ).
pub(crate) fn strip_hash_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&c| c == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Appends an unsigned integer in decimal.
pub(crate) fn push_u64(out: &mut Vec<u8>, mut v: u64) {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.extend_from_slice(&buf[i..]);
}

/// An 8-bit colour channel from a float in 0..1 (clamped, rounded to nearest).
pub(crate) fn unit_to_u8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Like [`push_f64`], but keeps the sign of zero (`-0`), so that every finite f64 reads back
/// bit for bit.
pub(crate) fn push_f64_exact(out: &mut Vec<u8>, v: f64) {
    if v == 0.0 && v.is_sign_negative() {
        out.extend_from_slice(b"-0");
    } else {
        push_f64(out, v);
    }
}

/// Parses a signed integer token like [`parse_i64`] (same accepted syntax and results), with a
/// fast path for the short decimal tokens that face indices are.
pub(crate) fn parse_int(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.first() {
        Some(b'-') => (true, &tok[1..]),
        Some(b'+') => (false, &tok[1..]),
        _ => (false, tok),
    };
    if digits.is_empty() || digits.len() > 18 {
        return parse_i64(tok);
    }
    let mut v: i64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (c - b'0') as i64;
    }
    Some(if neg { -v } else { v })
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
    fn fast_integers_agree_with_std() {
        for t in [
            "0",
            "-0",
            "+7",
            "-",
            "+",
            "",
            "12a",
            "999999999999999999",
            "-999999999999999999",
            "9223372036854775807",
            "-9223372036854775808",
            "9223372036854775808",
            " 1",
            "1.0",
            "+-1",
            "--1",
        ] {
            assert_eq!(parse_int(t.as_bytes()), parse_i64(t.as_bytes()), "{t:?}");
        }
    }

    #[test]
    fn floats_round_trip() {
        for v in [
            0.1,
            -1.0 / 3.0,
            1e-300,
            6.02e23,
            12.5,
            -0.0,
            f64::MIN_POSITIVE,
        ] {
            let mut out = Vec::new();
            push_f64(&mut out, v);
            let back = parse_f64(&out).unwrap();
            assert_eq!(back, v, "{}", String::from_utf8_lossy(&out));
        }
    }
}

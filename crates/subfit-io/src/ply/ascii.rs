//! The ascii record decoder.

use std::path::Path;

use super::header::{Element, Header, Property, Slot, Ty};
use super::sink::{set_color, Record, Sink};
use crate::error::{Error, ErrorKind, Result};
use crate::text::{parse_f64, parse_i64, tokens, NumberedLines};

pub(super) fn read_ascii(h: &Header, data: &[u8], path: &Path, sink: &mut Sink) -> Result<()> {
    let mut lines = NumberedLines::new(data);
    let mut rec = Record::default();
    let mut last_line = h.lines;
    for el in &h.elements {
        if el.props.is_empty() {
            continue;
        }
        // Every ascii value takes at least two bytes (digit and separator).
        let room = data.len() / (2 * el.props.len());
        sink.reserve(el.role, (el.count.min(room as u64)) as usize);
        for index in 0..el.count {
            let (line, text) = loop {
                match lines.next() {
                    None => {
                        return Err(Error::at_line(
                            path,
                            last_line + 1,
                            ErrorKind::Truncated(format!(
                                "{} {index} is missing (the header declares {})",
                                el.name, el.count
                            )),
                        ))
                    }
                    Some((n, t)) if t.iter().all(|c| c.is_ascii_whitespace()) => {
                        last_line = h.lines + n;
                    }
                    Some((n, t)) => break (h.lines + n, t),
                }
            };
            last_line = line;
            ascii_record(el, index, line, text, path, &mut rec)?;
            sink.finish(el.role, &rec, index)
                .map_err(|k| Error::at_line(path, line, k))?;
        }
    }
    Ok(())
}

/// Decodes one ascii element line into `rec`.
fn ascii_record(
    el: &Element,
    index: u64,
    line: u64,
    text: &[u8],
    path: &Path,
    rec: &mut Record,
) -> Result<()> {
    let mut toks = tokens(text);
    rec.nan_color = false;
    let name = &el.name;
    let missing = |p: &Property| {
        Error::at_line(
            path,
            line,
            ErrorKind::Syntax(format!(
                "{name} {index}: no value for property `{}` (the line ends early)",
                p.name
            )),
        )
    };
    for (p, &slot) in el.props.iter().zip(&el.slots) {
        match p.ty {
            Ty::Scalar(s) => {
                let tok = toks.next().ok_or_else(|| missing(p))?;
                if slot == Slot::Skip {
                    continue;
                }
                let v = parse_f64(tok).ok_or_else(|| {
                    crate::text::syntax(
                        path,
                        line,
                        &format!("{name} {index}: `{}` is not a number", p.name),
                        tok,
                    )
                })?;
                match slot {
                    Slot::Coord(k) => rec.p[k] = v,
                    Slot::Normal(k) => rec.n[k] = v,
                    Slot::Color(k) => set_color(rec, k, v, s),
                    Slot::Skip | Slot::Indices => {}
                }
            }
            Ty::List(_, _) => {
                let tok = toks.next().ok_or_else(|| missing(p))?;
                let n = ascii_int(tok).ok_or_else(|| {
                    crate::text::syntax(
                        path,
                        line,
                        &format!(
                            "{name} {index}: list count of `{}` is not an integer",
                            p.name
                        ),
                        tok,
                    )
                })?;
                if n < 0 {
                    return Err(Error::at_line(
                        path,
                        line,
                        ErrorKind::BadCount(format!(
                            "{name} {index}: negative list count {n} for `{}`",
                            p.name
                        )),
                    ));
                }
                let short = |got: i64| {
                    Error::at_line(
                        path,
                        line,
                        ErrorKind::BadCount(format!(
                            "{name} {index}: list `{}` announces {n} values but the line holds {got}",
                            p.name
                        )),
                    )
                };
                if slot == Slot::Indices {
                    rec.list.clear();
                    for got in 0..n {
                        let tok = toks.next().ok_or_else(|| short(got))?;
                        let v = ascii_int(tok).ok_or_else(|| {
                            crate::text::syntax(
                                path,
                                line,
                                &format!("{name} {index}: vertex index is not an integer"),
                                tok,
                            )
                        })?;
                        rec.list.push(v);
                    }
                } else {
                    for got in 0..n {
                        toks.next().ok_or_else(|| short(got))?;
                    }
                }
            }
        }
    }
    if toks.next().is_some() {
        return Err(Error::at_line(
            path,
            line,
            ErrorKind::Syntax(format!(
                "{name} {index}: more values than the header declares"
            )),
        ));
    }
    Ok(())
}

/// An integer token; also accepts integral floats such as `3.0`, which some writers emit.
fn ascii_int(tok: &[u8]) -> Option<i64> {
    parse_i64(tok).or_else(|| {
        let v = parse_f64(tok)?;
        (v.fract() == 0.0 && v.abs() < 9.0e15).then_some(v as i64)
    })
}

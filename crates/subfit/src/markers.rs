//! Marker files of a sequence (`subfit sequence --markers FILE`): where known points are in
//! each frame ([`crate::TrackingOptions::markers`]), one observation a line of CSV:
//!
//! ```text
//! frame,marker,x,y,z
//! 0,LKNE,0.12,-0.40,0.83
//! 1,LKNE,0.13,-0.41,0.84
//! ```
//!
//! The header is required (spaces around fields and its case do not matter); `frame` is the
//! frame's index in the order the frames are given, 0 the first; `marker` a name (no comma);
//! `x,y,z` the position in the frames' units. Blank lines and lines starting with `#` are
//! skipped. A marker missing from a frame is not used there (occluded). Errors name the file
//! and the line.

use std::path::Path;

use crate::sequence_tracking::MarkerObservation;
use crate::Error;

/// The header's fields.
const HEADER: [&str; 5] = ["frame", "marker", "x", "y", "z"];

/// Reads a marker file (see the module docs). Errors: unreadable file, missing or wrong
/// header, a line without five fields, a frame that is not a whole number, a coordinate that
/// is not a finite number, an empty name; each with the file and the line. Cost: O(file).
pub fn read_markers(path: &Path) -> Result<Vec<MarkerObservation>, Error> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::input(&name, format_args!("cannot read the marker file: {e}")))?;
    parse_markers(&text, &name)
}

/// [`read_markers`] of a file's text; `name` names it in errors.
pub fn parse_markers(text: &str, name: &str) -> Result<Vec<MarkerObservation>, Error> {
    let at = |line: usize, m: String| Error::input(&format!("{name}:{line}"), m);
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((line, header)) = rows.next() else {
        return Err(Error::input(
            name,
            "the marker file is empty: expected the header frame,marker,x,y,z",
        ));
    };
    let fields: Vec<String> = header
        .split(',')
        .map(|f| f.trim().to_ascii_lowercase())
        .collect();
    if fields != HEADER {
        return Err(at(
            line,
            format!("expected the header frame,marker,x,y,z, got {header:?}"),
        ));
    }
    let mut out = Vec::new();
    for (line, row) in rows {
        let f: Vec<&str> = row.split(',').map(str::trim).collect();
        if f.len() != 5 {
            return Err(at(
                line,
                format!(
                    "expected 5 fields (frame,marker,x,y,z), got {}: {row:?}",
                    f.len()
                ),
            ));
        }
        let frame: usize = f[0].parse().map_err(|_| {
            at(
                line,
                format!("the frame must be a whole number ≥ 0, got {:?}", f[0]),
            )
        })?;
        if f[1].is_empty() {
            return Err(at(line, "the marker's name is empty".into()));
        }
        let mut position = [0.0; 3];
        for (a, (v, axis)) in position.iter_mut().zip(f[2..].iter().zip(["x", "y", "z"])) {
            *a = v
                .parse::<f64>()
                .ok()
                .filter(|c| c.is_finite())
                .ok_or_else(|| at(line, format!("{axis} must be a finite number, got {v:?}")))?;
        }
        out.push(MarkerObservation {
            frame,
            marker: f[1].to_string(),
            position,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_marker_file_is_read() {
        let text = "# knee markers\n Frame, Marker, X, Y, Z \n0,LKNE,0.1,-0.4,0.8\n\n1,LKNE,0.2,-0.4,0.9\n";
        let m = parse_markers(text, "m.csv").unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].frame, 1);
        assert_eq!(m[1].marker, "LKNE");
        assert_eq!(m[1].position, [0.2, -0.4, 0.9]);
    }

    #[test]
    fn bad_marker_files_name_the_line() {
        for (text, says) in [
            ("", "empty"),
            ("frame,x,y,z\n", "m.csv:1: expected the header"),
            (
                "frame,marker,x,y,z\n0,a,1,2\n",
                "m.csv:2: expected 5 fields",
            ),
            (
                "frame,marker,x,y,z\n-1,a,1,2,3\n",
                "m.csv:2: the frame must be",
            ),
            (
                "frame,marker,x,y,z\n0,a,1,nan,3\n",
                "m.csv:2: y must be a finite",
            ),
            (
                "frame,marker,x,y,z\n0,,1,2,3\n",
                "m.csv:2: the marker's name is empty",
            ),
        ] {
            let err = parse_markers(text, "m.csv").unwrap_err().to_string();
            assert!(err.contains(says), "{text:?}: {err}");
        }
    }
}

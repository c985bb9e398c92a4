//! What the columns after `x y z` of a point list hold, decided from their values.
//!
//! Point lists carry normals, colours, intensity and alpha after the coordinates in several
//! orders, with nothing in the file to say which (`x y z nx ny nz` from normal estimators,
//! `x y z r g b` from photogrammetry, `x y z r g b a` from CloudCompare, `x y z i r g b` in Leica
//! PTS). The values tell them apart:
//!
//! 1. **Normals** are three columns whose rows are unit vectors: | ‖n‖ − 1 | ≤ 0.01 (normals
//!    printed with three significant digits are within 0.5 % of unit length) on at least 90 %
//!    of the rows without a NaN (estimators write zero normals where they found no plane). They
//!    are looked for right after `x y z`, then, on lines of 9 values or more, as the last three.
//! 2. **Colours**, in the columns left, are three columns of integers in 0..=255 (some above 1),
//!    or of values in 0..1 (scaled by 255); NaN values are passed over (they read as 0):
//!    - 3 columns left: `r g b`;
//!    - 4 left: `r g b a` when the fourth holds one opaque alpha (255 or 1) on every row,
//!      otherwise `i r g b`, the Leica PTS order (colours clamped to 0..=255 as PTS writes
//!      them);
//!    - 5 or more left: `r g b` first, when they are colour values.
//! 3. Six values or more with neither unit normals nor colours: columns 4-6 are normals as
//!    written (not normalized), as before this rule existed.
//!
//! Every other column (intensity, confidence, scan index…) is ignored. [`Plan::describe`]
//! says what was decided, for a warning.
//!
//! Cost: O(rows × columns), one pass per candidate group.

use super::table::Table;

/// How colour values map to 8 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scale {
    /// Integers 0..=255 (others clamped and rounded).
    Byte,
    /// Values in 0..1, scaled by 255.
    Unit,
}

impl Scale {
    /// The 8-bit channel of `v` (NaN reads as 0).
    pub(crate) fn to_u8(self, v: f64) -> u8 {
        let v = match self {
            Scale::Byte => v,
            Scale::Unit => v * 255.0,
        };
        // `as` maps NaN to 0.
        v.clamp(0.0, 255.0).round() as u8
    }

    fn name(self) -> &'static str {
        match self {
            Scale::Byte => "integers in 0..255",
            Scale::Unit => "values in 0..1",
        }
    }
}

/// What the columns hold; column indices are 0-based.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Plan {
    /// First column of `nx ny nz`.
    pub(crate) normals: Option<usize>,
    /// Whether those rows are unit vectors (rule 1) or merely the fallback (rule 3).
    normals_unit: bool,
    /// First column of `r g b` and its scale.
    pub(crate) colours: Option<(usize, Scale)>,
    /// An alpha column that was dropped, with its constant value.
    alpha: Option<(usize, f64)>,
    /// An intensity column before the colours (Leica PTS).
    intensity: Option<usize>,
}

/// Relative tolerance on the length of a unit normal, and the share of rows that must have it
/// (see the module documentation for why these values).
const UNIT_TOLERANCE: f64 = 0.01;
const UNIT_SHARE: f64 = 0.9;

/// Whether the rows of columns `a..a + 3` are unit vectors (rule 1); rows holding a NaN are
/// passed over (a NaN normal is an error later, a NaN colour reads as 0).
fn unit_rows(t: &Table, a: usize) -> bool {
    let (mut unit, mut rows) = (0usize, 0usize);
    for i in 0..t.rows() {
        let r = &t.row(i)[a..a + 3];
        if r.iter().any(|v| v.is_nan()) {
            continue;
        }
        rows += 1;
        let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        unit += ((len - 1.0).abs() <= UNIT_TOLERANCE) as usize;
    }
    rows > 0 && unit as f64 >= UNIT_SHARE * rows as f64
}

/// The scale of columns `a..a + 3` if they hold colour values.
fn colour_scale(t: &Table, a: usize) -> Option<Scale> {
    let (mut bytes, mut unit, mut above_one) = (true, true, false);
    for i in 0..t.rows() {
        for &v in &t.row(i)[a..a + 3] {
            if v.is_nan() {
                continue;
            }
            bytes &= (0.0..=255.0).contains(&v) && v.fract() == 0.0;
            unit &= (0.0..=1.0).contains(&v);
            above_one |= v > 1.0;
        }
        if !bytes && !unit {
            return None;
        }
    }
    if unit {
        Some(Scale::Unit)
    } else {
        (bytes && above_one).then_some(Scale::Byte)
    }
}

/// The alpha value of column `a` if every row holds the same opaque one (255 or 1).
fn opaque_alpha(t: &Table, a: usize) -> Option<f64> {
    let v = t.row(0)[a];
    ((v == 255.0 || v == 1.0) && (0..t.rows()).all(|i| t.row(i)[a] == v)).then_some(v)
}

/// Decides what the columns of `t` (at least one row) hold; see the module documentation.
pub(crate) fn decide(t: &Table) -> Plan {
    let cols = t.cols;
    let mut plan = Plan::default();
    if cols >= 6 && unit_rows(t, 3) {
        plan.normals = Some(3);
    } else if cols >= 9 && unit_rows(t, cols - 3) {
        plan.normals = Some(cols - 3);
    }
    plan.normals_unit = plan.normals.is_some();
    let (lo, hi) = match plan.normals {
        Some(3) => (6, cols),
        Some(a) => (3, a),
        None => (3, cols),
    };
    match hi - lo {
        3 => plan.colours = colour_scale(t, lo).map(|s| (lo, s)),
        4 => match (colour_scale(t, lo), opaque_alpha(t, lo + 3)) {
            (Some(s), Some(alpha)) => {
                plan.colours = Some((lo, s));
                plan.alpha = Some((lo + 3, alpha));
            }
            _ => {
                plan.colours = Some((lo + 1, colour_scale(t, lo + 1).unwrap_or(Scale::Byte)));
                plan.intensity = Some(lo);
            }
        },
        m if m >= 5 => plan.colours = colour_scale(t, lo).map(|s| (lo, s)),
        _ => {}
    }
    if plan.normals.is_none() && plan.colours.is_none() && cols >= 6 {
        plan.normals = Some(3);
    }
    plan
}

/// `4-6` for the 0-based columns `a..a + n`.
fn span(a: usize, n: usize) -> String {
    if n == 1 {
        format!("column {}", a + 1)
    } else {
        format!("columns {}-{}", a + 1, a + n)
    }
}

impl Plan {
    /// What was decided, for a warning; `None` for plain `x y z`.
    pub(crate) fn describe(&self, cols: usize) -> Option<String> {
        if cols == 3 {
            return None;
        }
        let mut used = vec![false; cols];
        let mut take = |a: usize, n: usize| used[a..a + n].iter_mut().for_each(|u| *u = true);
        let mut parts = Vec::new();
        if let Some(a) = self.normals {
            take(a, 3);
            parts.push(if self.normals_unit {
                format!("nx ny nz in {} (unit vectors)", span(a, 3))
            } else {
                format!(
                    "nx ny nz in {} (not unit vectors, not colour values: taken as normals \
                     as written)",
                    span(a, 3)
                )
            });
        }
        if let Some(i) = self.intensity {
            take(i, 1);
            parts.push(format!(
                "intensity in {} (ignored; x y z i r g b is the Leica PTS order)",
                span(i, 1)
            ));
        }
        if let Some((a, scale)) = self.colours {
            take(a, 3);
            let not_normals = if self.normals.is_none() && a == 3 {
                ", not unit vectors: colours, not normals"
            } else {
                ""
            };
            parts.push(format!(
                "r g b in {} ({}{not_normals})",
                span(a, 3),
                scale.name()
            ));
        }
        if let Some((a, v)) = self.alpha {
            take(a, 1);
            parts.push(format!("alpha in {} (always {v}, dropped)", span(a, 1)));
        }
        let ignored: Vec<String> = (3..cols)
            .filter(|&c| !used[c])
            .map(|c| (c + 1).to_string())
            .collect();
        if !ignored.is_empty() {
            parts.push(format!("column(s) {} ignored", ignored.join(", ")));
        }
        Some(format!(
            "{cols} values per point: x y z, then {}",
            parts.join("; ")
        ))
    }
}

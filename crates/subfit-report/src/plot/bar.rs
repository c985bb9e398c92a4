//! Horizontal bar charts: one labelled bar per category with its value written at the end,
//! e.g. control points per stage or seconds per phase. Horizontal so that long category names
//! (`"stage 3 (λ = 0.001)"`, `"closest points"`) read without rotation.

use super::frame::{esc, fmt_value, nice_ticks, Frame, COLORS};
use std::fmt::Write as _;

/// One category and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    /// Category name, drawn left of the bar.
    pub label: String,
    /// Value; non-finite values get no bar and the label `n/a`.
    pub value: f64,
}

impl Bar {
    /// A bar from a label and a value.
    pub fn new(label: impl Into<String>, value: f64) -> Self {
        Self {
            label: label.into(),
            value,
        }
    }
}

/// Renders `bars` top to bottom from a zero baseline (negative values extend left), the value
/// axis labelled `value_label` (e.g. `"seconds"`), each value written at its bar's end with
/// three significant digits. The height grows with the number of bars (26 px each); empty
/// input gives an empty frame. Cost `O(#bars)`.
pub fn bar_chart(title: &str, value_label: &str, bars: &[Bar]) -> String {
    let longest = bars
        .iter()
        .map(|b| b.label.chars().count())
        .max()
        .unwrap_or(0);
    let row = 26.0;
    let f = Frame {
        w: 760.0,
        h: (40.0 + 55.0 + row * bars.len() as f64).max(150.0),
        ml: (12.0 + 7.0 * longest as f64).clamp(60.0, 320.0),
        mr: 80.0,
        mt: 40.0,
        mb: 55.0,
    };
    let finite = || bars.iter().map(|b| b.value).filter(|v| v.is_finite());
    let lo = finite().fold(0.0, f64::min);
    let hi = finite().fold(0.0, f64::max);
    let (lo, hi) = if hi > lo { (lo, hi) } else { (0.0, 1.0) };
    let ticks = nice_ticks(lo, hi, 6);
    let step = if ticks.len() > 1 {
        ticks[1] - ticks[0]
    } else {
        1.0
    };
    let x0 = if lo < 0.0 {
        (lo / step).floor() * step
    } else {
        0.0
    };
    let x1 = (hi / step).ceil() * step;
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let sx = |x: f64| f.left() + (x - x0) / (x1 - x0) * (f.right() - f.left());

    let mut s = String::new();
    f.begin(&mut s, title, value_label, "");
    f.x_ticks(&mut s, &nice_ticks(x0, x1, 6), sx);
    f.plot_box(&mut s);
    let zero = sx(0.0);
    for (i, b) in bars.iter().enumerate() {
        let y = f.top() + row * i as f64;
        let cy = y + row / 2.0 + 4.0;
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{cy:.1}" text-anchor="end">{}</text>"#,
            f.left() - 6.0,
            esc(&b.label)
        );
        let end = if b.value.is_finite() {
            let x = sx(b.value);
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{}"/>"#,
                zero.min(x),
                y + 4.0,
                (x - zero).abs(),
                row - 8.0,
                COLORS[0]
            );
            x.max(zero)
        } else {
            zero
        };
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{cy:.1}">{}</text>"#,
            end + 4.0,
            esc(&fmt_value(b.value))
        );
    }
    s.push_str("</svg>\n");
    s
}

//! The frame every chart of [`super`] draws in (axes, ticks, legend colours) and the text
//! helpers they share; the charts use this module, never their parent.

use std::fmt::Write as _;

/// One polyline: a name for the legend and `(x, y)` points (`y > 0` for a log axis; others are
/// skipped).
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Data points.
    pub points: Vec<(f64, f64)>,
}

pub(super) const COLORS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// The chart's canvas and the margins around its plot area, in SVG user units (pixels).
#[derive(Clone, Copy)]
pub(super) struct Frame {
    pub(super) w: f64,
    pub(super) h: f64,
    pub(super) ml: f64,
    pub(super) mr: f64,
    pub(super) mt: f64,
    pub(super) mb: f64,
}

impl Frame {
    pub(super) fn left(&self) -> f64 {
        self.ml
    }
    pub(super) fn right(&self) -> f64 {
        self.w - self.mr
    }
    pub(super) fn top(&self) -> f64 {
        self.mt
    }
    pub(super) fn bottom(&self) -> f64 {
        self.h - self.mb
    }

    /// The `<svg>` header, white background, title and axis labels.
    /// A light vertical grid line and a label under the plot at each tick (`sx`: value → x).
    pub(super) fn x_ticks(&self, s: &mut String, ticks: &[f64], sx: impl Fn(f64) -> f64) {
        for &t in ticks {
            let x = sx(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{}" x2="{x:.1}" y2="{:.1}" stroke="#eee"/>"##,
                self.top(),
                self.bottom()
            );
            let _ = writeln!(
                s,
                r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                self.bottom() + 16.0,
                fmt_tick(t)
            );
        }
    }

    pub(super) fn begin(&self, s: &mut String, title: &str, xlabel: &str, ylabel: &str) {
        let (w, h) = (self.w, self.h);
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        let cx = (self.left() + self.right()) / 2.0;
        let _ = writeln!(
            s,
            r#"<text x="{cx}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            esc(title)
        );
        if !xlabel.is_empty() {
            let _ = writeln!(
                s,
                r#"<text x="{cx}" y="{:.1}" text-anchor="middle">{}</text>"#,
                h - 14.0,
                esc(xlabel)
            );
        }
        if !ylabel.is_empty() {
            let _ = writeln!(
                s,
                r#"<text transform="translate(18,{:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
                (self.top() + self.bottom()) / 2.0,
                esc(ylabel)
            );
        }
    }

    /// The black box around the plot area.
    pub(super) fn plot_box(&self, s: &mut String) {
        let _ = writeln!(
            s,
            r#"<rect x="{}" y="{}" width="{:.1}" height="{:.1}" fill="none" stroke="black"/>"#,
            self.left(),
            self.top(),
            self.right() - self.left(),
            self.bottom() - self.top()
        );
    }

    /// Legend entry `i` in the right margin: a swatch line (dashed if `dash`) and the name.
    pub(super) fn legend(
        &self,
        s: &mut String,
        i: usize,
        color: &str,
        dash: Option<&str>,
        name: &str,
    ) {
        let ly = self.top() + 10.0 + 20.0 * i as f64;
        let lx = self.right() + 15.0;
        let dash = dash.map_or(String::new(), |d| format!(r#" stroke-dasharray="{d}""#));
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{color}" stroke-width="3"{dash}/>"#,
            lx + 24.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            lx + 30.0,
            ly + 4.0,
            esc(name)
        );
    }
}

/// Escapes text for XML content and attributes; drops characters XML 1.0 forbids.
pub(super) fn esc(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    for c in t.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {}
            c => out.push(c),
        }
    }
    out
}

pub(super) fn fmt_tick(t: f64) -> String {
    if (t - t.round()).abs() < 1e-9 {
        format!("{}", t.round() as i64)
    } else {
        fmt_value(t)
    }
}

/// A value label with three significant digits: `1230`, `12.3`, `0.0123`, `1.23e-5`.
pub(super) fn fmt_value(v: f64) -> String {
    if !v.is_finite() {
        return "n/a".into();
    }
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    if !(1e-3..1e6).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// About `n` evenly spaced round tick values covering `[a, b]`.
pub(super) fn nice_ticks(a: f64, b: f64, n: usize) -> Vec<f64> {
    if !(a.is_finite() && b.is_finite()) || b <= a {
        return if a.is_finite() { vec![a] } else { Vec::new() };
    }
    let raw = (b - a) / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    // Tick k is k·m·mag, written as (k·m) / (1/mag) for mag < 1 so that 3 × 0.1 prints "0.3".
    let m = (step / mag).round();
    let inv = if mag < 1.0 { (1.0 / mag).round() } else { 0.0 };
    let value = |k: f64| {
        let v = if inv > 0.0 { k * m / inv } else { k * m * mag };
        if v == 0.0 {
            0.0
        } else {
            v
        }
    };
    let mut k = (a / step).ceil();
    let mut out = Vec::new();
    while value(k) <= b + 1e-9 * step && out.len() < 100 {
        out.push(value(k));
        k += 1.0;
    }
    out
}

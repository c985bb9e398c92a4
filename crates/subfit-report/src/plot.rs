//! Minimal SVG line charts for the convergence study (log-scale `E_rms` against iteration, one
//! polyline per method, like Cheng 2007 Fig. 4, 5, 7a, 8).
//!
//! Written by hand rather than with `plotters`: its text layout needs a font backend (system
//! fonts through C libraries, or a TTF file we would have to ship), while an SVG viewer lays out
//! `<text>` itself. The output is plain SVG 1.1, deterministic for given data.

use std::fmt::Write as _;

/// One polyline: a name for the legend and `(x, y)` points (`y > 0` for a log axis; others are
/// skipped).
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Data points.
    pub points: Vec<(f64, f64)>,
}

const COLORS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// Renders a chart with a linear x axis and a log10 y axis; `hline` draws a dashed horizontal
/// reference line (e.g. the tolerance).
pub fn log_chart(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    hline: Option<f64>,
) -> String {
    let (w, h) = (760.0, 480.0);
    let (ml, mr, mt, mb) = (80.0, 170.0, 40.0, 55.0);
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.1 > 0.0 && p.1.is_finite() && p.0.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y.log10());
        y1 = y1.max(y.log10());
    }
    if let Some(t) = hline.filter(|t| *t > 0.0) {
        y0 = y0.min(t.log10());
        y1 = y1.max(t.log10());
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, -3.0, 0.0);
    }
    let (y0, y1) = (y0.floor(), y1.ceil().max(y0.floor() + 1.0));
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let sx = |x: f64| ml + (x - x0) / (x1 - x0) * (w - ml - mr);
    let sy = |ly: f64| mt + (y1 - ly) / (y1 - y0) * (h - mt - mb);

    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        (ml + w - mr) / 2.0,
        esc(title)
    );
    // Axes and grid.
    for e in (y0 as i64)..=(y1 as i64) {
        let y = sy(e as f64);
        let _ = writeln!(
            s,
            r##"<line x1="{ml}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/>"##,
            w - mr
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">1e{e}</text>"#,
            ml - 6.0,
            y + 4.0
        );
    }
    let xticks = nice_ticks(x0, x1, 10);
    for &t in &xticks {
        let x = sx(t);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="#eee"/>"##,
            h - mb
        );
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            h - mb + 16.0,
            fmt_tick(t)
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{ml}" y="{mt}" width="{:.1}" height="{:.1}" fill="none" stroke="black"/>"#,
        w - ml - mr,
        h - mt - mb
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        (ml + w - mr) / 2.0,
        h - 14.0,
        esc(xlabel)
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18,{:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        (mt + h - mb) / 2.0,
        esc(ylabel)
    );
    if let Some(t) = hline.filter(|t| *t > 0.0) {
        let y = sy(t.log10());
        let _ = writeln!(
            s,
            r#"<line x1="{ml}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black" stroke-dasharray="6,4"/>"#,
            w - mr
        );
    }
    // Series and legend.
    for (i, ser) in series.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        let path: Vec<String> = ser
            .points
            .iter()
            .filter(|p| p.1 > 0.0 && p.1.is_finite())
            .map(|&(x, y)| format!("{:.1},{:.1}", sx(x), sy(y.log10())))
            .collect();
        if !path.is_empty() {
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#,
                path.join(" ")
            );
            for p in &path {
                let (x, y) = p.split_once(',').unwrap_or(("0", "0"));
                let _ = writeln!(s, r#"<circle cx="{x}" cy="{y}" r="2.5" fill="{c}"/>"#);
            }
        }
        let ly = mt + 10.0 + 20.0 * i as f64;
        let lx = w - mr + 15.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="3"/>"#,
            lx + 24.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            lx + 30.0,
            ly + 4.0,
            esc(&ser.name)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn esc(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn fmt_tick(t: f64) -> String {
    if (t - t.round()).abs() < 1e-9 {
        format!("{}", t.round() as i64)
    } else {
        format!("{t:.2}")
    }
}

/// About `n` evenly spaced round tick values covering `[a, b]`.
fn nice_ticks(a: f64, b: f64, n: usize) -> Vec<f64> {
    let raw = (b - a) / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (a / step).ceil() * step;
    let mut out = Vec::new();
    while t <= b + 1e-9 * step && out.len() < 100 {
        out.push(t);
        t += step;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chart_has_one_polyline_per_series_and_escapes_text() {
        let series = vec![
            Series {
                name: "SDM".into(),
                points: vec![(0.0, 0.1), (1.0, 0.01), (2.0, 0.001)],
            },
            Series {
                name: "P<D>M".into(),
                points: vec![(0.0, 0.1), (1.0, 0.05), (2.0, 0.0)],
            },
        ];
        let svg = log_chart(
            "E_rms & iterations",
            "iteration",
            "E_rms",
            &series,
            Some(0.002),
        );
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("P&lt;D&gt;M"));
        assert!(svg.contains("E_rms &amp; iterations"));
        assert!(svg.contains(">1e-3<"));
        assert!(svg.trim_end().ends_with("</svg>"));
        // The zero value is skipped on the log axis.
        assert_eq!(svg.matches("<circle").count(), 5);
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(
            nice_ticks(0.0, 10.0, 10),
            (0..=10).map(f64::from).collect::<Vec<_>>()
        );
        assert_eq!(
            nice_ticks(0.0, 50.0, 10),
            vec![0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0]
        );
    }
}

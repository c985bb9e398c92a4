//! Line charts with a linear x axis and a log10 y axis: error per iteration, one polyline per
//! series, with dashed vertical stage boundaries and horizontal reference lines.

use super::frame::{esc, nice_ticks, Frame, Series, COLORS};
use std::fmt::Write as _;

/// Reference lines and size of a [`log_chart_with`] chart. Default: none, 760 × 480.
#[derive(Clone, Debug, PartialEq)]
pub struct LogChartOptions {
    /// Vertical dashed lines at `x` with a label drawn along them, e.g. stage boundaries
    /// labelled with the stage's λ (`"λ = 0.01"`). Non-finite `x` are skipped.
    pub vlines: Vec<(f64, String)>,
    /// Horizontal dashed lines at `y` (`> 0`) with a label at their right end, e.g. the
    /// tolerance. Others are skipped.
    pub hlines: Vec<(f64, String)>,
    /// Canvas width in pixels. Default `760`.
    pub width: f64,
    /// Canvas height in pixels. Default `480`.
    pub height: f64,
}

impl Default for LogChartOptions {
    fn default() -> Self {
        Self {
            vlines: Vec::new(),
            hlines: Vec::new(),
            width: 760.0,
            height: 480.0,
        }
    }
}

/// Renders a chart with a linear x axis and a log10 y axis; `hline` draws a dashed horizontal
/// reference line (e.g. the tolerance). Same as [`log_chart_with`] with that one unlabelled
/// line.
pub fn log_chart(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    hline: Option<f64>,
) -> String {
    let options = LogChartOptions {
        hlines: hline.map(|t| (t, String::new())).into_iter().collect(),
        ..Default::default()
    };
    log_chart_with(title, xlabel, ylabel, series, &options)
}

/// Renders `series` (points with `y ≤ 0` or non-finite coordinates skipped) on a linear x and
/// log10 y axis with decade grid lines, plus `options`' reference lines; the axes cover the
/// data and the reference lines. Empty input gives an empty frame (x in `[0, 1]`,
/// y in `[1e-3, 1]`). Cost `O(#points)`.
pub fn log_chart_with(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    options: &LogChartOptions,
) -> String {
    let f = Frame {
        w: options.width.max(200.0),
        h: options.height.max(150.0),
        ml: 80.0,
        mr: 170.0,
        mt: 40.0,
        mb: 55.0,
    };
    let ok = |p: &&(f64, f64)| p.1 > 0.0 && p.1.is_finite() && p.0.is_finite();
    let hlines: Vec<&(f64, String)> = options
        .hlines
        .iter()
        .filter(|l| l.0 > 0.0 && l.0.is_finite())
        .collect();
    let vlines: Vec<&(f64, String)> = options.vlines.iter().filter(|l| l.0.is_finite()).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in series.iter().flat_map(|s| s.points.iter()).filter(ok) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y.log10());
        y1 = y1.max(y.log10());
    }
    for l in &hlines {
        y0 = y0.min(l.0.log10());
        y1 = y1.max(l.0.log10());
    }
    if y0 > y1 {
        (y0, y1) = (-3.0, 0.0);
    }
    for l in &vlines {
        x0 = x0.min(l.0);
        x1 = x1.max(l.0);
    }
    if x0 > x1 {
        (x0, x1) = (0.0, 1.0);
    }
    let (y0, y1) = (y0.floor(), y1.ceil().max(y0.floor() + 1.0));
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let sx = |x: f64| f.left() + (x - x0) / (x1 - x0) * (f.right() - f.left());
    let sy = |ly: f64| f.top() + (y1 - ly) / (y1 - y0) * (f.bottom() - f.top());

    let mut s = String::new();
    f.begin(&mut s, title, xlabel, ylabel);
    // Decade grid, or every tenth decade past 100 decades.
    let step = (((y1 - y0) / 100.0).ceil() as i64).max(1) as usize;
    for e in ((y0 as i64)..=(y1 as i64)).step_by(step) {
        let y = sy(e as f64);
        let _ = writeln!(
            s,
            r##"<line x1="{}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/>"##,
            f.left(),
            f.right()
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">1e{e}</text>"#,
            f.left() - 6.0,
            y + 4.0
        );
    }
    f.x_ticks(&mut s, &nice_ticks(x0, x1, 10), sx);
    f.plot_box(&mut s);
    for (t, label) in hlines {
        let y = sy(t.log10());
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black" stroke-dasharray="6,4"/>"#,
            f.left(),
            f.right()
        );
        if !label.is_empty() {
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end" font-size="10">{}</text>"#,
                f.right() - 4.0,
                y - 4.0,
                esc(label)
            );
        }
    }
    for (x, label) in vlines {
        let x = sx(*x);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{}" x2="{x:.1}" y2="{:.1}" stroke="#555" stroke-dasharray="4,3"/>"##,
            f.top(),
            f.bottom()
        );
        if !label.is_empty() {
            let _ = writeln!(
                s,
                r##"<text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="end" font-size="10" fill="#333">{}</text>"##,
                x - 3.0,
                f.top() + 4.0,
                esc(label)
            );
        }
    }
    for (i, ser) in series.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        let path: Vec<(f64, f64)> = ser
            .points
            .iter()
            .filter(ok)
            .map(|&(x, y)| (sx(x), sy(y.log10())))
            .collect();
        if !path.is_empty() {
            let pts: Vec<String> = path.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#,
                pts.join(" ")
            );
            for (x, y) in &path {
                let _ = writeln!(s, r#"<circle cx="{x:.1}" cy="{y:.1}" r="2.5" fill="{c}"/>"#);
            }
        }
        f.legend(&mut s, i, c, None, &ser.name);
    }
    s.push_str("</svg>\n");
    s
}

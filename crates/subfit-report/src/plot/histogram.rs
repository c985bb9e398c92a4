//! Error histograms: the distribution of distances in each direction (surface → data and
//! data → surface), overlaid as filled step outlines on one set of bins.
//!
//! Distances to a fitted surface have a long tail (a few points near holes, creases or noise are
//! tens of times the typical error), so by default the bins are logarithmic
//! ([`Binning::Log`]): from the 1st percentile of the positive distances to the largest, equal
//! in `log10`; zeros and anything below the first edge are counted in the first bin. Linear
//! bins from 0 to the largest value are available for distributions without a tail.
//! The y axis shows the fraction of each direction's samples (default), so directions with
//! different sample counts compare, or raw counts.

use super::frame::{esc, fmt_tick, fmt_value, nice_ticks, Frame, COLORS};
use std::fmt::Write as _;

/// How the x axis is cut into bins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binning {
    /// Equal widths in `log10` between the 1st percentile of the positive values (at most a
    /// tenth and at least `1e-9` of the largest) and the largest; smaller values and zeros go
    /// in the first bin. Falls back to [`Binning::Linear`] when no value is positive.
    Log,
    /// Equal widths from `min(0, smallest)` to the largest value.
    Linear,
}

/// How a [`histogram_chart`] is binned and labelled. Every field has a documented default.
#[derive(Clone, Debug, PartialEq)]
pub struct HistogramOptions {
    /// Number of bins, at least 1. Default `40`.
    pub bins: usize,
    /// Bin spacing. Default [`Binning::Log`].
    pub binning: Binning,
    /// `true`: y is the fraction of each series' finite values; `false`: counts. Default `true`.
    pub fractions: bool,
    /// Unit of the values, shown in the x label as `distance (unit)`, e.g. `"unit cube"`.
    /// Default empty (no unit shown).
    pub unit: String,
    /// Vertical dashed marks at `x` with a label, e.g. each direction's `E_rms` or the
    /// tolerance. Non-finite `x` (and `x ≤ 0` on log bins) are skipped. Default none.
    pub vlines: Vec<(f64, String)>,
}

impl Default for HistogramOptions {
    fn default() -> Self {
        Self {
            bins: 40,
            binning: Binning::Log,
            fractions: true,
            unit: String::new(),
            vlines: Vec::new(),
        }
    }
}

/// Counts of several series over shared bins.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// Bin edges, increasing, `#bins + 1` values; bin `i` is `[edges[i], edges[i + 1])`, the
    /// last one closed. With log binning the first bin also holds all smaller values.
    pub edges: Vec<f64>,
    /// Whether the edges are log-spaced ([`Binning::Log`] with some positive value).
    pub log: bool,
    /// `counts[s][i]`: values of series `s` in bin `i` (`#series by #bins`).
    pub counts: Vec<Vec<u64>>,
    /// Non-finite values skipped, per series.
    pub skipped: Vec<usize>,
}

/// Bins every finite value of `sets` on one set of `bins` bins chosen by `binning` (see
/// [`Binning`]). Cost `O(n)` for `n` values in all (one selection for the percentile).
pub fn histogram(sets: &[&[f64]], bins: usize, binning: Binning) -> Histogram {
    let bins = bins.max(1);
    let finite = || {
        sets.iter()
            .flat_map(|s| s.iter().copied())
            .filter(|v| v.is_finite())
    };
    let hi = finite().fold(f64::NEG_INFINITY, f64::max);
    let lo = finite().fold(f64::INFINITY, f64::min);
    let mut positive: Vec<f64> = finite().filter(|v| *v > 0.0).collect();
    let log = binning == Binning::Log && !positive.is_empty();
    let edges: Vec<f64> = if log {
        let k = positive.len() / 100;
        let (_, p1, _) = positive.select_nth_unstable_by(k, f64::total_cmp);
        let first = p1.clamp(hi * 1e-9, hi / 10.0);
        let (a, b) = (first.log10(), hi.log10());
        (0..=bins)
            .map(|i| 10f64.powf(a + (b - a) * i as f64 / bins as f64))
            .collect()
    } else {
        let (a, b) = if hi >= lo {
            (lo.min(0.0), hi)
        } else {
            (0.0, 1.0)
        };
        let b = if b > a { b } else { a + 1.0 };
        (0..=bins)
            .map(|i| a + (b - a) * i as f64 / bins as f64)
            .collect()
    };
    positive.clear();
    let (a, b) = if log {
        (edges[0].log10(), edges[bins].log10())
    } else {
        (edges[0], edges[bins])
    };
    let index = |v: f64| {
        let x = if log { v.max(edges[0]).log10() } else { v };
        let t = ((x - a) / (b - a) * bins as f64).floor();
        (t.max(0.0) as usize).min(bins - 1)
    };
    let mut counts = vec![vec![0u64; bins]; sets.len()];
    let mut skipped = vec![0usize; sets.len()];
    for (s, set) in sets.iter().enumerate() {
        for &v in set.iter() {
            if v.is_finite() {
                counts[s][index(v)] += 1;
            } else {
                skipped[s] += 1;
            }
        }
    }
    Histogram {
        edges,
        log,
        counts,
        skipped,
    }
}

/// Renders the histogram of each named series (e.g. `("surface → data", &d1)`,
/// `("data → surface", &d2)`) overlaid on shared bins, with a legend giving each series' count
/// and any non-finite values skipped. Empty input gives an empty frame. Cost `O(n)`.
pub fn histogram_chart(
    title: &str,
    series: &[(&str, &[f64])],
    options: &HistogramOptions,
) -> String {
    let sets: Vec<&[f64]> = series.iter().map(|s| s.1).collect();
    let hist = histogram(&sets, options.bins, options.binning);
    let f = Frame {
        w: 760.0,
        h: 420.0,
        ml: 80.0,
        mr: 190.0,
        mt: 40.0,
        mb: 55.0,
    };
    let totals: Vec<u64> = hist.counts.iter().map(|c| c.iter().sum()).collect();
    let height = |s: usize, c: u64| {
        if options.fractions {
            c as f64 / totals[s].max(1) as f64
        } else {
            c as f64
        }
    };
    let ymax = (0..series.len())
        .flat_map(|s| hist.counts[s].iter().map(move |&c| (s, c)))
        .map(|(s, c)| height(s, c))
        .fold(0.0, f64::max);
    let yticks = nice_ticks(0.0, if ymax > 0.0 { ymax } else { 1.0 }, 5);
    let step = yticks.get(1).map_or(1.0, |t| t - yticks[0]);
    let y1 = (ymax / step).ceil().max(1.0) * step;
    let n = hist.edges.len() - 1;
    let ex = |x: f64| if hist.log { x.log10() } else { x };
    let (x0, x1) = (ex(hist.edges[0]), ex(hist.edges[n]));
    let sx = |x: f64| f.left() + (ex(x) - x0) / (x1 - x0) * (f.right() - f.left());
    let sy = |y: f64| f.bottom() - y / y1 * (f.bottom() - f.top());

    let mut s = String::new();
    let xlabel = if options.unit.is_empty() {
        "distance".to_string()
    } else {
        format!("distance ({})", options.unit)
    };
    let ylabel = if options.fractions {
        "fraction of samples"
    } else {
        "samples"
    };
    f.begin(&mut s, title, &xlabel, ylabel);
    for t in yticks.iter().copied().filter(|t| *t <= y1 + 1e-12) {
        let y = sy(t);
        let _ = writeln!(
            s,
            r##"<line x1="{}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/>"##,
            f.left(),
            f.right()
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            f.left() - 6.0,
            y + 4.0,
            fmt_tick(t)
        );
    }
    for (t, label) in x_ticks(&hist) {
        let x = sx(t);
        let _ = writeln!(
            s,
            r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="black"/>"#,
            f.bottom(),
            f.bottom() + 4.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{label}</text>"#,
            f.bottom() + 16.0
        );
    }
    for (i, (name, _)) in series.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        let mut pts = vec![format!("{:.1},{:.1}", sx(hist.edges[0]), sy(0.0))];
        for (b, &count) in hist.counts[i].iter().enumerate() {
            let y = sy(height(i, count));
            pts.push(format!("{:.1},{y:.1}", sx(hist.edges[b])));
            pts.push(format!("{:.1},{y:.1}", sx(hist.edges[b + 1])));
        }
        pts.push(format!("{:.1},{:.1}", sx(hist.edges[n]), sy(0.0)));
        let _ = writeln!(
            s,
            r#"<polygon points="{}" fill="{c}" fill-opacity="0.25" stroke="{c}" stroke-width="1.5"/>"#,
            pts.join(" ")
        );
        let mut label = format!("{name} (n = {})", totals[i]);
        if hist.skipped[i] > 0 {
            label.push_str(&format!(", {} non-finite skipped", hist.skipped[i]));
        }
        f.legend(&mut s, i, c, None, &label);
    }
    for (x, label) in &options.vlines {
        if !x.is_finite() || (hist.log && *x <= 0.0) {
            continue;
        }
        let px = sx(*x).clamp(f.left(), f.right());
        let _ = writeln!(
            s,
            r##"<line x1="{px:.1}" y1="{}" x2="{px:.1}" y2="{:.1}" stroke="#333" stroke-dasharray="4,3"/>"##,
            f.top(),
            f.bottom()
        );
        let _ = writeln!(
            s,
            r##"<text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="end" font-size="10" fill="#333">{}</text>"##,
            px - 3.0,
            f.top() + 4.0,
            esc(label)
        );
    }
    f.plot_box(&mut s);
    s.push_str("</svg>\n");
    s
}

/// Tick positions and labels on the x axis: `1`, `2`, `5` times each decade on log bins (only
/// decades past three decades), round values on linear bins.
fn x_ticks(hist: &Histogram) -> Vec<(f64, String)> {
    let (a, b) = (hist.edges[0], hist.edges[hist.edges.len() - 1]);
    if !hist.log {
        return nice_ticks(a, b, 8)
            .into_iter()
            .map(|t| (t, fmt_tick(t)))
            .collect();
    }
    let (la, lb) = (a.log10(), b.log10());
    let mantissas: &[f64] = if lb - la > 3.0 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let mut out = Vec::new();
    for e in (la.floor() as i64)..=(lb.ceil() as i64) {
        for &m in mantissas {
            let t = m * 10f64.powi(e as i32);
            if t >= a * (1.0 - 1e-9) && t <= b * (1.0 + 1e-9) {
                let label = if (-2..=3).contains(&e) {
                    fmt_value(t)
                } else {
                    format!("{m}e{e}")
                };
                out.push((t, label));
            }
        }
    }
    out
}

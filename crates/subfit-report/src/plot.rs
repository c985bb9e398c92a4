//! Deterministic SVG charts for fit reports and the convergence study: log-scale error curves
//! per iteration with stage boundaries and tolerances (like Cheng 2007 Fig. 4, 5, 7a, 8), bar
//! charts (control points per stage, time per phase) and error histograms both ways.
//!
//! Written by hand rather than with `plotters`: its text layout needs a font backend (system
//! fonts through C libraries, or a TTF file we would have to ship), while an SVG viewer lays out
//! `<text>` itself. The output is plain SVG 1.1, deterministic for given data; text is
//! XML-escaped and non-finite values are skipped, never written as coordinates.
//!
//! * [`line`]: [`log_chart`], [`log_chart_with`] ([`LogChartOptions`]: stage lines, tolerances).
//! * [`bar`]: [`bar_chart`] ([`Bar`]).
//! * [`histogram`]: [`histogram_chart`] ([`HistogramOptions`], [`Binning`]) and the binning
//!   itself, [`histogram()`].

pub mod bar;
mod frame;
pub mod histogram;
pub mod line;

pub use bar::{bar_chart, Bar};
pub use frame::Series;
pub use histogram::{histogram, histogram_chart, Binning, Histogram, HistogramOptions};
pub use line::{log_chart, log_chart_with, LogChartOptions};

#[cfg(test)]
mod tests;

//! Tests of the SVG charts: well-formed XML, the series and labels present, no panic or
//! non-finite coordinate on empty or non-finite input.

use super::frame::{esc, fmt_value, nice_ticks, COLORS};
use super::*;

/// Parses `svg` as XML and checks that no attribute holds a non-finite number.
fn parse(svg: &str) -> roxmltree::Document<'_> {
    let doc = roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("{e}\n{svg}"));
    for node in doc.descendants() {
        for a in node.attributes() {
            let v = a.value();
            assert!(!v.contains("NaN") && !v.contains("inf"), "{}={v}", a.name());
        }
    }
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc
}

fn texts(doc: &roxmltree::Document<'_>) -> Vec<String> {
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").to_string())
        .collect()
}

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
    let doc = parse(&svg);
    assert!(texts(&doc).contains(&"P<D>M".to_string()));
}

#[test]
fn stage_boundaries_and_tolerances_are_drawn_and_labelled() {
    let series = vec![
        Series {
            name: "E_rms".into(),
            points: (0..12)
                .map(|i| (f64::from(i), 0.1 / f64::from(i + 1)))
                .collect(),
        },
        Series {
            name: "E_max".into(),
            points: (0..12)
                .map(|i| (f64::from(i), 0.5 / f64::from(i + 1)))
                .collect(),
        },
    ];
    let o = LogChartOptions {
        vlines: vec![
            (4.0, "λ = 0.01".into()),
            (8.0, "λ = 0.001".into()),
            (f64::NAN, "x".into()),
        ],
        hlines: vec![(0.002, "tolerance 2e-3".into()), (-1.0, "skipped".into())],
        ..Default::default()
    };
    let svg = log_chart_with(
        "E per iteration",
        "iteration",
        "error (unit cube)",
        &series,
        &o,
    );
    let doc = parse(&svg);
    let t = texts(&doc);
    for want in [
        "λ = 0.01",
        "λ = 0.001",
        "tolerance 2e-3",
        "E_rms",
        "E_max",
        "E per iteration",
    ] {
        assert!(t.iter().any(|s| s == want), "{want} missing");
    }
    assert!(!t.iter().any(|s| s == "skipped" || s == "x"));
    assert_eq!(svg.matches(r#"stroke-dasharray="4,3""#).count(), 2);
    assert_eq!(svg.matches(r#"stroke-dasharray="6,4""#).count(), 1);
    assert_eq!(
        log_chart_with(
            "E per iteration",
            "iteration",
            "error (unit cube)",
            &series,
            &o
        ),
        svg,
        "deterministic"
    );
}

#[test]
fn empty_and_non_finite_input_give_a_frame() {
    let nan = vec![Series {
        name: "bad".into(),
        points: vec![(f64::NAN, 1.0), (1.0, f64::INFINITY), (f64::INFINITY, 0.1)],
    }];
    parse(&log_chart("empty", "x", "y", &[], None));
    parse(&log_chart("nan", "x", "y", &nan, Some(f64::NAN)));
    parse(&bar_chart("empty", "seconds", &[]));
    parse(&bar_chart(
        "bad",
        "s",
        &[Bar::new("nan", f64::NAN), Bar::new("inf", f64::INFINITY)],
    ));
    let o = HistogramOptions::default();
    parse(&histogram_chart("empty", &[], &o));
    parse(&histogram_chart(
        "empty series",
        &[("a", &[]), ("b", &[])],
        &o,
    ));
    let weird = [f64::NAN, 0.0, 0.0, f64::NEG_INFINITY];
    let svg = histogram_chart("zeros", &[("a", &weird)], &o);
    assert!(svg.contains("2 non-finite skipped"));
    parse(&svg);
    let lin = HistogramOptions {
        binning: Binning::Linear,
        bins: 0,
        ..Default::default()
    };
    parse(&histogram_chart("one value", &[("a", &[3.0])], &lin));
}

#[test]
fn bars_carry_labels_and_values() {
    let bars = [
        Bar::new("stage 1 (λ = 0.1)", 120.0),
        Bar::new("stage 2 (λ = 0.01)", 480.0),
        Bar::new("closest points & <feet>", 1.234_56),
    ];
    let svg = bar_chart("control points per stage", "control points", &bars);
    let doc = parse(&svg);
    let t = texts(&doc);
    for want in [
        "stage 1 (λ = 0.1)",
        "closest points & <feet>",
        "120",
        "480",
        "1.23",
        "control points",
    ] {
        assert!(t.iter().any(|s| s == want), "{want} missing in {t:?}");
    }
    let rects = doc.descendants().filter(|n| n.has_tag_name("rect")).count();
    assert_eq!(rects, 2 + 3, "background, frame and one per bar");
    // Lengths are proportional to values.
    let widths: Vec<f64> = doc
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some(COLORS[0]))
        .map(|n| n.attribute("width").unwrap().parse().unwrap())
        .collect();
    assert!((widths[1] / widths[0] - 4.0).abs() < 0.01, "{widths:?}");
}

#[test]
fn log_bins_cover_a_long_tail_and_count_everything() {
    // 1000 values around 1e-3 and a tail up to 0.5, plus zeros.
    let a: Vec<f64> = (0..1000)
        .map(|i| 1e-3 * (1.0 + f64::from(i % 10) / 10.0))
        .collect();
    let mut b: Vec<f64> = (0..500).map(|i| 1e-3 * 1.5f64.powi(i % 16)).collect();
    b.extend([0.0, 0.0, f64::NAN]);
    let h = histogram(&[&a, &b], 30, Binning::Log);
    assert!(h.log);
    assert_eq!(h.edges.len(), 31);
    assert!(h.edges.windows(2).all(|w| w[0] < w[1]));
    assert!(
        (h.edges[30]
            - b.iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max))
        .abs()
            < 1e-12
    );
    assert_eq!(h.counts[0].iter().sum::<u64>(), 1000);
    assert_eq!(h.counts[1].iter().sum::<u64>(), 502);
    assert_eq!(h.skipped, vec![0, 1]);
    // Equal log widths.
    let r: Vec<f64> = h.edges.windows(2).map(|w| w[1] / w[0]).collect();
    assert!(r.iter().all(|x| (x / r[0] - 1.0).abs() < 1e-9));

    let lin = histogram(&[&a], 10, Binning::Linear);
    assert!(!lin.log);
    assert_eq!(lin.edges[0], 0.0);
    assert_eq!(lin.counts[0].iter().sum::<u64>(), 1000);

    let o = HistogramOptions {
        unit: "unit cube".into(),
        vlines: vec![(1.2e-3, "E_rms s→d".into()), (-1.0, "skipped".into())],
        ..Default::default()
    };
    let svg = histogram_chart(
        "error histogram",
        &[("surface → data", &a), ("data → surface", &b)],
        &o,
    );
    let doc = parse(&svg);
    let t = texts(&doc);
    for want in [
        "distance (unit cube)",
        "fraction of samples",
        "surface → data (n = 1000)",
        "E_rms s→d",
    ] {
        assert!(t.iter().any(|s| s == want), "{want} missing in {t:?}");
    }
    assert!(!t.iter().any(|s| s == "skipped"));
    assert_eq!(
        doc.descendants()
            .filter(|n| n.has_tag_name("polygon"))
            .count(),
        2
    );
}

#[test]
fn labels_and_ticks_are_round() {
    assert_eq!(
        nice_ticks(0.0, 10.0, 10),
        (0..=10).map(f64::from).collect::<Vec<_>>()
    );
    assert_eq!(
        nice_ticks(0.0, 50.0, 10),
        vec![0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0]
    );
    assert_eq!(nice_ticks(0.0, 0.3, 3), vec![0.0, 0.1, 0.2, 0.3]);
    assert!(nice_ticks(f64::NAN, 1.0, 5).is_empty());
    assert_eq!(fmt_value(1234.0), "1234");
    assert_eq!(fmt_value(0.012345), "0.0123");
    assert_eq!(fmt_value(2.5e-5), "2.50e-5");
    assert_eq!(esc("a<b & \"c\"\u{1}"), "a&lt;b &amp; &quot;c&quot;");
}

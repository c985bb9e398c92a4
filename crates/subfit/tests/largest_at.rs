//! Where the largest errors are (report.json `final.largest_at`): a box fitted without crease
//! tags by a few control points rounds its corners, so the data point farthest from the limit
//! surface is at a corner of the box; the limit point farthest from the data is at the
//! distance the report gives, measured independently here (the box is analytic).

use subfit::mesh::shapes::gridded_box;
use subfit::{fit_scan, FitScanOptions, Input};

/// The box's lowest corner (away from the origin, which an unset location would be).
const LO: [f64; 3] = [1.0, -2.0, 3.0];
/// Its sides.
const SIDES: [f64; 3] = [2.0, 1.0, 0.5];

/// Distance of `p` to the surface of the box `LO + [0, 2] × [0, 1] × [0, 0.5]`.
fn box_distance(p: [f64; 3]) -> f64 {
    let p = [p[0] - LO[0], p[1] - LO[1], p[2] - LO[2]];
    let hi = SIDES;
    let outside: f64 = (0..3)
        .map(|a| (-p[a]).max(p[a] - hi[a]).max(0.0).powi(2))
        .sum::<f64>()
        .sqrt();
    if outside > 0.0 {
        outside
    } else {
        (0..3)
            .map(|a| p[a].min(hi[a] - p[a]))
            .fold(f64::INFINITY, f64::min)
    }
}

#[test]
fn the_largest_errors_are_located_where_they_are() {
    // A box (not a cube: the corners are not all alike after normalization) on a grid.
    let mut mesh = gridded_box(8, false);
    for p in &mut mesh.positions {
        *p = [
            LO[0] + SIDES[0] * p[0],
            LO[1] + SIDES[1] * p[1],
            LO[2] + SIDES[2] * p[2],
        ];
    }
    let mut options = FitScanOptions {
        control_points: Some(40),
        ..FitScanOptions::default()
    };
    options.init_options.features = None;
    options.stages.refine = false;
    options.stages.max_iterations = 6;
    let fitted = fit_scan(
        Input::Mesh {
            mesh,
            name: "box".into(),
        },
        &options,
        None,
    )
    .expect("the box fits");
    let r = &fitted.report;
    let two = &r.r#final.two_sided;
    let at = r.r#final.largest_at;

    // Data → surface: a corner of the box, as far from the limit as reported.
    let corner = at.data_to_surface;
    let off_corner = (0..3)
        .map(|a| {
            let c = corner[a] - LO[a];
            c.abs().min((c - SIDES[a]).abs())
        })
        .fold(0.0, f64::max);
    assert!(
        off_corner < 1e-9,
        "the farthest data point {corner:?} is not a corner of the box (data → surface max {:.3e})",
        two.data_to_surface.max
    );

    // Surface → data: the limit point's own distance to the box is the reported maximum
    // (normalized units in the report's statistics; the box is in its own units).
    let unit = r.normalized_unit_in_original_units;
    let measured = box_distance(at.surface_to_data);
    let reported = two.surface_to_data.max * unit;
    assert!(
        (measured - reported).abs() <= 1e-6 * reported.max(1e-12),
        "limit point {:?}: {measured:.6e} from the box, reported {reported:.6e}",
        at.surface_to_data
    );
    assert!(reported > 0.0);
}

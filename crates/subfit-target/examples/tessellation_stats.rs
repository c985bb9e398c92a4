//! Prints what the facets of each mesh file say ([`subfit_target::tessellation`]): whether it
//! is a CAD tessellation, the share of flat edges, planar regions, slivers, the chord height
//! estimated from its curved faces and the edges' classes at the CAD tolerance (a fraction of
//! the diagonal).
//!
//! `cargo run --release -p subfit-target --example tessellation_stats -- FILE...`
#![allow(clippy::print_stdout)]

use subfit_mesh::vec3::{norm, sub};
use subfit_target::tessellation::{classify_edges, EdgeClass, Facets, SmoothBudget};

fn main() {
    for path in std::env::args().skip(1) {
        let (mesh, _) = match subfit_io::read_file(path.as_ref(), &Default::default()) {
            Ok(m) => m,
            Err(e) => {
                println!("{path}: {e}");
                continue;
            }
        };
        let Some((lo, hi)) = mesh.bounding_box() else {
            continue;
        };
        let diagonal = norm(sub(hi, lo));
        let magnitude = lo.iter().chain(&hi).fold(0.0f64, |m, c| m.max(c.abs()));
        let tris = mesh.faces.triangulate_fan();
        let t = std::time::Instant::now();
        let f = Facets::new(
            &mesh.positions,
            &tris,
            Facets::float32_tolerance(magnitude, 1.0),
        );
        let s = f.stats(&mesh.positions);
        let budget = SmoothBudget {
            max_sag: 1.5e-3 * diagonal,
            max_rms: 2e-4 * diagonal,
        };
        let c = classify_edges(&mesh.positions, &f, &budget);
        println!(
            "{path}: tessellation {} (flat edges {:.3}, {} planar regions over {:.2} of the area, slivers {:.2}), {} vertices; chord height {:.2e} of the diagonal; edges flat {} smooth {} crease {} (threshold {:.2e}, predicted RMS {:.2e}); {:.2} s",
            s.is_tessellation,
            s.flat_edge_share,
            s.planar_regions,
            s.planar_area_share,
            s.sliver_share,
            s.vertices,
            c.chord_height / diagonal,
            c.count(EdgeClass::Flat),
            c.count(EdgeClass::Smooth),
            c.count(EdgeClass::Crease),
            c.threshold / diagonal,
            c.predicted_rms / diagonal,
            t.elapsed().as_secs_f64()
        );
    }
}

//! Is the drift of a tracked sequence the tracker's fault, or do the frames not determine it?
//!
//! On a generated sequence (`subfit_mesh::deforming`, the default motion: bend, twist and a
//! thickness wave) the template — frame 0's vertices — is carried onto frame `F` by the
//! embedded deformation of [`subfit_fit::track`], as `subfit sequence` does (from the
//! template, warm-started from the previous frames' motions, default weights, run to
//! convergence), and compared with where its material really went; then again with 12 and 32
//! [`Marker`]s (vertices spread over the template) pulled to their true places in every frame.
//! Then, on the same graph:
//!
//! 1. **the reference**: the motion fitted to the true correspondences
//!    ([`fit_correspondences`]) — what the graph can represent at best;
//! 2. **tracking from the reference**: does the tracker stay at the truth when it starts
//!    there, or do its priors pull it to the same drifting motion?
//! 3. **priors a hundred times weaker, frames four times denser**, again from the reference:
//!    do the frames alone hold the material in place?
//! 4. **surface strain** (mean squared relative change of the template's edge lengths) of the
//!    true motion and of the tracked one: would a least-strain prior choose the truth?
//!
//! Each line gives the largest and RMS drift (fraction of the frame's diagonal) and the RMS
//! point-to-plane distance to the frame (normalized units) the motion leaves.
//!
//! Run: `cargo run --release -p subfit-fit --example drift_identifiability [-- FRAME [VERTICES [NODES]]]`
//! (defaults 8, the strongest bend, 8000 and 60 as in `subfit sequence`). About a minute on two cores.
#![allow(clippy::print_stdout)]

use subfit_fit::track::{
    deform, fit_correspondences, track, DeformationGraph, Marker, NodeMotion, Samples,
    TrackOptions, TrackStats,
};
use subfit_mesh::deforming::DeformingSequence;
use subfit_mesh::vec3::{cross, dist2, normalize, sub};
use subfit_target::{Normalization, Target, TargetOptions};

/// Depth and neighbours of the graph's nodes, as `subfit sequence` builds it.
const DEPTH: f64 = 0.5;
const NEIGHBORS: usize = 8;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let last: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(8).max(1);
    let vertices: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(8000);
    let nodes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(60);
    let seq = DeformingSequence::default();
    let rest = seq.frame(0, vertices, 1);
    let (lo, hi) = rest.mesh.bounding_box().ok_or("an empty frame")?;
    let norm = Normalization::from_bounds(lo, hi).ok_or("a degenerate frame")?;
    let samples: Vec<[f64; 3]> = rest
        .mesh
        .positions
        .iter()
        .map(|&p| norm.to_normalized(p))
        .collect();
    let triangles: Vec<[usize; 3]> = rest
        .mesh
        .faces
        .iter()
        .map(|f| [f[0] as usize, f[1] as usize, f[2] as usize])
        .collect();
    let normals = vertex_normals(&samples, &triangles);
    let graph = DeformationGraph::interior(&samples, &normals, DEPTH, nodes, NEIGHBORS);
    let options = TrackOptions::default();
    let rest_samples = Samples {
        positions: &samples,
        normals: &normals,
    };
    let target_options = TargetOptions {
        normalization: Some(norm),
        ..TargetOptions::default()
    };
    let frame = |t: usize, v: usize| {
        let f = seq.frame(t, v, 1 + t as u64);
        Target::from_mesh(&f.mesh, &target_options)
    };
    let truth: Vec<[f64; 3]> = rest
        .material
        .iter()
        .map(|&m| norm.to_normalized(seq.deform(last, m)))
        .collect();
    let drift = |moved: &[[f64; 3]]| drift(moved, &truth);
    println!(
        "frame {last} of the default motion, template of {} vertices, {} nodes",
        samples.len(),
        graph.len()
    );

    // The tracker, as a sequence runs it; then with markers at their true positions.
    let targets: Vec<Target> = (1..=last)
        .map(|t| frame(t, vertices))
        .collect::<Result<_, _>>()?;
    let run = |picks: &[usize]| {
        let (mut now, mut before): (Option<NodeMotion>, Option<NodeMotion>) = (None, None);
        let mut out = (samples.clone(), TrackStats::default());
        for (t, tg) in (1..=last).zip(&targets) {
            let markers: Vec<Marker> = picks
                .iter()
                .map(|&i| Marker {
                    rest: samples[i],
                    position: norm.to_normalized(seq.deform(t, rest.material[i])),
                })
                .collect();
            let start = match (&now, &before) {
                (Some(a), Some(b)) => Some(a.extrapolated(b)),
                (a, _) => a.clone(),
            };
            let (moved, motion, stats) = track(
                &graph,
                &samples,
                rest_samples,
                tg,
                &markers,
                start.as_ref(),
                &options,
            );
            out = (moved, stats);
            before = now.replace(motion);
        }
        out
    };
    let (tracked, stats) = run(&[]);
    line(
        "tracked as a sequence does",
        drift(&tracked),
        stats.rms_after,
    );
    for count in [12, 32] {
        let picks = rest.spread_vertices(count);
        let (moved, stats) = run(&picks);
        line(
            &format!("with {count} markers"),
            drift(&moved),
            stats.rms_after,
        );
    }
    let target = targets.last().ok_or("no frame tracked")?;

    // 1. The reference: the graph fitted to the true correspondences. One step from it
    // measures what it leaves on the frame (`rms_before`).
    let reference = fit_correspondences(&graph, &samples, &truth, options.skin);
    let at_reference = deform(&graph, &samples, &reference, options.skin);
    let from_reference = |frame: &Target, iterations: usize, o: &TrackOptions| {
        let o = TrackOptions {
            iterations,
            ..o.clone()
        };
        let (moved, _, stats) = track(
            &graph,
            &samples,
            rest_samples,
            frame,
            &[],
            Some(&reference),
            &o,
        );
        (moved, stats)
    };
    let (_, stats) = from_reference(target, 1, &options);
    line(
        "reference (true correspondences)",
        drift(&at_reference),
        stats.rms_before,
    );

    // 2. The tracker started at the reference.
    let (moved, stats) = from_reference(target, 100, &options);
    line("tracked from the reference", drift(&moved), stats.rms_after);

    // 3. Priors a hundred times weaker, a denser frame.
    let weak = TrackOptions {
        regularity: options.regularity / 100.0,
        rigidity: options.rigidity / 100.0,
        second_order: options.second_order / 100.0,
        ..options.clone()
    };
    let dense = frame(last, 4 * vertices)?;
    let (moved, stats) = from_reference(&dense, 100, &weak);
    line(
        "weak priors, 4x denser frame",
        drift(&moved),
        stats.rms_after,
    );
    let (_, stats) = from_reference(&dense, 1, &weak);
    println!(
        "  (the reference leaves {:.2e} on the denser frame)",
        stats.rms_before
    );

    // 4. Surface strain.
    println!(
        "surface strain: true motion {:.3e}, tracked {:.3e}",
        strain(&samples, &truth, &triangles),
        strain(&samples, &tracked, &triangles)
    );
    Ok(())
}

fn line(what: &str, (max, rms): (f64, f64), plane_rms: f64) {
    println!(
        "{what:<34} drift max {:6.3}% RMS {:6.3}%, point-to-plane RMS {plane_rms:.2e}",
        100.0 * max,
        100.0 * rms
    );
}

/// Largest and RMS distance of `moved` to `truth`, as fractions of `truth`'s diagonal.
fn drift(moved: &[[f64; 3]], truth: &[[f64; 3]]) -> (f64, f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in truth {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let diagonal = dist2(lo, hi).sqrt();
    let (mut max2, mut sum2) = (0.0f64, 0.0);
    for (p, q) in moved.iter().zip(truth) {
        let d2 = dist2(*p, *q);
        max2 = max2.max(d2);
        sum2 += d2;
    }
    (
        max2.sqrt() / diagonal,
        (sum2 / moved.len().max(1) as f64).sqrt() / diagonal,
    )
}

/// Mean squared relative change of the edge lengths of `triangles` from `rest` to `moved`.
fn strain(rest: &[[f64; 3]], moved: &[[f64; 3]], triangles: &[[usize; 3]]) -> f64 {
    let mut sum = 0.0;
    for t in triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let l0 = dist2(rest[a], rest[b]).sqrt();
            let l1 = dist2(moved[a], moved[b]).sqrt();
            sum += (l1 / l0 - 1.0).powi(2);
        }
    }
    sum / (3 * triangles.len()).max(1) as f64
}

/// Area-weighted vertex normals.
fn vertex_normals(p: &[[f64; 3]], triangles: &[[usize; 3]]) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0; 3]; p.len()];
    for t in triangles {
        let c = cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]]));
        for &i in t {
            for a in 0..3 {
                n[i][a] += c[a];
            }
        }
    }
    n.into_iter()
        .map(|v| normalize(v).unwrap_or([0.0, 0.0, 1.0]))
        .collect()
}

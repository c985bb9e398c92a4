//! Timings of the initial-mesh steps on real data (needs `SUBFIT_DATA`): QEM simplification of
//! Igea (134k vertices, 269k faces) to 2,385 vertices (Cheng 2007 Tab. IV), the same through a
//! point cloud (contour + simplification), and the rocker arm / fertility meshes; then the octree
//! contour of a torus cloud at 512 finest cells (far beyond the 160 of the former uniform grid).
//! Run with `cargo bench -p subfit-init --bench init`.
#![allow(clippy::print_stdout)]

use std::path::PathBuf;
use std::time::Instant;

use subfit_init::{
    contour, initial_control_mesh, simplify, ContourOptions, InitOptions, SimplifyOptions,
};
use subfit_mesh::HalfEdgeMesh;
use subfit_target::{Target, TargetOptions};

fn main() {
    let Some(dir) = std::env::var_os("SUBFIT_DATA").map(PathBuf::from) else {
        println!("SUBFIT_DATA unset: nothing to measure");
        return;
    };
    let read = |f: &str| {
        subfit_io::read_file(&dir.join(f), &subfit_io::ReadOptions::default())
            .expect("readable data file")
            .0
    };
    for (file, n) in [
        ("igea.ply", 2385),
        ("rocker-arm.off", 950),
        ("fertility.off", 1000),
    ] {
        let m = read(file);
        let g0 = HalfEdgeMesh::from_mesh(&m).map(|h| h.genus()).ok();
        let t = Instant::now();
        let (out, rep) = simplify(
            &m,
            &SimplifyOptions {
                target_vertices: n,
                ..SimplifyOptions::default()
            },
        )
        .expect("simplifiable");
        let dt = t.elapsed();
        let g1 = HalfEdgeMesh::from_mesh(&out).map(|h| h.genus()).ok();
        println!(
            "simplify {file}: {} V / {} F -> {} V in {:.3} s; genus {g0:?} -> {g1:?}; \
             rejected link {} boundary {} flip {} degenerate {}; max error {:.3e}",
            rep.vertices_before,
            rep.faces_before,
            rep.vertices_after,
            dt.as_secs_f64(),
            rep.rejected_link,
            rep.rejected_boundary,
            rep.rejected_flip,
            rep.rejected_degenerate,
            rep.max_error
        );
    }

    let m = read("igea.ply");
    let t = Instant::now();
    let target = Target::from_points(&m.positions, None, &TargetOptions::default())
        .expect("a valid point cloud");
    println!(
        "igea point cloud: target build {:.3} s",
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let (c, crep) = contour(&target, &ContourOptions::default()).expect("contour");
    println!(
        "contour igea: finest {:?} cell {:.4}, octree {} points (a uniform grid: {}), leaves per \
         level {:?}, {} band nodes, {} V / {} F, {} components kept of {}, genus {} in {:.3} s",
        crep.nodes,
        crep.cell_size,
        crep.octree_nodes,
        crep.nodes.iter().product::<usize>(),
        crep.leaves_per_level,
        crep.band_nodes,
        c.num_vertices(),
        c.num_faces(),
        crep.components_kept,
        crep.components_found,
        crep.genus,
        t.elapsed().as_secs_f64()
    );
    let (out, rep) = initial_control_mesh(
        &target,
        None,
        2385,
        &InitOptions {
            expected_genus: Some(0),
            ..InitOptions::default()
        },
    )
    .expect("initial mesh");
    println!(
        "initial_control_mesh(igea cloud, 2385): {} V, genus {} (target {}), contour {:.3} s, \
         simplify {:.3} s, total {:.3} s; rejected link {} flip {} degenerate {}, relaxations {}",
        out.num_vertices(),
        rep.genus_after,
        rep.genus_target,
        rep.timings.contour.as_secs_f64(),
        rep.timings.simplify.as_secs_f64(),
        rep.timings.total.as_secs_f64(),
        rep.simplify.rejected_link,
        rep.simplify.rejected_flip,
        rep.simplify.rejected_degenerate,
        rep.simplify.relaxations
    );

    torus_at_512();
}

/// The octree contour of an 8000-point torus cloud at 512 finest cells: time, size of the
/// octree against the 512³ of a uniform grid, leaves per level.
fn torus_at_512() {
    let shape = subfit_mesh::shapes::Shape::DEFAULT_TORUS;
    let cloud = shape.sample(8000, 0.0, 7);
    let target = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .expect("a valid point cloud");
    let opts = ContourOptions {
        resolution: Some(512),
        ..ContourOptions::default()
    };
    let t = Instant::now();
    let (c, crep) = contour(&target, &opts).expect("contour");
    println!(
        "contour torus (8000 points) at 512: octree {} points ({:.2} % of 512³), band level {}, \
         leaves per level {:?}, cut {:?}, {} V / {} F, genus {} in {:.3} s",
        crep.octree_nodes,
        100.0 * crep.octree_nodes as f64 / 512f64.powi(3),
        crep.band_level,
        crep.leaves_per_level,
        crep.cut_leaves_per_level,
        c.num_vertices(),
        c.num_faces(),
        crep.genus,
        t.elapsed().as_secs_f64()
    );
}

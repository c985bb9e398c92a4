//! `subfit info FILE`: format, counts, bounding box and topology of a mesh or point cloud.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use serde::Serialize;
use subfit::io::{Encoding, ReadOptions};
use subfit::mesh::PolyMesh;

use crate::cli::InfoArgs;

/// Everything `info` reports; `--json` prints it as is.
#[derive(Serialize)]
struct Info {
    file: String,
    format: &'static str,
    encoding: &'static str,
    bytes: u64,
    vertices: usize,
    faces: usize,
    /// Polygon size → count (JSON keys are strings).
    faces_by_size: BTreeMap<usize, usize>,
    point_cloud: bool,
    normals: bool,
    colors: bool,
    bbox: Option<BBox>,
    topology: Option<Topology>,
    /// What the reader decided about the file (also printed on stderr).
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct BBox {
    min: [f64; 3],
    max: [f64; 3],
    size: [f64; 3],
    diagonal: f64,
}

/// The topology section: stable JSON names over [`subfit::mesh::MeshReport`].
#[derive(Serialize)]
struct Topology {
    referenced_vertices: usize,
    unreferenced_vertices: usize,
    edges: usize,
    boundary_edges: usize,
    boundary_loops: usize,
    components: usize,
    euler_characteristic: i64,
    /// Total genus, when every component is a manifold, orientable surface.
    genus: Option<u32>,
    closed: bool,
    manifold: bool,
    consistently_oriented: bool,
    non_manifold_edges: usize,
    non_manifold_vertices: usize,
    /// Referenced vertices at exactly the position of another (a mesh split along seams;
    /// `fit` welds them).
    coincident_vertices: usize,
    inconsistent_edges: usize,
    degenerate_faces: usize,
    zero_area_faces: Option<usize>,
    duplicate_faces: usize,
    out_of_range_faces: usize,
    per_component: Vec<subfit::mesh::ComponentReport>,
    /// A few offending elements of each kind (face ids, edges as vertex pairs, vertex ids).
    examples: subfit::mesh::IssueExamples,
}

impl Topology {
    fn new(r: subfit::mesh::MeshReport) -> Self {
        Self {
            referenced_vertices: r.referenced_vertices,
            unreferenced_vertices: r.unreferenced_vertices,
            edges: r.num_edges,
            boundary_edges: r.boundary_edges,
            boundary_loops: r.boundary_loops,
            components: r.num_components,
            euler_characteristic: r.euler_characteristic,
            genus: r.genus,
            closed: r.is_closed,
            manifold: r.is_manifold,
            consistently_oriented: r.is_consistently_oriented,
            non_manifold_edges: r.non_manifold_edges,
            non_manifold_vertices: r.non_manifold_vertices,
            coincident_vertices: 0,
            inconsistent_edges: r.inconsistent_edges,
            degenerate_faces: r.degenerate_faces + r.repeated_vertex_faces,
            zero_area_faces: r.zero_area_faces,
            duplicate_faces: r.duplicate_faces,
            out_of_range_faces: r.out_of_range_faces,
            per_component: r.components,
            examples: r.examples,
        }
    }

    fn to_text(&self) -> String {
        let mut s = String::new();
        let yes = |b: bool| if b { "yes" } else { "no" };
        let _ = writeln!(
            s,
            "topology    {} edges, {} boundary edges in {} loop(s), {} component(s)",
            self.edges, self.boundary_edges, self.boundary_loops, self.components
        );
        let genus = self
            .genus
            .map_or("n/a (not a manifold surface)".to_string(), |g| {
                g.to_string()
            });
        let _ = writeln!(
            s,
            "euler       χ = {}, genus {}",
            self.euler_characteristic, genus
        );
        let _ = writeln!(
            s,
            "closed      {}; manifold {}; consistently oriented {}",
            yes(self.closed),
            yes(self.manifold),
            yes(self.consistently_oriented)
        );
        let defects = [
            ("non-manifold edges", self.non_manifold_edges),
            ("non-manifold vertices", self.non_manifold_vertices),
            (
                "coincident vertices (split seams?)",
                self.coincident_vertices,
            ),
            ("inconsistently oriented edges", self.inconsistent_edges),
            ("degenerate faces", self.degenerate_faces),
            ("zero-area faces", self.zero_area_faces.unwrap_or(0)),
            ("duplicate faces", self.duplicate_faces),
            ("faces with out-of-range indices", self.out_of_range_faces),
            ("unreferenced vertices", self.unreferenced_vertices),
        ];
        let found: Vec<String> = defects
            .iter()
            .filter(|d| d.1 > 0)
            .map(|(n, c)| format!("{c} {n}"))
            .collect();
        let _ = writeln!(
            s,
            "defects     {}",
            if found.is_empty() {
                "none".to_string()
            } else {
                found.join(", ")
            }
        );
        if self.per_component.len() > 1 {
            for (i, c) in self.per_component.iter().enumerate().take(20) {
                let _ = writeln!(
                    s,
                    "component {i:<3} {} faces, {} vertices, {} loop(s), genus {}",
                    c.faces,
                    c.vertices,
                    c.boundary_loops,
                    c.genus.map_or("n/a".to_string(), |g| g.to_string())
                );
            }
        }
        s
    }
}

fn encoding_name(e: Encoding) -> &'static str {
    match e {
        Encoding::Ascii => "ascii",
        Encoding::BinaryLittleEndian => "binary_little_endian",
        Encoding::BinaryBigEndian => "binary_big_endian",
    }
}

fn describe(path: &Path, mesh: &PolyMesh, fi: &subfit::io::FileInfo) -> Info {
    let bbox = mesh.bounding_box().map(|(min, max)| {
        let size = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
        BBox {
            min,
            max,
            size,
            diagonal: (size[0] * size[0] + size[1] * size[1] + size[2] * size[2]).sqrt(),
        }
    });
    let topology = (!mesh.faces.is_empty()).then(|| Topology {
        coincident_vertices: subfit::mesh::coincident_vertices(mesh),
        ..Topology::new(subfit::mesh::diagnose_mesh(mesh))
    });
    Info {
        file: path.display().to_string(),
        format: fi.format.name(),
        encoding: encoding_name(fi.encoding),
        bytes: fi.bytes,
        vertices: mesh.num_vertices(),
        faces: mesh.num_faces(),
        faces_by_size: mesh.faces.size_histogram().into_iter().collect(),
        point_cloud: mesh.is_point_cloud(),
        normals: mesh.normals.is_some(),
        colors: mesh.colors.is_some(),
        bbox,
        topology,
        warnings: fi.warnings.clone(),
    }
}

pub fn run(a: InfoArgs) -> anyhow::Result<ExitCode> {
    let (mesh, fi) = if let Some(f) = a.format {
        let bytes = crate::progress::read_with_progress(&a.file)?;
        let opts = ReadOptions {
            format: Some(f.into()),
            ..ReadOptions::default()
        };
        let out = subfit::io::read_bytes(&bytes, &a.file, &opts)?;
        crate::progress::print_read_warnings(&a.file, &out.1.warnings);
        out
    } else {
        crate::progress::load(&a.file)?
    };
    let info = describe(&a.file, &mesh, &fi);
    if a.json {
        out!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print!("{}", text(&info));
    }
    Ok(ExitCode::SUCCESS)
}

fn text(i: &Info) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "file        {}", i.file);
    let _ = writeln!(
        s,
        "format      {} ({}, {} bytes)",
        i.format, i.encoding, i.bytes
    );
    let attrs = match (i.normals, i.colors) {
        (true, true) => "with normals and colours",
        (true, false) => "with normals",
        (false, true) => "with colours, without normals",
        (false, false) => "without normals",
    };
    if i.point_cloud {
        let _ = writeln!(s, "points      {} ({attrs}), no faces", i.vertices);
    } else {
        let _ = writeln!(s, "vertices    {} ({attrs})", i.vertices);
        let sizes: Vec<String> = i
            .faces_by_size
            .iter()
            .map(|(k, v)| format!("{v} {}", polygon_name(*k)))
            .collect();
        let _ = writeln!(s, "faces       {} ({})", i.faces, sizes.join(", "));
    }
    if let Some(b) = &i.bbox {
        let _ = writeln!(
            s,
            "bbox        [{:.6}, {:.6}, {:.6}] – [{:.6}, {:.6}, {:.6}]",
            b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]
        );
        let _ = writeln!(s, "diagonal    {:.6}", b.diagonal);
    }
    if let Some(t) = &i.topology {
        s.push_str(&t.to_text());
    }
    s
}

fn polygon_name(n: usize) -> String {
    match n {
        3 => "triangles".into(),
        4 => "quads".into(),
        n => format!("{n}-gons"),
    }
}

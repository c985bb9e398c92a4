//! Parts written twice, once inside out: what keeping both sides of a duplicated face leaves
//! after [`crate::cut_nonmanifold_edges`].
//!
//! [`crate::clean_faces`] keeps a face that repeats another's vertices in the opposite turn,
//! because a scan's thin part collapsed by the reconstruction is such a sheet of no thickness,
//! both of whose sides continue the surface (the cut pairs each side with the side of the
//! surface it faces). A mesh exported double-sided (every face written again, turned, for a
//! renderer that culls back faces) has the same pairs, and the cut makes them into surfaces
//! that enclose nothing. Two such results are recognised here, by faces whose *twin* — a
//! face at the same positions turned the other way — lies in the same or another connected
//! component (Attene et al., "Polygon mesh repairing: an application perspective", ACM
//! Computing Surveys 45(2), 2013, §3.3 on duplicated and overlapping elements):
//!
//! * a *pillow*: a closed component every face of which has its twin in the component (an open
//!   sheet written double-sided, glued along its rim by the cut). One side is kept: a
//!   breadth-first search from its lowest face across edges keeps every face it reaches whose
//!   twin it has not kept. The result is the open sheet.
//! * a *copy*: a component every face of which has its twin in one other component (a patch of
//!   a surface written again turned, which the cut takes off as a sheet of its own). It is
//!   dropped; when the other component is a copy of it too (a closed surface written
//!   double-sided), one of the two is: the one whose signed volume is negative (inside out)
//!   when the volume decides, otherwise the later one.
//!
//! Components with some faces untwinned (a thin part of a scan) are left alone. Positions are
//! never changed; vertices of dropped faces stay, unused. Cost `O(#H log #H)`.

use std::collections::HashMap;

use crate::edges::{corner_faces, corner_next, group_edges};
use crate::polygons::{PolyMesh, Polygons};

/// What [`drop_twin_sides`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TwinReport {
    /// Pillows reduced to one side.
    pub pillows_halved: usize,
    /// Components dropped as the inside-out copy of another.
    pub copies_dropped: usize,
    /// Faces dropped by both.
    pub faces_dropped: usize,
}

/// Reduces pillows to one side and drops inside-out copies of components, as the module docs
/// say. Faces must be valid (in range, no repeated vertex). The mesh is unchanged when there is
/// neither.
pub fn drop_twin_sides(mesh: &mut PolyMesh) -> TwinReport {
    let mut report = TwinReport::default();
    let nf = mesh.faces.len();
    let twin = twins(&mesh.faces, &mesh.positions);
    if twin.iter().all(|&t| t == u32::MAX) {
        return report;
    }
    let comps = crate::face_components(&mesh.faces, mesh.num_vertices());
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); comps.count];
    for (f, &c) in comps.face_labels.iter().enumerate() {
        if c != u32::MAX {
            members[c as usize].push(f as u32);
        }
    }
    // Per component: the single component holding the twins of all its faces, if any.
    let twin_comp: Vec<Option<u32>> = members
        .iter()
        .map(|list| {
            let mut of = list.iter().map(|&f| match twin[f as usize] {
                u32::MAX => u32::MAX,
                t => comps.face_labels[t as usize],
            });
            let first = of.next()?;
            (first != u32::MAX && of.all(|c| c == first)).then_some(first)
        })
        .collect();
    let mut drop = vec![false; nf];
    let adjacency = edge_neighbours(&mesh.faces, mesh.num_vertices());
    for (c, list) in members.iter().enumerate() {
        match twin_comp[c] {
            Some(t) if t as usize == c => {
                halve(list, &twin, &adjacency, &mut drop);
                report.pillows_halved += 1;
            }
            // Each of the pair copies the other: one goes, decided at the later of the two.
            Some(t) if twin_comp[t as usize] == Some(c as u32) && (t as usize) < c => {
                let inside_out = |k: usize| {
                    signed_volume(&mesh.faces, &members[k], &mesh.positions)
                        .is_some_and(|v| v < 0.0)
                };
                let gone = if inside_out(t as usize) && !inside_out(c) {
                    t as usize
                } else {
                    c
                };
                for &f in &members[gone] {
                    drop[f as usize] = true;
                }
                report.copies_dropped += 1;
            }
            Some(t) if twin_comp[t as usize] == Some(c as u32) => {}
            Some(_) => {
                // A copy of a part of another component, which has faces of its own.
                for &f in list {
                    drop[f as usize] = true;
                }
                report.copies_dropped += 1;
            }
            _ => {}
        }
    }
    report.faces_dropped = drop.iter().filter(|&&d| d).count();
    if report.faces_dropped > 0 {
        let mut out = Polygons::with_capacity(nf, mesh.faces.indices().len());
        for (f, face) in mesh.faces.iter().enumerate() {
            if !drop[f] {
                out.push(face);
            }
        }
        mesh.faces = out;
    }
    report
}

/// Per face its twin (see the module docs), or `u32::MAX`: faces at the same positions (as
/// sets, compared bitwise) matched first come first between the two turns. Cost `O(#H)`
/// expected, with hash maps.
fn twins(faces: &Polygons, positions: &[[f64; 3]]) -> Vec<u32> {
    let mut class: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let n = class.len() as u32;
            *class.entry(p.map(|c| (c + 0.0).to_bits())).or_insert(n)
        })
        .collect();
    let mut waiting: HashMap<(Vec<u32>, bool), Vec<u32>> = HashMap::new();
    let mut twin = vec![u32::MAX; faces.len()];
    for (f, face) in faces.iter().enumerate() {
        let mapped: Vec<u32> = face.iter().map(|&v| ids[v as usize]).collect();
        let mut key = mapped.clone();
        key.sort_unstable();
        if key.windows(2).any(|w| w[0] == w[1]) {
            continue;
        }
        let turn = crate::nonmanifold::turn(&mapped);
        match waiting.get_mut(&(key.clone(), !turn)).and_then(|q| q.pop()) {
            Some(g) => {
                twin[f] = g;
                twin[g as usize] = f as u32;
            }
            None => waiting.entry((key, turn)).or_default().push(f as u32),
        }
    }
    twin
}

/// Per face its neighbours across edges of exactly two faces, as CSR `(starts, list)`.
fn edge_neighbours(faces: &Polygons, nv: usize) -> (Vec<u32>, Vec<u32>) {
    let next = corner_next(faces);
    let face_of = corner_faces(faces);
    let groups = group_edges(faces, &next, nv, |_| true);
    let mut starts = vec![0u32; faces.len() + 1];
    let pairs: Vec<(u32, u32)> = (0..groups.len())
        .filter_map(|e| match groups.group(e) {
            &[a, b] => Some((face_of[a as usize], face_of[b as usize])),
            _ => None,
        })
        .collect();
    for &(a, b) in &pairs {
        starts[a as usize + 1] += 1;
        starts[b as usize + 1] += 1;
    }
    for f in 0..faces.len() {
        starts[f + 1] += starts[f];
    }
    let mut fill = starts.clone();
    let mut list = vec![0u32; starts[faces.len()] as usize];
    for &(a, b) in &pairs {
        for (x, y) in [(a, b), (b, a)] {
            list[fill[x as usize] as usize] = y;
            fill[x as usize] += 1;
        }
    }
    (starts, list)
}

/// Marks in `drop` one side of the pillow `list`: breadth-first from its lowest face, a face
/// reached is kept unless its twin was kept.
fn halve(list: &[u32], twin: &[u32], (starts, adj): &(Vec<u32>, Vec<u32>), drop: &mut [bool]) {
    let mut kept = std::collections::HashSet::new();
    let mut queue = std::collections::VecDeque::from([list[0]]);
    kept.insert(list[0]);
    while let Some(f) = queue.pop_front() {
        for &g in &adj[starts[f as usize] as usize..starts[f as usize + 1] as usize] {
            if !kept.contains(&g) && !kept.contains(&twin[g as usize]) {
                kept.insert(g);
                queue.push_back(g);
            }
        }
    }
    for &f in list {
        drop[f as usize] = !kept.contains(&f);
    }
}

/// Signed volume enclosed by the faces `list` (fan triangles about their centroid); `None` when
/// it is not decisive ([`crate::reorient::VOLUME_DECISIVE`] of the sum of the absolute terms).
fn signed_volume(faces: &Polygons, list: &[u32], positions: &[[f64; 3]]) -> Option<f64> {
    use crate::vec3::{cross, dot, sub};
    let corners = list.iter().flat_map(|&f| faces.face(crate::FaceId(f)));
    let (mut c, mut n) = ([0.0; 3], 0.0);
    for &v in corners {
        c = crate::vec3::add(c, positions[v as usize]);
        n += 1.0;
    }
    let c = crate::vec3::scale(c, 1.0 / f64::max(n, 1.0));
    let (mut vol, mut abs) = (0.0, 0.0);
    for &f in list {
        let poly = faces.face(crate::FaceId(f));
        let p = |i: usize| sub(positions[poly[i] as usize], c);
        for i in 1..poly.len() - 1 {
            let t = dot(p(0), cross(p(i), p(i + 1)));
            vol += t;
            abs += t.abs();
        }
    }
    (abs > 0.0 && vol.abs() >= crate::reorient::VOLUME_DECISIVE * abs).then_some(vol)
}

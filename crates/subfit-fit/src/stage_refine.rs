//! Refinement of a cage between stages ([`crate::stages`]): the faces whose error is above the
//! tolerance (or in an error field, [`crate::error_field`]) are split, worst first and crease
//! faces preferred, within the growth and control-point budget and the refinement depth —
//! red-green for Loop (Cheng et al. 2004 §4.5), the polygon templates of
//! [`crate::refine_polygons`] for every other scheme (Lavoué et al. 2005 §5.2) — and the tags
//! are carried to the refined cage.

use std::collections::HashSet;

use subfit_mesh::{PolyMesh, Polygons, Tags, SHARPNESS_INFINITE};
use subfit_subdiv::{Options, Scheme};

use crate::error::FitError;
use crate::options::FitOptions;
use crate::refine_polygons::refine_polygons;
use crate::remesh::{refine_red_green_with_parents, RefineStats};
use crate::stage_options::StageOptions;

/// A refined cage: what was done, a value per new face (its parent, or its depth) and the
/// carried tags.
pub(crate) struct Refined<T> {
    pub(crate) mesh: PolyMesh,
    pub(crate) stats: RefineStats,
    pub(crate) per_face: Vec<T>,
    pub(crate) tags: Tags,
}

/// How a cage is split: red-green for Loop, the polygon templates for every other scheme
/// (whatever the cage's faces are: "not Loop" means polygons).
pub(crate) enum Splitter {
    RedGreen,
    Polygons(Options),
}

impl Splitter {
    pub(crate) fn for_options(opts: &FitOptions) -> Self {
        if opts.scheme == Scheme::Loop {
            Self::RedGreen
        } else {
            Self::Polygons(opts.subdivision())
        }
    }

    /// The refined cage, what was done, the parent of every face and the carried tags; `None`
    /// when this splitter does not apply (red-green on a non-triangle cage).
    fn split(
        &self,
        mesh: &PolyMesh,
        tags: &Tags,
        marked: &[bool],
    ) -> Result<Option<Refined<u32>>, FitError> {
        Ok(match self {
            Self::RedGreen => {
                refine_red_green_with_parents(mesh, tags, marked).map(|(m, stats, p)| {
                    let tags = carry_tags(tags, mesh.num_vertices(), &m.faces);
                    Refined {
                        mesh: m,
                        stats,
                        per_face: p,
                        tags,
                    }
                })
            }
            Self::Polygons(opts) => {
                let r = refine_polygons(mesh, tags, marked, opts)?;
                Some(Refined {
                    mesh: r.mesh,
                    stats: r.stats,
                    per_face: r.parents,
                    tags: r.tags,
                })
            }
        })
    }
}

/// How much a face along a crease is preferred when refinement cannot split every face above
/// the tolerance (the growth or control-point budget): its score counts this many times for
/// the order (not for whether it is above the tolerance). A sharp feature is where a smooth
/// patch misses most and where a split buys most ("refinement prefers feature
/// regions").
pub(crate) const FEATURE_PRIORITY: f64 = 2.0;

/// Marks the faces scoring above 1, worst first (crease faces preferred: [`FEATURE_PRIORITY`]),
/// within the growth and control-point budget and the refinement depth, and refines them with `how`. Returns the new mesh, what was done,
/// the depth of every new face and the carried tags.
pub(crate) fn refine_step(
    mesh: &PolyMesh,
    tags: &Tags,
    score: &[f64],
    depth: &[u8],
    stages: &StageOptions,
    how: &Splitter,
) -> Result<Option<Refined<u8>>, FitError> {
    let n = mesh.num_vertices();
    let room = stages.max_control_points.saturating_sub(n);
    let allowed = room.min(((n as f64) * stages.growth).ceil() as usize);
    if allowed == 0 {
        return Ok(None);
    }
    // Faces above the tolerance, those along a crease first (by FEATURE_PRIORITY).
    let mut order: Vec<(f64, usize)> = score
        .iter()
        .enumerate()
        .filter(|&(f, &s)| depth[f] < stages.max_depth && s > 1.0)
        .map(|(f, &s)| {
            let face = mesh.faces.face(subfit_mesh::FaceId(f as u32));
            let creased = !tags.is_empty()
                && (0..face.len()).any(|i| {
                    tags.crease(face[i], face[(i + 1) % face.len()]) >= SHARPNESS_INFINITE
                });
            (if creased { FEATURE_PRIORITY * s } else { s }, f)
        })
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    if order.is_empty() {
        return Ok(None);
    }
    // A split face adds about 1.5 points (3 edges, each shared by two faces), plus closure.
    let mut take = order
        .len()
        .min((allowed as f64 / 1.5).ceil() as usize)
        .max(1);
    loop {
        let mut marked = vec![false; mesh.faces.len()];
        for &(_, f) in &order[..take] {
            marked[f] = true;
        }
        let Some(Refined {
            mesh: refined,
            stats,
            per_face: parents,
            tags: new_tags,
        }) = how.split(mesh, tags, &marked)?
        else {
            return Ok(None);
        };
        if refined.num_vertices() <= n + allowed || take == 1 {
            if refined.num_vertices() > stages.max_control_points {
                return Ok(None);
            }
            // An unsplit face (its parent's only child) keeps its depth; children of a split
            // face (red or green) are one deeper.
            let mut children = vec![0u32; mesh.faces.len()];
            for &p in &parents {
                children[p as usize] += 1;
            }
            let d = parents
                .iter()
                .map(|&p| {
                    let dp = depth[p as usize];
                    if children[p as usize] > 1 {
                        dp.saturating_add(1)
                    } else {
                        dp
                    }
                })
                .collect();
            return Ok(Some(Refined {
                mesh: refined,
                stats,
                per_face: d,
                tags: new_tags,
            }));
        }
        take = (take * 3 / 4).max(1);
    }
}

/// The tags of a cage carried to its refinement (`faces`, whose first `old_n` points are the
/// cage's): a tagged edge that is still an edge keeps its tag; a split one passes it to both
/// halves, through its new midpoint (the new point joined to both ends), with
/// [`crate::refine_polygons::split_sharpness`]. Corners keep theirs.
pub(crate) fn carry_tags(tags: &Tags, old_n: usize, faces: &Polygons) -> Tags {
    if tags.is_empty() {
        return Tags::new();
    }
    let mut edges: HashSet<(u32, u32)> = HashSet::new();
    for f in faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let has = |a: u32, b: u32| edges.contains(&(a.min(b), a.max(b)));
    // New points by their neighbours among the old ones.
    let mut by_ends: std::collections::HashMap<(u32, u32), u32> = Default::default();
    let mut nbrs: Vec<Vec<u32>> = Vec::new();
    for &(a, b) in &edges {
        for (o, m) in [(a, b), (b, a)] {
            if (m as usize) >= old_n && (o as usize) < old_n {
                let k = m as usize - old_n;
                if nbrs.len() <= k {
                    nbrs.resize(k + 1, Vec::new());
                }
                nbrs[k].push(o);
            }
        }
    }
    for (k, ns) in nbrs.iter().enumerate() {
        for (i, &a) in ns.iter().enumerate() {
            for &b in &ns[i + 1..] {
                by_ends.insert((a.min(b), a.max(b)), (old_n + k) as u32);
            }
        }
    }
    let mut out = Tags::new();
    for ((a, b), s) in tags.creases() {
        if has(a, b) {
            out.set_crease(a, b, s);
        } else if let Some(&m) = by_ends.get(&(a.min(b), a.max(b))) {
            let half = crate::refine_polygons::split_sharpness(s);
            out.set_crease(a, m, half);
            out.set_crease(m, b, half);
        }
    }
    for (v, s) in tags.corners() {
        out.set_corner(v, s);
    }
    out
}

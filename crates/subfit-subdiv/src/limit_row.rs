//! The closed-form limit row of one vertex: its limit position and tangent masks (module
//! `mask`: Halstead et al. 1993, Loop's limit, OpenSubdiv 3.5 tangent masks) laid over its
//! ring. Used by the whole-mesh limit stencils ([`crate::limit`]) and by the local refinement
//! of semi-sharp neighbourhoods (module `semi_limit`), which ends on these rows once no finite
//! sharpness is left (DeRose, Kass & Truong 1998, §3).

use crate::mask::Mask;
use crate::refine::face_kinds;
use crate::scheme::{classify, Neighborhood, Options, Scheme};
use crate::topology::Topology;
use subfit_mesh::Tags;

/// The three limit masks of the last neighbourhood seen: consecutive vertices mostly share
/// their neighbourhood (valence, rule), so the masks are recomputed only when it changes.
/// `weights` holds them interleaved in row order: the vertex, its ring edges, its faces (as
/// many as both the masks and the vertex have).
#[derive(Default)]
pub(crate) struct LimitMasks {
    hood: Option<Neighborhood>,
    masks: [Mask; 3],
    weights: Vec<[f64; 3]>,
}

/// Appends the limit row of vertex `v` (position and two tangent weights per entry; repeated
/// columns possible) to `row`: `ring` holds the far ends of its ring edges and `diagonal(i)` is
/// the vertex two corners away from `v` in its ring face `i` (the quad's diagonal).
pub(crate) fn push_limit_row(
    scheme: Scheme,
    hood: &Neighborhood,
    cache: &mut LimitMasks,
    v: u32,
    ring: &[u32],
    diagonal: impl Fn(usize) -> u32,
    row: &mut Vec<(u32, [f64; 3])>,
) {
    if cache.hood.as_ref() != Some(hood) {
        let [p, a, b] = &mut cache.masks;
        scheme.limit_masks(hood, p, a, b);
        cache.hood = Some(*hood);
        let nf = p.faces.len().max(a.faces.len()).max(b.faces.len());
        let get = |m: &Mask, i: usize| m.faces.get(i).copied().unwrap_or(0.0);
        cache.weights.clear();
        cache.weights.push([p.vertex, a.vertex, b.vertex]);
        cache
            .weights
            .extend((0..hood.num_edges).map(|i| [p.edges[i], a.edges[i], b.edges[i]]));
        cache
            .weights
            .extend((0..nf.min(hood.num_faces)).map(|i| [get(p, i), get(a, i), get(b, i)]));
    }
    let w = &cache.weights;
    let (ne, nf) = (ring.len(), w.len() - 1 - ring.len());
    debug_assert_eq!(ne, hood.num_edges);
    row.reserve(w.len());
    row.push((v, w[0]));
    row.extend(ring.iter().copied().zip(w[1..=ne].iter().copied()));
    row.extend((0..nf).map(diagonal).zip(w[1 + ne..].iter().copied()));
}

/// [`push_limit_row`] for vertex `v` of `topo`, its rule classified from `tags` (boundary and
/// infinitely sharp edges, corner tags; finite sharpness is not looked at). Cost O(valence).
pub(crate) fn push_topology_limit_row_for(
    topo: &Topology,
    tags: &Tags,
    options: &Options,
    v: u32,
    row: &mut Vec<(u32, [f64; 3])>,
) {
    let tagged = !tags.is_empty();
    let sharp = topo
        .vertex_edges(v)
        .iter()
        .zip(topo.vertex_ring(v))
        .map(|(&e, &u)| topo.is_boundary_edge(e) || (tagged && tags.is_sharp_edge(v, u)));
    let hood = classify(
        sharp,
        topo.vertex_corners(v).len(),
        face_kinds(topo, v),
        tagged && tags.is_corner(v),
        options.boundary,
    );
    let mut masks = LimitMasks::default();
    push_topology_limit_row(topo, options.scheme, &hood, &mut masks, v, row);
}

/// [`push_limit_row`] for vertex `v` of `topo`.
pub(crate) fn push_topology_limit_row(
    topo: &Topology,
    scheme: Scheme,
    hood: &Neighborhood,
    cache: &mut LimitMasks,
    v: u32,
    row: &mut Vec<(u32, [f64; 3])>,
) {
    let corners = topo.vertex_corners(v);
    let diagonal = |i: usize| topo.corner_vertex(topo.corner_next(topo.corner_next(corners[i])));
    push_limit_row(scheme, hood, cache, v, topo.vertex_ring(v), diagonal, row);
}

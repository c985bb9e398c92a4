//! Subdivision schemes, boundary rules and options, in OpenSubdiv's `Sdc` vocabulary.
//!
//! Sources: Loop 1987 (*Smooth subdivision surfaces based on triangles*, MSc thesis, Utah);
//! Catmull & Clark 1978 (*Recursively generated B-spline surfaces on arbitrary topological
//! meshes*); Hoppe et al. 1994 (*Piecewise smooth surface reconstruction*) for sharp creases and
//! corners; OpenSubdiv 3.5 `sdc/` documentation ("Subdivision Surfaces" and "Sharpness and
//! creasing") for the vocabulary (vertex rules Smooth / Dart / Crease / Corner and the
//! `VTX_BOUNDARY_*` interpolation rules).
//!
//! Nothing here knows about mesh storage: a vertex is described to the scheme by a
//! [`Neighborhood`] (how many edges and faces surround it, which rule applies, where the crease
//! edges are in its ring), and the scheme fills masks from it (see [`crate::mask`]).

/// A subdivision scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Loop 1987: triangle meshes only; 1→4 triangle split; box-spline (quartic) regular patches.
    #[default]
    Loop,
    /// Catmull & Clark 1978: any polygons; every `n`-gon is split into `n` quads at the first
    /// level (face point + edge points), after which the mesh is all quads; bicubic B-spline
    /// regular patches.
    CatmullClark,
    /// The quad/triangle hybrid of Stam & Loop 2003 (*Quad/triangle subdivision*, CGF 22(1)), as
    /// used by Lavoué et al. (§3.1, Fig. 8): triangles split 1→4 into triangles (no face point),
    /// quads 1→4 into quads (face point), `n`-gons (`n ≥ 5`) into `n` quads as Catmull-Clark.
    /// The rules are "linear subdivision, then averaging": Loop's exactly where a vertex or edge
    /// sees only triangles, Catmull-Clark's where it sees no triangle, and the average of the
    /// incident children's centroids (triangles weighted 1/4, 3/8, 3/8) where both meet (see
    /// [`crate::mask`]). Limits at mixed vertices come from the eigenvectors of the local
    /// subdivision matrix (module `mixed`).
    QuadTriangle,
}

impl Scheme {
    /// The face size of the regular case (3 for Loop, 4 for Catmull-Clark).
    /// For [`Scheme::QuadTriangle`] 4 (its regular quads; its regular triangles are Loop's).
    pub fn regular_face_size(self) -> usize {
        match self {
            Scheme::Loop => 3,
            Scheme::CatmullClark | Scheme::QuadTriangle => 4,
        }
    }

    /// Whether a non-triangle face gets a face point (and is split into quads): Catmull-Clark and
    /// quad/triangle; Loop has triangles only.
    pub fn splits_into_quads(self, face_len: usize) -> bool {
        match self {
            Scheme::Loop => false,
            Scheme::CatmullClark => true,
            Scheme::QuadTriangle => face_len != 3,
        }
    }

    /// The valence of a regular interior vertex (6 for Loop, 4 for Catmull-Clark).
    /// For [`Scheme::QuadTriangle`] 4 (all-quad regions).
    pub fn regular_valence(self) -> usize {
        match self {
            Scheme::Loop => 6,
            Scheme::CatmullClark | Scheme::QuadTriangle => 4,
        }
    }

    /// The name used on command lines and in files (`loop`, `catmull-clark`, `quad-tri`).
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Loop => "loop",
            Scheme::CatmullClark => "catmull-clark",
            Scheme::QuadTriangle => "quad-tri",
        }
    }
}

/// How boundary vertices and edges are treated, as OpenSubdiv's `VtxBoundaryInterpolation`.
///
/// In both rules every boundary edge is an infinitely sharp crease, so the limit boundary is the
/// uniform cubic B-spline of the boundary polygon (between corners).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BoundaryRule {
    /// `VTX_BOUNDARY_EDGE_ONLY`: boundary edges are sharp; boundary vertices on a single face
    /// (valence 2) follow the crease rule like any other boundary vertex (they are smooth
    /// along the boundary curve, not corners).
    #[default]
    EdgeOnly,
    /// `VTX_BOUNDARY_EDGE_AND_CORNER`: as `EdgeOnly`, and every boundary vertex on exactly one
    /// face is an infinitely sharp corner (it is interpolated).
    EdgeAndCorner,
}

/// Options for refinement and limit evaluation.
///
/// Creases and corners follow OpenSubdiv's uniform creasing (`CREASE_UNIFORM`, DeRose, Kass &
/// Truong 1998; see [`crate::crease`]). A crease or corner tag with sharpness at least
/// [`subfit_mesh::SHARPNESS_INFINITE`] (10, OpenSubdiv's infinite value) is sharp at every level
/// (Hoppe et al. 1994 rules). A finite sharpness `s > 0` is semi-sharp: it is held in single
/// precision as OpenSubdiv holds it, the crease rules apply for `⌊s⌋` levels, the next level
/// blends the sharp and smooth rules by the fractional part (edge points by `s`, vertex points by
/// OpenSubdiv's fractional weight), and refinement passes `s − 1` to the child edges and
/// vertices (dropped at 0). Limit stencils, the sampling operator, exact evaluation and closest
/// points refine locally (or, for the stencils, the whole mesh) until no finite sharpness is
/// left around a vertex before applying the closed-form limit masks, so the limit surface is
/// exact there too; this costs up to `⌈s⌉` extra levels where finite sharpness exists.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Options {
    /// The subdivision scheme. Default: [`Scheme::Loop`].
    pub scheme: Scheme,
    /// The boundary interpolation rule. Default: [`BoundaryRule::EdgeOnly`].
    pub boundary: BoundaryRule,
    /// Catmull-Clark's edge rule next to triangles (OpenSubdiv `TriangleSubdivision`, USD
    /// `triangleSubdivisionRule`). Default: [`TriangleRule::Catmark`]. Only the refinement
    /// matrices and the sampling operator honour [`TriangleRule::Smooth`].
    pub triangles: TriangleRule,
}

/// OpenSubdiv's `Sdc::Options::TriangleSubdivision` for Catmull-Clark.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TriangleRule {
    /// `TRI_SUB_CATMARK`: the plain Catmull-Clark rules on triangles.
    #[default]
    Catmark,
    /// `TRI_SUB_SMOOTH`: an edge point next to a triangle weights the face points by the mean
    /// of 0.47 (per triangle) and 1/4 (per other face), OpenSubdiv `catmarkScheme.h`; USD's
    /// `triangleSubdivisionRule = "smooth"`.
    Smooth,
}

impl Options {
    /// Options for `scheme` with the default boundary rule.
    pub fn new(scheme: Scheme) -> Self {
        Self {
            scheme,
            boundary: BoundaryRule::default(),
            triangles: TriangleRule::default(),
        }
    }

    /// Builder-style setter for the scheme.
    pub fn with_scheme(mut self, scheme: Scheme) -> Self {
        self.scheme = scheme;
        self
    }

    /// Builder-style setter for the Catmull-Clark triangle rule.
    pub fn with_triangles(mut self, triangles: TriangleRule) -> Self {
        self.triangles = triangles;
        self
    }

    /// Builder-style setter for the boundary rule.
    pub fn with_boundary(mut self, boundary: BoundaryRule) -> Self {
        self.boundary = boundary;
        self
    }
}

/// The rule that applies at a vertex (OpenSubdiv `Sdc::Crease::Rule`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexRule {
    /// No sharp incident edge: the smooth rule.
    Smooth,
    /// Exactly one sharp incident edge (interior): the smooth rule applies.
    Dart,
    /// Exactly two sharp incident edges (including boundary edges): the crease rule
    /// (1/8, 3/4, 1/8; the limit is the cubic B-spline of the crease polygon).
    Crease,
    /// A corner tag, three or more sharp edges, an `EdgeAndCorner` boundary vertex on one face,
    /// or an isolated vertex: the vertex is fixed.
    Corner,
}

impl VertexRule {
    /// The rule of a vertex with `num_edges` incident edges on `num_faces` faces, `nsharp` of
    /// the edges sharp (boundary edges count as sharp), a corner tag or not, under `boundary`.
    pub fn classify(
        num_edges: usize,
        num_faces: usize,
        nsharp: usize,
        corner_tag: bool,
        boundary: BoundaryRule,
    ) -> Self {
        let corner = num_edges == 0
            || nsharp > 2
            || corner_tag
            || (boundary == BoundaryRule::EdgeAndCorner && num_faces == 1 && num_edges == 2);
        match (corner, nsharp) {
            (true, _) => VertexRule::Corner,
            (false, 2) => VertexRule::Crease,
            (false, 1) => VertexRule::Dart,
            _ => VertexRule::Smooth,
        }
    }
}

/// What a scheme needs to know about a vertex to fill its masks.
///
/// The vertex's ring is ordered counter-clockwise (seen with the face winding counter-clockwise):
/// edge `i` joins the vertex to its `i`-th ring neighbour and face `i` lies between edges `i` and
/// `i + 1`. At a boundary vertex edge 0 is the leading boundary edge, so there is one more edge
/// than faces. This is OpenSubdiv's `Vtr` ordering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Neighborhood {
    /// Number of incident edges (the valence).
    pub num_edges: usize,
    /// Number of incident faces (`num_edges` for an interior vertex, `num_edges - 1` at a
    /// boundary).
    pub num_faces: usize,
    /// The rule at the vertex.
    pub rule: VertexRule,
    /// For [`VertexRule::Crease`]: the ring positions of the two sharp edges, ascending; the
    /// first is the "leading" crease edge. For [`VertexRule::Dart`]: `crease_ends[0]` is the
    /// ring position of the sharp edge. Ignored for other rules.
    pub crease_ends: [usize; 2],
    /// Which incident faces are triangles (only the quad/triangle scheme's rules read it).
    pub faces: FaceKinds,
}

/// Which faces around a vertex are triangles, in ring order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FaceKinds {
    /// Every incident face is a triangle.
    #[default]
    Triangles,
    /// No incident face is a triangle (quads, or `n`-gons before their first split).
    Polygons,
    /// Both: bit `i` is set when ring face `i` is a triangle. Only for vertices on at most 64
    /// faces (the quad/triangle scheme refuses mixed vertices on more, see
    /// [`crate::SubdivError::MixedValence`]).
    Mixed(u64),
}

impl FaceKinds {
    /// The kinds of faces given in ring order (`true` = triangle).
    pub fn from_triangles(is_triangle: impl IntoIterator<Item = bool>) -> Self {
        let (mut bits, mut tris, mut n) = (0u64, 0usize, 0usize);
        for (i, t) in is_triangle.into_iter().enumerate() {
            if t {
                tris += 1;
                if i < 64 {
                    bits |= 1 << i;
                }
            }
            n += 1;
        }
        if tris == n {
            FaceKinds::Triangles
        } else if tris == 0 {
            FaceKinds::Polygons
        } else {
            FaceKinds::Mixed(bits)
        }
    }

    /// Whether ring face `i` is a triangle.
    pub fn is_triangle(self, i: usize) -> bool {
        match self {
            FaceKinds::Triangles => true,
            FaceKinds::Polygons => false,
            FaceKinds::Mixed(bits) => i < 64 && bits >> i & 1 == 1,
        }
    }
}

/// What a scheme needs to know about an edge to fill its mask.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeNeighborhood {
    /// Number of incident faces (1 on a boundary, 2 inside).
    pub num_faces: usize,
    /// Whether the edge is infinitely sharp (boundary edges always are).
    pub sharp: bool,
    /// Whether each incident face (the first `num_faces`) is a triangle (only the quad/triangle
    /// scheme reads it).
    pub triangles: [bool; 2],
}

/// The [`Neighborhood`] of a vertex from the sharpness of its ring edges (in ring order), its
/// face count and kinds and whether it carries a corner tag. Cost O(valence).
#[inline]
pub(crate) fn classify(
    edge_sharp: impl ExactSizeIterator<Item = bool>,
    num_faces: usize,
    faces: FaceKinds,
    corner_tag: bool,
    boundary: BoundaryRule,
) -> Neighborhood {
    let num_edges = edge_sharp.len();
    let mut ends = [0usize; 2];
    let mut nsharp = 0;
    for (i, sharp) in edge_sharp.enumerate() {
        if sharp {
            if nsharp < 2 {
                ends[nsharp] = i;
            }
            nsharp += 1;
        }
    }
    let rule = VertexRule::classify(num_edges, num_faces, nsharp, corner_tag, boundary);
    Neighborhood {
        num_edges,
        num_faces,
        rule,
        crease_ends: ends,
        faces,
    }
}

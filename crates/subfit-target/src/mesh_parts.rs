//! The connected components of a mesh target's triangles and whether each encloses a volume:
//! what [`Target::mesh_foot_points_facing`] needs to orient each separate sheet on its own and
//! to leave sheets, which have no inside, alone.

use crate::target::Target;

/// The largest share of a mesh component's edges that may be boundary edges for the component
/// to count as closed ([`Target::closed_components`]): small holes (a scanner's, a repair's)
/// leave its inside an inside.
pub const CLOSED_BOUNDARY_SHARE: f64 = 0.01;

impl Target {
    /// The connected component of every triangle of [`Self::mesh`] (triangles sharing a vertex
    /// are connected; `#T` labels, empty for a point cloud), e.g. to orient each separate sheet
    /// of an open target on its own. Computed on the first call (O(#T log #T), with
    /// [`Self::closed_components`]) and kept.
    pub fn triangle_components(&self) -> &[u32] {
        &self.components_and_closure().0
    }

    /// Per component of [`Self::triangle_components`], whether it bounds a volume: at most
    /// [`CLOSED_BOUNDARY_SHARE`] of its edges are boundary edges (a scan with a few small
    /// holes still encloses its inside; a sheet or a single view does not).
    pub fn closed_components(&self) -> &[bool] {
        &self.components_and_closure().1
    }

    fn components_and_closure(&self) -> &(Vec<u32>, Vec<bool>) {
        self.triangle_components.get_or_init(|| {
            let Some(bvh) = self.mesh() else {
                return (Vec::new(), Vec::new());
            };
            let faces = subfit_mesh::Polygons::from_triangles(bvh.triangles());
            let c = subfit_mesh::face_components(&faces, bvh.vertices().len());
            // Every edge with the component of a triangle using it, sorted so that an edge's
            // uses are adjacent: an edge used once is a boundary edge.
            let mut edges: Vec<(u32, u32, u32)> = bvh
                .triangles()
                .iter()
                .zip(&c.face_labels)
                .flat_map(|(t, &l)| {
                    (0..3).map(move |k| {
                        let (a, b) = (t[k], t[(k + 1) % 3]);
                        (a.min(b), a.max(b), l)
                    })
                })
                .collect();
            edges.sort_unstable();
            let (mut all, mut open) = (vec![0usize; c.count], vec![0usize; c.count]);
            for run in edges.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1) {
                if let Some(l) = all.get_mut(run[0].2 as usize) {
                    *l += 1;
                    if run.len() == 1 {
                        open[run[0].2 as usize] += 1;
                    }
                }
            }
            let closed = all
                .iter()
                .zip(&open)
                .map(|(&a, &o)| (o as f64) <= CLOSED_BOUNDARY_SHARE * a as f64)
                .collect();
            (c.face_labels, closed)
        })
    }
}

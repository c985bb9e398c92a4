//! The smoothing term `F_s = λ/n Σ_i |W(P_i)|²` with the umbrella Laplacian
//! `W(P_i) = P_i − mean_{j ∈ N(i)} P_j` over the control mesh's one-ring (Cheng et al. 2007,
//! §II-E; Cheng 2004 §4.4). In matrix form `F_s = λ/n ‖L P‖²` (per coordinate) with
//! `L = I − D⁻¹A`; its normal-equation contribution is `λ/n · LᵀL ⊗ I3`.
//!
//! With crease and corner tags ([`Laplacian::umbrella_tagged`]) the umbrella follows Hoppe et
//! al. 1994's rules instead of rounding the features off: a vertex on a crease (two sharp
//! edges) is averaged with its two crease neighbours only, a corner (tagged, or three or more
//! sharp edges, boundary edges counted as sharp, as OpenSubdiv counts them) is not smoothed.

use subfit_mesh::{Polygons, Tags};

/// The umbrella Laplacian `L` as CSR rows over the control points (`n × n`): row `i` holds
/// `1` at `i` and `−1/|N(i)|` at each one-ring neighbour (neighbours = vertices sharing an edge
/// of a face). A vertex without neighbours gets an empty row (it is not smoothed).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Laplacian {
    /// Row offsets, `n + 1`.
    pub offsets: Vec<usize>,
    /// Column indices, sorted within a row.
    pub indices: Vec<u32>,
    /// Weights (dimensionless); each non-empty row sums to 0.
    pub weights: Vec<f64>,
}

impl Laplacian {
    /// Builds `L` for `faces` over `n` control points. Cost: O(Σ face sizes · log).
    ///
    /// # Panics
    /// If a face index is `≥ n`.
    #[track_caller]
    pub fn umbrella(faces: &Polygons, n: usize) -> Self {
        Self::umbrella_tagged(faces, n, &Tags::new())
    }

    /// [`Self::umbrella`] respecting `tags` (see the module docs): a crease vertex's row
    /// averages its two crease neighbours, a corner's row is empty. Infinitely sharp and
    /// semi-sharp creases alike.
    ///
    /// # Panics
    /// If a face index is `≥ n`.
    #[track_caller]
    pub fn umbrella_tagged(faces: &Polygons, n: usize, tags: &Tags) -> Self {
        let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); n];
        for f in faces.iter() {
            let k = f.len();
            for c in 0..k {
                let (a, b) = (f[c], f[(c + 1) % k]);
                assert!(
                    (a as usize) < n && (b as usize) < n,
                    "face index out of range"
                );
                nbrs[a as usize].push(b);
                nbrs[b as usize].push(a);
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut indices = Vec::new();
        let mut weights = Vec::new();
        offsets.push(0);
        for (i, nb) in nbrs.iter_mut().enumerate() {
            nb.sort_unstable();
            // An edge of one face is a boundary edge: its far end appears once.
            let boundary_edges = nb
                .chunk_by(|a, b| a == b)
                .filter(|run| run.len() == 1)
                .count();
            nb.dedup();
            nb.retain(|&j| j as usize != i);
            if !tags.is_empty() {
                let v = i as u32;
                let sharp: Vec<u32> = nb
                    .iter()
                    .copied()
                    .filter(|&j| tags.crease(v, j) > 0.0)
                    .collect();
                if tags.corner(v) > 0.0 || sharp.len() + boundary_edges > 2 {
                    nb.clear();
                } else if sharp.len() == 2 {
                    *nb = sharp;
                }
            }
            if !nb.is_empty() {
                let w = -1.0 / nb.len() as f64;
                let mut row: Vec<(u32, f64)> = nb.iter().map(|&j| (j, w)).collect();
                row.push((i as u32, 1.0));
                row.sort_unstable_by_key(|e| e.0);
                for (j, w) in row {
                    indices.push(j);
                    weights.push(w);
                }
            }
            offsets.push(indices.len());
        }
        Self {
            offsets,
            indices,
            weights,
        }
    }

    /// Number of rows (control points).
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `i` as (column indices, weights).
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.offsets[i]..self.offsets[i + 1];
        (&self.indices[r.clone()], &self.weights[r])
    }

    /// `W(P_i)` for all `i` (`n by 3`). Cost: O(nnz).
    pub fn apply(&self, p: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.len())
            .map(|i| {
                let (idx, w) = self.row(i);
                let mut s = [0.0; 3];
                for (&j, &w) in idx.iter().zip(w) {
                    for a in 0..3 {
                        s[a] += w * p[j as usize][a];
                    }
                }
                s
            })
            .collect()
    }

    /// `Σ_i |W(P_i)|²` (units: squared normalized length). Cost: O(nnz).
    pub fn energy(&self, p: &[[f64; 3]]) -> f64 {
        self.apply(p)
            .iter()
            .map(|w| w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
            .sum()
    }

    /// The transpose as CSR (columns of `L` as rows). Cost: O(nnz).
    pub fn transpose(&self) -> Laplacian {
        let n = self.len();
        let mut counts = vec![0usize; n + 1];
        for &j in &self.indices {
            counts[j as usize + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let mut next = counts.clone();
        let mut indices = vec![0u32; self.indices.len()];
        let mut weights = vec![0.0; self.indices.len()];
        for i in 0..n {
            let (idx, w) = self.row(i);
            for (&j, &w) in idx.iter().zip(w) {
                let s = &mut next[j as usize];
                indices[*s] = i as u32;
                weights[*s] = w;
                *s += 1;
            }
        }
        Laplacian {
            offsets: counts,
            indices,
            weights,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::cube_mesh;

    #[test]
    fn tagged_rows_follow_creases_and_leave_corners_alone() {
        let cube = cube_mesh(1.0);
        let n = cube.num_vertices();
        let plain = Laplacian::umbrella(&cube.faces, n);
        assert_eq!(plain.row(0).0.len(), 4); // itself and three neighbours
        let mut tags = Tags::new();
        // Crease 1–0–2 through vertex 0 (its neighbours are 1, 2, 4); corner at 7.
        tags.set_crease(0, 1, 10.0);
        tags.set_crease(0, 2, 10.0);
        tags.set_corner(7, 10.0);
        let l = Laplacian::umbrella_tagged(&cube.faces, n, &tags);
        let (cols, w) = l.row(0);
        assert_eq!(cols, &[0, 1, 2]);
        assert_eq!(w, &[1.0, -0.5, -0.5]);
        assert!(l.row(7).0.is_empty());
        // Untouched vertices keep their umbrella; a dart end (one crease) too.
        assert_eq!(l.row(3), plain.row(3));
        assert_eq!(l.row(1), plain.row(1));
        // Three creases make a corner.
        tags.set_crease(0, 4, 10.0);
        assert!(Laplacian::umbrella_tagged(&cube.faces, n, &tags)
            .row(0)
            .0
            .is_empty());
    }

    #[test]
    fn a_boundary_vertex_with_a_crease_is_a_corner() {
        // Open box without its top face: vertex 4 (on the rim) has two boundary edges.
        let cube = cube_mesh(1.0);
        let mut faces = Polygons::new();
        for f in cube.faces.iter().filter(|f| !f.iter().all(|&v| v & 4 != 0)) {
            faces.push(f);
        }
        let mut tags = Tags::new();
        tags.set_crease(4, 0, 10.0);
        let l = Laplacian::umbrella_tagged(&faces, 8, &tags);
        assert!(l.row(4).0.is_empty());
        assert_eq!(l.row(5), Laplacian::umbrella(&faces, 8).row(5));
    }
}

//! The as-rigid-as-possible regularizer on the control mesh (Sorkine & Alexa 2007, §2–3; Xie
//! et al. 2023 §4.1, eq. 5), folded into the fitter's sparse Gauss-Newton system.
//!
//! With rest positions `r` (the cage the fitter starts from), current control points `p`,
//! per-vertex rotations `R_i` and cotangent weights `w_ij`,
//!
//! ```text
//! E(p, R) = Σ_i Σ_{j ∈ N(i)} w_ij ‖(p_i − p_j) − R_i (r_i − r_j)‖².
//! ```
//!
//! (Xie et al. print eq. 5 with the rest positions on both sides; this is Sorkine–Alexa's
//! energy, which their text describes.) The regularizer is `E(p) = min_R E(p, R)`:
//!
//! * **local step** ([`Arap::rotations`]): `R_i = V Uᵀ` from the SVD `S_i = U Σ Vᵀ` of the
//!   covariance `S_i = Σ_j w_ij (r_i − r_j)(p_i − p_j)ᵀ`, with the column of `U` of the smallest
//!   singular value negated when `det(V Uᵀ) < 0` (a reflection);
//! * **global step**: for fixed rotations `E` is quadratic in `p`,
//!   `E = 2 pᵀ L p − 4 bᵀ p + const` per coordinate, where `L` is the cotangent Laplacian
//!   (`L_ii = Σ_j w_ij`, `L_ij = −w_ij`) and `b_i = Σ_j (w_ij / 2)(R_i + R_j)(r_i − r_j)`; so
//!   `∇E = 4 (L p − b)`.
//!
//! The fitter adds `α/n · E` to its objective ([`crate::FitOptions::arap`], `n` control points:
//! the data term is a mean, so this keeps Xie et al.'s ratio of eq. 1 when the samples are about
//! as many as the control points), hence `(2α/n) L ⊗ I₃` to the normal matrix `H` and
//! `(2α/n)(L p − b)` to the half-gradient `g`. `L` is nonzero only between vertices of a common
//! face, pairs the pattern of `H` already holds (every sample stencil of a face touches all its
//! corners, and the umbrella `LᵀL` spans two rings), so the pattern, its symbolic Cholesky and
//! the fill are unchanged; the values are added in place after the fill. Rotations are refreshed
//! at every assembly (the current iterate) and at every evaluation of the objective, so the
//! step control judges the true `min_R E`.
//!
//! **Rotations in the model.** With the rotations frozen, the model charges a turn of the cage as
//! much as a stretch, and a stiff `α` only lets it translate: on Cheng's ellipsoid turned by
//! 0.3 rad, a fit from the unturned cage (rest shape: that cage, 40 LM iterations) ended 0.19
//! (`α` = 1) and 0.23 (`α` = 100, i.e. not moved) from the turned cage, normalized units. So each
//! vertex's rotation is linearized too, `R_i ← (I + [ω_i]×) R_i`, and eliminated: `H` gets the
//! Schur complement of `ω_i` in vertex `i`'s terms (`add_rotation_coupling`), a Gauss-Newton
//! model of `min_R E` itself. Both fits above now end on the turned cage (2.8e-7; `tests/arap.rs`).
//! The pairs it couples — two neighbours of one vertex — are in the pattern (the umbrella `LᵀL`);
//! the coupling needs block size 3 (SDM, TDM, IMLS), so the PD system keeps frozen rotations.
//!
//! **Weights.** `w_ij = ½ (cot α_ij + cot β_ij)` over the triangles of the rest cage. A polygon
//! of `k > 3` corners is triangulated by each of its `k` corner fans, each fan's triangles
//! counted with weight `1/k` (for a quad, the two diagonal triangulations averaged): symmetric,
//! independent of where the face's corner list starts; diagonals get weights too (they are
//! within the face). Weights are **clamped at 0**: a pair whose opposite angles sum beyond π has
//! a negative cotangent weight, which makes `L` indefinite — `E` could then decrease by
//! stretching such an edge and `H` could lose positive definiteness; clamped, `L` is PSD and
//! `E ≥ 0`. A near-degenerate triangle's cotangent is capped at [`MAX_COT`].
//!
//! **With or instead of the umbrella smoothing?** Added to it (`λ = 0` gives ARAP alone): they
//! regularize different things — the umbrella term pulls each point to its neighbours' mean,
//! ARAP keeps the cage's local shape — and the stage driver's `λ` schedule stays as it is.
//! Measured, the rest shape being a cage that lies on the data costs accuracy, since a limit
//! surface fitting the data needs a cage that grows away from it, and ARAP resists exactly that:
//! on Cheng's ellipsoid from the 14-vertex cage (λ = 0, 10 LM iterations; `tests/arap.rs`) final
//! E_rms 0.0014 at α = 0, 0.0018 at 1e-4, 0.0045 at 1e-3, 0.018 at 0.01; on the bunny's points
//! at 314 control points (`subfit fit --as-points --method imls`, default stages) two-sided
//! E_rms 3.17e-3 without ARAP, 4.95e-3 with α = 0.01 (+ λ), 5.20e-3 with α = 0.01 and λ = 0,
//! 4.72e-3 with α = 0.001 and λ = 0 (3.59e-3 with neither). Xie et al. need ARAP to keep a
//! first-order optimizer's cage from tangling; with Gauss-Newton/LM and the umbrella term the
//! fit is stable without it, so it stays off by default — it is for sequences (one template,
//! frames fitted in turn), where keeping the template's shape is the point.

use nalgebra::Matrix3;
use rayon::prelude::*;
use subfit_mesh::Polygons;

use crate::assemble::Pattern;

/// Largest cotangent counted (an angle of about 0.06°).
pub const MAX_COT: f64 = 1e3;

/// The ARAP energy of one cage topology and rest shape: cotangent weights per neighbour pair
/// (CSR, both directions) and the rest positions. See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct Arap {
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
    weights: Vec<f64>,
    rest: Vec<[f64; 3]>,
}

impl Arap {
    /// The regularizer of `faces` (over `rest.len()` points) with rest shape `rest` (`n by 3`,
    /// normalized units). Cost: O(Σ k²) over the face sizes `k`.
    ///
    /// # Panics
    /// If a face index is `≥ rest.len()`.
    #[track_caller]
    pub fn new(faces: &Polygons, rest: &[[f64; 3]]) -> Self {
        let n = rest.len();
        let mut pairs: Vec<(u32, u32, f64)> = Vec::new();
        for f in faces.iter() {
            assert!(
                f.iter().all(|&v| (v as usize) < n),
                "face index out of range"
            );
            let k = f.len();
            if k < 3 {
                continue;
            }
            let fans = if k == 3 { 1 } else { k };
            let s = 1.0 / fans as f64;
            for a in 0..fans {
                for t in 1..k - 1 {
                    let tri = [f[a], f[(a + t) % k], f[(a + t + 1) % k]];
                    add_triangle(&mut pairs, rest, tri, s);
                }
            }
        }
        // Both directions, sorted, duplicates summed.
        let mut both: Vec<(u32, u32, f64)> = Vec::with_capacity(2 * pairs.len());
        for &(i, j, w) in &pairs {
            both.push((i, j, w));
            both.push((j, i, w));
        }
        both.sort_unstable_by_key(|e| (e.0, e.1));
        let mut counts = vec![0usize; n + 1];
        let mut neighbors = Vec::new();
        let mut weights: Vec<f64> = Vec::new();
        let mut prev = None;
        for (i, j, w) in both {
            if prev == Some((i, j)) {
                *weights.last_mut().expect("a weight per neighbour") += w;
                continue;
            }
            prev = Some((i, j));
            neighbors.push(j);
            weights.push(w);
            counts[i as usize + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let offsets = counts;
        for w in &mut weights {
            *w = w.max(0.0);
        }
        Self {
            offsets,
            neighbors,
            weights,
            rest: rest.to_vec(),
        }
    }

    /// Number of control points `n`.
    pub fn len(&self) -> usize {
        self.rest.len()
    }

    /// True when there are no control points.
    pub fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }

    /// The rest positions (`n by 3`).
    pub fn rest(&self) -> &[[f64; 3]] {
        &self.rest
    }

    /// Neighbours of `i` and their weights `w_ij ≥ 0` (sorted by neighbour).
    pub fn neighbors(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.offsets[i]..self.offsets[i + 1];
        (&self.neighbors[r.clone()], &self.weights[r])
    }

    /// The local step: the best rotation of every vertex for the positions `p` (`n by 3`).
    /// Cost: one 3×3 SVD per vertex, in parallel.
    ///
    /// # Panics
    /// If `p.len() != n`.
    #[track_caller]
    pub fn rotations(&self, p: &[[f64; 3]]) -> Vec<Matrix3<f64>> {
        assert_eq!(p.len(), self.len(), "one position per control point");
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (nb, w) = self.neighbors(i);
                let mut s = Matrix3::zeros();
                for (&j, &w) in nb.iter().zip(w) {
                    let e = vector(sub(self.rest[i], self.rest[j as usize]));
                    let d = vector(sub(p[i], p[j as usize]));
                    s += w * e * d.transpose();
                }
                best_rotation(&s)
            })
            .collect()
    }

    /// `E(p, R)` for given rotations (normalized units²). Cost: O(nnz).
    pub fn energy_with(&self, p: &[[f64; 3]], rotations: &[Matrix3<f64>]) -> f64 {
        let per: Vec<f64> = (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (nb, w) = self.neighbors(i);
                let mut e = 0.0;
                for (&j, &w) in nb.iter().zip(w) {
                    let j = j as usize;
                    let r = rotations[i] * vector(sub(self.rest[i], self.rest[j]));
                    let d = vector(sub(p[i], p[j])) - r;
                    e += w * d.norm_squared();
                }
                e
            })
            .collect();
        per.iter().sum()
    }

    /// `E(p) = min_R E(p, R)` (the local step, then [`Self::energy_with`]).
    pub fn energy(&self, p: &[[f64; 3]]) -> f64 {
        self.energy_with(p, &self.rotations(p))
    }

    /// `b_i = Σ_j (w_ij / 2)(R_i + R_j)(r_i − r_j)` (`n by 3`). Cost: O(nnz).
    pub fn rhs(&self, rotations: &[Matrix3<f64>]) -> Vec<[f64; 3]> {
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (nb, w) = self.neighbors(i);
                let mut b = nalgebra::Vector3::zeros();
                for (&j, &w) in nb.iter().zip(w) {
                    let j = j as usize;
                    let e = vector(sub(self.rest[i], self.rest[j]));
                    b += 0.5 * w * ((rotations[i] + rotations[j]) * e);
                }
                [b.x, b.y, b.z]
            })
            .collect()
    }

    /// `L p` with the cotangent Laplacian (`n by 3`). Cost: O(nnz).
    pub fn laplacian_apply(&self, p: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (nb, w) = self.neighbors(i);
                let mut s = [0.0; 3];
                for (&j, &w) in nb.iter().zip(w) {
                    for a in 0..3 {
                        s[a] += w * (p[i][a] - p[j as usize][a]);
                    }
                }
                s
            })
            .collect()
    }

    /// `∇_p E(p, R) = 4 (L p − b)` for fixed rotations (`n by 3`).
    pub fn gradient(&self, p: &[[f64; 3]], rotations: &[Matrix3<f64>]) -> Vec<[f64; 3]> {
        let lp = self.laplacian_apply(p);
        let b = self.rhs(rotations);
        lp.iter()
            .zip(&b)
            .map(|(l, b)| std::array::from_fn(|a| 4.0 * (l[a] - b[a])))
            .collect()
    }

    /// Adds `w · L ⊗ I_b` to the values of `H` (`pattern`, block size `b`) and
    /// `w · (L p − b)` to the half-gradient `g`, at the rotations of `p` — the global step's
    /// system, `w = 2α/n`. `points`: the active control points `H` and `g` are over (their
    /// local index is their position; `None`: all). Entries between an active and a fixed
    /// point only enter `g` (through `L p` with the full `p`). Cost: O(nnz · log) and one SVD
    /// per point.
    ///
    /// Errors: a neighbour pair missing from the pattern (cannot happen for the fitter's
    /// patterns; see the module docs).
    pub(crate) fn add_to_system(
        &self,
        p: &[[f64; 3]],
        w: f64,
        pattern: &Pattern,
        values: &mut [f64],
        g: &mut [[f64; 3]],
        points: Option<&[u32]>,
    ) -> Result<(), (usize, usize)> {
        let rot = self.rotations(p);
        let lp = self.laplacian_apply(p);
        let b = self.rhs(&rot);
        let local: Vec<u32> = match points {
            None => (0..self.len() as u32).collect(),
            Some(pts) => {
                let mut l = vec![u32::MAX; self.len()];
                for (k, &i) in pts.iter().enumerate() {
                    l[i as usize] = k as u32;
                }
                l
            }
        };
        let bs = pattern.block();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut add = |row: usize, col: usize, v: f64| -> bool {
            let r = col_ptr[col]..col_ptr[col + 1];
            match row_idx[r.clone()].binary_search(&row) {
                Ok(k) => {
                    values[r.start + k] += v;
                    true
                }
                Err(_) => false,
            }
        };
        for i in 0..self.len() {
            let li = local[i];
            if li == u32::MAX {
                continue;
            }
            let li = li as usize;
            for a in 0..3 {
                g[li][a] += w * (lp[i][a] - b[i][a]);
            }
            let (nb, wij) = self.neighbors(i);
            let diag: f64 = wij.iter().sum();
            for c in 0..bs {
                if !add(bs * li + c, bs * li + c, w * diag) {
                    return Err((i, i));
                }
            }
            for (&j, &wj) in nb.iter().zip(wij) {
                let lj = local[j as usize];
                // Upper triangle: each unordered pair once, from its smaller local index.
                if lj == u32::MAX || (lj as usize) <= li || wj == 0.0 {
                    continue;
                }
                for c in 0..bs {
                    if !add(bs * li + c, bs * lj as usize + c, -w * wj) {
                        return Err((i, j as usize));
                    }
                }
            }
        }
        if bs == 3 {
            self.add_rotation_coupling(&rot, w, &local, &mut add);
        }
        Ok(())
    }

    /// Subtracts from `H` the part of the frozen-rotation model that the rotations would undo:
    /// per vertex `i` the Schur complement of its linearized rotation `ω_i`
    /// (`R_i ← (I + [ω_i]×) R_i`) in `Σ_j w_ij ‖d_ij − R_i e_ij − ω_i × R_i e_ij‖²`, i.e.
    /// `(w/2) G_iᵀ A_i⁻¹ G_i` with `A_i = Σ_j w_ij [r_ij]×ᵀ[r_ij]×` (`r_ij = R_i e_ij`) and `G_i`
    /// mapping `p` to `Σ_j w_ij [r_ij]×ᵀ d_ij`. The gradient needs no change (at the optimal
    /// rotations the torque `Σ_j w_ij r_ij × d_ij` vanishes). Each vertex's term stays positive
    /// semi-definite, so `H` does; a vertex some of whose neighbour pairs the pattern lacks is
    /// left frozen (see the module docs for why). Cost: O(Σ_i (k_i + 1)² · 9 · log) for valences `k_i`.
    fn add_rotation_coupling(
        &self,
        rot: &[Matrix3<f64>],
        w: f64,
        local: &[u32],
        add: &mut dyn FnMut(usize, usize, f64) -> bool,
    ) {
        let blocks: Vec<(Vec<usize>, Vec<Matrix3<f64>>)> = (0..self.len())
            .into_par_iter()
            .map(|i| self.rotation_schur(i, rot, local))
            .collect();
        for (idx, m) in &blocks {
            let k = idx.len();
            // Probe every slot first: all or nothing per vertex keeps H PSD.
            let mut slots_ok = true;
            for a in 0..k {
                for b in a..k {
                    let (la, lb) = (idx[a], idx[b]);
                    if la != usize::MAX
                        && lb != usize::MAX
                        && !add(3 * la.min(lb), 3 * la.max(lb), 0.0)
                    {
                        slots_ok = false;
                    }
                }
            }
            if !slots_ok {
                continue;
            }
            for a in 0..k {
                for b in 0..k {
                    let (la, lb) = (idx[a], idx[b]);
                    if la == usize::MAX || lb == usize::MAX || la > lb {
                        continue;
                    }
                    let mab = &m[a * k + b];
                    for x in 0..3 {
                        for y in 0..3 {
                            if la == lb && x > y {
                                continue;
                            }
                            add(3 * la + x, 3 * lb + y, -0.5 * w * mab[(x, y)]);
                        }
                    }
                }
            }
        }
    }

    /// Vertex `i`'s rotation Schur complement: its local indices (`i` first, then its
    /// neighbours; `usize::MAX` when not active) and the `(k+1)²` blocks `G_aᵀ A⁻¹ G_b`.
    fn rotation_schur(
        &self,
        i: usize,
        rot: &[Matrix3<f64>],
        local: &[u32],
    ) -> (Vec<usize>, Vec<Matrix3<f64>>) {
        let (nb, wij) = self.neighbors(i);
        let to_local = |v: usize| match local[v] {
            u32::MAX => usize::MAX,
            l => l as usize,
        };
        let mut idx = Vec::with_capacity(nb.len() + 1);
        idx.push(to_local(i));
        // G blocks: at i, Σ_j w_ij C_jᵀ; at j, −w_ij C_jᵀ, with C_j = [r_ij]× (so C_jᵀ = −C_j).
        let mut g = Vec::with_capacity(nb.len() + 1);
        g.push(Matrix3::zeros());
        let mut a = Matrix3::zeros();
        for (&j, &w) in nb.iter().zip(wij) {
            let r = rot[i] * vector(sub(self.rest[i], self.rest[j as usize]));
            let c = r.cross_matrix();
            let ct = -c;
            g[0] += w * ct;
            g.push(-w * ct);
            idx.push(to_local(j as usize));
            a += w * (ct * c);
        }
        let eps = 1e-9 * a.trace().max(f64::MIN_POSITIVE);
        a += Matrix3::identity() * eps;
        let Some(a_inv) = a.try_inverse() else {
            return (idx, vec![Matrix3::zeros(); g.len() * g.len()]);
        };
        let k = g.len();
        let ag: Vec<Matrix3<f64>> = g.iter().map(|gb| a_inv * gb).collect();
        let mut m = Vec::with_capacity(k * k);
        for ga in &g {
            let gat = ga.transpose();
            for agb in &ag {
                m.push(gat * agb);
            }
        }
        (idx, m)
    }
}

/// The regularizer as the fitter holds it: the faces until the first run fixes the rest shape.
#[derive(Clone, Debug)]
pub(crate) enum ArapState {
    /// Waiting for the rest shape (the control points of the first run).
    Pending(Polygons),
    /// Built.
    Ready(Arap),
}

impl ArapState {
    /// The regularizer, building it with rest shape `rest` if still pending.
    pub fn ensure(&mut self, rest: &[[f64; 3]]) -> &Arap {
        if let Self::Pending(faces) = self {
            *self = Self::Ready(Arap::new(faces, rest));
        }
        match self {
            Self::Ready(a) => a,
            Self::Pending(_) => unreachable!("built above"),
        }
    }

    /// The regularizer once built.
    pub fn ready(&self) -> Option<&Arap> {
        match self {
            Self::Ready(a) => Some(a),
            Self::Pending(_) => None,
        }
    }
}

/// Adds `s · ½ cot` of each corner of `tri` (at `rest`) to the opposite edge's pair.
fn add_triangle(pairs: &mut Vec<(u32, u32, f64)>, rest: &[[f64; 3]], tri: [u32; 3], s: f64) {
    for c in 0..3 {
        let (a, b, o) = (tri[c], tri[(c + 1) % 3], tri[(c + 2) % 3]);
        let u = sub(rest[a as usize], rest[o as usize]);
        let v = sub(rest[b as usize], rest[o as usize]);
        let dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let cr = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let area2 = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        let cot = if area2 > 0.0 {
            (dot / area2).clamp(-MAX_COT, MAX_COT)
        } else if dot > 0.0 {
            MAX_COT
        } else {
            0.0
        };
        if a != b {
            pairs.push((a.min(b), a.max(b), 0.5 * s * cot));
        }
    }
}

/// The rotation closest to `S`ᵀ's polar factor: `V Uᵀ` for `S = U Σ Vᵀ`, reflection removed.
fn best_rotation(s: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = s.svd(true, true);
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Matrix3::identity();
    };
    let mut r = v_t.transpose() * u.transpose();
    if r.determinant() < 0.0 {
        let k = (0..3)
            .min_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]))
            .unwrap_or(2);
        for row in 0..3 {
            u[(row, k)] = -u[(row, k)];
        }
        r = v_t.transpose() * u.transpose();
    }
    if r.iter().all(|x| x.is_finite()) {
        r
    } else {
        Matrix3::identity()
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn vector(a: [f64; 3]) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(a[0], a[1], a[2])
}

//! Exact evaluation of the limit surface at any `(face, u, v)`, with derivatives and the sparse
//! weight row over control points.
//!
//! Method: Stam 1998 (*Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary
//! parameter values*; *Evaluation of Loop subdivision surfaces*), in its "repeated subdivision of
//! the local patch" form rather than the eigen-basis form: the two-ring neighbourhood of the face
//! is refined locally (module `local`, with the masks of [`crate::mask`]) and the child face
//! containing the point is kept, until that face is regular; then the regular polynomial patch
//! ([`crate::patch`]: quartic box spline for Loop, bicubic B-spline for Catmull-Clark) is
//! evaluated. Both steps are exact, so the result is exact to rounding, near extraordinary
//! vertices too (no Gregory or other approximation). Exactly at an irregular vertex the limit
//! masks ([`Scheme::limit_masks`](crate::Scheme::limit_masks)) give the position and two limit
//! tangents.
//!
//! # Parametrisation
//! * Loop triangle `(c0, c1, c2)` (corner order of the face): barycentric, the point is
//!   `(1 − u − v) c0 + u c1 + v c2` on the domain triangle, `u, v ≥ 0`, `u + v ≤ 1`.
//! * Catmull-Clark quad `(c0, c1, c2, c3)`: `(u, v) ∈ [0,1]²`, `c0` at `(0,0)`, `c1` at `(1,0)`,
//!   `c2` at `(1,1)`, `c3` at `(0,1)`.
//! * Catmull-Clark `n`-gon (`n ≠ 4`): sub-patch `k` (`0 ≤ k < n`) is the quad of the first-level
//!   split at corner `k`, `(v_k, e_{k,k+1}, F, e_{k−1,k})` with `e_{i,j}` the edge point of edge
//!   `v_i v_j` and `F` the face point (the order of [`mod@crate::refine`]); `(u, v) ∈ [0,1]²` on it
//!   with the quad convention above (`v_k` at `(0,0)`, `e_{k,k+1}` at `(1,0)`, `F` at `(1,1)`,
//!   `e_{k−1,k}` at `(0,1)`). Each sub-patch covers a quarter-like sector of the `n`-gon.
//!
//! Closest points on the surface: [`crate::closest`].
//!
//! A [`SurfaceParam`] is `(face, sub, u, v)`; `sub` is 0 except for Catmull-Clark `n`-gons.
//! Dyadic parameters `(i / 2^l, j / 2^l)` are the level-`l` vertices of uniform refinement
//! (level `l − 1` of the sub-quads for `n`-gons).
//!
//! # Boundaries, creases, corners
//! Boundary edges and infinitely sharp creases (sharpness ≥ [`subfit_mesh::SHARPNESS_INFINITE`])
//! follow [`mod@crate::refine`]'s rules exactly (`EdgeOnly` and `EdgeAndCorner`); regular patches
//! along them use phantom points (module `local`), so they are exact as well. Semi-sharp tags
//! (finite sharpness, [`crate::crease`]) blend the rules in local refinement as
//! [`mod@crate::refine`] does; a patch corner with finite sharpness at it or on an incident edge
//! is never regular and never given the closed-form limit masks, so evaluation refines until
//! the sharpness has decayed (at most `⌈s⌉` extra levels), and is exact there too.
//!
//! # Modules
//! * `types` — [`SurfaceParam`], [`EvalWeights`], [`SurfacePoint`], [`EvalKind`], [`EvalError`].
//! * `basis` — the regular patch basis and a regular patch's control points as weight rows.
//! * `memo` — the memoised local-refinement tree of each patch and its memory budget.
//! * `evaluator` — [`Evaluator`]: construction, the walk down the memoised tree, batches.
//! * `shape` — interned local topologies below the memoised levels and the sparse refinement
//!   steps between them (Stam 1998's repeated local subdivision matrices).
//! * `chain` — those steps computed on first use and evaluation rows pulled back through them.
//! * `descend` — the walk below the memoised levels, local refinement where it cannot be
//!   used, and limits at irregular vertices.
//! * `random` — seeded random parameters ([`random_samples`]).

mod basis;
mod chain;
mod descend;
mod evaluator;
mod memo;
mod random;
mod shape;
mod types;

pub use descend::MAX_DEPTH;
pub use evaluator::Evaluator;
pub use memo::{CACHE_DEPTH, DEFAULT_CACHE_BYTES};
pub use random::{area_weights, random_samples};
pub use types::{EvalError, EvalKind, EvalWeights, SurfaceParam, SurfacePoint};

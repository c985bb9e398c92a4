//! The options of a tracking step ([`super::track`]) and the known points it can be given
//! ([`Marker`]); Sumner, Schmid & Pauly 2007 §§3–4 and Li et al. 2009 §4 for the weights (see
//! [`super`]'s module docs). Below both the driver and the normal system, which name them.

/// Options of [`super::track`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOptions {
    /// Gauss-Newton iterations. Default 20.
    pub iterations: usize,
    /// Nodes each sample is skinned to (`s`). Default 6 (with a graph laid over the surface,
    /// [`super::DeformationGraph::on_surface`]; 12 with one through space smoothed a limb's motion
    /// into the body it hangs beside; 4, Sumner et al.'s, left a hand 1.4 % of the diagonal off
    /// in one frame of the dance).
    pub skin: usize,
    /// Weight `γ` of the regularity term. Default 1e-4 (see the module docs).
    pub regularity: f64,
    /// Weight `ρ` of the rigidity term. Default 1e-6.
    pub rigidity: f64,
    /// Weight `μ` of the second-order term (the linear parts' departure from a linear field
    /// over each neighbourhood). Default 1e-6.
    pub second_order: f64,
    /// Weight `β` of the point-to-point part of the fit. Default 0.
    pub point_weight: f64,
    /// Weight of the markers ([`Marker`]), all together: 1 weighs them like all the samples'
    /// point-to-plane distances. Default 1.
    pub marker_weight: f64,
    /// Samples whose foot point is farther than this (normalized units) are left out.
    /// Default 0.1.
    pub max_distance: f64,
    /// The iterations stop once the RMS point-to-plane distance is at or below this
    /// (normalized units; Morozov's discrepancy principle): what the data's own noise explains
    /// is not fitted with motion. Default 0 (never).
    pub stop_rms: f64,
    /// Weight of the data → model correspondences, all together against the model → data
    /// ones (1 weighs both sides alike; 0 turns them off): each of up to
    /// [`Self::backward_points`] frame points pulls the nearest moved sample whose normal
    /// agrees along the frame's normal. Where a limb moved farther than its own width, the
    /// model's samples find nothing of it nearby, but its points still find the model's limb
    /// (symmetric ICP; see [`super::backward`]). Used in the stiff levels of the annealing only
    /// ([`Self::stiffness_start`]). Default 1.
    pub backward_weight: f64,
    /// Frame points used by the data → model correspondences at most (an even subsample).
    /// Default 3000.
    pub backward_points: usize,
    /// Stiffness annealing (Amberg, Romdhani & Vetter, "Optimal step nonrigid ICP
    /// algorithms for surface registration", CVPR 2007, §3.2): the step starts with the
    /// regularity and rigidity weights times this and divides them by 10 every
    /// [`Self::level_iterations`] iterations down to ×1, the correspondence radius going from
    /// [`Self::reach_start`] down to [`Self::max_distance`] alike: the graph first moves piece
    /// by piece nearly rigidly onto the far-moved frame, then bends into its details. 1 turns
    /// the annealing off. Default 100.
    pub stiffness_start: f64,
    /// Iterations per stiffness level before the last (which gets the rest). Default 4.
    pub level_iterations: usize,
    /// Correspondence radius at the stiffest level (normalized units). Default 0.3.
    pub reach_start: f64,
    /// Robust weights of the last stiffness level's correspondences (iteratively reweighted
    /// least squares with Cauchy weights `1 / (1 + (e / c)²)`, Holland & Welsch, "Robust
    /// regression using iteratively reweighted least-squares", Comm. Statistics 1977), the
    /// scale `c` this multiple of the iteration's RMS point-to-plane distance; 0 turns them
    /// off. What the graph cannot explain — a part the template's cage does not reach, two
    /// parts that touched in the template's frame and come apart — then stops pulling the
    /// material around it along the surface. Default 1: on the first 12 frames of the
    /// corpus's low-poly cat (`subfit bench sequence --meshes`, 1,500 control points, no
    /// silhouette) drift RMS 1.83 % and p95 3.35 % instead of 2.50 % and 5.18 %, worst
    /// two-sided RMS 0.148 % instead of 0.162 %; on the dance of the module docs drift RMS
    /// 0.72 %, p95 1.50 % instead of 0.73 % and 1.56 % (scale 2: the cat 1.81 % / 3.83 %).
    pub robust: f64,
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            iterations: 20,
            skin: 6,
            regularity: 1e-4,
            rigidity: 1e-6,
            second_order: 1e-6,
            point_weight: 0.0,
            marker_weight: 1.0,
            max_distance: 0.1,
            stop_rms: 0.0,
            backward_weight: 1.0,
            backward_points: 3000,
            stiffness_start: 100.0,
            level_iterations: 4,
            reach_start: 0.3,
            robust: 1.0,
        }
    }
}

/// A point whose place in the frame is known (a motion-capture marker, a tracked texture
/// feature): where it is on the rest shape and where it is in this frame. [`super::track`] pulls it
/// there point to point, which pins what the surfaces alone leave free — sliding along them
/// (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// Position in the graph's rest configuration.
    pub rest: [f64; 3],
    /// Position in the frame.
    pub position: [f64; 3],
}

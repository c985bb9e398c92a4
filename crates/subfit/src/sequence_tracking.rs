//! The tracking step of a sequence (see [`crate::sequence`]'s module docs): the template
//! carried onto each new frame by an embedded deformation ([`subfit_fit::track`]) whose nodes
//! lie inside the body, warm-started from the previous frames' motions, before the frame's fit.

use std::sync::Arc;

use serde::Serialize;
use subfit_fit::track::{plane_rms_to, track, DeformationGraph, NodeMotion, TrackOptions};
use subfit_subdiv::{normals_from_tangents, SamplingOperator};
use subfit_target::Target;

use crate::sequence::LimitStencils;

/// The embedded-deformation tracking step of a sequence ([`subfit_fit::track`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackingOptions {
    /// Nodes of the deformation graph. Default 60 (see [`crate::sequence`]'s module docs).
    pub nodes: usize,
    /// Nearest nodes each node is tied to. Default 8.
    pub neighbors: usize,
    /// Where the nodes lie: this fraction of the way from the template's limit surface to its
    /// medial points ([`DeformationGraph::interior`]); 0 puts them on the surface. Default 0.5.
    pub depth: f64,
    /// Start each frame from the motion of the two previous frames extrapolated (constant
    /// velocity, [`NodeMotion::extrapolated`]); otherwise from the previous frame's motion.
    /// Default true.
    pub predict: bool,
    /// Refinement level of the limit samples that are tracked. Default 1.
    pub level: usize,
    /// Discrepancy factor `τ`: a step stops once its point-to-plane RMS is within `τ` times
    /// the previous frame's own (the fitted cage against the frame it was fitted to: the
    /// data's noise and tessellation), so a subject that holds still is not tracked into a
    /// slide ([`TrackOptions::stop_rms`]). 0 turns the rule off. Default 1.5.
    pub discrepancy: f64,
    /// The step's own options.
    pub step: TrackOptions,
}

impl Default for TrackingOptions {
    fn default() -> Self {
        Self {
            nodes: 60,
            neighbors: 8,
            depth: 0.5,
            predict: true,
            level: 1,
            discrepancy: 1.5,
            step: TrackOptions::default(),
        }
    }
}

/// What the tracking step did on one frame (`report.json` → `frames[i].tracking`).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct TrackingReport {
    /// Limit samples with a foot point on the frame.
    pub matched: usize,
    /// Their RMS point-to-plane distance to the frame before the step (normalized units).
    pub rms_before: f64,
    /// After it.
    pub rms_after: f64,
    /// Gauss-Newton iterations.
    pub iterations: usize,
    /// The RMS at which the step would stop ([`TrackingOptions::discrepancy`] times the
    /// previous frame's own; 0 without the rule).
    pub stop_rms: f64,
}

/// The step's state between frames: its graph (inside the template), the limit stencils of
/// the samples it tracks, the template with its samples, and the last two motions (template →
/// frame).
pub(crate) struct Tracking {
    graph: DeformationGraph,
    samples: LimitStencils,
    template: Arc<Vec<[f64; 3]>>,
    rest: (Vec<[f64; 3]>, Vec<[f64; 3]>),
    motion: Option<NodeMotion>,
    before: Option<NodeMotion>,
    /// The previous frame's point-to-plane RMS against its own frame ([`Self::settle`]).
    floor: f64,
}

impl Tracking {
    /// The graph inside `template`, samples from `op` (the limit at
    /// [`TrackingOptions::level`]).
    pub(crate) fn new(
        template: Arc<Vec<[f64; 3]>>,
        op: SamplingOperator,
        o: &TrackingOptions,
    ) -> Self {
        let samples = LimitStencils {
            position: op.position,
            tangent1: op.tangent1,
            tangent2: op.tangent2,
        };
        let rest = samples_of(&samples, &template);
        Self {
            graph: DeformationGraph::interior(&rest.0, &rest.1, o.depth, o.nodes, o.neighbors),
            samples,
            template,
            rest,
            motion: None,
            before: None,
            floor: 0.0,
        }
    }

    /// Records how closely `cage`, fitted to `target`, lies on it (the samples' RMS
    /// point-to-plane distance): the next step's floor.
    pub(crate) fn settle(&mut self, cage: &[[f64; 3]], target: &Target, o: &TrackingOptions) {
        let (samples, normals) = samples_of(&self.samples, cage);
        self.floor = plane_rms_to(&samples, &normals, target, o.step.max_distance).0;
    }

    /// Carries the template onto `target` (the next frame); returns the moved cage.
    pub(crate) fn step(
        &mut self,
        target: &Target,
        o: &TrackingOptions,
    ) -> (Vec<[f64; 3]>, TrackingReport) {
        let step = TrackOptions {
            stop_rms: o.discrepancy * self.floor,
            ..o.step.clone()
        };
        let initial = match (&self.motion, &self.before) {
            (Some(last), Some(before)) if o.predict => Some(last.extrapolated(before)),
            (last, _) => last.clone(),
        };
        let (moved, motion, stats) = track(
            &self.graph,
            &self.template,
            &self.rest.0,
            &self.rest.1,
            target,
            initial.as_ref(),
            &step,
        );
        self.before = self.motion.replace(motion);
        let report = TrackingReport {
            matched: stats.matched,
            rms_before: stats.rms_before,
            rms_after: stats.rms_after,
            iterations: stats.iterations,
            stop_rms: step.stop_rms,
        };
        (moved, report)
    }
}

/// The limit samples of `cage` and their unit normals.
fn samples_of(stencils: &LimitStencils, cage: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let samples = stencils.position.apply(cage);
    let normals = normals_from_tangents(
        &stencils.tangent1.apply(cage),
        &stencils.tangent2.apply(cage),
    );
    (samples, normals)
}

//! The tracking step of a sequence (see [`crate::sequence`]'s module docs): the previous
//! frame's cage carried onto the new frame by an embedded deformation
//! ([`subfit_fit::track`]) before the frame's fit.

use serde::Serialize;
use subfit_fit::track::{plane_rms_to, track, DeformationGraph, NodeMotion, TrackOptions};
use subfit_subdiv::{normals_from_tangents, SamplingOperator};
use subfit_target::Target;

use crate::sequence::LimitStencils;

/// The embedded-deformation tracking step of a sequence ([`subfit_fit::track`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackingOptions {
    /// Nodes of the deformation graph. Default 30 (more nodes follow finer motion but let
    /// regions slide where the frame shows nothing; see [`subfit_fit::track`]).
    pub nodes: usize,
    /// Nearest nodes each node is tied to. Default 8.
    pub neighbors: usize,
    /// Start each step from the previous step's motion repeated (constant velocity,
    /// [`NodeMotion::repeated`]). Default true.
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
            nodes: 30,
            neighbors: 8,
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

/// The step's state between frames: its graph (on the template), the limit samples it tracks
/// and its last motion.
pub(crate) struct Tracking {
    graph: DeformationGraph,
    samples: LimitStencils,
    motion: Option<NodeMotion>,
    /// The previous frame's point-to-plane RMS against its own frame ([`Self::settle`]).
    floor: f64,
}

impl Tracking {
    /// The graph on `template`, samples from `op` (the limit at [`TrackingOptions::level`]).
    pub(crate) fn new(template: &[[f64; 3]], op: SamplingOperator, o: &TrackingOptions) -> Self {
        Self {
            graph: DeformationGraph::new(template, o.nodes, o.neighbors),
            samples: LimitStencils {
                position: op.position,
                tangent1: op.tangent1,
                tangent2: op.tangent2,
            },
            motion: None,
            floor: 0.0,
        }
    }

    /// Records how closely `cage`, fitted to `target`, lies on it (the samples' RMS
    /// point-to-plane distance): the next step's floor.
    pub(crate) fn settle(&mut self, cage: &[[f64; 3]], target: &Target, o: &TrackingOptions) {
        let (samples, normals) = self.samples_of(cage);
        self.floor = plane_rms_to(&samples, &normals, target, o.step.max_distance).0;
    }

    fn samples_of(&self, cage: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let samples = self.samples.position.apply(cage);
        let normals = normals_from_tangents(
            &self.samples.tangent1.apply(cage),
            &self.samples.tangent2.apply(cage),
        );
        (samples, normals)
    }

    /// Carries `cage` (the previous frame's) onto `target`; returns the moved cage.
    pub(crate) fn step(
        &mut self,
        cage: &[[f64; 3]],
        target: &Target,
        o: &TrackingOptions,
    ) -> (Vec<[f64; 3]>, TrackingReport) {
        let (samples, normals) = self.samples_of(cage);
        let step = TrackOptions {
            stop_rms: o.discrepancy * self.floor,
            ..o.step.clone()
        };
        let initial = self
            .motion
            .as_ref()
            .filter(|_| o.predict)
            .map(NodeMotion::repeated);
        let (moved, motion, stats) = track(
            &self.graph,
            cage,
            &samples,
            &normals,
            target,
            initial.as_ref(),
            &step,
        );
        self.motion = Some(motion);
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

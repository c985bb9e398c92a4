//! The tracking step of a sequence (see [`crate::sequence`]'s module docs): the template
//! carried onto each new frame by an embedded deformation ([`subfit_fit::track`]) whose nodes
//! lie inside the body, warm-started from the previous frames' motions, before the frame's fit.
//!
//! **Markers.** What the frames' surfaces leave free is sliding along them, and on the
//! generated sequences the priors then choose a motion 2–4 % of the diagonal away from the
//! true one (`cargo run --release -p subfit-fit --example drift_identifiability`). Where the
//! capture knows some points' places (motion-capture markers, tracked texture features),
//! [`TrackingOptions::markers`] pulls them there point to point ([`subfit_fit::track::Marker`]):
//! on frame 8 of the default motion 12 markers take the largest drift of the tracking step
//! from 2.3 % to 1.3 %, 32 to 0.7 %.
//!
//! **Starts.** Each frame starts from the previous frames' motion extrapolated while that
//! lies within [`TrackingOptions::restart`] times the least distance of a fitted cage to its
//! own frame; a frame farther than that (poses that are not a capture's steps) is tracked from
//! the [`TrackingOptions::starts`] nearest of the previous motion, the rest and rigid
//! alignments, and the result nearest the frame kept ([`subfit_fit::track::warm_starts`];
//! figures in [`subfit_fit::track`]'s module docs).

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use serde::Serialize;
use subfit_fit::track::{
    distance_to, motion_distance, plane_rms_to, track, warm_starts, DeformationGraph, Marker,
    NodeMotion, Samples, Start, TrackOptions,
};
use subfit_subdiv::{normals_from_tangents, SamplingOperator};
use subfit_target::{Normalization, Target};

use crate::limit_stencils::LimitStencils;

/// The embedded-deformation tracking step of a sequence ([`subfit_fit::track`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackingOptions {
    /// Nodes of the deformation graph. Default 60 (see the module docs of `sequence.rs`).
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
    /// How far (a multiple of the least symmetric distance of a fitted cage to its own frame
    /// so far, [`distance_to`]) the predicted start may lie from a frame before the step looks for a
    /// nearer one among the previous frame's motion, the rest and rigid alignments
    /// ([`warm_starts`]); 0 always looks. Default 3.
    pub restart: f64,
    /// Starts tracked when the prediction is far (the rest of [`Self::restart`]): the
    /// nearest distinct ones of [`warm_starts`], each carried onto the frame by the step, the
    /// result nearest the frame kept ([`motion_distance`]). Default 3.
    pub starts: usize,
    /// Known places of markers over the frames (empty: none). Every marker must be seen in
    /// the first frame, which puts it on the template; in later frames it is used where it is
    /// seen. Observations of frames the sequence does not reach are ignored.
    pub markers: Vec<MarkerObservation>,
    /// The step's own options.
    pub step: TrackOptions,
}

/// Where a marker is in one frame ([`TrackingOptions::markers`]).
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerObservation {
    /// The frame, 0 the first.
    pub frame: usize,
    /// The marker's name.
    pub marker: String,
    /// Its position, in the frames' units.
    pub position: [f64; 3],
}

impl TrackingOptions {
    /// Checks the options: the depth within 0..=1, markers with finite positions, each seen
    /// at most once a frame and in the first frame.
    pub(crate) fn check(&self) -> Result<(), String> {
        if !(0.0..=1.0).contains(&self.depth) {
            return Err(format!(
                "the tracking nodes' depth must be within 0..=1, got {}",
                self.depth
            ));
        }
        let mut seen = HashMap::new();
        for (i, m) in self.markers.iter().enumerate() {
            if !m.position.iter().all(|c| c.is_finite()) {
                return Err(format!(
                    "marker {:?} in frame {} (observation {i}) has a non-finite position",
                    m.marker, m.frame
                ));
            }
            if seen.insert((m.frame, m.marker.as_str()), i).is_some() {
                return Err(format!(
                    "marker {:?} is given twice in frame {} (observation {i})",
                    m.marker, m.frame
                ));
            }
        }
        if let Some(m) = self
            .markers
            .iter()
            .find(|m| !seen.contains_key(&(0, m.marker.as_str())))
        {
            return Err(format!(
                "marker {:?} is not in the first frame (frame 0), which puts it on the template",
                m.marker
            ));
        }
        Ok(())
    }
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
            restart: 3.0,
            starts: 3,
            markers: Vec::new(),
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
    /// Markers seen in this frame ([`TrackingOptions::markers`]).
    pub markers: usize,
    /// Their RMS distance to where the step put them (normalized units; 0 without markers).
    pub marker_rms: f64,
    /// Whether the step started from a rigid alignment of the template onto the frame rather
    /// than from the previous frames' motions or the rest ([`warm_starts`]).
    pub start_rigid: bool,
    /// The start's symmetric truncated distance to the frame (normalized units).
    pub start_distance: f64,
    /// The nearest of the previous frames' motions and the rest, by the same measure.
    pub given_distance: f64,
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
    /// The least symmetric distance of a fitted cage to its own frame so far ([`distance_to`]):
    /// a frame fitted badly does not loosen the next one's test.
    distance_floor: f64,
    /// The markers of each frame (normalized units), by frame.
    markers: BTreeMap<usize, Vec<Marker>>,
}

impl Tracking {
    /// The graph inside `template`, samples from `op` (the limit at
    /// [`TrackingOptions::level`]); the markers brought into the normalized units of
    /// `normalization` (the first frame's; [`TrackingOptions::check`] has passed).
    pub(crate) fn new(
        template: Arc<Vec<[f64; 3]>>,
        op: SamplingOperator,
        o: &TrackingOptions,
        normalization: &Normalization,
    ) -> Self {
        let rest: HashMap<&str, [f64; 3]> = o
            .markers
            .iter()
            .filter(|m| m.frame == 0)
            .map(|m| (m.marker.as_str(), normalization.to_normalized(m.position)))
            .collect();
        let mut markers: BTreeMap<usize, Vec<Marker>> = BTreeMap::new();
        for m in o.markers.iter().filter(|m| m.frame > 0) {
            if let Some(&r) = rest.get(m.marker.as_str()) {
                markers.entry(m.frame).or_default().push(Marker {
                    rest: r,
                    position: normalization.to_normalized(m.position),
                });
            }
        }
        let faces = op.faces;
        let samples = LimitStencils {
            position: op.position,
            tangent1: op.tangent1,
            tangent2: op.tangent2,
        };
        let rest = samples_of(&samples, &template);
        let graph = DeformationGraph::on_surface(
            &rest.0,
            &rest.1,
            &faces,
            o.depth,
            (o.nodes, o.neighbors, o.step.skin),
        );
        Self {
            graph,
            samples,
            template,
            rest,
            motion: None,
            before: None,
            floor: 0.0,
            distance_floor: 0.0,
            markers,
        }
    }

    /// Records how closely `cage`, fitted to `target`, lies on it (the samples' RMS
    /// point-to-plane distance): the next step's floor.
    pub(crate) fn settle(&mut self, cage: &[[f64; 3]], target: &Target, o: &TrackingOptions) {
        let (samples, normals) = samples_of(&self.samples, cage);
        self.floor = plane_rms_to(&samples, &normals, target, o.step.max_distance).0;
        let d = distance_to(&samples, &normals, target, &o.step);
        self.distance_floor = if self.distance_floor > 0.0 {
            self.distance_floor.min(d)
        } else {
            d
        };
    }

    /// Carries the template onto `target` (frame `frame`, 0 the first, with its markers);
    /// returns the moved cage.
    pub(crate) fn step(
        &mut self,
        target: &Target,
        frame: usize,
        o: &TrackingOptions,
    ) -> (Vec<[f64; 3]>, TrackingReport) {
        let step = TrackOptions {
            stop_rms: o.discrepancy * self.floor,
            ..o.step.clone()
        };
        let samples = Samples {
            positions: &self.rest.0,
            normals: &self.rest.1,
        };
        let mut candidates = Vec::new();
        if let (Some(last), Some(before), true) = (&self.motion, &self.before, o.predict) {
            candidates.push(last.extrapolated(before));
        }
        candidates.extend(self.motion.clone());
        candidates.push(NodeMotion::identity(self.graph.len()));
        let near = o.restart * self.distance_floor;
        let starts = warm_starts(
            &self.graph,
            samples,
            target,
            &candidates,
            near,
            o.starts,
            &o.step,
        );
        let markers = self.markers.get(&frame).map_or(&[][..], Vec::as_slice);
        // One start: the prediction was near. Several: each tracked, the nearest result kept.
        let tracked: Vec<_> = starts
            .iter()
            .map(|(initial, start)| {
                let (moved, motion, stats) = track(
                    &self.graph,
                    &self.template,
                    samples,
                    target,
                    markers,
                    Some(initial),
                    &step,
                );
                let d = if starts.len() > 1 {
                    motion_distance(&self.graph, samples, target, &motion, &o.step)
                } else {
                    0.0
                };
                (moved, motion, stats, *start, d)
            })
            .collect();
        let (moved, motion, stats, start, _) = tracked
            .into_iter()
            .min_by(|a, b| a.4.total_cmp(&b.4))
            .expect("at least one start");
        self.before = self.motion.replace(motion);
        let report = TrackingReport {
            matched: stats.matched,
            rms_before: stats.rms_before,
            rms_after: stats.rms_after,
            iterations: stats.iterations,
            stop_rms: step.stop_rms,
            markers: markers.len(),
            marker_rms: stats.marker_rms,
            start_rigid: start.start == Start::Rigid,
            start_distance: start.distance,
            given_distance: start.given_distance,
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

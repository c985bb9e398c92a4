//! What [`crate::fit_scan`] tells its caller while it works ([`Progress`]), and the one handle
//! on the caller's callback that every step of the pipeline borrows ([`Notify`]). Nothing here
//! prints (STYLE.md rule 6).

use subfit_fit::{IterationRow, StageEvent, StageReport};

/// A step of [`crate::fit_scan`], for progress display.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Reading the input file.
    Read,
    /// Target analysis: normals, orientation, curvature, indices.
    Analyse,
    /// Building the initial control mesh.
    Init,
    /// The fitting stages.
    Fit,
}

/// What [`crate::fit_scan`] tells its caller while it works.
#[derive(Clone, Copy, Debug)]
pub enum Progress<'a> {
    /// A step starts.
    Step(Step),
    /// An iteration ended.
    Iteration {
        /// Stage.
        stage: usize,
        /// The row.
        row: &'a IterationRow,
    },
    /// A stage ended.
    Stage(&'a StageReport),
    /// Something the user should know (also kept in the report).
    Warning(&'a str),
}

/// The caller's progress callback, if any, as the pipeline's steps use it.
pub(crate) struct Notify<'p> {
    callback: Option<&'p mut dyn FnMut(Progress<'_>)>,
}

impl<'p> Notify<'p> {
    /// Wraps the callback given to [`crate::fit_scan`].
    pub(crate) fn new(callback: Option<&'p mut dyn FnMut(Progress<'_>)>) -> Self {
        Self { callback }
    }

    /// Tells the caller that step `s` starts.
    pub(crate) fn step(&mut self, s: Step) {
        if let Some(p) = self.callback.as_mut() {
            p(Progress::Step(s));
        }
    }

    /// Tells the caller `msg` and keeps it in `kept` (the report's warnings).
    pub(crate) fn warn(&mut self, kept: &mut Vec<String>, msg: String) {
        if let Some(p) = self.callback.as_mut() {
            p(Progress::Warning(&msg));
        }
        kept.push(msg);
    }

    /// Passes on an event of the fitting stages.
    pub(crate) fn stage_event(&mut self, e: StageEvent<'_>) {
        if let Some(p) = self.callback.as_mut() {
            match e {
                StageEvent::Iteration { stage, row } => p(Progress::Iteration { stage, row }),
                StageEvent::Stage(s) => p(Progress::Stage(s)),
            }
        }
    }
}

//! The real-data scoreboard: `subfit bench corpus` runs the fit on a corpus of real models and
//! measures every result with an independent judge ([`mod@judge`]), a code path of its own (parry's
//! closest points on triangles, the limit surface evaluated exactly and sampled by area) that
//! shares nothing with the fit's foot points or the report's distances.

pub mod judge;

pub use judge::{judge, Candidate, Direction, JudgeError, JudgeOptions, Judgement, Reference};

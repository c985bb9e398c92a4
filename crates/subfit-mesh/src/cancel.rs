//! Cooperative cancellation of long computations.
//!
//! The library does no signal handling and keeps no global state: a caller that wants to stop a
//! long phase (target analysis, contouring, simplification, fitting) puts a [`Cancel`] token in
//! the phase's options, keeps a clone, and calls [`Cancel::cancel`] on it (from another thread,
//! a signal handler's thread, or a progress callback). The phase polls the token in its long
//! loops and returns its crate's `Interrupted` error soon after; nothing it computed is
//! returned.
//!
//! ```
//! use subfit_mesh::{Cancel, Cancelled};
//! let token = Cancel::new();
//! let seen_by_the_phase = token.clone();
//! assert_eq!(seen_by_the_phase.check(), Ok(()));
//! token.cancel();
//! assert!(seen_by_the_phase.is_cancelled());
//! assert_eq!(seen_by_the_phase.check(), Err(Cancelled));
//! ```

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A cancellation token: a shared flag, cheap to clone (clones share the flag) and to poll (one
/// relaxed atomic load).
///
/// `Default` is a fresh token that nobody else holds, so it is never cancelled. Tokens compare
/// equal whatever their state and identity: a token is not a setting, and option structs that
/// hold one compare by their settings alone.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

/// The error of [`Cancel::check`]: the token was cancelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, thiserror::Error)]
#[error("interrupted")]
pub struct Cancelled;

impl Cancel {
    /// A fresh, not cancelled token.
    pub fn new() -> Self {
        Self::default()
    }

    /// Cancels the token and all its clones; irreversible. Callable from any thread.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Self::cancel`] was called on this token or a clone. Cost: one relaxed atomic
    /// load, cheap enough to call per item of a parallel loop.
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once the token is cancelled, for use with `?`.
    #[inline]
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

impl PartialEq for Cancel {
    /// Always true (see the type's documentation).
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for Cancel {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag_and_defaults_are_independent() {
        let a = Cancel::default();
        let b = a.clone();
        let other = Cancel::default();
        assert!(!a.is_cancelled() && !b.is_cancelled());
        std::thread::scope(|s| {
            s.spawn(|| b.cancel());
        });
        assert!(a.is_cancelled());
        assert_eq!(a.check(), Err(Cancelled));
        assert!(!other.is_cancelled());
        assert_eq!(other.check(), Ok(()));
        assert_eq!(a, other);
        assert_eq!(Cancelled.to_string(), "interrupted");
    }
}

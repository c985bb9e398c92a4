//! The library's errors as Python exceptions (DESIGN.md §2 `subfit-py`): bad input and bad
//! options → `ValueError`; a file the system refuses → `OSError` (`FileNotFoundError`, …);
//! numerical trouble and failed steps → `RuntimeError` with the library's diagnostics;
//! cancellation → `KeyboardInterrupt`.

use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyKeyboardInterrupt, PyOSError, PyPermissionError,
    PyRuntimeError, PyValueError,
};
use pyo3::PyErr;
use subfit::io::ErrorKind;

/// A `ValueError` with `msg`.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// The exception for a pipeline error.
pub fn fit_error(e: subfit::Error) -> PyErr {
    match e {
        subfit::Error::Options(_) | subfit::Error::Input { .. } | subfit::Error::Budget(_) => {
            PyValueError::new_err(e.to_string())
        }
        subfit::Error::Io(io) => io_error(io),
        subfit::Error::Interrupted => PyKeyboardInterrupt::new_err("subfit: interrupted"),
        subfit::Error::Init { .. } | subfit::Error::Fit { .. } | subfit::Error::Output(_) => {
            PyRuntimeError::new_err(e.to_string())
        }
    }
}

/// The exception for a file error: the system's refusals as `OSError` subclasses, everything
/// about the content as `ValueError`. The message names the file and the element.
pub fn io_error(e: subfit::io::Error) -> PyErr {
    let msg = e.to_string();
    match &e.kind {
        ErrorKind::Io(io) => match io.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(msg),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(msg),
            _ => PyOSError::new_err(msg),
        },
        ErrorKind::IsDirectory => PyIsADirectoryError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}

/// The exception for an evaluation error (bad face, sub-patch or parameter → `ValueError`; a
/// topology the scheme cannot evaluate → `ValueError`; an incomplete evaluation →
/// `RuntimeError`).
pub fn eval_error(e: subfit::subdiv::EvalError) -> PyErr {
    use subfit::subdiv::EvalError as E;
    match e {
        E::Topology(_)
        | E::FaceOutOfRange { .. }
        | E::SubOutOfRange { .. }
        | E::OutOfDomain { .. }
        | E::PositionCount { .. } => PyValueError::new_err(e.to_string()),
        _ => PyRuntimeError::new_err(e.to_string()),
    }
}

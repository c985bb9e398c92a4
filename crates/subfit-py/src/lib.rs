//! `subfit._subfit`: the native half of the `subfit` Python package (pyo3 + numpy).
//!
//! This crate only translates: numpy arrays and Python keywords in, the library's types
//! through, numpy arrays and plain Python objects out. The pipeline is [`subfit::fit_scan`],
//! the operators and evaluators are `subfit::subdiv`'s, the files `subfit::io`'s. The public,
//! documented Python API is the pure-Python package around it (`python/subfit`), which
//! coerces array-likes (`np.ascontiguousarray`) and shapes the results; everything is
//! validated here again, so a bad array gives a `ValueError` naming what is wrong and never a
//! panic.
//!
//! Long computations (fits, operators, closest points, IMLS) run with the interpreter
//! detached (`Python::detach`, the GIL released), so other Python threads — a Dask worker's,
//! say — keep running.

mod arrays;
mod errors;
mod fit;
mod imls;
mod io;
mod sequence;
mod surface;

use pyo3::prelude::*;

/// The native module `subfit._subfit`.
#[pymodule]
fn _subfit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_class::<fit::NativeFit>()?;
    m.add_function(wrap_pyfunction!(sequence::fit_sequence_py, m)?)?;
    m.add_class::<sequence::NativeSequence>()?;
    m.add_class::<surface::NativeSurface>()?;
    m.add_function(wrap_pyfunction!(surface::sampling_operator, m)?)?;
    m.add_class::<imls::ImlsField>()?;
    m.add_function(wrap_pyfunction!(io::read, m)?)?;
    m.add_function(wrap_pyfunction!(io::write, m)?)?;
    m.add_function(wrap_pyfunction!(io::formats, m)?)?;
    Ok(())
}

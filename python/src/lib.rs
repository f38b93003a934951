//! Python package over the navigators of `estimator-core` and host-sim's dataset reader and
//! metrics (the native module `estimator._estimator`; `python/pysrc/estimator` wraps it).
//!
//! Every function checks all of its input before it runs anything, and reports bad input as a
//! Python exception naming the argument and the index; nothing here panics.

use pyo3::prelude::*;

mod arrays;
mod attitude;
mod config;
mod dataset;
mod ins;
mod score;

/// The native module.
#[pymodule]
fn _estimator(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<attitude::PyAttitudeNavigator>()?;
    m.add_class::<ins::PyInsNavigator>()?;
    m.add_function(wrap_pyfunction!(attitude::run_attitude, m)?)?;
    m.add_function(wrap_pyfunction!(ins::run_ins, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::read_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::replay, m)?)?;
    m.add_function(wrap_pyfunction!(score::score, m)?)?;
    m.add_function(wrap_pyfunction!(config::default_config, m)?)?;
    m.add("REASONS", attitude::REASONS.to_vec())?;
    Ok(())
}

//! The workspace root package: it owns the end-to-end tests in `tests/` and the criterion
//! benchmarks in `benches/`, and re-exports the two crates they exercise.
pub use estimator_core;
pub use host_sim;

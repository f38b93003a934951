//! `host-sim`: the host-side simulator, dataset replay and scoring for `estimator-core`.
//!
//! Not yet built (see the project's issues); for now it re-exports the core so the workspace
//! builds end to end.
pub use estimator_core;

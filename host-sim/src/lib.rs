//! `host-sim`: the host-side simulator, dataset replay and scoring for `estimator-core`.
//!
//! * [`trajectory`]: smooth analytic SE(3) motions with exact derivatives.
//! * [`sensors`]: IMU, magnetometer, GNSS, camera and barometer models.
//! * [`scenario`]: named and TOML scenarios.
//! * [`dataset`]: the EuRoC / ASL dataset folder, written and streamed.
#![warn(missing_docs)]

pub mod dataset;
pub mod scenario;
pub mod sensors;
pub mod trajectory;

pub use estimator_core;

//! `host-sim`: the host-side simulator, dataset replay and scoring for `estimator-core`.
//!
//! * [`baseline`]: Madgwick and Mahony, measured on the same data as the filter.
//! * [`calibrate`]: IMU and magnetometer noise from a static recording (Allan deviation).
//! * [`trajectory`]: smooth analytic SE(3) motions with exact derivatives.
//! * [`sensors`]: IMU, magnetometer, GNSS, camera and barometer models.
//! * [`scenario`]: named and TOML scenarios.
//! * [`dataset`]: the EuRoC / ASL dataset folder, written and streamed.
//! * [`metrics`]: streaming scores against ground truth; [`stats`]: chi-square quantiles.
//! * [`plot`]: the PNG plots.
//! * [`montecarlo`]: consistency over seeds against chi-square bands.
//! * [`faults`]: the fault bench: detection and recovery times, false-valid epochs and ATE of
//!   the INS navigator over the fault scenarios.
//! * [`progress`]: progress of the long commands on stderr: a bar on a terminal, plain lines
//!   off one.
//! * [`replay`]: the filter over a dataset folder, with its outputs (trajectories, metrics, plots).
//! * [`bench`](mod@bench): the filter over every dataset under a folder, against published references.
//! * [`output`]: output folders written beside their target and moved into place on success;
//!   nothing host-sim did not create is deleted or overwritten.
#![warn(missing_docs)]

pub mod baseline;
pub mod bench;
pub mod calibrate;
pub mod dataset;
pub mod faults;
pub mod metrics;
pub mod montecarlo;
pub mod output;
pub mod plot;
pub mod progress;
pub mod replay;
pub mod scenario;
pub mod sensors;
pub mod stats;
pub mod trajectory;

pub use estimator_core;

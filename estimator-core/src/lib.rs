//! `estimator-core`: allocation-free, panic-free state estimation for microcontrollers.
//!
//! * [`lie`]: the fixed-size Lie groups SO(2), SE(2), SO(3), SE(3) with every Jacobian, generic
//!   over `f32` and `f64`, following one convention (right perturbation `a ⊕ τ = a·exp(τ^)`,
//!   eq. 4.5 of the paper below). Its module docs state the conventions.
//! * [`eskf`]: the on-manifold error-state Kalman filter, 15-state inertial ([`eskf::Ins`]) and
//!   attitude-only ([`eskf::Ahrs`]), with gated square-root Joseph and iterated updates and typed outcomes.
//! * [`gn`]: a fixed-size Gauss-Newton / Levenberg-Marquardt solver on manifolds with robust
//!   losses, and on top of it [`gn::solve_pnp`], triangulation and rotation from vector pairs.
//! * [`scalar`]: the [`Real`] scalar trait, with an all-`f32` sine/cosine for Cortex-M4F.
//! * `kernels` (private): the hand-written small-matrix routines the modules above call, each
//!   with its reference test.
//!
//! Nothing allocates and nothing panics: every entry point that takes outside data returns a
//! `Result` with a typed error.
//!
//! The mathematics follows *Lie Groups and Smooth Manifolds for Robotic State Estimation*;
//! equation numbers in the docs refer to it, and each equation is restated where it is used.
//!
//! The crate re-exports the [`nalgebra`] it is built with, so a user's matrices are always of
//! the same version: `use estimator_core::nalgebra::Vector3;`.
//!
//! # Where to start
//!
//! * A firmware main loop calls a navigator ([`nav`]), one timestamped sample at a time:
//!   [`nav::AttitudeNavigator`] (attitude and gyro bias from gyro, accelerometer and an optional
//!   magnetometer: an AHRS) or [`nav::InsNavigator`] (position, velocity, attitude and IMU
//!   biases from an IMU and GNSS, with delayed and out-of-order measurements and fault
//!   handling). The [`nav`] module docs are the tuning guide.
//! * For a Cortex-M firmware crate: `firmware/src/starter.rs` in the repository is a main loop
//!   with both navigators, to copy unchanged as the `src/main.rs` of a fresh `cortex-m-rt`
//!   crate; `firmware/README.md`, "Starting your own firmware", gives every step (the crate is
//!   not on a registry: depend by path or git; minimum Rust 1.89).
//! * The examples: `examples/main_loop.rs` (both navigators in a firmware-style loop on the
//!   host: `cargo run --release -p estimator-core --example main_loop`) and
//!   `examples/lie_tour.rs` (the Lie groups at work).
//! * Below the navigators: the filters ([`eskf::Ins`], [`eskf::Ahrs`]) for your own sensor
//!   policy, and [`gn`] for batch problems such as [`gn::solve_pnp`].
//!
//! The crate's README (a first example) is compiled as a doctest.
//!
//! Where things go: a new measurement model is one file in `eskf/models/` (plus its Jacobian
//! test in `tests/eskf_jacobians.rs`), a new Lie group one file in `lie/` (plus its entry in the
//! battery of `tests/lie_battery.rs`), a new kernel one file in `kernels/` with its reference
//! test.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod eskf;
pub mod gn;
mod kernels;
pub mod lie;
pub mod nav;
pub mod scalar;
// The unit tests share the integration tests' support module (and need `std` for it).
#[cfg(test)]
extern crate std;
#[cfg(test)]
#[path = "../tests/support/mod.rs"]
mod test_support;

pub use nalgebra;
pub use scalar::Real;

// The README's example is compiled and run with the doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

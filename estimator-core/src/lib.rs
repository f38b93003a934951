//! `estimator-core`: allocation-free, panic-free state estimation for microcontrollers.
//!
//! * [`lie`]: the fixed-size Lie groups SO(2), SE(2), SO(3), SE(3) with every Jacobian, generic
//!   over `f32` and `f64`, following one convention (right perturbation `a ⊕ τ = a·exp(τ^)`,
//!   seed paper eq. 4.5). Its module docs state the conventions.
//! * [`eskf`]: the on-manifold error-state Kalman filter, 15-state inertial ([`eskf::Ins`]) and
//!   attitude-only ([`eskf::Ahrs`]), with gated Joseph and iterated updates and typed outcomes.
//! * [`gn`]: a fixed-size Gauss-Newton / Levenberg-Marquardt solver on manifolds with robust
//!   losses, and on top of it [`gn::solve_pnp`], triangulation and rotation from vector pairs.
//! * [`scalar`]: the [`Real`] scalar trait, with an all-`f32` sine/cosine for Cortex-M4F.
//!
//! Nothing allocates and nothing panics: every entry point that takes outside data returns a
//! `Result` with a typed error.
//!
//! Built for size (opt-level `"s"` or `"z"`, or the `compact` feature), a few kernels are
//! compiled once and called instead of being inlined at every use: the same source and the same
//! results, only the inlining differs (`build.rs` sets `cfg(estimator_compact)`). Opt-level 2 and
//! 3 keep the specialised, faster copies.
//!
//! The mathematics follows the seed paper on Lie groups for state estimation; equation numbers in
//! the docs refer to it.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod eskf;
pub mod gn;
mod kernels;
pub mod lie;
pub mod scalar;
#[cfg(test)]
mod test_support;

pub use scalar::Real;

//! `estimator-core`: allocation-free, panic-free state estimation for microcontrollers.
//!
//! * [`lie`]: the fixed-size Lie groups SO(2), SE(2), SO(3), SE(3) with every Jacobian, generic
//!   over `f32` and `f64`, following one convention (right perturbation `a ⊕ τ = a·exp(τ^)`,
//!   seed paper eq. 4.5). Its module docs state the conventions.
//! * [`scalar`]: the [`Real`] scalar trait, with an all-`f32` sine/cosine for Cortex-M4F.
//!
//! The mathematics follows the seed paper on Lie groups for state estimation; equation numbers in
//! the docs refer to it.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod eskf;
pub mod gn;
pub mod lie;
pub mod scalar;

pub use scalar::Real;

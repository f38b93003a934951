//! What a measurement model provides to the update: its linearization and its noise.

use crate::eskf::error::EskfError;
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// A measurement linearized at a state: the residual `r = z ⊖ h(x)` (for a vector measurement
/// `z − h(x)`; angles wrapped) and `H`, with `h(x ⊕ δx) ≈ h(x) + H δx` (*Lie Groups and Smooth
/// Manifolds for Robotic State Estimation*, eq. 4.3 and Definition 4.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearization<T: Real, const N: usize, const M: usize> {
    /// `r = z ⊖ h(x)`.
    pub residual: SVector<T, M>,
    /// `H` (`M × N`), right Jacobian with respect to the error state.
    pub jacobian: SMatrix<T, M, N>,
}

/// A fixed-size measurement model `z = h(x) + n`, `n ~ N(0, R)`, for the nominal state `S` with an
/// `N`-dimensional error state. Implement it for a new sensor (one file in `eskf/models/`).
pub trait Measurement<T: Real, S, const N: usize, const M: usize> {
    /// `r = z ⊖ h(x)` and `H` at `x`.
    ///
    /// # Errors
    /// Non-finite data, or a state where `h` is not defined (landmark behind the camera,
    /// heading at ±90° pitch, ...).
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, M>, EskfError>;

    /// The noise covariance `R` (must be symmetric positive definite).
    #[must_use]
    fn noise(&self) -> SMatrix<T, M, M>;
}

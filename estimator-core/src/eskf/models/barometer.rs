//! Barometric altitude.

use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::Real;
use nalgebra::{Matrix1, SMatrix, Vector1};

/// Barometric altitude (world `z`, up): `h(x) = p_z + offset`, `H = e₃ᵀ` on `δp`.
///
/// ```
/// use estimator_core::eskf::{BaroAltitude, FilterConfig, Ins, InsState, UpdateOptions};
/// use nalgebra::SMatrix;
///
/// let mut ins = Ins::new(InsState::identity(), SMatrix::identity(), FilterConfig::<f64>::default()).unwrap();
/// ins.update(&BaroAltitude::new(2.0, 0.5), &UpdateOptions::default()).unwrap();
/// assert!(ins.state().position.z > 1.5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaroAltitude<T: Real> {
    /// Measured altitude, m.
    pub altitude: T,
    /// Known offset between the barometric and the world altitude datum, m.
    pub offset: T,
    /// `R = σ²`, m².
    pub noise: Matrix1<T>,
}

impl<T: Real> BaroAltitude<T> {
    /// Zero offset, noise `σ²`.
    #[must_use]
    pub fn new(altitude: T, sigma: T) -> Self {
        Self {
            altitude,
            offset: T::zero(),
            noise: Matrix1::new(sigma * sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 1> for BaroAltitude<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 1>, EskfError> {
        if !(self.altitude.is_finite() && self.offset.is_finite()) {
            return Err(EskfError::NonFinite);
        }
        let mut jacobian = SMatrix::<T, 1, 15>::zeros();
        if let Some(e) = jacobian.get_mut((0, 8)) {
            *e = T::one();
        }
        Ok(Linearization {
            residual: Vector1::new(self.altitude - (x.position.z + self.offset)),
            jacobian,
        })
    }

    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

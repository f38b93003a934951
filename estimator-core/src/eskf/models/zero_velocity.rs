//! The zero-velocity update of a body known to be at rest.

use super::shared::{isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::Real;
use nalgebra::Matrix3;

/// Zero-velocity update: `z = 0`, `h(x) = v`, `H = [0, I, 0, 0, 0]`.
///
/// ```
/// use estimator_core::eskf::{FilterConfig, Ins, InsState, UpdateOptions, ZeroVelocity};
/// use nalgebra::SMatrix;
///
/// let mut ins = Ins::new(InsState::identity(), SMatrix::identity(), FilterConfig::<f64>::default()).unwrap();
/// ins.update(&ZeroVelocity::new(0.01), &UpdateOptions::default()).unwrap();
/// assert!(ins.sigmas()[3] < 0.011); // the velocity is now known to about σ
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZeroVelocity<T: Real> {
    /// `R`, (m/s)².
    pub noise: Matrix3<T>,
}

impl<T: Real> ZeroVelocity<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(sigma: T) -> Self {
        Self {
            noise: isotropic(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for ZeroVelocity<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        Ok(three_rows(-x.velocity, &[], &[3]))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

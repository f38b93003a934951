//! The zero-velocity update of a body known to be at rest.

use super::shared::{isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::{AhrsAccelBiasState, InsState};
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

/// The attitude filter's velocity (columns 9–11). With the spread of the body's velocity as
/// its noise (a hand-held body moves at up to about 1 m/s) it is a bound on the velocity, not
/// a rest: through the velocity's covariance with the tilt (the tilt error turns gravity into
/// a velocity error that grows as `g t δθ`) it measures the tilt.
impl<T: Real> Measurement<T, AhrsAccelBiasState<T>, 12, 3> for ZeroVelocity<T> {
    fn linearize(&self, x: &AhrsAccelBiasState<T>) -> Result<Linearization<T, 12, 3>, EskfError> {
        Ok(three_rows(-x.velocity, &[], &[9]))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

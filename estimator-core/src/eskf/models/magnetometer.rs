//! Three-axis magnetometer against a world reference field.

use super::shared::{attitude_only, in_body, isotropic};
use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::all_finite;
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// Three-axis magnetometer against a world reference field: `h(x) = Rᵀ m_w`,
/// `H = [[Rᵀ m_w]×, 0, …]` (only the attitude columns are nonzero). For both filters.
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, Magnetometer, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut ahrs = Ahrs::new(AhrsState::identity(), SMatrix::identity() * 0.01, FilterConfig::<f64>::default()).unwrap();
/// let reference = Vector3::new(0.0, 22.0, -42.0); // µT, north and down
/// let reading = reference; // level, facing east: the body sees the world field
/// ahrs.update(&Magnetometer::new(reading, reference, 0.5), &UpdateOptions::default()).unwrap();
/// assert!(ahrs.sigmas()[2] < 0.1); // yaw is now observed
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnetometer<T: Real> {
    /// Measured field, body frame (any unit, the same as `reference`).
    pub field: Vector3<T>,
    /// The world reference field `m_w`.
    pub reference: Vector3<T>,
    /// `R`, unit².
    pub noise: Matrix3<T>,
}

impl<T: Real> Magnetometer<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(field: Vector3<T>, reference: Vector3<T>, sigma: T) -> Self {
        Self {
            field,
            reference,
            noise: isotropic(sigma),
        }
    }
}

impl<T: Real> Magnetometer<T> {
    /// The residual `z − Rᵀ m_w` and the attitude block `[Rᵀ m_w]×`: the part that does not
    /// depend on the filter (one compiled copy for both).
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(Vector3<T>, Matrix3<T>), EskfError> {
        if !(all_finite(self.field.as_slice()) && all_finite(self.reference.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        if self.field.norm_squared() <= T::zero() || self.reference.norm_squared() <= T::zero() {
            return Err(EskfError::ZeroNorm);
        }
        let (predicted, d_attitude) = in_body(attitude, &self.reference);
        Ok((self.field - predicted, d_attitude))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 3> for Magnetometer<T> {
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 3>, EskfError> {
        attitude_only(self.attitude_parts(x.attitude()))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

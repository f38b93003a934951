//! GNSS position (with the antenna lever arm) and GNSS velocity.

use super::shared::{isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::all_finite;
use crate::lie::LieGroup;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// GNSS antenna position in the world frame, with the antenna at `lever_arm` in the body frame.
///
/// `h(x) = p + R ℓ`; `H = [−R[ℓ]×, 0, I, 0, 0]` (blocks δθ, δv, δp, δb_g, δb_a), the attitude
/// block being the action Jacobian `−R[ℓ]×`.
///
/// ```
/// use estimator_core::eskf::{FilterConfig, GnssPosition, Ins, InsState, UpdateOptions, UpdateOutcome};
/// use nalgebra::{SMatrix, Vector3};
///
/// let p0 = SMatrix::<f64, 15, 15>::identity() * 0.01;
/// let mut ins = Ins::new(InsState::identity(), p0, FilterConfig::default()).unwrap();
/// // A fix 5 cm east of the estimate, σ = 0.1 m, antenna 0.3 m ahead of the IMU.
/// let fix = GnssPosition::new(Vector3::new(0.35, 0.0, 0.0), Vector3::new(0.3, 0.0, 0.0), 0.1);
/// let outcome = ins.update(&fix, &UpdateOptions::default()).unwrap();
/// assert!(matches!(outcome, UpdateOutcome::Accepted { .. }));
/// assert!(ins.state().position.x > 0.0); // pulled towards the fix
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssPosition<T: Real> {
    /// Measured antenna position `z`, world frame, m.
    pub position: Vector3<T>,
    /// Antenna position `ℓ` in the body frame, m.
    pub lever_arm: Vector3<T>,
    /// `R`, m².
    pub noise: Matrix3<T>,
}

impl<T: Real> GnssPosition<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(position: Vector3<T>, lever_arm: Vector3<T>, sigma: T) -> Self {
        Self {
            position,
            lever_arm,
            noise: isotropic(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for GnssPosition<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        if !(all_finite(self.position.as_slice()) && all_finite(self.lever_arm.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        let (r_l, d_attitude, _) = x.attitude.act_jac(&self.lever_arm);
        let residual = self.position - (x.position + r_l);
        Ok(three_rows(residual, &[(0, &d_attitude)], &[6]))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// GNSS velocity in the world frame (lever arm neglected): `h(x) = v`, `H = [0, I, 0, 0, 0]`.
///
/// ```
/// use estimator_core::eskf::{FilterConfig, GnssVelocity, Ins, InsState, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut ins = Ins::new(InsState::identity(), SMatrix::identity(), FilterConfig::<f32>::default()).unwrap();
/// ins.update(&GnssVelocity::new(Vector3::new(1.0, 0.0, 0.0), 0.05), &UpdateOptions::default()).unwrap();
/// assert!((ins.state().velocity.x - 1.0).abs() < 0.01);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssVelocity<T: Real> {
    /// Measured velocity, world frame, m/s.
    pub velocity: Vector3<T>,
    /// `R`, (m/s)².
    pub noise: Matrix3<T>,
}

impl<T: Real> GnssVelocity<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(velocity: Vector3<T>, sigma: T) -> Self {
        Self {
            velocity,
            noise: isotropic(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for GnssVelocity<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        if !all_finite(self.velocity.as_slice()) {
            return Err(EskfError::NonFinite);
        }
        Ok(three_rows(self.velocity - x.velocity, &[], &[3]))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

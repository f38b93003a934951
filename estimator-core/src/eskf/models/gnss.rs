//! GNSS position (with the antenna lever arm) and GNSS velocity.

use super::shared::{horizontal_vertical, isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::{all_finite, positive_finite, usable_variance};
use crate::lie::LieGroup;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// GNSS antenna position in the world frame, with the antenna at `lever_arm` in the body frame.
///
/// `h(x) = p + R ℓ`; `H = [−R[ℓ]×, 0, I, 0, 0]` (blocks δθ, δv, δp, δb_g, δb_a), the attitude
/// block being the action Jacobian `−R[ℓ]×`.
///
/// The noise `R` is any symmetric positive definite 3 × 3 matrix in the world (ENU) frame:
/// [`GnssPosition::new`] makes it `σ² I`, [`GnssPosition::with_sigmas`] `diag(σ_h², σ_h², σ_v²)`
/// (a receiver's horizontal and vertical accuracy, the vertical typically 1.5–2 times the
/// horizontal).
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

    /// Separate horizontal and vertical noise: `R = diag(σ_h², σ_h², σ_v²)` in the world (ENU)
    /// frame, `sigma_h` the 1σ of east and north, `sigma_v` of up, m. With `σ_h = σ_v` it is
    /// [`GnssPosition::new`].
    ///
    /// ```
    /// use estimator_core::eskf::{FilterConfig, GnssPosition, Ins, InsState, UpdateOptions};
    /// use nalgebra::{SMatrix, Vector3};
    ///
    /// let p0 = SMatrix::<f64, 15, 15>::identity();
    /// let mut ins = Ins::new(InsState::identity(), p0, FilterConfig::default()).unwrap();
    /// // 1 m horizontally, 3 m vertically: the fix moves east more than up.
    /// let fix = GnssPosition::with_sigmas(Vector3::new(1.0, 0.0, 1.0), Vector3::zeros(), 1.0, 3.0)
    ///     .unwrap();
    /// ins.update(&fix, &UpdateOptions::default()).unwrap();
    /// assert!(ins.state().position.x > ins.state().position.z);
    /// assert!(GnssPosition::with_sigmas(Vector3::zeros(), Vector3::zeros(), 1.0, 0.0).is_err());
    /// ```
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a non-finite position or lever arm;
    /// [`EskfError::NoiseNotPositiveDefinite`] for a sigma that is not finite and positive, or
    /// whose square is below the variance floor or above the variance ceiling
    /// ([`crate::Real::VARIANCE_FLOOR_F64`], [`crate::Real::VARIANCE_CEILING_F64`]). Nothing is
    /// built.
    pub fn with_sigmas(
        position: Vector3<T>,
        lever_arm: Vector3<T>,
        sigma_h: T,
        sigma_v: T,
    ) -> Result<Self, EskfError> {
        if !(all_finite(position.as_slice()) && all_finite(lever_arm.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        let usable = |s: T| positive_finite(s) && usable_variance(s * s);
        if !(usable(sigma_h) && usable(sigma_v)) {
            return Err(EskfError::NoiseNotPositiveDefinite);
        }
        Ok(Self {
            position,
            lever_arm,
            noise: horizontal_vertical(sigma_h, sigma_v),
        })
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

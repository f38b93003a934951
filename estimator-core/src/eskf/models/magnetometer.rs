//! The magnetometer: the whole field against a world reference, or only its heading.

use super::shared::{attitude_only, in_body, isotropic};
use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::{all_finite, mat3};
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix1, Matrix3, SMatrix, Vector1, Vector3};

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

/// Magnetic heading: the azimuth of the measured field in the world, against the azimuth of
/// the reference field. It corrects the rotation about the vertical only, so a magnetic
/// disturbance can move the heading but never the tilt. For both filters.
///
/// With `c = R m_b` the measured field seen in the world and `u` the world up (`[0, 0, 1]`,
/// ENU), the azimuth is `ψ(c) = atan2(c_y, c_x)` and the residual
/// `r = wrap(ψ(m_w) − ψ(R̂ m_b))` in `(−π, π]`. A rotation of the world by `α` about `u`
/// changes `ψ` by exactly `α`; the right error `δθ` rotates the world by `R̂ δθ`, whose
/// vertical part is `uᵀ R̂ δθ`. The row is that part alone, `H = [uᵀ R̂, 0, …]`: the tilt part
/// of `∂ψ/∂δθ` is left out on purpose (the yaw-only magnetometer fusion of most AHRS, PX4's
/// EKF2 among them).
///
/// Singular ([`EskfError::ZeroNorm`]) when the measured or the reference field has no
/// horizontal part (`c_x² + c_y² ≤ (10⁻³‖c‖)²`, within 0.06° of vertical, where the azimuth is
/// not defined).
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, MagneticHeading, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut ahrs = Ahrs::new(AhrsState::identity(), SMatrix::identity() * 0.01, FilterConfig::<f64>::default()).unwrap();
/// let reference = Vector3::new(0.0, 22.0, -42.0); // µT, north and down
/// // The body is turned 0.1 rad to the left of where the filter thinks: the field it reads
/// // points 0.1 rad to the right of north in its own frame.
/// let reading = Vector3::new(22.0 * 0.1f64.sin(), 22.0 * 0.1f64.cos(), -42.0);
/// ahrs.update(&MagneticHeading::new(reading, reference, 0.01), &UpdateOptions::default()).unwrap();
/// let (roll, pitch, yaw) = ahrs.state().attitude.quaternion().euler_angles();
/// assert!((yaw - 0.1).abs() < 0.01 && roll.abs() < 1e-9 && pitch.abs() < 1e-9);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticHeading<T: Real> {
    /// Measured field, body frame (any unit).
    pub field: Vector3<T>,
    /// The world reference field `m_w` (only its azimuth is used).
    pub reference: Vector3<T>,
    /// `R = σ²`, rad².
    pub noise: Matrix1<T>,
}

impl<T: Real> MagneticHeading<T> {
    /// Noise `σ²` (σ in radians of heading).
    #[must_use]
    pub fn new(field: Vector3<T>, reference: Vector3<T>, sigma: T) -> Self {
        Self {
            field,
            reference,
            noise: Matrix1::new(sigma * sigma),
        }
    }

    /// The wrapped residual and the attitude row `uᵀ R̂` (the third row of `R̂`).
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(T, [T; 3]), EskfError> {
        if !(all_finite(self.field.as_slice()) && all_finite(self.reference.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        let r = attitude.rotation_matrix();
        let c = mat3::mul_vec(&r, &self.field);
        let (Some(measured), Some(reference)) = (azimuth(&c), azimuth(&self.reference)) else {
            return Err(EskfError::ZeroNorm);
        };
        let (s, co) = (reference - measured).sincos();
        Ok((s.arctan2(co), [r.m31, r.m32, r.m33]))
    }
}

/// `atan2(v_y, v_x)`, or `None` when `v` is within `10⁻³` rad of vertical (or zero).
fn azimuth<T: Real>(v: &Vector3<T>) -> Option<T> {
    let horizontal = v.x * v.x + v.y * v.y;
    let limit = T::lit(1e-6) * v.z * v.z;
    // False for NaN and for the zero vector.
    (horizontal > limit && horizontal > T::zero()).then(|| v.y.arctan2(v.x))
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 1> for MagneticHeading<T> {
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 1>, EskfError> {
        let (residual, row) = self.attitude_parts(x.attitude())?;
        let mut jacobian = SMatrix::<T, 1, N>::zeros();
        for (d, s) in jacobian.iter_mut().zip(row) {
            *d = s;
        }
        Ok(Linearization {
            residual: Vector1::new(residual),
            jacobian,
        })
    }

    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

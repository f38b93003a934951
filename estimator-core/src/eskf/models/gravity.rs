//! The accelerometer as a gravity sensor: its direction (both filters), or the whole specific
//! force of a body at rest with the accelerometer bias (15-state filter).

use super::shared::{attitude_only, in_body, isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::{AhrsAccelBiasState, ErrorState, InsState};
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::{all_finite, mat3};
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// Accelerometer gravity direction (tilt aiding, for a body near rest):
/// `z = f_m/‖f_m‖`, `h(x) = Rᵀ u` with `u` the world up direction, `H = [[Rᵀ u]×, 0, …]`.
/// For both filters.
///
/// The model neglects the accelerometer bias and any non-gravitational acceleration; both are
/// time-correlated errors (`‖b_a‖/g`, `‖a‖/g` radians), so `σ` must cover them, or repeated
/// updates make the filter overconfident. In the 15-state filter, which estimates `b_a`, prefer
/// [`AccelerometerAtRest`] or [`ZeroVelocity`](super::ZeroVelocity) at rest.
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, GravityDirection, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut ahrs = Ahrs::new(AhrsState::identity(), SMatrix::identity() * 0.01, FilterConfig::<f32>::default()).unwrap();
/// // Level: the accelerometer reads +g along body z.
/// ahrs.update(&GravityDirection::new(Vector3::new(0.0, 0.0, 9.81), 0.02), &UpdateOptions::default()).unwrap();
/// assert!(ahrs.sigmas()[0] < 0.03 && ahrs.sigmas()[1] < 0.03); // roll and pitch observed
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GravityDirection<T: Real> {
    /// Measured specific force `f_m`, body frame (normalized inside).
    pub accel: Vector3<T>,
    /// World direction the accelerometer reads at rest (`−g/‖g‖`, `[0, 0, 1]` in ENU).
    pub up: Vector3<T>,
    /// `R` on the unit direction (rad², small-angle).
    pub noise: Matrix3<T>,
}

impl<T: Real> GravityDirection<T> {
    /// ENU up `[0, 0, 1]`, isotropic noise `σ² I` (σ in radians of tilt).
    #[must_use]
    pub fn new(accel: Vector3<T>, sigma: T) -> Self {
        Self {
            accel,
            up: Vector3::z(),
            noise: isotropic(sigma),
        }
    }
}

impl<T: Real> GravityDirection<T> {
    /// The residual `f_m/‖f_m‖ − Rᵀ u` and the attitude block `[Rᵀ u]×` (one compiled copy for
    /// both filters).
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(Vector3<T>, Matrix3<T>), EskfError> {
        if !(all_finite(self.accel.as_slice()) && all_finite(self.up.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        let (na, nu) = (mat3::norm(&self.accel), mat3::norm(&self.up));
        if !(na > T::zero() && nu > T::zero()) {
            return Err(EskfError::ZeroNorm);
        }
        let (predicted, d_attitude) = in_body(attitude, &(self.up / nu));
        Ok((self.accel / na - predicted, d_attitude))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 3> for GravityDirection<T> {
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 3>, EskfError> {
        attitude_only(self.attitude_parts(x.attitude()))
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// The accelerometer of a body at rest (or its mean over a while, with the mean linear
/// acceleration in the noise), for the filters with an accelerometer bias:
/// `h(x) = Rᵀ(−g) + M b_a`, `H = [[Rᵀ(−g)]×, 0, …, M]` (`M` on the `b_a` columns; `M = I` for
/// one sample). Unlike [`GravityDirection`] it models the accelerometer bias,
/// so repeated updates at rest stay consistent (tilt and horizontal bias are separated only as
/// far as the data allow).
///
/// ```
/// use estimator_core::eskf::{AccelerometerAtRest, FilterConfig, Ins, InsState, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let p0 = SMatrix::<f64, 15, 15>::identity() * 0.01;
/// let mut ins = Ins::new(InsState::identity(), p0, FilterConfig::default()).unwrap();
/// // Level and at rest, with a 0.05 m/s² bias on the vertical axis.
/// let reading = Vector3::new(0.0, 0.0, 9.81 + 0.05);
/// for _ in 0..50 {
///     ins.update(&AccelerometerAtRest::new(reading, 0.01), &UpdateOptions::default()).unwrap();
/// }
/// assert!((ins.state().accel_bias.z - 0.05).abs() < 0.005);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelerometerAtRest<T: Real> {
    /// Measured specific force `f_m`, body frame, m/s².
    pub accel: Vector3<T>,
    /// World gravity `g` (`[0, 0, −9.81]`).
    pub gravity: Vector3<T>,
    /// `R`, (m/s²)².
    pub noise: Matrix3<T>,
    /// `M` in `h(x) = Rᵀ(−g) + M b_a`: the identity for one sample; for a mean over samples
    /// taken while the body turned, the mean rotation from each sample's body to the last,
    /// `M = mean(R_eᵀ R_i)` (the bias turns with the body).
    pub bias_map: Matrix3<T>,
}

impl<T: Real> AccelerometerAtRest<T> {
    /// ENU gravity `[0, 0, −9.81]`, isotropic noise `σ² I`, `M = I`.
    #[must_use]
    pub fn new(accel: Vector3<T>, sigma: T) -> Self {
        Self {
            accel,
            gravity: Vector3::new(T::zero(), T::zero(), T::lit(-9.81)),
            noise: isotropic(sigma),
            bias_map: Matrix3::identity(),
        }
    }
}

impl<T: Real> AccelerometerAtRest<T> {
    /// `z − (Rᵀ(−g) + b_a)` and `H`, with the bias columns starting at `column`.
    fn linearization<const N: usize>(
        &self,
        attitude: &So3<T>,
        accel_bias: &Vector3<T>,
        column: usize,
    ) -> Result<Linearization<T, N, 3>, EskfError> {
        let finite = all_finite(self.accel.as_slice())
            && all_finite(self.gravity.as_slice())
            && all_finite(self.bias_map.as_slice());
        if !finite {
            return Err(EskfError::NonFinite);
        }
        if self.accel.norm_squared() <= T::zero() {
            return Err(EskfError::ZeroNorm);
        }
        let (predicted, d_attitude) = in_body(attitude, &-self.gravity);
        let residual = self.accel - (predicted + mat3::mul_vec(&self.bias_map, accel_bias));
        Ok(three_rows(
            residual,
            &[(0, &d_attitude), (column, &self.bias_map)],
            &[],
        ))
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for AccelerometerAtRest<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        self.linearization(&x.attitude, &x.accel_bias, 12)
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// The attitude filter with both biases: the bias columns are 6–8.
impl<T: Real> Measurement<T, AhrsAccelBiasState<T>, 12, 3> for AccelerometerAtRest<T> {
    fn linearize(&self, x: &AhrsAccelBiasState<T>) -> Result<Linearization<T, 12, 3>, EskfError> {
        self.linearization(&x.attitude, &x.accel_bias, 6)
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

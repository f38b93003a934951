//! The inputs of the prediction: IMU samples, the IMU noise model and the filter
//! configuration.

use super::error::EskfError;
use crate::kernels::{all_finite, mat3, non_negative_finite, positive_finite};
use crate::Real;
use nalgebra::Vector3;

/// One IMU sample: body angular rate `ω_m` (rad/s), specific force `f_m` (m/s²), and the interval
/// `dt` (s) over which both are taken as constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample<T: Real> {
    /// Measured angular rate `ω_m`, body frame, rad/s.
    pub gyro: Vector3<T>,
    /// Measured specific force `f_m`, body frame, m/s².
    pub accel: Vector3<T>,
    /// Time step `dt > 0`, s.
    pub dt: T,
}

/// Continuous-time IMU noise in Kalibr units.
///
/// White noise densities `σ_g` (rad/s/√Hz) and `σ_a` (m/s²/√Hz); bias random walks `σ_bg`
/// (rad/s²/√Hz) and `σ_ba` (m/s³/√Hz). The discrete covariances over `dt` are `σ² dt` for the
/// integrated quantities (see the module docs for `Q`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuNoise<T: Real> {
    /// `σ_g`, rad/s/√Hz.
    pub gyroscope_noise_density: T,
    /// `σ_bg`, rad/s²/√Hz.
    pub gyroscope_random_walk: T,
    /// `σ_a`, m/s²/√Hz.
    pub accelerometer_noise_density: T,
    /// `σ_ba`, m/s³/√Hz.
    pub accelerometer_random_walk: T,
}

impl<T: Real> ImuNoise<T> {
    /// A consumer MEMS IMU (BMI088-class): `σ_g = 1.7e-4`, `σ_bg = 2e-5`, `σ_a = 2e-3`,
    /// `σ_ba = 3e-4`.
    #[must_use]
    pub fn mems() -> Self {
        Self {
            gyroscope_noise_density: T::lit(1.7e-4),
            gyroscope_random_walk: T::lit(2.0e-5),
            accelerometer_noise_density: T::lit(2.0e-3),
            accelerometer_random_walk: T::lit(3.0e-4),
        }
    }

    pub(crate) fn is_valid(&self) -> bool {
        let all = [
            self.gyroscope_noise_density,
            self.gyroscope_random_walk,
            self.accelerometer_noise_density,
            self.accelerometer_random_walk,
        ];
        all.iter().all(|x| non_negative_finite(*x))
    }
}

/// Filter configuration shared by both filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterConfig<T: Real> {
    /// IMU noise (Kalibr units).
    pub imu_noise: ImuNoise<T>,
    /// Gravity `g` in the world frame (ENU, z up): default `[0, 0, −9.81]`.
    pub gravity: Vector3<T>,
    /// Largest accepted `dt` (s); larger gives [`EskfError::DtTooLarge`]. Default 0.1 s.
    pub max_dt: T,
}

impl<T: Real> Default for FilterConfig<T> {
    fn default() -> Self {
        Self {
            imu_noise: ImuNoise::mems(),
            gravity: Vector3::new(T::zero(), T::zero(), T::lit(-9.81)),
            max_dt: T::lit(0.1),
        }
    }
}

impl<T: Real> FilterConfig<T> {
    /// `Ok` when every number is finite, the noise densities are `≥ 0`, `max_dt > 0`, and the
    /// largest process noise a prediction can add, `σ² max_dt` for each density, is at most
    /// the variance ceiling [`Real::VARIANCE_CEILING_F64`] (a finite density can still
    /// overflow it).
    pub fn validate(&self) -> Result<(), EskfError> {
        if !(all_finite(self.gravity.as_slice()) && self.max_dt.is_finite()) {
            return Err(EskfError::NonFinite);
        }
        if !self.imu_noise.is_valid() {
            return Err(EskfError::NoiseNotPositiveDefinite);
        }
        if self.max_dt <= T::zero() {
            return Err(EskfError::InvalidOption);
        }
        let n = &self.imu_noise;
        let densities = [
            n.gyroscope_noise_density,
            n.gyroscope_random_walk,
            n.accelerometer_noise_density,
            n.accelerometer_random_walk,
        ];
        if !densities
            .iter()
            .all(|d| *d * *d * self.max_dt <= T::lit(T::VARIANCE_CEILING_F64))
        {
            return Err(EskfError::NoiseNotPositiveDefinite);
        }
        Ok(())
    }
}

pub(crate) fn check_dt<T: Real>(dt: T, max_dt: T) -> Result<(), EskfError> {
    if !dt.is_finite() {
        Err(EskfError::NonFinite)
    } else if dt <= T::zero() {
        Err(EskfError::NonPositiveDt)
    } else if dt > max_dt {
        Err(EskfError::DtTooLarge)
    } else {
        Ok(())
    }
}

/// The world's up direction `u = −g / ‖g‖` for the gravity `g` (the direction a specific force
/// at rest points), or `None` when `‖g‖` is zero or not finite.
pub(crate) fn up_direction<T: Real>(gravity: &Vector3<T>) -> Option<Vector3<T>> {
    let norm = mat3::norm(gravity);
    positive_finite(norm).then(|| -gravity / norm)
}

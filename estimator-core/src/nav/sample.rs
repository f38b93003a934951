//! The checks every navigator makes on a sample before it reads it.

use super::error::NavError;
use super::{IMU_ACCEL_LIMIT, IMU_RATE_LIMIT};
use crate::kernels::all_finite;
use crate::Real;
use nalgebra::Vector3;

/// `Ok` for a finite vector that is not all zero (no sensor reads exactly zero on every axis).
pub(crate) fn check_vector<T: Real>(v: &Vector3<T>) -> Result<(), NavError> {
    if !all_finite(v.as_slice()) {
        Err(NavError::NonFinite)
    } else if v.x == T::zero() && v.y == T::zero() && v.z == T::zero() {
        Err(NavError::ZeroVector)
    } else {
        Ok(())
    }
}

/// `Ok` for an IMU sample a sensor can give: finite, an accelerometer not all zero, and every
/// axis within [`IMU_RATE_LIMIT`] and [`IMU_ACCEL_LIMIT`] (larger values are faults, and would
/// overflow the covariance in `f32`).
pub(crate) fn check_imu<T: Real>(gyro: &Vector3<T>, accel: &Vector3<T>) -> Result<(), NavError> {
    if !all_finite(gyro.as_slice()) {
        return Err(NavError::NonFinite);
    }
    check_vector(accel)?;
    let within = |v: &Vector3<T>, limit: f64| v.iter().all(|x| x.abs() <= T::lit(limit));
    if within(gyro, IMU_RATE_LIMIT) && within(accel, IMU_ACCEL_LIMIT) {
        Ok(())
    } else {
        Err(NavError::OutOfRange)
    }
}

/// `min ≤ x ≤ max` (false for NaN), the bounds `f64` literals folded into `T` (no `f64`
/// arithmetic at run time).
pub(crate) fn within_limits<T: Real>(x: T, min: f64, max: f64) -> bool {
    x >= T::lit(min) && x <= T::lit(max)
}

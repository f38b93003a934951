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

/// [`check_imu`] against a sensor's own full scale: `Ok((gyro at its rail, accelerometer at
/// its rail))`, an axis within 0.1 % of `gyro_range` or `accel_range` being at the rail (a
/// 16-bit converter's last 32 codes); an axis beyond its range by more than 1 % (or beyond
/// [`IMU_RATE_LIMIT`], [`IMU_ACCEL_LIMIT`]) is no reading the sensor can give:
/// [`NavError::OutOfRange`].
pub(crate) fn check_imu_range<T: Real>(
    gyro: &Vector3<T>,
    accel: &Vector3<T>,
    gyro_range: T,
    accel_range: T,
) -> Result<(bool, bool), NavError> {
    if !all_finite(gyro.as_slice()) {
        return Err(NavError::NonFinite);
    }
    check_vector(accel)?;
    let largest = |v: &Vector3<T>| {
        let (x, y, z) = (v.x.abs(), v.y.abs(), v.z.abs());
        let xy = if x > y { x } else { y };
        if xy > z {
            xy
        } else {
            z
        }
    };
    let rail = |v: &Vector3<T>, range: T, limit: f64| -> Result<bool, NavError> {
        let m = largest(v);
        if m > range * T::lit(1.01) || m > T::lit(limit) {
            Err(NavError::OutOfRange)
        } else {
            Ok(m >= range * T::lit(0.999))
        }
    };
    Ok((
        rail(gyro, gyro_range, IMU_RATE_LIMIT)?,
        rail(accel, accel_range, IMU_ACCEL_LIMIT)?,
    ))
}

/// `min ≤ x ≤ max` (false for NaN), the bounds `f64` literals folded into `T` (no `f64`
/// arithmetic at run time).
pub(crate) fn within_limits<T: Real>(x: T, min: f64, max: f64) -> bool {
    x >= T::lit(min) && x <= T::lit(max)
}

//! IMU faults: clipped and stuck samples. The sample is still integrated (there is no other
//! measurement of the motion); the covariance is widened by what it may hide.

use super::report::InsEvent;
use super::window::Interval;
use super::{InsNavigator, Mode};
use crate::Real;
use nalgebra::Vector3;

/// The rate error a stuck gyro axis may hide when the gyro's range is not configured, rad/s.
const STUCK_RATE_UNKNOWN_RANGE: f64 = 1.0;

/// `true` when some axis of `v` is at 99.9 % of `range` or beyond (`range > 0`).
fn at_limit<T: Real>(v: &Vector3<T>, range: T) -> bool {
    range > T::zero() && v.iter().any(|x| x.abs() >= range * T::lit(0.999))
}

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// Checks one IMU sample for clipping (an axis at its range) and a stuck gyro axis (the
    /// same value for `gyro_stuck_s` while another axis changes). A faulty sample widens the
    /// filter: velocity by `σ = range_a dt` for a clipped accelerometer, attitude by
    /// `σ = range_g dt` (tilt and heading) for a clipped or stuck gyro.
    pub(super) fn check_imu_faults(
        &mut self,
        t_ns: u64,
        gyro: &Vector3<T>,
        accel: &Vector3<T>,
        interval: Option<&Interval<T>>,
    ) {
        let c = &self.config;
        let accel_clipped = at_limit(accel, c.accelerometer_range);
        let gyro_clipped = at_limit(gyro, c.gyro_range);
        let mut stuck = false;
        if c.gyro_stuck_s > T::zero() && self.last_sample.is_some() {
            let last = self.stuck.last;
            let changed = (0..3).filter(|&i| gyro.get(i) != last.get(i)).count();
            let limit = (c.gyro_stuck_s * T::lit(1e3)).to_count();
            for (i, since) in self.stuck.since.iter_mut().enumerate() {
                if gyro.get(i) == last.get(i) && changed > 0 {
                    let start = *since.get_or_insert(t_ns);
                    let held_ms = (t_ns.saturating_sub(start) / 1_000_000).min(u64::from(u32::MAX));
                    stuck |= held_ms >= u64::from(limit);
                } else {
                    *since = None;
                }
            }
        }
        self.stuck.last = *gyro;
        if !(accel_clipped || gyro_clipped || stuck) {
            return;
        }
        self.report.imu_fault = true;
        self.counters.imu_faults = self.counters.imu_faults.saturating_add(1);
        let (Mode::Running(ins), Some(interval)) = (&mut self.mode, interval) else {
            return;
        };
        let dt = interval.dt;
        let mut failed = false;
        if accel_clipped {
            failed |= ins.widen_velocity(c.accelerometer_range * dt).is_err();
        }
        if gyro_clipped || stuck {
            let range = if c.gyro_range > T::zero() {
                c.gyro_range
            } else {
                T::lit(STUCK_RATE_UNKNOWN_RANGE)
            };
            failed |= ins.widen_attitude(range * dt, range * dt).is_err();
        }
        if failed {
            self.counters.numerical_failures = self.counters.numerical_failures.saturating_add(1);
        } else {
            self.report.event = Some(InsEvent::ImuFault);
        }
    }
}

//! IMU faults: clipped and stuck samples. The sample is still integrated (there is no other
//! measurement of the motion); the covariance is widened by what it may hide.

use super::report::InsEvent;
use super::window::Interval;
use super::{InsNavigator, Mode};
use crate::kernels::larger;
use crate::Real;
use nalgebra::Vector3;

/// The smallest rate error a stuck gyro axis is taken to hide, rad/s.
const STUCK_RATE_FLOOR: f64 = 1.0;

/// After a faulty IMU sample, the velocity and position are reported invalid for this long,
/// ns (1 s): the samples between two detected ones may be faulty too.
const FAULT_HOLD_NS: u64 = 1_000_000_000;

/// Samples of each accelerometer axis remembered for the saturation check.
const HISTORY: usize = 16;

/// Earlier samples among the last [`HISTORY`] that must hold exactly the same magnitude above
/// 2 g for a sample to be taken as saturated: the third sample at a rail is the first flagged.
const RAIL_MATCHES: usize = 2;

/// Per accelerometer axis, the magnitudes of the last [`HISTORY`] samples: a magnitude above
/// 2 g met exactly [`RAIL_MATCHES`] times before is a saturation level. Noise and motion do
/// not repeat a large value exactly; a clipped axis does, sample after sample, even when it
/// touches its rail only at the peaks of a vibration (two or three samples a period). One
/// exact repeat is not enough: a quantized vibration peaking above 2 g repeats a value by
/// chance a few times a minute (about 9 samples in 120 s in the clipping scenario), two
/// repeats almost never.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Repeats<T: Real> {
    history: [[T; HISTORY]; 3],
    next: usize,
}

impl<T: Real> Repeats<T> {
    pub(super) fn new() -> Self {
        Self {
            history: [[T::zero(); HISTORY]; 3],
            next: 0,
        }
    }

    /// Takes a sample; returns the saturation level when an axis sits at one (its configured
    /// `range`, or a magnitude whose square is above `floor_sq`, met [`RAIL_MATCHES`] times in
    /// the history).
    fn clipped(&mut self, v: &Vector3<T>, range: T, floor_sq: T) -> Option<T> {
        let mut level = None;
        let slot = self.next % HISTORY;
        for (x, past) in v.iter().zip(self.history.iter_mut()) {
            let a = x.abs();
            if range > T::zero() && a >= range * T::lit(0.999) {
                level = Some(range);
            } else if a * a > floor_sq && past.iter().filter(|p| **p == a).count() >= RAIL_MATCHES {
                level = Some(a);
            }
            if let Some(p) = past.get_mut(slot) {
                *p = a;
            }
        }
        self.next = (slot + 1) % HISTORY;
        level
    }
}

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// Checks one IMU sample for saturation (an accelerometer axis at its configured range, or
    /// at a magnitude above 2 g met exactly [`RAIL_MATCHES`] times within the last [`HISTORY`]
    /// samples; a gyro axis
    /// at its configured range) and a stuck gyro axis (the same value for `gyro_stuck_s` while
    /// another axis changes). A faulty sample widens the filter by what it may hide: the
    /// velocity by `σ = a_max dt` for a saturated accelerometer (`a_max` the saturation
    /// level), the attitude by `σ = 2 ω_max dt` (tilt and heading; `ω_max` the largest rate
    /// seen, at least 1 rad/s; never past a variance of π² per axis) for a saturated or stuck gyro.
    pub(super) fn check_imu_faults(
        &mut self,
        t_ns: u64,
        gyro: &Vector3<T>,
        accel: &Vector3<T>,
        interval: Option<&Interval<T>>,
    ) {
        let c = &self.config;
        // (2 g)², so that no square root is taken per sample.
        let two_g_sq = c.attitude.filter.gravity.norm_squared() * T::lit(4.0);
        let accel_level = self
            .stuck
            .accel_repeats
            .clipped(accel, c.accelerometer_range, two_g_sq);
        let accel_clipped = accel_level.is_some();
        let gyro_clipped = c.gyro_range > T::zero()
            && gyro.iter().any(|w| w.abs() >= c.gyro_range * T::lit(0.999));
        for (w, peak) in gyro.iter().zip(self.stuck.gyro_peak.iter_mut()) {
            *peak = larger(*peak, w.abs());
        }
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
        self.stuck.invalid_until = Some(t_ns.saturating_add(FAULT_HOLD_NS));
        self.counters.imu_faults = self.counters.imu_faults.saturating_add(1);
        let accel_range = accel_level.unwrap_or(c.accelerometer_range);
        let peak = self
            .stuck
            .gyro_peak
            .x
            .max(self.stuck.gyro_peak.y)
            .max(self.stuck.gyro_peak.z);
        let rate = c
            .gyro_range
            .max(peak * T::lit(2.0))
            .max(T::lit(STUCK_RATE_FLOOR));
        let (Mode::Running(ins, _), Some(interval)) = (&mut self.mode, interval) else {
            return;
        };
        let dt = interval.dt;
        let mut failed = false;
        if accel_clipped {
            failed |= ins.widen_velocity(accel_range * dt).is_err();
        }
        if gyro_clipped || stuck {
            // Widened by `rate · dt`, but never beyond a variance of π² per axis: past it the
            // attitude is unknown, and a larger number only costs precision.
            let p = ins.covariance();
            let largest = (0..3).fold(T::zero(), |m, k| p.get((k, k)).map_or(m, |d| m.max(*d)));
            let room = T::pi() * T::pi() - largest;
            let step = rate * dt;
            let sigma = if step * step <= room {
                step
            } else if room > T::zero() {
                room.sqrt_rn()
            } else {
                T::zero()
            };
            if sigma > T::zero() {
                failed |= ins.widen_attitude(sigma, sigma).is_err();
            }
        }
        if failed {
            self.counters.numerical_failures = self.counters.numerical_failures.saturating_add(1);
        } else {
            self.report.event = Some(InsEvent::ImuFault);
        }
    }
}

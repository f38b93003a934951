//! The error of integrating a vibrating specific force from its samples.
//!
//! With instantaneous IMU samples (`instantaneous_imu`), each interval's velocity increment is
//! integrated with the mean of its two ends, the trapezoid rule, which errs by
//! `∫ f dt − dt (f₀ + f₁)/2 = −dt³ f''(ξ)/12` for a specific force `f(t)`. The second difference
//! of the samples, `d₂ = f_k − 2 f_{k−1} + f_{k−2} ≈ dt² f''`, measures it: `e ≈ dt |d₂| / 12`
//! per interval. Smooth motion keeps `e` far below the accelerometer's noise; a vibration
//! within a few times the sampling rate does not (23 Hz of ±40 m/s² sampled at 200 Hz: about
//! 9 mm/s per interval, against 0.14 mm/s of a 2e-3 m/s²/√Hz noise density), and a filter that
//! models only the noise then claims a velocity it does not have.
//!
//! White noise of density `N_a` gives `E|d₂|² = 3 · 6 N_a²/dt` (three axes, `1 + 4 + 1` times
//! the per-sample variance `N_a²/dt`). A sample whose `|d₂|²` exceeds [`NOISE_MULTIPLE`] times
//! that (for noise alone, the chi-square of 3 degrees of freedom beyond 27: 6e-6 of samples)
//! widens the velocity by `σ = e` on every axis (`e` points along `d₂` in the body frame; every
//! axis is its bound in the world frame). Below the threshold `e²` is at most
//! `162 N_a² dt / 144`, about the noise's own `N_a² dt` per interval, which the filter models.

use super::{InsNavigator, Mode};
use crate::Real;
use nalgebra::Vector3;

/// Multiple of white noise's `E|d₂|²` above which the integration error is added (see the
/// module docs).
const NOISE_MULTIPLE: f64 = 9.0;

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// Widens the filter's velocity by the trapezoid error of the interval ending at the
    /// sample `accel` (its `dt`), from the second difference with the two samples before it;
    /// then remembers the previous sample as the one before the next.
    pub(super) fn widen_for_vibration(&mut self, accel: &Vector3<T>, dt: T) {
        let Some((_, previous)) = self.last_sample else {
            return;
        };
        let Some(before) = self.accel_before.replace(previous) else {
            return;
        };
        let d2 = accel - previous * T::lit(2.0) + before;
        let c = &self.config.attitude;
        let density = c.filter.imu_noise.accelerometer_noise_density;
        let d2_sq = d2.norm_squared();
        // |d₂|² > 9 · 18 N_a² / dt, without the division.
        if !(c.instantaneous_imu && d2_sq * dt > T::lit(NOISE_MULTIPLE * 18.0) * density * density)
        {
            return;
        }
        if let Mode::Running(ins, _) = &mut self.mode {
            let sigma = dt * d2_sq.sqrt_rn() / T::lit(12.0);
            if ins.widen_velocity(sigma).is_err() {
                self.counters.numerical_failures =
                    self.counters.numerical_failures.saturating_add(1);
            }
        }
    }
}

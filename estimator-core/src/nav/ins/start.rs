//! Start and restart: the INS takes over from the alignment at the first usable fix, and an
//! IMU gap sends it back to aligning.

use super::report::{AidStatus, InsEvent};
use super::window::Increment;
use super::{InsNavigator, Mode, INVALID_START};
use crate::eskf::Ins;
use crate::lie::LieGroup;
use crate::nav::attitude::AttitudeNavigator;
use crate::Real;
use nalgebra::Vector3;

/// The velocity's 1σ at start when the first fix has none, m/s: a road vehicle or a drone
/// moves slower than this.
const UNKNOWN_VELOCITY_SIGMA: f64 = 30.0;

/// The tilt and heading the alignment may be off by beyond its covariance when it ran while
/// moving, rad (3° and 5°).
const MOVING_TILT_SIGMA: f64 = 0.052_359_88;
const MOVING_YAW_SIGMA: f64 = 0.087_266_46;

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// Starts the INS at the filter's time `t_f` from the alignment and a fix valid `dt`
    /// earlier, if the alignment is ready (tilt valid; heading valid with a magnetometer);
    /// otherwise the fix is counted as unused.
    ///
    /// The attitude navigator's estimate is at the newest sample; the output predictor's
    /// rotation `ΔR` over the horizon carries it back, `R_f = R ΔRᵀ`
    /// ([`Ins::from_attitude_filter`]). The antenna position is carried to `t_f` by the fix's
    /// velocity (`p + v dt`), and the lever arm removed with that attitude (`p − R_f ℓ`). When
    /// the body was not at rest, the attitude (3° tilt, 5° heading) and the biases (their
    /// priors, `gyro_bias_sigma` and `accelerometer_bias_sigma`) are widened.
    #[inline(never)] // once per start: its matrices stay out of the caller's frame
    pub(super) fn start(
        &mut self,
        dt: T,
        position: Vector3<T>,
        sigma_position: T,
        velocity: Option<(Vector3<T>, T)>,
    ) {
        let Mode::Aligning(att) = &self.mode else {
            return;
        };
        let report = att.report();
        let heading_ready =
            self.config.attitude.magnetometer.is_none() || report.heading.is_valid();
        let (Some(filter), true) = (att.filter(), report.tilt.is_valid() && heading_ready) else {
            self.counters.unused = self.counters.unused.saturating_add(1);
            return;
        };
        let carry = self.window.rotation.inverse();
        let attitude = filter.state().attitude.compose(&carry);
        let (v, sigma_v) = velocity.unwrap_or((Vector3::zeros(), T::lit(UNKNOWN_VELOCITY_SIGMA)));
        let antenna = position + v * dt;
        let p = antenna - attitude.act(&self.config.gnss_lever_arm);
        let reference = att.magnetic_reference();
        let moving = !report.at_rest;
        let c = &self.config.attitude;
        let started = Ins::from_attitude_filter(filter, &carry, v, p, sigma_v, sigma_position)
            .and_then(|mut ins| {
                if moving {
                    // Aligned while moving, the attitude navigator's covariance holds only as
                    // far as its motion model did (a vehicle's sustained accelerations break
                    // it): its tilt, heading and biases are widened by their priors.
                    ins.widen_attitude(T::lit(MOVING_TILT_SIGMA), T::lit(MOVING_YAW_SIGMA))?;
                    ins.widen_biases(c.gyro_bias_sigma, c.accelerometer_bias_sigma)?;
                }
                Ok(ins)
            });
        match started {
            Ok(ins) => {
                self.mode = Mode::Running(ins);
                // Every aid starts counted as heard from now (the magnetometer fed the
                // alignment until now).
                self.last_due = [self.filter_t; 3];
                self.magnetic_reference = reference;
                self.gnss.last_position = Some(position);
                self.report.gnss = AidStatus::Fused;
                self.report.event = Some(InsEvent::Started);
            }
            Err(_) => {
                self.counters.numerical_failures =
                    self.counters.numerical_failures.saturating_add(1);
            }
        }
    }

    /// Back to aligning after an IMU gap: the buffers are emptied (their samples and
    /// measurements belong to the time before the gap) and the report says nothing is valid.
    pub(super) fn restart(&mut self) {
        if let Ok(att) = AttitudeNavigator::new(self.config.attitude) {
            self.mode = Mode::Aligning(att);
        }
        self.ring.clear();
        self.queue.clear();
        self.window = Increment::empty(Vector3::zeros(), Vector3::zeros());
        self.fresh = self.window;
        self.fresh_lag = 0;
        self.filter_t = None;
        self.last_sample = None;
        self.gnss = super::GnssTrack::default();
        self.stuck.since = [None; 3];
        self.last_due = [None; 3];
        self.last_measured = [None; 3];
        self.aid_interval = [None; 3];
        self.report.validity = INVALID_START;
    }
}

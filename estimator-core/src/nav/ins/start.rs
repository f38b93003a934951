//! Start and restart: the INS takes over from the alignment at the first usable fix, and an
//! IMU gap sends it back to aligning.

use super::buffer::FixSigma;
use super::heading::UNKNOWN_HEADING_VARIANCE;
use super::report::{AidStatus, InsEvent};
use super::window::Increment;
use super::yaw::YawBank;
use super::{InsNavigator, Mode, INVALID_START};
use crate::eskf::Ins;
use crate::kernels::{all_finite, mat3, positive_finite};
use crate::lie::LieGroup;
use crate::nav::attitude::AttitudeNavigator;
use crate::Real;
use nalgebra::Vector3;

/// The velocity's 1σ at start when the first fix has none, m/s: a road vehicle or a drone
/// moves slower than this.
const UNKNOWN_VELOCITY_SIGMA: f64 = 30.0;

/// The two fixes that start the INS are at most this far apart, ns (2 s).
const START_PAIR_NS: u64 = 2_000_000_000;

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
    ///
    /// A fix starts the INS only when it agrees with the one before it (a gross outlier must
    /// not become the start): `|p₂ − p₁ − v̄ Δt| ≤ 3 √(σ₁² + σ₂²) + 3 σ_v̄ Δt`, with `v̄` the two
    /// fixes' mean velocity (without velocities, `σ_v̄` is the 30 m/s of an unknown velocity),
    /// fixes at most 2 s apart, and `σ₁`, `σ₂` the larger of each fix's horizontal and vertical
    /// 1σ. The position starts with the second fix's covariance, `diag(σ_h², σ_h², σ_v²)`.
    #[inline(never)] // once per start: its matrices stay out of the caller's frame
    pub(super) fn start(
        &mut self,
        t_m: u64,
        dt: T,
        position: Vector3<T>,
        sigma_position: FixSigma<T>,
        velocity: Option<(Vector3<T>, T)>,
    ) {
        let Mode::Aligning(att) = &self.mode else {
            return;
        };
        let previous = self
            .gnss
            .start_candidate
            .replace((t_m, position, sigma_position, velocity));
        let agrees = previous.is_some_and(|(t_p, p_p, s_p, v_p)| {
            let gap_ns = t_m.saturating_sub(t_p);
            if gap_ns == 0 || gap_ns > START_PAIR_NS {
                return false;
            }
            let gap: T = super::seconds(gap_ns);
            let (v, sigma_v) = match (v_p, velocity) {
                (Some((a, sa)), Some((b, sb))) => ((a + b) * T::lit(0.5), sa.max(sb)),
                _ => (Vector3::zeros(), T::lit(UNKNOWN_VELOCITY_SIGMA)),
            };
            let miss = mat3::norm(&(position - p_p - v * gap));
            let (s_p, s_n) = (s_p.largest(), sigma_position.largest());
            let tolerance = T::lit(3.0) * ((s_p * s_p + s_n * s_n).sqrt_rn() + sigma_v * gap);
            miss <= tolerance
        });
        if !agrees {
            self.counters.unused = self.counters.unused.saturating_add(1);
            return;
        }
        let report = att.report();
        let has_magnetometer = self.config.attitude.magnetometer.is_some();
        let heading_ready = !has_magnetometer || report.heading.is_valid();
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
        let (gyro_bias_sigma, accel_bias_sigma) = (
            self.config.attitude.gyro_bias_sigma,
            self.config.attitude.accelerometer_bias_sigma,
        );
        // The attitude filter lives where the INS will: copied out first (a 12-state filter),
        // so that the INS is built in place rather than beside it. What the in-place start
        // checks is checked here, before the alignment is given up (the attitude filter's own
        // state is finite, an invariant of the filter).
        let aligned = *filter;
        let square = |s: T| s * s;
        let position_sigma = sigma_position.per_axis();
        let ok = all_finite(v.as_slice())
            && all_finite(p.as_slice())
            && carry.is_finite()
            && positive_finite(square(sigma_v))
            && position_sigma.iter().all(|s| positive_finite(square(*s)));
        let started = if ok {
            let bank = YawBank::new(!has_magnetometer, self.config.travel);
            self.mode = Mode::Running(Ins::unstarted(*aligned.config()), bank);
            match &mut self.mode {
                Mode::Running(ins, _) => ins
                    .restart_from_attitude_filter_per_axis(
                        &aligned,
                        &carry,
                        v,
                        p,
                        sigma_v,
                        &position_sigma,
                    )
                    .and_then(|()| {
                        if moving {
                            // Aligned while moving, the attitude navigator's covariance holds
                            // only as far as its motion model did (a vehicle's sustained
                            // accelerations break it): its tilt, heading and biases are
                            // widened by their priors.
                            ins.widen_attitude(
                                T::lit(MOVING_TILT_SIGMA),
                                T::lit(MOVING_YAW_SIGMA),
                            )?;
                            ins.widen_biases(gyro_bias_sigma, accel_bias_sigma)?;
                        }
                        if !has_magnetometer {
                            // The alignment's heading is relative to where it started: the
                            // INS's is unknown, uniform over the circle, until the GNSS track
                            // resolves it (`nav/ins/heading.rs`).
                            ins.reset_heading(
                                T::zero(),
                                T::lit(UNKNOWN_HEADING_VARIANCE).sqrt_rn(),
                            )?;
                        }
                        Ok(())
                    }),
                Mode::Aligning(_) => Ok(()),
            }
        } else {
            Err(crate::eskf::EskfError::NonFinite)
        };
        match started {
            Ok(()) => {
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
    #[cold]
    #[inline(never)] // rare: its new attitude navigator stays out of every IMU call's frame
    pub(super) fn restart(&mut self) {
        // The configuration was validated by `new`.
        self.mode = Mode::Aligning(AttitudeNavigator::waiting(self.config.attitude));
        self.ring.clear();
        self.queue.clear();
        self.window = Increment::empty(Vector3::zeros(), Vector3::zeros());
        self.fresh = self.window;
        self.fresh_lag = 0;
        self.filter_t = None;
        self.last_sample = None;
        self.accel_before = None;
        self.gnss = super::GnssTrack::default();
        self.stuck.since = [None; 3];
        self.stuck.invalid_until = None;
        self.last_due = [None; 3];
        self.last_measured = [None; 3];
        self.aid_interval = [None; 3];
        self.report.validity = INVALID_START;
    }
}

//! The INS navigator: the 15-state [`Ins`] filter with everything a vehicle's sensor stream
//! needs around it: delayed and out-of-order measurements, start-up from whatever the stream
//! gives, fault handling, and the validity of each quantity after every call.
//!
//! One call per sample, each with its own timestamp (ns): [`InsNavigator::imu`] for every IMU
//! sample, and [`InsNavigator::gnss`], [`InsNavigator::magnetometer`],
//! [`InsNavigator::barometer`] for the aiding sensors, stamped with the time the measurement
//! was *valid* (a receiver's fix arrives 0.1–0.3 s after it; stamp it with its own time).
//!
//! # Delayed fusion horizon
//!
//! The filter runs `horizon_s` behind the newest IMU sample. IMU intervals wait in a ring of
//! `H` entries, measurements in a queue of `Q`; each IMU call integrates the oldest interval
//! into the filter (one prediction), then fuses at most one measurement whose time the filter
//! has reached, in time order. An output predictor (`nav/ins/window.rs`) carries the filter's state to
//! the newest sample in O(1) per sample, so the estimate is always the present one. A
//! measurement stamped anywhere inside the horizon is fused at its own time (up to one IMU
//! interval later, its value carried over that step by the estimated rate), and the order in
//! which measurements arrive inside the horizon does not matter. The alternative, re-running
//! the filter from a stored past state, costs one 15-state prediction per buffered sample for
//! every late measurement (60 × 5,660 Cortex-M4F instructions for a 0.3 s horizon at 200 Hz);
//! the horizon costs one prediction per sample, whatever the delays.
//!
//! # Start-up
//!
//! Until the first position fix, an [`AttitudeNavigator`] aligns on the IMU and magnetometer
//! samples as they arrive (static or moving, for as long as the stream has no fix: minutes of
//! IMU data are used). When a fix comes due and the attitude navigator's tilt is valid (and its
//! heading, with a magnetometer), the INS starts at the filter's time: attitude, biases and
//! their covariance from the attitude navigator, carried back over the horizon by the output
//! predictor's rotation; position and velocity from the fix. A gap in the IMU longer than
//! `max_dt` starts the alignment again.
//!
//! # Faults
//!
//! * **GNSS.** A fix that repeats the previous one exactly is a frozen receiver: refused. Three
//!   rejected fixes in a row mark the position invalid (`FixesDisagree`): either the fixes
//!   or the estimate is wrong, and the gate alone cannot say which. A streak that begins with
//!   a jump (NIS above 100 right after fused fixes: the estimate cannot move that far in one
//!   fix interval) is the receiver's: the estimate is kept until the fixes come back to it or
//!   its own growing uncertainty lets them through. Any other streak that lasts
//!   `gnss_reset_s` takes the estimate for the wrong one (a covariance that claimed too
//!   much): position and velocity are reset to the fixes ([`Ins::reset_position`]), and the
//!   position stays invalid (`Reset`) until fixes have been fused again for 1 s. A consistent
//!   covariance needs no reset: after an outage, the position's own growth lets the first fix
//!   through the gate.
//! * **Magnetometer.** A sample whose norm differs from the reference by more than
//!   `norm_tolerance` is refused (`Faulty`); one that fails the gate is rejected. The heading
//!   is then held by the GNSS velocity and the gyro.
//! * **Barometer.** Gated.
//! * **IMU.** A sample with an axis at the sensor's range (configured, or for the
//!   accelerometer learned: a magnitude above 2 g met exactly twice before within 16 samples,
//!   which noise and motion do not do) is saturated; a
//!   gyro axis repeating its value exactly for `gyro_stuck_s` while another changes is stuck.
//!   Such a sample is still integrated (nothing else measures the motion), and the velocity
//!   (accelerometer) or attitude (gyro) covariance is widened by what it may hide.
//! * **Vibration.** A specific force that changes faster than the samples can follow (its
//!   second difference beyond what the noise gives) widens the velocity by the error of
//!   integrating it from its samples (`nav/ins/vibration.rs`).
//!
//! Nothing allocates; the navigator is a plain value.

mod aid;
mod buffer;
mod config;
mod faults;
mod heading;
mod report;
mod start;
mod track_axis;
mod validity;
mod velocity_check;
mod vibration;
mod window;
mod yaw;

pub use config::{InsConfig, Travel};
pub use report::{
    AidStatus, Aiding, InsCounters, InsEstimate, InsEvent, InsFusion, InsReport, InsValidity,
};

use crate::eskf::{ImuSample, Ins};
use crate::kernels::block::block;
use crate::kernels::{all_finite, mat3};
use crate::lie::{skew, LieGroup};
use crate::nav::attitude::{AttitudeNavigator, Reason, Validity};
use crate::nav::clock::{Clock, Tick};
use crate::nav::error::NavError;
use crate::nav::sample::{check_imu, check_vector, within_limits};
use crate::nav::{FIX_POSITION_SIGMA, FIX_VELOCITY_SIGMA};
use crate::Real;
use buffer::{Aid, AidQueue, FixSigma, ImuRing, QueueError, Queued};
use nalgebra::{Matrix3, Vector3};
use window::{Increment, Interval};
use yaw::YawBank;

/// An aiding sensor with nothing due for 2.5 of its own last intervals between measurements
/// ([`AID_STALE_INTERVALS`]) is [`AidStatus::Stale`]; before an interval is known, for this
/// long, ns (1 s).
pub const AID_STALE_NS: u64 = 1_000_000_000;

/// Twice the number of an aid's measurement intervals without a measurement that make it
/// stale (5: 2.5 intervals, two missed measurements with room for jitter).
pub const AID_STALE_INTERVALS: u64 = 5;

/// Before the first fix, the attitude navigator; then the INS.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // one of the two is always there; they share the space
enum Mode<T: Real> {
    Aligning(AttitudeNavigator<T>),
    /// The INS, and the bank of yaw hypotheses that finds its heading without a magnetometer
    /// (`nav/ins/yaw.rs`; in the space the alignment used).
    Running(Ins<T>, YawBank<T>),
}

/// The GNSS policy's memory.
#[derive(Clone, Copy, Debug, PartialEq)]
struct GnssTrack<T: Real> {
    /// The previous fix's position, for the frozen-receiver check.
    last_position: Option<Vector3<T>>,
    /// The last fix was frozen (its velocity is not fused either).
    frozen: bool,
    /// While aligning, the last fix (time, position, 1σ, velocity): the next one starts the
    /// INS if the two agree.
    #[allow(clippy::type_complexity)]
    start_candidate: Option<(u64, Vector3<T>, FixSigma<T>, Option<(Vector3<T>, T)>)>,
    /// Consecutive rejected position fixes, and the time of the first.
    rejected: u16,
    rejected_since: Option<u64>,
    /// The time of the last fused fix.
    last_fused: Option<u64>,
    /// The current rejection streak began with a jump of the fixes (never reset to them).
    jump: bool,
    /// The next velocity fix resets the velocity (after a position reset).
    reset_velocity: bool,
    /// After a reset: the time from which fixes have been fused again.
    unconfirmed: bool,
    fused_since: Option<u64>,
}

impl<T: Real> Default for GnssTrack<T> {
    fn default() -> Self {
        Self {
            last_position: None,
            frozen: false,
            start_candidate: None,
            rejected: 0,
            rejected_since: None,
            last_fused: None,
            jump: false,
            reset_velocity: false,
            unconfirmed: false,
            fused_since: None,
        }
    }
}

/// The stuck-axis check's memory: the last gyro sample and since when each axis repeats it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct StuckTrack<T: Real> {
    last: Vector3<T>,
    since: [Option<u64>; 3],
    accel_repeats: faults::Repeats<T>,
    gyro_peak: Vector3<T>,
    /// The velocity and position stay invalid until this time after a faulty sample, ns (the
    /// samples between two detected ones may be faulty too).
    invalid_until: Option<u64>,
}

/// The INS navigator (module docs), with an IMU ring of `H` intervals (64: a 0.3 s horizon at
/// 200 Hz with room) and a measurement queue of `Q` (40: over a 0.3 s horizon, a magnetometer
/// at 50 Hz, a barometer at 25 Hz and GNSS position and velocity at 5 Hz keep 26 waiting).
///
/// ```
/// use estimator_core::eskf::FilterConfig;
/// use estimator_core::nav::{AttitudeConfig, GnssFix, InsConfig, InsNavigator, MagneticConfig};
/// use nalgebra::Vector3;
///
/// let mut attitude = AttitudeConfig::<f64>::new(FilterConfig::default());
/// let field = Vector3::new(0.0, 20.0, -40.0); // µT, north along y
/// attitude.magnetometer = Some(MagneticConfig::new(0.5, Some(field)));
/// let mut nav: InsNavigator<f64> = InsNavigator::new(InsConfig::new(attitude)).unwrap();
/// // 4 s at rest at 200 Hz; magnetometer at 50 Hz; fixes at 5 Hz, valid 0.2 s before they arrive.
/// for k in 0..800u64 {
///     let t = 1_000_000_000 + k * 5_000_000;
///     nav.imu(t, &Vector3::zeros(), &Vector3::new(0.0, 0.0, 9.81)).unwrap();
///     if k % 4 == 0 {
///         nav.magnetometer(t, &field).unwrap();
///     }
///     if k % 40 == 0 && k >= 80 {
///         let fix = GnssFix::new(Vector3::new(10.0, 5.0, 2.0), Some(Vector3::zeros()), 1.0, 0.1);
///         nav.gnss(t - 200_000_000, &fix).unwrap();
///     }
/// }
/// let report = nav.report();
/// assert!(report.validity.position.is_valid() && report.validity.heading.is_valid());
/// let estimate = nav.estimate().unwrap();
/// assert!((estimate.state.position - Vector3::new(10.0, 5.0, 2.0)).norm() < 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsNavigator<T: Real, const H: usize = 64, const Q: usize = 40> {
    config: InsConfig<T>,
    horizon_ns: u64,
    reset_ns: u64,
    max_step_ns: u32,
    mode: Mode<T>,
    /// The intervals after the filter's time, oldest first.
    ring: ImuRing<T, H>,
    queue: AidQueue<T, Q>,
    /// The output predictor's increments over `ring`, and over its last `ring.len() −
    /// fresh_lag` intervals (the output predictor, `nav/ins/window.rs`).
    window: Increment<T>,
    fresh: Increment<T>,
    fresh_lag: usize,
    imu_clock: Clock,
    /// The filter's time: the end of the last interval it integrated.
    filter_t: Option<u64>,
    /// The newest IMU sample (gyro, accel), for the trapezoidal intervals.
    last_sample: Option<(Vector3<T>, Vector3<T>)>,
    /// The accelerometer sample before `last_sample`'s, for the vibration check.
    accel_before: Option<Vector3<T>>,
    /// The last integrated interval's rate and specific force (biases included).
    filter_rate: Vector3<T>,
    filter_accel: Vector3<T>,
    gnss: GnssTrack<T>,
    /// When a measurement of each aid (GNSS, magnetometer, barometer) last came due, ns.
    last_due: [Option<u64>; 3],
    /// The time of the last measurement of each, and the last nonzero interval between two
    /// of them, ns.
    last_measured: [Option<u64>; 3],
    aid_interval: [Option<u64>; 3],
    /// The magnetometer's world reference: configured, or learned by the alignment.
    magnetic_reference: Option<Vector3<T>>,
    stuck: StuckTrack<T>,
    report: InsReport<T>,
    counters: InsCounters,
}

/// A GNSS fix: antenna position and optional velocity (world frame, ENU) with their 1σ.
///
/// The position's noise is `R = diag(σ_h², σ_h², σ_v²)` ([`GnssPosition::with_sigmas`](crate::eskf::GnssPosition::with_sigmas)):
/// `σ_h = sigma_position` on east and north, and `σ_v = sigma_position_up` on up, or
/// `sigma_position` as well when that is `None` (a receiver's vertical accuracy is typically
/// 1.5–2 times its horizontal one; give it with [`GnssFix::with_vertical_sigma`]).
///
/// ```
/// use estimator_core::nav::GnssFix;
/// use nalgebra::Vector3;
///
/// let fix = GnssFix::new(Vector3::new(10.0, 5.0, 2.0), None, 1.0, 0.1).with_vertical_sigma(1.5);
/// assert_eq!((fix.sigma_position, fix.sigma_position_up), (1.0, Some(1.5)));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix<T: Real> {
    /// Antenna position, m.
    pub position: Vector3<T>,
    /// Antenna velocity, m/s, when the receiver gives one.
    pub velocity: Option<Vector3<T>>,
    /// Horizontal (east, north) position 1σ per axis, m; also the vertical one when
    /// `sigma_position_up` is `None`.
    pub sigma_position: T,
    /// Velocity 1σ per axis, m/s.
    pub sigma_velocity: T,
    /// Vertical (up) position 1σ, m; `None`: `sigma_position`.
    pub sigma_position_up: Option<T>,
}

impl<T: Real> GnssFix<T> {
    /// A fix with one position 1σ on every axis.
    #[must_use]
    pub fn new(
        position: Vector3<T>,
        velocity: Option<Vector3<T>>,
        sigma_position: T,
        sigma_velocity: T,
    ) -> Self {
        Self {
            position,
            velocity,
            sigma_position,
            sigma_velocity,
            sigma_position_up: None,
        }
    }

    /// The fix with the vertical (up) position 1σ `sigma_up`, m; `sigma_position` then holds
    /// for east and north only. Checked as `sigma_position` is, by [`InsNavigator::gnss`].
    #[must_use]
    pub fn with_vertical_sigma(self, sigma_up: T) -> Self {
        Self {
            sigma_position_up: Some(sigma_up),
            ..self
        }
    }

    /// The position's 1σ, horizontal and vertical.
    fn position_sigma(&self) -> FixSigma<T> {
        FixSigma {
            horizontal: self.sigma_position,
            up: self.sigma_position_up.unwrap_or(self.sigma_position),
        }
    }
}

fn seconds<T: Real>(ns: u64) -> T {
    // Durations here are within a horizon or a reset time: u32 nanoseconds cover 4.29 s, so
    // longer ones are counted in milliseconds.
    match u32::try_from(ns) {
        Ok(n) => T::from_count(n) * T::lit(1e-9),
        Err(_) => T::from_count(u32::try_from(ns / 1_000_000).unwrap_or(u32::MAX)) * T::lit(1e-3),
    }
}

fn nanoseconds<T: Real>(s: T) -> u64 {
    // `to_count` saturates at u32::MAX: count the horizon (≤ 10 s) in microseconds.
    u64::from((s * T::lit(1e6)).to_count()) * 1_000
}

const INVALID_START: InsValidity = InsValidity {
    tilt: Validity::Invalid(Reason::Starting),
    heading: Validity::Invalid(Reason::Starting),
    velocity: Validity::Invalid(Reason::NoFix),
    position: Validity::Invalid(Reason::NoFix),
    gyro_bias: Validity::Invalid(Reason::Starting),
    accel_bias: Validity::Invalid(Reason::Starting),
};

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// A navigator waiting for its first sample.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] for a configuration out of its domain
    /// ([`InsConfig::validate`]), or a ring of fewer than 2 intervals.
    pub fn new(config: InsConfig<T>) -> Result<Self, NavError> {
        config.validate()?;
        if H < 2 || Q < 2 {
            return Err(NavError::InvalidConfig);
        }
        Ok(Self {
            horizon_ns: nanoseconds(config.horizon_s),
            reset_ns: nanoseconds(config.gnss_reset_s),
            max_step_ns: (config.attitude.filter.max_dt * T::lit(1e9)).to_count(),
            mode: Mode::Aligning(AttitudeNavigator::new(config.attitude)?),
            ring: ImuRing::new(),
            queue: AidQueue::new(),
            window: Increment::empty(Vector3::zeros(), Vector3::zeros()),
            fresh: Increment::empty(Vector3::zeros(), Vector3::zeros()),
            fresh_lag: 0,
            imu_clock: Clock::default(),
            filter_t: None,
            last_sample: None,
            accel_before: None,
            filter_rate: Vector3::zeros(),
            filter_accel: Vector3::zeros(),
            gnss: GnssTrack::default(),
            magnetic_reference: config.attitude.magnetometer.and_then(|m| m.reference),
            last_due: [None; 3],
            last_measured: [None; 3],
            aid_interval: [None; 3],
            stuck: StuckTrack {
                last: Vector3::zeros(),
                since: [None; 3],
                accel_repeats: faults::Repeats::new(),
                gyro_peak: Vector3::zeros(),
                invalid_until: None,
            },
            report: InsReport {
                t_ns: 0,
                validity: INVALID_START,
                gnss: AidStatus::Absent,
                magnetometer: if config.attitude.magnetometer.is_some() {
                    AidStatus::Waiting
                } else {
                    AidStatus::Absent
                },
                barometer: if config.barometer_sigma.is_some() {
                    AidStatus::Waiting
                } else {
                    AidStatus::Absent
                },
                imu_fault: false,
                event: None,
                fused: None,
            },
            counters: InsCounters::default(),
            config,
        })
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &InsConfig<T> {
        &self.config
    }

    /// The report of the last call.
    #[must_use]
    pub fn report(&self) -> &InsReport<T> {
        &self.report
    }

    /// Counts since construction.
    #[must_use]
    pub fn counters(&self) -> &InsCounters {
        &self.counters
    }

    /// The delayed filter, once the INS runs (its state is `horizon_s` behind the estimate).
    #[must_use]
    pub fn filter(&self) -> Option<&Ins<T>> {
        match &self.mode {
            Mode::Running(ins, _) => Some(ins),
            Mode::Aligning(_) => None,
        }
    }

    /// The attitude navigator, while aligning.
    #[must_use]
    pub fn aligning(&self) -> Option<&AttitudeNavigator<T>> {
        match &self.mode {
            Mode::Aligning(a) => Some(a),
            Mode::Running(..) => None,
        }
    }

    /// The estimate at the newest IMU sample, once the INS runs: the filter's state carried by
    /// the output predictor (`R = R_f ΔR`, `v = v_f + g T + R_f Δv`,
    /// `p = p_f + v_f T + ½ g T² + R_f Δp`, `nav/ins/window.rs`) and its covariance carried to first
    /// order, `δθ = ΔRᵀ δθ_f`, `δv = δv_f − R_f[Δv]× δθ_f`,
    /// `δp = δp_f + T δv_f − R_f[Δp]× δθ_f`, plus the white noise over `T`
    /// (`σ_g² T`, `σ_a² T`, `σ_a² T³/3`); the bias blocks are the filter's.
    #[must_use]
    pub fn estimate(&self) -> Option<InsEstimate<T>> {
        let Mode::Running(ins, _) = &self.mode else {
            return None;
        };
        let s = ins.state();
        let w = &self.window;
        let g = ins.config().gravity;
        let r = s.attitude.rotation_matrix();
        let t = w.duration;
        let half = T::lit(0.5);
        let mut state = *s;
        state.attitude = s.attitude.compose(&w.rotation).renormalize();
        state.velocity = s.velocity + g * t + mat3::mul_vec(&r, &w.velocity);
        state.position =
            s.position + s.velocity * t + g * (half * t * t) + mat3::mul_vec(&r, &w.position);
        let p = ins.covariance();
        let dr = w.rotation.rotation_matrix();
        let a = -mat3::mul(&r, &skew(&w.velocity));
        let b = -mat3::mul(&r, &skew(&w.position));
        let (ptt, ptv, ptp) = (block(p, 0, 0), block(p, 0, 1), block(p, 0, 2));
        let (pvv, pvp, ppp) = (block(p, 1, 1), block(p, 1, 2), block(p, 2, 2));
        let n = &ins.config().imu_noise;
        let qg = n.gyroscope_noise_density * n.gyroscope_noise_density * t;
        let qa = n.accelerometer_noise_density * n.accelerometer_noise_density * t;
        let eye = Matrix3::identity();
        let attitude = mat3::mul(&mat3::mul(&dr.transpose(), &ptt), &dr) + eye * qg;
        // δv = δv_f + A δθ_f.
        let a_ptv = mat3::mul(&a, &ptv);
        let velocity = pvv
            + a_ptv
            + a_ptv.transpose()
            + mat3::mul(&mat3::mul(&a, &ptt), &a.transpose())
            + eye * qa;
        // δp = δp_f + T δv_f + B δθ_f.
        let cross = pvp * t + mat3::mul(&b, &ptp);
        let pv_t = mat3::mul(&b, &ptv) * t;
        let position = ppp
            + cross
            + cross.transpose()
            + pvv * (t * t)
            + pv_t
            + pv_t.transpose()
            + mat3::mul(&mat3::mul(&b, &ptt), &b.transpose())
            + eye * (qa * t * t / T::lit(3.0));
        Some(InsEstimate {
            t_ns: self.report.t_ns,
            state,
            covariance: [attitude, velocity, position, block(p, 3, 3), block(p, 4, 4)],
        })
    }

    /// Takes one IMU sample: gyro (rad/s) and accelerometer (m/s², specific force) in the body
    /// frame at `t_ns`. Integrates the oldest buffered interval into the filter and fuses at
    /// most one measurement that has come due.
    ///
    /// # Errors
    /// [`NavError::NonFinite`], [`NavError::ZeroVector`] (an all-zero accelerometer),
    /// [`NavError::OutOfRange`], [`NavError::TimeNotIncreasing`]; the navigator is then
    /// unchanged. A numerical failure of
    /// the filter is counted, not returned: the step is skipped.
    pub fn imu(
        &mut self,
        t_ns: u64,
        gyro: &Vector3<T>,
        accel: &Vector3<T>,
    ) -> Result<InsReport<T>, NavError> {
        let checked =
            check_imu(gyro, accel).and_then(|()| self.imu_clock.tick(t_ns, self.max_step_ns));
        let tick = match checked {
            Ok(tick) => tick,
            Err(e) => {
                self.counters.refused = self.counters.refused.saturating_add(1);
                return Err(e);
            }
        };
        self.report.event = None;
        self.report.fused = None;
        self.report.imu_fault = false;
        let interval = match tick {
            Tick::First => None,
            Tick::Step(ns) => {
                let dt = T::from_count(ns) * T::lit(1e-9);
                let (g, a) = match (self.config.attitude.instantaneous_imu, self.last_sample) {
                    (true, Some((g0, a0))) => {
                        ((g0 + gyro) * T::lit(0.5), (a0 + accel) * T::lit(0.5))
                    }
                    _ => (*gyro, *accel),
                };
                Some(Interval {
                    t_ns,
                    gyro: g,
                    accel: a,
                    dt,
                })
            }
            Tick::Gap => {
                self.restart();
                self.report.event = Some(InsEvent::Realigned);
                self.counters.realigned = self.counters.realigned.saturating_add(1);
                None
            }
        };
        if let Mode::Aligning(att) = &mut self.mode {
            if att.imu(t_ns, gyro, accel).is_err() {
                self.counters.numerical_failures =
                    self.counters.numerical_failures.saturating_add(1);
            }
        }
        self.check_imu_faults(t_ns, gyro, accel, interval.as_ref());
        if let Some(interval) = &interval {
            self.widen_for_vibration(accel, interval.dt);
        }
        self.imu_clock.set(t_ns);
        self.last_sample = Some((*gyro, *accel));
        self.counters.imu = self.counters.imu.saturating_add(1);
        self.report.t_ns = t_ns;
        match interval {
            None => {
                // The first sample (or the first after a gap): the filter's time starts here.
                self.filter_t = Some(t_ns);
                self.fresh_lag = 0;
            }
            Some(interval) => {
                // A full ring integrates its oldest interval first (a horizon longer than the
                // ring holds).
                if self.ring.is_full() {
                    self.advance();
                }
                self.ring.push(interval);
                self.window.append(&interval);
                self.fresh.append(&interval);
                if self.window_span() > self.horizon_ns {
                    self.advance();
                }
                self.fuse_due();
            }
        }
        self.refresh_validity();
        Ok(self.report)
    }

    /// Takes one GNSS fix, valid at `t_ns` (the time of the fix, not of its arrival).
    ///
    /// # Errors
    /// [`NavError::NonFinite`]; [`NavError::InvalidSigma`] for a sigma (horizontal, vertical
    /// or velocity) outside
    /// [`FIX_POSITION_SIGMA`](crate::nav::FIX_POSITION_SIGMA) or
    /// [`FIX_VELOCITY_SIGMA`](crate::nav::FIX_VELOCITY_SIGMA);
    /// [`NavError::TooOld`] for a fix the filter has passed (older than the horizon);
    /// [`NavError::InFuture`] for one stamped after the newest IMU sample by more than
    /// `max_dt`; [`NavError::QueueFull`], or [`NavError::TimeNotIncreasing`] for a second fix
    /// with the same time; the navigator is then unchanged.
    pub fn gnss(&mut self, t_ns: u64, fix: &GnssFix<T>) -> Result<InsReport<T>, NavError> {
        let velocity_ok = fix.velocity.is_none_or(|v| all_finite(v.as_slice()));
        let in_range = |s: T, [min, max]: [f64; 2]| within_limits(s, min, max);
        let sigma = fix.position_sigma();
        let sigmas_ok = in_range(sigma.horizontal, FIX_POSITION_SIGMA)
            && in_range(sigma.up, FIX_POSITION_SIGMA)
            && (fix.velocity.is_none() || in_range(fix.sigma_velocity, FIX_VELOCITY_SIGMA));
        let checked = if !(all_finite(fix.position.as_slice()) && velocity_ok) {
            Err(NavError::NonFinite)
        } else if !sigmas_ok {
            Err(NavError::InvalidSigma)
        } else {
            Ok(())
        };
        let position = Aid::Gnss(fix.position, sigma);
        let velocity = fix
            .velocity
            .map(|v| Aid::GnssVelocity(v, fix.sigma_velocity));
        self.enqueue(t_ns, position, velocity, checked)?;
        if self.report.gnss == AidStatus::Absent {
            self.report.gnss = AidStatus::Waiting;
        }
        Ok(self.report)
    }

    /// Takes one magnetometer sample (body frame, the unit of the configured sigma), valid at
    /// `t_ns`. Ignored (`Ok`) without a configured magnetometer.
    ///
    /// # Errors
    /// [`NavError::NonFinite`], [`NavError::ZeroVector`], and the time errors of
    /// [`InsNavigator::gnss`]; the navigator is then unchanged.
    pub fn magnetometer(
        &mut self,
        t_ns: u64,
        field: &Vector3<T>,
    ) -> Result<InsReport<T>, NavError> {
        let checked = check_vector(field);
        if checked.is_ok() && self.config.attitude.magnetometer.is_none() {
            return Ok(self.report);
        }
        if let (Ok(()), Mode::Aligning(att)) = (checked, &mut self.mode) {
            // The alignment takes samples as they come; a late one it cannot use is dropped.
            if att.magnetometer(t_ns, field).is_err() {
                self.counters.unused = self.counters.unused.saturating_add(1);
            }
            return Ok(self.report);
        }
        self.enqueue(t_ns, Aid::Magnetometer(*field), None, checked)?;
        Ok(self.report)
    }

    /// Takes one barometric altitude (m, up), valid at `t_ns`. Ignored (`Ok`) without a
    /// configured barometer.
    ///
    /// # Errors
    /// [`NavError::NonFinite`] and the time errors of [`InsNavigator::gnss`]; the navigator
    /// is then unchanged.
    pub fn barometer(&mut self, t_ns: u64, altitude: T) -> Result<InsReport<T>, NavError> {
        let checked = if altitude.is_finite() {
            Ok(())
        } else {
            Err(NavError::NonFinite)
        };
        if checked.is_ok() && self.config.barometer_sigma.is_none() {
            return Ok(self.report);
        }
        self.enqueue(t_ns, Aid::Barometer(altitude), None, checked)?;
        Ok(self.report)
    }

    /// Queues a measurement after its value check (`checked`) and the time checks; counts a
    /// refusal.
    fn enqueue(
        &mut self,
        t_ns: u64,
        aid: Aid<T>,
        second: Option<Aid<T>>,
        checked: Result<(), NavError>,
    ) -> Result<(), NavError> {
        let first = Queued { t_ns, aid };
        let second = second.map(|aid| Queued { t_ns, aid });
        let result = checked.and_then(|()| {
            if self.filter_t.is_some_and(|t| t_ns < t) {
                return Err(NavError::TooOld);
            }
            let newest = self.imu_clock.last().unwrap_or(0);
            if self.imu_clock.last().is_some()
                && t_ns > newest.saturating_add(u64::from(self.max_step_ns))
            {
                return Err(NavError::InFuture);
            }
            // Both halves of a fix or neither: the checks come before the first insertion.
            let room = if second.is_some() { 2 } else { 1 };
            let fits = self.queue.check(&first).and_then(|()| match &second {
                Some(v) => self.queue.check(v),
                None => Ok(()),
            });
            let fits = fits.and_then(|()| {
                if self.queue.free() >= room {
                    Ok(())
                } else {
                    Err(QueueError::Full)
                }
            });
            fits.map_err(|e| match e {
                QueueError::Full => NavError::QueueFull,
                QueueError::Duplicate => NavError::TimeNotIncreasing,
            })
        });
        if let Err(e) = result {
            self.counters.refused = self.counters.refused.saturating_add(1);
            return Err(e);
        }
        for item in core::iter::once(first).chain(second) {
            if self.queue.insert(item).is_err() {
                // Unreachable after the checks above; counted rather than trusted.
                self.counters.numerical_failures =
                    self.counters.numerical_failures.saturating_add(1);
            }
        }
        self.report.event = None;
        self.report.fused = None;
        Ok(())
    }

    /// The time the ring spans: from the filter's time to the newest sample, ns.
    fn window_span(&self) -> u64 {
        match (self.filter_t, self.imu_clock.last()) {
            (Some(f), Some(n)) => n.saturating_sub(f),
            _ => 0,
        }
    }

    /// Integrates the oldest interval into the filter (or, while aligning, lets it go).
    fn advance(&mut self) {
        let Some(interval) = self.ring.pop() else {
            return;
        };
        self.window.remove_first(&interval);
        self.filter_t = Some(interval.t_ns);
        self.filter_rate = interval.gyro;
        self.filter_accel = interval.accel;
        if let Mode::Running(ins, bank) = &mut self.mode {
            let imu = ImuSample {
                gyro: interval.gyro,
                accel: interval.accel,
                dt: interval.dt,
            };
            // Every buffered sample passed `check_imu` (finite, within range).
            if bank.predict(ins, &imu).is_err() {
                self.counters.numerical_failures =
                    self.counters.numerical_failures.saturating_add(1);
            }
        }
        // The fresh window starts where this one ends; when the filter reaches its start, it
        // replaces the window (its rounding is that of fewer steps).
        if self.fresh_lag == 0 {
            let (gyro_bias, accel_bias) = self.bias();
            self.fresh = Increment::empty(gyro_bias, accel_bias);
            self.fresh_lag = self.ring.len();
            // Everything in the ring is older than the new fresh window.
            if self.fresh_lag == 0 {
                self.window = self.fresh;
            }
        } else {
            self.fresh_lag -= 1;
            if self.fresh_lag == 0 {
                self.window = self.fresh;
                let (gyro_bias, accel_bias) = self.bias();
                self.fresh = Increment::empty(gyro_bias, accel_bias);
                self.fresh_lag = self.ring.len();
            }
        }
    }

    /// The biases the output predictor integrates with: the filter's, or the alignment's.
    fn bias(&self) -> (Vector3<T>, Vector3<T>) {
        match &self.mode {
            Mode::Running(ins, _) => (ins.state().gyro_bias, ins.state().accel_bias),
            Mode::Aligning(att) => att
                .estimate()
                .map_or((Vector3::zeros(), Vector3::zeros()), |e| {
                    (e.gyro_bias, e.accel_bias)
                }),
        }
    }

    /// Fuses the earliest measurement the filter has reached, if any.
    fn fuse_due(&mut self) {
        let Some(t_f) = self.filter_t else {
            return;
        };
        let Some(item) = self.queue.take_due(t_f) else {
            return;
        };
        let kind = match item.aid {
            Aid::Gnss(..) | Aid::GnssVelocity(..) => 0,
            Aid::Magnetometer(_) => 1,
            Aid::Barometer(_) => 2,
        };
        if let (Some(due), Some(last), Some(interval)) = (
            self.last_due.get_mut(kind),
            self.last_measured.get_mut(kind),
            self.aid_interval.get_mut(kind),
        ) {
            // The interval between the measurements' own times (a GNSS velocity shares its
            // position's time: an interval of zero is no interval).
            if let Some(gap) = last.map(|l| item.t_ns.saturating_sub(l)).filter(|g| *g > 0) {
                *interval = Some(gap);
            }
            *last = Some(item.t_ns);
            *due = Some(t_f);
        }
        // The measurement is carried over the `dt ≥ 0` between its time and the filter's.
        let dt = seconds::<T>(t_f.saturating_sub(item.t_ns));
        match &mut self.mode {
            Mode::Aligning(_) => match item.aid {
                Aid::Gnss(position, sigma) => {
                    // The fix's velocity, stamped alike, is the next item: the start takes it.
                    let velocity = self.queue.take_velocity_at(item.t_ns);
                    self.start(item.t_ns, dt, position, sigma, velocity);
                }
                _ => self.counters.unused = self.counters.unused.saturating_add(1),
            },
            Mode::Running(ins, bank) => {
                // The bank follows what each fusion does to the INS's heading
                // (`nav/ins/heading.rs`).
                bank.note_attitude(&ins.state().attitude);
                match item.aid {
                    Aid::Gnss(position, sigma) => {
                        self.fuse_gnss(t_f, item.t_ns, dt, position, sigma);
                    }
                    Aid::GnssVelocity(v, sigma) => {
                        self.fuse_gnss_velocity(item.t_ns, dt, v, sigma);
                    }
                    Aid::Magnetometer(field) => self.fuse_magnetometer(item.t_ns, dt, field),
                    Aid::Barometer(altitude) => self.fuse_barometer(item.t_ns, dt, altitude),
                }
                self.track_heading();
            }
        }
    }
}

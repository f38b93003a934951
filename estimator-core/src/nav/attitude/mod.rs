//! The attitude navigator: an [`AhrsAccelBias`] filter (attitude, gyro and accelerometer
//! biases, and the velocity the specific force integrates to) with everything a sensor stream
//! needs around it.
//!
//! One call per sample: [`AttitudeNavigator::imu`] for every IMU sample,
//! [`AttitudeNavigator::magnetometer`] for every magnetometer sample, each with its own
//! timestamp (ns). Each returns an [`AttitudeReport`]: the validity of tilt and heading, the
//! magnetometer's state, rest, and what the navigator did on its own.
//!
//! What happens inside, in order (each step's model is in its file):
//!
//! 1. **Start-up** (`startup`): the first `startup_s` of samples are averaged in a frame the
//!    gyro carries along, at rest or moving; tilt, heading, bias and their covariance come from
//!    the means. A gap in the IMU longer than `max_dt` starts it again.
//! 2. **Prediction**: every IMU interval turns the attitude by [`AhrsAccelBias::predict`](crate::eskf::Filter::predict)
//!    (the sample's rate over the interval ending at it, or the mean of both ends for
//!    instantaneous samples).
//! 3. **Blocks** (`block`): accelerometer and magnetometer samples are summed over `block_s`
//!    in the same gyro-carried frame; at the block's end the velocity moves by the block's
//!    world-frame specific force ([`AhrsAccelBias::integrate_velocity`]) and the gyro's scale
//!    error widens the attitude; then, one update per call:
//!    * **rest** (`rest`): a still block, after `rest_min_s` of them, is a zero-rate update
//!      of the gyro bias;
//!    * **tilt** (`tilt`): the velocity is bounded, by the spread of a moving body's velocity
//!      or by the drift of a still one: a tilt error shows as a velocity that grows as
//!      `g t δθ`; widened, never locked out, after repeated rejections;
//!    * **hard iron** (`hard_iron`): every magnetometer sample loses the offset learned while
//!      the body turns; at a block's end, the window of recent samples is fitted for it;
//!    * **heading** (`magnetic`): the magnetometer's heading only, when its norm and dip agree
//!      with the reference; a steady new field becomes the reference. Each magnetometer
//!      sample is rotated with the frame of its true time: its delay behind the gyro is
//!      learned from the heading innovations while the body turns fast about the vertical.
//!
//! # Beside VQF and BROAD
//!
//! VQF (Laidig and Seel, "VQF: Highly accurate IMU orientation estimation with bias estimation
//! and magnetic disturbance rejection", Information Fusion 2023) and the BROAD benchmark
//! (Laidig, Caruso, Cereatti and Seel, "BROAD — A Benchmark for Robust Inertial Orientation
//! Estimation", Data 2021) shaped these choices; no code is taken from either.
//!
//! * Taken from VQF: the accelerometer is low-pass filtered in a frame the gyro carries along
//!   (here: summed over a block in the estimate's frame, `block`), so the body's rotation does
//!   not smear the mean; the gyro bias is learned at rest and while moving; the magnetometer
//!   corrects the heading only, and a disturbed field (norm, dip) is not fused.
//! * Done differently: VQF low-pass filters the specific force (a time constant of about 3 s)
//!   and corrects the tilt toward its direction with a fixed gain; here the specific force is
//!   integrated to a velocity, and a bound on the body's velocity corrects the tilt through a
//!   Kalman gain. Both rest on the same physics — the body's acceleration averages out because
//!   its velocity stays bounded — but the velocity state keeps the sum exactly (the mean
//!   acceleration over a window `W` is `Δv/W`) and the filter knows how uncertain the tilt is,
//!   which gives the reported covariance and the validity flags. The gyro's scale error widens
//!   the attitude in proportion to the rotation, and the accelerometer bias is a state
//!   (separated from the tilt by the body's turns), where VQF has neither. The magnetometer's
//!   hard iron and its delay behind the gyro are learned (VQF fuses the sample with the
//!   orientation of its stamp): on BROAD's fastest trials the delay learned is 9–13 ms, degrees
//!   of heading at their 800 °/s.
//! * From BROAD: its metric (the inclination and heading parts of the error, in movement
//!   phases) is what `host-sim bench` prints, beside VQF's published figures; its trial
//!   kinds (rotation, translation, rest breaks, tapping, vibration, magnetic disturbances)
//!   are the motions the defaults are derived for, from sensor and motion properties written
//!   beside each in [`AttitudeConfig::new`] and the tuning table of [`crate::nav`].
//!
//! Nothing allocates; the navigator is a plain value (`size_of::<AttitudeNavigator<f32>>()`
//! is in the firmware table of the README).

mod block;
mod config;
mod hard_iron;
mod magnetic;
mod report;
mod rest;
mod startup;
mod tilt;

pub use config::{AttitudeConfig, MagneticConfig, MagneticFusion};
pub use report::{
    AttitudeEstimate, AttitudeReport, Counters, Event, Fusion, Fusions, MagneticStatus, Reason,
    Validity,
};

use crate::eskf::{AhrsAccelBias, ImuSample};
use crate::kernels::mat3;
use crate::lie::{LieGroup, So3};
use crate::nav::clock::{Clock, Tick};
use crate::nav::error::NavError;
use crate::nav::sample::{check_imu_range, check_vector};
use crate::Real;
use block::Block;
use magnetic::Magnetic;
use nalgebra::Vector3;

/// The update a pending block makes next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// The gyro at rest.
    ZeroRate,
    /// The accelerometer.
    Gravity,
    /// The magnetometer's hard iron.
    HardIron,
    /// The magnetometer.
    Heading,
}

/// A finished block whose accelerometer and magnetometer updates are still to be made, one per
/// IMU call.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pending<T: Real> {
    stats: block::BlockStats<T>,
    /// The velocity bound's variance per axis, (m/s)².
    variance: Vector3<T>,
    stage: Stage,
    /// An accelerometer sample of the block was at the rail: no tilt update.
    clipped: bool,
}

/// How long a body keeps turning one way, s: the attitude error that the gyro's scale and
/// cross-axis errors (`gyro_scale_sigma`, `σ_s`) leave from one turn is coherent over it and
/// independent of the next turn's, so a block of length `T` turning at an RMS rate `ω` adds
/// `(σ_s ω)² T τ_turn` to the attitude variance per axis (a random walk in the turned angle,
/// independent of the block length). Hand-held and worn motion reverses its turns within about
/// half a second (the arm's and wrist's motions run at 1 Hz and above); a vehicle turns more
/// slowly, for which the same variance per second is conservative.
const TURN_CORRELATION_S: f64 = 0.5;

/// Moves the filter's velocity by a block's world-frame sums ([`Block::world_sums`],
/// [`AhrsAccelBias::integrate_velocity`]). Out of line: the sums stay out of the frame of the
/// call that ends a block, which the start-up also goes through.
#[inline(never)]
fn integrate_block<T: Real>(
    filter: &mut AhrsAccelBias<T>,
    block: &Block<T>,
) -> Result<(), crate::eskf::EskfError> {
    match block.world_sums() {
        Some((force, frames, duration)) => filter.integrate_velocity(&force, &frames, duration),
        None => Ok(()),
    }
}

/// Durations of the configuration in nanoseconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Durations {
    startup: u32,
    block: u32,
    max_step: u32,
}

fn nanoseconds<T: Real>(s: T) -> u32 {
    (s * T::lit(1e9)).to_count()
}

/// The attitude navigator (module docs).
///
/// ```
/// use estimator_core::eskf::{FilterConfig, ImuNoise};
/// use estimator_core::nav::{AttitudeConfig, AttitudeNavigator, MagneticConfig};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut config = AttitudeConfig::<f32>::new(FilterConfig::default());
/// config.magnetometer = Some(MagneticConfig::new(0.5, None)); // µT; reference learned
/// let mut nav = AttitudeNavigator::new(config).unwrap();
/// // 3 s at rest and level at 100 Hz, facing north-east.
/// let field = Vector3::new(15.0, 15.0, -40.0);
/// for k in 0..300u64 {
///     let t = 1_000_000_000 + k * 10_000_000;
///     nav.imu(t, &Vector3::new(0.001, 0.0, 0.0), &Vector3::new(0.0, 0.0, 9.81)).unwrap();
///     let report = nav.magnetometer(t + 1, &field).unwrap();
///     if k == 299 {
///         assert!(report.tilt.is_valid() && report.heading.is_valid());
///     }
/// }
/// let estimate = nav.estimate().unwrap();
/// assert!((estimate.gyro_bias.x - 0.001).abs() < 1e-4); // learned at rest
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeNavigator<T: Real> {
    config: AttitudeConfig<T>,
    durations: Durations,
    /// The filter: a placeholder until `running`, then the estimate.
    filter: AhrsAccelBias<T>,
    /// Started (`false`: collecting the start-up window).
    running: bool,
    /// During start-up: the gyro-integrated rotation since the window's first sample.
    frame: So3<T>,
    block: Block<T>,
    /// The last finished block's remaining updates.
    pending: Option<Pending<T>>,
    /// The rotation since that block's end (gyro increments of the predictions).
    carry: So3<T>,
    imu_clock: Clock,
    mag_clock: Clock,
    /// The previous IMU sample (gyro, accel), for trapezoidal integration.
    last_imu: Option<(Vector3<T>, Vector3<T>)>,
    /// The bias to start from after a gap.
    bias_prior: Vector3<T>,
    /// The running mean of the estimated velocity's square per axis, (m/s)²: the spread of
    /// the body's velocity (`tilt`).
    velocity_spread: Vector3<T>,
    /// Still blocks in a row, s.
    still_s: T,
    tilt_rejected: u16,
    magnetic: Option<Magnetic<T>>,
    report: AttitudeReport<T>,
    counters: Counters,
}

impl<T: Real> AttitudeNavigator<T> {
    /// A navigator waiting for its first sample.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] (or the filter configuration's error) for a configuration
    /// out of its domain ([`AttitudeConfig::validate`]).
    pub fn new(config: AttitudeConfig<T>) -> Result<Self, NavError> {
        config.validate()?;
        Ok(Self::waiting(config))
    }

    /// [`new`](Self::new) for a configuration its caller has validated
    /// ([`AttitudeConfig::validate`]): a restart (the INS navigator's, after an IMU gap) needs
    /// no `Result` on its stack.
    #[inline(never)]
    pub(crate) fn waiting(config: AttitudeConfig<T>) -> Self {
        let magnetic = config.magnetometer.as_ref().map(Magnetic::new);
        Self {
            durations: Durations {
                startup: nanoseconds(config.startup_s),
                block: nanoseconds(config.block_s),
                max_step: nanoseconds(config.filter.max_dt),
            },
            filter: AhrsAccelBias::placeholder(config.filter),
            running: false,
            frame: So3::identity(),
            block: Block::default(),
            pending: None,
            carry: So3::identity(),
            imu_clock: Clock::default(),
            mag_clock: Clock::default(),
            last_imu: None,
            bias_prior: Vector3::zeros(),
            velocity_spread: Vector3::zeros(),
            still_s: T::zero(),
            tilt_rejected: 0,
            report: AttitudeReport {
                t_ns: 0,
                tilt: Validity::Invalid(Reason::Starting),
                heading: Validity::Invalid(Reason::Starting),
                at_rest: false,
                magnetic: if magnetic.is_some() {
                    MagneticStatus::Waiting
                } else {
                    MagneticStatus::NotConfigured
                },
                event: None,
                fused: Fusions::default(),
                clipped: false,
            },
            magnetic,
            counters: Counters::default(),
            config,
        }
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &AttitudeConfig<T> {
        &self.config
    }

    /// The filter, once started.
    #[must_use]
    pub fn filter(&self) -> Option<&AhrsAccelBias<T>> {
        self.running.then_some(&self.filter)
    }

    /// The report of the last call.
    #[must_use]
    pub fn report(&self) -> &AttitudeReport<T> {
        &self.report
    }

    /// Counts since construction.
    #[must_use]
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// The magnetometer's world reference field, once known.
    #[must_use]
    pub fn magnetic_reference(&self) -> Option<Vector3<T>> {
        self.magnetic.and_then(|m| m.reference)
    }

    /// The estimate with its uncertainty, once started.
    #[must_use]
    pub fn estimate(&self) -> Option<AttitudeEstimate<T>> {
        let filter = self.filter()?;
        let (sigma_tilt, sigma_heading) = self.sigmas()?;
        Some(AttitudeEstimate {
            t_ns: self.report.t_ns,
            attitude: filter.state().attitude,
            gyro_bias: filter.state().gyro_bias,
            accel_bias: filter.state().accel_bias,
            sigma_tilt,
            sigma_heading,
            hard_iron: self
                .magnetic
                .map_or_else(Vector3::zeros, |m| m.hard_iron.offset()),
            sigma_hard_iron: self
                .magnetic
                .map_or_else(Vector3::zeros, |m| m.hard_iron.sigma()),
            magnetometer_delay_s: self.magnetic.map_or_else(T::zero, |m| m.delay),
        })
    }

    /// The 1σ of the tilt (the larger horizontal axis) and of the heading, rad, once started.
    fn sigmas(&self) -> Option<(T, T)> {
        let w = tilt::world_attitude_covariance(self.filter()?);
        let tilt = if w.m11 > w.m22 { w.m11 } else { w.m22 };
        Some((tilt.sqrt_rn(), w.m33.sqrt_rn()))
    }

    /// Takes one IMU sample: gyro (rad/s) and accelerometer (m/s², specific force) in the body
    /// frame at `t_ns`.
    ///
    /// # Errors
    /// [`NavError::NonFinite`], [`NavError::ZeroVector`] (an all-zero accelerometer),
    /// [`NavError::TimeNotIncreasing`], or [`NavError::Filter`] for a numerical failure; the
    /// navigator is then unchanged.
    pub fn imu(
        &mut self,
        t_ns: u64,
        gyro: &Vector3<T>,
        accel: &Vector3<T>,
    ) -> Result<AttitudeReport<T>, NavError> {
        match self.take_imu(t_ns, gyro, accel) {
            Ok(()) => Ok(self.report),
            Err(e) => {
                self.counters.refused = self.counters.refused.saturating_add(1);
                Err(e)
            }
        }
    }

    /// Takes one magnetometer sample (body frame, the unit of the configured sigma) at `t_ns`.
    /// It is fused at the end of the current block; without a configured magnetometer it is
    /// ignored.
    ///
    /// # Errors
    /// [`NavError::NonFinite`], [`NavError::ZeroVector`], [`NavError::TimeNotIncreasing`]
    /// (against the previous magnetometer sample); the navigator is then unchanged.
    pub fn magnetometer(
        &mut self,
        t_ns: u64,
        field: &Vector3<T>,
    ) -> Result<AttitudeReport<T>, NavError> {
        let checked = check_vector(field).and_then(|()| self.mag_clock.tick(t_ns, u32::MAX));
        if let Err(e) = checked {
            self.counters.refused = self.counters.refused.saturating_add(1);
            return Err(e);
        }
        self.mag_clock.set(t_ns);
        self.counters.magnetometer = self.counters.magnetometer.saturating_add(1);
        self.report.event = None;
        self.report.fused = Fusions::default();
        let stuck = match (self.magnetic.as_mut(), self.config.magnetometer.as_ref()) {
            (Some(state), Some(config)) => state.stuck(t_ns, field, config),
            _ => false,
        };
        if stuck {
            self.counters.magnetometer_stuck = self.counters.magnetometer_stuck.saturating_add(1);
            self.report.magnetic = MagneticStatus::Stuck;
        } else if let Some(delay) = self.magnetic.as_ref().map(|m| m.delay) {
            let frame = self.frame_at(t_ns, delay);
            if let (Some(state), Some(config)) =
                (self.magnetic.as_mut(), self.config.magnetometer.as_ref())
            {
                let corrected = state.hard_iron.take(field, config);
                self.block.mag.add(&frame.act(&corrected));
            }
        }
        Ok(self.report)
    }

    /// The frame of the estimate at `t_ns − delay` (`delay` in s), carried from the last IMU
    /// sample by its rate (a magnetometer sample between two IMU samples would otherwise be
    /// rotated with the attitude of up to one interval earlier: a lag of `ω Δt`; one that is
    /// the field `delay` before its stamp, with the attitude of `delay` later).
    fn frame_at(&self, t_ns: u64, delay: T) -> So3<T> {
        let (frame, bias) = if self.running {
            (self.filter.state().attitude, self.filter.state().gyro_bias)
        } else {
            (self.frame, self.bias_prior)
        };
        let (Some(last), Some((gyro, _))) = (self.imu_clock.last(), self.last_imu) else {
            return frame;
        };
        let ahead = t_ns.checked_sub(last).and_then(|d| u32::try_from(d).ok());
        let behind = last.checked_sub(t_ns).and_then(|d| u32::try_from(d).ok());
        let dt = match (ahead, behind) {
            (Some(d), _) if d <= self.durations.max_step => T::from_count(d) * T::lit(1e-9),
            (_, Some(d)) if d <= self.durations.max_step => -(T::from_count(d) * T::lit(1e-9)),
            _ => return frame,
        };
        frame.compose(&So3::exp(&((gyro - bias) * (dt - delay))))
    }

    /// The IMU step. Every check that can refuse the sample (its values, its time, the
    /// prediction) comes before the first change, so a refused sample changes nothing; what
    /// follows cannot fail (an update the filter refuses is counted and skipped).
    fn take_imu(
        &mut self,
        t_ns: u64,
        gyro: &Vector3<T>,
        accel: &Vector3<T>,
    ) -> Result<(), NavError> {
        let (gyro_clipped, accel_clipped) =
            check_imu_range(gyro, accel, self.config.gyro_range, self.config.accel_range)?;
        let tick = self.imu_clock.tick(t_ns, self.durations.max_step)?;
        let mut event = None;
        let dt_ns = match tick {
            Tick::First => None,
            Tick::Step(ns) => Some(ns),
            Tick::Gap => {
                self.restart();
                event = Some(Event::Realigned);
                self.counters.realigned = self.counters.realigned.saturating_add(1);
                None
            }
        };
        if let Some(ns) = dt_ns {
            let dt = T::from_count(ns) * T::lit(1e-9);
            let (g_mid, a_mid) = match (self.config.instantaneous_imu, self.last_imu) {
                (true, Some((g0, a0))) => ((g0 + gyro) * T::lit(0.5), (a0 + accel) * T::lit(0.5)),
                _ => (*gyro, *accel),
            };
            if self.running {
                let bias = self.filter.state().gyro_bias;
                self.filter.predict(&ImuSample {
                    gyro: g_mid,
                    accel: a_mid,
                    dt,
                })?;
                // The rotation since the pending block's end, by the same increments.
                self.carry = self.carry.compose(&So3::exp(&((g_mid - bias) * dt)));
                if gyro_clipped {
                    // The body turned faster than the gyro reads, by an unknown amount: up to
                    // one more full-scale turn over the interval is taken as 1σ.
                    let turn = self.config.gyro_range * dt;
                    if self.filter.widen_attitude(turn, turn).is_err() {
                        self.failed();
                    }
                }
            } else {
                let w = (g_mid - self.bias_prior) * dt;
                self.frame = self.frame.compose(&So3::exp(&w)).normalize();
            }
            self.block.elapsed_ns = self.block.elapsed_ns.saturating_add(ns);
        }
        self.report.event = event;
        self.report.fused = Fusions::default();
        self.report.clipped = gyro_clipped || accel_clipped;
        if self.report.clipped {
            self.counters.clipped = self.counters.clipped.saturating_add(1);
        }
        self.block.clipped |= accel_clipped;
        // At most one update of the pending block per call (the cost of a call stays that of
        // one update).
        self.fuse_pending_stage();
        let frame = self.current_frame();
        self.block.accel.add(&frame.act(accel));
        self.block.frames += frame.rotation_matrix();
        self.block.gyro.add(gyro);
        self.imu_clock.set(t_ns);
        self.last_imu = Some((*gyro, *accel));
        self.counters.imu = self.counters.imu.saturating_add(1);
        self.report.t_ns = t_ns;
        let length = if self.running {
            self.durations.block
        } else {
            self.durations.startup
        };
        if self.block.elapsed_ns >= length {
            // A block shorter than its updates: finish the previous one first.
            while self.pending.is_some() {
                self.fuse_pending_stage();
            }
            self.end_block();
        }
        self.refresh_validity();
        Ok(())
    }

    /// The frame the samples are rotated into: the estimate once running, the start-up frame
    /// before.
    fn current_frame(&self) -> So3<T> {
        if self.running {
            self.filter.state().attitude
        } else {
            self.frame
        }
    }

    /// Counts an update the filter refused (a numerical failure: the filter is unchanged).
    fn failed(&mut self) {
        self.counters.numerical_failures = self.counters.numerical_failures.saturating_add(1);
    }

    /// Back to start-up (after a gap), keeping the bias estimate and the magnetic reference.
    fn restart(&mut self) {
        if self.running {
            self.bias_prior = self.filter.state().gyro_bias;
        }
        self.running = false;
        self.frame = So3::identity();
        self.block = Block::default();
        self.pending = None;
        self.last_imu = None;
        self.still_s = T::zero();
        self.tilt_rejected = 0;
    }

    /// Closes the finished block: starts the filter from the start-up window, or widens for
    /// the gyro's scale error and leaves the block's updates (zero rate at rest, accelerometer,
    /// magnetometer) pending, one for each of the next calls.
    #[inline(never)]
    fn end_block(&mut self) {
        let frame = self.current_frame();
        let stats = self.block.stats(&frame);
        // The velocity over a running block (in free fall nothing is fused: below), from the
        // block's world-frame sums, before the block is emptied.
        // A block with a clipped accelerometer sample has the wrong specific force: it is not
        // integrated or fused, and the velocity starts again from the bound.
        let clipped = self.block.clipped;
        let integrated = match &stats {
            Some(s) if self.running && !clipped && tilt::has_direction(&s.accel_body) => {
                integrate_block(&mut self.filter, &self.block)
            }
            _ => Ok(()),
        };
        self.block = Block::default();
        let Some(stats) = stats else {
            return;
        };
        let g = mat3::norm(&self.config.filter.gravity);
        if !tilt::has_direction(&stats.accel_body) {
            // Free fall for a whole block: nothing to fuse.
            return;
        }
        if !self.running {
            self.begin(&stats);
            return;
        }
        let filter = &mut self.filter;
        // The gyro's scale and cross-axis errors over the block's rotation: a turn at RMS rate
        // ω for T adds (σ_s ω)² T τ_turn, whatever the block's length.
        let turned = self.config.gyro_scale_sigma
            * stats.rate(&filter.state().gyro_bias)
            * (stats.duration * T::lit(TURN_CORRELATION_S)).sqrt_rn();
        let widened = turned > T::zero() && filter.widen_attitude(turned, turned).is_err();
        // Rest: zero-rate update of the gyro bias.
        let still = rest::is_still(&stats, &filter.state().gyro_bias, &self.config, g);
        self.still_s = if still {
            self.still_s + stats.duration
        } else {
            T::zero()
        };
        self.report.at_rest = still && self.still_s >= self.config.rest_min_s;
        let velocity = filter.state().velocity;
        if widened || integrated.is_err() {
            self.failed();
        }
        self.velocity_spread = tilt::update_spread(
            &self.velocity_spread,
            &velocity,
            stats.duration,
            &self.config,
        );
        let variance = tilt::velocity_variance(
            &stats,
            &self.config,
            &self.velocity_spread,
            self.report.at_rest,
        );
        if clipped {
            let sigma = variance.max().sqrt_rn();
            if self
                .filter
                .restart_velocity(Vector3::zeros(), sigma)
                .is_err()
            {
                self.failed();
            }
        }
        self.pending = Some(Pending {
            stats,
            variance,
            stage: if self.report.at_rest {
                Stage::ZeroRate
            } else {
                Stage::Gravity
            },
            clipped,
        });
        self.carry = So3::identity();
    }

    /// Starts the filter from the start-up window's statistics, in the navigator's own storage
    /// ([`AhrsAccelBias::restart_from_alignment`]).
    fn begin(&mut self, stats: &block::BlockStats<T>) {
        let start = startup::start(stats, &self.config, &self.bias_prior, &mut self.magnetic);
        let started = match start {
            Ok(s) => match self.filter.restart_from_alignment(&s.alignment, &s.sigmas) {
                Ok(()) => Some(s.still),
                Err(_) => None,
            },
            Err(_) => None,
        };
        let Some(still) = started else {
            // The window gave no attitude (a numerical failure): collect another.
            self.failed();
            return;
        };
        self.running = true;
        if let Some(state) = self.magnetic.as_mut() {
            state.fused_since_start = false;
        }
        self.still_s = if still { stats.duration } else { T::zero() };
        self.velocity_spread = Vector3::zeros();
        self.report.at_rest = still;
        if self.report.event.is_none() {
            self.report.event = Some(Event::Started);
        }
        if stats.mag.is_some() && self.magnetic.is_some() {
            self.report.magnetic = MagneticStatus::Fused;
        }
    }

    /// The next update of the pending block, with its measurements carried from the block's
    /// end to now by the gyro (`v_now = C⁻¹ v_end`, `C` the rotation since the end).
    #[inline(never)]
    fn fuse_pending_stage(&mut self) {
        let (Some(pending), true) = (self.pending.as_mut(), self.running) else {
            self.pending = None;
            return;
        };
        // Carried in place, and the carry restarted: the next stage carries from here.
        let back = self.carry.inverse();
        self.carry = So3::identity();
        let stats = &mut pending.stats;
        stats.accel_body = back.act(&stats.accel_body);
        stats.bias_map = mat3::mul(&back.rotation_matrix(), &stats.bias_map);
        if let Some(m) = stats.mag.as_mut() {
            m.body = back.act(&m.body);
        }
        let (filter, c, report) = (&mut self.filter, &mut self.counters, &mut self.report);
        let next = match pending.stage {
            Stage::ZeroRate => {
                match rest::fuse(filter, stats, &self.config) {
                    Ok(fusion) => {
                        if fusion.accepted {
                            c.zero_rate = c.zero_rate.saturating_add(1);
                        }
                        report.fused.zero_rate = Some(fusion);
                    }
                    Err(_) => c.numerical_failures = c.numerical_failures.saturating_add(1),
                }
                Some(Stage::Gravity)
            }
            Stage::Gravity if pending.clipped => {
                (stats.mag.is_some() && self.magnetic.is_some()).then_some(Stage::HardIron)
            }
            Stage::Gravity => {
                let fused = tilt::fuse(
                    filter,
                    stats,
                    &pending.variance,
                    &self.config,
                    &mut self.tilt_rejected,
                );
                match fused {
                    Ok((fusion, event)) => {
                        report.fused.gravity = Some(fusion);
                        if fusion.accepted {
                            c.gravity_fused = c.gravity_fused.saturating_add(1);
                        } else {
                            c.gravity_rejected = c.gravity_rejected.saturating_add(1);
                        }
                        if event.is_some() {
                            c.widened = c.widened.saturating_add(1);
                            report.event = event;
                        }
                    }
                    Err(_) => c.numerical_failures = c.numerical_failures.saturating_add(1),
                }
                (stats.mag.is_some() && self.magnetic.is_some()).then_some(Stage::HardIron)
            }
            Stage::HardIron => {
                let learned = match (self.magnetic.as_mut(), self.config.magnetometer.as_ref()) {
                    (Some(state), Some(mag)) => {
                        state.hard_iron_stage(filter, stats.duration, stats.mag.as_ref(), mag)
                    }
                    _ => Ok(None),
                };
                match learned {
                    Ok(Some(event)) => {
                        c.new_hard_irons = c.new_hard_irons.saturating_add(1);
                        report.event = Some(event);
                        report.magnetic = MagneticStatus::Disturbed;
                        None
                    }
                    Ok(None) => Some(Stage::Heading),
                    Err(_) => {
                        c.numerical_failures = c.numerical_failures.saturating_add(1);
                        Some(Stage::Heading)
                    }
                }
            }
            Stage::Heading => {
                if let (Some(state), Some(mag), Some(ms)) = (
                    self.magnetic.as_mut(),
                    self.config.magnetometer.as_ref(),
                    stats.mag.as_ref(),
                ) {
                    let turn = magnetic::Turn {
                        duration: stats.duration,
                        rotation: stats.rotation(&filter.state().gyro_bias),
                        rate_up: magnetic::rate_up(
                            filter,
                            &stats.gyro_mean,
                            &self.config.filter.gravity,
                        ),
                    };
                    match state.fuse(filter, ms, &turn, &self.config, mag) {
                        Ok((status, fusion, event)) => {
                            report.magnetic = status;
                            report.fused.heading = fusion;
                            match status {
                                MagneticStatus::Fused => {
                                    c.heading_fused = c.heading_fused.saturating_add(1);
                                }
                                MagneticStatus::Rejected => {
                                    c.heading_rejected = c.heading_rejected.saturating_add(1);
                                }
                                MagneticStatus::Disturbed => {
                                    c.magnetic_disturbed = c.magnetic_disturbed.saturating_add(1);
                                }
                                MagneticStatus::NotConfigured
                                | MagneticStatus::Waiting
                                | MagneticStatus::Stuck => {}
                            }
                            match event {
                                Some(Event::HeadingWidened) => {
                                    c.widened = c.widened.saturating_add(1);
                                }
                                Some(Event::NewMagneticField) => {
                                    c.new_fields = c.new_fields.saturating_add(1);
                                }
                                _ => {}
                            }
                            if event.is_some() {
                                report.event = event;
                            }
                        }
                        Err(_) => c.numerical_failures = c.numerical_failures.saturating_add(1),
                    }
                }
                None
            }
        };
        match next {
            Some(stage) => pending.stage = stage,
            None => self.pending = None,
        }
    }

    /// The validity of tilt and heading from the current covariance.
    fn refresh_validity(&mut self) {
        let Some((sigma_tilt, sigma_heading)) = self.sigmas() else {
            self.report.tilt = Validity::Invalid(Reason::Starting);
            self.report.heading = Validity::Invalid(Reason::Starting);
            return;
        };
        self.report.tilt = if sigma_tilt <= self.config.tilt_valid_sigma {
            Validity::Valid
        } else {
            Validity::Invalid(Reason::Uncertain)
        };
        self.report.heading = if self.magnetic_reference().is_none() {
            Validity::Invalid(Reason::NoMagnetometer)
        } else if sigma_heading <= self.config.heading_valid_sigma {
            Validity::Valid
        } else {
            Validity::Invalid(Reason::Uncertain)
        };
    }
}

//! Navigators: the layer a firmware main loop calls, one timestamped sample at a time.
//!
//! A filter ([`crate::eskf`]) knows the mathematics of one step; a navigator owns a filter and
//! everything a real sensor stream needs around it: start-up from whatever the stream gives,
//! IMU integration between samples, the sensor policy (what to fuse, when, with which noise),
//! fault handling, and a report after every call saying which parts of the estimate are valid
//! and why not.
//!
//! * [`AttitudeNavigator`]: attitude and gyro bias from a gyro, an accelerometer and an
//!   optional magnetometer (an AHRS).
//! * [`InsNavigator`]: position, velocity, attitude and both IMU biases from an IMU and GNSS,
//!   with an optional magnetometer and barometer; measurements delayed up to a horizon and
//!   out of order, fault detection, per-quantity validity.
//!
//! Conventions: timestamps are `u64` nanoseconds on one clock, strictly increasing per
//! sensor; the world frame is ENU (`z` up), gravity `[0, 0, −9.81]`; the body frame is the
//! IMU's; the attitude `R` maps body to world. Every call that takes a sample returns a
//! `Result`; on `Err` the navigator is unchanged bit for bit. Nothing allocates or panics.
//!
//! # Tuning the attitude navigator
//!
//! Start from the sensor's noise ([`FilterConfig`](crate::eskf::FilterConfig)): the white-noise
//! densities and random walks of the gyro and accelerometer, from the data sheet or better from
//! a static recording (`host-sim calibrate`, Allan deviation), and the magnetometer's per-sample
//! `sigma`. Then, in [`AttitudeConfig`], in order of effect:
//!
//! | parameter | what it does | how to choose it |
//! |---|---|---|
//! | `magnetometer.heading_noise` (8°·√s) | how fast the heading follows the magnetometer | larger near iron and for poorly calibrated magnetometers (slower, more robust); smaller in a clean field |
//! | `gyro_scale_sigma` (0.5 %) | attitude uncertainty added while turning: `(σ_s ω)² T τ_turn` per block, `τ_turn` = 0.5 s, how long a body keeps turning one way | the gyro's sensitivity and cross-axis error after calibration (data sheets: 1–3 % raw); raise it if the attitude lags after fast turns |
//! | `block_s` (0.25 s) | how often the velocity bound, the magnetometer and rest are fused (what each block tells is set by the noise densities, not by its length) | shorter corrects sooner and costs more instructions per sample: 0.25 s keeps the Cortex-M4F mean under 2,500 per sample at 200 Hz; 0.5 s halves the updates |
//! | `velocity_sigma` (0.3 m/s), `motion_memory_s` (5 s) | the bound on the body's velocity that measures the tilt: never tighter than `velocity_sigma` while moving, else twice the RMS of the estimated velocity over the memory | the slowest spread of velocity the body has while it moves (a hand moving an object: 0.3 m/s; the bound loosens itself for faster bodies); the memory, the time over which the body's speed changes |
//! | `instantaneous_imu` (false) | how a sample's rate is integrated over its interval | `false` for a MEMS IMU whose output is the mean of its internal samples since the last output (a decimation filter); `true` for samples of the rate at an instant (a simulator) |
//! | `rotation_only` (false) | leaves out the motion terms | `true` only for a body that turns in place (gimbal, turntable) |
//! | `accelerometer_bias_sigma` (0.1 m/s²) | prior of the accelerometer bias | the data sheet's zero-g offset after calibration |
//! | `gyro_bias_sigma` (0.5 °/s) | prior of the gyro bias when the start is not at rest | the data sheet's zero-rate offset |
//! | `rest_gyro`, `rest_accel`, `rest_min_s` (2 °/s, 0.5 m/s², 1.5 s) | when the body counts as at rest (zero-rate updates) | lower for a quiet sensor on a table; never above the slowest real rotation |
//! | `magnetometer.norm_tolerance`, `dip_tolerance` (10 %, 10°) | when a field counts as disturbed | tighter for a well-calibrated magnetometer |
//! | `magnetometer.hard_iron` (on), `hard_iron_sigma` (3 % of the field), `hard_iron_max` (3 fields), `hard_iron_drift` (0.1 %/√s) | a constant offset in the body frame (a magnet or a battery on the board) learned while the body turns about two axes and taken off every sample; offsets within 3 `hard_iron_sigma` of the calibration's are left to it | `hard_iron_sigma`: what the magnetometer's calibration leaves; off for a magnetometer calibrated on the finished device |
//! | `magnetometer.fusion` (`Heading`) | heading only, or the whole field | `Vector` only for a calibrated magnetometer in a clean field (it then also corrects the tilt) |
//! | `max_rejected_blocks` (8) | how many rejected blocks in a row before the estimate is taken for wrong | lower recovers faster from a wrong estimate, higher resists long disturbances |
//! | `gyro_range`, `accel_range` (±2000 °/s, ±16 g) | the sensors' full scale: a sample at the rail is flagged (`AttitudeReport::clipped`), a clipped gyro widens the attitude by a full-scale turn over its interval, a clipped accelerometer's block is not fused; a sample beyond the scale by more than 1 % is refused | the range the IMU is configured to |
//! | `magnetometer.delay_s` (0), `delay_max_s` (50 ms) | the magnetometer's delay behind the gyro (its conversion and output filter), learned between 0 and `delay_max_s` from blocks that turn fast enough about the vertical for the largest delay to show above a block's heading noise; each sample is rotated with the frame of its true time | `delay_s`: a delay measured beforehand; `delay_max_s = 0` for a magnetometer sampled with the gyro |
//! | `magnetometer.stuck_s` (0.5 s) | a magnetometer repeating its sample bit for bit this long is stuck or saturated (`MagneticStatus::Stuck`): not used until it changes | above the magnetometer's output interval |
//! | `tilt_valid_sigma`, `heading_valid_sigma` (5°, 10°) | when the report calls a quantity valid | what the application can use |
//!
//! Chosen by data, not by a sensor property: `heading_noise` and `gyro_scale_sigma` (the
//! result moves 11–38 % for a factor of two), and `velocity_sigma`, `motion_memory_s` (flat
//! within 3 % from half to twice). They are cross-validated on 14 real recordings (BROAD):
//! chosen on one half, scored on the other (`tools/cross_validate.py`, the table in
//! `docs/FIGURES.md`). Each half chooses the first two defaults for itself; the halves'
//! choices of the last two move the mean by at most 2 %.
//!
//! # The INS navigator without a magnetometer
//!
//! Its heading is unknown until the GNSS track resolves it (`nav/ins/heading.rs`,
//! `nav/ins/yaw.rs`); in [`InsConfig`]:
//!
//! | parameter | what it does | how to choose it |
//! |---|---|---|
//! | `travel` (`Travel::Detect`) | whether the vehicle travels along its body x axis; then its heading is resolved along the GNSS track at any speed (forward, the one assumption: a run starts driving forward or from rest) and held to it with a lateral-velocity 1σ: learned from the track (`Detect`: the body-frame GNSS velocities' smaller spread, noise removed, plus its 2σ sampling bound; taken back when the body turns under its track or three lateral updates in a row fail their gate), declared (`Forward { lateral_sigma }`), or none (`Sideways`) | `Detect` unless known: `Sideways` for a multirotor or a hand-held device (a straight start would be taken for a track until its first turn, a second or so of a heading valid but wrong); `Forward` with the slip and crab of a car or rover on its ground, 0.05–0.1 m/s on a firm surface |
//! | `heading_valid_sigma` (10°) | also when the bank of yaw hypotheses is sure enough to resolve the heading (half of it) | what the application can use |
//!
//! Fixed by the physics, not tuned: the bank's 6 hypotheses (even, each with one at 180°), the
//! heading's unknown variance `π²/3` (uniform over the circle), 10 GNSS velocities before a
//! resolution (likelihoods need independent fixes), the shared acceleration error's 10 s
//! persistence (the INS's tilt and bias errors, corrected over tens of seconds), and a log-weight
//! floor of 20 below the best (a hypothesis can come back).
//!
//! Check a tuning on recordings with truth: `host-sim replay` prints the attitude RMSE and the
//! ANEES (3 for a consistent filter: much above, the noise values are too small; much below,
//! too large), and `host-sim bench` runs every dataset under a folder.

/// The largest IMU rate a navigator takes, rad/s (about 11,500 °/s, above every MEMS gyro's
/// range): a larger finite sample is a fault, refused with [`NavError::OutOfRange`].
pub const IMU_RATE_LIMIT: f64 = 200.0;

/// The largest specific force a navigator takes, m/s² (about 510 g, above every MEMS
/// accelerometer's range), refused beyond like [`IMU_RATE_LIMIT`].
pub const IMU_ACCEL_LIMIT: f64 = 5_000.0;

/// The range of gravity's norm a navigator's configuration may give, m/s² (the Moon's 1.6 to
/// Jupiter's 25 fit; a gravity of 10²⁹ is a mistake).
pub const GRAVITY_MIN: f64 = 0.5;
/// See [`GRAVITY_MIN`].
pub const GRAVITY_MAX: f64 = 50.0;

/// A GNSS fix's position 1σ a navigator takes, m: from 1 mm (better than RTK) to 10 km.
/// Outside it the 15-state covariance mixes scales `f32` cannot hold (a 1 µm position beside a
/// 1 km/s velocity), and the fix is refused with [`NavError::InvalidSigma`].
pub const FIX_POSITION_SIGMA: [f64; 2] = [1e-3, 1e4];
/// A GNSS fix's velocity 1σ a navigator takes, m/s (1 mm/s to 100 m/s), as
/// [`FIX_POSITION_SIGMA`].
pub const FIX_VELOCITY_SIGMA: [f64; 2] = [1e-3, 100.0];

mod attitude;
mod clock;
mod error;
mod ins;
mod mean;
mod sample;

pub use attitude::{
    AttitudeConfig, AttitudeEstimate, AttitudeNavigator, AttitudeReport, Counters, Event, Fusion,
    Fusions, MagneticConfig, MagneticFusion, MagneticStatus, Reason, Validity,
};
pub use error::NavError;
pub use ins::{
    AidStatus, Aiding, GnssFix, InsConfig, InsCounters, InsEstimate, InsEvent, InsFusion,
    InsNavigator, InsReport, InsValidity, Travel, AID_STALE_INTERVALS, AID_STALE_NS,
};
pub use mean::VectorMean;

//! Scenarios: a trajectory, the sensors that watch it, and the accuracy a filter must reach on it.
//!
//! Built-in scenarios are listed by `host-sim scenarios`; a scenario can also be read from a TOML
//! file with the same fields (`host-sim run --scenario path/to/file.toml`), every sensor table
//! optional, every field defaulted.

use crate::replay::ReplayConfig;
use crate::sensors::baro::BaroConfig;
use crate::sensors::camera::CameraConfig;
use crate::sensors::gnss::GnssConfig;
use crate::sensors::imu::ImuConfig;
use crate::sensors::mag::MagConfig;
use crate::trajectory::{builtin, Signal, Sine, Trajectory};
use serde::{Deserialize, Serialize};

/// Accuracy ceilings the end-to-end tests hold a filter to on this scenario.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct Ceilings {
    /// Position RMSE (ATE), m.
    pub ate_m: f64,
    /// Attitude RMSE, degrees.
    pub attitude_deg: f64,
}

impl Default for Ceilings {
    fn default() -> Self {
        Self {
            ate_m: f64::INFINITY,
            attitude_deg: f64::INFINITY,
        }
    }
}

/// A complete scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// One line for `host-sim scenarios`.
    pub description: String,
    /// Duration, s.
    pub duration_s: f64,
    /// Static period at the start, s.
    pub static_s: f64,
    /// When the recording begins, s from the trajectory's start: every sensor stream and the
    /// ground truth hold only the samples stamped in `[record_from_s, duration_s]`, on the same
    /// clock (the first stamp is `start_ns` plus this), so a scenario can start while the
    /// vehicle already moves. Fault times stay in seconds from the trajectory's start.
    pub record_from_s: f64,
    /// A built-in trajectory shape (see `trajectory::SHAPES`), used when `trajectory` is absent.
    pub shape: String,
    /// An explicit trajectory, overriding `shape`.
    pub trajectory: Option<Trajectory>,
    /// Gravity in the world frame, m/s².
    pub gravity: [f64; 3],
    /// First timestamp, ns.
    pub start_ns: u64,
    /// The IMU (always present).
    pub imu: ImuConfig,
    /// Magnetometer, if any.
    pub mag: Option<MagConfig>,
    /// GNSS, if any.
    pub gnss: Option<GnssConfig>,
    /// Camera, if any.
    pub camera: Option<CameraConfig>,
    /// Barometer, if any.
    pub baro: Option<BaroConfig>,
    /// Accuracy ceilings.
    pub ceilings: Ceilings,
    /// How the filter is run on this scenario; `simulate` writes it to the dataset's
    /// `replay.toml`, which `replay` reads when no `--config` is given.
    pub replay: ReplayConfig,
}

impl Default for Scenario {
    fn default() -> Self {
        Self {
            name: "custom".into(),
            description: String::new(),
            duration_s: 60.0,
            static_s: 5.0,
            record_from_s: 0.0,
            shape: "figure8".into(),
            trajectory: None,
            gravity: [0.0, 0.0, -9.81],
            start_ns: 1_000_000_000,
            imu: ImuConfig::default(),
            mag: None,
            gnss: None,
            camera: None,
            baro: None,
            ceilings: Ceilings::default(),
            replay: ReplayConfig::simulated(),
        }
    }
}

/// Errors of scenario lookup.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// No built-in scenario has that name and no such file exists.
    #[error("unknown scenario '{0}' (see `host-sim scenarios`, or give a .toml file)")]
    Unknown(String),
    /// The scenario names a trajectory shape that does not exist.
    #[error("{path}: unknown shape '{shape}' (one of: {known})")]
    UnknownShape {
        /// The scenario (file or name).
        path: String,
        /// The shape asked for.
        shape: String,
        /// The shapes that exist.
        known: String,
    },
    /// A value out of its domain.
    #[error("{path}: {message}")]
    Invalid {
        /// The scenario (file or name).
        path: String,
        /// Which value, and why.
        message: String,
    },
    /// The TOML file could not be read or parsed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl Scenario {
    /// The trajectory (explicit, or the built-in shape).
    pub fn trajectory(&self) -> Result<Trajectory, ScenarioError> {
        match &self.trajectory {
            Some(t) => Ok(t.clone()),
            None => {
                builtin(&self.shape, self.static_s).ok_or_else(|| ScenarioError::UnknownShape {
                    path: self.name.clone(),
                    shape: self.shape.clone(),
                    known: crate::trajectory::SHAPES.join(", "),
                })
            }
        }
    }

    /// `Ok` when every value is in its domain: a positive finite duration, a non-negative static
    /// period, a recording start `0 ≤ record_from_s < duration_s`, positive sensor rates, a
    /// finite gravity, fault intervals with finite values and `0 ≤ start_s < end_s` (a stuck gyro
    /// axis 0, 1 or 2, a positive clipping limit, an outlier probability in `[0, 1]`), and a valid
    /// replay configuration.
    ///
    /// # Errors
    /// The first value out of its domain, named.
    pub fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} = {x}: must be a positive number"))
            }
        };
        positive("duration_s", self.duration_s)?;
        if !(self.static_s.is_finite() && self.static_s >= 0.0) {
            return Err(format!("static_s = {}: must be 0 or more", self.static_s));
        }
        if !(self.record_from_s >= 0.0 && self.record_from_s < self.duration_s) {
            return Err(format!(
                "record_from_s = {}: must be 0 or more and below duration_s = {}",
                self.record_from_s, self.duration_s
            ));
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err("gravity: must be finite".into());
        }
        positive("imu.rate_hz", self.imu.rate_hz)?;
        let rates = [
            ("mag.rate_hz", self.mag.as_ref().map(|c| c.rate_hz)),
            ("gnss.rate_hz", self.gnss.as_ref().map(|c| c.rate_hz)),
            ("camera.rate_hz", self.camera.as_ref().map(|c| c.rate_hz)),
            ("baro.rate_hz", self.baro.as_ref().map(|c| c.rate_hz)),
        ];
        for (name, rate) in rates {
            if let Some(r) = rate {
                positive(name, r)?;
            }
        }
        self.validate_faults()?;
        self.replay.validate().map_err(|e| format!("replay.{e}"))
    }

    /// The fault part of [`Scenario::validate`].
    fn validate_faults(&self) -> Result<(), String> {
        let imu = &self.imu;
        intervals("imu.accel_clip", &imu.accel_clip)?;
        intervals("imu.gyro_stuck", &imu.gyro_stuck)?;
        for (i, f) in imu.accel_clip.iter().enumerate() {
            if f[2] <= 0.0 {
                return Err(format!(
                    "imu.accel_clip[{i}] = {f:?}: the limit must be positive"
                ));
            }
        }
        for (i, f) in imu.gyro_stuck.iter().enumerate() {
            if ![0.0, 1.0, 2.0].contains(&f[2]) {
                return Err(format!(
                    "imu.gyro_stuck[{i}] = {f:?}: the axis must be 0, 1 or 2"
                ));
            }
        }
        if let Some(c) = &self.mag {
            intervals("mag.disturbances", &c.disturbances)?;
            intervals("mag.rotated", &c.rotated)?;
            if !(c.delay_s.is_finite() && c.delay_s >= 0.0) {
                return Err(format!("mag.delay_s = {}: must be 0 or more", c.delay_s));
            }
        }
        if let Some(c) = &self.gnss {
            intervals("gnss.outages", &c.outages)?;
            intervals("gnss.steps", &c.steps)?;
            intervals("gnss.frozen", &c.frozen)?;
            let p = c.outlier_probability;
            if !(0.0..=1.0).contains(&p) {
                return Err(format!("gnss.outlier_probability = {p}: must be in [0, 1]"));
            }
            if !c.outlier_m.is_finite() {
                return Err(format!("gnss.outlier_m = {}: must be finite", c.outlier_m));
            }
        }
        if let Some(c) = &self.baro {
            intervals("baro.steps", &c.steps)?;
        }
        Ok(())
    }

    /// A built-in scenario by name, or a TOML file by path.
    pub fn load(name: &str) -> Result<Self, ScenarioError> {
        if let Some(s) = builtin_scenarios().into_iter().find(|s| s.name == name) {
            return Ok(s);
        }
        if name.ends_with(".toml") || std::path::Path::new(name).is_file() {
            let text = std::fs::read_to_string(name).map_err(|e| ScenarioError::File {
                path: name.into(),
                message: e.to_string(),
            })?;
            let mut s: Scenario = toml::from_str(&text).map_err(|e| ScenarioError::File {
                path: name.into(),
                message: e.to_string().replace('\n', " "),
            })?;
            if s.name == "custom" {
                s.name = name.into();
            }
            s.validate().map_err(|message| ScenarioError::Invalid {
                path: name.into(),
                message,
            })?;
            s.trajectory().map_err(|e| match e {
                ScenarioError::UnknownShape { shape, known, .. } => ScenarioError::UnknownShape {
                    path: name.into(),
                    shape,
                    known,
                },
                e => e,
            })?;
            return Ok(s);
        }
        Err(ScenarioError::Unknown(name.into()))
    }
}

/// `Ok` when every entry of the fault list `name` is finite with `0 ≤ start_s < end_s` (its first
/// two values).
fn intervals<const N: usize>(name: &str, list: &[[f64; N]]) -> Result<(), String> {
    for (i, f) in list.iter().enumerate() {
        if !f.iter().all(|x| x.is_finite()) {
            return Err(format!("{name}[{i}] = {f:?}: every value must be finite"));
        }
        if !(f[0] >= 0.0 && f[0] < f[1]) {
            return Err(format!(
                "{name}[{i}] = {f:?}: needs 0 ≤ start_s < end_s (seconds from the start)"
            ));
        }
    }
    Ok(())
}

/// The hard-iron offset of the `handheld_hard_iron` scenario, µT, body frame: a small magnet
/// or a speaker a few centimetres from the magnetometer (0.65 of the 48 µT field).
pub const HARD_IRON_UT: [f64; 3] = [15.0, -10.0, 25.0];

/// When the magnet of the `handheld_hard_iron` scenario is fixed to the board, s.
pub const HARD_IRON_FROM_S: f64 = 20.0;

/// When the `rover_moving` scenario's recording begins, s: the rover has been driving for 20 s.
pub const ROVER_MOVING_FROM_S: f64 = 30.0;

/// The built-in scenarios. `default` is what `host-sim run` runs with no arguments.
#[must_use]
pub fn builtin_scenarios() -> Vec<Scenario> {
    let deg = std::f64::consts::PI / 180.0;
    let base = Scenario::default();
    // Sensors exactly as the filter models them (no quantization, scale error or turn-on bias
    // beyond the filter's prior), for the Monte-Carlo consistency checks.
    let matched_imu = ImuConfig {
        gyro_lsb: 0.0,
        accel_lsb: 0.0,
        gyro_range: 0.0,
        accel_range: 0.0,
        ..ImuConfig::default()
    };
    let faults = fault_scenarios(&base);
    let car = Scenario {
        name: "car".into(),
        description: "60 s planar drive on a 15 m circle at 2.5 m/s; IMU, GNSS with 0.3 m lever arm, magnetometer".into(),
        shape: "car".into(),
        mag: Some(MagConfig::default()),
        gnss: Some(GnssConfig { lever_arm: [0.3, 0.0, 0.5], ..GnssConfig::default() }),
        ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.5 },
        ..base.clone()
    };
    let rover = Scenario {
        name: "rover".into(),
        description: "360 s slow rover on rough ground, 15 m circle at 0.23-0.47 m/s, tilts to ±13°; IMU 200 Hz, GNSS 1.5 m at 5 Hz, no magnetometer".into(),
        duration_s: 360.0,
        static_s: 10.0,
        shape: "rover".into(),
        gnss: Some(GnssConfig { sigma_horizontal: 1.5, ..GnssConfig::default() }),
        replay: ReplayConfig::simulated(),
        ..base.clone()
    };
    let mut all = vec![
        Scenario {
            name: "default".into(),
            description: "60 s figure-eight flight; IMU 200 Hz, magnetometer 50 Hz, GNSS 1 m at 5 Hz".into(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig::default()),
            ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.0 },
            ..base.clone()
        },
        Scenario {
            name: "static".into(),
            description: "60 s at rest; IMU, magnetometer, GNSS".into(),
            shape: "static".into(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig::default()),
            ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.0 },
            ..base.clone()
        },
        Scenario {
            name: "hover".into(),
            description: "60 s hover with 25 Hz vibration; IMU, magnetometer, GNSS, barometer".into(),
            shape: "hover".into(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig::default()),
            baro: Some(BaroConfig::default()),
            ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.0 },
            ..base.clone()
        },
        car.clone(),
        Scenario {
            name: "car_no_mag".into(),
            description: "car without its magnetometer: 60 s planar drive on a 15 m circle at 2.5 m/s; IMU, GNSS with 0.3 m lever arm, no magnetometer".into(),
            mag: None,
            ceilings: Ceilings::default(),
            replay: ReplayConfig::simulated(),
            ..car
        },
        rover.clone(),
        Scenario {
            name: "rover_reversing".into(),
            description: "the rover driving back and forth: its speed swings between -0.25 and 0.95 m/s every 200 s, reversing for a third of each swing; 360 s, IMU 200 Hz, GNSS 1.5 m at 5 Hz, no magnetometer".into(),
            shape: "rover_reversing".into(),
            ..rover.clone()
        },
        Scenario {
            name: "rover_moving".into(),
            description: "the rover recorded from 30 s, while it drives (never seen at rest): 330 s; IMU 200 Hz, GNSS 1.5 m at 5 Hz, no magnetometer".into(),
            record_from_s: ROVER_MOVING_FROM_S,
            ..rover
        },
        Scenario {
            name: "coning".into(),
            description: "60 s aggressive 2 Hz coning at 0.3 rad; IMU, magnetometer (attitude only)".into(),
            shape: "coning".into(),
            mag: Some(MagConfig::default()),
            ceilings: Ceilings { ate_m: f64::INFINITY, attitude_deg: 1.5 },
            ..base.clone()
        },
        Scenario {
            name: "pitch90".into(),
            description: "60 s pitching through ±90°; IMU, magnetometer, GNSS".into(),
            shape: "pitch90".into(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig::default()),
            ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.5 },
            ..base.clone()
        },
        Scenario {
            name: "handheld_ahrs".into(),
            description: "60 s hand-held motion, 0.5°/s gyro turn-on bias; IMU 200 Hz, magnetometer 50 Hz (attitude only)".into(),
            shape: "handheld".into(),
            imu: ImuConfig { gyro_turn_on_bias: 0.5 * deg, ..ImuConfig::default() },
            mag: Some(MagConfig::default()),
            ceilings: Ceilings { ate_m: f64::INFINITY, attitude_deg: 1.2 },
            ..base.clone()
        },
        Scenario {
            name: "handheld_hard_iron".into(),
            description: "handheld_ahrs with a magnet fixed to the board at 20 s: a 31 µT hard-iron offset the navigator learns while the body turns".into(),
            shape: "handheld".into(),
            imu: ImuConfig { gyro_turn_on_bias: 0.5 * deg, ..ImuConfig::default() },
            mag: Some(MagConfig { hard_iron: HARD_IRON_UT, hard_iron_from_s: HARD_IRON_FROM_S, ..MagConfig::default() }),
            ceilings: Ceilings { ate_m: f64::INFINITY, attitude_deg: 1.2 },
            ..base.clone()
        },
        Scenario {
            name: "handheld_ins".into(),
            description: "60 s hand-held motion; IMU 200 Hz, magnetometer 50 Hz, GNSS 1 m at 5 Hz".into(),
            shape: "handheld".into(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig::default()),
            ceilings: Ceilings { ate_m: 0.5, attitude_deg: 1.0 },
            ..base.clone()
        },
        Scenario {
            name: "gnss_faults".into(),
            description: "figure-eight with a 10 s GNSS outage, 5 % gross outliers and a magnetic disturbance".into(),
            mag: Some(MagConfig { disturbances: vec![[30.0, 36.0, 25.0]], ..MagConfig::default() }),
            gnss: Some(GnssConfig {
                outages: vec![[20.0, 30.0]],
                outlier_probability: 0.05,
                ..GnssConfig::default()
            }),
            ceilings: Ceilings { ate_m: 1.5, attitude_deg: 2.0 },
            ..base.clone()
        },
        Scenario {
            name: "camera".into(),
            description: "hover in front of 300 known landmarks; IMU, magnetometer and a 10 Hz camera (pose from PnP at start)".into(),
            shape: "hover".into(),
            mag: Some(MagConfig::default()),
            camera: Some(CameraConfig::default()),
            ceilings: Ceilings { ate_m: 0.3, attitude_deg: 1.0 },
            ..base.clone()
        },
        Scenario {
            name: "matched_ins".into(),
            description: "noise exactly as the filter models it (Monte-Carlo consistency); figure-eight, IMU, magnetometer, GNSS".into(),
            imu: matched_imu.clone(),
            mag: Some(MagConfig::default()),
            gnss: Some(GnssConfig { sigma_vertical: 1.0, ..GnssConfig::default() }),
            ceilings: Ceilings { ate_m: 0.6, attitude_deg: 1.0 },
            ..base.clone()
        },
        Scenario {
            name: "matched_ahrs".into(),
            description: "noise exactly as the filter models it (Monte-Carlo consistency); hand-held rotation in place, IMU, magnetometer".into(),
            shape: "rotate".into(),
            // In place, with an accelerometer bias drawn from the navigator's prior, no gyro scale
            // error and an ideal magnetometer (its whole field fused): nothing beyond what the
            // navigator models.
            replay: ReplayConfig { rotation_only: true, magnetometer_vector: true, accelerometer_bias_sigma: 0.05, gyro_scale_sigma: 0.0, heading_floor_deg: 0.0, heading_noise_deg: 0.0, ..ReplayConfig::simulated() },
            imu: ImuConfig { accel_turn_on_bias: 0.05, accelerometer_random_walk: 0.0, ..matched_imu },
            mag: Some(MagConfig::default()),
            ceilings: Ceilings { ate_m: f64::INFINITY, attitude_deg: 1.2 },
            ..base
        },
    ];
    all.extend(faults);
    all
}

/// The fault scenarios, one sensor fault each, for showing that a navigator detects a fault and
/// recovers once good data returns. Each flies the `default` figure-eight (or a variant of it
/// where the fault needs a particular motion) with every sensor a navigator fuses (IMU 200 Hz,
/// magnetometer 50 Hz, GNSS 5 Hz, barometer 25 Hz), with at least 50 s after the fault ends.
/// Their ceilings are left open.
fn fault_scenarios(base: &Scenario) -> Vec<Scenario> {
    fn sine(amplitude: f64, frequency_hz: f64, phase: f64) -> Sine {
        Sine {
            amplitude,
            frequency_hz,
            phase,
        }
    }
    let all_sensors = Scenario {
        duration_s: 120.0,
        mag: Some(MagConfig::default()),
        gnss: Some(GnssConfig::default()),
        baro: Some(BaroConfig::default()),
        ceilings: Ceilings::default(),
        ..base.clone()
    };
    let figure8 = |edit: fn(&mut Trajectory)| {
        builtin("figure8", base.static_s).map(|mut t| {
            edit(&mut t);
            t
        })
    };
    // Ten times the size at half the frequency: x = 100 sin(ωτ), y = 50 sin(2ωτ), ω = 2π/40 s,
    // so the speed stays between 10.4 and 22 m/s (a 0.2 s latency is 2 to 4.4 m of lag).
    let fast = figure8(|t| {
        t.position[0] = Signal {
            sines: vec![sine(100.0, 1.0 / 40.0, 0.0)],
            ..Signal::default()
        };
        t.position[1] = Signal {
            sines: vec![sine(50.0, 1.0 / 20.0, 0.0)],
            ..Signal::default()
        };
    });
    // A 23.3 Hz vertical vibration of 1.84 mm (motors on a stiff mount): ±39.5 m/s², so the
    // vertical specific force peaks near 5 g and a ±4 g range clips it, on one side only. Not a
    // divisor of the 200 Hz IMU rate: a motor is not phase-locked to the IMU's clock, and a
    // locked one would repeat its quantized samples exactly, as only a clipped axis does.
    let vibrating = figure8(|t| t.position[2].sines.push(sine(0.001_843, 23.3, 0.0)));
    // The heading swing phased so that its rate crosses zero, rising, at 40 s (τ = 34 s): a turn
    // begins, and by 42 s the heading has moved 0.19 rad that a stuck z gyro does not see.
    let turning = figure8(|t| {
        t.euler[2] = Signal {
            offset: 0.4,
            sines: vec![sine(1.0, 1.0 / 20.0, 0.1 * std::f64::consts::PI)],
            ..Signal::default()
        };
    });
    vec![
        Scenario {
            name: "fault_gnss_step".into(),
            description: "GNSS fixes 50 m off (30 m east, 40 m north) from 40 s to 70 s; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            gnss: Some(GnssConfig { steps: vec![[40.0, 70.0, 30.0, 40.0, 0.0]], ..GnssConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_gnss_frozen".into(),
            description: "GNSS receiver repeats its last fix from 40 s to 55 s; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            gnss: Some(GnssConfig { frozen: vec![[40.0, 55.0]], ..GnssConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_gnss_outage".into(),
            description: "10 min GNSS outage from 30 s to 630 s, then 70 s of fixes; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer".into(),
            duration_s: 700.0,
            gnss: Some(GnssConfig { outages: vec![[30.0, 630.0]], ..GnssConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_gnss_outliers".into(),
            description: "5 % of GNSS fixes 50 m off horizontally, at random; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            gnss: Some(GnssConfig { outlier_probability: 0.05, outlier_m: 50.0, ..GnssConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_gnss_latency".into(),
            description: "GNSS fixes 0.2 s late on a 200 m figure-eight at 10-22 m/s; IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            trajectory: fast,
            gnss: Some(GnssConfig { latency_s: 0.2, ..GnssConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_mag_rotated".into(),
            description: "magnetometer reads rotated 90° about body z from 40 s to 100 s; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 160 s".into(),
            duration_s: 160.0,
            mag: Some(MagConfig { rotated: vec![[40.0, 100.0, 90.0]], ..MagConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_baro_step".into(),
            description: "barometer reads 20 m high from 40 s to 70 s; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            baro: Some(BaroConfig { steps: vec![[40.0, 70.0, 20.0]], ..BaroConfig::default() }),
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_accel_clip".into(),
            description: "accelerometer clipped at ±4 g from 40 s to 42 s under a 23.3 Hz vibration peaking near 5 g; figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            trajectory: vibrating,
            imu: ImuConfig { accel_clip: vec![[40.0, 42.0, 4.0 * 9.81]], ..ImuConfig::default() },
            ..all_sensors.clone()
        },
        Scenario {
            name: "fault_gyro_stuck".into(),
            description: "z gyro stuck from 40 s to 42 s as a turn begins (0.19 rad unseen); figure-eight, IMU, magnetometer, GNSS 5 Hz, barometer, 120 s".into(),
            trajectory: turning,
            imu: ImuConfig { gyro_stuck: vec![[40.0, 42.0, 2.0]], ..ImuConfig::default() },
            ..all_sensors
        },
    ]
}

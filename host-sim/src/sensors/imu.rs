//! A MEMS IMU: white noise density, bias random walk, turn-on bias, scale factor and
//! misalignment, quantization, saturation and rate; and two faults, a clipping accelerometer and
//! a stuck gyro axis.
//!
//! Measurement model at sample `k` (body frame = sensor frame):
//!
//! ```text
//! ω̃ = Q(M_g (ω_b + b_g) + n_g),   n_g ~ N(0, σ_g² · rate)    σ_g: gyroscope_noise_density
//! f̃ = Q(M_a (Rᵀ(a − g) + b_a) + n_a),  n_a ~ N(0, σ_a² · rate)
//! b_g ← b_g + σ_bg √dt · N(0, I)                              σ_bg: gyroscope_random_walk
//! ```
//!
//! with `M = I + (scale and misalignment)` and `Q` quantization and saturation. The densities
//! are continuous-time, in Kalibr units (rad/s/√Hz, m/s²/√Hz, rad/s²/√Hz, m/s³/√Hz).
//!
//! Faults act on the output, at the sample's time `t` (seconds from the scenario's start): during
//! an `accel_clip` interval `f̃ᵢ ← clamp(f̃ᵢ, −limit, limit)` on every axis (a range too small for
//! the motion); during a `gyro_stuck` interval the named axis repeats the value it gave at the
//! sample before the interval. The ground truth's biases stay those of the model above.
//!
//! Defaults are those of a Bosch BMI088 class IMU: gyro noise density 0.014 °/s/√Hz, accelerometer
//! 175 µg/√Hz (datasheet typicals); ±2000 °/s and ±24 g ranges with 16-bit output; bias random
//! walks and turn-on biases typical of that class in calibration (Kalibr) practice.

use super::{quantize_saturate, Noise};
use crate::trajectory::Kinematics;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// IMU parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct ImuConfig {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Gyroscope white noise density, rad/s/√Hz.
    pub gyroscope_noise_density: f64,
    /// Gyroscope bias random walk, rad/s²/√Hz.
    pub gyroscope_random_walk: f64,
    /// Accelerometer white noise density, m/s²/√Hz.
    pub accelerometer_noise_density: f64,
    /// Accelerometer bias random walk, m/s³/√Hz.
    pub accelerometer_random_walk: f64,
    /// 1-σ of the gyroscope turn-on bias per axis, rad/s.
    pub gyro_turn_on_bias: f64,
    /// 1-σ of the accelerometer turn-on bias per axis, m/s².
    pub accel_turn_on_bias: f64,
    /// 1-σ of scale-factor errors and axis misalignments (dimensionless), gyro.
    pub gyro_scale_misalignment: f64,
    /// 1-σ of scale-factor errors and axis misalignments, accelerometer.
    pub accel_scale_misalignment: f64,
    /// Gyro LSB, rad/s (0: no quantization).
    pub gyro_lsb: f64,
    /// Accelerometer LSB, m/s².
    pub accel_lsb: f64,
    /// Gyro range, rad/s (0: no saturation).
    pub gyro_range: f64,
    /// Accelerometer range, m/s².
    pub accel_range: f64,
    /// Clipping `[start_s, end_s, limit_mps2]`: every accelerometer axis of a sample taken in
    /// `[start_s, end_s)` (seconds from the scenario's start) is clamped to `±limit_mps2`.
    pub accel_clip: Vec<[f64; 3]>,
    /// Stuck gyro axes `[start_s, end_s, axis]` (axis 0, 1 or 2): in `[start_s, end_s)` that axis
    /// repeats the last value it gave before `start_s` (its first value if none came before).
    pub gyro_stuck: Vec<[f64; 3]>,
}

impl Default for ImuConfig {
    fn default() -> Self {
        let deg = std::f64::consts::PI / 180.0;
        let g = 9.80665;
        Self {
            rate_hz: 200.0,
            gyroscope_noise_density: 0.014 * deg,
            gyroscope_random_walk: 2.0e-5,
            accelerometer_noise_density: 175e-6 * g,
            accelerometer_random_walk: 3.0e-4,
            gyro_turn_on_bias: 0.5 * deg,
            accel_turn_on_bias: 0.02,
            gyro_scale_misalignment: 0.0,
            accel_scale_misalignment: 0.0,
            gyro_lsb: 2000.0 * deg / 32768.0,
            accel_lsb: 24.0 * g / 32768.0,
            gyro_range: 2000.0 * deg,
            accel_range: 24.0 * g,
            accel_clip: Vec::new(),
            gyro_stuck: Vec::new(),
        }
    }
}

/// One IMU sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample {
    /// Angular rate, rad/s.
    pub gyro: Vector3<f64>,
    /// Specific force, m/s².
    pub accel: Vector3<f64>,
    /// True gyro bias at this sample, rad/s.
    pub gyro_bias: Vector3<f64>,
    /// True accelerometer bias at this sample, m/s².
    pub accel_bias: Vector3<f64>,
}

/// The IMU model with its evolving biases.
#[derive(Clone, Debug)]
pub struct Imu {
    cfg: ImuConfig,
    gravity: Vector3<f64>,
    noise: Noise,
    gyro_bias: Vector3<f64>,
    accel_bias: Vector3<f64>,
    m_g: Matrix3<f64>,
    m_a: Matrix3<f64>,
    /// The gyro output of the previous sample, which a stuck axis repeats.
    last_gyro: Option<Vector3<f64>>,
}

impl Imu {
    /// A new IMU drawing its turn-on biases and scale/misalignment from `noise`.
    #[must_use]
    pub fn new(cfg: ImuConfig, gravity: Vector3<f64>, mut noise: Noise) -> Self {
        let gyro_bias = noise.normal3() * cfg.gyro_turn_on_bias;
        let accel_bias = noise.normal3() * cfg.accel_turn_on_bias;
        let mut draw = |s: f64| Matrix3::identity() + Matrix3::from_fn(|_, _| noise.normal() * s);
        let m_g = draw(cfg.gyro_scale_misalignment);
        let m_a = draw(cfg.accel_scale_misalignment);
        Self {
            cfg,
            gravity,
            noise,
            gyro_bias,
            accel_bias,
            m_g,
            m_a,
            last_gyro: None,
        }
    }

    /// Samples the IMU at the true state `k` (instantaneous values, as a sensor without a
    /// decimation filter gives them) with the faults active at `k.t`, then advances the biases by
    /// one period.
    pub fn sample(&mut self, k: &Kinematics) -> ImuSample {
        let c = &self.cfg;
        let sqrt_rate = c.rate_hz.sqrt();
        let specific_force = k.attitude.inverse_act(&(k.acceleration - self.gravity));
        let gyro = self.m_g * (k.omega_body + self.gyro_bias)
            + self.noise.normal3() * (c.gyroscope_noise_density * sqrt_rate);
        let accel = self.m_a * (specific_force + self.accel_bias)
            + self.noise.normal3() * (c.accelerometer_noise_density * sqrt_rate);
        let mut gyro = gyro.map(|x| quantize_saturate(x, c.gyro_lsb, c.gyro_range));
        let mut accel = accel.map(|x| quantize_saturate(x, c.accel_lsb, c.accel_range));
        let during = |f: &[f64; 3]| k.t >= f[0] && k.t < f[1];
        for f in c.gyro_stuck.iter().filter(|f| during(f)) {
            // The last output holds the stuck value already when the interval has begun.
            let axis = f[2] as usize;
            if let (Some(last), true) = (self.last_gyro, axis < 3) {
                gyro[axis] = last[axis];
            }
        }
        for f in c.accel_clip.iter().filter(|f| during(f)) {
            // Not `clamp`, which panics on a limit `Scenario::validate` would refuse.
            accel = accel.map(|x| x.max(-f[2]).min(f[2]));
        }
        self.last_gyro = Some(gyro);
        let out = ImuSample {
            gyro,
            accel,
            gyro_bias: self.gyro_bias,
            accel_bias: self.accel_bias,
        };
        let sqrt_dt = (1.0 / c.rate_hz).sqrt();
        self.gyro_bias += self.noise.normal3() * (c.gyroscope_random_walk * sqrt_dt);
        self.accel_bias += self.noise.normal3() * (c.accelerometer_random_walk * sqrt_dt);
        out
    }
}

/// `Rᵀ v` for a rotation (extension used by the sensor models).
pub trait InverseAct {
    /// `Rᵀ v`.
    fn inverse_act(&self, v: &Vector3<f64>) -> Vector3<f64>;
}

impl InverseAct for estimator_core::lie::So3<f64> {
    fn inverse_act(&self, v: &Vector3<f64>) -> Vector3<f64> {
        use estimator_core::lie::LieGroup;
        self.inverse().act(v)
    }
}

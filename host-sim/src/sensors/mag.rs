//! A 3-axis magnetometer: white noise, hard and soft iron, disturbance episodes, rotated output.
//!
//! `m̃ = R_z(α(t)) (A (Rᵀ (m_w + d(t))) + b(t) + σ n)`, with `A = I + S` (soft iron), `b` (hard
//! iron, µT, from `hard_iron_from_s` on), `d(t)` a world-frame disturbance that is non-zero during episodes (a steel structure
//! nearby), `σ` the per-sample white noise (µT), and `R_z(α)` a rotation by `α` about the body z
//! axis, the identity outside `rotated` intervals (a sensor remounted or its axes mislabelled).
//! A sample stamped `t` is taken at the true state of `t − delay_s` (the sensor's delay
//! behind the IMU). Defaults: an ICM-20948 class magnetometer (AK09916: 0.15 µT/LSB, about 0.4 µT rms noise) under
//! a mid-latitude field of 48 µT, 60° inclination, with calibrated (zero) iron terms and no
//! faults.

use super::Noise;
use crate::sensors::imu::InverseAct;
use crate::trajectory::Kinematics;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Magnetometer parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct MagConfig {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// White noise per sample and axis, µT.
    pub sigma: f64,
    /// The Earth's field in the world frame (ENU), µT.
    pub reference_field: [f64; 3],
    /// Hard-iron offset in the body frame, µT.
    pub hard_iron: [f64; 3],
    /// The hard iron is there from this time on, s from the scenario's start (a magnet fixed
    /// to the board while it runs); 0: from the start.
    pub hard_iron_from_s: f64,
    /// Soft-iron matrix minus identity, row-major.
    pub soft_iron: [f64; 9],
    /// Disturbance episodes `[start_s, end_s, magnitude_uT]`, a world-frame field along east.
    pub disturbances: Vec<[f64; 3]>,
    /// How long the sample lags its timestamp, s: the row stamped `t` is the field at
    /// `t − delay_s` (a magnetometer's conversion and output filter, behind the IMU's stamps).
    pub delay_s: f64,
    /// Rotated output `[start_s, end_s, angle_deg]`: a sample taken in `[start_s, end_s)`
    /// (seconds from the scenario's start) is rotated by `angle_deg` about the body z axis,
    /// `(x, y) ← (x cos α − y sin α, x sin α + y cos α)` (overlapping intervals add).
    pub rotated: Vec<[f64; 3]>,
}

impl Default for MagConfig {
    fn default() -> Self {
        let (total, incl) = (48.0f64, 60.0f64.to_radians());
        Self {
            rate_hz: 50.0,
            sigma: 0.4,
            reference_field: [0.0, total * incl.cos(), -total * incl.sin()],
            hard_iron: [0.0; 3],
            hard_iron_from_s: 0.0,
            soft_iron: [0.0; 9],
            disturbances: Vec::new(),
            delay_s: 0.0,
            rotated: Vec::new(),
        }
    }
}

/// The magnetometer model.
#[derive(Clone, Debug)]
pub struct Mag {
    cfg: MagConfig,
    noise: Noise,
}

impl Mag {
    /// A new magnetometer.
    #[must_use]
    pub fn new(cfg: MagConfig, noise: Noise) -> Self {
        Self { cfg, noise }
    }

    /// One sample at the true state `k`, µT, body frame, with the faults active at `k.t`.
    pub fn sample(&mut self, k: &Kinematics) -> Vector3<f64> {
        let c = &self.cfg;
        let mut world = Vector3::from(c.reference_field);
        for d in &c.disturbances {
            if k.t >= d[0] && k.t < d[1] {
                world.x += d[2];
            }
        }
        let a = Matrix3::identity() + Matrix3::from_row_slice(&c.soft_iron);
        let hard_iron = if k.t >= c.hard_iron_from_s {
            Vector3::from(c.hard_iron)
        } else {
            Vector3::zeros()
        };
        let m = a * k.attitude.inverse_act(&world) + hard_iron + self.noise.normal3() * c.sigma;
        let angle_deg: f64 = c
            .rotated
            .iter()
            .filter(|r| k.t >= r[0] && k.t < r[1])
            .map(|r| r[2])
            .sum();
        if angle_deg == 0.0 {
            // Outside every interval the sample is as it always was, bit for bit.
            return m;
        }
        let (s, co) = angle_deg.to_radians().sin_cos();
        Vector3::new(m.x * co - m.y * s, m.x * s + m.y * co, m.z)
    }
}

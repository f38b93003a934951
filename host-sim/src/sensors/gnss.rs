//! A GNSS receiver: position and velocity fixes with noise, latency, outages, gross outliers,
//! position steps and a frozen output.
//!
//! The antenna sits at the body-frame lever arm `l`: `p_ant = p + R l`, `v_ant = v + R(ω_b × l)`.
//! A fix stamped `t` describes the state at `t − latency` (its *state time*). During an outage no
//! fix is produced; a gross outlier adds `outlier_m` metres in a random horizontal direction; a
//! step adds a constant world-frame offset to the position; a frozen receiver repeats the position
//! and velocity of its last fix under new timestamps. Outages go by the stamp (the receiver sends
//! nothing then); steps and freezes go by the state time (they corrupt what is measured then), so
//! with a latency the rows they change are those stamped `[start + latency, end + latency)`. The
//! reported `sigma_p`, `sigma_v` are the configured 1-σ (what a receiver would report), whatever
//! the faults: `sigma_p` the larger of horizontal and vertical (one σ for readers that take one
//! for every axis), the two themselves in `gnss0/sensor.yaml` (`sigma_p_horizontal`,
//! `sigma_p_up`) when they differ. Defaults: a u-blox M8/M9 class receiver at 5 Hz, 1 m
//! horizontal and 1.5 m vertical, without faults.

use super::Noise;
use crate::trajectory::Kinematics;
use estimator_core::lie::LieGroup;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// GNSS parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct GnssConfig {
    /// Fix rate, Hz.
    pub rate_hz: f64,
    /// Horizontal position noise, m (1σ).
    pub sigma_horizontal: f64,
    /// Vertical position noise, m (1σ).
    pub sigma_vertical: f64,
    /// Velocity noise, m/s (1σ per axis).
    pub sigma_velocity: f64,
    /// Latency of the fix, s.
    pub latency_s: f64,
    /// Antenna lever arm in the body frame, m.
    pub lever_arm: [f64; 3],
    /// Outages `[start_s, end_s]`: no fix stamped in `[start_s, end_s)` (seconds from the
    /// scenario's start).
    pub outages: Vec<[f64; 2]>,
    /// Probability that a fix is a gross outlier.
    pub outlier_probability: f64,
    /// Size of a gross outlier, m.
    pub outlier_m: f64,
    /// Position steps `[start_s, end_s, dx, dy, dz]`: every fix whose state time (stamp −
    /// latency) is in `[start_s, end_s)` is offset by `(dx, dy, dz)` m in the world frame
    /// (overlapping steps add). The end lets a test see the recovery once good fixes return.
    pub steps: Vec<[f64; 5]>,
    /// Frozen output `[start_s, end_s]`: every fix whose state time is in `[start_s, end_s)`
    /// repeats the position and velocity of the last fix produced before it, under its own new
    /// timestamp (the first fix of the interval is held when none came before).
    pub frozen: Vec<[f64; 2]>,
}

impl Default for GnssConfig {
    fn default() -> Self {
        Self {
            rate_hz: 5.0,
            sigma_horizontal: 1.0,
            sigma_vertical: 1.5,
            sigma_velocity: 0.1,
            latency_s: 0.0,
            lever_arm: [0.0; 3],
            outages: Vec::new(),
            outlier_probability: 0.0,
            outlier_m: 20.0,
            steps: Vec::new(),
            frozen: Vec::new(),
        }
    }
}

/// One GNSS fix (world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix {
    /// Antenna position, m.
    pub position: Vector3<f64>,
    /// Antenna velocity, m/s.
    pub velocity: Vector3<f64>,
    /// Reported position 1σ, m (the larger of horizontal and vertical).
    pub sigma_p: f64,
    /// Reported horizontal position 1σ, m.
    pub sigma_p_horizontal: f64,
    /// Reported vertical position 1σ, m.
    pub sigma_p_up: f64,
    /// Reported velocity 1σ, m/s.
    pub sigma_v: f64,
}

/// The receiver model.
#[derive(Clone, Debug)]
pub struct Gnss {
    cfg: GnssConfig,
    noise: Noise,
    /// The last fix produced, which a frozen receiver repeats.
    last: Option<GnssFix>,
}

impl Gnss {
    /// A new receiver.
    #[must_use]
    pub fn new(cfg: GnssConfig, noise: Noise) -> Self {
        Self {
            cfg,
            noise,
            last: None,
        }
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &GnssConfig {
        &self.cfg
    }

    /// A fix of the (already delayed) true state `k`, or `None` during an outage. `stamp_s` is
    /// the fix's timestamp; `k.t` its state time, which steps and freezes go by.
    pub fn sample(&mut self, k: &Kinematics, stamp_s: f64) -> Option<GnssFix> {
        let c = &self.cfg;
        // Draw every random number first, so the stream does not depend on the faults.
        let n_p = self.noise.normal3();
        let n_v = self.noise.normal3();
        let outlier = self.noise.uniform() < c.outlier_probability;
        let dir = self.noise.uniform() * std::f64::consts::TAU;
        if c.outages.iter().any(|o| stamp_s >= o[0] && stamp_s < o[1]) {
            return None;
        }
        let during = |start: f64, end: f64| k.t >= start && k.t < end;
        if c.frozen.iter().any(|f| during(f[0], f[1])) {
            if let Some(held) = self.last {
                return Some(held);
            }
        }
        let l = Vector3::from(c.lever_arm);
        let mut position = k.position
            + k.attitude.act(&l)
            + Vector3::new(
                n_p.x * c.sigma_horizontal,
                n_p.y * c.sigma_horizontal,
                n_p.z * c.sigma_vertical,
            );
        if outlier {
            position += Vector3::new(dir.cos(), dir.sin(), 0.0) * c.outlier_m;
        }
        for s in c.steps.iter().filter(|s| during(s[0], s[1])) {
            position += Vector3::new(s[2], s[3], s[4]);
        }
        let velocity =
            k.velocity + k.attitude.act(&k.omega_body.cross(&l)) + n_v * c.sigma_velocity;
        let fix = GnssFix {
            position,
            velocity,
            sigma_p: c.sigma_horizontal.max(c.sigma_vertical),
            sigma_p_horizontal: c.sigma_horizontal,
            sigma_p_up: c.sigma_vertical,
            sigma_v: c.sigma_velocity,
        };
        self.last = Some(fix);
        Some(fix)
    }
}

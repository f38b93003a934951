//! A barometric altimeter: `h̃ = p_z + b + s(t) + σ n`, with a constant bias `b` drawn at start
//! and `s(t)` the sum of the `steps` active at `t` (a pressure jump: a door, a weather front, a
//! prop wash). Defaults: a BMP388 class sensor, about 0.1 m rms at 25 Hz after its filter,
//! referenced to the local pressure (offset 0 by default: the 15-state filter has no
//! barometer-bias state, so an offset would go straight into its altitude; set `bias_sigma` to
//! study that), no steps.

use super::Noise;
use crate::trajectory::Kinematics;
use serde::{Deserialize, Serialize};

/// Barometer parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct BaroConfig {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// White noise per sample, m.
    pub sigma: f64,
    /// 1σ of the constant offset, m.
    pub bias_sigma: f64,
    /// Altitude steps `[start_s, end_s, dz_m]`: a sample taken in `[start_s, end_s)` (seconds
    /// from the scenario's start) reads `dz_m` higher (overlapping steps add).
    pub steps: Vec<[f64; 3]>,
}

impl Default for BaroConfig {
    fn default() -> Self {
        Self {
            rate_hz: 25.0,
            sigma: 0.1,
            bias_sigma: 0.0,
            steps: Vec::new(),
        }
    }
}

/// The barometer model.
#[derive(Clone, Debug)]
pub struct Baro {
    cfg: BaroConfig,
    noise: Noise,
    bias: f64,
}

impl Baro {
    /// A new barometer.
    #[must_use]
    pub fn new(cfg: BaroConfig, mut noise: Noise) -> Self {
        let bias = noise.normal() * cfg.bias_sigma;
        Self { cfg, noise, bias }
    }

    /// Altitude, m, with the steps active at `k.t`.
    pub fn sample(&mut self, k: &Kinematics) -> f64 {
        let h = k.position.z + self.bias + self.noise.normal() * self.cfg.sigma;
        self.cfg
            .steps
            .iter()
            .filter(|s| k.t >= s[0] && k.t < s[1])
            .fold(h, |h, s| h + s[2])
    }
}

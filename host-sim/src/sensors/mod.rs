//! Sensor models with the parameters users read off datasheets.
//!
//! Every model draws from its own ChaCha8 stream (`seed`, stream = the sensor's id), so turning
//! one sensor on or off never changes another's noise, and the same seed gives the same bytes.

pub mod baro;
pub mod camera;
pub mod gnss;
pub mod imu;
pub mod mag;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The random stream of one sensor.
#[derive(Clone, Debug)]
pub struct Noise {
    rng: ChaCha8Rng,
}

impl Noise {
    /// Stream `stream` of seed `seed`.
    #[must_use]
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Self { rng }
    }

    /// A standard normal sample.
    pub fn normal(&mut self) -> f64 {
        self.rng.sample(StandardNormal)
    }

    /// Three independent standard normal samples.
    pub fn normal3(&mut self) -> nalgebra::Vector3<f64> {
        nalgebra::Vector3::new(self.normal(), self.normal(), self.normal())
    }

    /// A uniform sample in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        self.rng.random::<f64>()
    }
}

/// Rounds to a multiple of `lsb` (no-op when `lsb ≤ 0`) and clamps to `±range` (no-op when
/// `range ≤ 0`): an ADC's quantization and saturation.
#[must_use]
pub fn quantize_saturate(x: f64, lsb: f64, range: f64) -> f64 {
    let x = if range > 0.0 {
        x.clamp(-range, range)
    } else {
        x
    };
    if lsb > 0.0 {
        (x / lsb).round() * lsb
    } else {
        x
    }
}

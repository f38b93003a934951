//! Motion and sensor generator for the eskf tests (f64 truth), on the shared `support`
//! random stream.
#![allow(dead_code)]

use estimator_core::eskf::{ImuNoise, ImuSample, InsState};
use estimator_core::lie::{LieGroup, So3};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

pub use crate::support::Rng;

pub const G: f64 = 9.81;

pub fn gravity() -> Vector3<f64> {
    Vector3::new(0.0, 0.0, -G)
}

/// World magnetic reference field (µT, ENU, north = +y, pointing down).
pub fn mag_reference() -> Vector3<f64> {
    Vector3::new(0.0, 22.0, -42.0)
}

/// Hand-held-like motion: at rest until `t0`, then sinusoidal body rates (up to ~0.8 rad/s) and
/// world accelerations (up to ~0.7 m/s²).
#[derive(Clone, Copy, Debug)]
pub struct Motion {
    pub t0: f64,
    pub rate_amp: Vector3<f64>,
    pub rate_freq: Vector3<f64>,
    pub acc_amp: Vector3<f64>,
    pub acc_freq: Vector3<f64>,
}

impl Motion {
    pub fn hand_held(t0: f64) -> Self {
        Self {
            t0,
            rate_amp: Vector3::new(0.5, 0.4, 0.8),
            rate_freq: Vector3::new(0.9, 1.3, 0.5),
            acc_amp: Vector3::new(0.3, 0.25, 0.1),
            acc_freq: Vector3::new(1.5, 1.1, 2.0),
        }
    }
    pub fn rate(&self, t: f64) -> Vector3<f64> {
        let s = (t - self.t0).max(0.0);
        Vector3::from_fn(|i, _| self.rate_amp[i] * (self.rate_freq[i] * s).sin())
    }
    /// World acceleration: `−A ω² sin(ω s)`.
    pub fn acc(&self, t: f64) -> Vector3<f64> {
        let s = (t - self.t0).max(0.0);
        Vector3::from_fn(|i, _| {
            let w = self.acc_freq[i];
            -self.acc_amp[i] * w * w * (w * s).sin()
        })
    }
}

/// Truth state and IMU generator, integrating exactly the filter's discrete model.
pub struct Sim {
    pub rng: Rng,
    pub t: f64,
    pub dt: f64,
    pub truth: InsState<f64>,
    pub noise: ImuNoise<f64>,
    pub motion: Motion,
}

impl Sim {
    pub fn new(seed: u64, dt: f64, motion: Motion, noise: ImuNoise<f64>) -> Self {
        let mut rng = Rng::new(seed);
        let yaw = 2.0 * std::f64::consts::PI * rng.uniform();
        let tilt = rng.vec3(0.1);
        let attitude = So3::exp(&Vector3::new(tilt.x, tilt.y, yaw));
        // 0.5 °/s turn-on gyro bias in a random direction; accelerometer bias 0.02 m/s² per axis.
        let d = rng.vec3(1.0).normalize();
        let truth = InsState {
            attitude,
            velocity: Vector3::zeros(),
            position: rng.vec3(10.0),
            gyro_bias: d * 0.5_f64.to_radians(),
            accel_bias: rng.vec3(0.02),
        };
        Self {
            rng,
            t: 0.0,
            dt,
            truth,
            noise,
            motion,
        }
    }

    /// One IMU sample over `[t, t + dt)`; advances the truth.
    pub fn step(&mut self) -> ImuSample<f64> {
        let dt = self.dt;
        let w = self.motion.rate(self.t);
        let a = self.motion.acc(self.t);
        let x = &mut self.truth;
        let r = x.attitude.rotation_matrix();
        let f = r.transpose() * (a - gravity());
        let sd = 1.0 / dt.sqrt();
        let n = self.noise;
        let gyro = w + x.gyro_bias + self.rng.vec3(n.gyroscope_noise_density * sd);
        let accel = f + x.accel_bias + self.rng.vec3(n.accelerometer_noise_density * sd);
        x.attitude = x.attitude.compose(&So3::exp(&(w * dt))).normalize();
        x.position += x.velocity * dt + a * (0.5 * dt * dt);
        x.velocity += a * dt;
        x.gyro_bias += self.rng.vec3(n.gyroscope_random_walk * dt.sqrt());
        x.accel_bias += self.rng.vec3(n.accelerometer_random_walk * dt.sqrt());
        self.t += dt;
        ImuSample { gyro, accel, dt }
    }

    /// The true specific force at the current time (noise-free, bias-free).
    pub fn specific_force(&self) -> Vector3<f64> {
        let r = self.truth.attitude.rotation_matrix();
        r.transpose() * (self.motion.acc(self.t) - gravity())
    }

    pub fn mag(&mut self, sigma: f64) -> Vector3<f64> {
        self.truth.attitude.inverse().act(&mag_reference()) + self.rng.vec3(sigma)
    }

    pub fn gnss(&mut self, sigma: f64) -> Vector3<f64> {
        self.truth.position + self.rng.vec3(sigma)
    }
}

/// `x_true ⊖ x̂` (15-vector) with the right attitude error.
pub fn ins_error(truth: &InsState<f64>, est: &InsState<f64>) -> SVector<f64, 15> {
    let mut e = SVector::<f64, 15>::zeros();
    e.fixed_rows_mut::<3>(0)
        .copy_from(&truth.attitude.rminus(&est.attitude));
    e.fixed_rows_mut::<3>(3)
        .copy_from(&(truth.velocity - est.velocity));
    e.fixed_rows_mut::<3>(6)
        .copy_from(&(truth.position - est.position));
    e.fixed_rows_mut::<3>(9)
        .copy_from(&(truth.gyro_bias - est.gyro_bias));
    e.fixed_rows_mut::<3>(12)
        .copy_from(&(truth.accel_bias - est.accel_bias));
    e
}

pub fn angle_deg(a: &So3<f64>, b: &So3<f64>) -> f64 {
    a.rminus(b).norm().to_degrees()
}

pub fn cast3(v: &Vector3<f64>) -> Vector3<f32> {
    v.map(|x| x as f32)
}

pub fn cast_imu(s: &ImuSample<f64>) -> ImuSample<f32> {
    ImuSample {
        gyro: cast3(&s.gyro),
        accel: cast3(&s.accel),
        dt: s.dt as f32,
    }
}

pub fn to_f64_mat<const R: usize, const C: usize>(m: &SMatrix<f32, R, C>) -> SMatrix<f64, R, C> {
    m.map(|x| x as f64)
}

pub fn ins_state_f64(s: &InsState<f32>) -> InsState<f64> {
    InsState {
        attitude: s.attitude.cast::<f64>(),
        velocity: s.velocity.map(|x| x as f64),
        position: s.position.map(|x| x as f64),
        gyro_bias: s.gyro_bias.map(|x| x as f64),
        accel_bias: s.accel_bias.map(|x| x as f64),
    }
}

pub fn skew_check(m: &Matrix3<f64>) -> f64 {
    (m - m.transpose()).amax()
}

/// An IMU sample with only a gyro reading (what the attitude-only filter's prediction reads).
pub fn gyro_only<T: estimator_core::Real>(gyro: Vector3<T>, dt: T) -> ImuSample<T> {
    ImuSample {
        gyro,
        accel: Vector3::zeros(),
        dt,
    }
}

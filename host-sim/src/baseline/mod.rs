//! Reference attitude filters that users compare against, run on the same data as ours: Madgwick's
//! gradient-descent MARG filter and Mahony's explicit complementary filter, both on SO(3) with the
//! crate's right perturbation `R ← R·exp(ω dt)` and the dataset's own magnetic reference.
//!
//! With `u = [0, 0, 1]` (world up, what an accelerometer at rest reads) and `m_w` the reference
//! field, both compare the predictions `Rᵀu`, `Rᵀm̂_w` with the normalized measurements `a`, `m`:
//!
//! * Madgwick (2010/2011): the gradient of `½‖f‖²`, `f = [Rᵀu − a; Rᵀm̂_w − m]`, with respect to
//!   the right perturbation is `∇ = [Rᵀu]×ᵀ(Rᵀu − a) + [Rᵀm̂_w]×ᵀ(Rᵀm̂_w − m)`; the rate used is
//!   `ω − β ∇/‖∇‖`. No gyro-bias estimate (the basic filter), `β = 0.1` (the commonly used value).
//! * Mahony (2008): error `e = a × Rᵀu + m × Rᵀm̂_w`, rate `ω − b̂ + K_p e`, bias `ḃ = −K_i e`,
//!   `K_p = 1`, `K_i = 0.05` (typical values).
//!
//! Both start from the same alignment as our filter. They are here to be measured against, not
//! to be tuned per scenario.

use estimator_core::lie::{skew, LieGroup, So3};
use nalgebra::Vector3;

/// Madgwick's MARG filter.
#[derive(Clone, Debug)]
pub struct Madgwick {
    /// `world_from_body`.
    pub attitude: So3<f64>,
    /// Gain β, rad/s.
    pub beta: f64,
    directions: Directions,
}

/// Mahony's complementary filter.
#[derive(Clone, Debug)]
pub struct Mahony {
    /// `world_from_body`.
    pub attitude: So3<f64>,
    /// Gyro bias estimate, rad/s.
    pub bias: Vector3<f64>,
    /// Proportional gain.
    pub kp: f64,
    /// Integral gain.
    pub ki: f64,
    directions: Directions,
}

/// The unit directions both filters compare: the latest accelerometer and magnetometer samples
/// (body frame) against world up and the magnetic reference.
#[derive(Clone, Debug)]
struct Directions {
    accel: Vector3<f64>,
    mag: Option<Vector3<f64>>,
    reference: Option<Vector3<f64>>,
}

impl Directions {
    fn new(reference: &Vector3<f64>) -> Self {
        Self {
            accel: Vector3::z(),
            mag: None,
            reference: unit(reference),
        }
    }

    fn record_accel(&mut self, a: &Vector3<f64>) {
        if let Some(a) = unit(a) {
            self.accel = a;
        }
    }

    /// `(measured, predicted)` pairs in the body frame: `(a, Rᵀu)` and, with a magnetometer
    /// sample, `(m, Rᵀm̂_w)`.
    fn pairs(&self, attitude: &So3<f64>) -> impl Iterator<Item = (Vector3<f64>, Vector3<f64>)> {
        let r_inv = attitude.inverse();
        let mag = match (self.mag, self.reference) {
            (Some(m), Some(mw)) => Some((m, r_inv.act(&mw))),
            _ => None,
        };
        std::iter::once((self.accel, r_inv.act(&Vector3::z()))).chain(mag)
    }
}

fn unit(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n > 0.0 && n.is_finite()).then(|| v / n)
}

impl Madgwick {
    /// Starts at `attitude` with the magnetic reference `reference` (world frame).
    #[must_use]
    pub fn new(attitude: So3<f64>, reference: Vector3<f64>) -> Self {
        Self {
            attitude,
            beta: 0.1,
            directions: Directions::new(&reference),
        }
    }

    /// Records the latest magnetometer sample.
    pub fn mag(&mut self, m: &Vector3<f64>) {
        self.directions.mag = unit(m);
    }

    /// One IMU step.
    pub fn imu(&mut self, gyro: &Vector3<f64>, accel: &Vector3<f64>, dt: f64) {
        self.directions.record_accel(accel);
        let grad = self
            .directions
            .pairs(&self.attitude)
            .fold(Vector3::zeros(), |g, (meas, pred)| {
                g + skew(&pred).transpose() * (pred - meas)
            });
        let n = grad.norm();
        let corr = if n > 0.0 {
            grad * (self.beta / n)
        } else {
            Vector3::zeros()
        };
        // ∇ is the gradient along +δθ; descending it means subtracting.
        self.attitude = self.attitude.rplus(&((gyro - corr) * dt)).normalize();
    }
}

impl Mahony {
    /// Starts at `attitude` with the magnetic reference `reference` (world frame).
    #[must_use]
    pub fn new(attitude: So3<f64>, reference: Vector3<f64>) -> Self {
        Self {
            attitude,
            bias: Vector3::zeros(),
            kp: 1.0,
            ki: 0.05,
            directions: Directions::new(&reference),
        }
    }

    /// Records the latest magnetometer sample.
    pub fn mag(&mut self, m: &Vector3<f64>) {
        self.directions.mag = unit(m);
    }

    /// One IMU step.
    pub fn imu(&mut self, gyro: &Vector3<f64>, accel: &Vector3<f64>, dt: f64) {
        self.directions.record_accel(accel);
        let e = self
            .directions
            .pairs(&self.attitude)
            .fold(Vector3::zeros(), |e, (meas, pred)| e + meas.cross(&pred));
        self.bias -= e * (self.ki * dt);
        self.attitude = self
            .attitude
            .rplus(&((gyro - self.bias + e * self.kp) * dt))
            .normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// From a 20° error at rest, both filters converge to the truth.
    #[test]
    fn both_converge_at_rest() {
        let truth = So3::exp(&Vector3::new(0.1, -0.2, 0.7));
        let start = truth.rplus(&Vector3::new(0.2, 0.15, -0.2));
        let mref = Vector3::new(0.0, 24.0, -41.6);
        let a = truth.inverse().act(&Vector3::new(0.0, 0.0, 9.81));
        let m = truth.inverse().act(&mref);
        let mut mw = Madgwick::new(start, mref);
        let mut mh = Mahony::new(start, mref);
        // 60 s: Mahony's bias integrator (K_p/K_i = 20 s) sets the slower time constant.
        for _ in 0..12000 {
            mw.mag(&m);
            mh.mag(&m);
            mw.imu(&Vector3::zeros(), &a, 0.005);
            mh.imu(&Vector3::zeros(), &a, 0.005);
        }
        assert!(
            mw.attitude.rminus(&truth).norm() < 0.01,
            "madgwick {}",
            mw.attitude.rminus(&truth).norm()
        );
        assert!(
            mh.attitude.rminus(&truth).norm() < 0.01,
            "mahony {}",
            mh.attitude.rminus(&truth).norm()
        );
    }
}

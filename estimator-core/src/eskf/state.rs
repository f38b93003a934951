//! Nominal states and their `⊕`.

use super::config::{FilterConfig, ImuSample};
use super::error::EskfError;
use crate::kernels::all_finite;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{SVector, Vector3};

/// A nominal state with an `N`-dimensional error state whose first three components are the
/// right attitude error `δθ` (`R = R̂·exp(δθ^)`, the right `⊕` of *Lie Groups and Smooth
/// Manifolds for Robotic State Estimation*, eq. 4.5: `a ⊕ τ = a·exp(τ^)`) and whose other
/// components are additive (`x = x̂ + δx`).
///
/// Sealed: implemented by [`InsState`] (`N = 15`), [`AhrsState`] (`N = 6`) and
/// [`AhrsAccelBiasState`] (`N = 12`).
pub trait ErrorState<T: Real, const N: usize>: Copy + sealed::Sealed<T, N> {
    /// `x ⊕ δx`: `R ← R·exp(δθ^)`, every other block `+ δ`.
    #[must_use]
    fn oplus(&self, dx: &SVector<T, N>) -> Self;

    /// `true` when every stored number is finite.
    #[must_use]
    fn is_finite(&self) -> bool;

    /// The attitude `R` (world from body).
    #[must_use]
    fn attitude(&self) -> &So3<T>;
}

pub(crate) mod sealed {
    use super::{EskfError, FilterConfig, ImuSample};
    use crate::Real;
    use nalgebra::SMatrix;

    /// Seals [`ErrorState`](super::ErrorState), and carries the prediction step of each state,
    /// which only the filter calls.
    pub trait Sealed<T: Real, const N: usize> {
        /// Propagates the state and its error covariance `P` over one IMU sample (the
        /// prediction; equations in the [`crate::eskf`] module docs). Writes `self` and `p` only
        /// on `Ok`.
        fn propagate(
            &mut self,
            p: &mut SMatrix<T, N, N>,
            imu: &ImuSample<T>,
            config: &FilterConfig<T>,
        ) -> Result<(), EskfError>;
    }
}

/// The 15-state inertial nominal state `x = (R, v, p, b_g, b_a)`.
///
/// Error state `δx = (δθ, δv, δp, δb_g, δb_a) ∈ R¹⁵` (indices 0–2, 3–5, 6–8, 9–11, 12–14):
/// `R = R̂·exp(δθ^)`, `v = v̂ + δv`, `p = p̂ + δp`, `b_g = b̂_g + δb_g`, `b_a = b̂_a + δb_a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsState<T: Real> {
    /// `R`: world from body (the body-to-world rotation).
    pub attitude: So3<T>,
    /// `v`: velocity in the world frame, m/s.
    pub velocity: Vector3<T>,
    /// `p`: position in the world frame, m.
    pub position: Vector3<T>,
    /// `b_g`: gyroscope bias (body frame), rad/s; `ω = ω_m − b_g`.
    pub gyro_bias: Vector3<T>,
    /// `b_a`: accelerometer bias (body frame), m/s²; `f = f_m − b_a`.
    pub accel_bias: Vector3<T>,
}

impl<T: Real> InsState<T> {
    /// At the origin, at rest, level, with zero biases.
    #[must_use]
    pub fn identity() -> Self {
        Self {
            attitude: So3::identity(),
            velocity: Vector3::zeros(),
            position: Vector3::zeros(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
        }
    }
}

/// The attitude-only nominal state `x = (R, b_g)`, error `δx = (δθ, δb_g) ∈ R⁶`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AhrsState<T: Real> {
    /// `R`: world from body.
    pub attitude: So3<T>,
    /// `b_g`: gyroscope bias (body frame), rad/s.
    pub gyro_bias: Vector3<T>,
}

impl<T: Real> AhrsState<T> {
    /// Level, zero bias.
    #[must_use]
    pub fn identity() -> Self {
        Self {
            attitude: So3::identity(),
            gyro_bias: Vector3::zeros(),
        }
    }
}

/// The attitude nominal state with both IMU biases and the body's velocity,
/// `x = (R, b_g, b_a, v)`, `δx = (δθ, δb_g, δb_a, δv) ∈ R¹²` (indices 0–2, 3–5, 6–8, 9–11): an
/// AHRS that also estimates the accelerometer bias, which the accelerometer's readings in
/// different orientations separate from the tilt, and carries the velocity the specific force
/// integrates to, so that a bound on the body's velocity
/// ([`ZeroVelocity`](super::ZeroVelocity) with the velocity's spread as its noise) measures the
/// tilt the way an INS's velocity aid does.
///
/// The velocity moves only by [`AhrsAccelBias::integrate_velocity`](super::AhrsAccelBias::integrate_velocity),
/// once per block of samples whose specific force the caller has summed in the world frame;
/// [`predict`](super::Filter::predict) turns the attitude and leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AhrsAccelBiasState<T: Real> {
    /// `R`: world from body.
    pub attitude: So3<T>,
    /// `b_g`: gyroscope bias (body frame), rad/s.
    pub gyro_bias: Vector3<T>,
    /// `b_a`: accelerometer bias (body frame), m/s²; `f = f_m − b_a`.
    pub accel_bias: Vector3<T>,
    /// `v`: velocity in the world frame, m/s.
    pub velocity: Vector3<T>,
}

impl<T: Real> AhrsAccelBiasState<T> {
    /// Level, at rest, zero biases.
    #[must_use]
    pub fn identity() -> Self {
        Self {
            attitude: So3::identity(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
            velocity: Vector3::zeros(),
        }
    }
}

impl<T: Real> ErrorState<T, 12> for AhrsAccelBiasState<T> {
    fn oplus(&self, dx: &SVector<T, 12>) -> Self {
        Self {
            attitude: self.attitude.rplus(&segment(dx, 0)).normalize(),
            gyro_bias: self.gyro_bias + segment(dx, 3),
            accel_bias: self.accel_bias + segment(dx, 6),
            velocity: self.velocity + segment(dx, 9),
        }
    }

    fn is_finite(&self) -> bool {
        let vectors = [
            self.gyro_bias.data.0,
            self.accel_bias.data.0,
            self.velocity.data.0,
        ];
        self.attitude.is_finite() && all_finite(vectors.as_flattened().as_flattened())
    }

    fn attitude(&self) -> &So3<T> {
        &self.attitude
    }
}

/// Entries `k..k + 3` of `dx` (zero past the end, which no caller reaches).
fn segment<T: Real, const N: usize>(dx: &SVector<T, N>, k: usize) -> Vector3<T> {
    match dx.as_slice().get(k..k + 3) {
        Some(&[a, b, c]) => Vector3::new(a, b, c),
        _ => Vector3::zeros(),
    }
}

impl<T: Real> ErrorState<T, 15> for InsState<T> {
    fn oplus(&self, dx: &SVector<T, 15>) -> Self {
        Self {
            attitude: self.attitude.rplus(&segment(dx, 0)).normalize(),
            velocity: self.velocity + segment(dx, 3),
            position: self.position + segment(dx, 6),
            gyro_bias: self.gyro_bias + segment(dx, 9),
            accel_bias: self.accel_bias + segment(dx, 12),
        }
    }

    fn is_finite(&self) -> bool {
        // The four vectors side by side: one check.
        let vectors = [
            self.velocity.data.0,
            self.position.data.0,
            self.gyro_bias.data.0,
            self.accel_bias.data.0,
        ];
        self.attitude.is_finite() && all_finite(vectors.as_flattened().as_flattened())
    }

    fn attitude(&self) -> &So3<T> {
        &self.attitude
    }
}

impl<T: Real> ErrorState<T, 6> for AhrsState<T> {
    fn oplus(&self, dx: &SVector<T, 6>) -> Self {
        Self {
            attitude: self.attitude.rplus(&segment(dx, 0)).normalize(),
            gyro_bias: self.gyro_bias + segment(dx, 3),
        }
    }

    fn is_finite(&self) -> bool {
        self.attitude.is_finite() && all_finite(self.gyro_bias.as_slice())
    }

    fn attitude(&self) -> &So3<T> {
        &self.attitude
    }
}

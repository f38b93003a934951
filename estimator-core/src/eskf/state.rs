//! Nominal states, their `⊕`, and the traits the generic update works on.

use super::imu::finite_vec;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3x4, SVector, Vector3};

/// A nominal state with an `N`-dimensional error state whose first three components are the
/// right attitude error `δθ` (`R = R̂·exp(δθ^)`, seed eq. 4.5) and whose other components are
/// additive (`x = x̂ + δx`).
pub trait ErrorState<T: Real, const N: usize>: Copy + sealed::Sealed {
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
    pub trait Sealed {}
    impl<T: crate::Real> Sealed for super::InsState<T> {}
    impl<T: crate::Real> Sealed for super::AhrsState<T> {}
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

impl<T: Real> ErrorState<T, 15> for InsState<T> {
    fn oplus(&self, dx: &SVector<T, 15>) -> Self {
        Self {
            attitude: self.attitude.rplus(&seg(dx, 0)).normalize(),
            velocity: plus_seg(&self.velocity, dx, 3),
            position: plus_seg(&self.position, dx, 6),
            gyro_bias: plus_seg(&self.gyro_bias, dx, 9),
            accel_bias: plus_seg(&self.accel_bias, dx, 12),
        }
    }

    fn is_finite(&self) -> bool {
        // The four vectors side by side: one check (see `finite_vec`).
        self.attitude.is_finite()
            && finite_vec(&Matrix3x4::from_columns(&[
                self.velocity,
                self.position,
                self.gyro_bias,
                self.accel_bias,
            ]))
    }

    fn attitude(&self) -> &So3<T> {
        &self.attitude
    }
}

/// Entries `k..k + 3` of `dx` (zero past the end, which no caller reaches): read from the
/// storage, without nalgebra's generic row view.
pub(crate) fn seg<T: Real, const N: usize>(dx: &SVector<T, N>, k: usize) -> Vector3<T> {
    match dx.as_slice().get(k..k + 3) {
        Some(&[a, b, c]) => Vector3::new(a, b, c),
        _ => Vector3::zeros(),
    }
}

/// `v + dx[k..k + 3]`, entry by entry (the same sums as `v + dx.fixed_rows::<3>(k)`): the
/// segment read here, the sum by the shared out-of-line [`add3`](super::models::add3) (one
/// copy for both states).
#[inline(always)]
pub(crate) fn plus_seg<T: Real, const N: usize>(
    v: &Vector3<T>,
    dx: &SVector<T, N>,
    k: usize,
) -> Vector3<T> {
    super::models::add3(v, &seg(dx, k))
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

impl<T: Real> ErrorState<T, 6> for AhrsState<T> {
    fn oplus(&self, dx: &SVector<T, 6>) -> Self {
        Self {
            attitude: self.attitude.rplus(&seg(dx, 0)).normalize(),
            gyro_bias: plus_seg(&self.gyro_bias, dx, 3),
        }
    }

    fn is_finite(&self) -> bool {
        self.attitude.is_finite() && finite_vec(&self.gyro_bias)
    }

    fn attitude(&self) -> &So3<T> {
        &self.attitude
    }
}

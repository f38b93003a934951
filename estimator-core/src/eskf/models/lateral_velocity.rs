//! The lateral velocity of a vehicle that does not move sideways (a car, a rover).

use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::mat3;
use crate::Real;
use nalgebra::{Matrix1, SMatrix, Vector1};

/// The body's lateral velocity is zero: `z = 0`, `h(x) = e₂ᵀ Rᵀ v` (the velocity along the body
/// `y` axis), with noise `σ²` for what the vehicle does slide or crab.
///
/// With `w = R̂ᵀ v̂` and `Rᵀ v ≈ w + [w]× δθ + R̂ᵀ δv` (body-frame attitude error,
/// `R = R̂ Exp(δθ)`), the row is `e₂ᵀ [w]× = (e₂ × w)ᵀ = (w_z, 0, −w_x)` on the attitude and
/// `e₂ᵀ R̂ᵀ = (R̂₁₂, R̂₂₂, R̂₃₂)` on the velocity. It observes the heading at any speed, as
/// `σ / ‖v‖` for a body moving along its `x` axis — but only up to 180°: a body moving
/// backwards satisfies it as well.
///
/// ```
/// use estimator_core::eskf::{FilterConfig, Ins, InsState, LateralVelocity, UpdateOptions};
/// use estimator_core::lie::{LieGroup, So3};
/// use nalgebra::{SMatrix, Vector3};
///
/// // Driving east at 2 m/s with the heading 3° off: the constraint turns it back.
/// let mut state = InsState::<f64>::identity();
/// state.velocity = Vector3::new(2.0, 0.0, 0.0);
/// state.attitude = So3::exp(&Vector3::new(0.0, 0.0, 3f64.to_radians()));
/// let mut p = SMatrix::<f64, 15, 15>::identity() * 1e-6;
/// p[(2, 2)] = 0.1; // heading σ ≈ 18°
/// let mut ins = Ins::new(state, p, FilterConfig::default()).unwrap();
/// ins.update(&LateralVelocity::new(0.01), &UpdateOptions::default()).unwrap();
/// let r = ins.state().attitude.rotation_matrix();
/// assert!(r[(1, 0)].atan2(r[(0, 0)]).abs() < 0.1f64.to_radians());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LateralVelocity<T: Real> {
    /// `R = σ²`, (m/s)².
    pub noise: Matrix1<T>,
}

impl<T: Real> LateralVelocity<T> {
    /// Noise `σ²`, `sigma` in m/s.
    #[must_use]
    pub fn new(sigma: T) -> Self {
        Self {
            noise: Matrix1::new(sigma * sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 1> for LateralVelocity<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 1>, EskfError> {
        let r = x.attitude.rotation_matrix();
        let w = mat3::mul_vec(&r.transpose(), &x.velocity);
        let mut jacobian = SMatrix::<T, 1, 15>::zeros();
        let row = [w.z, T::zero(), -w.x, r.m12, r.m22, r.m32];
        for (d, s) in jacobian.iter_mut().zip(row) {
            *d = s;
        }
        Ok(Linearization {
            residual: Vector1::new(-w.y),
            jacobian,
        })
    }

    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

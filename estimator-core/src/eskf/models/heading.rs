//! Heading (yaw) of the body `x` axis, from a compass or a dual-antenna GNSS.

use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::eskf::update::{Linearization, Measurement};
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix1, SMatrix, Vector1};

/// Heading (yaw about world `z`) of the body `x` axis: `h(x) = ψ = atan2(R₂₁, R₁₁)`.
///
/// With `R e₁ = (c_x, c_y, ·)` and `∂(R e₁)/∂δθ = −R[e₁]× = [0, −R e₃, R e₂]` (columns), the
/// row `H = (c_x ∂c_y − c_y ∂c_x)/(c_x² + c_y²)` is
/// `(0, c_y R₁₃ − c_x R₂₃, c_x R₂₂ − c_y R₁₂)/(c_x² + c_y²)` on the attitude columns; the
/// residual is wrapped to `(−π, π]`. Singular (an error) when the body `x` axis is vertical
/// (`c_x² + c_y² ≤ 10⁻⁶`). For both filters.
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, Heading, UpdateOptions};
/// use nalgebra::SMatrix;
///
/// let mut ahrs = Ahrs::new(AhrsState::identity(), SMatrix::identity() * 0.01, FilterConfig::<f64>::default()).unwrap();
/// ahrs.update(&Heading::new(0.05, 0.01), &UpdateOptions::default()).unwrap();
/// let (_, _, yaw) = ahrs.state().attitude.quaternion().euler_angles();
/// assert!((yaw - 0.05).abs() < 0.01);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heading<T: Real> {
    /// Measured yaw, rad (counter-clockwise from world `x` = east).
    pub yaw: T,
    /// `R = σ²`, rad².
    pub noise: Matrix1<T>,
}

impl<T: Real> Heading<T> {
    /// Noise `σ²`.
    #[must_use]
    pub fn new(yaw: T, sigma: T) -> Self {
        Self {
            yaw,
            noise: Matrix1::new(sigma * sigma),
        }
    }
}

impl<T: Real> Heading<T> {
    /// The wrapped residual and the attitude row (entries 1 and 2; entry 0 is zero): the part
    /// that does not depend on the filter.
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(T, [T; 2]), EskfError> {
        if !self.yaw.is_finite() {
            return Err(EskfError::NonFinite);
        }
        let r = attitude.rotation_matrix();
        let (cx, cy) = (r.m11, r.m21);
        let n2 = cx * cx + cy * cy;
        // False for NaN too.
        let away_from_vertical = n2 > T::lit(1e-6);
        if !away_from_vertical {
            return Err(EskfError::SingularGeometry);
        }
        let row = [
            (cy * r.m13 - cx * r.m23) / n2,
            (cx * r.m22 - cy * r.m12) / n2,
        ];
        let (s, c) = (self.yaw - cy.arctan2(cx)).sincos();
        Ok((s.arctan2(c), row))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 1> for Heading<T> {
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 1>, EskfError> {
        let (residual, row) = self.attitude_parts(x.attitude())?;
        let mut jacobian = SMatrix::<T, 1, N>::zeros();
        for (d, s) in jacobian.iter_mut().skip(1).zip(row) {
            *d = s;
        }
        Ok(Linearization {
            residual: Vector1::new(residual),
            jacobian,
        })
    }

    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

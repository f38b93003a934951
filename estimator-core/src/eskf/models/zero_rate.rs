//! The gyroscope of a body known to be at rest: it reads its own bias.

use super::shared::{isotropic, three_rows};
use crate::eskf::error::EskfError;
use crate::eskf::state::{AhrsAccelBiasState, AhrsState, InsState};
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::all_finite;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// Zero-rate update: at rest the true rate is zero, so the measured rate is the bias,
/// `z = ω_m`, `h(x) = b_g`, `H = [0, I]` on the gyro-bias columns (3–5 of [`Ahrs`](crate::eskf::Ahrs),
/// 9–11 of [`Ins`](crate::eskf::Ins)).
///
/// Averaging `n` samples of white noise with density `σ_g` at rate `f` gives `σ² = σ_g² f / n`
/// per axis; a body only nearly at rest needs a floor on `σ` for its remaining rate.
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, UpdateOptions, ZeroRate};
/// use nalgebra::{SMatrix, Vector3};
///
/// let mut ahrs = Ahrs::new(AhrsState::identity(), SMatrix::identity() * 1e-4, FilterConfig::<f64>::default()).unwrap();
/// // At rest the gyro reads 0.002 rad/s about z: that is its bias.
/// ahrs.update(&ZeroRate::new(Vector3::new(0.0, 0.0, 0.002), 1e-4), &UpdateOptions::default()).unwrap();
/// assert!((ahrs.state().gyro_bias.z - 0.002).abs() < 1e-4);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZeroRate<T: Real> {
    /// Measured angular rate at rest (body frame), rad/s.
    pub rate: Vector3<T>,
    /// `R`, (rad/s)².
    pub noise: Matrix3<T>,
}

impl<T: Real> ZeroRate<T> {
    /// Isotropic noise `σ² I` (σ in rad/s).
    #[must_use]
    pub fn new(rate: Vector3<T>, sigma: T) -> Self {
        Self {
            rate,
            noise: isotropic(sigma),
        }
    }

    /// `z − b̂_g` and `H` with the identity at `column`.
    fn linearization<const N: usize>(
        &self,
        bias: &Vector3<T>,
        column: usize,
    ) -> Result<Linearization<T, N, 3>, EskfError> {
        if !all_finite(self.rate.as_slice()) {
            return Err(EskfError::NonFinite);
        }
        Ok(three_rows(self.rate - bias, &[], &[column]))
    }
}

impl<T: Real> Measurement<T, AhrsState<T>, 6, 3> for ZeroRate<T> {
    fn linearize(&self, x: &AhrsState<T>) -> Result<Linearization<T, 6, 3>, EskfError> {
        self.linearization(&x.gyro_bias, 3)
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for ZeroRate<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        self.linearization(&x.gyro_bias, 9)
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

impl<T: Real> Measurement<T, AhrsAccelBiasState<T>, 12, 3> for ZeroRate<T> {
    fn linearize(&self, x: &AhrsAccelBiasState<T>) -> Result<Linearization<T, 12, 3>, EskfError> {
        self.linearization(&x.gyro_bias, 3)
    }

    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

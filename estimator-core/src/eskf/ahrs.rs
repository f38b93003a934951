//! The attitude-only filter (AHRS).

use super::align::{prior_attitude_covariance, Alignment, InitialSigmas};
use super::error::{EskfError, UpdateOutcome};
use super::imu::{add_diag, predict_ahrs, set_blk, FilterConfig};
use super::state::AhrsState;
use super::update::{check_start, update, Measurement, UpdateOptions};
use crate::Real;
use nalgebra::{SMatrix, SVector, Vector3};

/// The on-manifold error-state filter for `x = (R, b_g)`, `δx = (δθ, δb_g) ∈ R⁶`, aided by
/// [`super::GravityDirection`], [`super::Magnetometer`] and [`super::Heading`].
///
/// Same guarantees as [`super::Ins`]: errors and gated-out measurements leave it unchanged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ahrs<T: Real> {
    state: AhrsState<T>,
    covariance: SMatrix<T, 6, 6>,
    config: FilterConfig<T>,
}

impl<T: Real> Ahrs<T> {
    /// From a given state and covariance (validated as for [`super::Ins::new`]). Only the gyro
    /// fields of `config.imu_noise` are used.
    pub fn new(
        state: AhrsState<T>,
        covariance: SMatrix<T, 6, 6>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        check_start(&state, &covariance, &config)?;
        Ok(Self {
            state,
            covariance,
            config,
        })
    }

    /// From a static [`Alignment`], with `sigmas.tilt`, `sigmas.yaw`, `sigmas.gyro_bias`.
    pub fn from_alignment(
        alignment: &Alignment<T>,
        sigmas: &InitialSigmas<T>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        config.validate()?;
        let mut p = SMatrix::<T, 6, 6>::zeros();
        // Read inside the `Result`, not moved out of it by `?` (no copy at opt-level "s").
        let att = prior_attitude_covariance(alignment, sigmas, &config);
        let att = match &att {
            Ok(att) => att,
            Err(e) => return Err(*e),
        };
        set_blk(&mut p, 0, 0, att);
        add_diag(&mut p, 1, sigmas.gyro_bias * sigmas.gyro_bias);
        Self::new(
            AhrsState {
                attitude: alignment.attitude,
                gyro_bias: alignment.gyro_bias,
            },
            p,
            config,
        )
    }

    /// The nominal state.
    #[must_use]
    pub fn state(&self) -> &AhrsState<T> {
        &self.state
    }

    /// The error-state covariance `P` (6 × 6).
    #[must_use]
    pub fn covariance(&self) -> &SMatrix<T, 6, 6> {
        &self.covariance
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &FilterConfig<T> {
        &self.config
    }

    /// `√diag(P)`.
    #[must_use]
    pub fn sigmas(&self) -> SVector<T, 6> {
        super::imu::sigmas(&self.covariance)
    }

    /// Propagates with one gyro sample: `R⁺ = R exp((ω_m − b_g) dt)`, `P⁺ = F P Fᵀ + Q`
    /// (module docs). Errors as [`super::Ins::predict`].
    pub fn predict(&mut self, gyro: &Vector3<T>, dt: T) -> Result<(), EskfError> {
        predict_ahrs(
            &mut self.state,
            &mut self.covariance,
            gyro,
            dt,
            &self.config,
        )
    }

    /// Fuses one measurement (see [`super::Ins::update`]).
    pub fn update<Mo, const M: usize>(
        &mut self,
        model: &Mo,
        options: &UpdateOptions<T>,
    ) -> Result<UpdateOutcome<T>, EskfError>
    where
        Mo: Measurement<T, AhrsState<T>, 6, M>,
    {
        update(&mut self.state, &mut self.covariance, model, options)
    }
}

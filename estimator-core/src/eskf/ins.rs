//! The 15-state inertial filter.

use super::align::{prior_attitude_covariance, Alignment, InitialSigmas};
use super::error::{EskfError, UpdateOutcome};
use super::imu::{add_diag, predict_ins, set_blk, FilterConfig, ImuSample};
use super::state::InsState;
use super::update::{check_start, update, Measurement, UpdateOptions};
use crate::Real;
use nalgebra::{SMatrix, SVector, Vector3};

/// The on-manifold error-state filter for `x = (R, v, p, b_g, b_a)`, `δx ∈ R¹⁵`.
///
/// Holds the nominal state, the full `15 × 15` covariance `P` and the configuration; no scratch
/// space (`size_of::<Ins<f32>>()` is 996 bytes). Every method that takes outside data returns a
/// `Result`; on `Err`, and on a gated-out measurement, the filter is unchanged bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ins<T: Real> {
    state: InsState<T>,
    covariance: SMatrix<T, 15, 15>,
    config: FilterConfig<T>,
}

impl<T: Real> Ins<T> {
    /// From a given state and covariance. Errors: non-finite state, `P` not symmetric positive
    /// definite, or an invalid configuration.
    pub fn new(
        state: InsState<T>,
        covariance: SMatrix<T, 15, 15>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        check_start(&state, &covariance, &config)?;
        Ok(Self {
            state,
            covariance,
            config,
        })
    }

    /// From a static [`Alignment`] at `position` (velocity zero, accelerometer bias zero), with
    /// the initial uncertainties `sigmas` (attitude covariance from
    /// [`InitialSigmas::attitude_covariance`]).
    pub fn from_alignment(
        alignment: &Alignment<T>,
        position: Vector3<T>,
        sigmas: &InitialSigmas<T>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        config.validate()?;
        let state = InsState {
            attitude: alignment.attitude,
            velocity: Vector3::zeros(),
            position,
            gyro_bias: alignment.gyro_bias,
            accel_bias: Vector3::zeros(),
        };
        let mut p = SMatrix::<T, 15, 15>::zeros();
        // Read inside the `Result`, not moved out of it by `?` (no copy at opt-level "s").
        let att = prior_attitude_covariance(alignment, sigmas, &config);
        let att = match &att {
            Ok(att) => att,
            Err(e) => return Err(*e),
        };
        set_blk(&mut p, 0, 0, att);
        let sq = |s: T| s * s;
        add_diag(&mut p, 1, sq(sigmas.velocity));
        add_diag(&mut p, 2, sq(sigmas.position));
        add_diag(&mut p, 3, sq(sigmas.gyro_bias));
        add_diag(&mut p, 4, sq(sigmas.accel_bias));
        Self::new(state, p, config)
    }

    /// The nominal state.
    #[must_use]
    pub fn state(&self) -> &InsState<T> {
        &self.state
    }

    /// The error-state covariance `P`.
    #[must_use]
    pub fn covariance(&self) -> &SMatrix<T, 15, 15> {
        &self.covariance
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &FilterConfig<T> {
        &self.config
    }

    /// `√diag(P)`, the 1-σ of each error-state component.
    #[must_use]
    pub fn sigmas(&self) -> SVector<T, 15> {
        super::imu::sigmas(&self.covariance)
    }

    /// Propagates with one IMU sample (module docs: nominal integration, `P⁺ = F P Fᵀ + Q`).
    ///
    /// Errors: [`EskfError::NonFinite`], [`EskfError::NonPositiveDt`], [`EskfError::DtTooLarge`].
    pub fn predict(&mut self, imu: &ImuSample<T>) -> Result<(), EskfError> {
        predict_ins(&mut self.state, &mut self.covariance, imu, &self.config)
    }

    /// Fuses one measurement with the generic update (gate, Joseph form, optional Gauss-Newton
    /// iterations, injection through `⊕`, reset). Returns the outcome with its NIS.
    pub fn update<Mo, const M: usize>(
        &mut self,
        model: &Mo,
        options: &UpdateOptions<T>,
    ) -> Result<UpdateOutcome<T>, EskfError>
    where
        Mo: Measurement<T, InsState<T>, 15, M>,
    {
        update(&mut self.state, &mut self.covariance, model, options)
    }
}

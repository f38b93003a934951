//! Rest detection, and the zero-rate update while at rest.
//!
//! A block is **still** when the RMS rate about the bias estimate and the RMS linear
//! acceleration are both small:
//!
//! ```text
//! s_ω² + ‖ω̄ − b̂_g‖² ≤ ω_rest²        s_f² + (‖f̄‖ − ‖g‖)² ≤ a_rest²
//! ```
//!
//! (`s²` the scatter about the block mean). The body is **at rest** once the still blocks in
//! a row have lasted `rest_min_s`; then the block's mean rate is a [`ZeroRate`] measurement of
//! the bias, with `σ² = N_g²/(n Δt) + σ_rest²` (`N_g` the gyro noise density, `n` samples of
//! interval `Δt`, `σ_rest` the floor for a body only nearly at rest).

use super::block::BlockStats;
use super::config::AttitudeConfig;
use super::report::Fusion;
use crate::eskf::{AhrsAccelBias, UpdateOptions, ZeroRate};
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// `true` for a still block (module docs).
pub(super) fn is_still<T: Real>(
    stats: &BlockStats<T>,
    bias: &Vector3<T>,
    config: &AttitudeConfig<T>,
    g: T,
) -> bool {
    let w = stats.gyro_mean - bias;
    let rate_sq = stats.gyro_scatter_sq + w.dot(&w);
    let vertical = stats.accel_norm - g;
    let accel_sq = stats.accel_scatter_sq + vertical * vertical;
    rate_sq <= config.rest_gyro * config.rest_gyro
        && accel_sq <= config.rest_accel * config.rest_accel
}

/// The variance of the mean rate of a still block, `N_g²/(n Δt) + σ_rest²`.
pub(super) fn mean_rate_variance<T: Real>(stats: &BlockStats<T>, config: &AttitudeConfig<T>) -> T {
    let density = config.filter.imu_noise.gyroscope_noise_density;
    let white = if stats.duration > T::zero() {
        density * density / stats.duration
    } else {
        T::zero()
    };
    white + config.rest_rate_sigma * config.rest_rate_sigma
}

/// The zero-rate update of a block at rest.
#[inline(never)] // its own stack frame, not the caller's
pub(super) fn fuse<T: Real>(
    filter: &mut AhrsAccelBias<T>,
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
) -> Result<Fusion<T>, NavError> {
    let sigma = mean_rate_variance(stats, config).sqrt_rn();
    let outcome = filter.update(
        &ZeroRate::new(stats.gyro_mean, sigma),
        &UpdateOptions::default(),
    )?;
    Ok(Fusion::from(outcome))
}

//! The accelerometer as a gravity sensor over a block, with a noise that follows the motion.
//!
//! The mean specific force of a block, seen in the body at its end (see `block`), is
//! `f̄ = Rᵀ(ā − g)`: gravity plus the block's mean linear acceleration `ā`. Its direction is a
//! [`GravityDirection`] measurement whose error is `ā⊥/‖g‖` (the part of `ā` across gravity)
//! plus the white noise. The variance per axis is taken as
//!
//! ```text
//! σ² = σ_s²/n  +  q·min(1, 2τ/T)  +  (‖f̄‖ − ‖g‖)²            (m/s²)², then / ‖g‖² for radians
//! ```
//!
//! * `σ_s² = N_a²/Δt`: the white noise of one sample (density `N_a`, interval `Δt`), `n`
//!   samples in the block;
//! * `q`: the variance per axis of the linear acceleration inside the block, from the scatter
//!   of the world-frame specific force beyond the white noise, `q = max(0, s² − 3σ_s²)/3`
//!   (the larger of this block's and the previous block's, so that a motion that starts at a
//!   block's end is not missed);
//! * `min(1, 2τ/T)`: the share of that variance left in the mean of a block of length `T`
//!   for an acceleration correlated over `τ` (a first-order Gauss–Markov process keeps
//!   `2τ/T` of its variance in a mean over `T ≫ τ`);
//! * `(‖f̄‖ − ‖g‖)²`: the vertical part of `ā`, which the norm shows directly, taken for the
//!   size of the horizontal part the norm cannot show.
//!
//! No threshold throws a block away: a block taken during strong motion simply weighs little.
//! The update is gated (chi-square, 99.9 %); when `max_rejected_blocks` blocks in a row fail
//! the gate, the estimate is what is wrong, not the data, and the tilt covariance is widened
//! by the innovation before the block is fused.
//!
//! The tilt is never known better than the accelerometer bias allows, `σ_ba/‖g‖`: after each
//! update the world-frame tilt variance is raised to that floor if it fell below it.

use super::block::BlockStats;
use super::config::AttitudeConfig;
use super::report::{Event, Fusion};
use crate::eskf::{Ahrs, GravityDirection, UpdateOptions};
use crate::kernels::mat3;
use crate::lie::LieGroup;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// The per-axis variance of the linear acceleration beyond the white noise in a block,
/// `q = max(0, s² − 3σ_s²)/3`, (m/s²)².
pub(super) fn acceleration_power<T: Real>(stats: &BlockStats<T>, white_sq: T) -> T {
    let excess = stats.accel_scatter_sq - T::lit(3.0) * white_sq;
    if excess > T::zero() {
        excess / T::lit(3.0)
    } else {
        T::zero()
    }
}

/// The white-noise variance of one accelerometer sample, `N_a²/Δt`, (m/s²)².
pub(super) fn white_sq<T: Real>(stats: &BlockStats<T>, config: &AttitudeConfig<T>) -> T {
    let density = config.filter.imu_noise.accelerometer_noise_density;
    let dt = stats.duration / T::from_count(stats.n.max(1));
    if dt > T::zero() {
        density * density / dt
    } else {
        T::zero()
    }
}

/// The 1σ of the block's gravity direction, rad (module docs), with `power` the per-axis
/// linear-acceleration variance to use.
pub(super) fn direction_sigma<T: Real>(
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
    power: T,
    g: T,
) -> T {
    let white = white_sq(stats, config) / T::from_count(stats.n.max(1));
    let two_tau = T::lit(2.0) * config.acceleration_correlation_s;
    let keep = if stats.duration > two_tau {
        two_tau / stats.duration
    } else {
        T::one()
    };
    let vertical = stats.accel_norm - g;
    let var = white + power * keep + vertical * vertical;
    var.sqrt() / g
}

/// The world-frame attitude covariance `R P_θθ Rᵀ` of the filter.
pub(super) fn world_attitude_covariance<T: Real>(filter: &Ahrs<T>) -> nalgebra::Matrix3<T> {
    let r = filter.state().attitude.rotation_matrix();
    let p = crate::kernels::block::block(filter.covariance(), 0, 0);
    mat3::mul(&mat3::mul(&r, &p), &r.transpose())
}

/// Fuses the block's gravity direction with 1σ `sigma`; widens the tilt after
/// `max_rejected_blocks` rejections in a row (`rejected` counts them); applies the tilt floor.
/// Returns the update's outcome (after the widening, if there was one), and the event if the
/// covariance was widened.
pub(super) fn fuse<T: Real>(
    filter: &mut Ahrs<T>,
    stats: &BlockStats<T>,
    sigma: T,
    config: &AttitudeConfig<T>,
    rejected: &mut u16,
) -> Result<(Fusion<T>, Option<Event>), NavError> {
    let model = GravityDirection::new(stats.accel_body, sigma);
    let options = UpdateOptions::default();
    let mut event = None;
    let mut fusion = Fusion::from(filter.update(&model, &options)?);
    if fusion.accepted {
        *rejected = 0;
    } else {
        *rejected = rejected.saturating_add(1);
        if *rejected >= config.max_rejected_blocks {
            // The innovation angle: between the measured and the predicted up direction.
            let up = -config.filter.gravity / mat3::norm(&config.filter.gravity);
            let predicted = filter.state().attitude.inverse().act(&up);
            let measured = stats.accel_body / stats.accel_norm;
            let angle = mat3::norm(&(measured - predicted));
            filter.widen_attitude(angle, T::zero())?;
            fusion = Fusion::from(filter.update(&model, &options)?);
            *rejected = 0;
            event = Some(Event::TiltWidened);
        }
    }
    let g = mat3::norm(&config.filter.gravity);
    let floor = config.accelerometer_bias_sigma / g;
    let w = world_attitude_covariance(filter);
    let smallest = if w.m11 < w.m22 { w.m11 } else { w.m22 };
    let deficit = floor * floor - smallest;
    if deficit > T::zero() {
        filter.widen_attitude(deficit.sqrt(), T::zero())?;
    }
    Ok((fusion, event))
}

/// `true` when `v` has a usable direction.
pub(super) fn has_direction<T: Real>(v: &Vector3<T>) -> bool {
    crate::kernels::positive_finite(mat3::norm(v))
}

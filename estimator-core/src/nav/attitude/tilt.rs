//! The accelerometer over a block, with a noise that follows the motion.
//!
//! The mean specific force of a block, seen in the body at its end (see `block`), is
//! `f̄ = Rᵀ(ā − g) + M b_a`: gravity, the block's mean linear acceleration `ā`, and the
//! accelerometer bias, which turned with the body during the block (`M = R̂ₑᵀ mean(R̂ᵢ)`, the
//! mean rotation from each sample to the end). It is an [`AccelerometerAtRest`] measurement
//! (`h(x) = Rᵀ(−g) + M b_a`)
//! whose noise is the mean linear acceleration plus the white noise, per axis
//!
//! ```text
//! σ² = σ_s²/n  +  max(q·min(1, 2τ/T), q_slow)  +  (‖f̄‖ − ‖g‖)²            (m/s²)²
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
//!   size of the horizontal part the norm cannot show;
//! * `q_slow`: the running mean of that vertical part's square over the last
//!   `motion_memory_s`: accelerations slower than a block (a body that speeds up for a second)
//!   leave no scatter inside a block, but they show in the vertical means of the blocks
//!   before, and a hand-held or worn body accelerates about as much across as along gravity.
//!
//! With `rotation_only` (a body that turns in place) only the white noise remains.
//!
//! No threshold throws a block away: a block taken during strong motion simply weighs little.
//! Because the bias is a state, blocks in different orientations separate it from the tilt
//! (a body-fixed bias turns with the body, gravity does not). The update is gated
//! (chi-square, 99.9 %); when `max_rejected_blocks` blocks in a row fail the gate, the
//! estimate is what is wrong, not the data, and the tilt covariance is widened by the
//! innovation angle before the block is fused.

use super::block::BlockStats;
use super::config::AttitudeConfig;
use super::report::{Event, Fusion};
use crate::eskf::{
    up_direction, AccelerometerAtRest, AhrsAccelBias, ErrorState, Filter, Gate, UpdateOptions,
};
use crate::kernels::mat3;
use crate::lie::LieGroup;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

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

/// The 1σ per axis of the block's mean specific force, m/s² (module docs), with `power` the
/// per-axis linear-acceleration variance inside the block and `slow` that of slow
/// accelerations.
pub(super) fn specific_force_sigma<T: Real>(
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
    power: T,
    slow: T,
    g: T,
) -> T {
    let white = white_sq(stats, config) / T::from_count(stats.n.max(1));
    if config.rotation_only {
        return white.sqrt_rn();
    }
    let two_tau = T::lit(2.0) * config.acceleration_correlation_s;
    let keep = if stats.duration > two_tau {
        two_tau / stats.duration
    } else {
        T::one()
    };
    let vertical = stats.accel_norm - g;
    let inside = power * keep;
    let motion = if inside > slow { inside } else { slow };
    (white + motion + vertical * vertical).sqrt_rn()
}

/// The running mean of `(‖f̄‖ − ‖g‖)²` over the last `motion_memory_s` (first order, weight
/// `min(1, T/τ_m)` per block).
pub(super) fn update_slow_power<T: Real>(
    slow: T,
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
    g: T,
) -> T {
    let vertical = stats.accel_norm - g;
    let w = stats.duration / config.motion_memory_s;
    let w = if w < T::one() { w } else { T::one() };
    slow + (vertical * vertical - slow) * w
}

/// The world-frame attitude covariance `R P_θθ Rᵀ` of a filter, its diagonal kept at the
/// block's resolution `16 ε tr P_θθ` or above: rotated in the scalar, a tilt variance far below
/// the heading's (which the filter's attitude floor keeps at that resolution) can come out a
/// little below zero, and its square root NaN.
pub(super) fn world_attitude_covariance<T: Real, S: ErrorState<T, N>, const N: usize>(
    filter: &Filter<T, S, N>,
) -> nalgebra::Matrix3<T> {
    let r = filter.state().attitude().rotation_matrix();
    let p = crate::kernels::block::block(filter.covariance(), 0, 0);
    let mut w = mat3::mul(&mat3::mul(&r, &p), &r.transpose());
    let resolution = (p.m11 + p.m22 + p.m33) * T::lit(16.0 * T::EPSILON_F64);
    w.m11 = crate::kernels::larger(w.m11, resolution);
    w.m22 = crate::kernels::larger(w.m22, resolution);
    w.m33 = crate::kernels::larger(w.m33, resolution);
    w
}

/// Fuses the block's mean specific force with 1σ `sigma` per axis; widens the tilt after
/// `max_rejected_blocks` rejections in a row (`rejected` counts them).
/// Returns the update's outcome (after the widening, if there was one), and the event if the
/// covariance was widened.
#[inline(never)] // its own stack frame, not the caller's
pub(super) fn fuse<T: Real>(
    filter: &mut AhrsAccelBias<T>,
    stats: &BlockStats<T>,
    sigma: T,
    config: &AttitudeConfig<T>,
    rejected: &mut u16,
) -> Result<(Fusion<T>, Option<Event>), NavError> {
    // The bias turned with the body during the block: the block sees `M b_a`.
    let model = AccelerometerAtRest {
        accel: stats.accel_body,
        gravity: config.filter.gravity,
        noise: Matrix3::from_diagonal_element(sigma * sigma),
        bias_map: stats.bias_map,
    };
    let options = UpdateOptions::default();
    let mut event = None;
    let mut fusion = Fusion::from(filter.update(&model, &options)?);
    if fusion.accepted {
        *rejected = 0;
    } else {
        *rejected = rejected.saturating_add(1);
        if *rejected >= config.max_rejected_blocks {
            // The innovation angle: between the measured (bias removed) and the predicted up
            // direction.
            let up = up_direction(&config.filter.gravity).unwrap_or_else(Vector3::zeros);
            let predicted = filter.state().attitude.inverse().act(&up);
            let f = stats.accel_body - filter.state().accel_bias;
            let angle = mat3::norm(&(f / mat3::norm(&f) - predicted));
            filter.widen_attitude(angle, T::zero())?;
            fusion = Fusion::from(filter.update(&model, &recovery_options())?);
            *rejected = 0;
            event = Some(Event::TiltWidened);
        }
    }
    Ok((fusion, event))
}

/// The update after a widening: ungated (the data were just found right and the estimate
/// wrong) and iterated (the error may be far beyond the linear range: a vector turned by `θ`
/// also changes along itself by `1 − cos θ`, which one linearization leaves in the residual).
pub(super) fn recovery_options<T: Real>() -> UpdateOptions<T> {
    UpdateOptions::iterated(Gate::Off, 5, T::lit(1e-6))
}

/// `true` when `v` has a usable direction.
pub(super) fn has_direction<T: Real>(v: &Vector3<T>) -> bool {
    crate::kernels::positive_finite(mat3::norm(v))
}

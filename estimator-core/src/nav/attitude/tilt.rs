//! Tilt from the accelerometer through a bound on the body's velocity.
//!
//! The filter carries the velocity `v` the specific force integrates to
//! ([`AhrsAccelBias::integrate_velocity`], once per block: `v⁺ = v + Σ R̂ᵢ(f_m,ᵢ − b_a)Δt + g T`).
//! A tilt error `δθ` turns gravity into a velocity error that grows as `g t δθ`, an
//! accelerometer bias into one that grows as `R̂ b_a t`; the body's own velocity, whatever it
//! does, stays bounded. So at each block's end the velocity is measured as zero
//! ([`ZeroVelocity`]) with the spread of the body's velocity as the noise, per axis
//!
//! ```text
//! moving:   σ_v² = max(σ_min², 4·⟨v̂²⟩)            at rest:  σ_v² = (a_rest T)²/12 + N_a² T
//! ```
//!
//! (with `rotation_only`, a body turning in place, the velocity is exactly zero: `σ_v²` is
//! `ε N_a² T`, positive only for the update, which raises it to its floor).
//!
//! * `σ_min` (`velocity_sigma`): the smallest spread assumed for a moving body;
//! * `⟨v̂²⟩`: the running mean of the estimated velocity's square on that axis over the last
//!   `motion_memory_s` (first order, weight `min(1, T/τ_m)` per block), so that a body that
//!   moves faster (walking, a vehicle) loosens its own bound: the factor 4 puts the mean
//!   square at 2σ, where the gate (99.9 %) still admits it;
//! * at rest (`rest`): a body whose RMS acceleration is below `a_rest` (`rest_accel`) drifts
//!   by at most `a_rest T` over a block of length `T`, taken as uniform (variance `/12`),
//!   plus the accelerometer's white noise integrated over the block (`N_a` its density).
//!
//! Why a velocity and not the block's mean specific force: the mean linear acceleration over
//! a window `W` is `(v_end − v_start)/W`. Fused block by block as independent noise, the
//! means of a moving body weigh little and a tilt error takes tens of seconds to correct;
//! their errors telescope, so the velocity state, which keeps the sum, corrects in a few
//! seconds what independent means would not (the mean over `W` has an error falling as `1/W`
//! for a bounded velocity, not as `1/√W`).
//!
//! The update is gated (chi-square, 99.9 %); when `max_rejected_blocks` blocks in a row fail
//! the gate, the estimate is what is wrong, not the data: the tilt covariance is widened by the
//! angle between the block's mean specific force and the predicted up direction, that mean
//! is fused (ungated, iterated) with the error a bounded velocity leaves in it
//! (`2σ_v²/T²` per axis: the mean linear acceleration over `T` is `Δv/T`), and the velocity,
//! which integrated the wrong tilt, starts again from the bound
//! ([`AhrsAccelBias::restart_velocity`]).

use super::block::BlockStats;
use super::config::AttitudeConfig;
use super::report::{Event, Fusion};
use crate::eskf::{
    up_direction, AccelerometerAtRest, AhrsAccelBias, ErrorState, Filter, Gate, UpdateOptions,
    ZeroVelocity,
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

/// The 1σ per axis of the start-up window's mean specific force, m/s²: the white noise, the
/// vertical part of the mean linear acceleration (`‖f̄‖ − ‖g‖`, which the norm shows and is
/// taken for the horizontal part too), and the motion inside the window, at most what a
/// velocity of spread `σ_min` allows over the window's length `W` (`2σ_min²/W²`: the mean
/// linear acceleration is `(v_end − v_start)/W`).
pub(super) fn startup_sigma<T: Real>(stats: &BlockStats<T>, config: &AttitudeConfig<T>, g: T) -> T {
    let sample = white_sq(stats, config);
    let white = sample / T::from_count(stats.n.max(1));
    if config.rotation_only {
        return white.sqrt_rn();
    }
    let power = acceleration_power(stats, sample);
    let w = stats.duration;
    let bound = T::lit(2.0) * config.velocity_sigma * config.velocity_sigma / (w * w);
    let inside = if power < bound { power } else { bound };
    let vertical = stats.accel_norm - g;
    (white + inside + vertical * vertical).sqrt_rn()
}

/// The variance per axis of the velocity bound of a block (module docs), (m/s)², with `spread`
/// the running mean of `v̂²` per axis.
pub(super) fn velocity_variance<T: Real>(
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
    spread: &Vector3<T>,
    at_rest: bool,
) -> Vector3<T> {
    let na = config.filter.imu_noise.accelerometer_noise_density;
    if config.rotation_only {
        // The velocity is exactly zero: the noise only has to be positive (the update raises it
        // to its floor, `256 N ε` of the predicted variance, where that is larger).
        return Vector3::repeat(na * na * stats.duration * T::lit(T::EPSILON_F64));
    }
    if at_rest {
        return Vector3::repeat(
            rest_drift_variance(config, stats.duration) + na * na * stats.duration,
        );
    }
    let floor = config.velocity_sigma * config.velocity_sigma;
    spread.map(|s| crate::kernels::larger(floor, T::lit(4.0) * s))
}

/// The variance per axis of a still body's velocity after `t` seconds, (m/s)²: a body whose RMS
/// acceleration is below `rest_accel` drifts by at most `a_rest t`, taken as uniform
/// (`(a_rest t)²/12`; module docs).
pub(super) fn rest_drift_variance<T: Real>(config: &AttitudeConfig<T>, t: T) -> T {
    let drift = config.rest_accel * t;
    drift * drift / T::lit(12.0)
}

/// The running mean of `v̂²` per axis over the last `motion_memory_s` (first order, weight
/// `min(1, T/τ_m)` per block).
pub(super) fn update_spread<T: Real>(
    spread: &Vector3<T>,
    velocity: &Vector3<T>,
    duration: T,
    config: &AttitudeConfig<T>,
) -> Vector3<T> {
    let w = duration / config.motion_memory_s;
    let w = if w < T::one() { w } else { T::one() };
    spread + (velocity.component_mul(velocity) - spread) * w
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

/// Fuses the velocity bound with the variance `variance` per axis; widens the tilt after
/// `max_rejected_blocks` rejections in a row (`rejected` counts them), by the angle between
/// the block's mean specific force (bias removed) and the predicted up direction.
/// Returns the update's outcome (after the widening, if there was one), and the event if the
/// covariance was widened.
#[inline(never)] // its own stack frame, not the caller's
pub(super) fn fuse<T: Real>(
    filter: &mut AhrsAccelBias<T>,
    stats: &BlockStats<T>,
    variance: &Vector3<T>,
    config: &AttitudeConfig<T>,
    rejected: &mut u16,
) -> Result<(Fusion<T>, Option<Event>), NavError> {
    let model = ZeroVelocity {
        noise: Matrix3::from_diagonal(variance),
    };
    let options = UpdateOptions::default();
    let mut event = None;
    let mut fusion = Fusion::from(filter.update(&model, &options)?);
    if fusion.accepted {
        *rejected = 0;
    } else {
        *rejected = rejected.saturating_add(1);
        if *rejected >= config.max_rejected_blocks {
            fusion = recover(filter, stats, variance, config)?;
            *rejected = 0;
            event = Some(Event::TiltWidened);
        }
    }
    Ok((fusion, event))
}

/// The recovery after `max_rejected_blocks` rejections (module docs): the tilt widened by the
/// innovation angle, the block's mean specific force fused with the error a bounded velocity
/// leaves in it, the velocity started again from the bound. Out of line: its models stay out
/// of the usual update's frame.
#[cold]
#[inline(never)]
fn recover<T: Real>(
    filter: &mut AhrsAccelBias<T>,
    stats: &BlockStats<T>,
    variance: &Vector3<T>,
    config: &AttitudeConfig<T>,
) -> Result<Fusion<T>, NavError> {
    // The innovation angle: between the block's mean specific force (bias removed) and the
    // predicted up direction.
    let up = up_direction(&config.filter.gravity).unwrap_or_else(Vector3::zeros);
    let predicted = filter.state().attitude.inverse().act(&up);
    let f = stats.accel_body - mat3::mul_vec(&stats.bias_map, &filter.state().accel_bias);
    let angle = mat3::norm(&(f / mat3::norm(&f) - predicted));
    filter.widen_attitude(angle, T::zero())?;
    // The velocity integrated the wrong tilt: it is no information. The block's mean specific
    // force measures the tilt again, with the error a bounded velocity leaves in a mean over
    // `T` (`Δv/T`, `Δv` of variance `2σ_v²`), and the velocity starts again from the bound.
    let larger = crate::kernels::larger;
    let spread = larger(variance.x, larger(variance.y, variance.z));
    let t = stats.duration;
    let model = AccelerometerAtRest {
        accel: stats.accel_body,
        gravity: config.filter.gravity,
        noise: Matrix3::from_diagonal_element(T::lit(2.0) * spread / (t * t)),
        bias_map: stats.bias_map,
    };
    let fusion = Fusion::from(filter.update(&model, &recovery_options())?);
    filter.restart_velocity(Vector3::zeros(), spread.sqrt_rn())?;
    Ok(fusion)
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

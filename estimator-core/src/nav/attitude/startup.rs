//! Start-up: the first attitude from the first window of samples, at rest or moving.
//!
//! The window is one long block (see `block`): its mean specific force and mean field are
//! seen in the body at its end, carried by the gyro, so a body that moves during the window
//! is aligned as well as one at rest; only the linear acceleration's mean stays in the tilt,
//! and the tilt model of `tilt` gives its 1σ. The velocity starts at zero, with the spread of a
//! moving body's velocity, or a still body's drift (`tilt`).
//!
//! * Tilt and heading: the triad of [`align_at_rest`] on the two means (the window's mean
//!   field against the reference; without a magnetometer the body `x` axis points to world
//!   `x` and the heading is unknown, 1σ = π).
//! * Accelerometer bias: zero, with `accelerometer_bias_sigma` (the tilt's 1σ includes it as
//!   `σ_ba/g`; the first blocks in other orientations separate the two).
//! * Gyro bias: a still window (see `rest`) measures it, `b = ω̄` with the zero-rate
//!   variance; a moving window leaves the prior (0 at switch-on, the last estimate after a
//!   gap) with `gyro_bias_sigma`.
//! * Heading 1σ: `σ_ψ² = σ_m²/(n ‖m_h‖²) + N_hd²/T + (tan δ · σ_tilt)²`, the last term because a
//!   tilt error `σ_tilt` moves the horizontal part of a field with dip `δ`.

use super::block::BlockStats;
use super::config::AttitudeConfig;
use super::magnetic::Magnetic;
use super::rest::{is_still, mean_rate_variance};
use super::tilt::{rest_drift_variance, startup_sigma};
use crate::eskf::{align_at_rest, Alignment, InitialSigmas, MagnetometerWindow};
use crate::kernels::mat3;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// The first attitude from a start-up window (module docs).
#[inline(never)] // its own stack frame, not the caller's
pub(super) fn start<T: Real>(
    stats: &BlockStats<T>,
    config: &AttitudeConfig<T>,
    bias_prior: &Vector3<T>,
    magnetic: &mut Option<Magnetic<T>>,
) -> Result<Start<T>, NavError> {
    let g = mat3::norm(&config.filter.gravity);
    let still = is_still(stats, bias_prior, config, g);
    let (gyro_bias, bias_sigma) = if still {
        (stats.gyro_mean, mean_rate_variance(stats, config).sqrt_rn())
    } else {
        (*bias_prior, config.gyro_bias_sigma)
    };
    // The mean specific force's error per axis: the motion's and the bias's, as an angle.
    let motion = startup_sigma(stats, config, g);
    let bias = config.accelerometer_bias_sigma;
    let tilt = (motion * motion + bias * bias).sqrt_rn() / g;

    let up_body = stats.accel_body / stats.accel_norm;
    // The field and its reference, when both exist (a missing reference is learned here).
    let field = match (magnetic.as_mut(), config.magnetometer.as_ref(), stats.mag) {
        (Some(state), Some(mag), Some(ms)) => {
            let (m, n) = (ms.body, ms.n);
            let vertical = m.dot(&up_body);
            let reference = *state.reference.get_or_insert_with(|| {
                let h = mat3::norm(&(m - up_body * vertical));
                Vector3::new(T::zero(), h, vertical)
            });
            Some((m, n, reference, mag))
        }
        _ => None,
    };
    let window;
    let mag_window = match &field {
        Some((m, _, reference, _)) => {
            window = [*m];
            Some(MagnetometerWindow {
                samples: &window,
                reference: *reference,
            })
        }
        None => None,
    };
    let alignment = align_at_rest(
        &[stats.accel_body],
        &[gyro_bias],
        &config.filter.gravity,
        mag_window.as_ref(),
        g,
    )?;
    let yaw = match &field {
        Some((m, n, reference, mag)) => {
            let vertical = m.dot(&up_body);
            let horizontal = mat3::norm(&(m - up_body * vertical));
            let white = mag.sigma / horizontal;
            let tan_dip = reference.z.abs()
                / (reference.x * reference.x + reference.y * reference.y).sqrt_rn();
            let coupling = tan_dip * tilt;
            (white * white / T::from_count((*n).max(1))
                + mag.heading_noise * mag.heading_noise / stats.duration
                + mag.heading_floor * mag.heading_floor
                + coupling * coupling)
                .sqrt_rn()
        }
        None => T::pi(),
    };
    let sigmas = InitialSigmas {
        tilt,
        yaw,
        gyro_bias: bias_sigma,
        accel_bias: config.accelerometer_bias_sigma,
        // At rest the velocity is zero; moving, it is one of the body's velocities.
        velocity: if still {
            rest_drift_variance(config, stats.duration).sqrt_rn()
        } else {
            config.velocity_sigma
        },
        ..InitialSigmas::default()
    };
    Ok(Start {
        alignment,
        sigmas,
        still,
    })
}

/// What the start-up window gives: the first attitude and bias, their uncertainties, and
/// whether the window was still (the filter is built from them by
/// [`AhrsAccelBias::from_alignment`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Start<T: Real> {
    pub(super) alignment: Alignment<T>,
    pub(super) sigmas: InitialSigmas<T>,
    pub(super) still: bool,
}

//! Start-up: static alignment from a window of samples at rest.
//!
//! * Tilt: at rest the accelerometer reads `f = Rᵀ u ‖g‖` with `u = −g/‖g‖`, so the mean
//!   specific force `f̄` gives the world up direction in the body, `u_b = f̄/‖f̄‖`.
//! * Heading: with a magnetometer, the horizontal part of the mean field
//!   `m_h = m̄ − (m̄·u_b)u_b` is matched to the horizontal part of the world reference field.
//!   Without one, yaw is set so that the body `x` axis projects onto world `x`.
//! * `R` is the rotation taking the body triad `(u_b, h_b, u_b × h_b)` onto the world triad
//!   `(u, h_w, u × h_w)`: `R = W Bᵀ`.
//! * Initial gyro bias: the mean angular rate `ω̄` (the body does not rotate).
//!
//! Results carrying vectors are matched, not propagated with `?`: on a Cortex-M4F the `?` of a
//! `Result<Vector3<f32>, _>` copies the value through an unaligned `memcpy`.

use super::config::{up_direction, FilterConfig};
use super::error::EskfError;
use crate::kernels::{all_finite, mat3};
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// The result of a static alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment<T: Real> {
    /// `R`, world from body.
    pub attitude: So3<T>,
    /// Initial gyroscope bias, the mean rate over the window, rad/s.
    pub gyro_bias: Vector3<T>,
    /// `true` when the heading came from a magnetometer.
    pub heading_from_magnetometer: bool,
}

/// Magnetometer data for the alignment.
#[derive(Clone, Copy, Debug)]
pub struct MagnetometerWindow<'a, T: Real> {
    /// Body-frame field samples.
    pub samples: &'a [Vector3<T>],
    /// World reference field.
    pub reference: Vector3<T>,
}

fn mean<T: Real>(xs: &[Vector3<T>]) -> Result<Vector3<T>, EskfError> {
    if xs.is_empty() {
        return Err(EskfError::EmptyWindow);
    }
    let mut sum = Vector3::zeros();
    let mut n = T::zero();
    for x in xs {
        if !all_finite(x.as_slice()) {
            return Err(EskfError::NonFinite);
        }
        sum += x;
        n += T::one();
    }
    Ok(sum / n)
}

/// The unit vector along the part of `v` orthogonal to the unit `u`, if any.
fn horizontal<T: Real>(v: &Vector3<T>, u: &Vector3<T>) -> Option<Vector3<T>> {
    let h = mat3::axpy(v, -u.dot(v), u);
    let n = mat3::norm(&h);
    if n > T::lit(1e-6) * mat3::norm(v) && n > T::zero() {
        Some(h / n)
    } else {
        None
    }
}

/// Without a magnetometer: the horizontal direction of the `x` axis, or of the `y` axis when
/// `x` is along `u` (module docs).
fn level_axis<T: Real>(u: &Vector3<T>) -> Option<Vector3<T>> {
    horizontal(&Vector3::x(), u).or_else(|| horizontal(&Vector3::y(), u))
}

/// The triad `[u, h, u × h]` (columns).
fn triad<T: Real>(u: &Vector3<T>, h: &Vector3<T>) -> Matrix3<T> {
    Matrix3::from_columns(&[*u, *h, u.cross(h)])
}

/// Static alignment from samples at rest.
///
/// `accel`, `gyro`: the IMU window (body frame, same length not required); `gravity`: the
/// world gravity vector (`[0, 0, −9.81]`); `mag`: optional magnetometer window. The mean specific
/// force must have a norm within `rest_tolerance` (m/s²) of `‖g‖`, else [`EskfError::NotAtRest`].
/// Errors: [`EskfError::EmptyWindow`], [`EskfError::NonFinite`], [`EskfError::ZeroNorm`] (zero
/// mean accelerometer, magnetometer or reference, or a field with no horizontal part).
#[allow(clippy::question_mark)] // the matches on vector results: see the module docs
#[inline(never)] // once at start-up: its vectors stay out of the caller's frame
pub fn align_at_rest<T: Real>(
    accel: &[Vector3<T>],
    gyro: &[Vector3<T>],
    gravity: &Vector3<T>,
    mag: Option<&MagnetometerWindow<'_, T>>,
    rest_tolerance: T,
) -> Result<Alignment<T>, EskfError> {
    let (f, w) = match (mean(accel), mean(gyro)) {
        (Ok(f), Ok(w)) => (f, w),
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };
    if !(all_finite(gravity.as_slice()) && rest_tolerance.is_finite()) {
        return Err(EskfError::NonFinite);
    }
    let (nf, ng) = (mat3::norm(&f), mat3::norm(gravity));
    if !(nf > T::zero() && ng > T::zero()) {
        return Err(EskfError::ZeroNorm);
    }
    if (nf - ng).abs() > rest_tolerance {
        return Err(EskfError::NotAtRest);
    }
    let ub = f / nf;
    let uw = -gravity / ng;
    let pair = match mag {
        Some(m) => {
            let mw = m.reference;
            let mb = match mean(m.samples) {
                Ok(mb) => mb,
                Err(e) => return Err(e),
            };
            if !all_finite(mw.as_slice()) {
                return Err(EskfError::NonFinite);
            }
            (horizontal(&mb, &ub), horizontal(&mw, &uw))
        }
        None => (level_axis(&ub), level_axis(&uw)),
    };
    let (Some(hb), Some(hw)) = pair else {
        return Err(EskfError::ZeroNorm);
    };
    // R = W Bᵀ, W = [u_w, h_w, u_w × h_w], B = [u_b, h_b, u_b × h_b] (columns).
    let w_triad = triad(&uw, &hw);
    let b_triad = triad(&ub, &hb);
    let Some(attitude) = So3::from_rotation_matrix(&mat3::mul(&w_triad, &b_triad.transpose()))
    else {
        return Err(EskfError::NonFinite);
    };
    Ok(Alignment {
        attitude,
        gyro_bias: w,
        heading_from_magnetometer: mag.is_some(),
    })
}

/// Initial 1-σ uncertainties for a filter started from an [`Alignment`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialSigmas<T: Real> {
    /// Roll/pitch (tilt), rad.
    pub tilt: T,
    /// Yaw about world up, rad (large without a magnetometer).
    pub yaw: T,
    /// Velocity, m/s.
    pub velocity: T,
    /// Position, m.
    pub position: T,
    /// Gyro bias, rad/s.
    pub gyro_bias: T,
    /// Accelerometer bias, m/s².
    pub accel_bias: T,
}

impl<T: Real> Default for InitialSigmas<T> {
    /// 1° tilt, 5° yaw, 0.1 m/s, 1 m, 0.2 °/s, 0.05 m/s².
    fn default() -> Self {
        Self {
            tilt: T::lit(0.017_453_29),
            yaw: T::lit(0.087_266_46),
            velocity: T::lit(0.1),
            position: T::lit(1.0),
            gyro_bias: T::lit(0.003_490_66),
            accel_bias: T::lit(0.05),
        }
    }
}

impl<T: Real> InitialSigmas<T> {
    /// The attitude covariance in the body-frame error: the world-frame
    /// `Σ_w = σ_t² I + (σ_ψ² − σ_t²) u uᵀ` (`diag(σ_t², σ_t², σ_ψ²)` for `u` = z) mapped by
    /// `δθ = Rᵀ δθ_w`: `Rᵀ Σ_w R = σ_t² I + (σ_ψ² − σ_t²) u_b u_bᵀ`, `u_b = Rᵀ u`, exactly
    /// symmetric.
    ///
    /// A sigma is taken by its magnitude, and one above π as π: an attitude error of σ = π
    /// carries no information, and a larger variance only costs the filter its resolution (the
    /// tilt of a body-frame attitude block is the difference of entries of the heading's size).
    #[must_use]
    pub fn attitude_covariance(&self, attitude: &So3<T>, up: &Vector3<T>) -> Matrix3<T> {
        let (tilt, yaw) = (self.tilt.abs().min(T::pi()), self.yaw.abs().min(T::pi()));
        let t2 = tilt * tilt;
        let y2 = yaw * yaw;
        // Σ_w = σ_t² I + (σ_ψ² − σ_t²) u uᵀ, so Rᵀ Σ_w R = σ_t² I + (σ_ψ² − σ_t²) u_b u_bᵀ with
        // u_b = Rᵀ u: exactly symmetric (u_i u_j = u_j u_i), at every magnitude. A u_b of
        // length² 1 + δ gives the eigenvalue σ_ψ² − δ (σ_t² − σ_ψ²) along it, below zero for a
        // yaw far below the tilt (an up rounded 64 ε long in f32 gave −7.5·10⁻⁵ rad² against
        // σ_t² = π²): beyond |δ| = 16 ε (an eigenvalue error of 16 ε σ_t², under the attitude
        // floor's margin) it is made a unit vector; a unit `up` and rotation never take the
        // branch (their rounding is a few ε).
        let u_b = mat3::mul_vec(&attitude.rotation_matrix().transpose(), up);
        let length_sq = u_b.dot(&u_b);
        let off = length_sq - T::one();
        let limit = T::lit(16.0 * T::EPSILON_F64);
        let u_b = if (off > limit || off < -limit) && crate::kernels::positive_finite(length_sq) {
            u_b / length_sq.sqrt_rn()
        } else {
            u_b
        };
        Matrix3::from_diagonal_element(t2) + u_b * u_b.transpose() * (y2 - t2)
    }
}

/// The prior attitude covariance of a filter started from `alignment`: tilt and yaw sigmas
/// about the world up `−g/‖g‖` of `config`. Error: a zero or non-finite gravity.
pub(crate) fn prior_attitude_covariance<T: Real>(
    alignment: &Alignment<T>,
    sigmas: &InitialSigmas<T>,
    config: &FilterConfig<T>,
) -> Result<Matrix3<T>, EskfError> {
    let Some(up) = up_direction(&config.gravity) else {
        return Err(EskfError::ZeroNorm);
    };
    Ok(sigmas.attitude_covariance(&alignment.attitude, &up))
}

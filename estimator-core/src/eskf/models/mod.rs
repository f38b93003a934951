//! Measurement models `z = h(x) + n`, `n ~ N(0, R)`, each with its right Jacobian
//! `H = ∂h(x ⊕ δx)/∂δx` at `δx = 0`: one file per sensor.
//!
//! Every attitude Jacobian follows from `R·exp(δθ^) ≈ R(I + [δθ]×)` (first order in `δθ`):
//!
//! ```text
//! (R exp(δθ^))ᵀ a ≈ Rᵀa + [Rᵀa]× δθ          (a world vector seen in the body)
//!  R exp(δθ^) b   ≈ R b − R[b]× δθ            (a body vector seen in the world)
//! ```
//!
//! the second being the action Jacobian `J^{R·b}_R = −R[b]×` of *Lie Groups and Smooth
//! Manifolds for Robotic State Estimation*, Theorem 5.1 / Example 5.2.
//!
//! A new model is one file here implementing [`Measurement`](super::Measurement) for the
//! states it observes, plus a Jacobian test in `tests/eskf_jacobians.rs`.

mod barometer;
mod camera;
mod gnss;
mod gravity;
mod heading;
mod magnetometer;
mod zero_velocity;

pub use barometer::BaroAltitude;
pub use camera::{CameraLandmark, PinholeIntrinsics};
pub use gnss::{GnssPosition, GnssVelocity};
pub use gravity::{AccelerometerAtRest, GravityDirection};
pub use heading::Heading;
pub use magnetometer::Magnetometer;
pub use zero_velocity::ZeroVelocity;

use super::update::Linearization;
use super::EskfError;
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// `σ² I₃`.
fn isotropic<T: Real>(sigma: T) -> Matrix3<T> {
    Matrix3::from_diagonal_element(sigma * sigma)
}

/// A world vector `v` seen in the body, `Rᵀ v`, and its attitude Jacobian `[Rᵀ v]×`
/// (`(R exp(δθ^))ᵀ v ≈ Rᵀ v + [Rᵀ v]× δθ`).
fn in_body<T: Real>(attitude: &So3<T>, v: &Vector3<T>) -> (Vector3<T>, Matrix3<T>) {
    let b = attitude.inverse().act(v);
    (b, skew(&b))
}

/// The linearization of a model that sees only the attitude, from its residual and attitude
/// block (the direction models, whose parts are computed once for both filters).
fn attitude_only<T: Real, const N: usize>(
    parts: Result<(Vector3<T>, Matrix3<T>), EskfError>,
) -> Result<Linearization<T, N, 3>, EskfError> {
    match parts {
        Ok((residual, d_attitude)) => Ok(three_rows(residual, &[(0, &d_attitude)], &[])),
        Err(e) => Err(e),
    }
}

/// The linearization of a three-row model: `residual`, and `H` zero except for the given
/// `(column, block)` pairs and the identity blocks starting at the columns in `identities`.
/// (Block `k` of a `3 × N` column-major matrix is the nine entries `9k .. 9k + 9`.)
fn three_rows<T: Real, const N: usize>(
    residual: Vector3<T>,
    blocks: &[(usize, &Matrix3<T>)],
    identities: &[usize],
) -> Linearization<T, N, 3> {
    let mut jacobian = SMatrix::<T, 3, N>::zeros();
    let h = jacobian.as_mut_slice();
    for (col, b) in blocks {
        if let Some(dst) = h.get_mut(3 * col..3 * col + 9) {
            dst.copy_from_slice(b.as_slice());
        }
    }
    for col in identities {
        for i in 0..3 {
            if let Some(e) = h.get_mut(3 * col + 4 * i) {
                *e = T::one();
            }
        }
    }
    Linearization { residual, jacobian }
}

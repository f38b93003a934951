//! The pieces several measurement models share.

use crate::eskf::error::EskfError;
use crate::eskf::update::Linearization;
use crate::kernels::block::copy;
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// `σ² I₃`.
pub(super) fn isotropic<T: Real>(sigma: T) -> Matrix3<T> {
    Matrix3::from_diagonal_element(sigma * sigma)
}

/// `diag(σ_h², σ_h², σ_v²)`: a world-frame (ENU) noise with horizontal 1σ `sigma_h` on east
/// and north and vertical 1σ `sigma_v` on up.
pub(super) fn horizontal_vertical<T: Real>(sigma_h: T, sigma_v: T) -> Matrix3<T> {
    let (h, v) = (sigma_h * sigma_h, sigma_v * sigma_v);
    Matrix3::new(
        h,
        T::zero(),
        T::zero(),
        T::zero(),
        h,
        T::zero(),
        T::zero(),
        T::zero(),
        v,
    )
}

/// A world vector `v` seen in the body, `Rᵀ v`, and its attitude Jacobian `[Rᵀ v]×`
/// (`(R exp(δθ^))ᵀ v ≈ Rᵀ v + [Rᵀ v]× δθ`).
pub(super) fn in_body<T: Real>(attitude: &So3<T>, v: &Vector3<T>) -> (Vector3<T>, Matrix3<T>) {
    let b = attitude.inverse().act(v);
    (b, skew(&b))
}

/// The linearization of a model that sees only the attitude, from its residual and attitude
/// block (the direction models, whose parts are computed once for both filters).
pub(super) fn attitude_only<T: Real, const N: usize>(
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
pub(super) fn three_rows<T: Real, const N: usize>(
    residual: Vector3<T>,
    blocks: &[(usize, &Matrix3<T>)],
    identities: &[usize],
) -> Linearization<T, N, 3> {
    let mut jacobian = SMatrix::<T, 3, N>::zeros();
    let h = jacobian.as_mut_slice();
    for (col, b) in blocks {
        if let Some(dst) = h.get_mut(3 * col..3 * col + 9) {
            copy(dst, b.as_slice());
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

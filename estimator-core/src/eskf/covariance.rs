//! Checks and read-outs of a covariance matrix.

use super::config::FilterConfig;
use super::error::EskfError;
use super::state::ErrorState;
use crate::kernels::all_finite;
use crate::kernels::cholesky::factor_in_place;
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// `A` is finite, symmetric to `10⁻⁶` of its largest entry, and positive definite (its Cholesky
/// factor exists).
pub(crate) fn is_spd<T: Real, const M: usize>(a: &SMatrix<T, M, M>) -> bool {
    if !all_finite(a.as_slice()) {
        return false;
    }
    let tol = a.amax() * T::lit(1e-6);
    let symmetric = (0..M).all(|j| {
        (j + 1..M).all(|i| match (a.get((i, j)), a.get((j, i))) {
            (Some(x), Some(y)) => (*x - *y).abs() <= tol,
            _ => false,
        })
    });
    let mut l = *a;
    symmetric && factor_in_place(l.as_mut_slice(), M, T::zero())
}

/// The checks every filter constructor makes on a given start: a valid configuration, a finite
/// state and a symmetric positive definite covariance.
pub(crate) fn check_start<T: Real, S: ErrorState<T, N>, const N: usize>(
    state: &S,
    covariance: &SMatrix<T, N, N>,
    config: &FilterConfig<T>,
) -> Result<(), EskfError> {
    config.validate()?;
    if !state.is_finite() {
        return Err(EskfError::NonFinite);
    }
    if !is_spd(covariance) {
        return Err(EskfError::CovarianceNotPositiveDefinite);
    }
    Ok(())
}

/// `√max(P_ii, 0)` for each `i`: the 1-σ of each error-state component.
pub(crate) fn sigmas<T: Real, const N: usize>(p: &SMatrix<T, N, N>) -> SVector<T, N> {
    p.diagonal().map(|d| d.max(T::zero()).sqrt_rn())
}

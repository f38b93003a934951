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
    let mut l = *a;
    is_symmetric(a.as_slice(), M) && factor_in_place(l.as_mut_slice(), M, T::zero())
}

/// The column-major `n × n` storage `a` is finite and symmetric to `10⁻⁶` of its largest entry
/// (one compiled copy for every size).
fn is_symmetric<T: Real>(a: &[T], n: usize) -> bool {
    if a.len() != n * n || !all_finite(a) {
        return false;
    }
    let tol = a.iter().fold(T::zero(), |m, x| m.max(x.abs())) * T::lit(1e-6);
    let at = |k: usize| a.get(k).copied().unwrap_or_else(T::zero);
    (0..n).all(|j| (j + 1..n).all(|i| (at(j * n + i) - at(i * n + j)).abs() <= tol))
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

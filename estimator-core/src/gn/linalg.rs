//! Factorization of the small information matrix `A = Hᵀ W H` (size `N × N`, `N` the tangent
//! dimension), with a typed failure.
//!
//! `A = L Lᵀ` (Cholesky) by the crate's left-looking column kernel (Golub & Van Loan, *Matrix
//! Computations*, §4.2). On top of a positive pivot, the factorization requires every variable
//! to carry information of its own: with the `LDLᵀ` pivot `dᵢ = Lᵢᵢ²`, the part of `Aᵢᵢ` that
//! the previous variables do not explain, it requires
//!
//! ```text
//! dᵢ > τ·Aᵢᵢ,   τ = PIVOT_TOLERANCE_EPS · N · ε.
//! ```
//!
//! Below that the variable is, to working precision, a combination of the others: rank
//! deficiency, as from collinear points, parallel rays or a rotation about an unobserved axis.

use super::SolveError;
use crate::kernels::all_finite;
use crate::kernels::cholesky::{factor_in_place, inverse_into, solve_in_place};
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// Multiple of `N · ε` below which a relative pivot `dᵢ / Aᵢᵢ` counts as zero.
pub const PIVOT_TOLERANCE_EPS: f64 = 16.0;

/// The factorization `A = L Lᵀ` of a symmetric positive-definite `N × N` matrix.
#[derive(Clone, Copy, Debug)]
pub struct Factor<T: Real, const N: usize> {
    /// `L` in the lower triangle (the strict upper triangle is whatever `A` had there).
    l: SMatrix<T, N, N>,
}

impl<T: Real, const N: usize> Factor<T, N> {
    /// Factorizes `a`: `L` comes from its lower triangle; every entry must be finite.
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] for a non-finite entry; [`SolveError::NotPositiveDefinite`]
    /// when a pivot is not positive or a relative pivot `dᵢ / Aᵢᵢ` is at or below
    /// `PIVOT_TOLERANCE_EPS · N · ε`.
    pub fn new(a: &SMatrix<T, N, N>) -> Result<Self, SolveError> {
        let mut l = *a;
        factor(l.as_mut_slice(), N)?;
        Ok(Self { l })
    }

    /// `A⁻¹ b` by forward substitution `L y = b`, then back substitution `Lᵀ x = y`.
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] if the result is not finite (a non-finite `b`).
    pub fn solve(&self, b: &SVector<T, N>) -> Result<SVector<T, N>, SolveError> {
        let mut x = *b;
        solve_in_place(self.l.as_slice(), N, x.as_mut_slice());
        if all_finite(x.as_slice()) {
            Ok(x)
        } else {
            Err(SolveError::NonFiniteResidual)
        }
    }

    /// `A⁻¹`, symmetrized (`(X + Xᵀ)/2`) against round-off.
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] if an entry is not finite.
    pub fn inverse(&self) -> Result<SMatrix<T, N, N>, SolveError> {
        let mut x = SMatrix::<T, N, N>::zeros();
        inverse(self.l.as_slice(), N, x.as_mut_slice())?;
        Ok(x)
    }
}

/// `A = L Lᵀ` in place on the column-major `n × n` storage `a` (the lower triangle becomes `L`),
/// with the checks and errors of [`Factor::new`].
///
/// # Errors
/// As [`Factor::new`].
pub(crate) fn factor<T: Real>(a: &mut [T], n: usize) -> Result<(), SolveError> {
    if !all_finite(a) {
        return Err(SolveError::NonFiniteResidual);
    }
    let tau = T::lit(const { PIVOT_TOLERANCE_EPS * T::EPSILON_F64 })
        * T::from_usize(n).unwrap_or_else(T::one);
    if factor_in_place(a, n, tau) {
        Ok(())
    } else {
        Err(SolveError::NotPositiveDefinite)
    }
}

/// `x ← (L Lᵀ)⁻¹` for the factor `l` (both column-major `n × n`), symmetrized.
///
/// # Errors
/// [`SolveError::NonFiniteResidual`] if an entry is not finite.
pub(crate) fn inverse<T: Real>(l: &[T], n: usize, x: &mut [T]) -> Result<(), SolveError> {
    if inverse_into(l, n, x) {
        Ok(())
    } else {
        Err(SolveError::NonFiniteResidual)
    }
}

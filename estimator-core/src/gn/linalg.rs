//! Factorization of the small information matrix `A = Hᵀ W H` (size `N × N`, `N` the tangent
//! dimension), with a typed failure instead of a panic.
//!
//! `A = L Lᵀ` (Cholesky; equivalently `L D Lᵀ` with `D = diag(Lᵢᵢ²)`), computed by nalgebra's
//! fixed-size [`nalgebra::Cholesky::new`], which returns `None` for a non-positive or NaN pivot and
//! never panics on a square fixed-size matrix. On top of that this module refuses a
//! *numerically* singular matrix: the `LDLᵀ` pivot `dᵢ = Lᵢᵢ²` is the part of `Aᵢᵢ` that the
//! previous variables do not explain, so `dᵢ / Aᵢᵢ` is the fraction of the information on
//! variable `i` that is its own. It must exceed `PIVOT_TOLERANCE_EPS · N · ε`; below that the
//! variable is (to working precision) a combination of the others — rank deficiency, as from
//! collinear points, parallel rays or a pure rotation about an unobserved axis.

use super::SolveError;
use crate::Real;
use nalgebra::{Cholesky, Const, SMatrix, SVector};

/// Multiple of `N · ε` below which a relative pivot `dᵢ / Aᵢᵢ` counts as zero.
pub const PIVOT_TOLERANCE_EPS: f64 = 16.0;

/// The factorization `A = L Lᵀ` of a symmetric positive-definite `N × N` matrix.
#[derive(Clone, Copy, Debug)]
pub struct Factor<T: Real, const N: usize> {
    chol: Cholesky<T, Const<N>>,
}

impl<T: Real, const N: usize> Factor<T, N> {
    /// Factorizes `a` (only its lower triangle is read).
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] for a non-finite entry; [`SolveError::NotPositiveDefinite`]
    /// when a diagonal entry is not positive or a relative pivot `dᵢ / Aᵢᵢ` is at or below
    /// `PIVOT_TOLERANCE_EPS · N · ε`.
    pub fn new(a: &SMatrix<T, N, N>) -> Result<Self, SolveError> {
        if !a.iter().all(|x| x.is_finite()) {
            return Err(SolveError::NonFiniteResidual);
        }
        let diag = a.diagonal();
        if !diag.iter().all(|&x| x > T::zero()) {
            return Err(SolveError::NotPositiveDefinite);
        }
        let chol = Cholesky::new(*a).ok_or(SolveError::NotPositiveDefinite)?;
        let tol = T::lit(const { PIVOT_TOLERANCE_EPS * T::EPSILON_F64 })
            * T::from_usize(N).unwrap_or_else(T::one);
        let ok = chol
            .l_dirty()
            .diagonal()
            .iter()
            .zip(diag.iter())
            .all(|(&l, &d)| l * l > tol * d);
        if ok {
            Ok(Self { chol })
        } else {
            Err(SolveError::NotPositiveDefinite)
        }
    }

    /// `A⁻¹ b` by forward and back substitution.
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] if the result is not finite (a non-finite `b`).
    pub fn solve(&self, b: &SVector<T, N>) -> Result<SVector<T, N>, SolveError> {
        let x = self.chol.solve(b);
        if x.iter().all(|v| v.is_finite()) {
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
        let mut x = SMatrix::zeros();
        self.inverse_into(&mut x)?;
        Ok(x)
    }

    /// [`Self::inverse`] written into `x`, without `N × N` temporaries (for small stacks).
    ///
    /// # Errors
    /// As [`Self::inverse`]; `x` then holds the non-finite result.
    #[inline(never)]
    pub(crate) fn inverse_into(&self, x: &mut SMatrix<T, N, N>) -> Result<(), SolveError> {
        x.fill_with_identity();
        self.chol.solve_mut(x);
        // (X + Xᵀ)/2 in place: entry (r, c) and (c, r) both get (x_rc + x_cr)·½ (the sum is
        // commutative, so both equal the out-of-place result).
        let half = T::lit(0.5);
        for c in 0..N {
            for r in c..N {
                let (Some(&a), Some(&b)) = (x.get((r, c)), x.get((c, r))) else {
                    continue;
                };
                let s = (a + b) * half;
                if let Some(v) = x.get_mut((r, c)) {
                    *v = s;
                }
                if let Some(v) = x.get_mut((c, r)) {
                    *v = s;
                }
            }
        }
        if x.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(SolveError::NonFiniteResidual)
        }
    }
}

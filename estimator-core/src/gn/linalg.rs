//! Factorization of the small information matrix `A = Hᵀ W H` (size `N × N`, `N` the tangent
//! dimension), with a typed failure instead of a panic.
//!
//! `A = L Lᵀ` (Cholesky; equivalently `L D Lᵀ` with `D = diag(Lᵢᵢ²)`), by the left-looking
//! ("gaxpy") column algorithm of Golub & Van Loan, *Matrix Computations*, §4.2, the one nalgebra's
//! `Cholesky::new` uses: column `j` minus its projections on the columns before it, then divided
//! by the square root of its pivot; a zero, negative or NaN pivot is refused. The kernels work on
//! the column-major storage with the dimension as a run-time number, so that every `N` shares
//! one copy of the code (the 3×3 and 6×6 solvers of the firmware); every access is checked
//! (`get`), nothing can panic. On top of that this module refuses a *numerically* singular
//! matrix: the `LDLᵀ` pivot `dᵢ = Lᵢᵢ²` is the part of `Aᵢᵢ` that the previous variables do not
//! explain, so `dᵢ / Aᵢᵢ` is the fraction of the information on variable `i` that is its own. It
//! must exceed `PIVOT_TOLERANCE_EPS · N · ε`; below that the variable is (to working precision) a
//! combination of the others — rank deficiency, as from collinear points, parallel rays or a pure
//! rotation about an unobserved axis.

use super::SolveError;
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
    /// Factorizes `a` (only its lower triangle is read).
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] for a non-finite entry; [`SolveError::NotPositiveDefinite`]
    /// when a diagonal entry is not positive or a relative pivot `dᵢ / Aᵢᵢ` is at or below
    /// `PIVOT_TOLERANCE_EPS · N · ε`.
    pub fn new(a: &SMatrix<T, N, N>) -> Result<Self, SolveError> {
        // Factorized in the returned value (no copy of `L` into the `Result`).
        let mut out = Ok(Self { l: *a });
        if let Ok(f) = &mut out {
            if let Err(e) = cholesky_in_place(f.l.as_mut_slice(), N) {
                out = Err(e);
            }
        }
        out
    }

    /// `A⁻¹ b` by forward and back substitution.
    ///
    /// # Errors
    /// [`SolveError::NonFiniteResidual`] if the result is not finite (a non-finite `b`).
    pub fn solve(&self, b: &SVector<T, N>) -> Result<SVector<T, N>, SolveError> {
        let mut x = *b;
        substitute(self.l.as_slice(), N, x.as_mut_slice());
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
        // Written in the returned value (no copy of `A⁻¹` into the `Result`).
        let mut out = Ok(SMatrix::zeros());
        if let Ok(x) = &mut out {
            if let Err(e) = self.inverse_into(x) {
                out = Err(e);
            }
        }
        out
    }

    /// [`Self::inverse`] written into `x`, without `N × N` temporaries (for small stacks).
    ///
    /// # Errors
    /// As [`Self::inverse`]; `x` then holds the non-finite result.
    pub(crate) fn inverse_into(&self, x: &mut SMatrix<T, N, N>) -> Result<(), SolveError> {
        inverse_in_place(self.l.as_slice(), N, x.as_mut_slice())
    }
}

pub(crate) use crate::scalar::all_finite;

/// `A = L Lᵀ` in place on the column-major `n × n` storage `a` (the lower triangle becomes `L`),
/// with the checks of [`Factor::new`]. Left-looking (see the module docs): at step `j` column `j`
/// below the diagonal loses `L[j, k] · L[j.., k]` for every `k < j`, then `L[j, j] = √d`,
/// `L[j+1.., j] /= L[j, j]`; the pivot test compares `L[j, j]²` with the original `A[j, j]`.
#[inline(never)]
pub(crate) fn cholesky_in_place<T: Real>(a: &mut [T], n: usize) -> Result<(), SolveError> {
    // `n = 0` is the empty factor (and `chunks_exact` needs `n > 0`).
    if n == 0 {
        return Ok(());
    }
    if !all_finite(a) {
        return Err(SolveError::NonFiniteResidual);
    }
    // No separate test of the diagonal: a pivot is `A[j, j]` minus squares (each update adds
    // `−L[j, k]²`, never positive, and rounding is monotonic), so `A[j, j] ≤ 0` gives a pivot
    // `≤ 0`, refused below with the same error.
    let tol = T::lit(const { PIVOT_TOLERANCE_EPS * T::EPSILON_F64 })
        * T::from_usize(n).unwrap_or_else(T::one);
    for j in 0..n {
        // Column j of the storage and the columns before it (split: both borrowed at once).
        let (before, rest) = a
            .split_at_mut_checked(j * n)
            .ok_or(SolveError::NotPositiveDefinite)?;
        // Rows `j..` of column j: `col_j[0]` is the diagonal entry.
        let col_j = rest.get_mut(j..n).ok_or(SolveError::NotPositiveDefinite)?;
        let a_jj = col_j.first().copied().unwrap_or_else(T::zero);
        for col_k in before.chunks_exact(n) {
            let Some(col_k) = col_k.get(j..) else {
                continue;
            };
            let factor = -col_k.first().copied().unwrap_or_else(T::zero);
            axpy(col_j, col_k, factor);
        }
        let d = col_j.first().copied().unwrap_or_else(T::zero);
        // Written so that a NaN pivot (which compares false) is refused too.
        let positive = d > T::zero();
        if !positive {
            return Err(SolveError::NotPositiveDefinite);
        }
        let l_jj = d.sqrt_rn();
        let own_information = l_jj * l_jj > tol * a_jj;
        if !own_information {
            return Err(SolveError::NotPositiveDefinite);
        }
        if let Some((diagonal, below)) = col_j.split_first_mut() {
            *diagonal = l_jj;
            for y in below {
                *y /= l_jj;
            }
        }
    }
    Ok(())
}

/// `yₖ ← xₖ·f + yₖ` over the common length: the column update of [`cholesky_in_place`] and of
/// the forward substitution (one copy when built for size).
#[cfg_attr(estimator_compact, inline(never))]
fn axpy<T: Real>(y: &mut [T], x: &[T], f: T) {
    for (y, &x) in y.iter_mut().zip(x) {
        *y = x * f + *y;
    }
}

/// `Σ xᵢyᵢ` over the common length, from zero, left to right: the back substitution's sums and
/// those of the solver's step statistics (one copy when built for size).
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn dot<T: Real>(x: &[T], y: &[T]) -> T {
    x.iter().zip(y).fold(T::zero(), |acc, (&p, &q)| acc + p * q)
}

/// `b ← (L Lᵀ)⁻¹ b` for the factor `l` (column-major `n × n`, lower triangle): forward
/// substitution `L y = b` by columns (`y_i = b_i / L_ii`, then `b_{i+1..} −= y_i L_{i+1.., i}`),
/// then back substitution `Lᵀ x = y` by dot products, as nalgebra's `Cholesky::solve_mut`.
#[inline(never)]
pub(crate) fn substitute<T: Real>(l: &[T], n: usize, b: &mut [T]) {
    if n == 0 {
        return;
    }
    for (i, col) in l.chunks_exact(n).enumerate().take(n) {
        let diag = col.get(i).copied().unwrap_or_else(T::one);
        let Some(b_i) = b.get_mut(i) else { break };
        let coeff = *b_i / diag;
        *b_i = coeff;
        if let (Some(y), Some(x)) = (b.get_mut(i + 1..), col.get(i + 1..)) {
            axpy(y, x, -coeff);
        }
    }
    for i in (0..n).rev() {
        let Some(col) = l.get(i * n..i * n + n) else {
            continue;
        };
        let dot = match (col.get(i + 1..), b.get(i + 1..)) {
            (Some(x), Some(y)) => dot(x, y),
            _ => T::zero(),
        };
        let diag = col.get(i).copied().unwrap_or_else(T::one);
        if let Some(b_i) = b.get_mut(i) {
            *b_i = (*b_i - dot) / diag;
        }
    }
}

/// `x ← (L Lᵀ)⁻¹`, symmetrized, for the factor `l` (both column-major `n × n`); see
/// [`Factor::inverse`]. Out of line at opt-level 2/3; built for size, LLVM decides (it has one
/// caller per firmware that solves, and inlining it there is smaller than the call).
#[cfg_attr(not(estimator_compact), inline(never))]
pub(crate) fn inverse_in_place<T: Real>(l: &[T], n: usize, x: &mut [T]) -> Result<(), SolveError> {
    if n == 0 {
        return Ok(());
    }
    // Column c of the identity, solved in place.
    for (c, col) in x.chunks_exact_mut(n).enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = if r == c { T::one() } else { T::zero() };
        }
        substitute(l, n, col);
    }
    // (X + Xᵀ)/2 in place: entry (r, c) and (c, r) both get (x_rc + x_cr)·½ (the sum is
    // commutative, so both equal the out-of-place result).
    let half = T::lit(0.5);
    for c in 0..n {
        for r in c..n {
            let (Some(&a), Some(&b)) = (x.get(c * n + r), x.get(r * n + c)) else {
                continue;
            };
            let s = (a + b) * half;
            if let Some(v) = x.get_mut(c * n + r) {
                *v = s;
            }
            if let Some(v) = x.get_mut(r * n + c) {
                *v = s;
            }
        }
    }
    if all_finite(x) {
        Ok(())
    } else {
        Err(SolveError::NonFiniteResidual)
    }
}

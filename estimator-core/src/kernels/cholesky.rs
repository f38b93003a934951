//! The Cholesky factor `A = L Lᵀ` of a small symmetric positive-definite matrix, its solves and
//! its inverse, over column-major storage with the dimension as a run-time number (one compiled
//! copy serves the filters' 1…6-row innovations and the solver's 3×3 and 6×6 normal equations).
//!
//! The factor is the left-looking ("gaxpy") column algorithm of Golub & Van Loan, *Matrix
//! Computations*, §4.2: column `j` loses `L_jk · L_{j.., k}` for every `k < j`, then
//! `L_jj = √d_j` and `L_{j+1.., j} /= L_jj`. A pivot `d_j` that is zero, negative or NaN is
//! refused, and so is one that is numerically zero: `d_j ≤ τ·A_jj`, where `d_j / A_jj` is the
//! fraction of the variance of variable `j` that the previous variables do not explain, and `τ`
//! is the caller's relative pivot tolerance.

use super::finite::all_finite;
use super::slice::{axpy, columns, dot};
use crate::Real;

/// `A = L Lᵀ` in place on the column-major `n × n` storage `a`: only the lower triangle is
/// read, and it becomes `L`. `false` (with `a` partly overwritten) when an entry of the lower
/// triangle is not finite or a pivot `d_j` is not above `relative_pivot · A_jj` (see the module
/// docs; `relative_pivot = 0` refuses only pivots `≤ 0` and NaN).
#[inline(never)]
#[must_use]
pub(crate) fn factor_in_place<T: Real>(a: &mut [T], n: usize, relative_pivot: T) -> bool {
    factor_inline(a, n, relative_pivot)
}

/// `L ← S = L Lᵀ` for a symmetric positive-definite 3 × 3 `s` (column-major; `L` in the lower
/// triangle of `l`, the strict upper triangle of `l` keeps `S`'s): [`factor_in_place`] with the
/// dimension a constant, so that the loops unroll and their index checks fold away (the
/// filters' innovation covariance). `false` as [`factor_in_place`] with `relative_pivot = 0`.
#[inline(never)]
#[must_use]
pub(crate) fn spd_factor_3<T: Real>(s: &[T; 9], l: &mut [T; 9]) -> bool {
    *l = *s;
    factor_inline(l, 3, T::zero())
}

/// The body of [`factor_in_place`], for it and [`spd_factor_3`].
#[inline(always)]
#[must_use]
fn factor_inline<T: Real>(a: &mut [T], n: usize, relative_pivot: T) -> bool {
    if a.len() != n * n {
        return false;
    }
    if !all_finite(a) {
        return false;
    }
    for j in 0..n {
        let Some((before, rest)) = a.split_at_mut_checked(j * n) else {
            return false;
        };
        let Some(col_j) = rest.get_mut(j..n) else {
            return false;
        };
        let a_jj = col_j.first().copied().unwrap_or_else(T::zero);
        for col_k in columns(before, n) {
            let Some(col_k) = col_k.get(j..) else {
                continue;
            };
            let l_jk = col_k.first().copied().unwrap_or_else(T::zero);
            axpy(col_j, -l_jk, col_k);
        }
        let Some((diagonal, below)) = col_j.split_first_mut() else {
            return false;
        };
        let d = *diagonal;
        // Written so that a NaN pivot (every comparison false) is refused.
        if !(d > T::zero() && d > relative_pivot * a_jj) {
            return false;
        }
        let l_jj = d.sqrt_rn();
        *diagonal = l_jj;
        for e in below {
            *e /= l_jj;
        }
    }
    true
}

/// `b ← (L Lᵀ)⁻¹ b` for the factor `l` (column-major `n × n`, lower triangle): forward
/// substitution `L y = b` ([`forward_in_place`]), then back substitution `Lᵀ x = y` by dot
/// products.
#[inline(never)]
pub(crate) fn solve_in_place<T: Real>(l: &[T], n: usize, b: &mut [T]) {
    if n == 0 {
        return;
    }
    forward_in_place(l, n, b);
    for i in (0..n).rev() {
        let Some(col) = l.get(i * n..i * n + n) else {
            continue;
        };
        let s = match (col.get(i + 1..), b.get(i + 1..)) {
            (Some(x), Some(y)) => dot(x, y),
            _ => T::zero(),
        };
        let diag = col.get(i).copied().unwrap_or_else(T::one);
        if let Some(b_i) = b.get_mut(i) {
            *b_i = (*b_i - s) / diag;
        }
    }
}

/// `b ← L⁻¹ b` for the lower-triangular `l` (column-major `n × n`): forward substitution by
/// columns, `y_i = b_i / L_ii`, then `b_k −= L_ki y_i` for `k > i`. Each `y_i` costs `n − i`
/// multiply-adds and one division; it is backward stable (the computed `y` solves
/// `(L + δL) y = b` with `|δL| ≤ n ε |L|`). Inlined, so that a caller with `n` a constant gets
/// it unrolled.
///
/// ```text
/// L = [2 0; 1 1], b = [4, 3]  →  y = [2, 1]
/// ```
#[inline(always)]
pub(crate) fn forward_in_place<T: Real>(l: &[T], n: usize, b: &mut [T]) {
    for (i, col) in columns(l, n).enumerate().take(n) {
        let diag = col.get(i).copied().unwrap_or_else(T::one);
        let Some(b_i) = b.get_mut(i) else { break };
        let y_i = *b_i / diag;
        *b_i = y_i;
        if let (Some(rest), Some(below)) = (b.get_mut(i + 1..), col.get(i + 1..)) {
            axpy(rest, -y_i, below);
        }
    }
}

/// `X ← (L Lᵀ)⁻¹ = L⁻ᵀ L⁻¹` for the factor `l` (both column-major `n × n`): `X`'s upper
/// triangle first receives `Y = L⁻¹` transposed (`Y_jj = 1/L_jj`,
/// `Y_ij = −(Σ_{j≤k<i} L_ik Y_kj)/L_ii`), then `X_ij = Σ_{k ≥ max(i,j)} Y_ki Y_kj` row by row
/// from the top, each row of `Y` read before it is overwritten; the result is exactly
/// symmetric. `false` when an entry of the result is not finite.
#[inline(never)]
#[must_use]
pub(crate) fn inverse_into<T: Real>(l: &[T], n: usize, x: &mut [T]) -> bool {
    inverse_inline(l, n, x)
}

/// The body of [`inverse_into`].
#[inline(always)]
#[must_use]
fn inverse_inline<T: Real>(l: &[T], n: usize, x: &mut [T]) -> bool {
    if l.len() != n * n || x.len() != n * n {
        return false;
    }
    let at = |s: &[T], i: usize, j: usize| s.get(j * n + i).copied().unwrap_or_else(T::zero);
    // Yᵀ into the upper triangle of x: x[j, i] = Y_ij for i ≥ j.
    for j in 0..n {
        let y_jj = T::one() / at(l, j, j);
        if let Some(e) = x.get_mut(j * n + j) {
            *e = y_jj;
        }
        for i in j + 1..n {
            let mut acc = T::zero();
            for k in j..i {
                acc += at(l, i, k) * at(x, j, k);
            }
            let y_ij = -acc / at(l, i, i);
            if let Some(e) = x.get_mut(i * n + j) {
                *e = y_ij;
            }
        }
    }
    // X_ij = Σ_{k ≥ j} Y_ki Y_kj for i ≤ j (Y_ki = x[i, k] above the diagonal): row i of X
    // needs rows i.. of Yᵀ, so rows are finished from the top and mirrored below.
    for i in 0..n {
        for j in i..n {
            let mut acc = T::zero();
            for k in j..n {
                acc += at(x, i, k) * at(x, j, k);
            }
            if let Some(e) = x.get_mut(j * n + i) {
                *e = acc;
            }
        }
        for j in i + 1..n {
            let v = at(x, i, j);
            if let Some(e) = x.get_mut(i * n + j) {
                *e = v;
            }
        }
    }
    all_finite(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::Rng;
    use nalgebra::{DMatrix, DVector};

    fn spd(rng: &mut Rng, n: usize) -> DMatrix<f64> {
        let b = DMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        &b * b.transpose() + DMatrix::identity(n, n) * 0.1
    }

    /// Backward stability of Cholesky (Higham Thm 10.3): `L Lᵀ = A + ΔA`,
    /// `|ΔA| ≤ γ_{n+1} |L||Lᵀ|`; checked entry by entry.
    #[test]
    fn factor_reproduces_a_within_the_backward_error_bound() {
        let mut rng = Rng::new(11);
        for n in 1..=8 {
            for _ in 0..50 {
                let a = spd(&mut rng, n);
                let mut l = a.clone();
                assert!(factor_in_place(l.as_mut_slice(), n, 0.0));
                let l = l.lower_triangle();
                let k = (n + 1) as f64 * f64::EPSILON;
                let gamma = k / (1.0 - k);
                let bound = (l.abs() * l.transpose().abs()) * gamma;
                let err = (&l * l.transpose() - &a).abs();
                assert!(err.iter().zip(bound.iter()).all(|(e, b)| e <= b), "n = {n}");
            }
        }
    }

    /// The solve and the inverse against nalgebra's Cholesky, to `κ(A)·n·ε` relative error.
    #[test]
    fn solve_and_inverse_agree_with_nalgebra() {
        let mut rng = Rng::new(12);
        for n in 1..=8 {
            let a = spd(&mut rng, n);
            let mut l = a.clone();
            assert!(factor_in_place(l.as_mut_slice(), n, 0.0));
            let chol = a.clone().cholesky().expect("spd");
            let svd = a.clone().svd(false, false);
            let kappa = svd.singular_values.max() / svd.singular_values.min();
            let tol = kappa * 8.0 * n as f64 * f64::EPSILON;

            let b = DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0));
            let mut x = b.clone();
            solve_in_place(l.as_slice(), n, x.as_mut_slice());
            let expected = chol.solve(&b);
            assert!((&x - &expected).norm() <= tol * expected.norm());

            let mut inv = DMatrix::zeros(n, n);
            assert!(inverse_into(l.as_slice(), n, inv.as_mut_slice()));
            assert_eq!(inv, inv.transpose());
            let expected = chol.inverse();
            assert!((&inv - &expected).norm() <= tol * expected.norm());
        }
    }

    /// The unrolled 3 × 3 factor within the backward error bound of
    /// `factor_reproduces_a_within_the_backward_error_bound`, and its refusals (an indefinite or
    /// non-finite `S`).
    #[test]
    fn spd_factor_3_reproduces_s_and_refuses_what_the_factor_refuses() {
        let mut rng = Rng::new(13);
        let k = 4.0 * f64::EPSILON;
        let gamma = k / (1.0 - k);
        for _ in 0..200 {
            let a = spd(&mut rng, 3);
            let s: [f64; 9] = core::array::from_fn(|i| a[(i % 3, i / 3)]);
            let mut l = [0.0; 9];
            assert!(spd_factor_3(&s, &mut l));
            let l = DMatrix::from_column_slice(3, 3, &l).lower_triangle();
            let bound = (l.abs() * l.transpose().abs()) * gamma;
            let err = (&l * l.transpose() - &a).abs();
            assert!(err.iter().zip(bound.iter()).all(|(e, b)| e <= b));
        }
        let mut l = [0.0; 9];
        let indefinite = [1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert!(!spd_factor_3(&indefinite, &mut l));
        let non_finite = [1.0, 0.0, 0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0, 1.0];
        assert!(!spd_factor_3(&non_finite, &mut l));
    }

    #[test]
    fn factor_refuses_indefinite_singular_and_non_finite() {
        let indefinite = [1.0, 2.0, 2.0, 1.0];
        assert!(!factor_in_place(&mut indefinite.clone(), 2, 0.0));
        // Rank one: the second pivot is zero up to rounding, below 16·2·ε of A_11.
        let singular = [1.0, 1.0, 1.0, 1.0 + 1e-17];
        assert!(!factor_in_place(
            &mut singular.clone(),
            2,
            32.0 * f64::EPSILON
        ));
        for bad in [f64::NAN, f64::INFINITY] {
            assert!(!factor_in_place(&mut [1.0, bad, bad, 1.0], 2, 0.0));
        }
        assert!(!factor_in_place(&mut [f64::NAN], 1, 0.0));
        assert!(!factor_in_place(&mut [1.0, 0.0, 0.0], 2, 0.0)); // wrong length
    }
}

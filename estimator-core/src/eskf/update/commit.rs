//! Steps 3–4 of the [update](super): the posterior covariance `P − W Wᵀ`, the injection
//! `x⁺ = x̂ ⊕ δx` and the covariance reset.

use super::work::{attitude_part, Work};
use crate::eskf::covariance::attitude_floor;
use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::kernels::block::{block, copy};
use crate::kernels::{mat3, usable_variance};
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The posterior covariance, injection and reset; writes `x` and `P` only when every check
/// passed.
///
/// With the optimal gain the Joseph form `P⁺ = (I − KH)P(I − KH)ᵀ + K R Kᵀ` is
/// `P − U S⁻¹ Uᵀ = P − W Wᵀ = P − Σ_c w_c w_cᵀ` (`U = P Hᵀ`, `W = U L⁻ᵀ`, [`super::gain`]):
/// `m` symmetric rank-one downdates, exactly symmetric, computed in place on the upper
/// triangle and mirrored, without an `N × N` temporary. `(W Wᵀ)_jj ≤ P_jj`, so no term is
/// larger than `P` and the rounding stays a few `ε √(P_ii P_jj)` per entry; the expanded
/// Joseph form `P + V Kᵀ + K Vᵀ` (`V = ½ K S − U`) has terms that grow with the condition of
/// `S`, and left `P` indefinite where two rows of `H` were nearly parallel. Then
/// `P⁺ ← G P⁺ Gᵀ`, `G = blockdiag(J_r(δθ), I)`: only the attitude rows and columns change. The
/// new attitude block gets its floor ([`attitude_floor`]). A correction with `|δθ| ≥ π` is
/// refused: there `exp` is no longer one-to-one and `J_r(δθ)` approaches singularity (at `2π`).
#[inline(never)]
pub(super) fn commit<T, S, const N: usize, const C: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    w: &mut Work<T, N, C>,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    let new_x = x.oplus(&w.dx);
    let half = T::lit(0.5);
    let wcols = &w.g.w.data.0;
    // The checks, before anything is written. W and P are finite, so P⁺ can only fail by
    // overflow or by rounding below zero; for a positive semi-definite P⁺,
    // |P⁺_ij| ≤ √(P⁺_ii P⁺_jj), so a finite positive diagonal bounds every entry. From row 3
    // on, P⁺_jj = P_jj − Σ_c w_cj² (the reset leaves it); the attitude block is G₀ M G₀ᵀ,
    // M = P₀₀ − Σ_c (w_c w_cᵀ)₀₀, G₀ = J_r(δθ), made exactly symmetric.
    let mut m00 = block(p, 0, 0);
    for wc in wcols.iter() {
        let a = attitude_part(wc);
        m00 -= a * a.transpose();
    }
    let diagonal_ok = p.data.0.iter().enumerate().skip(3).all(|(j, pc)| {
        let d = wcols
            .iter()
            .fold(T::zero(), |acc, wc| acc + at(wc, j) * at(wc, j));
        usable_variance(at(pc, j) - d)
    });
    let dtheta = attitude_part(w.dx.as_slice());
    let gr: Matrix3<T> = So3::right_jacobian(&dtheta);
    let c00 = mat3::mul(&mat3::mul(&gr, &m00), &gr.transpose());
    let c00 = (c00 + c00.transpose()) * half;
    let c00 = c00 + Matrix3::from_diagonal_element(attitude_floor(&c00));
    let diagonal_ok = diagonal_ok && usable_variance(c00.m11) && usable_variance(c00.m22);
    // The correction stays inside the chart: below π the exponential map is one-to-one and
    // J_r(δθ) regular; at 2π it is singular, and the reset G P Gᵀ with it is not definite.
    let in_chart = dtheta.dot(&dtheta) < T::pi() * T::pi();
    if !(in_chart && new_x.is_finite() && diagonal_ok && usable_variance(c00.m33)) {
        return Err(EskfError::NumericalFailure);
    }
    // The upper triangle (column j holds rows 0..=j): P_ij −= Σ_c w_ci w_cj; then the attitude
    // rows of the columns from 3 on multiplied by J_r(δθ), the attitude block replaced by
    // `c00`, and the upper triangle mirrored below.
    let cols = &mut p.data.0;
    downdate_upper(cols, wcols);
    for (pc, c) in cols.iter_mut().zip(c00.data.0.iter()) {
        if let Some(head) = pc.get_mut(0..3) {
            copy(head, c);
        }
    }
    for pc in cols.iter_mut().skip(3) {
        if let Some(head) = pc.first_chunk_mut::<3>() {
            *head = mat3::mul_vec(&gr, &Vector3::from(*head)).into();
        }
    }
    for j in 1..N {
        let Some((left, right)) = cols.split_at_mut_checked(j) else {
            break;
        };
        let Some(col_j) = right.first() else {
            break;
        };
        for (col_i, upper) in left.iter_mut().zip(col_j.iter()) {
            if let Some(e) = col_i.get_mut(j) {
                *e = *upper;
            }
        }
    }
    *x = new_x;
    Ok(())
}

/// `P_ij −= Σ_c w_ci w_cj` on the upper triangle (`i ≤ j`) of the columns `cols`, over all `C`
/// columns of `w` (those past the active rows are zero and take nothing). Each column of `P` is
/// swept once with its `C` entries `w_cj` in registers: with `C` a constant the sum over `c`
/// unrolls. A model with fewer rows pays for the zero columns so that one copy serves every
/// row count.
#[inline(always)]
fn downdate_upper<T: Real, const N: usize, const C: usize>(
    cols: &mut [[T; N]; N],
    w: &[[T; N]; C],
) {
    for (j, pc) in cols.iter_mut().enumerate() {
        let mut wj = [T::zero(); C];
        for (a, wc) in wj.iter_mut().zip(w) {
            *a = at(wc, j);
        }
        for (i, e) in pc.iter_mut().enumerate().take(j + 1) {
            let mut acc = *e;
            for (wc, a) in w.iter().zip(wj.iter()) {
                acc -= at(wc, i) * *a;
            }
            *e = acc;
        }
    }
}

/// `s[i]`, or zero past the end (never reached: every caller indexes below the length).
#[inline(always)]
fn at<T: Real>(s: &[T], i: usize) -> T {
    s.get(i).copied().unwrap_or_else(T::zero)
}

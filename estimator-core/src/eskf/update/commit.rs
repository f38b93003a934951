//! Steps 3–4 of the [update](super): the Joseph-form covariance, the injection `x⁺ = x̂ ⊕ δx`
//! and the covariance reset.

use super::work::{attitude_part, Work};
use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::kernels::slice::axpy;
use crate::kernels::{mat3, positive_finite};
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// Joseph-form covariance, injection and reset; writes `x` and `P` only when every check
/// passed. Overwrites `U` with `V`.
///
/// The Joseph form `P⁺ = (I − KH)P(I − KH)ᵀ + K R Kᵀ`, expanded with `U = P Hᵀ` and `S = H U + R`,
/// is `P − K Uᵀ − U Kᵀ + K S Kᵀ = P + V Kᵀ + K Vᵀ = P + Σ_c (v_c k_cᵀ + k_c v_cᵀ)` with
/// `V = ½ K S − U`: `m` symmetric rank-2 corrections, exactly symmetric, computed in place without
/// an `N × N` temporary. Then `P⁺ ← G P⁺ Gᵀ`, `G = blockdiag(J_r(δθ), I)`: only the attitude
/// rows and columns change.
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
    if N < 3 {
        return Err(EskfError::NumericalFailure); // no filter has such a state
    }
    let n = N;
    let (m, u, k, s) = (w.m, w.g.u.as_mut_slice(), w.g.k.as_slice(), &w.g.s);
    for (c, vc) in u.chunks_exact_mut(n).enumerate().take(m) {
        vc.iter_mut().for_each(|e| *e = -*e);
        for (j, kj) in k.chunks_exact(n).enumerate().take(m) {
            let sjc = s.get((j, c)).copied().unwrap_or_else(T::zero);
            axpy(vc, sjc * T::lit(0.5), kj);
        }
    }
    let v: &[T] = u;
    let pairs = || v.chunks_exact(n).zip(k.chunks_exact(n)).take(m);
    // Attitude rows of P⁺ (column j: P[0..3, j] + Σ_c (v_c[0..3] k_c[j] + k_c[0..3] v_c[j])),
    // then multiplied by J_r(δθ). K, U, S and P are finite, so P⁺ can only fail by overflow;
    // for a positive semi-definite P⁺, |P⁺_ij| ≤ √(P⁺_ii P⁺_jj), so a finite positive diagonal
    // bounds every entry. The diagonal from row 3 on is checked here as
    // `P_jj + 2 Σ_c v_cj k_cj`.
    let gr: Matrix3<T> = So3::right_jacobian(&attitude_part(w.dx.as_slice()));
    let two = T::lit(2.0);
    let mut diagonal_ok = true;
    let mut top = [Vector3::<T>::zeros(); N];
    for (j, (t, pc)) in top.iter_mut().zip(p.as_slice().chunks_exact(n)).enumerate() {
        let mut c0 = attitude_part(pc);
        let mut d = T::zero();
        for (vc, kc) in pairs() {
            let (vj, kj) = (at(vc, j), at(kc, j));
            for (e, (a, b)) in c0.iter_mut().zip(vc.iter().zip(kc)) {
                *e += *a * kj + *b * vj;
            }
            d += vj * kj;
        }
        if j >= 3 {
            diagonal_ok &= positive_finite(at(pc, j) + d * two);
        }
        *t = mat3::mul_vec(&gr, &c0);
    }
    let c00 = match top.first_chunk::<3>() {
        Some(t012) => mat3::mul(&Matrix3::from_columns(t012), &gr.transpose()),
        None => return Err(EskfError::NumericalFailure),
    };
    let c00 = (c00 + c00.transpose()) * T::lit(0.5);
    let diagonal_ok = diagonal_ok && (0..3).all(|i| positive_finite(at(c00.as_slice(), 4 * i)));
    if !(new_x.is_finite() && diagonal_ok) {
        return Err(EskfError::NumericalFailure);
    }
    // Rows and columns 3.. of P⁺, upper triangle (column j holds entries (0..=j, j)):
    // P_ij += v_i k_j + k_i v_j for each active c, 3 ≤ i ≤ j; mirrored below.
    let ps = p.as_mut_slice();
    for (vc, kc) in pairs() {
        for (j, pc) in ps.chunks_exact_mut(n).enumerate() {
            let (vj, kj) = (at(vc, j), at(kc, j));
            let (Some(pc), Some(vs), Some(ks)) = (pc.get_mut(3..=j), vc.get(3..=j), kc.get(3..=j))
            else {
                continue;
            };
            for (e, (vi, ki)) in pc.iter_mut().zip(vs.iter().zip(ks)) {
                *e += *vi * kj + *ki * vj;
            }
        }
    }
    // Rows 0..3 from `top` (column j of those rows is top[j]), block (0, 0) from the exactly
    // symmetric `c00`, then the upper triangle mirrored.
    for (t, c) in top.iter_mut().zip(c00.as_slice().chunks_exact(3)) {
        for (d, e) in t.iter_mut().zip(c) {
            *d = *e;
        }
    }
    for (col, t) in ps.chunks_exact_mut(n).zip(top.iter()) {
        if let Some(head) = col.get_mut(0..3) {
            head.copy_from_slice(t.as_slice());
        }
    }
    for j in 1..n {
        for i in 0..j {
            let upper = at(ps, j * n + i);
            if let Some(e) = ps.get_mut(i * n + j) {
                *e = upper;
            }
        }
    }
    *x = new_x;
    Ok(())
}

/// `s[i]`, or zero past the end (never reached: every caller indexes below the length).
fn at<T: Real>(s: &[T], i: usize) -> T {
    s.get(i).copied().unwrap_or_else(T::zero)
}

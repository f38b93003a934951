//! The gain `K = P H̃ᵀ S⁻¹`, in square-root form (`S = L Lᵀ`, `W = P H̃ᵀ L⁻ᵀ`, `K = W L⁻¹`),
//! the NIS and gate at the prior, and the Gauss-Newton step of the iterated update (steps 1–2
//! of the [module docs](super)).

use super::options::UpdateOptions;
use super::work::Work;
use crate::eskf::error::{EskfError, UpdateOutcome};
use crate::kernels::cholesky::{factor_in_place, forward_in_place, spd_factor_3};
use crate::kernels::slice::{axpy, distance, dot, mat_vec};
use crate::kernels::{all_finite, larger, slice::symmetrize};
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// The noise floor `f = 256 N ε` (`N` the error-state size): the smallest variance an update may
/// leave on the combination `h_cᵀ δx` that row `c` measures, as a fraction of
/// `w_c = Σ_i H_ci² P_ii`, the variance that combination would have if the states it reads
/// were uncorrelated.
///
/// Rounding moves each entry of `P⁺` by a few `ε √(P_ii P_jj)`: a few `Nε` on the correlation
/// matrix `C = D^-½ P D^-½` (`D = diag P`), so `P⁺` stays positive definite while the smallest
/// eigenvalue of its correlation matrix stays well above `Nε`. The combination's variance,
/// relative to `w_c`, is such an eigenvalue's scale: a measurement far more precise than its
/// prior (in `f32`, a heading of σ = 1e-5 rad against 0.1 rad; in `f64`, an accelerometer with
/// no noise), or the same combination measured again and again (tilt against accelerometer bias
/// at rest, with no process noise to loosen it), takes it below rounding and leaves `P`
/// indefinite. So with `p_c = (H P Hᵀ)_cc` the row's variance is raised to
///
/// ```text
/// R_eff,cc = max(R_cc, f w_c p_c / max(p_c − f w_c, ε p_c))
/// ```
///
/// which keeps the posterior `p_c R / (p_c + R)` at `f w_c` or above; a combination already at
/// the floor (`p_c ≤ f w_c`) is fused with `R_eff = f w_c / ε`, which shrinks it by about `ε`
/// per update. `R_eff = R + diag(…)` is positive definite whenever `R` is and never smaller.
///
/// Each row adds at most `w_c / R_eff ≤ 1/f` to the largest eigenvalue of `C⁻¹`, so an update
/// leaves `λ_min(C⁺) ≥ 1 / (1/λ_min(C) + M/f)`; `f/M` must clear the rounding of `C⁺`, about
/// `(2M + 2) N ε` per update for `M ≤ 3` rows, with room for the prior's own: `256 N ε` is ten
/// times that (a camera update with σ = 1e-6 px after another left `P` indefinite in `f64` at
/// `64 N ε`). In `f64`, `f = 8.5e-13` (σ ratio 9e-7): it acts on no real sensor. In `f32`,
/// `f = 4.6e-4` (σ ratio 0.021): a 1 m fix after a position prior of 1 km is fused as a 21 m
/// fix, and the next one at its own σ.
const NOISE_FLOOR: f64 = 256.0;

/// The noise floor's fraction `f = 256 N ε` for a filter of `N` states ([`NOISE_FLOOR`]).
pub(super) fn noise_floor<T: Real, const N: usize>() -> T {
    T::lit(NOISE_FLOOR * T::EPSILON_F64 * N as f64)
}

/// The gain in square-root form into `w.g`: `U = P H̃ᵀ`, `S = H̃ U + R_eff = L Lᵀ` (Cholesky),
/// and `W = U L⁻ᵀ`, over the `m` active columns of the working set only; the covariance `p`, the
/// `m × m` noise `noise` (column-major).
///
/// With them the gain is `K = U S⁻¹ = W L⁻¹`, so the correction is `δx = K r = W y` with the
/// whitened residual `y = L⁻¹ r` ([`whitened`]), the NIS is `rᵀ S⁻¹ r = ‖y‖²`, and the
/// posterior is `P⁺ = P − U S⁻¹ Uᵀ = P − W Wᵀ` ([`super::commit`]). Neither `S⁻¹` nor `K` is
/// formed: where the rows of `H` are nearly parallel (`S` ill-conditioned, `κ(S)` up to the
/// noise floor's `M/f`), `K` and `K S Kᵀ` grow with `κ(S)` while `W Wᵀ ≤ P` entry by entry, so
/// the rounding of `P⁺` stays a few `ε √(P_ii P_jj)`, the size the floors are set against.
/// The computed `W` is the exact one of an `S` moved by a few `ε √(S_ii S_jj)` (Cholesky and
/// triangular solves are backward stable), that is of a noise `R_eff` moved by a fraction
/// `ε/f` of its floor: `P − W Wᵀ` is the posterior of a slightly different, still positive
/// definite, noise.
///
/// The matrices are walked as arrays of columns (`[[T; N]; C]`), never as run-time chunks of a
/// slice: no length is divided by a chunk size, so no panic path depends on what the optimizer
/// inlines.
#[inline(never)]
fn gain_into<T: Real, const N: usize, const C: usize>(
    p: &SMatrix<T, N, N>,
    noise: &[T],
    w: &mut Work<T, N, C>,
) -> Result<(), EskfError> {
    let (m, ht) = (w.m, &w.ht.data.0);
    let u = &mut w.g.w.data.0;
    // Column c of U = Σ_j P e_j H_cj over the nonzero entries of row c of H only (most models
    // touch 3–6 of the 15 error components).
    // With it, w_c = Σ_j H_cj² P_jj for the noise floor.
    for uc in u.iter_mut() {
        uc.fill(T::zero());
    }
    let mut wc = [T::zero(); C];
    for ((uc, hc), w) in u.iter_mut().zip(ht.iter()).zip(wc.iter_mut()).take(m) {
        for (j, (pc, h)) in p.data.0.iter().zip(hc).enumerate() {
            if *h != T::zero() {
                axpy(uc, *h, pc);
                *w += *h * *h * pc.get(j).copied().unwrap_or_else(T::zero);
            }
        }
    }
    // S_ij = R_ij + (row i of H)·(column j of U) for i, j < m; the identity padding stays.
    // On the diagonal R_cc is raised to the noise floor ([`NOISE_FLOOR`]).
    let mut s = padded_noise::<T, C>(noise, m);
    let floor = noise_floor::<T, N>();
    for (j, (uc, w)) in u.iter().zip(wc).enumerate().take(m) {
        for (i, hc) in ht.iter().enumerate().take(m) {
            if let Some(e) = s.get_mut((i, j)) {
                let hph = dot(hc, uc);
                *e = if i == j {
                    // max(R_cc, …) by comparison: `max` is a libm call on a Cortex-M4F.
                    let low = floor * w;
                    let room = larger(hph - low, hph * T::lit(T::EPSILON_F64));
                    let least = low * hph / room;
                    hph + if least > *e { least } else { *e }
                } else {
                    *e + hph
                };
            }
        }
    }
    symmetrize(s.as_mut_slice(), C);
    // S = L Lᵀ (C × C; the 3 × 3 of every model up to three rows through the unrolled kernel).
    let l = &mut w.g.l;
    let factored = match (
        s.as_slice().first_chunk::<9>(),
        l.as_mut_slice().first_chunk_mut::<9>(),
    ) {
        (Some(s3), Some(l3)) if C == 3 => spd_factor_3(s3, l3),
        _ => {
            *l = s;
            factor_in_place(l.as_mut_slice(), C, T::zero())
        }
    };
    if !factored {
        return Err(EskfError::SingularInnovation);
    }
    // W Lᵀ = U, column by column: w_c = (u_c − Σ_{k<c} L_ck w_k) / L_cc, in place of U: the
    // forward substitution of [`forward_in_place`] with N-vectors for entries, one sweep for all
    // N rows of U.
    for c in 0..m {
        let Some((done, rest)) = u.split_at_mut_checked(c) else {
            break;
        };
        let Some(wc) = rest.first_mut() else {
            break;
        };
        for (k, wk) in done.iter().enumerate() {
            axpy(wc, -l.get((c, k)).copied().unwrap_or_else(T::zero), wk);
        }
        let inverse = T::one() / l.get((c, c)).copied().unwrap_or_else(T::one);
        wc.iter_mut().for_each(|e| *e *= inverse);
    }
    if !all_finite(w.g.w.as_slice()) {
        return Err(EskfError::SingularInnovation);
    }
    Ok(())
}

/// `y = L⁻¹ v` ([`forward_in_place`]): the whitened residual of [`gain_into`]. Past the `m`
/// active rows `L` is the identity and `v` zero, so `y` is zero there too.
fn whitened<T: Real, const C: usize>(l: &SMatrix<T, C, C>, v: &SVector<T, C>) -> SVector<T, C> {
    let mut y = *v;
    forward_in_place(l.as_slice(), C, y.as_mut_slice());
    y
}

/// The gain at the prior, the NIS `‖L⁻¹ r‖²` and the gate, then `δx₁ = W L⁻¹ r₀` into `w.dx`.
/// Returns `Rejected`, or `Accepted` with the NIS (its iteration count is set by the caller).
pub(super) fn gate_step<T: Real, const N: usize, const C: usize>(
    p: &SMatrix<T, N, N>,
    noise: &[T],
    m: usize,
    opts: &UpdateOptions<T>,
    w: &mut Work<T, N, C>,
) -> Result<UpdateOutcome<T>, EskfError> {
    gain_into(p, noise, w)?;
    let y = whitened(&w.g.l, &w.r);
    let nis = dot(y.as_slice(), y.as_slice());
    if !nis.is_finite() {
        return Err(EskfError::SingularInnovation);
    }
    let threshold = opts.gate.threshold(m);
    if nis > threshold {
        return Ok(UpdateOutcome::Rejected { nis, threshold });
    }
    mat_vec(w.g.w.as_slice(), y.as_slice(), w.dx.as_mut_slice());
    Ok(UpdateOutcome::Accepted { nis, iterations: 1 })
}

/// One Gauss-Newton step after a re-linearization: the gain there, then
/// `δx_{k+1} = K_k (r_k + H̃_k δx_k) = W_k L_k⁻¹ (r_k + H̃_k δx_k)` into `w.dx`. `None` (with the
/// gain and `δx` as they were) when the gain or the step failed, else whether
/// `‖δx_{k+1} − δx_k‖ < tol`.
#[inline(never)]
pub(super) fn step<T: Real, const N: usize, const C: usize>(
    p: &SMatrix<T, N, N>,
    noise: &[T],
    opts: &UpdateOptions<T>,
    w: &mut Work<T, N, C>,
) -> Option<bool> {
    let saved = w.g;
    let ok = gain_into(p, noise, w).is_ok();
    // r + H̃ δx_k (row c of H̃ is column c of H̃ᵀ), whitened.
    let mut v = w.r;
    for (vc, hc) in v.iter_mut().zip(w.ht.data.0.iter()).take(w.m) {
        *vc += dot(hc, w.dx.as_slice());
    }
    let mut next = SVector::<T, N>::zeros();
    let y = whitened(&w.g.l, &v);
    mat_vec(w.g.w.as_slice(), y.as_slice(), next.as_mut_slice());
    if !(ok && all_finite(next.as_slice())) {
        w.g = saved;
        return None;
    }
    let converged = distance(next.as_slice(), w.dx.as_slice()) < opts.step_tolerance;
    w.dx = next;
    Some(converged)
}

/// `R` (`m × m`, column-major in `noise`) in the top-left of the `C × C` identity: the padded
/// noise of the [module docs](super) (`S_pad = [[S, 0], [0, I]]`). Entries missing from `noise`
/// stay those of the identity.
pub(super) fn padded_noise<T: Real, const C: usize>(noise: &[T], m: usize) -> SMatrix<T, C, C> {
    let mut r = SMatrix::<T, C, C>::identity();
    for j in 0..m {
        for i in 0..m {
            if let (Some(e), Some(v)) = (r.get_mut((i, j)), noise.get(j * m + i)) {
                *e = *v;
            }
        }
    }
    r
}

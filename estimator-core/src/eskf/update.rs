//! The generic measurement update: innovation, gate, Joseph-form covariance, iterated
//! (Gauss-Newton) re-linearization, injection through `⊕` and the covariance reset.

use super::error::{EskfError, UpdateOutcome};
use super::gate::{Gate, GateProbability};
use super::imu::{finite_vec, greater};
use super::state::ErrorState;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Cholesky, Matrix3, SMatrix, SVector, Vector3};

/// A measurement linearized at a state: the residual `r = z ⊖ h(x)` (for a vector measurement
/// `z − h(x)`; angles wrapped) and `H = ∂h(x ⊕ δx)/∂δx` at `δx = 0` (seed eq. 4.3 / Def. 4.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearization<T: Real, const N: usize, const M: usize> {
    /// `r = z ⊖ h(x)`.
    pub residual: SVector<T, M>,
    /// `H` (`M × N`), right Jacobian with respect to the error state.
    pub jacobian: SMatrix<T, M, N>,
}

/// A fixed-size measurement model `z = h(x) + n`, `n ~ N(0, R)`, for the nominal state `S` with an
/// `N`-dimensional error state.
pub trait Measurement<T: Real, S, const N: usize, const M: usize> {
    /// `r = z ⊖ h(x)` and `H` at `x`. Errors for non-finite data or a state where `h` is not
    /// defined (landmark behind the camera, heading at ±90° pitch, ...).
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, M>, EskfError>;

    /// The noise covariance `R` (must be symmetric positive definite).
    #[must_use]
    fn noise(&self) -> SMatrix<T, M, M>;
}

/// How an update is done: the gate, and the number of Gauss-Newton iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOptions<T: Real> {
    /// The chi-square gate on the NIS at the prior.
    pub gate: Gate<T>,
    /// Iteration cap, `≥ 1`; `1` is the plain (extended) update, more is the iterated update.
    pub max_iterations: u8,
    /// The iterated update stops when `‖δx_{k+1} − δx_k‖ <` this.
    pub step_tolerance: T,
}

impl<T: Real> Default for UpdateOptions<T> {
    /// Single-step update gated at 99.9 %.
    fn default() -> Self {
        Self::ekf(Gate::Probability(GateProbability::P999))
    }
}

impl<T: Real> UpdateOptions<T> {
    /// The plain single-linearization update with `gate`.
    #[must_use]
    pub fn ekf(gate: Gate<T>) -> Self {
        Self {
            gate,
            max_iterations: 1,
            step_tolerance: T::lit(1e-6),
        }
    }

    /// The iterated update (IEKF) with `gate`, at most `max_iterations` linearizations, stopping
    /// when the step changes by less than `step_tolerance`.
    #[must_use]
    pub fn iterated(gate: Gate<T>, max_iterations: u8, step_tolerance: T) -> Self {
        Self {
            gate,
            max_iterations,
            step_tolerance,
        }
    }
}

/// The checks every filter constructor makes on a given start: a valid configuration, a finite
/// state and a symmetric positive definite covariance.
pub(crate) fn check_start<T: Real, S: ErrorState<T, N>, const N: usize>(
    state: &S,
    covariance: &SMatrix<T, N, N>,
    config: &super::imu::FilterConfig<T>,
) -> Result<(), EskfError> {
    config.validate()?;
    if !state.is_finite() {
        return Err(EskfError::NonFinite);
    }
    if !check_spd(covariance) {
        return Err(EskfError::CovarianceNotPositiveDefinite);
    }
    Ok(())
}

/// Checks that `A` is finite, symmetric (to `1e-6` of its largest entry) and positive definite,
/// by an in-place Cholesky factorization of one copy (no other `N × N` temporary).
pub(crate) fn check_spd<T: Real, const M: usize>(r: &SMatrix<T, M, M>) -> bool {
    if !finite_vec(r) {
        return false;
    }
    let tol = r.amax() * T::lit(1e-6);
    for (i, col) in r.column_iter().enumerate() {
        for (j, v) in col.iter().enumerate().skip(i + 1) {
            // v = A(j, i); compare with A(i, j).
            match r.get((i, j)) {
                Some(w) if (*v - *w).abs() <= tol => {}
                _ => return false,
            }
        }
    }
    if M <= PACKED_MAX_DIM {
        cholesky_packed(r)
    } else {
        Cholesky::new(*r).is_some()
    }
}

/// Largest dimension whose Cholesky test uses the packed lower triangle.
const PACKED_MAX_DIM: usize = 15;

/// Cholesky test (`A = L Lᵀ` with a positive diagonal) storing only the lower triangle of `L`
/// (packed row by row: `(i, j) ↦ i(i+1)/2 + j`): 480 bytes for a 15 × 15 `f32` matrix instead of
/// a full copy.
#[inline(never)]
fn cholesky_packed<T: Real, const M: usize>(r: &SMatrix<T, M, M>) -> bool {
    let mut l = [T::zero(); PACKED_MAX_DIM * (PACKED_MAX_DIM + 1) / 2];
    let at =
        |l: &[T], i: usize, j: usize| l.get(i * (i + 1) / 2 + j).copied().unwrap_or_else(T::zero);
    for i in 0..M {
        for j in 0..=i {
            let mut s = r.get((i, j)).copied().unwrap_or_else(T::zero);
            for k in 0..j {
                s -= at(&l, i, k) * at(&l, j, k);
            }
            let v = if i == j {
                if !greater(s, T::zero()) {
                    return false;
                }
                s.sqrt()
            } else {
                s / at(&l, j, j)
            };
            if let Some(e) = l.get_mut(i * (i + 1) / 2 + j) {
                *e = v;
            }
        }
    }
    true
}

/// The working set of one update, kept in one place on the caller's stack and filled in place
/// by the phases below (each phase is a separate, non-inlined function, so their frames do not
/// add up: the peak stack stays small on a Cortex-M).
struct Work<T: Real, const N: usize, const M: usize> {
    /// `H̃` at the current iterate.
    h: SMatrix<T, M, N>,
    /// Residual `r = z ⊖ h(x̂ ⊕ δx)` at the current iterate.
    r: SVector<T, M>,
    /// `U = P H̃ᵀ`.
    u: SMatrix<T, N, M>,
    /// `S = H̃ P H̃ᵀ + R`.
    s: SMatrix<T, M, M>,
    /// `K = U S⁻¹`.
    k: SMatrix<T, N, M>,
    /// The current correction `δx`.
    dx: SVector<T, N>,
}

/// Linearizes at `x̂ ⊕ δx` (`δx` = `w.dx`) into `w.h`, `w.r`, with the chart Jacobian
/// `H̃ = H · blockdiag(J_r(δθ), I)` (the Jacobian of `h(x̂ ⊕ δx)` in `δx`, so that the iterated
/// update is Gauss-Newton in the chart at the prior `x̂`; `J_r(0) = I`).
#[inline(never)]
fn linearize_into<T, S, Mo, const N: usize, const M: usize>(
    model: &Mo,
    x: &S,
    w: &mut Work<T, N, M>,
    first: bool,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
    Mo: Measurement<T, S, N, M>,
{
    let lin = if first {
        model.linearize(x)?
    } else {
        model.linearize(&x.oplus(&w.dx))?
    };
    if !(finite_vec(&lin.residual) && finite_vec(&lin.jacobian)) {
        return Err(EskfError::NonFinite);
    }
    w.r = lin.residual;
    w.h = lin.jacobian;
    if !first {
        let dth: SVector<T, 3> = w.dx.fixed_rows::<3>(0).into_owned();
        let jr = So3::right_jacobian(&dth);
        let hth = w.h.fixed_columns::<3>(0) * jr;
        w.h.fixed_columns_mut::<3>(0).copy_from(&hth);
    }
    Ok(())
}

/// `U = P H̃ᵀ`, `S = H̃ U + R`, `K = U S⁻¹` into `w`; returns the Cholesky factor of `S`.
#[inline(never)]
fn gain_into<T: Real, const N: usize, const M: usize>(
    p: &SMatrix<T, N, N>,
    r_noise: &SMatrix<T, M, M>,
    w: &mut Work<T, N, M>,
) -> Result<SMatrix<T, M, M>, EskfError> {
    // U = P Hᵀ = Σ_k P e_k (H e_k)ᵀ over the nonzero columns of H only (most models touch 3–6
    // of the 15 error components).
    w.u.fill(T::zero());
    for (pc, hc) in p.column_iter().zip(w.h.column_iter()) {
        if hc.iter().any(|v| *v != T::zero()) {
            w.u.ger(T::one(), &pc, &hc, T::one());
        }
    }
    w.s.copy_from(r_noise);
    w.s.gemm(T::one(), &w.h, &w.u, T::one());
    let st = w.s.transpose();
    w.s += st;
    w.s *= T::lit(0.5);
    let chol = Cholesky::new(w.s).ok_or(EskfError::SingularInnovation)?;
    // K = U S⁻¹ with S⁻¹ from the Cholesky factor (M × M, small).
    let s_inv = chol.inverse();
    w.k.gemm(T::one(), &w.u, &s_inv, T::zero());
    if !finite_vec(&w.k) {
        return Err(EskfError::SingularInnovation);
    }
    Ok(s_inv)
}

/// The generic update on `(x, P)`; `x` and `P` are written only when the result is `Accepted`.
///
/// 1. Linearize at the prior: `r₀ = z ⊖ h(x̂)`, `H₀`; `S = H₀ P H₀ᵀ + R`;
///    `NIS = r₀ᵀ S⁻¹ r₀` (seed Remark 4.2); gate `NIS ≤ χ²_M(p)` or return `Rejected`.
/// 2. `δx₁ = K₀ r₀`, `K = P Hᵀ S⁻¹`. Iterated: at `x_k = x̂ ⊕ δx_k` linearize again,
///    `H̃_k = H_k·blockdiag(J_r(δθ_k), I)`, `δx_{k+1} = K_k (r_k + H̃_k δx_k)`: the Gauss-Newton
///    step (seed eqs. 4.3–4.4) for `‖δx‖²_P + ‖z ⊖ h(x̂ ⊕ δx)‖²_R`; stop when
///    `‖δx_{k+1} − δx_k‖ < tol` or at the cap.
/// 3. Joseph form, expanded so that it costs `O(N²M)`:
///    `P⁺ = (I − KH)P(I − KH)ᵀ + K R Kᵀ = P − K Uᵀ − U Kᵀ + K S Kᵀ = P + X + Xᵀ`,
///    `U = P Hᵀ`, `X = (½ K S − U) Kᵀ`, computed in place entry by entry (exactly symmetric, no
///    `N × N` temporary).
/// 4. Inject `x⁺ = x̂ ⊕ δx` (seed eq. 4.5) and reset `P ← G P Gᵀ`,
///    `G = blockdiag(J_r(δθ), I)` (the new error `e⁺ = log(exp(δθ)⁻¹ exp(e)) ≈ J_r(δθ)(e − δθ)`).
pub(crate) fn update<T, S, Mo, const N: usize, const M: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    model: &Mo,
    opts: &UpdateOptions<T>,
) -> Result<UpdateOutcome<T>, EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
    Mo: Measurement<T, S, N, M>,
{
    if opts.max_iterations == 0 || !opts.step_tolerance.is_finite() {
        return Err(EskfError::InvalidOption);
    }
    if let Gate::Threshold(t) = opts.gate {
        if !(t.is_finite() || t > T::zero()) {
            return Err(EskfError::InvalidOption);
        }
    }
    let r_noise = model.noise();
    if !check_spd(&r_noise) {
        return Err(EskfError::NoiseNotPositiveDefinite);
    }
    let mut w = Work {
        h: SMatrix::zeros(),
        r: SVector::zeros(),
        u: SMatrix::zeros(),
        s: SMatrix::zeros(),
        k: SMatrix::zeros(),
        dx: SVector::zeros(),
    };
    linearize_into(model, x, &mut w, true)?;
    let s_inv = gain_into(p, &r_noise, &mut w)?;
    // NIS = rᵀ S⁻¹ r with the S⁻¹ already formed for K, and an explicit sum: `Cholesky::solve`
    // (dynamic-range `dot`s) and `dot` keep shape asserts, panic paths at opt-level "s".
    let y = s_inv * w.r;
    let nis =
        w.r.iter()
            .zip(y.iter())
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
    if !nis.is_finite() {
        return Err(EskfError::SingularInnovation);
    }
    let threshold = opts.gate.threshold(M);
    if nis > threshold {
        return Ok(UpdateOutcome::Rejected { nis, threshold });
    }
    w.dx = w.k * w.r;
    let iterations = iterate(x, p, model, opts, &r_noise, &mut w);
    commit(x, p, &w)?;
    Ok(UpdateOutcome::Accepted { nis, iterations })
}

/// The Gauss-Newton iterations (step 2 after the first): at `x̂ ⊕ δx_k`,
/// `δx_{k+1} = K_k (r_k + H̃_k δx_k)`. A failure to re-linearize stops at the last good iterate
/// (whose `K`, `U`, `S` are restored). Returns the number of linearizations used.
#[inline(never)]
fn iterate<T, S, Mo, const N: usize, const M: usize>(
    x: &S,
    p: &SMatrix<T, N, N>,
    model: &Mo,
    opts: &UpdateOptions<T>,
    r_noise: &SMatrix<T, M, M>,
    w: &mut Work<T, N, M>,
) -> u8
where
    T: Real,
    S: ErrorState<T, N>,
    Mo: Measurement<T, S, N, M>,
{
    let mut iterations: u8 = 1;
    while iterations < opts.max_iterations {
        let (u, s, k, prev) = (w.u, w.s, w.k, w.dx);
        let ok = linearize_into(model, x, w, false).is_ok() && gain_into(p, r_noise, w).is_ok();
        let y = w.r + w.h * prev;
        let next = w.k * y;
        if !(ok && finite_vec(&next)) {
            w.u = u;
            w.s = s;
            w.k = k;
            w.dx = prev;
            break;
        }
        w.dx = next;
        iterations += 1;
        if (next - prev).norm() < opts.step_tolerance {
            break;
        }
    }
    iterations
}

/// Steps 3–4: Joseph-form covariance, injection and reset; writes only when every check passed.
#[inline(never)]
fn commit<T, S, const N: usize, const M: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    w: &Work<T, N, M>,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    // Joseph form, expanded and written as a symmetric rank-2M correction:
    //   P⁺ = P − K Uᵀ − U Kᵀ + K S Kᵀ = P + V Kᵀ + K Vᵀ,  V = ½ K S − U,
    // i.e. P⁺_ij = P_ij + V_i·K_j + V_j·K_i (rows V_i, K_i): exactly symmetric, computed in place
    // without an N × N temporary. The checks below need only its diagonal and attitude rows.
    let mut v = w.u;
    v.gemm(T::lit(0.5), &w.k, &w.s, -T::one());
    // Attitude rows of P⁺ (column j: P[0..3, j] + V[0..3] Kⱼᵀ + K[0..3] Vⱼᵀ), then the reset
    // P⁺ ← G P⁺ Gᵀ, G = blockdiag(J_r(δθ), I): only the attitude rows and columns change.
    let dth: SVector<T, 3> = w.dx.fixed_rows::<3>(0).into_owned();
    let gr: Matrix3<T> = So3::right_jacobian(&dth);
    let v3 = v.fixed_rows::<3>(0);
    let k3 = w.k.fixed_rows::<3>(0);
    let mut top = p.fixed_rows::<3>(0).into_owned();
    for (mut c, (vj, kj)) in top.column_iter_mut().zip(v.row_iter().zip(w.k.row_iter())) {
        // Copy through `copy_from` (shape checked at compile time): `clone_owned` of a view goes
        // through nalgebra's `allocate_from_iterator`, whose length assert is a panic path
        // that opt-level "s" does not remove.
        let mut c0 = Vector3::<T>::zeros();
        c0.copy_from(&c);
        let col = gr * (c0 + v3 * kj.transpose() + k3 * vj.transpose());
        c.copy_from(&col);
    }
    let c00 = top.fixed_columns::<3>(0) * gr.transpose();
    let c00 = (c00 + c00.transpose()) * T::lit(0.5);
    let new_x = x.oplus(&w.dx);
    // K, U, S and P are finite, so P⁺ can only fail by overflow; for a positive semi-definite
    // P⁺, |P⁺_ij| ≤ √(P⁺_ii P⁺_jj), so a finite positive diagonal bounds every entry.
    let ok = |d: T| d.is_finite() && d > T::zero();
    let two = T::lit(2.0);
    let diag_ok = p
        .diagonal()
        .iter()
        .zip(v.row_iter().zip(w.k.row_iter()))
        .skip(3)
        .all(|(pii, (vi, ki))| ok(*pii + vi.dot(&ki) * two))
        && c00.diagonal().iter().all(|d| ok(*d));
    if !(new_x.is_finite() && diag_ok) {
        return Err(EskfError::NumericalFailure);
    }
    *x = new_x;
    // Upper triangle, mirrored: P_ij += V_i·K_j + K_i·V_j for i ≤ j (column-major slices:
    // entry (i, c) of an N-row matrix is at c·N + i). Half of the N²·2M products of the full
    // square, and exactly symmetric by construction.
    let vs = v.as_slice();
    let ks = w.k.as_slice();
    let at = |s: &[T], idx: usize| s.get(idx).copied().unwrap_or_else(T::zero);
    for j in 0..N {
        let kj: [T; M] = core::array::from_fn(|c| at(ks, c * N + j));
        let vj: [T; M] = core::array::from_fn(|c| at(vs, c * N + j));
        for (i, (vi, ki)) in v.row_iter().zip(w.k.row_iter()).enumerate().take(j + 1) {
            let (mut t, mut u) = (T::zero(), T::zero());
            for ((a, b), (c, d)) in vi.iter().zip(kj.iter()).zip(ki.iter().zip(vj.iter())) {
                t += *a * *b;
                u += *c * *d;
            }
            let ps = p.as_mut_slice();
            let mut new = T::zero();
            if let Some(e) = ps.get_mut(j * N + i) {
                *e += t + u;
                new = *e;
            }
            if let Some(e) = ps.get_mut(i * N + j) {
                *e = new;
            }
        }
    }
    // Rows 0..3 ← top, columns 0..3 ← topᵀ, block (0, 0) ← c00 (element by element: no
    // transposed temporary).
    for (j, col) in top.column_iter().enumerate() {
        for (a, v) in col.iter().enumerate() {
            let v = if j < 3 {
                c00.get((a, j)).copied().unwrap_or(*v)
            } else {
                *v
            };
            if let Some(e) = p.get_mut((a, j)) {
                *e = v;
            }
            if let Some(e) = p.get_mut((j, a)) {
                *e = v;
            }
        }
    }
    Ok(())
}

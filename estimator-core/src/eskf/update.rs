//! The generic measurement update: innovation, gate, Joseph-form covariance, iterated
//! (Gauss-Newton) re-linearization, injection through `⊕` and the covariance reset.

use super::error::{EskfError, UpdateOutcome};
use super::gate::{Gate, GateProbability};
use super::imu::{finite_vec, greater, sum_times_zero_is_zero};
use super::state::ErrorState;
use crate::gn::linalg::dot;
use crate::lie::{LieGroup, So3};
use crate::scalar::positive_finite;
use crate::Real;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

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

/// Checks that `A` is finite, symmetric (to `1e-6` of its largest entry) and positive definite:
/// the symmetry test, then the Cholesky factorization ([`factor_lower`]) of a copy.
pub(crate) fn check_spd<T: Real, const M: usize>(r: &SMatrix<T, M, M>) -> bool {
    let mut l = *r;
    finite_symmetric(r.as_slice(), M) && factor_lower(l.as_mut_slice(), M)
}

/// The largest error state (`Ins`, 15): the storage rows of the update's working set when built
/// for size (see [`update`]).
#[cfg_attr(not(any(estimator_compact, test)), allow(dead_code))]
pub(crate) const MAX_STATE: usize = 15;

/// `A = L Lᵀ` in place on the column-major storage `l` of an `n × n` matrix, operation for
/// operation as `nalgebra::Cholesky::new` (the same bits, failing exactly when it fails): column
/// by column, `a_ij ← (−l_jk) l_ik + a_ij` for `k < j ≤ i`, then `l_jj = √a_jj`, refused unless
/// `a_jj > 0` (zero, negative or NaN), and `l_ij = a_ij / l_jj` (`i > j`). Only the lower
/// triangle is read or written. Not generic over the size: one copy of this code serves the
/// covariance and noise checks and the innovation's inverse.
#[inline(never)]
pub(crate) fn factor_lower<T: Real>(l: &mut [T], n: usize) -> bool {
    for j in 0..n {
        // The columns before j, and rows j.. of column j (`col_j[0]` is the diagonal entry).
        let Some((before, rest)) = l.split_at_mut_checked(j * n) else {
            return false;
        };
        let Some(col_j) = rest.get_mut(j..n) else {
            return false;
        };
        for col_k in before.chunks_exact(n) {
            let col_k = col_k.get(j..).unwrap_or_default();
            let f = -at(col_k, 0);
            for (e, x) in col_j.iter_mut().zip(col_k) {
                *e = f * *x + *e;
            }
        }
        let Some((diagonal, below)) = col_j.split_first_mut() else {
            return false;
        };
        if !greater(*diagonal, T::zero()) {
            return false;
        }
        let d = diagonal.sqrt_rn();
        *diagonal = d;
        for e in below {
            *e /= d;
        }
    }
    true
}

/// `a` (column-major, `n × n`) is finite and symmetric to `1e-6` of its largest entry.
fn finite_symmetric<T: Real>(a: &[T], n: usize) -> bool {
    if a.len() != n * n || !slice_finite(a) {
        return false;
    }
    let tol = a.iter().fold(T::zero(), |m, x| m.max(x.abs())) * T::lit(1e-6);
    let get = |idx: usize| a.get(idx).copied().unwrap_or_else(T::zero);
    (0..n).all(|j| (j + 1..n).all(|i| (get(j * n + i) - get(i * n + j)).abs() <= tol))
}

/// Every entry of `a` is finite. Built for size, the shared out-of-line `Σ x·0 = 0` (the same
/// answer, 32 bytes less at opt-level "s"); at opt-level 2 or 3 the fold of `is_finite` stays
/// (its instruction counts are budgeted).
#[cfg(estimator_compact)]
#[inline(always)]
fn slice_finite<T: Real>(a: &[T]) -> bool {
    sum_times_zero_is_zero(a)
}

/// Every entry of `a` is finite (see the build for size above).
#[cfg(not(estimator_compact))]
#[inline(always)]
fn slice_finite<T: Real>(a: &[T]) -> bool {
    a.iter().fold(true, |acc, x| acc & x.is_finite())
}

/// Row capacity of the shared update core.
///
/// Every measurement with `M ≤ CORE_ROWS` rows runs through one compiled core per scalar type and
/// state (one for `Ins<f32>`, one for `Ahrs<f32>`, …) instead of one per measurement model: on a
/// Cortex-M4F the per-model copies of the update took about 35 KB of flash at opt-level "s". The
/// core sees a model through [`Rows`], with its residual and Jacobian padded by zero rows and its
/// noise padded by the identity, which leaves every result unchanged:
/// `S_pad = [[S, 0], [0, I]]`, `S_pad⁻¹ = [[S⁻¹, 0], [0, I]]`, `K_pad = [K, 0]`,
/// `NIS = r_padᵀ S_pad⁻¹ r_pad = rᵀ S⁻¹ r`; the products whose cost grows with the number of rows
/// run over the `m = M` active rows only. A larger measurement (`M > CORE_ROWS`) gets a core of
/// its own size (`C = M`).
pub(crate) const CORE_ROWS: usize = 3;

/// A measurement model as the update core sees it: through a row capacity `C ≥ M`.
///
/// The core takes `&dyn Rows<T, S, N, R, C>`, so it is compiled once per `(T, S, N, R, C)`, not
/// once per model; only [`Padded::linearize_rows`] (the model's own `linearize` and a copy) is per model.
trait Rows<T: Real, S, const N: usize, const R: usize, const C: usize> {
    /// Linearizes at `x` into `w.ht = Hᵀ` (`N × C`, column-major in the first `N·C` entries of
    /// the storage; column `c` is row `c` of `H`, so that each row of `H` is contiguous) and
    /// `w.r`; the columns and rows past `M` are zero, and so is the rest of the storage. Nothing
    /// else in `w` is written.
    fn linearize_rows(&self, x: &S, w: &mut Work<T, R, C>) -> Result<(), EskfError>;
}

/// A model with `M` rows, seen through any capacity `C ≥ M`.
struct Padded<'a, Mo, const M: usize>(&'a Mo);

impl<T, S, Mo, const N: usize, const M: usize, const R: usize, const C: usize> Rows<T, S, N, R, C>
    for Padded<'_, Mo, M>
where
    T: Real,
    Mo: Measurement<T, S, N, M>,
{
    fn linearize_rows(&self, x: &S, w: &mut Work<T, R, C>) -> Result<(), EskfError> {
        // Borrowed inside the `Result`, not moved out of it: one copy of the linearization on
        // the stack instead of two (this frame is on the deepest path of the update).
        let lin = self.0.linearize(x);
        let lin = match &lin {
            Ok(lin) => lin,
            Err(e) => return Err(*e),
        };
        rows_into_work(lin.jacobian.as_slice(), lin.residual.as_slice(), w);
        Ok(())
    }
}

/// [`rows_into`] into the working set's `H̃ᵀ` and `r`: one pointer to pass from each model's
/// [`Padded::linearize_rows`] instead of two slices (fewer arguments on the stack per model).
#[cfg_attr(estimator_compact, inline(never))]
fn rows_into_work<T: Real, const R: usize, const C: usize>(
    h: &[T],
    r_in: &[T],
    w: &mut Work<T, R, C>,
) {
    rows_into(h, r_in, w.ht.as_mut_slice(), w.r.as_mut_slice());
}

/// Copies `H` (`m × n`, column-major in `h`, `m = r_in.len()`) into `ht` as `Hᵀ` (`n × C`,
/// column `c` = row `c` of `H`) and the residual into `r`, zeros past `m`. Not generic over the
/// model or its size: one copy of this code serves every model.
#[cfg_attr(estimator_compact, inline(always))] // into its one caller, rows_into_work
pub(crate) fn rows_into<T: Real>(h: &[T], r_in: &[T], ht: &mut [T], r: &mut [T]) {
    let m = r_in.len().max(1);
    let n = h.len() / m;
    ht.fill(T::zero());
    // Column j of H (entries j·m .. j·m + m) goes to row j of Hᵀ: entry (j, c) at c·n + j.
    for (j, col) in h.chunks_exact(m).enumerate() {
        for (c, v) in col.iter().enumerate() {
            if let Some(e) = ht.get_mut(c * n + j) {
                *e = *v;
            }
        }
    }
    r.fill(T::zero());
    for (d, s) in r.iter_mut().zip(r_in) {
        *d = *s;
    }
}

/// Copies the column-major `m × m` matrix `src` into the top-left of the column-major `c × c`
/// matrix `dst` (one copy of this code for every size).
fn pad_into<T: Real>(src: &[T], m: usize, dst: &mut [T], c: usize) {
    for (j, col) in src.chunks_exact(m.max(1)).enumerate() {
        for (i, v) in col.iter().enumerate() {
            if let Some(e) = dst.get_mut(j * c + i) {
                *e = *v;
            }
        }
    }
}

/// The working set of one update, kept in one place on the caller's stack and filled in place
/// by the phases below (the phases with large temporaries are separate, non-inlined functions,
/// so their frames do not add up: the peak stack stays small on a Cortex-M). An `n × C` matrix
/// (`n` the error-state dimension, 15 or 6) is stored column-major in the first `n·C` entries
/// of an `R × C` array (column `c` at `c·n .. c·n + n`), the rest zero. Built for size,
/// `R = MAX_STATE` for both filters: the type does not depend on the filter, so the steps that
/// do not touch the state are one compiled copy for both. Otherwise `R = n`: each filter's frame
/// holds only its own rows. Columns and rows past `m` are zero.
struct Work<T: Real, const R: usize, const C: usize> {
    /// `H̃ᵀ` at the current iterate.
    ht: SMatrix<T, R, C>,
    /// Residual `r = z ⊖ h(x̂ ⊕ δx)` at the current iterate.
    r: SVector<T, C>,
    /// `U`, `S` and `K` at the current iterate.
    g: Gain<T, R, C>,
    /// `S⁻¹` (for the NIS at the prior).
    s_inv: SMatrix<T, C, C>,
    /// The current correction `δx` (the first `n` entries; the rest zero).
    dx: SVector<T, R>,
    /// `R` padded to `C × C` with the identity.
    noise: SMatrix<T, C, C>,
    /// The number of active rows, `M`.
    m: usize,
}

/// The gain part of the working set: kept together so that the iterated update saves and
/// restores it as one block (one copy each way instead of three).
#[derive(Clone, Copy)]
struct Gain<T: Real, const R: usize, const C: usize> {
    /// `U = P H̃ᵀ`.
    u: SMatrix<T, R, C>,
    /// `S = H̃ P H̃ᵀ + R` (identity past `m`).
    s: SMatrix<T, C, C>,
    /// `K = U S⁻¹`.
    k: SMatrix<T, R, C>,
}

/// The first `len` entries of `s` (all of `s` if shorter; no caller asks for more).
#[inline(always)]
fn head<T>(s: &[T], len: usize) -> &[T] {
    s.get(..len).unwrap_or(s)
}

/// The first `N` entries of `s` as the state's error vector (zero past the end of `s`).
#[inline(always)]
fn error_vector<T: Real, const N: usize>(s: &[T]) -> SVector<T, N> {
    let mut v = SVector::<T, N>::zeros();
    for (d, e) in v.as_mut_slice().iter_mut().zip(s) {
        *d = *e;
    }
    v
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
///
/// This wrapper is the only per-model code: it picks the core's row capacity ([`CORE_ROWS`])
/// and calls the core, which pads the model's rows and noise to it.
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
    let rows = Padded::<Mo, M>(model);
    let noise = model.noise();
    let noise = noise.as_slice();
    // The working set's storage rows: `MAX_STATE` when built for size (one type for both
    // filters, so one compiled copy of the shared steps), `N` otherwise (each filter's frame
    // only as large as its own state: the attitude-only filter's update needs 6 rows, not 15).
    #[cfg(estimator_compact)]
    {
        if M <= CORE_ROWS {
            update_core::<T, S, N, MAX_STATE, CORE_ROWS>(x, p, &rows, noise, M, opts)
        } else {
            update_core::<T, S, N, MAX_STATE, M>(x, p, &rows, noise, M, opts)
        }
    }
    #[cfg(not(estimator_compact))]
    {
        if M <= CORE_ROWS {
            update_core::<T, S, N, N, CORE_ROWS>(x, p, &rows, noise, M, opts)
        } else {
            update_core::<T, S, N, N, M>(x, p, &rows, noise, M, opts)
        }
    }
}

/// Steps 1–4 for a model seen through `C` rows, `m` of them active (see [`update`]). Only the
/// parts that touch the state (`h`, `⊕`) are here, per filter; the rest are the shared steps
/// ([`start`], [`gate_step`], [`step_shared`], [`commit_shared`]), built for size one copy for
/// both filters (at opt-level 2 or 3 inlined, where `n = N` is a constant).
#[inline(never)]
fn update_core<T, S, const N: usize, const R: usize, const C: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    model: &dyn Rows<T, S, N, R, C>,
    noise: &[T],
    m: usize,
    opts: &UpdateOptions<T>,
) -> Result<UpdateOutcome<T>, EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    let mut w = Work::<T, R, C> {
        ht: SMatrix::zeros(),
        r: SVector::zeros(),
        g: Gain {
            u: SMatrix::zeros(),
            s: SMatrix::zeros(),
            k: SMatrix::zeros(),
        },
        s_inv: SMatrix::zeros(),
        dx: SVector::zeros(),
        noise: SMatrix::zeros(),
        m,
    };
    // The identity written in place (not built aside and copied in).
    for i in 0..C {
        if let Some(e) = w.noise.as_mut_slice().get_mut(i * (C + 1)) {
            *e = T::one();
        }
    }
    start(opts, noise, &mut w)?;
    linearize_into(model, x, &mut w, true)?;
    // Read inside the `Result` (not moved out of it by `?`).
    let gated = gate_step(p.as_slice(), N, m, opts, &mut w);
    let nis = match &gated {
        Ok(UpdateOutcome::Accepted { nis, .. }) => *nis,
        _ => return gated,
    };
    let iterations = iterate(x, p, model, opts, &mut w);
    commit(x, p, &mut w)?;
    Ok(UpdateOutcome::Accepted { nis, iterations })
}

/// The checks before any work: the options, and `R` (`noise`, `m × m` column-major, padded
/// into `w.noise`) symmetric positive definite.
fn start<T: Real, const R: usize, const C: usize>(
    opts: &UpdateOptions<T>,
    noise: &[T],
    w: &mut Work<T, R, C>,
) -> Result<(), EskfError> {
    if opts.max_iterations == 0 || !opts.step_tolerance.is_finite() {
        return Err(EskfError::InvalidOption);
    }
    if let Gate::Threshold(t) = opts.gate {
        if !(t.is_finite() || t > T::zero()) {
            return Err(EskfError::InvalidOption);
        }
    }
    pad_into(noise, w.m, w.noise.as_mut_slice(), C);
    if !check_spd(&w.noise) {
        return Err(EskfError::NoiseNotPositiveDefinite);
    }
    Ok(())
}

/// The gain at the prior, the NIS and the gate (`m` = `w.m`, the argument lets the compiler
/// see its range), then `δx₁ = K₀ r₀` into `w.dx`. Returns
/// `Rejected`, or `Accepted` with the NIS (its iteration count is set by the caller).
#[cfg_attr(not(estimator_compact), inline(always))]
fn gate_step<T: Real, const R: usize, const C: usize>(
    p: &[T],
    n: usize,
    m: usize,
    opts: &UpdateOptions<T>,
    w: &mut Work<T, R, C>,
) -> Result<UpdateOutcome<T>, EskfError> {
    gain_into(p, n, w)?;
    let nis = nis(&w.s_inv, &w.r);
    if !nis.is_finite() {
        return Err(EskfError::SingularInnovation);
    }
    let threshold = opts.gate.threshold(m);
    if nis > threshold {
        return Ok(UpdateOutcome::Rejected { nis, threshold });
    }
    mat_vec(
        w.g.k.as_slice(),
        w.r.as_slice(),
        w.dx.as_mut_slice().get_mut(..n).unwrap_or_default(),
    );
    Ok(UpdateOutcome::Accepted { nis, iterations: 1 })
}

/// `NIS = rᵀ S⁻¹ r` with the `S⁻¹` already formed for `K`, and an explicit sum:
/// `Cholesky::solve` (dynamic-range `dot`s) and `dot` keep shape asserts, panic paths at
/// opt-level "s". Generic over the row capacity only: one copy for both filters.
pub(crate) fn nis<T: Real, const C: usize>(s_inv: &SMatrix<T, C, C>, r: &SVector<T, C>) -> T {
    let mut y = SVector::<T, C>::zeros();
    mat_vec(s_inv.as_slice(), r.as_slice(), y.as_mut_slice());
    r.as_slice()
        .iter()
        .zip(y.as_slice())
        .fold(T::zero(), |acc, (a, b)| acc + *a * *b)
}

/// `out = A x` for the column-major `out.len() × x.len()` matrix `a`, in the order of
/// nalgebra's product (`gemv`): `out_i = a_i0 x_0`, then `out_i = a_ij x_j + out_i` for
/// `j = 1, 2, …` (no leading zero term). Not generic over the sizes: one copy for `K r` in
/// both filters and for the NIS.
pub(crate) fn mat_vec<T: Real>(a: &[T], x: &[T], out: &mut [T]) {
    for (j, (col, xj)) in a.chunks_exact(out.len().max(1)).zip(x).enumerate() {
        for (o, e) in out.iter_mut().zip(col) {
            *o = if j == 0 { *e * *xj } else { *e * *xj + *o };
        }
    }
}

/// Linearizes at `x̂ ⊕ δx` (`δx` = `w.dx`) into `w.ht`, `w.r`, with the chart Jacobian
/// `H̃ = H · blockdiag(J_r(δθ), I)` (the Jacobian of `h(x̂ ⊕ δx)` in `δx`, so that the iterated
/// update is Gauss-Newton in the chart at the prior `x̂`; `J_r(0) = I`).
///
/// Built for size, inlined into [`update_core`] (as is [`iterate`]): one function per filter
/// instead of three, and this frame is on the update's deepest path either way.
#[cfg_attr(estimator_compact, inline(always))]
#[cfg_attr(not(estimator_compact), inline(never))]
fn linearize_into<T, S, const N: usize, const R: usize, const C: usize>(
    model: &dyn Rows<T, S, N, R, C>,
    x: &S,
    w: &mut Work<T, R, C>,
    first: bool,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    if first {
        model.linearize_rows(x, w)?;
    } else {
        let dx = error_vector::<T, N>(w.dx.as_slice());
        model.linearize_rows(&x.oplus(&dx), w)?;
    }
    check_rows(N, w, first)
}

/// The rows just linearized: finite (else `NonFinite`), and after the first linearization
/// turned into the chart Jacobian ([`chart_jacobian`]).
#[cfg_attr(not(estimator_compact), inline(always))]
fn check_rows<T: Real, const R: usize, const C: usize>(
    n: usize,
    w: &mut Work<T, R, C>,
    first: bool,
) -> Result<(), EskfError> {
    if !(finite_vec(&w.r) && finite_vec(&w.ht)) {
        return Err(EskfError::NonFinite);
    }
    if !first {
        let ht = w.ht.as_mut_slice();
        chart_jacobian(
            head(w.dx.as_slice(), n),
            ht.get_mut(..n * C).unwrap_or_default(),
        );
    }
    Ok(())
}

/// `H̃ᵀ = blockdiag(J_r(δθ)ᵀ, I) Hᵀ` in place on the column-major storage `ht` of the `n × C`
/// matrix `Hᵀ`, `n = dx.len()`: only the first three rows change, column by column
/// `J_rᵀ h` ([`mv`](super::imu::mv), the sums of nalgebra's `J_rᵀ · Hᵀ[0..3, ..]`), over every
/// column (the zero padding too, as that product did). Not generic over the sizes: one copy
/// for both filters.
pub(crate) fn chart_jacobian<T: Real>(dx: &[T], ht: &mut [T]) {
    let dth = Vector3::new(at(dx, 0), at(dx, 1), at(dx, 2));
    let jrt = super::imu::tr33(&So3::right_jacobian(&dth));
    for col in ht.chunks_exact_mut(dx.len().max(1)) {
        if let Some(top) = col.get_mut(0..3) {
            let h = Vector3::new(at(top, 0), at(top, 1), at(top, 2));
            let v = super::imu::mv(&jrt, &h);
            for (e, x) in top.iter_mut().zip(v.as_slice()) {
                *e = *x;
            }
        }
    }
}

/// `U = P H̃ᵀ`, `S = H̃ U + R`, `S⁻¹`, `K = U S⁻¹` into `w`, for the `n × n` covariance `p`
/// (column-major), over the `n × C` matrices of the working set (column `c` is entries
/// `c·n .. c·n + n`), for the `m` active columns only.
#[inline(always)]
fn gain_into<T: Real, const R: usize, const C: usize>(
    p: &[T],
    n: usize,
    w: &mut Work<T, R, C>,
) -> Result<(), EskfError> {
    gain_shared(p, n, w)
}

/// The body of [`gain_into`]: one out-of-line copy built for size, inlined at opt-level 2 or 3.
#[cfg_attr(estimator_compact, inline(never))]
#[cfg_attr(not(estimator_compact), inline(always))]
fn gain_shared<T: Real, const R: usize, const C: usize>(
    p: &[T],
    n: usize,
    w: &mut Work<T, R, C>,
) -> Result<(), EskfError> {
    let (m, r_noise, ht) = (w.m, &w.noise, w.ht.as_slice());
    let (u, s, s_inv_out, k) = (
        w.g.u.as_mut_slice(),
        &mut w.g.s,
        &mut w.s_inv,
        w.g.k.as_mut_slice(),
    );
    // Column c of U = Σ_j P e_j H_cj over the nonzero entries of row c of H only (most models
    // touch 3–6 of the 15 error components).
    u.fill(T::zero());
    for (uc, hc) in u
        .chunks_exact_mut(n.max(1))
        .zip(ht.chunks_exact(n.max(1)))
        .take(m)
    {
        for (pc, h) in p.chunks_exact(n.max(1)).zip(hc) {
            if *h != T::zero() {
                axpy(uc, *h, pc);
            }
        }
    }
    // S_ij = R_ij + (row i of H)·(column j of U) for i, j < m; the identity padding stays.
    s.copy_from(r_noise);
    for (j, uc) in u.chunks_exact(n.max(1)).enumerate().take(m) {
        for (i, hc) in ht.chunks_exact(n.max(1)).enumerate().take(m) {
            if let Some(e) = s.get_mut((i, j)) {
                *e += dot(hc, uc);
            }
        }
    }
    symmetrize(s);
    // K = U S⁻¹ with S⁻¹ from the Cholesky factor (C × C, small); the columns past m stay zero.
    // Built for size, nalgebra's factorization and solves in plain loops (the same bits, see
    // `cholesky_inverse`); at opt-level 2 or 3, nalgebra's own, which it unrolls faster.
    // (Written to the caller's `S⁻¹` directly: after an error the caller does not read it.)
    #[cfg(estimator_compact)]
    {
        *s_inv_out = cholesky_inverse(s).ok_or(EskfError::SingularInnovation)?;
    }
    #[cfg(not(estimator_compact))]
    {
        *s_inv_out = nalgebra::Cholesky::new(*s)
            .ok_or(EskfError::SingularInnovation)?
            .inverse();
    }
    let s_inv: &SMatrix<T, C, C> = s_inv_out;
    k.fill(T::zero());
    for (kc, sc) in k
        .chunks_exact_mut(n.max(1))
        .zip(s_inv.as_slice().chunks_exact(C.max(1)))
        .take(m)
    {
        for (uc, s) in u.chunks_exact(n.max(1)).zip(sc).take(m) {
            axpy(kc, *s, uc);
        }
    }
    if !sum_times_zero_is_zero(k) {
        return Err(EskfError::SingularInnovation);
    }
    Ok(())
}

/// `S ← (S + Sᵀ)·½` entry by entry over the storage, `(s_ij + s_ji)·½` from a copy of `S`:
/// nalgebra's `s += sᵀ; s *= ½`, without its generic loops.
#[inline(always)]
pub(crate) fn symmetrize<T: Real, const C: usize>(s: &mut SMatrix<T, C, C>) {
    let s0 = *s;
    for (j, col) in s.as_mut_slice().chunks_exact_mut(C.max(1)).enumerate() {
        for (i, e) in col.iter_mut().enumerate() {
            *e = (*e + at(s0.as_slice(), i * C + j)) * T::lit(0.5);
        }
    }
}

/// `A⁻¹` by `nalgebra::Cholesky::new(A)?.inverse()`, operation for operation (the same bits;
/// `None` exactly when nalgebra's factorization fails), over the column arrays instead of
/// nalgebra's run-time-sized views: the factor by [`factor_lower`], then, per column `b` of the
/// identity, the forward solve `b_i ← b_i / l_ii`, `b_k ← (−b_i) l_ki + b_k` (`k > i`) and the
/// backward solve `b_i ← (b_i − (0 + Σ_{k>i} l_ki b_k)) / l_ii` (`i` descending): the
/// substitution the solver's factor uses (`gn::linalg::substitute`), one copy for both.
#[cfg_attr(not(estimator_compact), allow(dead_code))] // tests only, unless built for size
pub(crate) fn cholesky_inverse<T: Real, const C: usize>(
    a: &SMatrix<T, C, C>,
) -> Option<SMatrix<T, C, C>> {
    let mut l = *a;
    if !factor_lower(l.as_mut_slice(), C) {
        return None;
    }
    let mut inv = SMatrix::<T, C, C>::identity();
    for b in inv.as_mut_slice().chunks_exact_mut(C.max(1)) {
        crate::gn::linalg::substitute(l.as_slice(), C, b);
    }
    Some(inv)
}

/// The Gauss-Newton step `next = K (r + H̃ prev)` over the `m` active rows, on the column-major
/// storage of the `n × C` matrices `ht` (`H̃ᵀ`) and `k` (`K`), `n = prev.len()`: `y = r`,
/// `y_c += (row c of H̃)·prev`, then `next = Σ_c y_c k_c` from zero. Generic over the row
/// capacity only: one copy for both filters.
pub(crate) fn gauss_newton_step<T: Real, const C: usize>(
    ht: &[T],
    k: &[T],
    r: &SVector<T, C>,
    m: usize,
    prev: &[T],
    next: &mut [T],
) {
    let n = prev.len().max(1);
    let mut y = *r;
    for (yc, hc) in y.as_mut_slice().iter_mut().zip(ht.chunks_exact(n)).take(m) {
        *yc += dot(hc, prev);
    }
    next.fill(T::zero());
    for (kc, yc) in k.chunks_exact(n).zip(y.as_slice()).take(m) {
        axpy(next, *yc, kc);
    }
}

/// `y += a x` over two equally long slices.
#[cfg_attr(not(estimator_compact), inline)]
#[cfg_attr(estimator_compact, inline(never))]
fn axpy<T: Real>(y: &mut [T], a: T, x: &[T]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += a * *x;
    }
}

/// `‖a − b‖` over two equally long slices: `√(a − b)·(a − b)`, the differences then [`dot`]'s
/// sum. Not generic over the length: one copy for both filters.
pub(crate) fn distance<T: Real>(a: &[T], b: &[T]) -> T {
    a.iter()
        .zip(b)
        .fold(T::zero(), |acc, (x, y)| {
            let d = *x - *y;
            acc + d * d
        })
        .sqrt_rn()
}

/// The Gauss-Newton iterations (step 2 after the first): at `x̂ ⊕ δx_k`,
/// `δx_{k+1} = K_k (r_k + H̃_k δx_k)`. A failure to re-linearize stops at the last good iterate
/// (whose `K`, `U`, `S` are restored). Returns the number of linearizations used.
#[cfg_attr(estimator_compact, inline(always))]
#[cfg_attr(not(estimator_compact), inline(never))]
fn iterate<T, S, const N: usize, const R: usize, const C: usize>(
    x: &S,
    p: &SMatrix<T, N, N>,
    model: &dyn Rows<T, S, N, R, C>,
    opts: &UpdateOptions<T>,
    w: &mut Work<T, R, C>,
) -> u8
where
    T: Real,
    S: ErrorState<T, N>,
{
    let mut iterations: u8 = 1;
    while iterations < opts.max_iterations {
        let linearized = linearize_into(model, x, w, false).is_ok();
        let Some(converged) = step_shared(p.as_slice(), N, opts, w, linearized) else {
            break;
        };
        iterations += 1;
        if converged {
            break;
        }
    }
    iterations
}

/// One Gauss-Newton step after a re-linearization (`linearized` tells whether it succeeded):
/// the gain there, then `δx_{k+1} = K_k (r_k + H̃_k δx_k)` into `w.dx`; `None` (with `U`, `S`,
/// `K` and `δx` as they were) when the linearization, the gain or the step failed, else whether
/// `‖δx_{k+1} − δx_k‖ < tol`. For the `n × n` covariance `p` (column-major).
#[cfg_attr(not(estimator_compact), inline(always))]
fn step_shared<T: Real, const R: usize, const C: usize>(
    p: &[T],
    n: usize,
    opts: &UpdateOptions<T>,
    w: &mut Work<T, R, C>,
    linearized: bool,
) -> Option<bool> {
    if !linearized {
        return None;
    }
    // The linearization wrote `H̃` and `r` only; the gain overwrites these.
    let saved = w.g;
    let ok = gain_into(p, n, w).is_ok();
    // y = r + H̃ δx_k (row c of H̃ is column c of H̃ᵀ), δx_{k+1} = K y.
    let mut next = SVector::<T, R>::zeros();
    let next = next.as_mut_slice().get_mut(..n).unwrap_or_default();
    let prev = head(w.dx.as_slice(), n);
    gauss_newton_step(w.ht.as_slice(), w.g.k.as_slice(), &w.r, w.m, prev, next);
    if !(ok && sum_times_zero_is_zero(next)) {
        w.g = saved;
        return None;
    }
    let converged = distance(next, prev) < opts.step_tolerance;
    for (d, e) in w.dx.as_mut_slice().iter_mut().zip(next.iter()) {
        *d = *e;
    }
    Some(converged)
}

/// Steps 3–4: Joseph-form covariance, injection and reset; writes `x` and `P` only when every
/// check passed. Overwrites `U` (with `V`, see [`commit_shared`]).
///
/// The covariance part is [`commit_shared`], written over a run-time dimension. At opt-level 2
/// or 3 it is inlined here, into one copy per filter where `n = N` is a constant (the
/// instruction counts are budgeted there); in a build for size (`cfg(estimator_compact)`, see
/// `build.rs`) this entry is inlined into its caller and the body is one out-of-line copy shared
/// by both filters.
#[cfg_attr(estimator_compact, inline(always))]
#[cfg_attr(not(estimator_compact), inline(never))]
fn commit<T, S, const N: usize, const R: usize, const C: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    w: &mut Work<T, R, C>,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    let dx = head(w.dx.as_slice(), N);
    let new_x = x.oplus(&error_vector(dx));
    commit_shared(p.as_mut_slice(), N, w, new_x.is_finite())?;
    *x = new_x;
    Ok(())
}

/// The covariance of steps 3–4 on the column-major storage of the `n × n` covariance `p`,
/// from the working set: the `n × C` matrices `U` (overwritten by `V`) and `K`, `S` and the
/// correction `δx`. Writes `p` only when `state_ok` and every check passes.
#[cfg_attr(estimator_compact, inline(never))]
#[cfg_attr(not(estimator_compact), inline(always))]
fn commit_shared<T: Real, const R: usize, const C: usize>(
    p: &mut [T],
    n: usize,
    w: &mut Work<T, R, C>,
    state_ok: bool,
) -> Result<(), EskfError> {
    if !(3..=R).contains(&n) {
        return Err(EskfError::NumericalFailure); // no filter has such a state
    }
    let (m, u, k, s) = (w.m, w.g.u.as_mut_slice(), w.g.k.as_slice(), &w.g.s);
    let dx = head(w.dx.as_slice(), n);
    // Joseph form, expanded and written as m symmetric rank-2 corrections:
    //   P⁺ = P − K Uᵀ − U Kᵀ + K S Kᵀ = P + V Kᵀ + K Vᵀ = P + Σ_c (v_c k_cᵀ + k_c v_cᵀ),
    //   V = ½ K S − U (columns v_c, k_c of V and K): exactly symmetric, computed in place
    // without an N × N temporary. The checks below need only its diagonal and attitude rows.
    for (c, vc) in u.chunks_exact_mut(n.max(1)).enumerate().take(m) {
        vc.iter_mut().for_each(|e| *e = -*e);
        for (j, kj) in k.chunks_exact(n.max(1)).enumerate().take(m) {
            let sjc = s.get((j, c)).copied().unwrap_or_else(T::zero);
            axpy(vc, sjc * T::lit(0.5), kj);
        }
    }
    let v: &[T] = u;
    let pairs = || {
        v.chunks_exact(n.max(1))
            .zip(k.chunks_exact(n.max(1)))
            .take(m)
    };
    // Attitude rows of P⁺ (column j: P[0..3, j] + Σ_c (v_c[0..3] k_c[j] + k_c[0..3] v_c[j])),
    // then the reset P⁺ ← G P⁺ Gᵀ, G = blockdiag(J_r(δθ), I): only the attitude rows and
    // columns change.
    let dth = Vector3::new(at(dx, 0), at(dx, 1), at(dx, 2));
    let gr: Matrix3<T> = So3::right_jacobian(&dth);
    // K, U, S and P are finite, so P⁺ can only fail by overflow; for a positive semi-definite
    // P⁺, |P⁺_ij| ≤ √(P⁺_ii P⁺_jj), so a finite positive diagonal bounds every entry. The
    // diagonal from row 3 on is checked here as `P_jj + 2 Σ_c v_cj k_cj` (the sum from zero,
    // over the same pairs as the attitude rows: one pass over V and K for both).
    let ok = positive_finite::<T>;
    let two = T::lit(2.0);
    let mut diag_ok = true;
    let mut top = [Vector3::<T>::zeros(); R];
    for (j, (t, pc)) in top.iter_mut().zip(p.chunks_exact(n.max(1))).enumerate() {
        let mut c0 = Vector3::new(at(pc, 0), at(pc, 1), at(pc, 2));
        let mut d = T::zero();
        for (vc, kc) in pairs() {
            let (vj, kj) = (at(vc, j), at(kc, j));
            for (e, (a, b)) in c0.as_mut_slice().iter_mut().zip(vc.iter().zip(kc)) {
                *e += *a * kj + *b * vj;
            }
            d += vj * kj;
        }
        if j >= 3 {
            diag_ok &= ok(at(pc, j) + d * two);
        }
        *t = super::imu::mv(&gr, &c0);
    }
    // `R ≥ n ≥ 3` (checked above): the first three always exist.
    let Some(t012) = top.first_chunk::<3>() else {
        return Err(EskfError::NumericalFailure);
    };
    let c00 = super::imu::mm(&Matrix3::from_columns(t012), &super::imu::tr33(&gr));
    let c00 = super::imu::sym(&c00);
    let diag_ok = diag_ok && (0..3).all(|i| ok(at(c00.as_slice(), 4 * i)));
    if !(state_ok && diag_ok) {
        return Err(EskfError::NumericalFailure);
    }
    // Rows and columns 3.. of P⁺ (rows 0..3 are `top`, written below). Upper triangle (column
    // j of P holds entries (0..=j, j)): P_ij += v_i k_j + k_i v_j for each active c, 3 ≤ i ≤ j,
    // then mirrored; half of the products of the full square.
    for (vc, kc) in pairs() {
        for (j, pc) in p.chunks_exact_mut(n.max(1)).enumerate() {
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
    write_rows(p, n, &mut top, &c00);
    Ok(())
}

/// The last step of [`commit_shared`] on the column-major `n × n` storage `p` whose upper
/// triangle from row 3 on is final: rows 0..3 ← `top` (column `j` of those rows is `top[j]`),
/// block (0, 0) ← `c00` (overwriting `top[0..3]`), then the whole upper triangle mirrored
/// (element by element: no transposed temporary). `c00` is exactly symmetric (from `sym`), so
/// mirroring its upper half leaves it as written: the same matrix as mirroring rows 3.. and
/// writing `top` and `c00` both ways, with one store per entry instead of two.
#[inline(always)]
pub(crate) fn write_rows<T: Real, const R: usize>(
    p: &mut [T],
    n: usize,
    top: &mut [Vector3<T>; R],
    c00: &Matrix3<T>,
) {
    for (t, c) in top.iter_mut().zip(c00.as_slice().chunks_exact(3)) {
        copy_into(t.as_mut_slice(), c);
    }
    for (col, t) in p.chunks_exact_mut(n.max(1)).zip(top.iter()) {
        copy_into(col, t.as_slice());
    }
    for j in 1..n {
        for i in 0..j {
            let u = at(p, j * n + i);
            if let Some(e) = p.get_mut(i * n + j) {
                *e = u;
            }
        }
    }
}

/// `dst[i] = src[i]` over the shorter of the two.
#[inline(always)]
fn copy_into<T: Real>(dst: &mut [T], src: &[T]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// `s[i]`, or zero past the end (never reached: every caller indexes below the length).
#[inline(always)]
fn at<T: Real>(s: &[T], i: usize) -> T {
    s.get(i).copied().unwrap_or_else(T::zero)
}

//! The measurement update: innovation, gate, gain, Joseph-form covariance, iterated
//! (Gauss-Newton) re-linearization, injection through `⊕` and the covariance reset.
//!
//! Equations cite *Lie Groups and Smooth Manifolds for Robotic State Estimation*.
//!
//! 1. Linearize at the prior: `r₀ = z ⊖ h(x̂)` and `H₀` with `h(x̂ ⊕ δx) ≈ h(x̂) + H₀ δx`
//!    (eq. 4.3); `S = H₀ P H₀ᵀ + R_eff`, `R` with the noise floor of `gain.rs`;
//!    `NIS = r₀ᵀ S⁻¹ r₀`, the squared Mahalanobis distance `‖e‖²_Σ = eᵀ Σ⁻¹ e` of eq. 4.1;
//!    gate `NIS ≤ χ²_M(p)` ([`Gate`]) or return `Rejected`.
//! 2. `δx₁ = K₀ r₀`, `K = P Hᵀ S⁻¹ = W L⁻¹` (square-root form: `S = L Lᵀ`, `W = P Hᵀ L⁻ᵀ`,
//!    [`gain`]): the minimizer of eq. 4.4,
//!    `ξ* = argmin ‖h(a) + H_a ξ − z‖²_Σ`, with the prior `‖δx‖²_P` added. Iterated: at
//!    `x_k = x̂ ⊕ δx_k` linearize again, `H̃_k = H_k·blockdiag(J_r(δθ_k), I)`,
//!    `δx_{k+1} = K_k (r_k + H̃_k δx_k)` (Gauss-Newton in the chart at `x̂`), until
//!    `‖δx_{k+1} − δx_k‖ < tol` or the iteration cap.
//! 3. The posterior in square-root form ([`commit`]): with the optimal gain the Joseph form
//!    `P⁺ = (I − KH)P(I − KH)ᵀ + K R Kᵀ = P − K Uᵀ − U Kᵀ + K S Kᵀ` (`U = P Hᵀ`) is
//!    `P − U S⁻¹ Uᵀ = P − W Wᵀ`: `M` symmetric rank-one downdates whose terms are bounded by
//!    `P` (`W Wᵀ ≤ P`), so that their rounding stays a few `ε √(P_ii P_jj)` however
//!    ill-conditioned `S` is (the expanded Joseph terms `K S Kᵀ` grow with `κ(S)`).
//! 4. Inject `x⁺ = x̂ ⊕ δx`, `a ⊕ ξ = a·exp(ξ^)` (eq. 4.5), and reset `P ← G P Gᵀ`,
//!    `G = blockdiag(J_r(δθ), I)` (the new error `e⁺ = log(exp(δθ)⁻¹ exp(e)) ≈ J_r(δθ)(e − δθ)`).
//!
//! Every model with up to [`CORE_ROWS`] rows runs through one compiled core per scalar type and
//! filter, not one per model: the core sees a model through [`Rows`], its residual and Jacobian
//! padded with zero rows and its noise with the identity, which leaves every result unchanged
//! (`S_pad = [[S, 0], [0, I]]`, `L_pad = [[L, 0], [0, I]]`, `W_pad = [W, 0]`, `NIS = rᵀ S⁻¹ r`), and the products whose cost
//! grows with the rows run over the `M` active rows only. The core's phases are separate
//! functions sharing one working set ([`Work`]), each `#[inline(never)]` so that their stack
//! frames do not add up (inlined into one another they exceed the 2 KiB stack a Cortex-M
//! firmware gives them at opt-level `s`).

mod commit;
mod gain;
pub(crate) mod gate;
mod model;
mod options;
mod work;

use super::covariance::is_usable_spd;
use super::error::{EskfError, UpdateOutcome};
use super::state::ErrorState;
use crate::kernels::block::copy;
use crate::kernels::slice::transpose_into;
use crate::kernels::{all_finite, mat3};
use crate::lie::{LieGroup, So3};
use crate::Real;
use commit::commit;
use gain::{gate_step, noise_floor, padded_noise, step};
pub use model::{Linearization, Measurement};
use nalgebra::SMatrix;
pub use options::UpdateOptions;
use work::{attitude_part, Work};

/// Row capacity of the shared update core (see the module docs).
pub(crate) const CORE_ROWS: usize = 3;

/// A measurement model as the update core sees it: through a row capacity `C ≥ M`.
///
/// The core takes `&dyn Rows<T, S, N, C>`, so it is compiled once per `(T, S, N, C)`, not
/// once per model; only [`Padded::linearize_rows`] is per model.
trait Rows<T: Real, S, const N: usize, const C: usize> {
    /// Linearizes at `x` into `w.ht = Hᵀ` (`N × C`; column `c` is row `c` of `H`) and `w.r`;
    /// the columns and rows past `M` are zero. Nothing else in `w` is written.
    fn linearize_rows(&self, x: &S, w: &mut Work<T, N, C>) -> Result<(), EskfError>;
}

/// A model with `M` rows, seen through any capacity `C ≥ M`.
struct Padded<'a, Mo, const M: usize>(&'a Mo);

impl<T, S, Mo, const N: usize, const M: usize, const C: usize> Rows<T, S, N, C>
    for Padded<'_, Mo, M>
where
    T: Real,
    Mo: Measurement<T, S, N, M>,
{
    fn linearize_rows(&self, x: &S, w: &mut Work<T, N, C>) -> Result<(), EskfError> {
        // Read in place: the linearization is not moved out of its `Result` (one copy of it on
        // the stack, on the update's deepest path).
        let lin = self.0.linearize(x);
        let lin = match &lin {
            Ok(lin) => lin,
            Err(e) => return Err(*e),
        };
        transpose_into(
            lin.jacobian.as_slice(),
            lin.residual.as_slice(),
            w.ht.as_mut_slice(),
            w.r.as_mut_slice(),
        );
        Ok(())
    }
}

/// The update on `(x, P)` (module docs); `x` and `P` are written only when the result is
/// `Accepted`. The only per-model code: it picks the core's row capacity and calls the core.
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
    if M <= CORE_ROWS {
        update_core::<T, S, N, CORE_ROWS>(x, p, &rows, noise.as_slice(), M, opts)
    } else {
        update_core::<T, S, N, M>(x, p, &rows, noise.as_slice(), M, opts)
    }
}

/// Steps 1–4 for a model seen through `C` rows, `m` of them active.
#[inline(never)]
fn update_core<T, S, const N: usize, const C: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    model: &dyn Rows<T, S, N, C>,
    noise: &[T],
    m: usize,
    opts: &UpdateOptions<T>,
) -> Result<UpdateOutcome<T>, EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    opts.validate()?;
    let mut w = Work::<T, N, C>::new(m);
    if !noise_is_spd::<T, C, N>(noise, m) {
        return Err(EskfError::NoiseNotPositiveDefinite);
    }
    linearize_into(model, x, &mut w, true)?;
    let nis = match gate_step(p, noise, m, opts, &mut w)? {
        UpdateOutcome::Accepted { nis, .. } => nis,
        rejected => return Ok(rejected),
    };
    let iterations = iterate(x, p, model, noise, opts, &mut w);
    commit(x, p, &mut w)?;
    Ok(UpdateOutcome::Accepted { nis, iterations })
}

/// `R` (padded to `C × C`, [`padded_noise`]) is symmetric and its symmetric part, the matrix
/// the gain uses, is positive definite and not singular to the scalar's resolution: every Cholesky pivot above the noise floor's fraction `256 N ε` of
/// its diagonal (a noise `R` with two rows correlated beyond `√(1 − 256 N ε)` measures their
/// difference more precisely than the floor on the diagonal allows); out of line, so that the
/// padded copy is not in the update's frame.
#[inline(never)]
fn noise_is_spd<T: Real, const C: usize, const N: usize>(noise: &[T], m: usize) -> bool {
    is_usable_spd(&padded_noise::<T, C>(noise, m), noise_floor::<T, N>())
}

/// Linearizes at `x̂ ⊕ δx` (`δx` = `w.dx`; at `x̂` when `first`) into `w.ht`, `w.r`, with the
/// chart Jacobian `H̃ = H · blockdiag(J_r(δθ), I)` (the Jacobian of `h(x̂ ⊕ δx)` in `δx`, so that
/// the iterated update is Gauss-Newton in the chart at the prior; `J_r(0) = I`).
#[inline(never)]
fn linearize_into<T, S, const N: usize, const C: usize>(
    model: &dyn Rows<T, S, N, C>,
    x: &S,
    w: &mut Work<T, N, C>,
    first: bool,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    if first {
        model.linearize_rows(x, w)?;
    } else {
        model.linearize_rows(&x.oplus(&w.dx), w)?;
    }
    if !(all_finite(w.r.as_slice()) && all_finite(w.ht.as_slice())) {
        return Err(EskfError::NonFinite);
    }
    if !first {
        // H̃ᵀ = blockdiag(J_r(δθ)ᵀ, I) Hᵀ: only the attitude rows change.
        let jrt = So3::right_jacobian(&attitude_part(w.dx.as_slice())).transpose();
        for col in w.ht.data.0.iter_mut() {
            if let Some(top) = col.get_mut(0..3) {
                let v = mat3::mul_vec(&jrt, &attitude_part(top));
                copy(top, v.as_slice());
            }
        }
    }
    Ok(())
}

/// The Gauss-Newton iterations (step 2 after the first): at `x̂ ⊕ δx_k`,
/// `δx_{k+1} = K_k (r_k + H̃_k δx_k)`. A failure to re-linearize stops at the last good iterate
/// (whose `K`, `U`, `S` are restored). Returns the number of linearizations used.
#[inline(never)]
fn iterate<T, S, const N: usize, const C: usize>(
    x: &S,
    p: &SMatrix<T, N, N>,
    model: &dyn Rows<T, S, N, C>,
    noise: &[T],
    opts: &UpdateOptions<T>,
    w: &mut Work<T, N, C>,
) -> u8
where
    T: Real,
    S: ErrorState<T, N>,
{
    let mut iterations: u8 = 1;
    while iterations < opts.max_iterations {
        if linearize_into(model, x, w, false).is_err() {
            break;
        }
        let Some(converged) = step(p, noise, opts, w) else {
            break;
        };
        iterations += 1;
        if converged {
            break;
        }
    }
    iterations
}

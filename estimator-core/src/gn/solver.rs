//! The solver core: block-wise accumulation of the normal equations, Gauss-Newton and
//! Levenberg-Marquardt steps through `⊕`, convergence tests, covariance.
//!
//! See the [module docs](crate::gn) for how each step maps to the equations of *Lie Groups and
//! Smooth Manifolds for Robotic State Estimation*.

use super::linalg;
use super::{Loss, Manifold, SolveError};
use crate::kernels::cholesky::solve_in_place;
use crate::kernels::slice::{columns, dot};
use crate::kernels::{all_finite, non_negative_finite};
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// A set of residual blocks of dimension `K` over a state `S` with `N` degrees of freedom.
///
/// For each block `i`, `linearize` hands the *whitened* error `eᵢ = Σᵢ^{-1/2} (hᵢ(a) − zᵢ)` and its
/// Jacobian `Jᵢ = ∂eᵢ/∂ξ` at `ξ = 0` in the sense of Definition 4.6 of *Lie Groups and Smooth
/// Manifolds for Robotic State Estimation* (`‖f(a) + F_a ξ − f(a exp(ξ^))‖ / ‖ξ‖ → 0`), i.e.
/// `eᵢ(a ⊕ ξ) ≈ eᵢ(a) + Jᵢ ξ` (its eq. 4.3, `h(a ⊕ ξ) ≈ h(a) + H_a ξ`), to `sink`. Nothing is stored: the solver folds each
/// block into the `N × N` normal equations as it arrives.
pub trait Problem<T: Real, S, const N: usize, const K: usize> {
    /// Calls `sink(eᵢ, Jᵢ)` for every block at `state`.
    ///
    /// # Errors
    /// Any [`SolveError`] the model detects at this state (for example a point behind the
    /// camera). The solver treats an error at a trial state as a rejected step and an error at
    /// the initial state as fatal.
    fn linearize<F>(&self, state: &S, sink: F) -> Result<(), SolveError>
    where
        F: FnMut(&SVector<T, K>, &SMatrix<T, K, N>);
}

/// One residual block: `(eᵢ, Jᵢ)` of [`Problem`] at a state. A slice of blocks is a [`Problem`].
pub trait ResidualBlock<T: Real, S, const N: usize, const K: usize> {
    /// The whitened error `eᵢ = Σᵢ^{-1/2}(hᵢ(a) − zᵢ)` and its right Jacobian `∂eᵢ/∂ξ`.
    ///
    /// # Errors
    /// Whatever makes the model undefined at `state`.
    fn evaluate(&self, state: &S) -> Result<(SVector<T, K>, SMatrix<T, K, N>), SolveError>;
}

impl<T, S, B, const N: usize, const K: usize> Problem<T, S, N, K> for [B]
where
    T: Real,
    B: ResidualBlock<T, S, N, K>,
{
    fn linearize<F>(&self, state: &S, mut sink: F) -> Result<(), SolveError>
    where
        F: FnMut(&SVector<T, K>, &SMatrix<T, K, N>),
    {
        for block in self {
            let (e, j) = block.evaluate(state)?;
            sink(&e, &j);
        }
        Ok(())
    }
}

/// The accumulated normal equations of the linearized problem (eq. 4.4 of *Lie Groups and Smooth
/// Manifolds for Robotic State Estimation*, `ξ* = argmin ‖h(a) + H_a ξ − z‖²_Σ`, solved by
/// `H_aᵀ H_a ξ* = H_aᵀ(z − h(a))`) with IRLS weights `wᵢ = ρ'(‖eᵢ‖²)`:
/// `A = Σ wᵢ Jᵢᵀ Jᵢ` (the information matrix `Hᵀ W H`), `g = Σ wᵢ Jᵢᵀ eᵢ` (so that
/// `Hᵀ W (z − h(a)) = −g`), and the robust cost `F = Σ ρ(‖eᵢ‖²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalEquations<T: Real, const N: usize> {
    /// `A = Σ wᵢ Jᵢᵀ Jᵢ`.
    pub information: SMatrix<T, N, N>,
    /// `g = Σ wᵢ Jᵢᵀ eᵢ`.
    pub gradient: SVector<T, N>,
    /// `F = Σ ρ(‖eᵢ‖²)`.
    pub cost: T,
    /// Number of blocks accumulated.
    pub blocks: usize,
}

impl<T: Real, const N: usize> NormalEquations<T, N> {
    /// All zero.
    #[must_use]
    pub fn zeros() -> Self {
        Self {
            information: SMatrix::zeros(),
            gradient: SVector::zeros(),
            cost: T::zero(),
            blocks: 0,
        }
    }

    /// Folds one block in: `A += w JᵀJ`, `g += w Jᵀe`, `F += ρ(‖e‖²)` with `(ρ, w) = (ρ(s), ρ'(s))`
    /// at `s = ‖e‖²`.
    pub fn add<const K: usize>(&mut self, loss: &Loss<T>, e: &SVector<T, K>, j: &SMatrix<T, K, N>) {
        let (rho, w) = loss.evaluate(e.norm_squared());
        let wj = j * w;
        // `A += (w J)ᵀ J` entry by entry, `A_rc += (w J_r)·J_c` over the columns `J_r`, `J_c`.
        // Columns as arrays (`[[T; K]; N]`), not nalgebra's column views, whose index
        // assertion is a panic path wherever they are not inlined.
        // Column c of A gains (w J_r)·J_c in row r.
        for (a_col, jcol) in self.information.data.0.iter_mut().zip(j.data.0.iter()) {
            for (x, wcol) in a_col.iter_mut().zip(wj.data.0.iter()) {
                *x += dot_k(wcol, jcol);
            }
        }
        let [e_col] = &e.data.0;
        for (g, wcol) in self.gradient.iter_mut().zip(wj.data.0.iter()) {
            *g += dot_k(wcol, e_col);
        }
        self.cost += rho;
        self.blocks += 1;
    }

    /// Accumulates every block of `problem` at `state`.
    ///
    /// # Errors
    /// The problem's own error, or [`SolveError::NonFiniteResidual`] for a non-finite sum.
    pub fn build<S, P, const K: usize>(
        problem: &P,
        state: &S,
        loss: &Loss<T>,
    ) -> Result<Self, SolveError>
    where
        P: Problem<T, S, N, K> + ?Sized,
    {
        let mut ne = Self::zeros();
        ne.accumulate(problem, state, loss)?;
        finite_sums(ne.information.as_slice(), ne.gradient.as_slice(), ne.cost)?;
        Ok(ne)
    }

    /// Resets `self` and accumulates every block of `problem` at `state` into it, without the
    /// finiteness test of [`Self::build`] (which [`solve_into`] runs in its shared part). On
    /// error `self` holds a partial sum.
    ///
    /// # Errors
    /// The problem's own error.
    fn accumulate<S, P, const K: usize>(
        &mut self,
        problem: &P,
        state: &S,
        loss: &Loss<T>,
    ) -> Result<(), SolveError>
    where
        P: Problem<T, S, N, K> + ?Sized,
    {
        *self = Self::zeros();
        problem.linearize(state, |e, j| self.add(loss, e, j))
    }
}

/// [`SolveError::NonFiniteResidual`] unless the cost, the gradient and the information of a
/// linearization are finite.
fn finite_sums<T: Real>(information: &[T], gradient: &[T], cost: T) -> Result<(), SolveError> {
    if cost.is_finite() && all_finite(gradient) && all_finite(information) {
        Ok(())
    } else {
        Err(SolveError::NonFiniteResidual)
    }
}

/// The iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Gauss-Newton: `A ξ = −g`, every step taken.
    GaussNewton,
    /// Levenberg-Marquardt: `(A + λ diag A) ξ = −g`, a step taken only if it lowers the cost,
    /// `λ` updated from the gain ratio (trust-region style, Nielsen's rule).
    LevenbergMarquardt,
}

/// Options of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverOptions<T: Real> {
    /// Gauss-Newton or Levenberg-Marquardt.
    pub method: Method,
    /// The robust loss, its scale in standard deviations of the whitened residual.
    pub loss: Loss<T>,
    /// Iteration cap (one iteration = one linear solve).
    pub max_iterations: usize,
    /// Stop when `‖ξ‖ ≤ step_tolerance` (tangent units: radians, metres…).
    pub step_tolerance: T,
    /// Stop when an accepted step lowers the cost by at most `cost_tolerance · F`.
    pub cost_tolerance: T,
    /// Stop when the step's own Mahalanobis length `ξᵀ A ξ` (in units of the solution's
    /// covariance, so scale-free) is at most this: the step is then far inside the uncertainty.
    pub information_step_tolerance: T,
    /// Initial Levenberg-Marquardt damping `λ₀` (relative to `diag A`).
    pub initial_damping: T,
}

impl<T: Real> Default for SolverOptions<T> {
    /// Levenberg-Marquardt, least squares, 50 iterations, step tolerance
    /// `max(1e3 ε, 1e-9)`, cost tolerance `max(1e2 ε, 1e-12)`, information step tolerance
    /// `1e-6`, `λ₀ = 1e-3`.
    fn default() -> Self {
        Self {
            method: Method::LevenbergMarquardt,
            loss: Loss::LeastSquares,
            max_iterations: 50,
            step_tolerance: T::lit(const { f64_max(1e3 * T::EPSILON_F64, 1e-9) }),
            cost_tolerance: T::lit(const { f64_max(1e2 * T::EPSILON_F64, 1e-12) }),
            information_step_tolerance: T::lit(1e-6),
            initial_damping: T::lit(1e-3),
        }
    }
}

const fn f64_max(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

impl<T: Real> SolverOptions<T> {
    /// `true` when the loss is valid and the tolerances and damping are finite and non-negative.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.loss.is_valid()
            && [
                self.step_tolerance,
                self.cost_tolerance,
                self.information_step_tolerance,
                self.initial_damping,
            ]
            .into_iter()
            .all(non_negative_finite)
    }
}

/// Why the iteration stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// The last step was at most `step_tolerance`, or its Mahalanobis length `ξᵀAξ` at most
    /// `information_step_tolerance`.
    StepConverged,
    /// The last accepted step lowered the cost by at most `cost_tolerance` relatively (or the
    /// cost is zero).
    CostConverged,
    /// `max_iterations` reached before either test held; the state is the best found.
    MaxIterations,
    /// Levenberg-Marquardt raised `λ` beyond `1e12` without finding a decrease: the state is a
    /// minimum to working precision.
    DampingSaturated,
}

/// The result of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<T: Real, S, const N: usize> {
    /// The estimate `a*`.
    pub state: S,
    /// `A⁻¹ = (Hᵀ W H)⁻¹` at the last linearization (see `final_cost`): the covariance of `ξ`
    /// in `a* ⊕ ξ` (the tangent at the solution, right perturbation).
    pub covariance: SMatrix<T, N, N>,
    /// Iterations run (linear solves).
    pub iterations: usize,
    /// The robust cost `Σ ρ(‖eᵢ‖²)` at the guess.
    pub initial_cost: T,
    /// The robust cost at the last linearization: at `a*`, or, when the last step passed the
    /// `information_step_tolerance` test and was taken without another pass over the residuals,
    /// just before that step (the model decrease `ξᵀAξ` is then at most that tolerance).
    pub final_cost: T,
    /// Why it stopped.
    pub status: Status,
}

const MAX_DAMPING: f64 = 1e12;

/// Minimizes `F(a) = Σᵢ ρ(‖hᵢ(a) − zᵢ‖²_Σ)` over the manifold `S`, from `initial`: eq. 4.1 of
/// *Lie Groups and Smooth Manifolds for Robotic State Estimation*, `a* = argmin ‖h(a) − z‖²_Σ`,
/// with a robust loss `ρ`.
///
/// Each iteration accumulates the normal equations block by block ([`NormalEquations`], eq. 4.4
/// with IRLS weights), factorizes `A` (+ damping) by Cholesky ([`Factor`](super::Factor)),
/// solves for `ξ` and moves `a ← a ⊕ ξ` (eq. 4.5, `a ⊕ ξ = a·exp(ξ^)`).
///
/// # Errors
/// [`SolveError::InvalidOptions`], [`SolveError::NonFiniteGuess`], any error of the problem at the
/// guess, [`SolveError::NotPositiveDefinite`] when `A` is singular (Gauss-Newton: at any
/// iterate; both methods: at the solution, where the covariance is formed),
/// [`SolveError::NonFiniteResidual`] for a non-finite cost or step. A returned state is always
/// finite.
pub fn solve<T, S, P, const N: usize, const K: usize>(
    problem: &P,
    initial: &S,
    options: &SolverOptions<T>,
) -> Result<Solution<T, S, N>, SolveError>
where
    T: Real,
    S: Manifold<T, N>,
    P: Problem<T, S, N, K> + ?Sized,
{
    let mut solution = Solution::placeholder(initial);
    solve_into(problem, options, &mut solution)?;
    Ok(solution)
}

impl<T: Real, S: Copy, const N: usize> Solution<T, S, N> {
    /// A value to be overwritten by [`solve_into`]: `state = *initial`, zero covariance and
    /// costs, no iterations.
    pub(crate) fn placeholder(initial: &S) -> Self {
        Self {
            state: *initial,
            covariance: SMatrix::zeros(),
            iterations: 0,
            initial_cost: T::zero(),
            final_cost: T::zero(),
            status: Status::MaxIterations,
        }
    }
}

/// [`solve`] from the guess `out.state`, writing its result into `out` (every field, on
/// success): the state is iterated in place, and a caller that keeps the solution holds one
/// copy of the `N × N` covariance on its stack. On error `out` may hold a partial result.
///
/// Only the storage and the problem-specific steps ([`Candidate`]) are per problem; the rest
/// ([`drive`]) is compiled once.
///
/// # Errors
/// As [`solve`].
pub(crate) fn solve_into<T, S, P, const N: usize, const K: usize>(
    problem: &P,
    options: &SolverOptions<T>,
    out: &mut Solution<T, S, N>,
) -> Result<(), SolveError>
where
    T: Real,
    S: Manifold<T, N>,
    P: Problem<T, S, N, K> + ?Sized,
{
    let Solution {
        state, covariance, ..
    } = out;
    let mut run = Run::<T, S, P, N, K> {
        problem,
        loss: options.loss,
        candidate: *state,
        state,
        ne: NormalEquations::zeros(),
        // The trial linearization, reused across iterations.
        trial: NormalEquations::zeros(),
        step: SVector::zeros(),
    };
    let done = drive(&mut run, options, covariance.as_mut_slice())?;
    out.iterations = done.iterations;
    out.initial_cost = done.initial_cost;
    out.final_cost = done.final_cost;
    out.status = done.status;
    Ok(())
}

/// The scalar results of [`drive`].
struct Done<T> {
    iterations: usize,
    initial_cost: T,
    final_cost: T,
    status: Status,
}

/// [`solve_into`] past the allocation of its storage: validation, the linearization at the
/// guess, [`iterate`], and the covariance `A⁻¹` of the last linearization into `cov`
/// (column-major). One copy of the code for every problem and dimension.
///
/// # Errors
/// As [`solve`].
fn drive<T: Real>(
    run: &mut dyn Candidate<T>,
    options: &SolverOptions<T>,
    cov: &mut [T],
) -> Result<Done<T>, SolveError> {
    if !options.is_valid() {
        return Err(SolveError::InvalidOptions);
    }
    if !run.finite() {
        return Err(SolveError::NonFiniteGuess);
    }
    // The candidate is the guess: its linearization becomes the current one.
    linearize(run)?;
    run.accept(true);
    let initial_cost = run.parts().cost;
    let (iterations, status) = iterate(run, options)?;
    // `cov = A⁻¹`, factorized in the trial's information as scratch (the trial linearization is
    // no longer needed).
    let finite = run.finite();
    run.information_to_scratch();
    let p = run.parts();
    if !finite || !p.cost.is_finite() {
        return Err(SolveError::NonFiniteResidual);
    }
    let n = p.step.len();
    linalg::factor(p.scratch, n)?;
    linalg::inverse(p.scratch, n, cov)?;
    Ok(Done {
        iterations,
        initial_cost,
        final_cost: p.cost,
        status,
    })
}

/// [`NormalEquations::build`] at the candidate of `run`, into its trial linearization: the
/// problem-specific accumulation, then the shared finiteness test.
///
/// # Errors
/// As [`NormalEquations::build`].
fn linearize<T: Real>(run: &mut dyn Candidate<T>) -> Result<(), SolveError> {
    run.linearize()?;
    let p = run.parts();
    finite_sums(p.scratch, p.trial_gradient, p.trial_cost)
}

/// What [`iterate`] needs of a step `ξ`: `‖ξ‖`, the model decrease terms `ξᵀAξ` and `ξᵀg`.
#[derive(Clone, Copy)]
struct StepStats<T> {
    norm: T,
    info: T,
    gradient: T,
}

/// The storage of a [`Candidate`] as slices over its column-major arrays (`n` the length of
/// `step`): the current linearization, the trial one's information as scratch, the step.
struct Parts<'a, T> {
    /// `A` (`n × n`) of the current linearization.
    information: &'a [T],
    /// `g` of the current linearization.
    gradient: &'a [T],
    /// `F` of the current linearization.
    cost: T,
    /// The trial linearization's `A` (`n × n`), scratch between linearizations.
    scratch: &'a mut [T],
    /// `g` of the trial linearization.
    trial_gradient: &'a [T],
    /// `F` of the trial linearization.
    trial_cost: T,
    /// The step `ξ`.
    step: &'a mut [T],
}

/// The problem- and dimension-dependent half of [`solve_into`], behind `dyn`, so that the rest
/// ([`drive`], [`iterate`]: damping, gain ratio, acceptance, convergence, covariance) is
/// compiled once, not once per problem or per dimension.
trait Candidate<T: Real> {
    /// The storage, as slices.
    fn parts(&mut self) -> Parts<'_, T>;
    /// `true` when the current state is finite.
    fn finite(&self) -> bool;
    /// The trial linearization's information becomes a copy of the current one's, `A`.
    fn information_to_scratch(&mut self);
    /// Forms the candidate `a ⊕ ξ` (eq. 4.5) from the current state and the kept step;
    /// `true` when it is finite.
    fn propose(&mut self) -> bool;
    /// The normal equations at the candidate, into the trial, unchecked (see [`linearize`]).
    fn linearize(&mut self) -> Result<(), SolveError>;
    /// The candidate becomes the state; with `adopt_trial` the trial linearization becomes the
    /// current one (the old one is scratch from then on).
    fn accept(&mut self, adopt_trial: bool);
}

/// The state of [`solve_into`]: the problem, its loss, the current state and the candidate, the
/// linearization at the state and the trial one, and the last step.
struct Run<'a, T: Real, S, P: ?Sized, const N: usize, const K: usize> {
    problem: &'a P,
    loss: Loss<T>,
    state: &'a mut S,
    candidate: S,
    ne: NormalEquations<T, N>,
    trial: NormalEquations<T, N>,
    step: SVector<T, N>,
}

impl<T, S, P, const N: usize, const K: usize> Candidate<T> for Run<'_, T, S, P, N, K>
where
    T: Real,
    S: Manifold<T, N>,
    P: Problem<T, S, N, K> + ?Sized,
{
    fn parts(&mut self) -> Parts<'_, T> {
        Parts {
            information: self.ne.information.as_slice(),
            gradient: self.ne.gradient.as_slice(),
            cost: self.ne.cost,
            scratch: self.trial.information.as_mut_slice(),
            trial_gradient: self.trial.gradient.as_slice(),
            trial_cost: self.trial.cost,
            step: self.step.as_mut_slice(),
        }
    }

    fn finite(&self) -> bool {
        self.state.all_finite()
    }

    fn information_to_scratch(&mut self) {
        self.trial.information = self.ne.information;
    }

    fn propose(&mut self) -> bool {
        self.candidate = self.state.oplus(&self.step);
        self.candidate.all_finite()
    }

    fn linearize(&mut self) -> Result<(), SolveError> {
        self.trial
            .accumulate(self.problem, &self.candidate, &self.loss)
    }

    fn accept(&mut self, adopt_trial: bool) {
        *self.state = self.candidate;
        if adopt_trial {
            core::mem::swap(&mut self.ne, &mut self.trial);
        }
    }
}

/// The Gauss-Newton / Levenberg-Marquardt iteration of [`solve_into`] from the linearization at
/// the current state of `run` (see the [module docs](crate::gn)): returns the iterations run and
/// why it stopped, with `run`'s linearization the one at the final state (or just before a
/// converged step, see [`Solution::final_cost`]).
///
/// # Errors
/// As [`solve`], for the failures that happen during the iteration.
fn iterate<T: Real>(
    run: &mut dyn Candidate<T>,
    options: &SolverOptions<T>,
) -> Result<(usize, Status), SolveError> {
    let mut lambda = options.initial_damping;
    let mut nu = T::lit(2.0);
    let mut status = Status::MaxIterations;
    let mut iterations = 0;
    let lm = options.method == Method::LevenbergMarquardt;

    while iterations < options.max_iterations {
        iterations += 1;
        run.information_to_scratch();
        let p = run.parts();
        let cost = p.cost;
        if cost <= T::zero() {
            status = Status::CostConverged;
            break;
        }
        // `None`: the damped information did not factorize (Levenberg-Marquardt only), and the
        // step is rejected like one that does not lower the cost.
        let step = match damped_step(p.scratch, p.information, p.gradient, lambda, lm, p.step) {
            Ok(s) => Some(s),
            Err(StepError::Solve(e)) => return Err(e),
            Err(StepError::Factor(e)) if !lm => return Err(e),
            Err(StepError::Factor(_)) => None,
        };
        if let Some(step) = step {
            let small_step = step.norm <= options.step_tolerance
                || step.info <= options.information_step_tolerance;
            let candidate_finite = run.propose();
            // A converged step (Gauss-Newton, or Levenberg-Marquardt with little damping) is
            // taken without another pass over the residuals: it moves the state by at most
            // `√information_step_tolerance` standard deviations, so the information, cost and
            // covariance of the current linearization hold to that order.
            if step.info <= options.information_step_tolerance
                && (!lm || lambda <= T::one())
                && candidate_finite
            {
                run.accept(false);
                status = Status::StepConverged;
                break;
            }
            let built = if candidate_finite {
                linearize(run)
            } else {
                Err(SolveError::NonFiniteResidual)
            };
            let trial_cost = run.parts().trial_cost;
            let accepted = match built {
                Ok(()) => {
                    if lm {
                        // Gain ratio of the actual to the predicted decrease of the weighted
                        // model F(ξ) ≈ F + 2ξᵀg + ξᵀAξ: predicted = −2ξᵀg − ξᵀAξ.
                        let actual = cost - trial_cost;
                        let predicted = -(step.gradient * T::lit(2.0)) - step.info;
                        if actual > T::zero() && predicted > T::zero() {
                            let r = actual / predicted;
                            let c = T::lit(2.0) * r - T::one();
                            lambda *= (T::one() - c * c * c).max(T::lit(1.0 / 3.0));
                            nu = T::lit(2.0);
                            true
                        } else {
                            false
                        }
                    } else {
                        true
                    }
                }
                Err(e) if !lm => return Err(e),
                Err(_) => false,
            };
            if accepted {
                let decrease = cost - trial_cost;
                run.accept(true);
                if small_step {
                    status = Status::StepConverged;
                    break;
                }
                if decrease >= T::zero() && decrease <= options.cost_tolerance * cost {
                    status = Status::CostConverged;
                    break;
                }
                continue;
            }
            if small_step {
                status = Status::StepConverged;
                break;
            }
        }
        // Rejected: more damping.
        lambda *= nu;
        nu *= T::lit(2.0);
        if lambda > T::lit(MAX_DAMPING) {
            status = Status::DampingSaturated;
            break;
        }
    }
    Ok((iterations, status))
}

/// Why [`damped_step`] produced no step.
enum StepError {
    /// The (damped) information did not factorize.
    Factor(SolveError),
    /// The substitution gave a non-finite step.
    Solve(SolveError),
}

/// The step `ξ` of one iteration, into `step`: `(A + λ diag A) ξ = −g` (Levenberg-Marquardt,
/// `lm`) or `A ξ = −g` (Gauss-Newton), with the figures [`iterate`] needs, on the column-major
/// storage: `a` is the `n × n` information, `g` the gradient, `damped` a copy of `a` that
/// becomes the damped matrix and its factor (`n` the length of `step`). One copy of the code
/// for every dimension.
fn damped_step<T: Real>(
    damped: &mut [T],
    a: &[T],
    g: &[T],
    lambda: T,
    lm: bool,
    step: &mut [T],
) -> Result<StepStats<T>, StepError> {
    let n = step.len();
    if lm {
        damp(damped, n, lambda);
    }
    linalg::factor(damped, n).map_err(StepError::Factor)?;
    for (x, &gk) in step.iter_mut().zip(g) {
        *x = -gk;
    }
    solve_in_place(damped, n, step);
    if !all_finite(step) {
        return Err(StepError::Solve(SolveError::NonFiniteResidual));
    }
    Ok(step_stats(a, g, step))
}

/// `a·b` for two columns of `K` entries: nalgebra's `dot` of owned fixed-size vectors (its
/// unrolled sums; no column view, so no index assertion), inlined where it is used
/// (`NormalEquations::add` runs it `N² + N` times per block).
#[inline(always)]
fn dot_k<T: Real, const K: usize>(a: &[T; K], b: &[T; K]) -> T {
    SVector::<T, K>::from(*a).dot(&SVector::<T, K>::from(*b))
}

/// `‖ξ‖`, `ξᵀAξ` and `ξᵀg` for the column-major `n × n` matrix `a` (`n` the length of `step`).
fn step_stats<T: Real>(a: &[T], g: &[T], step: &[T]) -> StepStats<T> {
    let n = step.len();
    // ξᵀAξ = Σ_c ξ_c (A ξ)_c, with (A ξ)_c = Σ_r A_rc ξ_r for the symmetric A (column c of A).
    let info = if n == 0 {
        T::zero()
    } else {
        columns(a, n)
            .zip(step)
            .fold(T::zero(), |acc, (col, &x)| acc + x * dot(col, step))
    };
    StepStats {
        norm: dot(step, step).sqrt_rn(),
        info,
        gradient: dot(step, g),
    }
}

/// Marquardt scaling on the diagonal of the column-major `n × n` matrix `a`:
/// `Aₖₖ += λ·max(Aₖₖ, ε·maxₖ Aₖₖ)`, the floor so that a zero column still gets damped. The
/// dimension is a run-time number: one copy of the code for every `N`.
fn damp<T: Real>(a: &mut [T], n: usize, lambda: T) {
    let diagonal = |a: &[T], k: usize| a.get(k * n + k).copied();
    let mut largest = diagonal(a, 0).unwrap_or_else(T::zero);
    for k in 1..n {
        if let Some(d) = diagonal(a, k) {
            if d > largest {
                largest = d;
            }
        }
    }
    let floor = largest * T::lit(T::EPSILON_F64);
    for k in 0..n {
        if let Some(x) = a.get_mut(k * n + k) {
            *x += lambda * (*x).max(floor);
        }
    }
}

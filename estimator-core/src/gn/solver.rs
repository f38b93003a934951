//! The solver core: block-wise accumulation of the normal equations, Gauss-Newton and
//! Levenberg-Marquardt steps through `⊕`, convergence tests, covariance.
//!
//! See the [module docs](crate::gn) for how each step maps to the seed paper's equations.

use super::linalg::Factor;
use super::{Loss, Manifold, SolveError};
use crate::Real;
use nalgebra::{SMatrix, SVector};

/// A set of residual blocks of dimension `K` over a state `S` with `N` degrees of freedom.
///
/// For each block `i`, `linearize` hands the *whitened* error `eᵢ = Σᵢ^{-1/2} (hᵢ(a) − zᵢ)` and its
/// Jacobian `Jᵢ = ∂eᵢ/∂ξ` at `ξ = 0` in the sense of seed Def. 4.6, i.e.
/// `eᵢ(a ⊕ ξ) ≈ eᵢ(a) + Jᵢ ξ` (seed eq. 4.3), to `sink`. Nothing is stored: the solver folds each
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

/// The accumulated normal equations of seed eq. (4.4) with IRLS weights `wᵢ = ρ'(‖eᵢ‖²)`:
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

    /// Folds one block in: `A += w JᵀJ`, `g += w Jᵀe`, `F += ρ(‖e‖²)`.
    #[inline]
    pub fn add<const K: usize>(&mut self, loss: &Loss<T>, e: &SVector<T, K>, j: &SMatrix<T, K, N>) {
        let (rho, w) = loss.evaluate(e.norm_squared());
        let wj = j * w;
        self.information += wj.tr_mul(j);
        self.gradient += wj.tr_mul(e);
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
        problem.linearize(state, |e, j| ne.add(loss, e, j))?;
        if ne.cost.is_finite()
            && ne.gradient.iter().all(|x| x.is_finite())
            && ne.information.iter().all(|x| x.is_finite())
        {
            Ok(ne)
        } else {
            Err(SolveError::NonFiniteResidual)
        }
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
        let ok = |x: T| x.is_finite() && x >= T::zero();
        self.loss.is_valid()
            && ok(self.step_tolerance)
            && ok(self.cost_tolerance)
            && ok(self.information_step_tolerance)
            && ok(self.initial_damping)
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

/// Minimizes `F(a) = Σᵢ ρ(‖hᵢ(a) − zᵢ‖²_Σ)` (seed eq. 4.1 with a robust loss) over the manifold
/// `S`, from `initial`.
///
/// Each iteration accumulates the normal equations block by block ([`NormalEquations`], seed
/// eq. 4.4 with IRLS weights), factorizes `A` (+ damping) by Cholesky ([`Factor`]), solves for
/// `ξ` and moves `a ← a ⊕ ξ` (seed eq. 4.5).
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
    if !options.is_valid() {
        return Err(SolveError::InvalidOptions);
    }
    if !initial.all_finite() {
        return Err(SolveError::NonFiniteGuess);
    }
    let loss = options.loss;
    let mut state = *initial;
    let mut ne = NormalEquations::build(problem, &state, &loss)?;
    let initial_cost = ne.cost;
    let mut lambda = options.initial_damping;
    let mut nu = T::lit(2.0);
    let mut status = Status::MaxIterations;
    let mut iterations = 0;
    let lm = options.method == Method::LevenbergMarquardt;

    while iterations < options.max_iterations {
        iterations += 1;
        if ne.cost <= T::zero() {
            status = Status::CostConverged;
            break;
        }
        let mut damped = ne.information;
        if lm {
            // Marquardt scaling: λ·diag(A), with a floor so a zero column still gets damped.
            let floor = ne.information.diagonal().max() * T::lit(T::EPSILON_F64);
            for (k, d) in ne.information.diagonal().iter().enumerate() {
                if let Some(x) = damped.get_mut((k, k)) {
                    *x += lambda * (*d).max(floor);
                }
            }
        }
        let factor = match Factor::new(&damped) {
            Ok(f) => f,
            Err(e) if !lm => return Err(e),
            Err(_) => {
                lambda *= nu;
                nu *= T::lit(2.0);
                if lambda > T::lit(MAX_DAMPING) {
                    status = Status::DampingSaturated;
                    break;
                }
                continue;
            }
        };
        let step = factor.solve(&-ne.gradient)?;
        let step_norm = step.norm();
        let step_info = step.dot(&(ne.information * step));
        let small_step =
            step_norm <= options.step_tolerance || step_info <= options.information_step_tolerance;
        let candidate = state.oplus(&step);
        // A converged step (Gauss-Newton, or Levenberg-Marquardt with little damping) is taken
        // without another pass over the residuals: it moves the state by at most
        // `√information_step_tolerance` standard deviations, so the information, cost and
        // covariance of the current linearization hold to that order.
        if step_info <= options.information_step_tolerance
            && (!lm || lambda <= T::one())
            && candidate.all_finite()
        {
            state = candidate;
            status = Status::StepConverged;
            break;
        }
        let trial = if candidate.all_finite() {
            NormalEquations::build(problem, &candidate, &loss)
        } else {
            Err(SolveError::NonFiniteResidual)
        };
        let accepted = match trial {
            Ok(t) => {
                if lm {
                    // Gain ratio of the actual to the predicted decrease of the weighted model
                    // F(ξ) ≈ F + 2ξᵀg + ξᵀAξ: predicted = −2ξᵀg − ξᵀAξ.
                    let actual = ne.cost - t.cost;
                    let predicted = -(step.dot(&ne.gradient) * T::lit(2.0)) - step_info;
                    if actual > T::zero() && predicted > T::zero() {
                        let r = actual / predicted;
                        let c = T::lit(2.0) * r - T::one();
                        lambda *= (T::one() - c * c * c).max(T::lit(1.0 / 3.0));
                        nu = T::lit(2.0);
                        Some(t)
                    } else {
                        None
                    }
                } else {
                    Some(t)
                }
            }
            Err(e) if !lm => return Err(e),
            Err(_) => None,
        };
        match accepted {
            Some(t) => {
                let decrease = ne.cost - t.cost;
                let old_cost = ne.cost;
                state = candidate;
                ne = t;
                if small_step {
                    status = Status::StepConverged;
                    break;
                }
                if decrease >= T::zero() && decrease <= options.cost_tolerance * old_cost {
                    status = Status::CostConverged;
                    break;
                }
            }
            None => {
                if small_step {
                    status = Status::StepConverged;
                    break;
                }
                lambda *= nu;
                nu *= T::lit(2.0);
                if lambda > T::lit(MAX_DAMPING) {
                    status = Status::DampingSaturated;
                    break;
                }
            }
        }
    }

    if !state.all_finite() || !ne.cost.is_finite() {
        return Err(SolveError::NonFiniteResidual);
    }
    let covariance = Factor::new(&ne.information)?.inverse()?;
    Ok(Solution {
        state,
        covariance,
        iterations,
        initial_cost,
        final_cost: ne.cost,
        status,
    })
}

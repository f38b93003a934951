//! Fixed-size Gauss-Newton / Levenberg-Marquardt on manifolds, with camera pose from landmark
//! projections (PnP), triangulation, rotation from vector pairs and robust losses: section 4
//! ("Optimization for Robotics") of *Lie Groups and Smooth Manifolds for Robotic State
//! Estimation* as a solver that fits on a microcontroller.
//!
//! Everything is generic over `T:`[`Real`](crate::Real) (`f32`, `f64`), sized at compile time
//! (state dimension `N`, residual dimension `K`), allocation-free and panic-free: every failure is
//! a [`SolveError`].
//!
//! # From the paper's equations to the code
//!
//! Equation numbers are those of *Lie Groups and Smooth Manifolds for Robotic State Estimation*.
//!
//! | paper | here |
//! |---|---|
//! | (4.1) `a* = argmin ‖h(a) − z‖²_Σ`, with `‖e‖²_Σ = eᵀΣ⁻¹e` | [`solve`] minimizes `F(a) = Σᵢ ρ(‖hᵢ(a) − zᵢ‖²_Σᵢ)`; each [`Problem`] block hands the **whitened** error `eᵢ = Σᵢ^{-1/2}(hᵢ(a) − zᵢ)`, so `‖eᵢ‖² = ‖hᵢ(a) − zᵢ‖²_Σᵢ`; `ρ` is a [`Loss`] (`ρ(s) = s` gives (4.1) exactly) |
//! | Def. 4.6: `F_a` is the Jacobian of `f` at `a` when `‖f(a) + F_a ξ − f(a·exp(ξ^))‖ / ‖ξ‖ → 0` | every block's `Jᵢ = ∂eᵢ/∂ξ` is that right Jacobian (checked against finite differences through `⊕` in the tests) |
//! | (4.3) `h(a ⊕ ξ) ≈ h(a) + H_a ξ` | the linearization `eᵢ(a ⊕ ξ) ≈ eᵢ + Jᵢ ξ` passed to [`Problem::linearize`] |
//! | (4.4) `ξ* = argmin ‖h(a) + H_a ξ − z‖²_Σ`, i.e. `Hᵀ H ξ* = Hᵀ(z − h(a))` | [`NormalEquations`]: `A = Σ wᵢ JᵢᵀJᵢ = HᵀWH`, `g = Σ wᵢ Jᵢᵀeᵢ = −HᵀW(z − h(a))`, summed block by block, no full `H` stored; IRLS weights `wᵢ = ρ'(‖eᵢ‖²)`; solved by Cholesky `A = LLᵀ` ([`Factor`]), `A ξ = −g` (Gauss-Newton) or `(A + λ diag A) ξ = −g` (Levenberg-Marquardt) |
//! | (4.5) `a ⊕ ξ = a·exp(ξ^)` | the step `a ← a ⊕ ξ` ([`Manifold::oplus`], [`crate::lie::LieGroup::rplus`]) |
//! | §4, `z = π(T p)`; Theorem 5.1, `F_(T,p) = T [H(p), I]` with `H(p) = [−p]×` for the rotation (Example 5.2) | [`solve_pnp`]: `z = K π(T p)` with [`PinholeCamera`]; the Jacobian is `∂(T p)/∂ξ = [R, −R[p]×]` (`ξ = [v; ω]`) chained with `∂(Kπ)/∂x` ([`reprojection_error`]) |
//!
//! # Iteration, convergence, covariance
//!
//! Levenberg-Marquardt accepts a step when the robust cost decreases, and updates `λ` from the
//! gain ratio `ϱ = (F(a) − F(a ⊕ ξ)) / (−2ξᵀg − ξᵀAξ)` (Nielsen: `λ ← λ·max(1/3, 1 − (2ϱ−1)³)`
//! on success, `λ ← λν, ν ← 2ν` on failure), a trust-region rule. It stops on
//! `‖ξ‖ ≤ step_tolerance`, on a relative cost decrease `≤ cost_tolerance`, or at
//! `max_iterations`, and says which in [`Status`]. The covariance of the solution is
//! `A⁻¹ = (HᵀWH)⁻¹` at the optimum, in the tangent of the right perturbation `a* ⊕ ξ`.
//!
//! # Robust losses and outliers
//!
//! [`Loss::Huber`] and [`Loss::Cauchy`] enter as iteratively reweighted least squares: the
//! weights `wᵢ = ρ'(‖eᵢ‖²)` are recomputed at every linearization, and Levenberg-Marquardt
//! accepts a step only if the robust cost `Σ ρ` decreases. The camera-facing functions take the
//! scale in pixels. [`solve_pnp`] uses the robust loss from the first iteration (from a guess
//! 20° off, every residual is large, and the weights still rank the points) and, at the
//! solution, marks inliers by the χ²(2) test `‖eⱼ‖² ≤ inlier_chi2`. With a robust loss the
//! returned covariance is `(Σ wᵢ JᵢᵀJᵢ)⁻¹` with the final weights, a little wider than the
//! inlier-only one (`wᵢ < 1` for every residual with a Cauchy loss).
//!
//! # Capacity, precision, failures
//!
//! State and residual sizes are const generics; nothing is stored per residual, so the number of
//! residuals is limited only by the input slices, except in [`solve_pnp`], whose [`Inliers`]
//! bitset holds [`PNP_CAPACITY`] = 128 points (more is [`SolveError::TooManyObservations`]).
//! In `f32`, every literal is converted by `T::lit` at compile time and no `f64` operation runs.
//! No function panics: inputs, options and guesses are validated, the factorization reports
//! singularity ([`Factor`]), and a state, covariance or cost that is not finite is never returned
//! as a success.
//!
//! # Modules
//!
//! * [`solver`]: [`Problem`], [`ResidualBlock`], [`NormalEquations`], [`solve`], options, status.
//! * [`linalg`]: the Cholesky factor with a typed failure and a relative pivot test.
//! * [`loss`]: Huber and Cauchy as IRLS.
//! * [`manifold`]: the state trait, Lie groups, `Rⁿ`, products ([`Product`]).
//! * [`camera`], [`pnp`], [`triangulation`], [`rotation`]: the models.

pub mod camera;
mod error;
pub mod linalg;
pub mod loss;
pub mod manifold;
pub mod pnp;
pub mod rotation;
pub mod solver;
pub mod triangulation;

pub use camera::PinholeCamera;
pub use error::SolveError;
pub use linalg::Factor;
pub use loss::Loss;
pub use manifold::{Manifold, Product};
pub use pnp::{
    check_point_spread, reprojection_error, solve_pnp, Inliers, PnpOptions, PnpProblem,
    PnpSolution, PNP_CAPACITY,
};
pub use rotation::{solve_rotation_from_vectors, vector_pair_error, RotationSolution, VectorPair};
pub use solver::{
    solve, Method, NormalEquations, Problem, ResidualBlock, Solution, SolverOptions, Status,
};
pub use triangulation::{
    point_reprojection_error, triangulate, Triangulation, TriangulationOptions,
};

/// `true` when every `x` is finite and `x > 0` (`false` for NaN): the check of scales, noise
/// levels and focal lengths in the options of every solver.
pub(crate) fn all_positive<T: crate::Real>(xs: &[T]) -> bool {
    xs.iter().all(|&x| crate::kernels::positive_finite(x))
}

//! Rotation from paired direction observations (for example gravity and the magnetic field in
//! the body frame against their world references): the start-up attitude of a filter, solved
//! by the same [`solve`](super::solve) core over `SO(3)`.
//!
//! Each pair gives a body-frame direction `bᵢ` and its world-frame reference `wᵢ` (both are
//! normalized; only directions matter). The model is `bᵢ = R⁻¹ wᵢ` with
//! `R = world_from_body`, the residual `eᵢ = (Rᵀ wᵢ − bᵢ)/σᵢ`. For `R ⊕ δ = R exp(δ^)` (eq. 4.5
//! of *Lie Groups and Smooth Manifolds for Robotic State Estimation*),
//! `(R exp δ^)ᵀ w = exp(−δ^) Rᵀw ≈ Rᵀw − δ × Rᵀw = Rᵀw + [Rᵀw]× δ`, so
//! `∂eᵢ/∂δ = [Rᵀ wᵢ]× / σᵢ`: the Jacobian of Definition 4.6 (`F_a` with
//! `‖f(a) + F_a δ − f(a·exp(δ^))‖ / ‖δ‖ → 0`), the action Jacobian `R[−p]×` of Theorem 5.1 and
//! Example 5.2 for the inverse rotation. `σᵢ` is the angular noise of `bᵢ` in radians. The Jacobian's null space is the
//! observed direction itself: one pair leaves the rotation about it unobservable, two
//! non-parallel pairs fix all three angles.
//!
//! Without a guess, the start is TRIAD: the orthonormal triads `(u, u×v/‖·‖, u×(u×v)/‖·‖)` built
//! from the first pair `u` and the pair most perpendicular to it `v`, in both frames, give
//! `R₀ = W Bᵀ`.

use super::solver::{solve_into, Problem, Solution, SolverOptions, Status};
use super::SolveError;
use crate::kernels::{all_finite, mat3, positive_finite};
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// One paired observation: a direction measured in the body frame and its known direction in the
/// world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VectorPair<T: Real> {
    /// Measured direction in the body frame (any non-zero length).
    pub body: Vector3<T>,
    /// Reference direction in the world frame (any non-zero length).
    pub world: Vector3<T>,
    /// Angular standard deviation of the measured direction, radians (`> 0`).
    pub sigma: T,
}

/// The result of [`solve_rotation_from_vectors`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotationSolution<T: Real> {
    /// `R = world_from_body`.
    pub world_from_body: So3<T>,
    /// Covariance of `δ` in `R ⊕ δ` (rad², body frame, right perturbation).
    pub covariance: Matrix3<T>,
    /// Iterations run.
    pub iterations: usize,
    /// Robust cost at the solution (whitened).
    pub final_cost: T,
    /// Why the iteration stopped.
    pub status: Status,
}

/// Relative threshold on `‖u × v‖` (unit vectors) under which two directions count as parallel.
const PARALLEL_REL: f64 = 1e-6;

/// The whitened residual of one pair and its Jacobian: `((Rᵀw − b)/σ, [Rᵀw]×/σ)` with unit `w`,
/// `b` (see the module docs).
#[must_use]
pub fn vector_pair_error<T: Real>(
    world_from_body: &So3<T>,
    body_unit: &Vector3<T>,
    world_unit: &Vector3<T>,
    inv_sigma: T,
) -> (Vector3<T>, Matrix3<T>) {
    let pred = world_from_body.inverse().act(world_unit);
    ((pred - body_unit) * inv_sigma, skew(&pred) * inv_sigma)
}

/// `v / ‖v‖`; `None` unless `‖v‖` is finite and positive.
pub(super) fn unit<T: Real>(v: &Vector3<T>) -> Option<Vector3<T>> {
    let (u, n) = normalized(v);
    positive_finite(n).then_some(u)
}

/// `(v / ‖v‖, ‖v‖)`, whatever the norm (for [`unit()`] and the rays of
/// [`triangulate`](super::triangulate)).
pub(super) fn normalized<T: Real>(v: &Vector3<T>) -> (Vector3<T>, T) {
    let n = v.norm_squared().sqrt_rn();
    (v / n, n)
}

/// The orthonormal triad `(u, s, u × s)`, `s = u×v/‖u×v‖`, of the unit vector `u` and a second
/// direction `v`, as the columns of a matrix; `None` when they are parallel (`‖u × v‖` at most
/// `PARALLEL_REL`).
fn triad_frame<T: Real>(u: &Vector3<T>, v: &Vector3<T>) -> Option<Matrix3<T>> {
    let (s, nn) = normalized(&u.cross(v));
    let not_parallel = nn > T::lit(PARALLEL_REL);
    not_parallel.then(|| Matrix3::from_columns(&[*u, s, u.cross(&s)]))
}

/// The TRIAD rotation `W Bᵀ` from two body/world pairs of unit vectors.
pub(super) fn triad<T: Real>(
    b1: &Vector3<T>,
    b2: &Vector3<T>,
    w1: &Vector3<T>,
    w2: &Vector3<T>,
) -> Option<So3<T>> {
    let b = triad_frame(b1, b2)?;
    let w = triad_frame(w1, w2)?;
    So3::from_rotation_matrix(&mat3::mul(&w, &b.transpose()))
}

/// [`triad`] of the unit vectors of two pairs; `None` for a zero vector or parallel directions.
fn triad_pairs<T: Real>(first: &VectorPair<T>, second: &VectorPair<T>) -> Option<So3<T>> {
    triad(
        &unit(&first.body)?,
        &unit(&second.body)?,
        &unit(&first.world)?,
        &unit(&second.world)?,
    )
}

/// The TRIAD start of [`solve_rotation_from_vectors`]: from the first pair and the pair whose body
/// direction is most perpendicular to the first one's (the first such pair on a tie).
///
/// # Errors
/// [`SolveError::DegenerateGeometry`]: fewer than 2 pairs, a zero vector, or parallel directions.
pub(super) fn triad_start<T: Real>(pairs: &[VectorPair<T>]) -> Result<So3<T>, SolveError> {
    // Every pair's vectors are checked here; the best pair is kept by reference and its unit
    // vectors formed again by `triad_pairs`.
    let (first, rest) = pairs.split_first().ok_or(SolveError::DegenerateGeometry)?;
    let b1 = unit(&first.body).ok_or(SolveError::DegenerateGeometry)?;
    let mut best: Option<(T, &VectorPair<T>)> = None;
    for p in rest {
        let b = unit(&p.body).ok_or(SolveError::DegenerateGeometry)?;
        unit(&p.world).ok_or(SolveError::DegenerateGeometry)?;
        let s = b1.cross(&b).norm_squared().sqrt_rn();
        if best.is_none_or(|(sb, _)| s > sb) {
            best = Some((s, p));
        }
    }
    let (_, second) = best.ok_or(SolveError::DegenerateGeometry)?;
    triad_pairs(first, second).ok_or(SolveError::DegenerateGeometry)
}

struct RotProblem<'a, T: Real> {
    pairs: &'a [VectorPair<T>],
}

impl<T: Real> Problem<T, So3<T>, 3, 3> for RotProblem<'_, T> {
    fn linearize<F>(&self, state: &So3<T>, mut sink: F) -> Result<(), SolveError>
    where
        F: FnMut(&SVector<T, 3>, &SMatrix<T, 3, 3>),
    {
        for pair in self.pairs {
            let (Some(b), Some(w)) = (unit(&pair.body), unit(&pair.world)) else {
                return Err(SolveError::DegenerateGeometry);
            };
            let (e, j) = vector_pair_error(state, &b, &w, T::one() / pair.sigma);
            sink(&e, &j);
        }
        Ok(())
    }
}

/// `R = world_from_body` from at least two non-parallel direction pairs, from `guess` or, when
/// `None`, from TRIAD; `options` are the solver's (a robust [`crate::gn::Loss`] has its scale in
/// standard deviations here).
///
/// # Errors
/// [`SolveError::TooFewObservations`] (fewer than 2 pairs); [`SolveError::NonFiniteInput`];
/// [`SolveError::InvalidOptions`] (a `σ ≤ 0` or invalid solver options);
/// [`SolveError::NonFiniteGuess`]; [`SolveError::DegenerateGeometry`] (a zero vector, or all
/// body or all world directions parallel); [`SolveError::NotPositiveDefinite`],
/// [`SolveError::NonFiniteResidual`] from the solver.
pub fn solve_rotation_from_vectors<T: Real>(
    pairs: &[VectorPair<T>],
    guess: Option<&So3<T>>,
    options: &SolverOptions<T>,
) -> Result<RotationSolution<T>, SolveError> {
    if pairs.len() < 2 {
        return Err(SolveError::TooFewObservations {
            needed: 2,
            got: pairs.len(),
        });
    }
    let finite = |v: &Vector3<T>| all_finite(v.as_slice());
    if !pairs
        .iter()
        .all(|p| finite(&p.body) && finite(&p.world) && p.sigma.is_finite())
    {
        return Err(SolveError::NonFiniteInput);
    }
    if !pairs.iter().all(|p| p.sigma > T::zero()) || !options.is_valid() {
        return Err(SolveError::InvalidOptions);
    }
    let start = triad_start(pairs)?;
    let start = match guess {
        Some(g) if g.is_finite() => *g,
        Some(_) => return Err(SolveError::NonFiniteGuess),
        None => start,
    };
    let mut sol = Solution::placeholder(&start);
    solve_into(&RotProblem { pairs }, options, &mut sol)?;
    let r = sol.state.normalize();
    if !r.is_finite() {
        return Err(SolveError::NonFiniteResidual);
    }
    Ok(RotationSolution {
        world_from_body: r,
        covariance: sol.covariance,
        iterations: sol.iterations,
        final_cost: sol.final_cost,
        status: sol.status,
    })
}

//! Camera pose from landmark projections (PnP): `z_j = K π(T p_j)`, the landmark model of
//! section 4 of *Lie Groups and Smooth Manifolds for Robotic State Estimation*
//! (`z_ij = π(T_i p_j)`), solved by the [`solve`](super::solve) core over `T ∈ SE(3)`.
//!
//! The Jacobian of the pixel with respect to the right perturbation `T ⊕ ξ`, `ξ = [v; ω]`, is the
//! action Jacobian of the paper's Theorem 5.1, `F_(T,p) = T [H(p), I]` with `H(p) = [−p]×` for
//! the rotation (Example 5.2), i.e. `∂(T p)/∂ξ = [R, −R[p]×]` ([`crate::lie::Se3`]'s
//! `act_jac`), chained with the projection's Jacobian ([`PinholeCamera::project_jac`]):
//!
//! ```text
//! ∂z/∂ξ = Jπ(x) · [R, −R[p]×],   x = T p.
//! ```
//!
//! It is evaluated as `B = Jπ R` (2×3) and, row by row, `bₖᵀ(−[p]×) = (p × bₖ)ᵀ`, the same
//! product without forming `R[p]×` (the tests compare it with `act_jac` and with finite
//! differences).

use super::solver::{solve_into, Method, Problem, Solution, SolverOptions, Status};
use super::{Loss, PinholeCamera, SolveError};
use crate::kernels::{all_finite, mat3};
use crate::lie::{LieGroup, Se3};
use crate::Real;
use nalgebra::{Matrix2x6, Matrix3, Matrix6, SMatrix, SVector, Vector2, Vector3};

/// Largest number of points [`solve_pnp`] accepts: the width of the [`Inliers`] bitset.
pub const PNP_CAPACITY: usize = 128;

/// Options of [`solve_pnp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PnpOptions<T: Real> {
    /// Gauss-Newton or Levenberg-Marquardt.
    pub method: Method,
    /// The robust loss, its scale **in pixels** (divided by `sigma_px` internally).
    pub loss: Loss<T>,
    /// Standard deviation of the pixel noise, per axis, pixels (`> 0`).
    pub sigma_px: T,
    /// Iteration cap.
    pub max_iterations: usize,
    /// Stop when the step `‖ξ‖` (metres and radians) is at most this.
    pub step_tolerance: T,
    /// Stop when an accepted step lowers the cost by at most this fraction.
    pub cost_tolerance: T,
    /// Stop when the step's Mahalanobis length `ξᵀAξ` is at most this (see
    /// [`SolverOptions::information_step_tolerance`]).
    pub information_step_tolerance: T,
    /// A point whose camera-frame depth is `≤ min_depth` (metres) counts as behind the camera.
    pub min_depth: T,
    /// Chi-square bound (2 degrees of freedom) on the whitened final residual `‖e‖²` below
    /// which a point is an inlier; the default `9.21` is the 99 % quantile.
    pub inlier_chi2: T,
}

impl<T: Real> Default for PnpOptions<T> {
    /// Levenberg-Marquardt, least squares, `sigma_px = 1`, 30 iterations, the solver's default
    /// tolerances, `min_depth = 1e-3` m, `inlier_chi2 = 9.21`.
    fn default() -> Self {
        let s = SolverOptions::<T>::default();
        Self {
            method: Method::LevenbergMarquardt,
            loss: Loss::LeastSquares,
            sigma_px: T::one(),
            max_iterations: 30,
            step_tolerance: s.step_tolerance,
            cost_tolerance: s.cost_tolerance,
            information_step_tolerance: s.information_step_tolerance,
            min_depth: T::lit(1e-3),
            inlier_chi2: T::lit(9.21),
        }
    }
}

impl<T: Real> PnpOptions<T> {
    /// The same options with another loss (its scale in pixels).
    #[must_use]
    pub fn with_loss(mut self, loss: Loss<T>) -> Self {
        self.loss = loss;
        self
    }

    /// The same options with noise `sigma_px`.
    #[must_use]
    pub fn with_sigma(mut self, sigma_px: T) -> Self {
        self.sigma_px = sigma_px;
        self
    }
}

/// Which observations passed the inlier test, as a bitset of up to [`PNP_CAPACITY`] entries
/// (bit `j` for observation `j`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Inliers {
    bits: u128,
    len: usize,
}

impl Inliers {
    /// The 32-bit word `k` of the bitset (bits `32k .. 32k + 31`), by shifts of constant amounts
    /// (on a 32-bit core a `u128` shift by a variable amount is a call to a four-word routine).
    fn word(&self, k: usize) -> u32 {
        // Each truncating cast keeps one 32-bit word.
        match k {
            0 => self.bits as u32,
            1 => (self.bits >> 32) as u32,
            2 => (self.bits >> 64) as u32,
            _ => (self.bits >> 96) as u32,
        }
    }

    /// `true` when observation `j` is an inlier (`false` beyond the length).
    #[must_use]
    pub fn contains(&self, j: usize) -> bool {
        j < self.len && (self.word(j / 32) >> (j % 32)) & 1 == 1
    }

    /// Number of inliers.
    #[must_use]
    pub fn count(&self) -> usize {
        (0..4).map(|k| self.word(k).count_ones() as usize).sum()
    }

    /// Number of observations tested.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` when no observation was tested.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The raw bitset.
    #[must_use]
    pub fn bits(&self) -> u128 {
        self.bits
    }

    /// One `bool` per observation, in order.
    pub fn iter(&self) -> impl Iterator<Item = bool> + '_ {
        (0..self.len).map(move |j| self.contains(j))
    }
}

/// The result of [`solve_pnp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PnpSolution<T: Real> {
    /// The estimate of `camera_from_world`.
    pub camera_from_world: Se3<T>,
    /// Covariance of `ξ = [v; ω]` in `camera_from_world ⊕ ξ` (m², rad²): the inverse
    /// information `(Hᵀ W H)⁻¹` at the optimum, with the pixel noise `sigma_px`.
    pub covariance: Matrix6<T>,
    /// Iterations run.
    pub iterations: usize,
    /// `Σ ρ(‖eⱼ‖²)` at the solution, whitened residuals (`‖e‖² = ‖z − ẑ‖²/σ²`).
    pub final_cost: T,
    /// Observations whose final whitened residual passes `‖e‖² ≤ inlier_chi2`.
    pub inliers: Inliers,
    /// Why the iteration stopped.
    pub status: Status,
}

/// The reprojection error of one landmark and its Jacobian, whitened by `1/σ`:
/// `e = (K π(T p) − z)/σ` and `∂e/∂ξ = Jπ(x)·[R | −R[p]×]/σ` for `T ⊕ ξ`, `x = T p`. `r` is the
/// rotation matrix of `T` (passed in so a pass over many points forms it once).
/// `None` unless the depth `x.z > min_depth`.
#[must_use]
pub fn reprojection_error<T: Real>(
    camera: &PinholeCamera<T>,
    r: &Matrix3<T>,
    t: &Vector3<T>,
    p: &Vector3<T>,
    z: &Vector2<T>,
    inv_sigma: T,
    min_depth: T,
) -> Option<(Vector2<T>, Matrix2x6<T>)> {
    let (uv, jp) = camera.project_jac(&(mat3::mul_vec(r, p) + t), min_depth)?;
    // `Jπ = [[fx/z, 0, −fx x/z²], [0, fy/z, −fy y/z²]]`, so row `i` of the translation block
    // `B = (Jπ/σ) R` is `f_i·(row i of R) + a_i·(row 3 of R)` with `f_i = Jπ_ii/σ`,
    // `a_i = Jπ_i3/σ`; the rotation block is `bᵢᵀ(−[p]×) = (p × bᵢ)ᵀ`.
    let r3 = r.row(2).transpose();
    let b0 = r.row(0).transpose() * (jp.m11 * inv_sigma) + r3 * (jp.m13 * inv_sigma);
    let b1 = r.row(1).transpose() * (jp.m22 * inv_sigma) + r3 * (jp.m23 * inv_sigma);
    let (c0, c1) = (p.cross(&b0), p.cross(&b1));
    #[rustfmt::skip]
    let j = Matrix2x6::new(
        b0.x, b0.y, b0.z, c0.x, c0.y, c0.z,
        b1.x, b1.y, b1.z, c1.x, c1.y, c1.z,
    );
    let e = (uv - z) * inv_sigma;
    Some((e, j))
}

/// The PnP residuals as a [`Problem`] over `Se3` (whitened, `K = 2`).
#[derive(Clone, Copy, Debug)]
pub struct PnpProblem<'a, T: Real> {
    /// Landmarks in the world frame.
    pub world_points: &'a [Vector3<T>],
    /// Their pixels.
    pub pixels: &'a [Vector2<T>],
    /// Intrinsics.
    pub camera: PinholeCamera<T>,
    /// `1/σ` of the pixel noise.
    pub inv_sigma: T,
    /// Minimum depth, metres.
    pub min_depth: T,
}

impl<T: Real> Problem<T, Se3<T>, 6, 2> for PnpProblem<'_, T> {
    fn linearize<F>(&self, state: &Se3<T>, mut sink: F) -> Result<(), SolveError>
    where
        F: FnMut(&SVector<T, 2>, &SMatrix<T, 2, 6>),
    {
        let r = state.rotation().rotation_matrix();
        let t = state.translation();
        for (p, z) in self.world_points.iter().zip(self.pixels) {
            let (e, j) =
                reprojection_error(&self.camera, &r, &t, p, z, self.inv_sigma, self.min_depth)
                    .ok_or(SolveError::PointBehindCamera)?;
            sink(&e, &j);
        }
        Ok(())
    }
}

/// Relative thresholds of the geometry test of [`check_point_spread`].
const COINCIDENT_REL: f64 = 1e-12;
const COLLINEAR_REL: f64 = 1e-10;

/// Refuses coincident or collinear points.
///
/// With the scatter `S = Σ (pⱼ − p̄)(pⱼ − p̄)ᵀ` and its eigenvalues `λ₁ ≥ λ₂ ≥ λ₃`: the points
/// coincide when `tr S = Σλ ≤ 1e-12 · n · (‖p̄‖² + 1)`, and they are collinear when the second
/// invariant `I₂ = λ₁λ₂ + λ₁λ₃ + λ₂λ₃` (sum of the principal 2×2 minors) satisfies
/// `I₂ ≤ 1e-10 · (tr S)²`; since `λ₁λ₂ ≤ I₂ ≤ 3λ₁λ₂` and `tr S/3 ≤ λ₁ ≤ tr S`, that bounds
/// `λ₂/λ₁` by about `1e-10` (a transverse spread below `1e-5` of the length).
///
/// # Errors
/// [`SolveError::DegenerateGeometry`].
pub fn check_point_spread<T: Real>(points: &[Vector3<T>]) -> Result<(), SolveError> {
    let n = points.len();
    if n == 0 {
        return Err(SolveError::DegenerateGeometry);
    }
    let count = T::from_usize(n).unwrap_or_else(T::one);
    let mean = points.iter().fold(Vector3::zeros(), |sum, p| sum + p) * (T::one() / count);
    // The six distinct entries of the symmetric `S`.
    let [mut s11, mut s22, mut s33, mut s12, mut s13, mut s23] = [T::zero(); 6];
    for p in points {
        let d = p - mean;
        s11 += d.x * d.x;
        s22 += d.y * d.y;
        s33 += d.z * d.z;
        s12 += d.x * d.y;
        s13 += d.x * d.z;
        s23 += d.y * d.z;
    }
    let tr = s11 + s22 + s33;
    let i2 = s11 * s22 - s12 * s12 + s11 * s33 - s13 * s13 + s22 * s33 - s23 * s23;
    let scale = mean.norm_squared() + T::one();
    let spread = tr > T::lit(COINCIDENT_REL) * count * scale;
    let not_collinear = i2 > T::lit(COLLINEAR_REL) * tr * tr;
    if spread && not_collinear {
        Ok(())
    } else {
        Err(SolveError::DegenerateGeometry)
    }
}

/// The χ²(2) inlier test `‖eⱼ‖² ≤ chi2` of every observation at `pose`.
///
/// # Errors
/// [`SolveError::PointBehindCamera`] if a point is at depth `≤ min_depth`.
fn inlier_mask<T: Real>(
    problem: &PnpProblem<'_, T>,
    pose: &Se3<T>,
    chi2: T,
) -> Result<Inliers, SolveError> {
    let r = pose.rotation().rotation_matrix();
    let t = pose.translation();
    // Four 32-bit words, assembled into the `u128` at the end (see `Inliers::word`).
    let mut words = [0u32; 4];
    let pairs = problem.world_points.iter().zip(problem.pixels);
    for (k, (p, z)) in pairs.enumerate() {
        // The pixel with the arithmetic of the solver's residual ([`reprojection_error`]).
        let (uv, _) = problem
            .camera
            .project_jac(&(mat3::mul_vec(&r, p) + t), problem.min_depth)
            .ok_or(SolveError::PointBehindCamera)?;
        let e = (uv - z) * problem.inv_sigma;
        if e.norm_squared() <= chi2 {
            if let Some(w) = words.get_mut(k / 32) {
                *w |= 1 << (k % 32);
            }
        }
    }
    let bits = words
        .iter()
        .rev()
        .fold(0u128, |acc, &w| (acc << 32) | u128::from(w));
    Ok(Inliers {
        bits,
        len: problem.world_points.len(),
    })
}

/// The Cauchy fallback of [`solve_pnp`]: a Huber solve of scale `k` (whitened) from `guess`,
/// then Cauchy (`options`) from there; when that reaches a lower cost than `best.0` and its
/// inlier test succeeds, it replaces `best`. Returns the iterations run.
///
fn cauchy_retry<T: Real>(
    problem: &PnpProblem<'_, T>,
    guess: &Se3<T>,
    options: &SolverOptions<T>,
    k: T,
    inlier_chi2: T,
    best: (&mut Solution<T, Se3<T>, 6>, &mut Inliers),
) -> usize {
    let huber = SolverOptions {
        loss: Loss::Huber(k),
        ..*options
    };
    // One solution serves both solves: the Huber state is the guess of the Cauchy one.
    let mut c = Solution::placeholder(guess);
    if solve_into(problem, &huber, &mut c).is_err() {
        return 0;
    }
    let mut iterations = c.iterations;
    // From the Huber state, in place.
    if solve_into(problem, options, &mut c).is_ok() {
        iterations += c.iterations;
        if c.final_cost < best.0.final_cost {
            if let Ok(m) = inlier_mask(problem, &c.state, inlier_chi2) {
                *best.0 = c;
                *best.1 = m;
            }
        }
    }
    iterations
}

/// Camera pose from landmark projections: minimizes `Σⱼ ρ(‖K π(T pⱼ) − zⱼ‖² / σ²)` over
/// `T = camera_from_world ∈ SE(3)`, from `camera_from_world_guess`.
///
/// Steps: validate; accumulate the 6×6 normal equations over the points (eq. 4.4 of *Lie Groups
/// and Smooth Manifolds for Robotic State Estimation*, `Hᵀ H ξ* = Hᵀ(z − h(a))`, here weighted),
/// with the Jacobian of [`reprojection_error`] (its Theorem 5.1 chained with `∂π`); Cholesky;
/// `T ← T ⊕ ξ = T·exp(ξ^)` (eq. 4.5); then mark inliers by `‖eⱼ‖² ≤ inlier_chi2` at the solution. With a robust loss the
/// IRLS weights down-weight gross outliers from the first iteration on (prefer
/// [`Loss::Cauchy`], whose weight vanishes for large residuals). With Cauchy, a result where
/// fewer than half the points are inliers triggers one more attempt through a Huber solve of the
/// same scale (the lower Cauchy cost wins); `iterations` counts every solve.
///
/// # Errors
/// * [`SolveError::LengthMismatch`]: `world_points.len() != pixels.len()`;
/// * [`SolveError::TooFewObservations`]: fewer than 3 points;
/// * [`SolveError::TooManyObservations`]: more than [`PNP_CAPACITY`];
/// * [`SolveError::InvalidCamera`], [`SolveError::InvalidOptions`];
/// * [`SolveError::NonFiniteInput`], [`SolveError::NonFiniteGuess`];
/// * [`SolveError::DegenerateGeometry`]: coincident or collinear points ([`check_point_spread`]);
/// * [`SolveError::PointBehindCamera`]: a point at depth `≤ min_depth` at the guess or solution;
/// * [`SolveError::NotPositiveDefinite`]: singular information (unobservable pose);
/// * [`SolveError::NonFiniteResidual`]: the iteration produced a non-finite number.
///
/// # Example
///
/// Twelve landmarks seen from a known pose, and the pose recovered from a guess about 10° and
/// 0.3 m away:
///
/// ```
/// use estimator_core::gn::{solve_pnp, PinholeCamera, PnpOptions, SolveError};
/// use estimator_core::lie::{LieGroup, Se3, So3};
/// use nalgebra::{Vector2, Vector3};
///
/// let camera = PinholeCamera::new(500.0, 500.0, 320.0, 240.0);
/// let truth = Se3::from_parts(
///     So3::exp(&Vector3::new(0.1, -0.2, 0.05)),
///     Vector3::new(0.3, -0.1, 4.0),
/// );
/// // A 4 × 3 grid of landmarks at three heights, and their exact pixels.
/// let world: Vec<Vector3<f64>> = (0..12)
///     .map(|k| Vector3::new((k % 4) as f64 - 1.5, (k / 4) as f64 - 1.0, 0.3 * (k % 3) as f64))
///     .collect();
/// let pixels: Vec<Vector2<f64>> = world
///     .iter()
///     .map(|p| camera.project(&truth.act(p), 1e-3).expect("in front of the camera"))
///     .collect();
///
/// let guess = Se3::from_parts(
///     So3::exp(&Vector3::new(0.2, -0.1, -0.05)),
///     Vector3::new(0.1, 0.1, 3.8),
/// );
/// let solution = solve_pnp(&world, &pixels, &camera, &guess, &PnpOptions::default())?;
///
/// // `truth ⊖ estimate = [v; ω]`: metres and radians.
/// assert!(truth.rminus(&solution.camera_from_world).norm() < 1e-9);
/// assert_eq!(solution.inliers.count(), 12);
/// # Ok::<(), SolveError>(())
/// ```
pub fn solve_pnp<T: Real>(
    world_points: &[Vector3<T>],
    pixels: &[Vector2<T>],
    camera: &PinholeCamera<T>,
    camera_from_world_guess: &Se3<T>,
    options: &PnpOptions<T>,
) -> Result<PnpSolution<T>, SolveError> {
    let n = world_points.len();
    if pixels.len() != n {
        return Err(SolveError::LengthMismatch);
    }
    if n < 3 {
        return Err(SolveError::TooFewObservations { needed: 3, got: n });
    }
    if n > PNP_CAPACITY {
        return Err(SolveError::TooManyObservations {
            capacity: PNP_CAPACITY,
            got: n,
        });
    }
    if !camera.is_valid() {
        return Err(SolveError::InvalidCamera);
    }
    if !(super::all_positive(&[options.sigma_px, options.inlier_chi2])
        && options.min_depth.is_finite()
        && options.loss.is_valid())
    {
        return Err(SolveError::InvalidOptions);
    }
    if !world_points.iter().all(|p| all_finite(p.as_slice()))
        || !pixels.iter().all(|z| all_finite(z.as_slice()))
    {
        return Err(SolveError::NonFiniteInput);
    }
    if !camera_from_world_guess.is_finite() {
        return Err(SolveError::NonFiniteGuess);
    }
    check_point_spread(world_points)?;

    let inv_sigma = T::one() / options.sigma_px;
    let problem = PnpProblem {
        world_points,
        pixels,
        camera: *camera,
        inv_sigma,
        min_depth: options.min_depth,
    };
    let solver_options = SolverOptions {
        method: options.method,
        loss: options.loss.scaled(inv_sigma),
        max_iterations: options.max_iterations,
        step_tolerance: options.step_tolerance,
        cost_tolerance: options.cost_tolerance,
        information_step_tolerance: options.information_step_tolerance,
        initial_damping: SolverOptions::<T>::default().initial_damping,
    };
    let mut sol = Solution::placeholder(camera_from_world_guess);
    solve_into(&problem, &solver_options, &mut sol)?;
    let mut inliers = inlier_mask(&problem, &sol.state, options.inlier_chi2)?;
    let mut iterations = sol.iterations;

    // Fallback for the non-convex Cauchy loss: from a far guess its weights can lock onto a
    // wrong basin (about 0.5 % of problems with 20 % outliers from 20° off). That shows as fewer
    // than half the points passing the inlier test; then re-solve through Huber (convex, same
    // scale) from the guess, continue with Cauchy from there, and keep the lower Cauchy cost.
    if let Loss::Cauchy(k) = options.loss {
        if inliers.count() * 2 < n {
            iterations += cauchy_retry(
                &problem,
                camera_from_world_guess,
                &solver_options,
                k * inv_sigma,
                options.inlier_chi2,
                (&mut sol, &mut inliers),
            );
        }
    }

    let pose = sol.state.normalize();
    if !pose.is_finite() {
        return Err(SolveError::NonFiniteResidual);
    }
    // The promise holds for the pose returned, not for the one before its normalization: the
    // rounding of `normalize` can move a point that was just beyond `min_depth` onto it.
    let (r, t) = (pose.rotation().rotation_matrix(), pose.translation());
    let in_front = world_points
        .iter()
        .all(|p| (mat3::mul_vec(&r, p) + t).z > options.min_depth);
    if !in_front {
        return Err(SolveError::PointBehindCamera);
    }
    Ok(PnpSolution {
        camera_from_world: pose,
        covariance: sol.covariance,
        iterations,
        final_cost: sol.final_cost,
        inliers,
        status: sol.status,
    })
}

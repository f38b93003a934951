//! Triangulation of one landmark `p ∈ R³` from several calibrated views:
//! minimizes `Σᵢ ρ(‖K π(Tᵢ p) − zᵢ‖² / σ²)` over `p` with the [`solve`](super::solve) core, from
//! a linear start.
//!
//! * **Start** (closed form): the point closest to all rays in the least-squares sense. The ray
//!   of view `i` leaves the centre `cᵢ = −Rᵢᵀ tᵢ` along `dᵢ = Rᵢᵀ K⁻¹[u, v, 1]ᵀ / ‖·‖`; with the
//!   projector `Pᵢ = I − dᵢdᵢᵀ`, `(Σ Pᵢ) p = Σ Pᵢ cᵢ`, a 3×3 system factorized by [`Factor`]
//!   (singular for parallel rays).
//! * **Refinement**: the residual `eᵢ = (K π(Tᵢ p) − zᵢ)/σ` with Jacobian
//!   `∂eᵢ/∂p = Jπ(xᵢ) Rᵢ / σ` (Theorem 5.1 of *Lie Groups and Smooth Manifolds for Robotic
//!   State Estimation*, `F_(T,p) = T [H(p), I]`, whose point block gives `∂(T p)/∂p = R`), and
//!   `p ⊕ δ = p + δ`.
//! * **Covariance**: `(Σ wᵢ JᵢᵀJᵢ)⁻¹` at the solution (m²).

use super::rotation::normalized;
use super::solver::{solve_into, Method, Problem, Solution, SolverOptions, Status};
use super::{reprojection_error, Factor, Loss, PinholeCamera, SolveError};
use crate::kernels::{all_finite, mat3};
use crate::lie::{LieGroup, Se3};
use crate::Real;
use nalgebra::{Matrix2x3, Matrix3, SMatrix, SVector, Vector2, Vector3};

/// Options of [`triangulate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangulationOptions<T: Real> {
    /// Gauss-Newton or Levenberg-Marquardt.
    pub method: Method,
    /// Robust loss, scale in pixels.
    pub loss: Loss<T>,
    /// Pixel noise per axis, pixels (`> 0`).
    pub sigma_px: T,
    /// Iteration cap.
    pub max_iterations: usize,
    /// A depth `≤ min_depth` (metres) in any view counts as behind that camera.
    pub min_depth: T,
}

impl<T: Real> Default for TriangulationOptions<T> {
    /// Levenberg-Marquardt, least squares, `σ = 1` px, 30 iterations, `min_depth = 1e-3` m.
    fn default() -> Self {
        Self {
            method: Method::LevenbergMarquardt,
            loss: Loss::LeastSquares,
            sigma_px: T::one(),
            max_iterations: 30,
            min_depth: T::lit(1e-3),
        }
    }
}

/// The result of [`triangulate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangulation<T: Real> {
    /// The landmark in the world frame.
    pub point: Vector3<T>,
    /// Its covariance (m²), the inverse information at the optimum.
    pub covariance: Matrix3<T>,
    /// Iterations run.
    pub iterations: usize,
    /// Robust cost at the solution (whitened).
    pub final_cost: T,
    /// Why the iteration stopped.
    pub status: Status,
}

/// The whitened reprojection error of a world point `p` in the view `camera_from_world` and its
/// Jacobian with respect to `p`: `((K π(R p + t) − z)/σ, Jπ R / σ)`; `None` unless the depth is
/// above `min_depth`.
#[must_use]
pub fn point_reprojection_error<T: Real>(
    camera: &PinholeCamera<T>,
    camera_from_world: &Se3<T>,
    p: &Vector3<T>,
    z: &Vector2<T>,
    inv_sigma: T,
    min_depth: T,
) -> Option<(Vector2<T>, Matrix2x3<T>)> {
    // `x = R p + t` and `∂x/∂p = R`: the translation block `(Jπ/σ) R` of the pose Jacobian of
    // [`reprojection_error`] (one copy of the projection code for both).
    let r = camera_from_world.rotation().rotation_matrix();
    let (e, j) = reprojection_error(
        camera,
        &r,
        &camera_from_world.translation(),
        p,
        z,
        inv_sigma,
        min_depth,
    )?;
    Some((e, Matrix2x3::new(j.m11, j.m12, j.m13, j.m21, j.m22, j.m23)))
}

struct TriProblem<'a, T: Real> {
    poses: &'a [Se3<T>],
    pixels: &'a [Vector2<T>],
    camera: PinholeCamera<T>,
    inv_sigma: T,
    min_depth: T,
}

impl<T: Real> Problem<T, Vector3<T>, 3, 2> for TriProblem<'_, T> {
    fn linearize<F>(&self, state: &Vector3<T>, mut sink: F) -> Result<(), SolveError>
    where
        F: FnMut(&SVector<T, 2>, &SMatrix<T, 2, 3>),
    {
        for (pose, z) in self.poses.iter().zip(self.pixels) {
            let (e, j) = point_reprojection_error(
                &self.camera,
                pose,
                state,
                z,
                self.inv_sigma,
                self.min_depth,
            )
            .ok_or(SolveError::PointBehindCamera)?;
            sink(&e, &j);
        }
        Ok(())
    }
}

/// Triangulates a landmark seen in `pixels[i]` from the views `cameras_from_world[i]`.
///
/// # Errors
/// [`SolveError::LengthMismatch`]; [`SolveError::TooFewObservations`] (fewer than 2 views);
/// [`SolveError::InvalidCamera`]; [`SolveError::InvalidOptions`]; [`SolveError::NonFiniteInput`]
/// (a pose or pixel); [`SolveError::DegenerateGeometry`] (parallel rays: no baseline or no
/// parallax); [`SolveError::PointBehindCamera`] (the point lies at depth `≤ min_depth` in a view
/// at the start or the solution); [`SolveError::NotPositiveDefinite`],
/// [`SolveError::NonFiniteResidual`] from the solver.
///
/// # Example
///
/// A point seen by two cameras 1 m apart, both looking along `+z`:
///
/// ```
/// use estimator_core::gn::{triangulate, PinholeCamera, SolveError, TriangulationOptions};
/// use estimator_core::lie::{LieGroup, Se3, So3};
/// use nalgebra::Vector3;
///
/// let camera = PinholeCamera::new(500.0, 500.0, 320.0, 240.0);
/// let point = Vector3::new(0.5, -0.2, 6.0);
/// let views = [
///     Se3::identity(),
///     Se3::from_parts(So3::identity(), Vector3::new(-1.0, 0.0, 0.0)),
/// ];
/// let pixels = views.map(|v| camera.project(&v.act(&point), 1e-3).expect("in front"));
///
/// let t = triangulate(&views, &pixels, &camera, &TriangulationOptions::default())?;
/// assert!((t.point - point).norm() < 1e-9);
/// # Ok::<(), SolveError>(())
/// ```
pub fn triangulate<T: Real>(
    cameras_from_world: &[Se3<T>],
    pixels: &[Vector2<T>],
    camera: &PinholeCamera<T>,
    options: &TriangulationOptions<T>,
) -> Result<Triangulation<T>, SolveError> {
    let n = cameras_from_world.len();
    if pixels.len() != n {
        return Err(SolveError::LengthMismatch);
    }
    if n < 2 {
        return Err(SolveError::TooFewObservations { needed: 2, got: n });
    }
    if !camera.is_valid() {
        return Err(SolveError::InvalidCamera);
    }
    if !(super::all_positive(&[options.sigma_px])
        && options.min_depth.is_finite()
        && options.loss.is_valid())
    {
        return Err(SolveError::InvalidOptions);
    }
    if !cameras_from_world.iter().all(|t| t.is_finite())
        || !pixels.iter().all(|z| all_finite(z.as_slice()))
    {
        return Err(SolveError::NonFiniteInput);
    }

    // Linear start: (Σ Pᵢ) p = Σ Pᵢ cᵢ, with the projector `Pᵢ = I − dᵢdᵢᵀ` off the ray.
    let mut m = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (pose, z) in cameras_from_world.iter().zip(pixels) {
        let world_from_camera = pose.inverse();
        let c = world_from_camera.translation();
        let (d, _) = normalized(&world_from_camera.rotation().act(&camera.unproject(z)));
        // d dᵀ as half of d dᵀ + d dᵀ (exact: a power of two).
        let projector = Matrix3::identity() - mat3::sym_outer(&d, &d) * T::lit(0.5);
        m += projector;
        b += mat3::mul_vec(&projector, &c);
    }
    // Any failure of the factor or the solve is degenerate geometry (parallel rays).
    let start = Factor::new(&m)
        .and_then(|f| f.solve(&b))
        .map_err(|_| SolveError::DegenerateGeometry)?;

    let inv_sigma = T::one() / options.sigma_px;
    let problem = TriProblem {
        poses: cameras_from_world,
        pixels,
        camera: *camera,
        inv_sigma,
        min_depth: options.min_depth,
    };
    let solver_options = SolverOptions {
        method: options.method,
        loss: options.loss.scaled(inv_sigma),
        max_iterations: options.max_iterations,
        ..SolverOptions::default()
    };
    let mut sol = Solution::placeholder(&start);
    solve_into(&problem, &solver_options, &mut sol)?;
    // The solver evaluated every view at its last linearization; the final (converged) step is
    // re-checked here so that a returned point is in front of every camera.
    let in_front = cameras_from_world
        .iter()
        .all(|pose| pose.act(&sol.state).z > options.min_depth);
    if !in_front {
        return Err(SolveError::PointBehindCamera);
    }
    Ok(Triangulation {
        point: sol.state,
        covariance: sol.covariance,
        iterations: sol.iterations,
        final_cost: sol.final_cost,
        status: sol.status,
    })
}

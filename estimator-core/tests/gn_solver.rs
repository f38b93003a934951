//! The generic solver core: the Cholesky factor, the robust losses, a product manifold
//! (`SE(3) × R³`) with its Jacobians against finite differences, Gauss-Newton against
//! Levenberg-Marquardt, and every error path of `solve`.

mod gn_util;
mod support;

use estimator_core::gn::{
    solve, Factor, Loss, Manifold, Method, Product, ResidualBlock, SolveError, SolverOptions,
    Status,
};
use estimator_core::lie::{LieGroup, Se3, So3};
use gn_util::*;
use nalgebra::{Matrix3, SMatrix, SVector, Vector1, Vector3};

/// The default options with the statistical stop (`ξᵀAξ ≤ 1e-6`) off: these problems are
/// noise-free, so the tests can demand convergence to rounding.
fn exact() -> SolverOptions<f64> {
    SolverOptions {
        information_step_tolerance: 0.0,
        ..SolverOptions::default()
    }
}

// ---------------------------------------------------------------------------------------------
// Factor
// ---------------------------------------------------------------------------------------------

/// Random SPD `A = MᵀM + I`: solve and inverse against nalgebra's LU, to `1e3 ε κ`-level.
#[test]
fn factor_solves_and_inverts_spd() {
    let mut rng = Rng::new(20);
    for _ in 0..200 {
        let m = SMatrix::<f64, 6, 6>::from_fn(|_, _| rng.normal());
        let a = m.transpose() * m + SMatrix::<f64, 6, 6>::identity();
        let b = SVector::<f64, 6>::from_fn(|_, _| rng.normal());
        let f = Factor::new(&a).unwrap();
        let x = f.solve(&b).unwrap();
        let x_ref = a.lu().solve(&b).unwrap();
        let kappa = {
            let e = a.symmetric_eigenvalues();
            e.max() / e.min()
        };
        assert!((x - x_ref).amax() <= 1e3 * f64::EPSILON * kappa * x_ref.amax());
        let inv = f.inverse().unwrap();
        assert!((inv * a - SMatrix::<f64, 6, 6>::identity()).amax() <= 1e3 * f64::EPSILON * kappa);
        assert_eq!(inv, inv.transpose());
    }
}

#[test]
fn factor_refuses_singular_indefinite_and_non_finite() {
    // Rank 2 (exactly and to rounding).
    let u = Vector3::new(1.0, 2.0, 3.0);
    let v = Vector3::new(-1.0, 0.5, 0.25);
    let a: Matrix3<f64> = u * u.transpose() + v * v.transpose();
    assert_eq!(
        Factor::new(&a).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
    let a32: Matrix3<f32> = a.cast();
    assert_eq!(
        Factor::new(&a32).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
    // Indefinite, zero, negative diagonal.
    let ind = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert_eq!(
        Factor::new(&ind).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
    assert_eq!(
        Factor::new(&Matrix3::<f64>::zeros()).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
    assert_eq!(
        Factor::new(&(-Matrix3::<f64>::identity())).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
    let mut nan = Matrix3::<f64>::identity();
    nan[(1, 0)] = f64::NAN;
    assert_eq!(
        Factor::new(&nan).unwrap_err(),
        SolveError::NonFiniteResidual
    );
    // A badly scaled but regular matrix is accepted (the test is relative to the diagonal).
    let d = Matrix3::from_diagonal(&Vector3::new(1e-12, 1.0, 1e12));
    let f = Factor::new(&d).unwrap();
    let x = f.solve(&Vector3::new(1e-12, 1.0, 1e12)).unwrap();
    assert!((x - Vector3::repeat(1.0)).amax() <= 4.0 * f64::EPSILON);
    assert_eq!(
        f.solve(&Vector3::new(f64::NAN, 0.0, 0.0)).unwrap_err(),
        SolveError::NonFiniteResidual
    );
}

/// Every symmetric matrix with a diagonal entry `≤ 0` is refused as not positive definite, one
/// with a non-finite entry (in either triangle) as non-finite, and one with a diagonal entry `1e-300` coupled to the
/// others by `O(1)` entries (its pivot leaves a negative Schur complement) as not positive
/// definite; the same Gram matrices untouched factorize. Sizes 3 and 6, `f32` and `f64`.
fn factor_classifies_corrupted_gram_matrices<T, const N: usize>(rng: &mut Rng)
where
    T: estimator_core::Real + nalgebra::RealField,
{
    let lit = |x: f64| nalgebra::convert::<f64, T>(x);
    for trial in 0..300 {
        let m = SMatrix::<f64, N, N>::from_fn(|_, _| rng.normal());
        let gram = m.transpose() * m + SMatrix::<f64, N, N>::identity();
        let a: SMatrix<T, N, N> = gram.map(lit);
        assert!(Factor::new(&a).is_ok());
        let j = trial % N;
        let mut bad = a;
        match trial % 6 {
            0 => bad[(j, j)] = lit(0.0),
            1 => bad[(j, j)] = lit(-0.0),
            2 => bad[(j, j)] = lit(-rng.uniform() - 1e-3),
            3 => {
                bad[(j, j)] = lit(1e-300);
                let other = (j + 1) % N;
                bad[(other, j)] = lit(1.0);
                bad[(j, other)] = lit(1.0);
            }
            4 => bad[(j, (j + N - 1) % N)] = lit([f64::NAN, f64::INFINITY][trial % 2]),
            _ => bad[(j, j)] = lit([f64::NAN, f64::NEG_INFINITY, f64::INFINITY][trial % 3]),
        }
        let want = if trial % 6 >= 4 {
            SolveError::NonFiniteResidual
        } else {
            SolveError::NotPositiveDefinite
        };
        assert_eq!(Factor::new(&bad).unwrap_err(), want, "{trial}");
    }
}

#[test]
fn factor_refuses_non_positive_diagonals_and_names_non_finite_entries() {
    let mut rng = Rng::new(21);
    factor_classifies_corrupted_gram_matrices::<f64, 3>(&mut rng);
    factor_classifies_corrupted_gram_matrices::<f64, 6>(&mut rng);
    factor_classifies_corrupted_gram_matrices::<f32, 3>(&mut rng);
    factor_classifies_corrupted_gram_matrices::<f32, 6>(&mut rng);
}

// ---------------------------------------------------------------------------------------------
// Losses
// ---------------------------------------------------------------------------------------------

/// `w = ρ'(s)` (Richardson differences, relative `1e-8`), `ρ` continuous at the Huber knee,
/// `ρ(s) ≤ s`, `0 < w ≤ 1`, and the closed forms at a few points.
#[test]
fn loss_weights_are_derivatives_of_rho() {
    for loss in [Loss::LeastSquares, Loss::Huber(1.5), Loss::Cauchy(2.0)] {
        for &s in &[1e-3, 0.5, 2.0, 2.25 + 1e-3, 9.0, 100.0, 1e4] {
            let (rho, w) = loss.evaluate(s);
            let h = 1e-4 * s;
            let d = |h: f64| (loss.evaluate(s + h).0 - loss.evaluate(s - h).0) / (2.0 * h);
            let fd = (4.0 * d(h / 2.0) - d(h)) / 3.0;
            assert!(
                (fd - w).abs() <= 1e-8 * w.max(1e-3),
                "{loss:?} s={s}: {fd} vs {w}"
            );
            assert!(rho <= s * (1.0 + 1e-15) && w > 0.0 && w <= 1.0);
        }
    }
    let k: f64 = 1.5;
    let below = Loss::Huber(k).evaluate(k * k * (1.0 - 1e-12)).0;
    let above = Loss::Huber(k).evaluate(k * k * (1.0 + 1e-12)).0;
    assert!((below - above).abs() <= 1e-10);
    assert_eq!(Loss::Huber(2.0).evaluate(16.0), (12.0, 0.5));
    let (rho, w) = Loss::Cauchy(2.0).evaluate(4.0);
    assert!((rho - 4.0 * 2f64.ln()).abs() <= 1e-15 && w == 0.5);
    assert_eq!(Loss::Cauchy(2.0).scaled(0.5), Loss::Cauchy(1.0));
    assert!(!Loss::Cauchy(f64::NAN).is_valid() && !Loss::Huber(-1.0).is_valid());
    assert!(Loss::<f32>::LeastSquares.is_valid());
}

// ---------------------------------------------------------------------------------------------
// A product manifold: pose and point
// ---------------------------------------------------------------------------------------------

type PosePoint = Product<Se3<f64>, Vector3<f64>, 6, 3>;

/// Residual blocks over `(T, p)`: a body point `q` observed in the world (`T q − y`), the point
/// `p` (body frame) observed in the world (`T p − m`), and a prior on `p`.
#[derive(Clone, Copy)]
enum Block {
    Pose { q: Vector3<f64>, y: Vector3<f64> },
    Point { m: Vector3<f64> },
    Prior { p0: Vector3<f64> },
}

impl ResidualBlock<f64, PosePoint, 9, 3> for Block {
    fn evaluate(&self, s: &PosePoint) -> Result<(SVector<f64, 3>, SMatrix<f64, 3, 9>), SolveError> {
        let mut j = SMatrix::<f64, 3, 9>::zeros();
        let e = match *self {
            Block::Pose { q, y } => {
                let (x, jt, _) = s.a.act_jac(&q);
                j.fixed_view_mut::<3, 6>(0, 0).copy_from(&jt);
                x - y
            }
            Block::Point { m } => {
                let (x, jt, jp) = s.a.act_jac(&s.b);
                j.fixed_view_mut::<3, 6>(0, 0).copy_from(&jt);
                j.fixed_view_mut::<3, 3>(0, 6).copy_from(&jp);
                x - m
            }
            Block::Prior { p0 } => {
                j.fixed_view_mut::<3, 3>(0, 6)
                    .copy_from(&Matrix3::identity());
                s.b - p0
            }
        };
        Ok((e, j))
    }
}

fn pose_point_problem(rng: &mut Rng) -> (PosePoint, Vec<Block>) {
    let truth = Product::new(
        rng.pose(),
        Vector3::new(rng.normal(), rng.normal(), rng.normal()),
    );
    let mut blocks = vec![];
    for _ in 0..4 {
        let q = Vector3::new(rng.normal(), rng.normal(), rng.normal());
        blocks.push(Block::Pose {
            q,
            y: truth.a.act(&q),
        });
    }
    blocks.push(Block::Point {
        m: truth.a.act(&truth.b),
    });
    blocks.push(Block::Prior { p0: truth.b });
    (truth, blocks)
}

/// `Product::split` hands `ξ_a` the first `NA` entries of `ξ` and `ξ_b` the next `NB`, exactly
/// (a copy), and `oplus` moves each factor by its own slice.
#[test]
fn product_split_gives_each_factor_its_slice() {
    let xi = SVector::<f64, 9>::from_fn(|r, _| r as f64 + 0.5);
    let (a, b) = PosePoint::split(&xi);
    assert_eq!(a.as_slice(), &xi.as_slice()[..6]);
    assert_eq!(b.as_slice(), &xi.as_slice()[6..]);
    let mut rng = Rng::new(22);
    let x = Product::new(rng.pose(), Vector3::new(1.0, -2.0, 3.0));
    let moved = Manifold::<f64, 9>::oplus(&x, &xi);
    assert_eq!(moved.a, x.a.rplus(&a));
    assert_eq!(moved.b, x.b + b);
}

/// Every block's Jacobian through `Product::oplus`, by Richardson differences (`h = 1e-3`,
/// tolerance `1e-8` relative: truncation `O(h⁴)`, rounding `2ε|e|/h` ≈ `1e-12`).
#[test]
fn product_manifold_jacobians_match_finite_differences() {
    let mut rng = Rng::new(21);
    for _ in 0..50 {
        let (truth, blocks) = pose_point_problem(&mut rng);
        let at = truth.oplus(&SVector::<f64, 9>::from_fn(|_, _| rng.normal() * 0.5));
        for b in &blocks {
            let (_, j) = b.evaluate(&at).unwrap();
            let fd = fd_jacobian(
                |xi: &SVector<f64, 9>| b.evaluate(&at.oplus(xi)).unwrap().0,
                1e-3,
            );
            assert!(
                (fd - j).amax() <= 1e-8 * j.amax().max(1.0),
                "{}",
                (fd - j).amax()
            );
        }
    }
}

/// Noise-free data: both methods reach the truth from a large perturbation (30° and 1 m) to
/// `1e-9`, with the same answer.
#[test]
fn gauss_newton_and_levenberg_marquardt_solve_the_product_problem() {
    let mut rng = Rng::new(22);
    for _ in 0..30 {
        let (truth, blocks) = pose_point_problem(&mut rng);
        let guess = Product::new(
            perturb(&mut rng, &truth.a, 30f64.to_radians(), 1.0),
            truth.b + rng.unit3(),
        );
        let mut answers = vec![];
        for method in [Method::GaussNewton, Method::LevenbergMarquardt] {
            let opts = SolverOptions { method, ..exact() };
            let s = solve(blocks.as_slice(), &guess, &opts).unwrap();
            assert!(matches!(
                s.status,
                Status::StepConverged | Status::CostConverged
            ));
            let d = truth.a.rminus(&s.state.a).norm() + (truth.b - s.state.b).norm();
            assert!(d <= 1e-9, "{method:?}: {d:e}");
            assert!(s.final_cost <= 1e-18 && s.initial_cost > 1e-2);
            assert!(s.iterations <= 20);
            answers.push(s.state);
        }
        assert!(answers[0].a.rminus(&answers[1].a).norm() <= 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------
// A 1-D problem with a domain: e = ln x − ln 2, defined for x > 0
// ---------------------------------------------------------------------------------------------

struct LogBlock;

impl ResidualBlock<f64, Vector1<f64>, 1, 1> for LogBlock {
    fn evaluate(
        &self,
        x: &Vector1<f64>,
    ) -> Result<(SVector<f64, 1>, SMatrix<f64, 1, 1>), SolveError> {
        if x.x <= 0.0 {
            return Err(SolveError::DegenerateGeometry);
        }
        Ok((
            Vector1::new(x.x.ln() - 2f64.ln()),
            SMatrix::<f64, 1, 1>::from_element(1.0 / x.x),
        ))
    }
}

/// From x = 10, the Gauss-Newton step lands at x < 0, outside the domain: GN reports the
/// model's error, LM rejects the step, raises λ and converges to 2.
#[test]
fn levenberg_marquardt_recovers_from_a_failed_trial_state() {
    let blocks = [LogBlock];
    let x0 = Vector1::new(10.0);
    let gn = SolverOptions {
        method: Method::GaussNewton,
        ..SolverOptions::default()
    };
    assert_eq!(
        solve(&blocks[..], &x0, &gn).unwrap_err(),
        SolveError::DegenerateGeometry
    );
    let s = solve(&blocks[..], &x0, &exact()).unwrap();
    assert!((s.state.x - 2.0).abs() <= 1e-9, "{}", s.state.x);
    // Covariance (A⁻¹ with A = 1/x² at x = 2): 4.
    assert!((s.covariance[(0, 0)] - 4.0).abs() <= 1e-8);
}

// ---------------------------------------------------------------------------------------------
// Error paths and statuses
// ---------------------------------------------------------------------------------------------

struct Fixed {
    e: Vector3<f64>,
    j: Matrix3<f64>,
    fail: Option<SolveError>,
}

impl ResidualBlock<f64, Vector3<f64>, 3, 3> for Fixed {
    fn evaluate(&self, x: &Vector3<f64>) -> Result<(SVector<f64, 3>, Matrix3<f64>), SolveError> {
        match self.fail {
            Some(e) => Err(e),
            None => Ok((self.e + self.j * x, self.j)),
        }
    }
}

#[test]
fn solve_error_paths() {
    let good = [Fixed {
        e: Vector3::new(1.0, 2.0, 3.0),
        j: Matrix3::identity(),
        fail: None,
    }];
    let x0 = Vector3::zeros();
    let o = exact();
    // A linear problem: one step, exact.
    let s = solve(&good[..], &x0, &o).unwrap();
    assert!((s.state + Vector3::new(1.0, 2.0, 3.0)).amax() <= 1e-12);
    // Invalid options.
    for bad in [
        SolverOptions {
            step_tolerance: -1.0,
            ..o
        },
        SolverOptions {
            cost_tolerance: f64::NAN,
            ..o
        },
        SolverOptions {
            information_step_tolerance: f64::INFINITY,
            ..o
        },
        SolverOptions {
            initial_damping: -1.0,
            ..o
        },
        SolverOptions {
            loss: Loss::Cauchy(0.0),
            ..o
        },
    ] {
        assert_eq!(
            solve(&good[..], &x0, &bad).unwrap_err(),
            SolveError::InvalidOptions
        );
    }
    // Non-finite guess.
    assert_eq!(
        solve(&good[..], &Vector3::new(0.0, f64::NAN, 0.0), &o).unwrap_err(),
        SolveError::NonFiniteGuess
    );
    // The model's error at the guess propagates.
    let failing = [Fixed {
        fail: Some(SolveError::PointBehindCamera),
        ..good[0]
    }];
    assert_eq!(
        solve(&failing[..], &x0, &o).unwrap_err(),
        SolveError::PointBehindCamera
    );
    // A non-finite residual.
    let nan = [Fixed {
        e: Vector3::new(f64::NAN, 0.0, 0.0),
        ..good[0]
    }];
    assert_eq!(
        solve(&nan[..], &x0, &o).unwrap_err(),
        SolveError::NonFiniteResidual
    );
    // An overflowing cost (finite residual, infinite square).
    let huge = [Fixed {
        e: Vector3::new(1e200, 0.0, 0.0),
        ..good[0]
    }];
    assert_eq!(
        solve(&huge[..], &x0, &o).unwrap_err(),
        SolveError::NonFiniteResidual
    );
    // Unobservable direction (z): singular information, for both methods.
    let mut j = Matrix3::identity();
    j[(2, 2)] = 0.0;
    let rank2 = [Fixed { j, ..good[0] }];
    for method in [Method::GaussNewton, Method::LevenbergMarquardt] {
        assert_eq!(
            solve(&rank2[..], &x0, &SolverOptions { method, ..o }).unwrap_err(),
            SolveError::NotPositiveDefinite,
            "{method:?}"
        );
    }
    // No blocks at all: zero information.
    let none: [Fixed; 0] = [];
    assert_eq!(
        solve(&none[..], &x0, &o).unwrap_err(),
        SolveError::NotPositiveDefinite
    );
}

/// The iteration cap is reported, with a finite state and the cost not above the initial one.
#[test]
fn max_iterations_status() {
    let mut rng = Rng::new(23);
    let (truth, blocks) = pose_point_problem(&mut rng);
    let guess = Product::new(perturb(&mut rng, &truth.a, 1.0, 2.0), truth.b);
    let o = SolverOptions {
        max_iterations: 1,
        ..SolverOptions::default()
    };
    let s = solve(blocks.as_slice(), &guess, &o).unwrap();
    assert_eq!(s.status, Status::MaxIterations);
    assert_eq!(s.iterations, 1);
    assert!(s.final_cost <= s.initial_cost);
    let o0 = SolverOptions {
        max_iterations: 0,
        ..o
    };
    let s = solve(blocks.as_slice(), &guess, &o0).unwrap();
    assert_eq!((s.iterations, s.status), (0, Status::MaxIterations));
    assert_eq!(s.state, guess);
}

/// `So3` as a state (the solver is generic over the Lie groups): align rotated vectors.
#[test]
fn solves_on_so3() {
    struct Align(Vector3<f64>, Vector3<f64>);
    impl ResidualBlock<f64, So3<f64>, 3, 3> for Align {
        fn evaluate(&self, r: &So3<f64>) -> Result<(Vector3<f64>, Matrix3<f64>), SolveError> {
            let (x, j, _) = r.act_jac(&self.0);
            Ok((x - self.1, j))
        }
    }
    let mut rng = Rng::new(24);
    for _ in 0..20 {
        let truth = rng.rotation();
        let blocks: Vec<Align> = (0..3)
            .map(|_| {
                let v = rng.unit3();
                Align(v, truth.act(&v))
            })
            .collect();
        let guess = So3::exp(&(rng.unit3() * 1.0)).compose(&truth);
        let s = solve(blocks.as_slice(), &guess, &exact()).unwrap();
        assert!(truth.rminus(&s.state).norm() <= 1e-10);
    }
}

/// A model whose Jacobian has the wrong sign: no Levenberg-Marquardt step lowers the cost, `λ`
/// grows past its cap, the status says so and the state is the guess, unchanged.
#[test]
fn damping_saturates_when_no_step_decreases_the_cost() {
    struct Wrong;
    impl ResidualBlock<f64, Vector3<f64>, 3, 3> for Wrong {
        fn evaluate(&self, x: &Vector3<f64>) -> Result<(Vector3<f64>, Matrix3<f64>), SolveError> {
            Ok((x - Vector3::new(1.0, 2.0, 3.0), -Matrix3::identity()))
        }
    }
    let o = SolverOptions {
        step_tolerance: 0.0,
        ..exact()
    };
    let x0 = Vector3::new(0.5, 0.5, 0.5);
    let s = solve(&[Wrong][..], &x0, &o).unwrap();
    assert_eq!(s.status, Status::DampingSaturated);
    assert_eq!(s.state, x0);
    assert_eq!(s.final_cost, s.initial_cost);
    assert!(s.iterations < 50);
}

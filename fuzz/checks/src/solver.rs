//! The solver target (see [`crate::run_solver`]).
//!
//! Input: a byte choosing the solver and scalar, then one problem: either made from a true
//! state (points in front of the cameras, their pixels with noise and outliers, a guess near
//! the truth) so that the solver reaches its iterations, or made of arbitrary numbers. The
//! options are the defaults or drawn. An `Ok` is checked against the function's guarantees.

use crate::input::{Input, Scalar};
use crate::{finding, Log, Outcome};
use estimator_core::gn::{
    solve, solve_pnp, solve_rotation_from_vectors, triangulate, Loss, Method, PinholeCamera,
    PnpOptions, Product, ResidualBlock, SolveError, SolverOptions, TriangulationOptions,
    VectorPair,
};
use estimator_core::lie::{skew, LieGroup, Se2, Se3, So3};
use estimator_core::nalgebra::{
    Matrix2x3, Matrix3, Matrix3x6, SMatrix, SVector, Vector2, Vector3, Vector6,
};

pub(crate) fn run(data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    let mut log = Log::default();
    let outcome = match input.pick(8) {
        0 => pnp::<f32>(&mut input),
        1 => pnp::<f64>(&mut input),
        2 => triangulation::<f32>(&mut input),
        3 => triangulation::<f64>(&mut input),
        4 => rotation::<f32>(&mut input),
        5 => rotation::<f64>(&mut input),
        6 => general::<f32>(&mut input),
        _ => general::<f64>(&mut input),
    };
    log.take(outcome)?;
    log.finish()
}

fn finite<T: Scalar, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// A `solver-result` finding unless `ok`.
fn promise(ok: bool, call: &str, detail: impl FnOnce() -> String) -> Outcome {
    if ok {
        Ok(())
    } else {
        Err(finding("solver-result", call, detail()))
    }
}

fn camera<T: Scalar>(input: &mut Input<'_>) -> PinholeCamera<T> {
    if input.chance(200) {
        let f = T::lit(100.0) + input.moderate::<T>().abs() * T::lit(0.1);
        PinholeCamera::new(f, f, T::lit(320.0), T::lit(240.0))
    } else {
        PinholeCamera::new(input.real(), input.real(), input.real(), input.real())
    }
}

fn loss<T: Scalar>(input: &mut Input<'_>) -> Loss<T> {
    match input.byte() % 4 {
        0 | 1 => Loss::LeastSquares,
        2 => Loss::Huber(input.sigma()),
        _ => Loss::Cauchy(input.sigma()),
    }
}

fn method(input: &mut Input<'_>) -> Method {
    if input.chance(160) {
        Method::LevenbergMarquardt
    } else {
        Method::GaussNewton
    }
}

/// A real, or `default` (most of the time).
fn or_default<T: Scalar>(input: &mut Input<'_>, default: T) -> T {
    if input.chance(208) {
        default
    } else {
        input.real()
    }
}

fn solver_options<T: Scalar>(input: &mut Input<'_>) -> SolverOptions<T> {
    let d = SolverOptions::<T>::default();
    SolverOptions {
        method: method(input),
        loss: loss(input),
        max_iterations: input.pick(64),
        step_tolerance: or_default(input, d.step_tolerance),
        cost_tolerance: or_default(input, d.cost_tolerance),
        information_step_tolerance: or_default(input, d.information_step_tolerance),
        initial_damping: or_default(input, d.initial_damping),
    }
}

/// A small pose perturbation (metres and radians, times `10^k`).
fn perturbation<T: Scalar>(input: &mut Input<'_>) -> Vector6<T> {
    let scale = T::lit([0.0, 1e-6, 1e-4, 1e-3, 1e-2, 0.03, 0.1, 1.0][input.pick(8)]);
    Vector6::from_fn(|_, _| input.moderate::<T>() * scale)
}

fn pnp<T: Scalar>(input: &mut Input<'_>) -> Outcome {
    let call = format!("solve_pnp::<{}>", T::NAME);
    let cam = camera::<T>(input);
    let made = input.chance(200);
    let n = match input.byte() {
        0..=239 => 3 + input.pick(20),
        b => usize::from(b - 240) * 9,
    };
    let truth = Se3::from_parts(
        So3::exp(&input.moderate3()),
        input.moderate3::<T>() * T::lit(1e-3),
    );
    let noise = T::lit([0.0, 1e-3, 0.3, 1.0, 5.0][input.pick(5)]);
    let mut world = Vec::with_capacity(n);
    let mut pixels = Vec::with_capacity(n);
    for _ in 0..n {
        if made {
            // A point in front of the camera, back in the world.
            let depth = T::lit(0.5) + input.moderate::<T>().abs() * T::lit(2e-3);
            let c = Vector3::new(
                input.moderate::<T>() * T::lit(1e-4) * depth,
                input.moderate::<T>() * T::lit(1e-4) * depth,
                depth,
            );
            let outlier = input.chance(24);
            let z = cam
                .project(&c, T::zero())
                .unwrap_or_else(|| Vector2::zeros())
                + Vector2::new(input.moderate::<T>(), input.moderate())
                    * (if outlier {
                        T::lit(0.1)
                    } else {
                        noise * T::lit(1e-4)
                    });
            world.push(truth.inverse().act(&c));
            pixels.push(z);
        } else {
            world.push(input.vec3());
            pixels.push(input.vec2());
        }
    }
    if input.chance(8) && !pixels.is_empty() {
        pixels.pop();
    }
    let guess = if made {
        truth.rplus(&perturbation(input))
    } else {
        Se3::from_parts(
            So3::from_wxyz(input.real(), input.real(), input.real(), input.real())
                .unwrap_or_else(So3::identity),
            input.vec3(),
        )
    };
    let d = PnpOptions::<T>::default();
    let options = PnpOptions {
        method: method(input),
        loss: loss(input),
        sigma_px: or_default(input, d.sigma_px),
        max_iterations: input.pick(64),
        step_tolerance: or_default(input, d.step_tolerance),
        cost_tolerance: or_default(input, d.cost_tolerance),
        information_step_tolerance: or_default(input, d.information_step_tolerance),
        min_depth: or_default(input, d.min_depth),
        inlier_chi2: or_default(input, d.inlier_chi2),
    };
    let Ok(s) = solve_pnp(&world, &pixels, &cam, &guess, &options) else {
        return Ok(());
    };
    let shown = || {
        format!("{s:?} from world {world:?}, pixels {pixels:?}, camera {cam:?}, guess {guess:?}, options {options:?}")
    };
    promise(s.camera_from_world.is_finite(), &call, || {
        format!("a non-finite pose: {}", shown())
    })?;
    promise(
        finite(&s.covariance) && s.final_cost.is_finite(),
        &call,
        || format!("a non-finite covariance or cost: {}", shown()),
    )?;
    promise(
        s.inliers.len() == world.len() && s.inliers.count() <= world.len(),
        &call,
        || format!("inliers of the wrong length: {}", shown()),
    )?;
    // The depth with the arithmetic of `solve_pnp` (row 3 of R p, then + t).
    let r = s.camera_from_world.rotation().rotation_matrix();
    let t = s.camera_from_world.translation();
    for (j, p) in world.iter().enumerate() {
        let depth = r.m31 * p.x + r.m32 * p.y + r.m33 * p.z + t.z;
        promise(depth > options.min_depth, &call, || {
            format!(
                "point {j} at depth {depth:?}, not above min_depth {:?}: {}",
                options.min_depth,
                shown()
            )
        })?;
    }
    Ok(())
}

fn triangulation<T: Scalar>(input: &mut Input<'_>) -> Outcome {
    let call = format!("triangulate::<{}>", T::NAME);
    let cam = camera::<T>(input);
    let made = input.chance(200);
    let n = input.pick(10);
    let point =
        Vector3::new(input.moderate::<T>(), input.moderate(), input.moderate()) * T::lit(1e-3);
    let mut views = Vec::with_capacity(n);
    let mut pixels = Vec::with_capacity(n);
    for _ in 0..n {
        if made {
            // A camera looking at the point from a distance, turned a little.
            let turn = input.moderate3::<T>() * T::lit(1e-5);
            let distance = T::lit(1.0) + input.moderate::<T>().abs() * T::lit(1e-3);
            let offset = input.moderate3::<T>() * T::lit(1e-4);
            let rotation = So3::exp(&turn);
            let in_camera = Vector3::new(offset.x, offset.y, distance);
            // camera_from_world: R p + t = in_camera.
            let t = in_camera - rotation.act(&point);
            let view = Se3::from_parts(rotation, t);
            let z = cam
                .project(&in_camera, T::zero())
                .unwrap_or_else(Vector2::zeros)
                + Vector2::new(input.moderate::<T>(), input.moderate()) * T::lit(1e-4);
            views.push(view);
            pixels.push(z);
        } else {
            views.push(Se3::from_parts(So3::exp(&input.vec3()), input.vec3()));
            pixels.push(input.vec2());
        }
    }
    let d = TriangulationOptions::<T>::default();
    let options = TriangulationOptions {
        method: method(input),
        loss: loss(input),
        sigma_px: or_default(input, d.sigma_px),
        max_iterations: input.pick(64),
        min_depth: or_default(input, d.min_depth),
    };
    let Ok(s) = triangulate(&views, &pixels, &cam, &options) else {
        return Ok(());
    };
    let shown = || {
        format!(
            "{s:?} from views {views:?}, pixels {pixels:?}, camera {cam:?}, options {options:?}"
        )
    };
    promise(
        finite(&s.point) && finite(&s.covariance) && s.final_cost.is_finite(),
        &call,
        || format!("a non-finite point, covariance or cost: {}", shown()),
    )?;
    for (j, view) in views.iter().enumerate() {
        let depth = view.act(&s.point).z;
        promise(depth > options.min_depth, &call, || {
            format!(
                "the point at depth {depth:?} in view {j}, not above min_depth {:?}: {}",
                options.min_depth,
                shown()
            )
        })?;
    }
    Ok(())
}

fn rotation<T: Scalar>(input: &mut Input<'_>) -> Outcome {
    let call = format!("solve_rotation_from_vectors::<{}>", T::NAME);
    let truth = So3::exp(&input.moderate3::<T>());
    let n = input.pick(8);
    let made = input.chance(200);
    let pairs: Vec<VectorPair<T>> = (0..n)
        .map(|_| {
            if made {
                let world = input.moderate3::<T>();
                let body = truth.inverse().act(&world) + input.moderate3::<T>() * T::lit(1e-5);
                VectorPair {
                    body,
                    world,
                    sigma: input.sigma(),
                }
            } else {
                VectorPair {
                    body: input.vec3(),
                    world: input.vec3(),
                    sigma: input.real(),
                }
            }
        })
        .collect();
    let guess = match input.byte() % 3 {
        0 => None,
        1 => Some(truth.rplus(&(input.moderate3::<T>() * T::lit(1e-4)))),
        _ => Some(So3::exp(&input.vec3())),
    };
    let options = solver_options(input);
    let Ok(s) = solve_rotation_from_vectors(&pairs, guess.as_ref(), &options) else {
        return Ok(());
    };
    promise(
        s.world_from_body.is_finite() && finite(&s.covariance) && s.final_cost.is_finite(),
        &call,
        || {
            format!("a non-finite result {s:?} from pairs {pairs:?}, guess {guess:?}, options {options:?}")
        },
    )
}

/// `e = A x − b` on `R³`.
#[derive(Clone, Copy, Debug)]
struct Linear<T: Scalar> {
    a: Matrix2x3<T>,
    b: Vector2<T>,
}

impl<T: Scalar> ResidualBlock<T, Vector3<T>, 3, 2> for Linear<T> {
    fn evaluate(&self, x: &Vector3<T>) -> Result<(Vector2<T>, Matrix2x3<T>), SolveError> {
        Ok((self.a * x - self.b, self.a))
    }
}

/// A point seen from a planar pose: `e = T p − q`, `J = ∂(T p)/∂T`.
#[derive(Clone, Copy, Debug)]
struct Planar<T: Scalar> {
    p: Vector2<T>,
    q: Vector2<T>,
}

impl<T: Scalar> ResidualBlock<T, Se2<T>, 3, 2> for Planar<T> {
    fn evaluate(&self, x: &Se2<T>) -> Result<(Vector2<T>, SMatrix<T, 2, 3>), SolveError> {
        let (tp, j, _) = x.act_jac(&self.p);
        Ok((tp - self.q, j))
    }
}

/// A rotation prior: `e = (R ⊖ R₀)·w`, `J = J_r⁻¹(e)·w`.
#[derive(Clone, Copy, Debug)]
struct Prior<T: Scalar> {
    target: So3<T>,
    weight: T,
}

impl<T: Scalar> ResidualBlock<T, So3<T>, 3, 3> for Prior<T> {
    fn evaluate(&self, x: &So3<T>) -> Result<(Vector3<T>, Matrix3<T>), SolveError> {
        let (e, j, _) = x.rminus_jac(&self.target);
        Ok((e * self.weight, j * self.weight))
    }
}

/// A point under a rotation and a translation kept apart: `e = R p + t − q` on
/// `SO(3) × R³`, `J = [−R[p]×, I]`.
#[derive(Clone, Copy, Debug)]
struct Split<T: Scalar> {
    p: Vector3<T>,
    q: Vector3<T>,
}

type RotationAndTranslation<T> = Product<So3<T>, Vector3<T>, 3, 3>;

impl<T: Scalar> ResidualBlock<T, RotationAndTranslation<T>, 6, 3> for Split<T> {
    fn evaluate(
        &self,
        x: &RotationAndTranslation<T>,
    ) -> Result<(Vector3<T>, Matrix3x6<T>), SolveError> {
        let r = x.a.rotation_matrix();
        let mut j = Matrix3x6::zeros();
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(-r * skew(&self.p)));
        j.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&Matrix3::identity());
        Ok((r * self.p + x.b - self.q, j))
    }
}

/// `gn::solve` on `blocks` from `initial`, its `Ok` checked.
fn solved<T, S, B, const N: usize, const K: usize>(
    call: &str,
    blocks: &[B],
    initial: &S,
    options: &SolverOptions<T>,
) -> Outcome
where
    T: Scalar,
    S: estimator_core::gn::Manifold<T, N> + core::fmt::Debug,
    B: ResidualBlock<T, S, N, K> + core::fmt::Debug,
{
    let Ok(s) = solve(blocks, initial, options) else {
        return Ok(());
    };
    promise(
        s.state.all_finite()
            && finite(&s.covariance)
            && s.final_cost.is_finite()
            && s.initial_cost.is_finite(),
        call,
        || {
            format!("a non-finite result {s:?} from {blocks:?}, initial {initial:?}, options {options:?}")
        },
    )
}

fn general<T: Scalar>(input: &mut Input<'_>) -> Outcome {
    let n = input.pick(12);
    let made = input.chance(192);
    let options = solver_options::<T>(input);
    let value = |input: &mut Input<'_>| -> T {
        if made {
            input.moderate()
        } else {
            input.real()
        }
    };
    match input.byte() % 4 {
        0 => {
            let blocks: Vec<Linear<T>> = (0..n)
                .map(|_| Linear {
                    a: Matrix2x3::from_fn(|_, _| value(input)),
                    b: Vector2::new(value(input), value(input)),
                })
                .collect();
            let initial = Vector3::new(value(input), value(input), value(input));
            solved(
                &format!("solve::<{}, R3>", T::NAME),
                &blocks,
                &initial,
                &options,
            )
        }
        1 => {
            let truth = Se2::new(value(input), value(input), value(input));
            let blocks: Vec<Planar<T>> = (0..n)
                .map(|_| {
                    let p = Vector2::new(value(input), value(input));
                    let q = truth.act(&p) + Vector2::new(value(input), value(input)) * T::lit(1e-3);
                    Planar { p, q }
                })
                .collect();
            let initial = truth.rplus(&SVector::<T, 3>::from_fn(|_, _| {
                value(input) * T::lit(1e-4)
            }));
            solved(
                &format!("solve::<{}, Se2>", T::NAME),
                &blocks,
                &initial,
                &options,
            )
        }
        2 => {
            let blocks: Vec<Prior<T>> = (0..n)
                .map(|_| Prior {
                    target: So3::exp(&Vector3::new(value(input), value(input), value(input))),
                    weight: value(input),
                })
                .collect();
            let initial = So3::exp(&Vector3::new(value(input), value(input), value(input)));
            solved(
                &format!("solve::<{}, So3>", T::NAME),
                &blocks,
                &initial,
                &options,
            )
        }
        _ => {
            let truth = (
                So3::exp(&Vector3::new(value(input), value(input), value(input))),
                Vector3::new(value(input), value(input), value(input)),
            );
            let blocks: Vec<Split<T>> = (0..n)
                .map(|_| {
                    let p = Vector3::new(value(input), value(input), value(input));
                    let q = truth.0.act(&p) + truth.1;
                    Split { p, q }
                })
                .collect();
            let initial = Product::new(
                truth.0,
                truth.1 + Vector3::new(value(input), value(input), value(input)),
            );
            solved(
                &format!("solve::<{}, So3×R3>", T::NAME),
                &blocks,
                &initial,
                &options,
            )
        }
    }
}

//! The Lie-group target (see [`crate::run_lie`]).
//!
//! Input: a byte choosing the group and scalar, then rounds until the input ends. Each round
//! draws two elements, a tangent vector, a point and an interpolation parameter, either in the
//! domain where the docs promise a finite result (built from finite numbers of magnitude at
//! most 10⁴; the inverse Jacobians only for rotation angles below 3 rad, short of their
//! singularity at 2π) or from arbitrary numbers (no panic is the only promise there), and calls
//! every operation of the group. A round may instead test a documented promise over the whole
//! finite range: `exp` (and `J_r`) of any finite rotation vector (with a moderate translation),
//! `So3::from_quaternion` / `So2::from_cos_sin` of any finite non-zero input, `So2::from_angle`
//! and `Se2::new` of any finite angle.

use crate::input::{Input, Scalar};
use crate::{finding, Log, Outcome};
use estimator_core::lie::{LieGroup, MatrixLieGroup, Se2, Se3, So2, So3};
use estimator_core::nalgebra::{
    Matrix3, Matrix4, Quaternion, SMatrix, SVector, UnitQuaternion, Vector1, Vector3, Vector6,
};

/// Rounds per input, at most.
const MAX_ROUNDS: usize = 200;

pub(crate) fn run(data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    let mut log = Log::default();
    match input.pick(8) {
        0 => so2::<f32>(&mut input, &mut log)?,
        1 => so2::<f64>(&mut input, &mut log)?,
        2 => se2::<f32>(&mut input, &mut log)?,
        3 => se2::<f64>(&mut input, &mut log)?,
        4 => so3::<f32>(&mut input, &mut log)?,
        5 => so3::<f64>(&mut input, &mut log)?,
        6 => se3::<f32>(&mut input, &mut log)?,
        _ => se3::<f64>(&mut input, &mut log)?,
    }
    log.finish()
}

fn finite<T: Scalar, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// A `lie-finite` finding unless `ok`.
fn expect_finite(ok: bool, group: &str, op: &str, detail: impl FnOnce() -> String) -> Outcome {
    if ok {
        Ok(())
    } else {
        Err(finding(
            "lie-finite",
            &format!("{group}::{op}"),
            format!("a non-finite result from finite inputs: {}", detail()),
        ))
    }
}

/// How a round builds its values: the group's constructors, in the domain or from anything,
/// and the rotation angle of a tangent vector.
struct Draw<G, T: Scalar, const N: usize, const D: usize> {
    domain: fn(&mut Input<'_>) -> G,
    any: fn(&mut Input<'_>) -> G,
    angle: fn(&SVector<T, N>) -> T,
}

/// One round on the group `G` (see the module docs).
fn round<T, G, const N: usize, const D: usize, const M: usize>(
    group: &str,
    draw: &Draw<G, T, N, D>,
    input: &mut Input<'_>,
) -> Outcome
where
    T: Scalar,
    G: MatrixLieGroup<T, N, D, M>,
{
    let in_domain = input.chance(192);
    let (a, b, tau, p, s) = if in_domain {
        (
            (draw.domain)(input),
            (draw.domain)(input),
            SVector::<T, N>::from_fn(|_, _| input.moderate()),
            SVector::<T, D>::from_fn(|_, _| input.moderate()),
            input.moderate::<T>() * T::lit(1e-3),
        )
    } else {
        (
            (draw.any)(input),
            (draw.any)(input),
            SVector::<T, N>::from_fn(|_, _| input.real()),
            SVector::<T, D>::from_fn(|_, _| input.real()),
            input.real(),
        )
    };
    // Every operation, in the order of the module docs of `lie`.
    let exp = G::exp(&tau);
    let (exp_j, jr_exp) = G::exp_jac(&tau);
    let log = a.log();
    let (log_j, jr_inv_log) = a.log_jac();
    let hat = G::hat(&tau);
    let vee = G::vee(&hat);
    let ab = a.compose(&b);
    let (ab_j, ja, jb) = a.compose_jac(&b);
    let inv = a.inverse();
    let (inv_j, j_inv) = a.inverse_jac();
    let between = a.between(&b);
    let (between_j, jba, jbb) = a.between_jac(&b);
    let act = a.act(&p);
    let (act_j, jat, jap) = a.act_jac(&p);
    let adjoint = a.adjoint();
    let jr = G::right_jacobian(&tau);
    let jl = G::left_jacobian(&tau);
    let jr_inv = G::right_jacobian_inv(&tau);
    let jl_inv = G::left_jacobian_inv(&tau);
    let matrix = a.matrix();
    let normalized = a.normalize();
    let back = G::try_from_matrix(&matrix);
    let rplus = a.rplus(&tau);
    let (rplus_j, jrp_a, jrp_t) = a.rplus_jac(&tau);
    let rminus = b.rminus(&a);
    let (rminus_j, jrm_a, jrm_b) = b.rminus_jac(&a);
    let interpolated = a.interpolate(&b, s);
    let _ = (a.is_finite(), G::identity(), G::try_from_matrix(&hat));
    if !in_domain {
        return Ok(());
    }
    let shown = || format!("a = {a:?}, b = {b:?}, τ = {tau:?}, p = {p:?}, s = {s:?}");
    let groups = [
        ("exp", exp),
        ("exp_jac", exp_j),
        ("compose", ab),
        ("compose_jac", ab_j),
        ("inverse", inv),
        ("inverse_jac", inv_j),
        ("between", between),
        ("between_jac", between_j),
        ("normalize", normalized),
        ("rplus", rplus),
        ("rplus_jac", rplus_j),
        ("interpolate", interpolated),
    ];
    for (op, g) in groups {
        expect_finite(g.is_finite(), group, op, shown)?;
    }
    let tangents = [
        ("log", log),
        ("log_jac", log_j),
        ("vee", vee),
        ("rminus", rminus),
        ("rminus_jac", rminus_j),
    ];
    for (op, v) in tangents {
        expect_finite(finite(&v), group, op, shown)?;
    }
    let near = (draw.angle)(&tau) < T::lit(3.0);
    let jacobians = [
        ("exp_jac", jr_exp, true),
        ("log_jac", jr_inv_log, true),
        ("compose_jac", ja, true),
        ("compose_jac", jb, true),
        ("inverse_jac", j_inv, true),
        ("between_jac", jba, true),
        ("between_jac", jbb, true),
        ("adjoint", adjoint, true),
        ("right_jacobian", jr, true),
        ("left_jacobian", jl, true),
        ("right_jacobian_inv", jr_inv, near),
        ("left_jacobian_inv", jl_inv, near),
        ("rplus_jac", jrp_a, true),
        ("rplus_jac", jrp_t, true),
        ("rminus_jac", jrm_a, true),
        ("rminus_jac", jrm_b, true),
    ];
    for (op, j, promised) in jacobians {
        if promised {
            expect_finite(finite(&j), group, op, shown)?;
        }
    }
    expect_finite(
        finite(&act) && finite(&act_j) && finite(&jat) && finite(&jap),
        group,
        "act_jac",
        shown,
    )?;
    expect_finite(finite(&hat) && finite(&matrix), group, "matrix", shown)?;
    if let Some(g) = back {
        expect_finite(g.is_finite(), group, "try_from_matrix", shown)?;
    }
    Ok(())
}

/// The rounds on one group; `whole_range` tests its promises over the whole finite range.
fn rounds<T, G, const N: usize, const D: usize, const M: usize>(
    group: &str,
    draw: &Draw<G, T, N, D>,
    input: &mut Input<'_>,
    log: &mut Log,
    whole_range: fn(&str, &mut Input<'_>, &mut Log) -> Outcome,
) -> Outcome
where
    T: Scalar,
    G: MatrixLieGroup<T, N, D, M>,
{
    for _ in 0..MAX_ROUNDS {
        if input.is_empty() {
            break;
        }
        if input.chance(64) {
            whole_range(group, input, log)?;
        } else {
            log.take(round::<T, G, N, D, M>(group, draw, input))?;
        }
    }
    Ok(())
}

/// `‖q‖ = 1` to `10⁻³`.
fn unit<T: Scalar>(norm_squared: T) -> bool {
    (norm_squared - T::one()).abs() <= T::lit(1e-3)
}

/// `exp` and `J_r` of a tangent with rotation part `w`, checked finite.
fn exp_whole<T, G, const N: usize, const D: usize, const M: usize>(
    group: &str,
    tau: &SVector<T, N>,
    log: &mut Log,
) -> Outcome
where
    T: Scalar,
    G: MatrixLieGroup<T, N, D, M>,
{
    if !finite(tau) {
        return Ok(());
    }
    let shown = || format!("τ = {tau:?}");
    log.take(expect_finite(G::exp(tau).is_finite(), group, "exp", shown))?;
    let (e, j) = G::exp_jac(tau);
    log.take(expect_finite(
        e.is_finite() && finite(&j),
        group,
        "exp_jac",
        shown,
    ))?;
    log.take(expect_finite(
        finite(&G::right_jacobian(tau)),
        group,
        "right_jacobian",
        shown,
    ))
}

fn so2<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let group = format!("So2<{}>", T::NAME);
    let draw = Draw::<So2<T>, T, 1, 2> {
        domain: |input| match input.byte() % 2 {
            0 => So2::from_angle(input.moderate()),
            _ => So2::from_cos_sin(input.moderate(), input.moderate())
                .unwrap_or_else(|| So2::from_angle(T::zero())),
        },
        any: |input| match input.byte() % 2 {
            0 => So2::from_angle(input.real()),
            _ => So2::from_cos_sin(input.real(), input.real())
                .unwrap_or_else(|| So2::from_angle(T::zero())),
        },
        angle: |_| T::zero(),
    };
    rounds::<T, So2<T>, 1, 2, 2>(&group, &draw, input, log, |group, input, log| {
        let (theta, re, im): (T, T, T) = (input.real(), input.real(), input.real());
        if theta.is_finite() {
            let r = So2::from_angle(theta);
            log.take(expect_finite(r.is_finite(), group, "from_angle", || {
                format!("θ = {theta:?}")
            }))?;
            exp_whole::<T, So2<T>, 1, 2, 2>(group, &Vector1::new(theta), log)?;
        }
        if re.is_finite() && im.is_finite() && (re != T::zero() || im != T::zero()) {
            let ok = So2::from_cos_sin(re, im)
                .is_some_and(|r| r.is_finite() && unit(r.cos() * r.cos() + r.sin() * r.sin()));
            if !ok {
                log.take(Err(finding(
                    "lie-constructor",
                    &format!("{group}::from_cos_sin"),
                    format!(
                        "({re:?}, {im:?}) has a finite non-zero norm, gave {:?}",
                        So2::from_cos_sin(re, im)
                    ),
                )))?;
            }
        }
        Ok(())
    })
}

fn se2<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let group = format!("Se2<{}>", T::NAME);
    let draw = Draw::<Se2<T>, T, 3, 2> {
        domain: |input| Se2::new(input.moderate(), input.moderate(), input.moderate()),
        any: |input| match input.byte() % 2 {
            0 => Se2::new(input.real(), input.real(), input.real()),
            _ => {
                let m = Matrix3::from_fn(|_, _| input.real());
                Se2::try_from_matrix_or_identity(&m)
            }
        },
        angle: |tau| tau[2].abs(),
    };
    rounds::<T, Se2<T>, 3, 2, 3>(&group, &draw, input, log, |group, input, log| {
        let (x, y, theta): (T, T, T) = (input.moderate(), input.moderate(), input.real());
        if theta.is_finite() {
            log.take(expect_finite(
                Se2::new(x, y, theta).is_finite(),
                group,
                "new",
                || format!("({x:?}, {y:?}, {theta:?})"),
            ))?;
            exp_whole::<T, Se2<T>, 3, 2, 3>(group, &Vector3::new(x, y, theta), log)?;
        }
        Ok(())
    })
}

fn so3<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let group = format!("So3<{}>", T::NAME);
    let draw = Draw::<So3<T>, T, 3, 3> {
        domain: |input| match input.byte() % 2 {
            0 => So3::exp(&input.moderate3()),
            _ => So3::from_wxyz(
                input.moderate(),
                input.moderate(),
                input.moderate(),
                input.moderate(),
            )
            .unwrap_or_else(So3::identity),
        },
        any: |input| match input.byte() % 3 {
            0 => So3::exp(&input.vec3()),
            1 => So3::from_unit_quaternion(UnitQuaternion::new_unchecked(Quaternion::new(
                input.real(),
                input.real(),
                input.real(),
                input.real(),
            ))),
            _ => So3::from_rotation_matrix(&input.mat3()).unwrap_or_else(So3::identity),
        },
        angle: |tau| tau.norm(),
    };
    rounds::<T, So3<T>, 3, 3, 3>(&group, &draw, input, log, |group, input, log| {
        let w: Vector3<T> = input.vec3();
        exp_whole::<T, So3<T>, 3, 3, 3>(group, &w, log)?;
        let q = Quaternion::new(input.real(), input.real(), input.real(), input.real());
        let finite_q = q.coords.iter().all(|x: &T| x.is_finite());
        let _ = (So3::from_unit_quaternion(UnitQuaternion::new_unchecked(q)).renormalize(),);
        if finite_q && q.coords.iter().any(|x| *x != T::zero()) {
            let r = So3::from_quaternion(&q);
            let ok = r.is_some_and(|r| {
                let u = r.quaternion();
                r.is_finite() && unit(u.coords.norm_squared())
            });
            if !ok {
                log.take(Err(finding(
                    "lie-constructor",
                    &format!("{group}::from_quaternion"),
                    format!("{q:?} has a finite non-zero norm, gave {r:?}"),
                )))?;
            }
            let _ = So3::from_wxyz(q.w, q.i, q.j, q.k).map(|r| r.cast::<f32>());
        }
        Ok(())
    })
}

fn se3<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let group = format!("Se3<{}>", T::NAME);
    let draw = Draw::<Se3<T>, T, 6, 3> {
        domain: |input| match input.byte() % 2 {
            0 => Se3::exp(&Vector6::from_fn(|_, _| input.moderate())),
            _ => Se3::from_parts(So3::exp(&input.moderate3()), input.moderate3()),
        },
        any: |input| match input.byte() % 3 {
            0 => Se3::exp(&Vector6::from_fn(|_, _| input.real())),
            1 => Se3::from_parts(
                So3::from_wxyz(input.real(), input.real(), input.real(), input.real())
                    .unwrap_or_else(So3::identity),
                input.vec3(),
            ),
            _ => {
                let m = Matrix4::from_fn(|_, _| input.real());
                Se3::try_from_matrix_or_identity(&m)
            }
        },
        angle: |tau| Vector3::new(tau[3], tau[4], tau[5]).norm(),
    };
    rounds::<T, Se3<T>, 6, 3, 4>(&group, &draw, input, log, |group, input, log| {
        let v = input.moderate3::<T>();
        let w = input.vec3::<T>();
        let xi = Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z);
        exp_whole::<T, Se3<T>, 6, 3, 4>(group, &xi, log)
    })
}

/// `try_from_matrix`, or the identity when refused.
trait OrIdentity<T, const M: usize>: Sized {
    fn try_from_matrix_or_identity(m: &SMatrix<T, M, M>) -> Self;
}

impl<T: Scalar> OrIdentity<T, 3> for Se2<T> {
    fn try_from_matrix_or_identity(m: &Matrix3<T>) -> Self {
        <Self as LieGroup<T>>::try_from_matrix(m).unwrap_or_else(<Self as LieGroup<T>>::identity)
    }
}

impl<T: Scalar> OrIdentity<T, 4> for Se3<T> {
    fn try_from_matrix_or_identity(m: &Matrix4<T>) -> Self {
        <Self as LieGroup<T>>::try_from_matrix(m).unwrap_or_else(<Self as LieGroup<T>>::identity)
    }
}

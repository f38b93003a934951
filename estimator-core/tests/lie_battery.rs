//! One test battery, written once over `MatrixLieGroup` and instantiated for every group
//! (SO(2), SE(2), SO(3), SE(3)) and both scalars (`f32`, `f64`).
//!
//! What it checks, at random points (proptest), at the identity, at tangents of size 1e-9…1e-4
//! and at rotations 1e-6…1e-2 short of π:
//!
//! * group laws (associativity, identity, inverse), `vee∘hat`, hat as `τ^ = Σ τᵢ Gⁱ` (eq. 3.2 of
//!   *Lie Groups and Smooth Manifolds for Robotic State Estimation*, "the paper");
//! * `log∘exp` and `exp∘log`; the adjoint identity `a·exp(τ) = exp(Ad_a τ)·a`;
//!   `J_r J_r⁻¹ = J_l J_l⁻¹ = I`;
//! * every `*_jac` Jacobian against central finite differences through `⊕`/`⊖`;
//! * the paper's Theorem 5.1, `F = a [H(p) | I]` with `τ^ p̄ = H(p) τ`: `∂(a·p)/∂a` column `k`
//!   equals `(M(a) Gᵏ p̄)` (homogeneous `p̄`);
//! * `f32` against `f64` at the same stored numbers, with relative error bounds in `f32` ulps.
//!
//! # Tolerances
//!
//! Finite differences use Richardson extrapolation of the central difference,
//! `D = (4 D(h/2) − D(h))/3`, whose truncation error is `O(h⁴)` and whose rounding error is about
//! `2 ε ‖f‖ / h`. The tolerance of each check is that bound, `fd_tol(ε, h)`, with the scale of
//! the Jacobian; nothing is tuned to the observed error. Values (`exp`, `log`, products) are
//! compared to a few `ε` times the size of the quantity and the condition of the operation.

mod support;
use estimator_core::lie::{MatrixLieGroup, Se2, Se3, So2, So3};
use estimator_core::Real;
use nalgebra::{SMatrix, SVector};
use proptest::prelude::*;
use support::fd_jacobian;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn maxabs<T: Real, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> f64 {
    m.iter().fold(0.0, |acc, x| acc.max(x.to_f64().abs()))
}

fn diff<T: Real, const R: usize, const C: usize>(
    a: &SMatrix<T, R, C>,
    b: &SMatrix<T, R, C>,
) -> f64 {
    a.iter()
        .zip(b.iter())
        .fold(0.0, |acc, (x, y)| acc.max((x.to_f64() - y.to_f64()).abs()))
}

/// Asserts `max|a − b| ≤ tol · max(1, max|b|)`.
#[track_caller]
fn close<T: Real, const R: usize, const C: usize>(
    a: &SMatrix<T, R, C>,
    b: &SMatrix<T, R, C>,
    tol: f64,
    what: &str,
) {
    let scale = maxabs(b).max(1.0);
    let err = diff(a, b);
    assert!(
        err <= tol * scale,
        "{what}: error {err:.3e} > {tol:.3e} × {scale:.3e}\n got {a:?}\n want {b:?}"
    );
}

/// The rounding bound of a Richardson-extrapolated central difference with step `h`, when each
/// evaluation of `f` errs by `δ = ε·S` (`S`: the size of the numbers it is computed from): `D(h)`
/// errs by `δ/h`, `D(h/2)` by `2δ/h`, and `(4D(h/2) − D(h))/3` by at most `3δ/h`; the chains
/// of two or three group operations behind each `f` carry a few `ε` each, hence the factor 8.
fn fd_tol(eps: f64, scale: f64, h: f64) -> f64 {
    8.0 * eps * scale / h
}

/// Which tangent coordinates are angles, for building rotations of a chosen size.
#[derive(Clone, Copy)]
struct Meta {
    rot: &'static [usize],
}

/// A tangent from raw numbers in `[−1, 1]`: the rotation part rescaled to angle `angle`, the
/// rest kept as translation.
fn tangent<T: Real, const N: usize>(raw: &[f64; 6], meta: Meta, angle: f64) -> SVector<T, N> {
    let mut v = SVector::<f64, N>::from_fn(|i, _| raw[i]);
    let norm = meta.rot.iter().map(|&i| v[i] * v[i]).sum::<f64>().sqrt();
    for &i in meta.rot {
        v[i] = if norm > 0.0 { v[i] / norm * angle } else { 0.0 };
    }
    if norm == 0.0 {
        v[meta.rot[0]] = angle;
    }
    v.map(T::lit)
}

fn epsilon<T: Real>() -> f64 {
    T::EPSILON_F64
}

/// Zero-padded homogeneous point `p̄` (`[p; 1]` for SE(n), `p` for SO(n)).
fn homogeneous<T: Real, const D: usize, const M: usize>(p: &SVector<T, D>) -> SVector<T, M> {
    SVector::<T, M>::from_fn(|i, _| if i < D { p[i] } else { T::one() })
}

/// `exp(X) = Σ_k X^k/k!` (the paper, §3), summed to convergence after scaling `X` by `2^-s` so that
/// `‖X‖ ≤ 1/2`, then squared `s` times. Independent of every closed form under test.
fn matrix_exp_series<const M: usize>(x: &SMatrix<f64, M, M>) -> SMatrix<f64, M, M> {
    let norm = x.norm();
    let mut s = 0;
    while norm / f64::powi(2.0, s) > 0.5 {
        s += 1;
    }
    let xs = x / f64::powi(2.0, s);
    let mut sum = SMatrix::<f64, M, M>::identity();
    let mut term = SMatrix::<f64, M, M>::identity();
    for k in 1..30 {
        term = term * xs / k as f64;
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}

// ---------------------------------------------------------------------------------------------
// The battery
// ---------------------------------------------------------------------------------------------

/// Group laws, hat/vee, round trips and the adjoint identity at `a, b, c` and tangent `tau`
/// (whose rotation angle is `angle`).
fn check_algebra<T, G, const N: usize, const D: usize, const M: usize>(
    a: &G,
    b: &G,
    c: &G,
    tau: &SVector<T, N>,
    angle: f64,
) where
    T: Real,
    G: MatrixLieGroup<T, N, D, M>,
{
    let eps = epsilon::<T>();
    let tol = 16.0 * eps;
    // Associativity, identity, inverse (on matrices).
    close(
        &(a.compose(b)).compose(c).matrix(),
        &a.compose(&b.compose(c)).matrix(),
        tol,
        "associativity",
    );
    close(
        &a.compose(&G::identity()).matrix(),
        &a.matrix(),
        tol,
        "right identity",
    );
    close(
        &G::identity().compose(a).matrix(),
        &a.matrix(),
        tol,
        "left identity",
    );
    close(
        &a.compose(&a.inverse()).matrix(),
        &G::identity().matrix(),
        tol,
        "inverse",
    );
    close(
        &a.between(b).matrix(),
        &a.inverse().compose(b).matrix(),
        tol,
        "between",
    );
    // Matrix representation is a homomorphism.
    close(
        &a.compose(b).matrix(),
        &(a.matrix() * b.matrix()),
        tol,
        "matrix homomorphism",
    );
    // hat / vee and the generators (the paper, eq. 3.2: τ^ = Σ τᵢ Gⁱ).
    close(&G::vee(&G::hat(tau)), tau, 0.0, "vee(hat)");
    let mut sum = SMatrix::<T, M, M>::zeros();
    for i in 0..N {
        sum += G::hat(&SVector::<T, N>::from_fn(|k, _| {
            if k == i {
                T::one()
            } else {
                T::zero()
            }
        })) * tau[i];
    }
    close(&G::hat(tau), &sum, 0.0, "hat = Σ τᵢ Gⁱ");
    // log∘exp: conditioned like 1 for angles below π (the SE parts through J_l⁻¹, bounded there).
    let e = G::exp(tau);
    assert!(e.is_finite());
    close(&e.log(), tau, 16.0 * eps * (1.0 + angle), "log(exp τ)");
    // ... and relative to τ itself, which matters for small steps (a 1e-9 rotation must come
    // back as 1e-9 to a few ulps, not to ε absolute).
    let rel = diff(&e.log(), tau) / maxabs(tau).max(f64::MIN_POSITIVE);
    assert!(
        maxabs(tau) == 0.0 || rel <= 8.0 * eps,
        "log(exp τ) relative error {rel:.3e} at {tau:?}"
    );
    // exp∘log.
    close(
        &G::exp(&a.log()).matrix(),
        &a.matrix(),
        16.0 * eps,
        "exp(log a)",
    );
    // rplus/rminus are inverse.
    close(
        &a.rplus(&b.rminus(a)).matrix(),
        &b.matrix(),
        16.0 * eps,
        "a ⊕ (b ⊖ a) = b",
    );
    // Adjoint: a·exp(τ) = exp(Ad_a τ)·a.
    let lhs = a.compose(&G::exp(tau));
    let rhs = G::exp(&(a.adjoint() * tau)).compose(a);
    close(
        &lhs.matrix(),
        &rhs.matrix(),
        32.0 * eps * (1.0 + maxabs(&a.adjoint())),
        "adjoint",
    );
    // J J⁻¹ = I for both Jacobians.
    let id = SMatrix::<T, N, N>::identity();
    let cond = maxabs(&G::right_jacobian_inv(tau)).max(1.0);
    close(
        &(G::right_jacobian(tau) * G::right_jacobian_inv(tau)),
        &id,
        16.0 * eps * cond,
        "J_r J_r⁻¹",
    );
    close(
        &(G::left_jacobian(tau) * G::left_jacobian_inv(tau)),
        &id,
        16.0 * eps * cond,
        "J_l J_l⁻¹",
    );
    // Interpolation end points and midpoint.
    close(
        &a.interpolate(b, T::zero()).matrix(),
        &a.matrix(),
        16.0 * eps,
        "interpolate(0)",
    );
    close(
        &a.interpolate(b, T::one()).matrix(),
        &b.matrix(),
        64.0 * eps,
        "interpolate(1)",
    );
    // normalize moves a unit element by its norm error (≤ 2ε, quadratic in the matrix) only.
    close(&a.normalize().matrix(), &a.matrix(), 8.0 * eps, "normalize");
    // Independent reference: the matrix exponential as the paper's series (§3), summed in f64
    // with scaling and squaring, against the closed form.
    let series = matrix_exp_series(&G::hat(tau).map(|x| x.to_f64()));
    close(
        &e.matrix().map(|x| x.to_f64()),
        &series,
        16.0 * eps * (1.0 + maxabs(tau)),
        "exp = Σ (τ^)^k/k!",
    );
    // try_from_matrix round trip.
    let back = G::try_from_matrix(&a.matrix()).expect("a group matrix is accepted");
    close(
        &back.matrix(),
        &a.matrix(),
        16.0 * eps,
        "try_from_matrix(matrix)",
    );
}

/// Every `*_jac` against Richardson central differences through `⊕`/`⊖`.
///
/// `h_log` is the step for maps whose output is a tangent (log, rminus): it must stay below the
/// distance of the angle to π, where `log` wraps.
fn check_jacobians<T, G, const N: usize, const D: usize, const M: usize>(
    a: &G,
    b: &G,
    tau: &SVector<T, N>,
    p: &SVector<T, D>,
    h: f64,
    h_log: f64,
) where
    T: Real,
    G: MatrixLieGroup<T, N, D, M>,
{
    let eps = epsilon::<T>();
    // The size of the numbers every finite difference is computed from.
    let scale = 1.0
        + maxabs(&a.matrix())
            .max(maxabs(&b.matrix()))
            .max(maxabs(&G::exp(tau).matrix()))
            .max(maxabs(tau))
            .max(maxabs(p));
    let tol = fd_tol(eps, scale, h);
    let tol_log = fd_tol(eps, scale, h_log);

    // exp_jac: exp(τ + δ) ⊖ exp(τ) ≈ J_r(τ) δ. (The output is a small local tangent: no wrap.)
    let (e, jr) = G::exp_jac(tau);
    close(
        &e.matrix(),
        &G::exp(tau).matrix(),
        4.0 * eps,
        "exp_jac value",
    );
    close(
        &jr,
        &G::right_jacobian(tau),
        4.0 * eps,
        "exp_jac = right_jacobian",
    );
    let num = fd_jacobian(|d| G::exp(&(tau + d)).rminus(&e), h);
    close(&jr, &num, tol, "exp_jac vs FD");
    // Left Jacobian: exp(τ + δ) ≈ exp(J_l δ)·exp(τ).
    let num = fd_jacobian(|d| G::exp(&(tau + d)).compose(&e.inverse()).log(), h);
    close(&G::left_jacobian(tau), &num, tol, "left_jacobian vs FD");

    // log_jac: log(a ⊕ δ) − log(a) ≈ J_r⁻¹(log a) δ.
    let (l, jl) = a.log_jac();
    close(&l, &a.log(), 4.0 * eps, "log_jac value");
    let num = fd_jacobian(|d| a.rplus(d).log() - l, h_log);
    close(&jl, &num, tol_log, "log_jac vs FD");
    close(
        &jl,
        &G::right_jacobian_inv(&l),
        16.0 * eps * maxabs(&jl).max(1.0),
        "log_jac = J_r⁻¹",
    );

    // inverse_jac.
    let (inv, j) = a.inverse_jac();
    let num = fd_jacobian(|d| a.rplus(d).inverse().rminus(&inv), h);
    close(&j, &num, tol, "inverse_jac vs FD");

    // compose_jac.
    let (ab, ja, jb) = a.compose_jac(b);
    close(
        &ab.matrix(),
        &a.compose(b).matrix(),
        0.0,
        "compose_jac value",
    );
    let num = fd_jacobian(|d| a.rplus(d).compose(b).rminus(&ab), h);
    close(&ja, &num, tol, "compose_jac ∂a vs FD");
    let num = fd_jacobian(|d| a.compose(&b.rplus(d)).rminus(&ab), h);
    close(&jb, &num, tol, "compose_jac ∂b vs FD");

    // between_jac.
    let (z, ja, jb) = a.between_jac(b);
    let num = fd_jacobian(|d| a.rplus(d).between(b).rminus(&z), h);
    close(&ja, &num, tol, "between_jac ∂a vs FD");
    let num = fd_jacobian(|d| a.between(&b.rplus(d)).rminus(&z), h);
    close(&jb, &num, tol, "between_jac ∂b vs FD");

    // rplus_jac.
    let (x, ja, jt) = a.rplus_jac(tau);
    let num = fd_jacobian(|d| a.rplus(d).rplus(tau).rminus(&x), h);
    close(&ja, &num, tol, "rplus_jac ∂a vs FD");
    let num = fd_jacobian(|d| a.rplus(&(tau + d)).rminus(&x), h);
    close(&jt, &num, tol, "rplus_jac ∂τ vs FD");

    // rminus_jac: τ = a ⊖ b.
    let (t, ja, jb) = a.rminus_jac(b);
    close(&t, &a.rminus(b), 4.0 * eps, "rminus_jac value");
    let num = fd_jacobian(|d| a.rplus(d).rminus(b) - t, h_log);
    close(&ja, &num, tol_log, "rminus_jac ∂a vs FD");
    let num = fd_jacobian(|d| a.rminus(&b.rplus(d)) - t, h_log);
    close(&jb, &num, tol_log, "rminus_jac ∂b vs FD");

    // act_jac (the paper, Theorem 5.1: F = a [H(p) | I]).
    let (q, ja, jp) = a.act_jac(p);
    // Two valid evaluations (matrix vs quaternion) differ by a few ε per term of R p.
    close(
        &q,
        &a.act(p),
        8.0 * eps * (1.0 + p.lp_norm(1).to_f64()),
        "act_jac value",
    );
    let num = fd_jacobian(|d| a.rplus(d).act(p) - q, h);
    close(&ja, &num, tol, "act_jac ∂a vs FD");
    let num = fd_jacobian(|d| a.act(&(p + d)) - q, h);
    close(&jp, &num, tol, "act_jac ∂p vs FD");
    // Theorem 5.1 literally: column k of ∂(a·p)/∂a is M(a)·Gᵏ·p̄, and ∂/∂p is the rotation block.
    let m = a.matrix();
    let pbar = homogeneous::<T, D, M>(p);
    for k in 0..N {
        let gk = G::hat(&SVector::<T, N>::from_fn(|i, _| {
            if i == k {
                T::one()
            } else {
                T::zero()
            }
        }));
        let col = m * gk * pbar;
        let want = SVector::<T, D>::from_fn(|i, _| col[i]);
        close(
            &ja.column(k).into_owned(),
            &want,
            8.0 * eps,
            "Theorem 5.1 column",
        );
    }
    let rot = SMatrix::<T, D, D>::from_fn(|i, j| m[(i, j)]);
    close(&jp, &rot, 0.0, "act_jac ∂p = R");
}

/// The whole battery at one configuration.
#[allow(clippy::too_many_arguments)]
fn battery<T, G, const N: usize, const D: usize, const M: usize>(
    meta: Meta,
    raw_a: &[f64; 6],
    raw_b: &[f64; 6],
    raw_t: &[f64; 6],
    angle_a: f64,
    angle_b: f64,
    angle_t: f64,
    p: &[f64; 3],
) where
    T: Real,
    G: MatrixLieGroup<T, N, D, M>,
{
    let a = G::exp(&tangent::<T, N>(raw_a, meta, angle_a));
    let b = G::exp(&tangent::<T, N>(raw_b, meta, angle_b));
    let c = G::exp(&tangent::<T, N>(raw_t, meta, 0.5 * (angle_a + angle_b)));
    let tau = tangent::<T, N>(raw_t, meta, angle_t);
    let p = SVector::<T, D>::from_fn(|i, _| T::lit(p[i]));
    check_algebra::<T, G, N, D, M>(&a, &b, &c, &tau, angle_t);
    // FD step: Richardson's O(h⁴) truncation against the 2ε/h rounding; h ≈ ε^{1/5}.
    let h = epsilon::<T>().powf(0.2);
    // For tangent-valued outputs (log, ⊖) the step must not carry the angle across π.
    let rot_norm = |v: &SVector<T, N>| {
        meta.rot
            .iter()
            .map(|&i| v[i].to_f64().powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let widest = rot_norm(&a.log()).max(rot_norm(&a.rminus(&b)));
    let h_log = h.min(0.25 * (core::f64::consts::PI - widest));
    // Where the step that avoids π is so small that rounding swamps the difference (f32 within
    // 1e-4 of π), the f32-against-f64 test covers the Jacobians instead.
    if fd_tol(epsilon::<T>(), 1.0, h_log) < 1e-3 {
        check_jacobians::<T, G, N, D, M>(&a, &b, &tau, &p, h, h_log);
    }
}

/// Tiny angles `1e-9…1e-4`, the identity, and angles `1e-6…1e-2` short of π.
fn battery_special<T, G, const N: usize, const D: usize, const M: usize>(meta: Meta)
where
    T: Real,
    G: MatrixLieGroup<T, N, D, M>,
{
    let raws = [
        [0.3, -0.7, 0.2, 0.9, -0.4, 0.5],
        [-0.8, 0.1, 0.6, -0.2, 0.7, 0.3],
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    ];
    let p = [0.7, -1.3, 2.1];
    let pi = core::f64::consts::PI;
    for raw in &raws {
        // Identity.
        battery::<T, G, N, D, M>(meta, raw, raw, raw, 0.0, 0.0, 0.0, &p);
        for &tiny in &[1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4] {
            battery::<T, G, N, D, M>(meta, raw, &raws[1], raw, tiny, 0.4, tiny, &p);
            battery::<T, G, N, D, M>(meta, raw, raw, raw, tiny, tiny, tiny, &p);
        }
        for &gap in &[1e-6, 1e-5, 1e-4, 1e-3, 1e-2] {
            battery::<T, G, N, D, M>(meta, raw, &raws[1], raw, pi - gap, 0.3, pi - gap, &p);
        }
    }
}

/// `f32` against `f64` at the same stored numbers: the error of each `f32` result, relative to
/// the size of the quantity, in units of the `f32` epsilon.
fn f32_vs_f64<G32, G64, const N: usize, const D: usize, const M: usize>(
    meta: Meta,
    raw_a: &[f64; 6],
    raw_t: &[f64; 6],
    angle: f64,
    cast: impl Fn(&G32) -> G64,
) where
    G32: MatrixLieGroup<f32, N, D, M>,
    G64: MatrixLieGroup<f64, N, D, M>,
{
    let eps = f32::EPSILON as f64;
    let t32 = tangent::<f32, N>(raw_t, meta, angle);
    let t64 = t32.map(|x| x as f64);
    let a32 = G32::exp(&tangent::<f32, N>(raw_a, meta, 1.1));
    let a64 = cast(&a32);
    let up = |m: &SMatrix<f32, M, M>| m.map(|x| x as f64);
    let upn = |m: &SMatrix<f32, N, N>| m.map(|x| x as f64);
    let upv = |m: &SVector<f32, N>| m.map(|x| x as f64);

    // exp: well conditioned (a few ulps).
    close(
        &up(&G32::exp(&t32).matrix()),
        &G64::exp(&t64).matrix(),
        4.0 * eps,
        "f32 exp",
    );
    // log: relative to the angle; near π the conditioning is that of atan2 (1).
    let e32 = G32::exp(&t32);
    close(
        &upv(&e32.log()),
        &cast(&e32).log(),
        4.0 * eps * (1.0 + angle),
        "f32 log",
    );
    // Jacobians and their inverses: the cancelling coefficients are multiplied by θ², θ⁴.
    let cond = maxabs(&G64::right_jacobian_inv(&t64)).max(1.0);
    close(
        &upn(&G32::right_jacobian(&t32)),
        &G64::right_jacobian(&t64),
        8.0 * eps,
        "f32 J_r",
    );
    close(
        &upn(&G32::right_jacobian_inv(&t32)),
        &G64::right_jacobian_inv(&t64),
        8.0 * eps * cond,
        "f32 J_r⁻¹",
    );
    close(&upn(&a32.adjoint()), &a64.adjoint(), 4.0 * eps, "f32 Ad");
    let (_, j32) = e32.log_jac();
    let (_, j64) = cast(&e32).log_jac();
    close(&upn(&j32), &j64, 8.0 * eps * cond, "f32 log_jac");
    close(
        &up(&a32.compose(&e32).matrix()),
        &a64.compose(&cast(&e32)).matrix(),
        4.0 * eps,
        "f32 compose",
    );
}

// ---------------------------------------------------------------------------------------------
// Instantiation for every group and scalar
// ---------------------------------------------------------------------------------------------

macro_rules! instantiate {
    ($modname:ident, $G:ident, $N:literal, $D:literal, $M:literal, $rot:expr) => {
        mod $modname {
            use super::*;
            const META: Meta = Meta { rot: $rot };

            #[test]
            fn special_points_f64() {
                battery_special::<f64, $G<f64>, $N, $D, $M>(META);
            }

            #[test]
            fn special_points_f32() {
                battery_special::<f32, $G<f32>, $N, $D, $M>(META);
            }

            #[test]
            fn f32_agrees_with_f64() {
                let raws = [[0.3, -0.7, 0.2, 0.9, -0.4, 0.5], [-0.8, 0.1, 0.6, -0.2, 0.7, 0.3]];
                let pi = core::f64::consts::PI;
                for raw in &raws {
                    for angle in [0.0, 1e-9, 1e-6, 1e-4, 1e-2, 0.1, 0.5, 1.0, 2.0, 3.0, pi - 1e-3, pi - 1e-5] {
                        f32_vs_f64::<$G<f32>, $G<f64>, $N, $D, $M>(META, raw, &raws[1], angle, |g| g.cast());
                    }
                }
            }

            proptest! {
                #![proptest_config(ProptestConfig { cases: 512, .. ProptestConfig::default() })]

                #[test]
                fn random_points_f64(
                    a in prop::array::uniform6(-1.0f64..1.0),
                    b in prop::array::uniform6(-1.0f64..1.0),
                    t in prop::array::uniform6(-1.0f64..1.0),
                    angles in prop::array::uniform3(0.0f64..3.1),
                    p in prop::array::uniform3(-2.0f64..2.0),
                ) {
                    battery::<f64, $G<f64>, $N, $D, $M>(META, &a, &b, &t, angles[0], angles[1], angles[2], &p);
                }

                #[test]
                fn random_points_f32(
                    a in prop::array::uniform6(-1.0f64..1.0),
                    b in prop::array::uniform6(-1.0f64..1.0),
                    t in prop::array::uniform6(-1.0f64..1.0),
                    angles in prop::array::uniform3(0.0f64..3.1),
                    p in prop::array::uniform3(-2.0f64..2.0),
                ) {
                    battery::<f32, $G<f32>, $N, $D, $M>(META, &a, &b, &t, angles[0], angles[1], angles[2], &p);
                }
            }
        }
    };
}

instantiate!(so2, So2, 1, 2, 2, &[0]);
instantiate!(se2, Se2, 3, 2, 3, &[2]);
instantiate!(so3, So3, 3, 3, 3, &[0, 1, 2]);
instantiate!(se3, Se3, 6, 3, 4, &[3, 4, 5]);

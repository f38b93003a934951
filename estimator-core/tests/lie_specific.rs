//! Group-specific checks that the generic battery cannot express: Example 5.2 of *Lie Groups and
//! Smooth Manifolds for Robotic State Estimation* ("the paper") in closed form, agreement with
//! nalgebra's own SO(3), SE(3)'s Jacobian against Barfoot's `Q` written with matrix products,
//! SO(3)'s `J_l = J_rᵀ`, SE(3)'s adjoint as its block formula, quaternion sign and norm
//! handling, `try_from_matrix` acceptance, projection and rejection (every branch of Shepperd's
//! method), and non-finite inputs.
//!
//! Tolerances are rounding bounds: `γ_k = kε/(1 − kε)` times the sum of the magnitudes of the
//! terms (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1), or a few `ε` times
//! the size of the result where the computation is a short chain of such sums.

use estimator_core::lie::{
    skew, LieGroup, MatrixLieGroup, Se2, Se3, So2, So3, ORTHOGONALITY_TOLERANCE,
};
use estimator_core::Real;
use nalgebra::{
    Matrix2, Matrix3, Matrix4, Matrix6, Quaternion, Rotation3, SMatrix, UnitQuaternion, Vector1,
    Vector2, Vector3, Vector6,
};

fn max_abs_diff<const R: usize, const C: usize>(
    a: &nalgebra::SMatrix<f64, R, C>,
    b: &nalgebra::SMatrix<f64, R, C>,
) -> f64 {
    (a - b).amax()
}

/// The paper's Example 5.2: the generators of so(3), `H(p) = Σ_k Gₖ pᵏ = [−p]×`, and
/// `F_(R,p) = R [[−p]× | I]` as returned by `So3::act_jac`.
#[test]
fn example_5_2_closed_form() {
    let g1 = Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
    let g2 = Matrix3::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0);
    let g3 = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert_eq!(So3::<f64>::hat(&Vector3::x()), g1);
    assert_eq!(So3::<f64>::hat(&Vector3::y()), g2);
    assert_eq!(So3::<f64>::hat(&Vector3::z()), g3);

    let p = Vector3::new(0.3, -1.7, 2.2);
    // Column k of H(p) is G_k p (Theorem 5.1's proof: ξ^ p = H(p) ξ).
    let mut h = Matrix3::zeros();
    h.set_column(0, &(g1 * p));
    h.set_column(1, &(g2 * p));
    h.set_column(2, &(g3 * p));
    let expected_h = Matrix3::new(0.0, p.z, -p.y, -p.z, 0.0, p.x, p.y, -p.x, 0.0);
    assert_eq!(h, expected_h, "H(p) = [-p]x as printed in Example 5.2");
    assert_eq!(h, skew(&-p));

    let r = So3::exp(&Vector3::new(0.4, -0.9, 1.3));
    let rm = r.matrix();
    let (rp, j_r, j_p) = r.act_jac(&p);
    assert!(max_abs_diff(&rp, &(rm * p)) < 1e-15);
    assert!(max_abs_diff(&j_r, &(rm * h)) < 1e-15, "F = R[-p]x");
    assert_eq!(j_p, rm, "F = R I");
}

/// Values against nalgebra's independent SO(3) implementation, at random, tiny and near-π angles.
#[test]
fn so3_agrees_with_nalgebra() {
    let axes = [
        Vector3::new(0.3, -0.7, 0.2),
        Vector3::new(-0.8, 0.1, 0.6),
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(1.0, 1.0, 1.0),
    ];
    let pi = core::f64::consts::PI;
    let angles = [
        0.0,
        1e-9,
        1e-6,
        1e-4,
        0.1,
        1.0,
        2.0,
        3.0,
        pi - 1e-2,
        pi - 1e-4,
        pi - 1e-6,
    ];
    for axis in &axes {
        for &angle in &angles {
            let w = axis.normalize() * angle;
            let ours = So3::exp(&w);
            let theirs = UnitQuaternion::from_scaled_axis(w);
            assert!(max_abs_diff(&ours.matrix(), theirs.to_rotation_matrix().matrix()) < 1e-15);
            let log = ours.log();
            assert!(
                (log - w).amax() < 1e-14 * (1.0 + angle),
                "log {angle}: {log:?} vs {w:?}"
            );
            let p = Vector3::new(0.5, -2.0, 1.5);
            assert!((ours.act(&p) - theirs * p).amax() < 1e-14);
            // Rotation3's own log is a different, matrix-based algorithm through
            // acos((tr R − 1)/2), whose error grows like ε/sin θ: it snaps angles below ~1e-7
            // to zero and errs by 1.4e-12 at 1e-4 (ours is exact there, see above). Compare
            // where it is well conditioned.
            if (0.1..3.0).contains(&angle) {
                let rot = Rotation3::from_scaled_axis(w);
                let d = (rot.scaled_axis() - log).amax();
                assert!(
                    d < 1e-12,
                    "angle {angle}: nalgebra {:?} ours {log:?}",
                    rot.scaled_axis()
                );
            }
        }
    }
}

/// Composition against nalgebra's quaternion product and SE(3) against nalgebra's isometry.
#[test]
fn products_agree_with_nalgebra() {
    let a = So3::exp(&Vector3::new(0.4, -1.1, 0.3));
    let b = So3::exp(&Vector3::new(-2.0, 0.5, 0.9));
    let ours = (a * b).quaternion();
    let theirs = a.quaternion() * b.quaternion();
    assert!((ours.coords - theirs.coords).amax() < 1e-15);

    let ta = Se3::exp(&Vector6::new(1.0, -2.0, 0.5, 0.3, 0.2, -0.9));
    let tb = Se3::exp(&Vector6::new(-0.3, 0.7, 2.0, -1.2, 0.4, 0.1));
    let iso = |t: &Se3<f64>| {
        nalgebra::Isometry3::from_parts(t.translation().into(), t.rotation().quaternion())
    };
    let prod = iso(&ta) * iso(&tb);
    assert!(max_abs_diff(&(ta * tb).matrix(), &prod.to_homogeneous()) < 1e-14);
}

/// `w < 0` and a norm of 1.0001 are accepted; `q` and `−q` have the same log, also near π.
#[test]
fn quaternion_sign_and_norm() {
    let q = Quaternion::new(0.3, -0.5, 0.7, 0.1);
    let pos = So3::from_quaternion(&q).expect("non-zero");
    let neg = So3::from_quaternion(&-q).expect("non-zero");
    assert!((pos.log() - neg.log()).amax() < 1e-15);
    assert!(max_abs_diff(&pos.matrix(), &neg.matrix()) < 1e-15);

    // Near π: w ≈ ±1e-7, both signs give angle π − 2e-7 about the same axis.
    let axis = Vector3::new(0.6, 0.0, 0.8);
    for w in [1e-7, -1e-7] {
        let s = So3::from_wxyz(w, axis.x, axis.y, axis.z).expect("unit");
        let log = s.log();
        let expected = axis * (core::f64::consts::PI - 2e-7) * w.signum();
        assert!((log - expected).amax() < 1e-13, "{log:?} vs {expected:?}");
    }

    let off = So3::from_quaternion(&(q * 1.0001 / q.norm())).expect("slightly off is handled");
    assert!(max_abs_diff(&off.matrix(), &pos.matrix()) < 1e-15);
    assert!((off.quaternion().norm() - 1.0).abs() < 1e-15);
    assert!(So3::from_quaternion(&Quaternion::new(0.0, 0.0, 0.0, 0.0)).is_none());
    assert!(So3::from_wxyz(f64::NAN, 0.0, 0.0, 1.0).is_none());
    assert!(So3::<f32>::from_wxyz(0.0, f32::INFINITY, 0.0, 0.0).is_none());
}

/// Accepts a rotation with 1e-6 error and projects it; rejects reflections, non-finite matrices
/// and matrices farther than the documented tolerance.
#[test]
fn try_from_matrix_accepts_and_rejects() {
    let r = So3::exp(&Vector3::new(0.2, 2.9, -0.4)).matrix();
    let noisy = r + Matrix3::new(1e-6, -2e-6, 0.0, 0.5e-6, 1e-6, -1e-6, 0.0, 2e-6, -1e-6);
    let proj = So3::try_from_matrix(&noisy).expect("1e-6 off is near the group");
    assert!(max_abs_diff(&proj.matrix(), &r) < 1e-5);
    assert!(((proj.matrix().transpose() * proj.matrix()) - Matrix3::identity()).amax() < 1e-15);
    // Near π, Shepperd's branch keeps full precision.
    let near_pi = So3::exp(&(Vector3::new(0.0, 0.6, 0.8) * (core::f64::consts::PI - 1e-6)));
    let back = So3::try_from_matrix(&near_pi.matrix()).expect("rotation");
    assert!((back.log() - near_pi.log()).amax() < 1e-12);

    let reflect = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    assert!(So3::try_from_matrix(&reflect).is_none(), "det < 0");
    assert!(So3::try_from_matrix(&(r * 1.01)).is_none(), "scaled");
    let tol = ORTHOGONALITY_TOLERANCE;
    assert!(So3::try_from_matrix(&(r * (1.0 + 2.0 * tol))).is_none());
    let mut nan = r;
    nan[(1, 2)] = f64::NAN;
    assert!(So3::try_from_matrix(&nan).is_none());
    for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::MAX] {
        let mut m = r;
        m[(0, 0)] = bad;
        assert!(So3::try_from_matrix(&m).is_none(), "{bad}");
    }
    assert!(So3::try_from_matrix(&Matrix3::<f64>::zeros()).is_none());

    let r2 = So2::from_angle(0.7).matrix();
    assert!(So2::try_from_matrix(&(r2 + Matrix2::new(1e-6, 0.0, 0.0, -1e-6))).is_some());
    assert!(So2::try_from_matrix(&Matrix2::new(1.0, 0.0, 0.0, -1.0)).is_none());

    let mut h = Se3::exp(&Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3)).matrix();
    assert!(Se3::try_from_matrix(&h).is_some());
    h[(3, 0)] = 0.5;
    assert!(Se3::try_from_matrix(&h).is_none(), "bottom row");
    let mut h = Matrix4::identity();
    h[(0, 3)] = f64::INFINITY;
    assert!(Se3::try_from_matrix(&h).is_none(), "non-finite translation");
    let mut h2 = Se2::new(1.0, 2.0, 0.3).matrix();
    assert!(Se2::try_from_matrix(&h2).is_some());
    h2[(2, 2)] = 2.0;
    assert!(Se2::try_from_matrix(&h2).is_none());
}

/// Non-finite tangents and points give non-finite results, never a panic, in both precisions.
#[test]
fn non_finite_inputs_propagate() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let w = Vector3::new(bad, 0.0, 0.1);
        assert!(!So3::exp(&w).is_finite());
        let (e, j) = So3::exp_jac(&w);
        assert!(!e.is_finite() || j.iter().any(|x| !x.is_finite()));
        assert!(!Se3::exp(&Vector6::new(0.0, 0.0, 0.0, bad, 0.0, 0.0)).is_finite());
        assert!(!Se2::exp(&Vector3::new(0.0, 0.0, bad)).is_finite());
        assert!(!So2::exp(&Vector1::new(bad)).is_finite());
        let p = Vector3::new(bad, 1.0, 2.0);
        let r = So3::exp(&Vector3::new(0.1, 0.2, 0.3));
        assert!(r.act(&p).iter().any(|x| !x.is_finite()));
        let _ = r.act_jac(&p);
        let _ = Se2::new(0.0, 0.0, 0.1).act_jac(&Vector2::new(bad, 0.0));
        let _ = Se3::right_jacobian_inv(&Vector6::new(bad, 0.0, 0.0, 0.0, bad, 0.0));
        let _ = So3::<f32>::exp(&Vector3::new(bad as f32, 0.0, 0.0)).log();
    }
}

/// The SE(2) logarithm near ±π uses the non-cancelling branch of `(ω/2)cot(ω/2)`.
#[test]
fn se2_log_near_pi() {
    let pi = core::f64::consts::PI;
    for gap in [1e-9, 1e-6, 1e-3] {
        for sign in [1.0, -1.0] {
            let tau = Vector3::new(0.7, -1.2, sign * (pi - gap));
            let back = Se2::exp(&tau).log();
            assert!((back - tau).amax() < 1e-14, "{tau:?} → {back:?}");
        }
    }
}

/// `renormalize` (one Newton step, no square root) takes a norm error ε to about ¾ε².
#[test]
fn renormalize_is_quadratic() {
    for eps in [1e-3, 1e-5, -1e-4, 1e-7] {
        let q = Quaternion::new(0.3, -0.5, 0.7, 0.1);
        let q = q * (1.0f64 + eps).sqrt() / q.norm();
        let r = So3::from_unit_quaternion(nalgebra::UnitQuaternion::new_unchecked(q)).renormalize();
        let err = r.quaternion().norm_squared() - 1.0;
        assert!(
            err.abs() <= 0.75 * eps * eps * 1.01 + 4.0 * f64::EPSILON,
            "{eps}: {err}"
        );
        let dir = r.quaternion().coords.normalize() - q.coords.normalize();
        assert!(dir.amax() < 4.0 * f64::EPSILON, "direction unchanged");
    }
    // f32: a product of unit quaternions comes back unit to rounding.
    let a = So3::<f32>::exp(&Vector3::new(0.3, -1.2, 0.4));
    let b = So3::<f32>::exp(&Vector3::new(-2.0, 0.1, 0.9));
    let r = a.compose(&b).renormalize();
    assert!((r.quaternion().norm_squared() - 1.0).abs() <= 4.0 * f32::EPSILON);
}

/// Deterministic numbers in `[-1, 1)` (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64) / ((1u64 << 52) as f64) - 1.0
    }
}

/// `γ_k = kε/(1 − kε)`.
fn gamma(k: f64, eps: f64) -> f64 {
    k * eps / (1.0 - k * eps)
}

/// `max |a − b|` over the entries, in `f64`.
fn max_diff<T: Real, const R: usize, const C: usize>(
    a: &SMatrix<T, R, C>,
    b: &SMatrix<f64, R, C>,
) -> f64 {
    a.iter()
        .zip(b.iter())
        .fold(0.0, |m, (x, y)| m.max((x.to_f64() - y).abs()))
}

/// `try_from_matrix` recovers a rotation matrix in each of the four branches of Shepperd's
/// method (the largest of `w, x, y, z` taken by the square root): angles from 0 to π about each
/// axis and random axes. The quaternion has a relative error of a few `ε` (a square root, one
/// division by `s ≥ 1`, a normalization), and each entry of its matrix adds `γ₄`: `16ε`.
/// Matrices within the tolerance are projected onto SO(3) (orthogonal to `8ε`); matrices far
/// from it are refused.
fn shepperd_branches<T: Real>() {
    let eps = T::EPSILON_F64;
    let mut rng = Lcg(7);
    let mut branch = [0usize; 4];
    for i in 0..400 {
        let axis = match i % 4 {
            0 => Vector3::x(),
            1 => Vector3::y(),
            2 => Vector3::z(),
            _ => Vector3::new(rng.next(), rng.next(), rng.next()).normalize(),
        };
        let angle = core::f64::consts::PI * (1.0 - (f64::from(i) / 400.0).powi(3));
        let r = *UnitQuaternion::from_scaled_axis(axis * angle)
            .to_rotation_matrix()
            .matrix();
        let m = r.map(T::lit);
        let back = So3::try_from_matrix(&m).expect("a rotation matrix is accepted");
        let m64 = m.map(|x| x.to_f64());
        assert!(max_diff(&back.matrix(), &m64) <= 16.0 * eps, "{i}: {m64}");
        let q = back.quaternion().coords;
        let largest = (0..4)
            .max_by(|&a, &b| q[a].abs().partial_cmp(&q[b].abs()).expect("finite"))
            .unwrap_or(0);
        if let Some(n) = branch.get_mut(largest) {
            *n += 1;
        }
        // A perturbation below the tolerance is projected onto the group.
        let noisy = r.map(|x| T::lit(x + 1e-4 * rng.next()));
        let p = So3::try_from_matrix(&noisy).expect("1e-4 off is near the group");
        let pm = p.matrix();
        let orth = (pm.transpose() * pm).map(|x| x.to_f64());
        assert!(max_diff(&orth.map(T::lit), &Matrix3::identity()) <= 8.0 * eps);
        assert!(max_diff(&pm, &r) <= 1e-3);
        // An arbitrary matrix is far from SO(3) (`‖mᵀm − I‖_F` well above the tolerance).
        let any = Matrix3::from_fn(|_, _| rng.next());
        let err = (any.transpose() * any - Matrix3::identity()).norm();
        if err > 2.0 * ORTHOGONALITY_TOLERANCE {
            assert!(So3::try_from_matrix(&any.map(T::lit)).is_none(), "{any}");
        }
    }
    // Storage order [x, y, z, w]: every branch was taken.
    assert!(branch.iter().all(|&n| n > 20), "{branch:?}");
}

#[test]
fn try_from_matrix_recovers_rotations_in_every_shepperd_branch() {
    shepperd_branches::<f32>();
    shepperd_branches::<f64>();
}

/// `Σ_k (−1)^k θ^{2k} / (2k + j)!`: the series of `(1 − cos θ)/θ²` (`j = 2`), `(θ − sin θ)/θ³`
/// (`j = 3`) and `(θ²/2 + cos θ − 1)/θ⁴` (`j = 4`), summed in `f64` to convergence for `θ ≤ π`.
fn series(theta: f64, j: u32) -> f64 {
    let x = theta * theta;
    let mut term = 1.0 / (1..=j).map(f64::from).product::<f64>();
    let mut sum = 0.0;
    for k in 0..40 {
        sum += term;
        let n = f64::from(2 * k + j);
        term *= -x / ((n + 1.0) * (n + 2.0));
    }
    sum
}

/// `(2θ − 3 sin θ + θ cos θ)/(2θ⁵) = ½ Σ_{n≥2} (−1)^n (2n − 2) θ^{2n−4}/(2n + 1)!`.
fn series_g(theta: f64) -> f64 {
    let x = theta * theta;
    let mut sum = 0.0;
    let mut power = 1.0; // θ^{2n−4}
    let mut fact: f64 = (1..=5).map(f64::from).product(); // (2n + 1)!
    for n in 2..40 {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        sum += sign * f64::from(2 * n - 2) * power / fact;
        power *= x;
        fact *= f64::from((2 * n + 2) * (2 * n + 3));
    }
    0.5 * sum
}

/// `J_r(ξ) = [[J_r(ω), Q(−v, −ω)], [0, J_r(ω)]]` in `f64` with Barfoot's `Q` as printed
/// (*State Estimation for Robotics*, eq. 7.86, `V = [v]×`, `W = [ω]×`):
///
/// ```text
/// Q(v, ω) = ½V + (θ − sin θ)/θ³ (WV + VW + WVW) + (θ²/2 + cos θ − 1)/θ⁴ (W²V + VW² − 3WVW)
///         + (2θ − 3 sin θ + θ cos θ)/(2θ⁵) (WVW² + W²VW)
/// ```
///
/// and `J_r(ω) = I − (1 − cos θ)/θ² W + (θ − sin θ)/θ³ W²`. Returns the matrix and the sum of
/// the magnitudes of its terms (entrywise), the scale of its rounding error.
fn se3_jr_reference(xi: &Vector6<f64>) -> (Matrix6<f64>, Matrix6<f64>) {
    let (v, w) = (xi.fixed_rows::<3>(0), xi.fixed_rows::<3>(3));
    let theta = w.norm();
    let (b, c, e, g) = (
        series(theta, 2),
        series(theta, 3),
        series(theta, 4),
        series_g(theta),
    );
    let (vm, wm) = (-skew(&v.into_owned()), -skew(&w.into_owned())); // Q(−v, −ω)
    let (va, wa) = (vm.abs(), wm.abs());
    let q = vm * 0.5
        + (wm * vm + vm * wm + wm * vm * wm) * c
        + (wm * wm * vm + vm * wm * wm - wm * vm * wm * 3.0) * e
        + (wm * vm * wm * wm + wm * wm * vm * wm) * g;
    let q_size = va * 0.5
        + (wa * va + va * wa + wa * va * wa) * c.abs()
        + (wa * wa * va + va * wa * wa + wa * va * wa * 3.0) * e.abs()
        + (wa * va * wa * wa + wa * wa * va * wa) * g.abs();
    let wr = skew(&w.into_owned());
    let jr = Matrix3::identity() - wr * b + wr * wr * c;
    let jr_size = Matrix3::identity() + wr.abs() * b + wr.abs() * wr.abs() * c;
    let block = |d: &Matrix3<f64>, u: &Matrix3<f64>| {
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(d);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(u);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(d);
        m
    };
    (block(&jr, &q), block(&jr_size, &q_size))
}

/// SE(3)'s `J_r(ξ)` and `J_l(ξ) = J_r(−ξ)` (closed-form `Q`, no matrix product) against
/// [`se3_jr_reference`], at angles from the series range to near π. Each side errs by a few
/// `γ_k` of the magnitudes of its terms (products of up to four 3×3 matrices, `γ₁₂` each, and
/// coefficients to a few `ε`): `64ε` times the reference's term sum.
fn se3_jacobians_against_barfoot<T: Real>() {
    let eps = T::EPSILON_F64;
    let mut rng = Lcg(23);
    for scale in [1e-6, 1e-3, 0.1, 0.5, 1.0, 2.0, 3.1] {
        for _ in 0..50 {
            let dir = Vector3::new(rng.next(), rng.next(), rng.next()).normalize();
            let w = dir * scale;
            let v = Vector3::new(rng.next(), rng.next(), rng.next()) * 2.0;
            let xi = Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z).map(T::lit);
            let xi64 = xi.map(|x| x.to_f64());
            for (got, at) in [
                (Se3::right_jacobian(&xi), xi64),
                (Se3::left_jacobian(&xi), -xi64),
            ] {
                let (want, size) = se3_jr_reference(&at);
                let err = max_diff(&got, &want);
                let bound = 64.0 * eps * size.amax();
                assert!(
                    err <= bound,
                    "ξ = {at:?}: {err:e} > {bound:e}\n{got}\n{want}"
                );
            }
        }
    }
}

#[test]
fn se3_jacobians_match_barfoot_q_with_matrix_products() {
    se3_jacobians_against_barfoot::<f32>();
    se3_jacobians_against_barfoot::<f64>();
}

/// SO(3): `J_l(ω) = J_r(−ω) = J_r(ω)ᵀ` and `J_l⁻¹(ω) = J_r⁻¹(ω)ᵀ` (`[−ω]× = [ω]×ᵀ`,
/// `[ω]×²` symmetric), and `rminus_jac`'s second Jacobian `−J_l⁻¹(τ) = −J_r⁻¹(τ)ᵀ`. Both sides
/// come from the same coefficients; each entry is a sum of three terms (`γ₃` of `‖J‖`).
fn so3_left_is_transposed_right<T: Real>() {
    let eps = T::EPSILON_F64;
    let mut rng = Lcg(37);
    for scale in [1e-6, 1e-2, 1.0, 3.0, 10.0] {
        for _ in 0..50 {
            let w = Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(scale * x));
            let pairs = [
                (So3::left_jacobian(&w), So3::right_jacobian(&w).transpose()),
                (
                    So3::left_jacobian_inv(&w),
                    So3::right_jacobian_inv(&w).transpose(),
                ),
            ];
            for (l, rt) in pairs {
                let rt64 = rt.map(|x| x.to_f64());
                let bound = 2.0 * gamma(3.0, eps) * rt64.amax().max(1.0);
                assert!(max_diff(&l, &rt64) <= bound, "{w:?}");
            }
            let a = So3::exp(&w);
            let b = So3::exp(&(w * T::lit(-0.4)));
            let (tau, ja, jb) = a.rminus_jac(&b);
            let jr_inv = So3::right_jacobian_inv(&tau);
            let want = (-jr_inv.transpose()).map(|x| x.to_f64());
            let bound = 2.0 * gamma(3.0, eps) * want.amax().max(1.0);
            assert!(max_diff(&jb, &want) <= bound);
            assert!(max_diff(&ja, &jr_inv.map(|x| x.to_f64())) <= bound);
        }
    }
}

#[test]
fn so3_left_jacobians_are_the_transposed_right_ones() {
    so3_left_is_transposed_right::<f32>();
    so3_left_is_transposed_right::<f64>();
}

/// SE(3)'s adjoint is `[[R, [t]×R], [0, R]]`: against the block formula with nalgebra's
/// product, entrywise within `2γ₃ (|[t]×|·|R|)` (each entry of `[t]×R` a sum of three
/// products on either side).
fn se3_adjoint_blocks<T: Real>() {
    let eps = T::EPSILON_F64;
    let mut rng = Lcg(29);
    for _ in 0..200 {
        let xi = Vector6::from_fn(|i, _| rng.next() * if i < 3 { 5.0 } else { 3.0 }).map(T::lit);
        let a = Se3::exp(&xi);
        let r = a.rotation().matrix().map(|x| x.to_f64());
        let tx = skew(&a.translation().map(|x| x.to_f64()));
        let ad = a.adjoint();
        let upper = tx * r;
        let bound = (tx.abs() * r.abs()) * (2.0 * gamma(3.0, eps));
        for i in 0..3 {
            for j in 0..3 {
                let got = |r0, c0| ad[(r0 + i, c0 + j)].to_f64();
                assert_eq!(got(0, 0), r[(i, j)]);
                assert_eq!(got(3, 3), r[(i, j)]);
                assert_eq!(got(3, 0), 0.0);
                assert!((got(0, 3) - upper[(i, j)]).abs() <= bound[(i, j)]);
            }
        }
    }
}

#[test]
fn se3_adjoint_is_its_block_formula() {
    se3_adjoint_blocks::<f32>();
    se3_adjoint_blocks::<f64>();
}

/// `∂(a·b)/∂b` and `∂(a⁻¹·b)/∂b` are exactly the identity (the right perturbation of `b`
/// passes through unchanged).
fn identity_jacobians<G, const N: usize, const D: usize, const M: usize>(a: &G, b: &G)
where
    G: MatrixLieGroup<f64, N, D, M>,
{
    let id = SMatrix::<f64, N, N>::identity();
    assert_eq!(a.compose_jac(b).2, id);
    assert_eq!(a.between_jac(b).2, id);
    assert_eq!(a.between_jac(&G::identity()).2, id);
}

#[test]
fn jacobians_with_respect_to_b_are_the_identity() {
    identity_jacobians::<So2<f64>, 1, 2, 2>(&So2::from_angle(0.3), &So2::from_angle(-2.0));
    identity_jacobians::<Se2<f64>, 3, 2, 3>(&Se2::new(0.5, -2.0, 2.0), &Se2::new(-1.5, 0.25, -2.8));
    let (a, b) = (
        So3::exp(&Vector3::new(0.3, -0.2, 1.1)),
        So3::exp(&Vector3::new(-1.0, 0.4, 0.2)),
    );
    identity_jacobians::<So3<f64>, 3, 3, 3>(&a, &b);
    identity_jacobians::<Se3<f64>, 6, 3, 4>(
        &Se3::from_parts(a, Vector3::new(1.0, 2.0, -3.0)),
        &Se3::exp(&Vector6::new(0.1, 2.0, -1.0, 0.4, -2.5, 0.9)),
    );
}

/// A NaN or infinite entry anywhere is refused by every `try_from_matrix` (in the rotation block
/// through the orthogonality error, in the translation by the finiteness test), and `is_finite`
/// tells a non-finite element from a finite one.
#[test]
fn non_finite_entries_are_refused() {
    let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
    let r2 = So2::from_angle(0.7).matrix();
    let h2 = Se2::new(1.0, 2.0, 0.3).matrix();
    let h3 = Se3::exp(&Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3)).matrix();
    for x in bad {
        for k in 0..4 {
            let mut m = r2;
            m[k] = x;
            assert!(So2::try_from_matrix(&m).is_none(), "{m}");
        }
        for k in [(0, 2), (1, 2)] {
            let mut m = h2;
            m[k] = x;
            assert!(Se2::try_from_matrix(&m).is_none(), "{m}");
        }
        for k in [(0, 3), (1, 3), (2, 3), (1, 1)] {
            let mut m = h3;
            m[k] = x;
            assert!(Se3::try_from_matrix(&m).is_none(), "{m}");
        }
        assert!(!So2::from_angle(x).is_finite());
        assert!(!Se2::from_parts(So2::from_angle(0.3), Vector2::new(x, 0.0)).is_finite());
        let r = So3::exp(&Vector3::new(0.1, 0.2, 0.3));
        assert!(!Se3::from_parts(r, Vector3::new(0.0, x, 0.0)).is_finite());
    }
    assert!(So2::from_angle(0.3).is_finite());
    assert!(Se2::new(1.0, 2.0, 0.3).is_finite());
}

/// `So3::from_quaternion` accepts any non-zero finite quaternion, as its docs promise: also
/// those whose squared norm overflows or underflows (found by fuzzing).
#[test]
fn so3_from_quaternion_takes_huge_and_tiny_quaternions() {
    use nalgebra::Quaternion;
    for (w, x) in [
        (1e154, 1e154),
        (1e-170, 1e-170),
        (f64::MAX, f64::MAX),
        (5e-324, 0.0),
    ] {
        let r = So3::from_quaternion(&Quaternion::new(w, x, 0.0, 0.0)).expect("finite, non-zero");
        let q = r.quaternion();
        let expected = if x == 0.0 {
            (1.0, 0.0)
        } else {
            (0.5f64.sqrt(), 0.5f64.sqrt())
        };
        assert!(
            (q.w - expected.0).abs() < 1e-15 && (q.i - expected.1).abs() < 1e-15,
            "{q:?}"
        );
    }
    let r = So3::from_quaternion(&Quaternion::new(1e20f32, 1e20, 0.0, 0.0)).expect("f32");
    assert!((r.quaternion().w - 0.5f32.sqrt()).abs() < 1e-7);
    assert!(So3::from_quaternion(&Quaternion::new(0.0f64, 0.0, 0.0, 0.0)).is_none());
    assert!(So3::from_quaternion(&Quaternion::new(f64::NAN, 1.0, 0.0, 0.0)).is_none());
    assert!(So3::from_quaternion(&Quaternion::new(f64::INFINITY, 1.0, 0.0, 0.0)).is_none());
}

/// `So3::exp` of a finite but huge rotation vector is a rotation about the same axis (a unit
/// quaternion), not NaN: `‖ω‖²` overflows from 1e155 (f64) and 1e20 (f32).
#[test]
fn so3_exp_of_huge_vectors_is_a_rotation() {
    for w in [
        Vector3::new(1e155, 0.0, 0.0),
        Vector3::new(-3e200, 4e200, 0.0),
        Vector3::new(f64::MAX, f64::MAX, f64::MAX),
    ] {
        let q = So3::exp(&w).quaternion();
        assert!(q.coords.iter().all(|c| c.is_finite()), "{w:?} -> {q:?}");
        assert!((q.coords.norm() - 1.0).abs() < 1e-12);
        // The vector part lies along the axis.
        let axis = w / w.amax();
        assert!(q.vector().cross(&axis).norm() < 1e-9 * axis.norm());
    }
    let q = So3::exp(&Vector3::new(0.0f32, 1e20, 0.0)).quaternion();
    assert!(q.coords.iter().all(|c| c.is_finite()) && (q.coords.norm() - 1.0).abs() < 1e-6);
    assert!(q.i == 0.0 && q.k == 0.0);
}

/// A rotation vector whose `‖ω‖²` overflows (`θ = 1e200` in `f64`): `exp`, `exp_jac` and
/// `right_jacobian` are finite, `exp_jac`'s rotation is `exp`'s, and `J_r` is its limit
/// `I + [u]×² = u uᵀ` up to the `O(1/θ)` terms (`(1 − cos θ)/θ`, `sin θ/θ`), here below 1e-199.
/// On both sides of the overflow (`θ = 1e153`, whose `θ²` is finite, and `1e155`) the Jacobian
/// is that limit within the same `O(1/θ)`.
#[test]
fn so3_huge_rotation_vectors_give_finite_limits() {
    let u = Vector3::new(2.0, -3.0, 6.0) / 7.0;
    for theta in [1e153, 1e155, 1e200, 1e308] {
        let w = u * theta;
        let (r, jr) = So3::<f64>::exp_jac(&w);
        assert!(
            r.is_finite() && jr.iter().all(|x: &f64| x.is_finite()),
            "θ = {theta}"
        );
        assert_eq!(r, So3::exp(&w));
        assert_eq!(jr, So3::right_jacobian(&w));
        let limit = u * u.transpose();
        assert!(max_abs_diff(&jr, &limit) < 1e-12, "θ = {theta}: {jr}");
    }
    let w = Vector3::new(1e20_f32, 0.0, 0.0);
    let (r, jr) = So3::<f32>::exp_jac(&w);
    assert!(r.is_finite() && jr.iter().all(|x: &f32| x.is_finite()));
    assert!((jr - Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)).amax() < 1e-6);
}

/// SE(3) with a huge rotation part: `exp`'s translation is `J_l(ω) v → (u·v) u` (the part of
/// `v` along the axis; the rest is divided by `θ`), `exp_jac` and `right_jacobian` are finite
/// and agree with each other, and both sides of the overflow agree to `O(1/θ)`.
#[test]
fn se3_huge_rotation_vectors_give_finite_limits() {
    let u = Vector3::new(2.0, -3.0, 6.0) / 7.0;
    let v = Vector3::new(1.0, 2.0, -0.5);
    let mut jacobians = Vec::new();
    for theta in [1e153, 1e155, 1e200] {
        let w = u * theta;
        let xi = Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z);
        let (t, j) = Se3::<f64>::exp_jac(&xi);
        assert!(
            t.is_finite() && j.iter().all(|x: &f64| x.is_finite()),
            "θ = {theta}"
        );
        assert_eq!(t, Se3::exp(&xi));
        assert_eq!(j, Se3::right_jacobian(&xi));
        let along = u * u.dot(&v);
        assert!((t.translation() - along).amax() < 1e-12, "θ = {theta}");
        jacobians.push(j);
    }
    assert!(max_abs_diff(&jacobians[0], &jacobians[1]) < 1e-12);
    assert!(max_abs_diff(&jacobians[1], &jacobians[2]) < 1e-12);
    let xi = Vector6::new(1.0_f32, 1.0, 1.0, 1e20, 0.0, 0.0);
    let (t, j) = Se3::<f32>::exp_jac(&xi);
    assert!(t.is_finite() && j.iter().all(|x: &f32| x.is_finite()));
    // ‖ω‖² is finite (1.5e38) but ω×(ω×v) is not: the fuzzer's input.
    let xi = Vector6::new(
        99.725334_f32,
        2812.3904,
        -0.9869688,
        0.007411765,
        -9.218709e18,
        -8.0297587e18,
    );
    let (t, j) = Se3::<f32>::exp_jac(&xi);
    assert!(t.is_finite() && j.iter().all(|x: &f32| x.is_finite()));
    assert_eq!(t, Se3::exp(&xi));
}

/// SE(2) with an angle whose square overflows: `exp` is a rotation (unit `(cos, sin)`) with a
/// translation of order `1/ω`, `exp_jac` and `right_jacobian` are finite, and both sides of the
/// overflow agree.
#[test]
fn se2_huge_angles_give_finite_results() {
    for w in [1e150, 1e160, -1e200] {
        let tau = Vector3::new(1.0, 1.0, w);
        let (t, j) = Se2::<f64>::exp_jac(&tau);
        assert!(
            t.is_finite() && j.iter().all(|x: &f64| x.is_finite()),
            "ω = {w}"
        );
        assert_eq!(t, Se2::exp(&tau));
        assert_eq!(j, Se2::right_jacobian(&tau));
        let r = t.rotation();
        assert!((r.cos() * r.cos() + r.sin() * r.sin() - 1.0).abs() < 4.0 * f64::EPSILON);
        assert!(t.translation().amax() < 1e-140, "ω = {w}");
    }
    let (t, j) = Se2::<f32>::exp_jac(&Vector3::new(1.0, 1.0, 1e20));
    assert!(t.is_finite() && j.iter().all(|x: &f32| x.is_finite()));
}

/// `So2::from_cos_sin` takes any non-zero finite pair, however large or small: it divides by
/// the larger magnitude before it normalizes. Zero and non-finite pairs are `None`.
#[test]
fn so2_from_cos_sin_takes_extreme_magnitudes() {
    for (re, im) in [(1e200, 0.0), (1e-200, 0.0), (0.0, 5e-324), (-1e308, 1e308)] {
        let r = So2::<f64>::from_cos_sin(re, im).expect("a finite non-zero pair");
        let n = (re / re.abs().max(im.abs()), im / re.abs().max(im.abs()));
        let norm = (n.0 * n.0 + n.1 * n.1).sqrt();
        assert!(
            (r.cos() - n.0 / norm).abs() <= 2.0 * f64::EPSILON,
            "({re}, {im})"
        );
        assert!(
            (r.sin() - n.1 / norm).abs() <= 2.0 * f64::EPSILON,
            "({re}, {im})"
        );
    }
    assert!(So2::<f32>::from_cos_sin(1e30, 0.0).is_some());
    assert!(So2::<f32>::from_cos_sin(1e-30, 0.0).is_some());
    for (re, im) in [
        (0.0, 0.0),
        (f64::NAN, 1.0),
        (1.0, f64::NAN),
        (f64::INFINITY, 0.0),
    ] {
        assert!(So2::<f64>::from_cos_sin(re, im).is_none(), "({re}, {im})");
    }
}

//! Group-specific checks that the generic battery cannot express: the seed's Example 5.2 in
//! closed form, agreement with nalgebra's own SO(3), quaternion sign and norm handling,
//! `try_from_matrix` acceptance and rejection, and non-finite inputs.

use estimator_core::lie::{skew, LieGroup, Se2, Se3, So2, So3, ORTHOGONALITY_TOLERANCE};
use nalgebra::{
    Matrix2, Matrix3, Matrix4, Quaternion, Rotation3, UnitQuaternion, Vector1, Vector2, Vector3,
    Vector6,
};

fn max_abs_diff<const R: usize, const C: usize>(
    a: &nalgebra::SMatrix<f64, R, C>,
    b: &nalgebra::SMatrix<f64, R, C>,
) -> f64 {
    (a - b).amax()
}

/// Seed Example 5.2: the generators of so(3), `H(p) = Σ_k Gₖ pᵏ = [−p]×`, and
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

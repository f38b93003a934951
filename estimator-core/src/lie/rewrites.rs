//! The size-driven rewrites (scalar forms, one-path Shepperd, shared helpers) against the
//! straightforward nalgebra expressions they replace: the same bits, `f32` and `f64`.

use super::trig::AngleCoeffs;
use super::*;
use crate::test_support::{every_class, same_up_to_zero_sign as same, Lcg};
use nalgebra::{Matrix2, Quaternion, UnitQuaternion, Vector2};

/// Rotation matrices of every Shepperd branch (angles up to and at π about each axis and
/// random axes), perturbed ones, and arbitrary matrices.
fn for_each_matrix<T: Real>(mut f: impl FnMut(&Matrix3<T>)) {
    let mut rng = Lcg(7);
    for i in 0..400 {
        let axis = match i % 4 {
            0 => Vector3::new(1.0, 0.0, 0.0),
            1 => Vector3::new(0.0, 1.0, 0.0),
            2 => Vector3::new(0.0, 0.0, 1.0),
            _ => Vector3::new(rng.next(), rng.next(), rng.next()),
        };
        let angle = core::f64::consts::PI * (1.0 - (f64::from(i) / 400.0).powi(3));
        let r = UnitQuaternion::from_scaled_axis(axis.normalize() * angle);
        let m = *r.to_rotation_matrix().matrix();
        let noise = if i % 3 == 0 { 1e-4 } else { 0.0 };
        f(&m.map(|x| T::lit(x + noise * rng.next())));
        f(&Matrix3::from_fn(|_, _| T::lit(rng.next())));
    }
}

/// Vectors of magnitudes from `1e-6` to `100`.
fn for_each_vector<T: Real>(seed: u64, mut f: impl FnMut(&Vector3<T>)) {
    let mut rng = Lcg(seed);
    for i in 0..100 {
        let s = [1e-6, 1e-2, 1.0, 3.0, 100.0][i % 5];
        f(&Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(s * x)));
    }
}

fn for_each_quaternion<T: Real>(mut f: impl FnMut(&UnitQuaternion<T>)) {
    let mut rng = Lcg(13);
    for _ in 0..100 {
        let q = Quaternion::new(rng.next(), rng.next(), rng.next(), rng.next());
        let q = Quaternion::from(q.coords.map(T::lit));
        f(&UnitQuaternion::new_unchecked(q * (T::one() / q.norm())));
    }
}

/// The four written-out branches of Shepperd's method (before the one-path form).
fn shepperd_branches<T: Real>(m: &Matrix3<T>) -> Option<So3<T>> {
    let one = T::one();
    let quarter = T::lit(0.25);
    let trace = m.m11 + m.m22 + m.m33;
    let (w, x, y, z);
    if trace > T::zero() {
        let s = (trace + one).sqrt() * T::lit(2.0);
        w = quarter * s;
        x = (m.m32 - m.m23) / s;
        y = (m.m13 - m.m31) / s;
        z = (m.m21 - m.m12) / s;
    } else if m.m11 > m.m22 && m.m11 > m.m33 {
        let s = (one + m.m11 - m.m22 - m.m33).sqrt() * T::lit(2.0);
        w = (m.m32 - m.m23) / s;
        x = quarter * s;
        y = (m.m12 + m.m21) / s;
        z = (m.m13 + m.m31) / s;
    } else if m.m22 > m.m33 {
        let s = (one + m.m22 - m.m11 - m.m33).sqrt() * T::lit(2.0);
        w = (m.m13 - m.m31) / s;
        x = (m.m12 + m.m21) / s;
        y = quarter * s;
        z = (m.m23 + m.m32) / s;
    } else {
        let s = (one + m.m33 - m.m11 - m.m22).sqrt() * T::lit(2.0);
        w = (m.m21 - m.m12) / s;
        x = (m.m13 + m.m31) / s;
        y = (m.m23 + m.m32) / s;
        z = quarter * s;
    }
    So3::from_wxyz(w, x, y, z)
}

fn so3_try_from_matrix_before<T: Real>(m: &Matrix3<T>) -> Option<So3<T>> {
    if !all_finite(m.as_slice()) {
        return None;
    }
    let err = (m.transpose() * m - Matrix3::<T>::identity()).norm_squared();
    let tol = T::lit(ORTHOGONALITY_TOLERANCE);
    if !(err <= tol * tol && m.determinant() > T::zero()) {
        return None;
    }
    shepperd_branches(m)
}

fn so3_matrices<T: Real>() {
    let mut accepted = 0;
    let mut branch = [0usize; 4];
    for_each_matrix::<T>(|m| {
        let err = (m.transpose() * m - Matrix3::<T>::identity()).norm_squared();
        assert!(same(&[orthogonality_error(m)], &[err]));
        let m2 = m.fixed_view::<2, 2>(0, 0).into_owned();
        let err2 = (m2.transpose() * m2 - Matrix2::<T>::identity()).norm_squared();
        assert!(same(&[orthogonality_error(&m2)], &[err2]));
        let got = So3::try_from_matrix(m).map(|r| r.quaternion().coords);
        let want = so3_try_from_matrix_before(m).map(|r| r.quaternion().coords);
        assert_eq!(got.is_some(), want.is_some());
        if let (Some(g), Some(w)) = (got, want) {
            assert!(same(g.as_slice(), w.as_slice()), "{m}");
            accepted += 1;
            // Which component Shepperd took by the square root: the largest here.
            let k = g.iamax();
            if let Some(b) = branch.get_mut((k + 1) % 4) {
                *b += 1;
            }
        }
    });
    assert!(accepted > 300, "{accepted}");
    assert!(branch.iter().all(|&n| n > 20), "{branch:?}");
}

fn so3_act<T: Real>() {
    for_each_quaternion::<T>(|q| {
        let r = So3::from_unit_quaternion(*q);
        for_each_vector::<T>(17, |p| {
            assert!(same(r.act(p).as_slice(), q.transform_vector(p).as_slice()));
            let m = r.rotation_matrix();
            let (rp, h, jp) = r.act_jac(p);
            assert!(same(rp.as_slice(), (m * p).as_slice()));
            assert!(same(h.as_slice(), mul_skew(&m, &-p).as_slice()));
            assert!(same(jp.as_slice(), m.as_slice()));
        });
    });
}

/// SE(3)'s `Q` block as it was: nalgebra vectors and an outer product.
fn q_block_before<T: Real>(k: &AngleCoeffs<T>, v: &Vector3<T>, w: &Vector3<T>) -> Matrix3<T> {
    let se = k.se();
    let dot = w.dot(v);
    let s = v * k.b - w * (dot * (k.c + se.e + se.e));
    let alpha = v * k.c + w * (T::lit(0.5) * se.f * dot);
    let g = dot * (k.c + k.c + se.f * k.theta_sq);
    let aw = alpha * w.transpose();
    aw + aw.transpose() + skew(&s) - Matrix3::from_diagonal_element(g)
}

fn upper_before<T: Real>(diag: &Matrix3<T>, upper: &Matrix3<T>) -> SMatrix<T, 6, 6> {
    let mut m = SMatrix::<T, 6, 6>::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(diag);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(upper);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(diag);
    m
}

fn split<T: Real>(xi: &SVector<T, 6>) -> (Vector3<T>, Vector3<T>) {
    (
        xi.fixed_rows::<3>(0).into_owned(),
        xi.fixed_rows::<3>(3).into_owned(),
    )
}

fn se3_jr_before<T: Real>(k: &AngleCoeffs<T>, xi: &SVector<T, 6>) -> SMatrix<T, 6, 6> {
    let (v, w) = split(xi);
    upper_before(
        &skew_poly(T::one(), -k.b, k.c, &w),
        &q_block_before(k, &-v, &-w),
    )
}

fn se3_jr_inv_before<T: Real>(k: &AngleCoeffs<T>, xi: &SVector<T, 6>) -> SMatrix<T, 6, 6> {
    let (v, w) = split(xi);
    let jinv = skew_poly(T::one(), T::lit(0.5), k.d(), &w);
    let q = q_block_before(k, &-v, &-w);
    upper_before(&jinv, &-(jinv * q * jinv))
}

fn se3_jacobians<T: Real>() {
    let mut rng = Lcg(19);
    for_each_vector::<T>(23, |v| {
        // Rotation angles from the series range to beyond π.
        let scale = [1e-5, 1e-3, 0.1, 0.5, 1.0, 2.0, 3.1, 3.2, 5.0][rng.0 as usize % 9];
        let w = Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(scale * x));
        let xi = SVector::<T, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z);
        let k = AngleCoeffs::from_theta_sq(w.norm_squared());
        let m = |a: &SMatrix<T, 6, 6>, b: &SMatrix<T, 6, 6>| same(a.as_slice(), b.as_slice());
        assert!(m(&Se3::right_jacobian(&xi), &se3_jr_before(&k, &xi)));
        assert!(m(&Se3::left_jacobian(&xi), &se3_jr_before(&k, &-xi)));
        assert!(m(
            &Se3::right_jacobian_inv(&xi),
            &se3_jr_inv_before(&k, &xi)
        ));
        assert!(m(
            &Se3::left_jacobian_inv(&xi),
            &se3_jr_inv_before(&k, &-xi)
        ));
        assert!(m(&Se3::exp_jac(&xi).1, &se3_jr_before(&k, &xi)));
        // log_jac and rminus_jac: the kernel of the logarithm's angle.
        let a = Se3::exp(&xi);
        let b = Se3::exp(&(xi * T::lit(0.3)));
        let (tau, j) = a.log_jac();
        let kl = a.rotation().log_with_coeffs().1;
        assert!(m(&j, &se3_jr_inv_before(&kl, &tau)));
        let (tau, jr, jl) = a.rminus_jac(&b);
        let kl = b.between(&a).rotation().log_with_coeffs().1;
        assert!(m(&jr, &se3_jr_inv_before(&kl, &tau)));
        assert!(m(&jl, &-se3_jr_inv_before(&kl, &-tau)));
    });
}

fn se3_adjoint_before<T: Real>(a: &Se3<T>) -> SMatrix<T, 6, 6> {
    let r = a.rotation().rotation_matrix();
    let tr = mul_skew(&r.transpose(), &-a.translation()).transpose();
    upper_before(&r, &tr)
}

fn se3_values<T: Real>() {
    let mut rng = Lcg(29);
    for_each_vector::<T>(31, |v| {
        let scale = [1e-5, 1e-3, 0.1, 1.0, 3.1, 5.0][rng.0 as usize % 6];
        let w = Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(scale * x));
        let xi = SVector::<T, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z);
        let k = AngleCoeffs::from_theta_sq(w.norm_squared());
        let a = Se3::exp(&xi);
        let wv = w.cross(v);
        let t = v + wv * k.b + w.cross(&wv) * k.c;
        assert!(same(a.translation().as_slice(), t.as_slice()));
        // log: J_l⁻¹(ω) t with the logarithm's kernel.
        let (w, kl) = a.rotation().log_with_coeffs();
        let t = a.translation();
        let wt = w.cross(&t);
        let v_log = t - wt * T::lit(0.5) + w.cross(&wt) * kl.d();
        let xi_log = a.log();
        assert!(same(&xi_log.as_slice()[..3], v_log.as_slice()));
        assert!(same(&xi_log.as_slice()[3..], w.as_slice()));
        // Adjoint, and −Ad in inverse_jac and between_jac.
        let b = Se3::exp(&(xi * T::lit(-0.7)));
        let m = |a: &SMatrix<T, 6, 6>, b: &SMatrix<T, 6, 6>| same(a.as_slice(), b.as_slice());
        assert!(m(&a.adjoint(), &se3_adjoint_before(&a)));
        assert!(m(&a.inverse_jac().1, &-se3_adjoint_before(&a)));
        let z = a.between(&b);
        assert!(m(&a.between_jac(&b).1, &-se3_adjoint_before(&z.inverse())));
        // act_jac: [R | −R[p]×], R p + t.
        let p = xi.fixed_rows::<3>(0) * T::lit(3.0);
        let r = a.rotation().rotation_matrix();
        let mut j = SMatrix::<T, 3, 6>::zeros();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        j.fixed_view_mut::<3, 3>(0, 3).copy_from(&mul_skew(&r, &-p));
        let (ap, ja, jp) = a.act_jac(&p.into_owned());
        assert!(same(ap.as_slice(), (r * p + a.translation()).as_slice()));
        assert!(same(ja.as_slice(), j.as_slice()));
        assert!(same(jp.as_slice(), r.as_slice()));
    });
}

/// `R[p]×` through the in-place kernel: the product the rewrites below are compared with.
fn mul_skew<T: Real>(r: &Matrix3<T>, p: &Vector3<T>) -> Matrix3<T> {
    let mut m = *r;
    mul_skew_in_place(&mut m, p.x, p.y, p.z);
    m
}

#[test]
fn se3_rewrites_are_bit_identical() {
    se3_values::<f32>();
    se3_values::<f64>();
    se3_jacobians::<f32>();
    se3_jacobians::<f64>();
}

fn so3_jacobians<T: Real>() {
    let m = |a: &Matrix3<T>, b: &Matrix3<T>| same(a.as_slice(), b.as_slice());
    for_each_vector::<T>(37, |w| {
        let jr = So3::right_jacobian(w);
        let jr_inv = So3::right_jacobian_inv(w);
        assert!(m(&So3::left_jacobian(w), &jr.transpose()));
        assert!(m(&So3::left_jacobian_inv(w), &jr_inv.transpose()));
        // Through jr_at / jr_inv_at (σ = ±1): the skew_poly forms they replace, to the bit.
        let k = AngleCoeffs::of_vector(w);
        let (b, c, d, h) = (k.b, k.c, k.d(), T::lit(0.5));
        let bits = |a: &Matrix3<T>, b: &Matrix3<T>| {
            crate::test_support::same_bits(a.as_slice(), b.as_slice())
        };
        assert!(bits(&jr, &skew_poly(T::one(), -b, c, w)));
        assert!(bits(&So3::left_jacobian(w), &skew_poly(T::one(), b, c, w)));
        assert!(bits(&jr_inv, &skew_poly(T::one(), h, d, w)));
        assert!(bits(
            &So3::left_jacobian_inv(w),
            &skew_poly(T::one(), -h, d, w)
        ));
        let a = So3::exp(w);
        let b = So3::exp(&(w * T::lit(-0.4)));
        let (tau, jr, jl) = a.rminus_jac(&b);
        let k = b.between(&a).log_with_coeffs().1;
        let jr_inv_k = skew_poly(T::one(), T::lit(0.5), k.d(), &tau);
        assert!(m(&jr, &jr_inv_k));
        assert!(m(&jl, &-jr_inv_k.transpose()));
    });
}

/// SO(3)'s logarithm as it was: the principal quaternion with `v` negated when `w < 0`.
fn so3_log_before<T: Real>(q: &UnitQuaternion<T>) -> (Vector3<T>, T, T, T) {
    use super::trig::Cutoff;
    let (w, v) = if q.w < T::zero() {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let n2 = v.norm_squared();
    let n = n2.sqrt();
    let scale = if n2 < T::lit(Cutoff::<T>::ATAN_RATIO) * w * w {
        let r2 = n2 / (w * w);
        T::lit(2.0) / w * poly_loop(r2, [T::lit(1.0), T::lit(-1.0 / 3.0), T::lit(1.0 / 5.0)])
    } else {
        T::lit(2.0) * n.arctan2(w) / n
    };
    (v * scale, scale * n, n, w)
}

fn so3_log_and_normalize<T: Real>() {
    let check = |q: &UnitQuaternion<T>| {
        for q in [*q, UnitQuaternion::new_unchecked(-q.into_inner())] {
            let (w, k) = So3::from_unit_quaternion(q).log_with_coeffs();
            let (w0, theta, sin_half, cos_half) = so3_log_before(&q);
            assert!(same(w.as_slice(), w0.as_slice()));
            assert!(same(
                &[k.theta, k.sin_half, k.cos_half],
                &[theta, sin_half, cos_half]
            ));
            // from_quaternion of a scaled copy: `q · (1/‖q‖)`.
            let big = q.into_inner() * T::lit(3.5);
            let n = So3::from_quaternion(&big).map(|r| r.quaternion().into_inner());
            let want = big * (T::one() / big.coords.norm_squared().sqrt());
            assert!(n.is_some_and(|n| same(n.coords.as_slice(), want.coords.as_slice())));
        }
    };
    for_each_quaternion::<T>(check);
    for_each_vector::<T>(41, |w| check(&So3::exp(w).quaternion()));
}

/// SO(3)'s exponential written out (the opt-level-3 form), against `exp` as built (through the
/// kernel under `estimator_compact`) and `exp_jac`'s value.
fn so3_exp<T: Real>() {
    use super::trig::half_sinc;
    for_each_vector::<T>(43, |w| {
        let theta_sq = w.norm_squared();
        let theta = theta_sq.sqrt();
        let (s, c) = (theta * T::lit(0.5)).sincos();
        let v = w * half_sinc(theta_sq, theta, s);
        let want = [c, v.x, v.y, v.z];
        for got in [So3::exp(w), So3::exp_jac(w).0] {
            let q = got.quaternion();
            assert!(same(&[q.w, q.i, q.j, q.k], &want));
        }
    });
}

#[test]
fn so3_rewrites_are_bit_identical() {
    so3_exp::<f32>();
    so3_exp::<f64>();
    so3_log_and_normalize::<f32>();
    so3_log_and_normalize::<f64>();
    so3_jacobians::<f32>();
    so3_jacobians::<f64>();
    so3_matrices::<f32>();
    so3_matrices::<f64>();
    so3_act::<f32>();
    so3_act::<f64>();
}

/// SO(2)'s `try_from_matrix` as it was: a finiteness check before the orthogonality test.
fn so2_try_from_matrix_before<T: Real>(m: &Matrix2<T>) -> Option<So2<T>> {
    if !all_finite(m.as_slice()) {
        return None;
    }
    let err = (m.transpose() * m - Matrix2::<T>::identity()).norm_squared();
    let tol = T::lit(ORTHOGONALITY_TOLERANCE);
    if !(err <= tol * tol && m.determinant() > T::zero()) {
        return None;
    }
    So2::from_cos_sin(m.m11 + m.m22, m.m21 - m.m12)
}

fn so2_values<T: Real>() {
    let special = [
        T::zero(),
        T::one(),
        T::lit(f64::NAN),
        T::lit(f64::INFINITY),
        T::lit(f64::NEG_INFINITY),
        T::lit(1e30),
    ];
    let mut rng = Lcg(43);
    let mut accepted = 0;
    for i in 0..600 {
        let r = So2::from_angle(T::lit(4.0 * rng.next()));
        let noise = [0.0, 1e-5, 1e-2][i % 3];
        let mut m = r.rotation_matrix().map(|x| x + T::lit(noise * rng.next()));
        if i % 5 == 4 {
            // A special value in one entry (or all four).
            let x = special[i / 5 % special.len()];
            match m.as_mut_slice().get_mut(i / 30 % 5) {
                Some(e) => *e = x,
                None => m = Matrix2::from_element(x),
            }
        }
        let got = So2::try_from_matrix(&m).map(|r| [r.cos(), r.sin()]);
        let want = so2_try_from_matrix_before(&m).map(|r| [r.cos(), r.sin()]);
        assert_eq!(got.is_some(), want.is_some(), "{m}");
        if let (Some(g), Some(w)) = (got, want) {
            assert!(same(&g, &w));
            accepted += 1;
        }
        // is_finite as it was, on finite and non-finite parts.
        for (c, s) in [(m.m11, m.m21), (m.m12, m.m22)] {
            let r = So2::from_unit(c, s);
            assert_eq!(r.is_finite(), c.is_finite() && s.is_finite());
            let t = Vector2::new(m.m22, m.m11);
            let e = Se2::from_parts(r, t);
            assert_eq!(e.is_finite(), r.is_finite() && all_finite(t.as_slice()));
        }
    }
    assert!(accepted > 200, "{accepted}");
}

fn se2_values<T: Real>() {
    let m = |a: &Matrix3<T>, b: &Matrix3<T>| same(a.as_slice(), b.as_slice());
    let mut rng = Lcg(47);
    for_each_vector::<T>(53, |tau| {
        let scale = [1e-5, 1e-3, 0.1, 1.0, 3.1, 5.0][rng.0 as usize % 6];
        let tau = Vector3::new(tau.x, tau.y, T::lit(scale * rng.next()));
        let a = Se2::exp(&tau);
        let b = Se2::exp(&(tau * T::lit(-0.6)));
        // inverse: (R⁻¹, −(R⁻¹ t)) with So2's act and nalgebra's negation.
        let r_inv = a.rotation().inverse();
        let inv = a.inverse();
        assert!(same(
            &[inv.rotation().cos(), inv.rotation().sin()],
            &[r_inv.cos(), r_inv.sin()]
        ));
        let t_inv = -r_inv.act(&a.translation());
        assert!(same(inv.translation().as_slice(), t_inv.as_slice()));
        // The Jacobians the trait's default methods gave.
        assert!(m(&a.inverse_jac().1, &-a.adjoint()));
        let z = a.between(&b);
        let (z2, j, i) = a.between_jac(&b);
        assert_eq!(z2, z);
        assert!(m(&j, &-z.inverse().adjoint()));
        assert!(m(&i, &Matrix3::identity()));
        let (t2, jr, jl) = a.rminus_jac(&b);
        let tau2 = a.rminus(&b);
        assert!(same(t2.as_slice(), tau2.as_slice()));
        assert!(m(&jr, &Se2::right_jacobian_inv(&tau2)));
        assert!(m(&jl, &-Se2::right_jacobian_inv(&-tau2)));
        // J_r⁻¹ with J_r's last column written out, as it was.
        let k = AngleCoeffs::from_theta_sq(tau.z * tau.z);
        let h = super::trig::half_cot(k.theta_sq, k.theta, k.sin_half, k.cos_half);
        let hw = T::lit(0.5) * tau.z;
        let wc = tau.z * k.c;
        let m13 = wc * tau.x - k.b * tau.y;
        let m23 = k.b * tau.x + wc * tau.y;
        let z0 = T::zero();
        let jr_inv = Matrix3::new(
            h,
            -hw,
            -(h * m13 - hw * m23),
            hw,
            h,
            -(hw * m13 + h * m23),
            z0,
            z0,
            T::one(),
        );
        assert!(m(&Se2::right_jacobian_inv(&tau), &jr_inv));
        assert!(m(&Se2::left_jacobian(&tau), &Se2::right_jacobian(&-tau)));
        assert!(m(
            &Se2::left_jacobian_inv(&tau),
            &Se2::right_jacobian_inv(&-tau)
        ));
    });
}

/// `negate` against nalgebra's `Neg`, and SO(3)'s `−Ad` in `inverse_jac` and `between_jac`.
fn negate_and_so3_adjoints<T: Real>() {
    let m = |a: &Matrix3<T>, b: &Matrix3<T>| same(a.as_slice(), b.as_slice());
    for_each_matrix::<T>(|x| {
        let mut y = *x;
        negate(&mut y);
        assert!(y
            .iter()
            .zip(x.iter())
            .all(|(a, b)| a.to_f64().to_bits() == (-*b).to_f64().to_bits()));
    });
    for_each_vector::<T>(59, |w| {
        let a = So3::exp(w);
        let b = So3::exp(&(w * T::lit(0.7) + Vector3::new(T::lit(0.3), T::zero(), T::zero())));
        let (ai, j) = a.inverse_jac();
        assert_eq!(ai, a.inverse());
        assert!(m(&j, &-a.adjoint()));
        let z = a.between(&b);
        let (z2, j, i) = a.between_jac(&b);
        assert_eq!(z2, z);
        assert!(m(&j, &-z.inverse().adjoint()));
        assert!(m(&i, &Matrix3::identity()));
    });
}

#[test]
fn so2_se2_rewrites_are_bit_identical() {
    so2_values::<f32>();
    so2_values::<f64>();
    se2_values::<f32>();
    se2_values::<f64>();
    negate_and_so3_adjoints::<f32>();
    negate_and_so3_adjoints::<f64>();
}

/// Horner's loop as `poly` had it: from `acc = 0`, `acc = acc·x + pₖ` for the last coefficient
/// first.
fn poly_loop<T: Real, const N: usize>(x: T, coeffs: [T; N]) -> T {
    let mut acc = T::zero();
    for k in coeffs.iter().rev() {
        acc = acc * x + *k;
    }
    acc
}

/// `poly` written out (three to six coefficients) against the loop, for finite `x ≥ 0` (every
/// caller's argument is a square below a cutoff), the kernel's own coefficients among them.
fn poly_unrolled<T: Real>() {
    use super::trig::poly;
    let mut rng = Lcg(47);
    let mut xs = [
        0.0, 1e-300, 1e-40, 1e-12, 1e-6, 0.01, 0.3, 1.0, 2.5, 30.0, 1e10,
    ]
    .to_vec();
    xs.extend((0..200).map(|i| (rng.next() + 1.0) * [1e-4, 0.1, 1.0, 5.0][i % 4]));
    let c: [T; 6] = [
        1.0 / 6.0,
        -1.0 / 120.0,
        1.0 / 5040.0,
        -1.0 / 362_880.0,
        0.3,
        -7.0,
    ]
    .map(T::lit);
    let [c0, c1, c2, c3, c4, _] = c;
    for x in xs.into_iter().map(T::lit) {
        let got = [
            poly(x, [c0, c1, c2]),
            poly(x, [c0, c1, c2, c3]),
            poly(x, [c0, c1, c2, c3, c4]),
            poly(x, c),
        ];
        let want = [
            poly_loop(x, [c0, c1, c2]),
            poly_loop(x, [c0, c1, c2, c3]),
            poly_loop(x, [c0, c1, c2, c3, c4]),
            poly_loop(x, c),
        ];
        assert!(same(&got, &want));
    }
}

#[test]
fn poly_is_bit_identical_to_the_loop() {
    poly_unrolled::<f32>();
    poly_unrolled::<f64>();
}

/// `positive_finite` against `is_finite() && > 0` on every class of number.
fn positive_finite_cases<T: Real>() {
    let mut xs = every_class().to_vec();
    let mut rng = Lcg(53);
    xs.extend((0..100).map(|_| rng.next() * 10f64.powf(40.0 * rng.next())));
    for x in xs.into_iter().map(T::lit) {
        assert_eq!(positive_finite(x), x.is_finite() && x > T::zero(), "{x:?}");
    }
}

#[test]
fn positive_finite_is_is_finite_and_positive() {
    positive_finite_cases::<f32>();
    positive_finite_cases::<f64>();
}

/// `eye` is nalgebra's identity, and the Jacobians that are `I` come from it.
fn eye_cases<T: Real>() {
    let (a3, b3) = (
        So3::<T>::exp(&Vector3::new(T::lit(0.3), T::lit(-0.2), T::lit(1.1))),
        So3::identity(),
    );
    assert!(same(
        eye::<T, 3>().as_slice(),
        Matrix3::<T>::identity().as_slice()
    ));
    assert!(same(
        eye::<T, 6>().as_slice(),
        SMatrix::<T, 6, 6>::identity().as_slice()
    ));
    assert!(same(
        a3.compose_jac(&b3).2.as_slice(),
        Matrix3::<T>::identity().as_slice()
    ));
    assert!(same(
        a3.between_jac(&b3).2.as_slice(),
        Matrix3::<T>::identity().as_slice()
    ));
    let a2 = Se2::<T>::new(T::lit(0.5), T::lit(-2.0), T::lit(2.0));
    assert!(same(
        a2.between_jac(&Se2::identity()).2.as_slice(),
        Matrix3::<T>::identity().as_slice()
    ));
    let a6 = Se3::<T>::from_parts(a3, Vector3::new(T::lit(1.0), T::lit(2.0), T::lit(-3.0)));
    let j = a6.between_jac(&Se3::identity()).2;
    assert!(same(
        j.as_slice(),
        SMatrix::<T, 6, 6>::identity().as_slice()
    ));
    let b2 = Se2::<T>::new(T::lit(-1.5), T::lit(0.25), T::lit(-2.8));
    let (ab2, jb2, ji2) = a2.compose_jac(&b2);
    assert!(crate::test_support::same_bits(
        ji2.as_slice(),
        Matrix3::<T>::identity().as_slice()
    ));
    assert!(same(jb2.as_slice(), b2.inverse().adjoint().as_slice()));
    assert!(ab2 == a2.compose(&b2));
    // SE(3)'s compose_jac: `I` from `eye`, `Ad_{b⁻¹}`, and the product.
    let b6 = Se3::exp(&SVector::<T, 6>::new(
        T::lit(0.1),
        T::lit(2.0),
        T::lit(-1.0),
        T::lit(0.4),
        T::lit(-2.5),
        T::lit(0.9),
    ));
    let (ab, jb, ji) = a6.compose_jac(&b6);
    assert!(crate::test_support::same_bits(
        ji.as_slice(),
        SMatrix::<T, 6, 6>::identity().as_slice()
    ));
    assert!(same(jb.as_slice(), b6.inverse().adjoint().as_slice()));
    assert!(ab == a6.compose(&b6));
}

#[test]
fn identity_jacobians_are_the_identity() {
    eye_cases::<f32>();
    eye_cases::<f64>();
}

/// `AngleCoeffs::of_vector(ω)` is `from_theta_sq(‖ω‖²)`, every field.
fn of_vector_cases<T: Real>() {
    let fields = |k: &AngleCoeffs<T>| {
        [
            k.theta_sq,
            k.theta,
            k.sin_half,
            k.cos_half,
            k.half_sinc,
            k.a,
            k.b,
            k.c,
        ]
    };
    for_each_vector::<T>(59, |w| {
        let got = AngleCoeffs::of_vector(w);
        let want = AngleCoeffs::from_theta_sq(w.norm_squared());
        assert!(same(&fields(&got), &fields(&want)));
    });
}

#[test]
fn of_vector_is_from_theta_sq_of_the_norm() {
    of_vector_cases::<f32>();
    of_vector_cases::<f64>();
}

/// SE(3)'s `hat` and `matrix` entry by entry against the block copies they replace.
fn se3_hat_cases<T: Real>() {
    for_each_vector::<T>(61, |v| {
        let w = Vector3::new(v.z, -v.x * T::lit(0.5), v.y);
        let xi = SVector::<T, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z);
        let mut want = SMatrix::<T, 4, 4>::zeros();
        want.fixed_view_mut::<3, 3>(0, 0).copy_from(&skew(&w));
        want.fixed_view_mut::<3, 1>(0, 3).copy_from(v);
        let got = Se3::hat(&xi);
        assert!(got
            .iter()
            .zip(want.iter())
            .all(|(a, b)| a.to_f64().to_bits() == b.to_f64().to_bits()));
        assert!(same(Se3::vee(&got).as_slice(), xi.as_slice()));
        // `matrix` entry by entry against the identity overwritten block by block.
        let a = Se3::exp(&xi);
        let mut want = SMatrix::<T, 4, 4>::identity();
        want.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&a.rotation().rotation_matrix());
        want.fixed_view_mut::<3, 1>(0, 3)
            .copy_from(&a.translation());
        assert!(a
            .matrix()
            .iter()
            .zip(want.iter())
            .all(|(x, y)| x.to_f64().to_bits() == y.to_f64().to_bits()));
    });
}

#[test]
fn se3_hat_is_bit_identical() {
    se3_hat_cases::<f32>();
    se3_hat_cases::<f64>();
}

/// `R(q*)` is `R(q)ᵀ` to the bit, signed zeros included (So3's `compose_jac`), for random,
/// axis-aligned and sign-flipped quaternions.
fn so3_conjugate_matrix<T: Real>() {
    let bits_eq = |a: &Matrix3<T>, b: &Matrix3<T>| {
        a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.to_f64().to_bits() == y.to_f64().to_bits())
    };
    let (o, z, h) = (
        T::one(),
        T::zero(),
        T::lit(core::f64::consts::FRAC_1_SQRT_2),
    );
    let mut qs = [
        [o, z, z, z],
        [z, o, z, z],
        [z, z, o, z],
        [z, z, z, o],
        [h, h, z, z],
        [h, z, -h, z],
        [z, h, z, h],
    ]
    .map(|c| UnitQuaternion::new_unchecked(Quaternion::new(c[0], c[1], c[2], c[3])))
    .to_vec();
    for_each_quaternion::<T>(|q| qs.push(*q));
    let a = So3::exp(&Vector3::new(T::lit(0.1), T::lit(0.2), T::lit(-0.3)));
    for q in qs {
        for q in [q, UnitQuaternion::new_unchecked(-q.into_inner())] {
            let b = So3::from_unit_quaternion(q);
            let want = b.rotation_matrix().transpose();
            assert!(bits_eq(&a.compose_jac(&b).1, &want));
        }
    }
}

#[test]
fn so3_conjugate_matrix_is_the_transpose() {
    so3_conjugate_matrix::<f32>();
    so3_conjugate_matrix::<f64>();
}

/// Special values for the per-component rewrites: signed zeros, infinities, NaN.
fn specials<T: Real>() -> [T; 7] {
    let inf = T::lit(f64::INFINITY);
    [
        T::zero(),
        -T::zero(),
        T::one(),
        -T::lit(2.5),
        inf,
        -inf,
        T::lit(f64::NAN),
    ]
}

/// Quaternions (not necessarily unit) and vectors: random ones and ones made of special values.
fn for_each_quaternion_and_vector<T: Real>(mut f: impl FnMut(&UnitQuaternion<T>, &Vector3<T>)) {
    let s = specials::<T>();
    for_each_quaternion::<T>(|q| {
        for_each_vector::<T>(47, |p| f(q, p));
        for (i, &x) in s.iter().enumerate() {
            let y = s[(i + 3) % s.len()];
            f(q, &Vector3::new(x, y, -x));
            let odd = Quaternion::new(x, q.i, y, q.k);
            f(
                &UnitQuaternion::new_unchecked(odd),
                &Vector3::new(y, T::one(), x),
            );
        }
    });
}

/// SO(3)'s conjugate, rotation, renormalization and exponential written per component, and
/// SE(3)'s `act`, `compose` and `inverse` through `act_plus`, against the nalgebra expressions
/// they replace: the same bits (signed zeros and NaN included).
fn so3_se3_per_component<T: Real>() {
    use crate::test_support::same_bits;
    for_each_quaternion_and_vector::<T>(|q, p| {
        let r = So3::from_unit_quaternion(*q);
        let qc = r.inverse().quaternion();
        assert!(same_bits(
            qc.coords.as_slice(),
            q.conjugate().coords.as_slice()
        ));
        assert!(same_bits(
            r.act(p).as_slice(),
            q.transform_vector(p).as_slice()
        ));
        let qq = q.quaternion();
        let scale = (T::lit(3.0) - qq.coords.norm_squared()) * T::lit(0.5);
        let want = *qq * scale;
        let got = r.renormalize().quaternion();
        assert!(same_bits(got.coords.as_slice(), want.coords.as_slice()));
        let k = AngleCoeffs::of_vector(p);
        let v = p * k.half_sinc;
        let e = So3::exp_from(&k, p).quaternion();
        assert!(same_bits(e.coords.as_slice(), &[v.x, v.y, v.z, k.cos_half]));
        // SE(3).
        let t = Vector3::new(p.z, p.x, p.y) * T::lit(1.5);
        let a = Se3::from_parts(r, t);
        let b = Se3::from_parts(So3::from_unit_quaternion(q.inverse()), *p);
        assert!(same_bits(
            a.act(p).as_slice(),
            (q.transform_vector(p) + t).as_slice()
        ));
        let ab = a.compose(&b);
        let want_t = q.transform_vector(p) + t;
        assert!(same_bits(ab.translation().as_slice(), want_t.as_slice()));
        assert!(same_bits(
            ab.rotation().quaternion().coords.as_slice(),
            (*q * q.inverse()).coords.as_slice()
        ));
        let ai = a.inverse();
        let want_i = -q.conjugate().transform_vector(&t);
        assert!(same_bits(ai.translation().as_slice(), want_i.as_slice()));
        // try_from_matrix: the blocks entry by entry, as `fixed_view(..).into_owned()` read them.
        let mut m = a.matrix();
        m[(0, 1)] += p.x * T::lit(1e-4);
        let got = Se3::try_from_matrix(&m);
        let want = So3::try_from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned())
            .map(|r| Se3::from_parts(r, Vector3::new(m.m14, m.m24, m.m34)))
            .filter(Se3::is_finite);
        assert_eq!(got.is_some(), want.is_some());
        if let (Some(g), Some(w)) = (got, want) {
            assert!(same_bits(
                g.translation().as_slice(),
                w.translation().as_slice()
            ));
            let (gq, wq) = (g.rotation().quaternion(), w.rotation().quaternion());
            assert!(same_bits(gq.coords.as_slice(), wq.coords.as_slice()));
        }
        let m2 = Se2::new(p.x, p.y, p.z).matrix();
        let got2 = Se2::try_from_matrix(&m2);
        let t2 = [m2.m13, m2.m23];
        let want2 = So2::try_from_matrix(&m2.fixed_view::<2, 2>(0, 0).into_owned())
            .filter(|_| all_finite(&t2));
        assert_eq!(got2.map(|g| g.rotation()), want2);
        // A non-finite translation entry alone is rejected (the `x·0` term of the bottom sum).
        for x in specials::<T>() {
            let mut m =
                Se3::from_parts(r, Vector3::new(T::one(), T::lit(2.0), T::lit(-3.0))).matrix();
            m.m24 = x;
            let rot_ok = So3::try_from_matrix(&r.rotation_matrix()).is_some();
            assert_eq!(
                Se3::try_from_matrix(&m).is_some(),
                all_finite(&[x]) && rot_ok
            );
            let mut m2 = Se2::new(T::one(), T::one(), T::lit(0.3)).matrix();
            m2.m13 = x;
            assert_eq!(Se2::try_from_matrix(&m2).is_some(), all_finite(&[x]));
        }
    });
}

#[test]
fn so3_se3_per_component_forms_are_bit_identical() {
    so3_se3_per_component::<f32>();
    so3_se3_per_component::<f64>();
}

/// SE(3)'s `mul3` (a loop over the entries when built for size) against nalgebra's `a * b`: the
/// same bits, on random matrices and ones made of signed zeros, infinities and NaN.
fn mul3_cases<T: Real>() {
    use crate::test_support::same_bits;
    let s = specials::<T>();
    let mut rng = Lcg(53);
    for n in 0..400 {
        let mut entry = |k: usize| {
            if n % 2 == 0 {
                T::lit(rng.next() * 4.0)
            } else {
                s[(n + 3 * k + k * k) % s.len()]
            }
        };
        let a = Matrix3::from_fn(|i, j| entry(3 * j + i));
        let b = Matrix3::from_fn(|i, j| entry(3 * j + i + 9));
        assert!(same_bits(
            super::se3::mul3(&a, &b).as_slice(),
            (a * b).as_slice()
        ));
    }
}

#[test]
fn mul3_is_bit_identical_to_the_product() {
    mul3_cases::<f32>();
    mul3_cases::<f64>();
}

/// `mul_skew` (now rows overwritten in place, a loop over the rows) against the written-out rows
/// it replaces, and SO(3)'s `act_jac` against `R[−p]×` built that way: the same bits, on random
/// matrices and ones made of signed zeros, infinities and NaN.
fn mul_skew_cases<T: Real>() {
    use crate::test_support::same_bits;
    let before = |r: &Matrix3<T>, p: &Vector3<T>| {
        let row = |a: T, b: T, c: T| (b * p.z - c * p.y, c * p.x - a * p.z, a * p.y - b * p.x);
        let (a1, a2, a3) = row(r.m11, r.m12, r.m13);
        let (b1, b2, b3) = row(r.m21, r.m22, r.m23);
        let (c1, c2, c3) = row(r.m31, r.m32, r.m33);
        Matrix3::new(a1, a2, a3, b1, b2, b3, c1, c2, c3)
    };
    let s = specials::<T>();
    let mut rng = Lcg(59);
    for n in 0..400 {
        let mut entry = |k: usize| {
            if n % 2 == 0 {
                T::lit(rng.next() * 4.0)
            } else {
                s[(n + 3 * k + k * k) % s.len()]
            }
        };
        let r = Matrix3::from_fn(|i, j| entry(3 * j + i));
        let p = Vector3::new(entry(9), entry(10), entry(11));
        assert!(same_bits(
            mul_skew(&r, &p).as_slice(),
            before(&r, &p).as_slice()
        ));
    }
    for_each_quaternion_and_vector::<T>(|q, p| {
        let a = So3::from_unit_quaternion(*q);
        let r = a.rotation_matrix();
        let (_, h, jp) = a.act_jac(p);
        assert!(same_bits(h.as_slice(), before(&r, &-p).as_slice()));
        assert!(same_bits(jp.as_slice(), r.as_slice()));
    });
}

#[test]
fn mul_skew_in_place_is_bit_identical() {
    mul_skew_cases::<f32>();
    mul_skew_cases::<f64>();
}

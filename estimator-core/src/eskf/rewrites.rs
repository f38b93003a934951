//! The size-driven rewrites of the filter (entry-by-entry forms, shared out-of-line checks)
//! against the straightforward nalgebra expressions they replace: the same bits (or the same
//! answer, for the checks), `f32` and `f64`.

use super::align::InitialSigmas;
use super::imu::{add33, axpy, mm, mv, ImuNoise};
use super::models::{add3, div3, dot3, neg3, norm3, sub3};
use super::state::{plus_seg, seg};
use crate::lie::{LieGroup, So3};
use crate::test_support::{same_bits as same, Lcg};
use crate::Real;
use nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3};

/// Numbers of magnitudes from `1e-6` to `1e3`, and signed zeros, infinities and NaN.
fn number<T: Real>(rng: &mut Lcg, i: usize) -> T {
    match i % 11 {
        0 => T::lit(-0.0),
        1 => T::lit(f64::INFINITY),
        2 => T::lit(f64::NAN),
        3 => T::lit(f64::NEG_INFINITY),
        k => T::lit([1e-6, 1e-2, 1.0, 3.0, 1e3, 0.0, 7.0][k - 4] * rng.next()),
    }
}

fn oplus_segments<T: Real>() {
    let mut rng = Lcg(3);
    for i in 0..200 {
        let dx = SVector::<T, 15>::from_fn(|r, _| number(&mut rng, i + r));
        let v = Vector3::<T>::from_fn(|r, _| number(&mut rng, 2 * i + r));
        for k in [0, 3, 6, 9, 12] {
            let old = dx.fixed_rows::<3>(k).into_owned();
            assert!(same(seg(&dx, k).as_slice(), old.as_slice()));
            let old = v + dx.fixed_rows::<3>(k);
            assert!(same(plus_seg(&v, &dx, k).as_slice(), old.as_slice()));
        }
        let d6 = SVector::<T, 6>::from_fn(|r, _| number(&mut rng, i + 3 * r));
        for k in [0, 3] {
            let old = v + d6.fixed_rows::<3>(k);
            assert!(same(plus_seg(&v, &d6, k).as_slice(), old.as_slice()));
        }
    }
}

fn noise_validity<T: Real>() {
    let mut rng = Lcg(5);
    for i in 0..400 {
        let n = ImuNoise {
            gyroscope_noise_density: number::<T>(&mut rng, i),
            gyroscope_random_walk: number(&mut rng, i / 3),
            accelerometer_noise_density: number(&mut rng, i / 5),
            accelerometer_random_walk: number(&mut rng, i / 7),
        };
        let old = [
            n.gyroscope_noise_density,
            n.gyroscope_random_walk,
            n.accelerometer_noise_density,
            n.accelerometer_random_walk,
        ]
        .iter()
        .all(|x| x.is_finite() && *x >= T::zero());
        assert_eq!(n.is_valid(), old);
    }
}

fn finite_check<T: Real>() {
    let mut rng = Lcg(9);
    for i in 0..400 {
        let v = Vector3::<T>::from_fn(|r, _| number(&mut rng, i / (r + 1)));
        let old = v.iter().all(|x| x.is_finite());
        assert_eq!(super::imu::finite(&v), old);
    }
}

#[test]
fn oplus_segments_are_the_row_views() {
    oplus_segments::<f32>();
    oplus_segments::<f64>();
}

#[test]
fn noise_validity_is_unchanged() {
    noise_validity::<f32>();
    noise_validity::<f64>();
}

#[test]
fn finite_is_the_iterator_check() {
    finite_check::<f32>();
    finite_check::<f64>();
}

fn vector_helpers<T: Real>() {
    let mut rng = Lcg(11);
    for i in 0..600 {
        let a = Vector3::<T>::from_fn(|r, _| number(&mut rng, i + r));
        let b = Vector3::<T>::from_fn(|r, _| number(&mut rng, i / 2 + 5 * r));
        let s = number::<T>(&mut rng, i / 3);
        assert!(same(sub3(&a, &b).as_slice(), (a - b).as_slice()));
        assert!(same(add3(&a, &b).as_slice(), (a + b).as_slice()));
        assert!(same(div3(&a, s).as_slice(), (a / s).as_slice()));
        assert!(same(neg3(&a).as_slice(), (-a).as_slice()));
        assert!(same(&[dot3(&a, &b)], &[a.dot(&b)]));
        assert!(same(&[dot3(&a, &a)], &[a.norm_squared()]));
        assert!(same(&[norm3(&a)], &[a.norm()]));
        assert!(same(div3(&neg3(&a), s).as_slice(), (-a / s).as_slice()));
        let old = a - b * b.dot(&a);
        assert!(same(axpy(&a, &b, -b.dot(&a)).as_slice(), old.as_slice()));
    }
}

fn attitude_covariance<T: Real>() {
    let mut rng = Lcg(17);
    for i in 0..400 {
        let axis = Vector3::new(rng.next(), rng.next(), rng.next());
        let q = UnitQuaternion::from_scaled_axis(axis * 3.0)
            .coords
            .map(T::lit);
        let attitude = So3::from_unit_quaternion(UnitQuaternion::new_unchecked(q.into()));
        let up = Vector3::<T>::from_fn(|r, _| number(&mut rng, i / 4 + 2 * r));
        let sigmas = InitialSigmas {
            tilt: number(&mut rng, i / 7),
            yaw: number(&mut rng, i / 5),
            ..InitialSigmas::default()
        };
        let (r, t2, y2) = (
            attitude.rotation_matrix(),
            sigmas.tilt * sigmas.tilt,
            sigmas.yaw * sigmas.yaw,
        );
        let sw = Matrix3::identity() * t2 + up * up.transpose() * (y2 - t2);
        let old = super::imu::mm(&super::imu::mm(&r.transpose(), &sw), &r);
        let new = sigmas.attitude_covariance(&attitude, &up);
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn vector_helpers_are_the_nalgebra_expressions() {
    vector_helpers::<f32>();
    vector_helpers::<f64>();
}

#[test]
fn attitude_covariance_is_the_matrix_expression() {
    attitude_covariance::<f32>();
    attitude_covariance::<f64>();
}

fn products<T: Real>() {
    let mut rng = Lcg(23);
    for i in 0..600 {
        let a = Matrix3::<T>::from_fn(|r, c| number(&mut rng, i / 3 + r + 3 * c));
        let b = Matrix3::<T>::from_fn(|r, c| number(&mut rng, i / 5 + 2 * r + c));
        let f = Vector3::<T>::from_fn(|r, _| number(&mut rng, i / 2 + r));
        let g = Vector3::<T>::from_fn(|r, _| number(&mut rng, i / 7 + 4 * r));
        assert!(same(mv(&a, &f).as_slice(), (a * f).as_slice()));
        assert!(same(
            add3(&mv(&a, &f), &g).as_slice(),
            (a * f + g).as_slice()
        ));
        assert!(same(mm(&a, &b).as_slice(), (a * b).as_slice()));
        assert!(same(add33(&a, &b).as_slice(), (a + b).as_slice()));
        let old = a * b.transpose();
        assert!(same(mm(&a, &b.transpose()).as_slice(), old.as_slice()));
        assert!(same(
            super::imu::tr33(&a).as_slice(),
            a.transpose().as_slice()
        ));
        let dt = number::<T>(&mut rng, i / 11);
        let old = a + (b + (a * b) * T::lit(0.5)) * dt;
        let new = super::imu::row_p(a, &b, &(a * b), dt);
        assert!(same(new.as_slice(), old.as_slice()));
        let old = (a + a.transpose()) * T::lit(0.5);
        assert!(same(super::imu::sym(&a).as_slice(), old.as_slice()));
        let old = Matrix3::from_columns(&[f, g, f.cross(&g)]);
        assert!(same(super::align::triad(&f, &g).as_slice(), old.as_slice()));
    }
}

#[test]
fn products_are_nalgebras() {
    products::<f32>();
    products::<f64>();
}

/// `cholesky_inverse` against `Cholesky::new(a).map(|c| c.inverse())` on `C × C` matrices:
/// symmetric positive definite ones over a wide range of scales and conditioning, symmetric
/// indefinite and singular ones, and ones with special numbers (zeros, infinities, NaN).
fn cholesky_inverse_case<T: Real, const C: usize>(seed: u64) {
    use super::update::cholesky_inverse;
    use nalgebra::{Cholesky, SMatrix};
    let mut rng = Lcg(seed);
    for i in 0..600 {
        let b = SMatrix::<T, C, C>::from_fn(|r, c| number(&mut rng, i / 2 + 3 * r + c));
        let g = SMatrix::<T, C, C>::from_fn(|_, _| T::lit(rng.next()));
        let d = T::lit([1e-6, 1e-3, 1.0, 1e3][i % 4] * (rng.next() + 1.0));
        let cases = [
            g * g.transpose() + SMatrix::identity() * d,
            g * g.transpose(),
            (b + b.transpose()) * T::lit(0.5),
            b,
            (g + g.transpose()) * T::lit(0.5),
        ];
        for a in cases {
            let old = Cholesky::new(a).map(|c| c.inverse());
            let new = cholesky_inverse(&a);
            assert_eq!(old.is_some(), new.is_some(), "{a:?}");
            if let (Some(old), Some(new)) = (old, new) {
                assert!(same(old.as_slice(), new.as_slice()), "{a:?}");
            }
        }
    }
}

#[test]
fn cholesky_inverse_is_nalgebras() {
    cholesky_inverse_case::<f32, 1>(29);
    cholesky_inverse_case::<f32, 2>(31);
    cholesky_inverse_case::<f32, 3>(37);
    cholesky_inverse_case::<f32, 4>(41);
    cholesky_inverse_case::<f64, 1>(43);
    cholesky_inverse_case::<f64, 2>(47);
    cholesky_inverse_case::<f64, 3>(53);
    cholesky_inverse_case::<f64, 6>(59);
}

/// The update's shared helpers against the per-size code they replace: the chart Jacobian
/// (`J_rᵀ · Hᵀ[0..3, ..]` through nalgebra), the Gauss-Newton step (the former per-size loops)
/// and the step length (`‖next − prev‖` through a vector difference).
fn update_helpers<T: Real, const N: usize>(seed: u64) {
    use super::update::{chart_jacobian, distance, gauss_newton_step};
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..400 {
        let dx = SVector::<T, N>::from_fn(|r, _| {
            if i % 3 == 0 {
                T::lit(rng.next())
            } else {
                number(&mut rng, i / 2 + r)
            }
        });
        let prev = SVector::<T, N>::from_fn(|r, _| number(&mut rng, i / 3 + 2 * r));
        let mut ht = SMatrix::<T, N, 3>::from_fn(|r, c| number(&mut rng, i / 5 + r + 7 * c));
        let k = SMatrix::<T, N, 3>::from_fn(|r, c| number(&mut rng, i / 7 + 3 * r + c));
        let r = SVector::<T, 3>::from_fn(|r, _| number(&mut rng, i + r));
        let m = 1 + i % 3;
        for c in m..3 {
            ht.column_mut(c).fill(T::zero());
        }

        let mut old = ht;
        let dth: SVector<T, 3> = dx.fixed_rows::<3>(0).into_owned();
        let jrt: Matrix3<T> = <So3<T> as LieGroup<T>>::right_jacobian(&dth).transpose();
        let top = jrt * old.fixed_rows::<3>(0);
        old.fixed_rows_mut::<3>(0).copy_from(&top);
        let mut new = ht;
        chart_jacobian(dx.as_slice(), new.as_mut_slice());
        assert!(same(new.as_slice(), old.as_slice()));

        let dot = |a: &[T], b: &[T]| a.iter().zip(b).fold(T::zero(), |acc, (x, y)| acc + *x * *y);
        let mut y = r;
        for (yc, hc) in y.iter_mut().zip(ht.as_slice().chunks_exact(N)).take(m) {
            *yc += dot(hc, prev.as_slice());
        }
        let mut old = SVector::<T, N>::zeros();
        for (kc, yc) in k.as_slice().chunks_exact(N).zip(y.iter()).take(m) {
            for (o, x) in old.iter_mut().zip(kc) {
                *o += *yc * *x;
            }
        }
        let mut new = SVector::<T, N>::from_element(T::lit(f64::NAN));
        gauss_newton_step(
            ht.as_slice(),
            k.as_slice(),
            &r,
            m,
            prev.as_slice(),
            new.as_mut_slice(),
        );
        assert!(same(new.as_slice(), old.as_slice()));

        let step = dx - prev;
        let old = dot(step.as_slice(), step.as_slice()).sqrt();
        let new = distance(dx.as_slice(), prev.as_slice());
        assert!(same(&[new], &[old]));
    }
}

#[test]
fn update_helpers_are_the_per_size_code() {
    update_helpers::<f32, 15>(61);
    update_helpers::<f32, 6>(67);
    update_helpers::<f64, 15>(71);
    update_helpers::<f64, 6>(73);
}

/// `mat_vec` against nalgebra's matrix-vector product (signed zeros included: no leading
/// zero term), for `K r` (`N × 3`) and `S⁻¹ r` (`3 × 3`, and other capacities).
fn mat_vec_case<T: Real, const R: usize, const C: usize>(seed: u64) {
    use super::update::mat_vec;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..600 {
        let a = SMatrix::<T, R, C>::from_fn(|r, c| number(&mut rng, i / 3 + 2 * r + c));
        let x = SVector::<T, C>::from_fn(|r, _| number(&mut rng, i / 2 + r));
        let old = a * x;
        let mut new = SVector::<T, R>::from_element(T::lit(f64::NAN));
        mat_vec(a.as_slice(), x.as_slice(), new.as_mut_slice());
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn mat_vec_is_nalgebras_product() {
    mat_vec_case::<f32, 15, 3>(79);
    mat_vec_case::<f32, 6, 3>(83);
    mat_vec_case::<f32, 3, 3>(89);
    mat_vec_case::<f32, 6, 6>(97);
    mat_vec_case::<f64, 15, 3>(101);
    mat_vec_case::<f64, 1, 1>(103);
    mat_vec_case::<f64, 4, 2>(107);
}

/// The update's checks in their compact forms against the expressions they replace:
/// `positive_finite(d)` is `d.is_finite() && d > 0` (the reset's diagonal test), and
/// `sum_times_zero_is_zero` is the fold of `is_finite` (`finite_symmetric`), on every kind of
/// number (signed zeros, subnormals, the largest finite, infinities, NaN).
fn update_checks<T: Real>() {
    use super::imu::sum_times_zero_is_zero;
    use crate::scalar::positive_finite;
    let mut rng = Lcg(109);
    let specials = [
        T::lit(0.0),
        T::lit(-0.0),
        T::lit(f64::from(f32::MIN_POSITIVE) / 4.0),
        T::lit(-f64::from(f32::MIN_POSITIVE) / 4.0),
        T::lit(f64::from(f32::MAX)),
        T::lit(-f64::from(f32::MAX)),
        T::lit(f64::MAX),
        T::lit(f64::MIN_POSITIVE / 4.0),
    ];
    for d in specials
        .iter()
        .copied()
        .chain((0..400).map(|i| number::<T>(&mut rng, i)))
    {
        assert_eq!(positive_finite(d), d.is_finite() && d > T::zero());
    }
    for i in 0..400 {
        let a: [T; 9] = core::array::from_fn(|r| {
            if (i + r) % 5 == 0 {
                number(&mut rng, i + r)
            } else {
                T::lit(rng.next() * 1e3)
            }
        });
        for len in [0, 1, 4, 9] {
            let s = a.get(..len).unwrap_or(&[]);
            let old = s.iter().fold(true, |acc, x| acc & x.is_finite());
            assert_eq!(sum_times_zero_is_zero(s), old);
        }
    }
}

#[test]
fn update_checks_are_the_plain_predicates() {
    update_checks::<f32>();
    update_checks::<f64>();
}

/// `rows_into` (`Hᵀ` read column by column of `H`) against the former copy (written column by
/// column of `Hᵀ`), for every row count of a core with capacity 3, and past-the-end padding.
fn rows_into_case<T: Real, const N: usize, const M: usize>(seed: u64) {
    use super::update::rows_into;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..100 {
        let h = SMatrix::<T, M, N>::from_fn(|r, c| number(&mut rng, i + 3 * r + c));
        let r_in = SVector::<T, M>::from_fn(|r, _| number(&mut rng, i + r));
        let (h, r_in) = (h.as_slice(), r_in.as_slice());
        let mut old_ht = SMatrix::<T, N, 3>::from_element(T::lit(f64::NAN));
        let mut old_r = SVector::<T, 3>::from_element(T::lit(f64::NAN));
        {
            let (ht, r) = (old_ht.as_mut_slice(), old_r.as_mut_slice());
            let m = r_in.len().max(1);
            let n = h.len() / m;
            ht.fill(T::zero());
            for (c, col) in ht.chunks_exact_mut(n.max(1)).enumerate().take(r_in.len()) {
                for (j, e) in col.iter_mut().enumerate() {
                    *e = h.get(j * m + c).copied().unwrap_or_else(T::zero);
                }
            }
            r.fill(T::zero());
            for (d, s) in r.iter_mut().zip(r_in) {
                *d = *s;
            }
        }
        let mut ht = SMatrix::<T, N, 3>::from_element(T::lit(f64::NAN));
        let mut r = SVector::<T, 3>::from_element(T::lit(f64::NAN));
        rows_into(h, r_in, ht.as_mut_slice(), r.as_mut_slice());
        assert!(same(ht.as_slice(), old_ht.as_slice()));
        assert!(same(r.as_slice(), old_r.as_slice()));
    }
}

#[test]
fn rows_into_is_the_former_copy() {
    rows_into_case::<f32, 15, 1>(113);
    rows_into_case::<f32, 15, 2>(127);
    rows_into_case::<f32, 15, 3>(131);
    rows_into_case::<f32, 6, 1>(137);
    rows_into_case::<f64, 6, 3>(139);
    rows_into_case::<f64, 15, 2>(149);
}

/// `nis` (over the storage slices) against `rᵀ (S⁻¹ r)` through nalgebra's product and
/// iterators, the former form.
fn nis_case<T: Real, const C: usize>(seed: u64) {
    use super::update::nis;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..400 {
        let s_inv = SMatrix::<T, C, C>::from_fn(|r, c| number(&mut rng, i / 3 + 2 * r + c));
        let r = SVector::<T, C>::from_fn(|r, _| number(&mut rng, i / 2 + r));
        let y = s_inv * r;
        let old = r
            .iter()
            .zip(y.iter())
            .fold(T::zero(), |acc, (a, b)| acc + *a * *b);
        assert!(same(&[nis(&s_inv, &r)], &[old]));
    }
}

#[test]
fn nis_is_the_former_sum() {
    nis_case::<f32, 3>(151);
    nis_case::<f32, 2>(157);
    nis_case::<f64, 3>(163);
    nis_case::<f64, 1>(167);
}

/// The gain's `symmetrize` against nalgebra's `s += sᵀ; s *= ½` on `C × C` matrices.
fn symmetrize_case<T: Real, const C: usize>(seed: u64) {
    use super::update::symmetrize;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..400 {
        let a = SMatrix::<T, C, C>::from_fn(|r, c| number(&mut rng, i / 3 + 2 * r + c));
        let mut old = a;
        let st = old.transpose();
        old += st;
        old *= T::lit(0.5);
        let mut new = a;
        symmetrize(&mut new);
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn symmetrize_is_nalgebras() {
    symmetrize_case::<f32, 3>(173);
    symmetrize_case::<f32, 2>(179);
    symmetrize_case::<f64, 3>(181);
    symmetrize_case::<f64, 4>(191);
}

/// `check_spd` (the symmetry test, then `factor_lower` on a full copy) against the former
/// recurrence on the packed lower triangle, on symmetric positive definite, indefinite, nearly
/// singular, asymmetric and non-finite `n × n` matrices.
fn check_spd_case<T: Real, const N: usize>(seed: u64) {
    use super::update::check_spd;
    use nalgebra::SMatrix;
    fn old<T: Real>(a: &[T], n: usize) -> bool {
        let get = |s: &[T], idx: usize| s.get(idx).copied().unwrap_or_else(T::zero);
        if a.len() != n * n || !a.iter().all(|x| x.is_finite()) {
            return false;
        }
        let tol = a.iter().fold(T::zero(), |m, x| m.max(x.abs())) * T::lit(1e-6);
        let sym = (0..n)
            .all(|j| (j + 1..n).all(|i| (get(a, j * n + i) - get(a, i * n + j)).abs() <= tol));
        if !sym {
            return false;
        }
        let mut l = [T::zero(); 120];
        let at = |l: &[T], i: usize, j: usize| get(l, i * (i + 1) / 2 + j);
        for i in 0..n {
            for j in 0..=i {
                let mut s = get(a, j * n + i);
                for k in 0..j {
                    s -= at(&l, i, k) * at(&l, j, k);
                }
                let v = if i == j {
                    if !super::imu::greater(s, T::zero()) {
                        return false;
                    }
                    s.sqrt()
                } else {
                    s / at(&l, j, j)
                };
                if let Some(e) = l.get_mut(i * (i + 1) / 2 + j) {
                    *e = v;
                }
            }
        }
        true
    }
    let mut rng = Lcg(seed);
    let mut accepted = 0;
    for i in 0..300 {
        let b = SMatrix::<T, N, N>::from_fn(|_, _| T::lit(rng.next()));
        let shift = T::lit([1e-9, 1e-3, 0.1, 1.0, -0.05][i % 5]);
        let mut a = b * b.transpose() + SMatrix::<T, N, N>::identity() * shift;
        if i % 7 == 0 {
            if let Some(e) = a.get_mut((N - 1, 0)) {
                *e = number(&mut rng, i);
            }
        }
        if i % 11 == 0 {
            if let Some(e) = a.get_mut((1, 1)) {
                *e = -*e;
            }
        }
        let new = check_spd(&a);
        assert_eq!(new, old(a.as_slice(), N));
        accepted += usize::from(new);
    }
    assert!(accepted > 50);
}

#[test]
fn check_spd_is_the_former_recurrence() {
    check_spd_case::<f32, 3>(193);
    check_spd_case::<f32, 6>(197);
    check_spd_case::<f32, 15>(199);
    check_spd_case::<f64, 15>(211);
    check_spd_case::<f64, 1>(223);
}

/// `imu::sigmas` against `diagonal().map(|d| d.max(0).sqrt())`, the former `sigmas()` body.
fn sigmas_case<T: Real, const N: usize>(seed: u64) {
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..200 {
        let p = SMatrix::<T, N, N>::from_fn(|r, c| number(&mut rng, i / 2 + 3 * r + c));
        let old = p.diagonal().map(|d| d.max(T::zero()).sqrt());
        assert!(same(super::imu::sigmas(&p).as_slice(), old.as_slice()));
    }
}

#[test]
fn sigmas_are_the_diagonal_map() {
    sigmas_case::<f32, 15>(227);
    sigmas_case::<f32, 6>(229);
    sigmas_case::<f64, 15>(233);
    sigmas_case::<f64, 6>(239);
}

/// `CameraLandmark::linearize` against its former body (nalgebra's `transpose`, `-m` and the
/// finiteness iterator): the same residual and Jacobian bits.
fn camera_case<T: Real>(seed: u64) {
    use super::models::{CameraLandmark, PinholeIntrinsics};
    use super::state::InsState;
    use super::update::Measurement;
    use crate::lie::{skew, Se3};
    use nalgebra::{SMatrix, Vector2};
    let mut rng = Lcg(seed);
    let rot = |rng: &mut Lcg| {
        let axis = Vector3::new(rng.next(), rng.next(), rng.next());
        let q = UnitQuaternion::from_scaled_axis(axis * 3.0)
            .coords
            .map(T::lit);
        So3::from_unit_quaternion(UnitQuaternion::new_unchecked(q.into()))
    };
    let mut accepted = 0;
    for i in 0..400 {
        let x = InsState {
            attitude: rot(&mut rng),
            position: Vector3::new(rng.next(), rng.next(), rng.next()).map(T::lit),
            ..InsState::identity()
        };
        let cam = CameraLandmark::new(
            Vector2::new(T::lit(300.0 * rng.next()), T::lit(200.0 * rng.next())),
            Vector3::new(3.0 * rng.next(), 3.0 * rng.next(), 3.0 * rng.next()).map(T::lit),
            PinholeIntrinsics {
                fx: T::lit(400.0),
                fy: T::lit(380.0 + rng.next()),
                cx: T::lit(320.0),
                cy: number(&mut rng, i),
            },
            Se3::from_parts(
                rot(&mut rng),
                Vector3::new(rng.next(), 0.0, 0.1).map(T::lit),
            ),
            T::lit(1.5),
        );
        let (Ok(lin), Ok((uv, c))) = (cam.linearize(&x), cam.project(&x)) else {
            continue;
        };
        accepted += 1;
        let k = &cam.intrinsics;
        let q = x.attitude.inverse().act(&(cam.landmark - x.position));
        let rcb = cam
            .body_from_camera
            .rotation()
            .rotation_matrix()
            .transpose();
        let rt = x.attitude.rotation_matrix().transpose();
        let iz = T::one() / c.z;
        let z = T::zero();
        let jpi = Matrix3::new(
            k.fx * iz,
            z,
            -k.fx * c.x * iz * iz,
            z,
            k.fy * iz,
            -k.fy * c.y * iz * iz,
            z,
            z,
            z,
        );
        let jc = mm(&jpi, &rcb);
        let (ja, jp) = (mm(&jc, &skew(&q)), -mm(&jc, &rt));
        let mut old = SMatrix::<T, 2, 15>::zeros();
        for r in 0..2 {
            for cc in 0..3 {
                for (col, src) in [(cc, &ja), (6 + cc, &jp)] {
                    if let (Some(e), Some(v)) = (old.get_mut((r, col)), src.get((r, cc))) {
                        *e = *v;
                    }
                }
            }
        }
        assert!(same(lin.jacobian.as_slice(), old.as_slice()));
        let res = Vector2::new(cam.pixel.x - uv.x, cam.pixel.y - uv.y);
        assert!(same(lin.residual.as_slice(), res.as_slice()));
    }
    assert!(accepted > 50);
}

#[test]
fn camera_linearization_is_the_former_body() {
    camera_case::<f32>(241);
    camera_case::<f64>(251);
}

/// `CameraLandmark::new`'s noise against the former `Matrix2::identity() * σ²`.
fn camera_noise<T: Real>() {
    use super::models::{CameraLandmark, PinholeIntrinsics};
    use crate::lie::Se3;
    use nalgebra::{Matrix2, Vector2};
    let mut rng = Lcg(257);
    for i in 0..200 {
        let sigma = number::<T>(&mut rng, i);
        let cam = CameraLandmark::new(
            Vector2::zeros(),
            Vector3::zeros(),
            PinholeIntrinsics {
                fx: T::one(),
                fy: T::one(),
                cx: T::zero(),
                cy: T::zero(),
            },
            Se3::identity(),
            sigma,
        );
        let old = Matrix2::<T>::identity() * (sigma * sigma);
        assert!(same(cam.noise.as_slice(), old.as_slice()));
    }
}

#[test]
fn camera_noise_is_the_scaled_identity() {
    camera_noise::<f32>();
    camera_noise::<f64>();
}

/// `Heading::linearize` against its former body: the attitude row as row 0 of a `3 × 3` block
/// (`Matrix3::new(0, a, b, 0, …)`) copied into the `1 × N` Jacobian by the block loop.
fn heading_case<T: Real, S: super::state::ErrorState<T, N>, const N: usize>(
    seed: u64,
    state: impl Fn(So3<T>) -> S,
) {
    use super::models::Heading;
    use super::update::Measurement;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    let mut accepted = 0;
    for i in 0..400 {
        let axis = Vector3::new(rng.next(), rng.next(), rng.next());
        let q = UnitQuaternion::from_scaled_axis(axis * 3.0)
            .coords
            .map(T::lit);
        let attitude = So3::from_unit_quaternion(UnitQuaternion::new_unchecked(q.into()));
        let model = Heading::new(number(&mut rng, i), T::lit(0.1));
        let new = model.linearize(&state(attitude));
        // The former body.
        let old = (|| {
            if !model.yaw.is_finite() {
                return None;
            }
            let r = attitude.rotation_matrix();
            let (cx, cy) = (r.m11, r.m21);
            let n2 = cx * cx + cy * cy;
            if !super::imu::greater(n2, T::lit(1e-6)) {
                return None;
            }
            let z = T::zero();
            let b = Matrix3::new(
                z,
                (cy * r.m13 - cx * r.m23) / n2,
                (cx * r.m22 - cy * r.m12) / n2,
                z,
                z,
                z,
                z,
                z,
                z,
            );
            let psi = cy.arctan2(cx);
            let (s, c) = (model.yaw - psi).sincos();
            let mut h = SMatrix::<T, 1, N>::zeros();
            for c in 0..3 {
                h[(0, c)] = b[(0, c)];
            }
            Some((s.arctan2(c), h))
        })();
        match (new, old) {
            (Ok(lin), Some((res, h))) => {
                assert!(same(lin.residual.as_slice(), &[res]));
                assert!(same(lin.jacobian.as_slice(), h.as_slice()));
                accepted += 1;
            }
            (Err(_), None) => {}
            _ => panic!("Heading: accepted by one body only"),
        }
    }
    assert!(accepted > 200);
}

#[test]
fn heading_linearization_is_the_former_body() {
    use super::state::{AhrsState, InsState};
    fn ins<T: Real>(attitude: So3<T>) -> InsState<T> {
        InsState {
            attitude,
            ..InsState::identity()
        }
    }
    fn ahrs<T: Real>(attitude: So3<T>) -> AhrsState<T> {
        AhrsState {
            attitude,
            ..AhrsState::identity()
        }
    }
    heading_case::<f32, _, 15>(41, ins);
    heading_case::<f64, _, 15>(42, ins);
    heading_case::<f32, _, 6>(43, ahrs);
    heading_case::<f64, _, 6>(44, ahrs);
}

/// The attitude-only Jacobian as the models build it (a zeroed `3 × N` Jacobian and the block
/// store of `b` into columns `0..3`) against the block loop it replaces, `jacobian(&[(0, &b)])`,
/// bit for bit (special values included).
fn attitude_jacobian_case<T: Real, const N: usize>(seed: u64) {
    use super::imu::set_blk_rc;
    use super::models::jacobian;
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..300 {
        let b = Matrix3::<T>::from_fn(|r, c| number(&mut rng, i + 3 * r + c));
        let mut new = SMatrix::<T, 3, N>::zeros();
        set_blk_rc(&mut new, 0, 0, &b);
        let old = jacobian::<T, 3, N>(&[(0, &b)]);
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn attitude_jacobian_is_the_block_loop() {
    attitude_jacobian_case::<f32, 15>(51);
    attitude_jacobian_case::<f64, 15>(52);
    attitude_jacobian_case::<f32, 6>(53);
    attitude_jacobian_case::<f64, 6>(54);
}

/// The covariance write-out of the update's commit against the former loops: rows 3.. mirrored
/// from the upper triangle, then rows and columns 0..3 written both ways from `top`, block
/// (0, 0) from `c00` (exactly symmetric, from `sym`); on an asymmetric `P` with special values.
fn write_rows_case<T: Real, const N: usize>(seed: u64) {
    use super::update::{write_rows, MAX_STATE};
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..300 {
        let p0 = SMatrix::<T, N, N>::from_fn(|r, c| number(&mut rng, i + 3 * r + c));
        let mut top = [Vector3::<T>::zeros(); MAX_STATE];
        for (j, t) in top.iter_mut().enumerate().take(N) {
            *t = Vector3::from_fn(|r, _| number(&mut rng, i / 3 + r + j));
        }
        let a = Matrix3::<T>::from_fn(|r, c| number(&mut rng, i / 2 + r + 2 * c));
        let c00 = super::imu::sym(&a);

        let mut old = p0;
        let p = old.as_mut_slice();
        for j in 3..N {
            for i in 3..j {
                p[i * N + j] = p[j * N + i];
            }
        }
        for (j, col) in top.iter().enumerate().take(N) {
            for (a, v) in col.iter().enumerate() {
                let v = if j < 3 { c00[(a, j)] } else { *v };
                p[j * N + a] = v;
                p[a * N + j] = v;
            }
        }
        let mut new = p0;
        let mut t = top;
        write_rows(new.as_mut_slice(), N, &mut t, &c00);
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn covariance_write_out_is_the_former_loops() {
    write_rows_case::<f32, 15>(211);
    write_rows_case::<f32, 6>(223);
    write_rows_case::<f64, 15>(227);
    write_rows_case::<f64, 6>(229);
}

/// The prediction's write-out of `N = F P Fᵀ` (both builds: entry by entry when built for size)
/// against the block loop: blocks `L_ki`, `k ≥ i < 3`, into `P` and their transposes above.
fn write_lower_case<T: Real>(seed: u64) {
    use super::imu::{blk_rc, set_blk, tr33, write_lower};
    use nalgebra::SMatrix;
    let mut rng = Lcg(seed);
    for i in 0..200 {
        let p0 = SMatrix::<T, 15, 15>::from_fn(|r, c| number(&mut rng, i + 2 * r + c));
        let l = SMatrix::<T, 15, 9>::from_fn(|r, c| number(&mut rng, i / 2 + r + 3 * c));
        let mut old = p0;
        for bi in 0..3 {
            for k in bi..5 {
                let n = blk_rc(&l, k, bi);
                set_blk(&mut old, k, bi, &n);
                if k > bi {
                    set_blk(&mut old, bi, k, &tr33(&n));
                }
            }
        }
        let mut new = p0;
        write_lower(&mut new, &l);
        assert!(same(new.as_slice(), old.as_slice()));
    }
}

#[test]
fn prediction_write_out_is_the_block_loop() {
    write_lower_case::<f32>(233);
    write_lower_case::<f64>(239);
}

//! The size-driven rewrites of the filter (entry-by-entry forms, shared out-of-line checks)
//! against the straightforward nalgebra expressions they replace: the same bits (or the same
//! answer, for the checks), `f32` and `f64`.

use super::align::InitialSigmas;
use super::imu::{add33, axpy, mm, mv, ImuNoise};
use super::models::{add3, div3, neg3, sub3};
use super::state::{plus_seg, seg};
use crate::lie::So3;
use crate::Real;
use nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3};

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

/// Equal bits, or both NaN.
fn same<T: Real>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            let (x, y) = (x.to_f64(), y.to_f64());
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
        })
}

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
    }
}

#[test]
fn products_are_nalgebras() {
    products::<f32>();
    products::<f64>();
}

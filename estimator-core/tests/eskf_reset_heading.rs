//! `Ins::reset_heading`: the turn about the world's up direction, the heading's new variance
//! free of every correlation, and everything orthogonal to the heading left as it was.

use estimator_core::eskf::*;
use estimator_core::lie::{LieGroup, So3};
use estimator_core::Real;
use nalgebra::{SMatrix, SVector, Vector3};
use proptest::prelude::*;

/// A filter with a covariance full of correlations: a start with a known heading, then
/// predictions while accelerating and turning, and GNSS position and velocity updates.
fn correlated<T: Real>(attitude: [f64; 3]) -> Ins<T> {
    let v = |a: [f64; 3]| Vector3::new(T::lit(a[0]), T::lit(a[1]), T::lit(a[2]));
    let alignment = Alignment {
        attitude: So3::exp(&v(attitude)),
        gyro_bias: Vector3::zeros(),
        heading_from_magnetometer: true,
    };
    let mut ins = Ins::<T>::from_alignment(
        &alignment,
        Vector3::zeros(),
        &InitialSigmas::default(),
        FilterConfig::default(),
    )
    .expect("valid start");
    for k in 0..400u32 {
        let s = T::from_count(k) * T::lit(0.01);
        let imu = ImuSample {
            gyro: Vector3::new(T::lit(0.05), T::lit(-0.02), T::lit(0.3)),
            accel: Vector3::new(T::lit(1.0) + s.sin(), T::lit(0.5), T::lit(9.81)),
            dt: T::lit(0.005),
        };
        ins.predict(&imu).expect("predict");
        if k % 40 == 39 {
            let o = UpdateOptions::default();
            let p = *ins.state();
            ins.update(
                &GnssPosition::new(p.position, Vector3::zeros(), T::lit(1.0)),
                &o,
            )
            .expect("position");
            ins.update(&GnssVelocity::new(p.velocity, T::lit(0.1)), &o)
                .expect("velocity");
        }
    }
    ins
}

fn to_f64<T: Real>(p: &SMatrix<T, 15, 15>) -> SMatrix<f64, 15, 15> {
    p.map(|x| x.to_f64())
}

/// `[u_b; 0]`, the heading direction of the error state, in `f64`.
fn heading_direction<T: Real>(ins: &Ins<T>) -> SVector<f64, 15> {
    let r = ins.state().attitude.rotation_matrix().map(|x| x.to_f64());
    let u = r.transpose() * Vector3::new(0.0, 0.0, 1.0);
    let mut e = SVector::<f64, 15>::zeros();
    e.fixed_rows_mut::<3>(0).copy_from(&u);
    e
}

fn check<T: Real>(attitude: [f64; 3], turn: f64, sigma: f64, tol: f64) {
    let before = correlated::<T>(attitude);
    let mut after = before;
    after
        .reset_heading(T::lit(turn), T::lit(sigma))
        .expect("accepted");
    // The attitude turned by `turn` about world up: R⁺ R̂ᵀ = Exp(turn · e_z).
    let r0 = before
        .state()
        .attitude
        .rotation_matrix()
        .map(|x| x.to_f64());
    let r1 = after.state().attitude.rotation_matrix().map(|x| x.to_f64());
    let expected = So3::exp(&Vector3::new(0.0, 0.0, turn)).rotation_matrix();
    assert!(
        (r1 * r0.transpose() - expected).amax() < 40.0 * T::EPSILON_F64,
        "turn"
    );
    // Everything but the attitude is unchanged.
    let (s0, s1) = (before.state(), after.state());
    assert_eq!((s0.velocity, s0.position), (s1.velocity, s1.position));
    let e = heading_direction(&before);
    let p0 = to_f64(before.covariance());
    let p1 = to_f64(after.covariance());
    let scale = p0.diagonal().amax().max(sigma * sigma);
    // Symmetric and positive definite.
    assert!((p1 - p1.transpose()).amax() <= tol * scale, "symmetric");
    assert!(p1.cholesky().is_some(), "positive definite");
    // The heading: variance σ², no covariance with any other direction: P⁺ e = σ² e.
    let pe = p1 * e;
    assert!(
        (pe - e * (sigma * sigma)).amax() <= tol * scale,
        "heading row {:?}",
        (pe - e * (sigma * sigma)).transpose()
    );
    // Orthogonal to the heading nothing changed: T P⁺ T = T P T with T = I − e eᵀ.
    let t = SMatrix::<f64, 15, 15>::identity() - e * e.transpose();
    let d = t * p1 * t - t * p0 * t;
    assert!(d.amax() <= tol * scale, "tilt and the rest: {}", d.amax());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn reset_heading_turns_about_up_and_replaces_the_heading_only(
        a in prop::array::uniform3(-0.4f64..0.4),
        turn in -3.1f64..3.1,
        sigma in 0.005f64..1.0,
    ) {
        // f64: rounding of a few products of P's entries; the floor is 3.6e-15 tr P_θθ.
        check::<f64>(a, turn, sigma, 1e-12);
        // f32: the same products at ε = 1.2e-7, and the attitude floor of 16 ε tr P_θθ.
        check::<f32>(a, turn, sigma, 2e-5);
    }
}

#[test]
fn refused_reset_leaves_the_filter_unchanged() {
    let before = correlated::<f64>([0.1, -0.2, 0.7]);
    for (turn, sigma) in [
        (f64::NAN, 0.1),
        (f64::INFINITY, 0.1),
        (0.3, 0.0),
        (0.3, -0.0),
        (0.3, f64::NAN),
        (0.3, 1e200),
    ] {
        let mut f = before;
        assert_eq!(f.reset_heading(turn, sigma), Err(EskfError::NonFinite));
        assert_eq!(f, before, "turn {turn}, sigma {sigma}");
    }
}

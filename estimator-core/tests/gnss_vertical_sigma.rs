//! GNSS positions with separate horizontal and vertical accuracy: the measurement model
//! `GnssPosition::with_sigmas` (`R = diag(σ_h², σ_h², σ_v²)`) and the navigator's
//! `GnssFix::with_vertical_sigma`, in `f32` and `f64`.
//!
//! With a prior position block `P_pp = p I` decoupled from the rest and no lever arm, the
//! Kalman update of one axis with noise `σ²` moves the estimate by the gain `k = p / (p + σ²)`
//! of its residual and leaves the variance `p σ² / (p + σ²)`: a larger vertical σ gives the up
//! axis the smaller gain and the larger posterior variance.

use estimator_core::eskf::{
    EskfError, FilterConfig, GnssPosition, Ins, InsState, Measurement, UpdateOptions, UpdateOutcome,
};
use estimator_core::nav::{
    AttitudeConfig, GnssFix, InsConfig, InsEstimate, InsEvent, InsNavigator, InsReport,
    MagneticConfig, NavError,
};
use estimator_core::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

fn v3<T: Real>(x: f64, y: f64, z: f64) -> Vector3<T> {
    Vector3::new(T::lit(x), T::lit(y), T::lit(z))
}

/// Finite, symmetric (to the scalar's rounding) and positive definite (Cholesky).
fn assert_spd<T: Real, const N: usize>(p: &SMatrix<T, N, N>, what: &str) {
    assert!(p.iter().all(|x| x.is_finite()), "{what}: not finite");
    let scale = p.iter().fold(0.0f64, |m, x| m.max(x.to_f64().abs()));
    let asym = (p - p.transpose())
        .iter()
        .fold(0.0f64, |m, x| m.max(x.to_f64().abs()));
    assert!(
        asym <= scale * T::EPSILON_F64 * 64.0,
        "{what}: asymmetry {asym}"
    );
    assert!(p.cholesky().is_some(), "{what}: not positive definite");
}

fn r_is_diagonal_as_stated<T: Real>() {
    let (sh, sv) = (T::lit(0.8), T::lit(2.5));
    let fix = GnssPosition::with_sigmas(v3(1.0, 2.0, 3.0), v3(0.1, 0.0, 0.0), sh, sv)
        .expect("valid sigmas");
    let r: Matrix3<T> = Measurement::<T, InsState<T>, 15, 3>::noise(&fix);
    let want = Matrix3::from_diagonal(&Vector3::new(sh * sh, sh * sh, sv * sv));
    assert_eq!(r, want, "R = diag(σh², σh², σv²)");
    assert_eq!(fix.position, v3(1.0, 2.0, 3.0));
    assert_eq!(fix.lever_arm, v3(0.1, 0.0, 0.0));
    // Equal sigmas are the isotropic model exactly.
    let iso = GnssPosition::new(v3(1.0, 2.0, 3.0), v3(0.1, 0.0, 0.0), sh);
    let same = GnssPosition::with_sigmas(v3(1.0, 2.0, 3.0), v3(0.1, 0.0, 0.0), sh, sh);
    assert_eq!(same, Ok(iso));
}

#[test]
fn r_is_diagonal_as_stated_f32() {
    r_is_diagonal_as_stated::<f32>();
}

#[test]
fn r_is_diagonal_as_stated_f64() {
    r_is_diagonal_as_stated::<f64>();
}

fn vertical_update_is_weaker<T: Real>() {
    // Position prior 4 m² per axis, decoupled: the gains are exactly p / (p + σ²).
    let p = 4.0;
    let mut p0 = SMatrix::<T, 15, 15>::identity() * T::lit(0.01);
    for k in 6..9 {
        p0[(k, k)] = T::lit(p);
    }
    let mut ins = Ins::new(InsState::identity(), p0, FilterConfig::default()).expect("filter");
    let (sh, sv) = (1.0, 3.0);
    let fix =
        GnssPosition::with_sigmas(v3(1.0, 1.0, 1.0), Vector3::zeros(), T::lit(sh), T::lit(sv))
            .expect("valid");
    let outcome = ins.update(&fix, &UpdateOptions::default()).expect("update");
    assert!(matches!(outcome, UpdateOutcome::Accepted { .. }));
    let pos = ins.state().position.map(|x| x.to_f64());
    let (kh, kv) = (p / (p + sh * sh), p / (p + sv * sv));
    let tol = 1e3 * T::EPSILON_F64;
    assert!(
        (pos.x - kh).abs() < tol && (pos.y - kh).abs() < tol,
        "{pos}"
    );
    assert!((pos.z - kv).abs() < tol, "{pos}");
    assert!(pos.z < 0.5 * pos.x, "vertical pulled less: {pos}");
    let cov = ins.covariance();
    let (ph, pv) = (cov[(6, 6)].to_f64(), cov[(8, 8)].to_f64());
    assert!((ph - p * sh * sh / (p + sh * sh)).abs() < tol, "{ph}");
    assert!((pv - p * sv * sv / (p + sv * sv)).abs() < tol, "{pv}");
    assert!(
        pv > 2.0 * ph,
        "vertical variance stays larger: {pv} vs {ph}"
    );
    assert_spd(cov, "after the update");

    // With an attitude uncertainty and a lever arm the blocks couple; the covariance stays
    // finite, symmetric and positive definite over many updates.
    let mut ins = Ins::new(
        InsState::identity(),
        p0 * T::lit(10.0),
        FilterConfig::default(),
    )
    .expect("filter");
    for k in 0..200 {
        let z = v3(0.01 * f64::from(k), -0.02, 0.5);
        let fix = GnssPosition::with_sigmas(z, v3(0.3, -0.1, 0.2), T::lit(0.5), T::lit(2.0))
            .expect("valid");
        ins.update(&fix, &UpdateOptions::default()).expect("update");
        assert_spd(ins.covariance(), "repeated updates");
    }
    let cov = ins.covariance();
    assert!(cov[(8, 8)] > cov[(6, 6)] && cov[(8, 8)] > cov[(7, 7)]);
}

#[test]
fn vertical_update_is_weaker_f32() {
    vertical_update_is_weaker::<f32>();
}

#[test]
fn vertical_update_is_weaker_f64() {
    vertical_update_is_weaker::<f64>();
}

fn invalid_sigmas_are_refused<T: Real>() {
    let z = v3::<T>(1.0, 2.0, 3.0);
    let zero = Vector3::zeros();
    let one = T::one();
    let huge = T::lit(if T::EPSILON_F64 > 1e-10 { 1e20 } else { 1e160 });
    for bad in [
        T::zero(),
        -one,
        T::lit(-0.0),
        T::lit(f64::NAN),
        T::lit(f64::INFINITY),
        huge,
    ] {
        for (sh, sv) in [(bad, one), (one, bad)] {
            assert_eq!(
                GnssPosition::with_sigmas(z, zero, sh, sv),
                Err(EskfError::NoiseNotPositiveDefinite),
                "sigmas {sh:?} {sv:?}"
            );
        }
    }
    let nan = v3::<T>(f64::NAN, 0.0, 0.0);
    assert_eq!(
        GnssPosition::with_sigmas(nan, zero, one, one),
        Err(EskfError::NonFinite)
    );
    assert_eq!(
        GnssPosition::with_sigmas(z, nan, one, one),
        Err(EskfError::NonFinite)
    );

    // A model whose R is singular on the vertical (built by hand, bypassing the check) is
    // refused by the update, and the filter is unchanged bit for bit.
    let mut ins = Ins::new(
        InsState::identity(),
        SMatrix::<T, 15, 15>::identity(),
        FilterConfig::default(),
    )
    .expect("filter");
    let before = ins;
    let mut fix = GnssPosition::with_sigmas(z, zero, one, one).expect("valid");
    fix.noise[(2, 2)] = T::zero();
    assert_eq!(
        ins.update(&fix, &UpdateOptions::default()),
        Err(EskfError::NoiseNotPositiveDefinite)
    );
    assert_eq!(ins, before);
    fix.noise[(2, 2)] = T::lit(f64::NAN);
    assert!(ins.update(&fix, &UpdateOptions::default()).is_err());
    assert_eq!(ins, before);
}

#[test]
fn invalid_sigmas_are_refused_f32() {
    invalid_sigmas_are_refused::<f32>();
}

#[test]
fn invalid_sigmas_are_refused_f64() {
    invalid_sigmas_are_refused::<f64>();
}

const T0: u64 = 1_000_000_000;
const IMU_NS: u64 = 5_000_000; // 200 Hz
const FIELD: [f64; 3] = [0.0, 20.0, -40.0];

fn config<T: Real>() -> InsConfig<T> {
    let mut attitude = AttitudeConfig::new(FilterConfig::default());
    attitude.magnetometer = Some(MagneticConfig::new(
        T::lit(0.5),
        Some(v3(FIELD[0], FIELD[1], FIELD[2])),
    ));
    InsConfig::new(attitude)
}

/// At rest, level, facing east, for `duration_s` at 200 Hz; magnetometer at 50 Hz; fixes at
/// 5 Hz from 1 s at `position(t)` with zero velocity, horizontal 1σ `sigma_h` and vertical
/// `sigma_v`. Every report, and the estimate after every sample.
#[allow(clippy::type_complexity)]
fn at_rest<T: Real>(
    duration_s: f64,
    position: impl Fn(f64) -> Vector3<f64>,
    sigma_h: f64,
    sigma_v: f64,
) -> (
    Vec<(f64, InsReport<T>, Option<InsEstimate<T>>)>,
    InsNavigator<T>,
) {
    let mut nav = InsNavigator::<T>::new(config()).expect("navigator");
    let mut out = Vec::new();
    for k in 0..(duration_s * 200.0) as u64 {
        let t = T0 + k * IMU_NS;
        let s = (k as f64) / 200.0;
        if k % 4 == 0 {
            nav.magnetometer(t, &v3(FIELD[0], FIELD[1], FIELD[2]))
                .expect("magnetometer");
        }
        if k % 40 == 20 && k > 200 {
            let p = position(s);
            let fix = GnssFix::new(
                v3(p.x, p.y, p.z),
                Some(Vector3::zeros()),
                T::lit(sigma_h),
                T::lit(0.05),
            )
            .with_vertical_sigma(T::lit(sigma_v));
            nav.gnss(t, &fix).expect("fix");
        }
        let r = nav
            .imu(t, &Vector3::zeros(), &v3(0.0, 0.0, 9.81))
            .expect("imu");
        out.push((s, r, nav.estimate()));
    }
    (out, nav)
}

fn assert_estimate_spd<T: Real>(e: &InsEstimate<T>, what: &str) {
    for (b, block) in e.covariance.iter().enumerate() {
        assert_spd(block, &format!("{what}, block {b}"));
    }
}

fn navigator_starts_and_runs_with_the_vertical_sigma<T: Real>() {
    let (sh, sv) = (0.5, 2.0);
    let (reports, nav) = at_rest::<T>(30.0, |_| Vector3::new(10.0, 5.0, 2.0), sh, sv);
    // At the start, the position's covariance is the fix's, diag(σh², σh², σv²) (carried
    // over the horizon by a velocity known to 0.05 m/s: a few mm² more).
    let (_, _, start) = reports
        .iter()
        .find(|(_, r, _)| r.event == Some(InsEvent::Started))
        .expect("the INS starts");
    let start = start.as_ref().expect("an estimate at the start");
    let p = start.covariance[2].map(|x| x.to_f64());
    assert!((p[(0, 0)] - sh * sh).abs() < 0.05 * sh * sh, "{p}");
    assert!((p[(1, 1)] - sh * sh).abs() < 0.05 * sh * sh, "{p}");
    assert!((p[(2, 2)] - sv * sv).abs() < 0.05 * sv * sv, "{p}");
    assert_estimate_spd(start, "at the start");
    // Running: every estimate stays a covariance, and the vertical stays the less certain.
    for (s, _, e) in reports.iter().filter(|(s, _, _)| *s > 5.0) {
        let e = e.as_ref().expect("running");
        let p = e.covariance[2];
        assert!(p[(2, 2)] > p[(0, 0)] && p[(2, 2)] > p[(1, 1)], "{s} s: {p}");
    }
    let last = nav.estimate().expect("running");
    assert_estimate_spd(&last, "at the end");
    let pos = last.state.position.map(|x| x.to_f64());
    assert!((pos - Vector3::new(10.0, 5.0, 2.0)).norm() < 0.5, "{pos}");
    assert!(nav.counters().gnss_position_fused > 100);
    assert_eq!(nav.counters().gnss_position_rejected, 0);
}

#[test]
fn navigator_starts_and_runs_with_the_vertical_sigma_f32() {
    navigator_starts_and_runs_with_the_vertical_sigma::<f32>();
}

#[test]
fn navigator_starts_and_runs_with_the_vertical_sigma_f64() {
    navigator_starts_and_runs_with_the_vertical_sigma::<f64>();
}

fn a_reset_takes_both_sigmas<T: Real>() {
    // Fixes drifting east at 2 m/s from 20 s, reported at rest: after `gnss_reset_s` of
    // rejected fixes the position is reset to them, with the fix's covariance per axis.
    let (sh, sv) = (0.5, 2.0);
    let drift = |s: f64| Vector3::new(2.0 * (s - 20.0).max(0.0), 0.0, 0.0);
    let (reports, nav) = at_rest::<T>(40.0, drift, sh, sv);
    let (s, _, e) = reports
        .iter()
        .find(|(_, r, _)| r.event == Some(InsEvent::PositionReset))
        .expect("a reset");
    let e = e.as_ref().expect("an estimate at the reset");
    let p = e.covariance[2].map(|x| x.to_f64());
    assert!(
        p[(2, 2)] > 0.8 * sv * sv && p[(0, 0)] < 2.0 * sh * sh && p[(2, 2)] > 4.0 * p[(0, 0)],
        "{s} s: {p}"
    );
    assert_estimate_spd(e, "at the reset");
    assert_estimate_spd(&nav.estimate().expect("running"), "after the reset");
}

#[test]
fn a_reset_takes_both_sigmas_f32() {
    a_reset_takes_both_sigmas::<f32>();
}

#[test]
fn a_reset_takes_both_sigmas_f64() {
    a_reset_takes_both_sigmas::<f64>();
}

fn navigator_refuses_a_bad_vertical_sigma<T: Real>() {
    let (_, mut nav) = at_rest::<T>(3.0, |_| Vector3::new(1.0, 2.0, 3.0), 0.5, 1.0);
    let t = T0 + 3 * 200 * IMU_NS - IMU_NS;
    let good = GnssFix::new(
        v3(1.0, 2.0, 3.0),
        Some(Vector3::zeros()),
        T::one(),
        T::lit(0.1),
    );
    // Bit for bit what it was, but for the refusal counter.
    let without_count = |n: &InsNavigator<T>| {
        format!("{n:?}").replace(&format!("refused: {}", n.counters().refused), "")
    };
    for bad in [0.0, -1.0, 1e-6, 1e5, f64::NAN, f64::INFINITY] {
        let before = nav;
        assert_eq!(
            nav.gnss(t, &good.with_vertical_sigma(T::lit(bad))),
            Err(NavError::InvalidSigma),
            "vertical sigma {bad}"
        );
        assert_eq!(nav.counters().refused, before.counters().refused + 1);
        assert_eq!(without_count(&nav), without_count(&before));
    }
    // The default is the horizontal sigma: a fix without one is taken.
    assert!(good.sigma_position_up.is_none());
    assert!(nav.gnss(t, &good).is_ok());
}

#[test]
fn navigator_refuses_a_bad_vertical_sigma_f32() {
    navigator_refuses_a_bad_vertical_sigma::<f32>();
}

#[test]
fn navigator_refuses_a_bad_vertical_sigma_f64() {
    navigator_refuses_a_bad_vertical_sigma::<f64>();
}

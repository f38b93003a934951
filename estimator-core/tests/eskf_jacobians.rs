//! Every measurement model's `H` and the prediction's `F` against Richardson-extrapolated central
//! finite differences through `⊕` (f64).
//!
//! `D(ε) = (r(x ⊕ εeᵢ) − r(x ⊕ −εeᵢ))/(2ε)` has error `O(ε²)`; `(4D(ε/2) − D(ε))/3` has error
//! `O(ε⁴)`. With `ε = 1e-3` the truncation error is ~1e-12 and round-off ~1e-13 relative, so the
//! stated tolerance is `1e-7 · max(1, max|H|)`: a wrong sign, block or factor fails by orders of
//! magnitude.

mod eskf_common;
mod support;

use eskf_common::{gyro_only, Rng};
use estimator_core::eskf::*;
use estimator_core::lie::{LieGroup, Se3, So3};
use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use support::fd_jacobian;

const EPS: f64 = 1e-3;

fn random_ins(rng: &mut Rng) -> InsState<f64> {
    InsState {
        attitude: So3::exp(&rng.vec3(1.0)),
        velocity: rng.vec3(2.0),
        position: rng.vec3(5.0),
        gyro_bias: rng.vec3(0.01),
        accel_bias: rng.vec3(0.1),
    }
}

fn random_ahrs(rng: &mut Rng) -> AhrsState<f64> {
    AhrsState {
        attitude: So3::exp(&rng.vec3(1.0)),
        gyro_bias: rng.vec3(0.01),
    }
}

/// `−∂r/∂δx` by Richardson-extrapolated central differences.
fn numeric_h<S, Mo, const N: usize, const M: usize>(model: &Mo, x: &S) -> SMatrix<f64, M, N>
where
    S: ErrorState<f64, N>,
    Mo: Measurement<f64, S, N, M>,
{
    let r = |dx: &SVector<f64, N>| model.linearize(&x.oplus(dx)).expect("linearize").residual;
    -fd_jacobian(r, EPS)
}

fn check<S, Mo, const N: usize, const M: usize>(name: &str, model: &Mo, x: &S)
where
    S: ErrorState<f64, N>,
    Mo: Measurement<f64, S, N, M>,
{
    let analytic = model.linearize(x).expect("linearize").jacobian;
    let numeric = numeric_h(model, x);
    let scale = analytic.amax().max(1.0);
    let err = (analytic - numeric).amax();
    assert!(
        err <= 1e-7 * scale,
        "{name}: |H - H_fd| = {err:e} (scale {scale})\nH = {analytic}\nfd = {numeric}"
    );
}

#[test]
fn ins_models_match_finite_differences() {
    let mut rng = Rng::new(7);
    for _ in 0..20 {
        let x = random_ins(&mut rng);
        check(
            "gnss position",
            &GnssPosition::new(rng.vec3(5.0), rng.vec3(0.5), 1.0),
            &x,
        );
        check("gnss velocity", &GnssVelocity::new(rng.vec3(2.0), 0.1), &x);
        check("zupt", &ZeroVelocity::new(0.01), &x);
        check("lateral velocity", &LateralVelocity::new(0.05), &x);
        check("baro", &BaroAltitude::new(rng.normal(), 0.5), &x);
        check(
            "magnetometer",
            &Magnetometer::new(rng.vec3(30.0), rng.vec3(30.0), 0.5),
            &x,
        );
        check("gravity", &GravityDirection::new(rng.vec3(9.0), 0.05), &x);
        check(
            "accelerometer at rest",
            &AccelerometerAtRest::new(rng.vec3(9.0), 0.05),
            &x,
        );
        check("heading", &Heading::new(0.3, 0.05), &x);
        // A landmark 0.3–1 m in front of a camera with a generic extrinsic.
        let bc = Se3::from_parts(So3::exp(&rng.vec3(0.3)), rng.vec3(0.1));
        let depth = 0.3 + 0.7 * rng.uniform();
        let in_cam = Vector3::new(0.1 * rng.normal(), 0.1 * rng.normal(), depth);
        let landmark = x.position + x.attitude.act(&bc.act(&in_cam));
        let k = PinholeIntrinsics {
            fx: 450.0,
            fy: 460.0,
            cx: 320.0,
            cy: 240.0,
        };
        check(
            "camera",
            &CameraLandmark::new(Vector2::new(300.0, 250.0), landmark, k, bc, 1.0),
            &x,
        );
    }
}

#[test]
fn ahrs_models_match_finite_differences() {
    let mut rng = Rng::new(8);
    for _ in 0..20 {
        let x = random_ahrs(&mut rng);
        check(
            "magnetometer",
            &Magnetometer::new(rng.vec3(30.0), rng.vec3(30.0), 0.5),
            &x,
        );
        check("gravity", &GravityDirection::new(rng.vec3(9.0), 0.05), &x);
        check("heading", &Heading::new(-2.0, 0.05), &x);
    }
}

fn random_spd<const N: usize>(rng: &mut Rng) -> SMatrix<f64, N, N> {
    let a = SMatrix::<f64, N, N>::from_fn(|_, _| rng.normal() * 0.1);
    a * a.transpose() + SMatrix::<f64, N, N>::identity() * 0.01
}

fn zero_noise() -> FilterConfig<f64> {
    FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: 0.0,
            gyroscope_random_walk: 0.0,
            accelerometer_noise_density: 0.0,
            accelerometer_random_walk: 0.0,
        },
        ..FilterConfig::default()
    }
}

/// `F` by finite differences of `g(δx) = prop(x ⊕ δx) ⊖ prop(x)`; the filter's block-sparse
/// covariance step must equal the dense `F P Fᵀ` (with `Q = 0`).
#[test]
fn ins_predict_matches_dense_f_p_ft() {
    let mut rng = Rng::new(9);
    for _ in 0..10 {
        let x = random_ins(&mut rng);
        let p = random_spd::<15>(&mut rng);
        let imu = ImuSample {
            gyro: rng.vec3(1.0),
            accel: rng.vec3(5.0) + Vector3::new(0.0, 0.0, 9.81),
            dt: 0.01,
        };
        let prop = |s: InsState<f64>| {
            let mut f = Ins::new(s, p, zero_noise()).expect("filter");
            f.predict(&imu).expect("predict");
            *f.state()
        };
        let base = prop(x);
        let g = |dx: &SVector<f64, 15>| eskf_common::ins_error(&prop(x.oplus(dx)), &base);
        let f = fd_jacobian(g, EPS);
        let mut filter = Ins::new(x, p, zero_noise()).expect("filter");
        filter.predict(&imu).expect("predict");
        let dense = f * p * f.transpose();
        let err = (filter.covariance() - dense).amax();
        assert!(err < 1e-8 * dense.amax(), "F P Fᵀ mismatch {err:e}");
    }
}

#[test]
fn ahrs_predict_matches_dense_f_p_ft() {
    let mut rng = Rng::new(10);
    for _ in 0..10 {
        let x = random_ahrs(&mut rng);
        let p = random_spd::<6>(&mut rng);
        let w = rng.vec3(1.0);
        let dt = 0.01;
        let prop = |s: AhrsState<f64>| {
            let mut f = Ahrs::new(s, p, zero_noise()).expect("filter");
            f.predict(&gyro_only(w, dt)).expect("predict");
            *f.state()
        };
        let base = prop(x);
        let g = |dx: &SVector<f64, 6>| {
            let s = prop(x.oplus(dx));
            let mut e = SVector::<f64, 6>::zeros();
            e.fixed_rows_mut::<3>(0)
                .copy_from(&s.attitude.rminus(&base.attitude));
            e.fixed_rows_mut::<3>(3)
                .copy_from(&(s.gyro_bias - base.gyro_bias));
            e
        };
        let f = fd_jacobian(g, EPS);
        let mut filter = Ahrs::new(x, p, zero_noise()).expect("filter");
        filter.predict(&gyro_only(w, dt)).expect("predict");
        let dense = f * p * f.transpose();
        let err = (filter.covariance() - dense).amax();
        assert!(err < 1e-8 * dense.amax(), "F P Fᵀ mismatch {err:e}");
    }
}

/// The reset Jacobian: after injecting `δx`, a true state `x̂ ⊕ e` has error
/// `(x̂ ⊕ δx) ⊖ … ≈ G (e − δx)` with `G = blockdiag(J_r(δθ), I)`; checked through the filter
/// on an exact measurement of the attitude whose posterior covariance is known.
#[test]
fn reset_jacobian_is_right_jacobian() {
    let mut rng = Rng::new(11);
    let dth = rng.vec3(0.2);
    let x0 = So3::exp(&rng.vec3(1.0));
    let x1 = x0.rplus(&dth);
    // e_new(e) = log(exp(dθ)⁻¹ exp(e)) around e = dθ.
    let jr = So3::right_jacobian(&dth);
    for i in 0..3 {
        let mut d = Vector3::zeros();
        d[i] = 1e-6;
        let plus = x0.rplus(&(dth + d)).rminus(&x1);
        let minus = x0.rplus(&(dth - d)).rminus(&x1);
        let col = (plus - minus) / 2e-6;
        assert!((col - jr.column(i)).amax() < 1e-8);
    }
}

fn random_ahrs_accel_bias(rng: &mut Rng) -> AhrsAccelBiasState<f64> {
    AhrsAccelBiasState {
        attitude: So3::exp(&rng.vec3(1.0)),
        gyro_bias: rng.vec3(0.01),
        accel_bias: rng.vec3(0.1),
        velocity: rng.vec3(1.0),
    }
}

#[test]
fn zero_rate_and_accelerometer_match_finite_differences_for_every_state() {
    let mut rng = Rng::new(12);
    for _ in 0..20 {
        let z = ZeroRate::new(rng.vec3(0.01), 1e-3);
        check("zero rate, ahrs", &z, &random_ahrs(&mut rng));
        check("zero rate, ins", &z, &random_ins(&mut rng));
        let x9 = random_ahrs_accel_bias(&mut rng);
        check("zero rate, ahrs accel bias", &z, &x9);
        let f = AccelerometerAtRest::new(rng.vec3(9.0), 0.05);
        check("accelerometer, ahrs accel bias", &f, &x9);
        check(
            "gravity, ahrs accel bias",
            &GravityDirection::new(rng.vec3(9.0), 0.05),
            &x9,
        );
        check(
            "velocity bound, ahrs accel bias",
            &ZeroVelocity::new(0.5),
            &x9,
        );
    }
}

/// `integrate_velocity` against the error it models: a block of constant attitude with the
/// true state `x = x̂ ⊕ δx` integrates the true specific force `R (f_m − b_a)` where the
/// estimate integrates `R̂ (f_m − b̂_a)`; the difference of the two velocities, to first order
/// in `δx` (central differences, error `O(ε²)`), is row `v` of `G` (`δv⁺ = G δx`), and the
/// covariance is `G P Gᵀ + N_a² T I`.
#[test]
fn ahrs_accel_bias_velocity_integration_matches_its_error_model() {
    let mut rng = Rng::new(15);
    let na = 0.003;
    let mut config = zero_noise();
    config.imu_noise.accelerometer_noise_density = na;
    for _ in 0..10 {
        let x = random_ahrs_accel_bias(&mut rng);
        let p = random_spd::<12>(&mut rng);
        let f_m = rng.vec3(10.0);
        let t = 0.5;
        // One block, attitude constant over it: Σ R̂ f_m Δt = R̂ f_m T, Σ R̂ Δt = R̂ T.
        let sums = |s: &AhrsAccelBiasState<f64>| {
            let r = s.attitude.rotation_matrix();
            (r * f_m * t, r * t)
        };
        let after = |s: &AhrsAccelBiasState<f64>| {
            let (force, frames) = sums(s);
            let mut f = AhrsAccelBias::new(*s, p, config).expect("filter");
            f.integrate_velocity(&force, &frames, t).expect("integrate");
            f.state().velocity - s.velocity
        };
        let g = |dx: &SVector<f64, 12>| {
            let truth = x.oplus(dx);
            // The true velocity after the block (the truth's own sums) minus the estimate's
            // after the block (the estimate's sums), as an error: v + Δv(truth) − (v̂ + Δv(x̂)).
            truth.velocity + after(&truth) - (x.velocity + after(&x))
        };
        let rows = fd_jacobian(g, EPS);
        let (force, frames) = sums(&x);
        let mut filter = AhrsAccelBias::new(x, p, config).expect("filter");
        filter
            .integrate_velocity(&force, &frames, t)
            .expect("integrate");
        let mut gm = SMatrix::<f64, 12, 12>::identity();
        gm.fixed_view_mut::<3, 12>(9, 0).copy_from(&rows);
        let mut dense = gm * p * gm.transpose();
        for k in 9..12 {
            dense[(k, k)] += na * na * t;
        }
        let err = (filter.covariance() - dense).amax();
        assert!(err < 1e-6 * dense.amax(), "G P Gᵀ mismatch {err:e}");
        // The nominal velocity: v + R̂ (f_m − b̂_a) T + g T.
        let expected = x.velocity
            + x.attitude.rotation_matrix() * (f_m - x.accel_bias) * t
            + config.gravity * t;
        assert!((filter.state().velocity - expected).amax() < 1e-12);
    }
}

/// Bad input to `integrate_velocity` is refused and leaves the filter as it was.
#[test]
fn ahrs_accel_bias_velocity_integration_refuses_bad_input_unchanged() {
    let mut rng = Rng::new(16);
    let x = random_ahrs_accel_bias(&mut rng);
    let f = AhrsAccelBias::new(x, random_spd::<12>(&mut rng), zero_noise()).expect("filter");
    let bad: [(Vector3<f64>, SMatrix<f64, 3, 3>, f64); 3] = [
        (Vector3::new(f64::NAN, 0.0, 0.0), SMatrix::identity(), 0.5),
        (Vector3::zeros(), SMatrix::identity() * f64::INFINITY, 0.5),
        (Vector3::zeros(), SMatrix::identity(), 0.0),
    ];
    for (force, frames, t) in bad {
        let mut g = f;
        assert!(g.integrate_velocity(&force, &frames, t).is_err());
        assert_eq!(g, f);
    }
}

/// The magnetic heading's row is the vertical part of the attitude error only: along
/// `δθ = ε R̂ᵀu` (a rotation of the world about up) it matches the finite difference of the
/// azimuth; across it (`δθ ⊥ R̂ᵀu`) the row is zero by construction.
#[test]
fn magnetic_heading_row_is_the_azimuth_derivative_about_up() {
    let mut rng = Rng::new(13);
    let up = Vector3::z();
    for _ in 0..20 {
        let x = random_ahrs(&mut rng);
        let model = MagneticHeading::new(rng.vec3(30.0), Vector3::new(0.0, 20.0, -40.0), 0.05);
        let row = Measurement::<f64, AhrsState<f64>, 6, 1>::linearize(&model, &x)
            .expect("linearize")
            .jacobian;
        let axis = x.attitude.inverse().act(&up);
        let r = |e: f64| {
            let mut dx = SVector::<f64, 6>::zeros();
            dx.fixed_rows_mut::<3>(0).copy_from(&(axis * e));
            Measurement::<f64, AhrsState<f64>, 6, 1>::linearize(&model, &x.oplus(&dx))
                .expect("linearize")
                .residual[0]
        };
        let d = |h: f64| (r(h) - r(-h)) / (2.0 * h);
        let numeric = -(4.0 * d(EPS / 2.0) - d(EPS)) / 3.0;
        let analytic = row.fixed_columns::<3>(0).dot(&axis.transpose());
        assert!((analytic - numeric).abs() < 1e-7, "{analytic} vs {numeric}");
        // Across the vertical: zero.
        let across = axis.cross(&rng.vec3(1.0)).normalize();
        assert!(row.fixed_columns::<3>(0).dot(&across.transpose()).abs() < 1e-12);
        assert!(row.fixed_columns::<3>(3).amax() == 0.0);
    }
}

#[test]
fn ahrs_accel_bias_predict_matches_dense_f_p_ft() {
    let mut rng = Rng::new(14);
    for _ in 0..10 {
        let x = random_ahrs_accel_bias(&mut rng);
        let p = random_spd::<12>(&mut rng);
        let w = rng.vec3(1.0);
        let dt = 0.01;
        let prop = |s: AhrsAccelBiasState<f64>| {
            let mut f = AhrsAccelBias::new(s, p, zero_noise()).expect("filter");
            f.predict(&gyro_only(w, dt)).expect("predict");
            *f.state()
        };
        let base = prop(x);
        let g = |dx: &SVector<f64, 12>| {
            let s = prop(x.oplus(dx));
            let mut e = SVector::<f64, 12>::zeros();
            e.fixed_rows_mut::<3>(0)
                .copy_from(&s.attitude.rminus(&base.attitude));
            e.fixed_rows_mut::<3>(3)
                .copy_from(&(s.gyro_bias - base.gyro_bias));
            e.fixed_rows_mut::<3>(6)
                .copy_from(&(s.accel_bias - base.accel_bias));
            e.fixed_rows_mut::<3>(9)
                .copy_from(&(s.velocity - base.velocity));
            e
        };
        let f = fd_jacobian(g, EPS);
        let mut filter = AhrsAccelBias::new(x, p, zero_noise()).expect("filter");
        filter.predict(&gyro_only(w, dt)).expect("predict");
        let dense = f * p * f.transpose();
        let err = (filter.covariance() - dense).amax();
        assert!(err < 1e-8 * dense.amax(), "F P Fᵀ mismatch {err:e}");
    }
}

//! The attitude navigator on synthetic streams with known truth: start-up at rest and while
//! moving, rest and the gyro bias, magnetic disturbances, recovery from a wrong estimate, and
//! bad input (every refused call leaves the navigator bit for bit unchanged).
//!
//! The streams: a body turning with a smooth angular rate, attitude integrated exactly (the
//! rate is constant over each 1 ms sub-step and `exp` is exact), the accelerometer reading
//! `Rᵀ(a − g)` and the magnetometer `Rᵀ m_w` plus white noise of the configured size. Bounds
//! are a few σ of what the sensors allow (stated at each assert).

mod support;

use estimator_core::eskf::{FilterConfig, ImuNoise};
use estimator_core::lie::{LieGroup, So3};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, Event, MagneticConfig, MagneticStatus, NavError, Reason,
    Validity,
};
use nalgebra::Vector3;
use support::Rng;

const RATE_HZ: u64 = 100;
const STEP_NS: u64 = 1_000_000_000 / RATE_HZ;
const T0: u64 = 1_600_000_000_000_000_000;
const FIELD: [f64; 3] = [0.0, 20.0, -45.0];
const GYRO_NOISE: f64 = 2e-4; // rad/s/√Hz
const ACCEL_NOISE: f64 = 2e-3; // m/s²/√Hz
const MAG_SIGMA: f64 = 0.4; // µT

fn config() -> AttitudeConfig<f64> {
    let filter = FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: GYRO_NOISE,
            gyroscope_random_walk: 2e-5,
            accelerometer_noise_density: ACCEL_NOISE,
            accelerometer_random_walk: 1e-3,
        },
        ..FilterConfig::default()
    };
    let mut c = AttitudeConfig::new(filter);
    c.magnetometer = Some(MagneticConfig::new(MAG_SIGMA, Some(Vector3::from(FIELD))));
    c
}

/// A synthetic body: attitude, angular rate function, linear acceleration function.
struct Body {
    attitude: So3<f64>,
    t: f64,
}

/// One sample of every sensor.
struct Sample {
    t_ns: u64,
    gyro: Vector3<f64>,
    accel: Vector3<f64>,
    mag: Vector3<f64>,
    truth: So3<f64>,
}

impl Body {
    /// Advances by one IMU interval under the rate `w(t)` (body frame) and returns the sensors
    /// at the new time with a linear acceleration `a(t)` (world frame) and a gyro bias `b`.
    fn step(
        &mut self,
        k: u64,
        w: &dyn Fn(f64) -> Vector3<f64>,
        a: &dyn Fn(f64) -> Vector3<f64>,
        bias: &Vector3<f64>,
        rng: &mut Rng,
    ) -> Sample {
        let dt = 1.0 / RATE_HZ as f64;
        let sub = 10;
        for _ in 0..sub {
            let h = dt / sub as f64;
            self.attitude = self.attitude.compose(&So3::exp(&(w(self.t + h / 2.0) * h)));
            self.t += h;
        }
        let r = self.attitude;
        let g = Vector3::new(0.0, 0.0, -9.81);
        let white = |density: f64| density * (RATE_HZ as f64).sqrt();
        Sample {
            t_ns: T0 + k * STEP_NS,
            gyro: w(self.t) + bias + rng.vec3(white(GYRO_NOISE)),
            accel: r.inverse().act(&(a(self.t) - g)) + rng.vec3(white(ACCEL_NOISE)),
            mag: r.inverse().act(&Vector3::from(FIELD)) + rng.vec3(MAG_SIGMA),
            truth: r,
        }
    }
}

fn angle_deg(a: &So3<f64>, b: &So3<f64>) -> f64 {
    a.inverse().compose(b).log().norm().to_degrees()
}

/// A hand-held-like motion: turning about every axis at up to ~60 °/s, accelerating up to
/// ~2 m/s² with zero mean velocity.
fn wave(t: f64) -> Vector3<f64> {
    Vector3::new(
        0.6 * (0.7 * t).sin(),
        0.5 * (1.1 * t + 1.0).sin(),
        0.8 * (0.5 * t).cos(),
    )
}

fn shake(t: f64) -> Vector3<f64> {
    Vector3::new(
        2.0 * (2.0 * t).sin(),
        1.5 * (2.6 * t + 0.5).cos(),
        1.0 * (3.1 * t).sin(),
    )
}

fn still(_: f64) -> Vector3<f64> {
    Vector3::zeros()
}

/// Runs `seconds` of the motion through a navigator; returns the largest attitude error
/// after `settle` seconds, and the last sample.
#[allow(clippy::too_many_arguments)] // each argument is one part of the synthetic stream
fn run(
    nav: &mut AttitudeNavigator<f64>,
    body: &mut Body,
    k0: u64,
    seconds: u64,
    settle: f64,
    w: &dyn Fn(f64) -> Vector3<f64>,
    a: &dyn Fn(f64) -> Vector3<f64>,
    bias: &Vector3<f64>,
    rng: &mut Rng,
) -> (f64, u64) {
    let mut worst: f64 = 0.0;
    let n = seconds * RATE_HZ;
    for k in k0..k0 + n {
        let s = body.step(k, w, a, bias, rng);
        nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        if (k - k0) as f64 / RATE_HZ as f64 >= settle {
            let e = nav.estimate().expect("started");
            worst = worst.max(angle_deg(&e.attitude, &s.truth));
        }
    }
    (worst, k0 + n)
}

#[test]
fn starts_at_rest_learns_the_gyro_bias_and_holds_the_attitude() {
    let mut rng = Rng::new(1);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let start = So3::exp(&Vector3::new(0.1, -0.2, 2.0));
    let mut body = Body {
        attitude: start,
        t: 0.0,
    };
    let bias = Vector3::new(0.005, -0.003, 0.008);
    let (worst, _) = run(
        &mut nav, &mut body, 0, 20, 1.5, &still, &still, &bias, &mut rng,
    );
    // At rest the tilt is known to the accelerometer bias's prior (0.1 m/s² → 0.6°) and the
    // heading to the magnetometer (0.4 µT on 20 µT horizontal, plus the tilt through the dip).
    assert!(worst < 1.5, "attitude error {worst}° at rest");
    let e = nav.estimate().expect("started");
    // 20 s at rest: the zero-rate updates measure the bias to the rest floor (0.1 °/s).
    assert!(
        (e.gyro_bias - bias).norm() < 0.1f64.to_radians() * 3.0,
        "bias {}",
        e.gyro_bias
    );
    let r = nav.report();
    assert!(
        r.at_rest && r.tilt.is_valid() && r.heading.is_valid(),
        "{r:?}"
    );
    assert!(nav.counters().zero_rate > 0);
}

#[test]
fn starts_while_moving_and_tracks_hand_held_motion() {
    let mut rng = Rng::new(2);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::exp(&Vector3::new(-0.3, 0.2, -1.0)),
        t: 0.0,
    };
    let bias = Vector3::new(-0.004, 0.006, 0.002);
    let mut first = None;
    for k in 0..300 {
        let s = body.step(k, &wave, &shake, &bias, &mut rng);
        let r = nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        if r.event == Some(Event::Started) {
            let e = nav.estimate().expect("started");
            let sigma = e.sigma_tilt.hypot(e.sigma_heading).to_degrees();
            first = Some((angle_deg(&e.attitude, &s.truth), sigma));
        }
    }
    // The start-up window averages 1 s of a motion whose mean acceleration over that second
    // is 1.4 m/s² (8° of tilt, ×2.25 in heading through the dip): no start can see it, but
    // the covariance must cover it.
    let (first, sigma) = first.expect("started within 3 s");
    assert!(
        first < 3.0 * sigma,
        "first attitude {first}° off, reported 1σ {sigma}°"
    );
    // 60 s of the motion: accuracy, and the reported covariance against the error (the
    // squared error over the squared 1σ, tilt and heading together: a consistent filter
    // keeps it below 3² nearly always).
    let (mut sq, mut outside, n) = (0.0, 0, 60 * RATE_HZ);
    for k in 300..300 + n {
        let s = body.step(k, &wave, &shake, &bias, &mut rng);
        nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        let e = nav.estimate().expect("started");
        let err = angle_deg(&e.attitude, &s.truth);
        sq += err * err;
        if err > 3.0 * e.sigma_tilt.hypot(e.sigma_heading).to_degrees() {
            outside += 1;
        }
    }
    let rms = (sq / n as f64).sqrt();
    // Accelerations of 2 m/s² held for a second and more (12° of gravity direction): a few
    // degrees RMS is what the accelerometer allows.
    assert!(rms < 4.0, "attitude RMS {rms}° while moving");
    assert!(outside < n / 20, "{outside} of {n} samples outside 3σ");
    assert_eq!(nav.counters().realigned, 0);
}

/// 30 s with a 25 µT offset fixed in the body after 10 s of motion: the blocks it disturbs
/// (norm, dip or steadiness give it away) are not fused, and, with the hard iron learned, the
/// offset is learned while the body turns and the magnetometer fused again. Returns the
/// navigator, the samples reported disturbed and the worst attitude error, degrees.
fn carried_magnet(hard_iron: bool) -> (AttitudeNavigator<f64>, u32, f64) {
    let mut rng = Rng::new(3);
    let mut c = config();
    if let Some(m) = c.magnetometer.as_mut() {
        m.hard_iron = hard_iron;
    }
    let mut nav = AttitudeNavigator::new(c).expect("config");
    let mut body = Body {
        attitude: So3::exp(&Vector3::new(0.0, 0.0, 0.5)),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, k) = run(
        &mut nav, &mut body, 0, 10, 2.0, &wave, &still, &bias, &mut rng,
    );
    let mut disturbed = 0;
    let mut worst: f64 = 0.0;
    for k in k..k + 3000 {
        let s = body.step(k, &wave, &still, &bias, &mut rng);
        nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        let r = nav
            .magnetometer(s.t_ns + 1, &(s.mag + MAGNET))
            .expect("mag");
        if r.magnetic == MagneticStatus::Disturbed {
            disturbed += 1;
        }
        worst = worst.max(angle_deg(
            &nav.estimate().expect("started").attitude,
            &s.truth,
        ));
    }
    (nav, disturbed, worst)
}

/// The offset of [`carried_magnet`], µT.
const MAGNET: Vector3<f64> = Vector3::new(15.0, -20.0, 5.0);

#[test]
fn a_magnet_carried_by_the_body_is_detected_and_not_fused() {
    let (_, disturbed, worst) = carried_magnet(false);
    assert!(
        disturbed > 2500,
        "only {disturbed} of 3000 samples reported disturbed"
    );
    // Gyro only for 30 s: the bias known to ~0.05 °/s drifts the heading by ~1.5° at most.
    assert!(
        worst < 3.0,
        "attitude error {worst}° during the disturbance"
    );
}

#[test]
fn a_magnet_carried_by_the_body_is_learned_and_the_magnetometer_fused_again() {
    let (nav, disturbed, worst) = carried_magnet(true);
    let e = nav.estimate().expect("started");
    assert!(nav.counters().new_hard_irons >= 1);
    for i in 0..3 {
        let error = (e.hard_iron[i] - MAGNET[i]).abs();
        assert!(
            error <= 3.0 * e.sigma_hard_iron[i],
            "axis {i}: {error} µT off, 1σ {}",
            e.sigma_hard_iron[i]
        );
    }
    // Disturbed until learned, fused after: fewer disturbed samples than without learning.
    let (_, disturbed_without, _) = carried_magnet(false);
    assert!(
        disturbed < disturbed_without,
        "{disturbed} against {disturbed_without}"
    );
    assert!(worst < 3.0, "attitude error {worst}° with the magnet");
}

#[test]
fn a_wrong_heading_is_recovered_not_locked_out() {
    let mut rng = Rng::new(4);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::identity(),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, k) = run(
        &mut nav, &mut body, 0, 5, 2.0, &still, &still, &bias, &mut rng,
    );
    // The body turns by 90° about up while the gyro reads nothing (a gyro outage the
    // navigator cannot see): the estimate is now 90° off, with a heading σ of about 1°.
    body.attitude = So3::exp(&Vector3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2));
    let mut widened = false;
    let mut k = k;
    for _ in 0..60 * RATE_HZ {
        let s = body.step(k, &still, &still, &bias, &mut rng);
        let r = nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        widened |= r.event == Some(Event::HeadingWidened);
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        k += 1;
    }
    assert!(widened, "the heading was never widened");
    let s = body.step(k, &still, &still, &bias, &mut rng);
    nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
    let e = nav.estimate().expect("started");
    assert!(
        angle_deg(&e.attitude, &s.truth) < 1.5,
        "still {}° off",
        angle_deg(&e.attitude, &s.truth)
    );
}

#[test]
fn a_wrong_tilt_is_recovered_not_locked_out() {
    let mut rng = Rng::new(5);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::identity(),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, k) = run(
        &mut nav, &mut body, 0, 5, 2.0, &still, &still, &bias, &mut rng,
    );
    body.attitude = So3::exp(&Vector3::new(0.5, 0.0, 0.0)); // 29° of roll the gyro never saw
    let mut widened = false;
    let mut k = k;
    for _ in 0..20 * RATE_HZ {
        let s = body.step(k, &still, &still, &bias, &mut rng);
        let r = nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        widened |= r.event == Some(Event::TiltWidened);
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        k += 1;
    }
    assert!(widened, "the tilt was never widened");
    let s = body.step(k, &still, &still, &bias, &mut rng);
    nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
    let e = nav.estimate().expect("started");
    assert!(
        angle_deg(&e.attitude, &s.truth) < 1.5,
        "still {}° off",
        angle_deg(&e.attitude, &s.truth)
    );
}

#[test]
fn bad_input_is_refused_and_leaves_the_navigator_unchanged() {
    let mut rng = Rng::new(6);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::identity(),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, k) = run(
        &mut nav, &mut body, 0, 3, 2.0, &wave, &still, &bias, &mut rng,
    );
    let s = body.step(k, &wave, &still, &bias, &mut rng);
    let before = nav;
    let last = T0 + (k - 1) * STEP_NS;
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    let inf = Vector3::new(0.0, f64::INFINITY, 0.0);
    let range = nav.config().gyro_range;
    let far_gyro = Vector3::new(0.0, -1.02 * range, 0.0);
    let far_accel = Vector3::new(1.02 * nav.config().accel_range, 0.0, 9.8);
    let cases: [(&str, Result<_, NavError>, NavError); 10] = [
        (
            "gyro beyond its full scale",
            nav.clone().imu(s.t_ns, &far_gyro, &s.accel),
            NavError::OutOfRange,
        ),
        (
            "accelerometer beyond its full scale",
            nav.clone().imu(s.t_ns, &s.gyro, &far_accel),
            NavError::OutOfRange,
        ),
        (
            "NaN gyro",
            nav.clone().imu(s.t_ns, &nan, &s.accel),
            NavError::NonFinite,
        ),
        (
            "infinite accel",
            nav.clone().imu(s.t_ns, &s.gyro, &inf),
            NavError::NonFinite,
        ),
        (
            "zero accel",
            nav.clone().imu(s.t_ns, &s.gyro, &Vector3::zeros()),
            NavError::ZeroVector,
        ),
        (
            "repeated time",
            nav.clone().imu(last, &s.gyro, &s.accel),
            NavError::TimeNotIncreasing,
        ),
        (
            "time back",
            nav.clone().imu(last - 1, &s.gyro, &s.accel),
            NavError::TimeNotIncreasing,
        ),
        (
            "NaN field",
            nav.clone().magnetometer(s.t_ns, &nan),
            NavError::NonFinite,
        ),
        (
            "zero field",
            nav.clone().magnetometer(s.t_ns, &Vector3::zeros()),
            NavError::ZeroVector,
        ),
        (
            "field time back",
            nav.clone().magnetometer(T0, &s.mag),
            NavError::TimeNotIncreasing,
        ),
    ];
    for (name, result, expected) in cases {
        assert_eq!(result, Err(expected), "{name}");
    }
    // The same calls on the navigator itself: refused, and nothing but the refusal count moved.
    assert!(nav.imu(s.t_ns, &nan, &s.accel).is_err());
    assert!(nav.magnetometer(s.t_ns, &Vector3::zeros()).is_err());
    assert_eq!(nav.counters().refused, before.counters().refused + 2);
    assert_eq!(nav.estimate(), before.estimate());
    assert_eq!(nav.report(), before.report());
    assert_eq!(nav.filter(), before.filter());
    // And the stream goes on.
    nav.imu(s.t_ns, &s.gyro, &s.accel)
        .expect("a good sample after bad ones");
}

/// A hand-held body whose accelerometer clips for 0.1 s (a knock at 20 g on a ±16 g part), then
/// whose gyro clips for 0.05 s (a flick beyond ±2000 °/s): each sample says so, the clipped
/// block's tilt is not fused, the gyro's clipping widens the attitude, and the estimate stays
/// within its reported uncertainty.
#[test]
fn samples_at_the_rail_are_flagged_and_not_trusted() {
    let mut rng = Rng::new(8);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::identity(),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, mut k) = run(
        &mut nav, &mut body, 0, 5, 2.0, &wave, &shake, &bias, &mut rng,
    );
    let rail = nav.config().accel_range;
    // A twin fed the accelerometer as it should have read: the clipped blocks are the tilt
    // updates the navigator makes fewer than the twin.
    let mut twin = nav;
    let tilt_updates =
        |n: &AttitudeNavigator<f64>| n.counters().gravity_fused + n.counters().gravity_rejected;
    for i in 0..RATE_HZ * 3 / 5 {
        let s = body.step(k, &wave, &shake, &bias, &mut rng);
        k += 1;
        // The knock, over the first 0.1 s: x reads its full scale.
        let knock = i < RATE_HZ / 10;
        let accel = if knock {
            Vector3::new(rail, s.accel.y, s.accel.z)
        } else {
            s.accel
        };
        let r = nav
            .imu(s.t_ns, &s.gyro, &accel)
            .expect("a clipped sample is taken");
        assert_eq!(r.clipped, knock, "sample {i}");
        twin.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        nav.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        twin.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
    }
    // 0.1 s of clipping lies in one or two 0.25 s blocks.
    let skipped = tilt_updates(&twin) - tilt_updates(&nav);
    assert!((1..=2).contains(&skipped), "{skipped} tilt updates skipped");
    let sigma_before = nav.estimate().expect("started").sigma_tilt;
    let range = nav.config().gyro_range;
    // The flick: 2,500 °/s about y for 0.05 s; the gyro reads its full scale (25° short).
    let flick = |_: f64| Vector3::new(0.0, 2500.0_f64.to_radians(), 0.0);
    for _ in 0..10 {
        let s = body.step(k, &flick, &shake, &bias, &mut rng);
        k += 1;
        let gyro = Vector3::new(s.gyro.x, s.gyro.y.min(range), s.gyro.z);
        let r = nav
            .imu(s.t_ns, &gyro, &s.accel)
            .expect("a clipped sample is taken");
        assert!(r.clipped);
    }
    let e = nav.estimate().expect("started");
    assert!(
        e.sigma_tilt > sigma_before,
        "{} against {sigma_before}",
        e.sigma_tilt
    );
    assert_eq!(u64::from(nav.counters().clipped), RATE_HZ / 10 + 10);
    // The turn was short by 25°; the widened covariance (a full-scale turn per interval, 1σ
    // 0.55 rad over the ten) lets the aiding pull the attitude back.
    let (worst, _) = run(
        &mut nav, &mut body, k, 20, 15.0, &wave, &shake, &bias, &mut rng,
    );
    assert!(
        worst < 4.0,
        "attitude error {worst}° 15 s after the clipping"
    );
}

/// A magnetometer that repeats its last sample bit for bit (stuck, or saturated) is not used
/// once it has for `stuck_s`, and is again once it changes.
#[test]
fn a_stuck_magnetometer_is_flagged_and_not_used() {
    let mut rng = Rng::new(9);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::identity(),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, mut k) = run(
        &mut nav, &mut body, 0, 5, 2.0, &wave, &still, &bias, &mut rng,
    );
    let frozen = body.step(k, &wave, &still, &bias, &mut rng).mag;
    let fused_before = nav.counters().heading_fused;
    let mut stuck = 0;
    for _ in 0..5 * RATE_HZ {
        let s = body.step(k, &wave, &still, &bias, &mut rng);
        k += 1;
        nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        let r = nav.magnetometer(s.t_ns + 1, &frozen).expect("mag");
        stuck += u32::from(r.magnetic == MagneticStatus::Stuck);
    }
    // Stuck after 0.5 s of the 5 s; one block's heading may still be fused from the samples
    // before.
    assert_eq!(nav.counters().magnetometer_stuck, stuck);
    let stuck_after = u64::from(stuck);
    assert!(
        stuck_after >= 4 * RATE_HZ,
        "{stuck} of {} samples stuck",
        5 * RATE_HZ
    );
    assert!(nav.counters().heading_fused <= fused_before + 3);
    // Working again: fused again.
    let (worst, _) = run(
        &mut nav, &mut body, k, 10, 0.0, &wave, &still, &bias, &mut rng,
    );
    assert!(nav.report().magnetic != MagneticStatus::Stuck);
    assert!(nav.counters().heading_fused > fused_before + 10);
    assert!(worst < 3.0, "attitude error {worst}°");
}

#[test]
fn a_gap_in_the_imu_restarts_and_says_so() {
    let mut rng = Rng::new(7);
    let mut nav = AttitudeNavigator::new(config()).expect("config");
    let mut body = Body {
        attitude: So3::exp(&Vector3::new(0.0, 0.0, 1.0)),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let (_, k) = run(
        &mut nav, &mut body, 0, 3, 2.0, &still, &still, &bias, &mut rng,
    );
    // Ten seconds missing: the body turned meanwhile.
    body.attitude = So3::exp(&Vector3::new(0.0, 0.0, -2.0));
    let k = k + 10 * RATE_HZ;
    let s = body.step(k, &still, &still, &bias, &mut rng);
    let r = nav.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
    assert_eq!(r.event, Some(Event::Realigned));
    assert_eq!(r.tilt, Validity::Invalid(Reason::Starting));
    assert!(nav.estimate().is_none());
    let (worst, _) = run(
        &mut nav,
        &mut body,
        k + 1,
        5,
        2.0,
        &still,
        &still,
        &bias,
        &mut rng,
    );
    assert!(worst < 1.5, "after the restart: {worst}°");
    assert_eq!(nav.counters().realigned, 1);
}

#[test]
fn an_invalid_configuration_is_refused() {
    let mut c = config();
    c.block_s = -1.0;
    assert_eq!(
        AttitudeNavigator::new(c).err(),
        Some(NavError::InvalidConfig)
    );
    let mut c = config();
    c.startup_s = 10.0;
    assert_eq!(
        AttitudeNavigator::new(c).err(),
        Some(NavError::InvalidConfig)
    );
    let mut c = config();
    c.magnetometer = Some(MagneticConfig::new(0.0, None));
    assert_eq!(
        AttitudeNavigator::new(c).err(),
        Some(NavError::InvalidConfig)
    );
    // The magnetometer's delay: not negative, at most 0.25 s, within the bound it is learned
    // up to (where it is learned).
    for (delay, max, valid) in [
        (-0.001, 0.05, false),
        (0.3, 0.0, false),
        (0.0, 0.3, false),
        (0.06, 0.05, false),
        (0.06, 0.0, true),
        (0.01, 0.05, true),
        (f64::NAN, 0.05, false),
    ] {
        let mut c = config();
        let mut m = MagneticConfig::new(0.5, None);
        m.delay_s = delay;
        m.delay_max_s = max;
        c.magnetometer = Some(m);
        assert_eq!(
            AttitudeNavigator::new(c).is_ok(),
            valid,
            "delay {delay} s, learned up to {max} s"
        );
    }
}

#[test]
fn f32_navigator_matches_f64_on_the_same_stream() {
    let mut rng = Rng::new(8);
    let c64 = config();
    let mut c32 = AttitudeConfig::<f32>::new(FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: GYRO_NOISE as f32,
            gyroscope_random_walk: 2e-5,
            accelerometer_noise_density: ACCEL_NOISE as f32,
            accelerometer_random_walk: 1e-3,
        },
        ..FilterConfig::default()
    });
    c32.magnetometer = Some(MagneticConfig::new(
        MAG_SIGMA as f32,
        Some(Vector3::from(FIELD).cast()),
    ));
    let mut n64 = AttitudeNavigator::new(c64).expect("config");
    let mut n32 = AttitudeNavigator::new(c32).expect("config");
    let mut body = Body {
        attitude: So3::exp(&Vector3::new(0.2, 0.1, 0.3)),
        t: 0.0,
    };
    let bias = Vector3::zeros();
    let mut worst: f64 = 0.0;
    for k in 0..30 * RATE_HZ {
        let s = body.step(k, &wave, &shake, &bias, &mut rng);
        n64.imu(s.t_ns, &s.gyro, &s.accel).expect("imu");
        n64.magnetometer(s.t_ns + 1, &s.mag).expect("mag");
        n32.imu(s.t_ns, &s.gyro.cast(), &s.accel.cast())
            .expect("imu f32");
        n32.magnetometer(s.t_ns + 1, &s.mag.cast())
            .expect("mag f32");
        if let (Some(a), Some(b)) = (n64.estimate(), n32.estimate()) {
            worst = worst.max(angle_deg(&a.attitude, &b.attitude.cast()));
            let p = n32.filter().expect("started").covariance();
            assert!(
                p.iter().all(|x| x.is_finite()) && p.cholesky().is_some(),
                "f32 P not SPD"
            );
        }
    }
    // Same decisions, f32 rounding: far below the sensors' error.
    assert!(worst < 0.05, "f32 and f64 differ by {worst}°");
}

//! The INS navigator on synthetic streams with exact truth: delayed and out-of-order
//! measurements, refusals that leave it unchanged, start-up from a late fix, IMU gaps, and the
//! GNSS faults it must detect (a frozen receiver, a persistent disagreement).

use estimator_core::eskf::FilterConfig;
use estimator_core::lie::LieGroup;
use estimator_core::nav::{
    AidStatus, Aiding, AttitudeConfig, GnssFix, InsConfig, InsEvent, InsNavigator, MagneticConfig,
    NavError, Reason, Validity,
};
use nalgebra::Vector3;

const T0: u64 = 1_000_000_000;
const IMU_NS: u64 = 5_000_000; // 200 Hz
const FIELD: [f64; 3] = [0.0, 20.0, -40.0];
const STILL_S: f64 = 4.0;
const A: f64 = 1.5; // m/s², peak acceleration along east

/// Truth at `t` s after the start: at rest for `STILL_S`, then along east with
/// `a = A sin(τ/2)` (τ from the end of the rest), level, facing east: `(p, v, a)`.
fn truth(t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let tau = (t - STILL_S).max(0.0);
    let a = A * (0.5 * tau).sin();
    let v = 2.0 * A * (1.0 - (0.5 * tau).cos());
    let s = 2.0 * A * (tau - 2.0 * (0.5 * tau).sin());
    (
        Vector3::new(s, 0.0, 0.0),
        Vector3::new(v, 0.0, 0.0),
        Vector3::new(a, 0.0, 0.0),
    )
}

fn seconds(t_ns: u64) -> f64 {
    (t_ns - T0) as f64 * 1e-9
}

fn config() -> InsConfig<f64> {
    let mut attitude = AttitudeConfig::new(FilterConfig::default());
    // The streams of these tests are the motion's values at each sample's instant.
    attitude.instantaneous_imu = true;
    attitude.magnetometer = Some(MagneticConfig::new(0.5, Some(Vector3::from(FIELD))));
    InsConfig::new(attitude)
}

/// A measurement of the stream: its validity time and what it is.
#[derive(Clone, Copy, Debug)]
enum Aid {
    Gnss(GnssFix<f64>),
    Mag(Vector3<f64>),
}

/// The IMU at `k` (noise-free, level, facing east: body = world).
fn imu(k: u64) -> (u64, Vector3<f64>, Vector3<f64>) {
    let t = T0 + k * IMU_NS;
    let (_, _, a) = truth(seconds(t));
    (t, Vector3::zeros(), a + Vector3::new(0.0, 0.0, 9.81))
}

/// Magnetometer at 50 Hz and fixes at 5 Hz (after `first_fix_s`), each with its validity time.
fn aids(duration_s: f64, first_fix_s: f64) -> Vec<(u64, Aid)> {
    let mut out = Vec::new();
    let n = (duration_s / 0.02) as u64;
    for j in 1..n {
        let t = T0 + j * 20_000_000;
        out.push((t, Aid::Mag(Vector3::from(FIELD))));
        if j % 10 == 0 && seconds(t) >= first_fix_s {
            let (p, v, _) = truth(seconds(t));
            out.push((t, Aid::Gnss(GnssFix::new(p, Some(v), 0.5, 0.05))));
        }
    }
    out
}

fn give(nav: &mut InsNavigator<f64>, t: u64, aid: &Aid) -> Result<(), NavError> {
    match aid {
        Aid::Gnss(fix) => nav.gnss(t, fix).map(|_| ()),
        Aid::Mag(m) => nav.magnetometer(t, m).map(|_| ()),
    }
}

/// Time (ns), position and velocity of the estimate at one IMU sample.
type Track = Vec<(u64, Vector3<f64>, Vector3<f64>)>;

/// Runs the stream with every measurement delivered at `arrival(validity time, index)`; returns
/// the estimate's position at every IMU sample once the INS runs, and the navigator.
fn run(
    duration_s: f64,
    deliveries: &[(u64, u64, Aid)], // (arrival, validity, aid), sorted by arrival
) -> (Track, InsNavigator<f64>) {
    let mut nav = InsNavigator::<f64>::new(config()).unwrap();
    let mut out = Vec::new();
    let mut next = 0;
    let n = (duration_s * 200.0) as u64;
    for k in 0..n {
        let (t, g, a) = imu(k);
        while let Some((arrival, valid, aid)) = deliveries.get(next) {
            if *arrival > t {
                break;
            }
            give(&mut nav, *valid, aid).unwrap();
            next += 1;
        }
        nav.imu(t, &g, &a).unwrap();
        if let Some(e) = nav.estimate() {
            out.push((t, e.state.position, e.state.velocity));
        }
    }
    (out, nav)
}

/// Delivered `delay_ns` after validity, in time order.
fn delayed(aids: &[(u64, Aid)], delay_ns: u64) -> Vec<(u64, u64, Aid)> {
    aids.iter().map(|(t, a)| (t + delay_ns, *t, *a)).collect()
}

#[test]
fn ins_navigator_out_of_order_within_horizon_matches_in_order_f64() {
    let aids = aids(30.0, 5.0);
    let in_order = delayed(&aids, 200_000_000);
    // Each measurement delivered 20–280 ms after its time, by a fixed pseudo-random draw:
    // arrival order differs from validity order once the INS runs (it starts at the first fix,
    // 5 s, delivered by 5.2 s). Until 1 s after that fix both runs get the same stream: the
    // alignment takes samples as they come and drops a late one (a magnetometer sample fewer
    // changes the start's heading variance, so the two runs would start from different
    // covariances, not differ in how the horizon orders them).
    let shuffled_from = T0 + 6_000_000_000;
    let mut shuffled: Vec<(u64, u64, Aid)> = aids
        .iter()
        .enumerate()
        .map(|(i, (t, a))| {
            let jitter = (i as u64).wrapping_mul(2_654_435_761) % 260_000_000;
            if *t < shuffled_from {
                (t + 200_000_000, *t, *a)
            } else {
                (t + 20_000_000 + jitter, *t, *a)
            }
        })
        .collect();
    shuffled.sort_by_key(|d| d.0);
    let swapped = shuffled.windows(2).filter(|w| w[1].1 < w[0].1).count();
    assert!(
        swapped > 100,
        "only {swapped} measurements arrive out of order"
    );
    let (a, _) = run(30.0, &in_order);
    let (b, nav) = run(30.0, &shuffled);
    assert!(nav.counters().gnss_position_fused > 100);
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| {
            assert_eq!(x.0, y.0);
            (x.1 - y.1).norm().max((x.2 - y.2).norm())
        })
        .fold(0.0, f64::max);
    assert!(
        worst <= 1e-5,
        "in-order and shuffled runs differ by {worst}"
    );
}

#[test]
fn ins_navigator_fuses_delayed_fixes_at_their_own_time() {
    // Fixes valid 0.2 s before they arrive, on a body reaching 6 m/s: stamped with their own
    // time they agree with the truth; stamped on arrival they lag it by v·0.2 s ≈ 1.2 m.
    let aids = aids(30.0, 5.0);
    let (good, _) = run(30.0, &delayed(&aids, 200_000_000));
    let stamped_on_arrival: Vec<(u64, u64, Aid)> = aids
        .iter()
        .map(|(t, a)| (t + 200_000_000, t + 200_000_000, *a))
        .collect();
    let (late, _) = run(30.0, &stamped_on_arrival);
    let rms = |run: &[(u64, Vector3<f64>, Vector3<f64>)]| {
        let tail: Vec<f64> = run
            .iter()
            .filter(|(t, ..)| seconds(*t) > 15.0)
            .map(|(t, p, _)| (p - truth(seconds(*t)).0).norm_squared())
            .collect();
        (tail.iter().sum::<f64>() / tail.len() as f64).sqrt()
    };
    let (e_good, e_late) = (rms(&good), rms(&late));
    assert!(
        e_good < 0.1,
        "delayed fixes at their own time: {e_good} m RMS"
    );
    assert!(
        e_late > 5.0 * e_good,
        "stamped on arrival: {e_late} m vs {e_good} m"
    );
}

#[test]
fn ins_navigator_refusals_leave_it_unchanged() {
    let aids = aids(10.0, 5.0);
    let (_, mut nav) = run(10.0, &delayed(&aids, 200_000_000));
    assert!(nav.estimate().is_some());
    let t_new = nav.report().t_ns;
    let fix = GnssFix::new(
        Vector3::new(1.0, 2.0, 3.0),
        Some(Vector3::zeros()),
        1.0,
        0.1,
    );
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    let before = nav;
    let cases: [(&str, Result<(), NavError>, NavError); 11] = [
        (
            "too old",
            nav.gnss(t_new - 400_000_000, &fix).map(|_| ()),
            NavError::TooOld,
        ),
        (
            "in the future",
            nav.gnss(t_new + 1_000_000_000, &fix).map(|_| ()),
            NavError::InFuture,
        ),
        (
            "non-finite fix",
            nav.gnss(
                t_new,
                &GnssFix {
                    position: nan,
                    ..fix
                },
            )
            .map(|_| ()),
            NavError::NonFinite,
        ),
        (
            "zero sigma",
            nav.gnss(
                t_new,
                &GnssFix {
                    sigma_position: 0.0,
                    ..fix
                },
            )
            .map(|_| ()),
            NavError::InvalidSigma,
        ),
        (
            "negative sigma",
            nav.gnss(
                t_new,
                &GnssFix {
                    sigma_velocity: -1.0,
                    ..fix
                },
            )
            .map(|_| ()),
            NavError::InvalidSigma,
        ),
        (
            "zero field",
            nav.magnetometer(t_new, &Vector3::zeros()).map(|_| ()),
            NavError::ZeroVector,
        ),
        (
            "repeated IMU time",
            nav.imu(t_new, &Vector3::zeros(), &Vector3::z()).map(|_| ()),
            NavError::TimeNotIncreasing,
        ),
        (
            "1 µm position sigma",
            nav.gnss(
                t_new,
                &GnssFix {
                    sigma_position: 1e-6,
                    ..fix
                },
            )
            .map(|_| ()),
            NavError::InvalidSigma,
        ),
        (
            "a gyro at 1e4 rad/s",
            nav.imu(t_new + IMU_NS, &Vector3::new(0.0, 0.0, 1e4), &Vector3::z())
                .map(|_| ()),
            NavError::OutOfRange,
        ),
        (
            "an accelerometer at 1e28 m/s²",
            nav.imu(
                t_new + IMU_NS,
                &Vector3::zeros(),
                &Vector3::new(0.0, 0.0, 1e28),
            )
            .map(|_| ()),
            NavError::OutOfRange,
        ),
        (
            "non-finite IMU",
            nav.imu(t_new + IMU_NS, &nan, &Vector3::z()).map(|_| ()),
            NavError::NonFinite,
        ),
    ];
    for (what, got, want) in cases {
        assert_eq!(got, Err(want), "{what}");
    }
    // Bit for bit what it was, but for the refusal counter.
    assert_eq!(nav.counters().refused, before.counters().refused + 11);
    let without_count = |n: &InsNavigator<f64>| {
        format!("{n:?}").replace(&format!("refused: {}", n.counters().refused), "")
    };
    assert_eq!(without_count(&nav), without_count(&before));
    // A duplicate fix (same time twice) is refused too.
    nav.gnss(t_new - 100_000_000, &fix).unwrap();
    assert_eq!(
        nav.gnss(t_new - 100_000_000, &fix).map(|_| ()),
        Err(NavError::TimeNotIncreasing)
    );
}

#[test]
fn ins_navigator_uses_minutes_of_imu_before_a_late_first_fix() {
    // Two minutes of IMU and magnetometer at rest, then fixes: the alignment runs all along,
    // and the INS starts at the first fix with the attitude it learned.
    let still = 120.0;
    let mut nav = InsNavigator::<f64>::new(config()).unwrap();
    let mut started_at = None;
    for k in 0..((still + 10.0) * 200.0) as u64 {
        let t = T0 + k * IMU_NS;
        let r = nav
            .imu(t, &Vector3::zeros(), &Vector3::new(0.0, 0.0, 9.81))
            .unwrap();
        if r.event == Some(InsEvent::Started) {
            started_at = Some(seconds(t));
        }
        if k % 4 == 0 {
            nav.magnetometer(t, &Vector3::from(FIELD)).unwrap();
        }
        if seconds(t) < still {
            assert_eq!(r.validity.position, Validity::Invalid(Reason::NoFix));
        } else if k % 40 == 0 {
            let fix = GnssFix::new(
                Vector3::new(3.0, 4.0, 5.0),
                Some(Vector3::zeros()),
                1.0,
                0.1,
            );
            nav.gnss(t - 100_000_000, &fix).unwrap();
        }
    }
    let started = started_at.expect("the INS started");
    assert!(
        started > still && started < still + 1.0,
        "started at {started} s"
    );
    let e = nav.estimate().unwrap();
    assert!((e.state.position - Vector3::new(3.0, 4.0, 5.0)).norm() < 1.0);
    let v = nav.report().validity;
    assert!(
        v.tilt.is_valid() && v.heading.is_valid() && v.position.is_valid() && v.velocity.is_valid()
    );
}

#[test]
fn ins_navigator_realigns_after_an_imu_gap() {
    let aids = aids(10.0, 5.0);
    let (_, mut nav) = run(10.0, &delayed(&aids, 0));
    assert!(nav.estimate().is_some());
    // 10 s without IMU samples: the estimate is no longer valid, and the navigator says so.
    let t = nav.report().t_ns + 10_000_000_000;
    let r = nav
        .imu(t, &Vector3::zeros(), &Vector3::new(0.0, 0.0, 9.81))
        .unwrap();
    assert_eq!(r.event, Some(InsEvent::Realigned));
    assert!(nav.estimate().is_none());
    assert!(!r.validity.position.is_valid() && !r.validity.tilt.is_valid());
    assert_eq!(nav.counters().realigned, 1);
}

/// Runs `duration_s` at rest with fixes at `position(t)`, returning every report.
fn at_rest_with_fixes(
    duration_s: f64,
    position: impl Fn(f64) -> Vector3<f64>,
    velocity: impl Fn(f64) -> Vector3<f64>,
) -> (
    Vec<(f64, estimator_core::nav::InsReport<f64>)>,
    InsNavigator<f64>,
) {
    let mut nav = InsNavigator::<f64>::new(config()).unwrap();
    let mut reports = Vec::new();
    for k in 0..(duration_s * 200.0) as u64 {
        let t = T0 + k * IMU_NS;
        if k % 4 == 0 {
            nav.magnetometer(t, &Vector3::from(FIELD)).unwrap();
        }
        if k % 40 == 20 && k > 200 {
            let s = seconds(t);
            nav.gnss(t, &GnssFix::new(position(s), Some(velocity(s)), 0.5, 0.05))
                .unwrap();
        }
        let r = nav
            .imu(t, &Vector3::zeros(), &Vector3::new(0.0, 0.0, 9.81))
            .unwrap();
        reports.push((seconds(t), r));
    }
    (reports, nav)
}

#[test]
fn ins_navigator_holds_through_a_jump_of_the_fixes() {
    // Fixes jump 50 m east from 20 s to 35 s: within 1 s the position is flagged; a jump is the
    // receiver's (the estimate cannot move 50 m in one fix interval), so the estimate is kept,
    // never reset, and valid again within 1 s of the fixes coming back.
    let step = |s: f64| {
        if (20.0..35.0).contains(&s) {
            Vector3::new(50.0, 0.0, 0.0)
        } else {
            Vector3::zeros()
        }
    };
    let (reports, nav) = at_rest_with_fixes(45.0, step, |_| Vector3::zeros());
    let flagged = first(&reports, 20.0, |r| {
        r.validity.position == Validity::Invalid(Reason::FixesDisagree)
    });
    assert!(flagged < 21.0, "flagged at {flagged} s");
    assert!(reports
        .iter()
        .all(|(_, r)| r.event != Some(InsEvent::PositionReset)));
    let back = first(&reports, 35.0, |r| r.validity.position.is_valid());
    assert!(back < 36.0, "valid again at {back} s");
    assert!(reports
        .iter()
        .filter(|(s, _)| (flagged..35.0).contains(s))
        .all(|(_, r)| !r.validity.position.is_valid()));
    assert!(nav.estimate().unwrap().state.position.norm() < 1.0);
}

#[test]
fn ins_navigator_resets_when_the_fixes_drift_away_for_good() {
    // Fixes leave the estimate gradually (2 m/s east from 20 s, reported as standing still):
    // not a jump, so after `gnss_reset_s` (10 s) of rejected fixes the estimate is taken for
    // the wrong one and reset to them, then confirmed by 1 s of fused fixes.
    let drift = |s: f64| Vector3::new(2.0 * (s - 20.0).max(0.0), 0.0, 0.0);
    let (reports, _) = at_rest_with_fixes(50.0, drift, |_| Vector3::zeros());
    let flagged = first(&reports, 20.0, |r| {
        r.validity.position == Validity::Invalid(Reason::FixesDisagree)
    });
    let reset = first(&reports, 0.0, |r| r.event == Some(InsEvent::PositionReset));
    assert!(
        reset >= flagged + 9.0 && reset < flagged + 11.0,
        "flagged {flagged} s, reset {reset} s"
    );
    assert!(reports
        .iter()
        .filter(|(s, _)| (flagged..reset).contains(s))
        .all(|(_, r)| !r.validity.position.is_valid()));
}

/// The first time at or after `from` s when `pred` holds.
fn first(
    reports: &[(f64, estimator_core::nav::InsReport<f64>)],
    from: f64,
    pred: impl Fn(&estimator_core::nav::InsReport<f64>) -> bool,
) -> f64 {
    reports
        .iter()
        .find(|(s, r)| *s >= from && pred(r))
        .map(|(s, _)| *s)
        .expect("it happens")
}

#[test]
fn ins_navigator_refuses_a_frozen_receiver() {
    // A moving body whose receiver repeats its last fix: refused as frozen (the report says
    // `Faulty`), never fused.
    let aids = aids(30.0, 5.0);
    let mut frozen = Vec::new();
    let mut last = None;
    for (t, a) in &aids {
        let a = match a {
            Aid::Gnss(f) if seconds(*t) >= 20.0 => Aid::Gnss(*last.get_or_insert(*f)),
            other => *other,
        };
        frozen.push((*t, a));
    }
    let (_, nav) = run(30.0, &delayed(&frozen, 0));
    // The body stops near 29 s (the truth's velocity returns to zero): there a repeated fix
    // may be a receiver at rest, and the gate judges it (it is 9 s stale: rejected).
    let c = nav.counters();
    assert!(c.gnss_frozen >= 38, "{c:?}");
    assert_eq!(c.gnss_frozen + c.gnss_position_rejected, 48, "{c:?}");
    assert_ne!(nav.report().gnss, AidStatus::Fused);
    let e = nav.estimate().unwrap();
    // Dead reckoning on a noise-free IMU: still on the truth.
    let truth_now = truth(seconds(nav.report().t_ns)).0;
    assert!((e.state.position - truth_now).norm() < 1.0);
}

/// At rest with a barometer; `mutate(k, t, gyro, accel, field, baro, gnss?)` alters the stream.
/// Returns every report and the navigator.
#[allow(clippy::type_complexity)]
fn at_rest_stream(
    duration_s: f64,
    mutate: impl Fn(f64, &mut Vector3<f64>, &mut Vector3<f64>, &mut Vector3<f64>, &mut f64, &mut bool),
) -> (
    Vec<(f64, estimator_core::nav::InsReport<f64>)>,
    InsNavigator<f64>,
) {
    let mut c = config();
    c.barometer_sigma = Some(0.5);
    let mut nav = InsNavigator::<f64>::new(c).unwrap();
    let mut reports = Vec::new();
    for k in 0..(duration_s * 200.0) as u64 {
        let t = T0 + k * IMU_NS;
        let s = seconds(t);
        // A little deterministic noise: a real sensor never repeats its values exactly.
        let wobble = |i: u64| ((k * 7 + i * 13) % 17) as f64 * 1e-4;
        let mut gyro = Vector3::new(wobble(1), wobble(2), wobble(3));
        let mut accel = Vector3::new(wobble(4), wobble(5), 9.81 + wobble(6));
        let mut field = Vector3::from(FIELD);
        let mut baro = 0.0;
        let mut gnss = true;
        mutate(s, &mut gyro, &mut accel, &mut field, &mut baro, &mut gnss);
        if k % 4 == 0 {
            nav.magnetometer(t, &field).unwrap();
        }
        if k % 8 == 0 {
            nav.barometer(t, baro).unwrap();
        }
        if k % 40 == 20 && k > 200 && gnss {
            nav.gnss(
                t,
                &GnssFix::new(Vector3::zeros(), Some(Vector3::zeros()), 0.5, 0.05),
            )
            .unwrap();
        }
        reports.push((s, nav.imu(t, &gyro, &accel).unwrap()));
    }
    (reports, nav)
}

#[test]
fn ins_navigator_rejects_a_rotated_magnetometer_and_takes_it_back() {
    // The field read rotated by 90° about the body's z for 20 s: rejected (never fused) while
    // it lasts, fused again within 1 s after; the heading holds.
    let (reports, nav) = at_rest_stream(40.0, |s, _, _, field, _, _| {
        if (15.0..35.0).contains(&s) {
            *field = Vector3::new(-field.y, field.x, field.z);
        }
    });
    let detected = first(&reports, 15.0, |r| {
        matches!(r.magnetometer, AidStatus::Rejected | AidStatus::Faulty)
    });
    assert!(detected < 16.0, "detected at {detected} s");
    assert!(reports
        .iter()
        .filter(|(s, _)| (15.5..35.0).contains(s))
        .all(|(_, r)| r
            .fused
            .is_none_or(|f| !(f.accepted && f.aid == Aiding::Magnetometer))));
    let back = first(&reports, 35.0, |r| r.magnetometer == AidStatus::Fused);
    assert!(back < 36.0, "fused again at {back} s");
    let (_, _, yaw) = nav
        .estimate()
        .unwrap()
        .state
        .attitude
        .quaternion()
        .euler_angles();
    assert!(yaw.abs().to_degrees() < 2.0, "yaw {} °", yaw.to_degrees());
}

#[test]
fn ins_navigator_rejects_a_barometer_step() {
    // The barometer reads 20 m high for 15 s: rejected, the height held by GNSS.
    let (reports, nav) = at_rest_stream(40.0, |s, _, _, _, baro, _| {
        if (15.0..30.0).contains(&s) {
            *baro = 20.0;
        }
    });
    let detected = first(&reports, 15.0, |r| r.barometer == AidStatus::Rejected);
    assert!(detected < 16.0, "detected at {detected} s");
    let back = first(&reports, 30.0, |r| r.barometer == AidStatus::Fused);
    assert!(back < 31.0, "fused again at {back} s");
    assert!(nav.estimate().unwrap().state.position.z.abs() < 1.0);
}

#[test]
fn ins_navigator_sees_a_gnss_outage_and_takes_fixes_back() {
    // No fixes for 60 s: GNSS stale within 1 s; the first fix after is fused and the position
    // valid again.
    let (reports, _) = at_rest_stream(100.0, |s, _, _, _, _, gnss| {
        *gnss = !(20.0..80.0).contains(&s);
    });
    let stale = first(&reports, 20.0, |r| r.gnss == AidStatus::Stale);
    assert!(stale < 21.0, "stale at {stale} s");
    let back = first(&reports, 80.0, |r| r.gnss == AidStatus::Fused);
    assert!(back < 81.0, "fused again at {back} s");
    let valid = first(&reports, 80.0, |r| r.validity.position.is_valid());
    assert!(valid < 81.0, "valid again at {valid} s");
}

#[test]
fn ins_navigator_widens_for_a_clipped_accelerometer_and_a_stuck_gyro() {
    // Vertical accelerometer clipped at 2.5 g under a 3 g vibration for 2 s, then the z gyro
    // stuck for 2 s: each flagged as an IMU fault within 0.1 s, and the velocity (clip) and
    // attitude (stuck) covariance widened.
    let (reports, _) = at_rest_stream(40.0, |s, gyro, accel, _, _, _| {
        if (15.0..17.0).contains(&s) {
            let vib = 3.0 * 9.81 * (2.0 * std::f64::consts::PI * 25.0 * s).sin();
            accel.z = (accel.z + vib).clamp(-2.5 * 9.81, 2.5 * 9.81);
        }
        if (25.0..27.0).contains(&s) {
            gyro.z = 0.01;
        }
    });
    let clip = first(&reports, 15.0, |r| r.imu_fault);
    assert!(clip < 15.1, "clip seen at {clip} s");
    let stuck = first(&reports, 25.0, |r| r.imu_fault);
    assert!(stuck < 25.2, "stuck axis seen at {stuck} s");
    assert!(reports
        .iter()
        .filter(|(s, _)| (18.0..25.0).contains(s))
        .all(|(_, r)| !r.imu_fault));
    assert!(reports
        .iter()
        .any(|(s, r)| (15.0..17.0).contains(s) && r.event == Some(InsEvent::ImuFault)));
}

#[test]
fn ins_navigator_takes_a_large_value_met_three_times_as_a_rail_but_not_one_met_twice() {
    // 25 m/s² (above 2 g) on the vertical axis at two samples 15 ms apart: noise, not a rail;
    // at three samples within 16: saturated.
    let at = |times: &'static [f64]| {
        at_rest_stream(20.0, move |s, _, accel, _, _, _| {
            if times.iter().any(|t| (s - t).abs() < 1e-6) {
                accel.z = 25.0;
            }
        })
        .0
    };
    let twice = at(&[15.0, 15.015]);
    assert!(twice.iter().all(|(_, r)| !r.imu_fault));
    let thrice = at(&[15.0, 15.015, 15.03]);
    let flagged = first(&thrice, 14.0, |r| r.imu_fault);
    assert!((flagged - 15.03).abs() < 1e-6, "flagged at {flagged} s");
}

#[test]
fn ins_navigator_widens_the_velocity_for_a_vibration_its_samples_cannot_follow() {
    // A vertical vibration of ±1 g at 23.3 Hz from 15 s to 20 s (0.07 m/s, 0.5 mm: at rest for
    // the fixes): the trapezoid rule over 5 ms errs by dt |d₂| / 12 ≈ 2 mm/s per interval, and
    // the velocity is widened for it. A smooth 0.5 Hz swing of ±0.01 g (the same 0.03 m/s order
    // of motion) is followed by the samples and widens nothing. Neither is taken as saturated.
    let run = |hz: f64, g: f64| {
        let (reports, nav) = at_rest_stream(20.0, move |s, _, accel, _, _, _| {
            if s >= 15.0 {
                accel.z += g * 9.81 * (2.0 * std::f64::consts::PI * hz * (s - 15.0)).sin();
            }
        });
        assert!(
            reports.iter().all(|(_, r)| !r.imu_fault),
            "{hz} Hz taken as a fault"
        );
        nav.estimate().unwrap().covariance[1][(2, 2)].sqrt()
    };
    let still = run(0.0, 0.0);
    let smooth = run(0.5, 0.01);
    let vibrating = run(23.3, 1.0);
    assert!(
        (smooth / still - 1.0).abs() < 0.01,
        "smooth {smooth} against {still} m/s"
    );
    assert!(
        vibrating > 1.5 * still,
        "vibrating {vibrating} against {still} m/s"
    );
}

#[test]
fn ins_navigator_does_not_start_from_an_outlier() {
    // The first fix is 50 m off: the INS starts only on two fixes that agree, so from the
    // next good pair, and never reports a valid position 50 m wrong.
    let outlier = |s: f64| {
        if s < 1.2 {
            Vector3::new(50.0, 0.0, 0.0)
        } else {
            Vector3::zeros()
        }
    };
    let (reports, nav) = at_rest_with_fixes(10.0, outlier, |_| Vector3::zeros());
    let started = first(&reports, 0.0, |r| r.event == Some(InsEvent::Started));
    assert!(started > 1.2 && started < 2.0, "started at {started} s");
    assert!(nav.estimate().unwrap().state.position.norm() < 1.0);
    assert!(nav.counters().unused >= 2, "{:?}", nav.counters());
}

/// Without a magnetometer, the stream's fixes with their velocities turned by `turn` about
/// the vertical (a receiver whose velocities disagree with its positions); returns the last
/// report, the counters and the estimate's yaw (the truth faces east: yaw 0).
fn without_magnetometer(
    turn: f64,
) -> (
    estimator_core::nav::InsReport<f64>,
    estimator_core::nav::InsCounters,
    f64,
) {
    let mut c = config();
    c.attitude.magnetometer = None;
    let mut nav = InsNavigator::<f64>::new(c).unwrap();
    let (s, co) = turn.sin_cos();
    let fixes: Vec<(u64, Aid)> = aids(40.0, 5.0)
        .into_iter()
        .filter_map(|(t, a)| match a {
            Aid::Gnss(f) => {
                let v = f.velocity.unwrap();
                let turned = Vector3::new(co * v.x - s * v.y, s * v.x + co * v.y, v.z);
                Some((
                    t,
                    Aid::Gnss(GnssFix::new(f.position, Some(turned), 0.5, 0.05)),
                ))
            }
            Aid::Mag(_) => None,
        })
        .collect();
    let mut next = 0;
    for k in 0..(40.0 * 200.0) as u64 {
        let (t, g, a) = imu(k);
        while let Some((valid, aid)) = fixes.get(next) {
            if *valid > t {
                break;
            }
            give(&mut nav, *valid, aid).unwrap();
            next += 1;
        }
        nav.imu(t, &g, &a).unwrap();
    }
    let q = nav.estimate().unwrap().state.attitude;
    let fwd = q.act(&Vector3::x());
    (*nav.report(), *nav.counters(), fwd.y.atan2(fwd.x))
}

#[test]
fn ins_navigator_without_a_magnetometer_takes_its_heading_only_from_velocities_the_positions_confirm(
) {
    // The vehicle accelerates east, facing east. With its true velocities the GNSS track
    // resolves the heading; with velocities turned by 90° (north, while the positions move
    // east) the comparison of velocities and positions finds them wrong, the bank takes none
    // of them, and the heading is reported unresolved to the end rather than locked 90° off.
    let (report, counters, yaw) = without_magnetometer(0.0);
    assert!(report.validity.heading.is_valid(), "{report:?}");
    assert!(counters.heading_resets >= 1);
    assert_eq!(counters.gnss_velocity_inconsistent, 0, "{counters:?}");
    assert!(yaw.abs() < 2f64.to_radians(), "yaw {}", yaw.to_degrees());

    let (report, counters, _) = without_magnetometer(core::f64::consts::FRAC_PI_2);
    assert_eq!(
        report.validity.heading,
        Validity::Invalid(Reason::HeadingUnresolved),
        "{counters:?}"
    );
    assert!(counters.gnss_velocity_inconsistent > 0, "{counters:?}");
}

//! The rover scenarios (`rover`, `rover_moving`) and `car_no_mag`, checked on the simulated
//! ground truth alone: a slow rover (0.2-0.5 m/s, varying) heading along its track on rough
//! ground (roll and pitch within ±15°, no sideways motion), no magnetometer, and a recording that
//! starts while the rover already drives.

use estimator_core::lie::LieGroup;
use host_sim::dataset::read::{Truth, TruthStream};
use host_sim::dataset::write::simulate;
use host_sim::scenario::{builtin_scenarios, Scenario, ROVER_MOVING_FROM_S};
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("estimator-rover-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn scenario(name: &str) -> Scenario {
    builtin_scenarios()
        .into_iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("built-in scenario {name}"))
}

/// Every ground-truth row of the dataset `dir`.
fn truth(dir: &Path) -> Vec<Truth> {
    let mut stream = TruthStream::open(dir).expect("ground truth");
    let mut rows = Vec::new();
    while let Some(t) = stream.next_truth().expect("truth row") {
        rows.push(t);
    }
    rows
}

/// The timestamp of the first data row of a CSV file.
fn first_stamp(path: &Path) -> u64 {
    let text = std::fs::read_to_string(path).expect("csv");
    let line = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .expect("a data row");
    line.split(',').next().unwrap().parse().expect("timestamp")
}

/// Speed, roll and pitch (degrees) and lateral body velocity of one truth row.
fn motion(t: &Truth) -> (f64, f64, f64, f64) {
    let (roll, pitch, _) = t.attitude.quaternion().euler_angles();
    let body = t.attitude.inverse().act(&t.velocity);
    (
        t.velocity.norm(),
        roll.to_degrees(),
        pitch.to_degrees(),
        body.y,
    )
}

#[test]
fn rover_is_slow_tilted_and_moves_along_its_heading() {
    let sc = scenario("rover");
    assert!(sc.mag.is_none(), "no magnetometer");
    assert_eq!(sc.duration_s, 360.0);
    assert_eq!(sc.imu.rate_hz, 200.0);
    let gnss = sc.gnss.as_ref().expect("GNSS");
    assert_eq!((gnss.rate_hz, gnss.sigma_horizontal), (5.0, 1.5));
    // The replay's defaults: the navigator learns from the track that it does not move
    // sideways.
    assert_eq!(
        (sc.replay.lateral_velocity_sigma, sc.replay.travel.as_str()),
        (0.0, "detect")
    );
    sc.validate().expect("valid");

    let dir = tmp("rover");
    simulate(&sc, 1, &dir).expect("simulate");
    assert!(dir.join("imu0/data.csv").is_file());
    assert!(dir.join("gnss0/data.csv").is_file());
    assert!(!dir.join("mag0").exists(), "no magnetometer stream");
    let rows = truth(&dir);
    assert_eq!(rows.len(), 360 * 200 + 1);

    let ramp_s = sc.trajectory().expect("trajectory").ramp_s;
    let moving_from = sc.start_ns + ((sc.static_s + ramp_s) * 1e9) as u64;
    let at_rest_until = sc.start_ns + (sc.static_s * 1e9) as u64;
    let mut speeds = Vec::new();
    let (mut max_tilt, mut max_lateral) = (0.0_f64, 0.0_f64);
    for t in &rows {
        let (speed, roll, pitch, lateral) = motion(t);
        if t.t_ns <= at_rest_until {
            assert_eq!(speed, 0.0, "at rest at {} ns", t.t_ns);
        }
        assert!(
            roll.abs() <= 15.0 && pitch.abs() <= 15.0,
            "roll {roll:.2}°, pitch {pitch:.2}° at {} ns",
            t.t_ns
        );
        max_tilt = max_tilt.max(roll.abs()).max(pitch.abs());
        max_lateral = max_lateral.max(lateral.abs());
        if t.t_ns >= moving_from {
            speeds.push(speed);
        }
    }
    speeds.sort_by(f64::total_cmp);
    let (min, max) = (speeds[0], speeds[speeds.len() - 1]);
    let median = speeds[speeds.len() / 2];
    println!(
        "rover: speed {min:.3} to {max:.3} m/s (median {median:.3}), tilt up to {max_tilt:.2}°, \
         lateral body velocity up to {max_lateral:.4} m/s"
    );
    assert!(min >= 0.15 && max <= 0.55, "speed {min} to {max} m/s");
    assert!((0.3..=0.4).contains(&median), "median speed {median} m/s");
    // The speed varies (0.35 ± 0.12 m/s by design), which tells forward from backward driving.
    assert!(max - min >= 0.15, "speed varies only {min} to {max} m/s");
    // Rough ground: the terrain tilts the body by several degrees.
    assert!(max_tilt >= 8.0, "tilt up to {max_tilt}°");
    assert!(
        max_lateral < 0.05,
        "lateral body velocity {max_lateral} m/s"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rover_moving_is_recorded_while_driving() {
    let sc = scenario("rover_moving");
    let rover = scenario("rover");
    assert_eq!(sc.record_from_s, ROVER_MOVING_FROM_S);
    assert!(sc.record_from_s > rover.static_s + 2.0, "after the start");
    assert_eq!(
        Scenario {
            name: rover.name.clone(),
            description: rover.description.clone(),
            record_from_s: 0.0,
            ..sc.clone()
        },
        rover,
        "the rover's scenario but for the recording's start"
    );
    sc.validate().expect("valid");

    let dir = tmp("rover_moving");
    simulate(&sc, 1, &dir).expect("simulate");
    assert!(!dir.join("mag0").exists(), "no magnetometer stream");
    let from_ns = sc.start_ns + (sc.record_from_s * 1e9) as u64;
    let rows = truth(&dir);
    let first = rows.first().expect("truth");
    assert_eq!(first.t_ns, from_ns);
    assert_eq!(first_stamp(&dir.join("imu0/data.csv")), from_ns);
    assert_eq!(first_stamp(&dir.join("gnss0/data.csv")), from_ns);
    assert_eq!(
        rows.len() as f64,
        (sc.duration_s - sc.record_from_s) * sc.imu.rate_hz + 1.0
    );
    let (speed, ..) = motion(first);
    println!("rover_moving: first truth sample at {speed:.3} m/s");
    assert!(speed >= 0.15, "first truth sample at {speed} m/s");
    // The same trajectory as the rover's, on the same clock.
    let k = rover.trajectory().expect("trajectory").at(sc.record_from_s);
    assert!((first.position - k.position).amax() < 1e-6);
    assert!((first.velocity - k.velocity).amax() < 1e-6);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_from_s_outside_the_duration_is_refused() {
    let sc = scenario("rover_moving");
    for bad in [-1.0, sc.duration_s, sc.duration_s + 1.0, f64::NAN] {
        let err = Scenario {
            record_from_s: bad,
            ..sc.clone()
        }
        .validate()
        .expect_err("refused");
        assert!(err.contains("record_from_s"), "{err}");
    }
    // A scenario file without the key records from the start.
    let parsed: Scenario = toml::from_str("duration_s = 10.0").expect("parses");
    assert_eq!(parsed.record_from_s, 0.0);
}

#[test]
fn car_no_mag_is_car_without_its_magnetometer() {
    let car = scenario("car");
    let sc = scenario("car_no_mag");
    assert!(car.mag.is_some() && sc.mag.is_none());
    assert_eq!(
        (sc.replay.lateral_velocity_sigma, sc.replay.travel.as_str()),
        (0.0, "detect")
    );
    assert!(sc.ceilings.ate_m.is_infinite() && sc.ceilings.attitude_deg.is_infinite());
    assert_eq!(
        Scenario {
            name: car.name.clone(),
            description: car.description.clone(),
            mag: car.mag.clone(),
            ceilings: car.ceilings,
            replay: car.replay.clone(),
            ..sc
        },
        car
    );
}

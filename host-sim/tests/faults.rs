//! Sensor faults in the simulator: each fault is in the written data exactly in its interval and
//! nowhere else (against a fault-free run with the same random streams), `faults.csv` lists the
//! intervals in the dataset's clock and reads back, the fault scenarios are built as described,
//! and fault values out of their domain are refused, named.

use host_sim::dataset::read::{read_faults, FaultInterval};
use host_sim::dataset::write::{faults, simulate};
use host_sim::scenario::{builtin_scenarios, Scenario};
use host_sim::sensors::baro::BaroConfig;
use host_sim::sensors::gnss::GnssConfig;
use host_sim::sensors::imu::ImuConfig;
use host_sim::sensors::mag::MagConfig;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-faults-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The data rows of a CSV written by `simulate`: timestamp → the other fields as written.
fn rows(path: &Path) -> BTreeMap<u64, Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let mut fields = l.split(',').map(str::to_string);
            let t = fields.next().expect("timestamp").parse().expect("ns");
            (t, fields.collect())
        })
        .collect()
}

fn num(s: &str) -> f64 {
    s.parse().expect("number")
}

/// Seconds from the scenario's start of a row stamped `ns`, as the simulator computes it.
fn secs(sc: &Scenario, ns: u64) -> f64 {
    (ns - sc.start_ns) as f64 * 1e-9
}

/// A short figure-eight with every sensor the faults concern.
fn short() -> Scenario {
    Scenario {
        name: "short".into(),
        duration_s: 10.0,
        static_s: 1.0,
        mag: Some(MagConfig::default()),
        gnss: Some(GnssConfig::default()),
        baro: Some(BaroConfig::default()),
        ..Scenario::default()
    }
}

/// `sc` without any fault (the random draws are the same: no sensor skips one for a fault).
fn without_faults(sc: &Scenario) -> Scenario {
    let mut clean = sc.clone();
    clean.imu.accel_clip.clear();
    clean.imu.gyro_stuck.clear();
    if let Some(c) = clean.mag.as_mut() {
        c.disturbances.clear();
        c.rotated.clear();
    }
    if let Some(c) = clean.gnss.as_mut() {
        c.outages.clear();
        c.steps.clear();
        c.frozen.clear();
        c.outlier_probability = 0.0;
    }
    if let Some(c) = clean.baro.as_mut() {
        c.steps.clear();
    }
    clean
}

/// Simulates `sc` and its fault-free twin with the same random streams; returns both folders.
fn pair(sc: &Scenario, name: &str) -> (PathBuf, PathBuf) {
    let (faulty, clean) = (
        tmp(&format!("{name}-faulty")),
        tmp(&format!("{name}-clean")),
    );
    simulate(sc, 7, &faulty).expect("simulate with the fault");
    simulate(&without_faults(sc), 7, &clean).expect("simulate without");
    (faulty, clean)
}

fn remove(dirs: &[&Path]) {
    for d in dirs {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// A `faults.csv` row, built from seconds as the dataset's clock counts them.
fn interval(sc: &Scenario, start_s: f64, end_s: f64, sensor: &str, kind: &str) -> FaultInterval {
    let ns = |s: f64| sc.start_ns + (s * 1e9).round() as u64;
    FaultInterval {
        start_ns: ns(start_s),
        end_ns: ns(end_s),
        sensor: sensor.into(),
        kind: kind.into(),
    }
}

/// The rows of `file` stamped inside `f`, and the rest, after checking that the rest are
/// identical in both runs and that the two runs have the same timestamps.
fn split_at_fault(
    faulty: &Path,
    clean: &Path,
    file: &str,
    f: &FaultInterval,
) -> Vec<(u64, Vec<String>, Vec<String>)> {
    let (a, b) = (rows(&faulty.join(file)), rows(&clean.join(file)));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "{file}: the same timestamps with and without the fault"
    );
    let mut inside = Vec::new();
    for (t, row) in &a {
        if (f.start_ns..f.end_ns).contains(t) {
            inside.push((*t, row.clone(), b[t].clone()));
        } else {
            assert_eq!(row, &b[t], "{file} at {t}: changed outside the fault");
        }
    }
    inside
}

#[test]
fn a_gnss_step_offsets_exactly_the_fixes_of_its_interval_by_their_state_time() {
    let mut sc = short();
    // With a latency, the fixes whose state time is in [4, 7) s are those stamped 0.2 s later.
    sc.gnss = Some(GnssConfig {
        latency_s: 0.2,
        steps: vec![[4.0, 7.0, 30.0, 40.0, -5.0]],
        ..GnssConfig::default()
    });
    let (faulty, clean) = pair(&sc, "gnss-step");
    let f = interval(&sc, 4.2, 7.2, "gnss", "step");
    assert_eq!(read_faults(&faulty).expect("faults.csv"), vec![f.clone()]);
    let inside = split_at_fault(&faulty, &clean, "gnss0/data.csv", &f);
    assert_eq!(inside.len(), 15, "3 s of fixes at 5 Hz");
    for (t, a, b) in &inside {
        for (i, d) in [30.0, 40.0, -5.0].into_iter().enumerate() {
            // Both printed to 0.1 mm.
            let got = num(&a[i]) - num(&b[i]);
            assert!((got - d).abs() <= 1.01e-4, "at {t}: axis {i} moved {got}");
        }
        assert_eq!(a[3..], b[3..], "at {t}: velocity and sigmas untouched");
    }
    remove(&[&faulty, &clean]);
}

#[test]
fn a_frozen_receiver_repeats_its_last_fix_under_new_timestamps() {
    let mut sc = short();
    sc.gnss = Some(GnssConfig {
        frozen: vec![[4.0, 6.0]],
        ..GnssConfig::default()
    });
    let (faulty, clean) = pair(&sc, "gnss-frozen");
    let f = interval(&sc, 4.0, 6.0, "gnss", "frozen");
    assert_eq!(read_faults(&faulty).expect("faults.csv"), vec![f.clone()]);
    let inside = split_at_fault(&faulty, &clean, "gnss0/data.csv", &f);
    assert_eq!(inside.len(), 10, "2 s of fixes at 5 Hz");
    let all = rows(&faulty.join("gnss0/data.csv"));
    let (_, held) = all.range(..f.start_ns).next_back().expect("a fix before");
    for (t, a, b) in &inside {
        assert_eq!(a, held, "at {t}: the last fix before the interval");
        assert_ne!(a[..3], b[..3], "at {t}: the true fix has moved on");
    }
    remove(&[&faulty, &clean]);
}

#[test]
fn a_gnss_outage_and_outliers_are_listed_and_stay_in_their_intervals() {
    let mut sc = short();
    sc.gnss = Some(GnssConfig {
        outages: vec![[3.0, 5.0]],
        outlier_probability: 0.2,
        outlier_m: 50.0,
        ..GnssConfig::default()
    });
    let (faulty, clean) = pair(&sc, "gnss-outage");
    let last_fix = sc.start_ns + 10_000_000_000;
    assert_eq!(
        read_faults(&faulty).expect("faults.csv"),
        vec![
            FaultInterval {
                start_ns: sc.start_ns,
                end_ns: last_fix + 1,
                sensor: "gnss".into(),
                kind: "outliers".into(),
            },
            interval(&sc, 3.0, 5.0, "gnss", "outage"),
        ]
    );
    let (a, b) = (
        rows(&faulty.join("gnss0/data.csv")),
        rows(&clean.join("gnss0/data.csv")),
    );
    let outage = sc.start_ns + 3_000_000_000..sc.start_ns + 5_000_000_000;
    assert_eq!(b.len(), 51);
    assert_eq!(a.len(), 51 - 10, "no fix stamped in [3, 5) s");
    let mut outliers = 0;
    for (t, row) in &b {
        match a.get(t) {
            None => assert!(outage.contains(t), "fix at {t} missing"),
            Some(r) if r != row => {
                let d = ((num(&r[0]) - num(&row[0])).powi(2) + (num(&r[1]) - num(&row[1])).powi(2))
                    .sqrt();
                assert!((d - 50.0).abs() < 2e-4, "outlier at {t}: {d} m");
                outliers += 1;
            }
            Some(_) => {}
        }
    }
    assert!(outliers > 0, "some outliers among 41 fixes at 20 %");
    remove(&[&faulty, &clean]);
}

#[test]
fn a_rotated_magnetometer_reads_its_field_rotated_about_body_z_in_its_interval() {
    let mut sc = short();
    sc.mag = Some(MagConfig {
        rotated: vec![[4.0, 7.0, 30.0]],
        ..MagConfig::default()
    });
    let (faulty, clean) = pair(&sc, "mag-rotated");
    let f = interval(&sc, 4.0, 7.0, "mag", "rotated");
    assert_eq!(read_faults(&faulty).expect("faults.csv"), vec![f.clone()]);
    let inside = split_at_fault(&faulty, &clean, "mag0/data.csv", &f);
    assert_eq!(inside.len(), 150, "3 s at 50 Hz");
    let (s, c) = 30f64.to_radians().sin_cos();
    for (t, a, b) in &inside {
        let (x, y) = (num(&b[0]), num(&b[1]));
        let want = [x * c - y * s, x * s + y * c, num(&b[2])];
        for i in 0..3 {
            // Each printed to 1e-6.
            assert!((num(&a[i]) - want[i]).abs() < 2e-6, "at {t}, axis {i}");
        }
        assert!((num(&a[0]) - x).abs() > 1.0, "at {t}: the rotation shows");
    }
    remove(&[&faulty, &clean]);
}

#[test]
fn a_barometer_step_raises_the_altitude_in_its_interval() {
    let mut sc = short();
    sc.baro = Some(BaroConfig {
        steps: vec![[4.0, 7.0, 20.0]],
        ..BaroConfig::default()
    });
    let (faulty, clean) = pair(&sc, "baro-step");
    let f = interval(&sc, 4.0, 7.0, "baro", "step");
    assert_eq!(read_faults(&faulty).expect("faults.csv"), vec![f.clone()]);
    let inside = split_at_fault(&faulty, &clean, "baro0/data.csv", &f);
    assert_eq!(inside.len(), 75, "3 s at 25 Hz");
    for (t, a, b) in &inside {
        let d = num(&a[0]) - num(&b[0]);
        assert!((d - 20.0).abs() <= 1.01e-4, "at {t}: {d}");
    }
    remove(&[&faulty, &clean]);
}

#[test]
fn a_clipping_accelerometer_is_clamped_to_its_limit_in_its_interval_only() {
    let mut sc = short();
    // Inside the range of the figure-eight's vertical specific force then (9.1 to 9.4 m/s²): some
    // samples are clipped, others not.
    let limit = 9.3;
    sc.imu = ImuConfig {
        accel_clip: vec![[4.0, 6.0, limit]],
        ..ImuConfig::default()
    };
    let (faulty, clean) = pair(&sc, "accel-clip");
    let f = interval(&sc, 4.0, 6.0, "imu", "clip");
    assert_eq!(read_faults(&faulty).expect("faults.csv"), vec![f.clone()]);
    let inside = split_at_fault(&faulty, &clean, "imu0/data.csv", &f);
    assert_eq!(inside.len(), 400, "2 s at 200 Hz");
    let mut clipped = 0;
    for (t, a, b) in &inside {
        assert_eq!(a[..3], b[..3], "at {t}: the gyro untouched");
        for i in 3..6 {
            let (got, was) = (num(&a[i]), num(&b[i]));
            assert!(got.abs() <= limit, "at {t}: {got} beyond ±{limit}");
            if was.abs() <= limit {
                assert_eq!(a[i], b[i], "at {t}: within the limit, untouched");
            } else {
                assert_eq!(got, limit.copysign(was), "at {t}: clamped");
                clipped += 1;
            }
        }
    }
    assert!(
        clipped > 0 && clipped < inside.len(),
        "the limit bites, not everywhere"
    );
    // The truth (biases included) is the same: the fault is in the output only.
    let truth = "state_groundtruth_estimate0/data.csv";
    assert_eq!(rows(&faulty.join(truth)), rows(&clean.join(truth)));
    remove(&[&faulty, &clean]);
}

#[test]
fn a_stuck_gyro_axis_repeats_its_last_value_in_its_interval() {
    let mut sc = short();
    sc.imu = ImuConfig {
        gyro_stuck: vec![[4.0, 6.0, 2.0], [0.0, 0.5, 0.0]],
        ..ImuConfig::default()
    };
    let (faulty, clean) = pair(&sc, "gyro-stuck");
    let stuck = interval(&sc, 4.0, 6.0, "imu", "stuck");
    let at_start = interval(&sc, 0.0, 0.5, "imu", "stuck");
    assert_eq!(
        read_faults(&faulty).expect("faults.csv"),
        vec![at_start.clone(), stuck.clone()]
    );
    let all = rows(&faulty.join("imu0/data.csv"));
    let clean_rows = rows(&clean.join("imu0/data.csv"));
    let (_, before) = all
        .range(..stuck.start_ns)
        .next_back()
        .expect("a sample before");
    let mut moved = false;
    for (t, a) in &all {
        let b = &clean_rows[t];
        if (stuck.start_ns..stuck.end_ns).contains(t) {
            assert_eq!(a[2], before[2], "at {t}: z repeats its last value");
            assert_eq!([&a[..2], &a[3..]], [&b[..2], &b[3..]], "at {t}: other axes");
            moved |= b[2] != before[2];
        } else if (at_start.start_ns..at_start.end_ns).contains(t) {
            // No sample came before: the first one's x is held.
            let first = all.values().next().expect("rows");
            assert_eq!(a[0], first[0], "at {t}");
            assert_eq!(a[1..], b[1..], "at {t}: other axes");
        } else {
            assert_eq!(a, b, "at {t}: changed outside the fault");
        }
    }
    assert!(moved, "the true z rate changed while the axis was stuck");
    remove(&[&faulty, &clean]);
}

#[test]
fn faults_csv_is_written_for_a_scenario_with_faults_only_and_reads_back() {
    let mut sc = short();
    sc.imu.accel_clip = vec![[2.0, 3.0, 30.0]];
    sc.imu.gyro_stuck = vec![[2.5, 2.75, 1.0]];
    sc.mag = Some(MagConfig {
        disturbances: vec![[1.0, 2.0, 25.0]],
        rotated: vec![[6.0, 8.0, 90.0]],
        ..MagConfig::default()
    });
    sc.gnss = Some(GnssConfig {
        latency_s: 0.1,
        outages: vec![[8.0, 9.0]],
        steps: vec![[0.0, 1.5, 1.0, 2.0, 3.0]],
        frozen: vec![[5.0, 5.5]],
        ..GnssConfig::default()
    });
    sc.baro = Some(BaroConfig {
        steps: vec![[3.0, 4.0, -2.0]],
        ..BaroConfig::default()
    });
    let want = vec![
        // A step from 0 s covers the fixes stamped before the latency as well.
        interval(&sc, 0.0, 1.6, "gnss", "step"),
        interval(&sc, 1.0, 2.0, "mag", "disturbance"),
        interval(&sc, 2.0, 3.0, "imu", "clip"),
        interval(&sc, 2.5, 2.75, "imu", "stuck"),
        interval(&sc, 3.0, 4.0, "baro", "step"),
        interval(&sc, 5.1, 5.6, "gnss", "frozen"),
        interval(&sc, 6.0, 8.0, "mag", "rotated"),
        interval(&sc, 8.0, 9.0, "gnss", "outage"),
    ];
    assert_eq!(faults(&sc), want);
    let dir = tmp("all");
    simulate(&sc, 3, &dir).expect("simulate");
    assert_eq!(read_faults(&dir).expect("faults.csv"), want);
    let text = std::fs::read_to_string(dir.join("faults.csv")).expect("faults.csv");
    assert!(
        text.starts_with("#start [ns],end [ns],sensor,kind\n"),
        "{text}"
    );
    assert!(
        text.contains("\n1000000000,2600000000,gnss,step\n"),
        "{text}"
    );

    // The same GNSS rows as the dataset shows them: the step's last fix is stamped 1.4 s (state
    // time 1.3 s), the first after it 1.6 s (state time 1.5 s, outside).
    let gnss = rows(&dir.join("gnss0/data.csv"));
    let clean = tmp("all-clean");
    simulate(&without_faults(&sc), 3, &clean).expect("simulate");
    let gnss_clean = rows(&clean.join("gnss0/data.csv"));
    let changed: Vec<f64> = gnss
        .iter()
        .filter(|(t, r)| gnss_clean.get(t) != Some(r))
        .map(|(t, _)| secs(&sc, *t))
        .collect();
    let expect: Vec<f64> = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 5.2, 5.4]
        .into_iter()
        .collect();
    assert_eq!(changed.len(), expect.len(), "{changed:?}");
    for (c, e) in changed.iter().zip(&expect) {
        assert!((c - e).abs() < 1e-9, "{changed:?}");
    }

    // Without faults, no file, and reading gives nothing.
    assert!(!clean.join("faults.csv").exists());
    assert!(read_faults(&clean).expect("absent").is_empty());
    assert!(faults(&without_faults(&sc)).is_empty());
    remove(&[&dir, &clean]);
}

/// The faults of every built-in fault scenario change their data only inside the intervals
/// `faults.csv` gives, and do change it.
#[test]
fn the_builtin_fault_scenarios_change_their_data_inside_their_intervals_only() {
    let files = [
        ("imu", "imu0/data.csv"),
        ("mag", "mag0/data.csv"),
        ("gnss", "gnss0/data.csv"),
        ("baro", "baro0/data.csv"),
    ];
    for sc in builtin_scenarios()
        .into_iter()
        .filter(|s| s.name.starts_with("fault_") && s.name != "fault_gnss_latency")
    {
        let (faulty, clean) = pair(&sc, &sc.name);
        let listed = read_faults(&faulty).expect("faults.csv");
        assert!(
            !listed.is_empty(),
            "{}: faults.csv lists its fault",
            sc.name
        );
        let mut changed = 0;
        for (sensor, file) in files {
            let (a, b) = (rows(&faulty.join(file)), rows(&clean.join(file)));
            for (t, row) in &b {
                if a.get(t) == Some(row) {
                    continue;
                }
                changed += 1;
                assert!(
                    listed
                        .iter()
                        .any(|f| f.sensor == sensor && (f.start_ns..f.end_ns).contains(t)),
                    "{}: {file} changed at {t}, outside every listed interval",
                    sc.name
                );
            }
            assert!(a.keys().all(|t| b.contains_key(t)), "{}: {file}", sc.name);
        }
        assert!(changed > 0, "{}: the fault shows in the data", sc.name);

        // The stuck z gyro misses a real turn: the heading it does not see over the interval.
        if sc.name == "fault_gyro_stuck" {
            let (a, b) = (
                rows(&faulty.join("imu0/data.csv")),
                rows(&clean.join("imu0/data.csv")),
            );
            let missed: f64 = b
                .iter()
                .map(|(t, r)| (num(&r[2]) - num(&a[t][2])) * 0.005)
                .sum();
            println!("fault_gyro_stuck: {missed:.3} rad of turn unseen");
            assert!(missed > 0.15, "{missed} rad");
        }
        // The vibration makes the ±4 g limit bite.
        if sc.name == "fault_accel_clip" {
            let a = rows(&faulty.join("imu0/data.csv"));
            let peak = a
                .values()
                .flat_map(|r| r[3..].iter().map(|x| num(x).abs()))
                .fold(0.0, f64::max);
            assert!(
                peak > 4.5 * 9.81,
                "outside the interval the vibration reaches {peak}"
            );
        }
        remove(&[&faulty, &clean]);
    }
}

#[test]
fn the_fault_scenarios_exist_with_every_sensor_and_open_ceilings() {
    let all = builtin_scenarios();
    let names = [
        "fault_gnss_step",
        "fault_gnss_frozen",
        "fault_gnss_outage",
        "fault_gnss_outliers",
        "fault_gnss_latency",
        "fault_mag_rotated",
        "fault_baro_step",
        "fault_accel_clip",
        "fault_gyro_stuck",
    ];
    for name in names {
        let sc = all.iter().find(|s| s.name == name).expect(name);
        sc.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!sc.description.is_empty() && !sc.description.contains('\n'));
        let gnss = sc.gnss.as_ref().expect("GNSS");
        assert_eq!((sc.imu.rate_hz, gnss.rate_hz), (200.0, 5.0), "{name}");
        assert!(sc.mag.is_some() && sc.baro.is_some(), "{name}");
        assert!(sc.ceilings.ate_m.is_infinite() && sc.ceilings.attitude_deg.is_infinite());
        assert!(sc.duration_s >= 120.0, "{name}: room for the recovery");
        for f in faults(sc) {
            assert!(
                f.end_ns <= sc.start_ns + (sc.duration_s * 1e9) as u64 + 1,
                "{name}: {f:?} ends in the run"
            );
        }
    }
    let outage = all
        .iter()
        .find(|s| s.name == "fault_gnss_outage")
        .expect("outage");
    assert_eq!(outage.duration_s, 700.0);
    assert_eq!(
        outage.gnss.as_ref().expect("GNSS").outages,
        vec![[30.0, 630.0]]
    );

    // At least 10 m/s once the start-up ramp is over.
    let fast = all
        .iter()
        .find(|s| s.name == "fault_gnss_latency")
        .expect("latency");
    let traj = fast.trajectory().expect("trajectory");
    let speeds: Vec<f64> = (0..=((fast.duration_s - 7.0) * 100.0) as usize)
        .map(|i| traj.at(7.0 + i as f64 * 0.01).velocity.norm())
        .collect();
    let min = speeds.iter().copied().fold(f64::INFINITY, f64::min);
    let max = speeds.iter().copied().fold(0.0, f64::max);
    let mean = speeds.iter().sum::<f64>() / speeds.len() as f64;
    println!("fault_gnss_latency: speed {min:.2} to {max:.2} m/s, mean {mean:.2}");
    assert!(min >= 10.0, "{min} m/s");
}

/// Makes a valid scenario invalid.
type Spoil = fn(&mut Scenario);

#[test]
fn fault_values_out_of_their_domain_are_refused_named() {
    let bad: [(&str, Spoil); 10] = [
        ("gnss.steps[0]", |s| {
            s.gnss.as_mut().unwrap().steps = vec![[5.0, 4.0, 1.0, 0.0, 0.0]]
        }),
        ("gnss.steps[1]", |s| {
            s.gnss.as_mut().unwrap().steps =
                vec![[1.0, 2.0, 0.0, 0.0, 0.0], [1.0, 2.0, f64::NAN, 0.0, 0.0]]
        }),
        ("gnss.frozen[0]", |s| {
            s.gnss.as_mut().unwrap().frozen = vec![[-1.0, 2.0]]
        }),
        ("gnss.outages[0]", |s| {
            s.gnss.as_mut().unwrap().outages = vec![[3.0, 3.0]]
        }),
        ("gnss.outlier_probability", |s| {
            s.gnss.as_mut().unwrap().outlier_probability = 1.5
        }),
        ("mag.rotated[0]", |s| {
            s.mag.as_mut().unwrap().rotated = vec![[1.0, f64::INFINITY, 90.0]]
        }),
        ("baro.steps[0]", |s| {
            s.baro.as_mut().unwrap().steps = vec![[2.0, 1.0, 20.0]]
        }),
        ("imu.accel_clip[0]", |s| {
            s.imu.accel_clip = vec![[1.0, 2.0, 0.0]]
        }),
        ("imu.gyro_stuck[0]", |s| {
            s.imu.gyro_stuck = vec![[1.0, 2.0, 3.0]]
        }),
        ("imu.gyro_stuck[0]", |s| {
            s.imu.gyro_stuck = vec![[1.0, 2.0, 0.5]]
        }),
    ];
    assert_eq!(short().validate(), Ok(()));
    for (field, spoil) in bad {
        let mut sc = short();
        spoil(&mut sc);
        let err = sc.validate().expect_err(field);
        assert!(err.starts_with(field), "{field}: {err}");
    }
}

#[test]
fn a_toml_scenario_names_its_faults_and_misspelt_fields_are_refused() {
    let dir = tmp("toml");
    std::fs::create_dir_all(&dir).expect("tmp");
    let good = dir.join("faulty.toml");
    std::fs::write(
        &good,
        "duration_s = 20.0\n\
         [imu]\naccel_clip = [[1.0, 2.0, 39.24]]\ngyro_stuck = [[3.0, 4.0, 2]]\n\
         [mag]\nrotated = [[5.0, 6.0, 90.0]]\n\
         [gnss]\nsteps = [[7.0, 8.0, 50.0, 0.0, 0.0]]\nfrozen = [[9.0, 10.0]]\n\
         [baro]\nsteps = [[11.0, 12.0, 20.0]]\n",
    )
    .expect("write");
    let sc = Scenario::load(good.to_str().expect("utf-8")).expect("loads");
    assert_eq!(sc.imu.gyro_stuck, vec![[3.0, 4.0, 2.0]]);
    assert_eq!(faults(&sc).len(), 6);

    let misspelt = dir.join("misspelt.toml");
    std::fs::write(&misspelt, "[gnss]\nstep = [[7.0, 8.0, 50.0, 0.0, 0.0]]\n").expect("write");
    let err = Scenario::load(misspelt.to_str().expect("utf-8"))
        .expect_err("unknown field")
        .to_string();
    assert!(err.contains("step"), "{err}");

    let invalid = dir.join("invalid.toml");
    std::fs::write(&invalid, "[imu]\ngyro_stuck = [[3.0, 4.0, 7]]\n").expect("write");
    let err = Scenario::load(invalid.to_str().expect("utf-8"))
        .expect_err("axis 7")
        .to_string();
    assert!(err.contains("imu.gyro_stuck[0]"), "{err}");
    remove(&[&dir]);
}

//! `host-sim replay` starting from whatever the stream gives: moving from the first sample,
//! GNSS arriving only after half a minute of IMU data, and a 10 s hole in the IMU. The INS
//! navigator aligns on the IMU and magnetometer meanwhile, says what is not valid and why
//! (`validity.csv`), and the run scores what it estimated.

use std::path::{Path, PathBuf};

mod common;
use common::host_sim;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-start-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run_ok(args: &[&str]) {
    let o = host_sim(args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// (t_ns, position validity, gnss status, event) of every row of `validity.csv`.
fn validity(out: &Path) -> Vec<(u64, String, String, String)> {
    let text = std::fs::read_to_string(out.join("validity.csv")).expect("validity.csv");
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap(),
                f[4].into(),
                f[7].into(),
                f[11].into(),
            )
        })
        .collect()
}

fn metric(out: &Path, key: &str) -> f64 {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"))
}

#[test]
fn replay_starts_moving_with_the_first_fix_after_30_s() {
    let dir = tmp("late");
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("late.toml");
    // Moving from the first sample (no static start); no fix for the first 30 s.
    std::fs::write(
        &scenario,
        "name = \"late\"\nduration_s = 60.0\nstatic_s = 0.0\nshape = \"figure8\"\n[mag]\n[gnss]\noutages = [[0.0, 30.0]]\n",
    )
    .unwrap();
    let ds = dir.join("ds");
    run_ok(&[
        "simulate",
        "--scenario",
        scenario.to_str().unwrap(),
        "--out",
        ds.to_str().unwrap(),
    ]);
    let out = dir.join("out");
    run_ok(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = validity(&out);
    let t0 = rows[0].0;
    let started = rows
        .iter()
        .find(|r| r.3 == "started")
        .map(|r| (r.0 - t0) as f64 * 1e-9)
        .expect("the INS started");
    assert!((30.0..31.0).contains(&started), "started at {started} s");
    assert!(rows
        .iter()
        .filter(|r| ((r.0 - t0) as f64) < 29.0e9)
        .all(|r| r.1 == "no_fix"));
    // The alignment carried the attitude through the 30 s without fixes; the INS starts from
    // it with 3° of tilt and 5° of heading added (a moving alignment), and the fixes bring it
    // to the default scenario's 1° within seconds: the run's RMSE stays below 1.5°.
    let attitude = metric(&out, "attitude_rmse_deg");
    assert!(attitude < 1.5, "attitude RMSE {attitude}°");
    let ate = metric(&out, "ate_position_rmse_m");
    assert!(ate < 1.0, "ATE {ate} m");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn replay_realigns_after_a_10_s_hole_in_the_imu() {
    let dir = tmp("hole");
    let ds = dir.join("ds");
    run_ok(&[
        "simulate",
        "--scenario",
        "default",
        "--out",
        ds.to_str().unwrap(),
    ]);
    // Remove the IMU rows from 20 s to 30 s after the first one.
    let imu = ds.join("imu0/data.csv");
    let text = std::fs::read_to_string(&imu).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let t0: u64 = rows[0].split(',').next().unwrap().parse().unwrap();
    let kept: Vec<&str> = rows
        .into_iter()
        .filter(|l| {
            let t: u64 = l.split(',').next().unwrap().parse().unwrap();
            !(t0 + 20_000_000_000..t0 + 30_000_000_000).contains(&t)
        })
        .collect();
    std::fs::write(&imu, format!("{header}\n{}\n", kept.join("\n"))).unwrap();
    let out = dir.join("out");
    run_ok(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = validity(&out);
    let realigned = rows
        .iter()
        .find(|r| r.3 == "realigned")
        .map(|r| (r.0 - t0) as f64 * 1e-9)
        .expect("the navigator says it realigned");
    assert!(
        (30.0..30.1).contains(&realigned),
        "realigned at {realigned} s"
    );
    let restarted = rows
        .iter()
        .rev()
        .find(|r| r.3 == "started")
        .map(|r| (r.0 - t0) as f64 * 1e-9)
        .unwrap();
    assert!(
        restarted > 30.0 && restarted < 33.0,
        "restarted at {restarted} s"
    );
    let attitude = metric(&out, "attitude_rmse_deg");
    assert!(attitude < 1.5, "attitude RMSE {attitude}°");
    let _ = std::fs::remove_dir_all(dir);
}

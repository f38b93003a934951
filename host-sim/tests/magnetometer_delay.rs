//! The attitude navigator learns a magnetometer's delay behind the gyro while the body turns
//! fast about the vertical: a simulated magnetometer whose sample stamped `t` is the field at
//! `t − 10 ms`, on a body yawing back and forth at up to 540 °/s.

#[path = "common/attitude_run.rs"]
mod attitude_run;

use estimator_core::lie::LieGroup;
use host_sim::dataset::write::simulate;
use host_sim::scenario::{builtin_scenarios, Scenario};
use host_sim::sensors::mag::MagConfig;
use host_sim::trajectory::{builtin, Signal, Sine};
use std::path::{Path, PathBuf};

/// The simulated magnetometer's delay, s.
const DELAY_S: f64 = 0.010;

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("estimator-mag-delay-{}-{name}", std::process::id()))
}

/// A body turning in place, its yaw swinging by ±1.5 rad at 1 Hz (9.4 rad/s at the peak) over a
/// slower wander, with a magnetometer at the IMU's rate, `DELAY_S` behind it.
fn scenario() -> Scenario {
    let mut sc = builtin_scenarios()
        .into_iter()
        .find(|s| s.name == "default")
        .expect("built-in scenario");
    let mut trajectory = builtin("rotate", sc.static_s).expect("shape");
    trajectory.euler[2] = Signal {
        offset: 0.3,
        rate: 0.0,
        sines: vec![
            Sine {
                amplitude: 1.5,
                frequency_hz: 1.0,
                phase: 0.0,
            },
            Sine {
                amplitude: 0.4,
                frequency_hz: 0.07,
                phase: 0.5,
            },
        ],
    };
    sc.name = "magnetometer_delay".into();
    sc.trajectory = Some(trajectory);
    sc.gnss = None;
    sc.mag = Some(MagConfig {
        rate_hz: sc.imu.rate_hz,
        delay_s: DELAY_S,
        ..MagConfig::default()
    });
    sc
}

/// What one run gives: the delay learned, s, and the heading RMSE over the last 30 s, degrees.
struct Run {
    delay_s: f64,
    heading_rmse_deg: f64,
}

/// The navigator (f32) driven sample by sample over `ds`; `learn`: the delay is learned (the
/// default bound), else held at zero.
fn run(ds: &Path, learn: bool) -> Run {
    let (nav, heading_rmse_deg) = attitude_run::drive(
        ds,
        |mc| {
            if !learn {
                mc.delay_max_s = 0.0;
            }
        },
        30.0,
        // The world-frame error's rotation about the vertical.
        |truth, estimate| estimate.compose(&truth.inverse()).log().z,
    );
    Run {
        delay_s: f64::from(nav.estimate().expect("started").magnetometer_delay_s),
        heading_rmse_deg,
    }
}

#[test]
fn a_magnetometer_behind_the_gyro_is_learned_and_its_heading_error_removed() {
    let sc = scenario();
    let dir = tmp("learned");
    simulate(&sc, 1, &dir).expect("simulate");
    let learned = run(&dir, true);
    let held = run(&dir, false);
    let _ = std::fs::remove_dir_all(dir);
    println!(
        "delay learned {:.2} ms (true {:.1} ms); heading RMSE over the last 30 s {:.3}° learned, {:.3}° held at 0",
        learned.delay_s * 1e3,
        DELAY_S * 1e3,
        learned.heading_rmse_deg,
        held.heading_rmse_deg
    );
    // The bound: at the 5.6 rad/s (the heading noise of a block over the 50 ms bound) from
    // which a block teaches the delay, 1 ms of error turns the field by 0.32°, three times the
    // heading's white noise over a block (0.4 µT / (√50 · 24 µT) = 0.14°) even before the
    // blocks are averaged: 2 ms is well outside what noise leaves.
    assert!(
        (learned.delay_s - DELAY_S).abs() <= 0.002,
        "learned {} s against {} s",
        learned.delay_s,
        DELAY_S
    );
    assert!(held.delay_s == 0.0);
    assert!(
        learned.heading_rmse_deg < held.heading_rmse_deg,
        "the learned delay must leave less heading error"
    );
}

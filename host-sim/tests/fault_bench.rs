//! The fault bench (`host-sim faults`): its figures on hand-made epochs (detection, recovery,
//! false-valid counting), then the bench itself on one run of two short fault scenarios, through
//! the library and through the command line.

use host_sim::dataset::read::FaultInterval;
use host_sim::faults::epochs::{AidStatus, Epoch, ErrorState, Validity};
use host_sim::faults::score::{
    alarms_before, detection_s, false_valid, gaussian_outside, recovery_s, FaultRule, QUANTITIES,
};
use host_sim::faults::{builtin_fault_scenarios, Options};
use nalgebra::Vector3;
use std::path::PathBuf;
use std::process::Command;

const MS: u64 = 1_000_000;

/// Epochs every 5 ms over `[0, end_ms)`, nominal, each with an error state of zero error and
/// 1σ = 1 on every axis.
fn epochs(end_ms: u64) -> Vec<Epoch> {
    (0..end_ms / 5)
        .map(|k| Epoch {
            state: Some(ErrorState {
                error: [Vector3::zeros(); 5],
                sigma: [Vector3::repeat(1.0); 5],
            }),
            ..Epoch::nominal(k * 5 * MS)
        })
        .collect()
}

fn at(eps: &mut [Epoch], t_ms: u64) -> &mut Epoch {
    eps.iter_mut()
        .find(|e| e.t_ns == t_ms * MS)
        .expect("an epoch at that time")
}

fn close(a: Option<f64>, b: f64) -> bool {
    a.is_some_and(|a| (a - b).abs() < 1e-9)
}

fn fault(sensor: &str, kind: &str) -> FaultInterval {
    FaultInterval {
        start_ns: 0,
        end_ns: 1,
        sensor: sensor.into(),
        kind: kind.into(),
    }
}

#[test]
fn each_fault_kind_has_its_rule_and_outliers_have_none() {
    let cases = [
        ("gnss", "step", Some(FaultRule::GnssStep)),
        ("gnss", "frozen", Some(FaultRule::GnssFrozen)),
        ("gnss", "outage", Some(FaultRule::GnssOutage)),
        ("gnss", "outliers", None),
        ("mag", "rotated", Some(FaultRule::Magnetometer)),
        ("baro", "step", Some(FaultRule::BaroStep)),
        ("imu", "clip", Some(FaultRule::Imu)),
        ("imu", "stuck", Some(FaultRule::Imu)),
    ];
    for (sensor, kind, rule) in cases {
        assert_eq!(FaultRule::of(&fault(sensor, kind)), rule, "{sensor} {kind}");
    }
    assert_eq!(FaultRule::GnssStep.target_s(), Some(7.0));
    assert_eq!(FaultRule::BaroStep.target_s(), Some(5.0));
}

#[test]
fn detection_is_the_first_epoch_at_or_after_the_start_that_shows_the_fault() {
    let mut eps = epochs(3000);
    // An ordinary rejection before the fault: an alarm before it, not its detection.
    at(&mut eps, 500).gnss = AidStatus::Rejected;
    at(&mut eps, 1300).gnss = AidStatus::Rejected;
    at(&mut eps, 1800).position = Validity::FixesDisagree;
    let start = 1000 * MS;
    assert!(close(detection_s(&eps, start, FaultRule::GnssStep), 0.3));
    assert_eq!(alarms_before(&eps, start, FaultRule::GnssStep), 1);
    // Position disagreement alone detects a step too.
    at(&mut eps, 1300).gnss = AidStatus::Fused;
    assert!(close(detection_s(&eps, start, FaultRule::GnssStep), 0.8));
    // Nothing shows a frozen receiver: never detected.
    assert_eq!(detection_s(&eps, start, FaultRule::GnssFrozen), None);
    at(&mut eps, 1000).imu_fault = true;
    assert!(close(detection_s(&eps, start, FaultRule::Imu), 0.0));
}

#[test]
fn recovery_needs_one_second_without_interruption() {
    let mut eps = epochs(5000);
    let end = 1000 * MS;
    // Not fused until 1.5 s; fused but the position off by 3.5σ (east) at 1.8 s; good after.
    for e in eps.iter_mut().filter(|e| e.t_ns < 1500 * MS) {
        e.gnss = AidStatus::Rejected;
    }
    at(&mut eps, 1800).state.as_mut().expect("state").error[2].x = 3.5;
    assert!(close(recovery_s(&eps, end, FaultRule::GnssStep), 0.805));
    // The barometer rule looks at the vertical axis only, and at the barometer.
    assert!(close(recovery_s(&eps, end, FaultRule::BaroStep), 0.0));
    at(&mut eps, 1800).state.as_mut().expect("state").error[2].z = -3.5;
    assert!(close(recovery_s(&eps, end, FaultRule::BaroStep), 0.805));
    // An invalid attitude from 4.5 s leaves less than 1 s before the run ends: never.
    for e in eps.iter_mut().filter(|e| e.t_ns >= 3900 * MS) {
        e.heading = Validity::Uncertain;
    }
    assert_eq!(recovery_s(&eps, 3000 * MS, FaultRule::Magnetometer), None);
    assert!(close(recovery_s(&eps, end, FaultRule::Magnetometer), 0.0));
    // Without an estimate nothing has recovered.
    for e in &mut eps {
        e.state = None;
    }
    assert_eq!(recovery_s(&eps, end, FaultRule::Imu), None);
}

#[test]
fn false_valid_counts_valid_quantities_outside_their_sigma_and_nothing_else() {
    let mut eps = epochs(1000);
    let fv = false_valid(&eps);
    for (q, t) in QUANTITIES.iter().zip(&fv.quantities) {
        assert_eq!(t.valid_epoch_axes, 600, "{q}");
        assert_eq!(
            (t.outside_3sigma, t.outside_4sigma),
            (0, 0),
            "{q}: within 1σ"
        );
    }
    // Position valid and 5σ off on one axis: counted outside 3σ and 4σ; velocity 3.5σ off:
    // outside 3σ only; a bias 2.9σ off: neither.
    {
        let s = at(&mut eps, 100).state.as_mut().expect("state");
        s.error[2].y = -5.0;
        s.error[1].z = 3.5;
        s.error[3].x = 2.9;
    }
    let fv = false_valid(&eps);
    assert_eq!(fv.quantities[2].outside_3sigma, 1);
    assert_eq!(fv.quantities[2].outside_4sigma, 1);
    assert_eq!(fv.quantities[1].outside_3sigma, 1);
    assert_eq!(fv.quantities[1].outside_4sigma, 0);
    assert_eq!(fv.quantities[3].outside_3sigma, 0);
    assert_eq!(fv.total().outside_3sigma, 2);
    // The same errors while the navigator says position and velocity are not valid: nothing.
    at(&mut eps, 100).position = Validity::FixesDisagree;
    at(&mut eps, 100).velocity = Validity::ImuFault;
    let fv = false_valid(&eps);
    assert_eq!(fv.total().outside_3sigma, 0);
    assert_eq!(fv.quantities[2].valid_epoch_axes, 597);
    // The attitude counts as valid only with tilt and heading valid.
    at(&mut eps, 200).state.as_mut().expect("state").error[0].z = 10.0;
    assert_eq!(false_valid(&eps).quantities[0].outside_4sigma, 1);
    at(&mut eps, 200).heading = Validity::NoMagnetometer;
    assert_eq!(false_valid(&eps).quantities[0].outside_4sigma, 0);
    // The consistent filter's expectation.
    assert!((gaussian_outside(3.0) - 0.0026998).abs() < 1e-6);
    assert!((gaussian_outside(4.0) - 6.334e-5).abs() < 1e-7);
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "host-sim-fault-bench-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn scenario(name: &str) -> host_sim::scenario::Scenario {
    builtin_fault_scenarios()
        .into_iter()
        .find(|s| s.name == name)
        .expect("a built-in fault scenario")
}

/// One run each of the GNSS step and the clipped accelerometer (120 s each; a few seconds in a
/// test build).
#[test]
fn the_bench_scores_a_gnss_step_and_a_clipped_accelerometer() {
    let scratch = tmp("lib");
    std::fs::create_dir_all(&scratch).expect("scratch");
    let opts = Options {
        scenarios: vec![scenario("fault_gnss_step"), scenario("fault_accel_clip")],
        first_seed: 1,
        runs: 1,
        latency: None,
        workers: 2,
        scratch: scratch.clone(),
        progress: false,
    };
    let bench = host_sim::faults::run(&opts).expect("bench runs");
    // Every run removed its own folder.
    assert_eq!(std::fs::read_dir(&scratch).expect("scratch").count(), 0);
    let _ = std::fs::remove_dir_all(&scratch);
    assert_eq!(bench.per_run.len(), 2);
    for r in &bench.per_run {
        assert_eq!(r.seed, 1);
        assert_eq!(r.faults.len(), 1, "{}", r.scenario);
        let f = &r.faults[0];
        assert_eq!(
            (f.start_s, f.end_s),
            (
                40.0,
                if r.scenario == "fault_gnss_step" {
                    70.0
                } else {
                    42.0
                }
            )
        );
        assert!(r.ate_m.is_some_and(|a| a.is_finite() && a > 0.0));
        assert!(r.false_valid.total().valid_epoch_axes > 0);
        assert!(r.epochs > 20_000);
        // The navigator shows both faults, within their intervals.
        let d = f.detection_s.expect("detected");
        assert!(
            (0.0..f.end_s - f.start_s).contains(&d),
            "{}: {d}",
            r.scenario
        );
    }
    assert_eq!(bench.summaries.len(), 2);
    assert!(bench.table().contains("fault_gnss_step"));
    let csv = bench.runs_csv().expect("csv");
    assert_eq!(csv.lines().count(), 3);
    let json = bench.json(&["test".into()]);
    assert_eq!(json["scenarios"].as_array().map(Vec::len), Some(2));
    assert!(json["latency"].is_null());
}

#[test]
fn the_command_writes_its_files_and_refuses_a_folder_it_did_not_write() {
    let base = tmp("cli");
    std::fs::create_dir_all(&base).expect("base");
    let out = base.join("faults");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "faults",
            "--scenario",
            "fault_gnss_step",
            "--runs",
            "1",
            "--seed",
            "2",
            "--out",
            out.to_str().expect("utf-8"),
        ];
        args.extend_from_slice(extra);
        Command::new(env!("CARGO_BIN_EXE_host-sim"))
            .args(&args)
            .output()
            .expect("host-sim runs")
    };
    let o = run(&["--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json on stdout");
    assert_eq!(printed["seeds"], serde_json::json!([2]));
    assert!(out.join("faults.csv").is_file() && out.join("faults.json").is_file());
    // Only the output folder is left beside it: the scratch and partial folders are gone.
    let names: Vec<String> = std::fs::read_dir(&base)
        .expect("base")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["faults".to_string()]);
    // An earlier output is replaced only with --force.
    let o = run(&[]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    // A folder with the user's files is never touched.
    let mine = base.join("mine");
    std::fs::create_dir_all(&mine).expect("mine");
    std::fs::write(mine.join("notes.txt"), "mine").expect("write");
    let o = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["faults", "--scenario", "fault_gnss_step", "--runs", "1"])
        .args(["--out", mine.to_str().expect("utf-8"), "--force"])
        .output()
        .expect("host-sim runs");
    assert!(!o.status.success());
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt"))
            .ok()
            .as_deref(),
        Some("mine")
    );
    let _ = std::fs::remove_dir_all(&base);
}

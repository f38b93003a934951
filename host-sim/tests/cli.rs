//! The `host-sim` command line as a user runs it: listing, simulate → replay against run,
//! reproducibility, TOML scenarios, and malformed datasets (one-line error naming file and
//! line, non-zero exit, no outputs left looking complete).

use std::path::{Path, PathBuf};

mod common;
use common::host_sim;
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `host-sim simulate --scenario NAME --out DIR`, which must succeed.
fn simulate(scenario: &str, out: &Path) {
    let o = host_sim(&[
        "simulate",
        "--scenario",
        scenario,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// `metrics.json` without what differs between identical runs: the time spent and where the
/// run comes from (its command line).
fn metrics_without_timing(p: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&read(p)).expect("json");
    let o = v.as_object_mut().expect("object");
    o.remove("filter_ns_per_imu_sample");
    o.remove("provenance");
    v
}

#[test]
fn scenarios_lists_the_builtins() {
    let o = host_sim(&["scenarios"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for name in [
        "default",
        "static",
        "hover",
        "car",
        "coning",
        "pitch90",
        "matched_ins",
        "matched_ahrs",
    ] {
        assert!(
            text.lines().any(|l| l.starts_with(name)),
            "{name} missing from:\n{text}"
        );
    }
}

/// `simulate` then `replay` reproduces `run` exactly, and the same seed gives the same bytes.
#[test]
fn simulate_then_replay_reproduces_run() {
    let run_dir = tmp("run");
    let o = host_sim(&[
        "run",
        "--scenario",
        "default",
        "--seed",
        "7",
        "--out",
        run_dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("position RMSE"), "summary table:\n{text}");

    let ds = tmp("ds");
    let o = host_sim(&[
        "simulate",
        "--scenario",
        "default",
        "--seed",
        "7",
        "--out",
        ds.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rep = tmp("replay");
    let o = host_sim(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    for f in ["estimate.tum", "estimate.csv", "groundtruth.tum"] {
        assert!(
            read(&run_dir.join(f)) == read(&rep.join(f)),
            "{f} differs between run and simulate+replay"
        );
    }
    assert_eq!(
        metrics_without_timing(&run_dir.join("metrics.json")),
        metrics_without_timing(&rep.join("metrics.json"))
    );
    for f in [
        "imu0/data.csv",
        "mag0/data.csv",
        "gnss0/data.csv",
        "state_groundtruth_estimate0/data.csv",
    ] {
        assert!(
            read(&run_dir.join("dataset").join(f)) == read(&ds.join(f)),
            "{f}: same seed, different bytes"
        );
    }
    for png in ["trajectory.png", "errors.png", "biases.png", "nis.png"] {
        assert!(run_dir.join(png).is_file(), "{png} missing");
    }
    // A different seed gives different noise.
    let ds2 = tmp("ds2");
    assert!(host_sim(&[
        "simulate",
        "--scenario",
        "default",
        "--seed",
        "8",
        "--out",
        ds2.to_str().unwrap()
    ])
    .status
    .success());
    assert!(read(&ds.join("imu0/data.csv")) != read(&ds2.join("imu0/data.csv")));
    for d in [run_dir, ds, rep, ds2] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn toml_scenario_file() {
    let dir = tmp("toml");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("short.toml");
    std::fs::write(
        &file,
        "name = \"short\"\nduration_s = 12.0\nstatic_s = 3.0\nshape = \"car\"\n[mag]\nrate_hz = 25.0\n[gnss]\nrate_hz = 2.0\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = host_sim(&[
        "run",
        "--scenario",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines = std::fs::read_to_string(out.join("dataset/gnss0/data.csv"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(lines, 1 + 25, "12 s at 2 Hz plus the header");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "duration_s = \"long\"\n").unwrap();
    let o = host_sim(&[
        "run",
        "--scenario",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.toml"));
    let _ = std::fs::remove_dir_all(dir);
}

/// Corrupts one line of one file of a fresh dataset and checks the error.
fn corrupt(name: &str, file: &str, line: usize, replacement: Option<&str>, expect: &[&str]) {
    let ds = tmp(&format!("bad-{name}"));
    assert!(host_sim(&[
        "simulate",
        "--scenario",
        "hover",
        "--seed",
        "2",
        "--out",
        ds.to_str().unwrap()
    ])
    .status
    .success());
    let path = ds.join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    match replacement {
        Some(r) => lines[line - 1] = r.to_string(),
        None => {
            // Swap with the previous line: a non-monotonic timestamp at `line`.
            lines.swap(line - 2, line - 1);
        }
    }
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    let out = ds.join("out");
    let o = host_sim(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{name}: should fail");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{name}: one line, got:\n{err}"
    );
    for e in expect {
        assert!(err.contains(e), "{name}: '{e}' not in: {err}");
    }
    for f in [
        "estimate.tum",
        "estimate.csv",
        "groundtruth.tum",
        "metrics.json",
    ] {
        assert!(!out.join(f).exists(), "{name}: {f} left behind");
    }
    let _ = std::fs::remove_dir_all(ds);
}

#[test]
fn malformed_datasets_name_file_and_line() {
    corrupt(
        "columns",
        "imu0/data.csv",
        600,
        Some("1234,0.1,0.2"),
        &["imu0/data.csv:600:", "expected 7 columns, got 3"],
    );
    corrupt(
        "number",
        "gnss0/data.csv",
        40,
        Some("9000000000,1,2,x3,0,0,0,1,0.1"),
        &["gnss0/data.csv:40:", "'x3' is not a number"],
    );
    corrupt(
        "order",
        "mag0/data.csv",
        1000,
        None,
        &["mag0/data.csv:1000:", "non-monotonic"],
    );
    corrupt(
        "dup",
        "baro0/data.csv",
        300,
        Some("12880000000,1.0"),
        &["baro0/data.csv:300:", "duplicated"],
    );
    corrupt(
        "units",
        "imu0/data.csv",
        3,
        Some("1010000000,0.1,0.2,0.3,nan,9.8,0.0"),
        &["imu0/data.csv:3:", "not finite"],
    );
    // A missing IMU file.
    let ds = tmp("missing");
    assert!(host_sim(&[
        "simulate",
        "--scenario",
        "static",
        "--out",
        ds.to_str().unwrap()
    ])
    .status
    .success());
    std::fs::remove_file(ds.join("imu0/data.csv")).unwrap();
    let o = host_sim(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        ds.join("out").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("imu0/data.csv"));
    let _ = std::fs::remove_dir_all(ds);
}

/// `host-sim` run from `cwd`.
fn host_sim_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("host-sim runs")
}

/// Every entry of `dir`, sorted, with the contents of its files.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let bytes = if p.is_file() { read(&p) } else { Vec::new() };
            (p.file_name().unwrap().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    out.sort();
    out
}

fn partial_folders_in(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("host-sim-partial") || n.contains("host-sim-old"))
        .collect()
}

/// `--out .` (or any folder holding the current one) is refused, and nothing in it changes.
#[test]
fn out_dot_is_refused_and_the_folder_is_untouched() {
    let dir = tmp("dot");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine\n").unwrap();
    let before = snapshot(&dir);
    for args in [
        &["simulate", "--scenario", "hover", "--out", "."][..],
        &["simulate", "--scenario", "hover", "--out", ".", "--force"][..],
        &["run", "--scenario", "hover", "--out", ".."][..],
    ] {
        let o = host_sim_in(&dir, args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("current folder"), "{args:?}: {err}");
        assert_eq!(snapshot(&dir), before, "{args:?} changed the folder");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A folder with files host-sim did not write is refused, with or without `--force`, and kept
/// as it was; an empty folder is written.
#[test]
fn a_folder_with_foreign_files_is_refused_even_with_force() {
    let parent = tmp("foreign");
    let dir = parent.join("data");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "my notes\n").unwrap();
    let before = snapshot(&dir);
    for force in [false, true] {
        let mut args = vec![
            "simulate",
            "--scenario",
            "hover",
            "--out",
            dir.to_str().unwrap(),
        ];
        if force {
            args.push("--force");
        }
        let o = host_sim(&args);
        assert!(!o.status.success(), "force {force}: should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("did not write"), "force {force}: {err}");
        assert_eq!(snapshot(&dir), before);
        assert!(partial_folders_in(&parent).is_empty());
    }
    let empty = parent.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = host_sim(&[
        "simulate",
        "--scenario",
        "hover",
        "--out",
        empty.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(empty.join("imu0/data.csv").is_file());
    let _ = std::fs::remove_dir_all(parent);
}

/// An earlier host-sim output is replaced only with `--force`, and a failing run over it leaves
/// it exactly as it was (the new output is written beside it and moved in only on success).
#[test]
fn an_earlier_output_survives_a_failing_run_and_needs_force_to_be_replaced() {
    let parent = tmp("earlier");
    let ds = parent.join("ds");
    let out = parent.join("out");
    let sim = |seed: &str, force: bool| {
        let mut args = vec![
            "simulate",
            "--scenario",
            "hover",
            "--seed",
            seed,
            "--out",
            ds.to_str().unwrap(),
        ];
        if force {
            args.push("--force");
        }
        host_sim(&args)
    };
    assert!(sim("2", false).status.success());
    let o = sim("3", false);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    assert!(sim("2", true).status.success());

    let replay = |force: bool| {
        let mut args = vec![
            "replay",
            ds.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        if force {
            args.push("--force");
        }
        host_sim(&args)
    };
    let o = replay(false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let good = snapshot(&out);
    assert!(good.iter().any(|(n, _)| n == "metrics.json"));
    // Break the dataset: the next replay fails, and the earlier output is untouched.
    let imu = ds.join("imu0/data.csv");
    let text = std::fs::read_to_string(&imu).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[5] = "1,2,3";
    std::fs::write(&imu, lines.join("\n") + "\n").unwrap();
    let o = replay(true);
    assert!(!o.status.success());
    assert_eq!(
        snapshot(&out),
        good,
        "a failing run changed the earlier output"
    );
    assert!(
        partial_folders_in(&parent).is_empty(),
        "{:?}",
        partial_folders_in(&parent)
    );
    // The output folder may not hold the dataset it replays.
    let o = host_sim(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        parent.to_str().unwrap(),
        "--force",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds the dataset"));
    let _ = std::fs::remove_dir_all(parent);
}

/// A misspelt key in a scenario or a replay configuration is an error naming the key and the
/// file; values out of their domain and unknown shapes are refused by name.
#[test]
fn unknown_keys_and_nonsense_values_are_errors_naming_key_and_file() {
    let dir = tmp("keys");
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "typo.toml",
            "duraton_s = 10.0\n",
            &["typo.toml", "duraton_s"][..],
        ),
        (
            "nested.toml",
            "[imu]\nrate_hz = 100.0\nprecission = 1\n",
            &["nested.toml", "precission"][..],
        ),
        (
            "negative.toml",
            "duration_s = -5.0\n",
            &["negative.toml", "duration_s", "-5"][..],
        ),
        (
            "rate.toml",
            "[gnss]\nrate_hz = 0.0\n",
            &["rate.toml", "gnss.rate_hz"][..],
        ),
        (
            "shape.toml",
            "shape = \"spiral\"\n",
            &["shape.toml", "unknown shape 'spiral'", "figure8"][..],
        ),
    ];
    for (file, text, expect) in cases {
        let path = dir.join(file);
        std::fs::write(&path, text).unwrap();
        let out = dir.join(format!("out-{file}"));
        let o = host_sim(&[
            "run",
            "--scenario",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{file}: should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        for e in expect {
            assert!(err.contains(e), "{file}: '{e}' not in: {err}");
        }
        assert!(!out.exists(), "{file}: an output was left");
    }
    // The replay configuration too.
    let ds = dir.join("ds");
    simulate("hover", &ds);
    for (file, text, expect) in [
        ("cfg-typo.toml", "max_dtt = 0.1\n", "max_dtt"),
        ("cfg-zero.toml", "max_dt = 0.0\n", "max_dt = 0"),
    ] {
        let cfg = dir.join(file);
        std::fs::write(&cfg, text).unwrap();
        let out = dir.join(format!("out-{file}"));
        let o = host_sim(&[
            "replay",
            ds.to_str().unwrap(),
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{file}: should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(file) && err.contains(expect), "{file}: {err}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// An empty ground truth scores nothing: an error and no output, never an RMSE of 0.
#[test]
fn an_empty_ground_truth_is_an_error_not_a_zero_rmse() {
    let dir = tmp("empty-gt");
    let ds = dir.join("ds");
    simulate("hover", &ds);
    let gt = ds.join("state_groundtruth_estimate0/data.csv");
    let header = std::fs::read_to_string(&gt)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    std::fs::write(&gt, header + "\n").unwrap();
    let out = dir.join("out");
    let o = host_sim(&[
        "replay",
        ds.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no estimate could be scored"));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}

/// Copies a dataset folder into `to` (created).
fn copy_dataset(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let p = entry.unwrap().path();
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dataset(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
}

/// `bench` over a folder of tiny simulated datasets: a BROAD-like group (movement.csv and a
/// `trials` references.json) and an attitude group (a `datasets` references.json naming one of
/// its two datasets). Prints both tables, writes bench.json; a broken dataset is reported in its
/// row, the others still run, and the exit status is non-zero.
#[test]
fn bench_prints_tables_and_writes_bench_json() {
    let dir = tmp("bench");
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    let scenario = dir.join("tiny.toml");
    std::fs::write(
        &scenario,
        "name = \"tiny\"\nduration_s = 8.0\nstatic_s = 3.0\n[mag]\nrate_hz = 25.0\n",
    )
    .unwrap();
    let sim = dir.join("sim");
    simulate(scenario.to_str().unwrap(), &sim);
    for (group, name) in [("broadlike", "trial_a"), ("indep", "one"), ("indep", "two")] {
        copy_dataset(&sim, &data.join(group).join(name));
    }
    std::fs::write(
        data.join("broadlike/trial_a/movement.csv"),
        "#start [ns],end [ns]\n4000000000,8000000000\n",
    )
    .unwrap();
    std::fs::write(
        data.join("broadlike/references.json"),
        r#"{"trials": {"trial_a": {"vqf_9d": {"total": 2.5}, "madgwick_tagp_published": {"total": 4.25}}}}"#,
    )
    .unwrap();
    std::fs::write(
        data.join("indep/references.json"),
        r#"{"datasets": {"one": {"vqf_9d": {"attitude_rmse_deg": 1.75}}}}"#,
    )
    .unwrap();

    let out = dir.join("out");
    let o = host_sim(&[
        "bench",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{}\n{text}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(text.contains("BROAD RMSE"), "{text}");
    assert!(text.contains("attitude RMSE [deg] from 2 s"), "{text}");
    let row = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no row {name}:\n{text}"))
            .to_string()
    };
    assert!(row("trial_a").contains("2.500") && row("trial_a").contains("4.250"));
    assert!(row("one").contains("1.750"));
    // No reference entry: ours only, the reference and the ratio not computed.
    assert_eq!(row("two").matches('–').count(), 2, "{}", row("two"));
    for f in [
        "trial_a/metrics.json",
        "one/estimate.tum",
        "two/metrics.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let json: serde_json::Value = serde_json::from_slice(&read(&out.join("bench.json"))).unwrap();
    let tables = json["tables"].as_array().expect("tables");
    assert_eq!(tables.len(), 2);
    let broad = &tables[0]["rows"][0];
    assert_eq!(tables[0]["kind"], "broad");
    assert_eq!(broad["vqf_total_deg"], 2.5);
    let total = broad["ours"]["total_deg"].as_f64().expect("BROAD total");
    assert!(total.is_finite() && total >= 0.0);
    assert!(broad["samples"].as_u64().expect("samples") > 0);
    assert_eq!(tables[1]["kind"], "attitude");
    let two = &tables[1]["rows"][1];
    assert!(two["attitude_rmse_after_2s_deg"].as_f64().is_some());
    assert!(two["vqf_attitude_rmse_deg"].is_null() && two["ratio_to_vqf"].is_null());

    // An earlier output needs --force; a broken dataset fails in its row only.
    let o = host_sim(&[
        "bench",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    let bad = data.join("indep/bad");
    copy_dataset(&sim, &bad);
    let imu = bad.join("imu0/data.csv");
    let imu_text = std::fs::read_to_string(&imu).unwrap();
    let mut lines: Vec<&str> = imu_text.lines().collect();
    lines[9] = "1,2,3";
    std::fs::write(&imu, lines.join("\n") + "\n").unwrap();
    let o = host_sim(&[
        "bench",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!o.status.success(), "a failed dataset is a failure");
    let bad_row = text
        .lines()
        .find(|l| l.starts_with("bad"))
        .unwrap_or_else(|| panic!("no row bad:\n{text}"));
    assert!(
        bad_row.contains("failed") && bad_row.contains("imu0/data.csv:10:"),
        "{bad_row}"
    );
    assert!(text.lines().any(|l| l.starts_with("one")), "{text}");
    let json: serde_json::Value = serde_json::from_slice(&read(&out.join("bench.json"))).unwrap();
    assert!(json["tables"][1]["rows"][0]["error"].is_string());
    let _ = std::fs::remove_dir_all(dir);
}

/// `bench` on one BROAD trial of the shared datasets, when they are present: BROAD's metric is
/// computed and below 20°, and so is the inclination without the magnetometer.
#[test]
fn bench_on_a_broad_trial_scores_it() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/datasets/broad");
    let trial = "05_undisturbed_slow_rotation_with_breaks_B";
    if !shared.join(trial).join("imu0/data.csv").is_file() {
        eprintln!(
            "skipped: {} is absent (the shared datasets are not on this machine)",
            shared.join(trial).display()
        );
        return;
    }
    // DIR may be the dataset folder itself; the references are those of its parent folder.
    let dir = tmp("bench-broad");
    let out = dir.join("out");
    let o = host_sim(&[
        "bench",
        shared.join(trial).to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{}\n{text}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&read(&out.join("bench.json"))).unwrap();
    let row = &json["tables"][0]["rows"][0];
    assert_eq!(row["dataset"], trial);
    let total = row["ours"]["total_deg"]
        .as_f64()
        .expect("BROAD total computed");
    assert!(
        total.is_finite() && total < 20.0,
        "BROAD total {total}°\n{text}"
    );
    assert!(row["vqf_total_deg"].as_f64().is_some(), "{text}");
    // The trial again without its magnetometer, beside VQF 6D where references.json has it
    // (else `–` and null: BROAD's published references have no VQF 6D).
    let six = row["inclination_6axis_deg"]
        .as_f64()
        .expect("6-axis inclination computed");
    assert!(
        six.is_finite() && six < 5.0,
        "6-axis inclination {six}°\n{text}"
    );
    assert!(out.join("6axis").join(trial).join("metrics.json").is_file());
    let refs: serde_json::Value =
        serde_json::from_slice(&read(&shared.join("references.json"))).unwrap();
    let published_6d = &refs["trials"][trial]["vqf_6d"]["inclination"];
    assert_eq!(&row["vqf_6d_inclination_deg"], published_6d, "{text}");
    if published_6d.is_null() {
        assert!(text.contains("no VQF 6D figure for"), "{text}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// `calibrate` on a simulated static recording: the table, the four outputs, `sensor.yaml` files
/// the dataset reader parses, and per axis a white noise density within the Allan estimator's
/// confidence of the simulated one.
#[test]
fn calibrate_a_static_recording() {
    use host_sim::dataset::yaml::SensorYaml;
    use host_sim::sensors::imu::ImuConfig;
    let dir = tmp("calibrate");
    let ds = dir.join("ds");
    simulate("static", &ds);
    let out = dir.join("noise");
    let o = host_sim(&[
        "calibrate",
        ds.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    for word in [
        "gyroscope",
        "accelerometer",
        "magnetometer",
        "rad/s/√Hz",
        "K not resolved",
        "imu0/sensor.yaml",
    ] {
        assert!(text.contains(word), "'{word}' not in:\n{text}");
    }
    for f in [
        "imu0/sensor.yaml",
        "mag0/sensor.yaml",
        "allan.csv",
        "calibration.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }

    let imu = SensorYaml::read(&out.join("imu0/sensor.yaml")).expect("imu0/sensor.yaml parses");
    assert!((imu.f64("rate_hz").unwrap() - 200.0).abs() < 1e-9);
    let t_bs = imu.list("T_BS", 16).unwrap();
    assert!(t_bs
        .iter()
        .enumerate()
        .all(|(i, &x)| x == if i % 5 == 0 { 1.0 } else { 0.0 }));
    let json: serde_json::Value = serde_json::from_slice(&read(&out.join("calibration.json")))
        .expect("calibration.json parses");

    // The simulated IMU: white noise, a bias random walk, and rounding to its LSB (white, of
    // variance lsb²/12 per sample). At the τ each axis was read, σ(τ)·√τ exceeds the density
    // by the walk's and the rounding's share; the estimate scatters by its relative error ε.
    let c = ImuConfig::default();
    for (sensor, key, n, k, lsb) in [
        (
            "gyroscope",
            "gyroscope_noise_density",
            c.gyroscope_noise_density,
            c.gyroscope_random_walk,
            c.gyro_lsb,
        ),
        (
            "accelerometer",
            "accelerometer_noise_density",
            c.accelerometer_noise_density,
            c.accelerometer_random_walk,
            c.accel_lsb,
        ),
    ] {
        let axes = json[sensor]["axes"].as_array().expect("axes");
        assert_eq!(axes.len(), 3);
        let mut largest = 0.0f64;
        for a in axes {
            let w = &a["white_noise"];
            let (value, tau, eps) = (
                w["value"].as_f64().unwrap(),
                w["tau"].as_f64().unwrap(),
                w["relative_error"].as_f64().unwrap(),
            );
            let rounding = lsb * lsb / 12.0 / c.rate_hz;
            let share = ((n * n + rounding + k * k * tau * tau / 3.0) / (n * n)).sqrt() - 1.0;
            let tol = 3.0 * eps + share;
            assert!(
                (value / n - 1.0).abs() <= tol,
                "{sensor} {}: N = {value} at τ = {tau} s against {n} (tolerance {tol})",
                a["axis"]
            );
            largest = largest.max(value);
        }
        let written = imu.f64(key).unwrap();
        assert!(
            (written / largest - 1.0).abs() < 1e-12,
            "{key}: {written} is not the largest axis {largest}"
        );
        assert_eq!(
            json[sensor]["random_walk_resolved"].as_bool(),
            Some(false),
            "60 s cannot resolve a {sensor} random walk"
        );
    }

    // The magnetometer: 60 s at 50 Hz of white noise σ = 0.4 µT; a standard deviation over n
    // samples scatters by 1/√(2(n − 1)).
    let mag = SensorYaml::read(&out.join("mag0/sensor.yaml")).expect("mag0/sensor.yaml parses");
    assert!((mag.f64("rate_hz").unwrap() - 50.0).abs() < 1e-9);
    let n = json["mag"]["samples"].as_f64().unwrap();
    let sigma = mag.f64("sigma").unwrap();
    assert!(
        (sigma / 0.4 - 1.0).abs() <= 3.0 / (2.0 * (n - 1.0)).sqrt(),
        "sigma {sigma}"
    );
    assert!(
        mag.list("reference_field", 3).is_err(),
        "the reference field is not calibrated"
    );
    let csv = std::fs::read_to_string(out.join("allan.csv")).unwrap();
    assert!(csv.starts_with("sensor,tau [s],m,sigma_x,sigma_y,sigma_z,unit,relative_error\n"));
    for sensor in ["gyroscope,", "accelerometer,", "magnetometer,"] {
        assert!(csv.lines().filter(|l| l.starts_with(sensor)).count() >= 5);
    }

    // An earlier output needs --force; the dataset folder is never the output.
    let again = |extra: &[&str]| {
        let mut args = vec!["calibrate", ds.to_str().unwrap()];
        args.extend_from_slice(extra);
        host_sim(&args)
    };
    assert!(!again(&["--out", out.to_str().unwrap()]).status.success());
    assert!(again(&["--out", out.to_str().unwrap(), "--force"])
        .status
        .success());
    let o = again(&["--out", ds.to_str().unwrap(), "--force"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds the dataset"));
    let _ = std::fs::remove_dir_all(dir);
}

/// A reversed interval, or one too short for an Allan curve, is a one-line error naming the
/// option or the file, and writes nothing.
#[test]
fn calibrate_refuses_bad_intervals() {
    let dir = tmp("calibrate-bad");
    let ds = dir.join("ds");
    simulate("static", &ds);
    let out = dir.join("noise");
    for (args, expect) in [
        (&["--from", "10", "--to", "5"][..], "--to 5"),
        (&["--from=-1"][..], "--from -1"),
        (&["--to", "0.1"][..], "imu0/data.csv"),
        (&["--from", "100"][..], "imu0/data.csv"),
    ] {
        let mut all = vec![
            "calibrate",
            ds.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        all.extend_from_slice(args);
        let o = host_sim(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} should fail");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: '{expect}' not in {err}");
        assert!(!out.exists(), "{args:?}: output left behind");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A missing optional file that changes the result is named in the summary and in
/// `metrics.json`, and the per-sensor counts say what became of every update.
#[test]
fn a_missing_lever_arm_is_a_warning_in_the_summary() {
    let base = tmp("missing-lever-arm");
    let ds = base.join("ds");
    simulate("car", &ds);
    std::fs::remove_file(ds.join("gnss0/sensor.yaml")).expect("remove");
    let out = base.join("out");
    let o = host_sim(&[
        "replay",
        ds.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("warning:") && stdout.contains("gnss0/sensor.yaml is missing"),
        "{stdout}"
    );
    assert!(
        stdout.contains("gated out") && stdout.contains("refused"),
        "{stdout}"
    );
    let m: serde_json::Value =
        serde_json::from_slice(&read(&out.join("metrics.json"))).expect("json");
    assert_eq!(m["warnings"].as_array().map(Vec::len), Some(1));
    let _ = std::fs::remove_dir_all(&base);
}

/// A 26 s scenario file in `dir` (the Monte-Carlo bands leave out the first 20 s).
fn short_montecarlo_scenario(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).expect("folder");
    let file = dir.join("short.toml");
    std::fs::write(
        &file,
        "name = \"short\"\nduration_s = 26.0\nstatic_s = 3.0\nshape = \"car\"\n[mag]\nrate_hz = 25.0\n[gnss]\nrate_hz = 2.0\n",
    )
    .expect("write");
    file
}

fn csv_rows(p: &Path) -> Vec<Vec<String>> {
    String::from_utf8_lossy(&read(p))
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

/// `montecarlo --out` writes runs.csv, bands.csv and montecarlo.json for the seeds asked for,
/// `--json` prints the same JSON, and the output folder follows the rules of every command.
#[test]
fn montecarlo_writes_runs_bands_and_json() {
    let base = tmp("montecarlo");
    let scenario = short_montecarlo_scenario(&base);
    let sc = scenario.to_str().expect("utf-8");
    let out = base.join("out");
    let out_s = out.to_str().expect("utf-8");
    let args = [
        "montecarlo",
        "--scenario",
        sc,
        "--runs",
        "2",
        "--seed",
        "5",
        "--out",
        out_s,
    ];
    let o = host_sim(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("ANEES attitude"), "{stdout}");

    let runs = csv_rows(&out.join("runs.csv"));
    assert_eq!(runs.len(), 3, "header and one row per run");
    let header = &runs[0];
    for col in [
        "seed",
        "ate_position_rmse_m",
        "attitude_rmse_deg",
        "velocity_rmse_mps",
        "anees_attitude",
        "nis_mean_gnss_position",
        "accepted_mag",
        "gated_out_mag",
        "refused_mag",
    ] {
        assert!(header.iter().any(|h| h == col), "{col} not in {header:?}");
    }
    assert_eq!((runs[1][0].as_str(), runs[2][0].as_str()), ("5", "6"));
    for row in &runs[1..] {
        assert_eq!(row.len(), header.len());
        // The heading's "largest error from 60 s after the first motion" has no sample in a
        // run shorter than that: its cell may be empty; every other figure is estimated here.
        assert!(
            row.iter()
                .zip(header)
                .all(|(c, h)| c.parse::<f64>().is_ok_and(f64::is_finite)
                    || (h == "heading_max_error_from_60s_deg" && c.is_empty())),
            "every figure is estimated here: {row:?}"
        );
    }

    let bands = csv_rows(&out.join("bands.csv"));
    assert_eq!(
        bands[0],
        [
            "statistic",
            "value",
            "expected",
            "lower",
            "upper",
            "fraction_inside",
            "holds"
        ]
    );
    assert!(bands.len() > 1, "no band: {bands:?}");
    for row in &bands[1..] {
        assert!(
            stdout.contains(&row[0]),
            "{} is in bands.csv, not in the table",
            row[0]
        );
    }

    let json: serde_json::Value =
        serde_json::from_slice(&read(&out.join("montecarlo.json"))).expect("json");
    assert_eq!(json["seeds"], serde_json::json!([5, 6]));
    assert_eq!(json["runs"], 2);
    assert_eq!(json["scenario"], "short");
    assert_eq!(json["host_sim_version"], env!("CARGO_PKG_VERSION"));
    assert!(json["precision"].is_string() && json["settle_s"].is_number());
    assert!(json["command_line"]
        .as_array()
        .is_some_and(|a| a.iter().any(|v| v == "montecarlo")));
    assert_eq!(json["per_run"].as_array().map(Vec::len), Some(2));
    assert_eq!(json["per_run"][1]["seed"], 6);
    assert_eq!(
        json["bands"].as_array().map(Vec::len),
        Some(bands.len() - 1)
    );

    // An earlier output needs --force; --json prints the same report, and --check fails
    // exactly when a band is missed.
    assert!(!host_sim(&args).status.success());
    let mut forced = args.to_vec();
    forced.extend(["--force", "--json", "--check"]);
    let o = host_sim(&forced);
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).expect("--json parses");
    assert_eq!(printed["seeds"], json["seeds"]);
    assert_eq!(printed["bands"], json["bands"]);
    assert_eq!(printed["per_run"], json["per_run"]);
    assert_eq!(Some(o.status.success()), printed["holds"].as_bool());

    // Without --seed the runs start at 1, and without --out nothing is written.
    let o = host_sim(&["montecarlo", "--scenario", sc, "--runs", "2", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).expect("--json parses");
    assert_eq!(printed["seeds"], serde_json::json!([1, 2]));

    // A folder with files host-sim did not write is refused, even with --force, and left as
    // it was.
    let foreign = base.join("foreign");
    std::fs::create_dir_all(&foreign).expect("folder");
    std::fs::write(foreign.join("notes.txt"), "mine").expect("write");
    let before = snapshot(&foreign);
    let o = host_sim(&[
        "montecarlo",
        "--scenario",
        sc,
        "--runs",
        "2",
        "--out",
        foreign.to_str().expect("utf-8"),
        "--force",
    ]);
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("did not write"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(snapshot(&foreign), before);
    assert!(partial_folders_in(&base).is_empty());
    let _ = std::fs::remove_dir_all(&base);
}

/// `run` of a short scenario writes every plot.
#[test]
fn run_writes_the_plots() {
    let base = tmp("plots");
    let scenario = short_montecarlo_scenario(&base);
    let out = base.join("out");
    let o = host_sim(&[
        "run",
        "--scenario",
        scenario.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for png in ["trajectory.png", "errors.png", "biases.png", "nis.png"] {
        let len = std::fs::metadata(out.join(png)).map_or(0, |m| m.len());
        assert!(len > 0, "{png} missing or empty");
    }
    let _ = std::fs::remove_dir_all(&base);
}

/// Kalibr's `imu0/sensor.yaml` as a EuRoC sequence ships it.
const EUROC_IMU_YAML: &str = "#Default imu sensor yaml file
sensor_type: imu
comment: VI-Sensor IMU (ADIS16448)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [1.0, 0.0, 0.0, 0.0,
         0.0, 1.0, 0.0, 0.0,
         0.0, 0.0, 1.0, 0.0,
         0.0, 0.0, 0.0, 1.0]
rate_hz: 200

# inertial sensor noise model parameters (static)
gyroscope_noise_density: 1.6968e-04     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )
gyroscope_random_walk: 1.9393e-05       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )
accelerometer_noise_density: 2.0000e-3  # [ m / s^2 / sqrt(Hz) ]  ( accel \"white noise\" )
accelerometer_random_walk: 3.0000e-3    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )
";

/// A EuRoC camera's `sensor.yaml` (pinhole, radial-tangential), without host-sim's keys.
const EUROC_CAM_YAML: &str = "# General sensor definitions.
sensor_type: camera
comment: VI-Sensor cam0 (MT9M034)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [752, 480]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
";

const EUROC_GT_HEADER: &str = "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]";

/// Writes a EuRoC sequence in its unpacked layout under `root`: `mav0/imu0` (Kalibr's
/// `sensor.yaml`, EuRoC's `data.csv` header, CRLF line ends), `mav0/state_groundtruth_estimate0`
/// (the 17 columns, EuRoC's header with its spaces, starting 1 s after the IMU, sampled 1 ms
/// after each IMU sample), `mav0/cam0` and `mav0/cam1` (camera `sensor.yaml`, `data.csv` of image
/// names, `data/` with the images' names), `mav0/leica0` and `mav0/body.yaml`.
///
/// The motion: `rest_s` at rest, then a rotation in place about a fixed tilted body axis at up to
/// 0.97 rad/s (a 1 s smooth ramp), `duration_s` in all; the true heading at the start is 70°.
/// The IMU is exact (instantaneous samples, no noise or bias).
fn write_euroc_sequence(root: &Path, rest_s: f64, duration_s: f64) {
    use host_sim::estimator_core::lie::{LieGroup, So3};
    use nalgebra::Vector3;
    let mav0 = root.join("mav0");
    for d in [
        "imu0",
        "state_groundtruth_estimate0",
        "cam0/data",
        "cam1/data",
        "leica0",
    ] {
        std::fs::create_dir_all(mav0.join(d)).unwrap();
    }
    let start: u64 = 1_403_636_579_758_555_392;
    let axis = Vector3::new(0.3, -0.2, 0.9);
    let rate = axis.norm();
    let axis = axis / rate;
    let r0 = So3::exp(&Vector3::new(0.0, 0.0, 70_f64.to_radians()))
        .compose(&So3::exp(&Vector3::new(0.05, -0.08, 0.0)));
    // The ramp s(u) = 3u² − 2u³ over the first second of motion; the angle is its integral.
    let at = |t: f64| -> (So3<f64>, Vector3<f64>) {
        let u = (t - rest_s).max(0.0);
        let (s, angle) = if u < 1.0 {
            (3.0 * u * u - 2.0 * u * u * u, u.powi(3) - 0.5 * u.powi(4))
        } else {
            (1.0, 0.5 + (u - 1.0))
        };
        (
            r0.compose(&So3::exp(&(axis * rate * angle))),
            axis * rate * s,
        )
    };
    let mut imu = String::from("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\r\n");
    let mut gt = format!("{EUROC_GT_HEADER}\n");
    let mut cam = String::from("#timestamp [ns],filename\n");
    let mut leica = String::from("#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m]\n");
    let samples = (duration_s * 200.0) as u64;
    for k in 0..samples {
        let t_ns = start + k * 5_000_000;
        let t = (k * 5_000_000) as f64 * 1e-9;
        let (r, w) = at(t);
        let f = r.inverse().act(&Vector3::new(0.0, 0.0, 9.81));
        imu.push_str(&format!(
            "{t_ns},{:.12},{:.12},{:.12},{:.12},{:.12},{:.12}\r\n",
            w.x, w.y, w.z, f.x, f.y, f.z
        ));
        if t >= 1.0 {
            let (r, _) = at(t + 1e-3);
            let q = r.quaternion();
            gt.push_str(&format!(
                "{},4.688319,-1.786938,0.783338,{:.12},{:.12},{:.12},{:.12},0.0,0.0,0.0,0.0,0.0,0.0,0.0,0.0,0.0\n",
                t_ns + 1_000_000,
                q.w,
                q.i,
                q.j,
                q.k
            ));
        }
        if k % 10 == 0 {
            cam.push_str(&format!("{t_ns},{t_ns}.png\n"));
            for c in ["cam0", "cam1"] {
                std::fs::write(mav0.join(c).join("data").join(format!("{t_ns}.png")), b"").unwrap();
            }
            leica.push_str(&format!("{t_ns},4.688319,-1.786938,0.783338\n"));
        }
    }
    std::fs::write(mav0.join("imu0/data.csv"), imu).unwrap();
    std::fs::write(mav0.join("imu0/sensor.yaml"), EUROC_IMU_YAML).unwrap();
    std::fs::write(mav0.join("state_groundtruth_estimate0/data.csv"), gt).unwrap();
    std::fs::write(
        mav0.join("state_groundtruth_estimate0/sensor.yaml"),
        "# Additional sensor information\nsensor_type: visual-inertial\ncomment: The nonlinear least-squares batch solution over the Vicon pose and IMU measurements including time offset estimation. The orientation is only accurate to within 3 degrees.\n",
    )
    .unwrap();
    for c in ["cam0", "cam1"] {
        std::fs::write(mav0.join(c).join("data.csv"), &cam).unwrap();
        std::fs::write(mav0.join(c).join("sensor.yaml"), EUROC_CAM_YAML).unwrap();
    }
    std::fs::write(mav0.join("leica0/data.csv"), leica).unwrap();
    std::fs::write(
        mav0.join("leica0/sensor.yaml"),
        "sensor_type: position\ncomment: position measurement of the prism\n",
    )
    .unwrap();
    std::fs::write(mav0.join("body.yaml"), "comment: 'Body frame reference'\n").unwrap();
}

/// `host-sim replay ROOT` on a EuRoC sequence as it unpacks (`ROOT/mav0/...`): the dataset is
/// found in `mav0/` (said in the summary), the image-only cameras are left out with a warning,
/// the attitude navigator runs on the IMU alone, and the run is scored with the heading aligned
/// (no heading reference), in the summary and in `metrics.json`.
#[test]
fn replay_of_a_euroc_sequence_root_scores_the_yaw_aligned_attitude() {
    let base = tmp("euroc");
    let root = base.join("MH_01_easy");
    write_euroc_sequence(&root, 3.0, 12.0);
    let out = base.join("out");
    let o = host_sim(&[
        "replay",
        root.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("dataset MH_01_easy"), "{stdout}");
    assert!(
        stdout.contains("holds mav0/ (EuRoC layout)") && stdout.contains("mav0"),
        "{stdout}"
    );
    assert!(
        stdout.contains("IMU only (no heading reference)"),
        "{stdout}"
    );
    for cam in ["cam0", "cam1"] {
        assert!(
            stdout
                .lines()
                .any(|l| l.contains("warning:") && l.contains(cam)),
            "{cam}: {stdout}"
        );
    }
    let m: serde_json::Value =
        serde_json::from_slice(&read(&out.join("metrics.json"))).expect("json");
    let aligned = m["attitude_rmse_yaw_aligned_deg"]
        .as_f64()
        .expect("yaw-aligned RMSE");
    let unaligned = m["attitude_rmse_deg"].as_f64().expect("RMSE");
    assert!(aligned.is_finite() && aligned < 3.0, "{aligned}°: {m}");
    assert!(unaligned > aligned + 10.0, "{unaligned}° vs {aligned}°");
    assert_eq!(m["heading_reference"], false);
    assert_eq!(m["warnings"].as_array().map(Vec::len), Some(2), "{m}");
    // No position is estimated: no ATE or RPE, not zeros.
    assert!(m["ate"].is_null() && m["rpe"].is_null(), "{m}");
    assert!(m["samples_scored"].as_u64().unwrap_or(0) > 1000);
    let dataset = m["provenance"]["dataset"].as_str().unwrap_or("");
    assert!(dataset.ends_with("mav0"), "{dataset}");
    let _ = std::fs::remove_dir_all(&base);
}

/// `host-sim run` writes evo's figures and where the run comes from in `metrics.json`.
#[test]
fn metrics_json_holds_ate_rpe_and_provenance() {
    let out = tmp("ate-rpe");
    let o = host_sim(&[
        "run",
        "--scenario",
        "car",
        "--seed",
        "4",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("ATE RMSE, SE(3)-aligned [m]"), "{stdout}");
    assert!(stdout.contains("RPE RMSE over 1 s [m]"), "{stdout}");
    let m: serde_json::Value =
        serde_json::from_slice(&read(&out.join("metrics.json"))).expect("json");
    assert_eq!(m["ate"]["alignment"], "se3");
    for a in ["none", "se3", "yaw", "origin"] {
        let s = &m["ate_by_alignment"][a];
        for k in ["rmse", "mean", "median", "std", "min", "max", "sse"] {
            assert!(s[k].as_f64().is_some_and(f64::is_finite), "{a} {k}: {s}");
        }
    }
    // The SE(3) alignment can only lower the RMSE; unaligned is the existing figure.
    let rmse = |a: &str| {
        m["ate_by_alignment"][a]["rmse"]
            .as_f64()
            .unwrap_or(f64::NAN)
    };
    assert!(rmse("se3") <= rmse("none") + 1e-12);
    assert!(rmse("se3") <= rmse("yaw") + 1e-12);
    let unaligned = m["ate_position_rmse_m"].as_f64().unwrap_or(f64::NAN);
    assert!((rmse("none") - unaligned).abs() < 1e-5, "{unaligned}");
    assert_eq!(m["rpe"]["delta"], 1.0);
    assert_eq!(m["rpe"]["delta_unit"], "s");
    assert!(m["rpe"]["pairs"].as_u64().unwrap_or(0) > 10);
    let p = &m["provenance"];
    assert_eq!(p["scenario"], "car");
    assert_eq!(p["seed"], 4);
    assert_eq!(p["precision"], "f32");
    assert_eq!(p["host_sim_version"], env!("CARGO_PKG_VERSION"));
    assert!(
        p["command_line"]
            .as_array()
            .is_some_and(|a| a.iter().any(|x| x == "--seed")),
        "{p}"
    );
    assert_eq!(m["heading_reference"], true);
    let _ = std::fs::remove_dir_all(&out);
}

/// evo (github.com/MichaelGrupp/evo) run on `estimate.tum` and `groundtruth.tum` reproduces the
/// ATE (unaligned, SE(3)- and origin-aligned) and the RPE of `metrics.json` within 1e-6
/// relative (`tools/evo_check.py`). Runs when `HOST_SIM_EVO` names a Python environment with
/// evo installed (its folder or its `python`), e.g. after
/// `python3 -m venv /tmp/evo-venv && /tmp/evo-venv/bin/pip install evo`:
/// `HOST_SIM_EVO=/tmp/evo-venv cargo test -p host-sim --test cli evo`.
#[test]
fn evo_reproduces_the_ate_and_rpe() {
    let Some(evo) = std::env::var_os("HOST_SIM_EVO") else {
        eprintln!(
            "skipped: HOST_SIM_EVO is not set (python3 -m venv /tmp/evo-venv && /tmp/evo-venv/bin/pip install evo; then HOST_SIM_EVO=/tmp/evo-venv)"
        );
        return;
    };
    let evo = PathBuf::from(evo);
    let python = if evo.is_dir() {
        evo.join("bin/python")
    } else {
        evo
    };
    assert!(
        python.is_file(),
        "HOST_SIM_EVO: {} is not a Python with evo",
        python.display()
    );
    let out = tmp("evo");
    let o = host_sim(&["run", "--out", out.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/evo_check.py");
    let check = Command::new(&python)
        .arg(&script)
        .arg(&out)
        .output()
        .expect("python runs");
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&check.stderr)
    );
    assert!(text.contains("agree with evo"), "{text}");
    let _ = std::fs::remove_dir_all(&out);
}

/// The RPE's delta and unit come from the replay configuration (evo's `--delta`,
/// `--delta_unit`), and a unit other than `s` or `m` is refused by name.
#[test]
fn rpe_delta_is_configurable() {
    let base = tmp("rpe-delta");
    let ds = base.join("ds");
    simulate("car", &ds);
    let cfg = base.join("rpe.toml");
    std::fs::write(
        &cfg,
        "rpe_delta = 5.0\nrpe_delta_unit = \"m\"\nplots = false\n",
    )
    .expect("write");
    let out = base.join("out");
    let args = [
        "replay",
        ds.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
        "--config",
        cfg.to_str().expect("utf-8"),
    ];
    let o = host_sim(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value =
        serde_json::from_slice(&read(&out.join("metrics.json"))).expect("json");
    assert_eq!(m["rpe"]["delta"].as_f64(), Some(5.0));
    assert_eq!(m["rpe"]["delta_unit"].as_str(), Some("m"));
    std::fs::write(&cfg, "rpe_delta_unit = \"km\"\n").expect("write");
    let bad = base.join("bad");
    let o = host_sim(&[
        "replay",
        ds.to_str().expect("utf-8"),
        "--out",
        bad.to_str().expect("utf-8"),
        "--config",
        cfg.to_str().expect("utf-8"),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("rpe_delta_unit"));
    let _ = std::fs::remove_dir_all(&base);
}

//! Output that can be read without knowing the code: progress off a terminal, figures with
//! their context, comparisons of like with like, and tools that say what they miss. Each test
//! runs the binary (or the tool) as a user does, on short scenarios.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{copy_dir, empty_dir, s};

/// `host-sim ARGS` with stdout and stderr captured (so stderr is not a terminal) and progress
/// lines every 0.05 s.
fn host_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .env("HOST_SIM_PROGRESS_S", "0.05")
        .output()
        .expect("host-sim runs")
}

fn tmp(name: &str) -> PathBuf {
    empty_dir("context", name)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn json(p: &Path) -> serde_json::Value {
    let b = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_slice(&b).expect("json")
}

/// The progress lines of `label` in `stderr`: `(done, total)` of each periodic line, and
/// whether the closing `N/N … done in` line is there.
fn progress_lines(stderr: &str, label: &str) -> (Vec<(u64, u64)>, bool) {
    let prefix = format!("host-sim {label}: ");
    let mut periodic = Vec::new();
    let mut done = false;
    for line in stderr.lines() {
        let Some(rest) = line.strip_prefix(&prefix) else {
            continue;
        };
        let counts = rest.split_whitespace().next().unwrap_or("");
        let (k, n) = counts.split_once('/').expect("done/total");
        let (k, n): (u64, u64) = (k.parse().expect("done"), n.parse().expect("total"));
        if rest.contains(" done in ") {
            assert_eq!(k, n, "{line}");
            done = true;
        } else {
            assert!(rest.contains(" elapsed, "), "{line}");
            assert!(
                rest.contains(" left") || rest.contains("no estimate"),
                "{line}"
            );
            periodic.push((k, n));
        }
    }
    (periodic, done)
}

/// Off a terminal, `faults` writes a plain progress line at the interval and one at the end; a
/// GNSS outage's ATE says it holds the dead reckoning and has the ATE outside the outage beside
/// it, while a scenario without an outage has none.
#[test]
fn faults_off_a_terminal_prints_progress_and_the_outage_ate_has_its_context() {
    let dir = tmp("faults");
    let outage = dir.join("short_outage.toml");
    std::fs::write(
        &outage,
        "name = \"short_outage\"\nduration_s = 40.0\n[gnss]\noutages = [[15.0, 25.0]]\n[mag]\n",
    )
    .expect("write");
    let plain = dir.join("no_outage.toml");
    std::fs::write(
        &plain,
        "name = \"no_outage\"\nduration_s = 25.0\n[gnss]\n[mag]\n",
    )
    .expect("write");
    let out = dir.join("out");
    let o = host_sim(&[
        "faults",
        "--scenario",
        s(&outage),
        "--scenario",
        s(&plain),
        "--runs",
        "1",
        "--out",
        s(&out),
    ]);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{stderr}");
    let (periodic, done) = progress_lines(&stderr, "faults");
    assert!(!periodic.is_empty(), "no periodic progress line:\n{stderr}");
    assert!(periodic.iter().all(|&(k, n)| n == 2 && k <= 2), "{stderr}");
    assert!(done, "no closing progress line:\n{stderr}");

    assert!(
        stdout.contains("short_outage: the ATE includes the IMU-only dead reckoning through the GNSS outage; ATE outside it"),
        "{stdout}"
    );
    assert!(!stdout.contains("no_outage: the ATE includes"), "{stdout}");
    let j = json(&out.join("faults.json"));
    let rows = j["scenarios"].as_array().expect("scenarios");
    let with = rows
        .iter()
        .find(|r| r["scenario"] == "short_outage")
        .expect("short_outage");
    let without = rows
        .iter()
        .find(|r| r["scenario"] == "no_outage")
        .expect("no_outage");
    assert!(with["ate_note"]
        .as_str()
        .is_some_and(|n| n.contains("dead reckoning")));
    let outside = with["ate_outside_gnss_outage_se3_rmse_m"]["mean"]
        .as_f64()
        .expect("ATE outside the outage");
    assert!(outside.is_finite() && outside > 0.0, "{outside}");
    assert!(
        without["ate_note"].is_null() && without["ate_outside_gnss_outage_se3_rmse_m"].is_null()
    );
    // faults.csv holds the same figure for the one run.
    let csv = std::fs::read_to_string(out.join("faults.csv")).expect("faults.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "ate_outside_gnss_outage_m")
        .expect("column");
    let row: Vec<&str> = lines
        .find(|l| l.starts_with("short_outage,"))
        .expect("row")
        .split(',')
        .collect();
    let per_run: f64 = row[col].parse().expect("a number");
    assert!(
        (per_run - outside).abs() <= 1e-12 * outside,
        "{per_run} {outside}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Off a terminal, `montecarlo` writes a plain progress line at the interval and one at the
/// end.
#[test]
fn montecarlo_off_a_terminal_prints_progress() {
    let dir = tmp("mc");
    let sc = dir.join("short.toml");
    std::fs::write(&sc, "name = \"short\"\nduration_s = 25.0\n[gnss]\n[mag]\n").expect("write");
    let o = host_sim(&["montecarlo", "--scenario", s(&sc), "--runs", "2"]);
    let stderr = text(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let (periodic, done) = progress_lines(&stderr, "montecarlo");
    assert!(!periodic.is_empty(), "no periodic progress line:\n{stderr}");
    assert!(periodic.iter().all(|&(k, n)| n == 2 && k <= 2), "{stderr}");
    assert!(done, "no closing progress line:\n{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `run --scenario handheld_ahrs` prints a magnetometer NIS far below 1 with the navigator's
/// defaults, and says why. The figure is right: replayed with the heading noise and floor at 0
/// (the magnetometer's own white noise only, as simulated), the same NIS lies inside the
/// 99.9 % band of a mean of N χ²(1) values, `χ²_p(N)/N` (N accepted updates), and no note is
/// printed.
#[test]
fn handheld_ahrs_magnetometer_nis_is_explained_and_right() {
    let dir = tmp("ahrs");
    let out = dir.join("run");
    let o = host_sim(&["run", "--scenario", "handheld_ahrs", "--out", s(&out)]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let note = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("note: the mean NIS mag"))
        .unwrap_or_else(|| panic!("no note:\n{stdout}"));
    for part in ["heading_noise_deg", "conservative", "matched_ahrs"] {
        assert!(note.contains(part), "{note}");
    }
    let m = json(&out.join("metrics.json"));
    assert!(m["nis_mean"]["mag"].as_f64().expect("nis") < 0.1, "{m}");

    let toml = std::fs::read_to_string(out.join("dataset/replay.toml")).expect("replay.toml");
    let cfg: String = toml
        .lines()
        .filter(|l| !l.starts_with("heading_noise_deg") && !l.starts_with("heading_floor_deg"))
        .chain(["heading_noise_deg = 0.0", "heading_floor_deg = 0.0"])
        .map(|l| format!("{l}\n"))
        .collect();
    let cfg_path = dir.join("white.toml");
    std::fs::write(&cfg_path, cfg).expect("write");
    let white = dir.join("white");
    let o = host_sim(&[
        "replay",
        s(&out.join("dataset")),
        "--config",
        s(&cfg_path),
        "--out",
        s(&white),
    ]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!stdout.contains("note: the mean NIS mag"), "{stdout}");
    let m = json(&white.join("metrics.json"));
    let nis = m["nis_mean"]["mag"].as_f64().expect("nis");
    let n = m["updates_accepted"]["mag"].as_f64().expect("count");
    assert!(n >= 50.0, "{m}");
    let (lo, hi) = (
        host_sim::stats::chi2_quantile(0.0005, n) / n,
        host_sim::stats::chi2_quantile(0.9995, n) / n,
    );
    assert!(
        (lo..=hi).contains(&nis),
        "mean NIS mag {nis} outside [{lo}, {hi}] for {n} updates"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run without a heading aid says the heading is observed by nothing.
#[test]
fn no_heading_aid_says_so() {
    let dir = tmp("noaid");
    let sc = dir.join("imu_only.toml");
    std::fs::write(
        &sc,
        "name = \"imu_only\"\nduration_s = 15.0\nshape = \"handheld\"\n",
    )
    .expect("write");
    let o = host_sim(&["run", "--scenario", s(&sc), "--out", s(&dir.join("out"))]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        stdout.contains("note: no heading aid (no magnetometer, GNSS or camera)"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn simulate(scenario: &Path, out: &Path) {
    let o = host_sim(&["simulate", "--scenario", s(scenario), "--out", s(out)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// `bench`: a dataset with GNSS is labelled with the sensors it fuses and is not divided by
/// attitude-only VQF, an IMU+magnetometer dataset is; BROAD's Madgwick mean is the mean of the
/// trials' figures where every trial has one, and is left out, saying why, where one lacks it.
#[test]
fn bench_compares_like_with_like() {
    let dir = tmp("bench");
    let ahrs = dir.join("ahrs.toml");
    std::fs::write(
        &ahrs,
        "name = \"a\"\nduration_s = 8.0\nshape = \"handheld\"\n[mag]\n",
    )
    .expect("write");
    let ins = dir.join("ins.toml");
    std::fs::write(&ins, "name = \"i\"\nduration_s = 8.0\n[gnss]\n[mag]\n").expect("write");
    let data = dir.join("data");
    let kinds = data.join("kinds");
    simulate(&ahrs, &kinds.join("ahrs_one"));
    simulate(&ins, &kinds.join("ins_one"));
    std::fs::write(
        kinds.join("references.json"),
        r#"{"datasets": {"ahrs_one": {"vqf_9d": {"attitude_rmse_deg": 2.0}}, "ins_one": {"vqf_9d": {"attitude_rmse_deg": 2.0}}}}"#,
    )
    .expect("write");
    // Two BROAD-like folders from one attitude dataset: every trial with Madgwick, and one
    // trial without.
    for (folder, second) in [("full", "3.0"), ("partial", "null")] {
        let f = data.join(folder);
        for t in ["t1", "t2"] {
            copy_dir(&kinds.join("ahrs_one"), &f.join(t));
            std::fs::write(
                f.join(t).join("movement.csv"),
                "#start [ns],end [ns]\n3000000000,8000000000\n",
            )
            .expect("write");
        }
        std::fs::write(
            f.join("references.json"),
            format!(
                r#"{{"trials": {{"t1": {{"vqf_9d": {{"total": 2.0}}, "madgwick_tagp_published": {{"total": 5.0}}}}, "t2": {{"vqf_9d": {{"total": 2.0}}, "madgwick_tagp_published": {{"total": {second}}}}}}}}}"#
            ),
        )
        .expect("write");
    }
    let out = dir.join("out");
    let o = host_sim(&["bench", s(&data), "--out", s(&out)]);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{stderr}\n{stdout}");
    let (_, done) = progress_lines(&stderr, "bench");
    assert!(done, "no closing progress line:\n{stderr}");

    let j = json(&out.join("bench.json"));
    let tables = j["tables"].as_array().expect("tables");
    let table = |name: &str| {
        tables
            .iter()
            .find(|t| t["folder"].as_str().is_some_and(|f| f.ends_with(name)))
            .unwrap_or_else(|| panic!("table {name}: {j}"))
    };
    let rows = table("kinds")["rows"].as_array().expect("rows");
    let row = |name: &str| {
        rows.iter()
            .find(|r| r["dataset"] == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let (a, i) = (row("ahrs_one"), row("ins_one"));
    assert_eq!(a["sensors"], serde_json::json!(["IMU", "mag"]));
    assert_eq!(a["navigator"], "attitude");
    let rmse = a["attitude_rmse_after_2s_deg"].as_f64().expect("rmse");
    let ratio = a["ratio_to_vqf"].as_f64().expect("ratio");
    assert!(
        (ratio - rmse / 2.0).abs() <= 1e-12 * ratio,
        "{ratio} {rmse}"
    );
    assert_eq!(i["sensors"], serde_json::json!(["IMU", "mag", "GNSS"]));
    assert_eq!(i["navigator"], "ins");
    assert!(i["attitude_rmse_after_2s_deg"].as_f64().is_some());
    assert!(i["ratio_to_vqf"].is_null(), "{i}");
    assert!(i["ratio_to_vqf_absent"]
        .as_str()
        .is_some_and(|w| w.contains("not the same sensors")));
    let ins_line = stdout
        .lines()
        .find(|l| l.starts_with("ins_one"))
        .expect("ins row");
    assert!(
        ins_line.contains("IMU+mag+GNSS") && ins_line.trim_end().ends_with("– ¹"),
        "{ins_line}"
    );
    assert!(stdout.contains("¹ no ratio"), "{stdout}");

    let full = table("full");
    assert_eq!(full["mean"]["madgwick_total_deg"].as_f64(), Some(4.0));
    assert_eq!(full["max"]["madgwick_total_deg"].as_f64(), Some(5.0));
    let partial = table("partial");
    assert!(partial["mean"]["madgwick_total_deg"].is_null());
    assert_eq!(partial["madgwick_missing"], serde_json::json!(["t2"]));
    assert!(
        stdout.contains("(no Madgwick mean or max: references.json has no Madgwick figure for t2)"),
        "{stdout}"
    );
    let mean_lines: Vec<&str> = stdout.lines().filter(|l| l.starts_with("mean")).collect();
    // Madgwick's column: after the label, ours' four and VQF's (the 6-axis columns follow).
    assert!(
        mean_lines
            .iter()
            .any(|l| l.split_whitespace().nth(6) == Some("4.000")),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Python interpreter a user would run the tool with, if any.
fn python() -> Option<PathBuf> {
    let o = Command::new("python3")
        .args(["-c", "import sys; print(sys.executable)"])
        .output()
        .ok()?;
    o.status
        .success()
        .then(|| PathBuf::from(text(&o.stdout).trim()))
}

/// `tools/evo_check.py` without NumPy, and with NumPy but without evo: one line saying what to
/// install, exit status 3, no traceback. NumPy is hidden (or stood in for) by a package on
/// PYTHONPATH, so the test does not depend on what is installed.
#[test]
fn evo_check_says_what_to_install() {
    let Some(python) = python() else {
        eprintln!("skipped: no python3 on PATH");
        return;
    };
    let dir = tmp("evo");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/evo_check.py");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).expect("mkdir");
    std::fs::write(
        out.join("metrics.json"),
        r#"{"ate_by_alignment": {"none": {}}, "rpe": {"delta": 1.0}}"#,
    )
    .expect("write");
    let empty = dir.join("empty_path");
    std::fs::create_dir_all(&empty).expect("mkdir");
    let run = |stub: &str| {
        let site = dir.join(format!("site-{}", stub.len()));
        std::fs::create_dir_all(site.join("numpy")).expect("mkdir");
        std::fs::write(site.join("numpy/__init__.py"), stub).expect("write");
        Command::new(&python)
            .arg(&script)
            .arg(&out)
            .env("PYTHONPATH", &site)
            .env("PATH", &empty)
            .output()
            .expect("python runs")
    };
    let no_numpy = run("raise ImportError('hidden by the test')\n");
    let evo_beside = python.with_file_name("evo_ape").is_file();
    let mut cases = vec![("NumPy is not installed", no_numpy)];
    if evo_beside {
        eprintln!(
            "evo is installed beside {}: its absence is not tested",
            python.display()
        );
    } else {
        cases.push((
            "evo's evo_ape is not beside",
            run("# stands in for NumPy\n"),
        ));
    }
    for (what, o) in cases {
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{what}: {stderr}");
        assert!(!stderr.contains("Traceback"), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains(what) && stderr.contains("pip install evo"),
            "{stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

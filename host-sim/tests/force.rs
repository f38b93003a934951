//! `--force` replaces only what host-sim wrote: the README's sequence of commands with their
//! outputs nested under `out/`, then `host-sim run --force`, keeps every other output and every
//! file of the user's; each command's `--force` over its own earlier output keeps the files a
//! user put in it; an edited output file or a user's file where the output writes is refused.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `host-sim ARGS` run in `dir`.
fn host_sim_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("host-sim runs")
}

/// Runs and requires success.
fn ok(dir: &Path, args: &[&str]) -> Output {
    let o = host_sim_in(dir, args);
    assert!(
        o.status.success(),
        "{args:?} failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-force-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every file under `dir` with its bytes, by relative path.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// The files of `before` under `prefix` are in `after`, byte for byte.
fn kept(before: &BTreeMap<String, Vec<u8>>, after: &BTreeMap<String, Vec<u8>>, prefix: &str) {
    let mut n = 0;
    for (rel, bytes) in before.iter().filter(|(r, _)| r.starts_with(prefix)) {
        n += 1;
        assert!(
            after.get(rel) == Some(bytes),
            "{rel} was removed or changed"
        );
    }
    assert!(n > 0, "nothing under {prefix} to compare");
}

/// A user's files put into an output folder: a note at its top and one in a folder of its own.
fn add_users_files(dir: &Path) {
    std::fs::write(dir.join("NOTES.md"), "my notes on this run\n").unwrap();
    std::fs::create_dir_all(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/keep.txt"), "keep me\n").unwrap();
}

fn users_files_are_there(dir: &Path) {
    assert_eq!(
        std::fs::read_to_string(dir.join("NOTES.md")).unwrap(),
        "my notes on this run\n",
        "{}",
        dir.display()
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("mine/keep.txt")).unwrap(),
        "keep me\n"
    );
}

/// No partial, old or scratch folder of host-sim's is left in `dir`.
fn nothing_left_beside(dir: &Path) {
    let left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".host-sim-") && n != ".host-sim-output")
        .collect();
    assert!(
        left.is_empty(),
        "left beside in {}: {left:?}",
        dir.display()
    );
}

/// The README's commands in its order, outputs under `out/` (runs shortened: 2 Monte-Carlo
/// runs, one fault scenario once, calibration over 10 s), a user's files inside, then
/// `host-sim run --force` as the README says: the nested outputs and the user's files stay.
#[test]
fn the_readme_sequence_then_run_force_keeps_every_other_output() {
    let dir = tmp("readme");
    let d = dir.as_path();
    ok(d, &[]);
    ok(
        d,
        &["run", "--scenario", "handheld_ahrs", "--out", "out/ahrs"],
    );
    ok(
        d,
        &[
            "simulate",
            "--scenario",
            "car",
            "--seed",
            "3",
            "--out",
            "data/car",
        ],
    );
    ok(d, &["replay", "data/car", "--out", "out/car"]);
    ok(
        d,
        &[
            "montecarlo",
            "--scenario",
            "matched_ins",
            "--runs",
            "2",
            "--out",
            "out/mc",
        ],
    );
    ok(
        d,
        &[
            "faults",
            "--scenario",
            "fault_gnss_step",
            "--runs",
            "1",
            "--out",
            "out/faults",
        ],
    );
    ok(
        d,
        &[
            "calibrate",
            "data/car",
            "--to",
            "10",
            "--out",
            "out/my_imu_noise",
        ],
    );
    add_users_files(&d.join("out"));
    let before = snapshot(&d.join("out"));
    let main_before = std::fs::read(d.join("out/estimate.tum")).unwrap();

    // Without --force the earlier output is refused, and nothing changes.
    let o = host_sim_in(d, &["run"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    assert_eq!(snapshot(&d.join("out")), before);

    // A different seed, so that the main job's own files are seen to be replaced.
    ok(d, &["run", "--force", "--seed", "2"]);
    let after = snapshot(&d.join("out"));
    for nested in ["ahrs/", "car/", "mc/", "faults/", "my_imu_noise/", "mine/"] {
        kept(&before, &after, nested);
    }
    users_files_are_there(&d.join("out"));
    assert_ne!(
        std::fs::read(d.join("out/estimate.tum")).unwrap(),
        main_before,
        "the main job's output was not replaced"
    );
    for f in [
        "estimate.csv",
        "metrics.json",
        "errors.png",
        "dataset/imu0/data.csv",
    ] {
        assert!(d.join("out").join(f).is_file(), "out/{f} missing");
    }
    nothing_left_beside(d);
    nothing_left_beside(&d.join("out"));
    let _ = std::fs::remove_dir_all(dir);
}

/// Each command, run again with `--force` over its own earlier output that a user has put files
/// into, replaces its files and keeps the user's.
#[test]
fn each_command_with_force_keeps_the_users_files_in_its_output() {
    let dir = tmp("each");
    let d = dir.as_path();
    let commands: [(&str, &[&str]); 6] = [
        (
            "data/hover",
            &["simulate", "--scenario", "hover", "--out", "data/hover"],
        ),
        (
            "out/run",
            &["run", "--scenario", "coning", "--out", "out/run"],
        ),
        (
            "out/replay",
            &["replay", "data/hover", "--out", "out/replay"],
        ),
        (
            "out/mc",
            &[
                "montecarlo",
                "--scenario",
                "matched_ahrs",
                "--runs",
                "2",
                "--out",
                "out/mc",
            ],
        ),
        (
            "out/faults",
            &[
                "faults",
                "--scenario",
                "fault_baro_step",
                "--runs",
                "1",
                "--out",
                "out/faults",
            ],
        ),
        (
            "out/cal",
            &["calibrate", "data/hover", "--to", "10", "--out", "out/cal"],
        ),
    ];
    for (out, args) in commands {
        ok(d, args);
        add_users_files(&d.join(out));
        let mut forced = args.to_vec();
        forced.push("--force");
        ok(d, &forced);
        users_files_are_there(&d.join(out));
        let manifest = std::fs::read_to_string(d.join(out).join(".host-sim-output")).unwrap();
        assert!(!manifest.contains("NOTES.md"), "{out}: {manifest}");
        // And once more: the user's files are not adopted by the second output either.
        ok(d, &forced);
        users_files_are_there(&d.join(out));
    }
    // bench, over a folder holding the simulated dataset (no references.json: ours only).
    ok(d, &["bench", "data", "--out", "out/bench"]);
    add_users_files(&d.join("out/bench"));
    ok(d, &["bench", "data", "--out", "out/bench", "--force"]);
    users_files_are_there(&d.join("out/bench"));
    nothing_left_beside(d);
    nothing_left_beside(&d.join("out"));
    nothing_left_beside(&d.join("data"));
    let _ = std::fs::remove_dir_all(dir);
}

/// An output file the user edited, or a file of the user's where the new output writes, stops
/// `--force` before anything changes, naming the file.
#[test]
fn an_edited_output_or_a_users_file_in_the_way_is_refused() {
    let dir = tmp("refused");
    let d = dir.as_path();
    let args = ["simulate", "--scenario", "hover", "--out", "data"];
    ok(d, &args);
    let forced = [&args[..], &["--force"]].concat();
    let original = snapshot(&d.join("data"));
    std::fs::write(d.join("data/imu0/sensor.yaml"), "rate_hz: 100 # mine\n").unwrap();
    let before = snapshot(&d.join("data"));
    let o = host_sim_in(d, &forced);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("sensor.yaml") && err.contains("changed since host-sim wrote it"),
        "{err}"
    );
    assert_eq!(snapshot(&d.join("data")), before);

    // A calibration's output, a file of the user's in it named as one of a replay's outputs,
    // then a replay over it.
    std::fs::write(
        d.join("data/imu0/sensor.yaml"),
        &original["imu0/sensor.yaml"],
    )
    .unwrap();
    ok(
        d,
        &[
            "simulate",
            "--scenario",
            "hover",
            "--out",
            "data",
            "--force",
        ],
    );
    ok(d, &["calibrate", "data", "--to", "10", "--out", "out"]);
    std::fs::write(d.join("out/metrics.json"), "{\"mine\": true}\n").unwrap();
    let before = snapshot(&d.join("out"));
    let o = host_sim_in(d, &["replay", "data", "--out", "out", "--force"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("metrics.json"), "{err}");
    assert_eq!(snapshot(&d.join("out")), before);
    nothing_left_beside(d);
    let _ = std::fs::remove_dir_all(dir);
}

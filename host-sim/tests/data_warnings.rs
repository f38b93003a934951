//! No silent data: what `host-sim replay` survives in a dataset (a last line cut short, a hole
//! in the IMU, a sensor that stops early) is a warning on stderr, `warning: FILE:LINE: message`
//! with the dataset's path as given, and an entry of `data_warnings` in `metrics.json`; the
//! replay still succeeds. Data that cannot be used at all stays an error.

use serde_json::Value;
use std::path::{Path, PathBuf};

mod common;
use common::{empty_dir, host_sim, s};

fn tmp(name: &str) -> PathBuf {
    empty_dir("data", name)
}

/// A 30 s dataset (IMU 200 Hz, magnetometer 50 Hz, GNSS 5 Hz, ground truth) in `dir/ds`.
fn dataset(dir: &Path) -> PathBuf {
    let scenario = dir.join("short.toml");
    std::fs::write(
        &scenario,
        "name = \"short\"\nduration_s = 30.0\n[gnss]\n[mag]\n",
    )
    .expect("write");
    let ds = dir.join("ds");
    let o = host_sim(&["simulate", "--scenario", s(&scenario), "--out", s(&ds)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    ds
}

/// A successful replay of `ds` into `out`: its stderr and `metrics.json`.
fn replay_ok(ds: &Path, out: &Path) -> (String, Value) {
    let o = host_sim(&["replay", s(ds), "--out", s(out)]);
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "the replay fails:\n{stderr}");
    let m: Value =
        serde_json::from_slice(&std::fs::read(out.join("metrics.json")).expect("metrics"))
            .expect("json");
    (stderr, m)
}

/// The data lines of a CSV file (after its header), and the header.
fn rows(path: &Path) -> (String, Vec<String>) {
    let text = std::fs::read_to_string(path).expect("read");
    let mut lines = text.lines().map(String::from);
    let header = lines.next().expect("header");
    (header, lines.collect())
}

fn time(row: &str) -> u64 {
    row.split(',').next().expect("t").parse().expect("ns")
}

/// The one `data_warnings` entry of `m` for `file` at `line` whose message holds `what`.
fn entry<'a>(m: &'a Value, file: &str, line: usize, what: &str) -> &'a Value {
    let all = m["data_warnings"].as_array().expect("data_warnings");
    all.iter()
        .find(|w| {
            w["file"] == file
                && w["line"] == line
                && w["message"].as_str().is_some_and(|t| t.contains(what))
        })
        .unwrap_or_else(|| panic!("no {file}:{line} '{what}' in {all:#?}"))
}

/// The stderr line warning about `file` at `line`.
fn warning_line<'a>(stderr: &'a str, file: &str, line: usize) -> &'a str {
    let prefix = format!("warning: {file}:{line}: ");
    stderr
        .lines()
        .find(|l| l.starts_with(&prefix))
        .unwrap_or_else(|| panic!("no '{prefix}' in:\n{stderr}"))
}

/// A last line without its newline that does not parse is skipped with a warning naming the
/// file and the line; one that parses is used, with a warning; the same line with its newline
/// is an error. A clean dataset has no warning at all.
#[test]
fn a_cut_last_line_is_skipped_or_used_with_a_warning() {
    let dir = tmp("cut");
    let ds = dataset(&dir);
    let (stderr, m) = replay_ok(&ds, &dir.join("clean"));
    assert!(!stderr.contains("warning:"), "{stderr}");
    assert_eq!(m["data_warnings"], Value::Array(Vec::new()));

    let imu = ds.join("imu0/data.csv");
    let (header, data) = rows(&imu);
    let n = data.len();
    // The recording stopped in the middle of the last row: three of its seven columns.
    let last = &data[n - 1];
    let cut: String = last.split(',').take(3).collect::<Vec<_>>().join(",");
    let body = data[..n - 1].join("\n");
    std::fs::write(&imu, format!("{header}\n{body}\n{cut}")).expect("write");
    let line = n + 1; // the header is line 1
    let file = format!("{}/imu0/data.csv", s(&ds));
    let (stderr, m) = replay_ok(&ds, &dir.join("cut"));
    let w = warning_line(&stderr, &file, line);
    assert!(
        w.contains("no newline")
            && w.contains("does not parse (expected 7 columns, got 3)")
            && w.contains("skipped"),
        "{w}"
    );
    entry(&m, &file, line, "taken as cut off and skipped");

    // Cut inside its last number: the row still parses and is used, with a warning.
    let cut = &last[..last.len() - 3];
    std::fs::write(&imu, format!("{header}\n{body}\n{cut}")).expect("write");
    let (stderr, m) = replay_ok(&ds, &dir.join("cut_number"));
    let w = warning_line(&stderr, &file, line);
    assert!(
        w.contains("may be cut short; it parses, so it is used"),
        "{w}"
    );
    entry(&m, &file, line, "it parses, so it is used");

    // The same short row ended by its newline was written whole: malformed, an error.
    let cut: String = last.split(',').take(3).collect::<Vec<_>>().join(",");
    std::fs::write(&imu, format!("{header}\n{body}\n{cut}\n")).expect("write");
    let o = host_sim(&["replay", s(&ds), "--out", s(&dir.join("error"))]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains(&format!("{file}:{line}: expected 7 columns, got 3")),
        "{err}"
    );

    // Every CSV reader: a cut last line of the GNSS file and of the ground truth.
    std::fs::write(&imu, format!("{header}\n{}\n", data.join("\n"))).expect("write");
    for rel in ["gnss0/data.csv", "state_groundtruth_estimate0/data.csv"] {
        let path = ds.join(rel);
        let (header, data) = rows(&path);
        let body = data[..data.len() - 1].join("\n");
        std::fs::write(&path, format!("{header}\n{body}\n1")).expect("write");
        let (stderr, m) = replay_ok(&ds, &dir.join(rel.replace('/', "_")));
        let file = format!("{}/{rel}", s(&ds));
        let w = warning_line(&stderr, &file, data.len() + 1);
        assert!(w.contains("does not parse"), "{w}");
        entry(&m, &file, data.len() + 1, "skipped");
    }

    // An IMU file with no row that parses cannot be replayed: an error naming it.
    std::fs::write(&imu, format!("{header}\n{cut}")).expect("write");
    let o = host_sim(&["replay", s(&ds), "--out", s(&dir.join("none"))]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains(&format!("{file}: no IMU sample")) && err.contains("line 2"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// A 10 s hole in the IMU: a warning at the first row after it, saying what the navigator does
/// (it realigns, as `validity.csv` shows) and what became of the aiding samples inside it (the
/// `refused` counts of the summary).
#[test]
fn a_ten_second_imu_hole_is_warned() {
    let dir = tmp("hole");
    let ds = dataset(&dir);
    let imu = ds.join("imu0/data.csv");
    let (header, data) = rows(&imu);
    let t0 = time(&data[0]);
    let (a, b) = (t0 + 10_000_000_000, t0 + 20_000_000_000);
    let kept: Vec<&String> = data.iter().filter(|r| !(a..b).contains(&time(r))).collect();
    let after = kept
        .iter()
        .position(|r| time(r) >= b)
        .expect("rows after the hole");
    let hole_end = time(kept[after]);
    let before = time(kept[after - 1]);
    let line = after + 2;
    std::fs::write(
        &imu,
        format!(
            "{header}\n{}\n",
            kept.iter()
                .map(|r| r.as_str())
                .collect::<Vec<_>>()
                .join("\n")
        ),
    )
    .expect("write");
    let out = dir.join("out");
    let (stderr, m) = replay_ok(&ds, &out);
    let file = format!("{}/imu0/data.csv", s(&ds));
    let w = warning_line(&stderr, &file, line);
    let gap = (hole_end - before) as f64 * 1e-9;
    assert!(
        w.contains(&format!("no IMU sample for {gap:.2} s"))
            && w.contains("max_dt = 0.1 s")
            && w.contains("realigned"),
        "{w}"
    );
    // The aiding samples stamped inside the hole, refused: the summary's counts, explained.
    let refused_mag = m["updates_refused"]["mag"].as_u64().expect("mag refused");
    let refused_gnss = m["updates_refused"]["gnss_position"]
        .as_u64()
        .expect("gnss refused");
    assert!(refused_mag > 400 && refused_gnss > 40, "{m}");
    assert!(
        w.contains(&format!(
            "{refused_mag} magnetometer samples, the navigator refused {refused_mag} of them"
        )) && w.contains(&format!(
            "{refused_gnss} GNSS fixes, the navigator refused {refused_gnss} of them"
        )),
        "{w}"
    );
    entry(&m, &file, line, "no IMU sample for");
    let validity = std::fs::read_to_string(out.join("validity.csv")).expect("validity.csv");
    assert!(validity.contains(&format!("{hole_end},")) && validity.contains(",realigned"));
    let _ = std::fs::remove_dir_all(dir);
}

/// A magnetometer whose file ends 20 s before the IMU's: a warning at its last row saying how
/// long the run goes without it.
#[test]
fn a_magnetometer_that_stops_early_is_warned() {
    let dir = tmp("mag");
    let ds = dataset(&dir);
    let mag = ds.join("mag0/data.csv");
    let (header, data) = rows(&mag);
    let t0 = time(&data[0]);
    let kept: Vec<&str> = data
        .iter()
        .filter(|r| time(r) <= t0 + 10_000_000_000)
        .map(String::as_str)
        .collect();
    std::fs::write(&mag, format!("{header}\n{}\n", kept.join("\n"))).expect("write");
    let (_, imu) = rows(&ds.join("imu0/data.csv"));
    let imu_end = time(imu.last().expect("rows"));
    let last = time(kept.last().expect("rows"));
    let early = (imu_end - last) as f64 * 1e-9;
    assert!(early > 19.0, "{early}");
    let (stderr, m) = replay_ok(&ds, &dir.join("out"));
    let file = format!("{}/mag0/data.csv", s(&ds));
    let line = kept.len() + 1;
    let w = warning_line(&stderr, &file, line);
    assert!(
        w.contains(&format!(
            "the magnetometer stops {early:.2} s before the IMU"
        )) && w.contains(&format!("the last {early:.2} s of the run go without it")),
        "{w}"
    );
    entry(&m, &file, line, "stops");
    assert_eq!(m["data_warnings"].as_array().map(Vec::len), Some(1), "{m}");
    let _ = std::fs::remove_dir_all(dir);
}

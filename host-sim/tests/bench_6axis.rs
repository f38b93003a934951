//! `host-sim bench`'s 6-axis column on tiny simulated BROAD-like trials: the attitude
//! navigator replayed without the magnetometer beside VQF 6D's inclination, taken from
//! `references.json` or `--references-6d`; `–` / `null` where there is none. And
//! `tools/vqf_references.py`, where Python with NumPy and vqf is present: its file is what the
//! bench reads, and its metric is host-sim's on the same estimate.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{copy_dir, empty_dir, host_sim, s};

fn read_json(p: &Path) -> serde_json::Value {
    let text = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_slice(&text).expect("json")
}

/// `DIR/data/broadlike/` with `trial_a` (IMU, magnetometer, a truth with rows lost inside the
/// movement interval) and `trial_b` (IMU only), and a references.json with VQF 6D for
/// `trial_a` only.
fn broadlike(dir: &Path) -> PathBuf {
    let scenario = dir.join("tiny.toml");
    std::fs::write(
        &scenario,
        "name = \"tiny\"\nduration_s = 9.0\nstatic_s = 3.0\n[mag]\nrate_hz = 25.0\n",
    )
    .unwrap();
    let sim = dir.join("sim");
    let o = host_sim(&["simulate", "--scenario", s(&scenario), "--out", s(&sim)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let group = dir.join("data/broadlike");
    for name in ["trial_a", "trial_b"] {
        let t = group.join(name);
        copy_dir(&sim, &t);
        std::fs::write(
            t.join("movement.csv"),
            "#start [ns],end [ns]\n4000000000,8500000000\n",
        )
        .unwrap();
    }
    std::fs::remove_dir_all(group.join("trial_b/mag0")).unwrap();
    // The truth as BROAD's is here: every third row (the replay interpolates between them),
    // and in trial_a rows lost from 5.5 to 5.8 s (after the first timestamp, at 1 s).
    for (name, lost) in [("trial_a", 6_500_000_000..6_800_000_000), ("trial_b", 0..0)] {
        let gt = group
            .join(name)
            .join("state_groundtruth_estimate0/data.csv");
        let text = std::fs::read_to_string(&gt).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap();
        let kept: Vec<&str> = std::iter::once(header)
            .chain(lines.step_by(3).filter(|l| {
                let t: u64 = l.split(',').next().unwrap().parse().unwrap();
                !lost.contains(&t)
            }))
            .collect();
        std::fs::write(&gt, kept.join("\n") + "\n").unwrap();
    }
    std::fs::write(
        group.join("references.json"),
        r#"{"trials": {"trial_a": {"vqf_9d": {"total": 2.5}, "vqf_6d": {"inclination": 0.5}}}}"#,
    )
    .unwrap();
    dir.join("data")
}

fn row<'a>(text: &'a str, name: &str) -> &'a str {
    text.lines()
        .find(|l| l.starts_with(name))
        .unwrap_or_else(|| panic!("no row {name}:\n{text}"))
}

#[test]
fn bench_sets_ours_without_the_magnetometer_beside_vqf_6d() {
    let dir = empty_dir("bench6", "column");
    let data = broadlike(&dir);

    // references.json has VQF 6D for trial_a only: trial_b's is `–` / null, and so are the
    // mean and max.
    let out = dir.join("out");
    let o = host_sim(&["bench", s(&data), "--out", s(&out)]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{}\n{text}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        text.contains("ours 6-ax") && text.contains("VQF 6D"),
        "{text}"
    );
    assert!(
        row(&text, "trial_a").trim_end().ends_with("0.500"),
        "{text}"
    );
    assert!(row(&text, "trial_b").trim_end().ends_with('–'), "{text}");
    assert!(row(&text, "mean").trim_end().ends_with('–'), "{text}");
    assert!(text.contains("no VQF 6D figure for trial_b"), "{text}");
    let json = read_json(&out.join("bench.json"));
    let table = &json["tables"][0];
    assert_eq!(table["kind"], "broad");
    let (a, b) = (&table["rows"][0], &table["rows"][1]);
    assert_eq!(a["dataset"], "trial_a");
    assert_eq!(a["vqf_6d_inclination_deg"], 0.5);
    assert!(a["vqf_6d_from"]
        .as_str()
        .is_some_and(|p| p.ends_with("references.json")));
    assert!(b["vqf_6d_inclination_deg"].is_null() && b["vqf_6d_from"].is_null());
    assert!(table["mean"]["vqf_6d_inclination_deg"].is_null());
    assert_eq!(table["vqf_6d_missing"], serde_json::json!(["trial_b"]));

    // trial_a ran again without its magnetometer, into OUT/6axis/trial_a; trial_b (IMU only)
    // is 6-axis already.
    let six = read_json(&out.join("6axis/trial_a/metrics.json"));
    let main = read_json(&out.join("trial_a/metrics.json"));
    assert!(main["updates_accepted"].get("mag").is_some());
    assert!(six["updates_accepted"].get("mag").is_none());
    assert_eq!(six["heading_reference"], false);
    assert_eq!(
        a["inclination_6axis_deg"].as_f64(),
        six["broad"]["inclination_deg"].as_f64()
    );
    assert!(a["inclination_6axis_deg"]
        .as_f64()
        .is_some_and(|x| x < 10.0));
    assert!(!out.join("6axis/trial_b").exists());
    assert_eq!(b["inclination_6axis_deg"], b["ours"]["inclination_deg"]);
    assert!(table["mean"]["inclination_6axis_deg"].as_f64().is_some());
    // The lost truth rows are not scored: fewer samples than the movement interval holds.
    let b_samples = b["samples"].as_u64().unwrap();
    assert!(a["samples"].as_u64().unwrap() + 50 < b_samples, "{a} {b}");

    // --references-6d fills in what references.json lacks; references.json comes first.
    let file = dir.join("six.json");
    std::fs::write(
        &file,
        r#"{"trials": {"trial_a": {"vqf_6d": {"inclination": 9.0}}, "trial_b": {"vqf_6d": {"inclination": 0.75}}}}"#,
    )
    .unwrap();
    let out2 = dir.join("out2");
    let o = host_sim(&[
        "bench",
        s(&data),
        "--references-6d",
        s(&file),
        "--out",
        s(&out2),
    ]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        row(&text, "trial_b").trim_end().ends_with("0.750"),
        "{text}"
    );
    assert!(row(&text, "mean").trim_end().ends_with("0.625"), "{text}");
    let json = read_json(&out2.join("bench.json"));
    assert_eq!(json["references_6d"], s(&file));
    let rows = &json["tables"][0]["rows"];
    assert_eq!(rows[0]["vqf_6d_inclination_deg"], 0.5);
    assert_eq!(rows[1]["vqf_6d_inclination_deg"], 0.75);
    assert_eq!(rows[1]["vqf_6d_from"], s(&file));

    // A --references-6d that is missing or not BROAD's shape stops the bench before it runs.
    std::fs::write(&file, r#"{"datasets": {}}"#).unwrap();
    for (arg, why) in [
        (dir.join("absent.json"), "no such file"),
        (file.clone(), "\"datasets\""),
    ] {
        let out3 = dir.join("out3");
        let o = host_sim(&[
            "bench",
            s(&data),
            "--references-6d",
            s(&arg),
            "--out",
            s(&out3),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(
            err.contains("--references-6d") && err.contains(why),
            "{err}"
        );
        assert!(!out3.exists());
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// `python3` with NumPy and vqf, or why not.
fn python_with_vqf() -> Result<(), String> {
    match Command::new("python3")
        .args(["-c", "import numpy, vqf"])
        .output()
    {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(String::from_utf8_lossy(&o.stderr).trim().to_string()),
        Err(e) => Err(format!("python3: {e}")),
    }
}

fn tool() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/vqf_references.py")
}

/// The tool on the simulated trials: the shape the bench reads, no overwriting, and its metric
/// (the tool's `score`) equal to host-sim's on the same estimate, lost truth rows included.
#[test]
fn vqf_references_writes_what_the_bench_reads_and_scores_as_host_sim() {
    if let Err(why) = python_with_vqf() {
        eprintln!("skipped: no python3 with NumPy and vqf ({why}); pip install numpy vqf");
        return;
    }
    let dir = empty_dir("bench6", "tool");
    let data = broadlike(&dir);
    let file = dir.join("vqf.json");
    let run = |out: &Path| {
        Command::new("python3")
            .arg(tool())
            .arg(data.join("broadlike"))
            .arg("--out")
            .arg(out)
            .output()
            .expect("python3 runs")
    };
    let o = run(&file);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = read_json(&file);
    for t in ["trial_a", "trial_b"] {
        let x = v["trials"][t]["vqf_6d"]["inclination"].as_f64();
        assert!(x.is_some_and(|x| x.is_finite() && x >= 0.0), "{t}: {v}");
    }
    assert!(v["trials"]["trial_a"]["vqf_9d"]["total"].as_f64().is_some());
    assert!(v["trials"]["trial_b"].get("vqf_9d").is_none(), "no mag0");
    // Never overwritten.
    let before = std::fs::read(&file).unwrap();
    let o = run(&file);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("exists"));
    assert_eq!(std::fs::read(&file).unwrap(), before);

    // The bench takes the file for trial_b (references.json has trial_a's).
    let out = dir.join("out");
    let o = host_sim(&[
        "bench",
        s(&data),
        "--references-6d",
        s(&file),
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bench = read_json(&out.join("bench.json"));
    assert_eq!(
        bench["tables"][0]["rows"][1]["vqf_6d_inclination_deg"],
        v["trials"]["trial_b"]["vqf_6d"]["inclination"]
    );

    // The tool's metric on ours' estimates equals host-sim's (both runs of trial_a, whose
    // truth has rows lost, and trial_b).
    let script = r#"
import json, sys
sys.path.insert(0, sys.argv[1])
import vqf_references as V
trial, run = sys.argv[2], sys.argv[3]
t_gt, gt = V.read_csv(trial + "/state_groundtruth_estimate0/data.csv", 8)
t, est = V.read_csv(run + "/estimate.csv", 8)
print(json.dumps(V.score(t, V.normalized(est[:, 3:7]), t_gt, V.normalized(gt[:, 3:7]),
                         V.read_movement(trial + "/movement.csv"))))
"#;
    for (trial, run) in [
        ("trial_a", "trial_a"),
        ("trial_a", "6axis/trial_a"),
        ("trial_b", "trial_b"),
    ] {
        // -B: no __pycache__ left in tools/.
        let o = Command::new("python3")
            .args(["-B", "-c", script])
            .arg(tool().parent().unwrap())
            .arg(data.join("broadlike").join(trial))
            .arg(out.join(run))
            .output()
            .expect("python3 runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let py: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
        let ours = read_json(&out.join(run).join("metrics.json"))["broad"].clone();
        assert_eq!(py["samples"], ours["samples"], "{run}");
        for (k, key) in [
            ("total", "total_deg"),
            ("heading", "heading_deg"),
            ("inclination", "inclination_deg"),
        ] {
            let (p, h) = (py[k].as_f64().unwrap(), ours[key].as_f64().unwrap());
            // estimate.csv holds the quaternion to 1e-9.
            assert!((p - h).abs() < 1e-6, "{run} {k}: python {p}, host-sim {h}");
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// On BROAD's trial 28 of the shared datasets (where the optical markers were lost for 1.4 s
/// of fast turns), the tool's real-time VQF 9D scores as BROAD's published one: it reproduces
/// BROAD's scoring. Skipped without the data or without Python's NumPy and vqf.
#[test]
fn vqf_references_reproduces_the_published_vqf_9d_on_a_shared_trial() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/datasets/broad");
    let trial = "28_disturbed_stationary_magnet_A";
    if !shared.join(trial).join("imu0/data.csv").is_file() {
        eprintln!(
            "skipped: {} is absent (the shared datasets are not on this machine)",
            shared.join(trial).display()
        );
        return;
    }
    if let Err(why) = python_with_vqf() {
        eprintln!("skipped: no python3 with NumPy and vqf ({why}); pip install numpy vqf");
        return;
    }
    let dir = empty_dir("bench6", "shared");
    let file = dir.join("vqf.json");
    let o = Command::new("python3")
        .arg(tool())
        .arg(shared.join(trial))
        .arg("--out")
        .arg(&file)
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ours = read_json(&file)["trials"][trial].clone();
    let published = read_json(&shared.join("references.json"))["trials"][trial]["vqf_9d"].clone();
    for k in ["total", "heading", "inclination"] {
        let (a, b) = (
            ours["vqf_9d"][k].as_f64().unwrap(),
            published[k].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 0.01, "{k}: tool {a}, published {b}\n{text}");
    }
    // VQF's 9D inclination is its 6D one: the magnetometer turns only the heading.
    let (six, nine) = (
        ours["vqf_6d"]["inclination"].as_f64().unwrap(),
        ours["vqf_9d"]["inclination"].as_f64().unwrap(),
    );
    assert!((six - nine).abs() < 1e-3, "6D {six}, 9D {nine}");
    let _ = std::fs::remove_dir_all(dir);
}

//! The dataset target (see [`crate::run_dataset`]).
//!
//! Input: which files exist, then each file's content, either raw bytes or text in the shape
//! the layout names (a header, rows of numbers with timestamps, YAML keys) with corruptions:
//! wrong column counts, timestamps out of order, non-numbers, non-finite numbers. The folder is
//! written under the system's temporary folder, read through every entry point of
//! `host_sim::dataset::read` (and `locate`), and removed. The promise is that nothing panics:
//! every problem is an `Err`.

use crate::input::Input;
use crate::Outcome;
use host_sim::dataset::locate;
use host_sim::dataset::read::{first_truth_ns, movement, Dataset, TruthStream};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Events read per dataset, at most.
const MAX_EVENTS: usize = 20_000;

/// The files of the layout: path, data columns (0 for a YAML file), and the YAML keys.
const FILES: [(&str, usize, &[&str]); 13] = [
    ("imu0/data.csv", 7, &[]),
    (
        "imu0/sensor.yaml",
        0,
        &[
            "rate_hz",
            "gyroscope_noise_density",
            "gyroscope_random_walk",
            "accelerometer_noise_density",
            "accelerometer_random_walk",
            "T_BS",
        ],
    ),
    ("mag0/data.csv", 4, &[]),
    (
        "mag0/sensor.yaml",
        0,
        &["rate_hz", "sigma", "reference_field"],
    ),
    ("gnss0/data.csv", 9, &[]),
    ("gnss0/sensor.yaml", 0, &["lever_arm"]),
    ("baro0/data.csv", 2, &[]),
    ("baro0/sensor.yaml", 0, &["sigma"]),
    (
        "cam0/sensor.yaml",
        0,
        &["intrinsics", "T_BS", "sigma_px", "resolution"],
    ),
    ("cam0/landmarks.csv", 4, &[]),
    ("cam0/observations.csv", 4, &[]),
    ("state_groundtruth_estimate0/data.csv", 17, &[]),
    ("movement.csv", 2, &[]),
];

/// A folder of its own per call (the replay runs tests in parallel).
fn scratch() -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    std::env::temp_dir().join(format!(
        "estimator-fuzz-dataset-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ))
}

pub(crate) fn run(data: &[u8]) -> Outcome {
    let root = scratch();
    let _ = std::fs::remove_dir_all(&root);
    let result = read(&root, data);
    let _ = std::fs::remove_dir_all(&root);
    result
}

fn read(root: &Path, data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    // The dataset in `root` or in `root/mav0` (EuRoC's layout).
    let dir = if input.chance(32) {
        root.join("mav0")
    } else {
        root.to_path_buf()
    };
    let present = u32::from(input.u16()) | if input.chance(224) { 1 } else { 0 };
    for (k, (path, columns, keys)) in FILES.iter().enumerate() {
        if present & (1 << k) == 0 {
            continue;
        }
        let content = if input.chance(64) {
            input.bytes(4096).to_vec()
        } else if *columns == 0 {
            yaml(&mut input, keys).into_bytes()
        } else {
            csv(&mut input, *columns, *path == "gnss0/data.csv").into_bytes()
        };
        let file = dir.join(path);
        if let Some(parent) = file.parent() {
            let _ = std::fs::create_dir_all(parent);
        }
        let _ = std::fs::write(&file, content);
    }
    if input.chance(16) {
        let _ = std::fs::create_dir_all(dir.join("cam1"));
    }
    let located = locate(root);
    let _ = located.note();
    let dir = located.dir;
    if let Ok(dataset) = Dataset::open(&dir) {
        let _ = format!("{dataset:?}");
        if let Ok(events) = dataset.events() {
            for event in events.take(MAX_EVENTS) {
                match event {
                    Ok(e) => {
                        let _ = e.t_ns();
                    }
                    Err(e) => {
                        let _ = e.to_string();
                        break;
                    }
                }
            }
        }
    } else if let Err(e) = Dataset::open(&dir) {
        let _ = e.to_string();
    }
    if let Ok(mut truth) = TruthStream::open(&dir) {
        for _ in 0..MAX_EVENTS {
            match truth.next_truth() {
                Ok(Some(_)) => {}
                Ok(None) => break,
                Err(e) => {
                    let _ = e.to_string();
                    break;
                }
            }
        }
    }
    let _ = movement(&dir).map_err(|e| e.to_string());
    let _ = first_truth_ns(&dir).map_err(|e| e.to_string());
    Ok(())
}

/// A number as text: a real in one of several spellings, or not a number at all.
fn number(input: &mut Input<'_>, out: &mut String) {
    const WORDS: [&str; 12] = [
        "", "nan", "NaN", "inf", "-inf", "1e999", "-0", "abc", "0x10", "+", "1_000", " 2 ",
    ];
    match input.byte() % 16 {
        0 => out.push_str(WORDS[input.pick(WORDS.len())]),
        1 => {
            let _ = write!(out, "{:e}", input.real::<f64>());
        }
        2 => {
            let _ = write!(out, "{}", input.real::<f32>());
        }
        _ => {
            let _ = write!(out, "{}", input.moderate::<f64>());
        }
    }
}

/// A CSV file of `columns` columns: an optional header, rows with timestamps (increasing,
/// equal, decreasing or anything) and numbers, with the column count sometimes wrong. For the
/// GNSS file (`gnss`) the second header is the geodetic form's, with its ten columns.
fn csv(input: &mut Input<'_>, columns: usize, gnss: bool) -> String {
    let mut out = String::new();
    let mut columns = columns;
    match input.byte() % 4 {
        0 => {}
        1 if gnss => {
            out.push_str(host_sim::dataset::read::GEODETIC_HEADER);
            out.push('\n');
            columns = 10;
        }
        1 => out.push_str("#timestamp [ns],a,b,c\n"),
        2 => out.push_str("timestamp,a,b,c\n"),
        _ => out.push_str("# a comment, with \"quotes\n"),
    }
    let mut t: u64 = if input.chance(200) {
        1_403_636_579_758_555_392
    } else {
        input.u64()
    };
    let rows = input.pick(64);
    for _ in 0..rows {
        t = match input.byte() {
            0..=219 => t.wrapping_add(u64::from(input.u16()) * 10_000),
            220..=229 => t,
            230..=239 => t.wrapping_sub(1),
            _ => input.u64(),
        };
        let count = if input.chance(240) {
            columns
        } else {
            input.pick(20)
        };
        if input.chance(250) {
            let _ = write!(out, "{t}");
        } else {
            number(input, &mut out);
        }
        for _ in 1..count {
            out.push(',');
            number(input, &mut out);
        }
        out.push_str(if input.chance(240) { "\n" } else { "\r\n\n" });
    }
    out
}

/// A YAML file with some of `keys`, each a number, a list, a `{rows, cols, data}` map or
/// something else.
fn yaml(input: &mut Input<'_>, keys: &[&str]) -> String {
    let mut out = String::from("%YAML:1.0\n");
    if input.chance(128) {
        out.clear();
    }
    for key in keys {
        if input.chance(32) {
            continue;
        }
        let _ = write!(out, "{key}: ");
        let length = match input.byte() % 8 {
            0 => 3,
            1 => 4,
            2 => 16,
            _ => input.pick(20),
        };
        match input.byte() % 6 {
            0 | 1 => number(input, &mut out),
            2 | 3 => {
                out.push('[');
                for i in 0..length {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    number(input, &mut out);
                }
                out.push(']');
            }
            4 => {
                let _ = write!(out, "\n  cols: 4\n  rows: 4\n  data: [");
                for i in 0..length {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    number(input, &mut out);
                }
                out.push(']');
            }
            _ => {
                let junk = input.bytes(64);
                out.push_str(&String::from_utf8_lossy(junk));
            }
        }
        out.push('\n');
    }
    out
}

//! `host-sim bench DIR`: the filter over every dataset folder under `DIR`, scored and set beside
//! the published references of the same data.
//!
//! A dataset folder is one holding `imu0/data.csv`: `DIR` itself, or a folder one or two levels
//! below it (so `bench ../shared/datasets` covers `broad/` and `independent/`). Each is replayed
//! with [`crate::replay::replay_scored`], plots off, into `OUT/<dataset name>`; the datasets of
//! one parent folder make one table, against the `references.json` of that folder when there is
//! one:
//!
//! | `references.json` | table |
//! |---|---|
//! | `trials.{name}.{anchor}.{total,heading,inclination}` (BROAD) | BROAD's total / heading / inclination RMSE inside `movement.csv` ([`crate::metrics::broad`]), real-time VQF's and Madgwick's total, with the mean and the worst trial; ours also the share of those samples inside the reported 3σ ellipsoid (`inside_3sigma_pct`, the lowest trial's in the max row) |
//! | `datasets.{name}.{anchor}.attitude_rmse_deg` | the sensors ours fuses, the attitude RMSE from 2 s after the first ground-truth sample, the ANEES of the attitude, VQF's RMSE and ours / VQF |
//! | none | the same columns as the kind of data suggests (BROAD where every dataset has `movement.csv`), ours only |
//!
//! **Without the magnetometer (6-axis).** Every trial of a BROAD table that has a magnetometer
//! (and no GNSS or camera) is replayed a second time with the same configuration but
//! `use_magnetometer = false`, into `OUT/6axis/<dataset name>`; its BROAD inclination RMSE
//! (`inclination_6axis_deg`) is set beside VQF 6D's (`vqf_6d_inclination_deg`: real-time VQF on
//! the gyroscope and accelerometer only, `getQuat6D`). A trial with the IMU alone is 6-axis
//! already: its first run's figure is used. The inclination only: without a magnetometer
//! nothing observes the heading, while a heading offset of the earth frame leaves the
//! inclination error unchanged. VQF 6D's figure is the anchor `vqf_6d` of the folder's
//! `references.json` where it has one, else that of the file given with `--references-6d FILE`
//! ([`BenchOptions::references_6d`]), which has the same shape,
//! `{"trials": {NAME: {"vqf_6d": {"inclination": x}}}}`, and is written by
//! `python3 tools/vqf_references.py DIR --out FILE` (VQF 6D and 9D on the trials, scored with
//! [`crate::metrics::broad`] as here). `bench.json` names the file each figure came from
//! (`vqf_6d_from`). Without either, the column prints `–`.
//!
//! **Like with like.** Real-time VQF 9D fuses the IMU and the magnetometer. A dataset with GNSS
//! (or a camera) replays through the INS navigator, which fuses those too: its row names the
//! sensors and gets no ours / VQF ratio, which is printed only where ours fuses exactly VQF's
//! sensors ([`VQF_SENSORS`]). The means of a BROAD table (ours, VQF, Madgwick) are computed
//! only where every trial has the figure; a mean left out says which trials lack it.
//!
//! A figure that was not computed (no reference, nothing scored, a failed run) is printed `–`
//! and written `null`, never as a number. `OUT/bench.json` holds every figure of the tables.

use crate::dataset::check::DataWarning;
use crate::metrics::Metrics;
use crate::output::{OutputError, Staging};
use crate::replay::{replay_scored, ReplayConfig};
use serde::Serialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The anchor of BROAD's `references.json` used as the main comparison (real-time VQF 9D).
pub const VQF: &str = "vqf_9d";
/// BROAD's published Madgwick at its trial-agnostic good parameter.
pub const MADGWICK: &str = "madgwick_tagp_published";
/// The anchor of VQF 6D (real-time, gyroscope and accelerometer only), in `references.json` or
/// the `--references-6d` file.
pub const VQF_6D: &str = "vqf_6d";
/// The folder of `OUT` that holds the 6-axis runs (`OUT/6axis/<dataset name>`).
pub const SIX_AXIS_DIR: &str = "6axis";

/// The sensors real-time VQF 9D fuses, as [`sensors_of`] names them.
pub const VQF_SENSORS: &[&str] = &["IMU", "mag"];

/// The sensors a replay of `dataset` fuses, by the files it holds: always `IMU`, then `mag`
/// (`mag0/data.csv`), `GNSS` (`gnss0/data.csv`), `camera` (`cam0/observations.csv`) and
/// `baro` (`baro0/data.csv`, fused by the INS navigator only).
#[must_use]
pub fn sensors_of(dataset: &Path) -> Vec<&'static str> {
    let mut out = vec!["IMU"];
    let ins =
        dataset.join("gnss0/data.csv").is_file() || dataset.join("cam0/observations.csv").is_file();
    for (file, name, needs_ins) in [
        ("mag0/data.csv", "mag", false),
        ("gnss0/data.csv", "GNSS", false),
        ("cam0/observations.csv", "camera", false),
        ("baro0/data.csv", "baro", true),
    ] {
        if dataset.join(file).is_file() && (ins || !needs_ins) {
            out.push(name);
        }
    }
    out
}

/// What to bench.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The folder searched for datasets.
    pub dir: PathBuf,
    /// The output folder (one subfolder per dataset, and `bench.json`).
    pub out: PathBuf,
    /// A replay configuration for every dataset (else each dataset's `replay.toml`, else the
    /// defaults); plots are turned off either way.
    pub config: Option<PathBuf>,
    /// Replace `out` if it holds an earlier host-sim output.
    pub force: bool,
    /// VQF 6D's figures for the BROAD trials whose folder's `references.json` has none: a JSON
    /// file `{"trials": {NAME: {"vqf_6d": {"inclination": x}}}}` (written by
    /// `tools/vqf_references.py`).
    pub references_6d: Option<PathBuf>,
}

/// Errors that stop the bench before or after the datasets run (a dataset that fails is
/// reported in its row instead).
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// No dataset folder was found.
    #[error("{}: no dataset folder (one holding imu0/data.csv) in it or one or two levels below", .0.display())]
    NoDatasets(PathBuf),
    /// The folder cannot be listed.
    #[error("{}: {source}", path.display())]
    Read {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The output folder would hold the datasets.
    #[error("{}: the output folder holds the datasets {}; name another folder with --out", out.display(), dir.display())]
    OutHoldsDatasets {
        /// The output folder.
        out: PathBuf,
        /// The dataset folder.
        dir: PathBuf,
    },
    /// The given configuration is unreadable or invalid.
    #[error("{0}")]
    Config(String),
    /// The `--references-6d` file is unreadable or not of BROAD's shape.
    #[error("--references-6d {0}")]
    References6d(String),
    /// The output folder may not be written, or moving it into place failed.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// `bench.json` could not be written.
    #[error("{}: {message}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// The replay configuration for `dataset`: the `given` file, else the dataset's `replay.toml`,
/// else the defaults (the order of `host-sim replay`).
///
/// # Errors
/// An unreadable or malformed file, or a value out of its domain, naming the file.
pub fn replay_config(given: Option<&Path>, dataset: &Path) -> Result<ReplayConfig, String> {
    let source = given.map_or_else(|| dataset.join("replay.toml"), Path::to_path_buf);
    let cfg: ReplayConfig = match std::fs::read_to_string(&source) {
        Ok(text) => toml::from_str(&text)
            .map_err(|e| format!("{}: {}", source.display(), e.to_string().replace('\n', " ")))?,
        Err(e) if given.is_none() && e.kind() == std::io::ErrorKind::NotFound => {
            ReplayConfig::default()
        }
        Err(e) => return Err(format!("{}: {e}", source.display())),
    };
    cfg.validate()
        .map_err(|e| format!("{}: {e}", source.display()))?;
    Ok(cfg)
}

fn is_dataset(dir: &Path) -> bool {
    dir.join("imu0/data.csv").is_file()
}

fn subfolders(dir: &Path) -> Result<Vec<PathBuf>, BenchError> {
    let entries = std::fs::read_dir(dir).map_err(|e| BenchError::Read {
        path: dir.to_path_buf(),
        source: e,
    })?;
    let mut out = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| BenchError::Read {
                path: dir.to_path_buf(),
                source: e,
            })?
            .path();
        let hidden = path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if path.is_dir() && !hidden {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// The dataset folders (holding `imu0/data.csv`): `dir` itself, or its subfolders one and two
/// levels deep (hidden folders skipped, nothing searched inside a dataset), sorted.
///
/// # Errors
/// A folder that cannot be listed.
pub fn find_datasets(dir: &Path) -> Result<Vec<PathBuf>, BenchError> {
    if is_dataset(dir) {
        return Ok(vec![dir.to_path_buf()]);
    }
    let mut found = Vec::new();
    for sub in subfolders(dir)? {
        if is_dataset(&sub) {
            found.push(sub);
        } else {
            found.extend(subfolders(&sub)?.into_iter().filter(|d| is_dataset(d)));
        }
    }
    Ok(found)
}

/// `Some(x)` when `x` is finite: a figure that was computed.
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// BROAD's figures of one trial.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BroadFigures {
    /// Total error RMSE, degrees.
    pub total_deg: Option<f64>,
    /// Heading error RMSE, degrees.
    pub heading_deg: Option<f64>,
    /// Inclination error RMSE, degrees.
    pub inclination_deg: Option<f64>,
    /// The share of the scored samples whose attitude error is inside the reported 3σ
    /// ellipsoid (NEES ≤ 9; 97.1 % for a consistent estimate), per cent; in the `max` summary,
    /// the lowest trial's.
    pub inside_3sigma_pct: Option<f64>,
}

/// One row of a BROAD table.
#[derive(Clone, Debug, Serialize)]
pub struct BroadRow {
    /// The trial (dataset folder name).
    pub dataset: String,
    /// Why the run failed, if it did.
    pub error: Option<String>,
    /// This project's figures.
    pub ours: BroadFigures,
    /// IMU samples scored inside the movement intervals.
    pub samples: Option<u64>,
    /// Real-time VQF 9D's total RMSE from `references.json`, degrees.
    pub vqf_total_deg: Option<f64>,
    /// BROAD's published Madgwick's total RMSE, degrees.
    pub madgwick_total_deg: Option<f64>,
    /// This project's inclination RMSE without the magnetometer (the 6-axis run, see the
    /// module docs), degrees.
    pub inclination_6axis_deg: Option<f64>,
    /// Why the 6-axis run failed, if it did.
    pub error_6axis: Option<String>,
    /// VQF 6D's inclination RMSE, degrees.
    pub vqf_6d_inclination_deg: Option<f64>,
    /// The file VQF 6D's figure comes from (`references.json` or the `--references-6d` file).
    pub vqf_6d_from: Option<PathBuf>,
}

/// The mean or the maximum over the trials of a BROAD table (each `null` unless every trial has
/// the figure).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BroadSummary {
    /// This project's figures.
    pub ours: BroadFigures,
    /// Real-time VQF 9D's total RMSE, degrees.
    pub vqf_total_deg: Option<f64>,
    /// BROAD's published Madgwick's total RMSE, degrees.
    pub madgwick_total_deg: Option<f64>,
    /// This project's inclination RMSE without the magnetometer, degrees.
    pub inclination_6axis_deg: Option<f64>,
    /// VQF 6D's inclination RMSE, degrees.
    pub vqf_6d_inclination_deg: Option<f64>,
}

/// One row of a table of attitude RMSEs.
#[derive(Clone, Debug, Serialize)]
pub struct AttitudeRow {
    /// The dataset folder name.
    pub dataset: String,
    /// The sensors ours fuses ([`sensors_of`]).
    pub sensors: Vec<String>,
    /// The navigator the replay runs: `attitude` (IMU and magnetometer) or `ins` (with GNSS or
    /// a camera).
    pub navigator: String,
    /// Why the run failed, if it did.
    pub error: Option<String>,
    /// Attitude RMSE from 2 s after the first ground-truth sample, degrees.
    pub attitude_rmse_after_2s_deg: Option<f64>,
    /// Mean NEES of the attitude block (3 for a consistent filter).
    pub anees_attitude: Option<f64>,
    /// Real-time VQF 9D's attitude RMSE from `references.json`, degrees.
    pub vqf_attitude_rmse_deg: Option<f64>,
    /// Ours / VQF, only where ours fuses exactly VQF's sensors ([`VQF_SENSORS`]).
    pub ratio_to_vqf: Option<f64>,
    /// Why there is no ratio although both RMSEs are there (different sensors).
    pub ratio_to_vqf_absent: Option<String>,
}

/// The rows of one table.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Rows {
    /// BROAD's metric.
    Broad {
        /// One row per trial.
        rows: Vec<BroadRow>,
        /// The mean over the trials.
        mean: Box<BroadSummary>,
        /// The worst trial per column.
        max: Box<BroadSummary>,
        /// The trials without a Madgwick figure in `references.json` (the Madgwick mean and
        /// maximum are left out when any is).
        madgwick_missing: Vec<String>,
        /// The trials without a VQF 6D figure (in `references.json` or the `--references-6d`
        /// file; its mean and maximum are left out when any is).
        vqf_6d_missing: Vec<String>,
    },
    /// Attitude RMSE from 2 s after the start.
    Attitude {
        /// One row per dataset.
        rows: Vec<AttitudeRow>,
    },
}

/// The datasets of one parent folder.
#[derive(Clone, Debug, Serialize)]
pub struct Table {
    /// The parent folder.
    pub folder: PathBuf,
    /// Its `references.json`, when present.
    pub references: Option<PathBuf>,
    /// Why `references.json` could not be used, if so.
    pub references_error: Option<String>,
    /// The rows.
    #[serde(flatten)]
    pub rows: Rows,
}

/// The outcome of a bench (`bench.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The folder searched.
    pub dir: PathBuf,
    /// The output folder.
    pub out: PathBuf,
    /// The replay configuration file given for every dataset, if any.
    pub config: Option<PathBuf>,
    /// The `--references-6d` file, if given.
    pub references_6d: Option<PathBuf>,
    /// One table per parent folder.
    pub tables: Vec<Table>,
    /// What the datasets had wrong that their runs survived, dataset by dataset
    /// ([`crate::dataset::check`]); each dataset's `metrics.json` holds its own.
    pub data_warnings: Vec<DataWarning>,
}

/// One dataset's run, and its 6-axis run where it has one.
struct Outcome {
    name: String,
    result: Result<Metrics, String>,
    six_axis: SixAxis,
}

/// The 6-axis figure of a dataset (see the module docs).
enum SixAxis {
    /// Not a BROAD trial, or one with GNSS or a camera: none.
    None,
    /// The IMU alone: the first run is the 6-axis run.
    SameRun,
    /// A second run with `use_magnetometer = false`.
    Run(Box<Result<Metrics, String>>),
}

/// How a dataset's 6-axis figure is had, by the sensors it holds ([`sensors_of`]): `Some(true)`
/// a second run (IMU and magnetometer), `Some(false)` the first run (the IMU alone), `None`
/// none (GNSS or a camera: not a 6-axis run either way).
fn six_axis_plan(dataset: &Path) -> Option<bool> {
    match sensors_of(dataset).as_slice() {
        ["IMU"] => Some(false),
        ["IMU", "mag"] => Some(true),
        _ => None,
    }
}

/// The references of one folder, by dataset name.
enum References {
    Broad(BTreeMap<String, Value>),
    Attitude(BTreeMap<String, Value>),
}

fn read_references(path: &Path) -> Result<Option<References>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let v: Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let entries = |key: &str| {
        v.get(key)
            .and_then(Value::as_object)
            .map(|m| m.iter().map(|(k, v)| (k.clone(), v.clone())).collect())
    };
    if let Some(t) = entries("trials") {
        Ok(Some(References::Broad(t)))
    } else if let Some(d) = entries("datasets") {
        Ok(Some(References::Attitude(d)))
    } else {
        Err(format!(
            "{}: neither a \"trials\" nor a \"datasets\" object",
            path.display()
        ))
    }
}

/// The `--references-6d` file: BROAD's shape (`trials`), by trial name.
fn read_references_6d(path: &Path) -> Result<BTreeMap<String, Value>, String> {
    match read_references(path)? {
        Some(References::Broad(m)) => Ok(m),
        Some(References::Attitude(_)) => Err(format!(
            "{}: a \"datasets\" object; VQF 6D's figures are BROAD's, {{\"trials\": {{NAME: {{\"{VQF_6D}\": {{\"inclination\": x}}}}}}}}",
            path.display()
        )),
        None => Err(format!("{}: no such file", path.display())),
    }
}

fn reference(entries: &BTreeMap<String, Value>, dataset: &str, path: &[&str]) -> Option<f64> {
    let mut v = entries.get(dataset)?;
    for key in path {
        v = v.get(key)?;
    }
    v.as_f64().and_then(finite)
}

/// The mean and the maximum of a column.
type MeanMax = (Option<f64>, Option<f64>);

/// Mean and maximum of a column, `None` unless every row has a value.
fn aggregate(values: &[Option<f64>]) -> MeanMax {
    let all: Option<Vec<f64>> = values.iter().copied().collect();
    match all {
        Some(v) if !v.is_empty() => (
            Some(v.iter().sum::<f64>() / v.len() as f64),
            v.iter().copied().reduce(f64::max),
        ),
        _ => (None, None),
    }
}

/// A source of reference figures: the file and its entries by dataset name.
type Source<'a> = (&'a Path, &'a BTreeMap<String, Value>);

/// BROAD's inclination RMSE of a run, degrees.
fn inclination(m: &Metrics) -> Option<f64> {
    m.broad.as_ref().and_then(|b| finite(b.inclination_deg))
}

/// VQF 6D's inclination for `dataset`: from the first of `sources` that has it, with that file.
fn vqf_6d(sources: &[Source<'_>], dataset: &str) -> (Option<f64>, Option<PathBuf>) {
    sources
        .iter()
        .find_map(|(path, m)| {
            reference(m, dataset, &[VQF_6D, "inclination"])
                .map(|x| (Some(x), Some(path.to_path_buf())))
        })
        .unwrap_or((None, None))
}

/// The rows of a BROAD table; `refs`: the folder's `references.json`, `refs_6d`: the
/// `--references-6d` file (VQF 6D is taken from `refs` first).
fn broad_table(
    runs: &[(&Path, &Outcome)],
    refs: Option<Source<'_>>,
    refs_6d: Option<Source<'_>>,
) -> Rows {
    let sources_6d: Vec<Source<'_>> = refs.into_iter().chain(refs_6d).collect();
    let refs = refs.map(|(_, m)| m);
    let rows: Vec<BroadRow> = runs
        .iter()
        .map(|(_, o)| {
            let r = |anchor: &str| refs.and_then(|m| reference(m, &o.name, &[anchor, "total"]));
            let (ours, samples, error) = match &o.result {
                Ok(m) => match &m.broad {
                    Some(b) => (
                        BroadFigures {
                            total_deg: finite(b.total_deg),
                            heading_deg: finite(b.heading_deg),
                            inclination_deg: finite(b.inclination_deg),
                            inside_3sigma_pct: finite(b.inside_3sigma * 100.0),
                        },
                        Some(b.samples),
                        None,
                    ),
                    None => (BroadFigures::default(), None, None),
                },
                Err(e) => (BroadFigures::default(), None, Some(e.clone())),
            };
            let (inclination_6axis_deg, error_6axis) = match &o.six_axis {
                SixAxis::None => (None, None),
                SixAxis::SameRun => (o.result.as_ref().ok().and_then(inclination), None),
                SixAxis::Run(run) => match run.as_ref() {
                    Ok(m) => (inclination(m), None),
                    Err(e) => (None, Some(e.clone())),
                },
            };
            let (vqf_6d_inclination_deg, vqf_6d_from) = vqf_6d(&sources_6d, &o.name);
            BroadRow {
                dataset: o.name.clone(),
                error,
                ours,
                samples,
                vqf_total_deg: r(VQF),
                madgwick_total_deg: r(MADGWICK),
                inclination_6axis_deg,
                error_6axis,
                vqf_6d_inclination_deg,
                vqf_6d_from,
            }
        })
        .collect();
    let column =
        |f: &dyn Fn(&BroadRow) -> Option<f64>| aggregate(&rows.iter().map(f).collect::<Vec<_>>());
    let total = column(&|r| r.ours.total_deg);
    let heading = column(&|r| r.ours.heading_deg);
    let inclination = column(&|r| r.ours.inclination_deg);
    let (inside_mean, _) = column(&|r| r.ours.inside_3sigma_pct);
    // The lowest trial: the largest of the negated shares.
    let inside_lowest = column(&|r| r.ours.inside_3sigma_pct.map(|x| -x))
        .1
        .map(|x| -x);
    let vqf = column(&|r| r.vqf_total_deg);
    let madgwick = column(&|r| r.madgwick_total_deg);
    let six = column(&|r| r.inclination_6axis_deg);
    let vqf_6d = column(&|r| r.vqf_6d_inclination_deg);
    let missing = |f: fn(&BroadRow) -> Option<f64>| {
        rows.iter()
            .filter(|r| f(r).is_none())
            .map(|r| r.dataset.clone())
            .collect()
    };
    let madgwick_missing = missing(|r| r.madgwick_total_deg);
    let vqf_6d_missing = missing(|r| r.vqf_6d_inclination_deg);
    let summary = |pick: fn(MeanMax) -> Option<f64>, inside: Option<f64>| BroadSummary {
        ours: BroadFigures {
            total_deg: pick(total),
            heading_deg: pick(heading),
            inclination_deg: pick(inclination),
            inside_3sigma_pct: inside,
        },
        vqf_total_deg: pick(vqf),
        madgwick_total_deg: pick(madgwick),
        inclination_6axis_deg: pick(six),
        vqf_6d_inclination_deg: pick(vqf_6d),
    };
    Rows::Broad {
        mean: Box::new(summary(|(mean, _)| mean, inside_mean)),
        max: Box::new(summary(|(_, max)| max, inside_lowest)),
        rows,
        madgwick_missing,
        vqf_6d_missing,
    }
}

fn attitude_table(runs: &[(&Path, &Outcome)], refs: Option<&BTreeMap<String, Value>>) -> Rows {
    let rows = runs
        .iter()
        .map(|(dataset, o)| {
            let sensors = sensors_of(dataset);
            let alike = sensors == VQF_SENSORS;
            let vqf = refs.and_then(|m| reference(m, &o.name, &[VQF, "attitude_rmse_deg"]));
            let (rmse, anees, error) = match &o.result {
                Ok(m) => (
                    finite(m.attitude_rmse_after_2s_deg),
                    m.nees_mean.get("attitude").copied().and_then(finite),
                    None,
                ),
                Err(e) => (None, None, Some(e.clone())),
            };
            let (ratio, ratio_absent) = match (rmse, vqf) {
                (Some(_), Some(_)) if !alike => (
                    None,
                    Some(format!(
                        "ours fuses {}, VQF 9D {}: not the same sensors",
                        sensors.join("+"),
                        VQF_SENSORS.join("+")
                    )),
                ),
                (Some(a), Some(b)) if b > 0.0 => (finite(a / b), None),
                _ => (None, None),
            };
            let navigator = if sensors.contains(&"GNSS") || sensors.contains(&"camera") {
                "ins"
            } else {
                "attitude"
            };
            AttitudeRow {
                dataset: o.name.clone(),
                sensors: sensors.iter().map(|s| (*s).to_string()).collect(),
                navigator: navigator.into(),
                error,
                attitude_rmse_after_2s_deg: rmse,
                anees_attitude: anees,
                vqf_attitude_rmse_deg: vqf,
                ratio_to_vqf: ratio,
                ratio_to_vqf_absent: ratio_absent,
            }
        })
        .collect();
    Rows::Attitude { rows }
}

/// Output subfolder names: the dataset folder's name, prefixed with its parent's where two
/// datasets share a name or where it is [`SIX_AXIS_DIR`] (the folder of the 6-axis runs).
fn output_names(datasets: &[PathBuf]) -> Vec<String> {
    let base = |d: &Path| {
        d.file_name().map_or_else(
            || "dataset".to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    };
    let names: Vec<String> = datasets.iter().map(|d| base(d)).collect();
    names
        .iter()
        .zip(datasets)
        .map(|(n, d)| {
            if n == SIX_AXIS_DIR || names.iter().filter(|m| *m == n).count() > 1 {
                let parent = d.parent().map_or_else(String::new, base);
                format!("{parent}-{n}")
            } else {
                n.clone()
            }
        })
        .collect()
}

/// Replays one dataset into `out` (`six_axis`: without its magnetometer); a panic in the filter
/// is reported as the dataset's failure.
fn run_one(
    dataset: &Path,
    out: &Path,
    given: Option<&Path>,
    name: &str,
    six_axis: bool,
) -> Result<Metrics, String> {
    let mut cfg = replay_config(given, dataset)?;
    cfg.plots = false;
    if six_axis {
        cfg.use_magnetometer = false;
    }
    let scorer = crate::metrics::Scorer::default()
        .for_dataset(dataset)
        .map_err(|e| e.to_string())?;
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        replay_scored(dataset, out, &cfg, name, scorer)
    }));
    let metrics = match run {
        Ok(Ok(scorer)) => scorer.metrics(),
        Ok(Err(e)) => return Err(e.to_string()),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            return Err(format!("panicked: {what}"));
        }
    };
    let truth = dataset.join("state_groundtruth_estimate0/data.csv");
    if metrics.samples_scored == 0 && truth.is_file() {
        return Err(format!(
            "{}: no estimate could be scored against it",
            truth.display()
        ));
    }
    Ok(metrics)
}

/// Runs the bench (see the module docs): replays every dataset under `opts.dir` into
/// `opts.out`, writes `bench.json` there and moves the folder into place. A dataset that fails
/// is reported in its row ([`Report::failures`]) and does not stop the others.
///
/// `progress` is called before each dataset with its index, the count and its folder.
///
/// # Errors
/// No dataset found, an unusable `--config`, or an output folder that may not be written.
pub fn run(
    opts: &BenchOptions,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Report, BenchError> {
    let datasets = find_datasets(&opts.dir)?;
    if datasets.is_empty() {
        return Err(BenchError::NoDatasets(opts.dir.clone()));
    }
    if let (Ok(d), Ok(o)) = (opts.dir.canonicalize(), opts.out.canonicalize()) {
        if d.starts_with(&o) {
            return Err(BenchError::OutHoldsDatasets {
                out: opts.out.clone(),
                dir: opts.dir.clone(),
            });
        }
    }
    if let Some(c) = &opts.config {
        // Checked once before anything runs (and again per dataset).
        replay_config(Some(c), &opts.dir).map_err(BenchError::Config)?;
    }
    let refs_6d = match &opts.references_6d {
        Some(p) => Some(read_references_6d(p).map_err(BenchError::References6d)?),
        None => None,
    };

    // One table per parent folder, in the order found, with its references: read before the
    // runs, since the trials of a BROAD table also run without the magnetometer.
    let mut groups: Vec<(PathBuf, Vec<usize>)> = Vec::new();
    for (i, dataset) in datasets.iter().enumerate() {
        let parent = dataset
            .parent()
            .map_or_else(PathBuf::new, Path::to_path_buf);
        match groups.iter_mut().find(|(p, _)| *p == parent) {
            Some((_, members)) => members.push(i),
            None => groups.push((parent, vec![i])),
        }
    }
    let group_refs: Vec<(PathBuf, Result<Option<References>, String>)> = groups
        .iter()
        .map(|(folder, _)| {
            let path = folder.join("references.json");
            let refs = read_references(&path);
            (path, refs)
        })
        .collect();
    let mut six_axis_plans: Vec<Option<bool>> = vec![None; datasets.len()];
    for ((_, members), (_, refs)) in groups.iter().zip(&group_refs) {
        let broad = match refs {
            Ok(Some(References::Broad(_))) => true,
            Ok(Some(References::Attitude(_))) => false,
            Ok(None) | Err(_) => members
                .iter()
                .all(|&i| datasets[i].join("movement.csv").is_file()),
        };
        if broad {
            for &i in members {
                six_axis_plans[i] = six_axis_plan(&datasets[i]);
            }
        }
    }

    let staging = Staging::new(&opts.out, opts.force, "bench")?;
    let names = output_names(&datasets);
    let total_runs = datasets.len() + six_axis_plans.iter().filter(|p| **p == Some(true)).count();
    let mut results = Vec::with_capacity(datasets.len());
    for (i, (dataset, name)) in datasets.iter().zip(&names).enumerate() {
        progress(i, total_runs, &dataset.display().to_string());
        results.push(run_one(
            dataset,
            &staging.dir().join(name),
            opts.config.as_deref(),
            name,
            false,
        ));
    }
    // The 6-axis runs, into OUT/6axis/<name>.
    let mut done = datasets.len();
    let mut outcomes = Vec::with_capacity(datasets.len());
    for (((dataset, name), result), plan) in datasets
        .iter()
        .zip(&names)
        .zip(results)
        .zip(&six_axis_plans)
    {
        let six_axis = match plan {
            None => SixAxis::None,
            Some(false) => SixAxis::SameRun,
            Some(true) => {
                progress(
                    done,
                    total_runs,
                    &format!("{} without the magnetometer", dataset.display()),
                );
                done += 1;
                SixAxis::Run(Box::new(run_one(
                    dataset,
                    &staging.dir().join(SIX_AXIS_DIR).join(name),
                    opts.config.as_deref(),
                    name,
                    true,
                )))
            }
        };
        let dataset_name = dataset
            .file_name()
            .map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned());
        outcomes.push(Outcome {
            name: dataset_name,
            result,
            six_axis,
        });
    }

    let refs_6d = refs_6d
        .as_ref()
        .zip(opts.references_6d.as_deref())
        .map(|(m, p)| (p, m));
    let mut tables = Vec::new();
    for ((folder, members), (path, refs)) in groups.into_iter().zip(group_refs) {
        let runs: Vec<(&Path, &Outcome)> = members
            .iter()
            .map(|&i| (datasets[i].as_path(), &outcomes[i]))
            .collect();
        let (refs, references_error) = match refs {
            Ok(r) => (r, None),
            Err(e) => (None, Some(e)),
        };
        let rows = match &refs {
            Some(References::Broad(m)) => broad_table(&runs, Some((&path, m)), refs_6d),
            Some(References::Attitude(m)) => attitude_table(&runs, Some(m)),
            None if runs.iter().all(|(d, _)| d.join("movement.csv").is_file()) => {
                broad_table(&runs, None, refs_6d)
            }
            None => attitude_table(&runs, None),
        };
        tables.push(Table {
            references: (refs.is_some() || references_error.is_some()).then_some(path),
            references_error,
            folder,
            rows,
        });
    }
    let data_warnings = outcomes
        .iter()
        .filter_map(|o| o.result.as_ref().ok())
        .flat_map(|m| m.data_warnings.iter().cloned())
        .collect();
    let report = Report {
        dir: opts.dir.clone(),
        out: opts.out.clone(),
        config: opts.config.clone(),
        references_6d: opts.references_6d.clone(),
        tables,
        data_warnings,
    };
    let json_path = staging.dir().join("bench.json");
    let json = serde_json::to_string_pretty(&report).map_err(|e| BenchError::Write {
        path: opts.out.join("bench.json"),
        message: e.to_string(),
    })?;
    std::fs::write(&json_path, json + "\n").map_err(|e| BenchError::Write {
        path: opts.out.join("bench.json"),
        message: e.to_string(),
    })?;
    staging.commit()?;
    Ok(report)
}

const DASH: &str = "–";

fn cell(x: Option<f64>, decimals: usize) -> String {
    x.map_or_else(|| DASH.to_string(), |v| format!("{v:.decimals$}"))
}

impl Report {
    /// The datasets that failed to run, and the `references.json` files that could not be read.
    #[must_use]
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        for t in &self.tables {
            if let Some(e) = &t.references_error {
                out.push(e.clone());
            }
            let errors: Vec<(String, &Option<String>)> = match &t.rows {
                Rows::Broad { rows, .. } => rows
                    .iter()
                    .flat_map(|r| {
                        [
                            (r.dataset.clone(), &r.error),
                            (
                                format!("{} (without the magnetometer)", r.dataset),
                                &r.error_6axis,
                            ),
                        ]
                    })
                    .collect(),
                Rows::Attitude { rows } => {
                    rows.iter().map(|r| (r.dataset.clone(), &r.error)).collect()
                }
            };
            for (name, e) in errors {
                if let Some(e) = e {
                    out.push(format!("{name}: {e}"));
                }
            }
        }
        out
    }

    /// The tables as printed.
    #[must_use]
    pub fn render(&self) -> String {
        let mut s = String::new();
        for t in &self.tables {
            let refs = match (&t.references, &t.references_error) {
                (_, Some(e)) => format!("references unusable: {e}"),
                (Some(p), None) => format!("references {}", p.display()),
                (None, None) => "no references.json".to_string(),
            };
            match &t.rows {
                Rows::Broad {
                    rows,
                    mean,
                    max,
                    madgwick_missing,
                    vqf_6d_missing,
                } => {
                    let w = rows
                        .iter()
                        .map(|r| r.dataset.chars().count())
                        .max()
                        .unwrap_or(5)
                        .max(5);
                    let _ = writeln!(
                        s,
                        "\nBROAD RMSE [deg] inside movement.csv: {} ({refs})",
                        t.folder.display()
                    );
                    let _ = writeln!(
                        s,
                        "{:<w$}  {:>8} {:>8} {:>8} {:>8}  {:>8}  {:>8}  {:>9} {:>9}",
                        "",
                        "ours",
                        "ours",
                        "ours",
                        "ours",
                        "VQF",
                        "Madgwick",
                        "ours 6-ax",
                        "VQF 6D"
                    );
                    let _ = writeln!(
                        s,
                        "{:<w$}  {:>8} {:>8} {:>8} {:>8}  {:>8}  {:>8}  {:>9} {:>9}",
                        "trial",
                        "total",
                        "heading",
                        "inclin.",
                        "in 3σ %",
                        "total",
                        "total",
                        "inclin.",
                        "inclin."
                    );
                    for r in rows {
                        if let Some(e) = &r.error {
                            let _ = writeln!(s, "{:<w$}  failed: {e}", r.dataset);
                            continue;
                        }
                        let _ = writeln!(
                            s,
                            "{:<w$}  {:>8} {:>8} {:>8} {:>8}  {:>8}  {:>8}  {:>9} {:>9}",
                            r.dataset,
                            cell(r.ours.total_deg, 3),
                            cell(r.ours.heading_deg, 3),
                            cell(r.ours.inclination_deg, 3),
                            cell(r.ours.inside_3sigma_pct, 1),
                            cell(r.vqf_total_deg, 3),
                            cell(r.madgwick_total_deg, 3),
                            cell(r.inclination_6axis_deg, 3),
                            cell(r.vqf_6d_inclination_deg, 3),
                        );
                    }
                    for (label, a) in [("mean", mean), ("max", max)] {
                        let _ = writeln!(
                            s,
                            "{:<w$}  {:>8} {:>8} {:>8} {:>8}  {:>8}  {:>8}  {:>9} {:>9}",
                            label,
                            cell(a.ours.total_deg, 3),
                            cell(a.ours.heading_deg, 3),
                            cell(a.ours.inclination_deg, 3),
                            cell(a.ours.inside_3sigma_pct, 1),
                            cell(a.vqf_total_deg, 3),
                            cell(a.madgwick_total_deg, 3),
                            cell(a.inclination_6axis_deg, 3),
                            cell(a.vqf_6d_inclination_deg, 3),
                        );
                    }
                    let _ = writeln!(
                        s,
                        "(in 3σ %: the movement samples whose attitude error is inside the reported 3σ ellipsoid, NEES ≤ 9: 97.1 % for a consistent estimate; in the max row, the lowest trial's)"
                    );
                    let mut sources: Vec<String> = Vec::new();
                    for r in rows {
                        if let Some(p) = &r.vqf_6d_from {
                            let p = p.display().to_string();
                            if !sources.contains(&p) {
                                sources.push(p);
                            }
                        }
                    }
                    let from = if sources.is_empty() {
                        String::new()
                    } else {
                        format!(", from {}", sources.join(" and "))
                    };
                    let _ = writeln!(
                        s,
                        "(6-ax: ours without the magnetometer, use_magnetometer = false (outputs in {SIX_AXIS_DIR}/); \
VQF 6D: real-time VQF on the gyroscope and accelerometer only{from}; the inclination only: without a magnetometer nothing observes the heading)"
                    );
                    for r in rows {
                        if let (None, Some(e)) = (&r.error, &r.error_6axis) {
                            let _ = writeln!(
                                s,
                                "({}: the run without the magnetometer failed: {e})",
                                r.dataset
                            );
                        }
                    }
                    if !vqf_6d_missing.is_empty() {
                        let _ = writeln!(
                            s,
                            "(no VQF 6D figure for {}: neither references.json nor a --references-6d file has {VQF_6D}; \
python3 tools/vqf_references.py DIR --out FILE writes one)",
                            vqf_6d_missing.join(", ")
                        );
                    }
                    if !madgwick_missing.is_empty() {
                        let _ = writeln!(
                            s,
                            "(no Madgwick mean or max: references.json has no Madgwick figure for {})",
                            madgwick_missing.join(", ")
                        );
                    }
                }
                Rows::Attitude { rows } => {
                    let w = rows
                        .iter()
                        .map(|r| r.dataset.chars().count())
                        .max()
                        .unwrap_or(7)
                        .max(7);
                    let _ = writeln!(
                        s,
                        "\nattitude RMSE [deg] from 2 s after the first truth sample: {} ({refs})",
                        t.folder.display()
                    );
                    let _ = writeln!(
                        s,
                        "{:<w$}  {:<14} {:>9} {:>11}  {:>9}  {:>8}",
                        "dataset", "ours fuses", "ours RMSE", "ours ANEES", "VQF RMSE", "ours/VQF"
                    );
                    for r in rows {
                        if let Some(e) = &r.error {
                            let _ = writeln!(s, "{:<w$}  failed: {e}", r.dataset);
                            continue;
                        }
                        let ratio = if r.ratio_to_vqf_absent.is_some() {
                            format!("{DASH} ¹")
                        } else {
                            cell(r.ratio_to_vqf, 2)
                        };
                        let _ = writeln!(
                            s,
                            "{:<w$}  {:<14} {:>9} {:>11}  {:>9}  {:>8}",
                            r.dataset,
                            r.sensors.join("+"),
                            cell(r.attitude_rmse_after_2s_deg, 3),
                            cell(r.anees_attitude, 2),
                            cell(r.vqf_attitude_rmse_deg, 3),
                            ratio,
                        );
                    }
                    let _ = writeln!(s, "(ANEES: mean NEES of the attitude, 3 when consistent)");
                    if rows.iter().any(|r| r.ratio_to_vqf_absent.is_some()) {
                        let _ = writeln!(
                            s,
                            "¹ no ratio: ours replays this dataset through the INS navigator with the sensors named, VQF 9D fuses {} only; \
a ratio is printed only where both fuse the same sensors",
                            VQF_SENSORS.join("+")
                        );
                    }
                }
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aggregates_need_every_value() {
        assert_eq!(aggregate(&[Some(1.0), Some(3.0)]), (Some(2.0), Some(3.0)));
        assert_eq!(aggregate(&[Some(1.0), None]), (None, None));
        assert_eq!(aggregate(&[]), (None, None));
    }

    #[test]
    fn shared_names_get_their_parent() {
        let d = [
            PathBuf::from("a/x"),
            PathBuf::from("b/x"),
            PathBuf::from("b/y"),
        ];
        assert_eq!(output_names(&d), ["a-x", "b-x", "y"]);
    }

    #[test]
    fn references_of_both_layouts_and_missing_entries() {
        let dir = std::env::temp_dir().join(format!("host-sim-bench-refs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let p = dir.join("references.json");
        std::fs::write(
            &p,
            r#"{"trials": {"t1": {"vqf_9d": {"total": 2.5}, "madgwick_tagp_published": {"total": null}}}}"#,
        )
        .expect("write");
        let Ok(Some(References::Broad(m))) = read_references(&p) else {
            panic!("a BROAD layout");
        };
        assert_eq!(reference(&m, "t1", &[VQF, "total"]), Some(2.5));
        assert_eq!(reference(&m, "t1", &[MADGWICK, "total"]), None);
        assert_eq!(reference(&m, "t2", &[VQF, "total"]), None);
        std::fs::write(
            &p,
            r#"{"datasets": {"d": {"vqf_9d": {"attitude_rmse_deg": 1.5}}}}"#,
        )
        .expect("write");
        assert!(matches!(
            read_references(&p),
            Ok(Some(References::Attitude(_)))
        ));
        std::fs::write(&p, "{ not json").expect("write");
        assert!(read_references(&p).is_err());
        std::fs::remove_file(&p).expect("rm");
        assert!(matches!(read_references(&p), Ok(None)));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn the_six_axis_folder_is_no_dataset_output() {
        let d = [PathBuf::from("a/6axis"), PathBuf::from("a/t1")];
        assert_eq!(output_names(&d), ["a-6axis", "t1"]);
    }

    fn broad_run(inclination_deg: f64) -> Result<Metrics, String> {
        let mut m = crate::metrics::Scorer::default().metrics();
        m.broad = Some(crate::metrics::broad::BroadRmse {
            total_deg: 2.0 * inclination_deg,
            heading_deg: inclination_deg,
            inclination_deg,
            samples: 10,
            inside_3sigma: f64::NAN,
        });
        Ok(m)
    }

    /// VQF 6D from references.json before the --references-6d file, each figure with its file;
    /// a trial that neither has prints `–` and is written `null`, and so are the mean and max.
    #[test]
    fn a_missing_vqf_6d_figure_is_a_dash_and_null() {
        let outcomes = [
            Outcome {
                name: "a".into(),
                result: broad_run(1.0),
                six_axis: SixAxis::Run(Box::new(broad_run(1.5))),
            },
            Outcome {
                name: "b".into(),
                result: broad_run(2.0),
                six_axis: SixAxis::SameRun,
            },
            Outcome {
                name: "c".into(),
                result: broad_run(3.0),
                six_axis: SixAxis::Run(Box::new(Err("boom".into()))),
            },
        ];
        let runs: Vec<(&Path, &Outcome)> = outcomes.iter().map(|o| (Path::new("x"), o)).collect();
        let entries = |json: &str| -> BTreeMap<String, Value> {
            let v: Value = serde_json::from_str(json).expect("json");
            v["trials"]
                .as_object()
                .expect("trials")
                .iter()
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect()
        };
        let refs = entries(r#"{"trials": {"a": {"vqf_6d": {"inclination": 0.5}}}}"#);
        let file = entries(
            r#"{"trials": {"a": {"vqf_6d": {"inclination": 9.0}}, "b": {"vqf_6d": {"inclination": 0.75}}}}"#,
        );
        let (rp, fp) = (Path::new("references.json"), Path::new("six.json"));
        let table = |refs_6d: Option<Source<'_>>| {
            let rows = broad_table(&runs, Some((rp, &refs)), refs_6d);
            let report = Report {
                dir: PathBuf::from("x"),
                out: PathBuf::from("out"),
                config: None,
                references_6d: None,
                tables: vec![Table {
                    folder: PathBuf::from("x"),
                    references: Some(rp.to_path_buf()),
                    references_error: None,
                    rows,
                }],
                data_warnings: Vec::new(),
            };
            let json = serde_json::to_value(&report).expect("json");
            (report, json)
        };

        // Without the file: b and c have no VQF 6D figure.
        let (report, json) = table(None);
        let rows = &json["tables"][0]["rows"];
        assert_eq!(rows[0]["vqf_6d_inclination_deg"], 0.5);
        assert_eq!(rows[0]["vqf_6d_from"], "references.json");
        assert_eq!(rows[0]["inclination_6axis_deg"], 1.5);
        // The IMU alone: the first run is the 6-axis run.
        assert_eq!(rows[1]["inclination_6axis_deg"], 2.0);
        assert!(rows[1]["vqf_6d_inclination_deg"].is_null() && rows[1]["vqf_6d_from"].is_null());
        assert!(rows[2]["inclination_6axis_deg"].is_null());
        assert_eq!(rows[2]["error_6axis"], "boom");
        for summary in ["mean", "max"] {
            let s = &json["tables"][0][summary];
            assert!(s["vqf_6d_inclination_deg"].is_null(), "{summary}: {s}");
            assert!(s["inclination_6axis_deg"].is_null(), "{summary}: {s}");
        }
        assert_eq!(
            json["tables"][0]["vqf_6d_missing"],
            serde_json::json!(["b", "c"])
        );
        let text = report.render();
        let row = |name: &str| {
            text.lines()
                .find(|l| l.starts_with(name))
                .unwrap_or_else(|| panic!("no row {name}:\n{text}"))
                .to_string()
        };
        for (name, last_columns) in [
            ("a ", "1.500     0.500"),
            ("b ", "2.000         –"),
            ("c ", "–         –"),
            ("mean", "–         –"),
        ] {
            let r = row(name);
            assert!(r.trim_end().ends_with(last_columns), "{r}");
        }
        assert!(text.contains("no VQF 6D figure for b, c"), "{text}");
        assert!(
            text.contains("c: the run without the magnetometer failed: boom"),
            "{text}"
        );
        assert!(report
            .failures()
            .contains(&"c (without the magnetometer): boom".to_string()));

        // With the file: references.json first, the file for the others.
        let (report, json) = table(Some((fp, &file)));
        let rows = &json["tables"][0]["rows"];
        assert_eq!(rows[0]["vqf_6d_inclination_deg"], 0.5);
        assert_eq!(rows[1]["vqf_6d_inclination_deg"], 0.75);
        assert_eq!(rows[1]["vqf_6d_from"], "six.json");
        assert!(rows[2]["vqf_6d_inclination_deg"].is_null());
        assert!(report
            .render()
            .contains("from references.json and six.json"));
    }

    #[test]
    fn nothing_computed_prints_a_dash() {
        assert_eq!(cell(None, 3), "–");
        assert_eq!(cell(Some(1.23456), 3), "1.235");
        assert_eq!(finite(f64::NAN), None);
    }
}

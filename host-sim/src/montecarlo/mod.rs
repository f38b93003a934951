//! `host-sim montecarlo`: filter consistency over seeds.
//!
//! Each run simulates the scenario with its own seed and replays it (in parallel with `rayon`,
//! with progress on stderr, [`crate::progress`]). Two tests, each against its 95 % chi-square band:
//!
//! * **NEES per block** (attitude, velocity, position, biases). At each sample `k` the average
//!   over the `N` runs, `ε̄_k = (1/N) Σ εᵢ_k`, has `N ε̄_k ~ χ²(3N)` for a consistent filter
//!   (Bar-Shalom). The band is `[χ²_{0.025}(3N), χ²_{0.975}(3N)] / N`. The report gives the ANEES
//!   (the mean of `ε̄_k` over the run after the first `settle_s` seconds, which belong to the
//!   start-up) and the fraction of samples whose `ε̄_k` is inside the band; the ANEES must lie in
//!   the band.
//! * **NIS per sensor**. Innovations of a consistent filter are white, so the sum of all NIS over
//!   all updates of all runs (after `settle_s`, as for the NEES: the prior is deliberately wide)
//!   is `χ²(Σ dof)`; the band of the mean NIS is `[χ²_{0.025}(D), χ²_{0.975}(D)] / count` with
//!   `D = Σ dof`.
//!
//! The [`Report`] also keeps each run's figures ([`RunResult`]); [`Report::write`] writes
//! `runs.csv` (one row per run), `bands.csv` (the band table) and `montecarlo.json` (both, with
//! how they were made). A figure a run did not estimate is an empty cell (`null` in the JSON),
//! never 0.

use crate::dataset::check::collate;
use crate::dataset::write::simulate;
use crate::metrics::heading::HeadingScore;
use crate::metrics::{Metrics, Scorer, BLOCKS};
use crate::progress::{Mode, Progress};
use crate::replay::{replay_scored, ReplayConfig};
use crate::scenario::Scenario;
use crate::stats::chi2_quantile;
use rayon::prelude::*;
use serde_json::{json, Map, Value};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The start-up the NEES and NIS tests leave out by default, s (`host-sim montecarlo`).
pub const DEFAULT_SETTLE_S: f64 = 20.0;

/// The files [`Report::write`] writes.
pub const FILES: [&str; 3] = ["runs.csv", "bands.csv", "montecarlo.json"];

/// One line of the report.
#[derive(Clone, Debug, PartialEq)]
pub struct BandResult {
    /// Block or sensor.
    pub name: String,
    /// The statistic (ANEES or mean NIS).
    pub value: f64,
    /// Its expectation (3 for NEES, the mean dof for NIS).
    pub expected: f64,
    /// Lower end of the 95 % band.
    pub lower: f64,
    /// Upper end of the 95 % band.
    pub upper: f64,
    /// For NEES: the fraction of samples whose run-average was inside the band.
    pub fraction_inside: Option<f64>,
    /// The chi-square degrees of freedom `D` and the divisor `c` of the band: the band at
    /// confidence `p` is `[χ²_{(1−p)/2}(D), χ²_{(1+p)/2}(D)] / c` (`lower`, `upper` at 95 %).
    pub dof: f64,
    /// See [`BandResult::dof`].
    pub divisor: f64,
}

impl BandResult {
    /// `true` when the statistic lies in its band.
    #[must_use]
    pub fn holds(&self) -> bool {
        self.value >= self.lower && self.value <= self.upper
    }

    /// The band at two-sided confidence `p` (the 95 % band for `p = 0.95`). Checking `k`
    /// statistics together at a family-wise confidence `P` takes `p = P^(1/k)` for each
    /// (Šidák): with `p = 0.95` each, some statistic of a consistent filter falls outside its
    /// band in `1 − 0.95^k` of the checks (49 % for 13).
    #[must_use]
    pub fn band(&self, p: f64) -> (f64, f64) {
        (
            chi2_quantile((1.0 - p) / 2.0, self.dof) / self.divisor,
            chi2_quantile((1.0 + p) / 2.0, self.dof) / self.divisor,
        )
    }
}

/// The figures of one run.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// The run's random seed.
    pub seed: u64,
    /// Its figures over the whole run, as `host-sim run` reports them.
    pub metrics: Metrics,
}

/// The whole Monte-Carlo report.
#[derive(Clone, Debug)]
pub struct Report {
    /// The scenario's name.
    pub scenario: String,
    /// The filter's precision (`"f32"` or `"f64"`).
    pub precision: String,
    /// The start-up left out of the bands, s.
    pub settle_s: f64,
    /// Runs that completed.
    pub runs: usize,
    /// NEES per block.
    pub nees: Vec<BandResult>,
    /// NIS per sensor.
    pub nis: Vec<BandResult>,
    /// Each run's figures, in seed order.
    pub per_run: Vec<RunResult>,
}

/// The empty cell for what was not estimated; a number otherwise.
fn cell(x: Option<f64>) -> String {
    match x {
        Some(v) if !v.is_nan() => v.to_string(),
        _ => String::new(),
    }
}

/// `null` for what was not estimated (or is not finite); a number otherwise.
fn number(x: Option<f64>) -> Value {
    x.filter(|v| v.is_finite()).map_or(Value::Null, Value::from)
}

impl Report {
    /// The data warnings of the runs, once per warning: `warning: SCENARIO, N of M runs (first
    /// seed S): FILE:LINE: message`, the file named inside the dataset folder (each run's is
    /// scratch).
    #[must_use]
    pub fn data_warning_lines(&self) -> Vec<String> {
        collate(
            self.per_run
                .iter()
                .map(|r| (r.seed, &r.metrics.data_warnings[..])),
        )
        .into_iter()
        .map(|(w, seed, n)| {
            format!(
                "warning: {}, {n} of {} runs (first seed {seed}): {w}",
                self.scenario, self.runs
            )
        })
        .collect()
    }

    /// `true` when every band holds.
    #[must_use]
    pub fn holds(&self) -> bool {
        self.nees.iter().chain(&self.nis).all(BandResult::holds)
    }

    /// The seeds of the runs, in order.
    #[must_use]
    pub fn seeds(&self) -> Vec<u64> {
        self.per_run.iter().map(|r| r.seed).collect()
    }

    /// Every band with its label (`ANEES <block>`, `mean NIS <sensor>`), NEES first.
    pub fn bands(&self) -> impl Iterator<Item = (String, &BandResult)> {
        self.nees
            .iter()
            .map(|r| (format!("ANEES {}", r.name), r))
            .chain(self.nis.iter().map(|r| (format!("mean NIS {}", r.name), r)))
    }

    /// The band table `host-sim montecarlo` prints.
    #[must_use]
    pub fn table(&self) -> String {
        let mut t = String::new();
        let seeds = self.seeds();
        let _ = writeln!(
            t,
            "scenario {}: {} runs (seeds {}..={}), precision {}; 95 % chi-square bands after the first {} s",
            self.scenario,
            self.runs,
            seeds.first().copied().unwrap_or_default(),
            seeds.last().copied().unwrap_or_default(),
            self.precision,
            self.settle_s
        );
        let _ = writeln!(
            t,
            "  {:<26} {:>8} {:>8} {:>17} {:>8} {:>7}",
            "statistic", "value", "expect", "band", "inside", "holds"
        );
        for (label, r) in self.bands() {
            let inside = r
                .fraction_inside
                .map_or("-".into(), |f| format!("{:.0} %", 100.0 * f));
            let _ = writeln!(
                t,
                "  {:<26} {:>8.3} {:>8.3} {:>17} {:>8} {:>7}",
                label,
                r.value,
                r.expected,
                format!("[{:.3}, {:.3}]", r.lower, r.upper),
                inside,
                if r.holds() { "yes" } else { "NO" }
            );
        }
        if let Some(h) = self.heading_summary() {
            t.push_str(&h.table());
        }
        if self.nees.is_empty() && self.nis.is_empty() {
            let _ = writeln!(
                t,
                "  no band: nothing was scored after the first {} s",
                self.settle_s
            );
        }
        t
    }

    /// The blocks with a NEES and the sensors with updates in any run, in order.
    fn columns(&self) -> (Vec<&'static str>, Vec<String>) {
        let blocks = BLOCKS
            .iter()
            .copied()
            .filter(|b| {
                self.per_run
                    .iter()
                    .any(|r| r.metrics.nees_mean.contains_key(*b))
            })
            .collect();
        let sensors: BTreeSet<String> = self
            .per_run
            .iter()
            .flat_map(|r| {
                let m = &r.metrics;
                m.nis_mean
                    .keys()
                    .chain(m.updates_accepted.keys())
                    .chain(m.updates_rejected.keys())
                    .chain(m.updates_refused.keys())
                    .cloned()
            })
            .collect();
        (blocks, sensors.into_iter().collect())
    }

    /// One row per run after its seed: the column names, then each run's cells (`None`: not
    /// estimated).
    fn run_rows(&self) -> (Vec<String>, Vec<Vec<Option<f64>>>) {
        let (blocks, sensors) = self.columns();
        let mut header: Vec<String> = [
            "ate_position_rmse_m",
            "attitude_rmse_deg",
            "velocity_rmse_mps",
        ]
        .iter()
        .map(|s| (*s).to_string())
        .collect();
        header.extend(blocks.iter().map(|b| format!("anees_{b}")));
        let heading = self.per_run.iter().any(|r| r.metrics.heading.is_some());
        if heading {
            header.extend(HEADING_COLUMNS.iter().map(|c| (*c).to_string()));
        }
        for s in &sensors {
            header.extend(
                ["nis_mean", "accepted", "gated_out", "refused"]
                    .iter()
                    .map(|c| format!("{c}_{s}")),
            );
        }
        let rows = self
            .per_run
            .iter()
            .map(|r| {
                let m = &r.metrics;
                let count = |map: &std::collections::BTreeMap<String, u64>, s: &String| {
                    map.get(s).map(|&n| n as f64)
                };
                let mut row = vec![
                    Some(m.ate_position_rmse_m),
                    Some(m.attitude_rmse_deg),
                    Some(m.velocity_rmse_mps),
                ];
                row.extend(blocks.iter().map(|b| m.nees_mean.get(*b).copied()));
                if heading {
                    row.extend(heading_cells(m.heading.as_ref()));
                }
                for s in &sensors {
                    row.push(m.nis_mean.get(s).copied());
                    row.push(count(&m.updates_accepted, s));
                    row.push(count(&m.updates_rejected, s));
                    row.push(count(&m.updates_refused, s));
                }
                row
            })
            .collect();
        (header, rows)
    }

    /// `runs.csv`: one row per run (seed, ATE, attitude and velocity RMSE, ANEES per block,
    /// mean NIS and accepted / gated-out / refused updates per sensor, each over the whole run
    /// as [`Scorer::metrics`] gives it, start-up included); an empty cell where the run
    /// estimated nothing.
    ///
    /// # Errors
    /// When the CSV writer fails (it writes to memory).
    pub fn runs_csv(&self) -> Result<String, String> {
        let (header, rows) = self.run_rows();
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| e.to_string();
        w.write_record(std::iter::once("seed").chain(header.iter().map(String::as_str)))
            .map_err(err)?;
        for (row, r) in rows.iter().zip(&self.per_run) {
            let mut cells = vec![r.seed.to_string()];
            cells.extend(row.iter().map(|c| cell(*c)));
            w.write_record(&cells).map_err(err)?;
        }
        let bytes = w.into_inner().map_err(|e| e.to_string())?;
        String::from_utf8(bytes).map_err(|e| e.to_string())
    }

    /// `bands.csv`: the printed band table (statistic, value, expected, lower, upper,
    /// fraction inside, holds); the fraction is empty for the NIS, which has none.
    ///
    /// # Errors
    /// When the CSV writer fails (it writes to memory).
    pub fn bands_csv(&self) -> Result<String, String> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| e.to_string();
        w.write_record([
            "statistic",
            "value",
            "expected",
            "lower",
            "upper",
            "fraction_inside",
            "holds",
        ])
        .map_err(err)?;
        for (label, r) in self.bands() {
            w.write_record([
                label,
                cell(Some(r.value)),
                cell(Some(r.expected)),
                cell(Some(r.lower)),
                cell(Some(r.upper)),
                cell(r.fraction_inside),
                r.holds().to_string(),
            ])
            .map_err(err)?;
        }
        let bytes = w.into_inner().map_err(|e| e.to_string())?;
        String::from_utf8(bytes).map_err(|e| e.to_string())
    }

    /// `montecarlo.json`: how the report was made (`host_sim_version`, `command_line`,
    /// `scenario`, `precision`, `settle_s`, `runs`, `seeds`), whether every band holds
    /// (`holds`), the bands (`bands`, as `bands.csv`) and the runs (`per_run`, one object per
    /// row of `runs.csv` with its column names; `null` where the cell is empty).
    #[must_use]
    pub fn json(&self, command_line: &[String]) -> Value {
        let bands: Vec<Value> = self
            .bands()
            .map(|(label, r)| {
                json!({
                    "statistic": label,
                    "value": number(Some(r.value)),
                    "expected": number(Some(r.expected)),
                    "lower": number(Some(r.lower)),
                    "upper": number(Some(r.upper)),
                    "fraction_inside": number(r.fraction_inside),
                    "holds": r.holds(),
                })
            })
            .collect();
        let (header, rows) = self.run_rows();
        let per_run: Vec<Value> = rows
            .iter()
            .zip(&self.per_run)
            .map(|(row, r)| {
                let mut obj = Map::new();
                obj.insert("seed".into(), Value::from(r.seed));
                for (name, c) in header.iter().zip(row) {
                    // Counts are whole numbers; write them as integers.
                    let v = match c {
                        Some(n)
                            if ["accepted_", "gated_out_", "refused_", "heading_valid_"]
                                .iter()
                                .any(|p| name.starts_with(p)) =>
                        {
                            Value::from(*n as u64)
                        }
                        _ => number(*c),
                    };
                    obj.insert(name.clone(), v);
                }
                Value::Object(obj)
            })
            .collect();
        json!({
            "host_sim_version": env!("CARGO_PKG_VERSION"),
            "command_line": command_line,
            "scenario": self.scenario,
            "precision": self.precision,
            "settle_s": self.settle_s,
            "runs": self.runs,
            "seeds": self.seeds(),
            "holds": self.holds(),
            "bands": bands,
            "heading": self.heading_summary().map(|h| h.json()),
            "per_run": per_run,
        })
    }

    /// Writes [`FILES`] into `dir`.
    ///
    /// # Errors
    /// A file that cannot be written, named.
    pub fn write(&self, dir: &Path, command_line: &[String]) -> Result<(), String> {
        let json = serde_json::to_string_pretty(&self.json(command_line))
            .map_err(|e| format!("montecarlo.json: {e}"))?;
        for (name, text) in [
            ("runs.csv", self.runs_csv()?),
            ("bands.csv", self.bands_csv()?),
            ("montecarlo.json", json + "\n"),
        ] {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(())
    }
}

/// The heading's columns of `runs.csv` ([`crate::metrics::heading::HeadingScore`]).
const HEADING_COLUMNS: [&str; 6] = [
    "heading_valid_after_motion_s",
    "heading_within_2deg_after_motion_s",
    "heading_within_5deg_after_motion_s",
    "heading_max_error_from_60s_deg",
    "heading_valid_samples",
    "heading_valid_outside_4sigma",
];

/// A run's cells under [`HEADING_COLUMNS`].
fn heading_cells(h: Option<&HeadingScore>) -> Vec<Option<f64>> {
    let Some(h) = h else {
        return vec![None; HEADING_COLUMNS.len()];
    };
    let settled = |deg: &str| h.settled_after_motion_s.get(deg).copied().flatten();
    vec![
        h.valid_after_motion_s,
        settled("2"),
        settled("5"),
        h.max_error_from_60s_deg,
        Some(h.valid_samples as f64),
        Some(h.valid_outside_4sigma as f64),
    ]
}

/// The heading over the runs whose body moved: the latest of each settling time (with the
/// runs that never got there), the largest error from 60 s after the first motion, and the
/// samples reported valid with the heading outside 3σ and 4σ.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadingSummary {
    /// Runs with a heading score.
    pub runs: usize,
    /// The latest first-valid time after the first motion, s, and the runs never valid.
    pub valid_after_motion_s: (Option<f64>, usize),
    /// Per settling threshold (degrees as `"2"`, `"5"`): the latest time after the first
    /// motion from which the error stayed within it, s, and the runs where it did not end so.
    pub settled_after_motion_s: Vec<(String, Option<f64>, usize)>,
    /// The largest heading error from 60 s after the first motion over the runs, degrees.
    pub max_error_from_60s_deg: Option<f64>,
    /// Samples reported valid, and those with the heading outside 3σ and 4σ.
    pub valid_samples: u64,
    /// See `valid_samples`.
    pub valid_outside_3sigma: u64,
    /// See `valid_samples`.
    pub valid_outside_4sigma: u64,
}

impl HeadingSummary {
    fn latest(values: impl Iterator<Item = Option<f64>>) -> (Option<f64>, usize) {
        let mut latest: Option<f64> = None;
        let mut never = 0;
        for v in values {
            match v {
                Some(x) => latest = Some(latest.map_or(x, |l| l.max(x))),
                None => never += 1,
            }
        }
        (latest, never)
    }

    fn table(&self) -> String {
        let s = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.1}"));
        let mut t = format!(
            "  heading after the first motion ({} runs; latest over the runs, s):\n    reported valid {} (never: {})\n",
            self.runs,
            s(self.valid_after_motion_s.0),
            self.valid_after_motion_s.1
        );
        for (deg, latest, never) in &self.settled_after_motion_s {
            t.push_str(&format!(
                "    within {deg}° to the end {} (not at the end: {never})\n",
                s(*latest)
            ));
        }
        t.push_str(&format!(
            "    largest error from 60 s after the first motion {} °\n    samples reported valid {}, with the heading outside 3σ {} ({:.3} %) and 4σ {} ({:.4} %; a consistent Gaussian filter 0.27 % and 0.0063 %)\n",
            s(self.max_error_from_60s_deg),
            self.valid_samples,
            self.valid_outside_3sigma,
            100.0 * self.valid_outside_3sigma as f64 / self.valid_samples.max(1) as f64,
            self.valid_outside_4sigma,
            100.0 * self.valid_outside_4sigma as f64 / self.valid_samples.max(1) as f64,
        ));
        t
    }

    fn json(&self) -> Value {
        let settled: Map<String, Value> = self
            .settled_after_motion_s
            .iter()
            .map(|(deg, latest, never)| {
                (
                    deg.clone(),
                    json!({ "latest_s": number(*latest), "runs_not_within_at_end": never }),
                )
            })
            .collect();
        json!({
            "runs": self.runs,
            "valid_after_motion_latest_s": number(self.valid_after_motion_s.0),
            "runs_never_valid": self.valid_after_motion_s.1,
            "within_deg_after_motion": settled,
            "max_error_from_60s_deg": number(self.max_error_from_60s_deg),
            "valid_samples": self.valid_samples,
            "valid_outside_3sigma": self.valid_outside_3sigma,
            "valid_outside_4sigma": self.valid_outside_4sigma,
        })
    }
}

impl Report {
    /// The heading over the runs ([`HeadingSummary`]); `None` when no run has a heading
    /// score.
    #[must_use]
    pub fn heading_summary(&self) -> Option<HeadingSummary> {
        let scores: Vec<&HeadingScore> = self
            .per_run
            .iter()
            .filter_map(|r| r.metrics.heading.as_ref())
            .collect();
        if scores.is_empty() {
            return None;
        }
        let degs = crate::metrics::heading::SETTLE_DEG.map(|d| format!("{d}"));
        Some(HeadingSummary {
            runs: scores.len(),
            valid_after_motion_s: HeadingSummary::latest(
                scores.iter().map(|h| h.valid_after_motion_s),
            ),
            settled_after_motion_s: degs
                .iter()
                .map(|deg| {
                    let (latest, never) = HeadingSummary::latest(
                        scores
                            .iter()
                            .map(|h| h.settled_after_motion_s.get(deg).copied().flatten()),
                    );
                    (deg.clone(), latest, never)
                })
                .collect(),
            max_error_from_60s_deg: scores
                .iter()
                .filter_map(|h| h.max_error_from_60s_deg)
                .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x)))),
            valid_samples: scores.iter().map(|h| h.valid_samples).sum(),
            valid_outside_3sigma: scores.iter().map(|h| h.valid_outside_3sigma).sum(),
            valid_outside_4sigma: scores.iter().map(|h| h.valid_outside_4sigma).sum(),
        })
    }
}

/// Runs `runs` seeds (1..=runs) of `scenario`, with the scenario's replay configuration: as
/// [`run_from`] from seed 1.
///
/// # Errors
/// As [`run_from`].
pub fn run(
    scenario: &Scenario,
    runs: u64,
    settle_s: f64,
    progress: bool,
) -> Result<Report, String> {
    run_from(scenario, 1, runs, settle_s, progress)
}

/// Runs `runs` seeds, `first_seed` to `first_seed + runs - 1`, of `scenario`, with the
/// scenario's replay configuration; the bands leave out the first `settle_s` seconds.
///
/// # Errors
/// No run, seeds past `u64::MAX`, or the first run that failed to simulate or replay.
pub fn run_from(
    scenario: &Scenario,
    first_seed: u64,
    runs: u64,
    settle_s: f64,
    progress: bool,
) -> Result<Report, String> {
    if runs == 0 {
        return Err("no runs: --runs must be at least 1".into());
    }
    let last_seed = first_seed.checked_add(runs - 1).ok_or_else(|| {
        format!(
            "seed {first_seed} and {runs} runs: the last seed would pass {}",
            u64::MAX
        )
    })?;
    let base: PathBuf = std::env::temp_dir().join(format!(
        "host-sim-mc-{}-{}",
        std::process::id(),
        scenario.name.replace('/', "_")
    ));
    let bar = Progress::new("montecarlo", "runs", runs, Mode::for_stderr(progress));
    let cfg = ReplayConfig {
        plots: false,
        ..scenario.replay.clone()
    };
    let results: Vec<Result<Scorer, String>> = (first_seed..=last_seed)
        .into_par_iter()
        .map(|seed| {
            let dir = base.join(format!("seed-{seed}"));
            let ds = dir.join("dataset");
            let r = simulate(scenario, seed, &ds)
                .map_err(|e| e.to_string())
                .and_then(|()| {
                    let mut scorer = Scorer::default();
                    scorer.keep_nees = true;
                    replay_scored(&ds, &dir, &cfg, &scenario.name, scorer)
                        .map_err(|e| e.to_string())
                        .map(|mut s| {
                            // The run's folder is scratch: files named inside the dataset.
                            s.data_warnings = std::mem::take(&mut s.data_warnings)
                                .into_iter()
                                .map(|w| w.relocated(&ds, Path::new("")))
                                .collect();
                            s
                        })
                });
            let _ = std::fs::remove_dir_all(&dir);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish();
    let _ = std::fs::remove_dir_all(&base);
    let scorers: Vec<Scorer> = results.into_iter().collect::<Result<_, _>>()?;
    let n = scorers.len();
    if n == 0 {
        return Err("no runs".into());
    }
    let rate = scenario.imu.rate_hz;
    let skip = (settle_s * rate) as usize;
    let steps = scorers
        .iter()
        .map(|s| s.nees_steps.len())
        .min()
        .unwrap_or(0);
    let nf = n as f64;
    let (lo, hi) = (
        chi2_quantile(0.025, 3.0 * nf) / nf,
        chi2_quantile(0.975, 3.0 * nf) / nf,
    );
    let mut nees = Vec::new();
    for (b, name) in BLOCKS.iter().enumerate() {
        let mut sum = 0.0;
        let mut count = 0usize;
        let mut inside = 0usize;
        for k in skip..steps {
            let avg = scorers.iter().map(|s| s.nees_steps[k][b]).sum::<f64>() / nf;
            if avg.is_finite() {
                sum += avg;
                count += 1;
                if (lo..=hi).contains(&avg) {
                    inside += 1;
                }
            }
        }
        if count > 0 {
            nees.push(BandResult {
                name: (*name).into(),
                value: sum / count as f64,
                expected: 3.0,
                lower: lo,
                upper: hi,
                fraction_inside: Some(inside as f64 / count as f64),
                dof: 3.0 * nf,
                divisor: nf,
            });
        }
    }
    let mut nis = Vec::new();
    let sensors: BTreeSet<String> = scorers
        .iter()
        .flat_map(|s| s.sensors.keys().cloned())
        .collect();
    for name in sensors {
        let (mut total, mut dof, mut count) = (0.0, 0.0, 0.0);
        for s in &scorers {
            if let Some(st) = s.sensors.get(&name) {
                // After the start-up, like the NEES (the history holds every update unless a
                // run is long enough to be decimated, when it holds a uniform subsample).
                for &(_, nis, d, _) in st.history.points().iter().filter(|p| p.0 >= settle_s) {
                    total += nis;
                    dof += d as f64;
                    count += 1.0;
                }
            }
        }
        if count > 0.0 {
            nis.push(BandResult {
                name,
                value: total / count,
                expected: dof / count,
                lower: chi2_quantile(0.025, dof) / count,
                upper: chi2_quantile(0.975, dof) / count,
                fraction_inside: None,
                dof,
                divisor: count,
            });
        }
    }
    let per_run = (first_seed..=last_seed)
        .zip(&scorers)
        .map(|(seed, s)| RunResult {
            seed,
            metrics: s.metrics(),
        })
        .collect();
    Ok(Report {
        scenario: scenario.name.clone(),
        precision: scenario.replay.precision.clone(),
        settle_s,
        runs: n,
        nees,
        nis,
        per_run,
    })
}

//! `host-sim faults`: the fault bench. Each fault scenario is simulated once per random seed and
//! replayed through the INS navigator with the scenario's replay configuration (as `host-sim
//! run` does, plots off); the run's `validity.csv`, `estimate.csv`, ground truth and `faults.csv`
//! are then read back ([`epochs`]) and scored ([`score`]):
//!
//! * **Detection time**: seconds from a fault's start to the first IMU epoch at or after it whose
//!   report shows the fault ([`score::FaultRule::detects`]: GNSS step → position
//!   `fixes_disagree` or GNSS `rejected`; frozen receiver → GNSS `faulty`; outage → GNSS
//!   `stale`; magnetometer → `rejected` or `faulty`; barometer step → `rejected`; IMU clipping or
//!   stuck axis → `imu_fault`). GNSS outliers (no single start) and latency (no fault interval)
//!   have none. The epochs before the start where the same condition already held are counted
//!   beside it: false alarms, or, for the rules that count a gate rejection, ordinary ones.
//! * **Recovery time**: seconds from a fault's end to the first epoch from which, for at least
//!   1 s without interruption, the faulty sensor is `fused` again and the quantity it affects is
//!   valid with its error within 3σ ([`score::FaultRule::recovered`]). Targets: 7 s for the
//!   position after a GNSS fault, 5 s for the height after a barometer step.
//! * **False-valid epoch-axes** over the whole run: a quantity reported `valid` while an axis of
//!   its error is outside 3σ (and 4σ) of the 1σ the navigator reported beside it
//!   ([`score::false_valid`]). A consistent Gaussian filter is outside 3σ on 0.27 % of its
//!   epoch-axes, so the 3σ count cannot be 0 even for a perfect filter and is printed beside
//!   that expectation; outside 4σ a consistent filter is 0.0063 % of the time, and that count
//!   is the check that the navigator never calls a wrong quantity valid. Errors are correlated
//!   in time, so one excursion covers many consecutive epochs: the counts come in bursts.
//! * **ATE**: the SE(3)-aligned ATE RMSE of the run ([`crate::metrics`]). Through a GNSS
//!   outage the navigator dead-reckons on the IMU alone and its position error grows without
//!   bound, so the ATE of a run with an outage is mostly that drift; beside it the bench gives
//!   the ATE outside the outages ([`ate_outside`]: the SE(3)-aligned ATE of the estimate–truth
//!   pairs whose time is outside every `gnss outage` interval, each extended to the first epoch
//!   where the GNSS is fused again, aligned on those pairs alone), the figure to set beside the
//!   other scenarios' ATE.
//!
//! **Latency** ([`LATENCY_SCENARIO`]): the scenario replayed (a) as it is, each fix fused at its
//! validity time, through [`crate::montecarlo::run_from`], which also gives the position ANEES
//! against its 95 % chi-square band; (b) the same datasets with `ignore_gnss_latency`, every fix
//! taken as valid on arrival; (c) the scenario simulated without latency. Target: mean ATE of
//! (a) at most [`LATENCY_RATIO_TARGET`] times that of (c).
//!
//! Runs go to a pool of worker threads, each in its own folder under a scratch folder removed
//! run by run.

pub mod epochs;
pub mod score;

use crate::dataset::check::{collate, DataWarning};
use crate::dataset::read::{read_faults, FaultInterval};
use crate::dataset::write::simulate;
use crate::metrics::trajectory::{self, Alignment, PosePair, Stats};
use crate::metrics::{Metrics, Scorer};
use crate::montecarlo::{BandResult, DEFAULT_SETTLE_S};
use crate::progress::{Mode, Progress};
use crate::replay::{replay, replay_scored, ReplayConfig};
use crate::scenario::Scenario;
use score::{FalseValid, FaultRule, Tally, QUANTITIES};
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// The scenario of the latency comparison.
pub const LATENCY_SCENARIO: &str = "fault_gnss_latency";

/// Target of the latency comparison: mean ATE fused at the validity time over mean ATE without
/// latency.
pub const LATENCY_RATIO_TARGET: f64 = 1.1;

/// The files [`FaultBench::write`] writes.
pub const FILES: [&str; 2] = ["faults.csv", "faults.json"];

/// The built-in fault scenarios (those named `fault_*`), in their listed order.
#[must_use]
pub fn builtin_fault_scenarios() -> Vec<Scenario> {
    crate::scenario::builtin_scenarios()
        .into_iter()
        .filter(|s| s.name.starts_with("fault_"))
        .collect()
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// The scenarios, each needing GNSS (the bench scores the INS navigator).
    pub scenarios: Vec<Scenario>,
    /// Random seed of the first run; the runs use `first_seed..first_seed + runs`.
    pub first_seed: u64,
    /// Runs per scenario.
    pub runs: u64,
    /// The scenario of the latency comparison, when it is to be made.
    pub latency: Option<Scenario>,
    /// Worker threads (at least 1).
    pub workers: usize,
    /// A folder for the runs' datasets and outputs: each run writes into a subfolder of its
    /// own and removes it when scored.
    pub scratch: PathBuf,
    /// Show progress on stderr ([`crate::progress`]: a bar on a terminal, a line every few
    /// seconds off one).
    pub progress: bool,
}

/// One fault of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultResult {
    /// The fault as `faults.csv` lists it.
    pub fault: FaultInterval,
    /// Its start, s from the scenario's first sample.
    pub start_s: f64,
    /// Its end, s from the scenario's first sample.
    pub end_s: f64,
    /// How it is detected and recovered from; `None`: neither is measured (GNSS outliers).
    pub rule: Option<FaultRule>,
    /// Detection time, s (`None`: not measured, or never detected).
    pub detection_s: Option<f64>,
    /// Epochs before the start where the detection condition already held.
    pub alarms_before: u64,
    /// Recovery time, s (`None`: not measured, or never recovered).
    pub recovery_s: Option<f64>,
}

/// The figures of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    /// The scenario's name.
    pub scenario: String,
    /// The random seed.
    pub seed: u64,
    /// Each fault of `faults.csv`, in its order.
    pub faults: Vec<FaultResult>,
    /// The false-valid tallies over the run.
    pub false_valid: FalseValid,
    /// SE(3)-aligned ATE RMSE, m.
    pub ate_m: Option<f64>,
    /// With a GNSS outage among the faults: the SE(3)-aligned ATE RMSE of the samples outside
    /// every outage, each up to the first epoch with the GNSS fused again ([`ate_outside`]), m; `None` without an outage (or no sample outside).
    pub ate_outside_outage_m: Option<f64>,
    /// IMU epochs in `validity.csv`.
    pub epochs: usize,
    /// What the simulated data had wrong that the replay survived (a GNSS outage is a gap),
    /// each file named inside the dataset folder (`gnss0/data.csv`): the run's folder is
    /// scratch.
    pub data_warnings: Vec<DataWarning>,
}

/// One line of the bench: one fault of one scenario (or the scenario, without faults) over the
/// runs.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The scenario's name.
    pub scenario: String,
    /// Its replay precision.
    pub precision: String,
    /// The fault (`None`: the scenario lists none).
    pub fault: Option<(FaultInterval, f64, f64)>,
    /// How it is detected and recovered from.
    pub rule: Option<FaultRule>,
    /// Runs.
    pub runs: usize,
    /// Detection times of the runs that detected the fault.
    pub detection: Option<Stats>,
    /// Runs that never detected it (with a rule).
    pub missed: Vec<u64>,
    /// Runs with alarm epochs before the fault, and the median of their counts over all runs.
    pub alarmed_before: (usize, f64),
    /// Recovery times of the runs that recovered.
    pub recovery: Option<Stats>,
    /// Runs that never recovered (with a rule).
    pub not_recovered: Vec<u64>,
    /// Runs over the recovery target, with their recovery time (never recovered included, as
    /// infinite).
    pub over_target: Vec<(u64, f64)>,
    /// False-valid tallies summed over the runs.
    pub false_valid: FalseValid,
    /// ATE RMSE over the runs, m.
    pub ate: Option<Stats>,
    /// Whether the scenario's runs hold a GNSS outage (their ATE includes the dead reckoning
    /// through it).
    pub gnss_outage: bool,
    /// ATE RMSE outside the GNSS outages over the runs, m ([`RunResult::ate_outside_outage_m`]).
    pub ate_outside_outage: Option<Stats>,
}

/// The latency comparison over the seeds.
#[derive(Clone, Debug)]
pub struct LatencyResult {
    /// The scenario.
    pub scenario: String,
    /// The seeds, in order.
    pub seeds: Vec<u64>,
    /// ATE RMSE per seed, m: (a) fused at the validity time, (b) taken as valid on arrival,
    /// (c) simulated without latency.
    pub ate_m: [Vec<f64>; 3],
    /// Mean of each.
    pub mean_m: [f64; 3],
    /// Mean (a) over mean (c).
    pub ratio: f64,
    /// Position ANEES of (a) with its 95 % band, as `host-sim montecarlo` computes it.
    pub anees_position: Option<BandResult>,
    /// The start-up the ANEES leaves out, s.
    pub settle_s: f64,
}

/// The whole bench.
#[derive(Clone, Debug)]
pub struct FaultBench {
    /// Seed of the first run.
    pub first_seed: u64,
    /// Runs per scenario.
    pub runs: u64,
    /// Worker threads used.
    pub workers: usize,
    /// Every run, grouped by scenario in the order given, seeds in order.
    pub per_run: Vec<RunResult>,
    /// One line per scenario and fault.
    pub summaries: Vec<Summary>,
    /// The latency comparison, when made.
    pub latency: Option<LatencyResult>,
    /// Wall time of the whole bench, s.
    pub elapsed_s: f64,
}

impl FaultBench {
    /// The data warnings of the runs, once per scenario and warning: `warning: SCENARIO, N of M
    /// runs (first seed S): FILE:LINE: message`, the file named inside the dataset folder.
    #[must_use]
    pub fn data_warning_lines(&self) -> Vec<String> {
        let mut scenarios: Vec<&str> = Vec::new();
        for r in &self.per_run {
            if !scenarios.contains(&r.scenario.as_str()) {
                scenarios.push(&r.scenario);
            }
        }
        let mut out = Vec::new();
        for sc in scenarios {
            let runs: Vec<&RunResult> = self.per_run.iter().filter(|r| r.scenario == sc).collect();
            for (w, seed, n) in collate(runs.iter().map(|r| (r.seed, &r.data_warnings[..]))) {
                out.push(format!(
                    "warning: {sc}, {n} of {} runs (first seed {seed}): {w}",
                    runs.len()
                ));
            }
        }
        out
    }
}

/// A folder beside an output target for the bench's runs, created fresh and removed (with
/// everything in it, all of it the bench's) when dropped.
#[derive(Debug)]
pub struct ScratchDir {
    path: PathBuf,
}

impl ScratchDir {
    /// Creates `.NAME.host-sim-faults-scratch-PID` beside `target`; refuses if it exists.
    ///
    /// # Errors
    /// When the folder cannot be created (it exists already, or the parent is not writable).
    pub fn beside(target: &Path) -> Result<Self, String> {
        let cwd = std::env::current_dir().map_err(|e| format!(".: {e}"))?;
        let absolute = cwd.join(target);
        let name = absolute
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let parent = absolute.parent().unwrap_or(&cwd);
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        let path = parent.join(format!(
            ".{name}.host-sim-faults-scratch-{}",
            std::process::id()
        ));
        // `create_dir`, not `create_dir_all`: never adopt a folder that is already there.
        std::fs::create_dir(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(Self { path })
    }

    /// The folder.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

/// The SE(3)-aligned ATE RMSE of a run.
fn ate_se3(m: &Metrics) -> Option<f64> {
    m.ate_by_alignment
        .values()
        .chain(m.ate.iter())
        .find(|a| a.alignment == Alignment::Se3)
        .map(|a| a.stats.rmse)
}

/// The SE(3)-aligned ATE RMSE (`√(Σ‖R p̂ᵢ + t − pᵢ‖²/n)` after Umeyama's alignment, as
/// [`trajectory::ate`]) of the `pairs` whose time is outside every interval of `outside`
/// (`[start, end)`, ns), the alignment made on those pairs alone; `None` when no pair is left.
#[must_use]
pub fn ate_outside(pairs: &[PosePair], outside: &[(u64, u64)]) -> Option<f64> {
    let kept: Vec<PosePair> = pairs
        .iter()
        .filter(|p| !outside.iter().any(|&(a, b)| p.t_ns >= a && p.t_ns < b))
        .copied()
        .collect();
    trajectory::ate(&kept, Alignment::Se3).map(|a| a.stats.rmse)
}

/// The end of the dead reckoning through a GNSS outage ending at `end_ns`: the first epoch at
/// or after it where the GNSS is fused again (`u64::MAX` when none is), so that the samples
/// dead-reckoned while the first fix after the outage is awaited count with the outage.
fn dead_reckoning_end(eps: &[epochs::Epoch], end_ns: u64) -> u64 {
    eps.iter()
        .find(|e| e.t_ns >= end_ns && e.gnss == epochs::AidStatus::Fused)
        .map_or(u64::MAX, |e| e.t_ns)
}

/// The replay configuration of a bench run: the scenario's, plots off.
fn bench_config(sc: &Scenario) -> ReplayConfig {
    ReplayConfig {
        plots: false,
        ..sc.replay.clone()
    }
}

/// Simulates `sc` with `seed` into `dir/dataset`, replays it into `dir/replay` and returns the
/// metrics (the folder is left for the caller to read and remove).
fn simulate_and_replay(
    sc: &Scenario,
    seed: u64,
    cfg: &ReplayConfig,
    dir: &Path,
) -> Result<Metrics, String> {
    let ds = dir.join("dataset");
    simulate(sc, seed, &ds).map_err(|e| e.to_string())?;
    replay(&ds, &dir.join("replay"), cfg, &sc.name).map_err(|e| e.to_string())
}

/// One bench run: simulate, replay, read back and score.
///
/// # Errors
/// A failed simulation or replay, or outputs that cannot be read back.
pub fn run_one(sc: &Scenario, seed: u64, dir: &Path) -> Result<RunResult, String> {
    let ds = dir.join("dataset");
    simulate(sc, seed, &ds).map_err(|e| e.to_string())?;
    let scorer = replay_scored(
        &ds,
        &dir.join("replay"),
        &bench_config(sc),
        &sc.name,
        Scorer::default(),
    )
    .map_err(|e| e.to_string())?;
    let m = scorer.metrics();
    let eps = epochs::read_epochs(&dir.join("replay"), &ds)?;
    let faults = read_faults(&ds).map_err(|e| e.to_string())?;
    let outages: Vec<(u64, u64)> = faults
        .iter()
        .filter(|f| FaultRule::of(f) == Some(FaultRule::GnssOutage))
        .map(|f| (f.start_ns, dead_reckoning_end(&eps, f.end_ns)))
        .collect();
    let ate_outside_outage_m = if outages.is_empty() {
        None
    } else {
        ate_outside(scorer.pairs(), &outages)
    };
    let secs = |ns: u64| ns.saturating_sub(sc.start_ns) as f64 * 1e-9;
    let faults = faults
        .into_iter()
        .map(|f| {
            let rule = FaultRule::of(&f);
            FaultResult {
                start_s: secs(f.start_ns),
                end_s: secs(f.end_ns),
                rule,
                detection_s: rule.and_then(|r| score::detection_s(&eps, f.start_ns, r)),
                alarms_before: rule.map_or(0, |r| score::alarms_before(&eps, f.start_ns, r)),
                recovery_s: rule.and_then(|r| score::recovery_s(&eps, f.end_ns, r)),
                fault: f,
            }
        })
        .collect();
    Ok(RunResult {
        scenario: sc.name.clone(),
        seed,
        faults,
        false_valid: score::false_valid(&eps),
        ate_m: ate_se3(&m),
        ate_outside_outage_m,
        epochs: eps.len(),
        data_warnings: m
            .data_warnings
            .iter()
            .map(|w| w.clone().relocated(&ds, Path::new("")))
            .collect(),
    })
}

/// A unit of work for the pool.
enum Job<'a> {
    /// A scored bench run.
    Bench(&'a Scenario, u64),
    /// A latency variant: its index in [`LatencyResult::ate_m`], the scenario to simulate, the
    /// configuration (boxed: large beside a bench run's), the seed; only the ATE is kept.
    Ate(usize, &'a Scenario, Box<ReplayConfig>, u64),
}

enum JobOut {
    // Boxed: a run's result is large beside an ATE.
    Bench(Box<RunResult>),
    Ate(f64),
}

impl Job<'_> {
    fn run(&self, dir: &Path) -> Result<JobOut, String> {
        match self {
            Job::Bench(sc, seed) => run_one(sc, *seed, dir)
                .map(|r| JobOut::Bench(Box::new(r)))
                .map_err(|e| format!("{} seed {seed}: {e}", sc.name)),
            Job::Ate(_, sc, cfg, seed) => simulate_and_replay(sc, *seed, cfg, dir)
                .and_then(|m| ate_se3(&m).ok_or_else(|| "no ATE".to_string()))
                .map(JobOut::Ate)
                .map_err(|e| format!("{} seed {seed}: {e}", sc.name)),
        }
    }

    /// Simulated seconds, to start the longest runs first.
    fn duration_s(&self) -> f64 {
        match self {
            Job::Bench(sc, _) | Job::Ate(_, sc, _, _) => sc.duration_s,
        }
    }
}

/// Runs `jobs` on `workers` threads, each job in `scratch/job-<i>` (removed after it); stops
/// handing out jobs at the first failure, which it returns.
fn run_pool(
    jobs: &[Job<'_>],
    workers: usize,
    scratch: &Path,
    progress: bool,
) -> Result<Vec<JobOut>, String> {
    let bar = Progress::new(
        "faults",
        "runs",
        jobs.len() as u64,
        Mode::for_stderr(progress),
    );
    // Longest first, so that no worker is left with a long run at the end.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by(|&a, &b| jobs[b].duration_s().total_cmp(&jobs[a].duration_s()));
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let results: Mutex<Vec<Option<Result<JobOut, String>>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..workers.max(1) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= order.len() || failed.load(Ordering::Relaxed) {
                    break;
                }
                let i = order[k];
                let dir = scratch.join(format!("job-{i}"));
                let r = jobs[i].run(&dir);
                let _ = std::fs::remove_dir_all(&dir);
                if r.is_err() {
                    failed.store(true, Ordering::Relaxed);
                }
                if let Ok(mut all) = results.lock() {
                    all[i] = Some(r);
                }
                bar.inc(1);
            });
        }
    });
    bar.finish();
    let all = results
        .into_inner()
        .map_err(|_| "a worker panicked".to_string())?;
    if let Some(e) = all.iter().flatten().find_map(|r| r.as_ref().err()) {
        return Err(e.clone());
    }
    all.into_iter()
        .map(|r| r.unwrap_or_else(|| Err("a run did not complete".into())))
        .collect()
}

/// Median of a non-empty list of counts (0 for an empty one).
fn median_count(xs: &[u64]) -> f64 {
    let v: Vec<f64> = xs.iter().map(|&x| x as f64).collect();
    Stats::of(&v).map_or(0.0, |s| s.median)
}

/// The summary lines of one scenario's runs.
fn summarize(sc: &Scenario, runs: &[RunResult]) -> Vec<Summary> {
    let mut fv = FalseValid::default();
    for r in runs {
        fv.add(&r.false_valid);
    }
    let ates: Vec<f64> = runs.iter().filter_map(|r| r.ate_m).collect();
    let outside: Vec<f64> = runs.iter().filter_map(|r| r.ate_outside_outage_m).collect();
    let gnss_outage = runs.iter().any(|r| {
        r.faults
            .iter()
            .any(|f| f.rule == Some(FaultRule::GnssOutage))
    });
    let base = Summary {
        scenario: sc.name.clone(),
        precision: sc.replay.precision.clone(),
        fault: None,
        rule: None,
        runs: runs.len(),
        detection: None,
        missed: Vec::new(),
        alarmed_before: (0, 0.0),
        recovery: None,
        not_recovered: Vec::new(),
        over_target: Vec::new(),
        false_valid: fv,
        ate: Stats::of(&ates),
        gnss_outage,
        ate_outside_outage: Stats::of(&outside),
    };
    let faults = runs.first().map_or(0, |r| r.faults.len());
    if faults == 0 {
        return vec![base];
    }
    (0..faults)
        .map(|k| {
            let of_k: Vec<(u64, &FaultResult)> = runs
                .iter()
                .filter_map(|r| r.faults.get(k).map(|f| (r.seed, f)))
                .collect();
            let first = of_k[0].1;
            let rule = first.rule;
            let det: Vec<f64> = of_k.iter().filter_map(|(_, f)| f.detection_s).collect();
            let rec: Vec<f64> = of_k.iter().filter_map(|(_, f)| f.recovery_s).collect();
            let alarms: Vec<u64> = of_k.iter().map(|(_, f)| f.alarms_before).collect();
            let without = |pick: fn(&FaultResult) -> Option<f64>| -> Vec<u64> {
                if rule.is_none() {
                    return Vec::new();
                }
                of_k.iter()
                    .filter(|(_, f)| pick(f).is_none())
                    .map(|(s, _)| *s)
                    .collect()
            };
            let over_target = match rule.and_then(FaultRule::target_s) {
                Some(target) => of_k
                    .iter()
                    .map(|(s, f)| (*s, f.recovery_s.unwrap_or(f64::INFINITY)))
                    .filter(|(_, t)| *t > target)
                    .collect(),
                None => Vec::new(),
            };
            Summary {
                fault: Some((first.fault.clone(), first.start_s, first.end_s)),
                rule,
                detection: Stats::of(&det),
                missed: without(|f| f.detection_s),
                alarmed_before: (
                    alarms.iter().filter(|&&a| a > 0).count(),
                    median_count(&alarms),
                ),
                recovery: Stats::of(&rec),
                not_recovered: without(|f| f.recovery_s),
                over_target,
                ..base.clone()
            }
        })
        .collect()
}

/// Runs the bench (see the module docs).
///
/// # Errors
/// No scenario or no run, a scenario without GNSS, seeds past `u64::MAX`, or the first run
/// that failed.
pub fn run(opts: &Options) -> Result<FaultBench, String> {
    let started = Instant::now();
    if opts.runs == 0 {
        return Err("no runs: --runs must be at least 1".into());
    }
    if opts.scenarios.is_empty() && opts.latency.is_none() {
        return Err("no scenario to run".into());
    }
    for sc in opts.scenarios.iter().chain(opts.latency.iter()) {
        if sc.gnss.is_none() {
            return Err(format!(
                "scenario '{}' has no GNSS: the fault bench scores the INS navigator, which needs it",
                sc.name
            ));
        }
    }
    let last_seed = opts.first_seed.checked_add(opts.runs - 1).ok_or_else(|| {
        format!(
            "seed {} and {} runs: the last seed would pass {}",
            opts.first_seed,
            opts.runs,
            u64::MAX
        )
    })?;
    let seeds: Vec<u64> = (opts.first_seed..=last_seed).collect();
    let no_latency = opts.latency.as_ref().map(|sc| {
        let mut c = sc.clone();
        if let Some(g) = c.gnss.as_mut() {
            g.latency_s = 0.0;
        }
        c
    });
    let mut jobs = Vec::new();
    for sc in &opts.scenarios {
        jobs.extend(seeds.iter().map(|&s| Job::Bench(sc, s)));
    }
    if let (Some(sc), Some(zero)) = (&opts.latency, &no_latency) {
        let on_arrival = ReplayConfig {
            ignore_gnss_latency: true,
            ..bench_config(sc)
        };
        for &s in &seeds {
            jobs.push(Job::Ate(1, sc, Box::new(on_arrival.clone()), s));
            jobs.push(Job::Ate(2, zero, Box::new(bench_config(zero)), s));
        }
    }
    let outs = run_pool(&jobs, opts.workers, &opts.scratch, opts.progress)?;
    let mut per_run = Vec::new();
    let mut ate_variants: [Vec<f64>; 3] = Default::default();
    for (job, out) in jobs.iter().zip(outs) {
        match (job, out) {
            (Job::Bench(..), JobOut::Bench(r)) => per_run.push(*r),
            (Job::Ate(k, ..), JobOut::Ate(a)) => ate_variants[*k].push(a),
            _ => return Err("a run returned the wrong kind of result".into()),
        }
    }
    let summaries = opts
        .scenarios
        .iter()
        .flat_map(|sc| {
            let runs: Vec<RunResult> = per_run
                .iter()
                .filter(|r| r.scenario == sc.name)
                .cloned()
                .collect();
            summarize(sc, &runs)
        })
        .collect();
    let latency = match &opts.latency {
        Some(sc) => Some(latency(sc, &seeds, ate_variants, opts.progress)?),
        None => None,
    };
    Ok(FaultBench {
        first_seed: opts.first_seed,
        runs: opts.runs,
        workers: opts.workers.max(1),
        per_run,
        summaries,
        latency,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}

/// The latency comparison: (a) through `montecarlo::run_from`, (b) and (c) given.
fn latency(
    sc: &Scenario,
    seeds: &[u64],
    mut ate_m: [Vec<f64>; 3],
    progress: bool,
) -> Result<LatencyResult, String> {
    let first = seeds.first().copied().unwrap_or(1);
    let mc =
        crate::montecarlo::run_from(sc, first, seeds.len() as u64, DEFAULT_SETTLE_S, progress)?;
    ate_m[0] = mc
        .per_run
        .iter()
        .map(|r| ate_se3(&r.metrics).ok_or_else(|| format!("{} seed {}: no ATE", sc.name, r.seed)))
        .collect::<Result<_, _>>()?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let mean_m = [mean(&ate_m[0]), mean(&ate_m[1]), mean(&ate_m[2])];
    Ok(LatencyResult {
        scenario: sc.name.clone(),
        seeds: seeds.to_vec(),
        ratio: mean_m[0] / mean_m[2],
        mean_m,
        ate_m,
        anees_position: mc.nees.iter().find(|b| b.name == "position").cloned(),
        settle_s: mc.settle_s,
    })
}

/// `x` with `d` decimals, or `–`.
fn fx(x: Option<f64>, d: usize) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v:.d$}"),
        _ => "–".into(),
    }
}

/// A median / max cell, with the runs that never reached it.
fn with_never(cell: String, never: usize) -> String {
    match (never, cell.as_str()) {
        (0, _) => cell,
        (n, "–") => format!("never ({n})"),
        (n, _) => format!("{cell}, {n} never"),
    }
}

/// A list of seeds, the first few of them.
fn some_seeds(seeds: &[u64]) -> String {
    let shown: Vec<String> = seeds.iter().take(5).map(u64::to_string).collect();
    let more = if seeds.len() > 5 { ", …" } else { "" };
    format!("{}{more}", shown.join(", "))
}

/// What a consistent Gaussian filter would show outside `k`σ on `n` epoch-axes.
fn expected(n: u64, k: f64) -> f64 {
    n as f64 * score::gaussian_outside(k)
}

impl Summary {
    /// `sensor kind start–end s`, or `–`.
    fn fault_label(&self) -> String {
        match &self.fault {
            Some((f, a, b)) => format!("{} {} {a:.0}–{b:.0} s", f.sensor, f.kind),
            None => "–".into(),
        }
    }
}

impl FaultBench {
    /// One line per scenario with a GNSS outage: its ATE includes the dead reckoning through
    /// the outage; the ATE outside it beside it.
    fn outage_lines(&self) -> Vec<String> {
        let mut seen = std::collections::BTreeSet::new();
        self.summaries
            .iter()
            .filter(|s| s.gnss_outage && seen.insert(s.scenario.clone()))
            .map(|s| {
                let outside = match &s.ate_outside_outage {
                    Some(a) => format!("{:.3} / {:.3} m", a.mean, a.max),
                    None => "not computed (no sample outside it)".into(),
                };
                format!(
                    "{}: the ATE includes the IMU-only dead reckoning through the GNSS outage; ATE outside it (until the first fix fused after it; SE(3)-aligned on those samples), mean / max: {outside}",
                    s.scenario
                )
            })
            .collect()
    }

    /// The seeds of each scenario's runs.
    #[must_use]
    pub fn seeds(&self) -> Vec<u64> {
        (0..self.runs).map(|i| self.first_seed + i).collect()
    }

    /// The tables `host-sim faults` prints.
    #[must_use]
    pub fn table(&self) -> String {
        let mut t = String::new();
        let seeds = self.seeds();
        let precisions: std::collections::BTreeSet<&str> = self
            .summaries
            .iter()
            .map(|s| s.precision.as_str())
            .collect();
        let _ = writeln!(
            t,
            "fault bench: {} runs per scenario (seeds {}..={}), precision {}, {} worker(s), {:.1} s",
            self.runs,
            seeds.first().copied().unwrap_or_default(),
            seeds.last().copied().unwrap_or_default(),
            precisions.into_iter().collect::<Vec<_>>().join("/"),
            self.workers,
            self.elapsed_s
        );
        let _ = writeln!(
            t,
            "  detection: s from the fault's start to the first epoch whose report shows it; \
recovery: s from its end until the sensor is fused and the quantity valid within 3σ for 1 s"
        );
        let _ = writeln!(
            t,
            "  {:<20} {:<20} {:>4}  {:>15}  {:>20}  {:>12}  {:>15}  {:>12}  {:>15}",
            "scenario",
            "fault",
            "runs",
            "detect med/max",
            "recover med/max",
            "target",
            ">3σ / expected",
            ">4σ / expected",
            "ATE mean/max"
        );
        for s in &self.summaries {
            let spread = |st: &Option<Stats>, d: usize| match st {
                Some(st) => format!("{} / {}", fx(Some(st.median), d), fx(Some(st.max), d)),
                None => "–".into(),
            };
            let target = match s.rule.and_then(FaultRule::target_s) {
                Some(target) => format!(
                    "≤ {target:.0} s {}/{}",
                    s.runs - s.over_target.len(),
                    s.runs
                ),
                None => "–".into(),
            };
            let total = s.false_valid.total();
            let _ = writeln!(
                t,
                "  {:<20} {:<20} {:>4}  {:>15}  {:>20}  {:>12}  {:>15}  {:>12}  {:>15}",
                s.scenario,
                s.fault_label(),
                s.runs,
                with_never(spread(&s.detection, 3), s.missed.len()),
                with_never(spread(&s.recovery, 2), s.not_recovered.len()),
                target,
                format!(
                    "{} / {:.0}",
                    total.outside_3sigma,
                    expected(total.valid_epoch_axes, 3.0)
                ),
                format!(
                    "{} / {:.1}",
                    total.outside_4sigma,
                    expected(total.valid_epoch_axes, 4.0)
                ),
                match &s.ate {
                    Some(a) => format!("{:.3} / {:.3}", a.mean, a.max),
                    None => "–".into(),
                },
            );
        }
        let _ = writeln!(t, "  (times in s, ATE SE(3)-aligned RMSE in m; >3σ / >4σ: false-valid epoch-axes summed over the runs / what a consistent Gaussian filter shows)");
        for s in self.outage_lines() {
            let _ = writeln!(t, "  {s}");
        }
        let mut notes = Vec::new();
        for s in &self.summaries {
            let name = &s.scenario;
            if !s.missed.is_empty() {
                notes.push(format!(
                    "{name}: fault never detected in {}/{} runs (seeds {})",
                    s.missed.len(),
                    s.runs,
                    some_seeds(&s.missed)
                ));
            }
            if let (Some(rule), (n, median)) = (s.rule, s.alarmed_before) {
                if n > 0 {
                    notes.push(format!(
                        "{name}: '{}' held before the fault began in {n}/{} runs (median {median:.0} epochs per run)",
                        rule.describe_detection(),
                        s.runs
                    ));
                }
            }
            if !s.not_recovered.is_empty() {
                notes.push(format!(
                    "{name}: never recovered by the end of the run in {}/{} runs (seeds {})",
                    s.not_recovered.len(),
                    s.runs,
                    some_seeds(&s.not_recovered)
                ));
            }
            let slow: Vec<&(u64, f64)> = s
                .over_target
                .iter()
                .filter(|(_, r)| r.is_finite())
                .collect();
            if let (Some(target), Some((seed, worst))) = (
                s.rule.and_then(FaultRule::target_s),
                slow.iter().max_by(|a, b| a.1.total_cmp(&b.1)),
            ) {
                notes.push(format!(
                    "{name}: recovered later than {target:.0} s in {}/{} runs (slowest: seed {seed}, {worst:.2} s after the fault's end)",
                    slow.len(),
                    s.runs
                ));
            }
        }
        if !notes.is_empty() {
            let _ = writeln!(t, "\n  notes:");
            for n in notes {
                let _ = writeln!(t, "    {n}");
            }
        }
        let _ = writeln!(
            t,
            "\nfalse-valid epoch-axes per quantity, summed over the runs (quantity reported valid, error outside kσ of its reported σ):"
        );
        let _ = writeln!(
            t,
            "  a consistent Gaussian filter is outside 3σ on {:.2} % of its epoch-axes, so that count is never 0; outside 4σ on {:.4} %: the check that a wrong quantity is not called valid",
            100.0 * score::gaussian_outside(3.0),
            100.0 * score::gaussian_outside(4.0)
        );
        let _ = writeln!(
            t,
            "  {:<20} {:<10} {:>12} {:>9} {:>9} {:>10} {:>7} {:>9}",
            "scenario", "quantity", "valid", ">3σ", "fraction", "expected", ">4σ", "expected"
        );
        for s in self.summaries.iter().filter(|s| {
            // One block per scenario, though it may have several fault lines.
            self.summaries
                .iter()
                .find(|o| o.scenario == s.scenario)
                .is_some_and(|o| std::ptr::eq(o, *s))
        }) {
            for (q, tally) in QUANTITIES.iter().zip(&s.false_valid.quantities) {
                let _ = writeln!(
                    t,
                    "  {:<20} {:<10} {:>12} {:>9} {:>9} {:>10.1} {:>7} {:>9.2}",
                    s.scenario,
                    q,
                    tally.valid_epoch_axes,
                    tally.outside_3sigma,
                    fraction(tally),
                    expected(tally.valid_epoch_axes, 3.0),
                    tally.outside_4sigma,
                    expected(tally.valid_epoch_axes, 4.0)
                );
            }
        }
        if let Some(l) = &self.latency {
            let _ = writeln!(
                t,
                "\nlatency ({}, {} runs): mean ATE (a) fixes fused at their validity time {:.3} m, \
(b) taken as valid on arrival {:.3} m, (c) simulated without latency {:.3} m",
                l.scenario,
                l.seeds.len(),
                l.mean_m[0],
                l.mean_m[1],
                l.mean_m[2]
            );
            let _ = writeln!(
                t,
                "  (a)/(c) = {:.3} (target ≤ {LATENCY_RATIO_TARGET}: {}); (b)/(c) = {:.3}",
                l.ratio,
                if l.ratio <= LATENCY_RATIO_TARGET {
                    "holds"
                } else {
                    "MISSED"
                },
                l.mean_m[1] / l.mean_m[2]
            );
            match &l.anees_position {
                Some(b) => {
                    let _ = writeln!(
                        t,
                        "  position ANEES of (a) {:.3}, 95 % band [{:.3}, {:.3}] after the first {} s ({}; {:.0} % of samples inside)",
                        b.value,
                        b.lower,
                        b.upper,
                        l.settle_s,
                        if b.holds() { "holds" } else { "MISSED" },
                        100.0 * b.fraction_inside.unwrap_or(f64::NAN)
                    );
                }
                None => {
                    let _ = writeln!(
                        t,
                        "  position ANEES of (a): not computed (nothing scored after {} s)",
                        l.settle_s
                    );
                }
            }
        }
        t
    }

    /// `faults.csv`: one row per run and fault (one per run for a scenario without faults):
    /// scenario, seed, the fault, its detection and recovery time (empty: not measured or never
    /// reached), the epochs alarmed before it, the recovery target, the ATE and (with a GNSS outage) the ATE outside it, and per quantity
    /// the valid epoch-axes and those outside 3σ and 4σ.
    ///
    /// # Errors
    /// When the CSV writer fails (it writes to memory).
    pub fn runs_csv(&self) -> Result<String, String> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| e.to_string();
        let mut header: Vec<String> = [
            "scenario",
            "seed",
            "sensor",
            "kind",
            "start_s",
            "end_s",
            "detection_s",
            "alarm_epochs_before",
            "recovery_s",
            "recovery_target_s",
            "ate_m",
            "ate_outside_gnss_outage_m",
        ]
        .iter()
        .map(|s| (*s).to_string())
        .collect();
        for q in QUANTITIES {
            header.push(format!("valid_{q}"));
            header.push(format!("over_3sigma_{q}"));
            header.push(format!("over_4sigma_{q}"));
        }
        w.write_record(&header).map_err(err)?;
        let cell = |x: Option<f64>| x.filter(|v| v.is_finite()).map_or(String::new(), seconds);
        for r in &self.per_run {
            let mut tail = vec![
                r.ate_m.map_or(String::new(), |a| a.to_string()),
                r.ate_outside_outage_m
                    .map_or(String::new(), |a| a.to_string()),
            ];
            for t in &r.false_valid.quantities {
                tail.push(t.valid_epoch_axes.to_string());
                tail.push(t.outside_3sigma.to_string());
                tail.push(t.outside_4sigma.to_string());
            }
            let rows: Vec<Vec<String>> = if r.faults.is_empty() {
                vec![vec![String::new(); 8]]
            } else {
                r.faults
                    .iter()
                    .map(|f| {
                        vec![
                            f.fault.sensor.clone(),
                            f.fault.kind.clone(),
                            seconds(f.start_s),
                            seconds(f.end_s),
                            cell(f.detection_s),
                            if f.rule.is_some() {
                                f.alarms_before.to_string()
                            } else {
                                String::new()
                            },
                            cell(f.recovery_s),
                            cell(f.rule.and_then(FaultRule::target_s)),
                        ]
                    })
                    .collect()
            };
            for mid in rows {
                let mut row = vec![r.scenario.clone(), r.seed.to_string()];
                row.extend(mid);
                row.extend(tail.iter().cloned());
                w.write_record(&row).map_err(err)?;
            }
        }
        let bytes = w.into_inner().map_err(|e| e.to_string())?;
        String::from_utf8(bytes).map_err(|e| e.to_string())
    }

    /// `faults.json`: how the bench was made (`host_sim_version`, `command_line`, `runs`,
    /// `seeds`, `workers`, `runtime_s`), the definitions, one object per table line
    /// (`scenarios`) and the latency comparison (`latency`, `null` when not made). A figure
    /// not measured is `null`.
    #[must_use]
    pub fn json(&self, command_line: &[String]) -> Value {
        let num = |x: Option<f64>| x.filter(|v| v.is_finite()).map_or(Value::Null, Value::from);
        let stats = |s: &Option<Stats>| match s {
            Some(s) => {
                json!({"n": s.pairs, "mean": s.mean, "median": s.median, "min": s.min, "max": s.max})
            }
            None => Value::Null,
        };
        let tally = |t: &Tally| {
            json!({
                "valid_epoch_axes": t.valid_epoch_axes,
                "outside_3sigma": t.outside_3sigma,
                "fraction_3sigma": num(Some(t.outside_3sigma as f64 / t.valid_epoch_axes as f64)),
                "expected_3sigma": expected(t.valid_epoch_axes, 3.0),
                "outside_4sigma": t.outside_4sigma,
                "fraction_4sigma": num(Some(t.outside_4sigma as f64 / t.valid_epoch_axes as f64)),
                "expected_4sigma": expected(t.valid_epoch_axes, 4.0),
            })
        };
        let scenarios: Vec<Value> = self
            .summaries
            .iter()
            .map(|s| {
                let mut fv = Map::new();
                for (q, t) in QUANTITIES.iter().zip(&s.false_valid.quantities) {
                    fv.insert((*q).into(), tally(t));
                }
                fv.insert("total".into(), tally(&s.false_valid.total()));
                let target = s.rule.and_then(FaultRule::target_s);
                json!({
                    "scenario": s.scenario,
                    "precision": s.precision,
                    "fault": s.fault.as_ref().map(|(f, a, b)| json!({
                        "sensor": f.sensor, "kind": f.kind, "start_s": a, "end_s": b,
                        "start_ns": f.start_ns, "end_ns": f.end_ns,
                    })),
                    "runs": s.runs,
                    "detection_s": s.rule.map(|r| json!({
                        "shown_by": r.describe_detection(),
                        "stats": stats(&s.detection),
                        "missed_seeds": s.missed,
                        "runs_alarmed_before_the_fault": s.alarmed_before.0,
                        "median_alarm_epochs_before_the_fault": s.alarmed_before.1,
                    })),
                    "recovery_s": s.rule.map(|r| json!({
                        "condition_for_1_s": r.describe_recovery(),
                        "stats": stats(&s.recovery),
                        "not_recovered_seeds": s.not_recovered,
                        "target_s": num(target),
                        "runs_within_target": target.map(|_| s.runs - s.over_target.len()),
                        "over_target": s.over_target.iter().map(|(seed, r)| json!({"seed": seed, "recovery_s": num(Some(*r))})).collect::<Vec<_>>(),
                    })),
                    "false_valid": Value::Object(fv),
                    "ate_se3_rmse_m": stats(&s.ate),
                    "ate_note": s.gnss_outage.then_some("includes the IMU-only dead reckoning through the GNSS outage; ate_outside_gnss_outage_se3_rmse_m leaves out the outage and the samples until the first fix fused after it"),
                    "ate_outside_gnss_outage_se3_rmse_m": if s.gnss_outage { stats(&s.ate_outside_outage) } else { Value::Null },
                })
            })
            .collect();
        let latency = self.latency.as_ref().map(|l| {
            json!({
                "scenario": l.scenario,
                "runs": l.seeds.len(),
                "mean_ate_m": {
                    "a_fused_at_validity_time": l.mean_m[0],
                    "b_taken_valid_on_arrival": l.mean_m[1],
                    "c_simulated_without_latency": l.mean_m[2],
                },
                "ratio_a_over_c": num(Some(l.ratio)),
                "ratio_b_over_c": num(Some(l.mean_m[1] / l.mean_m[2])),
                "target_ratio": LATENCY_RATIO_TARGET,
                "holds": l.ratio <= LATENCY_RATIO_TARGET,
                "anees_position_a": l.anees_position.as_ref().map(|b| json!({
                    "value": b.value, "expected": b.expected, "lower": b.lower, "upper": b.upper,
                    "fraction_inside": num(b.fraction_inside), "holds": b.holds(), "settle_s": l.settle_s,
                })),
                "per_run": l.seeds.iter().enumerate().map(|(i, seed)| json!({
                    "seed": seed,
                    "ate_a_m": num(l.ate_m[0].get(i).copied()),
                    "ate_b_m": num(l.ate_m[1].get(i).copied()),
                    "ate_c_m": num(l.ate_m[2].get(i).copied()),
                })).collect::<Vec<_>>(),
            })
        });
        json!({
            "host_sim_version": env!("CARGO_PKG_VERSION"),
            "command_line": command_line,
            "runs": self.runs,
            "seeds": self.seeds(),
            "workers": self.workers,
            "runtime_s": self.elapsed_s,
            "definitions": {
                "detection_s": "from the fault's start to the first IMU epoch at or after it whose report shows the fault",
                "recovery_s": "from the fault's end to the first epoch from which the condition holds for 1 s without interruption",
                "false_valid": "epoch-axes where a quantity is reported valid while its error (truth interpolated at the epoch) is outside 3 or 4 sigma of the reported 1-sigma; attitude per body axis (valid: tilt and heading valid), velocity and position per world axis, biases per axis",
                "expected": "a consistent Gaussian filter has 0.27 % of its epoch-axes outside 3 sigma and 0.0063 % outside 4 sigma; the 3-sigma count cannot be 0 even for a perfect filter, the 4-sigma count is the check",
            },
            "scenarios": scenarios,
            "latency": latency,
        })
    }

    /// Writes [`FILES`] into `dir`.
    ///
    /// # Errors
    /// A file that cannot be written, named.
    pub fn write(&self, dir: &Path, command_line: &[String]) -> Result<(), String> {
        let json = serde_json::to_string_pretty(&self.json(command_line))
            .map_err(|e| format!("faults.json: {e}"))?;
        for (name, text) in [
            ("faults.csv", self.runs_csv()?),
            ("faults.json", json + "\n"),
        ] {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(())
    }
}

/// A time in seconds to the nanosecond, without trailing zeros (the times are whole ns, and
/// `0.30000000000000004` says nothing more than `0.3`).
fn seconds(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// `outside / valid` as a percentage, or `–`.
fn fraction(t: &Tally) -> String {
    if t.valid_epoch_axes == 0 {
        "–".into()
    } else {
        format!(
            "{:.3} %",
            100.0 * t.outside_3sigma as f64 / t.valid_epoch_axes as f64
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::trajectory::Pose;
    use estimator_core::lie::{LieGroup, So3};
    use nalgebra::Vector3;

    /// An estimate exact outside `[10, 20)` s and 5 m off inside: the ATE outside the interval
    /// is 0 (to rounding), the whole run's is not.
    #[test]
    fn ate_outside_leaves_the_interval_out() {
        let pairs: Vec<PosePair> = (0..30u64)
            .map(|k| {
                let t_ns = k * 1_000_000_000;
                let truth = Pose {
                    position: Vector3::new(k as f64, (k * k) as f64 * 0.1, 0.5 * k as f64),
                    attitude: So3::identity(),
                };
                let off = if (10..20).contains(&k) { 5.0 } else { 0.0 };
                let estimate = Pose {
                    position: truth.position + Vector3::new(0.0, off, 0.0),
                    ..truth
                };
                PosePair {
                    t_ns,
                    estimate,
                    truth,
                }
            })
            .collect();
        let interval = [(10_000_000_000, 20_000_000_000)];
        let outside = ate_outside(&pairs, &interval).expect("pairs left");
        let whole = trajectory::ate(&pairs, Alignment::Se3)
            .expect("ate")
            .stats
            .rmse;
        assert!(outside < 1e-9, "{outside}");
        assert!(whole > 0.5, "{whole}");
        assert_eq!(ate_outside(&pairs[10..20], &interval), None);
    }

    /// The dead reckoning lasts until the first epoch at or after the outage's end with the
    /// GNSS fused, or to the end of the run.
    #[test]
    fn dead_reckoning_ends_at_the_first_fused_fix() {
        let eps: Vec<epochs::Epoch> = (0..10u64)
            .map(|k| {
                let mut e = epochs::Epoch::nominal(k * 100);
                e.gnss = if k == 2 || k >= 7 {
                    epochs::AidStatus::Fused
                } else {
                    epochs::AidStatus::Stale
                };
                e
            })
            .collect();
        assert_eq!(dead_reckoning_end(&eps, 500), 700);
        assert_eq!(dead_reckoning_end(&eps, 700), 700);
        assert_eq!(dead_reckoning_end(&eps, 1_000), u64::MAX);
    }
}

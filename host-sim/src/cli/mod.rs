//! The command line:
//!
//! | command | does |
//! |---|---|
//! | `host-sim [run] [--scenario NAME] [--seed N] [--out DIR] [--force]` | simulate, filter, score, plot; prints a summary table (default: the `default` scenario into `out/`) |
//! | `host-sim simulate --scenario NAME [--seed N] --out DIR [--force]` | write a dataset folder with ground truth ([`crate::dataset`]) |
//! | `host-sim replay DATASET [--out DIR] [--config FILE] [--force]` | run the filter over a dataset folder, with or without ground truth |
//! | `host-sim bench DIR [--out OUT] [--config FILE] [--references-6d FILE] [--force]` | replay every dataset folder under `DIR` (one and two levels deep) and print its scores beside the `references.json` of its folder; BROAD trials also without the magnetometer, beside VQF 6D ([`host_sim::bench`]; default `OUT`: `out/bench`) |
//! | `host-sim montecarlo --scenario NAME --runs N [--seed S] [--out DIR] [--json] [--force] [--check]` | consistency over the seeds `S`..`S+N-1`: NEES / NIS against chi-square bands; with `--out`, the runs and bands as CSV and JSON ([`host_sim::montecarlo`]) |
//! | `host-sim faults [--scenario NAME ...] [--runs N] [--seed S] --out DIR [--force] [--json] [--latency]` | the fault bench over the `fault_*` scenarios: detection and recovery times, false-valid epochs, ATE, and the latency comparison ([`host_sim::faults`]) |
//! | `host-sim calibrate DIR [--out DIR] [--from S] [--to S] [--force]` | IMU and magnetometer noise from a static recording (Allan deviation, `host_sim::calibrate`) |
//! | `host-sim scenarios` | list the built-in scenarios |
//!
//! Every output folder is written beside its target and moved into place when the command
//! succeeds. An existing folder is written only if it holds an earlier host-sim output and
//! `--force` is given, and then only the files that output listed are replaced: any other file
//! or folder inside (a user's notes, another command's output nested in it) is kept
//! (`host_sim::output`).
//!
//! Exit status 0 on success; bad input (a missing file, a malformed row, time going backwards)
//! gives a one-line error naming the file and the line, and a non-zero exit status.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

pub mod faults;
pub mod notes;

/// Simulate, replay and score the estimator.
#[derive(Debug, Parser)]
#[command(
    name = "host-sim",
    version,
    about,
    after_help = "Without a command, runs `host-sim run`: 60 s of the `default` scenario into out/ \
(refused if out/ exists and is not empty; `host-sim run --force` replaces the files of an earlier host-sim output \
and keeps every other file or folder in it).\n\n\
Examples:\n  host-sim scenarios\n  host-sim run --scenario car --seed 3 --out out/car\n  \
host-sim simulate --scenario car --out data/car\n  host-sim replay data/car --out out/car\n  \
host-sim bench ../shared/datasets --out out/bench\n  host-sim montecarlo --scenario matched_ins --runs 60 --check"
)]
pub struct Cli {
    /// What to do (default: `run`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate, filter, score and plot; prints a summary table.
    #[command(
        after_help = "Writes into --out: estimate.tum, estimate.csv, groundtruth.tum (TUM: t x y z qx qy qz qw), \
metrics.json, validity.csv (with GNSS: the INS navigator's report after every IMU sample), trajectory.png, errors.png, \
biases.png, nis.png, and dataset/ (the simulated EuRoC-layout dataset).\n\n\
Example: host-sim run --scenario handheld_ahrs --seed 2 --out out/ahrs"
    )]
    Run {
        /// A built-in scenario name or a TOML file.
        #[arg(long, default_value = "default")]
        scenario: String,
        /// Random seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
    },
    /// Write a dataset folder (EuRoC layout) with ground truth.
    #[command(
        after_help = "Writes into --out: imu0/, and mag0/, gnss0/, baro0/ as the scenario has them \
(data.csv and sensor.yaml each), cam0/ (sensor.yaml, landmarks.csv, observations.csv), state_groundtruth_estimate0/data.csv, and replay.toml (how `replay` runs on it).\n\n\
Example: host-sim simulate --scenario car --seed 3 --out data/car"
    )]
    Simulate {
        /// A built-in scenario name or a TOML file.
        #[arg(long)]
        scenario: String,
        /// Random seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output dataset folder.
        #[arg(long)]
        out: PathBuf,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
    },
    /// Run the filter over a dataset folder.
    #[command(
        after_help = "Reads DATASET (EuRoC layout: imu0/ required; mag0/, gnss0/, cam0/, baro0/, \
state_groundtruth_estimate0/ when present) and its replay.toml unless --config is given.\n\
Writes into --out the same files as `run` (without dataset/).\n\
What the data has wrong that the replay survives (a last line cut short, gaps, a sensor starting late or stopping early, \
samples the navigator refused) is printed on stderr as `warning: FILE:LINE: message` and kept in metrics.json (data_warnings).\n\n\
Example: host-sim replay data/car --out out/car"
    )]
    Replay {
        /// The dataset folder.
        dataset: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Filter configuration (TOML).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
    },
    /// Replay every dataset folder under DIR and print its scores beside the published
    /// references.
    #[command(
        after_help = "Finds every dataset folder (one holding imu0/data.csv) in DIR or one or two levels below, \
replays each (plots off; --config, else the dataset's replay.toml, else the defaults) and prints one table per parent folder, \
against that folder's references.json when present:\n\
  BROAD (references.json with \"trials\"): BROAD's total / heading / inclination RMSE [deg] inside movement.csv, \
the share of those samples inside the reported 3σ ellipsoid (NEES ≤ 9), real-time VQF's and Madgwick's total, \
and the 6-axis inclination: each trial with a magnetometer replayed again with use_magnetometer = false (into OUT/6axis/), \
beside VQF 6D's inclination (gyroscope and accelerometer only) from references.json's \"vqf_6d\", else from --references-6d FILE; \
the mean and the worst trial (each only where every trial has the figure);\n\
  otherwise (\"datasets\", or none): the sensors ours fuses, the attitude RMSE [deg] from 2 s after the first ground-truth sample, \
the attitude ANEES, VQF's RMSE and ours/VQF, the ratio only where ours fuses VQF 9D's sensors (IMU+mag): \
a dataset with GNSS replays through the INS navigator and is not divided by attitude-only VQF.\n\
Progress goes to stderr: a bar on a terminal, else a line every 5 s (HOST_SIM_PROGRESS_S sets the interval).\n\
A figure not computed is printed '–' (null in bench.json).\n\
Writes into --out: one folder per dataset (estimate.tum, estimate.csv, groundtruth.tum, metrics.json), 6axis/ (the same for the runs without the magnetometer) and bench.json (every figure of the tables).\n\
Exit status non-zero when a dataset fails to run (its error is in its row; the others still run) or a references.json cannot be read.\n\n\
Examples:\n  host-sim bench ../shared/datasets --out out/bench\n  \
python3 tools/vqf_references.py ../shared/datasets/broad --out out/vqf_6d.json\n  \
host-sim bench ../shared/datasets --references-6d out/vqf_6d.json --out out/bench-6d"
    )]
    Bench {
        /// The folder holding the dataset folders.
        dir: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out/bench")]
        out: PathBuf,
        /// Filter configuration (TOML) for every dataset.
        #[arg(long)]
        config: Option<PathBuf>,
        /// VQF 6D's BROAD figures for the trials whose references.json has none: a JSON file
        /// {"trials": {NAME: {"vqf_6d": {"inclination": DEG}}}}, as
        /// `python3 tools/vqf_references.py DIR --out FILE` writes it.
        #[arg(long, value_name = "FILE")]
        references_6d: Option<PathBuf>,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
    },
    /// Consistency over seeds: NEES/NIS against chi-square bounds.
    #[command(
        after_help = "Simulates the scenario (a built-in name or a TOML file) once per seed, --seed to --seed + --runs - 1, \
and replays each with the scenario's replay configuration (no plots).\n\
Prints, after the first 20 s (the start-up), the ANEES per block and the mean NIS per sensor over the runs \
against their 95 % chi-square bands, with the fraction of samples inside (NEES) and whether each holds; \
--json prints montecarlo.json instead.\n\
Writes with --out (nothing without it): runs.csv (one row per run: seed, ATE, attitude and velocity RMSE, \
ANEES per block, mean NIS and accepted / gated-out / refused updates per sensor, each over the whole run as `run` reports it; \
an empty cell where not estimated), \
bands.csv (the printed table: statistic, value, expected, lower, upper, fraction_inside, holds) and montecarlo.json \
(both, with the command line, scenario, precision, seeds, runs, settle time and host-sim version).\n\
Exit status non-zero with --check when a band is missed (the outputs are still written).\n\
Progress goes to stderr: a bar on a terminal, else a line every 5 s (HOST_SIM_PROGRESS_S sets the interval).\n\n\
Examples:\n  host-sim montecarlo --scenario matched_ins --runs 60 --check\n  \
host-sim montecarlo --scenario matched_ahrs --runs 20 --seed 101 --out out/mc_ahrs"
    )]
    Montecarlo {
        /// A built-in scenario name or a TOML file.
        #[arg(long)]
        scenario: String,
        /// Number of runs.
        #[arg(long, default_value_t = 25, value_parser = clap::value_parser!(u64).range(1..))]
        runs: u64,
        /// Random seed of the first run; the runs use --seed to --seed + --runs - 1.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output folder for runs.csv, bands.csv and montecarlo.json (default: write nothing).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print montecarlo.json to stdout instead of the table.
        #[arg(long)]
        json: bool,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long, requires = "out")]
        force: bool,
        /// Exit non-zero when a band is missed.
        #[arg(long)]
        check: bool,
    },
    /// The fault bench: detection and recovery times, false-valid epochs and ATE of the INS
    /// navigator over the fault scenarios.
    #[command(
        after_help = "Simulates each scenario (default: every built-in fault_* scenario; a name or a TOML file, repeatable) \
once per seed, --seed to --seed + --runs - 1, replays it with its replay configuration (no plots) and reads back validity.csv, \
estimate.csv, the ground truth and faults.csv. Per scenario and fault it prints:\n\
  detection: s from the fault's start to the first IMU epoch whose report shows it (GNSS step: position fixes_disagree or gnss rejected; \
frozen: gnss faulty; outage: gnss stale; magnetometer: rejected or faulty; barometer step: rejected; IMU clip or stuck axis: imu_fault), median / max;\n\
  recovery: s from the fault's end until, for 1 s without interruption, the sensor is fused and the quantity it affects valid with its error within 3σ, \
median / max, against the target (7 s position, 5 s height);\n\
  false-valid: epoch-axes reported valid with the error outside 3σ (beside the 0.27 % a consistent Gaussian filter shows, never 0) and outside 4σ;\n\
  ATE: the SE(3)-aligned ATE RMSE, mean / max.\n\
With fault_gnss_latency among the scenarios, or --latency: the mean ATE with fixes fused at their validity time, taken as valid on arrival, \
and simulated without latency, their ratio (target ≤ 1.1), and the position ANEES against its 95 % band as `montecarlo` computes it.\n\
With a GNSS outage the ATE includes the IMU-only dead reckoning through it; the ATE outside it (until the first fix fused after it) is given beside it.\n\
The runs are simulated in a scratch folder beside --out, removed at the end.\n\
Progress goes to stderr: a bar on a terminal, else a line every 5 s (HOST_SIM_PROGRESS_S sets the interval).\n\
Writes into --out: faults.csv (one row per run and fault) and faults.json (the summary; --json prints it instead of the tables).\n\n\
Examples:\n  host-sim faults --out out/faults\n  host-sim faults --scenario fault_gnss_step --scenario fault_accel_clip --runs 5 --out out/faults_short"
    )]
    Faults {
        /// A scenario (built-in name or TOML file); repeat for several (default: every
        /// built-in `fault_*` scenario).
        #[arg(long)]
        scenario: Vec<String>,
        /// Runs per scenario.
        #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u64).range(1..))]
        runs: u64,
        /// Random seed of the first run; the runs use --seed to --seed + --runs - 1.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output folder for faults.csv and faults.json.
        #[arg(long)]
        out: PathBuf,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
        /// Print faults.json to stdout instead of the tables.
        #[arg(long)]
        json: bool,
        /// Make the latency comparison even when fault_gnss_latency is not among the scenarios.
        #[arg(long)]
        latency: bool,
    },
    /// IMU and magnetometer noise from a static recording (Allan deviation).
    #[command(
        after_help = "Reads DIR/imu0/data.csv and, when present, DIR/mag0/data.csv (EuRoC layout), between --from \
and --to seconds after the first IMU sample (default: all of it); the sensor must be at rest there.\n\
Prints per sensor and axis the white noise density N, bias instability B and rate random walk K with the \
cluster time each was read at.\n\
Writes into --out: imu0/sensor.yaml (rate_hz, gyroscope_/accelerometer_noise_density and _random_walk, the \
largest over the axes, T_BS identity), mag0/sensor.yaml (rate_hz, sigma; reference_field is left to you), \
allan.csv (tau and sigma per axis per sensor) and calibration.json (everything printed).\n\n\
Example: host-sim calibrate data/bench_static --to 30 --out out/imu_noise"
    )]
    Calibrate {
        /// The dataset folder (imu0/data.csv required, mag0/data.csv optional).
        dir: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out/calibration")]
        out: PathBuf,
        /// Start of the static interval, seconds after the first IMU sample.
        #[arg(long)]
        from: Option<f64>,
        /// End of the static interval, seconds after the first IMU sample (default: the end).
        #[arg(long)]
        to: Option<f64>,
        /// Replace the files of an earlier host-sim output in the output folder (the ones its
        /// manifest lists; every other file or folder in it is kept; a folder host-sim did not
        /// write is refused).
        #[arg(long)]
        force: bool,
    },
    /// List the built-in scenarios.
    Scenarios,
}

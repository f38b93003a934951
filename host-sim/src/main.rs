//! The `host-sim` binary: see `host_sim::cli`.

mod cli;

/// `println!` that ignores a closed pipe (`host-sim run | head`) instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

use clap::Parser;
use cli::{Cli, Command};
use host_sim::bench::{replay_config, BenchOptions};
use host_sim::dataset::write::simulate;
use host_sim::metrics::trajectory::Alignment;
use host_sim::metrics::{Metrics, Scorer, ATE_ALIGNMENT};
use host_sim::output::Staging;
use host_sim::progress::{Mode, Progress};
use host_sim::replay::{replay, replay_scored, ReplayConfig};
use host_sim::scenario::{builtin_scenarios, Scenario};
use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Run {
        scenario: "default".into(),
        seed: 1,
        out: "out".into(),
        force: false,
    });
    match execute(command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("host-sim: {e}");
            ExitCode::FAILURE
        }
    }
}

fn execute(command: Command) -> Result<(), Box<dyn std::error::Error>> {
    match command {
        Command::Scenarios => {
            for s in builtin_scenarios() {
                out!("{:<14} {}", s.name, s.description);
            }
            Ok(())
        }
        Command::Simulate {
            scenario,
            seed,
            out,
            force,
        } => {
            let sc = Scenario::load(&scenario)?;
            let staging = Staging::new(&out, force, "simulate")?;
            simulate(&sc, seed, staging.dir())?;
            staging.commit()?;
            out!(
                "wrote {} ({} s of '{}', seed {seed})",
                out.display(),
                sc.duration_s,
                sc.name
            );
            Ok(())
        }
        Command::Run {
            scenario,
            seed,
            out,
            force,
        } => {
            let sc = Scenario::load(&scenario)?;
            let staging = Staging::new(&out, force, "run")?;
            let dataset = staging.dir().join("dataset");
            simulate(&sc, seed, &dataset)?;
            let cfg = sc.replay.clone();
            let mut scorer = Scorer::default();
            scorer.provenance.scenario = Some(sc.name.clone());
            scorer.provenance.seed = Some(seed);
            scorer.provenance.dataset = Some(out.join("dataset").display().to_string());
            let m = replay_scored(&dataset, staging.dir(), &cfg, &sc.name, scorer)?.metrics();
            print_data_warnings(&m);
            staging.commit()?;
            print_summary(&sc.name, Some(seed), &cfg, &m, &out, None);
            Ok(())
        }
        Command::Replay {
            dataset,
            out,
            config,
            force,
        } => {
            // A EuRoC sequence's folder (holding mav0/) is read as its mav0/.
            let located = host_sim::dataset::locate(&dataset);
            let dataset = located.dir.clone();
            if let (Ok(d), Ok(o)) = (dataset.canonicalize(), out.canonicalize()) {
                if d.starts_with(&o) {
                    return Err(format!(
                        "{}: the output folder holds the dataset {}; name another folder with --out",
                        out.display(),
                        dataset.display()
                    )
                    .into());
                }
            }
            // The given configuration, else the dataset's replay.toml, else the defaults.
            let cfg = replay_config(config.as_deref(), &dataset)?;
            let title = located
                .root
                .as_deref()
                .unwrap_or(&dataset)
                .file_name()
                .map_or("dataset".into(), |n| n.to_string_lossy().into_owned());
            let staging = Staging::new(&out, force, "replay")?;
            let m = replay(&dataset, staging.dir(), &cfg, &title)?;
            print_data_warnings(&m);
            let truth = dataset.join("state_groundtruth_estimate0/data.csv");
            if m.samples_scored == 0 && truth.is_file() {
                return Err(format!(
                    "{}: no estimate could be scored against it (empty, or no time in common with the IMU); nothing written",
                    truth.display()
                )
                .into());
            }
            staging.commit()?;
            print_summary(&title, None, &cfg, &m, &out, located.note());
            Ok(())
        }
        Command::Bench {
            dir,
            out,
            config,
            force,
            references_6d,
        } => {
            let opts = BenchOptions {
                dir,
                out,
                config,
                force,
                references_6d,
            };
            let mut progress: Option<Progress> = None;
            let report = host_sim::bench::run(&opts, |i, n, run| {
                let p = progress.get_or_insert_with(|| {
                    Progress::new("bench", "runs", n as u64, Mode::for_stderr(true))
                });
                if i > 0 {
                    p.inc(1);
                }
                p.note(&format!("bench [{}/{n}] {run}", i + 1));
            });
            if let Some(p) = progress {
                if report.is_ok() {
                    p.inc(1);
                }
                p.finish();
            }
            let report = report?;
            for w in &report.data_warnings {
                eprintln!("warning: {w}");
            }
            out!("{}", report.render().trim_start());
            out!("outputs in {}", opts.out.display());
            let failures = report.failures();
            if failures.is_empty() {
                Ok(())
            } else {
                Err(format!("{} failure(s): {}", failures.len(), failures.join("; ")).into())
            }
        }
        Command::Calibrate {
            dir,
            out,
            from,
            to,
            force,
        } => {
            if let (Ok(d), Ok(o)) = (dir.canonicalize(), out.canonicalize()) {
                if d.starts_with(&o) {
                    return Err(format!(
                        "{}: the output folder holds the dataset {}; name another folder with --out",
                        out.display(),
                        dir.display()
                    )
                    .into());
                }
            }
            let staging = Staging::new(&out, force, "calibrate")?;
            let cal = host_sim::calibrate::calibrate(&dir, from, to)?;
            for w in &cal.data_warnings {
                eprintln!("warning: {w}");
            }
            cal.write(staging.dir())?;
            staging.commit()?;
            out!("{}", cal.table());
            out!("  outputs in {}", out.display());
            Ok(())
        }
        Command::Faults {
            scenario,
            runs,
            seed,
            out,
            force,
            json,
            latency,
        } => cli::faults::execute(cli::faults::Args {
            scenario,
            runs,
            seed,
            out,
            force,
            json,
            latency,
        }),
        Command::Montecarlo {
            scenario,
            runs,
            seed,
            out,
            json,
            force,
            check,
        } => {
            let sc = Scenario::load(&scenario)?;
            // The output folder is checked before the runs, not after.
            let staging = match &out {
                Some(o) => Some(Staging::new(o, force, "montecarlo")?),
                None => None,
            };
            let settle = host_sim::montecarlo::DEFAULT_SETTLE_S;
            let report = host_sim::montecarlo::run_from(&sc, seed, runs, settle, true)?;
            for line in report.data_warning_lines() {
                eprintln!("{line}");
            }
            let command_line: Vec<String> = std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect();
            if let Some(staging) = staging {
                report.write(staging.dir(), &command_line)?;
                staging.commit()?;
            }
            if json {
                out!(
                    "{}",
                    serde_json::to_string_pretty(&report.json(&command_line))?
                );
            } else {
                out!("{}", report.table().trim_end());
                if let Some(o) = &out {
                    out!("  outputs in {}", o.display());
                }
            }
            if check && !report.holds() {
                return Err("a consistency band is missed".into());
            }
            Ok(())
        }
    }
}

/// What the data had wrong that the run survived, one `warning: FILE:LINE: message` line each
/// on stderr.
fn print_data_warnings(m: &Metrics) {
    for w in &m.data_warnings {
        eprintln!("warning: {w}");
    }
}

/// The summary table of a run (`seed`: the simulated scenario's) or of a replay (`None`).
fn print_summary(
    name: &str,
    seed: Option<u64>,
    cfg: &ReplayConfig,
    m: &Metrics,
    out: &Path,
    dataset_note: Option<String>,
) {
    match seed {
        Some(seed) => out!("scenario {name}  seed {seed}  precision {}", cfg.precision),
        None => out!("dataset {name}  precision {}", cfg.precision),
    }
    if let Some(note) = dataset_note {
        out!("  dataset: {note}");
    }
    if m.samples_scored == 0 {
        out!("  not scored: the dataset has no ground truth (the estimate is in the outputs)");
    }
    out!(
        "  {:<28} {:>12}",
        "position RMSE, unaligned [m]",
        fmt(m.ate_position_rmse_m)
    );
    // evo's figures: the ATE after the alignment of `ate`, the others beside it, and the RPE.
    if let Some(a) = &m.ate {
        let others: Vec<String> = m
            .ate_by_alignment
            .values()
            .filter(|o| o.alignment != ATE_ALIGNMENT)
            .map(|o| format!("{} {}", o.alignment.describe(), fmt(o.stats.rmse)))
            .collect();
        let evo = if a.alignment == Alignment::Se3 {
            " (evo_ape -a)"
        } else {
            ""
        };
        out!(
            "  {:<28} {:>12}   max {}, {} pairs{evo}; {}",
            format!("ATE RMSE, {} [m]", a.alignment.describe()),
            fmt(a.stats.rmse),
            fmt(a.stats.max),
            a.stats.pairs,
            others.join(", ")
        );
    }
    if let Some(r) = &m.rpe {
        out!(
            "  {:<28} {:>12}   max {}, {} pairs (evo_rpe, translation)",
            format!("RPE RMSE over {} {} [m]", r.delta, r.delta_unit),
            fmt(r.stats.rmse),
            fmt(r.stats.max),
            r.stats.pairs
        );
    }
    out!(
        "  {:<28} {:>12}",
        "attitude RMSE [deg]",
        fmt(m.attitude_rmse_deg)
    );
    let yaw_note = if m.heading_reference == Some(false) {
        "IMU only (no heading reference), the figure to read: "
    } else {
        ""
    };
    out!(
        "  {:<28} {:>12}   {yaw_note}constant heading offset {}° over the run removed",
        "attitude RMSE, yaw-aligned [deg]",
        fmt(m.attitude_rmse_yaw_aligned_deg),
        fmt(m.attitude_yaw_offset_deg)
    );
    out!(
        "  {:<28} {:>12}",
        "attitude RMSE after 2 s [deg]",
        fmt(m.attitude_rmse_after_2s_deg)
    );
    if let Some(b) = &m.broad {
        out!(
            "  {:<28} {:>12}   heading {}, inclination {} ({} samples in movement.csv)",
            "BROAD total RMSE [deg]",
            fmt(b.total_deg),
            fmt(b.heading_deg),
            fmt(b.inclination_deg),
            b.samples
        );
    }
    out!(
        "  {:<28} {:>12}",
        "velocity RMSE [m/s]",
        fmt(m.velocity_rmse_mps)
    );
    for (block, v) in &m.nees_mean {
        out!(
            "  {:<28} {:>12}",
            format!("ANEES {block} (expect 3)"),
            fmt(*v)
        );
    }
    // Every sensor that took part, with what became of its updates (refused: bad input or a
    // numerical failure; rejected: the gate).
    let sensors: std::collections::BTreeSet<&String> = m
        .updates_accepted
        .keys()
        .chain(m.updates_rejected.keys())
        .chain(m.updates_refused.keys())
        .collect();
    for sensor in sensors {
        let a = m.updates_accepted.get(sensor).copied().unwrap_or(0);
        let r = m.updates_rejected.get(sensor).copied().unwrap_or(0);
        let f = m.updates_refused.get(sensor).copied().unwrap_or(0);
        let nis = m.nis_mean.get(sensor).copied().unwrap_or(f64::NAN);
        out!(
            "  {:<28} {:>12}   accepted {a}, gated out {r}, refused {f}",
            format!("mean NIS {sensor}"),
            fmt(nis)
        );
    }
    for w in &m.warnings {
        out!("  warning: {w}");
    }
    if !m.data_warnings.is_empty() {
        let n = m.data_warnings.len();
        out!(
            "  warning: {n} about the data (gaps, a cut line, unused samples), each on stderr and in metrics.json (data_warnings)"
        );
    }
    for n in cli::notes::consistency_notes(cfg, m, seed.is_some()) {
        out!("  note: {n}");
    }
    for (name, v) in &m.baseline_attitude_rmse_deg {
        out!(
            "  {:<28} {:>12}",
            format!("  {name} attitude RMSE [deg]"),
            fmt(*v)
        );
    }
    out!(
        "  {:<28} {:>12}",
        "filter ns per IMU sample",
        fmt(m.filter_ns_per_imu_sample)
    );
    out!("  outputs in {}", out.display());
}

fn fmt(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "-".into()
    }
}

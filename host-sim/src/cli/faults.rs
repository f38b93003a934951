//! `host-sim faults`: the command around [`host_sim::faults`].

use host_sim::faults::{builtin_fault_scenarios, Options, ScratchDir, LATENCY_SCENARIO};
use host_sim::output::Staging;
use host_sim::scenario::Scenario;
use std::io::Write as _;
use std::path::PathBuf;

/// The arguments of `host-sim faults` (see [`super::Command::Faults`]).
#[derive(Debug)]
pub struct Args {
    /// Scenario names or TOML files; empty: every built-in `fault_*` scenario.
    pub scenario: Vec<String>,
    /// Runs per scenario.
    pub runs: u64,
    /// Seed of the first run.
    pub seed: u64,
    /// Output folder.
    pub out: PathBuf,
    /// Replace an earlier host-sim output.
    pub force: bool,
    /// Print the JSON summary instead of the tables.
    pub json: bool,
    /// Make the latency comparison whatever the scenarios.
    pub latency: bool,
}

/// Runs the bench, writes `faults.csv` and `faults.json` into the output folder (written beside
/// it and moved into place, see `host_sim::output`) and prints the tables or the JSON.
///
/// # Errors
/// An unknown scenario, an output folder that may not be written, or a failed run.
pub fn execute(a: Args) -> Result<(), Box<dyn std::error::Error>> {
    let mut scenarios: Vec<Scenario> = if a.scenario.is_empty() {
        builtin_fault_scenarios()
    } else {
        a.scenario
            .iter()
            .map(|n| Scenario::load(n))
            .collect::<Result<_, _>>()?
    };
    // A scenario named twice runs once.
    let mut seen = std::collections::BTreeSet::new();
    scenarios.retain(|s| seen.insert(s.name.clone()));
    let latency = match scenarios.iter().find(|s| s.name == LATENCY_SCENARIO) {
        Some(s) => Some(s.clone()),
        None if a.latency => Some(Scenario::load(LATENCY_SCENARIO)?),
        None => None,
    };
    // The output folder is checked before the runs, not after.
    let staging = Staging::new(&a.out, a.force, "faults")?;
    let scratch = ScratchDir::beside(&a.out)?;
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let opts = Options {
        scenarios,
        first_seed: a.seed,
        runs: a.runs,
        latency,
        workers,
        scratch: scratch.path().to_path_buf(),
        progress: true,
    };
    let bench = host_sim::faults::run(&opts)?;
    drop(scratch);
    for line in bench.data_warning_lines() {
        eprintln!("{line}");
    }
    let command_line: Vec<String> = std::env::args_os()
        .map(|x| x.to_string_lossy().into_owned())
        .collect();
    bench.write(staging.dir(), &command_line)?;
    staging.commit()?;
    // A closed pipe (`host-sim faults | head`) is not an error.
    let mut stdout = std::io::stdout();
    if a.json {
        let _ = writeln!(
            stdout,
            "{}",
            serde_json::to_string_pretty(&bench.json(&command_line))?
        );
    } else {
        let _ = writeln!(stdout, "{}", bench.table().trim_end());
        let _ = writeln!(stdout, "  outputs in {}", a.out.display());
    }
    Ok(())
}

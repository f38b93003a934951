//! The `host-sim` binary: see `host_sim::cli`.

mod cli;

use clap::Parser;
use cli::{Cli, Command};
use host_sim::dataset::write::simulate;
use host_sim::scenario::{builtin_scenarios, Scenario};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Run {
        scenario: "default".into(),
        seed: 1,
        out: "out".into(),
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
                println!("{:<14} {}", s.name, s.description);
            }
            Ok(())
        }
        Command::Simulate {
            scenario,
            seed,
            out,
        } => {
            let sc = Scenario::load(&scenario)?;
            simulate(&sc, seed, &out)?;
            println!(
                "wrote {} ({} s of '{}', seed {seed})",
                out.display(),
                sc.duration_s,
                sc.name
            );
            Ok(())
        }
        Command::Run { .. } | Command::Replay { .. } | Command::Montecarlo { .. } => {
            Err("the filter replay is not wired in yet".into())
        }
    }
}

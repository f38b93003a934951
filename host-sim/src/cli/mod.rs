//! The command line (see the contract's `host-sim` table).

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Simulate, replay and score the estimator.
#[derive(Debug, Parser)]
#[command(name = "host-sim", version, about)]
pub struct Cli {
    /// What to do (default: `run`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate, filter, score and plot; prints a summary table.
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
    },
    /// Write a dataset folder (EuRoC layout) with ground truth.
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
    },
    /// Run the filter over a dataset folder.
    Replay {
        /// The dataset folder.
        dataset: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Filter configuration (TOML).
        #[arg(long)]
        config: Option<PathBuf>,
    },
    /// Consistency over seeds: NEES/NIS against chi-square bounds.
    Montecarlo {
        /// A built-in scenario name or a TOML file.
        #[arg(long)]
        scenario: String,
        /// Number of runs.
        #[arg(long, default_value_t = 25)]
        runs: u64,
        /// Exit non-zero when a band is missed.
        #[arg(long)]
        check: bool,
    },
    /// List the built-in scenarios.
    Scenarios,
}

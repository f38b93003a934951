//! `host-sim montecarlo`: filter consistency over seeds.
//!
//! Each run simulates the scenario with its own seed and replays it (in parallel with `rayon`,
//! with an `indicatif` progress bar). Two tests, each against its 95 % chi-square band:
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

use crate::dataset::write::simulate;
use crate::metrics::{Scorer, BLOCKS};
use crate::replay::{replay_scored, ReplayConfig};
use crate::scenario::Scenario;
use crate::stats::chi2_quantile;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::PathBuf;

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
}

impl BandResult {
    /// `true` when the statistic lies in its band.
    #[must_use]
    pub fn holds(&self) -> bool {
        self.value >= self.lower && self.value <= self.upper
    }
}

/// The whole Monte-Carlo report.
#[derive(Clone, Debug)]
pub struct Report {
    /// Runs that completed.
    pub runs: usize,
    /// NEES per block.
    pub nees: Vec<BandResult>,
    /// NIS per sensor.
    pub nis: Vec<BandResult>,
}

impl Report {
    /// `true` when every band holds.
    #[must_use]
    pub fn holds(&self) -> bool {
        self.nees.iter().chain(&self.nis).all(BandResult::holds)
    }
}

/// Runs `runs` seeds (1..=runs) of `scenario`, with the scenario's replay configuration.
pub fn run(
    scenario: &Scenario,
    runs: u64,
    settle_s: f64,
    progress: bool,
) -> Result<Report, String> {
    let base: PathBuf = std::env::temp_dir().join(format!(
        "host-sim-mc-{}-{}",
        std::process::id(),
        scenario.name.replace('/', "_")
    ));
    let bar = if progress {
        ProgressBar::new(runs)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let cfg = ReplayConfig {
        plots: false,
        ..scenario.replay.clone()
    };
    let results: Vec<Result<Scorer, String>> = (1..=runs)
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
                });
            let _ = std::fs::remove_dir_all(&dir);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
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
            });
        }
    }
    let mut nis = Vec::new();
    let sensors: std::collections::BTreeSet<String> = scorers
        .iter()
        .flat_map(|s| s.sensors.keys().cloned())
        .collect();
    for name in sensors {
        let (mut total, mut dof, mut count) = (0.0, 0.0, 0.0);
        for s in &scorers {
            if let Some(st) = s.sensors.get(&name) {
                // After the start-up, like the NEES (the history holds every update unless a
                // run is long enough to be decimated, when it holds a uniform subsample).
                for &(t, nis, d) in st.history.points().iter().filter(|p| p.0 >= settle_s) {
                    let _ = t;
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
            });
        }
    }
    Ok(Report { runs: n, nees, nis })
}

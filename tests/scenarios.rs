//! End to end: simulator → filter → metrics, for every built-in scenario, and Monte-Carlo
//! consistency of the matched-noise scenarios.

use host_sim::dataset::write::simulate;
use host_sim::replay::{replay, ReplayConfig};
use host_sim::scenario::builtin_scenarios;

fn tmp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("estimator-e2e-{}-{name}", std::process::id()))
}

/// Every built-in scenario runs and stays inside its accuracy ceilings.
#[test]
fn every_scenario_within_its_ceilings() {
    let mut failures = Vec::new();
    for sc in builtin_scenarios() {
        let dir = tmp(&sc.name);
        let ds = dir.join("dataset");
        simulate(&sc, 1, &ds).expect("simulate");
        let cfg = ReplayConfig {
            plots: false,
            ..sc.replay.clone()
        };
        let m = replay(&ds, &dir, &cfg, &sc.name).expect("replay");
        let ate_ok = !sc.ceilings.ate_m.is_finite() || m.ate_position_rmse_m <= sc.ceilings.ate_m;
        let att_ok = m.attitude_rmse_deg <= sc.ceilings.attitude_deg;
        println!(
            "{:<14} ATE {:>7.3} m (ceiling {:>5}), attitude {:>6.3}° (ceiling {:>4}), ANEES {:?}",
            sc.name,
            m.ate_position_rmse_m,
            sc.ceilings.ate_m,
            m.attitude_rmse_deg,
            sc.ceilings.attitude_deg,
            m.nees_mean
        );
        if !(ate_ok && att_ok) {
            failures.push(sc.name.clone());
        }
        let _ = std::fs::remove_dir_all(dir);
    }
    assert!(failures.is_empty(), "over their ceilings: {failures:?}");
}

/// With the simulated noise equal to the noise the filter assumes, ANEES per block and mean NIS
/// per sensor lie inside their chi-square bands, over 60 seeds, at a family-wise confidence of
/// 95 % for the statistics of both scenarios together (Šidák: each at `0.95^(1/k)`; each at 95 %,
/// a consistent filter would miss some band in `1 − 0.95^k` of the seeds' draws, 49 % for
/// `k` = 13).
#[test]
fn matched_scenarios_are_consistent() {
    let reports: Vec<_> = ["matched_ins", "matched_ahrs"]
        .into_iter()
        .map(|name| {
            let sc = builtin_scenarios()
                .into_iter()
                .find(|s| s.name == name)
                .expect("builtin");
            let report = host_sim::montecarlo::run(&sc, 60, 20.0, false).expect("monte carlo");
            (name, report)
        })
        .collect();
    let k = reports
        .iter()
        .map(|(_, r)| r.nees.len() + r.nis.len())
        .sum::<usize>();
    let p = 0.95_f64.powf(1.0 / k as f64);
    let mut missed = Vec::new();
    for (name, report) in &reports {
        for r in report.nees.iter().chain(&report.nis) {
            let (lower, upper) = r.band(p);
            // The band at 95 % is the report's own.
            let (l95, u95) = r.band(0.95);
            assert!((l95 - r.lower).abs() < 1e-9 && (u95 - r.upper).abs() < 1e-9);
            println!(
                "{name}: {:<12} {:.3} in [{lower:.3}, {upper:.3}] (95 % band [{:.3}, {:.3}])",
                r.name, r.value, r.lower, r.upper
            );
            if !(lower..=upper).contains(&r.value) {
                missed.push(format!("{name} {}", r.name));
            }
        }
    }
    assert!(
        missed.is_empty(),
        "bands (each at {p:.4}, 95 % together) missed by {missed:?}"
    );
}

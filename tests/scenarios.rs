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
/// per sensor lie inside their 95 % chi-square bands, over 60 seeds.
#[test]
fn matched_scenarios_are_consistent() {
    for name in ["matched_ins", "matched_ahrs"] {
        let sc = builtin_scenarios()
            .into_iter()
            .find(|s| s.name == name)
            .expect("builtin");
        let report = host_sim::montecarlo::run(&sc, 60, 20.0, false).expect("monte carlo");
        for r in report.nees.iter().chain(&report.nis) {
            println!(
                "{name}: {:<12} {:.3} in [{:.3}, {:.3}]",
                r.name, r.value, r.lower, r.upper
            );
        }
        let missed: Vec<_> = report
            .nees
            .iter()
            .chain(&report.nis)
            .filter(|r| !r.holds())
            .map(|r| r.name.clone())
            .collect();
        assert!(missed.is_empty(), "{name}: bands missed by {missed:?}");
    }
}

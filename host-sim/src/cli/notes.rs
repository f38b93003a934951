//! Notes printed under a run's or a replay's summary where a consistency figure (a mean NIS,
//! an ANEES) needs its context to be read.

use host_sim::metrics::Metrics;
use host_sim::replay::ReplayConfig;

/// Any sensor of the run's update tallies called `name`.
fn has_sensor(m: &Metrics, name: &str) -> bool {
    m.updates_accepted.contains_key(name)
        || m.updates_rejected.contains_key(name)
        || m.updates_refused.contains_key(name)
}

/// The notes for the summary of `m` replayed with `cfg`; `simulated`: the data came from
/// host-sim's own simulator (`run`), whose sensors have exactly the noise of their files.
///
/// * Attitude navigator (it reports `gravity` updates) with the magnetometer fused as a
///   heading, a heading noise or floor above 0, and a mean magnetometer NIS below 1 (its
///   expectation, one degree of freedom): the heading model is set for real magnetometers. Its
///   per-block heading variance is at least `heading_noise²/block_s` (the noise density over the
///   block's length, beyond the magnetometer's white noise), and its heading σ is kept at or
///   above `heading_floor_deg`; where the magnetometer is cleaner than that, the σ stays above
///   the error and the NIS and the attitude ANEES read low: the navigator is conservative.
///   `matched_ahrs` is the scenario that checks consistency.
/// * No heading aid (no magnetometer, or `use_magnetometer = false`; no GNSS or camera): the
///   heading is observed by nothing, and
///   where the attitude ANEES is below 3, the heading's σ, grown from the start-up prior with
///   the gyro noise and bias, is why.
#[must_use]
pub fn consistency_notes(cfg: &ReplayConfig, m: &Metrics, simulated: bool) -> Vec<String> {
    let mut notes = Vec::new();
    let attitude_navigator = has_sensor(m, "gravity");
    let anees = m
        .nees_mean
        .get("attitude")
        .copied()
        .filter(|v| v.is_finite());
    let mag_nis = m.nis_mean.get("mag").copied().filter(|v| v.is_finite());
    let heading_model = cfg.heading_noise_deg > 0.0 || cfg.heading_floor_deg > 0.0;
    if attitude_navigator && !cfg.magnetometer_vector && heading_model {
        if let Some(nis) = mag_nis.filter(|&v| v < 1.0) {
            let per_block = if cfg.block_s > 0.0 {
                cfg.heading_noise_deg / cfg.block_s.sqrt()
            } else {
                f64::NAN
            };
            let anees_part = match anees {
                Some(a) if a < 3.0 => format!(" and the attitude ANEES ({a:.3}, expect 3)"),
                _ => String::new(),
            };
            let source = if simulated {
                "host-sim's simulated magnetometer has white noise only"
            } else {
                "this dataset's magnetometer is cleaner than that"
            };
            notes.push(format!(
                "the mean NIS mag ({nis:.3}, expect 1){anees_part} read low because the attitude navigator's heading model is set for real magnetometers \
(iron nearby, calibration errors): heading_noise_deg = {} °·√s beyond the white noise (σ ≥ {per_block:.1}° per {} s block) and heading_floor_deg = {}° keep the heading's σ above its error, and {source}; \
the reported σ is conservative, not wrong. The scenario that checks consistency is matched_ahrs (noise as the filter models it, heading noise and floor 0): \
host-sim montecarlo --scenario matched_ahrs --runs 20 --check",
                cfg.heading_noise_deg, cfg.block_s, cfg.heading_floor_deg
            ));
        }
    }
    if m.heading_reference == Some(false) {
        let anees_part = match anees {
            Some(a) if a < 3.0 => format!(
                "; its σ grows from the start-up prior with the gyro noise and bias and stays large, so the attitude ANEES ({a:.3}) reads below 3"
            ),
            _ => String::new(),
        };
        let aids = if cfg.use_magnetometer {
            "no magnetometer, GNSS or camera"
        } else {
            "use_magnetometer = false, no GNSS or camera"
        };
        notes.push(format!(
            "no heading aid ({aids}): the heading is observed by nothing{anees_part}; \
the yaw-aligned attitude RMSE is the figure to read"
        ));
    }
    notes
}

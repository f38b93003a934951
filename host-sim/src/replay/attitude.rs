//! The attitude-only replay (a dataset with an IMU and optionally a magnetometer, without GNSS
//! or camera): every sample goes to [`AttitudeNavigator`], exactly as a firmware main loop
//! would call it; this file only reads, writes and scores. With `use_magnetometer = false` the
//! dataset comes opened without its magnetometer (`ds.mag` is `None`, no `mag0` samples): the
//! navigator is configured without one and fuses the gyroscope and accelerometer only.

use super::output::{EstimateFiles, Partials};
use super::{filter_config, lit3, up3, ReplayConfig, ReplayError, SensorParameters};
use crate::baseline::{Madgwick, Mahony};
use crate::dataset::read::{Dataset, Event, EventStream};
use crate::metrics::{Estimate, Outcome, Scorer};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, AttitudeReport, Fusion, MagneticConfig, MagneticFusion,
    NavError,
};
use estimator_core::Real;
use nalgebra::{Matrix3, Vector3};
use std::path::Path;
use std::time::Instant;

/// The attitude navigator's configuration, as `host-sim replay` builds it: the IMU's noise
/// and the magnetometer's from `sensors`, everything else from `cfg`.
///
/// The navigator has a magnetometer when `with_magnetometer` (the data has one) and
/// `cfg.use_magnetometer`; it fuses its heading, or its whole field with
/// `cfg.magnetometer_vector`.
#[must_use]
pub fn navigator_config<T: Real>(
    sensors: &SensorParameters,
    cfg: &ReplayConfig,
    with_magnetometer: bool,
) -> AttitudeConfig<T> {
    let mut c = AttitudeConfig::new(filter_config(sensors, cfg));
    c.instantaneous_imu = cfg.instantaneous_imu;
    c.startup_s = T::lit(cfg.align_window_s);
    c.block_s = T::lit(cfg.block_s);
    c.velocity_sigma = T::lit(cfg.velocity_sigma);
    c.motion_memory_s = T::lit(cfg.motion_memory_s);
    c.rotation_only = cfg.rotation_only;
    c.accelerometer_bias_sigma = T::lit(cfg.accelerometer_bias_sigma);
    c.gyro_bias_sigma = T::lit(cfg.gyro_bias_sigma_dps.to_radians());
    c.gyro_scale_sigma = T::lit(cfg.gyro_scale_sigma);
    c.magnetometer = (with_magnetometer && cfg.use_magnetometer).then(|| {
        let reference = sensors.mag_reference.map(|r| lit3(&Vector3::from(r)));
        let mut mc = MagneticConfig::new(T::lit(sensors.mag_sigma), reference);
        mc.heading_noise = T::lit(cfg.heading_noise_deg.to_radians());
        mc.heading_floor = T::lit(cfg.heading_floor_deg.to_radians());
        mc.hard_iron = cfg.magnetometer_hard_iron;
        mc.delay_s = T::lit(cfg.magnetometer_delay_s);
        mc.delay_max_s = T::lit(cfg.magnetometer_delay_max_s);
        if cfg.magnetometer_vector {
            mc.fusion = MagneticFusion::Vector;
        }
        mc
    });
    c
}

fn estimate<T: Real>(nav: &AttitudeNavigator<T>, t_ns: u64) -> Option<Estimate> {
    let f = nav.filter()?;
    let s = f.state();
    let p = f.covariance();
    let block = |b: usize| Matrix3::from_fn(|i, j| p[(3 * b + i, 3 * b + j)].to_f64());
    Some(Estimate {
        t_ns,
        position: Vector3::zeros(),
        attitude: s.attitude.cast(),
        velocity: Vector3::zeros(),
        gyro_bias: up3(&s.gyro_bias),
        accel_bias: up3(&s.accel_bias),
        cov: [Some(block(0)), None, None, Some(block(1)), Some(block(2))],
        valid: None,
    })
}

fn score_fusion<T: Real>(
    scorer: &mut Scorer,
    name: &str,
    t_ns: u64,
    f: Option<Fusion<T>>,
    dof: usize,
) {
    if let Some(f) = f {
        let nis = f.nis.to_f64();
        let outcome = if f.accepted {
            Outcome::Accepted { nis, dof }
        } else {
            Outcome::Rejected { nis, dof }
        };
        scorer.measurement(name, t_ns, outcome);
    }
}

/// What the attitude navigator does after an IMU gap, for the data warnings.
const GAP_EFFECT: &str = "the attitude navigator starts again after it (its start-up, keeping the bias estimate and the magnetic reference)";

/// Scores the updates a call made, or a refused sample (noted in `events`, with its reason).
fn score_report<T: Real>(
    mag_dof: usize,
    scorer: &mut Scorer,
    events: &mut EventStream,
    r: &Result<AttitudeReport<T>, NavError>,
    sensor: &str,
    t_ns: u64,
) {
    match r {
        Ok(r) => {
            score_fusion(scorer, "gravity", t_ns, r.fused.gravity, 3);
            score_fusion(scorer, "mag", t_ns, r.fused.heading, mag_dof);
            score_fusion(scorer, "zero_rate", t_ns, r.fused.zero_rate, 3);
        }
        Err(e) => {
            scorer.measurement(sensor, t_ns, Outcome::Refused);
            events.refused(sensor, e);
        }
    }
}

/// Runs the navigator over the dataset and writes the outputs (see the module docs of
/// `replay`).
pub(super) fn replay_attitude<T: Real>(
    ds: &Dataset,
    dir: &Path,
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
    mut scorer: Scorer,
) -> Result<Scorer, ReplayError> {
    let sensors = SensorParameters::from_dataset(ds);
    let mut nav = AttitudeNavigator::<T>::new(navigator_config(&sensors, cfg, ds.mag.is_some()))
        .map_err(|e| ReplayError::Config(format!("navigator: {e}")))?;
    let mut partials = Partials::new(out);
    partials.clear_previous();
    let mut files = EstimateFiles::open(out, dir, ds.has_groundtruth)?;
    let mut baselines: Option<(Madgwick, Mahony)> = None;
    // The heading is one number; the whole field three.
    let mag_dof = if cfg.magnetometer_vector { 3 } else { 1 };
    let mut last_imu: Option<u64> = None;
    let mut events = ds.events()?.with_max_dt(cfg.max_dt);
    while let Some(ev) = events.next() {
        let started = Instant::now();
        match ev? {
            Event::Imu { t_ns, gyro, accel } => {
                let dt = last_imu.map_or(1.0 / ds.imu.rate_hz, |t| {
                    t_ns.saturating_sub(t) as f64 * 1e-9
                });
                last_imu = Some(t_ns);
                let r = nav.imu(t_ns, &lit3(&gyro), &lit3(&accel));
                score_report(mag_dof, &mut scorer, &mut events, &r, "imu", t_ns);
                scorer.filter_ns += started.elapsed().as_nanos();
                scorer.imu_samples += 1;
                let Some(e) = estimate(&nav, t_ns) else {
                    continue;
                };
                // The reference filters start where the navigator started, on the same samples.
                match (&mut baselines, &ds.mag) {
                    (None, Some(m)) => {
                        baselines = Some((
                            Madgwick::new(e.attitude, m.reference_field),
                            Mahony::new(e.attitude, m.reference_field),
                        ));
                    }
                    (Some((mw, mh)), _) => {
                        mw.imu(&gyro, &accel, dt);
                        mh.imu(&gyro, &accel, dt);
                    }
                    (None, None) => {}
                }
                files.add(&mut scorer, &e, baselines.as_ref())?;
            }
            Event::Mag { t_ns, field } => {
                if let Some((mw, mh)) = baselines.as_mut() {
                    mw.mag(&field);
                    mh.mag(&field);
                }
                let r = nav.magnetometer(t_ns, &lit3(&field));
                score_report(mag_dof, &mut scorer, &mut events, &r, "mag", t_ns);
                scorer.filter_ns += started.elapsed().as_nanos();
            }
            // Without GNSS and camera, the other sensors have nothing to aid.
            _ => {}
        }
    }
    let mut warnings = events.finish(GAP_EFFECT)?;
    warnings.extend(files.finish()?);
    scorer.add_data_warnings(dir, warnings);
    super::finish(out, cfg, title, ds, &scorer)?;
    partials.commit()?;
    Ok(scorer)
}

//! The GNSS replay (a dataset with an IMU and GNSS, optionally a magnetometer and a
//! barometer): every sample goes to [`InsNavigator`], exactly as a firmware main loop would
//! call it, each GNSS fix stamped with the time it was valid (its row's time minus the
//! receiver's `latency_s`); this file only reads, writes and scores. With `use_magnetometer =
//! false` the dataset comes opened without its magnetometer (`ds.mag` is `None`, no `mag0`
//! samples), so the navigator has none.

use super::attitude::navigator_config;
use super::output::{open_partial, EstimateFiles, Partials};
use super::{lit3, out_err, up3, ReplayConfig, ReplayError, SensorParameters};
use crate::baseline::{Madgwick, Mahony};
use crate::dataset::read::{Dataset, Event, EventStream};
use crate::faults::epochs;
use crate::metrics::{Estimate, Outcome, Scorer};
use estimator_core::nav::{
    AidStatus, Aiding, GnssFix, InsConfig, InsEvent, InsNavigator, InsReport, MagneticFusion,
    NavError, Travel, Validity,
};
use estimator_core::Real;
use nalgebra::{Matrix3, Vector3};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// The INS navigator of `host-sim replay`: its ring holds [`HORIZON_SAMPLES`] IMU intervals
/// (with room) and 64 queued measurements.
pub type ReplayInsNavigator<T> = InsNavigator<T, 256, 64>;

/// The most IMU samples `cfg.horizon_s` may span in [`ReplayInsNavigator`]'s ring (0.3 s at
/// 200 Hz is 60).
pub const HORIZON_SAMPLES: f64 = 250.0;

/// The INS navigator's configuration, as `host-sim replay` builds it on a GNSS dataset: the
/// attitude navigator's ([`navigator_config`], with the magnetometer's whole field fused),
/// the GNSS lever arm and the barometer's 1σ from `sensors`, the horizon and how the vehicle
/// travels from `cfg`.
///
/// The navigator has a magnetometer when `with_magnetometer` and `cfg.use_magnetometer`, a
/// barometer when `with_barometer`.
#[must_use]
pub fn ins_config<T: Real>(
    sensors: &SensorParameters,
    cfg: &ReplayConfig,
    with_magnetometer: bool,
    with_barometer: bool,
) -> InsConfig<T> {
    let mut attitude = navigator_config::<T>(sensors, cfg, with_magnetometer);
    // The INS fuses the magnetometer's whole field: the GNSS velocity, not the magnetometer,
    // holds the tilt, and the gate guards the heading.
    if let Some(m) = attitude.magnetometer.as_mut() {
        m.fusion = MagneticFusion::Vector;
    }
    let mut c = InsConfig::new(attitude);
    c.horizon_s = T::lit(cfg.horizon_s);
    c.travel = if cfg.lateral_velocity_sigma > 0.0 {
        Travel::Forward {
            lateral_sigma: T::lit(cfg.lateral_velocity_sigma),
        }
    } else if cfg.travel == "sideways" {
        Travel::Sideways
    } else {
        Travel::Detect
    };
    c.gnss_lever_arm = lit3(&Vector3::from(sensors.gnss_lever_arm));
    c.barometer_sigma = with_barometer.then(|| T::lit(sensors.baro_sigma));
    c
}

fn estimate<T: Real, const H: usize, const Q: usize>(
    nav: &InsNavigator<T, H, Q>,
) -> Option<Estimate> {
    let e = nav.estimate()?;
    let v = nav.report().validity;
    let block =
        |b: usize| -> Option<Matrix3<f64>> { e.covariance.get(b).map(|m| m.map(|x| x.to_f64())) };
    Some(Estimate {
        t_ns: e.t_ns,
        position: up3(&e.state.position),
        attitude: e.state.attitude.cast(),
        velocity: up3(&e.state.velocity),
        gyro_bias: up3(&e.state.gyro_bias),
        accel_bias: up3(&e.state.accel_bias),
        cov: [block(0), block(1), block(2), block(3), block(4)],
        valid: Some([
            v.tilt.is_valid() && v.heading.is_valid(),
            v.velocity.is_valid(),
            v.position.is_valid(),
            v.gyro_bias.is_valid(),
            v.accel_bias.is_valid(),
        ]),
    })
}

/// The header of `validity.csv`: one row per IMU sample, what the navigator's report said.
const VALIDITY_HEADER: &str =
    "t_ns,tilt,heading,velocity,position,gyro_bias,accel_bias,gnss,magnetometer,barometer,imu_fault,event";

fn event_word(e: Option<InsEvent>) -> &'static str {
    match e {
        None => "",
        Some(InsEvent::Started) => "started",
        Some(InsEvent::Realigned) => "realigned",
        Some(InsEvent::PositionReset) => "position_reset",
        Some(InsEvent::HeadingFromGnss) => "heading_from_gnss",
        Some(InsEvent::ImuFault) => "imu_fault",
    }
}

/// One row of `validity.csv` (its words are the fault bench's reader's, `faults::epochs`).
fn write_validity<T: Real>(f: &mut impl Write, r: &InsReport<T>) -> std::io::Result<()> {
    let v = &r.validity;
    let word = |v: Validity| epochs::Validity::from(v).word();
    let status = |s: AidStatus| epochs::AidStatus::from(s).word();
    writeln!(
        f,
        "{},{},{},{},{},{},{},{},{},{},{},{}",
        r.t_ns,
        word(v.tilt),
        word(v.heading),
        word(v.velocity),
        word(v.position),
        word(v.gyro_bias),
        word(v.accel_bias),
        status(r.gnss),
        status(r.magnetometer),
        status(r.barometer),
        u8::from(r.imu_fault),
        event_word(r.event),
    )
}

/// What the INS navigator does after an IMU gap, for the data warnings.
const GAP_EFFECT: &str = "the INS navigator starts its alignment again after it (`realigned` in validity.csv) and has no estimate until it has started again at a GNSS fix";

/// Scores the update a call made, or a refused sample (noted in `events`, with its reason).
fn score<T: Real>(
    scorer: &mut Scorer,
    events: &mut EventStream,
    r: &Result<InsReport<T>, NavError>,
    sensor: &str,
    t_ns: u64,
) {
    match r {
        Ok(report) => {
            if let Some(f) = report.fused {
                let (name, dof) = match f.aid {
                    Aiding::GnssPosition => ("gnss_position", 3),
                    Aiding::GnssVelocity => ("gnss_velocity", 3),
                    Aiding::Magnetometer => ("mag", 3),
                    Aiding::Barometer => ("baro", 1),
                };
                let nis = f.nis.to_f64();
                let outcome = if f.accepted {
                    Outcome::Accepted { nis, dof }
                } else {
                    Outcome::Rejected { nis, dof }
                };
                scorer.measurement(name, t_ns, outcome);
            }
        }
        Err(e) => {
            scorer.measurement(sensor, t_ns, Outcome::Refused);
            events.refused(sensor, e);
        }
    }
}

/// Runs the navigator over the dataset and writes the outputs (see the module docs of
/// `replay`).
pub(super) fn replay_ins<T: Real>(
    ds: &Dataset,
    dir: &Path,
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
    mut scorer: Scorer,
) -> Result<Scorer, ReplayError> {
    let sensors = SensorParameters::from_dataset(ds);
    let config = ins_config(&sensors, cfg, ds.mag.is_some(), ds.baro.is_some());
    // A ring for the horizon at the IMU's rate, with room: 0.3 s at 200 Hz is 60 intervals.
    let mut nav = ReplayInsNavigator::<T>::new(config)
        .map_err(|e| ReplayError::Config(format!("navigator: {e}")))?;
    if cfg.horizon_s * ds.imu.rate_hz > HORIZON_SAMPLES {
        return Err(ReplayError::Config(format!(
            "horizon_s = {} holds {:.0} IMU samples at {} Hz; at most {HORIZON_SAMPLES}",
            cfg.horizon_s,
            cfg.horizon_s * ds.imu.rate_hz,
            ds.imu.rate_hz
        )));
    }
    let latency_ns = sensors.gnss_latency_ns(cfg);
    let mut partials = Partials::new(out);
    partials.clear_previous();
    let mut files = EstimateFiles::open(out, dir, ds.has_groundtruth)?;
    let (mut validity, validity_path) = open_partial(out, "validity.csv")?;
    writeln!(validity, "{VALIDITY_HEADER}").map_err(out_err(&validity_path))?;
    let mut baselines: Option<(Madgwick, Mahony)> = None;
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
                score(&mut scorer, &mut events, &r, "imu", t_ns);
                if let Ok(report) = &r {
                    write_validity(&mut validity, report).map_err(out_err(&validity_path))?;
                }
                scorer.filter_ns += started.elapsed().as_nanos();
                scorer.imu_samples += 1;
                let Some(e) = estimate(&nav) else {
                    continue;
                };
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
                continue;
            }
            Event::Mag { t_ns, field } => {
                if let Some((mw, mh)) = baselines.as_mut() {
                    mw.mag(&field);
                    mh.mag(&field);
                }
                let r = nav.magnetometer(t_ns, &lit3(&field));
                score(&mut scorer, &mut events, &r, "mag", t_ns);
            }
            Event::Gnss {
                t_ns,
                position,
                velocity,
                sigma_p,
                sigma_p_up,
                sigma_v,
            } => {
                let fix = GnssFix::new(
                    lit3(&position),
                    velocity.as_ref().map(lit3),
                    T::lit(sigma_p),
                    T::lit(sigma_v),
                )
                .with_vertical_sigma(T::lit(sigma_p_up));
                let r = nav.gnss(t_ns.saturating_sub(latency_ns), &fix);
                score(&mut scorer, &mut events, &r, "gnss_position", t_ns);
            }
            Event::Baro { t_ns, altitude } => {
                let r = nav.barometer(t_ns, T::lit(altitude));
                score(&mut scorer, &mut events, &r, "baro", t_ns);
            }
            // The camera is the other replay's.
            Event::Camera { .. } => {}
        }
        scorer.filter_ns += started.elapsed().as_nanos();
    }
    let mut warnings = events.finish(GAP_EFFECT)?;
    warnings.extend(files.finish()?);
    scorer.add_data_warnings(dir, warnings);
    validity.flush().map_err(out_err(&validity_path))?;
    if nav.estimate().is_none() {
        return Err(ReplayError::Start(format!(
            "the INS never started: no GNSS fix came due with the alignment ready ({} fixes unused)",
            nav.counters().unused
        )));
    }
    super::finish(out, cfg, title, ds, &scorer)?;
    partials.commit()?;
    Ok(scorer)
}

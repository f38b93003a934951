//! `host-sim replay`: runs a navigator over a dataset folder and writes its outputs:
//!
//! | file | content |
//! |---|---|
//! | `estimate.tum` | TUM trajectory, `timestamp[s] tx ty tz qx qy qz qw` |
//! | `estimate.csv` | the full state and the 1-σ of each error-state component, with a header |
//! | `groundtruth.tum` | the truth in TUM format, where the dataset has it |
//! | `metrics.json` | where the truth exists: RMSEs, NEES, NIS and update counts per sensor, time per IMU sample |
//! | `validity.csv` | GNSS datasets: after every IMU sample, the INS navigator's validity of each quantity (or why not), each aid's status, IMU faults and events |
//! | `*.png` | trajectory, per-axis errors inside their ±3σ bands, biases, NIS |
//!
//! The navigator configures itself from the dataset's `sensor.yaml` files and starts itself from
//! the data, at rest or moving; it never reads the ground truth to start or to run, the truth is
//! only scored against.
//!
//! What the data has wrong that the run survives (a last line cut short, IMU and aiding gaps,
//! sensors starting late or stopping early, refused samples with the navigator's reason) is
//! collected as [`crate::dataset::check::DataWarning`]s into `metrics.json` (`data_warnings`),
//! the files named from the dataset folder as the caller gave it. With GNSS, every sample goes to [`estimator_core::nav::InsNavigator`]
//! (`ins`), each fix stamped with the time it was valid; with an IMU and a magnetometer alone, to
//! [`estimator_core::nav::AttitudeNavigator`] (`attitude`). A camera dataset without GNSS runs the
//! 15-state filter here, started from a window at rest and a PnP pose of the first frame.

use crate::baseline::{Madgwick, Mahony};
use crate::dataset::read::{CameraParams, Dataset, Event};
use crate::dataset::DatasetError;
use crate::metrics::trajectory::Delta;
use crate::metrics::{Estimate, Metrics, Outcome, Scorer};
use estimator_core::eskf::{
    align_at_rest, BaroAltitude, EskfError, FilterConfig, ImuNoise, ImuSample, InitialSigmas, Ins,
    Magnetometer, MagnetometerWindow, UpdateOptions, UpdateOutcome,
};
use estimator_core::eskf::{Alignment, CameraLandmark, PinholeIntrinsics};
use estimator_core::gn::{solve_pnp, Loss, PinholeCamera, PnpOptions};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{Matrix3, SMatrix, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod attitude;
mod ins;
mod output;

pub use attitude::navigator_config;
pub use ins::{ins_config, ReplayInsNavigator, HORIZON_SAMPLES};
pub use output::TruthCursor;
use output::{EstimateFiles, Partials};

/// The sensor parameters a navigator is configured from besides the [`ReplayConfig`]: what
/// `host-sim replay` reads from a dataset's `sensor.yaml` files ([`Self::from_dataset`]), or
/// what a caller without a dataset gives (the Python package's keyword arguments of the same
/// names).
///
/// A sensor's values are used only where the navigator has that sensor (the flags of
/// [`navigator_config`] and [`ins_config`]). The [`Default`]: a consumer MEMS IMU
/// ([`ImuNoise::mems`]), a magnetometer of 0.4 µT per axis (host-sim's simulated one) without
/// a known reference field, the GNSS antenna at the IMU and its fixes stamped without latency,
/// a barometer of 0.5 m.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorParameters {
    /// The IMU's white noise densities and bias random walks (`imu0/sensor.yaml`): gyroscope
    /// rad/s/√Hz and rad/s²/√Hz, accelerometer m/s²/√Hz and m/s³/√Hz.
    pub imu_noise: ImuNoise<f64>,
    /// The magnetometer's white noise per sample and axis, µT (`mag0/sensor.yaml`'s `sigma`).
    pub mag_sigma: f64,
    /// The magnetic field in the world frame (ENU), µT (`mag0/sensor.yaml`'s reference
    /// field); `None`: not known, the navigator learns it from its first samples, which then
    /// define north.
    pub mag_reference: Option<[f64; 3]>,
    /// The GNSS antenna in the body frame, m (`gnss0/sensor.yaml`'s lever arm).
    pub gnss_lever_arm: [f64; 3],
    /// How long before its row's time each GNSS fix was valid, s (`gnss0/sensor.yaml`'s
    /// `latency_s`).
    pub gnss_latency_s: f64,
    /// The barometric altitude's white noise per sample, 1σ, m (`baro0/sensor.yaml`'s
    /// `sigma`).
    pub baro_sigma: f64,
}

impl Default for SensorParameters {
    fn default() -> Self {
        Self {
            imu_noise: ImuNoise::mems(),
            mag_sigma: 0.4,
            mag_reference: None,
            gnss_lever_arm: [0.0; 3],
            gnss_latency_s: 0.0,
            baro_sigma: 0.5,
        }
    }
}

impl SensorParameters {
    /// The parameters of the dataset's sensors, as `host-sim replay` configures its navigator
    /// from them; those of a sensor the dataset lacks (or was opened without) keep their
    /// [`Default`].
    #[must_use]
    pub fn from_dataset(ds: &Dataset) -> Self {
        let mut s = Self {
            imu_noise: ImuNoise {
                gyroscope_noise_density: ds.imu.gyroscope_noise_density,
                gyroscope_random_walk: ds.imu.gyroscope_random_walk,
                accelerometer_noise_density: ds.imu.accelerometer_noise_density,
                accelerometer_random_walk: ds.imu.accelerometer_random_walk,
            },
            ..Self::default()
        };
        if let Some(m) = &ds.mag {
            s.mag_sigma = m.sigma;
            s.mag_reference = Some(m.reference_field.into());
        }
        if let Some(g) = &ds.gnss {
            s.gnss_lever_arm = g.lever_arm.into();
            s.gnss_latency_s = g.latency_s;
        }
        if let Some(b) = &ds.baro {
            s.baro_sigma = b.sigma;
        }
        s
    }

    /// How far back each GNSS fix is stamped from its row's time, ns: `gnss_latency_s`
    /// rounded to the nanosecond, 0 with `cfg.ignore_gnss_latency`.
    #[must_use]
    pub fn gnss_latency_ns(&self, cfg: &ReplayConfig) -> u64 {
        if cfg.ignore_gnss_latency {
            0
        } else {
            (self.gnss_latency_s * 1e9).round() as u64
        }
    }
}

/// The 15-state filter's configuration: the IMU's noise from `sensors`, gravity and the
/// longest IMU interval from `cfg`.
fn filter_config<T: Real>(sensors: &SensorParameters, cfg: &ReplayConfig) -> FilterConfig<T> {
    let n = &sensors.imu_noise;
    FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: T::lit(n.gyroscope_noise_density),
            gyroscope_random_walk: T::lit(n.gyroscope_random_walk),
            accelerometer_noise_density: T::lit(n.accelerometer_noise_density),
            accelerometer_random_walk: T::lit(n.accelerometer_random_walk),
        },
        gravity: lit3(&Vector3::from(cfg.gravity)),
        max_dt: T::lit(cfg.max_dt),
    }
}

/// Replay options (a TOML file given with `--config`; every field optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct ReplayConfig {
    /// `"f32"` (the firmware's precision) or `"f64"`.
    pub precision: String,
    /// Length of the start-up window, s: averaged for the first attitude (at rest or moving).
    pub align_window_s: f64,
    /// Gravity, world frame, m/s².
    pub gravity: [f64; 3],
    /// Largest accepted IMU interval, s; a longer one is a gap (the attitude navigator starts
    /// again).
    pub max_dt: f64,
    /// Attitude navigator: length of an aiding block, s.
    pub block_s: f64,
    /// Attitude navigator: the smallest spread (1σ per axis) of a moving body's velocity, m/s.
    pub velocity_sigma: f64,
    /// Fuse the magnetometer where the dataset has one (`mag0/`). `false`: `mag0/` is not read
    /// at all (neither its `sensor.yaml` nor its samples), as if absent, by every navigator
    /// (attitude, INS, the camera replay): a 6-axis run on the gyroscope and the
    /// accelerometer, whose heading nothing observes (score it by the yaw-aligned attitude RMSE
    /// or BROAD's inclination). `host-sim bench` replays BROAD trials so a second time.
    pub use_magnetometer: bool,
    /// Attitude navigator: fuse the magnetometer's whole field (`true`: a calibrated
    /// magnetometer in a clean field; it then also measures the tilt) rather than its heading.
    pub magnetometer_vector: bool,
    /// Attitude navigator: learn the magnetometer's hard iron (a constant offset in the body
    /// frame: a magnet or a battery on the board) while the body turns, and take it off every
    /// sample.
    pub magnetometer_hard_iron: bool,
    /// Attitude navigator: the magnetometer's delay behind the gyro known beforehand, s (a
    /// sample stamped `t` is the field at `t − delay`); where it is learned, where it starts.
    pub magnetometer_delay_s: f64,
    /// Attitude navigator: the largest magnetometer delay learned while the body turns about
    /// the vertical, s; 0: not learned (it stays `magnetometer_delay_s`).
    pub magnetometer_delay_max_s: f64,
    /// Attitude navigator: the body only rotates in place (no linear acceleration).
    pub rotation_only: bool,
    /// Attitude navigator: memory of the velocity spread, s.
    pub motion_memory_s: f64,
    /// Attitude navigator: 1σ of the accelerometer bias per axis, m/s² (the tilt floor is
    /// this over g; 0 where the accelerometer has no bias).
    pub accelerometer_bias_sigma: f64,
    /// Attitude navigator: 1σ of the gyro's scale-factor and cross-axis errors (fraction).
    pub gyro_scale_sigma: f64,
    /// Attitude navigator: 1σ of the gyro bias at switch-on, °/s.
    pub gyro_bias_sigma_dps: f64,
    /// Attitude navigator: heading noise density beyond the magnetometer's white noise, °·√s.
    pub heading_noise_deg: f64,
    /// Attitude navigator: lower bound on the heading's 1σ with a magnetometer, °.
    pub heading_floor_deg: f64,
    /// The relative pose error's delta (evo's `--delta`), in `rpe_delta_unit`.
    pub rpe_delta: f64,
    /// `"s"` (seconds) or `"m"` (metres travelled; evo's `--delta_unit`).
    pub rpe_delta_unit: String,
    /// The IMU samples are instantaneous values (integrate with the trapezoidal rule) rather
    /// than means over the period ending at their timestamp.
    pub instantaneous_imu: bool,
    /// INS navigator: how far in the past a measurement may be stamped, s (the filter runs
    /// this far behind the newest IMU sample).
    pub horizon_s: f64,
    /// INS navigator: the vehicle does not move sideways (a car, a rover): 1σ of its lateral
    /// body velocity, m/s, with the body's x axis along its track; 0: not declared (`travel`
    /// says). Without a magnetometer, this is what finds the heading of a slow ground vehicle
    /// from its GNSS track.
    pub lateral_velocity_sigma: f64,
    /// INS navigator, when `lateral_velocity_sigma` is 0: `"detect"` (learn from the GNSS
    /// track whether the vehicle travels along its body x axis, and its lateral 1σ) or
    /// `"sideways"` (it may move sideways: a multirotor, a hand-held device).
    pub travel: String,
    /// Take every GNSS fix as valid when its row is stamped, ignoring `latency_s` (to see
    /// what the latency costs).
    pub ignore_gnss_latency: bool,
    /// Write the plots.
    pub plots: bool,
}

impl ReplayConfig {
    /// `Ok` when every value is in its domain.
    ///
    /// # Errors
    /// The first value out of its domain, named.
    pub fn validate(&self) -> Result<(), String> {
        if self.rpe_delta_unit != "s" && self.rpe_delta_unit != "m" {
            return Err(format!(
                "rpe_delta_unit = \"{}\": must be \"s\" or \"m\"",
                self.rpe_delta_unit
            ));
        }
        if !(self.rpe_delta.is_finite() && self.rpe_delta > 0.0) {
            return Err(format!(
                "rpe_delta = {}: must be a positive number",
                self.rpe_delta
            ));
        }
        if self.precision != "f32" && self.precision != "f64" {
            return Err(format!(
                "precision = \"{}\": must be \"f32\" or \"f64\"",
                self.precision
            ));
        }
        let positive = [
            ("align_window_s", self.align_window_s),
            ("max_dt", self.max_dt),
            ("block_s", self.block_s),
            ("velocity_sigma", self.velocity_sigma),
            ("motion_memory_s", self.motion_memory_s),
        ];
        for (name, x) in positive {
            if !(x.is_finite() && x > 0.0) {
                return Err(format!("{name} = {x}: must be a positive number"));
            }
        }
        if !(self.accelerometer_bias_sigma.is_finite() && self.accelerometer_bias_sigma > 0.0) {
            return Err(format!(
                "accelerometer_bias_sigma = {}: must be a positive number (the bias is a state)",
                self.accelerometer_bias_sigma
            ));
        }
        for (name, x) in [
            ("gyro_bias_sigma_dps", self.gyro_bias_sigma_dps),
            ("gyro_scale_sigma", self.gyro_scale_sigma),
            ("heading_noise_deg", self.heading_noise_deg),
            ("heading_floor_deg", self.heading_floor_deg),
            ("magnetometer_delay_s", self.magnetometer_delay_s),
            ("magnetometer_delay_max_s", self.magnetometer_delay_max_s),
        ] {
            if !(x.is_finite() && x >= 0.0) {
                return Err(format!("{name} = {x}: must be 0 or more"));
            }
        }
        for (name, x) in [
            ("magnetometer_delay_s", self.magnetometer_delay_s),
            ("magnetometer_delay_max_s", self.magnetometer_delay_max_s),
        ] {
            if x > 0.25 {
                return Err(format!("{name} = {x}: must be at most 0.25 s"));
            }
        }
        if self.magnetometer_delay_max_s > 0.0
            && self.magnetometer_delay_s > self.magnetometer_delay_max_s
        {
            return Err(format!(
                "magnetometer_delay_s = {}: must not exceed magnetometer_delay_max_s = {}",
                self.magnetometer_delay_s, self.magnetometer_delay_max_s
            ));
        }
        for (name, x) in [
            ("align_window_s", self.align_window_s),
            ("block_s", self.block_s),
            ("max_dt", self.max_dt),
        ] {
            if x >= 4.0 {
                return Err(format!("{name} = {x}: must be below 4 s"));
            }
        }
        if self.travel != "detect" && self.travel != "sideways" {
            return Err(format!(
                "travel = \"{}\": must be \"detect\" or \"sideways\"",
                self.travel
            ));
        }
        if self.travel == "sideways" && self.lateral_velocity_sigma > 0.0 {
            return Err(format!(
                "travel = \"sideways\" with lateral_velocity_sigma = {}: a vehicle that moves sideways has no lateral sigma",
                self.lateral_velocity_sigma
            ));
        }
        if !(self.lateral_velocity_sigma.is_finite() && self.lateral_velocity_sigma >= 0.0) {
            return Err(format!(
                "lateral_velocity_sigma = {}: must be a finite value, 0 or more",
                self.lateral_velocity_sigma
            ));
        }
        if !(self.horizon_s.is_finite() && (0.0..=1.0).contains(&self.horizon_s)) {
            return Err(format!(
                "horizon_s = {}: must be between 0 and 1 s",
                self.horizon_s
            ));
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err("gravity: must be finite".into());
        }
        Ok(())
    }
}

impl ReplayConfig {
    /// The defaults for data from host-sim's own simulator, whose IMU samples are the motion's
    /// values at their instant (`instantaneous_imu`; a MEMS IMU's are means over the interval)
    /// and whose magnetometer is sampled with the IMU unless its model says otherwise (no
    /// delay learned, `magnetometer_delay_max_s = 0`: with a magnetometer of white noise only,
    /// `heading_noise_deg = 0`, the learned delay wanders by a few milliseconds, enough to take
    /// the heading's NIS out of its band); every sensor of the dataset fused
    /// (`use_magnetometer`), as by default.
    #[must_use]
    pub fn simulated() -> Self {
        Self {
            instantaneous_imu: true,
            magnetometer_delay_max_s: 0.0,
            ..Self::default()
        }
    }
}

impl Default for ReplayConfig {
    fn default() -> Self {
        Self {
            precision: "f32".into(),
            align_window_s: 1.0,
            gravity: [0.0, 0.0, -9.81],
            max_dt: 0.1,
            block_s: 0.25,
            velocity_sigma: 0.3,
            motion_memory_s: 5.0,
            rotation_only: false,
            rpe_delta: 1.0,
            rpe_delta_unit: "s".into(),
            use_magnetometer: true,
            magnetometer_vector: false,
            magnetometer_hard_iron: true,
            magnetometer_delay_s: 0.0,
            magnetometer_delay_max_s: 0.05,
            accelerometer_bias_sigma: 0.1,
            gyro_bias_sigma_dps: 0.5,
            gyro_scale_sigma: 0.005,
            heading_noise_deg: 8.0,
            heading_floor_deg: 1.0,
            instantaneous_imu: false,
            horizon_s: 0.3,
            lateral_velocity_sigma: 0.0,
            travel: "detect".into(),
            ignore_gnss_latency: false,
            plots: true,
        }
    }
}

/// Errors of a replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The dataset is malformed.
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// An output could not be written.
    #[error("{}: {message}", path.display())]
    Output {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The filter could not be started.
    #[error("cannot start the filter: {0}")]
    Start(String),
    /// Bad configuration.
    #[error("configuration: {0}")]
    Config(String),
}

fn out_err(path: &Path) -> impl Fn(std::io::Error) -> ReplayError + '_ {
    move |e| ReplayError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The 15-state filter of the GNSS and camera replays.
#[derive(Clone, Debug)]
struct Filter<T: Real>(Box<Ins<T>>);

fn lit3<T: Real>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(T::lit)
}

fn up3<T: Real>(v: &Vector3<T>) -> Vector3<f64> {
    v.map(|x| x.to_f64())
}

fn block<T: Real, const N: usize>(p: &SMatrix<T, N, N>, b: usize) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| p[(3 * b + i, 3 * b + j)].to_f64())
}

impl<T: Real> Filter<T> {
    fn estimate(&self, t_ns: u64) -> Estimate {
        let s = self.0.state();
        let p = self.0.covariance();
        Estimate {
            t_ns,
            position: up3(&s.position),
            attitude: s.attitude.cast(),
            velocity: up3(&s.velocity),
            gyro_bias: up3(&s.gyro_bias),
            accel_bias: up3(&s.accel_bias),
            cov: [
                Some(block(p, 0)),
                Some(block(p, 1)),
                Some(block(p, 2)),
                Some(block(p, 3)),
                Some(block(p, 4)),
            ],
            valid: None,
        }
    }

    fn predict(
        &mut self,
        gyro: &Vector3<f64>,
        accel: &Vector3<f64>,
        dt: f64,
    ) -> Result<(), EskfError> {
        let imu = ImuSample {
            gyro: lit3(gyro),
            accel: lit3(accel),
            dt: T::lit(dt),
        };
        self.0.predict(&imu)
    }
}

fn outcome<T: Real>(r: Result<UpdateOutcome<T>, EskfError>, dof: usize) -> Outcome {
    match r {
        Ok(UpdateOutcome::Accepted { nis, .. }) => Outcome::Accepted {
            nis: nis.to_f64(),
            dof,
        },
        Ok(UpdateOutcome::Rejected { nis, .. }) => Outcome::Rejected {
            nis: nis.to_f64(),
            dof,
        },
        Err(_) => Outcome::Refused,
    }
}

/// Runs the replay in the configured precision.
pub fn replay(
    dataset_dir: &Path,
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
) -> Result<Metrics, ReplayError> {
    replay_scored(dataset_dir, out, cfg, title, Scorer::default()).map(|s| s.metrics())
}

/// As [`replay`], starting from (and returning) a given scorer, for callers that need more than
/// the summary (Monte Carlo keeps the per-sample NEES).
///
/// A folder holding `mav0/` (a EuRoC sequence) is read as its `mav0/` ([`crate::dataset::locate`]).
pub fn replay_scored(
    dataset_dir: &Path,
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
    scorer: Scorer,
) -> Result<Scorer, ReplayError> {
    let dataset_dir = crate::dataset::locate(dataset_dir).dir;
    let dataset_dir = dataset_dir.as_path();
    let mut scorer = scorer.for_dataset(dataset_dir)?;
    if scorer.rpe_delta.is_none() {
        scorer.rpe_delta = Some(if cfg.rpe_delta_unit == "m" {
            Delta::Metres(cfg.rpe_delta)
        } else {
            Delta::Seconds(cfg.rpe_delta)
        });
    }
    match cfg.precision.as_str() {
        "f32" => replay_in::<f32>(dataset_dir, out, cfg, title, scorer),
        "f64" => replay_in::<f64>(dataset_dir, out, cfg, title, scorer),
        other => Err(ReplayError::Config(format!(
            "precision '{other}' (use f32 or f64)"
        ))),
    }
}

/// What the camera replay's filter does after an IMU gap, for the data warnings.
const GAP_EFFECT: &str = "the filter refuses the step over it (an `imu` refusal) and goes on from its state before the gap";

fn replay_in<T: Real>(
    dir: &Path,
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
    mut scorer: Scorer,
) -> Result<Scorer, ReplayError> {
    let ds = Dataset::open_with_magnetometer(dir, cfg.use_magnetometer)?;
    for note in &ds.notes {
        eprintln!("note: {note}");
    }
    scorer.note_run(&ds, &cfg.precision);
    std::fs::create_dir_all(out).map_err(out_err(out))?;
    if ds.gnss.is_none() && ds.camera.is_none() {
        return attitude::replay_attitude::<T>(&ds, dir, out, cfg, title, scorer);
    }
    if ds.gnss.is_some() {
        return ins::replay_ins::<T>(&ds, dir, out, cfg, title, scorer);
    }
    let gravity = Vector3::from(cfg.gravity);
    let config = filter_config::<T>(&SensorParameters::from_dataset(&ds), cfg);
    let mut events = ds.events()?.with_max_dt(cfg.max_dt);

    // --- Start-up: a window at rest, then the first camera frame, solved for the pose. ---
    let window_ns = (cfg.align_window_s * 1e9) as u64;
    let (mut accel, mut gyro, mut mags) = (Vec::new(), Vec::new(), Vec::new());
    let mut t_first: Option<u64> = None;
    let mut last_imu: Option<u64> = None;
    let mut first_frame: Option<Vec<(u64, Vector2<f64>)>> = None;
    // The event that ends the start-up, left for the run.
    let mut carried: Option<Event> = None;
    for ev in events.by_ref() {
        let ev = ev?;
        let t0 = *t_first.get_or_insert(ev.t_ns());
        let in_window = ev.t_ns() < t0 + window_ns;
        let need_fix = first_frame.is_none();
        if !in_window && !need_fix {
            carried = Some(ev);
            break;
        }
        match &ev {
            Event::Imu {
                t_ns,
                gyro: g,
                accel: a,
            } if in_window => {
                accel.push(lit3::<T>(a));
                gyro.push(lit3::<T>(g));
                last_imu = Some(*t_ns);
            }
            Event::Imu { t_ns, .. } => last_imu = Some(*t_ns),
            Event::Mag { field, .. } if in_window => mags.push(lit3::<T>(field)),
            Event::Camera { observations, .. } if !in_window && observations.len() >= 6 => {
                first_frame = Some(observations.clone());
            }
            _ => {}
        }
        if !in_window && first_frame.is_some() {
            break;
        }
    }
    let mag_window = ds.mag.as_ref().map(|m| MagnetometerWindow {
        samples: &mags,
        reference: lit3::<T>(&m.reference_field),
    });
    let alignment = align_at_rest(
        &accel,
        &gyro,
        &lit3(&gravity),
        mag_window.as_ref().filter(|w| !w.samples.is_empty()),
        T::lit(0.5),
    )
    .map_err(|e| {
        ReplayError::Start(format!(
            "alignment over the first {} s: {e}",
            cfg.align_window_s
        ))
    })?;
    let sigmas = InitialSigmas::<T>::default();
    let mut filter = match (first_frame, &ds.camera) {
        (Some(frame), Some(cam)) => {
            let world_from_body = pnp_pose(&frame, cam, &alignment.attitude.cast())?;
            let start = Alignment {
                attitude: world_from_body.rotation().cast(),
                ..alignment
            };
            let ins = Ins::from_alignment(
                &start,
                lit3(&world_from_body.translation()),
                &InitialSigmas {
                    position: T::lit(0.2),
                    ..sigmas
                },
                config,
            )
            .map_err(|e| ReplayError::Start(e.to_string()))?;
            Filter(Box::new(ins))
        }
        _ => {
            return Err(ReplayError::Start(
                "no camera frame with 6 known landmarks to take the position from".into(),
            ))
        }
    };

    // Reference filters on the same data, from the same start (where a magnetometer exists).
    let mut baselines = ds.mag.as_ref().map(|m| {
        let start = filter.estimate(0).attitude;
        (
            Madgwick::new(start, m.reference_field),
            Mahony::new(start, m.reference_field),
        )
    });

    // --- Outputs: written as `*.partial`, renamed only when the whole run succeeded. ---
    let mut partials = Partials::new(out);
    partials.clear_previous();
    let mut files = EstimateFiles::open(out, dir, ds.has_groundtruth)?;

    // --- The run. ---
    let ekf = UpdateOptions::<T>::default();
    // Projections are strongly nonlinear near the camera: re-linearize (iterated update).
    let camera_options = UpdateOptions::<T>::iterated(ekf.gate, 3, T::lit(1e-6));
    let mut last_sample: Option<(Vector3<f64>, Vector3<f64>)> = None;
    while let Some(ev) = carried.take().map(Ok).or_else(|| events.next()) {
        let ev = ev?;
        let started = Instant::now();
        match ev {
            Event::Imu { t_ns, gyro, accel } => {
                let dt = last_imu.map_or(1.0 / ds.imu.rate_hz, |t| {
                    (t_ns.saturating_sub(t)) as f64 * 1e-9
                });
                last_imu = Some(t_ns);
                // Instantaneous samples (the simulator's) are integrated over the interval with
                // the average of its two ends (trapezoidal rule, second order); samples that
                // are already means over their period are used as they are.
                let (g_mid, a_mid) = match (cfg.instantaneous_imu, last_sample) {
                    (true, Some((g0, a0))) => ((g0 + gyro) * 0.5, (a0 + accel) * 0.5),
                    _ => (gyro, accel),
                };
                last_sample = Some((gyro, accel));
                if let Some((mw, mh)) = baselines.as_mut() {
                    mw.imu(&g_mid, &a_mid, dt);
                    mh.imu(&g_mid, &a_mid, dt);
                }
                if let Err(e) = filter.predict(&g_mid, &a_mid, dt) {
                    scorer.measurement("imu", t_ns, Outcome::Refused);
                    events.refused("imu", &e);
                }
                scorer.filter_ns += started.elapsed().as_nanos();
                scorer.imu_samples += 1;
                let e = filter.estimate(t_ns);
                files.add(&mut scorer, &e, baselines.as_ref())?;
                continue;
            }
            Event::Mag { t_ns, field } => {
                if let Some((mw, mh)) = baselines.as_mut() {
                    mw.mag(&field);
                    mh.mag(&field);
                }
                if let Some(m) = &ds.mag {
                    let model =
                        Magnetometer::new(lit3(&field), lit3(&m.reference_field), T::lit(m.sigma));
                    let r = filter.0.update(&model, &ekf);
                    if let Err(e) = &r {
                        events.refused("mag", e);
                    }
                    scorer.measurement("mag", t_ns, outcome(r, 3));
                }
            }
            // GNSS datasets replay through the INS navigator (`ins`).
            Event::Gnss { .. } => {}
            Event::Baro { t_ns, altitude } => {
                if let (Filter(f), Some(b)) = (&mut filter, &ds.baro) {
                    let r = f.update(&BaroAltitude::new(T::lit(altitude), T::lit(b.sigma)), &ekf);
                    if let Err(e) = &r {
                        events.refused("baro", e);
                    }
                    scorer.measurement("baro", t_ns, outcome(r, 1));
                }
            }
            Event::Camera { t_ns, observations } => {
                if let (Filter(f), Some(cam)) = (&mut filter, &ds.camera) {
                    let [fx, fy, cx, cy] = cam.intrinsics;
                    let intrinsics = PinholeIntrinsics {
                        fx: T::lit(fx),
                        fy: T::lit(fy),
                        cx: T::lit(cx),
                        cy: T::lit(cy),
                    };
                    let body_from_camera = cam.body_from_camera.cast::<T>();
                    for (id, pixel) in &observations {
                        let Some(landmark) = cam.landmarks.get(id) else {
                            scorer.measurement("camera", t_ns, Outcome::Refused);
                            events.refused("camera", &"landmark id not in cam0/landmarks.csv");
                            continue;
                        };
                        let model = CameraLandmark::new(
                            lit2(pixel),
                            lit3(landmark),
                            intrinsics,
                            body_from_camera,
                            T::lit(cam.sigma_px),
                        );
                        let r = f.update(&model, &camera_options);
                        if let Err(e) = &r {
                            events.refused("camera", e);
                        }
                        scorer.measurement("camera", t_ns, outcome(r, 2));
                    }
                }
            }
        }
        scorer.filter_ns += started.elapsed().as_nanos();
    }
    let mut warnings = events.finish(GAP_EFFECT)?;
    warnings.extend(files.finish()?);
    scorer.add_data_warnings(dir, warnings);
    finish(out, cfg, title, &ds, &scorer)?;
    partials.commit()?;
    Ok(scorer)
}

/// The header of `estimate.csv`.
fn write_csv_header(f: &mut impl Write) -> std::io::Result<()> {
    writeln!(
        f,
        "t_ns,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,bg_x,bg_y,bg_z,ba_x,ba_y,ba_z,\
         sigma_att_x,sigma_att_y,sigma_att_z,sigma_v_x,sigma_v_y,sigma_v_z,sigma_p_x,sigma_p_y,sigma_p_z,\
         sigma_bg_x,sigma_bg_y,sigma_bg_z,sigma_ba_x,sigma_ba_y,sigma_ba_z"
    )
}

/// Writes `metrics.json` (as a partial file) and the plots.
fn finish(
    out: &Path,
    cfg: &ReplayConfig,
    title: &str,
    ds: &Dataset,
    scorer: &Scorer,
) -> Result<(), ReplayError> {
    let metrics = scorer.metrics();
    let mpath = out.join("metrics.json.partial");
    let json = serde_json::to_string_pretty(&metrics).map_err(|e| ReplayError::Output {
        path: mpath.clone(),
        message: e.to_string(),
    })?;
    std::fs::write(&mpath, json).map_err(out_err(&mpath))?;
    if cfg.plots && ds.has_groundtruth {
        crate::plot::write_all(out, scorer, title).map_err(|e| ReplayError::Output {
            path: out.to_path_buf(),
            message: e.to_string(),
        })?;
    }
    Ok(())
}

fn lit2<T: Real>(v: &Vector2<f64>) -> Vector2<T> {
    v.map(T::lit)
}

/// `world_from_body` from one camera frame: `solve_pnp` (Cauchy loss, 2 px scale) from a guess
/// with the aligned attitude at the origin, then `T_wb = T_cw⁻¹ T_BS⁻¹`.
fn pnp_pose(
    frame: &[(u64, Vector2<f64>)],
    cam: &CameraParams,
    attitude: &So3<f64>,
) -> Result<Se3<f64>, ReplayError> {
    let (mut world, mut pixels) = (Vec::new(), Vec::new());
    for (id, px) in frame {
        if let Some(p) = cam.landmarks.get(id) {
            world.push(*p);
            pixels.push(*px);
        }
    }
    let [fx, fy, cx, cy] = cam.intrinsics;
    let camera = PinholeCamera { fx, fy, cx, cy };
    let world_from_camera_guess =
        Se3::from_parts(*attitude, Vector3::zeros()).compose(&cam.body_from_camera);
    let options = PnpOptions {
        loss: Loss::Cauchy(2.0),
        sigma_px: cam.sigma_px,
        ..PnpOptions::default()
    };
    let sol = solve_pnp(
        &world,
        &pixels,
        &camera,
        &world_from_camera_guess.inverse(),
        &options,
    )
    .map_err(|e| ReplayError::Start(format!("camera pose from the first frame: {e}")))?;
    Ok(sol
        .camera_from_world
        .inverse()
        .compose(&cam.body_from_camera.inverse()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::write::simulate;
    use crate::scenario::Scenario;
    use crate::sensors::gnss::GnssConfig;
    use crate::sensors::mag::MagConfig;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "host-sim-replay-unit-{}-{name}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn read(p: &Path) -> String {
        std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    }

    /// `use_magnetometer = false`: the attitude and the INS replays fuse no magnetometer and
    /// read nothing of `mag0/`; their estimate is the same with the magnetometer's files
    /// garbled or gone, and differs from the run that fuses them.
    #[test]
    fn without_the_magnetometer_the_mag_files_do_not_matter() {
        let key: ReplayConfig = toml::from_str("use_magnetometer = false").expect("the key");
        assert!(!key.use_magnetometer && ReplayConfig::default().use_magnetometer);
        assert!(ReplayConfig::simulated().use_magnetometer);
        let err = toml::from_str::<ReplayConfig>("use_magnetometer = 0")
            .expect_err("not a bool")
            .to_string();
        assert!(err.contains("use_magnetometer"), "{err}");
        for (name, gnss) in [("attitude", None), ("ins", Some(GnssConfig::default()))] {
            let dir = tmp(name);
            let ds = dir.join("ds");
            let sc = Scenario {
                duration_s: 12.0,
                static_s: 3.0,
                mag: Some(MagConfig {
                    rate_hz: 25.0,
                    ..MagConfig::default()
                }),
                gnss,
                ..Scenario::default()
            };
            simulate(&sc, 1, &ds).expect("simulate");
            let with = ReplayConfig {
                plots: false,
                ..sc.replay.clone()
            };
            let without = ReplayConfig {
                use_magnetometer: false,
                ..with.clone()
            };
            without.validate().expect("valid");
            let m_with = replay(&ds, &dir.join("with"), &with, name).expect("with mag");
            let m_without = replay(&ds, &dir.join("without"), &without, name).expect("without");
            assert!(m_with.updates_accepted.contains_key("mag"), "{name}");
            for m in [&m_without.updates_accepted, &m_without.updates_rejected] {
                assert!(!m.contains_key("mag"), "{name}: {m:?}");
            }
            assert!(!m_without.updates_refused.contains_key("mag"), "{name}");
            assert_eq!(m_with.heading_reference, Some(true));
            // GNSS observes the heading (the INS replay); nothing does in the attitude replay.
            assert_eq!(m_without.heading_reference, Some(name == "ins"));
            let estimate = |out: &str| read(&dir.join(out).join("estimate.csv"));
            assert_ne!(estimate("with"), estimate("without"), "{name}: mag unused");

            // Garbled magnetometer files: unreadable with it, no difference without it.
            std::fs::write(ds.join("mag0/data.csv"), "not,a\nmagnetometer\n").expect("garble");
            std::fs::write(ds.join("mag0/sensor.yaml"), "rate_hz: [\n").expect("garble");
            assert!(replay(&ds, &dir.join("garbled-with"), &with, name).is_err());
            replay(&ds, &dir.join("garbled"), &without, name).expect("mag0 not read");
            assert_eq!(estimate("without"), estimate("garbled"), "{name}");
            // And no magnetometer at all.
            std::fs::remove_dir_all(ds.join("mag0")).expect("rm mag0");
            replay(&ds, &dir.join("gone"), &without, name).expect("no mag0");
            assert_eq!(estimate("without"), estimate("gone"), "{name}");
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

//! `host-sim calibrate`: IMU and magnetometer noise from a static recording, by the Allan
//! deviation.
//!
//! # The Allan variance
//!
//! For `N` samples `x_i` of one axis (a rate: rad/s, m/s², µT) at the interval `τ0`, the
//! integrated signal is `θ_k = τ0 Σ_{i<k} x_i`, `k = 0..=N` (`N + 1` values). For the cluster
//! time `τ = m τ0` the overlapping Allan variance is
//!
//! ```text
//! σ²(τ) = 1 / (2 τ² (N + 1 − 2m)) · Σ_{k=0}^{N−2m} (θ_{k+2m} − 2 θ_{k+m} + θ_k)²
//! ```
//!
//! half the mean square difference of two consecutive averages over `τ`, taken at every start
//! sample ([`allan_deviation`]; the mean is subtracted first, which the second difference
//! ignores, so that `θ` stays small). The cluster sizes `m` run on a logarithmic grid, 10 per
//! decade, while at least [`MIN_CLUSTERS`] clusters fit in the recording (`N/m ≥ 9`).
//!
//! **Confidence.** With `K = N/m` non-overlapping clusters, `σ²(τ)` averages `K − 1` squared
//! differences of cluster means; for Gaussian noise each is `σ² χ²₁`, so, counting them as
//! independent, the estimate is `σ² χ²_{K−1}/(K−1)`, of relative standard deviation
//! `√(2/(K−1))`, and `σ(τ)` (its square root) has half of it:
//! `ε(τ) = 1/√(2 (N/m − 1))` (El-Sheimy et al.). The overlapping estimator used here does
//! better on white noise (about 11.5 equivalent degrees of freedom instead of 8 at `N/m = 9`) and
//! about as well on a random walk (about 6.4 there, Howe, Allan and Barnes 1981), so `ε` is the
//! estimator's confidence to about 10 %. At the longest `τ`, `N/m = 9`: `ε = 25 %`.
//!
//! # Reading the noise terms (IEEE Std 952-1997, annex C)
//!
//! Independent noise terms add in the Allan variance:
//! `σ²(τ) = N²/τ + (2 ln 2/π) B² + K² τ/3` (plus quantization, slope −1, and rate ramp,
//! slope +1, not read here). On a log-log plot each term is a straight line:
//!
//! | term | slope of `σ(τ)` | read as | unit (gyroscope; accelerometer; magnetometer) |
//! |---|---|---|---|
//! | white noise density `N` (angle / velocity random walk) | −1/2 | `N = σ(τ = 1 s)` on the −1/2 line, i.e. `σ(τ)·√τ` | rad/s/√Hz; m/s²/√Hz; µT/√Hz |
//! | bias instability `B` | 0 | `B = min σ / 0.664`, `0.664 = √(2 ln 2/π)` | rad/s; m/s²; µT |
//! | rate random walk `K` | +1/2 | `K = σ(τ = 3 s)` on the +1/2 line, i.e. `σ(τ)·√(3/τ)` | rad/s²/√Hz; m/s³/√Hz; µT/s/√Hz |
//!
//! How [`fit`] reads them from a finite, noisy curve (slopes are least-squares slopes of
//! `ln σ` against `ln τ` over five neighbouring points, half a decade):
//!
//! * `N`: at `τ = 1 s` when the curve reaches it and its slope there is within
//!   [`SLOPE_TOLERANCE`] of −1/2 (white noise then holds at least 80 % of the variance, so `N` is
//!   overstated by at most 12 %). Otherwise at the `τ` where the slope is closest to −1/2, and the
//!   output says so: searched below 1 s when the slope at 1 s is off (white noise dominates the
//!   short cluster times; the bias instability and random walks spoil the long ones), and up to
//!   the minimum of `σ` when the curve ends before 1 s.
//! * `B`: the minimum of `σ`. When the minimum is the longest `τ` (the curve still falls), `B` is
//!   an upper bound, and the output says so.
//! * `K`: at the `τ`, past the minimum, where the slope is closest to +1/2, when it is within
//!   [`SLOPE_TOLERANCE`] and `σ` has risen there above the minimum by more than twice its relative
//!   error. Otherwise `K` is *not resolved*: the output says how long a recording would at least
//!   be needed (the curve reaching a decade past its minimum, with [`MIN_CLUSTERS`] clusters
//!   there) and gives the +1/2 line through the minimum, `σ_min·√(3/τ_min)`, as an upper bound
//!   (`σ²(τ) ≥ K²τ/3` at every `τ`).
//!
//! # What is written
//!
//! `imu0/sensor.yaml` and `mag0/sensor.yaml` hold one value per sensor, the **largest over the
//! three axes**: a filter given a noise smaller than an axis has becomes overconfident on that
//! axis (inconsistent, and it rejects good measurements), while one given a larger noise only
//! weighs that axis a little less. Every axis is in the table and in `calibration.json`.
//!
//! The `*_random_walk` keys of EuRoC and Kalibr (`gyroscope_random_walk`,
//! `accelerometer_random_walk`) are the rate random walk `K`: the bias's random walk, in
//! rad/s²/√Hz and m/s³/√Hz. When `K` is not resolved the upper bound is written, with a comment.
//!
//! Advice, not applied here: the values describe the sensor at rest. Many users inflate the
//! white-noise densities by a factor of 2 to 10 for a filter on a real vehicle, for vibration,
//! temperature changes and errors the filter does not model (scale factor, misalignment,
//! g-sensitivity), and the random walks likewise.
//!
//! The magnetometer's `sigma` is the largest per-axis standard deviation of the static
//! recording (µT per sample); its noise density is reported too. `reference_field`, the Earth's
//! field at the site, is not calibrated here: `mag0/sensor.yaml` says it must be set.
//!
//! # References
//!
//! * IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
//!   Single-Axis Interferometric Fiber Optic Gyros*, annex C (Allan variance).
//! * N. El-Sheimy, H. Hou, X. Niu, "Analysis and Modeling of Inertial Sensors Using Allan
//!   Variance", *IEEE Transactions on Instrumentation and Measurement* 57(1), 2008.
//! * D. A. Howe, D. W. Allan, J. A. Barnes, "Properties of Signal Sources and Measurement
//!   Methods", *35th Annual Symposium on Frequency Control*, 1981 (degrees of freedom of the
//!   overlapping estimator).

use crate::dataset::check::DataWarning;
use crate::dataset::read::Rows;
use crate::dataset::DatasetError;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The fewest clusters of the longest cluster time: `N/m ≥ 9` (relative error of `σ` ≤ 25 %).
pub const MIN_CLUSTERS: usize = 9;

/// Cluster times per decade of `τ`.
pub const POINTS_PER_DECADE: u32 = 10;

/// The fewest points of an Allan curve [`fit`] reads.
pub const MIN_POINTS: usize = 5;

/// `√(2 ln 2/π)`: the flat part of the Allan deviation over the bias instability.
pub const BIAS_INSTABILITY_FACTOR: f64 = 0.664_282_5;

/// How far from ±1/2 the log-log slope may be where `N` is read at `τ = 1 s` and where `K` is
/// read.
pub const SLOPE_TOLERANCE: f64 = 0.1;

/// Neighbours on each side in the least-squares slope.
const SLOPE_HALF_WINDOW: usize = 2;

/// One point of an Allan deviation curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AllanPoint {
    /// Cluster size, samples.
    pub m: usize,
    /// Cluster time `m τ0`, s.
    pub tau: f64,
    /// Allan deviation, in the unit of the samples.
    pub sigma: f64,
    /// Relative standard deviation of `sigma` as an estimate, `1/√(2 (N/m − 1))`.
    pub relative_error: f64,
}

/// An Allan deviation curve of one axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanCurve {
    /// Sample interval, s.
    pub tau0: f64,
    /// Number of samples.
    pub samples: usize,
    /// The points, by increasing `tau`.
    pub points: Vec<AllanPoint>,
}

impl AllanCurve {
    /// Length of the recording, `N τ0`, s.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.samples as f64 * self.tau0
    }
}

/// The cluster sizes for `samples` samples: 10 per decade from 1, while `N/m ≥ 9`.
#[must_use]
pub fn cluster_sizes(samples: usize) -> Vec<usize> {
    let mut sizes: Vec<usize> = Vec::new();
    for i in 0u32.. {
        let m = 10f64
            .powf(f64::from(i) / f64::from(POINTS_PER_DECADE))
            .round() as usize;
        if m.saturating_mul(MIN_CLUSTERS) > samples {
            break;
        }
        if sizes.last() != Some(&m) {
            sizes.push(m);
        }
    }
    sizes
}

/// The relative standard deviation of an Allan deviation estimate over `duration / tau`
/// clusters: `1/√(2 (duration/tau − 1))` (see the module docs).
#[must_use]
pub fn relative_error(duration: f64, tau: f64) -> f64 {
    1.0 / (2.0 * (duration / tau - 1.0)).sqrt()
}

/// The overlapping Allan deviation of `samples` taken every `tau0` seconds, at the cluster sizes
/// of [`cluster_sizes`] (none when fewer than 9 samples).
#[must_use]
pub fn allan_deviation(samples: &[f64], tau0: f64) -> AllanCurve {
    let n = samples.len();
    let mean = samples.iter().sum::<f64>() / n.max(1) as f64;
    let mut theta = Vec::with_capacity(n + 1);
    let mut acc = 0.0;
    theta.push(acc);
    for x in samples {
        acc += (x - mean) * tau0;
        theta.push(acc);
    }
    let duration = n as f64 * tau0;
    let points = cluster_sizes(n)
        .into_iter()
        .map(|m| {
            let sum: f64 = theta
                .iter()
                .zip(&theta[m..])
                .zip(&theta[2 * m..])
                .map(|((a, b), c)| {
                    let d = c - 2.0 * b + a;
                    d * d
                })
                .sum();
            let terms = (n + 1 - 2 * m) as f64;
            let tau = m as f64 * tau0;
            AllanPoint {
                m,
                tau,
                sigma: (sum / (2.0 * tau * tau * terms)).sqrt(),
                relative_error: relative_error(duration, tau),
            }
        })
        .collect();
    AllanCurve {
        tau0,
        samples: n,
        points,
    }
}

/// One value read off an Allan curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reading {
    /// The value, in the unit of its term.
    pub value: f64,
    /// The cluster time it was read at, s.
    pub tau: f64,
    /// The log-log slope of the curve there.
    pub slope: f64,
    /// The relative error of `σ` there.
    pub relative_error: f64,
}

/// Where the white noise density was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WhiteNoiseAt {
    /// At `τ = 1 s`, the slope there within [`SLOPE_TOLERANCE`] of −1/2.
    OneSecond,
    /// Below 1 s, where the slope is closest to −1/2: the slope at 1 s is not within
    /// [`SLOPE_TOLERANCE`] of −1/2.
    BelowOneSecond,
    /// Where the slope is closest to −1/2, up to the minimum: the curve ends before 1 s.
    CurveEndsBeforeOneSecond,
}

/// The rate random walk: read, or bounded.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum RateRandomWalk {
    /// Read on the +1/2 slope.
    Resolved(Reading),
    /// The curve shows no +1/2 slope.
    NotResolved {
        /// The +1/2 line through the minimum of `σ`, `σ_min·√(3/τ_min)`: an upper bound.
        upper_bound: f64,
        /// `τ_min`, s.
        tau: f64,
        /// The shortest recording that reaches a decade past the minimum, s.
        need_s: f64,
        /// Whether the recording is shorter than `need_s`.
        too_short: bool,
    },
}

impl RateRandomWalk {
    /// The value read, or the upper bound.
    #[must_use]
    pub fn value(&self) -> f64 {
        match self {
            Self::Resolved(r) => r.value,
            Self::NotResolved { upper_bound, .. } => *upper_bound,
        }
    }

    /// Whether it was read on a +1/2 slope.
    #[must_use]
    pub fn is_resolved(&self) -> bool {
        matches!(self, Self::Resolved(_))
    }
}

/// The noise terms of one axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseFit {
    /// White noise density `N`.
    pub white_noise: Reading,
    /// Where `N` was read.
    pub white_noise_at: WhiteNoiseAt,
    /// Bias instability `B` (minimum of `σ` over 0.664).
    pub bias_instability: Reading,
    /// Whether `B` is only an upper bound (the curve still falls at its longest `τ`).
    pub bias_instability_upper_bound: bool,
    /// Rate random walk `K`.
    pub rate_random_walk: RateRandomWalk,
}

/// Why a curve cannot be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Too few samples for [`MIN_POINTS`] cluster times.
    #[error("{samples} samples: the Allan deviation needs at least {needed}")]
    TooShort {
        /// Samples given.
        samples: usize,
        /// Samples needed.
        needed: usize,
    },
    /// The curve is zero (or not finite) somewhere: a constant or periodic signal.
    #[error(
        "the Allan deviation is {sigma} at τ = {tau} s: a constant or periodic signal, not noise"
    )]
    NoNoise {
        /// Where, s.
        tau: f64,
        /// The value there.
        sigma: f64,
    },
}

/// The fewest samples [`fit`] reads: [`MIN_POINTS`] cluster sizes, with [`MIN_CLUSTERS`] at the
/// longest.
#[must_use]
pub fn samples_needed() -> usize {
    let mut n = MIN_CLUSTERS;
    while cluster_sizes(n).len() < MIN_POINTS {
        n += 1;
    }
    n
}

/// Least-squares slopes of `ln σ` against `ln τ` over [`SLOPE_HALF_WINDOW`] neighbours on each
/// side.
fn slopes(points: &[AllanPoint]) -> Vec<f64> {
    let last = points.len().saturating_sub(1);
    (0..points.len())
        .map(|i| {
            let window =
                &points[i.saturating_sub(SLOPE_HALF_WINDOW)..=(i + SLOPE_HALF_WINDOW).min(last)];
            let n = window.len() as f64;
            let mx = window.iter().map(|p| p.tau.ln()).sum::<f64>() / n;
            let my = window.iter().map(|p| p.sigma.ln()).sum::<f64>() / n;
            let (sxy, sxx) = window.iter().fold((0.0, 0.0), |(sxy, sxx), p| {
                let dx = p.tau.ln() - mx;
                (sxy + dx * (p.sigma.ln() - my), sxx + dx * dx)
            });
            sxy / sxx
        })
        .collect()
}

/// Reads `N`, `B` and `K` off an Allan deviation curve (see the module docs).
///
/// # Errors
/// When the curve has fewer than [`MIN_POINTS`] points, or a point is zero or not finite.
pub fn fit(curve: &AllanCurve) -> Result<NoiseFit, FitError> {
    let p = &curve.points;
    if p.len() < MIN_POINTS {
        return Err(FitError::TooShort {
            samples: curve.samples,
            needed: samples_needed(),
        });
    }
    if let Some(q) = p.iter().find(|q| !(q.sigma.is_finite() && q.sigma > 0.0)) {
        return Err(FitError::NoNoise {
            tau: q.tau,
            sigma: q.sigma,
        });
    }
    let slope = slopes(p);
    let at = |i: usize, value: f64| Reading {
        value,
        tau: p[i].tau,
        slope: slope[i],
        relative_error: p[i].relative_error,
    };
    let last = p.len() - 1;

    // B: the minimum.
    let mut i_min = 0;
    for (i, q) in p.iter().enumerate() {
        if q.sigma < p[i_min].sigma {
            i_min = i;
        }
    }
    let sigma_min = p[i_min].sigma;
    let bias_instability = at(i_min, sigma_min / BIAS_INSTABILITY_FACTOR);

    // N: at 1 s on a −1/2 slope, else where the slope is closest to −1/2.
    let (white_noise, white_noise_at) = match one_second(p, &slope, curve.duration()) {
        Some(r) if (r.slope + 0.5).abs() <= SLOPE_TOLERANCE => (r, WhiteNoiseAt::OneSecond),
        reached => {
            let (end, why) = match reached {
                Some(_) => {
                    let below = p.iter().take_while(|q| q.tau < 1.0).count();
                    (below.saturating_sub(1), WhiteNoiseAt::BelowOneSecond)
                }
                None => (i_min, WhiteNoiseAt::CurveEndsBeforeOneSecond),
            };
            let i = closest(0..=end, &slope, -0.5);
            (at(i, p[i].sigma * p[i].tau.sqrt()), why)
        }
    };

    // K: past the minimum, where the slope is closest to +1/2 and the rise is real.
    let candidate = (i_min < last).then(|| closest(i_min + 1..=last, &slope, 0.5));
    let rate_random_walk = match candidate {
        Some(i)
            if (slope[i] - 0.5).abs() <= SLOPE_TOLERANCE
                && p[i].sigma > sigma_min * (1.0 + 2.0 * p[i].relative_error) =>
        {
            RateRandomWalk::Resolved(at(i, p[i].sigma * (3.0 / p[i].tau).sqrt()))
        }
        _ => {
            let tau = p[i_min].tau;
            let need_s = MIN_CLUSTERS as f64 * 10.0 * tau;
            RateRandomWalk::NotResolved {
                upper_bound: sigma_min * (3.0 / tau).sqrt(),
                tau,
                need_s,
                too_short: need_s > curve.duration(),
            }
        }
    };

    Ok(NoiseFit {
        white_noise,
        white_noise_at,
        bias_instability,
        bias_instability_upper_bound: i_min == last,
        rate_random_walk,
    })
}

/// `σ` and the slope at `τ = 1 s`, interpolated in log-log, when the curve spans it.
fn one_second(p: &[AllanPoint], slope: &[f64], duration: f64) -> Option<Reading> {
    let j = p.iter().position(|q| q.tau >= 1.0)?;
    let (ln_sigma, s) = if p[j].tau == 1.0 {
        (p[j].sigma.ln(), slope[j])
    } else {
        let i = j.checked_sub(1)?;
        let w = -p[i].tau.ln() / (p[j].tau.ln() - p[i].tau.ln());
        let lerp = |a: f64, b: f64| a + w * (b - a);
        (
            lerp(p[i].sigma.ln(), p[j].sigma.ln()),
            lerp(slope[i], slope[j]),
        )
    };
    Some(Reading {
        value: ln_sigma.exp(),
        tau: 1.0,
        slope: s,
        relative_error: relative_error(duration, 1.0),
    })
}

/// The index in `range` whose slope is closest to `target`.
fn closest(range: std::ops::RangeInclusive<usize>, slope: &[f64], target: f64) -> usize {
    let start = *range.start();
    range.fold(start, |best, i| {
        if (slope[i] - target).abs() < (slope[best] - target).abs() {
            i
        } else {
            best
        }
    })
}

/// Units of one sensor's terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Units {
    /// Of the white noise density `N`.
    pub white_noise: &'static str,
    /// Of the bias instability `B` and of the standard deviation.
    pub bias_instability: &'static str,
    /// Of the rate random walk `K`.
    pub rate_random_walk: &'static str,
}

const GYROSCOPE: Units = Units {
    white_noise: "rad/s/√Hz",
    bias_instability: "rad/s",
    rate_random_walk: "rad/s²/√Hz",
};
const ACCELEROMETER: Units = Units {
    white_noise: "m/s²/√Hz",
    bias_instability: "m/s²",
    rate_random_walk: "m/s³/√Hz",
};
const MAGNETOMETER: Units = Units {
    white_noise: "µT/√Hz",
    bias_instability: "µT",
    rate_random_walk: "µT/s/√Hz",
};

/// One axis of one sensor.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisCalibration {
    /// `x`, `y` or `z`.
    pub axis: &'static str,
    /// Standard deviation of the samples (unit of `B`).
    pub std: f64,
    /// The noise terms.
    #[serde(flatten)]
    pub fit: NoiseFit,
}

/// One three-axis sensor.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorCalibration {
    /// `gyroscope`, `accelerometer` or `magnetometer`.
    pub sensor: &'static str,
    /// Units of the terms.
    pub units: Units,
    /// Per axis.
    pub axes: Vec<AxisCalibration>,
    /// The white noise density written: the largest over the axes.
    pub noise_density: f64,
    /// The rate random walk written: the largest over the axes of `K`, or of its upper bound
    /// where it is not resolved.
    pub random_walk: f64,
    /// Whether `K` is resolved on every axis.
    pub random_walk_resolved: bool,
    /// The largest standard deviation over the axes.
    pub std: f64,
    /// The Allan curves, per axis (in `allan.csv`).
    #[serde(skip)]
    pub curves: Vec<AllanCurve>,
}

/// The samples read from one file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Recording {
    /// The file, relative to the dataset.
    pub file: &'static str,
    /// Samples in the interval.
    pub samples: usize,
    /// First sample, s from the first IMU sample.
    pub start_s: f64,
    /// Last sample, s from the first IMU sample.
    pub end_s: f64,
    /// `1 / (median sample interval)`, Hz.
    pub rate_hz: f64,
    /// Intervals longer than 1.5 median intervals (the Allan deviation assumes none).
    pub gaps: usize,
}

/// Everything `host-sim calibrate` found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Calibration {
    /// The dataset folder.
    pub dataset: PathBuf,
    /// `--from`, s from the first IMU sample.
    pub from_s: f64,
    /// `--to`, s from the first IMU sample (none: to the end).
    pub to_s: Option<f64>,
    /// `imu0/data.csv`.
    pub imu: Recording,
    /// The gyroscope.
    pub gyroscope: SensorCalibration,
    /// The accelerometer.
    pub accelerometer: SensorCalibration,
    /// `mag0/data.csv`, when present.
    pub mag: Option<Recording>,
    /// The magnetometer, when present.
    pub magnetometer: Option<SensorCalibration>,
    /// What the files had wrong that the calibration survived (a last line cut short and
    /// skipped), each with its file and line.
    pub data_warnings: Vec<DataWarning>,
}

/// Why calibration failed.
#[derive(Debug, thiserror::Error)]
pub enum CalibrateError {
    /// Reading the dataset.
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// `--from` / `--to` out of their domain.
    #[error("{0}")]
    Interval(String),
    /// The samples of a file cannot be calibrated.
    #[error("{}: {message}", path.display())]
    Samples {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Writing an output.
    #[error("{}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

/// Samples of one file inside the interval.
struct Series {
    t_ns: Vec<u64>,
    axes: Vec<Vec<f64>>,
    /// What the reader skipped or doubts (a last line cut short).
    warnings: Vec<DataWarning>,
}

/// Reads the rows of `path` whose time is in `[from, to]` ns (absolute), keeping the
/// `columns − 1` values of each.
fn read_interval(path: &Path, columns: usize, from: u64, to: u64) -> Result<Series, DatasetError> {
    let mut rows = Rows::open(path, columns, false)?;
    let mut series = Series {
        t_ns: Vec::new(),
        axes: vec![Vec::new(); columns - 1],
        warnings: Vec::new(),
    };
    while let Some((_, t, v)) = rows.next_row()? {
        if t > to {
            break;
        }
        if t >= from {
            series.t_ns.push(t);
            for (axis, x) in series.axes.iter_mut().zip(v) {
                axis.push(x);
            }
        }
    }
    series.warnings = rows.warnings().to_vec();
    Ok(series)
}

/// The first timestamp of `path`.
fn first_timestamp(path: &Path, columns: usize) -> Result<u64, CalibrateError> {
    let mut rows = Rows::open(path, columns, false)?;
    match rows.next_row()? {
        Some((_, t, _)) => Ok(t),
        None => Err(CalibrateError::Samples {
            path: path.to_path_buf(),
            message: "no samples".into(),
        }),
    }
}

fn seconds_to_ns(s: f64) -> u64 {
    (s * 1e9).round() as u64
}

/// The recording of a series, with `origin` the first IMU timestamp.
fn recording(
    file: &'static str,
    path: &Path,
    s: &Series,
    origin: u64,
) -> Result<Recording, CalibrateError> {
    let needed = samples_needed();
    if s.t_ns.len() < needed {
        return Err(CalibrateError::Samples {
            path: path.to_path_buf(),
            message: format!(
                "{} samples in the interval; the Allan deviation needs at least {needed}",
                s.t_ns.len()
            ),
        });
    }
    let mut intervals: Vec<u64> = s.t_ns.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = intervals.len() / 2;
    let median = *intervals.select_nth_unstable(mid).1;
    let gaps = intervals.iter().filter(|&&d| 2 * d > 3 * median).count();
    let rel = |t: u64| (t as i128 - origin as i128) as f64 * 1e-9;
    Ok(Recording {
        file,
        samples: s.t_ns.len(),
        start_s: rel(s.t_ns[0]),
        end_s: rel(s.t_ns[s.t_ns.len() - 1]),
        rate_hz: 1e9 / median as f64,
        gaps,
    })
}

fn sensor(
    name: &'static str,
    units: Units,
    axes: &[Vec<f64>],
    tau0: f64,
    path: &Path,
) -> Result<SensorCalibration, CalibrateError> {
    let mut out = Vec::new();
    let mut curves = Vec::new();
    for (axis, x) in ["x", "y", "z"].into_iter().zip(axes) {
        let curve = allan_deviation(x, tau0);
        let fit = fit(&curve).map_err(|e| CalibrateError::Samples {
            path: path.to_path_buf(),
            message: format!("{name} {axis}: {e}"),
        })?;
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let std = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        out.push(AxisCalibration { axis, std, fit });
        curves.push(curve);
    }
    let max = |f: &dyn Fn(&AxisCalibration) -> f64| out.iter().map(f).fold(0.0, f64::max);
    Ok(SensorCalibration {
        sensor: name,
        units,
        noise_density: max(&|a| a.fit.white_noise.value),
        random_walk: max(&|a| a.fit.rate_random_walk.value()),
        random_walk_resolved: out.iter().all(|a| a.fit.rate_random_walk.is_resolved()),
        std: max(&|a| a.std),
        axes: out,
        curves,
    })
}

/// Reads `imu0/data.csv` (and `mag0/data.csv` when present) of the dataset `dir` between `from_s`
/// and `to_s` seconds from the first IMU sample (the whole recording by default) and computes
/// the noise terms of every axis.
///
/// # Errors
/// A missing or malformed file (named with its line), an empty or reversed interval, too few
/// samples in it, or an axis without noise.
pub fn calibrate(
    dir: &Path,
    from_s: Option<f64>,
    to_s: Option<f64>,
) -> Result<Calibration, CalibrateError> {
    let from = from_s.unwrap_or(0.0);
    if !(from.is_finite() && from >= 0.0) {
        return Err(CalibrateError::Interval(format!(
            "--from {from}: must be a number of seconds, 0 or more"
        )));
    }
    if let Some(to) = to_s {
        if !(to.is_finite() && to > from) {
            return Err(CalibrateError::Interval(format!(
                "--to {to}: must be a number of seconds after --from ({from})"
            )));
        }
    }
    let imu_path = dir.join("imu0/data.csv");
    if !imu_path.is_file() {
        return Err(DatasetError::file(&imu_path, "missing (every dataset needs imu0)").into());
    }
    let origin = first_timestamp(&imu_path, 7)?;
    let from_ns = origin.saturating_add(seconds_to_ns(from));
    let to_ns = to_s.map_or(u64::MAX, |t| origin.saturating_add(seconds_to_ns(t)));

    let imu = read_interval(&imu_path, 7, from_ns, to_ns)?;
    let imu_rec = recording("imu0/data.csv", &imu_path, &imu, origin)?;
    let tau0 = 1.0 / imu_rec.rate_hz;
    let gyroscope = sensor("gyroscope", GYROSCOPE, &imu.axes[0..3], tau0, &imu_path)?;
    let accelerometer = sensor(
        "accelerometer",
        ACCELEROMETER,
        &imu.axes[3..6],
        tau0,
        &imu_path,
    )?;

    let mut data_warnings = imu.warnings.clone();
    let mag_path = dir.join("mag0/data.csv");
    let (mag, magnetometer) = if mag_path.is_file() {
        let s = read_interval(&mag_path, 4, from_ns, to_ns)?;
        data_warnings.extend(s.warnings.iter().cloned());
        let rec = recording("mag0/data.csv", &mag_path, &s, origin)?;
        let cal = sensor(
            "magnetometer",
            MAGNETOMETER,
            &s.axes,
            1.0 / rec.rate_hz,
            &mag_path,
        )?;
        (Some(rec), Some(cal))
    } else {
        (None, None)
    };
    Ok(Calibration {
        dataset: dir.to_path_buf(),
        from_s: from,
        to_s,
        imu: imu_rec,
        gyroscope,
        accelerometer,
        mag,
        magnetometer,
        data_warnings,
    })
}

/// Three significant digits, for cluster times and durations.
fn short(x: f64) -> String {
    if !(x.is_finite() && x > 0.0) {
        return format!("{x}");
    }
    let decimals = (2 - x.log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// The body-from-sensor transform of a `sensor.yaml`, EuRoC's 4×4 row-major matrix, written as
/// the dataset writer writes it.
fn t_bs_identity() -> String {
    let d = (0..16)
        .map(|i| format!("{}", if i % 5 == 0 { 1.0 } else { 0.0 }))
        .collect::<Vec<_>>()
        .join(", ");
    format!("T_BS:\n  cols: 4\n  rows: 4\n  data: [{d}]\n")
}

impl Calibration {
    fn source(&self) -> String {
        let to = self
            .to_s
            .map_or_else(|| "the end".to_string(), |t| format!("{t} s"));
        format!(
            "{}, t = {} s … {to} (t from its first IMU sample; {} IMU samples)",
            self.dataset.display(),
            self.from_s,
            self.imu.samples
        )
    }

    /// `imu0/sensor.yaml`: the rate, the largest densities and random walks over the axes, and
    /// an identity `T_BS`.
    #[must_use]
    pub fn imu_yaml(&self) -> String {
        let rw = |s: &SensorCalibration| {
            let need = s
                .axes
                .iter()
                .filter_map(|a| match a.fit.rate_random_walk {
                    RateRandomWalk::NotResolved { need_s, .. } => Some(need_s),
                    RateRandomWalk::Resolved(_) => None,
                })
                .fold(0.0, f64::max);
            let too_short = s.axes.iter().any(|a| {
                matches!(
                    a.fit.rate_random_walk,
                    RateRandomWalk::NotResolved {
                        too_short: true,
                        ..
                    }
                )
            });
            if s.random_walk_resolved {
                format!("{:e}", s.random_walk)
            } else if too_short {
                format!(
                    "{:e}  # not resolved (recording too short: need >= {} s); the upper bound from the bias instability",
                    s.random_walk,
                    short(need)
                )
            } else {
                format!(
                    "{:e}  # not resolved (no +1/2 slope); the upper bound from the bias instability",
                    s.random_walk
                )
            }
        };
        format!(
            "# imu0: host-sim calibrate over {}.\n\
             # Allan deviation; each value is the largest over the three axes. These are the sensor at rest:\n\
             # a filter on a moving vehicle usually needs the densities inflated (x2..10).\n\
             sensor_type: imu\n{}rate_hz: {}\ngyroscope_noise_density: {:e}\ngyroscope_random_walk: {}\n\
             accelerometer_noise_density: {:e}\naccelerometer_random_walk: {}\n",
            self.source(),
            t_bs_identity(),
            self.imu.rate_hz,
            self.gyroscope.noise_density,
            rw(&self.gyroscope),
            self.accelerometer.noise_density,
            rw(&self.accelerometer),
        )
    }

    /// `mag0/sensor.yaml`, when there is a magnetometer: the rate and the largest per-axis
    /// standard deviation; `reference_field` is left to the user.
    #[must_use]
    pub fn mag_yaml(&self) -> Option<String> {
        let (rec, m) = (self.mag.as_ref()?, self.magnetometer.as_ref()?);
        Some(format!(
            "# mag0: host-sim calibrate over {}.\n\
             # sigma is the largest per-axis standard deviation of the static recording, µT.\n\
             sensor_type: magnetometer\nrate_hz: {}\nsigma: {:e}\n\
             # reference_field: [x, y, z]  the Earth's field at the site, world frame (ENU), µT.\n\
             # Not calibrated here: it must be set (from a geomagnetic model, or measured level and\n\
             # facing north) before this dataset can be replayed.\n",
            self.source(),
            rec.rate_hz,
            m.std
        ))
    }

    /// `allan.csv`: one row per sensor and cluster time, `σ` per axis.
    #[must_use]
    pub fn allan_csv(&self) -> String {
        let mut s = String::from("sensor,tau [s],m,sigma_x,sigma_y,sigma_z,unit,relative_error\n");
        for sensor in self.sensors() {
            let Some(first) = sensor.curves.first() else {
                continue;
            };
            for (i, p) in first.points.iter().enumerate() {
                let _ = write!(s, "{},{:e},{}", sensor.sensor, p.tau, p.m);
                for c in &sensor.curves {
                    let _ = write!(s, ",{:e}", c.points.get(i).map_or(f64::NAN, |q| q.sigma));
                }
                let _ = writeln!(
                    s,
                    ",{},{:.4}",
                    sensor.units.bias_instability, p.relative_error
                );
            }
        }
        s
    }

    fn sensors(&self) -> impl Iterator<Item = &SensorCalibration> {
        [&self.gyroscope, &self.accelerometer]
            .into_iter()
            .chain(self.magnetometer.as_ref())
    }

    /// Writes `imu0/sensor.yaml`, `mag0/sensor.yaml` (with a magnetometer), `allan.csv` and
    /// `calibration.json` into `out`.
    ///
    /// # Errors
    /// When a file cannot be written.
    pub fn write(&self, out: &Path) -> Result<(), CalibrateError> {
        let put = |rel: &str, text: &str| -> Result<(), CalibrateError> {
            let path = out.join(rel);
            let err = |source| CalibrateError::Write {
                path: path.clone(),
                source,
            };
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(err)?;
            }
            std::fs::write(&path, text).map_err(err)
        };
        put("imu0/sensor.yaml", &self.imu_yaml())?;
        if let Some(y) = self.mag_yaml() {
            put("mag0/sensor.yaml", &y)?;
        }
        put("allan.csv", &self.allan_csv())?;
        let json = serde_json::to_string_pretty(self).map_err(|e| CalibrateError::Write {
            path: out.join("calibration.json"),
            source: e.into(),
        })?;
        put("calibration.json", &(json + "\n"))
    }

    /// The table `host-sim calibrate` prints: per sensor and axis `N`, `B`, `K` with the `τ`
    /// each was read at, the standard deviation, the notes, and the values written.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "calibrate {}", self.source());
        for rec in std::iter::once(&self.imu).chain(self.mag.as_ref()) {
            let _ = writeln!(
                s,
                "  {}: {} samples, t = {:.3} … {:.3} s, {:.3} Hz (median interval){}",
                rec.file,
                rec.samples,
                rec.start_s,
                rec.end_s,
                rec.rate_hz,
                if rec.gaps > 0 {
                    format!(
                        "; {} gaps longer than 1.5 intervals (the Allan deviation assumes none)",
                        rec.gaps
                    )
                } else {
                    String::new()
                }
            );
        }
        let mut notes: Vec<String> = Vec::new();
        let mut note = |text: String| -> String {
            let mark = match notes.iter().position(|n| *n == text) {
                Some(i) => i,
                None => {
                    notes.push(text);
                    notes.len() - 1
                }
            };
            format!("({})", (b'a' + mark as u8 % 26) as char)
        };
        for sensor in self.sensors() {
            let u = sensor.units;
            let _ = writeln!(
                s,
                "\n  {:<13} {:<22} {:>8}  {:<22} {:>8}  {:<26} {:>8}  std [{}]",
                sensor.sensor,
                format!("N [{}]", u.white_noise),
                "τ_N",
                format!("B [{}]", u.bias_instability),
                "τ_B",
                format!("K [{}]", u.rate_random_walk),
                "τ_K",
                u.bias_instability,
            );
            for a in &sensor.axes {
                let f = &a.fit;
                let n = &f.white_noise;
                let n_note = match f.white_noise_at {
                    WhiteNoiseAt::OneSecond => String::new(),
                    WhiteNoiseAt::BelowOneSecond => note(format!(
                        "N read below 1 s where the slope is closest to −1/2: the slope at τ = 1 s is not within {SLOPE_TOLERANCE} of −1/2"
                    )),
                    WhiteNoiseAt::CurveEndsBeforeOneSecond => note(
                        "N read where the slope is closest to −1/2: the curve ends before τ = 1 s"
                            .into(),
                    ),
                };
                let b = &f.bias_instability;
                let (b_text, b_note) = if f.bias_instability_upper_bound {
                    (
                        format!("≤ {:.3e}", b.value),
                        note("B: the curve still falls at its longest τ; an upper bound".into()),
                    )
                } else {
                    (format!("{:.3e}", b.value), String::new())
                };
                let (k_text, k_tau, k_note) = match f.rate_random_walk {
                    RateRandomWalk::Resolved(r) => {
                        (format!("{:.3e}", r.value), r.tau, String::new())
                    }
                    RateRandomWalk::NotResolved {
                        upper_bound,
                        tau,
                        need_s,
                        too_short,
                    } => {
                        let why = if too_short {
                            format!("recording too short: need ≥ {} s", short(need_s))
                        } else {
                            format!(
                                "no +1/2 slope within {SLOPE_TOLERANCE} rising clear of the noise"
                            )
                        };
                        (
                            format!("≤ {upper_bound:.3e}"),
                            tau,
                            note(format!(
                                "K not resolved ({why}); ≤: the +1/2 line through the minimum of σ, an upper bound"
                            )),
                        )
                    }
                };
                let _ = writeln!(
                    s,
                    "    {:<11} {:<22} {:>8}  {:<22} {:>8}  {:<26} {:>8}  {:.3e}",
                    a.axis,
                    format!("{:.3e} {n_note}", n.value),
                    format!("{} s", short(n.tau)),
                    format!("{b_text} {b_note}"),
                    format!("{} s", short(b.tau)),
                    format!("{k_text} {k_note}"),
                    format!("{} s", short(k_tau)),
                    a.std,
                );
            }
        }
        if !notes.is_empty() {
            s.push('\n');
        }
        for (i, n) in notes.iter().enumerate() {
            let _ = writeln!(s, "  ({}) {n}", (b'a' + i as u8 % 26) as char);
        }
        let rw = |x: &SensorCalibration| {
            if x.random_walk_resolved {
                format!("{:.3e}", x.random_walk)
            } else {
                format!("{:.3e} (upper bound)", x.random_walk)
            }
        };
        let _ = writeln!(
            s,
            "\n  written, the largest over the axes:\n    imu0/sensor.yaml  rate_hz {:.3}, gyroscope_noise_density {:.3e}, gyroscope_random_walk {}\n                      accelerometer_noise_density {:.3e}, accelerometer_random_walk {}",
            self.imu.rate_hz,
            self.gyroscope.noise_density,
            rw(&self.gyroscope),
            self.accelerometer.noise_density,
            rw(&self.accelerometer),
        );
        if let (Some(rec), Some(m)) = (&self.mag, &self.magnetometer) {
            let _ = writeln!(
                s,
                "    mag0/sensor.yaml  rate_hz {:.3}, sigma {:.3e} µT; reference_field not calibrated: set it before replay",
                rec.rate_hz, m.std
            );
        }
        let _ = write!(s, "    allan.csv, calibration.json");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift64* generator with Box–Muller normals.
    struct Gaussian {
        state: u64,
        spare: Option<f64>,
    }

    impl Gaussian {
        fn new(start: u64) -> Self {
            Self {
                state: start.max(1),
                spare: None,
            }
        }

        fn uniform(&mut self) -> f64 {
            self.state ^= self.state >> 12;
            self.state ^= self.state << 25;
            self.state ^= self.state >> 27;
            let r = self.state.wrapping_mul(0x2545_f491_4f6c_dd1d);
            // (0, 1]: 53 bits, never 0.
            ((r >> 11) as f64 + 1.0) / (1u64 << 53) as f64
        }

        fn normal(&mut self) -> f64 {
            if let Some(z) = self.spare.take() {
                return z;
            }
            let (u1, u2) = (self.uniform(), self.uniform());
            let r = (-2.0 * u1.ln()).sqrt();
            let a = 2.0 * std::f64::consts::PI * u2;
            self.spare = Some(r * a.sin());
            r * a.cos()
        }
    }

    /// White noise of density `n` plus a rate random walk of `k`, sampled at `rate` Hz: the
    /// IMU model of the module docs, `σ²(τ) = n²/τ + k²τ/3`.
    fn synthetic(n: f64, k: f64, rate: f64, samples: usize, start: u64) -> Vec<f64> {
        let mut g = Gaussian::new(start);
        let mut bias = 0.0;
        let dt = 1.0 / rate;
        (0..samples)
            .map(|_| {
                let x = bias + n * rate.sqrt() * g.normal();
                bias += k * dt.sqrt() * g.normal();
                x
            })
            .collect()
    }

    fn theory(n: f64, k: f64, tau: f64) -> f64 {
        (n * n / tau + k * k * tau / 3.0).sqrt()
    }

    #[test]
    fn cluster_sizes_are_a_log_grid_with_nine_clusters_at_the_end() {
        let m = cluster_sizes(100_000);
        assert_eq!(&m[..8], &[1, 2, 3, 4, 5, 6, 8, 10]);
        let last = *m.last().expect("sizes");
        assert!(9 * last <= 100_000 && m.windows(2).all(|w| w[0] < w[1]));
        // 10 per decade once m is large enough to be distinct.
        let decade = m.iter().filter(|&&x| (100..1000).contains(&x)).count();
        assert_eq!(decade, 10);
        assert_eq!(samples_needed(), 45);
        assert_eq!(cluster_sizes(44).len(), 4);
    }

    /// Two signals whose Allan deviation is known in closed form.
    #[test]
    fn allan_deviation_of_known_signals() {
        // ±1 alternating: σ(τ0) = √2, σ(2τ0) = 0.
        let x: Vec<f64> = (0..1000)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let c = allan_deviation(&x, 0.01);
        assert!((c.points[0].sigma - 2f64.sqrt()).abs() < 1e-9);
        assert!(c.points[1].sigma.abs() < 1e-9);
        // A rate ramp R (units/s): σ(τ) = R τ/√2 at every τ.
        let (r, tau0) = (0.3, 0.005);
        let x: Vec<f64> = (0..20_000).map(|i| 5.0 + r * tau0 * i as f64).collect();
        for p in allan_deviation(&x, tau0).points {
            let want = r * p.tau / 2f64.sqrt();
            assert!((p.sigma - want).abs() <= 1e-9 * want, "{p:?}: {want}");
        }
    }

    /// White noise and a rate random walk of known size come back within the estimator's
    /// confidence at the `τ` each was read at: three relative errors `ε(τ)`, plus the exact share
    /// of the other term at that `τ`.
    #[test]
    fn white_noise_and_rate_random_walk_are_recovered() {
        let (n, k, rate) = (0.01, 0.002, 100.0);
        let x = synthetic(n, k, rate, 1_000_000, 7);
        let curve = allan_deviation(&x, 1.0 / rate);
        for p in &curve.points {
            let t = theory(n, k, p.tau);
            assert!(
                (p.sigma / t - 1.0).abs() <= 3.0 * p.relative_error,
                "σ({}) = {} against {t}",
                p.tau,
                p.sigma
            );
        }
        let f = fit(&curve).expect("fit");

        assert_eq!(f.white_noise_at, WhiteNoiseAt::OneSecond);
        let w = f.white_noise;
        // σ(1 s) = √(n² + k²/3): the random walk's share is known exactly.
        let share = theory(n, k, 1.0) / n - 1.0;
        let tol = 3.0 * w.relative_error + share;
        assert!(
            (w.value / n - 1.0).abs() <= tol,
            "N = {} against {n} (tolerance {tol})",
            w.value
        );

        let RateRandomWalk::Resolved(r) = f.rate_random_walk else {
            panic!("K not resolved: {:?}", f.rate_random_walk);
        };
        // At τ, σ·√(3/τ) = k·√(1 + 3n²/(k²τ²)).
        let share = (1.0 + 3.0 * n * n / (k * k * r.tau * r.tau)).sqrt() - 1.0;
        let tol = 3.0 * r.relative_error + share;
        assert!(
            (r.value / k - 1.0).abs() <= tol,
            "K = {} at τ = {} against {k} (tolerance {tol})",
            r.value,
            r.tau
        );
        assert!((r.slope - 0.5).abs() <= SLOPE_TOLERANCE);
        assert!(!f.bias_instability_upper_bound);
    }

    /// Pure white noise: `N` at 1 s, `B` only bounded (the curve falls to its end), `K` not
    /// resolved and the recording said to be too short.
    #[test]
    fn white_noise_alone_bounds_b_and_k() {
        let (n, rate, samples) = (2e-3, 200.0, 12_000);
        let x = synthetic(n, 0.0, rate, samples, 3);
        let curve = allan_deviation(&x, 1.0 / rate);
        let f = fit(&curve).expect("fit");
        assert_eq!(f.white_noise_at, WhiteNoiseAt::OneSecond);
        let w = f.white_noise;
        assert!((w.value / n - 1.0).abs() <= 3.0 * w.relative_error);
        let RateRandomWalk::NotResolved {
            upper_bound,
            too_short,
            need_s,
            ..
        } = f.rate_random_walk
        else {
            panic!("resolved on white noise: {:?}", f.rate_random_walk);
        };
        assert!(too_short && need_s > samples as f64 / rate);
        assert!(upper_bound > 0.0);
        if f.bias_instability_upper_bound {
            let last = curve.points.last().expect("points");
            assert_eq!(f.bias_instability.tau, last.tau);
        }
    }

    /// When 1 s is beyond the curve, `N` is read where the slope is closest to −1/2.
    #[test]
    fn short_recordings_read_n_on_the_slope() {
        let (n, rate) = (1e-3, 1000.0);
        let x = synthetic(n, 0.0, rate, 5_000, 11);
        let f = fit(&allan_deviation(&x, 1.0 / rate)).expect("fit");
        assert_eq!(f.white_noise_at, WhiteNoiseAt::CurveEndsBeforeOneSecond);
        let w = f.white_noise;
        assert!(w.tau < 1.0);
        assert!((w.value / n - 1.0).abs() <= 3.0 * w.relative_error);
    }

    /// A random walk strong enough to spoil the −1/2 slope at 1 s: `N` is read below 1 s, within
    /// the confidence there plus the walk's exact share.
    #[test]
    fn a_strong_random_walk_moves_n_below_one_second() {
        let (n, k, rate) = (0.01, 0.05, 100.0);
        let x = synthetic(n, k, rate, 100_000, 5);
        let f = fit(&allan_deviation(&x, 1.0 / rate)).expect("fit");
        assert_eq!(f.white_noise_at, WhiteNoiseAt::BelowOneSecond);
        let w = f.white_noise;
        assert!(w.tau < 1.0 && (w.slope + 0.5).abs() <= SLOPE_TOLERANCE);
        let share = theory(n, k, w.tau) / (n / w.tau.sqrt()) - 1.0;
        let tol = 3.0 * w.relative_error + share;
        assert!(
            (w.value / n - 1.0).abs() <= tol,
            "N = {} at τ = {} against {n} (tolerance {tol})",
            w.value,
            w.tau
        );
        assert!(f.rate_random_walk.is_resolved());
    }

    #[test]
    fn too_short_and_constant_signals_are_errors() {
        let x = vec![1.0; 40];
        assert_eq!(
            fit(&allan_deviation(&x, 0.01)),
            Err(FitError::TooShort {
                samples: 40,
                needed: 45
            })
        );
        let x = vec![1.0; 400];
        assert!(matches!(
            fit(&allan_deviation(&x, 0.01)),
            Err(FitError::NoNoise { .. })
        ));
    }
}

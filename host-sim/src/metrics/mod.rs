//! Scoring an estimate against ground truth, streamed: RMSEs, NEES per error-state block, NIS
//! per sensor, update counts, and a bounded, decimated history for the plots.
//!
//! Errors follow the filter's error definition (right perturbation, see `estimator_core::eskf`):
//! `δθ = log(R̂ᵀ R)`, `δv = v − v̂`, `δp = p − p̂`, `δb = b − b̂`. The NEES of a block is
//! `δᵀ P_block⁻¹ δ` with the filter's own 3×3 covariance block; for a consistent filter its mean
//! over a run is near 3.

use crate::dataset::read::Truth;
use estimator_core::lie::{LieGroup, So3};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use std::collections::BTreeMap;

/// The blocks of the 15-dimensional error state, in order.
pub const BLOCKS: [&str; 5] = [
    "attitude",
    "velocity",
    "position",
    "gyro_bias",
    "accel_bias",
];

/// The filter's estimate at one instant, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// ns.
    pub t_ns: u64,
    /// Position, m (zero for an attitude-only filter).
    pub position: Vector3<f64>,
    /// `world_from_body`.
    pub attitude: So3<f64>,
    /// Velocity, m/s.
    pub velocity: Vector3<f64>,
    /// Gyro bias, rad/s.
    pub gyro_bias: Vector3<f64>,
    /// Accelerometer bias, m/s².
    pub accel_bias: Vector3<f64>,
    /// Covariance blocks in [`BLOCKS`] order; `None` for blocks the filter does not estimate.
    pub cov: [Option<Matrix3<f64>>; 5],
}

impl Estimate {
    /// 1σ of the 15 error-state components (NaN where not estimated).
    #[must_use]
    pub fn sigmas(&self) -> [f64; 15] {
        let mut s = [f64::NAN; 15];
        for (b, c) in self.cov.iter().enumerate() {
            if let Some(c) = c {
                for i in 0..3 {
                    s[3 * b + i] = c[(i, i)].max(0.0).sqrt();
                }
            }
        }
        s
    }
}

/// The error of an estimate against the truth, per block.
#[must_use]
pub fn errors(e: &Estimate, t: &Truth) -> [Vector3<f64>; 5] {
    [
        e.attitude.inverse().compose(&t.attitude).log(),
        t.velocity - e.velocity,
        t.position - e.position,
        t.gyro_bias - e.gyro_bias,
        t.accel_bias - e.accel_bias,
    ]
}

/// One point of the decimated history.
#[derive(Clone, Copy, Debug)]
pub struct HistoryPoint {
    /// s since the first sample.
    pub t: f64,
    /// Estimated position.
    pub est_position: Vector3<f64>,
    /// True position.
    pub true_position: Vector3<f64>,
    /// Errors, 15 components.
    pub error: [f64; 15],
    /// 1σ, 15 components.
    pub sigma: [f64; 15],
    /// Estimated gyro then accelerometer bias.
    pub est_bias: [f64; 6],
    /// True gyro then accelerometer bias.
    pub true_bias: [f64; 6],
}

/// A bounded history: when full, every other point is dropped and the stride doubles, so memory
/// stays constant however long the run.
#[derive(Clone, Debug)]
pub struct History<P> {
    points: Vec<P>,
    stride: u64,
    seen: u64,
}

impl<P> Default for History<P> {
    fn default() -> Self {
        Self {
            points: Vec::new(),
            stride: 1,
            seen: 0,
        }
    }
}

impl<P> History<P> {
    const CAPACITY: usize = 8192;

    /// Offers a point; it is kept if it falls on the current stride.
    pub fn push(&mut self, p: P) {
        if self.seen.is_multiple_of(self.stride) {
            self.points.push(p);
            if self.points.len() >= Self::CAPACITY {
                let mut i = 0;
                self.points.retain(|_| {
                    i += 1;
                    (i - 1) % 2 == 0
                });
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }

    /// The kept points.
    #[must_use]
    pub fn points(&self) -> &[P] {
        &self.points
    }
}

/// NIS and update counts of one sensor.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SensorStats {
    /// Accepted updates.
    pub accepted: u64,
    /// Updates rejected by the gate.
    pub rejected: u64,
    /// Measurements refused with an error (bad input).
    pub refused: u64,
    /// Sum of the NIS of accepted and rejected updates.
    #[serde(skip)]
    pub nis_sum: f64,
    /// Sum of the measurement dimensions (the NIS expectation).
    #[serde(skip)]
    pub dof_sum: f64,
    /// (s, NIS, dof) history for the plots.
    #[serde(skip)]
    pub history: History<(f64, f64, usize)>,
}

impl SensorStats {
    /// Mean NIS.
    #[must_use]
    pub fn nis_mean(&self) -> f64 {
        let n = (self.accepted + self.rejected) as f64;
        if n > 0.0 {
            self.nis_sum / n
        } else {
            f64::NAN
        }
    }

    /// Mean measurement dimension (the expected mean NIS).
    #[must_use]
    pub fn dof_mean(&self) -> f64 {
        let n = (self.accepted + self.rejected) as f64;
        if n > 0.0 {
            self.dof_sum / n
        } else {
            f64::NAN
        }
    }
}

/// The streaming accumulator.
#[derive(Clone, Debug, Default)]
pub struct Scorer {
    t0_ns: Option<u64>,
    n: u64,
    sq: [f64; 5],
    nees_sum: [f64; 5],
    nees_n: [u64; 5],
    /// Per-sensor NIS statistics.
    pub sensors: BTreeMap<String, SensorStats>,
    /// Decimated history.
    pub history: History<HistoryPoint>,
    /// Nanoseconds spent inside the filter.
    pub filter_ns: u128,
    /// IMU samples processed.
    pub imu_samples: u64,
    /// When `true`, the NEES of every scored sample is kept in `nees_steps` (Monte Carlo).
    pub keep_nees: bool,
    /// Per-sample NEES per block (NaN where not estimated), when `keep_nees`.
    pub nees_steps: Vec<[f64; 5]>,
    /// Sum of squared attitude errors and count, per reference filter (`baseline`).
    pub baselines: BTreeMap<String, (f64, u64)>,
}

/// The figures of one run (`metrics.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Metrics {
    /// Position RMSE over the run, m (no alignment: the world frame is absolute).
    pub ate_position_rmse_m: f64,
    /// Attitude RMSE, degrees (NaN, written `null`, when nothing was scored).
    pub attitude_rmse_deg: f64,
    /// Velocity RMSE, m/s.
    pub velocity_rmse_mps: f64,
    /// Mean NEES per block (expected 3 for a consistent filter).
    pub nees_mean: BTreeMap<String, f64>,
    /// Mean NIS per sensor.
    pub nis_mean: BTreeMap<String, f64>,
    /// Accepted updates per sensor.
    pub updates_accepted: BTreeMap<String, u64>,
    /// Gate-rejected updates per sensor.
    pub updates_rejected: BTreeMap<String, u64>,
    /// Refused (bad input) measurements per sensor.
    pub updates_refused: BTreeMap<String, u64>,
    /// Host time inside the filter per IMU sample, ns.
    pub filter_ns_per_imu_sample: f64,
    /// Samples scored.
    pub samples_scored: u64,
    /// Attitude RMSE of the reference filters run on the same data (Madgwick, Mahony), degrees.
    pub baseline_attitude_rmse_deg: BTreeMap<String, f64>,
}

impl Scorer {
    /// Scores one estimate against the truth at the same time.
    pub fn add(&mut self, e: &Estimate, truth: &Truth) {
        let t0 = *self.t0_ns.get_or_insert(e.t_ns);
        let errs = errors(e, truth);
        let mut error = [0.0; 15];
        let mut step = [f64::NAN; 5];
        for (b, d) in errs.iter().enumerate() {
            if let Some(p) = &e.cov[b] {
                self.sq[b] += d.norm_squared();
                if let Some(inv) = p.try_inverse() {
                    let nees = (d.transpose() * inv * d)[(0, 0)];
                    step[b] = nees;
                    self.nees_sum[b] += nees;
                    self.nees_n[b] += 1;
                }
            }
            for i in 0..3 {
                error[3 * b + i] = d[i];
            }
        }
        self.n += 1;
        if self.keep_nees {
            self.nees_steps.push(step);
        }
        let eb = [e.gyro_bias, e.accel_bias];
        let tb = [truth.gyro_bias, truth.accel_bias];
        let six = |v: [Vector3<f64>; 2]| [v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z];
        self.history.push(HistoryPoint {
            t: (e.t_ns.saturating_sub(t0)) as f64 * 1e-9,
            est_position: e.position,
            true_position: truth.position,
            error,
            sigma: e.sigmas(),
            est_bias: six(eb),
            true_bias: six(tb),
        });
    }

    /// Scores a reference filter's attitude against the truth.
    pub fn add_baseline(&mut self, name: &str, attitude: &So3<f64>, truth: &Truth) {
        let e = attitude
            .inverse()
            .compose(&truth.attitude)
            .log()
            .norm_squared();
        let entry = self.baselines.entry(name.to_string()).or_insert((0.0, 0));
        entry.0 += e;
        entry.1 += 1;
    }

    /// Records the outcome of one measurement.
    pub fn measurement(&mut self, sensor: &str, t_ns: u64, outcome: Outcome) {
        let t0 = *self.t0_ns.get_or_insert(t_ns);
        let s = self.sensors.entry(sensor.to_string()).or_default();
        match outcome {
            Outcome::Accepted { nis, dof } | Outcome::Rejected { nis, dof } => {
                if matches!(outcome, Outcome::Accepted { .. }) {
                    s.accepted += 1;
                } else {
                    s.rejected += 1;
                }
                s.nis_sum += nis;
                s.dof_sum += dof as f64;
                s.history
                    .push(((t_ns.saturating_sub(t0)) as f64 * 1e-9, nis, dof));
            }
            Outcome::Refused => s.refused += 1,
        }
    }

    /// The figures so far.
    #[must_use]
    pub fn metrics(&self) -> Metrics {
        let n = self.n.max(1) as f64;
        let rmse = |b: usize| (self.sq[b] / n).sqrt();
        let mut nees_mean = BTreeMap::new();
        for (b, name) in BLOCKS.iter().enumerate() {
            if self.nees_n[b] > 0 {
                nees_mean.insert(
                    (*name).to_string(),
                    self.nees_sum[b] / self.nees_n[b] as f64,
                );
            }
        }
        let map = |f: &dyn Fn(&SensorStats) -> u64| {
            self.sensors
                .iter()
                .map(|(k, v)| (k.clone(), f(v)))
                .collect()
        };
        Metrics {
            ate_position_rmse_m: if self.nees_n[2] > 0 {
                rmse(2)
            } else {
                f64::NAN
            },
            // Nothing scored is no number (`null` in metrics.json), never 0.
            attitude_rmse_deg: if self.n > 0 {
                rmse(0).to_degrees()
            } else {
                f64::NAN
            },
            velocity_rmse_mps: if self.nees_n[1] > 0 {
                rmse(1)
            } else {
                f64::NAN
            },
            nees_mean,
            nis_mean: self
                .sensors
                .iter()
                .map(|(k, v)| (k.clone(), v.nis_mean()))
                .collect(),
            updates_accepted: map(&|s| s.accepted),
            updates_rejected: map(&|s| s.rejected),
            updates_refused: map(&|s| s.refused),
            filter_ns_per_imu_sample: if self.imu_samples > 0 {
                self.filter_ns as f64 / self.imu_samples as f64
            } else {
                f64::NAN
            },
            samples_scored: self.n,
            baseline_attitude_rmse_deg: self
                .baselines
                .iter()
                .map(|(k, (sq, n))| (k.clone(), (sq / (*n).max(1) as f64).sqrt().to_degrees()))
                .collect(),
        }
    }
}

/// What became of one measurement, as the scorer needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    /// Accepted with this NIS and measurement dimension.
    Accepted {
        /// NIS.
        nis: f64,
        /// Dimension.
        dof: usize,
    },
    /// Rejected by the gate.
    Rejected {
        /// NIS.
        nis: f64,
        /// Dimension.
        dof: usize,
    },
    /// Refused with an error.
    Refused,
}

/// Linear interpolation of the truth between two rows at `t_ns` (slerp for the attitude).
#[must_use]
pub fn interpolate_truth(a: &Truth, b: &Truth, t_ns: u64) -> Truth {
    if b.t_ns <= a.t_ns {
        return *a;
    }
    let s = (t_ns.saturating_sub(a.t_ns)) as f64 / (b.t_ns - a.t_ns) as f64;
    let lerp = |x: &Vector3<f64>, y: &Vector3<f64>| x + (y - x) * s;
    Truth {
        t_ns,
        position: lerp(&a.position, &b.position),
        attitude: a.attitude.interpolate(&b.attitude, s),
        velocity: lerp(&a.velocity, &b.velocity),
        gyro_bias: lerp(&a.gyro_bias, &b.gyro_bias),
        accel_bias: lerp(&a.accel_bias, &b.accel_bias),
    }
}

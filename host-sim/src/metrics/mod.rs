//! Scoring an estimate against ground truth, streamed: RMSEs, NEES per error-state block, NIS
//! per sensor, update counts, and a bounded, decimated history for the plots.
//!
//! Errors follow the filter's error definition (right perturbation, see `estimator_core::eskf`):
//! `δθ = log(R̂ᵀ R)`, `δv = v − v̂`, `δp = p − p̂`, `δb = b − b̂`. The NEES of a block is
//! `δᵀ P_block⁻¹ δ` with the filter's own 3×3 covariance block; for a consistent filter its mean
//! over a run is near 3.
//!
//! Two further figures compare with published references: the attitude RMSE from 2 s after the
//! first ground-truth sample (so that every filter is judged after the same start), and BROAD's
//! total / heading / inclination RMSEs inside a trial's movement intervals ([`broad`]).
//!
//! The trajectory metrics users know from evo — the absolute trajectory error after an
//! alignment and the relative pose error over 1 s — are computed from the scored pose pairs
//! ([`trajectory`]); so is the attitude RMSE with the heading offset removed, the score of a run
//! without a heading reference (IMU only). The pairs are kept as they are written to
//! `estimate.tum` and `groundtruth.tum` (positions to the µm, quaternions to 1e-9), so that evo
//! on those two files reproduces the figures; they take 120 bytes per scored sample.

pub mod broad;
pub mod heading;
pub mod trajectory;

use crate::dataset::check::DataWarning;
use crate::dataset::read::{Dataset, Truth};
use crate::dataset::DatasetError;
use broad::{broad_error, in_intervals, BroadAccumulator, BroadRmse};
use estimator_core::lie::{LieGroup, So3};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use trajectory::{Alignment, Ate, Pose, PosePair, Rpe, DEFAULT_RPE_DELTA};

/// The attitude RMSE after the start scores from this long after the first truth sample, ns.
pub const AFTER_START_NS: u64 = 2_000_000_000;

/// The alignment of the `ate` object of `metrics.json` (evo's `-a`); every alignment is in
/// `ate_by_alignment`.
pub const ATE_ALIGNMENT: Alignment = Alignment::Se3;

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
    /// Whether the navigator reported each block valid (attitude: tilt and heading), in
    /// [`BLOCKS`] order; `None` when it reports no such thing.
    pub valid: Option<[bool; 5]>,
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
    /// The navigator's validity of each block, when it reports one.
    pub valid: Option<[bool; 5]>,
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
    /// (s, NIS, dof, accepted) history for the plots (`false`: gated out).
    #[serde(skip)]
    pub history: History<(f64, f64, usize, bool)>,
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
    /// What the run assumed for want of an optional file (copied to `metrics.json`).
    pub warnings: Vec<String>,
    /// What the data had wrong that the run survived (copied to `metrics.json`).
    pub data_warnings: Vec<DataWarning>,
    /// BROAD's movement intervals (ns, inclusive); `None`: BROAD's metric is not computed.
    movement: Option<Vec<(u64, u64)>>,
    /// BROAD's errors inside the movement intervals.
    broad: BroadAccumulator,
    /// Time of the first ground-truth sample, ns (else the first scored sample's).
    truth_start_ns: Option<u64>,
    /// Sum of squared attitude errors and count from [`AFTER_START_NS`] after the truth start.
    after_start: (f64, u64),
    /// The RPE's delta (`None`: [`DEFAULT_RPE_DELTA`], 1 s).
    pub rpe_delta: Option<trajectory::Delta>,
    /// The scored (estimate, truth) pose pairs, as written to the TUM files.
    pairs: Vec<PosePair>,
    /// Whether a scored estimate had a position (a position covariance block).
    positions: bool,
    /// The dataset's fault intervals (`faults.csv`), for the plots.
    pub faults: Vec<crate::dataset::read::FaultInterval>,
    /// Whether the dataset has a heading reference; `None` until [`Scorer::note_run`].
    heading_reference: Option<bool>,
    /// Where the run comes from (copied to `metrics.json`).
    pub provenance: Provenance,
    /// The heading's settling and false-valid tallies ([`heading`]).
    heading: heading::HeadingAccumulator,
}

/// Where a run comes from, recorded in `metrics.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Provenance {
    /// The command line of the process (`std::env::args_os`, lossily as UTF-8).
    pub command_line: Vec<String>,
    /// `host-sim`'s version.
    pub host_sim_version: String,
    /// The dataset folder the replay read.
    pub dataset: Option<String>,
    /// The scenario simulated, for `host-sim run`.
    pub scenario: Option<String>,
    /// The RNG seed of the simulation, for `host-sim run`.
    pub seed: Option<u64>,
    /// `f32` or `f64`.
    pub precision: Option<String>,
}

impl Default for Provenance {
    /// This process's command line and host-sim's version; the rest unknown.
    fn default() -> Self {
        Self {
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            host_sim_version: env!("CARGO_PKG_VERSION").to_string(),
            dataset: None,
            scenario: None,
            seed: None,
            precision: None,
        }
    }
}

/// `x` as `{:.decimals}` writes it and a reader parses it back.
fn as_written(x: f64, decimals: usize) -> f64 {
    format!("{x:.decimals$}").parse().unwrap_or(x)
}

/// A pose as `estimate.tum` and `groundtruth.tum` hold it: position to 6 decimals, the
/// quaternion's components to 9 (normalised when read, as evo does).
fn written_pose(position: &Vector3<f64>, attitude: &So3<f64>) -> Pose {
    let q = attitude.quaternion();
    let w = |x: f64| as_written(x, 9);
    Pose {
        position: position.map(|x| as_written(x, 6)),
        attitude: So3::from_wxyz(w(q.w), w(q.i), w(q.j), w(q.k)).unwrap_or(*attitude),
    }
}

/// The figures of one run (`metrics.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Metrics {
    /// Position RMSE over the run, m (no alignment: the world frame is absolute).
    pub ate_position_rmse_m: f64,
    /// Absolute trajectory error (translation part) after the [`ATE_ALIGNMENT`] alignment, with
    /// evo's statistics ([`trajectory`]); `None` (`null`) when the position is not estimated or
    /// nothing was scored.
    pub ate: Option<Ate>,
    /// The ATE after each alignment (`none`, `se3`, `yaw`, `origin`).
    pub ate_by_alignment: BTreeMap<String, Ate>,
    /// Relative pose error (translation part) over [`DEFAULT_RPE_DELTA`], with evo's
    /// statistics; `None` (`null`) when the position is not estimated or no pair spans the delta.
    pub rpe: Option<Rpe>,
    /// Attitude RMSE, degrees (NaN, written `null`, when nothing was scored).
    pub attitude_rmse_deg: f64,
    /// Attitude RMSE with the heading offset removed: the constant rotation about the world
    /// vertical that minimises the error over the whole run is applied to the estimate first
    /// ([`trajectory::attitude_yaw_aligned`]), degrees. The score of a run without a heading
    /// reference.
    pub attitude_rmse_yaw_aligned_deg: f64,
    /// That heading offset, degrees.
    pub attitude_yaw_offset_deg: f64,
    /// Whether the run has a heading reference (a magnetometer it fuses, GNSS or a camera);
    /// `false`: IMU only (or `use_magnetometer = false`), the heading is arbitrary and
    /// `attitude_rmse_yaw_aligned_deg` is the score.
    pub heading_reference: Option<bool>,
    /// Attitude RMSE (geodesic angle) from 2 s after the first ground-truth sample, degrees
    /// (NaN, written `null`, when nothing was scored there).
    pub attitude_rmse_after_2s_deg: f64,
    /// Samples scored from 2 s after the first ground-truth sample.
    pub samples_scored_after_2s: u64,
    /// BROAD's RMSEs inside the movement intervals ([`broad`]); `None` (`null`) without
    /// movement intervals.
    pub broad: Option<BroadRmse>,
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
    /// What the run assumed for want of an optional file.
    pub warnings: Vec<String>,
    /// What the data had wrong that the run survived, each with its file and line: a last line
    /// cut short, gaps, sensors that start late or stop early, refused samples
    /// ([`crate::dataset::check`]).
    pub data_warnings: Vec<DataWarning>,
    /// Where the run comes from.
    pub provenance: Provenance,
    /// The heading after the first motion, for a navigator's run whose body moves
    /// ([`heading::HeadingScore`]); `None` (`null`) otherwise.
    pub heading: Option<heading::HeadingScore>,
}

impl Scorer {
    /// Scores BROAD's metric inside these intervals (ns, inclusive, ordered and disjoint, as
    /// `movement.csv` holds them); `None` turns it off.
    pub fn set_movement(&mut self, intervals: Option<Vec<(u64, u64)>>) {
        self.movement = intervals;
    }

    /// The time of the first ground-truth sample, from which [`AFTER_START_NS`] is counted
    /// (without it, the first scored sample's time).
    pub fn set_truth_start(&mut self, t_ns: u64) {
        self.truth_start_ns = Some(t_ns);
    }

    /// This scorer with the dataset's movement intervals (`movement.csv`) and first
    /// ground-truth time, for what was not set already.
    ///
    /// # Errors
    /// A malformed `movement.csv` or first ground-truth row, naming the file and line.
    pub fn for_dataset(mut self, dir: &Path) -> Result<Self, DatasetError> {
        if self.movement.is_none() {
            let (movement, warnings) = crate::dataset::read::movement_checked(dir)?;
            self.movement = movement;
            self.data_warnings.extend(warnings);
        }
        if self.truth_start_ns.is_none() {
            self.truth_start_ns = crate::dataset::read::first_truth_ns(dir)?;
        }
        let (faults, warnings) = crate::dataset::read::read_faults_checked(dir)?;
        self.faults = faults;
        self.data_warnings.extend(warnings);
        Ok(self)
    }

    /// Adds `warnings` about the files of the dataset folder `dir`, then names every file as
    /// the run's provenance names the folder (the folder as the user gave it), in file and
    /// line order, each once.
    pub fn add_data_warnings(&mut self, dir: &Path, warnings: Vec<DataWarning>) {
        self.data_warnings.extend(warnings);
        if let Some(shown) = self.provenance.dataset.clone() {
            self.data_warnings = std::mem::take(&mut self.data_warnings)
                .into_iter()
                .map(|w| w.relocated(dir, Path::new(&shown)))
                .collect();
        }
        self.data_warnings.sort();
        self.data_warnings.dedup();
    }

    /// Records what the dataset holds and the precision of the run: the reader's warnings and
    /// data warnings, the presence of a heading reference, the dataset folder (unless already
    /// set) and the precision.
    pub fn note_run(&mut self, ds: &Dataset, precision: &str) {
        self.warnings.extend(ds.warnings.iter().cloned());
        self.data_warnings.extend(ds.data_warnings.iter().cloned());
        self.heading_reference = Some(ds.mag.is_some() || ds.gnss.is_some() || ds.camera.is_some());
        if self.provenance.dataset.is_none() {
            self.provenance.dataset = Some(ds.dir.display().to_string());
        }
        self.provenance.precision = Some(precision.to_string());
    }

    /// The time all history points are counted from, ns.
    #[must_use]
    pub fn t0_ns(&self) -> Option<u64> {
        self.t0_ns
    }

    /// The scored (estimate, truth) pose pairs, in time order.
    #[must_use]
    pub fn pairs(&self) -> &[PosePair] {
        &self.pairs
    }

    /// Scores one estimate against the truth at the same time.
    pub fn add(&mut self, e: &Estimate, truth: &Truth) {
        let t0 = *self.t0_ns.get_or_insert(e.t_ns);
        self.positions |= e.cov[2].is_some();
        self.pairs.push(PosePair {
            t_ns: e.t_ns,
            estimate: written_pose(&e.position, &e.attitude),
            truth: written_pose(&truth.position, &truth.attitude),
        });
        let truth_start = *self.truth_start_ns.get_or_insert(truth.t_ns);
        self.heading.add(e, truth);
        let errs = errors(e, truth);
        if truth.t_ns >= truth_start.saturating_add(AFTER_START_NS) {
            self.after_start.0 += errs[0].norm_squared();
            self.after_start.1 += 1;
        }
        let moving = self
            .movement
            .as_ref()
            .is_some_and(|intervals| in_intervals(intervals, truth.t_ns));
        if moving {
            self.broad.add(&broad_error(
                &e.attitude.quaternion(),
                &truth.attitude.quaternion(),
            ));
        }
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
        // The attitude's NEES (block 0), when it has a covariance, for BROAD's 3σ share.
        if moving && step[0].is_finite() {
            self.broad.add_nees(step[0]);
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
            valid: e.valid,
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
                let accepted = matches!(outcome, Outcome::Accepted { .. });
                if accepted {
                    s.accepted += 1;
                } else {
                    s.rejected += 1;
                }
                s.nis_sum += nis;
                s.dof_sum += dof as f64;
                s.history
                    .push(((t_ns.saturating_sub(t0)) as f64 * 1e-9, nis, dof, accepted));
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
        let (ate, ate_by_alignment, rpe) = if self.positions {
            let all: BTreeMap<String, Ate> = Alignment::ALL
                .iter()
                .filter_map(|a| trajectory::ate(&self.pairs, *a))
                .map(|a| (a.alignment.name().to_string(), a))
                .collect();
            (
                all.get(ATE_ALIGNMENT.name()).copied(),
                all,
                trajectory::rpe(&self.pairs, self.rpe_delta.unwrap_or(DEFAULT_RPE_DELTA)),
            )
        } else {
            (None, BTreeMap::new(), None)
        };
        let yaw = trajectory::attitude_yaw_aligned(&self.pairs);
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
            ate,
            ate_by_alignment,
            rpe,
            // Nothing scored is no number (`null` in metrics.json), never 0.
            attitude_rmse_deg: if self.n > 0 {
                rmse(0).to_degrees()
            } else {
                f64::NAN
            },
            attitude_rmse_yaw_aligned_deg: yaw.map_or(f64::NAN, |y| y.rmse_rad.to_degrees()),
            attitude_yaw_offset_deg: yaw.map_or(f64::NAN, |y| y.offset_rad.to_degrees()),
            heading_reference: self.heading_reference,
            attitude_rmse_after_2s_deg: if self.after_start.1 > 0 {
                (self.after_start.0 / self.after_start.1 as f64)
                    .sqrt()
                    .to_degrees()
            } else {
                f64::NAN
            },
            samples_scored_after_2s: self.after_start.1,
            broad: self.movement.as_ref().map(|_| self.broad.rmse()),
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
            warnings: self.warnings.clone(),
            data_warnings: self.data_warnings.clone(),
            provenance: self.provenance.clone(),
            heading: self.heading.score(),
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

/// Rows of the truth farther apart than this many of its shortest row interval have rows missing
/// between them (a motion-capture system that lost the marker leaves its rows out): no time
/// between them is scored. A regularly sampled truth with one row missing has an interval of 2;
/// 1.5 lies halfway and lets the timestamps jitter by up to half an interval. BROAD scores only
/// the samples with an optical truth (its `calculateRMSE` skips the NaN rows); interpolating
/// across a lost marker would score the interpolation, not the estimate (on the shared BROAD
/// trial 28, 1.4 s of such gaps during 700 °/s turns raise real-time VQF's inclination RMSE
/// from its published 1.21° to 1.89°).
pub const TRUTH_GAP_FACTOR: f64 = 1.5;

/// The truth's sampling: the shortest interval between consecutive rows seen so far, which tells
/// a lost row from a sampled one ([`TRUTH_GAP_FACTOR`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TruthSpacing {
    /// The shortest positive row interval so far, ns (0: none seen).
    shortest_ns: u64,
}

impl TruthSpacing {
    /// Takes in the interval between consecutive rows at `a_ns` and `b_ns`.
    pub fn observe(&mut self, a_ns: u64, b_ns: u64) {
        let dt = b_ns.saturating_sub(a_ns);
        if dt > 0 && (self.shortest_ns == 0 || dt < self.shortest_ns) {
            self.shortest_ns = dt;
        }
    }

    /// The truth at `t_ns` between the consecutive rows `a` and `b` ([`interpolate_truth`]),
    /// or `None` when they are more than [`TRUTH_GAP_FACTOR`] shortest intervals apart (rows
    /// lost between them); takes in their interval first.
    ///
    /// ```
    /// use estimator_core::lie::{LieGroup, So3};
    /// use host_sim::dataset::read::Truth;
    /// use host_sim::metrics::TruthSpacing;
    /// use nalgebra::Vector3;
    /// let zero = Vector3::zeros();
    /// let row = |t_ns| Truth {
    ///     t_ns,
    ///     position: zero,
    ///     attitude: So3::identity(),
    ///     velocity: zero,
    ///     gyro_bias: zero,
    ///     accel_bias: zero,
    /// };
    /// let mut spacing = TruthSpacing::default();
    /// assert!(spacing.between(&row(0), &row(10), 5).is_some());
    /// assert!(spacing.between(&row(10), &row(20), 15).is_some());
    /// // Two rows lost: nothing is scored between the rows around them.
    /// assert!(spacing.between(&row(20), &row(50), 35).is_none());
    /// ```
    #[must_use]
    pub fn between(&mut self, a: &Truth, b: &Truth, t_ns: u64) -> Option<Truth> {
        self.observe(a.t_ns, b.t_ns);
        let dt = b.t_ns.saturating_sub(a.t_ns);
        let lost = self.shortest_ns > 0 && dt as f64 > TRUTH_GAP_FACTOR * self.shortest_ns as f64;
        (!lost).then(|| interpolate_truth(a, b, t_ns))
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(t_ns: u64) -> Truth {
        Truth {
            t_ns,
            position: Vector3::zeros(),
            attitude: So3::identity(),
            velocity: Vector3::zeros(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
        }
    }

    /// An attitude-only estimate rotated by `deg` about the world vertical.
    fn heading_off(t_ns: u64, deg: f64) -> Estimate {
        Estimate {
            t_ns,
            position: Vector3::zeros(),
            attitude: So3::exp(&Vector3::new(0.0, 0.0, deg.to_radians())),
            velocity: Vector3::zeros(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
            cov: [Some(Matrix3::identity()), None, None, None, None],
            valid: None,
        }
    }

    const S: u64 = 1_000_000_000;

    #[test]
    fn broad_scores_only_inside_the_movement_intervals() {
        let mut scorer = Scorer::default();
        scorer.set_movement(Some(vec![(2 * S, 3 * S)]));
        for (t, deg) in [(S, 50.0), (2 * S, 3.0), (3 * S, 4.0), (4 * S, 50.0)] {
            scorer.add(&heading_off(t, deg), &truth(t));
        }
        let m = scorer.metrics();
        let b = m.broad.expect("movement given");
        assert_eq!(b.samples, 2);
        assert!((b.total_deg - 12.5_f64.sqrt()).abs() < 1e-9, "{b:?}");
        assert!((b.heading_deg - 12.5_f64.sqrt()).abs() < 1e-9, "{b:?}");
        assert!(b.inclination_deg.abs() < 1e-6, "{b:?}");
        assert_eq!(m.samples_scored, 4);
    }

    #[test]
    fn nothing_in_the_intervals_is_null_not_zero_and_no_intervals_is_no_broad() {
        let mut scorer = Scorer::default();
        scorer.set_movement(Some(vec![(10 * S, 11 * S)]));
        scorer.add(&heading_off(S, 5.0), &truth(S));
        let b = scorer.metrics().broad.expect("movement given");
        assert_eq!(b.samples, 0);
        assert!(b.total_deg.is_nan() && b.heading_deg.is_nan() && b.inclination_deg.is_nan());
        let json = serde_json::to_value(scorer.metrics()).expect("json");
        assert!(json["broad"]["total_deg"].is_null(), "{json}");

        let mut plain = Scorer::default();
        plain.add(&heading_off(S, 5.0), &truth(S));
        assert!(plain.metrics().broad.is_none());
    }

    #[test]
    fn the_after_start_rmse_counts_from_two_seconds_after_the_first_truth() {
        let mut scorer = Scorer::default();
        // The first truth is at 0; scoring starts later (after the filter's alignment).
        scorer.set_truth_start(0);
        for (t, deg) in [(S, 30.0), (2 * S - 1, 30.0), (2 * S, 3.0), (5 * S, 4.0)] {
            scorer.add(&heading_off(t, deg), &truth(t));
        }
        let m = scorer.metrics();
        assert_eq!(m.samples_scored_after_2s, 2);
        assert!((m.attitude_rmse_after_2s_deg - 12.5_f64.sqrt()).abs() < 1e-9);

        // Without a truth start, the first scored sample starts the count.
        let mut scorer = Scorer::default();
        for t in [S, 2 * S, 3 * S] {
            scorer.add(&heading_off(t, 1.0), &truth(t));
        }
        let m = scorer.metrics();
        assert_eq!(m.samples_scored_after_2s, 1);
        assert!(Scorer::default()
            .metrics()
            .attitude_rmse_after_2s_deg
            .is_nan());
    }
}

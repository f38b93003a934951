//! The fault bench's figures from the epochs of one run: detection and recovery time of a
//! fault, and the epochs where a quantity was reported valid while its error was outside kσ.

use super::epochs::{AidStatus, Epoch, ErrorState};
use crate::dataset::read::FaultInterval;
use serde::Serialize;

/// How long the recovered condition must hold without interruption, ns.
pub const RECOVERY_HOLD_NS: u64 = 1_000_000_000;

/// The quantities of the false-valid count, in [`crate::metrics::BLOCKS`] order.
pub const QUANTITIES: [&str; 5] = [
    "attitude",
    "velocity",
    "position",
    "gyro_bias",
    "accel_bias",
];

/// How a fault shows in the navigator's report, and what counts as recovered from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultRule {
    /// GNSS position step: detected by position `fixes_disagree` or GNSS `rejected`.
    GnssStep,
    /// Frozen receiver: detected by GNSS `faulty`.
    GnssFrozen,
    /// GNSS outage: detected by GNSS `stale`.
    GnssOutage,
    /// Magnetometer fault (rotated, disturbed): detected by magnetometer `rejected` or `faulty`.
    Magnetometer,
    /// Barometer step: detected by barometer `rejected`.
    BaroStep,
    /// IMU fault (clipping, stuck axis): detected by `imu_fault` = 1.
    Imu,
}

/// `|e| ≤ k σ` on every axis (false where σ or the error is not finite).
fn within(error: &nalgebra::Vector3<f64>, sigma: &nalgebra::Vector3<f64>, k: f64) -> bool {
    error
        .iter()
        .zip(sigma.iter())
        .all(|(e, s)| e.is_finite() && s.is_finite() && e.abs() <= k * s)
}

impl FaultRule {
    /// The rule of a `faults.csv` row; `None` for a fault without a single start (GNSS
    /// outliers) or one the bench does not know.
    #[must_use]
    pub fn of(fault: &FaultInterval) -> Option<Self> {
        Some(match (fault.sensor.as_str(), fault.kind.as_str()) {
            ("gnss", "step") => Self::GnssStep,
            ("gnss", "frozen") => Self::GnssFrozen,
            ("gnss", "outage") => Self::GnssOutage,
            ("mag", "rotated" | "disturbance") => Self::Magnetometer,
            ("baro", "step") => Self::BaroStep,
            ("imu", "clip" | "stuck") => Self::Imu,
            _ => return None,
        })
    }

    /// `true` when the report of `e` shows the fault.
    #[must_use]
    pub fn detects(self, e: &Epoch) -> bool {
        use super::epochs::Validity::FixesDisagree;
        match self {
            Self::GnssStep => e.position == FixesDisagree || e.gnss == AidStatus::Rejected,
            Self::GnssFrozen => e.gnss == AidStatus::Faulty,
            Self::GnssOutage => e.gnss == AidStatus::Stale,
            Self::Magnetometer => {
                matches!(e.magnetometer, AidStatus::Rejected | AidStatus::Faulty)
            }
            Self::BaroStep => e.barometer == AidStatus::Rejected,
            Self::Imu => e.imu_fault,
        }
    }

    /// `true` when, at `e`, the faulty sensor is fused again and the quantity it affects is
    /// valid with its error within 3σ (see [`FaultRule::describe_recovery`]).
    #[must_use]
    pub fn recovered(self, e: &Epoch) -> bool {
        let Some(ErrorState { error, sigma }) = &e.state else {
            return false;
        };
        let attitude_ok =
            e.tilt.is_valid() && e.heading.is_valid() && within(&error[0], &sigma[0], 3.0);
        match self {
            Self::GnssStep | Self::GnssFrozen | Self::GnssOutage => {
                e.gnss == AidStatus::Fused
                    && e.position.is_valid()
                    && within(&error[2], &sigma[2], 3.0)
            }
            Self::BaroStep => {
                let (ez, sz) = (error[2].z, sigma[2].z);
                e.barometer == AidStatus::Fused
                    && e.position.is_valid()
                    && ez.is_finite()
                    && sz.is_finite()
                    && ez.abs() <= 3.0 * sz
            }
            Self::Magnetometer => e.magnetometer == AidStatus::Fused && attitude_ok,
            Self::Imu => attitude_ok && e.velocity.is_valid() && within(&error[1], &sigma[1], 3.0),
        }
    }

    /// The recovery target, s: 7 s for the position after a GNSS fault, 5 s for the height
    /// after a barometer step; `None` where none is set.
    #[must_use]
    pub fn target_s(self) -> Option<f64> {
        match self {
            Self::GnssStep | Self::GnssFrozen | Self::GnssOutage => Some(7.0),
            Self::BaroStep => Some(5.0),
            Self::Magnetometer | Self::Imu => None,
        }
    }

    /// What the report must show for the fault to count as detected.
    #[must_use]
    pub fn describe_detection(self) -> &'static str {
        match self {
            Self::GnssStep => "position fixes_disagree or gnss rejected",
            Self::GnssFrozen => "gnss faulty",
            Self::GnssOutage => "gnss stale",
            Self::Magnetometer => "magnetometer rejected or faulty",
            Self::BaroStep => "barometer rejected",
            Self::Imu => "imu_fault = 1",
        }
    }

    /// What must hold, for 1 s without interruption, for the run to count as recovered.
    #[must_use]
    pub fn describe_recovery(self) -> &'static str {
        match self {
            Self::GnssStep | Self::GnssFrozen | Self::GnssOutage => {
                "gnss fused, position valid, position error within 3σ on every axis"
            }
            Self::BaroStep => "barometer fused, position valid, vertical position error within 3σ",
            Self::Magnetometer => {
                "magnetometer fused, tilt and heading valid, attitude error within 3σ on every body axis"
            }
            Self::Imu => {
                "tilt, heading and velocity valid, attitude and velocity errors within 3σ on every axis"
            }
        }
    }
}

/// Seconds from `start_ns` to the first epoch at or after it whose report shows the fault;
/// `None` when none does.
#[must_use]
pub fn detection_s(epochs: &[Epoch], start_ns: u64, rule: FaultRule) -> Option<f64> {
    epochs
        .iter()
        .find(|e| e.t_ns >= start_ns && rule.detects(e))
        .map(|e| (e.t_ns - start_ns) as f64 * 1e-9)
}

/// The epochs before `start_ns` whose report already shows what detects the fault (false
/// alarms, or ordinary gate rejections for rules that count a rejection).
#[must_use]
pub fn alarms_before(epochs: &[Epoch], start_ns: u64, rule: FaultRule) -> u64 {
    epochs
        .iter()
        .take_while(|e| e.t_ns < start_ns)
        .filter(|e| rule.detects(e))
        .count() as u64
}

/// Seconds from `end_ns` to the first epoch at or after it from which [`FaultRule::recovered`]
/// holds at every epoch for at least [`RECOVERY_HOLD_NS`]; `None` when that never happens
/// before the run ends.
#[must_use]
pub fn recovery_s(epochs: &[Epoch], end_ns: u64, rule: FaultRule) -> Option<f64> {
    let mut from: Option<u64> = None;
    for e in epochs.iter().filter(|e| e.t_ns >= end_ns) {
        if rule.recovered(e) {
            let f = *from.get_or_insert(e.t_ns);
            if e.t_ns - f >= RECOVERY_HOLD_NS {
                return Some((f - end_ns) as f64 * 1e-9);
            }
        } else {
            from = None;
        }
    }
    None
}

/// Epoch-axes of one quantity reported valid, and those of them with the error outside 3σ and
/// 4σ of the reported 1σ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Tally {
    /// Epoch-axes where the quantity was reported valid and both error and σ are finite.
    pub valid_epoch_axes: u64,
    /// Of those, the ones with `|error| > 3σ`.
    pub outside_3sigma: u64,
    /// Of those, the ones with `|error| > 4σ`.
    pub outside_4sigma: u64,
}

impl Tally {
    /// Adds another tally.
    pub fn add(&mut self, o: &Tally) {
        self.valid_epoch_axes += o.valid_epoch_axes;
        self.outside_3sigma += o.outside_3sigma;
        self.outside_4sigma += o.outside_4sigma;
    }
}

/// The false-valid tallies of the [`QUANTITIES`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FalseValid {
    /// One tally per quantity, in [`QUANTITIES`] order.
    pub quantities: [Tally; 5],
}

impl FalseValid {
    /// Adds another run's tallies.
    pub fn add(&mut self, o: &FalseValid) {
        for (a, b) in self.quantities.iter_mut().zip(&o.quantities) {
            a.add(b);
        }
    }

    /// The sum over the quantities.
    #[must_use]
    pub fn total(&self) -> Tally {
        let mut t = Tally::default();
        for q in &self.quantities {
            t.add(q);
        }
        t
    }
}

/// The probability that a standard normal variable lies outside `±k`.
#[must_use]
pub fn gaussian_outside(k: f64) -> f64 {
    statrs::function::erf::erfc(k / std::f64::consts::SQRT_2)
}

/// Counts, over every epoch with an error state, the axes of each quantity reported valid and
/// those of them outside 3σ and 4σ. The attitude counts as reported valid when tilt and heading
/// both are (its axes are body axes, each mixing the two); position and velocity are per world
/// axis, the biases per sensor axis.
#[must_use]
pub fn false_valid(epochs: &[Epoch]) -> FalseValid {
    let mut fv = FalseValid::default();
    for e in epochs {
        let Some(s) = &e.state else {
            continue;
        };
        let valid = [
            e.tilt.is_valid() && e.heading.is_valid(),
            e.velocity.is_valid(),
            e.position.is_valid(),
            e.gyro_bias.is_valid(),
            e.accel_bias.is_valid(),
        ];
        for (q, tally) in fv.quantities.iter_mut().enumerate() {
            if !valid[q] {
                continue;
            }
            for (err, sigma) in s.error[q].iter().zip(s.sigma[q].iter()) {
                if !(err.is_finite() && sigma.is_finite()) {
                    continue;
                }
                tally.valid_epoch_axes += 1;
                if err.abs() > 3.0 * sigma {
                    tally.outside_3sigma += 1;
                }
                if err.abs() > 4.0 * sigma {
                    tally.outside_4sigma += 1;
                }
            }
        }
    }
    fv
}

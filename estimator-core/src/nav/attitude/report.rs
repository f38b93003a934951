//! What the navigator says after every call: the estimate's validity and the sensors' health.

use crate::eskf::UpdateOutcome;
use crate::lie::So3;
use crate::Real;
use nalgebra::Vector3;

/// Why a quantity is not valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Reason {
    /// The start-up window is still being collected.
    Starting,
    /// Its 1σ is above the configured limit.
    Uncertain,
    /// Heading without a magnetometer: only relative to the start.
    NoMagnetometer,
    /// Heading without a magnetometer, in an INS: the GNSS track has not yet told it (the
    /// bank of yaw hypotheses is not yet sure of one).
    HeadingUnresolved,
    /// No position fix has been fused yet (an INS navigator aligns its attitude meanwhile).
    NoFix,
    /// The position fixes have disagreed with the estimate for the last second or more: one
    /// of them is wrong, and the navigator cannot yet say which.
    FixesDisagree,
    /// The state was just reset to the aiding sensor after a long disagreement, and is not
    /// yet confirmed by it.
    Reset,
    /// The IMU is faulty (clipped or stuck): the prediction is not trusted.
    ImuFault,
}

/// Whether a quantity of the estimate can be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Validity {
    /// Within its configured 1σ limit.
    Valid,
    /// Not to be used, and why.
    Invalid(Reason),
}

impl Validity {
    /// `true` for [`Validity::Valid`].
    #[must_use]
    pub fn is_valid(&self) -> bool {
        matches!(self, Self::Valid)
    }
}

/// The magnetometer's state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MagneticStatus {
    /// No magnetometer configured.
    NotConfigured,
    /// Configured, no block fused yet.
    Waiting,
    /// The last block agreed with the reference field and was fused.
    Fused,
    /// The last block's norm or dip angle disagreed with the reference: not fused.
    Disturbed,
    /// The last block was consistent with the reference but its heading innovation failed
    /// the gate.
    Rejected,
    /// The magnetometer's samples have repeated bit for bit for `stuck_s` (stuck or
    /// saturated): not used until they change.
    Stuck,
}

/// Something the navigator did on its own in the last call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Event {
    /// The filter started from the start-up window.
    Started,
    /// An IMU gap longer than `max_dt`: the navigator started again.
    Realigned,
    /// Consecutive accelerometer blocks failed the gate: the tilt covariance was widened to
    /// the innovation and the block fused.
    TiltWidened,
    /// Consecutive magnetometer blocks failed the gate: the heading covariance was widened.
    HeadingWidened,
    /// A steady field different from the reference was taken as the new reference.
    NewMagneticField,
    /// A new magnetometer offset (hard iron) was learned and replaced the previous one.
    NewHardIron,
}

/// The outcome of one aiding update: its normalized innovation squared and whether it was
/// fused (`false`: gated out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fusion<T: Real> {
    /// `NIS = rᵀ S⁻¹ r`.
    pub nis: T,
    /// Fused (`false`: the gate rejected it).
    pub accepted: bool,
}

impl<T: Real> From<UpdateOutcome<T>> for Fusion<T> {
    fn from(outcome: UpdateOutcome<T>) -> Self {
        match outcome {
            UpdateOutcome::Accepted { nis, .. } => Self {
                nis,
                accepted: true,
            },
            UpdateOutcome::Rejected { nis, .. } => Self {
                nis,
                accepted: false,
            },
        }
    }
}

/// The updates made in one call (all `None` except at the end of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fusions<T: Real> {
    /// The gravity direction (2 degrees of freedom).
    pub gravity: Option<Fusion<T>>,
    /// The magnetic heading (1 degree of freedom).
    pub heading: Option<Fusion<T>>,
    /// The zero-rate update at rest (3 degrees of freedom).
    pub zero_rate: Option<Fusion<T>>,
}

impl<T: Real> Default for Fusions<T> {
    fn default() -> Self {
        Self {
            gravity: None,
            heading: None,
            zero_rate: None,
        }
    }
}

/// The report after every call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeReport<T: Real> {
    /// The time of the estimate, ns (the last IMU sample).
    pub t_ns: u64,
    /// Roll and pitch.
    pub tilt: Validity,
    /// Yaw against the reference field's north.
    pub heading: Validity,
    /// The body was found at rest in the last block (zero-rate update applied).
    pub at_rest: bool,
    /// The magnetometer.
    pub magnetic: MagneticStatus,
    /// What the navigator did on its own in this call, if anything.
    pub event: Option<Event>,
    /// The updates made in this call.
    pub fused: Fusions<T>,
    /// This call's IMU sample was at the rail of the gyro or the accelerometer (`gyro_range`,
    /// `accel_range`): a clipped gyro widens the attitude by a full-scale turn over its
    /// interval; a clipped accelerometer's block is not fused and the velocity starts again.
    pub clipped: bool,
}

/// The attitude estimate with its uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeEstimate<T: Real> {
    /// The time, ns.
    pub t_ns: u64,
    /// `R`: world (ENU) from body.
    pub attitude: So3<T>,
    /// Gyro bias, rad/s.
    pub gyro_bias: Vector3<T>,
    /// Accelerometer bias, m/s².
    pub accel_bias: Vector3<T>,
    /// 1σ of the tilt: the larger of the two horizontal axes, rad.
    pub sigma_tilt: T,
    /// 1σ of the heading (about world up), rad.
    pub sigma_heading: T,
    /// The magnetometer's hard iron, body frame, in its unit: taken off every sample (zero
    /// without a magnetometer, or until learning begins).
    pub hard_iron: Vector3<T>,
    /// Its 1σ per axis: small once the body has turned about two axes; it grows slowly while
    /// the body does not turn (the offset is then frozen).
    pub sigma_hard_iron: Vector3<T>,
    /// The magnetometer's delay behind the gyro, s, as learned while the body turns about the
    /// vertical (zero without a magnetometer).
    pub magnetometer_delay_s: T,
}

/// Counts since construction, for logs and summaries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// IMU samples taken.
    pub imu: u32,
    /// Magnetometer samples taken.
    pub magnetometer: u32,
    /// Samples refused with an error.
    pub refused: u32,
    /// Accelerometer blocks fused.
    pub gravity_fused: u32,
    /// Accelerometer blocks that failed the gate.
    pub gravity_rejected: u32,
    /// Magnetometer blocks fused.
    pub heading_fused: u32,
    /// Magnetometer blocks that failed the gate.
    pub heading_rejected: u32,
    /// Magnetometer blocks found disturbed.
    pub magnetic_disturbed: u32,
    /// Zero-rate updates at rest.
    pub zero_rate: u32,
    /// Covariance widenings after repeated rejections (tilt and heading).
    pub widened: u32,
    /// Restarts after IMU gaps.
    pub realigned: u32,
    /// New reference fields taken.
    pub new_fields: u32,
    /// New magnetometer offsets (hard iron) learned.
    pub new_hard_irons: u32,
    /// IMU samples at the rail of the gyro or the accelerometer.
    pub clipped: u32,
    /// Magnetometer samples not used because they repeated (stuck).
    pub magnetometer_stuck: u32,
    /// Updates the filter refused (a numerical failure; the filter was left as it was and
    /// the update skipped).
    pub numerical_failures: u32,
}

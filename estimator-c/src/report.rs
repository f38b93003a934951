//! What the navigators report after every call, as C enums (`int32_t`) and structs.

use estimator_core::nav::{AidStatus, Event, InsEvent, MagneticStatus, Reason, Validity};

/// Why a quantity is not valid (`int32_t`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_reason {
    /// The quantity is valid.
    EST_REASON_NONE = 0,
    /// The start-up window is still being collected.
    EST_REASON_STARTING = 1,
    /// Its 1σ is above the configured limit (`*_valid_sigma`).
    EST_REASON_UNCERTAIN = 2,
    /// Heading without a magnetometer: only relative to the start.
    EST_REASON_NO_MAGNETOMETER = 3,
    /// INS heading without a magnetometer: the GNSS track has not yet resolved it.
    EST_REASON_HEADING_UNRESOLVED = 4,
    /// INS: no position fix fused yet.
    EST_REASON_NO_FIX = 5,
    /// INS: the fixes have disagreed with the estimate for a second or more.
    EST_REASON_FIXES_DISAGREE = 6,
    /// INS: just reset to the fixes after a long disagreement, not yet confirmed.
    EST_REASON_RESET = 7,
    /// The IMU is faulty (clipped or stuck): the prediction is not trusted.
    EST_REASON_IMU_FAULT = 8,
}

/// Whether one quantity of the estimate can be used, and if not why.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct est_validity {
    /// Within its configured 1σ limit.
    pub valid: bool,
    /// `EST_REASON_NONE` when valid, else why not.
    pub reason: est_reason,
}

impl From<Validity> for est_validity {
    fn from(v: Validity) -> Self {
        let reason = match v {
            Validity::Valid => est_reason::EST_REASON_NONE,
            Validity::Invalid(r) => match r {
                Reason::Starting => est_reason::EST_REASON_STARTING,
                Reason::Uncertain => est_reason::EST_REASON_UNCERTAIN,
                Reason::NoMagnetometer => est_reason::EST_REASON_NO_MAGNETOMETER,
                Reason::HeadingUnresolved => est_reason::EST_REASON_HEADING_UNRESOLVED,
                Reason::NoFix => est_reason::EST_REASON_NO_FIX,
                Reason::FixesDisagree => est_reason::EST_REASON_FIXES_DISAGREE,
                Reason::Reset => est_reason::EST_REASON_RESET,
                Reason::ImuFault => est_reason::EST_REASON_IMU_FAULT,
            },
        };
        Self {
            valid: v.is_valid(),
            reason,
        }
    }
}

/// The attitude navigator's magnetometer state (`int32_t`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_magnetic_status {
    /// No magnetometer configured.
    EST_MAGNETIC_NOT_CONFIGURED = 0,
    /// Configured, no block fused yet.
    EST_MAGNETIC_WAITING = 1,
    /// The last block agreed with the reference field and was fused.
    EST_MAGNETIC_FUSED = 2,
    /// The last block's norm or dip disagreed with the reference: not fused.
    EST_MAGNETIC_DISTURBED = 3,
    /// The last block's heading innovation failed the gate.
    EST_MAGNETIC_REJECTED = 4,
    /// The samples repeated bit for bit (stuck or saturated): not used until they change.
    EST_MAGNETIC_STUCK = 5,
}

impl From<MagneticStatus> for est_magnetic_status {
    fn from(s: MagneticStatus) -> Self {
        match s {
            MagneticStatus::NotConfigured => Self::EST_MAGNETIC_NOT_CONFIGURED,
            MagneticStatus::Waiting => Self::EST_MAGNETIC_WAITING,
            MagneticStatus::Fused => Self::EST_MAGNETIC_FUSED,
            MagneticStatus::Disturbed => Self::EST_MAGNETIC_DISTURBED,
            MagneticStatus::Rejected => Self::EST_MAGNETIC_REJECTED,
            MagneticStatus::Stuck => Self::EST_MAGNETIC_STUCK,
        }
    }
}

/// What the attitude navigator did on its own in the last call (`int32_t`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_attitude_event {
    /// Nothing.
    EST_ATTITUDE_EVENT_NONE = 0,
    /// The filter started from the start-up window.
    EST_ATTITUDE_EVENT_STARTED = 1,
    /// An IMU gap longer than `max_dt_s`: the navigator started again.
    EST_ATTITUDE_EVENT_REALIGNED = 2,
    /// Repeatedly rejected accelerometer blocks: the tilt covariance was widened.
    EST_ATTITUDE_EVENT_TILT_WIDENED = 3,
    /// Repeatedly rejected magnetometer blocks: the heading covariance was widened.
    EST_ATTITUDE_EVENT_HEADING_WIDENED = 4,
    /// A steady field different from the reference was taken as the new reference.
    EST_ATTITUDE_EVENT_NEW_MAGNETIC_FIELD = 5,
    /// A new magnetometer offset (hard iron) was learned.
    EST_ATTITUDE_EVENT_NEW_HARD_IRON = 6,
}

impl From<Option<Event>> for est_attitude_event {
    fn from(e: Option<Event>) -> Self {
        match e {
            None => Self::EST_ATTITUDE_EVENT_NONE,
            Some(Event::Started) => Self::EST_ATTITUDE_EVENT_STARTED,
            Some(Event::Realigned) => Self::EST_ATTITUDE_EVENT_REALIGNED,
            Some(Event::TiltWidened) => Self::EST_ATTITUDE_EVENT_TILT_WIDENED,
            Some(Event::HeadingWidened) => Self::EST_ATTITUDE_EVENT_HEADING_WIDENED,
            Some(Event::NewMagneticField) => Self::EST_ATTITUDE_EVENT_NEW_MAGNETIC_FIELD,
            Some(Event::NewHardIron) => Self::EST_ATTITUDE_EVENT_NEW_HARD_IRON,
        }
    }
}

/// An INS aiding sensor's state (`int32_t`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_aid_status {
    /// Not configured (or, for GNSS, no fix ever received).
    EST_AID_ABSENT = 0,
    /// Configured; nothing fused yet.
    EST_AID_WAITING = 1,
    /// The last measurement was fused.
    EST_AID_FUSED = 2,
    /// No measurement has come due for 2.5 of the sensor's own intervals.
    EST_AID_STALE = 3,
    /// The last measurement failed the gate.
    EST_AID_REJECTED = 4,
    /// The last measurement was refused before the gate (a frozen GNSS fix, a magnetometer
    /// norm that disagrees with the reference).
    EST_AID_FAULTY = 5,
}

impl From<AidStatus> for est_aid_status {
    fn from(s: AidStatus) -> Self {
        match s {
            AidStatus::Absent => Self::EST_AID_ABSENT,
            AidStatus::Waiting => Self::EST_AID_WAITING,
            AidStatus::Fused => Self::EST_AID_FUSED,
            AidStatus::Stale => Self::EST_AID_STALE,
            AidStatus::Rejected => Self::EST_AID_REJECTED,
            AidStatus::Faulty => Self::EST_AID_FAULTY,
        }
    }
}

/// What the INS navigator did on its own in the last call (`int32_t`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_ins_event {
    /// Nothing.
    EST_INS_EVENT_NONE = 0,
    /// The INS started: attitude and biases from the alignment, position and velocity from
    /// the first fix.
    EST_INS_EVENT_STARTED = 1,
    /// An IMU gap longer than `max_dt_s`: the navigator went back to aligning.
    EST_INS_EVENT_REALIGNED = 2,
    /// The fixes were rejected for `gnss_reset_s`: position and velocity were reset to them.
    EST_INS_EVENT_POSITION_RESET = 3,
    /// A clipped or stuck IMU sample widened the covariance.
    EST_INS_EVENT_IMU_FAULT = 4,
    /// Without a magnetometer, the heading was set from the GNSS track.
    EST_INS_EVENT_HEADING_FROM_GNSS = 5,
}

impl From<Option<InsEvent>> for est_ins_event {
    fn from(e: Option<InsEvent>) -> Self {
        match e {
            None => Self::EST_INS_EVENT_NONE,
            Some(InsEvent::Started) => Self::EST_INS_EVENT_STARTED,
            Some(InsEvent::Realigned) => Self::EST_INS_EVENT_REALIGNED,
            Some(InsEvent::PositionReset) => Self::EST_INS_EVENT_POSITION_RESET,
            Some(InsEvent::ImuFault) => Self::EST_INS_EVENT_IMU_FAULT,
            Some(InsEvent::HeadingFromGnss) => Self::EST_INS_EVENT_HEADING_FROM_GNSS,
        }
    }
}

//! The validity of each quantity after a call: from the delayed filter's covariance (the
//! present one differs by the horizon's growth, a fraction of the thresholds) and the GNSS
//! policy's state.

use super::aid::DISAGREEING_FIXES;
use super::report::AidStatus;
use super::{InsNavigator, Mode, AID_STALE_INTERVALS, AID_STALE_NS, INVALID_START};
use crate::kernels::block::block;
use crate::kernels::{larger, mat3};
use crate::nav::attitude::{Reason, Validity};
use crate::Real;
use nalgebra::SMatrix;

/// Valid when `variance ≤ limit²`.
fn within<T: Real>(variance: T, limit: T) -> Validity {
    if variance <= limit * limit {
        Validity::Valid
    } else {
        Validity::Invalid(Reason::Uncertain)
    }
}

/// The largest variance of block `b` of the 15-state `P` (its diagonal only, read in place).
pub(super) fn largest<T: Real>(p: &SMatrix<T, 15, 15>, b: usize) -> T {
    (0..3).fold(T::zero(), |m, k| {
        p.get((3 * b + k, 3 * b + k)).map_or(m, |d| larger(m, *d))
    })
}

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// Marks an aid as stale when its last measurement came due more than 2.5 of its own
    /// measurement intervals before the filter's time ([`AID_STALE_NS`] before one is known).
    fn refresh_staleness(&mut self) {
        let (Some(t_f), Mode::Running(..)) = (self.filter_t, &self.mode) else {
            return;
        };
        let statuses = [
            &mut self.report.gnss,
            &mut self.report.magnetometer,
            &mut self.report.barometer,
        ];
        for ((status, due), interval) in statuses
            .into_iter()
            .zip(self.last_due)
            .zip(self.aid_interval)
        {
            let limit =
                interval.map_or(AID_STALE_NS, |i| i.saturating_mul(AID_STALE_INTERVALS) / 2);
            let quiet = due.is_none_or(|d| t_f.saturating_sub(d) > limit);
            if quiet && !matches!(status, AidStatus::Absent | AidStatus::Waiting) {
                *status = AidStatus::Stale;
            }
        }
    }

    pub(super) fn refresh_validity(&mut self) {
        self.refresh_staleness();
        let c = &self.config;
        let unresolved = self.heading_unresolved();
        let v = &mut self.report.validity;
        match &self.mode {
            Mode::Aligning(att) => {
                *v = INVALID_START;
                v.tilt = att.report().tilt;
                v.heading = att.report().heading;
            }
            Mode::Running(ins, _) => {
                let p = ins.covariance();
                let r = ins.state().attitude.rotation_matrix();
                // The world-frame attitude variances, `W_kk = r_kᵀ P_θθ r_k` with `r_k` row k
                // of R (the diagonal of R P_θθ Rᵀ, without the whole product): tilt on x, y;
                // heading on z (up).
                let ptt = block(p, 0, 0);
                let world = |k: usize| {
                    let row = r.row(k).transpose();
                    row.dot(&mat3::mul_vec(&ptt, &row))
                };
                v.tilt = within(larger(world(0), world(1)), c.tilt_valid_sigma);
                v.heading = if unresolved {
                    Validity::Invalid(Reason::HeadingUnresolved)
                } else {
                    within(world(2), c.heading_valid_sigma)
                };
                v.velocity = within(largest(p, 1), c.velocity_valid_sigma);
                v.position = if self.gnss.rejected >= DISAGREEING_FIXES {
                    Validity::Invalid(Reason::FixesDisagree)
                } else if self.gnss.unconfirmed {
                    Validity::Invalid(Reason::Reset)
                } else {
                    within(largest(p, 2), c.position_valid_sigma)
                };
                v.gyro_bias = within(largest(p, 3), c.gyro_bias_valid_sigma);
                v.accel_bias = within(largest(p, 4), c.accel_bias_valid_sigma);
                let held = self
                    .stuck
                    .invalid_until
                    .is_some_and(|until| self.report.t_ns < until);
                if self.report.imu_fault || held {
                    v.velocity = Validity::Invalid(Reason::ImuFault);
                    v.position = Validity::Invalid(Reason::ImuFault);
                }
            }
        }
    }
}

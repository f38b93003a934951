//! The aiding updates at the filter's time, each measurement carried over the `dt ≥ 0`
//! between its own time and the filter's (at most a few IMU intervals, when several
//! measurements come due together), and the GNSS policy.

use super::buffer::FixSigma;
use super::report::{AidStatus, Aiding, InsEvent, InsFusion};
use super::{InsNavigator, Mode};
use crate::eskf::{
    BaroAltitude, EskfError, GnssPosition, GnssVelocity, Ins, Magnetometer, UpdateOptions,
    UpdateOutcome,
};
use crate::kernels::mat3;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::Vector3;

/// Rejected fixes in a row that mark the position invalid.
pub(super) const DISAGREEING_FIXES: u16 = 3;

/// A moving body, m/s: above this, a fix that repeats the previous one exactly is frozen (at
/// rest a receiver's rounded output may repeat).
const FROZEN_MIN_SPEED: f64 = 0.5;

/// A first rejected fix this far outside the gate (NIS), right after fused fixes, is a jump of
/// the receiver: the estimate cannot move that far in one fix interval. Its streak never
/// resets the estimate; the fixes must come back to it, or the estimate's own growing
/// uncertainty must let them through the gate.
const JUMP_NIS: f64 = 100.0;

/// "Right after": the previous fix was fused less than this before, ns.
const JUMP_WINDOW_NS: u64 = 1_000_000_000;

/// Fixes fused for this long after a reset confirm it, ns.
const CONFIRM_NS: u64 = 1_000_000_000;

/// What an update did.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Fused {
    Accepted,
    Rejected,
    Failed,
}

fn count(c: &mut u32) {
    *c = c.saturating_add(1);
}

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    fn ins_mut(&mut self) -> Option<&mut Ins<T>> {
        match &mut self.mode {
            Mode::Running(ins, _) => Some(ins),
            Mode::Aligning(_) => None,
        }
    }

    /// Records an update's outcome in the report and the counters (`fused`, `rejected`).
    fn record(&mut self, aid: Aiding, t_ns: u64, r: Result<UpdateOutcome<T>, EskfError>) -> Fused {
        let Ok(outcome) = r else {
            count(&mut self.counters.numerical_failures);
            return Fused::Failed;
        };
        let accepted = outcome.is_accepted();
        self.report.fused = Some(InsFusion {
            aid,
            t_ns,
            nis: outcome.nis(),
            accepted,
        });
        let c = &mut self.counters;
        let (counter, status) = match (aid, accepted) {
            (Aiding::GnssPosition, true) => (&mut c.gnss_position_fused, None),
            (Aiding::GnssPosition, false) => (&mut c.gnss_position_rejected, None),
            (Aiding::GnssVelocity, true) => (&mut c.gnss_velocity_fused, None),
            (Aiding::GnssVelocity, false) => (&mut c.gnss_velocity_rejected, None),
            (Aiding::Magnetometer, true) => (
                &mut c.magnetometer_fused,
                Some(&mut self.report.magnetometer),
            ),
            (Aiding::Magnetometer, false) => (
                &mut c.magnetometer_rejected,
                Some(&mut self.report.magnetometer),
            ),
            (Aiding::Barometer, true) => (&mut c.barometer_fused, Some(&mut self.report.barometer)),
            (Aiding::Barometer, false) => {
                (&mut c.barometer_rejected, Some(&mut self.report.barometer))
            }
        };
        count(counter);
        if let Some(status) = status {
            *status = if accepted {
                AidStatus::Fused
            } else {
                AidStatus::Rejected
            };
        }
        if accepted {
            Fused::Accepted
        } else {
            Fused::Rejected
        }
    }

    /// A GNSS position valid at `t_m`, `dt` before the filter's time `t_f`: `z + v̂ dt` against
    /// `h(x) = p + R ℓ` ([`GnssPosition`]) with `R = diag(σ_h², σ_h², σ_v²)`
    /// ([`GnssPosition::with_sigmas`]). A fix repeating the previous one exactly while the
    /// body moves is frozen and refused; rejections count towards the disagreement flag and,
    /// after `gnss_reset_s`, reset position and velocity to the fixes.
    pub(super) fn fuse_gnss(
        &mut self,
        t_f: u64,
        t_m: u64,
        dt: T,
        z: Vector3<T>,
        sigma: FixSigma<T>,
    ) {
        let lever = self.config.gnss_lever_arm;
        let repeated = self.gnss.last_position == Some(z);
        self.gnss.last_position = Some(z);
        if let Mode::Running(_, bank) = &mut self.mode {
            if !repeated && bank.check_position(t_m, &z, sigma.horizontal) {
                count(&mut self.counters.gnss_velocity_inconsistent);
            }
        }
        let Some(ins) = self.ins_mut() else {
            return;
        };
        let s = *ins.state();
        let frozen = repeated && mat3::norm(&s.velocity) > T::lit(FROZEN_MIN_SPEED);
        let shifted = z + s.velocity * dt;
        let r = if frozen {
            None
        } else {
            // The sigmas were checked when the fix was taken; a model that cannot be built
            // (a position carried out of the finite numbers) is counted as a failed update.
            Some(
                GnssPosition::with_sigmas(shifted, lever, sigma.horizontal, sigma.up)
                    .and_then(|fix| ins.update(&fix, &UpdateOptions::default())),
            )
        };
        self.gnss.frozen = frozen;
        let Some(r) = r else {
            count(&mut self.counters.gnss_frozen);
            self.report.gnss = AidStatus::Faulty;
            return;
        };
        match self.record(Aiding::GnssPosition, t_m, r) {
            Fused::Accepted => {
                self.report.gnss = AidStatus::Fused;
                self.gnss.last_fused = Some(t_m);
                self.gnss.jump = false;
                self.gnss.rejected = 0;
                self.gnss.rejected_since = None;
                let since = *self.gnss.fused_since.get_or_insert(t_f);
                if t_f.saturating_sub(since) >= CONFIRM_NS {
                    self.gnss.unconfirmed = false;
                }
            }
            Fused::Rejected => {
                self.report.gnss = AidStatus::Rejected;
                if self.gnss.rejected == 0 {
                    let nis = self.report.fused.map_or(T::zero(), |f| f.nis);
                    let recent = self
                        .gnss
                        .last_fused
                        .is_some_and(|t| t_m.saturating_sub(t) < JUMP_WINDOW_NS);
                    self.gnss.jump = recent && nis > T::lit(JUMP_NIS);
                }
                self.gnss.rejected = self.gnss.rejected.saturating_add(1);
                self.gnss.fused_since = None;
                let since = *self.gnss.rejected_since.get_or_insert(t_m);
                if !self.gnss.jump && t_m.saturating_sub(since) >= self.reset_ns {
                    self.reset_to_fix(shifted - s.attitude.act(&lever), sigma);
                }
            }
            Fused::Failed => {}
        }
    }

    /// Resets the position to a fix (body position `p`, the fix's horizontal and vertical 1σ)
    /// and asks the next velocity fix to reset the velocity.
    fn reset_to_fix(&mut self, p: Vector3<T>, sigma: FixSigma<T>) {
        let done = self
            .ins_mut()
            .map(|ins| ins.reset_position_per_axis(p, &sigma.per_axis()).is_ok());
        if done != Some(true) {
            count(&mut self.counters.numerical_failures);
            return;
        }
        self.gnss.rejected = 0;
        self.gnss.rejected_since = None;
        self.gnss.reset_velocity = true;
        self.gnss.unconfirmed = true;
        count(&mut self.counters.resets);
        self.report.event = Some(InsEvent::PositionReset);
    }

    /// A GNSS velocity valid at `t_m`, `dt` before the filter's time: the antenna's,
    /// `v + R(ω × ℓ)`, so `z − R((ω_m − b_g) × ℓ) + a dt` with `a = R(f_m − b_a) + g` (the last
    /// interval's rate and specific force) against `h(x) = v` ([`GnssVelocity`]). After a
    /// position reset, the velocity is reset to it instead. The bank of yaw hypotheses takes
    /// that body velocity too (`nav/ins/heading.rs`), unless the receiver is frozen or its
    /// velocities disagree with its positions (`nav/ins/velocity_check.rs`).
    pub(super) fn fuse_gnss_velocity(&mut self, t_m: u64, dt: T, z: Vector3<T>, sigma: T) {
        let (rate, specific_force, lever) = (
            self.filter_rate,
            self.filter_accel,
            self.config.gnss_lever_arm,
        );
        let (frozen, reset) = (self.gnss.frozen, self.gnss.reset_velocity);
        let Mode::Running(ins, bank) = &mut self.mode else {
            return;
        };
        if frozen {
            return;
        }
        bank.check_velocity(t_m, &z, sigma);
        let s = *ins.state();
        let omega = rate - s.gyro_bias;
        let accel = s.attitude.act(&(specific_force - s.accel_bias)) + ins.config().gravity;
        let body = z - s.attitude.act(&omega.cross(&lever)) + accel * dt;
        bank.take_velocity(&body, sigma);
        if reset {
            let ok = ins.reset_velocity(body, sigma).is_ok();
            self.gnss.reset_velocity = false;
            if !ok {
                count(&mut self.counters.numerical_failures);
            }
            return;
        }
        let r = ins.update(&GnssVelocity::new(body, sigma), &UpdateOptions::default());
        self.record(Aiding::GnssVelocity, t_m, r);
    }

    /// A magnetometer sample valid at `t_m`, `dt` before the filter's time, carried by the
    /// rate (`m_f = Exp(ω dt)ᵀ m`), against `h(x) = Rᵀ m_w` ([`Magnetometer`]); refused when
    /// its norm differs from the reference's by more than `norm_tolerance`.
    pub(super) fn fuse_magnetometer(&mut self, t_m: u64, dt: T, field: Vector3<T>) {
        let (Some(reference), Some(mag)) =
            (self.magnetic_reference, self.config.attitude.magnetometer)
        else {
            return;
        };
        let rate = self.filter_rate;
        let Some(ins) = self.ins_mut() else {
            return;
        };
        let omega = rate - ins.state().gyro_bias;
        let carried = So3::exp(&(omega * dt)).inverse().act(&field);
        let norm = mat3::norm(&reference);
        if (mat3::norm(&carried) - norm).abs() > mag.norm_tolerance * norm {
            count(&mut self.counters.magnetometer_disturbed);
            self.report.magnetometer = AidStatus::Faulty;
            return;
        }
        let r = ins.update(
            &Magnetometer::new(carried, reference, mag.sigma),
            &UpdateOptions::default(),
        );
        self.record(Aiding::Magnetometer, t_m, r);
    }

    /// A barometric altitude valid at `t_m`, `dt` before the filter's time, `h + v_z dt`,
    /// against `h(x) = p_z` ([`BaroAltitude`]).
    pub(super) fn fuse_barometer(&mut self, t_m: u64, dt: T, altitude: T) {
        let Some(sigma) = self.config.barometer_sigma else {
            return;
        };
        let Some(ins) = self.ins_mut() else {
            return;
        };
        let shifted = altitude + ins.state().velocity.z * dt;
        let r = ins.update(
            &BaroAltitude::new(shifted, sigma),
            &UpdateOptions::default(),
        );
        self.record(Aiding::Barometer, t_m, r);
    }
}

//! The heading without a magnetometer: what the INS is told of it, and when.
//!
//! * **At the start** the heading is unknown: the alignment's heading is only relative to
//!   where the IMU started, so the INS starts with the variance of a heading uniform over
//!   the circle, `π²/3` ([`UNKNOWN_HEADING_VARIANCE`]), and its validity is
//!   [`Reason::HeadingUnresolved`](crate::nav::Reason::HeadingUnresolved).
//! * **Until resolved** every fused measurement that narrows the INS's heading below 0.9 of
//!   that is undone: the heading is set back to unknown, without its covariance with the other
//!   states ([`Ins::reset_heading`](crate::eskf::Ins::reset_heading) by no turn): a filter
//!   linearized at a heading that may be 180° off must not lock on to what its first
//!   accelerations suggest.
//! * **Resolved** by the bank of yaw hypotheses (`nav/ins/yaw.rs`), fed every GNSS velocity:
//!   once it has [`MIN_FIXES`] of them and its 1σ is at most half of `heading_valid_sigma`,
//!   the INS's heading is reset to it ([`Ins::reset_heading`](crate::eskf::Ins::reset_heading),
//!   [`InsEvent::HeadingFromGnss`]). A ground vehicle's bank finds the track long before it
//!   can tell forward from backward (only the speed's changes do, and a slow, steady vehicle's
//!   are below what a tilt or bias error fakes): it is resolved once the hypotheses that see
//!   the vehicle move forward agree to that 1σ — the one assumption of this module, that a
//!   ground vehicle starts its run driving forward or from rest (a run that starts reversing
//!   is resolved 180° off). Later, the bank resets it again when the INS's heading variance
//!   has grown past 4 times the bank's, or the two disagree by more than 3 σ of their
//!   difference (an INS locked on a wrong heading); a ground vehicle's INS, which the lateral
//!   constraint holds better than the bank, only once its own heading is no longer valid, and
//!   never turned around (by more than 90°): a reversal of travel is not a new heading.
//! * **A ground vehicle** ([`InsConfig::travel`](super::InsConfig::travel), its lateral
//!   velocity's 1σ declared or learned from the track: `nav/ins/track_axis.rs`)
//!   with its heading resolved is also held to a zero lateral velocity at each GNSS velocity
//!   while its horizontal speed is above 3σ of its velocity ([`LateralVelocity`]): at a slow,
//!   steady speed the accelerations say little, the track says it to `σ_l/‖v‖`; at rest the
//!   velocity's direction is noise, and so would be the heading it gives.
//! * **Each update** that turns the INS's attitude about the vertical turns the bank's
//!   reference with it ([`YawBank::shift`]).
//! * **Velocities the positions refute** (`nav/ins/velocity_check.rs`: the displacement the
//!   velocities describe against the positions', window by window) are not given to the bank
//!   until a window agrees again (`InsCounters::gnss_velocity_inconsistent`), nor are a frozen
//!   receiver's: the bank would take a heading from them as confidently as from true ones.

use super::report::InsEvent;
use super::validity::largest;
use super::yaw::{StepNoise, YawBank};
use super::{InsNavigator, Mode};
use crate::eskf::{up_direction, Ins, LateralVelocity, UpdateOptions};
use crate::kernels::block::block;
use crate::kernels::mat3;
use crate::lie::LieGroup;
use crate::Real;
use nalgebra::{Vector2, Vector3};

/// The variance of a heading uniform over the circle, rad² (`π²/3`).
pub(crate) const UNKNOWN_HEADING_VARIANCE: f64 =
    core::f64::consts::PI * core::f64::consts::PI / 3.0;

/// The bank resolves the heading only after this many GNSS velocities (2 s at 5 Hz): its
/// likelihoods need a few independent fixes before one hypothesis can stand out.
pub(crate) const MIN_FIXES: u16 = 10;

/// The world-frame variance of the INS's heading, `uᵀ R̂ P_θθ R̂ᵀ u`, and `u`.
fn heading_variance<T: Real>(ins: &Ins<T>) -> Option<(T, Vector3<T>)> {
    let up = up_direction(&ins.config().gravity)?;
    let r = ins.state().attitude.rotation_matrix();
    let u_b = mat3::mul_vec(&r.transpose(), &up);
    let p = block(ins.covariance(), 0, 0);
    Some((u_b.dot(&mat3::mul_vec(&p, &u_b)), up))
}

impl<T: Real, const H: usize, const Q: usize> InsNavigator<T, H, Q> {
    /// After a measurement was fused (or not): the bank follows the INS's turn since the
    /// attitude it noted before, takes the GNSS velocity the fusion brought, if any, and
    /// resolves or holds the INS's heading (module docs).
    #[inline(never)] // its bank step and resets stay out of every IMU call's frame
    pub(super) fn track_heading(&mut self) {
        let valid = self.config.heading_valid_sigma;
        let Mode::Running(ins, bank) = &mut self.mode else {
            return;
        };
        if !bank.active() {
            return;
        }
        let (before, velocity) = bank.fused();
        let Some((_, up)) = heading_variance(ins) else {
            return;
        };
        let moving = |ins: &Ins<T>| {
            let (v, p) = (ins.state().velocity, ins.covariance());
            let var = |k: usize| p.get((k, k)).copied().unwrap_or_else(T::zero);
            v.x * v.x + v.y * v.y >= T::lit(9.0) * var(3).max(var(4))
        };
        if let (Some(sigma), Some(_), true, true) =
            (bank.lateral_sigma(), velocity, bank.resolved(), moving(ins))
        {
            // A ground vehicle with a known heading: its lateral velocity is zero, at each GNSS
            // velocity (`LateralVelocity`); the heading's second source beside the
            // accelerations.
            let r = ins.update(&LateralVelocity::new(sigma), &UpdateOptions::default());
            let c = &mut self.counters;
            match r {
                Ok(o) if o.is_accepted() => {
                    c.lateral_fused = c.lateral_fused.saturating_add(1);
                    bank.lateral_outcome(true);
                }
                Ok(_) => {
                    c.lateral_rejected = c.lateral_rejected.saturating_add(1);
                    bank.lateral_outcome(false);
                }
                Err(_) => c.numerical_failures = c.numerical_failures.saturating_add(1),
            }
        }
        let turned = ins.state().attitude.compose(&before.inverse()).log();
        bank.shift(up.dot(&turned));
        if let Some((z, sigma)) = velocity {
            let noise = step_noise(ins);
            let r = ins.state().attitude.rotation_matrix();
            let forward = Vector2::new(r.m11, r.m21);
            bank.fuse_velocity(&Vector2::new(z.x, z.y), sigma * sigma, &forward, &noise);
            if resolve(ins, bank, valid, &forward) {
                self.counters.heading_resets = self.counters.heading_resets.saturating_add(1);
                self.report.event = Some(InsEvent::HeadingFromGnss);
            }
        }
        if !bank.resolved() {
            hold_unknown(ins);
        }
    }

    /// The heading is not resolved: nothing but the bank could resolve it, and it has not.
    pub(super) fn heading_unresolved(&self) -> bool {
        match &self.mode {
            Mode::Running(_, bank) => bank.active() && !bank.resolved(),
            Mode::Aligning(_) => false,
        }
    }
}

/// The bank's process noise from the IMU's noise and the INS's covariance (`nav/ins/yaw.rs`).
fn step_noise<T: Real>(ins: &Ins<T>) -> StepNoise<T> {
    let c = ins.config();
    let n = &c.imu_noise;
    let g2 = c.gravity.dot(&c.gravity);
    let p = ins.covariance();
    // The tilt's world-frame variances (east and north axes of R̂ P_θθ R̂ᵀ), not the body
    // frame's, which hold the heading's.
    let r = ins.state().attitude.rotation_matrix();
    let world = mat3::mul(&mat3::mul(&r, &block(p, 0, 0)), &r.transpose());
    StepNoise {
        white_velocity: n.accelerometer_noise_density * n.accelerometer_noise_density,
        drift_velocity: g2 * world.m11.max(world.m22) + largest(p, 4),
        white_yaw: n.gyroscope_noise_density * n.gyroscope_noise_density,
        drift_yaw: largest(p, 3),
    }
}

/// Resets the INS's heading to the bank's when the bank is sure of it and the INS is not (or
/// disagrees with it); `true` when it did (module docs). `forward`: the INS's horizontal
/// forward direction, for a vehicle that moves along its track.
fn resolve<T: Real>(
    ins: &mut Ins<T>,
    bank: &mut YawBank<T>,
    valid: T,
    forward: &Vector2<T>,
) -> bool {
    let (Some((offset, sigma)), Some((variance, _))) = (bank.estimate(), heading_variance(ins))
    else {
        return false;
    };
    let half = valid * T::lit(0.5);
    if bank.fixes() < MIN_FIXES {
        return false;
    }
    let (offset, sigma) = if bank.track() && !bank.resolved() {
        // Along a track, first the hypotheses that see the vehicle moving forward: a ground
        // vehicle starts its run forward (or from rest, where its first acceleration says so
        // too), and at a steady speed nothing else tells forward from backward (module docs).
        match bank.forward_estimate(forward) {
            Some((o, s)) if s <= half => (o, s),
            _ => return false,
        }
    } else if sigma <= half {
        (offset, sigma)
    } else {
        return false;
    };
    let sigma2 = sigma * sigma;
    let again = if bank.track() {
        // A ground vehicle's INS holds its heading with the lateral constraint, better than
        // the bank, whose velocities random-walk: it takes the bank's again only once its own
        // is no longer valid, and never turned around (the forward and backward hypotheses
        // differ only through accelerations, which a long reversal or a tilt error can tip).
        variance > valid * valid && offset.abs() <= T::frac_pi_2()
    } else {
        let apart = offset * offset > T::lit(9.0) * (sigma2 + variance);
        let wider = variance > T::lit(4.0) * sigma2;
        apart || wider
    };
    if bank.resolved() && !again {
        return false;
    }
    if ins.reset_heading(offset, sigma).is_err() {
        return false;
    }
    bank.shift(offset);
    bank.set_resolved();
    true
}

/// Sets the INS's heading back to unknown (variance [`UNKNOWN_HEADING_VARIANCE`], no
/// covariance with any other state: [`Ins::reset_heading`] by no turn) when a measurement
/// narrowed it by a tenth or more.
fn hold_unknown<T: Real>(ins: &mut Ins<T>) {
    let Some((variance, _)) = heading_variance(ins) else {
        return;
    };
    let unknown = T::lit(UNKNOWN_HEADING_VARIANCE);
    if variance < T::lit(0.9) * unknown {
        // A failure leaves the filter as it was; the heading is reported unresolved anyway.
        let _ = ins.reset_heading(T::zero(), unknown.sqrt_rn());
    }
}

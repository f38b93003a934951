//! The magnetometer: heading only, with disturbance detection and a reference learned online.
//!
//! A block's mean field `m̄` (body frame at the block's end) is seen in the world as
//! `c = R̂ m̄`, with norm `‖c‖` and dip angle `δ = atan2(c_up, ‖c_h‖)`. Against the reference
//! `m_w` (norm `‖m_w‖`, dip `δ_w`) the block is **disturbed** when
//! `|‖c‖ − ‖m_w‖| > ε_n ‖m_w‖` or `|δ − δ_w| > ε_δ` (iron or a magnet near the sensor changes
//! both; a heading error changes neither, so this test cannot be fooled by the estimate).
//! A disturbed block is not fused.
//!
//! An undisturbed block is fused as a [`MagneticHeading`] (the azimuth of `c` against the
//! azimuth of `m_w`; it moves the heading only, never the tilt) with
//!
//! ```text
//! σ_ψ² = σ_m²/(n ‖c_h‖²) + σ_hd²
//! ```
//!
//! (`σ_m` the white noise of one sample, `n` samples, `σ_hd` the per-block heading noise of
//! the configuration), gated at 99.9 %, with the same widening after repeated rejections as
//! the tilt, and with the heading floor `σ_ψ ≥ heading_floor` applied afterwards.
//!
//! **A new field.** A disturbed field that stays the same (norm and dip within the tolerances
//! of the first disturbed block) for `new_field_s` is taken as the new reference: its norm and
//! dip, with the old reference's north. Without a configured reference, the first block
//! defines it: `m_w = [0, ‖c_h‖, c_up]`, north is where the field points.

use super::config::{AttitudeConfig, MagneticConfig};
use super::report::{Event, Fusion, MagneticStatus};
use super::tilt::world_attitude_covariance;
use crate::eskf::{Ahrs, MagneticHeading, UpdateOptions};
use crate::kernels::mat3;
use crate::lie::LieGroup;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// Norm, horizontal norm and dip angle of a world (ENU) vector.
fn norm_dip<T: Real>(c: &Vector3<T>) -> (T, T, T) {
    let h = (c.x * c.x + c.y * c.y).sqrt();
    (mat3::norm(c), h, c.z.arctan2(h))
}

/// The magnetometer's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Magnetic<T: Real> {
    /// The world reference field, once known.
    pub(super) reference: Option<Vector3<T>>,
    /// The first disturbed field of a run of similar ones, and how long the run has lasted, s.
    candidate: Option<(Vector3<T>, T)>,
    /// Consecutive gated-out blocks.
    rejected: u16,
}

impl<T: Real> Magnetic<T> {
    pub(super) fn new(config: &MagneticConfig<T>) -> Self {
        Self {
            reference: config.reference,
            candidate: None,
            rejected: 0,
        }
    }

    /// `true` when `c` is within the tolerances of `reference`.
    fn agrees(c: &Vector3<T>, reference: &Vector3<T>, config: &MagneticConfig<T>) -> bool {
        let (nc, _, dc) = norm_dip(c);
        let (nr, _, dr) = norm_dip(reference);
        (nc - nr).abs() <= config.norm_tolerance * nr && (dc - dr).abs() <= config.dip_tolerance
    }

    /// Learns the reference from a world-frame field: `[0, ‖c_h‖, c_up]`.
    pub(super) fn learn(c: &Vector3<T>) -> Vector3<T> {
        let (_, h, _) = norm_dip(c);
        Vector3::new(T::zero(), h, c.z)
    }

    /// Fuses one block's mean field `m_body` (from `n` samples, over `duration` s).
    pub(super) fn fuse(
        &mut self,
        filter: &mut Ahrs<T>,
        m_body: &Vector3<T>,
        n: u32,
        duration: T,
        config: &AttitudeConfig<T>,
        mag: &MagneticConfig<T>,
    ) -> Result<(MagneticStatus, Option<Fusion<T>>, Option<Event>), NavError> {
        let c = filter.state().attitude.act(m_body);
        let Some(reference) = self.reference else {
            self.reference = Some(Self::learn(&c));
            return Ok((MagneticStatus::Fused, None, Some(Event::NewMagneticField)));
        };
        if !Self::agrees(&c, &reference, mag) {
            let (status, event) = self.disturbed(&c, &reference, duration, mag);
            return Ok((status, None, event));
        }
        self.candidate = None;
        let (_, horizontal, _) = norm_dip(&c);
        if !crate::kernels::positive_finite(horizontal) {
            return Ok((MagneticStatus::Disturbed, None, None));
        }
        let white = mag.sigma / horizontal;
        let var = white * white / T::from_count(n.max(1)) + mag.heading_noise * mag.heading_noise;
        let model = MagneticHeading::new(*m_body, reference, var.sqrt());
        let options = UpdateOptions::default();
        let mut event = None;
        let mut fusion = Fusion::from(filter.update(&model, &options)?);
        if fusion.accepted {
            self.rejected = 0;
        } else {
            self.rejected = self.rejected.saturating_add(1);
            if self.rejected >= config.max_rejected_blocks {
                let c_az = c.y.arctan2(c.x);
                let r_az = reference.y.arctan2(reference.x);
                let (s, co) = (r_az - c_az).sincos();
                filter.widen_attitude(T::zero(), s.arctan2(co).abs())?;
                fusion = Fusion::from(filter.update(&model, &options)?);
                self.rejected = 0;
                event = Some(Event::HeadingWidened);
            }
        }
        let w = world_attitude_covariance(filter);
        let deficit = mag.heading_floor * mag.heading_floor - w.m33;
        if deficit > T::zero() {
            filter.widen_attitude(T::zero(), deficit.sqrt())?;
        }
        let status = if fusion.accepted {
            MagneticStatus::Fused
        } else {
            MagneticStatus::Rejected
        };
        Ok((status, Some(fusion), event))
    }

    /// A disturbed block: tracks a run of similar fields and takes it as the new reference
    /// once it has lasted `new_field_s`.
    fn disturbed(
        &mut self,
        c: &Vector3<T>,
        reference: &Vector3<T>,
        duration: T,
        mag: &MagneticConfig<T>,
    ) -> (MagneticStatus, Option<Event>) {
        let run = match self.candidate {
            Some((first, t)) if Self::agrees(c, &first, mag) => (first, t + duration),
            _ => (*c, duration),
        };
        if run.1 < mag.new_field_s {
            self.candidate = Some(run);
            return (MagneticStatus::Disturbed, None);
        }
        // The new field's norm and dip, with the old reference's north.
        let (_, h_new, _) = norm_dip(c);
        let (_, h_old, _) = norm_dip(reference);
        let north = if h_old > T::zero() {
            Vector3::new(reference.x, reference.y, T::zero()) / h_old
        } else {
            Vector3::y()
        };
        self.reference = Some(north * h_new + Vector3::z() * c.z);
        self.candidate = None;
        (MagneticStatus::Disturbed, Some(Event::NewMagneticField))
    }
}

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
//! σ_ψ² = σ_m²/(n ‖c_h‖²) + N_hd²/T
//! ```
//!
//! (`σ_m` the white noise of one sample, `n` samples, `N_hd` the heading noise density of the
//! configuration, `T` the block's length). The azimuth is computed with the estimated tilt, so
//! a tilt error `δ` shows in it as about `tan(dip)·δ`; `N_hd` covers it (the row leaves the
//! tilt alone, so the coupling is not in `H`: this is the price of never letting the
//! magnetometer move the tilt, and why a calibrated magnetometer in a clean field is better
//! fused whole), gated at 99.9 %, and with the heading floor `σ_ψ ≥ heading_floor`
//! applied afterwards. After `max_rejected_blocks` rejections in a row whose innovations agree
//! within `4N_hd/√T` while the body turned by 90° or more (or for `new_field_s` without turning,
//! with norm and dip agreeing all along), the estimate is taken for wrong (a disturbance would
//! change with the orientation; a heading error does not), the heading covariance is widened
//! to the innovation and the block fused.
//!
//! A block is also disturbed when the field moved in the world during it: a world-frame
//! scatter beyond the white noise, `s_m² − 3σ_m² > (ε_n ‖m_w‖)²` (a magnet carried by the body
//! turns with it).
//!
//! With [`MagneticFusion::Vector`] the undisturbed block is fused as the whole field instead
//! ([`Magnetometer`], per axis `σ² = σ_m²/n + ‖c_h‖² N_hd²/T`), which also corrects the tilt:
//! for a calibrated magnetometer in a clean field.
//!
//! **The magnetometer's delay.** A sample stamped `t` that is the field at `t − τ` (the
//! magnetometer's conversion and output filter, behind the gyro) is seen in the world, with
//! the frame at `t`, turned by `τ ω_w` (`ω_w` the world-frame rate): its azimuth is off by
//! `τ ω_up`, the rate about the vertical, which during fast turns is degrees (2.9° at 800 °/s
//! and 3.5 ms). Each sample is therefore rotated with the frame at `t − τ̂`, carried back from
//! the newest IMU sample by its rate, and `τ̂` is learned from every fused block: its heading
//! innovation is `ν = −(τ − τ̂) r + e`, with `r` the block's mean rate about the vertical
//! (`(ω̄ − b̂_g)·u_b`, `u_b` the up direction in the body) and `e` of the innovation's variance
//! `S = P_ψψ + σ_ψ²` (the predicted heading's and the block's, `σ_ψ²` above), so the
//! least-squares estimate with the prior `τ̂₀ = delay_s`, `σ₀ = delay_max_s`, is updated block
//! by block as
//!
//! ```text
//! I⁺ = I + r²/S,      τ̂⁺ = τ̂ − ν r / (S I⁺),      clamped to [0, delay_max_s]
//! ```
//!
//! (`I = 1/σ₀²` at first), from the blocks where the largest delay would show above the
//! innovation's noise, `(delay_max_s · r)² ≥ S`: slower turns carry less of the delay than
//! of the heading errors that also follow the turns (an offset not yet learned, the gyro's
//! scale). Turning about the vertical one way and the other makes it observable; a body that
//! does not turn fast leaves it where it was. A new hard iron starts it again from its prior
//! information. `delay_max_s = 0` keeps it at `delay_s`.
//!
//! **A new field.** A disturbed but steady field that stays the same (norm and dip within the
//! tolerances of the first disturbed block) for `new_field_s`, while the body turned at a mean
//! rate of at least `new_field_min_rate`, is taken as the new reference: its norm and dip, with
//! the old reference's north. Without a configured reference, the first block
//! defines it: `m_w = [0, ‖c_h‖, c_up]`, north is where the field points.

use super::block::MagStats;
use super::config::{AttitudeConfig, MagneticConfig, MagneticFusion};
use super::hard_iron::{HardIron, HardIronOutcome};
use super::report::{Event, Fusion, MagneticStatus};
use super::tilt::{recovery_options, world_attitude_covariance};
use crate::eskf::{up_direction, AhrsAccelBias, MagneticHeading, Magnetometer, UpdateOptions};
use crate::kernels::mat3;
use crate::lie::LieGroup;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// Norm, horizontal norm and dip angle of a world (ENU) vector.
fn norm_dip<T: Real>(c: &Vector3<T>) -> (T, T, T) {
    let h = (c.x * c.x + c.y * c.y).sqrt_rn();
    (mat3::norm(c), h, c.z.arctan2(h))
}

/// The heading innovation of a block whose field is `c` in the world, wrapped to `(−π, π]`:
/// the reference's azimuth less the block's, `atan2(r_y c_x − r_x c_y, r_x c_x + r_y c_y)`
/// (the sine and cosine of the difference of the two azimuths, times the two horizontal
/// norms).
fn heading_innovation<T: Real>(c: &Vector3<T>, reference: &Vector3<T>) -> T {
    (reference.y * c.x - reference.x * c.y).arctan2(reference.x * c.x + reference.y * c.y)
}

/// The mean rate about the vertical of a block whose mean gyro is `gyro_mean`, rad/s:
/// `(ω̄ − b̂_g)·u_b`, `u_b` the up direction in the body. Out of line: its vectors stay out of
/// the caller's frame.
#[inline(never)]
pub(super) fn rate_up<T: Real>(
    filter: &AhrsAccelBias<T>,
    gyro_mean: &Vector3<T>,
    gravity: &Vector3<T>,
) -> T {
    let up = up_direction(gravity).unwrap_or_else(Vector3::zeros);
    let state = filter.state();
    (gyro_mean - state.gyro_bias).dot(&state.attitude.inverse().act(&up))
}

/// How the body turned during a block: its length, s, the angle it turned by, rad, and its
/// mean rate about the vertical, rad/s (counter-clockwise seen from above positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Turn<T: Real> {
    pub(super) duration: T,
    pub(super) rotation: T,
    pub(super) rate_up: T,
}

/// What one block of the magnetometer did: its status, the heading update (if one was made)
/// and the event (if any).
pub(super) type Outcome<T> = (MagneticStatus, Option<Fusion<T>>, Option<Event>);

/// The magnetometer's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Magnetic<T: Real> {
    /// The world reference field, once known.
    pub(super) reference: Option<Vector3<T>>,
    /// The first disturbed field of a run of similar ones, how long the run has lasted, s, and
    /// how far the body turned meanwhile, rad.
    candidate: Option<(Vector3<T>, T, T)>,
    /// The run of consecutive gated-out blocks: how many, the first and the extreme heading
    /// innovations (rad, relative to the first), and how far the body turned meanwhile, rad.
    rejected: Rejections<T>,
    /// The magnetometer's offset in the body frame, taken off every sample.
    pub(super) hard_iron: HardIron<T>,
    /// A heading update was fused since the start-up (whose heading came from the field read
    /// with the offset of then).
    pub(super) fused_since_start: bool,
    /// The last sample and when it was first read, ns (a stuck magnetometer repeats it).
    last: Option<(Vector3<T>, u64)>,
    /// The magnetometer's delay behind the gyro, s, as learned (module docs).
    pub(super) delay: T,
    /// What the delay is known with, s⁻²: the inverse of its variance.
    delay_information: T,
}

/// A run of gated-out heading innovations.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rejections<T: Real> {
    count: u16,
    first: T,
    low: T,
    high: T,
    turned: T,
}

impl<T: Real> Rejections<T> {
    fn none() -> Self {
        Self {
            count: 0,
            first: T::zero(),
            low: T::zero(),
            high: T::zero(),
            turned: T::zero(),
        }
    }

    /// Adds a rejected block with heading innovation `r` (wrapped) and rotation `turned`.
    fn add(&mut self, r: T, turned: T) {
        if self.count == 0 {
            *self = Self {
                count: 1,
                first: r,
                low: T::zero(),
                high: T::zero(),
                turned,
            };
            return;
        }
        let (s, c) = (r - self.first).sincos();
        let d = s.arctan2(c);
        self.low = if d < self.low { d } else { self.low };
        self.high = if d > self.high { d } else { self.high };
        self.turned += turned;
        self.count = self.count.saturating_add(1);
    }
}

impl<T: Real> Magnetic<T> {
    pub(super) fn new(config: &MagneticConfig<T>) -> Self {
        Self {
            reference: config.reference,
            candidate: None,
            rejected: Rejections::none(),
            hard_iron: HardIron::new(),
            fused_since_start: false,
            last: None,
            delay: config.delay_s,
            delay_information: if config.delay_max_s > T::zero() {
                T::one() / (config.delay_max_s * config.delay_max_s)
            } else {
                T::zero()
            },
        }
    }

    /// `true` when `field` (at `t_ns`) repeats the previous sample bit for bit and has since
    /// `stuck_s` or longer: a stuck or saturated magnetometer.
    pub(super) fn stuck(
        &mut self,
        t_ns: u64,
        field: &Vector3<T>,
        config: &MagneticConfig<T>,
    ) -> bool {
        match self.last {
            Some((last, since)) if last == *field => {
                let ns = u32::try_from(t_ns.saturating_sub(since)).unwrap_or(u32::MAX);
                T::from_count(ns) * T::lit(1e-9) >= config.stuck_s
            }
            _ => {
                self.last = Some((*field, t_ns));
                false
            }
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

    /// Fuses one block's magnetometer samples (a block of `turn.duration` s during which the
    /// body turned by `turn.rotation` rad, at `turn.rate_up` rad/s about the vertical).
    #[inline(never)] // its own stack frame, not the caller's
    pub(super) fn fuse(
        &mut self,
        filter: &mut AhrsAccelBias<T>,
        stats: &MagStats<T>,
        turn: &Turn<T>,
        config: &AttitudeConfig<T>,
        mag: &MagneticConfig<T>,
    ) -> Result<Outcome<T>, NavError> {
        let (duration, rotation) = (turn.duration, turn.rotation);
        let (m_body, n) = (&stats.body, stats.n);
        let c = filter.state().attitude.act(m_body);
        let Some(reference) = self.reference else {
            self.reference = Some(Self::learn(&c));
            return Ok((MagneticStatus::Fused, None, Some(Event::NewMagneticField)));
        };
        // Beyond the white noise, the field moved in the world during the block.
        let moving = stats.scatter_sq - T::lit(3.0) * mag.sigma * mag.sigma;
        let tolerance = mag.norm_tolerance * mat3::norm(&reference);
        let steady = moving <= tolerance * tolerance;
        if !(steady && Self::agrees(&c, &reference, mag)) {
            let (status, event) = self.disturbed(&c, &reference, duration, rotation, steady, mag);
            return Ok((status, None, event));
        }
        self.candidate = None;
        let (_, horizontal, _) = norm_dip(&c);
        if !crate::kernels::positive_finite(horizontal) {
            return Ok((MagneticStatus::Disturbed, None, None));
        }
        let white = mag.sigma / horizontal;
        // A learned offset's uncertainty moves the horizontal field as much as it is itself
        // (before one is learned, the calibration's residual is in the heading noise).
        let offset = self.hard_iron.learned_sigma();
        let iron = (offset.dot(&offset) / T::lit(3.0)) / (horizontal * horizontal);
        let var = white * white / T::from_count(n.max(1))
            + mag.heading_noise * mag.heading_noise / duration
            + iron;
        let model = MagneticHeading::new(*m_body, reference, var.sqrt_rn());
        let options = UpdateOptions::default();
        let mut event = None;
        let mut fusion = match mag.fusion {
            MagneticFusion::Heading => Fusion::from(filter.update(&model, &options)?),
            MagneticFusion::Vector => {
                let sigma_sq = mag.sigma * mag.sigma / T::from_count(n.max(1))
                    + horizontal * horizontal * mag.heading_noise * mag.heading_noise / duration;
                let vector = Magnetometer::new(*m_body, reference, sigma_sq.sqrt_rn());
                Fusion::from(filter.update(&vector, &options)?)
            }
        };
        let innovation = heading_innovation(&c, &reference);
        if fusion.accepted {
            self.fused_since_start = true;
            self.rejected = Rejections::none();
        } else {
            self.rejected.add(innovation, rotation);
            let run = &self.rejected;
            // The estimate is what is wrong when the magnetometer keeps telling the same heading
            // error while the body turns: a disturbance would change with the orientation.
            let lasted = T::from_count(u32::from(run.count)) * duration;
            let wrong_estimate = run.count >= config.max_rejected_blocks
                && run.high - run.low <= T::lit(4.0) * mag.heading_noise / duration.sqrt_rn()
                && (run.turned >= T::frac_pi_2() || lasted >= mag.new_field_s);
            if wrong_estimate {
                filter.widen_attitude(T::zero(), innovation.abs())?;
                fusion = Fusion::from(filter.update(&model, &recovery_options())?);
                self.rejected = Rejections::none();
                event = Some(Event::HeadingWidened);
            }
        }
        let w = world_attitude_covariance(filter);
        if fusion.accepted {
            // The innovation's variance `S = P_ψψ + σ_ψ²` from the heading's variance after the
            // update, `P⁺ = P_ψψ σ_ψ² / (P_ψψ + σ_ψ²)`: `S = σ_ψ⁴ / (σ_ψ² − P⁺)`.
            let margin = var - w.m33;
            if margin > T::zero() {
                self.learn_delay(innovation, turn.rate_up, var * var / margin, mag);
            }
        }
        let deficit = mag.heading_floor * mag.heading_floor - w.m33;
        if deficit > T::zero() {
            filter.widen_attitude(T::zero(), deficit.sqrt_rn())?;
        }
        let status = if fusion.accepted {
            MagneticStatus::Fused
        } else {
            MagneticStatus::Rejected
        };
        Ok((status, Some(fusion), event))
    }

    /// One block's step of the delay's least squares (module docs): heading innovation `ν`,
    /// rate about the vertical `r`, the innovation's variance `S` (the predicted heading's and
    /// the block's).
    fn learn_delay(&mut self, innovation: T, rate_up: T, variance: T, mag: &MagneticConfig<T>) {
        let shown = mag.delay_max_s * rate_up;
        if !(mag.delay_max_s > T::zero() && variance > T::zero() && shown * shown >= variance) {
            return;
        }
        let information = self.delay_information + rate_up * rate_up / variance;
        let delay = self.delay - innovation * rate_up / (variance * information);
        if crate::kernels::positive_finite(information) && delay.is_finite() {
            let below_max = if delay < mag.delay_max_s {
                delay
            } else {
                mag.delay_max_s
            };
            self.delay_information = information;
            self.delay = crate::kernels::larger(T::zero(), below_max);
        }
    }

    /// The hard iron's part of a block (its own update, before the heading's): the offset
    /// drifts and the window of recent samples is fitted ([`HardIron::end_block`]). A new
    /// offset returns [`Event::NewHardIron`], and the block's heading is not fused (its
    /// samples were corrected with the old offset). Without a heading update since the
    /// start-up, the heading came from the start-up's field, read with the old offset: its
    /// error can be as large as the angle the change moves the horizontal field by,
    /// `|Δb| / ‖m_h‖` (at most π), and the covariance is widened to that. (After heading
    /// updates, the heading came from fields the old offset explained: a magnet fixed to the
    /// board since did not bias it.)
    #[inline(never)] // its own stack frame, not the caller's
    pub(super) fn hard_iron_stage(
        &mut self,
        filter: &mut AhrsAccelBias<T>,
        duration: T,
        stats: Option<&MagStats<T>>,
        mag: &MagneticConfig<T>,
    ) -> Result<Option<Event>, NavError> {
        let before = self.hard_iron.offset();
        let outcome = self
            .hard_iron
            .end_block(duration, self.reference.as_ref(), mag);
        let gone = outcome != HardIronOutcome::Learned
            && stats.is_some_and(|m| {
                self.hard_iron
                    .gone(&m.body, m.n, duration, self.reference.as_ref(), mag)
            });
        if outcome != HardIronOutcome::Learned && !gone {
            return Ok(None);
        }
        self.candidate = None;
        // The delay was learned from fields read with the old offset, whose error turns with
        // the body as a delay's does: it is learned again from its prior (from where it is).
        self.delay_information = if mag.delay_max_s > T::zero() {
            T::one() / (mag.delay_max_s * mag.delay_max_s)
        } else {
            T::zero()
        };
        if let (Some(reference), false) = (self.reference, self.fused_since_start) {
            let (_, horizontal, _) = norm_dip(&reference);
            if crate::kernels::positive_finite(horizontal) {
                let angle = mat3::norm(&(self.hard_iron.offset() - before)) / horizontal;
                let angle = if angle < T::pi() { angle } else { T::pi() };
                filter.widen_attitude(T::zero(), angle)?;
            }
        }
        Ok(Some(Event::NewHardIron))
    }

    /// A disturbed block: tracks a run of similar, steady fields and takes it as the new
    /// reference once it has lasted `new_field_s` while the body turned at a mean rate of at
    /// least `new_field_min_rate` (a field that stays the same in the world while the body
    /// turns is not a magnet carried by the body).
    fn disturbed(
        &mut self,
        c: &Vector3<T>,
        reference: &Vector3<T>,
        duration: T,
        rotation: T,
        steady: bool,
        mag: &MagneticConfig<T>,
    ) -> (MagneticStatus, Option<Event>) {
        if !steady {
            self.candidate = None;
            return (MagneticStatus::Disturbed, None);
        }
        let run = match self.candidate {
            Some((first, t, turned)) if Self::agrees(c, &first, mag) => {
                (first, t + duration, turned + rotation)
            }
            _ => (*c, duration, rotation),
        };
        if run.1 < mag.new_field_s || run.2 < mag.new_field_min_rate * run.1 {
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

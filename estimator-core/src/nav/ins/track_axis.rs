//! Whether the vehicle travels along one body axis (a car, a rover), from its GNSS velocities
//! seen in the INS's heading frame: what [`Travel::Detect`](super::Travel::Detect) learns.
//!
//! Each GNSS velocity `z` (horizontal, σ_v² per axis) at a speed of at least 2σ_v, turned into
//! the INS's horizontal body frame by its forward azimuth `ψ̂`, `u = R(−ψ̂) z`, adds to the
//! second moment of the body-frame velocities and to the noise it carries,
//!
//! ```text
//! M = Σ u uᵀ,      N = Σ σ_v²,      λ_± = ½ (tr M ± √((M₁₁ − M₂₂)² + 4 M₁₂²))
//! ```
//!
//! For a vehicle that does not move sideways the `u` lie along one axis (the body's `x` turned
//! by the INS's heading error, whatever it is; reversing stays on it), so the smaller
//! eigenvalue per sample is its lateral velocity's variance plus the fixes' noise,
//! `λ_−/n = σ_l² + N/n`, and the larger is the squared speed. A body that moves sideways as
//! freely as forwards spreads `M` like the world-frame velocities. The vehicle is taken to
//! travel along an axis while
//!
//! ```text
//! λ_− ≤ ¼ λ_+      (the lateral RMS at most half the speed)
//! ```
//!
//! from [`MIN_SAMPLES`] samples on, and no longer once `λ_− > ½ λ_+` (the margin keeps a
//! borderline vehicle from switching at every fix), with the lateral variance
//!
//! ```text
//! σ_l² = max(0, λ_−/n − N/n) + 2 (λ_−/n) √(2/n)
//! ```
//!
//! (the noise removed, and the upper 2σ bound taken: a variance from `n` samples has the
//! relative 1σ `√(2/n)`, so that a lateral motion the first fixes did not show is not ruled
//! out by them). Only a turn of the body tells an axis fixed in the body from a straight run
//! of a body that could have moved sideways: a vehicle that has not turned is *assumed* to
//! travel along its axis (the one assumption, for a vehicle without a magnetometer whose
//! heading nothing else gives at a steady speed), and its turns confirm it or take it back.
//!
//! When the INS's attitude turns by `δ` about the vertical, later samples arrive turned by `−δ`
//! against the earlier ones: `M` turns with them ([`TrackAxis::turn`]), which leaves its
//! eigenvalues as they were.

use crate::Real;
use nalgebra::Vector2;

/// Samples before the axis is judged (2 s at 5 Hz): a variance from fewer is noise.
pub(crate) const MIN_SAMPLES: u32 = 10;

/// The second moment of the body-frame velocities and their noise (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TrackAxis<T: Real> {
    /// `M₁₁`, `M₁₂`, `M₂₂`, (m/s)².
    m11: T,
    m12: T,
    m22: T,
    /// `N = Σ σ_v²`, (m/s)².
    noise: T,
    /// Samples.
    n: u32,
    /// The vehicle travels along an axis (the last judgement).
    along: bool,
}

impl<T: Real> Default for TrackAxis<T> {
    fn default() -> Self {
        Self {
            m11: T::zero(),
            m12: T::zero(),
            m22: T::zero(),
            noise: T::zero(),
            n: 0,
            along: false,
        }
    }
}

impl<T: Real> TrackAxis<T> {
    /// One GNSS velocity `z` (horizontal, `variance` per axis) with the INS's horizontal forward
    /// direction `d` (unit); a velocity slower than 2σ_v says nothing of a direction and is left
    /// out.
    pub(crate) fn add(&mut self, z: &Vector2<T>, variance: T, d: &Vector2<T>) {
        if !(z.dot(z) >= T::lit(4.0) * variance && variance.is_finite()) {
            return;
        }
        let u = Vector2::new(d.x * z.x + d.y * z.y, d.x * z.y - d.y * z.x);
        self.m11 += u.x * u.x;
        self.m12 += u.x * u.y;
        self.m22 += u.y * u.y;
        self.noise += variance;
        self.n = self.n.saturating_add(1);
        self.judge();
    }

    /// The INS's attitude turned by `turn` about the vertical: `M ← R(−turn) M R(−turn)ᵀ`.
    pub(crate) fn turn(&mut self, turn: T) {
        // In the double angle: (M₁₁ − M₂₂)/2 and M₁₂ turn by −2·turn, the trace stays.
        let (s, c) = (-(turn + turn)).sincos();
        let half = (self.m11 - self.m22) * T::lit(0.5);
        let mean = (self.m11 + self.m22) * T::lit(0.5);
        let (p, q) = (c * half - s * self.m12, s * half + c * self.m12);
        self.m11 = mean + p;
        self.m22 = mean - p;
        self.m12 = q;
    }

    /// `(λ_−, λ_+)` of `M`.
    fn eigenvalues(&self) -> (T, T) {
        let half = (self.m11 - self.m22) * T::lit(0.5);
        let mean = (self.m11 + self.m22) * T::lit(0.5);
        let radius = (half * half + self.m12 * self.m12).sqrt_rn();
        ((mean - radius).max(T::zero()), mean + radius)
    }

    fn judge(&mut self) {
        if self.n < MIN_SAMPLES {
            return;
        }
        let (low, high) = self.eigenvalues();
        self.along = if self.along {
            low <= T::lit(0.5) * high
        } else {
            low <= T::lit(0.25) * high
        };
    }

    /// The lateral velocity's variance, (m/s)², while the vehicle travels along an axis
    /// (module docs); `None` before [`MIN_SAMPLES`] samples or when it does not.
    pub(crate) fn lateral_variance(&self) -> Option<T> {
        if !self.along {
            return None;
        }
        let n = T::from_count(self.n);
        let (low, _) = self.eigenvalues();
        let per_sample = low / n;
        let excess = (per_sample - self.noise / n).max(T::zero());
        let sampling = per_sample * (T::lit(2.0) / n).sqrt_rn();
        Some(excess + T::lit(2.0) * sampling)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Velocities of `speed` along the world azimuth `track(k)`, seen by an INS whose forward
    /// azimuth is `heading(k)`, with a lateral wobble `lateral(k)`.
    fn feed(
        axis: &mut TrackAxis<f64>,
        n: u32,
        speed: f64,
        track: impl Fn(u32) -> f64,
        heading: impl Fn(u32) -> f64,
    ) {
        for k in 0..n {
            let t = track(k);
            let z = Vector2::new(t.cos(), t.sin()) * speed;
            let h = heading(k);
            axis.add(&z, 0.0001, &Vector2::new(h.cos(), h.sin()));
        }
    }

    #[test]
    fn a_vehicle_turning_with_its_track_travels_along_an_axis() {
        let mut axis = TrackAxis::default();
        // The body turns with the track, the INS 70° off: the axis holds through a full circle.
        feed(
            &mut axis,
            200,
            0.4,
            |k| 0.03 * f64::from(k),
            |k| 0.03 * f64::from(k) + 1.2,
        );
        let var = axis.lateral_variance().expect("along an axis");
        // No lateral motion: the sampling bound alone, 2 σ_v² √(2/n) with the noise only.
        assert!(
            var <= 2.0 * 0.0001 * (2.0_f64 / 200.0).sqrt() + 1e-12,
            "{var}"
        );
    }

    #[test]
    fn a_body_whose_track_turns_under_it_does_not() {
        let mut axis = TrackAxis::default();
        // A drone holding its heading while its track goes round the circle.
        feed(&mut axis, 200, 0.4, |k| 0.03 * f64::from(k), |_| 0.3);
        assert_eq!(axis.lateral_variance(), None);
    }

    #[test]
    fn reversing_stays_on_the_axis() {
        let mut axis = TrackAxis::default();
        // Forward for 30 fixes, backward for 30, the body turning slowly throughout.
        feed(
            &mut axis,
            60,
            0.3,
            |k| 0.01 * f64::from(k) + if k >= 30 { core::f64::consts::PI } else { 0.0 },
            |k| 0.01 * f64::from(k),
        );
        assert!(axis.lateral_variance().is_some());
    }

    #[test]
    fn a_turn_of_the_ins_turns_the_moment_not_its_eigenvalues() {
        let mut axis = TrackAxis::default();
        feed(&mut axis, 20, 0.4, |_| 0.5, |_| 0.1);
        let before = axis.eigenvalues();
        axis.turn(0.7);
        let after = axis.eigenvalues();
        assert!((before.0 - after.0).abs() < 1e-12 && (before.1 - after.1).abs() < 1e-12);
        // Later samples come turned by −0.7: with the moment turned alike, still one axis.
        feed(&mut axis, 20, 0.4, |_| 0.5, |_| 0.8);
        let (low, _) = axis.eigenvalues();
        assert!(low < 1e-9, "{low}");
    }

    #[test]
    fn slow_velocities_are_left_out() {
        let mut axis = TrackAxis::default();
        feed(&mut axis, 50, 0.01, f64::from, |_| 0.0);
        assert_eq!(axis.n, 0);
    }
}

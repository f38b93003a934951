//! Whether a receiver's velocities agree with its positions: the bank of yaw hypotheses
//! (`nav/ins/yaw.rs`) takes its heading from the velocities alone, so velocities that do not
//! describe the motion the positions show (a receiver reporting them in another frame, or
//! from another antenna) would give it a heading as confidently as true ones.
//!
//! Over a window that starts at a fix `(t₀, p₀)`, the horizontal velocities are integrated
//! (trapezoids, the last one carried to the fix's time) into the displacement they describe,
//! `d = ∫ v dt`, and compared with the displacement of the positions at the fix `(t, p)` that
//! closes it:
//!
//! ```text
//! e = d − (p − p₀),     S = σ_p₀² + σ_p² + Σ σ_v² Δt²/2   (per horizontal axis)
//! the velocities agree  ⇔  eᵀe / S ≤ 13.8                (χ², 2 degrees of freedom, 99.9 %)
//! ```
//!
//! A window closes once the velocities describe a displacement of 4σ of the positions' own
//! difference, `‖d‖² ≥ 16 (σ_p₀² + σ_p²)`: before that, a wrong direction of travel is lost
//! in the positions' noise. (Closed when the positions moved that far, a window would end when
//! their noise happens to carry them out, and its verdict would judge that noise: a false
//! alarm in one window of ten.) At rest it stays open; velocities that say rest while the
//! positions move are not judged, and say nothing of a heading either. The verdict holds until
//! the next window closes.

use super::seconds;
use crate::Real;
use nalgebra::Vector2;

/// The 99.9 % point of a χ² with 2 degrees of freedom.
const CHI2_2_999: f64 = 13.8155;

/// The running comparison of velocities and positions (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VelocityCheck<T: Real> {
    /// The window's first fix: its time, horizontal position and per-axis variance.
    start: Option<(u64, Vector2<T>, T)>,
    /// The last velocity in the window: its time and horizontal value.
    last: Option<(u64, Vector2<T>)>,
    /// `∫ v dt` since the window's start, m, and its variance per axis, m².
    displacement: Vector2<T>,
    displacement_variance: T,
    /// The velocities agreed with the positions over the last closed window (or none closed).
    agree: bool,
}

impl<T: Real> Default for VelocityCheck<T> {
    fn default() -> Self {
        Self {
            start: None,
            last: None,
            displacement: Vector2::zeros(),
            displacement_variance: T::zero(),
            agree: true,
        }
    }
}

impl<T: Real> VelocityCheck<T> {
    /// A horizontal velocity valid at `t_ns`, with `variance` per axis.
    pub(crate) fn velocity(&mut self, t_ns: u64, v: &Vector2<T>, variance: T) {
        if let Some((t0, v0)) = self.last {
            let dt: T = seconds(t_ns.saturating_sub(t0));
            self.displacement += (v0 + v) * (dt * T::lit(0.5));
            self.displacement_variance += variance * dt * dt * T::lit(0.5);
        }
        if self.start.is_some() {
            self.last = Some((t_ns, *v));
        }
    }

    /// A horizontal position valid at `t_ns`, with `variance` per axis. Returns the verdict
    /// when it closes a window (`Some(true)`: the velocities agree), and opens the next.
    pub(crate) fn position(&mut self, t_ns: u64, p: &Vector2<T>, variance: T) -> Option<bool> {
        let Some((_, p0, var0)) = self.start else {
            self.open(t_ns, p, variance);
            return None;
        };
        let moved = p - p0;
        let positions = var0 + variance;
        // The last velocity carried to the fix's time.
        let carried = self.last.map_or(Vector2::zeros(), |(t, v)| {
            v * seconds::<T>(t_ns.saturating_sub(t))
        });
        let described = self.displacement + carried;
        // Closed by the velocities' displacement alone: closed by the positions', a window
        // would end when their noise happens to carry them out, and judge that noise.
        if described.dot(&described) < T::lit(16.0) * positions {
            return None;
        }
        let e = described - moved;
        let s = positions + self.displacement_variance;
        self.agree = e.dot(&e) <= T::lit(CHI2_2_999) * s;
        self.open(t_ns, p, variance);
        Some(self.agree)
    }

    /// The velocities agreed with the positions over the last closed window.
    pub(crate) fn agree(&self) -> bool {
        self.agree
    }

    fn open(&mut self, t_ns: u64, p: &Vector2<T>, variance: T) {
        self.start = Some((t_ns, *p, variance));
        self.last = None;
        self.displacement = Vector2::zeros();
        self.displacement_variance = T::zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    /// Fixes at 5 Hz of a body moving at `v` m/s east, with velocities reported as `reported`.
    fn run(v: f64, reported: Vector2<f64>, seconds: u64) -> Vec<bool> {
        run_noisy(v, reported, seconds, 1.0, |_| Vector2::zeros())
    }

    /// [`run`] with the positions' variance per axis `variance` and their error `noise(k)`
    /// at fix `k`.
    fn run_noisy(
        v: f64,
        reported: Vector2<f64>,
        seconds: u64,
        variance: f64,
        noise: impl Fn(u64) -> Vector2<f64>,
    ) -> Vec<bool> {
        let mut check = VelocityCheck::default();
        let mut verdicts = Vec::new();
        for k in 0..seconds * 5 {
            let t = k * 200_000_000;
            let p = Vector2::new(v * k as f64 * 0.2, 0.0) + noise(k);
            if let Some(v) = check.position(t, &p, variance) {
                verdicts.push(v);
            }
            check.velocity(t, &reported, 0.01);
        }
        verdicts
    }

    #[test]
    fn velocities_that_describe_the_motion_agree() {
        let v = run(1.0, Vector2::new(1.0, 0.0), 60);
        // A window closes every 4√2 m ≈ 5.7 m: about every 6 s.
        assert!(v.len() >= 8, "{v:?}");
        assert!(v.iter().all(|a| *a));
    }

    #[test]
    fn velocities_turned_by_90_degrees_do_not() {
        let v = run(1.0, Vector2::new(0.0, 1.0), 60);
        assert!(!v.is_empty() && v.iter().all(|a| !*a), "{v:?}");
    }

    #[test]
    fn white_position_noise_seldom_fails_the_check() {
        // 1.5 m white noise on the positions (a deterministic spread of ±√3 σ), 0.35 m/s:
        // every window agrees.
        let u = |j: u64| ((j.wrapping_mul(2_654_435_761) % 1_000) as f64 / 999.0 - 0.5) * 2.0;
        let verdicts = run_noisy(0.35, Vector2::new(0.35, 0.0), 400, 2.25, |k| {
            Vector2::new(u(k), u(k + 7_919)) * (1.5 * 3f64.sqrt())
        });
        assert!(verdicts.len() >= 10, "{verdicts:?}");
        assert!(verdicts.iter().all(|a| *a), "{verdicts:?}");
    }

    #[test]
    fn velocities_of_a_motion_the_positions_do_not_show_do_not_agree() {
        // The positions stay; the velocities say 1 m/s north.
        let v = run(0.0, Vector2::new(0.0, 1.0), 20);
        assert!(!v.is_empty() && v.iter().all(|a| !*a), "{v:?}");
    }

    #[test]
    fn at_rest_nothing_is_judged() {
        assert!(run(0.0, Vector2::zeros(), 20).is_empty());
    }
}

//! The heading of a run that must find it: when it is found after the body starts to move,
//! and whether it was ever reported valid while wrong.
//!
//! The heading error is the error rotation's component about the world's up direction:
//! `ψ_e = e_zᵀ Log(R R̂ᵀ) = e_zᵀ R̂ δθ` (`δθ = Log(R̂ᵀ R)`, the body-frame attitude error the
//! other metrics use), and its reported variance `σ_ψ² = u_bᵀ P_θθ u_b` with `u_b = R̂ᵀ e_z`.

use super::Estimate;
use crate::dataset::read::Truth;
use estimator_core::lie::LieGroup;
use nalgebra::Vector3;
use serde::Serialize;

/// The body moves once the truth's horizontal speed reaches this, m/s (a walking pace is
/// 1.4; a GNSS velocity's noise 0.05–0.1).
pub const MOVING_SPEED_MPS: f64 = 0.05;

/// The heading errors whose settling times are reported, degrees.
pub const SETTLE_DEG: [f64; 2] = [2.0, 5.0];

/// The heading's figures of one run (`metrics.json` `heading`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeadingScore {
    /// When the body first moved ([`MOVING_SPEED_MPS`]), s after the first scored sample.
    pub first_motion_s: f64,
    /// The first time the heading was reported valid, s after the first motion (negative:
    /// before it); `None` (`null`): never.
    pub valid_after_motion_s: Option<f64>,
    /// For each of [`SETTLE_DEG`] (`"2"`, `"5"`): how long after the first motion the heading
    /// error came within it for good (to the end of the run), s; `None` (`null`): it was
    /// outside at the end.
    pub settled_after_motion_s: std::collections::BTreeMap<String, Option<f64>>,
    /// The largest heading error from 60 s after the first motion, degrees.
    pub max_error_from_60s_deg: Option<f64>,
    /// Samples with the attitude (tilt and heading) reported valid, from the first motion.
    pub valid_samples: u64,
    /// … of them with the heading error outside 3σ and 4σ of its reported σ.
    pub valid_outside_3sigma: u64,
    /// See `valid_outside_3sigma`.
    pub valid_outside_4sigma: u64,
}

/// The streaming accumulator of [`HeadingScore`].
#[derive(Clone, Debug, Default)]
pub struct HeadingAccumulator {
    first_ns: Option<u64>,
    motion_ns: Option<u64>,
    valid_ns: Option<u64>,
    /// The last time after the first motion the error was outside each of [`SETTLE_DEG`].
    last_outside_ns: [Option<u64>; 2],
    /// Whether the last sample was outside each of them.
    outside_now: [bool; 2],
    max_from_60s: Option<f64>,
    valid_samples: u64,
    outside_3: u64,
    outside_4: u64,
}

impl HeadingAccumulator {
    /// Takes in one estimate with the truth at its time. Only estimates with an attitude
    /// covariance and a validity (a navigator's) count.
    pub fn add(&mut self, e: &Estimate, truth: &Truth) {
        let (Some(p), Some(valid)) = (e.cov[0], e.valid) else {
            return;
        };
        self.first_ns.get_or_insert(e.t_ns);
        let speed = Vector3::new(truth.velocity.x, truth.velocity.y, 0.0).norm();
        if self.motion_ns.is_none() && speed >= MOVING_SPEED_MPS {
            self.motion_ns = Some(e.t_ns);
        }
        if valid[0] {
            self.valid_ns.get_or_insert(e.t_ns);
        }
        let Some(motion) = self.motion_ns else {
            return;
        };
        let r = e.attitude.rotation_matrix();
        let body = e.attitude.inverse().compose(&truth.attitude);
        let error = (r * body.log()).z;
        let u = r.transpose() * Vector3::z();
        let sigma = (u.dot(&(p * u))).max(0.0).sqrt();
        if valid[0] {
            self.valid_samples += 1;
            self.outside_3 += u64::from(error.abs() > 3.0 * sigma);
            self.outside_4 += u64::from(error.abs() > 4.0 * sigma);
        }
        for (k, deg) in SETTLE_DEG.iter().enumerate() {
            let outside = error.abs() > deg.to_radians();
            self.outside_now[k] = outside;
            if outside {
                self.last_outside_ns[k] = Some(e.t_ns);
            }
        }
        if e.t_ns >= motion.saturating_add(60_000_000_000) {
            let d = error.abs().to_degrees();
            self.max_from_60s = Some(self.max_from_60s.map_or(d, |m| m.max(d)));
        }
    }

    /// The figures, once the body has moved.
    #[must_use]
    pub fn score(&self) -> Option<HeadingScore> {
        let (first, motion) = (self.first_ns?, self.motion_ns?);
        let after = |t: u64| (t as f64 - motion as f64) * 1e-9;
        let settled = SETTLE_DEG
            .iter()
            .enumerate()
            .map(|(k, deg)| {
                let s = if self.outside_now[k] {
                    None
                } else {
                    Some(self.last_outside_ns[k].map_or(0.0, after))
                };
                (format!("{deg}"), s)
            })
            .collect();
        Some(HeadingScore {
            first_motion_s: (motion - first) as f64 * 1e-9,
            valid_after_motion_s: self.valid_ns.map(after),
            settled_after_motion_s: settled,
            max_error_from_60s_deg: self.max_from_60s,
            valid_samples: self.valid_samples,
            valid_outside_3sigma: self.outside_3,
            valid_outside_4sigma: self.outside_4,
        })
    }
}

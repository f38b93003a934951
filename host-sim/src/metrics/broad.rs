//! The orientation error metric of BROAD (`calculateRMSE`), from D. Laidig, M. Caruso,
//! A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust Inertial Orientation Estimation",
//! Data 6(7), 2021, doi:10.3390/data6070072.
//!
//! With `q_est` and `q_true` the estimated and true `world_from_body` quaternions at one IMU
//! sample, the error is taken in the earth frame,
//!
//! ```text
//! e = q_est ⊗ q_true⁻¹ = (e_w, e_x, e_y, e_z),
//! ```
//!
//! and split into its rotation about the vertical (heading, world `z` up) and the rest
//! (inclination):
//!
//! ```text
//! total        = 2·acos |e_w|
//! heading      = 2·atan |e_z / e_w|
//! inclination  = 2·acos √(e_w² + e_z²)
//! ```
//!
//! Each is invariant to the sign of `e` (`q` and `−q` are the same rotation). They are computed
//! as the equal forms `2·atan2(‖(e_x, e_y, e_z)‖, |e_w|)`, `2·atan2(|e_z|, |e_w|)` and
//! `2·atan2(‖(e_x, e_y)‖, ‖(e_w, e_z)‖)`, which keep their precision near zero error. The figure of a
//! trial is the RMSE in degrees of each angle over the IMU samples inside the trial's movement
//! intervals (`movement.csv`, inclusive), with the estimate at a sample being the filter's
//! output after that sample. A sample where the optical system lost the marker (rows left out of
//! the truth) is not scored, as BROAD skips its NaN truth ([`super::TruthSpacing`]).

use nalgebra::UnitQuaternion;
use serde::Serialize;

/// The three error angles of one sample, radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BroadError {
    /// `2·acos |e_w|`, in `[0, π]`.
    pub total: f64,
    /// `2·atan |e_z / e_w|`, in `[0, π]`.
    pub heading: f64,
    /// `2·acos √(e_w² + e_z²)`, in `[0, π]`.
    pub inclination: f64,
}

/// The error of `estimate` against `truth` (both `world_from_body`), see the module docs.
#[must_use]
pub fn broad_error(estimate: &UnitQuaternion<f64>, truth: &UnitQuaternion<f64>) -> BroadError {
    let e = estimate * truth.inverse();
    let (w, x, y, z) = (e.w.abs(), e.i, e.j, e.k.abs());
    let horizontal = x.hypot(y);
    // For a unit quaternion these equal the acos forms of the module docs, without their
    // loss of precision near zero error (acos(1 − ε) ≈ √(2ε)).
    BroadError {
        total: 2.0 * horizontal.hypot(z).atan2(w),
        heading: 2.0 * z.atan2(w),
        inclination: 2.0 * horizontal.atan2(w.hypot(z)),
    }
}

/// Whether `t_ns` lies in one of `intervals` (ordered, disjoint, inclusive at both ends).
#[must_use]
pub fn in_intervals(intervals: &[(u64, u64)], t_ns: u64) -> bool {
    // The first interval that ends at or after t; t is inside if that interval starts by t.
    let i = intervals.partition_point(|&(_, end)| end < t_ns);
    intervals.get(i).is_some_and(|&(start, _)| start <= t_ns)
}

/// The NEES bound of the reported 3σ ellipsoid of a 3-D error: `eᵀ P⁻¹ e ≤ 3²`, which a
/// consistent estimate's error satisfies with probability `P(χ²₃ ≤ 9) = 97.1 %`.
pub const THREE_SIGMA_NEES: f64 = 9.0;

/// Squared error angles summed over the scored samples, and how many of the samples with a
/// reported attitude covariance had their error inside its 3σ ellipsoid.
#[derive(Clone, Debug, Default)]
pub struct BroadAccumulator {
    sq: [f64; 3],
    n: u64,
    inside: u64,
    covered: u64,
}

impl BroadAccumulator {
    /// Adds one sample's error.
    pub fn add(&mut self, e: &BroadError) {
        self.sq[0] += e.total * e.total;
        self.sq[1] += e.heading * e.heading;
        self.sq[2] += e.inclination * e.inclination;
        self.n += 1;
    }

    /// Adds one sample's attitude NEES `eᵀ P⁻¹ e` (the error in the frame of the reported
    /// covariance `P`): inside the 3σ ellipsoid when at most [`THREE_SIGMA_NEES`].
    pub fn add_nees(&mut self, nees: f64) {
        self.covered += 1;
        if nees <= THREE_SIGMA_NEES {
            self.inside += 1;
        }
    }

    /// The RMSEs so far (NaN, written `null`, when no sample was scored).
    #[must_use]
    pub fn rmse(&self) -> BroadRmse {
        let rmse = |i: usize| {
            if self.n > 0 {
                (self.sq[i] / self.n as f64).sqrt().to_degrees()
            } else {
                f64::NAN
            }
        };
        BroadRmse {
            total_deg: rmse(0),
            heading_deg: rmse(1),
            inclination_deg: rmse(2),
            samples: self.n,
            inside_3sigma: if self.covered > 0 {
                self.inside as f64 / self.covered as f64
            } else {
                f64::NAN
            },
        }
    }
}

/// BROAD's figures of one trial.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BroadRmse {
    /// RMSE of the total error angle, degrees.
    pub total_deg: f64,
    /// RMSE of the heading error, degrees.
    pub heading_deg: f64,
    /// RMSE of the inclination error, degrees.
    pub inclination_deg: f64,
    /// IMU samples scored (inside the movement intervals, with a truth).
    pub samples: u64,
    /// The fraction of those samples, among the ones with a reported attitude covariance,
    /// whose attitude error is inside the reported 3σ ellipsoid ([`THREE_SIGMA_NEES`]; 0.971
    /// for a consistent estimate); NaN (`null`) without a covariance.
    pub inside_3sigma: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn rot(axis: Vector3<f64>, deg: f64) -> UnitQuaternion<f64> {
        UnitQuaternion::from_scaled_axis(axis.normalize() * deg.to_radians())
    }

    fn degrees(e: BroadError) -> [f64; 3] {
        [
            e.total.to_degrees(),
            e.heading.to_degrees(),
            e.inclination.to_degrees(),
        ]
    }

    fn close(got: [f64; 3], want: [f64; 3]) {
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-9, "got {got:?}, want {want:?}");
        }
    }

    /// Some true attitudes, far from the identity.
    fn truths() -> [UnitQuaternion<f64>; 3] {
        [
            UnitQuaternion::identity(),
            rot(Vector3::new(1.0, 2.0, -0.5), 73.0),
            rot(Vector3::new(-0.3, 0.1, 1.0), 150.0),
        ]
    }

    #[test]
    fn a_pure_heading_error_is_all_heading() {
        for t in truths() {
            // An error about the world vertical, applied in the earth frame.
            let est = rot(Vector3::z(), 12.0) * t;
            close(degrees(broad_error(&est, &t)), [12.0, 12.0, 0.0]);
            let est = rot(Vector3::z(), -170.0) * t;
            close(degrees(broad_error(&est, &t)), [170.0, 170.0, 0.0]);
        }
    }

    #[test]
    fn a_pure_tilt_error_is_all_inclination() {
        for t in truths() {
            let est = rot(Vector3::x(), 7.0) * t;
            close(degrees(broad_error(&est, &t)), [7.0, 0.0, 7.0]);
            let est = rot(Vector3::new(1.0, -1.0, 0.0), 25.0) * t;
            close(degrees(broad_error(&est, &t)), [25.0, 0.0, 25.0]);
        }
    }

    #[test]
    fn a_mixed_error_splits_into_heading_then_tilt() {
        // e = q_z(α) ⊗ q_x(β): e_w = cos(α/2)cos(β/2), e_z = sin(α/2)cos(β/2), so heading = α,
        // inclination = β and total = 2·acos(cos(α/2)cos(β/2)).
        let (a, b) = (30.0_f64, 40.0_f64);
        let total = 2.0
            * ((a.to_radians() / 2.0).cos() * (b.to_radians() / 2.0).cos())
                .acos()
                .to_degrees();
        for t in truths() {
            let est = rot(Vector3::z(), a) * rot(Vector3::x(), b) * t;
            close(degrees(broad_error(&est, &t)), [total, a, b]);
        }
    }

    #[test]
    fn the_sign_of_the_quaternion_does_not_matter() {
        let t = truths()[1];
        let est = rot(Vector3::new(0.2, 0.3, 1.0), 50.0) * t;
        let flipped = UnitQuaternion::new_unchecked(-est.into_inner());
        close(
            degrees(broad_error(&flipped, &t)),
            degrees(broad_error(&est, &t)),
        );
        close(degrees(broad_error(&t, &t)), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn rmse_over_samples_and_nothing_scored_is_nan() {
        assert!(BroadAccumulator::default().rmse().total_deg.is_nan());
        let mut acc = BroadAccumulator::default();
        let t = truths()[2];
        acc.add(&broad_error(&(rot(Vector3::z(), 3.0) * t), &t));
        acc.add(&broad_error(&(rot(Vector3::x(), 4.0) * t), &t));
        let r = acc.rmse();
        assert_eq!(r.samples, 2);
        close(
            [r.total_deg, r.heading_deg, r.inclination_deg],
            [(12.5_f64).sqrt(), (4.5_f64).sqrt(), (8.0_f64).sqrt()],
        );
    }

    #[test]
    fn intervals_are_inclusive() {
        let iv = [(10, 20), (30, 30), (40, 50)];
        for (t, inside) in [
            (9, false),
            (10, true),
            (15, true),
            (20, true),
            (21, false),
            (30, true),
            (31, false),
            (50, true),
            (51, false),
        ] {
            assert_eq!(in_intervals(&iv, t), inside, "t = {t}");
        }
        assert!(!in_intervals(&[], 5));
    }

    /// The 3σ share counts a NEES of exactly 9 as inside and above it as outside, over the
    /// samples with a covariance only; without any it is NaN (`null`), not 0.
    #[test]
    fn the_three_sigma_share_counts_nees_up_to_nine() {
        let mut a = BroadAccumulator::default();
        assert!(a.rmse().inside_3sigma.is_nan());
        for nees in [1.0, 9.0, 9.5, 20.0, 0.0] {
            a.add_nees(nees);
        }
        assert!((a.rmse().inside_3sigma - 0.6).abs() < 1e-12);
    }
}

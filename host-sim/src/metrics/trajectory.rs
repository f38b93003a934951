//! Trajectory metrics as [evo](https://github.com/MichaelGrupp/evo) defines them: the absolute
//! trajectory error (APE/ATE, translation part) after an alignment, and the relative pose error
//! (RPE, translation part) over a delta in seconds or metres, each summarised by evo's
//! statistics.
//!
//! The input is a list of [`PosePair`]s: the estimate and the truth at the same instants, in
//! time order (the replay pairs every estimate with the truth interpolated at its time, see
//! [`crate::metrics::Scorer`]). With `Pᵢ = (R̂ᵢ, p̂ᵢ)` the estimated and `Qᵢ = (Rᵢ, pᵢ)` the true
//! `world_from_body` poses:
//!
//! * **ATE** of pair `i` after the alignment `S = (R_S, t_S)` (applied to the estimate):
//!   `eᵢ = ‖R_S p̂ᵢ + t_S − pᵢ‖` (evo's `APE` with `translation_part`: the translation of
//!   `Qᵢ⁻¹ S Pᵢ` has that norm).
//! * **RPE** of the index pair `(i, j)`: `E = (Qᵢ⁻¹Qⱼ)⁻¹(Pᵢ⁻¹Pⱼ)`, whose translation has the norm
//!   `eᵢⱼ = ‖R̂ᵢᵀ(p̂ⱼ − p̂ᵢ) − Rᵢᵀ(pⱼ − pᵢ)‖` (evo's `RPE` with `translation_part`, from the TUM
//!   RGB-D benchmark). It does not depend on any alignment of the estimate.
//! * **Statistics** (evo's): over the errors `e₁…e_n`, `rmse = √(Σeᵢ²/n)`, `mean`, `median` (the
//!   mean of the two middle values for even `n`), `std = √(Σ(eᵢ − mean)²/n)` (the population
//!   standard deviation, numpy's default), `min`, `max` and `sse = Σeᵢ²`.
//!
//! The alignments ([`Alignment`]):
//!
//! * `none`: the frames are taken as the same (a GNSS-referenced run is in the true frame).
//! * `se3`: the rotation and translation minimising `Σ‖R p̂ᵢ + t − pᵢ‖²`, Umeyama's closed form
//!   without scale (evo's `-a`, [`umeyama`]).
//! * `yaw`: the same minimum over rotations about the vertical `z` only, and a translation (the
//!   four unobservable directions of visual-inertial odometry, [`yaw_alignment`]).
//! * `origin`: the rigid motion that makes the first estimated pose equal the first true one,
//!   `S = Q₀ P₀⁻¹` (evo's `--align_origin`).
//!
//! Evo pairs the two TUM files by nearest timestamp (within 10 ms), while the replay
//! interpolates the truth at each estimate time; where the truth is sampled at the estimate
//! times (host-sim's simulated datasets) the pairs are the same. Evo has no delta in seconds:
//! on a uniformly sampled estimate, a delta of `δ` seconds is evo's delta of `δ·rate` frames.

use estimator_core::lie::{LieGroup, So3};
use nalgebra::{Matrix3, Vector3, SVD};
use serde::Serialize;

/// A `world_from_body` pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Position, m.
    pub position: Vector3<f64>,
    /// Attitude, `world_from_body`.
    pub attitude: So3<f64>,
}

/// The estimate and the truth at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PosePair {
    /// ns.
    pub t_ns: u64,
    /// The estimated pose.
    pub estimate: Pose,
    /// The true pose.
    pub truth: Pose,
}

/// How the estimate is aligned to the truth before its absolute error is taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Alignment {
    /// No alignment.
    None,
    /// Rotation and translation, Umeyama without scale (evo `-a`).
    Se3,
    /// Rotation about the vertical and translation.
    Yaw,
    /// The first poses made equal (evo `--align_origin`).
    Origin,
}

impl Alignment {
    /// Every alignment, in this order.
    pub const ALL: [Alignment; 4] = [
        Alignment::None,
        Alignment::Se3,
        Alignment::Yaw,
        Alignment::Origin,
    ];

    /// The name used in `metrics.json`: `none`, `se3`, `yaw`, `origin`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Alignment::None => "none",
            Alignment::Se3 => "se3",
            Alignment::Yaw => "yaw",
            Alignment::Origin => "origin",
        }
    }

    /// A short description for the summary, e.g. `SE(3)-aligned`.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Alignment::None => "unaligned",
            Alignment::Se3 => "SE(3)-aligned",
            Alignment::Yaw => "yaw-aligned",
            Alignment::Origin => "origin-aligned",
        }
    }
}

/// A rigid motion `p ↦ R p + t`, applied to the estimate (truth world from estimate world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// `R`.
    pub rotation: Matrix3<f64>,
    /// `t`, m.
    pub translation: Vector3<f64>,
}

impl Transform {
    /// The identity.
    #[must_use]
    pub fn identity() -> Self {
        Self {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// `R p + t`.
    #[must_use]
    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    /// The rotation angle of `R`, rad.
    #[must_use]
    pub fn angle(&self) -> f64 {
        ((self.rotation.trace() - 1.0) * 0.5)
            .clamp(-1.0, 1.0)
            .acos()
    }
}

fn mean(v: &[Vector3<f64>]) -> Vector3<f64> {
    v.iter().fold(Vector3::zeros(), |a, p| a + p) / v.len() as f64
}

/// Umeyama's closed form without scale: the rotation `R` and translation `t` minimising
/// `Σᵢ ‖yᵢ − (R xᵢ + t)‖²` (S. Umeyama, "Least-squares estimation of transformation parameters
/// between two point patterns", IEEE TPAMI 13(4), 1991).
///
/// With `μ_x, μ_y` the means and `Σ_xy = (1/n) Σᵢ (yᵢ − μ_y)(xᵢ − μ_x)ᵀ = U D Vᵀ` (SVD),
/// `R = U S Vᵀ` where `S = I`, except that the entry of the smallest singular value is `−1` when
/// `det U · det V < 0` (a reflection would fit better: the closest rotation is taken), and
/// `t = μ_y − R μ_x`.
///
/// `None` for empty or unequal inputs, non-finite numbers, or an SVD that does not converge.
/// The rotation is not unique when the points are collinear (any rotation about the line fits).
#[must_use]
pub fn umeyama(x: &[Vector3<f64>], y: &[Vector3<f64>]) -> Option<Transform> {
    if x.is_empty() || x.len() != y.len() {
        return None;
    }
    let (mx, my) = (mean(x), mean(y));
    let n = x.len() as f64;
    let cov = x.iter().zip(y).fold(Matrix3::zeros(), |c, (a, b)| {
        c + (b - my) * (a - mx).transpose()
    }) / n;
    if !cov.iter().all(|v| v.is_finite()) {
        return None;
    }
    let svd = SVD::try_new_unordered(cov, true, true, f64::EPSILON, 0)?;
    let (u, v_t) = (svd.u?, svd.v_t?);
    let mut s = Matrix3::identity();
    if u.determinant() * v_t.determinant() < 0.0 {
        let smallest = svd.singular_values.imin();
        s[(smallest, smallest)] = -1.0;
    }
    let rotation = u * s * v_t;
    Some(Transform {
        rotation,
        translation: my - rotation * mx,
    })
}

/// The rotation about `z` by `θ`.
#[must_use]
pub fn rot_z(theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// The rotation about the vertical `z` by `θ` and the translation `t` minimising
/// `Σᵢ ‖yᵢ − (R_z(θ) xᵢ + t)‖²`.
///
/// With `x'ᵢ = xᵢ − μ_x` and `y'ᵢ = yᵢ − μ_y` the centred points, the sum is smallest where
/// `Σᵢ y'ᵢ · R_z(θ) x'ᵢ = cos θ · Σᵢ(x'ₓy'ₓ + x'ᵧy'ᵧ) + sin θ · Σᵢ(x'ₓy'ᵧ − x'ᵧy'ₓ) + const` is
/// largest: `θ = atan2(Σᵢ(x'ₓy'ᵧ − x'ᵧy'ₓ), Σᵢ(x'ₓy'ₓ + x'ᵧy'ᵧ))`, and `t = μ_y − R_z(θ) μ_x`.
///
/// `None` for empty or unequal inputs or non-finite numbers.
#[must_use]
pub fn yaw_alignment(x: &[Vector3<f64>], y: &[Vector3<f64>]) -> Option<Transform> {
    if x.is_empty() || x.len() != y.len() {
        return None;
    }
    let (mx, my) = (mean(x), mean(y));
    let (mut sin, mut cos) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        let (a, b) = (a - mx, b - my);
        sin += a.x * b.y - a.y * b.x;
        cos += a.x * b.x + a.y * b.y;
    }
    let theta = sin.atan2(cos);
    if !theta.is_finite() {
        return None;
    }
    let rotation = rot_z(theta);
    Some(Transform {
        rotation,
        translation: my - rotation * mx,
    })
}

/// The rigid motion `S = Q₀ P₀⁻¹` taking the first estimated pose onto the first true one
/// (evo's `--align_origin`): `R_S = R₀ R̂₀ᵀ`, `t_S = p₀ − R_S p̂₀`.
#[must_use]
pub fn origin_alignment(first: &PosePair) -> Transform {
    let rotation = first.truth.attitude.rotation_matrix()
        * first.estimate.attitude.rotation_matrix().transpose();
    Transform {
        rotation,
        translation: first.truth.position - rotation * first.estimate.position,
    }
}

/// The transform of `alignment` for these pairs; `None` where there are no pairs (or, for
/// `se3` and `yaw`, non-finite positions or an SVD that does not converge).
#[must_use]
pub fn align(pairs: &[PosePair], alignment: Alignment) -> Option<Transform> {
    let first = pairs.first()?;
    let positions = || {
        let est: Vec<Vector3<f64>> = pairs.iter().map(|p| p.estimate.position).collect();
        let truth: Vec<Vector3<f64>> = pairs.iter().map(|p| p.truth.position).collect();
        (est, truth)
    };
    match alignment {
        Alignment::None => Some(Transform::identity()),
        Alignment::Origin => Some(origin_alignment(first)),
        Alignment::Se3 => {
            let (x, y) = positions();
            umeyama(&x, &y)
        }
        Alignment::Yaw => {
            let (x, y) = positions();
            yaw_alignment(&x, &y)
        }
    }
}

/// Evo's summary statistics of a list of errors (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stats {
    /// Number of errors.
    pub pairs: usize,
    /// `√(Σeᵢ²/n)`.
    pub rmse: f64,
    /// `Σeᵢ/n`.
    pub mean: f64,
    /// The middle value (the mean of the two middle values for even `n`).
    pub median: f64,
    /// Population standard deviation `√(Σ(eᵢ − mean)²/n)`.
    pub std: f64,
    /// Smallest error.
    pub min: f64,
    /// Largest error.
    pub max: f64,
    /// `Σeᵢ²`.
    pub sse: f64,
}

impl Stats {
    /// The statistics of `errors`; `None` when there are none.
    #[must_use]
    pub fn of(errors: &[f64]) -> Option<Self> {
        if errors.is_empty() {
            return None;
        }
        let n = errors.len() as f64;
        let sse: f64 = errors.iter().map(|e| e * e).sum();
        let mean = errors.iter().sum::<f64>() / n;
        let var = errors.iter().map(|e| (e - mean) * (e - mean)).sum::<f64>() / n;
        let mut sorted = errors.to_vec();
        sorted.sort_by(f64::total_cmp);
        let m = sorted.len() / 2;
        let median = if sorted.len() % 2 == 1 {
            sorted[m]
        } else {
            0.5 * (sorted[m - 1] + sorted[m])
        };
        Some(Self {
            pairs: errors.len(),
            rmse: (sse / n).sqrt(),
            mean,
            median,
            std: var.sqrt(),
            min: sorted[0],
            max: sorted[sorted.len() - 1],
            sse,
        })
    }
}

/// The absolute trajectory error after one alignment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Ate {
    /// The alignment.
    pub alignment: Alignment,
    /// Statistics of `‖R_S p̂ᵢ + t_S − pᵢ‖`, m.
    #[serde(flatten)]
    pub stats: Stats,
    /// Rotation angle of the alignment, degrees.
    pub alignment_rotation_deg: f64,
    /// Translation of the alignment, m.
    pub alignment_translation_m: [f64; 3],
}

/// The ATE (translation part) of `pairs` after `alignment`; `None` without pairs or where the
/// alignment cannot be computed (see [`align`]).
#[must_use]
pub fn ate(pairs: &[PosePair], alignment: Alignment) -> Option<Ate> {
    let s = align(pairs, alignment)?;
    let errors: Vec<f64> = pairs
        .iter()
        .map(|p| (s.apply(&p.estimate.position) - p.truth.position).norm())
        .collect();
    Some(Ate {
        alignment,
        stats: Stats::of(&errors)?,
        alignment_rotation_deg: s.angle().to_degrees(),
        alignment_translation_m: [s.translation.x, s.translation.y, s.translation.z],
    })
}

/// The spacing of the RPE's pairs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Delta {
    /// Time between the two poses of a pair, s.
    Seconds(f64),
    /// Distance travelled by the estimate between the two poses of a pair, m (evo's `m` unit).
    Metres(f64),
}

impl Delta {
    /// The value.
    #[must_use]
    pub fn value(self) -> f64 {
        match self {
            Delta::Seconds(v) | Delta::Metres(v) => v,
        }
    }

    /// The unit as `metrics.json` writes it: `s` or `m`.
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Delta::Seconds(_) => "s",
            Delta::Metres(_) => "m",
        }
    }
}

/// The RPE's default delta: 1 s.
pub const DEFAULT_RPE_DELTA: Delta = Delta::Seconds(1.0);

/// The index pairs `(i, j)` of the RPE, consecutive and not overlapping, as evo's
/// `filter_pairs_by_path` chooses them (with `all_pairs` off): the first pair starts at pose 0;
/// a pair ends at the first pose `j` where the delta accumulated since its start `i` reaches
/// `δ` (time `t_j − t_i ≥ δ`, or the estimate's path length `Σ‖p̂ₖ₊₁ − p̂ₖ‖ ≥ δ`), and the next
/// pair starts there. On a uniformly sampled estimate, `δ` seconds gives the pairs of evo's
/// `filter_pairs_by_index` with `δ·rate` frames.
///
/// Empty for a delta that is not positive and finite.
#[must_use]
pub fn rpe_index_pairs(pairs: &[PosePair], delta: Delta) -> Vec<(usize, usize)> {
    let d = delta.value();
    let mut out = Vec::new();
    if !(d.is_finite() && d > 0.0) || pairs.is_empty() {
        return out;
    }
    let mut start = 0usize;
    let mut path = 0.0;
    for j in 1..pairs.len() {
        let reached = match delta {
            Delta::Seconds(s) => {
                let dt_ns = pairs[j].t_ns.saturating_sub(pairs[start].t_ns);
                dt_ns as f64 >= s * 1e9
            }
            Delta::Metres(m) => {
                path += (pairs[j].estimate.position - pairs[j - 1].estimate.position).norm();
                path >= m
            }
        };
        if reached {
            out.push((start, j));
            start = j;
            path = 0.0;
        }
    }
    out
}

/// The translation error of the relative motion between poses `i` and `j`:
/// `‖R̂ᵢᵀ(p̂ⱼ − p̂ᵢ) − Rᵢᵀ(pⱼ − pᵢ)‖`, the norm of the translation of
/// `(Qᵢ⁻¹Qⱼ)⁻¹(Pᵢ⁻¹Pⱼ)`.
#[must_use]
pub fn relative_translation_error(a: &PosePair, b: &PosePair) -> f64 {
    let est = a
        .estimate
        .attitude
        .inverse()
        .act(&(b.estimate.position - a.estimate.position));
    let truth = a
        .truth
        .attitude
        .inverse()
        .act(&(b.truth.position - a.truth.position));
    (est - truth).norm()
}

/// The relative pose error over a delta.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Rpe {
    /// The delta's value.
    pub delta: f64,
    /// The delta's unit: `s` or `m`.
    pub delta_unit: &'static str,
    /// Statistics of the translation errors, m.
    #[serde(flatten)]
    pub stats: Stats,
}

/// The RPE (translation part) of `pairs` over `delta` ([`rpe_index_pairs`],
/// [`relative_translation_error`]); `None` when no pair reaches the delta.
#[must_use]
pub fn rpe(pairs: &[PosePair], delta: Delta) -> Option<Rpe> {
    let errors: Vec<f64> = rpe_index_pairs(pairs, delta)
        .into_iter()
        .map(|(i, j)| relative_translation_error(&pairs[i], &pairs[j]))
        .collect();
    Some(Rpe {
        delta: delta.value(),
        delta_unit: delta.unit(),
        stats: Stats::of(&errors)?,
    })
}

/// The attitude error after removing a constant heading offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YawAligned {
    /// The offset `ψ` (the estimate is rotated by `R_z(ψ)`), rad, in `(−π, π]`.
    pub offset_rad: f64,
    /// RMSE of the geodesic angle `‖log((R_z(ψ) R̂ᵢ)ᵀ Rᵢ)‖` over the pairs, rad.
    pub rmse_rad: f64,
}

fn yaw_residuals(pairs: &[PosePair], psi: f64) -> f64 {
    let rz = So3::exp(&Vector3::new(0.0, 0.0, -psi));
    pairs
        .iter()
        .map(|p| {
            p.estimate
                .attitude
                .inverse()
                .compose(&rz)
                .compose(&p.truth.attitude)
                .log()
                .norm_squared()
        })
        .sum()
}

/// The constant rotation `R_z(ψ)` about the world vertical that, applied to every estimated
/// attitude, minimises the attitude error `Σᵢ ‖rᵢ(ψ)‖²`, `rᵢ(ψ) = log((R_z(ψ) R̂ᵢ)ᵀ Rᵢ)` (the
/// scorer's error with the heading offset removed: the score of an attitude estimate without a
/// heading reference, whose heading is arbitrary but should not drift).
///
/// Start: the chordal minimum `ψ₀ = atan2(M₁₀ − M₀₁, M₀₀ + M₁₁)` with `M = Σᵢ Rᵢ R̂ᵢᵀ` (it
/// maximises `tr(R_z(ψ)ᵀ M)`); then Gauss-Newton on the geodesic residuals, with
/// `∂rᵢ/∂ψ = −J_r⁻¹(rᵢ) Rᵢᵀ e_z`, a step taken only where it lowers the sum.
///
/// `None` without pairs.
#[must_use]
pub fn attitude_yaw_aligned(pairs: &[PosePair]) -> Option<YawAligned> {
    if pairs.is_empty() {
        return None;
    }
    let m = pairs.iter().fold(Matrix3::zeros(), |m, p| {
        m + p.truth.attitude.rotation_matrix() * p.estimate.attitude.rotation_matrix().transpose()
    });
    let mut psi = (m[(1, 0)] - m[(0, 1)]).atan2(m[(0, 0)] + m[(1, 1)]);
    if !psi.is_finite() {
        psi = 0.0;
    }
    let mut cost = yaw_residuals(pairs, psi);
    let ez = Vector3::z();
    for _ in 0..50 {
        let rz = So3::exp(&Vector3::new(0.0, 0.0, -psi));
        let (mut g, mut h) = (0.0, 0.0);
        for p in pairs {
            let e = p
                .estimate
                .attitude
                .inverse()
                .compose(&rz)
                .compose(&p.truth.attitude);
            let (r, jr_inv) = e.log_jac();
            let j = -(jr_inv * p.truth.attitude.inverse().act(&ez));
            g += j.dot(&r);
            h += j.norm_squared();
        }
        if !(h > 0.0 && g.is_finite()) {
            break;
        }
        let mut step = -g / h;
        let mut improved = false;
        for _ in 0..30 {
            let c = yaw_residuals(pairs, psi + step);
            if c < cost {
                psi += step;
                cost = c;
                improved = true;
                break;
            }
            step *= 0.5;
        }
        if !improved || step.abs() < 1e-12 {
            break;
        }
    }
    let offset = (psi.sin()).atan2(psi.cos());
    Some(YawAligned {
        offset_rad: offset,
        rmse_rad: (cost / pairs.len() as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: u64 = 1_000_000_000;

    fn pose(p: Vector3<f64>, r: So3<f64>) -> Pose {
        Pose {
            position: p,
            attitude: r,
        }
    }

    /// A curved 3-D path with a turning attitude, sampled at 10 Hz for 20 s.
    fn truth_path() -> Vec<(u64, Pose)> {
        (0..200)
            .map(|k| {
                let t = k as f64 * 0.1;
                let p = Vector3::new(
                    3.0 * (0.3 * t).sin(),
                    2.0 * (0.2 * t).cos() + 0.1 * t,
                    0.5 * (0.5 * t).sin(),
                );
                let r = So3::exp(&Vector3::new(
                    0.1 * (0.4 * t).sin(),
                    -0.05 * t.cos(),
                    0.3 * t,
                ));
                (k * S / 10, pose(p, r))
            })
            .collect()
    }

    /// Pairs whose estimate is `f(truth)`.
    fn pairs_with(f: impl Fn(u64, &Pose) -> Pose) -> Vec<PosePair> {
        truth_path()
            .into_iter()
            .map(|(t_ns, truth)| PosePair {
                t_ns,
                estimate: f(t_ns, &truth),
                truth,
            })
            .collect()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn statistics_follow_evos_definitions() {
        let s = Stats::of(&[1.0, 2.0, 3.0, 4.0]).expect("four errors");
        assert_eq!(s.pairs, 4);
        assert!(close(s.rmse, 7.5_f64.sqrt(), 1e-15));
        assert!(close(s.mean, 2.5, 1e-15));
        assert!(close(s.median, 2.5, 1e-15));
        // Population standard deviation (numpy's np.std): √1.25, not the sample √(5/3).
        assert!(close(s.std, 1.25_f64.sqrt(), 1e-15));
        assert_eq!((s.min, s.max, s.sse), (1.0, 4.0, 30.0));
        assert_eq!(Stats::of(&[3.0, 1.0, 2.0]).map(|s| s.median), Some(2.0));
        assert!(Stats::of(&[]).is_none());
    }

    #[test]
    fn a_translation_offset_is_the_unaligned_error_and_vanishes_when_aligned() {
        let offset = Vector3::new(0.3, -0.4, 1.2);
        let pairs = pairs_with(|_, t| pose(t.position + offset, t.attitude));
        let none = ate(&pairs, Alignment::None).expect("pairs");
        assert!(close(none.stats.rmse, offset.norm(), 1e-12), "{none:?}");
        assert!(close(none.stats.max, offset.norm(), 1e-12));
        assert!(close(none.stats.std, 0.0, 1e-12));
        for a in [Alignment::Se3, Alignment::Yaw, Alignment::Origin] {
            let r = ate(&pairs, a).expect("pairs");
            assert!(r.stats.rmse < 1e-9, "{a:?}: {r:?}");
            assert!(r.alignment_rotation_deg < 1e-6, "{a:?}: {r:?}");
            let t = Vector3::from(r.alignment_translation_m);
            assert!((t + offset).norm() < 1e-9, "{a:?}: {r:?}");
        }
    }

    #[test]
    fn a_rotated_copy_is_undone_by_se3_and_a_yaw_rotated_copy_by_yaw() {
        // The estimate lives in a frame rotated by 40° about z and shifted.
        let shift = Vector3::new(5.0, -2.0, 0.7);
        let yaw = So3::exp(&Vector3::new(0.0, 0.0, 40_f64.to_radians()));
        let pairs = pairs_with(|_, t| pose(yaw.act(&t.position) + shift, yaw.compose(&t.attitude)));
        assert!(ate(&pairs, Alignment::None).expect("pairs").stats.rmse > 1.0);
        for a in [Alignment::Se3, Alignment::Yaw, Alignment::Origin] {
            let r = ate(&pairs, a).expect("pairs");
            assert!(r.stats.rmse < 1e-9, "{a:?}: {r:?}");
            assert!(close(r.alignment_rotation_deg, 40.0, 1e-7), "{a:?}: {r:?}");
        }
        // A tilt is not a yaw: the yaw alignment leaves an error, SE(3) removes it.
        let tilt = So3::exp(&Vector3::new(0.2, 0.0, 0.0));
        let tilted = pairs_with(|_, t| pose(tilt.act(&t.position), tilt.compose(&t.attitude)));
        assert!(ate(&tilted, Alignment::Yaw).expect("pairs").stats.rmse > 1e-3);
        assert!(ate(&tilted, Alignment::Se3).expect("pairs").stats.rmse < 1e-9);
        // The RPE does not see a rigid change of the estimate's frame.
        let r = rpe(&pairs, DEFAULT_RPE_DELTA).expect("pairs");
        assert!(r.stats.max < 1e-12, "{r:?}");
    }

    #[test]
    fn umeyama_returns_a_rotation_and_refuses_bad_input() {
        let x: Vec<Vector3<f64>> = truth_path().iter().map(|(_, p)| p.position).collect();
        let r = So3::exp(&Vector3::new(0.3, -1.1, 2.0));
        let y: Vec<Vector3<f64>> = x.iter().map(|p| r.act(p) + Vector3::x()).collect();
        let s = umeyama(&x, &y).expect("fits");
        assert!((s.rotation - r.rotation_matrix()).norm() < 1e-9);
        assert!(close(s.rotation.determinant(), 1.0, 1e-12));
        assert!((s.translation - Vector3::x()).norm() < 1e-9);
        // A mirror image: the best proper rotation, never a reflection.
        let mirrored: Vec<Vector3<f64>> = x.iter().map(|p| Vector3::new(p.x, p.y, -p.z)).collect();
        let m = umeyama(&x, &mirrored).expect("fits");
        assert!(close(m.rotation.determinant(), 1.0, 1e-12));
        assert!(umeyama(&[], &[]).is_none());
        assert!(umeyama(&x, &y[1..]).is_none());
        assert!(umeyama(&[Vector3::new(f64::NAN, 0.0, 0.0)], &[Vector3::zeros()]).is_none());
    }

    #[test]
    fn origin_alignment_makes_the_first_poses_equal() {
        // The estimate starts right and then drifts: aligned at the origin, the first error is 0.
        let rot = So3::exp(&Vector3::new(0.0, 0.1, 0.5));
        let pairs = pairs_with(|t_ns, t| {
            let drift = Vector3::new(0.01, 0.0, 0.0) * (t_ns / S) as f64;
            pose(rot.act(&t.position) + drift, rot.compose(&t.attitude))
        });
        let s = align(&pairs, Alignment::Origin).expect("pairs");
        let first = &pairs[0];
        assert!((s.apply(&first.estimate.position) - first.truth.position).norm() < 1e-12);
        let r = ate(&pairs, Alignment::Origin).expect("pairs");
        assert!(close(r.stats.min, 0.0, 1e-12));
        assert!(close(r.stats.max, 0.01 * 19.0, 1e-9), "{r:?}");
    }

    #[test]
    fn rpe_of_a_constant_drift_is_the_drift_per_delta() {
        // The estimate gains 0.02 m/s along the body's x axis, on top of the true motion.
        let speed = 0.02;
        let truth: Vec<(u64, Pose)> = (0..101)
            .map(|k| {
                let t = k as f64 * 0.1;
                let r = So3::exp(&Vector3::new(0.0, 0.0, 0.2 * t));
                (k * S / 10, pose(Vector3::new(t, 0.5 * t, 0.0), r))
            })
            .collect();
        // Estimated poses: P(t) = Q(t) with the extra displacement integrated in the world frame
        // along the body axis, so P_i⁻¹P_j − Q_i⁻¹Q_j has the drift's translation.
        let mut extra = Vector3::zeros();
        let mut pairs = Vec::new();
        for (k, (t_ns, q)) in truth.iter().enumerate() {
            if k > 0 {
                extra += truth[k - 1].1.attitude.act(&Vector3::x()) * speed * 0.1;
            }
            pairs.push(PosePair {
                t_ns: *t_ns,
                estimate: pose(q.position + extra, q.attitude),
                truth: *q,
            });
        }
        let r = rpe(&pairs, Delta::Seconds(1.0)).expect("pairs");
        assert_eq!(r.stats.pairs, 10);
        assert_eq!(rpe_index_pairs(&pairs, Delta::Seconds(1.0))[1], (10, 20));
        // Over 1 s the body turns 0.2 rad while drifting 0.02 m: the chord of that arc.
        let chord = speed
            * 0.1
            * (0..10)
                .map(|k| {
                    let a = 0.2 * k as f64 * 0.1;
                    Vector3::new(a.cos(), a.sin(), 0.0)
                })
                .fold(Vector3::zeros(), |s, v| s + v)
                .norm();
        assert!(close(r.stats.mean, chord, 1e-12), "{r:?} vs {chord}");
        assert!(close(r.stats.std, 0.0, 1e-12));
        assert_eq!((r.delta, r.delta_unit), (1.0, "s"));

        // A straight constant drift along a straight path: 2 s apart, twice the error.
        let straight = pairs_with(|t_ns, t| {
            pose(
                t.position + Vector3::new(0.0, 0.0, 0.05) * t_ns as f64 * 1e-9,
                t.attitude,
            )
        });
        for (delta, want) in [(1.0, 0.05), (2.0, 0.10)] {
            let r = rpe(&straight, Delta::Seconds(delta)).expect("pairs");
            // The truth turns, and its z axis is not vertical: compare with the exact formula.
            let direct: Vec<f64> = rpe_index_pairs(&straight, Delta::Seconds(delta))
                .into_iter()
                .map(|(i, j)| {
                    let (a, b) = (&straight[i], &straight[j]);
                    (a.truth
                        .attitude
                        .inverse()
                        .act(&Vector3::new(0.0, 0.0, 0.05))
                        * (b.t_ns - a.t_ns) as f64
                        * 1e-9)
                        .norm()
                })
                .collect();
            assert!(direct.iter().all(|d| close(*d, want, 1e-12)));
            assert!(close(r.stats.rmse, want, 1e-12), "{delta}: {r:?}");
        }
    }

    #[test]
    fn rpe_pairs_by_path_length_follow_evo() {
        // 1 m steps along x: a delta of 2.5 m closes a pair every third pose (path reset to 0).
        let pairs: Vec<PosePair> = (0..10)
            .map(|k| {
                let p = pose(Vector3::new(k as f64, 0.0, 0.0), So3::identity());
                PosePair {
                    t_ns: k * S,
                    estimate: p,
                    truth: p,
                }
            })
            .collect();
        assert_eq!(
            rpe_index_pairs(&pairs, Delta::Metres(2.5)),
            vec![(0, 3), (3, 6), (6, 9)]
        );
        assert_eq!(
            rpe_index_pairs(&pairs, Delta::Seconds(2.0)),
            vec![(0, 2), (2, 4), (4, 6), (6, 8)]
        );
        assert!(rpe_index_pairs(&pairs, Delta::Seconds(0.0)).is_empty());
        assert!(rpe_index_pairs(&pairs, Delta::Metres(f64::NAN)).is_empty());
        assert!(rpe(&pairs, Delta::Seconds(100.0)).is_none());
        assert_eq!(
            rpe(&pairs, Delta::Metres(2.5)).map(|r| r.stats.max),
            Some(0.0)
        );
    }

    #[test]
    fn a_constant_heading_offset_is_removed_from_the_attitude_error() {
        let yaw = So3::exp(&Vector3::new(0.0, 0.0, -2.5));
        let pairs = pairs_with(|_, t| pose(t.position, yaw.compose(&t.attitude)));
        let y = attitude_yaw_aligned(&pairs).expect("pairs");
        assert!(close(y.offset_rad, 2.5, 1e-9), "{y:?}");
        assert!(y.rmse_rad < 1e-9, "{y:?}");
        // With a small tilt error on top, the yaw offset is still found and the tilt remains.
        let tilt = So3::exp(&Vector3::new(0.01, 0.0, 0.0));
        let pairs = pairs_with(|_, t| pose(t.position, yaw.compose(&t.attitude).compose(&tilt)));
        let y = attitude_yaw_aligned(&pairs).expect("pairs");
        assert!(close(y.offset_rad, 2.5, 1e-3), "{y:?}");
        assert!(y.rmse_rad <= 0.01 + 1e-9 && y.rmse_rad > 0.005, "{y:?}");
        assert!(attitude_yaw_aligned(&[]).is_none());
    }
}

//! The magnetometer's hard iron: a constant offset in the body frame (a magnet, a speaker or a
//! battery fixed to the board), learned while the body turns and taken off every sample.
//!
//! **Model.** A magnetometer sample is `m = Rᵀ m_w + b + n`: the world field seen in the body,
//! the offset `b` and white noise `n` (`σ_m` per axis). Whatever the orientation,
//! `‖m − b‖ = F = ‖m_w‖`. In units of a field scale `s` (the reference's norm), with
//! `u = m/s`, `β = b/s` and `f = F²/s²`, this is linear in `z = (β, k)`:
//!
//! ```text
//! y = ‖u‖² = 2uᵀβ + k,   k = f − ‖β‖²,   H = [2uᵀ, 1]
//! ```
//!
//! (the sphere fit of magnetometer calibration, written as a measurement). Every sample is one
//! such row with noise `r = 4f σ_u²` (`σ_u = σ_m/s`: `y` moves by `2√f` times the norm's noise).
//! The noise of `u` is in `H` as well as in `y`; on average it adds `4σ_u²` to each of the
//! first three diagonal entries of `Σ HHᵀ`, which reads as a spread of directions the body never
//! turned through (a sphere of any radius around still samples would fit). Those means are taken
//! off the sums (adjusted least squares, `Rows::adjusted`).
//!
//! The rows of the recent blocks (a **window** of up to `new_field_s`) are fitted alone:
//! `(Σ HHᵀ) z_w = Σ H y`, `P_w = r (Σ HHᵀ)⁻¹`. Once that fit is known to `σ_β/3` on every axis,
//! with pivots of `Σ HHᵀ` above `100σ_u²` of their diagonal (the body's turning, not the
//! noise, spread the samples), it is one measurement of `z`, and a Kalman filter takes it in,
//! in information form:
//!
//! ```text
//! P⁻ = P + Q Δt (every block),   P⁺ = (P⁻⁻¹ + P_w⁻¹)⁻¹,   z⁺ = P⁺ (P⁻⁻¹ z + P_w⁻¹ z_w)
//! ```
//!
//! with a random walk `Q = diag(q², q², q², 4q²)` (`q` = `hard_iron_drift`, per √s: the offset
//! of a magnet or a battery's current drifts as the board warms) and the prior
//! `β ~ N(0, σ_β²)` (`σ_β` = `hard_iron_sigma`: what a calibration leaves). The window then
//! starts again.
//!
//! **Observability.** `Σ HHᵀ` has full rank only when the samples `u` point in three
//! independent directions: the body must turn about two axes. Until a window has seen that, no
//! measurement of the offset is made: it is frozen, and its variance grows by `Q` until the
//! body turns again. Its 1σ is in the estimate ([`HardIron::sigma`]) and widens the heading's
//! noise, so a poorly known offset is fused as such.
//!
//! **What no offset explains.** A block whose residual at the estimate,
//! `e² = mean(yᵢ − Hᵢ z)² / 4f` (the squared error of the norm, `(‖u − β‖ − √f)²`, to first
//! order), exceeds `9σ_u² + σ_β²` is not explained by the offset (reported, `Unexplained`): a
//! field that changes in the world (iron, a magnet nearby) or a new offset (a magnet fixed to
//! the board since). A window whose own fit does not explain its rows by the same test is no
//! single offset: it is dropped and starts again, and so is one older than `new_field_s`. A
//! window's fit whose field norm is not the reference's (within the norm tolerance), or whose
//! offset is beyond `hard_iron_max` (of the field's norm), is never taken: such a field is a
//! disturbance.
//!
//! **A new offset.** A window's fit more than 4σ from the estimate on an axis replaces it
//! ([`Event::NewHardIron`]) rather than being averaged with it: a magnet fixed to the board
//! moves the offset at once, which the drift alone would follow only slowly.
//!
//! [`Event::NewHardIron`]: super::report::Event::NewHardIron

use super::config::MagneticConfig;
use crate::kernels::cholesky;
use crate::Real;
use nalgebra::Vector3;

/// The packed lower triangle of a symmetric 4 × 4 matrix: `(0,0) (1,0) (2,0) (3,0) (1,1)
/// (2,1) (3,1) (2,2) (3,2) (3,3)`.
type Packed<T> = [T; 10];

/// The index of `(i, j)`, `i ≥ j`, in [`Packed`].
const fn packed(i: usize, j: usize) -> usize {
    let (i, j) = if i >= j { (i, j) } else { (j, i) };
    // Columns 0..j hold 4, 3, 2, 1 entries.
    j * 4 - j * (j.saturating_sub(1)) / 2 - j + i
}

fn unpack<T: Real>(p: &Packed<T>) -> [T; 16] {
    let mut full = [T::zero(); 16];
    for j in 0..4 {
        for i in 0..4 {
            if let (Some(e), Some(v)) = (full.get_mut(j * 4 + i), p.get(packed(i, j))) {
                *e = *v;
            }
        }
    }
    full
}

fn pack<T: Real>(full: &[T; 16]) -> Packed<T> {
    let mut p = [T::zero(); 10];
    for j in 0..4 {
        for i in j..4 {
            if let (Some(e), Some(v)) = (p.get_mut(packed(i, j)), full.get(j * 4 + i)) {
                *e = *v;
            }
        }
    }
    p
}

/// The rows of one batch of samples, unscaled: `Σ HHᵀ`, `Σ H y`, `Σ y²` and their count.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rows<T: Real> {
    hh: Packed<T>,
    hy: [T; 4],
    yy: T,
    n: u32,
}

impl<T: Real> Rows<T> {
    fn empty() -> Self {
        Self {
            hh: [T::zero(); 10],
            hy: [T::zero(); 4],
            yy: T::zero(),
            n: 0,
        }
    }

    fn add(&mut self, u: &Vector3<T>) {
        let y = u.x * u.x + u.y * u.y + u.z * u.z;
        let two = T::lit(2.0);
        let h = [two * u.x, two * u.y, two * u.z, T::one()];
        for j in 0..4 {
            let h_j = h.get(j).copied().unwrap_or_else(T::zero);
            for i in j..4 {
                let h_i = h.get(i).copied().unwrap_or_else(T::zero);
                if let Some(e) = self.hh.get_mut(packed(i, j)) {
                    *e += h_i * h_j;
                }
            }
            if let Some(e) = self.hy.get_mut(j) {
                *e += h_j * y;
            }
        }
        self.yy += y * y;
        self.n = self.n.saturating_add(1);
    }

    fn merge(&mut self, other: &Self) {
        for (a, b) in self.hh.iter_mut().zip(other.hh.iter()) {
            *a += *b;
        }
        for (a, b) in self.hy.iter_mut().zip(other.hy.iter()) {
            *a += *b;
        }
        self.yy += other.yy;
        self.n = self.n.saturating_add(other.n);
    }

    /// `Σ HHᵀ` and `Σ H y` without what the white noise `σ_u` adds to them on average (the
    /// noise of `u` is in `H` as well as in `y`: left in, it reads as a spread of directions
    /// the body never turned through, and the fit shrinks toward a small sphere around the
    /// samples). With `u = ū + e`, `E[4uuᵀ] = 4ūūᵀ + 4σ_u² I`, `E[2u‖u‖²] = 2ū‖ū‖² + 10σ_u² ū`
    /// and `E[‖u‖²] = ‖ū‖² + 3σ_u²`; the means are removed (the adjusted least squares of
    /// errors in variables).
    fn adjusted(&self, sigma_u: T) -> ([T; 16], [T; 4]) {
        let mut hh = unpack(&self.hh);
        let s2 = sigma_u * sigma_u;
        let n = T::from_count(self.n);
        let mut hy = self.hy;
        for i in 0..3 {
            if let Some(e) = hh.get_mut(i * 5) {
                *e -= T::lit(4.0) * s2 * n;
            }
            // Σ 2uᵢ sits in column 3 of Σ HHᵀ.
            let sum_u = hh.get(12 + i).copied().unwrap_or_else(T::zero) * T::lit(0.5);
            if let Some(e) = hy.get_mut(i) {
                *e -= T::lit(10.0) * s2 * sum_u;
            }
        }
        if let Some(e) = hy.get_mut(3) {
            *e -= T::lit(3.0) * s2 * n;
        }
        (hh, hy)
    }

    /// The mean squared residual `mean(y − Hz)²` at `z`:
    /// `(Σy² − 2 zᵀ Σ Hy + zᵀ (Σ HHᵀ) z) / n`.
    fn mean_residual_sq(&self, z: &[T; 4]) -> T {
        let full = unpack(&self.hh);
        let mut quad = T::zero();
        let mut lin = T::zero();
        for j in 0..4 {
            let z_j = z.get(j).copied().unwrap_or_else(T::zero);
            lin += z_j * self.hy.get(j).copied().unwrap_or_else(T::zero);
            for i in 0..4 {
                let z_i = z.get(i).copied().unwrap_or_else(T::zero);
                quad += z_i * z_j * full.get(j * 4 + i).copied().unwrap_or_else(T::zero);
            }
        }
        let rss = self.yy - T::lit(2.0) * lin + quad;
        // Rounding can leave a tiny negative sum of squares.
        let rss = if rss > T::zero() { rss } else { T::zero() };
        rss / T::from_count(self.n.max(1))
    }
}

/// The recent rows, fitted alone to find a new offset.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Window<T: Real> {
    rows: Rows<T>,
    /// How long it has collected, s.
    duration: T,
}

/// What a block did to the offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum HardIronOutcome {
    /// Nothing to learn (not started, no samples, turned off).
    Idle,
    /// The block was explained by the offset.
    Explained,
    /// Not explained by the offset: a disturbance, or a new offset being learned.
    Unexplained,
    /// A new offset replaced the estimate.
    Learned,
}

/// The hard-iron estimate (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct HardIron<T: Real> {
    /// The field scale `s` (the reference's norm when learning began); 0 until then.
    scale: T,
    /// `z = (β, k)`.
    z: [T; 4],
    /// Its covariance.
    p: Packed<T>,
    /// The rows of the current block.
    block: Rows<T>,
    window: Option<Window<T>>,
    /// An offset beyond the calibration's residual has been learned (until then the offset
    /// is the prior's zero, and the magnetometer is taken as calibrated).
    learned: bool,
}

impl<T: Real> HardIron<T> {
    /// No offset known, not started.
    pub(super) fn new() -> Self {
        Self {
            scale: T::zero(),
            z: [T::zero(); 4],
            p: [T::zero(); 10],
            block: Rows::empty(),
            window: None,
            learned: false,
        }
    }

    /// Learning began (the field scale is known).
    fn started(&self) -> bool {
        crate::kernels::positive_finite(self.scale)
    }

    /// The offset, in the magnetometer's unit (zero until learning began).
    pub(super) fn offset(&self) -> Vector3<T> {
        let [x, y, z, _] = self.z;
        Vector3::new(x, y, z) * self.scale
    }

    /// The offset's 1σ per axis, in the magnetometer's unit (zero until learning began).
    pub(super) fn sigma(&self) -> Vector3<T> {
        let d = |i: usize| {
            let v = self.p.get(packed(i, i)).copied().unwrap_or_else(T::zero);
            (if v > T::zero() { v } else { T::zero() }).sqrt_rn() * self.scale
        };
        Vector3::new(d(0), d(1), d(2))
    }

    /// [`sigma`](Self::sigma) once an offset has been learned, else zero.
    pub(super) fn learned_sigma(&self) -> Vector3<T> {
        if self.learned {
            self.sigma()
        } else {
            Vector3::zeros()
        }
    }

    /// Begins learning with the reference field's norm `scale` as the unit: the offset's prior
    /// is zero with 1σ `hard_iron_sigma` per axis, `k` that of the reference's norm.
    fn begin(&mut self, scale: T, config: &MagneticConfig<T>) {
        let s2 = config.hard_iron_sigma * config.hard_iron_sigma;
        // k = f − ‖β‖² ≈ f: the field's norm is known to the norm tolerance, f to twice it.
        let k_sigma = T::lit(2.0) * config.norm_tolerance;
        self.scale = scale;
        self.z = [T::zero(), T::zero(), T::zero(), T::one()];
        self.p = [T::zero(); 10];
        for (i, v) in [s2, s2, s2, k_sigma * k_sigma].into_iter().enumerate() {
            if let Some(e) = self.p.get_mut(packed(i, i)) {
                *e = v;
            }
        }
        self.block = Rows::empty();
        self.window = None;
        self.learned = false;
    }

    /// Takes one raw sample into the current block (once learning began, when turned on) and
    /// returns it without the offset.
    pub(super) fn take(&mut self, field: &Vector3<T>, config: &MagneticConfig<T>) -> Vector3<T> {
        if !config.hard_iron || !self.started() {
            return *field;
        }
        self.block.add(&(field / self.scale));
        field - self.offset()
    }

    /// Ends a block of `duration` s: fuses its rows when the offset explains them, and looks
    /// for a new offset in the recent rows (module docs). `reference` is the world reference field,
    /// once known (learning begins with it).
    pub(super) fn end_block(
        &mut self,
        duration: T,
        reference: Option<&Vector3<T>>,
        config: &MagneticConfig<T>,
    ) -> HardIronOutcome {
        if !config.hard_iron {
            return HardIronOutcome::Idle;
        }
        if !self.started() {
            let scale = reference.map_or_else(T::zero, crate::kernels::mat3::norm);
            if crate::kernels::positive_finite(scale) {
                self.begin(scale, config);
            }
            return HardIronOutcome::Idle;
        }
        let rows = self.block;
        self.block = Rows::empty();
        if rows.n == 0 {
            return HardIronOutcome::Idle;
        }
        let sigma_u = config.sigma / self.scale;
        let f = self.field_sq();
        // Per-sample noise of y, and the largest mean squared residual the offset explains.
        let r = T::lit(4.0) * f * sigma_u * sigma_u;
        let explained = T::lit(4.0)
            * f
            * (T::lit(9.0) * sigma_u * sigma_u + config.hard_iron_sigma * config.hard_iron_sigma);
        // The offset drifts (a random walk): frozen while nothing is learned, less known.
        let q2 = config.hard_iron_drift * config.hard_iron_drift * duration;
        for (i, scale) in [(0, 1.0), (1, 1.0), (2, 1.0), (3, 4.0)] {
            if let Some(e) = self.p.get_mut(packed(i, i)) {
                *e += q2 * T::lit(scale);
            }
        }
        let outcome = if rows.mean_residual_sq(&self.z) <= explained {
            HardIronOutcome::Explained
        } else {
            HardIronOutcome::Unexplained
        };
        if self.learn_window(&rows, reference, r, explained, duration, config) {
            HardIronOutcome::Learned
        } else {
            outcome
        }
    }

    /// `f = k + ‖β‖²`, at least a small fraction of the scale's square (a degenerate `k`).
    fn field_sq(&self) -> T {
        let [x, y, z, k] = self.z;
        let f = k + x * x + y * y + z * z;
        let floor = T::lit(0.01);
        if f > floor {
            f
        } else {
            floor
        }
    }

    /// The Kalman update by a window's fit `z_w` with covariance `c` (module docs), in
    /// covariance form: `K = P (P + C)⁻¹`, `z ← z + K (z_w − z)`, `P ← P − K P`; nothing changes
    /// on a numerical failure.
    fn fuse(&mut self, z_w: &[T; 4], c: &[T; 16]) {
        let p = unpack(&self.p);
        let mut s = p;
        for (a, b) in s.iter_mut().zip(c.iter()) {
            *a += *b;
        }
        let mut s_inv = [T::zero(); 16];
        if !cholesky::factor_in_place(&mut s, 4, T::zero())
            || !cholesky::inverse_into(&s, 4, &mut s_inv)
        {
            return;
        }
        let at =
            |m: &[T; 16], i: usize, j: usize| m.get(j * 4 + i).copied().unwrap_or_else(T::zero);
        // K = P S⁻¹.
        let mut k = [T::zero(); 16];
        for j in 0..4 {
            for i in 0..4 {
                let mut acc = T::zero();
                for m in 0..4 {
                    acc += at(&p, i, m) * at(&s_inv, m, j);
                }
                if let Some(e) = k.get_mut(j * 4 + i) {
                    *e = acc;
                }
            }
        }
        let mut z = self.z;
        for (i, z_i) in z.iter_mut().enumerate() {
            for j in 0..4 {
                let d = z_w.get(j).copied().unwrap_or_else(T::zero)
                    - self.z.get(j).copied().unwrap_or_else(T::zero);
                *z_i += at(&k, i, j) * d;
            }
        }
        // P − K P, its lower triangle (symmetric in exact arithmetic).
        let mut posterior = [T::zero(); 16];
        for j in 0..4 {
            for i in j..4 {
                let mut acc = T::zero();
                for m in 0..4 {
                    acc += at(&k, i, m) * at(&p, m, j);
                }
                if let Some(e) = posterior.get_mut(j * 4 + i) {
                    *e = at(&p, i, j) - acc;
                }
            }
        }
        if crate::kernels::all_finite(&z) && crate::kernels::all_finite(&posterior) {
            self.z = z;
            self.p = pack(&posterior);
        }
    }

    /// `true` when the offset of `z` is finite and within `hard_iron_max` of the field scale.
    fn within_bound(&self, z: &[T; 4], config: &MagneticConfig<T>) -> bool {
        let [x, y, w, k] = *z;
        let b2 = x * x + y * y + w * w;
        crate::kernels::all_finite(z)
            && b2 <= config.hard_iron_max * config.hard_iron_max
            && k + b2 > T::zero()
    }

    /// Adds a block to the window of recent rows and fits them alone, without the prior;
    /// `true` when that fit replaced the estimate: known within `hard_iron_sigma/3`, with the
    /// reference's field norm (within the norm tolerance),
    /// explaining the window's rows, within the bound, and apart from the estimate by more
    /// than their uncertainties allow (a new offset). A window no single offset explains, or
    /// older than `new_field_s`, starts again.
    fn learn_window(
        &mut self,
        rows: &Rows<T>,
        reference: Option<&Vector3<T>>,
        r: T,
        explained: T,
        duration: T,
        config: &MagneticConfig<T>,
    ) -> bool {
        let mut window = match self.window {
            Some(w) if w.duration < config.new_field_s => w,
            _ => Window {
                rows: Rows::empty(),
                duration: T::zero(),
            },
        };
        window.rows.merge(rows);
        window.duration += duration;
        self.window = Some(window);
        // The least-squares offset: (Σ HHᵀ) z = Σ H y, with covariance r (Σ HHᵀ)⁻¹. The noise
        // alone spreads the samples' directions by σ_u, which leaves pivots of about σ_u² of
        // their diagonal: a pivot below 100 σ_u² is a direction the body has not turned
        // through (the noise would make a sphere of any radius around one sample fit).
        let sigma_u = config.sigma / self.scale;
        let (mut l, mut z) = window.rows.adjusted(sigma_u);
        if !cholesky::factor_in_place(&mut l, 4, T::lit(100.0) * sigma_u * sigma_u) {
            return false;
        }
        cholesky::solve_in_place(&l, 4, &mut z);
        let mut cov = [T::zero(); 16];
        if !cholesky::inverse_into(&l, 4, &mut cov) {
            return false;
        }
        // The rows' noise: the white noise's, or what the fit leaves when that is more (the
        // magnetometer's scale and cross-axis errors, a slightly moving field): the least-
        // squares estimate of the residual variance.
        let residual = window.rows.mean_residual_sq(&z);
        let r = if residual > r { residual } else { r };
        for e in &mut cov {
            *e *= r;
        }
        let third = config.hard_iron_sigma / T::lit(3.0);
        let known = [0, 5, 10]
            .iter()
            .all(|&i| cov.get(i).is_some_and(|v| *v <= third * third));
        if !known {
            return false;
        }
        // Its field's norm is the reference's, within the norm tolerance: the Earth's field
        // does not change with the offset.
        let [x, y, w, k] = z;
        let f = k + x * x + y * y + w * w;
        let norm = reference.map_or_else(T::zero, |r| crate::kernels::mat3::norm(r) / self.scale);
        let (low, high) = (
            norm * (T::one() - config.norm_tolerance),
            norm * (T::one() + config.norm_tolerance),
        );
        if !(f >= low * low && f <= high * high) {
            return false;
        }
        if residual > explained || !self.within_bound(&z, config) {
            // No single offset explains these rows: start again from the next block.
            self.window = None;
            return false;
        }
        // What a window leaves beyond its statistics (the magnetometer's scale and cross-axis
        // errors over the part of the sphere it saw): a third of the calibration's residual.
        for i in 0..3 {
            if let Some(e) = cov.get_mut(i * 5) {
                *e += third * third;
            }
        }
        self.window = None;
        // A new offset when the estimate does not explain the rows this fit explains, and the
        // fit is more than 3σ of the calibration's residual away from it (closer, it is the
        // same offset, or a calibrated magnetometer's residual, and is averaged in).
        let [x0, y0, w0, _] = self.z;
        let moved = (x - x0) * (x - x0) + (y - y0) * (y - y0) + (w - w0) * (w - w0);
        let sigma = config.hard_iron_sigma;
        if moved > T::lit(9.0) * sigma * sigma && window.rows.mean_residual_sq(&self.z) > explained
        {
            self.z = z;
            self.p = pack(&cov);
            self.learned = true;
            return true;
        }
        // The same offset, learned again: one more measurement of it. Within the calibration's
        // residual of zero, the magnetometer is taken as calibrated and left alone.
        if self.learned {
            self.fuse(&z, &cov);
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lie::{LieGroup, So3};

    fn config() -> MagneticConfig<f64> {
        MagneticConfig::new(0.5, Some(Vector3::new(0.0, 20.0, -40.0)))
    }

    /// The field a body turning through many orientations sees with `offset`, one block of
    /// `n` samples per call, starting at orientation index `k0`.
    fn block(hi: &mut HardIron<f64>, offset: &Vector3<f64>, k0: usize, n: usize, turning: bool) {
        let c = config();
        let m_w = Vector3::new(0.0, 20.0, -40.0);
        for k in k0..k0 + n {
            let t = if turning { k as f64 * 0.01 } else { 0.0 };
            // Turning about world up while rocking about body x: two axes.
            let r = So3::exp(&Vector3::new(0.0, 0.0, 1.3 * t)).compose(&So3::exp(&Vector3::new(
                1.2 * (0.9 * t).sin(),
                0.0,
                0.0,
            )));
            let m = r.inverse().act(&m_w) + offset;
            let _ = hi.take(&m, &c);
        }
    }

    #[test]
    fn packed_indices_cover_the_lower_triangle_once() {
        let mut seen = [false; 10];
        for j in 0..4 {
            for i in j..4 {
                assert!(!seen[packed(i, j)]);
                seen[packed(i, j)] = true;
                assert_eq!(packed(i, j), packed(j, i));
            }
        }
        assert!(seen.iter().all(|s| *s));
    }

    #[test]
    fn a_turning_body_learns_a_new_offset_and_a_still_one_does_not() {
        let c = config();
        let reference = Vector3::new(0.0, 20.0, -40.0);
        let offset = Vector3::new(8.0, -5.0, 30.0);
        let mut hi = HardIron::new();
        assert_eq!(
            hi.end_block(0.25, Some(&reference), &c),
            HardIronOutcome::Idle
        );
        // At rest the offset cannot be told from the field: never learned.
        let mut k = 0;
        for _ in 0..40 {
            block(&mut hi, &offset, k, 25, false);
            k += 25;
            assert_ne!(
                hi.end_block(0.25, Some(&reference), &c),
                HardIronOutcome::Learned
            );
        }
        assert_eq!(hi.offset(), Vector3::zeros());
        // Turning: learned, to within 3σ of what it reports.
        let mut learned = false;
        for _ in 0..80 {
            block(&mut hi, &offset, k, 25, true);
            k += 25;
            learned |= hi.end_block(0.25, Some(&reference), &c) == HardIronOutcome::Learned;
        }
        assert!(learned);
        let (e, s) = (hi.offset() - offset, hi.sigma());
        for i in 0..3 {
            assert!(e[i].abs() <= 3.0 * s[i] + 1e-9, "error {e:?} sigma {s:?}");
        }
        assert!(s.max() < c.hard_iron_sigma * 50.0 / 3.0);
    }

    #[test]
    fn an_offset_beyond_the_bound_is_never_taken() {
        let mut c = config();
        c.hard_iron_max = 0.5;
        let reference = Vector3::new(0.0, 20.0, -40.0);
        let offset = Vector3::new(0.0, 0.0, 40.0); // 0.9 of the field's norm
        let mut hi = HardIron::new();
        let _ = hi.end_block(0.25, Some(&reference), &c);
        let (mut k, mut unexplained) = (0, 0);
        for _ in 0..120 {
            block(&mut hi, &offset, k, 25, true);
            k += 25;
            let outcome = hi.end_block(0.25, Some(&reference), &c);
            assert_ne!(outcome, HardIronOutcome::Learned);
            unexplained += usize::from(outcome == HardIronOutcome::Unexplained);
            // A block may look explained by chance (its norm error small at its orientations)
            // and be fused, but the offset never leaves the bound.
            assert!(hi.offset().norm() <= c.hard_iron_max * reference.norm() * (1.0 + 1e-12));
        }
        // The field is reported as a disturbance nearly throughout.
        assert!(
            unexplained >= 108,
            "{unexplained} of 120 blocks unexplained"
        );
    }
}

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
//! The rows of the recent blocks (a **window** of up to `new_field_s`, tried every sixteenth of
//! it) are fitted alone:
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
//! **An offset that goes.** A magnet taken away, or one that is a device switched off (a
//! phone's vibration motor), leaves a learned offset that no longer exists; a body at rest
//! never turns, so no window would measure the change. So every block is also judged without
//! turning ([`HardIron::gone`]): when for `new_field_s / 16` s its mean field without the offset
//! has the reference's norm and the field with it does not, the offset returns to its prior
//! ([`Event::NewHardIron`]). One orientation suffices for this test, because it compares
//! two explanations of the same norm: the zero offset, which a calibrated magnetometer starts
//! from, and the learned one.
//!
//! [`Event::NewHardIron`]: super::report::Event::NewHardIron

use super::config::MagneticConfig;
use crate::kernels::cholesky;
use crate::Real;
use nalgebra::Vector3;

/// The packed lower triangle of a symmetric 4 × 4 matrix: `(0,0) (1,0) (2,0) (3,0) (1,1)
/// (2,1) (3,1) (2,2) (3,2) (3,3)`.
type Packed<T> = [T; 10];

/// The index of `(i, j)` in [`Packed`] (either order).
const fn packed(i: usize, j: usize) -> usize {
    let (i, j) = if i >= j { (i, j) } else { (j, i) };
    // Columns 0..j hold 4, 3, 2, 1 entries.
    j * 4 - j * (j.saturating_sub(1)) / 2 - j + i
}

/// Entry `(i, j)` of a packed matrix.
fn at<T: Real>(p: &Packed<T>, i: usize, j: usize) -> T {
    p.get(packed(i, j)).copied().unwrap_or_else(T::zero)
}

/// The full column-major matrix of a packed one.
fn unpack<T: Real>(p: &Packed<T>) -> [T; 16] {
    let mut full = [T::zero(); 16];
    for (k, e) in full.iter_mut().enumerate() {
        *e = at(p, k % 4, k / 4);
    }
    full
}

/// The rows of a window of samples, unscaled: `Σ HHᵀ` (packed), `Σ H y`, `Σ y²` and their
/// count.
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

    /// One sample `u`: the row `H = [2uᵀ, 1]`, `y = ‖u‖²`.
    fn add(&mut self, u: &Vector3<T>) {
        let (x, y, z) = (u.x + u.x, u.y + u.y, u.z + u.z);
        let v = u.x * u.x + u.y * u.y + u.z * u.z;
        let [a0, a1, a2, a3, a4, a5, a6, a7, a8, a9] = &mut self.hh;
        *a0 += x * x;
        *a1 += y * x;
        *a2 += z * x;
        *a3 += x;
        *a4 += y * y;
        *a5 += z * y;
        *a6 += y;
        *a7 += z * z;
        *a8 += z;
        *a9 += T::one();
        let [b0, b1, b2, b3] = &mut self.hy;
        *b0 += x * v;
        *b1 += y * v;
        *b2 += z * v;
        *b3 += v;
        self.yy += v * v;
        self.n = self.n.saturating_add(1);
    }

    /// `Σ HHᵀ` (full) and `Σ H y` without what the white noise `σ_u` adds to them on average
    /// (the noise of `u` is in `H` as well as in `y`: left in, it reads as a spread of
    /// directions the body never turned through, and the fit shrinks toward a small sphere
    /// around the samples). With `u = ū + e`, `E[4uuᵀ] = 4ūūᵀ + 4σ_u² I`,
    /// `E[2u‖u‖²] = 2ū‖ū‖² + 10σ_u² ū` and `E[‖u‖²] = ‖ū‖² + 3σ_u²`; the means are removed
    /// (the adjusted least squares of errors in variables).
    fn adjusted(&self, sigma_u: T) -> ([T; 16], [T; 4]) {
        let mut hh = unpack(&self.hh);
        let s2 = sigma_u * sigma_u;
        let n = T::from_count(self.n);
        let mut hy = self.hy;
        for (i, h) in hy.iter_mut().enumerate().take(3) {
            if let Some(e) = hh.get_mut(i * 5) {
                *e -= T::lit(4.0) * s2 * n;
            }
            // Σ 2uᵢ is entry (i, 3) of Σ HHᵀ.
            *h -= T::lit(5.0) * s2 * at(&self.hh, i, 3);
        }
        if let Some(e) = hy.get_mut(3) {
            *e -= T::lit(3.0) * s2 * n;
        }
        (hh, hy)
    }

    /// The mean squared residual `mean(y − Hz)²` at `z`:
    /// `(Σy² − 2 zᵀ Σ Hy + zᵀ (Σ HHᵀ) z) / n`.
    fn mean_residual_sq(&self, z: &[T; 4]) -> T {
        let mut rss = self.yy;
        for (i, z_i) in z.iter().enumerate() {
            let mut hz = T::zero();
            for (j, z_j) in z.iter().enumerate() {
                hz += at(&self.hh, i, j) * *z_j;
            }
            rss += *z_i * (hz - T::lit(2.0) * self.hy.get(i).copied().unwrap_or_else(T::zero));
        }
        // Rounding can leave a tiny negative sum of squares.
        let rss = if rss > T::zero() { rss } else { T::zero() };
        rss / T::from_count(self.n.max(1))
    }
}

/// What a block did to the offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum HardIronOutcome {
    /// Nothing learned (not started, turned off, or the window does not yet know the offset).
    Idle,
    /// The window's rows are no single offset (a field that changes in the world): dropped.
    Unexplained,
    /// The window measured the same offset again: averaged in.
    Fused,
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
    /// The rows of the current window, how long it has collected, s, and when its fit is
    /// tried next, s.
    window: Rows<T>,
    window_s: T,
    next_try_s: T,
    /// An offset beyond the calibration's residual has been learned (until then the offset
    /// is the prior's zero, and the magnetometer is taken as calibrated).
    learned: bool,
    /// How many blocks in a row have had fields explained by no offset and not by the learned
    /// one ([`gone`](Self::gone)); in the padding after `learned`.
    gone_blocks: u16,
}

impl<T: Real> HardIron<T> {
    /// No offset known, not started.
    pub(super) fn new() -> Self {
        Self {
            scale: T::zero(),
            z: [T::zero(); 4],
            p: [T::zero(); 10],
            window: Rows::empty(),
            window_s: T::zero(),
            next_try_s: T::zero(),
            learned: false,
            gone_blocks: 0,
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
            let v = at(&self.p, i, i);
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
        let zero = T::zero();
        *self = Self::new();
        self.scale = scale;
        self.z = [zero, zero, zero, T::one()];
        self.p = [
            s2,
            zero,
            zero,
            zero,
            s2,
            zero,
            zero,
            s2,
            zero,
            k_sigma * k_sigma,
        ];
    }

    /// Takes one raw sample into the window (once learning began, when turned on) and returns
    /// it without the offset.
    pub(super) fn take(&mut self, field: &Vector3<T>, config: &MagneticConfig<T>) -> Vector3<T> {
        if !config.hard_iron || !self.started() {
            return *field;
        }
        self.window.add(&(field * (T::one() / self.scale)));
        field - self.offset()
    }

    /// Ends a block of `duration` s: the offset drifts, and the window's rows are fitted
    /// (module docs). `reference` is the world reference field, once known (learning begins
    /// with it).
    #[inline(never)] // its own stack frame, not the caller's
    pub(super) fn end_block(
        &mut self,
        duration: T,
        reference: Option<&Vector3<T>>,
        config: &MagneticConfig<T>,
    ) -> HardIronOutcome {
        if !config.hard_iron {
            return HardIronOutcome::Idle;
        }
        let norm = reference.map_or_else(T::zero, crate::kernels::mat3::norm);
        if !self.started() {
            if crate::kernels::positive_finite(norm) {
                self.begin(norm, config);
            }
            return HardIronOutcome::Idle;
        }
        // The offset drifts (a random walk): frozen while nothing is learned, less known.
        let q2 = config.hard_iron_drift * config.hard_iron_drift * duration;
        let [p0, _, _, _, p4, _, _, p7, _, p9] = &mut self.p;
        *p0 += q2;
        *p4 += q2;
        *p7 += q2;
        *p9 += T::lit(4.0) * q2;
        self.window_s += duration;
        let last = self.window_s >= config.new_field_s;
        // The fit is tried every 1/16 of the window's length (1.25 s by default) and at its
        // end: an offset is learned at most that late after the window knows it, for a
        // sixteenth of the cost of a try after every block.
        let outcome = if self.window_s >= self.next_try_s || last {
            self.next_try_s = self.window_s + config.new_field_s / T::lit(16.0);
            self.learn_window(norm / self.scale, config)
        } else {
            HardIronOutcome::Idle
        };
        if outcome != HardIronOutcome::Idle || last {
            self.window = Rows::empty();
            self.window_s = T::zero();
            self.next_try_s = T::zero();
        }
        outcome
    }

    /// The learned offset has gone (the magnet that made it was taken away or switched off):
    /// for `new_field_s / 16` s of blocks in a row (blocks of `duration` s), the block's mean field without the
    /// offset, `corrected + b`, has the reference's norm `F` and the field with it does not,
    /// each judged to `δ = √(9σ_m²/n + (σ_β F)²)` (three of the block mean's white noise and
    /// the calibration's residual, as the window's test). The offset then returns to its prior
    /// (zero, `σ_β`) and `true` says so. A turning window would measure the change too, but a
    /// body left at rest never turns: this test needs no turning, only one orientation.
    pub(super) fn gone(
        &mut self,
        corrected: &Vector3<T>,
        n: u32,
        duration: T,
        reference: Option<&Vector3<T>>,
        config: &MagneticConfig<T>,
    ) -> bool {
        let norm = reference.map_or_else(T::zero, crate::kernels::mat3::norm);
        if !(config.hard_iron && self.learned && crate::kernels::positive_finite(norm)) {
            self.gone_blocks = 0;
            return false;
        }
        let raw = corrected + self.offset();
        let spread = config.hard_iron_sigma * norm;
        let delta_sq =
            T::lit(9.0) * config.sigma * config.sigma / T::from_count(n.max(1)) + spread * spread;
        let off = |v: &Vector3<T>| {
            let e = crate::kernels::mat3::norm(v) - norm;
            e * e
        };
        self.gone_blocks = if off(&raw) <= delta_sq && off(corrected) > delta_sq {
            self.gone_blocks.saturating_add(1)
        } else {
            0
        };
        // The blocks are of one length, `duration`.
        if T::from_count(u32::from(self.gone_blocks)) * duration
            >= config.new_field_s / T::lit(16.0)
        {
            let scale = self.scale;
            self.begin(scale, config);
            return true;
        }
        false
    }

    /// `f = k + ‖β‖²`, at least a small fraction of the scale's square (a degenerate `k`).
    fn field_sq(z: &[T; 4]) -> T {
        let [x, y, w, k] = *z;
        let f = k + x * x + y * y + w * w;
        let floor = T::lit(0.01);
        if f > floor {
            f
        } else {
            floor
        }
    }

    /// Fits the window's rows alone, without the prior, and takes the fit: `Idle` until it is
    /// known within `hard_iron_sigma/3`; `Unexplained` when its own fit does not explain its
    /// rows (or has another field norm than the reference's `norm`, in scale units, or an
    /// offset beyond the bound); else a new offset (`Learned`) when the estimate does not
    /// explain the rows and the fit is more than `3 hard_iron_sigma` from it, or one more
    /// measurement of the same (`Fused`).
    fn learn_window(&mut self, norm: T, config: &MagneticConfig<T>) -> HardIronOutcome {
        let window = &self.window;
        if window.n == 0 {
            return HardIronOutcome::Idle;
        }
        // The least-squares fit: (Σ HHᵀ) z = Σ H y, with covariance r (Σ HHᵀ)⁻¹. The noise
        // alone spreads the samples' directions by σ_u, which leaves pivots of about σ_u² of
        // their diagonal: a pivot below 100 σ_u² is a direction the body has not turned
        // through (the noise would make a sphere of any radius around one sample fit).
        let sigma_u = config.sigma / self.scale;
        let s2 = sigma_u * sigma_u;
        let (mut l, mut z) = window.adjusted(sigma_u);
        if !cholesky::factor_in_place(&mut l, 4, T::lit(100.0) * s2) {
            return HardIronOutcome::Idle;
        }
        cholesky::solve_in_place(&l, 4, &mut z);
        let mut cov = [T::zero(); 16];
        if !cholesky::inverse_into(&l, 4, &mut cov) {
            return HardIronOutcome::Idle;
        }
        // Per-sample noise of y, r = 4fσ_u²; the rows' noise is that, or what the fit leaves
        // when that is more (the magnetometer's scale and cross-axis errors, a slightly moving
        // field): the least-squares estimate of the residual variance. The largest mean
        // squared residual an offset explains: 4f(9σ_u² + σ_β²), a norm error of 3σ of the
        // noise and the calibration's residual.
        let f = Self::field_sq(&z);
        let residual = window.mean_residual_sq(&z);
        let white = T::lit(4.0) * f * s2;
        let r = if residual > white { residual } else { white };
        let sigma = config.hard_iron_sigma;
        let explained = T::lit(4.0) * f * (T::lit(9.0) * s2 + sigma * sigma);
        for e in &mut cov {
            *e *= r;
        }
        let third = sigma / T::lit(3.0);
        let known = [0, 5, 10]
            .iter()
            .all(|&i| cov.get(i).is_some_and(|v| *v <= third * third));
        if !known {
            return HardIronOutcome::Idle;
        }
        // Its field's norm is the reference's, within the norm tolerance (the Earth's field
        // does not change with the offset), and its offset within the bound.
        let (low, high) = (
            norm * (T::one() - config.norm_tolerance),
            norm * (T::one() + config.norm_tolerance),
        );
        let [x, y, w, _] = z;
        let bound = config.hard_iron_max;
        if residual > explained
            || !(f >= low * low && f <= high * high)
            || !crate::kernels::all_finite(&z)
            || x * x + y * y + w * w > bound * bound
        {
            return HardIronOutcome::Unexplained;
        }
        // What a window leaves beyond its statistics (the magnetometer's scale and cross-axis
        // errors over the part of the sphere it saw): a third of the calibration's residual.
        for i in [0, 5, 10] {
            if let Some(e) = cov.get_mut(i) {
                *e += third * third;
            }
        }
        // A new offset when the estimate does not explain the rows this fit explains, and the
        // fit is more than 3σ of the calibration's residual away from it (closer, it is the
        // same offset, or a calibrated magnetometer's residual, and is averaged in).
        let [x0, y0, w0, _] = self.z;
        let moved = (x - x0) * (x - x0) + (y - y0) * (y - y0) + (w - w0) * (w - w0);
        if moved > T::lit(9.0) * sigma * sigma && window.mean_residual_sq(&self.z) > explained {
            self.z = z;
            for j in 0..4 {
                for i in j..4 {
                    if let (Some(e), Some(v)) = (self.p.get_mut(packed(i, j)), cov.get(j * 4 + i)) {
                        *e = *v;
                    }
                }
            }
            self.learned = true;
            return HardIronOutcome::Learned;
        }
        if !self.learned {
            // Within the calibration's residual of zero: the magnetometer is taken as
            // calibrated and left alone.
            return HardIronOutcome::Idle;
        }
        // The factor is no longer needed: its storage is the update's scratch.
        self.fuse(&z, &cov, &mut l);
        HardIronOutcome::Fused
    }

    /// The Kalman update by a window's fit `z_w` with covariance `c` (module docs), in
    /// covariance form: with `S = P + C` (factored in `scratch`) and `X = S⁻¹ P` (so
    /// `K = P S⁻¹ = Xᵀ`), `z ← z + Xᵀ (z_w − z)`, `P ← P − P X`; nothing changes on a
    /// numerical failure.
    fn fuse(&mut self, z_w: &[T; 4], c: &[T; 16], scratch: &mut [T; 16]) {
        let mut x = unpack(&self.p);
        for ((s, p), c) in scratch.iter_mut().zip(x.iter()).zip(c.iter()) {
            *s = *p + *c;
        }
        if !cholesky::factor_in_place(scratch, 4, T::zero()) {
            return;
        }
        for column in x.chunks_exact_mut(4) {
            cholesky::solve_in_place(scratch, 4, column);
        }
        let x_at = |i: usize, j: usize| x.get(j * 4 + i).copied().unwrap_or_else(T::zero);
        let mut z = self.z;
        for (i, z_i) in z.iter_mut().enumerate() {
            for (j, (w, v)) in z_w.iter().zip(self.z.iter()).enumerate() {
                *z_i += x_at(j, i) * (*w - *v);
            }
        }
        let mut posterior = self.p;
        for j in 0..4 {
            for i in j..4 {
                let mut px = T::zero();
                for m in 0..4 {
                    px += at(&self.p, i, m) * x_at(m, j);
                }
                if let Some(e) = posterior.get_mut(packed(i, j)) {
                    *e -= px;
                }
            }
        }
        if crate::kernels::all_finite(&z) && crate::kernels::all_finite(&posterior) {
            self.z = z;
            self.p = posterior;
        }
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
            // Every window that knows its fit reports it unexplained: a disturbance.
            assert!(
                matches!(
                    outcome,
                    HardIronOutcome::Idle | HardIronOutcome::Unexplained
                ),
                "{outcome:?}"
            );
            unexplained += usize::from(outcome == HardIronOutcome::Unexplained);
        }
        assert!(unexplained >= 5, "{unexplained} windows unexplained");
        assert_eq!(hi.offset(), Vector3::zeros());
    }

    /// A learned offset whose magnet is taken away while the body rests: the blocks' raw
    /// field has the reference's norm and the corrected one does not, and after
    /// `new_field_s / 16` s (1.25 s) of such blocks the offset returns to its prior. While the
    /// magnet stays, resting in any orientation, it is kept.
    #[test]
    fn an_offset_that_goes_away_at_rest_is_dropped_and_one_that_stays_is_kept() {
        let c = config();
        let reference = Vector3::new(0.0, 20.0, -40.0);
        let offset = Vector3::new(8.0, -5.0, 30.0);
        let learn = |hi: &mut HardIron<f64>| {
            let _ = hi.end_block(0.25, Some(&reference), &c);
            let mut k = 0;
            for _ in 0..80 {
                block(hi, &offset, k, 25, true);
                k += 25;
                let _ = hi.end_block(0.25, Some(&reference), &c);
            }
            assert!(hi.learned && (hi.offset() - offset).norm() < 3.0);
        };
        // The still body's mean field in the body, corrected by the estimate.
        let still = |hi: &HardIron<f64>, present: &Vector3<f64>, k: usize| {
            let r = So3::exp(&Vector3::new(0.3 * k as f64, -0.7, 0.2 * k as f64));
            r.inverse().act(&reference) + present - hi.offset()
        };
        let mut kept = HardIron::new();
        learn(&mut kept);
        for k in 0..40 {
            let m = still(&kept, &offset, k / 8);
            assert!(!kept.gone(&m, 25, 0.25, Some(&reference), &c), "block {k}");
        }
        assert!(kept.learned);
        let mut gone = HardIron::new();
        learn(&mut gone);
        let mut dropped_after = None;
        for k in 0..40 {
            let m = still(&gone, &Vector3::zeros(), 0);
            if gone.gone(&m, 25, 0.25, Some(&reference), &c) {
                dropped_after = Some(k + 1);
                break;
            }
        }
        assert_eq!(dropped_after, Some(5), "1.25 s of 0.25 s blocks");
        assert_eq!(gone.offset(), Vector3::zeros());
        assert!(!gone.learned);
    }
}

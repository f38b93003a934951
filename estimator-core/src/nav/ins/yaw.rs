//! The heading when no sensor measures it: a bank of yaw hypotheses weighted by how well
//! each explains the GNSS velocities (a Gaussian sum over the yaw, the idea behind PX4 EKF2's
//! yaw estimator), with the track of a vehicle that does not move sideways as a second source.
//!
//! Without a magnetometer the INS's heading is only as good as its start, and at constant
//! velocity GNSS does not observe it: the velocity error a heading error `ψ` makes is `ψ`
//! times the horizontal velocity change the IMU measured. A filter started with the wrong
//! heading then converges to whatever the first accelerations suggest, 180° included.
//!
//! **Hypotheses.** `K` = [`HYPOTHESES`] small filters, each with its own yaw offset `c_k` from
//! the INS's attitude (hypothesis `k` holds the attitude `Exp(c_k u) R̂`, `u` the world's up),
//! spread evenly over the circle with 1σ `π/K`, and its own horizontal velocity `v_k`
//! (east, north). The INS's predictions accumulate the horizontal part of their velocity
//! increments between two GNSS velocities, `Δ = Σ (R̂ (f − b̂_a) Δt)_h` (gravity is vertical and
//! drops out), and each hypothesis sees them turned by its offset:
//!
//! ```text
//! v_k⁺ = v_k + R(c_k) Δ,      F = [I₂  J R(c_k) Δ; 0  1],      J = [0 −1; 1 0]
//! Q = diag(q_v, q_v, q_c),    q_v = n_a² τ + (g² σ_t² + σ_b²) τ²,    q_c = n_g² τ + σ_bu² τ²
//! ```
//!
//! (`R(c)` the 2-D rotation by `c`, `τ` the time since the last velocity, `n_a`, `n_g` the
//! IMU's noise densities, `σ_t`, `σ_b`, `σ_bu` the INS's tilt, accelerometer-bias and
//! vertical gyro-bias 1σ: the errors every hypothesis shares, which act alike over `τ`). A
//! GNSS velocity `z` (horizontal, σ_v per axis) updates each with `H = [I₂ 0]`, and each
//! weight by its likelihood, in logarithms:
//!
//! ```text
//! ν = z − v_k,   S = P_vv + σ_v² I,   ln w_k += −½ νᵀ S_w⁻¹ ν − ½ ln det S_w,   S_w = S + σ_a² τ T_c I
//! ```
//!
//! with `σ_a² = g² σ_t² + σ_b²` the accelerations' error every hypothesis shares: it
//! persists for `T_c` (10 s: the INS corrects its tilt and bias over tens of seconds), so
//! the innovations of successive steps are not independent, and summed as if they were they
//! would pick a hypothesis as surely from a tilt error as from the motion (a rover cruising
//! at a slowly varying speed would lock on backwards as often as forwards). The states
//! themselves are updated with `S`.
//!
//!
//! **A vehicle that does not move sideways** (a car, a rover: [`InsConfig::travel`](super::InsConfig::travel),
//! declared or learned from the GNSS velocities seen in the body frame, `nav/ins/track_axis.rs`,
//! and taken back when the body turns under its track or the INS's lateral updates fail
//! their gate three times in a row),
//! adds at each velocity, once the hypothesis's speed is above 3σ of its velocity, the
//! pseudo-measurement "no lateral body velocity": with `d` the
//! horizontal forward direction (body `x`) of the INS's attitude, `d_k = R(c_k) d` and
//! `l_k = J d_k`, `0 = l_kᵀ v_k + e`, `e ~ N(0, σ_l²)`, `H = [l_kᵀ, −d_kᵀ v_k]`. It observes
//! the yaw at any speed above its noise, not only while accelerating, but cannot tell forward
//! from backward (`c` and `c + π` satisfy it alike): the accelerations do, through the
//! likelihoods (a speed change is along `+d` for one and `−d` for the other).
//!
//! **The estimate.** With normalized weights, the circular mean and the variance about it,
//!
//! ```text
//! ĉ = atan2(Σ w_k sin c_k, Σ w_k cos c_k),    σ_ĉ² = Σ w_k (P_k,cc + wrap(c_k − ĉ)²)
//! ```
//!
//! (the spread of the hypotheses counts: two at 180° from each other give `σ_ĉ ≈ π/2`).
//! Without the lateral constraint, `σ_ĉ²` gets the floor `σ_a² Σ τ² / Σ ‖Δ‖²`, with
//! `σ_a² = g² σ_t² + σ_b²` the accelerations' error every hypothesis shares (a tilt error
//! leaks gravity, a bias adds to every sample): a yaw found from accelerations is no better
//! than their shared error over their RMS size, however many fixes agree on it. A
//! log-weight is never let below the best one's by more than [`LOG_WEIGHT_FLOOR`], so a
//! hypothesis the data first disfavoured can still win later.
//!
//! **Keeping up with the INS.** The offsets are relative to the INS's attitude: when an
//! update or a reset turns it about `u` by `δ`, every offset moves by `−δ`, and the increments
//! accumulated so far turn by `δ` (`R(c) Δ = R(c − δ) R(δ) Δ`: [`YawBank::shift`]).

use super::config::Travel;
use super::track_axis::TrackAxis;
use super::velocity_check::VelocityCheck;
use crate::eskf::{EskfError, ImuSample, Ins};
use crate::kernels::mat3;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, Vector2, Vector3};

/// The number of yaw hypotheses (even: each has one at 180° from it, which only the
/// accelerations tell apart).
pub(crate) const HYPOTHESES: usize = 6;

/// The lowest log-weight below the best one's (`e⁻²⁰ ≈ 2·10⁻⁹`): low enough not to matter
/// in the mean, high enough for a hypothesis to come back when the data turn for it.
pub(crate) const LOG_WEIGHT_FLOOR: f64 = 20.0;

/// How long an acceleration error every hypothesis shares persists, s (`T_c`, module docs):
/// the INS's tilt and accelerometer-bias errors, which its GNSS aiding corrects over tens of
/// seconds, not from one fix to the next.
const SHARED_ERROR_PERSISTENCE_S: f64 = 10.0;

/// The INS's lateral-velocity updates rejected in a row that take a learned track axis back
/// ([`YawBank::lateral_outcome`]): each passes a consistent filter's 99.9 % gate but once in a
/// thousand, three in a row once in 10⁹.
pub(crate) const LATERAL_REJECTIONS_TO_REFUTE: u8 = 3;

/// A forward direction whose horizontal part is shorter than this (body `x` within 30° of
/// the vertical) gives no track direction.
const MIN_FORWARD_HORIZONTAL: f64 = 0.5;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Hypothesis<T: Real> {
    /// Yaw offset from the INS's attitude, rad, in `(−π, π]`.
    offset: T,
    /// Horizontal velocity (east, north), m/s.
    velocity: Vector2<T>,
    /// Covariance of `(v_e, v_n, c)`.
    covariance: Matrix3<T>,
    log_weight: T,
}

/// The process noise of the bank ([`YawBank::fuse_velocity`]), as densities: over `τ`,
/// `q_v = white_velocity τ + drift_velocity τ²` and `q_c = white_yaw τ + drift_yaw τ²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StepNoise<T: Real> {
    /// `n_a²`, (m/s²)²/Hz.
    pub white_velocity: T,
    /// `g² σ_t² + σ_b²`, (m/s²)².
    pub drift_velocity: T,
    /// `n_g²`, (rad/s)²/Hz.
    pub white_yaw: T,
    /// `σ_bu²`, (rad/s)².
    pub drift_yaw: T,
}

/// The bank of yaw hypotheses (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct YawBank<T: Real> {
    hypotheses: [Hypothesis<T>; HYPOTHESES],
    /// The INS's horizontal velocity increments since the last velocity, m/s.
    increment: Vector2<T>,
    /// Their duration, s.
    duration: T,
    /// The hypotheses have their first velocity.
    started: bool,
    /// GNSS velocities fused since the start.
    fixes: u16,
    /// `Σ ‖Δ‖²` and `Σ τ²` over the bank's steps, and the latest `g² σ_t² + σ_b²`: the
    /// floor of a yaw found from the accelerations alone (module docs).
    increments_squared: T,
    durations_squared: T,
    systematic: T,
    /// The lateral velocity's variance of a vehicle that does not move sideways (the yaw is
    /// then not from the accelerations alone); `None` for one that may.
    lateral: Option<T>,
    /// How the vehicle moves against its body, as configured.
    travel: Travel<T>,
    /// Its GNSS velocities in the INS's heading frame, for [`Travel::Detect`].
    axis: TrackAxis<T>,
    /// Whether the GNSS velocities agree with the positions (`nav/ins/velocity_check.rs`):
    /// the bank takes none while they do not.
    check: VelocityCheck<T>,
    /// The INS's attitude before the fusion under way, and the GNSS velocity it brought
    /// (the body's, at the filter's time, with its 1σ per axis): what
    /// [`InsNavigator::track_heading`](super::InsNavigator) takes after it.
    before: So3<T>,
    velocity: Option<(Vector3<T>, T)>,
    /// Nothing else measures the heading (no magnetometer): the bank runs.
    active: bool,
    /// The INS's heading has been set from the bank.
    resolved: bool,
    /// … while the bank held a vehicle along its track.
    resolved_by_track: bool,
    /// The INS's lateral-velocity updates rejected in a row.
    lateral_rejections: u8,
}

/// `x` wrapped into `(−π, π]`.
fn wrap<T: Real>(x: T) -> T {
    let two_pi = T::two_pi();
    let turns = (x / two_pi).round();
    let y = x - two_pi * turns;
    if y <= -T::pi() {
        y + two_pi
    } else if y > T::pi() {
        y - two_pi
    } else {
        y
    }
}

/// `R(c) a` for `(sin c, cos c)`.
fn rotate<T: Real>((s, c): (T, T), a: &Vector2<T>) -> Vector2<T> {
    Vector2::new(c * a.x - s * a.y, s * a.x + c * a.y)
}

impl<T: Real> Hypothesis<T> {
    /// The velocity update `H = [I₂ 0]` (σ_v² per axis); returns the log-likelihood of its
    /// innovation with `shared` added to each axis of its covariance (module docs).
    fn fuse_velocity(&mut self, z: &Vector2<T>, variance: T, shared: T) -> T {
        let p = &self.covariance;
        let (a, b, d) = (p.m11 + variance, p.m12, p.m22 + variance);
        let det = a * d - b * b;
        // S⁻¹ = [d −b; −b a] / det S; the gain K = P[:, 0..2] S⁻¹.
        let inv = |x: T, y: T| Vector2::new(d * x - b * y, a * y - b * x) / det;
        let nu = z - self.velocity;
        let s_inv_nu = inv(nu.x, nu.y);
        let rows = [
            Vector2::new(p.m11, p.m12),
            Vector2::new(p.m21, p.m22),
            Vector2::new(p.m31, p.m32),
        ];
        // δx = P[:, 0..2] S⁻¹ ν; P⁺ = P − P[:, 0..2] S⁻¹ P[0..2, :].
        let gain_rows = rows.map(|r| inv(r.x, r.y));
        let dx = Vector3::new(
            rows[0].dot(&s_inv_nu),
            rows[1].dot(&s_inv_nu),
            rows[2].dot(&s_inv_nu),
        );
        let mut down = Matrix3::zeros();
        for (i, gi) in gain_rows.iter().enumerate() {
            for (j, rj) in rows.iter().enumerate() {
                if let Some(e) = down.get_mut((i, j)) {
                    *e = gi.dot(rj);
                }
            }
        }
        self.apply(&dx, &down);
        let (a, d) = (a + shared, d + shared);
        let det = a * d - b * b;
        let s_inv_nu = Vector2::new(d * nu.x - b * nu.y, a * nu.y - b * nu.x) / det;
        -T::lit(0.5) * (nu.dot(&s_inv_nu) + det.ln())
    }

    /// The scalar update `0 = h x + e`, `e ~ N(0, variance)`, linearized at the estimate with
    /// the row `h` and the value `y = h(x̂)`.
    fn fuse_scalar(&mut self, h: &Vector3<T>, y: T, variance: T) {
        let ph = mat3::mul_vec(&self.covariance, h);
        let s = h.dot(&ph) + variance;
        let nu = -y;
        let dx = ph * (nu / s);
        let down = mat3::sym_outer(&ph, &ph) * (T::lit(0.5) / s);
        self.apply(&dx, &down);
    }

    /// `x += δx`, `P −= D`, `P` made exactly symmetric with a non-negative diagonal.
    fn apply(&mut self, dx: &Vector3<T>, down: &Matrix3<T>) {
        self.velocity += Vector2::new(dx.x, dx.y);
        self.offset = wrap(self.offset + dx.z);
        let p = self.covariance - down;
        let p = (p + p.transpose()) * T::lit(0.5);
        let floor = T::lit(T::EPSILON_F64);
        let mut p = p;
        for k in 0..3 {
            if let Some(e) = p.get_mut((k, k)) {
                *e = e.max(floor);
            }
        }
        self.covariance = p;
    }
}

impl<T: Real> YawBank<T> {
    /// A bank without its first velocity; `active` when nothing else measures the heading,
    /// `travel` how the vehicle moves against its body.
    pub(crate) fn new(active: bool, travel: Travel<T>) -> Self {
        let lateral = match travel {
            Travel::Forward { lateral_sigma } => Some(lateral_sigma * lateral_sigma),
            Travel::Detect | Travel::Sideways => None,
        };
        let h = Hypothesis {
            offset: T::zero(),
            velocity: Vector2::zeros(),
            covariance: Matrix3::zeros(),
            log_weight: T::zero(),
        };
        Self {
            hypotheses: [h; HYPOTHESES],
            increment: Vector2::zeros(),
            duration: T::zero(),
            started: false,
            fixes: 0,
            increments_squared: T::zero(),
            durations_squared: T::zero(),
            systematic: T::zero(),
            lateral,
            travel,
            axis: TrackAxis::default(),
            check: VelocityCheck::default(),
            before: So3::identity(),
            velocity: None,
            active,
            resolved: false,
            resolved_by_track: false,
            lateral_rejections: 0,
        }
    }

    /// The INS's attitude before a fusion.
    pub(crate) fn note_attitude(&mut self, attitude: &So3<T>) {
        if self.active {
            self.before = *attitude;
        }
    }

    /// A GNSS velocity the INS fused (or reset to): the body's, at the filter's time, with
    /// its 1σ per axis.
    pub(crate) fn take_velocity(&mut self, velocity: &Vector3<T>, sigma: T) {
        if self.active && self.check.agree() {
            self.velocity = Some((*velocity, sigma));
        }
    }

    /// The attitude noted before the fusion, and the velocity it brought (taken: `None`
    /// until the next one).
    pub(crate) fn fused(&mut self) -> (So3<T>, Option<(Vector3<T>, T)>) {
        (self.before, self.velocity.take())
    }

    /// The bank runs: nothing else measures the heading.
    pub(crate) fn active(&self) -> bool {
        self.active
    }

    /// The INS's heading has been set from the bank.
    pub(crate) fn resolved(&self) -> bool {
        self.resolved
    }

    /// Marks the INS's heading as set from the bank.
    pub(crate) fn set_resolved(&mut self) {
        self.resolved = true;
        self.resolved_by_track = self.lateral.is_some();
    }

    /// Adds one INS prediction's horizontal velocity increment `(R̂ (f − b̂_a) Δt)_h` over `dt`.
    pub(crate) fn accumulate(&mut self, increment: &Vector2<T>, dt: T) {
        self.increment += increment;
        self.duration += dt;
    }

    /// The INS's prediction with `imu` ([`Ins::predict_finite`]), whose horizontal velocity
    /// increment, `(R̂ (f − b̂_a) + g) Δt` east and north, the bank takes when it runs.
    /// Out of line: the velocity kept across the prediction stays out of every IMU call's frame.
    #[inline(never)]
    pub(crate) fn predict(
        &mut self,
        ins: &mut Ins<T>,
        imu: &ImuSample<T>,
    ) -> Result<(), EskfError> {
        let before = self.active.then(|| ins.state().velocity);
        ins.predict_finite(imu)?;
        if let Some(before) = before {
            let dv = ins.state().velocity - before;
            self.accumulate(&Vector2::new(dv.x, dv.y), imu.dt);
        }
        Ok(())
    }

    /// The INS's attitude turned by `turn` about the up direction: every offset moves by
    /// `−turn`, so that each hypothesis keeps its own attitude.
    pub(crate) fn shift(&mut self, turn: T) {
        for h in &mut self.hypotheses {
            h.offset = wrap(h.offset - turn);
        }
        // The increments so far were measured in the INS's frame before the turn: in the new
        // one, `R(c) Δ = R(c − turn) R(turn) Δ`.
        self.increment = rotate(turn.sincos(), &self.increment);
        self.axis.turn(turn);
    }

    /// GNSS velocities fused since the first.
    pub(crate) fn fixes(&self) -> u16 {
        self.fixes
    }

    /// One GNSS velocity: horizontal `z` with `variance` per axis, and the INS's horizontal
    /// forward direction `forward` (body `x`, not normalized). The first starts the hypotheses at
    /// `z`; each later one predicts them over the accumulated increments with `noise` and
    /// updates them and their weights.
    pub(crate) fn fuse_velocity(
        &mut self,
        z: &Vector2<T>,
        variance: T,
        forward: &Vector2<T>,
        noise: &StepNoise<T>,
    ) {
        let track = forward.dot(forward).sqrt_rn();
        let d = (track >= T::lit(MIN_FORWARD_HORIZONTAL)).then(|| forward / track);
        if self.travel == Travel::Detect {
            if let Some(d) = &d {
                self.axis.add(z, variance, d);
            }
            let was = self.lateral.is_some();
            self.lateral = self.axis.lateral_variance();
            if was && self.lateral.is_none() {
                // The body turned under its track: it moves sideways.
                self.refute();
            }
        }
        if !self.started {
            let count = T::from_count(HYPOTHESES as u32);
            let spread = T::pi() / count;
            for (k, h) in self.hypotheses.iter_mut().enumerate() {
                h.offset = wrap(T::two_pi() * T::from_count(k as u32) / count);
                h.velocity = *z;
                h.covariance =
                    Matrix3::from_diagonal(&Vector3::new(variance, variance, spread * spread));
                h.log_weight = T::zero();
            }
            self.started = true;
        } else {
            let (increment, tau) = (self.increment, self.duration);
            let q_v = (noise.white_velocity + noise.drift_velocity * tau) * tau;
            let q_c = (noise.white_yaw + noise.drift_yaw * tau) * tau;
            // The weights see the error every hypothesis shares as what it is, one that
            // persists: over its persistence `T_c` it adds `σ_a² τ T_c` to each innovation.
            let shared = noise.drift_velocity * tau * T::lit(SHARED_ERROR_PERSISTENCE_S);
            self.increments_squared += increment.dot(&increment);
            self.durations_squared += tau * tau;
            self.systematic = noise.drift_velocity;
            for h in &mut self.hypotheses {
                let sc = h.offset.sincos();
                let turned = rotate(sc, &increment);
                h.velocity += turned;
                // P ← F P Fᵀ + Q with F = I + f e₃ᵀ, f = (J R(c) Δ, 0).
                let f = Vector3::new(-turned.y, turned.x, T::zero());
                let p = h.covariance;
                let pc = Vector3::new(p.m13, p.m23, p.m33);
                let fp =
                    p + mat3::sym_outer(&f, &pc) + mat3::sym_outer(&f, &f) * (p.m33 * T::lit(0.5));
                h.covariance = fp + Matrix3::from_diagonal(&Vector3::new(q_v, q_v, q_c));
                let log_likelihood = h.fuse_velocity(z, variance, shared);
                // The constraint tells the yaw through the velocity's direction: only when the
                // hypothesis's speed is above 3σ of its velocity (at rest, a velocity of noise
                // would point the yaw anywhere).
                let moving = h.velocity.dot(&h.velocity)
                    >= T::lit(9.0) * h.covariance.m11.max(h.covariance.m22);
                if let (Some(d), Some(sigma2), true) = (d, self.lateral, moving) {
                    let dk = rotate(h.offset.sincos(), &d);
                    let lk = Vector2::new(-dk.y, dk.x);
                    let row = Vector3::new(lk.x, lk.y, -dk.dot(&h.velocity));
                    // The state only, not the weight: a hypothesis that started far from the
                    // track would pay for its way there, and which of a forward and a backward
                    // pair started nearer is chance.
                    h.fuse_scalar(&row, lk.dot(&h.velocity), sigma2);
                }
                h.log_weight += log_likelihood;
            }
            self.normalize();
            self.fixes = self.fixes.saturating_add(1);
        }
        self.increment = Vector2::zeros();
        self.duration = T::zero();
    }

    /// Log-weights relative to the best, floored at [`LOG_WEIGHT_FLOOR`] below it; a
    /// non-finite one (a failed update) starts the bank again at the next velocity.
    fn normalize(&mut self) {
        let best = self
            .hypotheses
            .iter()
            .fold(T::lit(f64::NEG_INFINITY), |m, h| m.max(h.log_weight));
        let finite = self.hypotheses.iter().all(|h| {
            h.log_weight.is_finite()
                && h.offset.is_finite()
                && h.covariance.iter().all(|x| x.is_finite())
        });
        if !(finite && best.is_finite()) {
            self.restart();
            return;
        }
        let floor = -T::lit(LOG_WEIGHT_FLOOR);
        for h in &mut self.hypotheses {
            h.log_weight = (h.log_weight - best).max(floor);
        }
    }

    /// The weighted circular mean and variance about it of the hypotheses `keep` selects, with
    /// their total weight (module docs).
    fn mixture(&self, keep: impl Fn(&Hypothesis<T>) -> bool) -> (T, T, T) {
        let (mut sum_w, mut sum_s, mut sum_c) = (T::zero(), T::zero(), T::zero());
        for h in self.hypotheses.iter().filter(|h| keep(h)) {
            let w = h.log_weight.exp();
            let (s, c) = h.offset.sincos();
            sum_w += w;
            sum_s += w * s;
            sum_c += w * c;
        }
        let mean = sum_s.arctan2(sum_c);
        let spread = self
            .hypotheses
            .iter()
            .filter(|h| keep(h))
            .fold(T::zero(), |acc, h| {
                let e = wrap(h.offset - mean);
                acc + h.log_weight.exp() * (h.covariance.m33 + e * e)
            });
        (mean, (spread / sum_w).max(T::zero()), sum_w)
    }

    /// The bank's yaw offset from the INS's attitude and its 1σ, rad: `(ĉ, σ_ĉ)` (module docs),
    /// once started.
    pub(crate) fn estimate(&self) -> Option<(T, T)> {
        if !self.started {
            return None;
        }
        let (mean, variance, _) = self.mixture(|_| true);
        // From the accelerations alone, a yaw is no better than the accelerations' shared
        // error over their size: `σ_a² Σ τ² / Σ ‖Δ‖²` (at most a uniform heading's π²/3).
        let uniform = T::pi() * T::pi() / T::lit(3.0);
        let floor = if self.lateral.is_some() {
            T::zero()
        } else if self.systematic * self.durations_squared < uniform * self.increments_squared {
            self.systematic * self.durations_squared / self.increments_squared
        } else {
            uniform
        };
        Some((mean, (variance + floor).sqrt_rn()))
    }

    /// For a vehicle that moves along its track, with the INS's horizontal forward direction
    /// `forward`: the hypotheses that see it moving forward (`R(c_k) d · v_k ≥ 0`), as
    /// [`YawBank::estimate`].
    pub(crate) fn forward_estimate(&self, forward: &Vector2<T>) -> Option<(T, T)> {
        let track = forward.dot(forward).sqrt_rn();
        if !(self.started && track >= T::lit(MIN_FORWARD_HORIZONTAL)) {
            return None;
        }
        let d = forward / track;
        let ahead = |h: &Hypothesis<T>| rotate(h.offset.sincos(), &d).dot(&h.velocity) >= T::zero();
        let (mean, variance, w_forward) = self.mixture(ahead);
        (w_forward > T::zero()).then(|| (mean, variance.sqrt_rn()))
    }

    /// The bank holds a vehicle that does not move sideways to its track.
    pub(crate) fn track(&self) -> bool {
        self.lateral.is_some()
    }

    /// The outcome of the INS's lateral-velocity update. A learned axis
    /// ([`Travel::Detect`]) is taken back, for the rest of the run, after
    /// [`LATERAL_REJECTIONS_TO_REFUTE`] rejections in a row: the body moved sideways, so its
    /// track is not its heading, and a heading resolved from the track is not known after all.
    pub(crate) fn lateral_outcome(&mut self, accepted: bool) {
        if accepted {
            self.lateral_rejections = 0;
            return;
        }
        self.lateral_rejections = self.lateral_rejections.saturating_add(1);
        if self.travel == Travel::Detect && self.lateral_rejections >= LATERAL_REJECTIONS_TO_REFUTE
        {
            self.refute();
        }
    }

    /// A learned track axis taken back for the rest of the run: the vehicle moves sideways.
    /// A heading resolved from the track is not known after all, and the hypotheses, pulled
    /// onto the track, start again at the next velocity.
    fn refute(&mut self) {
        self.travel = Travel::Sideways;
        self.lateral = None;
        if self.resolved_by_track {
            self.resolved = false;
            self.resolved_by_track = false;
        }
        self.restart();
    }

    /// A GNSS velocity as the receiver gave it (horizontal, world), valid at `t_ns`, with its
    /// 1σ per axis: for the comparison with the positions.
    pub(crate) fn check_velocity(&mut self, t_ns: u64, velocity: &Vector3<T>, sigma: T) {
        if self.active {
            let v = Vector2::new(velocity.x, velocity.y);
            self.check.velocity(t_ns, &v, sigma * sigma);
        }
    }

    /// A GNSS position (world), valid at `t_ns`, with its horizontal 1σ; `true` when it
    /// closes a window over which the velocities disagreed with the positions (the bank then
    /// takes no velocity until a window agrees again).
    pub(crate) fn check_position(&mut self, t_ns: u64, position: &Vector3<T>, sigma: T) -> bool {
        if !self.active {
            return false;
        }
        let p = Vector2::new(position.x, position.y);
        self.check.position(t_ns, &p, sigma * sigma) == Some(false)
    }

    /// Starts the hypotheses again at the next velocity, from nothing learned.
    fn restart(&mut self) {
        self.started = false;
        self.fixes = 0;
        self.increments_squared = T::zero();
        self.durations_squared = T::zero();
    }

    /// The lateral velocity's 1σ of a vehicle that does not move sideways, m/s, configured or
    /// learned ([`Travel`]); `None` for one that may.
    pub(crate) fn lateral_sigma(&self) -> Option<T> {
        self.lateral.map(|v| v.sqrt_rn())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NOISE: StepNoise<f64> = StepNoise {
        white_velocity: 1e-4,
        drift_velocity: 1e-4,
        white_yaw: 1e-6,
        drift_yaw: 1e-8,
    };

    /// A vehicle driven for `seconds` at 5 Hz fixes with world acceleration `accel(t)` from
    /// rest, seen by an INS whose heading is off by `error` (so its increments are the true
    /// ones turned by `error`), forward along its velocity; returns the bank.
    fn drive(
        error: f64,
        seconds: f64,
        lateral: Option<f64>,
        accel: impl Fn(f64) -> Vector2<f64>,
    ) -> YawBank<f64> {
        let travel = lateral.map_or(Travel::Sideways, |v: f64| Travel::Forward {
            lateral_sigma: v.sqrt(),
        });
        drive_with(travel, error, seconds, accel)
    }

    /// [`drive`] with the vehicle's travel as configured.
    fn drive_with(
        travel: Travel<f64>,
        error: f64,
        seconds: f64,
        accel: impl Fn(f64) -> Vector2<f64>,
    ) -> YawBank<f64> {
        let mut bank = YawBank::new(true, travel);
        let (dt, steps_per_fix) = (0.01, 20);
        let mut v = Vector2::zeros();
        let mut heading = 0.0_f64;
        let mut t = 0.0;
        let turn = |a: f64, x: &Vector2<f64>| rotate(a.sincos(), x);
        while t < seconds {
            for _ in 0..steps_per_fix {
                let a = accel(t);
                v += a * dt;
                if v.norm() > 0.05 {
                    heading = v.y.atan2(v.x);
                }
                bank.accumulate(&turn(error, &(a * dt)), dt);
                t += dt;
            }
            // The INS's forward direction: the true one turned by the INS's heading error.
            let forward = turn(error, &Vector2::new(heading.cos(), heading.sin()));
            bank.fuse_velocity(&v, 0.01, &forward, &NOISE);
        }
        bank
    }

    #[test]
    fn wrap_keeps_angles_in_the_half_open_circle() {
        let pi = core::f64::consts::PI;
        for (x, w) in [
            (0.0, 0.0),
            (pi, pi),
            (-pi, pi),
            (3.0 * pi, pi),
            (2.5 * pi, 0.5 * pi),
        ] {
            assert!((wrap(x) - w).abs() < 1e-12, "{x}");
        }
    }

    #[test]
    fn accelerations_resolve_a_heading_off_by_150_degrees() {
        let error = 150f64.to_radians();
        // Accelerate east, then turn: a = 0.5 m/s² east for 4 s, then a centripetal 0.3 m/s².
        let bank = drive(error, 30.0, None, |t| {
            if t < 4.0 {
                Vector2::new(0.5, 0.0)
            } else {
                let s = 0.15 * (t - 4.0);
                Vector2::new(-s.sin(), s.cos()) * 0.3
            }
        });
        let (offset, sigma) = bank.estimate().expect("started");
        // The offset takes the INS's heading to the truth: −error.
        assert!(
            wrap(offset + error).abs() < 2f64.to_radians(),
            "{}",
            offset.to_degrees()
        );
        assert!(sigma < 2f64.to_radians(), "σ {}", sigma.to_degrees());
    }

    #[test]
    fn the_track_alone_cannot_tell_forward_from_backward() {
        // A start already moving (the bank starts at the first fix), then constant velocity:
        // the lateral constraint finds the track, and nothing tells its sign.
        let error = 100f64.to_radians();
        let bank = drive(error, 20.0, Some(0.01), |t| {
            if t < 0.2 {
                Vector2::new(0.0, 5.0)
            } else {
                Vector2::zeros()
            }
        });
        let (_, sigma) = bank.estimate().expect("started");
        assert!(sigma > 60f64.to_radians(), "σ {}", sigma.to_degrees());
        // Every hypothesis sits on the track, forward or backward.
        for h in &bank.hypotheses {
            let off = wrap(h.offset + error);
            let on_track = off.abs().min(core::f64::consts::PI - off.abs());
            assert!(on_track < 1f64.to_radians(), "{}", off.to_degrees());
        }
    }

    #[test]
    fn a_speed_change_on_the_track_tells_forward_from_backward() {
        let error = -120f64.to_radians();
        let bank = drive(error, 40.0, Some(0.05), rover_speed);
        // The yaw is known to the velocity's steady-state error over the speed: with the
        // random walk q_v = 2.4e-5 (m/s)² per fix against the fixes' 0.01, (q_v r)^¼ ≈ 0.022
        // m/s, over 0.35 m/s: 3.6°.
        assert_found(bank.estimate(), error);
    }

    /// 0.35 m/s north reached in 2 s, then slower and faster again (a rover's speed): the
    /// acceleration at `t`.
    fn rover_speed(t: f64) -> Vector2<f64> {
        let along = if t < 2.0 {
            0.175
        } else {
            0.05 * (0.5 * t).cos()
        };
        Vector2::new(0.0, along)
    }

    /// The bank's `(offset, σ)` takes an INS off by `error` to the truth: σ below 5°, the
    /// offset within 3σ of `−error`.
    fn assert_found(estimate: Option<(f64, f64)>, error: f64) {
        let (offset, sigma) = estimate.expect("started");
        assert!(sigma < 5f64.to_radians(), "σ {}", sigma.to_degrees());
        assert!(
            wrap(offset + error).abs() < 3.0 * sigma,
            "{}",
            offset.to_degrees()
        );
    }

    #[test]
    fn a_turn_of_the_ins_moves_every_offset_and_the_increments() {
        let mut bank = drive(0.3, 10.0, None, |_| Vector2::new(0.3, 0.0));
        let (before, _) = bank.estimate().expect("started");
        bank.accumulate(&Vector2::new(0.1, 0.0), 0.1);
        bank.shift(0.2);
        let (after, _) = bank.estimate().expect("started");
        assert!((wrap(after - before) + 0.2).abs() < 1e-12);
        assert!((bank.increment - rotate(0.2f64.sincos(), &Vector2::new(0.1, 0.0))).norm() < 1e-15);
    }

    #[test]
    fn a_vehicle_along_its_track_is_learned_and_found_forward() {
        let error = -120f64.to_radians();
        let bank = drive_with(Travel::Detect, error, 40.0, rover_speed);
        // No lateral motion: the learned σ_l is the sampling bound of the fixes' noise,
        // σ_v √2 (2/n)^¼ with σ_v = 0.1 m/s and n ≈ 200: 0.045 m/s.
        let sigma_l = bank.lateral_sigma().expect("an axis");
        assert!(sigma_l < 0.05, "{sigma_l}");
        let d = rotate(error.sincos(), &Vector2::new(0.0, 1.0));
        assert_found(bank.forward_estimate(&d), error);
    }

    #[test]
    fn three_rejected_lateral_updates_in_a_row_take_a_learned_axis_back() {
        let mut bank = drive_with(Travel::Detect, 0.5, 20.0, |t| {
            Vector2::new(0.0, if t < 2.0 { 0.2 } else { 0.0 })
        });
        assert!(bank.track());
        bank.set_resolved();
        bank.lateral_outcome(false);
        bank.lateral_outcome(false);
        bank.lateral_outcome(true);
        bank.lateral_outcome(false);
        bank.lateral_outcome(false);
        assert!(bank.track() && bank.resolved(), "not three in a row");
        bank.lateral_outcome(false);
        assert!(!bank.track() && !bank.resolved());
        assert_eq!(
            (bank.travel, bank.started, bank.fixes),
            (Travel::Sideways, false, 0)
        );
    }

    #[test]
    fn a_declared_axis_is_never_taken_back() {
        let mut bank = drive(0.5, 20.0, Some(0.01), |t| {
            Vector2::new(0.0, if t < 2.0 { 0.2 } else { 0.0 })
        });
        for _ in 0..10 {
            bank.lateral_outcome(false);
        }
        assert!(bank.track());
    }
}

//! The output predictor: the IMU increments between the delayed filter and the present, kept
//! as one running product so the present estimate costs O(1) per sample.
//!
//! Over IMU intervals `k = 1…n` after the filter's time `t_f` (rate `ω_k`, specific force `f_k`,
//! both bias-corrected, length `dt_k`), in the body frame at `t_f`:
//!
//! ```text
//! ΔR ← ΔR·Exp(ω_k dt_k),   Δv ← Δv + ΔR f_k dt_k,   Δp ← Δp + Δv dt_k + ½ ΔR f_k dt_k²,   T ← T + dt_k
//! ```
//!
//! (each step as the filter's own prediction integrates it, before `ΔR` moves), and the
//! present state is
//!
//! ```text
//! R = R_f ΔR,   v = v_f + g T + R_f Δv,   p = p_f + v_f T + ½ g T² + R_f Δp
//! ```
//!
//! (the preintegrated IMU increments of Forster et al., *On-Manifold Preintegration for
//! Real-Time Visual-Inertial Odometry*, 2017, eqs. 33–35, on the right-perturbed rotation
//! of *Lie Groups and Smooth Manifolds for Robotic State Estimation*, eq. 4.5,
//! `R ⊕ θ = R·Exp(θ)`). When the filter takes the oldest interval `(δR, δv, δp, δt)`
//! (one step of the recursion above from the identity), the window becomes its remainder:
//! from `Δ₀ₙ = Δ₀₁ ∘ Δ₁ₙ`,
//!
//! ```text
//! ΔR₁ₙ = δRᵀ ΔR₀ₙ,   Δv₁ₙ = δRᵀ (Δv₀ₙ − δv),   Δp₁ₙ = δRᵀ (Δp₀ₙ − δp − δv (T − δt)),   T₁ₙ = T − δt.
//! ```
//!
//! Removal rounds a little every step; so a second window (`fresh`) integrates only new
//! samples, and replaces the first when the filter reaches its start (every horizon), which
//! bounds the rounding to that of one horizon's steps. For the same reason the rotation is not
//! renormalized per step: a product of at most two horizons' unit quaternions (128 at 200 Hz)
//! departs from unit norm by about 128 ε (2·10⁻⁵ in `f32`), and the estimate renormalizes the
//! attitude it reports. Each window integrates with one fixed
//! bias, the filter's when it began, so that removal undoes exactly what was added.

use crate::kernels::mat3;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::Vector3;

/// One IMU interval as the filter integrates it: the rate and specific force over the
/// interval (the trapezoidal mean of its two samples for instantaneous samples), its length
/// and end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Interval<T: Real> {
    /// The interval's end, ns.
    pub t_ns: u64,
    /// Rate, rad/s (bias included).
    pub gyro: Vector3<T>,
    /// Specific force, m/s² (bias included).
    pub accel: Vector3<T>,
    /// Length, s.
    pub dt: T,
}

/// The product of the increments of consecutive intervals (module docs), integrated with
/// the fixed biases `gyro_bias`, `accel_bias`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Increment<T: Real> {
    pub rotation: So3<T>,
    pub velocity: Vector3<T>,
    pub position: Vector3<T>,
    pub duration: T,
    pub gyro_bias: Vector3<T>,
    pub accel_bias: Vector3<T>,
}

impl<T: Real> Increment<T> {
    /// The empty product, for intervals to be integrated with these biases.
    pub(crate) fn empty(gyro_bias: Vector3<T>, accel_bias: Vector3<T>) -> Self {
        Self {
            rotation: So3::identity(),
            velocity: Vector3::zeros(),
            position: Vector3::zeros(),
            duration: T::zero(),
            gyro_bias,
            accel_bias,
        }
    }

    /// The increment of one interval, `(δR, δv, δp, δt)`, in the frame at its start.
    fn single(&self, s: &Interval<T>) -> (So3<T>, Vector3<T>, Vector3<T>) {
        let f = s.accel - self.accel_bias;
        let dv = f * s.dt;
        let dp = dv * (T::lit(0.5) * s.dt);
        (So3::exp(&((s.gyro - self.gyro_bias) * s.dt)), dv, dp)
    }

    /// Appends an interval at the end: `Δ ← Δ ∘ δ`.
    pub(crate) fn append(&mut self, s: &Interval<T>) {
        let (dr, dv, dp) = self.single(s);
        let r = self.rotation.rotation_matrix();
        self.position += self.velocity * s.dt + mat3::mul_vec(&r, &dp);
        self.velocity += mat3::mul_vec(&r, &dv);
        self.rotation = self.rotation.compose(&dr);
        self.duration += s.dt;
    }

    /// Removes the first interval: `Δ ← δ⁻¹ ∘ Δ`.
    pub(crate) fn remove_first(&mut self, s: &Interval<T>) {
        let (dr, dv, dp) = self.single(s);
        let back = dr.inverse();
        let rest = self.duration - s.dt;
        self.position = back.act(&(self.position - dp - dv * rest));
        self.velocity = back.act(&(self.velocity - dv));
        self.rotation = back.compose(&self.rotation);
        self.duration = if rest > T::zero() { rest } else { T::zero() };
    }
}

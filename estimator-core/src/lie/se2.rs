//! SE(2), planar rigid motions `T = (R, t)`, the motivating example of *Lie Groups and Smooth
//! Manifolds for Robotic State Estimation* (§3).
//!
//! Tangent `τ = [v_x, v_y, ω]`, the paper's 2-D twist `ξ = (v, ω)`; its hat (§3, and eq. 3.2
//! `τ^ = Σᵢ τᵢ Gⁱ`) is
//!
//! ```text
//! τ^ = [0 −ω v_x; ω 0 v_y; 0 0 0]
//! ```
//!
//! With `a = sin ω/ω`, `b = (1 − cos ω)/ω²`, `c = (ω − sin ω)/ω³` (all even in `ω`):
//!
//! * `exp(τ) = (R(ω), V v)`, `V = [[a, −ωb], [ωb, a]]`.
//! * `log(T) = [V⁻¹ t; ω]`, `V⁻¹ = [[h, ω/2], [−ω/2, h]]`, `h = (ω/2)·cot(ω/2)`.
//! * `J_r(τ) = [[a, ωb, ωc·v_x − b·v_y], [−ωb, a, b·v_x + ωc·v_y], [0, 0, 1]]`, and
//!   `J_r⁻¹` by block inversion: `M⁻¹ = [[h, −ω/2], [ω/2, h]]`, last column `−M⁻¹ m`.
//! * `Ad_T = [[R, (t_y, −t_x)ᵀ], [0, 1]]`.
//! * `act_jac(p) = (R p + t, [R | R G p], R)` with `G = [0 −1; 1 0]`: the paper's Theorem 5.1,
//!   `F = T [H(p) | I]` with `H(p) = [I | G p]`.

use super::so2::So2;
use super::trig::{half_cot, poly, AngleCoeffs, Cutoff};
use super::{LieGroup, Real, ORTHOGONALITY_TOLERANCE};
use crate::kernels::all_finite;
use nalgebra::{Matrix2, Matrix2x3, Matrix3, Vector2, Vector3};

/// A planar rigid motion `T = (R, t) ∈ SE(2)`.
///
/// ```
/// use estimator_core::lie::{LieGroup, Se2};
/// use nalgebra::{Vector2, Vector3};
///
/// // A quarter turn, then one metre along the new x axis: exp of the twist (v, ω) = (π/2, 0, π/2).
/// let h = core::f64::consts::FRAC_PI_2;
/// let a = Se2::exp(&Vector3::new(h, 0.0, h));
/// assert!((a.translation() - Vector2::new(1.0, 1.0)).amax() < 1e-15);
/// assert!((a.log() - Vector3::new(h, 0.0, h)).amax() < 1e-15);
/// assert!((a.act(&Vector2::new(1.0, 0.0)) - Vector2::new(1.0, 2.0)).amax() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se2<T: Real> {
    rotation: So2<T>,
    translation: Vector2<T>,
}

/// `ω b = (1 − cos ω)/ω`: `±θb` ([`AngleCoeffs::b_theta`]) for a huge `ω`, whose `b = 2h²`
/// underflows.
fn w_times_b<T: Real>(k: &AngleCoeffs<T>, w: T) -> T {
    if k.is_huge() {
        k.b_theta() * w.signum()
    } else {
        w * k.b
    }
}

impl<T: Real> Se2<T> {
    /// `T = (R, t)`.
    #[must_use]
    pub fn from_parts(rotation: So2<T>, translation: Vector2<T>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// From `x`, `y` and the heading `θ`.
    #[must_use]
    pub fn new(x: T, y: T, theta: T) -> Self {
        Self::from_parts(So2::from_angle(theta), Vector2::new(x, y))
    }

    /// The same motion in another precision, stored numbers converted as they are.
    #[must_use]
    pub fn cast<U: Real>(&self) -> Se2<U> {
        let t = &self.translation;
        Se2::from_parts(
            self.rotation.cast(),
            Vector2::new(U::lit(t.x.to_f64()), U::lit(t.y.to_f64())),
        )
    }

    /// The rotation `R`.
    #[must_use]
    pub fn rotation(&self) -> So2<T> {
        self.rotation
    }

    /// The translation `t`.
    #[must_use]
    pub fn translation(&self) -> Vector2<T> {
        self.translation
    }

    /// `exp(τ) = (R(ω), V v)` from the kernel of `ω`.
    fn exp_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Self {
        let w = tau.z;
        let wb = w_times_b(k, w);
        // (cos ω, sin ω) from the half-angle kernel: unit to rounding, NaN in gives NaN out.
        let rotation = So2::from_unit(k.cos(), k.a * w);
        Self {
            rotation,
            translation: Vector2::new(k.a * tau.x - wb * tau.y, wb * tau.x + k.a * tau.y),
        }
    }

    /// `J_r(τ)` from the kernel of `ω` (module docs).
    fn jr_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Matrix3<T> {
        let (vx, vy, w) = (tau.x, tau.y, tau.z);
        let wb = w_times_b(k, w);
        // ω c = ±(1 − a)/θ for a huge ω (c underflows to 0 there).
        let wc = if k.is_huge() {
            (T::one() - k.a) / k.theta * w.signum()
        } else {
            w * k.c
        };
        Matrix3::new(
            k.a,
            wb,
            wc * vx - k.b * vy,
            -wb,
            k.a,
            k.b * vx + wc * vy,
            T::zero(),
            T::zero(),
            T::one(),
        )
    }

    /// `J_r⁻¹(τ)` by block inversion of `J_r = [[M, m], [0, 1]]`: `[[M⁻¹, −M⁻¹ m], [0, 1]]`,
    /// `M⁻¹ = [[h, −ω/2], [ω/2, h]]`.
    fn jr_inv_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Matrix3<T> {
        let w = tau.z;
        let h = half_cot(k.theta_sq, k.theta, k.sin_half, k.cos_half);
        let hw = T::lit(0.5) * w;
        // J_r's last column `m`.
        let jr = Self::jr_from(k, tau);
        let (m13, m23) = (jr.m13, jr.m23);
        Matrix3::new(
            h,
            -hw,
            -(h * m13 - hw * m23),
            hw,
            h,
            -(hw * m13 + h * m23),
            T::zero(),
            T::zero(),
            T::one(),
        )
    }
}

impl<T: Real> core::ops::Mul for Se2<T> {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        self.compose(&rhs)
    }
}

impl<T: Real> LieGroup<T> for Se2<T> {
    const DOF: usize = 3;
    const DIM: usize = 2;
    type Tangent = Vector3<T>;
    type Jacobian = Matrix3<T>;
    type Point = Vector2<T>;
    type Matrix = Matrix3<T>;
    type ActJacobian = Matrix2x3<T>;
    type PointJacobian = Matrix2<T>;

    fn identity() -> Self {
        Self::from_parts(So2::identity(), Vector2::zeros())
    }

    fn exp(tau: &Vector3<T>) -> Self {
        Self::exp_from(&AngleCoeffs::of_angle(tau.z), tau)
    }

    /// `ω = atan2`, and `V⁻¹ t` with `h = (ω/2)cot(ω/2)` taken from the stored `(cos ω, sin ω)`
    /// without trigonometry: `h = (ω/2)(1 + cos ω)/sin ω` for `cos ω ≥ 0` and the equal
    /// `(ω/2) sin ω/(1 − cos ω)` otherwise, so neither form cancels.
    fn log(&self) -> Vector3<T> {
        let (c, s) = (self.rotation.cos(), self.rotation.sin());
        let w = self.rotation.angle();
        let w2 = w * w;
        let half_w = T::lit(0.5) * w;
        let h = if w2 < T::lit(Cutoff::<T>::HALF_COT) {
            poly(w2, [T::lit(1.0), T::lit(-1.0 / 12.0), T::lit(-1.0 / 720.0)])
        } else if c >= T::zero() {
            half_w * (T::one() + c) / s
        } else {
            half_w * s / (T::one() - c)
        };
        let t = &self.translation;
        Vector3::new(h * t.x + half_w * t.y, -half_w * t.x + h * t.y, w)
    }

    fn hat(tau: &Vector3<T>) -> Matrix3<T> {
        let z = T::zero();
        Matrix3::new(z, -tau.z, tau.x, tau.z, z, tau.y, z, z, z)
    }

    fn vee(m: &Matrix3<T>) -> Vector3<T> {
        Vector3::new(m.m13, m.m23, m.m21)
    }

    /// `(R_a R_b, R_a t_b + t_a)` (the paper, §3).
    fn compose(&self, b: &Self) -> Self {
        Self {
            rotation: self.rotation.compose(&b.rotation),
            translation: self.rotation.act(&b.translation) + self.translation,
        }
    }

    /// `(R⁻¹, −R⁻¹ t)`.
    fn inverse(&self) -> Self {
        let r_inv = self.rotation.inverse();
        Self {
            rotation: r_inv,
            translation: -r_inv.act(&self.translation),
        }
    }

    fn act(&self, p: &Vector2<T>) -> Vector2<T> {
        self.rotation.act(p) + self.translation
    }

    fn adjoint(&self) -> Matrix3<T> {
        let (c, s) = (self.rotation.cos(), self.rotation.sin());
        let t = &self.translation;
        Matrix3::new(c, -s, t.y, s, c, -t.x, T::zero(), T::zero(), T::one())
    }

    fn right_jacobian(tau: &Vector3<T>) -> Matrix3<T> {
        Self::jr_from(&AngleCoeffs::of_angle(tau.z), tau)
    }

    fn right_jacobian_inv(tau: &Vector3<T>) -> Matrix3<T> {
        Self::jr_inv_from(&AngleCoeffs::of_angle(tau.z), tau)
    }

    fn matrix(&self) -> Matrix3<T> {
        let (c, s) = (self.rotation.cos(), self.rotation.sin());
        let t = &self.translation;
        Matrix3::new(c, -s, t.x, s, c, t.y, T::zero(), T::zero(), T::one())
    }

    fn normalize(&self) -> Self {
        Self::from_parts(self.rotation.normalize(), self.translation)
    }

    /// Accepts `[[R, t], [0, 1]]` with `Σ|bottom row − (0, 0, 1)| ≤` [`ORTHOGONALITY_TOLERANCE`],
    /// a finite `t`, and `R` accepted by [`So2`]'s `try_from_matrix`.
    fn try_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        let t = Vector2::new(m.m13, m.m23);
        let bottom = m.m31.abs() + m.m32.abs() + (m.m33 - T::one()).abs();
        // Written so that NaN (which compares false) is rejected too.
        if !(bottom <= T::lit(ORTHOGONALITY_TOLERANCE) && all_finite(t.as_slice())) {
            return None;
        }
        let r = So2::try_from_matrix(&Matrix2::new(m.m11, m.m12, m.m21, m.m22))?;
        Some(Self::from_parts(r, t))
    }

    fn is_finite(&self) -> bool {
        let t = &self.translation;
        all_finite(&[self.rotation.cos(), self.rotation.sin(), t.x, t.y])
    }

    fn exp_jac(tau: &Vector3<T>) -> (Self, Matrix3<T>) {
        let k = AngleCoeffs::of_angle(tau.z);
        (Self::exp_from(&k, tau), Self::jr_from(&k, tau))
    }

    /// `(R p + t, [R | R G p], R)`, `G = [0 −1; 1 0]`.
    fn act_jac(&self, p: &Vector2<T>) -> (Vector2<T>, Matrix2x3<T>, Matrix2<T>) {
        let r = self.rotation.rotation_matrix();
        let d = r * Vector2::new(-p.y, p.x);
        let j = Matrix2x3::new(r.m11, r.m12, d.x, r.m21, r.m22, d.y);
        (r * p + self.translation, j, r)
    }
}

//! SE(2), planar rigid motions `T = (R, t)`, the seed's motivating example (§3).
//!
//! Tangent `τ = [v_x, v_y, ω]`, the seed's 2-D twist; generators give (seed §3)
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
//! * `act_jac(p) = (R p + t, [R | R G p], R)` with `G = [0 −1; 1 0]` (seed Theorem 5.1).

use super::so2::So2;
use super::trig::{half_cot, poly, AngleCoeffs, Cutoff};
use super::{all_finite, eye, negate, LieGroup, Real, ORTHOGONALITY_TOLERANCE};
use nalgebra::{Matrix2, Matrix2x3, Matrix3, Vector2, Vector3};

/// A planar rigid motion `T = (R, t) ∈ SE(2)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se2<T: Real> {
    rotation: So2<T>,
    translation: Vector2<T>,
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

    #[cfg_attr(estimator_compact, inline(never))]
    fn exp_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Self {
        let w = tau.z;
        let wb = w * k.b;
        // (cos ω, sin ω) from the half-angle kernel: unit to rounding, NaN in gives NaN out.
        let rotation = So2::from_unit(k.cos(), k.a * w);
        Self {
            rotation,
            translation: Vector2::new(k.a * tau.x - wb * tau.y, wb * tau.x + k.a * tau.y),
        }
    }

    #[cfg_attr(estimator_compact, inline(never))]
    fn jr_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Matrix3<T> {
        let (vx, vy, w) = (tau.x, tau.y, tau.z);
        let wb = w * k.b;
        let wc = w * k.c;
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

    fn jr_inv_from(k: &AngleCoeffs<T>, tau: &Vector3<T>) -> Matrix3<T> {
        let w = tau.z;
        let h = half_cot(k.theta_sq, k.theta, k.sin_half, k.cos_half);
        let hw = T::lit(0.5) * w;
        // J_r's last column `m` (the same expressions), read from jr_from.
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
        Self::exp_from(&AngleCoeffs::from_theta_sq(tau.z * tau.z), tau)
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

    #[cfg_attr(estimator_compact, inline(never))]
    fn compose(&self, b: &Self) -> Self {
        Self {
            rotation: self.rotation.compose(&b.rotation),
            translation: self.rotation.act(&b.translation) + self.translation,
        }
    }

    #[cfg_attr(estimator_compact, inline(never))]
    fn inverse(&self) -> Self {
        // `−(R⁻¹ t)` entry by entry: So2::act of `(cos, −sin)`, each entry negated (no vector
        // temporary and no `Neg` pass).
        let r_inv = self.rotation.inverse();
        let (c, ns) = (r_inv.cos(), r_inv.sin());
        let t = &self.translation;
        Self {
            rotation: r_inv,
            translation: Vector2::new(-(c * t.x - ns * t.y), -(ns * t.x + c * t.y)),
        }
    }

    fn act(&self, p: &Vector2<T>) -> Vector2<T> {
        self.rotation.act(p) + self.translation
    }

    #[cfg_attr(estimator_compact, inline(never))]
    fn adjoint(&self) -> Matrix3<T> {
        let (c, s) = (self.rotation.cos(), self.rotation.sin());
        let t = &self.translation;
        Matrix3::new(c, -s, t.y, s, c, -t.x, T::zero(), T::zero(), T::one())
    }

    fn right_jacobian(tau: &Vector3<T>) -> Matrix3<T> {
        Self::jr_from(&AngleCoeffs::from_theta_sq(tau.z * tau.z), tau)
    }

    fn right_jacobian_inv(tau: &Vector3<T>) -> Matrix3<T> {
        Self::jr_inv_from(&AngleCoeffs::from_theta_sq(tau.z * tau.z), tau)
    }

    /// `J_r(−τ)`, `−τ` entry by entry.
    fn left_jacobian(tau: &Vector3<T>) -> Matrix3<T> {
        Self::right_jacobian(&Vector3::new(-tau.x, -tau.y, -tau.z))
    }

    /// `J_r⁻¹(−τ)`, `−τ` entry by entry. Out of line when built for size (`rminus_jac` calls it
    /// too).
    #[cfg_attr(estimator_compact, inline(never))]
    fn left_jacobian_inv(tau: &Vector3<T>) -> Matrix3<T> {
        Self::right_jacobian_inv(&Vector3::new(-tau.x, -tau.y, -tau.z))
    }

    fn matrix(&self) -> Matrix3<T> {
        let (c, s) = (self.rotation.cos(), self.rotation.sin());
        let t = &self.translation;
        Matrix3::new(c, -s, t.x, s, c, t.y, T::zero(), T::zero(), T::one())
    }

    fn normalize(&self) -> Self {
        Self::from_parts(self.rotation.normalize(), self.translation)
    }

    fn try_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        let tol = T::lit(ORTHOGONALITY_TOLERANCE);
        // `x·0` is `±0` for finite `x` and NaN otherwise (see SE(3)'s `try_from_matrix`): the sum
        // is NaN exactly when `t` is not finite.
        let z = T::zero();
        let finite_t = m.m13 * z + m.m23 * z;
        let bottom = m.m31.abs() + m.m32.abs() + (m.m33 - T::one()).abs() + finite_t;
        // Written so that NaN (which compares false) is rejected too.
        let bottom_ok = bottom <= tol;
        if !bottom_ok {
            return None;
        }
        // The rotation block entry by entry (`fixed_view(..).into_owned()` is a copy loop).
        let r = So2::try_from_matrix(&Matrix2::new(m.m11, m.m12, m.m21, m.m22))?;
        Some(Self::from_parts(r, Vector2::new(m.m13, m.m23)))
    }

    fn is_finite(&self) -> bool {
        let t = &self.translation;
        all_finite(&[self.rotation.cos(), self.rotation.sin(), t.x, t.y])
    }

    fn exp_jac(tau: &Vector3<T>) -> (Self, Matrix3<T>) {
        let k = AngleCoeffs::from_theta_sq(tau.z * tau.z);
        (Self::exp_from(&k, tau), Self::jr_from(&k, tau))
    }

    /// `(a·b, Ad_{b⁻¹}, I)`, the identity from `eye` (not `Ad_e` built from an identity motion).
    fn compose_jac(&self, b: &Self) -> (Self, Matrix3<T>, Matrix3<T>) {
        (self.compose(b), b.inverse().adjoint(), eye())
    }

    /// `(a⁻¹, −Ad_a)`, negated in place (`negate`).
    fn inverse_jac(&self) -> (Self, Matrix3<T>) {
        // Negated where it is returned (no copy of the Jacobian after the negation).
        let mut out = (self.inverse(), self.adjoint());
        negate(&mut out.1);
        out
    }

    /// `(z = a⁻¹·b, −Ad_{z⁻¹}, I)`, negated in place (`negate`).
    fn between_jac(&self, b: &Self) -> (Self, Matrix3<T>, Matrix3<T>) {
        // `z` written where it is returned and read there (no copy of it into the tuple).
        let mut out = (self.between(b), eye(), eye());
        out.1 = out.0.inverse().adjoint();
        negate(&mut out.1);
        out
    }

    /// `(τ = a ⊖ b, J_r⁻¹(τ), −J_l⁻¹(τ))`, the last negated in place (`negate`).
    fn rminus_jac(&self, b: &Self) -> (Vector3<T>, Matrix3<T>, Matrix3<T>) {
        let tau = self.rminus(b);
        let mut jl = Self::left_jacobian_inv(&tau);
        negate(&mut jl);
        (tau, Self::right_jacobian_inv(&tau), jl)
    }

    /// `(R p + t, [R | R G p], R)`, `G = [0 −1; 1 0]`.
    fn act_jac(&self, p: &Vector2<T>) -> (Vector2<T>, Matrix2x3<T>, Matrix2<T>) {
        let r = self.rotation.rotation_matrix();
        let d = r * Vector2::new(-p.y, p.x);
        let j = Matrix2x3::new(r.m11, r.m12, d.x, r.m21, r.m22, d.y);
        (r * p + self.translation, j, r)
    }
}

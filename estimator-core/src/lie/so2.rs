//! SO(2), planar rotations, stored as a unit complex number `(cos θ, sin θ)`.
//!
//! Tangent `θ ∈ R¹`; one generator `G¹ = [0 −1; 1 0]`, so `θ^ = θG¹`.
//! `exp(θ) = (cos θ, sin θ)`, `log = atan2(sin θ, cos θ) ∈ (−π, π]`. The group is commutative:
//! `Ad = J_r = J_l = 1`. `act_jac(p) = (R p, R G¹ p, R)`: Theorem 5.1 of *Lie Groups and Smooth
//! Manifolds for Robotic State Estimation*, `F = R [H(p) | I]` with `H(p) = G¹p`.

use super::{near_rotation, LieGroup, Real};
use crate::kernels::{all_finite, larger, positive_finite};
use nalgebra::{Matrix1, Matrix2, Matrix2x1, Vector1, Vector2};

/// A planar rotation `R ∈ SO(2)`.
///
/// ```
/// use estimator_core::lie::{LieGroup, So2};
/// use nalgebra::{Vector1, Vector2};
///
/// let r = So2::from_angle(0.5_f64);
/// let p = r.act(&Vector2::new(1.0, 0.0));
/// assert!((p - Vector2::new(0.5_f64.cos(), 0.5_f64.sin())).amax() < 1e-15);
/// // exp and log are the angle; ⊕ adds angles.
/// assert!((r.rplus(&Vector1::new(0.25)).angle() - 0.75).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct So2<T: Real> {
    re: T,
    im: T,
}

impl<T: Real> So2<T> {
    /// From an angle in radians.
    #[must_use]
    pub fn from_angle(theta: T) -> Self {
        let (s, c) = theta.sincos();
        Self { re: c, im: s }
    }

    /// From `(cos θ, sin θ)` of any non-zero finite norm (normalized); `None` otherwise. The
    /// pair is first divided by its larger magnitude `m`, so that `re² + im²` can neither
    /// overflow nor underflow (`(1e200, 0)` and `(1e-200, 0)` in `f64` are both the identity).
    #[must_use]
    pub fn from_cos_sin(re: T, im: T) -> Option<Self> {
        let m = larger(re.abs(), im.abs());
        if !(positive_finite(m) && all_finite(&[re, im])) {
            return None;
        }
        let (x, y) = (re / m, im / m);
        // 1 ≤ x² + y² ≤ 2.
        let inv = T::one() / (x * x + y * y).sqrt_rn();
        Some(Self {
            re: x * inv,
            im: y * inv,
        })
    }

    /// From `(cos θ, sin θ)` already of unit norm (not checked).
    pub(crate) fn from_unit(re: T, im: T) -> Self {
        Self { re, im }
    }

    /// The same rotation in another precision, stored numbers converted as they are.
    #[must_use]
    pub fn cast<U: Real>(&self) -> So2<U> {
        So2 {
            re: U::lit(self.re.to_f64()),
            im: U::lit(self.im.to_f64()),
        }
    }

    /// The angle in `(−π, π]`.
    #[must_use]
    pub fn angle(&self) -> T {
        self.im.arctan2(self.re)
    }

    /// `cos θ`.
    #[must_use]
    pub fn cos(&self) -> T {
        self.re
    }

    /// `sin θ`.
    #[must_use]
    pub fn sin(&self) -> T {
        self.im
    }

    /// `R = [cos −sin; sin cos]`.
    #[must_use]
    pub fn rotation_matrix(&self) -> Matrix2<T> {
        Matrix2::new(self.re, -self.im, self.im, self.re)
    }
}

impl<T: Real> core::ops::Mul for So2<T> {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        self.compose(&rhs)
    }
}

impl<T: Real> LieGroup<T> for So2<T> {
    const DOF: usize = 1;
    const DIM: usize = 2;
    type Tangent = Vector1<T>;
    type Jacobian = Matrix1<T>;
    type Point = Vector2<T>;
    type Matrix = Matrix2<T>;
    type ActJacobian = Matrix2x1<T>;
    type PointJacobian = Matrix2<T>;

    fn identity() -> Self {
        Self {
            re: T::one(),
            im: T::zero(),
        }
    }

    fn exp(tau: &Vector1<T>) -> Self {
        Self::from_angle(tau.x)
    }

    fn log(&self) -> Vector1<T> {
        Vector1::new(self.angle())
    }

    fn hat(tau: &Vector1<T>) -> Matrix2<T> {
        Matrix2::new(T::zero(), -tau.x, tau.x, T::zero())
    }

    fn vee(m: &Matrix2<T>) -> Vector1<T> {
        Vector1::new(m.m21)
    }

    fn compose(&self, b: &Self) -> Self {
        Self {
            re: self.re * b.re - self.im * b.im,
            im: self.re * b.im + self.im * b.re,
        }
    }

    fn inverse(&self) -> Self {
        Self {
            re: self.re,
            im: -self.im,
        }
    }

    fn act(&self, p: &Vector2<T>) -> Vector2<T> {
        Vector2::new(self.re * p.x - self.im * p.y, self.im * p.x + self.re * p.y)
    }

    fn adjoint(&self) -> Matrix1<T> {
        Matrix1::identity()
    }

    fn right_jacobian(_tau: &Vector1<T>) -> Matrix1<T> {
        Matrix1::identity()
    }

    fn right_jacobian_inv(_tau: &Vector1<T>) -> Matrix1<T> {
        Matrix1::identity()
    }

    fn matrix(&self) -> Matrix2<T> {
        self.rotation_matrix()
    }

    fn normalize(&self) -> Self {
        Self::from_cos_sin(self.re, self.im).unwrap_or(*self)
    }

    /// The nearest rotation of a 2×2 matrix is `((m₁₁ + m₂₂)/2, (m₂₁ − m₁₂)/2)` normalized.
    fn try_from_matrix(m: &Matrix2<T>) -> Option<Self> {
        if !near_rotation(m) {
            return None;
        }
        Self::from_cos_sin(m.m11 + m.m22, m.m21 - m.m12)
    }

    fn is_finite(&self) -> bool {
        all_finite(&[self.re, self.im])
    }

    /// `(R p, R G¹ p = R [−p_y; p_x], R)`.
    fn act_jac(&self, p: &Vector2<T>) -> (Vector2<T>, Matrix2x1<T>, Matrix2<T>) {
        let r = self.rotation_matrix();
        let d = r * Vector2::new(-p.y, p.x);
        (r * p, Matrix2x1::new(d.x, d.y), r)
    }
}

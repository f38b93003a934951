//! SO(3), 3-D rotations, stored as a unit quaternion.
//!
//! Tangent `ω ∈ R³` (rotation vector, angle `θ = ‖ω‖` about `ω/θ`). Generators (Example 5.2 of
//! *Lie Groups and Smooth Manifolds for Robotic State Estimation*, "the paper" below), and the hat
//! of its eq. 3.2:
//!
//! ```text
//! G¹ = [0 0 0; 0 0 −1; 0 1 0],  G² = [0 0 1; 0 0 0; −1 0 0],  G³ = [0 −1 0; 1 0 0; 0 0 0]
//! ω^ = ω₁G¹ + ω₂G² + ω₃G³ = [ω]×
//! ```
//!
//! * `exp(ω)`: `q = [cos(θ/2), (sin(θ/2)/θ)·ω]`; as a matrix `R = I + a[ω]× + b[ω]×²`.
//! * `log(q)`: with `q ← −q` when `w < 0`, `θ = 2·atan2(‖v‖, w)`, `ω = (θ/‖v‖)·v`.
//! * `J_r(ω) = I − b[ω]× + c[ω]×²`, `J_r⁻¹(ω) = I + ½[ω]× + d[ω]×²`, `J_l(ω) = J_r(−ω) = J_r(ω)ᵀ`.
//! * `Ad_R = R`; `act_jac(p) = (R p, −R[p]×, R)`: the paper's Theorem 5.1, `F = R [H(p) | I]`,
//!   with `H(p) = [−p]×` (Example 5.2).
//!
//! with `a, b, c, d` the coefficients of the crate's trigonometric kernel (`sin θ/θ`,
//! `(1 − cos θ)/θ²`, `(θ − sin θ)/θ³`, `1/θ² − (1 + cos θ)/(2θ sin θ)`).

use super::trig::{half_sinc, poly, AngleCoeffs, Cutoff};
use super::{near_rotation, skew, skew_poly, LieGroup, Real};
use crate::kernels::mat3::{mul_skew, mul_vec};
use crate::kernels::{all_finite, positive_finite};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3, Vector4};

/// A 3-D rotation `R ∈ SO(3)`, stored as a unit Hamilton quaternion.
///
/// ```
/// use estimator_core::lie::{LieGroup, So3};
/// use nalgebra::{UnitQuaternion, Vector3};
///
/// // A quarter turn about z: exp of the rotation vector ω = (0, 0, π/2).
/// let w = Vector3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2);
/// let r = So3::exp(&w);
/// assert!((r.act(&Vector3::x()) - Vector3::y()).amax() < 1e-15);
/// assert!((r.log() - w).amax() < 1e-15);
///
/// // The same rotation as nalgebra's quaternion, and R·Rᵀ = I.
/// let q = UnitQuaternion::from_scaled_axis(w);
/// assert!((r.quaternion().coords - q.coords).amax() < 1e-15);
/// assert!((r.matrix() * r.inverse().matrix() - nalgebra::Matrix3::identity()).amax() < 1e-15);
///
/// // Right perturbation a ⊕ δ = a·exp(δ^), and its Jacobians.
/// let d = Vector3::new(1e-3, -2e-3, 0.5e-3);
/// let (b, j_a, j_d) = r.rplus_jac(&d);
/// assert!((b.rminus(&r) - d).amax() < 1e-15);
/// assert!((j_a - So3::exp(&d).inverse().matrix()).amax() < 1e-15); // Ad_{exp(δ)}⁻¹
/// assert!((j_d - So3::right_jacobian(&d)).amax() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct So3<T: Real> {
    q: UnitQuaternion<T>,
}

impl<T: Real> So3<T> {
    /// From a quaternion of any non-zero finite norm (it is normalized; `w < 0` is fine).
    /// `None` for a zero or non-finite quaternion.
    ///
    /// The quaternion is first divided by its largest component, so that its squared norm lies
    /// in `[1, 4]`: components up to the largest finite value and down to the smallest
    /// subnormal are accepted (their squares alone would overflow or underflow).
    #[must_use]
    pub fn from_quaternion(q: &Quaternion<T>) -> Option<Self> {
        if !all_finite(q.coords.as_slice()) {
            return None;
        }
        let largest = q.coords.iter().fold(T::zero(), |m, c| m.max(c.abs()));
        if !positive_finite(largest) {
            return None;
        }
        let scaled = q.coords / largest;
        let n = scaled.norm_squared().sqrt_rn();
        Some(Self {
            q: UnitQuaternion::new_unchecked(Quaternion::from(scaled / n)),
        })
    }

    /// From the components `w, x, y, z` of a Hamilton quaternion (see [`So3::from_quaternion`]).
    #[must_use]
    pub fn from_wxyz(w: T, x: T, y: T, z: T) -> Option<Self> {
        Self::from_quaternion(&Quaternion::new(w, x, y, z))
    }

    /// From a nalgebra unit quaternion, trusted to be unit (use [`LieGroup::normalize`] if not).
    #[must_use]
    pub fn from_unit_quaternion(q: UnitQuaternion<T>) -> Self {
        Self { q }
    }

    /// The unit quaternion (Hamilton; its sign is whatever the computation produced).
    #[must_use]
    pub fn quaternion(&self) -> UnitQuaternion<T> {
        self.q
    }

    /// The same rotation in another precision, stored numbers converted as they are (no
    /// re-normalization).
    #[must_use]
    pub fn cast<U: Real>(&self) -> So3<U> {
        let q = self.q.quaternion();
        let c = |x: T| U::lit(x.to_f64());
        So3 {
            q: UnitQuaternion::new_unchecked(Quaternion::new(c(q.w), c(q.i), c(q.j), c(q.k))),
        }
    }

    /// From a rotation matrix: the same as [`LieGroup::try_from_matrix`].
    #[must_use]
    pub fn from_rotation_matrix(m: &Matrix3<T>) -> Option<Self> {
        Self::try_from_matrix(m)
    }

    /// Shepperd's method: the largest of `4w² = 1 + tr R`, `4x² = 1 + 2R₁₁ − tr R`, … picks the
    /// component computed by a square root, `q_i = s/4` with `s = 2√(4q_i²)`; the others come
    /// from the off-diagonal combinations `4q_iq_j` (`R₃₂ − R₂₃ = 4wx`, `R₁₂ + R₂₁ = 4xy`, …)
    /// divided by `s`. Dividing by the largest component keeps full precision near `θ = π`. The
    /// result is normalized.
    fn quaternion_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        /// Marks the component computed by the square root.
        const ROOT: u8 = 6;
        let one = T::one();
        let trace = m.m11 + m.m22 + m.m33;
        // 4·q_i·q_j for the pairs (w,x) (w,y) (w,z) (x,y) (x,z) (y,z).
        let pairs = [
            m.m32 - m.m23,
            m.m13 - m.m31,
            m.m21 - m.m12,
            m.m12 + m.m21,
            m.m13 + m.m31,
            m.m23 + m.m32,
        ];
        // `from[i]`: the entry of `pairs` that gives component `i` of nalgebra's storage order
        // `[x, y, z, w]`, or `ROOT`.
        let (radicand, from) = if trace > T::zero() {
            (trace + one, [0, 1, 2, ROOT])
        } else if m.m11 > m.m22 && m.m11 > m.m33 {
            (one + m.m11 - m.m22 - m.m33, [ROOT, 3, 4, 0])
        } else if m.m22 > m.m33 {
            (one + m.m22 - m.m11 - m.m33, [3, ROOT, 5, 1])
        } else {
            (one + m.m33 - m.m11 - m.m22, [4, 5, ROOT, 2])
        };
        let s = radicand.sqrt_rn() * T::lit(2.0);
        let q = from.map(|j| match pairs.get(usize::from(j)) {
            Some(p) => *p / s,
            None => T::lit(0.25) * s,
        });
        Self::from_quaternion(&Quaternion::from(Vector4::from(q)))
    }

    /// `log` plus the half-angle sine and cosine it found, to build the kernel without
    /// trigonometry: `(ω, θ, sin(θ/2), cos(θ/2))`.
    ///
    /// With `±q = [w, v]` taken with `w ≥ 0` (the same rotation), `sin(θ/2) = ‖v‖`,
    /// `cos(θ/2) = w`, `θ = 2·atan2(‖v‖, w)` and `ω = (θ/‖v‖)·v`.
    fn log_parts(&self) -> (Vector3<T>, T, T, T) {
        let q = self.q.quaternion();
        let (w, x, y, z) = if q.w < T::zero() {
            (-q.w, -q.i, -q.j, -q.k)
        } else {
            (q.w, q.i, q.j, q.k)
        };
        let n2 = x * x + y * y + z * z;
        let n = n2.sqrt_rn();
        // θ/n = 2·atan2(n, w)/n; below the cutoff (n/w small) the series of 2·atan(r)/(r·w),
        // r = n/w: (2/w)(1 − r²/3 + r⁴/5).
        let scale = if n2 < T::lit(Cutoff::<T>::ATAN_RATIO) * w * w {
            let r2 = n2 / (w * w);
            T::lit(2.0) / w * poly(r2, [T::lit(1.0), T::lit(-1.0 / 3.0), T::lit(1.0 / 5.0)])
        } else {
            T::lit(2.0) * n.arctan2(w) / n
        };
        (
            Vector3::new(x * scale, y * scale, z * scale),
            scale * n,
            n,
            w,
        )
    }

    /// `J_r(ω) = I − b[ω]× + c[ω]×²` from the kernel of `ω`.
    fn jr_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Matrix3<T> {
        skew_poly(T::one(), -k.b, k.c, w)
    }

    /// `J_r⁻¹(ω) = I + ½[ω]× + d[ω]×²` from the kernel of `ω`.
    fn jr_inv_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Matrix3<T> {
        skew_poly(T::one(), T::lit(0.5), k.d(), w)
    }

    /// The unit quaternion `exp(ω) = [cos(θ/2), (sin(θ/2)/θ)·ω]` from the kernel of `ω`.
    pub(crate) fn exp_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Self {
        Self {
            q: UnitQuaternion::new_unchecked(Quaternion::from_parts(k.cos_half, w * k.half_sinc)),
        }
    }

    /// `log` and the kernel of its angle (SE(3)'s log needs `J_l⁻¹` of the same angle).
    pub(crate) fn log_with_coeffs(&self) -> (Vector3<T>, AngleCoeffs<T>) {
        let (w, theta, sin_half, cos_half) = self.log_parts();
        let k = AngleCoeffs::from_half_angle(theta * theta, theta, sin_half, cos_half);
        (w, k)
    }

    /// Re-projects a quaternion already near unit norm without a square root: one Newton step
    /// for `1/‖q‖`, `q ← q·(3 − ‖q‖²)/2`. A norm error `‖q‖² = 1 + ε` becomes `−¾ε² + O(ε³)`,
    /// so after a product of unit quaternions (`ε` of a few ulps) the result is unit to
    /// rounding. For `|ε|` above about 0.1 use [`LieGroup::normalize`]. It is the cheap choice
    /// for a filter step at 1 kHz (no square root, which is software on a Cortex-M4F).
    #[must_use]
    pub fn renormalize(&self) -> Self {
        let q = self.q.quaternion();
        let scale = (T::lit(3.0) - q.coords.norm_squared()) * T::lit(0.5);
        Self {
            q: UnitQuaternion::new_unchecked(q * scale),
        }
    }

    /// Rotation matrix `R`.
    #[must_use]
    pub fn rotation_matrix(&self) -> Matrix3<T> {
        *self.q.to_rotation_matrix().matrix()
    }
}

impl<T: Real> From<UnitQuaternion<T>> for So3<T> {
    fn from(q: UnitQuaternion<T>) -> Self {
        Self::from_unit_quaternion(q)
    }
}

impl<T: Real> core::ops::Mul for So3<T> {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        self.compose(&rhs)
    }
}

impl<T: Real> LieGroup<T> for So3<T> {
    const DOF: usize = 3;
    const DIM: usize = 3;
    type Tangent = Vector3<T>;
    type Jacobian = Matrix3<T>;
    type Point = Vector3<T>;
    type Matrix = Matrix3<T>;
    type ActJacobian = Matrix3<T>;
    type PointJacobian = Matrix3<T>;

    fn identity() -> Self {
        Self {
            q: UnitQuaternion::identity(),
        }
    }

    /// `q = [cos(θ/2), (sin(θ/2)/θ)·ω]`, with only the coefficient it needs (not the whole
    /// kernel).
    fn exp(w: &Vector3<T>) -> Self {
        let theta_sq = w.norm_squared();
        if !theta_sq.is_finite() && all_finite(w.as_slice()) {
            return exp_huge(w);
        }
        let theta = theta_sq.sqrt_rn();
        let (s, c) = (theta * T::lit(0.5)).sincos();
        let v = w * half_sinc(theta_sq, theta, s);
        Self {
            q: UnitQuaternion::new_unchecked(Quaternion::new(c, v.x, v.y, v.z)),
        }
    }

    fn log(&self) -> Vector3<T> {
        self.log_parts().0
    }

    fn hat(w: &Vector3<T>) -> Matrix3<T> {
        skew(w)
    }

    fn vee(m: &Matrix3<T>) -> Vector3<T> {
        Vector3::new(m.m32, m.m13, m.m21)
    }

    fn compose(&self, b: &Self) -> Self {
        Self { q: self.q * b.q }
    }

    /// The conjugate `q* = [w, −v]`.
    fn inverse(&self) -> Self {
        Self {
            q: self.q.inverse(),
        }
    }

    /// `q p q*` with `q = [w, v]`: `u = 2 v × p`, `R p = p + w u + v × u`.
    fn act(&self, p: &Vector3<T>) -> Vector3<T> {
        let q = self.q.quaternion();
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        let two = T::lit(2.0);
        let ux = (y * p.z - z * p.y) * two;
        let uy = (z * p.x - x * p.z) * two;
        let uz = (x * p.y - y * p.x) * two;
        Vector3::new(
            ux * w + (y * uz - z * uy) + p.x,
            uy * w + (z * ux - x * uz) + p.y,
            uz * w + (x * uy - y * ux) + p.z,
        )
    }

    fn adjoint(&self) -> Matrix3<T> {
        self.rotation_matrix()
    }

    fn right_jacobian(w: &Vector3<T>) -> Matrix3<T> {
        let theta_sq = w.norm_squared();
        if !theta_sq.is_finite() {
            return exp_jac_huge(w).1;
        }
        Self::jr_from(&AngleCoeffs::from_theta_sq(theta_sq), w)
    }

    fn right_jacobian_inv(w: &Vector3<T>) -> Matrix3<T> {
        Self::jr_inv_from(&AngleCoeffs::of_vector(w), w)
    }

    fn matrix(&self) -> Matrix3<T> {
        self.rotation_matrix()
    }

    fn normalize(&self) -> Self {
        Self::from_quaternion(self.q.as_ref()).unwrap_or(*self)
    }

    fn try_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        if !near_rotation(m) {
            return None;
        }
        Self::quaternion_from_matrix(m)
    }

    fn is_finite(&self) -> bool {
        all_finite(self.q.coords.as_slice())
    }

    /// `exp(ω)` and `J_r(ω)` from one kernel.
    fn exp_jac(w: &Vector3<T>) -> (Self, Matrix3<T>) {
        let theta_sq = w.norm_squared();
        if !theta_sq.is_finite() {
            return exp_jac_huge(w);
        }
        let k = AngleCoeffs::from_theta_sq(theta_sq);
        (Self::exp_from(&k, w), Self::jr_from(&k, w))
    }

    /// `log(R)` and `J_r⁻¹` from the kernel the logarithm found (no trigonometric call).
    fn log_jac(&self) -> (Vector3<T>, Matrix3<T>) {
        let (w, k) = self.log_with_coeffs();
        (w, Self::jr_inv_from(&k, &w))
    }

    /// `(τ = a ⊖ b, J_r⁻¹(τ), −J_l⁻¹(τ))` from the logarithm's kernel, with
    /// `−J_l⁻¹(τ) = −J_r⁻¹(τ)ᵀ = −I + ½[τ]× − d[τ]×²`.
    fn rminus_jac(&self, b: &Self) -> (Vector3<T>, Matrix3<T>, Matrix3<T>) {
        let (tau, k) = b.between(self).log_with_coeffs();
        let d = k.d();
        (
            tau,
            skew_poly(T::one(), T::lit(0.5), d, &tau),
            skew_poly(-T::one(), T::lit(0.5), -d, &tau),
        )
    }

    /// `(R p, R[−p]×, R)`: the paper's Theorem 5.1 with `H(p) = [−p]×` (Example 5.2).
    fn act_jac(&self, p: &Vector3<T>) -> (Vector3<T>, Matrix3<T>, Matrix3<T>) {
        let r = self.rotation_matrix();
        (mul_vec(&r, p), mul_skew(&r, &-p), r)
    }
}

/// `exp(ω)` and `J_r(ω)` of a finite `ω` whose `‖ω‖²` overflows ([`AngleCoeffs::of_huge`]):
/// `[cos(θ/2), sin(θ/2)·u]` and `I − θb[u]× + θ²c[u]×²` (`θb = (1 − cos θ)/θ`,
/// `θ²c = 1 − sin θ/θ`, both finite), with `u = ω/θ`. Out of line and cold: the ordinary path
/// of every caller stays as it was.
#[cold]
#[inline(never)]
fn exp_jac_huge<T: Real>(w: &Vector3<T>) -> (So3<T>, Matrix3<T>) {
    let (k, u) = AngleCoeffs::of_huge(w);
    (
        rotation_huge(&k, &u),
        skew_poly(T::one(), -k.b_theta(), T::one() - k.a, &u),
    )
}

/// `exp(ω) = [cos(θ/2), sin(θ/2)·u]` of a finite `ω` whose `‖ω‖²` overflows (as
/// [`exp_jac_huge`], without the Jacobian).
#[cold]
#[inline(never)]
fn exp_huge<T: Real>(w: &Vector3<T>) -> So3<T> {
    let (k, u) = AngleCoeffs::of_huge(w);
    rotation_huge(&k, &u)
}

/// `[cos(θ/2), sin(θ/2)·u]` from a huge kernel and its axis.
pub(crate) fn rotation_huge<T: Real>(k: &AngleCoeffs<T>, u: &Vector3<T>) -> So3<T> {
    So3 {
        q: UnitQuaternion::new_unchecked(Quaternion::from_parts(k.cos_half, u * k.sin_half)),
    }
}

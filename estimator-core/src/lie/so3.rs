//! SO(3), 3-D rotations, stored as a unit quaternion.
//!
//! Tangent `ω ∈ R³` (rotation vector, angle `θ = ‖ω‖` about `ω/θ`). Generators (seed Example 5.2):
//!
//! ```text
//! G¹ = [0 0 0; 0 0 −1; 0 1 0],  G² = [0 0 1; 0 0 0; −1 0 0],  G³ = [0 −1 0; 1 0 0; 0 0 0]
//! ω^ = ω₁G¹ + ω₂G² + ω₃G³ = [ω]×
//! ```
//!
//! * `exp(ω)`: `q = [cos(θ/2), (sin(θ/2)/θ)·ω]`; as a matrix `R = I + a[ω]× + b[ω]×²`.
//! * `log(q)`: with `q ← −q` when `w < 0`, `θ = 2·atan2(‖v‖, w)`, `ω = (θ/‖v‖)·v`.
//! * `J_r(ω) = I − b[ω]× + c[ω]×²`, `J_r⁻¹(ω) = I + ½[ω]× + d[ω]×²`, `J_l(ω) = J_r(ω)ᵀ`.
//! * `Ad_R = R`; `act_jac(p) = (R p, −R[p]×, R)` (seed Theorem 5.1 with `H(p) = [−p]×`,
//!   Example 5.2).
//!
//! with `a, b, c, d` the coefficients of the crate's trigonometric kernel (`sin θ/θ`,
//! `(1 − cos θ)/θ²`, `(θ − sin θ)/θ³`, `1/θ² − (1 + cos θ)/(2θ sin θ)`).

use super::trig::{poly, AngleCoeffs, Cutoff};
use super::{
    all_finite, eye, mul_skew_in_place, negate, orthogonality_error, positive_finite, skew,
    skew_poly, LieGroup, Real, ORTHOGONALITY_TOLERANCE,
};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3, Vector4};

/// A 3-D rotation `R ∈ SO(3)`, stored as a unit Hamilton quaternion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct So3<T: Real> {
    q: UnitQuaternion<T>,
}

impl<T: Real> So3<T> {
    /// From a quaternion of any non-zero finite norm (it is normalized; `w < 0` is fine).
    /// `None` for a zero or non-finite quaternion.
    #[must_use]
    pub fn from_quaternion(q: &Quaternion<T>) -> Option<Self> {
        let n2 = q.coords.norm_squared();
        if !positive_finite(n2) {
            return None;
        }
        Some(Self::scaled(q, T::one() / n2.sqrt_rn()))
    }

    /// `s·q`, trusted to be unit, written per component (no 4-vector temporary at opt-level "s").
    #[inline]
    fn scaled(q: &Quaternion<T>, s: T) -> Self {
        Self {
            q: UnitQuaternion::new_unchecked(Quaternion::new(q.w * s, q.i * s, q.j * s, q.k * s)),
        }
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

    /// Shepperd's method: the largest of `w², x², y², z²` (from the trace and the diagonal) sets
    /// which component is computed by a square root, the others by division, so no branch loses
    /// precision near `θ = π`. The result is normalized.
    ///
    /// One path for the four cases: the branch picks the radicand `4q_i²` and, per component, which
    /// of the six off-diagonal combinations `4q_iq_j` it divides (the component `i` itself is
    /// `s/4`); the same operations as four written-out branches.
    fn quaternion_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        /// Marks the component computed by the square root.
        const SELF: u8 = 6;
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
        // `from` lists the components in nalgebra's storage order `[x, y, z, w]`, one byte each
        // of a little-endian word (one constant per case instead of four byte stores).
        let (radicand, from): (T, u32) = if trace > T::zero() {
            (trace + one, u32::from_le_bytes([0, 1, 2, SELF]))
        } else if m.m11 > m.m22 && m.m11 > m.m33 {
            (
                one + m.m11 - m.m22 - m.m33,
                u32::from_le_bytes([SELF, 3, 4, 0]),
            )
        } else if m.m22 > m.m33 {
            (
                one + m.m22 - m.m11 - m.m33,
                u32::from_le_bytes([3, SELF, 5, 1]),
            )
        } else {
            (
                one + m.m33 - m.m11 - m.m22,
                u32::from_le_bytes([4, 5, SELF, 2]),
            )
        };
        let from = from.to_le_bytes();
        let s = radicand.sqrt_rn() * T::lit(2.0);
        let q = from.map(|j| match pairs.get(usize::from(j)) {
            Some(p) => *p / s,
            None => T::lit(0.25) * s,
        });
        Self::from_quaternion(&Quaternion::from(Vector4::from(q)))
    }

    /// `log` plus the half-angle sine and cosine it found, to build the kernel without trigonometry.
    ///
    /// The principal representative `±q` with `w ≥ 0`, component by component (no 3-vector
    /// temporaries at opt-level "s").
    fn log_parts(&self) -> (Vector3<T>, T, T, T) {
        let q = self.q.quaternion();
        let (w, x, y, z) = if q.w < T::zero() {
            (-q.w, -q.i, -q.j, -q.k)
        } else {
            (q.w, q.i, q.j, q.k)
        };
        let n2 = x * x + y * y + z * z;
        let n = n2.sqrt_rn();
        // θ = 2·atan2(n, w); below the cutoff (n/w small) use 2·atan(r)/r's series, r = n/w.
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

    /// The SO(3) right Jacobian from precomputed coefficients: `I − b[ω]× + c[ω]×²`.
    #[inline]
    pub(crate) fn jr_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Matrix3<T> {
        skew_poly(T::one(), -k.b, k.c, w)
    }

    /// `J_r⁻¹ = I + ½[ω]× + d[ω]×²`.
    #[inline]
    pub(crate) fn jr_inv_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Matrix3<T> {
        skew_poly(T::one(), T::lit(0.5), k.d(), w)
    }

    /// `J_r(σω) = I − σb[ω]× + c[ω]×²` for `σ = ±1` (`σ = −1`: `J_l(ω)`), with the kernel of `ω`
    /// (`−b·σ` is `∓b` exactly). Out of line when built for size: one copy for the right and
    /// left Jacobians.
    #[cfg_attr(not(estimator_compact), inline(always))]
    fn jr_at(w: &Vector3<T>, sigma: T) -> Matrix3<T> {
        let k = AngleCoeffs::of_vector(w);
        skew_poly(T::one(), -k.b * sigma, k.c, w)
    }

    /// `J_r⁻¹(σω) = I + ½σ[ω]× + d[ω]×²` for `σ = ±1` (`½·σ` is `±½` exactly), out of line
    /// when built for size as `jr_at`.
    #[cfg_attr(not(estimator_compact), inline(always))]
    #[cfg_attr(estimator_compact, inline(never))]
    fn jr_inv_at(w: &Vector3<T>, sigma: T) -> Matrix3<T> {
        let k = AngleCoeffs::of_vector(w);
        skew_poly(T::one(), T::lit(0.5) * sigma, k.d(), w)
    }

    /// The unit quaternion `exp(ω)` from precomputed coefficients, `v = h ω` per component (no
    /// 3-vector temporary at opt-level "s").
    #[inline]
    pub(crate) fn exp_from(k: &AngleCoeffs<T>, w: &Vector3<T>) -> Self {
        let h = k.half_sinc;
        Self {
            q: UnitQuaternion::new_unchecked(Quaternion::new(
                k.cos_half,
                w.x * h,
                w.y * h,
                w.z * h,
            )),
        }
    }

    /// `log` and its kernel (for SE(3)'s log, which needs `J_l⁻¹` of the same angle). Out of
    /// line under `estimator_compact` (one copy for `log_jac`, `rminus_jac` and SE(3)'s log).
    #[cfg_attr(not(estimator_compact), inline)]
    #[cfg_attr(estimator_compact, inline(never))]
    pub(crate) fn log_with_coeffs(&self) -> (Vector3<T>, AngleCoeffs<T>) {
        // Not destructured (read in place, see `log_jac`).
        let p = self.log_parts();
        let k = AngleCoeffs::from_half_angle(p.1 * p.1, p.1, p.2, p.3);
        (p.0, k)
    }

    /// Re-projects a quaternion already near unit norm without a square root: one Newton step
    /// for `1/‖q‖`, `q ← q·(3 − ‖q‖²)/2`. A norm error `‖q‖² = 1 + ε` becomes `−¾ε² + O(ε³)`,
    /// so after a product of unit quaternions (`ε` of a few ulps) the result is unit to
    /// rounding. For `|ε|` above about 0.1 use [`LieGroup::normalize`]. It is the cheap choice
    /// for a filter step at 1 kHz (no `sqrtf`, which is software on a Cortex-M4F).
    #[must_use]
    #[cfg_attr(estimator_compact, inline(never))]
    pub fn renormalize(&self) -> Self {
        let q = self.q.quaternion();
        let scale = (T::lit(3.0) - q.coords.norm_squared()) * T::lit(0.5);
        Self::scaled(q, scale)
    }

    /// `q p q* + t`: nalgebra's formula for `q p q*` written out per component (the same
    /// operations in the same order, so the same result; no temporary vectors at opt-level "s"):
    /// `u = 2 v × p`, `p' = w u + v × u + p`, and `t` added last, as `R p + t` would. One shared
    /// copy for SO(3)'s `act` (`t = −0`) and SE(3)'s `act`, `compose`.
    pub(crate) fn act_plus(&self, p: &Vector3<T>, t: &Vector3<T>) -> Vector3<T> {
        let q = self.q.quaternion();
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        let two = T::lit(2.0);
        let tx = (y * p.z - z * p.y) * two;
        let ty = (z * p.x - x * p.z) * two;
        let tz = (x * p.y - y * p.x) * two;
        Vector3::new(
            tx * w + (y * tz - z * ty) + p.x + t.x,
            ty * w + (z * tx - x * tz) + p.y + t.y,
            tz * w + (x * ty - y * tx) + p.z + t.z,
        )
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

    /// Under `estimator_compact`, through the shared kernel ([`AngleCoeffs::from_theta_sq`] and
    /// [`So3::exp_from`]): the same `θ`, `sincos(θ/2)` and `sin(θ/2)/θ`, so the same bits, without
    /// a second inlined copy of them (the kernel's `a`, `b`, `c` are computed and unused).
    #[cfg(estimator_compact)]
    #[inline(never)]
    fn exp(w: &Vector3<T>) -> Self {
        Self::exp_from(&AngleCoeffs::of_vector(w), w)
    }

    #[cfg(not(estimator_compact))]
    fn exp(w: &Vector3<T>) -> Self {
        let theta_sq = w.norm_squared();
        let theta = theta_sq.sqrt_rn();
        let (s, c) = (theta * T::lit(0.5)).sincos();
        let v = w * super::trig::half_sinc(theta_sq, theta, s);
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

    /// The conjugate, per component (nalgebra's `conjugate` negates the vector part in a loop
    /// through a temporary at opt-level "s").
    #[cfg_attr(estimator_compact, inline(never))]
    fn inverse(&self) -> Self {
        let q = self.q.quaternion();
        Self {
            q: UnitQuaternion::new_unchecked(Quaternion::new(q.w, -q.i, -q.j, -q.k)),
        }
    }

    /// `q p q*` (see `act_plus`).
    #[cfg_attr(estimator_compact, inline(never))]
    fn act(&self, p: &Vector3<T>) -> Vector3<T> {
        // `x + (−0) = x` for every `x` (signed zeros and NaN included): the plain rotation.
        let z = -T::zero();
        self.act_plus(p, &Vector3::new(z, z, z))
    }

    fn adjoint(&self) -> Matrix3<T> {
        self.rotation_matrix()
    }

    fn right_jacobian(w: &Vector3<T>) -> Matrix3<T> {
        Self::jr_at(w, T::one())
    }

    fn right_jacobian_inv(w: &Vector3<T>) -> Matrix3<T> {
        Self::jr_inv_at(w, T::one())
    }

    /// `J_r(ω)ᵀ = I + b[ω]× + c[ω]×²`.
    fn left_jacobian(w: &Vector3<T>) -> Matrix3<T> {
        Self::jr_at(w, -T::one())
    }

    /// `J_r⁻¹(ω)ᵀ = I − ½[ω]× + d[ω]×²`.
    fn left_jacobian_inv(w: &Vector3<T>) -> Matrix3<T> {
        Self::jr_inv_at(w, -T::one())
    }

    fn matrix(&self) -> Matrix3<T> {
        self.rotation_matrix()
    }

    #[cfg_attr(estimator_compact, inline(never))]
    fn normalize(&self) -> Self {
        match Self::from_quaternion(self.q.as_ref()) {
            Some(r) => r,
            None => *self,
        }
    }

    fn try_from_matrix(m: &Matrix3<T>) -> Option<Self> {
        // No separate finiteness check: a NaN or infinite entry makes the error NaN or infinite,
        // and the comparison below (false for NaN) rejects it.
        let err = orthogonality_error(m);
        let tol = T::lit(ORTHOGONALITY_TOLERANCE);
        let orthogonal = err <= tol * tol;
        let proper = m.determinant() > T::zero();
        if !(orthogonal && proper) {
            return None;
        }
        Self::quaternion_from_matrix(m)
    }

    fn is_finite(&self) -> bool {
        all_finite(self.q.coords.as_slice())
    }

    fn exp_jac(w: &Vector3<T>) -> (Self, Matrix3<T>) {
        let k = AngleCoeffs::of_vector(w);
        (Self::exp_from(&k, w), Self::jr_from(&k, w))
    }

    fn log_jac(&self) -> (Vector3<T>, Matrix3<T>) {
        // Not destructured: the kernel is read where `log_with_coeffs` put it (no copy).
        let lk = self.log_with_coeffs();
        (lk.0, Self::jr_inv_from(&lk.1, &lk.0))
    }

    fn compose_jac(&self, b: &Self) -> (Self, Matrix3<T>, Matrix3<T>) {
        // R_bᵀ as the rotation matrix of the conjugate: nalgebra's formula gives R(q*) = R(q)ᵀ bit
        // for bit (each off-diagonal pair is x − (−y) against y + x), without a transposing copy.
        (self.compose(b), b.inverse().rotation_matrix(), eye())
    }

    /// `(a⁻¹, −R)`, negated in place (`negate`).
    fn inverse_jac(&self) -> (Self, Matrix3<T>) {
        // Negated where it is returned (no copy of the Jacobian after the negation).
        let mut out = (self.inverse(), self.adjoint());
        negate(&mut out.1);
        out
    }

    /// `(z = a⁻¹·b, −R_{z⁻¹}, I)`, negated in place (`negate`).
    fn between_jac(&self, b: &Self) -> (Self, Matrix3<T>, Matrix3<T>) {
        // `z` written where it is returned and read there (no copy of it into the tuple).
        let mut out = (self.between(b), eye(), eye());
        out.1 = out.0.inverse().adjoint();
        negate(&mut out.1);
        out
    }

    fn rminus_jac(&self, b: &Self) -> (Vector3<T>, Matrix3<T>, Matrix3<T>) {
        let lk = b.between(self).log_with_coeffs();
        let (tau, d) = (lk.0, lk.1.d());
        // −J_l⁻¹(τ) = −J_r⁻¹(τ)ᵀ = −I + ½[τ]× − d[τ]×², built negated.
        (
            tau,
            skew_poly(T::one(), T::lit(0.5), d, &tau),
            skew_poly(-T::one(), T::lit(0.5), -d, &tau),
        )
    }

    /// `(R p, −R[p]×, R)`: seed Theorem 5.1 with `H(p) = [−p]×` (Example 5.2).
    fn act_jac(&self, p: &Vector3<T>) -> (Vector3<T>, Matrix3<T>, Matrix3<T>) {
        let r = self.rotation_matrix();
        // `R p` and `−p` entry by entry (nalgebra's order of operations for `R p`); `R[−p]×`
        // computed over a copy of `R` where it is returned.
        let rp = Vector3::new(
            r.m11 * p.x + r.m12 * p.y + r.m13 * p.z,
            r.m21 * p.x + r.m22 * p.y + r.m23 * p.z,
            r.m31 * p.x + r.m32 * p.y + r.m33 * p.z,
        );
        let mut out = (rp, r, r);
        mul_skew_in_place(&mut out.1, -p.x, -p.y, -p.z);
        out
    }
}

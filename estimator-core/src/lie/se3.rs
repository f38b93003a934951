//! SE(3), rigid motions `T = (R, t)` acting as `T p = R p + t`.
//!
//! Tangent `ξ = [v; ω] ∈ R⁶`, translation part first (the seed's twist `(v, ω)`); generators
//! `Gⁱ` (i = 1..3) put `eᵢ` in the translation column, `Gⁱ⁺³` put SO(3)'s `Gⁱ` in the rotation block:
//!
//! ```text
//! ξ^ = [ [ω]×  v ]
//!      [  0    0 ]
//! ```
//!
//! * `exp(ξ) = (exp(ω), J_l(ω) v)` with SO(3)'s left Jacobian `J_l(ω) = I + b[ω]× + c[ω]×²`.
//! * `log(T) = [J_l(ω)⁻¹ t; ω]`, `ω = log(R)`.
//! * `J_r(ξ) = [[J_r(ω), Q(−v, −ω)], [0, J_r(ω)]]`, and its inverse
//!   `[[J_r⁻¹, −J_r⁻¹ Q J_r⁻¹], [0, J_r⁻¹]]`, where (Barfoot, *State Estimation for Robotics*,
//!   eq. 7.86, with `V = [v]×`, `W = [ω]×`):
//!   `Q(v, ω) = ½V + c(WV + VW + WVW) − e(W²V + VW² − 3WVW) − ½f(WVW² + W²VW)`, evaluated in
//!   a closed form without matrix products (see `q_block`).
//! * `Ad_T = [[R, [t]×R], [0, R]]`.
//! * `act_jac(p) = (R p + t, [R | −R[p]×], R)`: seed Theorem 5.1, `F = T [H(p) | I]`.

use super::so3::So3;
use super::trig::AngleCoeffs;
use super::{
    all_finite, eye, mul_skew_in_place, negate, skew_poly, LieGroup, Real, ORTHOGONALITY_TOLERANCE,
};
use nalgebra::{Matrix3, Matrix3x6, Matrix4, Matrix6, Vector3, Vector6};

/// A rigid motion `T = (R, t) ∈ SE(3)`; `a_from_b` maps `b` coordinates into `a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3<T: Real> {
    rotation: So3<T>,
    translation: Vector3<T>,
}

/// Splits `ξ = [v; ω]`.
#[inline]
fn split<T: Real>(xi: &Vector6<T>) -> (Vector3<T>, Vector3<T>) {
    (
        Vector3::new(xi.x, xi.y, xi.z),
        Vector3::new(xi.w, xi.a, xi.b),
    )
}

#[inline]
fn join<T: Real>(v: &Vector3<T>, w: &Vector3<T>) -> Vector6<T> {
    Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z)
}

/// `[[a, bᵀ], [0, a]]` from 3×3 blocks (the shape of every SE(3) Jacobian), the upper block given
/// transposed: each caller builds `bᵀ` as cheaply as `b` (the adjoint's `[σt]×R` is
/// `(Rᵀ[−σt]×)ᵀ`), so no transposed temporary is made.
fn upper_block<T: Real>(diag: &Matrix3<T>, upper_t: &Matrix3<T>) -> Matrix6<T> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(diag);
    m.fixed_view_mut::<3, 3>(0, 3).tr_copy_from(upper_t);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(diag);
    m
}

/// Barfoot's `Q(v, ω)` (see the module docs) from the kernel of `ω`, in closed form.
///
/// With `V = [v]×`, `W = [ω]×`, `δ = ω·v`, `u = ω × v` and the identities
/// `[a]×[b]× = b aᵀ − (a·b) I`, `ωᵀW = 0`, `a bᵀ − b aᵀ = [b × a]×`, the products of eq. 7.86
/// reduce to `WV + VW + WVW = vωᵀ + ωvᵀ − 2δI − δW`, `W²V + VW² − 3WVW = [ω × u]× + δW`
/// (`ω × u = δω − θ²v`) and `WVW² + W²VW = −2δW²`, so that, with `W² = ωωᵀ − θ²I` and
/// `½ + eθ² = b`,
///
/// ```text
/// Q = [b v − δ(c + 2e) ω]× + αωᵀ + ωαᵀ − δ(2c + fθ²) I,   α = c v + ½ f δ ω.
/// ```
///
/// No 3×3 product at all (eq. 7.86 as written takes eight). Returned as
/// `sym·(αωᵀ + ωαᵀ − δ(2c + fθ²) I) + skew·[b v − δ(c + 2e) ω]×` for signs `sym`, `skew` = ±1,
/// which covers every use: `Q` is even in `(v, ω)` in its symmetric part and odd in its skew
/// part, so `Q(−v, −ω)` is `sym = 1, skew = −1`, and `−Q(−v, −ω)` is `sym = −1, skew = 1` (the
/// signs are exact, so each is bit for bit the negated-argument or negated-result form).
/// Written entry by entry (no 3-vector temporaries at opt-level "s").
fn q_block<T: Real>(k: &AngleCoeffs<T>, xi: &Vector6<T>, sym: T, skew: T) -> Matrix3<T> {
    // `ξ = [v; ω]` read in place (the callers' `ω` copy is for `skew_poly` only).
    let (v, w) = split(xi);
    let (v, w) = (&v, &w);
    let se = k.se();
    let dot = w.dot(v);
    let g = dot * (k.c + k.c + se.f * k.theta_sq) * sym;
    // α (times `sym`) and s = b v − δ(c + 2e) ω (times `skew`), the signs folded into the
    // coefficients: as `sym`, `skew` = ±1, `(x + y)σ` and `xσ + yσ` differ at most in a zero's sign.
    let (c, fa) = (k.c * sym, T::lit(0.5) * se.f * dot * sym);
    let (b, sc) = (k.b * skew, dot * (k.c + se.e + se.e) * skew);
    let (ax, ay, az) = (v.x * c + w.x * fa, v.y * c + w.y * fa, v.z * c + w.z * fa);
    let (sx, sy, sz) = (v.x * b - w.x * sc, v.y * b - w.y * sc, v.z * b - w.z * sc);
    let (xy, xz, yz) = (
        ax * w.y + ay * w.x,
        ax * w.z + az * w.x,
        ay * w.z + az * w.y,
    );
    Matrix3::new(
        ax * w.x + ax * w.x - g,
        xy - sz,
        xz + sy,
        xy + sz,
        ay * w.y + ay * w.y - g,
        yz - sx,
        xz - sy,
        yz + sx,
        az * w.z + az * w.z - g,
    )
}

/// `x + p ω×x + q ω×(ω×x)`, entry by entry: `J_l(ω) x` of SO(3) (`p = b`, `q = c`, the
/// exponential's translation) and `J_l⁻¹(ω) x` (`p = −½`, `q = d`, the logarithm's).
///
/// The vectors by component (in registers, not copied to the stack for a pointer).
#[allow(clippy::too_many_arguments)]
fn cross_poly<T: Real>(p: T, q: T, w0: T, w1: T, w2: T, x0: T, x1: T, x2: T) -> Vector3<T> {
    let (w, x) = (&Vector3::new(w0, w1, w2), &Vector3::new(x0, x1, x2));
    let wx = w.cross(x);
    let wwx = w.cross(&wx);
    Vector3::new(
        x.x + wx.x * p + wwx.x * q,
        x.y + wx.y * p + wwx.y * q,
        x.z + wx.z * p + wwx.z * q,
    )
}

/// `a·b` for 3×3 matrices: one out-of-line copy when built for size.
#[cfg_attr(estimator_compact, inline(never))]
pub(super) fn mul3<T: Real>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    #[cfg(not(estimator_compact))]
    {
        a * b
    }
    // A loop over the entries, each `(a_i1 b_1j + a_i2 b_2j) + a_i3 b_3j` as nalgebra sums it.
    #[cfg(estimator_compact)]
    {
        // Column `j` of the product overwrites column `j` of a copy of `b` once it is read.
        let [a1, a2, a3] = &a.data.0;
        let mut c = *b;
        for cj in &mut c.data.0 {
            let [x, y, z] = *cj;
            for (((e, p), q), r) in cj.iter_mut().zip(a1).zip(a2).zip(a3) {
                *e = *p * x + *q * y + *r * z;
            }
        }
        c
    }
}

impl<T: Real> Se3<T> {
    /// `T = (R, t)`.
    #[must_use]
    pub fn from_parts(rotation: So3<T>, translation: Vector3<T>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// The same motion in another precision, stored numbers converted as they are.
    #[must_use]
    pub fn cast<U: Real>(&self) -> Se3<U> {
        let c = |x: T| U::lit(x.to_f64());
        let t = &self.translation;
        Se3::from_parts(self.rotation.cast(), Vector3::new(c(t.x), c(t.y), c(t.z)))
    }

    /// The rotation `R`.
    #[must_use]
    pub fn rotation(&self) -> So3<T> {
        self.rotation
    }

    /// The translation `t`.
    #[must_use]
    pub fn translation(&self) -> Vector3<T> {
        self.translation
    }

    /// `exp(ξ)` from the kernel of `ω` (`ξ` split here, as in [`Self::jr_from`]).
    fn exp_from(k: &AngleCoeffs<T>, xi: &Vector6<T>) -> Self {
        let (v, w) = split(xi);
        Self {
            rotation: So3::exp_from(k, &w),
            translation: cross_poly(k.b, k.c, w.x, w.y, w.z, v.x, v.y, v.z),
        }
    }

    /// `J_r(σξ)` for `σ = ±1` (`σ = −1`: `J_l(ξ)`), from the kernel of `ω`: the SO(3) block of
    /// `σω` and `Q(−σv, −σω)`.
    ///
    /// Takes `ξ` whole and splits it here: one copy of `v`, `ω` for every caller.
    fn jr_from(k: &AngleCoeffs<T>, xi: &Vector6<T>, sigma: T) -> Matrix6<T> {
        let w = Vector3::new(xi.w, xi.a, xi.b);
        let jr = skew_poly(T::one(), -k.b * sigma, k.c, &w);
        // `Q(−σv, −σω)ᵀ`: the skew part's sign flipped (exact, see `q_block`).
        upper_block(&jr, &q_block(k, xi, T::one(), sigma))
    }

    /// `ρ·J_r⁻¹(σξ)` for `σ, ρ = ±1`: `[[ρJ, −ρ J Q(−σv, −σω) J], [0, ρJ]]` with `J = J_r⁻¹(σω)`
    /// of SO(3); the signs go into `Q` (see [`q_block`]) and `J`, exactly.
    /// `ξ` is split here, as in [`Self::jr_from`].
    fn jr_inv_from(k: &AngleCoeffs<T>, xi: &Vector6<T>, sigma: T, rho: T) -> Matrix6<T> {
        let w = &Vector3::new(xi.w, xi.a, xi.b);
        let (half_sigma, d) = (T::lit(0.5) * sigma, k.d());
        // Transposed for `upper_block`: `((J Q) J)ᵀ = Jᵀ (Qᵀ Jᵀ)`, the same products and sums
        // (`Jᵀ` and `Qᵀ` flip the sign of the skew parts, exactly).
        let jinv_t = skew_poly(T::one(), -half_sigma, d, w);
        let q_t = q_block(k, xi, -rho, -(rho * sigma));
        // `ρJ` as `skew_poly(ρ, ½σρ, ρd)`: the same numbers as `J·ρ` up to the sign of zeros
        // (see `skew_poly`), without a scaled copy of `J`.
        let diag = skew_poly(rho, half_sigma * rho, d * rho, w);
        upper_block(&diag, &mul3(&jinv_t, &mul3(&q_t, &jinv_t)))
    }

    /// `J_r(σξ)` from `ξ` (`σ = ±1`): shared source of the right and left Jacobians. Out of line
    /// when built for size (one copy of the split and the kernel call for both).
    #[cfg_attr(not(estimator_compact), inline(always))]
    #[cfg_attr(estimator_compact, inline(never))]
    fn jr_at(xi: &Vector6<T>, sigma: T) -> Matrix6<T> {
        Self::jr_from(&AngleCoeffs::of_components(xi.w, xi.a, xi.b), xi, sigma)
    }

    /// `J_r⁻¹(σξ)` from `ξ` (`σ = ±1`): shared source of the right and left inverse Jacobians
    /// (out of line when built for size, as [`Self::jr_at`]).
    #[cfg_attr(not(estimator_compact), inline(always))]
    #[cfg_attr(estimator_compact, inline(never))]
    fn jr_inv_at(xi: &Vector6<T>, sigma: T) -> Matrix6<T> {
        let k = AngleCoeffs::of_components(xi.w, xi.a, xi.b);
        Self::jr_inv_from(&k, xi, sigma, T::one())
    }

    /// `σ·Ad_T = [[σR, [σt]×R], [0, σR]]` for `σ = ±1`: the adjoint, and `−Ad_T` built negated
    /// (no negation pass over 36 entries); `[σt]×R = (Rᵀ[−σt]×)ᵀ` since `[t]×ᵀ = −[t]×`.
    #[cfg_attr(estimator_compact, inline(never))]
    fn signed_adjoint(&self, sigma: T) -> Matrix6<T> {
        let mut r = self.rotation.rotation_matrix();
        // `Rᵀ` as the rotation matrix of the conjugate (the same bits, see `compose_jac` of SO(3))
        // and `−σt` per component: no transposing copy and no loop over a temporary.
        let mut rt = self.rotation.inverse().rotation_matrix();
        let t = &self.translation;
        // `σR` in place through the shared `negate` (no multiply loop over a temporary; `σ = ±1`,
        // so the numbers are those of `R·σ`).
        if sigma < T::zero() {
            negate(&mut r);
        }
        mul_skew_in_place(&mut rt, t.x * -sigma, t.y * -sigma, t.z * -sigma);
        upper_block(&r, &rt)
    }

    /// `−Ad_T`.
    fn neg_adjoint(&self) -> Matrix6<T> {
        self.signed_adjoint(-T::one())
    }

    /// `log` and the kernel of its rotation angle.
    fn log_with_coeffs(&self) -> (Vector6<T>, AngleCoeffs<T>) {
        let lk = self.rotation.log_with_coeffs();
        let w = &lk.0;
        // J_l⁻¹(ω) t = t − ½ ω×t + d ω×(ω×t).
        let v = {
            let t = &self.translation;
            cross_poly(T::lit(-0.5), lk.1.d(), w.x, w.y, w.z, t.x, t.y, t.z)
        };
        (join(&v, w), lk.1)
    }
}

impl<T: Real> core::ops::Mul for Se3<T> {
    type Output = Self;
    fn mul(self, rhs: Self) -> Self {
        self.compose(&rhs)
    }
}

impl<T: Real> LieGroup<T> for Se3<T> {
    const DOF: usize = 6;
    const DIM: usize = 3;
    type Tangent = Vector6<T>;
    type Jacobian = Matrix6<T>;
    type Point = Vector3<T>;
    type Matrix = Matrix4<T>;
    type ActJacobian = Matrix3x6<T>;
    type PointJacobian = Matrix3<T>;

    fn identity() -> Self {
        Self::from_parts(So3::identity(), Vector3::zeros())
    }

    fn exp(xi: &Vector6<T>) -> Self {
        // Not `of_vector`: where SE(3)'s exponential is the only user of the kernel (the PnP
        // firmware) the squared norm inlines with it, and a call to a shared copy costs 80 bytes.
        let (_, w) = split(xi);
        Self::exp_from(&AngleCoeffs::from_theta_sq(w.norm_squared()), xi)
    }

    fn log(&self) -> Vector6<T> {
        self.log_with_coeffs().0
    }

    /// `[[ω]×, v], [0, 0]]` entry by entry (no `[ω]×` temporary copied into a zeroed matrix).
    fn hat(xi: &Vector6<T>) -> Matrix4<T> {
        let (v, w) = split(xi);
        let z = T::zero();
        Matrix4::new(
            z, -w.z, w.y, v.x, //
            w.z, z, -w.x, v.y, //
            -w.y, w.x, z, v.z, //
            z, z, z, z,
        )
    }

    fn vee(m: &Matrix4<T>) -> Vector6<T> {
        Vector6::new(m.m14, m.m24, m.m34, m.m32, m.m13, m.m21)
    }

    #[cfg_attr(estimator_compact, inline(never))]
    fn compose(&self, b: &Self) -> Self {
        Self {
            rotation: self.rotation.compose(&b.rotation),
            translation: self.rotation.act_plus(&b.translation, &self.translation),
        }
    }

    fn inverse(&self) -> Self {
        let r_inv = self.rotation.inverse();
        // `R⁻¹(−t)`: the operations of `−(R⁻¹ t)` on negated operands, so the same numbers up to
        // the sign of zeros (rounding is symmetric), with `−t` built in registers.
        let t = &self.translation;
        Self {
            translation: r_inv.act(&Vector3::new(-t.x, -t.y, -t.z)),
            rotation: r_inv,
        }
    }

    fn act(&self, p: &Vector3<T>) -> Vector3<T> {
        self.rotation.act_plus(p, &self.translation)
    }

    /// `[[R, [t]×R], [0, R]]`.
    fn adjoint(&self) -> Matrix6<T> {
        self.signed_adjoint(T::one())
    }

    fn right_jacobian(xi: &Vector6<T>) -> Matrix6<T> {
        Self::jr_at(xi, T::one())
    }

    fn right_jacobian_inv(xi: &Vector6<T>) -> Matrix6<T> {
        Self::jr_inv_at(xi, T::one())
    }

    /// `J_r(−ξ)`, with the sign taken inside (no negated tangent).
    fn left_jacobian(xi: &Vector6<T>) -> Matrix6<T> {
        Self::jr_at(xi, -T::one())
    }

    /// `J_r⁻¹(−ξ)`, with the sign taken inside (no negated tangent).
    fn left_jacobian_inv(xi: &Vector6<T>) -> Matrix6<T> {
        Self::jr_inv_at(xi, -T::one())
    }

    /// `[[R, t], [0, 1]]` entry by entry (no identity matrix overwritten block by block).
    fn matrix(&self) -> Matrix4<T> {
        let r = self.rotation.rotation_matrix();
        let t = &self.translation;
        let (z, o) = (T::zero(), T::one());
        Matrix4::new(
            r.m11, r.m12, r.m13, t.x, //
            r.m21, r.m22, r.m23, t.y, //
            r.m31, r.m32, r.m33, t.z, //
            z, z, z, o,
        )
    }

    fn normalize(&self) -> Self {
        Self::from_parts(self.rotation.normalize(), self.translation)
    }

    fn try_from_matrix(m: &Matrix4<T>) -> Option<Self> {
        let tol = T::lit(ORTHOGONALITY_TOLERANCE);
        // `x·0` is `±0` for finite `x` and NaN otherwise: adding the translation's makes the sum
        // NaN exactly when `t` is not finite, and leaves it unchanged otherwise (no separate
        // finiteness check of `t`).
        let z = T::zero();
        let finite_t = m.m14 * z + m.m24 * z + m.m34 * z;
        let bottom = m.m41.abs() + m.m42.abs() + m.m43.abs() + (m.m44 - T::one()).abs() + finite_t;
        // Written so that NaN (which compares false) is rejected too.
        let bottom_ok = bottom <= tol;
        if !bottom_ok {
            return None;
        }
        // The rotation block entry by entry (`fixed_view(..).into_owned()` is a copy loop).
        let r = So3::try_from_matrix(&Matrix3::new(
            m.m11, m.m12, m.m13, m.m21, m.m22, m.m23, m.m31, m.m32, m.m33,
        ))?;
        Some(Self::from_parts(r, Vector3::new(m.m14, m.m24, m.m34)))
    }

    fn is_finite(&self) -> bool {
        self.rotation.is_finite() && all_finite(self.translation.as_slice())
    }

    fn exp_jac(xi: &Vector6<T>) -> (Self, Matrix6<T>) {
        let k = AngleCoeffs::of_components(xi.w, xi.a, xi.b);
        (Self::exp_from(&k, xi), Self::jr_from(&k, xi, T::one()))
    }

    fn log_jac(&self) -> (Vector6<T>, Matrix6<T>) {
        // Not destructured: the kernel is read where `log_with_coeffs` put it (no copy).
        let lk = self.log_with_coeffs();
        (lk.0, Self::jr_inv_from(&lk.1, &lk.0, T::one(), T::one()))
    }

    /// `(a·b, Ad_{b⁻¹}, I)`, the identity from `eye` (not `Ad_e` built from an identity motion).
    fn compose_jac(&self, b: &Self) -> (Self, Matrix6<T>, Matrix6<T>) {
        (self.compose(b), b.inverse().adjoint(), eye())
    }

    /// `(a⁻¹, −Ad_a)`.
    fn inverse_jac(&self) -> (Self, Matrix6<T>) {
        (self.inverse(), self.neg_adjoint())
    }

    /// `(z = a⁻¹·b, −Ad_{z⁻¹}, I)`.
    fn between_jac(&self, b: &Self) -> (Self, Matrix6<T>, Matrix6<T>) {
        // `z` written where it is returned and read there (no copy of it into the tuple).
        let mut out = (self.between(b), eye(), eye());
        out.1 = out.0.inverse().neg_adjoint();
        out
    }

    /// `(τ = a ⊖ b, J_r⁻¹(τ), −J_l⁻¹(τ))` with one trigonometric kernel for the log and both
    /// inverse Jacobians (`J_l⁻¹(τ) = J_r⁻¹(−τ)`, same angle).
    fn rminus_jac(&self, b: &Self) -> (Vector6<T>, Matrix6<T>, Matrix6<T>) {
        let lk = b.between(self).log_with_coeffs();
        let (tau, k) = (&lk.0, &lk.1);
        (
            *tau,
            Self::jr_inv_from(k, tau, T::one(), T::one()),
            Self::jr_inv_from(k, tau, -T::one(), -T::one()),
        )
    }

    /// `(R p + t, [R | −R[p]×], R)`: seed Theorem 5.1.
    ///
    /// SO(3)'s `act_jac` gives `R p`, `−R[p]×` and `R`; the 3×6 block is their columns side by side.
    fn act_jac(&self, p: &Vector3<T>) -> (Vector3<T>, Matrix3x6<T>, Matrix3<T>) {
        // Not destructured: the blocks are read where SO(3)'s `act_jac` put them.
        let a = self.rotation.act_jac(p);
        let (rp, h, r) = (&a.0, &a.1, &a.2);
        let t = &self.translation;
        let mut out = (
            Vector3::new(rp.x + t.x, rp.y + t.y, rp.z + t.z),
            Matrix3x6::zeros(),
            *r,
        );
        // The two 3×3 blocks copied whole into the column-major 3×6 where it is returned (two
        // block copies, no temporary 3×6 copied into the tuple).
        let (jr, jh) = out.1.as_mut_slice().split_at_mut(9);
        jr.copy_from_slice(r.as_slice());
        jh.copy_from_slice(h.as_slice());
        out
    }
}

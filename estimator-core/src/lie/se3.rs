//! SE(3), rigid motions `T = (R, t)` acting as `T p = R p + t`.
//!
//! Tangent `ξ = [v; ω] ∈ R⁶`, translation part first (the twist `ξ = (v, ω)` of *Lie Groups and
//! Smooth Manifolds for Robotic State Estimation*, "the paper" below); generators `Gⁱ`
//! (i = 1..3) put `eᵢ` in the translation column, `Gⁱ⁺³` put SO(3)'s `Gⁱ` in the rotation block,
//! so that the hat of the paper's eq. 3.2, `ξ^ = Σᵢ ξᵢ Gⁱ`, is
//!
//! ```text
//! ξ^ = [ [ω]×  v ]
//!      [  0    0 ]
//! ```
//!
//! * `exp(ξ) = (exp(ω), J_l(ω) v)` with SO(3)'s left Jacobian `J_l(ω) = I + b[ω]× + c[ω]×²`.
//! * `log(T) = [J_l(ω)⁻¹ t; ω]`, `ω = log(R)`, `J_l⁻¹(ω) = I − ½[ω]× + d[ω]×²`.
//! * `J_r(ξ) = [[J_r(ω), Q(−v, −ω)], [0, J_r(ω)]]`, and its inverse
//!   `[[J_r⁻¹, −J_r⁻¹ Q J_r⁻¹], [0, J_r⁻¹]]`, where (Barfoot, *State Estimation for Robotics*,
//!   eq. 7.86, with `V = [v]×`, `W = [ω]×`):
//!   `Q(v, ω) = ½V + c(WV + VW + WVW) − e(W²V + VW² − 3WVW) − ½f(WVW² + W²VW)`, evaluated in
//!   a closed form without matrix products (see `q_block`).
//! * `Ad_T = [[R, [t]×R], [0, R]]`.
//! * `act_jac(p) = (R p + t, [R | −R[p]×], R)`: the paper's Theorem 5.1, `F = T [H(p) | I]`.
//!
//! `a, b, c, d` are SO(3)'s coefficients of the angle `θ = ‖ω‖`, and `e`, `f` those of the
//! `Q` block (the `trig` kernel).

use super::so3::So3;
use super::trig::AngleCoeffs;
use super::{skew_poly, LieGroup, Real, ORTHOGONALITY_TOLERANCE};
use crate::kernels::all_finite;
use crate::kernels::block::set_block;
use crate::kernels::mat3::{mul, mul_skew};
use nalgebra::{Matrix3, Matrix3x6, Matrix4, Matrix6, Vector3, Vector6};

/// A rigid motion `T = (R, t) ∈ SE(3)`; `a_from_b` maps `b` coordinates into `a`.
///
/// ```
/// use estimator_core::lie::{LieGroup, Se3, So3};
/// use nalgebra::{Matrix4, Vector3, Vector6};
///
/// // `b_from_c`: a quarter turn about z, then a shift of (1, 2, 3).
/// let r = So3::exp(&Vector3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2));
/// let b_from_c = Se3::from_parts(r, Vector3::new(1.0, 2.0, 3.0));
/// let p_b = b_from_c.act(&Vector3::new(1.0, 0.0, 0.0));
/// assert!((p_b - Vector3::new(1.0, 3.0, 3.0)).amax() < 1e-15);
///
/// // Composition is the product of homogeneous matrices; the inverse undoes the action.
/// let a_from_b = Se3::exp(&Vector6::new(0.5, -1.0, 0.0, 0.1, 0.2, -0.3));
/// let a_from_c = a_from_b * b_from_c;
/// let m: Matrix4<f64> = a_from_b.matrix() * b_from_c.matrix();
/// assert!((a_from_c.matrix() - m).amax() < 1e-15);
/// assert!((b_from_c.inverse().act(&p_b) - Vector3::x()).amax() < 1e-15);
///
/// // exp and log of a twist ξ = [v; ω] are inverse, and the Jacobian of T p is [R | −R[p]×].
/// let xi = Vector6::new(1.0, -2.0, 0.5, 0.3, -0.7, 1.1);
/// let t = Se3::exp(&xi);
/// assert!((t.log() - xi).amax() < 1e-14);
/// let (tp, j_t, j_p) = t.act_jac(&Vector3::new(0.2, 0.4, -1.0));
/// assert!((tp - t.act(&Vector3::new(0.2, 0.4, -1.0))).amax() < 1e-15);
/// assert_eq!(j_p, t.rotation().matrix());
/// assert_eq!(j_t.fixed_columns::<3>(0), t.rotation().matrix());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3<T: Real> {
    rotation: So3<T>,
    translation: Vector3<T>,
}

/// Splits `ξ = [v; ω]`.
fn split<T: Real>(xi: &Vector6<T>) -> (Vector3<T>, Vector3<T>) {
    (
        Vector3::new(xi.x, xi.y, xi.z),
        Vector3::new(xi.w, xi.a, xi.b),
    )
}

/// `[[a, b], [0, a]]` from 3×3 blocks (the shape of every SE(3) Jacobian), the upper block `b`
/// given as `bᵀ`, the form in which every caller builds it.
fn upper_block<T: Real>(diag: &Matrix3<T>, upper_t: &Matrix3<T>) -> Matrix6<T> {
    let mut m = Matrix6::zeros();
    set_block(&mut m, 0, 0, diag);
    set_block(&mut m, 0, 1, &upper_t.transpose());
    set_block(&mut m, 1, 1, diag);
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
/// `Q` is even in `(v, ω)` in its symmetric part and odd in its skew part, so
/// `Q(−v, −ω) = Q(v, ω)ᵀ`.
///
/// For a huge `ω` ([`AngleCoeffs::is_huge`]) the same `Q` with `ω = θu`, `δ = θδᵤ`: with
/// `cθ² = 1 − a`, `eθ² = b − ½` and `fθ² = b − 3c`, `δ(c + 2e)ω = δᵤ(2b − a)u`,
/// `αωᵀ = α'uᵀ` with `α' = θα = cθ v + ½ fθ³ δᵤ u` (`fθ³ = θb − 3cθ`), and
/// `δ(2c + fθ²) = δᵤ(θb − cθ)`: every coefficient finite, none multiplied by `θ²`.
fn q_block<T: Real>(k: &AngleCoeffs<T>, v: &Vector3<T>, w: &Vector3<T>) -> Matrix3<T> {
    let se = k.se();
    let dot = w.dot(v);
    let g = dot * (k.c + k.c + se.f * k.theta_sq);
    let a = v * k.c + w * (T::lit(0.5) * se.f * dot);
    let s = v * k.b - w * (dot * (k.c + se.e + se.e));
    q_assemble(&a, w, &s, g)
}

/// `[s]× + a wᵀ + w aᵀ − g I`, the assembly of [`q_block`].
fn q_assemble<T: Real>(a: &Vector3<T>, w: &Vector3<T>, s: &Vector3<T>, g: T) -> Matrix3<T> {
    // αωᵀ + ωαᵀ: entry (i, j) is αᵢωⱼ + αⱼωᵢ.
    let (xy, xz, yz) = (
        a.x * w.y + a.y * w.x,
        a.x * w.z + a.z * w.x,
        a.y * w.z + a.z * w.y,
    );
    Matrix3::new(
        a.x * w.x + a.x * w.x - g,
        xy - s.z,
        xz + s.y,
        xy + s.z,
        a.y * w.y + a.y * w.y - g,
        yz - s.x,
        xz - s.y,
        yz + s.x,
        a.z * w.z + a.z * w.z - g,
    )
}

/// `x + p ω×x + q ω×(ω×x)`: `J_l(ω) x` of SO(3) (`p = b`, `q = c`, the exponential's
/// translation) and `J_l⁻¹(ω) x` (`p = −½`, `q = d`, the logarithm's). For a huge `ω` the
/// exponential's is `x + θb u×x + θ²c u×(u×x)` ([`AngleCoeffs::is_huge`]).
fn cross_poly<T: Real>(p: T, q: T, w: &Vector3<T>, x: &Vector3<T>) -> Vector3<T> {
    let wx = w.cross(x);
    let wwx = w.cross(&wx);
    x + wx * p + wwx * q
}

/// `true` when the ordinary formulas would overflow in an intermediate product although the
/// result is finite: `‖ω‖²` itself, or `ω×(ω×v)` (about `θ²‖v‖`, so whenever `θ²‖v‖²`
/// overflows with `θ > 1`). The scaled path ([`exp_jac_huge`]) never forms those products.
#[inline(always)]
fn needs_scaling<T: Real>(theta_sq: T, v: &Vector3<T>) -> bool {
    !theta_sq.is_finite() || (theta_sq > T::one() && !(theta_sq * v.norm_squared()).is_finite())
}

/// `exp(ξ)` and `J_r(ξ)` of a finite `ξ = [v; ω]` whose `‖ω‖²` or `θ²‖v‖²` overflows
/// ([`AngleCoeffs::of_huge`]; every `[ω]×ᵏ` written as `θᵏ[u]×ᵏ`, see [`q_block`]):
/// `(exp(ω), v + θb u×v + θ²c u×(u×v))` and `[[J_r(ω), Q(−v, −ω)], [0, J_r(ω)]]`. Out of line
/// and cold: the ordinary path of every caller stays as it was.
#[cold]
#[inline(never)]
fn exp_jac_huge<T: Real>(v: &Vector3<T>, w: &Vector3<T>) -> (Se3<T>, Matrix6<T>) {
    let (k, u) = AngleCoeffs::of_huge(w);
    let jr = skew_poly(T::one(), -k.b_theta(), T::one() - k.a, &u);
    let (b_t, c_t) = (k.b_theta(), (T::one() - k.a) / k.theta);
    // Q(v, ω) with ω = θu (see `q_block`).
    let dot = u.dot(v);
    let g = dot * (b_t - c_t);
    let a = v * c_t + u * (T::lit(0.5) * (b_t - T::lit(3.0) * c_t) * dot);
    let s = v * k.b - u * (dot * (k.b + k.b - k.a));
    let q = q_assemble(&a, &u, &s, g);
    let translation = cross_poly(b_t, T::one() - k.a, &u, v);
    let exp = Se3::from_parts(super::so3::rotation_huge(&k, &u), translation);
    (exp, upper_block(&jr, &q))
}

/// `exp(ξ) = (exp(ω), v + θb u×v + θ²c u×(u×v))` of a finite `ξ` whose `‖ω‖²` or `θ²‖v‖²`
/// overflows (as
/// [`exp_jac_huge`], without the Jacobian).
#[cold]
#[inline(never)]
fn exp_huge<T: Real>(v: &Vector3<T>, w: &Vector3<T>) -> Se3<T> {
    let (k, u) = AngleCoeffs::of_huge(w);
    let translation = cross_poly(k.b_theta(), T::one() - k.a, &u, v);
    Se3::from_parts(super::so3::rotation_huge(&k, &u), translation)
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

    /// `exp(ξ) = (exp(ω), J_l(ω) v)` from the kernel of `ω`.
    fn exp_from(k: &AngleCoeffs<T>, v: &Vector3<T>, w: &Vector3<T>) -> Self {
        Self {
            rotation: So3::exp_from(k, w),
            translation: cross_poly(k.b, k.c, w, v),
        }
    }

    /// `J_r(ξ) = [[J_r(ω), Q(−v, −ω)], [0, J_r(ω)]]` from the kernel of `ω`.
    fn jr_from(k: &AngleCoeffs<T>, v: &Vector3<T>, w: &Vector3<T>) -> Matrix6<T> {
        let jr = skew_poly(T::one(), -k.b, k.c, w);
        // Q(−v, −ω)ᵀ = Q(v, ω).
        upper_block(&jr, &q_block(k, v, w))
    }

    /// `J_r⁻¹(ξ) = [[J, −J Q(−v, −ω) J], [0, J]]`, `J = J_r⁻¹(ω) = I + ½[ω]× + d[ω]×²`, from the
    /// kernel of `ω`.
    fn jr_inv_from(k: &AngleCoeffs<T>, xi: &Vector6<T>) -> Matrix6<T> {
        let (v, w) = split(xi);
        let d = k.d();
        let j = skew_poly(T::one(), T::lit(0.5), d, &w);
        // The upper block transposed: (−J Q(−v, −ω) J)ᵀ = Jᵀ (−Q(v, ω)) Jᵀ, Jᵀ = J(−ω).
        let jt = skew_poly(T::one(), T::lit(-0.5), d, &w);
        let q = -q_block(k, &v, &w);
        upper_block(&j, &mul(&jt, &mul(&q, &jt)))
    }

    /// `log` and the kernel of its rotation angle.
    fn log_with_coeffs(&self) -> (Vector6<T>, AngleCoeffs<T>) {
        let (w, k) = self.rotation.log_with_coeffs();
        // v = J_l⁻¹(ω) t = t − ½ ω×t + d ω×(ω×t).
        let v = cross_poly(T::lit(-0.5), k.d(), &w, &self.translation);
        (Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z), k)
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
        let (v, w) = split(xi);
        let theta_sq = w.norm_squared();
        if needs_scaling(theta_sq, &v) {
            return exp_huge(&v, &w);
        }
        Self::exp_from(&AngleCoeffs::from_theta_sq(theta_sq), &v, &w)
    }

    fn log(&self) -> Vector6<T> {
        self.log_with_coeffs().0
    }

    /// `[[ω]×, v], [0, 0]]`.
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

    /// `(R_a R_b, R_a t_b + t_a)`.
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

    fn act(&self, p: &Vector3<T>) -> Vector3<T> {
        self.rotation.act(p) + self.translation
    }

    /// `[[R, [t]×R], [0, R]]`; the upper block is built transposed, `([t]×R)ᵀ = Rᵀ[−t]×`.
    fn adjoint(&self) -> Matrix6<T> {
        let r = self.rotation.rotation_matrix();
        upper_block(&r, &mul_skew(&r.transpose(), &-self.translation))
    }

    fn right_jacobian(xi: &Vector6<T>) -> Matrix6<T> {
        let (v, w) = split(xi);
        let theta_sq = w.norm_squared();
        if needs_scaling(theta_sq, &v) {
            return exp_jac_huge(&v, &w).1;
        }
        Self::jr_from(&AngleCoeffs::from_theta_sq(theta_sq), &v, &w)
    }

    fn right_jacobian_inv(xi: &Vector6<T>) -> Matrix6<T> {
        let (_, w) = split(xi);
        Self::jr_inv_from(&AngleCoeffs::of_vector(&w), xi)
    }

    /// `[[R, t], [0, 1]]`.
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

    /// Accepts `[[R, t], [0, 1]]` with `Σ|bottom row − (0, 0, 0, 1)| ≤`
    /// [`ORTHOGONALITY_TOLERANCE`], a finite `t`, and `R` accepted by [`So3`]'s
    /// `try_from_matrix`.
    fn try_from_matrix(m: &Matrix4<T>) -> Option<Self> {
        let t = Vector3::new(m.m14, m.m24, m.m34);
        let bottom = m.m41.abs() + m.m42.abs() + m.m43.abs() + (m.m44 - T::one()).abs();
        // Written so that NaN (which compares false) is rejected too.
        if !(bottom <= T::lit(ORTHOGONALITY_TOLERANCE) && all_finite(t.as_slice())) {
            return None;
        }
        let r = So3::try_from_matrix(&Matrix3::new(
            m.m11, m.m12, m.m13, m.m21, m.m22, m.m23, m.m31, m.m32, m.m33,
        ))?;
        Some(Self::from_parts(r, t))
    }

    fn is_finite(&self) -> bool {
        self.rotation.is_finite() && all_finite(self.translation.as_slice())
    }

    /// `exp(ξ)` and `J_r(ξ)` from one kernel.
    fn exp_jac(xi: &Vector6<T>) -> (Self, Matrix6<T>) {
        let (v, w) = split(xi);
        let theta_sq = w.norm_squared();
        if needs_scaling(theta_sq, &v) {
            return exp_jac_huge(&v, &w);
        }
        let k = AngleCoeffs::from_theta_sq(theta_sq);
        (Self::exp_from(&k, &v, &w), Self::jr_from(&k, &v, &w))
    }

    /// `log(T)` and `J_r⁻¹` from the kernel the logarithm found (no trigonometric call).
    fn log_jac(&self) -> (Vector6<T>, Matrix6<T>) {
        let (tau, k) = self.log_with_coeffs();
        (tau, Self::jr_inv_from(&k, &tau))
    }

    /// `(τ = a ⊖ b, J_r⁻¹(τ), −J_l⁻¹(τ) = −J_r⁻¹(−τ))`, all three from the logarithm's kernel
    /// (`−τ` has the same angle).
    fn rminus_jac(&self, b: &Self) -> (Vector6<T>, Matrix6<T>, Matrix6<T>) {
        let (tau, k) = b.between(self).log_with_coeffs();
        (
            tau,
            Self::jr_inv_from(&k, &tau),
            -Self::jr_inv_from(&k, &-tau),
        )
    }

    /// `(R p + t, [R | R[−p]×], R)`: the paper's Theorem 5.1, from SO(3)'s `act_jac`.
    fn act_jac(&self, p: &Vector3<T>) -> (Vector3<T>, Matrix3x6<T>, Matrix3<T>) {
        let (rp, h, r) = self.rotation.act_jac(p);
        let mut j = Matrix3x6::zeros();
        set_block(&mut j, 0, 0, &r);
        set_block(&mut j, 0, 1, &h);
        (rp + self.translation, j, r)
    }
}

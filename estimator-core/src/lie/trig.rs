//! The trigonometric coefficients shared by the exponential maps and Jacobians of SO(3), SE(2)
//! and SE(3), computed once per call from one half-angle `sincos` and reused (the idea of GTSAM's
//! `SO3` kernel).
//!
//! With `θ ≥ 0`, `s = sin(θ/2)`, `c = cos(θ/2)` (so `sin θ = 2sc` and `1 − cos θ = 2s²`, which
//! avoids the cancellation of `1 − cos θ`):
//!
//! | field | closed form | series in `θ²` near 0 |
//! |---|---|---|
//! | `h` (`half_sinc`) | `sin(θ/2)/θ = s/θ` | `1/2 − θ²/48 + θ⁴/3840` |
//! | `a` | `sin θ / θ = 2hc` | (from `h`) |
//! | `b` | `(1 − cos θ)/θ² = 2s²/θ² = 2h²` | (from `h`) |
//! | `c` | `(θ − sin θ)/θ³ = (1 − a)/θ²` | `1/6 − θ²/120 + θ⁴/5040 − θ⁶/362880 + θ⁸/39916800 − θ¹⁰/6227020800` |
//! | `d` | `1/θ² − (1 + cos θ)/(2θ sin θ) = (1 − (θ/2)·c/s)/θ²` | `1/12 + θ²/720 + θ⁴/30240 + θ⁶/1209600 + θ⁸/47900160` |
//!
//! and for SE(3)'s `Q` block ([`SeCoeffs`]):
//!
//! | field | closed form | series |
//! |---|---|---|
//! | `e` | `(1 − θ²/2 − cos θ)/θ⁴ = (b − 1/2)/θ²` | `−1/24 + θ²/720 − θ⁴/40320 + θ⁶/3628800` |
//! | `f` | `e − 3(c − 1/6)/θ²` | `−1/60 + θ²/1260 − θ⁴/60480 + θ⁶/4989600` |
//!
//! `a` and `b` are products of `h` and `cos(θ/2)` (half-angle identities), so they need no
//! branch of their own: `h` is exact to `ε/2` on both sides of its cutoff and each product adds
//! one rounding. Each other coefficient switches to its series below its own cutoff `θ² < x*`, with
//! `x* = `[`taylor_cutoff`]`(ε, t₀, t_omitted, terms)`: the series is then exact to `ε/2`. The
//! cancelling closed forms (`c`, `d`, `e`, `f`) carry more series terms so that their cutoff sits
//! where the cancellation has cost little; their error is relative to a term that is multiplied by
//! `θ²` or `θ⁴` in every use, so the products stay accurate to a few ulps absolutely. `c` is
//! the exception: SE(3)'s `Q` multiplies it by `θ‖v‖` only, so it carries six terms (its cutoff
//! sits at `θ ≈ 0.4` in `f64`, where `1 − a` has lost only a few bits).

use crate::kernels::larger;
use crate::scalar::{taylor_cutoff, Real};
use core::marker::PhantomData;
use nalgebra::Vector3;

/// Small-angle cutoffs (in `θ²`), one per series, derived from `T::EPSILON`.
pub(crate) struct Cutoff<T>(PhantomData<T>);

impl<T: Real> Cutoff<T> {
    pub(crate) const C: f64 =
        taylor_cutoff(T::EPSILON_F64, 1.0 / 6.0, 1.0 / 1_307_674_368_000.0, 6);
    pub(crate) const D: f64 = taylor_cutoff(T::EPSILON_F64, 1.0 / 12.0, 1.0 / 1_892_437_580.0, 5);
    pub(crate) const E: f64 = taylor_cutoff(T::EPSILON_F64, 1.0 / 24.0, 1.0 / 479_001_600.0, 4);
    pub(crate) const F: f64 = taylor_cutoff(T::EPSILON_F64, 1.0 / 60.0, 1.0 / 622_702_080.0, 4);
    /// `sin(θ/2)/θ`: `1/2 − θ²/48 + θ⁴/3840`, omitted `θ⁶/645120`.
    pub(crate) const HALF_SINC: f64 = taylor_cutoff(T::EPSILON_F64, 0.5, 1.0 / 645_120.0, 3);
    /// `(θ/2)·cot(θ/2)`: `1 − θ²/12 − θ⁴/720`, omitted `θ⁶/30240`.
    pub(crate) const HALF_COT: f64 = taylor_cutoff(T::EPSILON_F64, 1.0, 1.0 / 30240.0, 3);
    /// `2·atan(n/w)/n` for the SO(3) log: `(2/w)(1 − n²/(3w²) + n⁴/(5w⁴))`, omitted `n⁶/(7w⁶)`.
    pub(crate) const ATAN_RATIO: f64 = taylor_cutoff(T::EPSILON_F64, 1.0, 1.0 / 7.0, 3);
}

/// `p₀ + p₁x + p₂x² + … + p_{N−1}x^{N−1}` by Horner's rule from the last coefficient:
/// `acc = p_{N−1}`, then `acc = acc·x + pₖ` for `k = N−2, …, 0`.
///
/// The coefficients arrive as `T` (each `T::lit(literal)` folds to a constant of type `T`), so an
/// `f32` evaluation has no `f64` operation (software floating point on a Cortex-M4F).
pub(crate) fn poly<T: Real, const N: usize>(x: T, coeffs: [T; N]) -> T {
    match coeffs.split_last() {
        Some((last, rest)) => rest.iter().rev().fold(*last, |acc, p| acc * x + *p),
        None => T::zero(),
    }
}

/// Coefficients of one rotation angle, shared by exp, the Jacobians and their inverses.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngleCoeffs<T> {
    /// `θ²`.
    pub theta_sq: T,
    /// `θ`.
    pub theta: T,
    /// `sin(θ/2)`.
    pub sin_half: T,
    /// `cos(θ/2)`.
    pub cos_half: T,
    /// `sin(θ/2)/θ`, the vector coefficient of the unit quaternion `exp(θ)`.
    pub half_sinc: T,
    /// `sin θ / θ`.
    pub a: T,
    /// `(1 − cos θ)/θ²`.
    pub b: T,
    /// `(θ − sin θ)/θ³`.
    pub c: T,
}

impl<T: Real> AngleCoeffs<T> {
    /// From `θ²` alone (one `sqrt` and one `sincos` of `θ/2`).
    pub fn from_theta_sq(theta_sq: T) -> Self {
        let theta = theta_sq.sqrt_rn();
        let (sin_half, cos_half) = (theta * T::lit(0.5)).sincos();
        Self::from_half_angle(theta_sq, theta, sin_half, cos_half)
    }

    /// From a rotation vector `ω`: [`Self::from_theta_sq`] of `‖ω‖²` (for a finite `ω` whose
    /// `‖ω‖²` overflows, the callers take [`Self::of_huge`] instead).
    pub fn of_vector(w: &Vector3<T>) -> Self {
        Self::from_theta_sq(w.norm_squared())
    }

    /// From a signed angle `ω` (SE(2)): `θ = |ω|` itself, so that an angle whose square
    /// overflows still has a finite `θ`, sine and cosine (its `θ²` is then infinite: see
    /// [`Self::is_huge`]).
    pub fn of_angle(w: T) -> Self {
        let theta = w.abs();
        let (sin_half, cos_half) = (theta * T::lit(0.5)).sincos();
        Self::from_half_angle(w * w, theta, sin_half, cos_half)
    }

    /// For a finite `ω` whose `‖ω‖²` overflows (`‖ω‖ ≳ 1.8e19` in `f32`, `1.3e154` in `f64`):
    /// the kernel and the unit axis `u = ω/θ`. `θ = m‖ω/m‖` from `ω` scaled by its largest
    /// component `m` (infinite only when `‖ω‖` itself exceeds the largest finite number), the
    /// half angle `(m/2)‖ω/m‖` (always finite) and its sine and cosine, reduced exactly by
    /// [`Real::sincos`], and `θ²` infinite. At such angles one unit in the last place of `θ` is
    /// many turns, so the rotation angle is what that rounding makes it; the axis is kept. The
    /// coefficients stay finite; the users of such a kernel write `[ω]×ᵏ` as `θᵏ[u]×ᵏ`
    /// ([`Self::is_huge`]).
    #[cold]
    #[inline(never)]
    pub fn of_huge(w: &Vector3<T>) -> (Self, Vector3<T>) {
        let m = w.iter().fold(T::zero(), |m, c| larger(m, c.abs()));
        let scaled = w / m;
        let n = scaled.norm_squared().sqrt_rn();
        let (sin_half, cos_half) = (m * T::lit(0.5) * n).sincos();
        (
            Self::from_half_angle(T::lit(f64::INFINITY), m * n, sin_half, cos_half),
            scaled / n,
        )
    }

    /// `θ²` overflowed ([`Self::of_huge`], or [`Self::of_angle`] of a huge angle): every
    /// coefficient is finite, but `[ω]×²` is not, so the Jacobians use `θ b = (1 − cos θ)/θ`
    /// ([`Self::b_theta`]) with `[u]×` and `θ² c = 1 − a` with `[u]×²`, `u = ω/θ`.
    pub fn is_huge(&self) -> bool {
        !self.theta_sq.is_finite()
    }

    /// `θ b = (1 − cos θ)/θ = 2 sin²(θ/2)/θ`, without `b`'s `h²` (which underflows when `θ` is
    /// huge).
    pub fn b_theta(&self) -> T {
        let s = self.sin_half;
        (s * s + s * s) / self.theta
    }

    /// From `θ` and the sine and cosine of `θ/2`, already known (for example the vector norm and
    /// scalar part of a unit quaternion): no trigonometric call at all.
    pub fn from_half_angle(theta_sq: T, theta: T, sin_half: T, cos_half: T) -> Self {
        let half_sinc = half_sinc(theta_sq, theta, sin_half);
        let two_h = half_sinc + half_sinc;
        // sin θ = 2 sin(θ/2) cos(θ/2) and 1 − cos θ = 2 sin²(θ/2), divided by θ and θ².
        let a = two_h * cos_half;
        let b = two_h * half_sinc;
        let c = if theta_sq < T::lit(Cutoff::<T>::C) {
            poly(
                theta_sq,
                [
                    T::lit(1.0 / 6.0),
                    T::lit(-1.0 / 120.0),
                    T::lit(1.0 / 5040.0),
                    T::lit(-1.0 / 362_880.0),
                    T::lit(1.0 / 39_916_800.0),
                    T::lit(-1.0 / 6_227_020_800.0),
                ],
            )
        } else {
            (T::one() - a) / theta_sq
        };
        Self {
            theta_sq,
            theta,
            sin_half,
            cos_half,
            half_sinc,
            a,
            b,
            c,
        }
    }

    /// `d = 1/θ² − (1 + cos θ)/(2θ sin θ)`, the coefficient of `[θ]×²` in `J_r⁻¹`; computed on
    /// demand, since only the inverse Jacobians need it.
    pub fn d(&self) -> T {
        let (theta_sq, theta) = (self.theta_sq, self.theta);
        if theta_sq < T::lit(Cutoff::<T>::D) {
            poly(
                theta_sq,
                [
                    T::lit(1.0 / 12.0),
                    T::lit(1.0 / 720.0),
                    T::lit(1.0 / 30240.0),
                    T::lit(1.0 / 1_209_600.0),
                    T::lit(1.0 / 47_900_160.0),
                ],
            )
        } else {
            (T::one() - half_cot(theta_sq, theta, self.sin_half, self.cos_half)) / theta_sq
        }
    }

    /// `1 − cos θ`, as `2 sin²(θ/2)`.
    pub fn one_minus_cos(&self) -> T {
        let s = self.sin_half;
        s * s + s * s
    }

    /// `cos θ = 1 − 2 sin²(θ/2)`.
    pub fn cos(&self) -> T {
        T::one() - self.one_minus_cos()
    }

    /// The SE(3) coefficients `e`, `f` of the `Q` block.
    pub fn se(&self) -> SeCoeffs<T> {
        let x = self.theta_sq;
        let e = if x < T::lit(Cutoff::<T>::E) {
            poly(
                x,
                [
                    T::lit(-1.0 / 24.0),
                    T::lit(1.0 / 720.0),
                    T::lit(-1.0 / 40320.0),
                    T::lit(1.0 / 3_628_800.0),
                ],
            )
        } else {
            (self.b - T::lit(0.5)) / x
        };
        let f = if x < T::lit(Cutoff::<T>::F) {
            poly(
                x,
                [
                    T::lit(-1.0 / 60.0),
                    T::lit(1.0 / 1260.0),
                    T::lit(-1.0 / 60480.0),
                    T::lit(1.0 / 4_989_600.0),
                ],
            )
        } else {
            e - T::lit(3.0) * (self.c - T::lit(1.0 / 6.0)) / x
        };
        SeCoeffs { e, f }
    }
}

/// SE(3) `Q`-block coefficients (see the module table).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SeCoeffs<T> {
    pub e: T,
    pub f: T,
}

/// `sin(θ/2)/θ` with its series below its cutoff.
pub(crate) fn half_sinc<T: Real>(theta_sq: T, theta: T, sin_half: T) -> T {
    if theta_sq < T::lit(Cutoff::<T>::HALF_SINC) {
        poly(
            theta_sq,
            [T::lit(0.5), T::lit(-1.0 / 48.0), T::lit(1.0 / 3840.0)],
        )
    } else {
        sin_half / theta
    }
}

/// `(θ/2)·cot(θ/2) = (θ/2)·cos(θ/2)/sin(θ/2)`, with its series below its cutoff.
pub(crate) fn half_cot<T: Real>(theta_sq: T, theta: T, sin_half: T, cos_half: T) -> T {
    if theta_sq < T::lit(Cutoff::<T>::HALF_COT) {
        poly(
            theta_sq,
            [T::lit(1.0), T::lit(-1.0 / 12.0), T::lit(-1.0 / 720.0)],
        )
    } else {
        T::lit(0.5) * theta * cos_half / sin_half
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every coefficient is continuous across its cutoff: the series and the closed form agree there
    /// to a few ulps of the quantity each is multiplied into.
    #[test]
    fn series_and_closed_forms_agree_at_their_cutoffs() {
        fn exact(theta: f64) -> [f64; 6] {
            // Reference values by long series in extended steps (θ ≤ 0.7 here): sum many terms.
            let x = theta * theta;
            let mut sin_t = 0.0; // Σ (−1)^k θ^{2k}/(2k+1)!  = sin θ/θ
            let mut omc = 0.0; // Σ (−1)^k θ^{2k}/(2k+2)!  = (1−cos θ)/θ²
            let mut tms = 0.0; // Σ (−1)^k θ^{2k}/(2k+3)!  = (θ−sin θ)/θ³
            let mut term_a = 1.0;
            let mut term_b = 0.5;
            let mut term_c = 1.0 / 6.0;
            for k in 0..30 {
                sin_t += term_a;
                omc += term_b;
                tms += term_c;
                let k = k as f64;
                term_a *= -x / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
                term_b *= -x / ((2.0 * k + 3.0) * (2.0 * k + 4.0));
                term_c *= -x / ((2.0 * k + 4.0) * (2.0 * k + 5.0));
            }
            // e = (b − 1/2)/θ² = Σ_{k≥1} (−1)^k θ^{2k-2}/(2k+2)!, f = e − 3(c − 1/6)/θ².
            let mut e = 0.0;
            let mut f_tail = 0.0;
            let mut te = -1.0 / 24.0;
            let mut tc = -1.0 / 120.0;
            for k in 1..30 {
                e += te;
                f_tail += tc;
                let k = k as f64;
                te *= -x / ((2.0 * k + 3.0) * (2.0 * k + 4.0));
                tc *= -x / ((2.0 * k + 4.0) * (2.0 * k + 5.0));
            }
            let f = e - 3.0 * f_tail;
            // d = (1 − (θ/2)cot(θ/2))/θ²: from (1 − cos θ) and sin θ: (θ/2)cot(θ/2) = θ sinθ/(2(1−cosθ)).
            let d = (1.0 - sin_t / (2.0 * omc)) / x;
            [sin_t, omc, tms, d, e, f]
        }
        for theta in [1e-3, 5e-3, 0.01, 0.02, 0.05, 0.1, 0.2, 0.4, 0.6, 0.7] {
            let k = AngleCoeffs::<f64>::from_theta_sq(theta * theta);
            let se = k.se();
            let r = exact(theta);
            let got = [k.a, k.b, k.c, k.d(), se.e, se.f];
            // The cancelling coefficients multiply θ² (c, d) or θ⁴ (e, f) wherever they are used.
            let weight = [
                1.0,
                1.0,
                theta * theta,
                theta * theta,
                theta.powi(4),
                theta.powi(4),
            ];
            for i in 0..6 {
                if i == 3 && theta < 0.2 {
                    // d's reference above is itself a cancelling closed form; compare with its series.
                    let x = theta * theta;
                    let series = 1.0 / 12.0 + x / 720.0 + x * x / 30240.0 + x.powi(3) / 1_209_600.0;
                    assert!((got[3] - series).abs() * x <= 4.0 * f64::EPSILON);
                    continue;
                }
                let err = (got[i] - r[i]).abs() * weight[i];
                assert!(
                    err <= 8.0 * f64::EPSILON,
                    "coef {i} θ={theta}: {} vs {}",
                    got[i],
                    r[i]
                );
            }
        }
    }

    /// Horner's rule errs by at most `γ_{2(N−1)} Σ|pₖ||x|ᵏ` (Higham, *Accuracy and Stability of
    /// Numerical Algorithms*, eq. 5.3), against the sum taken in `f64` for `f32` coefficients.
    #[test]
    fn poly_is_horner_within_its_error_bound() {
        let c = [
            1.0 / 6.0,
            -1.0 / 120.0,
            1.0 / 5040.0,
            -1.0 / 362_880.0,
            0.3,
            -7.0,
        ];
        let gamma = |k: f64| k * f64::from(f32::EPSILON) / (1.0 - k * f64::from(f32::EPSILON));
        for i in 0..=400 {
            let x = f64::from(i) * 0.01;
            let xf = x as f32;
            let cf = c.map(|p| p as f32);
            let xe = f64::from(xf);
            let terms = |n: usize| {
                cf.iter()
                    .take(n)
                    .enumerate()
                    .map(|(k, p)| f64::from(*p) * xe.powi(k as i32))
            };
            let check = |got: f32, n: usize| {
                let exact: f64 = terms(n).sum();
                let bound = gamma(2.0 * (n as f64 - 1.0)) * terms(n).map(f64::abs).sum::<f64>();
                assert!(
                    (f64::from(got) - exact).abs() <= bound,
                    "{x} {n}: {got} vs {exact}"
                );
            };
            check(poly(xf, [cf[0], cf[1], cf[2]]), 3);
            check(poly(xf, [cf[0], cf[1], cf[2], cf[3]]), 4);
            check(poly(xf, [cf[0], cf[1], cf[2], cf[3], cf[4]]), 5);
            check(poly(xf, cf), 6);
        }
    }

    #[test]
    fn cutoffs_are_ordered_sensibly() {
        // f32 cutoffs are wider than f64's; all are positive and inside every series' radius of
        // convergence (the smallest is d's: θ < 2π).
        for (c32, c64) in [
            (Cutoff::<f32>::HALF_SINC, Cutoff::<f64>::HALF_SINC),
            (Cutoff::<f32>::C, Cutoff::<f64>::C),
            (Cutoff::<f32>::D, Cutoff::<f64>::D),
            (Cutoff::<f32>::F, Cutoff::<f64>::F),
        ] {
            assert!(
                c64 > 0.0 && c32 > c64 && c32 < 4.0 * core::f64::consts::PI.powi(2),
                "{c32} {c64}"
            );
        }
    }
}

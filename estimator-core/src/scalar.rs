//! The scalar type every estimator type is generic over: `f32` or `f64`.
//!
//! [`Real`] is nalgebra's [`RealField`] plus the few things this crate needs that nalgebra does not
//! give in the right form:
//!
//! * [`Real::EPSILON_F64`], the machine epsilon as an `f64`, from which every small-angle threshold
//!   in [`crate::lie`] is derived at compile time ([`taylor_cutoff`]); there is no global epsilon.
//! * [`Real::lit`], a literal conversion that folds to a constant of type `T`, so that `f32` code
//!   never performs an `f64` operation at run time (on a Cortex-M4F that would be software
//!   floating point).
//! * [`Real::sincos`], sine and cosine of one angle. For `f64` it is `libm::sincos`. For `f32` it
//!   is [`sincos_f32`], computed entirely in `f32`: `libm::sinf`/`cosf` reduce and evaluate in
//!   `f64` internally, which a Cortex-M4F emulates in software.
//! * `x.sqrt_rn()`, the crate's square root (a method of the sealed supertrait, so that
//!   nalgebra's `x.sqrt()` stays unambiguous): for `f32` [`sqrt_f32`], correctly rounded like
//!   `libm::sqrtf` and smaller and faster on a Cortex-M4F; for `f64` `libm::sqrt`.

use nalgebra::RealField;

mod sealed {
    /// Seals [`Real`](super::Real), and carries the crate's own square root, `x.sqrt_rn()`:
    /// nalgebra's `ComplexField::sqrt` is the method that `x.sqrt()` finds, so a second `sqrt`
    /// on `Real` would make every such call ambiguous (here and in users' generic code).
    pub trait Sealed: Copy {
        /// `√self`, correctly rounded, with IEEE 754's special values: [`super::sqrt_f32`] for
        /// `f32`, `libm::sqrt` for `f64`. Being correctly rounded, it equals nalgebra's `sqrt`
        /// (`libm` or `std`, both correctly rounded) on every target.
        fn sqrt_rn(self) -> Self;
    }
    impl Sealed for f32 {
        fn sqrt_rn(self) -> Self {
            super::sqrt_f32(self)
        }
    }
    impl Sealed for f64 {
        fn sqrt_rn(self) -> Self {
            libm::sqrt(self)
        }
    }
}

// The finiteness and sign tests live in `crate::kernels`; re-exported for the modules that
// import them from here.

/// A real scalar: `f32` or `f64` (sealed).
pub trait Real: RealField + Copy + sealed::Sealed {
    /// Machine epsilon of `Self` (`2⁻²³` for `f32`, `2⁻⁵²` for `f64`), widened to `f64` so that
    /// thresholds can be computed in `const` context.
    const EPSILON_F64: f64;

    /// The largest variance a filter holds, `√MAX` rounded down (`1.8e19` for `f32`, `1.3e154`
    /// for `f64`), as an `f64`: the product of any two such variances (a covariance's
    /// `P_ii P_jj`, a gain's `P H² P`) stays finite.
    const VARIANCE_CEILING_F64: f64;

    /// The smallest variance a filter holds, `√MIN_POSITIVE` rounded up (`1.1e-19` for `f32`,
    /// `1.5e-154` for `f64`), as an `f64`: the product of any two such variances stays a
    /// normal number, with its full relative precision (a subnormal variance has lost it: at
    /// `5e-324` there is one bit left).
    const VARIANCE_FLOOR_F64: f64;

    /// Converts a literal: `T::lit(1.0 / 6.0)` folds to a constant of type `T`.
    fn lit(x: f64) -> Self;

    /// `(sin x, cos x)` computed in `Self`'s own precision.
    fn sincos(self) -> (Self, Self);

    /// `atan2(self, x)`: the angle of the point `(x, self)` in `[−π, π]`, with IEEE 754's
    /// signed zeros and infinities. For `f64` it is `libm::atan2`; for `f32` it is
    /// [`atan2_f32`] (smaller and faster than `libm::atan2f` on a Cortex-M4F).
    fn arctan2(self, x: Self) -> Self;

    /// Widens to `f64` (for casts between precisions, tests and host tools; never on an `f32`
    /// hot path).
    fn to_f64(self) -> f64;

    /// Converts a count (a nanosecond interval, a number of samples), rounding to nearest: one
    /// instruction on a Cortex-M4F for `f32`, no `f64` on the way.
    fn from_count(x: u32) -> Self;

    /// Converts to a count, truncating toward zero and saturating: `0` for a negative value or
    /// NaN, `u32::MAX` above it. One instruction on a Cortex-M4F for `f32`.
    fn to_count(self) -> u32;
}

impl Real for f64 {
    const EPSILON_F64: f64 = f64::EPSILON;
    const VARIANCE_CEILING_F64: f64 = 1.3e154;
    const VARIANCE_FLOOR_F64: f64 = 1.5e-154;

    fn lit(x: f64) -> Self {
        x
    }

    fn sincos(self) -> (Self, Self) {
        libm::sincos(self)
    }

    fn arctan2(self, x: Self) -> Self {
        libm::atan2(self, x)
    }

    fn to_f64(self) -> f64 {
        self
    }

    fn from_count(x: u32) -> Self {
        f64::from(x)
    }

    fn to_count(self) -> u32 {
        self as u32
    }
}

impl Real for f32 {
    const EPSILON_F64: f64 = f32::EPSILON as f64;
    const VARIANCE_CEILING_F64: f64 = 1.8e19;
    const VARIANCE_FLOOR_F64: f64 = 1.1e-19;

    fn lit(x: f64) -> Self {
        x as f32
    }

    fn sincos(self) -> (Self, Self) {
        sincos_f32(self)
    }

    fn arctan2(self, x: Self) -> Self {
        atan2_f32(self, x)
    }

    fn to_f64(self) -> f64 {
        self as f64
    }

    fn from_count(x: u32) -> Self {
        x as f32
    }

    fn to_count(self) -> u32 {
        self as u32
    }
}

/// `(sin x, cos x)` in pure `f32` arithmetic (no `f64` operation at all).
///
/// Method (Cody–Waite reduction, as in Cephes `sinf`/`cosf`): `j` = `|x|·4/π` rounded up to
/// even, so that `z = |x| − j·π/4 ∈ [−π/4, π/4]`, with `π/4` split in three parts whose products
/// with `j` are exact for `|x| < 8192`; then the minimax polynomials
/// `sin z ≈ z + z³·P(z²)` and `cos z ≈ 1 − z²/2 + z⁴·Q(z²)` and the quadrant `j/2 mod 4`.
///
/// Accuracy, measured against `f64` in the tests of this module: absolute error at most `2⁻²³`
/// (one `f32` epsilon) for `|x| ≤ 8192`, and a relative error under one epsilon for
/// `|x| < π/4`. Beyond `|x| = 8192` the argument is first reduced modulo the `f32` value of `2π`
/// (an exact `fmod`, but that `2π` is off by `1.7e-7`), so the phase error grows like
/// `|x|·2.8e-8`; the result stays finite with `sin² + cos² ≈ 1`. Non-finite input gives
/// `(NaN, NaN)`.
#[must_use]
pub fn sincos_f32(x: f32) -> (f32, f32) {
    const FOUR_OVER_PI: f32 = 1.273_239_5;
    // π/4 = DP1 + DP2 + DP3, DP1 and DP2 with few significant bits so that j·DP1, j·DP2 are exact.
    const DP1: f32 = 0.785_156_25;
    const DP2: f32 = 2.418_756_5e-4;
    const DP3: f32 = 3.774_895e-8;

    let ax = libm::fabsf(x);
    let ax = if ax > 8192.0 { reduce_large(ax) } else { ax };
    // Saturating float-to-int conversion: NaN gives 0, huge values give u32::MAX (then masked).
    let j = (ax * FOUR_OVER_PI) as u32;
    let j = j.wrapping_add(j & 1);
    let y = j as f32;
    let z = ((ax - y * DP1) - y * DP2) - y * DP3;
    let zz = z * z;
    let s = z + z * zz * ((-1.951_529_6e-4 * zz + 8.332_161e-3) * zz - 1.666_665_5e-1);
    let c =
        1.0 - 0.5 * zz + zz * zz * ((2.443_315_7e-5 * zz - 1.388_731_6e-3) * zz + 4.166_664_6e-2);
    let (sin_ax, cos_ax) = match (j >> 1) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    };
    let sin_x = if x < 0.0 { -sin_ax } else { sin_ax };
    if x.is_finite() {
        (sin_x, cos_ax)
    } else {
        (f32::NAN, f32::NAN)
    }
}

/// `atan2(y, x)` in pure `f32` arithmetic: the angle of the point `(x, y)` in `[−π, π]`.
///
/// Method: with `t = min(|x|, |y|) / max(|x|, |y|) ∈ [0, 1]`, `atan t` is `atan u` with `u = t`
/// up to `tan(π/8)`, and `π/4 + atan u` with `u = (t − 1)/(t + 1)` above (the reduction of Cephes
/// `atanf`), where `atan u ≈ u + u³·P(u²)` for `|u| ≤ tan(π/8)`: `P` of degree 4 interpolates
/// `(atan √z / √z − 1)/z` at the five Chebyshev nodes of `z ∈ [0, tan²(π/8)]` (relative error
/// `2.8e-9` with the coefficients rounded to `f32`, a twentieth of an `f32` ulp). The parts of
/// `π/4`, `π/2`, `π` that their `f32` values miss are added to the small terms first. Then the quadrant
/// (`π − a` when `x` is negative, `−0` included; `π/2 ∓ a` when `|y| > |x|`) and the sign of `y`.
/// IEEE 754's special cases hold: `atan2(±0, +0) = ±0`, `atan2(±0, −0) = ±π`, infinities give
/// the multiples of `π/4`, and `NaN` in gives `NaN`.
///
/// Accuracy, measured against `f64` in the tests of this module: at most 2 units in the last
/// place of the result (1.85 measured, against 1.44 for `libm::atan2f`). Smaller code than
/// `libm::atan2f` + `atanf`, which split `[0, ∞)` into five intervals, with one more polynomial
/// degree.
#[must_use]
pub fn atan2_f32(y: f32, x: f32) -> f32 {
    use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    // The parts of π/4, π/2, π that their `f32` values miss (`c − f32(c)`, rounded).
    const FRAC_PI_4_LO: f32 = -2.185_569_4e-8;
    const FRAC_PI_2_LO: f32 = -4.371_139e-8;
    const PI_LO: f32 = -8.742_278e-8;
    const TAN_PI_8: f32 = 0.414_213_57;
    if y.is_nan() || x.is_nan() {
        return y + x;
    }
    let (ay, ax) = (y.abs(), x.abs());
    let steep = ay > ax;
    let (num, den) = if steep { (ax, ay) } else { (ay, ax) };
    // u = (t − 1)/(t + 1) from num and den directly (t = num/den would round once more), halved
    // first when large so that num + den cannot overflow (exact: both are then ≥ 0.4).
    let (hi, lo, u) = if den == 0.0 {
        (0.0, 0.0, 0.0) // both zero
    } else if num == den {
        (FRAC_PI_4, FRAC_PI_4_LO, 0.0) // t = 1, also for two infinities
    } else if num > TAN_PI_8 * den {
        let (n, d) = if den > 1.0 {
            (num * 0.5, den * 0.5)
        } else {
            (num, den)
        };
        (FRAC_PI_4, FRAC_PI_4_LO, (n - d) / (n + d))
    } else {
        (0.0, 0.0, num / den)
    };
    let z = u * u;
    let p = (((-6.451_928e-2 * z + 1.074_373_1e-1) * z - 1.426_395_6e-1) * z + 1.999_954e-1) * z
        - 3.333_333e-1;
    // The constant's missing part joins the small terms before the one rounding against it.
    let a = hi + (u + (p * z * u + lo));
    let a = match (steep, x.is_sign_negative()) {
        (false, false) => a,
        (false, true) => PI - (a - PI_LO),
        (true, false) => FRAC_PI_2 - (a - FRAC_PI_2_LO),
        (true, true) => FRAC_PI_2 + (a + FRAC_PI_2_LO),
    };
    a.copysign(y)
}

/// `√x` in `f32`, correctly rounded (IEEE 754 round to nearest) for every input, without a
/// table and without `f64`. The Cortex-M4F's `vsqrt.f32` is out of reach from stable safe Rust
/// (`f32::sqrt` is `std`-only, `core`'s is unstable), and `libm::sqrtf` there is an integer
/// routine with a table. This one has no table and is shorter: 38 instructions on the path of a
/// positive normal number, two of them `vdiv.f32`. Special values as IEEE 754:
/// `√±0 = ±0`, `√+∞ = +∞`, `NaN` for `NaN` and for every number below zero (`−∞` included).
///
/// Method. A positive normal `x = m·2^(e−150)` (`m` the 24-bit significand, `e` the biased
/// exponent) is `f·4^k` with `f = m·2⁻²³ ∈ [1, 2)` when `e` is odd and `f = m·2⁻²² ∈ [2, 4)`
/// when it is even; the significand of `√x = √f·2^k` is then `√N` rounded to an integer,
/// `N = f·2⁴⁶ < 2⁴⁸`.
///
/// 1. `f` is `x` with its exponent field replaced by 127 or 128. With `j = bits(x) + 125·2²³`
///    (the exponent arithmetic of step 3, done first) the low 24 bits of `j` are already
///    `f`'s significand and the low bit of its exponent field, so `bits(f) = (j mod 2²⁴) +
///    bits(1.0)`.
/// 2. `t₀ = 0.6875 + 0.34375·f` (relative error at most 3.1 %), one Heron step
///    `t₁ = c·(t₀ + f/t₀)` with `c = 0.49988` a little under `½`, which centres Heron's
///    one-sided error (at most `4.9e-4` with `½`) on zero, and a last Heron step
///    `y = t₁ + f/t₁ ≈ 2√f ∈ [2, 4]`, whose bits less those of `1.0` are the integer
///    `q = y·2²²`. The exhaustive test over `[1, 4)` finds `q − round(√N) ∈ {−1, 0, 1}`.
/// 3. Exact correction in integers: `d = N − q²` is small (`|d| < 3q < 2³¹`), so the low
///    32 bits of `N` (those of `m·2²³` or `m·2²⁴`) and a wrapping `q·q` give it exactly. `q` is
///    the correctly rounded root iff `(q − ½)² < N < (q + ½)²`, that is `−q < d ≤ q` (`N` is
///    an integer, so a tie `N = (q ± ½)²` never happens); otherwise it is `q + 1` (`d > q`) or
///    `q − 1` (`d ≤ −q`). The result's bits are `q` plus the exponent `⌊(e + 125)/2⌋·2²³`, the
///    top byte of `j` shifted down by one (`q = 2²⁴` carries into the exponent, as it should).
///
/// A subnormal `x = i·2⁻¹⁴⁹` first becomes the `f32` of the integer `2i < 2²⁴` (exact), an
/// exponent 150 too high in the field: subtracting `150·2²³` (a multiple of `2²⁴`, so the low
/// 24 bits stay) lets the same arithmetic run on a field that has gone negative.
#[must_use]
pub fn sqrt_f32(x: f32) -> f32 {
    let mut i = x.to_bits();
    // Everything but a positive normal number: ±0, subnormals, below zero, +∞ and NaN.
    if i.wrapping_sub(0x0080_0000) >= 0x7f00_0000 {
        if i.wrapping_sub(1) >= 0x007f_ffff {
            // Not a positive subnormal: ±0 and +∞ are their own roots, a NaN stays NaN
            // (quieted by the addition), below zero is NaN.
            return if i > 0x8000_0000 { f32::NAN } else { x + x };
        }
        i = ((i << 1) as f32).to_bits().wrapping_sub(150 << 23);
    }
    let j = i.wrapping_add(125 << 23);
    let fb = (j & 0x00ff_ffff) + 0x3f80_0000;
    let f = f32::from_bits(fb);
    let t = 0.6875 + 0.34375 * f;
    let t = 0.49988 * (t + f / t);
    let q = (t + f / t).to_bits().wrapping_sub(0x3f80_0000);
    // The low 32 bits of N = m·2^(23 or 24): f ≥ 2 (bit 30 of its bits) when the shift is 24.
    let n = (j << 23) << (fb >> 30);
    let d = n.wrapping_sub(q.wrapping_mul(q)) as i32;
    let q = q as i32;
    let mut r = (j >> 24 << 23).wrapping_add(q as u32);
    if d > q {
        r = r.wrapping_add(1);
    }
    if d.wrapping_add(q) <= 0 {
        r = r.wrapping_sub(1);
    }
    f32::from_bits(r)
}

/// `x mod 2π` (`x ≥ 0`; non-finite in gives non-finite out) for the rare huge argument: the
/// exact `fmodf(x, 2π_f32)`, by binary long division on floats (`libm::fmodf` is an integer
/// routine that links 64-bit division into the firmware).
///
/// With `d = 2π·2^k` the largest such multiple `≤ x`, each step subtracts `d` when `r ≥ d` and
/// halves `d`. The invariant `r < 2d` makes every subtraction exact (Sterbenz: `d ≤ r ≤ 2d`),
/// and halving is exact, so the result is `x − m·2π` exactly, `0 ≤ r < 2π`. At most 128
/// doublings and 128 halvings (the `f32` exponent range). Cold: the common path never pays for
/// it.
#[cold]
fn reduce_large(x: f32) -> f32 {
    const TAU: f32 = core::f32::consts::TAU;
    if !x.is_finite() {
        return x;
    }
    let mut d = TAU;
    // `2d` overflows to infinity before it could exceed a finite `x`, which ends the loop.
    while d * 2.0 <= x {
        d *= 2.0;
    }
    let mut r = x;
    while d >= TAU {
        if r >= d {
            r -= d;
        }
        d *= 0.5;
    }
    r
}

/// The largest `x = θ²` at which a truncated Taylor series is exact to half an epsilon.
///
/// A coefficient `f(θ) = Σ_k t_k θ^{2k}` evaluated with its first `terms` terms errs by about the
/// first omitted term `t_terms · x^terms`. Requiring `|t_terms| x^terms ≤ (ε/2)|t_0|` gives
/// `x ≤ (ε |t_0| / (2 |t_terms|))^{1/terms}`. Each small-angle branch in [`crate::lie`] calls this
/// with its own series, so every threshold follows from `T::EPSILON` and from that series.
#[must_use]
pub const fn taylor_cutoff(epsilon: f64, leading: f64, omitted: f64, terms: u32) -> f64 {
    let leading = if leading < 0.0 { -leading } else { leading };
    let omitted = if omitted < 0.0 { -omitted } else { omitted };
    const_root(0.5 * epsilon * leading / omitted, terms)
}

/// `x^{1/n}` for `x > 0`, `n ≥ 1`, by Newton's iteration in `const` context (start above the root
/// so the iteration decreases monotonically; it stops when it no longer decreases).
const fn const_root(x: f64, n: u32) -> f64 {
    if n <= 1 || x <= 0.0 {
        return x;
    }
    let mut y = if x > 1.0 { x } else { 1.0 };
    let nf = n as f64;
    let mut i = 0;
    while i < 10_000 {
        let mut p = 1.0; // y^{n-1}
        let mut k = 1;
        while k < n {
            p *= y;
            k += 1;
        }
        let next = ((nf - 1.0) * y + x / p) / nf;
        if next >= y {
            break;
        }
        y = next;
        i += 1;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn const_root_inverts_power() {
        for &(x, n) in &[(2.0, 2), (1e-16, 6), (3.5e-7, 3), (8.0, 3), (1e-300, 4)] {
            let r = const_root(x, n);
            let back = (0..n).fold(1.0, |acc, _| acc * r);
            assert!(
                (back - x).abs() <= 4.0 * f64::EPSILON * x,
                "{x} {n} {r} {back}"
            );
        }
    }

    #[test]
    fn taylor_cutoff_bounds_the_omitted_term() {
        // sin θ/θ with three terms: omitted −θ⁶/5040 must be ≤ ε/2 at the cutoff.
        let x = taylor_cutoff(f64::EPSILON, 1.0, 1.0 / 5040.0, 3);
        assert!((x * x * x / 5040.0 - 0.5 * f64::EPSILON).abs() < 1e-3 * f64::EPSILON);
    }

    /// Error of `sincos_f32` against `f64`, sampled densely; also the relative error near zero.
    #[test]
    fn sincos_f32_matches_f64() {
        let mut worst_abs = 0.0f64;
        let n = 400_000;
        for i in 0..=n {
            let x = -8192.0 + 16384.0 * (i as f64) / (n as f64);
            let xf = x as f32;
            let (s, c) = sincos_f32(xf);
            let xe = xf as f64;
            worst_abs = worst_abs.max((s as f64 - xe.sin()).abs());
            worst_abs = worst_abs.max((c as f64 - xe.cos()).abs());
        }
        assert!(worst_abs <= f32::EPSILON as f64, "abs {worst_abs}");
        let mut worst_rel = 0.0f64;
        for i in 1..=100_000 {
            let xf = (i as f32) * (core::f32::consts::FRAC_PI_4 / 100_000.0);
            for x in [xf, -xf, xf * 1e-6, xf * 1e-30] {
                let (s, _) = sincos_f32(x);
                let e = (x as f64).sin();
                worst_rel = worst_rel.max(((s as f64 - e) / e).abs());
            }
        }
        assert!(worst_rel <= f32::EPSILON as f64, "rel {worst_rel}");
    }

    /// The float long division of `reduce_large` is the exact `fmod` (`%`).
    #[test]
    fn reduce_large_is_exact_fmod() {
        let tau = core::f32::consts::TAU;
        let mut x = 8192.0f32;
        while x.is_finite() {
            for k in 0..64 {
                let y = x * (1.0 + k as f32 * 0.013_7);
                if y.is_finite() {
                    assert_eq!(reduce_large(y).to_bits(), (y % tau).to_bits(), "{y}");
                }
            }
            x *= 1.9;
        }
        assert_eq!(reduce_large(f32::MAX).to_bits(), (f32::MAX % tau).to_bits());
        assert!(reduce_large(f32::INFINITY).is_infinite());
        assert!(reduce_large(f32::NAN).is_nan());
    }

    /// Error of `atan2_f32` in units of the last place of the correctly rounded result, over
    /// every direction (dense in angle), radii from `1e-30` to `1e30`, and near the axes.
    #[test]
    fn atan2_f32_matches_f64() {
        // (1.85 ulp measured; `libm::atan2f` gives 1.44 on the same points.)
        let ulps = |y: f32, x: f32| {
            let e = (y as f64).atan2(x as f64);
            let r = e as f32;
            let ulp = f32::from_bits(r.abs().to_bits() + 1) - r.abs();
            ((atan2_f32(y, x) as f64 - e) / ulp as f64).abs()
        };

        let mut worst = 0.0f64;
        let mut at = (0.0f32, 0.0f32);
        let n = 200_000;
        for i in 0..n {
            let th = -core::f64::consts::PI + 2.0 * core::f64::consts::PI * (i as f64) / (n as f64);
            for r in [1e-30, 1e-3, 1.0, 7.5, 1e30, 3e38] {
                let (y, x) = ((r * th.sin()) as f32, (r * th.cos()) as f32);
                if ulps(y, x) > worst {
                    (worst, at) = (ulps(y, x), (y, x));
                }
            }
        }
        for k in 0..2000 {
            let s = 1e-7f32 * (k as f32 + 0.5);
            for (y, x) in [
                (s, 1.0),
                (-s, 1.0),
                (s, -1.0),
                (-s, -1.0),
                (1.0, s),
                (1.0, -s),
            ] {
                if ulps(y, x) > worst {
                    (worst, at) = (ulps(y, x), (y, x));
                }
            }
        }
        assert!(worst <= 2.0, "{worst} ulp at {at:?}");
    }

    /// IEEE 754's special values of `atan2`, as `f64`'s `atan2` gives them.
    #[test]
    fn atan2_f32_special_values() {
        let inf = f32::INFINITY;
        let vals = [0.0, -0.0, 1.0, -1.0, 1e-45, inf, -inf];
        for &y in &vals {
            for &x in &vals {
                let got = atan2_f32(y, x);
                let want = (y as f64).atan2(x as f64) as f32;
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "atan2({y}, {x}) = {got}, not {want}"
                );
            }
        }
        assert!(atan2_f32(f32::NAN, 1.0).is_nan());
        assert!(atan2_f32(0.0, f32::NAN).is_nan());
    }

    /// `sqrt_rn` gives nalgebra's `sqrt` bit for bit (here `std`'s, correctly rounded like the
    /// `libm` one the firmware links), in both precisions, signed zeros included; NaN where
    /// nalgebra gives NaN.
    #[test]
    fn sqrt_rn_matches_nalgebra_sqrt() {
        use crate::test_support::Rng;
        use nalgebra::ComplexField;
        // A correctly rounded square root has one right answer: equal bits (any NaN for NaN).
        fn check<T: Real>(x: T) {
            let (got, want) = (x.sqrt_rn().to_f64(), ComplexField::sqrt(x).to_f64());
            let same = got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan());
            assert!(same, "{x:?}: {got:?}, not {want:?}");
        }
        let mut rng = Rng::new(17);
        for _ in 0..200_000 {
            let x = rng.range(-1.0, 1.0);
            let scale = 10f64.powi((rng.range(-1.0, 1.0) * 45.0) as i32);
            for v in [x * scale, x / scale, x, x * 1e300, x * 1e-300, x * 1e-40] {
                check(v);
                check(v as f32);
            }
        }
        let specials = [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
        ];
        for v in specials {
            check(v);
            check(v as f32);
        }
        check(f32::from_bits(1));
        check(f64::from_bits(1));
    }

    #[test]
    fn sincos_f32_non_finite_is_nan() {
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let (s, c) = sincos_f32(x);
            assert!(s.is_nan() && c.is_nan());
        }
        let (s, c) = sincos_f32(3.0e38);
        assert!(s.is_finite() && c.is_finite());
    }
}

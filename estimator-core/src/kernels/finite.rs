//! Finiteness and sign tests, branch-free over slices.

use crate::Real;

/// `true` when every element of `s` is finite: `Σ xᵢ·0 = 0`. One out-of-line copy for every
/// length.
///
/// `x·0` is `±0` for a finite `x` and NaN for `±∞` or NaN (IEEE 754-2008 §7.2: `0·∞` is an
/// invalid operation); NaN propagates through the sum and `−0 = +0` in the comparison. Two
/// floating-point instructions per element and no branch, over the contiguous storage.
#[inline(never)]
#[must_use]
pub(crate) fn all_finite<T: Real>(s: &[T]) -> bool {
    let z = T::zero();
    s.iter().fold(z, |acc, x| acc + *x * z) == z
}

/// `0 < x < ∞` (false for NaN): the test of a positive-definite pivot or a norm. Two
/// floating-point comparisons: `x > 0`, and `x·0 = 0`, which is false for `∞` and NaN (see
/// [`all_finite`]).
#[inline(always)]
#[must_use]
pub(crate) fn positive_finite<T: Real>(x: T) -> bool {
    x > T::zero() && x * T::zero() == T::zero()
}

/// `x` is a variance a filter may take in: at least [`Real::VARIANCE_FLOOR_F64`] and at most
/// [`Real::VARIANCE_CEILING_F64`] (so finite and normal; NaN fails). Checked where a
/// covariance enters a filter (its constructors, resets and widenings).
#[inline(always)]
pub(crate) fn usable_variance<T: Real>(x: T) -> bool {
    x >= T::lit(T::VARIANCE_FLOOR_F64) && x <= T::lit(T::VARIANCE_CEILING_F64)
}

/// `x` is positive and at most [`Real::VARIANCE_CEILING_F64`] (NaN fails): the check on the
/// variances a prediction or an update computes from ones [`usable_variance`] let in. A
/// prediction only adds to them, and an update leaves each measured combination at least the
/// noise floor's fraction of its prior (`update/gain.rs`), so a comparison with zero (one
/// instruction on a Cortex-M4F, where the floor needs its constant loaded, on every variance
/// of the hot path) is what is left to check.
#[inline(always)]
pub(crate) fn positive_variance<T: Real>(x: T) -> bool {
    x > T::zero() && x <= T::lit(T::VARIANCE_CEILING_F64)
}

/// The larger of `a` and `b`, `a` when `b` is NaN: a comparison and a select. `f32::max` is
/// a call of `libm`'s `fmaxf` on a Cortex-M4F (no `vmaxnm` before ARMv8). Folded from a
/// number over a sequence, NaN elements are passed over, as with `fmax`.
#[inline(always)]
#[must_use]
pub(crate) fn larger<T: Real>(a: T, b: T) -> T {
    if b > a {
        b
    } else {
        a
    }
}

/// `0 ≤ x < ∞` (false for NaN), as [`positive_finite`].
#[inline(always)]
#[must_use]
pub(crate) fn non_negative_finite<T: Real>(x: T) -> bool {
    x >= T::zero() && x * T::zero() == T::zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_finite_agrees_with_is_finite_for_every_special_value() {
        let specials = [
            0.0,
            -0.0,
            1.0,
            -f64::MAX,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &a in &specials {
            for &b in &specials {
                let s = [1.0, a, -2.0, b];
                assert_eq!(all_finite(&s), s.iter().all(|x| x.is_finite()), "{a} {b}");
                let s32 = s.map(|x| x as f32);
                assert_eq!(all_finite(&s32), s32.iter().all(|x| x.is_finite()));
            }
        }
        assert!(all_finite::<f64>(&[]));
    }

    #[test]
    fn larger_is_max_and_passes_over_nan() {
        for (a, b, want) in [
            (1.0, 2.0, 2.0),
            (2.0, 1.0, 2.0),
            (-0.5, -3.0, -0.5),
            (1.0, f64::NAN, 1.0),
        ] {
            assert_eq!(larger(a, b), want, "{a} {b}");
        }
        let folded = [3.0, f64::NAN, 7.0, -1.0]
            .iter()
            .fold(0.0, |m, x| larger(m, *x));
        assert_eq!(folded, 7.0);
    }

    #[test]
    fn sign_tests_refuse_nan_and_infinity() {
        for (x, pos, nonneg) in [
            (1.0, true, true),
            (5e-324, true, true),
            (0.0, false, true),
            (-0.0, false, true),
            (-1.0, false, false),
            (f64::INFINITY, false, false),
            (f64::NAN, false, false),
        ] {
            assert_eq!(positive_finite(x), pos, "{x}");
            assert_eq!(non_negative_finite(x), nonneg, "{x}");
        }
    }
}

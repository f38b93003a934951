//! Helpers shared by the unit tests of the crate (`#[cfg(test)]` only): a deterministic number
//! stream and the bit-for-bit comparisons of the rewrite tests (`lie/rewrites.rs`,
//! `eskf/rewrites.rs`, `gn/rewrites.rs`).

use crate::Real;
use nalgebra::Vector3;

/// Deterministic numbers in `[-1, 1)` (64-bit LCG).
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64) / ((1u64 << 52) as f64) - 1.0
    }

    /// A vector of three such numbers times `scale`.
    pub(crate) fn vector<T: Real>(&mut self, scale: f64) -> Vector3<T> {
        Vector3::new(self.next(), self.next(), self.next()).map(|x| T::lit(scale * x))
    }
}

/// One number of every class, as `f64` (`T::lit` rounds them into `f32`): signed zeros,
/// subnormals of `f64` and `f32`, ±1, the edges of `f32`'s range, ±`f64::MAX`, the infinities
/// and both `NaN` signs. The finiteness and sign tests of the rewrites run on these.
pub(crate) fn every_class() -> [f64; 17] {
    [
        0.0,
        -0.0,
        1e-310,
        -1e-310,
        1e-45,
        -1e-45,
        1.0,
        -1.0,
        3.4e38,
        -3.4e38,
        1e300,
        f64::MAX,
        -f64::MAX,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        -f64::NAN,
    ]
}

/// Equal bits, entry by entry (any two `NaN`s count as equal).
pub(crate) fn same_bits<T: Real>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            let (x, y) = (x.to_f64(), y.to_f64());
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
        })
}

/// Equal bits, except that `0.0` and `−0.0` count as equal (a rewrite that builds a negated
/// block directly no longer negates its structural zeros), and any two `NaN`s do.
pub(crate) fn same_up_to_zero_sign<T: Real>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            let (x, y) = (x.to_f64(), y.to_f64());
            x.to_bits() == y.to_bits() || x == y || (x.is_nan() && y.is_nan())
        })
}

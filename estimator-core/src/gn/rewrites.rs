//! The size-driven rewrites of `gn` (scalar forms, shared helpers) against the straightforward
//! nalgebra code they replace: the same bits (and the same errors), `f32` and `f64`.

use super::*;
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Vector2, Vector3};

/// Deterministic numbers in `[-1, 1)` (64-bit LCG).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64) / ((1u64 << 52) as f64) - 1.0
    }

    fn vector<T: Real>(&mut self, scale: f64) -> Vector3<T> {
        Vector3::new(self.next(), self.next(), self.next()).map(|x| T::lit(scale * x))
    }
}

/// Equal bits, entry by entry (any two `NaN`s count as equal).
fn same<T: Real>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            let (x, y) = (x.to_f64(), y.to_f64());
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
        })
}

/// [`check_point_spread`] before the scalar sums: nalgebra's `sum += p`, `sum * inv_n`, `p − mean`.
fn check_point_spread_before<T: Real>(points: &[Vector3<T>]) -> Result<(), SolveError> {
    let n = points.len();
    if n == 0 {
        return Err(SolveError::DegenerateGeometry);
    }
    let count = T::from_usize(n).unwrap_or_else(T::one);
    let inv_n = T::one() / count;
    let mut sum = Vector3::zeros();
    for p in points {
        sum += p;
    }
    let mean = sum * inv_n;
    let [mut s11, mut s22, mut s33, mut s12, mut s13, mut s23] = [T::zero(); 6];
    for p in points {
        let d = p - mean;
        s11 += d.x * d.x;
        s22 += d.y * d.y;
        s33 += d.z * d.z;
        s12 += d.x * d.y;
        s13 += d.x * d.z;
        s23 += d.y * d.z;
    }
    let tr = s11 + s22 + s33;
    let i2 = s11 * s22 - s12 * s12 + s11 * s33 - s13 * s13 + s22 * s33 - s23 * s23;
    let scale = mean.x * mean.x + mean.y * mean.y + mean.z * mean.z + T::one();
    let spread = tr > T::lit(1e-12) * count * scale;
    let not_collinear = i2 > T::lit(1e-10) * tr * tr;
    if spread && not_collinear {
        Ok(())
    } else {
        Err(SolveError::DegenerateGeometry)
    }
}

/// Point sets of every kind: spread, nearly collinear, nearly coincident, far from the origin,
/// with non-finite entries, and the empty set.
fn point_spread<T: Real>() {
    let mut rng = Lcg(3);
    let (mut ok, mut degenerate) = (0, 0);
    for i in 0..600 {
        let n = i % 9;
        let offset = rng.vector::<T>([0.0, 1.0, 1e3, 1e6][i % 4]);
        let dir = rng.vector::<T>(1.0);
        let mut pts = [Vector3::<T>::zeros(); 8];
        for (k, p) in pts.iter_mut().enumerate().take(n) {
            let along = dir * T::lit(k as f64);
            let across = rng.vector::<T>([1.0, 1e-4, 1e-6, 1e-9, 0.0][i % 5]);
            *p = offset + along + across;
        }
        if i % 97 == 5 {
            pts[0].y = T::lit(f64::NAN);
        }
        if i % 89 == 7 {
            pts[1].x = T::lit(f64::INFINITY);
        }
        let pts = &pts[..n];
        let got = check_point_spread(pts);
        assert_eq!(got, check_point_spread_before(pts), "{i}");
        if got.is_ok() {
            ok += 1;
        } else {
            degenerate += 1;
        }
    }
    assert!(ok > 100 && degenerate > 100, "{ok} {degenerate}");
}

#[test]
fn check_point_spread_is_the_nalgebra_form() {
    point_spread::<f32>();
    point_spread::<f64>();
}

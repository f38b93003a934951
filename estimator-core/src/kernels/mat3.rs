//! 3×3 and 3-vector products, unrolled for a generic scalar.
//!
//! nalgebra's `Matrix3 * Matrix3` goes through its generic GEMM loop for a generic `T`; these
//! write the sums out (`(a_i1 b_1j + a_i2 b_2j) + a_i3 b_3j`, within `γ₃ Σ|a_ik b_kj|` of the
//! exact product, `γ₃ = 3ε/(1 − 3ε)`), so that they inline into a handful of instructions.

use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// `a·b`: `(ab)_ij = a_i1 b_1j + a_i2 b_2j + a_i3 b_3j`.
#[must_use]
pub(crate) fn mul<T: Real>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    let column = |x: T, y: T, z: T| mul_vec(a, &Vector3::new(x, y, z));
    Matrix3::from_columns(&[
        column(b.m11, b.m21, b.m31),
        column(b.m12, b.m22, b.m32),
        column(b.m13, b.m23, b.m33),
    ])
}

/// `a·v`: `(av)_i = a_i1 v_1 + a_i2 v_2 + a_i3 v_3`.
#[must_use]
pub(crate) fn mul_vec<T: Real>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::new(
        a.m11 * v.x + a.m12 * v.y + a.m13 * v.z,
        a.m21 * v.x + a.m22 * v.y + a.m23 * v.z,
        a.m31 * v.x + a.m32 * v.y + a.m33 * v.z,
    )
}

/// `‖v‖ = √(v·v)` through the crate's correctly rounded square root ([`Real::sqrt_rn`]);
/// nalgebra's `norm` would link `libm`'s table-driven `sqrtf` into a Cortex-M4F firmware.
#[inline(always)]
#[must_use]
pub(crate) fn norm<T: Real>(v: &Vector3<T>) -> T {
    // By components: nalgebra's `norm_squared` walks column views, whose bounds check an
    // opt-level "z" build may keep out of line (a panic path the firmware check refuses).
    (v.x * v.x + v.y * v.y + v.z * v.z).sqrt_rn()
}

/// `a bᵀ + b aᵀ`, exactly symmetric (`(ab)_ij + (ba)_ij` is computed once per pair).
#[must_use]
pub(crate) fn sym_outer<T: Real>(a: &Vector3<T>, b: &Vector3<T>) -> Matrix3<T> {
    let e = |ai: T, bj: T, bi: T, aj: T| ai * bj + bi * aj;
    let (xy, xz, yz) = (
        e(a.x, b.y, b.x, a.y),
        e(a.x, b.z, b.x, a.z),
        e(a.y, b.z, b.y, a.z),
    );
    Matrix3::new(
        e(a.x, b.x, b.x, a.x),
        xy,
        xz,
        xy,
        e(a.y, b.y, b.y, a.y),
        yz,
        xz,
        yz,
        e(a.z, b.z, b.z, a.z),
    )
}

/// `y + a·x` for 3-vectors.
#[must_use]
pub(crate) fn axpy<T: Real>(y: &Vector3<T>, a: T, x: &Vector3<T>) -> Vector3<T> {
    Vector3::new(y.x + x.x * a, y.y + x.y * a, y.z + x.z * a)
}

/// `a·[p]×`, the product with the skew-symmetric matrix of `p` (`[p]× x = p × x`): row `i`
/// is `(aᵢ × p)ᵀ`, `aᵢ` the row `i` of `a`, since `xᵀ[p]× = (x × p)ᵀ`: two products per entry,
/// the three zeros of `[p]×` never multiplied.
#[must_use]
pub(crate) fn mul_skew<T: Real>(a: &Matrix3<T>, p: &Vector3<T>) -> Matrix3<T> {
    let row = |x: T, y: T, z: T| (y * p.z - z * p.y, z * p.x - x * p.z, x * p.y - y * p.x);
    let (a11, a12, a13) = row(a.m11, a.m12, a.m13);
    let (a21, a22, a23) = row(a.m21, a.m22, a.m23);
    let (a31, a32, a33) = row(a.m31, a.m32, a.m33);
    Matrix3::new(a11, a12, a13, a21, a22, a23, a31, a32, a33)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::Rng;

    /// Each entry is a sum of three products: `|fl(Σ) − Σ| ≤ γ₃ Σ|a||b|` (Higham §3.1), and
    /// nalgebra's product rounds the same way, so two such results differ by at most twice that.
    #[test]
    fn mul_and_mul_vec_agree_with_nalgebra_within_gamma3() {
        let mut rng = Rng::new(7);
        let gamma3 = 3.0 * f64::EPSILON / (1.0 - 3.0 * f64::EPSILON);
        for _ in 0..1000 {
            let a = Matrix3::from_fn(|_, _| rng.range(-1.0, 1.0) * 10.0);
            let b = Matrix3::from_fn(|_, _| rng.range(-1.0, 1.0) * 10.0);
            let v = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0));
            let bound = (a.abs() * b.abs()) * (2.0 * gamma3);
            let d = (mul(&a, &b) - a * b).abs();
            assert!(d.iter().zip(bound.iter()).all(|(d, b)| d <= b));
            let bound = (a.abs() * v.abs()) * (2.0 * gamma3);
            let d = (mul_vec(&a, &v) - a * v).abs();
            assert!(d.iter().zip(bound.iter()).all(|(d, b)| d <= b));
        }
    }

    /// Each entry is `a_i b_j + b_i a_j`, two products and a sum, within
    /// `γ₂ (|a_i b_j| + |b_i a_j|)` of the exact value, as is nalgebra's `a bᵀ + b aᵀ`; the two
    /// differ by at most twice that, and the result is exactly symmetric.
    #[test]
    fn sym_outer_agrees_with_nalgebra_within_gamma2_and_is_symmetric() {
        let mut rng = Rng::new(9);
        let gamma2 = 2.0 * f64::EPSILON / (1.0 - 2.0 * f64::EPSILON);
        for _ in 0..1000 {
            let a = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0) * 10.0);
            let b = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0) * 10.0);
            let m = sym_outer(&a, &b);
            assert_eq!(m, m.transpose());
            let bound =
                (a.abs() * b.abs().transpose() + b.abs() * a.abs().transpose()) * (2.0 * gamma2);
            let d = (m - (a * b.transpose() + b * a.transpose())).abs();
            assert!(d.iter().zip(bound.iter()).all(|(d, b)| d <= b));
        }
    }

    #[test]
    fn axpy_is_one_rounding_per_product_and_sum() {
        let mut rng = Rng::new(8);
        for _ in 0..1000 {
            let y = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0));
            let x = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0));
            let a = rng.range(-1.0, 1.0);
            let exact = y + x * a;
            // y + x·a is the same two roundings in either form.
            assert_eq!(axpy(&y, a, &x), exact);
        }
    }

    /// Each entry is a difference of two products, `|fl − exact| ≤ γ₂ Σ|terms|`; nalgebra's
    /// product with the skew matrix adds a third, zero product and errs by at most `γ₃` of the
    /// same sum, so the two differ by at most `2γ₃ (|a|·|[p]×|)` entrywise.
    #[test]
    fn mul_skew_agrees_with_the_product_by_the_skew_matrix_within_gamma3() {
        let mut rng = Rng::new(9);
        let gamma3 = 3.0 * f64::EPSILON / (1.0 - 3.0 * f64::EPSILON);
        for _ in 0..1000 {
            let a = Matrix3::from_fn(|_, _| rng.range(-1.0, 1.0) * 10.0);
            let p = Vector3::from_fn(|_, _| rng.range(-1.0, 1.0) * 3.0);
            let skew = Matrix3::new(0.0, -p.z, p.y, p.z, 0.0, -p.x, -p.y, p.x, 0.0);
            let bound = (a.abs() * skew.abs()) * (2.0 * gamma3);
            let d = (mul_skew(&a, &p) - a * skew).abs();
            assert!(d.iter().zip(bound.iter()).all(|(d, b)| d <= b));
        }
    }
}

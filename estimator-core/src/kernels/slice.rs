//! Vector kernels over slices: one compiled copy for every length.

use crate::Real;

/// `Σ xᵢ yᵢ` over the common length, from zero, left to right.
#[must_use]
pub(crate) fn dot<T: Real>(x: &[T], y: &[T]) -> T {
    x.iter().zip(y).fold(T::zero(), |acc, (&p, &q)| acc + p * q)
}

/// `y ← y + a·x` over the common length.
pub(crate) fn axpy<T: Real>(y: &mut [T], a: T, x: &[T]) {
    for (y, &x) in y.iter_mut().zip(x) {
        *y += a * x;
    }
}

/// The whole columns of the column-major storage `a` with `rows` rows, in order (none when
/// `rows` is 0). The run-time matrices are walked through this, never with
/// `chunks_exact(rows)`: a chunk iterator divides its length by the chunk size, and that
/// division's panic path is removed only where the optimizer inlines it; this one splits
/// the slice off column by column (`split_at_checked`) and cannot panic.
pub(crate) fn columns<T>(a: &[T], rows: usize) -> Columns<'_, T> {
    Columns { rest: a, rows }
}

/// The iterator of [`columns`].
pub(crate) struct Columns<'a, T> {
    rest: &'a [T],
    rows: usize,
}

impl<'a, T> Iterator for Columns<'a, T> {
    type Item = &'a [T];

    fn next(&mut self) -> Option<&'a [T]> {
        if self.rows == 0 {
            return None;
        }
        let (column, rest) = self.rest.split_at_checked(self.rows)?;
        self.rest = rest;
        Some(column)
    }
}

/// `out ← A x` for the column-major `out.len() × x.len()` matrix `a`.
pub(crate) fn mat_vec<T: Real>(a: &[T], x: &[T], out: &mut [T]) {
    out.fill(T::zero());
    let rows = out.len();
    for (col, xj) in columns(a, rows).zip(x) {
        axpy(out, *xj, col);
    }
}

/// `‖a − b‖₂` over the common length.
#[must_use]
pub(crate) fn distance<T: Real>(a: &[T], b: &[T]) -> T {
    a.iter()
        .zip(b)
        .fold(T::zero(), |acc, (x, y)| {
            let d = *x - *y;
            acc + d * d
        })
        .sqrt_rn()
}

/// `A ← (A + Aᵀ)/2` for the column-major `n × n` storage `a`: both `a_ij` and `a_ji` get
/// `(a_ij + a_ji)·½` (the sum commutes, so the result is exactly symmetric).
pub(crate) fn symmetrize<T: Real>(a: &mut [T], n: usize) {
    let half = T::lit(0.5);
    for c in 0..n {
        for r in c + 1..n {
            let (Some(&x), Some(&y)) = (a.get(c * n + r), a.get(r * n + c)) else {
                continue;
            };
            let s = (x + y) * half;
            if let Some(v) = a.get_mut(c * n + r) {
                *v = s;
            }
            if let Some(v) = a.get_mut(r * n + c) {
                *v = s;
            }
        }
    }
}

/// `dst ← srcᵀ`, `dst_vec ← src_vec`: the column-major `rows × cols` matrix in `src`
/// (`rows = src_vec.len()`, `cols = src.len() / rows`) written transposed into the column-major
/// storage `dst` with `cols` rows, and the vector `src_vec` copied into `dst_vec`; the rest of
/// `dst` and `dst_vec` is set to zero (a measurement's `H` and residual into a padded working
/// set).
#[inline(never)]
pub(crate) fn transpose_into<T: Real>(src: &[T], src_vec: &[T], dst: &mut [T], dst_vec: &mut [T]) {
    dst_vec.fill(T::zero());
    for (d, s) in dst_vec.iter_mut().zip(src_vec) {
        *d = *s;
    }
    let rows = src_vec.len();
    let cols = src.len().checked_div(rows).unwrap_or(0);
    dst.fill(T::zero());
    for (j, col) in columns(src, rows).enumerate() {
        for (i, v) in col.iter().enumerate() {
            if let Some(e) = dst.get_mut(i * cols + j) {
                *e = *v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::Rng;
    use nalgebra::{DMatrix, DVector};

    fn gamma(k: usize) -> f64 {
        let k = k as f64 * f64::EPSILON;
        k / (1.0 - k)
    }

    /// `|fl(xᵀy) − xᵀy| ≤ γ_n Σ|xᵢ yᵢ|` (Higham §3.1), against nalgebra's `dot`.
    #[test]
    fn dot_axpy_distance_agree_with_nalgebra_within_gamma_n() {
        let mut rng = Rng::new(3);
        for n in 1..20 {
            let x = DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0) * 5.0);
            let y = DVector::from_fn(n, |_, _| rng.range(-1.0, 1.0) * 5.0);
            let s: f64 = x.iter().zip(y.iter()).map(|(a, b)| (a * b).abs()).sum();
            assert!((dot(x.as_slice(), y.as_slice()) - x.dot(&y)).abs() <= 2.0 * gamma(n) * s);

            let a = rng.range(-1.0, 1.0);
            let mut z = y.clone();
            axpy(z.as_mut_slice(), a, x.as_slice());
            assert_eq!(z, &y + &x * a); // one product and one sum per entry, either way

            let d = (&x - &y).norm();
            let bound = 2.0 * gamma(n + 2) * d;
            assert!((distance(x.as_slice(), y.as_slice()) - d).abs() <= bound);
        }
    }

    #[test]
    fn transpose_into_is_the_transpose_padded_with_zeros() {
        let m = nalgebra::Matrix2x3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        let (mut out, mut v) = ([9.0; 9], [9.0; 3]);
        transpose_into(m.as_slice(), &[7.0, 8.0], &mut out, &mut v);
        assert_eq!(&out[..6], m.transpose().as_slice());
        assert_eq!(&out[6..], &[0.0; 3]);
        assert_eq!(v, [7.0, 8.0, 0.0]);
    }

    #[test]
    fn mat_vec_is_the_matrix_vector_product() {
        let a = nalgebra::Matrix3x2::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        let x = nalgebra::Vector2::new(0.5, -1.0);
        let mut out = [0.0; 3];
        mat_vec(a.as_slice(), x.as_slice(), &mut out);
        assert_eq!(out.as_slice(), (a * x).as_slice());
    }

    #[test]
    fn symmetrize_gives_the_symmetric_part() {
        let mut rng = Rng::new(4);
        for n in 1..8 {
            let m = DMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
            let mut s = m.clone();
            symmetrize(s.as_mut_slice(), n);
            assert_eq!(s, s.transpose());
            let expected = (&m + m.transpose()) * 0.5;
            assert!((s - expected).amax() <= f64::EPSILON);
        }
    }
}

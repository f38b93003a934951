//! 3×3 blocks of fixed-size matrices, read and written through checked storage indices.
//!
//! Block `(i, j)` of an `R × C` matrix is rows `3i..3i+3`, columns `3j..3j+3`. nalgebra's
//! `fixed_view` asserts its bounds (a panic path); these read zeros and write nothing outside
//! the matrix, which no caller reaches.

use crate::Real;
use nalgebra::{Matrix3, SMatrix};

/// Block `(i, j)` of `m` (zero outside the matrix).
#[must_use]
pub(crate) fn block<T: Real, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
    i: usize,
    j: usize,
) -> Matrix3<T> {
    block_in(m.as_slice(), R, i, j)
}

/// Block `(i, j)` of the column-major matrix with `rows` rows stored in `s` (zero outside it).
#[must_use]
pub(crate) fn block_in<T: Real>(s: &[T], rows: usize, i: usize, j: usize) -> Matrix3<T> {
    let mut out = Matrix3::zeros();
    if 3 * i + 3 > rows {
        return out;
    }
    for (c, dst) in out.data.0.iter_mut().enumerate() {
        let start = rows * (3 * j + c) + 3 * i;
        if let Some(src) = s.get(start..start + 3) {
            copy(dst, src);
        }
    }
    out
}

/// `dst[k] = src[k]` over the common length: `copy_from_slice` without its panic on a length
/// mismatch (which only the optimizer removes).
pub(crate) fn copy<T: Copy>(dst: &mut [T], src: &[T]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}

/// Writes `v` into block `(i, j)` of `m` (nothing outside the matrix).
pub(crate) fn set_block<T: Real, const R: usize, const C: usize>(
    m: &mut SMatrix<T, R, C>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    if 3 * i + 3 > R {
        return;
    }
    for (c, src) in v.data.0.iter().enumerate() {
        let s = R * (3 * j + c) + 3 * i;
        if let Some(dst) = m.as_mut_slice().get_mut(s..s + 3) {
            copy(dst, src);
        }
    }
}

/// Adds `s·I` to block `(i, j)` of the square `m`, and to block `(j, i)` when `i ≠ j` (a
/// symmetric update of a covariance).
pub(crate) fn add_scaled_identity<T: Real, const N: usize>(
    m: &mut SMatrix<T, N, N>,
    i: usize,
    j: usize,
    s: T,
) {
    for k in 0..3 {
        if let Some(x) = m.get_mut((3 * i + k, 3 * j + k)) {
            *x += s;
        }
        if i != j {
            if let Some(x) = m.get_mut((3 * j + k, 3 * i + k)) {
                *x += s;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    #[test]
    fn block_and_set_block_match_fixed_view_and_ignore_out_of_range() {
        let m = SMatrix::<f64, 9, 6>::from_fn(|r, c| (10 * r + c) as f64);
        for i in 0..3 {
            for j in 0..2 {
                assert_eq!(
                    block(&m, i, j),
                    m.fixed_view::<3, 3>(3 * i, 3 * j).into_owned()
                );
                let mut w = m;
                let v = Matrix3::from_fn(|r, c| -((r + 3 * c) as f64));
                set_block(&mut w, i, j, &v);
                let mut expected = m;
                expected.fixed_view_mut::<3, 3>(3 * i, 3 * j).copy_from(&v);
                assert_eq!(w, expected);
            }
        }
        assert_eq!(block(&m, 3, 0), Matrix3::zeros());
        assert_eq!(block(&m, 0, 2), Matrix3::zeros());
        let mut w = m;
        set_block(&mut w, 3, 0, &Matrix3::identity());
        set_block(&mut w, 0, 2, &Matrix3::identity());
        assert_eq!(w, m);
    }

    #[test]
    fn add_scaled_identity_is_symmetric() {
        let mut m = SMatrix::<f64, 6, 6>::zeros();
        add_scaled_identity(&mut m, 0, 1, 2.0);
        add_scaled_identity(&mut m, 1, 1, 3.0);
        let mut expected = SMatrix::<f64, 6, 6>::zeros();
        for k in 0..3 {
            expected[(k, 3 + k)] = 2.0;
            expected[(3 + k, k)] = 2.0;
            expected[(3 + k, 3 + k)] = 3.0;
        }
        assert_eq!(m, expected);
    }
}

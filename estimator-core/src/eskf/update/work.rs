//! The working set one update fills in place, phase by phase.

use crate::Real;
use nalgebra::{SMatrix, SVector, Vector3};

/// The working set of one update, on the caller's stack and filled in place by the phases.
/// `N × C` matrices hold one column per measurement row; columns and rows past `m` are zero.
pub(super) struct Work<T: Real, const N: usize, const C: usize> {
    /// `H̃ᵀ` at the current iterate.
    pub(super) ht: SMatrix<T, N, C>,
    /// Residual `r = z ⊖ h(x̂ ⊕ δx)` at the current iterate.
    pub(super) r: SVector<T, C>,
    /// `W` and `L` at the current iterate ([`Gain`]).
    pub(super) g: Gain<T, N, C>,
    /// The current correction `δx`.
    pub(super) dx: SVector<T, N>,
    /// The number of active rows, `M`.
    pub(super) m: usize,
}

/// The gain part of the working set, saved and restored as one block by the iterated update.
impl<T: Real, const N: usize, const C: usize> Work<T, N, C> {
    /// Zeros, `L = I`, `m` active rows. Out of line: built inline, the `Gain` is a temporary
    /// copied into place, which opt-level "s" keeps in the update's frame, on its deepest stack
    /// path; returned, it is written straight into the caller's slot.
    #[inline(never)]
    pub(super) fn new(m: usize) -> Self {
        Self {
            ht: SMatrix::zeros(),
            r: SVector::zeros(),
            g: Gain {
                w: SMatrix::zeros(),
                l: SMatrix::identity(),
            },
            dx: SVector::zeros(),
            m,
        }
    }
}

#[derive(Clone, Copy)]
pub(super) struct Gain<T: Real, const N: usize, const C: usize> {
    /// `W = P H̃ᵀ L⁻ᵀ` (`U = P H̃ᵀ` while it is computed): `K = W L⁻¹`, `P⁺ = P − W Wᵀ`.
    pub(super) w: SMatrix<T, N, C>,
    /// `L`, the Cholesky factor of `S = H̃ P H̃ᵀ + R_eff` (lower triangle; identity past `m`).
    pub(super) l: SMatrix<T, C, C>,
}

/// The attitude part `δθ` (entries 0..3) of an error vector or of a column of `Hᵀ`.
pub(super) fn attitude_part<T: Real>(s: &[T]) -> Vector3<T> {
    match s.get(0..3) {
        Some(&[a, b, c]) => Vector3::new(a, b, c),
        _ => Vector3::zeros(),
    }
}

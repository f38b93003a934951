//! Hand-written small-matrix routines over fixed storage: the one home of every loop that
//! `lie`, `eskf` and `gn` would otherwise write by hand.
//!
//! Why they exist: nalgebra's generic expressions are the first choice everywhere else, but a
//! few operations need what nalgebra does not give on a microcontroller — an index that can
//! never panic (`fixed_view` asserts its bounds), one compiled copy for every run-time
//! dimension (the Cholesky factor of a 3×3 innovation and of a 6×6 information matrix), or a
//! 3×3 product unrolled for a generic scalar.
//!
//! Inline policy, set by measurement on a Cortex-M4F (instruction counts at opt-level 3, flash
//! at opt-level `s`): the sign tests and the 3-vector operations are `#[inline(always)]`; the
//! routines over a run-time dimension that no prediction runs in its inner loop are
//! `#[inline(never)]`, one copy for every size (`all_finite`, the Cholesky factor, solve and
//! inverse, the padded copy of a measurement's rows), and beside them the 3 × 3 factor of the
//! update core's innovation covariance (`spd_factor_3`, the same loops with a constant
//! dimension, unrolled); the 3×3 product, the blocks and the slice
//! loops are left to the compiler, which inlines them where they are hot. The only other inline
//! attributes of the crate keep the measurement update's phases in stack frames of their own
//! (`eskf::update`).
//!
//! Every routine has a reference test here that compares it with the nalgebra expression it
//! stands for, within a bound derived from the floating-point error of the operation
//! (`γ_k = k ε / (1 − k ε)` for a sum of `k` products, Higham, *Accuracy and Stability of
//! Numerical Algorithms*, §3.1), never bit for bit.
//!
//! Storage is nalgebra's: column-major, entry `(i, j)` of an `R × C` matrix at `j·R + i`.

pub(crate) mod block;
pub(crate) mod cholesky;
pub(crate) mod finite;
pub(crate) mod mat3;
pub(crate) mod slice;

pub(crate) use finite::{
    all_finite, larger, non_negative_finite, positive_finite, positive_variance, usable_variance,
};

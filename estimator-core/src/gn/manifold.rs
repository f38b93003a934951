//! The state spaces the solver works on: any Lie group of [`crate::lie`], Euclidean vectors, and
//! products of two of them (e.g. a pose and a point).

use crate::lie::{LieGroup, Se2, Se3, So2, So3};
use crate::Real;
use nalgebra::SVector;

/// A state with `N` degrees of freedom and the retraction `⊕` of eq. 4.5 of *Lie Groups and
/// Smooth Manifolds for Robotic State Estimation*, `a ⊕ ξ = a·exp(ξ^)`.
///
/// For a Lie group `a ⊕ ξ = a · exp(ξ^)` (the right perturbation of [`crate::lie`]); for `Rⁿ`,
/// `a ⊕ ξ = a + ξ`; for a product, each factor takes its own slice of `ξ`.
pub trait Manifold<T: Real, const N: usize>: Copy {
    /// `a ⊕ ξ`.
    #[must_use]
    fn oplus(&self, xi: &SVector<T, N>) -> Self;

    /// `true` when every stored number is finite.
    #[must_use]
    fn all_finite(&self) -> bool;
}

macro_rules! lie_manifold {
    ($g:ident, $n:literal) => {
        impl<T: Real> Manifold<T, $n> for $g<T> {
            fn oplus(&self, xi: &SVector<T, $n>) -> Self {
                self.rplus(xi)
            }
            fn all_finite(&self) -> bool {
                self.is_finite()
            }
        }
    };
}

lie_manifold!(So2, 1);
lie_manifold!(Se2, 3);
lie_manifold!(So3, 3);
lie_manifold!(Se3, 6);

impl<T: Real, const N: usize> Manifold<T, N> for SVector<T, N> {
    fn oplus(&self, xi: &SVector<T, N>) -> Self {
        self + xi
    }
    fn all_finite(&self) -> bool {
        crate::kernels::all_finite(self.as_slice())
    }
}

/// The product manifold `A × B` with `NA + NB` degrees of freedom; the tangent is `[ξ_a; ξ_b]`
/// and `(a, b) ⊕ [ξ_a; ξ_b] = (a ⊕ ξ_a, b ⊕ ξ_b)`.
///
/// It implements [`Manifold<T, N>`] for `N = NA + NB` only: any other `N` is rejected at compile
/// time (a `const` assertion evaluated when the impl is instantiated).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Product<A, B, const NA: usize, const NB: usize> {
    /// The first factor.
    pub a: A,
    /// The second factor.
    pub b: B,
}

impl<A, B, const NA: usize, const NB: usize> Product<A, B, NA, NB> {
    /// `(a, b)`.
    #[must_use]
    pub fn new(a: A, b: B) -> Self {
        Self { a, b }
    }

    /// Splits `[ξ_a; ξ_b]` (entries beyond `NA + NB` are ignored, missing ones are zero; the
    /// `Manifold` impl guarantees `N = NA + NB` at compile time).
    #[must_use]
    pub fn split<T: Real, const N: usize>(xi: &SVector<T, N>) -> (SVector<T, NA>, SVector<T, NB>) {
        let entry = |k: usize| xi.get(k).copied().unwrap_or_else(T::zero);
        (
            SVector::from_fn(|r, _| entry(r)),
            SVector::from_fn(|r, _| entry(NA + r)),
        )
    }
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Manifold<T, N>
    for Product<A, B, NA, NB>
where
    T: Real,
    A: Manifold<T, NA>,
    B: Manifold<T, NB>,
{
    fn oplus(&self, xi: &SVector<T, N>) -> Self {
        const {
            assert!(
                N == NA + NB,
                "Product<A, B, NA, NB> has NA + NB degrees of freedom"
            )
        };
        let (xa, xb) = Self::split(xi);
        Self {
            a: self.a.oplus(&xa),
            b: self.b.oplus(&xb),
        }
    }
    fn all_finite(&self) -> bool {
        self.a.all_finite() && self.b.all_finite()
    }
}

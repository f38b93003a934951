//! Robust losses `ρ(s)` of the squared whitened residual `s = ‖e‖²_Σ`, applied as iteratively
//! reweighted least squares (IRLS).
//!
//! The solver minimizes `F(a) = Σᵢ ρ(sᵢ)`. At a linearization point each block gets the weight
//! `wᵢ = ρ'(sᵢ)` and the step solves the weighted normal equations `Hᵀ W H ξ = Hᵀ W (z − h(a))`.
//! Because both losses below are concave in `s`, `ρ(s) ≤ ρ(s₀) + ρ'(s₀)(s − s₀)`: the weighted
//! quadratic model majorizes the robust cost, so a step that lowers the model lowers `F`.
//!
//! | loss | `ρ(s)` | `w(r) = ρ'(s)`, `r = √s` |
//! |---|---|---|
//! | least squares | `s` | `1` |
//! | Huber, scale `k` | `s` if `r ≤ k`, else `2kr − k²` | `1` if `r ≤ k`, else `k / r` |
//! | Cauchy, scale `k` | `k² ln(1 + s/k²)` | `1 / (1 + s/k²)` |
//!
//! The scale `k` is in the units of the *whitened* residual (standard deviations). The
//! camera-facing functions ([`crate::gn::solve_pnp`], …) take it in pixels and divide by
//! `sigma_px`.

use crate::Real;

/// A robust loss; see the module docs for `ρ` and its IRLS weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Loss<T: Real> {
    /// Plain least squares, `ρ(s) = s`.
    LeastSquares,
    /// Huber with threshold `k > 0`: quadratic inside `k`, linear outside.
    Huber(T),
    /// Cauchy (Lorentzian) with scale `k > 0`: logarithmic, weight `→ 0` for gross outliers.
    Cauchy(T),
}

impl<T: Real> Loss<T> {
    /// `true` when the scale (if any) is finite and positive.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        match *self {
            Self::LeastSquares => true,
            Self::Huber(k) | Self::Cauchy(k) => super::all_positive(&[k]),
        }
    }

    /// The same loss with its scale multiplied by `factor` (used to turn a scale in pixels into
    /// one in standard deviations).
    #[must_use]
    pub fn scaled(&self, factor: T) -> Self {
        match *self {
            Self::LeastSquares => Self::LeastSquares,
            Self::Huber(k) => Self::Huber(k * factor),
            Self::Cauchy(k) => Self::Cauchy(k * factor),
        }
    }

    /// `(ρ(s), ρ'(s))` for a squared whitened residual `s ≥ 0`.
    #[must_use]
    pub fn evaluate(&self, s: T) -> (T, T) {
        match *self {
            Self::LeastSquares => (s, T::one()),
            Self::Huber(k) => {
                if s <= k * k {
                    (s, T::one())
                } else {
                    let r = s.sqrt_rn();
                    (T::lit(2.0) * k * r - k * k, k / r)
                }
            }
            Self::Cauchy(k) => {
                let k2 = k * k;
                let q = T::one() + s / k2;
                (k2 * q.ln(), T::one() / q)
            }
        }
    }
}

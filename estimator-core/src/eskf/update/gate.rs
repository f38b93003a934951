//! Chi-square gate on the normalized innovation squared.
//!
//! For a Gaussian innovation `r ~ N(0, S)` of dimension `m`, `NIS = rᵀ S⁻¹ r` (the squared
//! Mahalanobis distance of *Lie Groups and Smooth Manifolds for Robotic State Estimation*,
//! eq. 4.1 / Remark 4.2) is chi-square with `m` degrees of freedom. The
//! gate accepts when `NIS ≤ χ²_m(p)`. Quantiles for `m = 1..6` are tabulated (exact to 6
//! significant digits); above 6 the Wilson–Hilferty approximation
//! `χ²_m(p) ≈ m (1 − 2/(9m) + z_p √(2/(9m)))³` (relative error below 0.5 % for `m > 6` at these
//! probabilities) is evaluated in `T`.

use crate::Real;

/// Gate probability: the fraction of consistent measurements the gate accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GateProbability {
    /// 95 %.
    P95,
    /// 99 %.
    P99,
    /// 99.9 %.
    P999,
}

/// Chi-square quantiles `χ²_m(p)` for `m = 1..=6`, columns 0.95, 0.99, 0.999.
pub const CHI_SQUARE_TABLE: [[f64; 3]; 6] = [
    [3.841_459, 6.634_897, 10.827_566],
    [5.991_465, 9.210_340, 13.815_511],
    [7.814_728, 11.344_867, 16.266_236],
    [9.487_729, 13.276_704, 18.466_827],
    [11.070_498, 15.086_272, 20.515_006],
    [12.591_587, 16.811_894, 22.457_744],
];

/// Standard-normal quantiles `z_p` for 0.95, 0.99, 0.999.
const Z_SCORES: [f64; 3] = [1.644_853_6, 2.326_347_9, 3.090_232_3];

/// `χ²` of row `R` (`R + 1` degrees of freedom), column `col` of [`CHI_SQUARE_TABLE`]. The row
/// is a constant, so each arm is `T::lit` of a constant, folded at compile time: no run-time
/// `f64` to `f32` conversion (software floating point on a Cortex-M4F).
fn table_entry<T: Real, const R: usize>(col: usize) -> T {
    match col {
        0 => T::lit(CHI_SQUARE_TABLE[R][0]),
        1 => T::lit(CHI_SQUARE_TABLE[R][1]),
        _ => T::lit(CHI_SQUARE_TABLE[R][2]),
    }
}

impl GateProbability {
    /// Standard-normal quantile `z_p`.
    #[must_use]
    pub fn z_score(self) -> f64 {
        Z_SCORES[self.column()]
    }

    fn column(self) -> usize {
        match self {
            Self::P95 => 0,
            Self::P99 => 1,
            Self::P999 => 2,
        }
    }

    /// `χ²_dof(p)`: table for `dof ≤ 6`, Wilson–Hilferty above; `0` for `dof = 0`.
    #[must_use]
    pub fn quantile<T: Real>(self, dof: usize) -> T {
        if dof == 0 {
            return T::zero();
        }
        if dof <= 6 {
            let c = self.column();
            return match dof {
                1 => table_entry::<T, 0>(c),
                2 => table_entry::<T, 1>(c),
                3 => table_entry::<T, 2>(c),
                4 => table_entry::<T, 3>(c),
                5 => table_entry::<T, 4>(c),
                _ => table_entry::<T, 5>(c),
            };
        }
        // `dof` as a `T` without an integer-to-f64 conversion (software on a Cortex-M4F).
        let mut m = T::zero();
        for _ in 0..dof.min(4096) {
            m += T::one();
        }
        let c = T::lit(2.0 / 9.0) / m;
        let z = match self {
            Self::P95 => T::lit(Z_SCORES[0]),
            Self::P99 => T::lit(Z_SCORES[1]),
            Self::P999 => T::lit(Z_SCORES[2]),
        };
        let base = T::one() - c + z * c.sqrt_rn();
        m * base * base * base
    }
}

/// The gate applied to each update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gate<T: Real> {
    /// Accept every measurement.
    Off,
    /// Accept when `NIS ≤ χ²_m(p)`.
    Probability(GateProbability),
    /// Accept when `NIS ≤` this threshold.
    Threshold(T),
}

impl<T: Real> Gate<T> {
    /// The threshold for a measurement of dimension `dof` (`+∞` when off).
    #[must_use]
    pub fn threshold(&self, dof: usize) -> T {
        match self {
            Self::Off => T::lit(f64::INFINITY),
            Self::Probability(p) => p.quantile(dof),
            Self::Threshold(t) => *t,
        }
    }
}

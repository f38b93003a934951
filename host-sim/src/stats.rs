//! Chi-square quantiles for the consistency bands, from `statrs`' exact inverse CDF.

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The `p` quantile of the chi-square distribution with `k` degrees of freedom (`NaN` for
/// `k ≤ 0`).
#[must_use]
pub fn chi2_quantile(p: f64, k: f64) -> f64 {
    match ChiSquared::new(k) {
        Ok(d) => d.inverse_cdf(p),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_tables() {
        for (p, k, want) in [
            (0.975, 3.0, 9.348),
            (0.025, 3.0, 0.2158),
            (0.95, 2.0, 5.991),
            (0.025, 1.0, 0.000982),
            (0.975, 75.0, 100.839),
            (0.025, 75.0, 52.942),
        ] {
            let got = chi2_quantile(p, k);
            assert!(
                ((got - want) / want).abs() < 1e-3,
                "p={p} k={k}: {got} vs {want}"
            );
        }
    }
}

//! Typed errors and update outcomes.

use crate::Real;

/// Why a call refused its input. Whenever one of these is returned, the filter is bit-for-bit
/// what it was before the call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EskfError {
    /// A NaN or infinite value in the input (sample, measurement, state, option).
    NonFinite,
    /// A time step `dt ≤ 0`.
    NonPositiveDt,
    /// A time step above the configured maximum.
    DtTooLarge,
    /// A noise matrix (`R`, or a noise density) that is not symmetric positive definite, or
    /// an `R` singular to the scalar's resolution (a row whose variance the others explain
    /// to all but `256 N ε` of it, the update's noise floor).
    NoiseNotPositiveDefinite,
    /// A covariance given to a constructor that is not symmetric positive definite, has a
    /// variance outside the floor and ceiling ([`crate::Real::VARIANCE_FLOOR_F64`],
    /// [`crate::Real::VARIANCE_CEILING_F64`]), or is singular to the resolution the filter
    /// keeps (a variable whose variance the others explain to all but `256 N ε` of it).
    CovarianceNotPositiveDefinite,
    /// A vector that must have a direction (magnetometer, accelerometer, reference field) has
    /// zero norm, or no horizontal component where a heading is needed.
    ZeroNorm,
    /// A camera landmark at or behind the image plane (depth below the model's minimum).
    BehindCamera,
    /// The measurement function is singular here (heading at ±90° pitch).
    SingularGeometry,
    /// The innovation covariance `S = H P Hᵀ + R` could not be factored.
    SingularInnovation,
    /// The updated covariance came out non-finite, with a non-positive diagonal or with a
    /// variance above the variance ceiling ([`crate::Real::VARIANCE_CEILING_F64`]), or the
    /// attitude correction `|δθ|` reached π (outside the chart where `⊕` is one-to-one); the
    /// update was not applied. Or a prediction whose bias-corrected rotation in one step,
    /// `|(ω_m − b_g) dt|`, reached π (the sample cannot say how the body turned).
    NumericalFailure,
    /// An alignment window with no samples.
    EmptyWindow,
    /// An alignment window whose mean specific force is not close to gravity's norm.
    NotAtRest,
    /// An option out of its range (for example zero iterations).
    InvalidOption,
}

impl core::fmt::Display for EskfError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let s = match self {
            Self::NonFinite => "non-finite value in the input",
            Self::NonPositiveDt => "time step is not positive",
            Self::DtTooLarge => "time step is above the configured maximum",
            Self::NoiseNotPositiveDefinite => "noise matrix is not symmetric positive definite",
            Self::CovarianceNotPositiveDefinite => "covariance is not symmetric positive definite",
            Self::ZeroNorm => "vector has zero norm (or no horizontal component)",
            Self::BehindCamera => "landmark is at or behind the camera",
            Self::SingularGeometry => "measurement function is singular at this state",
            Self::SingularInnovation => "innovation covariance is not positive definite",
            Self::NumericalFailure => "updated covariance is not finite and positive",
            Self::EmptyWindow => "alignment window is empty",
            Self::NotAtRest => "alignment window is not at rest",
            Self::InvalidOption => "option out of range",
        };
        f.write_str(s)
    }
}

/// What a measurement update did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UpdateOutcome<T: Real> {
    /// The measurement passed the gate and was fused.
    Accepted {
        /// Normalized innovation squared `rᵀ S⁻¹ r` at the prior (the squared
        /// Mahalanobis distance of the innovation).
        nis: T,
        /// Gauss-Newton iterations performed (1 for the plain EKF update).
        iterations: u8,
    },
    /// The measurement failed the chi-square gate; the filter is unchanged.
    Rejected {
        /// Normalized innovation squared at the prior.
        nis: T,
        /// The gate threshold it exceeded.
        threshold: T,
    },
}

impl<T: Real> UpdateOutcome<T> {
    /// The normalized innovation squared, in either case.
    #[must_use]
    pub fn nis(&self) -> T {
        match self {
            Self::Accepted { nis, .. } | Self::Rejected { nis, .. } => *nis,
        }
    }

    /// `true` for [`UpdateOutcome::Accepted`].
    #[must_use]
    pub fn is_accepted(&self) -> bool {
        matches!(self, Self::Accepted { .. })
    }
}

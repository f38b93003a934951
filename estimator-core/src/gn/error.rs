//! The typed failures of every solver in [`crate::gn`].

/// Why a solve was refused or failed. Never a panic, never a non-finite result returned as
/// success: every path that could produce one maps to a variant here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolveError {
    /// Fewer observations than the model needs (`needed` is the minimum, `got` what was given).
    TooFewObservations {
        /// Minimum number of observations for the model.
        needed: usize,
        /// Number given.
        got: usize,
    },
    /// More observations than the compile-time capacity of the result (see the function's docs).
    TooManyObservations {
        /// The capacity.
        capacity: usize,
        /// Number given.
        got: usize,
    },
    /// Two input slices that must pair up one to one have different lengths.
    LengthMismatch,
    /// An input number (point, pixel, vector, weight) is NaN or infinite.
    NonFiniteInput,
    /// The initial guess has a NaN or infinite component.
    NonFiniteGuess,
    /// The camera intrinsics are not finite or a focal length is not positive.
    InvalidCamera,
    /// An option is out of range (non-positive sigma or loss scale, non-finite tolerance…).
    InvalidOptions,
    /// The geometry cannot determine the state: coincident or collinear points, parallel rays,
    /// parallel vector pairs.
    DegenerateGeometry,
    /// A point is at or behind the camera (depth below the minimum) at the guess or the solution.
    PointBehindCamera,
    /// The information matrix `Hᵀ W H` is not (numerically) positive definite: its `LDLᵀ`
    /// factorization has a pivot at or below the relative threshold (see
    /// [`crate::gn::linalg::PIVOT_TOLERANCE_EPS`]).
    NotPositiveDefinite,
    /// A residual, cost, step or the state became NaN or infinite during the iterations.
    NonFiniteResidual,
}

impl core::fmt::Display for SolveError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooFewObservations { needed, got } => {
                write!(
                    f,
                    "too few observations: {got} given, at least {needed} needed"
                )
            }
            Self::TooManyObservations { capacity, got } => {
                write!(
                    f,
                    "too many observations: {got} given, capacity is {capacity}"
                )
            }
            Self::LengthMismatch => f.write_str("input slices have different lengths"),
            Self::NonFiniteInput => f.write_str("non-finite input"),
            Self::NonFiniteGuess => f.write_str("non-finite initial guess"),
            Self::InvalidCamera => f.write_str("invalid camera intrinsics"),
            Self::InvalidOptions => f.write_str("invalid solver options"),
            Self::DegenerateGeometry => f.write_str("degenerate geometry"),
            Self::PointBehindCamera => f.write_str("a point is at or behind the camera"),
            Self::NotPositiveDefinite => f.write_str("information matrix is not positive definite"),
            Self::NonFiniteResidual => f.write_str("non-finite residual, cost or step"),
        }
    }
}

//! How an update is done: the gate and the Gauss-Newton iterations.

use super::gate::{Gate, GateProbability};
use crate::eskf::error::EskfError;
use crate::kernels::positive_finite;
use crate::Real;

/// How an update is done: the gate, and the number of Gauss-Newton iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOptions<T: Real> {
    /// The chi-square gate on the NIS at the prior.
    pub gate: Gate<T>,
    /// Iteration cap, `≥ 1`; `1` is the plain (extended) update, more is the iterated update.
    pub max_iterations: u8,
    /// The iterated update stops when `‖δx_{k+1} − δx_k‖ <` this.
    pub step_tolerance: T,
}

impl<T: Real> Default for UpdateOptions<T> {
    /// Single-step update gated at 99.9 %.
    fn default() -> Self {
        Self::ekf(Gate::Probability(GateProbability::P999))
    }
}

impl<T: Real> UpdateOptions<T> {
    /// The plain single-linearization update with `gate`.
    #[must_use]
    pub fn ekf(gate: Gate<T>) -> Self {
        Self {
            gate,
            max_iterations: 1,
            step_tolerance: T::lit(1e-6),
        }
    }

    /// The iterated update (IEKF) with `gate`, at most `max_iterations` linearizations, stopping
    /// when the step changes by less than `step_tolerance`.
    #[must_use]
    pub fn iterated(gate: Gate<T>, max_iterations: u8, step_tolerance: T) -> Self {
        Self {
            gate,
            max_iterations,
            step_tolerance,
        }
    }

    /// `Ok` when the iteration cap is at least 1, the tolerance finite and a threshold gate
    /// positive and finite.
    pub(super) fn validate(&self) -> Result<(), EskfError> {
        if self.max_iterations == 0 || !self.step_tolerance.is_finite() {
            return Err(EskfError::InvalidOption);
        }
        if let Gate::Threshold(t) = self.gate {
            // Positive and finite (`Gate::Off` accepts everything); NaN, zero and negatives
            // would silently reject every measurement.
            if !positive_finite(t) {
                return Err(EskfError::InvalidOption);
            }
        }
        Ok(())
    }
}

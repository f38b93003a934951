//! The mean and scatter of a stream of vectors, in constant memory.

use crate::Real;
use nalgebra::Vector3;

/// Running mean and scatter of vectors `v₁ … vₙ`.
///
/// The sums are taken about the first vector, `dᵢ = vᵢ − v₁` (shifted data: the scatter of
/// vectors near `g = 9.81` does not cancel catastrophically in `f32`):
/// `v̄ = v₁ + Σdᵢ/n`, scatter `s² = Σ‖dᵢ‖²/n − ‖Σdᵢ/n‖²`, the total variance (the sum over the
/// three axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VectorMean<T: Real> {
    origin: Vector3<T>,
    sum: Vector3<T>,
    sum_sq: T,
    count: u32,
}

impl<T: Real> Default for VectorMean<T> {
    fn default() -> Self {
        Self {
            origin: Vector3::zeros(),
            sum: Vector3::zeros(),
            sum_sq: T::zero(),
            count: 0,
        }
    }
}

impl<T: Real> VectorMean<T> {
    /// Adds one vector.
    pub fn add(&mut self, v: &Vector3<T>) {
        if self.count == 0 {
            self.origin = *v;
        }
        let d = v - self.origin;
        self.sum += d;
        self.sum_sq += d.dot(&d);
        self.count = self.count.saturating_add(1);
    }

    /// The number of vectors added.
    #[must_use]
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The mean `v̄`, `None` before the first vector.
    #[must_use]
    pub fn mean(&self) -> Option<Vector3<T>> {
        (self.count > 0).then(|| self.origin + self.sum / T::from_count(self.count))
    }

    /// The total variance about the mean, `s² = Σ‖vᵢ − v̄‖²/n ≥ 0` (0 before two vectors).
    #[must_use]
    pub fn scatter_sq(&self) -> T {
        if self.count < 2 {
            return T::zero();
        }
        let n = T::from_count(self.count);
        let m = self.sum / n;
        let s = self.sum_sq / n - m.dot(&m);
        if s > T::zero() {
            s
        } else {
            T::zero()
        }
    }
}

//! Measurement models `z = h(x) + n`, `n ~ N(0, R)`, each with its right Jacobian
//! `H = ∂h(x ⊕ δx)/∂δx` at `δx = 0`: one file per sensor.
//!
//! Every attitude Jacobian follows from `R·exp(δθ^) ≈ R(I + [δθ]×)` (first order in `δθ`):
//!
//! ```text
//! (R exp(δθ^))ᵀ a ≈ Rᵀa + [Rᵀa]× δθ          (a world vector seen in the body)
//!  R exp(δθ^) b   ≈ R b − R[b]× δθ            (a body vector seen in the world)
//! ```
//!
//! the second being the action Jacobian `J^{R·b}_R = −R[b]×` of *Lie Groups and Smooth
//! Manifolds for Robotic State Estimation*, Theorem 5.1 / Example 5.2.
//!
//! A new model is one file here implementing [`Measurement`](super::Measurement) for the
//! states it observes, plus a Jacobian test in `tests/eskf_jacobians.rs`.

mod barometer;
mod camera;
mod gnss;
mod gravity;
mod heading;
mod lateral_velocity;
mod magnetometer;
mod shared;
mod zero_rate;
mod zero_velocity;

pub use barometer::BaroAltitude;
pub use camera::{CameraLandmark, PinholeIntrinsics};
pub use gnss::{GnssPosition, GnssVelocity};
pub use gravity::{AccelerometerAtRest, GravityDirection};
pub use heading::Heading;
pub use lateral_velocity::LateralVelocity;
pub use magnetometer::{MagneticHeading, Magnetometer};
pub use zero_rate::ZeroRate;
pub use zero_velocity::ZeroVelocity;

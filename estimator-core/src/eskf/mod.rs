//! On-manifold error-state Kalman filter: a 15-state inertial navigator ([`Ins`]) and an
//! attitude-only AHRS ([`Ahrs`]), one generic implementation ([`Filter`]), with chi-square
//! gating, square-root (Cholesky) Joseph-form updates, iterated (Gauss-Newton) updates and
//! typed outcomes.
//! Allocation-free and panic-free.
//!
//! Equations cite *Lie Groups and Smooth Manifolds for Robotic State Estimation* ("the
//! paper") by number, each restated where it is used.
//!
//! # Layout
//!
//! `state.rs` (the nominal states and `⊕`), `config.rs` (IMU samples, noise, configuration),
//! `predict.rs` (the prediction), `update/` (gain, gate, commit), `models/` (one file per
//! sensor), `align.rs` (start-up), `filter.rs` (the filter the user holds).
//!
//! # State and error
//!
//! Nominal state `x = (R, v, p, b_g, b_a)`: `R ∈ SO(3)` world-from-body ([`crate::lie::So3`]),
//! velocity `v` and position `p` in the world frame (ENU, z up), gyro and accelerometer biases in
//! the body frame. Error state `δx = (δθ, δv, δp, δb_g, δb_a) ∈ R¹⁵` with the attitude error on the
//! right (the paper's eq. 4.5, `a ⊕ τ = a·exp(τ^)`, the crate's convention):
//!
//! ```text
//! R = R̂ · exp(δθ^),   v = v̂ + δv,   p = p̂ + δp,   b_g = b̂_g + δb_g,   b_a = b̂_a + δb_a
//! ```
//!
//! so `x = x̂ ⊕ δx` ([`ErrorState::oplus`]). The attitude-only state is `(R, b_g)` with
//! `δx = (δθ, δb_g) ∈ R⁶`.
//!
//! # Prediction ([`Filter::predict`])
//!
//! One IMU sample `(ω_m, f_m, dt)`, held constant over `dt`; `ω = ω_m − b_g`, `f = f_m − b_a`,
//! `a = R f + g` (`g = [0, 0, −9.81]` by default):
//!
//! ```text
//! R⁺ = R · exp((ω dt)^)           (on the manifold, not a first-order quaternion step)
//! v⁺ = v + a dt
//! p⁺ = p + v dt + ½ a dt²
//! ```
//!
//! The error propagates as `δx⁺ = F δx + w`, with `ΔR = exp(ω dt)` and `J_r` the SO(3) right
//! Jacobian (`exp(τ + δ) ≈ exp(τ)·exp(J_r(τ)δ)`); the nonzero 3×3 blocks of `F` are
//!
//! ```text
//!        δθ                δv      δp    δb_g              δb_a
//! δθ⁺ [ ΔRᵀ               0       0     −J_r(ω dt) dt     0         ]
//! δv⁺ [ −R[f]× dt         I       0     0                 −R dt     ]
//! δp⁺ [ −½R[f]× dt²       I dt    I     0                 −½R dt²   ]
//! δb_g⁺[ 0                0       0     I                 0         ]
//! δb_a⁺[ 0                0       0     0                 I         ]
//! ```
//!
//! `P⁺ = F P Fᵀ + Q` is computed block by block (`F P`, then `(F P) Fᵀ` in place), never as a
//! dense 15×15×15 product. From the Kalibr continuous-time densities (`σ_g` rad/s/√Hz,
//! `σ_a` m/s²/√Hz, random walks `σ_bg`, `σ_ba`; [`ImuNoise`]):
//!
//! ```text
//! Q_θθ = σ_g² dt I,  Q_vv = σ_a² dt I,  Q_vp = Q_pv = ½σ_a² dt² I,  Q_pp = ¼σ_a² dt³ I,
//! Q_bgbg = σ_bg² dt I,  Q_baba = σ_ba² dt I.
//! ```
//!
//! The `(v, p)` block holds the sample's noise over the step (`G Gᵀ σ_a²/dt`, `G = [dt, ½dt²]`):
//! it has rank one, so where `Q` dominates `P` the growth floor (below) keeps `P⁺` definite.
//!
//! The AHRS uses the `(δθ, δb_g)` corner: `F = [ΔRᵀ, −J_r dt; 0, I]`,
//! `Q = diag(σ_g² dt I, σ_bg² dt I)`.
//!
//! # Measurement update ([`Filter::update`])
//!
//! A model ([`Measurement`]) gives the residual `r = z ⊖ h(x̂)` and the right Jacobian
//! `H = ∂h(x̂ ⊕ δx)/∂δx`, with `h(x̂ ⊕ δx) ≈ h(x̂) + H δx` (the paper's eq. 4.3 and
//! Definition 4.6), and its noise `R`. Then
//!
//! ```text
//! S   = H P Hᵀ + R_eff                  R with the noise floor (below)
//! NIS = rᵀ S⁻¹ r                        squared Mahalanobis distance ‖e‖²_Σ = eᵀΣ⁻¹e (eq. 4.1)
//! gate: NIS ≤ χ²_m(p), else Rejected { nis } and nothing changes
//! K   = P Hᵀ S⁻¹,  δx = K r            the minimizer of eq. 4.4 with the prior ‖δx‖²_P added
//!                                       in square-root form: S = L Lᵀ, W = P Hᵀ L⁻ᵀ, K = W L⁻¹
//! P⁺  = (I − KH) P (I − KH)ᵀ + K R Kᵀ  Joseph form, for this K equal to P − U S⁻¹ Uᵀ, U = P Hᵀ,
//!                                       evaluated as P − W Wᵀ (every term ≤ P; exactly symmetric)
//! x⁺  = x̂ ⊕ δx                          injection (eq. 4.5)
//! P⁺ ← G P⁺ Gᵀ,  G = blockdiag(J_r(δθ), I)   reset to the error about x⁺
//! ```
//!
//! The iterated update ([`UpdateOptions::iterated`]) is Gauss-Newton on the manifold (the paper's §4) for
//! `‖δx‖²_P + ‖z ⊖ h(x̂ ⊕ δx)‖²_R`: at `x_k = x̂ ⊕ δx_k` the model is linearized again,
//! `H̃_k = H_k · blockdiag(J_r(δθ_k), I)` and `δx_{k+1} = K_k (r_k + H̃_k δx_k)`, until
//! `‖δx_{k+1} − δx_k‖ < tol` or the iteration cap. The gate uses the NIS at the prior.
//!
//! # Measurement models
//!
//! | model | `h(x)` | nonzero blocks of `H` |
//! |---|---|---|
//! | [`GnssPosition`] | `p + R ℓ` | `δθ: −R[ℓ]×` (action Jacobian, Theorem 5.1 / Example 5.2), `δp: I` |
//! | [`GnssVelocity`] | `v` | `δv: I` |
//! | [`ZeroVelocity`] | `v` (z = 0) | `δv: I` |
//! | [`BaroAltitude`] | `p_z + offset` | `δp: [0 0 1]` |
//! | [`Magnetometer`] | `Rᵀ m_w` | `δθ: [Rᵀ m_w]×` |
//! | [`GravityDirection`] | `Rᵀ u` (u up) vs `f_m/‖f_m‖` | `δθ: [Rᵀ u]×` |
//! | [`AccelerometerAtRest`] | `Rᵀ(−g) + b_a` | `δθ: [Rᵀ(−g)]×`, `δb_a: I` |
//! | [`Heading`] | `atan2(R₂₁, R₁₁)` | `δθ: (c_x ∂c_y − c_y ∂c_x)/(c_x²+c_y²)`, `∂(R e₁) = −R[e₁]×` |
//! | [`CameraLandmark`] | `π(T_cw ℓ)` (the paper's `z_ij = π(T_i p_j)`, §4) | `δθ: J_π R_bcᵀ [q]×`, `δp: −J_π R_bcᵀ Rᵀ` |
//!
//! # Start-up
//!
//! [`align_at_rest`] gives tilt from the mean specific force, heading from the magnetometer when
//! present, and the gyro bias from the mean rate; `Ins::from_alignment` /
//! `Ahrs::from_alignment` start from it, [`Filter::new`] from a given state and covariance.
//!
//! # Resources
//!
//! `size_of::<Ins<f32>>()` is 996 bytes (state 64, `P` as a full 15 × 15 `f32` 900,
//! configuration 32); `Ahrs<f32>` is 204 bytes. No scratch space is stored. An update runs in
//! separate phases (linearize, gain and gate, iterate, commit) over one small working set on
//! the stack, so no `N × N` temporary exists during an update, and it is compiled once per
//! scalar type and filter, not once per measurement model: every model with up to three rows
//! goes through one core, its rows padded to three (`update/mod.rs`).
//!
//! # Numerical resolution
//!
//! After every accepted call `P` is finite, symmetric and positive definite, in `f32` too.
//! Rounding moves each entry `P_ij` by a few `ε √(P_ii P_jj)`, so this holds while the smallest
//! eigenvalue of the correlation matrix `C = D^-½ P D^-½` (`D = diag P`) stays well above `Nε`.
//! Four floors keep it there; in `f64` none acts on any usable filter. The premise holds for
//! the update because its posterior is computed as `P − W Wᵀ` (square-root form, `W Wᵀ ≤ P`);
//! the expanded Joseph form `P + V Kᵀ + K Vᵀ` has terms that grow with the condition of `S`
//! and broke it where two rows of `H` were nearly parallel.
//!
//! * **Noise floor** (`update/gain.rs`): the combination `h_cᵀ δx` a row measures keeps a
//!   posterior variance of at least `f w_c`, `w_c = Σ_i H_ci² P_ii`, `f = 256 N ε`: its noise
//!   is raised to `R_eff,cc = max(R_cc, f w_c p_c / (p_c − f w_c))`, `p_c = (H P Hᵀ)_cc`. Row
//!   `c` then adds at most `1/f` to the largest eigenvalue of `C⁻¹`, so an update leaves
//!   `λ_min(C⁺) ≥ 1 / (1/λ_min(C) + M/f)`, and a combination measured again and again stays at
//!   the floor. A measurement far more precise than its prior (in `f32`: σ below 0.021 of the
//!   prior's) is fused as if it were that precise. A noise `R` whose rows are correlated
//!   beyond the same resolution is refused.
//! * **Attitude floor** (`covariance.rs`): the attitude error is in the body frame, so with the
//!   heading unknown every entry of `P_θθ` is of the heading's size and the tilt is a
//!   difference of such entries. When `4 det P_θθ / (tr P_θθ)² ≤ 16 ε tr P_θθ` (a lower bound
//!   of its smallest eigenvalue), the prediction, the update and the widening add
//!   `16 ε tr P_θθ · I`; the widening adds it always (it scales the attitude rows up and keeps
//!   their covariance with the biases). In `f32` with σ_ψ ≈ 2.4 rad this keeps the tilt's σ at
//!   least 3.4 mrad.
//!
//! * **Growth floor** (`covariance.rs`): a prediction integrates (`p⁺ = p + v dt`, …), and
//!   the variance it adds may be wholly correlated with its source; the floor adds
//!   `f max(P⁺_kk − P_kk, 0) + 2 ε P⁺_kk` (`f = 64 N ε`), so that each state keeps a part of
//!   its variance independent of the others, ahead of the rounding of each step (which is
//!   there whether the variance grew or not). The rotation `R [f]× dt` mixes the axes of `v`
//!   and of `p`, so their variances also get `64 ε` of the size of the products that feed
//!   them, `dt² (‖f‖² tr P_θθ + tr P_ba)` (times `(dt/2)²` for `p`): where `f` lies along a
//!   well-known attitude direction the result is far smaller than the products, and its
//!   rounding with it.
//! * **Reset floor** (`update/commit.rs`): the reset `G P⁺ Gᵀ`, `G = blockdiag(J_r(δθ), I)`,
//!   mixes the attitude rows by up to `1.03 |δθ|`, so a large row rotated into a small one
//!   brings its rounding along. The attitude variances get `8 N ε |δθ| tr P_θθ`, the others
//!   `16 ε |δθ|` of themselves; a correction of a milliradian makes them negligible.
//!
//! A prediction whose step turns by `|ω dt| ≥ π` is refused (`NumericalFailure`): the sample
//! cannot say how the body turned, and `J_r(ω dt)` tends to rank one.
//!
//! A noise `R` is checked through its symmetric part `½(R + Rᵀ)`, the matrix the gain uses.
//!
//! Attitude sigmas above π are taken as π (start-up, widening): σ = π is no information.
//!
//! # Edges
//!
//! Every entry point with outside data returns a `Result`. NaN/∞ anywhere, `dt ≤ 0`,
//! `dt > max_dt`, a noise matrix that is not symmetric positive definite, a zero-norm
//! magnetometer/accelerometer vector, a landmark behind the camera: an [`EskfError`], and the
//! filter is bit-for-bit unchanged. A gated-out measurement returns
//! `Ok(`[`UpdateOutcome::Rejected`]`)` and also changes nothing.

mod align;
mod config;
mod covariance;
mod error;
mod filter;
mod models;
mod predict;
mod state;
mod update;

pub use align::{align_at_rest, Alignment, InitialSigmas, MagnetometerWindow};
pub(crate) use config::up_direction;
pub use config::{FilterConfig, ImuNoise, ImuSample};
pub use error::{EskfError, UpdateOutcome};
pub use filter::{Ahrs, AhrsAccelBias, Filter, Ins};
pub use models::{
    AccelerometerAtRest, BaroAltitude, CameraLandmark, GnssPosition, GnssVelocity,
    GravityDirection, Heading, LateralVelocity, MagneticHeading, Magnetometer, PinholeIntrinsics,
    ZeroRate, ZeroVelocity,
};
pub use state::{AhrsAccelBiasState, AhrsState, ErrorState, InsState};
pub use update::gate::{Gate, GateProbability, CHI_SQUARE_TABLE};
pub use update::{Linearization, Measurement, UpdateOptions};

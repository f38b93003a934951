//! The error-state filter: one generic implementation behind [`Ins`] and [`Ahrs`].

use super::align::{prior_attitude_covariance, Alignment, InitialSigmas};
use super::config::{up_direction, FilterConfig, ImuSample};
use super::covariance::{
    attitude_floor, attitude_resolution, cap_attitude, check_start, floor_attitude, growth_floor,
    is_spd, sigmas,
};
use super::error::{EskfError, UpdateOutcome};
use super::state::{sealed::Sealed, AhrsAccelBiasState, AhrsState, ErrorState, InsState};
use super::update::{update, Measurement, UpdateOptions};
use crate::kernels::block::{add_scaled_identity, block, set_block};
use crate::kernels::{all_finite, mat3, non_negative_finite, positive_finite, usable_variance};
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// The on-manifold error-state Kalman filter over the nominal state `S` with an
/// `N`-dimensional error state: the state, its full `N × N` covariance `P` and the
/// configuration, and no scratch space.
///
/// Use it through [`Ins`] (`x = (R, v, p, b_g, b_a)`, `N = 15`) or [`Ahrs`] (`x = (R, b_g)`,
/// `N = 6`). Every method that takes outside data returns a `Result`; on `Err`, and on a
/// gated-out measurement, the filter is unchanged bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filter<T: Real, S, const N: usize> {
    state: S,
    covariance: SMatrix<T, N, N>,
    config: FilterConfig<T>,
}

/// The 15-state inertial filter, `x = (R, v, p, b_g, b_a)`, `δx ∈ R¹⁵`
/// (`size_of::<Ins<f32>>()` is 996 bytes).
///
/// ```
/// use estimator_core::eskf::{FilterConfig, GnssPosition, ImuSample, Ins, InsState, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let p0 = SMatrix::<f32, 15, 15>::identity() * 0.01;
/// let mut ins = Ins::new(InsState::identity(), p0, FilterConfig::default()).unwrap();
/// // At rest and level for one second at 200 Hz: the accelerometer reads +g up.
/// let imu = ImuSample { gyro: Vector3::zeros(), accel: Vector3::new(0.0, 0.0, 9.81), dt: 0.005 };
/// for _ in 0..200 {
///     ins.predict(&imu).unwrap();
/// }
/// let fix = GnssPosition::new(Vector3::zeros(), Vector3::zeros(), 0.5);
/// ins.update(&fix, &UpdateOptions::default()).unwrap();
/// assert!(ins.state().position.norm() < 0.01);
/// assert!(ins.sigmas()[6] < 0.5); // east position σ, m
/// ```
pub type Ins<T> = Filter<T, InsState<T>, 15>;

/// The attitude-only filter (AHRS), `x = (R, b_g)`, `δx = (δθ, δb_g) ∈ R⁶`, aided by
/// [`GravityDirection`](super::GravityDirection), [`Magnetometer`](super::Magnetometer) and
/// [`Heading`](super::Heading). Its prediction reads only the gyro and `dt` of an
/// [`ImuSample`].
///
/// ```
/// use estimator_core::eskf::{Ahrs, AhrsState, FilterConfig, GravityDirection, ImuSample, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let p0 = SMatrix::<f32, 6, 6>::identity() * 1e-3;
/// let mut ahrs = Ahrs::new(AhrsState::identity(), p0, FilterConfig::default()).unwrap();
/// // Turning about z at 0.5 rad/s for one second at 100 Hz.
/// let imu = ImuSample { gyro: Vector3::new(0.0, 0.0, 0.5), accel: Vector3::new(0.0, 0.0, 9.81), dt: 0.01 };
/// for _ in 0..100 {
///     ahrs.predict(&imu).unwrap();
///     ahrs.update(&GravityDirection::new(imu.accel, 0.05), &UpdateOptions::default()).unwrap();
/// }
/// let (_, _, yaw) = ahrs.state().attitude.quaternion().euler_angles();
/// assert!((yaw - 0.5).abs() < 1e-3);
/// ```
pub type Ahrs<T> = Filter<T, AhrsState<T>, 6>;

/// The attitude filter with both IMU biases and the velocity, `x = (R, b_g, b_a, v)`,
/// `δx ∈ R¹²`: an [`Ahrs`] that also estimates the accelerometer bias and carries the velocity
/// its specific force integrates to ([`AhrsAccelBiasState`]), aided by
/// [`AccelerometerAtRest`](super::AccelerometerAtRest) (the specific force, bias included),
/// [`ZeroVelocity`](super::ZeroVelocity) (a bound on the body's velocity),
/// [`MagneticHeading`](super::MagneticHeading) and [`ZeroRate`](super::ZeroRate). Its
/// prediction reads only the gyro and `dt`; the velocity moves by
/// [`integrate_velocity`](Self::integrate_velocity).
///
/// ```
/// use estimator_core::eskf::{AccelerometerAtRest, AhrsAccelBias, AhrsAccelBiasState, FilterConfig, UpdateOptions};
/// use nalgebra::{SMatrix, Vector3};
///
/// let p0 = SMatrix::<f64, 12, 12>::identity() * 1e-2;
/// let mut f = AhrsAccelBias::new(AhrsAccelBiasState::identity(), p0, FilterConfig::default()).unwrap();
/// // Level, with a 0.2 m/s² bias on the vertical axis: only the bias can explain the norm.
/// for _ in 0..20 {
///     f.update(&AccelerometerAtRest::new(Vector3::new(0.0, 0.0, 10.01), 0.01), &UpdateOptions::default()).unwrap();
/// }
/// assert!((f.state().accel_bias.z - 0.2).abs() < 0.01);
/// ```
pub type AhrsAccelBias<T> = Filter<T, AhrsAccelBiasState<T>, 12>;

impl<T: Real> Ins<T> {
    /// [`predict`](Self::predict) of a sample its caller has checked to be finite (the INS
    /// navigator checks every sample before it is buffered): the same prediction without the
    /// second look at the sample (about 70 Cortex-M4F instructions of the navigator's step).
    pub(crate) fn predict_finite(&mut self, imu: &ImuSample<T>) -> Result<(), EskfError> {
        super::predict::predict_ins_finite(&mut self.state, &mut self.covariance, imu, &self.config)
    }
}

impl<T: Real> AhrsAccelBias<T> {
    /// The identity state with `P = I` and a configuration its caller has validated
    /// ([`FilterConfig::validate`]): the placeholder the attitude navigator holds until it
    /// starts the filter ([`restart_from_alignment`](Self::restart_from_alignment)), built
    /// without [`new`](Self::new)'s checks of values that are valid by construction (no
    /// factorization, no `Result` on the stack of a restart).
    pub(crate) fn placeholder(config: FilterConfig<T>) -> Self {
        Self {
            state: AhrsAccelBiasState::identity(),
            covariance: SMatrix::identity(),
            config,
        }
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Filter<T, S, N> {
    /// From a given state and covariance. The filter keeps `P` as every prediction leaves it:
    /// attitude variances above π² scaled down to it, and the attitude floor `16 ε tr P_θθ · I`
    /// added to the attitude block when its smallest eigenvalue may be below that. So a filter
    /// can be built again from its own [`state`](Self::state) and
    /// [`covariance`](Self::covariance).
    ///
    /// # Errors
    /// A non-finite state, `P` not symmetric positive definite, with a variance outside the
    /// variance floor and ceiling, or singular to the scalar's
    /// resolution (a state other than the attitude known, given the attitude and the states
    /// before it, to less than `256 N ε` of its variance), or an invalid configuration
    /// ([`FilterConfig::validate`]).
    pub fn new(
        state: S,
        covariance: SMatrix<T, N, N>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        // Capped first, then checked: the scaling rounds, and the filter keeps what was checked.
        let mut covariance = covariance;
        cap_attitude(&mut covariance);
        // The attitude floor every prediction adds: a body-frame block with the heading unknown
        // is representable only with it (`check_start`).
        floor_attitude(&mut covariance);
        check_start(&state, &covariance, &config)?;
        Ok(Self {
            state,
            covariance,
            config,
        })
    }

    /// The nominal state.
    #[must_use]
    pub fn state(&self) -> &S {
        &self.state
    }

    /// The error-state covariance `P`.
    #[must_use]
    pub fn covariance(&self) -> &SMatrix<T, N, N> {
        &self.covariance
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &FilterConfig<T> {
        &self.config
    }

    /// `√diag(P)`, the 1-σ of each error-state component.
    #[must_use]
    pub fn sigmas(&self) -> SVector<T, N> {
        sigmas(&self.covariance)
    }

    /// Widens the attitude uncertainty: adds `Rᵀ Σ_w R` to the attitude block of `P`, with
    /// `Σ_w = σ_t² I + (σ_ψ² − σ_t²) u uᵀ` the world-frame covariance of `tilt` (about the
    /// horizontal axes) and `yaw` (about the up direction `u = −g/‖g‖`), both in radians.
    /// Adding a positive semi-definite matrix keeps `P` positive definite; a navigator calls it
    /// when the data say the estimate is worse than `P` claims.
    ///
    /// An attitude error of σ = π is no information, and the error model is a small rotation:
    /// with `A = P_θθ` and `u_b = Rᵀ u`, `σ_ψ` is capped at `√(π² − u_bᵀ A u_b)` (the heading
    /// variance) and `σ_t` at `√(π² − (tr A − u_bᵀ A u_b))` (the sum of the two tilt
    /// variances), so widening never takes the heading or a tilt variance above π² (one already
    /// there is left as it is). Then the attitude block gets the attitude floor `16 ε tr A · I`
    /// whatever its smallest eigenvalue: the widened rows are large beside their covariance with
    /// the other states, and a tilt correlated with the gyro bias would otherwise be known, given
    /// the bias, below the scalar's resolution of those rows.
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a negative or non-finite sigma, [`EskfError::ZeroNorm`] for
    /// a zero gravity, [`EskfError::NumericalFailure`] when `P` would overflow; `P` is then
    /// unchanged.
    #[allow(clippy::question_mark)] // a matched, not propagated, matrix result (see `align`)
    pub fn widen_attitude(&mut self, tilt: T, yaw: T) -> Result<(), EskfError> {
        if !(non_negative_finite(tilt) && non_negative_finite(yaw)) {
            return Err(EskfError::NonFinite);
        }
        let (tilt_room, yaw_room) = widening_room(
            &block(&self.covariance, 0, 0),
            self.state.attitude(),
            &self.config.gravity,
        );
        let capped = |s: T, room: T| if s > room { room } else { s };
        let sigmas = InitialSigmas {
            tilt: capped(tilt, tilt_room),
            yaw: capped(yaw, yaw_room),
            ..InitialSigmas::default()
        };
        let alignment = Alignment {
            attitude: *self.state.attitude(),
            gyro_bias: Vector3::zeros(),
            heading_from_magnetometer: false,
        };
        let extra = match prior_attitude_covariance(&alignment, &sigmas, &self.config) {
            Ok(m) => m,
            Err(e) => return Err(e),
        };
        // Only the attitude block changes (the rest of `P` is finite, an invariant of the
        // filter): checked and written in place, without a second `P` on the stack.
        let widened = block(&self.covariance, 0, 0) + extra;
        let widened = widened + Matrix3::from_diagonal_element(attitude_resolution(&widened));
        if !all_finite(widened.as_slice()) {
            return Err(EskfError::NumericalFailure);
        }
        set_block(&mut self.covariance, 0, 0, &widened);
        Ok(())
    }

    /// Propagates with one IMU sample: nominal integration and `P⁺ = F P Fᵀ + Q` (equations in
    /// the [`crate::eskf`] module docs).
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] (also for a prediction that would take a variance above the
    /// variance ceiling, [`crate::Real::VARIANCE_CEILING_F64`]), [`EskfError::NonPositiveDt`],
    /// [`EskfError::DtTooLarge`]; the filter is then unchanged.
    pub fn predict(&mut self, imu: &ImuSample<T>) -> Result<(), EskfError> {
        Sealed::propagate(&mut self.state, &mut self.covariance, imu, &self.config)
    }

    /// Fuses one measurement: gate, Joseph form (as `P − W Wᵀ`), optional Gauss-Newton iterations, injection
    /// through `⊕`, reset ([`crate::eskf`] module docs). Returns the outcome with its NIS; a
    /// `Rejected` outcome leaves the filter unchanged.
    ///
    /// # Errors
    /// Invalid options, a noise that is not symmetric positive definite, the model's own
    /// errors, or a numerical failure; the filter is then unchanged.
    pub fn update<Mo, const M: usize>(
        &mut self,
        model: &Mo,
        options: &UpdateOptions<T>,
    ) -> Result<UpdateOutcome<T>, EskfError>
    where
        Mo: Measurement<T, S, N, M>,
    {
        update(&mut self.state, &mut self.covariance, model, options)
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Filter<T, S, N> {
    /// A filter from a block-diagonal prior: `attitude` (3 × 3) on block 0, with the attitude
    /// floor of the predictions ([`attitude_floor`]: `16 ε tr A · I` when its smallest
    /// eigenvalue may be below that), and `variances[k]` times the identity on block `k + 1`.
    /// Such a `P` is symmetric positive definite exactly when the attitude block is and every
    /// variance is positive, so that is what is checked (a 3 × 3 factorization, not one of
    /// `P`), with every variance at most the ceiling.
    fn from_block_diagonal(
        state: S,
        attitude: &Matrix3<T>,
        variances: &[T],
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        config.validate()?;
        let mut filter = Self {
            state,
            covariance: SMatrix::zeros(),
            config,
        };
        filter.reset_block_diagonal(state, attitude, variances)?;
        Ok(filter)
    }

    /// Replaces state and covariance by `state` and the block-diagonal prior of
    /// [`Filter::from_block_diagonal`], in place (no second `P` on the stack); on `Err` the
    /// filter is unchanged.
    fn reset_block_diagonal(
        &mut self,
        state: S,
        attitude: &Matrix3<T>,
        variances: &[T],
    ) -> Result<(), EskfError> {
        if !state.is_finite() {
            return Err(EskfError::NonFinite);
        }
        // A heading of σ = π beside a tilt of 1e-8 rad is a block singular to the scalar's
        // resolution: floored as every prediction floors it.
        let attitude = attitude + Matrix3::from_diagonal_element(attitude_floor(attitude));
        let usable = (0..3).all(|k| attitude.get((k, k)).is_some_and(|d| usable_variance(*d)))
            && is_spd(&attitude)
            && variances.iter().all(|v| usable_variance(*v));
        if !usable {
            return Err(EskfError::CovarianceNotPositiveDefinite);
        }
        self.state = state;
        self.covariance = SMatrix::zeros();
        set_block(&mut self.covariance, 0, 0, &attitude);
        for (k, v) in variances.iter().enumerate() {
            add_scaled_identity(&mut self.covariance, k + 1, k + 1, *v);
        }
        Ok(())
    }
}

impl<T: Real> Filter<T, InsState<T>, 15> {
    /// From a static [`Alignment`] at `position` (velocity zero, accelerometer bias zero), with
    /// the initial uncertainties `sigmas` (attitude covariance from
    /// [`InitialSigmas::attitude_covariance`]).
    ///
    /// # Errors
    /// As [`Filter::new`], and [`EskfError::ZeroNorm`] for a zero gravity.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    #[allow(clippy::question_mark)] // a matched, not propagated, matrix result (see `align`)
    pub fn from_alignment(
        alignment: &Alignment<T>,
        position: Vector3<T>,
        sigmas: &InitialSigmas<T>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        let state = InsState {
            attitude: alignment.attitude,
            velocity: Vector3::zeros(),
            position,
            gyro_bias: alignment.gyro_bias,
            accel_bias: Vector3::zeros(),
        };
        let attitude = match prior_attitude_covariance(alignment, sigmas, &config) {
            Ok(a) => a,
            Err(e) => return Err(e),
        };
        let sq = |s: T| s * s;
        let variances = [
            sq(sigmas.velocity),
            sq(sigmas.position),
            sq(sigmas.gyro_bias),
            sq(sigmas.accel_bias),
        ];
        Self::from_block_diagonal(state, &attitude, &variances, config)
    }
}

impl<T: Real> Filter<T, InsState<T>, 15> {
    /// An INS started from an attitude filter's estimate: `R`, `b_g`, `b_a` and their joint
    /// covariance (the 9 × 9 `P` of `attitude`, blocks δθ, δb_g, δb_a) carried over, with
    /// `velocity` and `position` independent of them, of 1σ `sigma_velocity` and
    /// `sigma_position` per axis. The attitude is taken as `R·C` with `C = carry` (an attitude
    /// estimated at another time, carried by a known rotation); the right error then becomes
    /// `δθ' = Cᵀ δθ` (from `R Exp(δθ) C = R C Exp(Cᵀ δθ)`), so the attitude rows and columns
    /// of `P` are multiplied by `Cᵀ`. `P = [P_θθ 0 0 P_θg P_θa; 0 σ_v² I …]` is positive
    /// definite because the attitude filter's `P` is and both variances are positive.
    ///
    /// # Errors
    /// A non-finite velocity or position, a sigma that is not positive and finite
    /// ([`EskfError::CovarianceNotPositiveDefinite`]); nothing is built.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    pub fn from_attitude_filter(
        attitude: &AhrsAccelBias<T>,
        carry: &So3<T>,
        velocity: Vector3<T>,
        position: Vector3<T>,
        sigma_velocity: T,
        sigma_position: T,
    ) -> Result<Self, EskfError> {
        let mut ins = Self::unstarted(*attitude.config());
        ins.restart_from_attitude_filter(
            attitude,
            carry,
            velocity,
            position,
            sigma_velocity,
            sigma_position,
        )?;
        Ok(ins)
    }

    /// A filter whose `P` is zero: not a filter until [`Filter::restart_from_attitude_filter`]
    /// has run on it (a navigator builds the INS in the place of its attitude filter).
    pub(crate) fn unstarted(config: FilterConfig<T>) -> Self {
        Self {
            state: InsState::identity(),
            covariance: SMatrix::zeros(),
            config,
        }
    }

    /// Starts this filter again as [`Filter::from_attitude_filter`] builds one, in place (a
    /// navigator switching from its attitude filter to the INS holds one `P`, not two), with
    /// the attitude filter's configuration.
    ///
    /// # Errors
    /// As [`Filter::from_attitude_filter`]; the filter is then unchanged.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    pub fn restart_from_attitude_filter(
        &mut self,
        attitude: &AhrsAccelBias<T>,
        carry: &So3<T>,
        velocity: Vector3<T>,
        position: Vector3<T>,
        sigma_velocity: T,
        sigma_position: T,
    ) -> Result<(), EskfError> {
        self.restart_from_attitude_filter_per_axis(
            attitude,
            carry,
            velocity,
            position,
            sigma_velocity,
            &Vector3::repeat(sigma_position),
        )
    }

    /// [`Filter::restart_from_attitude_filter`] with a position 1σ per world axis
    /// (`sigma_position = [σ_e, σ_n, σ_u]`: the position block of `P` is
    /// `diag(σ_e², σ_n², σ_u²)`, still decoupled from the rest, so `P` stays positive
    /// definite).
    ///
    /// # Errors
    /// As [`Filter::restart_from_attitude_filter`]; the filter is then unchanged.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    pub(crate) fn restart_from_attitude_filter_per_axis(
        &mut self,
        attitude: &AhrsAccelBias<T>,
        carry: &So3<T>,
        velocity: Vector3<T>,
        position: Vector3<T>,
        sigma_velocity: T,
        sigma_position: &Vector3<T>,
    ) -> Result<(), EskfError> {
        let a = attitude.state();
        let state = InsState {
            attitude: a.attitude.compose(carry).renormalize(),
            velocity,
            position,
            gyro_bias: a.gyro_bias,
            accel_bias: a.accel_bias,
        };
        if !state.is_finite() {
            return Err(EskfError::NonFinite);
        }
        let position_variance = sigma_position.component_mul(sigma_position);
        if !(positive_finite(sigma_velocity * sigma_velocity)
            && position_variance.iter().all(|v| positive_finite(*v)))
        {
            return Err(EskfError::CovarianceNotPositiveDefinite);
        }
        self.state = state;
        self.config = *attitude.config();
        let p = &mut self.covariance;
        *p = SMatrix::zeros();
        // Block k of the attitude filter (δθ, δb_g, δb_a) is block `to[k]` of the INS.
        let to = [0, 3, 4];
        let m = carry.rotation_matrix().transpose();
        for (i, bi) in to.iter().enumerate() {
            for (j, bj) in to.iter().enumerate() {
                let mut b = block(attitude.covariance(), i, j);
                if i == 0 {
                    b = mat3::mul(&m, &b);
                }
                if j == 0 {
                    b = mat3::mul(&b, &m.transpose());
                }
                set_block(p, *bi, *bj, &b);
            }
        }
        add_scaled_identity(p, 1, 1, sigma_velocity * sigma_velocity);
        set_block(p, 2, 2, &Matrix3::from_diagonal(&position_variance));
        Ok(())
    }

    /// Resets the position to `position` with 1σ `sigma` per axis, forgetting what the filter
    /// knew of it: the position rows and columns of `P` become `σ² I` on the diagonal and zero
    /// elsewhere. What remains is block diagonal with a principal submatrix of a positive
    /// definite `P`, so it stays positive definite. A navigator calls it when the aiding
    /// sensor has disagreed with the estimate for so long that the estimate is the suspect.
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a non-finite position, or a sigma whose square is below the
    /// variance floor or above the variance ceiling ([`crate::Real::VARIANCE_FLOOR_F64`],
    /// [`crate::Real::VARIANCE_CEILING_F64`]); the
    /// filter is then unchanged.
    pub fn reset_position(&mut self, position: Vector3<T>, sigma: T) -> Result<(), EskfError> {
        self.reset_block(2, position, &Vector3::repeat(sigma))
    }

    /// [`Filter::reset_position`] with a 1σ per world axis, `sigma = [σ_e, σ_n, σ_u]`: the
    /// position block becomes `diag(σ_e², σ_n², σ_u²)` (a GNSS fix's horizontal and vertical
    /// accuracy), decoupled from the rest.
    ///
    /// # Errors
    /// As [`Filter::reset_position`], for any of the three sigmas.
    pub(crate) fn reset_position_per_axis(
        &mut self,
        position: Vector3<T>,
        sigma: &Vector3<T>,
    ) -> Result<(), EskfError> {
        self.reset_block(2, position, sigma)
    }

    /// Resets the velocity as [`Filter::reset_position`] resets the position.
    ///
    /// # Errors
    /// As [`Filter::reset_position`].
    pub fn reset_velocity(&mut self, velocity: Vector3<T>, sigma: T) -> Result<(), EskfError> {
        self.reset_block(1, velocity, &Vector3::repeat(sigma))
    }

    /// Adds `σ² I` to the velocity block of `P`: a velocity change the IMU did not measure
    /// (a clipped accelerometer), of 1σ `sigma` per axis, m/s. `P` stays positive definite.
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a negative or non-finite sigma, or one that takes a
    /// variance above the variance ceiling ([`crate::Real::VARIANCE_CEILING_F64`]); the filter
    /// is then unchanged.
    pub fn widen_velocity(&mut self, sigma: T) -> Result<(), EskfError> {
        self.widen_blocks(&[(1, sigma)])
    }

    /// Adds `σ_g² I` to the gyro-bias block and `σ_a² I` to the accelerometer-bias block of
    /// `P`: biases known less well than `P` says (an estimate carried over from a model that
    /// did not hold). `P` stays positive definite.
    ///
    /// # Errors
    /// As [`Filter::widen_velocity`].
    pub fn widen_biases(&mut self, gyro: T, accel: T) -> Result<(), EskfError> {
        self.widen_blocks(&[(3, gyro), (4, accel)])
    }

    /// Turns the attitude about the world's up direction `u = −g/‖g‖` by `turn` (rad, positive
    /// counter-clockwise seen from above: east towards north in ENU) and replaces what the
    /// filter knew of its heading by a heading of 1σ `sigma`, uncorrelated with every other
    /// state: the heading from a source the filter's own aiding does not see (a bank of yaw
    /// hypotheses resolved by GNSS, an operator's entry). Velocity, position and the biases
    /// are left as they are.
    ///
    /// With the attitude error in the body frame (`R = R̂ Exp(δθ)`), the heading error is
    /// `u_bᵀ δθ`, `u_b = R̂ᵀ u` (unchanged by the turn), and the reset maps the error to
    /// `δθ⁺ = (I − u_b u_bᵀ) δθ + u_b η`, `η ~ N(0, σ²)`:
    ///
    /// ```text
    /// R̂⁺ = Exp(turn · u) R̂,    P⁺ = T P Tᵀ + σ² e eᵀ,    T = blockdiag(I − u_b u_bᵀ, I₁₂),  e = [u_b; 0]
    /// ```
    ///
    /// `T P Tᵀ` is positive semi-definite with `e` its only null direction, which `σ² e eᵀ`
    /// fills: `P⁺` is positive definite for `σ > 0`. The tilt (the attitude error orthogonal
    /// to `u_b`) keeps its variance and its covariance with the other states.
    ///
    /// ```
    /// use estimator_core::eskf::{Alignment, FilterConfig, InitialSigmas, Ins};
    /// use estimator_core::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    ///
    /// let start = Alignment {
    ///     attitude: So3::identity(),
    ///     gyro_bias: Vector3::zeros(),
    ///     heading_from_magnetometer: true,
    /// };
    /// let sigmas = InitialSigmas::default();
    /// let mut ins =
    ///     Ins::<f64>::from_alignment(&start, Vector3::zeros(), &sigmas, FilterConfig::default())
    ///         .unwrap();
    /// ins.reset_heading(0.5, 0.02).unwrap();
    /// let heading = ins.state().attitude.rotation_matrix();
    /// assert!((heading[(1, 0)].atan2(heading[(0, 0)]) - 0.5).abs() < 1e-12);
    /// assert!((ins.covariance()[(2, 2)] - 0.02 * 0.02).abs() < 1e-15);
    /// ```
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a non-finite turn, or a sigma whose square is below the
    /// variance floor or above the variance ceiling; [`EskfError::ZeroNorm`] for a zero gravity;
    /// [`EskfError::NumericalFailure`] when the result is not finite. The filter is then
    /// unchanged.
    #[inline(never)] // rare: its matrices stay out of the caller's frame
    pub fn reset_heading(&mut self, turn: T, sigma: T) -> Result<(), EskfError> {
        if !(turn.is_finite() && usable_variance(sigma * sigma)) {
            return Err(EskfError::NonFinite);
        }
        let Some(up) = up_direction(&self.config.gravity) else {
            return Err(EskfError::ZeroNorm);
        };
        let attitude = So3::exp(&(up * turn)).compose(&self.state.attitude);
        let u = mat3::mul_vec(&self.state.attitude.rotation_matrix().transpose(), &up);
        let project = Matrix3::identity() - mat3::sym_outer(&u, &u) * T::lit(0.5);
        // The attitude block itself: (I − u uᵀ) P_θθ (I − u uᵀ) + σ² u uᵀ, made exactly
        // symmetric, with the attitude floor.
        let a = mat3::mul(
            &mat3::mul(&project, &block(&self.covariance, 0, 0)),
            &project,
        );
        let a = (a + a.transpose()) * T::lit(0.5)
            + mat3::sym_outer(&u, &u) * (sigma * sigma * T::lit(0.5));
        let a = a + Matrix3::from_diagonal_element(attitude_floor(&a));
        // Checked before the first change: the projection does not lengthen a column of the
        // (finite) P, so only the new block and the turned attitude can fail.
        if !(attitude.is_finite() && all_finite(a.as_slice())) {
            return Err(EskfError::NumericalFailure);
        }
        // T P Tᵀ in place: the attitude rows of the other columns multiplied by I − u uᵀ, then
        // mirrored into the attitude columns (column-major: cols[j][i] = P_ij).
        let cols = &mut self.covariance.data.0;
        for col in cols.iter_mut().skip(3) {
            if let Some(head) = col.first_chunk_mut::<3>() {
                *head = mat3::mul_vec(&project, &Vector3::from(*head)).into();
            }
        }
        for j in 3..15 {
            for k in 0..3 {
                let v = cols.get(j).and_then(|c| c.get(k)).copied();
                if let (Some(v), Some(e)) = (v, cols.get_mut(k).and_then(|c| c.get_mut(j))) {
                    *e = v;
                }
            }
        }
        set_block(&mut self.covariance, 0, 0, &a);
        self.state.attitude = attitude;
        Ok(())
    }

    /// Adds `σ² I` to each listed diagonal block; checks every sum before the first change.
    fn widen_blocks(&mut self, blocks: &[(usize, T)]) -> Result<(), EskfError> {
        for (b, sigma) in blocks {
            let v = *sigma * *sigma;
            let fits = (0..3).all(|k| {
                self.covariance
                    .get((3 * b + k, 3 * b + k))
                    .is_some_and(|d| usable_variance(*d + v))
            });
            if !(non_negative_finite(*sigma) && v.is_finite() && fits) {
                return Err(EskfError::NonFinite);
            }
        }
        for (b, sigma) in blocks {
            add_scaled_identity(&mut self.covariance, *b, *b, *sigma * *sigma);
        }
        Ok(())
    }

    /// Block `b` (1: velocity, 2: position) set to `value` with covariance
    /// `diag(σ₁², σ₂², σ₃²)`, decoupled.
    fn reset_block(
        &mut self,
        b: usize,
        value: Vector3<T>,
        sigma: &Vector3<T>,
    ) -> Result<(), EskfError> {
        let variance = sigma.component_mul(sigma);
        if !(all_finite(value.as_slice()) && variance.iter().all(|v| usable_variance(*v))) {
            return Err(EskfError::NonFinite);
        }
        for k in 0..5 {
            set_block(&mut self.covariance, b, k, &Matrix3::zeros());
            set_block(&mut self.covariance, k, b, &Matrix3::zeros());
        }
        set_block(
            &mut self.covariance,
            b,
            b,
            &Matrix3::from_diagonal(&variance),
        );
        if b == 1 {
            self.state.velocity = value;
        } else {
            self.state.position = value;
        }
        Ok(())
    }
}

impl<T: Real> Filter<T, AhrsState<T>, 6> {
    /// From a static [`Alignment`], with `sigmas.tilt`, `sigmas.yaw`, `sigmas.gyro_bias`.
    ///
    /// # Errors
    /// As [`Filter::new`], and [`EskfError::ZeroNorm`] for a zero gravity.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    #[allow(clippy::question_mark)] // a matched, not propagated, matrix result (see `align`)
    pub fn from_alignment(
        alignment: &Alignment<T>,
        sigmas: &InitialSigmas<T>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        let attitude = match prior_attitude_covariance(alignment, sigmas, &config) {
            Ok(a) => a,
            Err(e) => return Err(e),
        };
        let state = AhrsState {
            attitude: alignment.attitude,
            gyro_bias: alignment.gyro_bias,
        };
        let variances = [sigmas.gyro_bias * sigmas.gyro_bias];
        Self::from_block_diagonal(state, &attitude, &variances, config)
    }
}

impl<T: Real> Filter<T, AhrsAccelBiasState<T>, 12> {
    /// From an [`Alignment`] (accelerometer bias and velocity zero), with `sigmas.tilt`,
    /// `sigmas.yaw`, `sigmas.gyro_bias`, `sigmas.accel_bias`, `sigmas.velocity`.
    ///
    /// # Errors
    /// As [`Filter::new`], and [`EskfError::ZeroNorm`] for a zero gravity.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    #[allow(clippy::question_mark)] // a matched, not propagated, matrix result (see `align`)
    pub fn from_alignment(
        alignment: &Alignment<T>,
        sigmas: &InitialSigmas<T>,
        config: FilterConfig<T>,
    ) -> Result<Self, EskfError> {
        config.validate()?;
        let mut filter = Self {
            state: AhrsAccelBiasState::identity(),
            covariance: SMatrix::zeros(),
            config,
        };
        filter.restart_from_alignment(alignment, sigmas)?;
        Ok(filter)
    }

    /// Starts this filter again from an [`Alignment`], as [`Filter::from_alignment`] with its
    /// own configuration, in place (a navigator restarting its filter holds one `P`, not two).
    ///
    /// # Errors
    /// A non-finite alignment, a sigma that is not positive and finite, or a zero gravity; the
    /// filter is then unchanged.
    #[inline(never)] // once at start-up: its matrices stay out of the caller's frame
    #[allow(clippy::question_mark)] // a matched, not propagated, matrix result (see `align`)
    pub fn restart_from_alignment(
        &mut self,
        alignment: &Alignment<T>,
        sigmas: &InitialSigmas<T>,
    ) -> Result<(), EskfError> {
        let attitude = match prior_attitude_covariance(alignment, sigmas, &self.config) {
            Ok(a) => a,
            Err(e) => return Err(e),
        };
        let state = AhrsAccelBiasState {
            attitude: alignment.attitude,
            gyro_bias: alignment.gyro_bias,
            accel_bias: Vector3::zeros(),
            velocity: Vector3::zeros(),
        };
        let sq = |s: T| s * s;
        let variances = [
            sq(sigmas.gyro_bias),
            sq(sigmas.accel_bias),
            sq(sigmas.velocity),
        ];
        self.reset_block_diagonal(state, &attitude, &variances)
    }

    /// Forgets what the filter knew of the velocity: `v = velocity` with 1σ `sigma` per axis,
    /// independent of every other state (block row and column `v` of `P` zeroed, `P_vv = σ² I`).
    /// `P` stays positive definite: what remains is a principal block of the old `P` beside a
    /// positive diagonal. A navigator calls it when the velocity integrated a wrong attitude.
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a non-finite velocity, a sigma that is not positive and
    /// finite or whose square leaves the usable range; the filter is then unchanged.
    pub fn restart_velocity(&mut self, velocity: Vector3<T>, sigma: T) -> Result<(), EskfError> {
        let variance = sigma * sigma;
        if !(all_finite(velocity.as_slice()) && positive_finite(sigma) && usable_variance(variance))
        {
            return Err(EskfError::NonFinite);
        }
        for j in 0..3 {
            set_block(&mut self.covariance, 3, j, &Matrix3::zeros());
            set_block(&mut self.covariance, j, 3, &Matrix3::zeros());
        }
        set_block(
            &mut self.covariance,
            3,
            3,
            &Matrix3::from_diagonal_element(variance),
        );
        self.state.velocity = velocity;
        Ok(())
    }

    /// Moves the velocity over a block of IMU samples whose attitude the predictions have
    /// already carried: `specific_force = Σᵢ R̂ᵢ f_m,ᵢ Δtᵢ` (the raw specific force of each
    /// sample turned to the world by the estimate at that sample, summed over the block),
    /// `frames = Σᵢ R̂ᵢ Δtᵢ` and `duration = Σᵢ Δtᵢ`. With the bias removed,
    /// `s = specific_force − frames·b̂_a`, the velocity is `v⁺ = v + s + g T` (the velocity
    /// equation `v̇ = R f + g` of the INS, integrated by the rectangle rule), and the error of
    /// the velocity grows as
    ///
    /// ```text
    /// δv⁺ = δv − [s]× R̂ δθ − frames·δb_a,      Q_v = N_a² T I,
    /// ```
    ///
    /// from `R f = R̂ Exp(δθ) f ≈ R̂f − [R̂f]× R̂δθ` (the right `⊕` of *Lie Groups and Smooth
    /// Manifolds for Robotic State Estimation*, eq. 4.5, with `R̂ δθ` the world-frame error,
    /// eq. 3.1's adjoint `Ad_R = R`), `N_a` the accelerometer noise density: `P⁺ = G P Gᵀ + Q`
    /// with `G` the identity but for block row `v`, and the mixing and growth floors of the
    /// 15-state prediction on the velocity variances. `R̂ δθ` is taken at the block's end: the
    /// world-frame attitude error moves inside the block only by the gyro bias error, so the
    /// approximation leaves out `½ g T² |δb_g|` (0.01 m/s for a 0.5 s block and a bias error
    /// of 0.01 rad/s).
    ///
    /// # Errors
    /// [`EskfError::NonFinite`] for a non-finite input or a variance that would leave the
    /// usable range, [`EskfError::NonPositiveDt`] for a duration that is not positive; the
    /// filter is then unchanged.
    #[inline(never)] // its own stack frame, not the navigator's
    pub fn integrate_velocity(
        &mut self,
        specific_force: &Vector3<T>,
        frames: &Matrix3<T>,
        duration: T,
    ) -> Result<(), EskfError> {
        if !(all_finite(specific_force.as_slice()) && all_finite(frames.as_slice())) {
            return Err(EskfError::NonFinite);
        }
        if !positive_finite(duration) {
            return Err(EskfError::NonPositiveDt);
        }
        let x = &self.state;
        let s = specific_force - mat3::mul_vec(frames, &x.accel_bias);
        let velocity = x.velocity + s + self.config.gravity * duration;
        let a = -mat3::mul(&crate::lie::skew(&s), &x.attitude.rotation_matrix());
        let b = -frames;
        let p = &self.covariance;
        // Block row 3 of G P: C_j = P_3j + A P_0j + B P_2j.
        let c = |j: usize| {
            block(p, 3, j) + mat3::mul(&a, &block(p, 0, j)) + mat3::mul(&b, &block(p, 2, j))
        };
        let (c0, c1, c2, c3) = (c(0), c(1), c(2), c(3));
        let na = self.config.imu_noise.accelerometer_noise_density;
        let n33 = c3 + mat3::mul(&c0, &a.transpose()) + mat3::mul(&c2, &b.transpose());
        let half = T::lit(0.5);
        // The mixing floor of the 15-state prediction (`floor_mixing`): `[s]× R̂` mixes the
        // three axes, so each velocity variance rounds by a few ε of the products that feed
        // it, `M = ‖s‖² tr P_θθ + ‖frames‖² tr P_aa`, not of its own result.
        let trace = |k: usize| {
            let b = block(p, k, k);
            b.m11 + b.m22 + b.m33
        };
        // ‖frames‖², over the slice (nalgebra's column views carry a panic branch).
        let frames_sq = frames
            .as_slice()
            .iter()
            .fold(T::zero(), |acc, x| acc + *x * *x);
        let products = s.dot(&s) * trace(0) + frames_sq * trace(2);
        let mixing = T::lit(super::covariance::GROWTH_MIXING * T::EPSILON_F64) * products;
        let n33 = (n33 + n33.transpose()) * half
            + Matrix3::from_diagonal_element(na * na * duration + mixing);
        // And the growth floor of every prediction (`floor_growth`): the velocity's growth
        // comes from the attitude and the bias and may be wholly correlated with them; block
        // after block without a velocity update (the bound rejected, the attitude widened) its
        // variance, given them, would fall below the rounding of the block.
        let mut n33 = n33;
        for k in 0..3 {
            let own = p.get((9 + k, 9 + k)).copied().unwrap_or_else(T::zero);
            if let Some(d) = n33.get_mut((k, k)) {
                *d += growth_floor::<T, 12>(*d, own);
            }
        }
        let usable = (0..3).all(|k| n33.get((k, k)).is_some_and(|d| usable_variance(*d)))
            && all_finite(velocity.as_slice())
            && all_finite(c0.as_slice())
            && all_finite(c1.as_slice())
            && all_finite(c2.as_slice());
        if !usable {
            return Err(EskfError::NonFinite);
        }
        // Every check has passed: written in place (no second `P` on the stack).
        let p = &mut self.covariance;
        for (j, cj) in [c0, c1, c2].iter().enumerate() {
            set_block(p, 3, j, cj);
            set_block(p, j, 3, &cj.transpose());
        }
        set_block(p, 3, 3, &n33);
        self.state.velocity = velocity;
        Ok(())
    }
}

/// The largest tilt and yaw sigmas [`Filter::widen_attitude`] may add to the attitude block
/// `A` of a filter at `attitude` under `gravity`: `√(π² − (tr A − u_bᵀ A u_b))` and
/// `√(π² − u_bᵀ A u_b)`, zero when negative. `u_b = Rᵀ u` is the up direction `u = −g/‖g‖`
/// in the body frame, `u_bᵀ A u_b` the heading variance and `tr A − u_bᵀ A u_b` the sum of the
/// two tilt variances. Out of line: one copy per scalar type.
#[inline(never)]
fn widening_room<T: Real>(a: &Matrix3<T>, attitude: &So3<T>, gravity: &Vector3<T>) -> (T, T) {
    // A zero gravity has no up: the widening refuses it (`ZeroNorm`).
    let up = up_direction(gravity).unwrap_or_else(Vector3::zeros);
    let ub = attitude.inverse().act(&up);
    let heading = ub.dot(&mat3::mul_vec(a, &ub));
    let tilts = a.m11 + a.m22 + a.m33 - heading;
    let room = |v: T| {
        let r = T::pi() * T::pi() - v;
        if r > T::zero() {
            r.sqrt_rn()
        } else {
            T::zero()
        }
    };
    (room(tilts), room(heading))
}

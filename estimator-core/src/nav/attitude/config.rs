//! What an attitude navigator is told about its sensors and its motion.

use crate::eskf::FilterConfig;
use crate::kernels::{all_finite, non_negative_finite, positive_finite};
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// What the magnetometer corrects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MagneticFusion {
    /// The heading only ([`MagneticHeading`](crate::eskf::MagneticHeading)): a wrong field can
    /// move the heading but never the tilt. For real magnetometers near iron.
    Heading,
    /// The whole field ([`Magnetometer`](crate::eskf::Magnetometer)): it also measures the
    /// tilt. Only for a calibrated magnetometer in a clean, known field.
    Vector,
}

/// The magnetometer, when there is one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticConfig<T: Real> {
    /// The world reference field (any unit, the magnetometer's), ENU: `[0, B_h, B_up]` with
    /// north along world `y`. `None`: learned at start-up from the first samples, which then
    /// define north.
    pub reference: Option<Vector3<T>>,
    /// White noise of one sample, per axis (the magnetometer's unit).
    pub sigma: T,
    /// What it corrects ([`MagneticFusion::Heading`] by default).
    pub fusion: MagneticFusion,
    /// Heading noise beyond the white noise, as a density, rad·√s (a block of length `T` gets
    /// `σ² = N²/T`): what a magnetometer reads wrong for a while without the norm or the dip
    /// showing it (iron nearby, residual calibration, the tilt error seen through the dip). It
    /// sets how fast the heading follows the magnetometer, whatever the block length.
    pub heading_noise: T,
    /// The heading is never known better than this, rad: a lower bound on its 1σ, for the
    /// calibration error that does not average out.
    pub heading_floor: T,
    /// A block whose field norm differs from the reference by more than this fraction is
    /// disturbed and not fused.
    pub norm_tolerance: T,
    /// A block whose dip angle differs from the reference by more than this, rad, is disturbed.
    pub dip_tolerance: T,
    /// A disturbed field that stays the same (within the two tolerances) for this long, s…
    pub new_field_s: T,
    /// …while the body turned at a mean rate of at least this, rad/s.
    pub new_field_min_rate: T,
    /// Learn the magnetometer's hard iron (a constant offset in the body frame) while the
    /// body turns, and take it off every sample (the `hard_iron` module of the navigator).
    pub hard_iron: bool,
    /// The hard iron's prior 1σ per axis, as a fraction of the field's norm: what the
    /// magnetometer's calibration leaves. Also the residual (beyond the white noise) up to
    /// which a block counts as explained by the offset, and a new offset is taken once known
    /// to a third of it.
    pub hard_iron_sigma: T,
    /// The largest offset ever taken, as a fraction of the field's norm; a field that only a
    /// larger one would explain is a disturbance.
    pub hard_iron_max: T,
    /// How fast the offset may drift, as a fraction of the field's norm per √s (a random
    /// walk).
    pub hard_iron_drift: T,
    /// The magnetometer's delay behind the gyro known beforehand, s: a sample stamped `t` is
    /// the field at `t − delay_s` (its conversion and output filter). Where the delay is
    /// learned (`delay_max_s > 0`), the value it starts from.
    pub delay_s: T,
    /// The largest delay learned, s; 0: the delay is not learned and stays `delay_s`. The
    /// delay is learned from the heading innovations while the body turns about the vertical
    /// (the `magnetic` module of the navigator).
    pub delay_max_s: T,
    /// A magnetometer whose samples repeat bit for bit for this long, s, is stuck or saturated
    /// (its noise alone changes the last bits of a working one; one that holds its output
    /// between conversions repeats it for one output interval): its samples are not used
    /// until they change.
    pub stuck_s: T,
}

/// The longest magnetometer delay a configuration may give, s: the frame of a delayed sample
/// is carried back from the newest IMU sample by its rate, which holds over a fraction of a
/// second, not longer.
const MAX_DELAY_S: f64 = 0.25;

impl<T: Real> MagneticConfig<T> {
    /// A magnetometer with white noise `sigma` per axis and an optional reference; the other
    /// values are the defaults listed on each field's use: heading-only fusion, 8°·√s heading noise, 1°
    /// heading floor, 10 % norm and 10° dip tolerance, 20 s turning at 20 °/s or more for a new field;
    /// the hard iron learned online, with a prior of 3 % of the field per axis (a calibrated
    /// magnetometer's residual offset: about 1.5 µT of the Earth's 25–65 µT), a bound of 3 times
    /// the field (a magnet that strong at the sensor is a fault of the board, and near the
    /// range of a MEMS magnetometer), and a drift of 0.1 % of the field per √s (1 % in 100 s:
    /// a magnet's field changes by about 0.1 %/K, a battery's with its current); the delay
    /// behind the gyro learned from 0 up to 50 ms (a MEMS magnetometer's conversion and output
    /// filter at the 20 Hz and faster output rates used beside an IMU: one output interval at
    /// most).
    #[must_use]
    pub fn new(sigma: T, reference: Option<Vector3<T>>) -> Self {
        Self {
            reference,
            sigma,
            fusion: MagneticFusion::Heading,
            heading_noise: T::lit(8.0_f64.to_radians()),
            heading_floor: T::lit(1.0_f64.to_radians()),
            norm_tolerance: T::lit(0.1),
            dip_tolerance: T::lit(10.0_f64.to_radians()),
            new_field_s: T::lit(20.0),
            new_field_min_rate: T::lit(20.0_f64.to_radians()),
            hard_iron: true,
            hard_iron_sigma: T::lit(0.03),
            hard_iron_max: T::lit(3.0),
            hard_iron_drift: T::lit(0.001),
            delay_s: T::zero(),
            delay_max_s: T::lit(0.05),
            stuck_s: T::lit(0.5),
        }
    }

    fn validate(&self) -> Result<(), NavError> {
        let reference_ok = match &self.reference {
            Some(r) => all_finite(r.as_slice()) && r.norm_squared() > T::zero(),
            None => true,
        };
        let ok = reference_ok
            && positive_finite(self.sigma)
            && non_negative_finite(self.heading_noise)
            && non_negative_finite(self.heading_floor)
            && positive_finite(self.norm_tolerance)
            && positive_finite(self.dip_tolerance)
            && positive_finite(self.new_field_s)
            && non_negative_finite(self.new_field_min_rate)
            && positive_finite(self.hard_iron_sigma)
            && positive_finite(self.hard_iron_max)
            && non_negative_finite(self.hard_iron_drift)
            && non_negative_finite(self.delay_s)
            && non_negative_finite(self.delay_max_s)
            && self.delay_s <= T::lit(MAX_DELAY_S)
            && self.delay_max_s <= T::lit(MAX_DELAY_S)
            && (self.delay_max_s == T::zero() || self.delay_s <= self.delay_max_s)
            && positive_finite(self.stuck_s)
            && self.stuck_s < T::lit(4.0);
        if ok {
            Ok(())
        } else {
            Err(NavError::InvalidConfig)
        }
    }
}

/// The configuration of an [`AttitudeNavigator`](super::AttitudeNavigator).
///
/// Every time is in seconds and every angle in radians. [`AttitudeConfig::new`] fills in
/// defaults for a hand-held or body-worn MEMS IMU; the tuning guide in the module docs of
/// [`crate::nav`] says which value does what.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeConfig<T: Real> {
    /// The filter: IMU noise densities, gravity, and `max_dt`, the longest IMU interval that
    /// is integrated; a longer one is a gap after which the navigator starts again.
    pub filter: FilterConfig<T>,
    /// The IMU samples are instantaneous values (integrated over an interval with the mean of
    /// its two ends) rather than means over the interval ending at their timestamp. A MEMS
    /// IMU's output is the mean of its internal samples since the previous output (its
    /// decimation filter), so the default is `false`; a simulator's samples are instants.
    pub instantaneous_imu: bool,
    /// Length of the start-up window, s: the accelerometer, gyro and magnetometer are averaged
    /// over it for the first attitude.
    pub startup_s: T,
    /// Length of one aiding block, s: the accelerometer and magnetometer are averaged over a
    /// block (in a frame carried along by the gyro) and fused once at its end.
    pub block_s: T,
    /// The body only rotates in place (a gimbal, a turntable): the accelerometer sees gravity,
    /// its bias and white noise, and the motion terms of the accelerometer noise are left out.
    pub rotation_only: bool,
    /// The smallest spread (1σ per axis) of a moving body's velocity, m/s: the velocity bound
    /// that measures the tilt (`tilt` in the module docs) is never tighter than this while the
    /// body moves.
    pub velocity_sigma: T,
    /// Memory of the velocity spread, s: the running mean of the estimated velocity's square,
    /// which loosens the bound for a body that moves faster.
    pub motion_memory_s: T,
    /// 1σ of the accelerometer bias per axis at switch-on, m/s², `> 0` (the bias is a state
    /// with this prior; its random walk is the filter configuration's).
    pub accelerometer_bias_sigma: T,
    /// 1σ of the gyro's scale-factor and cross-axis errors (a fraction): a block of length `T`
    /// turning at an RMS rate `ω` adds `(σ_s ω)² T τ_turn` to the attitude variance on every
    /// axis, `τ_turn` = 0.5 s the time a body keeps turning one way (the error of one turn is
    /// coherent, the next turn's independent of it). The noise densities of a
    /// data sheet do not contain this error; it dominates during fast rotation.
    pub gyro_scale_sigma: T,
    /// 1σ of the gyro bias at switch-on per axis, rad/s (used when the start is not at rest).
    pub gyro_bias_sigma: T,
    /// At rest when the RMS gyro rate about the bias estimate is below this, rad/s…
    pub rest_gyro: T,
    /// …and the RMS linear acceleration below this, m/s²…
    pub rest_accel: T,
    /// …for at least this long, s.
    pub rest_min_s: T,
    /// 1σ of the remaining rate of a body found at rest, rad/s (the floor of the zero-rate
    /// update).
    pub rest_rate_sigma: T,
    /// After this many consecutive gated-out blocks of one aid, the navigator takes its own
    /// estimate for wrong, widens its covariance to the innovation, and fuses again.
    pub max_rejected_blocks: u16,
    /// Tilt reported valid while its 1σ is below this, rad.
    pub tilt_valid_sigma: T,
    /// Heading reported valid while its 1σ is below this, rad.
    pub heading_valid_sigma: T,
    /// The gyro's full scale, rad/s: a sample with an axis within 0.1 % of it is at the rail
    /// (the body turned at least that fast, by how much more is unknown), one beyond it by more
    /// than 1 % is no reading the sensor can give, and is refused.
    pub gyro_range: T,
    /// The accelerometer's full scale, m/s² (as `gyro_range`).
    pub accel_range: T,
    /// The magnetometer, if any.
    pub magnetometer: Option<MagneticConfig<T>>,
}

impl<T: Real> AttitudeConfig<T> {
    /// The defaults around a filter configuration: IMU samples as means over their interval;
    /// 1 s start-up;
    /// 0.25 s blocks; a moving body's velocity spread at least 0.3 m/s per axis, remembered
    /// over 5 s; 0.1 m/s² accelerometer bias (0.6° of
    /// tilt); 0.5 % gyro scale and cross-axis error; 0.5 °/s gyro bias at switch-on; rest below 2 °/s and 0.5 m/s² for 1.5 s with a
    /// 0.1 °/s floor; widen after 8 rejected blocks (2 s); valid below 5° tilt and 10° heading;
    /// a ±2000 °/s gyro and a ±16 g accelerometer (the widest ranges of MEMS IMUs); no
    /// magnetometer.
    #[must_use]
    pub fn new(filter: FilterConfig<T>) -> Self {
        Self {
            filter,
            instantaneous_imu: false,
            startup_s: T::lit(1.0),
            block_s: T::lit(0.25),
            rotation_only: false,
            velocity_sigma: T::lit(0.3),
            motion_memory_s: T::lit(5.0),
            accelerometer_bias_sigma: T::lit(0.1),
            gyro_scale_sigma: T::lit(0.005),
            gyro_bias_sigma: T::lit(0.5_f64.to_radians()),
            rest_gyro: T::lit(2.0_f64.to_radians()),
            rest_accel: T::lit(0.5),
            rest_min_s: T::lit(1.5),
            rest_rate_sigma: T::lit(0.1_f64.to_radians()),
            max_rejected_blocks: 8,
            tilt_valid_sigma: T::lit(5.0_f64.to_radians()),
            heading_valid_sigma: T::lit(10.0_f64.to_radians()),
            gyro_range: T::lit(2000.0_f64.to_radians()),
            accel_range: T::lit(16.0 * 9.806_65),
            magnetometer: None,
        }
    }

    /// `Ok` when every value is in its domain: the filter configuration valid, every time and
    /// sigma positive (the gyro bias, scale and heading sigmas may be 0), `max_rejected_blocks ≥ 1`, and the block and
    /// start-up shorter than 4 s (their length in nanoseconds fits 32 bits); a gravity whose
    /// norm is between [`GRAVITY_MIN`](crate::nav::GRAVITY_MIN) and
    /// [`GRAVITY_MAX`](crate::nav::GRAVITY_MAX).
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`], or the filter's own error.
    pub fn validate(&self) -> Result<(), NavError> {
        self.filter.validate()?;
        let four_seconds = T::lit(4.0);
        let ok = positive_finite(self.startup_s)
            && self.startup_s < four_seconds
            && positive_finite(self.block_s)
            && self.block_s < four_seconds
            && positive_finite(self.velocity_sigma)
            && positive_finite(self.motion_memory_s)
            && positive_finite(self.accelerometer_bias_sigma)
            && non_negative_finite(self.gyro_scale_sigma)
            && non_negative_finite(self.gyro_bias_sigma)
            && positive_finite(self.gyro_range)
            && positive_finite(self.accel_range)
            && positive_finite(self.rest_gyro)
            && positive_finite(self.rest_accel)
            && non_negative_finite(self.rest_min_s)
            && positive_finite(self.rest_rate_sigma)
            && self.max_rejected_blocks >= 1
            && positive_finite(self.tilt_valid_sigma)
            && positive_finite(self.heading_valid_sigma)
            && self.filter.max_dt < four_seconds
            && crate::nav::sample::within_limits(
                crate::kernels::mat3::norm(&self.filter.gravity),
                crate::nav::GRAVITY_MIN,
                crate::nav::GRAVITY_MAX,
            );
        if !ok {
            return Err(NavError::InvalidConfig);
        }
        match &self.magnetometer {
            Some(m) => m.validate(),
            None => Ok(()),
        }
    }
}

//! One public entry point of estimator-core alone in a firmware: the way a user's firmware holds
//! one call, with one call site for LTO to inline or not. The entry is chosen when the binary is
//! built, by name, in the environment variable `SINGLE_ENTRY` (one of [`ENTRIES`]; `f64` with
//! `--features f64`, else `f32`):
//!
//! ```sh
//! SINGLE_ENTRY=ins-gnss-position cargo build --profile release-s --bin single
//! ```
//!
//! The binary links only if no panic path is reachable from that call and what builds its
//! arguments (the filter's constructor). `.ci/firmware.sh` links every entry over the matrix of
//! opt-levels, CPU models and scalar types. An unknown name fails the build; without the
//! variable the binary calls nothing.
#![no_std]
#![no_main]

#[allow(dead_code)] // `input3` is for `f32` only; this binary builds its own
#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
use estimator_core::eskf::{
    align_at_rest, AccelerometerAtRest, Ahrs, AhrsAccelBias, AhrsAccelBiasState, AhrsState,
    Alignment, BaroAltitude, CameraLandmark, FilterConfig, GnssPosition, GnssVelocity,
    GravityDirection, Heading, ImuSample, InitialSigmas, Ins, InsState, MagneticHeading,
    Magnetometer, PinholeIntrinsics, UpdateOptions, ZeroRate, ZeroVelocity,
};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, GnssFix, InsConfig, InsNavigator, MagneticConfig,
};
use footprint::keep;
use nalgebra::{SMatrix, Vector2, Vector3, Vector6};

/// The scalar type of the build.
#[cfg(not(feature = "f64"))]
type F = f32;
/// The scalar type of the build.
#[cfg(feature = "f64")]
type F = f64;

/// An opaque number of the build's scalar type ([`footprint::input`]).
#[inline(always)]
fn x(i: usize) -> F {
    F::from(footprint::input(i))
}

/// Three opaque numbers from `i` on.
#[inline(always)]
fn x3(i: usize) -> Vector3<F> {
    Vector3::new(x(i), x(i + 1), x(i + 2))
}

/// Every entry this binary can hold: the calls a firmware main loop makes (each filter's
/// prediction and each of its measurement models, both navigators' sensor calls) and the
/// constructors that start them.
const ENTRIES: [&str; 36] = [
    "ins-new",
    "ins-from-alignment",
    "ins-predict",
    "ins-gnss-position",
    "ins-gnss-velocity",
    "ins-zero-velocity",
    "ins-baro",
    "ins-magnetometer",
    "ins-gravity",
    "ins-heading",
    "ins-accel-at-rest",
    "ins-zero-rate",
    "ins-magnetic-heading",
    "ins-camera",
    "ins-widen-reset",
    "ahrs-new",
    "ahrs-predict",
    "ahrs-magnetometer",
    "ahrs-gravity",
    "ahrs-heading",
    "ahrs-zero-rate",
    "ahrs-magnetic-heading",
    "ahrs-widen-attitude",
    "aab-from-alignment",
    "aab-predict",
    "aab-zero-rate",
    "aab-accel-at-rest",
    "aab-magnetic-heading",
    "aab-gravity",
    "aab-magnetometer",
    "align-at-rest",
    "attitude-navigator-imu",
    "attitude-navigator-magnetometer",
    "ins-navigator-imu",
    "ins-navigator-gnss",
    "ins-navigator-magnetometer-barometer",
];

/// The entry chosen at build time, or `""`.
const ENTRY: &str = match option_env!("SINGLE_ENTRY") {
    Some(e) => e,
    None => "",
};

/// `a == b`, at compile time.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// `ENTRY` is empty or one of [`ENTRIES`].
const fn known(entry: &str) -> bool {
    let mut i = 0;
    while i < ENTRIES.len() {
        if same(entry, ENTRIES[i]) {
            return true;
        }
        i += 1;
    }
    entry.is_empty()
}

const _: () = assert!(known(ENTRY), "SINGLE_ENTRY names no entry of ENTRIES");

/// Runs the block when the binary is built for entry `$name` (a constant condition: the other
/// blocks are not compiled into the binary).
macro_rules! only {
    ($name:literal, $body:block) => {{
        const ON: bool = same(ENTRY, $name);
        const _: () = assert!(known($name), "not in ENTRIES");
        if ON $body
    }};
}

#[entry]
fn main() -> ! {
    let config = FilterConfig::<F>::default();
    let options = UpdateOptions::<F>::default();
    let ins_new = || {
        Ins::new(
            InsState::identity(),
            SMatrix::<F, 15, 15>::identity() * x(7),
            config,
        )
    };
    let ahrs_new = || Ahrs::new(AhrsState::identity(), SMatrix::<F, 6, 6>::identity() * x(7), config);
    let aab_new = || {
        AhrsAccelBias::new(
            AhrsAccelBiasState::identity(),
            SMatrix::<F, 9, 9>::identity() * x(7),
            config,
        )
    };
    let alignment = || Alignment {
        attitude: So3::exp(&x3(0)),
        gyro_bias: x3(1),
        heading_from_magnetometer: false,
    };
    let mut ins = ins_new();
    let mut ahrs = ahrs_new();
    let mut aab = aab_new();
    let mut att_nav = AttitudeNavigator::<F>::new({
        let mut c = AttitudeConfig::new(config);
        c.magnetometer = Some(MagneticConfig::new(x(6), Some(x3(4))));
        c
    });
    let mut ins_nav = InsNavigator::<F>::new({
        let mut a = AttitudeConfig::new(config);
        a.magnetometer = Some(MagneticConfig::new(x(6), Some(x3(4))));
        let mut c = InsConfig::new(a);
        c.barometer_sigma = Some(x(6));
        c
    });
    let mut t: u64 = 1_000_000_000;
    loop {
        t += 5_000_000;
        let imu = ImuSample {
            gyro: x3(0),
            accel: x3(1),
            dt: x(7),
        };
        only!("ins-new", { keep(&ins_new()) });
        only!("ins-from-alignment", {
            keep(&Ins::from_alignment(&alignment(), x3(2), &InitialSigmas::default(), config));
        });
        macro_rules! ins_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut ins {
                        keep(&$call);
                    }
                })
            };
        }
        ins_call!("ins-predict", f => f.predict(&imu));
        ins_call!("ins-gnss-position", f => f.update(&GnssPosition::new(x3(2), x3(5), x(6)), &options));
        ins_call!("ins-gnss-velocity", f => f.update(&GnssVelocity::new(x3(2), x(6)), &options));
        ins_call!("ins-zero-velocity", f => f.update(&ZeroVelocity::new(x(6)), &options));
        ins_call!("ins-baro", f => f.update(&BaroAltitude::new(x(3), x(6)), &options));
        ins_call!("ins-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        ins_call!("ins-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        ins_call!("ins-heading", f => f.update(&Heading::new(x(2), x(7)), &options));
        ins_call!("ins-accel-at-rest", f => f.update(&AccelerometerAtRest::new(x3(1), x(7)), &options));
        ins_call!("ins-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        ins_call!("ins-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        ins_call!("ins-camera", f => {
            let intrinsics = PinholeIntrinsics { fx: x(6), fy: x(6), cx: x(4), cy: x(5) };
            let camera = Se3::exp(&Vector6::repeat(x(0)));
            f.update(&CameraLandmark::new(Vector2::new(x(3), x(4)), x3(0), intrinsics, camera, x(1)), &options)
        });
        ins_call!("ins-widen-reset", f => (
            f.widen_velocity(x(3)),
            f.widen_biases(x(6), x(7)),
            f.reset_position(x3(3), x(4)),
            f.reset_velocity(x3(0), x(5)),
        ));
        only!("ahrs-new", { keep(&ahrs_new()) });
        macro_rules! ahrs_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut ahrs {
                        keep(&$call);
                    }
                })
            };
        }
        ahrs_call!("ahrs-predict", f => f.predict(&imu));
        ahrs_call!("ahrs-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        ahrs_call!("ahrs-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        ahrs_call!("ahrs-heading", f => f.update(&Heading::new(x(2), x(7)), &options));
        ahrs_call!("ahrs-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        ahrs_call!("ahrs-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        ahrs_call!("ahrs-widen-attitude", f => f.widen_attitude(x(0), x(1)));
        only!("aab-from-alignment", {
            keep(&AhrsAccelBias::from_alignment(&alignment(), &InitialSigmas::default(), config));
        });
        macro_rules! aab_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut aab {
                        keep(&$call);
                    }
                })
            };
        }
        aab_call!("aab-predict", f => f.predict(&imu));
        aab_call!("aab-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        aab_call!("aab-accel-at-rest", f => f.update(&AccelerometerAtRest::new(x3(1), x(7)), &options));
        aab_call!("aab-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        aab_call!("aab-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        aab_call!("aab-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        only!("align-at-rest", {
            let samples = [x3(1); 8];
            let gyro = [x3(0); 8];
            keep(&align_at_rest(&samples, &gyro, &config.gravity, None, x(7)));
        });
        only!("attitude-navigator-imu", {
            if let Ok(n) = &mut att_nav {
                keep(&n.imu(t, &x3(0), &x3(1)));
            }
        });
        only!("attitude-navigator-magnetometer", {
            if let Ok(n) = &mut att_nav {
                keep(&n.magnetometer(t, &x3(4)));
            }
        });
        only!("ins-navigator-imu", {
            if let Ok(n) = &mut ins_nav {
                keep(&n.imu(t, &x3(0), &x3(1)));
            }
        });
        only!("ins-navigator-gnss", {
            if let Ok(n) = &mut ins_nav {
                keep(&n.gnss(t, &GnssFix::new(x3(2), Some(x3(3)), x(6), x(7))));
            }
        });
        only!("ins-navigator-magnetometer-barometer", {
            if let Ok(n) = &mut ins_nav {
                keep(&(n.magnetometer(t, &x3(4)), n.barometer(t, x(3))));
            }
        });
        keep(&t);
    }
}

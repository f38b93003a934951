//! One public entry point of estimator-core alone in a firmware, selected by a `single-*`
//! feature: the way a user's firmware holds one call, with one call site for LTO to inline or
//! not. `.ci/firmware.sh` links it for every such feature at several opt-levels; it links only
//! if no panic path is reachable from that one call. Without a feature it calls nothing.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
#[allow(unused_imports)]
use estimator_core::eskf::{
    Ahrs, AhrsState, FilterConfig, GnssPosition, GravityDirection, Heading, ImuSample, Ins,
    InsState, Magnetometer, UpdateOptions,
};
#[allow(unused_imports)]
use estimator_core::nav::{AttitudeConfig, AttitudeNavigator, InsConfig, InsNavigator};
#[allow(unused_imports)]
use footprint::{input, input3, keep};
#[allow(unused_imports)]
use nalgebra::{SMatrix, Vector3};

#[entry]
fn main() -> ! {
    #[cfg(any(
        feature = "single-ins-predict",
        feature = "single-ins-gnss-position",
        feature = "single-ins-magnetometer",
        feature = "single-ins-heading"
    ))]
    let mut ins = Ins::new(
        InsState::identity(),
        SMatrix::<f32, 15, 15>::identity() * input(7),
        FilterConfig::default(),
    );
    #[cfg(any(
        feature = "single-ahrs-predict",
        feature = "single-ahrs-gravity",
        feature = "single-ahrs-magnetometer"
    ))]
    let mut ahrs = Ahrs::new(
        AhrsState::identity(),
        SMatrix::<f32, 6, 6>::identity() * input(7),
        FilterConfig::default(),
    );
    #[cfg(feature = "single-ins-navigator-imu")]
    let mut nav =
        InsNavigator::<f32>::new(InsConfig::new(AttitudeConfig::new(FilterConfig::default())));
    #[cfg(feature = "single-attitude-navigator-imu")]
    let mut nav = AttitudeNavigator::<f32>::new(AttitudeConfig::new(FilterConfig::default()));
    let mut t: u64 = 1_000_000_000;
    loop {
        t += 5_000_000;
        let _ = t;
        #[allow(unused_variables)]
        let options = UpdateOptions::<f32>::default();
        #[allow(unused_variables)]
        let imu = ImuSample {
            gyro: input3(0),
            accel: input3(1),
            dt: input(7),
        };
        #[cfg(feature = "single-ins-predict")]
        if let Ok(f) = &mut ins {
            keep(&f.predict(&imu));
        }
        #[cfg(feature = "single-ins-gnss-position")]
        if let Ok(f) = &mut ins {
            let z = GnssPosition::new(input3(2), input3(5), input(6));
            keep(&f.update(&z, &options));
        }
        #[cfg(feature = "single-ins-magnetometer")]
        if let Ok(f) = &mut ins {
            keep(&f.update(&Magnetometer::new(input3(4), input3(1), input(7)), &options));
        }
        #[cfg(feature = "single-ins-heading")]
        if let Ok(f) = &mut ins {
            keep(&f.update(&Heading::new(input(2), input(7)), &options));
        }
        #[cfg(feature = "single-ahrs-predict")]
        if let Ok(f) = &mut ahrs {
            keep(&f.predict(&imu));
        }
        #[cfg(feature = "single-ahrs-gravity")]
        if let Ok(f) = &mut ahrs {
            keep(&f.update(&GravityDirection::new(input3(1), input(7)), &options));
        }
        #[cfg(feature = "single-ahrs-magnetometer")]
        if let Ok(f) = &mut ahrs {
            keep(&f.update(&Magnetometer::new(input3(4), input3(1), input(7)), &options));
        }
        #[cfg(any(
            feature = "single-ins-navigator-imu",
            feature = "single-attitude-navigator-imu"
        ))]
        if let Ok(n) = &mut nav {
            keep(&n.imu(t, &input3(0), &input3(1)));
        }
        keep(&t);
    }
}

//! Footprint: an attitude and heading reference (the 6-state filter) fed by a gyroscope, an
//! accelerometer (gravity direction) and a magnetometer. See `src/footprint/mod.rs`.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
use estimator_core::eskf::{
    Ahrs, AhrsState, FilterConfig, GravityDirection, ImuSample, Magnetometer, UpdateOptions,
};
use footprint::{input, input3, keep};
use nalgebra::{SMatrix, Vector3};

#[entry]
fn main() -> ! {
    let start = AhrsState::identity();
    let p0 = SMatrix::<f32, 6, 6>::identity() * input(7);
    let Ok(mut ahrs) = Ahrs::new(start, p0, FilterConfig::default()) else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let options = UpdateOptions::default();
    let reference = Vector3::new(0.2, 0.0, -0.4);
    loop {
        keep(&ahrs.predict(&ImuSample {
            gyro: input3(0),
            accel: input3(1),
            dt: input(7),
        }));
        keep(&ahrs.update(&GravityDirection::new(input3(1), input(7)), &options));
        keep(&ahrs.update(&Magnetometer::new(input3(2), reference, input(7)), &options));
        keep(ahrs.state());
    }
}

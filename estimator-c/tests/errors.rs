//! Every refusal of the C interface: the right code, no output written, and the navigator bit
//! for bit what it was (its storage unchanged for errors of the boundary; its estimate and
//! report for a sample the navigator refuses, which counts it).

mod common;

use common::{turning_body, Sample};
use core::ffi::{c_void, CStr};
use estimator_c::*;
use std::ptr::{null, null_mut};

/// Storage for either navigator, aligned beyond what both need.
#[repr(C, align(64))]
struct Storage([u8; 8192]);

fn storage() -> Box<Storage> {
    assert!(est_attitude_storage_size() <= 8192 && est_ins_storage_size() <= 8192);
    assert!(est_attitude_storage_align() <= 64 && est_ins_storage_align() <= 64);
    Box::new(Storage([0; 8192]))
}

fn ptr(s: &mut Storage) -> *mut c_void {
    s.0.as_mut_ptr().cast()
}

fn attitude_config() -> est_attitude_config {
    // SAFETY (tests): every pointer given below points to a live local of the right type.
    let mut cfg = unsafe { std::mem::zeroed::<est_attitude_config>() };
    assert_eq!(
        unsafe { est_attitude_config_default(&mut cfg) },
        est_error::EST_OK
    );
    cfg.instantaneous_imu = true;
    cfg.has_magnetometer = true;
    cfg.magnetometer_sigma = 0.5;
    cfg.has_magnetometer_reference = true;
    cfg.magnetometer_reference = common::FIELD;
    cfg
}

fn init_attitude(s: &mut Storage, cfg: &est_attitude_config) -> *mut est_attitude {
    let mut nav = null_mut();
    let code = unsafe { est_attitude_init(ptr(s), s.0.len(), cfg, &mut nav) };
    assert_eq!(code, est_error::EST_OK);
    assert_eq!(nav.cast::<c_void>(), ptr(s), "the handle is the storage");
    nav
}

/// A navigator fed `seconds` of the turning body (started, magnetometer fused).
fn running_attitude(s: &mut Storage, seconds: u64) -> *mut est_attitude {
    let nav = init_attitude(s, &attitude_config());
    for sample in turning_body(seconds).0 {
        let code = match sample {
            Sample::Imu { t_ns, gyro, accel } => unsafe {
                est_attitude_imu(nav, t_ns, gyro.as_ptr(), accel.as_ptr())
            },
            Sample::Mag { t_ns, field } => unsafe {
                est_attitude_magnetometer(nav, t_ns, field.as_ptr())
            },
        };
        assert_eq!(code, est_error::EST_OK);
    }
    nav
}

/// Every number of the estimate and the report, as bits (NaN-proof equality).
fn attitude_bits(nav: *const est_attitude) -> Vec<u64> {
    let mut e = unsafe { std::mem::zeroed::<est_attitude_estimate>() };
    let mut r = unsafe { std::mem::zeroed::<est_attitude_report>() };
    assert_eq!(
        unsafe { est_attitude_get_estimate(nav, &mut e) },
        est_error::EST_OK
    );
    assert_eq!(
        unsafe { est_attitude_get_report(nav, &mut r) },
        est_error::EST_OK
    );
    let scalars = [e.sigma_tilt, e.sigma_heading, e.magnetometer_delay_s];
    let floats = e
        .quaternion
        .iter()
        .chain(&e.gyro_bias)
        .chain(&e.accel_bias)
        .chain(&scalars)
        .chain(&e.hard_iron)
        .chain(&e.sigma_hard_iron);
    let mut bits: Vec<u64> = floats.map(|x| u64::from(x.to_bits())).collect();
    bits.extend([
        e.t_ns,
        r.t_ns,
        u64::from(r.tilt.valid),
        r.tilt.reason as u64,
        u64::from(r.heading.valid),
        r.heading.reason as u64,
        u64::from(r.at_rest),
        u64::from(r.clipped),
        r.magnetic as u64,
        r.event as u64,
    ]);
    bits
}

fn refused(nav: *const est_attitude) -> u32 {
    let mut c = est_attitude_counters::default();
    assert_eq!(
        unsafe { est_attitude_get_counters(nav, &mut c) },
        est_error::EST_OK
    );
    c.refused
}

#[test]
fn init_checks_its_pointers_storage_and_configuration() {
    let mut s = storage();
    let cfg = attitude_config();
    let sentinel = std::ptr::dangling_mut::<est_attitude>();
    let mut out = sentinel;
    let size = s.0.len();
    let base = ptr(&mut s);
    let cases: [(*mut c_void, usize, *const est_attitude_config, est_error); 5] = [
        (null_mut(), size, &cfg, est_error::EST_ERR_NULL_POINTER),
        (base, size, null(), est_error::EST_ERR_NULL_POINTER),
        // One byte in: misaligned for the navigator.
        (
            base.wrapping_byte_add(1),
            size - 1,
            &cfg,
            est_error::EST_ERR_MISALIGNED,
        ),
        (
            base,
            est_attitude_storage_size() - 1,
            &cfg,
            est_error::EST_ERR_STORAGE_TOO_SMALL,
        ),
        (base, 0, &cfg, est_error::EST_ERR_STORAGE_TOO_SMALL),
    ];
    for (storage, size, cfg, expected) in cases {
        assert_eq!(
            unsafe { est_attitude_init(storage, size, cfg, &mut out) },
            expected
        );
        assert_eq!(out, sentinel, "no handle written on {expected:?}");
    }
    assert_eq!(
        unsafe { est_attitude_init(base, size, &cfg, null_mut()) },
        est_error::EST_ERR_NULL_POINTER
    );
    assert!(s.0.iter().all(|&b| b == 0), "a refused init writes nothing");
    // Exactly the size asked for is enough.
    let code = unsafe { est_attitude_init(base, est_attitude_storage_size(), &cfg, &mut out) };
    assert_eq!(code, est_error::EST_OK);
    assert_eq!(out.cast::<c_void>(), base);
}

#[test]
fn init_validates_the_configuration_through_estimator_core() {
    let mut s = storage();
    let base = ptr(&mut s);
    let mut out = null_mut();
    let good = attitude_config();
    let mut cases = Vec::new();
    let mut c = good;
    c.magnetometer_sigma = -1.0;
    cases.push((c, est_error::EST_ERR_INVALID_CONFIG));
    c = good;
    c.magnetometer_fusion = 7; // no such est_magnetic_fusion
    cases.push((c, est_error::EST_ERR_INVALID_CONFIG));
    c = good;
    c.block_s = 5.0; // at most 4 s
    cases.push((c, est_error::EST_ERR_INVALID_CONFIG));
    c = good;
    c.gravity = [0.0, 0.0, 1e29];
    cases.push((c, est_error::EST_ERR_INVALID_CONFIG));
    c = good;
    c.gravity[2] = f32::NAN; // the filter's own check
    cases.push((c, est_error::EST_ERR_FILTER));
    c = good;
    c.gyro_noise_density = -1.0;
    cases.push((c, est_error::EST_ERR_FILTER));
    c = good;
    c.has_magnetometer = true;
    c.magnetometer_sigma = 0.0; // the default: must be set with a magnetometer
    cases.push((c, est_error::EST_ERR_INVALID_CONFIG));
    for (cfg, expected) in cases {
        assert_eq!(
            unsafe { est_attitude_init(base, s.0.len(), &cfg, &mut out) },
            expected
        );
        assert!(out.is_null());
    }
    assert!(s.0.iter().all(|&b| b == 0), "a refused init writes nothing");
    // The handle of a refused init was never made: the storage is not a navigator.
    let handle = base.cast::<est_attitude>();
    let (g, a) = ([0.0f32; 3], [0.0f32, 0.0, 9.81]);
    let code = unsafe { est_attitude_imu(handle, 1, g.as_ptr(), a.as_ptr()) };
    assert_eq!(code, est_error::EST_ERR_NOT_INITIALIZED);
}

#[test]
fn the_default_configuration_is_estimator_cores() {
    let mut a = unsafe { std::mem::zeroed::<est_attitude_config>() };
    assert_eq!(
        unsafe { est_attitude_config_default(&mut a) },
        est_error::EST_OK
    );
    assert_eq!(a.gravity, [0.0, 0.0, -9.81]);
    assert_eq!((a.max_dt_s, a.block_s, a.startup_s), (0.1, 0.25, 1.0));
    assert!(!a.has_magnetometer && !a.instantaneous_imu && a.magnetometer_hard_iron);
    assert_eq!(
        a.magnetometer_fusion,
        est_magnetic_fusion::EST_FUSION_HEADING as i32
    );
    let mut i = unsafe { std::mem::zeroed::<est_ins_config>() };
    assert_eq!(unsafe { est_ins_config_default(&mut i) }, est_error::EST_OK);
    assert_eq!(i.attitude, a);
    assert_eq!(
        (i.horizon_s, i.gnss_reset_s, i.has_barometer),
        (0.3, 10.0, false)
    );
    assert_eq!(i.travel, est_travel::EST_TRAVEL_DETECT as i32);
    assert_eq!(
        unsafe { est_attitude_config_default(null_mut()) },
        est_error::EST_ERR_NULL_POINTER
    );
    assert_eq!(
        unsafe { est_ins_config_default(null_mut()) },
        est_error::EST_ERR_NULL_POINTER
    );
    // The defaults are a valid configuration (without a magnetometer).
    let mut s = storage();
    let mut out = null_mut();
    assert_eq!(
        unsafe { est_ins_init(ptr(&mut s), s.0.len(), &i, &mut out) },
        est_error::EST_OK
    );
}

#[test]
fn a_handle_before_init_or_of_the_other_kind_is_refused() {
    let mut zeroed = storage();
    let handle = ptr(&mut zeroed).cast::<est_attitude>();
    let mut e = unsafe { std::mem::zeroed::<est_attitude_estimate>() };
    let (g, a, m) = ([0.0f32; 3], [0.0f32, 0.0, 9.81], common::FIELD);
    unsafe {
        assert_eq!(
            est_attitude_imu(handle, 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_NOT_INITIALIZED
        );
        assert_eq!(
            est_attitude_magnetometer(handle, 1, m.as_ptr()),
            est_error::EST_ERR_NOT_INITIALIZED
        );
        assert_eq!(
            est_attitude_get_estimate(handle, &mut e),
            est_error::EST_ERR_NOT_INITIALIZED
        );
    }
    assert!(zeroed.0.iter().all(|&b| b == 0));
    // An INS built in the storage is not an attitude navigator, and the other way round.
    let mut cfg = unsafe { std::mem::zeroed::<est_ins_config>() };
    let mut ins = null_mut();
    unsafe {
        assert_eq!(est_ins_config_default(&mut cfg), est_error::EST_OK);
        assert_eq!(
            est_ins_init(ptr(&mut zeroed), 8192, &cfg, &mut ins),
            est_error::EST_OK
        );
        assert_eq!(
            est_attitude_imu(handle, 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_NOT_INITIALIZED
        );
        let mut s2 = storage();
        let att = init_attitude(&mut s2, &attitude_config());
        let wrong = att.cast::<est_ins>();
        assert_eq!(
            est_ins_imu(wrong, 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_NOT_INITIALIZED
        );
        // The INS itself works.
        assert_eq!(
            est_ins_imu(ins, 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_OK
        );
        // Null and misaligned handles.
        assert_eq!(
            est_attitude_imu(null_mut(), 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_NULL_POINTER
        );
        let odd = ptr(&mut s2).wrapping_byte_add(4).cast::<est_attitude>();
        assert_eq!(
            est_attitude_imu(odd, 1, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_MISALIGNED
        );
    }
}

#[test]
fn refused_samples_leave_the_attitude_navigator_unchanged() {
    let mut s = storage();
    let nav = running_attitude(&mut s, 5);
    let before = attitude_bits(nav);
    let storage_before = s.0.to_vec();
    let last = 1_000_000_000 + (5 * 200 - 1) * 5_000_000;
    let last_mag = 1_000_000_000 + (5 * 200 - 4) * 5_000_000; // every 4th IMU sample
    let (g, a, m) = ([0.01f32, 0.0, 0.5], [0.1f32, 0.2, 9.8], common::FIELD);
    let nan = [0.0f32, f32::NAN, 9.8];
    let inf = [f32::INFINITY, 0.0, 0.0];
    let zero = [0.0f32; 3];

    // Errors of the boundary: nothing reaches the navigator, its storage is unchanged.
    unsafe {
        assert_eq!(
            est_attitude_imu(nav, last + 1, null(), a.as_ptr()),
            est_error::EST_ERR_NULL_POINTER
        );
        assert_eq!(
            est_attitude_imu(nav, last + 1, g.as_ptr(), null()),
            est_error::EST_ERR_NULL_POINTER
        );
        assert_eq!(
            est_attitude_magnetometer(nav, last + 1, null()),
            est_error::EST_ERR_NULL_POINTER
        );
        let bytes = [0u8; 16];
        let odd = bytes.as_ptr().wrapping_add(1).cast::<f32>();
        if !odd.is_aligned() {
            assert_eq!(
                est_attitude_imu(nav, last + 1, odd, a.as_ptr()),
                est_error::EST_ERR_MISALIGNED
            );
        }
        assert_eq!(
            est_attitude_get_estimate(nav, null_mut()),
            est_error::EST_ERR_NULL_POINTER
        );
        assert_eq!(
            est_attitude_get_report(nav, null_mut()),
            est_error::EST_ERR_NULL_POINTER
        );
        assert_eq!(
            est_attitude_get_counters(nav, null_mut()),
            est_error::EST_ERR_NULL_POINTER
        );
    }
    assert!(
        s.0[..] == storage_before[..],
        "a boundary error changed the storage"
    );

    // Samples the navigator refuses: same estimate and report, counted as refused.
    let refused_before = refused(nav);
    let cases: [(u64, [f32; 3], [f32; 3], est_error); 6] = [
        (last + 5_000_000, nan, a, est_error::EST_ERR_NON_FINITE),
        (last + 5_000_000, g, nan, est_error::EST_ERR_NON_FINITE),
        (last + 5_000_000, inf, a, est_error::EST_ERR_NON_FINITE),
        (last + 5_000_000, g, zero, est_error::EST_ERR_ZERO_VECTOR),
        (
            last + 5_000_000,
            [1e3, 0.0, 0.0],
            a,
            est_error::EST_ERR_OUT_OF_RANGE,
        ),
        (
            last - 5_000_000,
            g,
            a,
            est_error::EST_ERR_TIME_NOT_INCREASING,
        ),
    ];
    for (k, (t, gyro, accel, expected)) in cases.into_iter().enumerate() {
        let code = unsafe { est_attitude_imu(nav, t, gyro.as_ptr(), accel.as_ptr()) };
        assert_eq!(code, expected, "case {k}");
        assert_eq!(
            attitude_bits(nav),
            before,
            "case {k} changed the estimate or report"
        );
    }
    let mag_cases: [(u64, [f32; 3], est_error); 3] = [
        (last + 1, nan, est_error::EST_ERR_NON_FINITE),
        (last + 1, zero, est_error::EST_ERR_ZERO_VECTOR),
        (last_mag, m, est_error::EST_ERR_TIME_NOT_INCREASING),
    ];
    for (k, (t, field, expected)) in mag_cases.into_iter().enumerate() {
        assert_eq!(
            unsafe { est_attitude_magnetometer(nav, t, field.as_ptr()) },
            expected,
            "mag case {k}"
        );
        assert_eq!(
            attitude_bits(nav),
            before,
            "mag case {k} changed the estimate or report"
        );
    }
    assert_eq!(refused(nav), refused_before + 9);
    // The next good sample is taken.
    let code = unsafe { est_attitude_imu(nav, last + 5_000_000, g.as_ptr(), a.as_ptr()) };
    assert_eq!(code, est_error::EST_OK);
    assert_ne!(attitude_bits(nav), before);
}

#[test]
fn the_estimate_waits_for_the_start() {
    let mut s = storage();
    let nav = init_attitude(&mut s, &attitude_config());
    let mut e = unsafe { std::mem::zeroed::<est_attitude_estimate>() };
    let mut r = unsafe { std::mem::zeroed::<est_attitude_report>() };
    unsafe {
        assert_eq!(
            est_attitude_get_estimate(nav, &mut e),
            est_error::EST_ERR_NOT_STARTED
        );
        assert_eq!(est_attitude_get_report(nav, &mut r), est_error::EST_OK);
    }
    assert!(!r.tilt.valid && r.tilt.reason == est_reason::EST_REASON_STARTING);
    assert_eq!(r.magnetic, est_magnetic_status::EST_MAGNETIC_WAITING);
    let nav = running_attitude(&mut s, 30);
    unsafe {
        assert_eq!(est_attitude_get_estimate(nav, &mut e), est_error::EST_OK);
        assert_eq!(est_attitude_get_report(nav, &mut r), est_error::EST_OK);
    }
    let [w, x, y, z] = e.quaternion;
    assert!(
        ((w * w + x * x + y * y + z * z) - 1.0).abs() < 1e-5,
        "unit quaternion"
    );
    assert!(r.tilt.valid && r.heading.valid, "{r:?}");
    assert_eq!(r.tilt.reason, est_reason::EST_REASON_NONE);
    assert!(e.sigma_tilt > 0.0 && e.sigma_tilt < 5f32.to_radians());
}

/// An INS at rest with a magnetometer, fixes at 5 Hz from 1 s on, stamped 0.2 s late.
fn running_ins(s: &mut Storage, seconds: u64) -> (*mut est_ins, u64) {
    let mut cfg = unsafe { std::mem::zeroed::<est_ins_config>() };
    assert_eq!(
        unsafe { est_ins_config_default(&mut cfg) },
        est_error::EST_OK
    );
    cfg.attitude = attitude_config();
    cfg.has_barometer = true;
    cfg.barometer_sigma = 0.5;
    let mut nav = null_mut();
    assert_eq!(
        unsafe { est_ins_init(ptr(s), s.0.len(), &cfg, &mut nav) },
        est_error::EST_OK
    );
    let fix = est_gnss_fix {
        position: [10.0, 5.0, 2.0],
        has_velocity: true,
        velocity: [0.0; 3],
        sigma_position: 1.0,
        sigma_velocity: 0.1,
        has_sigma_position_up: false,
        sigma_position_up: 0.0,
    };
    let mut t = 0;
    for k in 0..seconds * 200 {
        t = 1_000_000_000 + k * 5_000_000;
        let (g, a) = ([0.0f32; 3], [0.0f32, 0.0, 9.81]);
        unsafe {
            assert_eq!(
                est_ins_imu(nav, t, g.as_ptr(), a.as_ptr()),
                est_error::EST_OK
            );
            if k % 4 == 0 {
                assert_eq!(
                    est_ins_magnetometer(nav, t, common::FIELD.as_ptr()),
                    est_error::EST_OK
                );
                assert_eq!(est_ins_barometer(nav, t, 2.0), est_error::EST_OK);
            }
            if k % 40 == 0 && k >= 200 {
                let mut f = fix;
                f.position[0] += (k as f32) * 1e-4; // never an exact repeat (a frozen receiver)
                assert_eq!(est_ins_gnss(nav, t - 200_000_000, &f), est_error::EST_OK);
            }
        }
    }
    (nav, t)
}

fn ins_bits(nav: *const est_ins) -> Vec<u32> {
    let mut e = unsafe { std::mem::zeroed::<est_ins_estimate>() };
    let mut r = unsafe { std::mem::zeroed::<est_ins_report>() };
    assert_eq!(
        unsafe { est_ins_get_estimate(nav, &mut e) },
        est_error::EST_OK
    );
    assert_eq!(
        unsafe { est_ins_get_report(nav, &mut r) },
        est_error::EST_OK
    );
    let mut bits: Vec<u32> = e
        .quaternion
        .iter()
        .chain(&e.velocity)
        .chain(&e.position)
        .chain(&e.gyro_bias)
        .chain(&e.accel_bias)
        .chain(&e.attitude_covariance)
        .chain(&e.velocity_covariance)
        .chain(&e.position_covariance)
        .chain(&e.gyro_bias_covariance)
        .chain(&e.accel_bias_covariance)
        .map(|x| x.to_bits())
        .collect();
    bits.extend([
        e.t_ns as u32,
        r.t_ns as u32,
        u32::from(r.position.valid),
        r.position.reason as u32,
        r.gnss as u32,
        r.magnetometer as u32,
        r.barometer as u32,
        r.event as u32,
    ]);
    bits
}

#[test]
fn the_ins_runs_and_refuses_bad_measurements_unchanged() {
    let mut s = storage();
    let (nav, last) = running_ins(&mut s, 8);
    let mut e = unsafe { std::mem::zeroed::<est_ins_estimate>() };
    let mut r = unsafe { std::mem::zeroed::<est_ins_report>() };
    let mut c = est_ins_counters::default();
    unsafe {
        assert_eq!(est_ins_get_estimate(nav, &mut e), est_error::EST_OK);
        assert_eq!(est_ins_get_report(nav, &mut r), est_error::EST_OK);
        assert_eq!(est_ins_get_counters(nav, &mut c), est_error::EST_OK);
    }
    assert!(r.position.valid && r.heading.valid, "{r:?}");
    let distance = e
        .position
        .iter()
        .zip([10.0f32, 5.0, 2.0])
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f32>();
    assert!(distance.sqrt() < 1.0, "position {:?}", e.position);
    assert!(e.position_covariance[0] > 0.0 && e.position_covariance[0] < 4.0);
    assert_eq!(
        e.position_covariance[1], e.position_covariance[3],
        "symmetric, row-major"
    );
    assert!(
        c.gnss_position_fused > 0 && c.barometer_fused > 0 && c.refused == 0,
        "{c:?}"
    );

    let before = ins_bits(nav);
    let good = est_gnss_fix {
        position: [10.0, 5.0, 2.0],
        has_velocity: false,
        velocity: [0.0; 3],
        sigma_position: 1.0,
        sigma_velocity: 0.1,
        has_sigma_position_up: false,
        sigma_position_up: 0.0,
    };
    let mut nan_fix = good;
    nan_fix.position[1] = f32::NAN;
    let mut bad_sigma = good;
    bad_sigma.sigma_position = 0.0;
    let mut bad_up = good;
    bad_up.has_sigma_position_up = true;
    bad_up.sigma_position_up = 1e9;
    let cases: [(u64, est_gnss_fix, est_error); 5] = [
        (last - 100_000_000, nan_fix, est_error::EST_ERR_NON_FINITE),
        (
            last - 100_000_000,
            bad_sigma,
            est_error::EST_ERR_INVALID_SIGMA,
        ),
        (last - 100_000_000, bad_up, est_error::EST_ERR_INVALID_SIGMA),
        (last - 2_000_000_000, good, est_error::EST_ERR_TOO_OLD),
        (last + 1_000_000_000, good, est_error::EST_ERR_IN_FUTURE),
    ];
    for (k, (t, fix, expected)) in cases.into_iter().enumerate() {
        assert_eq!(
            unsafe { est_ins_gnss(nav, t, &fix) },
            expected,
            "gnss case {k}"
        );
        assert_eq!(
            ins_bits(nav),
            before,
            "gnss case {k} changed the estimate or report"
        );
    }
    let (nan, g, a) = ([f32::NAN, 0.0, 0.0], [0.0f32; 3], [0.0f32, 0.0, 9.81]);
    unsafe {
        assert_eq!(
            est_ins_gnss(nav, last, null()),
            est_error::EST_ERR_NULL_POINTER
        );
        assert_eq!(
            est_ins_barometer(nav, last, f32::NAN),
            est_error::EST_ERR_NON_FINITE
        );
        assert_eq!(
            est_ins_magnetometer(nav, last, nan.as_ptr()),
            est_error::EST_ERR_NON_FINITE
        );
        assert_eq!(
            est_ins_imu(nav, last + 5_000_000, nan.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_NON_FINITE
        );
        assert_eq!(
            est_ins_imu(nav, last, g.as_ptr(), a.as_ptr()),
            est_error::EST_ERR_TIME_NOT_INCREASING
        );
        assert_eq!(
            est_ins_imu(nav, last + 5_000_000, g.as_ptr(), null()),
            est_error::EST_ERR_NULL_POINTER
        );
    }
    assert_eq!(ins_bits(nav), before);
    unsafe {
        assert_eq!(est_ins_get_counters(nav, &mut c), est_error::EST_OK);
    }
    assert_eq!(
        c.refused, 9,
        "the navigator's refusals are counted; the boundary's are not"
    );
}

#[test]
fn error_names_and_version() {
    let name = |c: i32| {
        unsafe { CStr::from_ptr(est_error_name(c)) }
            .to_str()
            .unwrap()
            .to_owned()
    };
    assert_eq!(name(est_error::EST_OK as i32), "EST_OK");
    assert_eq!(name(est_error::EST_ERR_TOO_OLD as i32), "EST_ERR_TOO_OLD");
    assert_eq!(
        name(est_error::EST_ERR_NOT_INITIALIZED as i32),
        "EST_ERR_NOT_INITIALIZED"
    );
    assert_eq!(name(-1), "EST_ERR_UNKNOWN");
    assert_eq!(est_api_version(), EST_API_VERSION);
    assert_eq!(est_api_version() >> 16, 1);
}

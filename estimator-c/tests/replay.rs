//! The C interface gives bit for bit what estimator-core's navigator gives: a C program
//! (tests/c/replay.c) built against the static library feeds a stream through it and prints
//! every estimate as bit patterns; the same stream through `AttitudeNavigator<f32>` must print
//! the same.

mod common;

use common::{c_compiler, stream_text, turning_body, Sample, FIELD};
use estimator_c::{est_attitude_event, est_error, est_magnetic_status, est_validity};
use estimator_core::eskf::FilterConfig;
use estimator_core::lie::LieGroup;
use estimator_core::nalgebra::Vector3;
use estimator_core::nav::{AttitudeConfig, AttitudeNavigator, MagneticConfig};
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// The static library cargo built with this test, found beside the test binary (in
/// `<target dir>/<profile>/deps`, wherever `CARGO_TARGET_DIR` puts it): `cargo test` leaves it
/// there as `libestimator_c-<hash>.a` (the crate's lib target is a staticlib too); `cargo
/// build` also copies it up as `<profile>/libestimator_c.a`. The newest is this source's.
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    let deps = exe
        .parent()
        .expect("the test binary is in <target>/<profile>/deps");
    let uplifted = deps.parent().map(|p| p.join("libestimator_c.a"));
    let in_deps = std::fs::read_dir(deps)
        .expect("read the deps folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("libestimator_c-") && n.ends_with(".a"))
        });
    let newest = in_deps
        .chain(uplifted)
        .filter_map(|p| Some((std::fs::metadata(&p).ok()?.modified().ok()?, p)))
        .max();
    match newest {
        Some((_, lib)) => lib,
        None => panic!(
            "no libestimator_c*.a in {} or beside it: cargo builds it with this test",
            deps.display()
        ),
    }
}

fn hex(v: &[f32]) -> String {
    v.iter().map(|x| format!(" {:08x}", x.to_bits())).collect()
}

fn validity(v: est_validity) -> String {
    format!("{}/{}", i32::from(v.valid), v.reason as i32)
}

/// What tests/c/replay.c prints, from estimator-core's navigator.
fn rust_replay(samples: &[Sample]) -> (String, AttitudeNavigator<f32>) {
    let mut config = AttitudeConfig::new(FilterConfig::default());
    config.instantaneous_imu = true;
    config.magnetometer = Some(MagneticConfig::new(0.5, Some(Vector3::from(FIELD))));
    let mut nav = AttitudeNavigator::new(config).expect("valid configuration");
    let mut out = String::new();
    for sample in samples {
        let result = match sample {
            Sample::Imu { t_ns, gyro, accel } => {
                nav.imu(*t_ns, &Vector3::from(*gyro), &Vector3::from(*accel))
            }
            Sample::Mag { t_ns, field } => nav.magnetometer(*t_ns, &Vector3::from(*field)),
        };
        let code = match result {
            Ok(_) => est_error::EST_OK,
            Err(e) => est_error::from(e),
        };
        out.push_str(&format!("{}", code as i32));
        match nav.estimate() {
            Some(e) => {
                let q = e.attitude.quaternion();
                let r = nav.report();
                out.push_str(&format!(" {}", e.t_ns));
                out.push_str(&hex(&[q.w, q.i, q.j, q.k]));
                out.push_str(&hex(e.gyro_bias.as_slice()));
                out.push_str(&hex(e.accel_bias.as_slice()));
                out.push_str(&hex(&[e.sigma_tilt, e.sigma_heading]));
                out.push_str(&format!(
                    " {} {} {} {}\n",
                    validity(r.tilt.into()),
                    validity(r.heading.into()),
                    est_magnetic_status::from(r.magnetic) as i32,
                    est_attitude_event::from(r.event) as i32
                ));
            }
            None => out.push_str(" -\n"),
        }
    }
    let c = nav.counters();
    out.push_str(&format!(
        "counters {} {} {} {} {}\n",
        c.imu, c.magnetometer, c.refused, c.gravity_fused, c.heading_fused
    ));
    (out, nav)
}

#[test]
fn c_replay_is_bit_for_bit_the_rust_navigator() {
    let (samples, truth) = turning_body(30);
    let (expected, nav) = rust_replay(&samples);

    // The stream is a real test of the navigator: it ends with a valid estimate near the truth.
    let estimate = nav.estimate().expect("started");
    let error = estimate
        .attitude
        .cast::<f64>()
        .inverse()
        .compose(&truth)
        .log()
        .norm();
    assert!(
        error.to_degrees() < 3.0 && nav.report().heading.is_valid(),
        "attitude error {:.2}° at the end (heading {:?})",
        error.to_degrees(),
        nav.report().heading
    );

    let Some(got) = c_program_output(&samples) else {
        return;
    };
    assert_same_lines(&got, &expected, samples.len());
}

/// A dataset host-sim writes (its hand-held scenario: IMU at 200 Hz, magnetometer at 50 Hz,
/// from a simulator independent of these tests' stream) through tests/c/replay.c: bit for bit
/// what `AttitudeNavigator<f32>` gives on the same samples.
#[test]
fn c_replay_of_a_host_sim_dataset_is_bit_for_bit_the_rust_navigator() {
    let samples = host_sim_stream("handheld_ahrs", 1);
    let (expected, nav) = rust_replay(&samples);
    assert!(
        nav.estimate().is_some() && nav.counters().heading_fused > 0,
        "the dataset starts the navigator and its magnetometer is fused"
    );
    let Some(got) = c_program_output(&samples) else {
        return;
    };
    assert_same_lines(&got, &expected, samples.len());
}

/// The IMU and magnetometer samples of a dataset host-sim simulates (`scenario`, `seed`), in
/// `f32`, as its replay reads them; written into this test's own folder under
/// `CARGO_TARGET_TMPDIR` and removed after.
fn host_sim_stream(scenario: &str, seed: u64) -> Vec<Sample> {
    use host_sim::dataset::read::{Dataset, Event};
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "estimator-c-{scenario}-{seed}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).expect("the dataset's folder");
    let sc = host_sim::scenario::Scenario::load(scenario).expect("a built-in scenario");
    host_sim::dataset::write::simulate(&sc, seed, &dir).expect("simulate");
    let ds = Dataset::open_with_magnetometer(&dir, true).expect("open the dataset");
    let f3 = |v: &Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
    let mut samples = Vec::new();
    for event in ds.events().expect("the dataset's events") {
        match event.expect("an event") {
            Event::Imu { t_ns, gyro, accel } => samples.push(Sample::Imu {
                t_ns,
                gyro: f3(&gyro),
                accel: f3(&accel),
            }),
            Event::Mag { t_ns, field } => samples.push(Sample::Mag {
                t_ns,
                field: f3(&field),
            }),
            _ => {}
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    samples
}

/// What tests/c/replay.c prints for `samples`, built with `cc` against the static library;
/// `None` (with a message) where there is no C compiler.
fn c_program_output(samples: &[Sample]) -> Option<String> {
    let cc = c_compiler()?;
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    // One folder per call: the tests run in parallel threads of one process.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir =
        std::env::temp_dir().join(format!("estimator-c-replay-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let exe = dir.join("replay");
    let build = Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-O1",
            "-I",
        ])
        .arg(crate_dir.join("include"))
        .arg(crate_dir.join("tests/c/replay.c"))
        .arg(static_library())
        // What a hosted build of the library needs from the system (rustc's
        // --print native-static-libs on Linux).
        .args([
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
        ])
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("run the C compiler");
    assert!(
        build.status.success(),
        "tests/c/replay.c does not build:\n{}",
        String::from_utf8_lossy(&build.stderr)
    );

    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run the replay");
    let input = stream_text(samples);
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().expect("replay output");
    writer.join().expect("writer").expect("write the stream");
    assert!(
        output.status.success(),
        "the replay failed ({}): {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let got = String::from_utf8(output.stdout).expect("ASCII output");
    let _ = std::fs::remove_dir_all(&dir);
    Some(got)
}

/// `got` (the C program's lines) equals `expected` (the Rust navigator's) line by line: one
/// line per sample and the counters.
fn assert_same_lines(got: &str, expected: &str, samples: usize) {
    let (mut got_lines, mut expected_lines) = (got.lines(), expected.lines());
    let mut line = 0;
    loop {
        line += 1;
        match (got_lines.next(), expected_lines.next()) {
            (None, None) => break,
            (g, e) => assert_eq!(g, e, "line {line}: C interface (left) against Rust (right)"),
        }
    }
    assert!(line > samples, "one line per sample and the counters");
}

/// The INS through the C interface (with a barometer and a declared travel, so that the
/// configuration's conversion is exercised beyond the defaults) is estimator-core's, bit for
/// bit: same codes, same estimate after every sample.
#[test]
fn c_interface_ins_is_bit_for_bit_the_rust_navigator() {
    use estimator_c::*;
    use estimator_core::nav::{GnssFix, InsConfig, InsNavigator, Travel};

    let mut cfg = unsafe { std::mem::zeroed::<est_ins_config>() };
    // SAFETY (tests): every pointer given below points to a live local of the right type.
    assert_eq!(
        unsafe { est_ins_config_default(&mut cfg) },
        est_error::EST_OK
    );
    cfg.attitude.has_magnetometer = true;
    cfg.attitude.magnetometer_sigma = 0.5;
    cfg.attitude.has_magnetometer_reference = true;
    cfg.attitude.magnetometer_reference = FIELD;
    cfg.has_barometer = true;
    cfg.barometer_sigma = 0.4;
    cfg.travel = est_travel::EST_TRAVEL_FORWARD as i32;
    cfg.lateral_sigma = 0.1;
    cfg.gnss_lever_arm = [0.1, 0.0, 0.2];

    let mut attitude = AttitudeConfig::new(FilterConfig::default());
    attitude.magnetometer = Some(MagneticConfig::new(0.5, Some(Vector3::from(FIELD))));
    let mut config = InsConfig::new(attitude);
    config.barometer_sigma = Some(0.4);
    config.travel = Travel::Forward { lateral_sigma: 0.1 };
    config.gnss_lever_arm = Vector3::new(0.1, 0.0, 0.2);
    let mut rust: InsNavigator<f32> = InsNavigator::new(config).expect("valid configuration");

    #[repr(C, align(16))]
    struct Storage([u8; 8192]);
    let mut storage = Box::new(Storage([0; 8192]));
    let mut nav = std::ptr::null_mut();
    let code = unsafe { est_ins_init(storage.0.as_mut_ptr().cast(), 8192, &cfg, &mut nav) };
    assert_eq!(code, est_error::EST_OK);

    let bits = |e: &est_ins_estimate| -> Vec<u32> {
        e.quaternion
            .iter()
            .chain(&e.velocity)
            .chain(&e.position)
            .chain(&e.gyro_bias)
            .chain(&e.accel_bias)
            .chain(&e.attitude_covariance)
            .chain(&e.position_covariance)
            .map(|x| x.to_bits())
            .collect()
    };
    let (samples, _) = turning_body(20);
    let mut started = 0;
    let same = |c: est_error, r: Result<_, estimator_core::nav::NavError>, what: &str| {
        assert_eq!(
            c,
            r.map_or_else(est_error::from, |_| est_error::EST_OK),
            "{what}"
        );
    };
    for (k, sample) in samples.iter().enumerate() {
        match *sample {
            Sample::Imu { t_ns, gyro, accel } => {
                let c = unsafe { est_ins_imu(nav, t_ns, gyro.as_ptr(), accel.as_ptr()) };
                same(
                    c,
                    rust.imu(t_ns, &Vector3::from(gyro), &Vector3::from(accel)),
                    "imu",
                );
                // GNSS every 50th sample (5 Hz) from 3 s on, stamped 0.2 s late (the body
                // turns in place at the origin); the barometer on the other 25th samples.
                if k % 50 == 0 && t_ns >= 3_000_000_000 {
                    let x = (k % 7) as f32 * 0.01; // never an exact repeat (a frozen receiver)
                    let fix = est_gnss_fix {
                        position: [x, 0.0, 0.0],
                        has_velocity: true,
                        velocity: [0.0; 3],
                        sigma_position: 1.0,
                        sigma_velocity: 0.1,
                        has_sigma_position_up: true,
                        sigma_position_up: 1.5,
                    };
                    let g =
                        GnssFix::new(Vector3::new(x, 0.0, 0.0), Some(Vector3::zeros()), 1.0, 0.1)
                            .with_vertical_sigma(1.5);
                    let t = t_ns - 200_000_000;
                    same(
                        unsafe { est_ins_gnss(nav, t, &fix) },
                        rust.gnss(t, &g),
                        "gnss",
                    );
                } else if k % 25 == 0 {
                    let c = unsafe { est_ins_barometer(nav, t_ns, 0.0) };
                    same(c, rust.barometer(t_ns, 0.0), "barometer");
                }
            }
            Sample::Mag { t_ns, field } => {
                let c = unsafe { est_ins_magnetometer(nav, t_ns, field.as_ptr()) };
                same(
                    c,
                    rust.magnetometer(t_ns, &Vector3::from(field)),
                    "magnetometer",
                );
            }
        }
        let mut e = unsafe { std::mem::zeroed::<est_ins_estimate>() };
        let code = unsafe { est_ins_get_estimate(nav, &mut e) };
        match rust.estimate() {
            None => assert_eq!(code, est_error::EST_ERR_NOT_STARTED, "sample {k}"),
            Some(r) => {
                started += 1;
                assert_eq!(code, est_error::EST_OK, "sample {k}");
                let q = r.state.attitude.quaternion();
                let (attitude, position) = (r.covariance[0], r.covariance[2]);
                let mut want: Vec<u32> = [q.w, q.i, q.j, q.k]
                    .iter()
                    .chain(r.state.velocity.iter())
                    .chain(r.state.position.iter())
                    .chain(r.state.gyro_bias.iter())
                    .chain(r.state.accel_bias.iter())
                    .map(|x| x.to_bits())
                    .collect();
                // Row-major in C; nalgebra stores column-major: transpose.
                want.extend(attitude.transpose().iter().map(|x| x.to_bits()));
                want.extend(position.transpose().iter().map(|x| x.to_bits()));
                assert_eq!(bits(&e), want, "sample {k}");
                assert_eq!(e.t_ns, r.t_ns);
            }
        }
    }
    assert!(started > 1000, "the INS ran ({started} estimates)");
    let mut c = est_ins_counters::default();
    assert_eq!(
        unsafe { est_ins_get_counters(nav, &mut c) },
        est_error::EST_OK
    );
    assert_eq!(c.gnss_position_fused, rust.counters().gnss_position_fused);
    assert_eq!(c.barometer_fused, rust.counters().barometer_fused);
    assert!(
        c.gnss_position_fused > 50 && c.barometer_fused > 50,
        "{c:?}"
    );
}

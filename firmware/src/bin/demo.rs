//! The firmware proof, run under QEMU (`mps2-an386`, Cortex-M4F):
//!
//! 1. runs the Lie-group operations, the 15-state filter (`Ins<f32>`), the attitude navigator
//!    (`AttitudeNavigator<f32>`) and a 20-point PnP solve on the embedded stream
//!    (`scenario.rs`), and checks the results against the host's (`expected.rs`): f64 reference
//!    within stated tolerances, the host's f32 run within a few ulps, and the errors against the
//!    truth within the scenario's bounds and the estimators' own 3σ;
//! 2. measures each operation once more between the `bench_start`/`bench_stop` markers (the
//!    instruction-count plugin `qemu-plugin/icount.c` counts between them) with the stack
//!    painted below the caller, and prints the peak stack of each; the navigator's costliest
//!    call, and every navigator call over the whole stream (one window each);
//! 3. runs the INS navigator (`InsNavigator<f32>`) from switch-on over its synthesized stream
//!    (`ins_stream.rs`: magnetometer and fixes delivered 0.2 s late), every call in its own
//!    window, each window classed by what the call did (its report's `fused` and `event`), and
//!    checks that the INS started, fused every fix and ends within a few metres of the truth;
//!    then once more over the same stream without its magnetometer (none configured: the bank
//!    of yaw hypotheses finds the heading from the GNSS track), and checks that the heading was
//!    set from the track and is valid at the end;
//! 4. prints `size_of` of the filter, navigator and solver types;
//! 5. exits through semihosting: status 0 when every check passed, 1 otherwise.
#![no_std]
#![no_main]

/// The host's results (`src/expected.rs`, or `$FIRMWARE_EXPECTED`; see build.rs).
mod expected {
    include!(concat!(env!("OUT_DIR"), "/expected.rs"));
}
#[path = "../ins_stream.rs"]
mod ins_stream;
#[path = "../mem.rs"]
mod mem;
#[path = "../scenario.rs"]
mod scenario;
#[path = "../vectors.rs"]
mod vectors;

use core::hint::black_box;
use core::mem::size_of;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use estimator_core::eskf::{
    Ahrs, AhrsAccelBias, AhrsAccelBiasState, AhrsState, EskfError, FilterConfig, Ins, InsState,
    Measurement, UpdateOptions, UpdateOutcome,
};
use estimator_core::gn::{self, solve_pnp, PnpSolution, SolveError};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::nav::{
    Aiding, AttitudeEstimate, AttitudeNavigator, AttitudeReport, InsCounters, InsEstimate,
    InsEvent, InsNavigator, InsReport,
};
use nalgebra::{Vector3, Vector6};

// ---------------------------------------------------------------- benchmark markers

/// Start of a measured window (the plugin's `start=` address).
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_start() {
    // SAFETY: no operation; the asm keeps the function (and its address) alive and distinct.
    unsafe { core::arch::asm!("nop", options(nomem, nostack, preserves_flags)) };
}

/// End of a measured window (the plugin's `stop=` address).
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_stop() {
    // SAFETY: as in `bench_start` (two nops, so the two functions cannot be merged).
    unsafe { core::arch::asm!("nop", "nop", options(nomem, nostack, preserves_flags)) };
}

// ---------------------------------------------------------------- stack painting

const PAINT: u32 = 0xC5A5_5A5C;
/// How far below the caller's stack pointer the paint reaches (bytes).
const PAINT_DEPTH: usize = 16 * 1024;

/// The caller's stack pointer after its prologue: a leaf with no frame, so `sp` here is the
/// caller's `sp` at the call.
#[inline(never)]
fn caller_stack_pointer() -> usize {
    let sp: usize;
    // SAFETY: reads the stack pointer register, no side effect.
    unsafe {
        core::arch::asm!("mov {}, sp", out(reg) sp, options(nomem, nostack, preserves_flags))
    };
    sp
}

/// Measures `f` once: paints `PAINT_DEPTH` bytes below this frame, runs `f` between the
/// benchmark markers, and returns the peak stack below this frame (`f`'s frames, the closure
/// trampoline included).
#[inline(never)]
fn measure(f: &mut dyn FnMut()) -> usize {
    let top = caller_stack_pointer() & !3;
    let bottom = top - PAINT_DEPTH;
    let mut a = bottom;
    while a < top {
        // SAFETY: the words below this frame's stack pointer belong to no live frame (no call
        // happens during the loop); the RAM there is ours (the stack grows down from the end of
        // the 4 MiB RAM); no interrupt is enabled.
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
    bench_start();
    f();
    bench_stop();
    let mut a = bottom;
    while a < top {
        // SAFETY: as above; reading back the paint.
        if unsafe { core::ptr::read_volatile(a as *const u32) } != PAINT {
            break;
        }
        a += 4;
    }
    top - a
}

// ---------------------------------------------------------------- result checks

struct Checker {
    failures: u32,
}

impl Checker {
    fn close(&mut self, what: &str, got: &[f32], want: &[f32], tol: f32) {
        let mut worst = 0.0f32;
        for (g, w) in got.iter().zip(want.iter()) {
            let d = if g.is_finite() {
                (g - w).abs()
            } else {
                f32::INFINITY
            };
            if d > worst || d.is_nan() {
                worst = d;
            }
        }
        let ok = worst <= tol && got.len() == want.len();
        if !ok {
            self.failures += 1;
        }
        hprintln!(
            "check {:<28} max|diff| {:e} <= {:e} {}",
            what,
            worst,
            tol,
            if ok { "ok" } else { "FAIL" }
        );
        if !ok {
            hprintln!("  got  {:?}", got);
            hprintln!("  want {:?}", want);
        }
    }

    fn below(&mut self, what: &str, got: f32, bound: f32) {
        let ok = got <= bound;
        if !ok {
            self.failures += 1;
        }
        hprintln!(
            "check {:<28} {:e} <= {:e} {}",
            what,
            got,
            bound,
            if ok { "ok" } else { "FAIL" }
        );
    }

    fn at_least(&mut self, what: &str, got: u32, min: u32) {
        let ok = got >= min;
        if !ok {
            self.failures += 1;
        }
        hprintln!(
            "check {:<28} {} >= {} {}",
            what,
            got,
            min,
            if ok { "ok" } else { "FAIL" }
        );
    }

    fn equal(&mut self, what: &str, got: u32, want: u32) {
        let ok = got == want;
        if !ok {
            self.failures += 1;
        }
        hprintln!(
            "check {:<28} {} == {} {}",
            what,
            got,
            want,
            if ok { "ok" } else { "FAIL" }
        );
    }
}

extern "C" {
    // The ARM run-time ABI's aligned copy and clear (src/mem.rs in size builds,
    // compiler_builtins otherwise): `dest`/`src` 4-byte aligned, `n` any byte count.
    fn __aeabi_memcpy4(dest: *mut u8, src: *const u8, n: usize);
    fn __aeabi_memclr4(dest: *mut u8, n: usize);
}

/// Byte `k` of a little-endian word buffer.
fn byte(words: &[u32; 12], k: usize) -> u32 {
    words.get(k / 4).map_or(0, |w| (w >> (8 * (k % 4))) & 0xff)
}

/// Copies and clears every length from 0 to 40 bytes into word 1 onwards of a 48-byte buffer
/// filled with guard bytes, and counts the lengths where a byte inside is wrong or a guard byte
/// (word 0, and everything after the end) changed.
fn mem_routine_errors() -> u32 {
    let mut src = [0u32; 12];
    for (i, w) in src.iter_mut().enumerate() {
        *w = 0x0403_0201u32.wrapping_mul(i as u32 + 1) ^ 0x8040_2010;
    }
    let mut errors = 0;
    for n in 0..=40usize {
        let (mut copy, mut clear) = ([0xa5a5_a5a5u32; 12], [0xa5a5_a5a5u32; 12]);
        // SAFETY: both buffers hold 44 bytes from word 1 on, and n <= 40; all are 4-byte aligned.
        unsafe {
            __aeabi_memcpy4(
                copy.as_mut_ptr().wrapping_add(1).cast(),
                src.as_ptr().cast(),
                black_box(n),
            );
            __aeabi_memclr4(clear.as_mut_ptr().wrapping_add(1).cast(), black_box(n));
        }
        let wrong = (0..48).any(|k| {
            let inside = (4..4 + n).contains(&k);
            let (want_copy, want_clear) = if inside {
                (byte(&src, k - 4), 0)
            } else {
                (0xa5, 0xa5)
            };
            byte(&copy, k) != want_copy || byte(&clear, k) != want_clear
        });
        errors += u32::from(wrong);
    }
    errors
}

fn check_outcome(c: &mut Checker, o: &scenario::Outcome<f32>) {
    let r = &expected::EXPECTED_F64;
    let h = &expected::EXPECTED_F32_HOST;
    c.equal("no error returned", o.failure, 0);
    // Against the f64 reference: tolerances of the f32 arithmetic (README, "The demo and its
    // checks").
    c.close("so3 exp vs f64", &o.so3_exp, &r.so3_exp, 1e-6);
    c.close("so3 log vs f64", &o.so3_log, &r.so3_log, 1e-5);
    c.close("se3 log vs f64", &o.se3_log, &r.se3_log, 1e-5);
    c.close("ins attitude q vs f64", &o.ins_q, &r.ins_q, 2e-5);
    c.close("ins velocity vs f64", &o.ins_v, &r.ins_v, 1e-4);
    c.close("ins position vs f64", &o.ins_p, &r.ins_p, 1e-4);
    c.equal("ins updates accepted", o.ins_accepted, r.ins_accepted);
    c.close("nav attitude q vs f64", &o.nav_q, &r.nav_q, 2e-5);
    c.close("nav gyro bias vs f64", &o.nav_bg, &r.nav_bg, 1e-5);
    c.equal("nav blocks fused", o.nav_fused, r.nav_fused);
    c.close("pnp rotation q vs f64", &o.pnp_q, &r.pnp_q, 1e-5);
    c.close("pnp translation vs f64", &o.pnp_t, &r.pnp_t, 1e-4);
    // Against the host's own f32 run: the same IEEE f32 arithmetic, so (nearly) identical.
    let all = |o: &scenario::Outcome<f32>| {
        let mut v = [0.0f32; 37 + 2 * scenario::TRUTH_CHECKS];
        let parts: [&[f32]; 12] = [
            &o.so3_exp,
            &o.so3_log,
            &o.se3_log,
            &o.ins_q,
            &o.ins_v,
            &o.ins_p,
            &o.nav_q,
            &o.nav_bg,
            &o.pnp_q,
            &o.pnp_t,
            &o.truth_errors,
            &o.truth_bounds,
        ];
        let mut i = 0;
        for p in parts {
            for x in p {
                if let Some(slot) = v.get_mut(i) {
                    *slot = *x;
                }
                i += 1;
            }
        }
        v
    };
    c.close("all values vs host f32", &all(o), &all(h), 1e-5);
    // Against host-sim's ground truth: each error within the 3-σ radius of the estimator's own
    // covariance; the navigator's tilt and heading also within the bounds the scenario's
    // sensors allow (`scenario::nav_tolerances`).
    let names = [
        "ins position error (m)",
        "ins attitude error (rad)",
        "nav tilt error (rad)",
        "pnp rotation error (rad)",
        "pnp translation error (m)",
        "ins gyro bias error (rad/s)",
        "ins accel bias error (m/s2)",
        "nav gyro bias error (rad/s)",
        "nav heading error (rad)",
        "nav tilt error, own 3s (rad)",
        "nav heading err, own 3s (rad)",
    ];
    for ((name, e), b) in names.iter().zip(o.truth_errors).zip(o.truth_bounds) {
        c.below(name, e, b);
    }
}

// ---------------------------------------------------------------- benchmarks

fn bench(index: &mut u32, name: &str, mut f: impl FnMut()) {
    let stack = measure(&mut f);
    hprintln!("bench {} {} stack={}", index, name, stack);
    *index += 1;
}

/// A filter whose `update` the demo benchmarks (both filters, every model).
trait Filter<Mo, const M: usize>: Copy {
    fn update_with(
        &mut self,
        m: &Mo,
        o: &UpdateOptions<f32>,
    ) -> Result<UpdateOutcome<f32>, EskfError>;
}

impl<Mo: Measurement<f32, InsState<f32>, 15, M>, const M: usize> Filter<Mo, M> for Ins<f32> {
    fn update_with(
        &mut self,
        m: &Mo,
        o: &UpdateOptions<f32>,
    ) -> Result<UpdateOutcome<f32>, EskfError> {
        self.update(m, o)
    }
}

impl<Mo: Measurement<f32, AhrsState<f32>, 6, M>, const M: usize> Filter<Mo, M> for Ahrs<f32> {
    fn update_with(
        &mut self,
        m: &Mo,
        o: &UpdateOptions<f32>,
    ) -> Result<UpdateOutcome<f32>, EskfError> {
        self.update(m, o)
    }
}

impl<Mo: Measurement<f32, AhrsAccelBiasState<f32>, 12, M>, const M: usize> Filter<Mo, M>
    for AhrsAccelBias<f32>
{
    fn update_with(
        &mut self,
        m: &Mo,
        o: &UpdateOptions<f32>,
    ) -> Result<UpdateOutcome<f32>, EskfError> {
        self.update(m, o)
    }
}

/// The benchmarked updates and how many of them the filter accepted: every benchmark input is
/// consistent with the filter's estimate, so each should run the whole update (gain, posterior
/// covariance, injection and reset), not stop at the gate.
#[derive(Default)]
struct Updates {
    run: u32,
    accepted: u32,
}

impl Updates {
    /// Benchmarks one update of a copy of `filter`; prints its outcome.
    fn bench<F: Filter<Mo, M>, Mo, const M: usize>(
        &mut self,
        index: &mut u32,
        name: &str,
        filter: &F,
        model: &Mo,
        options: &UpdateOptions<f32>,
    ) {
        let mut f = *filter;
        bench(index, name, || {
            let _ = black_box(black_box(&mut f).update_with(black_box(model), options));
        });
        // The outcome, from the same update of another copy (outside the measured window: keeping
        // the measured call's result would add to the frames measured).
        let mut g = *filter;
        let result = g.update_with(model, options);
        self.run += 1;
        match result {
            Ok(o) if o.is_accepted() => {
                self.accepted += 1;
                hprintln!("info {} accepted nis={}", name, o.nis());
            }
            Ok(o) => hprintln!("info {} rejected nis={}", name, o.nis()),
            _ => hprintln!("info {} error", name),
        }
    }
}

/// Benchmarks the navigator's IMU call at rest that makes a block's zero-rate update (the
/// prediction and the update; the block ended in an earlier call, its accelerometer and
/// magnetometer updates come in the next two). Returns whether the same call on another copy
/// fused the zero rate.
fn bench_nav_step(index: &mut u32, s: &scenario::NavStep<f32>) -> bool {
    let mut nav = s.nav;
    bench(index, "nav_imu_block_end", || {
        let _ = black_box(black_box(&mut nav).imu(
            black_box(s.t_ns),
            black_box(&s.gyro),
            black_box(&s.accel),
        ));
    });
    let mut other = s.nav;
    let Ok(r) = other.imu(s.t_ns, &s.gyro, &s.accel) else {
        hprintln!("info nav_imu_block_end error");
        return false;
    };
    let nis = |f: Option<estimator_core::nav::Fusion<f32>>| f.map_or(f32::NAN, |f| f.nis);
    hprintln!(
        "info nav_imu_block_end at_rest={} nis zero_rate={} gravity={} heading={}",
        r.at_rest,
        nis(r.fused.zero_rate),
        nis(r.fused.gravity),
        nis(r.fused.heading)
    );
    r.at_rest && r.fused.zero_rate.is_some_and(|f| f.accepted)
}

/// Runs a new navigator over the whole attitude stream, each call in its own measured window
/// (painted like every other), and prints
/// `bench_group <first window> <windows> nav_stream imu_samples=<n> stack=<peak>`:
/// `tools/check_budgets.py` sums the plugin's counts of those windows. Returns the final
/// estimate and the samples refused.
fn bench_nav_stream(index: &mut u32) -> Option<(AttitudeEstimate<f32>, u32)> {
    let mut nav = AttitudeNavigator::new(scenario::attitude_config::<f32>()).ok()?;
    let first = *index;
    let (mut windows, mut imu, mut peak) = (0u32, 0u32, 0usize);
    scenario::attitude_samples::<f32>(|sample| {
        let stack = match sample {
            scenario::Sample::Imu { t_ns, gyro, accel } => {
                imu += 1;
                measure(&mut || {
                    let _ = black_box(black_box(&mut nav).imu(
                        black_box(t_ns),
                        black_box(&gyro),
                        black_box(&accel),
                    ));
                })
            }
            scenario::Sample::Mag { t_ns, field } => measure(&mut || {
                let _ =
                    black_box(black_box(&mut nav).magnetometer(black_box(t_ns), black_box(&field)));
            }),
        };
        peak = peak.max(stack);
        windows += 1;
    });
    *index += windows;
    hprintln!(
        "bench_group {} {} nav_stream imu_samples={} stack={}",
        first,
        windows,
        imu,
        peak
    );
    Some((nav.estimate()?, nav.counters().refused))
}

/// The classes of the INS navigator's calls, by what each did: its code in the `bench_tags`
/// lines, and its name (`tools/check_budgets.py` gives each class `icount.ins_nav_<name>_max`,
/// `_mean`, and the demo prints its peak stack, `stack.ins_nav_<name>`).
const INS_CLASSES: [(u8, &str); 10] = [
    (b's', "step"),
    (b'p', "gnss_position"),
    (b'v', "gnss_velocity"),
    (b'm', "magnetometer"),
    (b'b', "barometer"),
    (b'S', "start"),
    (b'a', "aligning"),
    (b'G', "gnss_call"),
    (b'M', "magnetometer_call"),
    (b'x', "refused"),
];

/// At most this many windows in the INS navigator's run (its stream has 2,031 calls).
const INS_WINDOWS: usize = 2_100;

/// The INS navigator's two runs over `ins_stream`: with its magnetometer (`ins_stream::config`,
/// every sample) and without (`ins_stream::config_without_magnetometer`, the magnetometer
/// samples left out: the bank of yaw hypotheses finds the heading from the GNSS track).
#[derive(Clone, Copy, PartialEq)]
enum InsRun {
    WithMagnetometer,
    WithoutMagnetometer,
}

impl InsRun {
    /// The run's name in the figures (`icount.<name>_<class>_max`, `stack.<name>_<class>`).
    fn name(self) -> &'static str {
        match self {
            InsRun::WithMagnetometer => "ins_nav",
            InsRun::WithoutMagnetometer => "ins_nav_no_mag",
        }
    }
}

/// What the INS navigator's measured run found.
struct InsNavRun {
    /// The report and estimate after the last call.
    report: InsReport<f32>,
    estimate: Option<InsEstimate<f32>>,
    counters: InsCounters,
    /// IMU calls that started the INS; that set the heading from the GNSS track
    /// (`HeadingFromGnss`); that raised any other event (realigned, reset, IMU fault); whose
    /// update the gate rejected.
    started: u32,
    heading_from_gnss: u32,
    other_events: u32,
    rejected: u32,
    /// Windows beyond the tag buffer (0 when every call was classed).
    unclassed: u32,
    /// When the INS started, and when its heading was first set from the GNSS track, ms after
    /// switch-on.
    start_ms: u32,
    heading_ms: u32,
    /// The call after an IMU gap went back to aligning (measured in the run with the
    /// magnetometer only: `None` in the other).
    realigned: Option<bool>,
}

/// The class of an INS navigator's `imu` call that was not refused, from its report.
fn ins_imu_class(nav: &InsNavigator<f32>) -> u8 {
    let r = nav.report();
    if r.event == Some(InsEvent::Started) {
        return b'S';
    }
    if nav.filter().is_none() {
        return b'a';
    }
    match r.fused.map(|f| f.aid) {
        Some(Aiding::GnssPosition) => b'p',
        Some(Aiding::GnssVelocity) => b'v',
        Some(Aiding::Magnetometer) => b'm',
        Some(Aiding::Barometer) => b'b',
        None => b's',
    }
}

/// Runs a new `InsNavigator<f32>` (its default ring of IMU intervals and queue, 0.3 s horizon)
/// from switch-on over `ins_stream` (`run`: with its magnetometer, or without), each call in its
/// own measured window, and prints `bench_group <first> <windows> <name> imu_samples=<n>
/// stack=<peak>`, the class of every window (`bench_tags <name> <first window> <codes>`, legend
/// in `bench_classes`) and each class's peak stack (`<name>`: [`InsRun::name`]); then, with the
/// magnetometer, measures `estimate()` once, and an `imu` call after an IMU gap on a copy.
fn bench_ins_nav(index: &mut u32, run: InsRun) -> Option<InsNavRun> {
    let magnetometer = run == InsRun::WithMagnetometer;
    let name = run.name();
    let config = if magnetometer {
        ins_stream::config::<f32>()
    } else {
        ins_stream::config_without_magnetometer::<f32>()
    };
    let mut nav: InsNavigator<f32> = InsNavigator::new(config).ok()?;
    let first = *index;
    let mut tags = [0u8; INS_WINDOWS];
    let mut class_stack = [0usize; INS_CLASSES.len()];
    let (mut windows, mut imu, mut peak) = (0usize, 0u32, 0usize);
    let (mut started, mut heading_from_gnss) = (0u32, 0u32);
    let (mut other_events, mut rejected) = (0u32, 0u32);
    let (mut start_ms, mut heading_ms) = (0u32, 0u32);
    let mut last_imu = None;
    ins_stream::samples::<f32>(|sample| {
        if !magnetometer && matches!(sample, ins_stream::InsSample::Mag { .. }) {
            // Without a magnetometer: its samples are not there.
            return;
        }
        let refused_before = nav.counters().refused;
        let (stack, tag) = match sample {
            ins_stream::InsSample::Imu { t_ns, gyro, accel } => {
                imu += 1;
                let stack = measure(&mut || {
                    let _ = black_box(black_box(&mut nav).imu(
                        black_box(t_ns),
                        black_box(&gyro),
                        black_box(&accel),
                    ));
                });
                let tag = ins_imu_class(&nav);
                last_imu = Some((t_ns, gyro, accel));
                let r = nav.report();
                let ms = (t_ns - ins_stream::T0_NS) / 1_000_000;
                let ms = u32::try_from(ms).unwrap_or(u32::MAX);
                match r.event {
                    Some(InsEvent::Started) => {
                        started += 1;
                        start_ms = ms;
                    }
                    Some(InsEvent::HeadingFromGnss) => {
                        if heading_from_gnss == 0 {
                            heading_ms = ms;
                        }
                        heading_from_gnss += 1;
                    }
                    Some(_) => other_events += 1,
                    None => {}
                }
                if r.fused.is_some_and(|f| !f.accepted) {
                    rejected += 1;
                }
                (stack, tag)
            }
            ins_stream::InsSample::Mag { t_ns, field } => {
                let stack = measure(&mut || {
                    let _ = black_box(
                        black_box(&mut nav).magnetometer(black_box(t_ns), black_box(&field)),
                    );
                });
                (stack, b'M')
            }
            ins_stream::InsSample::Gnss { t_ns, fix } => {
                let stack = measure(&mut || {
                    let _ = black_box(black_box(&mut nav).gnss(black_box(t_ns), black_box(&fix)));
                });
                (stack, b'G')
            }
        };
        // A refused call returns an error and leaves the report as it was.
        let tag = if nav.counters().refused != refused_before {
            b'x'
        } else {
            tag
        };
        if let Some(slot) = tags.get_mut(windows) {
            *slot = tag;
        }
        if let Some(k) = INS_CLASSES.iter().position(|(c, _)| *c == tag) {
            if let Some(s) = class_stack.get_mut(k) {
                *s = (*s).max(stack);
            }
        }
        peak = peak.max(stack);
        windows += 1;
    });
    *index += windows as u32;
    hprintln!(
        "bench_group {} {} {} imu_samples={} stack={}",
        first,
        windows,
        name,
        imu,
        peak
    );
    let mut legend = [0u8; 160];
    let mut n = 0;
    for (code, class) in INS_CLASSES {
        for b in [code, b':'].iter().chain(class.as_bytes()).chain(b" ") {
            if let Some(slot) = legend.get_mut(n) {
                *slot = *b;
                n += 1;
            }
        }
    }
    hprintln!(
        "bench_classes {} {}",
        name,
        core::str::from_utf8(legend.get(..n).unwrap_or(&[])).unwrap_or("")
    );
    let classed = windows.min(INS_WINDOWS);
    let mut at = 0;
    while at < classed {
        let end = (at + 100).min(classed);
        let line = tags.get(at..end).unwrap_or(&[]);
        hprintln!(
            "bench_tags {} {} {}",
            name,
            first as usize + at,
            core::str::from_utf8(line).unwrap_or("")
        );
        at = end;
    }
    for ((code, class), stack) in INS_CLASSES.iter().zip(class_stack) {
        if tags.get(..classed).is_some_and(|t| t.contains(code)) {
            hprintln!("bench_stack {}_{} {}", name, class, stack);
        }
    }
    if !magnetometer {
        return Some(InsNavRun {
            report: *nav.report(),
            estimate: nav.estimate(),
            counters: *nav.counters(),
            started,
            heading_from_gnss,
            other_events,
            rejected,
            unclassed: u32::try_from(windows - classed).unwrap_or(u32::MAX),
            start_ms,
            heading_ms,
            realigned: None,
        });
    }
    bench(index, "ins_nav_estimate", || {
        black_box(black_box(&nav).estimate());
    });
    // An IMU sample 0.2 s after the last (a gap over `max_dt`, 0.1 s): the call goes back to
    // aligning (`Realigned`), building a new attitude navigator in place of the INS. Measured
    // on a copy; another copy checks the event.
    let mut realigned = false;
    if let Some((t_ns, gyro, accel)) = last_imu {
        let t_gap = t_ns + 200_000_000;
        let mut copy = nav;
        bench(index, "ins_nav_imu_after_gap", || {
            let _ = black_box(black_box(&mut copy).imu(
                black_box(t_gap),
                black_box(&gyro),
                black_box(&accel),
            ));
        });
        let mut other = nav;
        realigned = other
            .imu(t_gap, &gyro, &accel)
            .is_ok_and(|r| r.event == Some(InsEvent::Realigned));
    }
    Some(InsNavRun {
        report: *nav.report(),
        estimate: nav.estimate(),
        counters: *nav.counters(),
        started,
        heading_from_gnss,
        other_events,
        rejected,
        unclassed: u32::try_from(windows - classed).unwrap_or(u32::MAX),
        start_ms,
        heading_ms,
        realigned: Some(realigned),
    })
}

/// Checks the INS navigator's run: every sample taken, the INS started once from the
/// alignment, every fix and magnetometer sample fused, and the end estimate near the truth.
fn check_ins_nav(c: &mut Checker, run: &Option<InsNavRun>) {
    let Some(r) = run else {
        c.equal("ins nav constructed", 0, 1);
        return;
    };
    let n = &r.counters;
    c.equal("ins nav windows classed", r.unclassed, 0);
    c.equal("ins nav samples refused", n.refused, 0);
    c.equal("ins nav started", r.started, 1);
    hprintln!("info ins_nav started {} ms after switch-on", r.start_ms);
    c.equal(
        "ins nav gap call realigned",
        u32::from(r.realigned == Some(true)),
        1,
    );
    c.equal("ins nav heading from gnss", r.heading_from_gnss, 0);
    c.equal("ins nav other events", r.other_events, 0);
    c.equal("ins nav updates rejected", r.rejected, 0);
    c.equal("ins nav numerical failures", n.numerical_failures, 0);
    hprintln!(
        "info ins_nav measurements unused while aligning {}",
        n.unused
    );
    c.at_least("ins nav gnss position fused", n.gnss_position_fused, 25);
    c.at_least("ins nav gnss velocity fused", n.gnss_velocity_fused, 25);
    c.at_least("ins nav magnetometer fused", n.magnetometer_fused, 250);
    check_ins_nav_end(
        c,
        r,
        [
            "ins nav tilt/heading/v/p valid",
            "ins nav estimate",
            "ins nav position error (m)",
            "ins nav velocity error (m/s)",
            "ins nav attitude error (rad)",
        ],
        0.03,
    );
}

/// The INS navigator's end: tilt, heading, velocity and position valid, and the estimate
/// within 1.5 m, 0.15 m/s and `attitude_bound` rad of the truth; `labels` name the checks
/// (validity, estimate present, position, velocity, attitude).
fn check_ins_nav_end(c: &mut Checker, r: &InsNavRun, labels: [&str; 5], attitude_bound: f32) {
    let [valid_label, estimate_label, position_label, velocity_label, attitude_label] = labels;
    let v = &r.report.validity;
    let valid = [v.tilt, v.heading, v.velocity, v.position]
        .iter()
        .filter(|x| x.is_valid())
        .count();
    c.equal(valid_label, valid as u32, 4);
    let Some(e) = &r.estimate else {
        c.equal(estimate_label, 0, 1);
        return;
    };
    let p = ins_stream::truth_position::<f32>(e.t_ns);
    c.below(position_label, (e.state.position - p).norm(), 1.5);
    let v = ins_stream::truth_velocity::<f32>();
    c.below(velocity_label, (e.state.velocity - v).norm(), 0.15);
    let a = ins_stream::truth_attitude::<f32>();
    let err = e.state.attitude.between(&a).log().norm();
    c.below(attitude_label, err, attitude_bound);
}

/// Checks the INS navigator's run without a magnetometer: every sample taken, the INS started
/// once, every fix fused, the bank of yaw hypotheses fed every GNSS velocity and the heading
/// set from it (resolved: valid at the end), the lateral velocity fused at the fixes after
/// that, and the end estimate near the truth (the heading to the stream's track: 0.036 rad off
/// its yaw, `ins_stream.rs`).
fn check_ins_nav_without_magnetometer(c: &mut Checker, run: &Option<InsNavRun>) {
    let Some(r) = run else {
        c.equal("ins nav no-mag constructed", 0, 1);
        return;
    };
    let n = &r.counters;
    c.equal("ins nav no-mag windows classed", r.unclassed, 0);
    c.equal("ins nav no-mag refused", n.refused, 0);
    c.equal("ins nav no-mag started", r.started, 1);
    hprintln!(
        "info ins_nav_no_mag started {} ms after switch-on, heading from gnss at {} ms",
        r.start_ms,
        r.heading_ms
    );
    c.equal("ins nav no-mag other events", r.other_events, 0);
    c.equal("ins nav no-mag updates rejected", r.rejected, 0);
    c.equal("ins nav no-mag num. failures", n.numerical_failures, 0);
    c.at_least("ins nav no-mag gnss pos fused", n.gnss_position_fused, 25);
    c.at_least("ins nav no-mag gnss vel fused", n.gnss_velocity_fused, 25);
    c.equal("ins nav no-mag mag fused", n.magnetometer_fused, 0);
    // The heading resolved by the bank: set from it (once: the INS keeps it after, held by the
    // lateral velocity), and the lateral velocity fused at every GNSS velocity after that.
    c.equal("ins nav no-mag heading resets", n.heading_resets, 1);
    c.equal(
        "ins nav no-mag HeadingFromGnss",
        r.heading_from_gnss,
        n.heading_resets,
    );
    c.at_least("ins nav no-mag lateral fused", n.lateral_fused, 20);
    c.equal("ins nav no-mag lateral rejected", n.lateral_rejected, 0);
    check_ins_nav_end(
        c,
        r,
        [
            "ins nav no-mag tilt/hdg/v/p valid",
            "ins nav no-mag estimate",
            "ins nav no-mag position error (m)",
            "ins nav no-mag velocity err (m/s)",
            "ins nav no-mag attitude err (rad)",
        ],
        0.06,
    );
}

/// What the benchmarks found besides the figures.
struct Benchmarks {
    updates: Updates,
    /// The navigator's block-end call at rest fused the zero rate (it ran its whole path).
    nav_step: bool,
    /// The navigator's measured run over the stream: final estimate, samples refused.
    nav_stream: Option<(AttitudeEstimate<f32>, u32)>,
    /// The INS navigator's measured runs over its stream, with its magnetometer and without.
    ins_nav: Option<InsNavRun>,
    ins_nav_no_mag: Option<InsNavRun>,
}

fn run_benchmarks(w: &scenario::Workload<f32>) -> Benchmarks {
    let mut i = 0u32;
    bench(&mut i, "empty", || {});

    // Scalar kernels the estimators call (what a Cortex-M4F pays for them in f32).
    let x = 0.7f32;
    bench(&mut i, "sincos_f32", || {
        black_box(estimator_core::scalar::sincos_f32(black_box(x)));
    });
    bench(&mut i, "sqrt_f32", || {
        black_box(estimator_core::scalar::sqrt_f32(black_box(x)));
    });
    bench(&mut i, "atan2_f32", || {
        black_box(estimator_core::scalar::atan2_f32(
            black_box(x),
            black_box(0.3f32),
        ));
    });

    let tau = Vector3::new(0.3f32, -0.2, 0.9);
    let r = So3::exp(&tau);
    let r2 = So3::exp(&Vector3::new(-0.1f32, 0.5, 0.2));
    bench(&mut i, "so3_exp", || {
        black_box(So3::exp(black_box(&tau)));
    });
    bench(&mut i, "so3_log", || {
        black_box(black_box(&r).log());
    });
    bench(&mut i, "so3_compose", || {
        black_box(black_box(&r).compose(black_box(&r2)));
    });
    let xi = Vector6::new(0.5f32, -1.0, 2.0, 0.1, 0.4, -0.3);
    let a = Se3::exp(&xi);
    let b = Se3::exp(&Vector6::new(-0.2f32, 0.3, 0.1, -0.6, 0.2, 0.5));
    bench(&mut i, "se3_exp", || {
        black_box(Se3::exp(black_box(&xi)));
    });
    bench(&mut i, "se3_log", || {
        black_box(black_box(&a).log());
    });
    bench(&mut i, "se3_compose", || {
        black_box(black_box(&a).compose(black_box(&b)));
    });

    let opts: &UpdateOptions<f32> = &w.options;
    let mut updates = Updates::default();
    let mut ins = w.ins;
    bench(&mut i, "ins_predict", || {
        let _ = black_box(black_box(&mut ins).predict(black_box(&w.imu)));
    });
    let ins = &w.ins;
    updates.bench(
        &mut i,
        "ins_update_gnss_position",
        ins,
        &w.gnss_position,
        opts,
    );
    updates.bench(&mut i, "ins_update_magnetometer", ins, &w.ins_mag, opts);
    let mut ahrs = w.ahrs;
    bench(&mut i, "ahrs_predict", || {
        let _ = black_box(black_box(&mut ahrs).predict(black_box(&w.imu)));
    });
    let ahrs = &w.ahrs;
    updates.bench(&mut i, "ahrs_update_magnetometer", ahrs, &w.ahrs_mag, opts);
    updates.bench(&mut i, "ahrs_update_gravity", ahrs, &w.ahrs_gravity, opts);
    let mut sol: Option<Result<PnpSolution<f32>, SolveError>> = None;
    bench(&mut i, "pnp_solve_20", || {
        sol = Some(solve_pnp(
            black_box(&w.world),
            black_box(&w.pixels),
            black_box(&w.camera),
            black_box(&w.guess),
            black_box(&w.pnp_options),
        ));
    });
    if let Some(Ok(s)) = sol {
        hprintln!("info pnp_iterations {}", s.iterations);
    }

    // The other update models (after PnP, so that the windows above keep their indices).
    updates.bench(
        &mut i,
        "ins_update_gnss_velocity",
        ins,
        &w.gnss_velocity,
        opts,
    );
    updates.bench(&mut i, "ins_update_gravity", ins, &w.ins_gravity, opts);
    updates.bench(&mut i, "ins_update_baro", ins, &w.baro, opts);
    updates.bench(&mut i, "ins_update_heading", ins, &w.ins_heading, opts);
    let rest = &w.ins_at_rest;
    updates.bench(
        &mut i,
        "ins_update_zero_velocity",
        rest,
        &w.zero_velocity,
        opts,
    );
    updates.bench(&mut i, "ins_update_accel_at_rest", rest, &w.at_rest, opts);
    updates.bench(&mut i, "ins_update_camera", ins, &w.landmark, opts);
    updates.bench(
        &mut i,
        "ins_update_camera_iterated",
        ins,
        &w.landmark,
        &w.iterated,
    );
    updates.bench(&mut i, "ahrs_update_heading", ahrs, &w.ahrs_heading, opts);
    let nav_step = w
        .nav_step
        .as_ref()
        .is_some_and(|s| bench_nav_step(&mut i, s));
    // The parts of that call, each alone on the navigator's filter (attitude, gyro and
    // accelerometer biases): what the call's cost is made of.
    if let Some(p) = &w.nav_parts {
        let mut f = p.filter;
        bench(&mut i, "nav_filter_predict", || {
            let _ = black_box(black_box(&mut f).predict(black_box(&p.imu)));
        });
        let mut f = p.filter;
        bench(&mut i, "nav_filter_widen_attitude", || {
            let _ = black_box(black_box(&mut f).widen_attitude(black_box(1e-3), black_box(1e-3)));
        });
        let f = &p.filter;
        updates.bench(&mut i, "nav_filter_update_zero_rate", f, &p.zero_rate, opts);
        updates.bench(&mut i, "nav_filter_update_accel", f, &p.at_rest, opts);
        updates.bench(&mut i, "nav_filter_update_heading", f, &p.heading, opts);
    }
    let nav_stream = bench_nav_stream(&mut i);
    let ins_nav = bench_ins_nav(&mut i, InsRun::WithMagnetometer);
    // After every other window, so that theirs keep their indices.
    let ins_nav_no_mag = bench_ins_nav(&mut i, InsRun::WithoutMagnetometer);
    Benchmarks {
        updates,
        nav_step,
        nav_stream,
        ins_nav,
        ins_nav_no_mag,
    }
}

#[entry]
fn main() -> ! {
    hprintln!(concat!(
        "estimator-core firmware demo (",
        env!("FIRMWARE_TARGET"),
        ", f32)"
    ));
    let (outcome, work) = scenario::run::<f32>();
    let mut c = Checker { failures: 0 };
    check_outcome(&mut c, &outcome);
    c.equal("mem routines, lengths wrong", mem_routine_errors(), 0);

    match work {
        Some(w) => {
            let b = run_benchmarks(&w);
            c.equal(
                "benchmarked updates accepted",
                b.updates.accepted,
                b.updates.run,
            );
            c.equal(
                "nav block-end call fused the zero rate",
                u32::from(b.nav_step),
                1,
            );
            match b.nav_stream {
                Some((e, refused)) => {
                    c.equal("nav stream samples refused", refused, 0);
                    // The measured run is the checked one.
                    let q = scenario::quat(&e.attitude);
                    c.close("nav stream = checked run", &q, &outcome.nav_q, 0.0);
                }
                None => c.equal("nav stream run", 0, 1),
            }
            check_ins_nav(&mut c, &b.ins_nav);
            check_ins_nav_without_magnetometer(&mut c, &b.ins_nav_no_mag);
        }
        None => c.equal("benchmark workload built", 0, 1),
    }

    hprintln!("size_of Ins<f32> {}", size_of::<Ins<f32>>());
    hprintln!("size_of Ahrs<f32> {}", size_of::<Ahrs<f32>>());
    hprintln!(
        "size_of AttitudeNavigator<f32> {}",
        size_of::<AttitudeNavigator<f32>>()
    );
    hprintln!(
        "size_of InsNavigator<f32> {}",
        size_of::<InsNavigator<f32>>()
    );
    hprintln!("size_of InsReport<f32> {}", size_of::<InsReport<f32>>());
    hprintln!("size_of InsEstimate<f32> {}", size_of::<InsEstimate<f32>>());
    hprintln!(
        "size_of AttitudeReport<f32> {}",
        size_of::<AttitudeReport<f32>>()
    );
    hprintln!(
        "size_of AttitudeEstimate<f32> {}",
        size_of::<AttitudeEstimate<f32>>()
    );
    hprintln!("size_of InsState<f32> {}", size_of::<InsState<f32>>());
    hprintln!("size_of PnpSolution<f32> {}", size_of::<PnpSolution<f32>>());
    hprintln!(
        "size_of PnpOptions<f32> {}",
        size_of::<estimator_core::gn::PnpOptions<f32>>()
    );
    hprintln!("size_of Se3<f32> {}", size_of::<Se3<f32>>());
    hprintln!("size_of So3<f32> {}", size_of::<So3<f32>>());
    hprintln!(
        "size_of NormalEquations<f32,6> {}",
        size_of::<estimator_core::gn::NormalEquations<f32, 6>>()
    );
    // The options, outcomes and solutions a caller holds next to the filters and the solver.
    hprintln!("size_of AhrsState<f32> {}", size_of::<AhrsState<f32>>());
    hprintln!(
        "size_of FilterConfig<f32> {}",
        size_of::<FilterConfig<f32>>()
    );
    hprintln!(
        "size_of UpdateOptions<f32> {}",
        size_of::<UpdateOptions<f32>>()
    );
    hprintln!(
        "size_of UpdateOutcome<f32> {}",
        size_of::<UpdateOutcome<f32>>()
    );
    hprintln!(
        "size_of SolverOptions<f32> {}",
        size_of::<gn::SolverOptions<f32>>()
    );
    hprintln!(
        "size_of Solution<f32,Se3<f32>,6> {}",
        size_of::<gn::Solution<f32, Se3<f32>, 6>>()
    );
    hprintln!("size_of Factor<f32,6> {}", size_of::<gn::Factor<f32, 6>>());
    hprintln!(
        "size_of Triangulation<f32> {}",
        size_of::<gn::Triangulation<f32>>()
    );
    hprintln!(
        "size_of RotationSolution<f32> {}",
        size_of::<gn::RotationSolution<f32>>()
    );

    if c.failures == 0 {
        hprintln!("RESULT PASS");
        debug::exit(debug::EXIT_SUCCESS);
    } else {
        hprintln!("RESULT FAIL ({} checks failed)", c.failures);
        debug::exit(debug::EXIT_FAILURE);
    }
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("PANIC {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
}

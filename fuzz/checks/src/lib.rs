//! The promises of `estimator-core` and of host-sim's dataset reader, checked on inputs decoded
//! from arbitrary bytes: one `run_<target>` per fuzz target, each returning the first promise
//! it saw broken.
//!
//! The promises (from the crates' docs):
//!
//! * `no-panic`: no call panics (a panic unwinds out of `run_<target>`; the fuzzer and the
//!   corpus replay report it).
//! * `unchanged-on-error`: a call that returns `Err` leaves the filter or navigator bit for bit
//!   as it was (a navigator's refusal counter excepted, incremented by design).
//! * `unchanged-on-rejection`: an update returning `Ok(UpdateOutcome::Rejected { .. })` leaves
//!   the filter bit for bit as it was.
//! * `covariance-valid`: a call that succeeds leaves `P` finite, symmetric
//!   (`|P_ij − P_ji| ≤ 10⁻⁶·max|P|`) and positive definite (nalgebra's `cholesky()` in the same
//!   precision succeeds).
//! * `state-finite`: a call that succeeds leaves the state (and a navigator's estimate) finite.
//! * `lie-finite`: a Lie-group operation on finite inputs where its docs promise a result
//!   returns finite numbers.
//! * `lie-constructor`: `So3::from_quaternion` / `So2::from_cos_sin` return a unit element for
//!   any finite, non-zero input (their docs: "any non-zero finite norm").
//! * `solver-result`: an `Ok` from `solve_pnp`, `triangulate`, `solve_rotation_from_vectors` or
//!   `gn::solve` meets its documented guarantees (finite state, covariance and cost; every point
//!   in front of every camera at a depth above `min_depth`).
//!
//! The findings still open are listed in `fuzz/regressions/KNOWN.md` (promise and call): a
//! fuzz target does not stop on them, and the corpus replay reports them for the files listed
//! there only.

mod dataset;
mod filters;
pub mod input;
mod ins;
mod lie;
mod navigator;
mod solver;

use estimator_core::nalgebra::SMatrix;
use estimator_core::Real;
use std::sync::OnceLock;

/// A broken promise: which, in which call, and what was seen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Finding {
    /// The promise's name (see the crate docs).
    pub promise: &'static str,
    /// The call that broke it, without its arguments (`Ahrs<f32>::update(Heading)`).
    pub call: String,
    /// What was seen.
    pub detail: String,
}

impl core::fmt::Display for Finding {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} broken by {}: {}",
            self.promise, self.call, self.detail
        )
    }
}

/// `Ok`, or the first promise seen broken.
pub type Outcome = Result<(), Finding>;

/// A target's checks: `run_<target>`.
pub type Run = fn(&[u8]) -> Outcome;

/// A finding for `promise` in `call`.
pub(crate) fn finding(promise: &'static str, call: &str, detail: impl Into<String>) -> Finding {
    Finding {
        promise,
        call: call.to_owned(),
        detail: detail.into(),
    }
}

/// `fuzz/regressions/KNOWN.md` as it was built in; [`known`] reads the file itself when it is
/// there (so that a fuzzer picks up a row added while it is built).
pub const KNOWN_MD: &str = include_str!("../../regressions/KNOWN.md");

/// Where `KNOWN.md` is.
const KNOWN_PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../regressions/KNOWN.md");

/// One row of `KNOWN.md`: a regression file, the promise it breaks and the call.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Known {
    /// `<target>/<file name>` under `fuzz/regressions/`.
    pub file: String,
    /// The promise.
    pub promise: String,
    /// The call.
    pub call: String,
}

/// The rows of `KNOWN.md`'s table: lines `| \`file\` | \`promise\` | \`call\` | … |`.
#[must_use]
pub fn known() -> &'static [Known] {
    static KNOWN: OnceLock<Vec<Known>> = OnceLock::new();
    KNOWN.get_or_init(|| {
        let text = std::fs::read_to_string(KNOWN_PATH).unwrap_or_else(|_| KNOWN_MD.to_owned());
        text.lines()
            .filter_map(|line| {
                let cells: Vec<&str> = line.split('|').map(str::trim).collect();
                let code = |i: usize| {
                    cells
                        .get(i)
                        .and_then(|c| c.strip_prefix('`'))
                        .and_then(|c| c.strip_suffix('`'))
                        .map(str::to_owned)
                };
                Some(Known {
                    file: code(1)?,
                    promise: code(2)?,
                    call: code(3)?,
                })
            })
            .collect()
    })
}

/// `true` when `finding`'s promise and call are listed in `KNOWN.md` (a `*` in a listed call
/// stands for any text: one row for a cause shared by several filters or models).
#[must_use]
pub fn is_known(finding: &Finding) -> bool {
    known()
        .iter()
        .any(|k| k.promise == finding.promise && matches(&k.call, &finding.call))
}

/// `text` matches `pattern`, whose `*` stand for any text.
fn matches(pattern: &str, text: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == text,
        Some((head, rest)) => text.strip_prefix(head).is_some_and(|tail| {
            (0..=tail.len())
                .filter(|&i| tail.is_char_boundary(i))
                .any(|i| matches(rest, &tail[i..]))
        }),
    }
}

/// Collects the known findings of a run and lets it go on past them; an unknown one ends it.
#[derive(Default)]
pub(crate) struct Log {
    known: Option<Finding>,
}

impl Log {
    /// `Ok` unless `outcome` is an unknown finding; a known one is kept for [`Log::finish`].
    pub(crate) fn take(&mut self, outcome: Outcome) -> Outcome {
        match outcome {
            Err(f) if is_known(&f) => {
                self.known.get_or_insert(f);
                Ok(())
            }
            other => other,
        }
    }

    /// The first known finding of the run, if any.
    pub(crate) fn finish(self) -> Outcome {
        self.known.map_or(Ok(()), Err)
    }
}

/// The body of a fuzz target: panics (a crash for libFuzzer) on any finding not in `KNOWN.md`.
pub fn fuzz_one(data: &[u8], run: Run) {
    if let Err(f) = run(data) {
        assert!(is_known(&f), "broken promise: {f}");
    }
}

/// The filters target: `Ins`, `Ahrs` and `AhrsAccelBias` in `f32` and `f64`, constructed from
/// arbitrary values, then arbitrary predictions, updates with every model, widenings and
/// restarts.
pub fn run_filters(data: &[u8]) -> Outcome {
    filters::run(data)
}

/// The navigator target: `AttitudeNavigator<f32/f64>` with an arbitrary configuration and an
/// arbitrary interleaving of IMU and magnetometer samples.
pub fn run_navigator(data: &[u8]) -> Outcome {
    navigator::run(data)
}

/// The INS target: `InsNavigator<f32/f64>` with the default ring and queue or a ring of 8 and
/// a queue of 4, an arbitrary configuration, and a simulated vehicle's IMU, GNSS, magnetometer
/// and barometer streams (delayed, out of order, with faults) interleaved with arbitrary
/// samples at arbitrary times.
pub fn run_ins(data: &[u8]) -> Outcome {
    ins::run(data)
}

/// The Lie-group target: every operation of SO(2), SE(2), SO(3), SE(3) in `f32` and `f64`.
pub fn run_lie(data: &[u8]) -> Outcome {
    lie::run(data)
}

/// The solver target: `solve_pnp`, `triangulate`, `solve_rotation_from_vectors` and
/// `gn::solve` on four problems.
pub fn run_solver(data: &[u8]) -> Outcome {
    solver::run(data)
}

/// The dataset target: host-sim's dataset reader on files made of arbitrary bytes.
pub fn run_dataset(data: &[u8]) -> Outcome {
    dataset::run(data)
}

/// The targets by name, for the replay.
pub const TARGETS: [(&str, Run); 6] = [
    ("filters", run_filters),
    ("navigator", run_navigator),
    ("ins", run_ins),
    ("lie", run_lie),
    ("solver", run_solver),
    ("dataset", run_dataset),
];

/// Why `p` is not a valid covariance (finite, symmetric to `10⁻⁶·max|P|`, positive definite by
/// nalgebra's Cholesky in the same precision), or `None`.
pub(crate) fn covariance_problem<T: Real, const N: usize>(p: &SMatrix<T, N, N>) -> Option<String> {
    if let Some((k, x)) = p.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Some(format!("P[{}, {}] = {x:?} is not finite", k % N, k / N));
    }
    let largest = p.iter().fold(T::zero(), |m, x| m.max(x.abs()));
    let tolerance = largest * T::lit(1e-6);
    for j in 0..N {
        for i in 0..j {
            let d = (p[(i, j)] - p[(j, i)]).abs();
            if d > tolerance {
                return Some(format!(
                    "not symmetric: |P[{i}, {j}] − P[{j}, {i}]| = {d:?} > 1e-6·max|P| = {tolerance:?}"
                ));
            }
        }
    }
    if p.cholesky().is_none() {
        return Some(format!(
            "not positive definite (Cholesky fails); diagonal {:?}",
            p.diagonal().as_slice()
        ));
    }
    None
}

/// The names of the parts whose comparison failed, for a finding's detail.
pub(crate) fn differing(parts: &[(&'static str, bool)]) -> Vec<&'static str> {
    parts
        .iter()
        .filter(|(_, same)| !same)
        .map(|(name, _)| *name)
        .collect()
}

/// `a` and `b` are the same value: `==`, or, where `==` fails on a NaN, the same printed form
/// (every float printed exactly).
pub(crate) fn same<V: PartialEq + core::fmt::Debug>(a: &V, b: &V) -> bool {
    a == b || format!("{a:?}") == format!("{b:?}")
}

#[cfg(test)]
mod tests {
    use super::matches;

    #[test]
    fn a_star_stands_for_any_text() {
        assert!(matches("Ins<f32>::predict", "Ins<f32>::predict"));
        assert!(!matches("Ins<f32>::predict", "Ins<f64>::predict"));
        assert!(matches("*::update(*)", "Ahrs<f64>::update(Heading)"));
        assert!(!matches("*::update(*)", "Ahrs<f64>::predict"));
        assert!(matches(
            "AttitudeNavigator<*>::imu",
            "AttitudeNavigator<f32>::imu"
        ));
        assert!(!matches(
            "AttitudeNavigator<*>::imu",
            "AttitudeNavigator<f32>::magnetometer"
        ));
    }
}

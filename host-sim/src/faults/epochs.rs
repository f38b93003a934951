//! A replay's outputs read back as one [`Epoch`] per IMU sample: what the navigator reported
//! (`validity.csv`), and where the INS ran, its error against the truth with the 1σ it reported
//! (`estimate.csv` and the dataset's ground truth).

use crate::dataset::read::{Truth, TruthStream};
use crate::metrics::{errors, Estimate, TruthSpacing};
use estimator_core::lie::So3;
use estimator_core::nav::{self, Reason};
use nalgebra::Vector3;
use std::path::Path;

/// A quantity's validity word in `validity.csv` (`valid`, or why not).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validity {
    /// `valid`.
    Valid,
    /// `starting`.
    Starting,
    /// `uncertain`.
    Uncertain,
    /// `no_magnetometer`.
    NoMagnetometer,
    /// `heading_unresolved`.
    HeadingUnresolved,
    /// `no_fix`.
    NoFix,
    /// `fixes_disagree`.
    FixesDisagree,
    /// `reset`.
    Reset,
    /// `imu_fault`.
    ImuFault,
}

/// `validity.csv`'s validity words, written by the replay and read here: the file's format,
/// defined once.
const VALIDITY_WORDS: [(Validity, &str); 9] = [
    (Validity::Valid, "valid"),
    (Validity::Starting, "starting"),
    (Validity::Uncertain, "uncertain"),
    (Validity::NoMagnetometer, "no_magnetometer"),
    (Validity::HeadingUnresolved, "heading_unresolved"),
    (Validity::NoFix, "no_fix"),
    (Validity::FixesDisagree, "fixes_disagree"),
    (Validity::Reset, "reset"),
    (Validity::ImuFault, "imu_fault"),
];

/// `validity.csv`'s status words, as [`VALIDITY_WORDS`].
const STATUS_WORDS: [(AidStatus, &str); 6] = [
    (AidStatus::Absent, "absent"),
    (AidStatus::Waiting, "waiting"),
    (AidStatus::Fused, "fused"),
    (AidStatus::Stale, "stale"),
    (AidStatus::Rejected, "rejected"),
    (AidStatus::Faulty, "faulty"),
];

/// The word of `key` in `table` (every key is in its table).
fn word_of<K: PartialEq + Copy>(table: &[(K, &'static str)], key: K) -> &'static str {
    table.iter().find(|(k, _)| *k == key).map_or("", |(_, w)| w)
}

/// The key of `word` in `table`.
fn key_of<K: Copy>(table: &[(K, &str)], word: &str) -> Option<K> {
    table.iter().find(|(_, w)| *w == word).map(|(k, _)| *k)
}

impl From<nav::Validity> for Validity {
    fn from(v: nav::Validity) -> Self {
        match v {
            nav::Validity::Valid => Self::Valid,
            nav::Validity::Invalid(Reason::Starting) => Self::Starting,
            nav::Validity::Invalid(Reason::Uncertain) => Self::Uncertain,
            nav::Validity::Invalid(Reason::NoMagnetometer) => Self::NoMagnetometer,
            nav::Validity::Invalid(Reason::HeadingUnresolved) => Self::HeadingUnresolved,
            nav::Validity::Invalid(Reason::NoFix) => Self::NoFix,
            nav::Validity::Invalid(Reason::FixesDisagree) => Self::FixesDisagree,
            nav::Validity::Invalid(Reason::Reset) => Self::Reset,
            nav::Validity::Invalid(Reason::ImuFault) => Self::ImuFault,
        }
    }
}

impl Validity {
    /// The word as `validity.csv` writes it; `None` for any other word.
    #[must_use]
    pub fn parse(word: &str) -> Option<Self> {
        key_of(&VALIDITY_WORDS, word)
    }

    /// The word `validity.csv` writes for it.
    #[must_use]
    pub fn word(self) -> &'static str {
        word_of(&VALIDITY_WORDS, self)
    }

    /// `true` for [`Validity::Valid`].
    #[must_use]
    pub fn is_valid(self) -> bool {
        self == Self::Valid
    }
}

/// An aid's status word in `validity.csv`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AidStatus {
    /// `absent`: the dataset has no such sensor.
    Absent,
    /// `waiting`: nothing fused yet.
    Waiting,
    /// `fused`.
    Fused,
    /// `stale`: nothing due for a while.
    Stale,
    /// `rejected`: gated out.
    Rejected,
    /// `faulty`: the navigator judged the sensor at fault.
    Faulty,
}

impl From<nav::AidStatus> for AidStatus {
    fn from(s: nav::AidStatus) -> Self {
        match s {
            nav::AidStatus::Absent => Self::Absent,
            nav::AidStatus::Waiting => Self::Waiting,
            nav::AidStatus::Fused => Self::Fused,
            nav::AidStatus::Stale => Self::Stale,
            nav::AidStatus::Rejected => Self::Rejected,
            nav::AidStatus::Faulty => Self::Faulty,
        }
    }
}

impl AidStatus {
    /// The word as `validity.csv` writes it; `None` for any other word.
    #[must_use]
    pub fn parse(word: &str) -> Option<Self> {
        key_of(&STATUS_WORDS, word)
    }

    /// The word `validity.csv` writes for it.
    #[must_use]
    pub fn word(self) -> &'static str {
        word_of(&STATUS_WORDS, self)
    }
}

/// The error of the estimate against the truth at one epoch and the 1σ the navigator reported,
/// per block in [`crate::metrics::BLOCKS`] order: attitude (body-frame `δθ = Log(R̂ᵀ R)`, rad),
/// velocity and position (world axes), gyro and accelerometer bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorState {
    /// Truth minus estimate per block (the filter's error definition; the tests here use its
    /// magnitude only).
    pub error: [Vector3<f64>; 5],
    /// The reported 1σ per block and axis (NaN where `estimate.csv` left it empty).
    pub sigma: [Vector3<f64>; 5],
}

/// What the navigator reported after one IMU sample, and how wrong it was.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Epoch {
    /// The IMU sample's time, ns (the dataset's clock).
    pub t_ns: u64,
    /// Tilt validity.
    pub tilt: Validity,
    /// Heading validity.
    pub heading: Validity,
    /// Velocity validity.
    pub velocity: Validity,
    /// Position validity.
    pub position: Validity,
    /// Gyro bias validity.
    pub gyro_bias: Validity,
    /// Accelerometer bias validity.
    pub accel_bias: Validity,
    /// GNSS status.
    pub gnss: AidStatus,
    /// Magnetometer status.
    pub magnetometer: AidStatus,
    /// Barometer status.
    pub barometer: AidStatus,
    /// The report flagged an IMU fault.
    pub imu_fault: bool,
    /// The error and its reported 1σ; `None` before the INS runs or outside the truth.
    pub state: Option<ErrorState>,
}

impl Epoch {
    /// An epoch at `t_ns` with every quantity valid, every aid fused, no IMU fault and no
    /// error state (a starting point for hand-made inputs).
    #[must_use]
    pub fn nominal(t_ns: u64) -> Self {
        Self {
            t_ns,
            tilt: Validity::Valid,
            heading: Validity::Valid,
            velocity: Validity::Valid,
            position: Validity::Valid,
            gyro_bias: Validity::Valid,
            accel_bias: Validity::Valid,
            gnss: AidStatus::Fused,
            magnetometer: AidStatus::Fused,
            barometer: AidStatus::Fused,
            imu_fault: false,
            state: None,
        }
    }
}

/// The columns of `validity.csv`.
const VALIDITY_COLUMNS: usize = 12;
/// The columns of `estimate.csv`: time, state (16), 15 sigmas.
const ESTIMATE_COLUMNS: usize = 32;

/// One row of `estimate.csv`: the estimate and its 15 sigmas.
struct EstimateRow {
    estimate: Estimate,
    sigma: [Vector3<f64>; 5],
}

fn parse_estimate(path: &Path, line: usize, row: &str) -> Result<EstimateRow, String> {
    let at = |what: String| format!("{}:{line}: {what}", path.display());
    let fields: Vec<&str> = row.split(',').collect();
    if fields.len() != ESTIMATE_COLUMNS {
        return Err(at(format!(
            "expected {ESTIMATE_COLUMNS} columns, got {}",
            fields.len()
        )));
    }
    let t_ns: u64 = fields[0]
        .parse()
        .map_err(|_| at(format!("time '{}' is not an integer", fields[0])))?;
    let mut x = [f64::NAN; ESTIMATE_COLUMNS - 1];
    for (i, f) in fields[1..].iter().enumerate() {
        // An empty sigma cell is a component the filter did not estimate.
        if !f.is_empty() {
            x[i] = f
                .parse()
                .map_err(|_| at(format!("'{f}' is not a number")))?;
        }
    }
    let v = |i: usize| Vector3::new(x[i], x[i + 1], x[i + 2]);
    let attitude = So3::from_wxyz(x[3], x[4], x[5], x[6])
        .ok_or_else(|| at("quaternion of zero norm".into()))?;
    Ok(EstimateRow {
        estimate: Estimate {
            t_ns,
            position: v(0),
            attitude,
            velocity: v(7),
            gyro_bias: v(10),
            accel_bias: v(13),
            cov: [None; 5],
            valid: None,
        },
        sigma: [v(16), v(19), v(22), v(25), v(28)],
    })
}

fn parse_validity(path: &Path, line: usize, row: &str) -> Result<Epoch, String> {
    let at = |what: String| format!("{}:{line}: {what}", path.display());
    let f: Vec<&str> = row.split(',').collect();
    if f.len() != VALIDITY_COLUMNS {
        return Err(at(format!(
            "expected {VALIDITY_COLUMNS} columns, got {}",
            f.len()
        )));
    }
    let validity =
        |w: &str| Validity::parse(w).ok_or_else(|| at(format!("unknown validity '{w}'")));
    let status = |w: &str| AidStatus::parse(w).ok_or_else(|| at(format!("unknown status '{w}'")));
    Ok(Epoch {
        t_ns: f[0]
            .parse()
            .map_err(|_| at(format!("time '{}' is not an integer", f[0])))?,
        tilt: validity(f[1])?,
        heading: validity(f[2])?,
        velocity: validity(f[3])?,
        position: validity(f[4])?,
        gyro_bias: validity(f[5])?,
        accel_bias: validity(f[6])?,
        gnss: status(f[7])?,
        magnetometer: status(f[8])?,
        barometer: status(f[9])?,
        imu_fault: match f[10] {
            "0" => false,
            "1" => true,
            other => return Err(at(format!("imu_fault '{other}' is not 0 or 1"))),
        },
        state: None,
    })
}

/// The data lines of a CSV file after its header, with their 1-based line numbers.
fn data_lines(path: &Path) -> Result<Vec<(usize, String)>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(text
        .lines()
        .enumerate()
        .skip(1)
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect())
}

/// The truth at sorted times, each interpolated between the rows around it (none where rows are
/// lost around it, [`TruthSpacing::between`]).
struct TruthCursor<'a> {
    rows: &'a [Truth],
    i: usize,
    spacing: TruthSpacing,
}

impl TruthCursor<'_> {
    fn at(&mut self, t_ns: u64) -> Option<Truth> {
        while self.i + 1 < self.rows.len() && self.rows[self.i + 1].t_ns <= t_ns {
            self.i += 1;
        }
        let a = self.rows.get(self.i)?;
        if a.t_ns == t_ns {
            return Some(*a);
        }
        let b = self.rows.get(self.i + 1)?;
        if !(a.t_ns < t_ns && t_ns < b.t_ns) {
            return None;
        }
        self.spacing.between(a, b, t_ns)
    }
}

/// The epochs of a GNSS replay: `out` holds its `validity.csv` and `estimate.csv`, `dataset` its
/// ground truth (`state_groundtruth_estimate0/data.csv`). Each epoch of `validity.csv` gets the
/// estimate written at the same time, when there is one, scored against the truth interpolated
/// at that time.
///
/// # Errors
/// A file missing or malformed, named with the line.
pub fn read_epochs(out: &Path, dataset: &Path) -> Result<Vec<Epoch>, String> {
    let vpath = out.join("validity.csv");
    let mut epochs = data_lines(&vpath)?
        .iter()
        .map(|(line, row)| parse_validity(&vpath, *line, row))
        .collect::<Result<Vec<_>, _>>()?;
    let epath = out.join("estimate.csv");
    let estimates = data_lines(&epath)?
        .iter()
        .map(|(line, row)| parse_estimate(&epath, *line, row))
        .collect::<Result<Vec<_>, _>>()?;
    let mut truth_rows = Vec::new();
    let mut stream = TruthStream::open(dataset).map_err(|e| e.to_string())?;
    while let Some(t) = stream.next_truth().map_err(|e| e.to_string())? {
        truth_rows.push(t);
    }
    // The shortest row interval of the whole file: these rows are all read before scoring.
    let mut spacing = TruthSpacing::default();
    for w in truth_rows.windows(2) {
        spacing.observe(w[0].t_ns, w[1].t_ns);
    }
    let mut truth = TruthCursor {
        rows: &truth_rows,
        i: 0,
        spacing,
    };
    // Both files are in time order and the estimates are written at epochs: walk them together.
    let mut k = 0;
    for e in &mut epochs {
        while k < estimates.len() && estimates[k].estimate.t_ns < e.t_ns {
            k += 1;
        }
        let Some(row) = estimates.get(k).filter(|r| r.estimate.t_ns == e.t_ns) else {
            continue;
        };
        if let Some(t) = truth.at(e.t_ns) {
            e.state = Some(ErrorState {
                error: errors(&row.estimate, &t),
                sigma: row.sigma,
            });
        }
    }
    Ok(epochs)
}

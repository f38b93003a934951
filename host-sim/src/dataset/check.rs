//! What a replay warns about in the data it reads without refusing it ([`DataWarning`]): a last
//! line cut off, gaps in the IMU and in the aiding sensors, sensors that start late or stop
//! early against the IMU, and samples the navigator refused, with its reason.
//!
//! The times in the messages are seconds after the first IMU sample.

use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// A problem in the data that the replay survives, named by file and line.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct DataWarning {
    /// The file, as the user named it: the dataset folder as given, then the file's path in it.
    pub file: String,
    /// The 1-based line at fault, where one is.
    pub line: Option<u64>,
    /// What is wrong and what the replay made of it.
    pub message: String,
}

impl DataWarning {
    /// A warning about `file` (at `line`, where one is at fault).
    pub fn new(file: &Path, line: Option<u64>, message: impl Into<String>) -> Self {
        Self {
            file: file.display().to_string(),
            line,
            message: message.into(),
        }
    }

    /// This warning with the folder `from`, where its file lies inside it, named `to` (the
    /// replay reads a copy or a staging folder; the user knows the folder by another name).
    #[must_use]
    pub fn relocated(mut self, from: &Path, to: &Path) -> Self {
        if let Ok(rest) = Path::new(&self.file).strip_prefix(from) {
            self.file = to.join(rest).display().to_string();
        }
        self
    }
}

impl fmt::Display for DataWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

/// The distinct warnings of several runs (`(seed, warnings)`), in order of first appearance,
/// each with the first seed that had it and how many runs had it: what the runs of one
/// scenario print once.
#[must_use]
pub fn collate<'a>(
    runs: impl IntoIterator<Item = (u64, &'a [DataWarning])>,
) -> Vec<(DataWarning, u64, usize)> {
    let mut out: Vec<(DataWarning, u64, usize)> = Vec::new();
    for (seed, warnings) in runs {
        for w in warnings {
            match out.iter_mut().find(|(v, _, _)| v == w) {
                Some((_, _, n)) => *n += 1,
                None => out.push((w.clone(), seed, 1)),
            }
        }
    }
    out
}

/// The sensors of a dataset's event stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Sensor {
    /// `imu0/data.csv`.
    Imu,
    /// `mag0/data.csv`.
    Mag,
    /// `gnss0/data.csv`.
    Gnss,
    /// `cam0/observations.csv` (one sample per frame).
    Camera,
    /// `baro0/data.csv`.
    Baro,
}

impl Sensor {
    /// Its data file inside the dataset folder.
    #[must_use]
    pub fn file(self) -> &'static str {
        match self {
            Self::Imu => "imu0/data.csv",
            Self::Mag => "mag0/data.csv",
            Self::Gnss => "gnss0/data.csv",
            Self::Camera => "cam0/observations.csv",
            Self::Baro => "baro0/data.csv",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Imu => "IMU",
            Self::Mag => "magnetometer",
            Self::Gnss => "GNSS",
            Self::Camera => "camera",
            Self::Baro => "barometer",
        }
    }

    /// `n` samples of this sensor, in words: `1 GNSS fix`, `3 camera frames`.
    fn count(self, n: u64) -> String {
        let (one, many) = match self {
            Self::Gnss => ("fix", "fixes"),
            Self::Camera => ("frame", "frames"),
            _ => ("sample", "samples"),
        };
        format!("{n} {} {}", self.name(), if n == 1 { one } else { many })
    }

    fn sample(self) -> &'static str {
        match self {
            Self::Gnss => "fix",
            Self::Camera => "frame",
            _ => "sample",
        }
    }
}

/// An aiding sensor's interval is a gap worth a warning when it is longer than this many of
/// its median intervals: one sample lost (two intervals) is ordinary and stays quiet, as does a
/// rate that jitters; three intervals and more is a hole in the recording.
pub const AID_GAP_FACTOR: f64 = 2.5;

/// ... and longer than this, ns: at a magnetometer's or camera's rate (10–100 Hz) a few lost
/// samples leave no mark on the estimate, while a second without aiding is where the
/// prediction's drift starts to show (a GNSS outage is several seconds).
pub const AID_GAP_MIN_NS: u64 = 1_000_000_000;

/// Gaps listed one by one per file; the others are summed up in one more warning.
const LISTED: usize = 5;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Mark {
    t_ns: u64,
    line: u64,
}

/// Consecutive rows of one file: how many, the first and the last.
#[derive(Clone, Copy, Debug)]
struct Run {
    n: u64,
    first: Mark,
    last: Mark,
}

/// Refusals by `updates_refused` key and reason: how many, and the first row (a few entries,
/// however many refusals).
#[derive(Clone, Debug, Default)]
struct Tally(Vec<(String, String, u64, Mark)>);

impl Tally {
    fn add(&mut self, key: &str, reason: &str, at: Mark, n: u64) {
        match self
            .0
            .iter_mut()
            .find(|(k, r, _, _)| k == key && r == reason)
        {
            Some(e) => {
                e.2 += n;
                if at.line < e.3.line {
                    e.3 = at;
                }
            }
            None => self.0.push((key.to_string(), reason.to_string(), n, at)),
        }
    }

    fn merge(&mut self, other: &Tally) {
        for (k, r, n, at) in &other.0 {
            self.add(k, r, *at, *n);
        }
    }

    /// "the navigator refused N of them (reason), counted in updates_refused.KEY", or `None`.
    fn note(&self) -> Option<String> {
        let total: u64 = self.0.iter().map(|e| e.2).sum();
        if total == 0 {
            return None;
        }
        let mut reasons: BTreeMap<&str, u64> = BTreeMap::new();
        let mut keys: Vec<String> = Vec::new();
        for (k, r, n, _) in &self.0 {
            *reasons.entry(r.as_str()).or_default() += n;
            let k = format!("updates_refused.{k}");
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        let why: Vec<String> = if reasons.len() == 1 {
            reasons.keys().map(|r| (*r).to_string()).collect()
        } else {
            reasons.iter().map(|(r, n)| format!("{n}: {r}")).collect()
        };
        Some(format!(
            "the navigator refused {total} of them ({}), counted in {}",
            why.join("; "),
            keys.join(" and ")
        ))
    }
}

/// Aiding rows of one stretch of time and what the navigator refused of them.
#[derive(Clone, Debug, Default)]
struct Stretch {
    run: Option<Run>,
    refused: Tally,
}

impl Stretch {
    fn extend(&mut self, m: Mark) {
        match &mut self.run {
            Some(r) => {
                r.n += 1;
                r.last = m;
            }
            None => {
                self.run = Some(Run {
                    n: 1,
                    first: m,
                    last: m,
                });
            }
        }
    }

    /// Adds a later stretch to this one.
    fn merge(&mut self, later: &Stretch) {
        match (&mut self.run, later.run) {
            (Some(r), Some(l)) => {
                r.n += l.n;
                r.last = l.last;
            }
            (None, l) => self.run = l,
            (Some(_), None) => {}
        }
        self.refused.merge(&later.refused);
    }

    /// "inside it: 49 GNSS fixes, the navigator refused …".
    fn inside(&self, sensor: Sensor) -> String {
        let n = self.run.map_or(0, |r| r.n);
        let mut text = format!("; inside it: {}", sensor.count(n));
        if let Some(note) = self.refused.note() {
            text.push_str(&format!(", {note}"));
        }
        text
    }
}

/// An IMU interval longer than the navigator's largest step, with the aiding rows inside it.
#[derive(Clone, Debug)]
struct ImuGap {
    before: Mark,
    after: Mark,
    inside: BTreeMap<Sensor, Stretch>,
}

/// The IMU gaps after the listed ones, summed up.
#[derive(Clone, Debug)]
struct MoreGaps {
    first_line: u64,
    count: u64,
    longest_ns: u64,
    total_ns: u64,
    inside: BTreeMap<Sensor, Stretch>,
}

/// Interval counts on a log scale, bins 1 % wide, each with its smallest interval: the median
/// in constant memory (a few bins in practice, a few thousand at most).
#[derive(Clone, Debug, Default)]
struct Histogram {
    bins: BTreeMap<u32, (u64, u64)>,
    total: u64,
}

impl Histogram {
    /// Counts an interval of `dt_ns` > 0.
    fn add(&mut self, dt_ns: u64) {
        let bin = ((dt_ns.max(1) as f64).ln() / 1.01_f64.ln()) as u32;
        let e = self.bins.entry(bin).or_insert((0, dt_ns));
        e.0 += 1;
        e.1 = e.1.min(dt_ns);
        self.total += 1;
    }

    /// The lower median, to 1 % (the smallest interval of its bin), `None` when empty.
    fn median(&self) -> Option<u64> {
        let mid = self.total.checked_sub(1)? / 2;
        let mut seen = 0;
        for (n, smallest) in self.bins.values() {
            seen += n;
            if seen > mid {
                return Some(*smallest);
            }
        }
        None
    }
}

#[derive(Clone, Debug, Default)]
struct AidTrack {
    first: Option<Mark>,
    last: Option<Mark>,
    /// The intervals between distinct timestamps, for the median.
    intervals: Histogram,
    /// The intervals above [`AID_GAP_MIN_NS`]: gap candidates until the median is known (at
    /// most one per second of data).
    long: Vec<(Mark, Mark)>,
    /// Rows before the first IMU sample.
    before_imu: Stretch,
    /// Rows since the latest IMU sample, stamped beyond its reach (`max_dt`): inside an IMU
    /// gap when another IMU sample follows, after the IMU's end when none does.
    pending: Stretch,
}

/// The timing of every file of a stream, recorded row by row in stream order, and the
/// refusals the replay reports, in memory that does not grow with the run (but for an aiding
/// sensor's intervals over 1 s); read out by [`DataCheck::warnings`].
#[derive(Clone, Debug)]
pub(crate) struct DataCheck {
    max_step_ns: u64,
    imu_first: Option<Mark>,
    imu_last: Option<Mark>,
    imu_gaps: Vec<ImuGap>,
    more_imu_gaps: Option<MoreGaps>,
    aids: BTreeMap<Sensor, AidTrack>,
    /// Refusals of rows inside the IMU's span, not in a gap.
    refused: BTreeMap<Sensor, Tally>,
}

impl DataCheck {
    /// A check for a navigator whose largest IMU step is `max_dt_s` (longer: a gap).
    pub(crate) fn new(max_dt_s: f64) -> Self {
        Self {
            max_step_ns: seconds_to_ns(max_dt_s),
            imu_first: None,
            imu_last: None,
            imu_gaps: Vec::new(),
            more_imu_gaps: None,
            aids: BTreeMap::new(),
            refused: BTreeMap::new(),
        }
    }

    /// Whether an IMU row was seen.
    pub(crate) fn has_imu(&self) -> bool {
        self.imu_first.is_some()
    }

    /// Records one row (one frame of the camera), in stream order.
    pub(crate) fn row(&mut self, sensor: Sensor, t_ns: u64, line: u64) {
        let m = Mark { t_ns, line };
        if sensor == Sensor::Imu {
            // Aiding rows beyond the previous sample's reach can only lie inside a gap (at
            // equal times the IMU comes first).
            let inside: BTreeMap<Sensor, Stretch> = self
                .aids
                .iter_mut()
                .map(|(s, a)| (*s, std::mem::take(&mut a.pending)))
                .filter(|(_, p)| p.run.is_some())
                .collect();
            if let Some(before) = self
                .imu_last
                .filter(|last| t_ns.saturating_sub(last.t_ns) > self.max_step_ns)
            {
                self.imu_gap(ImuGap {
                    before,
                    after: m,
                    inside,
                });
            }
            self.imu_first.get_or_insert(m);
            self.imu_last = Some(m);
            return;
        }
        let reach = self
            .imu_last
            .map(|l| l.t_ns.saturating_add(self.max_step_ns));
        let a = self.aids.entry(sensor).or_default();
        if let Some(prev) = a.last {
            let dt = t_ns.saturating_sub(prev.t_ns);
            if dt > 0 {
                a.intervals.add(dt);
            }
            if dt > AID_GAP_MIN_NS {
                a.long.push((prev, m));
            }
        }
        a.first.get_or_insert(m);
        a.last = Some(m);
        match reach {
            None => a.before_imu.extend(m),
            Some(r) if t_ns > r => a.pending.extend(m),
            Some(_) => {}
        }
    }

    /// Keeps the first [`LISTED`] gaps; sums up the others.
    fn imu_gap(&mut self, g: ImuGap) {
        if self.imu_gaps.len() < LISTED {
            self.imu_gaps.push(g);
            return;
        }
        let d = g.after.t_ns - g.before.t_ns;
        let more = self.more_imu_gaps.get_or_insert_with(|| MoreGaps {
            first_line: g.after.line,
            count: 0,
            longest_ns: 0,
            total_ns: 0,
            inside: BTreeMap::new(),
        });
        more.count += 1;
        more.longest_ns = more.longest_ns.max(d);
        more.total_ns += d;
        for (s, stretch) in &g.inside {
            more.inside.entry(*s).or_default().merge(stretch);
        }
    }

    /// Records that the navigator refused the row last recorded, `line` (stamped `t_ns`) of
    /// `sensor`, counted under `key` in `updates_refused`, for `reason`.
    pub(crate) fn refused(
        &mut self,
        sensor: Sensor,
        t_ns: u64,
        line: u64,
        key: &str,
        reason: &str,
    ) {
        let at = Mark { t_ns, line };
        let beyond = self
            .imu_last
            .is_some_and(|l| t_ns > l.t_ns.saturating_add(self.max_step_ns));
        let before = self.imu_first.is_none();
        if let Some(a) = self.aids.get_mut(&sensor) {
            if before {
                a.before_imu.refused.add(key, reason, at, 1);
                return;
            }
            if beyond {
                a.pending.refused.add(key, reason, at, 1);
                return;
            }
        }
        self.refused
            .entry(sensor)
            .or_default()
            .add(key, reason, at, 1);
    }

    /// The warnings, with the files named inside `dir`; `imu_gap_effect` says what the
    /// navigator does after an IMU gap. Nothing without an IMU row (the caller's error).
    pub(crate) fn warnings(&self, dir: &Path, imu_gap_effect: &str) -> Vec<DataWarning> {
        let mut out = Vec::new();
        let (Some(imu_first), Some(imu_last)) = (self.imu_first, self.imu_last) else {
            return out;
        };
        let at = |t_ns: u64| {
            let s = (i128::from(t_ns) - i128::from(imu_first.t_ns)) as f64 * 1e-9;
            format!("{s:.2} s")
        };
        let imu_file = dir.join(Sensor::Imu.file());
        let max_dt = self.max_step_ns as f64 * 1e-9;
        for g in &self.imu_gaps {
            let mut message = format!(
                "no IMU sample for {} (from {} to {} after the first), longer than the navigator's largest step (max_dt = {max_dt} s): {imu_gap_effect}",
                duration(g.after.t_ns - g.before.t_ns),
                at(g.before.t_ns),
                at(g.after.t_ns),
            );
            for (s, stretch) in &g.inside {
                message.push_str(&stretch.inside(*s));
            }
            out.push(DataWarning::new(&imu_file, Some(g.after.line), message));
        }
        if let Some(more) = &self.more_imu_gaps {
            let mut message = format!(
                "{} more IMU gaps longer than max_dt = {max_dt} s from here on (the longest {}, together {})",
                more.count,
                duration(more.longest_ns),
                duration(more.total_ns)
            );
            for (s, stretch) in &more.inside {
                message.push_str(&stretch.inside(*s).replace("inside it", "inside them"));
            }
            out.push(DataWarning::new(&imu_file, Some(more.first_line), message));
        }

        for (&sensor, a) in &self.aids {
            let (Some(first), Some(last)) = (a.first, a.last) else {
                continue;
            };
            let file = dir.join(sensor.file());
            let median = a.intervals.median();
            let threshold = median.map_or(AID_GAP_MIN_NS, |m| {
                AID_GAP_MIN_NS.max((AID_GAP_FACTOR * m as f64).ceil() as u64)
            });
            let gaps: Vec<&(Mark, Mark)> = a
                .long
                .iter()
                .filter(|(p, n)| n.t_ns - p.t_ns > threshold)
                .collect();
            for (p, n) in gaps.iter().take(LISTED) {
                let d = n.t_ns - p.t_ns;
                let times = median.map_or_else(String::new, |m| {
                    format!(
                        ", {:.0} times its median interval of {}",
                        d as f64 / m as f64,
                        duration(m)
                    )
                });
                out.push(DataWarning::new(
                    &file,
                    Some(n.line),
                    format!(
                        "no {} {} for {} (from {} to {} after the first IMU sample){times}: the navigator runs without it there",
                        sensor.name(),
                        sensor.sample(),
                        duration(d),
                        at(p.t_ns),
                        at(n.t_ns),
                    ),
                ));
            }
            if let Some((_, n)) = gaps.get(LISTED) {
                let rest = &gaps[LISTED..];
                let lengths = rest.iter().map(|(p, n)| n.t_ns - p.t_ns);
                out.push(DataWarning::new(
                    &file,
                    Some(n.line),
                    format!(
                        "{} more {} gaps from here on (the longest {}, together {})",
                        rest.len(),
                        sensor.name(),
                        duration(lengths.clone().max().unwrap_or(0)),
                        duration(lengths.sum())
                    ),
                ));
            }

            // Before the IMU: the IMU starts late, or the navigator refused some.
            if let Some(run) = a.before_imu.run {
                let lead = imu_first.t_ns.saturating_sub(run.first.t_ns);
                let note = a.before_imu.refused.note();
                if lead > threshold || note.is_some() {
                    let mut message = format!(
                        "{} come before the first IMU sample (the first of them {} before it)",
                        sensor.count(run.n),
                        duration(lead)
                    );
                    if lead > threshold {
                        message.push_str(&format!(
                            ": the IMU starts {} after the {}",
                            duration(lead),
                            sensor.name()
                        ));
                    }
                    if let Some(note) = note {
                        message.push_str(&format!("; {note}"));
                    }
                    out.push(DataWarning::new(&file, Some(run.first.line), message));
                }
            }
            // Starts late or stops early against the IMU.
            let late = first.t_ns.saturating_sub(imu_first.t_ns);
            if late > threshold {
                out.push(DataWarning::new(
                    &file,
                    Some(first.line),
                    format!(
                        "the {} starts {} after the IMU (its first {} at {}): the first {} of the run go without it",
                        sensor.name(),
                        duration(late),
                        sensor.sample(),
                        at(first.t_ns),
                        duration(late)
                    ),
                ));
            }
            let early = imu_last.t_ns.saturating_sub(last.t_ns);
            if early > threshold {
                out.push(DataWarning::new(
                    &file,
                    Some(last.line),
                    format!(
                        "the {} stops {} before the IMU (its last {} at {}, the IMU's last sample at {}): the last {} of the run go without it",
                        sensor.name(),
                        duration(early),
                        sensor.sample(),
                        at(last.t_ns),
                        at(imu_last.t_ns),
                        duration(early)
                    ),
                ));
            }
            // After the IMU's end: nothing left to fuse them at.
            if let Some(run) = a.pending.run {
                let fate = a.pending.refused.note().map_or_else(
                    || "no IMU sample follows to carry them".to_string(),
                    |note| format!("not used; {note}"),
                );
                out.push(DataWarning::new(
                    &file,
                    Some(run.first.line),
                    format!(
                        "{} (from {} to {} after the first IMU sample) come after the last IMU sample ({}, {}:{}): {fate}",
                        sensor.count(run.n),
                        at(run.first.t_ns),
                        at(run.last.t_ns),
                        at(imu_last.t_ns),
                        imu_file.display(),
                        imu_last.line
                    ),
                ));
            }
        }

        // Every other refusal, by sensor and reason, at its first row.
        for (sensor, tally) in &self.refused {
            for (key, reason, n, first) in &tally.0 {
                out.push(DataWarning::new(
                    &dir.join(sensor.file()),
                    Some(first.line),
                    format!(
                        "the navigator refused {} ({reason}), this one the first; counted in updates_refused.{key}",
                        sensor.count(*n)
                    ),
                ));
            }
        }
        out
    }
}

fn seconds_to_ns(s: f64) -> u64 {
    if s.is_finite() && s > 0.0 {
        (s * 1e9).round() as u64
    } else {
        0
    }
}

fn duration(ns: u64) -> String {
    format!("{:.2} s", ns as f64 * 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    /// Feeds `rows` (time, sensor) in stream order (by time, the IMU first at equal times),
    /// each file's lines counted from 2 (under a header); GNSS rows stamped after `refuse_after`
    /// ns are refused.
    fn feed(c: &mut DataCheck, mut rows: Vec<(u64, Sensor)>, refuse_after: u64) {
        rows.sort_by_key(|(t, s)| (*t, *s));
        let mut lines: BTreeMap<Sensor, u64> = BTreeMap::new();
        for (t, s) in rows {
            let line = lines.entry(s).or_insert(1);
            *line += 1;
            c.row(s, t, *line);
            if s == Sensor::Gnss && t > refuse_after {
                c.refused(s, t, *line, "gnss_position", "too late");
            }
        }
    }

    /// An IMU at 100 Hz over `[0, 10]` s with a hole over `(3, 5)` s, a magnetometer at 10 Hz
    /// from 0 to 7 s, and GNSS at 1 Hz from 0 to 12 s; the GNSS fixes after the IMU refused.
    fn stream() -> DataCheck {
        let mut c = DataCheck::new(0.1);
        let mut rows: Vec<(u64, Sensor)> = (0..=1000)
            .map(|k| k * 10 * MS)
            .filter(|t| !(3_000 * MS < *t && *t < 5_000 * MS))
            .map(|t| (t, Sensor::Imu))
            .collect();
        rows.extend((0..=70).map(|k| (k * 100 * MS, Sensor::Mag)));
        rows.extend((0..=12).map(|k| (k * 1000 * MS, Sensor::Gnss)));
        feed(&mut c, rows, 10_000 * MS);
        c
    }

    #[test]
    fn gaps_spans_and_refusals_are_named_with_file_and_line() {
        let c = stream();
        let w = c.warnings(Path::new("ds"), "it starts again");
        let text: Vec<String> = w.iter().map(ToString::to_string).collect();
        let find = |file: &str, what: &str| {
            text.iter()
                .find(|t| t.starts_with(file) && t.contains(what))
                .unwrap_or_else(|| panic!("no '{what}' for {file} in {text:#?}"))
                .clone()
        };
        // The IMU hole between the rows at 3 s (line 302) and 5 s (line 303).
        let imu = find("ds/imu0/data.csv:", "no IMU sample for 2.00 s");
        assert!(imu.starts_with("ds/imu0/data.csv:303:"), "{imu}");
        assert!(imu.contains("from 3.00 s to 5.00 s") && imu.contains("it starts again"));
        // Inside it, beyond the reach of the sample at 3 s (0.1 s): the magnetometer samples
        // of 3.2–4.9 s (18) and the fix at 4 s.
        assert!(imu.contains("inside it: 18 magnetometer samples"), "{imu}");
        assert!(imu.contains("1 GNSS fix"), "{imu}");
        // The magnetometer's own gap is not one: its samples went on inside the IMU hole.
        assert!(!text.iter().any(|t| t.contains("no magnetometer sample")));
        let stops = find("ds/mag0/data.csv:", "stops 3.00 s before the IMU");
        assert!(stops.starts_with("ds/mag0/data.csv:72:"), "{stops}");
        let after = find("ds/gnss0/data.csv:", "after the last IMU sample");
        assert!(after.starts_with("ds/gnss0/data.csv:13:"), "{after}");
        assert!(
            after.contains("2 GNSS fixes (from 11.00 s to 12.00 s after the first IMU sample)")
                && after.contains("refused 2 of them (too late)")
                && after.contains("updates_refused.gnss_position")
                && after.contains("(10.00 s, ds/imu0/data.csv:803)"),
            "{after}"
        );
        assert_eq!(w.len(), 3, "{text:#?}");
    }

    #[test]
    fn aid_gaps_need_both_the_median_factor_and_a_second() {
        let mut c = DataCheck::new(0.1);
        // IMU at 100 Hz over 20 s; GNSS at 5 Hz with 0.6 s (3 intervals, under 1 s) and 2 s
        // holes; the magnetometer at 0.5 Hz (2 s intervals, none a gap).
        for k in 0..=2000 {
            c.row(Sensor::Imu, k * 10 * MS, k + 2);
        }
        let mut line = 1;
        for k in 0..=100 {
            let t = k * 200 * MS;
            if (21..=22).contains(&k) || (51..=59).contains(&k) {
                continue;
            }
            line += 1;
            c.row(Sensor::Gnss, t, line);
        }
        for k in 0..=10 {
            c.row(Sensor::Mag, k * 2000 * MS, k + 2);
        }
        let w = c.warnings(Path::new("d"), "");
        assert_eq!(w.len(), 1, "{w:#?}");
        assert_eq!(w[0].file, "d/gnss0/data.csv");
        assert!(
            w[0].message
                .starts_with("no GNSS fix for 2.00 s (from 10.00 s to 12.00 s")
                && w[0]
                    .message
                    .contains("10 times its median interval of 0.20 s"),
            "{}",
            w[0].message
        );
    }

    #[test]
    fn a_late_start_and_early_samples_are_warned() {
        let mut c = DataCheck::new(0.1);
        // The magnetometer at 10 Hz from 0 s, the IMU at 100 Hz from 3 s, GNSS at 5 Hz from
        // 5 s, all to 10 s.
        let mut rows: Vec<(u64, Sensor)> = (0..=100).map(|k| (k * 100 * MS, Sensor::Mag)).collect();
        rows.extend((300..=1000).map(|k| (k * 10 * MS, Sensor::Imu)));
        rows.extend((25..=50).map(|k| (k * 200 * MS, Sensor::Gnss)));
        feed(&mut c, rows, u64::MAX);
        let w: Vec<String> = c
            .warnings(Path::new("d"), "")
            .iter()
            .map(ToString::to_string)
            .collect();
        assert!(
            w.iter().any(|t| t.starts_with("d/mag0/data.csv:2:")
                && t.contains("30 magnetometer samples come before the first IMU sample")
                && t.contains("the IMU starts 3.00 s after the magnetometer")),
            "{w:#?}"
        );
        assert!(
            w.iter().any(|t| t.starts_with("d/gnss0/data.csv:2:")
                && t.contains("the GNSS starts 2.00 s after the IMU (its first fix at 2.00 s)")),
            "{w:#?}"
        );
        assert_eq!(w.len(), 2, "{w:#?}");
    }

    #[test]
    fn imu_gaps_past_the_fifth_are_summed_up_with_what_lies_inside() {
        let mut c = DataCheck::new(0.1);
        // An IMU at 100 Hz for 20 s with a 0.5 s hole every 2 s (9 holes), GNSS at 10 Hz;
        // every fix inside a hole refused.
        let mut rows: Vec<(u64, Sensor)> = (0..=2000)
            .map(|k| k * 10 * MS)
            .filter(|t| !(1..=9).any(|h| h * 2000 * MS < *t && *t < (h * 2000 + 500) * MS))
            .map(|t| (t, Sensor::Imu))
            .collect();
        rows.extend((0..=200).map(|k| (k * 100 * MS, Sensor::Gnss)));
        rows.sort_by_key(|(t, s)| (*t, *s));
        let mut lines: BTreeMap<Sensor, u64> = BTreeMap::new();
        for (t, s) in rows {
            let line = lines.entry(s).or_insert(1);
            *line += 1;
            c.row(s, t, *line);
            let in_hole = (1..=9).any(|h| (h * 2000 + 100) * MS < t && t < (h * 2000 + 500) * MS);
            if s == Sensor::Gnss && in_hole {
                c.refused(s, t, *line, "gnss_position", "too late");
            }
        }
        let w = c.warnings(Path::new("d"), "again");
        let imu: Vec<&DataWarning> = w.iter().filter(|w| w.file == "d/imu0/data.csv").collect();
        assert_eq!(imu.len(), 6, "{w:#?}");
        assert!(imu[..5]
            .iter()
            .all(|w| w.message.starts_with("no IMU sample for 0.50 s")
                && w.message
                    .contains("inside it: 3 GNSS fixes, the navigator refused 3 of them")));
        assert_eq!(
            imu[5].message,
            "4 more IMU gaps longer than max_dt = 0.1 s from here on (the longest 0.50 s, together 2.00 s); inside them: 12 GNSS fixes, the navigator refused 12 of them (too late), counted in updates_refused.gnss_position"
        );
        // Nothing else: every refusal is explained by a gap.
        assert_eq!(w.len(), 6, "{w:#?}");
    }

    #[test]
    fn other_refusals_are_counted_by_reason_at_their_first_line() {
        let mut c = DataCheck::new(0.1);
        for k in 0..=100 {
            c.row(Sensor::Imu, k * 10 * MS, k + 2);
            c.row(Sensor::Baro, k * 10 * MS, k + 2);
            if k % 10 == 5 {
                c.refused(Sensor::Baro, k * 10 * MS, k + 2, "baro", "non-finite");
            }
        }
        let w = c.warnings(Path::new("d"), "");
        assert_eq!(w.len(), 1, "{w:#?}");
        assert_eq!(
            w[0].to_string(),
            "d/baro0/data.csv:7: the navigator refused 10 barometer samples (non-finite), this one the first; counted in updates_refused.baro"
        );
    }

    #[test]
    fn a_warning_is_relocated_and_printed_with_or_without_a_line() {
        let w = DataWarning::new(
            Path::new("/tmp/stage/dataset/imu0/data.csv"),
            Some(4),
            "cut",
        )
        .relocated(Path::new("/tmp/stage/dataset"), Path::new("out/dataset"));
        assert_eq!(w.to_string(), "out/dataset/imu0/data.csv:4: cut");
        let w = DataWarning::new(Path::new("a/b.csv"), None, "x")
            .relocated(Path::new("elsewhere"), Path::new("z"));
        assert_eq!(w.to_string(), "a/b.csv: x");
        let mut h = Histogram::default();
        assert_eq!(h.median(), None);
        for dt in [5, 1, 3, 2] {
            h.add(dt * 100 * MS);
        }
        assert_eq!(h.median(), Some(200 * MS));
        // Within 1 %: the smallest interval of the median's bin.
        let mut h = Histogram::default();
        for dt in [1_000_000, 1_004_000, 1_002_000, 9_000_000] {
            h.add(dt);
        }
        assert_eq!(h.median(), Some(1_000_000));
    }

    #[test]
    fn runs_alike_are_collated() {
        let w = |m: &str| DataWarning::new(Path::new("gnss0/data.csv"), Some(3), m);
        let (a, b) = (vec![w("gap"), w("late")], vec![w("gap")]);
        let got = collate([(4, &a[..]), (5, &b[..]), (6, &[][..])]);
        assert_eq!(got, vec![(w("gap"), 4, 2), (w("late"), 4, 1)]);
    }
}

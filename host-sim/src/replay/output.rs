//! The files a replay writes: the estimate (TUM and CSV), the truth (TUM) beside it, and the
//! guard that renames them into place only when the whole run succeeded.

use super::{out_err, ReplayError};
use crate::baseline::{Madgwick, Mahony};
use crate::dataset::check::DataWarning;
use crate::dataset::read::{Truth, TruthStream};
use crate::metrics::{Estimate, Scorer, TruthSpacing};
use estimator_core::lie::So3;
use nalgebra::Vector3;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The truth at increasing times, from its rows read one by one in time order: each time is
/// given the row stamped with it, or the two rows around it interpolated
/// ([`TruthSpacing::between`]); nothing before the first row, after the last, or where rows
/// are lost around it. This is how `host-sim replay` scores each estimate.
///
/// `I` yields the rows (`Err`: a row that could not be read, passed on by [`Self::at`]); only
/// the two around the last time asked for are held.
pub struct TruthCursor<I> {
    rows: I,
    prev: Option<Truth>,
    next: Option<Truth>,
    /// The truth's sampling, to leave its lost rows unscored.
    spacing: TruthSpacing,
}

impl<I, E> TruthCursor<I>
where
    I: Iterator<Item = Result<Truth, E>>,
{
    /// A cursor before the first of `rows` (none read yet).
    pub fn new(rows: I) -> Self {
        Self {
            rows,
            prev: None,
            next: None,
            spacing: TruthSpacing::default(),
        }
    }

    /// Reads one more row into `next`.
    fn advance(&mut self) -> Result<(), E> {
        self.prev = self.next.take();
        self.next = self.rows.next().transpose()?;
        // Every row interval, also where the samples fall on the rows themselves.
        if let (Some(a), Some(b)) = (&self.prev, &self.next) {
            self.spacing.observe(a.t_ns, b.t_ns);
        }
        Ok(())
    }

    /// The truth at `t_ns` (ns, not before the time of the previous call): the row stamped
    /// `t_ns`, else the rows around it interpolated; `None` outside the truth and where rows
    /// are lost around `t_ns` ([`TruthSpacing::between`]).
    ///
    /// # Errors
    /// A row that could not be read.
    pub fn at(&mut self, t_ns: u64) -> Result<Option<Truth>, E> {
        if self.prev.is_none() && self.next.is_none() {
            self.advance()?;
            self.prev = None;
        }
        while self.next.is_some_and(|n| n.t_ns < t_ns) {
            self.advance()?;
        }
        Ok(match (self.prev, self.next) {
            (_, Some(b)) if b.t_ns == t_ns => Some(b),
            (Some(a), Some(b)) if a.t_ns <= t_ns => self.spacing.between(&a, &b, t_ns),
            _ => None,
        })
    }

    /// The rows not read yet.
    pub fn into_rows(self) -> I {
        self.rows
    }
}

/// The truth file's rows, each copied to `groundtruth.tum` as it is read.
pub(super) struct TruthFile {
    stream: TruthStream,
    tum: BufWriter<File>,
    tum_path: PathBuf,
}

impl Iterator for TruthFile {
    type Item = Result<Truth, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        let row = match self.stream.next_truth() {
            Ok(row) => row?,
            Err(e) => return Some(Err(e.into())),
        };
        Some(
            write_tum(&mut self.tum, row.t_ns, &row.position, &row.attitude)
                .map(|()| row)
                .map_err(out_err(&self.tum_path)),
        )
    }
}

impl TruthFile {
    /// Copies the remaining rows to `groundtruth.tum`; returns the truth file's warnings (a
    /// cut last line).
    fn finish(mut self) -> Result<Vec<DataWarning>, ReplayError> {
        for row in self.by_ref() {
            row?;
        }
        self.tum.flush().map_err(out_err(&self.tum_path))?;
        Ok(self.stream.warnings().to_vec())
    }
}

pub(super) fn write_tum(
    f: &mut impl Write,
    t_ns: u64,
    p: &Vector3<f64>,
    r: &So3<f64>,
) -> std::io::Result<()> {
    let q = r.quaternion();
    writeln!(
        f,
        "{}.{:09} {:.6} {:.6} {:.6} {:.9} {:.9} {:.9} {:.9}",
        t_ns / 1_000_000_000,
        t_ns % 1_000_000_000,
        p.x,
        p.y,
        p.z,
        q.i,
        q.j,
        q.k,
        q.w
    )
}

/// The file outputs (the plots aside). They are written as `NAME.partial` and renamed together at the
/// end; on any error (the guard drops uncommitted) the partial files are removed, so a failed
/// run never leaves outputs that look complete.
pub(super) const OUTPUTS: [&str; 5] = [
    "estimate.tum",
    "estimate.csv",
    "groundtruth.tum",
    "metrics.json",
    "validity.csv",
];

pub(super) struct Partials<'a> {
    out: &'a Path,
    committed: bool,
}

impl<'a> Partials<'a> {
    pub(super) fn new(out: &'a Path) -> Self {
        Self {
            out,
            committed: false,
        }
    }

    /// Removes the outputs (and plots) of an earlier run in the same folder.
    pub(super) fn clear_previous(&mut self) {
        for name in OUTPUTS.iter().chain(crate::plot::FILES.iter()) {
            let _ = std::fs::remove_file(self.out.join(name));
        }
    }

    pub(super) fn commit(&mut self) -> Result<(), ReplayError> {
        for name in OUTPUTS {
            let from = self.out.join(format!("{name}.partial"));
            if from.exists() {
                std::fs::rename(&from, self.out.join(name)).map_err(out_err(&from))?;
            }
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Partials<'_> {
    fn drop(&mut self) {
        if !self.committed {
            for name in OUTPUTS {
                let _ = std::fs::remove_file(self.out.join(format!("{name}.partial")));
            }
        }
    }
}

pub(super) fn write_estimate_csv(f: &mut impl Write, e: &Estimate) -> std::io::Result<()> {
    let q = e.attitude.quaternion();
    let (p, v, bg, ba) = (e.position, e.velocity, e.gyro_bias, e.accel_bias);
    write!(
        f,
        "{},{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{:.9},{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{:.6},{:.6},{:.6}",
        e.t_ns, p.x, p.y, p.z, q.w, q.i, q.j, q.k, v.x, v.y, v.z, bg.x, bg.y, bg.z, ba.x, ba.y, ba.z
    )?;
    for s in e.sigmas() {
        if s.is_finite() {
            write!(f, ",{s:.6e}")?;
        } else {
            write!(f, ",")?;
        }
    }
    writeln!(f)
}

/// Creates `out/NAME.partial` (renamed to `NAME` by [`Partials::commit`]).
pub(super) fn open_partial(
    out: &Path,
    name: &str,
) -> Result<(BufWriter<File>, PathBuf), ReplayError> {
    let p = out.join(format!("{name}.partial"));
    File::create(&p)
        .map(|f| (BufWriter::new(f), p.clone()))
        .map_err(|e| ReplayError::Output {
            path: p,
            message: e.to_string(),
        })
}

/// The reference filters run beside a navigator on the same samples (where a magnetometer
/// exists), scored with it.
pub(super) type Baselines = (Madgwick, Mahony);

/// What every replay writes as it goes: the estimate (TUM and CSV) at each IMU sample, and the
/// truth it is scored against (copied to `groundtruth.tum`).
pub(super) struct EstimateFiles {
    tum: BufWriter<File>,
    tum_path: PathBuf,
    csv: BufWriter<File>,
    csv_path: PathBuf,
    truth: Option<TruthCursor<TruthFile>>,
}

impl EstimateFiles {
    /// Opens the partial files in `out` (the truth's when `has_truth`, read from `dir`).
    pub(super) fn open(out: &Path, dir: &Path, has_truth: bool) -> Result<Self, ReplayError> {
        let (tum, tum_path) = open_partial(out, "estimate.tum")?;
        let (mut csv, csv_path) = open_partial(out, "estimate.csv")?;
        super::write_csv_header(&mut csv).map_err(out_err(&csv_path))?;
        let truth = if has_truth {
            let (tum, tum_path) = open_partial(out, "groundtruth.tum")?;
            Some(TruthCursor::new(TruthFile {
                stream: TruthStream::open(dir)?,
                tum,
                tum_path,
            }))
        } else {
            None
        };
        Ok(Self {
            tum,
            tum_path,
            csv,
            csv_path,
            truth,
        })
    }

    /// Writes one estimate and scores it (and the reference filters) against the truth at its
    /// time, where there is one.
    pub(super) fn add(
        &mut self,
        scorer: &mut Scorer,
        e: &Estimate,
        baselines: Option<&Baselines>,
    ) -> Result<(), ReplayError> {
        write_tum(&mut self.tum, e.t_ns, &e.position, &e.attitude)
            .map_err(out_err(&self.tum_path))?;
        write_estimate_csv(&mut self.csv, e).map_err(out_err(&self.csv_path))?;
        if let Some(tr) = self.truth.as_mut() {
            if let Some(t) = tr.at(e.t_ns)? {
                scorer.add(e, &t);
                if let Some((mw, mh)) = baselines {
                    scorer.add_baseline("madgwick", &mw.attitude, &t);
                    scorer.add_baseline("mahony", &mh.attitude, &t);
                }
            }
        }
        Ok(())
    }

    /// Flushes the files and copies the rest of the truth; returns the truth file's warnings
    /// (a cut last line).
    pub(super) fn finish(mut self) -> Result<Vec<DataWarning>, ReplayError> {
        self.tum.flush().map_err(out_err(&self.tum_path))?;
        self.csv.flush().map_err(out_err(&self.csv_path))?;
        match self.truth {
            Some(tr) => tr.into_rows().finish(),
            None => Ok(Vec::new()),
        }
    }
}

//! The PNG plots a person looks at after a run, each with a legend for every line, band and
//! marker, placed outside the plotting areas so that it covers no data:
//!
//! * `trajectory.png`: the estimate against the truth, top view (x-y, equal scale) and side view
//!   (height against the distance along the true track, or against time when the track is
//!   shorter than 1 m), with start and end markers;
//! * `errors.png`: per-axis errors inside their ±3σ bands;
//! * `biases.png`: bias estimates against the truth;
//! * `nis.png`: NIS per update and sensor against its 95 % chi-square bounds and expected mean:
//!   accepted updates as dots, gated-out ones as hollow squares; a point above the scale is
//!   drawn at its top edge with a marker of its own, never dropped. The panel's caption gives
//!   the counts.
//!
//! Lines and bands over time break where the data do ([`split_at_gaps`]: an interval longer
//! than [`GAP_FACTOR`] median intervals, an IMU gap or the navigator's restart after one)
//! rather than drawing a straight line across what was never estimated.
//!
//! Text needs a TrueType font: DejaVu Sans from the system (Debian's `fonts-dejavu-core`), Arial on
//! macOS and Windows, or the file named by `HOST_SIM_FONT`. Without one the plots are skipped with a warning.

use crate::metrics::{HistoryPoint, Scorer, SensorStats, BLOCKS};
use crate::stats::chi2_quantile;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The plot files a run may write.
pub const FILES: [&str; 4] = ["trajectory.png", "errors.png", "biases.png", "nis.png"];

type PlotResult = Result<(), Box<dyn std::error::Error>>;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Where the common systems keep a sans-serif TrueType font: Debian/Ubuntu, Fedora, Arch,
/// macOS, Windows.
const FONT_PATHS: [&str; 7] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
    "C:\\Windows\\Fonts\\DejaVuSans.ttf",
];

/// Registers a font once; `false` when none could be found.
fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        let mut candidates: Vec<PathBuf> = std::env::var_os("HOST_SIM_FONT")
            .map(PathBuf::from)
            .into_iter()
            .collect();
        candidates.extend(FONT_PATHS.iter().map(PathBuf::from));
        for path in candidates {
            if let Ok(bytes) = std::fs::read(&path) {
                let leaked: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if register_font("sans-serif", FontStyle::Normal, leaked).is_ok() {
                    return true;
                }
            }
        }
        false
    })
}

/// Writes every plot into `dir`; returns the files written.
///
/// # Errors
/// When a file cannot be drawn or written.
pub fn write_all(
    dir: &Path,
    scorer: &Scorer,
    title: &str,
) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    if !font_ready() {
        eprintln!("host-sim: no TrueType font found (install fonts-dejavu-core or set HOST_SIM_FONT); plots skipped");
        return Ok(Vec::new());
    }
    let pts = scorer.history.points();
    let mut written = Vec::new();
    if pts.is_empty() {
        return Ok(written);
    }
    let has_position = pts.iter().any(|p| p.sigma[6].is_finite());
    if has_position {
        let f = dir.join("trajectory.png");
        trajectory(&f, pts, title)?;
        written.push(f);
    }
    let f = dir.join("errors.png");
    let t0 = scorer.t0_ns().unwrap_or(0);
    let seconds = |ns: u64| (ns as f64 - t0 as f64) * 1e-9;
    let faults: Vec<(f64, f64)> = scorer
        .faults
        .iter()
        .map(|f| (seconds(f.start_ns), seconds(f.end_ns)))
        .collect();
    errors(&f, pts, &faults, title)?;
    written.push(f);
    let f = dir.join("biases.png");
    biases(&f, pts, title)?;
    written.push(f);
    if scorer
        .sensors
        .values()
        .any(|s| !s.history.points().is_empty())
    {
        let f = dir.join("nis.png");
        nis(&f, scorer, title)?;
        written.push(f);
    }
    Ok(written)
}

/// An interval between two plotted points longer than this many median intervals is a gap:
/// lines and bands stop at it. Decimation keeps the points evenly spaced in samples, so the
/// median is the plotting step; jitter and a lost sample stay well below five of them.
pub const GAP_FACTOR: f64 = 5.0;

/// The index ranges of `t` (times in increasing order) between its gaps: intervals longer
/// than [`GAP_FACTOR`] times the median of the positive intervals. One range over everything
/// when there is no positive interval; none for no times.
#[must_use]
pub fn split_at_gaps(t: &[f64]) -> Vec<Range<usize>> {
    if t.is_empty() {
        return Vec::new();
    }
    let mut steps: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    if steps.is_empty() {
        return std::iter::once(0..t.len()).collect();
    }
    let mid = (steps.len() - 1) / 2;
    let (_, median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
    let limit = GAP_FACTOR * *median;
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..t.len() {
        if t[i] - t[i - 1] > limit {
            out.push(start..i);
            start = i;
        }
    }
    out.push(start..t.len());
    out
}

/// The ranges of the history's points between time gaps ([`split_at_gaps`]).
fn segments(pts: &[HistoryPoint]) -> Vec<Range<usize>> {
    let t: Vec<f64> = pts.iter().map(|p| p.t).collect();
    split_at_gaps(&t)
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (lo - pad, hi + pad)
}

/// The colours of the plots.
const ESTIMATE: RGBColor = RED;
const TRUTH: RGBColor = BLACK;
const START: RGBColor = RGBColor(0, 150, 0);
const END: RGBColor = RGBColor(30, 90, 220);
const POINT: RGBColor = BLUE;
const CLIPPED: RGBColor = RGBColor(230, 120, 0);
const GATED: RGBColor = RGBColor(200, 0, 0);
const EXPECTED: RGBColor = RGBColor(0, 150, 0);

/// Pixel size of the markers.
const MARKER: i32 = 6;

/// How a legend entry is drawn.
#[derive(Clone, Copy)]
enum Mark {
    /// A line segment.
    Line(ShapeStyle),
    /// A filled box (a band).
    Band(ShapeStyle),
    /// A dot of this radius.
    Dot(ShapeStyle, i32),
    /// An upward triangle.
    Triangle(ShapeStyle),
    /// A square.
    Square(ShapeStyle),
}

/// A legend entry.
struct Entry {
    mark: Mark,
    label: String,
}

impl Entry {
    fn new(mark: Mark, label: impl Into<String>) -> Self {
        Self {
            mark,
            label: label.into(),
        }
    }
}

/// Width of a legend entry's mark, px.
const MARK_W: i32 = 26;

/// Draws a legend mark whose left edge is at `x`, centred on `y`.
fn draw_mark(area: &Area<'_>, mark: Mark, x: i32, y: i32) -> PlotResult {
    let c = x + MARK_W / 2;
    match mark {
        Mark::Line(s) => area.draw(&PathElement::new(vec![(x, y), (x + MARK_W, y)], s))?,
        Mark::Band(s) => area.draw(&Rectangle::new([(x, y - 7), (x + MARK_W, y + 7)], s))?,
        Mark::Dot(s, r) => area.draw(&Circle::new((c, y), r, s))?,
        Mark::Triangle(s) => area.draw(&TriangleMarker::new((c, y), MARKER, s))?,
        Mark::Square(s) => area.draw(&Rectangle::new(
            [
                (c - MARKER + 1, y - MARKER + 1),
                (c + MARKER - 1, y + MARKER - 1),
            ],
            s,
        ))?,
    }
    Ok(())
}

/// A legend in one row across `area` (a strip outside the plotting areas), framed.
fn legend_row(area: &Area<'_>, entries: &[Entry]) -> PlotResult {
    let font = ("sans-serif", 16).into_font();
    let text = font
        .clone()
        .into_text_style(area)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let (_, h) = area.dim_in_pixel();
    let y = i32::try_from(h / 2).unwrap_or(0);
    let mut widths = Vec::with_capacity(entries.len());
    for e in entries {
        let (w, _) = area.estimate_text_size(&e.label, &text)?;
        widths.push(i32::try_from(w).unwrap_or(0));
    }
    let total: i32 = widths.iter().map(|w| MARK_W + 8 + w + 28).sum::<i32>() - 28;
    let x0 = 15;
    area.draw(&Rectangle::new(
        [(x0 - 8, y - 14), (x0 + total + 8, y + 14)],
        BLACK.stroke_width(1),
    ))?;
    let mut x = x0;
    for (e, w) in entries.iter().zip(widths) {
        draw_mark(area, e.mark, x, y)?;
        area.draw(&Text::new(
            e.label.clone(),
            (x + MARK_W + 8, y),
            text.clone(),
        ))?;
        x += MARK_W + 8 + w + 28;
    }
    Ok(())
}

/// A legend in one column down `area` (beside a plotting area).
fn legend_column(area: &Area<'_>, entries: &[Entry]) -> PlotResult {
    let text = ("sans-serif", 14)
        .into_font()
        .into_text_style(area)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let mut y = 30;
    for e in entries {
        draw_mark(area, e.mark, 8, y)?;
        area.draw(&Text::new(
            e.label.clone(),
            (8 + MARK_W + 8, y),
            text.clone(),
        ))?;
        y += 24;
    }
    Ok(())
}

/// The plotting area inside a chart cell of `dim` pixels with these margins and label areas.
fn plotting_pixels(dim: (u32, u32), margin: u32, x_label: u32, y_label: u32) -> (f64, f64) {
    let w = dim.0.saturating_sub(2 * margin + y_label).max(1);
    let h = dim.1.saturating_sub(2 * margin + x_label).max(1);
    (f64::from(w), f64::from(h))
}

fn trajectory(path: &Path, pts: &[HistoryPoint], title: &str) -> PlotResult {
    let root = BitMapBackend::new(path, (1600, 860)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: trajectory, estimate against truth"),
        ("sans-serif", 24),
    )?;
    let (strip, body) = body.split_vertically(44);
    let thin = |c: RGBColor| ShapeStyle::from(c).stroke_width(2);
    legend_row(
        &strip,
        &[
            Entry::new(Mark::Line(thin(TRUTH)), "truth"),
            Entry::new(Mark::Line(ShapeStyle::from(ESTIMATE)), "estimate"),
            Entry::new(Mark::Dot(START.filled(), MARKER), "start"),
            Entry::new(Mark::Square(END.filled()), "end"),
        ],
    )?;
    let (left, right) = body.split_horizontally(800);
    let (margin, x_label, y_label) = (15_u32, 45_u32, 65_u32);

    // Top view, equal scale on both axes.
    let left = left.titled("top view", ("sans-serif", 18))?;
    let xs = pts
        .iter()
        .flat_map(|p| [p.est_position.x, p.true_position.x]);
    let ys = pts
        .iter()
        .flat_map(|p| [p.est_position.y, p.true_position.y]);
    let ((x0, x1), (y0, y1)) = (range(xs), range(ys));
    let (pw, ph) = plotting_pixels(left.dim_in_pixel(), margin, x_label, y_label);
    let per_px = ((x1 - x0) / pw).max((y1 - y0) / ph);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * per_px * pw, 0.5 * per_px * ph);
    let mut chart = ChartBuilder::on(&left)
        .margin(margin)
        .x_label_area_size(x_label)
        .y_label_area_size(y_label)
        .build_cartesian_2d(cx - hx..cx + hx, cy - hy..cy + hy)?;
    chart
        .configure_mesh()
        .x_desc("east x [m]")
        .y_desc("north y [m]")
        .draw()?;
    let top_view: [Vec<(f64, f64)>; 2] = [
        pts.iter()
            .map(|p| (p.true_position.x, p.true_position.y))
            .collect(),
        pts.iter()
            .map(|p| (p.est_position.x, p.est_position.y))
            .collect(),
    ];
    let parts = segments(pts);
    draw_tracks(&mut chart, &top_view, &parts)?;

    // Side view: height against the distance along the true track (time when it stays put).
    let right = right.titled("side view", ("sans-serif", 18))?;
    let mut along = Vec::with_capacity(pts.len());
    let mut d = 0.0;
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            let q = &pts[i - 1];
            d += (p.true_position.xy() - q.true_position.xy()).norm();
        }
        along.push(d);
    }
    let (abscissa, x_desc) = if d >= 1.0 {
        (along, "distance along the true track, horizontal [m]")
    } else {
        (pts.iter().map(|p| p.t).collect(), "t [s]")
    };
    let side: [Vec<(f64, f64)>; 2] = [
        abscissa
            .iter()
            .zip(pts)
            .map(|(a, p)| (*a, p.true_position.z))
            .collect(),
        abscissa
            .iter()
            .zip(pts)
            .map(|(a, p)| (*a, p.est_position.z))
            .collect(),
    ];
    let (a0, a1) = range(abscissa.iter().copied());
    let (z0, z1) = range(side.iter().flatten().map(|p| p.1));
    let mut chart = ChartBuilder::on(&right)
        .margin(margin)
        .x_label_area_size(x_label)
        .y_label_area_size(y_label)
        .build_cartesian_2d(a0..a1, z0..z1)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("up z [m] (own scale)")
        .draw()?;
    draw_tracks(&mut chart, &side, &parts)?;
    root.present()?;
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The truth and the estimate (in that order) with their start and end markers, each line
/// broken between the `parts` (index ranges between time gaps).
fn draw_tracks(
    chart: &mut Chart<'_, '_>,
    tracks: &[Vec<(f64, f64)>; 2],
    parts: &[Range<usize>],
) -> PlotResult {
    let styles = [TRUTH.stroke_width(2), ESTIMATE.into()];
    for (track, style) in tracks.iter().zip(styles) {
        for part in parts {
            if let Some(points) = track.get(part.clone()) {
                chart.draw_series(LineSeries::new(points.iter().copied(), style))?;
            }
        }
    }
    for track in tracks {
        if let (Some(&first), Some(&last)) = (track.first(), track.last()) {
            chart.draw_series(std::iter::once(Circle::new(first, MARKER, START.filled())))?;
            chart.draw_series(std::iter::once(
                EmptyElement::at(last)
                    + Rectangle::new(
                        [(-MARKER + 1, -MARKER + 1), (MARKER - 1, MARKER - 1)],
                        END.filled(),
                    ),
            ))?;
        }
    }
    Ok(())
}

/// The spans `[t_a, t_b]` of consecutive points where block `b` was reported not valid, each
/// inside one segment between time gaps ([`split_at_gaps`]): nothing was reported in a gap, so
/// no span crosses it.
fn invalid_spans(pts: &[HistoryPoint], b: usize) -> Vec<(f64, f64)> {
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for range in segments(pts) {
        let part = pts.get(range).unwrap_or(&[]);
        let mut open: Option<f64> = None;
        for p in part {
            let invalid = p.valid.is_some_and(|v| !v.get(b).copied().unwrap_or(true));
            match (invalid, open) {
                (true, None) => open = Some(p.t),
                (false, Some(a)) => {
                    spans.push((a, p.t));
                    open = None;
                }
                _ => {}
            }
        }
        if let (Some(a), Some(last)) = (open, part.last()) {
            spans.push((a, last.t));
        }
    }
    spans
}

/// Per-axis errors inside their ±3σ bands; the dataset's fault intervals (`faults`, s) shaded,
/// and the spans the navigator reported a block not valid marked along the bottom.
fn errors(path: &Path, pts: &[HistoryPoint], faults: &[(f64, f64)], title: &str) -> PlotResult {
    let blocks: Vec<usize> = (0..5)
        .filter(|b| pts.iter().any(|p| p.sigma[3 * b].is_finite()))
        .collect();
    let root =
        BitMapBackend::new(path, (1500, 260 * blocks.len() as u32 + 100)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: errors inside ±3σ (the first second clipped to the scale of the rest)"),
        ("sans-serif", 24),
    )?;
    let (strip, body) = body.split_vertically(40);
    let band = BLACK.mix(0.15).filled();
    let fault_fill = RED.mix(0.12).filled();
    let invalid_fill = RGBColor(230, 140, 0).mix(0.8).filled();
    let mut entries = vec![
        Entry::new(Mark::Line(ESTIMATE.into()), "error"),
        Entry::new(Mark::Band(band), "±3σ"),
    ];
    if !faults.is_empty() {
        entries.push(Entry::new(
            Mark::Band(fault_fill),
            "sensor fault (faults.csv)",
        ));
    }
    if pts.iter().any(|p| p.valid.is_some()) {
        entries.push(Entry::new(Mark::Band(invalid_fill), "reported not valid"));
    }
    legend_row(&strip, &entries)?;
    let cells = body.split_evenly((blocks.len(), 3));
    let units = ["deg", "m/s", "m", "deg/s", "m/s²"];
    let scale = [57.295_779_5, 1.0, 1.0, 57.295_779_5, 1.0];
    let t1 = pts.last().map_or(1.0, |p| p.t.max(1e-3));
    let parts = segments(pts);
    for (row, &b) in blocks.iter().enumerate() {
        for axis in 0..3 {
            let i = 3 * b + axis;
            let Some(cell) = cells.get(row * 3 + axis) else {
                continue;
            };
            let k = scale[b];
            let lim = pts
                .iter()
                .map(|p| (3.0 * p.sigma[i] * k).max((p.error[i] * k).abs()))
                .filter(|v| v.is_finite())
                // Skip the first second, where the prior's wide bands would flatten the rest.
                .zip(pts.iter().map(|p| p.t))
                .filter(|(_, t)| *t > 1.0)
                .fold(1e-6_f64, |a, (v, _)| a.max(v))
                * 1.1;
            let mut chart = ChartBuilder::on(cell)
                .caption(
                    format!("{} {}", BLOCKS[b], ["x", "y", "z"][axis]),
                    ("sans-serif", 16),
                )
                .margin(6)
                .x_label_area_size(28)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t1, -lim..lim)?;
            chart
                .configure_mesh()
                .x_desc("t [s]")
                .y_desc(units[b])
                .label_style(("sans-serif", 12))
                .draw()?;
            for part in &parts {
                let upper: Vec<(f64, f64)> = pts[part.clone()]
                    .iter()
                    .map(|p| (p.t, (3.0 * p.sigma[i] * k).min(lim)))
                    .collect();
                let mut band_pts = upper.clone();
                band_pts.extend(upper.iter().rev().map(|(t, v)| (*t, -v)));
                chart.draw_series(std::iter::once(Polygon::new(band_pts, band)))?;
            }
            chart.draw_series(
                faults
                    .iter()
                    .map(|(a, b)| Rectangle::new([(*a, -lim), (*b, lim)], fault_fill)),
            )?;
            chart.draw_series(
                invalid_spans(pts, b)
                    .into_iter()
                    .map(|(a, z)| Rectangle::new([(a, -lim), (z, -0.9 * lim)], invalid_fill)),
            )?;
            for part in &parts {
                chart.draw_series(LineSeries::new(
                    pts[part.clone()]
                        .iter()
                        .map(|p| (p.t, (p.error[i] * k).clamp(-lim, lim))),
                    ESTIMATE,
                ))?;
            }
        }
    }
    root.present()?;
    Ok(())
}

fn biases(path: &Path, pts: &[HistoryPoint], title: &str) -> PlotResult {
    let root = BitMapBackend::new(path, (1500, 660)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: bias estimates against truth"),
        ("sans-serif", 24),
    )?;
    let (strip, body) = body.split_vertically(40);
    legend_row(
        &strip,
        &[
            Entry::new(Mark::Line(TRUTH.stroke_width(2)), "truth"),
            Entry::new(Mark::Line(ESTIMATE.into()), "estimate"),
        ],
    )?;
    let cells = body.split_evenly((2, 3));
    let t1 = pts.last().map_or(1.0, |p| p.t.max(1e-3));
    let parts = segments(pts);
    for (i, cell) in cells.iter().enumerate() {
        let (k, unit) = if i < 3 {
            (57.295_779_5, "deg/s")
        } else {
            (1.0, "m/s²")
        };
        let (lo, hi) = range(
            pts.iter()
                .flat_map(|p| [p.est_bias[i] * k, p.true_bias[i] * k]),
        );
        let name = if i < 3 { "gyro bias" } else { "accel bias" };
        let mut chart = ChartBuilder::on(cell)
            .caption(
                format!("{name} {}", ["x", "y", "z"][i % 3]),
                ("sans-serif", 16),
            )
            .margin(6)
            .x_label_area_size(28)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t1, lo..hi)?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(unit)
            .label_style(("sans-serif", 12))
            .draw()?;
        for part in &parts {
            let part = &pts[part.clone()];
            chart.draw_series(LineSeries::new(
                part.iter().map(|p| (p.t, p.true_bias[i] * k)),
                TRUTH.stroke_width(2),
            ))?;
            chart.draw_series(LineSeries::new(
                part.iter().map(|p| (p.t, p.est_bias[i] * k)),
                ESTIMATE,
            ))?;
        }
    }
    root.present()?;
    Ok(())
}

/// Width of the legend column beside each NIS panel, px.
const NIS_LEGEND_W: u32 = 300;

fn nis(path: &Path, scorer: &Scorer, title: &str) -> PlotResult {
    let sensors: Vec<_> = scorer
        .sensors
        .iter()
        .filter(|(_, s)| !s.history.points().is_empty())
        .collect();
    if sensors.is_empty() {
        return Ok(());
    }
    let root =
        BitMapBackend::new(path, (1400, 280 * sensors.len() as u32 + 60)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: NIS per update, with its 95 % chi-square interval"),
        ("sans-serif", 24),
    )?;
    // One time axis for every sensor.
    let t1 = sensors
        .iter()
        .filter_map(|(_, s)| s.history.points().last().map(|p| p.0))
        .fold(1e-3, f64::max);
    let cells = body.split_evenly((sensors.len(), 1));
    for ((name, stats), cell) in sensors.iter().zip(cells.iter()) {
        let (w, _) = cell.dim_in_pixel();
        let (plot, legend) = cell.split_horizontally(w.saturating_sub(NIS_LEGEND_W));
        nis_panel(&plot, &legend, name, stats, t1)?;
    }
    root.present()?;
    Ok(())
}

/// One sensor's NIS: the chart in `plot`, its legend in `legend`.
fn nis_panel(
    plot: &Area<'_>,
    legend: &Area<'_>,
    name: &str,
    stats: &SensorStats,
    t1: f64,
) -> PlotResult {
    let h = stats.history.points();
    // The bounds are those of the most frequent measurement dimension.
    let mut dofs = std::collections::BTreeMap::<usize, usize>::new();
    for p in h {
        *dofs.entry(p.2).or_default() += 1;
    }
    let dof = dofs
        .iter()
        .max_by_key(|(_, n)| **n)
        .map_or(1, |(d, _)| *d)
        .max(1);
    let (lo, hi) = (
        chi2_quantile(0.025, dof as f64),
        chi2_quantile(0.975, dof as f64),
    );
    let ymax = h
        .iter()
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .fold(hi * 1.5, f64::max)
        .min(hi * 6.0);
    // Above the scale: drawn at its top edge, with a marker of their own.
    let edge = ymax * 0.97;
    let (inside, above): (Vec<&(f64, f64, usize, bool)>, Vec<_>) = h
        .iter()
        .filter(|p| !p.1.is_nan())
        .partition(|p| p.1 <= ymax);
    let not_a_number = h.iter().filter(|p| p.1.is_nan()).count();
    let dof_note = if dofs.len() > 1 {
        format!(
            "dof {}–{}, bounds for dof {dof}",
            dofs.keys().min().unwrap_or(&dof),
            dofs.keys().max().unwrap_or(&dof)
        )
    } else {
        format!("dof {dof}")
    };
    let mut chart = ChartBuilder::on(plot)
        .caption(
            format!(
                "{name} ({dof_note}): mean {:.2}, accepted {}, gated out {}, refused {}",
                stats.nis_mean(),
                stats.accepted,
                stats.rejected,
                stats.refused
            ),
            ("sans-serif", 16),
        )
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..t1, 0.0..ymax)?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc("NIS")
        .label_style(("sans-serif", 12))
        .draw()?;
    // The lines first, so that they hide no point.
    let bound = BLACK.stroke_width(2);
    let expected = EXPECTED.stroke_width(2);
    for (v, style) in [(lo, bound), (hi, bound), (dof as f64, expected)] {
        chart.draw_series(LineSeries::new([(0.0, v), (t1, v)], style))?;
    }
    // Accepted updates as dots; gated-out ones as hollow squares of their own colour, drawn
    // over the dots (a square the size of the marker in pixels, whatever the scale).
    let (accepted, gated): (Vec<&(f64, f64, usize, bool)>, Vec<_>) =
        inside.iter().copied().partition(|p| p.3);
    chart.draw_series(
        accepted
            .iter()
            .map(|p| Circle::new((p.0, p.1), 2, POINT.filled())),
    )?;
    chart.draw_series(gated.iter().map(|p| {
        EmptyElement::at((p.0, p.1))
            + Rectangle::new(
                [(-MARKER + 1, -MARKER + 1), (MARKER - 1, MARKER - 1)],
                GATED.stroke_width(2),
            )
    }))?;
    chart.draw_series(
        above
            .iter()
            .map(|p| TriangleMarker::new((p.0, edge), MARKER, CLIPPED.filled())),
    )?;
    let mut entries = vec![
        Entry::new(Mark::Dot(POINT.filled(), 3), "NIS, accepted"),
        Entry::new(Mark::Line(bound), "95 % bounds"),
        Entry::new(Mark::Line(expected), format!("expected mean ({dof})")),
    ];
    if !gated.is_empty() {
        entries.insert(
            1,
            Entry::new(
                Mark::Square(GATED.stroke_width(2)),
                format!("NIS, gated out: {}", gated.len()),
            ),
        );
    }
    if !above.is_empty() {
        entries.insert(
            1,
            Entry::new(
                Mark::Triangle(CLIPPED.filled()),
                format!("clipped (off scale): {}", above.len()),
            ),
        );
    }
    if not_a_number > 0 {
        entries.push(Entry::new(
            Mark::Line(WHITE.into()),
            format!("not a number (not drawn): {not_a_number}"),
        ));
    }
    legend_column(legend, &entries)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::read::Truth;
    use crate::metrics::{Estimate, Outcome};
    use estimator_core::lie::{LieGroup, So3};
    use nalgebra::{Matrix3, Vector3};

    /// A short synthetic run: a circle with a small error, and NIS values some of which are
    /// far above the scale or not numbers.
    fn scorer(with_position: bool) -> Scorer {
        let mut s = Scorer::default();
        for k in 0..400_u64 {
            let t_ns = k * 50_000_000;
            let a = k as f64 * 0.02;
            let position = Vector3::new(10.0 * a.cos(), 10.0 * a.sin(), 0.1 * a);
            let truth = Truth {
                t_ns,
                position,
                attitude: So3::exp(&Vector3::new(0.0, 0.0, a)),
                velocity: Vector3::new(-0.2 * a.sin(), 0.2 * a.cos(), 0.0),
                gyro_bias: Vector3::new(0.001, 0.0, 0.0),
                accel_bias: Vector3::new(0.0, 0.02, 0.0),
            };
            let cov = Some(Matrix3::identity() * 0.01);
            let est = Estimate {
                t_ns,
                position: position + Vector3::new(0.05, -0.05, 0.02),
                attitude: So3::exp(&Vector3::new(0.0, 0.0, a + 0.01)),
                velocity: truth.velocity,
                gyro_bias: Vector3::zeros(),
                accel_bias: Vector3::zeros(),
                cov: if with_position {
                    [cov, cov, cov, cov, cov]
                } else {
                    [cov, None, None, cov, cov]
                },
                valid: None,
            };
            s.add(&est, &truth);
            let nis = match k % 40 {
                0 => 500.0,
                1 => f64::INFINITY,
                2 => f64::NAN,
                _ => (k % 7) as f64,
            };
            let outcome = if nis > 20.0 {
                Outcome::Rejected { nis, dof: 3 }
            } else {
                Outcome::Accepted { nis, dof: 3 }
            };
            s.measurement("gnss_position", t_ns, outcome);
        }
        s
    }

    #[test]
    fn lines_break_at_gaps_of_more_than_five_median_intervals() {
        assert!(split_at_gaps(&[]).is_empty());
        assert_eq!(split_at_gaps(&[3.0]), vec![0..1]);
        // Equal times: no interval to judge by, one piece.
        assert_eq!(split_at_gaps(&[1.0, 1.0, 1.0]), vec![0..3]);
        // 0.1 s steps with a 10 s hole after the fourth point.
        let t = [0.0, 0.1, 0.2, 0.3, 10.3, 10.4, 10.5];
        assert_eq!(split_at_gaps(&t), vec![0..4, 4..7]);
        // Five intervals exactly is not a gap; a little more is, and jitter is not.
        assert_eq!(split_at_gaps(&[0.0, 1.0, 2.0, 7.0, 8.0]), vec![0..5]);
        assert_eq!(split_at_gaps(&[0.0, 1.0, 2.0, 7.01, 8.0]), vec![0..3, 3..5]);
        let jitter: Vec<f64> = (0..100)
            .map(|k| f64::from(k) * 0.01 + if k % 2 == 0 { 0.004 } else { 0.0 })
            .collect();
        assert_eq!(split_at_gaps(&jitter), vec![0..100]);
        // Several gaps, one at each end.
        let t = [0.0, 5.0, 5.1, 5.2, 5.3, 9.0, 9.1, 9.2, 20.0];
        assert_eq!(split_at_gaps(&t), vec![0..1, 1..5, 5..8, 8..9]);
    }

    /// A "not valid" span stops at a time gap and starts again after it.
    #[test]
    fn not_valid_spans_stop_at_gaps() {
        let point = |t: f64, valid: bool| HistoryPoint {
            t,
            est_position: Vector3::zeros(),
            true_position: Vector3::zeros(),
            error: [0.0; 15],
            sigma: [0.0; 15],
            est_bias: [0.0; 6],
            true_bias: [0.0; 6],
            valid: Some([valid; 5]),
        };
        // Not valid from 0.2 s, through a 10 s hole after 0.3 s, valid again at 10.5 s.
        let pts: Vec<HistoryPoint> = [0.0, 0.1, 0.2, 0.3, 10.3, 10.4, 10.5]
            .iter()
            .map(|&t| point(t, !(0.15..=10.45).contains(&t)))
            .collect();
        assert_eq!(invalid_spans(&pts, 0), vec![(0.2, 0.3), (10.3, 10.5)]);
    }

    /// The gated-out updates the legend lists are drawn: hollow squares of their colour, in
    /// the plotting area (not markers of no size).
    #[test]
    fn gated_out_nis_points_are_drawn_as_hollow_squares() {
        if !font_ready() {
            eprintln!("no font: the plots are skipped, nothing to check");
            return;
        }
        let count = |gated: bool| {
            let mut stats = SensorStats::default();
            for k in 0..100_u32 {
                let t = f64::from(k) * 0.1;
                stats
                    .history
                    .push((t, f64::from(k % 5), 3, !(gated && k % 25 == 7)));
            }
            let (w, h) = (1400_u32, 300_u32);
            let mut buf = vec![0_u8; (w * h * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
                root.fill(&WHITE).expect("fill");
                let (plot, legend) = root.split_horizontally(w - NIS_LEGEND_W);
                nis_panel(&plot, &legend, "gnss_position", &stats, 10.0).expect("panel");
                root.present().expect("present");
            }
            // Pixels of the gated colour in the plotting area, left of the legend.
            buf.chunks(3)
                .enumerate()
                .filter(|(i, px)| {
                    (*i as u32 % w) < w - NIS_LEGEND_W && px == &[GATED.0, GATED.1, GATED.2]
                })
                .count()
        };
        assert_eq!(count(false), 0);
        let drawn = count(true);
        // Four squares of 10 px a side, 2 px wide: about 70 px each.
        assert!(drawn >= 4 * 40, "{drawn} px of gated-out markers");
    }

    #[test]
    fn the_plots_are_written() {
        if !font_ready() {
            eprintln!("no font: the plots are skipped, nothing to check");
            return;
        }
        let dir = std::env::temp_dir().join(format!("host-sim-plot-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp folder");
        let written = write_all(&dir, &scorer(true), "test").expect("plots");
        assert_eq!(written.len(), FILES.len());
        for f in FILES {
            let len = std::fs::metadata(dir.join(f)).map_or(0, |m| m.len());
            assert!(len > 0, "{f} missing or empty");
        }
        // Without a position there is no trajectory.
        std::fs::remove_file(dir.join("trajectory.png")).expect("remove");
        let written = write_all(&dir, &scorer(false), "test").expect("plots");
        assert_eq!(written.len(), FILES.len() - 1);
        assert!(!dir.join("trajectory.png").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}

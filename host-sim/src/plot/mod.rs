//! The PNG plots a person looks at after a run: trajectory top view against truth, per-axis
//! errors inside their ±3σ bands, bias estimates against truth, and NIS per sensor against its
//! chi-square bounds.
//!
//! Text needs a TrueType font: DejaVu Sans from the system (Debian's `fonts-dejavu-core`), Arial on
//! macOS and Windows, or the file named by `HOST_SIM_FONT`. Without one the plots are skipped with a warning.

use crate::metrics::{HistoryPoint, Scorer, BLOCKS};
use crate::stats::chi2_quantile;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The plot files a run may write.
pub const FILES: [&str; 4] = ["trajectory.png", "errors.png", "biases.png", "nis.png"];

type PlotResult = Result<(), Box<dyn std::error::Error>>;

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
    errors(&f, pts, title)?;
    written.push(f);
    let f = dir.join("biases.png");
    biases(&f, pts, title)?;
    written.push(f);
    if !scorer.sensors.is_empty() {
        let f = dir.join("nis.png");
        nis(&f, scorer, title)?;
        written.push(f);
    }
    Ok(written)
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

fn trajectory(path: &Path, pts: &[HistoryPoint], title: &str) -> PlotResult {
    let root = BitMapBackend::new(path, (900, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let xs = pts
        .iter()
        .flat_map(|p| [p.est_position.x, p.true_position.x]);
    let ys = pts
        .iter()
        .flat_map(|p| [p.est_position.y, p.true_position.y]);
    let ((x0, x1), (y0, y1)) = (range(xs), range(ys));
    // Equal scale on both axes.
    let span = (x1 - x0).max(y1 - y0);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{title}: trajectory, top view"), ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(
            cx - span / 2.0..cx + span / 2.0,
            cy - span / 2.0..cy + span / 2.0,
        )?;
    chart
        .configure_mesh()
        .x_desc("east x [m]")
        .y_desc("north y [m]")
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            pts.iter().map(|p| (p.true_position.x, p.true_position.y)),
            BLACK.stroke_width(2),
        ))?
        .label("truth")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(
            pts.iter().map(|p| (p.est_position.x, p.est_position.y)),
            RED,
        ))?
        .label("estimate")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

fn errors(path: &Path, pts: &[HistoryPoint], title: &str) -> PlotResult {
    let blocks: Vec<usize> = (0..5)
        .filter(|b| pts.iter().any(|p| p.sigma[3 * b].is_finite()))
        .collect();
    let root = BitMapBackend::new(path, (1500, 260 * blocks.len() as u32 + 60)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: errors (red) inside ±3σ (grey)"),
        ("sans-serif", 24),
    )?;
    let cells = body.split_evenly((blocks.len(), 3));
    let units = ["deg", "m/s", "m", "deg/s", "m/s²"];
    let scale = [57.295_779_5, 1.0, 1.0, 57.295_779_5, 1.0];
    let t1 = pts.last().map_or(1.0, |p| p.t.max(1e-3));
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
                .fold(1e-6_f64, |a, (v, _)| a.max(v));
            let mut chart = ChartBuilder::on(cell)
                .caption(
                    format!("{} {}", BLOCKS[b], ["x", "y", "z"][axis]),
                    ("sans-serif", 16),
                )
                .margin(6)
                .x_label_area_size(28)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t1, -lim * 1.1..lim * 1.1)?;
            chart
                .configure_mesh()
                .x_desc("t [s]")
                .y_desc(units[b])
                .label_style(("sans-serif", 12))
                .draw()?;
            let upper: Vec<(f64, f64)> = pts
                .iter()
                .map(|p| (p.t, (3.0 * p.sigma[i] * k).min(lim * 1.1)))
                .collect();
            let mut band = upper.clone();
            band.extend(upper.iter().rev().map(|(t, v)| (*t, -v)));
            chart.draw_series(std::iter::once(Polygon::new(
                band,
                BLACK.mix(0.15).filled(),
            )))?;
            chart.draw_series(LineSeries::new(
                pts.iter().map(|p| (p.t, p.error[i] * k)),
                RED,
            ))?;
        }
    }
    root.present()?;
    Ok(())
}

fn biases(path: &Path, pts: &[HistoryPoint], title: &str) -> PlotResult {
    let root = BitMapBackend::new(path, (1500, 620)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: bias estimates (red) against truth (black)"),
        ("sans-serif", 24),
    )?;
    let cells = body.split_evenly((2, 3));
    let t1 = pts.last().map_or(1.0, |p| p.t.max(1e-3));
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
        chart.draw_series(LineSeries::new(
            pts.iter().map(|p| (p.t, p.true_bias[i] * k)),
            BLACK.stroke_width(2),
        ))?;
        chart.draw_series(LineSeries::new(
            pts.iter().map(|p| (p.t, p.est_bias[i] * k)),
            RED,
        ))?;
    }
    root.present()?;
    Ok(())
}

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
        BitMapBackend::new(path, (1200, 280 * sensors.len() as u32 + 60)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(50);
    top.titled(
        &format!("{title}: NIS per update, with its 95 % chi-square interval"),
        ("sans-serif", 24),
    )?;
    let cells = body.split_evenly((sensors.len(), 1));
    for ((name, stats), cell) in sensors.iter().zip(cells.iter()) {
        let h = stats.history.points();
        let dof = h.first().map_or(1, |p| p.2).max(1);
        let (lo, hi) = (
            chi2_quantile(0.025, dof as f64),
            chi2_quantile(0.975, dof as f64),
        );
        let t1 = h.last().map_or(1.0, |p| p.0.max(1e-3));
        let ymax = h
            .iter()
            .map(|p| p.1)
            .filter(|v| v.is_finite())
            .fold(hi * 1.5, f64::max)
            .min(hi * 6.0);
        let mut chart = ChartBuilder::on(cell)
            .caption(
                format!(
                    "{name} (dof {dof}): mean {:.2}, accepted {}, rejected {}",
                    stats.nis_mean(),
                    stats.accepted,
                    stats.rejected
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
        chart.draw_series(
            h.iter()
                .map(|p| Circle::new((p.0, p.1.min(ymax)), 2, BLUE.filled())),
        )?;
        for (v, style) in [(lo, BLACK), (hi, BLACK), (dof as f64, GREEN)] {
            chart.draw_series(LineSeries::new([(0.0, v), (t1, v)], style.stroke_width(2)))?;
        }
    }
    root.present()?;
    Ok(())
}

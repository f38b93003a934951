//! A dataset whose `gnss0/data.csv` speaks latitude and longitude replays like the same
//! dataset in local ENU metres.
//!
//! A simulated dataset (ENU) is copied with its GNSS rows converted to WGS-84 geodetic
//! coordinates by the inverse of the reader's conversion, at a known origin, and printed to
//! 10⁻¹²° and 1 µm. The reader maps them back to ENU with an error `ε` per fix (measured here
//! from the printed rows: about 10⁻⁷ m). The replay is a function of the fixes whose position
//! moves with a fix by at most its Kalman gain, and over a run by the sum of those gains'
//! magnitudes over the fixes; a common shift of every fix shifts the estimate by exactly that
//! shift (the position is seen only through the fixes), so that sum is 1 for a filter whose
//! weights are all positive, and a few where its velocity makes some negative. The bound used,
//! `10 ε` plus the 10⁻⁶ m to which `estimate.tum` is printed, leaves room for that.
//!
//! With `origin` in `gnss0/sensor.yaml` the world frames are the same. Without it the reader
//! takes the first fix for the origin (and says so on stderr): the ENU frame there is the
//! first one moved by the first fix and turned by `θ ≈ |p₁| / b` (the tangent planes of two
//! points `|p₁|` apart), so the estimate is the ENU one mapped by the geodesy into the new frame,
//! up to what the turn `θ` does to the rest of the run (gravity and the IMU are in a frame
//! turned by `θ` against the fixes: at most `θ` times the distance travelled).

use host_sim::bench::replay_config;
use host_sim::dataset::geodesy::{Geodetic, LocalEnu, WGS84_B};
use host_sim::dataset::read::GEODETIC_HEADER;
use host_sim::dataset::write::simulate;
use host_sim::replay::replay;
use host_sim::scenario::Scenario;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{copy_dir, empty_dir};

fn tmp(name: &str) -> PathBuf {
    empty_dir("geodetic", name)
}

/// Zürich, 408 m above the ellipsoid.
const ORIGIN: Geodetic = Geodetic {
    lat_deg: 47.376_887,
    lon_deg: 8.541_694,
    height_m: 408.0,
};

/// A 40 s car run with a magnetometer, a lever arm and a latency, simulated into `dir/enu`.
fn enu_dataset(dir: &Path) -> (PathBuf, Scenario) {
    let file = dir.join("geo.toml");
    std::fs::write(
        &file,
        "name = \"geo\"\nduration_s = 40.0\nstatic_s = 4.0\nshape = \"car\"\n[mag]\n[gnss]\nlatency_s = 0.1\nlever_arm = [0.3, 0.0, 0.2]\n",
    )
    .expect("scenario");
    let sc = Scenario::load(file.to_str().expect("utf-8")).expect("scenario loads");
    let enu = dir.join("enu");
    simulate(&sc, 11, &enu).expect("simulate");
    (enu, sc)
}

/// Copies the ENU dataset `enu` to `to` with its fixes in the geodetic form at `ORIGIN`
/// (`with_origin`: `origin` in `sensor.yaml`). Returns the largest distance between a fix of
/// `enu` and the one the reader makes of its printed geodetic row, m (`ε`).
fn geodetic_copy(enu: &Path, to: &Path, sc: &Scenario, with_origin: bool) -> f64 {
    copy_dir(enu, to);
    let gnss = sc.gnss.as_ref().expect("gnss");
    let frame = LocalEnu::new(ORIGIN);
    let text = std::fs::read_to_string(enu.join("gnss0/data.csv")).expect("gnss rows");
    let mut out = format!("{GEODETIC_HEADER}\n");
    let mut eps: f64 = 0.0;
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|f| f.parse().expect("number"))
            .collect();
        let p = Vector3::new(v[1], v[2], v[3]);
        let vel = Vector3::new(v[4], v[5], v[6]);
        let g = frame.to_geodetic(&p);
        // The velocity as a receiver gives it: east-north-up where it is.
        let v_here = frame.vector_from_enu(&g, &vel);
        let row = format!("{:.12},{:.12},{:.6}", g.lat_deg, g.lon_deg, g.height_m);
        let back: Vec<f64> = row.split(',').map(|f| f.parse().expect("number")).collect();
        let printed = Geodetic::new(back[0], back[1], back[2]);
        eps = eps.max((frame.to_enu(&printed) - p).norm());
        out += &format!(
            "{},{row},{:.9},{:.9},{:.9},{},{},{}\n",
            line.split(',').next().expect("timestamp"),
            v_here.x,
            v_here.y,
            v_here.z,
            gnss.sigma_horizontal,
            gnss.sigma_vertical,
            v[8]
        );
    }
    std::fs::write(to.join("gnss0/data.csv"), out).expect("write");
    let mut yaml = std::fs::read_to_string(enu.join("gnss0/sensor.yaml")).expect("yaml");
    if with_origin {
        yaml += &format!(
            "origin: [{}, {}, {}]\n",
            ORIGIN.lat_deg, ORIGIN.lon_deg, ORIGIN.height_m
        );
    }
    std::fs::write(to.join("gnss0/sensor.yaml"), yaml).expect("write");
    eps
}

/// `(t, position)` of every line of `estimate.tum`.
fn tum(out: &Path) -> Vec<(String, Vector3<f64>)> {
    std::fs::read_to_string(out.join("estimate.tum"))
        .expect("estimate.tum")
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let x = |i: usize| f[i].parse::<f64>().expect("number");
            (f[0].to_string(), Vector3::new(x(1), x(2), x(3)))
        })
        .collect()
}

/// The largest distance between matching lines of two trajectories (same timestamps).
fn largest_gap(
    a: &[(String, Vector3<f64>)],
    b: &[(String, Vector3<f64>)],
    map: impl Fn(&Vector3<f64>) -> Vector3<f64>,
) -> f64 {
    assert_eq!(a.len(), b.len(), "same number of estimates");
    assert!(a.len() > 1000);
    a.iter()
        .zip(b)
        .map(|((ta, pa), (tb, pb))| {
            assert_eq!(ta, tb);
            (map(pa) - pb).norm()
        })
        .fold(0.0, f64::max)
}

/// `estimate.tum` is printed to 1 µm per axis: two of them differ by up to √3 µm from that.
const TUM_ROUNDING: f64 = 1.8e-6;

#[test]
fn a_geodetic_dataset_with_its_origin_replays_like_the_enu_one() {
    let dir = tmp("with-origin");
    let (enu, sc) = enu_dataset(&dir);
    let geo = dir.join("geo");
    let eps = geodetic_copy(&enu, &geo, &sc, true);
    assert!(eps < 1e-6, "conversion error {eps} m");
    let mut cfg = replay_config(None, &enu).expect("replay.toml");
    cfg.precision = "f64".into();
    cfg.plots = false;
    let m_enu = replay(&enu, &dir.join("out-enu"), &cfg, "enu").expect("ENU replay");
    let m_geo = replay(&geo, &dir.join("out-geo"), &cfg, "geodetic").expect("geodetic replay");
    let bound = 10.0 * eps + TUM_ROUNDING;
    let gap = largest_gap(
        &tum(&dir.join("out-enu")),
        &tum(&dir.join("out-geo")),
        |p| *p,
    );
    assert!(
        gap <= bound,
        "estimates differ by {gap} m (bound {bound} m)"
    );
    assert!(
        (m_enu.ate_position_rmse_m - m_geo.ate_position_rmse_m).abs() <= bound,
        "ATE {} vs {}",
        m_enu.ate_position_rmse_m,
        m_geo.ate_position_rmse_m
    );
    assert_eq!(m_enu.updates_accepted, m_geo.updates_accepted);
    assert_eq!(m_enu.updates_rejected, m_geo.updates_rejected);
    assert!(
        m_enu
            .updates_accepted
            .get("gnss_position")
            .copied()
            .unwrap_or(0)
            > 150
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn without_an_origin_the_first_fix_is_the_origin_and_a_note_says_so() {
    let dir = tmp("first-fix");
    let (enu, sc) = enu_dataset(&dir);
    let geo = dir.join("geo");
    let eps = geodetic_copy(&enu, &geo, &sc, false);
    std::fs::write(dir.join("f64.toml"), "precision = \"f64\"\nplots = false\n").expect("cfg");
    let run = |ds: &Path, out: &Path| {
        let o = Command::new(env!("CARGO_BIN_EXE_host-sim"))
            .args([
                "replay",
                ds.to_str().expect("utf-8"),
                "--out",
                out.to_str().expect("utf-8"),
                "--config",
                dir.join("f64.toml").to_str().expect("utf-8"),
            ])
            .output()
            .expect("host-sim runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let stderr_enu = run(&enu, &dir.join("out-enu"));
    assert!(!stderr_enu.contains("first fix"), "{stderr_enu}");
    let stderr = run(&geo, &dir.join("out-geo"));
    assert!(
        stderr.contains("note:") && stderr.contains("first fix"),
        "{stderr}"
    );

    // The first fix's position in the ENU dataset, and the two frames.
    let first = std::fs::read_to_string(enu.join("gnss0/data.csv")).expect("rows");
    let v: Vec<f64> = first
        .lines()
        .nth(1)
        .expect("a fix")
        .split(',')
        .map(|f| f.parse().expect("number"))
        .collect();
    let p1 = Vector3::new(v[1], v[2], v[3]);
    let frame0 = LocalEnu::new(ORIGIN);
    let frame1 = LocalEnu::new(frame0.to_geodetic(&p1));
    // The frames are turned by θ ≈ |p₁| / b against each other.
    let theta = p1.norm() / WGS84_B;
    let a = tum(&dir.join("out-enu"));
    let travelled = a.iter().map(|(_, p)| p.norm()).fold(0.0, f64::max);
    let bound = 10.0 * eps + TUM_ROUNDING + 10.0 * theta * (travelled + p1.norm());
    let gap = largest_gap(&a, &tum(&dir.join("out-geo")), |p| {
        frame1.to_enu(&frame0.to_geodetic(p))
    });
    assert!(
        gap <= bound,
        "estimates differ by {gap} m (bound {bound} m; θ = {theta} rad over {travelled} m)"
    );
    // And the frames really differ: the estimate is not the ENU one unmapped.
    assert!(p1.norm() > 0.1);
    let _ = std::fs::remove_dir_all(dir);
}

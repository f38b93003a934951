//! Dataset folders in the EuRoC / ASL layout: writing a simulated one, and reading any one as a
//! time-ordered stream of sensor events with constant memory.
//!
//! Times are integer nanoseconds (64 bits; they may start anywhere, as EuRoC's near 1.4e18).
//!
//! | file | columns |
//! |---|---|
//! | `imu0/data.csv` | `#timestamp [ns]`, gyroscope `w_RS_S_x/y/z [rad s^-1]`, accelerometer `a_RS_S_x/y/z [m s^-2]` (body frame) |
//! | `imu0/sensor.yaml` | `rate_hz`, `gyroscope_noise_density`, `gyroscope_random_walk`, `accelerometer_noise_density`, `accelerometer_random_walk` (continuous time, Kalibr units) |
//! | `mag0/data.csv` | `#timestamp [ns]`, `m_x/y/z [uT]` (body frame) |
//! | `mag0/sensor.yaml` | `rate_hz`, `sigma` (white noise per sample and axis, µT), `reference_field` (`[x, y, z]`, world frame, µT) |
//! | `gnss0/data.csv`, ENU form | `#timestamp [ns]`, `p_x/y/z [m]`, `v_x/y/z [m s^-1]` (world frame), `sigma_p [m]`, `sigma_v [m s^-1]`, optionally a 10th column `sigma_p_up [m]` (then `sigma_p` is the horizontal 1σ and `sigma_p_up` the vertical) |
//! | `gnss0/data.csv`, geodetic form | told apart by a header naming `lat`: `#timestamp [ns]`, `lat [deg]`, `lon [deg]`, `h [m]` (WGS-84, height above the ellipsoid), `v_e/v_n/v_u [m s^-1]` (east-north-up at the fix; optional), `sigma_h [m]`, `sigma_v_up [m]`, `sigma_vel [m s^-1]` (with the velocity); columns found by name, in any order after the timestamp, others ignored ([`read::GeodeticColumns`]); converted to the world frame by [`geodesy`] |
//! | `gnss0/sensor.yaml` | optional: `lever_arm` (`[x, y, z]`, body frame, m; zero when absent), `latency_s` (s; 0 when absent), `rate_hz`; `origin: [lat, lon, h]` (the geodetic form's world-frame origin, degrees and m; the first fix when absent, with a note on stderr); `sigma_p_horizontal`, `sigma_p_up` (m: the 9-column ENU form's horizontal and vertical 1σ, replacing the rows' `sigma_p`) |
//! | `baro0/data.csv`, `baro0/sensor.yaml` | `#timestamp [ns]`, `altitude [m]`; `sigma` (m) |
//! | `cam0/sensor.yaml` | `intrinsics: [fu, fv, cu, cv]`, `resolution: [w, h]`, `T_BS` (body from camera, 4×4 row-major `data:` list as in EuRoC), `sigma_px` |
//! | `cam0/landmarks.csv` | `id`, `x/y/z [m]` (world frame) |
//! | `cam0/observations.csv` | `#timestamp [ns]`, `id`, `u [px]`, `v [px]` |
//! | `state_groundtruth_estimate0/data.csv` | EuRoC ground truth: timestamp, `p_RS_R` xyz, `q_RS` w x y z, `v_RS_R` xyz, `b_w_RS_S` xyz, `b_a_RS_S` xyz |
//!
//! Every sensor folder but `imu0` is optional; files and keys the layout does not name are
//! ignored.
//!
//! A real EuRoC sequence unpacks as `MH_01_easy/mav0/{imu0,cam0,cam1,leica0,
//! state_groundtruth_estimate0,body.yaml}`: given the folder that holds `mav0/` (and no `imu0/`
//! of its own), the dataset is `mav0/` ([`locate`]). Its `sensor.yaml` files are Kalibr's (the
//! keys above, `T_BS` as `{cols, rows, data}`, comments), read as they are. Its camera folders
//! hold images (`data.csv` of file names and `data/*.png`), not the landmark observations this
//! layout names: the reader leaves such a camera out, with a warning, and the replay runs on the
//! IMU alone. `leica0/`, `body.yaml` and other files are not read.
//!
//! Errors name the file and the line, in one line: `imu0/data.csv:17: expected 7 columns, got 6`.
//! What the reader survives is a warning, named the same way ([`check::DataWarning`]): a last
//! line cut short, gaps, sensors that start late or stop early, refused samples.

pub mod check;
pub mod geodesy;
pub mod read;
pub mod write;
pub mod yaml;

use std::path::{Path, PathBuf};

/// A dataset folder as found from the folder given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    /// The dataset folder (the one holding `imu0/`).
    pub dir: PathBuf,
    /// The folder given, when the dataset is its `mav0/` (EuRoC's layout).
    pub root: Option<PathBuf>,
}

impl Located {
    /// A sentence for the summary when the dataset is a `mav0/` found inside the folder given.
    #[must_use]
    pub fn note(&self) -> Option<String> {
        self.root.as_ref().map(|root| {
            format!(
                "{} holds mav0/ (EuRoC layout): the dataset folder is {}",
                root.display(),
                self.dir.display()
            )
        })
    }
}

/// The dataset folder of `dir`: `dir/mav0` when `dir` has no `imu0/` but a `mav0/` folder (a
/// EuRoC sequence unpacked), else `dir` itself.
#[must_use]
pub fn locate(dir: &Path) -> Located {
    let mav0 = dir.join("mav0");
    if !dir.join("imu0").is_dir() && mav0.is_dir() {
        Located {
            dir: mav0,
            root: Some(dir.to_path_buf()),
        }
    } else {
        Located {
            dir: dir.to_path_buf(),
            root: None,
        }
    }
}

/// An error reading or writing a dataset: where, and what.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// A problem at a line of a file.
    #[error("{}:{line}: {message}", path.display())]
    At {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A problem with a whole file (missing, unreadable).
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl DatasetError {
    pub(crate) fn at(path: &Path, line: u64, message: impl Into<String>) -> Self {
        Self::At {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn file(path: &Path, message: impl std::fmt::Display) -> Self {
        Self::File {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}

//! Reading a dataset folder as one time-ordered stream of sensor events, holding one row of
//! look-ahead per file (memory does not grow with the run).

use super::check::{DataCheck, DataWarning, Sensor};
use super::geodesy::{Geodetic, LocalEnu};
use super::yaml::SensorYaml;
use super::DatasetError;
use estimator_core::lie::{LieGroup, Se3, So3};
use nalgebra::{Matrix4, Vector2, Vector3};
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// IMU noise parameters from `imu0/sensor.yaml` (continuous time, Kalibr units).
#[derive(Clone, Debug, PartialEq)]
pub struct ImuParams {
    /// Rate, Hz.
    pub rate_hz: f64,
    /// rad/s/√Hz.
    pub gyroscope_noise_density: f64,
    /// rad/s²/√Hz.
    pub gyroscope_random_walk: f64,
    /// m/s²/√Hz.
    pub accelerometer_noise_density: f64,
    /// m/s³/√Hz.
    pub accelerometer_random_walk: f64,
}

/// Magnetometer parameters from `mag0/sensor.yaml`.
#[derive(Clone, Debug, PartialEq)]
pub struct MagParams {
    /// Rate, Hz.
    pub rate_hz: f64,
    /// White noise per sample and axis, µT.
    pub sigma: f64,
    /// World-frame reference field, µT.
    pub reference_field: Vector3<f64>,
}

/// GNSS parameters from `gnss0/sensor.yaml` (optional file: defaults to no lever arm) and the
/// form of `gnss0/data.csv`, told by its header.
#[derive(Clone, Debug, PartialEq)]
pub struct GnssParams {
    /// Antenna lever arm in the body frame, m.
    pub lever_arm: Vector3<f64>,
    /// The fix was valid this long before its row's timestamp, s (`latency_s`; 0 when absent).
    pub latency_s: f64,
    /// How `gnss0/data.csv` gives its fixes.
    pub format: GnssFormat,
    /// The geodetic form's world frame: ENU at `origin: [lat, lon, h]` of `sensor.yaml`, else
    /// at the first fix (`None` for the ENU form, or a file without fixes).
    pub frame: Option<LocalEnu>,
    /// The geodetic form's origin is the first fix (`sensor.yaml` has no `origin`).
    pub origin_from_first_fix: bool,
    /// The ENU form without a `sigma_p_up` column: `sensor.yaml`'s `sigma_p_horizontal`, m,
    /// which replaces the rows' `sigma_p` on east and north.
    pub sigma_p_horizontal: Option<f64>,
    /// The ENU form without a `sigma_p_up` column: `sensor.yaml`'s `sigma_p_up`, m, the
    /// vertical 1σ of every fix.
    pub sigma_p_up: Option<f64>,
}

/// The two forms of `gnss0/data.csv` (module docs of [`crate::dataset`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GnssFormat {
    /// Local ENU metres, 9 columns (`sigma_p` on every axis), or 10 with a trailing
    /// `sigma_p_up [m]` (`sigma_p` then horizontal only).
    Enu {
        /// The 10-column form.
        sigma_up_column: bool,
    },
    /// WGS-84 latitude, longitude and ellipsoidal height, the columns found by name.
    Geodetic(GeodeticColumns),
}

impl GnssFormat {
    /// The number of columns of a row, the timestamp included.
    #[must_use]
    pub fn columns(&self) -> usize {
        match self {
            Self::Enu { sigma_up_column } => 9 + usize::from(*sigma_up_column),
            Self::Geodetic(c) => c.columns,
        }
    }
}

/// Where the geodetic form's values are: indices into a row's values after the timestamp
/// (column `k + 1` of the file is value `k`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeodeticColumns {
    /// Columns of a row, the timestamp included.
    pub columns: usize,
    /// `lat [deg]`.
    pub lat: usize,
    /// `lon [deg]`.
    pub lon: usize,
    /// `h [m]`, above the ellipsoid.
    pub height: usize,
    /// `v_e`, `v_n`, `v_u [m s^-1]`, east-north-up at the fix, when given.
    pub velocity: Option<[usize; 3]>,
    /// `sigma_h [m]`.
    pub sigma_h: usize,
    /// `sigma_v_up [m]`.
    pub sigma_up: usize,
    /// `sigma_vel [m s^-1]`, with the velocity.
    pub sigma_vel: Option<usize>,
}

/// A header cell's name: lower case, without a leading `#` and without its `[unit]`.
fn column_name(cell: &str) -> String {
    let cell = cell.trim().trim_start_matches('#');
    let name = cell.split('[').next().unwrap_or(cell);
    name.trim().to_ascii_lowercase()
}

/// The names a geodetic header may give each quantity (the first is the one written).
const LAT_NAMES: [&str; 2] = ["lat", "latitude"];
const LON_NAMES: [&str; 2] = ["lon", "longitude"];
const HEIGHT_NAMES: [&str; 3] = ["h", "height", "ellipsoidal_height"];
const VE_NAMES: [&str; 2] = ["v_e", "v_east"];
const VN_NAMES: [&str; 2] = ["v_n", "v_north"];
const VU_NAMES: [&str; 2] = ["v_u", "v_up"];
const SIGMA_H_NAMES: [&str; 2] = ["sigma_h", "sigma_horizontal"];
const SIGMA_UP_NAMES: [&str; 4] = ["sigma_v_up", "sigma_p_up", "sigma_up", "sigma_vertical"];
const SIGMA_VEL_NAMES: [&str; 2] = ["sigma_vel", "sigma_velocity"];

impl GeodeticColumns {
    /// The columns of a geodetic header (`names` from [`column_name`], the timestamp first);
    /// other names are ignored.
    fn from_header(path: &Path, names: &[String]) -> Result<Self, DatasetError> {
        let err = |m: String| DatasetError::at(path, 1, m);
        let find = |aliases: &[&str]| -> Result<Option<usize>, DatasetError> {
            let mut found = None;
            for (i, n) in names.iter().enumerate().skip(1) {
                if aliases.contains(&n.as_str()) {
                    if found.is_some() {
                        return Err(err(format!("geodetic header names '{}' twice", aliases[0])));
                    }
                    found = Some(i - 1);
                }
            }
            Ok(found)
        };
        if names.iter().skip(1).any(|n| n == "sigma_v") {
            return Err(err(
                "'sigma_v' is ambiguous in the geodetic form: name the vertical position 1σ \
                 'sigma_v_up [m]' and the velocity 1σ 'sigma_vel [m s^-1]'"
                    .into(),
            ));
        }
        let required = |aliases: &[&str]| -> Result<usize, DatasetError> {
            find(aliases)?.ok_or_else(|| {
                err(format!(
                    "geodetic header has no '{}' column (expected {GEODETIC_HEADER})",
                    aliases[0]
                ))
            })
        };
        let (lat, lon, height) = (
            required(&LAT_NAMES)?,
            required(&LON_NAMES)?,
            required(&HEIGHT_NAMES)?,
        );
        let (sigma_h, sigma_up) = (required(&SIGMA_H_NAMES)?, required(&SIGMA_UP_NAMES)?);
        let velocity = match (find(&VE_NAMES)?, find(&VN_NAMES)?, find(&VU_NAMES)?) {
            (Some(e), Some(n), Some(u)) => Some([e, n, u]),
            (None, None, None) => None,
            _ => {
                return Err(err(
                    "geodetic header has some of v_e, v_n, v_u but not all three".into(),
                ))
            }
        };
        let sigma_vel = find(&SIGMA_VEL_NAMES)?;
        if velocity.is_some() && sigma_vel.is_none() {
            return Err(err(
                "geodetic header has a velocity but no 'sigma_vel [m s^-1]' column".into(),
            ));
        }
        Ok(Self {
            columns: names.len(),
            lat,
            lon,
            height,
            velocity,
            sigma_h,
            sigma_up,
            sigma_vel,
        })
    }
}

/// The header the simulator's geodetic form would write, and the error messages quote.
pub const GEODETIC_HEADER: &str = "#timestamp [ns],lat [deg],lon [deg],h [m],v_e [m s^-1],v_n [m s^-1],v_u [m s^-1],sigma_h [m],sigma_v_up [m],sigma_vel [m s^-1]";

/// The form of `gnss0/data.csv` from its first line: a header naming a latitude is the
/// geodetic form; otherwise the ENU form, with the 10th column `sigma_p_up` when the header
/// (or, without a header, the first row) has ten.
fn gnss_format(path: &Path) -> Result<GnssFormat, DatasetError> {
    let file = File::open(path).map_err(|e| DatasetError::file(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(file);
    let mut record = csv::StringRecord::new();
    loop {
        let more = reader.read_record(&mut record).map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            DatasetError::at(path, line, e.to_string())
        })?;
        if !more {
            return Ok(GnssFormat::Enu {
                sigma_up_column: false,
            });
        }
        if !(record.len() <= 1 && record.get(0).unwrap_or("").is_empty()) {
            break;
        }
    }
    let line = record.position().map_or(0, |p| p.line());
    let first = record.get(0).unwrap_or("");
    let header = line == 1 && (first.starts_with('#') || first.parse::<u64>().is_err());
    if !header {
        return Ok(GnssFormat::Enu {
            sigma_up_column: record.len() == 10,
        });
    }
    let names: Vec<String> = record.iter().map(column_name).collect();
    if names.iter().any(|n| LAT_NAMES.contains(&n.as_str())) {
        return GeodeticColumns::from_header(path, &names).map(GnssFormat::Geodetic);
    }
    if names.len() == 10 {
        let last = names.get(9).map_or("", String::as_str);
        if !SIGMA_UP_NAMES.contains(&last) {
            return Err(DatasetError::at(
                path,
                1,
                format!("column 10 '{last}' of the ENU form must be 'sigma_p_up [m]'"),
            ));
        }
    }
    Ok(GnssFormat::Enu {
        sigma_up_column: names.len() == 10,
    })
}

/// Camera parameters from `cam0/sensor.yaml` and the landmark map from `cam0/landmarks.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraParams {
    /// `[fu, fv, cu, cv]`.
    pub intrinsics: [f64; 4],
    /// Body-from-camera.
    pub body_from_camera: Se3<f64>,
    /// Pixel noise, px.
    pub sigma_px: f64,
    /// Landmarks by id, world frame.
    pub landmarks: HashMap<u64, Vector3<f64>>,
}

/// Barometer parameters from `baro0/sensor.yaml`.
#[derive(Clone, Debug, PartialEq)]
pub struct BaroParams {
    /// White noise per sample, m.
    pub sigma: f64,
}

/// What a dataset folder holds.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// The folder.
    pub dir: PathBuf,
    /// IMU parameters.
    pub imu: ImuParams,
    /// Magnetometer, if present.
    pub mag: Option<MagParams>,
    /// GNSS, if present.
    pub gnss: Option<GnssParams>,
    /// Camera, if present.
    pub camera: Option<CameraParams>,
    /// Barometer, if present.
    pub baro: Option<BaroParams>,
    /// Whether ground truth is present.
    pub has_groundtruth: bool,
    /// What the reader decided for the user to know, not a problem (the replay prints them on
    /// stderr): the geodetic form's origin taken from the first fix.
    pub notes: Vec<String>,
    /// The scored intervals of `movement.csv` (`[start, end]` ns, inclusive), if present.
    pub movement: Option<Vec<(u64, u64)>>,
    /// What a missing optional file made the reader assume (printed in the summary).
    pub warnings: Vec<String>,
    /// What the files read on opening (`cam0/landmarks.csv`, `movement.csv`) had wrong that
    /// was survived (a cut last line).
    pub data_warnings: Vec<DataWarning>,
}

/// One sensor event.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// An IMU sample.
    Imu {
        /// ns.
        t_ns: u64,
        /// rad/s.
        gyro: Vector3<f64>,
        /// m/s².
        accel: Vector3<f64>,
    },
    /// A magnetometer sample, µT.
    Mag {
        /// ns.
        t_ns: u64,
        /// µT, body frame.
        field: Vector3<f64>,
    },
    /// A GNSS fix (the geodetic form converted to the world frame).
    Gnss {
        /// ns.
        t_ns: u64,
        /// m, world (ENU).
        position: Vector3<f64>,
        /// m/s, world (ENU), when the receiver gives one.
        velocity: Option<Vector3<f64>>,
        /// Horizontal (east, north) position 1σ, m.
        sigma_p: f64,
        /// Vertical (up) position 1σ, m (`sigma_p` where the file gives one σ).
        sigma_p_up: f64,
        /// Velocity 1σ, m/s (0 without a velocity).
        sigma_v: f64,
    },
    /// The observations of one camera frame.
    Camera {
        /// ns.
        t_ns: u64,
        /// `(landmark id, pixel)`.
        observations: Vec<(u64, Vector2<f64>)>,
    },
    /// A barometric altitude, m.
    Baro {
        /// ns.
        t_ns: u64,
        /// m.
        altitude: f64,
    },
}

impl Event {
    /// The event's timestamp, ns.
    #[must_use]
    pub fn t_ns(&self) -> u64 {
        match self {
            Event::Imu { t_ns, .. }
            | Event::Mag { t_ns, .. }
            | Event::Gnss { t_ns, .. }
            | Event::Camera { t_ns, .. }
            | Event::Baro { t_ns, .. } => *t_ns,
        }
    }
}

/// A CSV file read row by row, with its header skipped and every row checked for its column
/// count, numbers and strictly (or, for camera frames, weakly) increasing timestamps.
///
/// A last line without its newline may have been cut short (a recording stopped while
/// writing): when it does not parse, it is skipped with a warning rather than refused; when it
/// parses, it is used, with a warning. Any other malformed line is an error.
pub struct Rows {
    path: PathBuf,
    reader: BufReader<File>,
    buf: Vec<u8>,
    line: u64,
    columns: usize,
    last_t: Option<u64>,
    allow_equal: bool,
    warnings: Vec<DataWarning>,
}

impl Rows {
    /// Opens `path`, expecting `columns` columns.
    pub fn open(path: &Path, columns: usize, allow_equal: bool) -> Result<Self, DatasetError> {
        let file = File::open(path).map_err(|e| DatasetError::file(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::new(file),
            buf: Vec::new(),
            line: 0,
            columns,
            last_t: None,
            allow_equal,
            warnings: Vec::new(),
        })
    }

    /// What was skipped or may be wrong so far (a cut last line).
    #[must_use]
    pub fn warnings(&self) -> &[DataWarning] {
        &self.warnings
    }

    /// The next data row as `(line, timestamp, values)`; `None` at the end.
    pub fn next_row(&mut self) -> Result<Option<(u64, u64, Vec<f64>)>, DatasetError> {
        loop {
            self.buf.clear();
            let n = self
                .reader
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| DatasetError::at(&self.path, self.line + 1, e.to_string()))?;
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            let line = self.line;
            // Only the last line can lack its newline.
            let cut = self.buf.last() != Some(&b'\n');
            match self.parse(line) {
                Ok(None) => {}
                Ok(Some((t, values))) => {
                    self.last_t = Some(t);
                    if cut {
                        self.warnings.push(DataWarning::new(
                            &self.path,
                            Some(line),
                            "the file ends inside this line (no newline): it may be cut short; it parses, so it is used",
                        ));
                    }
                    return Ok(Some((line, t, values)));
                }
                Err(message) if cut => {
                    self.warnings.push(DataWarning::new(
                        &self.path,
                        Some(line),
                        format!("the file ends inside this line (no newline) and it does not parse ({message}): taken as cut off and skipped"),
                    ));
                    return Ok(None);
                }
                Err(message) => return Err(DatasetError::at(&self.path, line, message)),
            }
        }
    }

    /// The row in the buffer: `None` for the header or a blank line, else its timestamp and
    /// values; what is wrong with it otherwise.
    fn parse(&self, line: u64) -> Result<Option<(u64, Vec<f64>)>, String> {
        let text = std::str::from_utf8(&self.buf).map_err(|_| "not UTF-8 text".to_string())?;
        // A byte-order mark some tools write first.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text).trim();
        if text.is_empty() {
            return Ok(None); // blank line
        }
        let mut fields = text.split(',').map(|f| {
            let f = f.trim();
            // A quoted field, as a CSV writer may quote it.
            f.strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .map_or(f, str::trim)
        });
        let first = fields.next().unwrap_or("");
        // The header: the first line, starting with '#' or not a number.
        if line == 1 && (first.starts_with('#') || first.parse::<u64>().is_err()) {
            return Ok(None);
        }
        let count = text.split(',').count();
        if count != self.columns {
            return Err(format!("expected {} columns, got {count}", self.columns));
        }
        let t: u64 = first
            .parse()
            .map_err(|_| format!("timestamp '{first}' is not an integer number of ns"))?;
        if let Some(last) = self.last_t {
            if t < last || (t == last && !self.allow_equal) {
                let what = if t == last {
                    "duplicated"
                } else {
                    "non-monotonic"
                };
                return Err(format!("{what} timestamp {t} (previous {last})"));
            }
        }
        let mut values = Vec::with_capacity(self.columns - 1);
        for (i, field) in fields.enumerate() {
            let column = i + 2;
            let v: f64 = field
                .parse()
                .map_err(|_| format!("column {column}: '{field}' is not a number"))?;
            if !v.is_finite() {
                return Err(format!("column {column}: '{field}' is not finite"));
            }
            values.push(v);
        }
        Ok(Some((t, values)))
    }
}

fn v3(v: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(v[i], v[i + 1], v[i + 2])
}

/// What turns a row of `gnss0/data.csv` into an [`Event::Gnss`].
#[derive(Clone, Debug)]
struct GnssDecode {
    format: GnssFormat,
    frame: Option<LocalEnu>,
    sigma_p_horizontal: Option<f64>,
    sigma_p_up: Option<f64>,
}

impl GnssDecode {
    fn new(p: &GnssParams) -> Self {
        Self {
            format: p.format.clone(),
            frame: p.frame,
            sigma_p_horizontal: p.sigma_p_horizontal,
            sigma_p_up: p.sigma_p_up,
        }
    }

    /// The event of the row `(line, t, values)` of `path` (values checked finite, one per
    /// column after the timestamp).
    fn event(&self, path: &Path, line: u64, t: u64, v: &[f64]) -> Result<Event, DatasetError> {
        match &self.format {
            GnssFormat::Enu { sigma_up_column } => {
                let (sigma_p, sigma_p_up) = if *sigma_up_column {
                    (v[6], v[8])
                } else {
                    (
                        self.sigma_p_horizontal.unwrap_or(v[6]),
                        self.sigma_p_up.unwrap_or(v[6]),
                    )
                };
                Ok(Event::Gnss {
                    t_ns: t,
                    position: v3(v, 0),
                    velocity: Some(v3(v, 3)),
                    sigma_p,
                    sigma_p_up,
                    sigma_v: v[7],
                })
            }
            GnssFormat::Geodetic(c) => {
                let g = Geodetic::new(v[c.lat], v[c.lon], v[c.height]);
                g.check().map_err(|m| DatasetError::at(path, line, m))?;
                let frame = self.frame.ok_or_else(|| {
                    DatasetError::at(path, line, "no origin for the geodetic fixes")
                })?;
                let velocity = c
                    .velocity
                    .map(|[e, n, u]| frame.vector_to_enu(&g, &Vector3::new(v[e], v[n], v[u])));
                Ok(Event::Gnss {
                    t_ns: t,
                    position: frame.to_enu(&g),
                    velocity,
                    sigma_p: v[c.sigma_h],
                    sigma_p_up: v[c.sigma_up],
                    sigma_v: c.sigma_vel.map_or(0.0, |i| v[i]),
                })
            }
        }
    }
}

/// The geodetic form's world frame: ENU at `origin` (from `sensor.yaml`), else at the first
/// fix of `data` (then `true`); `None` for a file without fixes.
fn geodetic_frame(
    data: &Path,
    columns: &GeodeticColumns,
    origin: Option<Geodetic>,
) -> Result<(Option<LocalEnu>, bool), DatasetError> {
    if let Some(o) = origin {
        return Ok((Some(LocalEnu::new(o)), false));
    }
    let mut rows = Rows::open(data, columns.columns, false)?;
    let Some((line, _, v)) = rows.next_row()? else {
        return Ok((None, false));
    };
    let first = Geodetic::new(v[columns.lat], v[columns.lon], v[columns.height]);
    first.check().map_err(|m| DatasetError::at(data, line, m))?;
    Ok((Some(LocalEnu::new(first)), true))
}

impl Dataset {
    /// Reads the folder's `sensor.yaml` files and the landmark map.
    pub fn open(dir: &Path) -> Result<Self, DatasetError> {
        Self::open_with_magnetometer(dir, true)
    }

    /// As [`Dataset::open`]; with `use_magnetometer` false, `mag0/` is not read at all, as if
    /// absent: `mag` is `None` and [`Dataset::events`] has no magnetometer samples (a replay's
    /// `use_magnetometer = false`).
    pub fn open_with_magnetometer(
        dir: &Path,
        use_magnetometer: bool,
    ) -> Result<Self, DatasetError> {
        let imu_yaml = dir.join("imu0/sensor.yaml");
        if !dir.join("imu0/data.csv").is_file() {
            return Err(DatasetError::file(
                &dir.join("imu0/data.csv"),
                "missing (every dataset needs imu0)",
            ));
        }
        let y = SensorYaml::read(&imu_yaml)?;
        let mut warnings = Vec::new();
        let mut data_warnings = Vec::new();
        // Kalibr's sensor.yaml gives the IMU's pose in the body frame; the filter's body is the
        // IMU, and the ground truth is taken to be of the IMU.
        if let Ok(t) = y.list("T_BS", 16) {
            let identity = |i: usize| if i.is_multiple_of(5) { 1.0 } else { 0.0 };
            if t.iter()
                .enumerate()
                .any(|(i, v)| (v - identity(i)).abs() > 1e-9)
            {
                warnings.push(format!(
                    "{}: T_BS is not the identity; the body frame is taken to be the IMU's (the ground truth must be of the IMU)",
                    imu_yaml.display()
                ));
            }
        }
        let imu = ImuParams {
            rate_hz: y.f64("rate_hz")?,
            gyroscope_noise_density: y.f64("gyroscope_noise_density")?,
            gyroscope_random_walk: y.f64("gyroscope_random_walk")?,
            accelerometer_noise_density: y.f64("accelerometer_noise_density")?,
            accelerometer_random_walk: y.f64("accelerometer_random_walk")?,
        };
        let mag = if use_magnetometer && dir.join("mag0/data.csv").is_file() {
            let y = SensorYaml::read(&dir.join("mag0/sensor.yaml"))?;
            let r = y.list("reference_field", 3)?;
            Some(MagParams {
                rate_hz: y.f64("rate_hz")?,
                sigma: y.f64("sigma")?,
                reference_field: Vector3::new(r[0], r[1], r[2]),
            })
        } else {
            None
        };
        let mut notes = Vec::new();
        let gnss = if dir.join("gnss0/data.csv").is_file() {
            let path = dir.join("gnss0/sensor.yaml");
            let data = dir.join("gnss0/data.csv");
            let format = gnss_format(&data)?;
            let mut latency_s = 0.0;
            let mut origin = None;
            let (mut sigma_p_horizontal, mut sigma_p_up) = (None, None);
            let lever_arm = if path.is_file() {
                let y = SensorYaml::read(&path)?;
                latency_s = y.f64_or("latency_s", 0.0)?;
                if !(latency_s.is_finite() && latency_s >= 0.0) {
                    return Err(DatasetError::file(
                        &path,
                        "latency_s must be a number of seconds, 0 or more",
                    ));
                }
                if y.has("origin") {
                    let o = y.list("origin", 3)?;
                    let g = Geodetic::new(o[0], o[1], o[2]);
                    g.check()
                        .map_err(|m| DatasetError::file(&path, format!("origin: {m}")))?;
                    origin = Some(g);
                }
                for (key, slot) in [
                    ("sigma_p_horizontal", &mut sigma_p_horizontal),
                    ("sigma_p_up", &mut sigma_p_up),
                ] {
                    if y.has(key) {
                        let s = y.f64(key)?;
                        if !(s.is_finite() && s > 0.0) {
                            return Err(DatasetError::file(
                                &path,
                                format!("{key} must be a positive number of metres"),
                            ));
                        }
                        *slot = Some(s);
                    }
                }
                match y.list("lever_arm", 3) {
                    Ok(l) => Vector3::new(l[0], l[1], l[2]),
                    Err(_) => {
                        warnings.push(format!(
                            "{} has no lever_arm: the antenna is taken to be at the IMU",
                            path.display()
                        ));
                        Vector3::zeros()
                    }
                }
            } else {
                warnings.push(format!(
                    "{} is missing: the antenna is taken to be at the IMU (no lever arm)",
                    path.display()
                ));
                Vector3::zeros()
            };
            let (frame, origin_from_first_fix) = match &format {
                GnssFormat::Geodetic(columns) => geodetic_frame(&data, columns, origin)?,
                GnssFormat::Enu { .. } => (None, false),
            };
            if let (Some(f), true) = (&frame, origin_from_first_fix) {
                let o = f.origin();
                notes.push(format!(
                    "{} has no origin: the world frame is east-north-up at the first fix, lat {:.9}°, lon {:.9}°, h {:.3} m",
                    path.display(),
                    o.lat_deg,
                    o.lon_deg,
                    o.height_m
                ));
            }
            Some(GnssParams {
                lever_arm,
                latency_s,
                format,
                frame,
                origin_from_first_fix,
                sigma_p_horizontal,
                sigma_p_up,
            })
        } else {
            None
        };
        let camera = if dir.join("cam0/observations.csv").is_file() {
            let ypath = dir.join("cam0/sensor.yaml");
            let y = SensorYaml::read(&ypath)?;
            let k = y.list("intrinsics", 4)?;
            let t = y.list("T_BS", 16)?;
            let body_from_camera = Se3::try_from_matrix(&Matrix4::from_row_slice(&t))
                .ok_or_else(|| DatasetError::file(&ypath, "T_BS is not a rigid motion"))?;
            let lpath = dir.join("cam0/landmarks.csv");
            let mut rows = Rows::open(&lpath, 4, false)?;
            let mut landmarks = HashMap::new();
            while let Some((line, id, v)) = rows.next_row()? {
                if landmarks.insert(id, v3(&v, 0)).is_some() {
                    return Err(DatasetError::at(
                        &lpath,
                        line,
                        format!("duplicated landmark id {id}"),
                    ));
                }
            }
            data_warnings.extend_from_slice(rows.warnings());
            Some(CameraParams {
                intrinsics: [k[0], k[1], k[2], k[3]],
                body_from_camera,
                sigma_px: y.f64_or("sigma_px", 1.0)?,
                landmarks,
            })
        } else {
            None
        };
        warnings.extend(unused_cameras(dir, camera.is_some()));
        let baro = if dir.join("baro0/data.csv").is_file() {
            let y = SensorYaml::read(&dir.join("baro0/sensor.yaml"))?;
            Some(BaroParams {
                sigma: y.f64("sigma")?,
            })
        } else {
            None
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            imu,
            mag,
            gnss,
            camera,
            baro,
            has_groundtruth: dir.join("state_groundtruth_estimate0/data.csv").is_file(),
            warnings,
            notes,
            movement: {
                let (m, w) = movement_checked(dir)?;
                data_warnings.extend(w);
                m
            },
            data_warnings,
        })
    }

    /// The merged, time-ordered event stream, its data checked for a navigator whose largest
    /// IMU step is 0.1 s ([`EventStream::with_max_dt`] sets another).
    pub fn events(&self) -> Result<EventStream, DatasetError> {
        let open = |rel: &str, cols: usize, eq: bool| -> Result<Option<Source>, DatasetError> {
            let p = self.dir.join(rel);
            if p.is_file() {
                Ok(Some(Source {
                    rows: Rows::open(&p, cols, eq)?,
                    ahead: None,
                }))
            } else {
                Ok(None)
            }
        };
        Ok(EventStream {
            imu: open("imu0/data.csv", 7, false)?,
            mag: if self.mag.is_some() {
                open("mag0/data.csv", 4, false)?
            } else {
                None
            },
            gnss: match &self.gnss {
                Some(g) => open("gnss0/data.csv", g.format.columns(), false)?,
                None => None,
            },
            gnss_decode: self.gnss.as_ref().map(GnssDecode::new),
            cam: if self.camera.is_some() {
                open("cam0/observations.csv", 4, true)?
            } else {
                None
            },
            baro: if self.baro.is_some() {
                open("baro0/data.csv", 2, false)?
            } else {
                None
            },
            dir: self.dir.clone(),
            check: DataCheck::new(0.1),
            last: None,
        })
    }
}

/// Warnings for the camera folders (`cam0`, `cam1`, …) the replay does not use: EuRoC's hold
/// images, not landmark observations; only `cam0` with `observations.csv` is read.
fn unused_cameras(dir: &Path, cam0_used: bool) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut names: Vec<String> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| {
            n.strip_prefix("cam")
                .is_some_and(|k| !k.is_empty() && k.chars().all(|c| c.is_ascii_digit()))
        })
        .collect();
    names.sort();
    names
        .into_iter()
        .filter(|n| !(n == "cam0" && cam0_used))
        .map(|n| {
            let why = if n == "cam0" {
                "has no observations.csv and landmarks.csv (EuRoC's images are not used)"
            } else {
                "is not used (only cam0 is read)"
            };
            format!(
                "{} {why}: the replay runs without this camera",
                dir.join(&n).display()
            )
        })
        .collect()
}

struct Source {
    rows: Rows,
    ahead: Option<(u64, u64, Vec<f64>)>,
}

impl Source {
    fn peek(&mut self) -> Result<Option<u64>, DatasetError> {
        if self.ahead.is_none() {
            self.ahead = self.rows.next_row()?;
        }
        Ok(self.ahead.as_ref().map(|(_, t, _)| *t))
    }
}

/// The row an event came from.
#[derive(Clone, Copy, Debug)]
struct Origin {
    sensor: Sensor,
    t_ns: u64,
    line: u64,
}

/// The merged stream: at equal timestamps the IMU comes first (the filter predicts to the
/// measurement time, then updates).
///
/// It records the timing of every file as it goes; [`EventStream::refused`] adds what the
/// navigator refused, and [`EventStream::finish`] turns both into warnings.
pub struct EventStream {
    imu: Option<Source>,
    mag: Option<Source>,
    gnss: Option<Source>,
    gnss_decode: Option<GnssDecode>,
    cam: Option<Source>,
    baro: Option<Source>,
    dir: PathBuf,
    check: DataCheck,
    last: Option<Origin>,
}

impl EventStream {
    /// This stream checked for a navigator whose largest IMU step is `max_dt_s` (an IMU
    /// interval above it is a gap).
    #[must_use]
    pub fn with_max_dt(mut self, max_dt_s: f64) -> Self {
        self.check = DataCheck::new(max_dt_s);
        self
    }

    /// Records that the navigator refused the event last returned, counted under `key` in
    /// `updates_refused`, for `reason`.
    pub fn refused(&mut self, key: &str, reason: &dyn std::fmt::Display) {
        if let Some(o) = self.last {
            self.check
                .refused(o.sensor, o.t_ns, o.line, key, &reason.to_string());
        }
    }

    /// Ends the stream: the warnings of its files (a cut last line) and of its data (gaps,
    /// sensors starting late or stopping early, refused samples, [`super::check`]), in file
    /// and line order; `imu_gap_effect` says what the navigator does after an IMU gap.
    ///
    /// # Errors
    /// No IMU sample at all: nothing to replay.
    pub fn finish(self, imu_gap_effect: &str) -> Result<Vec<DataWarning>, DatasetError> {
        let mut warnings: Vec<DataWarning> =
            [&self.imu, &self.mag, &self.gnss, &self.cam, &self.baro]
                .into_iter()
                .flatten()
                .flat_map(|s| s.rows.warnings().iter().cloned())
                .collect();
        if !self.check.has_imu() {
            let path = self.dir.join(Sensor::Imu.file());
            let cut = warnings
                .iter()
                .find(|w| w.file == path.display().to_string())
                .map_or_else(String::new, |w| {
                    format!(" (line {}: {})", w.line.unwrap_or(0), w.message)
                });
            return Err(DatasetError::file(
                &path,
                format!("no IMU sample: the file has no data row that parses{cut}"),
            ));
        }
        warnings.extend(self.check.warnings(&self.dir, imu_gap_effect));
        warnings.sort();
        Ok(warnings)
    }

    fn step(&mut self) -> Result<Option<(Event, Origin)>, DatasetError> {
        let mut best: Option<(u64, usize)> = None;
        for (i, src) in [
            &mut self.imu,
            &mut self.mag,
            &mut self.gnss,
            &mut self.cam,
            &mut self.baro,
        ]
        .into_iter()
        .enumerate()
        {
            if let Some(s) = src {
                if let Some(t) = s.peek()? {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, i));
                    }
                }
            }
        }
        let Some((_, which)) = best else {
            return Ok(None);
        };
        let take = |s: &mut Option<Source>| s.as_mut().and_then(|s| s.ahead.take());
        let origin = |sensor, line, t_ns| Origin { sensor, t_ns, line };
        let produced = match which {
            0 => take(&mut self.imu).map(|(line, t, v)| {
                let e = Event::Imu {
                    t_ns: t,
                    gyro: v3(&v, 0),
                    accel: v3(&v, 3),
                };
                (e, origin(Sensor::Imu, line, t))
            }),
            1 => take(&mut self.mag).map(|(line, t, v)| {
                let e = Event::Mag {
                    t_ns: t,
                    field: v3(&v, 0),
                };
                (e, origin(Sensor::Mag, line, t))
            }),
            2 => {
                let (Some(src), Some(decode)) = (self.gnss.as_mut(), self.gnss_decode.as_ref())
                else {
                    return Ok(None);
                };
                let Some((line, t, v)) = src.ahead.take() else {
                    return Ok(None);
                };
                let e = decode.event(&src.rows.path, line, t, &v)?;
                Some((e, origin(Sensor::Gnss, line, t)))
            }
            3 => {
                let Some(src) = self.cam.as_mut() else {
                    return Ok(None);
                };
                let Some((line, t, v)) = src.ahead.take() else {
                    return Ok(None);
                };
                let mut observations = vec![(v[0] as u64, Vector2::new(v[1], v[2]))];
                while src.peek()? == Some(t) {
                    if let Some((_, _, v)) = src.ahead.take() {
                        observations.push((v[0] as u64, Vector2::new(v[1], v[2])));
                    }
                }
                let e = Event::Camera {
                    t_ns: t,
                    observations,
                };
                Some((e, origin(Sensor::Camera, line, t)))
            }
            _ => take(&mut self.baro).map(|(line, t, v)| {
                let e = Event::Baro {
                    t_ns: t,
                    altitude: v[0],
                };
                (e, origin(Sensor::Baro, line, t))
            }),
        };
        if let Some((_, o)) = &produced {
            self.check.row(o.sensor, o.t_ns, o.line);
        }
        Ok(produced)
    }
}

impl Iterator for EventStream {
    type Item = Result<Event, DatasetError>;
    fn next(&mut self) -> Option<Self::Item> {
        match self.step() {
            Ok(Some((event, origin))) => {
                self.last = Some(origin);
                Some(Ok(event))
            }
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

/// One ground-truth row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// ns.
    pub t_ns: u64,
    /// Position, m.
    pub position: Vector3<f64>,
    /// `world_from_body`.
    pub attitude: So3<f64>,
    /// Velocity, m/s.
    pub velocity: Vector3<f64>,
    /// Gyro bias, rad/s.
    pub gyro_bias: Vector3<f64>,
    /// Accelerometer bias, m/s².
    pub accel_bias: Vector3<f64>,
}

/// The ground truth, streamed.
pub struct TruthStream {
    rows: Rows,
}

impl TruthStream {
    /// Opens `state_groundtruth_estimate0/data.csv`.
    pub fn open(dir: &Path) -> Result<Self, DatasetError> {
        Ok(Self {
            rows: Rows::open(&dir.join("state_groundtruth_estimate0/data.csv"), 17, false)?,
        })
    }

    /// What was skipped or may be wrong so far (a cut last line).
    #[must_use]
    pub fn warnings(&self) -> &[DataWarning] {
        self.rows.warnings()
    }

    /// The next row.
    pub fn next_truth(&mut self) -> Result<Option<Truth>, DatasetError> {
        let Some((line, t, v)) = self.rows.next_row()? else {
            return Ok(None);
        };
        let attitude = So3::from_wxyz(v[3], v[4], v[5], v[6])
            .ok_or_else(|| DatasetError::at(&self.rows.path, line, "quaternion of zero norm"))?;
        Ok(Some(Truth {
            t_ns: t,
            position: v3(&v, 0),
            attitude: attitude.normalize(),
            velocity: v3(&v, 7),
            gyro_bias: v3(&v, 10),
            accel_bias: v3(&v, 13),
        }))
    }
}

/// Time intervals `[start, end]`, ns.
pub type Intervals = Vec<(u64, u64)>;

/// The intervals of `DIR/movement.csv`, or `None` when the file is absent.
///
/// The file holds one interval a line, `start [ns],end [ns]`, both inclusive (BROAD's scored
/// movement phases); lines starting with `#`, blank lines and a first line that is not a number
/// (a header) are skipped. The intervals must be ordered and disjoint, each with `start ≤ end`.
/// A last line without its newline that does not parse is taken as cut off and skipped
/// ([`movement_checked`] gives the warning).
///
/// # Errors
/// An unreadable file, or a line that is not two integers in order, naming the file and line.
pub fn movement(dir: &Path) -> Result<Option<Vec<(u64, u64)>>, DatasetError> {
    movement_checked(dir).map(|(m, _)| m)
}

/// As [`movement`], with the warning of a last line cut short (no newline, not parsing: it is
/// skipped).
///
/// # Errors
/// As [`movement`].
pub fn movement_checked(dir: &Path) -> Result<(Option<Intervals>, Vec<DataWarning>), DatasetError> {
    let path = dir.join("movement.csv");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((None, Vec::new())),
        Err(e) => return Err(DatasetError::file(&path, e)),
    };
    let (m, w) = without_cut_last_line(&path, &text, parse_movement)?;
    Ok((Some(m), w))
}

/// `parse(path, text)`, except that a last line without its newline on which it fails is taken
/// as cut off: `text` without it is parsed instead, with a warning.
fn without_cut_last_line<R>(
    path: &Path,
    text: &str,
    parse: impl Fn(&Path, &str) -> Result<R, DatasetError>,
) -> Result<(R, Vec<DataWarning>), DatasetError> {
    match parse(path, text) {
        Ok(r) => Ok((r, Vec::new())),
        Err(DatasetError::At { line, message, .. })
            if !text.is_empty() && !text.ends_with('\n') && line == text.lines().count() as u64 =>
        {
            let start = text.rfind('\n').map_or(0, |i| i + 1);
            let r = parse(path, &text[..start])?;
            let warning = DataWarning::new(
                path,
                Some(line),
                format!("the file ends inside this line (no newline) and it does not parse ({message}): taken as cut off and skipped"),
            );
            Ok((r, vec![warning]))
        }
        Err(e) => Err(e),
    }
}

/// Parses the text of a `movement.csv` (see [`movement`]); `path` names it in errors.
///
/// # Errors
/// A line that is not two integers `start,end` with `start ≤ end`, after the previous interval.
pub fn parse_movement(path: &Path, text: &str) -> Result<Vec<(u64, u64)>, DatasetError> {
    let mut intervals: Vec<(u64, u64)> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i as u64 + 1;
        let row = raw.trim();
        if row.is_empty() || row.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        if line == 1 && fields.first().is_some_and(|f| f.parse::<u64>().is_err()) {
            continue; // a header without '#'
        }
        if fields.len() != 2 {
            return Err(DatasetError::at(
                path,
                line,
                format!(
                    "expected 2 columns (start [ns],end [ns]), got {}",
                    fields.len()
                ),
            ));
        }
        let parse = |f: &str, what: &str| {
            f.parse::<u64>().map_err(|_| {
                DatasetError::at(
                    path,
                    line,
                    format!("{what} '{f}' is not an integer number of ns"),
                )
            })
        };
        let start = parse(fields[0], "start")?;
        let end = parse(fields[1], "end")?;
        if end < start {
            return Err(DatasetError::at(
                path,
                line,
                format!("end {end} before start {start}"),
            ));
        }
        if let Some(&(_, last_end)) = intervals.last() {
            if start <= last_end {
                return Err(DatasetError::at(
                    path,
                    line,
                    format!("interval starting at {start} overlaps or precedes the previous one (ending at {last_end})"),
                ));
            }
        }
        intervals.push((start, end));
    }
    Ok(intervals)
}

/// One row of `faults.csv`, which `host-sim simulate` writes at the dataset root when its
/// scenario has faults: the rows of `sensor`'s data stamped in `[start_ns, end_ns)` carry the
/// fault `kind`.
///
/// `sensor` is `imu`, `mag`, `gnss` or `baro`; `kind` is `clip`, `stuck` (IMU), `rotated`,
/// `disturbance` (magnetometer), `outage`, `outliers`, `step`, `frozen` (GNSS) or `step`
/// (barometer). GNSS outliers, drawn fix by fix, are one `outliers` row over the whole run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaultInterval {
    /// First timestamp of the interval, ns (the dataset's clock, as `imu0/data.csv`).
    pub start_ns: u64,
    /// End of the interval, ns, excluded.
    pub end_ns: u64,
    /// The sensor at fault.
    pub sensor: String,
    /// What the fault is.
    pub kind: String,
}

/// The fault intervals of `DIR/faults.csv`, empty when the file is absent.
///
/// The file holds one interval a line, `start [ns],end [ns],sensor,kind` (see
/// [`FaultInterval`]); lines starting with `#`, blank lines and a first line that is not a number
/// (a header) are skipped. Intervals may overlap and come in any order. A last line without its
/// newline that does not parse is taken as cut off and skipped ([`read_faults_checked`] gives
/// the warning).
///
/// # Errors
/// An unreadable file, or a malformed line, naming the file and line.
pub fn read_faults(dir: &Path) -> Result<Vec<FaultInterval>, DatasetError> {
    read_faults_checked(dir).map(|(f, _)| f)
}

/// As [`read_faults`], with the warning of a last line cut short (no newline, not parsing: it
/// is skipped).
///
/// # Errors
/// As [`read_faults`].
pub fn read_faults_checked(
    dir: &Path,
) -> Result<(Vec<FaultInterval>, Vec<DataWarning>), DatasetError> {
    let path = dir.join("faults.csv");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((Vec::new(), Vec::new())),
        Err(e) => return Err(DatasetError::file(&path, e)),
    };
    without_cut_last_line(&path, &text, parse_faults)
}

/// Parses the text of a `faults.csv` (see [`read_faults`]); `path` names it in errors.
///
/// # Errors
/// A line that is not `start,end,sensor,kind` with integer `start ≤ end` and non-empty names.
pub fn parse_faults(path: &Path, text: &str) -> Result<Vec<FaultInterval>, DatasetError> {
    let mut faults = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i as u64 + 1;
        let row = raw.trim();
        if row.is_empty() || row.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        if line == 1 && fields.first().is_some_and(|f| f.parse::<u64>().is_err()) {
            continue; // a header without '#'
        }
        if fields.len() != 4 {
            return Err(DatasetError::at(
                path,
                line,
                format!(
                    "expected 4 columns (start [ns],end [ns],sensor,kind), got {}",
                    fields.len()
                ),
            ));
        }
        let parse = |f: &str, what: &str| {
            f.parse::<u64>().map_err(|_| {
                DatasetError::at(
                    path,
                    line,
                    format!("{what} '{f}' is not an integer number of ns"),
                )
            })
        };
        let start_ns = parse(fields[0], "start")?;
        let end_ns = parse(fields[1], "end")?;
        if end_ns < start_ns {
            return Err(DatasetError::at(
                path,
                line,
                format!("end {end_ns} before start {start_ns}"),
            ));
        }
        for (f, what) in [(fields[2], "sensor"), (fields[3], "kind")] {
            if f.is_empty() {
                return Err(DatasetError::at(path, line, format!("empty {what}")));
            }
        }
        faults.push(FaultInterval {
            start_ns,
            end_ns,
            sensor: fields[2].to_string(),
            kind: fields[3].to_string(),
        });
    }
    Ok(faults)
}

/// The timestamp of the first row of `DIR/state_groundtruth_estimate0/data.csv`, or `None`
/// when the file is absent or has no rows.
///
/// # Errors
/// An unreadable file or a malformed first row, naming the file and line.
pub fn first_truth_ns(dir: &Path) -> Result<Option<u64>, DatasetError> {
    if !dir.join("state_groundtruth_estimate0/data.csv").is_file() {
        return Ok(None);
    }
    Ok(TruthStream::open(dir)?.next_truth()?.map(|t| t.t_ns))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn movement_intervals_are_read_with_header_comments_and_blank_lines() {
        let text = "#start [ns],end [ns]  (inclusive)\n10,20\n\n 30 , 40 \n# a note\n40000000001,40000000001\n";
        let got = parse_movement(Path::new("d/movement.csv"), text).expect("parses");
        assert_eq!(
            got,
            vec![(10, 20), (30, 40), (40_000_000_001, 40_000_000_001)]
        );
        let plain_header = "start,end\n1,2\n";
        assert_eq!(
            parse_movement(Path::new("m.csv"), plain_header).expect("parses"),
            vec![(1, 2)]
        );
        assert!(parse_movement(Path::new("m.csv"), "")
            .expect("parses")
            .is_empty());
    }

    #[test]
    fn malformed_movement_lines_name_file_and_line() {
        let cases = [
            ("#h\n1,2\n3\n", "movement.csv:3:", "expected 2 columns"),
            (
                "#h\n1,2\n3,x4\n",
                "movement.csv:3:",
                "'x4' is not an integer",
            ),
            ("#h\n5,4\n", "movement.csv:2:", "end 4 before start 5"),
            ("#h\n1,10\n10,20\n", "movement.csv:3:", "overlaps"),
            ("#h\n1,2\n-3,4\n", "movement.csv:3:", "'-3'"),
        ];
        for (text, at, what) in cases {
            let err = parse_movement(Path::new("d/movement.csv"), text)
                .expect_err(text)
                .to_string();
            assert!(err.contains(at) && err.contains(what), "{text:?}: {err}");
        }
    }

    /// A EuRoC sequence as it unpacks, in miniature: Kalibr's `imu0/sensor.yaml` with its
    /// comments, EuRoC's `data.csv` headers (CRLF line ends in the IMU file), the ground truth's
    /// 17 columns under a header with spaces after the commas, and image-only cameras.
    #[test]
    fn a_euroc_sequence_is_read_from_its_mav0_with_the_cameras_left_out() {
        let root = std::env::temp_dir().join(format!("host-sim-euroc-read-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let mav0 = root.join("mav0");
        for d in [
            "imu0",
            "state_groundtruth_estimate0",
            "cam0/data",
            "cam1/data",
            "leica0",
        ] {
            std::fs::create_dir_all(mav0.join(d)).expect("tmp");
        }
        let imu_yaml = "#Default imu sensor yaml file\nsensor_type: imu\ncomment: VI-Sensor IMU (ADIS16448)\n\n# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n         0.0, 0.0, 1.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\nrate_hz: 200\n\n# inertial sensor noise model parameters (static)\ngyroscope_noise_density: 1.6968e-04     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\ngyroscope_random_walk: 1.9393e-05       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\naccelerometer_noise_density: 2.0000e-3  # [ m / s^2 / sqrt(Hz) ]  ( accel \"white noise\" )\naccelerometer_random_walk: 3.0000e-3    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )\n";
        std::fs::write(mav0.join("imu0/sensor.yaml"), imu_yaml).expect("write");
        std::fs::write(
            mav0.join("imu0/data.csv"),
            "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\r\n\
             1403636579758555392,-0.099134701513277898,0.14730578886832138,0.02722713633111154,8.1476917083333333,-0.37592158333333331,-2.4026292499999999\r\n\
             1403636579763555584,-0.099134701513277898,0.14032447186034408,0.029321531433504733,8.033280791666666,-0.40861041666666664,-2.4026292499999999\r\n",
        )
        .expect("write");
        std::fs::write(
            mav0.join("state_groundtruth_estimate0/data.csv"),
            "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n\
             1403636580838555648,4.688319,-1.786938,0.783338,0.534108,-0.153029,-0.827383,-0.082152,-0.027876,0.033207,0.800006,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\n",
        )
        .expect("write");
        for cam in ["cam0", "cam1"] {
            std::fs::write(
                mav0.join(cam).join("sensor.yaml"),
                "sensor_type: camera\ncomment: VI-Sensor cam0 (MT9M034)\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\nrate_hz: 20\nresolution: [752, 480]\ncamera_model: pinhole\nintrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv\n",
            )
            .expect("write");
            std::fs::write(
                mav0.join(cam).join("data.csv"),
                "#timestamp [ns],filename\n1403636579763555584,1403636579763555584.png\n",
            )
            .expect("write");
        }
        std::fs::write(mav0.join("body.yaml"), "comment: 'Body frame reference'\n").expect("write");

        let located = crate::dataset::locate(&root);
        assert_eq!(located.dir, mav0);
        assert!(located.note().is_some_and(|n| n.contains("mav0")));
        assert_eq!(crate::dataset::locate(&mav0).root, None);
        let ds = Dataset::open(&located.dir).expect("a EuRoC sequence opens");
        assert_eq!(ds.imu.rate_hz, 200.0);
        assert_eq!(ds.imu.gyroscope_noise_density, 1.6968e-04);
        assert_eq!(ds.imu.accelerometer_random_walk, 3.0e-3);
        assert!(ds.camera.is_none() && ds.mag.is_none() && ds.gnss.is_none());
        assert!(ds.has_groundtruth);
        assert_eq!(ds.warnings.len(), 2, "{:?}", ds.warnings);
        assert!(ds.warnings[0].contains("cam0") && ds.warnings[1].contains("cam1"));
        let events: Vec<Event> = ds
            .events()
            .expect("stream")
            .collect::<Result<_, _>>()
            .expect("rows");
        assert_eq!(events.len(), 2);
        assert_eq!(events[1].t_ns(), 1_403_636_579_763_555_584);
        let truth = TruthStream::open(&located.dir)
            .expect("truth")
            .next_truth()
            .expect("row")
            .expect("one row");
        assert_eq!(truth.position, Vector3::new(4.688319, -1.786938, 0.783338));
        assert!((truth.attitude.quaternion().w - 0.534108).abs() < 1e-4);

        // An IMU that is not the body frame is named, not silently taken as it.
        std::fs::write(
            mav0.join("imu0/sensor.yaml"),
            imu_yaml.replace("data: [1.0, 0.0, 0.0, 0.0,", "data: [1.0, 0.0, 0.0, 0.1,"),
        )
        .expect("write");
        let ds = Dataset::open(&mav0).expect("opens");
        assert!(ds
            .warnings
            .iter()
            .any(|w| w.contains("T_BS is not the identity")));
        let _ = std::fs::remove_dir_all(root);
    }

    #[test]
    fn fault_intervals_are_read_and_malformed_lines_name_file_and_line() {
        let text = "#start [ns],end [ns],sensor,kind\n10,20,gnss,step\n\n 5 , 5 , imu , stuck \n";
        let got = parse_faults(Path::new("d/faults.csv"), text).expect("parses");
        let row = |start_ns, end_ns, sensor: &str, kind: &str| FaultInterval {
            start_ns,
            end_ns,
            sensor: sensor.into(),
            kind: kind.into(),
        };
        assert_eq!(
            got,
            vec![row(10, 20, "gnss", "step"), row(5, 5, "imu", "stuck")]
        );
        let cases = [
            ("#h\n1,2,gnss\n", "faults.csv:2:", "expected 4 columns"),
            ("#h\n1,2,gnss,step\nx,4,baro,step\n", "faults.csv:3:", "'x'"),
            (
                "#h\n5,4,mag,rotated\n",
                "faults.csv:2:",
                "end 4 before start 5",
            ),
            ("#h\n1,2,,step\n", "faults.csv:2:", "empty sensor"),
            ("#h\n1,2,imu,\n", "faults.csv:2:", "empty kind"),
            ("#h\n-1,2,imu,clip\n", "faults.csv:2:", "'-1'"),
        ];
        for (text, at, what) in cases {
            let err = parse_faults(Path::new("d/faults.csv"), text)
                .expect_err(text)
                .to_string();
            assert!(err.contains(at) && err.contains(what), "{text:?}: {err}");
        }
        let dir = std::env::temp_dir().join(format!("host-sim-faults-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        assert!(read_faults(&dir).expect("absent is fine").is_empty());
        std::fs::write(dir.join("faults.csv"), "#h\n1,2,gnss,frozen\nbad\n").expect("write");
        let err = read_faults(&dir).expect_err("malformed").to_string();
        assert!(err.contains("faults.csv:3:"), "{err}");
        let _ = std::fs::remove_dir_all(dir);
    }

    /// A dataset folder with a two-row IMU and the given `gnss0/data.csv` (and
    /// `gnss0/sensor.yaml`, when given).
    fn gnss_dataset(name: &str, data: &str, yaml: Option<&str>) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("host-sim-gnss-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("imu0")).expect("tmp");
        std::fs::create_dir_all(dir.join("gnss0")).expect("tmp");
        std::fs::write(
            dir.join("imu0/sensor.yaml"),
            "rate_hz: 200\ngyroscope_noise_density: 1e-4\ngyroscope_random_walk: 1e-5\naccelerometer_noise_density: 1e-3\naccelerometer_random_walk: 1e-4\n",
        )
        .expect("write");
        std::fs::write(
            dir.join("imu0/data.csv"),
            "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n1000,0,0,0,0,0,9.81\n2000,0,0,0,0,0,9.81\n",
        )
        .expect("write");
        std::fs::write(dir.join("gnss0/data.csv"), data).expect("write");
        if let Some(y) = yaml {
            std::fs::write(dir.join("gnss0/sensor.yaml"), y).expect("write");
        }
        dir
    }

    fn gnss_events(dir: &Path) -> Result<Vec<Event>, DatasetError> {
        Dataset::open(dir)?
            .events()?
            .filter(|e| matches!(e, Ok(Event::Gnss { .. }) | Err(_)))
            .collect()
    }

    /// `(position, velocity, sigma_p, sigma_p_up, sigma_v)` of a GNSS event.
    #[allow(clippy::type_complexity)]
    fn fix(e: &Event) -> (Vector3<f64>, Option<Vector3<f64>>, f64, f64, f64) {
        match e {
            Event::Gnss {
                position,
                velocity,
                sigma_p,
                sigma_p_up,
                sigma_v,
                ..
            } => (*position, *velocity, *sigma_p, *sigma_p_up, *sigma_v),
            other => panic!("not a fix: {other:?}"),
        }
    }

    const ENU_HEADER: &str = "#timestamp [ns],p_x [m],p_y [m],p_z [m],v_x [m s^-1],v_y [m s^-1],v_z [m s^-1],sigma_p [m],sigma_v [m s^-1]";

    #[test]
    fn the_enu_form_gives_one_sigma_or_a_vertical_one() {
        // Nine columns: one σ for every axis, as before.
        let row = "1500,1,2,3,0.1,0.2,0.3,1.5,0.1";
        let dir = gnss_dataset("enu9", &format!("{ENU_HEADER}\n{row}\n"), None);
        let ds = Dataset::open(&dir).expect("opens");
        let g = ds.gnss.as_ref().expect("gnss");
        assert_eq!(
            g.format,
            GnssFormat::Enu {
                sigma_up_column: false
            }
        );
        assert!(g.frame.is_none() && ds.notes.is_empty());
        let events = gnss_events(&dir).expect("rows");
        assert_eq!(
            fix(&events[0]),
            (
                Vector3::new(1.0, 2.0, 3.0),
                Some(Vector3::new(0.1, 0.2, 0.3)),
                1.5,
                1.5,
                0.1
            )
        );
        // The simulator's keys in sensor.yaml: horizontal and vertical replace the row's σ.
        std::fs::write(
            dir.join("gnss0/sensor.yaml"),
            "lever_arm: [0, 0, 0]\nsigma_p_horizontal: 1.0\nsigma_p_up: 1.5\n",
        )
        .expect("write");
        let (_, _, h, up, _) = fix(&gnss_events(&dir).expect("rows")[0]);
        assert_eq!((h, up), (1.0, 1.5));
        std::fs::write(dir.join("gnss0/sensor.yaml"), "sigma_p_up: -2\n").expect("write");
        let err = Dataset::open(&dir).expect_err("negative").to_string();
        assert!(
            err.contains("sensor.yaml") && err.contains("sigma_p_up"),
            "{err}"
        );
        // Ten columns, with a header or without: the 10th is the vertical σ.
        for (name, text) in [
            (
                "enu10",
                format!("{ENU_HEADER},sigma_p_up [m]\n1500,1,2,3,0.1,0.2,0.3,0.8,0.1,2.5\n"),
            ),
            (
                "enu10-bare",
                "1500,1,2,3,0.1,0.2,0.3,0.8,0.1,2.5\n1600,1,2,3,0.1,0.2,0.3,0.8,0.1,2.5\n"
                    .to_string(),
            ),
        ] {
            let dir = gnss_dataset(name, &text, Some("lever_arm: [0, 0, 0]\nsigma_p_up: 9\n"));
            let ds = Dataset::open(&dir).expect("opens");
            assert_eq!(
                ds.gnss.expect("gnss").format,
                GnssFormat::Enu {
                    sigma_up_column: true
                }
            );
            let (p, _, h, up, _) = fix(&gnss_events(&dir).expect("rows")[0]);
            assert_eq!(
                (p, h, up),
                (Vector3::new(1.0, 2.0, 3.0), 0.8, 2.5),
                "{name}"
            );
            let _ = std::fs::remove_dir_all(dir);
        }
        // A 10th column of another name, or a row of the wrong length, names file and line.
        let dir2 = gnss_dataset("enu10-bad", &format!("{ENU_HEADER},hdop\n"), None);
        let err = Dataset::open(&dir2).expect_err("unknown").to_string();
        assert!(
            err.contains("gnss0/data.csv:1:") && err.contains("'hdop'"),
            "{err}"
        );
        let dir3 = gnss_dataset(
            "enu10-short",
            &format!("{ENU_HEADER},sigma_p_up [m]\n1500,1,2,3,0.1,0.2,0.3,0.8,0.1\n"),
            None,
        );
        let err = gnss_events(&dir3).expect_err("short").to_string();
        assert!(
            err.contains("gnss0/data.csv:2:") && err.contains("expected 10 columns"),
            "{err}"
        );
        for d in [dir, dir2, dir3] {
            let _ = std::fs::remove_dir_all(d);
        }
    }

    #[test]
    fn the_geodetic_form_is_converted_to_enu_at_its_origin() {
        use crate::dataset::geodesy::LocalEnu;
        let origin = Geodetic::new(47.376_887, 8.541_694, 408.0);
        let frame = LocalEnu::new(origin);
        let enu = [
            Vector3::new(10.0, -20.0, 3.0),
            Vector3::new(12.0, -19.0, 2.5),
        ];
        let v_here = Vector3::new(2.0, 1.0, -0.5);
        let mut text = format!("{GEODETIC_HEADER}\n");
        for (k, p) in enu.iter().enumerate() {
            let g = frame.to_geodetic(p);
            // The velocity as the receiver gives it: east-north-up where it is.
            let v = frame.vector_from_enu(&g, &v_here);
            text += &format!(
                "{},{:.12},{:.12},{:.6},{},{},{},0.7,1.4,0.05\n",
                1500 + k,
                g.lat_deg,
                g.lon_deg,
                g.height_m,
                v.x,
                v.y,
                v.z
            );
        }
        let yaml = format!(
            "lever_arm: [0, 0, 0]\norigin: [{}, {}, {}]\n",
            origin.lat_deg, origin.lon_deg, origin.height_m
        );
        let dir = gnss_dataset("geodetic", &text, Some(&yaml));
        let ds = Dataset::open(&dir).expect("opens");
        let g = ds.gnss.as_ref().expect("gnss");
        assert!(matches!(g.format, GnssFormat::Geodetic(_)));
        assert!(!g.origin_from_first_fix && ds.notes.is_empty());
        let events = gnss_events(&dir).expect("rows");
        assert_eq!(events.len(), 2);
        for (e, want) in events.iter().zip(&enu) {
            let (p, v, h, up, sv) = fix(e);
            // 1e-12° is 0.1 µm, 1e-6 m of height 1 µm.
            assert!((p - want).norm() < 1e-5, "{p} vs {want}");
            assert!((v.expect("velocity") - v_here).norm() < 1e-9);
            assert_eq!((h, up, sv), (0.7, 1.4, 0.05));
        }

        // Without an origin, the first fix is the origin (and a note says so); another order
        // and names of the columns, no velocity, an extra column ignored.
        let first = frame.to_geodetic(&enu[0]);
        let second = frame.to_geodetic(&enu[1]);
        let text = format!(
            "#timestamp [ns],sigma_h [m],latitude [deg],longitude [deg],height [m],num_sv,sigma_p_up [m]\n\
             1500,0.7,{:.12},{:.12},{:.6},12,1.4\n1600,0.7,{:.12},{:.12},{:.6},11,1.4\n",
            first.lat_deg, first.lon_deg, first.height_m, second.lat_deg, second.lon_deg, second.height_m
        );
        std::fs::write(dir.join("gnss0/data.csv"), text).expect("write");
        std::fs::write(dir.join("gnss0/sensor.yaml"), "lever_arm: [0, 0, 0]\n").expect("write");
        let ds = Dataset::open(&dir).expect("opens");
        assert!(ds.gnss.as_ref().expect("gnss").origin_from_first_fix);
        assert!(
            ds.notes.len() == 1 && ds.notes[0].contains("first fix"),
            "{:?}",
            ds.notes
        );
        let events = gnss_events(&dir).expect("rows");
        let (p0, v0, h, up, _) = fix(&events[0]);
        assert!(p0.norm() < 1e-5 && v0.is_none() && (h, up) == (0.7, 1.4));
        let (p1, ..) = fix(&events[1]);
        let want = LocalEnu::new(first).to_enu(&second);
        assert!((p1 - want).norm() < 1e-5 && (p1 - (enu[1] - enu[0])).norm() < 1e-3);
        let _ = std::fs::remove_dir_all(dir);
    }

    /// The header with the velocity's unit written once, after the three
    /// (`v_e,v_n,v_u [m s^-1]`), reads as the one the reader writes in its messages.
    #[test]
    fn the_short_spelling_of_the_geodetic_header_is_read() {
        let short = "#timestamp [ns],lat [deg],lon [deg],h [m],v_e,v_n,v_u [m s^-1],sigma_h [m],sigma_v_up [m],sigma_vel [m s^-1]";
        let row = "1500,47.1,8.5,400.0,1.0,2.0,0.5,0.8,1.6,0.05";
        for (k, header) in [short, GEODETIC_HEADER].iter().enumerate() {
            let dir = gnss_dataset(
                &format!("short-{k}"),
                &format!("{header}\n{row}\n"),
                Some("lever_arm: [0, 0, 0]\norigin: [47.1, 8.5, 400.0]\n"),
            );
            let ds = Dataset::open(&dir).expect("opens");
            assert_eq!(
                ds.gnss.as_ref().expect("gnss").format,
                GnssFormat::Geodetic(GeodeticColumns {
                    columns: 10,
                    lat: 0,
                    lon: 1,
                    height: 2,
                    velocity: Some([3, 4, 5]),
                    sigma_h: 6,
                    sigma_up: 7,
                    sigma_vel: Some(8),
                })
            );
            let (p, v, h, up, sv) = fix(&gnss_events(&dir).expect("rows")[0]);
            // At the origin, with the velocity in the origin's own frame.
            assert!(p.norm() < 1e-9, "{p}");
            assert!((v.expect("velocity") - Vector3::new(1.0, 2.0, 0.5)).norm() < 1e-12);
            assert_eq!((h, up, sv), (0.8, 1.6, 0.05));
            let _ = std::fs::remove_dir_all(dir);
        }
    }

    #[test]
    fn malformed_geodetic_files_name_file_and_line() {
        let cases = [
            (
                "#timestamp [ns],lat [deg],lon [deg],h [m],sigma_v_up [m]\n",
                "gnss0/data.csv:1:",
                "no 'sigma_h' column",
            ),
            (
                "#timestamp [ns],lat [deg],lon [deg],h [m],sigma_h [m],sigma_v [m]\n",
                "gnss0/data.csv:1:",
                "ambiguous",
            ),
            (
                "#timestamp [ns],lat,lon,h,v_e,v_n,sigma_h,sigma_v_up,sigma_vel\n",
                "gnss0/data.csv:1:",
                "not all three",
            ),
            (
                "#timestamp [ns],lat,lon,h,v_e,v_n,v_u,sigma_h,sigma_v_up\n",
                "gnss0/data.csv:1:",
                "no 'sigma_vel [m s^-1]'",
            ),
            (
                "#timestamp [ns],lat,latitude,lon,h,sigma_h,sigma_v_up\n",
                "gnss0/data.csv:1:",
                "twice",
            ),
            (
                "#timestamp [ns],lat,lon,h,sigma_h,sigma_v_up\n1500,47.1,8.5,400,1,2\n1600,95.0,8.5,400,1,2\n",
                "gnss0/data.csv:3:",
                "latitude 95",
            ),
            (
                "#timestamp [ns],lat,lon,h,sigma_h,sigma_v_up\n1500,47.1,8.5,400,1\n",
                "gnss0/data.csv:2:",
                "expected 6 columns, got 5",
            ),
        ];
        for (k, (text, at, what)) in cases.iter().enumerate() {
            let dir = gnss_dataset(&format!("bad-{k}"), text, Some("lever_arm: [0, 0, 0]\n"));
            let err = gnss_events(&dir).expect_err(text).to_string();
            assert!(err.contains(at) && err.contains(what), "{text:?}: {err}");
            let _ = std::fs::remove_dir_all(dir);
        }
        // An origin out of range in sensor.yaml is named.
        let dir = gnss_dataset(
            "bad-origin",
            "#timestamp [ns],lat,lon,h,sigma_h,sigma_v_up\n1500,47.1,8.5,400,1,2\n",
            Some("origin: [47.1, 400.0, 0]\n"),
        );
        let err = Dataset::open(&dir).expect_err("origin").to_string();
        assert!(
            err.contains("sensor.yaml") && err.contains("longitude 400"),
            "{err}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn rows_count_lines_as_written_and_a_cut_last_line_is_a_warning() {
        let dir = std::env::temp_dir().join(format!("host-sim-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let p = dir.join("d.csv");
        let read_all = |text: &str| {
            std::fs::write(&p, text).expect("write");
            let mut r = Rows::open(&p, 2, false).expect("open");
            let mut rows = Vec::new();
            while let Some(row) = r.next_row().expect("rows") {
                rows.push(row);
            }
            (rows, r.warnings().to_vec())
        };
        // A byte-order mark, CRLF and a blank line: lines numbered as an editor shows them.
        std::fs::write(&p, "\u{feff}#t,a\r\n1,0.5\r\n\r\n2,x\r\n").expect("write");
        let mut r = Rows::open(&p, 2, false).expect("open");
        assert_eq!(r.next_row().expect("row"), Some((2, 1, vec![0.5])));
        let err = r.next_row().expect_err("x").to_string();
        assert!(
            err.ends_with("d.csv:4: column 2: 'x' is not a number"),
            "{err}"
        );

        // Cut inside the last row: skipped, with a warning; a quoted number is a number.
        let (rows, w) = read_all("#t,a\n1,0.5\n2,\"0.25\"\n3");
        assert_eq!(rows, vec![(2, 1, vec![0.5]), (3, 2, vec![0.25])]);
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].line, Some(4));
        assert!(
            w[0].message
                .contains("does not parse (expected 2 columns, got 1)"),
            "{}",
            w[0].message
        );
        // Cut inside its timestamp (smaller than the one before): skipped too.
        let (rows, w) = read_all("#t,a\n15,0.5\n1");
        assert_eq!((rows.len(), w.len()), (1, 1));
        let (rows, w) = read_all("#t,a\n15,0.5\n1,0.5");
        assert_eq!(rows.len(), 1);
        assert!(w[0].message.contains("non-monotonic"), "{w:?}");
        // Cut after a number that parses: used, with a warning.
        let (rows, w) = read_all("#t,a\n1,0.5\n2,0.2");
        assert_eq!(rows.len(), 2);
        assert!(w[0].message.contains("it parses, so it is used"), "{w:?}");
        // A header alone, or a file ending with its newline: nothing to say.
        assert_eq!(read_all("#t,a"), (Vec::new(), Vec::new()));
        assert_eq!(read_all("#t,a\n1,0.5\n").1, Vec::new());
        // The same short row with its newline was written whole: an error.
        std::fs::write(&p, "#t,a\n1,0.5\n3\n").expect("write");
        let mut r = Rows::open(&p, 2, false).expect("open");
        assert!(r.next_row().is_ok());
        let err = r.next_row().expect_err("short row").to_string();
        assert!(err.ends_with("d.csv:3: expected 2 columns, got 1"), "{err}");

        // movement.csv and faults.csv, read as text, alike.
        std::fs::write(dir.join("movement.csv"), "#s,e\n1,2\n5,").expect("write");
        let (m, w) = movement_checked(&dir).expect("cut line skipped");
        assert_eq!(m, Some(vec![(1, 2)]));
        assert_eq!(w.len(), 1);
        assert!(w[0]
            .to_string()
            .contains("movement.csv:3: the file ends inside this line"));
        std::fs::write(dir.join("movement.csv"), "#s,e\n1,2\n5,\n").expect("write");
        assert!(movement_checked(&dir).is_err());
        std::fs::write(dir.join("faults.csv"), "#h\n1,2,gnss,step\n3,4,gn").expect("write");
        let (f, w) = read_faults_checked(&dir).expect("cut line skipped");
        assert_eq!((f.len(), w.len()), (1, 1));
        assert_eq!(w[0].line, Some(3));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_missing_movement_file_is_none() {
        let dir = std::env::temp_dir().join(format!("host-sim-movement-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        assert_eq!(movement(&dir).expect("absent is fine"), None);
        std::fs::write(dir.join("movement.csv"), "#s,e\n1,2\nbad\n").expect("write");
        let err = movement(&dir).expect_err("malformed").to_string();
        assert!(err.contains("movement.csv:3:"), "{err}");
        let _ = std::fs::remove_dir_all(dir);
    }
}

//! WGS-84 geodetic coordinates (latitude, longitude, ellipsoidal height) to Earth-centred
//! Earth-fixed (ECEF) coordinates and to a local east-north-up (ENU) frame, and back: how a
//! receiver's latitude and longitude become the world frame (ENU, z up) the filters run in.
//!
//! # The ellipsoid
//!
//! WGS-84: semi-major axis `a = 6 378 137 m`, flattening `f = 1 / 298.257 223 563`, first
//! eccentricity squared `e² = f (2 − f)`, semi-minor axis `b = a (1 − f)`.
//!
//! # Geodetic to ECEF
//!
//! With latitude `φ`, longitude `λ`, ellipsoidal height `h` and the prime-vertical radius of
//! curvature
//!
//! ```text
//! N(φ) = a / √(1 − e² sin²φ)
//! ```
//!
//! the ECEF point is
//!
//! ```text
//! X = (N + h) cos φ cos λ
//! Y = (N + h) cos φ sin λ
//! Z = (N (1 − e²) + h) sin φ
//! ```
//!
//! # ECEF to geodetic
//!
//! `λ = atan2(Y, X)`, `p = √(X² + Y²)`. The latitude by Bowring's iteration on the reduced
//! (parametric) latitude `β`, started at `tan β = (a Z) / (b p)`:
//!
//! ```text
//! φ = atan2(Z + e'² b sin³β,  p − e² a cos³β),     e'² = e² / (1 − e²)
//! tan β = (1 − f) tan φ
//! ```
//!
//! One step is exact to about a micrometre up to 10 km above the ellipsoid (1 mm at 400 km);
//! the iteration runs until the latitude stops changing (at most 8 steps, two or three in
//! practice). The height then follows without dividing by `cos φ`, so it stays exact at the
//! poles:
//!
//! ```text
//! h = p cos φ + Z sin φ − a √(1 − e² sin²φ)      (= p cos φ + Z sin φ − a² / N)
//! ```
//!
//! # The local ENU frame
//!
//! At an origin `(φ₀, λ₀, h₀)` with ECEF point `X₀`, the ENU coordinates of an ECEF point `X`
//! are `enu = R (X − X₀)`, and back `X = X₀ + Rᵀ enu`, with the rows of `R` the east, north and
//! up unit vectors at the origin:
//!
//! ```text
//!     ⎡ −sin λ₀          cos λ₀           0     ⎤   east
//! R = ⎢ −sin φ₀ cos λ₀   −sin φ₀ sin λ₀   cos φ₀ ⎥   north
//!     ⎣  cos φ₀ cos λ₀    cos φ₀ sin λ₀   sin φ₀ ⎦   up
//! ```
//!
//! A vector given in the ENU frame of another point `P` (a receiver's velocity, east-north-up
//! where it is) is in this frame `R₀ R_Pᵀ v`: the two frames differ by a rotation of about the
//! distance between the points over the Earth's radius (1.6·10⁻⁴ rad a kilometre).
//!
//! Near the origin the frame agrees with the flat-earth approximation
//! `e ≈ (λ − λ₀)(N₀ + h₀) cos φ₀`, `n ≈ (φ − φ₀)(M₀ + h₀)`, `u ≈ h − h₀`, with the meridian
//! radius `M(φ) = a (1 − e²) / (1 − e² sin²φ)^{3/2}`, up to terms of second order in the
//! offset `d`: the tangent plane leaves the ellipsoid by about `d² / 2R` (0.8 mm at 100 m), and a
//! parallel of latitude curves away from the east axis by about `d² tan φ₀ / 2R`.

use nalgebra::{Matrix3, Vector3};

/// WGS-84 semi-major axis, m.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 first eccentricity squared, `f (2 − f)`.
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);
/// WGS-84 semi-minor axis, `a (1 − f)`, m.
pub const WGS84_B: f64 = WGS84_A * (1.0 - WGS84_F);

/// A WGS-84 position: latitude and longitude in degrees, height above the ellipsoid in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geodetic {
    /// Latitude, degrees, north positive, in `[−90, 90]`.
    pub lat_deg: f64,
    /// Longitude, degrees, east positive.
    pub lon_deg: f64,
    /// Ellipsoidal height, m (not the height above the geoid / mean sea level).
    pub height_m: f64,
}

impl Geodetic {
    /// A position from latitude, longitude (degrees) and ellipsoidal height (m).
    #[must_use]
    pub fn new(lat_deg: f64, lon_deg: f64, height_m: f64) -> Self {
        Self {
            lat_deg,
            lon_deg,
            height_m,
        }
    }

    /// `Ok` for finite numbers with the latitude in `[−90, 90]` and the longitude in
    /// `[−180, 360]` (east of Greenwich counted either way); otherwise what is wrong.
    ///
    /// # Errors
    /// A sentence naming the value out of range.
    pub fn check(&self) -> Result<(), String> {
        if !(self.lat_deg.is_finite() && self.lon_deg.is_finite() && self.height_m.is_finite()) {
            return Err("latitude, longitude and height must be finite".into());
        }
        if !(-90.0..=90.0).contains(&self.lat_deg) {
            return Err(format!(
                "latitude {} is outside [-90, 90] degrees",
                self.lat_deg
            ));
        }
        if !(-180.0..=360.0).contains(&self.lon_deg) {
            return Err(format!(
                "longitude {} is outside [-180, 360] degrees",
                self.lon_deg
            ));
        }
        Ok(())
    }
}

/// The prime-vertical radius of curvature `N(φ) = a / √(1 − e² sin²φ)`, m (`φ` in radians).
#[must_use]
pub fn prime_vertical_radius(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    WGS84_A / (1.0 - WGS84_E2 * s * s).sqrt()
}

/// The meridian radius of curvature `M(φ) = a (1 − e²) / (1 − e² sin²φ)^{3/2}`, m.
#[must_use]
pub fn meridian_radius(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    let w = 1.0 - WGS84_E2 * s * s;
    WGS84_A * (1.0 - WGS84_E2) / (w * w.sqrt())
}

/// Geodetic to ECEF, m: `X = (N + h) cos φ cos λ`, `Y = (N + h) cos φ sin λ`,
/// `Z = (N (1 − e²) + h) sin φ`.
#[must_use]
pub fn to_ecef(g: &Geodetic) -> Vector3<f64> {
    let (phi, lambda) = (g.lat_deg.to_radians(), g.lon_deg.to_radians());
    let n = prime_vertical_radius(phi);
    let (sp, cp) = phi.sin_cos();
    let (sl, cl) = lambda.sin_cos();
    Vector3::new(
        (n + g.height_m) * cp * cl,
        (n + g.height_m) * cp * sl,
        (n * (1.0 - WGS84_E2) + g.height_m) * sp,
    )
}

/// ECEF to geodetic by Bowring's iteration (module docs); the longitude in `(−180, 180]`.
#[must_use]
pub fn from_ecef(x: &Vector3<f64>) -> Geodetic {
    let ep2 = WGS84_E2 / (1.0 - WGS84_E2);
    let p = x.x.hypot(x.y);
    let lambda = x.y.atan2(x.x);
    let mut beta = (WGS84_A * x.z).atan2(WGS84_B * p);
    let mut phi = 0.0;
    for _ in 0..8 {
        let (sb, cb) = beta.sin_cos();
        let next =
            (x.z + ep2 * WGS84_B * sb * sb * sb).atan2(p - WGS84_E2 * WGS84_A * cb * cb * cb);
        let done = (next - phi).abs() <= 1e-15;
        phi = next;
        if done {
            break;
        }
        beta = ((1.0 - WGS84_F) * phi.sin()).atan2(phi.cos());
    }
    let (sp, cp) = phi.sin_cos();
    let h = p * cp + x.z * sp - WGS84_A * (1.0 - WGS84_E2 * sp * sp).sqrt();
    Geodetic::new(phi.to_degrees(), lambda.to_degrees(), h)
}

/// The rotation `R` from ECEF to the ENU frame at `origin` (rows: east, north, up).
#[must_use]
pub fn enu_from_ecef(origin: &Geodetic) -> Matrix3<f64> {
    let (sp, cp) = origin.lat_deg.to_radians().sin_cos();
    let (sl, cl) = origin.lon_deg.to_radians().sin_cos();
    Matrix3::new(-sl, cl, 0.0, -sp * cl, -sp * sl, cp, cp * cl, cp * sl, sp)
}

/// A local ENU frame: the world frame of a dataset whose GNSS speaks latitude and longitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalEnu {
    origin: Geodetic,
    origin_ecef: Vector3<f64>,
    enu_from_ecef: Matrix3<f64>,
}

impl LocalEnu {
    /// The ENU frame with its origin at `origin`.
    #[must_use]
    pub fn new(origin: Geodetic) -> Self {
        Self {
            origin,
            origin_ecef: to_ecef(&origin),
            enu_from_ecef: enu_from_ecef(&origin),
        }
    }

    /// The origin.
    #[must_use]
    pub fn origin(&self) -> Geodetic {
        self.origin
    }

    /// `R`, ECEF to this frame.
    #[must_use]
    pub fn rotation(&self) -> Matrix3<f64> {
        self.enu_from_ecef
    }

    /// The ENU coordinates of `g`, m: `R (X(g) − X₀)`.
    #[must_use]
    pub fn to_enu(&self, g: &Geodetic) -> Vector3<f64> {
        self.enu_from_ecef * (to_ecef(g) - self.origin_ecef)
    }

    /// The geodetic position of the ENU point `enu`: `X₀ + Rᵀ enu` to geodetic.
    #[must_use]
    pub fn to_geodetic(&self, enu: &Vector3<f64>) -> Geodetic {
        from_ecef(&(self.origin_ecef + self.enu_from_ecef.transpose() * enu))
    }

    /// A vector given in the ENU frame at `at` (a velocity east-north-up where the receiver
    /// is) in this frame: `R₀ R_atᵀ v`.
    #[must_use]
    pub fn vector_to_enu(&self, at: &Geodetic, v: &Vector3<f64>) -> Vector3<f64> {
        self.enu_from_ecef * (enu_from_ecef(at).transpose() * v)
    }

    /// The inverse of [`LocalEnu::vector_to_enu`]: a vector of this frame in the ENU frame at
    /// `at`, `R_at R₀ᵀ v`.
    #[must_use]
    pub fn vector_from_enu(&self, at: &Geodetic, v: &Vector3<f64>) -> Vector3<f64> {
        enu_from_ecef(at) * (self.enu_from_ecef.transpose() * v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A metre in degrees of latitude is about 9·10⁻⁶: 10⁻¹¹ degrees is about 1 µm.
    const DEG_UM: f64 = 1e-11;

    #[test]
    fn known_points_on_the_axes() {
        let cases = [
            // Equator, prime meridian: X = a.
            (
                Geodetic::new(0.0, 0.0, 0.0),
                Vector3::new(WGS84_A, 0.0, 0.0),
            ),
            // Equator, 90° E, 1 km up: Y = a + h.
            (
                Geodetic::new(0.0, 90.0, 1000.0),
                Vector3::new(0.0, WGS84_A + 1000.0, 0.0),
            ),
            // Equator, 180°: X = −a.
            (
                Geodetic::new(0.0, 180.0, 0.0),
                Vector3::new(-WGS84_A, 0.0, 0.0),
            ),
            // North pole: Z = b (N(90°)(1 − e²) = a²/b (1 − e²) = b).
            (
                Geodetic::new(90.0, 0.0, 0.0),
                Vector3::new(0.0, 0.0, WGS84_B),
            ),
            // South pole, 100 m up.
            (
                Geodetic::new(-90.0, 0.0, 100.0),
                Vector3::new(0.0, 0.0, -(WGS84_B + 100.0)),
            ),
        ];
        for (g, x) in cases {
            let got = to_ecef(&g);
            assert!((got - x).norm() < 1e-6, "{g:?}: {got} vs {x}");
            let back = from_ecef(&x);
            assert!((back.lat_deg - g.lat_deg).abs() < DEG_UM, "{g:?}: {back:?}");
            assert!((back.height_m - g.height_m).abs() < 1e-6, "{g:?}: {back:?}");
            // The longitude is undefined at the poles.
            if g.lat_deg.abs() < 90.0 {
                let dl = (back.lon_deg - g.lon_deg).rem_euclid(360.0);
                assert!(dl.min(360.0 - dl) < DEG_UM, "{g:?}: {back:?}");
            }
        }
        // b from a and f: 6 356 752.314 245 m, the published value.
        assert!((WGS84_B - 6_356_752.314_245).abs() < 1e-6);
        assert!((WGS84_E2 - 6.694_379_990_14e-3).abs() < 1e-14);
    }

    /// 45° N 45° E on the ellipsoid, worked by hand: `N(45°) = a / √(1 − e²/2)`
    /// = 6 388 838.29 m, `X = Y = N cos²45°` = 3 194 419.15 m, `Z = N (1 − e²) sin 45°`
    /// = 4 487 348.41 m.
    #[test]
    fn a_mid_latitude_point() {
        let x = to_ecef(&Geodetic::new(45.0, 45.0, 0.0));
        assert!((prime_vertical_radius(45f64.to_radians()) - 6_388_838.29).abs() < 0.01);
        assert!((x - Vector3::new(3_194_419.15, 3_194_419.15, 4_487_348.41)).norm() < 0.02);
    }

    #[test]
    fn round_trips_are_exact_to_a_micrometre_everywhere() {
        let mut worst: f64 = 0.0;
        for lat in (-90..=90).step_by(5) {
            for lon in (-180..=180).step_by(15) {
                for h in [-400.0, 0.0, 35.7, 1_500.0, 12_000.0, 400_000.0] {
                    let g = Geodetic::new(f64::from(lat) + 0.123_456_789, f64::from(lon), h);
                    let g = Geodetic::new(g.lat_deg.clamp(-90.0, 90.0), g.lon_deg, g.height_m);
                    let x = to_ecef(&g);
                    let back = to_ecef(&from_ecef(&x));
                    worst = worst.max((back - x).norm());
                }
            }
        }
        assert!(worst < 1e-6, "worst ECEF round trip {worst} m");
    }

    #[test]
    fn enu_round_trip_and_frame() {
        let origin = Geodetic::new(47.376_887, 8.541_694, 408.0);
        let frame = LocalEnu::new(origin);
        assert!(frame.to_enu(&origin).norm() < 1e-9);
        let r = frame.rotation();
        assert!((r * r.transpose() - Matrix3::identity()).norm() < 1e-15);
        assert!((r.determinant() - 1.0).abs() < 1e-15);
        for enu in [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(123.4, -56.7, 8.9),
            Vector3::new(-5_000.0, 20_000.0, -300.0),
            Vector3::new(0.001, 0.002, 0.003),
        ] {
            let g = frame.to_geodetic(&enu);
            assert!((frame.to_enu(&g) - enu).norm() < 1e-6, "{enu}");
        }
        // Up is up: a point straight above the origin.
        let above = Geodetic::new(origin.lat_deg, origin.lon_deg, origin.height_m + 10.0);
        assert!((frame.to_enu(&above) - Vector3::new(0.0, 0.0, 10.0)).norm() < 1e-9);
        // North is north: a point at a higher latitude has n > 0, e ≈ 0.
        let north = frame.to_enu(&Geodetic::new(origin.lat_deg + 1e-3, origin.lon_deg, 408.0));
        assert!(north.y > 100.0 && north.x.abs() < 1e-6, "{north}");
        // A vector in the frame of a point 10 km away and back.
        let far = frame.to_geodetic(&Vector3::new(7_000.0, 7_000.0, 0.0));
        let v = Vector3::new(1.0, -2.0, 0.5);
        let there = frame.vector_from_enu(&far, &v);
        assert!((frame.vector_to_enu(&far, &there) - v).norm() < 1e-12);
        // The frames differ by about distance / radius: 10 km is 1.6e-3 rad.
        let angle = (there - v).norm() / v.norm();
        assert!(angle > 1e-3 && angle < 2.5e-3, "{angle}");
    }

    /// Near the origin, the ENU frame is the flat-earth approximation up to second-order
    /// terms: `e ≈ Δλ (N₀ + h₀) cos φ₀`, `n ≈ Δφ (M₀ + h₀)`, `u ≈ Δh`, off by about
    /// `d² / 2R` in height and `d² tan φ₀ / 2R` in north (a parallel's curvature).
    #[test]
    fn small_offsets_agree_with_the_flat_earth_approximation() {
        for origin in [
            Geodetic::new(0.0, 0.0, 0.0),
            Geodetic::new(47.376_887, 8.541_694, 408.0),
            Geodetic::new(-33.9, 151.2, 50.0),
            Geodetic::new(78.2, 15.6, 10.0),
        ] {
            let frame = LocalEnu::new(origin);
            let phi0 = origin.lat_deg.to_radians();
            let n0 = prime_vertical_radius(phi0);
            let m0 = meridian_radius(phi0);
            for (dn, de, du) in [
                (100.0, 0.0, 0.0),
                (0.0, 100.0, 0.0),
                (-70.0, 70.0, 5.0),
                (3.0, -4.0, -2.0),
            ] {
                // The geodetic offsets of the flat-earth model.
                let dphi = dn / (m0 + origin.height_m);
                let dlambda = de / ((n0 + origin.height_m) * phi0.cos());
                let g = Geodetic::new(
                    origin.lat_deg + dphi.to_degrees(),
                    origin.lon_deg + dlambda.to_degrees(),
                    origin.height_m + du,
                );
                let enu = frame.to_enu(&g);
                let flat = Vector3::new(de, dn, du);
                let d2 = de * de + dn * dn + du * du;
                // Second order: within (1 + |tan φ₀|) d² / R (R ≥ b), twice the terms above.
                let bound = (1.0 + phi0.tan().abs()) * d2 / WGS84_B + 1e-9;
                // And the approximation is not exact: 100 m offsets show the second order.
                if d2 > 5_000.0 {
                    assert!((enu - flat).norm() > 1e-4, "{origin:?} {flat}: {enu}");
                }
                assert!(
                    (enu - flat).norm() <= bound,
                    "{origin:?} {flat}: {enu} ({} > {bound})",
                    (enu - flat).norm()
                );
            }
        }
    }

    #[test]
    fn out_of_range_positions_are_named() {
        assert!(Geodetic::new(47.0, 8.0, 400.0).check().is_ok());
        assert!(Geodetic::new(47.0, 350.0, 400.0).check().is_ok());
        assert!(Geodetic::new(91.0, 8.0, 0.0)
            .check()
            .is_err_and(|e| e.contains("latitude 91")));
        assert!(Geodetic::new(0.0, -181.0, 0.0)
            .check()
            .is_err_and(|e| e.contains("longitude -181")));
        assert!(Geodetic::new(0.0, 0.0, f64::NAN).check().is_err());
    }
}

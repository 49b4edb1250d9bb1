//! WGS 84 geodesy for placing a terrain on the globe and a photo on a terrain: longitude/latitude/
//! height to earth-centred, earth-fixed (ECEF) coordinates, and between longitude/latitude and the
//! projected systems elevation models and orthophotos come in (UTM, Web Mercator).
//!
//! The inverse UTM is Snyder's series (USGS Professional Paper 1395, 1987, pp. 63–64), good to
//! millimetres within a zone and to centimetres a few degrees beyond it; the forward UTM is
//! Krüger's series in the third flattening `n` to `n³` (Karney, J. Geodesy 85, 2011, eqs. 7–12),
//! better than a millimetre within a zone; Web Mercator (EPSG:3857) is the spherical Mercator of
//! WGS 84 longitude and latitude on a sphere of radius `A`, exact. All are checked against PROJ's
//! answers (`gdaltransform`, tests/data/geodesy.sh).
//!
//! ETRS89 (EPSG:4258, UTM 25828–25838) and NAD83 (EPSG:4269, UTM 26901–26923) coordinates are
//! taken as WGS 84, as PROJ does when no transformation grid is installed (its null
//! transformations EPSG:1149 and EPSG:1188, stated accuracy 1 m and 4 m). A grid's heights are taken as
//! ellipsoidal heights: elevation models usually give heights above a geoid (SRTM: EGM96), which
//! differ from WGS 84 ellipsoidal heights by the geoid undulation (−106 to +85 m worldwide).

use crate::dem::{CrsKind, Georef};

/// WGS 84 semi-major axis, metres.
pub const A: f64 = 6_378_137.0;
/// WGS 84 flattening.
pub const F: f64 = 1.0 / 298.257_223_563;

/// ECEF `[x, y, z]` in metres of longitude and latitude in degrees and ellipsoidal height `h`.
pub fn ecef(lon_deg: f64, lat_deg: f64, h: f64) -> [f64; 3] {
    let e2 = F * (2.0 - F);
    let (lon, lat) = (lon_deg.to_radians(), lat_deg.to_radians());
    let n = A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
    [
        (n + h) * lat.cos() * lon.cos(),
        (n + h) * lat.cos() * lon.sin(),
        (n * (1.0 - e2) + h) * lat.sin(),
    ]
}

/// The UTM zone (1–60) and hemisphere of a UTM EPSG code: WGS 84 (326zz north, 327zz south),
/// ETRS89 (258zz, zones 28–38 north) or NAD83 (269zz, zones 1–23 north), the last two taken as
/// WGS 84 (see the module docs).
pub fn utm_zone(epsg: u16) -> Option<(u8, bool)> {
    match epsg {
        32601..=32660 => Some(((epsg - 32600) as u8, true)),
        32701..=32760 => Some(((epsg - 32700) as u8, false)),
        25828..=25838 => Some(((epsg - 25800) as u8, true)),
        26901..=26923 => Some(((epsg - 26900) as u8, true)),
        _ => None,
    }
}

/// UTM easting and northing (metres) in `zone`, northern or southern hemisphere, of longitude and
/// latitude in degrees (Krüger's series, see the module docs).
pub fn lonlat_to_utm(zone: u8, north: bool, lon_deg: f64, lat_deg: f64) -> (f64, f64) {
    let k0 = 0.9996;
    let n = F / (2.0 - F);
    let (n2, n3) = (n * n, n * n * n);
    // Rectifying radius and the α coefficients of the series.
    let a_r = A / (1.0 + n) * (1.0 + n2 / 4.0 + n2 * n2 / 64.0);
    let alpha = [
        n / 2.0 - 2.0 / 3.0 * n2 + 5.0 / 16.0 * n3,
        13.0 / 48.0 * n2 - 3.0 / 5.0 * n3,
        61.0 / 240.0 * n3,
    ];
    let lon0 = (zone as f64 * 6.0 - 183.0).to_radians();
    let (phi, dl) = (lat_deg.to_radians(), lon_deg.to_radians() - lon0);
    // Conformal latitude through t = tan χ.
    let e = (F * (2.0 - F)).sqrt();
    let s = phi.sin();
    let t = (s.atanh() - e * (e * s).atanh()).sinh();
    let xi1 = t.atan2(dl.cos());
    let eta1 = (dl.sin() / (1.0 + t * t).sqrt()).atanh();
    let (mut xi, mut eta) = (xi1, eta1);
    for (j, a) in alpha.iter().enumerate() {
        let k = 2.0 * (j + 1) as f64;
        xi += a * (k * xi1).sin() * (k * eta1).cosh();
        eta += a * (k * xi1).cos() * (k * eta1).sinh();
    }
    let easting = 500_000.0 + k0 * a_r * eta;
    let northing = k0 * a_r * xi + if north { 0.0 } else { 10_000_000.0 };
    (easting, northing)
}

/// Web Mercator (EPSG:3857) `x, y` in metres of longitude and latitude in degrees (latitudes
/// beyond ±85.06° map beyond the square world; the poles to infinity).
pub fn lonlat_to_web_mercator(lon_deg: f64, lat_deg: f64) -> (f64, f64) {
    let phi = lat_deg.to_radians();
    (
        A * lon_deg.to_radians(),
        A * (std::f64::consts::FRAC_PI_4 + phi / 2.0).tan().ln(),
    )
}

/// Longitude and latitude in degrees of Web Mercator (EPSG:3857) `x, y` in metres.
pub fn web_mercator_to_lonlat(x: f64, y: f64) -> (f64, f64) {
    let lat = 2.0 * (y / A).exp().atan() - std::f64::consts::FRAC_PI_2;
    ((x / A).to_degrees(), lat.to_degrees())
}

/// Longitude and latitude in degrees of UTM easting and northing (metres) in `zone`, northern or
/// southern hemisphere.
pub fn utm_to_lonlat(zone: u8, north: bool, easting: f64, northing: f64) -> (f64, f64) {
    let k0 = 0.9996;
    let e2 = F * (2.0 - F);
    let ep2 = e2 / (1.0 - e2);
    let y = if north {
        northing
    } else {
        northing - 10_000_000.0
    };
    let m = y / k0;
    let mu = m / (A * (1.0 - e2 / 4.0 - 3.0 * e2 * e2 / 64.0 - 5.0 * e2.powi(3) / 256.0));
    let e1 = (1.0 - (1.0 - e2).sqrt()) / (1.0 + (1.0 - e2).sqrt());
    let phi1 = mu
        + (1.5 * e1 - 27.0 / 32.0 * e1.powi(3)) * (2.0 * mu).sin()
        + (21.0 / 16.0 * e1 * e1 - 55.0 / 32.0 * e1.powi(4)) * (4.0 * mu).sin()
        + (151.0 / 96.0 * e1.powi(3)) * (6.0 * mu).sin()
        + (1097.0 / 512.0 * e1.powi(4)) * (8.0 * mu).sin();
    let (s, c, t) = (phi1.sin(), phi1.cos(), phi1.tan());
    let c1 = ep2 * c * c;
    let t1 = t * t;
    let n1 = A / (1.0 - e2 * s * s).sqrt();
    let r1 = A * (1.0 - e2) / (1.0 - e2 * s * s).powf(1.5);
    let d = (easting - 500_000.0) / (n1 * k0);
    let lat = phi1
        - (n1 * t / r1)
            * (d * d / 2.0
                - (5.0 + 3.0 * t1 + 10.0 * c1 - 4.0 * c1 * c1 - 9.0 * ep2) * d.powi(4) / 24.0
                + (61.0 + 90.0 * t1 + 298.0 * c1 + 45.0 * t1 * t1 - 252.0 * ep2 - 3.0 * c1 * c1)
                    * d.powi(6)
                    / 720.0);
    let lon0 = (zone as f64 * 6.0 - 183.0).to_radians();
    let lon = lon0
        + (d - (1.0 + 2.0 * t1 + c1) * d.powi(3) / 6.0
            + (5.0 - 2.0 * c1 + 28.0 * t1 - 3.0 * c1 * c1 + 8.0 * ep2 + 24.0 * t1 * t1)
                * d.powi(5)
                / 120.0)
            / c;
    (lon.to_degrees(), lat.to_degrees())
}

/// How a georeference's grid coordinates become longitude and latitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// Grid coordinates are longitude and latitude in degrees.
    Geographic,
    /// Grid coordinates are UTM easting and northing of `zone`.
    Utm { zone: u8, north: bool },
    /// Grid coordinates are Web Mercator (EPSG:3857) metres.
    WebMercator,
}

impl Placement {
    /// The placement of `georef`, or `None` where it has none this module knows (a local grid, or
    /// a projected one other than UTM and Web Mercator).
    pub fn of(georef: &Georef) -> Option<Placement> {
        match georef.crs {
            CrsKind::Geographic => Some(Placement::Geographic),
            CrsKind::Projected if georef.is_web_mercator() => Some(Placement::WebMercator),
            CrsKind::Projected => georef
                .epsg
                .and_then(utm_zone)
                .map(|(zone, north)| Placement::Utm { zone, north }),
            CrsKind::Local => None,
        }
    }

    /// Longitude and latitude in degrees of grid coordinates `(x, y)`.
    pub fn lonlat(&self, x: f64, y: f64) -> (f64, f64) {
        match *self {
            Placement::Geographic => (x, y),
            Placement::Utm { zone, north } => utm_to_lonlat(zone, north, x, y),
            Placement::WebMercator => web_mercator_to_lonlat(x, y),
        }
    }

    /// Grid coordinates of longitude and latitude in degrees (the inverse of [`Placement::lonlat`]).
    pub fn xy(&self, lon_deg: f64, lat_deg: f64) -> (f64, f64) {
        match *self {
            Placement::Geographic => (lon_deg, lat_deg),
            Placement::Utm { zone, north } => lonlat_to_utm(zone, north, lon_deg, lat_deg),
            Placement::WebMercator => lonlat_to_web_mercator(lon_deg, lat_deg),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poles_and_equator_are_on_the_axes() {
        let p = ecef(0.0, 0.0, 0.0);
        assert_eq!(p, [A, 0.0, 0.0]);
        let q = ecef(0.0, 90.0, 0.0);
        let b = A * (1.0 - F);
        assert!(q[0].abs() < 1e-6 && (q[2] - b).abs() < 1e-6, "{q:?}");
    }

    #[test]
    fn central_meridian_and_equator_invert_exactly() {
        // Easting 500 km is the zone's central meridian; northing 0 the equator.
        let (lon, lat) = utm_to_lonlat(33, true, 500_000.0, 0.0);
        assert!(
            (lon - 15.0).abs() < 1e-12 && lat.abs() < 1e-12,
            "{lon} {lat}"
        );
        assert_eq!(utm_zone(32619), Some((19, true)));
        assert_eq!(utm_zone(32733), Some((33, false)));
        assert_eq!(utm_zone(4326), None);
    }
}

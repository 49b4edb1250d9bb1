//! WGS 84 geodesy for placing a terrain on the globe: longitude/latitude/height to earth-centred,
//! earth-fixed (ECEF) coordinates, and UTM grid coordinates back to longitude/latitude.
//!
//! The inverse UTM is Snyder's series (USGS Professional Paper 1395, 1987, pp. 63–64), good to
//! millimetres within a zone and to centimetres a few degrees beyond it; both are checked against
//! PROJ's answers (`gdaltransform`, tests/data/geodesy.sh). A grid's heights are taken as
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

/// The UTM zone (1–60) and hemisphere of a WGS 84 UTM EPSG code (326zz north, 327zz south).
pub fn utm_zone(epsg: u16) -> Option<(u8, bool)> {
    match epsg {
        32601..=32660 => Some(((epsg - 32600) as u8, true)),
        32701..=32760 => Some(((epsg - 32700) as u8, false)),
        _ => None,
    }
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
}

impl Placement {
    /// The placement of `georef`, or `None` where it has none this module knows (a local grid, or
    /// a projected one other than WGS 84 UTM).
    pub fn of(georef: &Georef) -> Option<Placement> {
        match georef.crs {
            CrsKind::Geographic => Some(Placement::Geographic),
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

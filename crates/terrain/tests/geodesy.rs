//! The geodesy under the 3D Tiles export and photo reprojection, against PROJ's coordinates
//! (`gdaltransform`, tests/data/geodesy.sh): UTM both ways, earth-centred coordinates, Web
//! Mercator.

use std::path::PathBuf;

use texmap_terrain::geodesy::{
    ecef, lonlat_to_utm, lonlat_to_web_mercator, utm_to_lonlat, utm_zone, web_mercator_to_lonlat,
};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn gdal_lines(kind: &str) -> Vec<Vec<f64>> {
    std::fs::read_to_string(data("geodesy_gdal.txt"))
        .unwrap()
        .lines()
        .filter(|l| l.starts_with(kind))
        .map(|l| {
            l.split_whitespace()
                .skip(1)
                .map(|x| x.parse().unwrap())
                .collect()
        })
        .collect()
}

#[test]
fn inverse_utm_matches_proj() {
    let pts = gdal_lines("utm ");
    assert_eq!(pts.len(), 10);
    for p in pts {
        let (zone, north) = utm_zone(p[0] as u16).unwrap();
        let (lon, lat) = utm_to_lonlat(zone, north, p[3], p[4]);
        // 1e-7 degrees is about a centimetre.
        assert!(
            (lon - p[1]).abs() < 1e-7 && (lat - p[2]).abs() < 1e-7,
            "EPSG:{} ({}, {}) -> ({lon}, {lat}), PROJ ({}, {})",
            p[0],
            p[3],
            p[4],
            p[1],
            p[2]
        );
    }
}

#[test]
fn ecef_matches_proj() {
    let pts = gdal_lines("ecef ");
    assert_eq!(pts.len(), 5);
    for p in pts {
        let got = ecef(p[0], p[1], p[2]);
        for k in 0..3 {
            assert!((got[k] - p[3 + k]).abs() < 1e-3, "{p:?}: {got:?}");
        }
    }
}

#[test]
fn forward_utm_matches_proj() {
    let pts = gdal_lines("utm ");
    assert_eq!(pts.len(), 10);
    for p in pts {
        let (zone, north) = utm_zone(p[0] as u16).unwrap();
        let (e, n) = lonlat_to_utm(zone, north, p[1], p[2]);
        // Up to 3.3° from the central meridian (−66.2° in zone 19 at 60° N): a millimetre.
        assert!(
            (e - p[3]).abs() < 1e-3 && (n - p[4]).abs() < 1e-3,
            "EPSG:{} ({}, {}) -> ({e}, {n}), PROJ ({}, {})",
            p[0],
            p[1],
            p[2],
            p[3],
            p[4]
        );
    }
}

#[test]
fn web_mercator_matches_proj_and_inverts() {
    let pts = gdal_lines("merc ");
    assert_eq!(pts.len(), 6);
    for p in pts {
        let (x, y) = lonlat_to_web_mercator(p[0], p[1]);
        assert!(
            (x - p[2]).abs() < 1e-6 * p[2].abs().max(1.0)
                && (y - p[3]).abs() < 1e-6 * p[3].abs().max(1.0),
            "({}, {}) -> ({x}, {y}), PROJ ({}, {})",
            p[0],
            p[1],
            p[2],
            p[3]
        );
        let (lon, lat) = web_mercator_to_lonlat(p[2], p[3]);
        assert!((lon - p[0]).abs() < 1e-9 && (lat - p[1]).abs() < 1e-9);
    }
}

#[test]
fn utm_round_trips_across_a_zone() {
    // Forward (Krüger) then inverse (Snyder): within 2 cm up to 3° from the central meridian.
    for (zone, north) in [(19u8, true), (33, false), (1, true)] {
        let lon0 = zone as f64 * 6.0 - 183.0;
        for dl in [-3.0, -1.0, 0.0, 0.5, 2.9] {
            for lat in [-79.0, -45.0, -0.5, 0.0, 0.5, 30.0, 60.0, 83.0] {
                let (e, n) = lonlat_to_utm(zone, north, lon0 + dl, lat);
                let (lon, lat2) = utm_to_lonlat(zone, north, e, n);
                let metres = ((lon - lon0 - dl) * 111_320.0 * f64::cos(lat.to_radians()))
                    .hypot((lat2 - lat) * 110_574.0);
                assert!(metres < 0.02, "zone {zone} ({dl}, {lat}): {metres} m");
            }
        }
    }
    // The other datums' UTM codes are zones of the same projection.
    assert_eq!(utm_zone(25832), Some((32, true)));
    assert_eq!(utm_zone(26918), Some((18, true)));
}

//! Recorded flights written by other programs (tests/data/track.py: GPX by gpxpy and by GDAL's
//! GPX driver, IGC by aerofiles) read as those programs read them back, and replayed over the
//! Mount Washington grid: heading along the glide, the thermalling circles' bank against a
//! coordinated turn's, the glide out past the grid's edge left out.

use std::path::PathBuf;

use texmap_terrain::dem::{Grid, ReadOptions, read_dem};
use texmap_terrain::track::{Track, TrackOptions, read_track, track_views};
use texmap_terrain::view::FlightCamera;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn grid() -> Grid {
    read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap()
}

const FILES: [&str; 3] = ["track_gpxpy.gpx", "track_ogr.gpx", "track_aerofiles.igc"];

/// The other program's reading of `file`: (lat, lon, altitude, unix time) per fix.
fn reference(file: &str) -> Vec<[f64; 4]> {
    std::fs::read_to_string(data("track_reference.txt"))
        .unwrap()
        .lines()
        .filter(|l| l.starts_with(&format!("{file} ")))
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .skip(1)
                .map(|x| x.parse().unwrap())
                .collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

#[test]
fn fixes_equal_the_writers_own_readings() {
    for file in FILES {
        let t: Track = read_track(&data(file)).unwrap();
        let want = reference(file);
        assert_eq!(t.fixes.len(), 280, "{file}");
        assert_eq!(want.len(), 280, "{file}");
        for (f, w) in t.fixes.iter().zip(&want) {
            assert!(
                (f.lat - w[0]).abs() < 1e-12 && (f.lon - w[1]).abs() < 1e-12,
                "{file} line {}: {} {} vs {w:?}",
                f.line,
                f.lat,
                f.lon
            );
            assert_eq!(f.altitude, Some(w[2]), "{file} line {}", f.line);
            assert_eq!(f.time, Some(w[3]), "{file} line {}", f.line);
        }
    }
}

#[test]
fn replayed_flights_look_along_the_track_and_bank_in_the_circles() {
    let grid = grid();
    let template = FlightCamera {
        width: 64,
        height: 48,
        ..FlightCamera::over(&grid)
    };
    // The writer's flight: 40 s of glide on 50° true, two right-hand circles of 300 m at
    // 24 m/s (157 s), the glide on. UTM 19N's grid north is 1.6° west of true north at
    // 71.3° W, 44.3° N, so the glide's grid heading is about 51.6°.
    let bank = (24.0f64 * 24.0 / (9.806_65 * 300.0)).atan().to_degrees();
    for (file, tol) in [
        ("track_gpxpy.gpx", 0.3),
        ("track_ogr.gpx", 0.3),
        // Thousandths of a minute: positions quantised to ~1.3 m east, 1.85 m north.
        ("track_aerofiles.igc", 1.5),
    ] {
        let t = read_track(&data(file)).unwrap();
        let v = track_views(&t, &grid, &template, &TrackOptions::default()).unwrap();
        // One view per fix; the last fixes lie east of the grid.
        assert!(v.outside > 5 && v.outside < 40, "{file}: {}", v.outside);
        assert_eq!(v.views.len() + v.outside, 280);
        assert_eq!(v.lifted, 0);
        for c in &v.views[5..35] {
            assert!(
                (c.heading_deg - 51.6).abs() < 1.0 + tol,
                "{file}: {}",
                c.heading_deg
            );
            assert!(c.roll_deg.abs() < tol, "{file}: roll {}", c.roll_deg);
            assert_eq!(c.pitch_deg, -10.0);
        }
        for c in &v.views[50..185] {
            assert!(
                (c.roll_deg - bank).abs() < tol,
                "{file}: {} vs {bank}",
                c.roll_deg
            );
        }
        // The IGC altitudes are GNSS ones in whole metres, the GPX ones to a decimetre.
        assert!((v.views[0].altitude - 1950.0).abs() < 0.51);
    }
}

#[test]
fn speedup_samples_the_tracks_clock() {
    let grid = grid();
    let template = FlightCamera {
        width: 64,
        height: 48,
        ..FlightCamera::over(&grid)
    };
    let t = read_track(&data("track_ogr.gpx")).unwrap();
    // 279 s at 20x and 5 frames a second: a frame every 4 s, 70 in all, less those off the grid.
    let opts = TrackOptions {
        speedup: Some(20.0),
        fps: 5.0,
        above: 50.0,
        ..TrackOptions::default()
    };
    let v = track_views(&t, &grid, &template, &opts).unwrap();
    assert_eq!(v.views.len() + v.outside, 70);
    // Frame 10 is fix 40 (40 s in), 50 m above its altitude.
    let f = &t.fixes[40];
    assert!((v.views[10].altitude - (f.altitude.unwrap() + 50.0)).abs() < 1e-9);
    // Halfway between two fixes: the mean of their altitudes.
    let opts = TrackOptions {
        speedup: Some(1.0),
        fps: 2.0,
        ..TrackOptions::default()
    };
    let v = track_views(&t, &grid, &template, &opts).unwrap();
    let (a, b) = (t.fixes[3].altitude.unwrap(), t.fixes[4].altitude.unwrap());
    assert!((v.views[7].altitude - 0.5 * (a + b)).abs() < 1e-9);
}

#[test]
fn bad_tracks_name_their_line() {
    use texmap_terrain::track::{parse_gpx, parse_igc};
    let e = parse_gpx(
        "<gpx>\n<trk><trkseg>\n<trkpt lat=\"44.2\" lon=\"-71.3\"/>\n<trkpt lat=\"95\" lon=\"-71.3\"/>\n</trkseg></trk></gpx>",
        "bad.gpx",
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "bad.gpx:4: <trkpt> lat=\"95\": expected degrees within ±90"
    );
    let e = parse_gpx("<gpx><trk><trkpt lat=\"1\"", "cut.gpx")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("cut.gpx:1:") && e.contains("XML"), "{e}");
    let e = parse_gpx(
        "<gpx><trk><trkseg><trkpt lat=\"44.2\" lon=\"-71.3\"><time>noon</time></trkpt></trkseg></trk></gpx>",
        "t.gpx",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("<time>noon</time>: expected an ISO 8601 time"),
        "{e}"
    );
    let e = parse_igc(
        "HFDTE150723\nB1458304415300N07120100WA019200195\n",
        "short.igc",
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("short.igc:2: B record: 34 characters"), "{e}");
    assert!(parse_gpx("<gpx></gpx>", "empty.gpx").is_err());
    // Off the grid entirely: named, not an empty movie.
    let far = parse_gpx(
        "<gpx><trk><trkseg><trkpt lat=\"46.0\" lon=\"7.0\"/><trkpt lat=\"46.1\" lon=\"7.0\"/></trkseg></trk></gpx>",
        "alps.gpx",
    )
    .unwrap();
    let grid = grid();
    let e = track_views(
        &far,
        &grid,
        &FlightCamera::over(&grid),
        &TrackOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("alps.gpx: no fix of the track lies over the grid"),
        "{e}"
    );
    // A replay by the clock needs every fix's time.
    let e = track_views(
        &far,
        &grid,
        &FlightCamera::over(&grid),
        &TrackOptions {
            speedup: Some(10.0),
            ..TrackOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("alps.gpx:1: a fix without a time"), "{e}");
}

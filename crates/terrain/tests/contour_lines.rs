//! `contour_lines` against `gdal_contour` 3.6.2's own GeoJSON (tests/data/gdal_contour.sh): levels
//! by interval and offset, fixed and exponential, heights exactly on levels, `-snodata`, no-data
//! holes on the edges, rings, `-3d`, geographic and UTM grids.
//!
//! The comparison is strict: the same features in the same order (GDAL's `ID`s), the same
//! properties, the same `crs` member, and every vertex equal within 1e-9 of the grid's units.
//! GDAL prints 15 decimals, so its files hold the exact doubles to within 1e-14 (degrees) and
//! the measured largest difference is that printing's rounding; 1e-9 leaves room for the corner
//! of a georeference recovered from its first sample's centre (one unit in the last place).

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use texmap_terrain::contour_lines::{
    ContourLine, ContourOptions, Levels, WriteOptions, contour_lines, write_geojson,
};
use texmap_terrain::dem::{Grid, ReadOptions, read_dem};

/// The largest coordinate difference accepted (grid units), see the module docs.
const TOL: f64 = 1e-9;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn input(file: &str) -> Grid {
    read_dem(data(file), &ReadOptions::default()).unwrap()
}

fn interval(interval: f64, offset: f64) -> Levels {
    Levels::Interval { interval, offset }
}

/// Ours written as GeoJSON into `dir`.
fn write_ours(dir: &Path, grid: &Grid, lines: &[ContourLine], opts: &WriteOptions) -> PathBuf {
    let path = dir.join("ours.geojson");
    write_geojson(&path, lines, grid.georef(), opts).unwrap();
    path
}

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Every feature's coordinates, read from the text of a file that holds one feature a line (as
/// GDAL and we write them) with Rust's correctly rounded parsing: serde_json's float parsing
/// (without its `float_roundtrip` feature) may be a unit in the last place off.
fn coordinates(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| l.split_once("\"coordinates\": "))
        .map(|(_, c)| {
            c.split(|ch: char| !(ch.is_ascii_digit() || "+-.eE".contains(ch)))
                .filter(|t| !t.is_empty())
                .map(|t| t.parse::<f64>().unwrap())
                .collect()
        })
        .collect()
}

/// Feature for feature, property for property, vertex for vertex; the largest difference.
fn compare(name: &str, gdal: &Path, ours: &Path) -> f64 {
    let (gj, oj) = (read_json(gdal), read_json(ours));
    assert_eq!(gj["crs"], oj["crs"], "{name}: crs member");
    let (g, o) = (
        gj["features"].as_array().unwrap(),
        oj["features"].as_array().unwrap(),
    );
    assert_eq!(g.len(), o.len(), "{name}: feature count (GDAL, ours)");
    for (i, (g, o)) in g.iter().zip(o).enumerate() {
        assert_eq!(
            g["properties"], o["properties"],
            "{name}: feature {i}: properties"
        );
        assert_eq!(g["geometry"]["type"], "LineString");
        assert_eq!(o["geometry"]["type"], "LineString");
        let (gn, on) = (
            g["geometry"]["coordinates"].as_array().unwrap(),
            o["geometry"]["coordinates"].as_array().unwrap(),
        );
        assert_eq!(gn.len(), on.len(), "{name}: feature {i}: vertex count");
        assert_eq!(
            gn[0].as_array().unwrap().len(),
            on[0].as_array().unwrap().len(),
            "{name}: feature {i}: dimension"
        );
    }
    let (gc, oc) = (coordinates(gdal), coordinates(ours));
    assert_eq!(gc.len(), g.len(), "{name}: one feature a line");
    let mut worst = 0.0f64;
    for (i, (gv, ov)) in gc.iter().zip(&oc).enumerate() {
        assert_eq!(gv.len(), ov.len(), "{name}: feature {i}: coordinate count");
        for (j, (&a, &b)) in gv.iter().zip(ov).enumerate() {
            let d = (a - b).abs();
            worst = worst.max(d);
            assert!(
                d <= TOL,
                "{name}: feature {i} coordinate {j}: GDAL {a}, ours {b}, tolerance {TOL}"
            );
        }
    }
    worst
}

/// One fixture of gdal_contour.sh against ours with the same options.
fn check(fixture: &str, file: &str, levels: Levels, opts: ContourOptions, write: WriteOptions) {
    let grid = input(file);
    let lines = contour_lines(&grid, &levels, &opts).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let ours = write_ours(dir.path(), &grid, &lines, &write);
    let gdal = data(&format!("gdal_contour/{fixture}.geojson"));
    let worst = compare(fixture, &gdal, &ours);
    eprintln!(
        "{fixture}: {} lines equal to GDAL's, largest difference {worst:e}",
        lines.len()
    );
}

fn elev() -> WriteOptions {
    WriteOptions {
        attr: Some("ELEV".into()),
        three_d: false,
    }
}

#[test]
fn contour_heights_on_levels_count_as_above_them() {
    let none = ContourOptions::default();
    check(
        "onlevel_i1",
        "contour_onlevel.asc",
        interval(1.0, 0.0),
        none.clone(),
        elev(),
    );
    // The lowest height (0, the pit) has no line; the highest (9) has one.
    let g = input("contour_onlevel.asc");
    let lines = contour_lines(&g, &interval(1.0, 0.0), &none).unwrap();
    assert!(lines.iter().all(|l| l.level != 0.0));
    assert!(lines.iter().any(|l| l.level == 9.0));
    check(
        "onlevel_noattr",
        "contour_onlevel.asc",
        interval(2.0, 0.0),
        none,
        WriteOptions::default(),
    );
}

#[test]
fn contour_fixed_and_exponential_levels_equal_gdal() {
    let none = ContourOptions::default();
    check(
        "onlevel_fl",
        "contour_onlevel.asc",
        Levels::Fixed(vec![2.5, 4.0, 6.5, 9.0]),
        none.clone(),
        elev(),
    );
    // Departure: the list is sorted first (GDAL 3.6.2 would drop 2.5 and 4 from this order).
    check(
        "onlevel_fl",
        "contour_onlevel.asc",
        Levels::Fixed(vec![9.0, 6.5, 4.0, 2.5, 4.0]),
        none.clone(),
        elev(),
    );
    check(
        "onlevel_e2",
        "contour_onlevel.asc",
        Levels::Exponential { base: 2.0 },
        none,
        elev(),
    );
}

#[test]
fn contour_snodata_stops_lines_as_gdal() {
    check(
        "onlevel_i1_snodata0",
        "contour_onlevel.asc",
        interval(1.0, 0.0),
        ContourOptions { nodata: Some(0.0) },
        elev(),
    );
}

#[test]
fn contour_snodata_keeps_the_files_nodata() {
    // Departure: GDAL's -snodata replaces the file's no-data (its -9999 holes would become
    // heights); ours adds to it, so a value the grid does not hold changes nothing.
    let g = input("gdaldem_holes.asc");
    let l = interval(100.0, 0.0);
    let plain = contour_lines(&g, &l, &ContourOptions::default()).unwrap();
    let extra = contour_lines(&g, &l, &ContourOptions { nodata: Some(1.5) }).unwrap();
    assert_eq!(plain, extra);
}

#[test]
fn contour_rings_close_as_gdal() {
    check(
        "rings_i10",
        "contour_rings.asc",
        interval(10.0, 0.0),
        ContourOptions::default(),
        elev(),
    );
    let g = input("contour_rings.asc");
    let lines = contour_lines(&g, &interval(10.0, 0.0), &ContourOptions::default()).unwrap();
    assert!(
        lines.iter().filter(|l| l.is_closed()).count() >= 4,
        "the peak and the pit give rings"
    );
    check(
        "rings_i7_off3_3d",
        "contour_rings.asc",
        interval(7.0, 3.0),
        ContourOptions::default(),
        WriteOptions {
            attr: Some("ELEV".into()),
            three_d: true,
        },
    );
}

#[test]
fn contour_nodata_holes_and_georeferences_equal_gdal() {
    let none = ContourOptions::default();
    check(
        "holes_i100",
        "gdaldem_holes.asc",
        interval(100.0, 0.0),
        none.clone(),
        elev(),
    );
    check(
        "geo_i40",
        "gdaldem_geo.tif",
        interval(40.0, 0.0),
        none.clone(),
        elev(),
    );
    check(
        "utm_i200_off50_3d",
        "hillshade_dem_utm.tif",
        interval(200.0, 50.0),
        none,
        WriteOptions {
            attr: Some("HEIGHT".into()),
            three_d: true,
        },
    );
}

#[test]
fn contour_write_is_atomic() {
    let g = input("contour_rings.asc");
    let lines = contour_lines(&g, &interval(10.0, 0.0), &ContourOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("missing/dir/out.geojson");
    assert!(write_geojson(&path, &lines, g.georef(), &elev()).is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Total length per level (grid units) and the feature count per level of a FeatureCollection.
fn per_level(json: &Value, attr: &str) -> std::collections::BTreeMap<i64, (usize, f64)> {
    let mut m = std::collections::BTreeMap::new();
    for f in json["features"].as_array().unwrap() {
        let level = f["properties"][attr].as_f64().unwrap();
        let c = f["geometry"]["coordinates"].as_array().unwrap();
        let len: f64 = c
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0].as_array().unwrap(), w[1].as_array().unwrap());
                let d = |i: usize| b[i].as_f64().unwrap() - a[i].as_f64().unwrap();
                d(0).hypot(d(1))
            })
            .sum();
        let e = m.entry((level * 1000.0).round() as i64).or_insert((0, 0.0));
        e.0 += 1;
        e.1 += len;
    }
    m
}

#[test]
fn contour_whole_srtm_tile_equals_live_gdal() {
    let hgt = data("N44W072.hgt");
    let dir = tempfile::tempdir().unwrap();
    let gdal_out = dir.path().join("gdal.geojson");
    let ran = Command::new("gdal_contour")
        .args(["-q", "-f", "GeoJSON", "-i", "50", "-a", "ELEV"])
        .arg(&hgt)
        .arg(&gdal_out)
        .status();
    if !matches!(ran, Ok(s) if s.success()) {
        eprintln!("SKIPPED: gdal_contour is not available");
        return;
    }
    let g = read_dem(&hgt, &ReadOptions::default()).unwrap();
    let lines = contour_lines(&g, &interval(50.0, 0.0), &ContourOptions::default()).unwrap();
    let ours = write_ours(dir.path(), &g, &lines, &elev());
    let (gm, om) = (
        per_level(&read_json(&gdal_out), "ELEV"),
        per_level(&read_json(&ours), "ELEV"),
    );
    assert_eq!(
        gm.keys().collect::<Vec<_>>(),
        om.keys().collect::<Vec<_>>(),
        "levels"
    );
    for (k, (gn, gl)) in &gm {
        let (on, ol) = om[k];
        assert_eq!(
            *gn,
            on,
            "level {}: feature count (GDAL, ours)",
            *k as f64 / 1000.0
        );
        assert!(
            (gl - ol).abs() <= 1e-9 * gl.max(1.0),
            "level {}: total length GDAL {gl}, ours {ol}, tolerance 1e-9 relative",
            *k as f64 / 1000.0
        );
    }
    // And line for line.
    let worst = compare("N44W072 -i 50", &gdal_out, &ours);
    eprintln!(
        "N44W072 -i 50: {} lines equal to GDAL's, largest difference {worst:e}",
        lines.len()
    );
}

#[test]
fn contour_shapefiles_equal_live_gdal() {
    use texmap_terrain::contour_lines::write_shapefile;
    let dir = tempfile::tempdir().unwrap();
    for (file, three_d) in [("hillshade_dem_utm.tif", true), ("gdaldem_geo.tif", false)] {
        let gdal = dir.path().join("gdal.shp");
        let mut cmd = Command::new("gdal_contour");
        cmd.args(["-q", "-i", "100", "-a", "ELEV"]);
        if three_d {
            cmd.arg("-3d");
        }
        if !matches!(cmd.arg(data(file)).arg(&gdal).status(), Ok(s) if s.success()) {
            eprintln!("SKIPPED: gdal_contour is not available");
            return;
        }
        let g = input(file);
        let lines = contour_lines(&g, &interval(100.0, 0.0), &ContourOptions::default()).unwrap();
        let ours = dir.path().join("ours.shp");
        let opts = WriteOptions {
            attr: Some("ELEV".into()),
            three_d,
        };
        assert!(write_shapefile(&ours, &lines, g.georef(), &opts).unwrap());
        let read = |p: &Path, ext: &str| std::fs::read(p.with_extension(ext)).unwrap();
        for ext in ["shp", "shx", "prj"] {
            assert!(
                read(&gdal, ext) == read(&ours, ext),
                "{file}: .{ext} differs from GDAL's"
            );
        }
        // The .dbf holds the day it was written (bytes 1..4).
        let (mut a, mut b) = (read(&gdal, "dbf"), read(&ours, "dbf"));
        a[1..4].fill(0);
        b[1..4].fill(0);
        assert!(a == b, "{file}: .dbf differs from GDAL's");
        // Our own reader reads it back.
        let layer = texmap_terrain::shapefile::read_shapefile(&ours).unwrap();
        assert_eq!(layer.features.len(), lines.len());
        for ext in ["shp", "shx", "dbf", "prj"] {
            std::fs::remove_file(gdal.with_extension(ext)).unwrap();
        }
    }
}

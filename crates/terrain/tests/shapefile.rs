//! ESRI shapefiles (`texmap_terrain::shapefile`) against GDAL: the features of vector.sh written
//! by ogr2ogr as shapefiles of each kind (tests/data/shapefile.sh: polygons, PolygonZ, polylines,
//! a multipoint layer, a point layer without a .prj, lines reprojected to degrees) must be the
//! features ogr2ogr wrote as GeoJSON from the same source, in the same system; damaged files are
//! refused with the byte offset, never a panic.

use std::path::PathBuf;

use texmap_terrain::dem::{ReadOptions, read_dem};
use texmap_terrain::shapefile::{parse_shp, read_shapefile};
use texmap_terrain::vector::{Feature, LayerCrs, Overlay, Style, read_geojson, read_vector};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The GeoJSON features of one kind (those with rings, lines or points), geometry only.
fn geojson_kind(file: &str, kind: &str) -> Vec<Feature> {
    read_geojson(data(file))
        .unwrap()
        .features
        .into_iter()
        .filter(|f| match kind {
            "area" => !f.rings.is_empty(),
            "line" => !f.lines.is_empty(),
            _ => !f.points.is_empty(),
        })
        .map(|f| Feature {
            style: Default::default(),
            ..f
        })
        .collect()
}

/// A ring as a closed cycle, whatever its start and direction: opened, started at its least
/// vertex, run toward the lesser of that vertex's neighbours, closed again (shapefiles store
/// outer rings clockwise, GeoJSON as the source had them).
fn canonical(ring: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut open = ring.to_vec();
    if open.len() > 1 && open.first() == open.last() {
        open.pop();
    }
    let n = open.len();
    let less = |a: &[f64; 2], b: &[f64; 2]| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]));
    let start = (0..n)
        .min_by(|&i, &j| less(&open[i], &open[j]))
        .unwrap_or(0);
    let forward: Vec<_> = (0..n).map(|k| open[(start + k) % n]).collect();
    let backward: Vec<_> = (0..n).map(|k| open[(start + n - k) % n]).collect();
    let mut best = if n > 1 && less(&backward[1], &forward[1]).is_lt() {
        backward
    } else {
        forward
    };
    if let Some(&p) = best.first() {
        best.push(p);
    }
    best
}

/// The largest coordinate difference between two feature lists of the same shapes.
fn difference(a: &[Feature], b: &[Feature]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut worst: f64 = 0.0;
    for (f, g) in a.iter().zip(b) {
        let parts = |f: &Feature| {
            let mut v = vec![f.points.clone()];
            v.extend(f.lines.clone());
            v.extend(f.rings.iter().map(|r| canonical(r)));
            v
        };
        let (p, q) = (parts(f), parts(g));
        assert_eq!(p.len(), q.len());
        for (x, y) in p.iter().zip(&q) {
            assert_eq!(x.len(), y.len());
            for (u, v) in x.iter().zip(y) {
                worst = worst.max((u[0] - v[0]).abs()).max((u[1] - v[1]).abs());
            }
        }
    }
    worst
}

#[test]
fn every_kind_is_gdals_geojson() {
    for (shp, kind) in [
        ("shp_utm_area.shp", "area"),
        ("shp_z_area.shp", "area"),
        ("shp_utm_line.shp", "line"),
        ("shp_utm_point.shp", "point"),
    ] {
        let layer = read_shapefile(data(shp)).unwrap();
        assert!(matches!(layer.crs, LayerCrs::Epsg(32619, _)), "{shp}");
        let want = geojson_kind("vector_utm.geojson", kind);
        let d = difference(&layer.features, &want);
        assert!(d < 1e-6, "{shp}: {d} m");
    }
    // The lake's hole and the forest's two parts are rings; the trail's two parts lines.
    let areas = read_shapefile(data("shp_utm_area.shp")).unwrap();
    assert_eq!(
        areas
            .features
            .iter()
            .map(|f| f.rings.len())
            .collect::<Vec<_>>(),
        [2, 2]
    );
    // Degrees, reprojected by GDAL: as the RFC 7946 file has them (7 decimals).
    let lines = read_vector(data("shp_wgs84_line.shp")).unwrap();
    assert_eq!(lines.crs, LayerCrs::Lonlat);
    let d = difference(
        &lines.features,
        &geojson_kind("vector_wgs84.geojson", "line"),
    );
    assert!(d < 1e-7, "{d}°");
    // No .prj: degrees, since every coordinate is one.
    let summit = read_shapefile(data("shp_noprj_point.shp")).unwrap();
    assert_eq!(summit.crs, LayerCrs::Lonlat);
    let want = &geojson_kind("vector_wgs84.geojson", "point")[..1];
    assert!(difference(&summit.features, want) < 1e-7);
}

#[test]
fn a_shapefile_overlay_draws_as_its_geojson() {
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let mut geo = read_geojson(data("vector_utm.geojson")).unwrap();
    geo.features.retain(|f| !f.lines.is_empty());
    for f in &mut geo.features {
        f.style = Default::default();
    }
    let shp = read_shapefile(data("shp_utm_line.shp")).unwrap();
    let draw = |layer| {
        let overlay = Overlay::place(&[layer], &Style::default(), &grid, 256, 256).unwrap();
        let mut map = image::RgbaImage::from_pixel(256, 256, image::Rgba([0, 0, 0, 255]));
        overlay.draw(0, 0, &mut map);
        map
    };
    let ours = draw(shp);
    assert_eq!(ours, draw(geo));
    assert!(ours.pixels().filter(|p| p.0[0] > 0).count() > 500);
}

#[test]
fn damaged_files_are_refused_with_the_byte() {
    let good = std::fs::read(data("shp_utm_area.shp")).unwrap();
    let err = |bytes: &[u8]| parse_shp(bytes, "x.shp").unwrap_err().to_string();
    assert!(err(&good[..60]).contains("100-byte shapefile header"));
    let mut b = good.clone();
    b[3] = 0;
    assert!(err(&b).contains("byte 0") && err(&b).contains("9994"));
    // The header claims more than the file holds.
    let mut b = good.clone();
    b[24..28].copy_from_slice(&100_000i32.to_be_bytes());
    assert!(err(&b).contains("byte 24"), "{}", err(&b));
    // A record claiming more points than it holds: the first record's point count.
    let mut b = good.clone();
    b[100 + 8 + 40..100 + 8 + 44].copy_from_slice(&1_000_000i32.to_le_bytes());
    let e = err(&b);
    assert!(
        e.contains("byte 148") && e.contains("1000000 points"),
        "{e}"
    );
    // A negative part start.
    let mut b = good.clone();
    b[100 + 8 + 44..100 + 8 + 48].copy_from_slice(&(-3i32).to_le_bytes());
    assert!(err(&b).contains("part 0's first point"), "{}", err(&b));
    // Every single-byte change and every cut: an answer, never a panic.
    for at in 0..good.len() {
        for v in [0u8, 0x7f, 0xff] {
            let mut b = good.clone();
            b[at] = v;
            let _ = parse_shp(&b, "x.shp");
        }
        let _ = parse_shp(&good[..at], "x.shp");
    }
}

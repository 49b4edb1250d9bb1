//! A real SRTM tile, `N44W072.hgt` (3 arc-seconds, 1201², the White Mountains of New Hampshire with
//! Mount Washington), from tkrajina/srtm.py's test files; SRTM heights are public domain
//! (NASA/USGS). Our reader is compared with GDAL's SRTMHGT driver (`tests/data/srtm_facts.sh`: its
//! georeference, statistics over all 1.44 M samples and 260 sample values), its spacing in metres
//! with the WGS 84 ellipsoid's radii of curvature, and its meshes with every sample by brute force.

use std::path::PathBuf;

use texmap_terrain::dem::{CrsKind, ReadOptions, read_dem};
use texmap_terrain::rtin::{ErrorMap, extract, pad_to_rtin};

mod common;
use common::true_error;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tile() -> texmap_terrain::dem::Grid {
    read_dem(data("N44W072.hgt"), &ReadOptions::default()).unwrap()
}

#[test]
fn the_tile_reads_as_gdal_reads_it() {
    let g = tile();
    assert_eq!((g.width(), g.height()), (1201, 1201));
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("N44W072.gdalinfo.json")).unwrap())
            .unwrap();
    // GDAL's geoTransform gives the corner of pixel (0, 0); SRTM samples are points, so the
    // centre of sample (0, 0) is half a pixel in from it.
    let t: Vec<f64> = info["geoTransform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let r = g.georef();
    assert_eq!(r.crs, CrsKind::Geographic);
    assert_eq!(r.epsg, Some(4326));
    assert!((r.dx - t[1]).abs() < 1e-12 && (r.dy - t[5]).abs() < 1e-12);
    assert!(
        (r.origin_x - (t[0] + 0.5 * t[1])).abs() < 1e-9,
        "{r:?} vs {t:?}"
    );
    assert!(
        (r.origin_y - (t[3] + 0.5 * t[5])).abs() < 1e-9,
        "{r:?} vs {t:?}"
    );

    let samples = std::fs::read_to_string(data("N44W072.gdal_samples.txt")).unwrap();
    let mut n = 0;
    for line in samples.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let (col, row) = (v[0] as u32, v[1] as u32);
        assert_eq!(g.at(col, row) as f64, v[2], "sample ({col}, {row})");
        n += 1;
    }
    assert_eq!(n, 260);

    // Statistics over every sample, against GDAL's.
    let meta = &info["bands"][0]["metadata"][""];
    let stat = |k: &str| meta[k].as_str().unwrap().parse::<f64>().unwrap();
    assert_eq!(g.nodata_count(), 0);
    assert_eq!(stat("STATISTICS_VALID_PERCENT"), 100.0);
    let (lo, hi) = g.height_range();
    assert_eq!(
        (lo as f64, hi as f64),
        (stat("STATISTICS_MINIMUM"), stat("STATISTICS_MAXIMUM"))
    );
    let mean = g.heights().iter().map(|&h| h as f64).sum::<f64>() / g.heights().len() as f64;
    assert!((mean - stat("STATISTICS_MEAN")).abs() < 1e-6, "{mean}");
    // Mount Washington, 1,917 m, is the tile's summit (the 3″ grid misses its top by a few metres).
    assert!((1_880.0..=1_917.0).contains(&hi), "{hi}");
}

#[test]
fn its_spacing_in_metres_follows_the_wgs84_ellipsoid() {
    let g = tile();
    let (east, north) = g.georef().spacing_metres(g.height());
    // Radii of curvature of the WGS 84 ellipsoid at the tile's centre latitude (44.5° N):
    // meridian M = a(1 − e²)/(1 − e² sin²φ)^{3/2}, prime vertical N = a/(1 − e² sin²φ)^{1/2}.
    let (a, f) = (6_378_137.0f64, 1.0 / 298.257_223_563);
    let e2 = f * (2.0 - f);
    let phi = 44.5f64.to_radians();
    let w = 1.0 - e2 * phi.sin().powi(2);
    let m = a * (1.0 - e2) / w.powf(1.5);
    let nrad = a / w.sqrt();
    let step = (1.0f64 / 1200.0).to_radians();
    let (want_e, want_n) = (nrad * phi.cos() * step, m * step);
    assert!((east / want_e - 1.0).abs() < 2e-4, "{east} vs {want_e}");
    assert!((north / want_n - 1.0).abs() < 2e-4, "{north} vs {want_n}");
}

#[test]
fn its_meshes_stay_within_their_error_bound_on_every_sample() {
    let g = tile();
    let (padded, n) = pad_to_rtin(g.heights(), g.width(), g.height());
    assert_eq!(n, 2049);
    let map = ErrorMap::new(&padded, n);
    let mut last = usize::MAX;
    for max_error in [2.0f32, 10.0, 30.0] {
        let mesh = extract(&map, &padded, 0, 0, n - 1, max_error, 1);
        let e = true_error(&padded, n, (1201, 1201), &mesh.vertices, &mesh.triangles);
        assert!(e <= max_error + 1e-3, "{max_error} m: true error {e} m");
        assert!(mesh.triangles.len() < last);
        last = mesh.triangles.len();
        eprintln!(
            "N44W072 RTIN, {max_error} m: {} triangles, true error {e:.2} m",
            mesh.triangles.len()
        );
    }
    let rtin10 = extract(&map, &padded, 0, 0, n - 1, 10.0, 1).triangles.len();
    let greedy = texmap_terrain::greedy::greedy(&g, 10.0).unwrap();
    let e = true_error(
        g.heights(),
        1201,
        (1201, 1201),
        &greedy.vertices,
        &greedy.triangles,
    );
    eprintln!(
        "N44W072 greedy, 10 m: {} triangles (RTIN {rtin10}), true error {e:.2} m",
        greedy.triangles.len()
    );
    assert!(e <= 10.0 + 1e-3, "greedy: true error {e} m");
    assert!(greedy.triangles.len() < rtin10);
}

/// Our hillshade (the texture of a database without a photo) against `gdaldem hillshade` with
/// its defaults (`tests/data/hillshade.sh`): the tile around Mount Washington warped by GDAL to
/// UTM 19N at 90 m, and GDAL's bytes `1 + 254·cos` (1 where the cosine is ≤ 0) for it.
#[test]
fn hillshade_matches_gdaldem() {
    use texmap_terrain::relief::{Hillshade, Light};
    let dem = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let gdal = read_dem(data("hillshade_gdal.asc"), &ReadOptions::default()).unwrap();
    assert_eq!((dem.width(), dem.height()), (64, 64));
    assert_eq!(dem.georef().crs, CrsKind::Projected);
    let hs = Hillshade::new(&dem, Light::default());
    let (mut worst, mut lit) = (0.0f64, 0);
    // The interior: at the edges GDAL's -compute_edges fills the missing neighbours its own way,
    // ours extrapolates them exactly on a plane (unit tests in relief.rs).
    for row in 1..63 {
        for col in 1..63 {
            let cos = hs.at(col, row).unwrap();
            let ours = if cos <= 0.0 { 1.0 } else { 1.0 + 254.0 * cos };
            worst = worst.max((ours - gdal.at(col, row) as f64).abs());
            lit += (cos > 0.0) as u32;
        }
    }
    // GDAL rounds to a byte: within half a unit (and a float's slack).
    assert!(worst <= 0.501, "differs from gdaldem by {worst}");
    assert!(lit > 3000, "{lit} of 3844 samples lit");
    eprintln!("hillshade vs gdaldem: max |diff| {worst:.3}");
}

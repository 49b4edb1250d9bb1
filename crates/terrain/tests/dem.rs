//! The readers against files written by GDAL (tests/data/generate.sh), checked against the
//! analytic heights and against GDAL's own reading of each georeference (gdalinfo -json).

use std::path::PathBuf;
use texmap_terrain::dem::{CrsKind, ReadOptions, geotiff, read_dem};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// GDAL's geoTransform: [x of pixel (0,0)'s corner, pixel width, 0, y of the corner, 0, −height].
fn gdal_transform(name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(data(&format!("{name}.gdalinfo.json"))).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["geoTransform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn expected(col: u32, row: u32) -> f32 {
    100.0 + 2.0 * col as f32 + 3.0 * row as f32
}

#[test]
fn every_geotiff_layout_reads_the_ramp_and_gdals_georeference() {
    for (name, crs) in [
        ("ramp_i16_lzw", CrsKind::Projected),
        ("ramp_u16_tiled_bigtiff", CrsKind::Projected),
        ("ramp_i32_point", CrsKind::Projected),
        ("ramp_f32_geo", CrsKind::Geographic),
        ("ramp_f64", CrsKind::Projected),
        // compression.sh: ZSTD with predictors 2 (integers) and 3 (floats)
        ("ramp_i16_zstd", CrsKind::Projected),
        ("ramp_f32_zstd", CrsKind::Geographic),
    ] {
        let g = read_dem(data(&format!("{name}.tif")), &ReadOptions::default()).unwrap();
        assert_eq!((g.width(), g.height()), (37, 29), "{name}");
        for row in 0..29 {
            for col in 0..37 {
                let h = g.at(col, row);
                if (col, row) == (5, 3) {
                    // GDAL records the no-data value of every file (gdalinfo's noDataValue).
                    assert!(h.is_nan(), "{name}: no-data at (5, 3) read as {h}");
                } else {
                    assert_eq!(h, expected(col, row), "{name} at ({col}, {row})");
                }
            }
        }
        // Sample centres: GDAL's corner plus half a pixel, whatever the raster type.
        let t = gdal_transform(name);
        let r = g.georef();
        assert_eq!(r.crs, crs, "{name}");
        let tol = 1e-9 * t[0].abs().max(1.0);
        assert!(
            (r.origin_x - (t[0] + 0.5 * t[1])).abs() < tol,
            "{name}: x {} vs GDAL {}",
            r.origin_x,
            t[0] + 0.5 * t[1]
        );
        assert!(
            (r.origin_y - (t[3] + 0.5 * t[5])).abs() < tol,
            "{name}: y {} vs GDAL {}",
            r.origin_y,
            t[3] + 0.5 * t[5]
        );
        assert!(
            (r.dx - t[1]).abs() < 1e-12 && (r.dy - t[5]).abs() < 1e-12,
            "{name}"
        );
    }
}

#[test]
fn tiles_load_under_a_decode_limit_smaller_than_the_image() {
    // 37 x 29 x 2 bytes = 2146 bytes whole; each 16x16 tile is 512 bytes. (`tiff` also bounds tag
    // value lists by this limit, so it cannot be much smaller than the image here.)
    // The tiff crate's whole-image decode refuses the file under this limit...
    let f = std::fs::File::open(data("ramp_u16_tiled_bigtiff.tif")).unwrap();
    let mut limits = tiff::decoder::Limits::default();
    limits.decoding_buffer_size = 2000;
    let mut dec = tiff::decoder::Decoder::new(f).unwrap().with_limits(limits);
    assert!(
        dec.read_image().is_err(),
        "the limit must be below the whole image"
    );
    // ...while the chunk-by-chunk reader loads it.
    let g = geotiff::read_geotiff_limited(&data("ramp_u16_tiled_bigtiff.tif"), 2000).unwrap();
    assert_eq!(g.at(36, 28), expected(36, 28));
}

#[test]
fn gdal_ascii_grid_matches_the_geotiff() {
    let a = read_dem(data("ramp_gdal.asc"), &ReadOptions::default()).unwrap();
    let t = read_dem(data("ramp_i16_lzw.tif"), &ReadOptions::default()).unwrap();
    assert_eq!(a.width(), t.width());
    assert_eq!(a.georef().origin_x, t.georef().origin_x);
    assert_eq!(a.georef().origin_y, t.georef().origin_y);
    assert_eq!(a.nodata_count(), 1);
    for (x, y) in a.heights().iter().zip(t.heights()) {
        assert!(x == y || (x.is_nan() && y.is_nan()));
    }
}

#[test]
fn multiband_planar_photo_picks_bands() {
    let r = geotiff::read_raster(&data("photo_4band.tif"), Some(&[1, 3]), 1 << 20).unwrap();
    assert_eq!(r.band_count, 4);
    assert_eq!(r.bands.len(), 2);
    // band 2 (index 1) = (8·row) mod 256, band 4 = band 1 = (12·col) mod 256.
    let i = |c: u32, row: u32| (row * r.width + c) as usize;
    assert_eq!(r.bands[0][i(3, 7)], 56.0);
    assert_eq!(r.bands[1][i(3, 7)], 36.0);
    let e = geotiff::read_raster(&data("photo_4band.tif"), Some(&[4]), 1 << 20).unwrap_err();
    assert!(e.to_string().contains("band = 5"), "{e}");
}

#[test]
fn missing_and_garbage_files_are_errors_naming_the_file() {
    let e = read_dem(data("nope.tif"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("nope.tif"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("junk.tif");
    std::fs::write(&p, b"II*\0garbage").unwrap();
    let e = read_dem(&p, &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("junk.tif"), "{e}");
    let p = dir.path().join("x.abc");
    std::fs::write(&p, b"1").unwrap();
    assert!(
        read_dem(&p, &ReadOptions::default())
            .unwrap_err()
            .to_string()
            .contains("unknown extension")
    );
    // A known extension over garbage: the reader's located error.
    let p = dir.path().join("x.xyz");
    std::fs::write(&p, b"1").unwrap();
    let e = read_dem(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.xyz") && e.contains("line 1"), "{e}");
}

#[test]
fn inputs_the_coverage_guided_fuzzer_found_are_located_errors() {
    // libFuzzer (fuzz/fuzz_targets/geotiff.rs) found a BigTIFF whose IFD entry count overflowed
    // the directory bound check (a panic with overflow checks, a huge allocation without).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let e = texmap_terrain::dem::geotiff::read_geotiff(&path)
            .err()
            .unwrap_or_else(|| panic!("{}: read as a grid", path.display()));
        let name = path.file_name().unwrap().to_string_lossy();
        assert!(e.to_string().contains(name.as_ref()), "{e}");
    }
}

/// The GeoTIFF writer against the reader and against GDAL: every fixture GDAL wrote (UTM with
/// −32768 no-data, degrees with NaN no-data, PixelIsPoint, float64, Web Mercator, BigTIFF tiles)
/// read, written by us, read back: the same samples, holes, system and georeference (origins to
/// an ulp: PixelIsArea puts the tie point half a pixel from the centre we store).
#[test]
fn written_geotiffs_read_back_as_they_were() {
    use texmap_terrain::dem::geotiff_writer::write_grid;
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "ramp_i16_lzw.tif",
        "ramp_f32_geo.tif",
        "ramp_i32_point.tif",
        "ramp_f64.tif",
        "ramp_u16_tiled_bigtiff.tif",
        "dem_merc.tif",
        "hillshade_dem_utm.tif",
    ] {
        let g = read_dem(data(name), &ReadOptions::default()).unwrap();
        let out = dir.path().join(name);
        write_grid(&out, &g).unwrap();
        let back = read_dem(&out, &ReadOptions::default()).unwrap();
        assert_eq!((back.width(), back.height()), (g.width(), g.height()));
        for (i, (a, b)) in back.heights().iter().zip(g.heights()).enumerate() {
            assert!(
                a == b || (a.is_nan() && b.is_nan()),
                "{name} sample {i}: {a} vs {b}"
            );
        }
        assert_eq!(back.nodata_count(), g.nodata_count(), "{name}");
        let (a, b) = (back.georef(), g.georef());
        assert_eq!((a.crs, a.epsg), (b.crs, b.epsg), "{name}");
        assert!(a.dx == b.dx && a.dy == b.dy, "{name}: {a:?} vs {b:?}");
        for (p, q) in [(a.origin_x, b.origin_x), (a.origin_y, b.origin_y)] {
            let tol = 4.0 * f64::EPSILON * q.abs().max(1.0);
            assert!(
                (p - q).abs() <= tol,
                "{name}: origin {p} vs {q} (tolerance {tol})"
            );
        }
    }
}

/// `gdalinfo -json` of what we wrote gives the origin, pixel size, coordinate system and no-data
/// GDAL gives for the file we read; SKIPPED without GDAL (CI has none).
#[test]
fn gdal_reads_written_geotiffs_with_their_georeference() {
    use std::process::Command;
    use texmap_terrain::dem::geotiff_writer::write_grid;
    if Command::new("gdalinfo").arg("--version").output().is_err() {
        eprintln!("SKIPPED gdalinfo check of written GeoTIFFs: gdalinfo is not installed");
        return;
    }
    let info = |p: &std::path::Path| -> serde_json::Value {
        let o = Command::new("gdalinfo")
            .arg("-json")
            .arg(p)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    // The EPSG code of the coordinate system as a whole: the WKT's last ID.
    let epsg = |v: &serde_json::Value| -> Option<String> {
        let wkt = v["coordinateSystem"]["wkt"].as_str()?;
        let at = wkt.rfind("ID[\"EPSG\",")? + "ID[\"EPSG\",".len();
        Some(format!("EPSG:{}", wkt[at..].split(']').next()?))
    };
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "ramp_i16_lzw.tif",
        "ramp_f32_geo.tif",
        "ramp_i32_point.tif",
        "dem_merc.tif",
        "hillshade_dem_utm.tif",
    ] {
        let g = read_dem(data(name), &ReadOptions::default()).unwrap();
        let out = dir.path().join(name);
        write_grid(&out, &g).unwrap();
        let (theirs, ours) = (info(&data(name)), info(&out));
        let t: Vec<f64> = theirs["geoTransform"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let o: Vec<f64> = ours["geoTransform"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        for (a, b) in o.iter().zip(&t) {
            let tol = 4.0 * f64::EPSILON * b.abs().max(1.0);
            assert!(
                (a - b).abs() <= tol,
                "{name}: geoTransform {o:?} vs GDAL's {t:?}"
            );
        }
        assert_eq!(epsg(&ours), epsg(&theirs), "{name}");
        assert!(epsg(&ours).is_some(), "{name}: no EPSG code");
        // Holes are NaN with no-data "nan"; a file without holes gets no tag.
        let nd = &ours["bands"][0]["noDataValue"];
        if g.nodata_count() > 0 {
            assert_eq!(nd.as_str(), Some("NaN"), "{name}: {nd}");
        } else {
            assert!(nd.is_null(), "{name}: {nd}");
        }
        eprintln!(
            "{name}: GDAL reads our copy at {o:?}, {}",
            epsg(&ours).unwrap()
        );
    }
}

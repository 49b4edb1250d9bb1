//! Grids joined into one, against GDAL's mosaic of the same pieces (`gdalbuildvrt`,
//! tests/data/mosaic.sh) and against the SRTM tile the pieces were cut from; GDAL VRTs over the
//! pieces read as grids against GDAL's translation of each (`dem::vrt`), and damaged or hostile
//! VRTs refused by file and element.

use std::path::PathBuf;

use texmap_terrain::dem::mosaic::{Overlap, mosaic};
use texmap_terrain::dem::{Georef, Grid, ReadOptions, read_dem};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn read(name: &str) -> Grid {
    read_dem(data(name), &ReadOptions::default()).unwrap()
}

fn pieces() -> Vec<(String, Grid)> {
    ["mosaic_nw.tif", "mosaic_ne.tif", "mosaic_s.tif"]
        .into_iter()
        .map(|n| (n.to_string(), read(n)))
        .collect()
}

#[test]
fn pieces_join_as_gdalbuildvrt_joins_them() {
    let (ours, overlaps) = mosaic(pieces()).unwrap();
    let gdal = read("mosaic_gdal.tif");
    assert_eq!((ours.width(), ours.height()), (gdal.width(), gdal.height()));
    let (a, b) = (ours.georef(), gdal.georef());
    assert_eq!((a.crs, a.epsg), (b.crs, b.epsg));
    for (x, y) in [
        (a.origin_x, b.origin_x),
        (a.origin_y, b.origin_y),
        (a.dx, b.dx),
    ] {
        assert!((x - y).abs() < 1e-9, "{a:?} vs {b:?}");
    }
    // Every height equal, and no-data in the same places (the two uncovered corners).
    let holes = ours.heights().iter().filter(|h| h.is_nan()).count();
    assert!(holes > 0);
    for (i, (x, y)) in ours.heights().iter().zip(gdal.heights()).enumerate() {
        assert!(
            x == y || (x.is_nan() && y.is_nan()),
            "sample {i}: {x} vs GDAL {y}"
        );
    }
    // Overlaps: ne shares column 859 with nw (40 rows); s shares row 879 with nw (columns
    // 820..=859: 40) and ne (860..=889: 30). The pieces come from one tile, so they agree.
    assert_eq!(
        overlaps,
        vec![
            Overlap {
                later: "mosaic_ne.tif".into(),
                samples: 40,
                max_difference: 0.0
            },
            Overlap {
                later: "mosaic_s.tif".into(),
                samples: 70,
                max_difference: 0.0
            },
        ]
    );
}

#[test]
fn the_mosaic_is_the_tile_it_was_cut_from() {
    // Pieces read from GeoTIFFs, the tile from the .hgt: the same heights where a piece covers.
    let (ours, _) = mosaic(pieces()).unwrap();
    let tile = read("N44W072.hgt");
    let (c0, r0) = (800usize, 840usize);
    let (w, tw) = (ours.width() as usize, tile.width() as usize);
    let g = ours.georef();
    let (col, row) = tile.georef().xy_to_sample(g.origin_x, g.origin_y);
    assert!((col - c0 as f64).abs() < 1e-6 && (row - r0 as f64).abs() < 1e-6);
    for (i, &h) in ours.heights().iter().enumerate() {
        if !h.is_nan() {
            let t = tile.heights()[(r0 + i / w) * tw + c0 + i % w];
            assert_eq!(h, t, "sample {i}");
        }
    }
}

#[test]
fn later_grids_win_overlaps_and_the_difference_is_reported() {
    let g = |h: Vec<f32>, ox: f64| {
        let georef = Georef {
            origin_x: ox,
            ..Georef::local(10.0)
        };
        Grid::new("t", 3, 2, h, georef).unwrap()
    };
    // b starts two columns east of a: they share column 2 of a (= column 0 of b).
    let a = g(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 0.0);
    let b = g(vec![30.0, 7.0, 8.0, f32::NAN, 9.0, 10.0], 20.0);
    let (m, o) = mosaic(vec![("a".into(), a), ("b".into(), b)]).unwrap();
    assert_eq!((m.width(), m.height()), (5, 2));
    // The shared column: b's 30 wins over 3; b's no-data keeps a's 6.
    assert_eq!(
        m.heights(),
        &[1.0, 2.0, 30.0, 7.0, 8.0, 4.0, 5.0, 6.0, 9.0, 10.0]
    );
    assert_eq!(
        o,
        vec![Overlap {
            later: "b".into(),
            samples: 1,
            max_difference: 27.0
        }]
    );
}

#[test]
fn grids_that_do_not_tile_are_refused_by_name() {
    let base = read("mosaic_nw.tif");
    let with = |f: &dyn Fn(&mut Georef)| {
        let mut r = *base.georef();
        f(&mut r);
        Grid::new("x", base.width(), base.height(), base.heights().to_vec(), r).unwrap()
    };
    let cases: [(Grid, &[&str]); 3] = [
        (
            with(&|r| r.epsg = Some(32619)),
            &[
                "other.tif",
                "EPSG:32619",
                "EPSG:4326",
                "gdalwarp -t_srs EPSG:4326",
            ],
        ),
        (
            with(&|r| r.dx *= 2.0),
            &["other.tif", "cell size", "gdalwarp -tr"],
        ),
        (
            with(&|r| r.origin_x += 0.4 * r.dx),
            &["other.tif", "0.400 cells off", "gdalwarp -tap"],
        ),
    ];
    for (other, parts) in cases {
        let e = mosaic(vec![
            ("mosaic_nw.tif".into(), base.clone()),
            ("other.tif".into(), other),
        ])
        .unwrap_err()
        .to_string();
        for p in parts {
            assert!(e.contains(p), "{p}: {e}");
        }
    }
}

/// Heights equal (no-data in the same places) and the same georeference as GDAL's reading.
fn assert_same_grid(ours: &Grid, gdal: &Grid, what: &str) {
    assert_eq!(
        (ours.width(), ours.height()),
        (gdal.width(), gdal.height()),
        "{what}"
    );
    let (a, b) = (ours.georef(), gdal.georef());
    assert_eq!((a.crs, a.epsg), (b.crs, b.epsg), "{what}");
    for (x, y) in [
        (a.origin_x, b.origin_x),
        (a.origin_y, b.origin_y),
        (a.dx, b.dx),
        (a.dy, b.dy),
    ] {
        assert!((x - y).abs() < 1e-9, "{what}: {a:?} vs {b:?}");
    }
    for (i, (x, y)) in ours.heights().iter().zip(gdal.heights()).enumerate() {
        assert!(
            x == y || (x.is_nan() && y.is_nan()),
            "{what} sample {i}: {x} vs GDAL {y}"
        );
    }
}

/// gdalbuildvrt's mosaic, a SimpleSource window, a source halved by nearest neighbour, a scaled
/// ComplexSource (Float32) and a VRT within a VRT: each read equals GDAL's translation of it
/// sample for sample, with its georeference.
#[test]
fn gdal_vrts_read_as_gdal_translates_them() {
    for name in [
        "mosaic",
        "mosaic_window",
        "mosaic_half",
        "mosaic_scaled",
        "mosaic_nested",
    ] {
        let ours = read(&format!("{name}.vrt"));
        let gdal = read(&format!("{name}_gdal.tif"));
        assert_same_grid(&ours, &gdal, name);
        eprintln!(
            "{name}.vrt: {} x {} samples, {} no-data, equal to GDAL's",
            ours.width(),
            ours.height(),
            ours.nodata_count()
        );
    }
    // gdalbuildvrt's VRT and the --dem list of the same pieces are one grid.
    let (joined, _) = mosaic(pieces()).unwrap();
    assert_same_grid(&read("mosaic.vrt"), &joined, "mosaic.vrt vs mosaic()");
    // The scaled source: heights times 0.0005, as f32.
    let (scaled, ne) = (read("mosaic_scaled.vrt"), read("mosaic_ne.tif"));
    let (a, b) = (scaled.heights()[0], ne.heights()[0]);
    assert_eq!(a, (b as f64 * 0.0005) as f32);
}

/// A VRT in a directory of its own, beside copies of the pieces, from `xml`.
fn vrt_file(dir: &std::path::Path, name: &str, xml: &str) -> PathBuf {
    for p in ["mosaic_nw.tif", "mosaic_ne.tif", "mosaic_s.tif"] {
        std::fs::copy(data(p), dir.join(p)).unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, xml).unwrap();
    path
}

/// mosaic.vrt's text with `from` replaced by `to`.
fn mutated(from: &str, to: &str) -> String {
    let xml = std::fs::read_to_string(data("mosaic.vrt")).unwrap();
    assert!(xml.contains(from), "{from}");
    xml.replacen(from, to, 1)
}

#[test]
fn damaged_and_hostile_vrts_are_refused_by_file_and_element() {
    let dir = tempfile::tempdir().unwrap();
    let xml = std::fs::read_to_string(data("mosaic.vrt")).unwrap();
    let line_of = |s: &str| xml[..xml.find(s).unwrap()].matches('\n').count() + 1;
    let source_line = format!("line {}", line_of("<ComplexSource>"));
    let huge = xml.replacen(
        "rasterXSize=\"109\" rasterYSize=\"69\"",
        "rasterXSize=\"1000000\" rasterYSize=\"1000000\"",
        1,
    );
    let cases: Vec<(&str, String, Vec<String>)> = vec![
        (
            "missing.vrt",
            mutated("mosaic_ne.tif", "mosaic_gone.tif"),
            vec![
                "missing.vrt".into(),
                "<SourceFilename>".into(),
                "mosaic_gone.tif".into(),
            ],
        ),
        (
            "bad_xml.vrt",
            mutated("</ComplexSource>", "</ComplexSourc>"),
            vec![
                "bad_xml.vrt".into(),
                format!("line {}, column", line_of("</ComplexSource>")),
                "well-formed XML".into(),
            ],
        ),
        (
            "outside.vrt",
            mutated(
                "<SrcRect xOff=\"0\" yOff=\"0\" xSize=\"60\"",
                "<SrcRect xOff=\"30\" yOff=\"0\" xSize=\"60\"",
            ),
            vec![
                "outside.vrt".into(),
                source_line.clone(),
                "<SrcRect> inside the 60 x 40 pixels".into(),
            ],
        ),
        (
            "huge.vrt",
            huge,
            vec![
                "huge.vrt".into(),
                "line 1, <VRTDataset> rasterXSize, rasterYSize".into(),
                "1000000 x 1000000".into(),
            ],
        ),
        (
            "padded.vrt",
            xml.replacen(
                "rasterXSize=\"109\" rasterYSize=\"69\"",
                "rasterXSize=\"30000\" rasterYSize=\"30000\"",
                1,
            ),
            vec![
                "padded.vrt".into(),
                "line 1, <VRTDataset> rasterXSize".into(),
                "a raster its sources back".into(),
                "30000 x 30000".into(),
            ],
        ),
        (
            "self.vrt",
            mutated("mosaic_ne.tif", "self.vrt"),
            vec![
                "self.vrt".into(),
                "<SourceFilename>".into(),
                "references itself".into(),
            ],
        ),
        (
            "derived.vrt",
            mutated(
                "<VRTRasterBand dataType=\"Int16\" band=\"1\">",
                "<VRTRasterBand dataType=\"Int16\" band=\"1\" subClass=\"VRTDerivedRasterBand\">",
            ),
            vec![
                "derived.vrt".into(),
                format!("line {}, <VRTRasterBand>", line_of("<VRTRasterBand")),
                "VRTDerivedRasterBand".into(),
                "gdal_translate".into(),
            ],
        ),
        (
            "warped.vrt",
            mutated("<VRTDataset ", "<VRTDataset subClass=\"VRTWarpedDataset\" "),
            vec![
                "warped.vrt".into(),
                "line 1, <VRTDataset>".into(),
                "VRTWarpedDataset".into(),
            ],
        ),
        (
            "vrt_path.vrt",
            mutated(
                "<SourceFilename relativeToVRT=\"1\">mosaic_ne.tif",
                "<SourceFilename relativeToVRT=\"0\">vrt://mosaic_ne.tif?bands=1",
            ),
            vec![
                "vrt_path.vrt".into(),
                "<SourceFilename>".into(),
                "vrt://".into(),
            ],
        ),
        (
            "pixel_function.vrt",
            mutated(
                "<ColorInterp>Gray</ColorInterp>",
                "<PixelFunctionType>sum</PixelFunctionType>",
            ),
            vec![
                "pixel_function.vrt".into(),
                "<PixelFunctionType>: a pixel function".into(),
                "SimpleSource and ComplexSource".into(),
            ],
        ),
        (
            "band.vrt",
            mutated("<SourceBand>1</SourceBand>", "<SourceBand>2</SourceBand>"),
            vec![
                "band.vrt".into(),
                "<SourceBand> 2".into(),
                "has 1 band(s)".into(),
            ],
        ),
    ];
    for (name, xml, parts) in cases {
        let path = vrt_file(dir.path(), name, &xml);
        let (r, peak) = crate::alloc::measure(|| read_dem(&path, &ReadOptions::default()));
        let e = match r {
            Ok(g) => panic!("{name}: read as {} x {}", g.width(), g.height()),
            Err(e) => e.to_string(),
        };
        eprintln!("{e}");
        for p in &parts {
            assert!(e.contains(p.as_str()), "{name}: {p:?} not in: {e}");
        }
        // Refused before anything is sized from the claims.
        assert!(peak < 1 << 20, "{name}: {peak} bytes");
    }
}

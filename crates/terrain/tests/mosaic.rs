//! Grids joined into one, against GDAL's mosaic of the same pieces (`gdalbuildvrt`,
//! tests/data/mosaic.sh) and against the SRTM tile the pieces were cut from.

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

//! Photos in another coordinate system than their elevation grid, against GDAL: the placed
//! texture against `gdalwarp`'s warp of the same photo onto the same texel lattice
//! (tests/data/reproject.sh: geographic, Web Mercator and UTM 18N photos over UTM 19N and
//! geographic grids). The projections themselves are checked in tests/geodesy.rs.

use std::path::PathBuf;

use texmap_terrain::dem::{CrsKind, Georef, ReadOptions, read_dem};
use texmap_terrain::error::TerrainError;
use texmap_terrain::geodesy::Placement;
use texmap_terrain::gst::{self, Orthophoto, read_photo};
use texmap_terrain::photo::PhotoOptions;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Our 129² texture of `photo` over `dem` against GDAL's warp: (texels compared, mean and largest
/// absolute difference over the RGB of texels both give, texels where exactly one gives).
fn against_gdal(dem: &str, photo: &str, reference: &str) -> (usize, f64, u8, usize) {
    let grid = read_dem(data(dem), &ReadOptions::default()).unwrap();
    let photo = read_photo(&data(photo), &PhotoOptions::bands(None)).unwrap();
    let ours = gst::place(&photo, &grid, 129).unwrap();
    let gdal = image::open(data(reference)).unwrap().to_rgba8();
    assert_eq!(gdal.dimensions(), (129, 129));
    let (mut n, mut sum, mut max, mut one) = (0usize, 0u64, 0u8, 0usize);
    for (a, b) in ours.pixels().zip(gdal.pixels()) {
        match (a.0[3], b.0[3]) {
            (255, 255) => {
                n += 1;
                for k in 0..3 {
                    let d = a.0[k].abs_diff(b.0[k]);
                    sum += d as u64;
                    max = max.max(d);
                }
            }
            (0, 0) => {}
            _ => one += 1,
        }
    }
    (n, sum as f64 / (3 * n) as f64, max, one)
}

#[test]
fn photos_in_other_systems_drape_where_gdal_warps_them() {
    for (dem, photo, reference) in [
        (
            "hillshade_dem_utm.tif",
            "photo_geo.tif",
            "ref_utm19_geo.png",
        ),
        (
            "hillshade_dem_utm.tif",
            "photo_merc.tif",
            "ref_utm19_merc.png",
        ),
        (
            "hillshade_dem_utm.tif",
            "photo_utm18.tif",
            "ref_utm19_utm18.png",
        ),
        ("dem_geo.tif", "photo_merc.tif", "ref_geo_merc.png"),
        ("dem_geo.tif", "photo_utm18.tif", "ref_geo_utm18.png"),
        ("dem_merc.tif", "photo_geo.tif", "ref_merc_geo.png"),
        ("dem_merc.tif", "photo_utm18.tif", "ref_merc_utm18.png"),
    ] {
        let (n, mean, max, one) = against_gdal(dem, photo, reference);
        eprintln!("{dem} <- {photo}: {n} texels, mean |diff| {mean:.3}, max {max}, {one} edge");
        // The photo covers the west part of each grid: thousands of texels in common; the
        // pattern changes by up to 27 codes a pixel, so a tenth of a pixel off shows as ~3 (GDAL and we differ by at most one code).
        assert!(n > 6000, "{dem} <- {photo}: {n} texels in common");
        assert!(mean < 0.05 && max <= 1, "{dem} <- {photo}: {mean} / {max}");
        // Texels on the photo's edge may fall either side.
        assert!(one <= 16, "{dem} <- {photo}: {one} edge texels");
    }
}

#[test]
fn taking_the_photo_in_the_grids_system_would_misplace_it() {
    // What placement without reprojection did: the UTM 18N photo's numbers read as UTM 19N
    // put it ~470 km west of the grid, so there is no overlap and the error says so.
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let mut photo = read_photo(&data("photo_utm18.tif"), &PhotoOptions::bands(None)).unwrap();
    let g = photo.georef.unwrap();
    assert_eq!(g.epsg, Some(32618));
    photo.georef = Some(Georef {
        epsg: Some(32619),
        ..g
    });
    let err = gst::place(&photo, &grid, 129).unwrap_err();
    assert!(matches!(err, TerrainError::NoOverlap { .. }), "{err}");
}

#[test]
fn unknown_pairs_of_systems_are_refused_by_name() {
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let photo = read_photo(&data("photo_utm18.tif"), &PhotoOptions::bands(None)).unwrap();
    // Swiss LV95: no conversion here.
    let swiss = Orthophoto {
        stretch: None,
        georef: Some(Georef {
            crs: CrsKind::Projected,
            epsg: Some(2056),
            origin_x: 2_600_000.0,
            origin_y: 1_200_000.0,
            dx: 10.0,
            dy: -10.0,
        }),
        ..photo
    };
    let msg = gst::place(&swiss, &grid, 129).unwrap_err().to_string();
    for part in [
        "photo_utm18.tif",
        "EPSG:2056",
        "EPSG:32619",
        "gdalwarp -t_srs EPSG:32619",
    ] {
        assert!(msg.contains(part), "{msg}");
    }
    // A grid's own system is recognised: the Placement of each fixture's georeference.
    let geo = read_dem(data("dem_geo.tif"), &ReadOptions::default()).unwrap();
    assert_eq!(Placement::of(geo.georef()), Some(Placement::Geographic));
    assert_eq!(
        Placement::of(grid.georef()),
        Some(Placement::Utm {
            zone: 19,
            north: true
        })
    );
}

#[test]
fn web_mercator_grids_are_measured_in_ground_metres() {
    use texmap_terrain::geodesy::{ecef, web_mercator_to_lonlat};
    // dem_merc.tif: the SRTM cut warped by GDAL to EPSG:3857 at 100 "metres", about 72 m on the
    // ground at 44.3° N. Distances between samples in local metres against the straight line
    // between the same points on the ellipsoid (earth-centred; the chord is shorter than the
    // surface by under a millimetre at these 10 km).
    let grid = read_dem(data("dem_merc.tif"), &ReadOptions::default()).unwrap();
    let g = *grid.georef();
    assert!(g.is_web_mercator());
    let (w, h) = ((grid.width() - 1) as f64, (grid.height() - 1) as f64);
    let (east, north) = g.spacing_metres(grid.height());
    let lat_mid = web_mercator_to_lonlat(0.0, g.sample_xy(0.0, h / 2.0).1).1;
    let k = lat_mid.to_radians().cos();
    assert!(
        (east / (100.0 * k) - 1.0).abs() < 0.01 && (north / (100.0 * k) - 1.0).abs() < 0.01,
        "{east} x {north} m, cos φ = {k}"
    );
    let on_ellipsoid = |c: f64, r: f64| {
        let (x, y) = g.sample_xy(c, r);
        let (lon, lat) = web_mercator_to_lonlat(x, y);
        glam::DVec3::from(ecef(lon, lat, 0.0))
    };
    // Along a row or a column: within a centimetre. Across (the diagonals): the local frame
    // takes each row's own metres per degree of longitude, which shears it by ±2 m over 8.7 km
    // here (the same as for a grid in degrees). Read as plain metres, as before, the
    // distances were 1.4x too long.
    for (a, b, tol) in [
        ((0.0, 0.0), (w, 0.0), 1e-6),
        ((0.0, h), (0.0, 0.0), 1e-6),
        ((0.0, 0.0), (w, h), 3e-4),
        ((w, 0.0), (0.0, h), 3e-4),
    ] {
        let (pa, pb) = (g.local_metres(a.0, a.1), g.local_metres(b.0, b.1));
        let local = (pb.0 - pa.0).hypot(pb.1 - pa.1);
        let truth = on_ellipsoid(a.0, a.1).distance(on_ellipsoid(b.0, b.1));
        assert!(
            (local - truth).abs() < tol * truth,
            "{a:?} -> {b:?}: {local} m, on the ellipsoid {truth} m"
        );
    }
}

//! Geoid undulations against PROJ: the EGM96 grid PROJ uses (proj-data's egm96_15.gtx), cut by
//! GDAL into a GTX and a GeoTIFF around the SRTM tile, read by us and interpolated at 40 points
//! where PROJ's `gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979` gave h − H
//! (tests/data/geoid.sh).

use std::path::PathBuf;

use texmap_terrain::geoid::Geoid;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn undulations_match_proj_from_gtx_and_geotiff() {
    let proj = std::fs::read_to_string(data("geoid_proj.txt")).unwrap();
    let points: Vec<[f64; 3]> = proj
        .lines()
        .filter(|l| !l.starts_with("corner"))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(points.len(), 40);
    for file in ["egm96_cut.gtx", "egm96_cut.tif"] {
        let g = Geoid::open(data(file)).unwrap();
        let mut worst = 0f64;
        for [lon, lat, n] in &points {
            let got = g.undulation(*lon, *lat).unwrap();
            worst = worst.max((got - n).abs());
        }
        eprintln!("{file}: largest |N - PROJ| = {worst:.2e} m over 40 points");
        assert!(worst < 1e-4, "{file}: {worst} m");
        // Outside the cut (the grid is regional): no undulation.
        assert_eq!(g.undulation(-75.0, 44.0), None);
        assert_eq!(g.undulation(-71.0, 47.0), None);
    }
}

#[test]
fn a_projected_grid_is_not_a_geoid() {
    let e = Geoid::open(data("hillshade_dem_utm.tif"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("hillshade_dem_utm.tif") && e.contains("degrees"),
        "{e}"
    );
}

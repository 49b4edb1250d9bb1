//! GeoJSON overlays against GDAL: the same features written by ogr2ogr in three forms (UTM with
//! the 2008 `crs` member, RFC 7946 degrees, an RFC 8142 text sequence) drawn by texmap over the
//! UTM grid, and burnt by `gdal_rasterize` (reprojecting the degrees itself, through PROJ) onto
//! the same texel lattice (tests/data/vector.sh).

use std::path::PathBuf;

use image::{GrayImage, RgbaImage};
use texmap_terrain::dem::{Grid, ReadOptions, read_dem};
use texmap_terrain::vector::{Overlay, Style, StyleKeys, VectorLayer, read_geojson};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn grid() -> Grid {
    read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap()
}

fn gdal(name: &str) -> GrayImage {
    let m = image::open(data(&format!("vector_gdal_{name}.png")))
        .unwrap()
        .to_luma8();
    assert_eq!(m.dimensions(), (256, 256));
    m
}

/// The layer with only polygons, lines or points kept, and the features' own styles dropped.
fn only(layer: &VectorLayer, kind: &str) -> VectorLayer {
    let mut l = layer.clone();
    for f in &mut l.features {
        if kind != "area" {
            f.rings.clear();
        }
        if kind != "line" {
            f.lines.clear();
        }
        if kind != "point" {
            f.points.clear();
        }
        f.style = StyleKeys::default();
    }
    l
}

/// Coverage (0..=1) per texel of a white overlay on black, 256² texels in 64² maps.
fn coverage(layer: &VectorLayer, style: &str) -> Vec<f32> {
    let style = Style::default().with_keys(style).unwrap();
    let o = Overlay::place(std::slice::from_ref(layer), &style, &grid(), 256, 64).unwrap();
    let mut img = RgbaImage::from_pixel(256, 256, image::Rgba([0, 0, 0, 255]));
    for my in 0..4 {
        for mx in 0..4 {
            let mut m = RgbaImage::from_pixel(64, 64, image::Rgba([0, 0, 0, 255]));
            o.draw(mx, my, &mut m);
            image::imageops::replace(&mut img, &m, mx as i64 * 64, my as i64 * 64);
        }
    }
    img.pixels().map(|p| p.0[0] as f32 / 255.0).collect()
}

const FILL: &str = "stroke=none,fill=#ffffff,fill-opacity=1,marker-color=none";

#[test]
fn polygons_cover_the_texels_gdal_burns_in_every_form() {
    // The UTM file against GDAL's burn of itself; the degrees against GDAL's reprojection.
    for (file, mask) in [
        ("vector_utm.geojson", "area_utm"),
        ("vector_wgs84.geojson", "area"),
        ("vector_wgs84.geojsons", "area"),
    ] {
        let area = gdal(mask);
        let layer = read_geojson(data(file)).unwrap();
        assert_eq!(layer.features.len(), 7, "{file}");
        let c = coverage(&only(&layer, "area"), FILL);
        let (mut differ, mut ties, mut inside) = (0, 0, 0);
        for (k, (&ours, g)) in c.iter().zip(area.pixels()).enumerate() {
            let theirs = g.0[0] > 0;
            inside += theirs as usize;
            // A centre on an edge (coverage 0.5, 8-bit 128) is a tie the centre rule leaves
            // to the implementation: GDAL counts it out.
            if (ours - 128.0 / 255.0).abs() < 1e-6 {
                ties += 1;
            } else if (ours >= 0.5) != theirs {
                differ += 1;
                // Only where the texel centre lies on an edge, within the anti-aliasing.
                assert!(
                    ours > 0.3 && ours < 0.7,
                    "{file}: texel {} {}: coverage {ours}, GDAL {theirs}",
                    k % 256,
                    k / 256
                );
            }
        }
        println!(
            "{file}: {inside} texels inside by GDAL, {ties} centres on an edge, {differ} others differ"
        );
        assert!(inside > 16_000 && differ <= 4, "{file}: {differ}");
    }
}

#[test]
fn lines_cover_gdals_line_and_stay_within_its_touched_texels() {
    let (line, touched) = (gdal("line"), gdal("line_touched"));
    let layer = read_geojson(data("vector_wgs84.geojson")).unwrap();
    let c = coverage(
        &only(&layer, "line"),
        "stroke=#ffffff,stroke-width=1,fill=none,marker-color=none",
    );
    let at = |x: i32, y: i32| (0..256).contains(&x) && (0..256).contains(&y);
    let mut burnt = 0;
    for y in 0..256i32 {
        for x in 0..256i32 {
            let k = (y * 256 + x) as usize;
            if line.get_pixel(x as u32, y as u32).0[0] > 0 {
                burnt += 1;
                assert!(c[k] > 0.0, "texel {x} {y}: GDAL's line, no coverage");
            }
            if c[k] >= 0.5 {
                let near = (-1..=1).any(|dy| {
                    (-1..=1).any(|dx| {
                        at(x + dx, y + dy)
                            && touched.get_pixel((x + dx) as u32, (y + dy) as u32).0[0] > 0
                    })
                });
                assert!(
                    near,
                    "texel {x} {y}: covered {} away from GDAL's line",
                    c[k]
                );
            }
        }
    }
    // A 1-texel line's ink is its length in texels; GDAL burns one texel per step along the
    // major axis, fewer than the length on a diagonal.
    let ink: f32 = c.iter().sum();
    println!("lines: GDAL burns {burnt} texels, our ink {ink:.1} texels");
    assert!(burnt > 300 && (ink - burnt as f32).abs() < 0.25 * burnt as f32);
}

#[test]
fn points_are_discs_on_gdals_texels() {
    let point = gdal("point");
    let layer = read_geojson(data("vector_wgs84.geojson")).unwrap();
    let c = coverage(&only(&layer, "point"), "marker-color=#ffffff,marker-size=3");
    let mut n = 0;
    for (k, g) in point.pixels().enumerate() {
        if g.0[0] > 0 {
            n += 1;
            let (x, y) = ((k % 256) as i64, (k / 256) as i64);
            // The disc's ink centroid within half a texel of GDAL's texel.
            let (mut s, mut sx, mut sy) = (0.0f64, 0.0, 0.0);
            for dy in -3..=3 {
                for dx in -3..=3 {
                    let v = c[((y + dy) * 256 + x + dx) as usize] as f64;
                    s += v;
                    sx += v * dx as f64;
                    sy += v * dy as f64;
                }
            }
            let (cx, cy) = (sx / s, sy / s);
            assert!(cx.abs() <= 0.5 && cy.abs() <= 0.5, "{x} {y}: {cx} {cy}");
            // π·1.5² texels of ink.
            assert!((s - 7.07).abs() < 0.5, "{s}");
        }
    }
    assert_eq!(n, 3);
}

#[test]
fn the_features_own_styles_win_over_the_layers() {
    // The road is red by its "stroke" property, the trail the layer's stroke.
    let layer = read_geojson(data("vector_wgs84.geojson")).unwrap();
    let style = Style::default()
        .with_keys("stroke=#0000ff,fill=none,marker-color=none")
        .unwrap();
    let o = Overlay::place(&[layer], &style, &grid(), 256, 256).unwrap();
    let mut m = RgbaImage::from_pixel(256, 256, image::Rgba([0, 0, 0, 255]));
    o.draw(0, 0, &mut m);
    let red = m.pixels().filter(|p| p.0 == [255, 0, 0, 255]).count();
    let blue = m.pixels().filter(|p| p.0 == [0, 0, 255, 255]).count();
    let green = m
        .pixels()
        .filter(|p| p.0 == [0x20, 0x60, 0x20, 255])
        .count();
    assert!(
        red > 200 && blue > 100 && green > 100,
        "{red} {blue} {green}"
    );
    // Drawn over the grid: the lake, the forest, the road, the trail (points have no colour).
    assert_eq!(o.counts()[0].1, 4);
}

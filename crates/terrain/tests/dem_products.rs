//! `dem_products` against `gdaldem` 3.6.2's own output (tests/data/gdaldem.sh): every mode and
//! its main options, on a UTM grid, the same grid with no-data holes (an ESRI ASCII grid both
//! read) and a geographic SRTM crop with `-s 111120`, with and without `-compute_edges`.
//!
//! Tolerances: byte products (hillshade, colour relief) at most 1 level apart, on at most 1 % of
//! the samples (GDAL sums the 3 x 3 window in `f32`, we in `f64`: a value within an `f32`
//! rounding of a half level can round the other way); float products within 1e-4 (the same
//! window sums' rounding, a few 1e-6 of a degree). No-data positions must be equal.

use std::path::PathBuf;
use texmap_terrain::dem::{Grid, ReadOptions, read_dem};
use texmap_terrain::dem_products::{
    ColorMatch, ColorTable, DemOptions, DemProduct, FLOAT_NODATA, Gradient, HillshadeOptions,
    Product, ProductSamples, Shading, TriAlg, color_relief, compute,
};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn input(name: &str) -> Grid {
    let file = match name {
        "utm" => "hillshade_dem_utm.tif",
        "holes" => "gdaldem_holes.asc",
        "geo" => "gdaldem_geo.tif",
        other => panic!("no input {other}"),
    };
    read_dem(data(file), &ReadOptions::default()).unwrap()
}

/// Bytes of a product against GDAL's PNG (1, 3 or 4 bands): at most `tol` levels apart, on at
/// most 1 % of the samples, and equal where either is gdaldem's no-data 0 (one band).
fn check_bytes(name: &str, ours: &DemProduct, tol: u8) {
    let png = image::open(data(&format!("gdaldem/{name}.png"))).unwrap();
    let (ours, gdal): (&[u8], Vec<u8>) = match &ours.samples {
        ProductSamples::Gray8(v) => (v, png.to_luma8().into_raw()),
        ProductSamples::Rgb8(v) => (v, png.to_rgb8().into_raw()),
        ProductSamples::Rgba8(v) => (v, png.to_rgba8().into_raw()),
        ProductSamples::F32(_) => panic!("{name}: a float product"),
    };
    assert_eq!(ours.len(), gdal.len(), "{name}: sample count");
    let (mut worst, mut differ) = (0u8, 0usize);
    for (i, (&a, &b)) in ours.iter().zip(&gdal).enumerate() {
        let d = a.abs_diff(b);
        if d > 0 {
            differ += 1;
        }
        worst = worst.max(d);
        assert!(
            d <= tol,
            "{name}: sample {i}: ours {a}, GDAL {b}, tolerance {tol}"
        );
        if tol > 0 {
            assert_eq!(a == 0, b == 0, "{name}: sample {i}: no-data differs");
        }
    }
    assert!(
        differ * 100 <= gdal.len(),
        "{name}: {differ} of {} samples differ (at most 1 %)",
        gdal.len()
    );
    eprintln!(
        "{name}: {differ} of {} samples differ, by at most {worst}",
        gdal.len()
    );
}

/// Floats against GDAL's GeoTIFF: within `tol`, no-data (−9999, read as NaN) in the same places.
fn check_floats(name: &str, ours: &DemProduct, tol: f32) {
    let gdal = read_dem(
        data(&format!("gdaldem/{name}.tif")),
        &ReadOptions::default(),
    )
    .unwrap();
    let ProductSamples::F32(v) = &ours.samples else {
        panic!("{name}: not a float product")
    };
    assert_eq!(ours.nodata, Some(-9999.0));
    assert_eq!(v.len(), gdal.heights().len(), "{name}: sample count");
    let mut worst = 0f32;
    for (i, (&a, &b)) in v.iter().zip(gdal.heights()).enumerate() {
        assert_eq!(
            a == FLOAT_NODATA,
            b.is_nan(),
            "{name}: sample {i} (col {}, row {}): ours {a}, GDAL {b}: no-data differs",
            i % 64,
            i / 64
        );
        if b.is_nan() {
            continue;
        }
        // Aspect: 0 and 360 are one direction.
        let d = (a - b).abs();
        let d = if name.starts_with("aspect") {
            d.min(360.0 - d)
        } else {
            d
        };
        assert!(
            d <= tol,
            "{name}: sample {i}: ours {a}, GDAL {b}, |diff| {d} > tolerance {tol}"
        );
        worst = worst.max(d);
    }
    eprintln!("{name}: max |diff| {worst:e}");
}

fn opts(gradient: Gradient, compute_edges: bool, scale: Option<f64>) -> DemOptions {
    DemOptions {
        gradient,
        compute_edges,
        scale,
    }
}

fn hs(z: f64, azimuth: f64, altitude: f64, shading: Shading) -> Product {
    Product::Hillshade(HillshadeOptions {
        z,
        azimuth,
        altitude,
        shading,
    })
}

#[test]
fn hillshade_equals_gdaldem() {
    use Gradient::{Horn, ZevenbergenThorne as Zt};
    use Shading::*;
    let cases = [
        (
            "hs_utm",
            "utm",
            hs(1.0, 315.0, 45.0, Standard),
            opts(Horn, false, None),
        ),
        (
            "hs_holes",
            "holes",
            hs(1.0, 315.0, 45.0, Standard),
            opts(Horn, false, None),
        ),
        (
            "hs_holes_edges",
            "holes",
            hs(1.0, 315.0, 45.0, Standard),
            opts(Horn, true, None),
        ),
        (
            "hs_zt_z2_az200_alt30_holes",
            "holes",
            hs(2.0, 200.0, 30.0, Standard),
            opts(Zt, false, None),
        ),
        (
            "hs_zt_holes_edges",
            "holes",
            hs(1.0, 315.0, 45.0, Standard),
            opts(Zt, true, None),
        ),
        (
            "hs_combined_holes_edges",
            "holes",
            hs(1.0, 315.0, 45.0, Combined),
            opts(Horn, true, None),
        ),
        (
            "hs_multi_z3_holes",
            "holes",
            hs(3.0, 315.0, 45.0, Multidirectional),
            opts(Horn, false, None),
        ),
        (
            "hs_multi_zt_utm_edges",
            "utm",
            hs(1.0, 315.0, 45.0, Multidirectional),
            opts(Zt, true, None),
        ),
        (
            "hs_igor_az100_holes",
            "holes",
            hs(1.0, 100.0, 45.0, Igor),
            opts(Horn, false, None),
        ),
        (
            "hs_geo_s111120_z2_edges",
            "geo",
            hs(2.0, 315.0, 45.0, Standard),
            opts(Horn, true, Some(111120.0)),
        ),
    ];
    for (name, dem, product, o) in cases {
        let ours = compute(&input(dem), &product, &o).unwrap();
        assert_eq!(ours.nodata, Some(0.0));
        check_bytes(name, &ours, 1);
    }
}

#[test]
fn slope_and_aspect_equal_gdaldem() {
    use Gradient::{Horn, ZevenbergenThorne as Zt};
    let slope = |percent| Product::Slope { percent };
    let aspect = |trigonometric, zero_for_flat| Product::Aspect {
        trigonometric,
        zero_for_flat,
    };
    let cases = [
        ("slope_utm", "utm", slope(false), opts(Horn, false, None)),
        (
            "slope_percent_holes_edges",
            "holes",
            slope(true),
            opts(Horn, true, None),
        ),
        (
            "slope_zt_holes",
            "holes",
            slope(false),
            opts(Zt, false, None),
        ),
        (
            "slope_geo_s111120",
            "geo",
            slope(false),
            opts(Horn, false, Some(111120.0)),
        ),
        (
            "aspect_holes",
            "holes",
            aspect(false, false),
            opts(Horn, false, None),
        ),
        (
            "aspect_trig_zero_geo_edges",
            "geo",
            aspect(true, true),
            opts(Horn, true, None),
        ),
        (
            "aspect_zt_holes_edges",
            "holes",
            aspect(false, false),
            opts(Zt, true, None),
        ),
    ];
    for (name, dem, product, o) in cases {
        let ours = compute(&input(dem), &product, &o).unwrap();
        check_floats(name, &ours, 1e-4);
    }
}

#[test]
fn color_relief_equals_gdaldem() {
    let table = ColorTable::read(&data("gdaldem_colors.txt")).unwrap();
    let cases = [
        ("cr_holes", "holes", ColorMatch::Linear, false),
        ("cr_alpha_holes", "holes", ColorMatch::Linear, true),
        ("cr_nearest_holes", "holes", ColorMatch::Nearest, false),
    ];
    for (name, dem, m, alpha) in cases {
        let ours = color_relief(&input(dem), &table, m, alpha);
        check_bytes(name, &ours, 0);
    }
}

/// `-exact_color_entry`: GDAL 3.6.2 colours only the heights equal to the lowest entry (its
/// search compares a height with the entry below the first one not below it, so every other
/// entry is missed); we colour every height equal to an entry, as gdaldem's documentation says.
/// Equal to GDAL's pixels everywhere else: the geo crop holds 0 % (309 m) once, 500 m 8 times,
/// 700 m twice and 100 % (941 m) once.
#[test]
fn exact_color_entries_match_every_entry() {
    let table = ColorTable::read(&data("gdaldem_colors_exact.txt")).unwrap();
    let grid = input("geo");
    let ours = color_relief(&grid, &table, ColorMatch::Exact, true);
    let ProductSamples::Rgba8(ours) = ours.samples else {
        panic!("RGBA")
    };
    let gdal = image::open(data("gdaldem/cr_exact_alpha_geo.png"))
        .unwrap()
        .to_rgba8()
        .into_raw();
    let mut beyond_gdal = std::collections::BTreeMap::new();
    for (i, (a, b)) in ours.chunks_exact(4).zip(gdal.chunks_exact(4)).enumerate() {
        let h = grid.heights()[i];
        if a != b {
            assert_eq!(b, [0; 4], "pixel {i} ({h} m): ours {a:?}, GDAL {b:?}");
            *beyond_gdal.entry(h as i32).or_insert(0) += 1;
        }
    }
    let want: std::collections::BTreeMap<i32, i32> = [(500, 8), (700, 2), (941, 1)].into();
    assert_eq!(beyond_gdal, want);
}

#[test]
fn tri_tpi_roughness_equal_gdaldem() {
    use Gradient::Horn;
    let cases = [
        (
            "tri_riley_holes",
            "holes",
            Product::Tri(TriAlg::Riley),
            false,
        ),
        (
            "tri_wilson_holes_edges",
            "holes",
            Product::Tri(TriAlg::Wilson),
            true,
        ),
        ("tpi_holes", "holes", Product::Tpi, false),
        ("tpi_geo_edges", "geo", Product::Tpi, true),
        ("roughness_holes_edges", "holes", Product::Roughness, true),
        ("roughness_utm", "utm", Product::Roughness, false),
    ];
    for (name, dem, product, edges) in cases {
        let ours = compute(&input(dem), &product, &opts(Horn, edges, None)).unwrap();
        check_floats(name, &ours, 1e-4);
    }
}

/// The same bytes for any thread count.
#[test]
fn products_do_not_depend_on_the_thread_count() {
    let grid = input("holes");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let o = opts(Gradient::Horn, true, None);
            (
                compute(&grid, &hs(1.0, 315.0, 45.0, Shading::Multidirectional), &o).unwrap(),
                compute(&grid, &Product::Slope { percent: false }, &o).unwrap(),
            )
        })
    };
    assert_eq!(run(1), run(3));
}

/// The colour relief's GeoTIFFs read back by another decoder (the `tiff` crate): in strips (RGB)
/// and as a COG with 16-pixel tiles (RGBA, so tiles and overviews on a small grid), the full
/// image is the product's bytes, the alpha is declared unassociated (ExtraSamples 2, as GDAL
/// writes `-alpha`), the COG has its overviews, and the georeference tags place the pixels as
/// the source GeoTIFF does (GDAL wrote it as PixelIsPoint, centres at whole arc-seconds; ours
/// are PixelIsArea, so the tie point is the first pixel's corner, half a pixel up and left).
#[test]
fn color_relief_geotiffs_read_back_with_their_georeference() {
    use texmap_terrain::dem::geotiff_writer::GeoTiffOptions;
    use tiff::decoder::{Decoder, DecodingResult};
    use tiff::tags::Tag;
    let table = ColorTable::read(&data("gdaldem_colors.txt")).unwrap();
    let grid = input("geo");
    let dir = tempfile::tempdir().unwrap();
    let georef_tags = |d: &mut Decoder<std::fs::File>| {
        [Tag::ModelPixelScaleTag, Tag::ModelTiepointTag].map(|t| d.get_tag_f64_vec(t).unwrap())
    };
    let raster_type = |d: &mut Decoder<std::fs::File>| {
        let keys = d.get_tag_u16_vec(Tag::GeoKeyDirectoryTag).unwrap();
        keys[4..]
            .chunks_exact(4)
            .find(|k| k[0] == 1025)
            .map_or(1, |k| k[3])
    };
    let mut source = Decoder::new(std::fs::File::open(data("gdaldem_geo.tif")).unwrap()).unwrap();
    let [scale, tie] = georef_tags(&mut source);
    assert_eq!(
        raster_type(&mut source),
        2,
        "GDAL wrote the crop as PixelIsPoint"
    );
    let (dx, dy) = (scale[0], -scale[1]);
    let corner = vec![0.0, 0.0, 0.0, tie[3] - dx / 2.0, tie[4] - dy / 2.0, 0.0];
    for (alpha, cog) in [(false, false), (true, true), (true, false), (false, true)] {
        let product = color_relief(&grid, &table, ColorMatch::Linear, alpha);
        let path = dir.path().join(format!("cr_{alpha}_{cog}.tif"));
        let options = GeoTiffOptions {
            cog,
            block_size: if cog { 16 } else { 512 },
        };
        product.write_geotiff(&path, &grid, &options).unwrap();
        let mut d = Decoder::new(std::fs::File::open(&path).unwrap()).unwrap();
        let case = format!("alpha {alpha}, cog {cog}");
        assert_eq!(
            d.dimensions().unwrap(),
            (grid.width(), grid.height()),
            "{case}"
        );
        let want = match (&product.samples, alpha) {
            (ProductSamples::Rgba8(v), true) => {
                assert_eq!(d.colortype().unwrap(), tiff::ColorType::RGBA(8), "{case}");
                assert_eq!(d.get_tag_u32_vec(Tag::ExtraSamples).unwrap(), [2], "{case}");
                v.clone()
            }
            (ProductSamples::Rgb8(v), false) => {
                assert_eq!(d.colortype().unwrap(), tiff::ColorType::RGB(8), "{case}");
                v.clone()
            }
            _ => panic!("{case}: unexpected sample layout"),
        };
        assert_eq!(raster_type(&mut d), 1, "{case}: PixelIsArea");
        let [our_scale, our_tie] = georef_tags(&mut d);
        assert_eq!(our_scale, scale, "{case}");
        assert_eq!(our_tie, corner, "{case}");
        let DecodingResult::U8(got) = d.read_image().unwrap() else {
            panic!("{case}: 8-bit samples expected")
        };
        assert!(
            got == want,
            "{case}: the decoded image differs from the product"
        );
        assert_eq!(d.more_images(), cog, "{case}: overviews only in the COG");
    }
}

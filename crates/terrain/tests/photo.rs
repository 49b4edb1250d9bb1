//! Orthophotos read by rows (`photo::TiffPhoto`) and GST pyramids written map by map
//! (`gst::write_pyramid`), against the whole-image reader (`gst::read_photo`) and the whole-level
//! pyramid (`gst::pyramid(gst::place(..))`): the same bytes. The photos are GDAL-written GeoTIFFs
//! (tiled, planar, 16-bit) over the real SRTM tile N44W072 (`tests/data/relief_photos.sh`).

use image::RgbaImage;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{self, Grid};
use texmap_terrain::gst::{self, MapKey, PhotoSource};
use texmap_terrain::photo::{TiffPhoto, open_photo};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn srtm() -> Grid {
    dem::read_dem(data("N44W072.hgt"), &dem::ReadOptions::default()).unwrap()
}

#[test]
fn rows_read_by_band_equal_the_whole_image() {
    for (file, bands) in [
        ("relief_tiled.tif", None),
        ("relief_planar_u16.tif", Some([4, 2, 1])),
        ("relief_planar_u16.tif", None),
        ("photo_4band.tif", Some([2, 3, 1])),
        ("photo_rgb_webp.tif", None),
        ("photo_rgb_jpeg.tif", None),
    ] {
        let whole = gst::read_photo(&data(file), bands).unwrap();
        let rows = TiffPhoto::open(&data(file), bands).unwrap();
        assert_eq!(rows.size(), whole.image.dimensions(), "{file}");
        assert_eq!(rows.georef(), whole.georef, "{file}");
        let h = whole.image.height();
        // Top to bottom in overlapping bands (how the pyramid writer asks), then out of order.
        let mut spans: Vec<(u32, u32)> = (0..h)
            .step_by(23)
            .map(|y| (y.saturating_sub(3), (y + 29).min(h)))
            .collect();
        spans.extend([(h - 5, h), (0, 7), (100.min(h - 1), h)]);
        for (y0, y1) in spans {
            let band = rows.rows(y0, y1).unwrap();
            let want = image::imageops::crop_imm(&whole.image, 0, y0, whole.image.width(), y1 - y0)
                .to_image();
            assert!(band == want, "{file} {bands:?} rows {y0}..{y1}");
        }
    }
    // The 16-bit bands are stretched, so the 8-bit values span the range.
    let p = TiffPhoto::open(&data("relief_planar_u16.tif"), Some([4, 2, 1])).unwrap();
    let img = p.rows(0, 240).unwrap();
    let reds: Vec<u8> = img.pixels().map(|px| px.0[0]).collect();
    assert_eq!(reds.iter().min(), Some(&0));
    assert_eq!(reds.iter().max(), Some(&255));
}

/// GDAL's COG compressions for photos (`tests/data/compression.sh`): lossless WebP decodes to the
/// uncompressed photo's bytes; JPEG in YCbCr (4:2:0) to within two levels of GDAL's own
/// decoding (libjpeg's and zune-jpeg's upsampling and IDCT round differently) and above 38 dB
/// PSNR against the photo it was made from.
#[test]
fn webp_and_ycbcr_jpeg_photos_decode_as_gdal_decodes_them() {
    let plain = gst::read_photo(&data("photo_rgb.tif"), None).unwrap();
    let webp = gst::read_photo(&data("photo_rgb_webp.tif"), None).unwrap();
    assert!(webp.image == plain.image);
    assert_eq!(webp.georef, plain.georef);
    let jpeg = gst::read_photo(&data("photo_rgb_jpeg.tif"), None).unwrap();
    let gdal = gst::read_photo(&data("photo_rgb_jpeg_gdal.tif"), None).unwrap();
    assert_eq!(jpeg.georef, plain.georef);
    assert_eq!(jpeg.image.dimensions(), gdal.image.dimensions());
    let diff = |a: &RgbaImage, b: &RgbaImage| {
        let d: Vec<i32> = a
            .as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(&x, &y)| (x as i32 - y as i32).abs())
            .collect();
        let mse = d.iter().map(|&x| (x * x) as f64).sum::<f64>() / d.len() as f64;
        (*d.iter().max().unwrap(), mse)
    };
    let (max_gdal, _) = diff(&jpeg.image, &gdal.image);
    assert!(
        max_gdal <= 2,
        "JPEG decode differs from GDAL's by {max_gdal}"
    );
    let (_, mse) = diff(&jpeg.image, &plain.image);
    let psnr = 10.0 * (255.0f64 * 255.0 / mse.max(1e-9)).log10();
    assert!(psnr > 38.0, "JPEG against its source: {psnr:.1} dB");
}

/// JPEG and WebP decoders size their output from the stream's own header: a damaged one claiming
/// 16384² pixels in a 16x16 tile is a located error, found before anything is allocated for it.
#[test]
fn a_codec_header_claiming_a_huge_frame_is_refused_before_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let jpeg = std::fs::read(data("photo_rgb_jpeg.tif")).unwrap();
    // The first tile's start-of-frame segment (FF C0, length, precision, height, width).
    let sof = jpeg.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
    let mut big = jpeg.clone();
    big[sof + 5..sof + 9].copy_from_slice(&[0x3F, 0xFF, 0x3F, 0xFF]);
    let vp8l = std::fs::read(data("photo_rgb_webp.tif")).unwrap();
    let at = vp8l.windows(4).position(|w| w == b"VP8L").unwrap();
    let mut big_webp = vp8l.clone();
    // 14 bits of width − 1, 14 of height − 1, after the signature byte.
    let v = u32::from_le_bytes(big_webp[at + 9..at + 13].try_into().unwrap()) | 0x0FFF_FFFF;
    big_webp[at + 9..at + 13].copy_from_slice(&v.to_le_bytes());
    for (name, bytes, claim) in [
        (
            "big.tif",
            big,
            "JPEG frame within the 16x16 chunk, its header claims 16383x16383",
        ),
        (
            "bigw.tif",
            big_webp,
            "WebP frame within the 16x16 chunk, its header claims 16384x16384",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let (r, peak) = crate::alloc::measure(|| gst::read_photo(&path, None).map(|_| ()));
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains(name) && e.contains("chunk 0") && e.contains(claim),
            "{e}"
        );
        assert!(peak < 1 << 20, "{name}: {peak} bytes");
    }
}

/// `write_pyramid` into memory.
fn pyramid_by_maps(
    photo: &dyn PhotoSource,
    grid: &Grid,
    t: u32,
    levels: u32,
) -> HashMap<MapKey, RgbaImage> {
    let maps = Mutex::new(HashMap::new());
    let write = |k: MapKey, m: &RgbaImage| {
        maps.lock().unwrap().insert(k, m.clone());
        Ok(())
    };
    let read = |k: MapKey| Ok(maps.lock().unwrap()[&k].clone());
    let mut done = Vec::new();
    gst::write_pyramid(photo, grid, t, levels, &write, &read, &mut |l| done.push(l)).unwrap();
    assert_eq!(done, (0..levels).rev().collect::<Vec<_>>());
    maps.into_inner().unwrap()
}

#[test]
fn the_pyramid_written_map_by_map_is_the_whole_level_pyramid() {
    let grid = srtm();
    // Placed by its georeference: it covers part of the tile, the rest is transparent.
    let whole = gst::read_photo(&data("relief_tiled.tif"), None).unwrap();
    let rows = TiffPhoto::open(&data("relief_tiled.tif"), None).unwrap();
    let (t, levels) = (64, 5);
    let reference = gst::pyramid(gst::place(&whole, &grid, t << (levels - 1)).unwrap(), t);
    for source in [&whole as &dyn PhotoSource, &rows] {
        let maps = pyramid_by_maps(source, &grid, t, levels);
        assert_eq!(
            maps.len(),
            (0..levels).map(|l| 1usize << (2 * l)).sum::<usize>()
        );
        let mut opaque = 0;
        let mut clear = 0;
        for (k, m) in &maps {
            assert!(reference.map(*k).unwrap() == *m, "{k:?}");
            opaque += m.pixels().filter(|p| p.0[3] == 255).count();
            clear += m.pixels().filter(|p| p.0[3] == 0).count();
        }
        assert!(opaque > 0 && clear > 0, "a partial cover: {opaque} {clear}");
    }
    // Stretched (no georeference): the whole photo over the whole extent.
    let stretched = gst::Orthophoto {
        georef: None,
        ..whole
    };
    let reference = gst::pyramid(gst::place(&stretched, &grid, 256).unwrap(), 64);
    let maps = pyramid_by_maps(&stretched, &grid, 64, 3);
    for (k, m) in &maps {
        assert!(reference.map(*k).unwrap() == *m, "{k:?}");
        assert!(m.pixels().all(|p| p.0[3] == 255));
    }
}

#[test]
fn a_database_built_from_rows_equals_one_built_from_the_whole_photo() {
    let grid = srtm();
    let dir = tempfile::tempdir().unwrap();
    let opts = BuildOptions {
        max_error: 20.0,
        chunk: 129,
        map_texels: 64,
        max_texture_levels: 8,
        ..Default::default()
    };
    let whole = gst::read_photo(&data("relief_planar_u16.tif"), Some([1, 2, 3])).unwrap();
    let rows = open_photo(&data("relief_planar_u16.tif"), Some([1, 2, 3])).unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    db::build(&grid, "srtm", Some(&whole), &opts, &a, |_, _| {}).unwrap();
    db::build_with(&grid, "srtm", Some(rows.as_ref()), &opts, &b, |_, _| {}).unwrap();
    let (da, dbb) = (Database::open(&a).unwrap(), Database::open(&b).unwrap());
    let ta = da.manifest.texture.clone().unwrap();
    assert_eq!(Some(ta.clone()), dbb.manifest.texture);
    // One texel per DEM sample at least: 1201 samples -> 64·2^5 = 2048, 6 levels.
    assert_eq!(ta.levels, 6);
    assert_eq!(ta.placed_by, "georeference");
    for level in 0..ta.levels {
        let n = 1 << level;
        for y in 0..n {
            for x in 0..n {
                let f = format!("tiles/{level}/{x}_{y}.png");
                let (fa, fb) = (
                    std::fs::read(a.join(&f)).unwrap(),
                    std::fs::read(b.join(&f)).unwrap(),
                );
                assert!(fa == fb, "{f}");
            }
        }
    }
}

#[test]
fn the_level_count_follows_the_photo_when_it_is_finer_than_the_grid() {
    let grid = srtm(); // 1201 samples a side
    let stretched = gst::Orthophoto {
        image: RgbaImage::new(5000, 3000),
        georef: None,
        source: "big".into(),
    };
    // 5000 pixels over the extent: 256·2^5 = 8192 ≥ 5000 -> 6 levels (the grid alone needs 4).
    assert_eq!(
        gst::photo_level_count(&stretched, &grid, 256, 9).unwrap(),
        6
    );
    assert_eq!(gst::level_count(&grid, 256, 9), 4);
    assert_eq!(
        gst::photo_level_count(&stretched, &grid, 256, 5).unwrap(),
        5
    );
    // The georeferenced relief covers 0.3° of the 1° tile at 320 pixels: 1067 across the extent.
    let relief = TiffPhoto::open(&data("relief_tiled.tif"), None).unwrap();
    assert_eq!(gst::photo_level_count(&relief, &grid, 256, 9).unwrap(), 4);
}

#[test]
fn damaged_photos_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(data("relief_tiled.tif")).unwrap();
    // Cut inside the tile data: the header opens, a band of rows fails, naming the file.
    let cut = dir.path().join("cut.tif");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let p = TiffPhoto::open(&cut, None).unwrap();
    let mut errors = 0;
    for y in (0..240).step_by(16) {
        if let Err(e) = p.rows(y, y + 16) {
            let e = e.to_string();
            assert!(e.contains("cut.tif") && e.contains("chunk"), "{e}");
            errors += 1;
        }
    }
    assert!(errors > 0);
    // Band 0 and a band the file lacks.
    let e = TiffPhoto::open(&data("relief_tiled.tif"), Some([0, 1, 2]))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("1-based"), "{e}");
    let e = TiffPhoto::open(&data("relief_tiled.tif"), Some([4, 1, 2]))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("band") && e.contains('4'), "{e}");
    // A photo beside the grid: no overlap.
    let grid = Grid::new("far", 3, 3, vec![1.0; 9], dem::Georef::local(1.0)).unwrap();
    let relief = TiffPhoto::open(&data("relief_tiled.tif"), None).unwrap();
    assert!(gst::photo_level_count(&relief, &grid, 256, 5).is_err());
}

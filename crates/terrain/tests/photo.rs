//! Orthophotos read by rows (`photo::TiffPhoto`) and GST pyramids written map by map
//! (`gst::write_pyramid`), against the whole-image reader (`gst::read_photo`) and the whole-level
//! pyramid (`gst::pyramid(gst::place(..))`): the same bytes. The photos are GDAL-written GeoTIFFs
//! (tiled, planar, 16-bit) over the real SRTM tile N44W072 (`tests/data/relief_photos.sh`).
//! Several photo tiles mosaicked (`photo::VrtPhoto::mosaic`, `--photo a.tif b.tif`) and GDAL's
//! VRT of them against GDAL's own mosaic (`gdalbuildvrt -addalpha`, then `gdal_translate`) and
//! against `gdalwarp` of the tiles onto a texel lattice when one is in another system
//! (`tests/data/photo_mosaic.sh`).

use image::RgbaImage;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{self, Grid};
use texmap_terrain::gst::{self, MapKey, PhotoSource};
use texmap_terrain::photo::{PhotoOptions, TiffPhoto, VrtPhoto, open_photo, open_photos};

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
        let whole = gst::read_photo(&data(file), &PhotoOptions::bands(bands)).unwrap();
        let rows = TiffPhoto::open(&data(file), &PhotoOptions::bands(bands)).unwrap();
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
    let p = TiffPhoto::open(
        &data("relief_planar_u16.tif"),
        &PhotoOptions::bands(Some([4, 2, 1])),
    )
    .unwrap();
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
    let plain = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let webp = gst::read_photo(&data("photo_rgb_webp.tif"), &PhotoOptions::bands(None)).unwrap();
    assert!(webp.image == plain.image);
    assert_eq!(webp.georef, plain.georef);
    let jpeg = gst::read_photo(&data("photo_rgb_jpeg.tif"), &PhotoOptions::bands(None)).unwrap();
    let gdal =
        gst::read_photo(&data("photo_rgb_jpeg_gdal.tif"), &PhotoOptions::bands(None)).unwrap();
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
        let (r, peak) = crate::alloc::measure(|| {
            gst::read_photo(&path, &PhotoOptions::bands(None)).map(|_| ())
        });
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
    let whole = gst::read_photo(&data("relief_tiled.tif"), &PhotoOptions::bands(None)).unwrap();
    let rows = TiffPhoto::open(&data("relief_tiled.tif"), &PhotoOptions::bands(None)).unwrap();
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
        stretch: None,
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
    let whole = gst::read_photo(
        &data("relief_planar_u16.tif"),
        &PhotoOptions::bands(Some([1, 2, 3])),
    )
    .unwrap();
    let rows = open_photo(
        &data("relief_planar_u16.tif"),
        &PhotoOptions::bands(Some([1, 2, 3])),
    )
    .unwrap();
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
    assert_same_tiles(&a, &b, ta.levels);
}

/// Every map tile of the databases `a` and `b` (`levels` levels) byte for byte.
fn assert_same_tiles(a: &std::path::Path, b: &std::path::Path, levels: u32) {
    for level in 0..levels {
        for y in 0..1u32 << level {
            for x in 0..1u32 << level {
                let f = format!("tiles/{level}/{x}_{y}.png");
                let (fa, fb) = (
                    std::fs::read(a.join(&f)).unwrap(),
                    std::fs::read(b.join(&f)).unwrap(),
                );
                assert!(fa == fb, "{f} differs between {a:?} and {b:?}");
            }
        }
    }
}

#[test]
fn the_level_count_follows_the_photo_when_it_is_finer_than_the_grid() {
    let grid = srtm(); // 1201 samples a side
    let stretched = gst::Orthophoto {
        stretch: None,
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
    let relief = TiffPhoto::open(&data("relief_tiled.tif"), &PhotoOptions::bands(None)).unwrap();
    assert_eq!(gst::photo_level_count(&relief, &grid, 256, 9).unwrap(), 4);
}

#[test]
fn damaged_photos_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(data("relief_tiled.tif")).unwrap();
    // Cut inside the tile data: the header opens, a band of rows fails, naming the file.
    let cut = dir.path().join("cut.tif");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let p = TiffPhoto::open(&cut, &PhotoOptions::bands(None)).unwrap();
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
    let e = TiffPhoto::open(
        &data("relief_tiled.tif"),
        &PhotoOptions::bands(Some([0, 1, 2])),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("1-based"), "{e}");
    let e = TiffPhoto::open(
        &data("relief_tiled.tif"),
        &PhotoOptions::bands(Some([4, 1, 2])),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("band") && e.contains('4'), "{e}");
    // A photo beside the grid: no overlap.
    let grid = Grid::new("far", 3, 3, vec![1.0; 9], dem::Georef::local(1.0)).unwrap();
    let relief = TiffPhoto::open(&data("relief_tiled.tif"), &PhotoOptions::bands(None)).unwrap();
    assert!(gst::photo_level_count(&relief, &grid, 256, 5).is_err());
}

/// The mosaic's tiles (tests/data/photo_mosaic.sh), in mosaic order.
fn tiles(names: &[&str]) -> Vec<PathBuf> {
    names
        .iter()
        .map(|n| data(&format!("mosaic_photo_{n}.tif")))
        .collect()
}

fn whole(p: &dyn PhotoSource) -> RgbaImage {
    p.rows(0, p.size().1).unwrap()
}

/// Tiles on one lattice, mosaicked from the files (`--photo a b c`) and from GDAL's VRT of them:
/// each pixel the top tile's that covers it (c over b over a; b's no-data holes and c's
/// transparent pixels let the tile below show), and GDAL's translation of the VRT pixel for
/// pixel, but where GDAL invents opaque black: in b's hole over no other tile (gdalbuildvrt
/// -addalpha's alpha band writes 255 over a tile's no-data; we leave it transparent).
#[test]
fn several_photos_and_their_vrt_mosaic_as_gdal_mosaics_them() {
    let mosaic = VrtPhoto::mosaic(&tiles(&["a", "b", "c"]), &PhotoOptions::bands(None)).unwrap();
    let vrt = VrtPhoto::open(&data("mosaic_photo.vrt"), &PhotoOptions::bands(None)).unwrap();
    let gdal = TiffPhoto::open(&data("mosaic_photo_gdal.tif"), &PhotoOptions::bands(None)).unwrap();
    assert_eq!(mosaic.size(), (320, 240));
    assert_eq!(vrt.size(), gdal.size());
    let (m, g) = (mosaic.georef().unwrap(), gdal.georef().unwrap());
    assert_eq!((m.crs, m.epsg), (g.crs, g.epsg));
    for (x, y) in [
        (m.origin_x, g.origin_x),
        (m.origin_y, g.origin_y),
        (m.dx, g.dx),
        (m.dy, g.dy),
    ] {
        assert!((x - y).abs() < 1e-12, "{m:?} vs {g:?}");
    }
    assert_eq!(vrt.georef(), mosaic.georef());
    let (ours, from_vrt, reference) = (whole(&mosaic), whole(&vrt), whole(&gdal));
    assert!(ours == from_vrt, "the --photo mosaic and the VRT differ");
    // The tiles themselves, at their places on the lattice (columns, rows).
    let own: Vec<(RgbaImage, u32, u32)> = [("c", 60, 110), ("b", 150, 0), ("a", 0, 0)]
        .into_iter()
        .map(|(n, x, y)| {
            (
                whole(
                    &TiffPhoto::open(
                        &data(&format!("mosaic_photo_{n}.tif")),
                        &PhotoOptions::bands(None),
                    )
                    .unwrap(),
                ),
                x,
                y,
            )
        })
        .collect();
    let (mut equal, mut invented, mut through, mut clear) = (0, 0, 0, 0);
    for (x, y, px) in ours.enumerate_pixels() {
        let mut covering = own.iter().filter_map(|(t, ox, oy)| {
            t.get_pixel_checked(x.wrapping_sub(*ox), y.wrapping_sub(*oy))
        });
        let under = covering.clone().find(|p| p.0[3] == 255);
        // A tile's pixel that does not cover, with a tile below that does: fall-through.
        if covering.next().is_some_and(|p| p.0[3] == 0) && under.is_some() {
            through += 1;
        }
        assert_eq!(
            *px,
            under.copied().unwrap_or(image::Rgba([0; 4])),
            "pixel ({x}, {y})"
        );
        let r = reference.get_pixel(x, y);
        if px == r {
            equal += 1;
        } else {
            // Only GDAL's opaque black where our mosaic is clear.
            assert_eq!((px.0, r.0), ([0; 4], [0, 0, 0, 255]), "pixel ({x}, {y})");
            invented += 1;
        }
        if px.0[3] == 0 {
            clear += 1;
        }
    }
    eprintln!(
        "mosaic of 3 tiles: {equal} of {} pixels equal to GDAL's, {invented} opaque black in \
         GDAL's (b's hole over no tile), {through} fall through to a lower tile, {clear} clear",
        320 * 240
    );
    assert!(
        invented > 100 && through > 1000 && clear > invented,
        "{invented} {through} {clear}"
    );
    assert_eq!(equal + invented, 320 * 240);
    // Read a band of rows at a time, top to bottom and out of order: the same pixels.
    for p in [&mosaic as &dyn PhotoSource, &vrt] {
        for (y0, y1) in [(0, 37), (30, 111), (100, 240), (5, 6), (0, 240)] {
            let band = p.rows(y0, y1).unwrap();
            let want = image::imageops::crop_imm(&ours, 0, y0, 320, y1 - y0).to_image();
            assert!(band == want, "rows {y0}..{y1}");
        }
    }
}

/// A grid in degrees over the tiles (sample centres -71.40..-71.18 E, 44.38..44.20 N), heights a
/// ramp, whose 257² texel lattice `ref_mosaic_photo.png` was warped onto.
fn mosaic_grid() -> Grid {
    let (w, h) = (97u32, 81u32);
    let heights = (0..w * h)
        .map(|i| 300.0 + 9.0 * (i % w) as f32 + 4.0 * (i / w) as f32)
        .collect();
    let georef = dem::Georef {
        crs: dem::CrsKind::Geographic,
        epsg: Some(4326),
        origin_x: -71.40,
        origin_y: 44.38,
        dx: 0.22 / 96.0,
        dy: -0.18 / 80.0,
    };
    Grid::new("mosaic grid", w, h, heights, georef).unwrap()
}

/// With a tile in UTM 19N among tiles in degrees, the mosaic reprojects it and the texture placed
/// on a grid in degrees agrees with gdalwarp of the four tiles onto the same texel lattice:
/// texels where only the three tiles in degrees show within one code (as a single photo's
/// placement, tests/reproject.rs), texels where the UTM tile shows (resampled twice: into the
/// mosaic, then onto the texels; gdalwarp once) within a stated tolerance.
#[test]
fn a_tile_in_another_system_is_reprojected_into_the_mosaic_as_gdalwarp_places_it() {
    let grid = mosaic_grid();
    let mosaic = VrtPhoto::mosaic(
        &tiles(&["a", "b", "c", "d_utm"]),
        &PhotoOptions::bands(None),
    )
    .unwrap();
    // The UTM tile's outline (its transparent margin too) reaches past the others'.
    let (w, h) = mosaic.size();
    assert!(w > 320 && h > 240 && w < 330 && h < 250, "{w} x {h}");
    let photo = gst::Orthophoto {
        stretch: None,
        image: whole(&mosaic),
        georef: mosaic.georef(),
        source: "mosaic".into(),
    };
    let ours = gst::place(&photo, &grid, 257).unwrap();
    let gdal = image::open(data("ref_mosaic_photo.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(gdal.dimensions(), (257, 257));
    // Where the UTM tile lies on the texture, two texels around its outline included (the
    // tile placed alone, as a single photo).
    let alone =
        gst::read_photo(&data("mosaic_photo_d_utm.tif"), &PhotoOptions::bands(None)).unwrap();
    let alone = gst::place(&alone, &grid, 257).unwrap();
    let near = |img: &RgbaImage, x: u32, y: u32, hit: &dyn Fn(u8) -> bool| {
        (x.saturating_sub(2)..(x + 3).min(257))
            .any(|i| (y.saturating_sub(2)..(y + 3).min(257)).any(|j| hit(img.get_pixel(i, j).0[3])))
    };
    // Where the tiles' coverage ends (their outlines, b's no-data holes, c's pentagon): placed
    // alone, their texels there are partly transparent.
    let edges: Vec<RgbaImage> = ["a", "b", "c"]
        .iter()
        .map(|n| {
            let p = gst::read_photo(
                &data(&format!("mosaic_photo_{n}.tif")),
                &PhotoOptions::bands(None),
            )
            .unwrap();
            gst::place(&p, &grid, 257).unwrap()
        })
        .collect();
    #[derive(Default, Debug)]
    struct Tally {
        texels: usize,
        sum: u64,
        max: u8,
        over_8: usize,
    }
    let (mut same, mut edge, mut warped) = (Tally::default(), Tally::default(), Tally::default());
    let mut warped_edge = Tally::default();
    let mut one_side = 0usize;
    for ((x, y, a), b) in ours.enumerate_pixels().zip(gdal.pixels()) {
        match (a.0[3], b.0[3]) {
            (255, 255) => {
                let t = if near(&alone, x, y, &|a| a > 0) {
                    if near(&alone, x, y, &|a| a < 255) {
                        &mut warped_edge
                    } else {
                        &mut warped
                    }
                } else if edges.iter().any(|e| near(e, x, y, &|a| a > 0 && a < 255)) {
                    &mut edge
                } else {
                    &mut same
                };
                t.texels += 1;
                for k in 0..3 {
                    let d = a.0[k].abs_diff(b.0[k]);
                    t.sum += d as u64;
                    t.max = t.max.max(d);
                    if d > 8 {
                        t.over_8 += 1;
                    }
                }
            }
            (0, 0) => {}
            _ => one_side += 1,
        }
    }
    let mean = |t: &Tally| t.sum as f64 / (3 * t.texels.max(1)) as f64;
    eprintln!(
        "texels of the tiles in degrees: {} (mean |diff| {:.3}, max {}); by their transparent \
         edges: {} (mean {:.3}, max {}, {} channels above 8); of the UTM tile: {} (mean {:.3}, \
         max {}, {} channels above 8), by its edge {} (mean {:.3}, max {}, {} channels above 8); \
         {one_side} texels one side only",
        same.texels,
        mean(&same),
        same.max,
        edge.texels,
        mean(&edge),
        edge.max,
        edge.over_8,
        warped.texels,
        mean(&warped),
        warped.max,
        warped.over_8,
        warped_edge.texels,
        mean(&warped_edge),
        warped_edge.max,
        warped_edge.over_8
    );
    assert!(
        same.texels > 30_000 && mean(&same) < 0.05 && same.max <= 1,
        "{same:?}"
    );
    // Along a later tile's transparent edge gdalwarp darkens the texels it blends over the tiles
    // below (the same relief on both sides); ours keep the relief.
    assert!(
        mean(&edge) < 1.0 && edge.over_8 * 20 < 3 * edge.texels,
        "{edge:?}"
    );
    // The UTM tile, resampled twice here and once by gdalwarp: within 12 codes inside it.
    assert!(
        warped.texels > 4_000 && mean(&warped) < 1.0 && warped.max <= 12,
        "{warped:?}"
    );
    assert!(mean(&warped_edge) < 2.0, "{warped_edge:?}");
    assert!(one_side < 1_000, "{one_side} texels on one side only");
}

/// A database built from the mosaic: where no tile covers (b's hole over no tile, the corners
/// outside c's pentagon) the texture is the grid's shaded relief, nowhere transparent; the same
/// bytes for any thread count; and reading a band of the mosaic's rows holds only the tiles
/// under them.
#[test]
fn a_mosaic_database_shows_the_relief_where_no_tile_covers_for_any_thread_count() {
    let grid = mosaic_grid();
    let dir = tempfile::tempdir().unwrap();
    let opts = BuildOptions {
        max_error: 5.0,
        chunk: 33,
        map_texels: 64,
        max_texture_levels: 8,
        ..Default::default()
    };
    let files = tiles(&["a", "b", "c", "d_utm"]);
    let build = |threads: usize, name: &str| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let out = dir.path().join(name);
        let photo = open_photos(&files, &PhotoOptions::bands(None)).unwrap();
        pool.install(|| {
            db::build_with(
                &grid,
                "mosaic",
                Some(photo.as_ref()),
                &opts,
                &out,
                |_, _| {},
            )
        })
        .unwrap();
        out
    };
    let (one, three) = (build(1, "one"), build(3, "three"));
    let d = Database::open(&one).unwrap();
    let t = d.manifest.texture.clone().unwrap();
    assert_eq!(t.placed_by, "georeference");
    assert_same_tiles(&one, &three, t.levels);
    let tex = d.texture(1 << 20).unwrap().unwrap();
    let size = tex.width();
    assert!(tex.pixels().all(|p| p.0[3] == 255), "no transparent texel");
    let shade = texmap_terrain::relief::Hillshade::new(&grid, Default::default());
    let texel = |lon: f64, lat: f64| {
        let u = (lon + 71.40) / 0.22;
        let v = (44.38 - lat) / 0.18;
        let s = (size - 1) as f64;
        ((u * s).round() as u32, (v * s).round() as u32)
    };
    // b's hole over no tile, and west of c's pentagon below tile a: the relief.
    for (lon, lat) in [(-71.19, 44.35), (-71.395, 44.215)] {
        let (x, y) = texel(lon, lat);
        let relief = texmap_terrain::relief::relief_texel(&grid, &shade, size, x, y);
        assert_eq!(tex.get_pixel(x, y).0, relief, "({lon}, {lat})");
    }
    // Tile a's pixels there, not the relief.
    let (x, y) = texel(-71.39, 44.37);
    let relief = texmap_terrain::relief::relief_texel(&grid, &shade, size, x, y);
    assert_ne!(tex.get_pixel(x, y).0, relief);
    // Streaming: eight rows of the mosaic read the strips of the two tiles under them; the whole
    // mosaic, every tile.
    let peak = |y1: u32| {
        let mosaic = VrtPhoto::mosaic(&files, &PhotoOptions::bands(None)).unwrap();
        let (band, peak) = crate::alloc::measure(|| mosaic.rows(0, y1).map(|b| b.len()));
        assert_eq!(band.unwrap(), mosaic.size().0 as usize * y1 as usize * 4);
        peak
    };
    let (band, all) = (peak(8), peak(240));
    eprintln!("heap peak reading rows 0..8 of the mosaic: {band} bytes; rows 0..240: {all}");
    assert!(band * 4 < all, "{band} vs {all} bytes");
}

/// Photos that make no mosaic are refused by name: one without a georeference, and photos of two
/// areas (the tiles in degrees and a photo in UTM 54N, in Japan); a directory stands for the
/// GeoTIFFs in it, in the order of their names.
#[test]
fn photos_that_make_no_mosaic_are_refused_and_a_directory_is_its_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("plain.png");
    RgbaImage::new(8, 8).save(&png).unwrap();
    let e = VrtPhoto::mosaic(
        &[data("mosaic_photo_a.tif"), png],
        &PhotoOptions::bands(None),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("plain.png") && e.contains("without a georeference"),
        "{e}"
    );
    let e = VrtPhoto::mosaic(
        &[data("mosaic_photo_a.tif"), data("photo_rgb.tif")],
        &PhotoOptions::bands(None),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("photo_rgb.tif") && e.contains("do the photos cover one area"),
        "{e}"
    );
    // Named so that the directory's order is the mosaic's.
    for (n, to) in [("a", "1.tif"), ("b", "2.tif"), ("c", "3.tif")] {
        std::fs::copy(data(&format!("mosaic_photo_{n}.tif")), dir.path().join(to)).unwrap();
    }
    std::fs::remove_file(dir.path().join("plain.png")).unwrap();
    let from_dir = open_photos(&[dir.path().to_path_buf()], &PhotoOptions::bands(None)).unwrap();
    let listed = VrtPhoto::mosaic(&tiles(&["a", "b", "c"]), &PhotoOptions::bands(None)).unwrap();
    assert!(whole(from_dir.as_ref()) == whole(&listed));
}

/// numpy's percentiles of `tests/data/stretch.py`'s scenes, per band `[low, high]`.
fn numpy_ranges(key: &str) -> [[f64; 2]; 3] {
    let text = std::fs::read_to_string(data("sat_percentiles.json")).unwrap();
    let all: HashMap<String, [[f64; 2]; 3]> = serde_json::from_str(&text).unwrap();
    all[key]
}

/// Our 8-bit rendering of `file` by `opts` against GDAL's `gdal_translate -scale` of it
/// (`expected`), over the covered pixels: the largest difference in levels, and the
/// transparent pixels, which must be exactly the scene's no-data wedge.
fn against_gdal(file: &str, opts: &PhotoOptions, expected: &str) -> (u8, Option<[[f64; 2]; 3]>) {
    let ours = gst::read_photo(&data(file), opts).unwrap();
    let gdal = gst::read_photo(&data(expected), &PhotoOptions::default())
        .unwrap()
        .image;
    assert_eq!(ours.image.dimensions(), gdal.dimensions());
    let mut worst = 0;
    for (x, y, p) in ours.image.enumerate_pixels() {
        let wedge = x + y < 30;
        assert_eq!(
            p[3],
            if wedge { 0 } else { 255 },
            "{file} alpha at ({x}, {y})"
        );
        if !wedge {
            let q = gdal.get_pixel(x, y);
            for k in 0..3 {
                worst = worst.max(p[k].abs_diff(q[k]));
            }
        }
    }
    (worst, ours.stretch.map(|a| a.ranges))
}

#[test]
fn percentile_stretch_takes_numpys_percentiles_and_gdals_scaling() {
    use texmap_terrain::photo::Stretch;
    let percent = |lo, hi, gamma| PhotoOptions {
        bands: None,
        stretch: Stretch::Percent(lo, hi),
        gamma,
    };
    // 16-bit samples: exact histograms, so numpy's percentiles to the sample.
    let (worst, ranges) = against_gdal(
        "sat_u16.tif",
        &percent(2.0, 98.0, 1.0),
        "sat_u16_p2_98_gdal.tif",
    );
    assert_eq!(ranges, Some(numpy_ranges("sat_u16 2,98")));
    assert!(worst <= 1, "2-98 %: {worst} levels from GDAL");
    let (worst, ranges) = against_gdal(
        "sat_u16.tif",
        &percent(1.0, 99.0, 2.0),
        "sat_u16_p1_99_gamma2_gdal.tif",
    );
    assert_eq!(ranges, Some(numpy_ranges("sat_u16 1,99")));
    assert!(worst <= 1, "1-99 %, gamma 2: {worst} levels from GDAL");
    // Float reflectance: 65,536 bins over the range, each percentile within half a bin.
    let (worst, ranges) = against_gdal(
        "sat_f32.tif",
        &percent(2.0, 98.0, 1.0),
        "sat_f32_p2_98_gdal.tif",
    );
    let (ranges, numpy) = (ranges.unwrap(), numpy_ranges("sat_f32 2,98"));
    let minmax = numpy_ranges("sat_u16 minmax");
    for k in 0..3 {
        let half_bin = (minmax[k][1] - minmax[k][0]) / 1e4 / 131_072.0;
        for e in 0..2 {
            let d = (ranges[k][e] - numpy[k][e]).abs();
            assert!(
                d <= half_bin * 1.01,
                "band {k}: {ranges:?} against {numpy:?}"
            );
        }
    }
    assert!(worst <= 1, "float 2-98 %: {worst} levels from GDAL");
    // The same scene through gdalbuildvrt's VRT, and as a mosaic of one, gives the same pixels.
    let tif = gst::read_photo(&data("sat_u16.tif"), &percent(2.0, 98.0, 1.0)).unwrap();
    let vrt = gst::read_photo(&data("sat_u16.vrt"), &percent(2.0, 98.0, 1.0)).unwrap();
    assert_eq!(vrt.stretch, tif.stretch);
    assert!(vrt.image == tif.image);
    // A 16-bit PNG (a window of the scene, without no-data).
    let png = gst::read_photo(&data("sat_u16_crop.png"), &percent(2.0, 98.0, 1.0)).unwrap();
    let applied = png.stretch.unwrap();
    assert_eq!(applied.ranges, numpy_ranges("sat_u16_crop.png 2,98"));
    assert_eq!(applied.rule, "percent:2,98");
    let crop = image::open(data("sat_u16_crop.png")).unwrap().to_rgb16();
    for (x, y, p) in png.image.enumerate_pixels() {
        let q = crop.get_pixel(x, y);
        for k in 0..3 {
            let [lo, hi] = applied.ranges[k];
            let want = ((q[k] as f64 - lo) * 255.0 / (hi - lo))
                .round()
                .clamp(0.0, 255.0);
            assert!((p[k] as f64 - want).abs() <= 1.0, "PNG ({x}, {y})");
        }
    }
}

#[test]
fn range_stretch_is_gdal_translates_scale_and_auto_is_minmax() {
    use texmap_terrain::photo::Stretch;
    let range = PhotoOptions {
        stretch: "range:0,3000".parse::<Stretch>().unwrap(),
        ..PhotoOptions::default()
    };
    let (worst, ranges) = against_gdal("sat_u16.tif", &range, "sat_u16_range_gdal.tif");
    assert_eq!(ranges, Some([[0.0, 3000.0]; 3]));
    assert!(worst <= 1, "range 0-3000: {worst} levels from GDAL");
    // 16-bit samples by default: each band's lowest to highest covered sample; the clouds'
    // brightness leaves the land in the lowest tenth of the levels.
    let auto = gst::read_photo(&data("sat_u16.tif"), &PhotoOptions::default()).unwrap();
    let applied = auto.stretch.unwrap();
    assert_eq!(applied.rule, "minmax");
    assert_eq!(applied.ranges, numpy_ranges("sat_u16 minmax"));
    // 8-bit photos stay as they are unless asked.
    let plain = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::default()).unwrap();
    assert!(plain.stretch.is_none());
}

#[test]
fn percentile_stretch_of_an_8_bit_photo_matches_sorting() {
    use texmap_terrain::photo::Stretch;
    let plain = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::default()).unwrap();
    let opts = PhotoOptions {
        stretch: Stretch::Percent(5.0, 95.0),
        ..PhotoOptions::default()
    };
    let stretched = gst::read_photo(&data("photo_rgb.tif"), &opts).unwrap();
    let ranges = stretched.stretch.unwrap().ranges;
    for (k, range) in ranges.iter().enumerate() {
        let mut v: Vec<u8> = plain.image.pixels().map(|p| p[k]).collect();
        v.sort_unstable();
        let at = 0.05 * (v.len() - 1) as f64;
        let high = 0.95 * (v.len() - 1) as f64;
        assert_eq!(
            *range,
            [
                v[at.floor() as usize] as f64,
                v[high.ceil() as usize] as f64
            ],
            "band {k}"
        );
    }
}

#[test]
fn bad_stretches_and_gammas_are_refused() {
    use texmap_terrain::photo::Stretch;
    for bad in [
        "percent:98,2",
        "percent:2",
        "percent:-1,50",
        "percent:2,101",
        "range:5,5",
        "range:0,1,2",
        "range:a,b",
        "range:0,nan",
        "gamma",
        "minmax:1",
        "",
    ] {
        assert!(bad.parse::<Stretch>().is_err(), "{bad}");
    }
    for (ok, want) in [
        ("percent:2,98", Stretch::Percent(2.0, 98.0)),
        ("minmax", Stretch::MinMax),
        ("range:0,3000", Stretch::Range([(0.0, 3000.0); 3])),
        (
            "range:1,2,3,4,5,6",
            Stretch::Range([(1.0, 2.0), (3.0, 4.0), (5.0, 6.0)]),
        ),
    ] {
        assert_eq!(ok.parse::<Stretch>().unwrap(), want);
    }
    for gamma in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let opts = PhotoOptions {
            gamma,
            ..PhotoOptions::default()
        };
        let e = gst::read_photo(&data("sat_u16.tif"), &opts).unwrap_err();
        assert!(e.to_string().contains("gamma"), "{e}");
    }
}

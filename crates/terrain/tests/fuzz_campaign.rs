//! The terrain readers in the fuzz campaign every reader of the project runs (the harness is
//! md-io's `tests/support/`, shared by path): GeoTIFF files written by GDAL (five sample types,
//! strips and tiles, LZW, BigTIFF, PixelIsPoint), the ESRI ASCII grid GDAL wrote, GDAL's DTED
//! level 0 cell and 16-bit BIL (its `.hdr` and its samples mutated apart), and an SRTM
//! `.hgt` tile and a 16-bit PNG made here; and the vector overlays and recorded flights (GeoJSON,
//! GPX, IGC) written by ogr2ogr, gpxpy and aerofiles; and the lidar point clouds (LAS 1.2 and
//! 1.4 by laspy, LAZ by LASzip), read and gridded; and GDAL VRTs (gdalbuildvrt's mosaics of
//! DEM pieces and of photo tiles, beside intact copies of their sources). Each mutant — a cut, bit flips, byte
//! replacements, header fields set to extremes — must end in a grid or an error naming the file,
//! never a panic, under a heap cap of 64x the mutant's size + 1 MiB (+ 4 MiB for LAZ, whose
//! decoder's models take 2.5 MB for any file).
//!
//! `cargo test -p texmap-terrain --test suite fuzz_campaign:: -- --nocapture` prints the table.

use std::path::{Path, PathBuf};

use crate::campaign::{Cuts, Field, Fixture, Settings, Verdict, run_campaign};
use texmap_terrain::TerrainError;
use texmap_terrain::dem::{self, Grid};
use texmap_terrain::photo::PhotoOptions;

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn fixture(name: &str, bytes: Vec<u8>, fields: Vec<(&'static str, Field)>, text: bool) -> Fixture {
    let n = bytes.len();
    Fixture {
        name: name.into(),
        frames: 1,
        boundaries: (1..16).map(|k| k * n / 16).collect(),
        cuts: Cuts::Declared,
        fields,
        text,
        bytes,
    }
}

/// A grid read, or an error that names the file: the campaign's verdict for one mutant.
fn verdict(result: Result<Grid, TerrainError>, file: &Path) -> Verdict {
    match result {
        Ok(g) => {
            if g.heights().len() != g.width() as usize * g.height() as usize {
                return Verdict::Broken("heights and size disagree".into());
            }
            if g.heights().iter().any(|h| h.is_infinite()) {
                return Verdict::Broken("an infinite height in a grid".into());
            }
            Verdict::Ok { frames: 1 }
        }
        Err(e) => {
            let msg = e.to_string();
            let name = file.file_name().unwrap().to_string_lossy();
            if msg.contains(name.as_ref()) {
                Verdict::Located(match e {
                    TerrainError::Io { .. } => "Io",
                    TerrainError::Format { .. } => "Format",
                    TerrainError::Unsupported { .. } => "Unsupported",
                    TerrainError::BadSize { .. } => "BadSize",
                    TerrainError::NonFinite { .. } => "NonFinite",
                    TerrainError::AllNoData { .. } => "AllNoData",
                    _ => "other",
                })
            } else {
                Verdict::Broken(format!("an error that names no file: {msg}"))
            }
        }
    }
}

/// A cut of a single-grid file is never a complete grid: with `Cuts::Declared` the harness
/// expects an error for every cut short of the end, but a TIFF cut after its last strip's data
/// still holds the whole image, so TIFF fixtures use `Cuts::Unchecked`.
fn unchecked(mut f: Fixture) -> Fixture {
    f.cuts = Cuts::Unchecked;
    f
}

#[test]
fn terrain_readers_survive_the_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let settings = Settings {
        seeded_cuts: 24,
        flips: 256,
        ..Settings::default()
    };
    let mut report = String::new();

    // GeoTIFF (bytes 4..8: the first IFD offset, a field every reader trusts first).
    let tiffs: Vec<Fixture> = [
        "ramp_i16_lzw.tif",
        "ramp_u16_tiled_bigtiff.tif",
        "ramp_i32_point.tif",
        "ramp_f32_geo.tif",
        "ramp_f64.tif",
        "ramp_i16_zstd.tif",
        "ramp_f32_zstd.tif",
        "photo_rgb_webp.tif",
        "photo_rgb_jpeg.tif",
    ]
    .iter()
    .map(|n| {
        let bytes = data(n);
        let ifd = if bytes.get(2) == Some(&43) {
            vec![]
        } else {
            vec![("first IFD offset", Field::I32Le(4))]
        };
        unchecked(fixture(n, bytes, ifd, false))
    })
    .collect();
    let path = dir.path().join("mutant.tif");
    let t = run_campaign("GeoTIFF", &tiffs, &settings, &|_, bytes| {
        std::fs::write(&path, bytes).unwrap();
        verdict(dem::geotiff::read_geotiff(&path), &path)
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // 16-bit and float satellite scenes read as photos stretched between percentiles: the
    // histograms meet whatever samples a mutant decodes to (NaN, infinities, any range).
    let scenes: Vec<Fixture> = ["sat_u16.tif", "sat_f32.tif"]
        .iter()
        .map(|n| {
            let ifd = vec![("first IFD offset", Field::I32Le(4))];
            unchecked(fixture(n, data(n), ifd, false))
        })
        .collect();
    let percent = PhotoOptions {
        stretch: texmap_terrain::photo::Stretch::Percent(2.0, 98.0),
        gamma: 1.5,
        ..PhotoOptions::default()
    };
    let t = run_campaign("GeoTIFF photo, 2-98 %", &scenes, &settings, &|_, bytes| {
        std::fs::write(&path, bytes).unwrap();
        match texmap_terrain::gst::read_photo(&path, &percent) {
            Ok(_) => Verdict::Ok { frames: 1 },
            Err(e) => located(e.to_string(), "mutant.tif", "read"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // ESRI ASCII (text: the ncols number set to extremes).
    let asc = data("ramp_gdal.asc");
    let text = String::from_utf8(asc.clone()).unwrap();
    let start = text.find(|c: char| c.is_ascii_digit()).unwrap();
    let end = start + text[start..].find(|c: char| !c.is_ascii_digit()).unwrap();
    let fx = vec![unchecked(fixture(
        "ramp_gdal.asc",
        asc,
        vec![("ncols", Field::Text(start, end))],
        true,
    ))];
    let t = run_campaign("ESRI ASCII", &fx, &settings, &|_, bytes| {
        let name = "ramp_gdal.asc";
        match std::str::from_utf8(bytes) {
            Ok(s) => verdict(dem::asc::read_asc_str(s, name), Path::new(name)),
            Err(_) => Verdict::Located("not UTF-8"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // Gridded XYZ (text: the first line's x set to extremes, which stretches the lattice).
    let fx: Vec<Fixture> = ["ramp_i16.xyz", "ramp_geo.xyz"]
        .iter()
        .map(|n| {
            let bytes = data(n);
            let text = String::from_utf8(bytes.clone()).unwrap();
            let start = text.find(|c: char| c.is_ascii_digit()).unwrap();
            let end = start + text[start..].find([' ', ';']).unwrap();
            unchecked(fixture(
                n,
                bytes,
                vec![("x", Field::Text(start, end))],
                true,
            ))
        })
        .collect();
    let t = run_campaign("XYZ", &fx, &settings, &|_, bytes| {
        let name = "ramp.xyz";
        match std::str::from_utf8(bytes) {
            Ok(s) => verdict(
                dem::xyz::read_xyz_str(s, name, (dem::CrsKind::Local, None)),
                Path::new(name),
            ),
            Err(_) => Verdict::Located("not UTF-8"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // SRTM .hgt: 1201² big-endian i16 with voids; the size is the whole header, so every cut is
    // an error.
    let mut hgt = Vec::with_capacity(1201 * 1201 * 2);
    for k in 0..1201 * 1201u32 {
        let h: i16 = if k % 997 == 0 {
            -32768
        } else {
            (k % 3000) as i16
        };
        hgt.extend_from_slice(&h.to_be_bytes());
    }
    let fx = vec![fixture("N35E138.hgt", hgt, vec![], false)];
    let hgt_path = dir.path().join("N35E138.hgt");
    let small = Settings {
        flips: 32,
        seeded_cuts: 8,
        ..settings.clone()
    };
    let t = run_campaign("SRTM hgt", &fx, &small, &|_, bytes| {
        std::fs::write(&hgt_path, bytes).unwrap();
        verdict(dem::hgt::read_hgt(&hgt_path), &hgt_path)
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // DTED: GDAL's level 0 cell, checksums verified (every record boundary a cut; the UHL's
    // line and point counts, ASCII, set to extremes).
    let dt0 = data("n44w072.dt0");
    let record = 12 + 2 * 121;
    let mut fx = fixture(
        "n44w072.dt0",
        dt0,
        vec![
            ("UHL longitude lines", Field::Text(47, 51)),
            ("UHL latitude points", Field::Text(51, 55)),
        ],
        false,
    );
    fx.boundaries = (0..=121)
        .map(|k| dem::dted::HEADER_LEN + k * record)
        .chain([80, 728])
        .collect();
    let t = run_campaign("DTED", &[fx], &settings, &|_, bytes| {
        let name = "n44w072.dt0";
        let r = dem::dted::read_dted_bytes(bytes, name, dem::dted::Checksums::Verify);
        verdict(r, Path::new(name))
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // ESRI .hdr rasters: GDAL's 16-bit BIL, its header text mutated over the true samples (NCOLS
    // and the row strides set to extremes), then its samples cut and flipped under the true
    // header.
    let hdr = data("ramp_i16.hdr");
    let bil = data("ramp_i16.bil");
    let text = String::from_utf8(hdr.clone()).unwrap();
    // The value after a key, as a text field.
    let value = |key: &str, v: &str| {
        let k = text.find(key).unwrap();
        let start = k + text[k..].find(v).unwrap();
        Field::Text(start, start + v.len())
    };
    let fields = vec![
        ("NCOLS", value("NCOLS", "37")),
        ("BANDROWBYTES", value("BANDROWBYTES", "74")),
        ("TOTALROWBYTES", value("TOTALROWBYTES", "74")),
    ];
    let mut fx = unchecked(fixture("ramp_i16.hdr", hdr, fields, true));
    fx.boundaries = crate::campaign::line_starts(&fx.bytes);
    // An error must name the header or the data file, whichever holds the fault.
    let either = |r: Result<Grid, TerrainError>| {
        let named = match &r {
            Err(e) => ["ramp_i16.hdr", "ramp_i16.bil"]
                .into_iter()
                .find(|n| e.to_string().starts_with(&format!("{n}: "))),
            Ok(_) => Some(""),
        };
        match named {
            Some(n) => verdict(r, Path::new(n)),
            None => Verdict::Broken(format!("an error that names neither file: {:?}", r.err())),
        }
    };
    let parts = |header: &str, samples: &[u8]| {
        dem::ehdr::read_ehdr_parts(&dem::ehdr::EhdrParts {
            header,
            header_name: "ramp_i16.hdr",
            data: samples,
            data_name: "ramp_i16.bil",
            prj: None,
            gridfloat: false,
        })
    };
    let t = run_campaign("ESRI .hdr header", &[fx], &settings, &|_, bytes| {
        either(parts(&String::from_utf8_lossy(bytes), &bil))
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());
    let mut fx = fixture("ramp_i16.bil", bil.clone(), vec![], false);
    fx.boundaries = (0..29).map(|r| r * 74).collect();
    let t = run_campaign("ESRI .hdr samples", &[fx], &settings, &|_, bytes| {
        either(parts(&text, bytes))
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // A 16-bit PNG heightmap written by the image crate.
    let png_path = dir.path().join("height16.png");
    let img = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(33, 21, |x, y| {
        image::Luma([(x * 900 + y * 50) as u16])
    });
    img.save(&png_path).unwrap();
    let fx = vec![unchecked(fixture(
        "height16.png",
        std::fs::read(&png_path).unwrap(),
        vec![],
        false,
    ))];
    let mutant = dir.path().join("mutant16.png");
    let t = run_campaign("16-bit PNG", &fx, &settings, &|_, bytes| {
        std::fs::write(&mutant, bytes).unwrap();
        verdict(dem::png::read_png16(&mutant, 0.1, -10.0, 30.0), &mutant)
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());
    eprintln!("{report}");
}

/// An error's verdict: located when its text names the file.
fn located(msg: String, name: &str, kind: &'static str) -> Verdict {
    if msg.contains(name) {
        Verdict::Located(kind)
    } else {
        Verdict::Broken(format!("an error that names no file: {msg}"))
    }
}

/// The vector overlays (GeoJSON written by ogr2ogr in three forms) and the recorded flights
/// (GPX by gpxpy and GDAL, IGC by aerofiles): each mutant is read and placed on, or flown over,
/// the grid of their tests (an overlay drawn into every map), ending in a result or an error
/// naming the file.
#[test]
fn overlay_and_track_readers_survive_the_campaign() {
    use texmap_terrain::track::{self, TrackOptions};
    use texmap_terrain::vector::{self, Overlay, Style};
    use texmap_terrain::view::FlightCamera;
    let grid = dem::read_dem(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/hillshade_dem_utm.tif"),
        &Default::default(),
    )
    .unwrap();
    let settings = Settings {
        seeded_cuts: 24,
        flips: 128,
        ..Settings::default()
    };
    let mut report = String::new();
    let text = |n: &str| unchecked(fixture(n, data(n), vec![], true));

    let fx: Vec<Fixture> = [
        "vector_utm.geojson",
        "vector_wgs84.geojson",
        "vector_wgs84.geojsons",
    ]
    .iter()
    .map(|n| text(n))
    .collect();
    let t = run_campaign("GeoJSON", &fx, &settings, &|f, bytes| {
        let layer = match vector::parse_geojson(bytes, &f.name) {
            Ok(l) => l,
            Err(e) => return located(e.to_string(), &f.name, "parse"),
        };
        match Overlay::place(&[layer], &Style::default(), &grid, 128, 64) {
            Ok(o) => {
                for my in 0..2 {
                    for mx in 0..2 {
                        let mut m = image::RgbaImage::new(64, 64);
                        o.draw(mx, my, &mut m);
                    }
                }
                Verdict::Ok { frames: 1 }
            }
            Err(e) => located(e.to_string(), &f.name, "place"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    // Shapefiles: the geometry parsed, placed as the UTM layer its .prj names, drawn.
    let fx: Vec<Fixture> = [
        "shp_utm_area.shp",
        "shp_z_area.shp",
        "shp_utm_line.shp",
        "shp_utm_point.shp",
    ]
    .iter()
    .map(|n| unchecked(fixture(n, data(n), vec![], false)))
    .collect();
    let utm = vector::read_vector(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/shp_utm_line.shp"),
    )
    .unwrap()
    .crs;
    let t = run_campaign("shapefile", &fx, &settings, &|f, bytes| {
        let features = match texmap_terrain::shapefile::parse_shp(bytes, &f.name) {
            Ok(l) => l,
            Err(e) => return located(e.to_string(), &f.name, "parse"),
        };
        let layer = vector::VectorLayer {
            source: f.name.clone(),
            crs: utm,
            features,
        };
        match Overlay::place(&[layer], &Style::default(), &grid, 128, 64) {
            Ok(o) => {
                let mut m = image::RgbaImage::new(64, 64);
                o.draw(1, 1, &mut m);
                Verdict::Ok { frames: 1 }
            }
            Err(e) => located(e.to_string(), &f.name, "place"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());

    let fx: Vec<Fixture> = ["track_gpxpy.gpx", "track_ogr.gpx", "track_aerofiles.igc"]
        .iter()
        .map(|n| text(n))
        .collect();
    let template = FlightCamera {
        width: 32,
        height: 24,
        ..FlightCamera::over(&grid)
    };
    let t = run_campaign("GPX / IGC", &fx, &settings, &|f, bytes| {
        let text = String::from_utf8_lossy(bytes);
        let parsed = if f.name.ends_with(".igc") {
            track::parse_igc(&text, &f.name)
        } else {
            track::parse_gpx(&text, &f.name)
        };
        let t = match parsed {
            Ok(t) => t,
            Err(e) => return located(e.to_string(), &f.name, "parse"),
        };
        let opts = TrackOptions {
            speedup: Some(4.0),
            ..TrackOptions::default()
        };
        match track::track_views(&t, &grid, &template, &opts) {
            Ok(v) if v.views.iter().all(|c| c.camera(&grid).is_ok()) => Verdict::Ok { frames: 1 },
            Ok(_) => Verdict::Broken("a view that is no camera over the grid".into()),
            Err(e) => located(e.to_string(), &f.name, "views"),
        }
    });
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());
    eprintln!("{report}");
}

/// Lidar point clouds (tests/data/lidar): LAS 1.2 and 1.4 that laspy wrote and their LAZ by
/// LASzip, each mutant read and gridded (the default classes and cell) into a grid or an error
/// naming the file. The work runs on this thread (a one-thread rayon pool that is this thread),
/// so the heap cap counts the gridding's allocations too.
#[test]
fn lidar_readers_survive_the_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let settings = Settings {
        seeded_cuts: 16,
        flips: 64,
        ..Settings::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .use_current_thread()
        .build()
        .unwrap();
    let mut fixtures = Vec::new();
    for name in [
        "lidar_12.las",
        "lidar_14.las",
        "lidar_12.laz",
        "lidar_14.laz",
        // Three chunks each: decoded in parallel windows.
        "lidar_chunked_12.laz",
        "lidar_chunked_14.laz",
    ] {
        let bytes = data(&format!("lidar/{name}"));
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let (offset, record) = (
            u32_at(96),
            u16::from_le_bytes([bytes[105], bytes[106]]) as usize,
        );
        let mut fields = vec![
            ("legacy point count", Field::I32Le(107)),
            ("offset to point data", Field::I32Le(96)),
            ("VLR count", Field::I32Le(100)),
            ("x scale", Field::F64Le(131)),
            ("min x", Field::F64Le(187)),
        ];
        if name.ends_with(".laz") {
            fields.push(("chunk table offset", Field::I32Le(offset)));
        }
        if name.contains("_14") {
            fields.push(("64-bit point count", Field::I32Le(247)));
            fields.push(("first EVLR offset", Field::I32Le(235)));
        }
        let mut fx = fixture(name, bytes.clone(), fields, false);
        // The header's end, the points' start and every 200th point record (uncompressed).
        fx.boundaries = vec![4, 94, 227, offset];
        if name.ends_with(".las") {
            fx.boundaries
                .extend((offset..bytes.len()).step_by(200 * record));
        }
        fixtures.push(fx);
    }
    let run = |f: &Fixture, bytes: &[u8]| {
        let path = dir.path().join(&f.name);
        std::fs::write(&path, bytes).unwrap();
        verdict(
            pool.install(|| dem::read_dem(&path, &dem::ReadOptions::default())),
            &path,
        )
    };
    let (las, laz): (Vec<Fixture>, Vec<Fixture>) =
        fixtures.into_iter().partition(|f| f.name.ends_with(".las"));
    let t = run_campaign("LAS", &las, &settings, &run);
    let mut report = t.report();
    assert!(t.failures.is_empty(), "{}", t.report());
    // The LASzip decoder's context models take about 2.5 MB whatever the file (256 models of
    // 256 symbols for each of three point fields of format 1): the cap is that much above the
    // usual one. The undamaged file's peak is printed beside the table.
    let clean = data("lidar/lidar_12.laz");
    let path = dir.path().join("clean.laz");
    std::fs::write(&path, &clean).unwrap();
    let (g, peak) = crate::alloc::measure(|| {
        pool.install(|| dem::read_dem(&path, &dem::ReadOptions::default()))
    });
    assert!(g.is_ok());
    report.push_str(&format!(
        "undamaged lidar_12.laz ({} bytes): heap peak {} bytes\n",
        clean.len(),
        peak
    ));
    let laz_settings = Settings {
        mem_extra: 4 << 20,
        ..settings
    };
    let t = run_campaign("LAZ", &laz, &laz_settings, &run);
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());
    eprintln!("{report}");
}

/// GDAL VRTs written by gdalbuildvrt (tests/data/mosaic.sh, photo_mosaic.sh): the mosaic of three
/// DEM pieces read as a grid, and the -addalpha mosaic of three photo tiles read as a photo, 32
/// rows at a time. Each mutant is the VRT's text beside intact copies of its sources (header
/// numbers, rectangles and no-data values set to extremes; lines cut), ending in a result or an
/// error naming the VRT.
#[test]
fn vrt_readers_survive_the_campaign() {
    use texmap_terrain::gst::PhotoSource;
    let dir = tempfile::tempdir().unwrap();
    let sources = [
        "mosaic_nw.tif",
        "mosaic_ne.tif",
        "mosaic_s.tif",
        "mosaic_photo_a.tif",
        "mosaic_photo_b.tif",
        "mosaic_photo_c.tif",
    ];
    for name in sources {
        std::fs::write(dir.path().join(name), data(name)).unwrap();
    }
    let settings = Settings {
        seeded_cuts: 24,
        flips: 256,
        ..Settings::default()
    };
    // The value after the first `key` following `after`, as a text field.
    let field = |text: &str, after: &str, key: &str| {
        let from = text.find(after).unwrap();
        let start = from + text[from..].find(key).unwrap() + key.len();
        let end = start + text[start..].find(['"', '<']).unwrap();
        Field::Text(start, end)
    };
    let fx = |name: &str| {
        let bytes = data(name);
        let text = String::from_utf8(bytes.clone()).unwrap();
        let fields = vec![
            ("rasterXSize", field(&text, "<VRTDataset", "rasterXSize=\"")),
            ("rasterYSize", field(&text, "<VRTDataset", "rasterYSize=\"")),
            (
                "GeoTransform",
                field(&text, "<GeoTransform>", "<GeoTransform>"),
            ),
            ("SrcRect xSize", field(&text, "<SrcRect", "xSize=\"")),
            (
                "second DstRect xOff",
                field(&text, "</ComplexSource>", "<DstRect xOff=\""),
            ),
            (
                "second DstRect ySize",
                field(&text, "</ComplexSource>", "ySize=\""),
            ),
            ("SourceBand", field(&text, "<SourceBand>", "<SourceBand>")),
            ("NODATA", field(&text, "<NODATA>", "<NODATA>")),
        ];
        let mut f = unchecked(fixture(name, bytes, fields, true));
        f.boundaries = crate::campaign::line_starts(&f.bytes);
        f
    };
    let path = dir.path().join("mutant.vrt");
    let t = run_campaign(
        "GDAL VRT (DEM)",
        &[fx("mosaic.vrt")],
        &settings,
        &|_, bytes| {
            std::fs::write(&path, bytes).unwrap();
            verdict(dem::read_dem(&path, &dem::ReadOptions::default()), &path)
        },
    );
    let mut report = t.report();
    assert!(t.failures.is_empty(), "{}", t.report());
    let t = run_campaign(
        "GDAL VRT (photo)",
        &[fx("mosaic_photo.vrt")],
        &settings,
        &|_, bytes| {
            std::fs::write(&path, bytes).unwrap();
            let read = texmap_terrain::photo::VrtPhoto::open(&path, &PhotoOptions::bands(None))
                .and_then(|p| {
                    let h = p.size().1;
                    for y in (0..h).step_by(32) {
                        p.rows(y, (y + 32).min(h))?;
                    }
                    Ok(())
                });
            match read {
                Ok(()) => Verdict::Ok { frames: 1 },
                Err(e) => located(e.to_string(), "mutant.vrt", "read"),
            }
        },
    );
    report.push_str(&t.report());
    assert!(t.failures.is_empty(), "{}", t.report());
    eprintln!("{report}");
}

//! DTED cells and ESRI `.hdr` rasters (GridFloat `.flt`, BIL `.bil`) that GDAL wrote from the SRTM
//! tile and the ramp GeoTIFFs (tests/data/dem_formats.sh), read as GDAL reads them: size,
//! georeference, no-data, statistics and sample values (`*.gdalinfo.json`,
//! `dem_formats_gdal_samples.txt`); the DTED cells' heights are the `.hgt` tile's sample for
//! sample; damaged files are errors naming the file and the place, never a panic or a partial
//! grid. (The mutation campaign over the same fixtures is in tests/fuzz_campaign.rs.)
//!
//! Web-map elevation tiles (tests/data/xyz_tiles.sh): Terrain-RGB tiles that rio-rgbify (Mapbox's
//! encoder) and Terrarium tiles that numpy encoded from GDAL's reprojection of the SRTM tile onto
//! zoom-10 XYZ tiles in EPSG:3857 are placed, tile by tile and joined, where GDAL placed them
//! (`xyz/*.gdalinfo.json`), with GDAL's heights to within the encodings' steps.
//!
//! Lidar point clouds (tests/data/lidar/gen_lidar.py): LAS 1.2 and 1.4 and LAZ that laspy and
//! LASzip wrote, read as laspy reads them and gridded as gdal_grid and PDAL's rule (numpy) grid
//! them.

use std::io::Read;
use std::path::{Path, PathBuf};

use texmap_terrain::TerrainError;
use texmap_terrain::dem::dted::{self, Checksums};
use texmap_terrain::dem::png::{TileAddress, terrain_rgb_height, terrarium_height};
use texmap_terrain::dem::{CrsKind, DemFormat, Grid, ReadOptions, ehdr, read_dem, read_dems};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn read(path: &Path) -> Grid {
    read_dem(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The level-1 cell, unpacked from its gzip beside the other fixtures into `dir`.
fn unpack_dt1(dir: &Path) -> PathBuf {
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data("n44w072.dt1.gz")).unwrap())
        .read_to_end(&mut bytes)
        .unwrap();
    let path = dir.join("n44w072.dt1");
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The window of the SRTM tile the level-1 cell holds (columns, rows; dem_formats.sh).
const WINDOW: (std::ops::Range<u32>, std::ops::Range<u32>) = (700..956, 760..1016);

fn hgt() -> Grid {
    read(&data("N44W072.hgt"))
}

/// Sample `at` of `a` and sample `at_b` of `b` are centred on the same point, within `tol`.
fn same_place(a: &Grid, at: (f64, f64), b: &Grid, at_b: (f64, f64), tol: f64) {
    let (x, y) = a.georef().sample_xy(at.0, at.1);
    let (bx, by) = b.georef().sample_xy(at_b.0, at_b.1);
    assert!(
        (x - bx).abs() <= tol && (y - by).abs() <= tol,
        "{at:?}: ({x}, {y}) vs {at_b:?}: ({bx}, {by}), tolerance {tol}"
    );
}

/// `grid`'s size and sample centres against gdalinfo's (`info`) for `file`: GDAL's geoTransform
/// gives pixel corners, ours sample centres half a pixel in. gdalinfo prints 16 significant
/// digits: the tolerance is that rounding's, 1e-9 of a degree (0.1 mm) or of a metre.
fn placed_like_gdal(grid: &Grid, info: &serde_json::Value, file: &str) {
    let size: [u32; 2] = serde_json::from_value(info["size"].clone()).unwrap();
    assert_eq!([grid.width(), grid.height()], size, "{file}");
    let mut t: [f64; 6] = serde_json::from_value(info["geoTransform"].clone()).unwrap();
    assert_eq!((t[2], t[4]), (0.0, 0.0), "{file}: GDAL reports no rotation");
    if t[5] > 0.0 {
        // GDAL keeps a file's south-first rows (a positive row step); ours are north first.
        (t[3], t[5]) = (t[3] + size[1] as f64 * t[5], -t[5]);
    }
    let r = grid.georef();
    for (ours, gdal, what) in [
        (r.origin_x, t[0] + 0.5 * t[1], "x of sample (0, 0)"),
        (r.origin_y, t[3] + 0.5 * t[5], "y of sample (0, 0)"),
        (r.dx, t[1], "column step"),
        (r.dy, t[5], "row step"),
    ] {
        let tol = 1e-9 * gdal.abs().max(1.0);
        assert!(
            (ours - gdal).abs() <= tol,
            "{file}: {what}: ours {ours}, GDAL {gdal}, tolerance {tol}"
        );
    }
}

/// `grid` (read from `file`) against GDAL's reading: size, georeference (GDAL's geoTransform
/// gives pixel corners, ours sample centres half a pixel in), the share of valid samples, the
/// statistics, and the values at the listed samples (GDAL's raw value, the no-data marker where
/// GDAL reports no-data).
fn matches_gdal(grid: &Grid, file: &str, crs: CrsKind, epsg: Option<u16>) {
    let info: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(data(&format!("{file}.gdalinfo.json"))).unwrap(),
    )
    .unwrap();
    let r = grid.georef();
    assert_eq!((r.crs, r.epsg), (crs, epsg), "{file}");
    placed_like_gdal(grid, &info, file);
    let band = &info["bands"][0];
    let nodata = band["noDataValue"].as_f64();
    // Statistics over the valid samples: GDAL prints the mean to 3 decimals and the valid
    // share to 2.
    let n = grid.heights().len() as f64;
    let valid_percent: f64 = band["metadata"][""]["STATISTICS_VALID_PERCENT"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    let ours_valid = 100.0 * (n - grid.nodata_count() as f64) / n;
    assert!(
        (ours_valid - valid_percent).abs() <= 0.005 + 1e-9,
        "{file}: {ours_valid}% valid, GDAL {valid_percent}%"
    );
    let (lo, hi) = grid.height_range();
    assert_eq!(
        (lo as f64, hi as f64),
        (
            band["minimum"].as_f64().unwrap(),
            band["maximum"].as_f64().unwrap()
        ),
        "{file}: height range"
    );
    let valid: Vec<f64> = grid
        .heights()
        .iter()
        .filter(|h| !h.is_nan())
        .map(|&h| h as f64)
        .collect();
    let mean = valid.iter().sum::<f64>() / valid.len() as f64;
    let gdal_mean = band["mean"].as_f64().unwrap();
    assert!(
        (mean - gdal_mean).abs() <= 0.0005 + 1e-9,
        "{file}: mean {mean}, GDAL {gdal_mean}"
    );
    // Sample values.
    let samples = std::fs::read_to_string(data("dem_formats_gdal_samples.txt")).unwrap();
    let mut count = 0;
    for line in samples
        .lines()
        .filter(|l| l.split(' ').next() == Some(file))
    {
        let f: Vec<&str> = line.split(' ').collect();
        let (col, row): (u32, u32) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        let v: f64 = f[3].parse().unwrap();
        let ours = grid.at(col, row);
        if Some(v) == nodata {
            assert!(
                ours.is_nan(),
                "{file} ({col}, {row}): GDAL no-data, ours {ours}"
            );
        } else {
            assert_eq!(ours as f64, v, "{file} ({col}, {row})");
        }
        count += 1;
    }
    assert!(count >= 44, "{file}: {count} samples listed");
}

#[test]
fn every_fixture_reads_as_gdal_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let dt1 = unpack_dt1(dir.path());
    let geo = (CrsKind::Geographic, Some(4326));
    let utm = (CrsKind::Projected, Some(32654));
    let cases = [
        ("n44w072.dt0", data("n44w072.dt0"), geo),
        ("n44w072.dt1", dt1, geo),
        ("ramp_geo.flt", data("ramp_geo.flt"), geo),
        ("ramp_usgs.flt", data("ramp_usgs.flt"), geo),
        ("ramp_utm.flt", data("ramp_utm.flt"), utm),
        ("ramp_i16.bil", data("ramp_i16.bil"), utm),
        // No .prj: GDAL reports no system, ours is local.
        (
            "ramp_i16_msb.bil",
            data("ramp_i16_msb.bil"),
            (CrsKind::Local, None),
        ),
        ("n44w072_crop.flt", data("n44w072_crop.flt"), geo),
    ];
    for (name, path, (crs, epsg)) in cases {
        matches_gdal(&read(&path), name, crs, epsg);
    }
}

#[test]
fn the_ramps_are_the_formula_with_one_hole() {
    // generate.sh's ramp: 100 + 2·col + 3·row, sample (5, 3) no-data, as the GeoTIFF holds it.
    let tif = read(&data("ramp_i16_lzw.tif"));
    for name in [
        "ramp_geo.flt",
        "ramp_usgs.flt",
        "ramp_utm.flt",
        "ramp_i16.bil",
        "ramp_i16_msb.bil",
    ] {
        let g = read(&data(name));
        assert_eq!((g.width(), g.height()), (37, 29), "{name}");
        // The GeoTIFF's samples (tests/dem.rs checks them against the formula), bit for bit.
        let same = g
            .heights()
            .iter()
            .zip(tif.heights())
            .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()));
        assert!(same, "{name}: heights differ from ramp_i16_lzw.tif's");
        assert!(g.at(5, 3).is_nan(), "{name}");
        assert_eq!(g.nodata_count(), 1, "{name}");
        if name.starts_with("ramp_utm") || name.starts_with("ramp_i16") {
            // The same lattice as the GeoTIFF it came from.
            assert_eq!(g.georef().origin_x, tif.georef().origin_x, "{name}");
            assert_eq!(g.georef().origin_y, tif.georef().origin_y, "{name}");
        }
    }
    // The GDAL header (ULXMAP, XDIM rounded to 15 digits) and the USGS one (corner, cellsize)
    // place the same samples.
    let (a, b) = (read(&data("ramp_geo.flt")), read(&data("ramp_usgs.flt")));
    same_place(&a, (36.0, 28.0), &b, (36.0, 28.0), 1e-12);
}

#[test]
fn the_dted_cells_hold_the_hgt_tiles_heights() {
    let hgt = hgt();
    let dir = tempfile::tempdir().unwrap();
    // Level 1: the tile's lattice; heights in the window, void elsewhere.
    let dt1 = read(&unpack_dt1(dir.path()));
    assert_eq!(
        dt1.georef(),
        hgt.georef(),
        "the same sample centres, bit for bit"
    );
    let (cols, rows) = WINDOW;
    for row in 0..1201 {
        for col in 0..1201 {
            let (d, h) = (dt1.at(col, row), hgt.at(col, row));
            if cols.contains(&col) && rows.contains(&row) {
                assert_eq!(d, h, "level 1 ({col}, {row})");
            } else {
                assert!(
                    d.is_nan(),
                    "level 1 ({col}, {row}): void expected, read {d}"
                );
            }
        }
    }
    assert_eq!(dt1.nodata_count(), 1201 * 1201 - 256 * 256);
    // Level 0: every tenth sample of the tile, at the same places.
    let dt0 = read(&data("n44w072.dt0"));
    assert_eq!((dt0.width(), dt0.height()), (121, 121));
    for row in 0..121 {
        for col in 0..121 {
            assert_eq!(
                dt0.at(col, row),
                hgt.at(10 * col, 10 * row),
                "level 0 ({col}, {row})"
            );
            let (c, r) = (col as f64, row as f64);
            same_place(&dt0, (c, r), &hgt, (10.0 * c, 10.0 * r), 1e-12);
        }
    }
    // The GridFloat crop: columns 800.., rows 850.. of the tile.
    let crop = read(&data("n44w072_crop.flt"));
    for row in 0..64 {
        for col in 0..64 {
            assert_eq!(crop.at(col, row), hgt.at(800 + col, 850 + row));
        }
    }
    // The header's ULXMAP/ULYMAP are printed to 15 digits.
    same_place(&crop, (0.0, 0.0), &hgt, (800.0, 850.0), 1e-9);
}

#[test]
fn formats_are_chosen_by_extension_or_content() {
    let dir = tempfile::tempdir().unwrap();
    // A DTED cell under another name: its UHL says what it is.
    let cell = dir.path().join("cell.bin");
    std::fs::copy(data("n44w072.dt0"), &cell).unwrap();
    assert_eq!(DemFormat::sniff(&cell), Some(DemFormat::Dted));
    assert_eq!(read(&cell).width(), 121);
    // The header given instead of the data file; an unknown data extension with a .hdr beside it.
    let g = read(&data("ramp_geo.hdr"));
    assert_eq!(g.georef().epsg, Some(4326));
    for ext in ["hdr", "prj"] {
        std::fs::copy(
            data(&format!("ramp_utm.{ext}")),
            dir.path().join(format!("grid.{ext}")),
        )
        .unwrap();
    }
    std::fs::copy(data("ramp_utm.flt"), dir.path().join("grid.raw")).unwrap();
    let g = read(&dir.path().join("grid.raw"));
    assert_eq!((g.width(), g.georef().epsg), (37, Some(32654)));
    // A data file without its header is named.
    let lone = dir.path().join("lone.flt");
    std::fs::copy(data("ramp_geo.flt"), &lone).unwrap();
    let e = read_dem(&lone, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("lone.flt") && e.contains("lone.hdr"), "{e}");
}

fn dt0_bytes() -> Vec<u8> {
    std::fs::read(data("n44w072.dt0")).unwrap()
}

/// An error whose text names `name`, or a panic with what came instead.
fn err_naming(r: Result<Grid, TerrainError>, name: &str) -> String {
    match r {
        Ok(_) => panic!("{name}: read as a grid"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.contains(name), "{s}");
            s
        }
    }
}

#[test]
fn a_bad_checksum_names_the_record_and_byte() {
    let b = dt0_bytes();
    let record = 12 + 2 * 121;
    // One height of longitude line 57 changed (its point 30 from the south).
    let col = 57;
    let start = dted::HEADER_LEN + col * record;
    let mut bad = b.clone();
    bad[start + 8 + 2 * 30 + 1] ^= 0x04;
    let e = err_naming(
        dted::read_dted_bytes(&bad, "n44w072.dt0", Checksums::Verify),
        "n44w072.dt0",
    );
    let checksum_at = start + record - 4;
    assert!(
        e.contains(&format!("byte {checksum_at}, record {col}")) && e.contains("checksum"),
        "{e}"
    );
    // Ignored on request: the changed height is read (row 120 − 30).
    let g = dted::read_dted_bytes(&bad, "n44w072.dt0", Checksums::Ignore).unwrap();
    let good = dted::read_dted_bytes(&b, "n44w072.dt0", Checksums::Verify).unwrap();
    assert_eq!((g.at(57, 90) - good.at(57, 90)).abs(), 4.0);
    // The checksum itself damaged.
    let mut bad = b.clone();
    bad[checksum_at] ^= 0x80;
    err_naming(
        dted::read_dted_bytes(&bad, "n44w072.dt0", Checksums::Verify),
        "checksum",
    );
    // Through read_dem and its option.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("n44w072.dt0");
    std::fs::write(&p, &bad).unwrap();
    err_naming(read_dem(&p, &ReadOptions::default()), "n44w072.dt0");
    let lax = ReadOptions {
        verify_checksums: false,
        ..ReadOptions::default()
    };
    assert!(read_dem(&p, &lax).is_ok());
}

#[test]
fn cut_dted_files_are_errors_never_partial_grids() {
    let b = dt0_bytes();
    let record = 12 + 2 * 121;
    for cut in (0..b.len())
        .step_by(97)
        .chain([dted::HEADER_LEN, b.len() - 1])
    {
        let e = err_naming(
            dted::read_dted_bytes(&b[..cut], "n44w072.dt0", Checksums::Verify),
            "n44w072.dt0",
        );
        if cut >= dted::HEADER_LEN {
            let r = (cut - dted::HEADER_LEN) / record;
            assert!(
                e.contains(&format!("stops in record {r} of 121")),
                "cut at {cut}: {e}"
            );
        } else {
            assert!(
                e.contains("3428 bytes of the UHL, DSI and ACC headers"),
                "cut at {cut}: {e}"
            );
        }
    }
    // The big cell cut anywhere, through the file reader.
    let dir = tempfile::tempdir().unwrap();
    let path = unpack_dt1(dir.path());
    let full = std::fs::read(&path).unwrap();
    for cut in (0..full.len()).step_by(99_991) {
        std::fs::write(&path, &full[..cut]).unwrap();
        err_naming(read_dem(&path, &ReadOptions::default()), "n44w072.dt1");
    }
    // A longer file: its header would drop the rest.
    let mut long = b.clone();
    long.extend_from_slice(&[0; 10]);
    let e = err_naming(
        dted::read_dted_bytes(&long, "n44w072.dt0", Checksums::Verify),
        "n44w072.dt0",
    );
    assert!(e.contains("10 bytes after the last record"), "{e}");
}

#[test]
fn damaged_dted_headers_are_errors_or_grids_never_panics() {
    let b = dt0_bytes();
    // Every byte of the UHL and of the DSI's repeated fields replaced by each of a few values.
    let fields = (0..80).chain(80 + 185..80 + 204).chain(80 + 273..80 + 289);
    let mut errors = 0;
    for at in fields {
        for v in [b'X', b'9', b'0', 0, 0xFF, b' '] {
            let mut m = b.clone();
            m[at] = v;
            match dted::read_dted_bytes(&m, "n44w072.dt0", Checksums::Verify) {
                Ok(g) => assert_eq!(g.heights().len(), g.width() as usize * g.height() as usize),
                Err(e) => {
                    assert!(e.to_string().starts_with("n44w072.dt0: byte "), "{e}");
                    errors += 1;
                }
            }
        }
    }
    assert!(errors > 300, "{errors} errors");
    // A counted field the DSI contradicts names the DSI's byte and the UHL's value.
    let mut m = b.clone();
    m[47..51].copy_from_slice(b"0122");
    let e = err_naming(
        dted::read_dted_bytes(&m, "n44w072.dt0", Checksums::Verify),
        "byte 365",
    );
    assert!(e.contains("byte 47: 122"), "{e}");
    // Both copies claim the most lines and points a UHL can (0.1″ apart, to stay on the globe):
    // refused by the file's length, before the grid is sized from the claim.
    m[20..28].copy_from_slice(b"00010001");
    m[80 + 273..80 + 281].copy_from_slice(b"00010001");
    m[80 + 285..80 + 289].copy_from_slice(b"9999");
    m[47..51].copy_from_slice(b"9999");
    m[51..55].copy_from_slice(b"9999");
    m[80 + 281..80 + 285].copy_from_slice(b"9999");
    let e = err_naming(
        dted::read_dted_bytes(&m, "n44w072.dt0", Checksums::Verify),
        "n44w072.dt0",
    );
    assert!(e.contains("9999 longitude lines of 9999 points"), "{e}");
    // The sentinel of a record.
    let mut m = b.clone();
    let at = dted::HEADER_LEN + 5 * (12 + 2 * 121);
    m[at] = 0;
    let e = err_naming(
        dted::read_dted_bytes(&m, "n44w072.dt0", Checksums::Verify),
        "sentinel",
    );
    assert!(e.contains(&format!("byte {at}, record 5")), "{e}");
}

/// The 16-bit BIL fixture's parts with another header or data.
fn bil_parts<'a>(header: &'a str, data: &'a [u8]) -> ehdr::EhdrParts<'a> {
    ehdr::EhdrParts {
        header,
        header_name: "ramp_i16.hdr",
        data,
        data_name: "ramp_i16.bil",
        prj: None,
        gridfloat: false,
    }
}

#[test]
fn damaged_hdr_rasters_are_errors_never_panics() {
    let hdr = std::fs::read_to_string(data("ramp_i16.hdr")).unwrap();
    let bil = std::fs::read(data("ramp_i16.bil")).unwrap();
    let prj = std::fs::read_to_string(data("ramp_i16.prj")).unwrap();
    let read = |h: &str, d: &[u8]| ehdr::read_ehdr_parts(&bil_parts(h, d));
    assert!(read(&hdr, &bil).is_ok());
    // A header claiming 10^9 columns (and rows): refused before anything is sized from it.
    let huge = hdr.replace("NCOLS          37", "NCOLS          1000000000");
    let e = read(&huge, &bil).unwrap_err();
    assert!(
        matches!(
            e,
            TerrainError::BadSize {
                width: 1_000_000_000,
                ..
            }
        ),
        "{e}"
    );
    let huge2 = huge.replace("NROWS          29", "NROWS          1000000000");
    assert!(matches!(
        read(&huge2, &bil),
        Err(TerrainError::BadSize { .. })
    ));
    // A few more rows than the file holds: the data file's byte where it stops.
    let more = hdr.replace("NROWS          29", "NROWS          31");
    let e = err_naming(read(&more, &bil), "ramp_i16.bil: byte 2146");
    assert!(e.contains("stops in row 29"), "{e}");
    // Cut data at many offsets.
    for cut in (0..bil.len()).step_by(37) {
        err_naming(read(&hdr, &bil[..cut]), "ramp_i16.bil");
    }
    // Every header line with its value replaced: a grid or an error naming the header or data.
    let lines: Vec<&str> = hdr.lines().collect();
    for (n, line) in lines.iter().enumerate() {
        let key = line.split_whitespace().next().unwrap();
        for v in ["-1", "0", "x", "1e400", "nan", "4294967296", "MSBFIRST", ""] {
            let changed = format!("{key} {v}");
            let mut l = lines.clone();
            l[n] = &changed;
            if let Err(e) = read(&l.join("\n"), &bil) {
                let s = e.to_string();
                assert!(
                    s.starts_with("ramp_i16.hdr: ") || s.starts_with("ramp_i16.bil: "),
                    "{key} {v}: {s}"
                );
            }
        }
    }
    // A .prj that is no system texmap places is named.
    let lambert = prj.replace("UTM_Zone_54N", "Lambert_93");
    let p = ehdr::EhdrParts {
        prj: Some((&lambert, "ramp_i16.prj")),
        ..bil_parts(&hdr, &bil)
    };
    let e = err_naming(ehdr::read_ehdr_parts(&p), "ramp_i16.prj");
    assert!(e.contains("gdalwarp -t_srs"), "{e}");
}

fn xyz(name: &str) -> PathBuf {
    data("xyz").join(name)
}

fn gdal_json(name: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(xyz(name)).unwrap()).unwrap()
}

/// `grid`'s georeference against gdalinfo's of `json` (corner and pixel size; ours is sample
/// centres, half a pixel in), to 1e-6 m, and its size.
fn placed_as_gdal(grid: &Grid, json: &str) {
    let info = gdal_json(json);
    let size: [u32; 2] = serde_json::from_value(info["size"].clone()).unwrap();
    assert_eq!([grid.width(), grid.height()], size, "{json}");
    let t: [f64; 6] = serde_json::from_value(info["geoTransform"].clone()).unwrap();
    let r = grid.georef();
    assert_eq!((r.crs, r.epsg), (CrsKind::Projected, Some(3857)), "{json}");
    assert!(r.is_web_mercator());
    for (ours, gdal, what) in [
        (r.origin_x, t[0] + 0.5 * t[1], "x of sample (0, 0)"),
        (r.origin_y, t[3] + 0.5 * t[5], "y of sample (0, 0)"),
        (r.dx, t[1], "column step"),
        (r.dy, t[5], "row step"),
    ] {
        assert!(
            (ours - gdal).abs() <= 1e-6,
            "{json}: {what}: ours {ours}, GDAL {gdal}"
        );
    }
}

/// GDAL's float heights (before encoding) at the listed samples of tile `tile` ("10_X_Y"),
/// shifted by `(dc, dr)` samples into `grid`, within `tol`.
fn heights_as_gdal(grid: &Grid, tile: &str, (dc, dr): (u32, u32), tol: f64) -> usize {
    let samples = std::fs::read_to_string(xyz("gdal_samples.txt")).unwrap();
    let mut count = 0;
    for line in samples
        .lines()
        .filter(|l| l.split(' ').next() == Some(tile))
    {
        let f: Vec<&str> = line.split(' ').collect();
        let (col, row): (u32, u32) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        let v: f64 = f[3].parse().unwrap();
        let ours = grid.at(col + dc, row + dr) as f64;
        assert!(
            (ours - v).abs() <= tol,
            "{tile} ({col}, {row}): ours {ours}, GDAL {v}, tolerance {tol}"
        );
        count += 1;
    }
    assert_eq!(count, 64, "{tile}: samples listed");
    count
}

fn tile_opts(format: DemFormat) -> ReadOptions {
    ReadOptions {
        format: Some(format),
        ..ReadOptions::default()
    }
}

#[test]
fn rgb_encodings_decode_the_published_examples() {
    // Mapbox: height = -10000 + ((R * 256 * 256 + G * 256 + B) * 0.1).
    for (rgb, h) in [
        ((1, 134, 160), 0.0),
        // 1916.6 m: 119166 tenths above -10000 = 1·65536 + 209·256 + 126.
        ((1, 209, 126), 1916.6),
        ((0, 0, 0), -10000.0),
        ((255, 255, 255), 1667721.5),
    ] {
        let v = terrain_rgb_height(rgb.0, rgb.1, rgb.2);
        assert!((v - h).abs() < 1e-6, "Terrain-RGB {rgb:?}: {v}, want {h}");
    }
    // Terrarium: height = (R * 256 + G + B / 256) - 32768.
    for (rgb, h) in [
        ((128, 0, 0), 0.0),
        ((135, 124, 128), 1916.5),
        ((127, 255, 0), -1.0),
        ((0, 0, 0), -32768.0),
        ((255, 255, 255), 32767.0 + 255.0 / 256.0),
    ] {
        assert_eq!(
            terrarium_height(rgb.0, rgb.1, rgb.2),
            h,
            "Terrarium {rgb:?}"
        );
    }
}

#[test]
fn web_map_tiles_are_placed_and_decoded_as_gdal_and_rio_rgbify_made_them() {
    // Terrain-RGB (rio-rgbify truncates to 0.1 m: one step) and Terrarium (numpy floors to
    // 1/256 m: one step), plus f32's rounding of the height.
    let cases = [
        (
            "terrain_rgb",
            DemFormat::TerrainRgb,
            0.1 + 1e-3,
            ["10_308_371", "10_309_371", ""],
        ),
        (
            "terrarium",
            DemFormat::Terrarium,
            1.0 / 256.0 + 1e-3,
            ["10_308_370", "10_309_370", "10_309_371"],
        ),
    ];
    for (dir, format, tol, tiles) in cases {
        for tile in tiles.iter().filter(|t| !t.is_empty()) {
            let [_, x, y]: [&str; 3] = tile.split('_').collect::<Vec<_>>().try_into().unwrap();
            let path = xyz(&format!("{dir}/10/{x}/{y}.png"));
            let grid = read_dem(&path, &tile_opts(format)).unwrap_or_else(|e| panic!("{e}"));
            placed_as_gdal(&grid, &format!("{tile}.gdalinfo.json"));
            heights_as_gdal(&grid, tile, (0, 0), tol);
            // The same file elsewhere, placed by --tile.
            let copy = tempfile::tempdir().unwrap();
            let elsewhere = copy.path().join("tile.png");
            std::fs::copy(&path, &elsewhere).unwrap();
            let opts = ReadOptions {
                tile: Some(TileAddress::parse(&format!("10/{x}/{y}")).unwrap()),
                ..tile_opts(format)
            };
            let placed = read_dem(&elsewhere, &opts).unwrap();
            assert_eq!(placed.georef(), grid.georef());
            // Without an address: the old local grid with --cell.
            let local = read_dem(
                &elsewhere,
                &ReadOptions {
                    cell: 30.0,
                    ..tile_opts(format)
                },
            )
            .unwrap();
            assert_eq!(local.georef().crs, CrsKind::Local);
            assert_eq!(local.georef().dx, 30.0);
            assert_eq!(local.heights(), grid.heights());
            // TMS numbering: row 2^10 - 1 - y from the south is the same tile.
            let tms = ReadOptions {
                tile: Some(
                    TileAddress::parse(&format!("10/{x}/{}", 1023 - y.parse::<u32>().unwrap()))
                        .unwrap(),
                ),
                tms: true,
                ..tile_opts(format)
            };
            assert_eq!(read_dem(&elsewhere, &tms).unwrap().georef(), grid.georef());
        }
    }
}

#[test]
fn web_map_tiles_join_as_gdalbuildvrt_joins_them() {
    use texmap_terrain::dem::mosaic::mosaic;
    // Two Terrain-RGB tiles side by side: 512 x 256.
    let rgb = read_dems(
        &[
            xyz("terrain_rgb/10/308/371.png"),
            xyz("terrain_rgb/10/309/371.png"),
        ],
        &tile_opts(DemFormat::TerrainRgb),
    )
    .unwrap();
    let (joined, overlaps) = mosaic(rgb).unwrap();
    assert!(overlaps.is_empty());
    placed_as_gdal(&joined, "joined_rgb.gdalinfo.json");
    heights_as_gdal(&joined, "10_308_371", (0, 0), 0.101);
    heights_as_gdal(&joined, "10_309_371", (256, 0), 0.101);
    assert_eq!(joined.nodata_count(), 0);
    // Three Terrarium tiles in an L, read from their directory: 10/308/371 is missing, its
    // 256 x 256 samples no-data (as gdalbuildvrt leaves them).
    let parts = read_dems(&[xyz("terrarium")], &tile_opts(DemFormat::Terrarium)).unwrap();
    assert_eq!(parts.len(), 3);
    let (joined, _) = mosaic(parts).unwrap();
    placed_as_gdal(&joined, "joined_terrarium.gdalinfo.json");
    let tol = 1.0 / 256.0 + 1e-3;
    heights_as_gdal(&joined, "10_308_370", (0, 0), tol);
    heights_as_gdal(&joined, "10_309_370", (256, 0), tol);
    heights_as_gdal(&joined, "10_309_371", (256, 256), tol);
    assert_eq!(joined.nodata_count(), 256 * 256);
    assert!(joined.at(0, 256).is_nan() && joined.at(255, 511).is_nan());
}

#[test]
fn bad_tiles_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let tile = xyz("terrarium/10/308/370.png");
    let put = |rel: &str| {
        let p = dir.path().join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::copy(&tile, &p).unwrap();
        p
    };
    let opts = tile_opts(DemFormat::Terrarium);
    // Addresses no tile has.
    for rel in [
        "10/1024/370.png",
        "10/308/1024.png",
        "31/0/0.png",
        "0/0/1.png",
    ] {
        let p = put(rel);
        let e = err_naming(read_dem(&p, &opts), rel);
        assert!(e.contains("tile address"), "{e}");
    }
    // Mixed zooms: both files named, nothing read.
    let z11 = put("11/616/740.png");
    let e = read_dems(&[tile.clone(), z11.clone()], &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("11/616/740.png") && e.contains("10/308/370.png"),
        "{e}"
    );
    assert!(e.contains("zoom 11") && e.contains("zoom 10"), "{e}");
    // Images of the wrong kind: 16-bit greyscale, 8-bit greyscale, 16-bit RGB.
    let grey16 = dir.path().join("10/308/369.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_pixel(256, 256, image::Luma([1000u16]))
        .save(&grey16)
        .unwrap();
    let grey8 = dir.path().join("10/308/368.png");
    image::GrayImage::from_pixel(256, 256, image::Luma([10]))
        .save(&grey8)
        .unwrap();
    let rgb16 = dir.path().join("10/308/367.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_pixel(256, 256, image::Rgb([1u16, 2, 3]))
        .save(&rgb16)
        .unwrap();
    for (p, format) in [
        (&grey16, DemFormat::Terrarium),
        (&grey8, DemFormat::TerrainRgb),
        (&rgb16, DemFormat::TerrainRgb),
    ] {
        let e = err_naming(read_dem(p, &tile_opts(format)), p.to_str().unwrap());
        assert!(e.contains("8-bit RGB"), "{e}");
    }
    // A tile that is no power of two a side cannot be placed; a backfilled 257 can.
    let odd = dir.path().join("10/308/366.png");
    image::RgbImage::from_pixel(300, 300, image::Rgb([128, 0, 0]))
        .save(&odd)
        .unwrap();
    let e = err_naming(read_dem(&odd, &opts), "366.png");
    assert!(e.contains("power of two"), "{e}");
    let backfilled = dir.path().join("10/308/365.png");
    image::RgbImage::from_pixel(257, 257, image::Rgb([128, 0, 0]))
        .save(&backfilled)
        .unwrap();
    let g = read_dem(&backfilled, &opts).unwrap();
    let t = TileAddress::parse("10/308/365").unwrap();
    let (west, _, _, north) = t.bounds();
    assert_eq!(g.georef().dx, t.side() / 256.0);
    assert!((g.georef().origin_x - (west + 0.5 * t.side() / 256.0)).abs() < 1e-6);
    assert!((g.georef().origin_y - (north - 0.5 * t.side() / 256.0)).abs() < 1e-6);
    // --tile for several files, and a directory without tiles.
    let several = ReadOptions {
        tile: Some(t),
        ..opts
    };
    assert!(read_dems(&[tile.clone(), tile.clone()], &several).is_err());
    let empty = tempfile::tempdir().unwrap();
    let e = read_dems(&[empty.path().to_path_buf()], &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains(empty.path().to_str().unwrap()), "{e}");
}

// Lidar point clouds (tests/data/lidar/gen_lidar.py): a survey over the SRTM terrain written by
// laspy as LAS 1.2 (format 1, GeoKeys) and 1.4 (format 6, WKT) and by LASzip as LAZ, read as
// laspy reads them (lidar_laspy.json) and gridded as gdal_grid (lidar_gdal_*.asc) and PDAL's
// rule in numpy (lidar_numpy.txt) grid them.

use texmap_terrain::dem::las::{CrsRecord, LasPoint, LasReader};
use texmap_terrain::dem::lidar::{
    self, ClassSet, Cloud, LidarMethod, LidarOptions, Selection, grid_cloud, read_lidar,
};

const LIDAR: [&str; 4] = [
    "lidar/lidar_12.las",
    "lidar/lidar_14.las",
    "lidar/lidar_12.laz",
    "lidar/lidar_14.laz",
];

fn all_points(path: &Path) -> Vec<LasPoint> {
    let mut r = LasReader::open(path).unwrap_or_else(|e| panic!("{e}"));
    let (mut all, mut batch) = (Vec::new(), Vec::new());
    while r.read_batch(&mut batch).unwrap_or_else(|e| panic!("{e}")) > 0 {
        all.extend_from_slice(&batch);
    }
    all
}

fn cell10(method: LidarMethod) -> LidarOptions {
    LidarOptions {
        cell: Some(10.0),
        method,
        ..LidarOptions::default()
    }
}

/// The same size, georeference and sample bits (no-data included, which `==` on NaN misses).
fn same_grid(a: &Grid, b: &Grid) -> bool {
    let bits = |g: &Grid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    (a.width(), a.height(), a.georef()) == (b.width(), b.height(), b.georef()) && bits(a) == bits(b)
}

fn grid_of(paths: &[PathBuf], opts: &LidarOptions) -> Grid {
    read_lidar(paths, opts).unwrap_or_else(|e| panic!("{e}")).0
}

#[test]
fn lidar_files_read_as_laspy_reads_them() {
    let text = std::fs::read_to_string(data("lidar/lidar_laspy.json")).unwrap();
    let refs: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in LIDAR {
        let path = data(name);
        let want = &refs[name.trim_start_matches("lidar/")];
        let r = LasReader::open(&path).unwrap();
        let h = r.header().clone();
        let f = |v: &serde_json::Value| v.as_f64().unwrap();
        assert_eq!(
            format!("{}.{}", h.version.0, h.version.1),
            want["version"].as_str().unwrap(),
            "{name}"
        );
        assert_eq!(
            h.point_format as u64,
            want["point_format"].as_u64().unwrap()
        );
        assert_eq!(
            h.compressed,
            want["compressed"].as_bool().unwrap(),
            "{name}"
        );
        assert_eq!(
            h.point_count,
            want["point_count"].as_u64().unwrap(),
            "{name}"
        );
        for k in 0..3 {
            // The header's doubles as stored (serde_json's parsing of laspy's shortest
            // round-trip digits may be an ulp off: 1e-9 is a thousandth of a scale step).
            for (got, key) in [
                (h.scale[k], "scales"),
                (h.offset[k], "offsets"),
                (h.min[k], "mins"),
                (h.max[k], "maxs"),
            ] {
                let exp = f(&want[key][k]);
                assert!(
                    (got - exp).abs() <= 1e-9,
                    "{name} {key}[{k}]: expected {exp}, got {got}, tolerance 1e-9"
                );
            }
        }
        // pyproj's reading of the GeoKeys (LAS 1.2), the WKT 1 VLR (1.4) and the WKT 2 EVLR
        // (the 1.4 LAZ).
        assert_eq!(h.crs, CrsKind::Projected, "{name}");
        assert_eq!(h.epsg.map(u64::from), want["epsg"].as_u64(), "{name}");
        let record = if name.contains("_12") {
            CrsRecord::GeoKeys
        } else {
            CrsRecord::Wkt
        };
        assert_eq!(h.crs_record, record, "{name}");

        let pts = all_points(&path);
        assert_eq!(pts.len() as u64, h.point_count);
        // The first and last points: laspy's `X·scale + offset` in float64, the same operations
        // as ours, so the same doubles (a tolerance of 1e-9 m would hide nothing real).
        for (p, key) in [(pts[0], "first"), (pts[pts.len() - 1], "last")] {
            let w = &want[key];
            for (got, field) in [(p.x, "x"), (p.y, "y"), (p.z, "z")] {
                let exp = f(&w[field]);
                assert!(
                    (got - exp).abs() <= 1e-9,
                    "{name} {key} {field}: expected {exp}, got {got}, tolerance 1e-9"
                );
            }
            assert_eq!(p.class as u64, w["class"].as_u64().unwrap());
            assert_eq!(p.return_number as u64, w["return_number"].as_u64().unwrap());
            assert_eq!(
                p.number_of_returns as u64,
                w["number_of_returns"].as_u64().unwrap()
            );
            assert_eq!(p.withheld, w["withheld"].as_bool().unwrap());
        }
        // Every point: the sums of the stored integers, the classes, withheld and last returns.
        let raw = |v: f64, k: usize| ((v - h.offset[k]) / h.scale[k]).round() as i64;
        for (k, key) in ["sum_X", "sum_Y", "sum_Z"].iter().enumerate() {
            let sum: i64 = pts.iter().map(|p| raw([p.x, p.y, p.z][k], k)).sum();
            assert_eq!(sum, want[key].as_i64().unwrap(), "{name} {key}");
        }
        let mut classes = std::collections::BTreeMap::new();
        for p in &pts {
            *classes.entry(p.class.to_string()).or_insert(0u64) += 1;
        }
        for (c, n) in want["classes"].as_object().unwrap() {
            assert_eq!(classes.get(c), n.as_u64().as_ref(), "{name} class {c}");
        }
        assert_eq!(classes.len(), want["classes"].as_object().unwrap().len());
        let withheld = pts.iter().filter(|p| p.withheld).count() as u64;
        let last = pts.iter().filter(|p| p.is_last_return()).count() as u64;
        assert_eq!(withheld, want["withheld"].as_u64().unwrap(), "{name}");
        assert_eq!(last, want["last_returns"].as_u64().unwrap(), "{name}");
    }
}

/// LAZ of three LASzip chunks (tests/data/lidar/gen_chunked.py), point-wise (LAS 1.2 format 1)
/// and layered (1.4 format 6): decoded a window of whole chunks at a time, the chunks side by
/// side, to laspy's points, the same for any thread count (the window is two chunks a thread).
#[test]
fn chunked_laz_decodes_in_parallel_as_laspy_reads_it() {
    let text = std::fs::read_to_string(data("lidar/lidar_chunked_laspy.json")).unwrap();
    let refs: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in ["lidar_chunked_12.laz", "lidar_chunked_14.laz"] {
        let want = &refs[name];
        let path = data(&format!("lidar/{name}"));
        assert_eq!(want["chunk_points"].as_array().unwrap().len(), 3, "{name}");
        let read = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| all_points(&path))
        };
        let pts = read(1);
        assert_eq!(pts.len() as u64, want["point_count"].as_u64().unwrap());
        let h = LasReader::open(&path).unwrap().header().clone();
        let raw = |v: f64, k: usize| ((v - h.offset[k]) / h.scale[k]).round() as i64;
        for (k, key) in ["sum_X", "sum_Y", "sum_Z"].iter().enumerate() {
            let sum: i64 = pts.iter().map(|p| raw([p.x, p.y, p.z][k], k)).sum();
            assert_eq!(sum, want[key].as_i64().unwrap(), "{name} {key}");
        }
        for s in want["samples"].as_array().unwrap() {
            let s = s.as_array().unwrap();
            let p = pts[s[0].as_u64().unwrap() as usize];
            for (got, exp) in [(p.x, &s[1]), (p.y, &s[2]), (p.z, &s[3])] {
                assert!((got - exp.as_f64().unwrap()).abs() <= 1e-9, "{name} {s:?}");
            }
            assert_eq!(p.class as u64, s[4].as_u64().unwrap(), "{name} {s:?}");
        }
        let vegetation = pts.iter().filter(|p| p.class == 5).count() as u64;
        assert_eq!(vegetation, want["classes"]["5"].as_u64().unwrap(), "{name}");
        for threads in [2, 3] {
            assert!(read(threads) == pts, "{name}: {threads} threads");
        }
    }
}

/// An ESRI ASCII grid's header and values as doubles (the f32 reader would round GDAL's six
/// decimals).
fn asc_f64(path: &Path) -> (Vec<(String, f64)>, Vec<f64>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<(String, f64)> = (0..6)
        .map(|_| {
            let mut it = lines.next().unwrap().split_whitespace();
            (
                it.next().unwrap().to_ascii_lowercase(),
                it.next().unwrap().parse().unwrap(),
            )
        })
        .collect();
    let values = lines
        .flat_map(|l| l.split_whitespace())
        .map(|v| v.parse::<f64>().unwrap())
        .collect();
    (head, values)
}

/// lidar_numpy.txt: per cell (row, col) the count, mean, min, max, idw, window-filled mean and
/// whether a point lies on the radius.
fn numpy_cells() -> Vec<(usize, usize, u32, [f64; 5], bool)> {
    let text = std::fs::read_to_string(data("lidar/lidar_numpy.txt")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<&str> = l.split_whitespace().collect();
            let f = |i: usize| v[i].parse::<f64>().unwrap();
            (
                v[0].parse().unwrap(),
                v[1].parse().unwrap(),
                v[2].parse().unwrap(),
                [f(3), f(4), f(5), f(6), f(7)],
                v[8] == "1",
            )
        })
        .collect()
}

/// Counts and population standard deviations per cell of the ground points by PDAL's rule, in
/// numpy on laspy's reading (lidar/stats_numpy.py): the quality-control grids.
#[test]
fn lidar_count_and_stdev_grids_match_pdals_rule() {
    let text = std::fs::read_to_string(data("lidar/lidar_numpy_stats.txt")).unwrap();
    let cells: Vec<(u32, u32, f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            (v[0] as u32, v[1] as u32, v[2], v[3])
        })
        .collect();
    assert_eq!(cells.len(), 30 * 24);
    assert!(
        cells.iter().any(|c| c.2 == 0.0),
        "the fixture has empty cells"
    );
    for las in [data("lidar/lidar_12.las"), data("lidar/lidar_14.laz")] {
        let count = grid_of(std::slice::from_ref(&las), &cell10(LidarMethod::Count));
        let stdev = grid_of(std::slice::from_ref(&las), &cell10(LidarMethod::Stdev));
        for &(row, col, n, sd) in &cells {
            assert_eq!(count.at(col, row) as f64, n, "count ({col}, {row})");
            let ours = stdev.at(col, row) as f64;
            if n == 0.0 {
                assert!(ours.is_nan(), "stdev ({col}, {row}): {ours} without points");
            } else {
                // f32 of a few metres: 2.4e-7 apart, numpy's printed 1e-9.
                assert!(
                    (ours - sd).abs() <= 1e-6,
                    "stdev ({col}, {row}): {ours}, numpy {sd}"
                );
            }
        }
    }
    assert!(!LidarMethod::Count.is_height() && !LidarMethod::Stdev.is_height());
    assert_eq!(LidarMethod::by_name("stdev"), Some(LidarMethod::Stdev));
}

#[test]
fn lidar_grids_match_gdal_grid_and_pdals_rule() {
    let cells = numpy_cells();
    let las = [data("lidar/lidar_12.las")];
    // f32 samples of heights near 1,850 m are 1.2e-4 apart: half a step plus the references'
    // printed digits (1e-9 numpy, 1e-6 GDAL) stays under 1e-4.
    let tol = 1e-4;
    let mut report = String::new();
    for (k, (method, gdal)) in [
        (LidarMethod::Mean, "average"),
        (LidarMethod::Min, "minimum"),
        (LidarMethod::Max, "maximum"),
        (LidarMethod::Idw, "invdist"),
    ]
    .into_iter()
    .enumerate()
    {
        let g = grid_of(&las, &cell10(method));
        assert_eq!((g.width(), g.height()), (30, 24));
        // GDAL's lattice: -txe/-tye at the cells' edges, so its corner is half a cell from our
        // first sample's centre.
        let (head, gv) = asc_f64(&data(&format!("lidar/lidar_gdal_{gdal}.asc")));
        let hv = |k: &str| head.iter().find(|(n, _)| n == k).unwrap().1;
        let geo = g.georef();
        assert_eq!(geo.origin_x, hv("xllcorner") + 5.0);
        assert_eq!(geo.origin_y, hv("yllcorner") + 24.0 * 10.0 - 5.0);
        assert_eq!((geo.dx, geo.dy), (hv("cellsize"), -hv("cellsize")));
        let (mut same_np, mut same_gdal, mut boundary) = (0, 0, 0);
        let (mut worst_np, mut worst_gdal, mut differ) = (0f64, 0f64, 0);
        for &(row, col, count, ref v, on_radius) in &cells {
            let ours = g.at(col as u32, row as u32) as f64;
            let np = v[k];
            assert_eq!(ours.is_nan(), count == 0, "{gdal} ({col}, {row})");
            if count == 0 {
                assert!(np.is_nan());
                same_np += 1;
            } else {
                assert!(
                    (ours - np).abs() <= tol,
                    "{gdal} ({col}, {row}): PDAL's rule (numpy) {np}, ours {ours}, tolerance {tol}"
                );
                worst_np = worst_np.max((ours - np).abs());
                same_np += 1;
            }
            let gd = gv[row * 30 + col];
            let gd = if gd == -9999.0 { f64::NAN } else { gd };
            if on_radius {
                // A point exactly R from the centre: GDAL counts it (≤), PDAL does not (<).
                boundary += 1;
                differ += ((ours - gd).abs() > tol) as u32;
                continue;
            }
            if ours.is_nan() {
                assert!(
                    gd.is_nan(),
                    "{gdal} ({col}, {row}): GDAL {gd}, ours no-data"
                );
            } else {
                assert!(
                    (ours - gd).abs() <= tol,
                    "{gdal} ({col}, {row}): gdal_grid {gd}, ours {ours}, tolerance {tol}"
                );
                worst_gdal = worst_gdal.max((ours - gd).abs());
            }
            same_gdal += 1;
        }
        report.push_str(&format!(
            "{gdal}: {same_np}/{} cells as PDAL's rule (largest difference {worst_np:.1e} m), \
             {same_gdal} as gdal_grid ({worst_gdal:.1e} m), {boundary} with a point on the radius \
             ({differ} of them differing from gdal_grid's)\n",
            cells.len()
        ));
        assert_eq!(
            boundary, 12,
            "three points on cell centres, four diagonal neighbours each"
        );
    }
    // PDAL's window_size = 2 fill of the mean grid.
    let g = grid_of(
        &las,
        &LidarOptions {
            fill: 2,
            ..cell10(LidarMethod::Mean)
        },
    );
    let mut filled = 0;
    for &(row, col, count, ref v, _) in &cells {
        let ours = g.at(col as u32, row as u32) as f64;
        assert!(
            (ours - v[4]).abs() <= tol,
            "fill2 ({col}, {row}): numpy {}, ours {ours}",
            v[4]
        );
        filled += (count == 0) as u32;
    }
    assert_eq!(filled, 6, "the building's and the pond's empty cells");
    assert_eq!(g.nodata_count(), 0);
    eprintln!("{report}");
}

#[test]
fn lidar_las_and_laz_of_one_survey_grid_alike() {
    let grids: Vec<Grid> = LIDAR
        .iter()
        .map(|n| grid_of(&[data(n)], &cell10(LidarMethod::Idw)))
        .collect();
    for (g, n) in grids.iter().zip(LIDAR) {
        assert!(
            same_grid(g, &grids[0]),
            "{n} grids otherwise than {}",
            LIDAR[0]
        );
    }
    // Two files are one cloud: the survey twice over gives the same means, min and max.
    let twice = [data(LIDAR[0]), data(LIDAR[3])];
    for m in [LidarMethod::Mean, LidarMethod::Min, LidarMethod::Max] {
        let one = grid_of(&[data(LIDAR[0])], &cell10(m));
        let two = grid_of(&twice, &cell10(m));
        for (a, b) in one.heights().iter().zip(two.heights()) {
            assert!(
                a.is_nan() && b.is_nan() || (a - b).abs() <= 1e-4,
                "{a} vs {b}"
            );
        }
    }
    // read_dem and read_dems: by extension, and the files as one grid named by both.
    let g = read_dem(
        data(LIDAR[2]),
        &ReadOptions {
            lidar: cell10(LidarMethod::Idw),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert!(same_grid(&g, &grids[0]));
    let parts = read_dems(
        &twice,
        &ReadOptions {
            lidar: cell10(LidarMethod::Mean),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert_eq!(parts.len(), 1);
    assert!(parts[0].0.contains("lidar_12.las + ") && parts[0].0.ends_with("lidar_14.laz"));
    assert_eq!(
        DemFormat::from_path(Path::new("a.LAZ")),
        Some(DemFormat::Las)
    );
}

#[test]
fn lidar_points_are_chosen_by_class_return_and_withheld_flag() {
    let las = [data("lidar/lidar_14.las")];
    let default = LidarOptions::default();
    let (cloud, r) = lidar::read_cloud(&las, &default).unwrap();
    // 1,808 ground points, 5 of them withheld.
    assert_eq!(r.selection, Selection::Ground);
    assert_eq!((r.points_read, r.withheld, r.points_used), (2436, 5, 1803));
    assert_eq!(cloud.len(), 1803);
    // The default cell: 1,803 points over about 300 x 240 m, two per cell: 8.9 m, so 10.
    let (_, _, g) = read_lidar(&las, &default).unwrap();
    assert!(g.cell_auto);
    assert_eq!(g.cell, 10.0);
    assert_eq!(g.radius, 10.0 * std::f64::consts::SQRT_2);
    // Ground and water: the pond's cells get heights.
    let water = LidarOptions {
        classes: Some(ClassSet::parse("2,9").unwrap()),
        ..cell10(LidarMethod::Mean)
    };
    let (_, r2, g2) = read_lidar(&las, &water).unwrap();
    assert_eq!(r2.points_used, 1843);
    let (_, _, g1) = read_lidar(&las, &cell10(LidarMethod::Mean)).unwrap();
    assert!(
        g2.empty_cells < g1.empty_cells,
        "{} vs {}",
        g2.empty_cells,
        g1.empty_cells
    );
    // Last returns: the ground points are last returns; vegetation (1 of 2) is not.
    let all = LidarOptions {
        classes: Some(ClassSet::of(&(0..=255).collect::<Vec<u8>>())),
        last_returns: true,
        ..cell10(LidarMethod::Mean)
    };
    let (_, r3) = lidar::read_cloud(&las, &all).unwrap();
    assert_eq!(r3.points_used, 1986 - 5);
    // No class asked for is present: an error listing the classes found.
    let none = LidarOptions {
        classes: Some(ClassSet::of(&[17])),
        ..default
    };
    let e = lidar::read_cloud(&las, &none).unwrap_err().to_string();
    assert!(
        e.contains("lidar_14.las") && e.contains("class 2: 1808"),
        "{e}"
    );

    // A survey without ground: every class but noise (7, 18).
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = std::fs::read(&las[0]).unwrap();
    let h = LasReader::open(&las[0]).unwrap().header().clone();
    for i in 0..h.point_count as usize {
        let c = h.offset_to_points as usize + i * h.record_len as usize + 16;
        if bytes[c] == 2 {
            bytes[c] = 1;
        }
    }
    let p = dir.path().join("unclassified.las");
    std::fs::write(&p, &bytes).unwrap();
    let (cloud, r) = lidar::read_cloud(&[p], &default).unwrap();
    assert_eq!(r.selection, Selection::AllButNoise);
    assert_eq!(cloud.len(), 2436 - 5 - 12 - 6);
    assert!(cloud.z.iter().all(|&z| z > 1700.0 && z < 1960.0));
}

/// A LAS 1.2 file of point format 0 with `points` `(x, y, z, class)` at scale 0.01, and a GeoKey
/// directory naming `epsg` when given.
fn write_las(points: &[(f64, f64, f64, u8)], epsg: Option<u16>) -> Vec<u8> {
    let (scale, off): (f64, [f64; 3]) = (0.01, [300000.0, 4900000.0, 0.0]);
    let vlr: Vec<u8> = match epsg {
        None => Vec::new(),
        Some(code) => {
            // GTModelType projected and ProjectedCSType, or geographic and GeographicType.
            let (model, key) = if code == 4326 { (2, 2048) } else { (1, 3072) };
            let keys: [u16; 12] = [1, 1, 0, 2, 1024, 0, 1, model, key, 0, 1, code];
            let mut v = vec![0u8; 54];
            v[2..17].copy_from_slice(b"LASF_Projection");
            v[18..20].copy_from_slice(&34735u16.to_le_bytes());
            v[20..22].copy_from_slice(&24u16.to_le_bytes());
            v.extend(keys.iter().flat_map(|k| k.to_le_bytes()));
            v
        }
    };
    let mut h = vec![0u8; 227];
    h[..4].copy_from_slice(b"LASF");
    h[24] = 1;
    h[25] = 2;
    h[94..96].copy_from_slice(&227u16.to_le_bytes());
    h[96..100].copy_from_slice(&((227 + vlr.len()) as u32).to_le_bytes());
    h[100..104].copy_from_slice(&(epsg.is_some() as u32).to_le_bytes());
    h[104] = 0;
    h[105..107].copy_from_slice(&20u16.to_le_bytes());
    h[107..111].copy_from_slice(&(points.len() as u32).to_le_bytes());
    for k in 0..3 {
        h[131 + 8 * k..139 + 8 * k].copy_from_slice(&scale.to_le_bytes());
        h[155 + 8 * k..163 + 8 * k].copy_from_slice(&off[k].to_le_bytes());
    }
    let fold = |f: fn(&(f64, f64, f64, u8)) -> f64| {
        points
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let (bx, by, bz) = (fold(|p| p.0), fold(|p| p.1), fold(|p| p.2));
    for (k, v) in [bx.1, bx.0, by.1, by.0, bz.1, bz.0].iter().enumerate() {
        h[179 + 8 * k..187 + 8 * k].copy_from_slice(&v.to_le_bytes());
    }
    h.extend(vlr);
    for &(x, y, z, c) in points {
        for (k, v) in [x, y, z].iter().enumerate() {
            h.extend((((v - off[k]) / scale).round() as i32).to_le_bytes());
        }
        h.extend([0, 0, 0x09, c, 0, 0, 0, 0]);
    }
    h
}

#[test]
fn lidar_tiles_grid_as_one_survey() {
    // The survey cut into a west and an east tile at x = 316150: the two grid as the whole.
    let pts: Vec<(f64, f64, f64, u8)> = all_points(&data("lidar/lidar_12.las"))
        .iter()
        .filter(|p| !p.withheld)
        .map(|p| (p.x, p.y, p.z, p.class))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let (west, east): (Vec<_>, Vec<_>) = pts.iter().partition(|p| p.0 < 316150.0);
    let paths = [dir.path().join("w.las"), dir.path().join("e.las")];
    std::fs::write(&paths[0], write_las(&west, Some(32619))).unwrap();
    std::fs::write(&paths[1], write_las(&east, Some(32619))).unwrap();
    let whole = grid_of(&[data("lidar/lidar_12.las")], &cell10(LidarMethod::Mean));
    let tiles = grid_of(&paths, &cell10(LidarMethod::Mean));
    assert_eq!(tiles.georef(), whole.georef());
    // The same points summed in another order: within f32 rounding.
    for (a, b) in whole.heights().iter().zip(tiles.heights()) {
        assert!(
            a.is_nan() && b.is_nan() || (a - b).abs() <= 1e-4,
            "{a} vs {b}"
        );
    }
    // Each tile alone shares the lattice: the two join in a mosaic without resampling.
    let w = grid_of(&paths[..1], &cell10(LidarMethod::Mean));
    let e = grid_of(&paths[1..], &cell10(LidarMethod::Mean));
    let (m, _) = texmap_terrain::dem::mosaic::mosaic(vec![("w".into(), w), ("e".into(), e)])
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.georef().origin_x, whole.georef().origin_x);
    // A tile in another system is refused, naming it; one without a system grids locally.
    std::fs::write(&paths[1], write_las(&east, Some(32618))).unwrap();
    let e = read_lidar(&paths, &cell10(LidarMethod::Mean))
        .unwrap_err()
        .to_string();
    assert!(e.contains("e.las") && e.contains("EPSG:32618"), "{e}");
    let local = dir.path().join("local.las");
    std::fs::write(&local, write_las(&east, None)).unwrap();
    let g = grid_of(&[local], &cell10(LidarMethod::Mean));
    assert_eq!((g.georef().crs, g.georef().epsg), (CrsKind::Local, None));
    // A cloud in degrees is refused.
    let deg = dir.path().join("deg.las");
    std::fs::write(&deg, write_las(&east, Some(4326))).unwrap();
    let e = read_lidar(&[deg], &cell10(LidarMethod::Mean))
        .unwrap_err()
        .to_string();
    assert!(e.contains("deg.las") && e.contains("degrees"), "{e}");
}

#[test]
fn lidar_grids_are_the_same_bytes_for_any_thread_count() {
    // 300 000 points over 400 x 300 m, cells of 0.5 m (sums over many points per cell).
    let mut cloud = Cloud::default();
    let mut s = 0x5eed_u64;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..300_000 {
        let (x, y) = (500_000.0 + rnd() * 400.0, 4_000_000.0 + rnd() * 300.0);
        cloud.push(x, y, 100.0 + 0.01 * x.sin() * 1000.0 + rnd());
    }
    for method in [LidarMethod::Mean, LidarMethod::Idw] {
        let opts = LidarOptions {
            cell: Some(0.5),
            method,
            fill: 3,
            ..LidarOptions::default()
        };
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| grid_cloud(&cloud, "synthetic", CrsKind::Projected, Some(32633), &opts))
                .unwrap()
                .0
        };
        let one = run(1);
        for t in [2, 3, 8] {
            let g = run(t);
            let bits = |g: &Grid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&g), bits(&one), "{method:?} with {t} threads");
        }
    }
}

#[test]
fn hostile_lidar_headers_are_errors_naming_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(data("lidar/lidar_12.las")).unwrap();
    let set = |at: usize, v: &[u8]| {
        let mut b = good.clone();
        b[at..at + v.len()].copy_from_slice(v);
        b
    };
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        // 10^12 points claimed by a 1 KB file: refused before anything is sized from it.
        (
            "count",
            {
                let mut b = set(107, &u32::MAX.to_le_bytes());
                b.truncate(1024);
                b
            },
            "the file ends at byte 1024",
        ),
        ("signature", set(0, b"LASG"), "signature"),
        ("version", set(24, &[2, 0]), "version 2.0"),
        ("offset", set(96, &u32::MAX.to_le_bytes()), "byte 96"),
        ("format", set(104, &[11]), "format 11"),
        ("record", set(105, &10u16.to_le_bytes()), "byte 105"),
        ("scale", set(131, &0f64.to_le_bytes()), "byte 131"),
        ("vlrs", set(100, &u32::MAX.to_le_bytes()), "VLR 1 at byte"),
        (
            "bounds",
            set(187, &317000.0f64.to_le_bytes()),
            "bounding box",
        ),
        (
            "x",
            {
                let off = u32::from_le_bytes(good[96..100].try_into().unwrap()) as usize;
                set(off + 28 * 100, &i32::MAX.to_le_bytes())
            },
            "point 100 at byte",
        ),
    ];
    for (what, bytes, expect) in cases {
        let p = dir.path().join(format!("{what}.las"));
        std::fs::write(&p, &bytes).unwrap();
        let (r, peak) = crate::alloc::measure(|| {
            read_lidar(std::slice::from_ref(&p), &cell10(LidarMethod::Mean))
        });
        let e = r
            .err()
            .unwrap_or_else(|| panic!("{what}: no error"))
            .to_string();
        assert!(
            e.contains(&format!("{what}.las")) && e.contains(expect),
            "{what}: {e}"
        );
        assert!(
            peak < 8 << 20,
            "{what}: {peak} bytes of heap for a {}-byte file",
            bytes.len()
        );
    }
    // LAZ: the chunk table cut off, and a layer size of a 1.4 chunk set to 4 GB.
    let laz = std::fs::read(data("lidar/lidar_12.laz")).unwrap();
    let p = dir.path().join("cut.laz");
    std::fs::write(&p, &laz[..laz.len() - 20]).unwrap();
    let e = LasReader::open(&p).err().unwrap().to_string();
    assert!(e.contains("cut.laz") && e.contains("chunk table"), "{e}");
    let laz14 = std::fs::read(data("lidar/lidar_14.laz")).unwrap();
    let h = LasReader::open(data("lidar/lidar_14.laz"))
        .unwrap()
        .header()
        .clone();
    let mut b = laz14.clone();
    // First chunk: the 8-byte table offset, a raw point, the point count, then layer sizes.
    let z_layer = h.offset_to_points as usize + 8 + h.record_len as usize + 4 + 4;
    b[z_layer..z_layer + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = dir.path().join("layer.laz");
    std::fs::write(&p, &b).unwrap();
    let (r, peak) = crate::alloc::measure(|| LasReader::open(&p).map(|_| ()));
    let e = r.unwrap_err().to_string();
    assert!(e.contains("layer.laz") && e.contains("LAZ chunk 0"), "{e}");
    assert!(peak < 8 << 20, "{peak}");
}

// Gridded XYZ text (tests/data/xyz.sh): GDAL's XYZ driver wrote the ramps and a window of the SRTM
// tile; GDAL's reading of each is `<file>.gdalinfo.json` and `xyz_gdal_samples.txt`.

/// GDAL's placing of `file` (from `<file>.gdalinfo.json`) against `grid`'s.
fn xyz_placed_as_gdal(grid: &Grid, file: &str) {
    let info = std::fs::read_to_string(data(&format!("{file}.gdalinfo.json"))).unwrap();
    placed_like_gdal(grid, &serde_json::from_str(&info).unwrap(), file);
}

/// `file`'s samples in xyz_gdal_samples.txt, as `(col, row, GDAL's value)`.
fn xyz_gdal_samples(file: &str) -> Vec<(u32, u32, f64)> {
    let text = std::fs::read_to_string(data("xyz_gdal_samples.txt")).unwrap();
    let v: Vec<(u32, u32, f64)> = text
        .lines()
        .map(|l| l.split(' ').collect::<Vec<_>>())
        .filter(|f| f[0] == file)
        .map(|f| {
            (
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
            )
        })
        .collect();
    assert_eq!(v.len(), 60, "{file}");
    v
}

#[test]
fn gridded_xyz_reads_as_gdal_reads_it_with_holes_as_no_data() {
    // The ramps: the GeoTIFFs' samples bit for bit, where GDAL placed them. GDAL's XYZ writer
    // writes the GeoTIFF's no-data marker (-32768) or nan as a value; both read as no-data here,
    // as heights in GDAL (the format declares no no-data).
    for (file, tif, system) in [
        // ramp_i16.prj, beside it for ramp_i16.bil, gives UTM 54N.
        (
            "ramp_i16.xyz",
            "ramp_i16_lzw.tif",
            (CrsKind::Projected, Some(32654)),
        ),
        (
            "ramp_geo.xyz",
            "ramp_f32_geo.tif",
            (CrsKind::Geographic, Some(4326)),
        ),
    ] {
        let g = read(&data(file));
        let t = read(&data(tif));
        xyz_placed_as_gdal(&g, file);
        assert_eq!((g.georef().crs, g.georef().epsg), system, "{file}");
        assert!(
            g.heights()
                .iter()
                .zip(t.heights())
                .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())),
            "{file}: heights differ from {tif}'s"
        );
        assert_eq!(g.nodata_count(), 1, "{file}");
        for (col, row, v) in xyz_gdal_samples(file) {
            let ours = g.at(col, row);
            if (col, row) == (5, 3) {
                assert!(ours.is_nan() && (v == -32768.0 || v.is_nan()), "{file}");
            } else {
                assert_eq!(ours as f64, v, "{file} ({col}, {row})");
            }
        }
    }
    // A spreadsheet's export: header names GDAL does not know, semicolons, decimal commas.
    let comma = read(&data("ramp_comma.xyz"));
    let ramp = read(&data("ramp_i16.xyz"));
    assert_eq!((comma.width(), comma.height()), (37, 29));
    assert_eq!(comma.georef().origin_x, ramp.georef().origin_x + 0.5);
    for (a, b) in comma.heights().iter().zip(ramp.heights()) {
        assert!(a == &(b + 0.25) || (a.is_nan() && b.is_nan()));
    }
    // Real heights south row first, a tenth of the lines left out: the SRTM window where listed,
    // no-data where not (GDAL reads those as 0, which no sample of this window is).
    let g = read(&data("srtm_gaps.xyz"));
    xyz_placed_as_gdal(&g, "srtm_gaps.xyz");
    let hgt = hgt();
    same_place(&g, (0.0, 0.0), &hgt, (800.0, 850.0), 1e-9);
    let mut holes = 0;
    for row in 0..64 {
        for col in 0..64 {
            let (ours, want) = (g.at(col, row), hgt.at(800 + col, 850 + row));
            if want as i32 % 10 == 7 {
                assert!(ours.is_nan(), "({col}, {row}): {ours}, listed as {want}");
                holes += 1;
            } else {
                assert_eq!(ours, want, "({col}, {row})");
            }
        }
    }
    assert_eq!(g.nodata_count(), holes);
    assert_eq!(4096 - holes, 3705, "the lines srtm_gaps.xyz lists");
    for (col, row, v) in xyz_gdal_samples("srtm_gaps.xyz") {
        let ours = g.at(col, 63 - row); // GDAL's rows run south to north here
        if v == 0.0 {
            assert!(ours.is_nan(), "({col}, {row})");
        } else {
            assert_eq!(ours as f64, v, "({col}, {row})");
        }
    }
}

#[test]
fn xyz_files_that_are_not_grids_are_errors_naming_the_line() {
    use texmap_terrain::dem::xyz::read_xyz_str;
    let local = (CrsKind::Local, None);
    let grid = "0 0 1\n10 0 2\n0 10 3\n10 10 4\n";
    let g = read_xyz_str(grid, "g.xyz", local).unwrap();
    assert_eq!(
        (g.width(), g.height(), g.at(0, 0), g.at(1, 1)),
        (2, 2, 3.0, 2.0)
    );
    for (text, want) in [
        // x = 14.5 among 0, 10, 20, 30: the smallest step, evened, leaves 10 a third off.
        (
            "0 0 1\n10 0 2\n20 0 3\n30 0 4\n14.5 10 5\n0 10 6\n",
            "line 2",
        ),
        // A second line for one sample.
        ("0 0 1\n10 0 2\n0 10 3\n10 10 4\n0 0 9\n", "line 5"),
        // Not a number; too few columns.
        ("x y z\n0 0 1\n10 0 2\n0 ten 3\n10 10 4\n", "line 4"),
        ("0 0 1\n10 0 2\n0 10\n10 10 4\n", "line 3"),
        // An infinite height.
        ("0 0 1\n10 0 2\n0 10 1e39\n10 10 4\n", "line 3"),
        // Four points a kilometre apart at 1 m: scattered points, not a grid.
        (
            "0 0 1\n1000 0 2\n0 1000 3\n1000 1000 4\n1 0 5\n",
            "scattered",
        ),
        // One column.
        ("0 0 1\n0 10 2\n0 20 3\n0 30 4\n", "two distinct x"),
        ("0 0 1\n", "at least 4"),
    ] {
        let e = read_xyz_str(text, "bad.xyz", local)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.xyz") && e.contains(want), "{text:?}: {e}");
    }
}

// ---- Cloud-Optimized GeoTIFFs (dem::geotiff_writer with GeoTiffOptions::cog) -----------------

/// A seeded 1101 x 1301 UTM grid (odd sizes: GDAL's overviews then weight partly covered
/// pixels) with a fifth of its samples and a block no-data, and a byte mask from the same seed.
fn cog_test_grid() -> (Grid, Vec<u8>) {
    use texmap_terrain::dem::Georef;
    let (w, h) = (1101u32, 1301u32);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut heights = Vec::with_capacity((w * h) as usize);
    let mut mask = Vec::with_capacity((w * h) as usize);
    for r in 0..h {
        for c in 0..w {
            let z = 100.0 + 30.0 * (c as f64 / 37.0).sin() + 20.0 * (r as f64 / 23.0).cos();
            let z = z + 5.0 * next();
            let hole = next() < 0.2 || ((400..700).contains(&r) && (300..800).contains(&c));
            heights.push(if hole { f32::NAN } else { z as f32 });
            mask.push(if next() < 0.5 { 255 } else { 0 });
        }
    }
    let georef = Georef {
        crs: CrsKind::Projected,
        epsg: Some(32619),
        origin_x: 500_015.0,
        origin_y: 4_899_985.0,
        dx: 30.0,
        dy: -30.0,
    };
    (Grid::new("cog", w, h, heights, georef).unwrap(), mask)
}

/// The IFDs of a little-endian classic TIFF, read by hand (independent of the writer): each
/// IFD's offset and its tags' values as integers (ASCII and DOUBLE values left out).
fn tiff_ifds(bytes: &[u8]) -> Vec<(u64, std::collections::BTreeMap<u16, Vec<u64>>)> {
    let u16_at = |o: usize| u16::from_le_bytes([bytes[o], bytes[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    assert_eq!(&bytes[..4], b"II\x2a\x00", "a little-endian classic TIFF");
    let mut ifds = Vec::new();
    let mut at = u32_at(4) as usize;
    while at != 0 {
        let n = u16_at(at) as usize;
        let mut tags = std::collections::BTreeMap::new();
        for i in 0..n {
            let e = at + 2 + 12 * i;
            let (tag, ty, count) = (u16_at(e), u16_at(e + 2), u32_at(e + 4) as usize);
            let size = match ty {
                3 => 2,
                4 => 4,
                _ => continue,
            };
            let base = if size * count <= 4 {
                e + 8
            } else {
                u32_at(e + 8) as usize
            };
            let v = (0..count)
                .map(|k| match size {
                    2 => u16_at(base + 2 * k) as u64,
                    _ => u32_at(base + 4 * k) as u64,
                })
                .collect();
            tags.insert(tag, v);
        }
        ifds.push((at as u64, tags));
        at = u32_at(at + 2 + 12 * n) as usize;
    }
    ifds
}

/// A COG read back by our reader is the grid sample for sample with the strip file's
/// georeference; its layout follows the COG rules (read by hand from the file); 1 and 2 threads
/// write the same bytes; a bad block size is an error that leaves no file.
#[test]
fn cog_reads_back_sample_for_sample_with_the_cog_layout() {
    use texmap_terrain::dem::geotiff_writer::{
        GeoTiffOptions, Samples, write_geotiff_with, write_grid, write_grid_with,
    };
    let (grid, mask) = cog_test_grid();
    let dir = tempfile::tempdir().unwrap();
    let (cog, strips) = (dir.path().join("cog.tif"), dir.path().join("strips.tif"));
    write_grid_with(&cog, &grid, &GeoTiffOptions::cog()).unwrap();
    write_grid(&strips, &grid).unwrap();
    let (back, strip_back) = (read(&cog), read(&strips));
    assert_eq!((back.width(), back.height()), (grid.width(), grid.height()));
    for (i, (a, b)) in back.heights().iter().zip(grid.heights()).enumerate() {
        assert!(a.to_bits() == b.to_bits(), "sample {i}: {a} vs {b}");
    }
    assert_eq!(back.georef(), strip_back.georef());

    // The layout, file by file.
    let masked = dir.path().join("mask.tif");
    write_geotiff_with(
        &masked,
        grid.width(),
        grid.height(),
        Samples::U8(&mask),
        grid.georef(),
        None,
        &GeoTiffOptions::cog(),
    )
    .unwrap();
    for (file, predictor) in [(&cog, 3), (&masked, 2)] {
        let bytes = std::fs::read(file).unwrap();
        let ghost = b"GDAL_STRUCTURAL_METADATA_SIZE=";
        assert_eq!(&bytes[8..8 + ghost.len()], ghost, "{}", file.display());
        let ifds = tiff_ifds(&bytes);
        let sizes: Vec<(u64, u64)> = ifds.iter().map(|(_, t)| (t[&256][0], t[&257][0])).collect();
        assert_eq!(sizes, [(1101, 1301), (550, 650), (275, 325)]);
        let first_tile = ifds
            .iter()
            .flat_map(|(_, t)| t[&324].clone())
            .min()
            .unwrap();
        for (level, (at, t)) in ifds.iter().enumerate() {
            assert!(
                *at < first_tile,
                "IFD {level} at {at} after a tile at {first_tile}"
            );
            assert_eq!(
                t.get(&254),
                (level > 0).then(|| vec![1]).as_ref(),
                "NewSubfileType"
            );
            assert_eq!((t[&322][0], t[&323][0], t[&317][0]), (512, 512, predictor));
            let tiles = 1101u64.div_ceil(512 << level) * 1301u64.div_ceil(512 << level);
            assert_eq!(t[&324].len() as u64, tiles.max(1));
            // Each tile between its leader (its size) and trailer (its last 4 bytes again).
            for (&o, &n) in t[&324].iter().zip(&t[&325]) {
                let (o, n) = (o as usize, n as usize);
                assert_eq!(bytes[o - 4..o], (n as u32).to_le_bytes());
                assert_eq!(bytes[o + n - 4..o + n], bytes[o + n..o + n + 4]);
            }
        }
        // The smallest overview's tiles first, the full resolution's last.
        for pair in ifds.windows(2) {
            let coarse_last = pair[1].1[&324].iter().max().unwrap();
            let fine_first = pair[0].1[&324].iter().min().unwrap();
            assert!(coarse_last < fine_first, "{}", file.display());
        }
    }

    // The same bytes for 1 and 2 threads.
    let mut files = Vec::new();
    for threads in [1, 2] {
        let p = dir.path().join(format!("t{threads}.tif"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| write_grid_with(&p, &grid, &GeoTiffOptions::cog()).unwrap());
        files.push(std::fs::read(&p).unwrap());
    }
    assert!(
        files[0] == files[1],
        "1 and 2 threads wrote different bytes"
    );

    // A block size that is not a multiple of 16 is refused, leaving nothing behind.
    let bad = dir.path().join("bad.tif");
    let opts = GeoTiffOptions {
        cog: true,
        block_size: 100,
    };
    let e = write_grid_with(&bad, &grid, &opts).unwrap_err();
    assert!(e.to_string().contains("block_size"), "{e}");
    assert!(!bad.exists());
}

/// gdalinfo reads our COG with 512 x 512 blocks, GDAL's overview sizes, LAYOUT=COG and the
/// strip file's georeference; each overview level is the one GDAL's COG driver makes from the
/// strip file (`-co RESAMPLING=AVERAGE` for heights, `NEAREST` for a byte mask), read by GDAL
/// from both files. SKIPPED without GDAL.
#[test]
fn cog_overviews_match_gdal_cog_driver() {
    use std::process::Command;
    use texmap_terrain::dem::geotiff_writer::{
        GeoTiffOptions, Samples, write_geotiff, write_geotiff_with, write_grid, write_grid_with,
    };
    // "GDAL 3.6.2, released 2023/01/02": the COG driver is GDAL 3.1's.
    let version = Command::new("gdalinfo").arg("--version").output();
    let Some(version) = version
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
    else {
        eprintln!("SKIPPED COG check against GDAL: gdalinfo is not installed");
        return;
    };
    let number = version.split([' ', ',']).nth(1).unwrap_or("");
    let mut parts = number.split('.').map(|p| p.parse::<u32>().unwrap_or(0));
    if (parts.next().unwrap_or(0), parts.next().unwrap_or(0)) < (3, 1) {
        eprintln!("SKIPPED COG check against GDAL: {version} has no COG driver (3.1)");
        return;
    }
    let run = |args: &[&std::ffi::OsStr]| {
        let o = Command::new(args[0]).args(&args[1..]).output().unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        o.stdout
    };
    // GDAL's own COG of `strips` with `resampling`, as `theirs`.
    let gdal_cog = |strips: &Path, theirs: &Path, resampling: &str| {
        let co = format!("RESAMPLING={resampling}");
        let args = ["-q", "-of", "COG", "-co", &co];
        let mut all: Vec<&std::ffi::OsStr> = vec!["gdal_translate".as_ref()];
        all.extend(args.iter().map(|a| std::ffi::OsStr::new(*a)));
        all.extend([strips.as_os_str(), theirs.as_os_str()]);
        run(&all);
    };
    let info = |p: &Path| -> serde_json::Value {
        serde_json::from_slice(&run(&["gdalinfo".as_ref(), "-json".as_ref(), p.as_ref()])).unwrap()
    };
    // Overview `k` of `p` as GDAL reads it, raw little-endian samples.
    let overview = |p: &Path, k: usize, out: &Path| -> Vec<u8> {
        let k = k.to_string();
        run(&[
            "gdal_translate".as_ref(),
            "-q".as_ref(),
            "-ovr".as_ref(),
            k.as_ref(),
            "-of".as_ref(),
            "ENVI".as_ref(),
            p.as_ref(),
            out.as_ref(),
        ]);
        std::fs::read(out).unwrap()
    };
    let (grid, mask) = cog_test_grid();
    // The grid whole, and a hole-free even-sized part of it (GDAL's fast 2x2 path).
    let mut solid = Vec::new();
    for r in 0..1024usize {
        for c in 0..1536usize {
            let v = grid.heights()[r * 1101 + c % 1101];
            solid.push(if v.is_nan() {
                50.0 + (r + c) as f32 * 0.25
            } else {
                v
            });
        }
    }
    let solid = Grid::new("solid", 1536, 1024, solid, *grid.georef()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, g) in [("holes", &grid), ("solid", &solid)] {
        let (ours, strips, theirs) = (
            d.join(format!("{name}_ours.tif")),
            d.join(format!("{name}_strips.tif")),
            d.join(format!("{name}_gdal.tif")),
        );
        write_grid_with(&ours, g, &GeoTiffOptions::cog()).unwrap();
        write_grid(&strips, g).unwrap();
        gdal_cog(&strips, &theirs, "AVERAGE");
        let (i_ours, i_strips, i_theirs) = (info(&ours), info(&strips), info(&theirs));
        let band = &i_ours["bands"][0];
        assert_eq!(band["block"], serde_json::json!([512, 512]), "{name}");
        assert_eq!(
            band["overviews"].as_array().map(|o| o.len()),
            i_theirs["bands"][0]["overviews"]
                .as_array()
                .map(|o| o.len())
        );
        for (a, b) in band["overviews"]
            .as_array()
            .unwrap()
            .iter()
            .zip(i_theirs["bands"][0]["overviews"].as_array().unwrap())
        {
            assert_eq!(a["size"], b["size"], "{name}: overview sizes");
        }
        assert_eq!(i_ours["geoTransform"], i_strips["geoTransform"], "{name}");
        assert_eq!(
            i_ours["coordinateSystem"], i_strips["coordinateSystem"],
            "{name}"
        );
        assert_eq!(
            i_ours["metadata"]["IMAGE_STRUCTURE"]["LAYOUT"], "COG",
            "{name}"
        );
        assert_eq!(
            band["noDataValue"], i_strips["bands"][0]["noDataValue"],
            "{name}"
        );
        // GDAL sums in f64 and rounds once, as we do, except its 2x2 fast path without no-data,
        // which sums four f32 in f32: up to 2 ulp apart.
        let levels = band["overviews"].as_array().unwrap().len();
        let mut worst = 0f64;
        for k in 0..levels {
            let a = overview(&ours, k, &d.join(format!("{name}_o{k}.bin")));
            let b = overview(&theirs, k, &d.join(format!("{name}_g{k}.bin")));
            assert_eq!(a.len(), b.len(), "{name} overview {k}");
            for (i, (x, y)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
                let x = f32::from_le_bytes(x.try_into().unwrap());
                let y = f32::from_le_bytes(y.try_into().unwrap());
                let tol = 2.0 * f32::EPSILON as f64 * (y.abs() as f64);
                let diff = (x as f64 - y as f64).abs();
                assert!(
                    x.is_nan() == y.is_nan() && (x.is_nan() || diff <= tol),
                    "{name} overview {k} sample {i}: ours {x}, GDAL {y}, tolerance {tol}"
                );
                if !x.is_nan() {
                    worst = worst.max(diff / y.abs() as f64);
                }
            }
        }
        eprintln!(
            "COG overviews vs GDAL 3.6 ({name}): {levels} levels, largest relative difference {worst:e}"
        );
    }
    // The mask: nearest, byte for byte.
    let (ours, strips, theirs) = (
        d.join("m_ours.tif"),
        d.join("m_strips.tif"),
        d.join("m_gdal.tif"),
    );
    let (w, h) = (grid.width(), grid.height());
    write_geotiff_with(
        &ours,
        w,
        h,
        Samples::U8(&mask),
        grid.georef(),
        None,
        &GeoTiffOptions::cog(),
    )
    .unwrap();
    write_geotiff(&strips, w, h, Samples::U8(&mask), grid.georef(), None).unwrap();
    gdal_cog(&strips, &theirs, "NEAREST");
    for k in 0..2 {
        let a = overview(&ours, k, &d.join(format!("m_o{k}.bin")));
        let b = overview(&theirs, k, &d.join(format!("m_g{k}.bin")));
        assert!(a == b, "mask overview {k} differs from GDAL's");
    }
}

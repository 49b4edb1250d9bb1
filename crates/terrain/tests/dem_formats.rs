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

/// `grid` (read from `file`) against GDAL's reading: size, georeference (GDAL's geoTransform
/// gives pixel corners, ours sample centres half a pixel in), the share of valid samples, the
/// statistics, and the values at the listed samples (GDAL's raw value, the no-data marker where
/// GDAL reports no-data).
fn matches_gdal(grid: &Grid, file: &str, crs: CrsKind, epsg: Option<u16>) {
    let info: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(data(&format!("{file}.gdalinfo.json"))).unwrap(),
    )
    .unwrap();
    let size: [u32; 2] = serde_json::from_value(info["size"].clone()).unwrap();
    assert_eq!([grid.width(), grid.height()], size, "{file}");
    let t: [f64; 6] = serde_json::from_value(info["geoTransform"].clone()).unwrap();
    let r = grid.georef();
    assert_eq!((r.crs, r.epsg), (crs, epsg), "{file}");
    // gdalinfo prints 16 significant digits: the tolerance is that rounding's, 1e-9 of a degree
    // (0.1 mm) or of a metre.
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
    assert_eq!((t[2], t[4]), (0.0, 0.0), "{file}: GDAL reports no rotation");
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

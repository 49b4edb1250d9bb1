//! DTED cells and ESRI `.hdr` rasters (GridFloat `.flt`, BIL `.bil`) that GDAL wrote from the SRTM
//! tile and the ramp GeoTIFFs (tests/data/dem_formats.sh), read as GDAL reads them: size,
//! georeference, no-data, statistics and sample values (`*.gdalinfo.json`,
//! `dem_formats_gdal_samples.txt`); the DTED cells' heights are the `.hgt` tile's sample for
//! sample; damaged files are errors naming the file and the place, never a panic or a partial
//! grid. (The mutation campaign over the same fixtures is in tests/fuzz_campaign.rs.)

use std::io::Read;
use std::path::{Path, PathBuf};

use texmap_terrain::TerrainError;
use texmap_terrain::dem::dted::{self, Checksums};
use texmap_terrain::dem::{CrsKind, DemFormat, Grid, ReadOptions, ehdr, read_dem};

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

//! DTED (Digital Terrain Elevation Data) levels 0, 1 and 2 (`.dt0`, `.dt1`, `.dt2`): the NGA
//! cells flight simulators and mission planners load, one file per 1° x 1° cell.
//!
//! **Layout** (MIL-PRF-89020B §3.11–3.14): three fixed headers, then one data record per
//! longitude line.
//! - UHL, the user header label (80 bytes, from byte 0): `UHL1`, the cell's origin (its
//!   south-west sample) as `DDDMMSSH` longitude (bytes 4–11) and latitude (12–19), the longitude
//!   and latitude intervals in tenths of an arc second (20–23, 24–27), the number of longitude
//!   lines (47–50) and of points per line (51–54), all ASCII.
//! - DSI, the data set identification (648 bytes from byte 80), which repeats the intervals
//!   (its bytes 273–280), the counts (281–288) and the origin (185–203, to a tenth of a second);
//!   and ACC, the accuracy description (2700 bytes from byte 728).
//! - From byte 3428, one record per longitude line, west to east: the sentinel `0xAA`, a 3-byte
//!   block count, the 2-byte longitude count (the line's index) and latitude count (0: the line
//!   starts at the south edge), the heights south to north as big-endian 16-bit **signed
//!   magnitude** integers (bit 15 the sign, not two's complement; −32767, `0xFFFF`, is void),
//!   and a 4-byte checksum: the sum of the record's bytes before it.
//!
//! Level 1 below 50° latitude is 1201 x 1201 samples 3″ apart, both edges included; from 50° the
//! latitude zones of the specification widen the longitude interval (6″ to 50°–70°, 9″, 12″, 18″
//! beyond 80°) and the cell has fewer longitude lines. The reader takes the intervals and counts
//! from the UHL and checks them against the DSI's copy, so any zone and level (and a partial
//! cell) reads the same way.
//!
//! **Georeference**: WGS 84 degrees (EPSG:4326; the specification's horizontal datum). Samples
//! sit on the grid lines, as in SRTM `.hgt` ([`super::hgt`]): sample (0, 0) is centred exactly
//! on the north-west grid intersection, `origin + (count − 1)·interval` north of the UHL origin.
//! GDAL's DTED driver reports the same points as the corners of pixels half an interval larger
//! (`AREA_OR_POINT=Point`). Heights are metres above the EGM96 geoid.
//!
//! **Checks**: the file's length against the counts before anything is sized from them (a
//! truncated file is an error naming the record it cuts, never a partial grid); the UHL's
//! fields against the DSI's; each record's sentinel, longitude count and latitude count; and
//! each record's checksum ([`Checksums::Verify`], the default of [`super::read_dem`]): a mismatch
//! is an error naming the record and the checksum's byte, since a damaged record would put
//! spikes into the terrain. [`Checksums::Ignore`] (`texmap terrain build --ignore-checksums`)
//! reads a file whose producer wrote wrong checksums. GDAL ignores checksums unless
//! `DTED_VERIFY_CHECKSUM=YES`, and then refuses a mismatching record as here.
//!
//! **Not read**: tape labels (`VOL1`/`HDR1` before the UHL, `EOF1` after the data), which make
//! the file fail the `UHL1` or length check; two's-complement heights written by some
//! nonconforming producers (GDAL reinterprets negative values below −16000; here such a value is
//! an error naming its byte, since −32767 void and a two's-complement −1 share a bit pattern);
//! the DSI's datum (WGS 72 cells are read as WGS 84, a few metres apart) and the ACC's accuracy
//! figures.
//!
//! # References
//! - MIL-PRF-89020B, *Performance Specification: Digital Terrain Elevation Data (DTED)*, NIMA,
//!   23 May 2000: §3.11 (UHL), §3.12 (DSI), §3.13 (ACC), §3.14 (data records), Table 4 (latitude
//!   zones and intervals).
//! - GDAL, *DTED — Military Elevation Data* driver page (gdal.org/drivers/raster/dted.html):
//!   georeference, `DTED_VERIFY_CHECKSUM`, two's-complement files.

use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use std::path::Path;

/// Bytes of the UHL, DSI and ACC headers before the first data record.
pub const HEADER_LEN: usize = 80 + 648 + 2700;

/// The void marker: −32767 in signed magnitude.
const VOID: u16 = 0xFFFF;

/// What to do with each record's checksum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Checksums {
    /// A record whose checksum differs from the sum of its bytes is an error (the default).
    Verify,
    /// Read the heights whatever the checksums say (a producer that wrote wrong ones).
    Ignore,
}

/// Read a DTED cell, verifying every record's checksum.
pub fn read_dted(path: &Path) -> Result<Grid, TerrainError> {
    read_dted_with(path, Checksums::Verify)
}

/// Read a DTED cell with the given checksum policy.
pub fn read_dted_with(path: &Path, checksums: Checksums) -> Result<Grid, TerrainError> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    read_dted_bytes(&bytes, &path.display().to_string(), checksums)
}

/// The UHL's and DSI's description of the cell, in whole tenths of an arc second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Cell {
    /// Origin (south-west sample): longitude and latitude, tenths of an arc second.
    lon0: i64,
    lat0: i64,
    /// Intervals between longitude lines and between points along a line.
    dlon: i64,
    dlat: i64,
    /// Longitude lines (columns) and points per line (rows).
    lines: u32,
    points: u32,
}

/// Decode a DTED cell held in memory; `source` names it in errors.
pub fn read_dted_bytes(
    bytes: &[u8],
    source: &str,
    checksums: Checksums,
) -> Result<Grid, TerrainError> {
    let cell = headers(bytes, source)?;
    let (w, h) = (cell.lines, cell.points);
    check_size(source, w as u64, h as u64)?;
    // The file's length against the counts, before the grid is sized from them.
    let record = 12 + 2 * h as usize;
    let want = HEADER_LEN as u64 + w as u64 * record as u64;
    if bytes.len() as u64 != want {
        let at = bytes.len().min(want as usize);
        let line = at.saturating_sub(HEADER_LEN) / record;
        return Err(format_err(
            source,
            format!("byte {}", bytes.len()),
            if (bytes.len() as u64) < want {
                format!(
                    "{want} bytes for {w} longitude lines of {h} points ({record}-byte records), \
                     found {}: the file stops in record {line} of {w}",
                    bytes.len()
                )
            } else {
                format!(
                    "{want} bytes for {w} longitude lines of {h} points ({record}-byte records), \
                     found {}: {} bytes after the last record",
                    bytes.len(),
                    bytes.len() as u64 - want
                )
            },
        ));
    }
    let mut heights = vec![0f32; w as usize * h as usize];
    for (col, rec) in bytes[HEADER_LEN..].chunks_exact(record).enumerate() {
        let base = HEADER_LEN + col * record;
        let at = |k: usize| format!("byte {}, record {col}", base + k);
        if rec[0] != 0xAA {
            return Err(format_err(
                source,
                at(0),
                format!("the data record sentinel 0xAA, found {:#04x}", rec[0]),
            ));
        }
        let lon_count = u16::from_be_bytes([rec[4], rec[5]]);
        if lon_count as usize != col {
            return Err(format_err(
                source,
                at(4),
                format!("longitude count {col} (records in order west to east), found {lon_count}"),
            ));
        }
        let lat_count = u16::from_be_bytes([rec[6], rec[7]]);
        if lat_count != 0 {
            return Err(format_err(
                source,
                at(6),
                format!("latitude count 0 (a line starting at the south edge), found {lat_count}"),
            ));
        }
        let body = &rec[..record - 4];
        if checksums == Checksums::Verify {
            let stored = u32::from_be_bytes([
                rec[record - 4],
                rec[record - 3],
                rec[record - 2],
                rec[record - 1],
            ]);
            let sum = body.iter().map(|&b| b as u32).sum::<u32>();
            if stored != sum {
                return Err(format_err(
                    source,
                    at(record - 4),
                    format!(
                        "the record's checksum, the sum of its {} bytes before it ({sum}), found \
                         {stored}: the record is damaged, or its producer wrote a wrong checksum \
                         (texmap terrain build --ignore-checksums reads it anyway)",
                        record - 4
                    ),
                ));
            }
        }
        // Heights south to north; grid rows run north to south.
        for (k, pair) in body[8..].chunks_exact(2).enumerate() {
            let v = u16::from_be_bytes([pair[0], pair[1]]);
            let magnitude = (v & 0x7FFF) as f32;
            let height = if v == VOID {
                f32::NAN
            } else if v & 0x8000 == 0 {
                magnitude
            } else if magnitude <= 16_000.0 {
                -magnitude
            } else {
                return Err(format_err(
                    source,
                    at(8 + 2 * k),
                    format!(
                        "a signed-magnitude height (bit 15 the sign) or the void −32767, found \
                         {v:#06x} = −{magnitude} m: the file looks like two's complement, which \
                         MIL-PRF-89020B does not allow"
                    ),
                ));
            };
            let row = h as usize - 1 - k;
            heights[row * w as usize + col] = height;
        }
    }
    let tenths = 36_000.0;
    let georef = Georef {
        crs: CrsKind::Geographic,
        epsg: Some(4326),
        origin_x: cell.lon0 as f64 / tenths,
        // Whole tenths of a second: exact for a whole-degree cell (45° N, not 45° − an ulp).
        origin_y: (cell.lat0 + (h as i64 - 1) * cell.dlat) as f64 / tenths,
        dx: cell.dlon as f64 / tenths,
        dy: -(cell.dlat as f64) / tenths,
    };
    Grid::new(source, w, h, heights, georef)
}

/// ASCII digits `bytes[at..at + len]` as a number, or an error naming the field.
fn digits(
    bytes: &[u8],
    at: usize,
    len: usize,
    source: &str,
    what: &str,
) -> Result<i64, TerrainError> {
    let field = &bytes[at..at + len];
    if field.iter().all(u8::is_ascii_digit) {
        Ok(field.iter().fold(0i64, |n, &d| n * 10 + (d - b'0') as i64))
    } else {
        Err(format_err(
            source,
            format!("byte {at}"),
            format!(
                "{what} as {len} ASCII digits, found {:?}",
                String::from_utf8_lossy(field)
            ),
        ))
    }
}

/// Which coordinate an angle field holds: its hemisphere letters and its largest value.
#[derive(Clone, Copy)]
enum Axis {
    Longitude,
    Latitude,
}

/// An angle `D..DMMSS[.S]H` at `at` (`deg` degree digits, a tenth's digit when `tenth`) in
/// tenths of an arc second, signed by its hemisphere letter (E/W, N/S), at most 180° or 90°.
fn angle(
    bytes: &[u8],
    at: usize,
    deg: usize,
    tenth: bool,
    axis: Axis,
    source: &str,
    what: &str,
) -> Result<i64, TerrainError> {
    let ((pos, neg), limit) = match axis {
        Axis::Longitude => ((b'E', b'W'), 180),
        Axis::Latitude => ((b'N', b'S'), 90),
    };
    let len = deg + 4 + if tenth { 2 } else { 0 } + 1;
    let field = &bytes[at..at + len];
    let shape = format!("{}MMSS{}H", "D".repeat(deg), if tenth { ".S" } else { "" });
    let bad = || {
        format_err(
            source,
            format!("byte {at}"),
            format!(
                "{what} as {shape} (degrees, minutes < 60, seconds < 60, hemisphere {}/{}, at \
                 most {limit}°), found {:?}",
                pos as char,
                neg as char,
                String::from_utf8_lossy(field)
            ),
        )
    };
    let num = |a: usize, n: usize| digits(bytes, at + a, n, source, what).map_err(|_| bad());
    let (d, m, s) = (num(0, deg)?, num(deg, 2)?, num(deg + 2, 2)?);
    let t = if tenth {
        if field[deg + 4] != b'.' {
            return Err(bad());
        }
        num(deg + 5, 1)?
    } else {
        0
    };
    let sign = match field[len - 1] {
        c if c == pos => 1,
        c if c == neg => -1,
        _ => return Err(bad()),
    };
    let value = d * 36_000 + m * 600 + s * 10 + t;
    if m >= 60 || s >= 60 || value > limit * 36_000 {
        return Err(bad());
    }
    Ok(sign * value)
}

/// Parse and cross-check the UHL and DSI; check the ACC's sentinel.
fn headers(bytes: &[u8], source: &str) -> Result<Cell, TerrainError> {
    if bytes.len() < HEADER_LEN {
        return Err(format_err(
            source,
            format!("byte {}", bytes.len()),
            format!(
                "the {HEADER_LEN} bytes of the UHL, DSI and ACC headers, found a {}-byte file",
                bytes.len()
            ),
        ));
    }
    let labels = [
        (0, &b"UHL1"[..], "user header label"),
        (80, b"DSI", "data set identification"),
        (728, b"ACC", "accuracy description"),
    ];
    for (at, label, name) in labels {
        if &bytes[at..at + label.len()] != label {
            return Err(format_err(
                source,
                format!("byte {at}"),
                format!(
                    "{:?} (the DTED {name} header), found {:?}",
                    String::from_utf8_lossy(label),
                    String::from_utf8_lossy(&bytes[at..at + label.len()])
                ),
            ));
        }
    }
    let lon0 = angle(
        bytes,
        4,
        3,
        false,
        Axis::Longitude,
        source,
        "the origin's longitude",
    )?;
    let lat0 = angle(
        bytes,
        12,
        3,
        false,
        Axis::Latitude,
        source,
        "the origin's latitude",
    )?;
    let dlon = digits(
        bytes,
        20,
        4,
        source,
        "the longitude interval (tenths of a second)",
    )?;
    let dlat = digits(
        bytes,
        24,
        4,
        source,
        "the latitude interval (tenths of a second)",
    )?;
    let lines = digits(bytes, 47, 4, source, "the number of longitude lines")?;
    let points = digits(
        bytes,
        51,
        4,
        source,
        "the number of points per longitude line",
    )?;
    for (at, v, what) in [
        (20, dlon, "longitude interval"),
        (24, dlat, "latitude interval"),
    ] {
        if v == 0 {
            return Err(format_err(
                source,
                format!("byte {at}"),
                format!("a positive {what}, found 0"),
            ));
        }
    }
    // The DSI repeats the UHL's description: a digit damaged in one of them shows here rather
    // than as a grid misplaced or stretched. A blank DSI field (not digits) is not compared.
    let dsi = 80;
    let repeats = [
        (dsi + 273, dlat, 24, "latitude interval"),
        (dsi + 277, dlon, 20, "longitude interval"),
        (dsi + 281, points, 51, "number of latitude points"),
        (dsi + 285, lines, 47, "number of longitude lines"),
    ];
    for (at, uhl, uhl_at, what) in repeats {
        if let Ok(v) = digits(bytes, at, 4, source, what)
            && v != uhl
        {
            return Err(format_err(
                source,
                format!("byte {at}"),
                format!("the DSI's {what} equal to the UHL's (byte {uhl_at}: {uhl}), found {v}"),
            ));
        }
    }
    let origins = [
        (dsi + 185, 2, Axis::Latitude, lat0, 12, "latitude"),
        (dsi + 194, 3, Axis::Longitude, lon0, 4, "longitude"),
    ];
    for (at, deg, axis, uhl, uhl_at, what) in origins {
        let blank = !bytes[at].is_ascii_digit();
        if blank {
            continue;
        }
        let v = angle(
            bytes,
            at,
            deg,
            true,
            axis,
            source,
            &format!("the DSI's origin {what}"),
        )?;
        // The UHL gives whole seconds: within a second of the DSI's tenths.
        if (v - uhl).abs() >= 10 {
            return Err(format_err(
                source,
                format!("byte {at}"),
                format!(
                    "the DSI's origin {what} within a second of the UHL's (byte {uhl_at}: {}″), \
                     found {}″",
                    uhl as f64 / 10.0,
                    v as f64 / 10.0
                ),
            ));
        }
    }
    let (w, h) = (lines as u32, points as u32);
    // The cell must stay on the globe: its north edge at most 90° N, its east edge at most 180° E.
    let north = lat0 + (h as i64 - 1).max(0) * dlat;
    let east = lon0 + (w as i64 - 1).max(0) * dlon;
    if north > 90 * 36_000 || east > 180 * 36_000 {
        return Err(format_err(
            source,
            "byte 4",
            format!(
                "a cell on the globe, found one from {:.4}° {:.4}° to {:.4}° {:.4}° (origin, \
                 intervals and counts of the UHL)",
                lon0 as f64 / 36_000.0,
                lat0 as f64 / 36_000.0,
                east as f64 / 36_000.0,
                north as f64 / 36_000.0
            ),
        ));
    }
    Ok(Cell {
        lon0,
        lat0,
        dlon,
        dlat,
        lines: w,
        points: h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell of `w` lines of `h` points at 44° N 72° W, 30″ apart (level 0), heights from `f`
    /// (column, point from the south) as signed-magnitude words, with true checksums.
    fn cell(w: u32, h: u32, f: impl Fn(u32, u32) -> u16) -> Vec<u8> {
        let mut b = vec![b' '; HEADER_LEN];
        b[..80].copy_from_slice(&{
            let mut u = [b' '; 80];
            let text = b"UHL10720000W0440000N03000300NA  U  ";
            u[..text.len()].copy_from_slice(text);
            u[47..55].copy_from_slice(format!("{w:04}{h:04}").as_bytes());
            u
        });
        b[80..83].copy_from_slice(b"DSI");
        b[80 + 185..80 + 204].copy_from_slice(b"440000.0N0720000.0W");
        b[80 + 273..80 + 289].copy_from_slice(format!("03000300{h:04}{w:04}").as_bytes());
        b[728..731].copy_from_slice(b"ACC");
        for c in 0..w {
            let mut r = vec![0xAA, 0, 0, c as u8, 0, 0, 0, 0];
            r[4..6].copy_from_slice(&(c as u16).to_be_bytes());
            for k in 0..h {
                r.extend_from_slice(&f(c, k).to_be_bytes());
            }
            let sum: u32 = r.iter().map(|&x| x as u32).sum();
            r.extend_from_slice(&sum.to_be_bytes());
            b.extend_from_slice(&r);
        }
        b
    }

    #[test]
    fn signed_magnitude_void_and_orientation() {
        // Column c, point k from the south: 100·c + k, negative at (1, 0), void at (2, 2).
        let b = cell(3, 4, |c, k| match (c, k) {
            (1, 0) => 0x8000 | 428, // −428 m, the Dead Sea shore
            (2, 2) => VOID,
            _ => (100 * c + k) as u16,
        });
        let g = read_dted_bytes(&b, "t.dt0", Checksums::Verify).unwrap();
        assert_eq!((g.width(), g.height()), (3, 4));
        // Row 0 is the north edge: point 3.
        assert_eq!(g.at(0, 0), 3.0);
        assert_eq!(g.at(2, 3), 200.0);
        assert_eq!(g.at(1, 3), -428.0);
        assert!(g.at(2, 1).is_nan());
        let r = g.georef();
        assert_eq!((r.origin_x, r.dx), (-72.0, 300.0 / 36_000.0));
        assert_eq!(r.sample_xy(0.0, 3.0), (-72.0, 44.0));
        assert_eq!(r.origin_y, 44.025);
    }

    #[test]
    fn damage_is_named_by_record_and_byte() {
        let b = cell(3, 4, |c, k| (c + k) as u16);
        let record = 12 + 8;
        // A height changed under its checksum.
        let mut bad = b.clone();
        bad[HEADER_LEN + record + 9] ^= 1;
        let e = read_dted_bytes(&bad, "t.dt0", Checksums::Verify).unwrap_err();
        let want = format!("t.dt0: byte {}, record 1:", HEADER_LEN + 2 * record - 4);
        assert!(e.to_string().starts_with(&want), "{e}");
        assert!(e.to_string().contains("checksum"), "{e}");
        assert!(read_dted_bytes(&bad, "t.dt0", Checksums::Ignore).is_ok());
        // The sentinel.
        let mut bad = b.clone();
        bad[HEADER_LEN + 2 * record] = 0xAB;
        let e = read_dted_bytes(&bad, "t.dt0", Checksums::Ignore).unwrap_err();
        assert!(e.to_string().contains("0xAA, found 0xab"), "{e}");
        // A cut: the record it ends in.
        let e = read_dted_bytes(&b[..b.len() - 30], "t.dt0", Checksums::Verify).unwrap_err();
        assert!(e.to_string().contains("stops in record 1 of 3"), "{e}");
        // A UHL digit that the DSI contradicts.
        let mut bad = b.clone();
        bad[23] = b'1';
        let e = read_dted_bytes(&bad, "t.dt0", Checksums::Verify).unwrap_err();
        assert!(
            e.to_string().contains("byte 357") && e.to_string().contains("301"),
            "{e}"
        );
        // Two's complement −5.
        let tc = cell(
            3,
            4,
            |c, k| if (c, k) == (0, 1) { (-5i16) as u16 } else { 7 },
        );
        let e = read_dted_bytes(&tc, "t.dt0", Checksums::Verify).unwrap_err();
        assert!(e.to_string().contains("two's complement"), "{e}");
        assert!(
            e.to_string().contains(&format!("byte {}", HEADER_LEN + 10)),
            "{e}"
        );
    }
}

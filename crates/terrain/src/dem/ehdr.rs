//! ESRI `.hdr` labelled rasters: GridFloat (`.flt`, what the USGS National Map distributes 3DEP
//! elevation in, and ArcGIS's `Raster to Float`) and BIL (`.bil`, GTOPO30, SRTM30 and GDAL's
//! `EHdr` output), each a headerless file of samples with a text `.hdr` beside it and an optional
//! `.prj`.
//!
//! **Header** (`x.hdr`: one `KEY value` a line, keys case-insensitive, both spellings read):
//! - size: `ncols`/`NCOLS`, `nrows`/`NROWS`, `NBANDS` (1; a multi-band file is refused);
//! - samples: `NBITS` (8, 16, 32), `PIXELTYPE` (`FLOAT`, `SIGNEDINT`, `UNSIGNEDINT`),
//!   `byteorder`/`BYTEORDER` (`LSBFIRST` or `I`: little-endian; `MSBFIRST` or `M`: big-endian),
//!   `LAYOUT` (`BIL`, `BIP`, `BSQ`: the same with one band), `SKIPBYTES`, `BANDROWBYTES`,
//!   `TOTALROWBYTES` (the row stride), `BANDGAPBYTES` (moot with one band);
//! - georeference: GridFloat's `xllcorner`/`xllcenter`, `yllcorner`/`yllcenter` and `cellsize`
//!   (a corner is the outer corner of the lower-left cell, half a cell from its centre, as in
//!   the ESRI ASCII grid, [`super::asc`]), or BIL's `ULXMAP`, `ULYMAP` (the centre of the
//!   upper-left cell) with `XDIM`, `YDIM`; without any, ESRI's defaults (`ULXMAP` 0, `ULYMAP`
//!   `nrows − 1`, cells of 1);
//! - `NODATA_value`/`NODATA`: samples equal to it are no-data; float NaNs are no-data too.
//!
//! Other keys (statistics, colour keys) are passed over, as GDAL does; a key given twice is an
//! error naming both lines. Rows run north to south, row 0 the top.
//!
//! **Defaults where the header is silent** (GDAL 3.6's reading, checked with `gdalinfo` on
//! hand-written headers): `NBITS` is 32 for a `.flt` file and ESRI's 8 otherwise; without
//! `PIXELTYPE` a `.flt` file is 32-bit float, and integers are signed when `NODATA` is negative
//! and unsigned otherwise. One departure: a missing byte order with samples wider than a byte is
//! an error here, not big-endian as GDAL assumes (ESRI documents the writing machine's order
//! instead; the wrong guess would give plausible-looking garbage heights).
//!
//! **Coordinate system** (the `.prj` beside the data file, ESRI or OGC WKT 1, read as the
//! shapefile reader reads its `.prj`: WGS 84, ETRS89 and NAD83 degrees, their UTM zones, Web
//! Mercator; any other system is refused by name with the `gdalwarp -t_srs` hint). Without a
//! `.prj` the grid is `Local` (metres assumed), as GDAL reports no coordinate system for such a
//! file; guessing degrees because the extent fits ±180°, ±90° would also turn a small local
//! grid in metres into a grid hundreds of kilometres wide, so the `.prj` USGS and GDAL ship is
//! what says degrees.
//!
//! **Checks**: the header's numbers (named by line) and the data file's length against them
//! before a sample is read (a truncated file is an error naming the row it stops in; a longer
//! one, whose header would drop samples, is refused too).
//!
//! **Not read**: multi-band files (`gdal_translate -b 1 -of EHdr` picks a band), 1- and 4-bit
//! samples, ENVI `.hdr` files (a different header that begins with `ENVI`), `.clr` colour
//! tables, `.stx` statistics and `.rep` projection files.
//!
//! # References
//! - ESRI, *BIL, BIP, and BSQ raster files* (ArcGIS Desktop help, "Raster and image file
//!   formats"): the `.hdr` keywords and their defaults.
//! - ESRI, *Float to Raster* / *Raster to Float* (ArcGIS tool help): the GridFloat header.
//! - USGS, *National Elevation Dataset* GridFloat product description: `.flt`, `.hdr`, `.prj`.
//! - GDAL, *EHdr — ESRI .hdr Labelled* driver page (gdal.org/drivers/raster/ehdr.html):
//!   `PIXELTYPE`, `NBITS`, the `.prj`.

use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use crate::vector::LayerCrs;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// An ESRI `.hdr` raster held in memory: the header's text, the samples, the `.prj`'s text, and
/// the names errors give each.
#[derive(Clone, Copy, Debug)]
pub struct EhdrParts<'a> {
    pub header: &'a str,
    pub header_name: &'a str,
    pub data: &'a [u8],
    pub data_name: &'a str,
    /// The `.prj`'s text and name, when there is one.
    pub prj: Option<(&'a str, &'a str)>,
    /// The data file is a GridFloat `.flt`: 32-bit floats unless the header says otherwise.
    pub gridfloat: bool,
}

/// Read an ESRI `.hdr` raster: `path` is the data file (`x.flt`, `x.bil`) or its `x.hdr`.
pub fn read_ehdr(path: &Path) -> Result<Grid, TerrainError> {
    let (data_path, hdr_path) = parts_of(path)?;
    let header = std::fs::read(&hdr_path).map_err(io(&hdr_path))?;
    let header = String::from_utf8_lossy(&header);
    let prj_path = sibling(&data_path, "prj");
    let prj = match &prj_path {
        Some(p) => Some(std::fs::read(p).map_err(io(p))?),
        None => None,
    };
    let prj_text = prj.as_deref().map(String::from_utf8_lossy);
    let prj_name = prj_path.as_ref().map(|p| p.display().to_string());
    let data_name = data_path.display().to_string();
    let header_name = hdr_path.display().to_string();
    let gridfloat = has_extension(&data_path, "flt");
    // The header's sizes against the data file's length before the file is read.
    let h = parse_header(&header, &header_name, gridfloat)?;
    let len = std::fs::metadata(&data_path).map_err(io(&data_path))?.len();
    h.check_length(len, &data_name)?;
    let data = std::fs::read(&data_path).map_err(io(&data_path))?;
    read_ehdr_parts(&EhdrParts {
        header: &header,
        header_name: &header_name,
        data: &data,
        data_name: &data_name,
        prj: prj_text.as_deref().zip(prj_name.as_deref()),
        gridfloat,
    })
}

/// The system a `.prj` (ESRI or OGC WKT 1, named `name`) gives a grid beside it.
pub(crate) fn crs_of_prj(wkt: &str, name: &str) -> Result<(CrsKind, Option<u16>), TerrainError> {
    Ok(
        match crate::shapefile::crs_of_wkt(wkt, "gdalwarp")
            .map_err(|e| format_err(name, "the system", e))?
        {
            LayerCrs::Lonlat => (CrsKind::Geographic, Some(4326)),
            LayerCrs::Epsg(code, _) => (CrsKind::Projected, Some(code)),
        },
    )
}

/// Decode an ESRI `.hdr` raster held in memory.
pub fn read_ehdr_parts(p: &EhdrParts) -> Result<Grid, TerrainError> {
    let h = parse_header(p.header, p.header_name, p.gridfloat)?;
    h.check_length(p.data.len() as u64, p.data_name)?;
    let (crs, epsg) = match p.prj {
        Some((wkt, name)) => crs_of_prj(wkt, name)?,
        None => (CrsKind::Local, None),
    };
    let georef = Georef {
        crs,
        epsg,
        ..h.georef
    };
    let (w, rows) = (h.ncols as usize, h.nrows as usize);
    let size = h.sample.bytes();
    let mut heights = Vec::with_capacity(w * rows);
    for r in 0..rows {
        let start = (h.skip + r as u64 * h.stride) as usize;
        let row = &p.data[start..start + w * size];
        heights.extend(
            row.chunks_exact(size)
                .map(|b| h.sample.decode(b, h.big_endian)),
        );
    }
    let float = matches!(h.sample, Sample::F32);
    Grid::from_samples(
        p.data_name,
        h.ncols as u32,
        h.nrows as u32,
        heights,
        h.nodata.filter(|v| !v.is_nan()),
        float,
        georef,
    )
}

/// The data file and the header of `path` (either one given).
fn parts_of(path: &Path) -> Result<(PathBuf, PathBuf), TerrainError> {
    let source = path.display().to_string();
    if has_extension(path, "hdr") {
        let data = ["flt", "bil"]
            .iter()
            .find_map(|e| sibling(path, e))
            .ok_or_else(|| {
                format_err(
                    &source,
                    "the data file",
                    "a .flt or .bil data file beside the header (the same name)",
                )
            })?;
        return Ok((data, path.to_path_buf()));
    }
    let hdr = sibling(path, "hdr").ok_or_else(|| {
        format_err(
            &source,
            "the header",
            format!(
                "a .hdr beside the data file ({}) describing its size, samples and place",
                path.with_extension("hdr").display()
            ),
        )
    })?;
    Ok((path.to_path_buf(), hdr))
}

/// `path` with extension `ext` in lower or upper case, if that file exists.
fn sibling(path: &Path, ext: &str) -> Option<PathBuf> {
    [ext.to_string(), ext.to_ascii_uppercase()]
        .iter()
        .map(|e| path.with_extension(e))
        .find(|p| p.is_file())
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// A sample type of the format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sample {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
}

impl Sample {
    fn bytes(self) -> usize {
        match self {
            Sample::U8 | Sample::I8 => 1,
            Sample::U16 | Sample::I16 => 2,
            Sample::U32 | Sample::I32 | Sample::F32 => 4,
        }
    }

    fn decode(self, b: &[u8], big: bool) -> f32 {
        let two = |b: &[u8]| if big { [b[0], b[1]] } else { [b[1], b[0]] };
        let four = |b: &[u8]| {
            if big {
                [b[0], b[1], b[2], b[3]]
            } else {
                [b[3], b[2], b[1], b[0]]
            }
        };
        match self {
            Sample::U8 => b[0] as f32,
            Sample::I8 => b[0] as i8 as f32,
            Sample::U16 => u16::from_be_bytes(two(b)) as f32,
            Sample::I16 => i16::from_be_bytes(two(b)) as f32,
            Sample::U32 => u32::from_be_bytes(four(b)) as f32,
            Sample::I32 => i32::from_be_bytes(four(b)) as f32,
            Sample::F32 => f32::from_be_bytes(four(b)),
        }
    }
}

/// What the header says, checked.
#[derive(Debug)]
struct Header {
    ncols: u64,
    nrows: u64,
    sample: Sample,
    big_endian: bool,
    skip: u64,
    /// Bytes from one row's start to the next's.
    stride: u64,
    nodata: Option<f64>,
    /// The sample centres (the system comes from the `.prj`).
    georef: Georef,
}

impl Header {
    /// The data file's `len` against the rows the header describes: exactly `SKIPBYTES` plus
    /// `nrows` strides (the last row's padding may be absent).
    fn check_length(&self, len: u64, data: &str) -> Result<(), TerrainError> {
        let row = self.ncols * self.sample.bytes() as u64;
        let full = self.skip + self.nrows * self.stride;
        let trimmed = full - (self.stride - row);
        if len == full || len == trimmed {
            return Ok(());
        }
        let described = format!(
            "{} rows of {} {}-byte samples{}{} ({full} bytes)",
            self.nrows,
            self.ncols,
            self.sample.bytes(),
            if self.stride > row {
                format!(", {} bytes apart", self.stride)
            } else {
                String::new()
            },
            if self.skip > 0 {
                format!(" after {} skipped bytes", self.skip)
            } else {
                String::new()
            },
        );
        Err(format_err(
            data,
            format!("byte {len}"),
            if len < trimmed {
                let r = len.saturating_sub(self.skip) / self.stride;
                format!(
                    "{described} as the header says, found {len} bytes: the file stops in row {r}"
                )
            } else {
                format!(
                    "{described} as the header says, found {len} bytes: {} bytes more than its \
                     rows (a wrong ncols, nrows or NBITS?)",
                    len - full
                )
            },
        ))
    }
}

/// Parse and check the `.hdr` text; `gridfloat` for a `.flt` data file.
fn parse_header(text: &str, source: &str, gridfloat: bool) -> Result<Header, TerrainError> {
    let line_err = |n: usize, what: String| format_err(source, format!("line {}", n + 1), what);
    if text.lines().find(|l| !l.trim().is_empty()).map(str::trim) == Some("ENVI") {
        return Err(TerrainError::Unsupported {
            source: source.into(),
            what: "an ENVI header (ENVI .hdr rasters are not read: gdal_translate -of GTiff)"
                .into(),
        });
    }
    // Every line a key and a value; the keys read are kept with their line.
    const KEYS: [&str; 22] = [
        "ncols",
        "nrows",
        "nbands",
        "nbits",
        "pixeltype",
        "byteorder",
        "layout",
        "skipbytes",
        "bandrowbytes",
        "totalrowbytes",
        "bandgapbytes",
        "ulxmap",
        "ulymap",
        "xdim",
        "ydim",
        "xllcorner",
        "xllcenter",
        "yllcorner",
        "yllcenter",
        "cellsize",
        "nodata",
        "nodata_value",
    ];
    let mut keys: BTreeMap<&str, (usize, &str)> = BTreeMap::new();
    for (n, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(key) = it.next() else { continue };
        let lower = key.to_ascii_lowercase();
        let Some(&known) = KEYS.iter().find(|k| **k == lower) else {
            continue;
        };
        let value = it
            .next()
            .ok_or_else(|| line_err(n, format!("a value after {key}")))?;
        // NODATA and NODATA_value are one key spelled two ways.
        let canonical = if known == "nodata_value" {
            "nodata"
        } else {
            known
        };
        if let Some((first, _)) = keys.insert(canonical, (n, value)) {
            return Err(line_err(
                n,
                format!(
                    "each key once, found {key} again (first on line {})",
                    first + 1
                ),
            ));
        }
    }
    let whole = |k: &str| -> Result<Option<u64>, TerrainError> {
        let Some(&(n, v)) = keys.get(k) else {
            return Ok(None);
        };
        v.parse::<u64>()
            .map(Some)
            .map_err(|_| line_err(n, format!("a whole number ≥ 0 for {k}, got {v:?}")))
    };
    let number = |k: &str| -> Result<Option<f64>, TerrainError> {
        let Some(&(n, v)) = keys.get(k) else {
            return Ok(None);
        };
        match v.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(line_err(n, format!("a finite number for {k}, got {v:?}"))),
        }
    };
    let positive = |k: &str| -> Result<Option<f64>, TerrainError> {
        match number(k)? {
            Some(x) if x <= 0.0 => Err(line_err(
                keys[k].0,
                format!("a positive cell size for {k}, got {x}"),
            )),
            other => Ok(other),
        }
    };
    let word = |k: &str| keys.get(k).map(|&(n, v)| (n, v.to_ascii_uppercase()));
    let need = |k: &str, v: Option<u64>| {
        v.ok_or_else(|| {
            format_err(
                source,
                "header",
                format!("the {k} key (found no line with it)"),
            )
        })
    };
    let ncols = need("ncols", whole("ncols")?)?;
    let nrows = need("nrows", whole("nrows")?)?;
    check_size(source, ncols, nrows)?;
    if let Some(b) = whole("nbands")?
        && b != 1
    {
        return Err(TerrainError::Unsupported {
            source: source.into(),
            what: format!(
                "line {}: NBANDS {b} (an elevation grid has one band; gdal_translate -b 1 -of \
                 EHdr writes one)",
                keys["nbands"].0 + 1
            ),
        });
    }
    if let Some((n, v)) = word("layout")
        && !matches!(v.as_str(), "BIL" | "BIP" | "BSQ")
    {
        return Err(line_err(n, format!("LAYOUT BIL, BIP or BSQ, got {v:?}")));
    }
    let nodata = match keys.get("nodata") {
        Some(&(n, v)) => Some(
            v.parse::<f64>()
                .map_err(|_| line_err(n, format!("a number for the no-data value, got {v:?}")))?,
        ),
        None => None,
    };
    // The sample type: NBITS and PIXELTYPE, with GDAL's defaults (module docs).
    let pixeltype = word("pixeltype");
    if let Some((n, v)) = &pixeltype
        && !matches!(v.as_str(), "FLOAT" | "SIGNEDINT" | "UNSIGNEDINT")
    {
        return Err(line_err(
            *n,
            format!("PIXELTYPE FLOAT, SIGNEDINT or UNSIGNEDINT, got {v:?}"),
        ));
    }
    let float = match &pixeltype {
        Some((_, v)) => v == "FLOAT",
        None => gridfloat,
    };
    let nbits = whole("nbits")?.unwrap_or(if float { 32 } else { 8 });
    let signed = match &pixeltype {
        Some((_, v)) => v == "SIGNEDINT",
        None => nodata.is_some_and(|v| v < 0.0),
    };
    let at_nbits = keys.get("nbits").map_or(0, |&(n, _)| n);
    let sample = match (nbits, float, signed) {
        (32, true, _) => Sample::F32,
        (_, true, _) => {
            return Err(line_err(
                at_nbits,
                format!("NBITS 32 for float samples (GridFloat), got {nbits}"),
            ));
        }
        (8, _, false) => Sample::U8,
        (8, _, true) => Sample::I8,
        (16, _, false) => Sample::U16,
        (16, _, true) => Sample::I16,
        (32, _, false) => Sample::U32,
        (32, _, true) => Sample::I32,
        _ => {
            return Err(line_err(
                at_nbits,
                format!("NBITS 8, 16 or 32 (1- and 4-bit samples are not read), got {nbits}"),
            ));
        }
    };
    let big_endian = match word("byteorder") {
        Some((_, v)) if v == "I" || v == "LSBFIRST" => false,
        Some((_, v)) if v == "M" || v == "MSBFIRST" => true,
        Some((n, v)) => {
            return Err(line_err(
                n,
                format!("byte order LSBFIRST or I (little-endian), MSBFIRST or M, got {v:?}"),
            ));
        }
        None if sample.bytes() == 1 => false,
        None => {
            return Err(format_err(
                source,
                "header",
                format!(
                    "a byteorder line (LSBFIRST or MSBFIRST) for {}-byte samples: readers \
                     disagree on the default (GDAL takes MSBFIRST, ESRI the writing machine's)",
                    sample.bytes()
                ),
            ));
        }
    };
    // Row layout: bytes per row of samples, the stride, the bytes skipped first.
    let row = ncols * sample.bytes() as u64;
    // Row strides and the skip are bounded by what a file could hold (2^40 bytes a row, 2^50
    // skipped), so that no sum of them overflows.
    let bounded = |k: &str, least: u64, most: u64| -> Result<Option<u64>, TerrainError> {
        match whole(k)? {
            Some(v) if v < least || v > most => Err(line_err(
                keys[k].0,
                format!(
                    "{k} from {least} to {most} (a row holds {ncols} samples of {} bytes), got {v}",
                    sample.bytes()
                ),
            )),
            other => Ok(other),
        }
    };
    let band_row = bounded("bandrowbytes", row, 1 << 40)?;
    let stride = bounded("totalrowbytes", row, 1 << 40)?
        .or(band_row)
        .unwrap_or(row);
    let skip = bounded("skipbytes", 0, 1 << 50)?.unwrap_or(0);
    // Georeference: sample centres, from whichever convention the header uses.
    let dx = positive("xdim")?.or(positive("cellsize")?).unwrap_or(1.0);
    let dy = positive("ydim")?.or(positive("cellsize")?).unwrap_or(1.0);
    let half = |corner: Option<f64>, d: f64| corner.map(|c| c + 0.5 * d);
    let x0 = number("ulxmap")?
        .or(number("xllcenter")?)
        .or(half(number("xllcorner")?, dx))
        .unwrap_or(0.0);
    let top = (nrows - 1) as f64 * dy;
    let y0 = number("ulymap")?
        .or(number("yllcenter")?.map(|y| y + top))
        .or(half(number("yllcorner")?, dy).map(|y| y + top))
        .unwrap_or(top);
    Ok(Header {
        ncols,
        nrows,
        sample,
        big_endian,
        skip,
        stride,
        nodata,
        georef: Georef {
            crs: CrsKind::Local,
            epsg: None,
            origin_x: x0,
            origin_y: y0,
            dx,
            dy: -dy,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts<'a>(
        header: &'a str,
        data: &'a [u8],
        prj: Option<&'a str>,
        flt: bool,
    ) -> EhdrParts<'a> {
        EhdrParts {
            header,
            header_name: "t.hdr",
            data,
            data_name: if flt { "t.flt" } else { "t.bil" },
            prj: prj.map(|p| (p, "t.prj")),
            gridfloat: flt,
        }
    }

    #[test]
    fn gridfloat_corner_and_bil_centre_conventions_agree() {
        // 3 x 2 floats, little-endian, one no-data.
        let v = [1.0f32, 2.0, 3.0, 4.0, -9999.0, 6.0];
        let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let flt = "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 10\nNODATA_value -9999\nbyteorder LSBFIRST\n";
        let g = read_ehdr_parts(&parts(flt, &data, None, true)).unwrap();
        assert_eq!((g.georef().origin_x, g.georef().origin_y), (105.0, 215.0));
        assert_eq!(g.georef().crs, CrsKind::Local);
        assert!(g.at(1, 1).is_nan());
        assert_eq!(g.at(2, 1), 6.0);
        let bil = "NROWS 2\nNCOLS 3\nNBITS 32\nPIXELTYPE FLOAT\nBYTEORDER I\nLAYOUT BIL\nULXMAP 105\nULYMAP 215\nXDIM 10\nYDIM 10\nNODATA -9999\n";
        let b = read_ehdr_parts(&parts(bil, &data, None, false)).unwrap();
        assert_eq!(b.georef(), g.georef());
        let bits = |g: &Grid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&b), bits(&g));
    }

    #[test]
    fn integer_types_byte_orders_and_strides() {
        // Big-endian signed 16-bit, rows padded to 8 bytes, 4 bytes skipped.
        let mut data = vec![0xEE; 4];
        for row in [[-5i16, 7, 300], [1, -2, 3]] {
            for v in row {
                data.extend_from_slice(&v.to_be_bytes());
            }
            data.extend_from_slice(&[0, 0]);
        }
        let h = "NCOLS 3\nNROWS 2\nNBITS 16\nPIXELTYPE SIGNEDINT\nBYTEORDER M\nSKIPBYTES 4\nTOTALROWBYTES 8\n";
        let g = read_ehdr_parts(&parts(h, &data, None, false)).unwrap();
        assert_eq!(g.heights(), &[-5.0, 7.0, 300.0, 1.0, -2.0, 3.0]);
        // The last row's padding may be absent.
        let g2 = read_ehdr_parts(&parts(h, &data[..data.len() - 2], None, false)).unwrap();
        assert_eq!(g2.heights(), g.heights());
        // Without PIXELTYPE, a negative NODATA makes the integers signed (GDAL's reading).
        let u = h.replace("PIXELTYPE SIGNEDINT\n", "");
        let g3 = read_ehdr_parts(&parts(&u, &data, None, false)).unwrap();
        assert_eq!(g3.at(0, 0), 65531.0);
        let s = format!("{u}NODATA -9999\n");
        assert_eq!(
            read_ehdr_parts(&parts(&s, &data, None, false))
                .unwrap()
                .at(0, 0),
            -5.0
        );
    }

    #[test]
    fn header_errors_name_the_line() {
        let data = [0u8; 16];
        // Lines after "ncols 2", "nrows 2" (lines 1 and 2); where the error is; what it says.
        let cases = [
            ("byteorder LSBFIRST\nnrows 3\n", "line 4", "first on line 2"),
            ("cellsize -1\nbyteorder I\n", "line 3", "positive"),
            ("nbits 12\nbyteorder I\n", "line 3", "NBITS 8, 16 or 32"),
            ("nbits 16\n", "header", "byteorder"),
            ("byteorder X\n", "line 3", "LSBFIRST"),
            ("nbits 16\nbyteorder I\n", "byte 16", "8 bytes more than"),
            (
                "nbits 16\nbyteorder I\nbandrowbytes 9999999999999\n",
                "line 5",
                "4 to",
            ),
            (
                "nbits 16\nbyteorder I\ntotalrowbytes 2\n",
                "line 5",
                "from 4 to",
            ),
        ];
        for (rest, at, what) in cases {
            let h = format!("ncols 2\nnrows 2\n{rest}");
            let flt = !h.contains("nbits");
            let e = read_ehdr_parts(&parts(&h, &data, None, flt))
                .unwrap_err()
                .to_string();
            assert!(e.contains(at) && e.contains(what), "{h:?}: {e}");
        }
        for (h, what) in [
            ("ncols 2\nnrows x\n", "line 2"),
            ("nrows 2\n", "the ncols key"),
        ] {
            let e = read_ehdr_parts(&parts(h, &data, None, true))
                .unwrap_err()
                .to_string();
            assert!(e.contains(what), "{h:?}: {e}");
        }
        // Cut data: the row it stops in; huge claims: refused before any allocation.
        let h = "ncols 2\nnrows 3\nbyteorder I\n";
        let e = read_ehdr_parts(&parts(h, &data, None, true)).unwrap_err();
        assert!(e.to_string().contains("stops in row 2"), "{e}");
        let h = "ncols 1000000000\nnrows 1000000000\nbyteorder I\n";
        let e = read_ehdr_parts(&parts(h, &data, None, true)).unwrap_err();
        assert!(matches!(e, TerrainError::BadSize { .. }), "{e}");
        let e = read_ehdr_parts(&parts("ENVI\nsamples = 2\n", &data, None, true)).unwrap_err();
        assert!(matches!(e, TerrainError::Unsupported { .. }), "{e}");
    }

    #[test]
    fn the_prj_names_the_system() {
        let data: Vec<u8> = [1.0f32; 4].iter().flat_map(|x| x.to_le_bytes()).collect();
        let h = "ncols 2\nnrows 2\nxllcorner 500000\nyllcorner 4900000\ncellsize 30\nbyteorder LSBFIRST\n";
        let utm = r#"PROJCS["WGS_1984_UTM_Zone_19N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]]],PROJECTION["Transverse_Mercator"],UNIT["Meter",1.0]]"#;
        let g = read_ehdr_parts(&parts(h, &data, Some(utm), true)).unwrap();
        assert_eq!(
            (g.georef().crs, g.georef().epsg),
            (CrsKind::Projected, Some(32619))
        );
        let lambert = r#"PROJCS["RGF93_Lambert_93",GEOGCS["GCS_RGF_1993"]]"#;
        let e = read_ehdr_parts(&parts(h, &data, Some(lambert), true)).unwrap_err();
        let e = e.to_string();
        assert!(
            e.starts_with("t.prj: ") && e.contains("gdalwarp -t_srs"),
            "{e}"
        );
    }
}

//! GDAL virtual rasters (`.vrt`), the XML that `gdalbuildvrt` and `gdal_translate -of VRT`
//! write, read as an elevation grid ([`read_vrt`]) or a band of rows at a time as an orthophoto
//! ([`crate::photo::VrtPhoto`]); and the mosaic that `terrain build --photo a.tif b.tif ...`
//! makes of several photos, laid out as `gdalbuildvrt` lays them ([`Vrt::mosaic`]).
//!
//! **What is read** (GDAL's VRT format, gdal.org/drivers/raster/vrt.html): a `VRTDataset` with
//! `rasterXSize` and `rasterYSize`, `SRS` (WKT, read as a `.prj` is read, [`super::ehdr`]; or
//! `EPSG:n`), `GeoTransform` (north up: its rotation terms 0) and `VRTRasterBand`s (`dataType`
//! Byte, Int8, UInt16, Int16, UInt32, Int32, UInt64, Int64, Float32 or Float64; `NoDataValue`;
//! `ColorInterp` Alpha marks a photo's alpha band) made of `SimpleSource` and `ComplexSource`
//! elements: `SourceFilename` (`relativeToVRT="1"`: beside the VRT; `"0"`: as written),
//! `SourceBand`, `SrcRect` and `DstRect` (by default the whole source, at the same place), and for
//! a complex source `NODATA`, `UseMaskBand`, `ScaleOffset` and `ScaleRatio`. A source is a
//! GeoTIFF (read a band of rows at a time, [`super::geotiff::RasterReader`]), another VRT (at most
//! [`MAX_DEPTH`] deep), for elevation any grid [`super::read_dem`] reads, for a photo a PNG or
//! JPEG (decoded whole, 8 bits). Metadata (`Metadata`, `Description`, `UnitType`, a band's
//! `Offset` and `Scale`, which GDAL does not apply to the values it reads either,
//! `SourceProperties`, `CategoryNames`, histograms, overviews) is passed over.
//!
//! **Compositing**, as GDAL's `VRTSourcedRasterBand` does it: band by band, sources in file
//! order, each writing the pixels of its `DstRect` from its `SrcRect`, so that a later source
//! wins where two overlap. A complex source leaves the pixels below it where its sample equals
//! its `NODATA`, and with `UseMaskBand` where its file's mask hides the pixel (the file's alpha
//! band, marked by TIFF `ExtraSamples` or `ColorInterp` Alpha, when it is 0; otherwise the file's
//! own no-data value, band by band). A scaled source writes `value · ScaleRatio + ScaleOffset`.
//! Every value written is converted to the band's type as GDAL converts it (through `f32`, or
//! `f64` for the 32- and 64-bit integer and Float64 bands; rounded half away from zero and
//! clamped for integer types). A source whose `SrcRect` and `DstRect` differ in size is
//! resampled by nearest neighbour, GDAL's default (any other `resampling` is refused):
//! destination pixel `x` reads source pixel
//! `⌊(x + ½ − DstRect.xOff) · SrcRect.xSize / DstRect.xSize + SrcRect.xOff⌋`, and the pixels a
//! `DstRect` covers are those whose centres lie in it.
//!
//! **Departures from GDAL**, both where GDAL invents a value: a pixel that no source writes is
//! no data here (no-data in a grid, transparent in a photo), where GDAL gives it the band's
//! `NoDataValue`, or 0 without one (a cliff to sea level in a terrain); and a sample its source
//! holds as no-data (NaN, or an elevation file's own no-data value) never covers what lies below
//! it, where a `SimpleSource` in GDAL copies the no-data value over it (`gdalbuildvrt` writes a
//! `ComplexSource` with `NODATA` for such files, which agrees).
//!
//! **Refused by name** (an error naming the file, the line, the element and what is read):
//! warped VRTs (`VRTWarpedDataset` and the other dataset subclasses), derived bands and pixel
//! functions (`VRTDerivedRasterBand`, `PixelFunctionType`), raw bands (`VRTRawRasterBand`),
//! `vrt://` and `/vsi...` source paths, `MaskBand`, GCPs, colour tables, look-up tables,
//! exponential scaling, averaged and kernel-filtered sources, `OpenOptions`, and any element this
//! list does not name.
//!
//! **Checks before anything is sized from the file**: the raster within [`super::MAX_SIDE`] a
//! side and [`super::MAX_SAMPLES`] in all, as every reader's grid; every source file opened (a
//! GeoTIFF's header only) and its band checked, its `SrcRect` inside it, its `DstRect` at most
//! [`MAX_ENLARGEMENT`] times its `SrcRect`; a VRT that reaches itself through its sources refused;
//! and the raster at most three times the box its sources' `DstRect`s cover on either axis, since
//! a size its data does not back (a 30000² raster around one 60 x 40 tile) is only a claim. A
//! grid is then allocated once, at the raster's size; a photo is read a band of rows at a time,
//! each source file opened when the rows first reach it and closed when they have passed it (an
//! elevation source other than a GeoTIFF or a VRT is read whole twice: once to check it, once
//! when its rows are reached).
//!
//! **Mosaics of photos** ([`Vrt::mosaic`]): the photos are laid on one lattice as
//! `gdalbuildvrt -addalpha` lays them: the first photo's coordinate system, the mean pixel size
//! of the photos in it (`-resolution average`) and the union of their extents; each photo is a
//! source at its place (nearest neighbour where it is off the lattice or of another pixel size,
//! as GDAL), later ones winning. A photo's pixel is not its coverage where its alpha band is 0
//! or where every band equals its no-data value (GDAL_NODATA 0 on an RGB photo marks black fill,
//! not black pixels). A photo in another system, which `gdalbuildvrt` skips, is reprojected onto
//! the lattice through [`crate::geodesy`] (the lattice transform a single photo's placement uses,
//! [`crate::gst`]) and sampled bilinearly from its covered pixels (a pixel is covered where its
//! covered neighbours hold at least half of the weight). Placing the mosaic on a grid in another
//! system resamples that photo a second time, so a photo in the grid's system is best listed
//! first.

use super::geotiff::{ChunkRows, RasterReader};
use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How deep VRTs may nest (a VRT whose sources are VRTs whose sources are...).
pub const MAX_DEPTH: usize = 8;
/// The most a source may be enlarged from its `SrcRect` to its `DstRect`, per axis.
pub const MAX_ENLARGEMENT: f64 = 256.0;
/// The per-chunk decode limit of GeoTIFF sources (bytes), as for photos.
const CHUNK_LIMIT: usize = 1 << 28;
/// Rows of a grid composited at a time.
const ROWS_AT_ONCE: u32 = 256;
/// What texmap reads of a VRT, for the errors that refuse the rest.
const WHAT_IS_READ: &str = "texmap reads VRTDataset rasters made of SimpleSource and \
    ComplexSource bands, as gdalbuildvrt and gdal_translate -of VRT write them; write this one \
    out first, e.g. gdal_translate in.vrt out.tif";

/// What a raster is read as: it decides how a source that is neither a GeoTIFF nor a VRT is
/// read, and whether a source's own no-data value covers what lies below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    /// Heights: other sources through [`super::read_dem`]; a file's no-data never covers.
    Elevation,
    /// An orthophoto: other sources are PNG or JPEG images.
    Photo,
}

/// A band's sample type (`dataType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataType {
    Byte,
    Int8,
    UInt16,
    Int16,
    UInt32,
    Int32,
    UInt64,
    Int64,
    Float32,
    Float64,
}

impl DataType {
    fn parse(s: &str) -> Option<DataType> {
        use DataType::*;
        Some(match s {
            "Byte" => Byte,
            "Int8" => Int8,
            "UInt16" => UInt16,
            "Int16" => Int16,
            "UInt32" => UInt32,
            "Int32" => Int32,
            "UInt64" => UInt64,
            "Int64" => Int64,
            "Float32" => Float32,
            "Float64" => Float64,
            _ => return None,
        })
    }

    /// `v` as GDAL stores it in a band of this type: through GDAL's working type (`f32`, or
    /// `f64` for 32- and 64-bit integers and Float64), then rounded half away from zero and
    /// clamped for integer types. NaN stays NaN.
    fn convert(self, v: f64) -> f32 {
        use DataType::*;
        let working = match self {
            UInt32 | Int32 | UInt64 | Int64 | Float64 => v,
            _ => v as f32 as f64,
        };
        let int = |lo: f64, hi: f64| working.round().clamp(lo, hi) as f32;
        match self {
            Byte => int(0.0, 255.0),
            Int8 => int(-128.0, 127.0),
            UInt16 => int(0.0, 65535.0),
            Int16 => int(-32768.0, 32767.0),
            UInt32 => int(0.0, u32::MAX as f64),
            Int32 => int(i32::MIN as f64, i32::MAX as f64),
            UInt64 => int(0.0, u64::MAX as f64),
            Int64 => int(i64::MIN as f64, i64::MAX as f64),
            Float32 | Float64 => working as f32,
        }
    }
}

/// A rectangle in pixels (`SrcRect`, `DstRect`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rect {
    x: f64,
    y: f64,
    w: f64,
    h: f64,
}

/// Which of a source's pixels it writes (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mask {
    /// `SimpleSource`, or a complex one without `NODATA` and `UseMaskBand`: every pixel.
    None,
    /// `NODATA`: not the samples equal to it.
    Value(f64),
    /// `UseMaskBand`: not where the file's alpha band is 0, or else its sample is the file's
    /// no-data value.
    Band,
    /// A photo of a mosaic: not where its alpha band is 0, or else every band is its no-data.
    Pixel,
}

/// A photo of a mosaic in another coordinate system: where each lattice pixel lies on it, and
/// the lattice pixels (columns, rows; ends excluded) it may cover.
#[derive(Debug)]
struct Warp {
    placement: crate::gst::Placement,
    cols: (u32, u32),
    rows: (u32, u32),
}

/// How a source's pixels land on the raster.
#[derive(Clone, Debug)]
enum Map {
    /// `SrcRect` to `DstRect`, by nearest neighbour where their sizes differ.
    Rect { src: Rect, dst: Rect },
    /// Reprojected and sampled bilinearly (a mosaic's photo in another system).
    Warp(Arc<Warp>),
}

/// One source of a band.
#[derive(Clone, Debug)]
struct Source {
    /// Index into [`Vrt::files`].
    file: usize,
    /// 0-based band of the file.
    band: u16,
    map: Map,
    mask: Mask,
    /// `(ScaleOffset, ScaleRatio)`.
    scale: Option<(f64, f64)>,
    /// A `resampling` other than nearest neighbour, refused if the source is resampled.
    resampling: Option<String>,
    /// Where it is written ("line 12, <ComplexSource>"), for errors.
    at: String,
}

/// A band of a VRT.
#[derive(Clone, Debug)]
pub struct Band {
    pub data_type: DataType,
    /// `NoDataValue`.
    pub nodata: Option<f64>,
    /// `ColorInterp` Alpha: the photo's alpha band.
    pub alpha: bool,
    sources: Vec<Source>,
}

/// How a source file is read.
#[derive(Clone, Debug)]
enum Kind {
    /// A GeoTIFF, by rows of chunks.
    Tiff,
    /// Another VRT, checked when this one was.
    Vrt(Box<Vrt>),
    /// A PNG or JPEG photo, decoded whole.
    Image,
    /// An elevation grid of another format, read whole.
    Grid,
}

/// A file the sources read, with what its header says.
#[derive(Clone, Debug)]
struct File {
    path: PathBuf,
    kind: Kind,
    width: u32,
    height: u32,
    band_count: u16,
    /// Its alpha band (0-based).
    alpha: Option<u16>,
    /// Its no-data value, per band.
    nodata: Vec<Option<f64>>,
    /// Every band 8 bits.
    byte: bool,
    /// The bands read from it (0-based, ascending): its sources' and the alpha band their masks
    /// need.
    read: Vec<u16>,
}

/// A virtual raster: a GDAL `.vrt` checked against its sources ([`Vrt::open`]), or a mosaic of
/// photos ([`Vrt::mosaic`]). Read it with a [`VrtReader`].
#[derive(Clone, Debug)]
pub struct Vrt {
    /// The file (or the mosaic's photos, `a.tif + b.tif`), for errors.
    pub source: String,
    pub width: u32,
    pub height: u32,
    /// `None` without a `GeoTransform`.
    pub georef: Option<Georef>,
    pub bands: Vec<Band>,
    files: Vec<File>,
    usage: Use,
    /// Where the `<VRTDataset>` element is ("line 1, <VRTDataset>"), for errors.
    root: String,
}

/// Read a VRT as an elevation grid: band 1, composited (see the module docs), its
/// `NoDataValue` and the pixels no source writes no-data; without a `GeoTransform` the grid is
/// local with 1 m between samples, as a GeoTIFF without one.
pub fn read_vrt(path: &Path) -> Result<Grid, TerrainError> {
    let vrt = Vrt::open(path, Use::Elevation)?;
    if vrt.bands.is_empty() {
        return Err(format_err(
            &vrt.source,
            &vrt.root,
            "at least one <VRTRasterBand>",
        ));
    }
    let (w, h) = (vrt.width, vrt.height);
    let nodata = vrt.bands[0].nodata.map(|v| v as f32);
    let georef = vrt.georef.unwrap_or(Georef::local(1.0));
    let source = vrt.source.clone();
    let mut reader = VrtReader::new(vrt, vec![0]);
    // Every source is checked: the raster's size is now backed by its data.
    let mut heights = Vec::with_capacity(w as usize * h as usize);
    for y in (0..h).step_by(ROWS_AT_ONCE as usize) {
        let mut rows = reader.rows(y, (y + ROWS_AT_ONCE).min(h))?;
        let mut band = rows.swap_remove(0);
        if let Some(nd) = nodata {
            for v in &mut band {
                if *v == nd {
                    *v = f32::NAN;
                }
            }
        }
        heights.extend_from_slice(&band);
    }
    Grid::new(&source, w, h, heights, georef)
}

/// Whether `path` is a VRT: by its extension (`.vrt`, any case) or its first element.
pub fn is_vrt(path: &Path) -> bool {
    use std::io::Read;
    if path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("vrt"))
    {
        return true;
    }
    let mut head = [0u8; 64];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .unwrap_or(0);
    let text = String::from_utf8_lossy(&head[..n]);
    text.trim_start().starts_with("<VRTDataset")
}

/// The place of `node` in the document: "line 12, <ComplexSource>".
fn at(doc: &roxmltree::Document, node: roxmltree::Node) -> String {
    let p = doc.text_pos_at(node.range().start);
    format!("line {}, <{}>", p.row, node.tag_name().name())
}

/// An element the reader does not read: refused by name.
fn refuse(
    name: &str,
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    what: &str,
) -> TerrainError {
    TerrainError::Unsupported {
        source: name.to_string(),
        what: format!("{}: {what}; {WHAT_IS_READ}", at(doc, node)),
    }
}

/// Parse `node`'s text as a number (NaN and infinities spelled `nan`, `inf` allowed only where
/// `finite` is false).
fn number(
    name: &str,
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    text: Option<&str>,
    finite: bool,
) -> Result<f64, TerrainError> {
    let t = text.unwrap_or("").trim();
    match t.parse::<f64>() {
        Ok(v) if !finite || v.is_finite() => Ok(v),
        _ => Err(format_err(
            name,
            at(doc, node),
            format!("a {}number, got {t:?}", if finite { "finite " } else { "" }),
        )),
    }
}

/// A rectangle from `xOff`, `yOff`, `xSize`, `ySize` (sizes > 0).
fn rect(
    name: &str,
    doc: &roxmltree::Document,
    node: roxmltree::Node,
) -> Result<Rect, TerrainError> {
    let get = |a: &str| number(name, doc, node, node.attribute(a), true);
    let r = Rect {
        x: get("xOff")?,
        y: get("yOff")?,
        w: get("xSize")?,
        h: get("ySize")?,
    };
    if r.w <= 0.0 || r.h <= 0.0 || r.x.abs() > 1e12 || r.y.abs() > 1e12 || r.w > 1e12 || r.h > 1e12
    {
        return Err(format_err(
            name,
            at(doc, node),
            format!(
                "sizes above 0 and offsets within 1e12 pixels, got xOff {} yOff {} xSize {} ySize {}",
                r.x, r.y, r.w, r.h
            ),
        ));
    }
    Ok(r)
}

/// The coordinate system `<SRS>` names: WKT as in a `.prj`, or `EPSG:n`.
fn crs_of_srs(text: &str, name: &str, place: &str) -> Result<(CrsKind, Option<u16>), TerrainError> {
    let t = text.trim();
    if let Some(code) = t
        .strip_prefix("EPSG:")
        .and_then(|c| c.trim().parse::<u32>().ok())
    {
        return match crate::vector::layer_crs_of_epsg(code) {
            Ok(crate::vector::LayerCrs::Lonlat) => Ok((CrsKind::Geographic, Some(4326))),
            Ok(crate::vector::LayerCrs::Epsg(e, _)) => Ok((CrsKind::Projected, Some(e))),
            Err(e) => Err(format_err(name, place, e)),
        };
    }
    super::ehdr::crs_of_prj(t, &format!("{name}: {place}"))
}

impl Vrt {
    /// Read and check the VRT at `path` (see the module docs): its XML, then every source file's
    /// header, band and rectangles.
    pub fn open(path: &Path, usage: Use) -> Result<Vrt, TerrainError> {
        let mut stack = Vec::new();
        Vrt::open_nested(path, usage, &mut stack)
    }

    /// Its bands (type, no-data, alpha, source count) and source files, for `terrain info`.
    pub fn summary(&self) -> serde_json::Value {
        serde_json::json!({
            "bands": self.bands.iter().map(|b| serde_json::json!({
                "data_type": format!("{:?}", b.data_type), "nodata": b.nodata, "alpha": b.alpha,
                "sources": b.sources.len(),
            })).collect::<Vec<_>>(),
            "files": self.files.iter().map(|f| f.path.display().to_string()).collect::<Vec<_>>(),
        })
    }

    /// [`Vrt::open`] within the VRTs `stack` is reading (canonical paths), which `path` must not
    /// be one of.
    fn open_nested(path: &Path, usage: Use, stack: &mut Vec<PathBuf>) -> Result<Vrt, TerrainError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(io(path))?;
        let text = std::str::from_utf8(&bytes).map_err(|e| {
            format_err(&name, format!("byte {}", e.valid_up_to()), "UTF-8 XML text")
        })?;
        let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let mut vrt = Vrt::parse(text, &name, &dir, usage)?;
        stack.push(std::fs::canonicalize(path).map_err(io(path))?);
        let checked = vrt.check(stack);
        stack.pop();
        checked?;
        Ok(vrt)
    }

    /// Parse VRT XML named `name` whose relative source paths are below `dir`; no file is
    /// opened.
    fn parse(text: &str, name: &str, dir: &Path, usage: Use) -> Result<Vrt, TerrainError> {
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let p = e.pos();
            format_err(
                name,
                format!("line {}, column {}", p.row, p.col),
                format!("well-formed XML ({e})"),
            )
        })?;
        let root = doc.root_element();
        if root.tag_name().name() != "VRTDataset" {
            return Err(format_err(
                name,
                at(&doc, root),
                "a <VRTDataset> document (a GDAL virtual raster)",
            ));
        }
        if let Some(class) = root.attribute("subClass") {
            return Err(refuse(
                name,
                &doc,
                root,
                &format!("subClass=\"{class}\" (warped and other derived datasets)"),
            ));
        }
        let size = |a: &str| -> Result<u64, TerrainError> {
            let t = root.attribute(a).unwrap_or("").trim();
            t.parse::<u64>().map_err(|_| {
                format_err(
                    name,
                    at(&doc, root),
                    format!("{a}: a pixel count, got {t:?}"),
                )
            })
        };
        let (w, h) = (size("rasterXSize")?, size("rasterYSize")?);
        check_size(name, w, h).map_err(|e| {
            format_err(
                name,
                format!("{} rasterXSize, rasterYSize", at(&doc, root)),
                format!("a raster texmap holds ({e})"),
            )
        })?;
        let mut vrt = Vrt {
            source: name.to_string(),
            width: w as u32,
            height: h as u32,
            georef: None,
            bands: Vec::new(),
            files: Vec::new(),
            usage,
            root: at(&doc, root),
        };
        let (mut crs, mut transform) = ((CrsKind::Local, None), None);
        for node in root.children().filter(|n| n.is_element()) {
            match node.tag_name().name() {
                "SRS" => {
                    let t = node.text().unwrap_or("");
                    if !t.trim().is_empty() {
                        crs = crs_of_srs(t, name, &at(&doc, node))?;
                    }
                }
                "GeoTransform" => {
                    let parts: Vec<&str> = node.text().unwrap_or("").split(',').collect();
                    let gt = parts
                        .iter()
                        .map(|p| number(name, &doc, node, Some(p), true))
                        .collect::<Result<Vec<f64>, _>>()?;
                    if gt.len() != 6 || gt[1] == 0.0 || gt[5] == 0.0 {
                        return Err(format_err(
                            name,
                            at(&doc, node),
                            format!("six numbers with non-zero pixel sizes, got {gt:?}"),
                        ));
                    }
                    if gt[2] != 0.0 || gt[4] != 0.0 {
                        return Err(refuse(
                            name,
                            &doc,
                            node,
                            "a rotated or sheared raster (terms 3 and 5 not 0)",
                        ));
                    }
                    transform = Some(gt);
                }
                "VRTRasterBand" => {
                    let band = vrt.parse_band(&doc, node, dir)?;
                    vrt.bands.push(band);
                }
                "Metadata" | "Description" | "OverviewList" => {}
                "GCPList" => {
                    return Err(refuse(
                        name,
                        &doc,
                        node,
                        "ground control points (place it first, e.g. gdalwarp)",
                    ));
                }
                "MaskBand" => {
                    return Err(refuse(
                        name,
                        &doc,
                        node,
                        "a dataset mask band (an alpha band is read: gdalbuildvrt -addalpha)",
                    ));
                }
                other => {
                    return Err(refuse(name, &doc, node, &format!("the element <{other}>")));
                }
            }
        }
        vrt.georef = transform.map(|gt| Georef {
            crs: crs.0,
            epsg: crs.1,
            // The geotransform places pixel corners; a georeference, pixel centres.
            origin_x: gt[0] + 0.5 * gt[1],
            origin_y: gt[3] + 0.5 * gt[5],
            dx: gt[1],
            dy: gt[5],
        });
        Ok(vrt)
    }

    /// Parse a `<VRTRasterBand>`.
    fn parse_band(
        &mut self,
        doc: &roxmltree::Document,
        node: roxmltree::Node,
        dir: &Path,
    ) -> Result<Band, TerrainError> {
        let name = self.source.clone();
        let name = name.as_str();
        match node.attribute("subClass") {
            None | Some("VRTSourcedRasterBand") => {}
            Some(class) => {
                return Err(refuse(
                    name,
                    doc,
                    node,
                    &format!("subClass=\"{class}\" (derived bands, pixel functions and raw bands)"),
                ));
            }
        }
        let t = node.attribute("dataType").unwrap_or("Byte");
        let data_type = DataType::parse(t).ok_or_else(|| {
            refuse(
                name,
                doc,
                node,
                &format!(
                    "dataType=\"{t}\" (Byte, Int8, UInt16, Int16, UInt32, Int32, UInt64, Int64, \
                     Float32 and Float64 are read)"
                ),
            )
        })?;
        let mut band = Band {
            data_type,
            nodata: None,
            alpha: false,
            sources: Vec::new(),
        };
        for child in node.children().filter(|n| n.is_element()) {
            match child.tag_name().name() {
                "NoDataValue" => {
                    band.nodata = Some(number(name, doc, child, child.text(), false)?);
                }
                "ColorInterp" => {
                    band.alpha = child
                        .text()
                        .is_some_and(|t| t.trim().eq_ignore_ascii_case("alpha"));
                }
                "SimpleSource" | "ComplexSource" => {
                    let s = self.parse_source(doc, child, dir)?;
                    band.sources.push(s);
                }
                "Description" | "UnitType" | "Offset" | "Scale" | "Metadata" | "CategoryNames"
                | "Histograms" | "OverviewList" | "Overview" | "HideNoDataValue" => {}
                "ColorTable" => {
                    return Err(refuse(
                        name,
                        doc,
                        child,
                        "a colour table (expand it first, e.g. gdal_translate -expand rgb)",
                    ));
                }
                "MaskBand" => {
                    return Err(refuse(name, doc, child, "a band mask band"));
                }
                "PixelFunctionType"
                | "PixelFunctionLanguage"
                | "PixelFunctionCode"
                | "PixelFunctionArguments"
                | "SourceTransferType" => {
                    return Err(refuse(
                        name,
                        doc,
                        child,
                        "a pixel function (derived bands: VRTDerivedRasterBand)",
                    ));
                }
                other => {
                    return Err(refuse(
                        name,
                        doc,
                        child,
                        &format!("the element <{other}> in a band"),
                    ));
                }
            }
        }
        Ok(band)
    }

    /// Parse a `<SimpleSource>` or `<ComplexSource>`.
    fn parse_source(
        &mut self,
        doc: &roxmltree::Document,
        node: roxmltree::Node,
        dir: &Path,
    ) -> Result<Source, TerrainError> {
        let name = self.source.clone();
        let name = name.as_str();
        let complex = node.tag_name().name() == "ComplexSource";
        let (mut file, mut band, mut src, mut dst) = (None, 1u16, None, None);
        let (mut nodata, mut use_mask, mut offset, mut ratio) = (None, false, None, None);
        for child in node.children().filter(|n| n.is_element()) {
            let tag = child.tag_name().name();
            match tag {
                "SourceFilename" => {
                    let t = child.text().unwrap_or("").trim();
                    if t.is_empty() {
                        return Err(format_err(name, at(doc, child), "a file name"));
                    }
                    if t.starts_with("vrt://") || t.starts_with("/vsi") {
                        return Err(refuse(
                            name,
                            doc,
                            child,
                            &format!("the path {t:?} (vrt:// and /vsi... paths)"),
                        ));
                    }
                    let relative = child
                        .attribute("relativeToVRT")
                        .is_some_and(|r| r.trim() == "1");
                    file = Some(if relative {
                        dir.join(t)
                    } else {
                        PathBuf::from(t)
                    });
                }
                "SourceBand" => {
                    let t = child.text().unwrap_or("").trim();
                    band = match t.parse::<u16>() {
                        Ok(b) if b >= 1 => b,
                        _ if t.starts_with("mask") => {
                            return Err(refuse(
                                name,
                                doc,
                                child,
                                &format!("the mask band {t:?} as a source"),
                            ));
                        }
                        _ => {
                            return Err(format_err(
                                name,
                                at(doc, child),
                                format!("a 1-based band number, got {t:?}"),
                            ));
                        }
                    };
                }
                "SourceProperties" => {}
                "SrcRect" => src = Some(rect(name, doc, child)?),
                "DstRect" => dst = Some(rect(name, doc, child)?),
                "NODATA" if complex => {
                    nodata = Some(number(name, doc, child, child.text(), false)?);
                }
                "UseMaskBand" if complex => {
                    use_mask = child
                        .text()
                        .is_some_and(|t| matches!(t.trim(), "true" | "1" | "TRUE" | "yes"));
                }
                "ScaleOffset" if complex => {
                    offset = Some(number(name, doc, child, child.text(), true)?);
                }
                "ScaleRatio" if complex => {
                    ratio = Some(number(name, doc, child, child.text(), true)?);
                }
                "LUT"
                | "ColorTableComponent"
                | "Exponent"
                | "SrcMin"
                | "SrcMax"
                | "DstMin"
                | "DstMax"
                | "OpenOptions" => {
                    return Err(refuse(
                        name,
                        doc,
                        child,
                        "look-up tables, colour table components, exponential scaling and open \
                         options",
                    ));
                }
                other => {
                    return Err(refuse(
                        name,
                        doc,
                        child,
                        &format!("the element <{other}> in a source"),
                    ));
                }
            }
        }
        let Some(path) = file else {
            return Err(format_err(name, at(doc, node), "a <SourceFilename>"));
        };
        // Without rectangles: the whole source at the same place (sized when it is opened).
        let unset = Rect {
            x: f64::NAN,
            y: f64::NAN,
            w: f64::NAN,
            h: f64::NAN,
        };
        let src = src.unwrap_or(unset);
        let dst = dst.unwrap_or(src);
        let resampling = node
            .attribute("resampling")
            .filter(|r| !r.eq_ignore_ascii_case("nearest"))
            .map(str::to_string);
        let file = match self.files.iter().position(|f| f.path == path) {
            Some(i) => i,
            None => {
                self.files.push(File {
                    path,
                    kind: Kind::Tiff,
                    width: 0,
                    height: 0,
                    band_count: 0,
                    alpha: None,
                    nodata: Vec::new(),
                    byte: true,
                    read: Vec::new(),
                });
                self.files.len() - 1
            }
        };
        let scale = match (offset, ratio) {
            (None, None) => None,
            (o, r) => Some((o.unwrap_or(0.0), r.unwrap_or(1.0))),
        };
        Ok(Source {
            file,
            band: band - 1,
            map: Map::Rect { src, dst },
            mask: match (nodata, use_mask) {
                (Some(v), _) => Mask::Value(v),
                (None, true) => Mask::Band,
                (None, false) => Mask::None,
            },
            scale,
            resampling,
            at: at(doc, node),
        })
    }

    /// Open every source file's header and check the sources against it (see the module docs).
    fn check(&mut self, stack: &mut Vec<PathBuf>) -> Result<(), TerrainError> {
        let name = self.source.clone();
        for i in 0..self.files.len() {
            let path = self.files[i].path.clone();
            let first = self
                .bands
                .iter()
                .flat_map(|b| &b.sources)
                .find(|s| s.file == i)
                .map_or(String::new(), |s| s.at.clone());
            let (file, _) = File::open(&path, self.usage, stack).map_err(|e| {
                format_err(
                    &name,
                    format!("{first}, <SourceFilename> {}", path.display()),
                    format!("a source texmap reads ({e})"),
                )
            })?;
            self.files[i] = file;
        }
        let mut boxed: Option<(f64, f64, f64, f64)> = None;
        for band in &mut self.bands {
            for s in &mut band.sources {
                let f = &self.files[s.file];
                let bad = |what: String| format_err(&name, s.at.clone(), what);
                if s.band >= f.band_count {
                    return Err(bad(format!(
                        "<SourceBand> {}: {} has {} band(s)",
                        s.band + 1,
                        f.path.display(),
                        f.band_count
                    )));
                }
                let Map::Rect { src, dst } = &mut s.map else {
                    continue;
                };
                let (fw, fh) = (f.width as f64, f.height as f64);
                if src.w.is_nan() {
                    *src = Rect {
                        x: 0.0,
                        y: 0.0,
                        w: fw,
                        h: fh,
                    };
                }
                if dst.w.is_nan() {
                    *dst = *src;
                }
                const SLACK: f64 = 1e-6;
                if src.x < -SLACK
                    || src.y < -SLACK
                    || src.x >= fw
                    || src.y >= fh
                    || src.x + src.w > fw + SLACK
                    || src.y + src.h > fh + SLACK
                {
                    return Err(bad(format!(
                        "a <SrcRect> inside the {fw} x {fh} pixels of {}, got xOff {} yOff {} \
                         xSize {} ySize {}",
                        f.path.display(),
                        src.x,
                        src.y,
                        src.w,
                        src.h
                    )));
                }
                // Inside the file to the last bit, so that every pixel read lies in it.
                (src.x, src.y) = (src.x.max(0.0), src.y.max(0.0));
                (src.w, src.h) = (src.w.min(fw - src.x), src.h.min(fh - src.y));
                if let Some(r) = &s.resampling
                    && (src.w != dst.w || src.h != dst.h)
                {
                    return Err(TerrainError::Unsupported {
                        source: name.clone(),
                        what: format!(
                            "{}: resampling=\"{r}\" (resampled sources are read by nearest \
                             neighbour); {WHAT_IS_READ}",
                            s.at
                        ),
                    });
                }
                if dst.w > MAX_ENLARGEMENT * src.w || dst.h > MAX_ENLARGEMENT * src.h {
                    return Err(bad(format!(
                        "a <DstRect> at most {MAX_ENLARGEMENT} times its <SrcRect>, got {} x {} \
                         from {} x {}",
                        dst.w, dst.h, src.w, src.h
                    )));
                }
                // The part of the raster this source covers.
                let (x0, y0) = (dst.x.max(0.0), dst.y.max(0.0));
                let x1 = (dst.x + dst.w).min(self.width as f64);
                let y1 = (dst.y + dst.h).min(self.height as f64);
                if x1 > x0 && y1 > y0 {
                    boxed = Some(match boxed {
                        None => (x0, y0, x1, y1),
                        Some(b) => (b.0.min(x0), b.1.min(y0), b.2.max(x1), b.3.max(y1)),
                    });
                }
            }
        }
        let (w, h) = (self.width as f64, self.height as f64);
        match boxed {
            None if self.bands.iter().any(|b| !b.sources.is_empty()) => {
                return Err(format_err(
                    &name,
                    format!("{} <DstRect>s", self.root),
                    format!("a source on the {w} x {h} raster, found none"),
                ));
            }
            Some((x0, y0, x1, y1)) if w > 3.0 * (x1 - x0) + 2.0 || h > 3.0 * (y1 - y0) + 2.0 => {
                return Err(format_err(
                    &name,
                    format!("{} rasterXSize, rasterYSize", self.root),
                    format!(
                        "a raster its sources back (at most three times the {:.0} x {:.0} \
                         pixels their DstRects cover on either axis), got {w} x {h}",
                        x1 - x0,
                        y1 - y0
                    ),
                ));
            }
            _ => {}
        }
        self.plan_reads();
        Ok(())
    }

    /// The bands each file is read for: its sources' and the alpha band their masks need.
    fn plan_reads(&mut self) {
        for f in &mut self.files {
            f.read.clear();
        }
        for s in self.bands.iter().flat_map(|b| &b.sources) {
            let f = &mut self.files[s.file];
            f.read.push(s.band);
            if matches!(s.mask, Mask::Band | Mask::Pixel)
                && let Some(a) = f.alpha
            {
                f.read.push(a);
            }
        }
        for f in &mut self.files {
            f.read.sort_unstable();
            f.read.dedup();
        }
    }

    /// The mosaic of `paths` as `gdalbuildvrt -addalpha` lays it out (see the module docs): three
    /// bands, each photo's `bands` (1-based; by default 1, 2, 3, or band 1 as grey), Byte when
    /// every photo is 8-bit and Float32 otherwise (for the stretch of wider samples).
    pub fn mosaic(paths: &[PathBuf], bands: Option<[u16; 3]>) -> Result<Vrt, TerrainError> {
        let source = paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" + ");
        let mut members = Vec::with_capacity(paths.len());
        for p in paths {
            let (f, georef) = File::open(p, Use::Photo, &mut Vec::new())?;
            let name = p.display().to_string();
            let Some(g) = georef else {
                return Err(TerrainError::Unsupported {
                    source: name,
                    what: "a photo without a georeference in a mosaic: each of several photos \
                           is placed by its own georeference (only a single photo is stretched \
                           over the grid)"
                        .into(),
                });
            };
            if !(g.dx > 0.0 && g.dy < 0.0) {
                return Err(TerrainError::Unsupported {
                    source: name,
                    what: format!(
                        "a photo whose rows do not run north to south (pixel size {} x {}) in a \
                         mosaic; warp it first, e.g. gdalwarp",
                        g.dx, g.dy
                    ),
                });
            }
            let pick = crate::photo::pick_bands(bands, f.band_count)?;
            if let Some(&b) = pick.iter().find(|&&b| b >= f.band_count) {
                return Err(TerrainError::Unsupported {
                    source: name,
                    what: format!("band {}: the photo has {} band(s)", b + 1, f.band_count),
                });
            }
            members.push((f, g, pick));
        }
        let Some((_, first, _)) = members.first() else {
            return Err(TerrainError::BadParameter {
                name: "photos",
                value: "none".into(),
                expected: "at least one photo",
            });
        };
        let first = *first;
        let same = |g: &Georef| g.crs == first.crs && g.epsg == first.epsg;
        let from = crate::geodesy::Placement::of(&first);
        // gdalbuildvrt's -resolution average over the photos in the first one's system.
        let alike: Vec<&Georef> = members.iter().map(|m| &m.1).filter(|g| same(g)).collect();
        let res_x = alike.iter().map(|g| g.dx).sum::<f64>() / alike.len() as f64;
        let res_y = alike.iter().map(|g| -g.dy).sum::<f64>() / alike.len() as f64;
        // Each photo's extent in the first one's system: (west, south, east, north).
        let mut extents = Vec::with_capacity(members.len());
        for (f, g, _) in &members {
            let (w, h) = (f.width as f64, f.height as f64);
            let corner = |c: f64, r: f64| g.sample_xy(c - 0.5, r - 0.5);
            let e = if same(g) {
                let (x0, y0) = corner(0.0, 0.0);
                let (x1, y1) = corner(w, h);
                (x0, y1, x1, y0)
            } else {
                let (Some(from), Some(to)) = (from, crate::geodesy::Placement::of(g)) else {
                    return Err(TerrainError::Unsupported {
                        source: f.path.display().to_string(),
                        what: format!(
                            "a photo in {} in a mosaic whose first photo is in {}: texmap \
                             reprojects between WGS 84 longitude/latitude, UTM (WGS 84, ETRS89, \
                             NAD83) and Web Mercator only; reproject it first, e.g. gdalwarp \
                             -t_srs {}",
                            crs_name(g),
                            crs_name(&first),
                            crs_name(&first)
                        ),
                    });
                };
                // The photo's outline, 16 points an edge, in the first photo's system.
                let mut e = (
                    f64::INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::NEG_INFINITY,
                );
                for k in 0..=16 {
                    let t = k as f64 / 16.0;
                    for (c, r) in [(t * w, 0.0), (t * w, h), (0.0, t * h), (w, t * h)] {
                        let (x, y) = corner(c, r);
                        let (lon, lat) = to.lonlat(x, y);
                        let (x, y) = from.xy(lon, lat);
                        e = (e.0.min(x), e.1.min(y), e.2.max(x), e.3.max(y));
                    }
                }
                e
            };
            if !(e.0.is_finite() && e.1.is_finite() && e.2.is_finite() && e.3.is_finite()) {
                return Err(format_err(
                    &f.path.display().to_string(),
                    "georeference",
                    format!("an extent in {}'s system", crs_name(&first)),
                ));
            }
            extents.push(e);
        }
        let (west, south, east, north) = extents.iter().fold(
            (
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ),
            |a, e| (a.0.min(e.0), a.1.min(e.1), a.2.max(e.2), a.3.max(e.3)),
        );
        let (w, h) = (
            (0.5 + (east - west) / res_x).floor(),
            (0.5 + (north - south) / res_y).floor(),
        );
        check_size(&source, w.max(0.0) as u64, h.max(0.0) as u64).map_err(|_| {
            TerrainError::Unsupported {
                source: source.clone(),
                what: format!(
                    "a mosaic of {w} x {h} pixels (the union of the photos' extents at the mean \
                     pixel size of those in the first one's system), beyond the 2 to {} pixels \
                     a side and {} in all a photo may have; do the photos cover one area?",
                    super::MAX_SIDE,
                    super::MAX_SAMPLES
                ),
            }
        })?;
        let (w, h) = (w as u32, h as u32);
        let georef = Georef {
            crs: first.crs,
            epsg: first.epsg,
            origin_x: west + 0.5 * res_x,
            origin_y: north - 0.5 * res_y,
            dx: res_x,
            dy: -res_y,
        };
        let data_type = if members.iter().all(|m| m.0.byte) {
            DataType::Byte
        } else {
            DataType::Float32
        };
        let mut vrt = Vrt {
            source,
            width: w,
            height: h,
            georef: Some(georef),
            bands: vec![
                Band {
                    data_type,
                    nodata: None,
                    alpha: false,
                    sources: Vec::new(),
                };
                3
            ],
            files: Vec::with_capacity(members.len()),
            usage: Use::Photo,
            root: "the mosaic".into(),
        };
        for (i, ((f, g, pick), e)) in members.into_iter().zip(extents).enumerate() {
            let at = f.path.display().to_string();
            let map = if same(&g) {
                let (fw, fh) = (f.width as f64, f.height as f64);
                Map::Rect {
                    src: Rect {
                        x: 0.0,
                        y: 0.0,
                        w: fw,
                        h: fh,
                    },
                    dst: Rect {
                        x: (e.0 - west) / res_x,
                        y: (north - e.3) / res_y,
                        w: fw * g.dx / res_x,
                        h: fh * -g.dy / res_y,
                    },
                }
            } else {
                let placement =
                    crate::gst::Placement::new((&georef, w, h), (f.width, f.height), Some(g), &at)?;
                let span = |a: f64, b: f64, n: u32| {
                    (
                        (a.floor().max(0.0) as u32).min(n),
                        (b.ceil().max(0.0) as u32).min(n),
                    )
                };
                Map::Warp(Arc::new(Warp {
                    placement,
                    cols: span((e.0 - west) / res_x - 1.0, (e.2 - west) / res_x + 1.0, w),
                    rows: span((north - e.3) / res_y - 1.0, (north - e.1) / res_y + 1.0, h),
                }))
            };
            for (k, band) in vrt.bands.iter_mut().enumerate() {
                band.sources.push(Source {
                    file: i,
                    band: pick[k],
                    map: map.clone(),
                    mask: Mask::Pixel,
                    scale: None,
                    resampling: None,
                    at: at.clone(),
                });
            }
            vrt.files.push(f);
        }
        vrt.plan_reads();
        Ok(vrt)
    }
}

fn crs_name(g: &Georef) -> String {
    match g.epsg {
        Some(e) => format!("EPSG:{e}"),
        None => format!("{:?}", g.crs).to_lowercase(),
    }
}

impl File {
    /// Open `path`'s header (see [`Kind`]): what it holds, and its georeference.
    fn open(
        path: &Path,
        usage: Use,
        stack: &mut Vec<PathBuf>,
    ) -> Result<(File, Option<Georef>), TerrainError> {
        let name = path.display().to_string();
        let file = |kind, width, height, band_count: u16, alpha, nodata, byte| File {
            path: path.to_path_buf(),
            kind,
            width,
            height,
            band_count,
            alpha,
            nodata: vec![nodata; band_count as usize],
            byte,
            read: Vec::new(),
        };
        if is_vrt(path) {
            let canonical = std::fs::canonicalize(path).map_err(io(path))?;
            if let Some(outer) = stack.iter().find(|p| **p == canonical) {
                return Err(format_err(
                    &name,
                    "the file",
                    format!(
                        "a source other than {}, a VRT being read (a VRT that references \
                         itself)",
                        outer.display()
                    ),
                ));
            }
            if stack.len() >= MAX_DEPTH {
                return Err(format_err(
                    &name,
                    "<SourceFilename>",
                    format!("VRTs nested at most {MAX_DEPTH} deep"),
                ));
            }
            let v = Vrt::open_nested(path, usage, stack)?;
            let mut f = file(
                Kind::Tiff,
                v.width,
                v.height,
                v.bands.len().min(u16::MAX as usize) as u16,
                v.bands.iter().position(|b| b.alpha).map(|a| a as u16),
                None,
                v.bands.iter().all(|b| b.data_type == DataType::Byte),
            );
            f.nodata = v.bands.iter().map(|b| b.nodata).collect();
            let georef = v.georef;
            f.kind = Kind::Vrt(Box::new(v));
            return Ok((f, georef));
        }
        if crate::photo::is_tiff(path) || usage == Use::Elevation && is_tiff_content(path) {
            let r = RasterReader::open(path, Some(&[0]), CHUNK_LIMIT)?;
            let f = file(
                Kind::Tiff,
                r.width,
                r.height,
                r.band_count,
                r.alpha,
                r.nodata,
                r.bits <= 8,
            );
            return Ok((f, r.georef));
        }
        match usage {
            Use::Photo => {
                let decoder = image::ImageReader::open(path)
                    .map_err(io(path))?
                    .with_guessed_format()
                    .map_err(io(path))?
                    .into_decoder()
                    .map_err(|e| {
                        format_err(&name, "image header", format!("a PNG or JPEG ({e})"))
                    })?;
                use image::ImageDecoder;
                let (w, h) = decoder.dimensions();
                check_size(&name, w as u64, h as u64)?;
                let channels = decoder.color_type().channel_count() as u16;
                let alpha = decoder.color_type().has_alpha().then_some(channels - 1);
                Ok((file(Kind::Image, w, h, channels, alpha, None, true), None))
            }
            Use::Elevation => {
                let g = super::read_dem(path, &super::ReadOptions::default())?;
                let f = file(Kind::Grid, g.width(), g.height(), 1, None, None, false);
                Ok((f, Some(*g.georef())))
            }
        }
    }
}

/// Whether `path` begins as a TIFF does (for an elevation source named without `.tif`).
fn is_tiff_content(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && matches!(&head, b"II*\0" | b"MM\0*" | b"II+\0" | b"MM\0+")
}

/// A source file opened for reading.
enum Opened {
    /// Its rows of chunks, as `f32` planes of the file's read bands at full width.
    Tiff(Box<ChunkRows<Vec<Vec<f32>>>>),
    /// The whole image, one plane per read band.
    Whole(Vec<Vec<f32>>),
    Vrt(Box<VrtReader>),
}

/// Planes of a window of a file: columns `x0..x0 + w`, rows `y0..`, one per read band.
struct Window {
    x0: u32,
    y0: u32,
    w: u32,
    planes: Vec<Vec<f32>>,
}

/// Reads a [`Vrt`]'s bands a band of rows at a time (see the module docs).
pub struct VrtReader {
    vrt: Vrt,
    /// The bands read (0-based; repeats allowed).
    want: Vec<usize>,
    open: Vec<Option<Opened>>,
    /// Per file, the raster row below the last one its sources write: it is closed once a
    /// request starts there.
    last_row: Vec<u32>,
}

/// The pixels `0..limit` whose centres lie in `[off, off + size)`.
fn span(off: f64, size: f64, limit: u32) -> (u32, u32) {
    let a = (off - 0.5).ceil().clamp(0.0, limit as f64);
    let b = (off + size - 0.5).ceil().clamp(0.0, limit as f64);
    (a as u32, (b as u32).max(a as u32))
}

/// The source pixel that destination pixel `d` reads (nearest neighbour, see the module docs),
/// within the source rectangle.
fn nearest(d: u32, src_off: f64, src_size: f64, dst_off: f64, dst_size: f64) -> u32 {
    let s = ((d as f64 + 0.5 - dst_off) * src_size / dst_size + src_off).floor();
    let lo = src_off.floor().max(0.0);
    let hi = ((src_off + src_size).ceil() - 1.0).max(lo);
    s.clamp(lo, hi) as u32
}

impl VrtReader {
    /// A reader of bands `want` (0-based, each below `vrt.bands.len()`).
    pub fn new(vrt: Vrt, want: Vec<usize>) -> VrtReader {
        let mut last_row = vec![0u32; vrt.files.len()];
        for &b in &want {
            for s in &vrt.bands[b].sources {
                let end = match &s.map {
                    Map::Rect { dst, .. } => span(dst.y, dst.h, vrt.height).1,
                    Map::Warp(w) => w.rows.1,
                };
                last_row[s.file] = last_row[s.file].max(end);
            }
        }
        let open = (0..vrt.files.len()).map(|_| None).collect();
        VrtReader {
            vrt,
            want,
            open,
            last_row,
        }
    }

    pub fn vrt(&self) -> &Vrt {
        &self.vrt
    }

    /// Rows `y0..y1` of the wanted bands, composited: one plane of `width · (y1 − y0)` samples
    /// per wanted band, NaN where no source writes.
    pub fn rows(&mut self, y0: u32, y1: u32) -> Result<Vec<Vec<f32>>, TerrainError> {
        let (w, h) = (self.vrt.width, self.vrt.height);
        let y1 = y1.min(h);
        let n = y1.saturating_sub(y0) as usize;
        let mut out = vec![vec![f32::NAN; w as usize * n]; self.want.len()];
        if n == 0 {
            return Ok(out);
        }
        // The window of each file that the sources over these rows read.
        let mut need: BTreeMap<usize, (u32, u32, u32, u32)> = BTreeMap::new();
        for &b in &self.want {
            for s in &self.vrt.bands[b].sources {
                if let Some((c0, r0, c1, r1)) = self.source_window(s, y0, y1) {
                    let e = need.entry(s.file).or_insert((c0, r0, c1, r1));
                    *e = (e.0.min(c0), e.1.min(r0), e.2.max(c1), e.3.max(r1));
                }
            }
        }
        let mut got = BTreeMap::new();
        for (&f, &(c0, r0, c1, r1)) in &need {
            got.insert(f, self.fetch(f, (c0, r0, c1, r1))?);
        }
        for (k, &b) in self.want.iter().enumerate() {
            let band = &self.vrt.bands[b];
            for s in &band.sources {
                if let Some(win) = got.get(&s.file) {
                    self.composite(s, band.data_type, win, &mut out[k], y0, y1);
                }
            }
        }
        // Files whose rows the requests have passed.
        for (slot, &last) in self.open.iter_mut().zip(&self.last_row) {
            if last <= y0 {
                *slot = None;
            }
        }
        Ok(out)
    }

    /// The window (columns `c0..c1`, rows `r0..r1`) of its file that source `s` reads for raster
    /// rows `y0..y1`, if it writes any of them.
    fn source_window(&self, s: &Source, y0: u32, y1: u32) -> Option<(u32, u32, u32, u32)> {
        let (w, h) = (self.vrt.width, self.vrt.height);
        match &s.map {
            Map::Rect { src, dst } => {
                let (c0, c1) = span(dst.x, dst.w, w);
                let (r0, r1) = span(dst.y, dst.h, h);
                let (r0, r1) = (r0.max(y0), r1.min(y1));
                if c0 >= c1 || r0 >= r1 {
                    return None;
                }
                let col = |c| nearest(c, src.x, src.w, dst.x, dst.w);
                let row = |r| nearest(r, src.y, src.h, dst.y, dst.h);
                Some((col(c0), row(r0), col(c1 - 1) + 1, row(r1 - 1) + 1))
            }
            Map::Warp(warp) => {
                let (r0, r1) = (warp.rows.0.max(y0), warp.rows.1.min(y1));
                if r0 >= r1 || warp.cols.0 >= warp.cols.1 {
                    return None;
                }
                let v = |r: u32| r as f64 / (h - 1).max(1) as f64;
                let (a, b) = warp.placement.rows_between(v(r0), v(r1 - 1))?;
                Some((0, a, self.vrt.files[s.file].width, b))
            }
        }
    }

    /// Read window `(c0, r0, c1, r1)` of file `f`, opening it if it is not open.
    fn fetch(
        &mut self,
        f: usize,
        (c0, r0, c1, r1): (u32, u32, u32, u32),
    ) -> Result<Window, TerrainError> {
        let file = &self.vrt.files[f];
        if self.open[f].is_none() {
            self.open[f] = Some(match &file.kind {
                Kind::Tiff => Opened::Tiff(Box::new(ChunkRows::new(RasterReader::open(
                    &file.path,
                    Some(&file.read),
                    CHUNK_LIMIT,
                )?))),
                Kind::Vrt(v) => Opened::Vrt(Box::new(VrtReader::new(
                    (**v).clone(),
                    file.read.iter().map(|&b| b as usize).collect(),
                ))),
                Kind::Image => Opened::Whole(image_planes(file)?),
                Kind::Grid => {
                    let g = super::read_dem(&file.path, &super::ReadOptions::default())?;
                    if (g.width(), g.height()) != (file.width, file.height) {
                        return Err(format_err(
                            &file.path.display().to_string(),
                            "size",
                            format!("{} x {} as when it was opened", file.width, file.height),
                        ));
                    }
                    Opened::Whole(vec![g.heights().to_vec()])
                }
            });
        }
        let (fw, bands) = (file.width as usize, file.read.len());
        let (ww, wh) = ((c1 - c0) as usize, (r1 - r0) as usize);
        let mut planes = vec![vec![0.0f32; ww * wh]; bands];
        // Copy rows `a..b` of full-width `src` planes whose first row is image row `top`.
        let mut copy = |src: &[Vec<f32>], top: u32, a: u32, b: u32| {
            for (dst, src) in planes.iter_mut().zip(src) {
                for y in a..b {
                    let s = (y - top) as usize * fw + c0 as usize;
                    let d = (y - r0) as usize * ww;
                    dst[d..d + ww].copy_from_slice(&src[s..s + ww]);
                }
            }
        };
        match self.open[f].as_mut().expect("opened above") {
            Opened::Tiff(rows) => {
                let height = file.height;
                let read = file.read.clone();
                rows.visit(
                    r0,
                    r1,
                    |reader, cr| decode_planes(reader, cr, read.len(), height),
                    |decoded, top| {
                        let end = top + (decoded[0].len() / fw.max(1)) as u32;
                        copy(decoded, top, r0.max(top), r1.min(end));
                    },
                )?;
            }
            Opened::Whole(whole) => copy(whole, 0, r0, r1),
            Opened::Vrt(inner) => {
                let got = inner.rows(r0, r1)?;
                copy(&got, r0, r0, r1);
            }
        }
        // A grid's own no-data never covers (see the module docs).
        if self.vrt.usage == Use::Elevation {
            for (plane, &b) in planes.iter_mut().zip(&file.read) {
                if let Some(nd) = file.nodata.get(b as usize).copied().flatten() {
                    let nd = nd as f32;
                    for v in plane.iter_mut() {
                        if *v == nd {
                            *v = f32::NAN;
                        }
                    }
                }
            }
        }
        Ok(Window {
            x0: c0,
            y0: r0,
            w: ww as u32,
            planes,
        })
    }

    /// Write source `s`'s pixels over rows `y0..y1` into `out` (band type `dt`) from its file's
    /// window `win`.
    fn composite(&self, s: &Source, dt: DataType, win: &Window, out: &mut [f32], y0: u32, y1: u32) {
        let file = &self.vrt.files[s.file];
        let plane = |b: u16| {
            file.read
                .iter()
                .position(|&r| r == b)
                .map(|i| &win.planes[i])
        };
        let Some(values) = plane(s.band) else {
            return;
        };
        let alpha = file.alpha.and_then(plane);
        let colours: Vec<&Vec<f32>> = file
            .read
            .iter()
            .zip(&win.planes)
            .filter(|(b, _)| Some(**b) != file.alpha)
            .map(|(_, p)| p)
            .collect();
        let band_nodata = file.nodata.get(s.band as usize).copied().flatten();
        let pixel_nodata = file.nodata.first().copied().flatten();
        // Whether the source hides its pixel `i` of the window (see `Mask`).
        let hidden = |i: usize| {
            let v = values[i];
            v.is_nan()
                || match s.mask {
                    Mask::None => false,
                    Mask::Value(nd) => v == nd as f32,
                    Mask::Band => match (alpha, band_nodata) {
                        (Some(a), _) => a[i] == 0.0,
                        (None, Some(nd)) => v == nd as f32,
                        (None, None) => false,
                    },
                    Mask::Pixel => match (alpha, pixel_nodata) {
                        (Some(a), _) => a[i] == 0.0,
                        (None, Some(nd)) => colours.iter().all(|p| p[i] == nd as f32),
                        (None, None) => false,
                    },
                }
        };
        let convert = |v: f32| {
            let v = match s.scale {
                Some((off, ratio)) => v as f64 * ratio + off,
                None => v as f64,
            };
            dt.convert(v)
        };
        let (w, h) = (self.vrt.width, self.vrt.height);
        let wu = w as usize;
        match &s.map {
            Map::Rect { src, dst } => {
                let (c0, c1) = span(dst.x, dst.w, w);
                let (r0, r1) = span(dst.y, dst.h, h);
                let cols: Vec<usize> = (c0..c1)
                    .map(|c| (nearest(c, src.x, src.w, dst.x, dst.w) - win.x0) as usize)
                    .collect();
                for r in r0.max(y0)..r1.min(y1) {
                    let sy = (nearest(r, src.y, src.h, dst.y, dst.h) - win.y0) as usize;
                    let base = sy * win.w as usize;
                    let line = &mut out[(r - y0) as usize * wu..][..wu];
                    for (c, &sx) in (c0..c1).zip(&cols) {
                        if !hidden(base + sx) {
                            line[c as usize] = convert(values[base + sx]);
                        }
                    }
                }
            }
            Map::Warp(warp) => {
                let (pw, ph) = (file.width as f64, file.height as f64);
                let rows = (win.planes[0].len() / win.w.max(1) as usize) as u32;
                let (iw, ih) = ((w - 1).max(1) as f64, (h - 1).max(1) as f64);
                for r in warp.rows.0.max(y0)..warp.rows.1.min(y1) {
                    let line = &mut out[(r - y0) as usize * wu..][..wu];
                    for c in warp.cols.0..warp.cols.1 {
                        let (x, y) = warp.placement.to_photo(c as f64 / iw, r as f64 / ih);
                        if !(x >= 0.0 && y >= 0.0 && x <= pw && y <= ph) {
                            continue;
                        }
                        // Bilinear over the covered neighbours (clamped at the photo's edges).
                        let (fx, fy) = (x - 0.5, y - 0.5);
                        let (x0, y0f) = (fx.floor(), fy.floor());
                        let (ax, ay) = (fx - x0, fy - y0f);
                        let (mut sum, mut weight) = (0.0f64, 0.0f64);
                        for (dx, dy, k) in [
                            (0, 0, (1.0 - ax) * (1.0 - ay)),
                            (1, 0, ax * (1.0 - ay)),
                            (0, 1, (1.0 - ax) * ay),
                            (1, 1, ax * ay),
                        ] {
                            let i = (x0 as i64 + dx).clamp(0, file.width as i64 - 1) as u32;
                            let j = (y0f as i64 + dy).clamp(0, file.height as i64 - 1) as u32;
                            if i < win.x0 || j < win.y0 || j - win.y0 >= rows {
                                continue;
                            }
                            let at = (j - win.y0) as usize * win.w as usize + (i - win.x0) as usize;
                            if k > 0.0 && !hidden(at) {
                                sum += k * values[at] as f64;
                                weight += k;
                            }
                        }
                        if weight >= 0.5 {
                            line[c as usize] = dt.convert(sum / weight);
                        }
                    }
                }
            }
        }
    }
}

/// Chunk row `cr` of `reader` as `bands` full-width `f32` planes (the reader's wanted bands).
fn decode_planes(
    reader: &mut RasterReader,
    cr: u32,
    bands: usize,
    height: u32,
) -> Result<Vec<Vec<f32>>, TerrainError> {
    let width = reader.width as usize;
    let top = cr * reader.chunk_rows();
    let rows = (top + reader.chunk_rows()).min(height) - top;
    let mut planes = vec![vec![0.0f32; width * rows as usize]; bands];
    reader.read_chunk_row(cr, |c| {
        for (dst, src) in planes.iter_mut().zip(&c.planes) {
            for row in 0..c.height as usize {
                let d = (c.y0 - top) as usize * width + row * width + c.x0 as usize;
                let s = row * c.width as usize;
                dst[d..d + c.width as usize].copy_from_slice(&src[s..s + c.width as usize]);
            }
        }
    })?;
    Ok(planes)
}

/// A PNG or JPEG photo's read bands, decoded whole (8 bits per channel).
fn image_planes(file: &File) -> Result<Vec<Vec<f32>>, TerrainError> {
    let name = file.path.display().to_string();
    let img = image::ImageReader::open(&file.path)
        .map_err(io(&file.path))?
        .with_guessed_format()
        .map_err(io(&file.path))?
        .decode()
        .map_err(|e| format_err(&name, "image data", format!("a PNG or JPEG ({e})")))?;
    if (img.width(), img.height()) == (file.width, file.height) {
        let channels = file.band_count as usize;
        let rgba = img.to_rgba8();
        // Channel of band b: grey (1), grey + alpha (2), RGB (3), RGBA (4).
        let channel = |b: u16| match (channels, b) {
            (1, _) | (2, 0) => 0,
            (2, _) => 3,
            (_, b) => b as usize,
        };
        Ok(file
            .read
            .iter()
            .map(|&b| rgba.pixels().map(|p| p.0[channel(b)] as f32).collect())
            .collect())
    } else {
        Err(format_err(
            &name,
            "size",
            format!("{} x {} as when it was opened", file.width, file.height),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_and_clamp_as_gdal() {
        assert_eq!(DataType::Byte.convert(2.5), 3.0);
        assert_eq!(DataType::Byte.convert(-0.4), 0.0);
        assert_eq!(DataType::Byte.convert(300.0), 255.0);
        assert_eq!(DataType::Int16.convert(-2.5), -3.0);
        assert_eq!(DataType::Int16.convert(1e9), 32767.0);
        assert_eq!(DataType::Float32.convert(0.1), 0.1f32);
        assert!(DataType::Int16.convert(f64::NAN).is_nan());
    }

    #[test]
    fn nearest_neighbour_reads_the_source_pixel_under_each_centre() {
        // 70 -> 35: every other pixel, from the second (GDAL: (i + ½)·2 = 2i + 1).
        assert_eq!(nearest(0, 0.0, 70.0, 0.0, 35.0), 1);
        assert_eq!(nearest(34, 0.0, 70.0, 0.0, 35.0), 69);
        // Same size, shifted: a copy.
        assert_eq!(nearest(150, 0.0, 170.0, 150.0, 170.0), 0);
        assert_eq!(nearest(319, 0.0, 170.0, 150.0, 170.0), 169);
        // Pixels whose centres lie in the rectangle.
        assert_eq!(span(150.0, 170.0, 320), (150, 320));
        assert_eq!(span(53.3, 10.0, 320), (53, 63));
        assert_eq!(span(-5.0, 10.0, 3), (0, 3));
    }
}

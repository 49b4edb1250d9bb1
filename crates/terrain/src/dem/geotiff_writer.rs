//! Writing a raster as a GeoTIFF that GDAL and our own reader ([`super::geotiff`]) read back with
//! the same georeference: 32-bit float samples (a [`Grid`], or heights computed from one) or bytes
//! (a visibility mask), Deflate-compressed in strips.
//!
//! The georeference is written as the reader interprets it (GeoTIFF 1.1, OGC 19-008):
//! - `ModelPixelScale` (33550) `(|dx|, |dy|, 0)` and `ModelTiepoint` (33922) tying raster point
//!   `(0, 0)`, the *corner* of pixel `(0, 0)`, to `origin − (dx, dy)/2`: `GTRasterTypeGeoKey` is
//!   `RasterPixelIsArea` (GDAL's default), so a pixel's centre is half a pixel in from its corner
//!   and [`Georef`]'s sample centres come back unchanged (up to one rounding of the half-pixel
//!   shift). A grid whose rows run south (`dy > 0`) or whose columns run west gets a
//!   `ModelTransformation` (34264) instead, which the scale + tie point pair cannot express.
//! - GeoKeys (34735): `GTModelTypeGeoKey` 1 (projected) or 2 (geographic);
//!   `ProjectedCSTypeGeoKey` (3072) with the EPSG code and `ProjLinearUnitsGeoKey` (3076) metres,
//!   or `GeographicTypeGeoKey` (2048) with the EPSG code (4326 when the grid knows none:
//!   geographic grids are taken as WGS 84, see [`crate::geodesy`]). A local grid gets only the
//!   raster type: GDAL reports no system, as for the file it came from.
//! - GDAL's no-data tag (42113, ASCII) when the caller gives a no-data value (`nan` for a float
//!   grid with holes, as GDAL writes it).
//!
//! The file is written under a temporary name beside the destination and renamed into place, so a
//! failure never leaves a partial file under the destination's name. Files over 4 GiB are BigTIFF.

use super::{CrsKind, Georef, Grid};
use crate::error::{TerrainError, io};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use tiff::encoder::compression::DeflateLevel;
use tiff::encoder::{
    Compression, Predictor, TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard, colortype,
};
use tiff::tags::Tag;

/// The samples of a raster to write, row-major.
#[derive(Clone, Copy, Debug)]
pub enum Samples<'a> {
    /// 32-bit floats (heights; `NaN` is no-data when the no-data value given is `NaN`).
    F32(&'a [f32]),
    /// Bytes (a mask).
    U8(&'a [u8]),
}

impl Samples<'_> {
    fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U8(v) => v.len(),
        }
    }

    fn bytes_per_sample(&self) -> u64 {
        match self {
            Samples::F32(_) => 4,
            Samples::U8(_) => 1,
        }
    }
}

/// Write `grid` as a float32 GeoTIFF, its holes as `NaN` with GDAL's no-data tag `nan` (no tag when
/// the grid has none).
pub fn write_grid(path: &Path, grid: &Grid) -> Result<(), TerrainError> {
    let nodata = (grid.nodata_count() > 0).then_some(f64::NAN);
    write_geotiff(
        path,
        grid.width(),
        grid.height(),
        Samples::F32(grid.heights()),
        grid.georef(),
        nodata,
    )
}

/// Write `width x height` samples placed by `georef` as a GeoTIFF at `path` (through a temporary
/// file renamed into place), with GDAL's no-data tag when `nodata` is given.
pub fn write_geotiff(
    path: &Path,
    width: u32,
    height: u32,
    samples: Samples,
    georef: &Georef,
    nodata: Option<f64>,
) -> Result<(), TerrainError> {
    let source = path.display().to_string();
    if width == 0 || height == 0 || samples.len() as u64 != width as u64 * height as u64 {
        return Err(TerrainError::BadParameter {
            name: "samples",
            value: format!("{} for {width} x {height}", samples.len()),
            expected: "width x height samples, at least one",
        });
    }
    let tags = GeoTags::of(georef, &source)?;
    let tmp = temp_beside(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(io(path))?;
        let mut out = std::io::BufWriter::new(file);
        // Classic TIFF offsets are 32-bit: leave a margin for the directory and the strip table
        // (Deflate never grows a strip by more than a few bytes per 64 KiB).
        let payload = samples.len() as u64 * samples.bytes_per_sample();
        if payload < (1u64 << 32) - (1 << 26) {
            let enc = TiffEncoder::<_, TiffKindStandard>::new_generic(&mut out);
            encode(enc, width, height, samples, &tags, nodata, &source)?;
        } else {
            let enc = TiffEncoder::<_, TiffKindBig>::new_generic(&mut out);
            encode(enc, width, height, samples, &tags, nodata, &source)?;
        }
        let file = out.into_inner().map_err(|e| TerrainError::Io {
            path: path.to_path_buf(),
            source: e.into_error(),
        })?;
        file.sync_all().map_err(io(path))?;
        std::fs::rename(&tmp, path).map_err(io(path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// `.NAME.partial-PID` beside `path`.
fn temp_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out.tif".into());
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// The georeference tags of one file, worked out before anything is written.
struct GeoTags {
    /// `ModelPixelScale` and `ModelTiepoint`, or a `ModelTransformation`.
    placement: Placement,
    keys: Vec<u16>,
}

enum Placement {
    ScaleTie([f64; 3], [f64; 6]),
    Transformation([f64; 16]),
}

impl GeoTags {
    fn of(g: &Georef, source: &str) -> Result<GeoTags, TerrainError> {
        let ok = [g.origin_x, g.origin_y, g.dx, g.dy]
            .iter()
            .all(|v| v.is_finite());
        if !ok || g.dx == 0.0 || g.dy == 0.0 {
            return Err(crate::error::format_err(
                source,
                "georeference",
                format!("finite origin and non-zero finite spacing, got {g:?}"),
            ));
        }
        // PixelIsArea: raster space counts pixel corners, so (0, 0) is half a pixel before the
        // centre of sample (0, 0).
        let (x0, y0) = (g.origin_x - 0.5 * g.dx, g.origin_y - 0.5 * g.dy);
        let placement = if g.dx > 0.0 && g.dy < 0.0 {
            Placement::ScaleTie([g.dx, -g.dy, 0.0], [0.0, 0.0, 0.0, x0, y0, 0.0])
        } else {
            Placement::Transformation([
                g.dx, 0.0, 0.0, x0, //
                0.0, g.dy, 0.0, y0, //
                0.0, 0.0, 0.0, 0.0, //
                0.0, 0.0, 0.0, 1.0,
            ])
        };
        // (KeyID, TIFFTagLocation 0 = inline, Count 1, Value), sorted by KeyID.
        let mut entries: Vec<[u16; 4]> = Vec::new();
        match g.crs {
            CrsKind::Projected => entries.push([1024, 0, 1, 1]),
            CrsKind::Geographic => entries.push([1024, 0, 1, 2]),
            CrsKind::Local => {}
        }
        entries.push([1025, 0, 1, 1]); // RasterPixelIsArea
        match g.crs {
            CrsKind::Geographic => entries.push([2048, 0, 1, g.epsg.unwrap_or(4326)]),
            CrsKind::Projected => {
                if let Some(code) = g.epsg {
                    entries.push([3072, 0, 1, code]);
                }
                entries.push([3076, 0, 1, 9001]); // metre
            }
            CrsKind::Local => {}
        }
        let mut keys = vec![1, 1, 0, entries.len() as u16];
        keys.extend(entries.iter().flatten());
        Ok(GeoTags { placement, keys })
    }
}

fn tiff_err(source: &str) -> impl Fn(tiff::TiffError) -> TerrainError + '_ {
    move |e| match e {
        tiff::TiffError::IoError(err) => TerrainError::Io {
            path: PathBuf::from(source),
            source: err,
        },
        other => TerrainError::Unsupported {
            source: source.to_string(),
            what: format!("writing the GeoTIFF: {other}"),
        },
    }
}

fn encode<W: Write + Seek, K: TiffKind>(
    enc: tiff::TiffResult<TiffEncoder<W, K>>,
    width: u32,
    height: u32,
    samples: Samples,
    tags: &GeoTags,
    nodata: Option<f64>,
    source: &str,
) -> Result<(), TerrainError> {
    let err = tiff_err(source);
    let enc = enc.map_err(&err)?;
    let mut enc = enc.with_compression(Compression::Deflate(DeflateLevel::Balanced));
    match samples {
        Samples::F32(v) => {
            let mut img = enc
                .new_image::<colortype::Gray32Float>(width, height)
                .map_err(&err)?;
            write_geo_tags(img.encoder(), tags, nodata).map_err(&err)?;
            img.write_data(v).map_err(&err)
        }
        Samples::U8(v) => {
            // Horizontal differencing makes long runs of one mask value runs of zeros.
            let mut enc = enc.with_predictor(Predictor::Horizontal);
            let mut img = enc
                .new_image::<colortype::Gray8>(width, height)
                .map_err(&err)?;
            write_geo_tags(img.encoder(), tags, nodata).map_err(&err)?;
            img.write_data(v).map_err(&err)
        }
    }
}

fn write_geo_tags<W: Write + Seek, K: TiffKind>(
    dir: &mut tiff::encoder::DirectoryEncoder<'_, W, K>,
    tags: &GeoTags,
    nodata: Option<f64>,
) -> tiff::TiffResult<()> {
    match &tags.placement {
        Placement::ScaleTie(scale, tie) => {
            dir.write_tag(Tag::ModelPixelScaleTag, &scale[..])?;
            dir.write_tag(Tag::ModelTiepointTag, &tie[..])?;
        }
        Placement::Transformation(m) => dir.write_tag(Tag::ModelTransformationTag, &m[..])?,
    }
    dir.write_tag(Tag::GeoKeyDirectoryTag, &tags.keys[..])?;
    if let Some(v) = nodata {
        let text = if v.is_nan() {
            "nan".to_string()
        } else {
            format!("{v}")
        };
        dir.write_tag(Tag::GdalNodata, text.as_str())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::geotiff::read_geotiff;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
    }

    #[test]
    fn south_up_and_local_grids_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        for georef in [
            Georef::local(2.5),
            Georef {
                crs: CrsKind::Projected,
                epsg: Some(32619),
                origin_x: 500_000.0,
                origin_y: 4_900_000.0,
                dx: 30.0,
                dy: 30.0, // rows run north: a ModelTransformation
            },
        ] {
            let h: Vec<f32> = (0..12).map(|i| i as f32 * 1.5).collect();
            let g = Grid::new("t", 4, 3, h, georef).unwrap();
            let p = dir.path().join("g.tif");
            write_grid(&p, &g).unwrap();
            let back = read_geotiff(&p).unwrap();
            assert_eq!(back.heights(), g.heights());
            let (a, b) = (back.georef(), g.georef());
            assert_eq!((a.crs, a.epsg), (b.crs, b.epsg));
            assert!(close(a.origin_x, b.origin_x) && close(a.origin_y, b.origin_y));
            assert!(a.dx == b.dx && a.dy == b.dy, "{a:?} vs {b:?}");
        }
        // Nothing is left beside the output.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/dir/g.tif");
        let g = Grid::new("t", 2, 2, vec![1.0; 4], Georef::local(1.0)).unwrap();
        let e = write_grid(&p, &g).unwrap_err();
        assert!(e.to_string().contains("g.tif"), "{e}");
        let bad = write_geotiff(
            &dir.path().join("m.tif"),
            3,
            3,
            Samples::U8(&[0; 8]),
            &Georef::local(1.0),
            None,
        );
        assert!(bad.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

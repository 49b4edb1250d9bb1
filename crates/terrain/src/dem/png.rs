//! PNG heightmaps and web-map elevation tiles.
//!
//! A 16-bit greyscale PNG stores `value`, and `height = scale · value + offset` with the scale and
//! offset the user states (the file cannot say). A Mapbox Terrain-RGB PNG stores
//! `height = −10000 + 0.1 · (R·256² + G·256 + B)` metres in 8-bit RGB (0.1 m steps); a Terrarium
//! PNG (the AWS Open Data "Terrain Tiles", Mapzen's encoding) stores
//! `height = R·256 + G + B/256 − 32768` metres (1/256 m steps). 8-bit greyscale PNGs are refused
//! for the 16-bit reader (256 levels are not an elevation model), greyscale and 16-bit images for
//! the RGB encodings.
//!
//! No PNG carries a georeference. A 16-bit PNG, and a Terrain-RGB or Terrarium image without a
//! tile address, is a `Local` grid with the stated cell size. A Terrain-RGB or Terrarium tile
//! with an address ([`TileAddress`]: the path's last three parts `Z/X/Y.png`, as web maps serve
//! and store them, or one given explicitly) is placed in Web Mercator (EPSG:3857) by the XYZ
//! scheme of OpenStreetMap, Mapbox, MapLibre and the AWS tiles: tile `(x, y)` of zoom `z` spans
//! `x·s − E ..= (x + 1)·s − E` east and `E − y·s ..= E − (y + 1)·s` north (y grows southwards),
//! `s = 2E / 2^z`, `E = 20037508.342789244` m (π times the WGS 84 semi-major axis). Pixels are
//! areas, as GDAL, rio-rgbify and the tile servers have them: the tile's bounds are the outer
//! edges of its `n x n` pixels, so sample centres sit half a pixel (`s / 2n`) inside. A tile of
//! `2^k + 1` pixels a side (martini's and MapLibre's "backfilled" tiles, one extra row and column
//! holding the neighbour's first or a copy of the last) is the `2^k` tile plus that row and column
//! one pixel beyond its east and south edges, on the same lattice: in a mosaic they overlap the
//! neighbours' first column and row, and the later file wins there (reported). Other sizes, and
//! non-square images, cannot be placed and are refused. With `tms` the address's y counts from
//! the south (the TMS scheme: `y_xyz = 2^z − 1 − y`).

use super::{CrsKind, Georef, Grid};
use crate::error::{TerrainError, format_err};
use std::path::Path;

fn open(path: &Path) -> Result<image::DynamicImage, TerrainError> {
    image::ImageReader::open(path)
        .map_err(crate::error::io(path))?
        .with_guessed_format()
        .map_err(crate::error::io(path))?
        .decode()
        .map_err(|e| {
            format_err(
                &path.display().to_string(),
                "PNG data",
                format!("a decodable image ({e})"),
            )
        })
}

fn check_cell(cell: f64) -> Result<(), TerrainError> {
    if cell.is_finite() && cell > 0.0 {
        Ok(())
    } else {
        Err(TerrainError::BadParameter {
            name: "cell",
            value: cell.to_string(),
            expected: "a positive cell size in metres",
        })
    }
}

/// Read a 16-bit greyscale PNG heightmap.
pub fn read_png16(path: &Path, scale: f64, offset: f64, cell: f64) -> Result<Grid, TerrainError> {
    check_cell(cell)?;
    if !(scale.is_finite() && scale != 0.0 && offset.is_finite()) {
        return Err(TerrainError::BadParameter {
            name: "scale/offset",
            value: format!("{scale}/{offset}"),
            expected: "finite values, scale non-zero",
        });
    }
    let source = path.display().to_string();
    let img = open(path)?;
    let luma = match img {
        image::DynamicImage::ImageLuma16(l) => l,
        other => {
            return Err(TerrainError::Unsupported {
                source,
                what: format!(
                    "PNG colour type {:?} (expected 16-bit greyscale; RGB elevation tiles are read as Terrain-RGB or Terrarium)",
                    other.color()
                ),
            });
        }
    };
    let (w, h) = luma.dimensions();
    let heights = luma
        .into_raw()
        .into_iter()
        .map(|v| (scale * v as f64 + offset) as f32)
        .collect();
    Grid::new(&source, w, h, heights, Georef::local(cell))
}

/// Decode one Terrain-RGB pixel: `−10000 + 0.1 · (R·65536 + G·256 + B)` metres.
pub fn terrain_rgb_height(r: u8, g: u8, b: u8) -> f64 {
    -10000.0 + 0.1 * ((r as u32) << 16 | (g as u32) << 8 | b as u32) as f64
}

/// Decode one Terrarium pixel: `R·256 + G + B/256 − 32768` metres.
pub fn terrarium_height(r: u8, g: u8, b: u8) -> f64 {
    r as f64 * 256.0 + g as f64 + b as f64 / 256.0 - 32768.0
}

/// Half the side of the Web Mercator square, metres: π · 6378137.
pub const WEB_MERCATOR_HALF: f64 = 20037508.342789244;

/// The deepest zoom accepted (2^30 tiles a side, 3.7 cm tiles: far beyond any elevation source).
pub const MAX_ZOOM: u8 = 30;

/// A web-map tile's address: zoom `z`, column `x` from the west, row `y` from the north (XYZ).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileAddress {
    pub z: u8,
    pub x: u32,
    pub y: u32,
}

impl TileAddress {
    /// A checked address: `z ≤ 30`, `x, y < 2^z`; `source` names the file in the error.
    pub fn new(source: &str, z: u64, x: u64, y: u64) -> Result<TileAddress, TerrainError> {
        let bad = |what: String| {
            Err(TerrainError::Unsupported {
                source: source.to_string(),
                what,
            })
        };
        if z > MAX_ZOOM as u64 {
            return bad(format!(
                "tile address {z}/{x}/{y}: zoom {z} is beyond {MAX_ZOOM}, the deepest zoom read"
            ));
        }
        let n = 1u64 << z;
        if x >= n || y >= n {
            return bad(format!(
                "tile address {z}/{x}/{y}: zoom {z} has columns and rows 0..={}, so {} is no tile",
                n - 1,
                if x >= n { "x" } else { "y" }
            ));
        }
        Ok(TileAddress {
            z: z as u8,
            x: x as u32,
            y: y as u32,
        })
    }

    /// Parse `Z/X/Y` (as given to `--tile`).
    pub fn parse(text: &str) -> Result<TileAddress, TerrainError> {
        let parts: Vec<&str> = text.trim().split('/').collect();
        let nums: Option<Vec<u64>> = match parts[..] {
            [z, x, y] => [z, x, y]
                .iter()
                .map(|t| {
                    (!t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()))
                        .then(|| t.parse::<u64>().ok())
                        .flatten()
                })
                .collect(),
            _ => None,
        };
        match nums.as_deref() {
            Some(&[z, x, y]) => TileAddress::new(text, z, x, y),
            _ => Err(TerrainError::BadParameter {
                name: "tile",
                value: text.to_string(),
                expected: "a tile address Z/X/Y of three whole numbers, e.g. 12/1205/1539",
            }),
        }
    }

    /// The address a path's last three parts spell, `.../Z/X/Y.png` (also `.pngraw` and `.webp`,
    /// the other names tile servers give these images): `None` when they are not three whole
    /// numbers, an error when they are but no tile has them (`x` or `y` ≥ 2^z, `z` > 30).
    pub fn from_path(path: &Path) -> Option<Result<TileAddress, TerrainError>> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        if !matches!(ext.as_str(), "png" | "pngraw" | "webp") {
            return None;
        }
        let num = |s: Option<&std::ffi::OsStr>| -> Option<u64> {
            let s = s?.to_str()?;
            if s.is_empty() || s.len() > 12 || !s.bytes().all(|b| b.is_ascii_digit()) {
                return None;
            }
            s.parse().ok()
        };
        let y = num(path.file_stem())?;
        let xdir = path.parent()?;
        let x = num(xdir.file_name())?;
        let z = num(xdir.parent()?.file_name())?;
        Some(TileAddress::new(&path.display().to_string(), z, x, y))
    }

    /// The same tile numbered from the south (TMS) instead of the north (XYZ), or back.
    pub fn flip_y(self) -> TileAddress {
        TileAddress {
            y: ((1u64 << self.z) - 1 - self.y as u64) as u32,
            ..self
        }
    }

    /// The tile's bounds in Web Mercator metres: `(west, south, east, north)`.
    pub fn bounds(&self) -> (f64, f64, f64, f64) {
        let s = self.side();
        (
            -WEB_MERCATOR_HALF + self.x as f64 * s,
            WEB_MERCATOR_HALF - (self.y as f64 + 1.0) * s,
            -WEB_MERCATOR_HALF + (self.x as f64 + 1.0) * s,
            WEB_MERCATOR_HALF - self.y as f64 * s,
        )
    }

    /// The tile's side in Web Mercator metres.
    pub fn side(&self) -> f64 {
        2.0 * WEB_MERCATOR_HALF / (1u64 << self.z) as f64
    }

    /// The georeference of a `width x height` image of this tile (see the module docs): `n x n`
    /// with `n` a power of two, or `n + 1` (backfilled).
    pub fn georef(&self, source: &str, width: u32, height: u32) -> Result<Georef, TerrainError> {
        let inner = if width.is_power_of_two() {
            width
        } else if width >= 3 && (width - 1).is_power_of_two() {
            width - 1
        } else {
            0
        };
        if width != height || inner == 0 {
            return Err(TerrainError::Unsupported {
                source: source.to_string(),
                what: format!(
                    "a {width} x {height} image as tile {}/{}/{}: a tile is n x n pixels with n a \
                     power of two (256, 512), or one more (257, 513: backfilled)",
                    self.z, self.x, self.y
                ),
            });
        }
        let (west, _, _, north) = self.bounds();
        let cell = self.side() / inner as f64;
        Ok(Georef {
            crs: CrsKind::Projected,
            epsg: Some(3857),
            origin_x: west + 0.5 * cell,
            origin_y: north - 0.5 * cell,
            dx: cell,
            dy: -cell,
        })
    }
}

/// Which RGB elevation encoding a tile uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RgbEncoding {
    /// Mapbox Terrain-RGB ([`terrain_rgb_height`]).
    TerrainRgb,
    /// Terrarium ([`terrarium_height`]).
    Terrarium,
}

impl RgbEncoding {
    fn name(self) -> &'static str {
        match self {
            RgbEncoding::TerrainRgb => "Terrain-RGB",
            RgbEncoding::Terrarium => "Terrarium",
        }
    }

    /// Decode one pixel.
    pub fn height(self, r: u8, g: u8, b: u8) -> f64 {
        match self {
            RgbEncoding::TerrainRgb => terrain_rgb_height(r, g, b),
            RgbEncoding::Terrarium => terrarium_height(r, g, b),
        }
    }
}

/// Heights no terrain reaches: below the Challenger Deep (−10,935 m) or above Everest
/// (8,849 m), with a margin.
const PLAUSIBLE: std::ops::RangeInclusive<f32> = -11_500.0..=9_000.0;

/// Refuses a tile most of whose heights no terrain reaches: the sign of a tile read in the other
/// encoding (a Terrarium tile read as Terrain-RGB decodes to ~840 km, a Terrain-RGB tile read as
/// Terrarium to ~−32 km), which would otherwise build a database of absurd heights.
fn check_plausible(
    source: &str,
    encoding: RgbEncoding,
    heights: &[f32],
) -> Result<(), TerrainError> {
    let outside = heights.iter().filter(|h| !PLAUSIBLE.contains(h)).count();
    if outside * 2 <= heights.len() {
        return Ok(());
    }
    let (lo, hi) = heights
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &h| {
            (a.min(h), b.max(h))
        });
    let other = match encoding {
        RgbEncoding::TerrainRgb => "a Terrarium tile (--terrarium)",
        RgbEncoding::Terrarium => "a Mapbox Terrain-RGB tile (--terrain-rgb)",
    };
    Err(format_err(
        source,
        format!(
            "{outside} of {} samples decode as {} to heights no terrain reaches ({lo} to {hi} m)",
            heights.len(),
            encoding.name()
        ),
        format!("heights between -11500 and 9000 m for most samples: is this {other}?"),
    ))
}

/// Read a Mapbox Terrain-RGB PNG as a `Local` grid with `cell` metres between samples.
pub fn read_terrain_rgb(path: &Path, cell: f64) -> Result<Grid, TerrainError> {
    read_rgb_tile(path, RgbEncoding::TerrainRgb, None, cell)
}

/// Read a Terrarium PNG as a `Local` grid with `cell` metres between samples.
pub fn read_terrarium(path: &Path, cell: f64) -> Result<Grid, TerrainError> {
    read_rgb_tile(path, RgbEncoding::Terrarium, None, cell)
}

/// Read a Terrain-RGB or Terrarium image: placed in Web Mercator by `tile` when given (see the
/// module docs), else a `Local` grid with `cell` metres between samples.
pub fn read_rgb_tile(
    path: &Path,
    encoding: RgbEncoding,
    tile: Option<TileAddress>,
    cell: f64,
) -> Result<Grid, TerrainError> {
    if tile.is_none() {
        check_cell(cell)?;
    }
    let source = path.display().to_string();
    let img = open(path)?;
    let rgb = match img {
        image::DynamicImage::ImageRgb8(i) => i,
        image::DynamicImage::ImageRgba8(_) => img.to_rgb8(),
        other => {
            return Err(TerrainError::Unsupported {
                source,
                what: format!(
                    "image colour type {:?} ({} is 8-bit RGB)",
                    other.color(),
                    encoding.name()
                ),
            });
        }
    };
    let (w, h) = rgb.dimensions();
    let georef = match tile {
        Some(t) => t.georef(&source, w, h)?,
        None => Georef::local(cell),
    };
    super::check_size(&source, w as u64, h as u64)?;
    let heights: Vec<f32> = rgb
        .pixels()
        .map(|p| encoding.height(p[0], p[1], p[2]) as f32)
        .collect();
    check_plausible(&source, encoding, &heights)?;
    Grid::new(&source, w, h, heights, georef)
}

/// The tile images under `dir` (its files `Z/X/Y.png`, `X/Y.png` under a zoom directory `Z`, or
/// `Y.png` under `Z/X`), in path order: how a directory given to `--dem` is read. Files whose
/// last three path parts are not a tile address are skipped; an error if there is none.
pub fn tiles_in_dir(dir: &Path) -> Result<Vec<std::path::PathBuf>, TerrainError> {
    let mut found = Vec::new();
    let mut todo = vec![(dir.to_path_buf(), 0u32)];
    while let Some((d, depth)) = todo.pop() {
        for entry in std::fs::read_dir(&d).map_err(crate::error::io(&d))? {
            let p = entry.map_err(crate::error::io(&d))?.path();
            if p.is_dir() {
                if depth < 2 {
                    todo.push((p, depth + 1));
                }
            } else if TileAddress::from_path(&p).is_some() {
                found.push(p);
            }
        }
    }
    if found.is_empty() {
        return Err(TerrainError::Unsupported {
            source: dir.display().to_string(),
            what: "a directory without tiles: expected Z/X/Y.png files (or X/Y.png under a zoom \
                   directory)"
                .into(),
        });
    }
    found.sort();
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terrain_rgb_formula() {
        // Mapbox's documented examples: RGB (1, 134, 160) = 0 m... (1·65536 + 134·256 + 160)·0.1 − 10000.
        assert!((terrain_rgb_height(1, 134, 160) - 0.0).abs() < 1e-9);
        assert_eq!(terrain_rgb_height(0, 0, 0), -10000.0);
    }

    #[test]
    fn terrarium_formula() {
        // (R·256 + G + B/256) − 32768: 0 m is (128, 0, 0); Mount Washington's 1916.5 m is
        // 34684.5 = 135·256 + 124 + 128/256.
        assert_eq!(terrarium_height(128, 0, 0), 0.0);
        assert_eq!(terrarium_height(135, 124, 128), 1916.5);
        assert_eq!(terrarium_height(0, 0, 0), -32768.0);
        assert_eq!(terrarium_height(127, 255, 192), -0.25);
    }

    #[test]
    fn a_tile_read_in_the_other_encoding_is_refused() {
        // A Terrarium tile of heights near 500 m (R 129, G 244) read as Terrain-RGB decodes to
        // ~840 km; read as Terrarium it is fine.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        image::RgbImage::from_pixel(4, 4, image::Rgb([129, 244, 0]))
            .save(&p)
            .unwrap();
        let g = read_terrarium(&p, 10.0).unwrap();
        assert_eq!(g.at(1, 1), 500.0);
        let e = read_terrain_rgb(&p, 10.0).unwrap_err().to_string();
        assert!(
            e.contains("16 of 16 samples") && e.contains("a Terrarium tile (--terrarium)"),
            "{e}"
        );
        // A Terrain-RGB tile at 0 m (1, 134, 160) read as Terrarium: about -32 km.
        image::RgbImage::from_pixel(4, 4, image::Rgb([1, 134, 160]))
            .save(&p)
            .unwrap();
        assert_eq!(read_terrain_rgb(&p, 10.0).unwrap().at(0, 0), 0.0);
        let e = read_terrarium(&p, 10.0).unwrap_err().to_string();
        assert!(e.contains("--terrain-rgb"), "{e}");
    }

    #[test]
    fn tile_addresses() {
        let p = |s: &str| TileAddress::from_path(Path::new(s));
        assert_eq!(
            p("tiles/12/1205/1539.png").unwrap().unwrap(),
            TileAddress {
                z: 12,
                x: 1205,
                y: 1539
            }
        );
        assert!(p("tiles/a/1205/1539.png").is_none());
        assert!(p("1205/1539.png").is_none());
        assert!(p("tiles/12/1205/1539.tif").is_none());
        assert!(p("tiles/2/4/1.png").unwrap().is_err());
        assert!(p("tiles/31/0/0.png").unwrap().is_err());
        assert!(p("tiles/99999999999999999999/0/0.png").is_none());
        assert!(TileAddress::parse("0/0/0").is_ok());
        assert!(TileAddress::parse("1/2/0").is_err());
        assert!(TileAddress::parse("1/-1/0").is_err());
        assert!(TileAddress::parse("1/1").is_err());
        let t = TileAddress::parse("1/1/0").unwrap();
        assert_eq!(t.bounds(), (0.0, 0.0, WEB_MERCATOR_HALF, WEB_MERCATOR_HALF));
        assert_eq!(t.flip_y().y, 1);
        let g = t.georef("t", 257, 257).unwrap();
        assert_eq!(g.dx, WEB_MERCATOR_HALF / 256.0);
        assert!(t.georef("t", 256, 255).is_err());
        assert!(t.georef("t", 300, 300).is_err());
    }

    #[test]
    fn png16_scale_offset_roundtrip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.png");
        let img = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(4, 3, |x, y| {
            image::Luma([(x * 1000 + y) as u16])
        });
        img.save(&p).unwrap();
        let g = read_png16(&p, 0.5, -100.0, 30.0).unwrap();
        assert_eq!((g.width(), g.height()), (4, 3));
        assert_eq!(g.at(3, 2), 0.5 * 3002.0 - 100.0);
        assert_eq!(g.georef().dx, 30.0);
        let rgb = image::RgbImage::new(2, 2);
        let p2 = dir.path().join("c.png");
        rgb.save(&p2).unwrap();
        assert!(matches!(
            read_png16(&p2, 1.0, 0.0, 1.0),
            Err(TerrainError::Unsupported { .. })
        ));
    }
}

//! PNG heightmaps. A 16-bit greyscale PNG stores `value`, and `height = scale · value + offset`
//! with the scale and offset the user states (the file cannot say). A Mapbox Terrain-RGB PNG stores
//! `height = −10000 + 0.1 · (R·256² + G·256 + B)` metres in 8-bit RGB. Neither carries a
//! georeference: the grid is `Local` with the stated cell size. 8-bit greyscale PNGs are refused
//! for the 16-bit reader (256 levels are not an elevation model).

use super::{Georef, Grid};
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
                    "PNG colour type {:?} (expected 16-bit greyscale; use the Terrain-RGB reader for RGB)",
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

/// Decode one Terrain-RGB pixel.
pub fn terrain_rgb_height(r: u8, g: u8, b: u8) -> f64 {
    -10000.0 + 0.1 * ((r as u32) << 16 | (g as u32) << 8 | b as u32) as f64
}

/// Read a Mapbox Terrain-RGB PNG.
pub fn read_terrain_rgb(path: &Path, cell: f64) -> Result<Grid, TerrainError> {
    check_cell(cell)?;
    let source = path.display().to_string();
    let img = open(path)?;
    let rgb = match img {
        image::DynamicImage::ImageRgb8(i) => i,
        image::DynamicImage::ImageRgba8(_) => img.to_rgb8(),
        other => {
            return Err(TerrainError::Unsupported {
                source,
                what: format!(
                    "PNG colour type {:?} (Terrain-RGB is 8-bit RGB)",
                    other.color()
                ),
            });
        }
    };
    let (w, h) = rgb.dimensions();
    let heights = rgb
        .pixels()
        .map(|p| terrain_rgb_height(p[0], p[1], p[2]) as f32)
        .collect();
    Grid::new(&source, w, h, heights, Georef::local(cell))
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

//! SRTM `.hgt` tiles: a square of big-endian `i16` heights in metres, 1201² (3 arc-seconds) or
//! 3601² (1 arc-second), north row first, void = −32768. The position is only in the file name:
//! `N35E138.hgt` is the 1° cell whose south-west corner is 35° N 138° E. Samples sit on the cell's
//! corners and edges (the edge rows and columns duplicate the neighbouring tiles'), so sample
//! (0, 0) is centred exactly on the north-west corner: the grid is geographic (WGS 84, EPSG:4326).

use super::{CrsKind, Georef, Grid};
use crate::error::{TerrainError, format_err, io};
use std::path::Path;

/// Read an SRTM `.hgt` tile; its position comes from the file name.
pub fn read_hgt(path: &Path) -> Result<Grid, TerrainError> {
    let source = path.display().to_string();
    // NASA's downloads add a product name (`N35E138.SRTMGL1.hgt`): the position is what comes
    // before the first dot.
    let name = path
        .file_name()
        .and_then(|s| s.to_str())
        .and_then(|s| s.split('.').next())
        .ok_or_else(|| format_err(&source, "file name", "a name like N35E138.hgt"))?;
    let (lat, lon) = parse_name(name).ok_or_else(|| {
        format_err(&source, "file name", format!("a name like N35E138.hgt (hemisphere letter, latitude, hemisphere letter, longitude), got {name:?}"))
    })?;
    let len = std::fs::metadata(path).map_err(io(path))?.len();
    let n: u32 = match len {
        2_884_802 => 1201,
        25_934_402 => 3601,
        _ => {
            return Err(format_err(
                &source,
                "file size",
                format!("2,884,802 bytes (1201² samples) or 25,934,402 (3601²), got {len}"),
            ));
        }
    };
    let bytes = std::fs::read(path).map_err(io(path))?;
    read_hgt_bytes(&bytes, n, lat, lon, &source)
}

/// Parse `N35E138` / `s01w072` into the south-west corner (lat, lon) in degrees.
pub fn parse_name(name: &str) -> Option<(i32, i32)> {
    let b = name.as_bytes();
    if b.len() != 7 {
        return None;
    }
    let lat: i32 = name.get(1..3)?.parse().ok()?;
    let lon: i32 = name.get(4..7)?.parse().ok()?;
    let lat = match b[0].to_ascii_uppercase() {
        b'N' => lat,
        b'S' => -lat,
        _ => return None,
    };
    let lon = match b[3].to_ascii_uppercase() {
        b'E' => lon,
        b'W' => -lon,
        _ => return None,
    };
    (lat.abs() <= 90 && lon.abs() <= 180).then_some((lat, lon))
}

/// Decode an `n x n` tile of big-endian `i16` whose south-west corner is (`lat`, `lon`).
pub fn read_hgt_bytes(
    bytes: &[u8],
    n: u32,
    lat: i32,
    lon: i32,
    source: &str,
) -> Result<Grid, TerrainError> {
    let count = n as usize * n as usize;
    if bytes.len() != 2 * count {
        return Err(format_err(
            source,
            "file size",
            format!("{} bytes for {n}² samples, got {}", 2 * count, bytes.len()),
        ));
    }
    let heights: Vec<f32> = bytes
        .chunks_exact(2)
        .map(|c| match i16::from_be_bytes([c[0], c[1]]) {
            -32768 => f32::NAN,
            v => v as f32,
        })
        .collect();
    let step = 1.0 / (n - 1) as f64;
    let georef = Georef {
        crs: CrsKind::Geographic,
        epsg: Some(4326),
        origin_x: lon as f64,
        origin_y: lat as f64 + 1.0,
        dx: step,
        dy: -step,
    };
    Grid::new(source, n, n, heights, georef)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(parse_name("N35E138"), Some((35, 138)));
        assert_eq!(parse_name("s01w072"), Some((-1, -72)));
        assert_eq!(parse_name("X35E138"), None);
        assert_eq!(parse_name("N35E13"), None);
    }

    #[test]
    fn product_suffixes_keep_the_position() {
        let dir = std::env::temp_dir().join(format!("texmap-hgt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("S01W072.SRTMGL3.hgt");
        std::fs::write(&path, vec![0u8; 2 * 1201 * 1201]).unwrap();
        let g = read_hgt(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!((g.georef().origin_x, g.georef().origin_y), (-72.0, 0.0));
    }

    #[test]
    fn void_and_position() {
        let n = 1201u32;
        let mut bytes = vec![0u8; 2 * (n * n) as usize];
        bytes[0..2].copy_from_slice(&(-32768i16).to_be_bytes());
        bytes[2..4].copy_from_slice(&3776i16.to_be_bytes());
        let g = read_hgt_bytes(&bytes, n, 35, 138, "N35E138.hgt").unwrap();
        assert!(g.at(0, 0).is_nan());
        assert_eq!(g.at(1, 0), 3776.0);
        assert_eq!(g.georef().sample_xy(0.0, 1200.0), (138.0, 35.0));
        assert_eq!(g.nodata_count(), 1);
    }
}

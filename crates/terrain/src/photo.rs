//! Orthophotos as [`PhotoSource`]s: PNG and JPEG decoded whole ([`Orthophoto`], within the
//! `image` crate's decode limits), GeoTIFFs of any size read a band of rows at a time
//! ([`TiffPhoto`]), so that a 32k² satellite scene becomes a GST pyramid without ever being held
//! in memory.
//!
//! [`TiffPhoto`] decodes the stored chunks (strips or tiles) under the rows asked for and keeps
//! the last row of chunks, because the pyramid writer asks for overlapping bands top to bottom.
//! Bands are chosen as [`crate::gst::read_photo`] chooses them (`--bands 3,2,1`; by default 1, 2, 3, or
//! band 1 as grey), and samples wider than 8 bits are stretched linearly from each band's minimum
//! to its maximum, found in one pass over the file when it is opened — the same 8-bit values
//! `read_photo` makes from the whole image.

use crate::dem::Georef;
use crate::dem::geotiff::RasterReader;
use crate::error::TerrainError;
use crate::gst::{Orthophoto, PhotoSource, read_photo};
use image::{Rgba, RgbaImage};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Mutex;

/// The per-chunk decode limit of photo reading (bytes).
const CHUNK_LIMIT: usize = 1 << 28;

/// A GeoTIFF orthophoto read by rows (see the module docs).
pub struct TiffPhoto {
    source: String,
    width: u32,
    height: u32,
    georef: Option<Georef>,
    /// Per output channel: `(lowest, 255 / (highest − lowest))`, or `(0, 1)` for 8-bit bands.
    scale: [(f32, f32); 3],
    state: Mutex<State>,
}

struct State {
    reader: RasterReader,
    /// Decoded rows of chunks: chunk row -> its image rows at full width.
    cache: BTreeMap<u32, RgbaImage>,
}

/// The bands to read for red, green and blue (0-based) from a 1-based choice.
pub(crate) fn pick_bands(
    bands: Option<[u16; 3]>,
    band_count: u16,
) -> Result<[u16; 3], TerrainError> {
    match bands {
        Some(b) => {
            if b.contains(&0) {
                return Err(TerrainError::BadParameter {
                    name: "bands",
                    value: format!("{b:?}"),
                    expected: "1-based band numbers",
                });
            }
            Ok(b.map(|x| x - 1))
        }
        None if band_count >= 3 => Ok([0, 1, 2]),
        None => Ok([0, 0, 0]),
    }
}

impl TiffPhoto {
    /// Open a TIFF photo: header, georeference, band choice, and (for samples wider than
    /// 8 bits) one pass for each band's range.
    pub fn open(path: &Path, bands: Option<[u16; 3]>) -> Result<TiffPhoto, TerrainError> {
        let band_count = crate::dem::geotiff::band_count(path)?;
        let pick = pick_bands(bands, band_count)?;
        let mut reader = RasterReader::open(path, Some(&pick), CHUNK_LIMIT)?;
        let mut scale = [(0.0f32, 1.0f32); 3];
        if reader.bits > 8 {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for c in 0..reader.chunk_count() {
                let planes = reader.read_chunk(c)?.planes;
                for (k, plane) in planes.iter().enumerate() {
                    for &v in plane {
                        lo[k] = lo[k].min(v);
                        hi[k] = hi[k].max(v);
                    }
                }
            }
            for k in 0..3 {
                scale[k] = (
                    lo[k],
                    if hi[k] > lo[k] {
                        255.0 / (hi[k] - lo[k])
                    } else {
                        0.0
                    },
                );
            }
        }
        Ok(TiffPhoto {
            source: path.display().to_string(),
            width: reader.width,
            height: reader.height,
            georef: reader.georef,
            scale,
            state: Mutex::new(State {
                reader,
                cache: BTreeMap::new(),
            }),
        })
    }

    /// Decode chunk row `cr` into full-width 8-bit RGBA rows.
    fn decode_row(&self, st: &mut State, cr: u32) -> Result<RgbaImage, TerrainError> {
        let ch = st.reader.chunk_rows();
        let y0 = cr * ch;
        let y1 = (y0 + ch).min(self.height);
        let mut img = RgbaImage::new(self.width, y1 - y0);
        for chunk in st.reader.chunks_in_rows(y0, y1) {
            let c = st.reader.read_chunk(chunk)?;
            for row in 0..c.height {
                for col in 0..c.width {
                    let i = (row * c.width + col) as usize;
                    let v = |k: usize| {
                        ((c.planes[k][i] - self.scale[k].0) * self.scale[k].1)
                            .round()
                            .clamp(0.0, 255.0) as u8
                    };
                    img.put_pixel(c.x0 + col, c.y0 - y0 + row, Rgba([v(0), v(1), v(2), 255]));
                }
            }
        }
        Ok(img)
    }
}

impl PhotoSource for TiffPhoto {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    fn georef(&self) -> Option<Georef> {
        self.georef
    }
    fn source(&self) -> &str {
        &self.source
    }
    fn rows(&self, y0: u32, y1: u32) -> Result<RgbaImage, TerrainError> {
        let y1 = y1.min(self.height);
        let mut out = RgbaImage::new(self.width, y1.saturating_sub(y0));
        if y1 <= y0 {
            return Ok(out);
        }
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let ch = st.reader.chunk_rows();
        let (cr0, cr1) = (y0 / ch, (y1 - 1) / ch);
        // Rows above this band are not asked for again by a top-to-bottom reader.
        st.cache.retain(|&cr, _| cr >= cr0);
        for cr in cr0..=cr1 {
            if !st.cache.contains_key(&cr) {
                let img = self.decode_row(&mut st, cr)?;
                st.cache.insert(cr, img);
            }
            let img = &st.cache[&cr];
            let top = cr * ch;
            let (a, b) = (y0.max(top), y1.min(top + img.height()));
            for y in a..b {
                for x in 0..self.width {
                    out.put_pixel(x, y - y0, *img.get_pixel(x, y - top));
                }
            }
        }
        Ok(out)
    }
}

/// Whether `path` names a TIFF (by its extension, `.tif` or `.tiff`, any case).
pub(crate) fn is_tiff(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
}

/// Open an orthophoto for a pyramid build: a TIFF by rows ([`TiffPhoto`]), a PNG or JPEG whole.
pub fn open_photo(
    path: &Path,
    bands: Option<[u16; 3]>,
) -> Result<Box<dyn PhotoSource>, TerrainError> {
    if is_tiff(path) {
        Ok(Box::new(TiffPhoto::open(path, bands)?))
    } else {
        let p: Orthophoto = read_photo(path, bands)?;
        Ok(Box::new(p))
    }
}

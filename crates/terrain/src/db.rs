//! The terrain database directory: a JSON manifest, the grid, mesh chunks and GST map tiles.
//!
//! ```text
//! DIR/manifest.json            version, georeference, sizes, levels with chunk errors, texture levels
//! DIR/grid.f32                 the heights, little-endian f32 row-major (NaN = no-data): exports at any error
//! DIR/chunks/D/IX_IY.bin       "TMCK", u32 version, u32 vertices, u32 triangles, u32 surface triangles,
//!                              positions (3 f32), uvs (2 f32), triangles (3 u32), little-endian
//! DIR/tiles/L/X_Y.png          GST maps, T x T RGBA: the photo, and the grid's shaded relief where
//!                              no photo covers (gst::Drawn::relief_under)
//! ```
//! A build writes everything into a sibling temporary directory and renames it to `DIR` at the
//! end, so an interrupted or failed build never leaves a half-written database (the temporary is
//! removed on failure). `DIR` must not exist.

use crate::chunks;
use crate::dem::{Georef, Grid};
use crate::error::{TerrainError, format_err, io};
use crate::gst::{self, Orthophoto, PhotoSource};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The manifest's format version.
pub const VERSION: u32 = 1;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChunkEntry {
    pub ix: u32,
    pub iy: u32,
    pub x0: u32,
    pub y0: u32,
    pub size: u32,
    pub geometric_error: f32,
    pub skirt: f32,
    pub triangles: u32,
    pub vertices: u32,
    pub file: String,
    /// The mesh's bounding box in local metres, `[min x, min y, min z, max x, max y, max z]`
    /// (surface and skirts): what a renderer selects by without reading the file. Absent in
    /// databases written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounds: Option<[f32; 6]>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelEntry {
    pub depth: u32,
    pub target_error: f32,
    pub chunks: Vec<ChunkEntry>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureEntry {
    pub map_texels: u32,
    pub levels: u32,
    pub placed_by: String,
    /// Vector overlays drawn into the texture, in drawing order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overlays: Vec<OverlayEntry>,
    /// How the photo's samples became colours, when they were mapped (wider than 8 bits, or a
    /// `--stretch`): the ranges mapped to 0 and 255, to pass as `--stretch range:...` to a
    /// neighbouring database so that its colours match.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch: Option<crate::photo::Applied>,
}

/// A vector overlay drawn into the texture: its file and how many of its features were drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OverlayEntry {
    pub source: String,
    pub features: usize,
    pub drawn: usize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub version: u32,
    pub source: String,
    pub width: u32,
    pub height: u32,
    pub georef: Georef,
    pub height_min: f32,
    pub height_max: f32,
    pub nodata: u64,
    pub max_error: f32,
    pub chunk: u32,
    pub levels: Vec<LevelEntry>,
    pub texture: Option<TextureEntry>,
    /// The shaded relief's colour table ([`crate::relief::TintTable`], from `--relief-colors`);
    /// absent: the built-in ramp.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief_tint: Option<crate::relief::TintTable>,
}

/// Build options.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    pub max_error: f32,
    pub chunk: u32,
    pub map_texels: u32,
    /// Cap on GST levels (the finest is `map_texels · 2^(levels−1)` a side).
    pub max_texture_levels: u32,
    /// Contour lines drawn into the texture ([`crate::relief::Contours`]); without a photo the
    /// texture is then the shaded relief (up to 4096² texels), with the lines.
    pub contours: Option<crate::relief::Contours>,
    /// GeoJSON layers drawn into the texture over the photo and the contours
    /// ([`crate::vector`]); without a photo the texture is then the shaded relief.
    pub overlays: Vec<crate::vector::VectorLayer>,
    /// What the overlays' features take for the style keys they do not set.
    pub overlay_style: crate::vector::Style,
    /// The shaded relief's height colours ([`crate::relief::Tint`]), saved in the manifest; a
    /// table without a photo makes the texture the shaded relief (up to 4096² texels).
    pub tint: crate::relief::Tint,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            max_error: 1.0,
            chunk: 257,
            map_texels: 256,
            max_texture_levels: 5,
            contours: None,
            overlays: Vec::new(),
            overlay_style: crate::vector::Style::default(),
            tint: crate::relief::Tint::Ramp,
        }
    }
}

fn chunk_bytes(c: &chunks::Chunk) -> Vec<u8> {
    let m = &c.mesh;
    let mut b = Vec::with_capacity(20 + m.positions.len() * 20 + m.triangles.len() * 12);
    b.extend_from_slice(b"TMCK");
    for v in [
        1u32,
        m.positions.len() as u32,
        m.triangles.len() as u32,
        c.surface_triangles,
    ] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for p in &m.positions {
        for x in p.to_array() {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in m.uvs.as_deref().unwrap_or(&[]) {
        for x in t.to_array() {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in &m.triangles {
        for i in t {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    b
}

impl ChunkEntry {
    /// The manifest entry of chunk `c` stored at `file` (relative to the database directory).
    pub fn of(c: &chunks::Chunk, file: String) -> ChunkEntry {
        ChunkEntry {
            ix: c.ix,
            iy: c.iy,
            x0: c.x0,
            y0: c.y0,
            size: c.size,
            geometric_error: c.geometric_error,
            skirt: c.skirt,
            triangles: c.surface_triangles,
            vertices: c.mesh.positions.len() as u32,
            file,
            bounds: Some(bounds_of(&c.mesh.positions)),
        }
    }
}

/// `[min x, min y, min z, max x, max y, max z]` of `points`.
fn bounds_of(points: &[glam::Vec3]) -> [f32; 6] {
    let b = crate::view::Aabb::of(points);
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]
}

/// Parse a chunk file written by [`chunk_bytes`], checking every count against the file's length
/// and every index against the vertex count.
fn parse_chunk(path: &Path, b: &[u8]) -> Result<texmap_mesh::TriMesh, TerrainError> {
    let src = path.display().to_string();
    let bad = |at: usize, what: String| format_err(&src, format!("byte {at}"), what);
    if b.len() < 20 || &b[..4] != b"TMCK" {
        return Err(bad(
            0,
            "a chunk file starting \"TMCK\" with a 20-byte header".into(),
        ));
    }
    let word = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    if word(4) != 1 {
        return Err(bad(4, format!("chunk format version 1, got {}", word(4))));
    }
    let (nv, nt) = (word(8) as u64, word(12) as u64);
    let want = 20 + nv * 20 + nt * 12;
    if b.len() as u64 != want {
        return Err(bad(
            8,
            format!(
                "{want} bytes for {nv} vertices and {nt} triangles, the file has {}",
                b.len()
            ),
        ));
    }
    let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let (nv, nt) = (nv as usize, nt as usize);
    let mut positions = Vec::with_capacity(nv);
    for v in 0..nv {
        let o = 20 + 12 * v;
        let p = glam::Vec3::new(f(o), f(o + 4), f(o + 8));
        if !p.is_finite() {
            return Err(bad(o, format!("a finite position for vertex {v}")));
        }
        positions.push(p);
    }
    let uo = 20 + 12 * nv;
    let uvs = (0..nv)
        .map(|v| glam::Vec2::new(f(uo + 8 * v), f(uo + 8 * v + 4)))
        .collect();
    let to = uo + 8 * nv;
    let mut triangles = Vec::with_capacity(nt);
    for t in 0..nt {
        let o = to + 12 * t;
        let tri = [word(o), word(o + 4), word(o + 8)];
        if tri.iter().any(|&i| i as usize >= nv) {
            return Err(bad(
                o,
                format!("triangle {t}: vertex indices below {nv}, got {tri:?}"),
            ));
        }
        triangles.push(tri);
    }
    Ok(texmap_mesh::TriMesh {
        positions,
        triangles,
        uvs: Some(uvs),
        normals: None,
    })
}

/// Build a database at `out` from `grid` (and an orthophoto); `progress(done, total)` is called
/// after each step.
pub fn build(
    grid: &Grid,
    source: &str,
    photo: Option<&Orthophoto>,
    opts: &BuildOptions,
    out: &Path,
    progress: impl FnMut(u64, u64),
) -> Result<Manifest, TerrainError> {
    build_with(
        grid,
        source,
        photo.map(|p| p as &dyn PhotoSource),
        opts,
        out,
        progress,
    )
}

/// As [`build`], with the photo from any [`PhotoSource`] (a GeoTIFF read by rows:
/// [`crate::photo::open_photo`]).
pub fn build_with(
    grid: &Grid,
    source: &str,
    photo: Option<&dyn PhotoSource>,
    opts: &BuildOptions,
    out: &Path,
    mut progress: impl FnMut(u64, u64),
) -> Result<Manifest, TerrainError> {
    write_dir_atomically(out, |tmp| {
        build_into(grid, source, photo, opts, tmp, &mut progress)
    })
}

/// Runs `fill` on a sibling temporary directory of `out` (`.NAME.tmp-PID`) and renames it to `out`
/// when `fill` succeeds; on failure the temporary directory is removed, so `out` either holds a
/// complete result or does not exist. Errors: `out` exists already.
pub(crate) fn write_dir_atomically<T>(
    out: &Path,
    fill: impl FnOnce(&Path) -> Result<T, TerrainError>,
) -> Result<T, TerrainError> {
    if out.exists() {
        return Err(TerrainError::Exists {
            path: out.to_path_buf(),
        });
    }
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "terrain".into());
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(io(&tmp))?;
    }
    let result = fill(&tmp).and_then(|m| {
        std::fs::rename(&tmp, out).map_err(io(out))?;
        Ok(m)
    });
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), TerrainError> {
    if let Some(p) = path.parent() {
        std::fs::create_dir_all(p).map_err(io(p))?;
    }
    std::fs::write(path, bytes).map_err(io(path))
}

fn build_into(
    grid: &Grid,
    source: &str,
    photo: Option<&dyn PhotoSource>,
    opts: &BuildOptions,
    dir: &Path,
    progress: &mut impl FnMut(u64, u64),
) -> Result<Manifest, TerrainError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    // Contours, overlays or a tint table without a photo: drawn over the shaded relief, which
    // becomes the texture.
    let tinted = opts.tint != crate::relief::Tint::Ramp;
    let relief = match (
        photo,
        opts.contours.is_some() || !opts.overlays.is_empty() || tinted,
    ) {
        (None, true) => Some(gst::Orthophoto {
            image: opts.tint.image(grid, 4096),
            georef: None,
            source: "shaded relief".into(),
            stretch: None,
        }),
        _ => None,
    };
    let photo = photo.or(relief.as_ref().map(|r| r as &dyn PhotoSource));
    let tex_levels = match photo {
        Some(p) => gst::photo_level_count(p, grid, opts.map_texels, opts.max_texture_levels)?,
        None => 0,
    };
    // Placed before the meshing, so that a layer off the terrain fails the build at once.
    let overlay = match tex_levels {
        0 => None,
        _ if opts.overlays.is_empty() => None,
        l => Some(crate::vector::Overlay::place(
            &opts.overlays,
            &opts.overlay_style,
            grid,
            opts.map_texels << (l - 1),
            opts.map_texels,
        )?),
    };
    let total = 3 + tex_levels as u64;
    let mut levels: Vec<LevelEntry> = Vec::new();
    // One band of chunks at a time: they go to disk and are dropped before the next is built.
    chunks::build_streaming(grid, opts.max_error, opts.chunk, |d, level| {
        let mut entries = Vec::new();
        for c in &level {
            let file = format!("chunks/{d}/{}_{}.bin", c.ix, c.iy);
            write(&dir.join(&file), &chunk_bytes(c))?;
            entries.push(ChunkEntry::of(c, file));
        }
        // A depth may come in several bands: extend its entry.
        let target = level.first().map(|c| c.target_error);
        match levels.last_mut() {
            Some(l) if l.depth == d => {
                if l.chunks.is_empty() {
                    l.target_error = target.unwrap_or(0.0);
                }
                l.chunks.extend(entries);
            }
            _ => levels.push(LevelEntry {
                depth: d,
                target_error: target.unwrap_or(0.0),
                chunks: entries,
            }),
        }
        Ok(())
    })?;
    progress(1, total);
    progress(2, total);
    // Streamed: no second copy of a large grid in memory.
    let gpath = dir.join("grid.f32");
    {
        use std::io::Write as _;
        let f = std::fs::File::create(&gpath).map_err(io(&gpath))?;
        let mut w = std::io::BufWriter::new(f);
        for h in grid.heights() {
            w.write_all(&h.to_le_bytes()).map_err(io(&gpath))?;
        }
        w.flush().map_err(io(&gpath))?;
    }
    let texture = match photo {
        Some(p) => {
            for l in 0..tex_levels {
                let d = dir.join(format!("tiles/{l}"));
                std::fs::create_dir_all(&d).map_err(io(&d))?;
            }
            let tile = |k: gst::MapKey| dir.join(format!("tiles/{}/{}_{}.png", k.level, k.x, k.y));
            let write = |k: gst::MapKey, map: &image::RgbaImage| {
                let path = tile(k);
                map.save(&path).map_err(|e| {
                    format_err(
                        &path.display().to_string(),
                        "PNG encoding",
                        format!("a writable file ({e})"),
                    )
                })
            };
            let read = |k: gst::MapKey| {
                let path = tile(k);
                Ok(image::open(&path)
                    .map_err(|e| format_err(&path.display().to_string(), "PNG", e.to_string()))?
                    .to_rgba8())
            };
            let mut done = 0;
            gst::write_pyramid_with(
                p,
                grid,
                opts.map_texels,
                tex_levels,
                &gst::Drawn {
                    relief_under: Some(&opts.tint),
                    contours: opts.contours.as_ref(),
                    overlay: overlay.as_ref(),
                },
                &write,
                &read,
                &mut |_| {
                    done += 1;
                    progress(2 + done, total);
                },
            )?;
            Some(TextureEntry {
                map_texels: opts.map_texels,
                levels: tex_levels,
                placed_by: if p.georef().is_some() {
                    "georeference".into()
                } else {
                    "stretched".into()
                },
                stretch: p.stretch(),
                overlays: overlay.as_ref().map_or(Vec::new(), |o| {
                    o.counts()
                        .iter()
                        .map(|(source, drawn, features)| OverlayEntry {
                            source: source.clone(),
                            features: *features,
                            drawn: *drawn,
                        })
                        .collect()
                }),
            })
        }
        None => None,
    };
    let (lo, hi) = grid.height_range();
    let manifest = Manifest {
        version: VERSION,
        source: source.to_string(),
        width: grid.width(),
        height: grid.height(),
        georef: *grid.georef(),
        height_min: lo,
        height_max: hi,
        nodata: grid.nodata_count(),
        max_error: opts.max_error,
        chunk: opts.chunk,
        levels,
        texture,
        relief_tint: match &opts.tint {
            crate::relief::Tint::Ramp => None,
            crate::relief::Tint::Table(t) => Some(t.clone()),
        },
    };
    let json = serde_json::to_vec_pretty(&manifest)
        .map_err(|e| format_err(source, "manifest", e.to_string()))?;
    write(&dir.join("manifest.json"), &json)?;
    progress(total, total);
    Ok(manifest)
}

/// An opened database.
#[derive(Clone, Debug)]
pub struct Database {
    pub dir: PathBuf,
    pub manifest: Manifest,
}

impl Database {
    /// The shaded relief's tint: the manifest's table, or the built-in ramp.
    pub fn tint(&self) -> crate::relief::Tint {
        self.manifest
            .relief_tint
            .clone()
            .map_or(crate::relief::Tint::Ramp, crate::relief::Tint::Table)
    }

    pub fn open(dir: &Path) -> Result<Database, TerrainError> {
        let path = dir.join("manifest.json");
        let text = std::fs::read_to_string(&path).map_err(io(&path))?;
        let manifest: Manifest = serde_json::from_str(&text).map_err(|e| {
            format_err(
                &path.display().to_string(),
                format!("line {}", e.line()),
                format!("a terrain manifest ({e})"),
            )
        })?;
        if manifest.version != VERSION {
            return Err(TerrainError::Unsupported {
                source: path.display().to_string(),
                what: format!(
                    "manifest version {} (this build reads {VERSION})",
                    manifest.version
                ),
            });
        }
        // The relief tint's guarantee: entries by ascending height.
        if let Some(t) = &manifest.relief_tint
            && !t.entries.is_sorted_by(|a, b| a.0 <= b.0)
        {
            return Err(format_err(
                &path.display().to_string(),
                "relief_tint",
                "colour entries by ascending height",
            ));
        }
        Ok(Database {
            dir: dir.to_path_buf(),
            manifest,
        })
    }

    /// The stored grid.
    pub fn grid(&self) -> Result<Grid, TerrainError> {
        let path = self.dir.join("grid.f32");
        let m = &self.manifest;
        let bytes = std::fs::read(&path).map_err(io(&path))?;
        let want = m.width as usize * m.height as usize * 4;
        if bytes.len() != want {
            return Err(format_err(
                &path.display().to_string(),
                "file size",
                format!("{want} bytes for {} x {} f32", m.width, m.height),
            ));
        }
        let h = bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Grid::new(&path.display().to_string(), m.width, m.height, h, m.georef)
    }

    /// The stored grid mapped into memory rather than read ([`Grid::map_file`]): pages are read
    /// only when their heights are used.
    pub fn grid_mapped(&self) -> Result<Grid, TerrainError> {
        let m = &self.manifest;
        Grid::map_file(
            &self.dir.join("grid.f32"),
            m.width,
            m.height,
            m.georef,
            (m.height_min, m.height_max),
        )
    }

    /// The mesh of one chunk (surface and skirts) from its file.
    pub fn read_chunk(&self, entry: &ChunkEntry) -> Result<texmap_mesh::TriMesh, TerrainError> {
        let rel = Path::new(&entry.file);
        if !rel
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
        {
            return Err(format_err(
                &self.dir.join("manifest.json").display().to_string(),
                format!("chunk file \"{}\"", entry.file),
                "a path inside the database directory",
            ));
        }
        let path = self.dir.join(rel);
        let bytes = std::fs::read(&path).map_err(io(&path))?;
        parse_chunk(&path, &bytes)
    }

    /// A GST map tile.
    pub fn map(&self, key: gst::MapKey) -> Result<image::RgbaImage, TerrainError> {
        let path = self
            .dir
            .join(format!("tiles/{}/{}_{}.png", key.level, key.x, key.y));
        Ok(image::open(&path)
            .map_err(|e| format_err(&path.display().to_string(), "PNG", e.to_string()))?
            .to_rgba8())
    }

    /// The finest texture level whose side is at most `max_side`, assembled from its tiles.
    pub fn texture(&self, max_side: u32) -> Result<Option<image::RgbaImage>, TerrainError> {
        let Some(t) = &self.manifest.texture else {
            return Ok(None);
        };
        let mut level = t.levels - 1;
        while level > 0 && (t.map_texels << level) > max_side {
            level -= 1;
        }
        let n = 1u32 << level;
        let mut img = image::RgbaImage::new(t.map_texels * n, t.map_texels * n);
        for y in 0..n {
            for x in 0..n {
                let m = self.map(gst::MapKey { level, x, y })?;
                image::imageops::replace(
                    &mut img,
                    &m,
                    (x * t.map_texels) as i64,
                    (y * t.map_texels) as i64,
                );
            }
        }
        Ok(Some(img))
    }
}

/// One mesh of the whole grid at `max_error` (RTIN over the padded grid; holes dropped), with
/// positions in local metres and uvs over the DEM extent.
pub fn whole_mesh(grid: &Grid, max_error: f32) -> Result<texmap_mesh::TriMesh, TerrainError> {
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(TerrainError::BadParameter {
            name: "max-error",
            value: max_error.to_string(),
            expected: "a finite error ≥ 0 metres",
        });
    }
    let (padded, n) = crate::rtin::pad_to_rtin(grid.heights(), grid.width(), grid.height());
    let map = crate::rtin::ErrorMap::new(&padded, n);
    let gm = crate::rtin::extract(&map, &padded, 0, 0, n - 1, max_error, 1);
    Ok(chunks::chunk_mesh(
        grid,
        &padded,
        n,
        &gm,
        (0, 0, n - 1),
        0.0,
    ))
}

/// As [`whole_mesh`] with the greedy Delaunay refinement (fewer triangles, more time; the grid
/// must have no no-data).
pub fn whole_mesh_greedy(
    grid: &Grid,
    max_error: f32,
) -> Result<texmap_mesh::TriMesh, TerrainError> {
    let gm = crate::greedy::greedy(grid, max_error)?;
    let w = grid.width();
    Ok(chunks::chunk_mesh(
        grid,
        grid.heights(),
        w,
        &gm,
        (0, 0, 0),
        0.0,
    ))
}

/// The `info` object of a grid: size, georeference, height range, no-data count.
pub fn grid_info(grid: &Grid, source: &str) -> serde_json::Value {
    let (lo, hi) = grid.height_range();
    let (sx, sy) = grid.georef().spacing_metres(grid.height());
    serde_json::json!({
        "source": source, "width": grid.width(), "height": grid.height(), "georef": grid.georef(),
        "spacing_m": [sx, sy], "height_min": lo, "height_max": hi, "nodata": grid.nodata_count(),
    })
}

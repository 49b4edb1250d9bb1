//! Export of a database as OGC 3D Tiles 1.1 — the chunked level-of-detail tree as Cesium (and the
//! engines with Cesium's plug-ins) stream it: `tileset.json` plus one binary glTF per chunk.
//!
//! The database's quadtree maps one to one onto the tileset: every chunk is a tile whose
//! `geometricError` is the chunk's measured geometric error in metres (a parent's is at least its
//! children's; the tileset's, the error of leaving the terrain out, is the radius of its box),
//! refined by replacement, with the chunk's mesh (surface and skirts) and its part of
//! the texture (the photo's or, without one, the shaded relief) as content. A viewer refines a
//! tile when that error, projected to the screen, exceeds its pixel tolerance — the same rule the
//! flight view uses.
//!
//! Placement on the globe: every vertex goes from its grid sample (recovered from its texture
//! coordinate) through the grid's georeference to WGS 84 longitude/latitude ([`crate::geodesy`]:
//! geographic grids directly, UTM and Web Mercator grids by the inverse projection) and, with its
//! height as ellipsoidal height, to earth-centred, earth-fixed (ECEF) metres. A DEM's heights are
//! usually above sea level (orthometric): with a geoid grid ([`TilesetOptions::geoid`]) each
//! vertex's height becomes `H + N(lon, lat)`, the ellipsoidal height Cesium World Terrain and
//! photogrammetry use, and `asset.extras.heights` says which the tileset holds. Each glTF holds its vertices
//! relative to the centre of its tile's box (single precision keeps millimetres there), the tile's
//! `transform` translating by that centre (relative to the parent's, as transforms compose), and
//! the y-up glTF axes are written so that the viewer's y-up to z-up rotation yields ECEF. Bounding
//! volumes are boxes aligned with the ECEF axes around each chunk's vertices. Grids without a
//! georeference on the ellipsoid (local grids, projections other than UTM and Web Mercator) are
//! refused by name.
//!
//! The output directory is written atomically (a temporary sibling renamed at the end).

use std::collections::HashMap;
use std::path::Path;

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use serde_json::{Value, json};
use texmap_mesh::TriMesh;

use crate::db::{ChunkEntry, Database, write_dir_atomically};
use crate::dem::Grid;
use crate::error::{TerrainError, io};
use crate::geodesy::{Placement, ecef};
use crate::geoid::Geoid;
use crate::relief::{Hillshade, Light, Tint};

/// The default largest texture side per tile.
pub const MAX_TILE_TEXTURE: u32 = 1024;

/// How [`write_tileset_with`] writes a tileset.
#[derive(Clone, Copy, Debug)]
pub struct TilesetOptions<'a> {
    /// Largest texture side per tile ([`MAX_TILE_TEXTURE`] by default).
    pub max_texture: u32,
    /// The geoid the grid's heights are above: each vertex is raised by the undulation there.
    /// `None` takes the heights as ellipsoidal.
    pub geoid: Option<&'a Geoid>,
}

impl Default for TilesetOptions<'_> {
    fn default() -> Self {
        TilesetOptions {
            max_texture: MAX_TILE_TEXTURE,
            geoid: None,
        }
    }
}

/// What [`write_tileset`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct TilesetSummary {
    /// Tiles in the tree (chunks).
    pub tiles: usize,
    /// Tiles with content (chunks holding at least one triangle).
    pub with_content: usize,
    /// Triangles over all tiles.
    pub triangles: u64,
    /// Bytes of all files written.
    pub bytes: u64,
}

/// One chunk's tile, before the tree is assembled.
struct Tile {
    depth: u32,
    ix: u32,
    iy: u32,
    geometric_error: f64,
    /// ECEF box of the chunk's vertices.
    lo: DVec3,
    hi: DVec3,
    content: Option<String>,
    triangles: u64,
    bytes: u64,
}

/// Write `db` as a 3D Tiles 1.1 tileset into the new directory `out` (which must not exist). Each
/// tile's texture is at most `max_texture` texels a side ([`MAX_TILE_TEXTURE`] is the usual
/// choice): the finest level of the photo's GST pyramid whose part under the tile fits, or, without
/// a photo, shaded relief at one texel per grid sample (reduced if it does not fit).
///
/// Errors: `out` exists; the grid has no placement on the ellipsoid; a chunk file or the texture
/// cannot be read; a file cannot be written.
pub fn write_tileset(
    db: &Database,
    out: &Path,
    max_texture: u32,
) -> Result<TilesetSummary, TerrainError> {
    let options = TilesetOptions {
        max_texture,
        geoid: None,
    };
    write_tileset_with(db, out, &options)
}

/// [`write_tileset`] with a geoid: heights are above it and become ellipsoidal. A vertex the
/// geoid grid does not cover is an error naming the grid and the point.
pub fn write_tileset_with(
    db: &Database,
    out: &Path,
    options: &TilesetOptions,
) -> Result<TilesetSummary, TerrainError> {
    let m = &db.manifest;
    let max_texture = options.max_texture;
    let placement = Placement::of(&m.georef).ok_or_else(|| TerrainError::Unsupported {
        source: db.dir.display().to_string(),
        what: format!(
            "3D Tiles need the grid placed on the WGS 84 ellipsoid: a geographic, UTM (EPSG:326zz/\
             327zz, ETRS89 258zz, NAD83 269zz) or Web Mercator (EPSG:3857) georeference; this \
             grid's is {:?}{}",
            m.georef.crs,
            m.georef
                .epsg
                .map(|e| format!(" (EPSG:{e})"))
                .unwrap_or_default()
        ),
    })?;
    let grid = db.grid_mapped()?;
    let shade = Hillshade::new(&grid, Light::default());
    let tint = db.tint();
    let source = match &m.texture {
        Some(t) => Source::Photo {
            db,
            map_texels: t.map_texels,
            levels: t.levels,
        },
        None => Source::Relief {
            grid: &grid,
            shade: &shade,
            tint: &tint,
        },
    };
    let max_texture = max_texture.max(1);
    write_dir_atomically(out, |tmp| {
        let mut tiles = Vec::new();
        for level in &m.levels {
            let dir = tmp.join(format!("tiles/{}", level.depth));
            std::fs::create_dir_all(&dir).map_err(io(&dir))?;
            let made: Vec<Result<Tile, TerrainError>> = level
                .chunks
                .par_iter()
                .map(|c| {
                    let place = Place {
                        placement,
                        geoid: options.geoid,
                    };
                    chunk_tile(db, level.depth, c, place, &source, max_texture, tmp)
                })
                .collect();
            for t in made {
                tiles.push(t?);
            }
        }
        let summary = TilesetSummary {
            tiles: tiles.len(),
            with_content: tiles.iter().filter(|t| t.content.is_some()).count(),
            triangles: tiles.iter().map(|t| t.triangles).sum(),
            bytes: tiles.iter().map(|t| t.bytes).sum(),
        };
        let mut json = tileset_json(&tiles, m.max_error as f64);
        json["asset"]["extras"] = json!({
            "heights": match options.geoid {
                Some(g) => format!(
                    "ellipsoidal (WGS 84): the grid's heights plus the undulation of {}",
                    file_name(g.name())
                ),
                None => "the grid's heights, taken as ellipsoidal (WGS 84)".to_string(),
            }
        });
        let text = serde_json::to_string_pretty(&json).expect("JSON values serialise");
        let path = tmp.join("tileset.json");
        std::fs::write(&path, &text).map_err(io(&path))?;
        Ok(TilesetSummary {
            bytes: summary.bytes + text.len() as u64,
            ..summary
        })
    })
}

/// How grid samples go onto the ellipsoid: the horizontal placement and the geoid, if any.
#[derive(Clone, Copy)]
struct Place<'a> {
    placement: Placement,
    geoid: Option<&'a Geoid>,
}

/// The last component of a path, for the tileset's description of its heights.
fn file_name(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

/// ECEF position of a chunk vertex: its grid sample from its texture coordinate (the databases'
/// `uv = (col, row) / (side − 1)`), its height from `y` plus the geoid's undulation there.
fn vertex_ecef(db: &Database, place: Place, p: Vec3, uv: Vec2) -> Result<DVec3, TerrainError> {
    let m = &db.manifest;
    let col = uv.x as f64 * (m.width - 1) as f64;
    let row = uv.y as f64 * (m.height - 1) as f64;
    let (x, y) = m.georef.sample_xy(col, row);
    let (lon, lat) = place.placement.lonlat(x, y);
    let n = match place.geoid {
        None => 0.0,
        Some(g) => g
            .undulation(lon, lat)
            .ok_or_else(|| TerrainError::Unsupported {
                source: g.name().to_string(),
                what: format!(
                    "the geoid grid has no undulation at longitude {lon:.6}, latitude {lat:.6} \
                 (outside the grid or no data), a point of the terrain {}",
                    db.dir.display()
                ),
            })?,
    };
    Ok(DVec3::from(ecef(lon, lat, p.y as f64 + n)))
}

fn chunk_tile(
    db: &Database,
    depth: u32,
    c: &ChunkEntry,
    place: Place,
    source: &Source,
    max_texture: u32,
    tmp: &Path,
) -> Result<Tile, TerrainError> {
    let mesh = db.read_chunk(c)?;
    let mut tile = Tile {
        depth,
        ix: c.ix,
        iy: c.iy,
        geometric_error: c.geometric_error as f64,
        lo: DVec3::ZERO,
        hi: DVec3::ZERO,
        content: None,
        triangles: 0,
        bytes: 0,
    };
    let Some(uvs) = mesh.uvs.as_ref().filter(|_| !mesh.triangles.is_empty()) else {
        return Ok(tile);
    };
    let world: Vec<DVec3> = mesh
        .positions
        .iter()
        .zip(uvs)
        .map(|(&p, &uv)| vertex_ecef(db, place, p, uv))
        .collect::<Result<_, _>>()?;
    let (lo, hi) = world.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let centre = 0.5 * (lo + hi);
    // glTF y-up: (x, y, z) is read as (x, −z, y), so ECEF offset (X, Y, Z) is written (X, Z, −Y).
    let positions = world
        .iter()
        .map(|&p| {
            let d = p - centre;
            Vec3::new(d.x as f32, d.z as f32, -d.y as f32)
        })
        .collect();
    let (crop, tile_uvs) = tile_texture(source, uvs, max_texture)?;
    let out = TriMesh {
        positions,
        triangles: mesh.triangles.clone(),
        uvs: Some(tile_uvs),
        normals: None,
    };
    let rel = format!("tiles/{}/{}_{}.glb", depth, c.ix, c.iy);
    let path = tmp.join(&rel);
    texmap_mesh::write_glb(&path, &out, Some(&crop)).map_err(TerrainError::Mesh)?;
    tile.bytes = std::fs::metadata(&path).map_err(io(&path))?.len();
    tile.lo = lo;
    tile.hi = hi;
    tile.content = Some(rel);
    tile.triangles = out.triangles.len() as u64;
    Ok(tile)
}

/// Where the tiles' textures come from.
enum Source<'a> {
    /// The database's GST pyramid: level `L` is `map_texels · 2^L` texels a side.
    Photo {
        db: &'a Database,
        map_texels: u32,
        levels: u32,
    },
    /// Shaded relief at one texel per grid sample.
    Relief {
        grid: &'a Grid,
        shade: &'a Hillshade<'a>,
        tint: &'a Tint,
    },
}

/// The texels a tile's `uvs` cover, at the finest resolution whose crop is at most `max_side`
/// texels a side (a GST level of the photo, or the relief at one texel per sample, reduced by a
/// box filter if still larger), and the uvs remapped onto that crop.
fn tile_texture(
    source: &Source,
    uvs: &[Vec2],
    max_side: u32,
) -> Result<(image::RgbaImage, Vec<Vec2>), TerrainError> {
    let (lo, hi) = uvs.iter().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), &uv| (lo.min(uv), hi.max(uv)),
    );
    // The crop `[x0, x1) x [y0, y1)` of a texture `side` texels a side.
    let rect = |side: u32| {
        let s = side as f32;
        let x0 = ((lo.x * s).floor().max(0.0) as u32).min(side - 1);
        let y0 = ((lo.y * s).floor().max(0.0) as u32).min(side - 1);
        let x1 = ((hi.x * s).ceil() as u32).clamp(x0 + 1, side);
        let y1 = ((hi.y * s).ceil() as u32).clamp(y0 + 1, side);
        (x0, y0, x1 - x0, y1 - y0)
    };
    let (side, (x0, y0, cw, ch), mut crop) = match *source {
        Source::Photo {
            db,
            map_texels,
            levels,
        } => {
            // The finest level whose crop fits (level 0 at worst).
            let level = (0..levels)
                .rev()
                .find(|&l| {
                    let (_, _, w, h) = rect(map_texels << l);
                    w.max(h) <= max_side
                })
                .unwrap_or(0);
            let side = map_texels << level;
            let r @ (x0, y0, cw, ch) = rect(side);
            let mut img = image::RgbaImage::new(cw, ch);
            for my in y0 / map_texels..=(y0 + ch - 1) / map_texels {
                for mx in x0 / map_texels..=(x0 + cw - 1) / map_texels {
                    let map = db.map(crate::gst::MapKey {
                        level,
                        x: mx,
                        y: my,
                    })?;
                    let (ox, oy) = (mx * map_texels, my * map_texels);
                    image::imageops::replace(
                        &mut img,
                        &map,
                        ox as i64 - x0 as i64,
                        oy as i64 - y0 as i64,
                    );
                }
            }
            (side, r, img)
        }
        Source::Relief { grid, shade, tint } => {
            let side = grid.width().max(grid.height());
            let r @ (x0, y0, cw, ch) = rect(side);
            let img = image::RgbaImage::from_fn(cw, ch, |x, y| {
                image::Rgba(tint.texel(grid, shade, side, x0 + x, y0 + y))
            });
            (side, r, img)
        }
    };
    let scale = (max_side as f32 / cw.max(ch) as f32).min(1.0);
    if scale < 1.0 {
        let (nw, nh) = (
            ((cw as f32 * scale).round() as u32).max(1),
            ((ch as f32 * scale).round() as u32).max(1),
        );
        crop = image::imageops::resize(&crop, nw, nh, image::imageops::FilterType::Triangle);
    }
    let s = side as f32;
    let remapped = uvs
        .iter()
        .map(|uv| {
            Vec2::new(
                (uv.x * s - x0 as f32) / cw as f32,
                (uv.y * s - y0 as f32) / ch as f32,
            )
        })
        .collect();
    Ok((crop, remapped))
}

/// An ECEF-aligned box (3D Tiles `box`: centre, then three half-axis vectors) around `lo..hi`,
/// relative to `origin`.
fn box_volume(lo: DVec3, hi: DVec3, origin: DVec3) -> Value {
    let c = 0.5 * (lo + hi) - origin;
    let h = (0.5 * (hi - lo)).max(DVec3::splat(0.01));
    json!({ "box": [c.x, c.y, c.z, h.x, 0.0, 0.0, 0.0, h.y, 0.0, 0.0, 0.0, h.z] })
}

fn translation(d: DVec3) -> Value {
    json!([
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, d.x, d.y, d.z, 1.0
    ])
}

/// The tree of tiles: `(depth, ix, iy)` has the children `(2ix + i, 2iy + j)` at the next depth
/// that exist; each subtree's box and largest error computed once.
struct Tree<'a> {
    tiles: &'a [Tile],
    index: HashMap<(u32, u32, u32), usize>,
    /// Per tile: its subtree's ECEF box and largest geometric error.
    subtrees: HashMap<usize, (DVec3, DVec3, f64)>,
}

impl Tree<'_> {
    fn children(&self, i: usize) -> Vec<usize> {
        let t = &self.tiles[i];
        let (x, y) = (2 * t.ix, 2 * t.iy);
        [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
            .iter()
            .filter_map(|&(cx, cy)| self.index.get(&(t.depth + 1, cx, cy)).copied())
            .collect()
    }

    /// The box (empty: `lo > hi`) and largest error of tile `i` and everything below it (a tile
    /// without content still bounds its children).
    fn subtree(&mut self, i: usize) -> (DVec3, DVec3, f64) {
        if let Some(&v) = self.subtrees.get(&i) {
            return v;
        }
        let t = &self.tiles[i];
        let (mut lo, mut hi) = if t.content.is_some() {
            (t.lo, t.hi)
        } else {
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY))
        };
        let mut error = t.geometric_error;
        for c in self.children(i) {
            let (clo, chi, ce) = self.subtree(c);
            lo = lo.min(clo);
            hi = hi.max(chi);
            error = error.max(ce);
        }
        self.subtrees.insert(i, (lo, hi, error));
        (lo, hi, error)
    }

    /// Tile `i` as JSON, its transform relative to `parent_origin`; `None` when no terrain lies
    /// anywhere below it.
    fn node(&mut self, i: usize, parent_origin: DVec3) -> Option<Value> {
        let (lo, hi, error) = self.subtree(i);
        if lo.x > hi.x {
            return None;
        }
        let t = &self.tiles[i];
        // The content's vertices are relative to its own box's centre; a tile without content
        // takes its subtree's.
        let origin = if t.content.is_some() {
            0.5 * (t.lo + t.hi)
        } else {
            0.5 * (lo + hi)
        };
        let (leaf_error, content) = (t.geometric_error, t.content.clone());
        let kids: Vec<Value> = self
            .children(i)
            .into_iter()
            .filter_map(|c| self.node(c, origin))
            .collect();
        let mut v = json!({
            "transform": translation(origin - parent_origin),
            "boundingVolume": box_volume(lo, hi, origin),
            "geometricError": if kids.is_empty() { leaf_error } else { error },
            "refine": "REPLACE",
        });
        if let Some(uri) = content {
            v["content"] = json!({ "uri": uri });
        }
        if !kids.is_empty() {
            v["children"] = Value::Array(kids);
        }
        Some(v)
    }
}

/// The tileset: geometric errors made monotone upwards; a root without content over several
/// depth-0 tiles.
fn tileset_json(tiles: &[Tile], max_error: f64) -> Value {
    let mut tree = Tree {
        tiles,
        index: tiles
            .iter()
            .enumerate()
            .map(|(i, t)| ((t.depth, t.ix, t.iy), i))
            .collect(),
        subtrees: HashMap::new(),
    };
    let roots: Vec<usize> = (0..tiles.len()).filter(|&i| tiles[i].depth == 0).collect();
    let (mut lo, mut hi, mut error) = (
        DVec3::splat(f64::INFINITY),
        DVec3::splat(f64::NEG_INFINITY),
        max_error,
    );
    for &r in &roots {
        let (rlo, rhi, re) = tree.subtree(r);
        (lo, hi, error) = (lo.min(rlo), hi.max(rhi), error.max(re));
    }
    let radius = if lo.x <= hi.x {
        0.5 * (hi - lo).length()
    } else {
        0.0
    };
    let root = if roots.len() == 1 {
        tree.node(roots[0], DVec3::ZERO)
    } else {
        let origin = 0.5 * (lo + hi);
        let kids: Vec<Value> = roots.iter().filter_map(|&r| tree.node(r, origin)).collect();
        (!kids.is_empty()).then(|| {
            json!({
                "transform": translation(origin),
                "boundingVolume": box_volume(lo, hi, origin),
                "geometricError": error,
                "refine": "REPLACE",
                "children": kids,
            })
        })
    };
    json!({
        "asset": { "version": "1.1", "generator": "texmap terrain export --3d-tiles" },
        // Not drawing the tileset at all leaves out the whole terrain: its error is the extent
        // (the radius of the root's box), so a viewer draws it from as far as it covers pixels.
        "geometricError": (2.0 * error).max(radius).max(1.0),
        "root": root.unwrap_or_else(|| json!({
            "boundingVolume": { "box": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] },
            "geometricError": 0.0,
        })),
    })
}

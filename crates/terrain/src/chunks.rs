//! A chunked level-of-detail quadtree over one RTIN error map, with per-chunk geometric errors
//! and skirts — the layout a renderer picks from by screen-space error.
//!
//! The grid is padded with no-data to `(2^k + 1)²` and one [`ErrorMap`] is built for all of it.
//! A chunk is an aligned cell of that hierarchy: depth 0 is the whole square, depth `d` has
//! `4^d` cells of side `S / 2^d`, and the finest depth `D` has cells of `chunk − 1` samples. A
//! chunk at depth `d` is the RTIN walk of its cell at the error `ε·2^(D−d)` (`ε` the finest
//! level's maximum error) never refined below steps of `2^(D−d)` samples, so every chunk holds at
//! most `2 (chunk − 1)²` triangles whatever its depth. Because chunks are cells of one
//! hierarchy, two neighbours extracted at the same error share their border vertices exactly
//! (the split decision on a shared edge reads one value of the map); neighbours at different
//! depths do not, and that is what the skirts are for.
//!
//! **Geometric error.** Each chunk records the largest error bound of its kept triangles
//! ([`crate::rtin::GridMesh::max_bound`]), a strict bound on the vertical distance of any grid
//! sample under the chunk from its surface. A renderer draws a chunk when
//! `geometric_error · k / distance` ([`screen_space_error`]) is below its pixel tolerance, and its
//! four children otherwise.
//!
//! **Skirts.** Along the chunk's border every edge gets a vertical strip hanging down by
//! `skirt = max(5 · geometric_error, 0.1 · sample spacing of the level)`. Where two chunks of
//! errors `e1 ≤ e2` meet, both border polylines run through the same grid columns and each is
//! within its error of the true samples, so the vertical gap is at most `e1 + e2 ≤ 2 e2`, which
//! the coarser chunk's `5 e2` skirt closes. The factor 5 is Cesium's rule of thumb (peers report
//! gaps from fixed 10 m skirts and spikes at 20x); the floor covers error-free chunks whose
//! T-junctions could still leave sub-pixel cracks. Stitching edges instead (forcing neighbours to
//! one level) was rejected: it couples the selection of neighbouring chunks, which the renderer
//! wants to pick independently.
//!
//! Vertices are in local metres: `x` east, `y` up (the height), `z` south, from the centre of
//! sample (0, 0) ([`crate::dem::Georef::local_metres`]), so geographic grids are metric here;
//! texture coordinates stretch the DEM extent over `[0, 1]²` (`v` down the rows, as glTF).

use crate::dem::Grid;
use crate::error::TerrainError;
use crate::rtin::{ErrorMap, extract, pad_to_rtin};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use texmap_mesh::TriMesh;

/// The screen-space error in pixels of a geometric error seen at `distance` with focal length `k`
/// pixels (Seed 000 Eq. (1)'s `k = n_pxl / (2 tan(ψ/2))`).
pub fn screen_space_error(geometric_error: f32, distance: f32, k: f32) -> f32 {
    geometric_error * k / distance.max(f32::MIN_POSITIVE)
}

/// One chunk of the quadtree.
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    /// Quadtree depth (0 = the whole grid).
    pub depth: u32,
    /// Cell index at this depth (column, row).
    pub ix: u32,
    pub iy: u32,
    /// Sample coordinates of the cell's north-west corner and its side in samples.
    pub x0: u32,
    pub y0: u32,
    pub size: u32,
    /// The error the chunk was extracted at, and the bound it reached (metres).
    pub target_error: f32,
    pub geometric_error: f32,
    /// Skirt depth (metres).
    pub skirt: f32,
    /// Triangles of the surface; the skirt's follow them in `mesh.triangles`.
    pub surface_triangles: u32,
    /// Kept triangles that bridge no-data (coarse levels only).
    pub bridging: u32,
    pub mesh: TriMesh,
}

/// The quadtree of chunks of a grid.
#[derive(Clone, Debug)]
pub struct ChunkTree {
    /// Samples per chunk side (`2^j + 1`).
    pub chunk: u32,
    /// The finest depth.
    pub max_depth: u32,
    /// Error of the finest level (metres).
    pub max_error: f32,
    /// `levels[d]` = the chunks at depth `d` holding terrain, in row-major cell order.
    pub levels: Vec<Vec<Chunk>>,
}

impl ChunkTree {
    /// The four children cells of a chunk (the next depth's `(ix, iy)`), `None` at the finest depth;
    /// children without terrain are absent from [`ChunkTree::get`].
    pub fn children(&self, c: &Chunk) -> Option<[(u32, u32); 4]> {
        (c.depth < self.max_depth).then(|| {
            let (x, y) = (2 * c.ix, 2 * c.iy);
            [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
        })
    }

    /// The chunk at `(depth, ix, iy)`, if it holds terrain.
    pub fn get(&self, depth: u32, ix: u32, iy: u32) -> Option<&Chunk> {
        let l = self.levels.get(depth as usize)?;
        l.binary_search_by_key(&(iy, ix), |c| (c.iy, c.ix))
            .ok()
            .map(|i| &l[i])
    }
}

/// Sizes of the padded grid and the quadtree for a grid of `w x h` and chunks of `chunk` samples.
pub fn layout(w: u32, h: u32, chunk: u32) -> Result<(u32, u32), TerrainError> {
    if !ErrorMap::is_valid_size(chunk) {
        return Err(TerrainError::BadParameter {
            name: "chunk",
            value: chunk.to_string(),
            expected: "2^k + 1 samples (e.g. 65, 129, 257)",
        });
    }
    let n = (w.max(h).max(3) - 1).next_power_of_two() + 1;
    let size = n - 1;
    let cell = (chunk - 1).min(size);
    Ok((n, (size / cell).trailing_zeros()))
}

/// Build the quadtree: an error map of the padded grid, then every chunk of every depth (in
/// parallel; the result does not depend on the thread count).
pub fn build(grid: &Grid, max_error: f32, chunk: u32) -> Result<ChunkTree, TerrainError> {
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(TerrainError::BadParameter {
            name: "max-error",
            value: max_error.to_string(),
            expected: "a finite error ≥ 0 metres",
        });
    }
    let (n, max_depth) = layout(grid.width(), grid.height(), chunk)?;
    let (padded, n2) = pad_to_rtin(grid.heights(), grid.width(), grid.height());
    debug_assert_eq!(n, n2);
    let map = ErrorMap::new(&padded, n);
    Ok(build_from_map(
        grid, &padded, &map, max_error, chunk, max_depth,
    ))
}

/// As [`build`] with the padded heights and their error map given.
pub fn build_from_map(
    grid: &Grid,
    padded: &[f32],
    map: &ErrorMap,
    max_error: f32,
    chunk: u32,
    max_depth: u32,
) -> ChunkTree {
    let levels = (0..=max_depth)
        .map(|d| build_level(grid, padded, map, max_error, max_depth, d))
        .collect();
    ChunkTree {
        chunk,
        max_depth,
        max_error,
        levels,
    }
}

/// Build the quadtree one depth at a time and, within a depth, one band of chunk rows at a time
/// (a band holds at least as many chunks as there are worker threads, so each band is still built
/// in parallel), handing each band's chunks to `sink` in row-major order and dropping them before
/// the next: a database build holds the grid, its error map and one band of chunk meshes, never a
/// whole depth. `sink` sees every depth in order, possibly in several calls. Returns the finest
/// depth.
pub fn build_streaming(
    grid: &Grid,
    max_error: f32,
    chunk: u32,
    mut sink: impl FnMut(u32, Vec<Chunk>) -> Result<(), TerrainError>,
) -> Result<u32, TerrainError> {
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(TerrainError::BadParameter {
            name: "max-error",
            value: max_error.to_string(),
            expected: "a finite error ≥ 0 metres",
        });
    }
    let (n, max_depth) = layout(grid.width(), grid.height(), chunk)?;
    let (padded, _) = pad_to_rtin(grid.heights(), grid.width(), grid.height());
    let map = ErrorMap::new(&padded, n);
    let threads = rayon::current_num_threads().max(1) as u32;
    for d in 0..=max_depth {
        let cells = 1u32 << d;
        let rows_per_band = threads.div_ceil(cells).max(1);
        let mut row = 0;
        while row < cells {
            let rows = row..(row + rows_per_band).min(cells);
            row = rows.end;
            sink(
                d,
                build_rows(grid, &padded, &map, max_error, max_depth, d, rows),
            )?;
        }
    }
    Ok(max_depth)
}

/// The chunks of depth `d` holding terrain, in row-major cell order (built in parallel).
pub fn build_level(
    grid: &Grid,
    padded: &[f32],
    map: &ErrorMap,
    max_error: f32,
    max_depth: u32,
    d: u32,
) -> Vec<Chunk> {
    build_rows(grid, padded, map, max_error, max_depth, d, 0..1u32 << d)
}

/// The chunks of depth `d` in the cell rows `rows` holding terrain, in row-major cell order.
fn build_rows(
    grid: &Grid,
    padded: &[f32],
    map: &ErrorMap,
    max_error: f32,
    max_depth: u32,
    d: u32,
    rows: std::ops::Range<u32>,
) -> Vec<Chunk> {
    let size = map.n() - 1;
    let cells = 1u32 << d;
    let s = size / cells;
    let step = 1u32 << (max_depth - d);
    let target = max_error * step as f32;
    (rows.start * cells..rows.end * cells)
        .into_par_iter()
        .filter_map(|i| {
            let (ix, iy) = (i % cells, i / cells);
            let (x0, y0) = (ix * s, iy * s);
            if x0 >= grid.width() || y0 >= grid.height() {
                return None;
            }
            let gm = extract(map, padded, x0, y0, s, target, step);
            if gm.triangles.is_empty() {
                return None;
            }
            let spacing = grid.georef().spacing_metres(grid.height());
            let floor = 0.1 * (spacing.0.min(spacing.1) as f32) * step as f32;
            let skirt = (5.0 * gm.max_bound).max(floor);
            let surface = gm.triangles.len() as u32;
            let mesh = chunk_mesh(grid, padded, map.n(), &gm, (x0, y0, s), skirt);
            Some(Chunk {
                depth: d,
                ix,
                iy,
                x0,
                y0,
                size: s,
                target_error: target,
                geometric_error: gm.max_bound,
                skirt,
                surface_triangles: surface,
                bridging: gm.bridging,
                mesh,
            })
        })
        .collect()
}

/// Vertex position in local metres (x east, y up, z south) and texture coordinate of a sample.
pub fn vertex(grid: &Grid, x: u32, y: u32, height: f32) -> (Vec3, Vec2) {
    let (e, s) = grid.georef().local_metres(x as f64, y as f64);
    let uv = Vec2::new(
        x as f32 / (grid.width() - 1) as f32,
        y as f32 / (grid.height() - 1) as f32,
    );
    (Vec3::new(e as f32, height, s as f32), uv)
}

/// Turn a grid mesh into positions and uvs, then add the skirt along the cell border.
pub fn chunk_mesh(
    grid: &Grid,
    heights: &[f32],
    n: u32,
    gm: &crate::rtin::GridMesh,
    cell: (u32, u32, u32),
    skirt: f32,
) -> TriMesh {
    let (x0, y0, s) = cell;
    let mut positions = Vec::with_capacity(gm.vertices.len());
    let mut uvs = Vec::with_capacity(gm.vertices.len());
    for &[x, y] in &gm.vertices {
        let (p, uv) = vertex(grid, x, y, heights[(y * n + x) as usize]);
        positions.push(p);
        uvs.push(uv);
    }
    let mut triangles = gm.triangles.clone();
    if skirt > 0.0 {
        let on_side = |v: u32, side: u8| {
            let [x, y] = gm.vertices[v as usize];
            match side {
                0 => y == y0,
                1 => x == x0 + s,
                2 => y == y0 + s,
                _ => x == x0,
            }
        };
        let mut lowered: Vec<u32> = vec![u32::MAX; gm.vertices.len()];
        for t in &gm.triangles {
            for k in 0..3 {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                if !(0..4u8).any(|side| on_side(p, side) && on_side(q, side)) {
                    continue;
                }
                for v in [p, q] {
                    if lowered[v as usize] == u32::MAX {
                        lowered[v as usize] = positions.len() as u32;
                        positions.push(positions[v as usize] - Vec3::new(0.0, skirt, 0.0));
                        uvs.push(uvs[v as usize]);
                    }
                }
                let (pl, ql) = (lowered[p as usize], lowered[q as usize]);
                // The strip under edge p→q, facing outwards (the edge runs the other way round it).
                triangles.push([q, p, pl]);
                triangles.push([q, pl, ql]);
            }
        }
    }
    TriMesh {
        positions,
        triangles,
        uvs: Some(uvs),
        normals: None,
    }
}

//! Export as Cesium's quantized-mesh-1.0 terrain: the format of Cesium World Terrain and of
//! `CesiumTerrainProvider`, which cesium-terrain-builder and martini-based servers produce, so the
//! grid can replace the globe's terrain in CesiumJS (and the engines with Cesium's plug-ins), under
//! any imagery.
//!
//! # Tiling
//! The TMS geographic scheme (EPSG:4326) quantized-mesh uses: level 0 is two tiles of 180° x 180°
//! (west and east hemispheres), each level splits every tile in four, and tile `(x, y)` of level
//! `L` spans longitude `−180 + x·w` and latitude `−90 + y·w` to `+w`, `w = 180°/2^L` (rows count
//! from the south). Both level-0 tiles are always written, so a viewer has the whole globe; below
//! level 0 only the tiles over the grid's extent are, and `layer.json` lists them per level
//! (`available`) so that a viewer asks for no other tile. The finest level is the first whose
//! lattice spacing (`w/64`) reaches the grid's own.
//!
//! # Meshes
//! Each tile samples its 65 x 65 lattice from the grid by bilinear interpolation (through the
//! grid's placement: degrees, UTM or Web Mercator), adds the geoid's undulation when one is given
//! (heights above sea level become the ellipsoidal heights Cesium draws), and is meshed by the
//! RTIN of [`crate::rtin`] with the geometric error Cesium assumes for the level:
//! `6 378 137 m · 2π / 4 / (65 · 2) / 2^L` (CesiumJS's `getEstimatedLevelZeroGeometricErrorFor
//! AHeightmap`, ≈ 77 km at level 0), or the database's own maximum error at the finest level.
//! Lattice points off the grid or on no-data take height 0 (sea level, plus the undulation): at
//! coarse levels a tile is mostly ocean around the grid, as in cesium-terrain-builder's output.
//!
//! # Encoding (quantized-mesh-1.0)
//! Per tile `L/x/y.terrain`, little-endian: the 88-byte header (tile centre in ECEF, height
//! range, bounding sphere, the horizon-occlusion point in ellipsoid-scaled coordinates as
//! CesiumJS's `EllipsoidalOccluder` computes it); the vertex count and the `u`, `v` (0..32767
//! across the tile, `v` north) and height (0..32767 over the range) arrays, each delta- and
//! zig-zag-encoded; the triangle count and the indices, high-water-mark encoded (vertices are
//! numbered in order of first use), 16-bit up to 65,536 vertices, 32-bit past it (after padding
//! to 4 bytes); then the west, south, east and north edge-vertex lists from which viewers hang
//! their skirts; then the `octvertexnormals` extension (id 1): each vertex's normal from the
//! surface's central differences one lattice step either side (across tile edges too, so that
//! neighbouring tiles agree) in local east-north-up metres, turned to ECEF and oct-encoded in
//! two bytes, which CesiumJS lights the terrain with (`requestVertexNormals`).
//! Triangles wind counter-clockwise seen from above. Tiles are written uncompressed, or with
//! [`QuantizedMeshOptions::gzip`] gzip-compressed under the same names (about a third to a half
//! of the bytes), which a server must send with `Content-Encoding: gzip` (CesiumJS asks for the
//! tiles with `Accept-Encoding: gzip` and never inflates them itself); `layer.json` stays plain.
//! The gzip header carries no name or time, so the bytes stay reproducible.
//!
//! The output directory is written atomically (a temporary sibling renamed at the end); the
//! bytes do not depend on the thread count.

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;
use serde_json::json;

use crate::db::{Database, write_dir_atomically};
use crate::dem::Grid;
use crate::error::{TerrainError, io};
use crate::geodesy::{A, F, Placement, ecef};
use crate::geoid::Geoid;
use crate::rtin::{ErrorMap, extract};

/// Lattice samples a side of every tile (2^6 + 1, as Cesium's heightmap tiles).
pub const TILE_SAMPLES: u32 = 65;

/// The geometric error (m) CesiumJS assumes for level 0 of a two-tile geographic terrain.
pub fn level_zero_error() -> f64 {
    A * 2.0 * std::f64::consts::PI * 0.25 / (TILE_SAMPLES as f64 * 2.0)
}

/// Deepest level written at most (tiles of 0.0003°, about 20 m: finer than any grid).
const MAX_LEVEL: u32 = 19;

/// How [`write_quantized_mesh`] writes the terrain.
#[derive(Clone, Copy, Debug, Default)]
pub struct QuantizedMeshOptions<'a> {
    /// The geoid the grid's heights are above (`None`: heights are taken as ellipsoidal).
    pub geoid: Option<&'a Geoid>,
    /// The finest level (default: the first whose lattice is as fine as the grid).
    pub max_level: Option<u32>,
    /// Write each tile gzip-compressed (still named `.terrain`), as cesium-terrain-builder
    /// does: a server sends the bytes as they are with `Content-Encoding: gzip`.
    pub gzip: bool,
}

/// What [`write_quantized_mesh`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedMeshSummary {
    /// Levels written (0 to `levels − 1`).
    pub levels: u32,
    /// Tile files.
    pub tiles: usize,
    /// Triangles over all tiles.
    pub triangles: u64,
    /// Bytes of all files.
    pub bytes: u64,
    /// The grid's extent in degrees: west, south, east, north.
    pub bounds: [f64; 4],
}

/// The grid's height at `(lon, lat)` by bilinear interpolation, `None` off the grid or next to
/// no-data.
fn grid_height(grid: &Grid, placement: Placement, lon: f64, lat: f64) -> Option<f64> {
    let (x, y) = placement.xy(lon, lat);
    let (col, row) = grid.georef().xy_to_sample(x, y);
    let (w, h) = (grid.width() as f64, grid.height() as f64);
    if !(col >= 0.0 && row >= 0.0 && col <= w - 1.0 && row <= h - 1.0) {
        return None;
    }
    let c0 = (col.floor() as u32).min(grid.width() - 2);
    let r0 = (row.floor() as u32).min(grid.height() - 2);
    let (fc, fr) = (col - c0 as f64, row - r0 as f64);
    let hs = grid.heights();
    let at = |c: u32, r: u32| hs[r as usize * grid.width() as usize + c as usize] as f64;
    let top = at(c0, r0) * (1.0 - fc) + at(c0 + 1, r0) * fc;
    let bottom = at(c0, r0 + 1) * (1.0 - fc) + at(c0 + 1, r0 + 1) * fc;
    let v = top * (1.0 - fr) + bottom * fr;
    v.is_finite().then_some(v)
}

/// The grid's extent in degrees (west, south, east, north) and its finest sample spacing in
/// degrees, from its boundary samples.
fn extent(grid: &Grid, placement: Placement) -> ([f64; 4], f64) {
    let (w, h) = (grid.width(), grid.height());
    let g = grid.georef();
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut add = |c: u32, r: u32| {
        let (x, y) = g.sample_xy(c as f64, r as f64);
        let (lon, lat) = placement.lonlat(x, y);
        b = [b[0].min(lon), b[1].min(lat), b[2].max(lon), b[3].max(lat)];
    };
    let step = |n: u32| (n / 64).max(1);
    for c in (0..w).step_by(step(w) as usize).chain([w - 1]) {
        add(c, 0);
        add(c, h - 1);
    }
    for r in (0..h).step_by(step(h) as usize).chain([h - 1]) {
        add(0, r);
        add(w - 1, r);
    }
    // Spacing at the centre: one column and one row step, in degrees.
    let (cc, cr) = ((w / 2) as f64, (h / 2) as f64);
    let lonlat = |c: f64, r: f64| {
        let (x, y) = g.sample_xy(c, r);
        placement.lonlat(x, y)
    };
    let (l0, p0) = lonlat(cc, cr);
    let (l1, p1) = lonlat(cc + 1.0, cr);
    let (l2, p2) = lonlat(cc, cr + 1.0);
    let d_col = (l1 - l0).hypot(p1 - p0);
    let d_row = (l2 - l0).hypot(p2 - p0);
    (b, d_col.min(d_row))
}

/// The inclusive tile ranges `(x0, y0, x1, y1)` of `level` over `bounds`.
fn tile_range(bounds: [f64; 4], level: u32) -> (u32, u32, u32, u32) {
    let w = 180.0 / (1u64 << level) as f64;
    let (nx, ny) = (2u32 << level, 1u32 << level);
    let ix = |lon: f64| (((lon + 180.0) / w).floor().max(0.0) as u32).min(nx - 1);
    let iy = |lat: f64| (((lat + 90.0) / w).floor().max(0.0) as u32).min(ny - 1);
    if level == 0 {
        return (0, 0, 1, 0);
    }
    (ix(bounds[0]), iy(bounds[1]), ix(bounds[2]), iy(bounds[3]))
}

/// Write the database's grid as quantized-mesh terrain into the new directory `out`
/// (`layer.json` and `L/x/y.terrain`). Errors: `out` exists; the grid has no placement on the
/// ellipsoid; a file cannot be written.
pub fn write_quantized_mesh(
    db: &Database,
    out: &Path,
    options: &QuantizedMeshOptions,
) -> Result<QuantizedMeshSummary, TerrainError> {
    let m = &db.manifest;
    let placement = Placement::of(&m.georef).ok_or_else(|| TerrainError::Unsupported {
        source: db.dir.display().to_string(),
        what: format!(
            "quantized-mesh terrain needs the grid placed on the WGS 84 ellipsoid: a geographic, \
             UTM or Web Mercator georeference; this grid's is {:?}",
            m.georef.crs
        ),
    })?;
    let grid = db.grid_mapped()?;
    let (bounds, spacing) = extent(&grid, placement);
    let finest = options.max_level.unwrap_or_else(|| {
        let lattice = |l: u32| 180.0 / (1u64 << l) as f64 / (TILE_SAMPLES - 1) as f64;
        (0..MAX_LEVEL)
            .find(|&l| lattice(l) <= spacing)
            .unwrap_or(MAX_LEVEL)
    });
    if finest > MAX_LEVEL {
        return Err(TerrainError::BadParameter {
            name: "max_level",
            value: finest.to_string(),
            expected: "a level from 0 to 19",
        });
    }
    let leaf_error = m.max_error as f64;
    write_dir_atomically(out, |tmp| {
        let mut summary = QuantizedMeshSummary {
            levels: finest + 1,
            tiles: 0,
            triangles: 0,
            bytes: 0,
            bounds,
        };
        let mut available = Vec::new();
        for level in 0..=finest {
            let (x0, y0, x1, y1) = tile_range(bounds, level);
            available.push(json!([{"startX": x0, "startY": y0, "endX": x1, "endY": y1}]));
            let error = if level == finest {
                leaf_error.min(level_zero_error() / (1u64 << level) as f64)
            } else {
                level_zero_error() / (1u64 << level) as f64
            };
            let tiles: Vec<(u32, u32)> = (x0..=x1)
                .flat_map(|x| (y0..=y1).map(move |y| (x, y)))
                .collect();
            for x in x0..=x1 {
                let dir = tmp.join(format!("{level}/{x}"));
                std::fs::create_dir_all(&dir).map_err(io(&dir))?;
            }
            let written: Vec<Result<(u64, u64), TerrainError>> = tiles
                .par_iter()
                .map(|&(x, y)| {
                    let t = encode_tile(&grid, placement, options.geoid, level, x, y, error);
                    let path = tmp.join(format!("{level}/{x}/{y}.terrain"));
                    let bytes = if options.gzip {
                        gzip(&t.bytes)
                    } else {
                        t.bytes
                    };
                    std::fs::write(&path, &bytes).map_err(io(&path))?;
                    Ok((t.triangles, bytes.len() as u64))
                })
                .collect();
            for w in written {
                let (tris, bytes) = w?;
                summary.tiles += 1;
                summary.triangles += tris;
                summary.bytes += bytes;
            }
        }
        let layer = json!({
            "tilejson": "2.1.0",
            "name": db.dir.file_name().map(|n| n.to_string_lossy().into_owned()),
            "description": match options.geoid {
                Some(g) => format!("texmap terrain; heights above the ellipsoid: the grid's plus the undulation of {}", g.name()),
                None => "texmap terrain; the grid's heights, taken as ellipsoidal".to_string(),
            },
            "version": "1.0.0",
            "format": "quantized-mesh-1.0",
            "extensions": ["octvertexnormals"],
            "scheme": "tms",
            "tiles": ["{z}/{x}/{y}.terrain?v={version}"],
            "projection": "EPSG:4326",
            "bounds": [-180.0, -90.0, 180.0, 90.0],
            "minzoom": 0,
            "maxzoom": finest,
            "available": available,
        });
        let text = serde_json::to_string_pretty(&layer).expect("JSON values serialise");
        let path = tmp.join("layer.json");
        std::fs::write(&path, &text).map_err(io(&path))?;
        summary.bytes += text.len() as u64;
        Ok(summary)
    })
}

/// `bytes` as one gzip member with an empty header (no name, time 0), best compression.
fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::GzBuilder::new().mtime(0).write(
        Vec::with_capacity(bytes.len() / 2),
        flate2::Compression::best(),
    );
    e.write_all(bytes).expect("writing to a Vec cannot fail");
    e.finish().expect("writing to a Vec cannot fail")
}

/// One encoded tile.
struct EncodedTile {
    bytes: Vec<u8>,
    triangles: u64,
}

/// Samples, meshes and encodes tile `(x, y)` of `level` (see the module docs).
fn encode_tile(
    grid: &Grid,
    placement: Placement,
    geoid: Option<&Geoid>,
    level: u32,
    x: u32,
    y: u32,
    max_error: f64,
) -> EncodedTile {
    let n = TILE_SAMPLES;
    let w = 180.0 / (1u64 << level) as f64;
    let (west, south) = (-180.0 + x as f64 * w, -90.0 + y as f64 * w);
    let north = south + w;
    // Lattice rows from the north (row 0) to the south, as the grid's rows run.
    let lonlat = |c: u32, r: u32| {
        (
            west + w * c as f64 / (n - 1) as f64,
            north - w * r as f64 / (n - 1) as f64,
        )
    };
    // The surface: the grid's height (sea level off it) plus the undulation.
    let surface = |lon: f64, lat: f64| {
        let h = grid_height(grid, placement, lon, lat).unwrap_or(0.0);
        h + geoid.and_then(|g| g.undulation(lon, lat)).unwrap_or(0.0)
    };
    let mut heights = vec![0f32; (n * n) as usize];
    for r in 0..n {
        for c in 0..n {
            let (lon, lat) = lonlat(c, r);
            heights[(r * n + c) as usize] = surface(lon, lat) as f32;
        }
    }
    let map = ErrorMap::new(&heights, n);
    let mesh = extract(&map, &heights, 0, 0, n - 1, max_error as f32, 1);
    // Vertices in order of first use (as `extract` numbers them): the high-water mark needs it.
    let verts: Vec<(u32, u32, f64)> = mesh
        .vertices
        .iter()
        .map(|&[c, r]| (c, r, heights[(r * n + c) as usize] as f64))
        .collect();
    let (lo, hi) = verts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.2), hi.max(v.2))
        });
    let quant = |v: f64, lo: f64, hi: f64| -> u16 {
        if hi > lo {
            ((v - lo) / (hi - lo) * 32767.0).round().clamp(0.0, 32767.0) as u16
        } else {
            0
        }
    };
    let u: Vec<u16> = verts
        .iter()
        .map(|v| quant(v.0 as f64, 0.0, (n - 1) as f64))
        .collect();
    let vq: Vec<u16> = verts
        .iter()
        .map(|v| quant((n - 1 - v.1) as f64, 0.0, (n - 1) as f64))
        .collect();
    let hq: Vec<u16> = verts.iter().map(|v| quant(v.2, lo, hi)).collect();
    // ECEF of the vertices as a viewer decodes them (quantised), for the bounding volumes.
    let world: Vec<DVec3> = (0..verts.len())
        .map(|k| {
            let lon = west + w * u[k] as f64 / 32767.0;
            let lat = south + w * vq[k] as f64 / 32767.0;
            let h = lo + (hi - lo) * hq[k] as f64 / 32767.0;
            DVec3::from(ecef(lon, lat, h))
        })
        .collect();
    let (bmin, bmax) = world.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    let sphere_centre = 0.5 * (bmin + bmax);
    let radius = world
        .iter()
        .map(|p| p.distance(sphere_centre))
        .fold(0.0, f64::max);
    let centre = DVec3::from(ecef(west + w / 2.0, south + w / 2.0, 0.5 * (lo + hi)));
    let horizon = horizon_occlusion_point(sphere_centre, &world);

    let mut b = Vec::with_capacity(88 + 12 * verts.len() + 12 * mesh.triangles.len());
    for v in centre.to_array() {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&(lo as f32).to_le_bytes());
    b.extend_from_slice(&(hi as f32).to_le_bytes());
    for v in sphere_centre.to_array() {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&radius.to_le_bytes());
    for v in horizon.to_array() {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&(verts.len() as u32).to_le_bytes());
    for arr in [&u, &vq, &hq] {
        let mut prev = 0i32;
        for &q in arr.iter() {
            b.extend_from_slice(&zigzag(q as i32 - prev).to_le_bytes());
            prev = q as i32;
        }
    }
    let wide = verts.len() > 65_536;
    if wide {
        while b.len() % 4 != 0 {
            b.push(0);
        }
    }
    let put = |b: &mut Vec<u8>, v: u32| {
        if wide {
            b.extend_from_slice(&v.to_le_bytes());
        } else {
            b.extend_from_slice(&(v as u16).to_le_bytes());
        }
    };
    // Counter-clockwise seen from above: in (u, v) with v north, a positive signed area.
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let p = |k: usize| (u[t[k] as usize] as i64, vq[t[k] as usize] as i64);
            let ((ax, ay), (bx, by), (cx, cy)) = (p(0), p(1), p(2));
            let area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
            if area < 0 { [t[0], t[2], t[1]] } else { *t }
        })
        .collect();
    b.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    let mut highest = 0u32;
    for t in &triangles {
        for &i in t {
            put(&mut b, highest - i);
            if i == highest {
                highest += 1;
            }
        }
    }
    let edge = |keep: &dyn Fn(usize) -> bool| -> Vec<u32> {
        (0..verts.len() as u32)
            .filter(|&k| keep(k as usize))
            .collect()
    };
    let lists = [
        edge(&|k| u[k] == 0),
        edge(&|k| vq[k] == 0),
        edge(&|k| u[k] == 32767),
        edge(&|k| vq[k] == 32767),
    ];
    for list in &lists {
        b.extend_from_slice(&(list.len() as u32).to_le_bytes());
        for &k in list {
            put(&mut b, k);
        }
    }
    // The oct-encoded vertex normals extension.
    b.push(1);
    b.extend_from_slice(&(2 * verts.len() as u32).to_le_bytes());
    let step = w / (n - 1) as f64;
    for &(c, r, _) in &verts {
        // Central differences of the surface one lattice step either side, also across the
        // tile's edges, so that neighbouring tiles agree on their shared vertices' normals.
        let (lon, lat) = lonlat(c, r);
        let (de, dn) = metres_per_degree(lat);
        let dh_de = (surface(lon + step, lat) - surface(lon - step, lat)) / (2.0 * step * de);
        let dh_dn = (surface(lon, lat + step) - surface(lon, lat - step)) / (2.0 * step * dn);
        let (sl, cl_) = lon.to_radians().sin_cos();
        let (sp, cp) = lat.to_radians().sin_cos();
        let east = DVec3::new(-sl, cl_, 0.0);
        let north = DVec3::new(-sp * cl_, -sp * sl, cp);
        let up = DVec3::new(cp * cl_, cp * sl, sp);
        let normal = (up - dh_de * east - dh_dn * north).normalize();
        b.extend_from_slice(&oct_encode(normal));
    }
    EncodedTile {
        bytes: b,
        triangles: triangles.len() as u64,
    }
}

/// Metres per degree of longitude and of latitude on the WGS 84 ellipsoid at latitude `lat`.
fn metres_per_degree(lat: f64) -> (f64, f64) {
    let e2 = F * (2.0 - F);
    let s2 = lat.to_radians().sin().powi(2);
    let prime = A / (1.0 - e2 * s2).sqrt();
    let meridian = A * (1.0 - e2) / (1.0 - e2 * s2).powf(1.5);
    let rad = std::f64::consts::PI / 180.0;
    (
        prime * lat.to_radians().cos().max(1e-12) * rad,
        meridian * rad,
    )
}

/// A unit vector in two bytes: octahedral projection folded onto the upper half, each coordinate
/// in 0..=255 (CesiumJS `AttributeCompression.octEncode`).
fn oct_encode(v: DVec3) -> [u8; 2] {
    let p = v / (v.x.abs() + v.y.abs() + v.z.abs());
    let sign = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let (x, y) = if p.z < 0.0 {
        ((1.0 - p.y.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.y))
    } else {
        (p.x, p.y)
    };
    let snorm = |x: f64| ((x.clamp(-1.0, 1.0) * 0.5 + 0.5) * 255.0).round() as u8;
    [snorm(x), snorm(y)]
}

/// Zig-zag encoding of a delta: small magnitudes of either sign become small codes.
fn zigzag(v: i32) -> u16 {
    ((v << 1) ^ (v >> 31)) as u16
}

/// The horizon-occlusion point of a tile, in ellipsoid-scaled coordinates: on the ray from the
/// earth's centre through `direction`, the nearest point that is below a viewer's horizon only
/// when every position is (CesiumJS `EllipsoidalOccluder.computeHorizonCullingPoint`). When no
/// such point exists (a position 90° or more from `direction`: the level-0 and level-1 tiles),
/// CesiumJS has none; the file needs one, so it is put 1000 earth radii out along `direction`,
/// where it is visible from every viewer on that side of the earth, and the tile is culled only
/// from the far side.
fn horizon_occlusion_point(direction: DVec3, positions: &[DVec3]) -> DVec3 {
    let b = A * (1.0 - F);
    let scale = DVec3::new(1.0 / A, 1.0 / A, 1.0 / b);
    let dir = (direction * scale).normalize_or_zero();
    const FAR: f64 = 1000.0;
    let mut magnitude: f64 = 0.0;
    for p in positions {
        let s = *p * scale;
        let mag2 = s.length_squared().max(1.0);
        let mag = mag2.sqrt();
        let unit = s.normalize_or_zero();
        let cos_alpha = unit.dot(dir);
        let sin_alpha = unit.cross(dir).length();
        let cos_beta = 1.0 / mag;
        let sin_beta = (mag2 - 1.0).sqrt() * cos_beta;
        let m = 1.0 / (cos_alpha * cos_beta - sin_alpha * sin_beta);
        if !(m.is_finite() && m > 0.0) {
            return dir * FAR;
        }
        magnitude = magnitude.max(m);
    }
    dir * magnitude.min(FAR)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_alternates_signs() {
        let codes: Vec<u16> = [0, -1, 1, -2, 2, 32767, -32767].map(zigzag).to_vec();
        assert_eq!(codes, [0, 1, 2, 3, 4, 65534, 65533]);
    }

    #[test]
    fn oct_encoding_round_trips_within_its_quantum() {
        // Decoding as CesiumJS's octDecode does; 8 bits per coordinate: about 1° at worst.
        let decode = |[x, y]: [u8; 2]| {
            let f = |b: u8| b as f64 / 255.0 * 2.0 - 1.0;
            let (x, y) = (f(x), f(y));
            let z = 1.0 - x.abs() - y.abs();
            let (x, y) = if z < 0.0 {
                let s = |v: f64| if v < 0.0 { -1.0 } else { 1.0 };
                ((1.0 - y.abs()) * s(x), (1.0 - x.abs()) * s(y))
            } else {
                (x, y)
            };
            DVec3::new(x, y, z).normalize()
        };
        for v in [
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::new(0.3, -0.5, 0.8),
            DVec3::new(-0.7, 0.1, -0.7),
        ] {
            let v = v.normalize();
            let back = decode(oct_encode(v));
            assert!(back.dot(v) > 1.5f64.to_radians().cos(), "{v} -> {back}");
        }
        assert_eq!(oct_encode(DVec3::Z), [128, 128]);
    }

    #[test]
    fn level_zero_error_is_cesiums() {
        // CesiumJS: 6378137 · 2π · 0.25 / (65 · 2) ≈ 77067.34 m.
        assert!((level_zero_error() - 77_067.34).abs() < 0.01);
    }

    #[test]
    fn tile_ranges_follow_tms_rows_from_the_south() {
        // Mount Washington's SRTM tile at level 8: tiles of 0.703125°.
        let b = [-72.0, 44.0, -71.0, 45.0];
        let (x0, y0, x1, y1) = tile_range(b, 8);
        assert_eq!((x0, x1), (153, 155));
        assert_eq!((y0, y1), (190, 192));
        assert_eq!(tile_range(b, 0), (0, 0, 1, 0));
        assert_eq!(tile_range(b, 1), (1, 1, 1, 1));
    }

    #[test]
    fn horizon_point_sees_a_flat_patch_from_above() {
        // Points on the equator around longitude 0: the point lies on the x axis beyond the
        // surface, far enough that the points at ±1° are not hidden behind the horizon.
        let pts: Vec<DVec3> = [-1.0f64, 0.0, 1.0]
            .iter()
            .map(|&lon| DVec3::from(ecef(lon, 0.0, 0.0)))
            .collect();
        let h = horizon_occlusion_point(pts[1], &pts);
        assert!(h.y.abs() < 1e-12 && h.z.abs() < 1e-12);
        // In scaled space the horizon of a unit sphere seen from distance d is at angle
        // acos(1/d) from the view direction: the points at ±1° must be within it.
        assert!(h.x > 1.0);
        assert!((1.0 / h.x).acos() >= 1f64.to_radians() - 1e-12);
        // A hemisphere: no such point; far out along the direction instead.
        let pts: Vec<DVec3> = [-90.0f64, 0.0, 90.0]
            .iter()
            .map(|&lon| DVec3::from(ecef(lon, 0.0, 0.0)))
            .collect();
        let h = horizon_occlusion_point(pts[1], &pts);
        assert!(h.x >= 999.0, "{h}");
    }
}

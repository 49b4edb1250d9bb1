//! # texmap-terrain — terrain databases for Seed 000
//!
//! Seed 000's visual system drew terrain generated from a real area's elevation grid, draped with
//! geospecific textures (GST) made from aerial photographs. This crate builds that database:
//!
//! - [`dem`]: elevation grids with their georeference and no-data — GeoTIFF (strips or tiles, chunk
//!   by chunk, BigTIFF, GeoKeys, PixelIsArea/PixelIsPoint, GDAL no-data), ESRI ASCII, SRTM `.hgt`,
//!   DTED levels 0–2 (checksums verified), ESRI GridFloat `.flt` and BIL `.bil` (with the `.prj`),
//!   16-bit and Terrain-RGB PNG, GDAL VRTs composited from their sources as GDAL composites them
//!   ([`dem::vrt`]); geographic grids become local metres with the latitude-dependent spacing.
//! - [`rtin`]: a right-triangulated irregular network with an *exact* per-triangle error bound
//!   (every grid sample within the maximum error of the mesh), holes where the data has none.
//! - [`chunks`]: a chunked level-of-detail quadtree cut from one error map, each chunk with its
//!   geometric error (for selection by screen-space error) and skirts sized 5x that error.
//! - [`photo`]: orthophotos as row sources — a GeoTIFF of any size read a band of rows at a time
//!   (any band count, wide samples stretched min-max or between percentiles with a gamma, no-data
//!   and alpha bands transparent), a GDAL VRT and a mosaic of several tiles (as `gdalbuildvrt`
//!   mosaics them, later tiles winning, each tile's rows read only while the rows asked for cross
//!   it), PNG and JPEG whole.
//! - [`gst`]: the orthophoto placed by georeference (or stretched), the shaded relief under it
//!   where it does not cover, cut into a pyramid of 256² maps written map by map; Seed 000
//!   Eq. (5)–(7) decide which maps are resident in a budgeted cache with counters.
//! - [`db`]: the database directory (JSON manifest, chunks, tiles, the grid), built atomically, and
//!   the whole-terrain mesh at any error for glTF/OBJ export (through `texmap-mesh`).
//! - [`view`]: the flight view — an aircraft camera (eye, altitude, heading, pitch, roll), chunks
//!   chosen by screen-space error and frustum culling and read from the database under a byte
//!   budget (the grid mapped, not read), drawn through texmap-raster with any
//!   texmap-core sampler (nearest, bilinear, trilinear, the span sampler with 3x3 or 4x4 banks,
//!   quadratic 3x3, anisotropic), per-frame statistics and optional haze.
//! - [`tiles3d`]: the database as OGC 3D Tiles 1.1 (`tileset.json` and a glTF per chunk, placed
//!   on the WGS 84 ellipsoid through [`geodesy`]) for Cesium and the engines that stream it;
//!   [`geoid`] turns heights above sea level into ellipsoidal heights there (EGM96 and other
//!   geoid grids from PROJ's `.gtx` or GeoTIFF files); [`qmesh`] writes Cesium's
//!   quantized-mesh-1.0 terrain (`layer.json` and a tile pyramid) for `CesiumTerrainProvider`.
//! - [`vector`]: GeoJSON overlays (points, lines, polygons with simplestyle colours) drawn into
//!   the texture's finest level, placed by their coordinate system.
//! - [`relief`]: shaded relief (height colours lit by a `gdaldem`-compatible hillshade), the
//!   texture of a database built without a photo.
//! - [`models`]: textured OBJ models placed on the terrain by georeference and a built-in tree
//!   billboard, drawn after the terrain with the same samplers and depth-tested against it.
//! - [`track`]: recorded flights (GPX tracks and routes, IGC flight logs) replayed as flight
//!   paths: the track's clock, heading along the track, a coordinated turn's bank.
//! - [`viewshed`]: what an observer on the terrain sees — `gdal_viewshed`'s reference-plane
//!   sweep (bit for bit GDAL 3.6's, or with the cells next to the observer seen as they are) and
//!   exact sight lines, with curvature and refraction; written as GeoTIFF by
//!   [`dem::geotiff_writer`].
//! - [`contour_lines`]: vector contour lines of a grid as GeoJSON or shapefiles, equal to
//!   `gdal_contour`'s.
//! - [`flight`]: flight paths — CSV/JSON path files (a bad line is named), orbits, and the
//!   built-in study path (look-down, low, grazing, turn, slow pass).
//!
//! Coordinates: vertices are in metres, `x` east, `y` up, `z` south (rows), from the centre of
//! sample (0, 0); texture coordinates span the grid's extent, `v` down the rows as in glTF.
//! Depends on texmap-core (coverage, Eq. 5–7, samplers), texmap-raster (the flight view, the crack test) and texmap-mesh;
//! never on the reference ray tracer.
//!
//! ```
//! use texmap_terrain::dem::{Georef, Grid};
//! use texmap_terrain::{chunks, db};
//!
//! // A 65 x 65 paraboloid bowl, 10 m between samples, with one no-data sample.
//! let n = 65u32;
//! let mut h: Vec<f32> = (0..n * n)
//!     .map(|i| {
//!         let (x, y) = ((i % n) as f32 - 32.0, (i / n) as f32 - 32.0);
//!         0.05 * (x * x + y * y)
//!     })
//!     .collect();
//! h[10 * 65 + 10] = f32::NAN;
//! let grid = Grid::new("bowl", n, n, h, Georef::local(10.0))?;
//!
//! // One mesh with every sample within 0.5 m; the no-data sample is a hole, not a spike.
//! let mesh = db::whole_mesh(&grid, 0.5)?;
//! assert!(mesh.triangles.len() < 2 * 64 * 64);
//! assert!(mesh.positions.iter().all(|p| p.y.is_finite() && p.y >= 0.0));
//!
//! // A quadtree of 33-sample chunks: depth 0 (one chunk) and depth 1 (four), errors doubling upwards.
//! let tree = chunks::build(&grid, 0.5, 33)?;
//! assert_eq!(tree.levels[1].len(), 4);
//! assert!(tree.levels[0][0].geometric_error <= 1.0);
//! # Ok::<(), texmap_terrain::TerrainError>(())
//! ```

pub mod chunks;
pub mod contour_lines;
pub mod db;
pub mod dem;
pub mod dem_products;
pub mod error;
pub mod flight;
pub mod geodesy;
pub mod geoid;
pub mod greedy;
pub mod gst;
pub mod models;
pub mod photo;
pub mod qmesh;
pub mod relief;
pub mod rtin;
pub mod shapefile;
pub mod stream;
pub mod tiles3d;
pub mod track;
pub mod vector;
pub mod view;
pub mod viewshed;

pub use error::TerrainError;

//! The flight view: the terrain database drawn from an aircraft with any Seed 000 sampler.
//!
//! A frame is three steps:
//!
//! 1. **Camera** ([`FlightCamera`]): eye position in the grid's georeference, altitude above sea
//!    level, heading, pitch, roll and field of view become a texmap-core [`Camera`] in the
//!    terrain's local metres (`x` east, `y` up, `z` south; see [`crate::chunks`]). Heading is
//!    measured clockwise from north, pitch is positive up, roll is positive right wing down.
//!    The camera's right axis is `(cos h, 0, sin h)` whatever the pitch, so a pitch of exactly
//!    ±90° is well defined (looking straight down, heading gives the image's up direction) and is
//!    accepted without clamping; a pitch beyond ±90° is an error (use heading + 180° instead).
//! 2. **Chunk selection** ([`FlightTerrain::select`]): a walk of the quadtree from the root that
//!    drops chunks whose bounding box lies outside the view frustum and refines a chunk while its
//!    screen-space error `geometric_error · k / distance` ([`crate::chunks::screen_space_error`],
//!    `k` the focal length in pixels of Seed 000 Eq. (1), `distance` from the eye to the chunk's
//!    bounding box) exceeds the pixel tolerance. Neighbours of different depths are closed by the
//!    chunks' skirts, so selection needs no neighbour constraint.
//! 3. **Draw** ([`FlightTerrain::render`]): the selected chunk meshes (surface and skirts) are
//!    concatenated into one mesh and drawn with one [`Framebuffer::draw_textured`] call, so the
//!    rasteriser bins and shades the whole frame in one parallel pass (one call per chunk would
//!    pay the tile pass per chunk; the streamed source does that, see below). The texture is one whole-terrain [`MipTexture`] (clamped at
//!    the edges) sampled by any texmap-core [`Sampler`]: nearest, bilinear, trilinear (Eq. 4),
//!    span 3x3 / 4x4 (Eq. 8–10, the rasteriser's 2x2 quad is the span), quadratic 3x3 or
//!    anisotropic.
//!
//! **Haze** ([`apply_haze`], off unless called): a post-pass on the finished frame that blends
//! each pixel toward a sky colour by Koschmieder's transmittance over its eye distance; a sky
//! alone is just the frame's background colour ([`ViewOptions::background`]).
//!
//! **Texture residency.** Two texture sources. [`FlightTerrain::render`] samples one whole-
//! terrain [`MipTexture`]: one level of the database's GST pyramid (the finest whose side fits a
//! caller's limit, [`Database::texture`]) assembled once, so its memory grows with the square of
//! that side (16 bytes a texel plus mips: 1.4 GB for 8192², and more than [`MipTexture`]'s
//! 16384 side cannot be held at all). [`FlightTerrain::render_streamed`] ([`crate::stream`])
//! instead textures each chunk from the GST maps at the level its on-screen size needs (Seed 000
//! Eq. 7's rule), through the map cache ([`gst::GstCache`], loads counted) and a
//! least-recently-used set of per-chunk textures, both under one byte budget, with one draw
//! call per chunk; the photo's size then bounds only the disk. For the whole-texture frame the
//! maps Seed 000's active area (Eq. 5–7) asks for at the eye are counted
//! ([`FrameStats::maps_needed`]) and can be made resident in a separate cache
//! ([`FlightTerrain::make_resident`]) to measure what a cache-fed renderer would hold.
//!
//! **Chunks.** [`FlightTerrain::open`] (and [`FlightTerrain::from_database`], with a default
//! budget) does not read the grid or rebuild the quadtree: selection runs on the boxes and errors
//! the manifest records per chunk, the grid is mapped ([`Grid::map_file`]) so the ground under the
//! eye touches a few pages, and a frame's chunk meshes are read from their files when it selects
//! them ([`FlightTerrain::prepare`], misses read in parallel), kept in a least-recently-used set
//! under a byte budget ([`ChunkCacheStats`] in [`FrameStats::chunk_cache`]). The files hold the
//! meshes the in-memory build makes, so a paged frame is the resident frame byte for byte. A
//! terrain made with [`FlightTerrain::new`] holds every mesh; so does a database whose manifest
//! predates the per-chunk boxes (its quadtree is rebuilt from the grid).
//!
//! Frames are deterministic: selection is a sequential walk, and the rasteriser's output does not
//! depend on the thread count.
//!
//! ```
//! use texmap_raster::Framebuffer;
//! use texmap_terrain::chunks;
//! use texmap_terrain::dem::{Georef, Grid};
//! use texmap_terrain::view::{self, FlightCamera, FlightTerrain, FrameScratch, ViewOptions};
//!
//! // A 129² tilted plane, 10 m between samples, and a grey-ramp photo.
//! let n = 129u32;
//! let h = (0..n * n).map(|i| 100.0 + 0.2 * (i % n) as f32).collect();
//! let grid = Grid::new("tilt", n, n, h, Georef::local(10.0))?;
//! let tree = chunks::build(&grid, 0.5, 33)?;
//! let photo = image::RgbaImage::from_fn(128, 128, |x, _| image::Rgba([x as u8 * 2, 90, 90, 255]));
//! let terrain = FlightTerrain::new(grid, tree, view::texture_from_rgba(&photo)?);
//!
//! // Above the centre, looking north and down, 160 x 120, span 3x3 sampler.
//! let eye = FlightCamera { width: 160, height: 120, ..FlightCamera::over(terrain.grid()) };
//! let opts = ViewOptions { sampler: view::sampler_by_name("span3").unwrap(), ..Default::default() };
//! let mut fb = Framebuffer::new(160, 120)?;
//! let stats = terrain.render(&eye, &opts, &mut fb, &mut FrameScratch::default())?;
//! assert!(stats.chunks_drawn >= 1 && stats.triangles > 0);
//! // Looking 30° down from a quarter of the extent up, the terrain fills the bottom row.
//! assert!(fb.depth_at(80, 119).is_some_and(|d| d.is_finite()));
//!
//! // Errors rather than panics: an eye under the ground.
//! let low = FlightCamera { altitude: 0.0, ..eye };
//! assert!(low.camera(terrain.grid()).is_err());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::chunks::{ChunkTree, screen_space_error};
use crate::db::{ChunkEntry, Database};
use crate::dem::Grid;
use crate::error::TerrainError;
use crate::gst;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use texmap_core::camera::{Camera, CameraError};
use texmap_core::coverage::ActiveArea;
use texmap_core::mip::{MipError, MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};
use texmap_mesh::TriMesh;
use texmap_raster::{
    Cull, DrawState, DrawStats, Framebuffer, Mesh, MipSampler, QuadSampler, RasterError,
};

/// Why a flight view could not be set up or drawn.
#[derive(Debug)]
#[non_exhaustive]
pub enum ViewError {
    /// A camera parameter is NaN or infinite.
    NonFinite {
        field: &'static str,
        value: f64,
    },
    /// The eye's map position lies outside the grid.
    EyeOutside {
        x: f64,
        y: f64,
        col: f64,
        row: f64,
        width: u32,
        height: u32,
    },
    /// The eye is at or below the ground under it.
    BelowGround {
        altitude: f64,
        ground: f64,
        col: f64,
        row: f64,
    },
    /// A parameter outside its range (pitch beyond ±90°, field of view, image size, tolerance).
    BadParameter {
        name: &'static str,
        value: String,
        expected: &'static str,
    },
    Camera(CameraError),
    Raster(RasterError),
    Texture(MipError),
    Terrain(TerrainError),
    /// A streamed texture budget below what the frame needs at the coarsest level.
    TextureBudget {
        budget: u64,
        needed: u64,
        what: &'static str,
    },
}

impl std::fmt::Display for ViewError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ViewError::NonFinite { field, value } => {
                write!(
                    f,
                    "flight camera: {field} is {value}, expected a finite number"
                )
            }
            ViewError::EyeOutside {
                x,
                y,
                col,
                row,
                width,
                height,
            } => write!(
                f,
                "flight camera: eye ({x}, {y}) is at sample ({col:.2}, {row:.2}), outside the \
                 {width} x {height} grid (expected columns 0..={} and rows 0..={})",
                width - 1,
                height - 1
            ),
            ViewError::BelowGround {
                altitude,
                ground,
                col,
                row,
            } => write!(
                f,
                "flight camera: altitude {altitude} m is not above the ground ({ground:.2} m) at \
                 sample ({col:.2}, {row:.2})"
            ),
            ViewError::BadParameter {
                name,
                value,
                expected,
            } => write!(f, "flight view: {name} = {value}, expected {expected}"),
            ViewError::Camera(e) => write!(f, "flight camera: {e}"),
            ViewError::Raster(e) => write!(f, "flight view: {e}"),
            ViewError::Texture(e) => write!(f, "flight view texture: {e}"),
            ViewError::Terrain(e) => write!(f, "{e}"),
            ViewError::TextureBudget {
                budget,
                needed,
                what,
            } => write!(
                f,
                "flight view: texture budget of {budget} bytes is too small for {what} \
                 (about {needed} bytes needed; raise the budget)"
            ),
        }
    }
}

impl std::error::Error for ViewError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ViewError::Camera(e) => Some(e),
            ViewError::Raster(e) => Some(e),
            ViewError::Texture(e) => Some(e),
            ViewError::Terrain(e) => Some(e),
            _ => None,
        }
    }
}

impl From<TerrainError> for ViewError {
    fn from(e: TerrainError) -> Self {
        ViewError::Terrain(e)
    }
}

impl From<RasterError> for ViewError {
    fn from(e: RasterError) -> Self {
        ViewError::Raster(e)
    }
}

/// The sampler names of the command line: `nearest`, `bilinear`, `trilinear`, `span3`, `span4`,
/// `aniso` (anisotropic, at most 16 taps per side), `quadratic3` (quadratic interpolation on
/// each level's 3x3 neighbourhood, trilinear's levels).
pub fn sampler_by_name(name: &str) -> Option<Sampler> {
    Some(match name {
        "nearest" => Sampler::Nearest,
        "bilinear" => Sampler::Bilinear,
        "trilinear" => Sampler::Trilinear,
        "span3" => Sampler::Span(Banks::K3),
        "span4" => Sampler::Span(Banks::K4),
        "aniso" => Sampler::Anisotropic { max_taps: 16 },
        "quadratic3" => Sampler::Quadratic3,
        _ => return None,
    })
}

/// The names [`sampler_by_name`] accepts.
pub const SAMPLER_NAMES: [&str; 7] = [
    "nearest",
    "bilinear",
    "trilinear",
    "span3",
    "span4",
    "aniso",
    "quadratic3",
];

/// An aircraft's view.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightCamera {
    /// Eye position in the grid's georeference coordinates ([`crate::dem::Georef::sample_xy`]).
    pub eye_x: f64,
    pub eye_y: f64,
    /// Metres above sea level (the grid's height datum).
    pub altitude: f64,
    /// Degrees clockwise from north (90 = east).
    pub heading_deg: f64,
    /// Degrees above the horizon (negative looks down), within ±90.
    pub pitch_deg: f64,
    /// Degrees, positive right wing down (the horizon turns anticlockwise in the image).
    pub roll_deg: f64,
    /// Horizontal field of view, degrees (default 45).
    pub hfov_deg: f64,
    /// Image size (default 1024 x 768).
    pub width: u32,
    pub height: u32,
}

impl FlightCamera {
    /// The default view of a grid: above its centre at the ground height there plus a quarter of
    /// the grid's smaller extent (at least 10 m), heading north, pitch −30°, no roll, 45°,
    /// 1024 x 768.
    pub fn over(grid: &Grid) -> FlightCamera {
        let g = grid.georef();
        let (c, r) = (
            0.5 * (grid.width() - 1) as f64,
            0.5 * (grid.height() - 1) as f64,
        );
        let (x, y) = g.sample_xy(c, r);
        let (e0, s0) = g.local_metres(0.0, 0.0);
        let (e1, s1) = g.local_metres((grid.width() - 1) as f64, (grid.height() - 1) as f64);
        let extent = (e1 - e0).abs().min((s1 - s0).abs());
        let ground = ground_height(grid, c, r).unwrap_or_else(|| grid.height_range().1 as f64);
        FlightCamera {
            eye_x: x,
            eye_y: y,
            altitude: ground + (0.25 * extent).max(10.0),
            heading_deg: 0.0,
            pitch_deg: -30.0,
            roll_deg: 0.0,
            hfov_deg: 45.0,
            width: 1024,
            height: 768,
        }
    }

    /// The view's camera in the grid's local metres. Errors: a non-finite value, an eye outside
    /// the grid or not above the ground under it (bilinear over the finite samples of the cell;
    /// over no-data the check is skipped), `|pitch| > 90°`, a field of view outside `(0°, 180°)`,
    /// a bad image size.
    pub fn camera(&self, grid: &Grid) -> Result<Camera, ViewError> {
        for (field, value) in [
            ("eye x", self.eye_x),
            ("eye y", self.eye_y),
            ("altitude", self.altitude),
            ("heading", self.heading_deg),
            ("pitch", self.pitch_deg),
            ("roll", self.roll_deg),
            ("field of view", self.hfov_deg),
        ] {
            if !value.is_finite() {
                return Err(ViewError::NonFinite { field, value });
            }
        }
        if self.pitch_deg.abs() > 90.0 {
            return Err(ViewError::BadParameter {
                name: "pitch",
                value: format!("{}°", self.pitch_deg),
                expected: "−90° ≤ pitch ≤ 90° (turn the heading by 180° to look behind)",
            });
        }
        let g = grid.georef();
        let (col, row) = g.xy_to_sample(self.eye_x, self.eye_y);
        let (w, h) = (grid.width(), grid.height());
        if !(col >= 0.0 && row >= 0.0 && col <= (w - 1) as f64 && row <= (h - 1) as f64) {
            return Err(ViewError::EyeOutside {
                x: self.eye_x,
                y: self.eye_y,
                col,
                row,
                width: w,
                height: h,
            });
        }
        if let Some(ground) = ground_height(grid, col, row)
            && self.altitude <= ground
        {
            return Err(ViewError::BelowGround {
                altitude: self.altitude,
                ground,
                col,
                row,
            });
        }
        let (e, s) = g.local_metres(col, row);
        let eye = DVec3::new(e, self.altitude, s);
        let (hd, p, r) = (
            self.heading_deg.to_radians(),
            self.pitch_deg.to_radians(),
            self.roll_deg.to_radians(),
        );
        // Heading 0 looks north (−z), 90° east (+x); the right axis stays horizontal at any pitch.
        let forward = DVec3::new(hd.sin() * p.cos(), p.sin(), -hd.cos() * p.cos());
        let right = DVec3::new(hd.cos(), 0.0, hd.sin());
        let up = right.cross(forward);
        // Roll right wing down: the camera's up tilts toward its right.
        let up = up * r.cos() + right * r.sin();
        let cam = Camera::perspective_look_at(
            eye.as_vec3(),
            (eye + forward).as_vec3(),
            up.as_vec3(),
            self.hfov_deg as f32,
            self.width,
            self.height,
        )
        .map_err(ViewError::Camera)?;
        // Depth is eye-space distance (not 1/z), so a fixed 0.1 m near plane costs no precision.
        cam.with_clip(0.1, f32::INFINITY).map_err(ViewError::Camera)
    }
}

/// Ground height at fractional sample `(col, row)`: bilinear over the cell's finite samples
/// (weights renormalised), `None` where all four are no-data.
pub fn ground_height(grid: &Grid, col: f64, row: f64) -> Option<f64> {
    let (w, h) = (grid.width(), grid.height());
    let c0 = (col.floor().max(0.0) as u32).min(w - 2);
    let r0 = (row.floor().max(0.0) as u32).min(h - 2);
    let (fx, fy) = (
        (col - c0 as f64).clamp(0.0, 1.0),
        (row - r0 as f64).clamp(0.0, 1.0),
    );
    let mut sum = 0.0;
    let mut wsum = 0.0;
    for (dc, dr, wt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let v = grid.at(c0 + dc, r0 + dr);
        if v.is_finite() && wt > 0.0 {
            sum += wt * v as f64;
            wsum += wt;
        }
    }
    (wsum > 0.0).then(|| sum / wsum)
}

/// An axis-aligned box in local metres.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub(crate) fn of(points: &[Vec3]) -> Aabb {
        let mut b = Aabb {
            min: Vec3::splat(f32::INFINITY),
            max: Vec3::splat(f32::NEG_INFINITY),
        };
        for &p in points {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }

    /// Euclidean distance from `p` to the box (0 inside).
    pub fn distance(&self, p: Vec3) -> f32 {
        let d = (self.min - p).max(p - self.max).max(Vec3::ZERO);
        d.length()
    }

    fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }
}

/// The view frustum's five planes (four sides and the eye plane), `n · (p − eye) ≤ 0` inside.
pub(crate) struct Frustum {
    eye: Vec3,
    normals: [Vec3; 5],
}

impl Frustum {
    pub(crate) fn new(cam: &Camera) -> Frustum {
        let k = cam.scale();
        let tx = 0.5 * cam.width() as f32 / k;
        let ty = 0.5 * cam.height() as f32 / k;
        let (f, r, u) = (cam.forward(), cam.right(), cam.up());
        Frustum {
            eye: cam.eye(),
            normals: [r - f * tx, -r - f * tx, u - f * ty, -u - f * ty, -f],
        }
    }

    /// True when the box lies entirely outside one plane (conservative: may keep a box that is
    /// outside the frustum near its edges, never drops one that is inside).
    pub(crate) fn culls(&self, b: &Aabb) -> bool {
        let c = b.corners();
        self.normals
            .iter()
            .any(|n| c.iter().all(|&p| n.dot(p - self.eye) > 0.0))
    }
}

/// A chunk chosen for a frame: its depth and its index in `tree.levels[depth]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ChunkRef {
    pub depth: u32,
    pub index: usize,
}

/// The chunks of one frame and what the walk did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    /// Chunks to draw, nearest first (by the distance from the eye to their bounding boxes, ties
    /// in walk order): the rasteriser tests depth before it samples, so front-to-back order
    /// spends no texture reads on hidden terrain where near chunks cover far ones.
    pub chunks: Vec<ChunkRef>,
    /// Chunks whose error and frustum were tested.
    pub visited: u32,
    /// Chunks dropped by frustum culling (their subtrees are not visited).
    pub culled: u32,
    /// Drawn chunks per depth (`chunks_per_level[d]`, one entry per depth of the tree).
    pub chunks_per_level: Vec<u32>,
}

/// Per-frame statistics (integer counts: identical for any thread count).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameStats {
    pub chunks_drawn: u32,
    pub chunks_visited: u32,
    pub chunks_culled: u32,
    pub chunks_per_level: Vec<u32>,
    /// Triangles submitted (surfaces and skirts) and the surfaces' share.
    pub triangles: u64,
    pub surface_triangles: u64,
    /// Of the submitted triangles: binned to a tile, back-facing, clipped at the near plane.
    pub triangles_binned: u64,
    pub triangles_backface: u64,
    pub triangles_clipped: u64,
    /// Side of the whole-terrain texture (level 0 of its pyramid) and its pyramid's bytes.
    pub texture_side: u32,
    pub texture_bytes: u64,
    /// GST maps Seed 000's active area (Eq. 5–7) needs at the eye, when the database has maps.
    pub maps_needed: Option<u64>,
    /// Streamed frames only ([`crate::stream`]): GST maps resident in the cache after the frame,
    /// maps loaded during it, bytes the stream holds (maps and chunk textures) and the chunk
    /// textures' share of them. (`texture_side` is then the finest level drawn and
    /// `texture_bytes` the bytes of the frame's chunk textures.)
    pub maps_resident: Option<u64>,
    pub maps_loaded: Option<u64>,
    pub cache_bytes: Option<u64>,
    pub chunk_texture_bytes: Option<u64>,
    /// Paged terrains only ([`FlightTerrain::open`]): the chunk-mesh cache after the frame
    /// (its counters accumulate over the terrain's frames).
    pub chunk_cache: Option<ChunkCacheStats>,
}

/// Options of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewOptions {
    /// Refine a chunk while its screen-space error exceeds this many pixels (default 1).
    pub pixel_error: f32,
    pub sampler: Sampler,
    /// Colour where no terrain is drawn (sRGB8 RGBA; default transparent black). A sky colour is
    /// just an opaque background.
    pub background: [u8; 4],
}

impl ViewOptions {
    /// Errors: a pixel tolerance that is not a finite number > 0.
    pub fn check(&self) -> Result<(), ViewError> {
        if !(self.pixel_error.is_finite() && self.pixel_error > 0.0) {
            return Err(ViewError::BadParameter {
                name: "pixel error",
                value: self.pixel_error.to_string(),
                expected: "a finite tolerance > 0 pixels",
            });
        }
        Ok(())
    }
}

impl Default for ViewOptions {
    fn default() -> Self {
        ViewOptions {
            pixel_error: 1.0,
            sampler: Sampler::Trilinear,
            background: [0, 0, 0, 0],
        }
    }
}

/// Reusable buffers for the concatenated frame mesh.
#[derive(Clone, Debug, Default)]
pub struct FrameScratch {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
}

impl FrameScratch {
    /// Empty the buffers (keeping their capacity).
    pub(crate) fn clear(&mut self) {
        self.positions.clear();
        self.uvs.clear();
        self.triangles.clear();
    }

    /// Append `m` with its uvs mapped by `uv` (zero uvs when it has none); returns the index of
    /// its first triangle in the concatenation.
    pub(crate) fn append(&mut self, m: &TriMesh, uv: impl Fn(Vec2) -> Vec2) -> u32 {
        let first = self.triangles.len() as u32;
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&m.positions);
        match &m.uvs {
            Some(u) => self.uvs.extend(u.iter().map(|&p| uv(p))),
            None => self
                .uvs
                .extend(std::iter::repeat_n(Vec2::ZERO, m.positions.len())),
        }
        self.triangles
            .extend(m.triangles.iter().map(|t| t.map(|v| v + base)));
        first
    }

    /// The concatenation as a raster mesh.
    pub(crate) fn mesh(&self) -> Result<Mesh<'_>, ViewError> {
        Ok(Mesh::new(&self.positions, &self.triangles)?.with_uvs(&self.uvs)?)
    }
}

/// The boxes of manifest entries (an entry without one gets an empty box at the origin;
/// [`FlightTerrain::open`] pages only manifests whose entries all have one).
fn boxes(chunks: &[Vec<ChunkEntry>]) -> Vec<Vec<Aabb>> {
    chunks
        .iter()
        .map(|l| {
            l.iter()
                .map(|c| {
                    let b = c.bounds.unwrap_or_default();
                    Aabb {
                        min: Vec3::new(b[0], b[1], b[2]),
                        max: Vec3::new(b[3], b[4], b[5]),
                    }
                })
                .collect()
        })
        .collect()
}

/// Where the chunk meshes live.
#[derive(Debug)]
enum Meshes {
    /// All of them in memory (`[depth][index]`).
    Resident(Vec<Vec<TriMesh>>),
    /// Read from the database's chunk files when a frame selects them.
    Paged(Box<ChunkPager>),
}

/// A chunk mesh borrowed from a resident tree or shared from the pager's cache.
#[derive(Debug)]
pub enum ChunkMesh<'a> {
    Borrowed(&'a TriMesh),
    Shared(Arc<TriMesh>),
}

impl std::ops::Deref for ChunkMesh<'_> {
    type Target = TriMesh;
    fn deref(&self) -> &TriMesh {
        match self {
            ChunkMesh::Borrowed(m) => m,
            ChunkMesh::Shared(m) => m,
        }
    }
}

/// The chunk-mesh cache's counters ([`FlightTerrain::chunk_cache`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ChunkCacheStats {
    /// Selected chunks found resident, and read from their files.
    pub hits: u64,
    pub loads: u64,
    /// Chunks dropped to keep the cache under its budget.
    pub evictions: u64,
    /// Chunks and mesh bytes resident now, and the budget.
    pub resident: u64,
    pub resident_bytes: u64,
    pub budget_bytes: u64,
}

/// Chunk meshes read from a database on demand and kept in a least-recently-used set under a
/// byte budget (the chunks of the current frame are never evicted, so one frame may exceed it).
#[derive(Debug)]
struct ChunkPager {
    db: Database,
    state: Mutex<PagerState>,
}

#[derive(Debug, Default)]
struct PagerState {
    /// `(depth, index)` -> (mesh, bytes, frame it was last used in).
    resident: HashMap<(u32, usize), (Arc<TriMesh>, u64, u64)>,
    frame: u64,
    stats: ChunkCacheStats,
}

/// Bytes a chunk mesh holds (positions, uvs, triangles).
fn mesh_bytes(m: &TriMesh) -> u64 {
    (m.positions.len() * 20 + m.triangles.len() * 12) as u64
}

impl ChunkPager {
    /// Make the meshes of `chunks` resident (misses read in parallel), then evict the least
    /// recently used others while over budget.
    fn prepare(&self, chunks: &[ChunkRef]) -> Result<(), ViewError> {
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        st.frame += 1;
        let frame = st.frame;
        let mut misses = Vec::new();
        for c in chunks {
            match st.resident.get_mut(&(c.depth, c.index)) {
                Some(e) => {
                    e.2 = frame;
                    st.stats.hits += 1;
                }
                None => misses.push(*c),
            }
        }
        let entries = &self.db.manifest.levels;
        let loaded: Vec<Result<TriMesh, TerrainError>> = misses
            .par_iter()
            .map(|c| {
                self.db
                    .read_chunk(&entries[c.depth as usize].chunks[c.index])
            })
            .collect();
        for (c, m) in misses.iter().zip(loaded) {
            let m = m?;
            let bytes = mesh_bytes(&m);
            st.stats.resident_bytes += bytes;
            st.stats.loads += 1;
            st.resident
                .insert((c.depth, c.index), (Arc::new(m), bytes, frame));
        }
        if st.stats.resident_bytes > st.stats.budget_bytes {
            // Oldest first, ties by key: deterministic.
            let mut old: Vec<(u64, (u32, usize), u64)> = st
                .resident
                .iter()
                .filter(|(_, e)| e.2 < frame)
                .map(|(k, e)| (e.2, *k, e.1))
                .collect();
            old.sort_unstable();
            for (_, key, bytes) in old {
                if st.stats.resident_bytes <= st.stats.budget_bytes {
                    break;
                }
                st.resident.remove(&key);
                st.stats.resident_bytes -= bytes;
                st.stats.evictions += 1;
            }
        }
        st.stats.resident = st.resident.len() as u64;
        Ok(())
    }

    fn get(&self, c: ChunkRef) -> Result<Arc<TriMesh>, ViewError> {
        if let Some(e) = self
            .state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .resident
            .get(&(c.depth, c.index))
        {
            return Ok(e.0.clone());
        }
        // Not prepared (a caller drawing chunks it did not select): read it, do not cache it.
        let entry = &self.db.manifest.levels[c.depth as usize].chunks[c.index];
        Ok(Arc::new(self.db.read_chunk(entry)?))
    }
}

/// The default byte budget of the chunk-mesh cache of a paged terrain
/// ([`FlightTerrain::from_database`]).
pub const DEFAULT_CHUNK_BUDGET: u64 = 128 << 20;

/// A terrain ready to be flown over: the grid (for the ground under the eye), the chunk
/// quadtree's boxes and errors, the chunk meshes (resident, or paged from a database) and the
/// whole-terrain texture.
#[derive(Debug)]
pub struct FlightTerrain {
    grid: Grid,
    max_depth: u32,
    /// `chunks[d]` = the chunks at depth `d`, in row-major cell order (their manifest entries;
    /// the file names are empty for a terrain made in memory), and `bounds[d]` their boxes.
    chunks: Vec<Vec<ChunkEntry>>,
    bounds: Vec<Vec<Aabb>>,
    meshes: Meshes,
    texture: MipTexture,
    /// GST map side and level count, when the terrain comes from a database with maps.
    maps: Option<(u32, u32)>,
}

impl FlightTerrain {
    /// A terrain from its parts, every chunk mesh in memory. `texture` spans the grid's extent
    /// (uv `[0, 1]²`, the chunks' texture coordinates).
    pub fn new(grid: Grid, tree: ChunkTree, texture: MipTexture) -> FlightTerrain {
        let mut chunks = Vec::with_capacity(tree.levels.len());
        let mut meshes = Vec::with_capacity(tree.levels.len());
        for level in tree.levels {
            let mut entries = Vec::with_capacity(level.len());
            let mut ms = Vec::with_capacity(level.len());
            for c in level {
                entries.push(ChunkEntry::of(&c, String::new()));
                ms.push(c.mesh);
            }
            chunks.push(entries);
            meshes.push(ms);
        }
        let bounds = boxes(&chunks);
        FlightTerrain {
            grid,
            max_depth: tree.max_depth,
            chunks,
            bounds,
            meshes: Meshes::Resident(meshes),
            texture,
            maps: None,
        }
    }

    /// Open a database with the default chunk budget ([`DEFAULT_CHUNK_BUDGET`]); see
    /// [`FlightTerrain::open`].
    pub fn from_database(db: &Database, max_texture_side: u32) -> Result<FlightTerrain, ViewError> {
        FlightTerrain::open(db, max_texture_side, DEFAULT_CHUNK_BUDGET)
    }

    /// Open a database for flight: the grid mapped, not read ([`Grid::map_file`]), the chunk
    /// boxes and errors from the manifest, the chunk meshes read from their files when a frame
    /// selects them and kept under `chunk_budget` bytes, and the finest texture level whose side
    /// is at most `max_texture_side` (a height-coloured texture when the database has no photo).
    /// A database whose manifest predates chunk boxes is opened the old way: its grid read and
    /// the quadtree rebuilt in memory (the same meshes).
    pub fn open(
        db: &Database,
        max_texture_side: u32,
        chunk_budget: u64,
    ) -> Result<FlightTerrain, ViewError> {
        let m = &db.manifest;
        let paged = m
            .levels
            .iter()
            .all(|l| l.chunks.iter().all(|c| c.bounds.is_some()));
        let mut t = if paged {
            let grid = db.grid_mapped()?;
            let texture = match db.texture(max_texture_side)? {
                Some(img) => texture_from_rgba(&img)?,
                None => {
                    texture_from_rgba(&db.tint().image(&grid, max_texture_side.clamp(1, 2048)))?
                }
            };
            let chunks: Vec<Vec<ChunkEntry>> = m.levels.iter().map(|l| l.chunks.clone()).collect();
            let bounds = boxes(&chunks);
            let pager = ChunkPager {
                db: db.clone(),
                state: Mutex::new(PagerState {
                    stats: ChunkCacheStats {
                        budget_bytes: chunk_budget,
                        ..ChunkCacheStats::default()
                    },
                    ..PagerState::default()
                }),
            };
            FlightTerrain {
                grid,
                max_depth: m.levels.len().saturating_sub(1) as u32,
                chunks,
                bounds,
                meshes: Meshes::Paged(Box::new(pager)),
                texture,
                maps: None,
            }
        } else {
            let grid = db.grid()?;
            let tree = crate::chunks::build(&grid, m.max_error, m.chunk)?;
            let texture = match db.texture(max_texture_side)? {
                Some(img) => texture_from_rgba(&img)?,
                None => {
                    texture_from_rgba(&db.tint().image(&grid, max_texture_side.clamp(1, 2048)))?
                }
            };
            FlightTerrain::new(grid, tree, texture)
        };
        t.maps = m.texture.as_ref().map(|t| (t.map_texels, t.levels));
        Ok(t)
    }

    pub fn grid(&self) -> &Grid {
        &self.grid
    }
    /// The finest depth of the quadtree.
    pub fn max_depth(&self) -> u32 {
        self.max_depth
    }
    /// `levels()[d]` = the chunks at depth `d`, in row-major cell order (as manifest entries).
    pub fn levels(&self) -> &[Vec<ChunkEntry>] {
        &self.chunks
    }
    /// The chunk `c` refers to.
    pub fn chunk(&self, c: ChunkRef) -> &ChunkEntry {
        &self.chunks[c.depth as usize][c.index]
    }
    /// True when chunk meshes are read from the database on demand.
    pub fn is_paged(&self) -> bool {
        matches!(self.meshes, Meshes::Paged(_))
    }
    /// The chunk-mesh cache's counters (`None` when every mesh is resident).
    pub fn chunk_cache(&self) -> Option<ChunkCacheStats> {
        match &self.meshes {
            Meshes::Resident(_) => None,
            Meshes::Paged(p) => Some(p.state.lock().unwrap_or_else(|e| e.into_inner()).stats),
        }
    }
    /// Make the meshes of `chunks` resident (a paged terrain reads its misses; a resident one
    /// has nothing to do). [`FlightTerrain::render`] calls it for its selection.
    pub fn prepare(&self, chunks: &[ChunkRef]) -> Result<(), ViewError> {
        match &self.meshes {
            Meshes::Resident(_) => Ok(()),
            Meshes::Paged(p) => p.prepare(chunks),
        }
    }
    /// The mesh of chunk `c` (read from its file if a paged terrain did not prepare it).
    pub fn mesh(&self, c: ChunkRef) -> Result<ChunkMesh<'_>, ViewError> {
        match &self.meshes {
            Meshes::Resident(m) => Ok(ChunkMesh::Borrowed(&m[c.depth as usize][c.index])),
            Meshes::Paged(p) => Ok(ChunkMesh::Shared(p.get(c)?)),
        }
    }
    pub fn texture(&self) -> &MipTexture {
        &self.texture
    }
    /// The bounding box of chunk `c` (surface and skirts).
    pub fn bounds(&self, c: ChunkRef) -> Aabb {
        self.bounds[c.depth as usize][c.index]
    }

    fn index_of(&self, depth: u32, ix: u32, iy: u32) -> Option<usize> {
        self.chunks
            .get(depth as usize)?
            .binary_search_by_key(&(iy, ix), |c| (c.iy, c.ix))
            .ok()
    }

    /// Choose the chunks of a frame: frustum culling and refinement while the screen-space error
    /// exceeds `pixel_error` pixels (see the module docs).
    pub fn select(&self, camera: &Camera, pixel_error: f32) -> Selection {
        let frustum = Frustum::new(camera);
        let k = camera.scale();
        let eye = camera.eye();
        let mut sel = Selection {
            chunks_per_level: vec![0; self.chunks.len()],
            ..Selection::default()
        };
        let mut stack: Vec<(u32, u32, u32)> = vec![(0, 0, 0)];
        // Children pushed in reverse so they pop in row-major order.
        while let Some((d, ix, iy)) = stack.pop() {
            let Some(i) = self.index_of(d, ix, iy) else {
                continue;
            };
            sel.visited += 1;
            let c = &self.chunks[d as usize][i];
            let b = self.bounds[d as usize][i];
            if frustum.culls(&b) {
                sel.culled += 1;
                continue;
            }
            let sse = screen_space_error(c.geometric_error, b.distance(eye), k);
            if sse > pixel_error && d < self.max_depth {
                for (cx, cy) in [(1, 1), (0, 1), (1, 0), (0, 0)] {
                    stack.push((d + 1, 2 * ix + cx, 2 * iy + cy));
                }
            } else {
                sel.chunks.push(ChunkRef { depth: d, index: i });
                sel.chunks_per_level[d as usize] += 1;
            }
        }
        // A stable sort on a total order: deterministic.
        sel.chunks.sort_by(|a, b| {
            self.bounds(*a)
                .distance(eye)
                .total_cmp(&self.bounds(*b).distance(eye))
        });
        sel
    }

    /// Concatenate the selected chunks' meshes (positions, uvs, triangles with offset indices)
    /// into `scratch`, in the selection's order; returns the triangle count.
    pub fn gather(
        &self,
        selection: &Selection,
        scratch: &mut FrameScratch,
    ) -> Result<usize, ViewError> {
        self.prepare(&selection.chunks)?;
        scratch.clear();
        for c in &selection.chunks {
            scratch.append(&*self.mesh(*c)?, |p| p);
        }
        Ok(scratch.triangles.len())
    }

    /// Concatenate the selected chunks' meshes into `scratch` and draw them with `sampler` into
    /// `fb` (not cleared here). Returns the rasteriser's counts.
    pub fn draw<S: QuadSampler + ?Sized>(
        &self,
        camera: &Camera,
        selection: &Selection,
        sampler: &S,
        fb: &mut Framebuffer,
        scratch: &mut FrameScratch,
    ) -> Result<DrawStats, ViewError> {
        self.gather(selection, scratch)?;
        let mesh = scratch.mesh()?;
        // Surfaces face up and skirts outward (counter-clockwise from outside): back faces are
        // never the visible side of a closed chunk.
        let state = DrawState {
            cull: Cull::Back,
            ..DrawState::default()
        };
        Ok(fb.draw_textured(camera, &mesh, sampler, &state)?)
    }

    /// One frame: camera, selection, draw with `options.sampler` into `fb` (cleared to the
    /// background first; its size must be the camera's).
    pub fn render(
        &self,
        view: &FlightCamera,
        options: &ViewOptions,
        fb: &mut Framebuffer,
        scratch: &mut FrameScratch,
    ) -> Result<FrameStats, ViewError> {
        options.check()?;
        let camera = view.camera(&self.grid)?;
        let sel = self.select(&camera, options.pixel_error);
        fb.clear(options.background);
        let sampler = MipSampler {
            texture: &self.texture,
            sampler: options.sampler,
        };
        let ds = self.draw(&camera, &sel, &sampler, fb, scratch)?;
        let mut stats = FrameStats {
            chunks_drawn: sel.chunks.len() as u32,
            chunks_visited: sel.visited,
            chunks_culled: sel.culled,
            chunks_per_level: sel.chunks_per_level.clone(),
            triangles: ds.submitted as u64,
            triangles_binned: ds.binned as u64,
            triangles_backface: ds.culled as u64,
            triangles_clipped: ds.clipped as u64,
            texture_side: self.texture.width().max(self.texture.height()),
            texture_bytes: std::mem::size_of_val(self.texture.texels()) as u64,
            ..FrameStats::default()
        };
        stats.surface_triangles = sel
            .chunks
            .iter()
            .map(|c| self.chunk(*c).triangles as u64)
            .sum();
        stats.chunk_cache = self.chunk_cache();
        stats.maps_needed = self.needed_maps(view).map(|k| k.len() as u64);
        Ok(stats)
    }

    /// The GST maps Seed 000's active area (Eq. 5–7) needs around the eye of `view`, when the
    /// terrain comes from a database with maps (`None` otherwise, or for a field of view the
    /// active area rejects).
    pub fn needed_maps(&self, view: &FlightCamera) -> Option<Vec<gst::MapKey>> {
        let (map_texels, levels) = self.maps?;
        let area = ActiveArea::new(view.hfov_deg, view.width, map_texels).ok()?;
        let g = self.grid.georef();
        let (col, row) = g.xy_to_sample(view.eye_x, view.eye_y);
        let u = (col / (self.grid.width() - 1) as f64).clamp(0.0, 1.0);
        let v = (row / (self.grid.height() - 1) as f64).clamp(0.0, 1.0);
        Some(gst::needed_maps(&area, u, v, levels))
    }

    /// Make the maps of [`FlightTerrain::needed_maps`] resident in `cache`, loading misses from
    /// the database's tiles; returns how many were needed and loaded, and the cache's counters.
    /// The frame itself samples the whole-terrain texture (see the module docs), so this measures
    /// what a cache-fed renderer would hold and load along a flight, not what was sampled.
    pub fn make_resident(
        &self,
        view: &FlightCamera,
        db: &Database,
        cache: &mut gst::GstCache,
    ) -> Result<Residency, ViewError> {
        let keys = self.needed_maps(view).unwrap_or_default();
        let loaded = cache.make_resident(&keys, |k| db.map(k))?;
        Ok(Residency {
            needed: keys.len() as u64,
            loaded,
            cache: cache.stats(),
        })
    }
}

/// GST map residency after one frame ([`FlightTerrain::make_resident`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Residency {
    /// Maps the active area needs at this eye.
    pub needed: u64,
    /// Of those, maps that were not resident and were loaded.
    pub loaded: u64,
    /// The cache's counters after the frame (hits, loads, evictions, resident maps and bytes).
    pub cache: gst::CacheStats,
}

/// A clamped, gamma-correct mip pyramid of an sRGB RGBA image.
pub fn texture_from_rgba(img: &image::RgbaImage) -> Result<MipTexture, ViewError> {
    MipTexture::from_srgb8(
        img.width(),
        img.height(),
        img.as_raw(),
        Reduction::GammaCorrect,
        Wrap::Clamp,
    )
    .map_err(ViewError::Texture)
}

/// A texture for a database without a photo: shaded relief ([`crate::relief`]: heights coloured
/// green (low) to brown to white (high), lit by `gdaldem`'s default hillshade), nearest grid
/// sample per texel, no-data grey; the side is at most `max_side` and at most the grid's larger
/// side.
pub fn height_texture(grid: &Grid, max_side: u32) -> Result<MipTexture, ViewError> {
    texture_from_rgba(&crate::relief::relief_image(grid, max_side))
}

/// Haze toward the horizon, applied to a finished frame (off unless called): each covered
/// pixel's linear colour is blended toward `sky` by the transmittance `exp(−3.912 · d / V)`
/// (Koschmieder: `V` is the visibility at which contrast falls to 2 %), `d` the eye distance of
/// the pixel's surface (its depth times the length of its eye ray of unit depth). Uncovered
/// pixels become the opaque sky. Errors: a visibility that is not finite and positive.
pub fn apply_haze(
    frame: &mut texmap_core::frame::Frame,
    camera: &Camera,
    sky: [u8; 3],
    visibility_m: f32,
) -> Result<(), ViewError> {
    if !(visibility_m.is_finite() && visibility_m > 0.0) {
        return Err(ViewError::BadParameter {
            name: "visibility",
            value: visibility_m.to_string(),
            expected: "a finite distance > 0 metres",
        });
    }
    if (frame.width(), frame.height()) != (camera.width(), camera.height()) {
        return Err(ViewError::BadParameter {
            name: "frame size",
            value: format!("{}x{}", frame.width(), frame.height()),
            expected: "the camera's image size",
        });
    }
    use texmap_core::color::{linear_to_srgb8, srgb8_to_linear_rgb};
    let sky_lin = srgb8_to_linear_rgb([sky[0], sky[1], sky[2], 255]);
    let sigma = 3.912 / visibility_m;
    let w = frame.width() as usize;
    let texmap_core::frame::Frame { color, depth, .. } = frame;
    for (i, (c, &d)) in color.iter_mut().zip(depth.iter()).enumerate() {
        if !d.is_finite() {
            *c = [sky[0], sky[1], sky[2], 255];
            continue;
        }
        let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
        let dist = d * camera.eye_ray_dir(x, y).length();
        let t = (-sigma * dist).exp();
        let lin = srgb8_to_linear_rgb(*c);
        *c = linear_to_srgb8(lin * t + sky_lin * (1.0 - t), c[3]);
    }
    Ok(())
}

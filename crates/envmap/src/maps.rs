//! Environment maps: storage, static construction from an [`Environment`], per-direction lookup
//! through texmap-core's samplers, and the per-frame (dynamic) update that draws the scene's
//! objects into the map with texmap-raster.
//!
//! # Storage
//! A map is one to six square [`MipTexture`]s (linear RGB, clamped addressing, box-filtered
//! pyramid) plus the probe's centre and [`MapFrame`]:
//! - sphere map: one `n × n` texture covering `(u, v) ∈ [0, 1]²` exactly; texels outside the disc
//!   hold the colour of the nearest rim point, so bilinear taps at the rim never read undefined
//!   data;
//! - cube map: six `(n + 2b)²` faces with a border of `b =` [`CUBE_BORDER`] texels rendered from
//!   the scene itself (the face camera's field of view is widened to `2·atan((n + 2b)/n)`), so a
//!   bilinear or first-levels trilinear lookup at a face edge reads the true neighbouring texels:
//!   edges are seamless without cross-face addressing. Coarser levels than `log2 b` still clamp
//!   at the face edge (a faint seam on very rough lookups);
//! - dual paraboloid: two `n × n` textures covering `p ∈ [−R, R]²`, `R =` [`PARABOLOID_EXTENT`],
//!   so each hemisphere carries an overlap band of the other one (up to 10° past the equator),
//!   for the same reason.
//!
//! # Lookup and level of detail
//! [`EnvMap::lookup_quad`] takes the four directions of a 2x2 pixel quad. Each lane is projected
//! onto its own face, and its three neighbours onto the *same* face (cube faces and paraboloids
//! extend past their edges), so the coarse derivatives `uv[1] − uv[0]`, `uv[2] − uv[0]` that
//! trilinear filtering needs are those of one continuous parameterisation. On a sphere map a quad
//! whose directions straddle the singular direction gets a derivative as wide as the disc and
//! the coarsest level: that blur at the rim is the sphere map's own behaviour, measured by the
//! study, not hidden.
//!
//! # Dynamic update
//! Objects are flat-lit as the reference shades its flat meshes (face normal turned toward the
//! probe, [`Lighting::shade`] seen from the probe); texels no object covers take the
//! environment (a cached static map of it, 2x2 supersampled per texel).
//! - **Cube map**: six perspective cameras at the probe. The objects are flattened once into a
//!   flat-coloured soup, each triangle listed under the faces whose frustum pyramid it may
//!   touch (4-bit outcodes per vertex and face), and each face draws only its own triangles,
//!   with their own vertices, in one call. Submitting every object to every face instead left the rasteriser
//!   projecting and clipping six times the geometry. [`update_cube_faces`] draws a subset of the
//!   faces (a time-sliced update): triangles on none of them are not flattened (their outcodes
//!   are still computed), and the other faces are moved from the previous map with their
//!   pyramids, untouched.
//! - **Sphere map** (Seed 003) and **dual paraboloid**: no camera can produce them, so the
//!   objects' triangles are *mapped*: every vertex goes to its map point
//!   (`d = normalize(v − centre)` through [`sphere_uv`] or [`paraboloid_point`]) and the
//!   triangles are drawn there by the rasteriser with an orthographic camera whose pixels are the
//!   map's texels (depth = distance to the centre; parallel over chunks of triangles,
//!   concatenated in order). Straight edges in the map are only right for small triangles, and a
//!   triangle whose directions straddle the sphere map's rim (around the singular direction
//!   `−z`, whose image is the whole rim circle) would be drawn across the whole disc. So
//!   ([`RimPolicy::Split`]) a triangle that contains the singular direction is split in four at
//!   its 3D edge midpoints, and otherwise each *edge* is split at its 3D midpoint when it is
//!   longer than [`MAX_MAPPED_EDGE_TEXELS`] in the map or the map bends it by more than
//!   [`CHORD_TOLERANCE_TEXELS`] (mapped 3D midpoint against the straight edge's midpoint; edges
//!   under [`MIN_SPLIT_EDGE_TEXELS`] never split). The decision depends on the edge alone, so the
//!   two triangles sharing an edge split it alike and no T-junction cracks appear (a triangle
//!   splits in two, three or four). Pieces that still contain the singular direction (or, on a
//!   paraboloid, leave the map's overlap band) after [`MAX_SPLIT_DEPTH`] splits are not drawn:
//!   they cover about `4^-depth` of the triangle, all at the rim, where the fill holds the
//!   environment ([`crate::Output::dropped_pieces`] counts them). [`RimPolicy::Naive`] draws
//!   every triangle as is (the 1998 behaviour, kept to measure it). A fixed 8-texel edge bound
//!   instead of the chord test cut the tunnel's far rings, stretched around the singular
//!   direction, into thousands of pieces: about 3x the update time of the cube map on the
//!   built-in scene (harness timing, shared machine).
//!
//! Faces are independent: each is drawn, composited over the environment and built into its
//! pyramid in a parallel job with its own buffers (drawn one after another, each draw's tile
//! pass had a few busy tiles per face to split between the cores). Every buffer, the soup's and
//! the pyramids' included, is kept in [`MapScratch`] and reused, so an animation's updates
//! allocate nothing once warm (the soup's `par_extend` alone caused most of an update's page
//! faults).
//!
//! Rejected: clipping against the map's rim circle in the plane of the map (the rim is one
//! direction, so there is no line in direction space to clip against), and per-texel ray casting
//! of the objects into the map (exact, but it needs a BVH: a second renderer).

use std::ops::Range;

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;
use texmap_core::camera::Camera;
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::Sampler;
use texmap_core::shade::Lighting;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, Shading};

use crate::address::{
    Face, Hemisphere, MapFrame, cube_dir, cube_face_uv, cube_uv, paraboloid_dir, paraboloid_point,
    sphere_dir, sphere_uv,
};
use crate::environment::Environment;
use crate::error::EnvMapError;
use crate::scene::Object;

/// The smallest map side accepted.
pub const MIN_MAP_SIZE: u32 = 4;
/// The largest map side accepted.
pub const MAX_MAP_SIZE: u32 = 4096;
/// Border texels around each cube face (see the module docs).
pub const CUBE_BORDER: u32 = 2;
/// Half-width of a paraboloid texture in paraboloid units (`|p| = 1` is the equator).
pub const PARABOLOID_EXTENT: f32 = 1.2;
/// Directions drawn into a paraboloid map: `s·z ≥ −PARABOLOID_OVERLAP_Z` (a band a little wider
/// than the texture's, `|p| ≤ 1.2` is `s·z ≥ −0.18`).
const PARABOLOID_OVERLAP_Z: f32 = 0.2;
/// Mapped triangles are split while an edge is longer than this many texels (a quarter of a
/// 256² map)...
pub const MAX_MAPPED_EDGE_TEXELS: f32 = 64.0;
/// ...or while the map bends an edge (its mapped 3D midpoint, or the centroid) more than this
/// many texels away from the straight edge the rasteriser draws...
pub const CHORD_TOLERANCE_TEXELS: f32 = 0.5;
/// ...unless every edge is at most this long.
pub const MIN_SPLIT_EDGE_TEXELS: f32 = 2.0;
/// Recycled pyramids a [`MapScratch`] keeps (a cube map's faces).
const MAX_SPARE: usize = 6;
/// Object triangles per parallel task of a mapped update.
const MAP_RUN: usize = 2048;
/// The deepest split of a mapped triangle (`4^10` pieces at most, only near the singular
/// direction in practice).
pub const MAX_SPLIT_DEPTH: u32 = 10;

/// The map layouts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MapKind {
    /// Seed 003 / OpenGL sphere map.
    Sphere,
    /// Six-face cube map.
    Cube,
    /// Two paraboloids.
    Paraboloid,
}

/// How map lookups filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Filter {
    /// Bilinear on level 0 (aliases when the reflection minifies the map).
    Bilinear,
    /// Trilinear over the map's pyramid (Seed 000 Eq. 4), level from the quad's derivatives.
    #[default]
    Trilinear,
}

impl Filter {
    fn sampler(self) -> Sampler {
        match self {
            Filter::Bilinear => Sampler::Bilinear,
            Filter::Trilinear => Sampler::Trilinear,
        }
    }
}

/// How a projected (sphere or paraboloid) map update treats triangles that cross its rim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum RimPolicy {
    /// Split until short, drop the pieces at the singular direction (see the module docs).
    #[default]
    Split,
    /// Draw every triangle with straight edges between its mapped vertices (the 1998 method).
    Naive,
}

/// An environment map (see the module docs).
#[derive(Clone, Debug)]
pub struct EnvMap {
    kind: MapKind,
    frame: MapFrame,
    centre: Vec3,
    size: u32,
    faces: Vec<MipTexture>,
}

/// Texture side for a map kind and map size.
fn tex_side(kind: MapKind, size: u32) -> u32 {
    match kind {
        MapKind::Cube => size + 2 * CUBE_BORDER,
        MapKind::Sphere | MapKind::Paraboloid => size,
    }
}

fn face_count(kind: MapKind) -> usize {
    match kind {
        MapKind::Sphere => 1,
        MapKind::Cube => 6,
        MapKind::Paraboloid => 2,
    }
}

fn check_size(size: u32) -> Result<(), EnvMapError> {
    if (MIN_MAP_SIZE..=MAX_MAP_SIZE).contains(&size) {
        Ok(())
    } else {
        Err(EnvMapError::MapSize { size })
    }
}

/// The map-frame direction shown at texture coordinates `t` (texture widths) of `face`.
#[inline]
fn texel_dir(kind: MapKind, size: u32, face: usize, t: Vec2) -> Vec3 {
    match kind {
        MapKind::Sphere => {
            // Outside the disc: the nearest rim point (just inside, so the direction is defined).
            let p = t * 2.0 - Vec2::ONE;
            let l = p.length();
            let p = if l > 1.0 - 1e-6 {
                p * ((1.0 - 1e-6) / l)
            } else {
                p
            };
            sphere_dir(p * 0.5 + Vec2::splat(0.5)).unwrap_or(Vec3::NEG_Z)
        }
        MapKind::Cube => {
            let n = size as f32;
            let b = CUBE_BORDER as f32;
            let uv = (t * (n + 2.0 * b) - Vec2::splat(b)) / n;
            cube_dir(Face::ALL[face], uv)
        }
        MapKind::Paraboloid => {
            let hemi = if face == 0 {
                Hemisphere::Front
            } else {
                Hemisphere::Back
            };
            paraboloid_dir(hemi, (t * 2.0 - Vec2::ONE) * PARABOLOID_EXTENT)
        }
    }
}

/// Texture coordinates of a map-frame direction on a given face (continuing past the face),
/// `None` where the face's parameterisation does not reach.
#[inline]
fn face_tex(kind: MapKind, size: u32, face: usize, d: Vec3) -> Option<Vec2> {
    match kind {
        MapKind::Sphere => Some(sphere_uv(d)),
        MapKind::Cube => {
            let uv = cube_face_uv(Face::ALL[face], d)?;
            let n = size as f32;
            let b = CUBE_BORDER as f32;
            Some((uv * n + Vec2::splat(b)) / (n + 2.0 * b))
        }
        MapKind::Paraboloid => {
            let hemi = if face == 0 {
                Hemisphere::Front
            } else {
                Hemisphere::Back
            };
            let p = paraboloid_point(hemi, d)?;
            Some(p * (0.5 / PARABOLOID_EXTENT) + Vec2::splat(0.5))
        }
    }
}

/// The face a map-frame direction is looked up on, and its texture coordinates there.
#[inline]
fn home(kind: MapKind, size: u32, d: Vec3) -> (usize, Vec2) {
    match kind {
        MapKind::Sphere => (0, sphere_uv(d)),
        MapKind::Cube => {
            let (f, _) = cube_uv(d);
            let i = f.index();
            (i, face_tex(kind, size, i, d).unwrap_or(Vec2::splat(0.5)))
        }
        MapKind::Paraboloid => {
            let i = if d.z >= 0.0 { 0 } else { 1 };
            (i, face_tex(kind, size, i, d).unwrap_or(Vec2::splat(0.5)))
        }
    }
}

/// Level-0 texels of a map filled with the environment: `s × s` supersamples per texel.
fn environment_texels(
    kind: MapKind,
    frame: MapFrame,
    size: u32,
    env: &Environment,
    s: u32,
) -> Vec<Vec<Vec4>> {
    let side = tex_side(kind, size);
    let inv = 1.0 / side as f32;
    (0..face_count(kind))
        .map(|face| {
            let mut texels = vec![Vec4::ZERO; (side * side) as usize];
            texels
                .par_chunks_mut(side as usize)
                .enumerate()
                .for_each(|(j, row)| {
                    for (i, t) in row.iter_mut().enumerate() {
                        let mut acc = Vec3::ZERO;
                        for b in 0..s {
                            for a in 0..s {
                                let tc = Vec2::new(
                                    i as f32 + (a as f32 + 0.5) / s as f32,
                                    j as f32 + (b as f32 + 0.5) / s as f32,
                                ) * inv;
                                let d = texel_dir(kind, size, face, tc);
                                acc += env.radiance(frame.to_world(d));
                            }
                        }
                        *t = (acc / (s * s) as f32).extend(1.0);
                    }
                });
            texels
        })
        .collect()
}

/// The face pyramid of `texels`, built into `old`'s buffers when given (see [`MapScratch::recycle`]).
fn pyramid(side: u32, texels: &[Vec4], old: Option<MipTexture>) -> Result<MipTexture, EnvMapError> {
    Ok(match old {
        Some(old) => {
            MipTexture::from_linear_reusing(old, side, side, texels, Reduction::Box, Wrap::Clamp)
        }
        None => MipTexture::from_linear(side, side, texels, Reduction::Box, Wrap::Clamp),
    }?)
}

impl EnvMap {
    /// A static map of the environment alone (2x2 supersampled per texel).
    pub fn from_environment(
        kind: MapKind,
        env: &Environment,
        frame: MapFrame,
        centre: Vec3,
        size: u32,
    ) -> Result<EnvMap, EnvMapError> {
        check_size(size)?;
        let side = tex_side(kind, size);
        let faces = environment_texels(kind, frame, size, env, 2)
            .iter()
            .map(|t| pyramid(side, t, None))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(EnvMap {
            kind,
            frame,
            centre,
            size,
            faces,
        })
    }

    pub fn kind(&self) -> MapKind {
        self.kind
    }

    pub fn frame(&self) -> MapFrame {
        self.frame
    }

    /// The probe position the map was made at.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// Map side `n` (cube faces without their border).
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The stored textures (1, 6 or 2), for display and tests.
    pub fn faces(&self) -> &[MipTexture] {
        &self.faces
    }

    /// Linear radiance the map holds for world direction `d`, bilinear on level 0.
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        let dm = self.frame.to_map(d);
        let (f, t) = home(self.kind, self.size, dm);
        Sampler::Bilinear
            .sample(&self.faces[f], t, Vec2::ZERO, Vec2::ZERO)
            .truncate()
    }

    /// Radiance for the four world directions of a 2x2 quad (lanes `(0,0), (1,0), (0,1),
    /// (1,1)`); only lanes in `mask` are computed (the others are black). The level of detail
    /// comes from the quad's own directions (see the module docs).
    #[inline]
    pub fn lookup_quad(&self, dirs: &[Vec3; 4], mask: u8, filter: Filter) -> [Vec3; 4] {
        let mut out = [Vec3::ZERO; 4];
        let dm = dirs.map(|d| self.frame.to_map(d));
        let sampler = filter.sampler();
        // The usual case: the whole quad on one face. Its coarse derivatives are then those of
        // the quad itself, which is what the samplers' quad path (SIMD where it has one) uses.
        let homes = dm.map(|d| home(self.kind, self.size, d));
        let f = homes[0].0;
        if homes.iter().all(|h| h.0 == f) {
            let q = sampler.sample_quad(&self.faces[f], homes.map(|h| h.1));
            for l in 0..4 {
                if mask & (1 << l) != 0 {
                    out[l] = q[l].truncate();
                }
            }
            return out;
        }
        for l in 0..4 {
            if mask & (1 << l) == 0 {
                continue;
            }
            let (f, t) = homes[l];
            let (dx, dy) = match filter {
                Filter::Bilinear => (Vec2::ZERO, Vec2::ZERO),
                Filter::Trilinear => {
                    let at = |k: usize| face_tex(self.kind, self.size, f, dm[k]);
                    // Coarse derivatives on lane l's face, from lanes 1 − 0 and 2 − 0.
                    match (at(0), at(1), at(2)) {
                        (Some(a), Some(b), Some(c)) => (b - a, c - a),
                        _ => (Vec2::ZERO, Vec2::ZERO),
                    }
                }
            };
            out[l] = sampler.sample(&self.faces[f], t, dx, dy).truncate();
        }
        out
    }
}

/// Reusable buffers of the dynamic updates.
#[derive(Debug, Default)]
pub struct MapScratch {
    env_cache: Option<(MapKind, u32, MapFrame, Vec<Vec<Vec4>>)>,
    /// One per map face: the faces are drawn in parallel.
    faces: Vec<FaceScratch>,
    /// The cube update's frustum outcodes per vertex of the object being flattened.
    codes: Vec<u32>,
    /// The cube update's flattened triangles (vertices, colour) per run of [`FLAT_RUN`] object
    /// triangles, listed under each face they may touch.
    flat: Vec<[Vec<FlatTri>; 6]>,
    /// Pieces of mapped triangles dropped at the rim in the last projected update.
    pub dropped_pieces: usize,
    /// Pyramids of recycled maps, rebuilt into by the next updates.
    spare: Vec<MipTexture>,
}

/// The buffers of one face's draw, kept across updates.
#[derive(Debug, Default)]
struct FaceScratch {
    fb: Option<Framebuffer>,
    positions: Vec<Vec3>,
    colors: Vec<Vec3>,
    tris: Vec<[u32; 3]>,
    /// Projected updates: the pieces mapped from each run of object triangles.
    pieces: Vec<Pieces>,
    /// The face composited over the environment (level 0 of its pyramid).
    texels: Vec<Vec4>,
    /// A recycled pyramid to build this face's into.
    spare: Option<MipTexture>,
}

impl MapScratch {
    /// Hand back a map no longer needed: the next updates build their face pyramids into its
    /// buffers instead of allocating (an animation's steady state then allocates no pyramid).
    /// At most six pyramids are kept.
    pub fn recycle(&mut self, map: EnvMap) {
        self.spare.extend(map.faces);
        self.spare.truncate(MAX_SPARE);
    }

    fn env_texels(
        &mut self,
        kind: MapKind,
        frame: MapFrame,
        size: u32,
        env: &Environment,
    ) -> &[Vec<Vec4>] {
        let hit = self
            .env_cache
            .as_ref()
            .is_some_and(|(k, s, f, _)| *k == kind && *s == size && *f == frame);
        if !hit {
            let t = environment_texels(kind, frame, size, env, 2);
            self.env_cache = Some((kind, size, frame, t));
        }
        &self.env_cache.as_ref().expect("just set").3
    }
}

impl FaceScratch {
    /// Draw the gathered pieces (`positions` and `colors`, three vertices per piece; every piece is
    /// flat, drawn in its first vertex's colour) into the square framebuffer of side `side`,
    /// cleared first, with `cam` and `state`.
    fn draw_pieces(
        &mut self,
        side: u32,
        cam: &Camera,
        state: &DrawState,
    ) -> Result<(), EnvMapError> {
        if self.fb.as_ref().is_none_or(|f| f.width() != side) {
            self.fb = Some(Framebuffer::new(side, side)?);
        }
        let fb = self.fb.as_mut().expect("just set");
        fb.clear([0, 0, 0, 255]);
        // Piece k is vertices 3k..3k + 3: the index list only grows, and is a prefix's.
        let pieces = self.positions.len() / 3;
        let have = self.tris.len() as u32;
        self.tris
            .extend((have..pieces as u32).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]));
        let mesh = Mesh::new(&self.positions, &self.tris[..pieces])?.with_colors(&self.colors)?;
        fb.draw_mesh(cam, &mesh, &Shading::FirstVertexColor, state)?;
        Ok(())
    }
}

/// What a dynamic update draws: the objects, the probe, and Seed 003's option of drawing only
/// triangles whose centroid lies at least `min_distance` from the centre.
#[derive(Clone, Copy, Debug)]
pub struct UpdateParams<'a> {
    pub objects: &'a [Object],
    pub lighting: &'a Lighting,
    pub environment: &'a Environment,
    pub centre: Vec3,
    pub frame: MapFrame,
    pub size: u32,
    pub min_distance: f32,
    pub rim: RimPolicy,
}

/// A flattened triangle: its world vertices and flat-lit colour.
type FlatTri = ([Vec3; 3], Vec3);

/// Object triangles flattened per parallel job by the cube update.
const FLAT_RUN: usize = 4096;

/// Whether the update draws the triangle `w`: its centroid is at least `min_distance` from the
/// centre (every triangle when it is 0).
#[inline]
fn far_enough(p: &UpdateParams, w: &[Vec3; 3]) -> bool {
    p.min_distance <= 0.0
        || ((w[0] + w[1] + w[2]) / 3.0 - p.centre).length_squared()
            >= p.min_distance * p.min_distance
}

/// The objects' triangles in runs `(object, range)` of at most `len`, in order: the parallel
/// jobs of an update, each writing into buffers of its own.
fn triangle_runs(objects: &[Object], len: usize) -> Vec<(usize, Range<usize>)> {
    objects
        .iter()
        .enumerate()
        .flat_map(|(k, o)| {
            let n = o.mesh.triangles.len();
            (0..n).step_by(len).map(move |a| (k, a..(a + len).min(n)))
        })
        .collect()
}

/// Every face of a map of `kind` as a face mask (bit `i` is `faces()[i]`).
pub fn all_faces(kind: MapKind) -> u8 {
    ((1u16 << face_count(kind)) - 1) as u8
}

/// Draw the faces in `faces`, each composited over the environment fill and built into its
/// pyramid; faces are independent, so they run in parallel (each draw is parallel inside too),
/// each in its own [`FaceScratch`]. `draw` fills a face's framebuffer and returns the pieces it
/// dropped ([`MapScratch::dropped_pieces`] gets their sum). The faces not in `faces` are moved,
/// texels and pyramid, from `previous` (which the caller has checked is a map of the same
/// layout, size, frame and centre).
fn finish_faces(
    kind: MapKind,
    p: &UpdateParams,
    scratch: &mut MapScratch,
    faces: u8,
    previous: Option<EnvMap>,
    draw: &(dyn Fn(usize, &mut FaceScratch) -> Result<usize, EnvMapError> + Sync),
) -> Result<EnvMap, EnvMapError> {
    let side = tex_side(kind, p.size);
    let count = face_count(kind);
    let drawn = |face: usize| faces & (1 << face) != 0;
    scratch.env_texels(kind, p.frame, p.size, p.environment);
    let MapScratch {
        env_cache,
        faces: face_scratch,
        spare,
        ..
    } = scratch;
    let env = &env_cache.as_ref().expect("filled").3;
    face_scratch.resize_with(count, FaceScratch::default);
    for (face, f) in face_scratch.iter_mut().enumerate() {
        if drawn(face) && f.spare.is_none() {
            f.spare = spare.pop();
        }
    }
    let built = face_scratch
        .par_iter_mut()
        .enumerate()
        .map(|(face, f)| {
            if !drawn(face) {
                return Ok((None, 0));
            }
            let dropped = draw(face, f)?;
            let fb = f.fb.as_ref().expect("drawn");
            f.texels.resize((side * side) as usize, Vec4::ZERO);
            fb.composite_linear_into(&env[face], &mut f.texels);
            if kind == MapKind::Sphere {
                fill_outside_disc(side, &mut f.texels);
            }
            Ok((Some(pyramid(side, &f.texels, f.spare.take())?), dropped))
        })
        .collect::<Result<Vec<_>, EnvMapError>>()?;
    scratch.dropped_pieces += built.iter().map(|b| b.1).sum::<usize>();
    // Faces not drawn come from the previous map; the previous map's redrawn faces are
    // rebuilt into by the next update.
    let mut kept = previous.map(|m| m.faces).unwrap_or_default().into_iter();
    let faces = built
        .into_iter()
        .map(|(b, _)| match (b, kept.next()) {
            (Some(b), old) => {
                scratch.spare.extend(old);
                Ok(b)
            }
            (None, Some(old)) => Ok(old),
            (None, None) => Err(EnvMapError::BadOption {
                what: "a partial map update needs the previous map",
            }),
        })
        .collect::<Result<Vec<_>, _>>()?;
    scratch.spare.truncate(MAX_SPARE);
    Ok(EnvMap {
        kind,
        frame: p.frame,
        centre: p.centre,
        size: p.size,
        faces,
    })
}

/// Texels of a sphere map outside the disc take the nearest texel inside it along the radius.
fn fill_outside_disc(side: u32, texels: &mut [Vec4]) {
    let n = side as f32;
    let c = n * 0.5;
    let r = c - 0.75;
    for y in 0..side {
        for x in 0..side {
            let p = Vec2::new(x as f32 + 0.5 - c, y as f32 + 0.5 - c);
            let l = p.length();
            if l > c {
                let q = p * (r / l) + Vec2::splat(c);
                let (qx, qy) = ((q.x as u32).min(side - 1), (q.y as u32).min(side - 1));
                texels[(y * side + x) as usize] = texels[(qy * side + qx) as usize];
            }
        }
    }
}

/// Flat-lit colour of an object triangle seen from the probe (as the reference shades its flat
/// meshes: the face normal turned toward the viewer, Lambert + Blinn-Phong), `None` if not finite.
#[inline]
fn flat_colour(p: &UpdateParams, o: &Object, w: [Vec3; 3]) -> Option<Vec3> {
    let nrm = (w[1] - w[0]).cross(w[2] - w[0]);
    let cen = (w[0] + w[1] + w[2]) / 3.0;
    let view = (p.centre - cen).normalize_or(Vec3::Z);
    let nrm = nrm.normalize_or(view);
    let nrm = if nrm.dot(view) < 0.0 { -nrm } else { nrm };
    let c = p.lighting.shade(&o.material, nrm, view);
    c.is_finite().then_some(c)
}

/// Dynamic cube map: the objects drawn by six face cameras at the probe.
///
/// All objects are first flattened into one vertex-coloured soup (three vertices per triangle,
/// its flat-lit colour seen from the probe), then each face draws, in one call, the triangles
/// not wholly outside one side of its frustum pyramid (four planes through the probe; 4-bit
/// outcodes per vertex). Submitting every object to every face instead (the rasteriser clips
/// what lies outside) spent most of the update in clipping and per-draw set-up.
pub fn update_cube(p: &UpdateParams, scratch: &mut MapScratch) -> Result<EnvMap, EnvMapError> {
    update_cube_faces(p, scratch, all_faces(MapKind::Cube), None)
}

/// A time-sliced cube update: only the faces in the mask `faces` (bit `i` is
/// [`Face::ALL`]`[i]`) are drawn, as [`update_cube`] draws them; the others are moved from
/// `previous`, level-0 texels and pyramid alike, untouched. Triangles that fall on no drawn face
/// are not flattened. With every face in the mask, `previous` is ignored and the result is
/// [`update_cube`]'s.
///
/// Errors: bits beyond the six faces; a partial mask without a `previous` cube map of the same
/// size, frame and centre (its faces would be of another map).
pub fn update_cube_faces(
    p: &UpdateParams,
    scratch: &mut MapScratch,
    faces: u8,
    previous: Option<EnvMap>,
) -> Result<EnvMap, EnvMapError> {
    check_size(p.size)?;
    let all = all_faces(MapKind::Cube);
    if faces & !all != 0 {
        return Err(EnvMapError::BadOption {
            what: "a cube face mask has six bits",
        });
    }
    let previous = if faces == all {
        None
    } else {
        let same = previous.as_ref().is_some_and(|m| {
            m.kind == MapKind::Cube
                && m.size == p.size
                && m.frame == p.frame
                && m.centre == p.centre
        });
        if !same {
            return Err(EnvMapError::BadOption {
                what: "a partial cube update needs the previous cube map of the same size, frame and centre",
            });
        }
        previous
    };
    let side = tex_side(MapKind::Cube, p.size);
    let fov = 2.0 * (side as f32 / p.size as f32).atan().to_degrees();
    let tan_half = side as f32 / p.size as f32;
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    // Flatten the objects once for the six faces (in parallel, concatenated in order), with
    // the set of faces each triangle may touch: bit f is set unless all three vertices lie
    // outside one of the four planes (through the probe) of face f's frustum pyramid.
    // In the map frame the faces' axes are the coordinate axes (see `Face::basis`): face k
    // looks along ±axis f with image axes r and u. The sign of r and u only swaps a pair of
    // bits for every vertex alike, which leaves the test unchanged.
    const AXES: [(usize, f32, usize, usize); 6] = [
        (0, 1.0, 2, 1),
        (0, -1.0, 2, 1),
        (1, 1.0, 0, 2),
        (1, -1.0, 0, 2),
        (2, 1.0, 0, 1),
        (2, -1.0, 0, 1),
    ];
    let vertex_code = |v: Vec3| {
        let d = p.frame.to_map(v - p.centre).to_array();
        let mut code = 0u32;
        for (k, &(f, sign, r, u)) in AXES.iter().enumerate() {
            let (z, x, y) = (d[f] * sign * tan_half, d[r], d[u]);
            let c = (x > z) as u32
                | (((-x) > z) as u32) << 1
                | ((y > z) as u32) << 2
                | (((-y) > z) as u32) << 3;
            code |= c << (4 * k);
        }
        code
    };
    // Faces not drawn are masked out: their triangles are neither flattened nor drawn.
    let face_mask = |out: u32| {
        (0..6).fold(0u8, |m, k| m | ((((out >> (4 * k)) & 0xf) == 0) as u8) << k) & faces
    };
    // Outcodes once per vertex (a vertex is shared by about six triangles), all objects'
    // vertices in one buffer.
    let mut codes = std::mem::take(&mut scratch.codes);
    let mut first_vertex = Vec::with_capacity(p.objects.len());
    codes.clear();
    for o in p.objects {
        first_vertex.push(codes.len());
        codes.resize(codes.len() + o.mesh.positions.len(), 0);
    }
    for (o, &v0) in p.objects.iter().zip(&first_vertex) {
        codes[v0..v0 + o.mesh.positions.len()]
            .par_iter_mut()
            .zip(o.mesh.positions.par_iter())
            .for_each(|(c, &v)| *c = vertex_code(v));
    }
    // Flattened in fixed runs of triangles, each into its own buffer kept across updates (so a
    // steady state allocates nothing), read back in order: the same soup for any thread count.
    let runs = triangle_runs(p.objects, FLAT_RUN);
    let mut flat = std::mem::take(&mut scratch.flat);
    flat.resize_with(runs.len(), Default::default);
    flat.par_iter_mut()
        .zip(&runs)
        .for_each(|(out, (k, range))| {
            out.iter_mut().for_each(Vec::clear);
            let o = &p.objects[*k];
            let (pos, codes) = (&o.mesh.positions, &codes[first_vertex[*k]..]);
            for t in &o.mesh.triangles[range.clone()] {
                let [a, b, c] = t.map(|i| i as usize);
                let m = face_mask(codes[a] & codes[b] & codes[c]);
                let w = [pos[a], pos[b], pos[c]];
                if m == 0 || !far_enough(p, &w) {
                    continue;
                }
                if let Some(c) = flat_colour(p, o, w) {
                    for (face, out) in out.iter_mut().enumerate() {
                        if m & (1 << face) != 0 {
                            out.push((w, c));
                        }
                    }
                }
            }
        });
    scratch.codes = codes;
    let draw = |face: usize, s: &mut FaceScratch| -> Result<usize, EnvMapError> {
        let (f, _, up) = Face::ALL[face].basis();
        let (fw, uw) = (p.frame.to_world(f), p.frame.to_world(up));
        let cam = Camera::perspective_look_at(p.centre, p.centre + fw, uw, fov, side, side)?;
        // Only this face's triangles, with their own vertices: the rasteriser projects every
        // vertex of the mesh it is given.
        s.positions.clear();
        s.colors.clear();
        for (w, c) in flat.iter().flat_map(|run| &run[face]) {
            s.positions.extend_from_slice(w);
            s.colors.extend([*c; 3]);
        }
        s.draw_pieces(side, &cam, &state)?;
        Ok(0)
    };
    let result = finish_faces(MapKind::Cube, p, scratch, faces, previous, &draw);
    scratch.flat = flat;
    result
}

/// Which projection a mapped update uses.
#[derive(Clone, Copy, Debug)]
enum Projected {
    Sphere,
    Paraboloid(Hemisphere),
}

/// Map-frame direction → pixel position in the `n × n` map, or `None` where the piece must not be
/// drawn (the paraboloid's far side).
#[inline]
fn project_dir(kind: Projected, n: f32, d: Vec3) -> Option<Vec2> {
    match kind {
        Projected::Sphere => Some(sphere_uv(d) * n),
        Projected::Paraboloid(h) => {
            let s = match h {
                Hemisphere::Front => 1.0,
                Hemisphere::Back => -1.0,
            };
            if s * d.z < -PARABOLOID_OVERLAP_Z {
                return None;
            }
            let q = paraboloid_point(h, d)?;
            Some((q * (0.5 / PARABOLOID_EXTENT) + Vec2::splat(0.5)) * n)
        }
    }
}

/// Whether the spherical triangle of unit directions `a, b, c` contains direction `q`.
#[inline]
fn contains_dir(a: Vec3, b: Vec3, c: Vec3, q: Vec3) -> bool {
    let s0 = a.cross(b).dot(q);
    let s1 = b.cross(c).dot(q);
    let s2 = c.cross(a).dot(q);
    let same = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
    same && (a + b + c).dot(q) > 0.0
}

/// Emit the pieces of one mapped triangle (positions relative to the centre, map frame).
struct Mapper<'a> {
    kind: Projected,
    n: f32,
    max_edge2: f32,
    /// `1 − cos` of the angle below which a piece at a paraboloid band's edge is dropped.
    band_edge_cos: f32,
    rim: RimPolicy,
    out: &'a mut Pieces,
}

/// Mapped pieces: three vertices per piece (map-space positions) and their colours, and the
/// pieces dropped at the rim.
#[derive(Debug, Default)]
struct Pieces {
    pos: Vec<Vec3>,
    col: Vec<Vec3>,
    dropped: usize,
}

impl Mapper<'_> {
    fn emit(&mut self, q: [Vec2; 3], dist: [f32; 3], colour: Vec3) {
        let h = self.n * 0.5;
        for k in 0..3 {
            // Orthographic camera at the origin looking down −z, one unit per pixel:
            // pixel (x, y) is world (x − n/2, n/2 − y); depth is the distance to the centre.
            self.out
                .pos
                .push(Vec3::new(q[k].x - h, h - q[k].y, -dist[k]));
            self.out.col.push(colour);
        }
    }

    /// Whether the edge `a`–`b` (map-frame positions relative to the centre) must be split: an
    /// endpoint cannot be mapped, or the mapped edge is longer than the bound, or its mapped 3D
    /// midpoint lies more than the chord tolerance off the straight edge (never for edges under
    /// [`MIN_SPLIT_EDGE_TEXELS`]). It depends on the edge's endpoints alone, so the two
    /// triangles sharing an edge split it alike and no T-junction (no crack) appears between
    /// them.
    #[inline]
    fn edge_splits(&self, a: Vec3, b: Vec3, qa: Option<Vec2>, qb: Option<Vec2>) -> bool {
        let (Some(qa), Some(qb)) = (qa, qb) else {
            return true;
        };
        let e = (qa - qb).length_squared();
        if e <= MIN_SPLIT_EDGE_TEXELS * MIN_SPLIT_EDGE_TEXELS {
            return false;
        }
        if e > self.max_edge2 {
            return true;
        }
        let tol2 = CHORD_TOLERANCE_TEXELS * CHORD_TOLERANCE_TEXELS;
        let m = (a + b).normalize_or_zero();
        !project_dir(self.kind, self.n, m)
            .is_some_and(|m| (m - (qa + qb) * 0.5).length_squared() <= tol2)
    }

    fn triangle(&mut self, v: [Vec3; 3], colour: Vec3, depth: u32) {
        let dist = v.map(Vec3::length);
        if dist.iter().any(|&d| !(d > 1e-12 && d.is_finite())) {
            self.out.dropped += 1;
            return;
        }
        let d = [v[0] / dist[0], v[1] / dist[1], v[2] / dist[2]];
        let q = [
            project_dir(self.kind, self.n, d[0]),
            project_dir(self.kind, self.n, d[1]),
            project_dir(self.kind, self.n, d[2]),
        ];
        if self.rim == RimPolicy::Naive {
            if let [Some(a), Some(b), Some(c)] = q {
                self.emit([a, b, c], dist, colour);
            } else {
                self.out.dropped += 1;
            }
            return;
        }
        let straddles = match self.kind {
            Projected::Sphere => contains_dir(d[0], d[1], d[2], Vec3::NEG_Z),
            Projected::Paraboloid(_) => false,
        };
        // Pieces with a vertex outside a paraboloid's band: whole pieces narrower than 90° cannot
        // reach into the band; pieces already a few texels wide lie on the band's outer edge,
        // beyond every lookup.
        if q.iter().any(Option::is_none) {
            let cos_max = d[0].dot(d[1]).min(d[1].dot(d[2])).min(d[2].dot(d[0]));
            if q.iter().all(Option::is_none) && cos_max > 0.0 {
                return;
            }
            if 1.0 - cos_max < self.band_edge_cos {
                return;
            }
        }
        let split = if straddles {
            [true; 3]
        } else {
            [
                self.edge_splits(v[0], v[1], q[0], q[1]),
                self.edge_splits(v[1], v[2], q[1], q[2]),
                self.edge_splits(v[2], v[0], q[2], q[0]),
            ]
        };
        if split == [false; 3] {
            if let [Some(a), Some(b), Some(c)] = q {
                self.emit([a, b, c], dist, colour);
            }
            return;
        }
        if depth >= MAX_SPLIT_DEPTH {
            self.out.dropped += 1;
            return;
        }
        let mid = |i: usize| (v[i] + v[(i + 1) % 3]) * 0.5;
        let depth = depth + 1;
        match split.iter().filter(|&&s| s).count() {
            3 => {
                let (m01, m12, m20) = (mid(0), mid(1), mid(2));
                self.triangle([v[0], m01, m20], colour, depth);
                self.triangle([m01, v[1], m12], colour, depth);
                self.triangle([m20, m12, v[2]], colour, depth);
                self.triangle([m01, m12, m20], colour, depth);
            }
            1 => {
                // Edge k (from v[k] to v[k+1]) splits; the opposite vertex fans.
                let k = split.iter().position(|&s| s).expect("one edge splits");
                let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                let m = mid(k);
                self.triangle([a, m, c], colour, depth);
                self.triangle([m, b, c], colour, depth);
            }
            _ => {
                // Two edges split: rotate so that they are (a, b) and (b, c).
                let k = split.iter().position(|&s| !s).expect("one edge stays");
                let (a, b, c) = (v[(k + 1) % 3], v[(k + 2) % 3], v[k]);
                let (mab, mbc) = ((a + b) * 0.5, (b + c) * 0.5);
                self.triangle([mab, b, mbc], colour, depth);
                self.triangle([a, mab, mbc], colour, depth);
                self.triangle([a, mbc, c], colour, depth);
            }
        }
    }
}

fn update_projected(
    kind: MapKind,
    p: &UpdateParams,
    scratch: &mut MapScratch,
) -> Result<EnvMap, EnvMapError> {
    check_size(p.size)?;
    let n = p.size;
    let cam = Camera::orthographic_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, n as f32, n, n)?
        .with_clip(1e-20, f32::INFINITY)?;
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    let max_edge = MAX_MAPPED_EDGE_TEXELS
        .min(n as f32 / 4.0)
        .max(MIN_SPLIT_EDGE_TEXELS);
    scratch.dropped_pieces = 0;
    let runs = triangle_runs(p.objects, MAP_RUN);
    let draw = |face: usize, s: &mut FaceScratch| -> Result<usize, EnvMapError> {
        let proj = match (kind, face) {
            (MapKind::Sphere, _) => Projected::Sphere,
            (_, 0) => Projected::Paraboloid(Hemisphere::Front),
            _ => Projected::Paraboloid(Hemisphere::Back),
        };
        let config = |out| Mapper {
            kind: proj,
            n: n as f32,
            max_edge2: max_edge * max_edge,
            // About four texels of the band's edge: 2R/n per texel in p, ~1.2 rad per unit p.
            band_edge_cos: {
                let a = 4.0 * 2.0 * PARABOLOID_EXTENT / n as f32 * 1.2;
                0.5 * a * a
            },
            rim: p.rim,
            out,
        };
        // Runs mapped in parallel into buffers kept across updates, concatenated in order: the
        // same pieces in the same order for any thread count.
        s.pieces.resize_with(runs.len(), Pieces::default);
        s.pieces
            .par_iter_mut()
            .zip(&runs)
            .for_each(|(out, (k, range))| {
                out.pos.clear();
                out.col.clear();
                out.dropped = 0;
                let o = &p.objects[*k];
                let mut m = config(out);
                for t in &o.mesh.triangles[range.clone()] {
                    let w = t.map(|i| o.mesh.positions[i as usize]);
                    if !far_enough(p, &w) {
                        continue;
                    }
                    let v = w.map(|x| p.frame.to_map(x - p.centre));
                    if let Some(colour) = flat_colour(p, o, w) {
                        m.triangle(v, colour, 0);
                    }
                }
            });
        s.positions.clear();
        s.colors.clear();
        let mut dropped = 0;
        for run in &s.pieces {
            s.positions.extend_from_slice(&run.pos);
            s.colors.extend_from_slice(&run.col);
            dropped += run.dropped;
        }
        s.draw_pieces(n, &cam, &state)?;
        Ok(dropped)
    };
    finish_faces(kind, p, scratch, all_faces(kind), None, &draw)
}

/// Dynamic sphere map (Seed 003): the objects' triangles mapped straight into sphere-map space.
pub fn update_sphere(p: &UpdateParams, scratch: &mut MapScratch) -> Result<EnvMap, EnvMapError> {
    update_projected(MapKind::Sphere, p, scratch)
}

/// Dynamic dual-paraboloid map: the objects' triangles mapped into both paraboloids.
pub fn update_paraboloid(
    p: &UpdateParams,
    scratch: &mut MapScratch,
) -> Result<EnvMap, EnvMapError> {
    update_projected(MapKind::Paraboloid, p, scratch)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_maps_reproduce_a_smooth_environment() {
        // A smooth environment (a lat-long gradient): every map must give back the radiance of
        // the direction within the map's bilinear error.
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
                Vec3::new(0.5 + 0.5 * (x * std::f32::consts::TAU).sin(), y, 0.3)
            })
            .collect();
        let env = Environment::lat_long(w, h, texels).unwrap();
        for kind in [MapKind::Sphere, MapKind::Cube, MapKind::Paraboloid] {
            let m = EnvMap::from_environment(kind, &env, MapFrame::WORLD, Vec3::ZERO, 128).unwrap();
            let mut worst: f32 = 0.0;
            for i in 0..500 {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 500.0;
                let r = (1.0 - z * z).sqrt();
                let a = i as f32 * 2.399_963;
                let d = Vec3::new(r * a.cos(), r * a.sin(), z);
                if kind == MapKind::Sphere && z < -0.9 {
                    continue; // the rim: checked by the study, not here
                }
                let e = (m.lookup(d) - env.radiance(d)).abs().max_element();
                worst = worst.max(e);
            }
            assert!(worst < 0.06, "{kind:?}: worst error {worst}, tol 0.06");
        }
    }

    #[test]
    fn map_sizes_are_checked() {
        let e = EnvMap::from_environment(
            MapKind::Cube,
            &Environment::Sky,
            MapFrame::WORLD,
            Vec3::ZERO,
            2,
        );
        assert!(matches!(e, Err(EnvMapError::MapSize { size: 2 })));
    }
}

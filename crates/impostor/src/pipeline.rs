//! The one pipeline every sprite-like method shares: transform + cull + project → bin into
//! 32x32 tiles → per-tile pixel kernels in parallel.
//!
//! 1. **Project and bin** (the raster crate's tile binner, [`texmap_raster::bin`], parallel
//!    over chunks of at most [`CHUNK`] spheres, their size fixed by the scene's size alone):
//!    each valid sphere is moved to eye space, culled against the near/far planes and the
//!    screen, and turned into a 32-byte [`Proj`] record by the method's projection function;
//!    the binner then copies each record into every tile its box touches, sphere order kept
//!    within every tile. A copy of the projected record (not an index) lives in the bin: the
//!    tile kernels then read their bins sequentially (PERFORMANCE-NOTES: the index version
//!    spent 55% of its time on cache misses).
//! 2. **Tiles** (parallel over bands of 32 rows): each tile runs the method's depth pass over its
//!    bin in the kernel's order ([`Kernel::order`]: sphere order, or the ray-cast kernel's front
//!    to back), remembering the winning record per pixel, then its resolve pass colours each
//!    covered pixel once (deferred shading: overdraw costs a depth test, not a shade).
//!
//! **Determinism:** chunk boundaries depend on the scene's size alone (not on the thread count),
//! records keep sphere order within every bin, a kernel's order depends on the records alone,
//! the depth test is strict (`<`, so of two equal depths the record visited first wins) and
//! every tile writes only its own pixels. The same input therefore gives the same bytes for any
//! number of threads.
//!
//! All per-frame buffers live in [`Bins`], which the [`crate::Renderer`] keeps between frames.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::Vec3;
use rayon::prelude::*;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_raster::bin::{ChunkSink, TileBins, TileGrid};

use crate::options::RenderStats;
use crate::scene::SphereScene;

/// Tile side in pixels.
pub(crate) const TILE: u32 = 32;
/// Pixels per tile.
pub(crate) const TILE_PX: usize = (TILE * TILE) as usize;
/// Most spheres per projection chunk.
pub(crate) const CHUNK: usize = 16_384;
/// Fewest spheres per projection chunk (below this a chunk is not worth a rayon job).
const MIN_CHUNK: usize = 256;

/// Spheres per projection chunk for a scene of `n` spheres: at most [`CHUNK`], and small
/// scenes are cut in four (but chunks of at least [`MIN_CHUNK`]) so that both cores project
/// them (S1: 1,115 spheres, a serial ~5% of the frame in one chunk). It depends on `n` alone,
/// never on the thread count, and the bins hold the same records in the same order for any
/// chunking (chunk runs are concatenated in chunk order), so the output does not change.
fn chunk_len(n: usize) -> usize {
    n.div_ceil(4).clamp(MIN_CHUNK, CHUNK)
}
/// "No winner" in a tile's winner buffer.
pub(crate) const NONE: u32 = u32::MAX;
/// Flag bit in a winner entry: the far (inside) intersection was taken.
pub(crate) const FLAG_INSIDE: u32 = 1 << 31;

/// One projected sphere, copied into every tile bin it touches (32 bytes).
///
/// `f` is method specific (the method's `project` documents it); `bbox` is the pixel rectangle
/// `[x0, x1) x [y0, y1)` whose pixel centres may be covered, clamped to the image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct Proj {
    pub f: [f32; 5],
    pub bbox: [u16; 4],
    pub kind: u16,
    pub aux: u16,
}

const _: () = assert!(std::mem::size_of::<Proj>() == 32);
const _: () = assert!(std::mem::align_of::<Proj>() == 4);

impl Proj {
    /// The record's 32 bytes as 8 `f32` lanes (`f`, then the bit patterns of `bbox` and
    /// `kind | aux << 16`), the rows of the resolve passes' lane transposes.
    #[inline(always)]
    pub fn as_lanes(&self) -> &[f32; 8] {
        // SAFETY: `Proj` is `repr(C)`, 32 bytes with alignment 4 (asserted above) and no
        // padding (5 f32 + 6 u16), and every bit pattern is a valid `f32`.
        unsafe { &*(self as *const Proj as *const [f32; 8]) }
    }
}

/// Per-frame camera constants in the form the kernels use.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    pub width: u32,
    pub height: u32,
    pub ortho: bool,
    /// Perspective focal length k (pixels) or orthographic pixels per world unit.
    pub k: f32,
    pub inv_k: f32,
    /// Image centre in pixels.
    pub cx: f32,
    pub cy: f32,
    pub near: f32,
    pub far: f32,
    pub eye: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub back: Vec3,
    pub tiles_x: u32,
    /// Tile rows (the tile passes walk the frame in bands instead; the tests walk tiles).
    #[cfg_attr(not(test), allow(dead_code))]
    pub tiles_y: u32,
    /// The tiles for the binner (`tiles_x` by `tiles_y` tiles of [`TILE`] pixels).
    pub grid: TileGrid,
}

impl View {
    pub fn new(cam: &Camera) -> View {
        let (w, h) = (cam.width(), cam.height());
        View {
            width: w,
            height: h,
            ortho: cam.is_orthographic(),
            k: cam.scale(),
            inv_k: 1.0 / cam.scale(),
            cx: w as f32 * 0.5,
            cy: h as f32 * 0.5,
            near: cam.near(),
            far: cam.far(),
            eye: cam.eye(),
            right: cam.right(),
            up: cam.up(),
            back: -cam.forward(),
            tiles_x: w.div_ceil(TILE),
            tiles_y: h.div_ceil(TILE),
            grid: match TileGrid::new(w, h, TILE) {
                Ok(g) => g,
                Err(_) => unreachable!("a camera's sides are in 1..=MAX_IMAGE_SIDE"),
            },
        }
    }

    #[inline]
    pub fn eye_space(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.back))
    }

    /// The pixel range `[i0, i1)` whose centres `i + 0.5` lie in `[lo, hi]` widened by a small
    /// conservative epsilon, clamped to `[0, n)`.
    #[inline]
    pub fn pixel_range(lo: f32, hi: f32, n: u32) -> (u16, u16) {
        // A tiny widening (1e-3 px plus a relative term) keeps the bound conservative against
        // rounding in the projection; the kernels' exact tests decide coverage.
        let eps = 1e-3 + 1e-6 * lo.abs().max(hi.abs());
        // Clamp first (the bounds may be huge near the eye plane, or NaN: then nothing), then
        // floor/ceil by integer conversion (no libm call in the portable baseline).
        let nf = n as f32;
        let a = lo - 0.5 - eps;
        let b = hi - 0.5 + eps;
        if !(a < nf && b >= -1.0 && a <= b) {
            return (0, 0);
        }
        let a = a.max(-1.0);
        let b = b.min(nf);
        // ceil(a) for a ≥ −1 and floor(b) for b ≥ −1.
        // SAFETY: a, b ∈ [−1, n] (clamped above; NaN returned early), so the truncations are
        // exact and in range; the checked `as` casts cost ~30 instructions per sphere here.
        let ai = unsafe { a.to_int_unchecked::<i32>() };
        let ceil_a = ai + ((ai as f32) < a) as i32;
        let bi = unsafe { b.to_int_unchecked::<i32>() };
        let floor_b = bi - ((bi as f32) > b) as i32;
        let i0 = ceil_a.max(0);
        let i1 = (floor_b + 1).min(n as i32);
        if i0 >= i1 {
            return (0, 0);
        }
        (i0 as u16, i1 as u16)
    }
}

/// What a method's projection decided for one valid sphere.
pub(crate) enum Projected {
    Draw(Proj),
    Culled,
}

/// The reusable per-frame buffers: the binned records of the frame.
#[derive(Debug, Default)]
pub(crate) struct Bins {
    bins: TileBins<Proj>,
}

impl Bins {
    /// Project every sphere with `project` and bin the records into tiles. Returns the stats.
    pub fn build<F>(&mut self, scene: &SphereScene, view: &View, project: F) -> RenderStats
    where
        F: Fn(Vec3, f32, u16) -> Projected + Sync,
    {
        let n = scene.len();
        let chunk_stats = self.bins.build(view.grid, n, chunk_len(n), |range, sink| {
            project_chunk(scene, view, &project, range, sink)
        });
        let mut stats = RenderStats::default();
        for s in &chunk_stats {
            stats.drawn += s.drawn;
            stats.culled += s.culled;
            stats.skipped_invalid += s.skipped_invalid;
        }
        stats
    }

    /// The records of tile `t`, in sphere order.
    #[inline]
    pub fn tile(&self, t: usize) -> &[Proj] {
        self.bins.tile(t)
    }
}

/// The project pass of [`Bins::build`] for one chunk of spheres: transform, cull, project,
/// push into the tiles of the record's box. Not inlined, so that profiles show the stage.
#[inline(never)]
fn project_chunk<F>(
    scene: &SphereScene,
    view: &View,
    project: &F,
    range: std::ops::Range<usize>,
    sink: &mut ChunkSink<'_, Proj>,
) -> RenderStats
where
    F: Fn(Vec3, f32, u16) -> Projected + Sync,
{
    let mut stats = RenderStats::default();
    for i in range {
        if !scene.is_valid(i) {
            stats.skipped_invalid += 1;
            continue;
        }
        let c = view.eye_space(scene.centers[i]);
        match project(c, scene.radii[i], scene.kinds[i]) {
            Projected::Draw(p) => {
                // A drawn record's box holds at least one pixel of the image.
                let [x0, y0, x1, y1] = p.bbox.map(u32::from);
                match view.grid.span(x0, y0, x1, y1) {
                    Some(span) => {
                        stats.drawn += 1;
                        sink.push(span, p);
                    }
                    None => stats.culled += 1,
                }
            }
            Projected::Culled => stats.culled += 1,
        }
    }
    stats
}

/// The pixel rectangle of one tile.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TileRect {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
}

/// Lane width of the vectorised kernels.
pub(crate) const LANES: usize = 8;
/// Tile buffer length: a row stride of [`TILE`] plus [`LANES`] slack, so that a full 8-lane
/// chunk starting anywhere in a row stays inside the buffer (lanes past the sphere's box carry
/// an infinite depth and never win).
pub(crate) const TILE_BUF: usize = TILE_PX + LANES;

/// Longest bin a [`Kernel::order`] may reorder (its scratch copy is 8 KB).
pub(crate) const ORDER_MAX: usize = 256;

/// A tile's depth and winner buffers (row stride [`TILE`]).
pub(crate) struct TileBuf {
    pub depth: [f32; TILE_BUF],
    pub win: [u32; TILE_BUF],
}

/// A method's per-pixel work, chosen once per frame (static dispatch).
pub(crate) trait Kernel: Sync {
    /// Depth pass: test every record of the bin (in order) against the tile's pixels, keeping
    /// in `buf` the nearest depth and the index of its record (plus [`FLAG_INSIDE`]). A depth
    /// is written only together with its winner, so pixels left at [`NONE`] keep an infinite
    /// depth ([`draw_tiles`] copies the depths as they are).
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf);
    /// The order in which both passes take the tile's records: the bin itself (the default),
    /// or a reordered copy in `scratch` (bins of at most [`ORDER_MAX`] records). Winner
    /// indices are positions in the returned slice. The order must depend on the records alone
    /// (determinism); it decides exact depth ties, which the first record visited wins (see the
    /// ray-cast kernel's front-to-back order).
    fn order<'r>(&self, recs: &'r [Proj], _scratch: &'r mut [Proj; ORDER_MAX]) -> &'r [Proj] {
        recs
    }
    /// Colour of pixel `(x, y)` won by `rec` at `depth` (sRGB RGBA8).
    fn resolve(&self, rec: &Proj, x: u32, y: u32, depth: f32, flags: u32) -> [u8; 4];

    /// Draw one tile (see [`TileJob`]). The default runs [`draw_tile`]; a kernel built for wider
    /// vectors runs that same body inside its `#[target_feature]` build, so that the buffer
    /// clears and the depth copies use those vectors too.
    fn draw_tile(&self, job: TileJob<'_>)
    where
        Self: Sized,
    {
        draw_tile(self, job);
    }

    /// Colours of one tile: `color[j * stride + i]` for tile pixel `(i, j)` (background where
    /// nothing won). The default calls [`Kernel::resolve`] per pixel; kernels with costly
    /// shading override it with lanes over the covered pixels.
    fn resolve_tile(
        &self,
        recs: &[Proj],
        tile: TileRect,
        buf: &TileBuf,
        background: [u8; 4],
        color: &mut [[u8; 4]],
        stride: usize,
    ) {
        for j in 0..tile.h {
            for i in 0..tile.w {
                let b = (j * TILE + i) as usize;
                let wv = buf.win[b];
                color[j as usize * stride + i as usize] = if wv == NONE {
                    background
                } else {
                    let rec = &recs[(wv & !FLAG_INSIDE) as usize];
                    self.resolve(
                        rec,
                        tile.x0 + i,
                        tile.y0 + j,
                        buf.depth[b],
                        wv & FLAG_INSIDE,
                    )
                };
            }
        }
    }
}

/// One non-empty tile's work for [`Kernel::draw_tile`]: its records (bin order), rectangle and
/// buffers, and the frame's colours and depths from the tile's first pixel on (row stride
/// `stride`).
pub(crate) struct TileJob<'a> {
    pub recs: &'a [Proj],
    pub tile: TileRect,
    pub buf: &'a mut TileBuf,
    pub scratch: &'a mut [Proj; ORDER_MAX],
    pub background: [u8; 4],
    pub color: &'a mut [[u8; 4]],
    pub depth: &'a mut [f32],
    pub stride: usize,
}

/// One tile: clear the buffers, the depth pass over the bin in the kernel's order, the resolve
/// (each covered pixel coloured once), the depths out.
#[inline(always)]
pub(crate) fn draw_tile<K: Kernel>(kernel: &K, job: TileJob<'_>) {
    let TileJob {
        recs,
        tile,
        buf,
        scratch,
        background,
        color,
        depth,
        stride,
    } = job;
    fill8(&mut buf.depth, f32::INFINITY);
    fill8(&mut buf.win, NONE);
    let recs = kernel.order(recs, scratch);
    kernel.raster(recs, tile, buf);
    kernel.resolve_tile(recs, tile, buf, background, color, stride);
    // Depths: every kernel writes a depth and its winner together (strict `<` against an
    // infinite start), so pixels nothing won still hold INFINITY: a plain copy.
    let tw = tile.w as usize;
    for j in 0..tile.h as usize {
        let o = j * stride;
        let bw = j * TILE as usize;
        copy_row(&mut depth[o..o + tw], &buf.depth[bw..bw + tw]);
    }
}

/// `dst.fill(v)` eight elements per store: `<[T]>::fill` on `[u8; 4]` pixels (and on `f32`
/// depths) compiles to one 4-byte store per element, which made the background of an empty
/// 500x500 frame cost ~0.9 M instructions; whole `[T; 8]` blocks become 256-bit stores.
#[inline(always)]
pub(crate) fn fill8<T: Copy>(dst: &mut [T], v: T) {
    let mut blocks = dst.chunks_exact_mut(8);
    for b in &mut blocks {
        let b: &mut [T; 8] = b.try_into().expect("chunks of 8");
        *b = [v; 8];
    }
    for x in blocks.into_remainder() {
        *x = v;
    }
}

/// `dst.copy_from_slice(src)` for a tile row (at most [`TILE`] elements): whole rows as one
/// fixed-size copy (inlined vector moves) instead of a `memcpy` call per row.
#[inline(always)]
pub(crate) fn copy_row<T: Copy>(dst: &mut [T], src: &[T]) {
    const T_: usize = TILE as usize;
    match (
        <&mut [T; T_]>::try_from(&mut *dst),
        <&[T; T_]>::try_from(src),
    ) {
        (Ok(d), Ok(s)) => *d = *s,
        _ => dst.copy_from_slice(src),
    }
}

/// Clip a record's box to a tile: `(x0, y0, x1, y1)` in tile-local pixels, or `None`.
#[inline]
pub(crate) fn clip(p: &Proj, t: TileRect) -> Option<(u32, u32, u32, u32)> {
    let x0 = (p.bbox[0] as u32).max(t.x0);
    let y0 = (p.bbox[1] as u32).max(t.y0);
    let x1 = (p.bbox[2] as u32).min(t.x0 + t.w);
    let y1 = (p.bbox[3] as u32).min(t.y0 + t.h);
    (x0 < x1 && y0 < y1).then(|| (x0 - t.x0, y0 - t.y0, x1 - t.x0, y1 - t.y0))
}

/// Run `kernel` over every tile, writing the whole frame (background where nothing won).
/// Walk every tile of the frame, in parallel by rows of tiles (one job per row: the rows' costs
/// differ a lot, and rayon's default splitting would leave one thread with the dense half).
/// `init` makes each row's scratch state; `f(state, t, tile, color, depth)` gets the tile's index
/// in the bins, its rectangle and the row's colour and depth slices from the tile's first
/// column (row stride `view.width`).
pub(crate) fn for_each_tile<S>(
    view: &View,
    frame: &mut Frame,
    init: impl Fn() -> S + Sync,
    f: impl Fn(&mut S, usize, TileRect, &mut [[u8; 4]], &mut [f32]) + Sync,
) {
    let w = view.width as usize;
    let band = w * TILE as usize;
    frame
        .color
        .par_chunks_mut(band)
        .zip(frame.depth.par_chunks_mut(band))
        .enumerate()
        .with_max_len(1)
        .for_each(|(ty, (color, depth))| {
            let mut state = init();
            let y0 = ty as u32 * TILE;
            let h = (view.height - y0).min(TILE);
            for tx in 0..view.tiles_x {
                let x0 = tx * TILE;
                let tile = TileRect {
                    x0,
                    y0,
                    w: (view.width - x0).min(TILE),
                    h,
                };
                let t = ty * view.tiles_x as usize + tx as usize;
                f(
                    &mut state,
                    t,
                    tile,
                    &mut color[x0 as usize..],
                    &mut depth[x0 as usize..],
                );
            }
        });
}

pub(crate) fn draw_tiles<K: Kernel>(
    bins: &Bins,
    view: &View,
    kernel: &K,
    background: [u8; 4],
    frame: &mut Frame,
) {
    let w = view.width as usize;
    let init = || {
        (
            TileBuf {
                depth: [f32::INFINITY; TILE_BUF],
                win: [NONE; TILE_BUF],
            },
            [Proj::default(); ORDER_MAX],
        )
    };
    for_each_tile(
        view,
        frame,
        init,
        |(buf, scratch), t, tile, color, depth| {
            let recs = bins.tile(t);
            if recs.is_empty() {
                // Nothing here: background.
                for j in 0..tile.h as usize {
                    let o = j * w;
                    fill8(&mut color[o..o + tile.w as usize], background);
                    fill8(&mut depth[o..o + tile.w as usize], f32::INFINITY);
                }
                return;
            }
            kernel.draw_tile(TileJob {
                recs,
                tile,
                buf,
                scratch,
                background,
                color,
                depth,
                stride: w,
            });
        },
    );
}

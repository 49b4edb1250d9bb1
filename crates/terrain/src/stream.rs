//! Streamed texturing of the flight view: every drawn chunk is textured from the database's GST
//! pyramid at the level its on-screen size needs, through the map cache, under one byte budget.
//!
//! **What is resident.** A [`TextureStream`] holds two things, both least-recently-used under
//! one budget ([`TextureStream::new`]): a quarter of it goes to the [`gst::GstCache`] of 256²
//! sRGB8 maps (4 bytes a texel) and the rest to the per-chunk textures, keyed by
//! `(chunk, level)`, each a small clamped gamma-correct [`MipTexture`] (linear `f32` RGBA, about
//! 21 bytes a texel with its mip levels). Nothing else of the photo is held: no whole-terrain
//! texture is assembled, so the photo's size does not bound the memory.
//!
//! **When it loads.** Per frame ([`FlightTerrain::render_streamed`]):
//!
//! 1. The maps Seed 000's active area (Eq. 5–7) asks for around the eye
//!    ([`FlightTerrain::needed_maps`]) are made resident through the map cache when they fit in
//!    its share of the budget (loads counted); otherwise they are loaded on demand in step 3.
//! 2. Each selected chunk gets the level of Eq. (7)'s rule at its nearest point: the coarsest
//!    level whose texel is no larger than a pixel there, `2^L ≥ extent · k / (T · d)` (`extent`
//!    the terrain's larger side in metres, `k` the focal length in pixels, `T` the map side, `d`
//!    the distance from the eye to the chunk's bounding box), capped by the finest level. A
//!    selected chunk whose uv rectangle spans more than [`MAX_CHUNK_TEXELS`] texels at that level
//!    is first replaced by its children in the view frustum (texture-driven refinement: smooth
//!    terrain keeps large chunks near the eye, whose textures would otherwise be huge). If the
//!    frame's chunk textures at those levels would not fit in the chunk share of the budget, the
//!    finest chunks fall back one level at a time (ties: the farther chunk first) until they
//!    fit. A budget that cannot hold even the coarsest textures of the frame is an error
//!    ([`ViewError::TextureBudget`]), as is one that cannot hold one map and one level-0
//!    texture ([`TextureStream::new`]).
//! 3. A chunk texture not resident is built from the maps covering its texel rectangle, read
//!    through the map cache (a map not resident is loaded from `tiles/L/X_Y.png`); textures of
//!    earlier frames are evicted, least recently used first, to make room. Textures of the
//!    current frame are never evicted while it is drawn.
//!
//! **How seams are avoided.** A chunk's texture at level `L` covers the chunk's uv rectangle
//! plus a border of [`BORDER`] texels of the neighbouring maps, and its rectangle is aligned to
//! multiples of [`BORDER`] texels of level `L` (clipped at the terrain's edges, where the whole
//! texture clamps too). Texel `(i, j)` of the chunk texture is texel `(tx0 + i, ty0 + j)` of
//! level `L`, and the chunk's texture coordinates are remapped to `u' = (u·N − tx0) / w` (`N`
//! the level's side, `w` the texture's width), so every sampler reads the same texel positions
//! it would read in the whole level. Because the rectangle is aligned, the chunk texture's mip
//! levels 1..=4 are exact windows of the whole level's mips (a 2x2 box over the same texels),
//! and the border covers the footprint of bilinear, trilinear and the span banks (3x3, 4x4) up
//! to mip 3 at the chunk's edges (a 2-texel footprint at mip `m` spans `2^(m+1)` level texels).
//! Beyond that, and where the anisotropic sampler's taps run further along a long footprint than
//! the border, the chunk texture repeats its edge texels where the whole level would have read
//! its neighbour's: a difference confined to coarse, far samples. Two neighbouring chunks therefore
//! sample the same colours along their shared edge unless their levels differ and one of them
//! magnifies there; the level rule keeps magnification to a chunk's nearest point.
//!
//! **Drawing.** The frame is one [`Framebuffer::draw_textured`] call: the chunk meshes are
//! concatenated nearest first (the depth test then skips hidden texels as in the whole frame),
//! each chunk's texture coordinates remapped into its own texture, and the sampler picks the
//! chunk's texture by the triangle each quad belongs to ([`texmap_raster::TexQuad::triangle`]).
//! Its cost against the whole-texture frame is measured by the `flight_1024x768_streamed` group
//! of `benches/flight.rs`.
//!
//! Frames are deterministic: planning, loading and eviction are sequential with ties broken by
//! keys, and the rasteriser's output does not depend on the thread count.

use crate::db::Database;
use crate::error::format_err;
use crate::gst::{self, GstCache, MapKey};
use crate::view::{
    ChunkRef, FlightCamera, FlightTerrain, FrameScratch, FrameStats, Frustum, Selection, ViewError,
    ViewOptions,
};
use glam::Vec2;
use std::collections::HashMap;
use texmap_core::camera::Camera;
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_raster::{Cull, DrawState, Framebuffer, MipSampler, QuadSampler, TexQuad};

/// Border (and alignment) of a chunk texture, in texels of its level.
pub const BORDER: u32 = 16;

/// A chunk whose uv rectangle spans more texels than this at the level it needs is replaced by
/// its children (when it has any), so one near, coarse chunk never needs a huge texture.
pub const MAX_CHUNK_TEXELS: u32 = 1024;

/// Key of a chunk texture: the chunk (depth, index in its level) and the GST level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ChunkTexKey {
    pub depth: u32,
    pub index: usize,
    pub level: u32,
}

/// One chunk's texture: texels `tx0..tx0 + width`, `ty0..ty0 + height` of GST level `level`.
#[derive(Debug)]
pub struct ChunkTexture {
    pub level: u32,
    /// The side of the whole level, in texels (`T·2^level`).
    pub level_side: u32,
    pub tx0: u32,
    pub ty0: u32,
    pub width: u32,
    pub height: u32,
    pub texture: MipTexture,
}

impl ChunkTexture {
    /// Bytes of the texture's texels (all mip levels).
    pub fn bytes(&self) -> u64 {
        std::mem::size_of_val(self.texture.texels()) as u64
    }
}

/// Counters of a [`TextureStream`] (integer counts: identical for any thread count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct StreamStats {
    /// Chunk textures built (all frames) and evicted.
    pub chunk_textures_built: u64,
    pub chunk_textures_evicted: u64,
    /// Chunk textures resident and their bytes.
    pub chunk_textures_resident: u64,
    pub chunk_texture_bytes: u64,
    /// Chunks drawn one or more levels coarser than Eq. (7) asked for, to fit the budget (last
    /// frame).
    pub chunks_fallen_back: u64,
    /// Chunks the last frame's selection replaced by their children for [`MAX_CHUNK_TEXELS`].
    pub chunks_split: u64,
    /// The coarsest and finest GST level drawn (last frame).
    pub coarsest_level: u32,
    pub finest_level: u32,
}

/// The streamed texture source of a database (see the module docs).
pub struct TextureStream {
    db: Database,
    map_texels: u32,
    levels: u32,
    maps: GstCache,
    map_budget: u64,
    chunk_budget: u64,
    textures: HashMap<ChunkTexKey, (ChunkTexture, u64)>,
    tick: u64,
    stats: StreamStats,
}

/// Bytes a chunk texture of `w x h` level-0 texels takes (texels of all mip levels, plus the
/// seam strips power-of-two pyramids carry; see [`MipTexture`]).
pub fn chunk_texture_bytes(w: u32, h: u32) -> u64 {
    let (mut a, mut b) = (w as u64, h as u64);
    let mut texels = 0u64;
    let mut strips = 0u64;
    loop {
        texels += a * b;
        strips += 4 * (b + 2) + 4 * a;
        if a == 1 && b == 1 {
            break;
        }
        a = (a / 2).max(1);
        b = (b / 2).max(1);
    }
    let pow2 = w.is_power_of_two() && h.is_power_of_two();
    16 * (texels + if pow2 { strips } else { 0 })
}

impl TextureStream {
    /// A stream over `db`'s GST pyramid holding at most `budget_bytes` (maps and chunk textures
    /// together). Errors: the database has no texture, or the budget cannot hold one map plus
    /// one level-0 texture (the coarsest a chunk can be drawn with).
    pub fn new(db: &Database, budget_bytes: u64) -> Result<TextureStream, ViewError> {
        let Some(t) = &db.manifest.texture else {
            return Err(ViewError::BadParameter {
                name: "texture source",
                value: "streamed".into(),
                expected: "a database built with a photo (its GST maps are streamed)",
            });
        };
        let (map_texels, levels) = (t.map_texels, t.levels);
        if map_texels == 0 || levels == 0 || levels > 20 {
            return Err(ViewError::Terrain(format_err(
                &db.dir.join("manifest.json").display().to_string(),
                "texture",
                format!("map texels > 0 and 1..=20 levels (got {map_texels}, {levels})"),
            )));
        }
        let map_budget = budget_bytes / 4;
        let chunk_budget = budget_bytes - map_budget;
        let one_map = 4 * map_texels as u64 * map_texels as u64;
        let coarsest = chunk_texture_bytes(map_texels, map_texels);
        if map_budget < one_map || chunk_budget < coarsest {
            return Err(ViewError::TextureBudget {
                budget: budget_bytes,
                needed: (4 * one_map).max(coarsest + coarsest / 3 + 1),
                what: "one GST map and one level-0 chunk texture",
            });
        }
        Ok(TextureStream {
            db: db.clone(),
            map_texels,
            levels,
            maps: GstCache::new(map_budget),
            map_budget,
            chunk_budget,
            textures: HashMap::new(),
            tick: 0,
            stats: StreamStats::default(),
        })
    }

    /// The map cache's counters.
    pub fn map_stats(&self) -> gst::CacheStats {
        self.maps.stats()
    }

    pub fn stats(&self) -> StreamStats {
        self.stats
    }

    /// The texel rectangle `(tx0, ty0, w, h)` of level `level` a chunk with uv rectangle
    /// `[u0, u1] x [v0, v1]` needs: its texels, a [`BORDER`] around, aligned to [`BORDER`],
    /// clipped to the level.
    pub fn rect(&self, uv: [f32; 4], level: u32) -> (u32, u32, u32, u32) {
        let n = (self.map_texels as u64) << level;
        let a = align(self.map_texels) as i64;
        let span = |lo: f32, hi: f32| {
            let t0 = ((lo as f64 * n as f64).floor() as i64 - BORDER as i64).div_euclid(a) * a;
            let t1 =
                ((hi as f64 * n as f64).ceil() as i64 + BORDER as i64 + a - 1).div_euclid(a) * a;
            let t0 = t0.clamp(0, n as i64 - a);
            let t1 = t1.clamp(t0 + a, n as i64);
            (t0 as u32, (t1 - t0) as u32)
        };
        let (tx0, w) = span(uv[0], uv[1]);
        let (ty0, h) = span(uv[2], uv[3]);
        (tx0, ty0, w, h)
    }

    /// Build (or find) the texture of `chunk` at `level`, marking it used at `tick`.
    fn ensure(
        &mut self,
        key: ChunkTexKey,
        uv: [f32; 4],
        frame_start: u64,
    ) -> Result<(), ViewError> {
        self.tick += 1;
        let tick = self.tick;
        if let Some(e) = self.textures.get_mut(&key) {
            e.1 = tick;
            return Ok(());
        }
        let (tx0, ty0, w, h) = self.rect(uv, key.level);
        let t = self.map_texels;
        let mut img = vec![0u8; 4 * w as usize * h as usize];
        let db = &self.db;
        for my in ty0 / t..(ty0 + h).div_ceil(t) {
            for mx in tx0 / t..(tx0 + w).div_ceil(t) {
                let mk = MapKey {
                    level: key.level,
                    x: mx,
                    y: my,
                };
                let map = self.maps.get(mk, |k| db.map(k))?;
                if map.dimensions() != (t, t) {
                    return Err(ViewError::Terrain(format_err(
                        &db.dir
                            .join(format!("tiles/{}/{}_{}.png", mk.level, mk.x, mk.y))
                            .display()
                            .to_string(),
                        "size",
                        format!("a {t} x {t} map (got {:?})", map.dimensions()),
                    )));
                }
                // The overlap of this map with the rectangle, in level texels.
                let (x0, x1) = ((mx * t).max(tx0), ((mx + 1) * t).min(tx0 + w));
                let (y0, y1) = ((my * t).max(ty0), ((my + 1) * t).min(ty0 + h));
                let raw = map.as_raw();
                for y in y0..y1 {
                    let src = 4 * (((y - my * t) * t + (x0 - mx * t)) as usize);
                    let dst = 4 * (((y - ty0) * w + (x0 - tx0)) as usize);
                    let len = 4 * (x1 - x0) as usize;
                    img[dst..dst + len].copy_from_slice(&raw[src..src + len]);
                }
            }
        }
        let texture = MipTexture::from_srgb8(w, h, &img, Reduction::GammaCorrect, Wrap::Clamp)
            .map_err(ViewError::Texture)?;
        let tex = ChunkTexture {
            level: key.level,
            level_side: t << key.level,
            tx0,
            ty0,
            width: w,
            height: h,
            texture,
        };
        let bytes = tex.bytes();
        // Evict textures of earlier frames, least recently used first (ties by key).
        while self.stats.chunk_texture_bytes + bytes > self.chunk_budget {
            let victim = self
                .textures
                .iter()
                .filter(|(_, v)| v.1 < frame_start)
                .min_by_key(|(k, v)| (v.1, **k))
                .map(|(k, _)| *k);
            let Some(victim) = victim else { break };
            let (old, _) = self.textures.remove(&victim).expect("present");
            self.stats.chunk_texture_bytes -= old.bytes();
            self.stats.chunk_textures_evicted += 1;
        }
        self.stats.chunk_texture_bytes += bytes;
        self.stats.chunk_textures_built += 1;
        self.textures.insert(key, (tex, tick));
        self.stats.chunk_textures_resident = self.textures.len() as u64;
        Ok(())
    }
}

/// The largest power of two dividing `map_texels`, at most [`BORDER`].
fn align(map_texels: u32) -> u32 {
    (1u32 << map_texels.trailing_zeros()).min(BORDER)
}

/// The uv rectangle `[u0, u1, v0, v1]` of a chunk's cell (its vertices' texture coordinates,
/// [`crate::chunks::vertex`], lie within it; the padding beyond the grid is clipped).
fn uv_rect(grid: &crate::dem::Grid, c: &crate::db::ChunkEntry) -> [f32; 4] {
    let (w1, h1) = ((grid.width() - 1) as f32, (grid.height() - 1) as f32);
    let last = (c.size - 1) as f32;
    [
        c.x0 as f32 / w1,
        (c.x0 as f32 + last) / w1,
        c.y0 as f32 / h1,
        (c.y0 as f32 + last) / h1,
    ]
    .map(|x| x.clamp(0.0, 1.0))
}

/// The textures of a frame's chunks in one draw call: chunk `i` owns the triangles from
/// `starts[i]` up to the next start and is sampled from `samplers[i]`.
struct PerChunk<'a> {
    starts: Vec<u32>,
    samplers: Vec<MipSampler<'a>>,
}

impl QuadSampler for PerChunk<'_> {
    #[inline]
    fn sample_quad(&self, quad: &TexQuad) -> [glam::Vec3; 4] {
        let i = self.starts.partition_point(|&s| s <= quad.triangle);
        self.samplers[i.saturating_sub(1)].sample_quad(quad)
    }
}

/// The level Eq. (7)'s rule asks for at distance `d` (see the module docs).
fn wanted_level(extent_m: f64, k: f64, map_texels: u32, d: f64, levels: u32) -> u32 {
    let need = extent_m * k / (map_texels as f64 * d.max(1e-6));
    if !need.is_finite() || need <= 1.0 {
        return 0;
    }
    (need.log2().ceil() as u32).min(levels - 1)
}

impl FlightTerrain {
    /// One frame textured from the GST pyramid through `stream` (see [`crate::stream`]): camera,
    /// selection, per-chunk levels under the budget, chunk textures made resident, one draw per
    /// chunk into `fb` (cleared to the background first). The statistics add the map cache's
    /// and the chunk textures' residency (`maps_resident`, `maps_loaded`, `cache_bytes`,
    /// `chunk_texture_bytes`).
    pub fn render_streamed(
        &self,
        view: &FlightCamera,
        options: &ViewOptions,
        stream: &mut TextureStream,
        fb: &mut Framebuffer,
        scratch: &mut FrameScratch,
    ) -> Result<FrameStats, ViewError> {
        options.check()?;
        let camera = view.camera(self.grid())?;
        let mut sel = self.select(&camera, options.pixel_error);
        self.split_for_texture(&camera, &mut sel, stream);
        let loads_before = stream.maps.stats().loads;
        // Step 1: Seed 000's active area, when it fits the map share.
        let needed = self.needed_maps(view);
        if let Some(keys) = &needed {
            let bytes = keys.len() as u64 * 4 * (stream.map_texels as u64).pow(2);
            if bytes <= stream.map_budget {
                let db = &stream.db;
                stream.maps.make_resident(keys, |k| db.map(k))?;
            }
        }
        // Step 2: levels.
        let plan = self.plan_levels(&camera, &sel.chunks, stream)?;
        self.prepare(&sel.chunks)?;
        // Step 3: textures.
        let frame_start = stream.tick + 1;
        for (c, level, uv) in &plan {
            let key = ChunkTexKey {
                depth: c.depth,
                index: c.index,
                level: *level,
            };
            stream.ensure(key, *uv, frame_start)?;
        }
        fb.clear(options.background);
        let state = DrawState {
            cull: Cull::Back,
            ..DrawState::default()
        };
        let mut stats = FrameStats {
            chunks_drawn: sel.chunks.len() as u32,
            chunks_visited: sel.visited,
            chunks_culled: sel.culled,
            chunks_per_level: sel.chunks_per_level.clone(),
            ..FrameStats::default()
        };
        // Step 4: one draw call. The chunk meshes are concatenated nearest first, each chunk's
        // uvs remapped to its own texture; the sampler picks the chunk's texture by the
        // triangle each quad belongs to.
        let mut frame_bytes = 0u64;
        let mut per_chunk = PerChunk {
            starts: Vec::with_capacity(plan.len()),
            samplers: Vec::with_capacity(plan.len()),
        };
        scratch.clear();
        for (c, level, _) in &plan {
            let key = ChunkTexKey {
                depth: c.depth,
                index: c.index,
                level: *level,
            };
            let tex = &stream.textures[&key].0;
            frame_bytes += tex.bytes();
            stats.texture_side = stats.texture_side.max(stream.map_texels << tex.level);
            per_chunk.samplers.push(MipSampler {
                texture: &tex.texture,
                sampler: options.sampler,
            });
            let n = tex.level_side as f64;
            let (sx, sy) = (n / tex.width as f64, n / tex.height as f64);
            let (ox, oy) = (
                tex.tx0 as f64 / tex.width as f64,
                tex.ty0 as f64 / tex.height as f64,
            );
            let first = scratch.append(&*self.mesh(*c)?, |p| {
                Vec2::new((p.x as f64 * sx - ox) as f32, (p.y as f64 * sy - oy) as f32)
            });
            per_chunk.starts.push(first);
            stats.surface_triangles += self.chunk(*c).triangles as u64;
        }
        let mesh = scratch.mesh()?;
        let ds = fb.draw_textured(&camera, &mesh, &per_chunk, &state)?;
        stats.triangles = ds.submitted as u64;
        stats.triangles_binned = ds.binned as u64;
        stats.triangles_backface = ds.culled as u64;
        stats.triangles_clipped = ds.clipped as u64;
        let ms = stream.maps.stats();
        stats.texture_bytes = frame_bytes;
        stats.maps_needed = needed.map(|k| k.len() as u64);
        stats.maps_resident = Some(ms.resident);
        stats.maps_loaded = Some(ms.loads - loads_before);
        stats.cache_bytes = Some(ms.resident_bytes + stream.stats.chunk_texture_bytes);
        stats.chunk_texture_bytes = Some(stream.stats.chunk_texture_bytes);
        stats.chunk_cache = self.chunk_cache();
        Ok(stats)
    }

    /// The terrain's larger side in metres.
    fn extent_m(&self) -> f64 {
        let g = self.grid().georef();
        let (e0, s0) = g.local_metres(0.0, 0.0);
        let (e1, s1) = g.local_metres(
            (self.grid().width() - 1) as f64,
            (self.grid().height() - 1) as f64,
        );
        (e1 - e0).abs().max((s1 - s0).abs())
    }

    /// Replace selected chunks whose uv rectangle spans more than [`MAX_CHUNK_TEXELS`] at the
    /// level they need by their children in the view frustum, recursively; nearest first again.
    fn split_for_texture(&self, camera: &Camera, sel: &mut Selection, stream: &mut TextureStream) {
        let frustum = Frustum::new(camera);
        let (extent, k, eye) = (self.extent_m(), camera.scale() as f64, camera.eye());
        let mut out = Vec::with_capacity(sel.chunks.len());
        let mut stack: Vec<ChunkRef> = sel.chunks.iter().rev().copied().collect();
        let mut split = 0;
        while let Some(c) = stack.pop() {
            let chunk = self.chunk(c);
            let uv = uv_rect(self.grid(), chunk);
            let d = self.bounds(c).distance(eye) as f64;
            let l = wanted_level(extent, k, stream.map_texels, d, stream.levels);
            let n = ((stream.map_texels as u64) << l) as f64;
            let span = ((uv[1] - uv[0]).max(uv[3] - uv[2])) as f64 * n;
            if span <= MAX_CHUNK_TEXELS as f64 || c.depth >= self.max_depth() {
                out.push(c);
                continue;
            }
            split += 1;
            let next = &self.levels()[c.depth as usize + 1];
            for (cx, cy) in [(1, 1), (0, 1), (1, 0), (0, 0)] {
                let key = (2 * chunk.iy + cy, 2 * chunk.ix + cx);
                if let Ok(i) = next.binary_search_by_key(&key, |ch| (ch.iy, ch.ix)) {
                    let child = ChunkRef {
                        depth: c.depth + 1,
                        index: i,
                    };
                    if !frustum.culls(&self.bounds(child)) {
                        stack.push(child);
                    }
                }
            }
        }
        // A stable sort on a total order, as the selection's: deterministic.
        out.sort_by(|a, b| {
            self.bounds(*a)
                .distance(eye)
                .total_cmp(&self.bounds(*b).distance(eye))
        });
        sel.chunks_per_level.iter_mut().for_each(|x| *x = 0);
        for c in &out {
            sel.chunks_per_level[c.depth as usize] += 1;
        }
        sel.chunks = out;
        stream.stats.chunks_split = split;
    }

    /// Per chunk of `chunks`: the level Eq. (7) asks for, lowered to fit the chunk budget.
    fn plan_levels(
        &self,
        camera: &Camera,
        chunks: &[ChunkRef],
        stream: &mut TextureStream,
    ) -> Result<Vec<(ChunkRef, u32, [f32; 4])>, ViewError> {
        let extent = self.extent_m();
        let k = camera.scale() as f64;
        let eye = camera.eye();
        let mut plan: Vec<(ChunkRef, u32, [f32; 4])> = chunks
            .iter()
            .map(|&c| {
                let uv = uv_rect(self.grid(), self.chunk(c));
                let d = self.bounds(c).distance(eye) as f64;
                let l = wanted_level(extent, k, stream.map_texels, d, stream.levels);
                (c, l, uv)
            })
            .collect();
        let bytes_of = |s: &TextureStream, uv: [f32; 4], l: u32| {
            let (_, _, w, h) = s.rect(uv, l);
            chunk_texture_bytes(w, h)
        };
        let mut sizes: Vec<u64> = plan.iter().map(|p| bytes_of(stream, p.2, p.1)).collect();
        let mut total: u64 = sizes.iter().sum();
        let mut fallen = vec![false; plan.len()];
        while total > stream.chunk_budget {
            // The finest chunk, the farther one (later in the nearest-first order) on ties.
            let Some(i) = (0..plan.len())
                .filter(|&i| plan[i].1 > 0)
                .max_by_key(|&i| (plan[i].1, i))
            else {
                return Err(ViewError::TextureBudget {
                    budget: stream.map_budget + stream.chunk_budget,
                    needed: stream.map_budget + total,
                    what: "this frame's chunk textures at the coarsest level",
                });
            };
            plan[i].1 -= 1;
            fallen[i] = true;
            let s = bytes_of(stream, plan[i].2, plan[i].1);
            total = total - sizes[i] + s;
            sizes[i] = s;
        }
        stream.stats.chunks_fallen_back = fallen.iter().filter(|&&f| f).count() as u64;
        stream.stats.coarsest_level = plan.iter().map(|p| p.1).min().unwrap_or(0);
        stream.stats.finest_level = plan.iter().map(|p| p.1).max().unwrap_or(0);
        Ok(plan)
    }
}

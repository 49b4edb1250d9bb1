//! Draw calls: vertex stage, binning, parallel tile rasterisation.
//!
//! Every draw runs the same three stages:
//! 1. **vertices** (parallel): world -> eye -> fixed-point screen ([`crate::project`]);
//! 2. **primitives** (the [`crate::bin`] binner, parallel over fixed chunks of [`CHUNK`]
//!    primitives): facing, bounding box, clipping of the few triangles that need it, and the
//!    set-up record (snapped vertices oriented clockwise, varyings) pushed with its tile span;
//!    the binner then copies each record into its tiles in primitive order;
//! 3. **tiles** (parallel): each tile walks its records in submission order and rasterises them
//!    into its own pixels.
//!
//! Nothing in stages 1–3 depends on how rayon splits the work, and every pixel is written by the
//! one worker that owns its tile, so the output is byte-identical for any thread count.

use rayon::prelude::*;
use texmap_core::camera::Camera;

use crate::RasterError;
use crate::bin::TileSpan;
use crate::framebuffer::{Framebuffer, Grid};
use crate::mesh::Mesh;
use crate::program::{
    FirstVertexColour, FlatProg, FragProgram, LitFlat, LitSmoothProg, PerTriangle, QuadSampler,
    Shading, TexturedProg, VertexColorProg,
};
use crate::project::{FLAG_INVALID, MAX_VAR, PVert, Proj};
use crate::record::{FRONT_BIT, Rec, VarStore};
use crate::sprite::{QuadShader, Sprite, raster_sprite};
use crate::state::{Cull, DrawState};
use crate::surface::{SurfaceProg, SurfaceShader};
use crate::tri::{RasterCtx, area2, facing, pixel_bounds, raster_tri};

/// Fixed chunk length of the primitive pass (independent of the thread count).
const CHUNK: usize = 8192;

/// What happened to the primitives of one draw call (integer counts, identical for any thread
/// count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Primitives submitted.
    pub submitted: usize,
    /// Primitives (or clipped pieces' sources) binned to at least one tile.
    pub binned: usize,
    /// Triangles discarded by the cull mode.
    pub culled: usize,
    /// Triangles of zero area after snapping to the fixed-point grid.
    pub degenerate: usize,
    /// Primitives whose bounding box holds no pixel centre of the image.
    pub no_pixels: usize,
    /// Primitives with a non-finite vertex (or an invalid sprite): skipped.
    pub skipped_invalid: usize,
    /// Triangles that crossed the near plane or the guard band and were clipped.
    pub clipped: usize,
}

impl DrawStats {
    fn add(&mut self, o: &DrawStats) {
        self.submitted += o.submitted;
        self.binned += o.binned;
        self.culled += o.culled;
        self.degenerate += o.degenerate;
        self.no_pixels += o.no_pixels;
        self.skipped_invalid += o.skipped_invalid;
        self.clipped += o.clipped;
    }
}

/// Classify a snapped triangle: its tile span and facing (`true`: front), or why it draws
/// nothing (counted in `stats`).
#[inline]
fn tri_span(
    v: &[PVert; 3],
    cull: Cull,
    grid: &Grid,
    stats: &mut DrawStats,
) -> Option<(TileSpan, bool)> {
    let a = area2(v);
    if a == 0 {
        stats.degenerate += 1;
        return None;
    }
    let Some(front) = facing(a, cull) else {
        stats.culled += 1;
        return None;
    };
    match pixel_bounds(v, grid.width, grid.height).and_then(|b| inclusive_span(grid, b)) {
        Some(span) => Some((span, front)),
        None => {
            stats.no_pixels += 1;
            None
        }
    }
}

/// The tile span of the inclusive pixel bounds `[x0, y0, x1, y1]` (inside the image).
#[inline]
fn inclusive_span(grid: &Grid, [x0, y0, x1, y1]: [i32; 4]) -> Option<TileSpan> {
    if x0 < 0 || y0 < 0 || x1 < x0 || y1 < y0 {
        return None;
    }
    grid.bins
        .span(x0 as u32, y0 as u32, x1 as u32 + 1, y1 as u32 + 1)
}

impl Framebuffer {
    fn check_camera(&self, camera: &Camera) -> Result<(), RasterError> {
        if camera.width() != self.grid.width || camera.height() != self.grid.height {
            return Err(RasterError::SizeMismatch {
                camera: (camera.width(), camera.height()),
                target: (self.grid.width, self.grid.height),
            });
        }
        Ok(())
    }

    /// Draw a triangle mesh seen by `camera` with a [`Shading`] program.
    ///
    /// Errors: the camera's image size differs from the framebuffer's, or the program needs an
    /// attribute the mesh lacks (`VertexColor` needs colours, `LitSmooth` normals). Triangles
    /// with a non-finite vertex, zero area or the culled facing are skipped and counted.
    pub fn draw_mesh(
        &mut self,
        camera: &Camera,
        mesh: &Mesh,
        shading: &Shading,
        state: &DrawState,
    ) -> Result<DrawStats, RasterError> {
        self.check_camera(camera)?;
        let proj = Proj::new(camera);
        Ok(match *shading {
            Shading::Flat(c) => self.draw_program(&proj, mesh, &FlatProg(c), state),
            Shading::VertexColor | Shading::FirstVertexColor => {
                if mesh.colors().is_none() {
                    return Err(RasterError::MissingAttribute {
                        attribute: "colors",
                    });
                }
                if matches!(shading, Shading::VertexColor) {
                    self.draw_program(&proj, mesh, &VertexColorProg, state)
                } else {
                    self.draw_program(&proj, mesh, &PerTriangle(FirstVertexColour), state)
                }
            }
            Shading::LitFlat { lighting, material } => {
                let prog = PerTriangle(LitFlat {
                    lighting: lighting.to_eye(camera),
                    material,
                    proj,
                });
                self.draw_program(&proj, mesh, &prog, state)
            }
            Shading::LitSmooth { lighting, material } => {
                if mesh.normals().is_none() {
                    return Err(RasterError::MissingAttribute {
                        attribute: "normals",
                    });
                }
                let prog = LitSmoothProg::new(lighting.to_eye(camera), material, proj);
                self.draw_program(&proj, mesh, &prog, state)
            }
        })
    }

    /// Draw a textured mesh: perspective-correct uvs, sampled a 2x2 quad at a time by `sampler`
    /// (see [`QuadSampler`]). The mesh must carry uvs.
    pub fn draw_textured<S: QuadSampler + ?Sized>(
        &mut self,
        camera: &Camera,
        mesh: &Mesh,
        sampler: &S,
        state: &DrawState,
    ) -> Result<DrawStats, RasterError> {
        self.check_camera(camera)?;
        if mesh.uvs().is_none() {
            return Err(RasterError::MissingAttribute { attribute: "uvs" });
        }
        let proj = Proj::new(camera);
        Ok(self.draw_program(&proj, mesh, &TexturedProg(sampler), state))
    }

    /// Draw a mesh with a [`SurfaceShader`] of the caller's own: per covered quad it receives
    /// the pixels' depths, world-space normals (the mesh's vertex normals interpolated, or the
    /// face normal when it has none) and triangle, and returns their colours. Coverage, depth
    /// test, blending and determinism are those of every other draw.
    ///
    /// Errors: the camera's image size differs from the framebuffer's.
    pub fn draw_surface<S: SurfaceShader + ?Sized>(
        &mut self,
        camera: &Camera,
        mesh: &Mesh,
        shader: &S,
        state: &DrawState,
    ) -> Result<DrawStats, RasterError> {
        self.check_camera(camera)?;
        let proj = Proj::new(camera);
        let prog = SurfaceProg {
            shader,
            has_normals: mesh.normals().is_some(),
        };
        Ok(self.draw_program(&proj, mesh, &prog, state))
    }

    fn draw_program<P: FragProgram>(
        &mut self,
        proj: &Proj,
        mesh: &Mesh,
        prog: &P,
        state: &DrawState,
    ) -> DrawStats {
        debug_assert!(P::NV <= MAX_VAR);
        let grid = self.grid;
        let Framebuffer {
            tiles,
            scratch,
            block_path,
            clear_linear,
            ..
        } = self;
        let clear_linear = *clear_linear;
        let positions = mesh.positions();
        let indices = mesh.indices();

        // Stage 1: vertices.
        scratch.pverts.resize(positions.len(), PVert::default());
        scratch
            .pverts
            .par_chunks_mut(4096)
            .zip(positions.par_chunks(4096))
            .for_each(|(out, p)| proj.project_slice(p, out));
        let pverts = &scratch.pverts;

        // Stage 2: primitives, in fixed chunks: set up and bin each record.
        let cull = state.cull;
        let bins = P::Vars::bins(&mut scratch.tris);
        let chunk_stats = bins.build(grid.bins, indices.len(), CHUNK, |range, sink| {
            let mut stats = DrawStats {
                submitted: range.len(),
                ..DrawStats::default()
            };
            let mut pieces = Vec::new();
            for t in range {
                let tri = indices[t];
                let v = tri.map(|i| pverts[i as usize]);
                if v.iter().any(PVert::flagged) {
                    if v.iter().any(|p| p.flagged() && p.y == FLAG_INVALID) {
                        stats.skipped_invalid += 1;
                        continue;
                    }
                    // Slow path: clip against the near plane and the guard band.
                    stats.clipped += 1;
                    pieces.clear();
                    let p = tri.map(|i| positions[i as usize]);
                    let var = tri.map(|i| prog.vertex_var(mesh, i as usize));
                    proj.clip_triangle(p, var, t as u32, &mut pieces);
                    let mut any = false;
                    for piece in &pieces {
                        // The pieces' own degenerate, culled and empty cases are not counted:
                        // the source triangle counts once, as clipped.
                        let mut s = DrawStats::default();
                        if let Some((span, front)) = tri_span(&piece.v, cull, &grid, &mut s) {
                            sink.push(span, Rec::new(piece.v, piece.var, piece.tri, front));
                            any = true;
                        }
                    }
                    if any {
                        stats.binned += 1;
                    }
                } else if let Some((span, front)) = tri_span(&v, cull, &grid, &mut stats) {
                    let mut var = [[0.0; MAX_VAR]; 3];
                    if P::NV > 0 {
                        var = tri.map(|i| prog.vertex_var(mesh, i as usize));
                    }
                    sink.push(span, Rec::new(v, var, t as u32, front));
                    stats.binned += 1;
                }
            }
            stats
        });
        let mut stats = DrawStats::default();
        for s in &chunk_stats {
            stats.add(s);
        }

        // Stage 3: tiles.
        let ctx = RasterCtx::new(*state, proj.far, grid.width, grid.height, *block_path);
        let bins = &*bins;
        tiles.par_iter_mut().enumerate().for_each(|(ti, tile)| {
            let recs = bins.tile(ti);
            if !recs.is_empty() {
                tile.prepare(clear_linear);
            }
            for rec in recs {
                let front = rec.tri_front & FRONT_BIT != 0;
                let tri = rec.tri_front & !FRONT_BIT;
                let cst = prog.tri_const(mesh, tri, front);
                raster_tri(tile, &ctx, prog, &cst, &rec.v, &rec.var.unpack(), front);
            }
        });
        stats
    }

    /// Draw sprites (screen-space rectangles, see [`crate::sprite`]) coloured by `shader`.
    /// Invalid sprites (non-finite or empty rectangles, NaN `depth_min`) are skipped and counted.
    /// `state.cull` does not apply to sprites.
    pub fn draw_sprites<S: QuadShader + ?Sized>(
        &mut self,
        sprites: &[Sprite],
        shader: &S,
        state: &DrawState,
    ) -> Result<DrawStats, RasterError> {
        if sprites.len() > i32::MAX as usize {
            return Err(RasterError::TooManyPrimitives {
                count: sprites.len(),
            });
        }
        let grid = self.grid;
        let Framebuffer {
            tiles,
            scratch,
            clear_linear,
            ..
        } = self;
        let clear_linear = *clear_linear;
        let chunk_stats = scratch
            .sprites
            .build(grid.bins, sprites.len(), CHUNK, |range, sink| {
                let mut stats = DrawStats {
                    submitted: range.len(),
                    ..DrawStats::default()
                };
                for sp in &sprites[range] {
                    if !sp.is_valid() {
                        stats.skipped_invalid += 1;
                    } else if let Some(span) = sp
                        .pixel_bounds(grid.width, grid.height)
                        .and_then(|b| inclusive_span(&grid, b))
                    {
                        sink.push(span, *sp);
                        stats.binned += 1;
                    } else {
                        stats.no_pixels += 1;
                    }
                }
                stats
            });
        let mut stats = DrawStats::default();
        for s in &chunk_stats {
            stats.add(s);
        }
        let ctx = RasterCtx::new(*state, f32::INFINITY, grid.width, grid.height, true);
        let bins = &scratch.sprites;
        tiles.par_iter_mut().enumerate().for_each(|(ti, tile)| {
            let sps = bins.tile(ti);
            if !sps.is_empty() {
                tile.prepare(clear_linear);
            }
            for sp in sps {
                raster_sprite(tile, &ctx, shader, sp);
            }
        });
        Ok(stats)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use texmap_core::camera::Camera;
    use texmap_core::shade::{Lighting, Material};

    use super::*;
    use crate::state::{Blend, DepthTest};
    use crate::tri::BLOCK;

    /// Many small triangles (1..14 px across, some straddling tile borders and the image edge,
    /// random depths and windings) with colours and normals.
    fn small_scene(cam: &Camera, n: usize) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
        let mut s = 7u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let (w, h, k) = (cam.width() as f32, cam.height() as f32, cam.scale());
        let mut pos = Vec::new();
        let mut col = Vec::new();
        let mut idx = Vec::new();
        for t in 0..n as u32 {
            let depth = 2.0 + 20.0 * r();
            let c = Vec3::new((r() - 0.5) * w, (r() - 0.5) * h, 0.0) * (depth / k);
            let size = (1.0 + 13.0 * r()) * depth / k;
            for _ in 0..3 {
                let off = Vec3::new(r() - 0.5, r() - 0.5, (r() - 0.5) * 0.5);
                pos.push(Vec3::new(c.x, c.y, -depth) + off * size);
                col.push(Vec3::new(r(), r(), r()));
            }
            idx.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        (pos, col, idx)
    }

    fn bits(fb: &Framebuffer) -> Vec<u32> {
        let mut out = Vec::new();
        for y in 0..fb.height() {
            for x in 0..fb.width() {
                let c = fb.color_at(x, y).unwrap();
                out.extend([fb.depth_at(x, y).unwrap(), c.x, c.y, c.z].map(f32::to_bits));
            }
        }
        out
    }

    #[test]
    fn block_path_gives_the_same_pixels_as_the_quad_loop() {
        let (w, h) = (203u32, 131u32);
        let cam = Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60.0, w, h)
            .unwrap()
            .with_clip(0.1, 100.0)
            .unwrap();
        let (pos, col, idx) = small_scene(&cam, 3000);
        let mesh = Mesh::new(&pos, &idx)
            .unwrap()
            .with_colors(&col)
            .unwrap()
            .with_normals(&col)
            .unwrap();
        // The scene must exercise both paths: count triangles whose pixel range fits a block.
        let proj = Proj::new(&cam);
        let fits = idx
            .iter()
            .filter_map(|t| pixel_bounds(&t.map(|i| proj.project(pos[i as usize])), w, h))
            .filter(|b| b[2] - (b[0] & !1) < BLOCK as i32 && b[3] - (b[1] & !1) < BLOCK as i32)
            .count();
        assert!(fits > 1000 && fits < 2900, "{fits} of 3000 fit a block");
        let lit = Shading::LitSmooth {
            lighting: Lighting::default_for(&cam),
            material: Material::plastic(Vec3::new(0.3, 0.5, 0.8)),
        };
        let states = [
            DrawState {
                cull: Cull::None,
                ..DrawState::default()
            },
            DrawState {
                depth_test: DepthTest::LessEqual,
                ..DrawState::default()
            },
            DrawState::additive_overlay(),
            DrawState {
                depth_test: DepthTest::Always,
                depth_write: false,
                cull: Cull::Front,
                blend: Blend::Replace,
            },
        ];
        for shading in [
            Shading::Flat(Vec3::new(0.2, 0.7, 1.0)),
            Shading::VertexColor,
            Shading::FirstVertexColor,
            lit,
        ] {
            for st in &states {
                let draw = |block: bool| {
                    let mut fb = Framebuffer::new(w, h).unwrap();
                    fb.block_path = block;
                    fb.clear([10, 20, 30, 255]);
                    let stats = fb.draw_mesh(&cam, &mesh, &shading, st).unwrap();
                    // Draw twice so that the depth test meets stored values of the same draw.
                    fb.draw_mesh(&cam, &mesh, &shading, st).unwrap();
                    (bits(&fb), stats)
                };
                let (fast, sf) = draw(true);
                let (general, sg) = draw(false);
                assert_eq!(sf, sg);
                let diff = fast.iter().zip(&general).filter(|(a, b)| a != b).count();
                assert_eq!(diff, 0, "{shading:?} {st:?}: {diff} values differ");
                let drawn = fast
                    .chunks(4)
                    .filter(|p| f32::from_bits(p[0]).is_finite() || p[1] != fast[1])
                    .count();
                assert!(
                    drawn > 3000,
                    "{shading:?} {st:?}: only {drawn} pixels drawn"
                );
            }
        }
    }
}

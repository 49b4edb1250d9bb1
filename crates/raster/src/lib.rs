//! # texmap-raster — the CPU rasteriser of texmap
//!
//! Draws triangle meshes and screen-space sprites into a colour + depth [`Framebuffer`] and
//! resolves it to the workspace's [`Frame`](texmap_core::frame::Frame) (sRGB8 colour, eye-space
//! depth, `INFINITY` where nothing was drawn). It is the drawing engine under the polygon-sphere
//! and impostor methods, the sphere/cube environment maps and the terrain renderer.
//!
//! - **Triangles** ([`Framebuffer::draw_mesh`], [`Framebuffer::draw_textured`]): projection by
//!   [`texmap_core::camera::Camera`], near-plane and guard-band clipping, back-face culling
//!   ([`Cull`]), exact fixed-point edge functions (8 sub-pixel bits) with the top-left fill rule
//!   (shared edges are never drawn twice nor missed), perspective-correct depth and attributes,
//!   depth test and write modes ([`DepthTest`], [`DrawState`]), replace or additive [`Blend`].
//! - **Programs**: [`Shading`] (flat, Gouraud vertex colours, flat-lit, per-pixel Phong through
//!   [`texmap_core::shade::Lighting`], the same model as the reference ray tracer), or textured
//!   through any [`QuadSampler`] — [`MipSampler`] wraps every texmap-core sampler, and the Seed 000
//!   span sampler receives the whole 2x2 quad (Eq. 8–10).
//! - **Surface shaders of the caller's own** ([`Framebuffer::draw_surface`], [`SurfaceShader`]):
//!   the open extension point. Per covered quad the shader gets the depth, the interpolated
//!   world-space normal, the world position and eye ray ([`SurfaceQuad`]) and returns colours —
//!   environment-mapped reflections and refractions are drawn this way.
//! - **Sprites** ([`Framebuffer::draw_sprites`]): rectangles shaded by a [`QuadShader`] that
//!   returns colour, depth and a keep mask per pixel — the impostor path.
//! - **Quads and tiles**: pixels are processed as 2x2 quads (texture derivatives come for free);
//!   primitives are binned into [`TILE`]-pixel tiles and tiles are rasterised in parallel with
//!   rayon. Each tile owns its pixels and sees its primitives in submission order, so the output is
//!   byte-identical for any thread count. [`Framebuffer::clear`] is deferred: the first draw that
//!   reaches a tile clears it on that tile's thread, and tiles no draw reaches resolve straight to
//!   the background.
//!
//! Degenerate input is never an error and never a panic: triangles with a non-finite vertex, zero
//! area after snapping, or no pixel centre inside are skipped and counted in [`DrawStats`]; no NaN
//! reaches the depth buffer. Errors ([`RasterError`]) are for inconsistent calls: a camera whose
//! image size differs from the framebuffer's, indices out of range, a missing attribute.
//! The crate writes no files.
//!
//! ```
//! use texmap_core::{camera::Camera, glam::Vec3};
//! use texmap_raster::{DrawState, Framebuffer, Mesh, Shading};
//!
//! // An orthographic camera with one world unit per pixel over a 64 x 48 image.
//! let cam = Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 64.0, 64, 48)
//!     .unwrap();
//! // Two triangles sharing a diagonal: a 20 x 10 rectangle, counter-clockwise (front-facing).
//! let pos = [
//!     Vec3::new(-10.0, -5.0, 0.0),
//!     Vec3::new(10.0, -5.0, 0.0),
//!     Vec3::new(10.0, 5.0, 0.0),
//!     Vec3::new(-10.0, 5.0, 0.0),
//! ];
//! let tris = [[0, 1, 2], [0, 2, 3]];
//! let mesh = Mesh::new(&pos, &tris).unwrap();
//!
//! let mut fb = Framebuffer::new(64, 48).unwrap();
//! fb.clear([0, 0, 0, 255]);
//! let stats = fb
//!     .draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::new(1.0, 0.5, 0.0)), &DrawState::default())
//!     .unwrap();
//! assert_eq!(stats.binned, 2);
//!
//! let frame = fb.to_frame();
//! // Exactly the 20 x 10 pixel centres inside; the shared diagonal is drawn once.
//! assert_eq!(frame.coverage_count(), 200);
//! // Depth is the eye-space distance along the view axis.
//! assert_eq!(frame.depth[frame.index(32, 24)], 10.0);
//! assert_eq!(frame.color[frame.index(32, 24)], [255, 188, 0, 255]);
//! ```
//!
//! # Design notes
//! - Bins hold *copies* of the set-up triangle records (snapped vertices + varyings), not indices:
//!   with indices, the tile pass of 1M scattered triangles spent about 80% of its time in two
//!   cache-missing loads (perf, this machine). Programs without varyings bin 52-byte records
//!   (vertices + triangle index with the facing bit), the others 88 bytes; records are oriented
//!   when they are set up, before binning, so the tile pass does no area or cull test. The binner
//!   itself ([`bin`]) is public: the sphere and bond passes of `texmap-impostor` bin through it.
//! - Programs are monomorphised: the per-quad loop holds no `dyn` and no per-pixel match on the
//!   shading mode. The depth test, depth write and blend run on four-lane masks and selects
//!   ([`texmap_core::lanes::F32x4`]: SSE2 on x86-64, the baseline, with a portable twin of
//!   identical semantics).
//! - Small triangles (at most 16 px across, pixel range within an 8 x 8 block) take the block
//!   path: i32 edge functions for the whole block (eight lanes per row, one bit mask per row),
//!   then only quads holding a covered pixel are shaded. It gives exactly the pixels of the
//!   general quad loop (tested); on 1M ~10-px triangles the two together cut the instructions
//!   of a draw from 2.88 G to 1.46 G (callgrind; docs/PERFORMANCE.md, "The levers that mattered").
//! - Vertices are projected four at a time, bit-identical to the scalar projection (tested).
//! - Attributes use screen-space plane equations of `a/W` and `1/W` (affine in screen space), set
//!   up in f64 per triangle and evaluated in f32 relative to the triangle's first quad in the
//!   tile. With perspective vertices `depth/W` is exactly 1 and depth is `W` itself.
//! - `Shading::LitSmooth` lights the quad's four lanes together with the operations of
//!   [`texmap_core::shade::Lighting::shade`]; only the Blinn-Phong power differs (a four-lane
//!   `exp2(p·log2 x)`, relative error < 1e-5 against `powf`, tested).

pub mod bin;
mod draw;
mod error;
mod framebuffer;
mod mesh;
mod program;
mod project;
mod record;
pub mod sprite;
mod state;
mod surface;
mod tri;

pub use draw::DrawStats;
pub use error::RasterError;
pub use framebuffer::{Framebuffer, TILE};
pub use mesh::Mesh;
pub use program::{MipSampler, QuadSampler, Shading, TexQuad};
pub use sprite::{QuadOut, QuadShader, Sprite, SpriteQuad};
pub use state::{Blend, Cull, DepthTest, DrawState};
pub use surface::{SurfaceQuad, SurfaceShader};

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
//! - **Sprites** ([`Framebuffer::draw_sprites`]): rectangles shaded by a [`QuadShader`] that
//!   returns colour, depth and a keep mask per pixel — the impostor path.
//! - **Quads and tiles**: pixels are processed as 2x2 quads (texture derivatives come for free);
//!   primitives are binned into [`TILE`]-pixel tiles and tiles are rasterised in parallel with
//!   rayon. Each tile owns its pixels and sees its primitives in submission order, so the output is
//!   byte-identical for any thread count.
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
//!   cache-missing loads (perf, this machine).
//! - Programs are monomorphised: the per-quad loop holds no `dyn` and no per-pixel match on the
//!   shading mode; the depth-test mode is a predictable branch.
//! - Attributes use screen-space plane equations of `a/W` and `1/W` (affine in screen space), set
//!   up in f64 per triangle and evaluated in f32 relative to the triangle's first quad.

mod bin;
mod draw;
mod error;
mod framebuffer;
mod mesh;
mod program;
mod project;
mod simd;
pub mod sprite;
mod state;
mod tri;

pub use draw::DrawStats;
pub use error::RasterError;
pub use framebuffer::{Framebuffer, TILE};
pub use mesh::Mesh;
pub use program::{MipSampler, QuadSampler, Shading, TexQuad};
pub use sprite::{QuadOut, QuadShader, Sprite, SpriteQuad};
pub use state::{Blend, Cull, DepthTest, DrawState};

//! # texmap-raster — the CPU rasteriser of texmap
//!
//! (crate docs being written)

mod bin;
mod draw;
mod error;
mod framebuffer;
mod mesh;
mod program;
mod project;
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

//! # texmap
//!
//! Texture-mapping methods from four classic papers (Seed 000 mipmapped and span-parallel
//! terrain texturing, Seed 002 sphere impostors from colour + depth images, Seed 003 dynamic
//! environment mapping, Seed 004 template-texture billboards), implemented as a CPU renderer and
//! measured for speed and accuracy against a BVH reference ray tracer.
//!
//! This crate only re-exports the workspace crates, so that one dependency gives all of them.
//! Each crate is also usable on its own; see its documentation.
//!
//! ```
//! use texmap::core::camera::Camera;
//! let cam = Camera::perspective_look_at(
//!     glam::Vec3::new(0.0, 0.0, 10.0), glam::Vec3::ZERO, glam::Vec3::Y, 60.0, 64, 48,
//! ).unwrap();
//! assert_eq!(cam.width(), 64);
//! ```

pub use texmap_core as core;
pub use texmap_envmap as envmap;
pub use texmap_impostor as impostor;
pub use texmap_md_io as md_io;
pub use texmap_md_scene as md_scene;
pub use texmap_mesh as mesh;
pub use texmap_movie as movie;
pub use texmap_quality as quality;
pub use texmap_raster as raster;
pub use texmap_reftrace as reftrace;
pub use texmap_study as study;
pub use texmap_terrain as terrain;

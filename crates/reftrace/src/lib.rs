//! # texmap-reftrace — the reference ray tracer (the oracle)
//!
//! Every drawing method of texmap is measured against the images this crate makes. It ray-traces
//! analytic spheres, capped cylinders (bonds) and triangle meshes held in one obvhs BVH, with the
//! workspace's camera ([`texmap_core::camera::Camera`]: horizontal field of view, pixel centres at
//! `i + 0.5`, depth along the view axis) and shading model ([`texmap_core::shade::Lighting::shade`]),
//! so a difference between a method and the reference is the method's own error.
//!
//! - [`SceneBuilder`] → [`Scene`]: add spheres, cylinders and meshes (a [`TriMesh`] read from OBJ
//!   or glTF by `texmap_mesh`, or slices; flat shaded, or smooth with interpolated vertex normals from the file or
//!   averaged from the faces, [`MeshShading`]), build the BVH once; [`Scene::intersect`] answers
//!   closest-hit queries.
//! - The BVH is built by obvhs (PLOC); by default ([`BvhKind::Wide4`]) it is collapsed into a
//!   4-wide tree with full-precision boxes in SIMD lanes and walked by this crate, with a
//!   sphere-only leaf kernel when the scene holds spheres alone. obvhs's own bvh2 and cwbvh
//!   traversals stay selectable.
//! - [`Scene::render`] / [`Scene::render_with_environment`] → [`Frame`]: exact primary visibility
//!   and depth, mirror and refraction rays with an environment for escaped rays, `n × n` stratified
//!   supersampling, a footprint-integrated texture reference. Parallel over rows with rayon and
//!   byte-identical for any thread count. Writes no files. [`Scene::depth_image`] is the trace
//!   alone (closest hit and exact depth, no shading).
//! - Optional ambient occlusion ([`AmbientOcclusion`]: stratified cosine-weighted rays within a
//!   distance), hard shadows from the key light or soft ones from it as a disc ([`DiscLight`]),
//!   depth cueing ([`DepthCue`]) and supersampled silhouette outlines ([`Outline`]) in
//!   [`RenderOptions`], so that `texmap-quality`'s effects have a converged reference; off by
//!   default, and then the output is unchanged.
//! - [`geom`]: the robust leaf tests — pbrt's cancellation-free sphere discriminant and the
//!   watertight ray/triangle test of Woop, Benthin and Wald (2013), which leaves no pinholes on
//!   shared edges (obvhs's own triangle test does; it is not used).
//!
//! Correctness and robustness come first; speed is measured in `benches/reftrace.rs` and
//! docs/PERFORMANCE.md (on the 100k-sphere S2 scene the 4-wide traversal executes about 1.5x
//! fewer instructions per primary ray than obvhs's cwbvh traversal).
//!
//! ```
//! use texmap_core::camera::Camera;
//! use texmap_core::shade::{Lighting, Material};
//! use texmap_reftrace::{RenderOptions, SceneBuilder, SurfaceMaterial, glam::Vec3};
//!
//! let mut builder = SceneBuilder::new();
//! builder.add_sphere(Vec3::ZERO, 1.0, 0);
//! let scene = builder.build();
//!
//! let cam = Camera::perspective_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 48)
//!     .unwrap();
//! let materials = [SurfaceMaterial::opaque(Material::plastic(Vec3::new(0.8, 0.2, 0.2)))];
//! let opts = RenderOptions::new(Lighting::default_for(&cam), &materials);
//! let frame = scene.render(&cam, &opts).unwrap();
//!
//! // The sphere's nearest point is 5 − 1 = 4 units down the view axis, at the image centre.
//! let d = frame.depth[frame.index(32, 24)];
//! assert!((d - 4.0).abs() < 1e-3, "{d}");
//! // A corner pixel sees the background.
//! assert_eq!(frame.depth[0], f32::INFINITY);
//! ```
//!
//! **Architecture invariant:** this crate depends on `texmap-core` and never on `texmap-raster`:
//! the oracle shares nothing with the methods it judges except the camera and the shading model.

pub use glam;

pub mod error;
pub mod geom;
mod render;
mod scene;
mod texture;
mod wide;

pub use error::{RenderError, SceneError, TextureError};
pub use geom::CylinderPart;
pub use render::{
    AmbientOcclusion, DepthCue, DiscLight, MAX_AO_SAMPLES_PER_AXIS, MAX_LIGHT_SIZE_DEG,
    MAX_OUTLINE_PX, MAX_RECURSION_DEPTH, MAX_SAMPLES_PER_AXIS, MAX_SHADOW_SAMPLES_PER_AXIS, Optics,
    Outline, RenderOptions, SurfaceMaterial,
};
pub use scene::{BuildStats, BvhKind, Hit, HitKind, MeshShading, Scene, SceneBuilder};
pub use texmap_core::frame::Frame;
pub use texmap_mesh::TriMesh;
pub use texture::Texture;

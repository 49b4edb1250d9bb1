//! # texmap-envmap — Seed 003 environment mapping, static and dynamic
//!
//! A reflective or refractive *target* among opaque objects, drawn with an environment map made
//! around the target's centre:
//!
//! | [`Method`] | map | update per frame |
//! |---|---|---|
//! | `SphereStatic` | sphere map of the environment alone, in the camera's frame | rebuilt only when the camera turns |
//! | `SphereStaticVertex` | the same, coordinates per vertex and interpolated (the 1998 way) | idem |
//! | `SphereDynamic` | Seed 003: objects mapped straight into sphere-map space | every frame |
//! | `Cube` | six faces drawn by six cameras | every frame, or N faces per frame (time-sliced) |
//! | `CubeBox` | the same cube map, looked up box-projected (parallax-corrected) | idem |
//! | `Paraboloid` | two paraboloids, objects mapped like the sphere map | every frame |
//!
//! - [`address`]: direction ⇄ map coordinates for the three layouts, both ways;
//! - [`bake`]: a probe baked by the cube map's update, as OpenGL faces, cross, c3x2 or lat-long;
//! - [`environment`]: the background at infinity (a lat-long image or the built-in sky);
//! - [`maps`]: map storage, static construction, filtered lookups, dynamic updates (with the
//!   rim-straddling triangles split, never smeared);
//! - [`scene`]: the validated scene and the built-in tunnel after Seed 003's demo;
//! - [`render`]: one face for every method, `Renderer::render(&scene, &camera, &options)`, with
//!   the map update timed apart from the frame;
//! - [`shapes`]: built-in meshes (sphere, box, torus, tunnel).
//!
//! Reflection and refraction use [`texmap_core::optics`], the formulas the reference ray tracer's
//! secondary rays use, and objects are drawn with texmap-raster's flat-lit program, so that the
//! study (the `texmap-study` crate) measures each method's own error against `texmap-reftrace`.
//!
//! ```
//! use texmap_envmap::{Method, Options, Renderer, scene};
//!
//! let s = scene::tunnel_scene(scene::TunnelParams::default()).unwrap();
//! let cam = scene::tunnel_camera(96, 72).unwrap();
//! let mut r = Renderer::new();
//! let out = r.render(&s, &cam, &Options::new(Method::Cube)).unwrap();
//! // The mirror sphere is at the image centre and reflects something (not the black clear colour).
//! let c = out.frame.color[out.frame.index(48, 36)];
//! assert!(c[0] as u32 + c[1] as u32 + c[2] as u32 > 30, "{c:?}");
//! assert!(out.frame.depth[out.frame.index(48, 36)].is_finite());
//! ```
//!
//! **Architecture invariant:** this crate depends on texmap-core, texmap-raster and texmap-mesh
//! only; the reference ray tracer appears in its tests alone. It opens no file.

pub use glam;

pub mod address;
pub mod bake;
pub mod environment;
pub mod error;
pub mod maps;
pub mod render;
pub mod scene;
pub mod shapes;

pub use environment::Environment;
pub use error::EnvMapError;
pub use maps::{EnvMap, Filter, MAX_MAP_SIZE, MIN_MAP_SIZE, MapKind, RimPolicy};
pub use render::{Method, Options, Output, Renderer};
pub use scene::{EnvScene, Object, Surface, Target, TargetShape};

//! # texmap-core — the pure maths and data of texmap
//!
//! Everything here is a pure function or a plain data type: no file IO, no threads, no logging.
//! The crate carries
//!
//! - the shared building blocks every renderer of the workspace agrees on: [`camera`] (perspective
//!   and orthographic, horizontal field of view), [`shade`] (one Lambert + Blinn-Phong model used by
//!   the rasteriser and the reference ray tracer alike), [`color`] (sRGB, HSV), [`frame`] (colour +
//!   depth image), [`metrics`] (PSNR, SSIM, depth and silhouette error) and [`optics`] (mirror
//!   reflection, Snell refraction, Fresnel: shared by environment mapping and the ray tracer);
//! - [`lanes`]: the workspace's one CPU-feature detection, the 4- and 8-lane types (SSE2, AVX2,
//!   with portable twins) and the maths written over them (pow, exp2/log2, sRGB, shading), used
//!   by the rasteriser, the sphere ray caster and the samplers;
//! - Seed 000's texture mapping: [`transform`] (Eq. 1–3), [`mip`] pyramids, [`sample`]rs (nearest,
//!   bilinear, trilinear Eq. 4, span-parallel with K x K banks Eq. 8–10, anisotropic reference) and
//!   [`coverage`] (Eq. 5–7, the active-area map count).
//!
//! ```
//! use texmap_core::{camera::Camera, glam::Vec3};
//! // A 640x480 camera with a 60° horizontal field of view, 10 units from the origin.
//! let cam = Camera::perspective_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 60.0, 640, 480)
//!     .expect("valid camera");
//! // The origin projects to the image centre, at depth 10 along the view axis.
//! let (p, depth) = cam.project(Vec3::ZERO).unwrap();
//! assert!((p.x - 320.0).abs() < 1e-4 && (p.y - 240.0).abs() < 1e-4);
//! assert!((depth - 10.0).abs() < 1e-5);
//! ```
//!
//! **Architecture invariant:** this crate never opens a file and depends on glam alone.

pub use glam;

pub mod camera;
pub mod camera_path;
pub mod color;
pub mod coverage;
pub mod frame;
pub mod lanes;
pub mod metrics;
pub mod mip;
pub mod optics;
pub mod sample;
pub mod shade;
pub mod solid_angle;
pub mod transform;

//! # texmap-study — the speed-versus-accuracy study of the sphere methods
//!
//! "Both speed and accuracy count: chart one against the other, test stability where methods
//! fail." This crate holds everything the study needs apart from the methods themselves
//! (`texmap-impostor`) and the oracle (`texmap-reftrace`):
//!
//! - [`scenes`]: the named scenes S1 (Seed 004's 1,115-particle silicate system), S2 (100k
//!   spheres), S3 (1M spheres) and Seed 002's ~300-atom molecule (an α-helix of 30 alanines),
//!   generated deterministically with their cameras and lighting; [`elements`] holds the few
//!   element colours and radii they need, [`rng`] the seeded generator.
//! - [`md`]: a small deterministic Lennard-Jones MD (velocity Verlet, cell list, periodic box) that
//!   moves the Seed 004 system for the animation demo.
//! - [`record`]: what every family of methods reports, whatever it draws: a [`record::Record`]
//!   per method, scene and reference (ms/frame, PSNR, SSIM, depth error, silhouette mismatch),
//!   the comparison of a frame with its reference, error images, JSON and CSV results.
//! - [`harness`]: the sphere methods and the reference on one scene (tables reused across
//!   frames), reported as records.
//! - [`sweeps`]: stability sweeps over field of view, angle off axis, eye distance and on-screen
//!   radius on a single sphere; the tests pin each method's breaking point.
//! - [`terrain`]: the flight-view study (Seed 000): every terrain sampler against a supersampled,
//!   footprint-integrated ray-traced reference, and the paper's bank claims counted.
//! - [`quality`]: the quality axis — `texmap-quality`'s anti-aliasing, ambient occlusion and
//!   shadow settings timed and measured against a converged reference with the same effects.
//! - [`chart`]: SVG/PNG charts (speed against accuracy, and the sweep curves) with an embedded
//!   font.
//!
//! Pure functions return data; only the `write_*` functions, which take a directory, touch files.
//!
//! ```
//! use texmap_study::harness::{compare, reference_materials, reference_scene, render_reference, study_options};
//! use texmap_study::sweeps::{sweep_setup, SweepKind};
//! use texmap_core::shade::Lighting;
//! use texmap_impostor::{Method, Renderer};
//!
//! // One point of the field-of-view sweep: a sphere seen at 60°, 64x64 pixels.
//! let (spheres, camera) = sweep_setup(SweepKind::Fov, 60.0, 64).unwrap();
//! let lighting = Lighting::default_for(&camera);
//! let reference = render_reference(
//!     &reference_scene(&spheres), &reference_materials(&spheres), &camera, lighting, [0, 0, 0, 255], 1,
//! ).unwrap();
//! let frame = Renderer::new().render(&spheres, &camera, &study_options(Method::Raycast, lighting)).frame;
//! let m = compare(&frame, &reference).unwrap();
//! // The exact ray-cast impostor matches the reference's outline to well under a pixel.
//! assert!(m.silhouette_px <= 0.5, "{m:?}");
//! ```
//!
//! **Architecture invariant:** the study never depends on the CLI; it takes the periodic table
//! from `texmap-md-io` (one table for the study and `texmap render`). The CLI calls these
//! functions and writes the files.

pub mod chart;
pub mod elements;
pub mod envmap;
pub mod error;
pub mod harness;
pub mod materials;
pub mod md;
pub mod quality;
pub mod record;
pub mod report;
pub mod rng;
pub mod scenes;
pub mod sweeps;
pub mod terrain;

pub use error::StudyError;

//! # texmap-impostor — sphere sets drawn four ways
//!
//! Molecules and particle systems are sets of spheres. This crate draws a [`SphereScene`] with a
//! [`Camera`] and [`Lighting`](texmap_core::shade::Lighting) by one of four methods behind one face, so that they can be
//! compared pixel for pixel and millisecond for millisecond:
//!
//! | [`Method`] | what it is | exact? | bonds? |
//! |---|---|---|---|
//! | `Polygon` | tessellated spheres (the papers' baseline), tessellation chosen per sphere from its projected size, drawn with `texmap-raster` | silhouette to within the tessellation error | exact cylinders (shared pass) |
//! | `Lut` | Seed 002: a square of side 2R per sphere textured with a colour image (lit once per scene per material, 1-bit mask) and a depth image (once ever); `z = z0 + D(s,t)·R/d0`, which in our linear eye-space depth is `z0 + D·R` (see the `lut` module) | exact for an orthographic camera; errs with perspective as documented | exact cylinders (shared pass) |
//! | `Template` | Seed 004: disc billboards textured with a window cut from a template texture at `x_tex = 0.5 − r·sin(θ/2)`, `y_tex = 0.5 − r·sin(φ/2)` (our texture rows run downward, so `+` there) | pseudo-shading | exact cylinders (shared pass) |
//! | `Raycast` | per-fragment ray–sphere intersection over the sphere's exact perspective bounding quad | exact depth, normals and silhouette | exact cylinders (shared pass) |
//!
//! **Bonds.** Every method draws [`SphereScene::bonds`] (when [`Options::draw_bonds`] is on, the
//! default) in one pass after its spheres: exact ray-cast cylinders of radius
//! [`SphereScene::bond_radius`] (or each bond's own, [`SphereScene::bond_radii`]) between the atom centres, half-bond coloured (each half in its
//! atom's material), flat-capped where a bond is thicker than its atom, depth-tested against the
//! spheres so that atoms and bonds interpenetrate correctly (module `bonds`). A bond's accuracy
//! is the ray caster's whatever method drew the atoms; invalid bonds are skipped and counted in
//! [`RenderStats::bonds_skipped`].
//!
//! All methods cull to the view frustum, do no work for spheres behind the camera, handle spheres
//! crossing the near plane and sub-pixel spheres, and skip (and count) spheres with a non-finite
//! centre or a non-positive or non-finite radius.
//!
//! A [`Renderer`] keeps the per-scene tables (Seed 002 images, Seed 004 template pyramid) between
//! frames, as the papers do, and the per-frame bin buffers; [`Renderer::render_into`] also reuses
//! the output frame. [`render`] is the one-shot convenience.
//!
//! # How a frame is drawn
//! `Lut`, `Template` and `Raycast` share one pipeline (module `pipeline`): transform + cull +
//! project every sphere (parallel over fixed chunks) → two-pass binning of a 32-byte copy of each
//! projected sphere into 32x32 tiles (count, prefix sum, fill) → per tile, a depth pass over its
//! bin in sphere order (8-pixel lanes) and a resolve pass that colours each covered pixel once,
//! in parallel over bands of tiles. The per-method kernel is chosen once per frame (static
//! dispatch); `Raycast` runs its lanes on AVX2 when the CPU has it (run-time detection, no
//! FMA) and on SSE2 otherwise, with the same bytes either way. `Polygon` batches shared icosphere levels into `texmap-raster`.
//!
//! - **Near plane.** `Raycast`: the exact answer — fragments nearer than the near plane are
//!   clipped and the ray takes the far intersection, so a cut sphere (or one the eye is inside)
//!   shows its interior, lit with the normal turned toward the viewer (as the reference ray
//!   tracer's two-sided surfaces). `Lut`/`Template` do the same with their sprites: a fragment
//!   nearer than the near plane shows the sphere's far side instead, also for spheres whose
//!   centre is behind the near plane (their square is sized from the tangent length; see the
//!   `lut` module). Only spheres wholly nearer than the near plane are culled.
//!   `Polygon`: the rasteriser clips triangles; spheres reaching the near plane are drawn
//!   two-sided.
//! - **Sub-pixel spheres** follow the pixel-centre rule: a sphere is drawn where it covers a pixel
//!   centre; one that covers none is counted as culled.
//! - **Determinism.** The same input gives the same bytes for any number of rayon threads (fixed
//!   chunking, sphere order kept per tile, strict depth test); tested with pools of 1 and 2.
//!
//! ```
//! use texmap_impostor::{render, Method, Options, SphereScene};
//! use texmap_core::{camera::Camera, glam::Vec3, shade::{Lighting, Material}};
//!
//! let mut scene = SphereScene::new(vec![Material::plastic(Vec3::new(0.8, 0.1, 0.1))]);
//! scene.push(Vec3::ZERO, 1.0, 0);
//! let cam = Camera::perspective_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 30.0, 64, 64).unwrap();
//! let opts = Options::new(Method::Raycast, Lighting::default_for(&cam));
//! let out = render(&scene, &cam, &opts);
//! // The sphere covers the image centre, at depth 10 − 1 (pixel (32, 32) has its centre half a
//! // pixel off the view axis, which moves the hit ~0.002 back along the sphere).
//! let c = out.frame.index(32, 32);
//! assert!((out.frame.depth[c] - 9.0).abs() < 5e-3);
//! assert_eq!(out.stats.skipped_invalid, 0);
//!
//! // Ball and stick: a second atom and a bond of radius 0.2 between them, drawn as a cylinder.
//! scene.push(Vec3::new(3.0, 0.0, 0.0), 1.0, 0);
//! scene.bonds.push([0, 1]);
//! scene.bond_radius = 0.2;
//! let out = render(&scene, &cam, &opts);
//! assert_eq!(out.stats.bonds_drawn, 1);
//! // Halfway between the atoms (world x = 1.5), the bond's front at depth 10 − 0.2.
//! let x = (32.0 + 1.5 * cam.scale() / 10.0) as u32;
//! let d = out.frame.depth[out.frame.index(x, 32)];
//! assert!((d - 9.8).abs() < 1e-2, "depth {d}");
//! ```
//!
//! **Architecture invariant:** this crate depends on `texmap-core` and `texmap-raster` only; the
//! reference ray tracer appears in its tests alone (the comparison harness lives in `texmap-study`).

mod bonds;
mod lut;
mod options;
mod pipeline;
mod polygon;
mod raycast;
mod scene;
mod template;

use texmap_core::camera::Camera;
use texmap_core::frame::Frame;

pub use options::{Method, Options, PolygonShading, RenderStats, TemplateColoring, TemplateDepth};
pub use polygon::{LEVELS as ICOSPHERE_LEVELS, Tess, icospheres};
pub use scene::SphereScene;

/// A rendered frame and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct Render {
    pub frame: Frame,
    pub stats: RenderStats,
}

/// Draws sphere scenes, keeping per-scene tables and per-frame buffers between frames.
#[derive(Debug, Default)]
pub struct Renderer {
    bins: pipeline::Bins,
    lut: Option<lut::LutTables>,
    template: Option<template::TemplateTables>,
    polygon: polygon::PolygonState,
    bonds: bonds::BondBins,
    /// The ray-cast kernel's per-material lane rows (rebuilt every frame, buffer reused).
    material_rows: Vec<raycast::MaterialRow>,
    /// The ray-cast kernel's lane backend (AVX2 when available unless a test asks otherwise).
    backend: raycast::Backend,
}

/// Smallest and largest accepted side of the Seed 002 images and Seed 004 templates; other
/// values of [`Options::lut_size`] and [`Options::template_size`] are clamped into this range.
pub const MIN_TABLE_SIZE: u32 = 4;
pub const MAX_TABLE_SIZE: u32 = 4096;

impl Renderer {
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// Draw `scene` as `camera` sees it with `options.method`.
    pub fn render(&mut self, scene: &SphereScene, camera: &Camera, options: &Options) -> Render {
        let mut frame = Frame::new(camera.width(), camera.height(), options.background);
        let stats = self.render_into(scene, camera, options, &mut frame);
        Render { frame, stats }
    }

    /// Draw into an existing frame (every pixel is written; a frame of another size is resized),
    /// so that an animation reuses its buffers.
    pub fn render_into(
        &mut self,
        scene: &SphereScene,
        camera: &Camera,
        options: &Options,
        frame: &mut Frame,
    ) -> RenderStats {
        if frame.width() != camera.width() || frame.height() != camera.height() {
            *frame = Frame::new(camera.width(), camera.height(), options.background);
        }
        let view = pipeline::View::new(camera);
        let lighting = options.lighting.to_eye(camera);
        let bg = options.background;
        let mut stats = match options.method {
            Method::Raycast => {
                let stats = self
                    .bins
                    .build(scene, &view, |c, r, k| raycast::project(&view, c, r, k));
                if view.ortho {
                    let k = raycast::Orthographic {
                        view,
                        lighting,
                        materials: &scene.materials,
                    };
                    pipeline::draw_tiles(&self.bins, &view, &k, bg, frame);
                } else {
                    raycast::draw_perspective(
                        &self.bins,
                        &view,
                        lighting,
                        &scene.materials,
                        &mut self.material_rows,
                        bg,
                        frame,
                        self.backend,
                    );
                }
                stats
            }
            Method::Lut => {
                let size = options.lut_size.clamp(MIN_TABLE_SIZE, MAX_TABLE_SIZE);
                // Seed 002: the colour images are lit once per scene (rebuilt only on change).
                if !self
                    .lut
                    .as_ref()
                    .is_some_and(|t| t.matches(size, &lighting, &scene.materials))
                {
                    self.lut = Some(lut::LutTables::build(size, &lighting, &scene.materials));
                }
                let tables = self.lut.as_ref().expect("built above");
                let stats = self
                    .bins
                    .build(scene, &view, |c, r, k| lut::project(&view, tables, c, r, k));
                let k = lut::LutKernel { view, tables };
                pipeline::draw_tiles(&self.bins, &view, &k, bg, frame);
                stats
            }
            Method::Template => {
                let size = options.template_size.clamp(MIN_TABLE_SIZE, MAX_TABLE_SIZE);
                let coloring = options.template_coloring;
                if !self
                    .template
                    .as_ref()
                    .is_some_and(|t| t.matches(size, coloring, &lighting, &scene.materials))
                {
                    self.template = Some(template::TemplateTables::build(
                        size,
                        coloring,
                        &lighting,
                        &scene.materials,
                    ));
                }
                let tables = self.template.as_ref().expect("built above");
                let dirs = template::LightDirs::new(&lighting);
                let stats = self.bins.build(scene, &view, |c, r, k| {
                    template::project(&view, &dirs, c, r, k)
                });
                let k = template::TemplateKernel {
                    view,
                    tables,
                    depth_mode: options.template_depth,
                };
                pipeline::draw_tiles(&self.bins, &view, &k, bg, frame);
                stats
            }
            Method::Polygon => self.polygon.render(scene, camera, options, frame),
        };
        // Bonds: exact cylinder impostors depth-tested against the sphere pass (module `bonds`).
        if options.draw_bonds && !scene.bonds.is_empty() {
            let b = bonds::draw(&mut self.bonds, scene, &view, &lighting, frame);
            stats.bonds_drawn = b.drawn;
            stats.bonds_culled = b.culled;
            stats.bonds_skipped = b.skipped;
        }
        stats
    }
}

/// One-shot [`Renderer::render`].
pub fn render(scene: &SphereScene, camera: &Camera, options: &Options) -> Render {
    Renderer::new().render(scene, camera, options)
}

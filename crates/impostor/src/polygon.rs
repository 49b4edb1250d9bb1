//! The papers' baseline: spheres tessellated into triangles and drawn by `texmap-raster`.
//!
//! - **Tessellations** are icospheres (an icosahedron whose faces are split in four and pushed
//!   onto the unit sphere, [`LEVELS`] levels: 20 … 20·4⁵ triangles), built once per renderer and
//!   shared by every sphere.
//! - **Level of detail.** The tessellated surface lies inside the sphere; its largest gap is the
//!   face "sag" `1 − (distance of the face plane from the centre)`, measured on the built mesh per
//!   level. A sphere of projected radius `ρ` pixels gets the coarsest level with
//!   `ρ·sag ≤ Options::polygon_max_error_px` (the finest level when none is enough), so no sphere
//!   carries more triangles than its image needs. `ρ` is half the larger side of the sphere's
//!   exact screen bound (the same bound as the ray-cast method, which also culls).
//! - **Batches.** Each sphere's level is transformed (`c + R·v`, normal `v`) into reusable
//!   buffers, one batch per material, flushed to the rasteriser every [`BATCH_VERTS`] vertices:
//!   no allocation per sphere, bounded memory for millions of spheres, one draw call per batch.
//! - **Shading**: [`PolygonShading::Phong`] draws with `Shading::LitSmooth` (per-pixel
//!   [`Lighting::shade`] with the interpolated normal); [`PolygonShading::Gouraud`] shades each
//!   vertex with [`Lighting::shade`] (view vector from the vertex to the eye) and interpolates
//!   the colours.
//! - **Near plane**: the rasteriser clips triangles against it. Spheres that reach the near
//!   plane are drawn without back-face culling, so their interior shows (lit with the flipped
//!   normal), as in the ray-cast method; all others cull back faces.
//!
//! Batching by material changes the drawing order between materials; the z-buffer makes the
//! result independent of it except for exactly equal depths, and the output is deterministic.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::shade::Lighting;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, Shading};

use crate::options::{Options, PolygonShading, RenderStats};
use crate::pipeline::{Projected, View};
use crate::raycast;
use crate::scene::SphereScene;

/// Icosphere levels built (level `L` has `20·4^L` triangles).
pub const LEVELS: usize = 6;
/// Vertices per batch before it is drawn.
const BATCH_VERTS: usize = 1 << 20;

/// One tessellation of the unit sphere (an icosphere level), shared by every sphere drawn at
/// that level (and by md-scene's ellipsoids, which map it onto each ellipsoid).
#[derive(Clone, Debug)]
pub struct Tess {
    /// Unit vectors.
    pub verts: Vec<Vec3>,
    /// Counter-clockwise seen from outside.
    pub tris: Vec<[u32; 3]>,
    /// Largest gap between a face and the unit sphere.
    pub sag: f32,
}

/// The icosphere levels 0..[`LEVELS`] (level `L` has `20·4^L` triangles), closed and wound
/// counter-clockwise from outside.
pub fn icospheres() -> Vec<Tess> {
    // Build the icosahedron (counter-clockwise seen from outside).
    let p = (1.0 + 5f32.sqrt()) * 0.5;
    let mut verts: Vec<Vec3> = [
        (-1.0, p, 0.0),
        (1.0, p, 0.0),
        (-1.0, -p, 0.0),
        (1.0, -p, 0.0),
        (0.0, -1.0, p),
        (0.0, 1.0, p),
        (0.0, -1.0, -p),
        (0.0, 1.0, -p),
        (p, 0.0, -1.0),
        (p, 0.0, 1.0),
        (-p, 0.0, -1.0),
        (-p, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut out = Vec::with_capacity(LEVELS);
    for level in 0..LEVELS {
        out.push(Tess {
            sag: sag(&verts, &tris),
            verts: verts.clone(),
            tris: tris.clone(),
        });
        if level + 1 == LEVELS {
            break;
        }
        // Split every face in four, sharing edge midpoints.
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(tris.len() * 4);
        for t in &tris {
            let mut m = [0u32; 3];
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[e] = *mid.entry(key).or_insert_with(|| {
                    verts.push((verts[a as usize] + verts[b as usize]).normalize());
                    verts.len() as u32 - 1
                });
            }
            next.push([t[0], m[0], m[2]]);
            next.push([t[1], m[1], m[0]]);
            next.push([t[2], m[2], m[1]]);
            next.push(m);
        }
        tris = next;
    }
    out
}

/// `1 − min over faces of the face plane's distance from the centre`.
fn sag(verts: &[Vec3], tris: &[[u32; 3]]) -> f32 {
    let mut min = 1.0f32;
    for t in tris {
        let (a, b, c) = (
            verts[t[0] as usize],
            verts[t[1] as usize],
            verts[t[2] as usize],
        );
        let n = (b - a).cross(c - a).normalize();
        min = min.min(n.dot(a).abs());
    }
    1.0 - min
}

/// The level for a sphere of projected radius `rho` pixels.
#[inline]
fn level_for(tess: &[Tess], rho: f32, max_err: f32) -> usize {
    tess.iter()
        .position(|t| rho * t.sag <= max_err)
        .unwrap_or(tess.len() - 1)
}

/// Reusable state of the polygon method.
#[derive(Debug, Default)]
pub(crate) struct PolygonState {
    tess: Vec<Tess>,
    fb: Option<Framebuffer>,
    pos: Vec<Vec3>,
    nrm: Vec<Vec3>,
    col: Vec<Vec3>,
    idx: Vec<[u32; 3]>,
}

impl PolygonState {
    fn flush(
        &mut self,
        camera: &Camera,
        options: &Options,
        lighting_world: &Lighting,
        kind: usize,
        scene: &SphereScene,
        cull: Cull,
    ) {
        if self.idx.is_empty() {
            return;
        }
        let fb = self.fb.as_mut().expect("framebuffer made before drawing");
        let state = DrawState {
            cull,
            ..DrawState::default()
        };
        let material = scene.materials[kind];
        // The buffers hold valid indices by construction, so the mesh and the draw cannot fail;
        // a failure would only lose this batch.
        if let Ok(mesh) = Mesh::new(&self.pos, &self.idx) {
            let _ = match options.polygon_shading {
                PolygonShading::Phong => mesh.with_normals(&self.nrm).and_then(|m| {
                    fb.draw_mesh(
                        camera,
                        &m,
                        &Shading::LitSmooth {
                            lighting: *lighting_world,
                            material,
                        },
                        &state,
                    )
                }),
                PolygonShading::Gouraud => mesh
                    .with_colors(&self.col)
                    .and_then(|m| fb.draw_mesh(camera, &m, &Shading::VertexColor, &state)),
            };
        }
        self.pos.clear();
        self.nrm.clear();
        self.col.clear();
        self.idx.clear();
    }

    /// Draw the scene; returns the stats (same culling rules as the ray-cast method).
    pub fn render(
        &mut self,
        scene: &SphereScene,
        camera: &Camera,
        options: &Options,
        frame: &mut Frame,
    ) -> RenderStats {
        if self.tess.is_empty() {
            self.tess = icospheres();
        }
        let (w, h) = (camera.width(), camera.height());
        if !self
            .fb
            .as_ref()
            .is_some_and(|f| f.width() == w && f.height() == h)
        {
            self.fb = Framebuffer::new(w, h).ok();
        }
        let Some(fb) = self.fb.as_mut() else {
            return RenderStats::default();
        };
        fb.clear(options.background);
        let view = View::new(camera);
        let lighting = options.lighting;
        let max_err = if options.polygon_max_error_px > 0.0 {
            options.polygon_max_error_px
        } else {
            0.25
        };
        let mut stats = RenderStats::default();
        // One batch stream per material; spheres reaching the near plane in a second stream
        // drawn without back-face culling.
        for pass_kind in 0..scene.materials.len() {
            for near_pass in [false, true] {
                let cull = if near_pass { Cull::None } else { Cull::Back };
                for i in 0..scene.len() {
                    if scene.kinds[i] as usize != pass_kind {
                        continue;
                    }
                    if !scene.is_valid(i) {
                        continue;
                    }
                    let c = view.eye_space(scene.centers[i]);
                    let r = scene.radii[i];
                    let p = match raycast::project(&view, c, r, scene.kinds[i]) {
                        Projected::Draw(p) => p,
                        Projected::Culled => {
                            if !near_pass {
                                stats.culled += 1;
                            }
                            continue;
                        }
                    };
                    let crosses = -c.z - r <= view.near;
                    if crosses != near_pass {
                        continue;
                    }
                    stats.drawn += 1;
                    // Level of detail from the projected size.
                    let rho = 0.5 * (p.bbox[2] - p.bbox[0]).max(p.bbox[3] - p.bbox[1]) as f32;
                    let level = level_for(&self.tess, rho, max_err);
                    if self.pos.len() + self.tess[level].verts.len() > BATCH_VERTS {
                        self.flush(camera, options, &lighting, pass_kind, scene, cull);
                    }
                    let t = &self.tess[level];
                    let base = self.pos.len() as u32;
                    let centre = scene.centers[i];
                    for &v in &t.verts {
                        let pw = centre + v * r;
                        self.pos.push(pw);
                        self.nrm.push(v);
                        if options.polygon_shading == PolygonShading::Gouraud {
                            let m = &scene.materials[pass_kind];
                            self.col.push(lighting.shade(m, v, camera.to_eye_dir(pw)));
                        }
                    }
                    for tri in &t.tris {
                        self.idx.push([tri[0] + base, tri[1] + base, tri[2] + base]);
                    }
                }
                self.flush(camera, options, &lighting, pass_kind, scene, cull);
            }
        }
        stats.skipped_invalid = (0..scene.len()).filter(|&i| !scene.is_valid(i)).count();
        if let Some(fb) = self.fb.as_ref() {
            *frame = fb.to_frame();
        }
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icospheres_are_closed_unit_meshes_with_shrinking_sag() {
        let t = icospheres();
        assert_eq!(t.len(), LEVELS);
        let mut prev = 1.0;
        for (l, m) in t.iter().enumerate() {
            // Euler: V − E + F = 2 for a closed genus-0 mesh; E = 3F/2.
            let f = m.tris.len() as i64;
            let v = m.verts.len() as i64;
            assert_eq!(f, 20 * 4i64.pow(l as u32));
            assert_eq!(v - 3 * f / 2 + f, 2, "level {l}");
            assert!(m.verts.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
            // Every face is wound counter-clockwise seen from outside.
            for tri in &m.tris {
                let (a, b, c) = (
                    m.verts[tri[0] as usize],
                    m.verts[tri[1] as usize],
                    m.verts[tri[2] as usize],
                );
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
            }
            assert!(m.sag < prev && m.sag > 0.0, "level {l}: sag {}", m.sag);
            prev = m.sag;
        }
        // Level 0 is the icosahedron: inradius / circumradius = 0.7947 (f64 closed form).
        let want = 1.0 - 0.794_654_472_291_766_1;
        assert!(
            (t[0].sag as f64 - want).abs() < 1e-5,
            "expected {want}, got {}, tolerance 1e-5",
            t[0].sag
        );
        assert_eq!(level_for(&t, 1.0, 0.25), 0);
        assert_eq!(level_for(&t, 1e9, 0.25), LEVELS - 1);
    }
}

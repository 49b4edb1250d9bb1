//! Seed 002 (Nakamura & Kawase): spheres drawn as squares textured with a colour image and a
//! depth image.
//!
//! - **Assumption (the method):** per sphere, the eye and all lights are at infinity, so every
//!   sphere of a kind looks like the same lit unit sphere seen head-on (Seed 002 §3.1).
//! - **Colour image** `C(s,t)` per material, `N x N` texels (`Options::lut_size`): the unit sphere
//!   lit with [`Lighting::shade`] in eye space, viewer along +z, stored as sRGB8 with the 1-bit
//!   mask in alpha (255 inside the disc, 0 outside) (§3.1, §3.3 "型抜き"). Lit once per scene and
//!   lighting: [`LutTables`] is kept by the renderer and rebuilt only when the materials, the
//!   eye-space lighting or the size change.
//! - **Depth image** `D(s,t) = −sqrt(1 − u² − w²)` with `u = 2s − 1`, `w = 1 − 2t`: the unit sphere's
//!   offset from its centre plane, toward the viewer (§3.2), built once per size.
//! - **Drawing** (§3.3): the square of side `2R` through the centre `P0`, perpendicular to `O→P0`,
//!   is mapped to the screen with the paper's simplification "only centres are projected, each
//!   sphere is scaled by the reciprocal of its centre's z" (§6): a screen-aligned square of
//!   half-side `h = k·R/z0` around the projected centre (`h = s·R` for an orthographic camera of
//!   `s` pixels per unit). `(s, t)` runs across it; `C` and `D` are looked up at the nearest texel.
//! - **Depth mapping.** The paper's `z = z0 + D(s,t)·R/d0` is written for a z-buffer in
//!   projected units, where an eye-space offset `δ` at distance `d0` counts as `δ/d0`. Our depth is
//!   the linear eye-space distance along the view axis, in which the same surface offset is
//!   `D·R`, so we store `z = z0 + D(s,t)·R` (`z0` = centre depth). The factor `R` per sphere is the
//!   paper's "once per sphere per scene" constant.
//!
//! **Accuracy.** Exact (to the texel) for an orthographic camera. Under perspective the true
//! silhouette is an ellipse stretched away from the image centre and slightly larger than `k·R/z0`,
//! and the lighting of an off-axis sphere is seen from the wrong direction; both errors grow with
//! the angle off the view axis and with `R/z0` (measured by the study harness).
//!
//! **Near plane.** Spheres whose centre is not in front of the near plane are skipped (counted as
//! culled); fragments nearer than the near plane are clipped.
//!
//! Record layout ([`Proj::f`]): `[sx, sy, 1/(2h), z0, R]` (screen centre in pixels).

use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_core::shade::{Lighting, Material};

use crate::pipeline::{Kernel, Proj, Projected, TILE, TileBuf, TileRect, View, clip};

/// Seed 002's images: one colour+mask image per material and the shared depth image.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LutTables {
    pub size: u32,
    /// The lighting (eye space) and materials the colour images were lit with.
    pub lighting: Lighting,
    pub materials: Vec<Material>,
    /// `materials.len()` images of `size²` texels, row 0 at the top (t = 0).
    pub color: Vec<[u8; 4]>,
    /// `size²` depth offsets of the unit sphere (≤ 0, toward the viewer); 0 outside the disc.
    pub depth: Vec<f32>,
}

/// The unit-sphere point under texel `(i, j)` of an `n x n` image: `(u, w)` in `[−1, 1]`, y up.
#[inline]
fn texel_uw(i: u32, j: u32, n: u32) -> (f32, f32) {
    let s = (i as f32 + 0.5) / n as f32;
    let t = (j as f32 + 0.5) / n as f32;
    (2.0 * s - 1.0, 1.0 - 2.0 * t)
}

/// Seed 002 §3.2: the depth image of the unit sphere (computed once per size).
pub(crate) fn depth_image(n: u32) -> Vec<f32> {
    let mut d = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (u, w) = texel_uw(i, j, n);
            let q = 1.0 - u * u - w * w;
            d.push(if q >= 0.0 { -q.sqrt() } else { 0.0 });
        }
    }
    d
}

impl LutTables {
    /// Seed 002 §3.1: light the unit sphere once per material (eye and lights at infinity).
    pub fn build(size: u32, lighting: &Lighting, materials: &[Material]) -> LutTables {
        let n = size;
        let mut color = Vec::with_capacity((n * n) as usize * materials.len());
        for m in materials {
            for j in 0..n {
                for i in 0..n {
                    let (u, w) = texel_uw(i, j, n);
                    let q = 1.0 - u * u - w * w;
                    if q >= 0.0 {
                        let normal = Vec3::new(u, w, q.sqrt());
                        color.push(linear_to_srgb8(lighting.shade(m, normal, Vec3::Z), 255));
                    } else {
                        // The 1-bit mask: outside the disc.
                        color.push([0, 0, 0, 0]);
                    }
                }
            }
        }
        LutTables {
            size,
            lighting: *lighting,
            materials: materials.to_vec(),
            color,
            depth: depth_image(n),
        }
    }

    /// Whether these tables were made for this size, lighting and materials.
    pub fn matches(&self, size: u32, lighting: &Lighting, materials: &[Material]) -> bool {
        self.size == size && self.lighting == *lighting && self.materials == materials
    }
}

/// Project one eye-space sphere as a Seed 002 / Seed 004 screen square: centre, half-side.
/// Returns `(sx, sy, h, z0)` or `None` when the centre is not in front of the near plane.
#[inline]
pub(crate) fn square(view: &View, c: Vec3, r: f32) -> Option<(f32, f32, f32, f32)> {
    let z0 = -c.z;
    if !(z0 >= view.near) || z0 - r > view.far {
        return None;
    }
    if view.ortho {
        Some((
            view.cx + c.x * view.k,
            view.cy - c.y * view.k,
            r * view.k,
            z0,
        ))
    } else {
        // Only the centre is perspective-projected; the sphere scales with 1/z0 (Seed 002 §6).
        let s = view.k / z0;
        Some((view.cx + c.x * s, view.cy - c.y * s, r * s, z0))
    }
}

/// Project one eye-space sphere for the LUT kernel.
#[inline]
pub(crate) fn project(view: &View, c: Vec3, r: f32, kind: u16) -> Projected {
    let Some((sx, sy, h, z0)) = square(view, c, r) else {
        return Projected::Culled;
    };
    let (x0, x1) = View::pixel_range(sx - h, sx + h, view.width);
    let (y0, y1) = View::pixel_range(sy - h, sy + h, view.height);
    if x0 >= x1 || y0 >= y1 || !(h > 0.0) {
        return Projected::Culled;
    }
    Projected::Draw(Proj {
        f: [sx, sy, 0.5 / h, z0, r],
        bbox: [x0, y0, x1, y1],
        kind,
        aux: 0,
    })
}

/// The Seed 002 kernel.
pub(crate) struct LutKernel<'a> {
    pub view: View,
    pub tables: &'a LutTables,
}

impl LutKernel<'_> {
    /// Texel index (within one image) under pixel `(x, y)`, or `None` off the square.
    #[inline(always)]
    fn texel(&self, f: &[f32; 5], x: u32, y: u32) -> Option<usize> {
        let n = self.tables.size as f32;
        // (s, t) ∈ [0, 1]² across the square, t down.
        let s = (x as f32 + 0.5 - f[0]) * f[2] + 0.5;
        let t = (y as f32 + 0.5 - f[1]) * f[2] + 0.5;
        if !(s >= 0.0 && s < 1.0 && t >= 0.0 && t < 1.0) {
            return None;
        }
        let i = ((s * n) as u32).min(self.tables.size - 1);
        let j = ((t * n) as u32).min(self.tables.size - 1);
        Some((j * self.tables.size + i) as usize)
    }
}

impl Kernel for LutKernel<'_> {
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let img = (self.tables.size * self.tables.size) as usize;
        let near = self.view.near;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            let color = &self.tables.color[p.kind as usize * img..][..img];
            for j in y0..y1 {
                let row = (j * TILE) as usize;
                for i in x0..x1 {
                    let Some(tx) = self.texel(&p.f, tile.x0 + i, tile.y0 + j) else {
                        continue;
                    };
                    // The 1-bit mask.
                    if color[tx][3] == 0 {
                        continue;
                    }
                    // Seed 002 §3.3: z = z0 + D(s,t)·R (linear eye-space form, see module docs).
                    let z = p.f[3] + self.tables.depth[tx] * p.f[4];
                    if z < near {
                        continue;
                    }
                    let b = row + i as usize;
                    if z < buf.depth[b] {
                        buf.depth[b] = z;
                        buf.win[b] = idx as u32;
                    }
                }
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, _depth: f32, _flags: u32) -> [u8; 4] {
        let img = (self.tables.size * self.tables.size) as usize;
        let tx = self.texel(&rec.f, x, y).unwrap_or(0);
        self.tables.color[rec.kind as usize * img + tx]
    }
}

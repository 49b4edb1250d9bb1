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
//! **Near plane** (as the ray-cast method does): a fragment `z0 + D·R` nearer than the near plane
//! is clipped and the texel shows the sphere's far side `z0 − D·R` instead when that is in range
//! (the interior of a cut sphere, coloured from the mirrored texel, i.e. the normal turned toward
//! the viewer). A sphere whose centre is not in front of the near plane but which reaches past it
//! is drawn the same way; its square cannot be scaled by `1/z0`, so its half-side is taken from
//! the tangent length instead, `h = k·R/sqrt(|c|² − R²)` (the exact silhouette radius of a
//! sphere on the view axis), centred at the centre's direction scaled alike; when the eye is
//! inside the sphere or its centre is behind the eye, the square covers the whole image.
//! Spheres wholly nearer than the near plane are culled.
//!
//! Record layout ([`Proj::f`]): `[sx, sy, 1/(2h), z0, R]` (screen centre in pixels); `aux` is the
//! pyramid level ([`LutTables`]).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_core::shade::{Lighting, Material};

use crate::pipeline::{
    FLAG_INSIDE, Kernel, LANES, Proj, Projected, TILE, TileBuf, TileRect, View, clip,
};

/// Texels per screen pixel the pyramid level must keep. Measured on the orthographic test scene
/// (`tests/sprites.rs`, PSNR against the exact render): 1 → 25.2 dB, 2 → 27.8 dB, 4 → over 30 dB,
/// the same as the full 256² image; nearest-texel lookups need the margin at the rim.
pub(crate) const TEXELS_PER_PIXEL: f32 = 4.0;

/// Seed 002's images as a pyramid: per level, one colour+mask image per material and the shared
/// depth image.
///
/// A departure from the paper, which samples one image per kind: the images are also kept at
/// halved sizes (each evaluated directly at its texel centres, not filtered) and every sphere
/// reads the coarsest level with at least [`TEXELS_PER_PIXEL`] texels per pixel. A 7-pixel
/// sphere then reads a 32x32 image that stays in L1 cache instead of striding through a
/// 256x256 one.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LutTables {
    pub size: u32,
    /// The lighting (eye space) and materials the colour images were lit with.
    pub lighting: Lighting,
    pub materials: Vec<Material>,
    /// Number of levels; level `l` has side `size >> l`.
    pub levels: u32,
    /// Start of level `l` in `depth` (and, times the material count, in `color`).
    pub offsets: Vec<usize>,
    /// Per level: `materials.len()` images of `side²` texels, row 0 at the top (t = 0).
    pub color: Vec<[u8; 4]>,
    /// Per level: `side²` depth offsets of the unit sphere (≤ 0, toward the viewer). The 1-bit
    /// mask is folded in: `INFINITY` outside the disc, so `z0 + D·R` fails every depth test.
    pub depth: Vec<f32>,
}

/// The unit-sphere point under texel `(i, j)` of an `n x n` image: `(u, w)` in `[−1, 1]`, y up.
#[inline]
fn texel_uw(i: u32, j: u32, n: u32) -> (f32, f32) {
    let s = (i as f32 + 0.5) / n as f32;
    let t = (j as f32 + 0.5) / n as f32;
    (2.0 * s - 1.0, 1.0 - 2.0 * t)
}

/// Seed 002 §3.2: the depth image of the unit sphere, `INFINITY` outside the disc.
pub(crate) fn depth_image(n: u32) -> Vec<f32> {
    let mut d = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (u, w) = texel_uw(i, j, n);
            let q = 1.0 - u * u - w * w;
            d.push(if q >= 0.0 { -q.sqrt() } else { f32::INFINITY });
        }
    }
    d
}

impl LutTables {
    /// Seed 002 §3.1: light the unit sphere once per material (eye and lights at infinity).
    pub fn build(size: u32, lighting: &Lighting, materials: &[Material]) -> LutTables {
        let mut offsets = Vec::new();
        let mut color = Vec::new();
        let mut depth = Vec::new();
        let mut n = size;
        while n >= 2 {
            offsets.push(depth.len());
            depth.extend(depth_image(n));
            for m in materials {
                for j in 0..n {
                    for i in 0..n {
                        let (u, w) = texel_uw(i, j, n);
                        let q = 1.0 - u * u - w * w;
                        if q >= 0.0 {
                            let normal = Vec3::new(u, w, q.sqrt());
                            color.push(linear_to_srgb8(lighting.shade(m, normal, Vec3::Z), 255));
                        } else {
                            // The 1-bit mask (alpha): outside the disc.
                            color.push([0, 0, 0, 0]);
                        }
                    }
                }
            }
            n /= 2;
        }
        LutTables {
            size,
            lighting: *lighting,
            materials: materials.to_vec(),
            levels: offsets.len() as u32,
            offsets,
            color,
            depth,
        }
    }

    /// Whether these tables were made for this size, lighting and materials.
    pub fn matches(&self, size: u32, lighting: &Lighting, materials: &[Material]) -> bool {
        self.size == size && self.lighting == *lighting && self.materials == materials
    }

    /// The coarsest level with at least [`TEXELS_PER_PIXEL`] texels per pixel across a square of
    /// `px` pixels.
    #[inline]
    pub fn level_for(&self, px: f32) -> u32 {
        let mut level = 0u32;
        while level + 1 < self.levels
            && ((self.size >> (level + 1)) as f32) >= px * TEXELS_PER_PIXEL
        {
            level += 1;
        }
        level
    }
}

/// Project one eye-space sphere as a Seed 002 / Seed 004 screen square: centre, half-side.
/// Returns `(sx, sy, h, z0)`, or `None` when the sphere lies wholly nearer than the near plane
/// or beyond the far plane. Spheres crossing the near plane with their centre behind it get the
/// square described in the module docs.
#[inline]
pub(crate) fn square(view: &View, c: Vec3, r: f32) -> Option<(f32, f32, f32, f32)> {
    let z0 = -c.z;
    if !(z0 + r >= view.near) || z0 - r > view.far {
        return None;
    }
    if view.ortho {
        return Some((
            view.cx + c.x * view.k,
            view.cy - c.y * view.k,
            r * view.k,
            z0,
        ));
    }
    if z0 >= view.near {
        // Only the centre is perspective-projected; the sphere scales with 1/z0 (Seed 002 §6).
        let s = view.k / z0;
        return Some((view.cx + c.x * s, view.cy - c.y * s, r * s, z0));
    }
    // Crossing the near plane with the centre behind it: scale by the tangent length.
    let t2 = c.length_squared() - r * r;
    let zs = if t2 > 0.0 { t2.sqrt() } else { 0.0 };
    if z0 > 0.0 && zs > 1e-6 * r {
        let s = view.k / zs;
        let h = r * s;
        if h < 4.0 * (view.width + view.height) as f32 {
            return Some((view.cx + c.x * s, view.cy - c.y * s, h, z0));
        }
    }
    // Eye inside the sphere, centre behind the eye, or a square far larger than the image:
    // the whole image.
    let h = (view.width.max(view.height)) as f32;
    Some((view.cx, view.cy, h, z0))
}

/// Project one eye-space sphere for the LUT kernel.
#[inline]
pub(crate) fn project(view: &View, tables: &LutTables, c: Vec3, r: f32, kind: u16) -> Projected {
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
        aux: tables.level_for(2.0 * h) as u16,
    })
}

/// The Seed 002 kernel.
pub(crate) struct LutKernel<'a> {
    pub view: View,
    pub tables: &'a LutTables,
}

impl Kernel for LutKernel<'_> {
    #[inline(never)]
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let near = self.view.near;
        let t = self.tables;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            let [sx, sy, inv2h, z0, r] = p.f;
            let level = p.aux as u32;
            let n = t.size >> level;
            let nf = n as f32;
            let dimg = &t.depth[t.offsets[level as usize]..][..(n * n) as usize];
            let base_s = (tile.x0 as f32 + 0.5 - sx) * inv2h + 0.5;
            // Nearest depth a fragment can have: 8-pixel chunks whose stored depths are all
            // nearer are skipped (hierarchical z, as the ray-cast kernel does).
            let zmin = (z0 - r).max(near);
            for j in y0..y1 {
                // t ∈ [0, 1) down the square; rows off the square are skipped.
                let tt = ((tile.y0 + j) as f32 + 0.5 - sy) * inv2h + 0.5;
                if !(0.0..1.0).contains(&tt) {
                    continue;
                }
                let trow = ((tt * nf) as u32).min(n - 1) * n;
                let row = (j * TILE) as usize;
                let mut i = x0 as usize;
                while i < x1 as usize {
                    let b = row + i;
                    if buf.depth[b..b + LANES].iter().all(|&d| d <= zmin) {
                        i += LANES;
                        continue;
                    }
                    let mut z = [f32::INFINITY; LANES];
                    let mut flag = [0u32; LANES];
                    for (l, zl) in z.iter_mut().enumerate() {
                        let s = base_s + (i + l) as f32 * inv2h;
                        let inside = (0.0..1.0).contains(&s) && i + l < x1 as usize;
                        let sc = if s > 0.0 { s } else { 0.0 };
                        let sc = if sc < 1.0 { sc } else { 1.0 };
                        // SAFETY: sc·n ∈ [0, n] (NaN became 0 above): exact truncation, in range.
                        let ti = (unsafe { (sc * nf).to_int_unchecked::<i32>() } as u32).min(n - 1);
                        // Seed 002 §3.3: z = z0 + D(s,t)·R (linear eye-space form, module docs);
                        // D is infinite outside the mask.
                        let dd = dimg[(trow + ti) as usize];
                        let zz = z0 + dd * r;
                        // Clipped by the near plane: the far side z0 − D·R (module docs).
                        let back = !(zz >= near);
                        let zz = if back { z0 - dd * r } else { zz };
                        *zl = if inside && zz >= near && dd.is_finite() {
                            zz
                        } else {
                            f32::INFINITY
                        };
                        flag[l] = if back { FLAG_INSIDE } else { 0 };
                    }
                    let depth = &mut buf.depth[b..b + LANES];
                    let win = &mut buf.win[b..b + LANES];
                    for l in 0..LANES {
                        let closer = z[l] < depth[l];
                        depth[l] = if closer { z[l] } else { depth[l] };
                        win[l] = if closer { idx as u32 | flag[l] } else { win[l] };
                    }
                    i += LANES;
                }
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, _depth: f32, flags: u32) -> [u8; 4] {
        let t = self.tables;
        let level = rec.aux as u32;
        let n = t.size >> level;
        let nf = n as f32;
        // (s, t) ∈ [0, 1]² across the square, t down; nearest texel.
        let s = (x as f32 + 0.5 - rec.f[0]) * rec.f[2] + 0.5;
        let tt = (y as f32 + 0.5 - rec.f[1]) * rec.f[2] + 0.5;
        // The far side seen from inside: the mirrored texel (normal turned toward the viewer).
        let (s, tt) = if flags & FLAG_INSIDE != 0 {
            (1.0 - s, 1.0 - tt)
        } else {
            (s, tt)
        };
        let i = ((s.max(0.0) * nf) as u32).min(n - 1);
        let j = ((tt.max(0.0) * nf) as u32).min(n - 1);
        let img = (n * n) as usize;
        let base = t.offsets[level as usize] * t.materials.len() + rec.kind as usize * img;
        t.color[base + (j * n + i) as usize]
    }
}

//! The exact method: a ray–sphere intersection per pixel over the sphere's perspective bounding
//! rectangle (a "ray-cast impostor").
//!
//! - **Bound.** Under perspective a sphere's silhouette is an ellipse. Its horizontal (vertical)
//!   extent is given by the two planes through the eye, parallel to the image's y (x) axis, that
//!   touch the sphere: in the eye-space xz (yz) plane these are the tangents from the origin to
//!   the circle of radius `r` around `(c.x, c.z)`, of length `t = sqrt(|c|² − r²)`, turned by
//!   `±asin(r/|c|)` from the centre direction. Their screen positions bound the ellipse exactly;
//!   [`View::pixel_range`] widens the bound by ~1e-3 px. When a tangent points behind the eye
//!   (the sphere reaches the eye plane), that axis falls back to the whole image.
//! - **Intersection.** The eye ray through pixel centre `(i + 0.5, j + 0.5)` is
//!   `d = ((x − w/2)/k, (h/2 − y)/k, −1)` so that the ray parameter IS the depth (eye-space
//!   distance along the view axis). With `a = d·d`, `b = d·c`, the pbrt-style stable discriminant
//!   uses the vector from the centre to the ray's closest point, `v = c − (b/a)·d`:
//!   `Δ = a·(r² − |v|²)` (no catastrophic cancellation for far spheres), then
//!   `q = b + sign(b)·sqrt(Δ)`, `t_near = (|c|² − r²)/q`, `t_far = q/a`.
//! - **Near plane.** A hit nearer than the camera's near plane is clipped away, exactly as a
//!   rasteriser's near plane does; the ray then takes the far intersection if that is in range, so
//!   a sphere cut by the near plane, or one the eye is inside, shows its **interior**, lit with
//!   the normal facing the viewer (two-sided lighting). Spheres wholly nearer than the near plane
//!   (or behind the eye) are culled.
//! - **Shading.** Exact normal `n = (p − c)/r`, `v = −d/|d|`, [`Lighting::shade`] with the lights
//!   in eye space (converted once per frame), as the reference ray tracer does.
//! - **Orthographic cameras** use parallel rays along −z: coverage `ρ² ≤ r²` with
//!   `ρ² = (x − c.x)² + (y − c.y)²`, depth `−c.z − sqrt(r² − ρ²)`.
//!
//! Record layout ([`Proj::f`]): `[c.x, c.y, c.z, r², |c|² − r²]` in eye space.

use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_core::shade::{Lighting, Material};

use crate::pipeline::{FLAG_INSIDE, Kernel, Proj, Projected, TILE, TileBuf, TileRect, View, clip};

/// Bounds of `x/(−z)` over the circle of radius `r` around `(a, b)` in a plane through the eye
/// (`b` is the eye-space z of the centre): the tangent directions from the origin.
/// Returns `None` when the circle reaches the eye plane (no finite bound).
#[inline]
fn tangent_bounds(a: f32, b: f32, r: f32) -> Option<(f32, f32)> {
    let l2 = a * a + b * b;
    let t2 = l2 - r * r;
    if !(t2 > 0.0) {
        return None;
    }
    let t = t2.sqrt();
    // Tangent directions (scaled by |c|): rotate (a, b) by ±asin(r/|c|).
    let ux0 = t * a - r * b;
    let uz0 = r * a + t * b;
    let ux1 = t * a + r * b;
    let uz1 = -r * a + t * b;
    // Both must point in front of the eye plane (z < 0), with a margin against rounding.
    let margin = 1e-6 * l2;
    if !(uz0 < -margin && uz1 < -margin) {
        return None;
    }
    let x0 = ux0 / -uz0;
    let x1 = ux1 / -uz1;
    Some((x0.min(x1), x0.max(x1)))
}

/// Project one eye-space sphere for the ray-cast kernels.
#[inline]
pub(crate) fn project(view: &View, c: Vec3, r: f32, kind: u16) -> Projected {
    let depth = -c.z;
    // Cull: wholly nearer than the near plane (or behind the eye), or beyond the far plane.
    if depth + r < view.near || depth - r > view.far {
        return Projected::Culled;
    }
    let (x_lo, x_hi, y_lo, y_hi);
    if view.ortho {
        x_lo = view.cx + (c.x - r) * view.k;
        x_hi = view.cx + (c.x + r) * view.k;
        y_lo = view.cy - (c.y + r) * view.k;
        y_hi = view.cy - (c.y - r) * view.k;
    } else {
        let w = view.width as f32;
        let h = view.height as f32;
        match tangent_bounds(c.x, c.z, r) {
            Some((lo, hi)) => {
                x_lo = view.cx + lo * view.k;
                x_hi = view.cx + hi * view.k;
            }
            None => {
                x_lo = 0.0;
                x_hi = w;
            }
        }
        match tangent_bounds(c.y, c.z, r) {
            Some((lo, hi)) => {
                y_lo = view.cy - hi * view.k;
                y_hi = view.cy - lo * view.k;
            }
            None => {
                y_lo = 0.0;
                y_hi = h;
            }
        }
    }
    let (x0, x1) = View::pixel_range(x_lo, x_hi, view.width);
    let (y0, y1) = View::pixel_range(y_lo, y_hi, view.height);
    if x0 >= x1 || y0 >= y1 {
        // Off screen, or so small that it covers no pixel centre.
        return Projected::Culled;
    }
    let r2 = r * r;
    Projected::Draw(Proj {
        f: [c.x, c.y, c.z, r2, c.length_squared() - r2],
        bbox: [x0, y0, x1, y1],
        kind,
        aux: 0,
    })
}

/// Ray-cast kernel, perspective camera.
pub(crate) struct Perspective<'a> {
    pub view: View,
    pub lighting: Lighting,
    pub materials: &'a [Material],
}

/// Intersect the eye ray `d` (with `d.z = −1`) with a record's sphere. Returns the depth and
/// whether the far (inside) intersection was taken.
#[inline(always)]
fn hit_perspective(f: &[f32; 5], d: Vec3, near: f32, far: f32) -> Option<(f32, bool)> {
    let c = Vec3::new(f[0], f[1], f[2]);
    // Compute the stable discriminant from the centre-to-closest-point vector.
    let a = d.length_squared();
    let b = d.dot(c);
    let v = c - d * (b / a);
    let disc = a * (f[3] - v.length_squared());
    if !(disc >= 0.0) {
        return None;
    }
    // Compute both roots without cancellation.
    let q = b + disc.sqrt().copysign(b);
    if q == 0.0 {
        return None;
    }
    let t0 = f[4] / q;
    let t1 = q / a;
    let (tn, tf) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    // Clip at the near plane: the near hit if in range, else the far (interior) one.
    if tn >= near && tn <= far {
        Some((tn, false))
    } else if tn < near && tf >= near && tf <= far {
        Some((tf, true))
    } else {
        None
    }
}

impl Kernel for Perspective<'_> {
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let v = &self.view;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            for j in y0..y1 {
                let dy = (v.cy - ((tile.y0 + j) as f32 + 0.5)) * v.inv_k;
                let row = (j * TILE) as usize;
                for i in x0..x1 {
                    let dx = ((tile.x0 + i) as f32 + 0.5 - v.cx) * v.inv_k;
                    let d = Vec3::new(dx, dy, -1.0);
                    if let Some((t, inside)) = hit_perspective(&p.f, d, v.near, v.far) {
                        let b = row + i as usize;
                        if t < buf.depth[b] {
                            buf.depth[b] = t;
                            buf.win[b] = idx as u32 | if inside { FLAG_INSIDE } else { 0 };
                        }
                    }
                }
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, depth: f32, flags: u32) -> [u8; 4] {
        let v = &self.view;
        let d = Vec3::new(
            (x as f32 + 0.5 - v.cx) * v.inv_k,
            (v.cy - (y as f32 + 0.5)) * v.inv_k,
            -1.0,
        );
        let c = Vec3::new(rec.f[0], rec.f[1], rec.f[2]);
        // Exact normal at the hit point; flipped toward the viewer on the interior.
        let mut n = (d * depth - c).normalize_or_zero();
        if flags & FLAG_INSIDE != 0 {
            n = -n;
        }
        let to_eye = -d.normalize();
        let m = &self.materials[rec.kind as usize];
        linear_to_srgb8(self.lighting.shade(m, n, to_eye), 255)
    }
}

/// Ray-cast kernel, orthographic camera (parallel rays along −z).
pub(crate) struct Orthographic<'a> {
    pub view: View,
    pub lighting: Lighting,
    pub materials: &'a [Material],
}

impl Kernel for Orthographic<'_> {
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let v = &self.view;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            let [cx, cy, cz, r2, _] = p.f;
            for j in y0..y1 {
                let ey = (v.cy - ((tile.y0 + j) as f32 + 0.5)) * v.inv_k - cy;
                let row = (j * TILE) as usize;
                for i in x0..x1 {
                    let ex = ((tile.x0 + i) as f32 + 0.5 - v.cx) * v.inv_k - cx;
                    let h2 = r2 - (ex * ex + ey * ey);
                    if !(h2 >= 0.0) {
                        continue;
                    }
                    let s = h2.sqrt();
                    let tn = -cz - s;
                    let tf = -cz + s;
                    let (t, inside) = if tn >= v.near {
                        (tn, false)
                    } else {
                        (tf, true)
                    };
                    if t < v.near || t > v.far {
                        continue;
                    }
                    let b = row + i as usize;
                    if t < buf.depth[b] {
                        buf.depth[b] = t;
                        buf.win[b] = idx as u32 | if inside { FLAG_INSIDE } else { 0 };
                    }
                }
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, depth: f32, flags: u32) -> [u8; 4] {
        let v = &self.view;
        let p = Vec3::new(
            (x as f32 + 0.5 - v.cx) * v.inv_k,
            (v.cy - (y as f32 + 0.5)) * v.inv_k,
            -depth,
        );
        let c = Vec3::new(rec.f[0], rec.f[1], rec.f[2]);
        let mut n = (p - c).normalize_or_zero();
        if flags & FLAG_INSIDE != 0 {
            n = -n;
        }
        let m = &self.materials[rec.kind as usize];
        linear_to_srgb8(self.lighting.shade(m, n, Vec3::Z), 255)
    }
}

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
//!   distance along the view axis). With `s = (d·c)/|d|²` the parameter of the ray point nearest
//!   the centre and `v = c − s·d` the vector to it, the discriminant is formed pbrt-style from `v`
//!   (`r² − |v|²`, no catastrophic cancellation of `b² − a·c` for distant spheres) and the hits are
//!   `t = s ∓ sqrt((r² − |v|²)/|d|²)`. `1/|d|²` comes from a per-tile table, so the depth pass
//!   has no division and one square root per pixel, over 8-pixel lanes. (The subtraction
//!   `s − half chord` loses relative precision only when the eye is within a tiny distance of
//!   the sphere surface; the absolute error stays ~1 ulp of `s`, far below the 1e-4 depth target.)
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
//! Record layout ([`Proj::f`]): `[c.x, c.y, c.z, r², 1/r]` in eye space.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_core::shade::{Lighting, Material};

use crate::fastshade::{self, M8, Surf8, V8, W};
use crate::pipeline::{
    FLAG_INSIDE, Kernel, LANES, NONE, Proj, Projected, TILE, TILE_BUF, TILE_PX, TileBuf, TileRect,
    View, clip,
};

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
        f: [c.x, c.y, c.z, r2, 1.0 / r],
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

/// Per-tile ray tables: `d = (dx[i], dy[j], −1)` and `1/|d|²` per pixel.
struct RayTable {
    dx: [f32; TILE as usize + LANES],
    dy: [f32; TILE as usize],
    inv_a: [f32; TILE_BUF],
}

impl RayTable {
    fn new(v: &View, tile: TileRect) -> RayTable {
        let mut t = RayTable {
            dx: [0.0; TILE as usize + LANES],
            dy: [0.0; TILE as usize],
            inv_a: [0.0; TILE_BUF],
        };
        for (i, dx) in t.dx.iter_mut().enumerate() {
            *dx = ((tile.x0 + i as u32) as f32 + 0.5 - v.cx) * v.inv_k;
        }
        for (j, dy) in t.dy.iter_mut().enumerate() {
            *dy = (v.cy - ((tile.y0 + j as u32) as f32 + 0.5)) * v.inv_k;
        }
        // 1/|d|² per pixel, 8 lanes at a time (the slack past the last row repeats it).
        let one = V8::splat(1.0);
        for (p, ia) in t.inv_a.chunks_exact_mut(LANES).enumerate() {
            let j = (p * LANES / TILE as usize).min(TILE as usize - 1);
            let i = p * LANES % TILE as usize;
            let dx = V8::load_from(&t.dx[i..]);
            let dy = V8::splat(t.dy[j]);
            (one / (dx * dx + dy * dy + one)).store_to(ia);
        }
        t
    }
}

/// Intersect the eye rays of 8 neighbouring pixels of one row with a record's sphere.
///
/// The ray `d = (dx, dy, −1)` has parameter = depth. With `s = (d·c)/|d|²` the parameter of the
/// point nearest the centre and `v = c − s·d` the vector to it (pbrt's stable discriminant), the
/// half chord is `sqrt((r² − |v|²)/|d|²)`, so `t = s ∓ sqrt((r² − |v|²)/|d|²)`: no division
/// per pixel (`1/|d|²` comes from the tile table) and no cancellation for distant spheres.
/// Returns the depths (`INFINITY` for a miss or a clipped hit) and the inside flags.
#[inline(always)]
fn hit8(f: &[f32; 5], dx: V8, dy: V8, ia: V8, near: V8, far: V8) -> (V8, M8) {
    let (cx, cy, cz, r2) = (
        V8::splat(f[0]),
        V8::splat(f[1]),
        V8::splat(f[2]),
        V8::splat(f[3]),
    );
    // Compute the closest point and the stable discriminant.
    let s = (dx * cx + dy * cy - cz) * ia;
    let vx = cx - dx * s;
    let vy = cy - dy * s;
    let vz = cz + s;
    let h2 = r2 - (vx * vx + vy * vy + vz * vz);
    let zero = V8::splat(0.0);
    let hc = (h2.max(zero) * ia).sqrt();
    let tn = s - hc;
    let tf = s + hc;
    // Clip at the near plane: the near hit if in range, else the far (interior) one.
    let inside = tn.lt(near);
    let th = V8::select(inside, tf, tn);
    let ok = h2.ge(zero).and(th.ge(near)).and(th.le(far));
    (V8::select(ok, th, V8::splat(f32::INFINITY)), inside)
}

/// Strict depth test of 8 lanes against `depth`/`win` (the earlier record wins ties).
#[inline(always)]
fn depth_test8(t: V8, inside: M8, idx: u32, depth: &mut [f32], win: &mut [u32]) {
    let d = V8::load_from(depth);
    let closer = t.lt(d);
    if closer.bits() == 0 {
        return;
    }
    V8::select(closer, t, d).store_to(depth);
    let w = V8::select(
        inside,
        V8::splat_bits(idx | FLAG_INSIDE),
        V8::splat_bits(idx),
    );
    V8::select(closer, w, V8::load_bits(win)).store_bits(win);
}

impl Kernel for Perspective<'_> {
    #[inline(never)]
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let v = &self.view;
        let rt = RayTable::new(v, tile);
        let (near, far) = (V8::splat(v.near), V8::splat(v.far));
        let inf = V8::splat(f32::INFINITY);
        const T: usize = TILE as usize;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            let (x0, y0, x1, y1) = (x0 as usize, y0 as usize, x1 as usize, y1 as usize);
            let idx = idx as u32;
            // Nearest depth the sphere can reach (widened by 1e-5 relative against rounding in
            // `hit8`): chunks whose 8 stored depths are all nearer are skipped, a cheap
            // hierarchical-z test.
            let z_front = -p.f[2] - p.f[3].sqrt();
            let zmin = V8::splat((z_front - 1e-5 * z_front.abs()).max(v.near));
            if x1 - x0 <= 4 {
                // Narrow boxes (small spheres): two rows of up to 4 pixels per 8-lane test.
                let cols = M8::first_of_halves(x1 - x0);
                let dx4 = &rt.dx[x0..];
                let mut j = y0;
                while j < y1 {
                    let two = j + 1 < y1;
                    let j1 = if two { j + 1 } else { j };
                    let (b0, b1) = (j * T + x0, j1 * T + x0);
                    let d = V8::load_halves(&buf.depth[b0..], &buf.depth[b1..]);
                    let lanes = if two { cols } else { cols.and(M8::first(4)) };
                    if zmin.lt(d).and(lanes).bits() != 0 {
                        let dx = V8::load_halves(dx4, dx4);
                        let dy = V8::load_halves(&[rt.dy[j]; 4], &[rt.dy[j1]; 4]);
                        let ia = V8::load_halves(&rt.inv_a[b0..], &rt.inv_a[b1..]);
                        let (t, inside) = hit8(&p.f, dx, dy, ia, near, far);
                        let t = V8::select(lanes, t, inf);
                        let closer = t.lt(d);
                        if closer.bits() != 0 {
                            let nd = V8::select(closer, t, d);
                            let w = V8::select(
                                inside,
                                V8::splat_bits(idx | FLAG_INSIDE),
                                V8::splat_bits(idx),
                            );
                            let mut wins = [0u32; LANES];
                            wins[..4].copy_from_slice(&buf.win[b0..b0 + 4]);
                            wins[4..].copy_from_slice(&buf.win[b1..b1 + 4]);
                            let nw = V8::select(closer, w, V8::load_bits(&wins));
                            nw.store_bits(&mut wins);
                            nd.store_lo(&mut buf.depth[b0..]);
                            buf.win[b0..b0 + 4].copy_from_slice(&wins[..4]);
                            if two {
                                nd.store_hi(&mut buf.depth[b1..]);
                                buf.win[b1..b1 + 4].copy_from_slice(&wins[4..]);
                            }
                        }
                    }
                    j += 2;
                }
                continue;
            }
            for j in y0..y1 {
                let row = j * T;
                let dy = V8::splat(rt.dy[j]);
                let mut i = x0;
                while i < x1 {
                    let b = row + i;
                    // Lanes past the box must not write.
                    let lanes = M8::first(x1 - i);
                    let d = V8::load_from(&buf.depth[b..]);
                    if zmin.lt(d).and(lanes).bits() != 0 {
                        let (t, inside) = hit8(
                            &p.f,
                            V8::load_from(&rt.dx[i..]),
                            dy,
                            V8::load_from(&rt.inv_a[b..]),
                            near,
                            far,
                        );
                        let t = V8::select(lanes, t, inf);
                        depth_test8(
                            t,
                            inside,
                            idx,
                            &mut buf.depth[b..b + LANES],
                            &mut buf.win[b..b + LANES],
                        );
                    }
                    i += LANES;
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
        let mut n = (d * depth - c) * rec.f[4];
        if flags & FLAG_INSIDE != 0 {
            n = -n;
        }
        let to_eye = d * -(1.0 / d.length());
        let m = &self.materials[rec.kind as usize];
        linear_to_srgb8(fastshade::shade(&self.lighting, m, n, to_eye), 255)
    }

    #[inline(never)]
    fn resolve_tile(
        &self,
        recs: &[Proj],
        tile: TileRect,
        buf: &TileBuf,
        background: [u8; 4],
        color: &mut [[u8; 4]],
        stride: usize,
    ) {
        let v = &self.view;
        // Ray directions of the tile's columns and rows (pixel centres).
        let mut dxs = [0f32; TILE as usize];
        let mut dys = [0f32; TILE as usize];
        for i in 0..TILE as usize {
            dxs[i] = ((tile.x0 as usize + i) as f32 + 0.5 - v.cx) * v.inv_k;
            dys[i] = (v.cy - ((tile.y0 as usize + i) as f32 + 0.5)) * v.inv_k;
        }
        let enc = fastshade::srgb_table();
        // Compact the covered pixels, so that lanes are spent on them only.
        let mut list = [0u16; TILE_PX];
        let mut n = 0;
        for j in 0..tile.h {
            for i in 0..tile.w {
                let b = (j * TILE + i) as usize;
                if buf.win[b] == NONE {
                    color[j as usize * stride + i as usize] = background;
                } else {
                    list[n] = b as u16;
                    n += 1;
                }
            }
        }
        for chunk in list[..n].chunks(W) {
            // Gather the winners into lanes (short chunks repeat their first pixel).
            let mut s = Surf8::default();
            let (mut dx, mut dy, mut t) = ([0f32; W], [0f32; W], [0f32; W]);
            let (mut c, mut sign) = ([[0f32; W]; 3], [0f32; W]);
            for l in 0..W {
                let b = chunk[if l < chunk.len() { l } else { 0 }] as usize;
                let wv = buf.win[b];
                let rec = &recs[(wv & !FLAG_INSIDE) as usize];
                t[l] = buf.depth[b];
                dx[l] = dxs[b % TILE as usize];
                dy[l] = dys[b / TILE as usize];
                for k in 0..3 {
                    c[k][l] = rec.f[k];
                }
                sign[l] = if wv & FLAG_INSIDE != 0 {
                    -rec.f[4]
                } else {
                    rec.f[4]
                };
                let m = &self.materials[rec.kind as usize];
                for k in 0..3 {
                    s.base[k][l] = m.base_color[k];
                }
                s.spec[l] = m.specular;
                s.shin[l] = m.shininess;
            }
            for l in 0..W {
                // Exact normal at the hit point; flipped toward the viewer on the interior.
                s.n[0][l] = (dx[l] * t[l] - c[0][l]) * sign[l];
                s.n[1][l] = (dy[l] * t[l] - c[1][l]) * sign[l];
                s.n[2][l] = (-t[l] - c[2][l]) * sign[l];
                // Unit vector toward the eye.
                let id = 1.0 / (dx[l] * dx[l] + dy[l] * dy[l] + 1.0).sqrt();
                s.v[0][l] = -dx[l] * id;
                s.v[1][l] = -dy[l] * id;
                s.v[2][l] = id;
            }
            let c = fastshade::shade8(&self.lighting, &s);
            // Encode to sRGB8 (texmap-core's table, indices over lanes).
            let idx = [
                fastshade::srgb_index8(&c[0]),
                fastshade::srgb_index8(&c[1]),
                fastshade::srgb_index8(&c[2]),
            ];
            for (l, &b) in chunk.iter().enumerate() {
                let (i, j) = (b as usize % TILE as usize, b as usize / TILE as usize);
                color[j * stride + i] = [
                    enc[idx[0][l] as usize],
                    enc[idx[1][l] as usize],
                    enc[idx[2][l] as usize],
                    255,
                ];
            }
        }
    }
}
/// Ray-cast kernel, orthographic camera (parallel rays along −z).
pub(crate) struct Orthographic<'a> {
    pub view: View,
    pub lighting: Lighting,
    pub materials: &'a [Material],
}

impl Kernel for Orthographic<'_> {
    #[inline(never)]
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
        linear_to_srgb8(fastshade::shade(&self.lighting, m, n, Vec3::Z), 255)
    }
}

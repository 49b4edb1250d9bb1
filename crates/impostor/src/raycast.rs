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
//! - **Lanes.** The perspective kernel (depth pass and resolve) is generic over
//!   [`Lanes8`] and compiled three times: on the SSE2 baseline; where [`lanes::isa`] allows
//!   AVX2 (checked once per frame), inside `#[target_feature(enable = "avx2")]` wrappers with
//!   one `__m256` per 8 lanes ([`F32x8Avx2`]); and where it allows AVX-512, the same `__m256`
//!   code compiled with AVX-512VL enabled (32 registers: the shading's spills go; mask-register selects). No FMA, so all
//!   three give the same bytes (tested). S1, one thread, interleaved A/B on an Intel Xeon
//!   (AVX-512): the AVX-512VL build ran ~10% faster than the AVX2 build of the same code.
//! - **Resolve.** Deferred shading over 8-pixel row chunks of the tile (S1 averages 7.5
//!   covered pixels per covered chunk, so compacting the covered pixels first does not pay):
//!   a chunk with no winner is background; otherwise the 8 winners' 32-byte records and their
//!   material rows are loaded whole and transposed to lanes (instead of 13 scalar gathers per
//!   lane), the inside flag (the sign bit of the winner entry) flips the sign of `1/r`, and
//!   the colour is encoded and stored as one 8-pixel write. A chunk whose covered pixels all
//!   lie on one sphere (most chunks of S1) takes that record and material as constants
//!   instead (no gather, no transpose). Measured on S1 (callgrind, AVX2 build, instructions
//!   per frame): shading 18.7 M → 6.9 M → 6.4 M, depth pass 8.5 M → 3.7 M. Tried and
//!   dropped: computing the view vector and the half-vector lengths in a first pass over the
//!   tile's covered chunks (off the shading's latency chain): ~10% less resolve time in a
//!   single-thread A/B under load, but +0.9 M instructions and 20 KB of tables to clear per
//!   tile (+3.9 M counted memset), not a clear win.
//!
//! Record layout ([`Proj::f`]): `[c.x, c.y, c.z, r², 1/r]` in eye space.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use std::marker::PhantomData;

use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_core::frame::Frame;
#[cfg(target_arch = "x86_64")]
use texmap_core::lanes::F32x8Avx2;
use texmap_core::lanes::{self, F32x8, LaneMask, Lanes8, SpecPow};
use texmap_core::shade::{Lighting, Material};

use crate::pipeline::{
    self, Bins, FLAG_INSIDE, Kernel, LANES, NONE, ORDER_MAX, Proj, Projected, TILE, TILE_BUF,
    TileBuf, TileJob, TileRect, View, clip,
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

/// Which lane backend the perspective kernel runs on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Backend {
    /// The AVX2 lanes when this CPU has AVX2 (checked once per frame), compiled with AVX-512VL
    /// enabled when it has that too; else the baseline.
    #[default]
    Best,
    /// The AVX2 lanes compiled for AVX2 alone (used by tests to compare the two builds).
    #[cfg_attr(not(test), allow(dead_code))]
    Avx2,
    /// The SSE2 / portable [`F32x8`] lanes (used by tests to check that both give the same bytes).
    #[cfg_attr(not(test), allow(dead_code))]
    Baseline,
}

/// One material as a row of 8 lanes for the resolve pass's transpose:
/// `[base r, base g, base b, specular, shininess, 0, 0, 0]`.
pub(crate) type MaterialRow = [f32; 8];

/// Ray-cast kernel, perspective camera, on the lanes of backend `V`.
pub(crate) struct Perspective<'a, V> {
    view: View,
    lighting: Lighting,
    materials: &'a [Material],
    /// [`MaterialRow`] per material.
    rows: &'a [MaterialRow],
    /// The specular power when every material has the same shininess (the common case): then
    /// no chunk needs to check its lanes.
    pow: Option<SpecPow>,
    /// Run the [`F32x8Avx2`] kernels' build compiled with AVX-512VL (see [`raster_evex`]).
    evex: bool,
    _lanes: PhantomData<V>,
}

impl<'a, V: Lanes8> Perspective<'a, V> {
    /// The kernel, or `None` when this CPU cannot run backend `V`. `rows` is filled from
    /// `materials` (a buffer kept between frames).
    fn new(
        view: View,
        lighting: Lighting,
        materials: &'a [Material],
        rows: &'a mut Vec<MaterialRow>,
    ) -> Option<Self> {
        if !V::available() {
            return None;
        }
        rows.clear();
        rows.extend(materials.iter().map(|m| {
            let b = m.base_color;
            [b.x, b.y, b.z, m.specular, m.shininess, 0.0, 0.0, 0.0]
        }));
        let pow = match materials.first() {
            Some(m0) if materials.iter().all(|m| m.shininess == m0.shininess) => {
                Some(lanes::spec_pow_of(V::splat(m0.shininess)))
            }
            _ => None,
        };
        Some(Perspective {
            view,
            lighting,
            materials,
            rows,
            pow,
            evex: false,
            _lanes: PhantomData,
        })
    }
}

/// Draw the binned records with the perspective kernel on the best available backend (or the
/// baseline when asked).
#[allow(clippy::too_many_arguments)] // the frame's inputs, passed through once per frame
pub(crate) fn draw_perspective(
    bins: &Bins,
    view: &View,
    lighting: Lighting,
    materials: &[Material],
    rows: &mut Vec<MaterialRow>,
    background: [u8; 4],
    frame: &mut Frame,
    backend: Backend,
) {
    #[cfg(target_arch = "x86_64")]
    if backend != Backend::Baseline
        && let Some(mut k) = Perspective::<F32x8Avx2>::new(*view, lighting, materials, rows)
    {
        k.evex = backend == Backend::Best && evex_available();
        pipeline::draw_tiles(bins, view, &k, background, frame);
        return;
    }
    let k = Perspective::<F32x8>::new(*view, lighting, materials, rows)
        .expect("the baseline lanes are always available");
    pipeline::draw_tiles(bins, view, &k, background, frame);
}

/// Per-tile ray tables: `d = (dx[i], dy[j], −1)` and `1/|d|²` per pixel.
struct RayTable {
    dx: [f32; TILE as usize + LANES],
    dy: [f32; TILE as usize],
    inv_a: [f32; TILE_BUF],
}

impl RayTable {
    #[inline(always)]
    fn new<V: Lanes8>(v: &View, tile: TileRect) -> RayTable {
        let dx: [f32; TILE as usize + LANES] =
            std::array::from_fn(|i| ((tile.x0 + i as u32) as f32 + 0.5 - v.cx) * v.inv_k);
        let dy: [f32; TILE as usize] =
            std::array::from_fn(|j| (v.cy - ((tile.y0 + j as u32) as f32 + 0.5)) * v.inv_k);
        // 1/|d|² per pixel, 8 lanes at a time (the slack past the last row repeats it). Every
        // lane is written, so the table is not cleared first (a 4 KB memset per tile, ~5% of an
        // S1 frame's instructions).
        let one = V::splat(1.0);
        let mut inv_a = std::mem::MaybeUninit::<[f32; TILE_BUF]>::uninit();
        let ptr = inv_a.as_mut_ptr() as *mut f32;
        for p in 0..TILE_BUF / LANES {
            let j = (p * LANES / TILE as usize).min(TILE as usize - 1);
            let i = p * LANES % TILE as usize;
            let (x, y) = (V::load_from(&dx[i..]), V::splat(dy[j]));
            let mut out = [0f32; LANES];
            (one / (x * x + y * y + one)).store_to(&mut out);
            // SAFETY: `p·LANES + LANES ≤ TILE_BUF` (TILE_BUF is a multiple of LANES, asserted
            // below), so the 8 writes stay inside the table.
            unsafe { std::ptr::copy_nonoverlapping(out.as_ptr(), ptr.add(p * LANES), LANES) };
        }
        const { assert!(TILE_BUF.is_multiple_of(LANES)) };
        // SAFETY: the loop above wrote all TILE_BUF values.
        let inv_a = unsafe { inv_a.assume_init() };
        RayTable { dx, dy, inv_a }
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
fn hit8<V: Lanes8>(f: &[f32; 5], dx: V, dy: V, ia: V, near: V, far: V) -> (V, V::Mask) {
    let (cx, cy, cz, r2) = (
        V::splat(f[0]),
        V::splat(f[1]),
        V::splat(f[2]),
        V::splat(f[3]),
    );
    // Compute the closest point and the stable discriminant.
    let s = (dx * cx + dy * cy - cz) * ia;
    let vx = cx - dx * s;
    let vy = cy - dy * s;
    let vz = cz + s;
    let h2 = r2 - (vx * vx + vy * vy + vz * vz);
    let zero = V::splat(0.0);
    let hc = (h2.max(zero) * ia).sqrt();
    let tn = s - hc;
    let tf = s + hc;
    // Clip at the near plane: the near hit if in range, else the far (interior) one.
    let inside = tn.lt(near);
    let th = V::select(inside, tf, tn);
    let ok = h2.ge(zero).and(th.ge(near)).and(th.le(far));
    (V::select(ok, th, V::splat(f32::INFINITY)), inside)
}

/// Strict depth test of 8 lanes against `depth`/`win`: of records at exactly the same depth
/// the one visited first wins (see [`front_to_back`]).
#[inline(always)]
fn depth_test8<V: Lanes8>(t: V, inside: V::Mask, idx: u32, depth: &mut [f32], win: &mut [u32]) {
    let d = V::load_from(depth);
    let closer = t.lt(d);
    if closer.bits() == 0 {
        return;
    }
    V::select(closer, t, d).store_to(depth);
    let w = V::select(inside, V::splat_bits(idx | FLAG_INSIDE), V::splat_bits(idx));
    V::select(closer, w, V::load_bits(win)).store_bits(win);
}

/// Front-to-back order of a tile's records for [`Kernel::order`]: by the nearest depth the
/// sphere can reach, then bin order. With the nearest sphere usually written first, the ones
/// behind it fail the depth pass's hierarchical-z test before any ray test. Longer bins (tiny
/// spheres, little overdraw: S3's) keep bin order.
///
/// Ties: the depth test is strict, so of two spheres hit at exactly the same depth the one
/// visited first wins — the one whose nearest point is nearer, or, for coincident spheres,
/// the one earlier in the scene (as in bin order). A rule that kept bin order's winners for
/// every exact tie (checked per 8 lanes, a scalar fix-up out of line) was measured: its extra
/// compares and live registers cost more in the depth pass than the reordering saved.
fn front_to_back<'r>(v: &View, recs: &'r [Proj], scratch: &'r mut [Proj; ORDER_MAX]) -> &'r [Proj] {
    let n = recs.len();
    if !(2..=ORDER_MAX).contains(&n) {
        return recs;
    }
    let mut keys = [0u64; ORDER_MAX];
    for (i, (key, p)) in keys.iter_mut().zip(recs).enumerate() {
        // `front` ≥ near > 0, so its bits order as the numbers do.
        *key = (front(p, v.near).to_bits() as u64) << 32 | i as u64;
    }
    keys[..n].sort_unstable();
    for (out, &key) in scratch.iter_mut().zip(&keys[..n]) {
        let i = key as u32 as usize;
        *out = recs[i];
    }
    &scratch[..n]
}

/// Nearest depth a record's sphere can reach, widened by 1e-5 relative against rounding in
/// `hit8` and clamped to the near plane.
#[inline(always)]
fn front(p: &Proj, near: f32) -> f32 {
    let z_front = -p.f[2] - p.f[3].sqrt();
    (z_front - 1e-5 * z_front.abs()).max(near)
}

/// Depth pass of the perspective kernel (see [`Kernel::raster`]).
#[inline(always)]
fn raster_persp<V: Lanes8>(v: &View, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
    let rt = RayTable::new::<V>(v, tile);
    let (near, far) = (V::splat(v.near), V::splat(v.far));
    let inf = V::splat(f32::INFINITY);
    const T: usize = TILE as usize;
    for (idx, p) in recs.iter().enumerate() {
        let Some((x0, y0, x1, y1)) = clip(p, tile) else {
            continue;
        };
        let (x0, y0, x1, y1) = (x0 as usize, y0 as usize, x1 as usize, y1 as usize);
        let idx = idx as u32;
        // Chunks whose 8 stored depths are all nearer than the sphere can reach are skipped, a
        // cheap hierarchical-z test.
        let zmin = V::splat(front(p, v.near));
        if x1 - x0 <= 4 {
            // Narrow boxes (small spheres): two rows of up to 4 pixels per 8-lane test.
            let cols = V::Mask::first_of_halves(x1 - x0);
            let dx4 = &rt.dx[x0..];
            let mut j = y0;
            while j < y1 {
                let two = j + 1 < y1;
                let j1 = if two { j + 1 } else { j };
                let (b0, b1) = (j * T + x0, j1 * T + x0);
                let d = V::load_halves(&buf.depth[b0..], &buf.depth[b1..]);
                let lanes = if two {
                    cols
                } else {
                    cols.and(V::Mask::first(4))
                };
                if zmin.lt(d).and(lanes).bits() != 0 {
                    let dx = V::load_halves(dx4, dx4);
                    let dy = V::load_halves(&[rt.dy[j]; 4], &[rt.dy[j1]; 4]);
                    let ia = V::load_halves(&rt.inv_a[b0..], &rt.inv_a[b1..]);
                    let (t, inside) = hit8(&p.f, dx, dy, ia, near, far);
                    let t = V::select(lanes, t, inf);
                    let closer = t.lt(d);
                    if closer.bits() != 0 {
                        let nd = V::select(closer, t, d);
                        let w =
                            V::select(inside, V::splat_bits(idx | FLAG_INSIDE), V::splat_bits(idx));
                        let mut wins = [0u32; LANES];
                        wins[..4].copy_from_slice(&buf.win[b0..b0 + 4]);
                        wins[4..].copy_from_slice(&buf.win[b1..b1 + 4]);
                        let nw = V::select(closer, w, V::load_bits(&wins));
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
            let dy = V::splat(rt.dy[j]);
            let mut i = x0;
            while i < x1 {
                let b = row + i;
                // Lanes past the box must not write.
                let lanes = V::Mask::first(x1 - i);
                let d = V::load_from(&buf.depth[b..]);
                if zmin.lt(d).and(lanes).bits() != 0 {
                    let (t, inside) = hit8(
                        &p.f,
                        V::load_from(&rt.dx[i..]),
                        dy,
                        V::load_from(&rt.inv_a[b..]),
                        near,
                        far,
                    );
                    let t = V::select(lanes, t, inf);
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

/// Resolve pass of the perspective kernel (see [`Kernel::resolve_tile`]): 8-pixel row chunks;
/// a chunk with no covered pixel is background; otherwise the winners' records and materials
/// are loaded as whole rows and transposed to lanes (uncovered lanes repeat the first covered
/// pixel's winner and are replaced by the background at the end), shaded and encoded.
#[inline(always)]
fn resolve_persp<V: Lanes8>(
    k: &Perspective<V>,
    recs: &[Proj],
    tile: TileRect,
    buf: &TileBuf,
    background: [u8; 4],
    color: &mut [[u8; 4]],
    stride: usize,
) {
    // One build per light count (0 to MAX_LIGHTS): the light loops unroll and the lights'
    // constants stay in registers across the tile.
    const { assert!(texmap_core::shade::MAX_LIGHTS == 4) };
    // Direct calls (not a function pointer): each build inlines into the caller's
    // `#[target_feature]` function, whose intrinsics it needs inlined.
    let a = (k, recs, tile, buf, background, color, stride);
    match k.lighting.lights().len() {
        0 => resolve_persp_n::<V, 0>(a.0, a.1, a.2, a.3, a.4, a.5, a.6),
        1 => resolve_persp_n::<V, 1>(a.0, a.1, a.2, a.3, a.4, a.5, a.6),
        2 => resolve_persp_n::<V, 2>(a.0, a.1, a.2, a.3, a.4, a.5, a.6),
        3 => resolve_persp_n::<V, 3>(a.0, a.1, a.2, a.3, a.4, a.5, a.6),
        _ => resolve_persp_n::<V, 4>(a.0, a.1, a.2, a.3, a.4, a.5, a.6),
    }
}

/// [`resolve_persp`] for a lighting of `N` lights.
///
/// When the frame has one specular power (`k.pow`), two neighbouring covered chunks of a row
/// are shaded together ([`lanes::shade::shade_chunks`]): a chunk's shading is one long chain of
/// dependent square roots, divisions and squarings, and two independent chains in one
/// straight-line body keep the CPU busy where one left it waiting. Every lane sees the same
/// operations either way, so the bytes do not change.
#[inline(always)]
fn resolve_persp_n<V: Lanes8, const N: usize>(
    k: &Perspective<V>,
    recs: &[Proj],
    tile: TileRect,
    buf: &TileBuf,
    background: [u8; 4],
    color: &mut [[u8; 4]],
    stride: usize,
) {
    let v = &k.view;
    // Ray directions of the tile's columns (plus lane slack) and rows (pixel centres).
    let mut dxs = [0f32; TILE as usize + LANES];
    for (i, dx) in dxs.iter_mut().enumerate() {
        *dx = ((tile.x0 as usize + i) as f32 + 0.5 - v.cx) * v.inv_k;
    }
    let enc = lanes::srgb_table32();
    let lights = lanes::shade::LanesLighting::<V, N>::new(&k.lighting);
    let bgv = V::splat_bits(u32::from_le_bytes(background));
    let none = V::splat_bits(NONE);
    let tw = tile.w as usize;
    for j in 0..tile.h as usize {
        let dy = V::splat((v.cy - ((tile.y0 as usize + j) as f32 + 0.5)) * v.inv_k);
        let out = &mut color[j * stride..j * stride + tw];
        let mut i = 0;
        while i < tw {
            let n = (tw - i).min(LANES);
            let b = j * TILE as usize + i;
            let win = V::load_bits(&buf.win[b..]);
            let covered = covered_lanes(win, none, n);
            if covered == 0 {
                pipeline::fill8(&mut out[i..i + n], background);
                i += LANES;
                continue;
            }
            let s = chunk_surface(k, recs, buf, b, covered, win, V::load_from(&dxs[i..]), dy);
            // With one specular power per frame, the next chunk (if covered) is shaded with
            // this one.
            let i2 = i + LANES;
            // (A plain condition, not `Option::filter`: closures do not inherit the caller's
            // `#[target_feature]`s.)
            if i2 < tw
                && let Some(pw) = k.pow
            {
                let (n2, b2) = ((tw - i2).min(LANES), b + LANES);
                let win2 = V::load_bits(&buf.win[b2..]);
                let covered2 = covered_lanes(win2, none, n2);
                if covered2 != 0 {
                    let dx2 = V::load_from(&dxs[i2..]);
                    let s2 = chunk_surface(k, recs, buf, b2, covered2, win2, dx2, dy);
                    let [c, c2] = lanes::shade::shade_chunks(&lights, [s, s2], pw);
                    store_chunk(c, win, none, bgv, enc, &mut out[i..], n);
                    store_chunk(c2, win2, none, bgv, enc, &mut out[i2..], n2);
                    i += 2 * LANES;
                    continue;
                }
            }
            let pw = match k.pow {
                Some(p) => p,
                None => lanes::spec_pow_of(s.shin),
            };
            let [c] = lanes::shade::shade_chunks(&lights, [s], pw);
            store_chunk(c, win, none, bgv, enc, &mut out[i..], n);
            i += LANES;
        }
    }
}

/// Covered lanes of a chunk of `n ≤ 8` pixels whose winner entries are `win` (lanes past the
/// tile hold NONE too).
#[inline(always)]
fn covered_lanes<V: Lanes8>(win: V, none: V, n: usize) -> u32 {
    !win.eq_bits(none).bits() & ((1u32 << n) - 1)
}

/// sRGB8 of a shaded chunk `c`, the background `bgv` where nothing won, into `out[..n]`.
#[inline(always)]
fn store_chunk<V: Lanes8>(
    c: [V; 3],
    win: V,
    none: V,
    bgv: V,
    enc: &[u32; lanes::SRGB_N],
    out: &mut [[u8; 4]],
    n: usize,
) {
    let px = V::select(
        win.eq_bits(none),
        bgv,
        lanes::srgb_rgba_lanes(c[0], c[1], c[2], enc),
    );
    if n == LANES {
        px.store_rgba(out);
    } else {
        let mut tmp = [[0u8; 4]; LANES];
        px.store_rgba(&mut tmp);
        out[..n].copy_from_slice(&tmp[..n]);
    }
}

/// The shading inputs of the covered chunk at `b` of a tile (`covered` its covered lanes, `win`
/// its winner entries, `dx`/`dy` its rays): the winners' records and materials as lanes
/// (uncovered lanes take the first covered pixel's winner; the caller replaces them by the
/// background), the exact normal at the hit point and the unit vector toward the eye.
#[allow(clippy::too_many_arguments)] // one chunk's inputs, inlined into the resolve loop
#[inline(always)]
fn chunk_surface<V: Lanes8>(
    k: &Perspective<V>,
    recs: &[Proj],
    buf: &TileBuf,
    b: usize,
    covered: u32,
    win: V,
    dx: V,
    dy: V,
) -> lanes::shade::LaneSurf<V> {
    let sign = V::splat_bits(FLAG_INSIDE);
    let one = V::splat(1.0);
    let first = buf.win[b + covered.trailing_zeros() as usize] & !FLAG_INSIDE;
    let idx = win.and_bits(V::splat_bits(!FLAG_INSIDE));
    let on_first = idx.eq_bits(V::splat_bits(first));
    let rest = covered & !on_first.bits();
    let second = buf.win[b + (rest.trailing_zeros() as usize).min(LANES - 1)] & !FLAG_INSIDE;
    let on_second = idx.eq_bits(V::splat_bits(second));
    let ([cx, cy, cz, _, inv_r, _, _, _], [br, bg, bb, spec, shin, _, _, _]) = if rest == 0 {
        // One sphere under all covered pixels (most chunks of a scene of large spheres): its
        // record and material as constants.
        let rec = &recs[first as usize];
        let row = &k.rows[rec.kind as usize];
        (rec.as_lanes().map(V::splat), row.map(V::splat))
    } else if rest & !on_second.bits() == 0 {
        // Two spheres (a silhouette crosses the chunk): both as constants, one select per
        // field.
        let (r0, r1) = (&recs[first as usize], &recs[second as usize]);
        let (m0, m1) = (&k.rows[r0.kind as usize], &k.rows[r1.kind as usize]);
        let pick = |a: &[f32; 8], b: &[f32; 8]| -> [V; 8] {
            std::array::from_fn(|f| V::select(on_second, V::splat(b[f]), V::splat(a[f])))
        };
        (pick(r0.as_lanes(), r1.as_lanes()), pick(m0, m1))
    } else {
        // Gather the rows and transpose them to lanes.
        let mut rec_rows = [recs[0].as_lanes(); LANES];
        let mut mat_rows = [&k.rows[0]; LANES];
        for l in 0..LANES {
            let wv = buf.win[b + l];
            let ri = (if wv == NONE { first } else { wv & !FLAG_INSIDE }) as usize;
            debug_assert!(ri < recs.len());
            // SAFETY: winner entries other than NONE are indices into this tile's `recs`
            // (written by the depth pass), and `first` is one of them.
            let rec = unsafe { recs.get_unchecked(ri) };
            debug_assert!((rec.kind as usize) < k.rows.len());
            rec_rows[l] = rec.as_lanes();
            // SAFETY: only valid spheres are projected, and a valid sphere's kind indexes
            // `materials`, whose rows these are.
            mat_rows[l] = unsafe { k.rows.get_unchecked(rec.kind as usize) };
        }
        (V::transpose(rec_rows), V::transpose(mat_rows))
    };
    let t = V::load_from(&buf.depth[b..]);
    // Exact normal at the hit point; flipped toward the viewer on the interior (the inside
    // flag is the sign bit of the winner entry: it flips the sign of 1/r).
    let s = inv_r.xor_bits(win.and_bits(sign));
    let n = [
        (dx * t - cx) * s,
        (dy * t - cy) * s,
        (t.xor_bits(sign) - cz) * s,
    ];
    // Unit vector toward the eye.
    let id = one / (dx * dx + dy * dy + one).sqrt();
    let v = [dx.xor_bits(sign) * id, dy.xor_bits(sign) * id, id];
    lanes::shade::LaneSurf {
        n,
        v,
        base: [br, bg, bb],
        spec,
        shin,
    }
}

/// Colour of one pixel (the per-pixel [`Kernel::resolve`]).
#[allow(clippy::too_many_arguments)] // the kernel's fields and the pixel, shared by two impls
fn resolve_px<V>(
    k: &Perspective<V>,
    rec: &Proj,
    x: u32,
    y: u32,
    depth: f32,
    flags: u32,
) -> [u8; 4] {
    let (v, lighting, materials) = (&k.view, &k.lighting, k.materials);
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
    let m = &materials[rec.kind as usize];
    linear_to_srgb8(lanes::shade::shade(lighting, m, n, to_eye), 255)
}

impl Kernel for Perspective<'_, F32x8> {
    #[inline(never)]
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        raster_persp::<F32x8>(&self.view, recs, tile, buf);
    }

    fn order<'r>(&self, recs: &'r [Proj], scratch: &'r mut [Proj; ORDER_MAX]) -> &'r [Proj] {
        front_to_back(&self.view, recs, scratch)
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, depth: f32, flags: u32) -> [u8; 4] {
        resolve_px(self, rec, x, y, depth, flags)
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
        resolve_persp(self, recs, tile, buf, background, color, stride);
    }
}

#[cfg(target_arch = "x86_64")]
impl Kernel for Perspective<'_, F32x8Avx2> {
    fn order<'r>(&self, recs: &'r [Proj], scratch: &'r mut [Proj; ORDER_MAX]) -> &'r [Proj] {
        front_to_back(&self.view, recs, scratch)
    }

    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        // SAFETY: a `Perspective<F32x8Avx2>` exists only when `F32x8Avx2::available()` (AVX2)
        // held, and `evex` is set only when `evex_available()` held.
        unsafe {
            if self.evex {
                raster_evex(&self.view, recs, tile, buf)
            } else {
                raster_avx2(&self.view, recs, tile, buf)
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, depth: f32, flags: u32) -> [u8; 4] {
        resolve_px(self, rec, x, y, depth, flags)
    }

    fn resolve_tile(
        &self,
        recs: &[Proj],
        tile: TileRect,
        buf: &TileBuf,
        background: [u8; 4],
        color: &mut [[u8; 4]],
        stride: usize,
    ) {
        // SAFETY: as in `raster`.
        unsafe {
            if self.evex {
                resolve_tile_evex(self, recs, tile, buf, background, color, stride)
            } else {
                resolve_tile_avx2(self, recs, tile, buf, background, color, stride)
            }
        }
    }

    fn draw_tile(&self, job: TileJob<'_>) {
        // SAFETY: as in `raster`.
        unsafe {
            if self.evex {
                draw_tile_evex(self, job)
            } else {
                draw_tile_avx2(self, job)
            }
        }
    }
}

/// The [`F32x8Avx2`] builds of the perspective kernel: [`raster_persp`], [`resolve_persp`] and the
/// tile's body ([`pipeline::draw_tile`]: its buffer clears and depth copies) compiled inside
/// `#[target_feature]` functions (the generic bodies and the intrinsics inline there), one set
/// per feature set.
macro_rules! avx2_lanes_build {
    ($features:literal, $raster:ident, $resolve:ident, $tile:ident, $doc:literal) => {
        #[doc = concat!("[`pipeline::draw_tile`] of the [`F32x8Avx2`] kernel, compiled for ", $doc, ".")]
        ///
        /// # Safety
        #[doc = concat!("The CPU must support ", $doc, ".")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        unsafe fn $tile(k: &Perspective<F32x8Avx2>, job: TileJob<'_>) {
            pipeline::draw_tile(k, job);
        }

        #[doc = concat!("[`raster_persp`] on the [`F32x8Avx2`] lanes, compiled for ", $doc, ".")]
        ///
        /// # Safety
        #[doc = concat!("The CPU must support ", $doc, ".")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        #[inline(never)]
        unsafe fn $raster(v: &View, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
            raster_persp::<F32x8Avx2>(v, recs, tile, buf);
        }

        #[doc = concat!("[`resolve_persp`] on the [`F32x8Avx2`] lanes, compiled for ", $doc, ".")]
        ///
        /// # Safety
        #[doc = concat!("The CPU must support ", $doc, ".")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        #[inline(never)]
        unsafe fn $resolve(
            k: &Perspective<F32x8Avx2>,
            recs: &[Proj],
            tile: TileRect,
            buf: &TileBuf,
            background: [u8; 4],
            color: &mut [[u8; 4]],
            stride: usize,
        ) {
            resolve_persp(k, recs, tile, buf, background, color, stride);
        }
    };
}

avx2_lanes_build!(
    "avx2",
    raster_avx2,
    resolve_tile_avx2,
    draw_tile_avx2,
    "AVX2"
);
// The same 256-bit lanes with AVX-512VL enabled as well: the compiler then has 32 vector
// registers instead of 16 (fewer spills in the long shading expressions) and mask registers
// for comparisons and selects (one-µop masked blends instead of `vblendvps`). The IEEE
// operations are the same (no fused multiply-add: Rust never contracts), so are the bytes
// (tested against the AVX2 build and the baseline).
avx2_lanes_build!(
    "avx2,avx512f,avx512vl",
    raster_evex,
    resolve_tile_evex,
    draw_tile_evex,
    "AVX2, AVX-512F and AVX-512VL"
);

/// Whether this CPU can run the AVX-512VL builds ([`raster_evex`], [`resolve_tile_evex`]).
#[cfg(target_arch = "x86_64")]
fn evex_available() -> bool {
    lanes::Isa::Avx512.enabled()
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
        linear_to_srgb8(lanes::shade::shade(&self.lighting, m, n, Vec3::Z), 255)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Method, Options, Renderer, SphereScene};
    use texmap_core::camera::Camera;

    /// A scene that reaches every branch of the kernels: random radii from sub-pixel to
    /// screen-filling, spheres cut by the near plane and one around the eye, materials with
    /// mixed integer and non-integer shininess (both specular powers), an image whose size is
    /// not a multiple of the tile.
    fn busy_scene(mixed_shininess: bool) -> (SphereScene, Camera) {
        let mut mats = vec![
            Material::plastic(Vec3::new(0.8, 0.2, 0.1)),
            Material::plastic(Vec3::new(0.1, 0.7, 0.3)),
            Material::matte(Vec3::new(0.3, 0.3, 0.9)),
        ];
        if mixed_shininess {
            mats[1].shininess = 7.5;
            mats[2].shininess = 3.0;
        }
        let mut scene = SphereScene::new(mats);
        let mut st = 99u32;
        let mut r = || {
            st = st.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (st >> 8) as f32 / (1u32 << 24) as f32
        };
        for i in 0..3000 {
            let c = Vec3::new(r() * 40.0 - 20.0, r() * 30.0 - 15.0, r() * 40.0 - 30.0);
            let rad = 0.02 + r() * r() * 3.0;
            scene.push(c, rad, (i % 3) as u16);
        }
        // Around the eye and cut by the near plane.
        scene.push(Vec3::new(0.0, 0.0, 14.0), 2.0, 0);
        scene.push(Vec3::new(1.0, 0.5, 11.9), 0.5, 1);
        let cam = Camera::perspective_look_at(
            Vec3::new(0.0, 0.0, 14.5),
            Vec3::ZERO,
            Vec3::Y,
            70.0,
            203,
            157,
        )
        .unwrap();
        (scene, cam)
    }

    #[test]
    fn avx2_and_baseline_lanes_give_the_same_bytes() {
        for mixed in [false, true] {
            let (scene, cam) = busy_scene(mixed);
            let opts = Options::new(
                Method::Raycast,
                texmap_core::shade::Lighting::default_for(&cam),
            );
            let mut base = Renderer::new();
            base.backend = Backend::Baseline;
            let b = base.render(&scene, &cam, &opts);
            // The best build (AVX-512VL where the CPU has it) and the AVX2-only build.
            for backend in [Backend::Best, Backend::Avx2] {
                let mut r = Renderer::new();
                r.backend = backend;
                let a = r.render(&scene, &cam, &opts);
                assert_eq!(a.stats, b.stats);
                let covered = a.frame.coverage_count();
                assert!(covered > 10_000, "covered {covered}");
                let diff_c = a
                    .frame
                    .color
                    .iter()
                    .zip(&b.frame.color)
                    .filter(|(x, y)| x != y)
                    .count();
                let diff_d = (a.frame.depth.iter().zip(&b.frame.depth))
                    .filter(|(x, y)| x.to_bits() != y.to_bits())
                    .count();
                assert_eq!(
                    (diff_c, diff_d),
                    (0, 0),
                    "pixels differing (colour, depth), {backend:?}, mixed {mixed}"
                );
            }
        }
    }

    #[test]
    fn lane_resolve_matches_the_per_pixel_resolve() {
        // The tile resolve on lanes and the per-pixel `Kernel::resolve` (scalar formula, libm
        // sqrt and texmap-core's encoder) agree to one 8-bit step, for one to four lights (the
        // lanes take the lights in pairs, an odd one alone).
        let dirs = [
            (Vec3::new(-0.4, 0.55, 1.0), Vec3::splat(0.6)),
            (Vec3::new(0.6, -0.2, 0.8), Vec3::new(0.2, 0.25, 0.3)),
            (Vec3::new(0.1, 0.9, -0.3), Vec3::new(0.3, 0.1, 0.05)),
            (Vec3::new(-0.7, -0.6, 0.4), Vec3::splat(0.15)),
        ];
        for mixed in [true, false] {
            let (scene, cam) = busy_scene(mixed);
            for n in 1..=dirs.len() {
                let lights: Vec<_> = dirs[..n]
                    .iter()
                    .map(|&(d, c)| (cam.dir_to_world(d.normalize()), c))
                    .collect();
                let lighting =
                    texmap_core::shade::Lighting::new(Vec3::splat(0.1), &lights).unwrap();
                check_lane_resolve(&scene, &cam, lighting, n);
            }
        }
    }

    /// The body of [`lane_resolve_matches_the_per_pixel_resolve`] for one lighting.
    fn check_lane_resolve(
        scene: &SphereScene,
        cam: &Camera,
        lighting: texmap_core::shade::Lighting,
        n_lights: usize,
    ) {
        let view = View::new(cam);
        let lighting = lighting.to_eye(cam);
        let mut bins = Bins::default();
        bins.build(scene, &view, |c, r, k| project(&view, c, r, k));
        let mut rows = Vec::new();
        let k = Perspective::<F32x8>::new(view, lighting, &scene.materials, &mut rows).unwrap();
        let mut worst = 0i32;
        let mut checked = 0;
        for ty in 0..view.tiles_y {
            for tx in 0..view.tiles_x {
                let t = (ty * view.tiles_x + tx) as usize;
                let recs = bins.tile(t);
                if recs.is_empty() {
                    continue;
                }
                let tile = TileRect {
                    x0: tx * TILE,
                    y0: ty * TILE,
                    w: (view.width - tx * TILE).min(TILE),
                    h: (view.height - ty * TILE).min(TILE),
                };
                let mut buf = TileBuf {
                    depth: [f32::INFINITY; TILE_BUF],
                    win: [NONE; TILE_BUF],
                };
                k.raster(recs, tile, &mut buf);
                let mut color = vec![[0u8; 4]; crate::pipeline::TILE_PX];
                k.resolve_tile(recs, tile, &buf, [1, 2, 3, 4], &mut color, TILE as usize);
                for j in 0..tile.h {
                    for i in 0..tile.w {
                        let b = (j * TILE + i) as usize;
                        let got = color[b];
                        let wv = buf.win[b];
                        if wv == NONE {
                            assert_eq!(got, [1, 2, 3, 4]);
                            continue;
                        }
                        let rec = &recs[(wv & !FLAG_INSIDE) as usize];
                        let want = k.resolve(
                            rec,
                            tile.x0 + i,
                            tile.y0 + j,
                            buf.depth[b],
                            wv & FLAG_INSIDE,
                        );
                        for c in 0..4 {
                            worst = worst.max((got[c] as i32 - want[c] as i32).abs());
                        }
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 10_000, "checked {checked}");
        assert!(
            worst <= 1,
            "{n_lights} lights: largest difference expected ≤ 1 step, got {worst}"
        );
    }
}

//! Bonds drawn as exact ray-cast cylinder impostors, after the sphere pass of every method.
//!
//! Molecules are drawn with their bonds; Seed 002 ends with "the same idea extends to pipes
//! (cylinders, i.e. bonds)". This pass draws every
//! [`SphereScene::bonds`] pair as a cylinder of radius [`SphereScene::bond_radius`] from one atom
//! centre to the other, **half-bond coloured** (the half nearer atom `i` in atom `i`'s material,
//! as VMD and OVITO do), lit with the workspace's one shading model in eye space.
//!
//! 1. **Project** (parallel over fixed chunks of [`BOND_CHUNK`] bonds): validate the bond (both
//!    indices in range, both atoms drawable, distinct centres, a finite positive radius), move the
//!    end points to eye space, clip the axis to depths `≥ near − r` (whatever lies nearer cannot
//!    produce a fragment at depth ≥ near), cull against the far plane, and bound the screen
//!    rectangle of the capped cylinder by the union of the rectangles of the two spheres of radius
//!    `r` around the clipped end points: the capped cylinder lies in the convex hull of those two
//!    spheres, and a perspective projection maps that hull onto the hull of their images (the
//!    eight tangent slopes of both spheres on one set of 8 lanes). A 96-byte [`BondRec`] holds
//!    the per-bond constants of the intersection below, formed in f64 and rounded once.
//! 2. **Bin** into the sphere pipeline's 32x32 tiles: count, prefix sum, fill (a copy of the
//!    record per tile, bond order kept within every tile).
//! 3. **Tiles** (parallel over bands of 32 rows): the tile's depth buffer starts as the depth the
//!    sphere pass wrote, so bonds and atoms interpenetrate correctly; every bond of the bin is
//!    intersected with the tile's eye rays 8 pixels at a time (one row, or two rows of 4 for
//!    boxes at most 4 px wide; rows of boxes wider than 16 px narrowed to the hull of the end
//!    rectangles) under a strict depth test (an atom wins a tie, then the earlier bond). A
//!    **hierarchical-z** test skips the 8 pixels when the stored depths are all nearer than the
//!    bond's nearest point (most bond pixels of a ball-and-stick image lie behind atoms). The
//!    lanes are SSE2 or, where the CPU has it, AVX2 (chosen once per frame; the same IEEE
//!    operations, so the same bits). Then each pixel won by a bond is shaded once (8 lanes,
//!    sRGB encoded over lanes) and written.
//!
//! # The intersection
//! A bond is the solid capped cylinder `{p : 0 ≤ h(p) ≤ L, |p − a − h(p)·u| ≤ r}` with
//! `h(p) = (p − a)·u`. A ray `o + t·d` (eye space; `d = (x/k, y/k, −1)` from the eye for a
//! perspective camera, `d = (0, 0, −1)` from the pixel's point on the eye plane for an orthographic
//! one, so that `t` is the depth in both) is inside it on the intersection of two intervals:
//! - the **infinite cylinder**: with `g = o − a`, `A = |d × u|²` and the ray–axis line distance
//!   `D = g·(d × u) / √A`, the ray is inside for `t ∈ s ∓ √(r²A − (g·(d × u))²) / A` around the
//!   closest approach `s`. The discriminant is written with `g·(d × u)` (for the perspective
//!   camera `−d·(u × a)`, a per-bond constant vector dotted with `d`) rather than `B² − AC`, which
//!   would cancel two numbers of size `|a|²` down to one of size `r²` (pbrt's robust sphere
//!   discriminant, carried to the cylinder). When the ray is parallel to the axis (`A ≤ 1e-12`)
//!   the interval is all or nothing by the ray's distance from the axis.
//! - the **slab** `0 ≤ h(o) + t·(d·u) ≤ L` between the two cap planes.
//!
//! Entering the solid at `max` of the lower ends hits the side or a flat cap: the exact capped
//! cylinder of the reference ray tracer, so bonds as thick as (or thicker than) an atom show flat
//! caps, and with thinner bonds the caps are hidden inside the atoms at no extra cost. **Near
//! plane** as the sphere ray caster: a fragment nearer than the near plane is clipped and the ray
//! takes the exit point instead (the inside of a cut bond), lit with the normal turned toward the
//! viewer, as the reference's two-sided surfaces.
//!
//! **Determinism:** chunk boundaries are fixed, bins keep bond order, the depth test is strict and
//! each tile writes only its own pixels, so the same input gives the same bytes for any number of
//! threads.
//!
//! # References
//! - Seed 002 (closing remark: pipes by the same method). We depart from its lookup tables: a
//!   cylinder seen at an angle has no single precomputable image, and the exact intersection costs
//!   a handful of multiplies per fragment.
//! - M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering* (4th ed.), §6.2 (cylinders)
//!   and §6.8 (robust quadric discriminants).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use texmap_core::frame::Frame;
use texmap_core::shade::{Lighting, Material};

#[cfg(target_arch = "x86_64")]
use crate::fastshade::V8x;
use crate::fastshade::{self, Mask8, Simd8, SpecPow, V8, W};
use crate::pipeline::{self, FLAG_INSIDE, LANES, NONE, TILE, TILE_BUF, TILE_PX, View};
use crate::scene::SphereScene;

/// Bonds per projection chunk: fixed, so results do not depend on the thread count.
pub(crate) const BOND_CHUNK: usize = 8192;
/// Flag bit in a winner entry: the hit is on a flat cap (normal `±u`), not on the side.
const FLAG_CAP: u32 = 1 << 30;
/// Mask of the record index in a winner entry.
const INDEX_MASK: u32 = FLAG_CAP - 1;
/// Below this `A = |d × u|²` a ray counts as parallel to the axis.
const PARALLEL_A: f32 = 1e-12;
/// The slab divides by `d·u`; a smaller magnitude is replaced by this one (a ray that parallel
/// to the cap planes is inside the slab everywhere or nowhere, which the huge quotients keep).
const MIN_DU: f32 = 1e-30;

/// One projected bond, copied into every tile bin it touches (96 bytes).
///
/// All vectors in eye space: `a` the first end point (atom `i`), `u` the unit axis toward atom
/// `j`, `len` the axis length.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct BondRec {
    /// `u × a`: the perspective discriminant is `r²A − (d·n)²`.
    n: [f32; 3],
    /// `a − (a·u)·u`: the foot of the perpendicular from the eye to the axis line; the
    /// perspective closest approach is `s = (d·q)/A`.
    q: [f32; 3],
    u: [f32; 3],
    /// `a·u`.
    au: f32,
    len: f32,
    r2: f32,
    inv_r: f32,
    /// Pixel rectangle `[x0, x1) x [y0, y1)` whose centres the bond may cover.
    bbox: [u16; 4],
    /// The screen rectangles (pixels) of the two end spheres, `[x0, x1, y0, y1]` each: the
    /// bond's image lies in their convex hull, which narrows every row to a span
    /// ([`row_span`]). `±HUGE` bounds where a rectangle is unbounded.
    ends: [[f32; 4]; 2],
    /// Material index of the half at `a` and of the half at the other end.
    kind: [u16; 2],
}

const _: () = assert!(std::mem::size_of::<BondRec>() == 96);

/// Stand-in for an unbounded screen coordinate (finite, so that interpolation cannot give NaN).
const HUGE: f32 = 1e9;

/// The x-range (pixels) of the convex hull of two axis-aligned rectangles at height `y`, or
/// `None` when the row misses the hull.
///
/// The hull is the union over `λ ∈ [0, 1]` of the rectangles `(1 − λ)·A + λ·B`, whose bounds
/// interpolate linearly: the row meets those with `y0(λ) ≤ y ≤ y1(λ)`, an interval of `λ`, and
/// the x-range is spanned by the interpolated bounds at its two ends.
#[inline]
fn row_span(ends: &[[f32; 4]; 2], y: f32) -> Option<(f32, f32)> {
    let [a, b] = ends;
    let (mut lo, mut hi) = (0f32, 1f32);
    // y0(λ) − y ≤ e and y − y1(λ) ≤ e, each `α + β·λ ≤ 0`; `e` (a thousandth of a pixel plus
    // a relative term) keeps the bound conservative against rounding, as `View::pixel_range`.
    let e = 1e-3 + 1e-6 * y.abs();
    for (alpha, beta) in [(a[2] - y - e, b[2] - a[2]), (y - a[3] - e, a[3] - b[3])] {
        if beta > 0.0 {
            let l = -alpha / beta;
            hi = if l < hi { l } else { hi };
        } else if beta < 0.0 {
            let l = -alpha / beta;
            lo = if l > lo { l } else { lo };
        } else if alpha > 0.0 {
            return None;
        }
    }
    if !(lo <= hi) {
        return None;
    }
    let x0 = |l: f32| a[0] + (b[0] - a[0]) * l;
    let x1 = |l: f32| a[1] + (b[1] - a[1]) * l;
    let (p, q) = (x0(lo), x0(hi));
    let (r, t) = (x1(lo), x1(hi));
    Some((if p < q { p } else { q }, if r > t { r } else { t }))
}

impl BondRec {
    /// The first end point, `q + (a·u)·u`.
    #[inline]
    fn a(&self) -> Vec3 {
        Vec3::from(self.q) + Vec3::from(self.u) * self.au
    }

    /// A lower bound of the depth of every fragment of the bond: the nearer end's depth minus
    /// `r` (the capped cylinder lies in the capsule around its axis), widened by 1e-4 of itself
    /// against rounding in the per-pixel intersection.
    #[inline]
    fn zmin(&self) -> f32 {
        let za = self.q[2] + self.u[2] * self.au;
        let zb = za + self.u[2] * self.len;
        let d = (if za > zb { -za } else { -zb }) - self.r2.sqrt();
        d - 1e-4 * d.abs()
    }
}

/// What happened to the bonds of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct BondStats {
    pub drawn: usize,
    pub culled: usize,
    pub skipped: usize,
}

/// The reusable per-frame buffers of the bond pass.
#[derive(Debug, Default)]
pub(crate) struct BondBins {
    chunk_recs: Vec<Vec<BondRec>>,
    chunk_counts: Vec<Vec<u32>>,
    chunk_stats: Vec<BondStats>,
    recs: Vec<BondRec>,
    /// `tile_start[t]..tile_start[t + 1]` is tile `t`'s run in `recs`.
    tile_start: Vec<usize>,
}

/// Bounds of `x/(−z)` over the circle of radius `r` around `(x, z)` (a plane through the eye):
/// the slopes of the two tangents from the origin. `None` when the circle reaches the eye plane
/// or lies behind it (no finite bound: the caller takes the whole screen along this axis).
#[inline]
fn slope_bounds(x: f32, z: f32, r: f32) -> Option<(f32, f32)> {
    let l2 = x * x + z * z;
    let t2 = l2 - r * r;
    if !(t2 > 0.0) {
        return None;
    }
    let t = t2.sqrt();
    // Tangent directions (scaled by the centre distance): the centre direction turned by
    // ±asin(r/l), i.e. cos = t/l, sin = r/l.
    let (x0, z0) = (t * x - r * z, r * x + t * z);
    let (x1, z1) = (t * x + r * z, -r * x + t * z);
    // Both must point in front of the eye plane, with a margin against rounding.
    let margin = 1e-6 * l2;
    if !(z0 < -margin && z1 < -margin) {
        return None;
    }
    let s0 = x0 / -z0;
    let s1 = x1 / -z1;
    Some(if s0 < s1 { (s0, s1) } else { (s1, s0) })
}

/// The screen rectangle (pixels, unclamped) of a sphere of radius `r` at eye-space `c`, or
/// `None` along an axis with no finite bound.
#[inline]
fn sphere_rect(view: &View, c: Vec3, r: f32) -> [Option<(f32, f32)>; 2] {
    if view.ortho {
        return [
            Some((view.cx + (c.x - r) * view.k, view.cx + (c.x + r) * view.k)),
            Some((view.cy - (c.y + r) * view.k, view.cy - (c.y - r) * view.k)),
        ];
    }
    let x =
        slope_bounds(c.x, c.z, r).map(|(lo, hi)| (view.cx + lo * view.k, view.cx + hi * view.k));
    let y =
        slope_bounds(c.y, c.z, r).map(|(lo, hi)| (view.cy - hi * view.k, view.cy - lo * view.k));
    [x, y]
}

/// [`sphere_rect`] of two spheres of radius `r` at once for a perspective camera: the eight
/// tangent slopes of [`slope_bounds`] (2 spheres x 2 axes x 2 tangents) on the 8 lanes, with the
/// same operations in the same order, so the rectangles are bit-identical to it.
#[inline]
fn sphere_rects_persp(view: &View, a: Vec3, b: Vec3, r: f32) -> [[Option<(f32, f32)>; 2]; 2] {
    // Lane k: sphere k / 4, axis (k / 2) % 2 (x, then y), tangent k % 2 (turned by ±asin(r/l)).
    let x = V8::load(&[a.x, a.x, a.y, a.y, b.x, b.x, b.y, b.y]);
    let z = V8::load(&[a.z, a.z, a.z, a.z, b.z, b.z, b.z, b.z]);
    let rs = V8::load(&[r, -r, r, -r, r, -r, r, -r]);
    let zero = V8::splat(0.0);
    let l2 = x * x + z * z;
    let t2 = l2 - V8::splat(r * r);
    let t = t2.max(zero).sqrt();
    // Tangent directions (scaled by the centre distance): cos = t/l, sin = ±r/l.
    let xt = t * x - rs * z;
    let zt = rs * x + t * z;
    // Both tangents of a pair must point in front of the eye plane, with a margin against
    // rounding; then the slopes x/(−z) map to pixels (x: cx + s·k, y: cy − s·k).
    let ok = t2.gt(zero).and(zt.lt(zero - V8::splat(1e-6) * l2)).bits();
    let s = xt / (zero - zt);
    let (k, cx, cy) = (view.k, view.cx, view.cy);
    let px = (V8::load(&[cx, cx, cy, cy, cx, cx, cy, cy])
        + s * V8::load(&[k, k, -k, -k, k, k, -k, -k]))
    .store();
    let pair = |i: usize| -> Option<(f32, f32)> {
        if ok >> i & 3 != 3 {
            return None;
        }
        let (p, q) = (px[i], px[i + 1]);
        Some(if p < q { (p, q) } else { (q, p) })
    };
    [[pair(0), pair(2)], [pair(4), pair(6)]]
}

/// A world point in eye space, in f64: the per-bond constants below are differences and cross
/// products of nearly parallel vectors when a bond is seen end-on, so they are formed in f64 and
/// rounded once (per bond, not per pixel).
#[inline]
fn eye_space_f64(view: &View, p: Vec3) -> DVec3 {
    let d = p.as_dvec3() - view.eye.as_dvec3();
    DVec3::new(
        d.dot(view.right.as_dvec3()),
        d.dot(view.up.as_dvec3()),
        d.dot(view.back.as_dvec3()),
    )
}

/// Project one bond between eye-space end points `a` and `b` (validated by the caller, `a ≠ b`).
#[inline]
fn project(view: &View, a: DVec3, b: DVec3, r: f32, kind: [u16; 2]) -> Option<BondRec> {
    let axis = b - a;
    let len = axis.length();
    if !(len > 0.0 && len.is_finite() && (len as f32) > 0.0) {
        return None;
    }
    let u = axis / len;
    // Cull against the far plane and (with the clipping margin r) the near plane.
    let (da, db) = (-a.z as f32, -b.z as f32);
    let lim = view.near - r;
    if (da < lim && db < lim) || (da - r > view.far && db - r > view.far) {
        return None;
    }
    // Clip the axis to depths ≥ near − r: nearer points cannot yield a fragment at depth ≥ near.
    let (af, bf) = (a.as_vec3(), b.as_vec3());
    let clip_end = |p: Vec3, dp: f32, other: Vec3, dother: f32| -> Vec3 {
        if dp >= lim {
            p
        } else {
            let f = (lim - dp) / (dother - dp);
            p + (other - p) * f
        }
    };
    let ca = clip_end(af, da, bf, db);
    let cb = clip_end(bf, db, af, da);
    // Screen rectangle: the union of the two end spheres' rectangles.
    let [[ax, ay], [bx, by]] = if view.ortho {
        [sphere_rect(view, ca, r), sphere_rect(view, cb, r)]
    } else {
        sphere_rects_persp(view, ca, cb, r)
    };
    let rect = |x: Option<(f32, f32)>, y: Option<(f32, f32)>| -> [f32; 4] {
        let (x0, x1) = x.unwrap_or((-HUGE, HUGE));
        let (y0, y1) = y.unwrap_or((-HUGE, HUGE));
        let c = |v: f32| v.clamp(-HUGE, HUGE);
        [c(x0), c(x1), c(y0), c(y1)]
    };
    let ends = [rect(ax, ay), rect(bx, by)];
    let union = |p: Option<(f32, f32)>, q: Option<(f32, f32)>, n: u32| -> (u16, u16) {
        match (p, q) {
            (Some((p0, p1)), Some((q0, q1))) => View::pixel_range(
                if p0 < q0 { p0 } else { q0 },
                if p1 > q1 { p1 } else { q1 },
                n,
            ),
            _ => View::pixel_range(0.0, n as f32, n),
        }
    };
    let (x0, x1) = union(ax, bx, view.width);
    let (y0, y1) = union(ay, by, view.height);
    if x0 >= x1 || y0 >= y1 {
        return None;
    }
    // Per-bond constants of the intersection (module docs), formed in f64.
    let au = a.dot(u);
    let q = a - u * au;
    let n = u.cross(a);
    Some(BondRec {
        n: n.as_vec3().to_array(),
        q: q.as_vec3().to_array(),
        u: u.as_vec3().to_array(),
        au: au as f32,
        len: len as f32,
        r2: r * r,
        inv_r: 1.0 / r,
        bbox: [x0, y0, x1, y1],
        ends,
        kind,
    })
}

#[inline]
fn tile_range(p: &BondRec) -> (usize, usize, usize, usize) {
    let [x0, y0, x1, y1] = p.bbox;
    debug_assert!(x0 < x1 && y0 < y1);
    (
        (x0 as u32 / TILE) as usize,
        (y0 as u32 / TILE) as usize,
        ((x1 as u32 - 1) / TILE) as usize,
        ((y1 as u32 - 1) / TILE) as usize,
    )
}

/// A raw pointer that chunks write through at disjoint offsets.
#[derive(Clone, Copy)]
struct SendPtr(*mut BondRec);
// SAFETY: every writer writes a disjoint set of slots (see `BondBins::build`).
unsafe impl Send for SendPtr {}
unsafe impl Sync for SendPtr {}

/// Pass 1 of [`BondBins::build`] for one chunk of bonds: validate, transform, cull, project and
/// count per tile.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn project_chunk(
    scene: &SphereScene,
    view: &View,
    ci: usize,
    n: usize,
    ntiles: usize,
    recs: &mut Vec<BondRec>,
    counts: &mut Vec<u32>,
    stats: &mut BondStats,
) {
    let tiles_x = view.tiles_x as usize;
    let r = scene.bond_radius;
    let radius_ok = r.is_finite() && r > 0.0;
    let natoms = scene.len();
    recs.clear();
    counts.clear();
    counts.resize(ntiles, 0);
    *stats = BondStats::default();
    let lo = ci * BOND_CHUNK;
    let hi = (lo + BOND_CHUNK).min(n);
    for &[i, j] in &scene.bonds[lo..hi] {
        let (i, j) = (i as usize, j as usize);
        // Validate: radius, indices, both atoms drawable, distinct centres.
        if !(radius_ok
            && i < natoms
            && j < natoms
            && scene.is_valid(i)
            && scene.is_valid(j)
            && scene.centers[i] != scene.centers[j])
        {
            stats.skipped += 1;
            continue;
        }
        let a = eye_space_f64(view, scene.centers[i]);
        let b = eye_space_f64(view, scene.centers[j]);
        match project(view, a, b, r, [scene.kinds[i], scene.kinds[j]]) {
            Some(p) => {
                stats.drawn += 1;
                let (tx0, ty0, tx1, ty1) = tile_range(&p);
                for ty in ty0..=ty1 {
                    for c in &mut counts[ty * tiles_x + tx0..=ty * tiles_x + tx1] {
                        *c += 1;
                    }
                }
                recs.push(p);
            }
            None => stats.culled += 1,
        }
    }
}

impl BondBins {
    /// Validate, project and bin every bond of `scene`. Returns the counts.
    fn build(&mut self, scene: &SphereScene, view: &View) -> BondStats {
        let n = scene.bonds.len();
        let nchunks = n.div_ceil(BOND_CHUNK);
        let ntiles = (view.tiles_x * view.tiles_y) as usize;
        let tiles_x = view.tiles_x as usize;
        self.chunk_recs.resize_with(nchunks, Vec::new);
        self.chunk_counts.resize_with(nchunks, Vec::new);
        self.chunk_stats.resize(nchunks, BondStats::default());

        // Pass 1: validate, transform, cull, project, count per tile (parallel over chunks).
        self.chunk_recs[..nchunks]
            .par_iter_mut()
            .zip(self.chunk_counts[..nchunks].par_iter_mut())
            .zip(self.chunk_stats[..nchunks].par_iter_mut())
            .enumerate()
            .for_each(|(ci, ((recs, counts), stats))| {
                project_chunk(scene, view, ci, n, ntiles, recs, counts, stats);
            });

        // Pass 2: prefix sum over (tile, chunk); counts become offsets within the tile's run.
        let total = pipeline::prefix_tile_offsets(
            &mut self.tile_start,
            &mut self.chunk_counts[..nchunks],
            ntiles,
        );

        // Pass 3: fill (parallel over chunks, each writing its own disjoint runs).
        self.recs.clear();
        self.recs.reserve(total);
        let base = SendPtr(self.recs.as_mut_ptr());
        let tile_start = &self.tile_start;
        self.chunk_recs[..nchunks]
            .par_iter()
            .zip(self.chunk_counts[..nchunks].par_iter_mut())
            .for_each(|(recs, offs)| {
                // Capture the whole `SendPtr` (edition 2024 closures capture fields).
                #[allow(clippy::redundant_locals)]
                let base = base;
                for p in recs {
                    let (tx0, ty0, tx1, ty1) = tile_range(p);
                    for ty in ty0..=ty1 {
                        for tx in tx0..=tx1 {
                            let t = ty * tiles_x + tx;
                            let slot = tile_start[t] + offs[t] as usize;
                            offs[t] += 1;
                            debug_assert!(slot < tile_start[t + 1]);
                            // SAFETY: `slot` lies in this chunk's own run of tile `t` (prefix
                            // sum above), which no other chunk writes, and below `total`, the
                            // reserved capacity.
                            unsafe { base.0.add(slot).write(*p) };
                        }
                    }
                }
            });
        // SAFETY: the runs of all (tile, chunk) pairs partition 0..total and each slot was
        // written exactly once above.
        unsafe { self.recs.set_len(total) };

        let mut stats = BondStats::default();
        for s in &self.chunk_stats[..nchunks] {
            stats.drawn += s.drawn;
            stats.culled += s.culled;
            stats.skipped += s.skipped;
        }
        stats
    }
}

/// The per-(bond, tile) constants of the intersection, splatted into lanes once.
struct BondV {
    u: [f32; 3],
    n: [f32; 3],
    q: [f32; 3],
    /// `a`, the first end point (orthographic rays start on the eye plane, so need `g = o − a`).
    a: [f32; 3],
    /// `a·u` and its negation `h(0)` (perspective rays start at the eye).
    au: f32,
    neg_au: f32,
    len: f32,
    r2: f32,
    /// Orthographic `A = ux² + uy²` and `d·u = −uz` (the same for every ray).
    a_ortho: f32,
    du_ortho: f32,
    /// Perspective: 1 where the eye lies inside the infinite cylinder (`|q|² ≤ r²`), else 0.
    par_in_persp: f32,
    /// `−ux`; orthographic `gz·uz`, `gz²` and `gz·A` with `gz = −az`.
    neg_ux: f32,
    gzuz: f32,
    gz2: f32,
    gza: f32,
    /// The bond's index in the tile's bin (the winner word).
    idx: u32,
}

impl BondV {
    /// The constants of `rec`, the `idx`-th record of the bin. Scalars: the kernels splat them
    /// where they are used (an 8-lane value held for a whole bond costs two registers or two
    /// stack slots, and most bonds are rejected by the hierarchical-z test before any use).
    #[inline(always)]
    fn new(rec: &BondRec, idx: u32) -> BondV {
        let a = rec.a();
        let [ux, uy, uz] = rec.u;
        let qq = Vec3::from(rec.q).length_squared();
        BondV {
            u: rec.u,
            n: rec.n,
            q: rec.q,
            a: a.to_array(),
            au: rec.au,
            neg_au: -rec.au,
            len: rec.len,
            r2: rec.r2,
            a_ortho: ux * ux + uy * uy,
            du_ortho: -uz,
            par_in_persp: if qq <= rec.r2 { 1.0 } else { 0.0 },
            neg_ux: -ux,
            gzuz: -a.z * uz,
            gz2: -a.z * -a.z,
            gza: -a.z * (ux * ux + uy * uy),
            idx,
        }
    }
}

/// Ray data of 8 pixels (any rows), in the generic form of the intersection.
struct Rays<V> {
    /// `A = |d × u|²`.
    a: V,
    /// `g·(d × u)` (up to sign): `√A` times the ray–axis distance.
    dn: V,
    /// Closest approach `s = num / A`.
    num: V,
    /// `h(o)`: axial coordinate of the ray origin, and its negation.
    h0: V,
    neg_h0: V,
    /// `d·u`.
    du: V,
    /// For rays parallel to the axis: 1 where the ray runs inside the infinite cylinder, else 0.
    par_in: V,
}

/// A camera's rays over lanes, in two steps: what depends on the row (`y`) once per row, then
/// what depends on the column (`x`) per 8 pixels. Both implementations keep the operations and
/// their order of the one-step form (so the results are bit-identical to it).
trait RayGen<V: Simd8> {
    type Row;
    fn row(b: &BondV, y: V) -> Self::Row;
    fn rays(b: &BondV, r: &Self::Row, x: V) -> Rays<V>;
}

/// Perspective rays: `o = 0`, `d = (x, y, −1)` per lane.
struct Persp;

/// The row terms of a perspective ray: `c1 = y·uz + uy` and the products of `y`.
struct PerspRow<V> {
    c1: V,
    yux: V,
    yuy: V,
    yny: V,
    yqy: V,
}

impl<V: Simd8> RayGen<V> for Persp {
    type Row = PerspRow<V>;
    #[inline(always)]
    fn row(b: &BondV, y: V) -> PerspRow<V> {
        let [ux, uy, uz] = b.u.map(V::splat);
        PerspRow {
            c1: y * uz + uy,
            yux: y * ux,
            yuy: y * uy,
            yny: y * V::splat(b.n[1]),
            yqy: y * V::splat(b.q[1]),
        }
    }
    #[inline(always)]
    fn rays(b: &BondV, r: &PerspRow<V>, x: V) -> Rays<V> {
        let [ux, uy, uz] = b.u.map(V::splat);
        // d × u, component by component (z of d is −1).
        let c2 = V::splat(b.neg_ux) - x * uz;
        let c3 = x * uy - r.yux;
        Rays {
            a: r.c1 * r.c1 + c2 * c2 + c3 * c3,
            dn: x * V::splat(b.n[0]) + r.yny - V::splat(b.n[2]),
            num: x * V::splat(b.q[0]) + r.yqy - V::splat(b.q[2]),
            h0: V::splat(b.neg_au),
            neg_h0: V::splat(b.au),
            du: x * ux + r.yuy - uz,
            par_in: V::splat(b.par_in_persp),
        }
    }
}

/// Orthographic rays: `o = (x, y, 0)` per lane, `d = (0, 0, −1)`.
struct Ortho;

/// The row terms of an orthographic ray: products of `gy = y − ay`.
struct OrthoRow<V> {
    gyux: V,
    gyuy: V,
    gy2: V,
}

impl<V: Simd8> RayGen<V> for Ortho {
    type Row = OrthoRow<V>;
    #[inline(always)]
    fn row(b: &BondV, y: V) -> OrthoRow<V> {
        let gy = y - V::splat(b.a[1]);
        OrthoRow {
            gyux: gy * V::splat(b.u[0]),
            gyuy: gy * V::splat(b.u[1]),
            gy2: gy * gy,
        }
    }
    #[inline(always)]
    fn rays(b: &BondV, r: &OrthoRow<V>, x: V) -> Rays<V> {
        let [ux, uy, uz] = b.u.map(V::splat);
        // g = o − a (gz = −az, the same for every ray); d × u = (uy, −ux, 0).
        let gx = x - V::splat(b.a[0]);
        let gxy = gx * ux + r.gyuy;
        let gu = gxy + V::splat(b.gzuz);
        let par_in = (gx * gx + r.gy2 + V::splat(b.gz2) - gu * gu).le(V::splat(b.r2));
        Rays {
            a: V::splat(b.a_ortho),
            dn: gx * uy - r.gyux,
            // s = −(g·w)/A with w = d − (d·u)u = (uz·ux, uz·uy, −A) (as |u| = 1): written so,
            // not as `gz − uz·(g·u)`, which cancels two terms of the size of the depth when the
            // bond is seen nearly end-on.
            num: V::splat(b.gza) - uz * gxy,
            h0: gu,
            neg_h0: V::splat(0.0) - gu,
            du: V::splat(b.du_ortho),
            par_in: V::select(par_in, V::splat(1.0), V::splat(0.0)),
        }
    }
}

/// Intersect 8 rays with one bond: depths (`INFINITY` for a miss, a clipped hit or a lane
/// outside `lanes`) and the winner words `idx | flags`.
///
/// Entry and exit of the solid capped cylinder are `max`/`min` of the infinite-cylinder interval
/// and the cap slab (module docs); entry nearer than the near plane takes the exit instead.
///
/// Chosen per 8 lanes: when no ray is parallel to the axis (`A > 1e-12`) or to the cap planes
/// (`(d·u)² > 1e-30`, so `|d·u| > MIN_DU`), and no hit lies behind the near plane (almost every
/// group), [`solve8_regular`] computes the same operations on the same values without the
/// selects those cases need; otherwise [`solve8_general`].
#[inline(always)]
fn solve8<V: Simd8>(b: &BondV, l: &Rays<V>, lanes: V::M, near: V, far: V) -> (V, V) {
    let regular =
        l.a.gt(V::splat(PARALLEL_A))
            .and((l.du * l.du).gt(V::splat(1e-30)));
    if regular.bits() == 0xff
        && let Some(r) = solve8_regular(b, l, lanes, near, far)
    {
        return r;
    }
    solve8_general(b, l, lanes, near, far)
}

/// [`solve8`] for 8 regular lanes, or `None` when a hit lane took the exit (near plane).
#[inline(always)]
fn solve8_regular<V: Simd8>(
    b: &BondV,
    l: &Rays<V>,
    lanes: V::M,
    near: V,
    far: V,
) -> Option<(V, V)> {
    let zero = V::splat(0.0);
    let one = V::splat(1.0);
    let inf = V::splat(f32::INFINITY);
    // Infinite cylinder: s ∓ √(r²A − dn²)/A.
    let ia = one / l.a;
    let disc = V::splat(b.r2) * l.a - l.dn * l.dn;
    let hc = disc.max(zero).sqrt() * ia;
    let s = l.num * ia;
    let t0 = s - hc;
    let t1 = s + hc;
    // Cap slab: 0 ≤ h0 + t·du ≤ len.
    let inv = one / l.du;
    let ta = l.neg_h0 * inv;
    let tb = (V::splat(b.len) - l.h0) * inv;
    let s0 = ta.min(tb);
    let s1 = tb.max(ta);
    // Entry and exit of the solid.
    let en = t0.max(s0);
    let ex = t1.min(s1);
    let front = en.ge(near);
    let th = V::select(front, en, ex);
    let ok = disc
        .ge(zero)
        .and(en.le(ex))
        .and(th.ge(near))
        .and(th.le(far))
        .and(lanes);
    if ok.bits() == 0 {
        return Some((inf, zero));
    }
    if en.lt(near).and(ok).bits() != 0 {
        return None;
    }
    // Every hit is the entry: the cap flag where the entry is on a cap.
    let word = V::select(
        s0.gt(t0),
        V::splat_bits(b.idx | FLAG_CAP),
        V::splat_bits(b.idx),
    );
    Some((V::select(ok, th, inf), word))
}

/// [`solve8`] for any lanes: rays parallel to the axis or the cap planes, and exits.
#[inline(always)]
fn solve8_general<V: Simd8>(b: &BondV, l: &Rays<V>, lanes: V::M, near: V, far: V) -> (V, V) {
    let zero = V::splat(0.0);
    let one = V::splat(1.0);
    let inf = V::splat(f32::INFINITY);
    // Infinite cylinder: s ∓ √(r²A − dn²)/A; a ray parallel to the axis (A ≤ 1e-12) is inside
    // everywhere or nowhere.
    let par = l.a.le(V::splat(PARALLEL_A));
    let ia = one / V::select(par, one, l.a);
    let disc = V::splat(b.r2) * l.a - l.dn * l.dn;
    let hc = disc.max(zero).sqrt() * ia;
    let s = l.num * ia;
    let side_hit = V::select(par, l.par_in, V::select(disc.ge(zero), one, zero));
    let t0 = V::select(par, V::splat(f32::NEG_INFINITY), s - hc);
    let t1 = V::select(par, inf, s + hc);
    // Cap slab: 0 ≤ h0 + t·du ≤ len (|du| ≤ MIN_DU replaced by MIN_DU).
    let du = V::select(
        l.du.lt(V::splat(-MIN_DU)),
        l.du,
        V::select(l.du.gt(V::splat(MIN_DU)), l.du, V::splat(MIN_DU)),
    );
    let inv = one / du;
    let ta = l.neg_h0 * inv;
    let tb = (V::splat(b.len) - l.h0) * inv;
    let s0 = ta.min(tb);
    let s1 = tb.max(ta);
    // Entry and exit of the solid.
    let en = t0.max(s0);
    let ex = t1.min(s1);
    let front = en.ge(near);
    let th = V::select(front, en, ex);
    let ok = side_hit
        .gt(zero)
        .and(en.le(ex))
        .and(th.ge(near))
        .and(th.le(far))
        .and(lanes);
    // Winner words: inside flag where the exit was taken, cap flag where the hit is on a cap.
    let word = V::select(
        front,
        V::select(
            s0.gt(t0),
            V::splat_bits(b.idx | FLAG_CAP),
            V::splat_bits(b.idx),
        ),
        V::select(
            s1.lt(t1),
            V::splat_bits(b.idx | FLAG_INSIDE | FLAG_CAP),
            V::splat_bits(b.idx | FLAG_INSIDE),
        ),
    );
    (V::select(ok, th, inf), word)
}

/// Strict depth test of 8 lanes against `depth`/`win` (the atom, then the earlier bond, wins ties).
#[inline(always)]
fn depth_test8<V: Simd8>(t: V, word: V, depth: &mut [f32], win: &mut [u32]) {
    let d = V::load_from(depth);
    let closer = t.lt(d);
    if closer.bits() == 0 {
        return;
    }
    V::select(closer, t, d).store_to(depth);
    V::select(closer, word, V::load_bits(win)).store_bits(win);
}

/// A tile's bond depth test: the depth buffer starts from the sphere pass.
struct TileBuf {
    depth: [f32; TILE_BUF],
    win: [u32; TILE_BUF],
}

/// Per-frame constants of the tile kernel.
struct Kernel<'a> {
    view: View,
    /// Run the depth and shading passes on AVX2 lanes (the CPU has them).
    avx2: bool,
    /// The specular power of every material when they all share one shininess (else per chunk).
    spec_pow: Option<SpecPow>,
    lighting: Lighting,
    materials: &'a [Material],
}

/// [`Kernel::raster_with`] on SSE2 lanes (the x86-64 baseline, or plain arrays elsewhere).
#[inline(never)]
fn raster_sse(k: &Kernel, recs: &[BondRec], x0t: u32, y0t: u32, w: u32, h: u32, buf: &mut TileBuf) {
    if k.view.ortho {
        k.raster_with::<Ortho, V8>(recs, x0t, y0t, w, h, buf);
    } else {
        k.raster_with::<Persp, V8>(recs, x0t, y0t, w, h, buf);
    }
}

/// [`Kernel::raster_with`] on AVX2 lanes (the generic body and the intrinsics inline here; the
/// same IEEE operations, so the same bits as [`raster_sse`]).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn raster_avx2(
    k: &Kernel,
    recs: &[BondRec],
    x0t: u32,
    y0t: u32,
    w: u32,
    h: u32,
    buf: &mut TileBuf,
) {
    if k.view.ortho {
        k.raster_with::<Ortho, V8x>(recs, x0t, y0t, w, h, buf);
    } else {
        k.raster_with::<Persp, V8x>(recs, x0t, y0t, w, h, buf);
    }
}

/// [`Kernel::resolve_with`] on SSE2 lanes.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn resolve_sse(
    k: &Kernel,
    recs: &[BondRec],
    x0t: u32,
    y0t: u32,
    w: u32,
    h: u32,
    buf: &TileBuf,
    color: &mut [[u8; 4]],
    depth: &mut [f32],
    stride: usize,
) {
    k.resolve_with::<V8>(recs, x0t, y0t, w, h, buf, color, depth, stride);
}

/// [`Kernel::resolve_with`] on AVX2 lanes (same IEEE operations, so the same bytes).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
#[inline(never)]
unsafe fn resolve_avx2(
    k: &Kernel,
    recs: &[BondRec],
    x0t: u32,
    y0t: u32,
    w: u32,
    h: u32,
    buf: &TileBuf,
    color: &mut [[u8; 4]],
    depth: &mut [f32],
    stride: usize,
) {
    k.resolve_with::<V8x>(recs, x0t, y0t, w, h, buf, color, depth, stride);
}

impl Kernel<'_> {
    /// Depth pass of one tile over its bin, in bond order.
    fn raster(&self, recs: &[BondRec], x0t: u32, y0t: u32, w: u32, h: u32, buf: &mut TileBuf) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where `V8x::available()` returned true.
            unsafe { raster_avx2(self, recs, x0t, y0t, w, h, buf) };
            return;
        }
        raster_sse(self, recs, x0t, y0t, w, h, buf);
    }

    /// [`Kernel::raster`] with the camera's ray generator chosen outside the loops.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn raster_with<G: RayGen<V>, V: Simd8>(
        &self,
        recs: &[BondRec],
        x0t: u32,
        y0t: u32,
        w: u32,
        h: u32,
        buf: &mut TileBuf,
    ) {
        const T: usize = TILE as usize;
        let v = &self.view;
        // Per-tile coordinate tables: perspective ray slopes, or orthographic ray origins (both
        // are `(pixel centre − image centre)/k`).
        let mut xs = [0f32; T + LANES];
        for (i, x) in xs.iter_mut().enumerate() {
            *x = ((x0t + i as u32) as f32 + 0.5 - v.cx) * v.inv_k;
        }
        let mut ys = [0f32; T];
        for (j, y) in ys.iter_mut().enumerate() {
            *y = (v.cy - ((y0t + j as u32) as f32 + 0.5)) * v.inv_k;
        }
        let (near, far) = (V::splat(v.near), V::splat(v.far));
        let view_w = v.width;
        for (idx, rec) in recs.iter().enumerate() {
            // Clip the bond's rectangle to the tile (tile-local columns i0..i1, rows j0..j1).
            let bx0 = (rec.bbox[0] as u32).max(x0t);
            let by0 = (rec.bbox[1] as u32).max(y0t);
            let bx1 = (rec.bbox[2] as u32).min(x0t + w);
            let by1 = (rec.bbox[3] as u32).min(y0t + h);
            if bx0 >= bx1 || by0 >= by1 {
                continue;
            }
            let (i0, i1) = ((bx0 - x0t) as usize, (bx1 - x0t) as usize);
            let (j0, j1) = ((by0 - y0t) as usize, (by1 - y0t) as usize);
            // The lane constants, made when the first 8 pixels pass the hierarchical-z test.
            let mut bv: Option<BondV> = None;
            // Hierarchical z: no fragment of the bond is nearer than its nearest end minus r
            // (the capped cylinder lies in the capsule around its axis), so 8 pixels whose
            // stored depths are all at least that near are skipped. The bound is widened by
            // 1e-4 of itself against rounding in `solve8`.
            let zmin = V::splat(rec.zmin());
            if i1 - i0 <= 4 {
                // Narrow boxes (thin or short bonds): two rows of up to 4 pixels per 8 lanes.
                let cols = <V::M as Mask8>::first_of_halves(i1 - i0);
                let x = V::load_halves(&xs[i0..], &xs[i0..]);
                let mut j = j0;
                while j < j1 {
                    let two = j + 1 < j1;
                    let jb = if two { j + 1 } else { j };
                    let (o0, o1) = (j * T + i0, jb * T + i0);
                    let d = V::load_halves(&buf.depth[o0..], &buf.depth[o1..]);
                    let lanes = if two {
                        cols
                    } else {
                        cols.and(<V::M as Mask8>::first(4))
                    };
                    if zmin.lt(d).and(lanes).bits() != 0 {
                        let y = V::load_halves(&[ys[j]; 4], &[ys[jb]; 4]);
                        let b = bv.get_or_insert_with(|| BondV::new(rec, idx as u32));
                        let rays = G::rays(b, &G::row(b, y), x);
                        let (t, word) = solve8(b, &rays, lanes, near, far);
                        let closer = t.lt(d);
                        if closer.bits() != 0 {
                            let nd = V::select(closer, t, d);
                            let mut wins = [0u32; LANES];
                            wins[..4].copy_from_slice(&buf.win[o0..o0 + 4]);
                            wins[4..].copy_from_slice(&buf.win[o1..o1 + 4]);
                            V::select(closer, word, V::load_bits(&wins)).store_bits(&mut wins);
                            nd.store_lo(&mut buf.depth[o0..]);
                            buf.win[o0..o0 + 4].copy_from_slice(&wins[..4]);
                            if two {
                                nd.store_hi(&mut buf.depth[o1..]);
                                buf.win[o1..o1 + 4].copy_from_slice(&wins[4..]);
                            }
                        }
                    }
                    j += 2;
                }
                continue;
            }
            for j in j0..j1 {
                // Wider boxes: this row's span of the hull of the end spheres' rectangles.
                let (a, e) = if i1 - i0 > 2 * LANES {
                    let y = (y0t as usize + j) as f32 + 0.5;
                    let Some((sx0, sx1)) = row_span(&rec.ends, y) else {
                        continue;
                    };
                    let (px0, px1) = View::pixel_range(sx0, sx1, view_w);
                    let a = (px0 as u32).max(bx0);
                    let e = (px1 as u32).min(bx1);
                    if a >= e {
                        continue;
                    }
                    ((a - x0t) as usize, (e - x0t) as usize)
                } else {
                    (i0, i1)
                };
                let y = V::splat(ys[j]);
                let mut i = a;
                while i < e {
                    let o = j * T + i;
                    let lanes = <V::M as Mask8>::first(e - i);
                    let d = V::load_from(&buf.depth[o..]);
                    if zmin.lt(d).and(lanes).bits() != 0 {
                        let x = V::load_from(&xs[i..]);
                        let b = bv.get_or_insert_with(|| BondV::new(rec, idx as u32));
                        let rays = G::rays(b, &G::row(b, y), x);
                        let (t, word) = solve8(b, &rays, lanes, near, far);
                        depth_test8(
                            t,
                            word,
                            &mut buf.depth[o..o + LANES],
                            &mut buf.win[o..o + LANES],
                        );
                    }
                    i += LANES;
                }
            }
        }
    }

    /// Shade the pixels of one tile won by a bond and write them (colour and depth) to the frame.
    #[allow(clippy::too_many_arguments)]
    fn resolve(
        &self,
        recs: &[BondRec],
        x0t: u32,
        y0t: u32,
        w: u32,
        h: u32,
        buf: &TileBuf,
        color: &mut [[u8; 4]],
        depth: &mut [f32],
        stride: usize,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where `V8x::available()` returned true.
            unsafe { resolve_avx2(self, recs, x0t, y0t, w, h, buf, color, depth, stride) };
            return;
        }
        resolve_sse(self, recs, x0t, y0t, w, h, buf, color, depth, stride);
    }

    /// [`Kernel::resolve`] on the lanes `V`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn resolve_with<V: Simd8>(
        &self,
        recs: &[BondRec],
        x0t: u32,
        y0t: u32,
        w: u32,
        h: u32,
        buf: &TileBuf,
        color: &mut [[u8; 4]],
        depth: &mut [f32],
        stride: usize,
    ) {
        let v = &self.view;
        // Compact the bond pixels so that the shading lanes are spent on them only.
        let mut list = [0u16; TILE_PX];
        let mut n = 0;
        for j in 0..h {
            for i in 0..w {
                let b = (j * TILE + i) as usize;
                if buf.win[b] != NONE {
                    list[n] = b as u16;
                    n += 1;
                }
            }
        }
        // Pixel-centre tables (the formula of the depth pass, so the rays are the same).
        let mut xs = [0f32; TILE as usize];
        for (i, x) in xs.iter_mut().enumerate() {
            *x = ((x0t + i as u32) as f32 + 0.5 - v.cx) * v.inv_k;
        }
        let mut ys = [0f32; TILE as usize];
        for (j, y) in ys.iter_mut().enumerate() {
            *y = (v.cy - ((y0t + j as u32) as f32 + 0.5)) * v.inv_k;
        }
        let zero = V::splat(0.0);
        let enc = fastshade::srgb_table32();
        for chunk in list[..n].chunks(W) {
            // Gather the lanes' ray, depth, bond and materials (short chunks repeat their first
            // pixel).
            let mut g = [[0f32; W]; 12];
            let mut flags = [0u32; W];
            let mut kinds = [[0u16; 2]; W];
            for l in 0..W {
                let b = chunk[if l < chunk.len() { l } else { 0 }] as usize;
                let wv = buf.win[b];
                let rec = &recs[(wv & INDEX_MASK) as usize];
                let a = rec.a();
                g[0][l] = xs[b % TILE as usize];
                g[1][l] = ys[b / TILE as usize];
                g[2][l] = buf.depth[b];
                g[3][l] = a.x;
                g[4][l] = a.y;
                g[5][l] = a.z;
                g[6][l] = rec.u[0];
                g[7][l] = rec.u[1];
                g[8][l] = rec.u[2];
                g[9][l] = 0.5 * rec.len;
                g[10][l] = rec.inv_r;
                flags[l] = wv;
                kinds[l] = rec.kind;
            }
            let [x, y, t, ax, ay, az, ux, uy, uz, half, inv_r, _] = g.map(|c| V::load_from(&c));
            // Hit point and unit vector toward the eye.
            let (p, to_eye) = if v.ortho {
                ([x, y, zero - t], [zero, zero, V::splat(1.0)])
            } else {
                let il = V::splat(1.0) / (x * x + y * y + V::splat(1.0)).sqrt();
                (
                    [x * t, y * t, zero - t],
                    [(zero - x) * il, (zero - y) * il, il],
                )
            };
            let pa = [p[0] - ax, p[1] - ay, p[2] - az];
            let hax = pa[0] * ux + pa[1] * uy + pa[2] * uz;
            // Half-bond colouring: the half at `a` in atom i's material.
            let first = hax.lt(half);
            // Outward normal: ±u on a cap, the radial direction on the side; the inside of a
            // bond cut by the near plane faces the viewer.
            let cap = V::bit_set(&flags, 30);
            let inside = V::bit_set(&flags, 31);
            let mut nrm = [zero; 3];
            for (k, uk) in [ux, uy, uz].into_iter().enumerate() {
                let side = (pa[k] - uk * hax) * inv_r;
                let capn = V::select(first, zero - uk, uk);
                let nk = V::select(cap, capn, side);
                nrm[k] = V::select(inside, zero - nk, nk);
            }
            let first = first.bits();
            let mut m = [[0f32; W]; 5];
            for l in 0..W {
                let mat =
                    &self.materials[kinds[l][if first >> l & 1 != 0 { 0 } else { 1 }] as usize];
                for k in 0..3 {
                    m[k][l] = mat.base_color[k];
                }
                m[3][l] = mat.specular;
                m[4][l] = mat.shininess;
            }
            let [br, bg, bb, spec, shin] = m.map(|c| V::load_from(&c));
            let pow = match self.spec_pow {
                Some(pw) => pw,
                None => fastshade::spec_pow_of(shin),
            };
            let c =
                fastshade::shade_lanes(&self.lighting, nrm, to_eye, [br, bg, bb], spec, shin, pow);
            // sRGB encode over lanes: the 4096-bin table of `linear_to_srgb8` (same bytes).
            let mut px = [0u32; W];
            fastshade::srgb_rgba_lanes(c[0], c[1], c[2], enc).store_bits(&mut px);
            for (l, &b) in chunk.iter().enumerate() {
                let (i, j) = (b as usize % TILE as usize, b as usize / TILE as usize);
                let o = j * stride + i;
                color[o] = px[l].to_le_bytes();
                depth[o] = buf.depth[b as usize];
            }
        }
    }
}

/// The [`SpecPow`] of the materials when they all have the same shininess.
fn shared_spec_pow(materials: &[Material]) -> Option<SpecPow> {
    let m0 = materials.first()?;
    materials
        .iter()
        .all(|m| m.shininess.to_bits() == m0.shininess.to_bits())
        .then(|| fastshade::spec_pow_of(V8::splat(m0.shininess)))
}

/// Whether the depth pass may use AVX2 lanes (checked once per frame).
fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        V8x::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Draw the bonds of `scene` over `frame`, which holds the sphere pass's colour and depth.
/// `lighting` is in eye space.
pub(crate) fn draw(
    bins: &mut BondBins,
    scene: &SphereScene,
    view: &View,
    lighting: &Lighting,
    frame: &mut Frame,
) -> BondStats {
    let stats = bins.build(scene, view);
    if stats.drawn == 0 {
        return stats;
    }
    let kernel = Kernel {
        view: *view,
        avx2: avx2_available(),
        spec_pow: shared_spec_pow(&scene.materials),
        lighting: *lighting,
        materials: &scene.materials,
    };
    let bins = &*bins;
    let w = view.width as usize;
    let band = w * TILE as usize;
    frame
        .color
        .par_chunks_mut(band)
        .zip(frame.depth.par_chunks_mut(band))
        .enumerate()
        // One job per band: the bands' costs differ a lot (bonds crowd the image centre), and
        // rayon's default splitting would leave one thread with the dense half.
        .with_max_len(1)
        .for_each(|(ty, (color, depth))| {
            let mut buf = TileBuf {
                depth: [f32::INFINITY; TILE_BUF],
                win: [NONE; TILE_BUF],
            };
            let y0 = ty as u32 * TILE;
            let th = (view.height - y0).min(TILE);
            for tx in 0..view.tiles_x {
                let t = ty * view.tiles_x as usize + tx as usize;
                let recs = &bins.recs[bins.tile_start[t]..bins.tile_start[t + 1]];
                if recs.is_empty() {
                    continue;
                }
                let x0 = tx * TILE;
                let tw = (view.width - x0).min(TILE);
                // Start from the sphere pass's depth (lanes past the tile stay infinite).
                buf.depth.fill(f32::INFINITY);
                buf.win.fill(NONE);
                for j in 0..th as usize {
                    let o = j * w + x0 as usize;
                    buf.depth[j * TILE as usize..j * TILE as usize + tw as usize]
                        .copy_from_slice(&depth[o..o + tw as usize]);
                }
                kernel.raster(recs, x0, y0, tw, th, &mut buf);
                kernel.resolve(
                    recs,
                    x0,
                    y0,
                    tw,
                    th,
                    &buf,
                    &mut color[x0 as usize..],
                    &mut depth[x0 as usize..],
                    w,
                );
            }
        });
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tiny deterministic RNG (LCG).
    struct Lcg(u64);
    impl Lcg {
        fn f(&mut self, lo: f32, hi: f32) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            lo + (hi - lo) * ((self.0 >> 40) as f32 / (1u64 << 24) as f32)
        }
    }

    #[test]
    fn row_span_contains_every_point_of_the_hull_and_is_tight() {
        let mut rng = Lcg(3);
        let mut hits = 0;
        for _ in 0..2000 {
            let mut ends = [[0f32; 4]; 2];
            for e in &mut ends {
                let (x, y) = (rng.f(0.0, 100.0), rng.f(0.0, 100.0));
                let (w, h) = (rng.f(0.0, 20.0), rng.f(0.0, 20.0));
                *e = [x, x + w, y, y + h];
            }
            // Points of the hull: (1 − λ)·p + λ·q with p in A and q in B.
            for _ in 0..50 {
                let l = rng.f(0.0, 1.0);
                let (pa, pb) = (rng.f(0.0, 1.0), rng.f(0.0, 1.0));
                let (qa, qb) = (rng.f(0.0, 1.0), rng.f(0.0, 1.0));
                let [a, b] = ends;
                let px = a[0] + (a[1] - a[0]) * pa;
                let py = a[2] + (a[3] - a[2]) * pb;
                let qx = b[0] + (b[1] - b[0]) * qa;
                let qy = b[2] + (b[3] - b[2]) * qb;
                let (x, y) = (px + (qx - px) * l, py + (qy - py) * l);
                let (s0, s1) = row_span(&ends, y).expect("a hull point's row meets the hull");
                assert!(
                    x >= s0 - 1e-3 && x <= s1 + 1e-3,
                    "x {x} outside span [{s0}, {s1}] at y {y} for {ends:?}"
                );
                hits += 1;
            }
            // Tight: the span's ends are hull points (x of an interpolated corner), so a row
            // beyond both rectangles' y-ranges misses.
            let top = ends[0][2].min(ends[1][2]) - 1.0;
            assert!(row_span(&ends, top).is_none(), "{ends:?}");
        }
        assert_eq!(hits, 100_000);
    }

    // The previous scalar kernel (one lane at a time, validated against reftrace), kept as the
    // reference of the lane kernel: the same IEEE operations in the same order.
    /// Per-lane ray data of 8 pixels in one row, in the generic form of the intersection.
    struct Lanes {
        /// `A = |d × u|²`.
        a: [f32; LANES],
        /// `g·(d × u)` (up to sign): `√A` times the ray–axis distance.
        dn: [f32; LANES],
        /// Closest approach `s = num / A`.
        num: [f32; LANES],
        /// `h(o)`: axial coordinate of the ray origin.
        h0: [f32; LANES],
        /// `d·u`.
        du: [f32; LANES],
        /// For rays parallel to the axis: whether the ray runs inside the infinite cylinder.
        par_in: [bool; LANES],
    }

    /// Intersect 8 rays with one bond: depths (`INFINITY` for a miss or a clipped hit) and flags.
    ///
    /// Entry and exit of the solid capped cylinder are `max`/`min` of the infinite-cylinder interval
    /// and the cap slab (module docs); entry nearer than the near plane takes the exit instead.
    #[inline(always)]
    fn solve8_scalar(
        rec: &BondRec,
        l: &Lanes,
        valid: usize,
        near: f32,
        far: f32,
    ) -> ([f32; LANES], [u32; LANES]) {
        let mut t = [f32::INFINITY; LANES];
        let mut flag = [0u32; LANES];
        for k in 0..LANES {
            let a = l.a[k];
            let par = !(a > PARALLEL_A);
            // Infinite cylinder: s ∓ √(r²A − dn²)/A.
            let ia = 1.0 / if par { 1.0 } else { a };
            let disc = rec.r2 * a - l.dn[k] * l.dn[k];
            let hc = (if disc > 0.0 { disc } else { 0.0 }).sqrt() * ia;
            let s = l.num[k] * ia;
            let side_hit = if par { l.par_in[k] } else { disc >= 0.0 };
            let t0 = if par { f32::NEG_INFINITY } else { s - hc };
            let t1 = if par { f32::INFINITY } else { s + hc };
            // Cap slab: 0 ≤ h0 + t·du ≤ len.
            let du = l.du[k];
            let du = if du.abs() > MIN_DU { du } else { MIN_DU };
            let inv = 1.0 / du;
            let ta = -l.h0[k] * inv;
            let tb = (rec.len - l.h0[k]) * inv;
            let (s0, s1) = if ta < tb { (ta, tb) } else { (tb, ta) };
            // Entry and exit of the solid.
            let en = if t0 > s0 { t0 } else { s0 };
            let ex = if t1 < s1 { t1 } else { s1 };
            let front = en >= near;
            let th = if front { en } else { ex };
            let cap = if front { s0 > t0 } else { s1 < t1 };
            let ok = side_hit && en <= ex && th >= near && th <= far && k < valid;
            t[k] = if ok { th } else { f32::INFINITY };
            flag[k] = (if front { 0 } else { FLAG_INSIDE }) | (if cap { FLAG_CAP } else { 0 });
        }
        (t, flag)
    }

    /// Fill the lanes of a perspective camera: `o = 0`, `d = (dx, dy, −1)`.
    #[inline(always)]
    fn lanes_persp(rec: &BondRec, dx: &[f32], dy: f32, qq: f32) -> Lanes {
        let [ux, uy, uz] = rec.u;
        let [nx, ny, nz] = rec.n;
        let [qx, qy, qz] = rec.q;
        let mut l = Lanes {
            a: [0.0; LANES],
            dn: [0.0; LANES],
            num: [0.0; LANES],
            h0: [-rec.au; LANES],
            du: [0.0; LANES],
            par_in: [qq <= rec.r2; LANES],
        };
        for k in 0..LANES {
            let x = dx[k];
            // d × u, component by component (z of d is −1).
            let c1 = dy * uz + uy;
            let c2 = -ux - x * uz;
            let c3 = x * uy - dy * ux;
            l.a[k] = c1 * c1 + c2 * c2 + c3 * c3;
            l.dn[k] = x * nx + dy * ny - nz;
            l.num[k] = x * qx + dy * qy - qz;
            l.du[k] = x * ux + dy * uy - uz;
        }
        l
    }

    /// Fill the lanes of an orthographic camera: `o = (ox, oy, 0)`, `d = (0, 0, −1)`.
    #[inline(always)]
    fn lanes_ortho(rec: &BondRec, ox: &[f32], oy: f32, a_eye: Vec3) -> Lanes {
        let [ux, uy, uz] = rec.u;
        let a = ux * ux + uy * uy;
        let mut l = Lanes {
            a: [a; LANES],
            dn: [0.0; LANES],
            num: [0.0; LANES],
            h0: [0.0; LANES],
            du: [-uz; LANES],
            par_in: [false; LANES],
        };
        for k in 0..LANES {
            let x = ox[k];
            // g = o − a; d × u = (uy, −ux, 0).
            let (gx, gy, gz) = (x - a_eye.x, oy - a_eye.y, -a_eye.z);
            let gu = gx * ux + gy * uy + gz * uz;
            l.dn[k] = gx * uy - gy * ux;
            // s = −(g·w)/A with w = d − (d·u)u = (uz·ux, uz·uy, −A) (as |u| = 1): written so,
            // not as `gz − uz·(g·u)`, which cancels two terms of the size of the depth when the
            // bond is seen nearly end-on.
            l.num[k] = gz * a - uz * (gx * ux + gy * uy);
            l.h0[k] = gu;
            l.par_in[k] = gx * gx + gy * gy + gz * gz - gu * gu <= rec.r2;
        }
        l
    }

    /// The lane kernel (`rays_*` + `solve8`) against the scalar reference on random bonds, views
    /// and pixels, including bonds seen exactly end-on (rays parallel to the axis) and bonds
    /// crossing the near plane: the same depths (bit for bit, up to the sign of zero) and the
    /// same flags wherever a lane hits.
    #[test]
    fn lane_kernel_matches_the_scalar_reference() {
        use texmap_core::camera::Camera;
        let mut rng = Lcg(11);
        let (mut hits, mut compared, mut par_lanes) = (0usize, 0usize, 0usize);
        for trial in 0..600 {
            let ortho = trial % 3 == 2;
            let eye = if trial % 5 == 0 {
                Vec3::new(0.0, 0.0, 8.0)
            } else {
                Vec3::new(rng.f(-9.0, 9.0), rng.f(-9.0, 9.0), rng.f(4.0, 12.0))
            };
            let cam = if ortho {
                Camera::orthographic_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(3.0, 9.0), 96, 80)
            } else {
                Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(10.0, 150.0), 96, 80)
            }
            .unwrap();
            let view = View::new(&cam);
            // Bond: random, or exactly along the view axis of the axis-aligned eye.
            let (pa, pb) = if trial % 5 == 0 {
                let p = Vec3::new(rng.f(-1.0, 1.0), rng.f(-1.0, 1.0), rng.f(-2.0, 2.0));
                (p, p - Vec3::Z * rng.f(0.5, 2.0))
            } else {
                let p = Vec3::new(rng.f(-3.0, 3.0), rng.f(-3.0, 3.0), rng.f(-3.0, 3.0));
                let q = Vec3::new(rng.f(-1.5, 1.5), rng.f(-1.5, 1.5), rng.f(-1.5, 1.5));
                (p, p + q)
            };
            let r = rng.f(0.05, 0.8);
            let a = eye_space_f64(&view, pa);
            let b = eye_space_f64(&view, pb);
            let Some(rec) = project(&view, a, b, r, [0, 1]) else {
                continue;
            };
            let bv = BondV::new(&rec, 5);
            let qq = Vec3::from(rec.q).length_squared();
            let (near, far) = (V8::splat(view.near), V8::splat(view.far));
            let [x0, y0, x1, y1] = rec.bbox.map(|v| v as u32);
            for y in y0.saturating_sub(2)..(y1 + 2).min(view.height) {
                let ys = (view.cy - (y as f32 + 0.5)) * view.inv_k;
                let mut xs = [0f32; LANES];
                let mut i = x0.saturating_sub(3);
                while i < (x1 + 3).min(view.width) {
                    for (k, x) in xs.iter_mut().enumerate() {
                        *x = ((i + k as u32) as f32 + 0.5 - view.cx) * view.inv_k;
                    }
                    let lanes_ref = if view.ortho {
                        lanes_ortho(&rec, &xs, ys, rec.a())
                    } else {
                        lanes_persp(&rec, &xs, ys, qq)
                    };
                    let (t_ref, f_ref) =
                        solve8_scalar(&rec, &lanes_ref, LANES, view.near, view.far);
                    let (x, yv) = (V8::load(&xs), V8::splat(ys));
                    let rays = if view.ortho {
                        Ortho::rays(&bv, &Ortho::row(&bv, yv), x)
                    } else {
                        Persp::rays(&bv, &Persp::row(&bv, yv), x)
                    };
                    let (t, word) = solve8(&bv, &rays, fastshade::M8::first(LANES), near, far);
                    let (t, word) = (t.store(), word.store());
                    for k in 0..LANES {
                        par_lanes += !(lanes_ref.a[k] > PARALLEL_A) as usize;
                        compared += 1;
                        assert!(
                            t[k] == t_ref[k] || (t[k].is_infinite() && t_ref[k].is_infinite()),
                            "trial {trial} pixel ({}, {y}): lane t {} vs scalar {}",
                            i + k as u32,
                            t[k],
                            t_ref[k]
                        );
                        if t[k].is_finite() {
                            hits += 1;
                            assert_eq!(
                                word[k].to_bits(),
                                5 | f_ref[k],
                                "trial {trial} pixel ({}, {y}): flags",
                                i + k as u32
                            );
                        }
                    }
                    i += LANES as u32;
                }
            }
        }
        eprintln!("{hits} hits, {par_lanes} parallel lanes of {compared} lanes compared");
        assert!(
            hits > 20_000 && par_lanes > 10,
            "{hits} hits, {par_lanes} parallel lanes"
        );
    }

    /// The 8-lane rectangles of two end spheres against the scalar [`sphere_rect`]: bit-equal,
    /// including spheres that reach or cross the eye plane (no finite bound: `None`).
    #[test]
    fn lane_sphere_rects_match_the_scalar_ones() {
        use texmap_core::camera::Camera;
        let mut rng = Lcg(7);
        let mut nones = 0;
        for trial in 0..20_000 {
            let fov = rng.f(5.0, 160.0);
            let cam = Camera::perspective_look_at(
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::ZERO,
                Vec3::Y,
                fov,
                64,
                48,
            )
            .unwrap();
            let view = View::new(&cam);
            let mut p = || Vec3::new(rng.f(-6.0, 6.0), rng.f(-6.0, 6.0), rng.f(-12.0, 1.0));
            let (a, b) = (p(), p());
            let r = rng.f(0.01, 2.0);
            let lanes = sphere_rects_persp(&view, a, b, r);
            let scalar = [sphere_rect(&view, a, r), sphere_rect(&view, b, r)];
            nones += lanes.iter().flatten().filter(|o| o.is_none()).count();
            let bits = |v: [[Option<(f32, f32)>; 2]; 2]| {
                v.map(|e| e.map(|o| o.map(|(lo, hi)| (lo.to_bits(), hi.to_bits()))))
            };
            assert_eq!(
                bits(lanes),
                bits(scalar),
                "trial {trial}: {a} {b} r {r} fov {fov}"
            );
        }
        assert!(
            nones > 100,
            "only {nones} unbounded axes: the eye-plane cases are not tested"
        );
    }

    /// The AVX2 depth and shading passes against the SSE2 ones on every tile of random
    /// ball-and-stick scenes (perspective and orthographic): the same depths and winners, bit for
    /// bit, then the same colours and depths. Skipped (with a note) on a CPU without AVX2.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx2_and_sse_depth_passes_are_bit_identical() {
        use texmap_core::camera::Camera;
        use texmap_core::shade::Material;
        if !V8x::available() {
            eprintln!("no AVX2 on this CPU: nothing to compare");
            return;
        }
        let mut rng = Lcg(23);
        let mut compared = 0usize;
        for trial in 0..12 {
            let mats = vec![Material::plastic(Vec3::ONE); 2];
            let mut scene = SphereScene::new(mats);
            scene.bond_radius = rng.f(0.05, 0.5);
            for i in 0..300u32 {
                let c = Vec3::new(rng.f(-4.0, 4.0), rng.f(-4.0, 4.0), rng.f(-4.0, 4.0));
                scene.push(c, rng.f(0.1, 0.5), (i % 2) as u16);
                if i > 0 {
                    scene.bonds.push([i - 1, i]);
                }
            }
            let eye = Vec3::new(rng.f(-3.0, 3.0), rng.f(-3.0, 3.0), rng.f(2.0, 12.0));
            let cam = if trial % 3 == 2 {
                Camera::orthographic_look_at(eye, Vec3::ZERO, Vec3::Y, 9.0, 150, 110)
            } else {
                Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(20.0, 120.0), 150, 110)
            }
            .unwrap();
            let view = View::new(&cam);
            let mut bins = BondBins::default();
            bins.build(&scene, &view);
            let k = Kernel {
                view,
                avx2: false,
                spec_pow: None,
                lighting: Lighting::default_for(&cam),
                materials: &scene.materials,
            };
            for ty in 0..view.tiles_y {
                for tx in 0..view.tiles_x {
                    let t = (ty * view.tiles_x + tx) as usize;
                    let recs = &bins.recs[bins.tile_start[t]..bins.tile_start[t + 1]];
                    let (x0, y0) = (tx * TILE, ty * TILE);
                    let (w, h) = ((view.width - x0).min(TILE), (view.height - y0).min(TILE));
                    // A sphere-pass depth to test against: a slanted plane through the scene.
                    let mut a = TileBuf {
                        depth: [f32::INFINITY; TILE_BUF],
                        win: [NONE; TILE_BUF],
                    };
                    for (i, d) in a.depth[..TILE_PX].iter_mut().enumerate() {
                        let (x, y) = ((x0 as usize + i % 32) as f32, (y0 as usize + i / 32) as f32);
                        let z = eye.length() + 0.02 * x - 0.03 * y;
                        *d = if (i / 7) % 3 == 0 { f32::INFINITY } else { z };
                    }
                    let mut b = TileBuf {
                        depth: a.depth,
                        win: a.win,
                    };
                    raster_sse(&k, recs, x0, y0, w, h, &mut a);
                    // SAFETY: AVX2 checked above.
                    unsafe { raster_avx2(&k, recs, x0, y0, w, h, &mut b) };
                    let bits = |d: &[f32; TILE_BUF]| d.map(f32::to_bits);
                    assert!(
                        bits(&a.depth) == bits(&b.depth),
                        "trial {trial} tile {tx},{ty}"
                    );
                    assert!(a.win == b.win, "trial {trial} tile {tx},{ty}: winners");
                    compared += a.win.iter().filter(|&&w| w != NONE).count();
                    // Shading: the same colours and depths from both backends.
                    let mut out = [([[0u8; 4]; TILE_PX], [0f32; TILE_PX]); 2];
                    let [(ca, da), (cb, db)] = &mut out;
                    resolve_sse(&k, recs, x0, y0, w, h, &a, ca, da, TILE as usize);
                    // SAFETY: AVX2 checked above.
                    unsafe { resolve_avx2(&k, recs, x0, y0, w, h, &a, cb, db, TILE as usize) };
                    assert!(ca == cb, "trial {trial} tile {tx},{ty}: colours");
                    assert!(
                        da.map(f32::to_bits) == db.map(f32::to_bits),
                        "trial {trial}: depths"
                    );
                }
            }
        }
        eprintln!("{compared} bond pixels compared");
        assert!(compared > 5_000, "only {compared} bond pixels");
    }
}

//! Stages 1 and 2 of the bond pass: project each bond to a record of per-bond constants and
//! bin the records into the sphere pipeline's tiles with the raster crate's binner (see the
//! parent module).

use super::*;

/// One projected bond, copied into every tile bin it touches (96 bytes).
///
/// All vectors in eye space: `a` the first end point (atom `i`), `u` the unit axis toward atom
/// `j`, `len` the axis length.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct BondRec {
    /// `u × a`: the perspective discriminant is `r²A − (d·n)²`.
    pub(super) n: [f32; 3],
    /// `a − (a·u)·u`: the foot of the perpendicular from the eye to the axis line; the
    /// perspective closest approach is `s = (d·q)/A`.
    pub(super) q: [f32; 3],
    pub(super) u: [f32; 3],
    /// `a·u`.
    pub(super) au: f32,
    pub(super) len: f32,
    pub(super) r2: f32,
    pub(super) inv_r: f32,
    /// Pixel rectangle `[x0, x1) x [y0, y1)` whose centres the bond may cover.
    pub(super) bbox: [u16; 4],
    /// The screen rectangles (pixels) of the two end spheres, `[x0, x1, y0, y1]` each: the
    /// bond's image lies in their convex hull, which narrows every row to a span
    /// ([`row_span`]). `±HUGE` bounds where a rectangle is unbounded.
    pub(super) ends: [[f32; 4]; 2],
    /// Material index of the half at `a` and of the half at the other end.
    pub(super) kind: [u16; 2],
}

const _: () = assert!(std::mem::size_of::<BondRec>() == 96);

/// Stand-in for an unbounded screen coordinate (finite, so that interpolation cannot give NaN).
pub(super) const HUGE: f32 = 1e9;

/// The x-range (pixels) of the convex hull of two axis-aligned rectangles at height `y`, or
/// `None` when the row misses the hull.
///
/// The hull is the union over `λ ∈ [0, 1]` of the rectangles `(1 − λ)·A + λ·B`, whose bounds
/// interpolate linearly: the row meets those with `y0(λ) ≤ y ≤ y1(λ)`, an interval of `λ`, and
/// the x-range is spanned by the interpolated bounds at its two ends.
#[inline]
pub(super) fn row_span(ends: &[[f32; 4]; 2], y: f32) -> Option<(f32, f32)> {
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
    pub(super) fn a(&self) -> Vec3 {
        Vec3::from(self.q) + Vec3::from(self.u) * self.au
    }

    /// A lower bound of the depth of every fragment of the bond: the nearer end's depth minus
    /// `r` (the capped cylinder lies in the capsule around its axis), widened by 1e-4 of itself
    /// against rounding in the per-pixel intersection.
    #[inline]
    pub(super) fn zmin(&self) -> f32 {
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

/// The reusable per-frame buffers of the bond pass: the binned records of the frame.
#[derive(Debug, Default)]
pub(crate) struct BondBins {
    bins: TileBins<BondRec>,
}

/// Bounds of `x/(−z)` over the circle of radius `r` around `(x, z)` (a plane through the eye):
/// the slopes of the two tangents from the origin. `None` when the circle reaches the eye plane
/// or lies behind it (no finite bound: the caller takes the whole screen along this axis).
#[inline]
pub(super) fn slope_bounds(x: f32, z: f32, r: f32) -> Option<(f32, f32)> {
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
pub(super) fn sphere_rect(view: &View, c: Vec3, r: f32) -> [Option<(f32, f32)>; 2] {
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
pub(super) fn sphere_rects_persp(
    view: &View,
    a: Vec3,
    b: Vec3,
    r: f32,
) -> [[Option<(f32, f32)>; 2]; 2] {
    // Lane k: sphere k / 4, axis (k / 2) % 2 (x, then y), tangent k % 2 (turned by ±asin(r/l)).
    let x = F32x8::load(&[a.x, a.x, a.y, a.y, b.x, b.x, b.y, b.y]);
    let z = F32x8::load(&[a.z, a.z, a.z, a.z, b.z, b.z, b.z, b.z]);
    let rs = F32x8::load(&[r, -r, r, -r, r, -r, r, -r]);
    let zero = F32x8::splat(0.0);
    let l2 = x * x + z * z;
    let t2 = l2 - F32x8::splat(r * r);
    let t = t2.max(zero).sqrt();
    // Tangent directions (scaled by the centre distance): cos = t/l, sin = ±r/l.
    let xt = t * x - rs * z;
    let zt = rs * x + t * z;
    // Both tangents of a pair must point in front of the eye plane, with a margin against
    // rounding; then the slopes x/(−z) map to pixels (x: cx + s·k, y: cy − s·k).
    let ok = t2
        .gt(zero)
        .and(zt.lt(zero - F32x8::splat(1e-6) * l2))
        .bits();
    let s = xt / (zero - zt);
    let (k, cx, cy) = (view.k, view.cx, view.cy);
    let px = (F32x8::load(&[cx, cx, cy, cy, cx, cx, cy, cy])
        + s * F32x8::load(&[k, k, -k, -k, k, k, -k, -k]))
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
pub(super) fn eye_space_f64(view: &View, p: Vec3) -> DVec3 {
    let d = p.as_dvec3() - view.eye.as_dvec3();
    DVec3::new(
        d.dot(view.right.as_dvec3()),
        d.dot(view.up.as_dvec3()),
        d.dot(view.back.as_dvec3()),
    )
}

/// Project one bond between eye-space end points `a` and `b` (validated by the caller, `a ≠ b`).
#[inline]
pub(super) fn project(view: &View, a: DVec3, b: DVec3, r: f32, kind: [u16; 2]) -> Option<BondRec> {
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

/// The binning pass of [`BondBins::build`] for one chunk of bonds: validate, transform, cull,
/// project and push into the tiles of the record's box.
#[inline(never)]
pub(super) fn project_chunk(
    scene: &SphereScene,
    view: &View,
    range: std::ops::Range<usize>,
    sink: &mut ChunkSink<'_, BondRec>,
) -> BondStats {
    let natoms = scene.len();
    let mut stats = BondStats::default();
    for (k, &[i, j]) in scene.bonds[range.clone()].iter().enumerate() {
        let (i, j) = (i as usize, j as usize);
        let r = scene.bond_radius_of(range.start + k);
        let radius_ok = r.is_finite() && r > 0.0;
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
        let rec = project(view, a, b, r, [scene.kinds[i], scene.kinds[j]]);
        // A projected record's box holds at least one pixel of the image.
        let span = rec.and_then(|p| {
            let [x0, y0, x1, y1] = p.bbox.map(u32::from);
            view.grid.span(x0, y0, x1, y1).map(|s| (s, p))
        });
        match span {
            Some((span, p)) => {
                stats.drawn += 1;
                sink.push(span, p);
            }
            None => stats.culled += 1,
        }
    }
    stats
}

impl BondBins {
    /// Validate, project and bin every bond of `scene`. Returns the counts.
    pub(super) fn build(&mut self, scene: &SphereScene, view: &View) -> BondStats {
        let n = scene.bonds.len();
        let chunk_stats = self.bins.build(view.grid, n, BOND_CHUNK, |range, sink| {
            project_chunk(scene, view, range, sink)
        });
        let mut stats = BondStats::default();
        for s in &chunk_stats {
            stats.drawn += s.drawn;
            stats.culled += s.culled;
            stats.skipped += s.skipped;
        }
        stats
    }

    /// The records of tile `t`, in bond order.
    #[inline]
    pub(super) fn tile(&self, t: usize) -> &[BondRec] {
        self.bins.tile(t)
    }
}

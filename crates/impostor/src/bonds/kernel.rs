//! Stage 3 of the bond pass: the ray–capped-cylinder intersection over 8 lanes, the depth pass
//! of a tile and the shading of the pixels bonds won (see the parent module).

use super::*;

/// The per-(bond, tile) constants of the intersection, splatted into lanes once.
pub(super) struct BondV {
    pub(super) u: [f32; 3],
    pub(super) n: [f32; 3],
    pub(super) q: [f32; 3],
    /// `a`, the first end point (orthographic rays start on the eye plane, so need `g = o − a`).
    pub(super) a: [f32; 3],
    /// `a·u` and its negation `h(0)` (perspective rays start at the eye).
    pub(super) au: f32,
    pub(super) neg_au: f32,
    pub(super) len: f32,
    pub(super) r2: f32,
    /// Orthographic `A = ux² + uy²` and `d·u = −uz` (the same for every ray).
    pub(super) a_ortho: f32,
    pub(super) du_ortho: f32,
    /// Perspective: 1 where the eye lies inside the infinite cylinder (`|q|² ≤ r²`), else 0.
    pub(super) par_in_persp: f32,
    /// `−ux`; orthographic `gz·uz`, `gz²` and `gz·A` with `gz = −az`.
    pub(super) neg_ux: f32,
    pub(super) gzuz: f32,
    pub(super) gz2: f32,
    pub(super) gza: f32,
    /// The bond's index in the tile's bin (the winner word).
    pub(super) idx: u32,
}

impl BondV {
    /// The constants of `rec`, the `idx`-th record of the bin. Scalars: the kernels splat them
    /// where they are used (an 8-lane value held for a whole bond costs two registers or two
    /// stack slots, and most bonds are rejected by the hierarchical-z test before any use).
    #[inline(always)]
    pub(super) fn new(rec: &BondRec, idx: u32) -> BondV {
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
pub(super) struct Rays<V> {
    /// `A = |d × u|²`.
    pub(super) a: V,
    /// `g·(d × u)` (up to sign): `√A` times the ray–axis distance.
    pub(super) dn: V,
    /// Closest approach `s = num / A`.
    pub(super) num: V,
    /// `h(o)`: axial coordinate of the ray origin, and its negation.
    pub(super) h0: V,
    pub(super) neg_h0: V,
    /// `d·u`.
    pub(super) du: V,
    /// For rays parallel to the axis: 1 where the ray runs inside the infinite cylinder, else 0.
    pub(super) par_in: V,
}

/// A camera's rays over lanes, in two steps: what depends on the row (`y`) once per row, then
/// what depends on the column (`x`) per 8 pixels. Both implementations keep the operations and
/// their order of the one-step form (so the results are bit-identical to it).
pub(super) trait RayGen<V: Lanes8> {
    type Row;
    fn row(b: &BondV, y: V) -> Self::Row;
    fn rays(b: &BondV, r: &Self::Row, x: V) -> Rays<V>;
}

/// Perspective rays: `o = 0`, `d = (x, y, −1)` per lane.
pub(super) struct Persp;

/// The row terms of a perspective ray: `c1 = y·uz + uy` and the products of `y`.
pub(super) struct PerspRow<V> {
    pub(super) c1: V,
    pub(super) yux: V,
    pub(super) yuy: V,
    pub(super) yny: V,
    pub(super) yqy: V,
}

impl<V: Lanes8> RayGen<V> for Persp {
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
pub(super) struct Ortho;

/// The row terms of an orthographic ray: products of `gy = y − ay`.
pub(super) struct OrthoRow<V> {
    pub(super) gyux: V,
    pub(super) gyuy: V,
    pub(super) gy2: V,
}

impl<V: Lanes8> RayGen<V> for Ortho {
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
pub(super) fn solve8<V: Lanes8>(b: &BondV, l: &Rays<V>, lanes: V::Mask, near: V, far: V) -> (V, V) {
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
pub(super) fn solve8_regular<V: Lanes8>(
    b: &BondV,
    l: &Rays<V>,
    lanes: V::Mask,
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
pub(super) fn solve8_general<V: Lanes8>(
    b: &BondV,
    l: &Rays<V>,
    lanes: V::Mask,
    near: V,
    far: V,
) -> (V, V) {
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
pub(super) fn depth_test8<V: Lanes8>(t: V, word: V, depth: &mut [f32], win: &mut [u32]) {
    let d = V::load_from(depth);
    let closer = t.lt(d);
    if closer.bits() == 0 {
        return;
    }
    V::select(closer, t, d).store_to(depth);
    V::select(closer, word, V::load_bits(win)).store_bits(win);
}

/// A tile's bond depth test: the depth buffer starts from the sphere pass.
pub(super) struct TileBuf {
    pub(super) depth: [f32; TILE_BUF],
    pub(super) win: [u32; TILE_BUF],
}

/// Per-frame constants of the tile kernel.
pub(super) struct Kernel<'a> {
    pub(super) view: View,
    /// Run the depth and shading passes on AVX2 lanes (the CPU has them).
    pub(super) avx2: bool,
    /// The specular power of every material when they all share one shininess (else per chunk).
    pub(super) spec_pow: Option<SpecPow>,
    pub(super) lighting: Lighting,
    pub(super) materials: &'a [Material],
}

/// [`Kernel::raster_with`] on SSE2 lanes (the x86-64 baseline, or plain arrays elsewhere).
#[inline(never)]
pub(super) fn raster_sse(
    k: &Kernel,
    recs: &[BondRec],
    x0t: u32,
    y0t: u32,
    w: u32,
    h: u32,
    buf: &mut TileBuf,
) {
    if k.view.ortho {
        k.raster_with::<Ortho, F32x8>(recs, x0t, y0t, w, h, buf);
    } else {
        k.raster_with::<Persp, F32x8>(recs, x0t, y0t, w, h, buf);
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
pub(super) unsafe fn raster_avx2(
    k: &Kernel,
    recs: &[BondRec],
    x0t: u32,
    y0t: u32,
    w: u32,
    h: u32,
    buf: &mut TileBuf,
) {
    if k.view.ortho {
        k.raster_with::<Ortho, F32x8Avx2>(recs, x0t, y0t, w, h, buf);
    } else {
        k.raster_with::<Persp, F32x8Avx2>(recs, x0t, y0t, w, h, buf);
    }
}

/// [`Kernel::resolve_with`] on SSE2 lanes.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(super) fn resolve_sse(
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
    k.resolve_with::<F32x8>(recs, x0t, y0t, w, h, buf, color, depth, stride);
}

/// [`Kernel::resolve_with`] on AVX2 lanes (same IEEE operations, so the same bytes).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(super) unsafe fn resolve_avx2(
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
    k.resolve_with::<F32x8Avx2>(recs, x0t, y0t, w, h, buf, color, depth, stride);
}

impl Kernel<'_> {
    /// Depth pass of one tile over its bin, in bond order.
    pub(super) fn raster(
        &self,
        recs: &[BondRec],
        x0t: u32,
        y0t: u32,
        w: u32,
        h: u32,
        buf: &mut TileBuf,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where `F32x8Avx2::available()` returned true.
            unsafe { raster_avx2(self, recs, x0t, y0t, w, h, buf) };
            return;
        }
        raster_sse(self, recs, x0t, y0t, w, h, buf);
    }

    /// [`Kernel::raster`] with the camera's ray generator chosen outside the loops.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn raster_with<G: RayGen<V>, V: Lanes8>(
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
                let cols = <V::Mask as LaneMask>::first_of_halves(i1 - i0);
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
                        cols.and(<V::Mask as LaneMask>::first(4))
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
                    let lanes = <V::Mask as LaneMask>::first(e - i);
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
    pub(super) fn resolve(
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
            // SAFETY: `avx2` is set only where `F32x8Avx2::available()` returned true.
            unsafe { resolve_avx2(self, recs, x0t, y0t, w, h, buf, color, depth, stride) };
            return;
        }
        resolve_sse(self, recs, x0t, y0t, w, h, buf, color, depth, stride);
    }

    /// [`Kernel::resolve`] on the lanes `V`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn resolve_with<V: Lanes8>(
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
        let enc = lanes::srgb_table32();
        for chunk in list[..n].chunks(LANES8) {
            // Gather the lanes' ray, depth, bond and materials (short chunks repeat their first
            // pixel).
            let mut g = [[0f32; LANES8]; 12];
            let mut flags = [0u32; LANES8];
            let mut kinds = [[0u16; 2]; LANES8];
            for l in 0..LANES8 {
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
            let mut m = [[0f32; LANES8]; 5];
            for l in 0..LANES8 {
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
                None => lanes::spec_pow_of(shin),
            };
            let c = lanes::shade::shade_lanes(
                &self.lighting,
                nrm,
                to_eye,
                [br, bg, bb],
                spec,
                shin,
                pow,
            );
            // sRGB encode over lanes: the 4096-bin table of `linear_to_srgb8` (same bytes).
            let mut px = [0u32; LANES8];
            lanes::srgb_rgba_lanes(c[0], c[1], c[2], enc).store_bits(&mut px);
            for (l, &b) in chunk.iter().enumerate() {
                let (i, j) = (b as usize % TILE as usize, b as usize / TILE as usize);
                let o = j * stride + i;
                color[o] = px[l].to_le_bytes();
                depth[o] = buf.depth[b as usize];
            }
        }
    }
}

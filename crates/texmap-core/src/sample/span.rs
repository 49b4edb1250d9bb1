//! The span sampler's planning (Seed 000 §3, Eq. 8–10): the span extent and level pair, the
//! K x K window each level reads (from the row-major pyramid or through the bank emulator, behind
//! one `WindowSource` trait so both give the same bits), and the per-pixel lerps.

use super::*;

/// Where a span's K x K windows come from: the row-major pyramid (fast path) or the bank
/// emulator (counts reads and conflicts). The per-pixel arithmetic is shared, so both give the
/// same bits.
pub(super) trait WindowSource {
    /// A fetched window.
    type Win;
    /// The window whose corner is texel `(x0, y0)` of `level` (any integers; wrapped).
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> Self::Win;
    /// Texels `(ox, oy), (ox+1, oy), (ox, oy+1), (ox+1, oy+1)` of a fetched window
    /// (offsets from its corner, `ox, oy ≤ K − 2`).
    fn quad(tex: &MipTexture, win: &Self::Win, ox: usize, oy: usize) -> [Vec4; 4];
    /// A texel access fell outside the window.
    fn conflict(&mut self);
}

/// Fast path: a window inside the level is just its corner index in the row-major level (pixels
/// read `corner + oy·w + ox`, no wrap); a window crossing an edge keeps K wrapped column indices
/// and K wrapped row starts. Either way no texel is copied.
pub(super) struct Direct;

/// A window of the fast path.
pub(super) struct DirectWin {
    /// Index of the corner texel when the window lies inside the level, else `usize::MAX`.
    pub(super) corner: usize,
    pub(super) width: usize,
    pub(super) cols: [usize; 4],
    pub(super) rows: [usize; 4],
}

impl WindowSource for Direct {
    type Win = DirectWin;
    #[inline(always)]
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> DirectWin {
        let l = &tex.levels()[level];
        let (w, h) = (l.width as i32, l.height as i32);
        let k = K as i32;
        if x0 >= 0 && y0 >= 0 && x0 + k <= w && y0 + k <= h {
            return DirectWin {
                corner: l.offset + (y0 * w + x0) as usize,
                width: w as usize,
                cols: [0; 4],
                rows: [0; 4],
            };
        }
        let mut cols = [0usize; 4];
        let mut rows = [l.offset; 4];
        for o in 0..K {
            cols[o] = A::wrap(x0 + o as i32, w) as usize;
            rows[o] = l.offset + (A::wrap(y0 + o as i32, h) * w) as usize;
        }
        DirectWin {
            corner: usize::MAX,
            width: w as usize,
            cols,
            rows,
        }
    }
    #[inline(always)]
    fn quad(tex: &MipTexture, win: &DirectWin, ox: usize, oy: usize) -> [Vec4; 4] {
        let t = tex.texels();
        if win.corner != usize::MAX {
            let i = win.corner + oy * win.width + ox;
            [
                texel(t, i),
                texel(t, i + 1),
                texel(t, i + win.width),
                texel(t, i + win.width + 1),
            ]
        } else {
            let (c0, c1) = (win.cols[ox & 3], win.cols[(ox + 1) & 3]);
            let (r0, r1) = (win.rows[oy & 3], win.rows[(oy + 1) & 3]);
            [
                texel(t, r0 + c0),
                texel(t, r0 + c1),
                texel(t, r1 + c0),
                texel(t, r1 + c1),
            ]
        }
    }
    #[inline(always)]
    fn conflict(&mut self) {}
}

/// `⌊v⌋` per lane for finite lanes with `|v| ≤ 2^30`: truncate, then step down where truncation
/// rounded up. SSE2 (baseline on x86_64) converts four lanes at once; other targets use the
/// scalar [`floor_i32`]. Both give the same values.
#[inline(always)]
pub(super) fn floor4(v: Vec4) -> Vec4 {
    let tf = trunc_lanes(v);
    Vec4::select(tf.cmpgt(v), tf - Vec4::ONE, tf)
}

/// Lanes truncated toward zero (finite, `|v| ≤ 2^30`), as floats.
#[inline(always)]
pub(super) fn trunc_lanes(v: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{__m128, _mm_cvtepi32_ps, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            let m: __m128 = v.into();
            Vec4::from(_mm_cvtepi32_ps(_mm_cvttps_epi32(m)))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::from(v.to_array().map(|x| floor_i32(x.abs()) as f32 * x.signum()))
    }
}

/// Integer-valued lanes (`|v| ≤ 2^30`) as `i32`.
#[inline(always)]
pub(super) fn lanes_i32(v: Vec4) -> [i32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{__m128, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of the x86_64 baseline; __m128i and [i32; 4] have the same size
        // and no invalid bit patterns.
        unsafe {
            let m: __m128 = v.into();
            core::mem::transmute::<_, [i32; 4]>(_mm_cvttps_epi32(m))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        v.to_array().map(floor_i32)
    }
}

#[inline(always)]
pub(super) fn lerp4(a: Vec4, b: Vec4, t: Vec4) -> Vec4 {
    a + (b - a) * t
}

/// Replace NaN lanes by 0 and clamp to ±2^30.
#[inline(always)]
pub(super) fn clamp4(v: Vec4) -> Vec4 {
    Vec4::select(v.cmpeq(v), v, Vec4::ZERO)
        .max(Vec4::splat(-COORD_LIMIT))
        .min(Vec4::splat(COORD_LIMIT))
}

/// A span's level decision (Seed 000 Eq. 9) and its lane coordinates.
#[derive(Clone, Copy)]
pub(super) struct SpanPlan {
    pub(super) sx: Vec4,
    pub(super) sy: Vec4,
    pub(super) i0: usize,
    pub(super) i1: usize,
    pub(super) t: f32,
}

/// First half of a span: Eq. (8)'s four pixel images `uv` as lanes, Eq. (9)'s level pair.
#[inline(always)]
pub(super) fn span_plan<A: Addr, const K: usize>(
    tex: &MipTexture,
    uv: [Vec2; 4],
    bias: i32,
) -> SpanPlan {
    let u = Vec4::new(uv[0].x, uv[1].x, uv[2].x, uv[3].x);
    let v = Vec4::new(uv[0].y, uv[1].y, uv[2].y, uv[3].y);
    span_plan_lanes::<A, K>(tex, u, v, bias)
}

/// [`span_plan`] on the images already in lanes (`u`, `v`: pixel `j` in lane `j`).
#[inline(always)]
pub(super) fn span_plan_lanes<A: Addr, const K: usize>(
    tex: &MipTexture,
    u: Vec4,
    v: Vec4,
    bias: i32,
) -> SpanPlan {
    let levels = tex.levels();
    let l0 = &levels[0];
    let last = levels.len() - 1;
    // Level-0 texel coordinates (no half-texel offset yet), one lane per pixel; NaN -> 0.
    let mut sx = clamp4(u * l0.width_f);
    let mut sy = clamp4(v * l0.height_f);
    // Repeat: shift the whole span by whole periods so its corner lies in the first period.
    if A::REPEAT {
        let px = floor_i32(sx.min_element() * l0.inv_width_f) as f32 * l0.width_f;
        let py = floor_i32(sy.min_element() * l0.inv_height_f) as f32 * l0.height_f;
        sx -= Vec4::splat(px);
        sy -= Vec4::splat(py);
    }
    // Seed 000 Eq. (9): span level from the extent of the four images (level-0 texels).
    let ext = (sx.max_element() - sx.min_element()).max(sy.max_element() - sy.min_element());
    let (i0, i1, t) = span_levels::<K>(ext, last, bias);
    SpanPlan { sx, sy, i0, i1, t }
}

/// Eq. (9)'s level pair `(i0, i1)` and blend weight of a span whose images span `ext` level-0
/// texels, clamped to the pyramid (`last`: its top level); K = 3 takes the pair one level
/// coarser (the module doc's level policy).
#[inline(always)]
pub(super) fn span_levels<const K: usize>(ext: f32, last: usize, bias: i32) -> (usize, usize, f32) {
    let shift = if K == 3 { 1 } else { 0 };
    // Exact ⌊λ⌋ from the exponent (0 and subnormals give −127), frac(λ) from the mantissa.
    let (e, frac) = log2_split(ext);
    let fine = e + shift + bias;
    if fine < 0 {
        (0, 0, 0.0)
    } else if fine as usize >= last {
        (last, last, 0.0)
    } else {
        (fine as usize, fine as usize + 1, frac)
    }
}

/// Second half of a span: Eq. (10)'s window per level and Eq. (4)'s per-pixel blend.
#[inline(always)]
pub(super) fn span_finish<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    p: SpanPlan,
    src: &mut S,
) -> [Vec4; 4] {
    let a = span_level::<A, S, K>(tex, p.i0, p.sx, p.sy, src);
    if p.i1 == p.i0 || p.t == 0.0 {
        return a;
    }
    let b = span_level::<A, S, K>(tex, p.i1, p.sx, p.sy, src);
    let mut out = a;
    for j in 0..4 {
        out[j] = lerp(a[j], b[j], p.t);
    }
    out
}

/// One span (Seed 000 §3): [`span_plan`] then [`span_finish`].
#[inline(always)]
pub(super) fn span_quad<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    uv: [Vec2; 4],
    bias: i32,
    src: &mut S,
) -> [Vec4; 4] {
    span_finish::<A, S, K>(tex, span_plan::<A, K>(tex, uv, bias), src)
}

/// Many spans, software-pipelined: the level decision of span `n + 1` is issued before the texel
/// work of span `n`, so the two dependency chains overlap (one span alone is latency-bound).
#[inline(always)]
pub(super) fn span_quads<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) {
    let n = quads.len().min(out.len());
    if n == 0 {
        return;
    }
    let mut next = span_plan::<A, K>(tex, quads[0], 0);
    for i in 0..n {
        let cur = next;
        if i + 1 < n {
            next = span_plan::<A, K>(tex, quads[i + 1], 0);
        }
        out[i] = span_finish_direct::<A, K>(tex, cur);
    }
}

/// One level of a span on the fast path, set up for [`span_finish_direct`]: when every pixel's
/// bilinear neighbourhood lies in a K x K window inside the level (the common case), the window
/// corner's index and each pixel's offset from it (`oy·w + ox`), else `None`.
pub(super) struct DirectLevel {
    pub(super) corner: usize,
    pub(super) width: usize,
    pub(super) idx: [i32; 4],
    pub(super) ax: Vec4,
    pub(super) ay: Vec4,
}

/// Seed 000 Eq. (10) for the fast path: the level's texel coordinates, floors and weights
/// exactly as [`span_level`] computes them, and the interior window if there is one.
#[inline(always)]
pub(super) fn direct_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
) -> Option<DirectLevel> {
    let l = &tex.levels()[level];
    let mut x = sx * l.scale_x - Vec4::splat(0.5);
    let mut y = sy * l.scale_y - Vec4::splat(0.5);
    if !A::REPEAT {
        x = x.max(Vec4::ZERO).min(Vec4::splat(l.width_f - 1.0));
        y = y.max(Vec4::ZERO).min(Vec4::splat(l.height_f - 1.0));
    }
    let (flx, fly) = (floor4(x), floor4(y));
    let (mx, my) = (flx.min_element(), fly.min_element());
    let (ox, oy) = (flx - Vec4::splat(mx), fly - Vec4::splat(my));
    let lim = Vec4::splat((K - 2) as f32);
    // SAFETY: mx, my are floors of lanes clamped to ±2^30: integer-valued and within i32.
    let (x0, y0): (i32, i32) = unsafe { (mx.to_int_unchecked(), my.to_int_unchecked()) };
    let (w, h) = (l.width as i32, l.height as i32);
    let k = K as i32;
    if (ox.cmpgt(lim) | oy.cmpgt(lim)).any() || x0 < 0 || y0 < 0 || x0 + k > w || y0 + k > h {
        return None;
    }
    Some(DirectLevel {
        corner: l.offset + (y0 * w + x0) as usize,
        width: w as usize,
        // oy·w + ox: small non-negative integers, exact in f32 (w ≤ 2^14, oy ≤ 2).
        idx: lanes_i32(oy * Vec4::splat(l.width_f) + ox),
        ax: x - flx,
        ay: y - fly,
    })
}

/// Bilinear of pixel `j` from an interior window (Eq. 4 weights, the arithmetic of
/// [`span_level`]).
#[inline(always)]
pub(super) fn direct_pixel(t: &[Vec4], d: &DirectLevel, ax: Vec4, ay: Vec4, j: usize) -> Vec4 {
    let i = d.corner + d.idx[j] as usize;
    let t00 = texel(t, i);
    let t10 = texel(t, i + 1);
    let t01 = texel(t, i + d.width);
    let t11 = texel(t, i + d.width + 1);
    lerp4(lerp4(t00, t10, ax), lerp4(t01, t11, ax), ay)
}

/// [`span_finish`] for the fast path with both levels fused per pixel: when both windows are
/// interior, each pixel reads its 2x2 on each level and blends, results staying in registers.
/// Bit-identical to [`span_finish`] (same operations in the same order); other spans take it.
#[inline(always)]
pub(super) fn span_finish_direct<A: Addr, const K: usize>(
    tex: &MipTexture,
    p: SpanPlan,
) -> [Vec4; 4] {
    let t = tex.texels();
    let Some(a) = direct_level::<A, K>(tex, p.i0, p.sx, p.sy) else {
        return span_finish::<A, Direct, K>(tex, p, &mut Direct);
    };
    let axs = [a.ax.xxxx(), a.ax.yyyy(), a.ax.zzzz(), a.ax.wwww()];
    let ays = [a.ay.xxxx(), a.ay.yyyy(), a.ay.zzzz(), a.ay.wwww()];
    let mut out = [Vec4::ZERO; 4];
    if p.i1 == p.i0 || p.t == 0.0 {
        for j in 0..4 {
            out[j] = direct_pixel(t, &a, axs[j], ays[j], j);
        }
        return out;
    }
    let Some(b) = direct_level::<A, K>(tex, p.i1, p.sx, p.sy) else {
        return span_finish::<A, Direct, K>(tex, p, &mut Direct);
    };
    let bxs = [b.ax.xxxx(), b.ax.yyyy(), b.ax.zzzz(), b.ax.wwww()];
    let bys = [b.ay.xxxx(), b.ay.yyyy(), b.ay.zzzz(), b.ay.wwww()];
    let tt = Vec4::splat(p.t);
    for j in 0..4 {
        let ca = direct_pixel(t, &a, axs[j], ays[j], j);
        let cb = direct_pixel(t, &b, bxs[j], bys[j], j);
        out[j] = lerp4(ca, cb, tt);
    }
    out
}

/// The four bilinear samples of one level from ONE window read.
#[inline(always)]
pub(super) fn span_level<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
    src: &mut S,
) -> [Vec4; 4] {
    let l = &tex.levels()[level];
    // This level's texel coordinates, texel centres at integers (Eq. 3 applied to 2^L r_m − ½).
    let mut x = sx * l.scale_x - Vec4::splat(0.5);
    let mut y = sy * l.scale_y - Vec4::splat(0.5);
    if !A::REPEAT {
        // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
        x = x.max(Vec4::ZERO).min(Vec4::splat(l.width_f - 1.0));
        y = y.max(Vec4::ZERO).min(Vec4::splat(l.height_f - 1.0));
    }
    let (flx, fly) = (floor4(x), floor4(y));
    let (ax, ay) = (x - flx, y - fly);
    let (mx, my) = (flx.min_element(), fly.min_element());
    // SAFETY: mx, my are floors of lanes clamped to ±2^30: integer-valued and within i32, so
    // truncation is exact.
    let (x0, y0): (i32, i32) = unsafe { (mx.to_int_unchecked(), my.to_int_unchecked()) };
    // Offsets of each pixel's texel from the window corner (small integers, exact in f32).
    let (ox, oy) = (flx - Vec4::splat(mx), fly - Vec4::splat(my));
    // Seed 000 Eq. (10): one parallel read of the K x K window at corner (x0, y0).
    let win = src.window::<A, K>(tex, level, x0, y0);
    let lim = (K - 2) as f32;
    let (oxi, oyi) = (lanes_i32(ox), lanes_i32(oy));
    if ox.max_element() <= lim && oy.max_element() <= lim {
        // Every bilinear neighbourhood lies in the window (the level policy's guarantee).
        let axs = [ax.xxxx(), ax.yyyy(), ax.zzzz(), ax.wwww()];
        let ays = [ay.xxxx(), ay.yyyy(), ay.zzzz(), ay.wwww()];
        // (A plain loop: `<[_; 4]>::map` does not inline here and cost 2x.)
        let mut out = [Vec4::ZERO; 4];
        for j in 0..4 {
            let [t00, t10, t01, t11] = S::quad(tex, &win, oxi[j] as usize, oyi[j] as usize);
            out[j] = lerp4(lerp4(t00, t10, axs[j]), lerp4(t01, t11, axs[j]), ays[j]);
        }
        return out;
    }
    let lim = K as i32 - 2;
    let mut out = [Vec4::ZERO; 4];
    for j in 0..4 {
        let (mut ox, mut oy) = (oxi[j], oyi[j]);
        if ox > lim || oy > lim {
            // Fold repeat-wrapped offsets on narrow levels back into the window (same texel).
            if A::REPEAT {
                if ox > lim {
                    ox = ox.rem_euclid(l.width as i32);
                }
                if oy > lim {
                    oy = oy.rem_euclid(l.height as i32);
                }
            }
            if ox > lim || oy > lim {
                // A bank conflict: the policy makes this unreachable; serve it from memory.
                src.conflict();
                out[j] = bilinear::<A>(
                    tex.texels(),
                    l,
                    Vec2::new((x[j] + 0.5) / l.width_f, (y[j] + 0.5) / l.height_f),
                );
                continue;
            }
        }
        let [t00, t10, t01, t11] = S::quad(tex, &win, ox as usize, oy as usize);
        let (axj, ayj) = (Vec4::splat(ax[j]), Vec4::splat(ay[j]));
        out[j] = lerp4(lerp4(t00, t10, axj), lerp4(t01, t11, axj), ayj);
    }
    out
}

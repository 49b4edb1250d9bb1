//! Triangle set-up and the 2x2-quad tile rasteriser.
//!
//! Coverage is decided exactly in fixed point ([`SUB_BITS`](crate::project::SUB_BITS) = 8
//! fractional bits, i64 edge functions), with the top-left fill rule: a pixel centre exactly on
//! an edge belongs to the triangle only if that edge is a top edge (horizontal, interior below)
//! or a left edge. Two triangles sharing an edge therefore never both cover, nor both miss, a
//! pixel centre on it.
//!
//! Attributes use plane equations in screen space: `1/W`, `depth/W` and every `varying/W` are
//! affine in (x, y); per pixel, `W = 1 / (1/W)` recovers depth and the perspective-correct
//! varyings (the perspective-correct form of Seed 000 Eq. 1: `z⁻¹` is affine on the screen).

use texmap_core::lanes::{F32x4, I32x4};

use crate::framebuffer::{TILE, Tile, quad_index};
use crate::program::{FragProgram, QuadFrag};
use crate::project::{MAX_VAR, PVert, SUB_BITS, Var};
use crate::state::{Blend, Cull, DepthTest, DrawState};

/// What the quad loop needs besides the triangle.
#[derive(Clone, Copy)]
pub(crate) struct RasterCtx {
    pub state: DrawState,
    pub far: f32,
    pub width: u32,
    pub height: u32,
    /// Whether small triangles take the block path (`false` only in tests comparing the paths).
    pub block_path: bool,
    /// The depth test of `state` as lane masks.
    zt: ZTest,
}

impl RasterCtx {
    pub fn new(state: DrawState, far: f32, width: u32, height: u32, block_path: bool) -> Self {
        RasterCtx {
            state,
            far,
            width,
            height,
            block_path,
            zt: ZTest::new(state, far),
        }
    }
}

/// Twice the signed area of a fixed-point triangle (y down): positive when the vertices run
/// clockwise on screen, i.e. the triangle is back-facing.
#[inline]
pub(crate) fn area2(v: &[PVert; 3]) -> i64 {
    let (x0, y0) = (v[0].x as i64, v[0].y as i64);
    (v[1].x as i64 - x0) * (v[2].y as i64 - y0) - (v[1].y as i64 - y0) * (v[2].x as i64 - x0)
}

/// Whether a triangle of signed area `a` (see [`area2`]) survives culling; `Some(front)`.
#[inline]
pub(crate) fn facing(a: i64, cull: Cull) -> Option<bool> {
    if a == 0 {
        return None;
    }
    let front = a < 0;
    match cull {
        Cull::None => Some(front),
        Cull::Back => front.then_some(true),
        Cull::Front => (!front).then_some(false),
    }
}

#[inline]
fn ceil_px(a: i64) -> i64 {
    // Smallest pixel i whose centre i*256 + 128 >= a.
    -((128 - a) >> 8)
}

#[inline]
fn floor_px(a: i64) -> i64 {
    // Largest pixel i whose centre i*256 + 128 <= a.
    (a - 128) >> 8
}

/// The inclusive pixel rectangle of the pixel centres inside the triangle's bounding box,
/// clipped to the image; `None` if it holds no pixel centre.
#[inline]
pub(crate) fn pixel_bounds(v: &[PVert; 3], width: u32, height: u32) -> Option<[i32; 4]> {
    let minx = v[0].x.min(v[1].x).min(v[2].x) as i64;
    let maxx = v[0].x.max(v[1].x).max(v[2].x) as i64;
    let miny = v[0].y.min(v[1].y).min(v[2].y) as i64;
    let maxy = v[0].y.max(v[1].y).max(v[2].y) as i64;
    let x0 = ceil_px(minx).max(0);
    let x1 = floor_px(maxx).min(width as i64 - 1);
    let y0 = ceil_px(miny).max(0);
    let y1 = floor_px(maxy).min(height as i64 - 1);
    (x0 <= x1 && y0 <= y1).then_some([x0 as i32, y0 as i32, x1 as i32, y1 as i32])
}

/// A plane `f(x, y) = base + gx·(x − x_start) + gy·(y − y_start)` over pixel offsets from the
/// first quad's top-left pixel.
#[derive(Clone, Copy, Default)]
struct Plane {
    base: f32,
    gx: f32,
    gy: f32,
}

impl Plane {
    /// The plane at four pixel offsets: `base + gx·fx + gy·fy` lane by lane (no FMA).
    #[inline(always)]
    fn eval4(&self, fx: F32x4, fy: F32x4) -> F32x4 {
        F32x4::splat(self.base)
            .add(F32x4::splat(self.gx).mul(fx))
            .add(F32x4::splat(self.gy).mul(fy))
    }
}

/// Rasterise one triangle into one tile. `v` must be oriented with [`area2`] > 0 (the caller
/// swaps vertices 1 and 2 of front faces), `var` the matching varyings.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn raster_tri<P: FragProgram>(
    tile: &mut Tile,
    ctx: &RasterCtx,
    prog: &P,
    cst: &P::TriConst,
    v: &[PVert; 3],
    var: &[Var; 3],
    front: bool,
) {
    let area = area2(v);
    debug_assert!(area > 0);
    // Pixel range: the bounding box's pixel centres, clipped to this tile and the image.
    let Some([bx0, by0, bx1, by1]) = pixel_bounds(v, ctx.width, ctx.height) else {
        return;
    };
    let xl = ((tile.x0 + TILE).min(ctx.width) - 1) as i32;
    let yl = ((tile.y0 + TILE).min(ctx.height) - 1) as i32;
    let px0 = bx0.max(tile.x0 as i32);
    let py0 = by0.max(tile.y0 as i32);
    let px1 = bx1.min(xl);
    let py1 = by1.min(yl);
    if px0 > px1 || py0 > py1 {
        return;
    }
    // Align the start to the quad grid (tile origins are even, so this stays in the tile).
    let px0 = px0 & !1;
    let py0 = py0 & !1;

    // Plane equations (set up in f64, evaluated in f32 relative to the first quad).
    let fx0 = v[0].x as f64 / 256.0;
    let fy0 = v[0].y as f64 / 256.0;
    let d1x = (v[1].x - v[0].x) as f64 / 256.0;
    let d1y = (v[1].y - v[0].y) as f64 / 256.0;
    let d2x = (v[2].x - v[0].x) as f64 / 256.0;
    let d2y = (v[2].y - v[0].y) as f64 / 256.0;
    let inv_det = 1.0 / (d1x * d2y - d2x * d1y);
    let ox = px0 as f64 + 0.5 - fx0;
    let oy = py0 as f64 + 0.5 - fy0;
    let plane = |f0: f64, f1: f64, f2: f64| -> Plane {
        let gx = ((f1 - f0) * d2y - (f2 - f0) * d1y) * inv_det;
        let gy = ((f2 - f0) * d1x - (f1 - f0) * d2x) * inv_det;
        Plane {
            base: (f0 + gx * ox + gy * oy) as f32,
            gx: gx as f32,
            gy: gy as f32,
        }
    };
    let q = [v[0].q as f64, v[1].q as f64, v[2].q as f64];
    let p_q = plane(q[0], q[1], q[2]);
    // Perspective vertices carry depth/W = 1 exactly: the depth plane is then the constant 1
    // (gradients ±0, base 1) and depth = W, so the plane is skipped with identical results.
    let dw_one = v[0].dw == 1.0 && v[1].dw == 1.0 && v[2].dw == 1.0;
    let p_dw = if dw_one {
        Plane {
            base: 1.0,
            gx: 0.0,
            gy: 0.0,
        }
    } else {
        plane(v[0].dw as f64, v[1].dw as f64, v[2].dw as f64)
    };
    let mut p_var = [Plane::default(); MAX_VAR];
    for k in 0..P::NV {
        p_var[k] = plane(
            var[0][k] as f64 * q[0],
            var[1][k] as f64 * q[1],
            var[2][k] as f64 * q[2],
        );
    }
    let setup = Setup {
        px0,
        py0,
        px1,
        py1,
        xl,
        yl,
        p_q,
        p_dw,
        dw_one,
        p_var,
    };
    // Small-triangle fast path: a triangle at most TINY_SPAN across whose pixel range in this
    // tile fits one block. Its edge functions (|dx|, |dy| <= 16 px; pixel centres of the block
    // at most 16 + 2 + 8 px from a vertex) stay below 2 · 4096 · 26 · 256 < 2^26 in magnitude:
    // set up and evaluated exactly in i32.
    if ctx.block_path
        && px1 - px0 < BLOCK as i32
        && py1 - py0 < BLOCK as i32
        && tri_span(v) <= TINY_SPAN
    {
        let sx = px0 * 256 + 128;
        let sy = py0 * 256 + 128;
        let mut e_row = [0i32; 3];
        let mut step_x = [0i32; 3];
        let mut step_y = [0i32; 3];
        for i in 0..3 {
            let a = v[(i + 1) % 3];
            let b = v[(i + 2) % 3];
            let dx = b.x - a.x;
            let dy = b.y - a.y;
            let top_left = (dy == 0 && dx > 0) || dy < 0;
            let bias = if top_left { 0 } else { -1 };
            e_row[i] = dx * (sy - a.y) - dy * (sx - a.x) + bias;
            step_x[i] = -dy * 256;
            step_y[i] = dx * 256;
        }
        block_loop::<P>(tile, ctx, prog, cst, front, &setup, e_row, step_x, step_y);
        return;
    }

    // Edge functions E_i (edge opposite vertex i), top-left rule as a bias of −1 on the others.
    let sx = (px0 as i64) * 256 + 128;
    let sy = (py0 as i64) * 256 + 128;
    let mut e_row = [0i64; 3];
    let mut step_x = [0i64; 3];
    let mut step_y = [0i64; 3];
    for i in 0..3 {
        let a = v[(i + 1) % 3];
        let b = v[(i + 2) % 3];
        let dx = b.x as i64 - a.x as i64;
        let dy = b.y as i64 - a.y as i64;
        let top_left = (dy == 0 && dx > 0) || dy < 0;
        let bias = if top_left { 0 } else { -1 };
        e_row[i] = dx * (sy - a.y as i64) - dy * (sx - a.x as i64) + bias;
        step_x[i] = -dy * 256;
        step_y[i] = dx * 256;
    }
    // Edge values stay within i32 when every pixel centre the loop can reach (the quad-aligned
    // range plus one step past it) has |E| < 2^30: E is affine, so checking the corners suffices.
    // Small triangles (the common case) then run on 32-bit lanes, twice as wide per register.
    let reach = |i: usize, cx: i64, cy: i64| (e_row[i] + cx * step_x[i] + cy * step_y[i]).abs();
    let (ex, ey) = ((px1 - px0 + 3) as i64, (py1 - py0 + 3) as i64);
    let small = (0..3).all(|i| {
        reach(i, 0, 0)
            .max(reach(i, ex, 0))
            .max(reach(i, 0, ey))
            .max(reach(i, ex, ey))
            < (1 << 30)
    });
    let cv = |a: [i64; 3]| a.map(|x| x as i32);
    if small {
        quad_loop::<P, i32>(
            tile,
            ctx,
            prog,
            cst,
            front,
            &setup,
            cv(e_row),
            cv(step_x),
            cv(step_y),
        );
    } else {
        quad_loop::<P, i64>(tile, ctx, prog, cst, front, &setup, e_row, step_x, step_y);
    }
}

/// Side in pixels of the block the small-triangle path covers in one go.
pub(crate) const BLOCK: u32 = 8;
/// Largest bounding-box side (fixed point: 16 pixels) of a triangle on the small-triangle path.
const TINY_SPAN: i32 = 16 << SUB_BITS;

/// The larger side of a triangle's fixed-point bounding box.
#[inline]
fn tri_span(v: &[PVert; 3]) -> i32 {
    let w = v[0].x.max(v[1].x).max(v[2].x) - v[0].x.min(v[1].x).min(v[2].x);
    let h = v[0].y.max(v[1].y).max(v[2].y) - v[0].y.min(v[1].y).min(v[2].y);
    w.max(h)
}

/// What the quad loop needs from the triangle set-up.
struct Setup {
    px0: i32,
    py0: i32,
    px1: i32,
    py1: i32,
    /// Last pixel column / row of the tile inside the image.
    xl: i32,
    yl: i32,
    p_q: Plane,
    p_dw: Plane,
    /// `p_dw` is the constant 1 (depth = W).
    dw_one: bool,
    p_var: [Plane; MAX_VAR],
}

/// Integer lanes for the edge functions (i32 for small triangles, i64 otherwise).
trait EdgeInt:
    Copy + Default + std::ops::Add<Output = Self> + std::ops::BitOr<Output = Self> + PartialOrd
{
    const ZERO: Self;
}
impl EdgeInt for i32 {
    const ZERO: Self = 0;
}
impl EdgeInt for i64 {
    const ZERO: Self = 0;
}

/// The depth test as lane masks, so that the per-quad test is branch-free:
/// `pass = (d < stored) | (eq & d == stored) | always`, then `0 < d <= far`.
#[derive(Clone, Copy)]
struct ZTest {
    eq: F32x4,
    always: F32x4,
    far: F32x4,
}

impl ZTest {
    fn new(state: DrawState, far: f32) -> ZTest {
        let flag = |b: bool| F32x4::from_bits(if b { 0b1111 } else { 0 });
        ZTest {
            eq: flag(state.depth_test == DepthTest::LessEqual),
            always: flag(state.depth_test == DepthTest::Always),
            far: F32x4::splat(far),
        }
    }

    /// Lanes of `depth` that pass against `stored` (NaN and out-of-range depths fail).
    #[inline(always)]
    fn mask(&self, d: F32x4, stored: F32x4) -> u8 {
        let pass = d
            .lt(stored)
            .or(self.eq.and(d.eq(stored)))
            .or(self.always)
            .and(F32x4::splat(0.0).lt(d))
            .and(d.le(self.far));
        pass.bits() as u8
    }
}

/// Depth-test, shade and write the quad whose top-left pixel is (qx, qy), lanes `mask` covered.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn shade_quad<P: FragProgram>(
    tile: &mut Tile,
    st: DrawState,
    zt: &ZTest,
    prog: &P,
    cst: &P::TriConst,
    front: bool,
    s: &Setup,
    qx: i32,
    qy: i32,
    mut mask: u8,
) {
    let qi = quad_index(qx as u32 - tile.x0, qy as u32 - tile.y0);
    let fxb = (qx - s.px0) as f32;
    let fyb = (qy - s.py0) as f32;
    let fx = F32x4::splat(fxb).add(F32x4::new([0.0, 1.0, 0.0, 1.0]));
    let fy = F32x4::splat(fyb).add(F32x4::new([0.0, 0.0, 1.0, 1.0]));
    // Perspective division: W = 1 / (1/W), depth = (depth/W)·W.
    let w = F32x4::splat(1.0).div(s.p_q.eval4(fx, fy));
    let depth = if s.dw_one {
        w
    } else {
        s.p_dw.eval4(fx, fy).mul(w)
    };
    // Depth test (NaN and out-of-range depths fail every comparison).
    mask &= zt.mask(depth, F32x4::new(tile.depth[qi]));
    if mask == 0 {
        return;
    }
    // Perspective-correct varyings.
    let mut frag = QuadFrag {
        x: [
            qx as f32 + 0.5,
            qx as f32 + 1.5,
            qx as f32 + 0.5,
            qx as f32 + 1.5,
        ],
        y: [
            qy as f32 + 0.5,
            qy as f32 + 0.5,
            qy as f32 + 1.5,
            qy as f32 + 1.5,
        ],
        var: [[0.0; 4]; MAX_VAR],
        depth: depth.to_array(),
        mask,
    };
    for k in 0..P::NV {
        frag.var[k] = s.p_var[k].eval4(fx, fy).mul(w).to_array();
    }
    let c = prog.shade(cst, &frag, front);
    write_quad(tile, qi, mask, &frag.depth, &c, st);
}

/// The small-triangle path: coverage of the whole pixel range (at most [`BLOCK`] x [`BLOCK`],
/// starting on the quad grid) as one bit mask per row, eight lanes per edge and row, then only
/// the quads with a covered pixel are visited. Same edge values, same fill rule and same plane
/// origin as [`quad_loop`], so the pixels (coverage, depth, colour) are identical.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn block_loop<P: FragProgram>(
    tile: &mut Tile,
    ctx: &RasterCtx,
    prog: &P,
    cst: &P::TriConst,
    front: bool,
    s: &Setup,
    e_row: [i32; 3],
    step_x: [i32; 3],
    step_y: [i32; 3],
) {
    const B: usize = BLOCK as usize;
    let ncols = (s.px1 - s.px0 + 1) as u32;
    let nrows = (s.py1 - s.py0 + 1) as usize;
    debug_assert!(ncols as usize <= B && nrows <= B);
    // Columns past the range lie outside the triangle's bounding box or outside this tile.
    let col_ok = ((1u32 << ncols) - 1) as u8;
    // Edge values of the first row at the eight columns (two 4-lane halves). Lanes past the
    // range may wrap (they are masked out); lanes inside it are exact (|E| < 2^30, checked by
    // the caller).
    let half = |i: usize, c0: i32| {
        I32x4::new([0, 1, 2, 3].map(|l| e_row[i].wrapping_add(step_x[i].wrapping_mul(c0 + l))))
    };
    let mut lo = [half(0, 0), half(1, 0), half(2, 0)];
    let mut hi = [half(0, 4), half(1, 4), half(2, 4)];
    let dy = step_y.map(I32x4::splat);
    // Row masks: bit c = pixel (px0 + c, py0 + r) covered (every edge function >= 0).
    let mut rows = [0u8; B + 1];
    for row in rows.iter_mut().take(nrows) {
        let neg =
            lo[0].or(lo[1]).or(lo[2]).neg_bits() | (hi[0].or(hi[1]).or(hi[2]).neg_bits() << 4);
        *row = !(neg as u8) & col_ok;
        for i in 0..3 {
            lo[i] = lo[i].add(dy[i]);
            hi[i] = hi[i].add(dy[i]);
        }
    }
    let st = ctx.state;
    let zt = ctx.zt;
    // Visit the covered quads, row pair by row pair, left to right.
    for j in 0..nrows.div_ceil(2) {
        let (r0, r1) = (rows[2 * j] as u32, rows[2 * j + 1] as u32);
        let any = r0 | r1;
        let mut pairs = (any | (any >> 1)) & 0x55;
        while pairs != 0 {
            let b = pairs.trailing_zeros();
            pairs &= pairs - 1;
            let mask = (((r0 >> b) & 3) | (((r1 >> b) & 3) << 2)) as u8;
            shade_quad(
                tile,
                st,
                &zt,
                prog,
                cst,
                front,
                s,
                s.px0 + b as i32,
                s.py0 + 2 * j as i32,
                mask,
            );
        }
    }
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn quad_loop<P: FragProgram, E: EdgeInt>(
    tile: &mut Tile,
    ctx: &RasterCtx,
    prog: &P,
    cst: &P::TriConst,
    front: bool,
    s: &Setup,
    mut e_row: [E; 3],
    step_x: [E; 3],
    step_y: [E; 3],
) {
    let Setup {
        px0,
        py0,
        px1,
        py1,
        xl,
        yl,
        ..
    } = *s;
    // Lane offsets of the quad (0,0), (1,0), (0,1), (1,1), and steps of two pixels.
    let lane_off = |i: usize| [E::ZERO, step_x[i], step_y[i], step_x[i] + step_y[i]];
    let off = [lane_off(0), lane_off(1), lane_off(2)];
    let step2_x = step_x.map(|v| v + v);
    let step2_y = step_y.map(|v| v + v);
    let st = ctx.state;
    let zt = ctx.zt;
    let mut qy = py0;
    while qy <= py1 {
        let mut e = e_row;
        let row_mask: u8 = if qy + 1 > yl { 0b0011 } else { 0b1111 };
        let mut qx = px0;
        while qx <= px1 {
            // Coverage of the four lanes: every edge function >= 0 (sign bits OR-ed).
            let mut mask = 0u8;
            // `l` is the lane of three offset rows and the mask bit: a range reads best.
            #[allow(clippy::needless_range_loop)]
            for l in 0..4 {
                let s = (e[0] + off[0][l]) | (e[1] + off[1][l]) | (e[2] + off[2][l]);
                mask |= ((s >= E::ZERO) as u8) << l;
            }
            let col_mask: u8 = if qx + 1 > xl { 0b0101 } else { 0b1111 };
            mask &= row_mask & col_mask;
            if mask != 0 {
                shade_quad(tile, st, &zt, prog, cst, front, s, qx, qy, mask);
            }
            for i in 0..3 {
                e[i] = e[i] + step2_x[i];
            }
            qx += 2;
        }
        for i in 0..3 {
            e_row[i] = e_row[i] + step2_y[i];
        }
        qy += 2;
    }
}

/// Write the masked lanes of quad `qi` of a tile (a select per lane, no per-lane branch; the
/// depth-write and blend modes are chosen once per quad).
#[inline]
pub(crate) fn write_quad(
    tile: &mut Tile,
    qi: usize,
    mask: u8,
    depth: &[f32; 4],
    c: &[[f32; 4]; 3],
    st: DrawState,
) {
    let on = F32x4::from_bits(mask);
    if st.depth_write {
        let d = &mut tile.depth[qi];
        *d = F32x4::select(on, F32x4::new(*depth), F32x4::new(*d)).to_array();
    }
    let planes = [&mut tile.r, &mut tile.g, &mut tile.b];
    for (plane, c) in planes.into_iter().zip(c) {
        let p = &mut plane[qi];
        let old = F32x4::new(*p);
        let c = F32x4::new(*c);
        let new = match st.blend {
            Blend::Replace => c,
            Blend::Add => old.add(c),
        };
        *p = F32x4::select(on, new, old).to_array();
    }
}

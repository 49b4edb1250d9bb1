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

use crate::framebuffer::{QUADS_PER_ROW, TILE, Tile};
use crate::program::{FragProgram, QuadFrag};
use crate::project::{MAX_VAR, PVert, Var};
use crate::state::{Blend, Cull, DepthTest, DrawState};

/// What the quad loop needs besides the triangle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RasterCtx {
    pub state: DrawState,
    pub far: f32,
    pub width: u32,
    pub height: u32,
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
    #[inline]
    fn eval(&self, fx: &[f32; 4], fy: &[f32; 4]) -> [f32; 4] {
        let mut o = [0.0; 4];
        for l in 0..4 {
            o[l] = self.base + self.gx * fx[l] + self.gy * fy[l];
        }
        o
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
    let p_dw = plane(v[0].dw as f64, v[1].dw as f64, v[2].dw as f64);
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
        p_var,
    };
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
    if small {
        let cv = |a: [i64; 3]| a.map(|x| x as i32);
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
        p_q,
        p_dw,
        ref p_var,
    } = *s;
    // Lane offsets of the quad (0,0), (1,0), (0,1), (1,1), and steps of two pixels.
    let lane_off = |i: usize| [E::ZERO, step_x[i], step_y[i], step_x[i] + step_y[i]];
    let off = [lane_off(0), lane_off(1), lane_off(2)];
    let step2_x = step_x.map(|v| v + v);
    let step2_y = step_y.map(|v| v + v);
    let st = ctx.state;
    let far = ctx.far;
    let mut qy = py0;
    while qy <= py1 {
        let mut e = e_row;
        let row_mask: u8 = if qy + 1 > yl { 0b0011 } else { 0b1111 };
        let fy_base = (qy - py0) as f32;
        let fy = [fy_base, fy_base, fy_base + 1.0, fy_base + 1.0];
        let ly = qy as u32 - tile.y0;
        let mut qx = px0;
        while qx <= px1 {
            // Coverage of the four lanes: every edge function >= 0 (sign bits OR-ed).
            let mut mask = 0u8;
            for l in 0..4 {
                let s = (e[0] + off[0][l]) | (e[1] + off[1][l]) | (e[2] + off[2][l]);
                mask |= ((s >= E::ZERO) as u8) << l;
            }
            let col_mask: u8 = if qx + 1 > xl { 0b0101 } else { 0b1111 };
            mask &= row_mask & col_mask;
            if mask != 0 {
                let lx = qx as u32 - tile.x0;
                let base = ((ly >> 1) as usize * QUADS_PER_ROW + (lx >> 1) as usize) << 2;
                let fxb = (qx - px0) as f32;
                let fx = [fxb, fxb + 1.0, fxb, fxb + 1.0];
                // Perspective division: W = 1 / (1/W), depth = (depth/W)·W.
                let qv = p_q.eval(&fx, &fy);
                let dwv = p_dw.eval(&fx, &fy);
                let mut w = [0.0f32; 4];
                let mut depth = [0.0f32; 4];
                for l in 0..4 {
                    w[l] = 1.0 / qv[l];
                    depth[l] = dwv[l] * w[l];
                }
                // Depth test (NaN and out-of-range depths fail every comparison below).
                let stored = &tile.depth[base..base + 4];
                let mut zmask = 0u8;
                for l in 0..4 {
                    let d = depth[l];
                    let pass = match st.depth_test {
                        DepthTest::Less => d < stored[l],
                        DepthTest::LessEqual => d <= stored[l],
                        DepthTest::Always => true,
                    } && d > 0.0
                        && d <= far;
                    zmask |= (pass as u8) << l;
                }
                mask &= zmask;
                if mask != 0 {
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
                        mask,
                    };
                    for k in 0..P::NV {
                        let pv = p_var[k].eval(&fx, &fy);
                        for l in 0..4 {
                            frag.var[k][l] = pv[l] * w[l];
                        }
                    }
                    let c = prog.shade(cst, &frag, front);
                    write_quad(tile, base, mask, &depth, &c, st);
                }
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

/// Write the masked lanes of a quad at tile index `base`.
#[inline]
pub(crate) fn write_quad(
    tile: &mut Tile,
    base: usize,
    mask: u8,
    depth: &[f32; 4],
    c: &[[f32; 4]; 3],
    st: DrawState,
) {
    for l in 0..4 {
        if mask & (1 << l) == 0 {
            continue;
        }
        let i = base + l;
        if st.depth_write {
            tile.depth[i] = depth[l];
        }
        match st.blend {
            Blend::Replace => {
                tile.r[i] = c[0][l];
                tile.g[i] = c[1][l];
                tile.b[i] = c[2][l];
            }
            Blend::Add => {
                tile.r[i] += c[0][l];
                tile.g[i] += c[1][l];
                tile.b[i] += c[2][l];
            }
        }
    }
}

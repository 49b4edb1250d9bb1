//! Sprites: screen-space rectangles whose fragments a caller-supplied shader colours, with
//! per-fragment depth and discard — what sphere impostors (Seed 002, Seed 004) need.
//!
//! A sprite covers the pixels whose centres lie in `[min.x, max.x) x [min.y, max.y)` (half-open,
//! the axis-aligned form of the top-left rule: abutting sprites neither overlap nor leave gaps).
//! Its fragments are visited as 2x2 quads; the shader receives the four pixel centres and the
//! sprite's local coordinates (s, t) ∈ [0, 1)² and returns four colours, depths and a keep mask.
//!
//! Early depth rejection: `depth_min` is a lower bound on every depth the shader will return for
//! the sprite (for a sphere, the depth of its nearest point). Lanes whose stored depth already
//! beats `depth_min` are dropped before the shader runs, and a quad with no lane left is not
//! shaded at all. Pass `0.0` to disable it.

use glam::{Vec2, Vec3};

use crate::framebuffer::{TILE, Tile, quad_index};
use crate::state::DepthTest;
use crate::tri::{RasterCtx, write_quad};

/// A screen-space rectangle to be shaded by a [`QuadShader`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sprite {
    /// Top-left corner in pixels (x right, y down).
    pub min: Vec2,
    /// Bottom-right corner in pixels (exclusive).
    pub max: Vec2,
    /// Lower bound of the depths the shader returns for this sprite (see the module docs).
    pub depth_min: f32,
    /// Passed back to the shader (e.g. the sphere's index).
    pub id: u32,
}

impl Sprite {
    /// Whether the sprite is usable: finite corners with `min < max`, and `depth_min` not NaN.
    /// Other sprites are skipped at draw time and counted in [`crate::DrawStats::skipped_invalid`].
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.min.is_finite()
            && self.max.is_finite()
            && self.min.cmplt(self.max).all()
            && !self.depth_min.is_nan()
    }

    /// The inclusive pixel rectangle of covered pixel centres, clipped to the image.
    #[inline]
    pub(crate) fn pixel_bounds(&self, width: u32, height: u32) -> Option<[i32; 4]> {
        // Clamp first so the float -> int casts are exact and in range.
        let lim = |v: f32, n: u32| v.clamp(-1.0, n as f32 + 1.0);
        // Pixel i is covered when min <= i + 0.5 < max.
        let x0 = (lim(self.min.x, width) - 0.5).ceil() as i32;
        let x1 = (lim(self.max.x, width) - 0.5).ceil() as i32 - 1;
        let y0 = (lim(self.min.y, height) - 0.5).ceil() as i32;
        let y1 = (lim(self.max.y, height) - 0.5).ceil() as i32 - 1;
        let x0 = x0.max(0);
        let y0 = y0.max(0);
        let x1 = x1.min(width as i32 - 1);
        let y1 = y1.min(height as i32 - 1);
        (x0 <= x1 && y0 <= y1).then_some([x0, y0, x1, y1])
    }
}

/// The four fragments of a sprite quad, lanes `(0,0), (1,0), (0,1), (1,1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpriteQuad {
    /// Pixel-centre screen coordinates.
    pub x: [f32; 4],
    pub y: [f32; 4],
    /// Sprite-local coordinates: `s = (x − min.x) / (max.x − min.x)`, same for `t` with y.
    pub s: [f32; 4],
    pub t: [f32; 4],
    /// Lanes inside the sprite, on the image, and not rejected early (bit l = lane l).
    pub mask: u8,
}

/// What a [`QuadShader`] returns for a quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadOut {
    /// Linear RGB per lane.
    pub color: [Vec3; 4],
    /// Eye-space depth per lane (NaN or non-positive depths discard the lane).
    pub depth: [f32; 4],
    /// Lanes to keep; the others are discarded (only lanes of the input mask are considered).
    pub mask: u8,
}

/// Colours the fragments of sprites, a 2x2 quad at a time (the impostor crates' shaders).
/// Closures `Fn(u32, &SpriteQuad) -> QuadOut` implement it.
pub trait QuadShader: Sync {
    /// Shade the quad of sprite `id`.
    fn shade_quad(&self, id: u32, quad: &SpriteQuad) -> QuadOut;
}

impl<F> QuadShader for F
where
    F: Fn(u32, &SpriteQuad) -> QuadOut + Sync,
{
    #[inline]
    fn shade_quad(&self, id: u32, quad: &SpriteQuad) -> QuadOut {
        self(id, quad)
    }
}

/// Rasterise one sprite into one tile.
#[inline]
pub(crate) fn raster_sprite<S: QuadShader + ?Sized>(
    tile: &mut Tile,
    ctx: &RasterCtx,
    shader: &S,
    sp: &Sprite,
) {
    let Some([bx0, by0, bx1, by1]) = sp.pixel_bounds(ctx.width, ctx.height) else {
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
    let inv_w = 1.0 / (sp.max.x - sp.min.x);
    let inv_h = 1.0 / (sp.max.y - sp.min.y);
    let st = ctx.state;
    let far = ctx.far;
    let mut qy = py0 & !1;
    while qy <= py1 {
        // Rows of the quad inside the pixel range.
        let mut row_mask = 0b1111u8;
        if qy < py0 {
            row_mask &= 0b1100;
        }
        if qy + 1 > py1 {
            row_mask &= 0b0011;
        }
        let ly = qy as u32 - tile.y0;
        let mut qx = px0 & !1;
        while qx <= px1 {
            let mut mask = row_mask;
            if qx < px0 {
                mask &= 0b1010;
            }
            if qx + 1 > px1 {
                mask &= 0b0101;
            }
            let qi = quad_index(qx as u32 - tile.x0, ly);
            // Early depth rejection against the sprite's nearest possible depth.
            if st.depth_test != DepthTest::Always {
                for l in 0..4 {
                    let stored = tile.depth[qi][l];
                    let hopeless = match st.depth_test {
                        DepthTest::LessEqual => stored < sp.depth_min,
                        _ => stored <= sp.depth_min,
                    };
                    if hopeless {
                        mask &= !(1 << l);
                    }
                }
            }
            if mask != 0 {
                let x = [
                    qx as f32 + 0.5,
                    qx as f32 + 1.5,
                    qx as f32 + 0.5,
                    qx as f32 + 1.5,
                ];
                let y = [
                    qy as f32 + 0.5,
                    qy as f32 + 0.5,
                    qy as f32 + 1.5,
                    qy as f32 + 1.5,
                ];
                let mut quad = SpriteQuad {
                    x,
                    y,
                    s: [0.0; 4],
                    t: [0.0; 4],
                    mask,
                };
                for l in 0..4 {
                    quad.s[l] = (x[l] - sp.min.x) * inv_w;
                    quad.t[l] = (y[l] - sp.min.y) * inv_h;
                }
                let out = shader.shade_quad(sp.id, &quad);
                // Depth test on the shader's depths; NaN fails every comparison.
                let mut keep = mask & out.mask;
                for l in 0..4 {
                    let d = out.depth[l];
                    let stored = tile.depth[qi][l];
                    let pass = match st.depth_test {
                        DepthTest::Less => d < stored,
                        DepthTest::LessEqual => d <= stored,
                        DepthTest::Always => true,
                    } && d > 0.0
                        && d <= far;
                    if !pass {
                        keep &= !(1 << l);
                    }
                }
                if keep != 0 {
                    let c = [
                        out.color.map(|c| c.x),
                        out.color.map(|c| c.y),
                        out.color.map(|c| c.z),
                    ];
                    write_quad(tile, qi, keep, &out.depth, &c, st);
                }
            }
            qx += 2;
        }
        qy += 2;
    }
}

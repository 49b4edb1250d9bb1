//! The colour + depth framebuffer, stored as independent screen tiles.
//!
//! Each [`TILE`] x [`TILE`] tile owns contiguous planes (depth, r, g, b) in *quad order*: the four
//! pixels of a 2x2 quad are adjacent (`(0,0), (1,0), (0,1), (1,1)`), quads row-major within the
//! tile. A quad's depth is then one 16-byte load, and tiles can be handed to rayon workers as
//! disjoint `&mut` borrows — no locking, no `unsafe`, and each pixel is written by exactly one
//! worker, which is what makes the output independent of the thread count.
//!
//! Colour is linear f32 (so additive blending and counting are exact); [`Framebuffer::to_frame`]
//! resolves it to the workspace's sRGB8 + depth [`Frame`].

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use texmap_core::camera::MAX_IMAGE_SIDE;
use texmap_core::color::{linear_to_srgb8, srgb8_to_linear_rgb};
use texmap_core::frame::Frame;

use crate::RasterError;
use crate::bin::TileGrid;

/// Side of a screen tile in pixels (a multiple of 2).
pub const TILE: u32 = 64;
pub(crate) const TILE_SHIFT: u32 = 6;
pub(crate) const QUADS_PER_ROW: usize = (TILE / 2) as usize;
pub(crate) const TILE_PIXELS: usize = (TILE * TILE) as usize;
/// 2x2 quads per tile (a power of two, so a masked quad index needs no bounds check).
pub(crate) const TILE_QUADS: usize = TILE_PIXELS / 4;

/// One pixel plane of a tile: `TILE_QUADS` quads of four lanes, in quad order.
pub(crate) type QuadPlane = Box<[[f32; 4]; TILE_QUADS]>;

fn quad_plane(v: f32) -> QuadPlane {
    let quads: Box<[[f32; 4]]> = vec![[v; 4]; TILE_QUADS].into_boxed_slice();
    match quads.try_into() {
        Ok(p) => p,
        Err(_) => unreachable!("the vector has TILE_QUADS elements"),
    }
}

/// One tile's pixel planes, in quad order.
#[derive(Clone, Debug)]
pub(crate) struct Tile {
    pub depth: QuadPlane,
    pub r: QuadPlane,
    pub g: QuadPlane,
    pub b: QuadPlane,
    /// Pixel origin of the tile.
    pub x0: u32,
    pub y0: u32,
    /// The tile holds the clear values but its planes were not written yet: the last
    /// [`Framebuffer::clear`] is applied by the first draw that reaches the tile (on that
    /// draw's thread, in cache) or stands in for the planes when they are read.
    pub pending: bool,
}

impl Tile {
    /// Apply a pending clear to linear colour `lin` and infinite depth.
    #[inline]
    pub(crate) fn prepare(&mut self, lin: Vec3) {
        if self.pending {
            self.depth.fill([f32::INFINITY; 4]);
            self.r.fill([lin.x; 4]);
            self.g.fill([lin.y; 4]);
            self.b.fill([lin.z; 4]);
            self.pending = false;
        }
    }
}

/// Index of the quad holding pixel (lx, ly) of a tile (masked: always in range).
#[inline]
pub(crate) fn quad_index(lx: u32, ly: u32) -> usize {
    ((ly >> 1) as usize * QUADS_PER_ROW + (lx >> 1) as usize) & (TILE_QUADS - 1)
}

/// Index of pixel (lx, ly) inside a tile, in quad order.
#[inline]
pub(crate) fn tile_index(lx: u32, ly: u32) -> usize {
    (((ly >> 1) as usize * QUADS_PER_ROW + (lx >> 1) as usize) << 2)
        | (((ly & 1) << 1) | (lx & 1)) as usize
}

/// The tile grid of a framebuffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Grid {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    /// The same grid for the binner.
    pub bins: TileGrid,
}

impl Grid {
    #[inline]
    pub fn tile_count(&self) -> usize {
        (self.tiles_x * self.tiles_y) as usize
    }
}

/// A colour + depth render target. Create it once per image size, [`clear`](Self::clear) it,
/// draw into it, then [`to_frame`](Self::to_frame).
///
/// # Guarantees
/// Width and height are in `1..=MAX_IMAGE_SIDE`. Depth holds eye-space distance along the view
/// axis, `INFINITY` where nothing was drawn; no NaN is ever stored in the depth planes.
#[derive(Clone, Debug)]
pub struct Framebuffer {
    pub(crate) grid: Grid,
    pub(crate) tiles: Vec<Tile>,
    background: [u8; 4],
    pub(crate) clear_linear: Vec3,
    pub(crate) scratch: crate::record::Scratch,
    /// Small triangles take the block path (`false` only in tests comparing it with the general
    /// quad loop).
    pub(crate) block_path: bool,
}

impl Framebuffer {
    /// A `width` x `height` framebuffer cleared to black (opaque) and infinite depth.
    pub fn new(width: u32, height: u32) -> Result<Framebuffer, RasterError> {
        if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
            return Err(RasterError::BadSize { width, height });
        }
        let tiles_x = width.div_ceil(TILE);
        let tiles_y = height.div_ceil(TILE);
        let grid = Grid {
            width,
            height,
            tiles_x,
            tiles_y,
            bins: TileGrid::new(width, height, TILE)?,
        };
        let mut tiles = Vec::with_capacity(grid.tile_count());
        for ty in 0..tiles_y {
            for tx in 0..tiles_x {
                tiles.push(Tile {
                    depth: quad_plane(f32::INFINITY),
                    r: quad_plane(0.0),
                    g: quad_plane(0.0),
                    b: quad_plane(0.0),
                    x0: tx * TILE,
                    y0: ty * TILE,
                    pending: false,
                });
            }
        }
        Ok(Framebuffer {
            grid,
            tiles,
            background: [0, 0, 0, 255],
            clear_linear: Vec3::ZERO,
            scratch: Default::default(),
            block_path: true,
        })
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.grid.width
    }
    #[inline]
    pub fn height(&self) -> u32 {
        self.grid.height
    }

    /// Clear depth to `INFINITY` and colour to `background` (sRGB8 RGBA). Uncovered pixels keep
    /// exactly these bytes in [`to_frame`](Self::to_frame). Constant time: each tile is cleared
    /// by the first draw that reaches it, and tiles no draw reaches are never written.
    pub fn clear(&mut self, background: [u8; 4]) {
        self.background = background;
        self.clear_linear = srgb8_to_linear_rgb(background);
        for t in &mut self.tiles {
            t.pending = true;
        }
    }

    #[inline]
    fn locate(&self, x: u32, y: u32) -> Option<(&Tile, usize)> {
        if x >= self.grid.width || y >= self.grid.height {
            return None;
        }
        let t = &self.tiles[((y >> TILE_SHIFT) * self.grid.tiles_x + (x >> TILE_SHIFT)) as usize];
        Some((t, tile_index(x & (TILE - 1), y & (TILE - 1))))
    }

    /// Stored depth of pixel (x, y) (`None` outside the image).
    pub fn depth_at(&self, x: u32, y: u32) -> Option<f32> {
        self.locate(x, y).map(|(t, i)| {
            if t.pending {
                f32::INFINITY
            } else {
                t.depth[i >> 2][i & 3]
            }
        })
    }

    /// Stored linear colour of pixel (x, y) (`None` outside the image). With [`crate::Blend::Add`]
    /// and a flat colour of 1 this is the number of fragments written there.
    pub fn color_at(&self, x: u32, y: u32) -> Option<Vec3> {
        self.locate(x, y).map(|(t, i)| {
            if t.pending {
                self.clear_linear
            } else {
                Vec3::new(t.r[i >> 2][i & 3], t.g[i >> 2][i & 3], t.b[i >> 2][i & 3])
            }
        })
    }

    /// Resolve to a [`Frame`]: sRGB8 colour (alpha 255 where drawn) and depth. A pixel whose
    /// depth is infinite and whose colour still equals the clear colour keeps the background bytes.
    /// Bands of one tile row are resolved in parallel; each output pixel is written once, so the
    /// bytes do not depend on the thread count.
    pub fn to_frame(&self) -> Frame {
        let mut frame = Frame::new(self.grid.width, self.grid.height, self.background);
        self.resolve_into(&mut frame);
        frame
    }

    /// [`to_frame`](Self::to_frame) into an existing frame, reusing its buffers when it already
    /// has this framebuffer's size (a renderer drawing many frames then allocates none).
    pub fn resolve_into(&self, frame: &mut Frame) {
        if frame.width() != self.grid.width || frame.height() != self.grid.height {
            *frame = Frame::new(self.grid.width, self.grid.height, self.background);
        }
        let w = self.grid.width as usize;
        let bg = self.clear_linear.to_array().map(f32::to_bits);
        let bg_bytes = self.background;
        let band = w * TILE as usize;
        let tiles_x = self.grid.tiles_x as usize;
        let Frame { color, depth, .. } = frame;
        color
            .par_chunks_mut(band)
            .zip(depth.par_chunks_mut(band))
            .zip(self.tiles.par_chunks(tiles_x))
            .for_each(|((color, depth), row_tiles)| {
                for t in row_tiles {
                    let xe = (t.x0 + TILE).min(self.grid.width);
                    let ye = (t.y0 + TILE).min(self.grid.height);
                    if t.pending {
                        for y in t.y0..ye {
                            let row = (y - t.y0) as usize * w;
                            let span = row + t.x0 as usize..row + xe as usize;
                            depth[span.clone()].fill(f32::INFINITY);
                            color[span].fill(bg_bytes);
                        }
                        continue;
                    }
                    for y in t.y0..ye {
                        let row = (y - t.y0) as usize * w;
                        for x in t.x0..xe {
                            let i = tile_index(x - t.x0, y - t.y0);
                            let (q, l) = (i >> 2, i & 3);
                            let c = Vec3::new(t.r[q][l], t.g[q][l], t.b[q][l]);
                            let d = t.depth[q][l];
                            let o = row + x as usize;
                            depth[o] = d;
                            color[o] = if d.is_finite() || c.to_array().map(f32::to_bits) != bg {
                                linear_to_srgb8(c, 255)
                            } else {
                                bg_bytes
                            };
                        }
                    }
                }
            });
    }

    /// The drawn image in linear light over `under`: `out[y·w + x]` is pixel `(x, y)`'s colour
    /// with alpha 1 where something was drawn (finite depth), else `under`'s texel (both
    /// `width × height`, row-major). For an image drawn over a background that is not one colour
    /// (a map face over its environment). Bands of one tile row are written in parallel, each
    /// texel once. Panics if a slice is not `width × height` long.
    pub fn composite_linear_into(&self, under: &[Vec4], out: &mut [Vec4]) {
        let w = self.grid.width as usize;
        let n = w * self.grid.height as usize;
        assert!(
            under.len() == n && out.len() == n,
            "composite_linear_into: {} and {} texels for a {}x{} image",
            under.len(),
            out.len(),
            self.grid.width,
            self.grid.height
        );
        let band = w * TILE as usize;
        let tiles_x = self.grid.tiles_x as usize;
        out.par_chunks_mut(band)
            .zip(under.par_chunks(band))
            .zip(self.tiles.par_chunks(tiles_x))
            .for_each(|((out, under), row_tiles)| {
                for t in row_tiles {
                    let xe = (t.x0 + TILE).min(self.grid.width);
                    let ye = (t.y0 + TILE).min(self.grid.height);
                    for y in t.y0..ye {
                        let row = (y - t.y0) as usize * w;
                        let span = row + t.x0 as usize..row + xe as usize;
                        if t.pending {
                            out[span.clone()].copy_from_slice(&under[span]);
                            continue;
                        }
                        // Two pixels of a quad row at a time: lanes l and l + 1 of quad q.
                        let ly = y - t.y0;
                        for x in (t.x0..xe).step_by(2) {
                            let i = tile_index(x - t.x0, ly);
                            let (q, l) = (i >> 2, i & 3);
                            let o = row + x as usize;
                            for k in 0..((xe - x) as usize).min(2) {
                                out[o + k] = if t.depth[q][l + k].is_finite() {
                                    Vec4::new(t.r[q][l + k], t.g[q][l + k], t.b[q][l + k], 1.0)
                                } else {
                                    under[o + k]
                                };
                            }
                        }
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_order_index_is_a_bijection() {
        let mut seen = vec![false; TILE_PIXELS];
        for y in 0..TILE {
            for x in 0..TILE {
                let i = tile_index(x, y);
                assert!(!seen[i], "({x},{y}) -> {i} twice");
                seen[i] = true;
            }
        }
        assert_eq!(tile_index(1, 1), 3);
        assert_eq!(tile_index(2, 0), 4);
        assert_eq!(tile_index(0, 2), 4 * QUADS_PER_ROW);
    }

    #[test]
    fn clear_and_resolve_keep_background_bytes() {
        let mut fb = Framebuffer::new(70, 3).unwrap();
        fb.clear([10, 20, 30, 0]);
        let f = fb.to_frame();
        assert!(f.color.iter().all(|&c| c == [10, 20, 30, 0]));
        assert_eq!(f.coverage_count(), 0);
        assert!(Framebuffer::new(0, 5).is_err());
        assert_eq!(fb.depth_at(70, 0), None);
        // Resolving into a frame of another size or content gives the same bytes.
        let mut g = Frame::new(5, 5, [1, 2, 3, 4]);
        fb.resolve_into(&mut g);
        assert_eq!(g.color, f.color);
        g.color.fill([9; 4]);
        g.depth.fill(0.0);
        fb.resolve_into(&mut g);
        assert_eq!((g.color, g.depth), (f.color, f.depth));
    }
}

//! Binning primitives into screen tiles: count, prefix sum, fill.
//!
//! The primitive pass (parallel over fixed-size chunks, so the result does not depend on the
//! thread count) writes one packed tile rectangle per primitive and counts, per chunk, how many
//! entries each tile receives. The fill pass then writes each primitive's entry into every tile it
//! overlaps, in primitive order, so each tile sees its primitives in submission order.
//!
//! An entry is a `u32`: a primitive index, or `PIECE | i` for clipped piece `i` of the draw.

use crate::framebuffer::{Grid, TILE_SHIFT};

/// Fixed chunk size of the parallel primitive pass (independent of the thread count).
pub(crate) const CHUNK: usize = 8192;
/// Rectangle value: the primitive covers no pixel (culled, degenerate, off-screen, invalid).
/// Encodes tile x0 = 1 > x1 = 0, which no real rectangle has.
pub(crate) const RECT_EMPTY: u32 = 1;
/// Rectangle value: the primitive was clipped; its pieces carry their own rectangles
/// (x0 = 2 > x1 = 0, impossible for a real rectangle).
pub(crate) const RECT_CLIPPED: u32 = 2;
/// Entry bit marking a clipped piece.
pub(crate) const PIECE: u32 = 1 << 31;

/// Pack the tiles overlapped by the inclusive pixel rectangle (x0..=x1, y0..=y1), which must lie
/// inside the image. Tile indices fit in 8 bits (16384 / 64 = 256).
#[inline]
pub(crate) fn pack_rect(x0: i32, y0: i32, x1: i32, y1: i32) -> u32 {
    let s = TILE_SHIFT;
    ((x0 as u32) >> s)
        | (((y0 as u32) >> s) << 8)
        | (((x1 as u32) >> s) << 16)
        | (((y1 as u32) >> s) << 24)
}

#[inline]
pub(crate) fn unpack_rect(r: u32) -> (u32, u32, u32, u32) {
    (r & 0xff, (r >> 8) & 0xff, (r >> 16) & 0xff, r >> 24)
}

/// What one chunk of the primitive pass produced.
pub(crate) struct ChunkBins<P> {
    /// Entries per tile from this chunk.
    pub counts: Vec<u32>,
    /// Clipped pieces, in primitive order.
    pub pieces: Vec<P>,
}

impl<P> ChunkBins<P> {
    pub fn new(grid: &Grid) -> Self {
        ChunkBins {
            counts: vec![0; grid.tile_count()],
            pieces: Vec::new(),
        }
    }

    #[inline]
    pub fn count(&mut self, grid: &Grid, rect: u32) {
        let (tx0, ty0, tx1, ty1) = unpack_rect(rect);
        for ty in ty0..=ty1 {
            let row = (ty * grid.tiles_x) as usize;
            for tx in tx0..=tx1 {
                self.counts[row + tx as usize] += 1;
            }
        }
    }
}

/// Per-tile entry lists: tile `t` owns `entries[starts[t]..starts[t + 1]]`.
#[derive(Default)]
pub(crate) struct Bins {
    pub starts: Vec<u32>,
    pub entries: Vec<u32>,
}

impl Bins {
    #[inline]
    pub fn tile(&self, t: usize) -> &[u32] {
        &self.entries[self.starts[t] as usize..self.starts[t + 1] as usize]
    }

    /// Fill from the per-primitive rectangles and the chunks' counts and pieces (`piece_rect`
    /// reads a piece's rectangle, `piece_prim` its source primitive).
    pub fn fill<P>(
        &mut self,
        grid: &Grid,
        rects: &[u32],
        chunks: &[ChunkBins<P>],
        piece_rect: impl Fn(&P) -> u32,
        piece_prim: impl Fn(&P) -> u32,
    ) {
        let nt = grid.tile_count();
        // Prefix sum of the counts over tiles.
        self.starts.clear();
        self.starts.resize(nt + 1, 0);
        let mut total = 0u32;
        let mut cursor = vec![0u32; nt];
        for t in 0..nt {
            self.starts[t] = total;
            cursor[t] = total;
            for c in chunks {
                total += c.counts[t];
            }
        }
        self.starts[nt] = total;
        self.entries.clear();
        self.entries.resize(total as usize, 0);
        // Fill in primitive order.
        let tiles_x = grid.tiles_x;
        let entries = &mut self.entries;
        let mut put = |rect: u32, e: u32| {
            let (tx0, ty0, tx1, ty1) = unpack_rect(rect);
            for ty in ty0..=ty1 {
                let row = (ty * tiles_x) as usize;
                for tx in tx0..=tx1 {
                    let c = &mut cursor[row + tx as usize];
                    entries[*c as usize] = e;
                    *c += 1;
                }
            }
        };
        let mut piece_base = 0u32;
        for (ci, chunk) in chunks.iter().enumerate() {
            let lo = ci * CHUNK;
            let hi = (lo + CHUNK).min(rects.len());
            let mut pc = 0usize;
            for (prim, &r) in (lo..hi).zip(&rects[lo..hi]) {
                if r == RECT_EMPTY {
                    continue;
                }
                if r == RECT_CLIPPED {
                    while pc < chunk.pieces.len() && piece_prim(&chunk.pieces[pc]) == prim as u32 {
                        let pr = piece_rect(&chunk.pieces[pc]);
                        if pr != RECT_EMPTY {
                            put(pr, PIECE | (piece_base + pc as u32));
                        }
                        pc += 1;
                    }
                    continue;
                }
                put(r, prim as u32);
            }
            piece_base += chunk.pieces.len() as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_packing_round_trips() {
        let r = pack_rect(0, 64, 16383, 130);
        assert_eq!(unpack_rect(r), (0, 1, 255, 2));
        // The sentinels are not rectangles (x0 > x1); every real one has x0 <= x1.
        for s in [RECT_EMPTY, RECT_CLIPPED] {
            let (x0, _, x1, _) = unpack_rect(s);
            assert!(x0 > x1);
        }
        assert_eq!(pack_rect(16383, 16383, 16383, 16383), u32::MAX);
    }
}

//! Binning primitives into screen tiles: count, prefix sum, fill.
//!
//! The count pass (parallel over fixed-size chunks, so the result does not depend on the thread
//! count) writes one packed tile rectangle per primitive and counts, per chunk, how many records
//! each tile receives. A prefix sum reserves a slot range per (chunk, tile); the fill pass (also
//! parallel over chunks) copies each primitive's record into every tile it overlaps, so every tile
//! holds its primitives in submission order.

use crate::framebuffer::{Grid, TILE_SHIFT};

/// Fixed chunk size of the parallel primitive pass (independent of the thread count).
pub(crate) const CHUNK: usize = 8192;
/// Rectangle value: the primitive covers no pixel (culled, degenerate, off-screen, invalid).
/// Encodes tile x0 = 1 > x1 = 0, which no real rectangle has.
pub(crate) const RECT_EMPTY: u32 = 1;
/// Rectangle value: the primitive was clipped; its pieces carry their own rectangles
/// (x0 = 2 > x1 = 0, impossible for a real rectangle).
pub(crate) const RECT_CLIPPED: u32 = 2;

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

/// Per-tile lists of copied primitive records: tile `t` owns `items[starts[t]..starts[t + 1]]`.
///
/// Records are copied into the bins rather than referenced by index: the tile pass then reads its
/// primitives as one sequential stream instead of gathering vertices from all over memory (with
/// indices, 1M scattered small triangles spent ~80% of their time in two cache-missing loads).
pub(crate) struct Bins<T> {
    pub starts: Vec<u32>,
    pub items: Vec<T>,
    cursors: Vec<u32>,
    ends: Vec<u32>,
}

impl<T> Default for Bins<T> {
    fn default() -> Self {
        Bins {
            starts: Vec::new(),
            items: Vec::new(),
            cursors: Vec::new(),
            ends: Vec::new(),
        }
    }
}

/// A raw pointer to the bins' storage, shared by the fill workers (see [`Emitter::put`]).
#[derive(Clone, Copy)]
struct SyncPtr<T>(*mut T);
// SAFETY: workers write through the pointer only into disjoint, bounds-checked ranges.
unsafe impl<T: Send> Send for SyncPtr<T> {}
unsafe impl<T: Send> Sync for SyncPtr<T> {}

/// Writes one chunk's records into its reserved slots of every tile.
pub(crate) struct Emitter<'a, T> {
    ptr: SyncPtr<T>,
    cur: &'a mut [u32],
    end: &'a [u32],
    tiles_x: u32,
}

impl<T> Emitter<'_, T> {
    /// Append `item` to every tile of the packed rectangle `rect`.
    #[inline]
    pub fn put(&mut self, rect: u32, item: T)
    where
        T: Copy,
    {
        let (tx0, ty0, tx1, ty1) = unpack_rect(rect);
        for ty in ty0..=ty1 {
            let row = (ty * self.tiles_x) as usize;
            for tx in tx0..=tx1 {
                let t = row + tx as usize;
                let c = self.cur[t];
                // Stay inside this chunk's reserved range of tile t (the count pass reserved
                // exactly what the fill pass puts; a mismatch would be a bug, never a race).
                if c < self.end[t] {
                    // SAFETY: `c` lies in [start, end) of the range reserved for this
                    // (chunk, tile) pair; the ranges of all pairs are disjoint and inside
                    // `items` (see `Bins::fill`), so no other worker writes this slot.
                    unsafe { self.ptr.0.add(c as usize).write(item) };
                    self.cur[t] = c + 1;
                } else {
                    debug_assert!(false, "fill put more records than were counted");
                }
            }
        }
    }
}

impl<T: Copy + Default + Send + Sync> Bins<T> {
    #[inline]
    pub fn tile(&self, t: usize) -> &[T] {
        &self.items[self.starts[t] as usize..self.starts[t + 1] as usize]
    }

    /// Lay out the bins from the per-chunk tile counts, then let `emit(chunk, emitter)` write
    /// each chunk's records in primitive order, all chunks in parallel. Chunk `c`'s records for
    /// tile `t` follow those of chunks `< c`, so every tile lists its primitives in submission
    /// order whatever the thread count.
    // Tile-major prefix sums over chunk-major counts: both indices address two arrays.
    #[allow(clippy::needless_range_loop)]
    pub fn fill<F>(&mut self, grid: &Grid, counts: &[&[u32]], emit: F)
    where
        F: Fn(usize, &mut Emitter<'_, T>) + Sync,
    {
        use rayon::prelude::*;
        let nt = grid.tile_count();
        let nc = counts.len();
        // Prefix sums: tile starts, then each chunk's slot range within each tile.
        self.starts.clear();
        self.starts.resize(nt + 1, 0);
        self.cursors.clear();
        self.cursors.resize(nc * nt, 0);
        self.ends.clear();
        self.ends.resize(nc * nt, 0);
        let mut total = 0u32;
        for t in 0..nt {
            self.starts[t] = total;
            for c in 0..nc {
                self.cursors[c * nt + t] = total;
                total += counts[c][t];
                self.ends[c * nt + t] = total;
            }
        }
        self.starts[nt] = total;
        // Every slot is overwritten by the fill below; growing fills with defaults.
        self.items.resize(total as usize, T::default());
        if nt == 0 || nc == 0 {
            return;
        }
        let ptr = SyncPtr(self.items.as_mut_ptr());
        let tiles_x = grid.tiles_x;
        self.cursors
            .par_chunks_mut(nt)
            .zip(self.ends.par_chunks(nt))
            .enumerate()
            .for_each(|(c, (cur, end))| {
                let mut em = Emitter {
                    ptr,
                    cur,
                    end,
                    tiles_x,
                };
                emit(c, &mut em);
            });
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

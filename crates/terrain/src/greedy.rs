//! Greedy Delaunay refinement (Garland & Heckbert 1995, "Fast polygonal approximation of terrains
//! and height fields", the greedy insertion algorithm): start from the grid's two corner
//! triangles, and repeatedly insert the grid sample farthest (vertically) from the current mesh,
//! keeping the triangulation Delaunay by edge flips, until every sample is within the maximum
//! error. Any grid shape works (no `2^k + 1` padding), and at equal error it needs fewer triangles
//! than the RTIN, whose triangles are confined to the right-isosceles hierarchy; the price is time
//! (each inserted point rescans the triangles it changed).
//!
//! Each triangle keeps its candidate — the sample of largest error inside it (edges included),
//! found by scanning its bounding box — in a max-heap with a generation counter, so stale entries
//! of replaced triangles are skipped. When the heap's top is within the error, every sample is:
//! the bound is exact, like the RTIN's. Predicates are exact: in-circle and orientation tests run
//! in `i128` on the integer grid coordinates. Grids with no-data are refused (fill them first, or use
//! the RTIN, which cuts holes).

use crate::dem::Grid;
use crate::error::TerrainError;
use crate::rtin::GridMesh;
use std::collections::BinaryHeap;

const NONE: u32 = u32::MAX;

fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether `d` is strictly inside the circumcircle of `a, b, c` (with `orient(a, b, c) > 0`).
fn in_circle(a: [i64; 2], b: [i64; 2], c: [i64; 2], d: [i64; 2]) -> bool {
    let r = |p: [i64; 2]| {
        let (x, y) = ((p[0] - d[0]) as i128, (p[1] - d[1]) as i128);
        (x, y, x * x + y * y)
    };
    let (ax, ay, a2) = r(a);
    let (bx, by, b2) = r(b);
    let (cx, cy, c2) = r(c);
    ax * (by * c2 - b2 * cy) - ay * (bx * c2 - b2 * cx) + a2 * (bx * cy - by * cx) > 0
}

struct Tin<'a> {
    grid: &'a Grid,
    pts: Vec<[i64; 2]>,
    tris: Vec<[u32; 3]>,
    half: Vec<u32>,
    generation: Vec<u32>,
    heap: BinaryHeap<(u64, u32, u32, u32, u32)>, // (error bits, triangle, generation, x, y)
    dirty: Vec<u32>,
}

impl Tin<'_> {
    fn h(&self, p: [i64; 2]) -> f64 {
        self.grid.at(p[0] as u32, p[1] as u32) as f64
    }

    fn link(&mut self, a: u32, b: u32) {
        self.half[a as usize] = b;
        if b != NONE {
            self.half[b as usize] = a;
        }
    }

    fn set_tri(&mut self, t: u32, v: [u32; 3]) {
        if t as usize == self.tris.len() {
            self.tris.push(v);
            self.half.extend([NONE; 3]);
            self.generation.push(0);
        } else {
            self.tris[t as usize] = v;
            self.generation[t as usize] += 1;
        }
        self.dirty.push(t);
    }

    /// Scan triangle `t` for its worst sample and queue it.
    fn scan(&mut self, t: u32) {
        let [a, b, c] = self.tris[t as usize].map(|i| self.pts[i as usize]);
        let (ha, hb, hc) = (self.h(a), self.h(b), self.h(c));
        let det = orient(a, b, c) as f64;
        let (x0, x1) = (a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]));
        let (y0, y1) = (a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]));
        let mut best = (0.0f64, NONE, NONE);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let p = [x, y];
                let (w0, w1, w2) = (orient(b, c, p), orient(c, a, p), orient(a, b, p));
                if w0 < 0 || w1 < 0 || w2 < 0 || p == a || p == b || p == c {
                    continue;
                }
                let z = (w0 as f64 * ha + w1 as f64 * hb + w2 as f64 * hc) / det;
                let e = (self.h(p) - z).abs();
                if e > best.0 {
                    best = (e, x as u32, y as u32);
                }
            }
        }
        if best.1 != NONE {
            self.heap.push((
                best.0.to_bits(),
                t,
                self.generation[t as usize],
                best.1,
                best.2,
            ));
        }
    }

    /// Restore the Delaunay property across half-edge `e`, whose triangle's third vertex is new.
    fn legalize(&mut self, e: u32) {
        let o = self.half[e as usize];
        if o == NONE {
            return;
        }
        let (t, i) = (e / 3, e % 3);
        let (u, j) = (o / 3, o % 3);
        let tv = self.tris[t as usize];
        let uv = self.tris[u as usize];
        let (v0, v1, p) = (
            tv[i as usize],
            tv[(i as usize + 1) % 3],
            tv[(i as usize + 2) % 3],
        );
        let q = uv[(j as usize + 2) % 3];
        let pt = |k: u32| self.pts[k as usize];
        if !in_circle(pt(v0), pt(v1), pt(p), pt(q)) {
            return;
        }
        // Outer edges of the quad v0, q, v1, p before the flip.
        let a = self.half[(3 * u + (j + 1) % 3) as usize]; // v0 -> q
        let b = self.half[(3 * u + (j + 2) % 3) as usize]; // q -> v1
        let c = self.half[(3 * t + (i + 1) % 3) as usize]; // v1 -> p
        let d = self.half[(3 * t + (i + 2) % 3) as usize]; // p -> v0
        self.set_tri(t, [v0, q, p]);
        self.set_tri(u, [q, v1, p]);
        self.link(3 * t, a);
        self.link(3 * t + 1, 3 * u + 2);
        self.link(3 * t + 2, d);
        self.link(3 * u, b);
        self.link(3 * u + 1, c);
        self.legalize(3 * t);
        self.legalize(3 * u);
    }

    /// Insert sample `p` (inside or on an edge of triangle `t`).
    fn insert(&mut self, t: u32, p: [i64; 2]) {
        let pi = self.pts.len() as u32;
        self.pts.push(p);
        let tv = self.tris[t as usize];
        let on_edge = (0..3).find(|&k| {
            orient(
                self.pts[tv[k] as usize],
                self.pts[tv[(k + 1) % 3] as usize],
                p,
            ) == 0
        });
        match on_edge {
            None => {
                let [a, b, c] = tv;
                let ext = [0, 1, 2].map(|k| self.half[(3 * t + k) as usize]);
                let (t1, t2) = (self.tris.len() as u32, self.tris.len() as u32 + 1);
                self.set_tri(t, [a, b, pi]);
                self.set_tri(t1, [b, c, pi]);
                self.set_tri(t2, [c, a, pi]);
                self.link(3 * t, ext[0]);
                self.link(3 * t1, ext[1]);
                self.link(3 * t2, ext[2]);
                self.link(3 * t + 1, 3 * t1 + 2);
                self.link(3 * t1 + 1, 3 * t2 + 2);
                self.link(3 * t2 + 1, 3 * t + 2);
                self.legalize(3 * t);
                self.legalize(3 * t1);
                self.legalize(3 * t2);
            }
            Some(k) => {
                let k = k as u32;
                let (a, b, c) = (
                    tv[k as usize],
                    tv[(k as usize + 1) % 3],
                    tv[(k as usize + 2) % 3],
                );
                let o = self.half[(3 * t + k) as usize];
                let bc = self.half[(3 * t + (k + 1) % 3) as usize];
                let ca = self.half[(3 * t + (k + 2) % 3) as usize];
                let t1 = self.tris.len() as u32;
                self.set_tri(t, [pi, b, c]);
                self.set_tri(t1, [a, pi, c]);
                self.link(3 * t + 1, bc);
                self.link(3 * t1 + 2, ca);
                self.link(3 * t + 2, 3 * t1 + 1);
                if o == NONE {
                    self.half[(3 * t) as usize] = NONE;
                    self.half[(3 * t1) as usize] = NONE;
                } else {
                    let (u, j) = (o / 3, o % 3);
                    let uv = self.tris[u as usize];
                    let d = uv[(j as usize + 2) % 3];
                    let ad = self.half[(3 * u + (j + 1) % 3) as usize];
                    let db = self.half[(3 * u + (j + 2) % 3) as usize];
                    let u1 = self.tris.len() as u32;
                    self.set_tri(u, [pi, a, d]);
                    self.set_tri(u1, [b, pi, d]);
                    self.link(3 * u + 1, ad);
                    self.link(3 * u1 + 2, db);
                    self.link(3 * u + 2, 3 * u1 + 1);
                    self.link(3 * t, 3 * u1);
                    self.link(3 * t1, 3 * u);
                    self.legalize(3 * u + 1);
                    self.legalize(3 * u1 + 2);
                }
                self.legalize(3 * t + 1);
                self.legalize(3 * t1 + 2);
            }
        }
    }
}

/// Triangulate `grid` greedily until every sample is within `max_error` metres (or every sample is
/// a vertex). Triangles are wound like the RTIN's.
pub fn greedy(grid: &Grid, max_error: f32) -> Result<GridMesh, TerrainError> {
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(TerrainError::BadParameter {
            name: "max-error",
            value: max_error.to_string(),
            expected: "a finite error ≥ 0 metres",
        });
    }
    if grid.nodata_count() > 0 {
        return Err(TerrainError::BadParameter {
            name: "grid",
            value: format!("{} no-data samples", grid.nodata_count()),
            expected: "a grid without no-data for greedy refinement (fill it first, or use the RTIN)",
        });
    }
    let (w, h) = (grid.width() as i64 - 1, grid.height() as i64 - 1);
    let mut tin = Tin {
        grid,
        pts: vec![[0, 0], [w, 0], [w, h], [0, h]],
        tris: Vec::new(),
        half: Vec::new(),
        generation: Vec::new(),
        heap: BinaryHeap::new(),
        dirty: Vec::new(),
    };
    tin.set_tri(0, [0, 1, 2]);
    tin.set_tri(1, [0, 2, 3]);
    tin.link(2, 3);
    loop {
        let mut dirty = std::mem::take(&mut tin.dirty);
        dirty.sort_unstable();
        dirty.dedup();
        for t in dirty {
            tin.scan(t);
        }
        let Some((bits, t, g, x, y)) = tin.heap.pop() else {
            break;
        };
        if tin.generation[t as usize] != g {
            continue;
        }
        if f64::from_bits(bits) <= max_error as f64 {
            break;
        }
        tin.insert(t, [x as i64, y as i64]);
    }
    let mut max_bound = 0.0f32;
    // The remaining live candidates bound each triangle's error.
    for &(bits, t, g, _, _) in tin.heap.iter() {
        if tin.generation[t as usize] == g {
            max_bound = max_bound.max(f64::from_bits(bits) as f32);
        }
    }
    Ok(GridMesh {
        vertices: tin.pts.iter().map(|p| [p[0] as u32, p[1] as u32]).collect(),
        triangles: tin.tris.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        max_bound,
        bridging: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    #[test]
    fn plane_is_two_triangles_and_bump_is_exact() {
        let g = Grid::new(
            "p",
            7,
            5,
            (0..35)
                .map(|i| (i % 7) as f32 * 2.0 + (i / 7) as f32)
                .collect(),
            Georef::local(1.0),
        )
        .unwrap();
        assert_eq!(greedy(&g, 0.0).unwrap().triangles.len(), 2);
        let mut h = vec![0.0f32; 35];
        h[2 * 7 + 3] = 4.0;
        let g = Grid::new("b", 7, 5, h, Georef::local(1.0)).unwrap();
        // The bump errs by exactly 4 against the two corner triangles.
        assert_eq!(greedy(&g, 4.0).unwrap().triangles.len(), 2);
        let m = greedy(&g, 3.99).unwrap();
        assert!(m.vertices.contains(&[3, 2]) && m.triangles.len() > 2);
    }
}

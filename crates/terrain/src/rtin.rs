//! Right-triangulated irregular network (RTIN) on a `(2^k + 1)²` grid: an error map computed
//! bottom-up once, then meshes extracted at any maximum vertical error by walking the implicit
//! binary triangle tree.
//!
//! # The hierarchy
//! The square of side `S = 2^k` is cut by its diagonal into two right isosceles triangles; a
//! triangle `(a, b, c)` (hypotenuse `a–b`, right angle at `c`) splits at the hypotenuse midpoint
//! `m` into `(c, a, m)` and `(b, c, m)`. Two kinds of midpoint alternate, finest first:
//! - *diamond* vertices of step `s`: midpoints of the edges of the `s`-cell lattice, shared by the
//!   two triangles whose hypotenuse is that edge (the rhombus `|dx| + |dy| ≤ s/2` around it);
//! - *square* vertices of step `s`: centres of `s`-cells, shared by the two triangles cut by the
//!   cell's diagonal (the diagonal passes through the centre of the parent `2s`-cell).
//!
//! # The error map (a strict bound, unlike martini's)
//! `errors[m]` is the largest vertical distance, over every grid sample inside either triangle
//! of `m`'s diamond, between the sample and the plane of the triangle it lies in — computed
//! exactly by visiting the samples — maxed with `errors` of the four children midpoints. A
//! triangle left unsplit because `errors[m] ≤ ε` therefore has every grid sample within `ε` of it,
//! and because a vertex's value dominates its descendants', splitting a triangle always splits its
//! ancestors and the neighbours sharing their hypotenuses: the mesh is conforming (no T-junction).
//! Mapbox martini stores only the midpoint's distance to its hypotenuse's linear interpolation
//! (maxed over descendants), which is cheaper but not a bound on the triangle's error; the cost
//! of the exact bound is visiting every sample once per level (`2 log2 S` passes over the grid),
//! done in parallel over vertex rows with rayon (the max is exact, so the map is the same for any
//! thread count).
//!
//! # No-data
//! A diamond holding both valid and no-data (`NaN`) samples gets an infinite error, so it is split
//! down to single cells around every hole; a diamond of no-data only gets 0 (nothing to refine),
//! and triangles with a no-data vertex are dropped at extraction: holes stay holes, with
//! cell-exact rims, and padding a grid with `NaN` to `2^k + 1` costs only its border.

use rayon::prelude::*;

/// A triangle of grid sample coordinates `(x, y)`: hypotenuse `a–b`, right angle at `c`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tri {
    pub a: [u32; 2],
    pub b: [u32; 2],
    pub c: [u32; 2],
}

/// The error map of a `(2^k + 1)²` grid.
#[derive(Clone, Debug)]
pub struct ErrorMap {
    n: u32,
    errors: Vec<f32>,
}

/// Fold of a diamond's samples: the max error, samples visited and no-data samples seen.
///
/// Branch-free per sample: a NaN difference never wins the `>` comparison, and no-data is counted
/// separately, so the inner loops vectorise.
#[derive(Clone, Copy)]
struct Acc {
    err: f32,
    seen: u32,
    nodata: u32,
}

impl Acc {
    fn new() -> Acc {
        Acc {
            err: 0.0,
            seen: 0,
            nodata: 0,
        }
    }
    /// Samples `row[i]` against the plane values `base + slope·i`.
    #[inline]
    fn scan(&mut self, row: &[f32], base: f32, slope: f32) {
        let mut err = self.err;
        let mut nodata = 0u32;
        for (i, &h) in row.iter().enumerate() {
            let e = (h - (base + slope * i as f32)).abs();
            err = if e > err { e } else { err };
            nodata += h.is_nan() as u32;
        }
        self.err = err;
        self.nodata += nodata;
        self.seen += row.len() as u32;
    }
    fn value(self) -> f32 {
        if self.nodata == 0 {
            self.err
        } else if self.nodata == self.seen {
            0.0
        } else {
            f32::INFINITY
        }
    }
}

impl ErrorMap {
    /// Side length `n = 2^k + 1` the map works on (with `k ≥ 1`).
    pub fn is_valid_size(n: u32) -> bool {
        n >= 3 && (n - 1).is_power_of_two()
    }

    /// Build the error map of `heights` (`n x n`, row-major, `NaN` = no-data).
    ///
    /// # Panics
    /// If `n` is not `2^k + 1` with `k ≥ 1` or `heights.len() != n²` (callers pad first).
    pub fn new(heights: &[f32], n: u32) -> ErrorMap {
        assert!(
            Self::is_valid_size(n),
            "RTIN needs 2^k + 1 samples a side, got {n}"
        );
        assert_eq!(heights.len(), n as usize * n as usize);
        let size = n - 1;
        let nu = n as usize;
        let mut errors = vec![0.0f32; nu * nu];
        let mut s = 2;
        while s <= size {
            let h = s / 2;
            let cells = size / s;
            // Diamond vertices of step s: horizontal edges (x0 + s/2, y), vertical edges (x, y0 + s/2).
            for horizontal in [true, false] {
                let (rows, cols) = if horizontal {
                    (cells + 1, cells)
                } else {
                    (cells, cells + 1)
                };
                let errs = &errors;
                // One Vec per row through an indexed collect: no intermediate copy of the phase.
                let vals: Vec<Vec<f32>> = (0..rows)
                    .into_par_iter()
                    .map(|r| {
                        (0..cols)
                            .map(move |q| {
                                let (mx, my) = if horizontal {
                                    (q * s + h, r * s)
                                } else {
                                    (q * s, r * s + h)
                                };
                                let own = diamond_error(heights, nu, mx, my, h, horizontal, size);
                                let mut e = own;
                                if h >= 2 {
                                    let k = h / 2;
                                    for (dx, dy) in [(-1i64, -1i64), (1, -1), (-1, 1), (1, 1)] {
                                        let cx = mx as i64 + dx * k as i64;
                                        let cy = my as i64 + dy * k as i64;
                                        if cx >= 0
                                            && cy >= 0
                                            && cx <= size as i64
                                            && cy <= size as i64
                                        {
                                            e = e.max(errs[cy as usize * nu + cx as usize]);
                                        }
                                    }
                                }
                                e
                            })
                            .collect()
                    })
                    .collect();
                for r in 0..rows {
                    for q in 0..cols {
                        let (mx, my) = if horizontal {
                            (q * s + h, r * s)
                        } else {
                            (q * s, r * s + h)
                        };
                        errors[my as usize * nu + mx as usize] = vals[r as usize][q as usize];
                    }
                }
            }
            // Square vertices of step s: cell centres.
            let errs = &errors;
            let vals: Vec<Vec<f32>> = (0..cells)
                .into_par_iter()
                .map(|j| {
                    (0..cells)
                        .map(move |i| {
                            let (x0, y0) = (i * s, j * s);
                            let main = is_main_diagonal(i, j, s, size);
                            let mut e = cell_error(heights, nu, x0, y0, s, main);
                            for (ex, ey) in [(h, 0), (h, s), (0, h), (s, h)] {
                                e = e.max(errs[(y0 + ey) as usize * nu + (x0 + ex) as usize]);
                            }
                            e
                        })
                        .collect()
                })
                .collect();
            for j in 0..cells {
                for i in 0..cells {
                    errors[(j * s + h) as usize * nu + (i * s + h) as usize] =
                        vals[j as usize][i as usize];
                }
            }
            s *= 2;
        }
        ErrorMap { n, errors }
    }

    /// Side length in samples.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The error bound stored at sample `(x, y)` (0 at the corners and for leaf cells).
    pub fn error_at(&self, x: u32, y: u32) -> f32 {
        self.errors[y as usize * self.n as usize + x as usize]
    }

    /// The two triangles of the `s`-cell at `(x0, y0)` (aligned: multiples of `s`, a power of two),
    /// wound the same way as every triangle of the hierarchy.
    pub fn cell_triangles(&self, x0: u32, y0: u32, s: u32) -> [Tri; 2] {
        let size = self.n - 1;
        let (x1, y1) = (x0 + s, y0 + s);
        if is_main_diagonal(x0 / s, y0 / s, s, size) {
            [
                Tri {
                    a: [x0, y0],
                    b: [x1, y1],
                    c: [x1, y0],
                },
                Tri {
                    a: [x1, y1],
                    b: [x0, y0],
                    c: [x0, y1],
                },
            ]
        } else {
            [
                Tri {
                    a: [x0, y1],
                    b: [x1, y0],
                    c: [x0, y0],
                },
                Tri {
                    a: [x1, y0],
                    b: [x0, y1],
                    c: [x1, y1],
                },
            ]
        }
    }

    /// Walk the tree under the `s`-cell at `(x0, y0)`: split a triangle while its hypotenuse
    /// midpoint's bound exceeds `max_error`, never below cells of `min_step` (a power of two ≥ 1).
    /// Calls `emit(tri, bound)` for each kept triangle, `bound` being its error bound (0 for a cell
    /// of one sample step; `INFINITY` if it spans no-data it could not split away).
    pub fn walk(
        &self,
        x0: u32,
        y0: u32,
        s: u32,
        max_error: f32,
        min_step: u32,
        mut emit: impl FnMut(Tri, f32),
    ) {
        let mut stack: Vec<Tri> = self.cell_triangles(x0, y0, s).into_iter().rev().collect();
        while let Some(t) = stack.pop() {
            let [ax, ay] = t.a;
            let [bx, by] = t.b;
            let [cx, cy] = t.c;
            let d = ax.abs_diff(cx) + ay.abs_diff(cy);
            let square = ax == cx || ay == cy;
            let splittable = if square { d > min_step } else { true } && d > 1;
            let (mx, my) = ((ax + bx) / 2, (ay + by) / 2);
            let bound = if d > 1 { self.error_at(mx, my) } else { 0.0 };
            if splittable && bound > max_error {
                let m = [mx, my];
                // Push the second child first so the first is walked first.
                stack.push(Tri {
                    a: t.b,
                    b: t.c,
                    c: m,
                });
                stack.push(Tri {
                    a: t.c,
                    b: t.a,
                    c: m,
                });
            } else {
                emit(t, bound);
            }
        }
    }
}

/// Whether the `s`-cell with index `(i, j)` is cut by its main diagonal `(x0, y0)–(x0+s, y0+s)`:
/// the diagonal passes through the parent cell's centre, i.e. the main one when `i` and `j` have
/// the same parity; the whole square (`s = size`) uses the main diagonal.
fn is_main_diagonal(i: u32, j: u32, s: u32, size: u32) -> bool {
    s == size || (i & 1) == (j & 1)
}

/// Exact error of the two triangles of an `s`-cell against their planes, row by row.
fn cell_error(heights: &[f32], nu: usize, x0: u32, y0: u32, s: u32, main: bool) -> f32 {
    let at = |x: u32, y: u32| heights[y as usize * nu + x as usize];
    let h00 = at(x0, y0);
    let h10 = at(x0 + s, y0);
    let h01 = at(x0, y0 + s);
    let h11 = at(x0 + s, y0 + s);
    if s == 2 {
        // The finest cells: besides the corners, the centre (on the diagonal) and the four edge
        // midpoints (on the legs), each measured against the line it lies on.
        let (hc, ht, hb, hl, hr) = (
            at(x0 + 1, y0 + 1),
            at(x0 + 1, y0),
            at(x0 + 1, y0 + 2),
            at(x0, y0 + 1),
            at(x0 + 2, y0 + 1),
        );
        let diag = if main {
            0.5 * (h00 + h11)
        } else {
            0.5 * (h10 + h01)
        };
        let all = [h00, h10, h01, h11, hc, ht, hb, hl, hr];
        let nodata = all.iter().filter(|v| v.is_nan()).count();
        if nodata == 9 {
            return 0.0;
        } else if nodata > 0 {
            return f32::INFINITY;
        }
        return (hc - diag)
            .abs()
            .max((ht - 0.5 * (h00 + h10)).abs())
            .max((hb - 0.5 * (h01 + h11)).abs())
            .max((hl - 0.5 * (h00 + h01)).abs())
            .max((hr - 0.5 * (h10 + h11)).abs());
    }
    let inv = 1.0 / s as f32;
    let mut acc = Acc::new();
    for v in 0..=s {
        let fv = v as f32 * inv;
        let start = (y0 + v) as usize * nu + x0 as usize;
        let row = &heights[start..=start + s as usize];
        if main {
            // u < v: the lower-left triangle (h00, h01, h11); u ≥ v: the upper-right (h00, h10, h11).
            let split = v as usize;
            acc.scan(&row[..split], h00 + (h01 - h00) * fv, (h11 - h01) * inv);
            let (b1, d1) = (h00 + (h11 - h10) * fv, (h10 - h00) * inv);
            acc.scan(&row[split..], b1 + d1 * split as f32, d1);
        } else {
            // u + v ≤ s: the upper-left triangle (h00, h10, h01); beyond: the lower-right (h10, h01, h11).
            let split = (s - v) as usize + 1;
            acc.scan(&row[..split], h00 + (h01 - h00) * fv, (h10 - h00) * inv);
            let d2 = -(h01 - h11) * inv;
            let b2 = h11 + (h01 - h11) + (h10 - h11) * (1.0 - fv);
            acc.scan(&row[split..], b2 + d2 * split as f32, d2);
        }
    }
    acc.value()
}

/// Exact error of the (one or two) triangles whose hypotenuse is the lattice edge of length `2h`
/// centred at `(mx, my)`: horizontal edge -> apexes above and below, vertical -> left and right.
/// Samples on the edge are visited once per side (harmless for a max).
fn diamond_error(
    heights: &[f32],
    nu: usize,
    mx: u32,
    my: u32,
    h: u32,
    horizontal: bool,
    size: u32,
) -> f32 {
    let at = |x: u32, y: u32| heights[y as usize * nu + x as usize];
    if h == 1 {
        // The finest diamonds: the only sample not a vertex of its triangle is the midpoint.
        let (a, b) = if horizontal {
            (at(mx - 1, my), at(mx + 1, my))
        } else {
            (at(mx, my - 1), at(mx, my + 1))
        };
        let m = at(mx, my);
        let (p, q) = if horizontal {
            (
                (my >= 1).then(|| at(mx, my - 1)),
                (my < size).then(|| at(mx, my + 1)),
            )
        } else {
            (
                (mx >= 1).then(|| at(mx - 1, my)),
                (mx < size).then(|| at(mx + 1, my)),
            )
        };
        let samples = [Some(a), Some(b), Some(m), p, q];
        let seen = samples.iter().flatten().count();
        let nodata = samples.iter().flatten().filter(|v| v.is_nan()).count();
        return if nodata == 0 {
            (m - 0.5 * (a + b)).abs()
        } else if nodata == seen {
            0.0
        } else {
            f32::INFINITY
        };
    }
    let mut acc = Acc::new();
    let inv = 1.0 / h as f32;
    let half = 0.5 * inv;
    if horizontal {
        let (ha, hb) = (at(mx - h, my), at(mx + h, my));
        let mid = 0.5 * (ha + hb);
        let slope = (hb - ha) * half;
        for side in [-1i64, 1] {
            let ay = my as i64 + side * h as i64;
            if ay < 0 || ay > size as i64 {
                continue;
            }
            let lift = at(mx, ay as u32) - mid;
            for wa in 0..=h {
                let y = (my as i64 + side * wa as i64) as usize;
                let r = h - wa;
                let x_start = mx - r;
                let start = y * nu + x_start as usize;
                let base = ha + slope * (x_start - (mx - h)) as f32 + lift * wa as f32 * inv;
                acc.scan(&heights[start..=start + 2 * r as usize], base, slope);
            }
        }
    } else {
        let (ha, hb) = (at(mx, my - h), at(mx, my + h));
        let mid = 0.5 * (ha + hb);
        let left = (mx >= h).then(|| at(mx - h, my) - mid);
        let right = (mx + h <= size).then(|| at(mx + h, my) - mid);
        for t in -(h as i64)..=h as i64 {
            let y = (my as i64 + t) as usize;
            let r = h - t.unsigned_abs() as u32;
            let along = ha + (hb - ha) * (t + h as i64) as f32 * half;
            if let Some(l) = left {
                let start = y * nu + (mx - r) as usize;
                acc.scan(
                    &heights[start..=start + r as usize],
                    along + l * r as f32 * inv,
                    -l * inv,
                );
            }
            if let Some(rl) = right {
                let start = y * nu + mx as usize;
                acc.scan(&heights[start..=start + r as usize], along, rl * inv);
            }
        }
    }
    acc.value()
}

/// A mesh extracted from an error map: grid sample indices per vertex, triangles over them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GridMesh {
    /// `(x, y)` grid sample of each vertex, in the order the walk first meets them.
    pub vertices: Vec<[u32; 2]>,
    /// Counter-clockwise seen from above (x east, y down the rows, heights up).
    pub triangles: Vec<[u32; 3]>,
    /// Largest error bound among the kept triangles (finite ones).
    pub max_bound: f32,
    /// Kept triangles whose bound is infinite: they span no-data they were not allowed to split away.
    pub bridging: u32,
}

/// Extract the mesh under the `s`-cell at `(x0, y0)` (the whole grid: `(0, 0, n − 1)`); triangles
/// with a no-data vertex are dropped.
pub fn extract(
    map: &ErrorMap,
    heights: &[f32],
    x0: u32,
    y0: u32,
    s: u32,
    max_error: f32,
    min_step: u32,
) -> GridMesh {
    let n = map.n;
    // Dense remap over the cell's lattice of `min_step` samples (every emitted vertex lies on
    // it: the walk stops only at triangles whose legs are axis-aligned and at least `min_step`
    // long), with vertex numbers in first-use order (deterministic). A coarse chunk of a large
    // grid thus needs `(s / min_step + 1)²` slots, not one per grid sample.
    let g = if min_step > 1
        && x0.is_multiple_of(min_step)
        && y0.is_multiple_of(min_step)
        && s.is_multiple_of(min_step)
    {
        min_step
    } else {
        1
    };
    let side = (s / g) as usize + 1;
    let mut index = vec![u32::MAX; side * side];
    let mut vertices: Vec<[u32; 2]> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut max_bound = 0.0f32;
    let mut bridging = 0;
    map.walk(x0, y0, s, max_error, min_step, |t, bound| {
        let pts = [t.a, t.b, t.c];
        if pts
            .iter()
            .any(|p| heights[(p[1] * n + p[0]) as usize].is_nan())
        {
            return;
        }
        if bound.is_finite() {
            max_bound = max_bound.max(bound);
        } else {
            bridging += 1;
        }
        tris.push(pts.map(|p| {
            let (dx, dy) = (p[0] - x0, p[1] - y0);
            debug_assert!(
                dx.is_multiple_of(g) && dy.is_multiple_of(g),
                "vertex off the lattice"
            );
            let slot = &mut index[(dy / g) as usize * side + (dx / g) as usize];
            if *slot == u32::MAX {
                *slot = vertices.len() as u32;
                vertices.push(p);
            }
            *slot
        }));
    });
    GridMesh {
        vertices,
        triangles: tris,
        max_bound,
        bridging,
    }
}

/// Pad a `w x h` grid with no-data to the smallest `(2^k + 1)²` square holding it (borrowed
/// as is when it already is one: no copy of a large grid).
pub fn pad_to_rtin(heights: &[f32], w: u32, h: u32) -> (std::borrow::Cow<'_, [f32]>, u32) {
    let need = w.max(h).max(3) - 1;
    let n = need.next_power_of_two() + 1;
    if n == w && n == h {
        return (std::borrow::Cow::Borrowed(heights), n);
    }
    let mut out = vec![f32::NAN; n as usize * n as usize];
    for r in 0..h as usize {
        out[r * n as usize..r * n as usize + w as usize]
            .copy_from_slice(&heights[r * w as usize..(r + 1) * w as usize]);
    }
    (std::borrow::Cow::Owned(out), n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32, f: impl Fn(f64, f64) -> f64) -> Vec<f32> {
        (0..n * n)
            .map(|i| f((i % n) as f64, (i / n) as f64) as f32)
            .collect()
    }

    #[test]
    fn plane_is_two_triangles_and_exact() {
        let n = 65;
        let h = grid(n, |x, y| 3.0 * x - 2.0 * y + 10.0);
        let m = ErrorMap::new(&h, n);
        let mesh = extract(&m, &h, 0, 0, n - 1, 0.0, 1);
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!(mesh.vertices.len(), 4);
    }

    #[test]
    fn zero_error_keeps_every_cell_of_a_paraboloid() {
        // A paraboloid has no plane over more than one cell: at error 0 every cell is 2 triangles.
        let n = 17;
        let h = grid(n, |x, y| (x - 7.3).powi(2) + (y - 4.1).powi(2));
        let m = ErrorMap::new(&h, n);
        let mesh = extract(&m, &h, 0, 0, n - 1, 0.0, 1);
        assert_eq!(mesh.triangles.len(), 2 * 16 * 16);
        assert_eq!(mesh.vertices.len(), 17 * 17);
    }

    #[test]
    fn bound_is_exact_on_a_single_bump() {
        // One raised centre sample on a 3x3 grid: the two top triangles err by exactly 5; the four
        // triangles around the centre represent it exactly.
        let mut h = vec![0.0f32; 9];
        h[4] = 5.0;
        let m = ErrorMap::new(&h, 3);
        assert_eq!(m.error_at(1, 1), 5.0);
        assert_eq!(extract(&m, &h, 0, 0, 2, 5.0, 1).triangles.len(), 2);
        assert_eq!(extract(&m, &h, 0, 0, 2, 4.99, 1).triangles.len(), 4);
    }
}

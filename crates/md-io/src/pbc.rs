//! Periodic boundaries: wrap atoms into the box, make bonded molecules whole across it, and drop
//! bonds that would be drawn across the box.
//!
//! - [`wrap`] moves every atom by whole cell vectors into the cell (fractional coordinates in
//!   [0, 1)), as `gmx trjconv -pbc atom`, VMD `pbc wrap` and MDAnalysis `atoms.wrap()` do.
//! - [`unwrap`] makes each molecule (a connected set of bonds) whole: a breadth-first walk from
//!   the molecule's lowest-index atom places every bonded neighbour at the nearest periodic
//!   image of its distance from the atom it was reached from (`gmx trjconv -pbc mol`, VMD
//!   `pbc unwrap` per molecule). Atoms without bonds stay where they are. Linear in atoms and
//!   bonds.
//! - [`drop_crossing`] keeps only the bonds whose two atoms are already at their nearest image
//!   of each other, so that a molecule the trajectory wrapped is never drawn with a stick
//!   through the whole box.
//!
//! Nearest images ([`minimum_image`], [`NearestImage`] for many displacements in one cell) round
//! the fractional offset along the periodic edges; in a skewed cell, when the rounded offset is
//! longer than half the cell's smallest height (where rounding can miss the nearest image: a
//! truncated octahedron's far corners), the shortest of it and its 26 neighbouring images is
//! taken. That is the nearest image in every cell whose tilts are reduced as GROMACS and LAMMPS
//! keep them (no tilt beyond half the edge it leans along; the tests check it against a search
//! of 343 images).

use crate::frame::{Frame, UnitCell};

/// Fractional coordinates of a Cartesian displacement `d` in `cell` (solving f·M = d; M's rows
/// are the edges, lower-triangular in the usual orientation, general here).
pub(crate) fn to_frac(m: &[[f64; 3]; 3], d: [f64; 3]) -> [f64; 3] {
    // Cramer's rule: f = d · M⁻¹.
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let col = |k: usize| {
        let mut mm = *m;
        mm[k] = d;
        mm[0][0] * (mm[1][1] * mm[2][2] - mm[1][2] * mm[2][1])
            - mm[0][1] * (mm[1][0] * mm[2][2] - mm[1][2] * mm[2][0])
            + mm[0][2] * (mm[1][0] * mm[2][1] - mm[1][1] * mm[2][0])
    };
    [col(0) / det, col(1) / det, col(2) / det]
}

pub(crate) fn to_cart(m: &[[f64; 3]; 3], f: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k])
}

/// The nearest periodic image of displacement `d` (Å) in `cell`: whole edges taken off along
/// the periodic edges only (see the module docs). For many displacements in one cell,
/// [`NearestImage`] does the set-up once.
pub fn minimum_image(cell: &UnitCell, d: [f64; 3]) -> [f64; 3] {
    match NearestImage::new(cell) {
        Some(image) => image.apply(d),
        None => d,
    }
}

/// A cell's nearest-image search, set up once: [`NearestImage::apply`] is [`minimum_image`].
#[derive(Clone, Copy, Debug)]
pub struct NearestImage {
    pub(crate) matrix: [[f64; 3]; 3],
    inverse: [[f64; 3]; 3],
    pub(crate) periodic: [bool; 3],
    /// Below this squared length a rounded offset is the nearest image.
    pub(crate) safe2: f64,
}

impl NearestImage {
    /// The search for `cell`; `None` when no edge is periodic (every displacement is its own
    /// nearest image) or the cell has no volume.
    pub fn new(cell: &UnitCell) -> Option<NearestImage> {
        let periodic = cell.periodic();
        if !periodic.contains(&true) {
            return None;
        }
        let m = basis(cell.matrix(), periodic)?;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if !(det.is_finite() && det.abs() > 1e-12) {
            return None;
        }
        // Rows of `m` are the basis: a displacement is f · m, so f = d · m⁻¹.
        let inv = |r: usize, c: usize| {
            let (r1, r2) = ((c + 1) % 3, (c + 2) % 3);
            let (c1, c2) = ((r + 1) % 3, (r + 2) % 3);
            (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det
        };
        // Below half the smallest height of the periodic edges over the faces of the other two
        // rows, rounding is exact; at any length when the periodic edges are orthogonal.
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let orthogonal = (0..3).all(|i| {
            (i + 1..3).all(|j| {
                !(periodic[i] && periodic[j])
                    || dot(m[i], m[j]).abs() <= 1e-12 * dot(m[i], m[i]).max(dot(m[j], m[j]))
            })
        });
        let safe2 = if orthogonal {
            f64::INFINITY
        } else {
            let height = |k: usize| {
                let c = cross(m[(k + 1) % 3], m[(k + 2) % 3]);
                det.abs() / dot(c, c).sqrt()
            };
            let half = (0..3)
                .filter(|&k| periodic[k])
                .map(height)
                .fold(f64::INFINITY, f64::min)
                / 2.0;
            half * half
        };
        Some(NearestImage {
            matrix: m,
            inverse: std::array::from_fn(|r| std::array::from_fn(|c| inv(r, c))),
            periodic,
            safe2,
        })
    }

    /// The nearest image of displacement `d` (Å).
    #[inline]
    pub fn apply(&self, d: [f64; 3]) -> [f64; 3] {
        let f: [f64; 3] = std::array::from_fn(|k| {
            let v =
                d[0] * self.inverse[0][k] + d[1] * self.inverse[1][k] + d[2] * self.inverse[2][k];
            if self.periodic[k] { v - v.round() } else { v }
        });
        let d: [f64; 3] = std::array::from_fn(|k| {
            f[0] * self.matrix[0][k] + f[1] * self.matrix[1][k] + f[2] * self.matrix[2][k]
        });
        let len2 = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if len2(d) <= self.safe2 {
            return d;
        }
        let shifts = |k: usize| if self.periodic[k] { -1..=1 } else { 0..=0 };
        let mut best = d;
        for a in shifts(0) {
            for b in shifts(1) {
                for c in shifts(2) {
                    let s = [f64::from(a), f64::from(b), f64::from(c)];
                    let v = std::array::from_fn(|k| {
                        d[k] + s[0] * self.matrix[0][k]
                            + s[1] * self.matrix[1][k]
                            + s[2] * self.matrix[2][k]
                    });
                    if len2(v) < len2(best) {
                        best = v;
                    }
                }
            }
        }
        best
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalised(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// The basis nearest images are taken in: the periodic edges, and in place of each open edge a
/// unit vector orthogonal to the periodic ones, so that an open edge's tilt (a film's leaning
/// `c`) never shifts a displacement's part along the periodic lattice. `None` for a flat cell.
fn basis(m: [[f64; 3]; 3], periodic: [bool; 3]) -> Option<[[f64; 3]; 3]> {
    let mut b = m;
    let open: Vec<usize> = (0..3).filter(|&k| !periodic[k]).collect();
    match open[..] {
        [] => {}
        [k] => b[k] = normalised(cross(m[(k + 1) % 3], m[(k + 2) % 3])),
        [j, k] => {
            let i = 3 - j - k;
            let e = m[i];
            // The axis least along the periodic edge, crossed with it, and the third at right
            // angles to both.
            let least = (0..3)
                .min_by(|&x, &y| e[x].abs().total_cmp(&e[y].abs()))
                .unwrap_or(0);
            let mut axis = [0.0; 3];
            axis[least] = 1.0;
            let u = normalised(cross(e, axis));
            b[j] = u;
            b[k] = normalised(cross(e, u));
        }
        _ => return None,
    }
    b.iter().flatten().all(|x| x.is_finite()).then_some(b)
}

/// Moves every atom of `frame` into its cell along the periodic edges (no-op without a cell).
pub fn wrap(frame: &mut Frame) {
    if let Some(cell) = frame.cell {
        wrap_positions(&cell, &mut frame.positions);
    }
}

/// Moves every position into `cell` along its periodic edges.
pub fn wrap_positions(cell: &UnitCell, positions: &mut [[f32; 3]]) {
    let m = cell.matrix();
    let o = cell.origin();
    for p in positions {
        let d = [p[0] as f64 - o[0], p[1] as f64 - o[1], p[2] as f64 - o[2]];
        let f = to_frac(&m, d);
        let periodic = cell.periodic();
        let shift = to_cart(
            &m,
            std::array::from_fn(|k| if periodic[k] { f[k].floor() } else { 0.0 }),
        );
        for k in 0..3 {
            p[k] = (d[k] - shift[k] + o[k]) as f32;
        }
    }
}

/// Makes every bonded molecule of `frame` whole across the box (no-op without a cell). `bonds`
/// are atom index pairs; pairs naming atoms past the frame are ignored.
pub fn unwrap(frame: &mut Frame, bonds: &[[u32; 2]]) {
    let Some(cell) = frame.cell else { return };
    let n = frame.n_atoms();
    let (start, adj) = adjacency(n, bonds);
    let mut seen = vec![false; n];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..n {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        queue.push_back(root);
        while let Some(a) = queue.pop_front() {
            let pa = frame.positions[a];
            for &c in &adj[start[a] as usize..start[a + 1] as usize] {
                let c = c as usize;
                if seen[c] {
                    continue;
                }
                seen[c] = true;
                let pc = frame.positions[c];
                let d = minimum_image(&cell, std::array::from_fn(|k| (pc[k] - pa[k]) as f64));
                frame.positions[c] = std::array::from_fn(|k| (pa[k] as f64 + d[k]) as f32);
                queue.push_back(c);
            }
        }
    }
}

/// Each of `n` atoms' partners in `pairs` (both ways; pairs naming an atom past `n` left out), in
/// CSR form: atom a's are `list[start[a]..start[a + 1]]`, in the pairs' order.
pub(crate) fn adjacency<'a>(
    n: usize,
    pairs: impl IntoIterator<Item = &'a [u32; 2]> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let inside = |b: &&[u32; 2]| (b[0] as usize) < n && (b[1] as usize) < n;
    let mut start = vec![0u32; n + 1];
    for b in pairs.clone().into_iter().filter(inside) {
        start[b[0] as usize + 1] += 1;
        start[b[1] as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut list = vec![0u32; start[n] as usize];
    for b in pairs.into_iter().filter(inside) {
        for (a, c) in [(b[0], b[1]), (b[1], b[0])] {
            list[fill[a as usize] as usize] = c;
            fill[a as usize] += 1;
        }
    }
    (start, list)
}

/// The bonds of `pairs` whose atoms are at their nearest image of each other in `positions`
/// (all of them without a cell).
pub fn drop_crossing(pairs: &mut Vec<[u32; 2]>, positions: &[[f32; 3]], cell: Option<&UnitCell>) {
    let Some(cell) = cell else { return };
    let n = positions.len();
    pairs.retain(|b| {
        let (i, j) = (b[0] as usize, b[1] as usize);
        if i >= n || j >= n {
            return false;
        }
        let d: [f64; 3] = std::array::from_fn(|k| (positions[j][k] - positions[i][k]) as f64);
        let mi = minimum_image(cell, d);
        let l2 = |v: [f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        l2(d) <= l2(mi) + 1e-3
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triclinic() -> UnitCell {
        UnitCell::from_lengths_angles([20.0, 22.0, 25.0], [80.0, 95.0, 105.0])
            .unwrap()
            .with_origin([1.0, -2.0, 3.0])
    }

    /// A small deterministic generator for the tests' random offsets and cells.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn the_nearest_image_is_the_shortest_of_343_in_reduced_skewed_cells() {
        let mut unit = uniform(2024);
        let mut searched = 0;
        for case in 0..40 {
            // A LAMMPS-style cell: edges along x, in the xy plane, anywhere, each tilt at most
            // half the edge it leans along; the first case GROMACS's truncated octahedron.
            let cell = if case == 0 {
                UnitCell::from_lengths_angles([60.0, 60.0, 60.0], [70.53, 109.47, 70.53]).unwrap()
            } else {
                let (lx, ly, lz) = (
                    20.0 + 40.0 * unit(),
                    20.0 + 40.0 * unit(),
                    20.0 + 40.0 * unit(),
                );
                let tilt = |unit: &mut dyn FnMut() -> f64, l: f64| (unit() - 0.5) * l;
                let xy = tilt(&mut unit, lx);
                let xz = tilt(&mut unit, lx);
                let yz = tilt(&mut unit, ly);
                UnitCell::from_matrix([[lx, 0.0, 0.0], [xy, ly, 0.0], [xz, yz, lz]])
                    .unwrap()
                    .with_periodic(match case % 6 {
                        4 => [true, true, false],
                        5 => [false, true, false],
                        _ => [true; 3],
                    })
            };
            let m = cell.matrix();
            let p = cell.periodic();
            let image = NearestImage::new(&cell).unwrap();
            let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            for _ in 0..300 {
                let d: [f64; 3] = std::array::from_fn(|_| (unit() - 0.5) * 300.0);
                let ours = image.apply(d);
                assert_eq!(ours, minimum_image(&cell, d));
                // Whole edges only: ours − d is an integer combination of the periodic edges.
                let moved = to_frac(&m, std::array::from_fn(|k| ours[k] - d[k]));
                for k in 0..3 {
                    let whole = moved[k].round();
                    assert!((moved[k] - whole).abs() < 1e-6, "{moved:?}");
                    assert!(p[k] || whole == 0.0, "moved along an open edge: {moved:?}");
                }
                // No image within ±3 cells of ours is shorter.
                let r = |k: usize| if p[k] { -3..=3 } else { 0..=0 };
                let mut best = f64::INFINITY;
                for a in r(0) {
                    for b in r(1) {
                        for c in r(2) {
                            let s = [f64::from(a), f64::from(b), f64::from(c)];
                            let v = std::array::from_fn(|k| {
                                ours[k] + s[0] * m[0][k] + s[1] * m[1][k] + s[2] * m[2][k]
                            });
                            best = best.min(len(v));
                        }
                    }
                }
                assert!(len(ours) <= best + 1e-9, "{d:?}: {} > {best}", len(ours));
                let f = to_frac(&m, d);
                let rounded = to_cart(
                    &m,
                    std::array::from_fn(|k| if p[k] { f[k] - f[k].round() } else { f[k] }),
                );
                if len(rounded) > len(ours) + 1e-9 {
                    searched += 1;
                }
            }
        }
        // Rounding alone would have missed the nearest image this often.
        assert!(searched > 100, "{searched}");
    }

    #[test]
    fn wrap_moves_by_whole_cell_vectors_into_the_cell() {
        let cell = triclinic();
        let m = cell.matrix();
        let mut f = Frame::new();
        f.positions = vec![[-30.0, 41.0, 7.0], [5.0, 5.0, 5.0], [100.0, -100.0, 60.0]];
        f.cell = Some(cell);
        let before = f.positions.clone();
        wrap(&mut f);
        for (p, q) in f.positions.iter().zip(&before) {
            let o = cell.origin();
            let fr = to_frac(&m, std::array::from_fn(|k| p[k] as f64 - o[k]));
            assert!(fr.iter().all(|x| (-1e-6..1.0 + 1e-6).contains(x)), "{fr:?}");
            // The move is an integer combination of the edges.
            let mv = to_frac(&m, std::array::from_fn(|k| (q[k] - p[k]) as f64));
            assert!(mv.iter().all(|x| (x - x.round()).abs() < 1e-4), "{mv:?}");
        }
    }

    #[test]
    fn unwrap_makes_a_split_water_whole_and_drop_crossing_removes_its_long_bonds() {
        let cell = UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap();
        let mut f = Frame::new();
        // O near x = 0, its hydrogens wrapped to the far face.
        f.positions = vec![[0.1, 5.0, 5.0], [9.5, 5.3, 5.0], [9.6, 4.4, 5.0]];
        f.cell = Some(cell);
        let bonds = [[0u32, 1u32], [0, 2]];
        let mut kept = bonds.to_vec();
        drop_crossing(&mut kept, &f.positions, Some(&cell));
        assert!(kept.is_empty());
        unwrap(&mut f, &bonds);
        assert_eq!(f.positions[0], [0.1, 5.0, 5.0]);
        let d =
            |a: [f32; 3], b: [f32; 3]| ((0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>()).sqrt();
        // The O–H lengths are the minimum-image ones: sqrt(0.6² + 0.3²) and sqrt(0.5² + 0.6²).
        assert!((d(f.positions[0], f.positions[1]) - 0.45f32.sqrt()).abs() < 1e-5);
        assert!((d(f.positions[0], f.positions[2]) - 0.61f32.sqrt()).abs() < 1e-5);
        let mut kept = bonds.to_vec();
        drop_crossing(&mut kept, &f.positions, Some(&cell));
        assert_eq!(kept, bonds.to_vec());
    }
}

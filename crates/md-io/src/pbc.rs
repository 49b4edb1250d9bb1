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
//! Nearest images come from rounding fractional differences ([`minimum_image`]): exact for
//! orthorhombic cells and for the moderately skewed triclinic cells MD uses.

use crate::frame::{Frame, UnitCell};

/// Fractional coordinates of a Cartesian displacement `d` in `cell` (solving f·M = d; M's rows
/// are the edges, lower-triangular in the usual orientation, general here).
fn to_frac(m: &[[f64; 3]; 3], d: [f64; 3]) -> [f64; 3] {
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

fn to_cart(m: &[[f64; 3]; 3], f: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k])
}

/// The nearest periodic image of displacement `d` (Å) in `cell`: whole edges taken off along
/// the periodic edges only.
pub fn minimum_image(cell: &UnitCell, d: [f64; 3]) -> [f64; 3] {
    let m = cell.matrix();
    let p = cell.periodic();
    let mut f = to_frac(&m, d);
    for k in 0..3 {
        if p[k] {
            f[k] -= f[k].round();
        }
    }
    to_cart(&m, f)
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

//! Periodic images: a frame copied along its cell vectors, as OVITO's Replicate modifier and
//! VMD's periodic images do, so that a crystal, a surface slab or a liquid cell is shown as the
//! extended material it stands for rather than as one box.
//!
//! [`replicate`] with `n = [nx, ny, nz]` makes `nx·ny·nz` copies, with OVITO's conventions, so
//! that a frame replicated here and in OVITO lists the same atoms in the same order:
//! - along axis `k` the images run from `-(n_k - 1) / 2` to `n_k / 2` (integer division): two
//!   images are the original and the next one along +k, three are centred on the original;
//! - copies are listed image by image, the x image outermost and the z image innermost, each
//!   copy in the frame's atom order;
//! - the cell grows to `n_k` times each edge vector, its origin moved to the lowest image;
//! - atom ids and residue ids (LAMMPS molecule ids) of image number `m` (in listing order) are
//!   offset by `m · (max − min + 1)` of the frame's values, so they stay unique (OVITO's
//!   `unique_ids`); every other column is copied.
//!
//! Positions are copied as they are (not wrapped: use `pbc::wrap` first for a tidy block).
//! Bonds follow the periodic images: a bond whose two atoms are at different images of each
//! other (it crosses the box) joins, in each copy, the first atom to the copy of the second
//! atom in the neighbouring image it reaches across to, taken modulo `n` at the outer faces.
//! So bonds across the inner faces become whole sticks, and those across the outer faces still
//! cross the enlarged box (where `pbc::drop_crossing` drops them, as for any periodic frame).
//!
//! ```
//! use texmap_md_io::replicate::replicate;
//! use texmap_md_io::{Frame, UnitCell};
//! let mut frame = Frame::new();
//! frame.positions = vec![[0.5, 1.0, 1.0], [3.5, 1.0, 1.0]];
//! frame.cell = Some(UnitCell::orthorhombic(4.0, 5.0, 6.0).unwrap());
//! // The two atoms are bonded across the x face of the box.
//! let mut bonds = vec![[0, 1]];
//! // Three images along x: one before the original, the original, one after.
//! replicate(&mut frame, &mut bonds, [3, 1, 1]).unwrap();
//! assert_eq!(frame.n_atoms(), 6);
//! assert_eq!(frame.positions[0], [-3.5, 1.0, 1.0]);
//! assert_eq!(frame.positions[2], [0.5, 1.0, 1.0]);
//! assert_eq!(frame.cell.unwrap().lengths(), [12.0, 5.0, 6.0]);
//! // Atom 0 of each copy bonds to atom 1 of the copy before it (0.5 -> -0.5): [1, 2] and
//! // [3, 4] are whole sticks; [0, 5] reaches across the outer faces.
//! assert_eq!(bonds, vec![[0, 5], [1, 2], [3, 4]]);
//! ```

use std::fmt;

use glam::{DMat3, DVec3};

use crate::frame::{Frame, UnitCell};

/// At most this many atoms after replication (a typo such as `100,100,100` would otherwise ask
/// for memory the machine lacks).
pub const MAX_REPLICATED_ATOMS: usize = 200_000_000;

/// Why a frame cannot be replicated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ReplicateError {
    /// The frame has no periodic cell to copy along.
    NoCell,
    /// An image count is zero.
    ZeroCount,
    /// The copies would hold more than [`MAX_REPLICATED_ATOMS`] atoms.
    TooLarge {
        /// Atoms the copies would hold.
        atoms: u128,
    },
}

impl fmt::Display for ReplicateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReplicateError::NoCell => {
                write!(f, "the frame has no periodic cell to replicate along")
            }
            ReplicateError::ZeroCount => write!(f, "every image count must be at least 1"),
            ReplicateError::TooLarge { atoms } => write!(
                f,
                "the copies would hold {atoms} atoms, more than the {MAX_REPLICATED_ATOMS} allowed"
            ),
        }
    }
}

impl std::error::Error for ReplicateError {}

/// The image offsets along one axis with `n` images: `-(n-1)/2 ..= n/2` (what [`replicate`]
/// copies along each cell vector; for other things drawn with the images, such as a periodic
/// grid's isosurface).
pub fn images(n: usize) -> std::ops::RangeInclusive<i64> {
    -((n as i64 - 1) / 2)..=n as i64 / 2
}

/// Copies `frame` `n[0]·n[1]·n[2]` times along its cell vectors and `bonds` with it (see the
/// module docs), and [`Frame::bonds`] likewise. `bonds` are index pairs into the frame; they
/// come back sorted, each `[i, j]` with `i < j`. Nothing changes on error.
pub fn replicate(
    frame: &mut Frame,
    bonds: &mut Vec<[u32; 2]>,
    n: [usize; 3],
) -> Result<(), ReplicateError> {
    let cell = frame.cell.ok_or(ReplicateError::NoCell)?;
    if n.contains(&0) {
        return Err(ReplicateError::ZeroCount);
    }
    let copies = n[0] * n[1] * n[2];
    let atoms = frame.n_atoms();
    let total = atoms as u128 * copies as u128;
    if total > MAX_REPLICATED_ATOMS as u128 {
        return Err(ReplicateError::TooLarge { atoms: total });
    }
    if copies == 1 {
        return Ok(());
    }
    let rows = cell.matrix().map(DVec3::from_array);
    // Image offsets in listing order (x outermost).
    let mut offsets = Vec::with_capacity(copies);
    for i in images(n[0]) {
        for j in images(n[1]) {
            for k in images(n[2]) {
                offsets.push([i, j, k]);
            }
        }
    }
    let shifts: Vec<DVec3> = offsets
        .iter()
        .map(|o| rows[0] * o[0] as f64 + rows[1] * o[1] as f64 + rows[2] * o[2] as f64)
        .collect();

    // Bonds first: the image each bond reaches across to, from the original positions.
    let m = DMat3::from_cols(rows[0], rows[1], rows[2]);
    let inverse = m.inverse();
    let pos = |i: u32| DVec3::from_array(frame.positions[i as usize].map(f64::from));
    let image_index = |o: [i64; 3]| -> usize {
        let wrap = |v: i64, k: usize| {
            let lo = *images(n[k]).start();
            (v - lo).rem_euclid(n[k] as i64) as usize
        };
        (wrap(o[0], 0) * n[1] + wrap(o[1], 1)) * n[2] + wrap(o[2], 2)
    };
    let images_of = |bonds: &[[u32; 2]]| {
        let mut out = Vec::with_capacity(bonds.len() * copies);
        for &[a, b] in bonds {
            // b's nearest image to a lies `back` cells from b.
            let back = -(inverse * (pos(b) - pos(a))).round();
            let back = [back.x as i64, back.y as i64, back.z as i64];
            for (m_a, o) in offsets.iter().enumerate() {
                let m_b = image_index([o[0] + back[0], o[1] + back[1], o[2] + back[2]]);
                let i = (m_a * atoms) as u32 + a;
                let j = (m_b * atoms) as u32 + b;
                out.push([i.min(j), i.max(j)]);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    };
    *bonds = images_of(bonds);
    // The frame's own bonds (SDF, MOL2) follow the copies the same way, each copy with its
    // original's order.
    let frame_bonds = images_of(&frame.bonds);
    if !frame.bond_orders.is_empty() && frame.bond_orders.len() == frame.bonds.len() {
        let original = |i: u32| i % atoms as u32;
        frame.bond_orders = frame_bonds
            .iter()
            .map(|&[i, j]| {
                let (a, b) = (original(i), original(j));
                let pair = [a.min(b), a.max(b)];
                frame
                    .bonds
                    .binary_search(&pair)
                    .map_or(0, |k| frame.bond_orders[k])
            })
            .collect();
    }
    frame.bonds = frame_bonds;

    // Positions by image; every other per-atom column copied.
    let positions = std::mem::take(&mut frame.positions);
    frame.positions = shifts
        .iter()
        .flat_map(|s| {
            positions.iter().map(move |p| {
                [
                    (p[0] as f64 + s.x) as f32,
                    (p[1] as f64 + s.y) as f32,
                    (p[2] as f64 + s.z) as f32,
                ]
            })
        })
        .collect();
    fn tile<T: Copy>(v: &mut Vec<T>, copies: usize) {
        if !v.is_empty() {
            *v = v.repeat(copies);
        }
    }
    tile(&mut frame.velocities, copies);
    tile(&mut frame.names, copies);
    tile(&mut frame.elements, copies);
    tile(&mut frame.types, copies);
    tile(&mut frame.res_names, copies);
    tile(&mut frame.chains, copies);
    tile(&mut frame.segments, copies);
    tile(&mut frame.radii, copies);
    tile(&mut frame.colors, copies);
    for p in &mut frame.properties {
        tile(&mut p.values, copies);
    }
    // Ids stay unique: each image's offset by the span of the frame's ids.
    fn unique(v: &mut Vec<i64>, copies: usize) {
        let (Some(lo), Some(hi)) = (v.iter().min(), v.iter().max()) else {
            return;
        };
        let span = hi - lo + 1;
        let one = std::mem::take(v);
        *v = (0..copies as i64)
            .flat_map(|m| one.iter().map(move |id| id + m * span))
            .collect();
    }
    unique(&mut frame.ids, copies);
    unique(&mut frame.res_ids, copies);

    let lowest = shifts[0];
    let grown = [0, 1, 2].map(|k| (rows[k] * n[k] as f64).to_array());
    let origin = (DVec3::from_array(cell.origin()) + lowest).to_array();
    frame.cell = Some(
        UnitCell::from_matrix(grown)
            .expect("whole multiples of a valid cell's edges form a valid cell")
            .with_origin(origin)
            .with_periodic(cell.periodic()),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_ranges_are_ovitos() {
        assert_eq!(images(1), 0..=0);
        assert_eq!(images(2), 0..=1);
        assert_eq!(images(3), -1..=1);
        assert_eq!(images(4), -1..=2);
    }
}

//! Density profiles along a cell axis: the number, mass and charge density of the atoms in
//! slabs parallel to two of the cell's faces, as MDAnalysis's `LinearDensity`, `gmx density`
//! and OVITO's one-dimensional Spatial binning give them: what an interface, a membrane or a
//! confined liquid is read from.
//!
//! The cell is cut into `bins` slabs of equal thickness along one edge vector (`a`, `b` or `c`;
//! for an orthorhombic cell, x, y or z), each atom counted in the slab its wrapped fractional
//! coordinate falls in; a slab's volume is the cell's over `bins`. Masses are the elements'
//! standard atomic weights, charges the frame's `charge` (or LAMMPS `q`) property when it has
//! one. Densities are per frame; a trajectory's profile is their mean (bins follow the cell
//! when it changes, as `gmx density` does).
//!
//! ```
//! use texmap_md_io::profile::density_profile;
//! use texmap_md_io::{Frame, UnitCell};
//! let mut frame = Frame::new();
//! frame.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 20.0).unwrap());
//! // Two atoms in the lower half, one in the upper.
//! frame.positions = vec![[1.0, 1.0, 2.0], [5.0, 5.0, 8.0], [5.0, 5.0, 15.0]];
//! let p = density_profile(&frame, 2, 2, &[0, 0, 0], 1).unwrap();
//! assert_eq!(p.position, vec![5.0, 15.0]);
//! assert!((p.number[0] - 2.0 / 1000.0).abs() < 1e-12 && (p.number[1] - 1e-3).abs() < 1e-12);
//! ```

use std::fmt;

use glam::{DMat3, DVec3};

use crate::frame::Frame;

/// Grams per cm³ of one atomic mass unit per Å³.
pub const AMU_PER_A3_IN_G_PER_CM3: f64 = 1.660_539_066_60;

/// The most slabs a profile has.
pub const MAX_BINS: usize = 1 << 20;

/// One frame's densities per slab.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityProfile {
    /// Each slab's centre: its distance (Å) along the normal of the two other edges from the
    /// cell's corner, plus the corner's own coordinate along that normal (for an orthorhombic
    /// cell, the Cartesian coordinate).
    pub position: Vec<f64>,
    /// Atoms per Å³.
    pub number: Vec<f64>,
    /// g/cm³, of the atoms' masses ([`crate::atom_mass`]: the file's, else the element's).
    pub mass: Vec<f64>,
    /// Elementary charges per Å³, when the frame has charges.
    pub charge: Option<Vec<f64>>,
    /// Atoms per Å³ of each kind.
    pub kinds: Vec<Vec<f64>>,
}

/// Why a frame has no profile.
#[derive(Clone, Debug, PartialEq)]
pub enum ProfileError {
    /// Slabs need a cell.
    NoCell,
    /// Not 1 to [`MAX_BINS`] slabs.
    Bins(usize),
    /// An axis other than 0, 1, 2.
    Axis(usize),
    /// The kinds given are not one per atom, or one is out of range.
    Kinds,
    /// An atom's position is not finite.
    NotFinite(usize),
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProfileError::NoCell => write!(
                f,
                "the frame has no cell, and the slabs are cut across the cell"
            ),
            ProfileError::Bins(n) => write!(f, "{n} slabs: give 1 to {MAX_BINS}"),
            ProfileError::Axis(a) => write!(f, "axis {a}: give 0, 1 or 2 (a, b, c)"),
            ProfileError::Kinds => write!(f, "not one kind per atom"),
            ProfileError::NotFinite(i) => write!(f, "atom {i} has no finite position"),
        }
    }
}

impl std::error::Error for ProfileError {}

/// The densities of `frame` in `bins` slabs along cell edge `axis` (0, 1, 2: a, b, c), with
/// `kind[i]` (below `kinds`) naming atom i's kind for the per-kind columns.
pub fn density_profile(
    frame: &Frame,
    axis: usize,
    bins: usize,
    kind: &[usize],
    kinds: usize,
) -> Result<DensityProfile, ProfileError> {
    if axis > 2 {
        return Err(ProfileError::Axis(axis));
    }
    if bins == 0 || bins > MAX_BINS {
        return Err(ProfileError::Bins(bins));
    }
    let n = frame.n_atoms();
    if kind.len() != n || kind.iter().any(|&k| k >= kinds) {
        return Err(ProfileError::Kinds);
    }
    let cell = frame.cell.as_ref().ok_or(ProfileError::NoCell)?;
    let m = cell.matrix().map(DVec3::from_array);
    let inverse = DMat3::from_cols(m[0], m[1], m[2]).inverse();
    let origin = DVec3::from_array(cell.origin());
    let periodic = cell.periodic()[axis];
    let charges = frame
        .property("charge")
        .or_else(|| frame.property("q"))
        .filter(|c| c.len() == n);
    let mut number = vec![0.0f64; bins];
    let mut mass = vec![0.0f64; bins];
    let mut charge = charges.map(|_| vec![0.0f64; bins]);
    let mut per_kind = vec![vec![0.0f64; bins]; kinds];
    for (i, p) in frame.positions.iter().enumerate() {
        let p = DVec3::new(p[0].into(), p[1].into(), p[2].into());
        if !p.is_finite() {
            return Err(ProfileError::NotFinite(i));
        }
        let s = (inverse * (p - origin))[axis];
        // Wrapped into the cell across a periodic edge; across an open one an atom outside
        // the cell counts in the nearest end slab.
        let s = if periodic { s - s.floor() } else { s.max(0.0) };
        let b = ((s * bins as f64) as usize).min(bins - 1);
        number[b] += 1.0;
        mass[b] += crate::atom_mass(frame, i);
        if let (Some(sum), Some(q)) = (&mut charge, charges) {
            let q = f64::from(q[i]);
            if q.is_finite() {
                sum[b] += q;
            }
        }
        per_kind[kind[i]][b] += 1.0;
    }
    let slab = cell.volume() / bins as f64;
    let (u, v) = [(1, 2), (2, 0), (0, 1)][axis];
    let normal = m[u].cross(m[v]).normalize();
    let height = m[axis].dot(normal);
    let start = origin.dot(normal);
    let scale = |values: Vec<f64>, factor: f64| -> Vec<f64> {
        values.into_iter().map(|x| x * factor / slab).collect()
    };
    Ok(DensityProfile {
        position: (0..bins)
            .map(|k| start + (k as f64 + 0.5) / bins as f64 * height)
            .collect(),
        number: scale(number, 1.0),
        mass: scale(mass, AMU_PER_A3_IN_G_PER_CM3),
        charge: charge.map(|c| scale(c, 1.0)),
        kinds: per_kind.into_iter().map(|k| scale(k, 1.0)).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::UnitCell;

    /// Water molecules on a 3 Å lattice filling the lower half of a box: 1,000 molecules of
    /// 18.015 u in 27,000 Å³ are 1.10795 g/cm³ (worked by hand), and the upper slab is empty.
    #[test]
    fn water_mass_density_by_hand() {
        let mut frame = Frame::new();
        frame.cell = Some(UnitCell::orthorhombic(30.0, 30.0, 60.0).unwrap());
        let element = |s: &str| crate::elements::Element::from_symbol(s).unwrap();
        for x in 0..10 {
            for y in 0..10 {
                for z in 0..10 {
                    let p = [x, y, z].map(|k| k as f64 * 3.0 + 0.1);
                    frame.positions.push(p.map(|v| v as f32));
                    frame.elements.push(element("O"));
                    for h in [[0.6, 0.0, 0.0], [0.0, 0.6, 0.0]] {
                        frame
                            .positions
                            .push(std::array::from_fn(|k| (p[k] + h[k]) as f32));
                        frame.elements.push(element("H"));
                    }
                }
            }
        }
        let kind: Vec<usize> = (0..frame.n_atoms())
            .map(|i| usize::from(i % 3 != 0))
            .collect();
        let p = density_profile(&frame, 2, 2, &kind, 2).unwrap();
        assert!((p.mass[0] - 1.10795).abs() < 1e-4, "{}", p.mass[0]);
        assert_eq!(p.mass[1], 0.0);
        assert!((p.number[0] - 3000.0 / 27000.0).abs() < 1e-12);
        assert!((p.kinds[1][0] - 2.0 * p.kinds[0][0]).abs() < 1e-12);
        assert_eq!(p.position, vec![15.0, 45.0]);
        assert!(p.charge.is_none());
    }

    /// Along a skewed cell's c, the slabs are parallel to the ab face: atoms at fractional c
    /// of 0.25 and 0.75 fall in the two halves whatever their a and b, and the positions are
    /// heights over that face.
    #[test]
    fn slabs_follow_a_triclinic_cell_and_charges() {
        let cell = UnitCell::from_lengths_angles([10.0, 12.0, 14.0], [70.0, 80.0, 100.0])
            .unwrap()
            .with_origin([1.0, 2.0, 3.0]);
        let mut frame = Frame::new();
        for (f, q) in [
            ([0.9, 0.1, 0.25], 1.0),
            ([0.2, 0.7, 1.75], -0.5),
            ([0.5, 0.5, -0.25], 0.25),
        ] {
            frame.positions.push(cell.to_cartesian(f).map(|v| v as f32));
            frame.property_mut("charge").push(q);
        }
        frame.cell = Some(cell);
        let p = density_profile(&frame, 2, 2, &[0, 0, 0], 1).unwrap();
        let slab = cell.volume() / 2.0;
        assert!((p.number[0] - 1.0 / slab).abs() < 1e-12);
        assert!((p.number[1] - 2.0 / slab).abs() < 1e-12);
        let charge = p.charge.unwrap();
        assert!((charge[0] - 1.0 / slab).abs() < 1e-12);
        assert!((charge[1] + 0.25 / slab).abs() < 1e-12);
        let height = cell.volume() / {
            let m = cell.matrix().map(DVec3::from_array);
            m[0].cross(m[1]).length()
        };
        assert!((p.position[1] - p.position[0] - height / 2.0).abs() < 1e-9);
        assert!((p.position[0] - (3.0 + height / 4.0)).abs() < 1e-9);
    }

    #[test]
    fn refuses_what_it_cannot_bin() {
        let mut frame = Frame::new();
        frame.positions = vec![[0.0; 3]];
        assert_eq!(
            density_profile(&frame, 2, 10, &[0], 1),
            Err(ProfileError::NoCell)
        );
        frame.cell = Some(UnitCell::orthorhombic(5.0, 5.0, 5.0).unwrap());
        assert_eq!(
            density_profile(&frame, 3, 10, &[0], 1),
            Err(ProfileError::Axis(3))
        );
        assert_eq!(
            density_profile(&frame, 0, 0, &[0], 1),
            Err(ProfileError::Bins(0))
        );
        assert_eq!(
            density_profile(&frame, 0, 4, &[1], 1),
            Err(ProfileError::Kinds)
        );
        frame.positions = vec![[f32::NAN, 0.0, 0.0]];
        assert_eq!(
            density_profile(&frame, 0, 4, &[0], 1),
            Err(ProfileError::NotFinite(0))
        );
    }
}

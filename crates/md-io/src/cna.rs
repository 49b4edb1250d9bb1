//! Crystal structure per atom by adaptive common neighbour analysis (a-CNA; A. Stukowski,
//! "Structure identification methods for atomistic simulations of crystalline materials",
//! Modelling Simul. Mater. Sci. Eng. 20 (2012) 045021), as OVITO's Common Neighbor Analysis
//! modifier assigns it in its default adaptive mode: FCC, HCP, BCC, icosahedral or other.
//! Materials simulations colour by it and hide the perfect crystal to show dislocations,
//! stacking faults, grain boundaries and surfaces.
//!
//! Per atom:
//! 1. The 12 nearest neighbours (FCC, HCP, icosahedral test): the local cutoff is
//!    `(1 + √2) / 2` times their mean distance, and two neighbours are bonded when they are at
//!    most that far apart. For each neighbour, its CNA signature is (common neighbours: the
//!    other neighbours bonded to it; bonds among those; bonds in the largest connected set of
//!    those bonds). Twelve (4,2,1) is FCC; six (4,2,1) and six (4,2,2) HCP; twelve (5,5,5)
//!    icosahedral.
//! 2. Otherwise the 14 nearest (BCC test): the cutoff is `(1 + √2) / 2` times
//!    `(2/√3 · Σ₁⁸ rⱼ + Σ₉¹⁴ rⱼ) / 14`; eight (6,6,6) and six (4,4,4) is BCC.
//! 3. Otherwise other (surfaces, cores of defects, liquids, too few atoms).
//!
//! Neighbours are found in a cell grid; in a periodic cell by the nearest image (rounded
//! fractional differences, exact within half the cell's width), so the box must be wider than
//! twice the 14th neighbour distance (any box of a few unit cells). Frames without a cell are
//! open. Atoms are classified in parallel (rayon); the result does not depend on the thread
//! count.
//!
//! ```
//! use texmap_md_io::cna::{StructureType, classify};
//! use texmap_md_io::{Frame, UnitCell};
//! // A 3x3x3 block of FCC unit cells (a = 3.6 Å), periodic.
//! let a = 3.6f32;
//! let mut frame = Frame::new();
//! for (i, j, k) in (0..27).map(|n| (n % 3, n / 3 % 3, n / 9)) {
//!     for b in [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]] {
//!         frame.positions.push([(i as f32 + b[0]) * a, (j as f32 + b[1]) * a, (k as f32 + b[2]) * a]);
//!     }
//! }
//! frame.cell = Some(UnitCell::orthorhombic(3.0 * a as f64, 3.0 * a as f64, 3.0 * a as f64).unwrap());
//! assert!(classify(&frame).iter().all(|t| *t == StructureType::Fcc));
//! ```

use crate::frame::Frame;
use crate::neighbours::{Grid, Scratch};

/// A crystal structure type; the numbers are OVITO's structure type codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum StructureType {
    Other = 0,
    Fcc = 1,
    Hcp = 2,
    Bcc = 3,
    Ico = 4,
}

impl StructureType {
    /// All types, in code order.
    pub const ALL: [StructureType; 5] = [
        StructureType::Other,
        StructureType::Fcc,
        StructureType::Hcp,
        StructureType::Bcc,
        StructureType::Ico,
    ];

    /// The lower-case name (`other`, `fcc`, `hcp`, `bcc`, `ico`).
    pub fn name(self) -> &'static str {
        match self {
            StructureType::Other => "other",
            StructureType::Fcc => "fcc",
            StructureType::Hcp => "hcp",
            StructureType::Bcc => "bcc",
            StructureType::Ico => "ico",
        }
    }

    /// The type named `name` (any case).
    pub fn from_name(name: &str) -> Option<StructureType> {
        StructureType::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(name))
    }
}

/// Neighbours examined per atom: the BCC test's 14.
const MAX_NEIGHBOURS: usize = 14;

/// The structure type of every atom of `frame` (see the module docs). Atoms with non-finite
/// coordinates are other, and are nobody's neighbour.
pub fn classify(frame: &Frame) -> Vec<StructureType> {
    use rayon::prelude::*;
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    // Atoms are independent: in parallel, each with its own scratch, in atom order.
    (0..frame.positions.len())
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            grid.nearest(i, MAX_NEIGHBOURS, scratch);
            signature_type(&scratch.near)
        })
        .collect()
}

/// The count of each type in `types`, indexed by the type's code.
pub fn counts(types: &[StructureType]) -> [usize; 5] {
    let mut c = [0; 5];
    for t in types {
        c[*t as usize] += 1;
    }
    c
}

/// A diamond-lattice structure type, as OVITO's Identify diamond structure modifier assigns it
/// (E. Maras et al., "Global transition path search for dislocation formation in Ge on
/// Si(001)", Comput. Phys. Commun. 205 (2016) 13); the numbers are OVITO's codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum DiamondType {
    Other = 0,
    Cubic = 1,
    /// Not itself cubic diamond, but a nearest neighbour of an atom that is.
    CubicFirstNeighbour = 2,
    /// A nearest neighbour of a [`DiamondType::CubicFirstNeighbour`] atom.
    CubicSecondNeighbour = 3,
    Hexagonal = 4,
    HexagonalFirstNeighbour = 5,
    HexagonalSecondNeighbour = 6,
}

impl DiamondType {
    /// All types, in code order.
    pub const ALL: [DiamondType; 7] = [
        DiamondType::Other,
        DiamondType::Cubic,
        DiamondType::CubicFirstNeighbour,
        DiamondType::CubicSecondNeighbour,
        DiamondType::Hexagonal,
        DiamondType::HexagonalFirstNeighbour,
        DiamondType::HexagonalSecondNeighbour,
    ];

    /// The lower-case name (`other`, `cubic`, `cubic-1st`, `cubic-2nd`, `hexagonal`,
    /// `hexagonal-1st`, `hexagonal-2nd`).
    pub fn name(self) -> &'static str {
        match self {
            DiamondType::Other => "other",
            DiamondType::Cubic => "cubic",
            DiamondType::CubicFirstNeighbour => "cubic-1st",
            DiamondType::CubicSecondNeighbour => "cubic-2nd",
            DiamondType::Hexagonal => "hexagonal",
            DiamondType::HexagonalFirstNeighbour => "hexagonal-1st",
            DiamondType::HexagonalSecondNeighbour => "hexagonal-2nd",
        }
    }
}

/// The diamond structure type of every atom of `frame` (silicon, germanium, carbon, ice): an
/// atom's 4 nearest neighbours and their own 3 others are its 12 second neighbours, which in
/// cubic diamond sit as an FCC shell and in hexagonal diamond as an HCP one; CNA on them (the
/// cutoff `(1 + √2) / 2` times their mean distance) gives twelve (4,2,1) for cubic and six
/// (4,2,1) with six (4,2,2) for hexagonal. Then, in atom order, the other atoms among a
/// diamond atom's 4 neighbours become its first neighbours, and the other atoms among theirs
/// its second neighbours (surfaces, defect cores). Neighbours at the nearest image in a
/// periodic cell; in parallel, the result not depending on the thread count.
pub fn classify_diamond(frame: &Frame) -> Vec<DiamondType> {
    use rayon::prelude::*;
    let n = frame.positions.len();
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    // Each atom's 4 nearest: vectors and indices (fewer for a frame of fewer atoms).
    let lists: Vec<([[f64; 3]; 4], [u32; 4], u8)> = (0..n)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            grid.nearest(i, 4, scratch);
            let mut v = [[0.0; 3]; 4];
            let mut idx = [0u32; 4];
            for (k, ((near, _), j)) in scratch.near.iter().zip(&scratch.index).enumerate() {
                v[k] = *near;
                idx[k] = *j;
            }
            (v, idx, scratch.near.len() as u8)
        })
        .collect();
    let mut types: Vec<DiamondType> = (0..n)
        .into_par_iter()
        .map(|i| {
            let (v, idx, count) = &lists[i];
            if *count < 4 {
                return DiamondType::Other;
            }
            let mut second = [([0.0f64; 3], 0.0f64); 12];
            let mut found = 0;
            for k in 0..4 {
                let (w, _, wn) = &lists[idx[k] as usize];
                let before = found;
                for u in &w[..*wn as usize] {
                    let s = [0, 1, 2].map(|a| v[k][a] + u[a]);
                    // The way back to the atom itself.
                    if s.iter().all(|c| c.abs() <= 1e-2) {
                        continue;
                    }
                    if found == 12 {
                        return DiamondType::Other;
                    }
                    second[found] = (s, (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt());
                    found += 1;
                }
                if found - before != 3 {
                    return DiamondType::Other;
                }
            }
            let mean = second.iter().map(|s| s.1).sum::<f64>() / 12.0;
            let sigs = signatures(&second, 0.5 * (1.0 + std::f64::consts::SQRT_2) * mean);
            let count = |s: [u8; 3]| sigs.iter().filter(|x| **x == s).count();
            match (count([4, 2, 1]), count([4, 2, 2])) {
                (12, _) => DiamondType::Cubic,
                (6, 6) => DiamondType::Hexagonal,
                _ => DiamondType::Other,
            }
        })
        .collect();
    // First, then second neighbours, in atom order (the first diamond atom to reach an atom
    // names it).
    for (from, to) in [
        (
            [DiamondType::Cubic, DiamondType::Hexagonal],
            [
                DiamondType::CubicFirstNeighbour,
                DiamondType::HexagonalFirstNeighbour,
            ],
        ),
        (
            [
                DiamondType::CubicFirstNeighbour,
                DiamondType::HexagonalFirstNeighbour,
            ],
            [
                DiamondType::CubicSecondNeighbour,
                DiamondType::HexagonalSecondNeighbour,
            ],
        ),
    ] {
        for i in 0..n {
            let Some(kind) = from.iter().position(|t| *t == types[i]) else {
                continue;
            };
            let (_, idx, count) = &lists[i];
            for &j in &idx[..*count as usize] {
                if types[j as usize] == DiamondType::Other {
                    types[j as usize] = to[kind];
                }
            }
        }
    }
    types
}

/// The type from the neighbour vectors sorted by length (at most [`MAX_NEIGHBOURS`] used).
fn signature_type(near: &[([f64; 3], f64)]) -> StructureType {
    if near.len() >= 12 {
        let mean = near[..12].iter().map(|n| n.1).sum::<f64>() / 12.0;
        let cutoff = 0.5 * (1.0 + std::f64::consts::SQRT_2) * mean;
        let sigs = signatures(&near[..12], cutoff);
        let count = |s: [u8; 3]| sigs.iter().filter(|x| **x == s).count();
        let (s421, s422, s555) = (count([4, 2, 1]), count([4, 2, 2]), count([5, 5, 5]));
        if s421 == 12 {
            return StructureType::Fcc;
        }
        if s421 == 6 && s422 == 6 {
            return StructureType::Hcp;
        }
        if s555 == 12 {
            return StructureType::Ico;
        }
    }
    if near.len() >= 14 {
        let first: f64 = near[..8].iter().map(|n| n.1).sum();
        let second: f64 = near[8..14].iter().map(|n| n.1).sum();
        let mean = (2.0 / 3f64.sqrt() * first + second) / 14.0;
        let cutoff = 0.5 * (1.0 + std::f64::consts::SQRT_2) * mean;
        let sigs = signatures(&near[..14], cutoff);
        let count = |s: [u8; 3]| sigs.iter().filter(|x| **x == s).count();
        if count([6, 6, 6]) == 8 && count([4, 4, 4]) == 6 {
            return StructureType::Bcc;
        }
    }
    StructureType::Other
}

/// Each neighbour's CNA signature among `near` (vectors from the central atom) with bonds
/// shorter than `cutoff`.
fn signatures(near: &[([f64; 3], f64)], cutoff: f64) -> Vec<[u8; 3]> {
    let n = near.len();
    let c2 = cutoff * cutoff;
    // bonded[j] has bit k when neighbours j and k are bonded.
    let mut bonded = [0u16; MAX_NEIGHBOURS];
    for j in 0..n {
        for k in j + 1..n {
            let d: f64 = (0..3).map(|a| (near[j].0[a] - near[k].0[a]).powi(2)).sum();
            if d <= c2 {
                bonded[j] |= 1 << k;
                bonded[k] |= 1 << j;
            }
        }
    }
    // Bonds among the atoms of `set`.
    let bonds_in = |set: u16| -> u32 {
        let mut twice = 0;
        let mut rest = set;
        while rest != 0 {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            twice += (bonded[k] & set).count_ones();
        }
        twice / 2
    };
    (0..n)
        .map(|j| {
            let common = bonded[j];
            // The largest set of bonds connected through shared atoms: the connected
            // components of the common neighbours' bond graph, each grown from an atom.
            let mut left = common;
            let mut largest = 0;
            while left != 0 {
                let mut component = 1u16 << left.trailing_zeros();
                loop {
                    let mut grown = component;
                    let mut rest = component;
                    while rest != 0 {
                        let k = rest.trailing_zeros() as usize;
                        rest &= rest - 1;
                        grown |= bonded[k] & common;
                    }
                    if grown == component {
                        break;
                    }
                    component = grown;
                }
                largest = largest.max(bonds_in(component));
                left &= !component;
            }
            [
                common.count_ones() as u8,
                bonds_in(common).min(255) as u8,
                largest.min(255) as u8,
            ]
        })
        .collect()
}

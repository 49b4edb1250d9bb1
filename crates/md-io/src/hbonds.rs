//! Hydrogen bonds by geometry, with the criterion and defaults of MDAnalysis's
//! `HydrogenBondAnalysis`: a donor D, one of its hydrogens H and an acceptor A form a hydrogen
//! bond when
//!
//! - the D–A distance is at most [`Criteria::distance`] (default 3.0 Å), and
//! - the D–H···A angle at the hydrogen is at least [`Criteria::angle`] (default 150°),
//!
//! every displacement taken to its nearest periodic image when the frame has a cell. VMD's
//! `measure hbonds` is the same test with an angle given as its deviation from 180° (its 20°
//! is `angle: 160.0` here).
//!
//! Who takes part:
//! - **donor–hydrogen pairs** come from bonds ([`donor_hydrogens`]): a hydrogen bonded to a
//!   nitrogen or an oxygen (the bonds a topology lists, or bonds by distance,
//!   [`crate::bonds`]);
//! - **acceptors** are the nitrogen and oxygen atoms;
//! - elements are the atoms' own or guessed from their names ([`crate::atom_element`]);
//! - a mask restricts all three to the atoms it keeps (a selection: the bonds within it).
//!
//! Candidate D–A pairs come from the cell grid of [`crate::bonds`] (linear in the atoms,
//! parallel, the same pairs for any thread count), each then tested in f64 on the f32 positions
//! (so a pair written exactly at the cutoff, as a trajectory's 0.01 Å grid makes some, is in or
//! out as its f32 rounding falls; MDAnalysis's f32 arithmetic may decide such a tie the other
//! way); pairs closer than the grid's 0.4 Å floor (overlapping atoms of a damaged frame) are
//! never bonds. As for [`crate::coordination`], a periodic cell narrower than three cutoffs along some axis would
//! need several images of one partner and is an error ([`HBondError::CellTooSmall`]).
//!
//! ```
//! use texmap_md_io::{Frame, Label};
//! use texmap_md_io::hbonds::{Criteria, donor_hydrogens, hydrogen_bonds};
//!
//! // A water dimer: the donor's O–H points straight at the acceptor's O, 2.9 Å away.
//! let mut frame = Frame::new();
//! frame.names = ["OW", "HW1", "HW2", "OW", "HW1", "HW2"].map(|n| Label::new(n).unwrap()).to_vec();
//! frame.positions = vec![
//!     [0.0, 0.0, 0.0], [0.96, 0.0, 0.0], [-0.24, 0.93, 0.0],
//!     [2.9, 0.0, 0.0], [3.15, 0.93, 0.0], [3.15, -0.47, 0.81],
//! ];
//! let bonds = [[0, 1], [0, 2], [3, 4], [3, 5]];
//! let dh = donor_hydrogens(&frame, &bonds);
//! assert_eq!(dh, [[0, 1], [0, 2], [3, 4], [3, 5]]);
//! let found = hydrogen_bonds(&frame, &dh, None, Criteria::default()).unwrap();
//! assert_eq!(found.len(), 1);
//! assert_eq!((found[0].donor, found[0].hydrogen, found[0].acceptor), (0, 1, 3));
//! assert!((found[0].distance - 2.9).abs() < 1e-6 && found[0].angle > 179.9);
//! ```

use std::fmt;

use crate::bonds::{BOND_TOLERANCE, bonds_with_radii};
use crate::elements::Element;
use crate::frame::Frame;
use crate::pbc::NearestImage;
use crate::style::atom_element;

/// MDAnalysis's default donor–acceptor cutoff (Å).
pub const DEFAULT_DISTANCE: f32 = 3.0;
/// MDAnalysis's default smallest donor–hydrogen–acceptor angle (degrees).
pub const DEFAULT_ANGLE: f32 = 150.0;
/// The largest donor–acceptor cutoff taken (Å): hydrogen bonds are shorter than 4 Å; a typo
/// such as 30 would pair most polar atoms with most others.
pub const MAX_DISTANCE: f32 = 6.0;

/// The geometric test (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Criteria {
    /// Largest donor–acceptor distance, Å, in (0.45, [`MAX_DISTANCE`]].
    pub distance: f32,
    /// Smallest donor–hydrogen–acceptor angle, degrees, in [0, 180].
    pub angle: f32,
}

impl Criteria {
    /// Whether the cutoffs are in range (see the fields).
    pub fn check(&self) -> Result<(), HBondError> {
        if !(self.distance > BOND_TOLERANCE && self.distance <= MAX_DISTANCE) {
            return Err(HBondError::BadDistance(self.distance));
        }
        if !(0.0..=180.0).contains(&self.angle) {
            return Err(HBondError::BadAngle(self.angle));
        }
        Ok(())
    }
}

impl Default for Criteria {
    fn default() -> Criteria {
        Criteria {
            distance: DEFAULT_DISTANCE,
            angle: DEFAULT_ANGLE,
        }
    }
}

/// Why hydrogen bonds cannot be found.
#[derive(Clone, Debug, PartialEq)]
pub enum HBondError {
    /// The distance cutoff is not in (0.45, [`MAX_DISTANCE`]] Å.
    BadDistance(f32),
    /// The angle is not in [0, 180] degrees.
    BadAngle(f32),
    /// The periodic cell is narrower than three cutoffs along an axis.
    CellTooSmall {
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The distance cutoff, Å.
        cutoff: f32,
    },
}

impl fmt::Display for HBondError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HBondError::BadDistance(d) => write!(
                f,
                "the hydrogen-bond distance {d} is not a donor-acceptor distance above \
                 {BOND_TOLERANCE} and at most {MAX_DISTANCE} Å"
            ),
            HBondError::BadAngle(a) => write!(
                f,
                "the hydrogen-bond angle {a} is not an angle from 0 to 180 degrees"
            ),
            HBondError::CellTooSmall { width, cutoff } => write!(
                f,
                "the periodic cell is {width:.2} Å wide, less than three hydrogen-bond cutoffs \
                 of {cutoff} Å: replicate it first (--replicate) so each partner has one \
                 nearest image"
            ),
        }
    }
}

impl std::error::Error for HBondError {}

/// One hydrogen bond: atom indices of the frame, the D–A distance (Å) and the D–H···A angle
/// (degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HBond {
    pub donor: u32,
    pub hydrogen: u32,
    pub acceptor: u32,
    pub distance: f32,
    pub angle: f32,
}

/// Whether atoms of element `e` donate (through a bonded hydrogen) and accept: N and O.
pub fn is_polar(e: Element) -> bool {
    matches!(e.symbol(), "N" | "O")
}

fn is_hydrogen(e: Element) -> bool {
    e.symbol() == "H"
}

/// The `[donor, hydrogen]` pairs among `bonds` (atom indices of `frame`): every bond of a
/// hydrogen with a nitrogen or an oxygen, sorted, each once.
pub fn donor_hydrogens(frame: &Frame, bonds: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let n = frame.n_atoms();
    let mut out: Vec<[u32; 2]> = bonds
        .iter()
        .filter(|[i, j]| (*i as usize) < n && (*j as usize) < n && i != j)
        .filter_map(|&[i, j]| {
            let (ei, ej) = (
                atom_element(frame, i as usize),
                atom_element(frame, j as usize),
            );
            if is_polar(ei) && is_hydrogen(ej) {
                Some([i, j])
            } else if is_polar(ej) && is_hydrogen(ei) {
                Some([j, i])
            } else {
                None
            }
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The displacement `to − from` (Å), to its nearest image in the cell.
#[inline]
fn displacement(image: Option<&NearestImage>, from: [f32; 3], to: [f32; 3]) -> [f64; 3] {
    let d = std::array::from_fn(|k| to[k] as f64 - from[k] as f64);
    match image {
        Some(image) => image.apply(d),
        None => d,
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The hydrogen bonds of `frame` (see the module docs) made by the `[donor, hydrogen]` pairs
/// `dh` ([`donor_hydrogens`], or any list of such pairs, in any order) with the frame's N and
/// O acceptors; with a `mask`, only
/// donors, hydrogens and acceptors it keeps take part. Sorted by donor, hydrogen, acceptor.
pub fn hydrogen_bonds(
    frame: &Frame,
    dh: &[[u32; 2]],
    mask: Option<&[bool]>,
    criteria: Criteria,
) -> Result<Vec<HBond>, HBondError> {
    criteria.check()?;
    let Criteria { distance, angle } = criteria;
    let n = frame.n_atoms();
    let keep = |i: usize| i < n && mask.is_none_or(|m| m.get(i).copied().unwrap_or(false));
    // Hydrogens per donor: the pairs kept, sorted, looked up by donor.
    let mut dh: Vec<[u32; 2]> = dh
        .iter()
        .copied()
        .filter(|[d, h]| keep(*d as usize) && keep(*h as usize))
        .collect();
    // Sorted by donor for the look-up below, whatever order the caller's pairs are in.
    dh.sort_unstable();
    dh.dedup();
    // The candidates: every donor and acceptor, once, in atom order.
    let mut role = vec![0u8; n];
    const DONOR: u8 = 1;
    const ACCEPTOR: u8 = 2;
    for [d, _] in &dh {
        role[*d as usize] |= DONOR;
    }
    for (i, r) in role.iter_mut().enumerate() {
        if keep(i) && is_polar(atom_element(frame, i)) {
            *r |= ACCEPTOR;
        }
    }
    let atoms: Vec<u32> = (0..n as u32).filter(|&i| role[i as usize] != 0).collect();
    let positions: Vec<[f32; 3]> = atoms.iter().map(|&i| frame.positions[i as usize]).collect();
    // Every pair closer than the cutoff (and a margin for the f32 test) is a candidate: the
    // grid's pair cutoff is r + r + tolerance.
    let reach = (distance + 0.01 - BOND_TOLERANCE) / 2.0;
    let pairs = bonds_with_radii(&positions, &vec![reach; atoms.len()], frame.cell);
    if let Some(cell) = frame.cell
        && !pairs.periodic
        && atoms.len() >= 2
    {
        let width = cell.min_periodic_width();
        return Err(HBondError::CellTooSmall {
            width,
            cutoff: distance,
        });
    }
    let image = frame.cell.as_ref().and_then(NearestImage::new);
    let cell = image.as_ref();
    let pos = |i: u32| frame.positions[i as usize];
    let hydrogens = |d: u32| {
        let from = dh.partition_point(|p| p[0] < d);
        let to = dh.partition_point(|p| p[0] <= d);
        dh[from..to].iter().map(|p| p[1])
    };
    let (dmax, cos_max) = (distance as f64, (angle as f64).to_radians().cos());
    let mut found = Vec::new();
    let mut test = |d: u32, a: u32| {
        let da = displacement(cell, pos(d), pos(a));
        let r = dot(da, da).sqrt();
        if r > dmax || r.is_nan() {
            return;
        }
        for h in hydrogens(d) {
            if h == a {
                continue;
            }
            let hd = displacement(cell, pos(h), pos(d));
            let ha = displacement(cell, pos(h), pos(a));
            let c = dot(hd, ha) / (dot(hd, hd) * dot(ha, ha)).sqrt();
            if c <= cos_max {
                found.push(HBond {
                    donor: d,
                    hydrogen: h,
                    acceptor: a,
                    distance: r as f32,
                    angle: c.clamp(-1.0, 1.0).acos().to_degrees() as f32,
                });
            }
        }
    };
    for [i, j] in pairs.pairs {
        let (a, b) = (atoms[i as usize], atoms[j as usize]);
        let (ra, rb) = (role[a as usize], role[b as usize]);
        if ra & DONOR != 0 && rb & ACCEPTOR != 0 {
            test(a, b);
        }
        if rb & DONOR != 0 && ra & ACCEPTOR != 0 {
            test(b, a);
        }
    }
    found.sort_unstable_by_key(|b| (b.donor, b.hydrogen, b.acceptor));
    Ok(found)
}

/// How long hydrogen bonds last: the autocorrelation C(τ) of their existence, as MDAnalysis's
/// `HydrogenBondAnalysis.lifetime` computes it (`lib.correlations`). `frames` lists each
/// frame's bonds as (hydrogen, acceptor) pairs (the donor follows from the hydrogen; the pair
/// is taken unordered, as MDAnalysis's `frozenset`); the curve is
/// [`crate::survival::survival_probability`]'s over those pairs: C(τ) is the mean, over every
/// time origin t whose frame has a bond and with t + τ a frame, of the share of t's bonds
/// present at every frame from t to t + τ; C(0) = 1. With `intermittency` k, a bond absent for
/// up to k consecutive frames between two frames that have it counts as present in them.
///
/// ```
/// use texmap_md_io::hbonds::lifetime;
/// // One bond present in frames 0–2, gone in 3, back in 4; another only in frame 0.
/// let frames = vec![vec![[1, 9], [2, 8]], vec![[1, 9]], vec![[9, 1]], vec![], vec![[1, 9]]];
/// let c = lifetime(&frames, 2, 0);
/// // Lag 1: origin 0 keeps 1 of 2, origin 1 keeps 1 of 1, origin 2 keeps 0 of 1, origin 4
/// // has no frame 5: (1/2 + 1 + 0) / 3.
/// assert_eq!(c[1], 0.5);
/// // With the one-frame gap forgiven, lag 2 from origins 0, 1, 2: (1/2 + 1 + 1) / 3.
/// assert!((lifetime(&frames, 2, 1)[2] - 2.5 / 3.0).abs() < 1e-12);
/// ```
pub fn lifetime(frames: &[Vec<[u32; 2]>], tau_max: usize, intermittency: usize) -> Vec<f64> {
    let keys: Vec<Vec<u64>> = frames
        .iter()
        .map(|bonds| bonds.iter().map(|&[h, a]| bond_key(h, a)).collect())
        .collect();
    crate::survival::survival_probability(&keys, tau_max, intermittency)
}

/// A hydrogen bond's key for [`crate::survival::survival_probability`]: its hydrogen and
/// acceptor, unordered, packed into a u64.
pub fn bond_key(hydrogen: u32, acceptor: u32) -> u64 {
    (u64::from(hydrogen.min(acceptor)) << 32) | u64::from(hydrogen.max(acceptor))
}

//! Salt bridges by VMD's Salt Bridges plugin (saltbr) criterion: an acidic residue and a basic
//! one form a salt bridge in a frame when any oxygen of the acidic side chain and any nitrogen
//! of the basic side chain are within the O–N cutoff ([`DEFAULT_CUTOFF`], VMD's 3.2 Å). For
//! each bridge found, as VMD's per-bridge files, the distance between the two side chains'
//! centres (the centroid of the acid's oxygens and that of the base's nitrogens: their centres
//! of mass, the atoms of a group being of one element) is given, with the shortest O–N
//! distance that made it.
//!
//! Who takes part ([`charged_groups`]), by residue name (a residue is consecutive atoms of one
//! residue number, name, chain and segment, [`crate::secondary::residue_ranges`]):
//! - **acids**: ASP (OD1, OD2), GLU (OE1, OE2), and their AMBER terminal spellings (NASP, CASP,
//!   NGLU, CGLU); the neutral ASH, ASPH, GLH, GLUH are not;
//! - **bases**: ARG (NH1, NH2, NE), LYS and GROMACS's LYSH (NZ), and their terminal spellings;
//!   the neutral ARGN and LYN are not;
//! - **histidines** (ND1, NE2) only when asked: every spelling (HIS, HSD, HSE, HSP, HID, HIE,
//!   HIP, HISA, HISB, HISD, HISE, HISH, HIS1, HIS2 and the AMBER terminal ones). VMD's `basic`
//!   macro takes HIS and HSP but not HSD or HSE; here the protonation a name states is not
//!   trusted, since many files name every histidine HIS.
//! - the termini's carboxylate and amine are not (VMD does not count them either);
//! - a mask restricts the groups to the atoms it keeps.
//!
//! Every displacement is taken to its nearest periodic image when the frame has a cell, and a
//! group's centroid is that of its atoms made whole around its first atom. Candidate O–N pairs
//! come from the cell grid of [`crate::bonds`] (linear in the atoms), each then tested in f64
//! on the f32 positions; a periodic cell narrower than three cutoffs along some axis is an
//! error ([`SaltBridgeError::CellTooSmall`]).
//!
//! ```
//! use texmap_md_io::{Frame, Label};
//! use texmap_md_io::saltbridges::{charged_groups, salt_bridges, DEFAULT_CUTOFF};
//!
//! // An aspartate's carboxylate 2.9 Å from a lysine's amine.
//! let mut frame = Frame::new();
//! let l = |s: &str| Label::new(s).unwrap();
//! frame.names = ["CG", "OD1", "OD2", "CE", "NZ"].map(l).to_vec();
//! frame.res_names = ["ASP", "ASP", "ASP", "LYS", "LYS"].map(l).to_vec();
//! frame.res_ids = vec![1, 1, 1, 2, 2];
//! frame.positions = vec![
//!     [0.0, 0.0, 0.0], [1.0, 0.8, 0.0], [1.0, -0.8, 0.0],
//!     [5.4, 0.0, 0.0], [3.9, 0.8, 0.0],
//! ];
//! let groups = charged_groups(&frame, None, false);
//! assert_eq!((groups.acids.len(), groups.bases.len()), (1, 1));
//! let found = salt_bridges(&frame, &groups, DEFAULT_CUTOFF).unwrap();
//! assert_eq!(found.len(), 1);
//! assert!((found[0].min_distance - 2.9).abs() < 1e-6);
//! // The oxygens' centroid (1, 0, 0) to the nitrogen (3.9, 0.8, 0).
//! assert!((found[0].distance - 2.9f32.hypot(0.8)).abs() < 1e-6);
//! ```

use std::collections::BTreeMap;
use std::fmt;

use crate::bonds::{BOND_TOLERANCE, bonds_with_radii};
use crate::frame::Frame;
use crate::pbc::NearestImage;

/// VMD's default oxygen–nitrogen cutoff (Å).
pub const DEFAULT_CUTOFF: f32 = 3.2;
/// The largest O–N cutoff taken (Å): salt bridges are shorter than 4–5 Å; a typo such as 32
/// would pair most charged residues with most others.
pub const MAX_CUTOFF: f32 = 8.0;

/// Acidic residue names and their side-chain oxygens.
const ACIDS: &[(&str, &[&str])] = &[
    ("ASP", &["OD1", "OD2"]),
    ("NASP", &["OD1", "OD2"]),
    ("CASP", &["OD1", "OD2"]),
    ("GLU", &["OE1", "OE2"]),
    ("NGLU", &["OE1", "OE2"]),
    ("CGLU", &["OE1", "OE2"]),
];

/// Basic residue names (histidine aside) and their side-chain nitrogens.
const BASES: &[(&str, &[&str])] = &[
    ("ARG", &["NH1", "NH2", "NE"]),
    ("NARG", &["NH1", "NH2", "NE"]),
    ("CARG", &["NH1", "NH2", "NE"]),
    ("LYS", &["NZ"]),
    ("LYSH", &["NZ"]),
    ("NLYS", &["NZ"]),
    ("CLYS", &["NZ"]),
];

/// Histidine's spellings (CHARMM, AMBER, GROMACS), all with ND1 and NE2.
const HISTIDINES: &[&str] = &[
    "HIS", "HIS1", "HIS2", "HISA", "HISB", "HISD", "HISE", "HISH", "HSD", "HSE", "HSP", "HID",
    "HIE", "HIP", "NHID", "NHIE", "NHIP", "CHID", "CHIE", "CHIP",
];
const HISTIDINE_NITROGENS: &[&str] = &["ND1", "NE2"];

/// Why salt bridges cannot be found.
#[derive(Clone, Debug, PartialEq)]
pub enum SaltBridgeError {
    /// The cutoff is not in (0.45, [`MAX_CUTOFF`]] Å.
    BadCutoff(f32),
    /// The periodic cell is narrower than three cutoffs along an axis.
    CellTooSmall {
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The O–N cutoff, Å.
        cutoff: f32,
    },
}

impl fmt::Display for SaltBridgeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SaltBridgeError::BadCutoff(c) => write!(
                f,
                "the salt-bridge cutoff {c} is not an oxygen-nitrogen distance above \
                 {BOND_TOLERANCE} and at most {MAX_CUTOFF} Å"
            ),
            SaltBridgeError::CellTooSmall { width, cutoff } => write!(
                f,
                "the periodic cell is {width:.2} Å wide, less than three salt-bridge cutoffs \
                 of {cutoff} Å: replicate it first (--replicate) so each partner has one \
                 nearest image"
            ),
        }
    }
}

impl std::error::Error for SaltBridgeError {}

/// A charged side chain: its residue (the index of the residue's first atom in the frame) and
/// its oxygens (acid) or nitrogens (base), atom indices in order.
#[derive(Clone, Debug, PartialEq)]
pub struct ChargedGroup {
    pub residue: usize,
    pub atoms: Vec<u32>,
}

/// The acidic and basic side chains of a frame, each in atom order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChargedGroups {
    pub acids: Vec<ChargedGroup>,
    pub bases: Vec<ChargedGroup>,
}

/// One salt bridge: indices into [`ChargedGroups::acids`] and [`ChargedGroups::bases`], the
/// distance between the two side chains' centroids (Å) and the shortest O–N distance (Å).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SaltBridge {
    pub acid: usize,
    pub base: usize,
    pub distance: f32,
    pub min_distance: f32,
}

/// The acidic and basic side chains of `frame` (see the module docs), histidines among the
/// bases when `histidine`; with a `mask`, only the atoms it keeps (a residue none of whose
/// side-chain atoms it keeps has no group).
pub fn charged_groups(frame: &Frame, mask: Option<&[bool]>, histidine: bool) -> ChargedGroups {
    let n = frame.n_atoms();
    let keep = |i: usize| i < n && mask.is_none_or(|m| m.get(i).copied().unwrap_or(false));
    let mut out = ChargedGroups::default();
    for r in crate::secondary::residue_ranges(frame) {
        let name = frame.res_names[r.start].as_str();
        let find = |table: &[(&str, &'static [&'static str])]| {
            table.iter().find(|(res, _)| *res == name).map(|(_, a)| *a)
        };
        let (atoms, acid): (&[&str], bool) = if let Some(a) = find(ACIDS) {
            (a, true)
        } else if let Some(a) = find(BASES) {
            (a, false)
        } else if histidine && HISTIDINES.contains(&name) {
            (HISTIDINE_NITROGENS, false)
        } else {
            continue;
        };
        let members: Vec<u32> = r
            .clone()
            .filter(|&i| keep(i))
            .filter(|&i| {
                frame
                    .names
                    .get(i)
                    .is_some_and(|l| atoms.contains(&l.as_str()))
            })
            .map(|i| i as u32)
            .collect();
        if members.is_empty() {
            continue;
        }
        let group = ChargedGroup {
            residue: r.start,
            atoms: members,
        };
        if acid {
            out.acids.push(group);
        } else {
            out.bases.push(group);
        }
    }
    out
}

/// The displacement `to − from` (Å), to its nearest image in the cell.
#[inline]
fn displacement(image: Option<&NearestImage>, from: [f64; 3], to: [f64; 3]) -> [f64; 3] {
    let d = std::array::from_fn(|k| to[k] - from[k]);
    match image {
        Some(image) => image.apply(d),
        None => d,
    }
}

fn norm(d: [f64; 3]) -> f64 {
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// The centroid of `atoms` (not empty), each taken at its image nearest the first.
fn centroid(frame: &Frame, image: Option<&NearestImage>, atoms: &[u32]) -> [f64; 3] {
    let pos = |i: u32| frame.positions[i as usize].map(f64::from);
    let first = pos(atoms[0]);
    let mut sum = [0.0; 3];
    for &a in atoms {
        let d = displacement(image, first, pos(a));
        for k in 0..3 {
            sum[k] += d[k];
        }
    }
    let n = atoms.len() as f64;
    std::array::from_fn(|k| first[k] + sum[k] / n)
}

/// The salt bridges of `frame` among `groups` ([`charged_groups`] of this frame's atoms) at
/// the O–N `cutoff` (Å; see the module docs), sorted by acid then base.
pub fn salt_bridges(
    frame: &Frame,
    groups: &ChargedGroups,
    cutoff: f32,
) -> Result<Vec<SaltBridge>, SaltBridgeError> {
    if !(cutoff > BOND_TOLERANCE && cutoff <= MAX_CUTOFF) {
        return Err(SaltBridgeError::BadCutoff(cutoff));
    }
    let n = frame.n_atoms();
    // Every oxygen and nitrogen once, with its group: acids as (true, k), bases as (false, k).
    let mut owner: Vec<(bool, usize)> = Vec::new();
    let mut atoms: Vec<u32> = Vec::new();
    for (acid, list) in [(true, &groups.acids), (false, &groups.bases)] {
        for (k, g) in list.iter().enumerate() {
            for &a in &g.atoms {
                if (a as usize) < n {
                    owner.push((acid, k));
                    atoms.push(a);
                }
            }
        }
    }
    let positions: Vec<[f32; 3]> = atoms.iter().map(|&i| frame.positions[i as usize]).collect();
    // Pairs closer than the cutoff (and a margin for the f64 test): the grid's pair cutoff is
    // r + r + tolerance.
    let reach = (cutoff + 0.01 - BOND_TOLERANCE) / 2.0;
    let pairs = bonds_with_radii(&positions, &vec![reach; atoms.len()], frame.cell);
    if let Some(cell) = frame.cell
        && !pairs.periodic
        && atoms.len() >= 2
    {
        return Err(SaltBridgeError::CellTooSmall {
            width: cell.min_periodic_width(),
            cutoff,
        });
    }
    let image = frame.cell.as_ref().and_then(NearestImage::new);
    let image = image.as_ref();
    let pos = |i: u32| frame.positions[i as usize].map(f64::from);
    let limit = f64::from(cutoff);
    // The shortest O–N distance of each (acid, base) pair within the cutoff.
    let mut near: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for [i, j] in pairs.pairs {
        let (oi, oj) = (owner[i as usize], owner[j as usize]);
        let ((acid, o), (base, nn)) = match (oi.0, oj.0) {
            (true, false) => ((oi.1, atoms[i as usize]), (oj.1, atoms[j as usize])),
            (false, true) => ((oj.1, atoms[j as usize]), (oi.1, atoms[i as usize])),
            _ => continue,
        };
        let r = norm(displacement(image, pos(o), pos(nn)));
        if r <= limit {
            let e = near.entry((acid, base)).or_insert(r);
            *e = e.min(r);
        }
    }
    Ok(near
        .into_iter()
        .map(|((acid, base), r)| {
            let a = centroid(frame, image, &groups.acids[acid].atoms);
            let b = centroid(frame, image, &groups.bases[base].atoms);
            SaltBridge {
                acid,
                base,
                distance: norm(displacement(image, a, b)) as f32,
                min_distance: r as f32,
            }
        })
        .collect())
}

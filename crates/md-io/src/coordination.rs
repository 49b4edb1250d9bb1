//! Coordination numbers: how many atoms lie within a cutoff distance of each atom, as OVITO's
//! Coordination analysis modifier counts them, so that under- and over-coordinated atoms
//! (surfaces, vacancies, amorphous regions, dangling bonds) can be coloured and selected; and
//! [`clusters`] of atoms joined by such pairs, as OVITO's Cluster analysis finds them
//! (precipitates, nuclei, droplets, fragments).
//!
//! The pairs come from the cell grid of [`crate::bonds`] ([`bonds_with_radii`] with every atom's
//! radius set so that its bond cutoff is the coordination cutoff): linear in the atoms,
//! parallel, the same counts for any thread count, under the minimum image in a periodic cell.
//! A pair counts when its distance is below the cutoff and above 0.4 Å (the bond finder's floor:
//! atoms on top of each other are damage, not neighbours).
//!
//! The minimum image is only the nearest image: a periodic cell narrower than three cutoffs
//! (perpendicular width) along some axis would need several images of one neighbour, and is an
//! error ([`CoordinationError::CellTooSmall`]) rather than a silent undercount; replicate the
//! frame first ([`crate::replicate`]).
//!
//! ```
//! use texmap_md_io::coordination::coordination;
//! use texmap_md_io::Frame;
//! let mut frame = Frame::new();
//! // A square of side 2 Å: each corner has two neighbours at 2 Å, the diagonal is 2.83 Å.
//! frame.positions = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]];
//! assert_eq!(coordination(&frame, 2.5).unwrap(), [2, 2, 2, 2]);
//! assert_eq!(coordination(&frame, 3.0).unwrap(), [3, 3, 3, 3]);
//! ```

use std::fmt;

use crate::bonds::{BOND_TOLERANCE, bonds_with_radii};
use crate::frame::Frame;

/// The largest cutoff taken, in Å (a typo such as 300 would otherwise make every atom a
/// neighbour of every other, quadratic in memory).
pub const MAX_CUTOFF: f32 = 20.0;

/// Why coordination numbers cannot be counted.
#[derive(Clone, Debug, PartialEq)]
pub enum CoordinationError {
    /// The cutoff is not a distance in (0.45, [`MAX_CUTOFF`]] Å.
    BadCutoff(f32),
    /// The periodic cell is narrower than three cutoffs along an axis.
    CellTooSmall {
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The cutoff, Å.
        cutoff: f32,
    },
}

impl fmt::Display for CoordinationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoordinationError::BadCutoff(c) => write!(
                f,
                "the cutoff {c} is not a distance between 0.45 and {MAX_CUTOFF} Å"
            ),
            CoordinationError::CellTooSmall { width, cutoff } => write!(
                f,
                "the periodic cell is {width:.2} Å wide, less than three cutoffs of {cutoff} Å: \
                 replicate it first (--replicate) so each neighbour has one nearest image"
            ),
        }
    }
}

impl std::error::Error for CoordinationError {}

/// The number of atoms within `cutoff` Å of each atom of `frame` (see the module docs).
pub fn coordination(frame: &Frame, cutoff: f32) -> Result<Vec<u32>, CoordinationError> {
    let mut counts = vec![0u32; frame.n_atoms()];
    for [i, j] in pairs_within(frame, cutoff)? {
        counts[i as usize] += 1;
        counts[j as usize] += 1;
    }
    Ok(counts)
}

/// Every pair of atoms within `cutoff` Å (and above the bond finder's floor), under the
/// minimum image.
pub(crate) fn pairs_within(frame: &Frame, cutoff: f32) -> Result<Vec<[u32; 2]>, CoordinationError> {
    if !(cutoff > BOND_TOLERANCE && cutoff <= MAX_CUTOFF) {
        return Err(CoordinationError::BadCutoff(cutoff));
    }
    let n = frame.n_atoms();
    // Every pair's bond cutoff is r + r + tolerance = `cutoff`.
    let radius = (cutoff - BOND_TOLERANCE) / 2.0;
    let bonds = bonds_with_radii(&frame.positions, &vec![radius; n], frame.cell);
    if let Some(cell) = frame.cell
        && !bonds.periodic
        && n >= 2
    {
        let width = cell.min_periodic_width();
        return Err(CoordinationError::CellTooSmall { width, cutoff });
    }
    Ok(bonds.pairs)
}

/// Clusters of atoms joined by neighbour pairs within a cutoff, as OVITO 3.17's Cluster analysis
/// modifier (cutoff mode, sorted by size) numbers them: every atom's cluster id, 0 the largest
/// cluster, 1 the next (equal sizes: the one holding the lower atom index first); atoms outside
/// `only` (when given) are in no cluster, id −1, and join none (OVITO before 3.17 counted from
/// 1, with 0 for none). An atom without neighbours is a cluster of its own. Pairs as
/// [`coordination`] finds them (the same cutoff range and the same refusal of a periodic cell
/// narrower than three cutoffs).
///
/// ```
/// use texmap_md_io::coordination::clusters;
/// use texmap_md_io::Frame;
/// let mut frame = Frame::new();
/// // A chain of three atoms 2 Å apart, and a pair far away.
/// frame.positions = vec![[0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [2.0, 0.0, 0.0], [4.0, 0.0, 0.0],
///                        [21.5, 0.0, 0.0]];
/// let c = clusters(&frame, 2.5, None).unwrap();
/// assert_eq!(c.ids, [0, 1, 0, 0, 1]);
/// assert_eq!(c.sizes, [3, 2]);
/// // Only the atoms a selection picks: the others are in no cluster. Without the middle atom
/// // the chain falls apart into two single atoms, smaller than the pair (equal sizes: the lower
/// // atom index first).
/// let c = clusters(&frame, 2.5, Some(&[true, true, false, true, true])).unwrap();
/// assert_eq!(c.ids, [1, 0, -1, 2, 0]);
/// ```
pub fn clusters(
    frame: &Frame,
    cutoff: f32,
    only: Option<&[bool]>,
) -> Result<Clusters, CoordinationError> {
    let pairs = pairs_within(frame, cutoff)?;
    let n = frame.n_atoms();
    let member = |i: usize| only.is_none_or(|m| m.get(i).copied().unwrap_or(false));
    // The root of a set is its lowest atom index.
    let mut parts = crate::components::UnionFind::new(n);
    for &[i, j] in &pairs {
        if member(i as usize) && member(j as usize) {
            parts.join(i as usize, j as usize);
        }
    }
    let mut size = vec![0usize; n];
    let mut roots = Vec::new();
    for i in 0..n {
        if member(i) {
            let r = parts.root(i);
            if size[r] == 0 {
                roots.push(r);
            }
            size[r] += 1;
        }
    }
    // Largest first; equal sizes by their lowest atom (the root), as found in index order.
    roots.sort_by(|&a, &b| size[b].cmp(&size[a]).then(a.cmp(&b)));
    let mut id_of_root = vec![0i32; n];
    for (k, &r) in roots.iter().enumerate() {
        id_of_root[r] = k as i32;
    }
    let ids: Vec<i32> = (0..n)
        .map(|i| {
            if member(i) {
                id_of_root[parts.root(i)]
            } else {
                -1
            }
        })
        .collect();
    let sizes = roots.iter().map(|&r| size[r]).collect();
    let (centers, gyration) = shapes(frame, &pairs, &ids, &roots);
    Ok(Clusters {
        ids,
        sizes,
        centers,
        gyration,
    })
}

/// Each cluster's centre and radius of gyration, its atoms unwrapped along its pairs from its
/// lowest atom (`roots[k]` is cluster `k`'s), so that a cluster cut by the cell's faces is
/// whole.
fn shapes(
    frame: &Frame,
    pairs: &[[u32; 2]],
    ids: &[i32],
    roots: &[usize],
) -> (Vec<[f64; 3]>, Vec<f64>) {
    let n = ids.len();
    // Pairs within a cluster, as adjacency lists.
    let mut starts = vec![0usize; n + 1];
    let inside = |[i, j]: [u32; 2]| ids[i as usize] >= 0 && ids[i as usize] == ids[j as usize];
    for &[i, j] in pairs.iter().filter(|p| inside(**p)) {
        starts[i as usize + 1] += 1;
        starts[j as usize + 1] += 1;
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    let mut fill = starts.clone();
    let mut next = vec![0u32; starts[n]];
    for &[i, j] in pairs.iter().filter(|p| inside(**p)) {
        next[fill[i as usize]] = j;
        fill[i as usize] += 1;
        next[fill[j as usize]] = i;
        fill[j as usize] += 1;
    }
    let at = |i: usize| frame.positions[i].map(f64::from);
    let mut unwrapped = vec![[0f64; 3]; n];
    let mut seen = vec![false; n];
    let mut queue = std::collections::VecDeque::new();
    let mut centers = Vec::with_capacity(roots.len());
    let mut gyration = Vec::with_capacity(roots.len());
    let mut members = Vec::new();
    let image = frame.cell.as_ref().and_then(crate::pbc::NearestImage::new);
    for &r in roots {
        members.clear();
        unwrapped[r] = at(r);
        seen[r] = true;
        queue.push_back(r);
        while let Some(i) = queue.pop_front() {
            members.push(i);
            for &j in &next[starts[i]..starts[i + 1]] {
                let j = j as usize;
                if !seen[j] {
                    seen[j] = true;
                    let step: [f64; 3] = std::array::from_fn(|k| at(j)[k] - at(i)[k]);
                    let step = image.as_ref().map_or(step, |m| m.apply(step));
                    unwrapped[j] = std::array::from_fn(|k| unwrapped[i][k] + step[k]);
                    queue.push_back(j);
                }
            }
        }
        let m = members.len() as f64;
        let c: [f64; 3] =
            std::array::from_fn(|k| members.iter().map(|&i| unwrapped[i][k]).sum::<f64>() / m);
        let r2 = members
            .iter()
            .map(|&i| {
                (0..3)
                    .map(|k| (unwrapped[i][k] - c[k]).powi(2))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / m;
        centers.push(c);
        gyration.push(r2.sqrt());
    }
    (centers, gyration)
}

/// What [`clusters`] finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Clusters {
    /// Per atom: its cluster (0 the largest), −1 when outside the atoms clustered.
    pub ids: Vec<i32>,
    /// Atoms per cluster, largest first (`sizes[k]` is cluster `k`).
    pub sizes: Vec<usize>,
    /// Each cluster's centre (Å): the mean position of its atoms, unwrapped along the cluster's
    /// pairs from its lowest-index atom, so a cluster cut by the cell's faces is taken whole
    /// (the centre may lie outside the cell). A cluster that spans the periodic system (it
    /// percolates) has no single unwrapping: its centre is that of the tree of pairs found.
    pub centers: Vec<[f64; 3]>,
    /// Each cluster's radius of gyration (Å): the root mean square distance of its unwrapped
    /// atoms from the centre (unweighted, as OVITO's with unit masses).
    pub gyration: Vec<f64>,
}

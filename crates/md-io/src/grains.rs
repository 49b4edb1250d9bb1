//! Grains of a polycrystal from the atoms' lattice orientations ([`crate::orientation`]), as
//! OVITO's Grain segmentation modifier finds them: each crystalline atom in one grain, grains
//! numbered from the largest, and the atoms between them (grain boundaries, dislocation cores)
//! given to the grain nearest them.
//!
//! 1. Grains grow from seeds taken in order of increasing RMSD (the most perfect crystal
//!    first): a neighbour (one of the 12 or 14 nearest, as the structure's template) joins the
//!    grain when it has the grain's lattice symmetry and its disorientation from the grain's
//!    mean orientation is below the threshold. The mean is the normalised sum of the members'
//!    orientations, each taken as its symmetric equivalent nearest the mean, so a grain does
//!    not creep across a low-angle boundary one small step at a time.
//! 2. Grains of fewer crystalline atoms than the minimum size are dissolved.
//! 3. Orphans (atoms in no grain) are adopted, when asked: each takes the grain nearest to it
//!    along links from atoms to their nearest neighbours (the shortest summed length, found
//!    from every grain at once); atoms no link reaches stay at −1.
//! 4. Grains are numbered by their crystalline atoms, most first (OVITO numbers from 0 too);
//!    ties go to the grain whose seed came first.
//!
//! Stacking faults and twin boundaries (HCP layers in FCC, or FCC layers in HCP) are joined to
//! the grain they lie in, as OVITO does by default: the commoner of the two phases is the
//! parent, its seeds come first, and its grains take in an atom of the other phase when the
//! parent lattice that continues the atom's ([111] along c, [1-10] along a₁) is within the
//! threshold of the grain's mean. A twin's two sides stay two grains (60° apart); its boundary
//! layer joins whichever side reaches it first. Without it
//! ([`GrainOptions::join_stacking_faults`] false) fault layers make grains of their own.
//!
//! ```
//! use texmap_md_io::cna::classify;
//! use texmap_md_io::grains::{GrainOptions, segment};
//! use texmap_md_io::orientation::orientations;
//! use texmap_md_io::{Frame, UnitCell};
//! // Two FCC slabs (a = 4.05 Å) in a periodic box, the upper one turned 30° about z.
//! let (a, side) = (4.05f64, 32.4f64);
//! let mut frame = Frame::new();
//! for (turn, zs) in [(0f64, 0.0..side / 2.0), (30f64.to_radians(), side / 2.0..side)] {
//!     let (c, s) = (turn.cos(), turn.sin());
//!     for m in 0..24 * 24 * 8 {
//!         let (i, j, k) = ((m % 24) as f64 - 12.0, (m / 24 % 24) as f64 - 6.0, (m / 576) as f64);
//!         for b in [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]] {
//!             let (x, y, z) = ((i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a);
//!             let p = [x * c - y * s, x * s + y * c, z];
//!             if (0.0..side).contains(&p[0]) && (0.0..side).contains(&p[1]) && zs.contains(&p[2]) {
//!                 frame.positions.push(p.map(|v| v as f32));
//!             }
//!         }
//!     }
//! }
//! frame.cell = Some(UnitCell::orthorhombic(side, side, side).unwrap());
//! let types = classify(&frame);
//! let fits = orientations(&frame, &types);
//! let grains = segment(&frame, &types, &fits, &GrainOptions::default());
//! assert_eq!(grains.grains.len(), 2);
//! assert!(grains.grain.iter().all(|g| *g >= 0)); // the boundary atoms adopted
//! ```

use glam::{DMat3, DQuat, DVec3};

use crate::cna::StructureType;
use crate::frame::Frame;
use crate::neighbours::{Grid, Scratch};
use crate::orientation::{LatticeFit, Symmetry, fundamental_zone};

/// How grains are found.
#[derive(Clone, Debug, PartialEq)]
pub struct GrainOptions {
    /// The largest disorientation (degrees, 0 to 180) of an atom from its grain's mean
    /// orientation.
    pub threshold_deg: f64,
    /// Grains of fewer crystalline atoms are dissolved (OVITO's default: 100).
    pub min_size: usize,
    /// Give atoms in no grain to the grain of their nearest neighbour that has one (OVITO's
    /// default).
    pub adopt_orphans: bool,
    /// Let the grains of the commoner of FCC and HCP take in the other's atoms where their
    /// lattices continue one another: the HCP layers of stacking faults and twin boundaries
    /// in an FCC crystal (or FCC layers in HCP) join the grain they lie in instead of making
    /// their own (OVITO's default: "handle stacking faults").
    pub join_stacking_faults: bool,
}

impl Default for GrainOptions {
    fn default() -> GrainOptions {
        GrainOptions {
            threshold_deg: 4.0,
            min_size: 100,
            adopt_orphans: true,
            join_stacking_faults: true,
        }
    }
}

/// One grain.
#[derive(Clone, Debug, PartialEq)]
pub struct Grain {
    /// Its atoms, orphans adopted included.
    pub size: usize,
    /// Its crystalline atoms.
    pub crystalline: usize,
    /// The structure of its crystalline atoms.
    pub structure: StructureType,
    /// Its mean lattice orientation, `[x, y, z, w]`, in the fundamental zone.
    pub orientation: [f64; 4],
}

/// The grains of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Grains {
    /// Each atom's grain (an index into `grains`), or −1.
    pub grain: Vec<i32>,
    /// The grains, the one of most crystalline atoms first.
    pub grains: Vec<Grain>,
}

/// The grains of `frame` (see the module docs) from its atoms' structure `types`
/// ([`crate::cna::classify`]) and lattice fits ([`crate::orientation::orientations`]). The
/// result does not depend on the thread count.
///
/// # Panics
/// If `types` or `fits` and the frame's atoms differ in number.
pub fn segment(
    frame: &Frame,
    types: &[StructureType],
    fits: &[Option<LatticeFit>],
    options: &GrainOptions,
) -> Grains {
    use rayon::prelude::*;
    let n = frame.positions.len();
    assert_eq!(types.len(), n, "one structure type per atom");
    assert_eq!(fits.len(), n, "one lattice fit per atom");
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    // Each atom's neighbours (as many as its template has, 12 for other atoms), nearest first,
    // with their distances.
    let lists: Vec<Neighbours> = (0..n)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            let k = if types[i] == StructureType::Bcc && fits[i].is_some() {
                14
            } else {
                12
            };
            grid.nearest(i, k, scratch);
            let mut out = Neighbours {
                index: [0; STRIDE],
                distance: [0.0; STRIDE],
                count: scratch.index.len() as u8,
            };
            out.index[..scratch.index.len()].copy_from_slice(&scratch.index);
            for (d, near) in out.distance.iter_mut().zip(&scratch.near) {
                *d = near.1 as f32;
            }
            out
        })
        .collect();
    let neighbours = |i: usize| &lists[i].index[..lists[i].count as usize];

    // The parent phase of stacking faults: the commoner of FCC and HCP.
    let count = |t: StructureType| {
        (0..n)
            .filter(|&i| fits[i].is_some() && types[i] == t)
            .count()
    };
    let (parent, minority) = if count(StructureType::Fcc) >= count(StructureType::Hcp) {
        (StructureType::Fcc, StructureType::Hcp)
    } else {
        (StructureType::Hcp, StructureType::Fcc)
    };
    let joins = |grain: StructureType, atom: StructureType| {
        options.join_stacking_faults && grain == parent && atom == minority
    };

    // 1. Growth from the most perfect atoms, the parent phase's first (so that its grains
    // reach the faults before the faults seed grains of their own).
    let mut seeds: Vec<usize> = (0..n).filter(|&i| fits[i].is_some()).collect();
    seeds.sort_by(|&a, &b| {
        let (ra, rb) = (fits[a].unwrap().rmsd, fits[b].unwrap().rmsd);
        let minor = |i: usize| options.join_stacking_faults && types[i] == minority;
        minor(a)
            .cmp(&minor(b))
            .then(ra.total_cmp(&rb))
            .then(a.cmp(&b))
    });
    // A threshold that is no angle (NaN) joins nothing.
    let threshold = match options.threshold_deg {
        t if t.is_nan() => 0.0,
        t => t.clamp(0.0, 180.0),
    };
    let cos_half = (threshold.to_radians() / 2.0).cos();
    let mut grain = vec![-1i32; n];
    let mut means: Vec<DQuat> = Vec::new();
    let mut symmetries: Vec<Symmetry> = Vec::new();
    let mut structures: Vec<StructureType> = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    for &seed in &seeds {
        if grain[seed] >= 0 {
            continue;
        }
        let fit = fits[seed].unwrap();
        let g = means.len() as i32;
        grain[seed] = g;
        let mut sum = quat(fit.orientation);
        let mut mean = sum;
        queue.push_back(seed);
        while let Some(a) = queue.pop_front() {
            for &b in neighbours(a) {
                let b = b as usize;
                if grain[b] >= 0 {
                    continue;
                }
                let Some(fb) = fits[b] else { continue };
                // The equivalent of b's orientation nearest the mean: across a fault, b's
                // orientation as the parent lattice's.
                let (eq, w) = if joins(types[seed], types[b]) {
                    across_fault(mean, quat(fb.orientation), fb.symmetry, fit.symmetry)
                } else if fb.symmetry == fit.symmetry {
                    nearest_equivalent(mean, quat(fb.orientation), fit.symmetry)
                } else {
                    continue;
                };
                if w < cos_half {
                    continue;
                }
                grain[b] = g;
                sum += eq;
                mean = sum.normalize();
                queue.push_back(b);
            }
        }
        means.push(mean);
        symmetries.push(fit.symmetry);
        structures.push(types[seed]);
    }

    // 2. Small grains dissolved; 4. the rest numbered by size.
    let mut crystalline = vec![0usize; means.len()];
    for &g in &grain {
        if g >= 0 {
            crystalline[g as usize] += 1;
        }
    }
    let mut kept: Vec<usize> = (0..means.len())
        .filter(|&g| crystalline[g] >= options.min_size.max(1))
        .collect();
    kept.sort_by(|&a, &b| crystalline[b].cmp(&crystalline[a]).then(a.cmp(&b)));
    let mut number = vec![-1i32; means.len()];
    for (k, &g) in kept.iter().enumerate() {
        number[g] = k as i32;
    }
    for g in grain.iter_mut() {
        if *g >= 0 {
            *g = number[*g as usize];
        }
    }

    // 3. Orphans adopted by the grain nearest along neighbour links (Dijkstra from every
    // grain atom at once; equal paths go to the lower atom index popped first).
    if options.adopt_orphans {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let mut dist = vec![f32::INFINITY; n];
        let mut heap = BinaryHeap::new();
        for i in 0..n {
            if grain[i] >= 0 {
                dist[i] = 0.0;
                heap.push(Reverse((Length(0.0), i)));
            }
        }
        while let Some(Reverse((Length(d), i))) = heap.pop() {
            if d > dist[i] {
                continue;
            }
            let list = &lists[i];
            for (&j, &len) in neighbours(i).iter().zip(&list.distance) {
                let j = j as usize;
                if d + len < dist[j] {
                    dist[j] = d + len;
                    grain[j] = grain[i];
                    heap.push(Reverse((Length(d + len), j)));
                }
            }
        }
    }

    let mut sizes = vec![0usize; kept.len()];
    for &g in &grain {
        if g >= 0 {
            sizes[g as usize] += 1;
        }
    }
    let grains = kept
        .iter()
        .enumerate()
        .map(|(k, &g)| {
            let q = means[g];
            Grain {
                size: sizes[k],
                crystalline: crystalline[g],
                structure: structures[g],
                orientation: fundamental_zone([q.x, q.y, q.z, q.w], symmetries[g]),
            }
        })
        .collect();
    Grains { grain, grains }
}

/// For an atom of one close-packed phase (`q`, its `own` symmetry) next to a grain of the
/// other (`mean`, symmetry `parent`): the orientation of the parent's lattice that continues
/// the atom's (FCC's [111] along HCP's c, an FCC [1-10] along HCP's a₁), the equivalent nearest
/// the mean, and cos(angle / 2) to it.
fn across_fault(mean: DQuat, q: DQuat, own: Symmetry, parent: Symmetry) -> (DQuat, f64) {
    use std::sync::OnceLock;
    // The rotation from the hexagonal template's frame to the cubic one's.
    static HEX_TO_CUBIC: OnceLock<DQuat> = OnceLock::new();
    let t = *HEX_TO_CUBIC.get_or_init(|| {
        let frame = |c: DVec3, a: DVec3| {
            let (c, a) = (c.normalize(), a.normalize());
            DMat3::from_cols(a, c.cross(a), c)
        };
        let m = frame(DVec3::new(1.0, 1.0, 1.0), DVec3::new(1.0, -1.0, 0.0))
            * frame(DVec3::Z, DVec3::X).transpose();
        DQuat::from_mat3(&m).normalize()
    });
    let convert = if parent == Symmetry::Cubic {
        t.conjugate()
    } else {
        t
    };
    let mut best = (DQuat::IDENTITY, f64::NEG_INFINITY);
    for g in own.rotations() {
        let candidate = nearest_equivalent(mean, q * *g * convert, parent);
        if candidate.1 > best.1 {
            best = candidate;
        }
    }
    best
}

fn quat(q: [f64; 4]) -> DQuat {
    DQuat::from_xyzw(q[0], q[1], q[2], q[3])
}

/// The equivalent `q·g` of `q` nearest `mean` (sign matched to it), and cos(angle / 2)
/// between them.
fn nearest_equivalent(mean: DQuat, q: DQuat, symmetry: Symmetry) -> (DQuat, f64) {
    // The rotation between them, m = mean⁻¹·q; w(m·g) is largest for the nearest equivalent.
    let m = mean.conjugate() * q;
    let mut best = (DQuat::IDENTITY, f64::NEG_INFINITY, 1.0);
    for g in symmetry.rotations() {
        let w = m.w * g.w - m.x * g.x - m.y * g.y - m.z * g.z;
        if w.abs() > best.1 {
            best = (*g, w.abs(), w.signum());
        }
    }
    let eq = q * best.0 * best.2;
    (eq, best.1)
}

/// An atom's nearest neighbours (indices, distances) for the growth and the adoption.
struct Neighbours {
    index: [u32; STRIDE],
    distance: [f32; STRIDE],
    count: u8,
}

/// Neighbours examined per atom at most: the BCC template's 14.
const STRIDE: usize = 14;

/// A path length, ordered totally for the adoption's heap.
#[derive(Clone, Copy, PartialEq)]
struct Length(f32);

impl Eq for Length {}

impl PartialOrd for Length {
    fn partial_cmp(&self, other: &Length) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Length {
    fn cmp(&self, other: &Length) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_frames_and_bad_thresholds_give_no_grains() {
        let empty = Frame::new();
        let found = segment(&empty, &[], &[], &GrainOptions::default());
        assert!(found.grain.is_empty() && found.grains.is_empty());
        // A few atoms of a crystal, one of them not finite, and a threshold that is no angle.
        let mut frame = Frame::new();
        for i in 0..4 {
            frame.positions.push([i as f32 * 2.5, 0.0, 0.0]);
        }
        frame.positions.push([f32::NAN, 0.0, 0.0]);
        let types = crate::cna::classify(&frame);
        let fits = crate::orientation::orientations(&frame, &types);
        for threshold_deg in [f64::NAN, -5.0, 1e9] {
            let options = GrainOptions {
                threshold_deg,
                ..GrainOptions::default()
            };
            let found = segment(&frame, &types, &fits, &options);
            assert_eq!(found.grain, vec![-1; 5]);
        }
    }
}

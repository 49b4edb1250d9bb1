//! Residue–residue maps over a trajectory, as `gmx mdmat` makes them: the smallest distance
//! between any atom of one residue and any atom of another, averaged over the frames (the
//! tertiary structure at a glance: helices pack where the map is dark off its diagonal), and
//! how often that smallest distance falls below a contact cutoff (a contact map: which
//! residues touch, and for what share of the run).
//!
//! Each frame's distances are taken between the atoms as the frame holds them, to the nearest
//! periodic image when the frame has a periodic cell (in a skewed cell such as a truncated
//! octahedron too, as gmx's `pbc_dx` and MDAnalysis's `distance_array` find it), so a molecule
//! split across the box still gives its true distances. Rows of the map are shared between threads; the map is the same for any thread count.
//!
//! ```
//! use texmap_md_io::distance_map::DistanceMap;
//! // Three one-atom "residues" on a line, 3 Å apart, then the third moved to 10 Å.
//! let groups = vec![vec![0], vec![1], vec![2]];
//! let mut map = DistanceMap::new(groups, 4.5).unwrap();
//! map.add(&[[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [6.0, 0.0, 0.0]], None).unwrap();
//! map.add(&[[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [10.0, 0.0, 0.0]], None).unwrap();
//! let mean = map.mean();
//! assert!((mean[2] - 8.0).abs() < 1e-12); // residues 0 and 2: (6 + 10) / 2
//! let contacts = map.contact_fraction();
//! assert_eq!((contacts[1], contacts[5]), (1.0, 0.5)); // 0–1 always, 1–2 in one frame of two
//! ```

use rayon::prelude::*;

use crate::UnitCell;
use crate::msd::MsdError;
use crate::pbc::NearestImage;

/// The running residue–residue map of a trajectory.
#[derive(Clone, Debug)]
pub struct DistanceMap {
    groups: Vec<Vec<usize>>,
    cutoff: f64,
    /// Per pair above the diagonal (row-major over the full square, the lower half unused):
    /// the sum of the frames' smallest distances and the frames in contact.
    sum: Vec<f64>,
    contacts: Vec<u32>,
    frames: usize,
}

impl DistanceMap {
    /// A map of `groups` (each residue's atom indices, none empty) with contacts below
    /// `cutoff` Å. `None` when a group is empty or the cutoff is not positive and finite.
    pub fn new(groups: Vec<Vec<usize>>, cutoff: f64) -> Option<DistanceMap> {
        if groups.iter().any(Vec::is_empty) || !(cutoff.is_finite() && cutoff > 0.0) {
            return None;
        }
        let n = groups.len();
        Some(DistanceMap {
            groups,
            cutoff,
            sum: vec![0.0; n * n],
            contacts: vec![0; n * n],
            frames: 0,
        })
    }

    /// The bytes a map of `residues` residues keeps (12 per pair of residues).
    pub fn bytes(residues: usize) -> usize {
        residues.saturating_mul(residues).saturating_mul(12)
    }

    /// The residues.
    pub fn residues(&self) -> usize {
        self.groups.len()
    }

    /// The frames added.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds a frame: every atom's position, the cell when the frame has one.
    pub fn add(&mut self, positions: &[[f32; 3]], cell: Option<&UnitCell>) -> Result<(), MsdError> {
        let needed = self.groups.iter().flatten().max().map_or(0, |&i| i + 1);
        if positions.len() < needed {
            return Err(MsdError::AtomCount {
                first: needed,
                frame: positions.len(),
            });
        }
        for g in &self.groups {
            for &i in g {
                if !positions[i].iter().all(|v| v.is_finite()) {
                    return Err(MsdError::NotFinite(i));
                }
            }
        }
        let image = cell.and_then(NearestImage::new);
        let n = self.groups.len();
        let whole: Vec<Whole> = self
            .groups
            .iter()
            .map(|g| Whole::new(g, positions, image.as_ref()))
            .collect();
        let cut2 = self.cutoff * self.cutoff;
        self.sum
            .par_chunks_mut(n.max(1))
            .zip(self.contacts.par_chunks_mut(n.max(1)))
            .enumerate()
            .for_each(|(a, (sum, contacts))| {
                for b in a + 1..n {
                    let d2 = smallest(&whole[a], &whole[b], image.as_ref());
                    sum[b] += d2.sqrt();
                    if d2 < cut2 {
                        contacts[b] += 1;
                    }
                }
            });
        self.frames += 1;
        Ok(())
    }

    /// The mean over the frames of each pair's smallest distance (Å), row-major `n x n`,
    /// symmetric with a zero diagonal (gmx mdmat's `-mean`); zeros before any frame.
    pub fn mean(&self) -> Vec<f64> {
        let f = self.frames.max(1) as f64;
        self.square(|k| self.sum[k] / f)
    }

    /// The fraction of the frames in which each pair's smallest distance is below the cutoff,
    /// row-major `n x n`, symmetric, 1 on the diagonal.
    pub fn contact_fraction(&self) -> Vec<f64> {
        let f = self.frames.max(1) as f64;
        let mut m = self.square(|k| f64::from(self.contacts[k]) / f);
        let n = self.groups.len();
        for i in 0..n {
            m[i * n + i] = 1.0;
        }
        m
    }

    /// The full square from the upper half's values.
    fn square(&self, value: impl Fn(usize) -> f64) -> Vec<f64> {
        let n = self.groups.len();
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in i + 1..n {
                let v = value(i * n + j);
                m[i * n + j] = v;
                m[j * n + i] = v;
            }
        }
        m
    }
}

/// A residue's atoms made whole about its first atom: each atom at the nearest image of its
/// offset from it, as coordinates in three arrays (for the vectorised inner loop), with the
/// largest offset.
struct Whole {
    origin: [f64; 3],
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    radius: f64,
}

impl Whole {
    fn new(atoms: &[usize], p: &[[f32; 3]], image: Option<&NearestImage>) -> Whole {
        let origin = p[atoms[0]].map(f64::from);
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        let mut radius = 0.0f64;
        for &i in atoms {
            let mut o: [f64; 3] = std::array::from_fn(|k| f64::from(p[i][k]) - origin[k]);
            if let Some(image) = image {
                o = image.apply(o);
            }
            radius = radius.max((o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt());
            x.push(o[0]);
            y.push(o[1]);
            z.push(o[2]);
        }
        Whole {
            origin,
            x,
            y,
            z,
            radius,
        }
    }
}

/// The smallest squared distance between an atom of `a` and one of `b`, each to the nearest
/// image of the other. With the two residues made whole, an atom pair's offset is
/// `t + (b's offset) − (a's offset)` for a periodic image `t` of the offset between their
/// origins; only images within the residues' radii of the nearest can hold the smallest,
/// and when the nearest plus both radii is below the cell's safe length it alone can.
fn smallest(a: &Whole, b: &Whole, image: Option<&NearestImage>) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|k| b.origin[k] - a.origin[k]);
    let reach = a.radius + b.radius;
    let mut best = f64::INFINITY;
    let mut pairs = |t: [f64; 3]| {
        for i in 0..a.x.len() {
            let (tx, ty, tz) = (t[0] - a.x[i], t[1] - a.y[i], t[2] - a.z[i]);
            let row =
                b.x.iter()
                    .zip(&b.y)
                    .zip(&b.z)
                    .map(|((x, y), z)| {
                        let (dx, dy, dz) = (tx + x, ty + y, tz + z);
                        dx * dx + dy * dy + dz * dz
                    })
                    .fold(f64::INFINITY, f64::min);
            best = best.min(row);
        }
    };
    let Some(image) = image else {
        pairs(d);
        return best;
    };
    let nearest = image.apply(d);
    let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let m = len(nearest);
    if (m + reach).powi(2) < image.safe2 {
        pairs(nearest);
        return best;
    }
    // Every image of the origins' offset that could hold a closer pair than the nearest's
    // farthest: within 2 x reach of the nearest.
    let shifts = |k: usize| if image.periodic[k] { -2..=2 } else { 0..=0 };
    for u in shifts(0) {
        for v in shifts(1) {
            for w in shifts(2) {
                let s = [f64::from(u), f64::from(v), f64::from(w)];
                let t: [f64; 3] = std::array::from_fn(|k| {
                    nearest[k]
                        + s[0] * image.matrix[0][k]
                        + s[1] * image.matrix[1][k]
                        + s[2] * image.matrix[2][k]
                });
                if len(t) <= m + 2.0 * reach {
                    pairs(t);
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded generator of numbers in [0, 1).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Every atom pair to its own nearest image: the definition, slowly.
    fn brute(a: &[usize], b: &[usize], p: &[[f32; 3]], image: Option<&NearestImage>) -> f64 {
        let mut best = f64::INFINITY;
        for &i in a {
            for &j in b {
                let mut d = std::array::from_fn(|k| f64::from(p[j][k]) - f64::from(p[i][k]));
                if let Some(image) = image {
                    d = image.apply(d);
                }
                best = best.min(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
        }
        best
    }

    #[test]
    fn residues_made_whole_give_every_atom_pairs_nearest_image() {
        // 60 residues of 8 atoms each, each within 4 Å of its first atom, scattered over a
        // small skewed cell (and wrapped into it, so residues straddle its faces).
        let cell =
            UnitCell::from_lengths_angles([30.0, 34.0, 28.0], [70.53, 109.47, 80.0]).unwrap();
        let image = NearestImage::new(&cell).unwrap();
        let m = cell.matrix();
        let mut next = uniform(99);
        let mut p = Vec::new();
        let mut groups = Vec::new();
        for r in 0..60 {
            let f = [next(), next(), next()];
            let c: [f64; 3] =
                std::array::from_fn(|k| f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k]);
            groups.push((8 * r..8 * r + 8).collect::<Vec<usize>>());
            for _ in 0..8 {
                let q: [f64; 3] = std::array::from_fn(|k| c[k] + 4.0 * (next() - 0.5));
                p.push(q);
            }
        }
        let mut frame = crate::Frame::new();
        frame.positions = p.iter().map(|q| q.map(|v| v as f32)).collect();
        crate::pbc::wrap_positions(&cell, &mut frame.positions);
        let whole: Vec<Whole> = groups
            .iter()
            .map(|g| Whole::new(g, &frame.positions, Some(&image)))
            .collect();
        let mut slow_paths = 0;
        for a in 0..60 {
            for b in a + 1..60 {
                let fast = smallest(&whole[a], &whole[b], Some(&image));
                let slow = brute(&groups[a], &groups[b], &frame.positions, Some(&image));
                assert!(
                    (fast - slow).abs() < 1e-6 * slow.max(1.0),
                    "({a}, {b}): {fast} vs {slow}"
                );
                let d: [f64; 3] = std::array::from_fn(|k| whole[b].origin[k] - whole[a].origin[k]);
                let n = image.apply(d);
                let reach = whole[a].radius + whole[b].radius;
                if ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() + reach).powi(2) >= image.safe2
                {
                    slow_paths += 1;
                }
            }
        }
        assert!(
            slow_paths > 100,
            "the search over images is exercised: {slow_paths}"
        );
    }

    #[test]
    fn the_nearest_image_counts_across_the_box() {
        // Two one-atom residues 1 Å and 19 Å apart along x in a 20 Å cubic box: 1 Å both
        // ways; without the cell, 19 Å.
        let cell = UnitCell::from_lengths_angles([20.0, 20.0, 20.0], [90.0, 90.0, 90.0]).unwrap();
        let groups = vec![vec![0], vec![1]];
        let mut map = DistanceMap::new(groups.clone(), 4.5).unwrap();
        map.add(&[[0.5, 3.0, 3.0], [19.5, 3.0, 3.0]], Some(&cell))
            .unwrap();
        assert!((map.mean()[1] - 1.0).abs() < 1e-5, "{}", map.mean()[1]);
        assert_eq!(map.contact_fraction()[2], 1.0);
        let mut open = DistanceMap::new(groups, 4.5).unwrap();
        open.add(&[[0.5, 3.0, 3.0], [19.5, 3.0, 3.0]], None)
            .unwrap();
        assert!((open.mean()[1] - 19.0).abs() < 1e-5);
        assert_eq!(open.contact_fraction()[1], 0.0);
    }

    #[test]
    fn the_smallest_pair_of_atoms_is_the_distance() {
        // Residue 0: atoms at x = 0 and 1; residue 1: x = 4 and 9. Smallest 3 Å.
        let mut map = DistanceMap::new(vec![vec![0, 1], vec![2, 3]], 3.0).unwrap();
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [9.0, 0.0, 0.0],
        ];
        map.add(&p, None).unwrap();
        assert!((map.mean()[1] - 3.0).abs() < 1e-12);
        // Strictly below the cutoff: 3 Å is not a contact at 3 Å.
        assert_eq!(map.contact_fraction()[1], 0.0);
        assert_eq!(map.frames(), 1);
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(DistanceMap::new(vec![vec![0], vec![]], 4.5).is_none());
        assert!(DistanceMap::new(vec![vec![0]], 0.0).is_none());
        assert!(DistanceMap::new(vec![vec![0]], f64::NAN).is_none());
        let mut map = DistanceMap::new(vec![vec![0], vec![3]], 4.5).unwrap();
        assert!(matches!(
            map.add(&[[0.0; 3]; 2], None),
            Err(MsdError::AtomCount { first: 4, frame: 2 })
        ));
        let mut p = [[0.0f32; 3]; 4];
        p[3][2] = f32::NAN;
        assert!(matches!(map.add(&p, None), Err(MsdError::NotFinite(3))));
        assert_eq!(map.frames(), 0);
    }
}

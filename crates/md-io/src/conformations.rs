//! Clustering of a trajectory's conformations on their pairwise RMSD
//! ([`crate::rmsd::rmsd_matrix`]), as `gmx cluster` does: which shapes the run visits, how
//! often, and one representative structure of each.
//!
//! - [`Method::Gromos`] (Daura et al., *Angew. Chem. Int. Ed.* 38, 236 (1999); gmx cluster's
//!   default): count each frame's neighbours, the frames closer than the cutoff (itself
//!   included); the frame with the most is the centre of the first cluster, which takes it and
//!   all its neighbours out of the pool; repeat on what is left. Clusters come out largest
//!   first. Where frames tie for the most neighbours the earliest is the centre (gmx leaves
//!   the choice to an unstable sort).
//! - [`Method::Linkage`] (single linkage, gmx cluster's `linkage`): a frame joins every
//!   cluster holding a frame closer than the cutoff, so clusters are the connected parts of
//!   the graph of close pairs; they are numbered by their first frame. A slow drift chains
//!   distinct shapes into one cluster; gromos does not.
//!
//! Each [`Cluster`] gives its members, its middle structure (gmx's "middle": the member with
//! the smallest mean RMSD to the other members, the earliest on a tie) with that mean, the
//! mean of every member's mean (gmx's cluster RMSD) and its largest pairwise RMSD. The
//! distances compared are strictly below the cutoff, as gmx compares them.
//!
//! ```
//! use texmap_md_io::conformations::{cluster, Method};
//! // Five frames: 0, 1, 2 close together, 3 and 4 close together, the two groups 3 Å apart.
//! let d = |i: usize, j: usize| -> f64 {
//!     if i == j { 0.0 } else if (i < 3) == (j < 3) { 0.5 } else { 3.0 }
//! };
//! let m: Vec<f64> = (0..25).map(|k| d(k / 5, k % 5)).collect();
//! let c = cluster(&m, 5, 1.0, Method::Gromos).unwrap();
//! assert_eq!(c.of_frame, vec![0, 0, 0, 1, 1]);
//! assert_eq!(c.clusters[0].members, vec![0, 1, 2]);
//! assert_eq!(c.clusters[1].middle, 3);
//! assert!((c.clusters[0].mean_rmsd - 0.5).abs() < 1e-12);
//! ```

use std::fmt;

/// How frames are grouped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Daura et al.'s: the frame with the most neighbours and its neighbours, repeated.
    Gromos,
    /// Single linkage: the connected parts of the graph of pairs closer than the cutoff.
    Linkage,
}

impl Method {
    /// The method's name, as gmx cluster's `-method` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Method::Gromos => "gromos",
            Method::Linkage => "linkage",
        }
    }
}

/// One cluster of frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster {
    /// Its frames (indices into the matrix), in order.
    pub members: Vec<usize>,
    /// The member with the smallest mean RMSD to the others (the first member when alone).
    pub middle: usize,
    /// That mean (Å; 0 for a cluster of one).
    pub middle_rmsd: f64,
    /// The mean over the members of each one's mean RMSD to the others (Å; 0 alone).
    pub mean_rmsd: f64,
    /// The largest RMSD between two members (Å).
    pub max_rmsd: f64,
}

/// The clusters of a set of frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Clustering {
    /// Each frame's cluster, an index into `clusters`.
    pub of_frame: Vec<usize>,
    /// The clusters: for gromos in the order found (largest first), for linkage by first frame.
    pub clusters: Vec<Cluster>,
}

impl Clustering {
    /// How many times consecutive frames fall in different clusters.
    pub fn transitions(&self) -> usize {
        self.of_frame.windows(2).filter(|w| w[0] != w[1]).count()
    }
}

/// Why frames could not be clustered.
#[derive(Clone, Debug, PartialEq)]
pub enum ClusterError {
    /// The matrix does not hold `frames²` values.
    Shape {
        /// Its length.
        len: usize,
        /// The frames it should pair.
        frames: usize,
    },
    /// The cutoff is not positive and finite.
    Cutoff(f64),
    /// A distance is negative or not finite, or the matrix is not symmetric there.
    Distance {
        /// Its row.
        i: usize,
        /// Its column.
        j: usize,
        /// The value.
        value: f64,
    },
}

impl fmt::Display for ClusterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClusterError::Shape { len, frames } => write!(
                f,
                "a matrix of {len} values cannot pair {frames} frames ({} expected)",
                frames.saturating_mul(*frames)
            ),
            ClusterError::Cutoff(c) => {
                write!(f, "the cutoff must be a positive RMSD in Å, not {c}")
            }
            ClusterError::Distance { i, j, value } => write!(
                f,
                "the distance between frames {i} and {j} is {value}: distances must be finite, not negative, and the same both ways"
            ),
        }
    }
}

impl std::error::Error for ClusterError {}

/// Clusters `frames` frames whose pairwise RMSD (Å) is `matrix`, row-major `frames x frames`,
/// pairs strictly closer than `cutoff` being neighbours.
pub fn cluster(
    matrix: &[f64],
    frames: usize,
    cutoff: f64,
    method: Method,
) -> Result<Clustering, ClusterError> {
    if matrix.len() != frames.saturating_mul(frames) {
        return Err(ClusterError::Shape {
            len: matrix.len(),
            frames,
        });
    }
    if !(cutoff.is_finite() && cutoff > 0.0) {
        return Err(ClusterError::Cutoff(cutoff));
    }
    for i in 0..frames {
        for j in i..frames {
            let v = matrix[i * frames + j];
            if !(v.is_finite() && v >= 0.0) || v != matrix[j * frames + i] {
                return Err(ClusterError::Distance { i, j, value: v });
            }
        }
    }
    let groups = match method {
        Method::Gromos => gromos(matrix, frames, cutoff),
        Method::Linkage => linkage(matrix, frames, cutoff),
    };
    let mut of_frame = vec![0; frames];
    let clusters = groups
        .into_iter()
        .enumerate()
        .map(|(k, members)| {
            for &f in &members {
                of_frame[f] = k;
            }
            describe(matrix, frames, members)
        })
        .collect();
    Ok(Clustering { of_frame, clusters })
}

/// Daura et al.'s method: each group's members in frame order, groups in the order found.
fn gromos(m: &[f64], n: usize, cutoff: f64) -> Vec<Vec<usize>> {
    let near = |i: usize, j: usize| m[i * n + j] < cutoff;
    let mut left = vec![true; n];
    // Each frame's neighbours still in the pool, itself included.
    let mut count: Vec<usize> = (0..n)
        .map(|i| (0..n).filter(|&j| near(i, j)).count())
        .collect();
    let mut groups = Vec::new();
    while let Some(centre) = (0..n)
        .filter(|&i| left[i])
        .max_by(|&a, &b| count[a].cmp(&count[b]).then(b.cmp(&a)))
    {
        let members: Vec<usize> = (0..n).filter(|&j| left[j] && near(centre, j)).collect();
        for &j in &members {
            left[j] = false;
        }
        for i in (0..n).filter(|&i| left[i]) {
            count[i] -= members.iter().filter(|&&j| near(i, j)).count();
        }
        groups.push(members);
    }
    groups
}

/// Single linkage: the connected parts, each in frame order, by their first frame.
fn linkage(m: &[f64], n: usize, cutoff: f64) -> Vec<Vec<usize>> {
    // A part's root is its lowest index: its first frame.
    let mut parts = crate::components::UnionFind::new(n);
    for i in 0..n {
        for j in i + 1..n {
            if m[i * n + j] < cutoff {
                parts.join(i, j);
            }
        }
    }
    let mut index = vec![usize::MAX; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let r = parts.root(i);
        if index[r] == usize::MAX {
            index[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[index[r]].push(i);
    }
    groups
}

/// A group's middle structure and spread.
fn describe(m: &[f64], n: usize, members: Vec<usize>) -> Cluster {
    let size = members.len();
    let mut middle = members[0];
    let mut middle_rmsd = f64::INFINITY;
    let mut total = 0.0;
    let mut max_rmsd = 0.0f64;
    for &a in &members {
        let mut sum = 0.0;
        for &b in &members {
            let d = m[a * n + b];
            sum += d;
            max_rmsd = max_rmsd.max(d);
        }
        let mean = if size > 1 {
            sum / (size - 1) as f64
        } else {
            0.0
        };
        if mean < middle_rmsd {
            middle = a;
            middle_rmsd = mean;
        }
        total += mean;
    }
    Cluster {
        middle,
        middle_rmsd,
        mean_rmsd: total / size as f64,
        max_rmsd,
        members,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames on a line at `xs`: the distance is |xᵢ − xⱼ|.
    fn line(xs: &[f64]) -> Vec<f64> {
        let n = xs.len();
        (0..n * n).map(|k| (xs[k / n] - xs[k % n]).abs()).collect()
    }

    #[test]
    fn gromos_takes_the_densest_frame_first_and_linkage_chains() {
        // A chain of frames 0.6 apart, then a tight group of four far away.
        let xs = [0.0, 0.6, 1.2, 1.8, 2.4, 10.0, 10.1, 10.2, 10.3];
        let m = line(&xs);
        let g = cluster(&m, xs.len(), 1.0, Method::Gromos).unwrap();
        // The group first (4 neighbours each: the tie goes to its first frame). In the chain
        // frames 1, 2 and 3 have 3 neighbours each: the earliest, frame 1, takes 0, 1 and 2;
        // then 3 and 4 are left with 2 each, and 3 takes both.
        let sizes: Vec<usize> = g.clusters.iter().map(|c| c.members.len()).collect();
        assert_eq!(sizes, vec![4, 3, 2]);
        assert_eq!(g.clusters[0].members, vec![5, 6, 7, 8]);
        assert_eq!(g.clusters[1].members, vec![0, 1, 2]);
        assert_eq!(g.clusters[2].members, vec![3, 4]);
        assert_eq!(g.of_frame, vec![1, 1, 1, 2, 2, 0, 0, 0, 0]);
        assert_eq!(g.transitions(), 2);
        // The middle of the group: 10.1 and 10.2 both have mean (0.1+0.1+0.2)/3; the earliest.
        assert_eq!(g.clusters[0].middle, 6);
        assert!((g.clusters[0].middle_rmsd - 0.4 / 3.0).abs() < 1e-12);
        assert!((g.clusters[0].max_rmsd - 0.3).abs() < 1e-12);
        // Single linkage chains 0.0 … 2.4 into one cluster, numbered by first frame.
        let l = cluster(&m, xs.len(), 1.0, Method::Linkage).unwrap();
        let members: Vec<&[usize]> = l.clusters.iter().map(|c| &c.members[..]).collect();
        assert_eq!(members, vec![&[0, 1, 2, 3, 4][..], &[5, 6, 7, 8][..]]);
        assert_eq!(l.clusters[0].middle, 2, "the chain's middle is its centre");
        assert!((l.clusters[0].max_rmsd - 2.4).abs() < 1e-12);
    }

    #[test]
    fn the_cutoff_is_strict_and_lone_frames_are_their_own_clusters() {
        let m = line(&[0.0, 1.0, 2.0]);
        // At exactly 1.0 nothing is a neighbour of anything else.
        let g = cluster(&m, 3, 1.0, Method::Gromos).unwrap();
        assert_eq!(g.clusters.len(), 3);
        assert!(
            g.clusters
                .iter()
                .all(|c| c.mean_rmsd == 0.0 && c.middle_rmsd == 0.0)
        );
        let g = cluster(&m, 3, 1.0 + 1e-9, Method::Gromos).unwrap();
        assert_eq!(g.clusters[0].members, vec![0, 1, 2]);
        assert_eq!(g.clusters[0].middle, 1);
        // A mean RMSD per member: (1+2)/2, (1+1)/2, (2+1)/2; their mean 4/3.
        assert!((g.clusters[0].mean_rmsd - 4.0 / 3.0).abs() < 1e-12);
        let empty = cluster(&[], 0, 1.0, Method::Linkage).unwrap();
        assert!(empty.clusters.is_empty() && empty.of_frame.is_empty());
    }

    #[test]
    fn bad_input_is_refused() {
        let m = line(&[0.0, 1.0]);
        assert_eq!(
            cluster(&m, 3, 1.0, Method::Gromos),
            Err(ClusterError::Shape { len: 4, frames: 3 })
        );
        for c in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                cluster(&m, 2, c, Method::Gromos),
                Err(ClusterError::Cutoff(_))
            ));
        }
        let mut bad = m.clone();
        bad[1] = f64::NAN;
        assert!(matches!(
            cluster(&bad, 2, 1.0, Method::Linkage),
            Err(ClusterError::Distance { i: 0, j: 1, .. })
        ));
        let mut skew = m.clone();
        skew[2] = 0.5;
        let e = cluster(&skew, 2, 1.0, Method::Gromos).unwrap_err();
        assert!(e.to_string().contains("frames 0 and 1"), "{e}");
    }
}

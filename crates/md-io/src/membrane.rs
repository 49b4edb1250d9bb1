//! Bilayer leaflets, thickness and area per lipid: the numbers a membrane simulation is checked
//! by before anything else (is it at the experimental area per lipid, has it thinned).
//!
//! - [`leaflets`] finds the leaflets as MDAnalysis's `LeafletFinder` does: the head-group atoms
//!   (one per lipid, usually the phosphorus) joined when closer than a cutoff (15 Å by default),
//!   nearest periodic images included; each connected set is a leaflet, the largest first. A
//!   flat bilayer gives two; a vesicle's inner and outer leaflets come out the same way.
//! - [`measure`] gives, for the two largest leaflets in a frame, the distance between their mean
//!   heights along the normal axis (the head-to-head thickness read off `gmx density`'s profile
//!   or FATSLiM's), and the area per lipid of each leaflet: the area of the box face normal to
//!   the axis over the leaflet's lipids. Each leaflet's mean height is taken about its first
//!   head through nearest images. Along a periodic normal the two leaflets are two gaps apart
//!   (through the bilayer and through the water); each lipid's tail atom (the CLI takes the
//!   atom of the head's residue farthest from it) tells which way the bilayer lies, so a bilayer
//!   across the box's faces is measured through its tails, not through the water. Without
//!   tails, the nearer gap is taken.
//!
//! ```
//! use texmap_md_io::membrane::{leaflets, measure};
//! use texmap_md_io::UnitCell;
//! // Four heads: two at z = 10, two at z = 50, 8 Å apart in each leaflet.
//! let p = [[0.0, 0.0, 10.0], [8.0, 0.0, 10.0], [0.0, 0.0, 50.0], [8.0, 0.0, 50.0]];
//! let cell = UnitCell::orthorhombic(16.0, 16.0, 80.0).unwrap();
//! let found = leaflets(&p, &[0, 1, 2, 3], Some(&cell), 15.0);
//! assert_eq!(found, vec![vec![0, 1], vec![2, 3]]);
//! let m = measure(&p, &found, Some(&cell), 2, |_| None).unwrap();
//! assert_eq!(m.thickness, 40.0);
//! assert_eq!(m.area_per_lipid, [128.0, 128.0]); // 16 x 16 Å² over two lipids
//! ```

use std::fmt;

use crate::frame::UnitCell;
use crate::pbc::NearestImage;

/// One frame's bilayer measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bilayer {
    /// The lipids of the upper and the lower leaflet (along the normal).
    pub lipids: [usize; 2],
    /// The distance between the two leaflets' mean head heights (Å).
    pub thickness: f64,
    /// The mean head height of the upper and of the lower leaflet (Å).
    pub heights: [f64; 2],
    /// The area of the box face normal to the axis (Å²); NaN without a cell.
    pub area: f64,
    /// `area` over each leaflet's lipids (Å²), upper then lower.
    pub area_per_lipid: [f64; 2],
}

/// Why a frame has no bilayer measures.
#[derive(Clone, Debug, PartialEq)]
pub enum MembraneError {
    /// Fewer than two leaflets (the cutoff joined them, or too few heads).
    Leaflets(usize),
    /// The normal is not axis 0, 1 or 2.
    Normal(usize),
    /// A head atom index past the frame's atoms.
    OutOfRange(usize),
}

impl fmt::Display for MembraneError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            MembraneError::Leaflets(n) => write!(
                f,
                "the head atoms form {n} leaflet(s), not two: the cutoff may be too long (it joins \
                 the leaflets) or the selection holds no bilayer"
            ),
            MembraneError::Normal(k) => {
                write!(f, "the normal must be axis 0, 1 or 2 (x, y, z), not {k}")
            }
            MembraneError::OutOfRange(i) => {
                write!(f, "head atom {} is past the frame's atoms", i + 1)
            }
        }
    }
}

impl std::error::Error for MembraneError {}

/// The leaflets of the head atoms `heads` (indices into `positions`): sets joined by distances
/// below `cutoff` Å (nearest images in `cell`), each sorted, the largest first (equal sizes by
/// their first atom). Heads past `positions` are left out.
pub fn leaflets(
    positions: &[[f32; 3]],
    heads: &[usize],
    cell: Option<&UnitCell>,
    cutoff: f64,
) -> Vec<Vec<usize>> {
    let heads: Vec<usize> = heads
        .iter()
        .copied()
        .filter(|&i| i < positions.len())
        .collect();
    let p: Vec<[f32; 3]> = heads.iter().map(|&i| positions[i]).collect();
    let radius = ((cutoff - crate::bonds::BOND_TOLERANCE as f64) / 2.0) as f32;
    let grid = crate::bonds::bonds_with_radii(&p, &vec![radius; p.len()], cell.copied());
    let periodic = cell.is_some_and(|c| c.periodic().contains(&true));
    let pairs = if grid.periodic || !periodic {
        grid.pairs
    } else {
        // A box too narrow for the cell grid's images: every pair, through the nearest image.
        let image = cell.and_then(NearestImage::new);
        let mut pairs = Vec::new();
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                let d: [f64; 3] = std::array::from_fn(|k| f64::from(p[j][k] - p[i][k]));
                let d = image.as_ref().map_or(d, |m| m.apply(d));
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < cutoff * cutoff {
                    pairs.push([i as u32, j as u32]);
                }
            }
        }
        pairs
    };
    let mut parts = crate::components::UnionFind::new(p.len());
    for [a, b] in pairs {
        parts.join(a as usize, b as usize);
    }
    let mut sets: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (k, &h) in heads.iter().enumerate() {
        sets.entry(parts.root(k)).or_default().push(h);
    }
    let mut out: Vec<Vec<usize>> = sets.into_values().collect();
    for s in &mut out {
        s.sort_unstable();
    }
    out.sort_by(|a, b| b.len().cmp(&a.len()).then(a[0].cmp(&b[0])));
    out
}

/// The thickness and areas per lipid of the two largest of `leaflets` (as [`leaflets`] gives
/// them) in `positions`, along axis `normal` (0, 1, 2 for x, y, z); `tail_of` gives a head's
/// tail atom, if known (see the module docs).
pub fn measure(
    positions: &[[f32; 3]],
    leaflets: &[Vec<usize>],
    cell: Option<&UnitCell>,
    normal: usize,
    tail_of: impl Fn(usize) -> Option<usize>,
) -> Result<Bilayer, MembraneError> {
    if normal > 2 {
        return Err(MembraneError::Normal(normal));
    }
    let two: Vec<&Vec<usize>> = leaflets.iter().filter(|l| !l.is_empty()).take(2).collect();
    if two.len() < 2 {
        return Err(MembraneError::Leaflets(two.len()));
    }
    let past = |i: &usize| *i >= positions.len();
    if let Some(i) = two
        .iter()
        .flat_map(|l| {
            l.iter()
                .copied()
                .chain(l.iter().filter_map(|&h| tail_of(h)))
        })
        .find(past)
    {
        return Err(MembraneError::OutOfRange(i));
    }
    let image = cell.and_then(NearestImage::new);
    let nearest = |d: [f64; 3]| image.as_ref().map_or(d, |m| m.apply(d));
    let at = |i: usize| positions[i].map(f64::from);
    // Each leaflet's mean height about its first head, through nearest images, and the mean
    // normal component of its head-to-tail vectors (which way its tails point).
    let side = |l: &[usize]| -> (f64, f64) {
        let o = at(l[0]);
        let (mut sum, mut inward) = (0.0, 0.0);
        for &i in l {
            sum += nearest(std::array::from_fn(|k| at(i)[k] - o[k]))[normal];
            if let Some(t) = tail_of(i) {
                inward += nearest(std::array::from_fn(|k| at(t)[k] - at(i)[k]))[normal];
            }
        }
        (o[normal] + sum / l.len() as f64, inward)
    };
    let ((a, inward_a), (b, inward_b)) = (side(two[0]), side(two[1]));
    let period = cell.filter(|c| c.periodic()[normal]).map(|c| {
        let m = c.matrix();
        c.volume() / face(m, normal).length()
    });
    // The offset from the first leaflet to the second along the normal: through the first
    // leaflet's tails when they say which way that is, else the nearest.
    let direction = inward_a - inward_b;
    let gap = match period {
        Some(h) if direction != 0.0 => {
            let s = direction.signum();
            s * (s * (b - a)).rem_euclid(h)
        }
        Some(h) => (b - a) - h * ((b - a) / h).round(),
        None => b - a,
    };
    let (upper, lower, top, bottom) = if gap < 0.0 {
        (two[0], two[1], a, a + gap)
    } else {
        (two[1], two[0], a + gap, a)
    };
    let area = match cell {
        Some(c) => {
            let m = c.matrix();
            face(m, normal)[normal].abs()
        }
        None => f64::NAN,
    };
    Ok(Bilayer {
        lipids: [upper.len(), lower.len()],
        thickness: gap.abs(),
        heights: [top, bottom],
        area,
        area_per_lipid: [area / upper.len() as f64, area / lower.len() as f64],
    })
}

/// The cross product of the cell's two edges other than `normal`: the face's normal, as long
/// as the face's area.
fn face(m: [[f64; 3]; 3], normal: usize) -> glam::DVec3 {
    glam::DVec3::from_array(m[(normal + 1) % 3]).cross(glam::DVec3::from_array(m[(normal + 2) % 3]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heads on a square lattice of `n` x `n` at `spacing` Å per leaflet, the lower leaflet at
    /// `z`, the upper at `z + gap`, z taken modulo `lz`; then each head's tail atom, 12 Å
    /// toward the other leaflet through the bilayer. Heads first, tails after.
    fn bilayer(n: usize, spacing: f32, z: f32, gap: f32, lz: f32) -> Vec<[f32; 3]> {
        let mut heads = Vec::new();
        let mut tails = Vec::new();
        for (layer, inward) in [(z, 12.0), (z + gap, -12.0)] {
            for i in 0..n {
                for j in 0..n {
                    let wobble = ((i * 7 + j * 3) % 5) as f32 * 0.2 - 0.4;
                    let (x, y) = (i as f32 * spacing, j as f32 * spacing);
                    heads.push([x, y, (layer + wobble).rem_euclid(lz)]);
                    tails.push([x, y, (layer + wobble + inward).rem_euclid(lz)]);
                }
            }
        }
        heads.extend(tails);
        heads
    }

    #[test]
    fn a_bilayer_across_the_box_faces_is_two_leaflets_of_the_right_thickness() {
        let lz = 60.0;
        let cell = UnitCell::orthorhombic(64.0, 64.0, f64::from(lz)).unwrap();
        let heads: Vec<usize> = (0..128).collect();
        let tail = |h: usize| Some(h + 128);
        // The second and third bilayers cross the top face, the third is thicker than the
        // water between its periodic images (38 Å against 22).
        for (z, gap) in [(10.0, 40.0), (50.0, 25.0), (55.0, 38.0)] {
            let p = bilayer(8, 8.0, z, gap, lz);
            let found = leaflets(&p, &heads, Some(&cell), 15.0);
            assert_eq!(found.len(), 2, "{z}");
            assert_eq!(found[0], (0..64).collect::<Vec<_>>());
            let m = measure(&p, &found, Some(&cell), 2, tail).unwrap();
            // The wobble is the same in both leaflets: the gap exactly, to float rounding.
            assert!((m.thickness - f64::from(gap)).abs() < 1e-4, "{z}: {m:?}");
            // The lower leaflet's mean height: z plus the mean wobble (−0.009 Å).
            assert!((m.heights[1] - f64::from(z)).abs() < 0.01, "{z}: {m:?}");
            assert_eq!(m.lipids, [64, 64]);
            assert_eq!(m.area, 64.0 * 64.0);
            assert_eq!(m.area_per_lipid, [64.0, 64.0]);
            // Without tails, the nearer of the two gaps.
            let near = measure(&p, &found, Some(&cell), 2, |_| None).unwrap();
            let want = f64::from(gap.min(lz - gap));
            assert!((near.thickness - want).abs() < 1e-4, "{z}: {near:?}");
        }
        // A cutoff below the spacing leaves every head alone; one longer than the gap joins
        // the leaflets into one.
        let p = bilayer(8, 8.0, 10.0, 40.0, lz);
        assert_eq!(leaflets(&p, &heads, Some(&cell), 7.0).len(), 128);
        assert_eq!(leaflets(&p, &heads, Some(&cell), 25.0).len(), 1);
        let e = measure(&p, std::slice::from_ref(&heads), Some(&cell), 2, tail).unwrap_err();
        assert_eq!(e, MembraneError::Leaflets(1));
        assert!(e.to_string().contains("not two"));
        // Heads joined only through the images, in a cell too narrow for the cell grid
        // (30 Å, below three 12 Å cutoffs): the search over pairs finds them.
        let p = [
            [1.0, 5.0, 10.0],
            [28.0, 5.0, 10.0],
            [1.0, 5.0, 50.0],
            [28.0, 5.0, 50.0],
        ];
        let narrow = UnitCell::orthorhombic(30.0, 30.0, 100.0).unwrap();
        let found = leaflets(&p, &[0, 1, 2, 3], Some(&narrow), 12.0);
        assert_eq!(found, vec![vec![0, 1], vec![2, 3]]);
        assert_eq!(leaflets(&p, &[0, 1, 2, 3], None, 12.0).len(), 4);
    }

    #[test]
    fn the_upper_leaflet_is_the_one_above_and_the_normal_may_be_any_axis() {
        // Leaflets stacked along x this time; the larger one is the lower.
        let mut p = Vec::new();
        for j in 0..5 {
            p.push([20.0, j as f32 * 6.0, 0.0]);
        }
        for j in 0..4 {
            p.push([45.0, j as f32 * 6.0, 0.0]);
        }
        let cell = UnitCell::orthorhombic(90.0, 30.0, 30.0).unwrap();
        let found = leaflets(&p, &(0..9).collect::<Vec<_>>(), Some(&cell), 10.0);
        let m = measure(&p, &found, Some(&cell), 0, |_| None).unwrap();
        assert_eq!(m.lipids, [4, 5]);
        assert_eq!(m.heights, [45.0, 20.0]);
        assert_eq!(m.thickness, 25.0);
        assert_eq!(m.area_per_lipid, [900.0 / 4.0, 900.0 / 5.0]);
        let open = measure(&p, &found, None, 0, |_| None).unwrap();
        assert_eq!(open.thickness, 25.0);
        assert!(open.area.is_nan());
        assert_eq!(
            measure(&p, &found, None, 3, |_| None),
            Err(MembraneError::Normal(3))
        );
        assert_eq!(
            measure(&p[..3], &found, None, 0, |_| None),
            Err(MembraneError::OutOfRange(3))
        );
    }
}

//! Local lattice orientation per atom, as OVITO's Polyhedral Template Matching modifier
//! outputs it (P. M. Larsen, S. Schmidt, J. Schiøtz, "Robust structural identification via
//! polyhedral template matching", Modelling Simul. Mater. Sci. Eng. 24 (2016) 055007): the
//! rotation that carries the ideal crystal's neighbour shell onto an atom's neighbours, and how
//! far they are from it (the RMSD). Polycrystal simulations colour atoms by it (an inverse pole
//! figure, as EBSD maps are coloured) and split the crystal into grains by it
//! ([`crate::grains`]).
//!
//! Per atom of a crystalline [`StructureType`] (FCC, HCP, BCC from [`crate::cna`]):
//! 1. Its 12 (FCC, HCP) or 14 (BCC) nearest neighbours and the template's, both with the atom
//!    itself, moved so their barycentre is the origin and scaled so the neighbours' mean
//!    distance from it is 1 (PTM's normalisation).
//! 2. Which neighbour is which template point: the nearest neighbour is paired with one
//!    template point per orbit of the template's own rotations (FCC 1, BCC 2, HCP 2: pairings
//!    that differ by such a rotation fit equally well), and a second neighbour (the one of the
//!    first shell whose angle to the nearest is closest to the shell's first angle: 60° in FCC
//!    and HCP, 70.5° in BCC) with every template point at a like angle; the rotation those two
//!    pairs fix pairs every other neighbour with its nearest template direction. Of the
//!    pairings that are one-to-one, the one of least RMSD wins.
//! 3. The best rotation for it by Horn's quaternion method ([`crate::rotation`]), and
//!    RMSD = √((Σ|t|² − E²/Σ|p|²) / (N + 1)), E its eigenvalue: the RMSD after the best
//!    scaling, as PTM reports it.
//! 4. The quaternion moved into the fundamental zone: of its equivalents under the lattice's
//!    proper rotations (24 cubic; 12 hexagonal), the one of largest |w|, with w ≥ 0.
//!
//! Quaternions are `[x, y, z, w]` (OVITO's order) and rotate the template's frame into the
//! simulation's: the cubic template's axes are x, y, z; the hexagonal one has a₁ along x and c
//! along z. A crystal built along the box axes has the identity orientation.
//!
//! ```
//! use texmap_md_io::cna::classify;
//! use texmap_md_io::orientation::{Symmetry, disorientation, orientations};
//! use texmap_md_io::{Frame, UnitCell};
//! // A 3x3x3 block of BCC cells (a = 2.87 Å), periodic, turned by 10° about z.
//! let (a, t) = (2.87f64, 10f64.to_radians());
//! let turn = |p: [f64; 3]| [p[0] * t.cos() - p[1] * t.sin(), p[0] * t.sin() + p[1] * t.cos(), p[2]];
//! let mut frame = Frame::new();
//! for (i, j, k) in (0..27).map(|n| (n % 3, n / 3 % 3, n / 9)) {
//!     for b in [0.0, 0.5] {
//!         let p = turn([(i as f64 + b) * a, (j as f64 + b) * a, (k as f64 + b) * a]);
//!         frame.positions.push([p[0] as f32, p[1] as f32, p[2] as f32]);
//!     }
//! }
//! let (e1, e2) = (turn([3.0 * a, 0.0, 0.0]), turn([0.0, 3.0 * a, 0.0]));
//! frame.cell = Some(UnitCell::from_matrix([e1, e2, [0.0, 0.0, 3.0 * a]]).unwrap());
//! let fits = orientations(&frame, &classify(&frame));
//! let expected = [0.0, 0.0, (t / 2.0).sin(), (t / 2.0).cos()];
//! for fit in &fits {
//!     let fit = fit.expect("every atom is BCC");
//!     assert!(disorientation(fit.orientation, expected, Symmetry::Cubic) < 1e-5);
//!     assert!(fit.rmsd < 1e-5);
//! }
//! ```

use glam::{DMat3, DQuat, DVec3};

use crate::cna::StructureType;
use crate::frame::Frame;
use crate::neighbours::{Grid, Scratch};
use crate::rotation::best_rotation;

/// A lattice's point group of proper rotations, for orientations that are the same crystal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// The 24 rotations of the cube (FCC, BCC).
    Cubic,
    /// The 12 rotations of the hexagonal prism (HCP).
    Hexagonal,
}

impl Symmetry {
    /// The symmetry of a crystalline structure type (`None`: other, icosahedral).
    pub fn of(structure: StructureType) -> Option<Symmetry> {
        match structure {
            StructureType::Fcc | StructureType::Bcc => Some(Symmetry::Cubic),
            StructureType::Hcp => Some(Symmetry::Hexagonal),
            StructureType::Other | StructureType::Ico => None,
        }
    }

    /// The group's rotations as quaternions, the identity first.
    pub fn rotations(self) -> &'static [DQuat] {
        use std::sync::OnceLock;
        static CUBIC: OnceLock<Vec<DQuat>> = OnceLock::new();
        static HEXAGONAL: OnceLock<Vec<DQuat>> = OnceLock::new();
        match self {
            Symmetry::Cubic => CUBIC.get_or_init(|| {
                // The signed permutation matrices of determinant +1.
                let mut out = Vec::with_capacity(24);
                for perm in [
                    [0, 1, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [0, 2, 1],
                    [2, 1, 0],
                    [1, 0, 2],
                ] {
                    for signs in 0..8 {
                        let mut cols = [DVec3::ZERO; 3];
                        for (c, col) in cols.iter_mut().enumerate() {
                            let s = if signs >> c & 1 == 1 { -1.0 } else { 1.0 };
                            col[perm[c]] = s;
                        }
                        let m = DMat3::from_cols(cols[0], cols[1], cols[2]);
                        if m.determinant() > 0.0 {
                            out.push(DQuat::from_mat3(&m).normalize());
                        }
                    }
                }
                out
            }),
            Symmetry::Hexagonal => HEXAGONAL.get_or_init(|| {
                let mut out = Vec::with_capacity(12);
                for k in 0..6 {
                    out.push(DQuat::from_rotation_z(
                        k as f64 * std::f64::consts::FRAC_PI_3,
                    ));
                }
                for j in 0..6 {
                    let a = j as f64 * std::f64::consts::FRAC_PI_6;
                    out.push(DQuat::from_axis_angle(
                        DVec3::new(a.cos(), a.sin(), 0.0),
                        std::f64::consts::PI,
                    ));
                }
                out
            }),
        }
    }
}

/// An atom's fit to its structure's template.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatticeFit {
    /// The rotation from the template to the atom's neighbours, `[x, y, z, w]`, in the
    /// fundamental zone of [`LatticeFit::symmetry`].
    pub orientation: [f64; 4],
    /// Root-mean-square deviation from the template after the best rotation and scale, the
    /// neighbours' mean distance taken as 1 (PTM's RMSD).
    pub rmsd: f64,
    /// The lattice symmetry the orientation is reduced by.
    pub symmetry: Symmetry,
}

/// The orientation and RMSD of every atom whose `types` entry is FCC, HCP or BCC (`None` for
/// the others, and for an atom too few neighbours or no one-to-one pairing fit). `types` is
/// [`crate::cna::classify`]'s result for `frame`. In parallel; the result does not depend on
/// the thread count.
///
/// # Panics
/// If `types` and the frame's atoms differ in number.
pub fn orientations(frame: &Frame, types: &[StructureType]) -> Vec<Option<LatticeFit>> {
    use rayon::prelude::*;
    assert_eq!(
        types.len(),
        frame.positions.len(),
        "one structure type per atom"
    );
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    (0..types.len())
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            let template = Template::of(types[i])?;
            grid.nearest(i, template.points.len(), scratch);
            if scratch.near.len() < template.points.len() {
                return None;
            }
            template.fit(&scratch.near)
        })
        .collect()
}

/// The smallest rotation angle (radians) between orientations `a` and `b` (`[x, y, z, w]`)
/// over the equivalents under `symmetry`: the disorientation, as OVITO's
/// `PolyhedralTemplateMatchingModifier.calculate_misorientation` computes it.
pub fn disorientation(a: [f64; 4], b: [f64; 4], symmetry: Symmetry) -> f64 {
    let m = quat(a).normalize().inverse() * quat(b).normalize();
    let w = best_equivalent(m, symmetry).1;
    2.0 * w.min(1.0).acos()
}

/// `q` (`[x, y, z, w]`) moved into the fundamental zone of `symmetry`: the equivalent `q·g` of
/// largest |w| over the group's rotations g, with w ≥ 0 (PTM's choice).
pub fn fundamental_zone(q: [f64; 4], symmetry: Symmetry) -> [f64; 4] {
    let q = quat(q).normalize();
    let (g, _) = best_equivalent(q, symmetry);
    let mut r = q * g;
    if r.w < 0.0 {
        r = -r;
    }
    [r.x, r.y, r.z, r.w]
}

/// The group rotation g making |w(q·g)| largest, and that |w|.
fn best_equivalent(q: DQuat, symmetry: Symmetry) -> (DQuat, f64) {
    let mut best = (DQuat::IDENTITY, -1.0);
    for g in symmetry.rotations() {
        // w(q·g) = q.w g.w − q.v·g.v: a 4-vector dot product.
        let w = (q.w * g.w - q.x * g.x - q.y * g.y - q.z * g.z).abs();
        if w > best.1 {
            best = (*g, w);
        }
    }
    best
}

fn quat(q: [f64; 4]) -> DQuat {
    DQuat::from_xyzw(q[0], q[1], q[2], q[3])
}

/// The colour of an inverse pole figure: which crystal direction the sample direction `axis`
/// lies along in an atom of orientation `q` (`[x, y, z, w]`), coloured by where that direction
/// falls in the standard triangle of the lattice's Laue group. Cubic: [001] red, [101] green,
/// [111] blue; hexagonal: [0001] red, [2-1-10] green, [10-10] blue; between them the
/// direction's barycentric weights in the triangle, scaled so the largest is 1 (the EBSD
/// convention of TSL/EDAX and MTEX's classic key).
pub fn ipf_colour(q: [f64; 4], symmetry: Symmetry, axis: [f64; 3]) -> [f32; 3] {
    let r = quat(q).normalize();
    let h = r.inverse() * DVec3::from(axis).normalize_or(DVec3::Z);
    let w = match symmetry {
        Symmetry::Cubic => {
            let mut s = [h.x.abs(), h.y.abs(), h.z.abs()];
            s.sort_by(f64::total_cmp);
            let (y, x, z) = (s[0], s[1], s[2]);
            [z - x, std::f64::consts::SQRT_2 * (x - y), 3f64.sqrt() * y]
        }
        Symmetry::Hexagonal => {
            // The in-plane angle folded into [0°, 30°] by the 6-fold axis and its mirrors.
            let rho = h.x.hypot(h.y);
            let sector = std::f64::consts::FRAC_PI_3;
            let mut phi = h.y.atan2(h.x).rem_euclid(sector);
            if phi > sector / 2.0 {
                phi = sector - phi;
            }
            let (hx, hy) = (rho * phi.cos(), rho * phi.sin());
            [h.z.abs(), hx - 3f64.sqrt() * hy, 2.0 * hy]
        }
    };
    let w = w.map(|v| v.max(0.0));
    let top = w[0].max(w[1]).max(w[2]);
    if top.is_nan() || top <= 0.0 {
        return [0.0; 3];
    }
    w.map(|v| (v / top) as f32)
}

/// A structure's ideal neighbour shell, normalised as PTM normalises.
struct Template {
    /// Neighbour directions in the template's frame, nearest shell first.
    points: Vec<DVec3>,
    /// How many points the first shell has (the anchor's candidates).
    first_shell: usize,
    /// The cosine of the angle between the anchor and the second neighbour chosen.
    anchor_cos: f64,
    /// The points' unit directions.
    unit: Vec<DVec3>,
    /// The points that stand for their orbits under the template's own rotations (the
    /// smallest index of each): the nearest neighbour is paired only with these, since
    /// pairings that differ by such a rotation fit equally well.
    representatives: Vec<usize>,
    /// The normalised points (centre first) and Σ|t|².
    normalised: Vec<DVec3>,
    g2: f64,
    symmetry: Symmetry,
}

impl Template {
    fn of(structure: StructureType) -> Option<&'static Template> {
        use std::sync::OnceLock;
        static FCC: OnceLock<Template> = OnceLock::new();
        static HCP: OnceLock<Template> = OnceLock::new();
        static BCC: OnceLock<Template> = OnceLock::new();
        match structure {
            StructureType::Fcc => Some(FCC.get_or_init(|| {
                let mut p = Vec::new();
                for (a, b) in [(0, 1), (0, 2), (1, 2)] {
                    for (sa, sb) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                        let mut v = DVec3::ZERO;
                        v[a] = sa;
                        v[b] = sb;
                        p.push(v / std::f64::consts::SQRT_2);
                    }
                }
                Template::new(p, 12, 0.5, Symmetry::Cubic)
            })),
            StructureType::Hcp => Some(HCP.get_or_init(|| {
                // Site A of a lattice with a₁ along x and c along z (c/a = √(8/3)): six
                // neighbours in the plane, three above and three below at 90°, 210°, 330°.
                let mut p = Vec::new();
                for k in 0..6 {
                    let t = (k as f64 * 60f64).to_radians();
                    p.push(DVec3::new(t.cos(), t.sin(), 0.0));
                }
                for z in [1.0, -1.0] {
                    for deg in [90f64, 210.0, 330.0] {
                        let t = deg.to_radians();
                        let r = 1.0 / 3f64.sqrt();
                        p.push(DVec3::new(
                            r * t.cos(),
                            r * t.sin(),
                            z * (2.0f64 / 3.0).sqrt(),
                        ));
                    }
                }
                Template::new(p, 12, 0.5, Symmetry::Hexagonal)
            })),
            StructureType::Bcc => Some(BCC.get_or_init(|| {
                let mut p = Vec::new();
                for s in 0..8 {
                    let sign = |b: usize| if s >> b & 1 == 1 { -0.5 } else { 0.5 };
                    p.push(DVec3::new(sign(0), sign(1), sign(2)));
                }
                for axis in 0..3 {
                    for s in [1.0, -1.0] {
                        let mut v = DVec3::ZERO;
                        v[axis] = s;
                        p.push(v);
                    }
                }
                Template::new(p, 8, 1.0 / 3.0, Symmetry::Cubic)
            })),
            StructureType::Other | StructureType::Ico => None,
        }
    }

    fn new(
        points: Vec<DVec3>,
        first_shell: usize,
        anchor_cos: f64,
        symmetry: Symmetry,
    ) -> Template {
        let normalised = normalise(&points);
        let g2 = normalised.iter().map(|v| v.length_squared()).sum();
        let unit: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
        let representatives = orbit_representatives(&points);
        Template {
            unit,
            representatives,
            points,
            first_shell,
            anchor_cos,
            normalised,
            g2,
            symmetry,
        }
    }

    /// The best fit of the neighbours `near` (vector, distance; nearest first).
    fn fit(&self, near: &[([f64; 3], f64)]) -> Option<LatticeFit> {
        let n = self.points.len();
        let nb: Vec<DVec3> = near[..n].iter().map(|(v, _)| DVec3::from(*v)).collect();
        if nb
            .iter()
            .any(|v| v.length_squared().is_nan() || v.length_squared() <= 0.0)
        {
            return None;
        }
        let unit: Vec<DVec3> = nb.iter().map(|v| v.normalize()).collect();
        // The second anchor: the neighbour of the first shell whose angle to the nearest is
        // closest to the template's.
        let second = (1..self.first_shell)
            .min_by(|&a, &b| {
                let da = (unit[0].dot(unit[a]) - self.anchor_cos).abs();
                let db = (unit[0].dot(unit[b]) - self.anchor_cos).abs();
                da.total_cmp(&db)
            })
            .expect("a shell has two points");
        let cos = unit[0].dot(unit[second]);
        let lab = frame_of(unit[0], unit[second])?;
        let points = normalise(&nb);
        let g1: f64 = points.iter().map(|v| v.length_squared()).sum();
        let mut best: Option<(f64, DQuat)> = None;
        let mut pairing = vec![0usize; n];
        // Every template point for the anchors (not only its shell's: in a distorted shell
        // the nearest neighbour may be the template's second shell).
        for &j in &self.representatives {
            let tj = self.unit[j];
            for k in 0..n {
                let tk = self.unit[k];
                if k == j || (tj.dot(tk) - cos).abs() > 0.25 {
                    continue;
                }
                let Some(tf) = frame_of(tj, tk) else { continue };
                let turn = lab * tf.transpose();
                // Pair every neighbour with its nearest template direction, one to one.
                let mut used = 0u32;
                let mut ok = true;
                for (m, u) in unit.iter().enumerate() {
                    let back = turn.transpose() * *u;
                    let mut pick = 0;
                    let mut most = f64::NEG_INFINITY;
                    for (t, p) in self.unit.iter().enumerate() {
                        let d = back.dot(*p);
                        if d > most {
                            most = d;
                            pick = t;
                        }
                    }
                    if used >> pick & 1 == 1 {
                        ok = false;
                        break;
                    }
                    used |= 1 << pick;
                    pairing[m] = pick;
                }
                if !ok {
                    continue;
                }
                // Σ t pᵀ; the centre (index 0 of the normalised sets) pairs with the centre.
                let mut s = [[0.0; 3]; 3];
                let pairs = std::iter::once((0, 0))
                    .chain(pairing.iter().enumerate().map(|(m, &t)| (t + 1, m + 1)));
                for (t, p) in pairs {
                    let (t, p) = (self.normalised[t], points[p]);
                    for (row, ta) in s.iter_mut().zip([t.x, t.y, t.z]) {
                        for (v, pb) in row.iter_mut().zip([p.x, p.y, p.z]) {
                            *v += ta * pb;
                        }
                    }
                }
                let (e, [w, x, y, z]) = best_rotation(s);
                let q = DQuat::from_xyzw(x, y, z, w);
                if best.is_none_or(|(be, _)| e > be) {
                    best = Some((e, q));
                }
            }
        }
        let (e, q) = best?;
        let rmsd = ((self.g2 - e * e / g1) / (n + 1) as f64).max(0.0).sqrt();
        Some(LatticeFit {
            orientation: fundamental_zone([q.x, q.y, q.z, q.w], self.symmetry),
            rmsd,
            symmetry: self.symmetry,
        })
    }
}

/// The smallest index of each orbit of `points` under the rotations that map the set onto
/// itself.
fn orbit_representatives(points: &[DVec3]) -> Vec<usize> {
    let n = points.len();
    let unit: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
    let image = |r: &DMat3, p: DVec3| (0..n).find(|&i| (*r * p - points[i]).length() < 1e-9);
    // A second point off the first's axis fixes a rotation.
    let a = (1..n)
        .find(|&k| unit[0].cross(unit[k]).length() > 1e-6)
        .expect("a template spans space");
    let from = frame_of(unit[0], unit[a]).expect("not parallel");
    let mut group = Vec::new();
    for j in 0..n {
        for k in 0..n {
            let same_shape = (points[j].length() - points[0].length()).abs() < 1e-9
                && (points[k].length() - points[a].length()).abs() < 1e-9
                && (unit[j].dot(unit[k]) - unit[0].dot(unit[a])).abs() < 1e-9;
            let Some(to) = frame_of(unit[j], unit[k]) else {
                continue;
            };
            let r = to * from.transpose();
            if same_shape && points.iter().all(|p| image(&r, *p).is_some()) {
                group.push(r);
            }
        }
    }
    (0..n)
        .filter(|&j| {
            group
                .iter()
                .all(|r| image(r, points[j]).is_none_or(|i| i >= j))
        })
        .collect()
}

/// The centre (the origin) and `points`, moved so their barycentre is the origin and scaled
/// so the points' mean length from it is 1; the centre first.
fn normalise(points: &[DVec3]) -> Vec<DVec3> {
    let centre = points.iter().sum::<DVec3>() / (points.len() + 1) as f64;
    let mut out = Vec::with_capacity(points.len() + 1);
    out.push(-centre);
    out.extend(points.iter().map(|p| *p - centre));
    let scale = out[1..].iter().map(|p| p.length()).sum::<f64>() / points.len() as f64;
    out.iter().map(|p| *p / scale).collect()
}

/// An orthonormal frame (columns) from two directions, `None` if they are parallel.
fn frame_of(a: DVec3, b: DVec3) -> Option<DMat3> {
    let w = a.cross(b);
    if w.length_squared() < 1e-12 {
        return None;
    }
    let w = w.normalize();
    Some(DMat3::from_cols(a, w.cross(a), w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_have_their_point_groups() {
        // FCC: one orbit under the cube's 24 rotations; BCC: the two shells; HCP (site A, D3):
        // the plane's six and the others' six.
        let reps = |s| Template::of(s).unwrap().representatives.clone();
        assert_eq!(reps(StructureType::Fcc), vec![0]);
        assert_eq!(reps(StructureType::Bcc), vec![0, 8]);
        assert_eq!(reps(StructureType::Hcp), vec![0, 6]);
    }

    #[test]
    fn groups_are_closed() {
        for sym in [Symmetry::Cubic, Symmetry::Hexagonal] {
            let g = sym.rotations();
            assert_eq!(g.len(), if sym == Symmetry::Cubic { 24 } else { 12 });
            for a in g {
                for b in g {
                    let p = *a * *b;
                    assert!(g.iter().any(|c| c.dot(p).abs() > 1.0 - 1e-12));
                }
            }
        }
    }

    #[test]
    fn ipf_vertices() {
        let id = [0.0, 0.0, 0.0, 1.0];
        let c = Symmetry::Cubic;
        assert_eq!(ipf_colour(id, c, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        assert_eq!(ipf_colour(id, c, [1.0, 0.0, 1.0]), [0.0, 1.0, 0.0]);
        let b = ipf_colour(id, c, [1.0, 1.0, 1.0]);
        assert!(b[0] < 1e-6 && b[1] < 1e-6 && b[2] == 1.0);
        let h = Symmetry::Hexagonal;
        assert_eq!(ipf_colour(id, h, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        assert_eq!(ipf_colour(id, h, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
        let t = 30f64.to_radians();
        let b = ipf_colour(id, h, [t.cos(), t.sin(), 0.0]);
        assert!(b[0] < 1e-6 && b[1] < 1e-6 && b[2] == 1.0, "{b:?}");
    }

    #[test]
    fn ipf_colour_is_the_same_for_equivalent_orientations() {
        let q = DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.7);
        for sym in [Symmetry::Cubic, Symmetry::Hexagonal] {
            let c0 = ipf_colour([q.x, q.y, q.z, q.w], sym, [0.2, 0.4, 1.0]);
            for g in sym.rotations() {
                let e = q * *g;
                let c = ipf_colour([e.x, e.y, e.z, e.w], sym, [0.2, 0.4, 1.0]);
                for k in 0..3 {
                    assert!((c[k] - c0[k]).abs() < 1e-5, "{sym:?}: {c:?} against {c0:?}");
                }
            }
        }
    }
}

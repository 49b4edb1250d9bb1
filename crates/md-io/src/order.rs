//! Order parameters of lipid tails (and of any bonded chain) against a membrane normal, as
//! membrane papers report them and NMR measures them: the deuterium order parameter S_CD of each
//! carbon along an acyl chain, averaged over the lipids and the frames.
//!
//! For a unit bond vector at angle θ to the normal, P₂ = (3 cos²θ − 1) / 2: 1 along the normal,
//! −1/2 in the membrane plane, 0 on average for random orientations. Three ways to get the
//! carbon's vectors, after the force field:
//!
//! - [`Method::Hydrogens`] (all-atom force fields: CHARMM36, Slipids, Lipid21): each selected
//!   atom's C–H bonds to the hydrogens bonded to it; the carbon's S_CH is their mean (`gorder`'s
//!   atomistic order, MemAnalysis, NMRlipids' `calcOrderParameters`).
//! - [`Method::UnitedAtom`] (GROMOS, Berger: CH₂ groups without hydrogens): `gmx order`'s
//!   construction from the carbon i and its two bonded heavy neighbours i−1, i+1. With z along
//!   i−1 → i+1, x normal to the plane of the three and y = z × x, S_CD = ⅔·S_xx + ⅓·S_yy, where
//!   S_aa is P₂ of axis a against the normal: for equal C–C lengths exactly the mean S_CH of two
//!   hydrogens placed at ideal tetrahedral angles (the tests check it against explicit
//!   hydrogens). Carbons with
//!   other than two heavy neighbours (chain ends, branches) are left out, as `gmx order` leaves
//!   out the first and last atoms of its groups; a double bond's carbons are taken as sp³ (`gmx
//!   order` without `-unsat`).
//! - [`Method::Bonds`] (coarse-grained Martini: the P₂ of each bond between two selected beads,
//!   as Martini's `do-order` script and `gorder`'s coarse-grained order give it).
//!
//! Each carbon (or bond) is grouped with its namesakes by residue name and atom name(s), so a
//! POPC bilayer gives one row per carbon of each chain. Bond vectors are taken to their nearest
//! periodic image, so a lipid split across the box counts as it is. The normal is a Cartesian
//! axis (the box's z for a bilayer in the xy plane); P₂ does not depend on its sign, so both
//! leaflets count alike.
//!
//! ```
//! use texmap_md_io::order::{Method, OrderParameters};
//! use texmap_md_io::{Element, Frame};
//! // A methyl-free CH: carbon 0 with a hydrogen straight up and one lying flat.
//! let mut frame = Frame::new();
//! frame.positions = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.09], [1.09, 0.0, 0.0]];
//! frame.elements = vec![Element::from_symbol("C").unwrap(), Element::from_symbol("H").unwrap(),
//!     Element::from_symbol("H").unwrap()];
//! let selected = [true, false, false];
//! let bonds = [[0, 1], [0, 2]];
//! let mut order = OrderParameters::new(&frame, &selected, &bonds, Method::Hydrogens, 2).unwrap();
//! order.add(&frame.positions, None).unwrap();
//! // P₂ = 1 for the first hydrogen and −1/2 for the second: S_CH = 1/4.
//! assert!((order.mean()[0] - 0.25).abs() < 1e-6);
//! ```

use std::fmt;

use crate::frame::{Frame, UnitCell};
use crate::pbc::NearestImage;
use crate::style::atom_element;

/// Where each carbon's bond vectors come from (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The C–H bonds to bonded hydrogens (all-atom force fields).
    Hydrogens,
    /// `gmx order`'s construction from the two bonded heavy neighbours (united-atom chains).
    UnitedAtom,
    /// Every bond between two selected atoms (coarse-grained beads).
    Bonds,
}

/// One row of the result: the carbons (or bonds) of one residue name and atom name(s).
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The residue name.
    pub residue: String,
    /// The carbon's name, or `A-B` for a bond between atoms named A and B.
    pub name: String,
    /// How many carbons (or bonds) of the system the group holds: one per lipid, usually.
    pub sites: usize,
    /// The vectors per site: the carbon's hydrogens, 2 for the united-atom construction, 1 for
    /// a bond.
    pub vectors: usize,
    /// Which chain of its lipid the carbon (a bond's first atom) is on, from 1: the chains are
    /// the sets of selected atoms joined by bonds among them (hydrogens aside), numbered within
    /// the residue by their first atom (sn-2 before sn-1 in CHARMM's order).
    pub chain: usize,
    /// The carbon's place along its chain, from 1: bonds counted from the chain's end of lowest
    /// atom index (the ester end, as force fields list the atoms).
    pub position: usize,
}

/// A site: its group and the atoms its vectors come from (carbon first).
#[derive(Clone, Debug)]
struct Site {
    group: u32,
    atoms: Vec<u32>,
}

/// Why order parameters could not be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum OrderError {
    /// The normal is not axis 0, 1 or 2.
    Normal(usize),
    /// No selected atom gives a vector; the message says what the method looked for.
    NoSites(Method),
    /// A frame holds another number of atoms than the first.
    AtomCount { expected: usize, found: usize },
    /// A bond vector of zero length or not finite: two atoms on top of each other.
    Degenerate { atom: usize },
}

impl fmt::Display for OrderError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            OrderError::Normal(k) => {
                write!(f, "the normal must be axis 0, 1 or 2 (x, y, z), not {k}")
            }
            OrderError::NoSites(Method::Hydrogens) => write!(
                f,
                "no selected atom has a bonded hydrogen: select the chain carbons (their hydrogens come \
                 from the bonds); a united-atom force field has no hydrogens (use the united-atom method)"
            ),
            OrderError::NoSites(Method::UnitedAtom) => write!(
                f,
                "no selected atom has exactly two bonded heavy atoms (the chain neighbours the \
                 united-atom construction needs)"
            ),
            OrderError::NoSites(Method::Bonds) => {
                write!(f, "no bond joins two selected atoms")
            }
            OrderError::AtomCount { expected, found } => write!(
                f,
                "the frame has {found} atoms, the first had {expected}: every frame must hold the same atoms"
            ),
            OrderError::Degenerate { atom } => write!(
                f,
                "atom {} has a bonded neighbour at the same position (no bond direction)",
                atom + 1
            ),
        }
    }
}

impl std::error::Error for OrderError {}

/// The running order parameters of a trajectory.
#[derive(Clone, Debug)]
pub struct OrderParameters {
    method: Method,
    normal: usize,
    groups: Vec<Group>,
    sites: Vec<Site>,
    /// Per site, the sum over frames of its order parameter.
    sums: Vec<f64>,
    n_atoms: usize,
    frames: usize,
}

fn p2(cos: f64) -> f64 {
    1.5 * cos * cos - 0.5
}

impl OrderParameters {
    /// The sites of `frame`: `selected` marks the carbons (or beads), `bonds` are the system's
    /// bonds (atom index pairs; pairs past the frame are ignored), `normal` the axis (0, 1, 2
    /// for x, y, z). Groups are in the order of their first atom.
    pub fn new(
        frame: &Frame,
        selected: &[bool],
        bonds: &[[u32; 2]],
        method: Method,
        normal: usize,
    ) -> Result<OrderParameters, OrderError> {
        if normal > 2 {
            return Err(OrderError::Normal(normal));
        }
        let n = frame.n_atoms().min(selected.len());
        let (start, adj) = crate::pbc::adjacency(n, bonds);
        let partners = |a: usize| &adj[start[a] as usize..start[a + 1] as usize];
        let hydrogen = |a: usize| atom_element(frame, a).symbol() == "H";
        let label =
            |v: &[crate::Label], i: usize| v.get(i).map(|l| l.to_string()).unwrap_or_default();
        let mut keys: std::collections::HashMap<(String, String), u32> = Default::default();
        let mut groups: Vec<Group> = Vec::new();
        let mut sites = Vec::new();
        let mut add = |residue: String, name: String, atoms: Vec<u32>| {
            let next = groups.len() as u32;
            let g = *keys.entry((residue.clone(), name.clone())).or_insert(next);
            if g == next {
                groups.push(Group {
                    residue,
                    name,
                    sites: 0,
                    vectors: atoms.len() - 1,
                    chain: 0,
                    position: 0,
                });
            }
            groups[g as usize].sites += 1;
            sites.push(Site { group: g, atoms });
        };
        for a in (0..n).filter(|&a| selected[a]) {
            let residue = label(&frame.res_names, a);
            let name = label(&frame.names, a);
            match method {
                Method::Hydrogens => {
                    if hydrogen(a) {
                        continue;
                    }
                    let mut atoms = vec![a as u32];
                    atoms.extend(partners(a).iter().filter(|&&h| hydrogen(h as usize)));
                    if atoms.len() > 1 {
                        atoms[1..].sort_unstable();
                        add(residue, name, atoms);
                    }
                }
                Method::UnitedAtom => {
                    let heavy: Vec<u32> = partners(a)
                        .iter()
                        .copied()
                        .filter(|&b| !hydrogen(b as usize))
                        .collect();
                    if let [p, q] = heavy[..]
                        && !hydrogen(a)
                    {
                        // i−1 before i+1 in atom order, as a chain is listed.
                        let (p, q) = (p.min(q), p.max(q));
                        add(residue, name, vec![a as u32, p, q]);
                    }
                }
                Method::Bonds => {
                    for &b in partners(a) {
                        let b = b as usize;
                        if b > a && selected[b] {
                            let name = format!("{name}-{}", label(&frame.names, b));
                            add(residue.clone(), name, vec![a as u32, b as u32]);
                        }
                    }
                }
            }
        }
        if sites.is_empty() {
            return Err(OrderError::NoSites(method));
        }
        let places = chains(frame, selected, n, &partners, &hydrogen);
        let mut named = vec![false; groups.len()];
        for site in &sites {
            let g = site.group as usize;
            if !named[g] {
                named[g] = true;
                (groups[g].chain, groups[g].position) = places[site.atoms[0] as usize];
            }
        }
        Ok(OrderParameters {
            method,
            normal,
            sums: vec![0.0; sites.len()],
            groups,
            sites,
            n_atoms: frame.n_atoms(),
            frames: 0,
        })
    }

    /// The groups, one per row of the result.
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }

    /// Frames added.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds a frame's `positions` (the first frame's atoms) with its `cell` for the nearest
    /// images; returns this frame's mean per group.
    pub fn add(
        &mut self,
        positions: &[[f32; 3]],
        cell: Option<&UnitCell>,
    ) -> Result<Vec<f64>, OrderError> {
        if positions.len() != self.n_atoms {
            return Err(OrderError::AtomCount {
                expected: self.n_atoms,
                found: positions.len(),
            });
        }
        let image = cell.and_then(NearestImage::new);
        // The bond from `from` to `to` at its nearest image, refused when of no length.
        let bond = |from: u32, to: u32| -> Result<([f64; 3], f64), OrderError> {
            let (p, q) = (positions[from as usize], positions[to as usize]);
            let d = std::array::from_fn(|k| f64::from(q[k]) - f64::from(p[k]));
            let d = image.as_ref().map_or(d, |i| i.apply(d));
            let l = norm(d);
            if l > 0.0 && l.is_finite() {
                Ok((d, l))
            } else {
                Err(OrderError::Degenerate {
                    atom: from as usize,
                })
            }
        };
        let k = self.normal;
        // Every site's value first, so that a refused frame leaves the sums as they were.
        let mut values = Vec::with_capacity(self.sites.len());
        for site in &self.sites {
            let a = site.atoms[0];
            values.push(match self.method {
                Method::Hydrogens | Method::Bonds => {
                    let mut s = 0.0;
                    for &h in &site.atoms[1..] {
                        let (d, l) = bond(a, h)?;
                        s += p2(d[k] / l);
                    }
                    s / (site.atoms.len() - 1) as f64
                }
                Method::UnitedAtom => {
                    // z along C(i−1) → C(i+1) as the atoms lie (gmx order's), x normal to the
                    // three carbons' plane.
                    let ((prev, _), (next, _)) = (bond(a, site.atoms[1])?, bond(a, site.atoms[2])?);
                    let z = sub(next, prev);
                    let x = cross(prev, next);
                    let (lz, lx) = (norm(z), norm(x));
                    if !(lz > 0.0 && lx > 0.0) {
                        // A straight angle: no plane for the hydrogens.
                        return Err(OrderError::Degenerate { atom: a as usize });
                    }
                    let (z, x) = (z.map(|v| v / lz), x.map(|v| v / lx));
                    let y = cross(z, x);
                    2.0 / 3.0 * p2(x[k]) + 1.0 / 3.0 * p2(y[k])
                }
            });
        }
        let mut frame_sum = vec![0.0; self.groups.len()];
        for ((site, sum), s) in self.sites.iter().zip(&mut self.sums).zip(values) {
            *sum += s;
            frame_sum[site.group as usize] += s;
        }
        self.frames += 1;
        Ok(frame_sum
            .iter()
            .zip(&self.groups)
            .map(|(s, g)| s / g.sites as f64)
            .collect())
    }

    /// Each group's order parameter: the mean over its sites and the frames (NaN before a frame).
    pub fn mean(&self) -> Vec<f64> {
        let mut sum = vec![0.0; self.groups.len()];
        for (site, s) in self.sites.iter().zip(&self.sums) {
            sum[site.group as usize] += s;
        }
        sum.iter()
            .zip(&self.groups)
            .map(|(s, g)| s / (g.sites * self.frames) as f64)
            .collect()
    }

    /// Each group's standard error over its sites: the spread of the sites' time averages over
    /// √sites (how the lipids differ, the error bar membrane papers draw); NaN for a group of
    /// one site or before a frame.
    pub fn standard_error(&self) -> Vec<f64> {
        let mean = self.mean();
        let mut squares = vec![0.0; self.groups.len()];
        for (site, s) in self.sites.iter().zip(&self.sums) {
            let g = site.group as usize;
            let d = s / self.frames as f64 - mean[g];
            squares[g] += d * d;
        }
        squares
            .iter()
            .zip(&self.groups)
            .map(|(q, g)| {
                let n = g.sites as f64;
                if g.sites < 2 {
                    f64::NAN
                } else {
                    (q / (n - 1.0)).sqrt() / n.sqrt()
                }
            })
            .collect()
    }
}

/// Each atom's (chain, position) as [`Group::chain`] and [`Group::position`] define them; (0, 0)
/// for atoms not selected.
fn chains<'a>(
    frame: &Frame,
    selected: &[bool],
    n: usize,
    partners: &impl Fn(usize) -> &'a [u32],
    hydrogen: &impl Fn(usize) -> bool,
) -> Vec<(usize, usize)> {
    let inside = |a: usize| a < n && selected[a] && !hydrogen(a);
    let next = |a: usize| {
        partners(a)
            .iter()
            .map(|&b| b as usize)
            .filter(move |&b| inside(b))
    };
    let mut place = vec![(0, 0); frame.n_atoms()];
    let mut component = vec![usize::MAX; frame.n_atoms()];
    // Components in order of their lowest atom, each walked from its lowest-index end.
    let mut lowest = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    for a in (0..n).filter(|&a| inside(a)) {
        if component[a] != usize::MAX {
            continue;
        }
        let id = lowest.len();
        lowest.push(a);
        let mut members = vec![a];
        component[a] = id;
        let mut k = 0;
        while k < members.len() {
            for b in next(members[k]) {
                if component[b] == usize::MAX {
                    component[b] = id;
                    members.push(b);
                }
            }
            k += 1;
        }
        let start = members
            .iter()
            .copied()
            .filter(|&m| next(m).count() <= 1)
            .min()
            .unwrap_or(a);
        let mut depth = std::collections::HashMap::from([(start, 1usize)]);
        queue.push_back(start);
        while let Some(m) = queue.pop_front() {
            let d = depth[&m];
            for b in next(m) {
                depth.entry(b).or_insert_with(|| {
                    queue.push_back(b);
                    d + 1
                });
            }
        }
        for (&m, &d) in &depth {
            place[m].1 = d;
        }
    }
    // Chains numbered within their residue by their lowest atom.
    let ranges = crate::secondary::residue_ranges(frame);
    let residue = |a: usize| ranges.partition_point(|r| r.end <= a);
    let mut rank = vec![0; lowest.len()];
    let mut last = (usize::MAX, 0);
    for (id, &a) in lowest.iter().enumerate() {
        let r = residue(a);
        last = if r == last.0 { (r, last.1 + 1) } else { (r, 1) };
        rank[id] = last.1;
    }
    for a in (0..n).filter(|&a| component[a] != usize::MAX) {
        place[a].0 = rank[component[a]];
    }
    place
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::Element;

    /// Sines and cosines of the tetrahedral half-angle: cos²(τ/2) = 1/3.
    const TET: f64 = 1.910_633_236_249_019; // 109.4712°

    /// A chain of `n` sp³ carbons with ideal tetrahedral angles and the given torsions (180°
    /// trans, ±60° gauche), each with its hydrogens at the ideal tetrahedral positions; names
    /// C1.., H1R/H1S.., residue LIP; bonds listed.
    fn chain(n: usize, torsions: &[f64]) -> (Frame, Vec<[u32; 2]>, Vec<usize>) {
        let (cc, ch) = (1.53, 1.09);
        let mut c: Vec<[f64; 3]> = vec![[0.0, 0.0, 0.0], [cc, 0.0, 0.0]];
        let bend = std::f64::consts::PI - TET;
        c.push(add(c[1], [cc * bend.cos(), cc * bend.sin(), 0.0]));
        for i in 3..n {
            // Place atom i from i−3, i−2, i−1 with bond angle TET and torsion t.
            let t = torsions[(i - 3) % torsions.len()].to_radians();
            let (a, b, d) = (c[i - 3], c[i - 2], c[i - 1]);
            let bc = unit(sub(d, b));
            let nrm = unit(cross(sub(b, a), bc));
            let m = cross(nrm, bc);
            let local = [
                -cc * TET.cos(),
                cc * TET.sin() * t.cos(),
                cc * TET.sin() * t.sin(),
            ];
            c.push(add(
                d,
                std::array::from_fn(|k| local[0] * bc[k] + local[1] * m[k] + local[2] * nrm[k]),
            ));
        }
        let mut frame = Frame::new();
        let mut bonds = Vec::new();
        let mut carbons = Vec::new();
        let el = |s: &str| Element::from_symbol(s).unwrap();
        for i in 0..n {
            carbons.push(frame.positions.len());
            let ci = frame.positions.len() as u32;
            frame.positions.push(c[i].map(|x| x as f32));
            frame.elements.push(el("C"));
            frame
                .names
                .push(crate::Label::new(&format!("C{}", i + 1)).unwrap());
            if i > 0 {
                bonds.push([carbons[i - 1] as u32, ci]);
            }
            // Hydrogens of an inner carbon: in the plane normal to the C–C–C plane through the
            // bisector, at ±τ/2 about the reversed bisector.
            if i > 0 && i + 1 < n {
                let (u, v) = (unit(sub(c[i - 1], c[i])), unit(sub(c[i + 1], c[i])));
                let bis = unit(add(u, v));
                let perp = unit(cross(u, v));
                let half = TET / 2.0;
                for (s, tag) in [(1.0, "R"), (-1.0, "S")] {
                    let h: [f64; 3] = std::array::from_fn(|k| {
                        c[i][k] + ch * (-half.cos() * bis[k] + s * half.sin() * perp[k])
                    });
                    bonds.push([ci, frame.positions.len() as u32]);
                    frame.positions.push(h.map(|x| x as f32));
                    frame.elements.push(el("H"));
                    frame
                        .names
                        .push(crate::Label::new(&format!("H{}{tag}", i + 1)).unwrap());
                }
            }
        }
        let m = frame.positions.len();
        frame.res_names = vec![crate::Label::new("LIP").unwrap(); m];
        (frame, bonds, carbons)
    }

    fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }

    fn unit(a: [f64; 3]) -> [f64; 3] {
        let l = norm(a);
        a.map(|x| x / l)
    }

    fn rotate(frame: &mut Frame, axis: [f64; 3], angle: f64) {
        let r = glam::DQuat::from_axis_angle(glam::DVec3::from_array(unit(axis)), angle);
        for p in &mut frame.positions {
            let v = r * glam::DVec3::new(p[0].into(), p[1].into(), p[2].into());
            *p = v.to_array().map(|x| x as f32);
        }
    }

    #[test]
    fn explicit_hydrogens_and_the_united_atom_construction_agree() {
        // A chain with gauche defects in arbitrary orientations: the mean S_CH of ideal
        // hydrogens is the united-atom construction's S_CD, carbon by carbon.
        let (mut frame, bonds, carbons) = chain(12, &[180.0, 60.0, 180.0, -60.0, 180.0]);
        let mut selected = vec![false; frame.n_atoms()];
        for &c in &carbons {
            selected[c] = true;
        }
        for (i, (axis, angle)) in [
            ([1.0, 2.0, 0.5], 0.3),
            ([0.0, 1.0, 0.0], 1.2),
            ([1.0, -1.0, 2.0], 2.5),
        ]
        .into_iter()
        .enumerate()
        {
            rotate(&mut frame, axis, angle);
            let mut h =
                OrderParameters::new(&frame, &selected, &bonds, Method::Hydrogens, i).unwrap();
            let mut ua =
                OrderParameters::new(&frame, &selected, &bonds, Method::UnitedAtom, i).unwrap();
            let sh = h.add(&frame.positions, None).unwrap();
            let su = ua.add(&frame.positions, None).unwrap();
            // Hydrogens: the 10 inner carbons; united atom: the same 10.
            assert_eq!(h.groups().len(), 10);
            assert_eq!(ua.groups().len(), 10);
            // C2 is the second carbon of the one chain, C11 the eleventh.
            let place = |g: &Group| (g.name.clone(), g.chain, g.position);
            assert_eq!(place(&h.groups()[0]), ("C2".into(), 1, 2));
            assert_eq!(place(&ua.groups()[9]), ("C11".into(), 1, 11));
            for ((a, b), (ga, gb)) in sh.iter().zip(&su).zip(h.groups().iter().zip(ua.groups())) {
                assert_eq!(ga.name, gb.name);
                assert!((a - b).abs() < 1e-5, "{}: {a} vs {b}", ga.name);
            }
            // The values differ from carbon to carbon (the test is not of a constant).
            assert!(sh.iter().any(|s| (s - sh[0]).abs() > 0.05), "{sh:?}");
        }
    }

    #[test]
    fn an_all_trans_chain_along_the_normal_gives_minus_one_half_and_tilted_p2_of_the_tilt() {
        let (mut frame, bonds, carbons) = chain(16, &[180.0]);
        // The all-trans chain's axis: first carbon to the last, in the xy plane here; turn it
        // onto z.
        let (a, b) = (frame.positions[carbons[0]], frame.positions[carbons[14]]);
        let axis = unit(std::array::from_fn(|k| f64::from(b[k] - a[k])));
        let to_z = glam::DQuat::from_rotation_arc(glam::DVec3::from_array(axis), glam::DVec3::Z);
        for p in &mut frame.positions {
            let v = to_z * glam::DVec3::new(p[0].into(), p[1].into(), p[2].into());
            *p = v.to_array().map(|x| x as f32);
        }
        let mut selected = vec![false; frame.n_atoms()];
        for &c in &carbons {
            selected[c] = true;
        }
        let mut h = OrderParameters::new(&frame, &selected, &bonds, Method::Hydrogens, 2).unwrap();
        let s = h.add(&frame.positions, None).unwrap();
        // Every C–H bond at right angles to the chain axis: P₂ = −1/2.
        assert!(s.iter().all(|s| (s + 0.5).abs() < 1e-4), "{s:?}");
        // Spun about its own axis and tilted by β: every C–H bond is at right angles to the
        // axis, so each carbon's mean over the spin is −P₂(cos β)/2; each C–C bond is at the
        // trans chain's (180° − τ)/2 to the axis, where P₂ = 1/2, so each bond's mean is
        // P₂(cos β)/2 (the addition theorem of the Legendre polynomials). 360 equal steps
        // average cos² of the spin exactly.
        let beta: f64 = 0.6;
        let mut spun =
            OrderParameters::new(&frame, &selected, &bonds, Method::Hydrogens, 2).unwrap();
        let mut cc = OrderParameters::new(&frame, &selected, &bonds, Method::Bonds, 2).unwrap();
        for step in 0..360 {
            let mut f = frame.clone();
            rotate(&mut f, [0.0, 0.0, 1.0], f64::from(step).to_radians());
            rotate(&mut f, [1.0, 0.0, 0.0], beta);
            spun.add(&f.positions, None).unwrap();
            cc.add(&f.positions, None).unwrap();
        }
        let want = -0.5 * p2(beta.cos());
        assert!(
            spun.mean().iter().all(|s| (s - want).abs() < 1e-4),
            "{:?} vs {want}",
            spun.mean()
        );
        assert_eq!(cc.groups()[0].name, "C1-C2");
        assert_eq!(cc.groups().len(), 15);
        let want = 0.5 * p2(beta.cos());
        assert!(
            cc.mean().iter().all(|s| (s - want).abs() < 1e-4),
            "{:?} vs {want}",
            cc.mean()
        );
        assert_eq!(spun.frames(), 360);
    }

    #[test]
    fn bonds_across_the_box_use_the_nearest_image_and_bad_input_is_refused() {
        // Two beads bonded across the z faces of a 10 Å box: 1 Å apart along z, P₂ = 1.
        let mut frame = Frame::new();
        frame.positions = vec![[5.0, 5.0, 9.5], [5.0, 5.0, 0.5]];
        frame.names = vec![
            crate::Label::new("PO4").unwrap(),
            crate::Label::new("GL1").unwrap(),
        ];
        frame.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
        let mut o =
            OrderParameters::new(&frame, &[true, true], &[[0, 1]], Method::Bonds, 2).unwrap();
        assert_eq!(
            o.add(&frame.positions, frame.cell.as_ref()).unwrap(),
            vec![1.0]
        );
        // Lying in the plane: −1/2.
        let flat = [[5.0, 5.0, 5.0], [6.0, 5.0, 5.0]];
        assert_eq!(o.add(&flat, None).unwrap(), vec![-0.5]);
        assert_eq!(o.mean(), vec![0.25]);
        assert!(o.standard_error()[0].is_nan());
        assert_eq!(
            o.add(&[[0.0; 3]], None),
            Err(OrderError::AtomCount {
                expected: 2,
                found: 1
            })
        );
        assert_eq!(
            o.add(&[[1.0; 3], [1.0; 3]], None),
            Err(OrderError::Degenerate { atom: 0 })
        );
        // A refused frame counts for nothing.
        assert_eq!((o.mean(), o.frames()), (vec![0.25], 2));
        assert_eq!(
            OrderParameters::new(&frame, &[true, false], &[[0, 1]], Method::Bonds, 2).unwrap_err(),
            OrderError::NoSites(Method::Bonds)
        );
        let e = OrderParameters::new(&frame, &[true, true], &[[0, 1]], Method::Hydrogens, 2)
            .unwrap_err();
        assert!(e.to_string().contains("united-atom"), "{e}");
        assert_eq!(
            OrderParameters::new(&frame, &[true, true], &[[0, 1]], Method::Bonds, 3).unwrap_err(),
            OrderError::Normal(3)
        );
    }
}

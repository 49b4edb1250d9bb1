//! Secondary structure of protein residues from their backbone coordinates: DSSP's
//! hydrogen-bond definition (Kabsch & Sander 1983) reduced to three classes, helix, strand and
//! coil, as MDAnalysis's `DSSP` (after pydssp) assigns them.
//!
//! A residue takes part when it has the four backbone atoms `N`, `CA`, `C` and `O` (the
//! C-terminal oxygen may be `O1` or `OT1`, MDAnalysis's spellings); the first atom of each name
//! is used, so alternate locations beyond the first are ignored. Residues are consecutive atoms
//! with the same residue number, name, chain and segment. Such residues are taken in file order
//! as one sequence, which breaks where the chain or segment changes or where the peptide bond
//! `C(i)-N(i+1)` is longer than [`MAX_PEPTIDE_BOND`] (a missing loop), as DSSP breaks it.
//!
//! 1. Each residue but the first of a piece, and but a proline, gets its amide hydrogen where
//!    MDAnalysis and pydssp place it: 1.01 Å from N along the bisector of C(i-1)->N and CA->N.
//!    Hydrogens in the file are not used (MDAnalysis's default `guess_hydrogens=True`).
//! 2. The electrostatic energy of every C=O(i) ... H-N(j) pair with N-O within
//!    [`HBOND_SEARCH`] Å is `E = 0.084 * 332 * (1/r_ON + 1/r_CH - 1/r_OH - 1/r_CN)` kcal/mol; a
//!    hydrogen bond is `E < -0.5`. Pairs with `j - i` in {0, 1, 2} are not considered.
//! 3. An n-turn at i is a bond C=O(i) -> N-H(i+n), n = 3, 4, 5; two consecutive n-turns at
//!    i-1 and i make residues i..i+n-1 helical. A 3- or 5-turn helix starting where a 4-turn
//!    helix holds the residue or the next one is dropped (α first). Every helix is `Helix`.
//! 4. A bridge between i and j is parallel, `[Hb(i-1, j) and Hb(j, i+1)]` or
//!    `[Hb(j-1, i) and Hb(i, j+1)]`, or antiparallel, `[Hb(i, j) and Hb(j, i)]` or
//!    `[Hb(i-1, j+1) and Hb(j-1, i+1)]`; both residues of every bridge are `Strand` (isolated
//!    bridges included, as in MDAnalysis's C3 reduction), unless they are helical.
//!
//! Where a piece breaks, no turn or bridge spans the break (DSSP's rule); MDAnalysis ignores
//! breaks, so the two differ only next to a missing loop. Distances are plain, without periodic
//! images: a protein split across a periodic box should be made whole first (`--pbc unwrap`).
//! The hydrogen-bond search uses a cell grid, so the cost is linear in the residues; a frame
//! whose residues are stacked denser than any protein's ([`MAX_CANDIDATES_PER_RESIDUE`]) is
//! all coil rather than a quadratic search.
//!
//! ```
//! use texmap_md_io::{Frame, Label, secondary::{self, Structure}};
//! let mut f = Frame::new();
//! // Two residues: too short for any structure, but both have a backbone.
//! for (k, name) in ["N", "CA", "C", "O", "N", "CA", "C", "O"].iter().enumerate() {
//!     f.names.push(Label::new(name).unwrap());
//!     f.res_names.push(Label::new("ALA").unwrap());
//!     f.res_ids.push(1 + k as i64 / 4);
//!     f.positions.push([k as f32 * 1.3, 0.0, 0.0]);
//! }
//! let ss = secondary::assign(&f);
//! assert_eq!(ss.residues().len(), 2);
//! assert_eq!(ss.codes(), "--");
//! assert_eq!(ss.per_atom(f.n_atoms())[5], Some(Structure::Coil));
//! ```

use std::ops::Range;

use crate::frame::{Frame, Label};

/// Longest `C(i)-N(i+1)` distance (Å) that joins two residues: DSSP's 2.5 Å.
pub const MAX_PEPTIDE_BOND: f32 = 2.5;
/// N-O distance (Å) within which a hydrogen bond is evaluated (MDAnalysis's 5 Å).
pub const HBOND_SEARCH: f32 = 5.0;
/// Energy (kcal/mol) below which a C=O ... H-N pair is a hydrogen bond.
pub const HBOND_ENERGY: f64 = -0.5;
/// Average oxygens per amide in the cells searched above which a frame is taken as degenerate
/// (residues stacked on each other, e.g. every atom at the origin) and every residue is coil:
/// proteins give a few dozen, and the search would otherwise cost time quadratic in the
/// residues.
pub const MAX_CANDIDATES_PER_RESIDUE: usize = 400;

/// The three-class secondary structure of a residue.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Structure {
    /// Neither helix nor strand (loops, turns, bends, termini).
    Coil,
    /// α, 3₁₀ or π helix (DSSP H, G, I).
    Helix,
    /// β strand or isolated β bridge (DSSP E, B).
    Strand,
}

impl Structure {
    /// DSSP's one-letter code in MDAnalysis's C3 alphabet: `-`, `H`, `E`.
    pub fn code(self) -> char {
        match self {
            Structure::Coil => '-',
            Structure::Helix => 'H',
            Structure::Strand => 'E',
        }
    }

    /// A lower-case name: `coil`, `helix`, `strand`.
    pub fn name(self) -> &'static str {
        match self {
            Structure::Coil => "coil",
            Structure::Helix => "helix",
            Structure::Strand => "strand",
        }
    }
}

/// A residue with a complete backbone: its atoms and the indices of N, CA, C, O.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BackboneResidue {
    /// The residue's atoms (consecutive in the frame).
    pub atoms: Range<usize>,
    /// Atom indices of N, CA, C and O.
    pub backbone: [usize; 4],
    /// The residue number as the file writes it.
    pub res_id: i64,
    /// Whether the sequence breaks before this residue (first residue, new chain or segment,
    /// or a peptide bond longer than [`MAX_PEPTIDE_BOND`]).
    pub starts_piece: bool,
}

/// The assignment of one frame (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SecondaryStructure {
    residues: Vec<BackboneResidue>,
    classes: Vec<Structure>,
    hbonds: usize,
}

impl SecondaryStructure {
    /// The residues with a backbone, in file order.
    pub fn residues(&self) -> &[BackboneResidue] {
        &self.residues
    }

    /// One class per residue of [`Self::residues`].
    pub fn classes(&self) -> &[Structure] {
        &self.classes
    }

    /// The classes as one string of [`Structure::code`]s (MDAnalysis's `''.join(dssp)`).
    pub fn codes(&self) -> String {
        self.classes.iter().map(|c| c.code()).collect()
    }

    /// Backbone hydrogen bonds found.
    pub fn hbonds(&self) -> usize {
        self.hbonds
    }

    /// The class of every atom of a frame of `n_atoms`: each atom of a residue with a backbone
    /// takes its residue's class; other atoms `None`.
    pub fn per_atom(&self, n_atoms: usize) -> Vec<Option<Structure>> {
        let mut out = vec![None; n_atoms];
        for (r, &c) in self.residues.iter().zip(&self.classes) {
            let end = r.atoms.end.min(n_atoms);
            for o in &mut out[r.atoms.start.min(end)..end] {
                *o = Some(c);
            }
        }
        out
    }

    /// How many residues have each class: `[coil, helix, strand]`.
    pub fn counts(&self) -> [usize; 3] {
        let mut n = [0; 3];
        for c in &self.classes {
            n[*c as usize] += 1;
        }
        n
    }
}

/// Consecutive atoms with the same residue number, name, chain and segment; empty when the frame
/// has no residue numbers or names.
pub fn residue_ranges(frame: &Frame) -> Vec<Range<usize>> {
    let n = frame.n_atoms();
    if frame.res_ids.len() != n || frame.res_names.len() != n || n == 0 {
        return Vec::new();
    }
    let same = |a: usize, b: usize| {
        frame.res_ids[a] == frame.res_ids[b]
            && frame.res_names[a] == frame.res_names[b]
            && label(&frame.chains, a) == label(&frame.chains, b)
            && label(&frame.segments, a) == label(&frame.segments, b)
    };
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..n {
        if !same(i - 1, i) {
            out.push(start..i);
            start = i;
        }
    }
    out.push(start..n);
    out
}

/// The label at `i` of a column that may be absent (empty).
fn label(v: &[Label], i: usize) -> Option<&[u8]> {
    v.get(i).map(Label::as_bytes)
}

fn v3(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    a.map(|x| x / l)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(sub(a, b))
}

/// The indices of the first `N`, `CA`, `C` and `O` (or `O1`, `OT1`) among `atoms` of `frame`
/// (which has names), `usize::MAX` for each missing.
pub(crate) fn backbone_of(frame: &Frame, atoms: Range<usize>) -> [usize; 4] {
    let mut bb = [usize::MAX; 4];
    for i in atoms {
        let k = match frame.names[i].as_str() {
            "N" => 0,
            "CA" => 1,
            "C" => 2,
            "O" | "O1" | "OT1" => 3,
            _ => continue,
        };
        if bb[k] == usize::MAX {
            bb[k] = i;
        }
    }
    bb
}

/// The residues of `frame` with a complete backbone, with their breaks.
fn backbone_residues(frame: &Frame) -> Vec<BackboneResidue> {
    let mut out: Vec<BackboneResidue> = Vec::new();
    if frame.names.len() != frame.n_atoms() {
        return out;
    }
    for atoms in residue_ranges(frame) {
        let bb = backbone_of(frame, atoms.clone());
        if bb.contains(&usize::MAX)
            || bb
                .iter()
                .any(|&i| !v3(frame.positions[i]).iter().all(|x| x.is_finite()))
        {
            continue;
        }
        let starts_piece = match out.last() {
            None => true,
            Some(prev) => {
                let (a, b) = (prev.atoms.start, atoms.start);
                label(&frame.chains, a) != label(&frame.chains, b)
                    || label(&frame.segments, a) != label(&frame.segments, b)
                    || dist(
                        v3(frame.positions[prev.backbone[2]]),
                        v3(frame.positions[bb[0]]),
                    ) > MAX_PEPTIDE_BOND as f64
            }
        };
        out.push(BackboneResidue {
            res_id: frame.res_ids[atoms.start],
            atoms,
            backbone: bb,
            starts_piece,
        });
    }
    out
}

/// Hydrogen bonds as a lookup: `donors[j]` lists the acceptors `i` with C=O(i) -> H-N(j).
struct HBonds {
    donors: Vec<Vec<u32>>,
}

impl HBonds {
    /// Whether C=O(`i`) accepts from N-H(`j`); false for indices out of range.
    fn has(&self, i: isize, j: isize) -> bool {
        if i < 0 || j < 0 {
            return false;
        }
        self.donors
            .get(j as usize)
            .is_some_and(|l| l.contains(&(i as u32)))
    }
}

/// The backbone hydrogen bonds of `res` (see the module docs, steps 1-2); `None` when the
/// residues are packed denser than any protein ([`MAX_CANDIDATES_PER_RESIDUE`]).
fn hbonds(frame: &Frame, res: &[BackboneResidue]) -> Option<HBonds> {
    let n = res.len();
    let pos = |r: usize, k: usize| v3(frame.positions[res[r].backbone[k]]);
    // Amide hydrogens: none for the first residue of a piece or a proline.
    let h: Vec<Option<[f64; 3]>> = (0..n)
        .map(|r| {
            let pro = frame.res_names[res[r].atoms.start].as_str() == "PRO";
            if res[r].starts_piece || pro {
                return None;
            }
            let nn = pos(r, 0);
            let b = unit(sub(nn, pos(r - 1, 2)));
            let c = unit(sub(nn, pos(r, 1)));
            let d = unit([b[0] + c[0], b[1] + c[1], b[2] + c[2]]);
            let hp = [
                nn[0] + 1.01 * d[0],
                nn[1] + 1.01 * d[1],
                nn[2] + 1.01 * d[2],
            ];
            hp.iter().all(|x| x.is_finite()).then_some(hp)
        })
        .collect();
    // A cell grid of the oxygens, cells of HBOND_SEARCH.
    let cell = HBOND_SEARCH as f64;
    let mut lo = [f64::INFINITY; 3];
    for r in 0..n {
        let o = pos(r, 3);
        for k in 0..3 {
            lo[k] = lo[k].min(o[k]);
        }
    }
    let ckey =
        |p: [f64; 3]| -> [i64; 3] { [0, 1, 2].map(|k| ((p[k] - lo[k]) / cell).floor() as i64) };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<u32>> = std::collections::HashMap::new();
    for r in 0..n {
        grid.entry(ckey(pos(r, 3))).or_default().push(r as u32);
    }
    // Real proteins put a few dozen oxygens in the 27 cells around an amide; a frame that puts
    // hundreds (every atom at the origin, a placeholder) would cost quadratic time: refused.
    let candidates: usize = (0..n)
        .filter(|&j| h[j].is_some())
        .map(|j| {
            let c = ckey(pos(j, 0));
            let mut k = 0;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        k += grid
                            .get(&[c[0] + dx, c[1] + dy, c[2] + dz])
                            .map_or(0, Vec::len);
                    }
                }
            }
            k
        })
        .sum();
    if candidates > MAX_CANDIDATES_PER_RESIDUE * n {
        return None;
    }
    let mut donors = vec![Vec::new(); n];
    let cut2 = cell * cell;
    for j in 0..n {
        let Some(hj) = h[j] else { continue };
        let nj = pos(j, 0);
        let c = ckey(nj);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &i in list {
                        let i = i as usize;
                        // j - i in {0, 1, 2} is never a hydrogen bond here.
                        if (0..=2).contains(&(j as isize - i as isize)) {
                            continue;
                        }
                        let oi = pos(i, 3);
                        let d_on = sub(oi, nj);
                        let r2 = d_on[0] * d_on[0] + d_on[1] * d_on[1] + d_on[2] * d_on[2];
                        if r2 > cut2 {
                            continue;
                        }
                        let ci = pos(i, 2);
                        let e = 0.084
                            * 332.0
                            * (1.0 / r2.sqrt() + 1.0 / dist(ci, hj)
                                - 1.0 / dist(oi, hj)
                                - 1.0 / dist(ci, nj));
                        if e < HBOND_ENERGY {
                            donors[j].push(i as u32);
                        }
                    }
                }
            }
        }
    }
    Some(HBonds { donors })
}

/// The secondary structure of `frame`'s residues (see the module docs). A frame without
/// residue names and numbers, or without protein backbones, gives no residues.
pub fn assign(frame: &Frame) -> SecondaryStructure {
    let res = backbone_residues(frame);
    let n = res.len();
    if n == 0 {
        return SecondaryStructure::default();
    }
    let Some(hb) = hbonds(frame, &res) else {
        return SecondaryStructure {
            classes: vec![Structure::Coil; n],
            residues: res,
            hbonds: 0,
        };
    };
    // piece[r]: index of the piece residue r belongs to, so "no break in a..=b" is
    // piece[a] == piece[b].
    let mut piece = vec![0usize; n];
    for r in 1..n {
        piece[r] = piece[r - 1] + res[r].starts_piece as usize;
    }
    let unbroken =
        |a: isize, b: isize| a >= 0 && (b as usize) < n && piece[a as usize] == piece[b as usize];
    let turn = |t: usize, i: usize| {
        unbroken(i as isize, (i + t) as isize) && hb.has(i as isize, (i + t) as isize)
    };
    // Minimal helices: start[t][i] when t-turns at i-1 and i.
    let starts = |t: usize| -> Vec<bool> {
        (0..n)
            .map(|i| i >= 1 && i + t < n && turn(t, i - 1) && turn(t, i))
            .collect()
    };
    let spread = |s: &[bool], t: usize| -> Vec<bool> {
        (0..n).map(|i| (0..t).any(|k| i >= k && s[i - k])).collect()
    };
    let h4 = starts(4);
    let helix4 = spread(&h4, 4);
    let alpha_first = |s: Vec<bool>| -> Vec<bool> {
        s.iter()
            .enumerate()
            .map(|(i, &v)| v && !helix4[i] && !(i + 1 < n && helix4[i + 1]))
            .collect()
    };
    let helix3 = spread(&alpha_first(starts(3)), 3);
    let helix5 = spread(&alpha_first(starts(5)), 5);
    let mut strand = vec![false; n];
    let bridge = |i: isize, j: isize| -> bool {
        if !(unbroken(i - 1, i + 1) && unbroken(j - 1, j + 1)) {
            return false;
        }
        (hb.has(i - 1, j) && hb.has(j, i + 1))
            || (hb.has(j - 1, i) && hb.has(i, j + 1))
            || (hb.has(i, j) && hb.has(j, i))
            || (hb.has(i - 1, j + 1) && hb.has(j - 1, i + 1))
    };
    let mut nbonds = 0;
    for (d, acc) in hb.donors.iter().enumerate() {
        nbonds += acc.len();
        for &a in acc {
            let (a, d) = (a as isize, d as isize);
            // Every bridge (i, j) uses some bond in one of these roles.
            for (i, j) in [(a + 1, d), (d - 1, a), (a, d), (a + 1, d - 1)] {
                if bridge(i, j) {
                    strand[i as usize] = true;
                    strand[j as usize] = true;
                }
            }
        }
    }
    let classes = (0..n)
        .map(|i| {
            if helix3[i] || helix4[i] || helix5[i] {
                Structure::Helix
            } else if strand[i] {
                Structure::Strand
            } else {
                Structure::Coil
            }
        })
        .collect();
    SecondaryStructure {
        residues: res,
        classes,
        hbonds: nbonds,
    }
}

//! Atom selections in the language VMD and MDAnalysis users type, so that the protein is not
//! hidden inside its water: `not resname SOL`, `name CA`, `element O and resid 1 to 20`,
//! `protein and not name H*`, `within 5 of resname LIG`.
//!
//! # The language
//! ```text
//! expr     := term ("or" term)*
//! term     := factor ("and" factor)*
//! factor   := "not" factor | "(" expr ")" | atom
//! atom     := "all" | "none" | "protein" | "nucleic" | "backbone" | "water"
//!           | "nucleicbackbone" | "nucleicbase" | "nucleicsugar"
//!           | "helix" | "sheet" | "betasheet" | "beta_sheet" | "coil"  -- VMD: structure
//!           | "cna" TYPE+          -- crystal structure: fcc hcp bcc ico other (OVITO's a-CNA)
//!           | "diamond" TYPE+      -- diamond structure: cubic hexagonal cubic-1st cubic-2nd
//!                                     hexagonal-1st hexagonal-2nd other (OVITO's)
//!           | ("name" | "type" | "resname" | "element") WORD+      -- any of the words
//!           | ("chain" | "chainID" | "segid" | "segname") WORD+
//!           | ("index" | "serial" | "bynum" | "id" | "resid" | "resindex" | "fragment") RANGE+
//!           | ("mass" | "charge") FRANGE+                          -- MDAnalysis: mass 10 to 20
//!           | "group" (WORD | N)                                   -- an index group (.ndx)
//!           | "bonded" expr                                        -- atoms bonded to expr's
//!           | "within" NUMBER "of" expr                            -- VMD: includes the expr
//!           | "around" NUMBER expr                                 -- MDAnalysis: excludes it
//!           | "sphzone" R expr | "sphlayer" R1 R2 expr              -- about expr's centre
//!           | "point" X Y Z R                                       -- about a point
//!           | "cyzone" R ZMAX ZMIN expr | "cylayer" R1 R2 ZMAX ZMIN expr  -- cylinders along z
//!           | "isolayer" R1 R2 expr                                 -- R1 < nearest distance <= R2
//!           | "byres" expr                                         -- whole residues
//!           | "same" FIELD "as" expr  -- FIELD: residue fragment resname resid name type element
//!                                        chain segid
//!           | "prop" ["abs"] NAME OP NUMBER                        -- MDAnalysis: prop z > 10
//!           | ("beta" | "occupancy" | "charge") OP NUMBER          -- VMD: beta > 50
//! RANGE    := N | N "to" M | N:M | N-M                              -- inclusive
//! FRANGE   := V | A "to" B | A:B | A-B         -- inclusive; V alone as numpy's isclose
//! OP       := "<" | "<=" | ">" | ">=" | "==" | "!="                  -- spaces optional
//! ```
//! Keywords are case-insensitive; a word in double quotes is a word even when it looks like a
//! keyword or holds parentheses (`group "Near ions"`); words are compared exactly (atom names are case-sensitive in
//! PDB), except `element`, which takes a chemical symbol in any case. A word may hold the glob
//! characters `*` (any run) and `?` (one character): `name H*`. `index` counts atoms from 0 in
//! file order; `serial` and `bynum` from 1 (`bynum` is MDAnalysis's name); `id` is the atom id the
//! file wrote. `protein` is a residue name among the amino acids of [`PROTEIN_RESIDUES`];
//! `backbone` is `protein and name N CA C O`; `nucleic` a residue name in [`NUCLEIC_RESIDUES`];
//! `water` a residue name in [`WATER_RESIDUES`].
//! `helix`, `sheet` (also `betasheet`, `beta_sheet`) and `coil` are VMD's secondary-structure
//! keywords: the atoms of residues that [`crate::secondary::assign`] finds helical, in a strand or
//! bridge, or neither (coil is only residues with a protein backbone: water is not coil). The
//! structure is assigned from the frame being selected, so it follows a trajectory.
//! `cna` selects by the crystal structure type [`crate::cna::classify`] gives each atom, as
//! OVITO's adaptive common neighbour analysis: `not cna fcc` hides the perfect FCC crystal and
//! leaves dislocations, stacking faults (`cna hcp`), grain boundaries and surfaces. `diamond`
//! selects by [`crate::cna::classify_diamond`]'s type, as OVITO's Identify diamond structure:
//! `not diamond cubic` leaves a silicon crystal's defects and surfaces.
//! `chain` (VMD) and `chainID` (MDAnalysis) match the chain identifier (PDB column 22, mmCIF
//! `auth_asym_id`); `segid` (MDAnalysis) and `segname` (VMD) the segment (PDB columns 73-76,
//! PSF). A blank chain or segment is matched by no word.
//! `prop` compares a coordinate (`x`, `y`, `z`) or a per-atom property ([`Frame::property`]:
//! `bfactor`, also spelt `tempfactor` (MDAnalysis) or `beta` (VMD), `occupancy`, a topology's
//! `charge`, a LAMMPS column such as `c_pe`) with a number, its absolute value with `abs`; the
//! number may come first (`prop 10 < z`); `==` is `|a - b| <= 1e-8 + 1e-5 |b|` (numpy's
//! `isclose`, as MDAnalysis). Comparisons are made in f32, the values' precision, as numpy makes
//! MDAnalysis's (`prop x == 3.278` holds for the x read as 3.278). An atom whose value is NaN
//! matches only `!=`.
//! `nucleicbackbone`, `nucleicbase` and `nucleicsugar` are MDAnalysis's: the atoms of a
//! `nucleic` residue named P C5' C3' O3' O5', the base's ring atoms and substituents (N9 N7 C8
//! C5 C4 N3 C2 N1 C6 O6 N2 N6 O2 N4 O4 C5M), and C1' C2' C3' C4' O4'.
//! `mass` takes [`crate::atom_mass`] (the file's masses, else the element's) and `charge` the
//! `charge` property, as MDAnalysis's float ranges (`charge -1 to 0`, `mass 30:40`); `charge`
//! followed by a comparison is VMD's form below.
//! `group NAME` picks an index group ([`crate::ndx`], a GROMACS `.ndx` file) given to
//! [`Selection::parse_with`]: by name as GROMACS resolves it (exactly, in any case, by a unique
//! prefix) or by its number from 0; a group naming an atom past the frame's is an error.
//! `bonded SEL` picks the atoms bonded to SEL's atoms (SEL's own atoms only where bonded to
//! one another), MDAnalysis's. `fragment N` (VMD) picks the Nth bonded fragment — the atoms the
//! frame's bonds join, numbered from 0 by their lowest atom, an atom without bonds its own —
//! and `same fragment as SEL` (both programs) every fragment SEL touches. Without bonds both
//! see single atoms, and `bonded` picks nothing, as in MDAnalysis.
//! `resindex` counts residues from 0 in file order (MDAnalysis's).
//! The geometric keywords are MDAnalysis's, with its periodic images: `sphzone R SEL` picks
//! the atoms within R of SEL's centre of geometry, `sphlayer R1 R2 SEL` those farther than R1
//! and within R2, `point X Y Z R` those within R of a point (nearest images when the frame has
//! a cell); `cyzone R ZMAX ZMIN SEL` those less than R from the z axis through SEL's centre
//! and between ZMIN and ZMAX above it (strictly), `cylayer R1 R2 ZMAX ZMIN SEL` a tube, with
//! displacements reduced as MDAnalysis reduces them (the c, b, a edges in turn); a cylinder
//! wider or taller than the cell is an error, as there. `isolayer R1 R2 SEL` picks the atoms
//! outside SEL whose nearest SEL atom is farther than R1 and within R2 (a solvation shell).
//! A centre of no atoms selects nothing.
//! `within`, `around`, `byres`, `same ... as`, `bonded` and the geometric keywords take the rest of the expression (up to a
//! closing parenthesis) as MDAnalysis does: `around 4 resname NA and resid 1:15` is
//! `around 4 (resname NA and resid 1:15)`; parenthesise to end them sooner. `byres` and
//! `same residue as` select whole residues (consecutive atoms of one residue number, name,
//! chain and segment); `same resname as around 3 resname NA` every atom whose residue name one
//! of the picked atoms has.
//! `within`/`around` reach through the periodic box when the frame has one (MDAnalysis's default
//! `periodic=True`; a water by the far face is next to an ion by the near one), else use plain
//! distances; both through a cell grid, so they cost time linear in the atoms.
//!
//! A selection is parsed once ([`Selection::parse`]) and evaluated per frame
//! ([`Selection::evaluate`]). A parse error points at the column of the bad token; evaluating a
//! keyword whose column the frame lacks (`resname` on an XYZ frame) is an error that says so,
//! never an empty selection.

use std::fmt;

use crate::elements::Element;
use crate::frame::{Frame, Label};
use crate::ndx::{FindError, IndexGroups};
use crate::secondary::Structure;

/// What one evaluation computes at most once, however many keywords need it.
#[derive(Default)]
struct Cache {
    /// Secondary structure per atom (`helix`, `sheet`, `coil`).
    structure: std::cell::OnceCell<Vec<Option<Structure>>>,
    /// Crystal structure type per atom (`cna`).
    cna: std::cell::OnceCell<Vec<crate::cna::StructureType>>,
    /// Diamond structure type per atom (`diamond`).
    diamond: std::cell::OnceCell<Vec<crate::cna::DiamondType>>,
    /// Bonded fragment per atom, numbered by their lowest atom (`fragment`).
    fragments: std::cell::OnceCell<Vec<u32>>,
}

/// Each atom's bonded fragment: the parts the frame's bonds join (an atom without bonds is a
/// fragment of its own), numbered from 0 in the order of their lowest atom, as MDAnalysis's
/// `fragindices` and VMD's `fragment` number them.
pub(crate) fn fragments(frame: &Frame) -> Vec<u32> {
    let n = frame.n_atoms();
    let mut parts = crate::components::UnionFind::new(n);
    for &[a, b] in &frame.bonds {
        if (a as usize) < n && (b as usize) < n {
            parts.join(a as usize, b as usize);
        }
    }
    let mut number = vec![u32::MAX; n];
    let mut next = 0;
    (0..n)
        .map(|i| {
            let r = parts.root(i);
            if number[r] == u32::MAX {
                number[r] = next;
                next += 1;
            }
            number[r]
        })
        .collect()
}

/// Each atom's residue as a 0-based position among [`crate::secondary::residue_ranges`].
fn residue_indices(frame: &Frame) -> Vec<i64> {
    let mut out = vec![0; frame.n_atoms()];
    for (k, r) in crate::secondary::residue_ranges(frame)
        .into_iter()
        .enumerate()
    {
        out[r].fill(k as i64);
    }
    out
}

/// Residue names `protein` matches: MDAnalysis 2.11's, the 20 amino acids with their
/// protonation and terminal variants in the AMBER (HID, CYX, NALA, CALA), CHARMM (HSD, HSE) and
/// GROMOS/OPLS spellings of GROMACS topologies (LYSH, HISB, CYSH, ASPH), the ACE and NME caps,
/// selenomethionine and a few modified residues (HYP, ORN, DAB).
pub const PROTEIN_RESIDUES: &[&str] = &[
    "ALA", "ARG", "ASN", "ASP", "CYS", "GLN", "GLU", "GLY", "HIS", "ILE", "LEU", "LYS", "MET",
    "PHE", "PRO", "SER", "THR", "TRP", "TYR", "VAL", "ACE", "ALAD", "ARGN", "ASF", "ASH", "ASN1",
    "ASPH", "CALA", "CARG", "CASF", "CASN", "CASP", "CCYS", "CCYX", "CGLN", "CGLU", "CGLY", "CHID",
    "CHIE", "CHIP", "CILE", "CLEU", "CLYS", "CME", "CMET", "CPHE", "CPRO", "CSER", "CTHR", "CTRP",
    "CTYR", "CVAL", "CYM", "CYS1", "CYS2", "CYSH", "CYX", "DAB", "GLH", "GLUH", "HID", "HIE",
    "HIP", "HIS1", "HIS2", "HISA", "HISB", "HISD", "HISE", "HISH", "HSD", "HSE", "HSP", "HYP",
    "LYN", "LYSH", "MSE", "NALA", "NARG", "NASN", "NASP", "NCYS", "NCYX", "NGLN", "NGLU", "NGLY",
    "NHID", "NHIE", "NHIP", "NILE", "NLEU", "NLYS", "NME", "NMET", "NPHE", "NPRO", "NSER", "NTHR",
    "NTRP", "NTYR", "NVAL", "ORN", "PGLU", "QLN",
];

/// Residue names `nucleic` matches: DNA and RNA nucleotides in the PDB, AMBER and CHARMM
/// spellings, with AMBER's 5'/3' terminal variants (MDAnalysis's list).
pub const NUCLEIC_RESIDUES: &[&str] = &[
    "ADE", "URA", "CYT", "GUA", "THY", "DA", "DC", "DG", "DT", "RA", "RU", "RG", "RC", "A", "T",
    "U", "C", "G", "DA5", "DC5", "DG5", "DT5", "DA3", "DC3", "DG3", "DT3", "RA5", "RU5", "RG5",
    "RC5", "RA3", "RU3", "RG3", "RC3",
];

/// Atom names of `nucleicbackbone`, `nucleicbase` and `nucleicsugar` (in a `nucleic` residue),
/// MDAnalysis's.
const NUCLEIC_BACKBONE: [&str; 5] = ["P", "C5'", "C3'", "O3'", "O5'"];
const NUCLEIC_BASE: [&str; 16] = [
    "N9", "N7", "C8", "C5", "C4", "N3", "C2", "N1", "C6", "O6", "N2", "N6", "O2", "N4", "O4", "C5M",
];
const NUCLEIC_SUGAR: [&str; 5] = ["C1'", "C2'", "C3'", "C4'", "O4'"];

/// Residue names `water` matches.
pub const WATER_RESIDUES: &[&str] = &[
    "SOL", "WAT", "HOH", "H2O", "TIP3", "TIP4", "TIP5", "SPC", "T3P", "T4P",
];

/// Longest selection accepted (characters), and deepest nesting: a selection is typed by a
/// person, so anything larger is a mistake, and the bound keeps the recursive parser safe.
const MAX_LEN: usize = 10_000;
const MAX_DEPTH: usize = 200;

/// A selection that could not be parsed or evaluated: the text, the 1-based column of the token
/// at fault and what was expected there.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SelectionError {
    pub selection: String,
    /// 1-based character column.
    pub column: usize,
    pub message: String,
}

impl fmt::Display for SelectionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "selection column {}: {}", self.column, self.message)?;
        writeln!(f, "  {}", self.selection)?;
        write!(f, "  {}^", " ".repeat(self.column.saturating_sub(1)))
    }
}

impl std::error::Error for SelectionError {}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum StrField {
    Name,
    Type,
    ResName,
    Chain,
    Segment,
}

impl StrField {
    /// The frame's column of this field, and its name for an error.
    fn column(self, frame: &Frame) -> (&[Label], &'static str) {
        match self {
            StrField::Name => (&frame.names, "atom names"),
            StrField::Type => (&frame.types, "atom types"),
            StrField::ResName => (&frame.res_names, "residue names"),
            StrField::Chain => (&frame.chains, "chain identifiers"),
            StrField::Segment => (&frame.segments, "segment identifiers"),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum NumField {
    Index,
    Serial,
    Id,
    ResId,
    /// The residue's 0-based position among the frame's residues (MDAnalysis's `resindex`).
    ResIndex,
    /// The 0-based number of the atom's bonded fragment (VMD's `fragment`).
    Fragment,
}

/// What `same ... as` compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SameField {
    /// The residue itself (consecutive atoms of one residue number, name, chain and segment).
    Residue,
    Str(StrField),
    ResId,
    Element,
    /// Bonded fragments: every atom of a fragment that holds a picked atom.
    Fragment,
}

#[derive(Clone, Debug, PartialEq)]
enum Node {
    All,
    None,
    Not(Box<Node>),
    And(Box<Node>, Box<Node>),
    Or(Box<Node>, Box<Node>),
    Str {
        field: StrField,
        words: Vec<String>,
        column: usize,
    },
    Element(Vec<Element>),
    Num {
        field: NumField,
        ranges: Vec<(i64, i64)>,
        column: usize,
    },
    Within {
        distance: f64,
        of: Box<Node>,
        include_reference: bool,
    },
    /// `byres SEL`, `same FIELD as SEL`: every atom sharing FIELD with an atom SEL selects.
    Same {
        field: SameField,
        of: Box<Node>,
        column: usize,
    },
    /// `helix`, `sheet`, `coil`: the atoms of residues of that secondary structure.
    Structure {
        class: Structure,
        column: usize,
    },
    /// `cna fcc hcp ...`: the atoms of those crystal structure types (bit `t` for type code t).
    Cna {
        types: u8,
    },
    /// `diamond cubic ...`: the atoms of those diamond structure types (bit `t` for code t).
    Diamond {
        types: u8,
    },
    /// `group NAME`: the atoms of an index group (0-based).
    Group {
        name: String,
        atoms: std::sync::Arc<[u32]>,
        column: usize,
    },
    /// `bonded SEL`: the atoms bonded to an atom SEL picks.
    Bonded(Box<Node>),
    /// `sphzone R SEL`, `sphlayer R1 R2 SEL`, `point X Y Z R`: the atoms whose distance from
    /// the centre lies in `(inner, outer]` (`inner` below zero: `[0, outer]`).
    Sphere {
        centre: Centre,
        inner: f64,
        outer: f64,
    },
    /// `cyzone R ZMAX ZMIN SEL`, `cylayer R1 R2 ZMAX ZMIN SEL`: the atoms in a cylinder (or
    /// tube) along z about SEL's centre of geometry.
    Cylinder {
        of: Box<Node>,
        inner: f64,
        outer: f64,
        zmax: f64,
        zmin: f64,
        column: usize,
    },
    /// `isolayer R1 R2 SEL`: the atoms outside SEL whose nearest SEL atom is farther than R1
    /// and within R2.
    IsoLayer {
        of: Box<Node>,
        inner: f64,
        outer: f64,
    },
    /// `mass RANGE+`, `charge RANGE+` (MDAnalysis's float ranges): inclusive ranges, a single
    /// value matched as numpy's `isclose`.
    FloatRange {
        mass: bool,
        ranges: Vec<(f64, Option<f64>)>,
        column: usize,
    },
    /// `prop [abs] NAME OP VALUE`: a coordinate or a property compared with a number.
    Prop {
        name: String,
        abs: bool,
        op: CmpOp,
        value: f64,
        column: usize,
    },
}

/// Where a spherical selection is centred.
#[derive(Clone, Debug, PartialEq)]
enum Centre {
    /// The centre of geometry of the atoms a selection picks (none picked: nothing selected).
    Of(Box<Node>),
    Point([f64; 3]),
}

/// The comparisons of `prop`, as MDAnalysis has them (`==` is numpy's `isclose`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CmpOp {
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
}

impl CmpOp {
    /// Longest symbols first, so `<=` is not read as `<`.
    const SYMBOLS: [(&'static str, CmpOp); 6] = [
        ("<=", CmpOp::Le),
        (">=", CmpOp::Ge),
        ("==", CmpOp::Eq),
        ("!=", CmpOp::Ne),
        ("<", CmpOp::Lt),
        (">", CmpOp::Gt),
    ];

    /// `a OP b` becomes `b OP' a`.
    fn flipped(self) -> CmpOp {
        match self {
            CmpOp::Lt => CmpOp::Gt,
            CmpOp::Le => CmpOp::Ge,
            CmpOp::Gt => CmpOp::Lt,
            CmpOp::Ge => CmpOp::Le,
            op => op,
        }
    }

    /// In f32, the precision of the values, as numpy compares a float32 column with a number.
    fn test(self, a: f32, b: f32) -> bool {
        match self {
            CmpOp::Lt => a < b,
            CmpOp::Le => a <= b,
            CmpOp::Gt => a > b,
            CmpOp::Ge => a >= b,
            // numpy.isclose's defaults, as MDAnalysis uses them.
            CmpOp::Eq => (a - b).abs() <= 1e-8 + 1e-5 * b.abs(),
            CmpOp::Ne => a != b,
        }
    }
}

/// The property a `prop` NAME reads: MDAnalysis's `tempfactor` (and VMD's `beta`) is the
/// `bfactor` property; `x`, `y`, `z` are coordinates; any other NAME is a property by that name.
fn prop_name(name: &str) -> String {
    match name {
        "tempfactor" | "tempfactors" | "beta" | "bfactor" => "bfactor".into(),
        "charges" => "charge".into(),
        "occupancies" => "occupancy".into(),
        other => other.into(),
    }
}

/// A parsed selection (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    text: String,
    root: Node,
}

#[derive(Clone, Debug, PartialEq)]
struct Token {
    text: String,
    /// 1-based column of its first character.
    column: usize,
    /// Written in double quotes: a word, never a keyword or a parenthesis.
    quoted: bool,
}

impl Token {
    /// A keyword or operator that ends a list of values (a quoted word never does).
    fn reserved(&self) -> bool {
        !self.quoted && is_reserved(&self.text)
    }
}

fn tokenize(s: &str) -> Vec<Token> {
    let mut out = Vec::new();
    let chars: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c == '(' || c == ')' {
            out.push(Token {
                text: c.to_string(),
                column: i + 1,
                quoted: false,
            });
            i += 1;
        } else if c == '"' {
            // A quoted word runs to the next '"' (or the end): an index group's name with
            // spaces or parentheses.
            let start = i;
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                i += 1;
            }
            out.push(Token {
                text: chars[start + 1..i].iter().collect(),
                column: start + 1,
                quoted: true,
            });
            i += 1;
        } else {
            let start = i;
            while i < chars.len() && !chars[i].is_whitespace() && chars[i] != '(' && chars[i] != ')'
            {
                i += 1;
            }
            out.push(Token {
                text: chars[start..i].iter().collect(),
                column: start + 1,
                quoted: false,
            });
        }
    }
    out
}

/// Words that end a keyword's list of values: the operators and every keyword, so that a
/// forgotten `and` (`name CA resid 5`) is an error, not a search for an atom named "resid".
fn is_reserved(w: &str) -> bool {
    matches!(
        w.to_ascii_lowercase().as_str(),
        "and"
            | "or"
            | "not"
            | "of"
            | "to"
            | "("
            | ")"
            | "all"
            | "none"
            | "protein"
            | "nucleic"
            | "backbone"
            | "water"
            | "helix"
            | "sheet"
            | "betasheet"
            | "beta_sheet"
            | "coil"
            | "cna"
            | "diamond"
            | "name"
            | "type"
            | "resname"
            | "chain"
            | "chainid"
            | "segid"
            | "segname"
            | "element"
            | "index"
            | "serial"
            | "bynum"
            | "id"
            | "resid"
            | "resnum"
            | "within"
            | "around"
            | "byres"
            | "same"
            | "prop"
            | "beta"
            | "occupancy"
            | "charge"
            | "mass"
            | "group"
            | "bonded"
            | "fragment"
            | "resindex"
            | "sphzone"
            | "sphlayer"
            | "isolayer"
            | "point"
            | "cyzone"
            | "cylayer"
            | "nucleicbackbone"
            | "nucleicbase"
            | "nucleicsugar"
    )
}

struct Parser<'a> {
    text: &'a str,
    /// The index groups `group` names.
    groups: Option<&'a IndexGroups>,
    tokens: Vec<Token>,
    pos: usize,
    depth: usize,
}

impl Parser<'_> {
    fn error(&self, column: usize, message: impl Into<String>) -> SelectionError {
        SelectionError {
            selection: self.text.to_string(),
            column,
            message: message.into(),
        }
    }

    fn end_column(&self) -> usize {
        self.text.chars().count() + 1
    }

    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    fn peek_is(&self, kw: &str) -> bool {
        self.peek()
            .is_some_and(|t| !t.quoted && t.text.eq_ignore_ascii_case(kw))
    }

    fn next(&mut self, expected: &str) -> Result<Token, SelectionError> {
        match self.tokens.get(self.pos) {
            Some(t) => {
                self.pos += 1;
                Ok(t.clone())
            }
            None => Err(self.error(
                self.end_column(),
                format!("expected {expected}, found the end"),
            )),
        }
    }

    fn expr(&mut self) -> Result<Node, SelectionError> {
        let mut left = self.term()?;
        while self.peek_is("or") {
            self.pos += 1;
            let right = self.term()?;
            left = Node::Or(Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn term(&mut self) -> Result<Node, SelectionError> {
        let mut left = self.factor()?;
        while self.peek_is("and") {
            self.pos += 1;
            let right = self.factor()?;
            left = Node::And(Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn factor(&mut self) -> Result<Node, SelectionError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            let col = self.peek().map_or(self.end_column(), |t| t.column);
            return Err(self.error(col, format!("nested deeper than {MAX_DEPTH} levels")));
        }
        let node = self.factor_inner();
        self.depth -= 1;
        node
    }

    fn factor_inner(&mut self) -> Result<Node, SelectionError> {
        let t =
            self.next("a selection keyword (name, resname, resid, element, index, not, ...)")?;
        if t.quoted {
            return Err(self.error(
                t.column,
                format!("expected a keyword, found the quoted word \"{}\" (quotes are for a value such as a group's name)", t.text),
            ));
        }
        let kw = t.text.to_ascii_lowercase();
        // `beta>=50` written as one word: the comparison is read from the word itself.
        if let Some((left, _, _)) = split_comparison(&kw)
            && matches!(left.as_str(), "beta" | "occupancy" | "charge")
        {
            self.pos -= 1;
            return self.prop(&t, Some(""));
        }
        match kw.as_str() {
            "not" => Ok(Node::Not(Box::new(self.factor()?))),
            "(" => {
                let inner = self.expr()?;
                match self.tokens.get(self.pos) {
                    Some(c) if c.text == ")" => {
                        self.pos += 1;
                        Ok(inner)
                    }
                    Some(c) => Err(self.error(c.column, format!("expected ')' to close the '(' at column {}, found '{}'", t.column, c.text))),
                    None => Err(self.error(self.end_column(), format!("expected ')' to close the '(' at column {}", t.column))),
                }
            }
            "all" => Ok(Node::All),
            "none" => Ok(Node::None),
            "protein" => Ok(protein()),
            "nucleic" => Ok(Node::Str {
                field: StrField::ResName,
                words: NUCLEIC_RESIDUES.iter().map(|s| s.to_string()).collect(),
                column: t.column,
            }),
            "backbone" => Ok(Node::And(
                Box::new(protein()),
                Box::new(Node::Str {
                    field: StrField::Name,
                    words: ["N", "CA", "C", "O"].map(String::from).to_vec(),
                    column: t.column,
                }),
            )),
            "water" => Ok(Node::Str {
                field: StrField::ResName,
                words: WATER_RESIDUES.iter().map(|s| s.to_string()).collect(),
                column: t.column,
            }),
            "nucleicbackbone" | "nucleicbase" | "nucleicsugar" => {
                let names: &[&str] = match kw.as_str() {
                    "nucleicbackbone" => &NUCLEIC_BACKBONE,
                    "nucleicbase" => &NUCLEIC_BASE,
                    _ => &NUCLEIC_SUGAR,
                };
                Ok(Node::And(
                    Box::new(Node::Str {
                        field: StrField::ResName,
                        words: NUCLEIC_RESIDUES.iter().map(|s| s.to_string()).collect(),
                        column: t.column,
                    }),
                    Box::new(Node::Str {
                        field: StrField::Name,
                        words: names.iter().map(|s| s.to_string()).collect(),
                        column: t.column,
                    }),
                ))
            }
            "group" => self.group(&t),
            "bonded" => Ok(Node::Bonded(Box::new(self.rest(&t)?))),
            "sphzone" | "sphlayer" => {
                let inner = if kw == "sphlayer" {
                    self.distance("the inner radius in Å")?
                } else {
                    -1.0
                };
                let outer = self.distance("the outer radius in Å")?;
                Ok(Node::Sphere {
                    centre: Centre::Of(Box::new(self.rest(&t)?)),
                    inner,
                    outer,
                })
            }
            "point" => {
                let mut p = [0.0; 3];
                for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                    p[k] = self.number(&format!("the point's {axis} in Å"))?;
                }
                let outer = self.distance("the radius in Å")?;
                Ok(Node::Sphere {
                    centre: Centre::Point(p),
                    inner: -1.0,
                    outer,
                })
            }
            "isolayer" => {
                let inner = self.distance("the inner distance in Å")?;
                let outer = self.distance("the outer distance in Å")?;
                Ok(Node::IsoLayer {
                    of: Box::new(self.rest(&t)?),
                    inner,
                    outer,
                })
            }
            "cyzone" | "cylayer" => {
                let inner = if kw == "cylayer" {
                    self.distance("the inner radius in Å")?
                } else {
                    -1.0
                };
                let outer = self.distance("the outer radius in Å")?;
                let zmax = self.number("the top of the cylinder (z above the centre, Å)")?;
                let zmin = self.number("the bottom of the cylinder (z from the centre, Å)")?;
                Ok(Node::Cylinder {
                    of: Box::new(self.rest(&t)?),
                    inner,
                    outer,
                    zmax,
                    zmin,
                    column: t.column,
                })
            }
            "mass" => self.float_ranges(&t, true),
            // MDAnalysis's range (`charge -1 to 0`) unless a comparison follows (VMD's).
            "charge"
                if self.peek().is_some_and(|n| {
                    !n.text.starts_with(['<', '>', '=', '!'])
                        && n.text.parse::<f64>().is_ok()
                        || float_range(&n.text).is_some()
                }) =>
            {
                self.float_ranges(&t, false)
            }
            "helix" => Ok(Node::Structure {
                class: Structure::Helix,
                column: t.column,
            }),
            "sheet" | "betasheet" | "beta_sheet" => Ok(Node::Structure {
                class: Structure::Strand,
                column: t.column,
            }),
            "coil" => Ok(Node::Structure {
                class: Structure::Coil,
                column: t.column,
            }),
            "cna" => {
                let names = crate::cna::StructureType::ALL.map(|s| s.name());
                let types = self.type_words(&t, &names, "a structure type")?;
                Ok(Node::Cna { types })
            }
            "diamond" => {
                let names = crate::cna::DiamondType::ALL.map(|d| d.name());
                let types = self.type_words(&t, &names, "a diamond structure type")?;
                Ok(Node::Diamond { types })
            }
            "name" | "type" | "resname" | "chain" | "chainid" | "segid" | "segname" => {
                let words = self.words(&t)?;
                let field = match kw.as_str() {
                    "name" => StrField::Name,
                    "type" => StrField::Type,
                    "resname" => StrField::ResName,
                    "chain" | "chainid" => StrField::Chain,
                    _ => StrField::Segment,
                };
                Ok(Node::Str {
                    field,
                    words: words.into_iter().map(|w| w.text).collect(),
                    column: t.column,
                })
            }
            "element" => {
                let words = self.words(&t)?;
                let mut els = Vec::new();
                for w in words {
                    match Element::from_symbol(&w.text) {
                        Some(e) => els.push(e),
                        None => {
                            return Err(self.error(w.column, format!("'{}' is not a chemical element symbol", w.text)));
                        }
                    }
                }
                Ok(Node::Element(els))
            }
            "index" | "serial" | "bynum" | "id" | "resid" | "resnum" | "resindex" | "fragment" => {
                let field = match kw.as_str() {
                    "index" => NumField::Index,
                    "serial" | "bynum" => NumField::Serial,
                    "id" => NumField::Id,
                    "resindex" => NumField::ResIndex,
                    "fragment" => NumField::Fragment,
                    _ => NumField::ResId,
                };
                let ranges = self.ranges(&t)?;
                Ok(Node::Num {
                    field,
                    ranges,
                    column: t.column,
                })
            }
            "within" | "around" => {
                let d = self.next("a distance in Å")?;
                let distance: f64 = d
                    .text
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite() && *v >= 0.0 && *v <= 1e4)
                    .ok_or_else(|| self.error(d.column, format!("expected a distance in Å (0 to 1e4), found '{}'", d.text)))?;
                let include_reference = kw == "within";
                if include_reference {
                    let of = self.next("'of'")?;
                    if !of.text.eq_ignore_ascii_case("of") {
                        return Err(self.error(of.column, format!("expected 'of' after 'within {}', found '{}'", d.text, of.text)));
                    }
                }
                Ok(Node::Within {
                    distance,
                    of: Box::new(self.rest(&t)?),
                    include_reference,
                })
            }
            "byres" => Ok(Node::Same {
                field: SameField::Residue,
                of: Box::new(self.rest(&t)?),
                column: t.column,
            }),
            "same" => {
                let f = self.next("what to compare: residue, fragment, resname, resid, name, type, element, chain or segid")?;
                let field = match f.text.to_ascii_lowercase().as_str() {
                    "residue" => SameField::Residue,
                    "fragment" => SameField::Fragment,
                    "resname" => SameField::Str(StrField::ResName),
                    "resid" | "resnum" => SameField::ResId,
                    "name" => SameField::Str(StrField::Name),
                    "type" => SameField::Str(StrField::Type),
                    "element" => SameField::Element,
                    "chain" | "chainid" => SameField::Str(StrField::Chain),
                    "segid" | "segname" => SameField::Str(StrField::Segment),
                    _ => {
                        return Err(self.error(
                            f.column,
                            format!("'same {}': expected residue, fragment, resname, resid, name, type, element, chain or segid", f.text),
                        ));
                    }
                };
                let as_ = self.next("'as'")?;
                if !as_.text.eq_ignore_ascii_case("as") {
                    return Err(self.error(as_.column, format!("expected 'as' after 'same {}', found '{}'", f.text, as_.text)));
                }
                Ok(Node::Same {
                    field,
                    of: Box::new(self.rest(&t)?),
                    column: t.column,
                })
            }
            "prop" => self.prop(&t, None),
            // VMD's spelling without `prop`: `beta > 50`, `occupancy < 1`, `charge < 0`.
            "beta" | "occupancy" | "charge" => self.prop(&t, Some(kw.as_str())),
            ")" => Err(self.error(t.column, "unexpected ')'")),
            _ => Err(self.error(
                t.column,
                format!(
                    "unknown keyword '{}': expected name, type, resname, element, resid, index, serial, id, prop, protein, backbone, water, within, around, group, all, none, not or '('",
                    t.text
                ),
            )),
        }
    }

    /// A number after a keyword.
    fn number(&mut self, what: &str) -> Result<f64, SelectionError> {
        let t = self.next(what)?;
        t.text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && v.abs() <= 1e9)
            .ok_or_else(|| self.error(t.column, format!("expected {what}, found '{}'", t.text)))
    }

    /// A distance after a keyword: 0 to 1e4 Å.
    fn distance(&mut self, what: &str) -> Result<f64, SelectionError> {
        let column = self.peek().map_or(self.end_column(), |t| t.column);
        let d = self.number(what)?;
        if !(0.0..=1e4).contains(&d) {
            return Err(self.error(column, format!("expected {what} (0 to 1e4), found {d}")));
        }
        Ok(d)
    }

    /// `group NAME` or `group N`: an index group by name (as GROMACS resolves it: exactly,
    /// in any case, by a unique prefix) or by its number from 0.
    fn group(&mut self, kw: &Token) -> Result<Node, SelectionError> {
        let w = self.next("an index group's name or number")?;
        let Some(groups) = self.groups else {
            return Err(self.error(kw.column, "'group' needs index groups, and none were given (texmap: --index FILE.ndx, a GROMACS index file)"));
        };
        let found = match groups.find(&w.text) {
            Ok(i) => Ok(i),
            Err(e) => match w.text.parse::<usize>() {
                Ok(i) if i < groups.len() => Ok(i),
                _ => Err(e),
            },
        };
        match found {
            Ok(i) => {
                let g = groups.get(i);
                Ok(Node::Group {
                    name: g.name.clone(),
                    atoms: g.atoms.clone().into(),
                    column: w.column,
                })
            }
            Err(FindError::Ambiguous(names)) => Err(self.error(
                w.column,
                format!(
                    "'{}' begins the names of several groups of {}: {}",
                    w.text,
                    groups.file,
                    names.join(", ")
                ),
            )),
            Err(FindError::Unknown) => Err(self.error(
                w.column,
                format!(
                    "{} has no group '{}' (its groups, numbered from 0: {})",
                    groups.file,
                    w.text,
                    groups
                        .groups()
                        .iter()
                        .enumerate()
                        .map(|(i, g)| format!("{i} {}", g.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
        }
    }

    /// `mass` / `charge` ranges: `V`, `A to B`, `A:B`, `A-B` (MDAnalysis's float ranges).
    fn float_ranges(&mut self, kw: &Token, mass: bool) -> Result<Node, SelectionError> {
        let mut ranges = Vec::new();
        while let Some(t) = self.peek().cloned() {
            if t.reserved() {
                break;
            }
            self.pos += 1;
            let range = match t.text.parse::<f64>().ok().filter(|v| v.is_finite()) {
                Some(lo) if self.peek_is("to") => {
                    self.pos += 1;
                    let hi = self.number("the end of the range")?;
                    (lo, Some(hi))
                }
                Some(v) => (v, None),
                None => match float_range(&t.text) {
                    Some((lo, hi)) => (lo, Some(hi)),
                    None => {
                        return Err(self.error(
                            t.column,
                            format!(
                                "expected a number or a range (V, A:B, A-B, A to B) after '{}', found '{}'",
                                kw.text, t.text
                            ),
                        ));
                    }
                },
            };
            if range.1.is_some_and(|hi| hi < range.0) {
                return Err(self.error(
                    t.column,
                    format!(
                        "range {}..{} is empty (its start is past its end)",
                        range.0,
                        range.1.unwrap_or_default()
                    ),
                ));
            }
            ranges.push(range);
        }
        if ranges.is_empty() {
            let col = self.peek().map_or(self.end_column(), |t| t.column);
            return Err(self.error(
                col,
                format!("expected at least one number after '{}'", kw.text),
            ));
        }
        Ok(Node::FloatRange {
            mass,
            ranges,
            column: kw.column,
        })
    }

    /// The selection after `within ... of`, `around ...`, `byres` and `same ... as`: the rest of
    /// the expression (up to a closing parenthesis), as MDAnalysis and VMD read it, so
    /// `around 4 resname NA and resid 1:15` is `around 4 (resname NA and resid 1:15)`.
    fn rest(&mut self, kw: &Token) -> Result<Node, SelectionError> {
        let column = match self.peek() {
            None => Some(self.end_column()),
            Some(t) if t.text == ")" => Some(t.column),
            Some(_) => None,
        };
        if let Some(column) = column {
            return Err(self.error(column, format!("expected a selection after '{}'", kw.text)));
        }
        self.expr()
    }

    /// `prop [abs] NAME OP VALUE` after `prop`: MDAnalysis's forms, spaced or not (`z > 10`,
    /// `z>10`, `z >10`), or with the value first (`10 < z`).
    /// With `name`, the comparison after VMD's `beta`, `occupancy` or `charge` keyword.
    fn prop(&mut self, kw: &Token, name: Option<&str>) -> Result<Node, SelectionError> {
        let abs = name.is_none() && self.peek().is_some_and(|t| t.text == "abs");
        if abs {
            self.pos += 1;
        }
        let expected =
            "'prop [abs] NAME OP VALUE' with OP one of < <= > >= == != (e.g. prop bfactor > 50)";
        let mut joined = name.unwrap_or_default().to_string();
        let mut parsed = None;
        for _ in 0..3 {
            let Some(t) = self.peek() else { break };
            if t.text == "(" || t.text == ")" {
                break;
            }
            joined.push_str(&t.text);
            self.pos += 1;
            parsed = split_comparison(&joined);
            if parsed.is_some() {
                break;
            }
        }
        let Some((left, op, right)) = parsed else {
            return Err(self.error(
                kw.column,
                format!("expected {expected}, found 'prop {joined}'"),
            ));
        };
        let number = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
        let name_like = |s: &str| !s.contains(['<', '>', '=', '!']);
        let (name, op, value) = match (number(&left), number(&right)) {
            (None, Some(v)) if name_like(&left) => (left, op, v),
            (Some(v), None) if name_like(&right) => (right, op.flipped(), v),
            _ => {
                return Err(self.error(
                    kw.column,
                    format!("expected {expected}, found 'prop {joined}'"),
                ));
            }
        };
        Ok(Node::Prop {
            name: prop_name(&name),
            abs,
            op,
            value,
            column: kw.column,
        })
    }

    /// One or more words after a keyword (up to and/or/')'/the end).
    /// The words after `kw`, each one of `names` (any case): bit `i` set for `names[i]`.
    fn type_words(&mut self, kw: &Token, names: &[&str], what: &str) -> Result<u8, SelectionError> {
        let mut types = 0u8;
        for w in self.words(kw)? {
            match names.iter().position(|n| n.eq_ignore_ascii_case(&w.text)) {
                Some(i) => types |= 1 << i,
                None => {
                    return Err(self.error(
                        w.column,
                        format!(
                            "{}: '{}' is not {what}; use {}",
                            kw.text,
                            w.text,
                            names.join(", ")
                        ),
                    ));
                }
            }
        }
        Ok(types)
    }

    fn words(&mut self, kw: &Token) -> Result<Vec<Token>, SelectionError> {
        let mut out = Vec::new();
        while let Some(t) = self.peek() {
            if t.reserved() {
                break;
            }
            out.push(t.clone());
            self.pos += 1;
        }
        if out.is_empty() {
            let col = self.peek().map_or(self.end_column(), |t| t.column);
            return Err(self.error(
                col,
                format!("expected at least one value after '{}'", kw.text),
            ));
        }
        Ok(out)
    }

    /// One or more ranges: `N`, `N to M`, `N:M`, `N-M` (negative numbers allowed: `-5:-1`).
    fn ranges(&mut self, kw: &Token) -> Result<Vec<(i64, i64)>, SelectionError> {
        let mut out = Vec::new();
        while let Some(t) = self.peek().cloned() {
            if t.reserved() {
                break;
            }
            self.pos += 1;
            let bad = |p: &Parser| {
                p.error(t.column, format!("expected an integer or a range (N, N:M, N-M, N to M) after '{}', found '{}'", kw.text, t.text))
            };
            let range = if let Ok(n) = t.text.parse::<i64>() {
                if self.peek_is("to") {
                    self.pos += 1;
                    let m = self.next("the end of the range")?;
                    let hi = m.text.parse::<i64>().map_err(|_| {
                        self.error(
                            m.column,
                            format!("expected an integer after 'to', found '{}'", m.text),
                        )
                    })?;
                    (n, hi)
                } else {
                    (n, n)
                }
            } else {
                // N:M or N-M (the '-' after the first character, so "-3" stays a number).
                let s = t.text.as_str();
                let split = s.find(':').or_else(|| s[1..].find('-').map(|k| k + 1));
                let Some(k) = split else {
                    return Err(bad(self));
                };
                match (s[..k].parse::<i64>(), s[k + 1..].parse::<i64>()) {
                    (Ok(a), Ok(b)) => (a, b),
                    _ => return Err(bad(self)),
                }
            };
            if range.0 > range.1 {
                return Err(self.error(
                    t.column,
                    format!(
                        "range {}..{} is empty (its start is past its end)",
                        range.0, range.1
                    ),
                ));
            }
            out.push(range);
        }
        if out.is_empty() {
            let col = self.peek().map_or(self.end_column(), |t| t.column);
            return Err(self.error(
                col,
                format!("expected at least one number after '{}'", kw.text),
            ));
        }
        Ok(out)
    }
}

fn protein() -> Node {
    Node::Str {
        field: StrField::ResName,
        words: PROTEIN_RESIDUES.iter().map(|s| s.to_string()).collect(),
        column: 0,
    }
}

/// `*` matches any run, `?` one character (on bytes: labels are short and mostly ASCII).
fn glob(pattern: &[u8], s: &[u8]) -> bool {
    let (mut p, mut i) = (0, 0);
    let (mut star, mut mark) = (None, 0);
    while i < s.len() {
        if p < pattern.len() && (pattern[p] == b'?' || pattern[p] == s[i]) {
            p += 1;
            i += 1;
        } else if p < pattern.len() && pattern[p] == b'*' {
            star = Some(p);
            mark = i;
            p += 1;
        } else if let Some(sp) = star {
            p = sp + 1;
            mark += 1;
            i = mark;
        } else {
            return false;
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

impl Selection {
    /// Parse `text`; the error names the column of the first bad token.
    pub fn parse(text: &str) -> Result<Selection, SelectionError> {
        Selection::parse_with(text, None)
    }

    /// Parse `text` with index groups for its `group` keyword (a GROMACS `.ndx` file's,
    /// [`IndexGroups::read`]). The groups' atoms are copied into the selection.
    pub fn parse_with(
        text: &str,
        groups: Option<&IndexGroups>,
    ) -> Result<Selection, SelectionError> {
        let err = |column, message: &str| SelectionError {
            selection: text.to_string(),
            column,
            message: message.to_string(),
        };
        if text.chars().count() > MAX_LEN {
            return Err(err(
                MAX_LEN + 1,
                "a selection longer than 10,000 characters",
            ));
        }
        let mut p = Parser {
            text,
            groups,
            tokens: tokenize(text),
            pos: 0,
            depth: 0,
        };
        if p.tokens.is_empty() {
            return Err(err(1, "empty selection (use 'all' to select every atom)"));
        }
        let root = p.expr()?;
        if let Some(t) = p.peek() {
            let message = if t.text == ")" {
                "unexpected ')' with no '(' open".to_string()
            } else {
                format!(
                    "expected 'and', 'or' or the end, found '{}'{}",
                    t.text,
                    if t.reserved() {
                        " (a missing 'and'?)"
                    } else {
                        ""
                    }
                )
            };
            return Err(p.error(t.column, message));
        }
        Ok(Selection {
            text: text.to_string(),
            root,
        })
    }

    /// The text this selection was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Which atoms of `frame` are selected (one flag per atom). Errors when the selection uses a
    /// column the frame does not have.
    pub fn evaluate(&self, frame: &Frame) -> Result<Vec<bool>, SelectionError> {
        let mut out = vec![false; frame.n_atoms()];
        self.eval(&self.root, frame, &Cache::default(), &mut out)?;
        Ok(out)
    }

    /// The selected atoms' indices, in file order.
    pub fn indices(&self, frame: &Frame) -> Result<Vec<usize>, SelectionError> {
        Ok(self
            .evaluate(frame)?
            .iter()
            .enumerate()
            .filter_map(|(i, &s)| s.then_some(i))
            .collect())
    }

    fn missing(&self, column: usize, what: &str) -> SelectionError {
        SelectionError {
            selection: self.text.clone(),
            column: column.max(1),
            message: if what.starts_with("chain") || what.starts_with("segment") {
                format!(
                    "this frame has no {what}: its file leaves them blank or has no such field (PDB, mmCIF and PSF files carry them)"
                )
            } else {
                format!(
                    "this frame has no {what} (trajectory-only formats such as XTC, DCD and TRR carry none, nor does plain XYZ: give a topology)"
                )
            },
        }
    }

    fn eval(
        &self,
        node: &Node,
        frame: &Frame,
        cache: &Cache,
        out: &mut [bool],
    ) -> Result<(), SelectionError> {
        let n = frame.n_atoms();
        match node {
            Node::All => out.fill(true),
            Node::None => out.fill(false),
            Node::Not(a) => {
                self.eval(a, frame, cache, out)?;
                out.iter_mut().for_each(|v| *v = !*v);
            }
            Node::And(a, b) => {
                self.eval(a, frame, cache, out)?;
                let mut rhs = vec![false; n];
                self.eval(b, frame, cache, &mut rhs)?;
                out.iter_mut().zip(&rhs).for_each(|(v, r)| *v &= r);
            }
            Node::Or(a, b) => {
                self.eval(a, frame, cache, out)?;
                let mut rhs = vec![false; n];
                self.eval(b, frame, cache, &mut rhs)?;
                out.iter_mut().zip(&rhs).for_each(|(v, r)| *v |= r);
            }
            Node::Structure { class, column } => {
                for (v, what) in [
                    (frame.names.len(), "atom names"),
                    (frame.res_names.len(), "residue names"),
                    (frame.res_ids.len(), "residue numbers"),
                ] {
                    if v != n {
                        return Err(self.missing(*column, what));
                    }
                }
                // Assigned once per evaluation, however many structure keywords it has.
                let ss = cache
                    .structure
                    .get_or_init(|| crate::secondary::assign(frame).per_atom(n));
                out.iter_mut()
                    .zip(ss)
                    .for_each(|(o, c)| *o = *c == Some(*class));
            }
            Node::Cna { types } => {
                // Classified once per evaluation, however many cna keywords it has.
                let cna = cache.cna.get_or_init(|| crate::cna::classify(frame));
                out.iter_mut()
                    .zip(cna)
                    .for_each(|(o, t)| *o = types >> *t as u8 & 1 == 1);
            }
            Node::Diamond { types } => {
                let diamond = cache
                    .diamond
                    .get_or_init(|| crate::cna::classify_diamond(frame));
                out.iter_mut()
                    .zip(diamond)
                    .for_each(|(o, t)| *o = types >> *t as u8 & 1 == 1);
            }
            Node::Str {
                field,
                words,
                column,
            } => {
                let (labels, what) = field.column(frame);
                if labels.len() != n {
                    return Err(self.missing(*column, what));
                }
                let plain: Vec<&[u8]> = words
                    .iter()
                    .filter(|w| !w.contains(['*', '?']))
                    .map(|w| w.as_bytes())
                    .collect();
                let globs: Vec<&[u8]> = words
                    .iter()
                    .filter(|w| w.contains(['*', '?']))
                    .map(|w| w.as_bytes())
                    .collect();
                let test = |l: &Label| {
                    let b = l.as_bytes();
                    plain.contains(&b) || globs.iter().any(|g| glob(g, b))
                };
                // Labels repeat (a residue's names, a run of one residue name): the answer for
                // each distinct label is computed once and kept in a small direct-mapped cache
                // keyed by the label's 128-bit value.
                const WAYS: usize = 256;
                let mut cache: [(u128, bool); WAYS] = [(u128::MAX, false); WAYS];
                for (v, l) in out.iter_mut().zip(labels) {
                    let key = l.key();
                    let slot =
                        &mut cache[(key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 120) as usize];
                    if slot.0 != key {
                        *slot = (key, test(l));
                    }
                    *v = slot.1;
                }
            }
            Node::Element(els) => {
                if frame.elements.len() != n {
                    return Err(self.missing(1, "elements"));
                }
                for (v, e) in out.iter_mut().zip(&frame.elements) {
                    *v = els.contains(e);
                }
            }
            Node::Num {
                field,
                ranges,
                column,
            } => {
                let hit = |x: i64| ranges.iter().any(|&(a, b)| a <= x && x <= b);
                match field {
                    NumField::Index => out
                        .iter_mut()
                        .enumerate()
                        .for_each(|(i, v)| *v = hit(i as i64)),
                    NumField::Serial => out
                        .iter_mut()
                        .enumerate()
                        .for_each(|(i, v)| *v = hit(i as i64 + 1)),
                    NumField::Fragment => {
                        let f = cache.fragments.get_or_init(|| fragments(frame));
                        for (v, &x) in out.iter_mut().zip(f) {
                            *v = hit(x as i64);
                        }
                    }
                    NumField::ResIndex => {
                        if frame.res_ids.len() != n || frame.res_names.len() != n {
                            return Err(self.missing(*column, "residue numbers and names"));
                        }
                        for (v, x) in out.iter_mut().zip(residue_indices(frame)) {
                            *v = hit(x);
                        }
                    }
                    NumField::Id | NumField::ResId => {
                        let (vals, what) = if *field == NumField::Id {
                            (&frame.ids, "atom ids")
                        } else {
                            (&frame.res_ids, "residue numbers")
                        };
                        if vals.len() != n {
                            return Err(self.missing(*column, what));
                        }
                        for (v, &x) in out.iter_mut().zip(vals) {
                            *v = hit(x);
                        }
                    }
                }
            }
            Node::Prop {
                name,
                abs,
                op,
                value,
                column,
            } => {
                let axis = ["x", "y", "z"].iter().position(|a| a == name);
                let values: Vec<f32> = match (axis, frame.property(name)) {
                    (Some(k), _) => frame.positions.iter().map(|p| p[k]).collect(),
                    (None, Some(v)) if v.len() == n => v.to_vec(),
                    _ => {
                        let have: Vec<&str> =
                            frame.properties.iter().map(|p| p.name.as_str()).collect();
                        return Err(SelectionError {
                            selection: self.text.clone(),
                            column: *column,
                            message: format!(
                                "this frame has no property '{name}' (it has x, y, z{}{}; charges come from a PSF, prmtop or LAMMPS data topology)",
                                if have.is_empty() { "" } else { ", " },
                                have.join(", ")
                            ),
                        });
                    }
                };
                for (v, x) in out.iter_mut().zip(values) {
                    let x = if *abs { x.abs() } else { x };
                    *v = op.test(x, *value as f32);
                }
            }
            Node::Same { field, of, column } => {
                let mut picked = vec![false; n];
                self.eval(of, frame, cache, &mut picked)?;
                match field {
                    SameField::Residue => {
                        if frame.res_ids.len() != n || frame.res_names.len() != n {
                            return Err(self.missing(*column, "residue numbers and names"));
                        }
                        for r in crate::secondary::residue_ranges(frame) {
                            let any = picked[r.clone()].iter().any(|&p| p);
                            out[r].fill(any);
                        }
                    }
                    SameField::Fragment => {
                        let f = cache.fragments.get_or_init(|| fragments(frame));
                        let mut keep = vec![false; n];
                        for i in (0..n).filter(|&i| picked[i]) {
                            keep[f[i] as usize] = true;
                        }
                        for (o, &x) in out.iter_mut().zip(f) {
                            *o = keep[x as usize];
                        }
                    }
                    SameField::ResId => {
                        if frame.res_ids.len() != n {
                            return Err(self.missing(*column, "residue numbers"));
                        }
                        let set: std::collections::HashSet<i64> = (0..n)
                            .filter(|&i| picked[i])
                            .map(|i| frame.res_ids[i])
                            .collect();
                        for (o, id) in out.iter_mut().zip(&frame.res_ids) {
                            *o = set.contains(id);
                        }
                    }
                    SameField::Element => {
                        let set: std::collections::HashSet<Element> = (0..n)
                            .filter(|&i| picked[i])
                            .map(|i| crate::style::atom_element(frame, i))
                            .collect();
                        for (i, o) in out.iter_mut().enumerate() {
                            *o = set.contains(&crate::style::atom_element(frame, i));
                        }
                    }
                    SameField::Str(f) => {
                        let (labels, what) = f.column(frame);
                        if labels.len() != n {
                            return Err(self.missing(*column, what));
                        }
                        let set: std::collections::HashSet<&Label> =
                            (0..n).filter(|&i| picked[i]).map(|i| &labels[i]).collect();
                        for (o, l) in out.iter_mut().zip(labels) {
                            *o = set.contains(l);
                        }
                    }
                }
            }
            Node::Group {
                name,
                atoms,
                column,
            } => {
                out.fill(false);
                for &a in atoms.iter() {
                    let Some(o) = out.get_mut(a as usize) else {
                        return Err(SelectionError {
                            selection: self.text.clone(),
                            column: *column,
                            message: format!(
                                "index group '{name}' has atom {} but the frame has {n} atoms (an index file of another system?)",
                                a as u64 + 1
                            ),
                        });
                    };
                    *o = true;
                }
            }
            Node::Bonded(of) => {
                let mut picked = vec![false; n];
                self.eval(of, frame, cache, &mut picked)?;
                out.fill(false);
                for &[a, b] in &frame.bonds {
                    let (a, b) = (a as usize, b as usize);
                    if a < n && b < n {
                        out[a] |= picked[b];
                        out[b] |= picked[a];
                    }
                }
            }
            Node::Sphere {
                centre,
                inner,
                outer,
            } => {
                let c = match centre {
                    Centre::Point(p) => *p,
                    Centre::Of(of) => {
                        let mut picked = vec![false; n];
                        self.eval(of, frame, cache, &mut picked)?;
                        match centre_of_geometry(&frame.positions, &picked) {
                            Some(c) => c,
                            None => {
                                out.fill(false);
                                return Ok(());
                            }
                        }
                    }
                };
                let image = frame.cell.as_ref().and_then(crate::pbc::NearestImage::new);
                let (in2, out2) = (inner * inner, outer * outer);
                for (o, p) in out.iter_mut().zip(&frame.positions) {
                    let v: [f64; 3] = std::array::from_fn(|k| p[k] as f64 - c[k]);
                    let m = image.as_ref().map_or(v, |image| image.apply(v));
                    let d2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
                    *o = d2 <= out2 && (*inner < 0.0 || d2 > in2);
                }
            }
            Node::Cylinder {
                of,
                inner,
                outer,
                zmax,
                zmin,
                column,
            } => {
                let mut picked = vec![false; n];
                self.eval(of, frame, cache, &mut picked)?;
                let Some(c) = centre_of_geometry(&frame.positions, &picked) else {
                    out.fill(false);
                    return Ok(());
                };
                let cell = frame.cell.as_ref().filter(|c| c.periodic().contains(&true));
                if let Some(cell) = cell {
                    let m = cell.matrix();
                    let len = |k: usize| m[k].iter().map(|x| x * x).sum::<f64>().sqrt();
                    let limits = [
                        (2.0 * outer, len(0), "diameter", "a"),
                        (2.0 * outer, len(1), "diameter", "b"),
                        (zmax - zmin, len(2), "height", "c"),
                    ];
                    for (k, (size, width, what, axis)) in limits.into_iter().enumerate() {
                        if cell.periodic()[k] && size > width {
                            return Err(SelectionError {
                                selection: self.text.clone(),
                                column: *column,
                                message: format!(
                                    "the cylinder's {what} ({size} Å) is larger than the cell's {axis} edge ({width:.3} Å); MDAnalysis refuses it too"
                                ),
                            });
                        }
                    }
                }
                for (o, p) in out.iter_mut().zip(&frame.positions) {
                    let mut v: [f64; 3] = std::array::from_fn(|k| p[k] as f64 - c[k]);
                    if let Some(cell) = cell {
                        // MDAnalysis's reduction: the c, b and a edges in turn, each by its
                        // diagonal component (exact for orthogonal cells).
                        let m = cell.matrix();
                        for k in [2, 1, 0] {
                            if cell.periodic()[k] {
                                let s = (v[k] / m[k][k]).round_ties_even();
                                for (j, vj) in v.iter_mut().enumerate() {
                                    *vj -= s * m[k][j];
                                }
                            }
                        }
                    }
                    let r2 = v[0] * v[0] + v[1] * v[1];
                    *o = v[2] > *zmin
                        && v[2] < *zmax
                        && r2 < outer * outer
                        && (*inner < 0.0 || r2 > inner * inner);
                }
            }
            Node::IsoLayer { of, inner, outer } => {
                let mut picked = vec![false; n];
                self.eval(of, frame, cache, &mut picked)?;
                let mut near = vec![false; n];
                within(
                    &frame.positions,
                    &picked,
                    *inner,
                    frame.cell.as_ref(),
                    &mut near,
                );
                within(&frame.positions, &picked, *outer, frame.cell.as_ref(), out);
                for ((o, p), w) in out.iter_mut().zip(&picked).zip(&near) {
                    *o &= !p && !w;
                }
            }
            Node::FloatRange {
                mass,
                ranges,
                column,
            } => {
                let values: Vec<f64> = if *mass {
                    (0..n).map(|i| crate::style::atom_mass(frame, i)).collect()
                } else {
                    match frame.property("charge") {
                        Some(v) if v.len() == n => v.iter().map(|&x| x as f64).collect(),
                        _ => return Err(self.missing(*column, "charges")),
                    }
                };
                for (o, x) in out.iter_mut().zip(values) {
                    *o = ranges.iter().any(|&(lo, hi)| match hi {
                        Some(hi) => x >= lo && x <= hi,
                        None => (x - lo).abs() <= 1e-8 + 1e-5 * lo.abs(),
                    });
                }
            }
            Node::Within {
                distance,
                of,
                include_reference,
            } => {
                let mut reference = vec![false; n];
                self.eval(of, frame, cache, &mut reference)?;
                within(
                    &frame.positions,
                    &reference,
                    *distance,
                    frame.cell.as_ref(),
                    out,
                );
                if !include_reference {
                    out.iter_mut().zip(&reference).for_each(|(v, r)| *v &= !r);
                }
            }
        }
        Ok(())
    }
}

/// The mean position of the picked atoms (plain, without periodic images, as MDAnalysis's
/// `center_of_geometry`); `None` when none is picked.
fn centre_of_geometry(positions: &[[f32; 3]], picked: &[bool]) -> Option<[f64; 3]> {
    let mut sum = [0.0f64; 3];
    let mut count = 0usize;
    for (p, _) in positions.iter().zip(picked).filter(|(_, s)| **s) {
        for k in 0..3 {
            sum[k] += p[k] as f64;
        }
        count += 1;
    }
    (count > 0).then(|| sum.map(|s| s / count as f64))
}

/// `A:B` or `A-B` with two finite numbers (the '-' after a digit or '.', so `-1--0.5` is
/// -1 to -0.5 and `1e-3` is no range).
fn float_range(text: &str) -> Option<(f64, f64)> {
    let b = text.as_bytes();
    let at = text.find(':').or_else(|| {
        (1..b.len()).find(|&i| b[i] == b'-' && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.'))
    })?;
    let num = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
    Some((num(&text[..at])?, num(&text[at + 1..])?))
}

/// `text` as `LEFT OP RIGHT` at its first comparison symbol, both sides non-empty.
fn split_comparison(text: &str) -> Option<(String, CmpOp, String)> {
    let (at, sym, op) = (0..text.len())
        .filter(|&i| text.is_char_boundary(i))
        .find_map(|i| {
            CmpOp::SYMBOLS
                .iter()
                .find(|(sym, _)| text[i..].starts_with(sym))
                .map(|(sym, op)| (i, *sym, *op))
        })?;
    let (left, right) = (&text[..at], &text[at + sym.len()..]);
    (!left.is_empty() && !right.is_empty()).then(|| (left.to_string(), op, right.to_string()))
}

/// `out[i]` = some reference atom lies within `d` of atom `i`, through the periodic images
/// when `cell` repeats along some edge (MDAnalysis's default `periodic=True`), else by plain
/// distances. With a cell, the positions are wrapped into it and each reference atom stands
/// with its images in the 26 neighbouring cells (along the periodic edges) that come within
/// `d` of a wrapped position; a cutoff of half the cell's narrowest periodic width or more
/// compares every pair through the nearest image instead.
fn within(
    pos: &[[f32; 3]],
    reference: &[bool],
    d: f64,
    cell: Option<&crate::frame::UnitCell>,
    out: &mut [bool],
) {
    let refs = (0..pos.len()).filter(|&i| reference[i]);
    let Some(cell) = cell.filter(|c| c.periodic().contains(&true)) else {
        let points: Vec<[f64; 3]> = refs.map(|i| pos[i].map(f64::from)).collect();
        return within_points(pos, &points, d, out);
    };
    if 2.0 * d >= cell.min_periodic_width() {
        let refs: Vec<usize> = refs.collect();
        let image = crate::pbc::NearestImage::new(cell);
        for (i, o) in out.iter_mut().enumerate() {
            *o = refs.iter().any(|&r| {
                let v: [f64; 3] = std::array::from_fn(|k| (pos[r][k] - pos[i][k]) as f64);
                let m = image.map_or(v, |image| image.apply(v));
                m[0] * m[0] + m[1] * m[1] + m[2] * m[2] <= d * d
            });
        }
        return;
    }
    let mut query = pos.to_vec();
    crate::pbc::wrap_positions(cell, &mut query);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in &query {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k] as f64 - d);
            hi[k] = hi[k].max(q[k] as f64 + d);
        }
    }
    let m = cell.matrix();
    let periodic = cell.periodic();
    let steps = |k: usize| if periodic[k] { -1..=1 } else { 0..=0 };
    let mut points = Vec::new();
    for r in refs {
        for a in steps(0) {
            for b in steps(1) {
                for c in steps(2) {
                    let p: [f64; 3] = std::array::from_fn(|k| {
                        query[r][k] as f64
                            + a as f64 * m[0][k]
                            + b as f64 * m[1][k]
                            + c as f64 * m[2][k]
                    });
                    if (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]) {
                        points.push(p);
                    }
                }
            }
        }
    }
    within_points(&query, &points, d, out);
}

/// `out[i]` = some point of `refs` lies within `d` of `query[i]` (plain distances). The
/// reference points are sorted into a dense grid of cells of side ≥ `d` over their bounding box
/// grown by `d`; a query outside that box is rejected at once, one inside looks at 27 cells.
fn within_points(query: &[[f32; 3]], refs: &[[f64; 3]], d: f64, out: &mut [bool]) {
    out.fill(false);
    if refs.is_empty() {
        return;
    }
    let p64 = |i: usize| refs[i];
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for r in 0..refs.len() {
        let p = p64(r);
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - d);
            hi[k] = hi[k].max(p[k] + d);
        }
    }
    // Cells of side ≥ d, at most 2^21 of them (a sparse reference spread wide gets larger cells;
    // correctness needs only side ≥ d).
    let mut cell = d.max(1e-6);
    let dims = loop {
        let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell).floor() + 1.0);
        if dims.iter().product::<f64>() <= (1u32 << 21) as f64 {
            break dims.map(|n| n as usize);
        }
        cell *= 2.0;
    };
    let cell_of = |p: [f64; 3]| {
        [0, 1, 2].map(|k| (((p[k] - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1))
    };
    let flat = |c: [usize; 3]| (c[2] * dims[1] + c[1]) * dims[0] + c[0];
    // Counting sort of the reference atoms by cell.
    let mut start = vec![0u32; dims.iter().product::<usize>() + 1];
    for r in 0..refs.len() {
        start[flat(cell_of(p64(r))) + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = start.clone();
    let mut sorted = vec![0u32; refs.len()];
    for r in 0..refs.len() {
        let c = flat(cell_of(p64(r)));
        sorted[fill[c] as usize] = r as u32;
        fill[c] += 1;
    }
    let d2 = d * d;
    // First the box test, in f32 on bounds rounded outwards (a query it keeps still gets the
    // exact test), a pass without branches: most queries of a small reference stop here.
    let lo32 = lo.map(|v| (v as f32).next_down());
    let hi32 = hi.map(|v| (v as f32).next_up());
    for (v, p) in out.iter_mut().zip(query) {
        *v = (p[0] >= lo32[0])
            & (p[0] <= hi32[0])
            & (p[1] >= lo32[1])
            & (p[1] <= hi32[1])
            & (p[2] >= lo32[2])
            & (p[2] <= hi32[2]);
    }
    for (v, p) in out.iter_mut().zip(query) {
        if !*v {
            continue;
        }
        *v = false;
        let p = p.map(f64::from);
        if (0..3).any(|k| p[k] < lo[k] || p[k] > hi[k]) {
            continue;
        }
        let c = cell_of(p);
        let range = |k: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(dims[k] - 1);
        'cells: for z in range(2) {
            for y in range(1) {
                for x in range(0) {
                    let f = flat([x, y, z]);
                    for &r in &sorted[start[f] as usize..start[f + 1] as usize] {
                        let q = p64(r as usize);
                        let s: f64 = (0..3).map(|k| (p[k] - q[k]).powi(2)).sum();
                        if s <= d2 {
                            *v = true;
                            break 'cells;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        let mut f = Frame::new();
        // Two alanines and a water, with positions on a line 1 Å apart.
        let atoms = [
            ("N", "ALA", 1, "N"),
            ("CA", "ALA", 1, "C"),
            ("C", "ALA", 1, "C"),
            ("O", "ALA", 1, "O"),
            ("HA", "ALA", 1, "H"),
            ("N", "ALA", 2, "N"),
            ("CA", "ALA", 2, "C"),
            ("OW", "SOL", 3, "O"),
            ("HW1", "SOL", 3, "H"),
            ("HW2", "SOL", 3, "H"),
        ];
        for (k, (name, res, resid, el)) in atoms.iter().enumerate() {
            f.positions.push([k as f32, 0.0, 0.0]);
            f.names.push(Label::new(name).unwrap());
            f.res_names.push(Label::new(res).unwrap());
            f.res_ids.push(*resid);
            f.elements.push(Element::from_symbol(el).unwrap());
            f.ids.push(100 + k as i64);
        }
        f
    }

    fn sel(s: &str) -> Vec<usize> {
        Selection::parse(s).unwrap().indices(&frame()).unwrap()
    }

    #[test]
    fn keywords_ranges_and_logic() {
        assert_eq!(sel("name CA"), [1, 6]);
        assert_eq!(sel("not resname SOL"), [0, 1, 2, 3, 4, 5, 6]);
        assert_eq!(sel("element O and resid 1 to 20"), [3, 7]);
        assert_eq!(sel("element O and resid 1 to 2"), [3]);
        assert_eq!(sel("resid 2:3"), [5, 6, 7, 8, 9]);
        assert_eq!(sel("resid 2-3 and not water"), [5, 6]);
        assert_eq!(sel("index 0 9"), [0, 9]);
        assert_eq!(sel("serial 1 10"), [0, 9]);
        assert_eq!(sel("id 101:102"), [1, 2]);
        assert_eq!(sel("name H*"), [4, 8, 9]);
        assert_eq!(sel("name ?W*"), [7, 8, 9]);
        assert_eq!(sel("name ?W?"), [8, 9]);
        assert_eq!(sel("backbone"), [0, 1, 2, 3, 5, 6]);
        assert_eq!(sel("protein and not (name N or element H)"), [1, 2, 3, 6]);
        assert_eq!(sel("NOT Protein AND Water"), [7, 8, 9]);
        assert_eq!(sel("element o"), [3, 7]);
        assert_eq!(sel("none or all").len(), 10);
        // Atom 7 (OW) at x = 7: within 1.5 Å are x = 6..9; around excludes OW itself.
        assert_eq!(sel("within 1.5 of name OW"), [6, 7, 8]);
        assert_eq!(sel("around 1.5 name OW"), [6, 8]);
        // `or` binds looser than `and`.
        assert_eq!(sel("name N or name CA and resid 2"), [0, 5, 6]);
    }

    #[test]
    fn errors_point_at_the_bad_token() {
        let cases = [
            ("name CA and resnme SOL", 13, "unknown keyword 'resnme'"),
            ("resid 1 to", 11, "the end of the range"),
            ("(name CA", 9, "close the '('"),
            ("name CA)", 8, "unexpected ')'"),
            ("element Xx", 9, "not a chemical element"),
            ("resid 5:2", 7, "empty"),
            ("within x of name CA", 8, "distance"),
            ("name", 5, "at least one value"),
            ("name CA CB resid", 12, "expected 'and', 'or' or the end"),
            ("", 1, "empty selection"),
            (
                "same colour as name CA",
                6,
                "expected residue, fragment, resname",
            ),
            ("same residue of name CA", 14, "expected 'as'"),
            ("byres", 6, "a selection after 'byres'"),
            ("name CA or (around 3 )", 22, "a selection after 'around'"),
        ];
        for (text, column, want) in cases {
            let e = Selection::parse(text).unwrap_err();
            assert_eq!(e.column, column, "{text:?}: {e}");
            assert!(e.message.contains(want), "{text:?}: {e}");
            // The caret sits under the column.
            let caret = e.to_string().lines().last().unwrap().find('^').unwrap();
            assert_eq!(caret, column + 1, "{e}");
        }
        let deep = "not ".repeat(MAX_DEPTH + 5) + "all";
        assert!(
            Selection::parse(&deep)
                .unwrap_err()
                .message
                .contains("nested")
        );
    }

    #[test]
    fn a_missing_column_is_an_error_not_an_empty_selection() {
        let mut f = frame();
        f.res_names.clear();
        let e = Selection::parse("name CA or resname SOL")
            .unwrap()
            .evaluate(&f)
            .unwrap_err();
        assert_eq!(e.column, 12);
        assert!(e.message.contains("residue names"), "{e}");
    }

    #[test]
    fn within_matches_brute_force() {
        let mut f = Frame::new();
        let mut state = 7u64;
        let mut r = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 20.0
        };
        for _ in 0..2000 {
            f.positions.push([r(), r(), r()]);
        }
        let reference: Vec<bool> = (0..2000).map(|i| i % 37 == 0).collect();
        for d in [0.0, 0.7, 2.5, 6.0] {
            let mut got = vec![false; 2000];
            within(&f.positions, &reference, d, None, &mut got);
            for (i, (&g, p)) in got.iter().zip(&f.positions).enumerate() {
                let want = f.positions.iter().zip(&reference).any(|(q, &is_ref)| {
                    let s: f64 = (0..3).map(|k| (p[k] as f64 - q[k] as f64).powi(2)).sum();
                    is_ref && s <= d * d
                });
                assert_eq!(g, want, "atom {i} at d = {d}");
            }
        }
        // Periodic: a triclinic cell with its origin off zero, some positions outside it, one
        // edge open; against every pair through the nearest image (and a cutoff past half the
        // cell's width, which takes the all-pairs path).
        for p in f.positions.iter_mut().step_by(5) {
            p[0] += 23.0;
            p[2] -= 9.0;
        }
        for open in [false, true] {
            let cell = crate::frame::UnitCell::from_lengths_angles(
                [20.0, 21.0, 22.0],
                [80.0, 95.0, 105.0],
            )
            .unwrap()
            .with_origin([1.0, -2.0, 0.5])
            .with_periodic([true, true, !open]);
            for d in [0.7, 2.5, 6.0, 11.0] {
                let mut got = vec![false; 2000];
                within(&f.positions, &reference, d, Some(&cell), &mut got);
                for (i, (&g, p)) in got.iter().zip(&f.positions).enumerate() {
                    let want = f.positions.iter().zip(&reference).any(|(q, &is_ref)| {
                        let v: [f64; 3] = std::array::from_fn(|k| q[k] as f64 - p[k] as f64);
                        let m = crate::pbc::minimum_image(&cell, v);
                        is_ref && m[0] * m[0] + m[1] * m[1] + m[2] * m[2] <= d * d
                    });
                    assert_eq!(g, want, "atom {i} at d = {d}, open c: {open}");
                }
            }
        }
    }

    #[test]
    fn glob_patterns() {
        for (p, s, want) in [
            ("H*", "HW1", true),
            ("H*", "OW", false),
            ("*1", "HW1", true),
            ("?W?", "HW1", true),
            ("?W?", "OW", false),
            ("*", "", true),
            ("C*A", "CXYA", true),
            ("C*A", "CXYB", false),
        ] {
            assert_eq!(glob(p.as_bytes(), s.as_bytes()), want, "{p} vs {s}");
        }
    }
}

//! PDBx/mmCIF coordinates (the Protein Data Bank's archive format, the only one that holds
//! entries past 99,999 atoms), multi-model.
//!
//! # What is read
//! The first data block (`data_…`) of a CIF 1.1 file, up to the end of its first `_atom_site`
//! loop:
//! - `_atom_site`, columns in any order, matched by tag (case-insensitive), unknown ones
//!   ignored. Per row: `Cartn_x/y/z` (required, Å); `id` (the frame's ids); the atom name from
//!   `auth_atom_id`, else `label_atom_id`; the residue name from `auth_comp_id`, else
//!   `label_comp_id`; the residue number from `auth_seq_id`, else `label_seq_id` (0 when both
//!   are missing, as for a blank PDB field); the element from `type_symbol`, else
//!   [`crate::elements::guess_element`] from the names. These are the fields the PDB reader fills
//!   from the same structure's ATOM/HETATM records, so selections read a `.pdb` and its `.cif`
//!   alike; and the chain from `auth_asym_id`, else `label_asym_id` (gemmi's chain name).
//!   `occupancy` and `B_iso_or_equiv` become the `occupancy` and `bfactor` properties
//!   ([`Frame::property`]; a missing value is 1 and 0, as in the PDB reader). `group_PDB` and
//!   insertion codes have no place in a [`Frame`] and are not kept.
//! - `pdbx_PDB_model_num` splits the rows into frames (NMR ensembles): each change of model
//!   number starts a frame; numbers must increase, and every model must hold as many atoms as
//!   model 1 (an error, or a warning under `ReadOptions::allow_truncated`, as for PDB). Without
//!   the column the file is one frame.
//! - `_cell.length_a/b/c`, `_cell.angle_alpha/beta/gamma` (angles 90° when absent) when they
//!   precede `_atom_site`, as the wwPDB, gemmi, PyMOL and ChimeraX write them; the 1 Å x 1 Å x
//!   1 Å placeholder of NMR entries is dropped, as in the PDB reader.
//! - `_struct.title` is frame 0's comment (as a PDB TITLE is).
//!
//! Everything after the first `_atom_site` loop (other categories, further data blocks) is not
//! read. Single-row categories may be written as `_tag value` pairs instead of a loop; that form
//! is read too (a one-atom file).
//!
//! # Alternate locations
//! Rows whose `label_alt_id` is not `.`/`?` are alternate conformations. Like gemmi's
//! `remove_alternative_conformations` (and so the tools built on it), the first conformation
//! of each atom is kept: within a residue (consecutive rows with the same chain, residue number
//! and insertion code) a row with an alternate location is dropped when an atom of its name was
//! kept already, or when its residue name differs from the residue's first (the second residue
//! of a microheterogeneity, e.g. 3JQH's PRO/SER 4). Rows without an alternate location are never
//! dropped. This is the one place a reader drops rows on purpose: each frame that lost some
//! gives one warning ([`crate::Trajectory::warnings`]) with the count and the first dropped row.
//!
//! # Syntax (CIF 1.1)
//! Tokens are separated by blanks; a value is bare, or in single or double quotes (a quote
//! closes only when a blank or the line end follows it, so `'O5''` is `O5'`), or a text field
//! from a line starting with `;` to the next line starting with `;`. Text fields and quoted
//! values are skipped wherever they appear, inside any loop. `#` starts a comment at a token
//! start. Bare `.` and `?` are missing values. A loop's value count must be a multiple of its tag
//! count.
//!
//! # Damage
//! Errors name the file, frame, line and byte of the token at fault: a missing `Cartn` column
//! (at the loop), a coordinate that is not a number, a loop row with too few values, an
//! unterminated quote or text field (the latter where it opened), no `_atom_site` loop in the
//! first data block. A model's end is only known from the next model's first row, so that row
//! must start a line (every writer does so); otherwise it is an error, not a guess. Nothing is
//! sized from a count in the file.
//!
//! # Design
//! The reader streams: [`TextReader`](crate::text) hands it lines, a small lexer turns them into
//! tokens (no copy except for text fields), and each value is parsed as it arrives into the
//! row being built. Frame 0 is everything up to the end of model 1's rows (the header included);
//! frame k starts at model k+1's first row, so random access needs only the column map kept
//! from frame 0. Rejected: reading the whole document into a tree first (what gemmi and
//! Biopython do): memory would follow the file, not the frame. Measured on a synthetic 149 MB
//! file of two 1,000,000-atom models: `/usr/bin/time -v texmap info big.cif` (a scan of both
//! models, then frame 0 read) takes 2.3 s with a 66 MB peak, the frame's own buffers.
//!
//! # References
//! - S. R. Hall, F. H. Allen, I. D. Brown, "The Crystallographic Information File (CIF)", Acta
//!   Cryst. A47 (1991) 655; CIF 1.1 syntax specification (IUCr, 2003).
//! - wwPDB, PDBx/mmCIF dictionary (`mmcif_pdbx_v50.dic`), category ATOM_SITE.
//! - gemmi 0.7 `include/gemmi/modify.hpp`, `remove_alternative_conformations`.

use std::collections::HashSet;
use std::hash::{BuildHasherDefault, Hasher};
use std::io::Read;

#[cfg(test)]
use crate::cif::classify;
use crate::cif::{Kind, Lexer, Tok, cell_number, cell_of, cell_parameters, strip_esd};
use crate::elements::guess_element;
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{parse_f32, parse_i64};
use crate::text::{Ctx, FrameWalk, LineReader, ModelCheck, Pos};

/// What the parser asks of the line loop after a token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Flow {
    More,
    /// The row being read belongs to the next model and starts this line: give the line back,
    /// the frame ends before it.
    NextModel,
    /// The `_atom_site` loop ended: the frame ends, and the rest of the file is not read.
    LoopEnd,
}

/// An `_atom_site` column the reader uses (the text and the BinaryCIF front-ends alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    X,
    Y,
    Z,
    Id,
    Symbol,
    AltId,
    Model,
    InsCode,
    /// `[label, auth]` pairs: index 0 is `label_*`, 1 is `auth_*`.
    Atom(usize),
    Comp(usize),
    Seq(usize),
    Asym(usize),
    /// `occupancy` and `B_iso_or_equiv`: the frame's `occupancy` and `bfactor` properties.
    Scalar(usize),
    Other,
}

/// The role of `_atom_site.<item>` (the item in lower case).
pub(crate) fn role(item: &[u8]) -> Role {
    match item {
        b"cartn_x" => Role::X,
        b"cartn_y" => Role::Y,
        b"cartn_z" => Role::Z,
        b"id" => Role::Id,
        b"type_symbol" => Role::Symbol,
        b"label_alt_id" => Role::AltId,
        b"pdbx_pdb_model_num" => Role::Model,
        b"pdbx_pdb_ins_code" => Role::InsCode,
        b"label_atom_id" => Role::Atom(0),
        b"auth_atom_id" => Role::Atom(1),
        b"label_comp_id" => Role::Comp(0),
        b"auth_comp_id" => Role::Comp(1),
        b"label_seq_id" => Role::Seq(0),
        b"auth_seq_id" => Role::Seq(1),
        b"label_asym_id" => Role::Asym(0),
        b"auth_asym_id" => Role::Asym(1),
        b"occupancy" => Role::Scalar(0),
        b"b_iso_or_equiv" => Role::Scalar(1),
        _ => Role::Other,
    }
}

/// What the header keeps of a tag's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Interest {
    None,
    /// `_cell`: a, b, c, α, β, γ.
    Cell(usize),
    Title,
    Atom(Role),
}

/// The `_cell` items read, in the order a, b, c, α, β, γ.
pub(crate) const CELL_ITEMS: [&str; 6] = [
    "length_a",
    "length_b",
    "length_c",
    "angle_alpha",
    "angle_beta",
    "angle_gamma",
];

fn interest(tag: &[u8]) -> Interest {
    let t = tag.to_ascii_lowercase();
    let cell = t
        .strip_prefix(b"_cell.")
        .and_then(|item| CELL_ITEMS.iter().position(|c| c.as_bytes() == item));
    if let Some(k) = cell {
        Interest::Cell(k)
    } else if t == b"_struct.title" {
        Interest::Title
    } else if let Some(item) = t.strip_prefix(b"_atom_site.") {
        Interest::Atom(role(item))
    } else {
        Interest::None
    }
}

/// What the warning for dropped alternate locations expected (see [`is_altloc_warning`]).
pub(crate) const ALTLOC_EXPECTED: &str =
    "one conformation per atom (label_alt_id: the first is kept)";

/// The warning for a frame that lost `dropped` rows of other alternate locations; `first` says
/// where the first of them is (the location's byte, or a row number).
pub(crate) fn altloc_warning(at: Location, dropped: usize, first: &str) -> Error {
    Error::Parse {
        at,
        expected: ALTLOC_EXPECTED,
        found: format!("{dropped} rows of other alternate locations, dropped ({first})"),
    }
}

/// What a model whose atom count differs from model 1's is checked against.
pub(crate) const MODEL_EXPECTED: &str = "as many _atom_site rows as model 1 (frame 0)";

/// What a set of `_atom_site` columns must have: each item once, and the three coordinates.
pub(crate) const COLUMNS_EXPECTED: &str = "the _atom_site.Cartn_x, Cartn_y and Cartn_z columns";

/// What is wrong with a set of `_atom_site` columns ([`check_roles`]).
pub(crate) enum RolesProblem {
    /// Column `k` (0-based) repeats an item an earlier column has.
    Repeated(usize),
    /// No `Cartn_<axis>` column (the name is given).
    Missing(&'static str),
}

/// Checks the roles of a loop's or category's `_atom_site` columns: each item used at most
/// once, and `Cartn_x/y/z` present.
pub(crate) fn check_roles(roles: &[Role]) -> Result<(), RolesProblem> {
    for (k, r) in roles.iter().enumerate() {
        if *r != Role::Other && roles[..k].contains(r) {
            return Err(RolesProblem::Repeated(k));
        }
    }
    for (axis, r) in ["Cartn_x", "Cartn_y", "Cartn_z"]
        .into_iter()
        .zip([Role::X, Role::Y, Role::Z])
    {
        if !roles.contains(&r) {
            return Err(RolesProblem::Missing(axis));
        }
    }
    Ok(())
}

/// The cell the six `_cell` values (a, b, c, α, β, γ) give, as lengths and angles: `None`
/// without the three lengths, and for the 1 Å x 1 Å x 1 Å placeholder of NMR entries (or zero
/// lengths), dropped as the PDB reader drops it.
pub(crate) fn cell_values(values: [Option<f64>; 6]) -> Option<([f64; 3], [f64; 3])> {
    let (lengths, angles) = cell_parameters(values)?;
    if (lengths == [1.0; 3] && angles == [90.0; 3]) || lengths == [0.0; 3] {
        return None;
    }
    Some((lengths, angles))
}

/// What a `_cell` that gives no cell was expected to be.
pub(crate) const CELL_EXPECTED: &str = "a _cell with lengths > 0 and a volume > 0";

/// Whether a [`crate::Trajectory::warnings`] entry is the PDBx/mmCIF reader's note of dropped
/// alternate locations (given whatever the options), rather than something tolerated under
/// `allow_truncated`.
pub fn is_altloc_warning(w: &Error) -> bool {
    matches!(w, Error::Parse { expected, .. } if *expected == ALTLOC_EXPECTED)
}

/// FNV-1a: the keys of the alternate-location filter (names, residue ids), in the read and in
/// the scan alike.
pub(crate) fn fnv(b: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &x in b {
        h = (h ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Hashes already FNV-hashed keys no further.
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        self.0 = fnv(bytes);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = v;
    }
}

/// The first-conformation rule of the module doc, one residue at a time; `P` is where a row is.
#[derive(Default)]
struct AltFilter<P> {
    /// The current residue (chain, number, insertion code) and its first residue name.
    residue: Option<u64>,
    comp: u64,
    /// Names of the atoms kept in the current residue.
    names: HashSet<u64, BuildHasherDefault<KeyHasher>>,
    /// Rows dropped in this frame, and where the first one starts.
    dropped: usize,
    first_dropped: Option<P>,
}

impl<P: Copy> AltFilter<P> {
    fn reset(&mut self) {
        self.residue = None;
        self.names.clear();
        self.dropped = 0;
        self.first_dropped = None;
    }

    /// Whether to keep a row; `alt` when it has an alternate location.
    fn keep(&mut self, residue: u64, comp: u64, name: u64, alt: bool, at: P) -> bool {
        if self.residue != Some(residue) || (!alt && comp != self.comp) {
            self.residue = Some(residue);
            self.comp = comp;
            // A huge residue must not make every later clear walk its capacity.
            if self.names.capacity() > 1024 {
                self.names = HashSet::default();
            } else {
                self.names.clear();
            }
        }
        // Rows without an alternate location are always kept, but their names are noted.
        let other_residue = alt && comp != self.comp;
        let seen = !other_residue && !self.names.insert(name);
        if other_residue || (alt && seen) {
            self.dropped += 1;
            self.first_dropped.get_or_insert(at);
            return false;
        }
        true
    }
}

/// One `_atom_site` row's values as a frame takes them: what a front-end (the text parser
/// here, the BinaryCIF reader in `crate::bcif`) hands [`AtomSites::push`]. Labels and numbers
/// are filled only when a frame is read; the keys always.
#[derive(Default)]
pub(crate) struct Site {
    pub xyz: [f32; 3],
    pub id: Option<i64>,
    pub symbol: Option<Label>,
    /// `[label, auth]` pairs, as [`Role`]'s.
    pub atom: [Option<Label>; 2],
    pub comp: [Option<Label>; 2],
    pub seq: [Option<i64>; 2],
    pub asym: [Option<Label>; 2],
    /// Occupancy and B-factor (`None` when missing).
    pub scalar: [Option<f32>; 2],
    /// Keys for the alternate-location filter (`[label, auth]`): [`fnv`] of the value's text,
    /// 0 when missing.
    pub atom_key: [u64; 2],
    pub comp_key: [u64; 2],
    pub seq_key: [u64; 2],
    pub asym_key: [u64; 2],
    pub ins_key: u64,
    /// The row has an alternate location (`label_alt_id` not missing).
    pub alt: bool,
}

/// The `_atom_site` row being read: values parsed as they arrive.
#[derive(Default)]
struct Row {
    /// Values seen so far.
    k: usize,
    /// Where its first value is, and whether that value starts its line.
    start: Pos,
    starts_line: bool,
    site: Site,
}

/// Turns `_atom_site` rows into a frame, for both front-ends: which optional columns exist,
/// the alternate-location filter and the atoms kept. `P` is where a row is (a text position,
/// a BinaryCIF row number), for the warning of dropped rows.
#[derive(Default)]
pub(crate) struct AtomSites<P> {
    /// Which optional columns exist: id, atom name, residue name, residue number, chain.
    has: [bool; 5],
    /// Whether there are occupancy and B-factor columns.
    has_scalar: [bool; 2],
    filter: AltFilter<P>,
    /// Atoms kept in the frame so far.
    pub n_atoms: usize,
}

impl<P: Copy> AtomSites<P> {
    /// Notes which optional columns `roles` has (the columns in file order).
    pub fn set_columns(&mut self, roles: &[Role]) {
        let has = |r: Role| roles.contains(&r);
        let any = |f: fn(usize) -> Role| has(f(0)) || has(f(1));
        self.has = [
            has(Role::Id),
            any(Role::Atom),
            any(Role::Comp),
            any(Role::Seq),
            any(Role::Asym),
        ];
        self.has_scalar = [has(Role::Scalar(0)), has(Role::Scalar(1))];
    }

    /// Starts a frame: no atom kept, no row dropped.
    pub fn start_frame(&mut self) {
        self.filter.reset();
        self.n_atoms = 0;
    }

    /// The rows of other alternate locations dropped in this frame, and where the first is.
    pub fn dropped(&self) -> Option<(usize, P)> {
        self.filter
            .first_dropped
            .map(|at| (self.filter.dropped, at))
    }

    /// A whole row (at `at`): through the alternate-location filter into the frame (counted
    /// only, without a frame).
    pub fn push(&mut self, row: &Site, at: P, frame: Option<&mut Frame>) {
        // auth_* wins over label_* where both are given, for the labels and for the keys.
        let pick = |k: [u64; 2]| if k[1] != 0 { k[1] } else { k[0] };
        let residue = [pick(row.asym_key), pick(row.seq_key), row.ins_key]
            .iter()
            .fold(fnv(b""), |h, k| {
                (h ^ k).wrapping_mul(0x0000_0100_0000_01b3).rotate_left(17)
            });
        let (comp, name) = (pick(row.comp_key), pick(row.atom_key));
        if !self.filter.keep(residue, comp, name, row.alt, at) {
            return;
        }
        self.n_atoms += 1;
        let Some(f) = frame else {
            return;
        };
        let name = row.atom[1].or(row.atom[0]).unwrap_or_default();
        let res = row.comp[1].or(row.comp[0]);
        let symbol = row.symbol.as_ref().map(|s| s.as_str());
        let [has_id, has_name, has_res, has_seq, has_chain] = self.has;
        if has_id {
            f.ids.push(row.id.unwrap_or(f.n_atoms() as i64 + 1));
        }
        f.positions.push(row.xyz);
        f.elements
            .push(guess_element(&name, res.as_deref(), symbol));
        if has_name {
            f.names.push(name);
        }
        if has_res {
            f.res_names.push(res.unwrap_or_default());
        }
        if has_seq {
            f.res_ids.push(row.seq[1].or(row.seq[0]).unwrap_or(0));
        }
        if has_chain {
            f.chains
                .push(row.asym[1].or(row.asym[0]).unwrap_or_default());
        }
        for (k, (name, _, missing)) in SCALAR_NAMES.iter().enumerate() {
            if self.has_scalar[k] {
                f.property_mut(name).push(row.scalar[k].unwrap_or(*missing));
            }
        }
    }
}

/// Where the parser is in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
enum Phase {
    /// Before `data_`.
    #[default]
    Start,
    /// Between items of the data block.
    Block,
    /// After a tag, before its value.
    Item(Interest),
    /// After `loop_`, reading its tags.
    LoopTags,
    /// The values of a loop other than `_atom_site`.
    Loop,
    /// `_atom_site.item value` pairs (a one-row category); `true` while a value is due.
    Pairs(bool),
    /// The `_atom_site` rows.
    Rows,
}

/// The properties of the `Role::Scalar` columns: name, what a bad value should have been, the
/// value of a missing one (`?` or `.`), as MDAnalysis and the PDB reader fill blanks.
pub(crate) const SCALAR_NAMES: [(&str, &str, f32); 2] = [
    ("occupancy", "a number for _atom_site.occupancy", 1.0),
    ("bfactor", "a number for _atom_site.B_iso_or_equiv", 0.0),
];

/// `Cartn_x/y/z` errors, by axis.
pub(crate) const NOT_A_COORDINATE: [&str; 3] = [
    "a number for _atom_site.Cartn_x",
    "a number for _atom_site.Cartn_y",
    "a number for _atom_site.Cartn_z",
];

/// The PDBx/mmCIF frame parser (see the module doc).
#[derive(Default)]
pub(crate) struct Mmcif {
    lex: Lexer,
    /// Boxed: the row and header state would make every `Trajectory` as large.
    p: Box<Parser>,
    models: ModelCheck,
}

#[derive(Default)]
struct Parser {
    phase: Phase,
    /// The `_atom_site` columns (empty until the loop's header is read).
    cols: Vec<Role>,
    /// `_cell` values and where the first one is; the cell built from them.
    cell_values: [Option<f64>; 6],
    cell_at: Option<Pos>,
    cell: Option<UnitCell>,
    title: Option<String>,
    /// Byte offset where reading stopped after the `_atom_site` loop: no frame starts past it.
    rows_end: Option<u64>,
    /// The current loop's tags with where each is, and where the loop and its current row start.
    tags: Vec<(Interest, Pos)>,
    loop_at: Pos,
    loop_values: usize,
    loop_row: Pos,
    /// `_atom_site` pairs: roles with their tag position, values with theirs.
    pairs: Vec<(Role, Pos)>,
    pair_values: Vec<(Kind, Vec<u8>, Pos)>,
    row: Row,
    /// The frame's model number and first row; the rows made into atoms.
    model: Option<i64>,
    first_row: Option<Pos>,
    sites: AtomSites<Pos>,
}

impl Mmcif {
    /// A parser; `lenient` turns an atom count that differs from model 1's into a warning.
    pub(crate) fn new(lenient: bool) -> Mmcif {
        Mmcif {
            models: ModelCheck::new(lenient),
            ..Mmcif::default()
        }
    }

    /// The warnings gathered so far (emptied).
    pub(crate) fn take_warnings(&mut self) -> Vec<Error> {
        self.models.take_warnings()
    }

    /// Closes a frame whose rows ended at `end`: the atom-count check, the warning for dropped
    /// alternate locations, the cell and (frame 0) the title. `Ok(false)` for a loop without rows.
    fn finish(&mut self, ctx: &Ctx, end: Pos, frame: Option<&mut Frame>) -> Result<bool, Error> {
        let p = &mut self.p;
        if p.sites.n_atoms == 0 {
            return Ok(false);
        }
        let at = p.first_row.unwrap_or(end);
        self.models
            .check(ctx, at, p.sites.n_atoms, MODEL_EXPECTED)?;
        if let Some((dropped, first)) = p.sites.dropped() {
            let w = altloc_warning(ctx.at(first), dropped, "the first here");
            self.models.warn(ctx.frame, ALTLOC_EXPECTED, w);
        }
        if let Some(f) = frame {
            f.cell = p.cell;
            if ctx.frame == 0
                && let Some(t) = &p.title
            {
                f.comment.clone_from(t);
            }
        }
        Ok(true)
    }
}

impl FrameWalk for Mmcif {
    /// Reads (with a frame) or checks (without) the frame starting at the next line.
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        let start = lines.pos();
        // No frame starts inside a text field (a failed read may have left one open).
        self.lex.open = None;
        if ctx.frame == 0 {
            // Frame 0 holds the header: read it afresh. Where the rows end is a property of
            // the file, kept for the frames after them.
            let rows_end = self.p.rows_end;
            *self.p = Parser {
                rows_end,
                ..Parser::default()
            };
        } else {
            // Frame k > 0 starts at a row of the loop frame 0 found; past the loop there is none.
            if self.p.cols.is_empty() || self.p.rows_end.is_some_and(|e| start.byte >= e) {
                return Ok(false);
            }
            self.p.phase = Phase::Rows;
        }
        self.p.model = None;
        self.p.first_row = None;
        self.p.row = Row::default();
        self.p.sites.start_frame();
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if let Some(open) = self.lex.open {
                    return Err(ctx.truncated(
                        open,
                        "a line starting with ';' to close the text field that opens here".into(),
                    ));
                }
                self.p.end_of_data(ctx, p, frame.as_deref_mut())?;
                self.p.rows_end = Some(p.byte);
                return self.finish(ctx, p, frame);
            };
            let Mmcif { lex, p: parser, .. } = self;
            let flow = lex
                .line(line, pos, ctx, |tok| {
                    let flow = parser.token(tok, ctx, frame.as_deref_mut())?;
                    Ok((flow != Flow::More).then_some(flow))
                })?
                .unwrap_or(Flow::More);
            match flow {
                Flow::More => {}
                Flow::NextModel => {
                    lines.unread(pos);
                    return self.finish(ctx, pos, frame);
                }
                Flow::LoopEnd => {
                    self.p.rows_end = Some(lines.pos().byte);
                    return self.finish(ctx, lines.pos(), frame);
                }
            }
        }
    }
}

impl Parser {
    /// Takes one token.
    fn token(&mut self, tok: Tok, ctx: &Ctx, frame: Option<&mut Frame>) -> Result<Flow, Error> {
        match self.phase {
            Phase::Start => match tok.kind {
                Kind::Data => {
                    self.phase = Phase::Block;
                    Ok(Flow::More)
                }
                _ => Err(tok.error(ctx, "a data_ block header (PDBx/mmCIF)")),
            },
            Phase::Block => self.block(tok, ctx),
            Phase::Item(what) => {
                if !tok.is_value() {
                    return Err(tok.error(ctx, "a value after the tag"));
                }
                self.keep(what, &tok, ctx)?;
                self.phase = Phase::Block;
                Ok(Flow::More)
            }
            Phase::LoopTags => {
                if tok.kind == Kind::Tag {
                    self.tags.push((interest(tok.text), tok.at));
                    return Ok(Flow::More);
                }
                if self.tags.is_empty() {
                    return Err(tok.error(ctx, "a tag after loop_"));
                }
                if self.atom_loop(ctx)? {
                    return self.rows(tok, ctx, frame);
                }
                self.phase = Phase::Loop;
                self.loop_values = 0;
                self.token(tok, ctx, frame)
            }
            Phase::Loop => {
                let n = self.tags.len();
                if tok.is_value() {
                    if self.loop_values.is_multiple_of(n) {
                        self.loop_row = tok.at;
                    }
                    // Categories of interest are read from the loop's first row.
                    if self.loop_values < n {
                        self.keep(self.tags[self.loop_values].0, &tok, ctx)?;
                    }
                    self.loop_values += 1;
                    return Ok(Flow::More);
                }
                if !self.loop_values.is_multiple_of(n) {
                    return Err(Error::Parse {
                        at: ctx.at(self.loop_row),
                        expected: "as many values in each loop row as the loop has tags",
                        found: format!("{} of {n} values in the last row", self.loop_values % n),
                    });
                }
                self.phase = Phase::Block;
                self.block(tok, ctx)
            }
            Phase::Pairs(value_due) => {
                if value_due {
                    if !tok.is_value() {
                        return Err(tok.error(ctx, "a value after the tag"));
                    }
                    self.pair_values.push((tok.kind, tok.text.to_vec(), tok.at));
                    self.phase = Phase::Pairs(false);
                    return Ok(Flow::More);
                }
                if tok.kind == Kind::Tag
                    && let Interest::Atom(r) = interest(tok.text)
                {
                    self.pairs.push((r, tok.at));
                    self.phase = Phase::Pairs(true);
                    return Ok(Flow::More);
                }
                self.end_pairs(ctx, frame)?;
                Ok(Flow::LoopEnd)
            }
            Phase::Rows => self.rows(tok, ctx, frame),
        }
    }

    /// A token between items of the data block.
    fn block(&mut self, tok: Tok, ctx: &Ctx) -> Result<Flow, Error> {
        match tok.kind {
            Kind::Tag => match interest(tok.text) {
                Interest::Atom(r) => {
                    self.pairs.clear();
                    self.pair_values.clear();
                    self.pairs.push((r, tok.at));
                    self.phase = Phase::Pairs(true);
                }
                what => self.phase = Phase::Item(what),
            },
            Kind::Loop => {
                self.tags.clear();
                self.loop_at = tok.at;
                self.phase = Phase::LoopTags;
            }
            Kind::Data => {
                return Err(tok.error(ctx, "an _atom_site loop in the first data block"));
            }
            Kind::Reserved => {}
            Kind::Bare | Kind::Quoted => {
                return Err(tok.error(ctx, "a tag or loop_ (a value without a tag)"));
            }
        }
        Ok(Flow::More)
    }

    /// After a loop's tags: when it is the `_atom_site` loop, sets up its columns and moves to
    /// its rows.
    fn atom_loop(&mut self, ctx: &Ctx) -> Result<bool, Error> {
        if !matches!(self.tags.first(), Some((Interest::Atom(_), _))) {
            return Ok(false);
        }
        let roles: Vec<_> = (self.tags.iter())
            .map(|(i, at)| match i {
                Interest::Atom(r) => (*r, *at),
                _ => (Role::Other, *at),
            })
            .collect();
        self.columns(&roles, self.loop_at, ctx)?;
        self.phase = Phase::Rows;
        Ok(true)
    }

    /// Keeps a header value of interest (`_cell`, `_struct.title`).
    fn keep(&mut self, what: Interest, tok: &Tok, ctx: &Ctx) -> Result<(), Error> {
        match what {
            Interest::Cell(k) => {
                self.cell_values[k] = cell_number(tok, ctx)?;
                self.cell_at.get_or_insert(tok.at);
            }
            Interest::Title if !tok.missing() => {
                self.title = Some(String::from_utf8_lossy(tok.text).trim().to_string());
            }
            _ => {}
        }
        Ok(())
    }

    /// Sets up the `_atom_site` columns from their roles (with where each tag is), and the cell
    /// from the `_cell` values read so far. `at` is where the loop (or first pair) starts.
    fn columns(&mut self, roles: &[(Role, Pos)], at: Pos, ctx: &Ctx) -> Result<(), Error> {
        let cols: Vec<Role> = roles.iter().map(|(r, _)| *r).collect();
        match check_roles(&cols) {
            Ok(()) => {}
            Err(RolesProblem::Repeated(k)) => {
                return Err(Error::Parse {
                    at: ctx.at(roles[k].1),
                    expected: "each _atom_site tag once",
                    found: format!("the same item again in column {}", k + 1),
                });
            }
            Err(RolesProblem::Missing(axis)) => {
                return Err(Error::Parse {
                    at: ctx.at(at),
                    expected: COLUMNS_EXPECTED,
                    found: format!("no _atom_site.{axis} among the loop's tags"),
                });
            }
        }
        self.sites.set_columns(&cols);
        self.cols = cols;
        self.cell = self.unit_cell(ctx)?;
        Ok(())
    }

    /// The cell of the `_cell` values, `None` without lengths or for the 1 Å placeholder.
    fn unit_cell(&self, ctx: &Ctx) -> Result<Option<UnitCell>, Error> {
        let Some((lengths, angles)) = cell_values(self.cell_values) else {
            return Ok(None);
        };
        let at = self.cell_at.unwrap_or_default();
        cell_of(lengths, angles, ctx, at, CELL_EXPECTED).map(Some)
    }

    /// A token of the `_atom_site` rows.
    fn rows(&mut self, tok: Tok, ctx: &Ctx, frame: Option<&mut Frame>) -> Result<Flow, Error> {
        if !tok.is_value() {
            self.loop_end(ctx)?;
            return Ok(Flow::LoopEnd);
        }
        self.value(tok, ctx, frame)
    }

    /// The loop ends: the last row must be whole.
    fn loop_end(&self, ctx: &Ctx) -> Result<(), Error> {
        if self.row.k == 0 {
            return Ok(());
        }
        Err(Error::Parse {
            at: ctx.at(self.row.start),
            expected: "as many values in each _atom_site row as the loop has tags",
            found: format!("{} of {} values in this row", self.row.k, self.cols.len()),
        })
    }

    /// The end of the data: a header without `_atom_site`, a cut row, or the end of the rows.
    fn end_of_data(&mut self, ctx: &Ctx, at: Pos, frame: Option<&mut Frame>) -> Result<(), Error> {
        match self.phase {
            Phase::Rows if self.row.k > 0 => Err(ctx.truncated(
                self.row.start,
                format!(
                    "{} more values of the _atom_site row that starts here",
                    self.cols.len() - self.row.k
                ),
            )),
            Phase::Rows => Ok(()),
            Phase::Pairs(false) => self.end_pairs(ctx, frame),
            // An _atom_site loop without rows: no frame.
            Phase::LoopTags if matches!(self.tags.first(), Some((Interest::Atom(_), _))) => {
                self.atom_loop(ctx).map(|_| ())
            }
            Phase::Item(_) | Phase::Pairs(true) => {
                Err(ctx.truncated(at, "a value after the last tag".into()))
            }
            _ => Err(Error::Parse {
                at: ctx.at(at),
                expected: "an _atom_site loop in the first data block",
                found: "end of file".into(),
            }),
        }
    }

    /// `_atom_site` pairs end: their tags are the columns, their values the one row.
    fn end_pairs(&mut self, ctx: &Ctx, mut frame: Option<&mut Frame>) -> Result<(), Error> {
        let roles = std::mem::take(&mut self.pairs);
        let at = roles.first().map_or_else(Pos::default, |r| r.1);
        self.columns(&roles, at, ctx)?;
        self.phase = Phase::Rows;
        let values = std::mem::take(&mut self.pair_values);
        for (kind, text, at) in &values {
            let tok = Tok {
                kind: *kind,
                text,
                at: *at,
                starts_line: false,
            };
            self.value(tok, ctx, frame.as_deref_mut())?;
        }
        self.pairs = roles;
        self.pair_values = values;
        Ok(())
    }

    /// One value of an `_atom_site` row, parsed as it arrives; the row is kept when whole.
    fn value(&mut self, tok: Tok, ctx: &Ctx, frame: Option<&mut Frame>) -> Result<Flow, Error> {
        let read = frame.is_some();
        let row = &mut self.row;
        if row.k == 0 {
            row.start = tok.at;
            row.starts_line = tok.starts_line;
        }
        let key = |t: &Tok| if t.missing() { 0 } else { fnv(t.text) };
        let label = |t: &Tok, what: &'static str| -> Result<Option<Label>, Error> {
            if !read || t.missing() {
                return Ok(None);
            }
            Label::from_utf8(t.text)
                .map(Some)
                .ok_or_else(|| t.error(ctx, what))
        };
        match self.cols[row.k] {
            r @ (Role::X | Role::Y | Role::Z) if read => {
                let axis = match r {
                    Role::X => 0,
                    Role::Y => 1,
                    _ => 2,
                };
                row.site.xyz[axis] = match tok.missing() {
                    true => None,
                    false => parse_f32(strip_esd(tok.text)),
                }
                .ok_or_else(|| tok.error(ctx, NOT_A_COORDINATE[axis]))?;
            }
            Role::Id if read && !tok.missing() => {
                let id = parse_i64(tok.text)
                    .ok_or_else(|| tok.error(ctx, "an integer _atom_site.id"))?;
                row.site.id = Some(id);
            }
            Role::Symbol => row.site.symbol = label(&tok, "an element symbol in type_symbol")?,
            Role::AltId => row.site.alt = !tok.missing(),
            Role::InsCode => row.site.ins_key = key(&tok),
            Role::Asym(k) => {
                row.site.asym_key[k] = key(&tok);
                row.site.asym[k] = label(&tok, "a chain name of at most 15 bytes")?;
            }
            Role::Atom(k) => {
                row.site.atom_key[k] = key(&tok);
                row.site.atom[k] = label(&tok, "an atom name of at most 15 bytes")?;
            }
            Role::Comp(k) => {
                row.site.comp_key[k] = key(&tok);
                row.site.comp[k] = label(&tok, "a residue name of at most 15 bytes")?;
            }
            Role::Seq(k) => {
                row.site.seq_key[k] = key(&tok);
                if read && !tok.missing() {
                    let s = parse_i64(tok.text)
                        .ok_or_else(|| tok.error(ctx, "an integer residue number (seq_id)"))?;
                    row.site.seq[k] = Some(s);
                }
            }
            Role::Scalar(k) if read && !tok.missing() => {
                let v = parse_f32(strip_esd(tok.text))
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| tok.error(ctx, SCALAR_NAMES[k].1))?;
                row.site.scalar[k] = Some(v);
            }
            Role::Model => {
                let m = (!tok.missing())
                    .then(|| parse_i64(tok.text))
                    .flatten()
                    .ok_or_else(|| tok.error(ctx, "an integer pdbx_PDB_model_num"))?;
                match self.model {
                    None => self.model = Some(m),
                    Some(cur) if m == cur => {}
                    Some(cur) if m > cur => {
                        // The row opens the next model: this frame ends before it.
                        if row.starts_line && row.start.line == tok.at.line {
                            return Ok(Flow::NextModel);
                        }
                        return Err(tok.error(
                            ctx,
                            "a new model's first _atom_site row at the start of a line",
                        ));
                    }
                    Some(cur) => {
                        return Err(Error::Parse {
                            at: ctx.at(tok.at),
                            expected: "increasing pdbx_PDB_model_num, each model's rows together",
                            found: format!("model {m} after model {cur}"),
                        });
                    }
                }
            }
            _ => {}
        }
        row.k += 1;
        if row.k == self.cols.len() {
            self.end_row(frame);
        }
        Ok(Flow::More)
    }

    /// A whole row: through the alternate-location filter into the frame.
    fn end_row(&mut self, frame: Option<&mut Frame>) {
        let row = std::mem::take(&mut self.row);
        self.first_row.get_or_insert(row.start);
        self.sites.push(&row.site, row.start, frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserved_words_and_esds() {
        assert_eq!(classify(b"LOOP_"), Kind::Loop);
        assert_eq!(classify(b"data_1ABC"), Kind::Data);
        assert_eq!(classify(b"_atom_site.id"), Kind::Tag);
        assert_eq!(classify(b"save_frame"), Kind::Reserved);
        assert_eq!(classify(b"loops"), Kind::Bare);
        assert_eq!(strip_esd(b"12.345(6)"), b"12.345");
        assert_eq!(strip_esd(b"(6)"), b"");
        assert_eq!(strip_esd(b"1.5(a)"), b"1.5(a)");
        assert_eq!(role(b"cartn_x"), Role::X);
        assert_eq!(interest(b"_ATOM_SITE.Cartn_Y"), Interest::Atom(Role::Y));
        assert_eq!(interest(b"_atom_site_anisotrop.id"), Interest::None);
        assert_eq!(interest(b"_cell.angle_gamma"), Interest::Cell(5));
    }
}

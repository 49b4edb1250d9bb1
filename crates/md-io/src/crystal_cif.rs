//! Crystallographic (small-molecule and inorganic) CIF: the files the Crystallography Open
//! Database (COD), ICSD, the Materials Project (pymatgen), VESTA and SHELXL write, with the
//! asymmetric unit expanded by the file's symmetry operations into the full unit cell.
//!
//! These use the DDL1 core dictionary's names (`_cell_length_a`, `_atom_site_fract_x`,
//! `_symmetry_equiv_pos_as_xyz`), where PDBx/mmCIF ([`crate::mmcif`]) uses DDL2's
//! `_atom_site.Cartn_x`. DDLm's dotted spellings of the same items (`_cell.length_a`,
//! `_atom_site.fract_x`, `_space_group_symop.operation_xyz`) are read as the DDL1 names.
//!
//! # What is read
//! Every data block (`data_…`) holding atom sites is one frame, in file order (a COD file has
//! one); blocks without atom sites (an IUCr paper's `data_global`) are passed over. A block is
//! gathered whole before it is interpreted, so its items may come in any order (the operations
//! after the atoms). Of each block:
//! - The cell: `_cell_length_a/b/c` (Å) and `_cell_angle_alpha/beta/gamma` (degrees, 90 when
//!   absent), standard uncertainties (`4.348(5)`) dropped, oriented as [`UnitCell`]'s
//!   `from_lengths_angles` does (a along x, b in the xy plane), which is also the CIF's default
//!   Cartesian frame.
//! - The sites, an `_atom_site_` loop (or, for one site, `_atom_site_` items): `label` (the
//!   frame's [`Frame::names`]), `type_symbol` (the frame's [`Frame::types`], as written, e.g.
//!   `Fe2+`), `fract_x/y/z`, else `Cartn_x/y/z` (Å, converted to fractions through the cell),
//!   `occupancy` (the `occupancy` property; 1 when missing), `U_iso_or_equiv` or
//!   `B_iso_or_equiv` (the `bfactor` property in Å², B = 8π²U; 0 when missing). A property
//!   exists when its column does. The element comes from the type symbol with its charge
//!   dropped (`Fe3+`, `O2-`: the leading symbol, two letters when the second is lower case,
//!   `D` read as H), else from the label by [`crate::elements::guess_element`] (`Fe1`, `O12a`).
//!   `_atom_site_aniso_*` (anisotropic displacements) is another category and is not read.
//! - The symmetry operations: `_space_group_symop_operation_xyz`, else
//!   `_symmetry_equiv_pos_as_xyz` (ASE's order of preference, for files that give both), in
//!   the notation of International Tables Vol. A: three comma-separated expressions in x, y, z
//!   with rational or decimal translations (`x,y,z`, `-y,x-y,z+1/3`, `1/2+x,-y+1/2,z`,
//!   `x+0.5`, `'-x, -y, -z'`), blanks anywhere, an optional leading operation number
//!   (`'1 x,y,z'`); an operation id column beside it is ignored. The list is taken as the
//!   file gives it, centring translations included (as COD, ICSD and pymatgen write it).
//!   Without a list, a block whose space group (`_symmetry_space_group_name_H-M`,
//!   `_space_group_name_H-M_alt`, the Hall symbol, `_symmetry_Int_Tables_number`,
//!   `_space_group_IT_number`) is P 1, or that names none, has its sites taken as they are (the
//!   identity); any other space group is an error that names it: no space-group table is
//!   carried here to make up the operations.
//! - The comment: the block's name, then `: ` and `_chemical_name_mineral`, else
//!   `_chemical_formula_sum`, when given (`9001665: Artroeite`, `mp-149: Si`).
//!
//! # Expansion
//! Every site is mapped by every operation (x' = R x + t, in fractions, f64) and wrapped into
//! [0, 1). An image closer than [`MERGE_TOLERANCE`] (0.02 Å) to an image already made of the
//! same site, measured through the cell with the minimum image, is the same atom: a site on a
//! special position gives as many atoms as its multiplicity, not one per operation. The atoms
//! are ordered site by site (all images of the first site in operation order, then the
//! second's, ...), each carrying its site's label, type, occupancy and B; ids are 1..n.
//!
//! ASE (`ase.io.read`, through `ase.spacegroup.Spacegroup.equivalent_sites`) merges images
//! whose fractional coordinates all differ by less than `symprec` = 10⁻³ (per axis, wrapped):
//! 0.005-0.02 Å per axis in common cells, more along a long axis. A tolerance in Å is the same
//! for every cell and direction; 0.02 Å is above the rounding of coordinates written to four
//! decimals in cells up to about 40 Å (and of `0.333`-style thirds in cells up to 10 Å), and
//! far below any distance between two real atoms. Where ASE goes further, this reader does
//! not: ASE also drops a whole site that lies on an image of an earlier one, and keeps one
//! atom (the species of largest occupancy) where partially occupied sites share a position
//! (a mixed Fe/Mg site). Here every site listed gives its own atoms, each with its
//! occupancy: nothing in the file is dropped, and a drawing picks what it shows with a
//! selection (`prop occupancy > 0.5`). In files without such sites (the eight COD minerals
//! the tests compare with ASE) the two agree atom for atom.
//!
//! # Syntax and damage
//! Tokens are CIF 1.1's ([`crate::cif`]). Errors name the file, frame, line and byte of the
//! token at fault and what was expected: a symmetry operation that does not parse (the token
//! named) or is no crystallographic operation (its matrix not integer with determinant ±1),
//! more than 192 operations (the most a space group has, Fm-3m's conventional cell), a
//! coordinate or cell value that is not a number, a loop row with too few values, a loop
//! without values, a tag without a value, an unterminated quote or text field, a site loop
//! without x/y/z columns, a cell that is no cell, fractional sites without a cell, a space
//! group without operations, a file without atom sites. Where the data ends inside a
//! block, it is a truncation. Memory follows the file: the block's sites and operations, each
//! taken from bytes of the file, and at most 192 images per site. Coordinates, occupancies
//! and B beyond ±10⁷ are damage too (wrapping them would hide it).
//!
//! # Design
//! The block is gathered (sites, operations, cell values) and then expanded, since CIF lets
//! the operations follow the atoms; the sites' values are parsed as they arrive, so an error
//! points at its token. A scan ([`crate::text`]'s frame index, the frame count) walks a
//! block as a read does, values parsed, and skips only the expansion: blocks are small, and a
//! value the end of the data cuts (`1/2+x,1/`) must be the same truncation to both. The
//! rejected alternative, a scan that parses no values (as the PDB and mmCIF readers do over
//! millions of atoms), would call a file cut inside its operation list damaged to the count
//! and cut to the read. Frames end where the next block's `data_` line starts; that line must
//! start with it (every writer does so).
//!
//! # References
//! - S. R. Hall, F. H. Allen, I. D. Brown, "The Crystallographic Information File (CIF)", Acta
//!   Cryst. A47 (1991) 655; CIF 1.1 syntax specification (IUCr, 2003); the core CIF dictionary
//!   (`cif_core.dic`, DDL1), categories CELL, ATOM_SITE, SYMMETRY, SYMMETRY_EQUIV,
//!   SPACE_GROUP_SYMOP.
//! - International Tables for Crystallography Vol. A (2016), section 1.4 (the x, y, z
//!   notation of symmetry operations).
//! - ASE 3.29, `ase/io/cif.py` and `ase/spacegroup/spacegroup.py` (`equivalent_sites`): the
//!   reading the tests compare with.

use std::io::Read;

use crate::cif::{Kind, Lexer, Tok, cell_number, cell_of, cell_parameters, number, strip_esd};
use crate::elements::{Element, guess_element};
use crate::error::Error;
use crate::frame::{Frame, Label, MAX_COORDINATE, UnitCell};
use crate::parse::{parse_f64, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};

/// Two images of one site closer than this (Å, minimum image through the cell) are one atom
/// (see the module doc for the choice and ASE's `symprec`).
pub const MERGE_TOLERANCE: f64 = 0.02;

/// Most symmetry operations a block may list: the order of the largest space group in its
/// conventional cell (Fm-3m and its kin: 48 point operations times 4 centring translations).
const MAX_OPERATIONS: usize = 192;

/// An `_atom_site_` column the reader uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Site {
    Label,
    Type,
    Fract(usize),
    Cartn(usize),
    Occupancy,
    Uiso,
    Biso,
    Other,
}

/// What the reader does with a tag's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    None,
    /// a, b, c, α, β, γ.
    Cell(usize),
    /// The space group: H-M name, Hall symbol, number.
    Group(usize),
    /// The mineral name, the formula sum (for the comment).
    Name(usize),
    /// An operation list: 0 `_space_group_symop_operation_xyz`, 1 `_symmetry_equiv_pos_as_xyz`.
    Op(usize),
    Site(Site),
}

/// The role of a tag (case-insensitive; a DDLm `.` read as DDL1's `_`).
fn role(tag: &[u8]) -> Role {
    let mut buf = [0u8; 48];
    if tag.len() > buf.len() {
        return Role::None;
    }
    let t = &mut buf[..tag.len()];
    for (o, b) in t.iter_mut().zip(tag) {
        *o = if *b == b'.' {
            b'_'
        } else {
            b.to_ascii_lowercase()
        };
    }
    let t = &*t;
    const CELL: [&[u8]; 6] = [
        b"_cell_length_a",
        b"_cell_length_b",
        b"_cell_length_c",
        b"_cell_angle_alpha",
        b"_cell_angle_beta",
        b"_cell_angle_gamma",
    ];
    if let Some(k) = CELL.iter().position(|c| *c == t) {
        return Role::Cell(k);
    }
    match t {
        b"_symmetry_space_group_name_h-m" | b"_space_group_name_h-m_alt" => Role::Group(0),
        b"_symmetry_space_group_name_hall" | b"_space_group_name_hall" => Role::Group(1),
        b"_symmetry_int_tables_number" | b"_space_group_it_number" => Role::Group(2),
        b"_chemical_name_mineral" => Role::Name(0),
        b"_chemical_formula_sum" => Role::Name(1),
        b"_space_group_symop_operation_xyz" => Role::Op(0),
        b"_symmetry_equiv_pos_as_xyz" => Role::Op(1),
        _ => match t.strip_prefix(b"_atom_site_") {
            Some(item) if !item.starts_with(b"aniso") => Role::Site(match item {
                b"label" => Site::Label,
                b"type_symbol" => Site::Type,
                b"fract_x" => Site::Fract(0),
                b"fract_y" => Site::Fract(1),
                b"fract_z" => Site::Fract(2),
                b"cartn_x" => Site::Cartn(0),
                b"cartn_y" => Site::Cartn(1),
                b"cartn_z" => Site::Cartn(2),
                b"occupancy" => Site::Occupancy,
                b"u_iso_or_equiv" => Site::Uiso,
                b"b_iso_or_equiv" => Site::Biso,
                _ => Site::Other,
            }),
            _ => Role::None,
        },
    }
}

/// A symmetry operation x' = R x + t on fractional coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Op {
    rot: [[f64; 3]; 3],
    trans: [f64; 3],
}

const IDENTITY: Op = Op {
    rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    trans: [0.0; 3],
};

impl Op {
    fn apply(&self, f: [f64; 3]) -> [f64; 3] {
        let r = &self.rot;
        [0, 1, 2].map(|k| r[k][0] * f[0] + r[k][1] * f[1] + r[k][2] * f[2] + self.trans[k])
    }
}

/// Parses an operation in the x, y, z notation (see the module doc); `None` when it is not one.
fn parse_op(text: &[u8]) -> Option<Op> {
    let t = trim(text);
    // An optional operation number before the operation: `1 x,y,z`.
    let t = match t.iter().position(|b| matches!(b, b' ' | b'\t')) {
        Some(k) if t[..k].iter().all(u8::is_ascii_digit) && k > 0 => trim(&t[k..]),
        _ => t,
    };
    let mut op = Op {
        rot: [[0.0; 3]; 3],
        trans: [0.0; 3],
    };
    let mut parts = t.split(|b| *b == b',');
    for k in 0..3 {
        expression(parts.next()?, &mut op.rot[k], &mut op.trans[k])?;
    }
    if parts.next().is_some() {
        return None;
    }
    // A crystallographic operation: an integer matrix with determinant ±1, a finite translation.
    let r = &op.rot;
    let integer = r
        .iter()
        .flatten()
        .all(|v| v.fract() == 0.0 && v.abs() <= 3.0);
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    let finite = op.trans.iter().all(|v| v.is_finite() && v.abs() <= 1e3);
    (integer && det.abs() == 1.0 && finite).then_some(op)
}

/// One component of an operation: signed terms, each a variable with an optional coefficient
/// (`x`, `-y`, `2*z`) or a number (`1/2`, `0.5`, `.25`); blanks anywhere.
fn expression(p: &[u8], rot: &mut [f64; 3], trans: &mut f64) -> Option<()> {
    let b: Vec<u8> = p
        .iter()
        .copied()
        .filter(|c| !matches!(c, b' ' | b'\t'))
        .collect();
    let mut i = 0;
    let mut terms = 0;
    let unsigned = |i: &mut usize| -> Option<Option<f64>> {
        let start = *i;
        while *i < b.len() && (b[*i].is_ascii_digit() || b[*i] == b'.') {
            *i += 1;
        }
        if *i == start {
            return Some(None);
        }
        parse_f64(&b[start..*i]).map(Some)
    };
    while i < b.len() {
        let sign = match b[i] {
            b'+' => 1.0,
            b'-' => -1.0,
            // Only the first term may go without a sign.
            _ if terms == 0 => 0.0,
            _ => return None,
        };
        if sign != 0.0 {
            i += 1;
        }
        let sign = if sign == 0.0 { 1.0 } else { sign };
        let mut num = unsigned(&mut i)?;
        if let Some(n) = num
            && b.get(i) == Some(&b'/')
        {
            i += 1;
            let d = unsigned(&mut i)?.filter(|d| *d != 0.0)?;
            num = Some(n / d);
        }
        let star = num.is_some() && b.get(i) == Some(&b'*');
        if star {
            i += 1;
        }
        let var = match b.get(i).map(u8::to_ascii_lowercase) {
            Some(c @ b'x'..=b'z') => {
                i += 1;
                Some((c - b'x') as usize)
            }
            _ => None,
        };
        match (num, var) {
            (_, Some(k)) => rot[k] += sign * num.unwrap_or(1.0),
            (Some(n), None) if !star => *trans += sign * n,
            _ => return None,
        }
        terms += 1;
    }
    (terms > 0).then_some(())
}

/// One atom site as read: what its row gives.
#[derive(Clone, Copy, Debug, Default)]
struct SiteRow {
    label: Option<Label>,
    kind: Option<Label>,
    fract: [Option<f64>; 3],
    cartn: [Option<f64>; 3],
    occupancy: Option<f32>,
    u: Option<f32>,
    b: Option<f32>,
    /// Where the row (or the first item) starts.
    at: Pos,
}

/// The block's atom-site table: its columns (Cartesian ones mapped to `Other` when the
/// fractional ones are there) and where it starts.
#[derive(Clone, Debug, Default)]
struct Table {
    cols: Vec<Site>,
    at: Pos,
    cartesian: bool,
}

impl Table {
    fn has(&self, s: Site) -> bool {
        self.cols.contains(&s)
    }
}

/// Where the parser is in the block.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
enum Phase {
    /// Before `data_`.
    #[default]
    Start,
    /// Between items of the block.
    Block,
    /// After a tag (its role and where it is), before its value.
    Item(Role, Pos),
    /// After `loop_`, reading its tags.
    LoopTags,
    /// A loop's values.
    Loop,
}

/// What a block has gathered.
#[derive(Default)]
struct Block {
    phase: Phase,
    name: String,
    cell: [Option<f64>; 6],
    cell_at: Option<Pos>,
    /// H-M name, Hall symbol, number, each with where its value is.
    group: [Option<(String, Pos)>; 3],
    names: [Option<String>; 2],
    ops: [Vec<Op>; 2],
    /// The atom-site loop's table, once its tags are read.
    table: Option<Table>,
    /// The sites read (rows, or the one site of items).
    sites: Vec<SiteRow>,
    /// `_atom_site_` items outside a loop (one site): their columns and values.
    pairs: Vec<(Site, Pos)>,
    pair: SiteRow,
    /// The current loop: tags, where it starts, values so far, the row being read.
    tags: Vec<(Role, Pos)>,
    loop_at: Pos,
    values: usize,
    row: SiteRow,
    atom_loop: bool,
}

/// Why the lexer was stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stop {
    /// The next block's `data_` starts this line and the block read holds atom sites: the frame
    /// ends before the line.
    NextBlock,
}

/// The crystallographic CIF frame parser (see the module doc).
#[derive(Default)]
pub(crate) struct CrystalCif {
    lex: Lexer,
    /// Boxed: the block state would make every `Trajectory` as large.
    b: Box<Block>,
}

impl FrameWalk for CrystalCif {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        // No frame starts inside a text field (a failed read may have left one open).
        self.lex.open = None;
        self.b.reset(Phase::Start);
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if let Some(open) = self.lex.open {
                    return Err(ctx.truncated(
                        open,
                        "a line starting with ';' to close the text field that opens here".into(),
                    ));
                }
                self.b.end_of_data(ctx, p)?;
                if !self.b.has_sites() {
                    if ctx.frame > 0 {
                        return Ok(false);
                    }
                    return Err(Error::Parse {
                        at: ctx.at(p),
                        expected: "a data block with atom sites (an _atom_site_ loop with \
                                   fract_x/y/z or Cartn_x/y/z)",
                        found: "end of file".into(),
                    });
                }
                return self.b.finish(ctx, frame).map(|_| true);
            };
            let CrystalCif { lex, b } = self;
            let stop = lex.line(line, pos, ctx, |tok| b.token(tok, ctx))?;
            if let Some(Stop::NextBlock) = stop {
                lines.unread(pos);
                return self.b.finish(ctx, frame.as_deref_mut()).map(|_| true);
            }
        }
    }
}

impl Block {
    /// Forgets everything read, keeping the buffers.
    fn reset(&mut self, phase: Phase) {
        let mut sites = std::mem::take(&mut self.sites);
        let mut tags = std::mem::take(&mut self.tags);
        let mut pairs = std::mem::take(&mut self.pairs);
        let mut ops = std::mem::take(&mut self.ops);
        sites.clear();
        tags.clear();
        pairs.clear();
        ops.iter_mut().for_each(Vec::clear);
        *self = Block {
            phase,
            sites,
            tags,
            pairs,
            ops,
            ..Block::default()
        };
    }

    fn has_sites(&self) -> bool {
        self.table.is_some() || !self.pairs.is_empty()
    }

    /// Takes one token.
    fn token(&mut self, tok: Tok, ctx: &Ctx) -> Result<Option<Stop>, Error> {
        match self.phase {
            Phase::Start => match tok.kind {
                Kind::Data => {
                    self.begin(&tok);
                    Ok(None)
                }
                _ => Err(tok.error(ctx, "a data_ block header (crystallographic CIF)")),
            },
            Phase::Block => self.block(tok, ctx),
            Phase::Item(role, _) => {
                if !tok.is_value() {
                    return Err(tok.error(ctx, "a value after the tag"));
                }
                self.phase = Phase::Block;
                self.item(role, &tok, ctx)?;
                Ok(None)
            }
            Phase::LoopTags => {
                if tok.kind == Kind::Tag {
                    self.tags.push((role(tok.text), tok.at));
                    return Ok(None);
                }
                if self.tags.is_empty() {
                    return Err(tok.error(ctx, "a tag after loop_"));
                }
                if !tok.is_value() {
                    return Err(Error::Parse {
                        at: ctx.at(self.loop_at),
                        expected: "values after the loop's tags",
                        found: format!(
                            "{} tags and no value before the next keyword",
                            self.tags.len()
                        ),
                    });
                }
                self.start_loop(ctx)?;
                self.phase = Phase::Loop;
                self.loop_value(tok, ctx)?;
                Ok(None)
            }
            Phase::Loop => {
                if tok.is_value() {
                    self.loop_value(tok, ctx)?;
                    return Ok(None);
                }
                self.end_loop(ctx)?;
                self.phase = Phase::Block;
                self.block(tok, ctx)
            }
        }
    }

    /// A new block starts at the `data_` token `tok`.
    fn begin(&mut self, tok: &Tok) {
        self.reset(Phase::Block);
        self.name = String::from_utf8_lossy(&tok.text[5..]).into_owned();
    }

    /// A token between items of the block.
    fn block(&mut self, tok: Tok, ctx: &Ctx) -> Result<Option<Stop>, Error> {
        match tok.kind {
            Kind::Tag => self.phase = Phase::Item(role(tok.text), tok.at),
            Kind::Loop => {
                self.tags.clear();
                self.loop_at = tok.at;
                self.phase = Phase::LoopTags;
            }
            Kind::Data if self.has_sites() => {
                if !tok.starts_line {
                    return Err(
                        tok.error(ctx, "the next data_ block header at the start of a line")
                    );
                }
                return Ok(Some(Stop::NextBlock));
            }
            Kind::Data => self.begin(&tok),
            Kind::Reserved => {}
            Kind::Bare | Kind::Quoted => {
                return Err(tok.error(ctx, "a tag or loop_ (a value without a tag)"));
            }
        }
        Ok(None)
    }

    /// The value of a single item (outside a loop), or of a loop's first row.
    fn item(&mut self, role: Role, tok: &Tok, ctx: &Ctx) -> Result<(), Error> {
        match role {
            Role::Cell(k) => {
                self.cell[k] = cell_number(tok, ctx)?;
                self.cell_at.get_or_insert(tok.at);
            }
            Role::Group(k) if !tok.missing() => {
                let s = String::from_utf8_lossy(trim(tok.text)).into_owned();
                self.group[k] = Some((s, tok.at));
            }
            Role::Name(k) if !tok.missing() => {
                self.names[k] = Some(String::from_utf8_lossy(trim(tok.text)).into_owned());
            }
            Role::Op(s) => self.op(s, tok, ctx)?,
            Role::Site(s) => {
                if self.pairs.iter().any(|(q, _)| *q == s && s != Site::Other) {
                    return Err(tok.error(ctx, "each _atom_site item once"));
                }
                if self.pairs.is_empty() {
                    self.pair = SiteRow {
                        at: tok.at,
                        ..SiteRow::default()
                    };
                }
                self.pairs.push((s, tok.at));
                site_value(&mut self.pair, s, tok, ctx, true)?;
            }
            _ => {}
        }
        Ok(())
    }

    /// One value of an operation list.
    fn op(&mut self, s: usize, tok: &Tok, ctx: &Ctx) -> Result<(), Error> {
        if self.ops[s].len() == MAX_OPERATIONS {
            return Err(tok.error(
                ctx,
                "at most 192 symmetry operations (the most a space group has)",
            ));
        }
        let op = (!tok.missing())
            .then(|| parse_op(tok.text))
            .flatten()
            .ok_or_else(|| {
                tok.error(
                    ctx,
                    "a symmetry operation such as x,y,z or -y,x-y,z+1/3 (integer matrix, \
                     determinant 1 or -1)",
                )
            })?;
        self.ops[s].push(op);
        Ok(())
    }

    /// A loop's tags are read: sets up an atom-site loop's columns.
    fn start_loop(&mut self, ctx: &Ctx) -> Result<(), Error> {
        self.values = 0;
        self.atom_loop = self.tags.iter().any(|(r, _)| matches!(r, Role::Site(_)));
        if !self.atom_loop {
            return Ok(());
        }
        if self.table.is_some() || !self.pairs.is_empty() {
            return Err(Error::Parse {
                at: ctx.at(self.loop_at),
                expected: "one table of atom sites per data block",
                found: "a second _atom_site loop".into(),
            });
        }
        let mut cols: Vec<Site> = (self.tags.iter())
            .map(|(r, _)| match r {
                Role::Site(s) => *s,
                _ => Site::Other,
            })
            .collect();
        for (k, s) in cols.iter().enumerate() {
            if *s != Site::Other && cols[..k].contains(s) {
                return Err(Error::Parse {
                    at: ctx.at(self.tags[k].1),
                    expected: "each _atom_site tag once",
                    found: format!("the same item again in column {}", k + 1),
                });
            }
        }
        let cartesian = columns(&cols, self.loop_at, ctx)?;
        if !cartesian {
            cols.iter_mut()
                .filter(|s| matches!(s, Site::Cartn(_)))
                .for_each(|s| *s = Site::Other);
        }
        self.table = Some(Table {
            cols,
            at: self.loop_at,
            cartesian,
        });
        Ok(())
    }

    /// One value of a loop.
    fn loop_value(&mut self, tok: Tok, ctx: &Ctx) -> Result<(), Error> {
        let n = self.tags.len();
        let k = self.values % n;
        if k == 0 {
            self.row = SiteRow {
                at: tok.at,
                ..SiteRow::default()
            };
        }
        let role = self.tags[k].0;
        match role {
            Role::Site(_) if self.atom_loop => {
                let s = self.table.as_ref().map_or(Site::Other, |t| t.cols[k]);
                site_value(&mut self.row, s, &tok, ctx, false)?;
            }
            Role::Op(s) => self.op(s, &tok, ctx)?,
            // Other items of interest are read from a loop's first row.
            r if self.values < n => self.item(r, &tok, ctx)?,
            _ => {}
        }
        self.values += 1;
        if self.atom_loop && k + 1 == n {
            self.sites.push(self.row);
        }
        Ok(())
    }

    /// A loop ends (a keyword follows its values): its last row must be whole.
    fn end_loop(&self, ctx: &Ctx) -> Result<(), Error> {
        let n = self.tags.len();
        if self.values.is_multiple_of(n) {
            return Ok(());
        }
        Err(Error::Parse {
            at: ctx.at(self.row.at),
            expected: "as many values in each loop row as the loop has tags",
            found: format!("{} of {n} values in this row", self.values % n),
        })
    }

    /// The data end (at `at`): what was open is cut.
    fn end_of_data(&self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        match self.phase {
            Phase::Item(..) => Err(ctx.truncated(at, "a value after the last tag".into())),
            Phase::LoopTags if self.tags.is_empty() => {
                Err(ctx.truncated(at, "a tag after loop_".into()))
            }
            Phase::LoopTags => Err(ctx.truncated(
                self.loop_at,
                "the values of the loop that starts here".into(),
            )),
            Phase::Loop if !self.values.is_multiple_of(self.tags.len()) => {
                let n = self.tags.len();
                Err(ctx.truncated(
                    self.row.at,
                    format!(
                        "{} more values of the loop row that starts here",
                        n - self.values % n
                    ),
                ))
            }
            _ => Ok(()),
        }
    }

    /// The block is whole: checks it and (with a frame) expands its sites into it.
    fn finish(&mut self, ctx: &Ctx, frame: Option<&mut Frame>) -> Result<(), Error> {
        // Sites given as items: one row whose columns are the items.
        if self.table.is_none() && !self.pairs.is_empty() {
            let at = self.pairs[0].1;
            let cols: Vec<Site> = self.pairs.iter().map(|p| p.0).collect();
            let cartesian = columns(&cols, at, ctx)?;
            self.table = Some(Table {
                cols,
                at,
                cartesian,
            });
            self.sites.clear();
            self.sites.push(self.pair);
        }
        let Some(frame) = frame else {
            return Ok(());
        };
        let table = self.table.take().unwrap_or_default();
        let cell = self.unit_cell(ctx)?;
        let ops = self.operations(ctx)?;
        // Fractions of every site (Cartesian sites through the cell's inverse).
        let inverse = cell.map(|c| inverse(c.matrix()));
        let mut fracts = Vec::with_capacity(self.sites.len());
        for s in &self.sites {
            let coords = if table.cartesian { s.cartn } else { s.fract };
            let [Some(x), Some(y), Some(z)] = coords else {
                return Err(Error::Parse {
                    at: ctx.at(s.at),
                    expected: "a number for each of the site's x, y and z",
                    found: "a missing coordinate".into(),
                });
            };
            let f = match (table.cartesian, inverse) {
                (false, _) => [x, y, z],
                (true, Some(inv)) => {
                    [0, 1, 2].map(|k| x * inv[0][k] + y * inv[1][k] + z * inv[2][k])
                }
                (true, None) => [x, y, z],
            };
            fracts.push(f);
        }
        if cell.is_none() {
            if !table.cartesian {
                return Err(Error::Parse {
                    at: ctx.at(table.at),
                    expected: "_cell_length_a, _b and _c (the atom sites are fractional)",
                    found: "no complete cell in the data block".into(),
                });
            }
            if ops.iter().any(|o| *o != IDENTITY) {
                return Err(Error::Parse {
                    at: ctx.at(table.at),
                    expected: "_cell_length_a, _b and _c to apply the symmetry operations to \
                               Cartesian sites",
                    found: "no complete cell in the data block".into(),
                });
            }
        }
        frame.cell = cell;
        frame.comment = match self.names.iter().flatten().next() {
            Some(n) => format!("{}: {n}", self.name),
            None => self.name.clone(),
        };
        // Expand every site by every operation, merging coincident images.
        let has = |s| table.has(s);
        let (has_b, has_occ) = (has(Site::Uiso) || has(Site::Biso), has(Site::Occupancy));
        let mut images: Vec<[f64; 3]> = Vec::new();
        for (site, f) in self.sites.iter().zip(&fracts) {
            images.clear();
            match cell {
                Some(c) => {
                    for op in ops {
                        let g = op.apply(*f).map(wrap);
                        if !images.iter().any(|h| same_place(&c, g, *h)) {
                            images.push(g);
                        }
                    }
                }
                None => images.push(*f),
            }
            let element = site_element(site);
            let b = site
                .u
                .map(|u| u * 8.0 * std::f32::consts::PI.powi(2))
                .or(site.b);
            for g in &images {
                let p = cell.map_or(*g, |c| c.to_cartesian(*g));
                frame.positions.push(p.map(|v| v as f32));
                frame.elements.push(element);
                frame.ids.push(frame.ids.len() as i64 + 1);
                if has(Site::Label) {
                    frame.names.push(site.label.unwrap_or_default());
                }
                if has(Site::Type) {
                    frame.types.push(site.kind.unwrap_or_default());
                }
                if has_occ {
                    frame
                        .property_mut("occupancy")
                        .push(site.occupancy.unwrap_or(1.0));
                }
                if has_b {
                    frame.property_mut("bfactor").push(b.unwrap_or(0.0));
                }
            }
        }
        self.table = Some(table);
        Ok(())
    }

    /// The cell of the `_cell` values, `None` without all three lengths.
    fn unit_cell(&self, ctx: &Ctx) -> Result<Option<UnitCell>, Error> {
        let Some((lengths, angles)) = cell_parameters(self.cell) else {
            return Ok(None);
        };
        let expected = "a _cell with lengths > 0 (at most 1e7 Å) and angles that make a volume > 0";
        let at = self.cell_at.unwrap_or_default();
        cell_of(lengths, angles, ctx, at, expected).map(Some)
    }

    /// The operations to expand by: the file's list, else the identity when the space group is
    /// P 1 or not named.
    fn operations(&self, ctx: &Ctx) -> Result<&[Op], Error> {
        if let Some(ops) = self.ops.iter().find(|o| !o.is_empty()) {
            return Ok(ops);
        }
        let squeeze = |s: &str| -> String {
            (s.chars())
                .filter(|c| !c.is_whitespace() && *c != '_')
                .flat_map(char::to_lowercase)
                .collect()
        };
        let p1 = |k: usize, s: &str| match k {
            2 => s.trim() == "1",
            _ => squeeze(s) == "p1",
        };
        if let Some((k, (name, at))) = (self.group.iter().enumerate())
            .find_map(|(k, g)| g.as_ref().filter(|(s, _)| !p1(k, s)).map(|g| (k, g)))
        {
            let what = [
                "space group",
                "space group (Hall symbol)",
                "space group number",
            ][k];
            return Err(Error::Parse {
                at: ctx.at(*at),
                expected: "a list of symmetry operations (_space_group_symop_operation_xyz or \
                           _symmetry_equiv_pos_as_xyz) for a space group other than P 1: no \
                           space-group table is carried to make them up",
                found: format!("{what} {name:?} and no operations in the data block"),
            });
        }
        Ok(std::slice::from_ref(&IDENTITY))
    }
}

/// Which coordinates a site table uses: fractional when it has all of `fract_x/y/z`,
/// Cartesian when it has all of `Cartn_x/y/z`; else an error at `at`.
fn columns(cols: &[Site], at: Pos, ctx: &Ctx) -> Result<bool, Error> {
    let all = |f: fn(usize) -> Site| (0..3).all(|k| cols.contains(&f(k)));
    if all(Site::Fract) {
        Ok(false)
    } else if all(Site::Cartn) {
        Ok(true)
    } else {
        Err(Error::Parse {
            at: ctx.at(at),
            expected: "the _atom_site_fract_x, _y and _z (or _Cartn_x, _y and _z) columns",
            found: "atom sites without all three coordinates".into(),
        })
    }
}

/// Parses one site value into `row`; `lenient` leaves a missing coordinate missing (items,
/// where the other coordinate set may be the one used) instead of an error.
fn site_value(
    row: &mut SiteRow,
    s: Site,
    tok: &Tok,
    ctx: &Ctx,
    lenient: bool,
) -> Result<(), Error> {
    let label = |what: &'static str| -> Result<Option<Label>, Error> {
        if tok.missing() {
            return Ok(None);
        }
        Label::from_utf8(tok.text)
            .map(Some)
            .ok_or_else(|| tok.error(ctx, what))
    };
    let scalar = |what: &'static str| -> Result<Option<f32>, Error> {
        if tok.missing() {
            return Ok(None);
        }
        let v = number(tok).filter(|v| v.abs() <= MAX_COORDINATE);
        v.map(|v| Some(v as f32))
            .ok_or_else(|| tok.error(ctx, what))
    };
    let coord = |what: &'static str| -> Result<Option<f64>, Error> {
        if tok.missing() && lenient {
            return Ok(None);
        }
        let v = (!tok.missing())
            .then(|| parse_f64(strip_esd(tok.text)))
            .flatten()
            .filter(|v| v.abs() <= MAX_COORDINATE);
        v.map(Some).ok_or_else(|| tok.error(ctx, what))
    };
    match s {
        Site::Label => row.label = label("a site label of at most 15 bytes")?,
        Site::Type => row.kind = label("a type symbol of at most 15 bytes")?,
        Site::Fract(k) => row.fract[k] = coord(FRACT[k])?,
        Site::Cartn(k) => row.cartn[k] = coord(CARTN[k])?,
        Site::Occupancy => row.occupancy = scalar("a number for _atom_site_occupancy")?,
        Site::Uiso => row.u = scalar("a number for _atom_site_U_iso_or_equiv")?,
        Site::Biso => row.b = scalar("a number for _atom_site_B_iso_or_equiv")?,
        Site::Other => {}
    }
    Ok(())
}

const FRACT: [&str; 3] = [
    "a number (within ±1e7) for _atom_site_fract_x",
    "a number (within ±1e7) for _atom_site_fract_y",
    "a number (within ±1e7) for _atom_site_fract_z",
];

const CARTN: [&str; 3] = [
    "a number (within ±1e7 Å) for _atom_site_Cartn_x",
    "a number (within ±1e7 Å) for _atom_site_Cartn_y",
    "a number (within ±1e7 Å) for _atom_site_Cartn_z",
];

/// The element of a site: from its type symbol without the charge, else from its label.
fn site_element(site: &SiteRow) -> Element {
    let from_symbol = |s: &str| -> Option<Element> {
        let b = s.trim().as_bytes();
        let n = b.iter().take_while(|c| c.is_ascii_alphabetic()).count();
        let letters = &s.trim()[..n];
        if n >= 2
            && b[1].is_ascii_lowercase()
            && let Some(e) = Element::from_symbol(&letters[..2])
        {
            return Some(e);
        }
        match letters.get(..1) {
            // Deuterium (and its labels: D1, D12), read as hydrogen as ASE does.
            Some("D") => Element::from_symbol("H"),
            Some(one) => Element::from_symbol(one),
            None => None,
        }
    };
    if let Some(e) = site.kind.as_deref().and_then(from_symbol) {
        return e;
    }
    let label = site.label.unwrap_or_default();
    match guess_element(&label, None, None) {
        Element::UNKNOWN => from_symbol(&label).unwrap_or(Element::UNKNOWN),
        e => e,
    }
}

/// `v` wrapped into [0, 1).
fn wrap(v: f64) -> f64 {
    let w = v - v.floor();
    if w >= 1.0 { 0.0 } else { w }
}

/// Whether fractional positions `a` and `b` are within [`MERGE_TOLERANCE`] of each other
/// through the cell (minimum image: exact for a tolerance below half the cell's narrowest
/// width, since then the nearest image has every fractional difference under one half).
fn same_place(cell: &UnitCell, a: [f64; 3], b: [f64; 3]) -> bool {
    let d = [0, 1, 2].map(|k| {
        let d = a[k] - b[k];
        d - d.round()
    });
    let m = cell.matrix();
    let v = [0, 1, 2].map(|k| d[0] * m[0][k] + d[1] * m[1][k] + d[2] * m[2][k]);
    v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < MERGE_TOLERANCE * MERGE_TOLERANCE
}

/// The inverse of a cell matrix (rows are the edges; its volume is > 0).
fn inverse(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let c = |r: usize, s: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
        m[r1][s1] * m[r2][s2] - m[r1][s2] * m[r2][s1]
    };
    // inverse[i][j] = cofactor(j, i) / det.
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn op(s: &str) -> Op {
        parse_op(s.as_bytes()).unwrap_or_else(|| panic!("{s}"))
    }

    #[test]
    fn operations_in_every_notation() {
        let o = op("-y,x-y,z+1/3");
        assert_eq!(o.rot, [[0.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(o.trans, [0.0, 0.0, 1.0 / 3.0]);
        let o = op("1/2+x,-y+1/2,z");
        assert_eq!(o.trans, [0.5, 0.5, 0.0]);
        assert_eq!(op("x+0.5, Y ,  -Z"), op("1/2+x,y,-z"));
        assert_eq!(op("1 x,y,z"), IDENTITY);
        assert_eq!(op("+x,+y,+z"), IDENTITY);
        assert_eq!(op("-x+y+2/3,y,.25+z").trans, [2.0 / 3.0, 0.0, 0.25]);
        for bad in [
            "x,y", "x,y,z,x", "x,y,w", "x,x,z", "2x,y,z", "x,y,z+", "x,y,1/0", "x y,y,z", "x,y,*z",
            "", "x,,z", "x,y,z1",
        ] {
            assert_eq!(parse_op(bad.as_bytes()), None, "{bad}");
        }
    }

    #[test]
    fn tags_and_dialects() {
        assert_eq!(role(b"_atom_site_fract_x"), Role::Site(Site::Fract(0)));
        assert_eq!(role(b"_atom_site.Cartn_z"), Role::Site(Site::Cartn(2)));
        assert_eq!(role(b"_atom_site_aniso_label"), Role::None);
        assert_eq!(role(b"_atom_sites_solution_primary"), Role::None);
        assert_eq!(role(b"_CELL.length_b"), Role::Cell(1));
        assert_eq!(role(b"_space_group_symop.operation_xyz"), Role::Op(0));
        assert_eq!(role(b"_symmetry_space_group_name_H-M"), Role::Group(0));
        assert_eq!(role(b"_space_group_IT_number"), Role::Group(2));
    }

    #[test]
    fn elements_from_type_symbols_and_labels() {
        let el = |kind: &str, label: &str| {
            let row = SiteRow {
                kind: (!kind.is_empty()).then(|| Label::new(kind).unwrap()),
                label: Label::new(label),
                ..SiteRow::default()
            };
            site_element(&row).symbol()
        };
        assert_eq!(el("Fe2+", "X1"), "Fe");
        assert_eq!(el("O2-", "Oh1"), "O");
        assert_eq!(el("Si4+", ""), "Si");
        assert_eq!(el("", "Fe1"), "Fe");
        assert_eq!(el("", "O12a"), "O");
        assert_eq!(el("", "D1"), "H");
        assert_eq!(el("D", "x"), "H");
    }

    #[test]
    fn inverse_undoes_the_cell() {
        let c = UnitCell::from_lengths_angles([5.0, 6.0, 7.0], [80.0, 95.0, 110.0]).unwrap();
        let inv = inverse(c.matrix());
        let f = [0.1, 0.7, 0.35];
        let p = c.to_cartesian(f);
        let back = [0, 1, 2].map(|k| p[0] * inv[0][k] + p[1] * inv[1][k] + p[2] * inv[2][k]);
        for k in 0..3 {
            assert!((back[k] - f[k]).abs() < 1e-12, "{back:?} {f:?}");
        }
        assert_eq!(wrap(-1e-17), 0.0);
        assert_eq!(wrap(1.25), 0.25);
        assert!(same_place(&c, [0.999_999, 0.5, 0.5], [0.000_001, 0.5, 0.5]));
    }
}

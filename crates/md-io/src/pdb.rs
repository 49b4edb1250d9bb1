//! PDB (Protein Data Bank) coordinates, multi-MODEL.
//!
//! Records used (1-based columns, PDB format v3.3):
//! - `ATOM`/`HETATM`: serial 7-11 (hybrid-36 past 99,999), name 13-16, residue name 18-21,
//!   chain 22, residue number 23-26 (hybrid-36 past 9,999), x y z 31-38, 39-46, 47-54,
//!   occupancy 55-60 and B-factor 61-66 (the `occupancy` and `bfactor` properties; a frame
//!   whose fields are all blank has neither, a blank among numbers is 1 and 0), segment 73-76,
//!   element 77-78. A frame whose chain (or segment) fields are all blank has no chain
//!   (segment) column, so `chain A` on it is an error rather than an empty selection;
//! - `CRYST1`: a b c 7-15, 16-24, 25-33, α β γ 34-40, 41-47, 48-54. A cell of 1 Å x 1 Å x 1 Å
//!   with right angles is the conventional "no cell" placeholder and is dropped (as MDAnalysis
//!   does). A CRYST1 holds for the frames after it until the next CRYST1;
//! - `MODEL` / `ENDMDL`: frame boundaries. Without them the whole file is one frame;
//! - `TITLE`: the frame's comment. Everything else (REMARK, TER, CONECT, MASTER, END, ...) is
//!   skipped, so trailing CONECT/MASTER/END records do not make a frame.
//!
//! Damage is never a silently dropped atom: every model must hold as many ATOM/HETATM records as
//! model 1 (an error, or a warning under `ReadOptions::allow_truncated`), and a line whose
//! record name is unknown but whose columns 31-54 hold three numbers (an atom record with a
//! damaged name) is an error. Unknown lines without coordinates are skipped.
//!
//! Elements: columns 77-78 when they hold a symbol, else [`crate::elements::guess_element`] from
//! the atom and residue names.
//!
//! **PDBQT** (AutoDock, Vina, Meeko, Open Babel): the same records, but columns 67-76 hold the
//! partial charge (the `charge` property) and 78-79 the AutoDock atom type (the atom's type;
//! its element by [`autodock_element`]: `A` aromatic carbon, `OA` acceptor oxygen, `HD` donor
//! hydrogen, `Cl`, `Br`, ...), so there is no segment. `ROOT`/`BRANCH`/`TORSDOF` lines (a
//! flexible ligand's torsion tree) are skipped; each `MODEL` of a docking output is a pose, and
//! its `REMARK VINA RESULT:` line (score in kcal/mol, RMSD bounds) becomes the frame's title.
//!
//! **Writing** (`PdbWriter`): every atom is an `ATOM` record (the writer does not tell
//! standard residues from hetero groups), so the wwPDB rule of `CONECT` records for the bonds
//! of `HETATM` records only would write none. All of the frame's bonds ([`Frame::bonds`]: an
//! SDF/MOL2 ligand's, or the topology's that `texmap convert` gives a PDB) are written instead,
//! as MDAnalysis (`bonds="all"`) and Open Babel do: a reader that ignores `CONECT` guesses
//! bonds anyway, and one that reads them (ours, MDAnalysis, gemmi, RDKit with
//! `proximityBonding=False`) gets exactly the frame's bonds, a protein's backbone included
//! (with `HETATM` bonds only, our reader would lose it).
//! - Layout: `CONECT`, the atom's serial in columns 7-11 and up to four bonded serials in
//!   12-31 (`CONECT%5d%5d%5d%5d%5d`, no padding), one line per bonded atom in file order with
//!   its partners in file order, more lines for more than four; each bond is listed from both
//!   atoms. Serials past 99,999 are hybrid-36, as in the `ATOM` records they name (our reader
//!   and cctbx read them; a reader without hybrid-36 cannot read those atoms either).
//! - Orders ([`Frame::bond_orders`]): a double or triple bond repeats its partner two or three
//!   times, the convention RDKit (checked), gemmi (kept), PyMOL and Open Babel read as bond
//!   order; aromatic and unknown orders are written once, as single bonds (PDB has no aromatic
//!   bond: kekulize first to keep them). MDAnalysis and our reader take the repeats as one bond.
//! - Place: one set of records for the file, the first frame's (bonds are topology), written
//!   in the first model just before its `ENDMDL`, as RDKit's writer places them. wwPDB entries
//!   put them after the last model, but RDKit's reader (and others reading the first model
//!   only) stops at the first `ENDMDL` and would see no bonds there; MDAnalysis, gemmi and our
//!   reader take `CONECT` records wherever they are.
//! - Refused (an error naming the frame, nothing dropped): a later frame whose bonds or written
//!   orders differ from the first's (one `CONECT` set cannot hold both: write one file per
//!   molecule, or SDF), and a bonded atom whose serial another atom shares (a GRO's numbers
//!   wrap at 100,000), which `CONECT` could not tell apart.
//!
//! Hybrid-36 (Grosse-Kunstleve, 2007): a field of width w holds decimal numbers up to 10^w - 1,
//! then base-36 with upper-case digits ("A0000" = 100,000 for w = 5), then lower-case digits.
//!
//! # References
//! - wwPDB, Protein Data Bank Contents Guide: Atomic Coordinate Entry Format v3.3
//!   (section 10, `CONECT`).
//! - R. W. Grosse-Kunstleve, "Hybrid-36", cctbx iotbx/pdb/hybrid_36 documentation (2007).
//! - AutoDock 4.2 user guide, "PDBQT format" and its atom types; AutoDock Vina 1.2 and Meeko
//!   documentation (the torsion tree, `REMARK VINA RESULT`).

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{parse_f32, parse_f64, trim};
use crate::text::{Ctx, FrameWalk, LineReader, ModelCheck, Pos};
use std::io::Read;

/// The properties of columns 55-60 and 61-66, and the value of a blank field in a frame whose
/// other atoms have one (MDAnalysis's defaults: occupancy 1, B-factor 0).
const SCALARS: [(&str, f32); 2] = [("occupancy", 1.0), ("bfactor", 0.0)];

/// Value of a base-36 digit in the given alphabet half (upper or lower case), else `None`.
fn digit36(b: u8, upper: bool) -> Option<u64> {
    match b {
        b'0'..=b'9' => Some((b - b'0') as u64),
        b'A'..=b'Z' if upper => Some((b - b'A') as u64 + 10),
        b'a'..=b'z' if !upper => Some((b - b'a') as u64 + 10),
        _ => None,
    }
}

/// Decodes a hybrid-36 field of width `w` (spaces allowed around decimal numbers).
pub(crate) fn hy36_decode(field: &[u8], w: u32) -> Option<i64> {
    let t = trim(field);
    let first = *t.first()?;
    if first.is_ascii_digit() || first == b'-' {
        return crate::parse::parse_i64(t);
    }
    // Letters: the field must be full width.
    if field.len() != w as usize || t.len() != w as usize {
        return None;
    }
    let upper = first.is_ascii_uppercase();
    let mut v: u64 = 0;
    for &b in t {
        v = v * 36 + digit36(b, upper)?;
    }
    let p36 = 36u64.pow(w - 1);
    let p10 = 10u64.pow(w);
    // Upper case starts at 10^w with "A000…" (= 10·36^(w-1)); lower case follows upper case.
    let base = if upper { p10 } else { p10 + 26 * p36 };
    Some((v - 10 * p36 + base) as i64)
}

/// Encodes `v` as hybrid-36 of width `w`; `None` past the largest lower-case number.
pub(crate) fn hy36_encode(v: i64, w: u32) -> Option<String> {
    let p10 = 10i64.pow(w);
    let p36 = 36i64.pow(w - 1);
    if v > -(10i64.pow(w - 1)) && v < p10 {
        return Some(format!("{v:>width$}", width = w as usize));
    }
    if v < 0 {
        return None;
    }
    let (mut r, digits) = if v < p10 + 26 * p36 {
        (v - p10 + 10 * p36, b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ")
    } else if v < p10 + 52 * p36 {
        (
            v - p10 - 26 * p36 + 10 * p36,
            b"0123456789abcdefghijklmnopqrstuvwxyz",
        )
    } else {
        return None;
    };
    let mut out = vec![b'0'; w as usize];
    for k in (0..w as usize).rev() {
        out[k] = digits[(r % 36) as usize];
        r /= 36;
    }
    String::from_utf8(out).ok()
}

/// Bytes `a..=b` (1-based, inclusive) of a line, cut to its length.
fn cols(line: &[u8], a: usize, b: usize) -> &[u8] {
    let s = (a - 1).min(line.len());
    let e = b.min(line.len());
    &line[s..e]
}

/// Record names of PDB v3.3 that carry no atom position (plus SIGATM, SIGUIJ and USER, which
/// programs write beside them). A line whose name is none of these nor ATOM/HETATM but whose
/// columns 31-54 hold three numbers is an atom record with a damaged name: an error, not a
/// silently skipped atom. Other unknown lines (comments of some programs) are skipped.
pub(crate) const OTHER_RECORDS: [&[u8]; 53] = [
    b"HEADER", b"OBSLTE", b"TITLE", b"SPLIT", b"CAVEAT", b"COMPND", b"SOURCE", b"KEYWDS",
    b"EXPDTA", b"NUMMDL", b"MDLTYP", b"AUTHOR", b"REVDAT", b"SPRSDE", b"JRNL", b"REMARK", b"DBREF",
    b"DBREF1", b"DBREF2", b"SEQADV", b"SEQRES", b"MODRES", b"HET", b"HETNAM", b"HETSYN", b"FORMUL",
    b"HELIX", b"SHEET", b"SSBOND", b"LINK", b"CISPEP", b"SITE", b"CRYST1", b"ORIGX1", b"ORIGX2",
    b"ORIGX3", b"SCALE1", b"SCALE2", b"SCALE3", b"MTRIX1", b"MTRIX2", b"MTRIX3", b"MODEL",
    b"ANISOU", b"TER", b"ENDMDL", b"CONECT", b"MASTER", b"END", b"SIGATM", b"SIGUIJ", b"USER", b"",
];

/// True if columns 31-54 of `line` hold three numbers (an atom record's coordinates).
fn has_coordinates(line: &[u8]) -> bool {
    line.len() >= 54
        && (0..3).all(|k| parse_f32(trim(cols(line, 31 + 8 * k, 38 + 8 * k))).is_some())
}

/// The element an AutoDock 4 atom type names: `A` (aromatic carbon), Meeko's `G0`-`G3` and
/// `CG0`-`CG3` (macrocycle closure carbons) are carbon; `NA`, `NS` nitrogen; `OA`, `OS` and
/// Meeko's water `W` oxygen; `SA` sulfur; `HD`, `HS` hydrogen; any other a symbol in any case
/// (`Cl`, `BR`, `Zn`, `Fe`, `Mg`; so `CA` is calcium, as AutoDock has it). `None` for a type
/// that is none of these (the names decide).
fn autodock_element(t: &[u8]) -> Option<crate::elements::Element> {
    use crate::elements::element_of_symbol;
    let sym: &[u8] = match t {
        b"A" | b"G0" | b"G1" | b"G2" | b"G3" | b"CG0" | b"CG1" | b"CG2" | b"CG3" => b"C",
        b"NA" | b"NS" => b"N",
        b"OA" | b"OS" | b"W" => b"O",
        b"SA" => b"S",
        b"HD" | b"HS" => b"H",
        other => other,
    };
    element_of_symbol(sym)
}

/// PDB frame parser state: the cell of the last CRYST1, and model 1's atom count, which every
/// later model must repeat ([`ModelCheck`]).
#[derive(Default)]
pub(crate) struct Pdb {
    cell: Option<UnitCell>,
    models: ModelCheck,
    /// AutoDock PDBQT: charge and AD4 type in columns 67-79 instead of segment and element.
    pdbqt: bool,
}

/// Record name of a line: its first 6 bytes, trailing spaces removed.
fn record(line: &[u8]) -> &[u8] {
    trim(cols(line, 1, 6))
}

impl Pdb {
    /// A parser; `lenient` turns an atom count that differs from model 1's into a warning.
    pub(crate) fn new(lenient: bool) -> Pdb {
        Pdb {
            cell: None,
            models: ModelCheck::new(lenient),
            pdbqt: false,
        }
    }

    /// A parser of AutoDock PDBQT (see the module doc).
    pub(crate) fn pdbqt(lenient: bool) -> Pdb {
        Pdb {
            pdbqt: true,
            ..Pdb::new(lenient)
        }
    }

    /// The warnings gathered so far (emptied).
    pub(crate) fn take_warnings(&mut self) -> Vec<Error> {
        self.models.take_warnings()
    }

    /// Checks a finished frame's atom count against model 1's.
    fn check_count(&mut self, ctx: &Ctx, pos: Pos, n_atoms: usize) -> Result<(), Error> {
        let expected = "as many ATOM/HETATM records as model 1 (frame 0)";
        self.models.check(ctx, pos, n_atoms, expected)
    }

    fn cryst1(&mut self, ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<(), Error> {
        let mut v = [0f64; 6];
        let spans = [(7, 15), (16, 24), (25, 33), (34, 40), (41, 47), (48, 54)];
        for (x, (a, b)) in v.iter_mut().zip(spans) {
            let f = trim(cols(line, a, b));
            *x = parse_f64(f).ok_or_else(|| ctx.parse(pos, line, f, "a number in CRYST1"))?;
        }
        if v == [1.0, 1.0, 1.0, 90.0, 90.0, 90.0] || v[..3] == [0.0; 3] {
            self.cell = None;
            return Ok(());
        }
        let cell = UnitCell::from_lengths_angles([v[0], v[1], v[2]], [v[3], v[4], v[5]])
            .map_err(|_| ctx.parse(pos, line, line, "a CRYST1 cell with volume > 0"))?;
        self.cell = Some(cell);
        Ok(())
    }

    fn atom(&self, ctx: &Ctx, pos: Pos, line: &[u8], frame: &mut Frame) -> Result<(), Error> {
        // Coordinates, columns 31-54.
        let mut p = [0f32; 3];
        for (k, x) in p.iter_mut().enumerate() {
            let f = trim(cols(line, 31 + 8 * k, 38 + 8 * k));
            *x = parse_f32(f)
                .ok_or_else(|| ctx.parse(pos, line, f, "a coordinate in columns 31-54"))?;
        }
        let serial_field = cols(line, 7, 11);
        let serial = if trim(serial_field).is_empty() {
            frame.n_atoms() as i64 + 1
        } else {
            hy36_decode(serial_field, 5).ok_or_else(|| {
                ctx.parse(pos, line, serial_field, "a serial number in columns 7-11")
            })?
        };
        let name_f = trim(cols(line, 13, 16));
        let res_f = trim(cols(line, 18, 21));
        let name = Label::from_utf8(name_f)
            .ok_or_else(|| ctx.parse(pos, line, name_f, "an atom name in columns 13-16"))?;
        let res = Label::from_utf8(res_f)
            .ok_or_else(|| ctx.parse(pos, line, res_f, "a residue name in columns 18-21"))?;
        let resid_field = cols(line, 23, 26);
        let resid = if trim(resid_field).is_empty() {
            0
        } else {
            hy36_decode(resid_field, 4).ok_or_else(|| {
                ctx.parse(pos, line, resid_field, "a residue number in columns 23-26")
            })?
        };
        let chain_f = trim(cols(line, 22, 22));
        let chain = Label::from_utf8(chain_f)
            .ok_or_else(|| ctx.parse(pos, line, chain_f, "a chain identifier in column 22"))?;
        let seg_f = if self.pdbqt {
            &b""[..]
        } else {
            trim(cols(line, 73, 76))
        };
        let segment = Label::from_utf8(seg_f)
            .ok_or_else(|| ctx.parse(pos, line, seg_f, "a segment identifier in columns 73-76"))?;
        // Occupancy 55-60 and B-factor 61-66; a blank field is NaN until the frame ends.
        let mut scalars = [f32::NAN; 2];
        for (k, (a, b, what)) in [
            (55, 60, "an occupancy in columns 55-60"),
            (61, 66, "a B-factor in columns 61-66"),
        ]
        .into_iter()
        .enumerate()
        {
            let f = trim(cols(line, a, b));
            if !f.is_empty() {
                scalars[k] = parse_f32(f)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| ctx.parse(pos, line, f, what))?;
            }
        }
        let element = if self.pdbqt {
            // Partial charge 67-76 (Vina and Meeko write it there; MDAnalysis reads 71-76),
            // AutoDock type 78-79.
            let q_f = trim(cols(line, 67, 76));
            let q = parse_f32(q_f)
                .filter(|v| v.is_finite())
                .ok_or_else(|| ctx.parse(pos, line, q_f, "a partial charge in columns 67-76"))?;
            frame.property_mut("charge").push(q);
            let t_f = trim(cols(line, 78, 79));
            let ty = Label::from_utf8(t_f)
                .filter(|t| !t.is_empty())
                .ok_or_else(|| {
                    ctx.parse(pos, line, t_f, "an AutoDock atom type in columns 78-79")
                })?;
            frame.types.push(ty);
            autodock_element(t_f).unwrap_or_else(|| guess_element(&name, Some(&res), None))
        } else {
            let elem = std::str::from_utf8(trim(cols(line, 77, 78))).ok();
            guess_element(&name, Some(&res), elem.filter(|e| !e.is_empty()))
        };
        frame.positions.push(p);
        frame.ids.push(serial);
        frame.names.push(name);
        frame.res_names.push(res);
        frame.res_ids.push(resid);
        frame.chains.push(chain);
        frame.segments.push(segment);
        frame.elements.push(element);
        for (k, (name, _)) in SCALARS.iter().enumerate() {
            frame.property_mut(name).push(scalars[k]);
        }
        Ok(())
    }

    /// Drops the chain and segment columns of a finished frame when every field was blank, and
    /// the occupancy and B-factor properties when every field was; fills the blanks of the
    /// others with [`SCALARS`]' defaults.
    fn finish(frame: &mut Frame) {
        for column in [&mut frame.chains, &mut frame.segments] {
            if column.iter().all(|l| l.is_empty()) {
                column.clear();
            }
        }
        for (name, missing) in SCALARS {
            if let Some(k) = frame.properties.iter().position(|p| p.name == name) {
                let values = &mut frame.properties[k].values;
                if values.iter().all(|v| v.is_nan()) {
                    frame.properties.remove(k);
                } else {
                    for v in values.iter_mut().filter(|v| v.is_nan()) {
                        *v = missing;
                    }
                }
            }
        }
    }
}

impl FrameWalk for Pdb {
    /// Walks the records of one frame; parses ATOM/HETATM lines when given a frame.
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        let mut in_model = false;
        let mut n_atoms = 0usize;
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if in_model {
                    return Err(ctx.truncated(p, "ENDMDL closing the MODEL".into()));
                }
                break;
            };
            match record(line) {
                b"ATOM" | b"HETATM" => {
                    n_atoms += 1;
                    if let Some(f) = frame.as_deref_mut() {
                        self.atom(ctx, pos, line, f)?;
                    }
                }
                b"MODEL" => {
                    if in_model || n_atoms > 0 {
                        // A new model without ENDMDL before it: this frame ends here.
                        lines.unread(pos);
                        break;
                    }
                    in_model = true;
                }
                b"ENDMDL" => {
                    self.check_count(ctx, pos, n_atoms)?;
                    if let Some(f) = frame.as_deref_mut() {
                        f.cell = self.cell;
                        Pdb::finish(f);
                    }
                    return Ok(true);
                }
                b"END" if n_atoms > 0 => break,
                b"CRYST1" => self.cryst1(ctx, pos, line)?,
                name if !OTHER_RECORDS.contains(&name) && has_coordinates(line) => {
                    let name = cols(line, 1, 6);
                    return Err(ctx.parse(pos, line, name, "ATOM or HETATM in columns 1-6"));
                }
                b"REMARK" if self.pdbqt && line.starts_with(b"REMARK VINA RESULT:") => {
                    // A docked pose's score: its title (`--label '{title}'`).
                    if let Some(f) = frame.as_deref_mut() {
                        let t = String::from_utf8_lossy(&line[7..]);
                        let words: Vec<&str> = t.split_whitespace().collect();
                        if !f.comment.is_empty() {
                            f.comment.push(' ');
                        }
                        f.comment.push_str(&words.join(" "));
                    }
                }
                b"TITLE" => {
                    if let Some(f) = frame.as_deref_mut() {
                        let t = String::from_utf8_lossy(trim(cols(line, 11, 80)));
                        if !f.comment.is_empty() {
                            f.comment.push(' ');
                        }
                        f.comment.push_str(&t);
                    }
                }
                _ => {}
            }
        }
        let found = n_atoms > 0 || in_model;
        if found {
            self.check_count(ctx, lines.pos(), n_atoms)?;
        }
        if let Some(f) = frame {
            f.cell = self.cell;
            Pdb::finish(f);
        }
        Ok(found)
    }
}

/// The element a writer gives atom `i`: the frame's, else (unknown or no element column) one
/// guessed from its name and residue name ([`guess_element`]); may still be unknown.
pub(crate) fn written_element(frame: &Frame, i: usize) -> crate::elements::Element {
    frame
        .elements
        .get(i)
        .filter(|e| !e.is_unknown())
        .copied()
        .unwrap_or_else(|| {
            let n = frame.names.get(i).map_or("", |l| l.as_str());
            let r = frame.res_names.get(i).map(|l| l.as_str());
            guess_element(n, r, None)
        })
}

/// Writes frames as PDB: one MODEL … ENDMDL per frame, a CRYST1 when the frame has a cell,
/// hybrid-36 serial and residue numbers, element symbols in columns 77-78, END at `finish`.
/// Segments longer than columns 73-76 keep their first 4 characters (MDAnalysis's and VMD's
/// rule); names, residue names and chains that do not fit are errors. The first frame's bonds
/// are written as `CONECT` records before its ENDMDL (see the module doc).
pub(crate) struct PdbWriter<W> {
    pub out: W,
    pub models: usize,
    /// The first frame's bonds and how many times each is written (its order, see
    /// [`conect_multiplicity`]); later frames must have the same.
    bonds: Option<(Vec<[u32; 2]>, Vec<u8>)>,
}

/// How many times a bond of order `order` is listed in `CONECT` records: 2 and 3 for double
/// and triple bonds, once for the rest (single, aromatic, unknown).
fn conect_multiplicity(frame: &Frame) -> Vec<u8> {
    if frame.bond_orders.len() != frame.bonds.len() {
        return vec![1; frame.bonds.len()];
    }
    frame
        .bond_orders
        .iter()
        .map(|o| if matches!(o, 2 | 3) { *o } else { 1 })
        .collect()
}

/// The serial number the writer gives atom `i`: its id, else `i + 1`.
fn written_serial(frame: &Frame, i: usize) -> i64 {
    frame.ids.get(i).copied().unwrap_or(i as i64 + 1)
}

/// Largest and smallest coordinate that fit `%8.3f`.
const PDB_MAX: f32 = 9999.999;
const PDB_MIN: f32 = -999.999;

impl<W: std::io::Write> PdbWriter<W> {
    pub fn new(out: W) -> Self {
        PdbWriter {
            out,
            models: 0,
            bonds: None,
        }
    }

    /// Why `frame` cannot be written as PDB, if it cannot.
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        Self::check_atoms(frame)?;
        match &self.bonds {
            Some((bonds, mult)) => {
                if *bonds != frame.bonds || *mult != conect_multiplicity(frame) {
                    return Err(format!(
                        "its bonds differ from the first frame's ({} bonds here, {} there): a PDB \
                         file's CONECT records are one set of bonds for all its models; write \
                         each molecule to its own file",
                        frame.bonds.len(),
                        bonds.len()
                    ));
                }
                Ok(())
            }
            None => Self::check_serials(frame),
        }
    }

    /// Whether `CONECT` records can name `frame`'s bonded atoms: their serials must be unique.
    fn check_serials(frame: &Frame) -> Result<(), String> {
        if frame.bonds.is_empty() || frame.ids.is_empty() {
            return Ok(());
        }
        let mut count: std::collections::HashMap<i64, u32> =
            std::collections::HashMap::with_capacity(frame.ids.len());
        for id in &frame.ids {
            *count.entry(*id).or_default() += 1;
        }
        for i in frame.bonds.iter().flatten().map(|&i| i as usize) {
            let s = written_serial(frame, i);
            if count.get(&s).is_some_and(|&c| c > 1) {
                let other = (0..frame.ids.len())
                    .find(|&j| j != i && frame.ids[j] == s)
                    .unwrap_or(i);
                return Err(format!(
                    "atoms {} and {} share the serial number {s} and atom {i} is bonded: \
                     CONECT records name atoms by serial and could not tell them apart \
                     (write .cif, or number the atoms uniquely)",
                    i.min(other),
                    i.max(other)
                ));
            }
        }
        Ok(())
    }

    /// Why `frame`'s atoms cannot be written as PDB, if they cannot.
    fn check_atoms(frame: &Frame) -> Result<(), String> {
        if let Some(i) = frame
            .positions
            .iter()
            .position(|p| p.iter().any(|x| !(PDB_MIN..=PDB_MAX).contains(x)))
        {
            return Err(format!(
                "atom {i} has a coordinate outside PDB's [-999.999, 9999.999] Å"
            ));
        }
        if let Some(i) = frame.ids.iter().position(|v| hy36_encode(*v, 5).is_none()) {
            return Err(format!("atom {i}'s id does not fit 5 hybrid-36 columns"));
        }
        if let Some(i) = frame
            .res_ids
            .iter()
            .position(|v| hy36_encode(*v, 4).is_none())
        {
            return Err(format!(
                "atom {i}'s residue number does not fit 4 hybrid-36 columns"
            ));
        }
        if let Some(i) = frame.names.iter().position(|l| l.len() > 4) {
            return Err(format!("atom {i}'s name is longer than 4 characters"));
        }
        if let Some(i) = frame.res_names.iter().position(|l| l.len() > 4) {
            return Err(format!(
                "atom {i}'s residue name is longer than 4 characters"
            ));
        }
        if let Some(i) = frame.chains.iter().position(|l| l.len() > 1) {
            return Err(format!(
                "atom {i}'s chain {:?} is longer than PDB's one column (write mmCIF-sized \
                 structures as XYZ, or rename the chains)",
                frame.chains[i].as_str()
            ));
        }
        for (name, _) in SCALARS {
            let fits = |v: &f32| (-99.995..999.995).contains(v);
            if let Some(i) = frame
                .property(name)
                .and_then(|v| v.iter().position(|v| !fits(v)))
            {
                return Err(format!(
                    "atom {i}'s {name} does not fit PDB's 6 columns (-99.99 to 999.99)"
                ));
            }
        }
        if frame.n_atoms() > 87_440_031 {
            return Err("more atoms than hybrid-36 serial numbers".into());
        }
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()> {
        let conect = if self.bonds.is_none() {
            let mult = conect_multiplicity(frame);
            let records = conect_records(frame, &mult);
            self.bonds = Some((frame.bonds.clone(), mult));
            records
        } else {
            String::new()
        };
        let w = &mut self.out;
        self.models += 1;
        if let Some(c) = &frame.cell {
            let [a, b, cc] = c.lengths();
            let [al, be, ga] = c.angles();
            writeln!(
                w,
                "CRYST1{a:9.3}{b:9.3}{cc:9.3}{al:7.2}{be:7.2}{ga:7.2} P 1           1"
            )?;
        }
        writeln!(w, "MODEL     {:>4}", self.models)?;
        let occupancy = frame.property("occupancy");
        let bfactor = frame.property("bfactor");
        for (i, p) in frame.positions.iter().enumerate() {
            let serial = written_serial(frame, i);
            // Serials past hybrid-36's range were rejected by `check`; wrap defensively.
            let serial = hy36_encode(serial, 5).unwrap_or_else(|| "*****".into());
            let element = written_element(frame, i);
            let sym = if element.is_unknown() {
                String::new()
            } else {
                element.symbol().to_ascii_uppercase()
            };
            let name = frame
                .names
                .get(i)
                .map_or_else(|| element.symbol().to_string(), |l| l.to_string());
            // Atom names start in column 14 unless they have 4 characters or a 2-letter element.
            let name = if name.len() >= 4 || sym.len() == 2 {
                format!("{name:<4}")
            } else {
                format!(" {name:<3}")
            };
            let res = frame.res_names.get(i).map_or("UNK", |l| l.as_str());
            let resid = frame.res_ids.get(i).copied().unwrap_or(1);
            let resid = hy36_encode(resid, 4).unwrap_or_else(|| "****".into());
            let chain = frame.chains.get(i).map_or(" ", |l| l.as_str());
            let chain = if chain.is_empty() { " " } else { chain };
            // A longer segment (a GROMACS molecule type) keeps its first 4 characters, as
            // MDAnalysis and VMD write it: the column is informational and 4 wide.
            let seg = frame.segments.get(i).map_or("", |l| l.as_str());
            let seg = seg.char_indices().nth(4).map_or(seg, |(k, _)| &seg[..k]);
            writeln!(
                w,
                "ATOM  {serial}{name:>5} {res:<4}{chain}{resid}    {:8.3}{:8.3}{:8.3}{:6.2}{:6.2}      {seg:<4}{sym:>2}",
                p[0],
                p[1],
                p[2],
                occupancy.map_or(1.0, |v| v[i]),
                bfactor.map_or(0.0, |v| v[i])
            )?;
        }
        w.write_all(conect.as_bytes())?;
        writeln!(w, "ENDMDL")
    }

    pub fn finish(&mut self) -> std::io::Result<()> {
        writeln!(self.out, "END")
    }
}

/// The `CONECT` records of `frame`'s bonds, each bond listed `mult` times from both atoms: one
/// line per atom in file order, up to four partners a line in file order.
fn conect_records(frame: &Frame, mult: &[u8]) -> String {
    use std::fmt::Write as _;
    let mut pairs: Vec<[u32; 2]> = Vec::with_capacity(frame.bonds.len() * 2);
    for (&[i, j], &m) in frame.bonds.iter().zip(mult) {
        for _ in 0..m {
            pairs.push([i, j]);
            pairs.push([j, i]);
        }
    }
    pairs.sort_unstable();
    // Serials were checked to fit 5 hybrid-36 columns; wrap defensively as the atoms do.
    let serial = |i: u32| {
        hy36_encode(written_serial(frame, i as usize), 5).unwrap_or_else(|| "*****".into())
    };
    let mut out = String::with_capacity(pairs.len() / 4 * 32 + pairs.len() * 3);
    for group in pairs.chunk_by(|a, b| a[0] == b[0]) {
        for line in group.chunks(4) {
            out.push_str("CONECT");
            out.push_str(&serial(line[0][0]));
            for p in line {
                out.push_str(&serial(p[1]));
            }
            let _ = writeln!(out);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hybrid36_matches_the_published_examples() {
        // Values from the hybrid-36 documentation.
        assert_eq!(hy36_decode(b"99999", 5), Some(99_999));
        assert_eq!(hy36_decode(b"A0000", 5), Some(100_000));
        assert_eq!(hy36_decode(b"A0001", 5), Some(100_001));
        assert_eq!(hy36_decode(b"ZZZZZ", 5), Some(43_770_015));
        assert_eq!(hy36_decode(b"a0000", 5), Some(43_770_016));
        assert_eq!(hy36_decode(b"zzzzz", 5), Some(87_440_031));
        assert_eq!(hy36_decode(b"A000", 4), Some(10_000));
        assert_eq!(hy36_decode(b"  12 ", 5), Some(12));
        assert_eq!(hy36_decode(b"A00", 5), None);
        assert_eq!(hy36_decode(b"A0a00", 5), None);
        // Encoding inverts decoding over the whole range boundaries and a stride through it.
        for v in (-9999..100_000)
            .step_by(7)
            .chain((99_990..87_440_032).step_by(9_973))
        {
            let s = hy36_encode(v, 5).unwrap();
            assert_eq!(s.len(), 5);
            assert_eq!(hy36_decode(s.as_bytes(), 5), Some(v), "{s}");
        }
        assert_eq!(hy36_encode(87_440_032, 5), None);
        assert_eq!(hy36_encode(10_000, 4).as_deref(), Some("A000"));
    }
}

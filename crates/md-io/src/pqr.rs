//! PQR (`.pqr`): PDB atom records with the occupancy and B-factor replaced by each atom's
//! partial charge (e) and radius (Å), as PDB2PQR writes them for APBS (also MEAD, MDAnalysis,
//! ParmEd, GROMACS `editconf -mead`).
//!
//! # Atom records
//! An `ATOM` or `HETATM` line is read as whitespace-separated fields, the way APBS, PDB2PQR and
//! MDAnalysis read it:
//!
//! ```text
//! ATOM serial name resName [chainID] resSeq[iCode] x y z charge radius [element]
//! ```
//!
//! The last five numbers are the coordinates, charge and radius (a trailing element symbol, as
//! GROMACS writes, is taken as the atom's element). What comes before them tells whether the
//! chain is there: `serial name resName resSeq` (four fields: PDB2PQR's default, without
//! `--keep-chain`) or `serial name resName chainID resSeq` (five). The insertion code may be
//! glued to the residue number (`36A`, as PDB2PQR writes it) or be a field of its own after
//! it; it is dropped (a [`Frame`] has no insertion codes, as for PDB), the number is kept.
//! Fields that touch, where PDB2PQR's fixed columns overflow, are read as PDB2PQR's own `psize`
//! reads them: a serial glued to `HETATM` (`HETATM10234`), a chain glued to a four-digit
//! residue number (`A1234`), and coordinates that run together (`15.180-188.097`) when the
//! line has PDB2PQR's fixed-column shape (columns 28-30 blank and three right-aligned
//! `%8.3f` numbers in columns 31-54: the coordinates are then read by column, the charge and
//! radius from the fields after column 54).
//!
//! The charge and radius become the `charge` and `radius` properties ([`Frame::property`]); the
//! radius is the electrostatics (Born) radius APBS uses, not a drawing radius, and hydrogens
//! may have 0, so it is not put in [`Frame::radii`]. Names, residue names and numbers, serials
//! (ids) and chains are kept (a frame whose chains are all absent has no chain column);
//! elements are guessed from the atom and residue names
//! ([`crate::elements::guess_element`]) unless the line ends in an element symbol.
//!
//! # Other records
//! `MODEL` / `ENDMDL` delimit frames (ParmEd writes every frame of a structure so; every
//! model must hold as many atoms as model 1, as for PDB); without them the file is one frame.
//! `CRYST1 a b c α β γ` (whitespace-separated; angles default to 90°) gives the cell of the
//! frames after it, the 1 Å placeholder none. `REMARK`, `TER`, `END` and the other PDB records
//! are skipped; a line with an unknown record name that ends in five numbers is an atom record
//! with a damaged name, an error rather than a silently lost atom.
//!
//! # References
//! - APBS documentation, "File formats: PQR" (docs/formats/pqr.rst of the APBS repository).
//! - PDB2PQR documentation and source (`pdb2pqr/structures.py` `Atom.from_pqr_line`,
//!   `pdb2pqr/psize.py` `parse_atom_fields`), version 3.8.

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{fields, parse_f32, parse_f64, parse_i64, res_number, span, trim};
use crate::pdb::{OTHER_RECORDS, hy36_decode};
use crate::text::{Ctx, FrameWalk, LineReader, ModelCheck, Pos};
use std::io::Read;

/// The PQR parser: the cell of the last CRYST1 and the model atom-count check.
#[derive(Default)]
pub(crate) struct Pqr {
    cell: Option<UnitCell>,
    models: ModelCheck,
}

/// Most fields an atom line may have: record, serial, name, resName, chain, resSeq, iCode,
/// x y z, charge, radius, element.
const MAX_FIELDS: usize = 13;

/// What a malformed atom line is told it should be.
const ATOM_LINE: &str = "ATOM serial name resName [chainID] resSeq x y z charge radius";

/// Record of a line: an atom record (with its serial when glued to the record name), another
/// record name, or none (a blank line).
enum Record<'a> {
    Atom(Option<&'a [u8]>),
    Other(&'a [u8]),
}

fn record(line: &[u8]) -> Record<'_> {
    let Some(first) = fields(line).next() else {
        return Record::Other(b"");
    };
    for name in [&b"ATOM"[..], b"HETATM"] {
        if let Some(rest) = first.strip_prefix(name) {
            if rest.is_empty() {
                return Record::Atom(None);
            }
            // `HETATM10234`: the fixed columns' serial glued to the record name.
            if rest[0].is_ascii_digit() {
                return Record::Atom(Some(rest));
            }
        }
    }
    Record::Other(first)
}

/// True when `f` is a right-aligned `%8.3f` number: blanks, an optional minus, digits, a point
/// and three digits, 8 bytes in all.
fn fixed_coordinate(f: &[u8]) -> bool {
    let Some(start) = f.iter().position(|b| *b != b' ') else {
        return false;
    };
    let t = &f[start..];
    let digits = t.strip_prefix(b"-").unwrap_or(t);
    let Some(dot) = digits.iter().position(|b| *b == b'.') else {
        return false;
    };
    let (int, frac) = (&digits[..dot], &digits[dot + 1..]);
    f.len() == 8
        && !int.is_empty()
        && int.iter().all(u8::is_ascii_digit)
        && frac.len() == 3
        && frac.iter().all(u8::is_ascii_digit)
}

/// True when the line has PDB2PQR's fixed-column shape (columns 28-30 blank, `%8.3f` numbers in
/// columns 31-38, 39-46, 47-54), where coordinates may touch.
fn fixed_columns(line: &[u8]) -> bool {
    line.len() >= 54
        && span(line, 27, 30).iter().all(|b| *b == b' ')
        && (0..3).all(|k| fixed_coordinate(span(line, 30 + 8 * k, 38 + 8 * k)))
}

/// True when `f` is an element symbol as a GROMACS PQR's last field holds it.
fn is_element_field(f: &[u8]) -> bool {
    !f.is_empty() && f.len() <= 2 && f.iter().all(u8::is_ascii_alphabetic)
}

/// True when a line whose record name is unknown ends in five numbers: an atom record whose
/// name is damaged.
fn has_atom_numbers(line: &[u8]) -> bool {
    let f: Vec<&[u8]> = fields(line).collect();
    f.len() >= 6 && f[f.len() - 5..].iter().all(|x| parse_f64(x).is_some())
}

/// The chain and residue number of the fields between the residue name and the coordinates
/// (`rest`: one to three fields), `None` when they are not one of the accepted shapes.
fn chain_and_residue<'a>(rest: &[&'a [u8]]) -> Option<(&'a [u8], i64)> {
    let icode = |f: &[u8]| f.len() == 1 && f[0].is_ascii_alphanumeric();
    match *rest {
        // `resSeq[iCode]`, or `A1234`: a chain glued to a four-digit number.
        [r] => match res_number(r) {
            Some(n) => Some((b"", n)),
            None if r.len() > 1 && r[0].is_ascii_alphabetic() => {
                res_number(&r[1..]).map(|n| (&r[..1], n))
            }
            None => None,
        },
        // `chain resSeq[iCode]`, else `resSeq iCode`.
        [a, b] => match res_number(b) {
            Some(n) => Some((a, n)),
            None if icode(b) => parse_i64(a).map(|n| (&b""[..], n)),
            None => None,
        },
        // `chain resSeq iCode`.
        [a, b, c] if icode(c) => parse_i64(b).map(|n| (a, n)),
        _ => None,
    }
}

impl Pqr {
    /// A parser; `lenient` turns an atom count that differs from model 1's into a warning.
    pub(crate) fn new(lenient: bool) -> Pqr {
        Pqr {
            cell: None,
            models: ModelCheck::new(lenient),
        }
    }

    /// The warnings gathered so far (emptied).
    pub(crate) fn take_warnings(&mut self) -> Vec<Error> {
        self.models.take_warnings()
    }

    fn check_count(&mut self, ctx: &Ctx, pos: Pos, n_atoms: usize) -> Result<(), Error> {
        let expected = "as many ATOM/HETATM records as model 1 (frame 0)";
        self.models.check(ctx, pos, n_atoms, expected)
    }

    /// A whitespace-separated `CRYST1 a b c [α β γ]`.
    fn cryst1(&mut self, ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<(), Error> {
        let mut v = [0f64, 0.0, 0.0, 90.0, 90.0, 90.0];
        let mut f = fields(line).skip(1);
        for (k, x) in v.iter_mut().enumerate() {
            match f.next() {
                Some(t) => {
                    *x =
                        parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, "a number in CRYST1"))?
                }
                None if k >= 3 => break,
                None => return Err(ctx.parse(pos, line, line, "CRYST1 a b c [alpha beta gamma]")),
            }
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

    /// Parses an atom line into `frame`; `serial` is the serial glued to the record name.
    fn atom(
        ctx: &Ctx,
        pos: Pos,
        line: &[u8],
        serial: Option<&[u8]>,
        frame: &mut Frame,
    ) -> Result<(), Error> {
        let fixed = fixed_columns(line);
        // The fields before the coordinates (`head`), the coordinates and after (`tail`).
        let (head_text, coords) = if fixed {
            (span(line, 0, 27), Some(span(line, 30, 54)))
        } else {
            (line, None)
        };
        let mut all = [&b""[..]; MAX_FIELDS + 1];
        let mut n = 0;
        let glued = usize::from(serial.is_some());
        if let Some(s) = serial {
            // After the record name; the name itself is field 0.
            all[1] = s;
        }
        for (k, f) in fields(head_text).enumerate() {
            let slot = if k == 0 { 0 } else { k + glued };
            if slot > MAX_FIELDS {
                return Err(ctx.parse(pos, line, f, ATOM_LINE));
            }
            all[slot] = f;
            n = slot + 1;
        }
        n = n.max(1 + glued);
        let mut xyz = [0f32; 3];
        let mut after = [&b""[..]; 3];
        let (head, tail): (&[&[u8]], &[&[u8]]) = match coords {
            Some(c) => {
                for (k, x) in xyz.iter_mut().enumerate() {
                    let f = trim(span(c, 8 * k, 8 * k + 8));
                    *x = parse_f32(f)
                        .ok_or_else(|| ctx.parse(pos, line, f, "a coordinate in columns 31-54"))?;
                }
                let mut t = 0;
                for f in fields(span(line, 54, line.len())) {
                    if t == after.len() {
                        return Err(ctx.parse(pos, line, f, "charge radius after the coordinates"));
                    }
                    after[t] = f;
                    t += 1;
                }
                (&all[1..n], &after[..t])
            }
            None => {
                // Whitespace: the last 5 numbers (6 fields with an element) end the line.
                let mut end = n;
                if end > 1 && is_element_field(all[end - 1]) {
                    end -= 1;
                }
                if end < 1 + 4 + 5 {
                    return Err(ctx.parse(pos, line, line, ATOM_LINE));
                }
                for (k, x) in xyz.iter_mut().enumerate() {
                    let f = all[end - 5 + k];
                    *x =
                        parse_f32(f).ok_or_else(|| ctx.parse(pos, line, f, "3 coordinates (Å)"))?;
                }
                (&all[1..end - 5], &all[end - 2..n])
            }
        };
        // serial name resName, then [chain] resSeq[iCode].
        if head.len() < 4 {
            return Err(ctx.parse(pos, line, line, ATOM_LINE));
        }
        let id_f = head[0];
        let id = parse_i64(id_f)
            .or_else(|| hy36_decode(id_f, 5))
            .ok_or_else(|| ctx.parse(pos, line, id_f, "an atom serial number"))?;
        let name = Label::from_utf8(head[1])
            .ok_or_else(|| ctx.parse(pos, line, head[1], "an atom name of at most 15 bytes"))?;
        let res = Label::from_utf8(head[2])
            .ok_or_else(|| ctx.parse(pos, line, head[2], "a residue name of at most 15 bytes"))?;
        let (chain_f, resid) = chain_and_residue(&head[3..]).ok_or_else(|| {
            ctx.parse(
                pos,
                line,
                head[3],
                "[chainID] resSeq[iCode] before the coordinates",
            )
        })?;
        let chain = Label::from_utf8(chain_f).ok_or_else(|| {
            ctx.parse(pos, line, chain_f, "a chain identifier of at most 15 bytes")
        })?;
        // charge radius [element]
        let (q_f, r_f, element) = match *tail {
            [q, r] => (q, r, None),
            [q, r, e] if is_element_field(e) => (q, r, Some(e)),
            _ => {
                let at = tail.first().copied().unwrap_or(&line[line.len()..]);
                return Err(ctx.parse(pos, line, at, "charge radius after the coordinates"));
            }
        };
        let charge = parse_f32(q_f)
            .ok_or_else(|| ctx.parse(pos, line, q_f, "a charge (e) after the coordinates"))?;
        let radius = parse_f32(r_f)
            .filter(|r| *r >= 0.0)
            .ok_or_else(|| ctx.parse(pos, line, r_f, "a radius >= 0 (Å) after the charge"))?;
        let element = element.and_then(|e| std::str::from_utf8(e).ok());
        frame.positions.push(xyz);
        frame
            .elements
            .push(guess_element(&name, Some(&res), element));
        frame.ids.push(id);
        frame.names.push(name);
        frame.res_names.push(res);
        frame.res_ids.push(resid);
        frame.chains.push(chain);
        frame.property_mut("charge").push(charge);
        frame.property_mut("radius").push(radius);
        Ok(())
    }

    /// Drops the chain column of a finished frame when no atom has a chain, and sets the cell.
    fn finish(&self, frame: &mut Frame) {
        if frame.chains.iter().all(|c| c.is_empty()) {
            frame.chains.clear();
        }
        frame.cell = self.cell;
    }
}

impl FrameWalk for Pqr {
    /// Walks the records of one frame; parses the atom lines when given a frame.
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
                Record::Atom(serial) => {
                    n_atoms += 1;
                    if let Some(f) = frame.as_deref_mut() {
                        Pqr::atom(ctx, pos, line, serial, f)?;
                    }
                }
                Record::Other(b"MODEL") => {
                    if in_model || n_atoms > 0 {
                        // A new model without ENDMDL before it: this frame ends here.
                        lines.unread(pos);
                        break;
                    }
                    in_model = true;
                }
                Record::Other(b"ENDMDL") => {
                    self.check_count(ctx, pos, n_atoms)?;
                    if let Some(f) = frame {
                        self.finish(f);
                    }
                    return Ok(true);
                }
                Record::Other(b"END") if n_atoms > 0 => break,
                Record::Other(b"CRYST1") => self.cryst1(ctx, pos, line)?,
                Record::Other(name) if !OTHER_RECORDS.contains(&name) && has_atom_numbers(line) => {
                    return Err(ctx.parse(pos, line, name, "ATOM or HETATM first"));
                }
                Record::Other(_) => {}
            }
        }
        let found = n_atoms > 0 || in_model;
        if found {
            self.check_count(ctx, lines.pos(), n_atoms)?;
        }
        if let Some(f) = frame {
            self.finish(f);
        }
        Ok(found)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Format, Trajectory};
    use std::io::Cursor;

    fn read(text: &str) -> Result<Vec<Frame>, Error> {
        let mut t = Trajectory::from_reader(Cursor::new(text.to_string()), Format::Pqr, "t")?;
        let mut out = Vec::new();
        let mut f = Frame::new();
        while t.read_next(&mut f)? {
            out.push(f.clone());
        }
        Ok(out)
    }

    /// An atom line as PDB2PQR's `Atom.get_pqr_string` lays it out (fixed columns); `seq` is
    /// the residue number and insertion code.
    fn pdb2pqr(
        (rec, serial): (&str, u32),
        name: &str,
        res: &str,
        chain: &str,
        seq: (i64, &str),
        x: [f64; 3],
        (q, r): (f64, f64),
    ) -> String {
        let name = if name.len() == 4 {
            name.to_string()
        } else {
            format!(" {name:<3}")
        };
        let (num, icode) = seq;
        let (q, r) = (format!("{q:.4}"), format!("{r:.4}"));
        format!(
            "{rec:<6}{serial:>5} {name} {res:<3} {chain:1}{num:>4}{icode:<4}{:8.3}{:8.3}{:8.3}{q:>8}{r:>7}\n",
            x[0], x[1], x[2]
        )
    }

    #[test]
    fn field_shapes() {
        let mut text = String::from("REMARK   1 PQR file generated by PDB2PQR\n");
        text += &pdb2pqr(
            ("ATOM", 1),
            "N",
            "ILE",
            "",
            (16, ""),
            [5.007, -9.234, 18.432],
            (-0.3, 1.85),
        );
        text += &pdb2pqr(
            ("ATOM", 335),
            "N",
            "SER",
            "",
            (36, "A"),
            [18.394, -8.624, 0.311],
            (-0.47, 1.85),
        );
        // Coordinates that touch, in the fixed columns.
        text += &pdb2pqr(
            ("ATOM", 3),
            "CA",
            "SER",
            "A",
            (37, ""),
            [18.394, -108.624, 0.311],
            (0.47, 1.85),
        );
        // A serial glued to HETATM, a chain to a four-digit residue number.
        text += &pdb2pqr(
            ("HETATM", 10234),
            "O",
            "HOH",
            "A",
            (1234, ""),
            [13.664, 24.877, 18.003],
            (-0.834, 1.7682),
        );
        text += "ATOM 5 OW SOL 7 1.0 2.0 3.0 -0.834 1.5 O\n";
        text += "ATOM 6 HW1 SOL B 7 X 1.0 2.0 3.0 0.417 0.0\nTER\nEND\n";
        assert!(
            text.contains("18.394-108.624")
                && text.contains("HETATM10234")
                && text.contains("A1234"),
            "{text}"
        );
        let f = &read(&text).unwrap()[0];
        assert_eq!(f.n_atoms(), 6);
        assert_eq!(f.ids, [1, 335, 3, 10234, 5, 6]);
        assert_eq!(f.res_ids, [16, 36, 37, 1234, 7, 7]);
        let chains: Vec<&str> = f.chains.iter().map(|c| c.as_str()).collect();
        assert_eq!(chains, ["", "", "A", "A", "", "B"]);
        assert_eq!(f.positions[2], [18.394, -108.624, 0.311]);
        assert_eq!(f.positions[4], [1.0, 2.0, 3.0]);
        assert_eq!(
            f.property("charge").unwrap(),
            [-0.3, -0.47, 0.47, -0.834, -0.834, 0.417]
        );
        assert_eq!(f.property("radius").unwrap()[5], 0.0);
        assert_eq!(f.elements[4].symbol(), "O");
        assert!(f.radii.is_empty());
    }

    #[test]
    fn damaged_record_name_is_an_error() {
        let text = "ATOM 1 N ALA 1 0 0 0 0.1 1.5\nATXM 2 C ALA 1 0 0 0 0.1 1.5\n";
        let e = read(text).unwrap_err().to_string();
        assert!(
            e.starts_with("t: frame 0, line 2, byte 29: expected ATOM or HETATM"),
            "{e}"
        );
    }
}

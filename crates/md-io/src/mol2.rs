//! Tripos MOL2 (`.mol2`): the format of docking inputs and outputs (DOCK, GOLD, Open Babel,
//! Chimera, antechamber's ligand parameters). Each `@<TRIPOS>MOLECULE` record is a frame:
//! several poses of a ligand make a trajectory, a library of molecules one frame per molecule.
//!
//! # What is read
//! - `@<TRIPOS>MOLECULE`: the name (the frame's comment) and the counts line (atoms, then
//!   bonds, the rest ignored).
//! - `@<TRIPOS>ATOM`, one line per atom: `atom_id atom_name x y z atom_type [subst_id
//!   [subst_name [charge ...]]]`, whitespace-separated. The name, id, position (Å) and type
//!   (`C.ar`, `N.am`, `O.co2`: SYBYL types) are kept; the element is the type's part before the
//!   dot when that is a symbol (as MDAnalysis and Open Babel read it), else guessed from the
//!   name (`Du`, `LP`, `Any`). `subst_id` and `subst_name` are the residue number and name, as
//!   MDAnalysis reads them (`LIG1`, `ALA12`: the name as written); `charge` becomes the `charge`
//!   property (partial charges in e). An optional column present on the first atom line must be
//!   on every one.
//! - `@<TRIPOS>BOND`: `bond_id origin target type`, the two atoms named by their `atom_id`,
//!   into [`Frame::bonds`], the SYBYL type into [`Frame::bond_orders`] (`1`, `2`, `3`, `ar`
//!   aromatic; an amide `am` single; `du`, `un`, `nc` 0).
//! - Other sections (`SUBSTRUCTURE`, `CRYSIN`, `COMMENT`, ...) are skipped, as are `#` comment
//!   and blank lines between records and sections.
//!
//! # Damage
//! Errors name the file, frame, line and byte: a record not starting with
//! `@<TRIPOS>MOLECULE`, a counts line without an atom count, an atom line with too few fields
//! or a coordinate that is no number, an atom id used twice, a bond naming an atom id the
//! molecule does not have (or one atom twice), fewer atom or bond lines than counted, a molecule
//! without its atom section or (with bonds counted) its bond section, or with a second atom
//! section (the next molecule's header damaged: two molecules are never read as one). Where
//! the data ends instead, it is a truncation, so `allow_truncated` keeps the molecules before it.
//!
//! # References
//! - Tripos, "Tripos Mol2 File Format" (SYBYL 7.1 documentation).

use std::io::Read;

use crate::elements::{Element, guess_element};
use crate::error::Error;
use crate::frame::{Frame, Label};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};

/// The MOL2 parser.
#[derive(Default)]
pub(crate) struct Mol2 {
    /// Per molecule: (atom id, index) sorted by id, to resolve bonds.
    ids: Vec<(i64, u32)>,
}

const MOLECULE: &[u8] = b"@<TRIPOS>MOLECULE";

/// True for lines that carry nothing: blank, or a `#` comment.
fn is_filler(line: &[u8]) -> bool {
    let t = trim(line);
    t.is_empty() || t[0] == b'#'
}

/// The next line that is not filler, or `None` at the end of the data.
fn next_content<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
) -> Result<Option<(Pos, &'a [u8])>, Error> {
    loop {
        let p = lines.pos();
        match lines.next_line().map_err(|e| ctx.io(p, e))? {
            None => return Ok(None),
            Some((_, l)) if is_filler(l) => continue,
            Some((pos, _)) => {
                // Re-read it, so the returned slice borrows the reader once.
                lines.unread(pos);
                return lines.next_line().map_err(|e| ctx.io(p, e));
            }
        }
    }
}

/// The next content line, or a truncation error saying what was expected.
fn need<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: impl FnOnce() -> String,
) -> Result<(Pos, &'a [u8]), Error> {
    let p = lines.pos();
    next_content(lines, ctx)?.ok_or_else(|| ctx.truncated(p, expected()))
}

impl FrameWalk for Mol2 {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        let Some((pos, line)) = next_content(lines, ctx)? else {
            return Ok(false);
        };
        if !trim(line).starts_with(MOLECULE) {
            return Err(ctx.parse(pos, line, line, "'@<TRIPOS>MOLECULE' starting a molecule"));
        }
        // The name line may be blank: read it raw.
        let p = lines.pos();
        let Some((_, name)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the molecule's name line".into()));
        };
        if let Some(f) = frame.as_deref_mut() {
            f.comment = String::from_utf8_lossy(trim(name)).into_owned();
        }
        let (n_atoms, n_bonds) = {
            let (pos, line) = need(lines, ctx, || "the molecule's counts line".into())?;
            let mut counts = fields(line);
            let n_atoms = counts
                .next()
                .and_then(parse_usize)
                .ok_or_else(|| ctx.parse(pos, line, line, "the number of atoms"))?;
            let n_bonds = match counts.next() {
                None => 0,
                Some(f) => {
                    parse_usize(f).ok_or_else(|| ctx.parse(pos, line, f, "the number of bonds"))?
                }
            };
            (n_atoms, n_bonds)
        };

        self.ids.clear();
        let mut atoms_seen = n_atoms == 0;
        let mut bonds_seen = false;
        let mut bonds = Vec::new();
        loop {
            let p = lines.pos();
            let Some((pos, line)) = next_content(lines, ctx)? else {
                if !atoms_seen {
                    return Err(ctx.truncated(p, "the molecule's '@<TRIPOS>ATOM' section".into()));
                }
                if n_bonds > 0 && !bonds_seen {
                    return Err(ctx.truncated(p, "the molecule's '@<TRIPOS>BOND' section".into()));
                }
                break;
            };
            let t = trim(line);
            let (next, atom, bond) = (
                t.starts_with(MOLECULE),
                t.starts_with(b"@<TRIPOS>ATOM"),
                t.starts_with(b"@<TRIPOS>BOND"),
            );
            if (next || bond) && !atoms_seen {
                return Err(ctx.parse(pos, line, line, "the '@<TRIPOS>ATOM' section first"));
            }
            if atom && atoms_seen && n_atoms > 0 {
                // Two atom sections: the next molecule's header line is damaged.
                return Err(ctx.parse(pos, line, line, "'@<TRIPOS>MOLECULE' before more atoms"));
            }
            if next && n_bonds > 0 && !bonds_seen {
                return Err(ctx.parse(pos, line, line, "the molecule's '@<TRIPOS>BOND' section"));
            }
            if next {
                lines.unread(pos);
                break;
            }
            if atom {
                self.atoms(lines, ctx, frame.as_deref_mut(), n_atoms)?;
                atoms_seen = true;
            } else if bond {
                bonds = self.bonds(lines, ctx, n_bonds)?;
                bonds_seen = true;
            }
            // Any other line belongs to a section not read.
        }
        if let Some(f) = frame {
            crate::frame::set_ordered_bonds(f, bonds);
        }
        Ok(true)
    }
}

impl Mol2 {
    fn atoms<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
        n: usize,
    ) -> Result<(), Error> {
        if let Some(f) = frame.as_deref_mut() {
            f.positions.reserve(n.min(ctx.reserve));
        }
        let mut columns = None;
        // Where each atom line starts, to name the second use of an atom id.
        let mut starts = Vec::with_capacity(n.min(ctx.reserve));
        for i in 0..n {
            let (pos, line) = need(lines, ctx, || format!("{} more atom lines", n - i))?;
            let w: Vec<&[u8]> = fields(line).take(9).collect();
            if w.len() < 6 {
                return Err(ctx.parse(pos, line, line, "atom_id name x y z type"));
            }
            let id = parse_i64(w[0]).ok_or_else(|| ctx.parse(pos, line, w[0], "an atom id"))?;
            let name = Label::from_utf8(w[1])
                .ok_or_else(|| ctx.parse(pos, line, w[1], "an atom name of at most 15 bytes"))?;
            let mut xyz = [0f32; 3];
            for (k, x) in xyz.iter_mut().enumerate() {
                *x = parse_f64(w[2 + k])
                    .map(|v| v as f32)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| ctx.parse(pos, line, w[2 + k], "x, y, z (Å)"))?;
            }
            let ty = Label::from_utf8(w[5])
                .ok_or_else(|| ctx.parse(pos, line, w[5], "an atom type of at most 15 bytes"))?;
            // The optional subst_id, subst_name, charge: as many as the first atom line has.
            let extra = (w.len() - 6).min(3);
            let want = *columns.get_or_insert(extra);
            if extra < want {
                return Err(ctx.parse(
                    pos,
                    line,
                    line,
                    "subst_id, subst_name and charge as on the first atom line",
                ));
            }
            let res_id = match want {
                0 => None,
                _ => Some(parse_i64(w[6]).ok_or_else(|| ctx.parse(pos, line, w[6], "a subst_id"))?),
            };
            let res_name = match want {
                0 | 1 => None,
                _ => Some(Label::from_utf8(w[7]).ok_or_else(|| {
                    ctx.parse(pos, line, w[7], "a subst_name of at most 15 bytes")
                })?),
            };
            let charge = match want {
                3 => Some(
                    parse_f64(w[8])
                        .map(|v| v as f32)
                        .ok_or_else(|| ctx.parse(pos, line, w[8], "a partial charge"))?,
                ),
                _ => None,
            };
            self.ids.push((id, i as u32));
            starts.push(pos);
            let Some(f) = frame.as_deref_mut() else {
                continue;
            };
            let symbol = ty.as_str().split('.').next().unwrap_or("");
            let element = Element::from_symbol(symbol).unwrap_or_else(|| {
                guess_element(name.as_str(), res_name.as_ref().map(Label::as_str), None)
            });
            f.positions.push(xyz);
            f.elements.push(element);
            f.names.push(name);
            f.types.push(ty);
            f.ids.push(id);
            if let Some(r) = res_id {
                f.res_ids.push(r);
            }
            if let Some(r) = res_name {
                f.res_names.push(r);
            }
            if let Some(q) = charge {
                f.property_mut("charge").push(q);
            }
        }
        self.ids.sort_unstable();
        if let Some(w) = self.ids.windows(2).find(|w| w[0].0 == w[1].0) {
            // The later of the two lines, named by its atom id.
            let id = w[0].0.to_string();
            let line = starts[w[0].1.max(w[1].1) as usize];
            return Err(ctx.parse(
                line,
                id.as_bytes(),
                id.as_bytes(),
                "atom ids each used once",
            ));
        }
        Ok(())
    }

    fn bonds<R: Read>(
        &self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        n: usize,
    ) -> Result<Vec<([u32; 2], u8)>, Error> {
        let mut bonds = Vec::with_capacity(n.min(ctx.reserve));
        let atom = |f: &[u8]| {
            let id = parse_i64(f)?;
            let k = self.ids.binary_search_by_key(&id, |e| e.0).ok()?;
            Some(self.ids[k].1)
        };
        for i in 0..n {
            let (pos, line) = need(lines, ctx, || format!("{} more bond lines", n - i))?;
            let w: Vec<&[u8]> = fields(line).take(4).collect();
            let what = "bond_id and two atom ids of this molecule";
            let (Some(a), Some(b)) = (
                w.get(1).and_then(|f| atom(f)),
                w.get(2).and_then(|f| atom(f)),
            ) else {
                return Err(ctx.parse(pos, line, line, what));
            };
            if a == b {
                return Err(ctx.parse(pos, line, line, what));
            }
            // The SYBYL bond type: 1, 2, 3, ar(omatic), am(ide: drawn single), du, un, nc.
            let order = match w.get(3).map(|t| t.to_ascii_lowercase()) {
                Some(t) if t == b"1" || t == b"am" => 1,
                Some(t) if t == b"2" => 2,
                Some(t) if t == b"3" => 3,
                Some(t) if t == b"ar" => crate::frame::BOND_AROMATIC,
                _ => 0,
            };
            bonds.push(([a.min(b), a.max(b)], order));
        }
        Ok(bonds)
    }
}

//! Tinker Cartesian coordinates (`.txyz`, and `.xyz` files in Tinker's layout) and archives
//! (`.arc`: the frames of a Tinker run, one after another).
//!
//! A frame is a header line — the atom count, then an optional title — an optional box line of
//! six numbers (a b c in Å, α β γ in degrees: Tinker writes it for a periodic system), then one
//! line per atom:
//!
//! ```text
//! index  name  x  y  z  type  [bonded atom indices ...]
//! ```
//!
//! whitespace-separated. Names become the atoms' names (elements guessed from them,
//! [`crate::elements::guess_element`]), the force field's atom type numbers their types, the
//! indices their ids, and the bonded indices (1-based, each bond listed by both atoms) the
//! frame's bonds. A bonded index that names no atom of the frame is an error. The box line is
//! told from an atom line by its first field: a number with a decimal point, where an atom
//! line starts with an integer index.
//!
//! A `.xyz` file is Tinker's when its second line (or third, after a box line) has an atom
//! line's shape ([`Format::tinker_xyz`](crate::Format::tinker_xyz)); otherwise it is XYZ.
//!
//! # References
//! - Tinker User's Guide, "Cartesian coordinate files (.xyz)" and "archive files (.arc)".
//! - Open Babel's `tinkerformat` (the writer of the tests' molecules) and MDAnalysis's
//!   `TXYZParser` / `TXYZReader` (the reader they are compared with).

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell, set_ordered_bonds};
use crate::parse::{fields, parse_f32, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, LineReader, Pos, TextFormat, need_line};
use std::io::Read;

/// The Tinker parser.
#[derive(Default)]
pub(crate) struct Tinker {
    bonds: Vec<([u32; 2], u8)>,
}

/// True when `line`'s first field is a number with a decimal point (a box line's).
fn starts_with_real(line: &[u8]) -> bool {
    fields(line)
        .next()
        .is_some_and(|f| f.contains(&b'.') && parse_f64(f).is_some())
}

impl Tinker {
    /// The header: the atom count (the title is the frame's comment).
    fn header<R: Read>(
        lines: &mut LineReader<R>,
        ctx: &Ctx,
    ) -> Result<Option<(usize, String)>, Error> {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(None);
        };
        let t = trim(line);
        let end = t
            .iter()
            .position(|b| matches!(b, b' ' | b'\t'))
            .unwrap_or(t.len());
        let n = parse_usize(&t[..end])
            .ok_or_else(|| ctx.parse(pos, line, &t[..end], "the number of atoms"))?;
        let title = String::from_utf8_lossy(trim(&t[end..])).into_owned();
        Ok(Some((n, title)))
    }

    /// The box line, if the next line is one (else it is given back).
    fn cell<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<Option<UnitCell>, Error> {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(None);
        };
        if !starts_with_real(line) {
            lines.unread(pos);
            return Ok(None);
        }
        let mut v = [0f64; 6];
        let mut k = 0;
        for f in fields(line) {
            if k == 6 {
                return Err(ctx.parse(pos, line, f, "6 box numbers: a b c alpha beta gamma"));
            }
            v[k] = parse_f64(f).ok_or_else(|| ctx.parse(pos, line, f, "a box number"))?;
            k += 1;
        }
        if k != 6 {
            return Err(ctx.parse(pos, line, line, "6 box numbers: a b c alpha beta gamma"));
        }
        UnitCell::from_lengths_angles([v[0], v[1], v[2]], [v[3], v[4], v[5]])
            .map(Some)
            .map_err(|_| ctx.parse(pos, line, line, "a box with volume > 0"))
    }
}

impl TextFormat for Tinker {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        let Some((n, title)) = Tinker::header(lines, ctx)? else {
            return Ok(false);
        };
        frame.comment = title;
        frame.cell = Tinker::cell(lines, ctx)?;
        frame.positions.reserve(n.min(ctx.reserve));
        self.bonds.clear();
        // Bonds as listed (1-based), checked once every atom is known.
        let mut listed: Vec<(u32, i64, Pos)> = Vec::new();
        for i in 0..n {
            let (pos, line) = need_line(lines, ctx, &format!("{} more atom lines", n - i))?;
            let mut it = fields(line);
            let mut next = |what: &'static str| {
                it.next()
                    .ok_or_else(|| ctx.parse(pos, line, &line[line.len()..], what))
            };
            let id_f = next("an atom index")?;
            let id = parse_i64(id_f).ok_or_else(|| ctx.parse(pos, line, id_f, "an atom index"))?;
            let name_f = next("an atom name")?;
            let name = Label::from_utf8(name_f)
                .ok_or_else(|| ctx.parse(pos, line, name_f, "an atom name"))?;
            let mut xyz = [0f32; 3];
            for x in &mut xyz {
                let f = next("3 coordinates (Å)")?;
                *x = parse_f32(f).ok_or_else(|| ctx.parse(pos, line, f, "a coordinate (Å)"))?;
            }
            let type_f = next("the atom type number")?;
            parse_i64(type_f)
                .ok_or_else(|| ctx.parse(pos, line, type_f, "the atom type number"))?;
            let ty = Label::from_utf8(type_f)
                .ok_or_else(|| ctx.parse(pos, line, type_f, "the atom type number"))?;
            for f in it {
                let j =
                    parse_i64(f).ok_or_else(|| ctx.parse(pos, line, f, "a bonded atom's index"))?;
                listed.push((i as u32, j, pos));
            }
            frame.positions.push(xyz);
            frame.elements.push(guess_element(&name, None, None));
            frame.names.push(name);
            frame.types.push(ty);
            frame.ids.push(id);
        }
        // Indices are the atoms' 1-based positions in the frame (Tinker numbers them so).
        for (i, j, pos) in listed {
            if j < 1 || j as usize > n || j as usize - 1 == i as usize {
                return Err(Error::Parse {
                    at: ctx.at(pos),
                    expected: "bonded atom indices between 1 and the atom count, not the atom's own",
                    found: format!("atom {} bonded to {j}", i + 1),
                });
            }
            let j = (j - 1) as u32;
            self.bonds.push(([i.min(j), i.max(j)], 1));
        }
        set_ordered_bonds(frame, std::mem::take(&mut self.bonds));
        frame.bond_orders.clear();
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some((n, _)) = Tinker::header(lines, ctx)? else {
            return Ok(false);
        };
        Tinker::cell(lines, ctx)?;
        let p = lines.pos();
        let missing = lines.skip_lines(n).map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{missing} more atom lines")));
        }
        Ok(true)
    }
}

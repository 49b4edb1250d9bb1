//! GROMACS .gro: fixed columns, nm (converted to Å), optional velocities, multi-frame.
//!
//! A frame is a title line (GROMACS writes `t= <ps> step= <n>` there, which we read), an
//! atom-count line, one line per atom and a box line. Atom lines are
//! `%5d%-5s%5s%5d` (residue number, residue name, atom name, atom number) then three positions
//! of width `w` (`%w.pf`) and optionally three velocities of the same width with one more
//! decimal (`%w.(p+1)f`), where `w` = precision p + 5:
//! the precision varies between writers, so `w` is measured on each frame's first atom line as
//! the distance between the first two decimal points. The box line holds 3 numbers
//! (v1x v2y v3z) or 9 (v1x v2y v3z v1y v1z v2x v2z v3x v3y), in nm. A zero box means no cell.
//!
//! Positions ×10 (nm → Å) and velocities ×10 (nm/ps → Å/ps), computed in f64 and rounded once
//! to f32. Elements are guessed from atom and residue names ([`crate::elements::guess_element`]).
//!
//! # References
//! - GROMACS manual, "File formats: gro".

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, span, trim};
use crate::text::{Ctx, LineReader, Pos, TextFormat};
use std::io::Read;

/// nm → Å.
const NM: f64 = 10.0;

#[derive(Default)]
pub(crate) struct Gro;

/// Reads `t=` and `step=` from a GROMACS title.
fn title_time_step(title: &[u8], frame: &mut Frame) {
    let mut it = fields(title).peekable();
    while let Some(f) = it.next() {
        let (key, inline) = match f.iter().position(|b| *b == b'=') {
            Some(k) => (&f[..k], &f[k + 1..]),
            None => continue,
        };
        let value = if inline.is_empty() {
            it.next().unwrap_or(inline)
        } else {
            inline
        };
        match key {
            b"t" => frame.time = parse_f64(value),
            b"step" => frame.step = parse_i64(value),
            _ => {}
        }
    }
}

impl Gro {
    fn count<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<Option<(Pos, usize)>, Error> {
        // Title line.
        let p = lines.pos();
        if lines.next_line().map_err(|e| ctx.io(p, e))?.is_none() {
            return Ok(None);
        }
        // Atom count.
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the number of atoms".into()));
        };
        let t = trim(line);
        let n = parse_usize(t).ok_or_else(|| ctx.parse(pos, line, t, "the number of atoms"))?;
        Ok(Some((pos, n)))
    }

    fn cell(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<Option<UnitCell>, Error> {
        let mut v = [0f64; 9];
        let mut k = 0;
        for f in fields(line) {
            if k == 9 {
                return Err(ctx.parse(pos, line, f, "3 or 9 box numbers"));
            }
            v[k] = parse_f64(f).ok_or_else(|| ctx.parse(pos, line, f, "a box number (nm)"))? * NM;
            k += 1;
        }
        if k != 3 && k != 9 {
            return Err(ctx.parse(pos, line, line, "3 or 9 box numbers"));
        }
        if v.iter().all(|x| *x == 0.0) {
            return Ok(None);
        }
        // v1 = (v1x, v1y, v1z), v2 = (v2x, v2y, v2z), v3 = (v3x, v3y, v3z).
        let m = [[v[0], v[3], v[4]], [v[5], v[1], v[6]], [v[7], v[8], v[2]]];
        UnitCell::from_matrix(m)
            .map(Some)
            .map_err(|_| ctx.parse(pos, line, line, "a box with volume > 0"))
    }
}

impl TextFormat for Gro {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        // Title (time and step), then the atom count.
        let p = lines.pos();
        let Some((_, title)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(false);
        };
        frame
            .comment
            .push_str(&String::from_utf8_lossy(trim(title)));
        title_time_step(title, frame);
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the number of atoms".into()));
        };
        let t = trim(line);
        let n = parse_usize(t).ok_or_else(|| ctx.parse(pos, line, t, "the number of atoms"))?;
        frame.positions.reserve(n.min(ctx.reserve));
        // Atom lines: fixed columns, position width measured on the first line.
        let mut width = 0usize;
        let mut has_vel = false;
        for i in 0..n {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Err(ctx.truncated(p, format!("{} more atom lines", n - i)));
            };
            if i == 0 {
                // Measure the field width between the first two decimal points after column 20.
                let rest = span(line, 20, line.len());
                let mut dots = rest
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| **b == b'.')
                    .map(|(k, _)| k);
                width = match (dots.next(), dots.next()) {
                    (Some(a), Some(b)) if b > a => b - a,
                    _ => {
                        return Err(ctx.parse(
                            pos,
                            line,
                            rest,
                            "3 positions with decimal points from column 21",
                        ));
                    }
                };
                has_vel = !trim(span(rest, 3 * width, rest.len())).is_empty();
            }
            let resid_f = trim(span(line, 0, 5));
            let res_f = trim(span(line, 5, 10));
            let name_f = trim(span(line, 10, 15));
            let id_f = trim(span(line, 15, 20));
            let resid = parse_i64(resid_f)
                .ok_or_else(|| ctx.parse(pos, line, resid_f, "a residue number in columns 1-5"))?;
            let res = Label::from_utf8(res_f)
                .ok_or_else(|| ctx.parse(pos, line, res_f, "a residue name in columns 6-10"))?;
            let name = Label::from_utf8(name_f)
                .ok_or_else(|| ctx.parse(pos, line, name_f, "an atom name in columns 11-15"))?;
            // Atom numbers wrap at 100,000 in GROMACS output: keep them as written.
            let id = parse_i64(id_f).unwrap_or(i as i64 + 1);
            let mut xyz = [0f32; 3];
            for (k, x) in xyz.iter_mut().enumerate() {
                let f = trim(span(line, 20 + k * width, 20 + (k + 1) * width));
                *x = parse_f64(f)
                    .map(|v| (v * NM) as f32)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| ctx.parse(pos, line, f, "3 positions (nm) from column 21"))?;
            }
            if has_vel {
                let mut v = [0f32; 3];
                let v0 = 20 + 3 * width;
                for (k, x) in v.iter_mut().enumerate() {
                    let f = trim(span(line, v0 + k * width, v0 + (k + 1) * width));
                    *x = parse_f64(f)
                        .map(|v| (v * NM) as f32)
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            ctx.parse(pos, line, f, "3 velocities (nm/ps) after the positions")
                        })?;
                }
                frame.velocities.push(v);
            }
            frame.positions.push(xyz);
            frame.elements.push(guess_element(&name, Some(&res), None));
            frame.names.push(name);
            frame.res_names.push(res);
            frame.res_ids.push(resid);
            frame.ids.push(id);
        }
        // Box line.
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the box line".into()));
        };
        frame.cell = Gro::cell(ctx, pos, line)?;
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some((_, n)) = Gro::count(lines, ctx)? else {
            return Ok(false);
        };
        let p = lines.pos();
        let missing = lines.skip_lines(n).map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{missing} more atom lines")));
        }
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the box line".into()));
        };
        Gro::cell(ctx, pos, line)?;
        Ok(true)
    }
}

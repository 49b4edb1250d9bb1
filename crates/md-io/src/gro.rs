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

/// Writes GROMACS .gro frames as `gmx trjconv` and MDAnalysis do, one after another (a
/// multi-frame .gro).
///
/// Each frame: the title (the frame's comment, else `texmap`, then GROMACS's ` t= <ps>` and
/// ` step= <n>` when the frame has them, which GROMACS tools and our reader take back), the atom
/// count, one `%5d%-5s%5s%5d%8.3f%8.3f%8.3f` line per atom (residue number, residue name, atom
/// name, atom number, position in nm) with `%8.4f` velocities (nm/ps) when the frame has them,
/// and the box line in nm as `%10.5f`: v1x v2y v3z, then v1y v1z v2x v2z v3x v3y when the cell
/// is not rectangular; a frame without a cell writes a zero box, which readers take as none.
///
/// Residue numbers are [`Frame::res_ids`] (else 1), residue names [`Frame::res_names`] (else
/// `UNK`), atom names [`Frame::names`] (else the element's symbol), atom numbers
/// [`Frame::ids`] (else 1, 2, ...); numbers wrap at 100,000 as GROMACS writes them. Positions
/// keep 0.01 Å (three decimals of nm), velocities 0.001 Å/ps.
///
/// [`GroWriter::check`] refuses what the fixed columns cannot hold: a name or residue name
/// longer than 5 bytes or with white space, a position beyond ±9999.999 nm, a velocity beyond
/// ±999.9999 nm/ps, a cell not in GROMACS's form (v1 along x, v2 in the xy plane).
pub(crate) struct GroWriter<W> {
    pub out: W,
}

impl<W: std::io::Write> GroWriter<W> {
    /// Why `frame` cannot be written as .gro, if it cannot (see [`GroWriter`]).
    pub fn check(frame: &Frame) -> Result<(), String> {
        for (what, labels) in [("name", &frame.names), ("residue name", &frame.res_names)] {
            if let Some((i, l)) = labels
                .iter()
                .enumerate()
                .find(|(_, l)| l.len() > 5 || l.bytes().any(|b| b.is_ascii_whitespace()))
            {
                return Err(format!(
                    "atom {i}'s {what} '{l}' does not fit .gro's 5 columns (at most 5 bytes, no white space)"
                ));
            }
        }
        let fits = |v: &[[f32; 3]], limit: f64| {
            v.iter()
                .position(|p| p.iter().any(|x| (*x as f64 / NM).abs() >= limit))
        };
        if let Some(i) = fits(&frame.positions, 9999.9995) {
            return Err(format!(
                "atom {i}'s position {:?} Å is beyond .gro's %8.3f nm columns",
                frame.positions[i]
            ));
        }
        if let Some(i) = fits(&frame.velocities, 999.99995) {
            return Err(format!(
                "atom {i}'s velocity {:?} Å/ps is beyond .gro's %8.4f nm/ps columns",
                frame.velocities[i]
            ));
        }
        if let Some(c) = &frame.cell {
            let m = c.matrix();
            let tol = 1e-9 * c.lengths().iter().fold(0.0f64, |a, b| a.max(*b));
            if m[0][1].abs() > tol || m[0][2].abs() > tol || m[1][2].abs() > tol {
                return Err(format!(
                    "the cell is not in GROMACS's form (v1 along x, v2 in the xy plane): a = {:?}, b = {:?}, c = {:?}",
                    m[0], m[1], m[2]
                ));
            }
        }
        Ok(())
    }

    /// A .gro file has no trailer.
    pub fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()> {
        let w = &mut self.out;
        let title = frame.comment.lines().next().unwrap_or("").trim();
        // A title's own t= and step= would be read before ours: ours replace them.
        let title: String = match title.find(" t=").or_else(|| title.find("step=")) {
            Some(k) if frame.time.is_some() || frame.step.is_some() => title[..k].trim().into(),
            _ => title.into(),
        };
        write!(w, "{}", if title.is_empty() { "texmap" } else { &title })?;
        if let Some(t) = frame.time {
            write!(w, " t= {t:.5}")?;
        }
        if let Some(s) = frame.step {
            write!(w, " step= {s}")?;
        }
        writeln!(w)?;
        let n = frame.n_atoms();
        writeln!(w, "{n:5}")?;
        for i in 0..n {
            let resid = frame
                .res_ids
                .get(i)
                .copied()
                .unwrap_or(1)
                .rem_euclid(100_000);
            let res = frame
                .res_names
                .get(i)
                .map(|l| l.as_str())
                .filter(|l| !l.is_empty())
                .unwrap_or("UNK");
            let name = match frame.names.get(i).map(|l| l.as_str()) {
                Some(l) if !l.is_empty() => l,
                _ => crate::atom_element(frame, i).symbol(),
            };
            let id = frame
                .ids
                .get(i)
                .copied()
                .unwrap_or(i as i64 + 1)
                .rem_euclid(100_000);
            let p = frame.positions[i].map(|x| x as f64 / NM);
            write!(
                w,
                "{resid:5}{res:<5}{name:>5}{id:5}{:8.3}{:8.3}{:8.3}",
                p[0], p[1], p[2]
            )?;
            if let Some(v) = frame.velocities.get(i) {
                let v = v.map(|x| x as f64 / NM);
                write!(w, "{:8.4}{:8.4}{:8.4}", v[0], v[1], v[2])?;
            }
            writeln!(w)?;
        }
        match &frame.cell {
            Some(c) => {
                let m = c.matrix().map(|r| r.map(|x| x / NM));
                write!(w, "{:10.5}{:10.5}{:10.5}", m[0][0], m[1][1], m[2][2])?;
                let off = [m[0][1], m[0][2], m[1][0], m[1][2], m[2][0], m[2][1]];
                if off.iter().any(|x| *x != 0.0) {
                    for x in off {
                        write!(w, "{x:10.5}")?;
                    }
                }
                writeln!(w)
            }
            None => writeln!(w, "{:10.5}{:10.5}{:10.5}", 0.0, 0.0, 0.0),
        }
    }
}

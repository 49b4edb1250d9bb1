//! AMBER's ASCII coordinate files: the trajectory (`mdcrd`) and the restart (`inpcrd`, `rst7`).
//!
//! **Trajectory** ([`crate::Format::AmberTrj`]): a title line, then per frame the 3N
//! coordinates (Å) as `10F8.3` — ten numbers of eight columns to a line, the frame's last line
//! holding the rest — and, for a periodic run, a box line: three lengths (`3F8.3`), or six,
//! lengths and angles, as cpptraj writes for a triclinic box. Fields are read by their columns,
//! not split at spaces: `-150.123` and `1234.567` fill all eight columns and run into their
//! neighbours. The file does not hold its atom count: it comes from the topology
//! ([`crate::ReadOptions::atoms`]). Whether frames carry a box line is decided once, after
//! frame 0's coordinates: a line of three or six fields there is a box (AMBER writes every
//! frame alike). With one or two atoms a frame is one line of three or six fields, which a box
//! line cannot be told from; such a file is read without boxes (MDAnalysis decides the same for
//! one atom). A box of three lengths has right angles unless [`crate::ReadOptions::box_angles`]
//! gives the run's angles (a truncated octahedron's 109.47°, which the prmtop's
//! `BOX_DIMENSIONS` holds and the trajectory does not). A replica-exchange trajectory's frames
//! start with a `REMD` (or `RXSGLD`) line: skipped. The file holds no time or step.
//!
//! **Restart** ([`crate::Format::AmberRestart`]): a title line; the atom count and optionally
//! the time in ps (`I5` or `I6`, then `E15.7`); the coordinates as `6F12.7` (six numbers of
//! twelve columns to a line); then optionally the velocities in the same layout and a box line
//! (`6F12.7`: lengths and angles; three lengths have right angles). What follows the
//! coordinates is told by its line count, L being the coordinates' lines: none, one (the box),
//! L (velocities) or L + 1 (velocities and box). Two to L − 1 lines, or one line that is not a
//! box but six numbers, are velocities cut short (the file ends inside the frame); more than
//! L + 1 lines are an error. With L = 1 (one or two atoms) a single line is read as the box.
//! One frame. AMBER's velocities are in Å per 1/20.455 ps: read ×20.455, in Å/ps.
//!
//! Names, elements, residues and bonds come from the topology (the prmtop).
//!
//! # References
//! - AMBER Reference Manual (2024), "Trajectory (mdcrd) file" and "Restart (inpcrd) file".
//! - cpptraj `Traj_AmberCoord` and `Traj_AmberRestart`: the six-number box line, REMD headers.

use crate::error::Error;
use crate::frame::{Frame, UnitCell};
use crate::parse::{fields, parse_f64, parse_usize, span, trim};
use crate::text::{Ctx, LineReader, Pos, TextFormat, need_line};
use std::io::Read;

/// AMBER's time unit is 1/20.455 ps: its velocities ×20.455 are Å/ps.
pub(crate) const VELOCITY_TO_A_PER_PS: f64 = 20.455;

/// Columns of a trajectory field (`F8.3`) and numbers per line.
const TRJ_WIDTH: usize = 8;
const TRJ_PER_LINE: usize = 10;
/// Columns of a restart field (`F12.7`) and numbers per line.
const RST_WIDTH: usize = 12;
const RST_PER_LINE: usize = 6;

/// How many fixed-width fields a line holds (its length without trailing blanks, rounded up).
pub(crate) fn field_count(line: &[u8], width: usize) -> usize {
    let end = line
        .iter()
        .rposition(|b| !matches!(b, b' ' | b'\t' | b'\r'))
        .map_or(0, |e| e + 1);
    end.div_ceil(width)
}

/// Reads the `count` fixed-width numbers of `line` into `out`; the line must hold exactly
/// `count` fields.
fn read_fields(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    width: usize,
    count: usize,
    expected: &'static str,
    out: &mut Vec<f64>,
) -> Result<(), Error> {
    if field_count(line, width) != count {
        return Err(ctx.parse(pos, line, line, expected));
    }
    for k in 0..count {
        let f = span(line, k * width, (k + 1) * width);
        let v = parse_f64(trim(f))
            .filter(|v| v.abs() <= crate::frame::MAX_COORDINATE)
            .ok_or_else(|| ctx.parse(pos, line, f, expected))?;
        out.push(v);
    }
    Ok(())
}

/// A cell from a box line's numbers: three lengths (with `angles`) or lengths and angles.
fn cell(ctx: &Ctx, pos: Pos, line: &[u8], v: &[f64], angles: [f64; 3]) -> Result<UnitCell, Error> {
    let angles = if v.len() == 6 {
        [v[3], v[4], v[5]]
    } else {
        angles
    };
    UnitCell::from_lengths_angles([v[0], v[1], v[2]], angles).map_err(|_| {
        ctx.parse(
            pos,
            line,
            line,
            "box lengths > 0 and angles of a cell with volume > 0",
        )
    })
}

/// Whether the trajectory's frames end in a box line, and with how many numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BoxLine {
    None,
    Numbers(usize),
}

/// The trajectory parser: the atom count from the caller, the box decision from frame 0.
pub(crate) struct AmberTrj {
    n_atoms: usize,
    angles: [f64; 3],
    box_line: Option<BoxLine>,
    /// The file's title, every frame's comment.
    title: String,
    values: Vec<f64>,
}

impl AmberTrj {
    pub fn new(n_atoms: usize, angles: Option<[f64; 3]>) -> AmberTrj {
        AmberTrj {
            n_atoms,
            angles: angles.unwrap_or([90.0; 3]),
            box_line: None,
            title: String::new(),
            values: Vec::new(),
        }
    }

    /// Coordinate lines per frame.
    fn lines_per_frame(&self) -> usize {
        (3 * self.n_atoms).div_ceil(TRJ_PER_LINE)
    }

    /// Numbers on coordinate line `k` of a frame.
    fn numbers_on(&self, k: usize) -> usize {
        (3 * self.n_atoms - k * TRJ_PER_LINE).min(TRJ_PER_LINE)
    }

    /// Reads the title before frame 0, and a frame's REMD header line; false when the data
    /// ends before the frame starts.
    fn start<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        if ctx.frame == 0 {
            let p = lines.pos();
            let Some((_, t)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Ok(false);
            };
            self.title = String::from_utf8_lossy(trim(t)).into_owned();
        }
        let p = lines.pos();
        match lines.next_line().map_err(|e| ctx.io(p, e))? {
            None => return Ok(false),
            Some((_, l)) if trim(l).is_empty() => {
                // Blank lines at the end of the file; anything after them is an error.
                loop {
                    let p = lines.pos();
                    match lines.next_line().map_err(|e| ctx.io(p, e))? {
                        None => return Ok(false),
                        Some((_, l)) if trim(l).is_empty() => continue,
                        Some((pos, l)) => {
                            return Err(ctx.parse(
                                pos,
                                l,
                                l,
                                "the end of the file after a blank line (a frame cannot start after one)",
                            ));
                        }
                    }
                }
            }
            Some((_, l)) if l.starts_with(b"REMD") || l.starts_with(b"RXSGLD") => {}
            Some((pos, _)) => lines.unread(pos),
        }
        Ok(true)
    }

    /// After frame 0's coordinates: whether a box line follows (the line is given back).
    fn decide_box<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<(), Error> {
        if self.box_line.is_some() {
            return Ok(());
        }
        let p = lines.pos();
        let decided = match lines.next_line().map_err(|e| ctx.io(p, e))? {
            None => BoxLine::None,
            Some((pos, l)) => {
                let n = field_count(l, TRJ_WIDTH);
                let first_line = (3 * self.n_atoms).min(TRJ_PER_LINE);
                lines.unread(pos);
                if (n == 3 || n == 6) && n != first_line {
                    BoxLine::Numbers(n)
                } else {
                    BoxLine::None
                }
            }
        };
        self.box_line = Some(decided);
        Ok(())
    }

    fn no_atoms(ctx: &Ctx) -> Error {
        Error::Unsupported {
            file: ctx.file.clone(),
            what: "an AMBER ASCII trajectory of 0 atoms (the topology gives the count)",
        }
    }
}

impl TextFormat for AmberTrj {
    const SKIPS_BLANK_LINES: bool = false;

    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        if self.n_atoms == 0 {
            return Err(AmberTrj::no_atoms(ctx));
        }
        if !self.start(lines, ctx)? {
            return Ok(false);
        }
        frame.comment.push_str(&self.title);
        let n = self.n_atoms;
        self.values.clear();
        self.values.reserve((3 * n).min(3 * ctx.reserve));
        for k in 0..self.lines_per_frame() {
            let (pos, line) = need_line(
                lines,
                ctx,
                &format!("{} more coordinate lines", self.lines_per_frame() - k),
            )?;
            let count = self.numbers_on(k);
            let expected = if count == TRJ_PER_LINE {
                "10 coordinates of 8 columns each (10F8.3)"
            } else {
                "the frame's last coordinates, 8 columns each (10F8.3)"
            };
            read_fields(ctx, pos, line, TRJ_WIDTH, count, expected, &mut self.values)?;
        }
        frame.positions.reserve(n.min(ctx.reserve));
        frame.positions.extend(
            self.values
                .chunks_exact(3)
                .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]),
        );
        self.decide_box(lines, ctx)?;
        if let Some(BoxLine::Numbers(k)) = self.box_line {
            let (pos, line) = need_line(lines, ctx, "the box line")?;
            let mut v = Vec::with_capacity(6);
            read_fields(
                ctx,
                pos,
                line,
                TRJ_WIDTH,
                k,
                "the box line, as frame 0's (3 lengths or 6 lengths and angles, 8 columns each)",
                &mut v,
            )?;
            frame.cell = Some(cell(ctx, pos, line, &v, self.angles)?);
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        if self.n_atoms == 0 {
            return Err(AmberTrj::no_atoms(ctx));
        }
        if !self.start(lines, ctx)? {
            return Ok(false);
        }
        let p = lines.pos();
        let missing = lines
            .skip_lines(self.lines_per_frame())
            .map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{missing} more coordinate lines")));
        }
        self.decide_box(lines, ctx)?;
        if let Some(BoxLine::Numbers(_)) = self.box_line {
            need_line(lines, ctx, "the box line")?;
        }
        Ok(true)
    }
}

/// The restart parser (one frame).
#[derive(Default)]
pub(crate) struct AmberRestart;

impl TextFormat for AmberRestart {
    const SKIPS_BLANK_LINES: bool = false;

    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        if ctx.frame > 0 {
            // One frame: what follows it was read as its velocities and box, or refused.
            return Ok(false);
        }
        let p = lines.pos();
        let Some((_, title)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(false);
        };
        frame
            .comment
            .push_str(&String::from_utf8_lossy(trim(title)));
        let n = {
            let (pos, line) = need_line(lines, ctx, "the atom count (and time) line")?;
            let mut it = fields(line);
            let count = it.next().unwrap_or(line);
            let n = parse_usize(count)
                .filter(|n| *n > 0)
                .ok_or_else(|| ctx.parse(pos, line, count, "the number of atoms (I5 or I6)"))?;
            if let Some(t) = it.next() {
                let time = parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, "the time in ps"))?;
                frame.time = Some(time);
            }
            n
        };
        let per_block = (3 * n).div_ceil(RST_PER_LINE);
        let numbers_on = |k: usize| (3 * n - k * RST_PER_LINE).min(RST_PER_LINE);
        let mut xyz = Vec::with_capacity((3 * n).min(3 * ctx.reserve));
        for k in 0..per_block {
            let (pos, line) = need_line(
                lines,
                ctx,
                &format!("{} more coordinate lines", per_block - k),
            )?;
            read_fields(
                ctx,
                pos,
                line,
                RST_WIDTH,
                numbers_on(k),
                "coordinates of 12 columns each (6F12.7)",
                &mut xyz,
            )?;
        }
        frame.positions.reserve(n.min(ctx.reserve));
        frame.positions.extend(
            xyz.chunks_exact(3)
                .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]),
        );
        // What follows: none, a box line, velocities, or velocities and a box line. At most
        // per_block + 1 lines are kept; one more is an error.
        let mut rest: Vec<(Pos, Vec<u8>)> = Vec::new();
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                break;
            };
            if trim(line).is_empty() {
                continue;
            }
            if rest.len() == per_block + 1 {
                return Err(ctx.parse(
                    pos,
                    line,
                    line,
                    "the end of the restart: after the coordinates come at most the velocities (as many lines) and a box line",
                ));
            }
            rest.push((pos, line.to_vec()));
        }
        // Velocities cut short: fewer lines than the coordinates' (one line that is not a box
        // is the first of them).
        let cut_velocities = |have: usize| {
            ctx.truncated(
                lines.pos(),
                format!("{} more velocity lines", per_block - have),
            )
        };
        let (vel_lines, box_line) = match rest.len() {
            0 => (&rest[..0], None),
            1 => (&rest[..0], Some(&rest[0])),
            r if r == per_block => (&rest[..], None),
            r if r == per_block + 1 => (&rest[..per_block], Some(&rest[per_block])),
            r => return Err(cut_velocities(r)),
        };
        if !vel_lines.is_empty() {
            let mut v = Vec::with_capacity(3 * n);
            for (k, (pos, line)) in vel_lines.iter().enumerate() {
                read_fields(
                    ctx,
                    *pos,
                    line,
                    RST_WIDTH,
                    numbers_on(k),
                    "velocities of 12 columns each (6F12.7)",
                    &mut v,
                )?;
            }
            frame.velocities.extend(v.chunks_exact(3).map(|c| {
                [
                    (c[0] * VELOCITY_TO_A_PER_PS) as f32,
                    (c[1] * VELOCITY_TO_A_PER_PS) as f32,
                    (c[2] * VELOCITY_TO_A_PER_PS) as f32,
                ]
            }));
        }
        if let Some((pos, line)) = box_line {
            let k = field_count(line, RST_WIDTH);
            let mut v = Vec::with_capacity(6);
            let k = if k == 3 || k == 6 { k } else { 6 };
            read_fields(
                ctx,
                *pos,
                line,
                RST_WIDTH,
                k,
                "the box line: 3 lengths, or lengths and angles (6F12.7)",
                &mut v,
            )?;
            match cell(ctx, *pos, line, &v, [90.0; 3]) {
                Ok(c) => frame.cell = Some(c),
                // Not a box: a first velocity line of a restart cut short.
                Err(_) if rest.len() == 1 && per_block > 1 && k == RST_PER_LINE => {
                    return Err(cut_velocities(1));
                }
                Err(e) => return Err(e),
            }
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let mut scratch = Frame::new();
        self.read(lines, ctx, &mut scratch)
    }
}

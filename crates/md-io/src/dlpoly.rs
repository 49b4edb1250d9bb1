//! DL_POLY configurations (`CONFIG`, `REVCON`, `CFGMIN`: one frame) and trajectories
//! (`HISTORY`, DL_POLY 4 and Classic), as DL_POLY names its files (any suffix: `HISTORY_run2`).
//!
//! Both start with a title line and a line `levcfg imcon [natoms [frames records]]`: `levcfg`
//! says what each atom record holds after its name line (0 positions, 1 also velocities, 2 also
//! forces), `imcon` the boundary (0 none; 1, 2, 3 cubic, orthorhombic, parallelepiped; 6 a slab,
//! periodic in x and y). A HISTORY frame starts with a line `timestep nstep natoms levcfg imcon
//! tstep [time]`; a CONFIG has none. Then, when `imcon > 0`, three lines with the cell vectors
//! (rows, Å), and per atom a line `name [index [mass charge rsd]]` followed by one line of
//! x y z (Å), one of velocities (Å/ps, DL_POLY's own unit) when `levcfg ≥ 1` and one of forces
//! when `levcfg = 2` (the properties `fx fy fz`, DL_POLY's 10 J/mol/Å). A HISTORY atom line's
//! mass and charge become the `mass` and `charge` properties. The time is `time` when the
//! timestep line has it, else `nstep · tstep` (ps); the step is `nstep`.
//!
//! Atoms are put in index order when the indices are not already (DL_POLY 4 run in parallel
//! may write them in any order), as MDAnalysis does; names give the elements
//! ([`crate::elements::guess_element`]: `Na+`, `OW`, `O_spc` are sodium and oxygen).
//!
//! # References
//! - DL_POLY 4 User Manual, "The CONFIG File" and "The HISTORY File"; DL_POLY Classic manual.
//! - ASE `io/dlp4.py` and MDAnalysis `coordinates/DLPoly.py`, the readers the tests compare with.

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos, need_line};
use std::io::Read;

/// The DL_POLY parser: the file header (read with frame 0) and scratch for reordering.
#[derive(Default)]
pub(crate) struct DlPoly {
    /// `levcfg`, `imcon` and the title, from the header.
    header: Option<(usize, usize, String)>,
    perm: Vec<usize>,
}

/// The first `N` numbers of `line` (at least `min` of them) and how many there were.
fn numbers<const N: usize>(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    min: usize,
    expected: &'static str,
) -> Result<([f64; N], usize), Error> {
    let mut v = [0f64; N];
    let mut k = 0;
    for f in fields(line).take(N) {
        v[k] = parse_f64(f).ok_or_else(|| ctx.parse(pos, line, f, expected))?;
        k += 1;
    }
    if k < min {
        return Err(ctx.parse(pos, line, line, expected));
    }
    Ok((v, k))
}

impl DlPoly {
    /// Frame 0: the title and the `levcfg imcon` line.
    fn read_header<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
    ) -> Result<bool, Error> {
        let p = lines.pos();
        let Some((_, title)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(false);
        };
        let title = String::from_utf8_lossy(trim(title)).into_owned();
        let (pos, line) = need_line(lines, ctx, "the levcfg and imcon line")?;
        let mut it = fields(line);
        let mut int = |what| {
            let f = it.next().unwrap_or(&line[line.len()..]);
            parse_usize(f).ok_or_else(|| ctx.parse(pos, line, f, what))
        };
        let levcfg = int("levcfg (0, 1 or 2)")?;
        let imcon = int("imcon (0 to 7)")?;
        if levcfg > 2 {
            return Err(ctx.parse(pos, line, line, "levcfg 0, 1 or 2"));
        }
        self.header = Some((levcfg, imcon, title));
        Ok(true)
    }

    /// One frame (or, with `frame` None, its structure only).
    fn walk_frame<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        if ctx.frame == 0 && !self.read_header(lines, ctx)? {
            return Ok(false);
        }
        let Some((levcfg, imcon, title)) = self.header.clone() else {
            return Ok(false);
        };
        // Blank lines after the last frame end the file. A HISTORY frame's timestep line gives
        // the count; a CONFIG's atoms run to the end.
        let (pos, count) = loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Ok(false);
            };
            if trim(line).is_empty() {
                continue;
            }
            if !line.starts_with(b"timestep") {
                if ctx.frame > 0 {
                    return Err(ctx.parse(
                        pos,
                        line,
                        line,
                        "a 'timestep' line starting the next frame (a CONFIG holds one frame)",
                    ));
                }
                lines.unread(pos);
                break (pos, None);
            }
            let f: Vec<&[u8]> = fields(line).collect();
            let int = |k: usize, what| {
                let x = f.get(k).copied().unwrap_or(&line[line.len()..]);
                parse_usize(x).ok_or_else(|| ctx.parse(pos, line, x, what))
            };
            let nstep = int(1, "the step number after 'timestep'")?;
            let natoms = int(2, "the atom count after the step")?;
            let real = |k: usize| f.get(k).and_then(|x| parse_f64(x));
            if let Some(fr) = frame.as_deref_mut() {
                fr.step = Some(nstep as i64);
                fr.time = real(6).or_else(|| real(5).map(|dt| dt * nstep as f64));
            }
            break (pos, Some(natoms));
        };
        if let Some(fr) = frame.as_deref_mut() {
            fr.comment = title;
        }
        // The cell.
        if imcon > 0 {
            let mut m = [[0f64; 3]; 3];
            for row in &mut m {
                let (pos, line) = need_line(lines, ctx, "a cell vector line")?;
                let (v, _) = numbers::<3>(ctx, pos, line, 3, "3 cell vector components (Å)")?;
                *row = v;
            }
            if let Some(fr) = frame.as_deref_mut() {
                fr.cell = Some(UnitCell::from_matrix(m).map_err(|_| Error::Parse {
                    at: ctx.at(pos),
                    expected: "cell vectors with volume > 0",
                    found: format!("{m:?}"),
                })?);
            }
        }
        // The atoms: a name line and 1 + levcfg vector lines each.
        let mut i = 0usize;
        loop {
            if count.is_some_and(|n| i == n) {
                break;
            }
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if let Some(n) = count {
                    return Err(ctx.truncated(p, format!("{} more atom records", n - i)));
                }
                break;
            };
            if count.is_none() && trim(line).is_empty() {
                break;
            }
            let f: Vec<&[u8]> = fields(line).collect();
            let name_f = f.first().copied().unwrap_or(line);
            if parse_f64(name_f).is_some() {
                return Err(ctx.parse(pos, line, name_f, "an atom record's name line"));
            }
            let name = Label::from_utf8(name_f)
                .ok_or_else(|| ctx.parse(pos, line, name_f, "an atom name"))?;
            let id = match f.get(1) {
                Some(x) => parse_i64(x).ok_or_else(|| ctx.parse(pos, line, x, "an atom index"))?,
                None => i as i64 + 1,
            };
            let mass_charge = [f.get(2), f.get(3)].map(|x| x.and_then(|x| parse_f64(x)));
            let mut vectors = [[0f64; 3]; 3];
            for (k, v) in vectors.iter_mut().enumerate().take(1 + levcfg) {
                let what = [
                    "3 coordinates (Å)",
                    "3 velocities (Å/ps), finite in single precision",
                    "3 forces, finite in single precision",
                ][k];
                let (pos, line) = need_line(lines, ctx, what)?;
                *v = numbers::<3>(ctx, pos, line, 3, what)?.0;
                if v.iter().any(|x| !(*x as f32).is_finite()) {
                    return Err(ctx.parse(pos, line, line, what));
                }
            }
            if let Some(fr) = frame.as_deref_mut() {
                let f32s = |v: [f64; 3]| v.map(|x| x as f32);
                fr.positions.push(f32s(vectors[0]));
                if levcfg >= 1 {
                    fr.velocities.push(f32s(vectors[1]));
                }
                if levcfg == 2 {
                    for (c, key) in ["fx", "fy", "fz"].into_iter().enumerate() {
                        fr.property_mut(key).push(vectors[2][c] as f32);
                    }
                }
                if count.is_some() {
                    let [m, q] = mass_charge;
                    fr.property_mut("mass").push(m.unwrap_or(f64::NAN) as f32);
                    fr.property_mut("charge").push(q.unwrap_or(f64::NAN) as f32);
                }
                fr.elements.push(guess_element(&name, None, None));
                fr.names.push(name);
                fr.ids.push(id);
            }
            i += 1;
        }
        if let Some(fr) = frame {
            if fr
                .properties
                .iter()
                .any(|p| p.values.iter().any(|v| v.is_nan()))
            {
                fr.properties
                    .retain(|p| p.name != "mass" && p.name != "charge");
            }
            self.order_by_id(fr);
        }
        Ok(i > 0 || count.is_some())
    }

    /// Puts the atoms of `frame` in index order, when they are not.
    fn order_by_id(&mut self, frame: &mut Frame) {
        if frame.ids.is_sorted() {
            return;
        }
        self.perm.clear();
        self.perm.extend(0..frame.ids.len());
        self.perm.sort_by_key(|&k| frame.ids[k]);
        let perm = &self.perm;
        fn apply<T: Clone>(v: &mut Vec<T>, perm: &[usize]) {
            if v.len() == perm.len() {
                *v = perm.iter().map(|&k| v[k].clone()).collect();
            }
        }
        apply(&mut frame.positions, perm);
        apply(&mut frame.velocities, perm);
        apply(&mut frame.names, perm);
        apply(&mut frame.elements, perm);
        apply(&mut frame.ids, perm);
        for p in &mut frame.properties {
            apply(&mut p.values, perm);
        }
    }
}

impl FrameWalk for DlPoly {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        self.walk_frame(lines, ctx, frame)
    }

    /// The title may be blank.
    const SKIPS_BLANK_LINES: bool = false;
}

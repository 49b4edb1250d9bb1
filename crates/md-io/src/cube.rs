//! Gaussian cube files: a molecule and values on a grid (see [`crate::volume`] for the layout
//! and units). One parser serves both readers: [`crate::volume::read_volumes`] keeps the values,
//! the trajectory reader ([`Cube`], `Format::Cube`) keeps the atoms and walks the values, so
//! that a damaged or cut data section is an error for frame 0 there too.
//!
//! Cost of the trajectory reader: reading the frame parses every value (a check, nothing
//! kept); counting frames counts the values' fields without parsing them. Either is one pass
//! over the file, a small fraction of what drawing an isosurface from it costs.

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label};
use crate::parse::{fields, parse_f64, parse_i64, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos, need_line};
use crate::volume::{Budget, MAX_POINTS, Values, Volume, walk_values};
use std::io::Read;

/// Å per Bohr (CODATA 2018).
pub(crate) const BOHR: f64 = 0.529177210903;

/// What the header says about the grid.
pub(crate) struct Header {
    /// Grid origin and steps, Å.
    pub origin: [f64; 3],
    pub steps: [[f64; 3]; 3],
    pub dims: [usize; 3],
    /// Values per grid point (the orbitals of DSET_IDS, else NVAL).
    pub per_point: usize,
    /// A name per value of a point.
    pub names: Vec<String>,
}

/// The trajectory reader's parser: one frame, the molecule.
#[derive(Default)]
pub(crate) struct Cube;

impl FrameWalk for Cube {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        // The frame starts at the first line that is not blank: a cube whose comment lines are
        // blank starts on line 2 or 3, and its blank comments are already read.
        let start = lines.pos();
        if ctx.frame > 0 {
            // The single frame reads the file to its end, so nothing can start here.
            return Err(ctx.parse(start, b"", b"", "the end of the file after the grid values"));
        }
        let comments = 2usize.saturating_sub((start.line - 1) as usize);
        let mut scratch = Frame::new();
        let parse = frame.is_some();
        let frame = frame.unwrap_or(&mut scratch);
        let h = header(lines, ctx, comments, frame, &Budget::unknown())?;
        let mode = if parse { Values::Check } else { Values::Count };
        data(lines, ctx, &h, mode)?;
        Ok(true)
    }
}

/// Reads a cube file: the atoms into `frame` and every data set.
pub(crate) fn read<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    frame: &mut Frame,
    budget: &Budget,
) -> Result<Vec<Volume>, Error> {
    let h = header(lines, ctx, 2, frame, budget)?;
    let n = h.dims.iter().product::<usize>() * h.per_point;
    let mut raw = Vec::with_capacity(n.min(budget.reserve_values()));
    data(lines, ctx, &h, Values::Keep(&mut raw))?;
    // The file's order is x outermost, z fastest, the values of one point together.
    let [nx, ny, nz] = h.dims;
    let m = h.per_point;
    let mut out = Vec::with_capacity(m);
    for (s, name) in h.names.iter().enumerate() {
        let mut v = Vec::with_capacity(nx * ny * nz);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    v.push(raw[((i * ny + j) * nz + k) * m + s]);
                }
            }
        }
        let vol = Volume::new(h.origin, h.steps, h.dims, v, false, name)
            .map_err(|e| Error::InvalidValue { what: e.0 })?;
        out.push(vol);
    }
    Ok(out)
}

/// Reads the values (`mode`) and then the rest of the file, which must be blank.
fn data<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    h: &Header,
    mut mode: Values,
) -> Result<(), Error> {
    let n = h.dims.iter().product::<usize>() * h.per_point;
    let what = format!(
        "the grid ({}x{}x{} points, {} per point)",
        h.dims[0], h.dims[1], h.dims[2], h.per_point
    );
    walk_values(lines, ctx, n, 1.0, &mut mode, &what)?;
    loop {
        let p = lines.pos();
        match lines.next_line().map_err(|e| ctx.io(p, e))? {
            None => return Ok(()),
            Some((_, l)) if trim(l).is_empty() => {}
            Some((pos, l)) => {
                return Err(ctx.parse(
                    pos,
                    l,
                    trim(l),
                    "the end of the file after the grid values",
                ));
            }
        }
    }
}

/// An integer and three numbers, exactly: an axis line, or line 3 (count and origin, with
/// `nval` allowing an optional fifth field, returned).
fn count_and_vector(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    expected: &'static str,
    nval: bool,
) -> Result<(i64, [f64; 3], Option<i64>), Error> {
    let f: Vec<&[u8]> = fields(line).collect();
    let most = if nval { 5 } else { 4 };
    if f.len() < 4 || f.len() > most {
        return Err(ctx.parse(pos, line, trim(line), expected));
    }
    let n = parse_i64(f[0]).ok_or_else(|| ctx.parse(pos, line, f[0], expected))?;
    let mut v = [0.0; 3];
    for (x, t) in v.iter_mut().zip(&f[1..4]) {
        *x = parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    }
    let extra = match f.get(4) {
        Some(t) => Some(parse_i64(t).ok_or_else(|| ctx.parse(pos, line, t, expected))?),
        None => None,
    };
    Ok((n, v, extra))
}

/// Parses the header: `comments` comment lines (2, or fewer when blank ones were skipped), the
/// counts, origin and axes, the atoms into `frame` (Å), and the DSET_IDS record.
pub(crate) fn header<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    comments: usize,
    frame: &mut Frame,
    budget: &Budget,
) -> Result<Header, Error> {
    let mut titles = Vec::new();
    for k in 0..comments {
        let (_, l) = need_line(lines, ctx, &format!("{} more comment lines", comments - k))?;
        titles.push(String::from_utf8_lossy(trim(l)).into_owned());
    }
    frame.comment = titles.first().cloned().unwrap_or_default();
    const LINE3: &str = "the atom count, the grid origin (3 numbers) and an optional NVAL";
    let (pos, line) = need_line(lines, ctx, LINE3)?;
    let (natoms, origin, nval) = count_and_vector(ctx, pos, line, LINE3, true)?;
    let (line3_pos, line3) = (pos, line.to_vec());
    let at_line3 = |expected| ctx.parse(line3_pos, &line3, trim(&line3), expected);
    let n_atoms = natoms.unsigned_abs() as usize;
    if natoms.unsigned_abs() > budget.max_atoms() as u64 {
        return Err(at_line3(
            "an atom count the file can hold (one line of ≥ 8 bytes each)",
        ));
    }
    let nval = match nval {
        None => 1,
        Some(v) if (1..=MAX_POINTS as i64).contains(&v) => v as usize,
        Some(_) => return Err(at_line3("NVAL, the values per grid point, ≥ 1")),
    };
    // The axes: a count and a step each; a positive count means Bohr, a negative one Å.
    const AXIS: &str = "an axis line: the point count (> 0: Bohr, < 0: Å) and the step (3 numbers)";
    let mut dims = [0usize; 3];
    let mut steps = [[0.0; 3]; 3];
    let mut bohr = true;
    let mut axis_at = Vec::new();
    for a in 0..3 {
        let (pos, line) = need_line(lines, ctx, &format!("{} more axis lines", 3 - a))?;
        let (n, step, _) = count_and_vector(ctx, pos, line, AXIS, false)?;
        if n == 0 || (a > 0 && (n > 0) != bohr) {
            let what = "a point count, > 0 (Bohr) or < 0 (Å) as on the first axis line";
            return Err(ctx.parse(pos, line, trim(line), what));
        }
        bohr = n > 0;
        dims[a] = n.unsigned_abs().min(u64::MAX >> 1) as usize;
        if dims[a] < 2 {
            return Err(ctx.parse(pos, line, trim(line), "at least 2 points along each axis"));
        }
        steps[a] = step;
        axis_at.push((pos, line.to_vec()));
    }
    let unit = if bohr { BOHR } else { 1.0 };
    let origin = origin.map(|x| x * unit);
    let steps = steps.map(|s| s.map(|x| x * unit));
    let (last_pos, last) = &axis_at[2];
    let points = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if points.is_none_or(|p| p > MAX_POINTS) {
        return Err(ctx.parse(*last_pos, last, trim(last), "a grid of at most 2^30 points"));
    }
    let det = crate::volume::det3(steps);
    if !(det.is_finite() && det != 0.0)
        || steps.iter().flatten().any(|x| !x.is_finite())
        || origin
            .iter()
            .any(|x| x.abs() > crate::frame::MAX_COORDINATE)
    {
        return Err(ctx.parse(
            *last_pos,
            last,
            trim(last),
            "axis steps spanning a volume, and an origin within 1e7 Å",
        ));
    }
    // The atoms: Z, charge, x y z.
    const ATOM: &str = "an atom line: atomic number, charge, x y z";
    let n = n_atoms.min(ctx.reserve);
    frame.positions.reserve(n);
    frame.elements.reserve(n);
    frame.names.reserve(n);
    for i in 0..n_atoms {
        let (pos, line) = need_line(lines, ctx, &format!("{} more atom lines", n_atoms - i))?;
        let f: Vec<&[u8]> = fields(line).collect();
        if f.len() != 5 {
            return Err(ctx.parse(pos, line, trim(line), ATOM));
        }
        let z = parse_i64(f[0])
            .or_else(|| {
                parse_f64(f[0])
                    .filter(|z| z.fract() == 0.0)
                    .map(|z| z as i64)
            })
            .filter(|z| *z >= 0)
            .ok_or_else(|| ctx.parse(pos, line, f[0], "an atomic number ≥ 0"))?;
        let mut x = [0.0f64; 4];
        for (v, t) in x.iter_mut().zip(&f[1..]) {
            *v = parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, ATOM))?;
        }
        let p = [x[1], x[2], x[3]].map(|c| c * unit);
        if p.iter().any(|c| c.abs() > crate::frame::MAX_COORDINATE) {
            return Err(ctx.parse(pos, line, trim(line), crate::cursor::IN_BOUNDS));
        }
        let e = u8::try_from(z)
            .ok()
            .and_then(Element::from_z)
            .unwrap_or(Element::UNKNOWN);
        frame.positions.push(p.map(|c| c as f32));
        frame.elements.push(e);
        frame.names.push(Label::new(e.symbol()).unwrap_or_default());
    }
    // DSET_IDS: `m id1 id2 …`, possibly over several lines; then m values per point.
    let ids = if natoms < 0 {
        let ids = dset_ids(lines, ctx)?;
        if nval != 1 && nval != ids.len() {
            return Err(at_line3("NVAL absent, 1 or the number of data set ids"));
        }
        Some(ids)
    } else {
        None
    };
    let per_point = ids.as_ref().map_or(nval, Vec::len);
    let total = points.unwrap_or(usize::MAX).checked_mul(per_point);
    if total.is_none_or(|t| t > MAX_POINTS || t > budget.max_values()) {
        return Err(ctx.parse(
            *last_pos,
            last,
            trim(last),
            "a grid the file can hold: at most 2^30 values, each of ≥ 2 bytes",
        ));
    }
    let names = match ids {
        Some(ids) => ids.iter().map(|id| format!("orbital {id}")).collect(),
        None if nval > 1 => (1..=nval).map(|k| format!("value {k}")).collect(),
        None => {
            let name = titles.iter().find(|t| !t.is_empty());
            vec![name.cloned().unwrap_or_else(|| "values".to_string())]
        }
    };
    Ok(Header {
        origin,
        steps,
        dims,
        per_point,
        names,
    })
}

/// The DSET_IDS record: `m id1 … idm`, over as many lines as it takes.
fn dset_ids<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<Vec<i64>, Error> {
    const IDS: &str = "the data set ids: their count m > 0, then m integers";
    let mut m = None;
    let mut ids: Vec<i64> = Vec::new();
    while m.is_none_or(|m| ids.len() < m) {
        let left = m.map_or("the data set ids (DSET_IDS)".to_string(), |m| {
            format!("{} more data set ids", m - ids.len())
        });
        let (pos, line) = need_line(lines, ctx, &left)?;
        for t in fields(line) {
            let v = parse_i64(t).ok_or_else(|| ctx.parse(pos, line, t, IDS))?;
            match m {
                None if v > 0 && v as u64 <= MAX_POINTS as u64 => {
                    m = Some(v as usize);
                    ids.reserve((v as usize).min(1024));
                }
                None => return Err(ctx.parse(pos, line, t, IDS)),
                Some(m) if ids.len() == m => {
                    return Err(ctx.parse(pos, line, t, "no more ids than their count"));
                }
                Some(_) => ids.push(v),
            }
        }
    }
    Ok(ids)
}

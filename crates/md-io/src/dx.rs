//! OpenDX scalar fields on regular grids (`.dx`): what APBS writes its electrostatic
//! potentials in, VMD's `volmap` and MDAnalysis's `DensityAnalysis` (through GridDataFormats)
//! their densities, and PyMOL, Chimera and VMD read. See [`crate::volume`] for the layout read
//! and [`write`] for the one written.

use crate::error::Error;
use crate::parse::{fields, parse_f64, parse_i64, trim};
use crate::text::{Ctx, LineReader, Pos};
use crate::volume::{Budget, MAX_POINTS, Values, Volume, walk_values};
use std::io::{Read, Write};

/// The header's grid, filled as its objects are met.
#[derive(Default)]
struct Grid {
    dims: Option<[usize; 3]>,
    origin: Option<[f64; 3]>,
    steps: Vec<[f64; 3]>,
    connections: Option<(Pos, Vec<u8>, [usize; 3])>,
}

/// Reads a DX file's one scalar field (the atoms' frame stays empty: DX holds none).
pub(crate) fn read<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    budget: &Budget,
) -> Result<Vec<Volume>, Error> {
    let mut g = Grid::default();
    // The header, up to the array's `data follows`.
    let items = loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(
                p,
                "the header's `object … class array … data follows` line".into(),
            ));
        };
        let line = trim(line);
        if line.is_empty() || line.starts_with(b"#") {
            continue;
        }
        let f: Vec<&[u8]> = fields(line).collect();
        match f[0] {
            b"object" => {
                if let Some(items) = object(ctx, pos, line, &f, &mut g, budget)? {
                    break items;
                }
            }
            b"origin" => g.origin = Some(vector(ctx, pos, line, &f, "origin x y z (Å)")?),
            b"delta" => {
                if g.steps.len() == 3 {
                    return Err(ctx.parse(pos, line, f[0], "three delta lines, no more"));
                }
                g.steps
                    .push(vector(ctx, pos, line, &f, "delta x y z: a grid step (Å)")?);
                if g.steps.len() == 3 {
                    let det = crate::volume::det3([g.steps[0], g.steps[1], g.steps[2]]);
                    if det == 0.0 || !det.is_finite() {
                        return Err(ctx.parse(
                            pos,
                            line,
                            line,
                            "three delta lines that span a volume (independent steps)",
                        ));
                    }
                }
            }
            _ => {
                return Err(ctx.parse(
                    pos,
                    line,
                    f[0],
                    "a DX header line: `object`, `origin`, `delta` or a # comment",
                ));
            }
        }
    };
    let missing = |what: &str| {
        ctx.truncated(
            lines.pos(),
            format!("{what} before the data (a `gridpositions` object)"),
        )
    };
    let dims = g.dims.ok_or_else(|| missing("the grid's counts"))?;
    let origin = g.origin.ok_or_else(|| missing("the grid's origin"))?;
    if g.steps.len() != 3 {
        return Err(missing("three delta lines"));
    }
    if let Some((pos, line, counts)) = &g.connections
        && *counts != dims
    {
        return Err(ctx.parse(
            *pos,
            line,
            trim(line),
            "gridconnections counts equal to the gridpositions counts",
        ));
    }
    let n = items;
    let mut raw = Vec::with_capacity(n.min(budget.reserve_values()));
    let what = format!("the grid ({}x{}x{} points)", dims[0], dims[1], dims[2]);
    walk_values(lines, ctx, n, 1.0, &mut Values::Keep(&mut raw), &what)?;
    let name = trailer(lines, ctx)?.unwrap_or_else(|| "values".to_string());
    // The file's order is x outermost, z fastest (C order); the volume's is x fastest.
    let [nx, ny, nz] = dims;
    let mut data = Vec::with_capacity(n);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                data.push(raw[(i * ny + j) * nz + k]);
            }
        }
    }
    let steps = [g.steps[0], g.steps[1], g.steps[2]];
    let v = Volume::new(origin, steps, dims, data, false, &name)
        .map_err(|e| Error::InvalidValue { what: e.0 })?;
    Ok(vec![v])
}

/// An `object` line: a grid's positions or connections (`None`: read on), or the array
/// whose values follow (`Some(items)`).
fn object(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    f: &[&[u8]],
    g: &mut Grid,
    budget: &Budget,
) -> Result<Option<usize>, Error> {
    let class = f.iter().position(|t| *t == b"class").map(|i| i + 1);
    let Some(&kind) = class.and_then(|i| f.get(i)) else {
        return Err(ctx.parse(pos, line, trim(line), "object <id> class <kind> …"));
    };
    let after = &f[class.unwrap_or(0) + 1..];
    match kind {
        b"gridpositions" | b"gridconnections" => {
            const COUNTS: &str = "counts nx ny nz: three point counts, each ≥ 2 (a 3-D grid)";
            if after.len() != 4 || after[0] != b"counts" {
                return Err(ctx.parse(pos, line, trim(line), COUNTS));
            }
            let mut dims = [0usize; 3];
            for (d, t) in dims.iter_mut().zip(&after[1..]) {
                *d = parse_i64(t)
                    .filter(|&n| (2..=MAX_POINTS as i64).contains(&n))
                    .ok_or_else(|| ctx.parse(pos, line, t, COUNTS))? as usize;
            }
            let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
            if n.is_none_or(|n| n > budget.max_values()) {
                return Err(ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "a grid the file can hold (2 bytes a value at least, at most 2^30 points)",
                ));
            }
            if kind == b"gridpositions" {
                g.dims = Some(dims);
            } else {
                g.connections = Some((pos, line.to_vec(), dims));
            }
            Ok(None)
        }
        b"array" => {
            const ARRAY: &str =
                "an array `type <t> rank 0 items <n> data follows`: scalar values in the file";
            let key = |k: &[u8]| after.iter().position(|t| *t == k).map(|i| i + 1);
            if let Some(i) = key(b"rank") {
                let r = after.get(i).copied().unwrap_or(b"");
                if r != b"0" {
                    return Err(ctx.parse(
                        pos,
                        line,
                        r,
                        "rank 0: one scalar per point (vector fields are not read)",
                    ));
                }
            }
            for t in after {
                let low = t.to_ascii_lowercase();
                if low == b"binary" || low == b"ieee" || low == b"msb" || low == b"lsb" {
                    return Err(ctx.parse(
                        pos,
                        line,
                        t,
                        "text values (binary DX arrays are not read: write the file as text)",
                    ));
                }
            }
            let Some(i) = key(b"data") else {
                return Err(ctx.parse(pos, line, trim(line), ARRAY));
            };
            if after.get(i).copied() != Some(b"follows") {
                let t = after.get(i).copied().unwrap_or(b"");
                return Err(ctx.parse(
                    pos,
                    line,
                    t,
                    "`data follows` (values in a separate file are not read)",
                ));
            }
            let items = key(b"items")
                .and_then(|i| after.get(i))
                .and_then(|t| parse_i64(t))
                .filter(|&n| n >= 0)
                .ok_or_else(|| ctx.parse(pos, line, trim(line), ARRAY))?;
            let Some(dims) = g.dims else {
                return Err(ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "a `gridpositions` object (the grid) before the array",
                ));
            };
            if items as usize != dims[0] * dims[1] * dims[2] {
                return Err(ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "as many items as the gridpositions counts' points",
                ));
            }
            Ok(Some(items as usize))
        }
        _ => Err(ctx.parse(
            pos,
            line,
            kind,
            "class gridpositions, gridconnections or array before the data",
        )),
    }
}

/// Three numbers after a keyword.
fn vector(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    f: &[&[u8]],
    expected: &'static str,
) -> Result<[f64; 3], Error> {
    if f.len() != 4 {
        return Err(ctx.parse(pos, line, trim(line), expected));
    }
    let mut v = [0.0; 3];
    for (x, t) in v.iter_mut().zip(&f[1..]) {
        *x = parse_f64(t)
            .filter(|v| v.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    }
    Ok(v)
}

/// What follows the values: `attribute`, `object … class field` (whose quoted name is the
/// field's, returned), `component` lines, comments and blank lines, nothing else.
fn trailer<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<Option<String>, Error> {
    let mut name = None;
    loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(name);
        };
        let line = trim(line);
        let first = fields(line).next().unwrap_or(b"");
        match first {
            b"" => {}
            _ if line.starts_with(b"#") => {}
            b"attribute" | b"component" => {}
            b"object" if fields(line).any(|t| t == b"field") => {
                let text = String::from_utf8_lossy(line);
                let mut quoted = text.split('"');
                if let (Some(_), Some(n)) = (quoted.next(), quoted.next())
                    && !n.trim().is_empty()
                {
                    name = Some(n.trim().to_string());
                }
            }
            _ => {
                return Err(ctx.parse(
                    pos,
                    line,
                    first,
                    "after the data: `attribute`, `object … class field`, `component` or a # \
                     comment (a count of items larger than the grid's?)",
                ));
            }
        }
    }
}

/// Writes `v` as an OpenDX file in the layout GridDataFormats and APBS write and VMD, PyMOL,
/// Chimera and APBS read: comments (`comments`, one per line, cut to 80 columns as VMD
/// needs), the grid's counts, origin (Å, 7 decimals) and three deltas (its steps), its
/// connections, then `object 3 class array type "double" rank 0 items N data follows` and the
/// values three per line (as VMD's reader needs) with x outermost and z fastest, in the
/// shortest decimal form that reads back to the same `f32` (with an exponent below 10⁻⁴ and
/// from 10⁷); then the field object named
/// `v.name`. A periodic volume is written as its points (the wrap is not part of DX).
pub fn write(v: &Volume, comments: &[&str], out: &mut impl Write) -> std::io::Result<()> {
    for c in comments {
        for l in c.lines() {
            let l: String = format!("# {l}").chars().take(80).collect();
            writeln!(out, "{l}")?;
        }
    }
    let [nx, ny, nz] = v.dims;
    writeln!(out, "object 1 class gridpositions counts {nx} {ny} {nz}")?;
    let [ox, oy, oz] = v.origin;
    writeln!(out, "origin {ox:.7} {oy:.7} {oz:.7}")?;
    for s in v.steps {
        writeln!(out, "delta {} {} {}", s[0], s[1], s[2])?;
    }
    writeln!(out, "object 2 class gridconnections counts {nx} {ny} {nz}")?;
    writeln!(
        out,
        "object 3 class array type \"double\" rank 0 items {} data follows",
        v.data.len()
    )?;
    let mut line = String::new();
    let mut on_line = 0;
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                if on_line > 0 {
                    line.push(' ');
                }
                let x = v.at(i, j, k);
                if x == 0.0 || (1e-4..1e7).contains(&x.abs()) {
                    line.push_str(&format!("{x}"));
                } else {
                    line.push_str(&format!("{x:e}"));
                }
                on_line += 1;
                if on_line == 3 {
                    line.push('\n');
                    out.write_all(line.as_bytes())?;
                    line.clear();
                    on_line = 0;
                }
            }
        }
    }
    if on_line > 0 {
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    writeln!(out, "attribute \"dep\" string \"positions\"")?;
    let name = v.name.replace('"', "'");
    writeln!(out, "object \"{name}\" class field")?;
    writeln!(out, "component \"positions\" value 1")?;
    writeln!(out, "component \"connections\" value 2")?;
    writeln!(out, "component \"data\" value 3")?;
    Ok(())
}

//! XCrySDen structure files, XSF and animated AXSF (`.xsf`, `.axsf`: written by Quantum
//! ESPRESSO's pp.x `output_format=5` and pwo2xsf, ASE, pymatgen, XCrySDen): each
//! structure a frame (`Format::Xsf`), and the 3-D data grids for
//! [`crate::volume::read_volumes`]. One walk serves both, as for cube files: the trajectory
//! reader checks (reading) or counts (scanning) a grid's values, so that a damaged or cut grid
//! is an error for the frame it follows.
//!
//! # The layout, as read here
//! The file is a sequence of records, each starting with a keyword line. Keywords are matched
//! in any letter case; blank lines and lines starting with `#` (comments) may stand anywhere
//! between lines of records (XCrySDen allows comments only between sections; ASE skips them
//! anywhere), but not among a grid's values. Lengths are Å.
//!
//! 1. `ANIMSTEPS n` (optional, first): an animation of n structures, each a frame; a file that
//!    ends before the n-th is cut ([`Error::Truncated`]), one with more is damaged.
//! 2. The dimensionality (optional, once, before the first structure): `CRYSTAL` (periodic in
//!    3-D), `SLAB` (2-D: along the first two cell vectors), `POLYMER` (1-D: along the first),
//!    `MOLECULE` (0-D, written in the periodic form or, as pymatgen writes it, with `ATOMS`).
//!    None at all is a molecule in `ATOMS` blocks. The cell is periodic along the vectors the
//!    keyword names ([`crate::UnitCell::periodic`]). The keyword is kept as every frame's
//!    [`Frame::comment`] (`CRYSTAL`, `SLAB`, `POLYMER`, `MOLECULE`; empty without one).
//! 3. A structure (a frame):
//!    - periodic: `PRIMVEC [k]` and three lines of the lattice vectors a, b, c (rows, Å; the
//!      frame's cell, [`crate::UnitCell::from_matrix`]: a crystal's must be right-handed with a
//!      volume > 0; a slab's, polymer's or molecule's that spans no volume, as a vacuum
//!      direction written as zeros would, gives no cell), then `PRIMCOORD [k]`, a line
//!      `natoms 1` and natoms atom lines. A `PRIMVEC` without an index applies to every
//!      structure after it (a fixed-cell animation); `PRIMVEC k` is step k's own (a
//!      variable-cell animation); a structure without one keeps the last cell given before
//!      it. `CONVVEC [k]` (three lines: the conventional cell) and `CONVCOORD [k]` (a count
//!      line and its atom lines) may stand before or after the atoms and are read past;
//!    - molecular: `ATOMS [k]`, then atom lines up to the next keyword or the end of the file.
//!
//!    An atom line is `Z x y z` or `Z x y z fx fy fz`, the same for every atom of a frame.
//!    `Z` is an atomic number (0 and numbers beyond the element table are
//!    [`crate::Element::UNKNOWN`]) or an element symbol in any case (`X` is a dummy atom,
//!    unknown; Quantum ESPRESSO's species labels such as `Fe1` or `O_up` name the element
//!    before their digit or `_`), kept as the atom's name. The forces, in Hartree/Å as the
//!    XCrySDen specification says, become the properties `fx`, `fy`, `fz` in eV/Å (times
//!    27.211386245988 eV/Hartree, CODATA 2018; ASE's reader multiplies by its own Hartree the
//!    same way), the names a LAMMPS dump's force columns have (`--arrows f` draws them). `k`
//!    in `ATOMS k` / `PRIMCOORD k` is the frame's [`Frame::step`].
//! 4. Sections after a structure belong to its frame: data grids, and any other
//!    `BEGIN_<name>` … `END_<name>` section (`BEGIN_INFO`, a band grid), read past.
//!
//! # Data grids
//! `BEGIN_BLOCK_DATAGRID_3D` (or `BEGIN_BLOCK_DATAGRID3D`), a line naming the block, then one
//! or more grids, then `END_BLOCK_DATAGRID_3D`. A grid: `BEGIN_DATAGRID_3D_<name>` (also
//! written `DATAGRID_3D_<name>`, as pp.x does, or `BEGIN_DATAGRID_3D<name>`, as ASE does), a
//! line `nx ny nz`, the origin, three spanning vectors, the nx·ny·nz values with x fastest in
//! any line layout, and `END_DATAGRID_3D`. Each grid is one [`Volume`], named
//! `<block>: <grid>`, its values as written: the format has no units for them (pp.x writes
//! its quantities in its own atomic units, a charge density in e/bohr³ as in its cube files;
//! ASE writes whatever array it is given).
//!
//! XSF grids are *general* grids: their points include both ends, point (i, j, k) at
//! origin + i/(nx−1)·span₁ + j/(ny−1)·span₂ + k/(nz−1)·span₃. A periodic quantity over the
//! cell is written with nx = N + 1 (pp.x's `xsf_fast_datagrid_3d` does), the last plane along
//! each axis the periodic image of the first: the specification's "periodic grid" of N points
//! written as a general one. **Periodicity:** when the frame is a `CRYSTAL`, the three
//! spanning vectors are its cell vectors (to 1e-5 of their length, at least 1e-5 Å) and the
//! last plane along each axis repeats the first (to 1e-5 of the largest |value|), the grid is
//! read as that periodic grid: the repeated planes are dropped, N = n − 1 points per axis
//! remain, the steps are the cell vectors / N, and the [`Volume`] is periodic (it wraps: point
//! N is point 0), as a CHGCAR's. Any other grid (a slab's, a molecule's, one over part of the
//! cell, or one whose end planes differ, such as ASE's default, whose spans are cell·(n+1)/n)
//! keeps all its points, steps span/(n−1), and is not periodic. 2-D grids (`BEGIN_BLOCK_DATAGRID_2D`) are read past by the trajectory
//! reader and refused by [`crate::volume::read_volumes`], which reads the atoms of the file's
//! last structure (as ASE's `read_xsf(read_data=True)` gives them) and every 3-D grid.
//!
//! # Damage and memory
//! Errors name the file, frame, line and byte and what was expected (the keyword, the count
//! line, an atom line, the grid's counts, a value, the `END_` line). A file cut inside a
//! structure, a grid or a section is an [`Error::Truncated`]; so is one that ends before the
//! `ANIMSTEPS` count of structures (a molecule's last `ATOMS` block has no count, so a cut
//! between its atom lines cannot be told). Nothing is sized from a count: atoms and values are
//! pushed as they are read; a grid of more than 2^30 points, or (its size known) more values
//! than the file's bytes could hold, is refused at its counts line.
//!
//! # References
//! - A. Kokalj, "XSF format specification", XCrySDen documentation,
//!   <http://www.xcrysden.org/doc/XSF.html> (keywords, animated XSF, forces in Hartree/Å,
//!   general vs periodic grids).
//! - Quantum ESPRESSO `PP/src/xsf.f90` (`xsf_fast_datagrid_3d`: `DATAGRID_3D_UNKNOWN`,
//!   N + 1 points per axis over the cell, origin 0).
//! - ASE `ase/io/xsf.py` (3.29): what the tests compare with; its writer's default grid
//!   (origin cell/n per non-periodic axis, spans cell·(n+1)/n) and its forces in Hartree/Å.

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label, MAX_COORDINATE, Property, UnitCell};
use crate::parse::{fields, parse_f64, parse_i64, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};
use crate::volume::{Budget, MAX_POINTS, Values, Volume, walk_values};
use std::collections::BTreeMap;
use std::io::Read;

/// eV per Hartree (CODATA 2018).
const HARTREE: f64 = 27.211386245988;

/// The dimensionality keyword.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// No keyword: `ATOMS` blocks.
    Atoms,
    Molecule,
    Polymer,
    Slab,
    Crystal,
}

impl Kind {
    fn keyword(self) -> &'static str {
        match self {
            Kind::Atoms => "",
            Kind::Molecule => "MOLECULE",
            Kind::Polymer => "POLYMER",
            Kind::Slab => "SLAB",
            Kind::Crystal => "CRYSTAL",
        }
    }
}

/// What the start of the file says for every frame.
#[derive(Clone, Copy, Debug)]
struct Header {
    kind: Kind,
    /// `ANIMSTEPS n`.
    steps: Option<usize>,
}

/// A record's keyword (its line's first field).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kw {
    Animsteps,
    Dim(Kind),
    Atoms,
    Primvec,
    Convvec,
    Primcoord,
    Convcoord,
    /// `BEGIN_BLOCK_DATAGRID_3D`.
    Grid3d,
    /// `BEGIN_BLOCK_DATAGRID_2D`.
    Grid2d,
    /// Any other `BEGIN_…` section.
    Begin,
    /// Not a keyword.
    None,
}

fn keyword(line: &[u8]) -> Kw {
    let Some(t) = fields(line).next() else {
        return Kw::None;
    };
    let is = |k: &[u8]| t.eq_ignore_ascii_case(k);
    if is(b"ANIMSTEPS") {
        Kw::Animsteps
    } else if is(b"CRYSTAL") {
        Kw::Dim(Kind::Crystal)
    } else if is(b"SLAB") {
        Kw::Dim(Kind::Slab)
    } else if is(b"POLYMER") {
        Kw::Dim(Kind::Polymer)
    } else if is(b"MOLECULE") {
        Kw::Dim(Kind::Molecule)
    } else if is(b"ATOMS") {
        Kw::Atoms
    } else if is(b"PRIMVEC") {
        Kw::Primvec
    } else if is(b"CONVVEC") {
        Kw::Convvec
    } else if is(b"PRIMCOORD") {
        Kw::Primcoord
    } else if is(b"CONVCOORD") {
        Kw::Convcoord
    } else if is(b"BEGIN_BLOCK_DATAGRID_3D") || is(b"BEGIN_BLOCK_DATAGRID3D") {
        Kw::Grid3d
    } else if is(b"BEGIN_BLOCK_DATAGRID_2D") || is(b"BEGIN_BLOCK_DATAGRID2D") {
        Kw::Grid2d
    } else if t.len() > 6 && t[..6].eq_ignore_ascii_case(b"BEGIN_") {
        Kw::Begin
    } else {
        Kw::None
    }
}

/// True for a line that starts any record (ends a molecule's atom lines): a keyword, or an
/// `END_…` / `DATAGRID_…` line out of place.
fn is_keyword(line: &[u8]) -> bool {
    if keyword(line) != Kw::None {
        return true;
    }
    let t = fields(line).next().unwrap_or(b"");
    let starts = |p: &[u8]| t.len() >= p.len() && t[..p.len()].eq_ignore_ascii_case(p);
    starts(b"END_") || starts(b"DATAGRID_")
}

/// The next line that is not blank or a `#` comment; `None` at the end of the data.
fn next_record<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
) -> Result<Option<(Pos, &'a [u8])>, Error> {
    loop {
        let p = lines.pos();
        match lines.next_line().map_err(|e| ctx.io(p, e))? {
            None => return Ok(None),
            Some((_, l)) if matches!(trim(l).first(), None | Some(b'#')) => {}
            Some((pos, _)) => {
                lines.unread(pos);
                break;
            }
        }
    }
    let p = lines.pos();
    lines.next_line().map_err(|e| ctx.io(p, e))
}

/// The next record line, or the cut-file error naming what was expected there.
fn need_record<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: &dyn Fn() -> String,
) -> Result<(Pos, &'a [u8]), Error> {
    let p = lines.pos();
    match next_record(lines, ctx)? {
        Some(l) => Ok(l),
        None => Err(ctx.truncated(p, expected())),
    }
}

/// The step index after a keyword (`ATOMS 3`): `None` without one.
fn index(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<Option<i64>, Error> {
    const INDEX: &str = "the keyword and at most a step number ≥ 1 after it";
    let mut f = fields(line).skip(1);
    let k = match f.next() {
        None => return Ok(None),
        Some(t) => parse_i64(t)
            .filter(|k| *k >= 1)
            .ok_or_else(|| ctx.parse(pos, line, t, INDEX))?,
    };
    if let Some(t) = f.next() {
        return Err(ctx.parse(pos, line, t, INDEX));
    }
    Ok(Some(k))
}

/// Exactly three numbers.
fn vector(ctx: &Ctx, pos: Pos, line: &[u8], expected: &'static str) -> Result<[f64; 3], Error> {
    let mut v = [0.0; 3];
    let mut f = fields(line);
    for x in &mut v {
        let t = f
            .next()
            .ok_or_else(|| ctx.parse(pos, line, trim(line), expected))?;
        *x = parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    }
    if let Some(t) = f.next() {
        return Err(ctx.parse(pos, line, t, expected));
    }
    Ok(v)
}

/// A line kept for an error found after it: where it starts and its bytes.
type Line = (Pos, Vec<u8>);

/// The three vector lines after `PRIMVEC` / `CONVVEC`; also the last one.
fn vectors<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    what: &'static str,
    expected: &'static str,
) -> Result<([[f64; 3]; 3], Line), Error> {
    let mut m = [[0.0; 3]; 3];
    let mut last = (Pos::default(), Vec::new());
    for (r, row) in m.iter_mut().enumerate() {
        let (pos, line) = need_record(lines, ctx, &|| {
            format!("{} more {what} vector lines (3 numbers each)", 3 - r)
        })?;
        *row = vector(ctx, pos, line, expected)?;
        if r == 2 {
            last = (pos, line.to_vec());
        }
    }
    Ok((m, last))
}

/// An atom's element and name from the first field of its line.
fn element(t: &[u8]) -> Option<(Element, Label)> {
    if let Some(z) = parse_i64(t) {
        let z = u8::try_from(z).ok()?;
        let e = Element::from_z(z).unwrap_or(Element::UNKNOWN);
        return Some((e, Label::new(e.symbol()).unwrap_or_default()));
    }
    let s = std::str::from_utf8(t).ok()?;
    let e = if s.eq_ignore_ascii_case("X") {
        Element::UNKNOWN
    } else if let Some(e) = Element::from_symbol(s) {
        e
    } else {
        // A species label: the element before a digit or `_` (`Fe1`, `O_up`).
        let end = s.find(|c: char| !c.is_ascii_alphabetic())?;
        let rest = &s[end..];
        if end == 0 || !rest.starts_with(|c: char| c.is_ascii_digit() || c == '_') {
            return None;
        }
        Element::from_symbol(&s[..end])?
    };
    let name = Label::new(s).or_else(|| Label::new(e.symbol()))?;
    Some((e, name))
}

/// Where a frame's atoms go while they are read.
struct Atoms<'a> {
    frame: Option<&'a mut Frame>,
    /// Forces (Hartree/Å → eV/Å) of the frame's atoms, when its lines have them.
    forces: Option<bool>,
    f: [Vec<f32>; 3],
    n: usize,
}

impl Atoms<'_> {
    /// One atom line: `Z x y z [fx fy fz]`.
    fn line(&mut self, ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<(), Error> {
        const ATOM: &str = "an atom line: an atomic number or element symbol, x y z (Å), and \
                            optionally fx fy fz (Hartree/Å)";
        const SAME: &str = "as many numbers as the frame's first atom line (3: x y z, or 6: \
                            x y z fx fy fz)";
        let mut f = [&b""[..]; 7];
        let mut n = 0;
        for t in fields(line) {
            if n == 7 {
                return Err(ctx.parse(pos, line, t, ATOM));
            }
            f[n] = t;
            n += 1;
        }
        if n != 4 && n != 7 {
            return Err(ctx.parse(pos, line, trim(line), ATOM));
        }
        let forces = n == 7;
        match self.forces {
            None => self.forces = Some(forces),
            Some(w) if w != forces => return Err(ctx.parse(pos, line, trim(line), SAME)),
            Some(_) => {}
        }
        self.n += 1;
        let Some(frame) = self.frame.as_deref_mut() else {
            return Ok(());
        };
        let (e, name) = element(f[0]).ok_or_else(|| {
            ctx.parse(
                pos,
                line,
                f[0],
                "an atomic number 0 to 255 or an element symbol (a species label such as Fe1 \
                 or O_up: the element before the digit or '_')",
            )
        })?;
        let mut x = [0.0f64; 6];
        for (v, t) in x.iter_mut().zip(&f[1..n]) {
            *v = parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, ATOM))?;
        }
        if x[..3].iter().any(|c| c.abs() > MAX_COORDINATE) {
            return Err(ctx.parse(pos, line, trim(line), crate::cursor::IN_BOUNDS));
        }
        frame.positions.push([x[0], x[1], x[2]].map(|c| c as f32));
        frame.elements.push(e);
        frame.names.push(name);
        if forces {
            for (a, col) in self.f.iter_mut().enumerate() {
                let v = (x[3 + a] * HARTREE) as f32;
                if !v.is_finite() {
                    return Err(ctx.parse(pos, line, f[4 + a], "a force within f32 range"));
                }
                col.push(v);
            }
        }
        Ok(())
    }

    /// Moves the forces into the frame as `fx fy fz`.
    fn finish(self) {
        let (Some(frame), Some(true)) = (self.frame, self.forces) else {
            return;
        };
        for (name, values) in ["fx", "fy", "fz"].into_iter().zip(self.f) {
            frame.properties.push(Property {
                name: name.into(),
                values,
            });
        }
    }
}

/// What a walk does with the data grids it meets.
pub(crate) enum Sink<'a> {
    /// Checks their values (`true`: parses each) and drops them: the trajectory reader.
    Walk(bool),
    /// Keeps each 3-D grid as a volume, the file's size bounding the counts.
    Keep(&'a mut Vec<Volume>, &'a Budget),
}

/// The XSF parser; it keeps what later frames need from earlier ones.
#[derive(Default)]
pub(crate) struct Xsf {
    /// Frame 0's dimensionality and step count.
    header: Option<Header>,
    /// The cells by the frame whose text gives them (a `PRIMVEC`): frame k's is the last at or
    /// before k. Frames are met in order (reading or scanning), so every earlier one is known.
    cells: BTreeMap<usize, Option<UnitCell>>,
}

impl FrameWalk for Xsf {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        let parse = frame.is_some();
        self.frame(lines, ctx, frame, &mut Sink::Walk(parse))
    }

    fn end(&mut self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        match self.header.and_then(|h| h.steps) {
            Some(n) if ctx.frame < n => Err(missing_step(ctx, at, n)),
            _ => Ok(()),
        }
    }
}

/// The cut of an animation that ends before its `ANIMSTEPS` count: structure `ctx.frame + 1`
/// of `n` was due at `at`.
fn missing_step(ctx: &Ctx, at: Pos, n: usize) -> Error {
    ctx.truncated(
        at,
        format!(
            "structure {} of ANIMSTEPS {n} (ATOMS, or PRIMVEC and PRIMCOORD)",
            ctx.frame + 1
        ),
    )
}

/// Reads an XSF file for [`crate::volume::read_volumes`]: the last structure into `frame` and
/// every 3-D data grid.
pub(crate) fn read<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    frame: &mut Frame,
    budget: &Budget,
) -> Result<Vec<Volume>, Error> {
    let mut xsf = Xsf::default();
    let mut volumes = Vec::new();
    let mut f = Frame::new();
    for k in 0.. {
        let ctx = Ctx {
            frame: k,
            ..ctx.clone()
        };
        if crate::text::skip_blank(lines, &ctx)?.is_none() {
            FrameWalk::end(&mut xsf, &ctx, lines.pos())?;
            break;
        }
        f.clear();
        if !xsf.frame(
            lines,
            &ctx,
            Some(&mut f),
            &mut Sink::Keep(&mut volumes, budget),
        )? {
            break;
        }
        std::mem::swap(frame, &mut f);
    }
    Ok(volumes)
}

impl Xsf {
    /// Walks the frame starting at the next line: its structure into `frame` (when given),
    /// then the sections after it up to the next structure or the end of the data; `Ok(false)`
    /// when no structure starts there.
    fn frame<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
        sink: &mut Sink,
    ) -> Result<bool, Error> {
        let k = ctx.frame;
        let mut header = match (k, self.header) {
            (0, _) => Header {
                kind: Kind::Atoms,
                steps: None,
            },
            (_, Some(h)) => h,
            (_, None) => {
                let p = lines.pos();
                return Err(ctx.parse(p, b"", b"", "the file's first structure, read first"));
            }
        };
        // The records before the atoms: the header (frame 0), cells, sections.
        let mut started = false;
        let mut cell_here: Option<Option<UnitCell>> = None;
        const START: &str = "an XSF keyword: ANIMSTEPS, CRYSTAL, SLAB, POLYMER, MOLECULE, \
                             PRIMVEC, PRIMCOORD, ATOMS or BEGIN_BLOCK_DATAGRID_3D";
        const ONLY_FIRST: &str = "ANIMSTEPS first, then CRYSTAL, SLAB, POLYMER or MOLECULE, \
                                  once each and before the first structure";
        const TOO_MANY: &str = "no more structures than ANIMSTEPS gives (or the end of the file)";
        const NEEDS_PERIODIC: &str =
            "CRYSTAL, SLAB, POLYMER or MOLECULE at the start of a file with PRIMVEC / PRIMCOORD";
        let (periodic, step) = loop {
            let p = lines.pos();
            let Some((pos, line)) = next_record(lines, ctx)? else {
                if let Some(n) = header.steps
                    && k < n
                {
                    return Err(missing_step(ctx, p, n));
                }
                if started {
                    return Err(
                        ctx.truncated(p, "a structure: ATOMS, or PRIMCOORD and its atoms".into())
                    );
                }
                if k == 0 {
                    self.header = Some(header);
                }
                return Ok(false);
            };
            let kw = keyword(line);
            let block = matches!(kw, Kw::Atoms | Kw::Primvec | Kw::Primcoord);
            if block && header.steps.is_some_and(|n| k >= n) {
                return Err(ctx.parse(pos, line, trim(line), TOO_MANY));
            }
            match kw {
                Kw::Animsteps if k == 0 && !started => {
                    let n = fields(line)
                        .nth(1)
                        .and_then(parse_i64)
                        .filter(|n| *n >= 1)
                        .filter(|_| fields(line).count() == 2);
                    let n = n.ok_or_else(|| {
                        ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "ANIMSTEPS and the number of steps ≥ 1",
                        )
                    })?;
                    header.steps = Some(usize::try_from(n).unwrap_or(usize::MAX));
                    started = true;
                }
                Kw::Dim(d) if k == 0 && header.kind == Kind::Atoms && cell_here.is_none() => {
                    if fields(line).count() != 1 {
                        return Err(ctx.parse(pos, line, trim(line), ONLY_FIRST));
                    }
                    header.kind = d;
                    started = true;
                }
                Kw::Animsteps | Kw::Dim(_) => {
                    return Err(ctx.parse(pos, line, trim(line), ONLY_FIRST));
                }
                Kw::Primvec => {
                    if header.kind == Kind::Atoms {
                        return Err(ctx.parse(pos, line, trim(line), NEEDS_PERIODIC));
                    }
                    index(ctx, pos, line)?;
                    cell_here = Some(self.primvec(lines, ctx, header.kind)?);
                    started = true;
                }
                Kw::Convvec => {
                    index(ctx, pos, line)?;
                    vectors(
                        lines,
                        ctx,
                        "CONVVEC",
                        "a conventional lattice vector: 3 numbers",
                    )?;
                    started = true;
                }
                Kw::Primcoord => {
                    if header.kind == Kind::Atoms {
                        return Err(ctx.parse(pos, line, trim(line), NEEDS_PERIODIC));
                    }
                    break (true, index(ctx, pos, line)?);
                }
                Kw::Atoms => {
                    if !matches!(header.kind, Kind::Atoms | Kind::Molecule) {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "PRIMVEC / PRIMCOORD in a CRYSTAL, SLAB or POLYMER file (ATOMS is \
                             a molecule's)",
                        ));
                    }
                    break (false, index(ctx, pos, line)?);
                }
                Kw::Grid3d | Kw::Grid2d | Kw::Begin => {
                    let (pos, line) = (pos, line.to_vec());
                    section(lines, ctx, pos, &line, sink, None)?;
                }
                Kw::Convcoord | Kw::None => return Err(ctx.parse(pos, line, trim(line), START)),
            }
        };
        if k == 0 {
            self.header = Some(header);
        }
        if let Some(c) = cell_here {
            self.cells.insert(k, c);
        }
        let cell = self.cells.range(..=k).next_back().and_then(|(_, c)| *c);
        let mut out = frame;
        if let Some(f) = out.as_deref_mut() {
            f.comment.push_str(header.kind.keyword());
            f.step = step;
            if periodic {
                // A slab repeats along a and b, a polymer along a, a molecule along none.
                let along = match header.kind {
                    Kind::Slab => [true, true, false],
                    Kind::Polymer => [true, false, false],
                    Kind::Molecule => [false; 3],
                    Kind::Crystal | Kind::Atoms => [true; 3],
                };
                f.cell = cell.map(|c| c.with_periodic(along));
            }
        }
        let mut atoms = Atoms {
            frame: out,
            forces: None,
            f: Default::default(),
            n: 0,
        };
        if periodic {
            if !self.cells.range(..=k).any(|_| true) {
                let p = lines.pos();
                return Err(ctx.parse(
                    p,
                    b"",
                    b"",
                    "PRIMVEC (the cell) before the first PRIMCOORD",
                ));
            }
            let n = count_line(lines, ctx, "PRIMCOORD")?;
            reserve(&mut atoms, n.min(ctx.reserve));
            for i in 0..n {
                let (pos, line) =
                    need_record(lines, ctx, &|| format!("{} more atom lines", n - i))?;
                if is_keyword(line) {
                    return Err(ctx.parse(
                        pos,
                        line,
                        trim(line),
                        "as many atom lines as the count after PRIMCOORD",
                    ));
                }
                atoms.line(ctx, pos, line)?;
            }
        } else {
            loop {
                let p = lines.pos();
                let Some((pos, line)) = next_record(lines, ctx)? else {
                    if atoms.n == 0 {
                        return Err(ctx.truncated(p, "the atom lines after ATOMS".into()));
                    }
                    break;
                };
                if is_keyword(line) {
                    if atoms.n == 0 {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "an atom line after ATOMS: an atomic number or element symbol, x y z",
                        ));
                    }
                    lines.unread(pos);
                    break;
                }
                atoms.line(ctx, pos, line)?;
            }
        }
        atoms.finish();
        let crystal = (header.kind == Kind::Crystal).then_some(cell).flatten();
        self.after(lines, ctx, header, sink, crystal)?;
        Ok(true)
    }

    /// The three lattice vectors after `PRIMVEC`: the cell, or `None` for a slab's, polymer's
    /// or molecule's that spans no volume.
    fn primvec<R: Read>(
        &self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        kind: Kind,
    ) -> Result<Option<UnitCell>, Error> {
        let (m, (pos, line)) = vectors(lines, ctx, "PRIMVEC", "a lattice vector: 3 numbers (Å)")?;
        match UnitCell::from_matrix(m) {
            Ok(c) => Ok(Some(c)),
            Err(_) if kind != Kind::Crystal && crate::volume::det3(m) == 0.0 => Ok(None),
            Err(_) => Err(ctx.parse(
                pos,
                &line,
                trim(&line),
                "lattice vectors of a right-handed cell with volume > 0, at most 1e7 Å long",
            )),
        }
    }

    /// The sections after a frame's atoms, up to the next structure (left unread) or the end.
    fn after<R: Read>(
        &self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        header: Header,
        sink: &mut Sink,
        crystal: Option<UnitCell>,
    ) -> Result<(), Error> {
        const AFTER: &str = "an XSF keyword after a structure (ATOMS, PRIMVEC, PRIMCOORD, \
                             CONVVEC, CONVCOORD, BEGIN_BLOCK_DATAGRID_3D, BEGIN_…) or the end \
                             of the file";
        loop {
            let Some((pos, line)) = next_record(lines, ctx)? else {
                return Ok(());
            };
            match keyword(line) {
                Kw::Atoms | Kw::Primvec | Kw::Primcoord => {
                    lines.unread(pos);
                    return Ok(());
                }
                Kw::Convvec => {
                    // The next step's own conventional cell starts its frame.
                    let next = (ctx.frame + 2) as i64;
                    if header.steps.is_some() && index(ctx, pos, line)? == Some(next) {
                        lines.unread(pos);
                        return Ok(());
                    }
                    index(ctx, pos, line)?;
                    vectors(
                        lines,
                        ctx,
                        "CONVVEC",
                        "a conventional lattice vector: 3 numbers",
                    )?;
                }
                Kw::Convcoord => {
                    index(ctx, pos, line)?;
                    let n = count_line(lines, ctx, "CONVCOORD")?;
                    let mut atoms = Atoms {
                        frame: None,
                        forces: None,
                        f: Default::default(),
                        n: 0,
                    };
                    for i in 0..n {
                        let (pos, line) = need_record(lines, ctx, &|| {
                            format!("{} more CONVCOORD atom lines", n - i)
                        })?;
                        atoms.line(ctx, pos, line)?;
                    }
                }
                Kw::Grid3d | Kw::Grid2d | Kw::Begin => {
                    let line = line.to_vec();
                    section(lines, ctx, pos, &line, sink, crystal.as_ref())?;
                }
                Kw::Animsteps | Kw::Dim(_) | Kw::None => {
                    return Err(ctx.parse(pos, line, trim(line), AFTER));
                }
            }
        }
    }
}

fn reserve(atoms: &mut Atoms, n: usize) {
    if let Some(f) = atoms.frame.as_deref_mut() {
        f.reserve_named(n);
    }
}

/// The `natoms 1` line after `PRIMCOORD` / `CONVCOORD`.
fn count_line<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    what: &'static str,
) -> Result<usize, Error> {
    const COUNT: &str = "the atom count line: natoms ≥ 1, then 1";
    let (pos, line) = need_record(lines, ctx, &|| format!("the atom count line after {what}"))?;
    let mut f = fields(line);
    let n = f
        .next()
        .and_then(parse_i64)
        .filter(|n| *n >= 1)
        .ok_or_else(|| ctx.parse(pos, line, trim(line), COUNT))?;
    if let Some(t) = f.next()
        && parse_i64(t).is_none()
    {
        return Err(ctx.parse(pos, line, t, COUNT));
    }
    if let Some(t) = f.next() {
        return Err(ctx.parse(pos, line, t, COUNT));
    }
    Ok(usize::try_from(n).unwrap_or(usize::MAX))
}

/// The first field of `line`, when it starts with `prefix` (any case): the rest of the line
/// after the prefix, trimmed, without a leading `_`.
fn after_prefix<'a>(line: &'a [u8], prefix: &[u8]) -> Option<&'a [u8]> {
    let t = trim(line);
    if t.len() < prefix.len() || !t[..prefix.len()].eq_ignore_ascii_case(prefix) {
        return None;
    }
    let rest = trim(&t[prefix.len()..]);
    Some(rest.strip_prefix(b"_").unwrap_or(rest))
}

/// A grid header's name (`BEGIN_DATAGRID_3D_rho`, `DATAGRID_3D_UNKNOWN`, `BEGIN_DATAGRID_3Dgrid#1`).
fn grid_name(line: &[u8]) -> Option<&[u8]> {
    const PREFIXES: [&[u8]; 4] = [
        b"BEGIN_DATAGRID_3D",
        b"BEGIN_DATAGRID3D",
        b"DATAGRID_3D",
        b"DATAGRID3D",
    ];
    PREFIXES.iter().find_map(|p| after_prefix(line, p))
}

fn first_is(line: &[u8], words: &[&[u8]]) -> bool {
    let t = fields(line).next().unwrap_or(b"");
    words.iter().any(|w| t.eq_ignore_ascii_case(w))
}

/// A section that starts with `line` (at `pos`): a 3-D grid block, else read past to its
/// `END_` line (a 2-D grid block is refused when grids are kept). `crystal`: the cell of the
/// crystal frame the grids follow, if it is one.
fn section<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    sink: &mut Sink,
    crystal: Option<&UnitCell>,
) -> Result<(), Error> {
    let kw = keyword(line);
    if kw == Kw::Grid3d {
        return grid_block(lines, ctx, sink, crystal);
    }
    if kw == Kw::Grid2d && matches!(sink, Sink::Keep(..)) {
        return Err(ctx.parse(
            pos,
            line,
            trim(line),
            "a 3-D data grid block (BEGIN_BLOCK_DATAGRID_3D): 2-D grids are not read as volumes",
        ));
    }
    // `BEGIN_X` … `END_X`.
    let begin = fields(line).next().unwrap_or(b"");
    let mut end = b"END_".to_vec();
    end.extend_from_slice(&begin[6..]);
    loop {
        let p = lines.pos();
        let Some((_, l)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(
                p,
                format!(
                    "{} closing the {} section",
                    String::from_utf8_lossy(&end).to_ascii_uppercase(),
                    String::from_utf8_lossy(begin).to_ascii_uppercase()
                ),
            ));
        };
        if first_is(l, &[&end]) {
            return Ok(());
        }
    }
}

/// A `BEGIN_BLOCK_DATAGRID_3D` block after its keyword line: the name, the grids, the end.
fn grid_block<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    sink: &mut Sink,
    crystal: Option<&UnitCell>,
) -> Result<(), Error> {
    const END: [&[u8]; 2] = [b"END_BLOCK_DATAGRID_3D", b"END_BLOCK_DATAGRID3D"];
    // The block's name (a missing one, the first grid's header in its place, is empty).
    let (pos, line) = need_record(lines, ctx, &|| "the data grid block's name".into())?;
    let block = if grid_name(line).is_some() || first_is(line, &END) {
        lines.unread(pos);
        String::new()
    } else {
        String::from_utf8_lossy(trim(line)).into_owned()
    };
    loop {
        let p = lines.pos();
        let Some((pos, line)) = next_record(lines, ctx)? else {
            return Err(ctx.truncated(
                p,
                format!("END_BLOCK_DATAGRID_3D closing data grid block '{block}'"),
            ));
        };
        if first_is(line, &END) {
            return Ok(());
        }
        let Some(name) = grid_name(line) else {
            return Err(ctx.parse(
                pos,
                line,
                trim(line),
                "a data grid (BEGIN_DATAGRID_3D_name) or END_BLOCK_DATAGRID_3D",
            ));
        };
        let name = String::from_utf8_lossy(name).into_owned();
        grid(lines, ctx, sink, crystal, &block, &name)?;
    }
}

/// One grid after its header line: counts, origin, spans, values, `END_DATAGRID_3D`.
fn grid<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    sink: &mut Sink,
    crystal: Option<&UnitCell>,
    block: &str,
    name: &str,
) -> Result<(), Error> {
    const DIMS: &str = "the grid's point counts nx ny nz, each ≥ 2 (a general grid: both \
                        ends included)";
    let max = match sink {
        Sink::Keep(_, budget) => budget.max_values(),
        Sink::Walk(_) => MAX_POINTS,
    };
    let (dims, n) = {
        let (pos, line) =
            need_record(lines, ctx, &|| format!("the point counts of grid '{name}'"))?;
        let mut dims = [0usize; 3];
        let mut f = fields(line);
        for d in &mut dims {
            let t = f
                .next()
                .ok_or_else(|| ctx.parse(pos, line, trim(line), DIMS))?;
            *d = parse_i64(t)
                .filter(|n| *n >= 2)
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| ctx.parse(pos, line, t, DIMS))?;
        }
        if let Some(t) = f.next() {
            return Err(ctx.parse(pos, line, t, DIMS));
        }
        let n = dims
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .filter(|n| *n <= MAX_POINTS && *n <= max)
            .ok_or_else(|| {
                ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "a grid the file can hold: at most 2^30 points, each of ≥ 2 bytes",
                )
            })?;
        (dims, n)
    };
    let origin = {
        let (pos, line) = need_record(lines, ctx, &|| format!("the origin of grid '{name}'"))?;
        let origin = vector(ctx, pos, line, "the grid origin: 3 numbers (Å)")?;
        if origin.iter().any(|x| x.abs() > MAX_COORDINATE) {
            return Err(ctx.parse(pos, line, trim(line), crate::cursor::IN_BOUNDS));
        }
        origin
    };
    let mut spans = [[0.0; 3]; 3];
    let mut last = (Pos::default(), Vec::new());
    for (a, s) in spans.iter_mut().enumerate() {
        let (pos, line) = need_record(lines, ctx, &|| {
            format!("{} more spanning vectors of grid '{name}'", 3 - a)
        })?;
        *s = vector(ctx, pos, line, "a spanning vector: 3 numbers (Å)")?;
        last = (pos, line.to_vec());
    }
    let steps: [[f64; 3]; 3] = std::array::from_fn(|b| spans[b].map(|x| x / (dims[b] - 1) as f64));
    let det = crate::volume::det3(steps);
    if !(det.is_finite() && det != 0.0) || spans.iter().flatten().any(|x| x.abs() > MAX_COORDINATE)
    {
        let (pos, line) = &last;
        return Err(ctx.parse(
            *pos,
            line,
            trim(line),
            "spanning vectors that span a volume, at most 1e7 Å long",
        ));
    }
    let what = format!("grid '{name}' ({}x{}x{} points)", dims[0], dims[1], dims[2]);
    let mut data = Vec::new();
    let mut mode = match sink {
        Sink::Walk(true) => Values::Check,
        Sink::Walk(false) => Values::Count,
        Sink::Keep(_, budget) => {
            data.reserve(n.min(budget.reserve_values()));
            Values::Keep(&mut data)
        }
    };
    walk_values(lines, ctx, n, 1.0, &mut mode, &what)?;
    const END: &str = "END_DATAGRID_3D after the grid's values";
    let p = lines.pos();
    let Some((pos, line)) = next_record(lines, ctx)? else {
        return Err(ctx.truncated(
            p,
            format!("END_DATAGRID_3D after the values of grid '{name}'"),
        ));
    };
    if !first_is(line, &[b"END_DATAGRID_3D", b"END_DATAGRID3D"]) {
        return Err(ctx.parse(pos, line, trim(line), END));
    }
    if let Sink::Keep(volumes, _) = sink {
        let label = match (block.is_empty(), name.is_empty()) {
            (false, false) => format!("{block}: {name}"),
            (false, true) => block.to_string(),
            (true, false) => name.to_string(),
            (true, true) => "values".to_string(),
        };
        volumes.push(volume(origin, spans, dims, data, crystal, &label)?);
    }
    Ok(())
}

/// The volume of a general grid (see the module docs): periodic over a crystal's cell when its
/// spans are the cell vectors and its end planes repeat its first ones.
fn volume(
    origin: [f64; 3],
    spans: [[f64; 3]; 3],
    dims: [usize; 3],
    data: Vec<f32>,
    crystal: Option<&UnitCell>,
    name: &str,
) -> Result<Volume, Error> {
    let invalid = |e: crate::volume::VolumeShapeError| Error::InvalidValue { what: e.0 };
    if let Some(cell) = crystal {
        let m = cell.matrix();
        let same = (0..3).all(|a| {
            let len = m[a].iter().map(|x| x * x).sum::<f64>().sqrt();
            (0..3).all(|c| (spans[a][c] - m[a][c]).abs() <= 1e-5 * len.max(1.0))
        });
        if same && wraps(&data, dims) {
            let [nx, ny, nz] = dims;
            let inner = [nx - 1, ny - 1, nz - 1];
            let mut v = Vec::with_capacity(inner.iter().product());
            for k in 0..nz - 1 {
                for j in 0..ny - 1 {
                    let row = (k * ny + j) * nx;
                    v.extend_from_slice(&data[row..row + nx - 1]);
                }
            }
            let steps = std::array::from_fn(|a| m[a].map(|x| x / inner[a] as f64));
            return Volume::new(origin, steps, inner, v, true, name).map_err(invalid);
        }
    }
    let steps = std::array::from_fn(|a| spans[a].map(|x| x / (dims[a] - 1) as f64));
    Volume::new(origin, steps, dims, data, false, name).map_err(invalid)
}

/// Whether the last plane along each axis repeats the first, to 1e-5 of the largest |value|.
fn wraps(data: &[f32], [nx, ny, nz]: [usize; 3]) -> bool {
    let tol = 1e-5 * data.iter().fold(0f32, |m, v| m.max(v.abs()));
    let at = |i: usize, j: usize, k: usize| data[(k * ny + j) * nx + i];
    let same = |a: f32, b: f32| (a - b).abs() <= tol;
    (0..nz).all(|k| (0..ny).all(|j| same(at(nx - 1, j, k), at(0, j, k))))
        && (0..nz).all(|k| (0..nx).all(|i| same(at(i, ny - 1, k), at(i, 0, k))))
        && (0..ny).all(|j| (0..nx).all(|i| same(at(i, j, nz - 1), at(i, j, 0))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_from_numbers_symbols_and_species_labels() {
        let sym = |t: &str| element(t.as_bytes()).map(|(e, n)| (e.symbol(), n.to_string()));
        assert_eq!(sym("26"), Some(("Fe", "Fe".into())));
        assert_eq!(sym("0"), Some(("X", "X".into())));
        assert_eq!(sym("200"), Some(("X", "X".into())));
        assert_eq!(sym("300"), None);
        assert_eq!(sym("-1"), None);
        assert_eq!(sym("fe"), Some(("Fe", "fe".into())));
        assert_eq!(sym("Fe1"), Some(("Fe", "Fe1".into())));
        assert_eq!(sym("O_up"), Some(("O", "O_up".into())));
        assert_eq!(sym("X"), Some(("X", "X".into())));
        assert_eq!(sym("Qq"), None);
        assert_eq!(sym("Fex"), None);
        assert_eq!(sym("1.5"), None);
    }

    #[test]
    fn keywords_in_any_case() {
        assert_eq!(keyword(b" primcoord 2"), Kw::Primcoord);
        assert_eq!(keyword(b"Begin_Block_Datagrid3D"), Kw::Grid3d);
        assert_eq!(keyword(b"BEGIN_INFO"), Kw::Begin);
        assert_eq!(keyword(b"Fe 0 0 0"), Kw::None);
        assert!(is_keyword(b"END_DATAGRID_3D"));
        assert_eq!(grid_name(b" BEGIN_DATAGRID_3Dgrid#1"), Some(&b"grid#1"[..]));
        assert_eq!(grid_name(b"DATAGRID_3D_UNKNOWN"), Some(&b"UNKNOWN"[..]));
        assert_eq!(grid_name(b"BEGIN_DATAGRID_2D_x"), None);
    }
}

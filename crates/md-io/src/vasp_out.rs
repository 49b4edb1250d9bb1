//! VASP's run outputs: `vasprun.xml` (`Format::VaspXml`) and `OUTCAR` (`Format::Outcar`),
//! every ionic step a frame, as ASE reads them (`ase.io.read(path, ':')` with the `vasp-xml`
//! and `vasp-out` formats).
//!
//! # vasprun.xml: which steps are frames
//! Every ionic step, a `<calculation>` element, is a frame: its `<structure>` (the cell
//! `crystal/varray name="basis"`, the fractional `varray name="positions"`), its `varray
//! name="forces"`, `varray name="stress"` and its own `<energy>` block. The `initialpos`,
//! `finalpos` (and `primitive_cell`) structures outside the calculations are not frames: ASE
//! returns one image per calculation, and the final positions repeat the last step's (a
//! relaxation's `finalpos` is its last `<calculation>`'s structure; VASP writes no results for
//! it). The species come from `<atominfo>`'s `atoms` array (one `<rc><c>Fe</c>…` row per
//! atom): the element column with VASP's padding removed (`"O "` is oxygen), as ASE reads it;
//! a name that is no element's symbol is kept as the atom's name with an unknown element (ASE
//! refuses such a file). `POTIM`, `IBRION` and `PSTRESS` are taken from the header (`<incar>`,
//! then `<parameters>`, which repeats them with VASP's defaults filled in: the later wins).
//!
//! The file is read as text, line by line, as VASP writes it (one element or `<v>` row per
//! line, which VASP 4.6, 5 and 6 write); a general XML parser was not needed for that and
//! would have added a dependency without telling more of the damage: each element's line is
//! matched by its tag, and a row's numbers must close with their end tag (`</v>`, `</i>`), so
//! that a line cut by the end of the file is a cut, not a shorter number.
//!
//! # OUTCAR: which steps are frames
//! ASE's rule: the header runs up to the first `Iteration` line; then every ionic step ends
//! with its `FREE ENERGIE OF THE ION-ELECTRON SYSTEM (eV)` block (the energies are the 2nd and
//! 4th lines after it), and the step holds the positions and forces of its `POSITION …
//! TOTAL-FORCE (eV/Angst)` table, the cell of its last `direct lattice vectors` block (or,
//! when the step has none, the header's last) and the stress of its `in kB` line. Species:
//! one per POTCAR, from its `TITEL  = PAW_PBE Fe_pv 02Aug2007` line (the symbol before any
//! `_` or digit: ASE reads the same symbol from the `POTCAR:` lines, which VASP writes twice
//! per species), repeated by the header's `ions per type` counts.
//!
//! # What a frame holds
//! - Positions (Å): the fractional positions times the step's basis (vasprun.xml), or the
//!   Cartesian table (OUTCAR); the cell, periodic along all three vectors.
//! - Names: the species' symbols; elements from them.
//! - Forces (eV/Å) as the properties `fx fy fz` (the names a LAMMPS dump's force columns
//!   have: `--arrows f` draws them).
//! - The energies and the stress in the frame's comment, as extended XYZ writes them:
//!   `energy=-970.73367436 free_energy=-970.73368093 stress="sxx sxy sxz syx syy syz szx szy
//!   szz"`, so `--label '{energy:.4} eV'` shows them. `energy` is what ASE's
//!   `get_potential_energy()` reports, `free_energy` what `get_potential_energy(
//!   force_consistent=True)` does:
//!   - vasprun.xml: `free_energy` is the calculation's `e_fr_energy` minus PSTRESS · volume
//!     (VASP adds the PV term there: ASE merge request 2685), and `energy` that plus the last
//!     `<scstep>`'s `e_0_energy − e_fr_energy` (the calculation's own `e_0_energy` is wrong,
//!     ASE's comment says: the Li relaxation fixture's, from VASP 5.2.12, is 0.00000000 eV
//!     in every step, the SiO2 one's, from VASP 5.4.1, −0.00000000 eV; the last
//!     `<scstep>` is a DFPT run's last linear-response step, as ASE takes it); a step without
//!     `<scstep>`
//!     (a machine-learned force field's) has `energy` = `free_energy`, where ASE fails;
//!   - OUTCAR: `free_energy` from `free  energy   TOTEN`, `energy` the `energy(sigma->0)` of
//!     the `energy  without entropy` line (ASE's choice; `e_wo_entrp` itself is not kept).
//! - Stress in eV/Å³ with ASE's sign (the negative of VASP's kB: pressure positive), 1 kB =
//!   0.1 GPa with ASE 3.29's GPa (CODATA 2014 e: 6.241509125883258e-4 eV/Å³ per kB); VASP's
//!   OUTCAR order `XX YY ZZ XY YZ ZX` becomes the matrix. PSTRESS (kB) uses the constant ASE
//!   uses for it (`1e-22 / 1.60217733e-19`).
//! - [`Frame::step`]: the ionic step's index from 0. [`Frame::time`] (ps) in molecular
//!   dynamics (IBRION = 0): step · POTIM (POTIM in fs), the first step at 0 (VASP's first
//!   ionic step computes the forces of the starting positions).
//!
//! Not kept: eigenvalues, densities of states, magnetic moments, dielectric tensors and Born
//! charges, selective-dynamics flags (a frame has no place for them; ASE keeps the flags as
//! constraints), OUTCAR's velocities and nearest-neighbour tables.
//!
//! # Unfinished files and damage
//! A run VASP did not finish (killed for time, crashed) is common: its vasprun.xml ends
//! without `</modeling>`, its OUTCAR without the closing `General timing and accounting`
//! report. The complete steps are read, then the cut is an [`Error::Truncated`] naming the
//! file, the frame and the byte where the data ends, or under `allow_truncated` a warning,
//! and the complete steps are the whole file. That gives ASE's frames: ASE reads the
//! calculations of a cut vasprun.xml that have an `<energy>` (a step cut after its energy
//! block is a frame here too, and the cut is the next frame's), and the steps of an OUTCAR
//! whose energy block is whole. (A vasprun.xml cut before its first calculation's energy has
//! no frame here; ASE returns its `initialpos` structure without results.) Bytes after
//! `</modeling>` are not read: a file VASP overwrote with a shorter run keeps the old run's
//! tail there, which ASE does not read either (no fixture kept in the tests has such a tail).
//! Any other error names the line and byte and what was expected there. Nothing is sized from
//! a count in the file (`<atoms>`, `ions per type`): atoms are pushed as their rows are read,
//! reserving at most the text reader's bound.
//!
//! # References
//! - ASE 3.29 `ase/io/vasp.py` (`read_vasp_xml`, `atoms_from_step`) and
//!   `ase/io/vasp_parsers/vasp_outcar_parsers.py`, what the tests compare with.
//! - The VASP wiki, `vasprun.xml` and `OUTCAR`; the fixtures in `tests/data/vasp_out` (from
//!   pymatgen's test files) are VASP 5.2.12's and 5.4.1's.

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label, MAX_COORDINATE, UnitCell};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};
use std::io::Read;

/// eV/Å³ per kB, ASE's `0.1 * ase.units.GPa` (ASE 3.29: CODATA 2014 e).
const KBAR: f64 = 0.1 * 1e9 / (1.602_176_620_8e-19 * 1e30);

/// eV/Å³ per kB of PSTRESS, as ASE's `read_vasp_xml` converts it (`1e-22 / EVTOJ`).
const PSTRESS_KBAR: f64 = 1e-22 / 1.602_177_33e-19;

/// True when `head` (a file's first bytes) is an XML document whose root is VASP's
/// `<modeling>`: after the optional `<?xml …?>` declaration and blank lines.
pub(crate) fn is_vasprun(head: &[u8]) -> bool {
    head.split(|b| *b == b'\n')
        .map(trim)
        .filter(|l| !l.is_empty() && !l.starts_with(b"<?xml"))
        .take(1)
        .any(|l| l.starts_with(b"<modeling>"))
}

/// True when the first line of `head` is VASP's banner, as an OUTCAR starts: ` vasp.6.4.1
/// 05Apr23 (build …)`.
pub(crate) fn is_outcar(head: &[u8]) -> bool {
    let first = head.split(|b| *b == b'\n').next().unwrap_or(b"");
    let t = trim(first);
    t.starts_with(b"vasp.") && t.get(5).is_some_and(u8::is_ascii_digit)
}

/// A species: its name and element.
type Species = (Label, Element);

/// The species a name (VASP's element column, a POTCAR symbol) gives.
fn species(name: &[u8]) -> Species {
    let s = std::str::from_utf8(name).unwrap_or("");
    let label = Label::new(s).unwrap_or_default();
    (label, Element::from_symbol(s).unwrap_or(Element::UNKNOWN))
}

/// The step's cell and positions (Å) into `frame`, checked.
fn fill(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    frame: &mut Frame,
    cell: [[f64; 3]; 3],
    positions: impl Iterator<Item = [f64; 3]>,
    species: impl Iterator<Item = Species>,
) -> Result<(), Error> {
    let cell = UnitCell::from_matrix(cell).map_err(|_| {
        ctx.parse(
            pos,
            line,
            trim(line),
            "the step's cell: three vectors of a right-handed cell with volume > 0, each at most \
             1e7 Å long",
        )
    })?;
    frame.cell = Some(cell);
    for (p, s) in positions.zip(species) {
        if p.iter().any(|v| !v.is_finite() || v.abs() > MAX_COORDINATE) {
            return Err(ctx.parse(pos, line, trim(line), crate::cursor::IN_BOUNDS));
        }
        frame.positions.push(p.map(|v| v as f32));
        frame.names.push(s.0);
        frame.elements.push(s.1);
    }
    Ok(())
}

/// Forces (eV/Å) as the properties `fx fy fz`.
fn push_forces(frame: &mut Frame, forces: &[[f64; 3]]) {
    for (c, key) in ["fx", "fy", "fz"].into_iter().enumerate() {
        let v = frame.property_mut(key);
        v.extend(forces.iter().map(|f| f[c] as f32));
    }
}

/// The comment's `energy= free_energy= stress="…"` (eV, eV/Å³ row by row).
fn comment(energy: f64, free_energy: f64, stress: Option<[[f64; 3]; 3]>) -> String {
    let mut c = format!("energy={energy} free_energy={free_energy}");
    if let Some(s) = stress {
        let s: Vec<String> = s.iter().flatten().map(f64::to_string).collect();
        c.push_str(&format!(" stress=\"{}\"", s.join(" ")));
    }
    c
}

/// The time (ps) of step `step` of a molecular-dynamics run (IBRION = 0) with POTIM (fs).
fn md_time(ibrion: Option<i64>, potim: Option<f64>, step: usize) -> Option<f64> {
    match (ibrion, potim) {
        (Some(0), Some(dt)) => Some(step as f64 * dt / 1000.0),
        _ => None,
    }
}

/// The next line, or the cut: the data ends where `expected` was due.
fn next<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: &dyn Fn() -> String,
) -> Result<(Pos, &'a [u8]), Error> {
    crate::text::need_line_with(lines, ctx, expected)
}

// ------------------------------------------------------------------------------------------
// vasprun.xml
// ------------------------------------------------------------------------------------------

/// A line's element tag: its name and whether it closes (`</energy>`); `None` for a line that
/// does not start with a tag.
fn tag(t: &[u8]) -> Option<(&[u8], bool)> {
    let rest = t.strip_prefix(b"<")?;
    let (rest, closing) = match rest.strip_prefix(b"/") {
        Some(r) => (r, true),
        None => (rest, false),
    };
    let end = rest
        .iter()
        .position(|b| matches!(b, b' ' | b'>' | b'/' | b'\t'))
        .unwrap_or(rest.len());
    Some((&rest[..end], closing))
}

/// An opening tag's attribute `key="value"`.
fn attr<'a>(t: &'a [u8], key: &[u8]) -> Option<&'a [u8]> {
    let head = &t[..t.iter().position(|b| *b == b'>').unwrap_or(t.len())];
    let mut i = 0;
    while let Some(k) = head[i..]
        .windows(key.len() + 2)
        .position(|w| w.starts_with(key) && w[key.len()] == b'=' && w[key.len() + 1] == b'"')
    {
        let at = i + k;
        let before_ok = at == 0 || matches!(head[at - 1], b' ' | b'\t');
        let v0 = at + key.len() + 2;
        if before_ok {
            let len = head[v0..].iter().position(|b| *b == b'"')?;
            return Some(&head[v0..v0 + len]);
        }
        i = v0;
    }
    None
}

/// The text of a one-line element `<name …>text</name>`, or `None` when the line is not one
/// whole such element.
fn content<'a>(t: &'a [u8], name: &[u8]) -> Option<&'a [u8]> {
    let open = t.iter().position(|b| *b == b'>')? + 1;
    let body = &t[open..];
    let close = body.len().checked_sub(name.len() + 3)?;
    let end = &body[close..];
    (end.starts_with(b"</") && &end[2..2 + name.len()] == name && end.ends_with(b">"))
        .then_some(&body[..close])
}

/// A `<v>x y z</v>` row's three numbers.
fn row3(ctx: &Ctx, pos: Pos, line: &[u8], expected: &'static str) -> Result<[f64; 3], Error> {
    let t = trim(line);
    let body = (tag(t) == Some((b"v", false)))
        .then(|| content(t, b"v"))
        .flatten()
        .ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    let mut v = [0.0; 3];
    let mut f = fields(body);
    for x in &mut v {
        let s = f.next().ok_or_else(|| ctx.parse(pos, line, t, expected))?;
        *x = parse_f64(s)
            .filter(|x| x.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, s, expected))?;
    }
    if let Some(s) = f.next() {
        return Err(ctx.parse(pos, line, s, expected));
    }
    Ok(v)
}

/// The rows of a `<varray>` whose opening line was just read, up to its `</varray>`: exactly
/// `n` of them, each `<v>x y z</v>`.
fn varray<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    n: usize,
    what: &'static str,
    expected: &'static str,
) -> Result<Vec<[f64; 3]>, Error> {
    let mut out = Vec::with_capacity(n.min(ctx.reserve));
    loop {
        let (pos, line) = next(lines, ctx, &|| format!("the rest of {what}"))?;
        let t = trim(line);
        if tag(t) == Some((b"varray", true)) {
            if out.len() == n {
                return Ok(out);
            }
            return Err(ctx.parse(pos, line, t, expected));
        }
        if out.len() == n {
            return Err(ctx.parse(pos, line, t, expected));
        }
        out.push(row3(ctx, pos, line, expected)?);
    }
}

/// Reads past the lines of an element whose opening line was just read, up to the line that
/// closes it (`</name>`), which holds no element of the same name.
fn skip_element<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    name: &'static [u8],
    what: &'static str,
) -> Result<(), Error> {
    loop {
        let (_, line) = next(lines, ctx, &|| format!("the rest of {what}"))?;
        if tag(trim(line)) == Some((name, true)) {
            return Ok(());
        }
    }
}

/// The number of a `<i name="key">x</i>` line.
fn item(ctx: &Ctx, pos: Pos, line: &[u8], expected: &'static str) -> Result<f64, Error> {
    let t = trim(line);
    let body = content(t, b"i").ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    let v = trim(body);
    parse_f64(v)
        .filter(|x| x.is_finite())
        .ok_or_else(|| ctx.parse(pos, line, v, expected))
}

/// An `<energy>` block's `e_fr_energy` and, if it has one, `e_0_energy` (eV), up to its
/// `</energy>`.
fn energy_block<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    what: &'static str,
) -> Result<(f64, Option<f64>), Error> {
    const ITEM: &str = "an energy item: <i name=\"…\"> number </i>";
    const FREE: &str = "an e_fr_energy item in the <energy> block";
    let (mut fr, mut e0) = (None, None);
    loop {
        let (pos, line) = next(lines, ctx, &|| format!("the rest of {what}"))?;
        let t = trim(line);
        match tag(t) {
            Some((b"energy", true)) => {
                return fr
                    .map(|fr| (fr, e0))
                    .ok_or_else(|| ctx.parse(pos, line, t, FREE));
            }
            Some((b"i", false)) => match attr(t, b"name") {
                Some(b"e_fr_energy") => fr = Some(item(ctx, pos, line, ITEM)?),
                Some(b"e_0_energy") => e0 = Some(item(ctx, pos, line, ITEM)?),
                _ => {
                    item(ctx, pos, line, ITEM)?;
                }
            },
            _ => return Err(ctx.parse(pos, line, t, ITEM)),
        }
    }
}

/// What the header before the first `<calculation>` gives every step.
#[derive(Clone, Debug, Default)]
struct XmlHeader {
    species: Vec<Species>,
    ibrion: Option<i64>,
    potim: Option<f64>,
    /// PSTRESS in kB.
    pstress: f64,
}

/// The vasprun.xml parser; it keeps the header, and where the document ended.
#[derive(Default)]
pub(crate) struct VaspXml {
    header: Option<XmlHeader>,
    /// The byte after the `</modeling>` line, once met: nothing after it is read.
    closed: Option<u64>,
    /// A frame the data ends inside of after its results (its `</calculation>` cut off).
    cut_after: Option<usize>,
}

impl FrameWalk for VaspXml {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        if self.closed.is_some_and(|end| lines.pos().byte >= end) {
            return Ok(false);
        }
        if ctx.frame == 0 {
            self.header = Some(xml_header(lines, ctx)?);
        } else {
            // The next `<calculation>`, or the document's end.
            loop {
                let p = lines.pos();
                let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                    return Err(ctx.truncated(
                        p,
                        "the next ionic step (<calculation>) or the end of the run \
                         (</modeling>): VASP did not finish the file"
                            .into(),
                    ));
                };
                match tag(trim(line)) {
                    Some((b"calculation", false)) => break,
                    Some((b"modeling", true)) => {
                        self.closed = Some(lines.pos().byte);
                        return Ok(false);
                    }
                    Some((b"calculation" | b"atominfo" | b"modeling", _)) => {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "the next ionic step (<calculation>) or the end of the run \
                             (</modeling>)",
                        ));
                    }
                    _ => {}
                }
            }
        }
        let Some(header) = self.header.as_ref() else {
            let p = lines.pos();
            return Err(ctx.parse(p, b"", b"", "the file's earlier frames, read first"));
        };
        let step = calculation(lines, ctx, header, frame)?;
        if step.cut {
            self.cut_after = Some(ctx.frame);
        }
        Ok(true)
    }

    fn end(&mut self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        if self.closed.is_some() {
            return Ok(());
        }
        let expected = match self.cut_after {
            Some(k) if k + 1 == ctx.frame => format!(
                "the rest of ionic step {k} (its </calculation>) and the end of the run \
                 (</modeling>): VASP did not finish the file"
            ),
            _ => "the next ionic step (<calculation>) or the end of the run (</modeling>): \
                  VASP did not finish the file"
                .into(),
        };
        Err(ctx.truncated(at, expected))
    }
}

/// The header, from the file's first line up to and with the first `<calculation>` line.
fn xml_header<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<XmlHeader, Error> {
    const FIRST: &str = "a vasprun.xml: the <?xml …?> declaration or the <modeling> element";
    const NUMBER: &str = "a parameter's value: <i … name=\"…\"> number </i>";
    const ROW: &str = "an atom's row of the atominfo 'atoms' array: <rc><c>element</c>…</rc>";
    const COUNT: &str = "as many rows in atominfo's 'atoms' array as its <atoms> count";
    let mut h = XmlHeader::default();
    let mut count: Option<(Pos, Vec<u8>, usize)> = None;
    let mut atoms_read = false;
    let mut first = true;
    loop {
        let (pos, line) = next(lines, ctx, &|| {
            "the first ionic step (<calculation>): VASP did not finish the file".into()
        })?;
        let t = trim(line);
        if first {
            if t.is_empty() {
                continue;
            }
            if !(t.starts_with(b"<?xml") || t.starts_with(b"<modeling>")) {
                return Err(ctx.parse(pos, line, t, FIRST));
            }
            first = false;
        }
        match tag(t) {
            Some((b"calculation", false)) => {
                if !atoms_read {
                    return Err(ctx.parse(
                        pos,
                        line,
                        t,
                        "the <atominfo> block with the atoms' elements before the first ionic \
                         step",
                    ));
                }
                return Ok(h);
            }
            Some((b"atoms", false)) => {
                let n = content(t, b"atoms")
                    .map(trim)
                    .and_then(parse_usize)
                    .filter(|n| *n > 0)
                    .ok_or_else(|| {
                        ctx.parse(pos, line, t, "the atom count: <atoms> n ≥ 1 </atoms>")
                    })?;
                count = Some((pos, line.to_vec(), n));
            }
            Some((b"array", false)) if attr(t, b"name") == Some(b"atoms") => {
                let Some((cpos, cline, n)) = count.take() else {
                    return Err(ctx.parse(pos, line, t, "the <atoms> count before its array"));
                };
                h.species.clear();
                h.species.reserve(n.min(ctx.reserve));
                loop {
                    let (pos, line) = next(lines, ctx, &|| "the rest of atominfo's array".into())?;
                    let t = trim(line);
                    match tag(t) {
                        Some((b"array", true)) => break,
                        Some((b"rc", false)) => {
                            let name = t
                                .strip_prefix(b"<rc><c>")
                                .and_then(|r| {
                                    r.windows(4).position(|w| w == b"</c>").map(|k| &r[..k])
                                })
                                .map(trim)
                                .filter(|n| !n.is_empty())
                                .ok_or_else(|| ctx.parse(pos, line, t, ROW))?;
                            if h.species.len() == n {
                                return Err(ctx.parse(cpos, &cline, trim(&cline), COUNT));
                            }
                            h.species.push(species(name));
                        }
                        _ => {}
                    }
                }
                if h.species.len() != n {
                    return Err(ctx.parse(cpos, &cline, trim(&cline), COUNT));
                }
                atoms_read = true;
            }
            Some((b"i", false)) => match attr(t, b"name") {
                Some(b"IBRION") => {
                    let v = item(ctx, pos, line, NUMBER)?;
                    h.ibrion = (v.fract() == 0.0).then_some(v as i64);
                }
                Some(b"POTIM") => h.potim = Some(item(ctx, pos, line, NUMBER)?),
                Some(b"PSTRESS") => h.pstress = item(ctx, pos, line, NUMBER)?,
                _ => {}
            },
            _ => {}
        }
    }
}

/// Whether `e` is the data's end: a cut, or damage on the data's last line when that line has
/// no end of line (a line cut short).
fn is_cut<R>(e: &Error, lines: &LineReader<R>) -> bool {
    match e {
        Error::Truncated { .. } => true,
        Error::Parse { at, .. } => lines.unterminated.is_some() && at.line == lines.unterminated,
        _ => false,
    }
}

/// A step's `<structure>`: the cell (rows, Å), the fractional positions, and where it starts.
struct Structure {
    basis: [[f64; 3]; 3],
    frac: Vec<[f64; 3]>,
    pos: Pos,
    line: Vec<u8>,
}

/// How a calculation ended.
struct Step {
    /// The data ended inside it, after its results.
    cut: bool,
}

/// One `<calculation>` whose opening line was just read, up to its `</calculation>`, into
/// `frame` when given.
fn calculation<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    h: &XmlHeader,
    frame: Option<&mut Frame>,
) -> Result<Step, Error> {
    const N_ROWS: &str = "one <v>x y z</v> row per atom (as many as <atominfo> lists), then \
                          </varray>";
    const THREE: &str = "three <v>x y z</v> rows, then </varray>";
    let n = h.species.len();
    let mut in_scstep = false;
    let mut last_scf: Option<(f64, f64)> = None;
    let mut energy: Option<(f64, Option<f64>)> = None;
    let mut structure: Option<Structure> = None;
    let mut forces = None;
    let mut stress = None;
    // A cut after the step's structure and energy leaves a frame (ASE keeps it too); a cut
    // before them is the step's.
    macro_rules! or_cut {
        ($calc:lifetime, $e:expr) => {
            match $e {
                Ok(v) => v,
                Err(e) if structure.is_some() && energy.is_some() && is_cut(&e, lines) => {
                    break $calc None;
                }
                Err(e) => return Err(e),
            }
        };
    }
    let end = 'calc: loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            if structure.is_some() && energy.is_some() {
                break None;
            }
            let missing = if structure.is_none() {
                "the rest of the ionic step (<calculation>): its <structure> and <energy>"
            } else {
                "the rest of the ionic step (<calculation>): its <energy>"
            };
            return Err(ctx.truncated(p, format!("{missing}: VASP did not finish the file")));
        };
        let t = trim(line);
        match tag(t) {
            Some((b"calculation", true)) => break Some((pos, line.to_vec())),
            Some((b"calculation" | b"modeling" | b"atominfo", _)) => {
                return Err(ctx.parse(pos, line, t, "the ionic step's </calculation>"));
            }
            Some((b"scstep", closing)) => in_scstep = !closing,
            Some((b"energy", false)) => {
                if in_scstep {
                    let (fr, e0) =
                        or_cut!('calc, energy_block(lines, ctx, "an electronic step's <energy>"));
                    let e0 = e0.ok_or_else(|| {
                        let p = lines.pos();
                        ctx.parse(
                            p,
                            b"",
                            b"",
                            "an e_0_energy item in the electronic step's <energy>",
                        )
                    })?;
                    last_scf = Some((fr, e0));
                } else {
                    energy = Some(or_cut!('calc, energy_block(
                        lines,
                        ctx,
                        "the ionic step's <energy>"
                    )));
                }
            }
            Some((b"structure", false)) => {
                let (pos, line) = (pos, line.to_vec());
                let (mut basis, mut frac) = (None, None);
                loop {
                    let (_, l) = or_cut!(
                        'calc,
                        next(lines, ctx, &|| "the rest of the step's <structure>".into())
                            .map(|(p, l)| (p, l.to_vec()))
                    );
                    let t = trim(&l);
                    match tag(t) {
                        Some((b"structure", true)) => break,
                        Some((b"varray", false)) => match attr(t, b"name") {
                            Some(b"basis") => {
                                let b = or_cut!('calc, varray(lines, ctx, 3, "the cell ('basis')", THREE));
                                basis = Some([b[0], b[1], b[2]]);
                            }
                            Some(b"positions") => {
                                frac = Some(
                                    or_cut!('calc, varray(lines, ctx, n, "the positions", N_ROWS)),
                                );
                            }
                            _ => or_cut!('calc, skip_element(lines, ctx, b"varray", "a <varray>")),
                        },
                        _ => {}
                    }
                }
                let (Some(basis), Some(frac)) = (basis, frac) else {
                    return Err(ctx.parse(
                        pos,
                        &line,
                        trim(&line),
                        "a <structure> with its cell (varray 'basis') and positions (varray \
                         'positions')",
                    ));
                };
                structure = Some(Structure {
                    basis,
                    frac,
                    pos,
                    line,
                });
            }
            Some((b"varray", false)) => match attr(t, b"name") {
                Some(b"forces") => {
                    forces = Some(or_cut!('calc, varray(lines, ctx, n, "the forces", N_ROWS)))
                }
                Some(b"stress") => {
                    let s = or_cut!('calc, varray(lines, ctx, 3, "the stress", THREE));
                    stress = Some([s[0], s[1], s[2]]);
                }
                _ => or_cut!('calc, skip_element(lines, ctx, b"varray", "a <varray>")),
            },
            _ => {}
        }
    };
    let Some(Structure {
        basis,
        frac,
        pos: spos,
        line: sline,
    }) = structure
    else {
        let (pos, line) = end.unwrap_or_default();
        return Err(ctx.parse(pos, &line, trim(&line), "the ionic step's <structure>"));
    };
    let Some((e_fr, _)) = energy else {
        let (pos, line) = end.unwrap_or_default();
        return Err(ctx.parse(pos, &line, trim(&line), "the ionic step's <energy>"));
    };
    if let Some(f) = frame {
        let cart = frac
            .iter()
            .map(|x| std::array::from_fn(|k| (0..3).map(|i| x[i] * basis[i][k]).sum::<f64>()));
        fill(ctx, spos, &sline, f, basis, cart, h.species.iter().copied())?;
        if let Some(forces) = &forces {
            push_forces(f, forces);
        }
        // ASE's energies: e_fr_energy less the PV term, plus the last electronic step's
        // e_0 − e_fr (the calculation's own e_0_energy can be wrong).
        let volume = f.cell.map_or(0.0, |c| c.volume());
        let free = e_fr - h.pstress * PSTRESS_KBAR * volume;
        let de = last_scf.map_or(0.0, |(fr, e0)| e0 - fr);
        let stress = stress.map(|s: [[f64; 3]; 3]| s.map(|r| r.map(|x| -x * KBAR)));
        f.comment = comment(free + de, free, stress);
        f.step = Some(ctx.frame as i64);
        f.time = md_time(h.ibrion, h.potim, ctx.frame);
    }
    Ok(Step { cut: end.is_none() })
}

// ------------------------------------------------------------------------------------------
// OUTCAR
// ------------------------------------------------------------------------------------------

/// What the header before the first `Iteration` line gives every step.
#[derive(Clone, Debug, Default)]
struct OutcarHeader {
    /// The species and their atom counts, in the atoms' order.
    runs: Vec<(usize, Species)>,
    /// The atom count (the sum of `runs`' counts).
    natoms: usize,
    ibrion: Option<i64>,
    potim: Option<f64>,
    /// The header's last `direct lattice vectors` (rows, Å).
    cell: Option<[[f64; 3]; 3]>,
}

/// The OUTCAR parser; it keeps the header and whether VASP's closing report was met.
#[derive(Default)]
pub(crate) struct Outcar {
    header: Option<OutcarHeader>,
    /// VASP's `General timing and accounting` report was met: the run is whole.
    finished: bool,
}

const FREE_ENERGIE: &[u8] = b"FREE ENERGIE OF THE ION-ELECTRON SYSTEM";

/// A POTCAR's symbol from its `TITEL  = PAW_PBE Fe_pv 02Aug2007` text (after the `=`), as ASE
/// reads the `POTCAR:` lines: the second word (the first for an all-electron `H 1/r
/// potential`), before any `_`, its letters only.
fn titel_symbol(text: &[u8]) -> Option<&[u8]> {
    let words: Vec<&[u8]> = fields(text).collect();
    let contains = |needle: &[u8]| text.windows(needle.len()).any(|w| w == needle);
    let word = if contains(b"1/r potential") {
        words.first()?
    } else {
        words.get(1)?
    };
    let sym = word.split(|b| *b == b'_').next()?;
    let end = sym
        .iter()
        .position(|b| !b.is_ascii_alphabetic())
        .unwrap_or(sym.len());
    let sym = &sym[..end];
    (!sym.is_empty() && sym.len() <= 2).then_some(sym)
}

/// Three numbers at the start of a line of `direct lattice vectors`.
fn lattice_row(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<[f64; 3], Error> {
    const ROW: &str = "a lattice vector row: x y z (Å), then the reciprocal vector";
    let mut f = fields(line);
    let mut v = [0.0; 3];
    for x in &mut v {
        let s = f
            .next()
            .ok_or_else(|| ctx.parse(pos, line, trim(line), ROW))?;
        *x = parse_f64(s)
            .filter(|x| x.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, s, ROW))?;
    }
    Ok(v)
}

/// The three lines after a `direct lattice vectors` line.
fn lattice<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<[[f64; 3]; 3], Error> {
    let mut m = [[0.0; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        let (pos, line) = next(lines, ctx, &|| format!("{} more lattice vectors", 3 - r))?;
        *row = lattice_row(ctx, pos, line)?;
    }
    Ok(m)
}

fn contains(line: &[u8], needle: &[u8]) -> bool {
    memchr::memmem::find(line, needle).is_some()
}

impl FrameWalk for Outcar {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        if ctx.frame == 0 {
            self.header = Some(outcar_header(lines, ctx)?);
        }
        let Some(h) = self.header.as_ref() else {
            let p = lines.pos();
            return Err(ctx.parse(p, b"", b"", "the file's earlier frames, read first"));
        };
        match outcar_step(lines, ctx, h, frame)? {
            Some(()) => Ok(true),
            None => {
                self.finished = true;
                Ok(false)
            }
        }
    }

    fn end(&mut self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        if self.finished {
            return Ok(());
        }
        Err(ctx.truncated(
            at,
            "the next ionic step or VASP's closing 'General timing and accounting' report: \
             VASP did not finish the file"
                .into(),
        ))
    }
}

/// The header, from the banner up to and with the first `Iteration` line.
fn outcar_header<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<OutcarHeader, Error> {
    const BANNER: &str = "VASP's banner on the first line of an OUTCAR (vasp.x.y.z …)";
    const COUNTS: &str = "ions per type = n1 n2 …: one count per POTCAR (TITEL line) before it";
    let mut h = OutcarHeader::default();
    let mut symbols: Vec<Vec<u8>> = Vec::new();
    let mut counts: Option<(Pos, Vec<u8>, Vec<usize>)> = None;
    let mut first = true;
    loop {
        let (pos, line) = next(lines, ctx, &|| {
            "the first electronic iteration ('Iteration'): VASP did not finish the file".into()
        })?;
        let t = trim(line);
        if first {
            if !is_outcar(line) {
                return Err(ctx.parse(pos, line, t, BANNER));
            }
            first = false;
            continue;
        }
        if contains(t, b"Iteration") {
            let Some((cpos, cline, counts)) = counts else {
                return Err(ctx.parse(
                    pos,
                    line,
                    t,
                    "the header's POTCAR TITEL lines and 'ions per type' before the first \
                     electronic iteration",
                ));
            };
            if counts.len() != symbols.len() {
                return Err(ctx.parse(cpos, &cline, trim(&cline), COUNTS));
            }
            h.natoms = counts
                .iter()
                .try_fold(0usize, |a, n| a.checked_add(*n))
                .ok_or_else(|| ctx.parse(cpos, &cline, trim(&cline), COUNTS))?;
            h.runs = counts
                .iter()
                .zip(&symbols)
                .map(|(n, s)| (*n, species(s)))
                .collect();
            return Ok(h);
        }
        if let Some(rest) = t.strip_prefix(b"TITEL") {
            let text = rest.iter().position(|b| *b == b'=').map(|k| &rest[k + 1..]);
            let sym = text.and_then(titel_symbol).ok_or_else(|| {
                ctx.parse(
                    pos,
                    line,
                    t,
                    "a POTCAR title: TITEL = PAW_xx Symbol date (the symbol an element's)",
                )
            })?;
            if Element::from_symbol(std::str::from_utf8(sym).unwrap_or("")).is_none() {
                return Err(ctx.parse(pos, line, sym, "an element's symbol in the POTCAR title"));
            }
            symbols.push(sym.to_vec());
        } else if t.starts_with(b"ions per type") {
            let rest = &t[t.iter().position(|b| *b == b'=').map_or(t.len(), |k| k + 1)..];
            // Counts only: nothing is sized from them (a step's rows are pushed as read).
            let mut v = Vec::new();
            for s in fields(rest) {
                let n = parse_usize(s)
                    .filter(|n| *n > 0 && *n <= 1 << 40)
                    .ok_or_else(|| ctx.parse(pos, line, s, COUNTS))?;
                v.push(n);
            }
            if v.is_empty() {
                return Err(ctx.parse(pos, line, t, COUNTS));
            }
            counts = Some((pos, line.to_vec(), v));
        } else if t.starts_with(b"IBRION =") {
            let v = fields(&t[8..]).next().unwrap_or(b"");
            h.ibrion =
                Some(parse_i64(v).ok_or_else(|| ctx.parse(pos, line, v, "IBRION = an integer"))?);
        } else if t.starts_with(b"POTIM  =") {
            let v = fields(&t[8..]).next().unwrap_or(b"");
            h.potim =
                Some(parse_f64(v).ok_or_else(|| ctx.parse(pos, line, v, "POTIM = a number (fs)"))?);
        } else if contains(t, b"direct lattice vectors") {
            h.cell = Some(lattice(lines, ctx)?);
        }
    }
}

/// One ionic step, up to and with the 4 lines after its `FREE ENERGIE OF THE ION-ELECTRON
/// SYSTEM` line, into `frame` when given; `None` when the run's closing report comes first.
fn outcar_step<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    h: &OutcarHeader,
    frame: Option<&mut Frame>,
) -> Result<Option<()>, Error> {
    const TABLE: &str = "a row of the POSITION / TOTAL-FORCE table: x y z fx fy fz, one per atom";
    const STRESS: &str = "the stress line: in kB XX YY ZZ XY YZ ZX";
    let n = h.natoms;
    let mut cell = None;
    let mut table: Option<(Vec<[f64; 6]>, Pos, Vec<u8>)> = None;
    let mut stress: Option<[f64; 6]> = None;
    let mut timing = false;
    let (epos, eline) = loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            if timing && table.is_none() {
                return Ok(None);
            }
            return Err(ctx.truncated(
                p,
                "the ionic step's energy ('FREE ENERGIE OF THE ION-ELECTRON SYSTEM') or VASP's \
                 closing 'General timing and accounting' report: VASP did not finish the file"
                    .into(),
            ));
        };
        let t = trim(line);
        if contains(t, FREE_ENERGIE) {
            break (pos, line.to_vec());
        }
        if t.starts_with(b"General timing and accounting") {
            timing = true;
        } else if contains(t, b"direct lattice vectors") {
            cell = Some(lattice(lines, ctx)?);
        } else if t.starts_with(b"POSITION") && contains(t, b"TOTAL-FORCE") {
            let (tpos, tline) = (pos, line.to_vec());
            next(lines, ctx, &|| "the POSITION / TOTAL-FORCE table".into())?;
            let mut rows = Vec::with_capacity(n.min(ctx.reserve));
            while rows.len() < n {
                let (pos, line) = next(lines, ctx, &|| {
                    format!(
                        "{} more rows of the POSITION / TOTAL-FORCE table",
                        n - rows.len()
                    )
                })?;
                let mut v = [0.0; 6];
                let mut f = fields(line);
                for x in &mut v {
                    let s = f
                        .next()
                        .ok_or_else(|| ctx.parse(pos, line, trim(line), TABLE))?;
                    *x = parse_f64(s)
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| ctx.parse(pos, line, s, TABLE))?;
                }
                if let Some(s) = f.next() {
                    return Err(ctx.parse(pos, line, s, TABLE));
                }
                rows.push(v);
            }
            table = Some((rows, tpos, tline));
        } else if let Some(k) = memchr::memmem::find(t, b"in kB ") {
            let mut v = [0.0; 6];
            let mut f = fields(&t[k + 6..]);
            for x in &mut v {
                let s = f.next().ok_or_else(|| ctx.parse(pos, line, t, STRESS))?;
                *x = parse_f64(s)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| ctx.parse(pos, line, s, STRESS))?;
            }
            stress = Some(v);
        }
    };
    // The energies: `free  energy   TOTEN  =  x eV` two lines on, `energy  without entropy=
    // y  energy(sigma->0) = z` four lines on (ASE takes their 5th and 7th words).
    let mut energy_line = |word: usize, expected: &'static str| -> Result<f64, Error> {
        next(lines, ctx, &|| "the rest of the step's energies".into())?;
        let (pos, line) = next(lines, ctx, &|| "the rest of the step's energies".into())?;
        let line = line.to_vec();
        if lines.unterminated == Some(pos.line) {
            // A number cut short still parses: the step's last line must be whole.
            return Err(ctx.truncated(
                pos,
                format!(
                    "the rest of line {}: the file ends inside the step's energies",
                    pos.line
                ),
            ));
        }
        let t = trim(&line);
        let w = fields(t)
            .nth(word)
            .ok_or_else(|| ctx.parse(pos, &line, t, expected))?;
        parse_f64(w)
            .filter(|x| x.is_finite())
            .ok_or_else(|| ctx.parse(pos, &line, w, expected))
    };
    let free = energy_line(
        4,
        "free  energy   TOTEN  = x eV, two lines after FREE ENERGIE",
    )?;
    let sigma0 = energy_line(
        6,
        "energy  without entropy= y  energy(sigma->0) = z, four lines after FREE ENERGIE",
    )?;
    let Some((rows, tpos, tline)) = table else {
        return Err(ctx.parse(
            epos,
            &eline,
            trim(&eline),
            "the step's POSITION / TOTAL-FORCE table before its energy",
        ));
    };
    let Some(cell) = cell.or(h.cell) else {
        return Err(ctx.parse(
            epos,
            &eline,
            trim(&eline),
            "a 'direct lattice vectors' block before the step's energy",
        ));
    };
    if let Some(f) = frame {
        let positions = rows.iter().map(|r| [r[0], r[1], r[2]]);
        let species = h.runs.iter().flat_map(|(n, s)| std::iter::repeat_n(*s, *n));
        fill(ctx, tpos, &tline, f, cell, positions, species)?;
        let forces: Vec<[f64; 3]> = rows.iter().map(|r| [r[3], r[4], r[5]]).collect();
        push_forces(f, &forces);
        // VASP's XX YY ZZ XY YZ ZX (kB) as the matrix, ASE's sign.
        let stress = stress.map(|s| {
            let m = [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
            m.map(|r| r.map(|x| -x * KBAR))
        });
        f.comment = comment(sigma0, free, stress);
        f.step = Some(ctx.frame as i64);
        f.time = md_time(h.ibrion, h.potim, ctx.frame);
    }
    Ok(Some(()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_attributes_and_contents() {
        assert_eq!(
            tag(b"<varray name=\"basis\" >"),
            Some((&b"varray"[..], false))
        );
        assert_eq!(tag(b"</calculation>"), Some((&b"calculation"[..], true)));
        assert_eq!(tag(b"<scstep>"), Some((&b"scstep"[..], false)));
        assert_eq!(tag(b"text"), None);
        assert_eq!(
            attr(b"<i type=\"int\" name=\"IBRION\">     0</i>", b"name"),
            Some(&b"IBRION"[..])
        );
        assert_eq!(
            attr(b"<i typename=\"x\" name=\"y\">", b"name"),
            Some(&b"y"[..])
        );
        assert_eq!(attr(b"<v>1 2 3</v>", b"name"), None);
        assert_eq!(content(b"<v>  1 2 3 </v>", b"v"), Some(&b"  1 2 3 "[..]));
        assert_eq!(content(b"<v>  1 2 3 </v", b"v"), None);
        assert_eq!(content(b"<v>  1 2 3", b"v"), None);
        assert_eq!(content(b"<i name=\"x\">1</i>", b"i"), Some(&b"1"[..]));
    }

    #[test]
    fn titel_symbols_as_ase_reads_potcar_lines() {
        let s =
            |t: &str| titel_symbol(t.as_bytes()).map(|s| String::from_utf8_lossy(s).into_owned());
        assert_eq!(s(" PAW_PBE Fe_pv 02Aug2007"), Some("Fe".into()));
        assert_eq!(s(" PAW_PBE H1.25 07Sep2000"), Some("H".into()));
        assert_eq!(s(" PAW_PBE C 08Apr2002"), Some("C".into()));
        assert_eq!(s(" H  1/r potential"), Some("H".into()));
        assert_eq!(s(" PAW_PBE"), None);
    }

    #[test]
    fn sniffing() {
        assert!(is_vasprun(
            b"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n<modeling>\n"
        ));
        assert!(is_vasprun(b"<modeling>\n <generator>\n"));
        assert!(!is_vasprun(b"<?xml version=\"1.0\"?>\n<svg>\n"));
        assert!(is_outcar(
            b" vasp.6.4.1 05Apr23 (build Jan 13 2025) complex\n"
        ));
        assert!(!is_outcar(b" vasp.x\n"));
        assert!(!is_outcar(b"3\nvasp.5\n"));
    }

    #[test]
    fn units_as_ase_has_them() {
        // ASE 3.29: 0.1 * units.GPa, 1e-22 / EVTOJ.
        assert!((KBAR - 6.241_509_125_883_258e-4).abs() < 1e-18);
        assert!((PSTRESS_KBAR - 6.241_506_363_094_028e-4).abs() < 1e-15);
    }
}

//! XYZ and extended XYZ.
//!
//! A frame is an atom-count line, a comment line and one line per atom. Plain XYZ atom lines are
//! `name x y z` (further columns ignored). When the comment line is extended XYZ (key=value pairs
//! as written by ASE, OVITO, QUIP), these keys are used:
//! - `Lattice="ax ay az bx by bz cx cy cz"`: the cell edge vectors (rows), Å;
//! - `pbc="T T F"`: which of them are periodic (T/F, True/False or 1/0, as ASE writes them;
//!   all three without the key) ([`UnitCell::periodic`]: a slab, a cluster in a box);
//! - `Origin="x y z"`: the cell's corner, Å (OVITO writes it);
//! - `Properties=name:type:count:...` with type S (string), R (real), I (integer), L (logical):
//!   the columns of the atom lines. Known names: `species` (→ names and elements), `pos`,
//!   `velo`/`vel`/`velocities` (Å/ps, stored as given), `radius`/`radii`, `color`/`colors`
//!   (R:3, sRGB in [0, 1]), `type` (→ types), `id` (→ ids), `Z` (→ elements); every other real
//!   or integer column of one component (ASE's `masses`, `initial_charges`, `energies`, ...) is
//!   a property of that name ([`Frame::property`]), where `nan` and `inf` (as ASE writes
//!   them) are NaN and infinity; a real or integer column of 2 to 9 components is one property
//!   per component, `fx fy fz` for ASE's `forces:R:3` (the names LAMMPS dumps give forces),
//!   else `NAME[1]` .. `NAME[n]` (`momenta[1]`, as LAMMPS names a vector compute's columns);
//!   the rest (strings, logicals, wider columns) are skipped. Without `Properties` the columns
//!   are `species:S:1:pos:R:3`.
//! - `Time=` (ps) and `step=`/`Step=`/`timestep=` when present.
//!
//! CP2K's comment lines (`i =        0, time =        0.000, E =       -17.1706942181` in an MD
//! run's `-pos-1.xyz`, `-vel-1.xyz` and `-frc-1.xyz`; `i = 3, E = ...` in an optimisation's) are
//! recognised by their first key `i`: it is the step, `time` is in fs (the frame's time is in
//! ps), and `E` (Hartree) stays a comment pair as ASE reads it (`{E}` in a caption). Such a file
//! holds no cell: CP2K writes it to `PROJECT-1.cell` ([`crate::cells::CellTable`]).
//!
//! The comment line stays the frame's [`Frame::comment`], so its other pairs (ASE's `energy=`,
//! `stress="…"`, `config_type=`) are at hand through [`Frame::comment_value`].
//!
//! Elements come from the species by [`crate::elements::guess_element`] (species are normally
//! symbols, so "Ca" and "CA" are calcium).

use crate::elements::{Element, guess_element};
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::lammps::non_finite;
use crate::parse::{
    field_f32, fields, next_field, parse_f32, parse_f64, parse_i64, parse_usize, trim,
};
use crate::text::{Ctx, LineReader, Pos, TextFormat};
use crate::writer::{integer_valued, write_atom_tail};
use std::io::Read;

/// What one atom-line column group holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Col {
    Species,
    Pos,
    Velo,
    Radius,
    Color,
    Type,
    Id,
    Z,
    /// A real or integer column of one component: property `k` of `Xyz::properties`.
    Property(usize),
    Skip(usize),
}

/// The most components a vector column is read as properties with (ASE's widest are 9: a
/// per-atom stress tensor); wider columns are skipped.
const MAX_VECTOR: usize = 9;

/// The property name of component `k` (from 0) of the vector column `name` of `n` components:
/// `fx fy fz` for ASE's `forces:R:3` (the names LAMMPS dumps give forces), else `name[k+1]`
/// (as LAMMPS names a vector compute's columns).
fn component(name: &str, k: usize, n: usize) -> String {
    if name == "forces" && n == 3 {
        ["fx", "fy", "fz"][k].to_string()
    } else {
        format!("{name}[{}]", k + 1)
    }
}

/// The columns [`XyzWriter`] writes for the frame's properties, in order: `(name, first
/// property, components)`: `forces` for `fx fy fz` in a row, `NAME` for `NAME[1]` ..
/// `NAME[n]` in a row (n ≥ 2), else each property alone.
fn property_columns(frame: &Frame) -> Vec<(String, usize, usize)> {
    let props = &frame.properties;
    let mut out = Vec::new();
    let mut k = 0;
    while k < props.len() {
        let name = props[k].name.as_str();
        let forces = props[k..]
            .iter()
            .map(|p| p.name.as_str())
            .take(3)
            .eq(["fx", "fy", "fz"]);
        let run = name.strip_suffix("[1]").map(|base| {
            let n = props[k..]
                .iter()
                .enumerate()
                .take_while(|(j, p)| p.name == format!("{base}[{}]", j + 1))
                .count();
            (base, n)
        });
        let (col, n) = match run {
            _ if forces => ("forces".to_string(), 3),
            Some((base, n)) if n >= 2 => (base.to_string(), n),
            _ => (name.to_string(), 1),
        };
        out.push((col, k, n));
        k += n;
    }
    out
}

/// XYZ frame parser state: the columns of the current frame and a species → element cache.
#[derive(Default)]
pub(crate) struct Xyz {
    cols: Vec<Col>,
    /// The names of the `Col::Property` columns, in column order.
    properties: Vec<String>,
    species: Vec<(Label, Element)>,
}

impl Xyz {
    fn element(&mut self, name: Label) -> Element {
        // Few distinct species per file: a short linear cache beats the name rules per atom.
        if let Some((_, e)) = self.species.iter().find(|(l, _)| *l == name) {
            return *e;
        }
        let e = guess_element(&name, None, None);
        if self.species.len() < 64 {
            self.species.push((name, e));
        }
        e
    }
}

/// A name of 1 to 3 bytes packed with its length into a `u32`; 0 for other lengths.
#[inline(always)]
fn short_key(b: &[u8]) -> u32 {
    match *b {
        [a] => 1 | (a as u32) << 8,
        [a, c] => 2 | (a as u32) << 8 | (c as u32) << 16,
        [a, c, d] => 3 | (a as u32) << 8 | (c as u32) << 16 | (d as u32) << 24,
        _ => 0,
    }
}

/// Splits an extended-XYZ comment into key=value pairs (values may be "double quoted"); any
/// ASCII white space separates them (a frame's comment may hold several lines).
pub(crate) fn key_values(line: &[u8]) -> impl Iterator<Item = (&[u8], &[u8])> {
    let mut i = 0;
    std::iter::from_fn(move || {
        loop {
            while i < line.len() && line[i].is_ascii_whitespace() {
                i += 1;
            }
            if i >= line.len() {
                return None;
            }
            let ks = i;
            while i < line.len() && line[i] != b'=' && !line[i].is_ascii_whitespace() {
                i += 1;
            }
            let key = &line[ks..i];
            // `key = value,` as CP2K writes its comment lines (ASE's parser allows the spaces).
            let mut j = i;
            while j < line.len() && line[j].is_ascii_whitespace() {
                j += 1;
            }
            let spaced = j > i && !key.is_empty() && line.get(j) == Some(&b'=');
            if spaced {
                i = j;
            }
            if i >= line.len() || line[i] != b'=' {
                // A bare word: not a pair.
                if key.is_empty() {
                    i += 1;
                }
                continue;
            }
            i += 1;
            if spaced {
                while i < line.len() && line[i].is_ascii_whitespace() {
                    i += 1;
                }
            }
            let value = if line.get(i) == Some(&b'"') {
                i += 1;
                let vs = i;
                while i < line.len() && line[i] != b'"' {
                    i += 1;
                }
                let v = &line[vs..i];
                i += 1;
                v
            } else {
                let vs = i;
                while i < line.len() && !line[i].is_ascii_whitespace() {
                    i += 1;
                }
                match &line[vs..i] {
                    [v @ .., b','] if spaced => v,
                    v => v,
                }
            };
            return Some((key, value));
        }
    })
}

impl Xyz {
    /// Reads the comment line's keys into `frame` and `self.cols`.
    fn parse_comment(
        &mut self,
        ctx: &Ctx,
        pos: Pos,
        line: &[u8],
        frame: &mut Frame,
    ) -> Result<(), Error> {
        self.cols.clear();
        self.properties.clear();
        let mut periodic = [true; 3];
        let mut origin = None;
        // CP2K's `i = STEP, time = FS, E = HARTREE` (or `i = STEP, E = ...` of an optimisation).
        let mut cp2k = None;
        for (key, value) in key_values(line) {
            if *cp2k.get_or_insert(key == b"i") {
                match key {
                    b"i" => frame.step = parse_i64(value),
                    b"time" => frame.time = parse_f64(value).map(|fs| fs / 1000.0),
                    _ => {}
                }
                continue;
            }
            if key.eq_ignore_ascii_case(b"Lattice") {
                let mut m = [0.0f64; 9];
                let mut k = 0;
                for f in fields(value) {
                    if k == 9 {
                        return Err(ctx.parse(pos, line, value, "9 numbers in Lattice"));
                    }
                    m[k] = parse_f64(f)
                        .ok_or_else(|| ctx.parse(pos, line, f, "a number in Lattice"))?;
                    k += 1;
                }
                if k != 9 {
                    return Err(ctx.parse(pos, line, value, "9 numbers in Lattice"));
                }
                let cell = UnitCell::from_matrix([
                    [m[0], m[1], m[2]],
                    [m[3], m[4], m[5]],
                    [m[6], m[7], m[8]],
                ])
                .map_err(|_| ctx.parse(pos, line, value, "a Lattice with volume > 0"))?;
                frame.cell = Some(cell);
            } else if key.eq_ignore_ascii_case(b"Origin") {
                let v: Vec<Option<f64>> = fields(value).map(parse_f64).collect();
                match v.as_slice() {
                    [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(|v| v.is_finite()) => {
                        origin = Some([*x, *y, *z])
                    }
                    _ => return Err(ctx.parse(pos, line, value, "3 numbers in Origin")),
                }
            } else if key.eq_ignore_ascii_case(b"pbc") {
                let flags: Vec<Option<bool>> = fields(value)
                    .map(|f| match f.to_ascii_lowercase().as_slice() {
                        b"t" | b"true" | b"1" => Some(true),
                        b"f" | b"false" | b"0" => Some(false),
                        _ => None,
                    })
                    .collect();
                match flags.as_slice() {
                    [Some(a), Some(b), Some(c)] => periodic = [*a, *b, *c],
                    _ => return Err(ctx.parse(pos, line, value, "pbc as three of T and F")),
                }
            } else if key.eq_ignore_ascii_case(b"Properties") {
                self.parse_properties(ctx, pos, line, value)?;
            } else if key.eq_ignore_ascii_case(b"Time") {
                frame.time = parse_f64(value);
            } else if key.eq_ignore_ascii_case(b"step") || key.eq_ignore_ascii_case(b"timestep") {
                frame.step = parse_i64(value);
            }
        }
        if let Some(cell) = &mut frame.cell {
            *cell = cell.with_periodic(periodic);
            if let Some(o) = origin {
                *cell = cell.with_origin(o);
            }
        }
        if self.cols.is_empty() {
            self.cols.extend([Col::Species, Col::Pos]);
        }
        Ok(())
    }

    /// The column of property `name`: a new property, or skipped when the name came before.
    fn property_col(&mut self, name: String) -> Col {
        if self.properties.contains(&name) {
            Col::Skip(1)
        } else {
            self.properties.push(name);
            Col::Property(self.properties.len() - 1)
        }
    }

    fn parse_properties(
        &mut self,
        ctx: &Ctx,
        pos: Pos,
        line: &[u8],
        value: &[u8],
    ) -> Result<(), Error> {
        let mut parts = value.split(|b| *b == b':');
        let mut has_pos = false;
        while let Some(name) = parts.next() {
            let (Some(ty), Some(count)) = (parts.next(), parts.next()) else {
                return Err(ctx.parse(pos, line, value, "Properties as name:type:count triples"));
            };
            let count = parse_usize(count)
                .filter(|c| *c >= 1)
                .ok_or_else(|| ctx.parse(pos, line, count, "a column count >= 1 in Properties"))?;
            let real3 = ty == b"R" && count == 3;
            let col = match name {
                b"species" if ty == b"S" && count == 1 => Col::Species,
                b"pos" if real3 => Col::Pos,
                b"velo" | b"vel" | b"velocities" if real3 => Col::Velo,
                b"radius" | b"radii" if ty == b"R" && count == 1 => Col::Radius,
                b"color" | b"colors" | b"Color" if real3 => Col::Color,
                b"type" if count == 1 => Col::Type,
                b"id" if ty == b"I" && count == 1 => Col::Id,
                b"Z" if ty == b"I" && count == 1 => Col::Z,
                _ if (ty == b"R" || ty == b"I") && count == 1 => {
                    self.property_col(String::from_utf8_lossy(name).into_owned())
                }
                _ if (ty == b"R" || ty == b"I") && count <= MAX_VECTOR => {
                    // A vector column: ASE's forces as fx fy fz, any other as name[1]..name[n].
                    let name = String::from_utf8_lossy(name);
                    for k in 0..count - 1 {
                        let col = self.property_col(component(&name, k, count));
                        self.cols.push(col);
                    }
                    self.property_col(component(&name, count - 1, count))
                }
                _ => Col::Skip(count),
            };
            has_pos |= col == Col::Pos;
            self.cols.push(col);
        }
        if !has_pos {
            return Err(ctx.parse(pos, line, value, "a pos:R:3 column in Properties"));
        }
        Ok(())
    }

    /// Parses one atom line by the column list.
    fn atom(&mut self, ctx: &Ctx, pos: Pos, line: &[u8], frame: &mut Frame) -> Result<(), Error> {
        let mut it = fields(line);
        let end = &line[line.len()..];
        for ci in 0..self.cols.len() {
            let col = self.cols[ci];
            match col {
                Col::Species | Col::Type => {
                    let f = it
                        .next()
                        .ok_or_else(|| ctx.parse(pos, line, end, "an atom name"))?;
                    let l = Label::from_utf8(f)
                        .ok_or_else(|| ctx.parse(pos, line, f, "a name of at most 15 bytes"))?;
                    if col == Col::Species {
                        let e = self.element(l);
                        frame.names.push(l);
                        frame.elements.push(e);
                    } else {
                        frame.types.push(l);
                    }
                }
                Col::Pos | Col::Velo | Col::Color => {
                    let mut v = [0f32; 3];
                    for x in &mut v {
                        let f = it.next().unwrap_or(end);
                        *x = parse_f32(f).ok_or_else(|| {
                            ctx.parse(pos, line, f, "3 coordinates after atom name")
                        })?;
                    }
                    match col {
                        Col::Pos => frame.positions.push(v),
                        Col::Velo => frame.velocities.push(v),
                        _ => frame.colors.push(v),
                    }
                }
                Col::Radius => {
                    let f = it.next().unwrap_or(end);
                    let r = parse_f32(f)
                        .filter(|r| *r >= 0.0)
                        .ok_or_else(|| ctx.parse(pos, line, f, "a radius >= 0"))?;
                    frame.radii.push(r);
                }
                Col::Id | Col::Z => {
                    let f = it.next().unwrap_or(end);
                    let v = parse_i64(f).ok_or_else(|| ctx.parse(pos, line, f, "an integer"))?;
                    if col == Col::Id {
                        frame.ids.push(v);
                    } else {
                        let e = u8::try_from(v)
                            .ok()
                            .and_then(Element::from_z)
                            .ok_or_else(|| ctx.parse(pos, line, f, "an atomic number 1..=103"))?;
                        frame.elements.push(e);
                    }
                }
                Col::Property(k) => {
                    let f = it.next().unwrap_or(end);
                    let v = parse_f32(f)
                        .or_else(|| non_finite(f))
                        .ok_or_else(|| ctx.parse(pos, line, f, "a number"))?;
                    if frame.properties.len() == k {
                        frame.properties.push(crate::frame::Property {
                            name: self.properties[k].clone(),
                            values: Vec::new(),
                        });
                    }
                    frame.properties[k].values.push(v);
                }
                Col::Skip(n) => {
                    for _ in 0..n {
                        it.next()
                            .ok_or_else(|| ctx.parse(pos, line, end, "more columns"))?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The plain `name x y z` kernel, the hot loop of most XYZ files. A species seen before is
    /// found by a byte compare in the species cache (no UTF-8 check, no name rules).
    #[inline]
    fn plain_atom(
        &mut self,
        ctx: &Ctx,
        pos: Pos,
        line: &[u8],
        frame: &mut Frame,
    ) -> Result<(), Error> {
        let mut i = 0;
        let f = next_field(line, &mut i);
        if f.is_empty() {
            return Err(ctx.parse(pos, line, f, "an atom name"));
        }
        // Species of up to 3 bytes are compared as one integer (no memcmp call).
        let key = short_key(f);
        let hit = if key != 0 {
            self.species
                .iter()
                .find(|(l, _)| short_key(l.as_bytes()) == key)
        } else {
            self.species.iter().find(|(l, _)| l.as_bytes() == f)
        };
        let (name, e) = match hit {
            Some(&(l, e)) => (l, e),
            None => {
                let l = Label::from_utf8(f)
                    .ok_or_else(|| ctx.parse(pos, line, f, "a name of at most 15 bytes"))?;
                (l, self.element(l))
            }
        };
        let mut v = [0f32; 3];
        for x in &mut v {
            *x = field_f32(line, &mut i)
                .map_err(|f| ctx.parse(pos, line, f, "3 coordinates after atom name"))?;
        }
        frame.names.push(name);
        frame.elements.push(e);
        frame.positions.push(v);
        Ok(())
    }

    fn count<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<Option<usize>, Error> {
        let p0 = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p0, e))? else {
            return Ok(None);
        };
        let t = trim(line);
        let n = parse_usize(fields(t).next().unwrap_or(t))
            .ok_or_else(|| ctx.parse(pos, line, t, "the number of atoms"))?;
        Ok(Some(n))
    }
}

impl TextFormat for Xyz {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        // Atom count line.
        let Some(n) = Xyz::count(lines, ctx)? else {
            return Ok(false);
        };
        // Comment line (extended XYZ keys).
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, "the comment line".into()));
        };
        frame.comment.push_str(&String::from_utf8_lossy(line));
        self.parse_comment(ctx, pos, line, frame)?;
        // Atom lines, with the kernel chosen once per frame.
        frame.positions.reserve(n.min(ctx.reserve));
        let plain = self.cols == [Col::Species, Col::Pos];
        for i in 0..n {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Err(ctx.truncated(p, format!("{} more atom lines", n - i)));
            };
            if plain {
                self.plain_atom(ctx, pos, line, frame)?;
            } else {
                self.atom(ctx, pos, line, frame)?;
            }
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some(n) = Xyz::count(lines, ctx)? else {
            return Ok(false);
        };
        let p = lines.pos();
        let missing = lines.skip_lines(n + 1).map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{} more lines", missing)));
        }
        Ok(true)
    }
}

/// Writes frames as extended XYZ, which plain XYZ readers also read (ASE, OVITO, QUIP and our
/// reader take the columns from `Properties=`).
///
/// The comment line carries `Lattice=` (and `Origin=`, as OVITO writes it, when the corner is
/// not at zero) when the frame has a cell, then `Properties=` with the
/// columns in this order: `species:S:1:pos:R:3`, `id:I:1` when the frame has ids, `type:S:1`
/// when it has types, `velo:R:3`, `radius:R:1`, `color:R:3` when it has velocities, radii,
/// colours, then each of [`Frame::properties`] in order as `NAME:I:1` when every value is an
/// integer below 2^24 in magnitude (written without a decimal point), else `NAME:R:1`, except
/// that `fx fy fz` in a row are ASE's `forces:R:3` and `NAME[1]` .. `NAME[n]` in a row one
/// `NAME:R:n` column, as the reader reads them; then `Time=` and `step=` when known,
/// `pbc="T T F"` (the cell's periodic edges) with a cell, and the frame's comment's other
/// `KEY=value` pairs (an energy, a stress, ASE's `info`), so that a training set for a
/// machine-learned potential keeps its energies.
///
/// The species of an atom is its name, else its element's symbol, else `X`. Numbers are
/// written in Rust's shortest round-trip form, so reading them back gives the same f32 bits; a
/// NaN property value is written `nan` (and makes its column R), infinities `inf` / `-inf`, as
/// ASE writes them.
///
/// [`XyzWriter::check`] refuses what would not read back as written: names or types with white
/// space (they would shift the columns), an empty type, a property whose name is not letters,
/// digits and `_`, is written twice, or is one of the columns above (`species`, `pos`, `id`,
/// `type`, `velo`, `radius`, `color`) or one readers take for another field (`Z`: atomic
/// numbers, `radii`: radii).
pub(crate) struct XyzWriter<W> {
    pub out: W,
}

/// The keys of the frame's comment [`XyzWriter`] writes again after its own (`energy=`,
/// `stress="…"`, `config_type=`: a frame's scalars as ASE writes them): every pair with a value
/// and a key other than those the writer writes or readers take for a field.
pub(crate) fn carried_pairs(frame: &Frame) -> impl Iterator<Item = (&str, &str)> {
    const OWN: [&str; 7] = [
        "Lattice",
        "Origin",
        "Properties",
        "Time",
        "step",
        "timestep",
        "pbc",
    ];
    frame
        .comment_pairs()
        .filter(|(k, v)| !v.is_empty() && !OWN.iter().any(|o| o.eq_ignore_ascii_case(k)))
}

/// The `Properties=` names [`XyzWriter`] writes itself or readers map to another field.
const XYZ_RESERVED: [&str; 9] = [
    "species", "pos", "id", "type", "velo", "radius", "color", "Z", "radii",
];

/// Why property names cannot be written as XYZ columns, if they cannot.
fn check_xyz_properties(frame: &Frame) -> Result<(), String> {
    let columns = property_columns(frame);
    for (k, (name, _, _)) in columns.iter().enumerate() {
        let name = name.as_str();
        if name.is_empty() || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(format!(
                "property '{name}' is not an extended-XYZ column name: letters, digits and _"
            ));
        }
        if XYZ_RESERVED.contains(&name) {
            return Err(format!(
                "property '{name}' has the name of a column extended XYZ gives another meaning \
                 ({})",
                XYZ_RESERVED.join(", ")
            ));
        }
        if columns[..k].iter().any(|q| q.0 == name) {
            return Err(format!("property '{name}' appears twice"));
        }
    }
    Ok(())
}

/// Why a label column cannot be written as white-space separated fields, if it cannot: the
/// first label with white space (or, when `empty_ok` is false, an empty one).
pub(crate) fn check_labels(labels: &[Label], what: &str, empty_ok: bool) -> Result<(), String> {
    for (i, l) in labels.iter().enumerate() {
        if l.bytes().any(|b| b.is_ascii_whitespace()) {
            return Err(format!("atom {i}'s {what} '{l}' contains white space"));
        }
        if !empty_ok && l.is_empty() {
            return Err(format!("atom {i}'s {what} is empty"));
        }
    }
    Ok(())
}

impl<W: std::io::Write> XyzWriter<W> {
    /// Why `frame` cannot be written as XYZ, if it cannot (see [`XyzWriter`]).
    pub fn check(frame: &Frame) -> Result<(), String> {
        check_labels(&frame.names, "name", true)?;
        check_labels(&frame.types, "type", false)?;
        check_xyz_properties(frame)
    }

    /// XYZ has no trailer.
    pub fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()> {
        let w = &mut self.out;
        let n = frame.n_atoms();
        writeln!(w, "{n}")?;
        // Comment line: cell, columns, time and step.
        if let Some(c) = &frame.cell {
            let m = c.matrix();
            write!(
                w,
                "Lattice=\"{} {} {} {} {} {} {} {} {}\" ",
                m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2]
            )?;
            let o = c.origin();
            if o != [0.0; 3] {
                write!(w, "Origin=\"{} {} {}\" ", o[0], o[1], o[2])?;
            }
        }
        write!(w, "Properties=species:S:1:pos:R:3")?;
        if !frame.ids.is_empty() {
            write!(w, ":id:I:1")?;
        }
        if !frame.types.is_empty() {
            write!(w, ":type:S:1")?;
        }
        if !frame.velocities.is_empty() {
            write!(w, ":velo:R:3")?;
        }
        if !frame.radii.is_empty() {
            write!(w, ":radius:R:1")?;
        }
        if !frame.colors.is_empty() {
            write!(w, ":color:R:3")?;
        }
        for (name, k, n) in property_columns(frame) {
            let props = &frame.properties[k..k + n];
            let ty = if props.iter().all(|p| integer_valued(&p.values)) {
                'I'
            } else {
                'R'
            };
            write!(w, ":{name}:{ty}:{n}")?;
        }
        if let Some(t) = frame.time {
            write!(w, " Time={t}")?;
        }
        if let Some(s) = frame.step {
            write!(w, " step={s}")?;
        }
        if let Some(cell) = &frame.cell {
            let [a, b, c] = cell.periodic().map(|p| if p { 'T' } else { 'F' });
            write!(w, " pbc=\"{a} {b} {c}\"")?;
        }
        for (key, value) in carried_pairs(frame) {
            if value.contains([' ', '\t']) {
                write!(w, " {key}=\"{value}\"")?;
            } else {
                write!(w, " {key}={value}")?;
            }
        }
        writeln!(w)?;
        // Atom lines.
        for i in 0..n {
            let name = match (frame.names.get(i), frame.elements.get(i)) {
                (Some(l), _) if !l.is_empty() => l.as_str(),
                (_, Some(e)) => e.symbol(),
                _ => "X",
            };
            let p = frame.positions[i];
            write!(w, "{name} {} {} {}", p[0], p[1], p[2])?;
            if let Some(id) = frame.ids.get(i) {
                write!(w, " {id}")?;
            }
            if let Some(t) = frame.types.get(i) {
                write!(w, " {t}")?;
            }
            write_atom_tail(w, frame, i)?;
        }
        Ok(())
    }
}

//! LAMMPS text dump (`dump atom` / `dump custom`).
//!
//! A frame is a series of `ITEM:` sections ending with `ITEM: ATOMS <columns>` and one line per
//! atom: `UNITS` and `TIME` (optional), `TIMESTEP`, `NUMBER OF ATOMS` (may change from frame to
//! frame), `BOX BOUNDS`, `ATOMS`.
//!
//! Box: `BOX BOUNDS pp pp pp` gives `lo hi` per axis; `BOX BOUNDS xy xz yz pp pp pp` gives
//! the bounds of the triclinic box's bounding box plus the tilt factors, from which the box is
//! recovered as the LAMMPS manual ("Triclinic (non-orthogonal) simulation boxes") documents:
//! `xlo = xlo_bound − min(0, xy, xz, xy+xz)`, `xhi = xhi_bound − max(0, xy, xz, xy+xz)`,
//! `ylo = ylo_bound − min(0, yz)`, `yhi = yhi_bound − max(0, yz)`; edges a = (xhi−xlo, 0, 0),
//! b = (xy, yhi−ylo, 0), c = (xz, yz, zhi−zlo), origin (xlo, ylo, zlo). `BOX BOUNDS abc origin`
//! (general triclinic, LAMMPS 2024+) gives each edge vector followed by one origin component.
//! The three boundary flags that end the line say which edges are periodic: `pp` is, `ff`,
//! `ss`, `fs`, `fm`… (fixed, shrink-wrapped) are not ([`UnitCell::periodic`]).
//!
//! Columns may come in any order. Positions come from the first present of `x y z` (wrapped),
//! `xs ys zs` (scaled), `xu yu zu` (unwrapped), `xsu ysu zsu` (scaled unwrapped); scaled ones
//! become Cartesian as origin + s·M with the frame's box (f64). Also read: `id`, `type`,
//! `element` (→ elements; a name there that is no element symbol, such as a type name `OW`,
//! names the atoms, its element guessed from it, as OVITO reads it as the type's name; without
//! the column elements are guessed from non-numeric types), `vx vy vz`,
//! `radius`, `diameter` (halved), the colour columns below. Every other column (`q`, `mass`,
//! `c_pe`, `v_stress[1]`, `fx`, `ix`, a partial velocity or colour, ...) is a property named by
//! its header ([`Frame::property`]), as OVITO imports it: a number per atom, NaN where LAMMPS
//! writes `nan` or `inf` (drawn grey when coloured by), an error for anything else.
//!
//! # Colour columns
//! Per-atom colours (sRGB in [0, 1], into [`Frame::colors`]) come from the column names OVITO's
//! LAMMPS dump importer maps to its `Color` property by itself: `Color.R Color.G Color.B` or
//! `ColorR ColorG ColorB`, in any letter case (OVITO 3.17 `LAMMPSTextDumpImporter::
//! generateAutomaticColumnMapping` lower-cases the column name and compares it with the standard
//! property name plus component, with and without the dot). OVITO's own dump exporter writes
//! `ColorR ColorG ColorB`. LAMMPS has no colour keyword: a run dumps colours as variables or
//! compute columns and names them with `dump_modify colname`, e.g.
//! `dump_modify d colname v_red ColorR colname v_green ColorG colname v_blue ColorB`.
//! Like OVITO, `c_color[1]`, `v_r`, `red`, `r`… are not colours (checked against OVITO 3.17.2
//! itself: `tests/data/color_reference.json`, `ovito_mapping`).
//!
//! The three columns may sit anywhere in the line, in any order; fewer than three is not a
//! colour and those columns are skipped. Values are stored as written (finite, not clamped, as
//! OVITO keeps them): a value outside [0, 1] is clamped only when a colour is chosen for drawing
//! ([`crate::AtomStyle::resolve`]), so reading then writing a file does not change it.
//!
//! Atoms are returned sorted by `id` when there is an id column (LAMMPS writes them in
//! processor order), as MDAnalysis and chemfiles do.
//!
//! Units: positions are taken as Å (LAMMPS `real` and `metal` units). `TIME` becomes ps and
//! velocities Å/ps when `UNITS` says `metal` or `real` (fs → ps); without `UNITS` velocities are
//! stored as written and the time is left out.

use crate::elements::{Element, guess_element};
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{
    field_f32, field_f64, fields, next_field, parse_f32, parse_f64, parse_i64, parse_usize, trim,
};
use crate::text::{Ctx, LineReader, Pos, TextFormat, need_line};
use std::io::Read;

/// What one atom column is read into (the binary dump reader, src/lammps_bin.rs, shares it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Act {
    Id,
    Type,
    Element,
    Pos(usize),
    Vel(usize),
    Color(usize),
    Radius,
    Diameter,
    /// A named number column: `Frame::properties[k]`.
    Property(usize),
    Skip,
}

/// How the position columns are expressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PosKind {
    Cartesian,
    Scaled,
}

/// The unit style a dump names (`ITEM: UNITS`), as far as it changes what is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Units {
    #[default]
    Unknown,
    Real,
    Metal,
}

impl Units {
    /// The units a unit style's name gives.
    pub(crate) fn from_name(name: &[u8]) -> Units {
        match name {
            b"real" => Units::Real,
            b"metal" => Units::Metal,
            _ => Units::Unknown,
        }
    }

    /// A dump's `TIME` in ps: as written in `metal` (ps), from fs in `real`; none without units.
    pub(crate) fn time_ps(self, time: Option<f64>) -> Option<f64> {
        match (time, self) {
            (Some(t), Units::Metal) => Some(t),
            (Some(t), Units::Real) => Some(t * 1e-3),
            _ => None,
        }
    }

    /// What a velocity is multiplied by to be in Å/ps (Å/fs in `real`).
    pub(crate) fn velocity_scale(self) -> f32 {
        if self == Units::Real { 1000.0 } else { 1.0 }
    }
}

/// The box a dump's header describes (`BOX BOUNDS` and its binary twin).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BoxKind {
    /// `lo hi` per axis.
    Orthogonal,
    /// The bounding box's `lo hi` and a tilt factor per axis (`xy xz yz`).
    Restricted,
    /// Each edge vector followed by one origin component (`abc origin`, LAMMPS 2024+).
    General,
}

/// The cell of a dump's box: per axis `[lo, hi, tilt, _]` (restricted triclinic; tilt 0 when
/// orthogonal) or `[a_k, b_k, c_k, origin_k]` rows (general); `None` for a degenerate box
/// (e.g. a 2-D run with zero thickness).
pub(crate) fn cell_from_bounds(rows: [[f64; 4]; 3], kind: BoxKind) -> Option<UnitCell> {
    let cell = match kind {
        BoxKind::General => {
            // General triclinic: edge vectors and origin components.
            let m = [
                [rows[0][0], rows[0][1], rows[0][2]],
                [rows[1][0], rows[1][1], rows[1][2]],
                [rows[2][0], rows[2][1], rows[2][2]],
            ];
            UnitCell::from_matrix(m).map(|c| c.with_origin([rows[0][3], rows[1][3], rows[2][3]]))
        }
        BoxKind::Orthogonal | BoxKind::Restricted => {
            // Restricted triclinic: remove the tilt from the bounding box (LAMMPS manual).
            let (xy, xz, yz) = if kind == BoxKind::Restricted {
                (rows[0][2], rows[1][2], rows[2][2])
            } else {
                (0.0, 0.0, 0.0)
            };
            let xlo = rows[0][0] - 0f64.min(xy).min(xz).min(xy + xz);
            let xhi = rows[0][1] - 0f64.max(xy).max(xz).max(xy + xz);
            let ylo = rows[1][0] - 0f64.min(yz);
            let yhi = rows[1][1] - 0f64.max(yz);
            let (zlo, zhi) = (rows[2][0], rows[2][1]);
            let m = [
                [xhi - xlo, 0.0, 0.0],
                [xy, yhi - ylo, 0.0],
                [xz, yz, zhi - zlo],
            ];
            UnitCell::from_matrix(m).map(|c| c.with_origin([xlo, ylo, zlo]))
        }
    };
    cell.ok()
}

/// The atoms of a frame put in `id` order (LAMMPS writes them in processor order), with the
/// scratch buffers reused from frame to frame.
#[derive(Default)]
pub(crate) struct IdSort {
    perm: Vec<(i64, u32)>,
    s3: Vec<[f32; 3]>,
    sl: Vec<Label>,
    se: Vec<Element>,
    si: Vec<i64>,
    sf: Vec<f32>,
}

impl IdSort {
    /// Sorts every per-atom vector of `frame` by its ids (nothing to do when they are sorted
    /// or absent).
    pub(crate) fn sort(&mut self, frame: &mut Frame) {
        if frame.ids.is_sorted() {
            return;
        }
        // Unique ids that fill a range (LAMMPS's 1..N) go straight to their slots, O(N); others
        // (a thresholded subset, duplicates) are sorted as (id, index) pairs: the same order.
        self.perm.clear();
        let (lo, hi) = frame
            .ids
            .iter()
            .fold((i64::MAX, i64::MIN), |(lo, hi), &id| {
                (lo.min(id), hi.max(id))
            });
        let n = frame.ids.len();
        if hi
            .checked_sub(lo)
            .is_some_and(|span| span as u64 == n as u64 - 1)
        {
            self.perm.resize(n, (0, u32::MAX));
            let mut unique = true;
            for (k, &id) in frame.ids.iter().enumerate() {
                let slot = &mut self.perm[(id - lo) as usize];
                unique &= slot.1 == u32::MAX;
                *slot = (id, k as u32);
            }
            if !unique {
                self.perm.clear();
            }
        }
        if self.perm.is_empty() {
            self.perm
                .extend(frame.ids.iter().enumerate().map(|(k, id)| (*id, k as u32)));
            self.perm.sort_unstable();
        }
        let perm = &self.perm;
        permute(&mut frame.positions, perm, &mut self.s3);
        permute(&mut frame.velocities, perm, &mut self.s3);
        permute(&mut frame.colors, perm, &mut self.s3);
        permute(&mut frame.types, perm, &mut self.sl);
        permute(&mut frame.elements, perm, &mut self.se);
        permute(&mut frame.names, perm, &mut self.sl);
        permute(&mut frame.radii, perm, &mut self.sf);
        permute(&mut frame.ids, perm, &mut self.si);
        for p in &mut frame.properties {
            permute(&mut p.values, perm, &mut self.sf);
        }
    }
}

/// LAMMPS dump parser state: column actions and the scratch buffers of the sort by id.
#[derive(Default)]
pub(crate) struct Lammps {
    acts: Vec<Act>,
    /// The names of the `Act::Property` columns, in column order.
    properties: Vec<String>,
    units: Units,
    sort: IdSort,
}

/// The colour component (0 = R, 1 = G, 2 = B) an OVITO-style colour column name gives:
/// `Color.R`/`ColorR` … in any letter case (see the module doc).
fn color_component(name: &[u8]) -> Option<usize> {
    let rest = name
        .get(..5)
        .filter(|p| p.eq_ignore_ascii_case(b"color"))
        .map(|_| &name[5..])?;
    let rest = rest.strip_prefix(b".").unwrap_or(rest);
    match rest {
        [c] => b"rgb".iter().position(|k| k.eq_ignore_ascii_case(c)),
        _ => None,
    }
}

/// The periodicity of each axis from the boundary flags ending a `BOX BOUNDS` line: `pp` is
/// periodic; `ff`, `ss`, `fs`, `fm`, … (fixed, shrink-wrapped, shrink-wrapped with a minimum)
/// are not. A line without three flags (dumps older than LAMMPS 2012) is periodic.
fn boundary(spec: &[u8]) -> [bool; 3] {
    let flags: Vec<&[u8]> = fields(spec)
        .filter(|f| f.len() == 2 && f.iter().all(|c| b"pfsm".contains(c)))
        .collect();
    match flags.as_slice() {
        [.., a, b, c] => [*a, *b, *c].map(|f| f == b"pp"),
        _ => [true; 3],
    }
}

/// The value of a field written for a non-finite number (`nan`, `-nan`, `inf`, `-inf`, as
/// LAMMPS, ASE and our writers write them): NaN, or an infinity of the written sign.
pub(crate) fn non_finite(f: &[u8]) -> Option<f32> {
    let neg = f.first() == Some(&b'-');
    let f = f.strip_prefix(b"-").or(f.strip_prefix(b"+")).unwrap_or(f);
    if f.eq_ignore_ascii_case(b"nan") {
        Some(f32::NAN)
    } else if f.eq_ignore_ascii_case(b"inf") || f.eq_ignore_ascii_case(b"infinity") {
        Some(if neg {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        })
    } else {
        None
    }
}

/// Replaces `v` by `v` permuted by `perm` (v'[k] = v[perm[k]]), using `scratch`.
fn permute<T: Copy>(v: &mut Vec<T>, perm: &[(i64, u32)], scratch: &mut Vec<T>) {
    if v.is_empty() {
        return;
    }
    scratch.clear();
    scratch.extend(perm.iter().map(|&(_, i)| v[i as usize]));
    std::mem::swap(v, scratch);
}

/// The header of one frame, up to the ATOMS line.
struct Header {
    n: usize,
    cell: Option<UnitCell>,
    pos_kind: PosKind,
}

impl Lammps {
    fn bounds(ctx: &Ctx, pos: Pos, line: &[u8], n: usize) -> Result<[f64; 4], Error> {
        let mut v = [0f64; 4];
        let mut k = 0;
        for f in fields(line) {
            if k == n {
                break;
            }
            v[k] = parse_f64(f).ok_or_else(|| ctx.parse(pos, line, f, "a box bound"))?;
            k += 1;
        }
        if k < n {
            return Err(ctx.parse(pos, line, line, "the box bounds (lo hi [tilt])"));
        }
        Ok(v)
    }

    fn boxes<R: Read>(
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        kind: BoxKind,
    ) -> Result<Option<UnitCell>, Error> {
        let mut rows = [[0f64; 4]; 3];
        let width = match kind {
            BoxKind::Orthogonal => 2,
            BoxKind::Restricted => 3,
            BoxKind::General => 4,
        };
        for row in &mut rows {
            let (pos, line) = need_line(lines, ctx, "3 box bound lines")?;
            *row = Lammps::bounds(ctx, pos, line, width)?;
        }
        // A degenerate box (e.g. a 2-D run with zero thickness) is reported as no cell.
        Ok(cell_from_bounds(rows, kind))
    }

    /// Reads the ITEM sections up to and including `ITEM: ATOMS`; `None` at a clean end.
    fn header<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<Option<Header>, Error> {
        let mut n = None;
        let mut cell = None;
        let mut time = None;
        let mut first = true;
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if first {
                    return Ok(None);
                }
                return Err(ctx.truncated(p, "ITEM: ATOMS".into()));
            };
            first = false;
            let t = trim(line);
            let Some(item) = t.strip_prefix(b"ITEM:") else {
                return Err(ctx.parse(pos, line, t, "an 'ITEM:' line"));
            };
            let item = trim(item);
            if item == b"TIMESTEP" {
                let (pos, line) = need_line(lines, ctx, "the timestep")?;
                let t = trim(line);
                let step =
                    parse_i64(t).ok_or_else(|| ctx.parse(pos, line, t, "an integer timestep"))?;
                if let Some(f) = frame.as_deref_mut() {
                    f.step = Some(step);
                }
            } else if item == b"TIME" {
                let (pos, line) = need_line(lines, ctx, "the time")?;
                let t = trim(line);
                time = Some(parse_f64(t).ok_or_else(|| ctx.parse(pos, line, t, "a time"))?);
            } else if item == b"UNITS" {
                let (_, line) = need_line(lines, ctx, "the units")?;
                self.units = Units::from_name(trim(line));
            } else if item == b"NUMBER OF ATOMS" {
                let (pos, line) = need_line(lines, ctx, "the number of atoms")?;
                let t = trim(line);
                n = Some(
                    parse_usize(t).ok_or_else(|| ctx.parse(pos, line, t, "the number of atoms"))?,
                );
            } else if let Some(spec) = item.strip_prefix(b"BOX BOUNDS") {
                let kind = match fields(spec).next() {
                    Some(b"abc") => BoxKind::General,
                    Some(b"xy") => BoxKind::Restricted,
                    _ => BoxKind::Orthogonal,
                };
                let periodic = boundary(spec);
                cell = Lammps::boxes(lines, ctx, kind)?.map(|c| c.with_periodic(periodic));
            } else if let Some(spec) = item.strip_prefix(b"ATOMS") {
                let spec = trim(spec);
                let Some(n) = n else {
                    return Err(ctx.parse(
                        pos,
                        line,
                        t,
                        "ITEM: NUMBER OF ATOMS before ITEM: ATOMS",
                    ));
                };
                let pos_kind = self.columns(ctx, pos, line, spec)?;
                if pos_kind == PosKind::Scaled && cell.is_none() {
                    return Err(ctx.parse(pos, line, spec, "a box before scaled coordinates"));
                }
                if let Some(f) = frame.as_deref_mut() {
                    f.cell = cell;
                    f.time = self.units.time_ps(time);
                }
                return Ok(Some(Header { n, cell, pos_kind }));
            } else {
                return Err(ctx.parse(
                    pos,
                    line,
                    t,
                    "ITEM: TIMESTEP, TIME, UNITS, NUMBER OF ATOMS, BOX BOUNDS or ATOMS",
                ));
            }
        }
    }

    /// Maps the ATOMS column names to actions.
    fn columns(&mut self, ctx: &Ctx, pos: Pos, line: &[u8], spec: &[u8]) -> Result<PosKind, Error> {
        plan_columns(spec, &mut self.acts, &mut self.properties).ok_or_else(|| {
            ctx.parse(
                pos,
                line,
                spec,
                "position columns x y z, xs ys zs, xu yu zu or xsu ysu zsu",
            )
        })
    }
}

/// Maps a dump's column names (`spec`, separated by white space) to `acts`, one per column,
/// and names the property columns in `properties`; the positions' kind, or `None` when no set
/// of three position columns is complete.
pub(crate) fn plan_columns(
    spec: &[u8],
    acts: &mut Vec<Act>,
    properties: &mut Vec<String>,
) -> Option<PosKind> {
    acts.clear();
    properties.clear();
    const SETS: [(&[&[u8]; 3], PosKind); 4] = [
        (&[b"x", b"y", b"z"], PosKind::Cartesian),
        (&[b"xs", b"ys", b"zs"], PosKind::Scaled),
        (&[b"xu", b"yu", b"zu"], PosKind::Cartesian),
        (&[b"xsu", b"ysu", b"zsu"], PosKind::Scaled),
    ];
    let &(set, kind) = SETS
        .iter()
        .find(|(set, _)| set.iter().all(|c| fields(spec).any(|n| n == *c)))?;
    for name in fields(spec) {
        let act = match name {
            b"id" => Act::Id,
            b"type" => Act::Type,
            b"element" => Act::Element,
            b"vx" => Act::Vel(0),
            b"vy" => Act::Vel(1),
            b"vz" => Act::Vel(2),
            b"radius" => Act::Radius,
            b"diameter" => Act::Diameter,
            c => match (set.iter().position(|s| *s == c), color_component(c)) {
                (Some(k), _) => Act::Pos(k),
                (None, Some(k)) => Act::Color(k),
                (None, None) => Act::Skip,
            },
        };
        // Only the first column of a kind counts.
        let act = if act != Act::Skip && acts.contains(&act) {
            Act::Skip
        } else {
            act
        };
        acts.push(act);
    }
    // A partial velocity or colour is not one: those columns are properties.
    let vel = (0..3).filter(|k| acts.contains(&Act::Vel(*k))).count();
    let rgb = (0..3).filter(|k| acts.contains(&Act::Color(*k))).count();
    for a in acts.iter_mut() {
        let partial = match a {
            Act::Vel(_) => vel != 3,
            Act::Color(_) => rgb != 3,
            _ => false,
        };
        if partial {
            *a = Act::Skip;
        }
    }
    // Every other column, named once, is a property.
    for (a, name) in acts.iter_mut().zip(fields(spec)) {
        if *a != Act::Skip {
            continue;
        }
        let name = String::from_utf8_lossy(name).into_owned();
        if !properties.contains(&name) {
            *a = Act::Property(properties.len());
            properties.push(name);
        }
    }
    Some(kind)
}

impl TextFormat for Lammps {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        let Some(h) = self.header(lines, ctx, Some(frame))? else {
            return Ok(false);
        };
        let has = |a: Act| self.acts.contains(&a);
        let (has_vel, has_id, has_type) = (has(Act::Vel(0)), has(Act::Id), has(Act::Type));
        let has_el = has(Act::Element);
        let has_color = has(Act::Color(0));
        let vel_scale = self.units.velocity_scale();
        frame.positions.reserve(h.n.min(ctx.reserve));
        for name in &self.properties {
            frame.properties.push(crate::frame::Property {
                name: name.clone(),
                values: Vec::with_capacity(h.n.min(ctx.reserve)),
            });
        }
        // Atom lines: one pass over each line's fields with the column actions.
        for i in 0..h.n {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Err(ctx.truncated(p, format!("{} more atom lines", h.n - i)));
            };
            let mut xyz = [0f64; 3];
            let mut v = [0f32; 3];
            let mut rgb = [0f32; 3];
            let mut at = 0;
            for &act in &self.acts {
                // Coordinates are parsed in place (one pass); other columns as fields.
                if let Act::Pos(k) = act {
                    xyz[k] = if h.pos_kind == PosKind::Scaled {
                        field_f64(line, &mut at)
                    } else {
                        // Cartesian: correctly rounded to f32 once (exact in f64).
                        field_f32(line, &mut at).map(f64::from)
                    }
                    .map_err(|f| {
                        if f.is_empty() {
                            ctx.parse(pos, line, f, "as many values as ITEM: ATOMS columns")
                        } else {
                            ctx.parse(pos, line, f, "a coordinate")
                        }
                    })?;
                    continue;
                }
                let f = next_field(line, &mut at);
                if f.is_empty() {
                    return Err(ctx.parse(pos, line, f, "as many values as ITEM: ATOMS columns"));
                }
                match act {
                    Act::Pos(_) => {}
                    Act::Vel(k) => {
                        v[k] = parse_f32(f)
                            .map(|x| x * vel_scale)
                            .ok_or_else(|| ctx.parse(pos, line, f, "a velocity"))?;
                    }
                    Act::Color(k) => {
                        rgb[k] = parse_f32(f)
                            .ok_or_else(|| ctx.parse(pos, line, f, "a finite colour component"))?;
                    }
                    Act::Id => {
                        let id = parse_i64(f)
                            .ok_or_else(|| ctx.parse(pos, line, f, "an integer atom id"))?;
                        frame.ids.push(id);
                    }
                    Act::Type => {
                        let l = Label::from_utf8(f)
                            .ok_or_else(|| ctx.parse(pos, line, f, "a type of at most 15 bytes"))?;
                        frame.types.push(l);
                    }
                    Act::Element => {
                        let label = Label::from_utf8(f).ok_or_else(|| {
                            ctx.parse(pos, line, f, "an element or type name of at most 15 bytes")
                        })?;
                        match Element::from_symbol(label.as_str()) {
                            Some(e) if frame.names.is_empty() => frame.elements.push(e),
                            known => {
                                // A name that is no element symbol (a type name such as OW, as
                                // OVITO reads the column): the atoms' names from here on, the
                                // element guessed from it; the atoms before are named by their
                                // symbols.
                                if frame.names.is_empty() {
                                    let before = frame.elements.iter().map(|e| {
                                        Label::new(e.symbol()).expect("a symbol is short")
                                    });
                                    frame.names.extend(before);
                                }
                                let e = known
                                    .unwrap_or_else(|| guess_element(label.as_str(), None, None));
                                frame.elements.push(e);
                                frame.names.push(label);
                            }
                        }
                    }
                    Act::Radius | Act::Diameter => {
                        let r = parse_f32(f)
                            .filter(|r| *r >= 0.0)
                            .ok_or_else(|| ctx.parse(pos, line, f, "a radius >= 0"))?;
                        frame
                            .radii
                            .push(if act == Act::Diameter { r * 0.5 } else { r });
                    }
                    Act::Property(k) => {
                        let v = parse_f32(f)
                            .or_else(|| non_finite(f))
                            .ok_or_else(|| ctx.parse(pos, line, f, "a number"))?;
                        frame.properties[k].values.push(v);
                    }
                    Act::Skip => {}
                }
            }
            // Scaled → Cartesian with the frame's box.
            let p = match (h.pos_kind, &h.cell) {
                (PosKind::Scaled, Some(c)) => c.to_cartesian(xyz),
                _ => xyz,
            };
            let p = [p[0] as f32, p[1] as f32, p[2] as f32];
            if p.iter().any(|x| !x.is_finite()) {
                return Err(ctx.parse(pos, line, line, "coordinates within f32 range"));
            }
            frame.positions.push(p);
            if has_vel {
                frame.velocities.push(v);
            }
            if has_color {
                frame.colors.push(rgb);
            }
        }
        // Elements from non-numeric types when there is no element column.
        if !has_el
            && has_type
            && frame
                .types
                .iter()
                .any(|t| parse_i64(t.as_bytes()).is_none())
        {
            for t in &frame.types {
                frame.elements.push(guess_element(t, None, None));
            }
        }
        // Sort atoms by id (processor order → id order).
        if has_id {
            self.sort.sort(frame);
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some(h) = self.header(lines, ctx, None)? else {
            return Ok(false);
        };
        let p = lines.pos();
        let missing = lines.skip_lines(h.n).map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{missing} more atom lines")));
        }
        Ok(true)
    }
}

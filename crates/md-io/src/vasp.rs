//! VASP structures and trajectories: POSCAR / CONTCAR (one structure) and XDATCAR (the ionic
//! steps of an MD run, VASP 5 and later).
//!
//! # What is read
//! A header, then coordinates:
//! 1. a comment line (the frame's comment; VASP writes the system name);
//! 2. the scaling factor: one number (a negative one is the cell volume in Å³, the lattice scaled
//!    to it), or three (VASP 6: one factor per Cartesian axis);
//! 3. three lattice vectors, one per line, scaled by the factor: the cell. VASP refuses a
//!    left-handed set of vectors and so does this reader;
//! 4. the species names (VASP 5 and later: `Fe O`, or POTCAR labels such as `Fe_pv` and
//!    `Fe_pv/6a2f546d`, whose element is the part before `_` or `/`), then the number of atoms
//!    of each species. A VASP 4 file has no names line: the species are then the comment's first
//!    words when they are element symbols (ASE's convention), else unknown elements typed `1`,
//!    `2`, … in order;
//! 5. an optional `Selective dynamics` line (first letter `S`); the per-atom `T`/`F` flags after
//!    the coordinates are constraints for VASP's optimiser and are not kept;
//! 6. the coordinate line: first letter `C` or `K` for Cartesian (Å, times the scaling factor),
//!    anything else Direct (fractions of the lattice vectors). In an XDATCAR it reads
//!    `Direct configuration=  N`: N is the frame's step;
//! 7. one line per atom, species by species: three numbers (anything after them, such as the
//!    selective-dynamics flags or a species comment, is read past).
//!
//! Atom names are the species' element symbols (the species label when it is not one), types
//! the species labels as written; ids count from 1.
//!
//! **XDATCAR:** every further frame is a configuration line and its coordinates, under the same
//! header (a fixed cell); a run with a changing cell (`ISIF=3`) repeats the whole header before
//! each configuration, and those frames take their own. VASP 4's XDATCAR layout is not read.
//!
//! **POSCAR / CONTCAR** hold one frame. After the coordinates a CONTCAR of an MD run may hold
//! the lattice velocities (a `Lattice velocities and vectors` block, read past), then a blank or
//! `Cartesian`/`Direct` line and one velocity per atom in Å/fs (Direct: lattice vectors per fs),
//! kept as [`Frame::velocities`] in Å/ps. Whatever follows (the predictor-corrector block VASP
//! writes for a restart) is not read.
//!
//! **Volumetric files** (CHGCAR, CHG, PARCHG, LOCPOT, ELFCAR, AECCAR*: a blank line and a
//! grid line `NGX NGY NGZ` after the coordinates) are one frame, the structure: their grids are
//! walked (values parsed when the frame is read, counted by a scan) so that a damaged or cut
//! grid is an error for that frame. [`crate::volume::read_volumes`] reads their values.
//!
//! Files are recognised by name (`POSCAR`, `CONTCAR`, `XDATCAR`, with any suffix such as
//! `POSCAR_relaxed` or `CONTCAR.2`; extensions `.vasp`, `.poscar`; the volumetric names) or by
//! the header's shape.
//!
//! # Damage
//! Errors name the file, frame, line and byte: a scaling factor that is zero or not one or three
//! numbers, a lattice line without three numbers, lattice vectors that are not a right-handed
//! cell, a species count that is not a positive integer or does not match the names, a
//! configuration line with no header before it, a coordinate or velocity that is not a number, a
//! missing line (a cut file). Nothing is sized from a count in the file.
//!
//! # References
//! - VASP wiki, "POSCAR" and "XDATCAR" (file layout, scaling factor, selective dynamics,
//!   velocities).
//! - ASE `ase.io.vasp` (the VASP 4 species convention).

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::{field_f64, fields, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, LineReader, TextFormat, need_line};
use std::io::Read;
use std::sync::Arc;

/// Å/fs → Å/ps.
const PS_PER_FS: f64 = 1000.0;

/// One header: the cell and the species.
#[derive(Clone, Debug)]
struct Header {
    comment: String,
    /// Lattice vectors (rows, Å), scaled.
    lattice: [[f64; 3]; 3],
    /// The factor per Cartesian axis applied to Cartesian coordinates.
    scale: [f64; 3],
    cell: UnitCell,
    /// Per species: its type label, atom name and element.
    species: Vec<(Label, Label, Element)>,
    /// Atoms per species.
    counts: Vec<usize>,
    /// Total atoms.
    n: usize,
}

/// How a frame's coordinates are written.
#[derive(Clone, Copy, Debug)]
struct Mode {
    cartesian: bool,
    /// True in an XDATCAR (a configuration line); false in a POSCAR / CONTCAR.
    configuration: bool,
    step: Option<i64>,
}

/// The VASP parser. Headers are kept for the configuration-only frames of an XDATCAR: `latest`
/// is the last header parsed (with its frame), `used` the headers configuration-only frames were
/// read under, so that random access back to such a frame finds its own header even after later
/// headers were parsed (a file with a changing cell).
#[derive(Default)]
pub(crate) struct Vasp {
    latest: Option<(usize, Arc<Header>)>,
    used: Vec<(usize, Arc<Header>)>,
}

/// True for an XDATCAR configuration line (`Direct configuration=     7`).
fn is_configuration(line: &[u8]) -> bool {
    let t = trim(line);
    t.len() >= 13
        && t.windows(13)
            .any(|w| w.eq_ignore_ascii_case(b"configuration"))
}

/// Whether a coordinate-mode line names Cartesian coordinates.
fn is_cartesian(line: &[u8]) -> bool {
    matches!(trim(line).first(), Some(b'C' | b'c' | b'K' | b'k'))
}

/// The step of a configuration line: the integer after `=`, if any.
fn configuration_step(line: &[u8]) -> Option<i64> {
    let eq = line.iter().position(|b| *b == b'=')?;
    parse_i64(fields(&line[eq + 1..]).next()?)
}

/// A species label's element: the part before `_` or `/` (`Fe_pv/6a2f546d` → Fe).
fn species_element(label: &[u8]) -> Option<Element> {
    let end = label
        .iter()
        .position(|b| *b == b'_' || *b == b'/')
        .unwrap_or(label.len());
    Element::from_symbol(std::str::from_utf8(&label[..end]).ok()?)
}

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Three numbers from the start of `line` (anything after them is read past).
fn three(line: &[u8]) -> Result<[f64; 3], &[u8]> {
    let mut i = 0;
    let mut v = [0f64; 3];
    for x in &mut v {
        *x = field_f64(line, &mut i)?;
    }
    Ok(v)
}

impl Vasp {
    /// Parses a header whose comment line `first` was read already.
    fn header<R: Read>(
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        first: &[u8],
    ) -> Result<Header, Error> {
        let comment = String::from_utf8_lossy(trim(first)).into_owned();
        // Scaling factor: one or three numbers.
        let (pos, line) = need_line(lines, ctx, "the scaling factor line")?;
        let mut s = [0f64; 3];
        let mut k = 0;
        for f in fields(line) {
            match parse_f64(f) {
                Some(v) if k < 3 => {
                    s[k] = v;
                    k += 1;
                }
                Some(_) => return Err(ctx.parse(pos, line, f, "one or three scaling factors")),
                None => break,
            }
        }
        if k == 2 || k == 0 {
            return Err(ctx.parse(pos, line, trim(line), "one or three scaling factors"));
        }
        let bad_scale = if k == 1 {
            s[0] == 0.0
        } else {
            s.iter().any(|v| *v <= 0.0)
        };
        if bad_scale {
            return Err(ctx.parse(
                pos,
                line,
                trim(line),
                "a non-zero scaling factor (or three positive ones)",
            ));
        }
        // Lattice vectors.
        let mut lattice = [[0f64; 3]; 3];
        let mut lattice_at = (pos, Vec::new());
        for (r, row) in lattice.iter_mut().enumerate() {
            let (pos, line) =
                need_line(lines, ctx, &format!("{} more lattice vector lines", 3 - r))?;
            *row = three(line).map_err(|f| ctx.parse(pos, line, f, "3 lattice vector numbers"))?;
            if r == 0 {
                lattice_at = (pos, line.to_vec());
            }
        }
        let scale = if k == 1 && s[0] < 0.0 {
            // A negative factor is the volume.
            let det = det3(&lattice).abs();
            let f = (-s[0] / det).cbrt();
            if !(f.is_finite() && f > 0.0) {
                let (p, l) = &lattice_at;
                return Err(ctx.parse(*p, l, trim(l), "lattice vectors with a volume > 0"));
            }
            [f; 3]
        } else if k == 1 {
            [s[0]; 3]
        } else {
            s
        };
        for row in &mut lattice {
            for (x, f) in row.iter_mut().zip(scale) {
                *x *= f;
            }
        }
        let cell = UnitCell::from_matrix(lattice).map_err(|_| {
            let (p, l) = &lattice_at;
            ctx.parse(
                *p,
                l,
                trim(l),
                "lattice vectors of a right-handed cell with volume > 0 (VASP refuses others), at most 1e7 Å long",
            )
        })?;
        // Species names (VASP 5+), then counts; VASP 4 has the counts only.
        let (pos, line) = need_line(lines, ctx, "the species names or counts line")?;
        let vasp4 = fields(line)
            .next()
            .is_some_and(|f| parse_usize(f).is_some());
        let mut names: Vec<Vec<u8>> = Vec::new();
        let (pos, line) = if vasp4 {
            (pos, line)
        } else {
            names = fields(line).map(<[u8]>::to_vec).collect();
            if names.is_empty() {
                return Err(ctx.parse(pos, line, line, "the species names"));
            }
            need_line(lines, ctx, "the species counts line")?
        };
        let mut counts = Vec::new();
        let mut n = 0usize;
        for f in fields(line) {
            // A `!` starts a comment.
            if f.starts_with(b"!") {
                break;
            }
            let c = parse_usize(f)
                .filter(|c| *c > 0)
                .ok_or_else(|| ctx.parse(pos, line, f, "a positive number of atoms per species"))?;
            n = n
                .checked_add(c)
                .ok_or_else(|| ctx.parse(pos, line, f, "an atom count that fits in memory"))?;
            counts.push(c);
        }
        if counts.is_empty() || (!vasp4 && counts.len() != names.len()) {
            return Err(ctx.parse(
                pos,
                line,
                trim(line),
                "one positive atom count per species name",
            ));
        }
        if vasp4 {
            // ASE's convention: element symbols on the comment line.
            let words: Vec<&[u8]> = fields(first).take(counts.len()).collect();
            if words.len() == counts.len() && words.iter().all(|w| species_element(w).is_some()) {
                names = words.into_iter().map(<[u8]>::to_vec).collect();
            } else {
                names = (1..=counts.len())
                    .map(|k| k.to_string().into_bytes())
                    .collect();
            }
        }
        let species = names
            .iter()
            .map(|name| {
                let label_end = name.iter().position(|b| *b == b'/').unwrap_or(name.len());
                let label = &name[..label_end];
                let ty = Label::from_utf8(label).ok_or_else(|| {
                    ctx.parse(pos, line, trim(line), "species labels of at most 15 bytes")
                })?;
                let element = species_element(label).unwrap_or(Element::UNKNOWN);
                let atom = if element.is_unknown() {
                    ty
                } else {
                    Label::new(element.symbol()).unwrap_or(ty)
                };
                Ok((ty, atom, element))
            })
            .collect::<Result<Vec<_>, Error>>()?;
        Ok(Header {
            comment,
            lattice,
            scale,
            cell,
            species,
            counts,
            n,
        })
    }

    /// Reads a frame's start: its header (or the kept one for a configuration-only frame) and
    /// its coordinate mode. `None` at the end of the data.
    fn start<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
    ) -> Result<Option<(Arc<Header>, Mode)>, Error> {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(None);
        };
        if is_configuration(line) {
            let mode = Mode {
                cartesian: is_cartesian(line),
                configuration: true,
                step: configuration_step(line),
            };
            let header = self.header_for(ctx.frame).ok_or_else(|| {
                ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "a header (comment, scaling factor, lattice, species, counts) before the first configuration",
                )
            })?;
            return Ok(Some((header, mode)));
        }
        let first = line.to_vec();
        let header = Arc::new(Vasp::header(lines, ctx, &first)?);
        let (pos, mut line) =
            need_line(lines, ctx, "the coordinate mode line (Direct or Cartesian)")?;
        let mut at = pos;
        if matches!(trim(line).first(), Some(b'S' | b's')) {
            (at, line) = need_line(lines, ctx, "the coordinate mode line (Direct or Cartesian)")?;
        }
        if trim(line).is_empty() {
            return Err(ctx.parse(
                at,
                line,
                line,
                "the coordinate mode line (Direct or Cartesian)",
            ));
        }
        let mode = Mode {
            cartesian: is_cartesian(line),
            configuration: is_configuration(line),
            step: configuration_step(line).filter(|_| is_configuration(line)),
        };
        self.latest = Some((ctx.frame, header.clone()));
        Ok(Some((header, mode)))
    }

    /// The header a configuration-only frame `k` is written under: the last header of a frame
    /// before it, found among those earlier such frames used and the latest parsed.
    fn header_for(&mut self, k: usize) -> Option<Arc<Header>> {
        let used = self.used.iter().rev().find(|(j, _)| *j < k).cloned();
        let latest = self.latest.clone().filter(|(j, _)| *j < k);
        let (j, h) = match (used, latest) {
            (Some(u), Some(l)) => {
                if l.0 > u.0 {
                    l
                } else {
                    u
                }
            }
            (Some(u), None) => u,
            (None, Some(l)) => l,
            (None, None) => return None,
        };
        if !self.used.iter().any(|(i, _)| *i == j) {
            let at = self.used.partition_point(|(i, _)| *i < j);
            self.used.insert(at, (j, h.clone()));
        }
        Some(h)
    }

    /// Reads past everything after a POSCAR's coordinates: its frame is the whole file.
    fn rest<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<(), Error> {
        loop {
            let p = lines.pos();
            if lines.next_line().map_err(|e| ctx.io(p, e))?.is_none() {
                return Ok(());
            }
        }
    }

    /// A CONTCAR's velocities, if it has them (see the module docs), into `frame`; without a
    /// frame (a scan), the same lines are walked and only the first is parsed (it tells
    /// whether velocities follow), so that a cut inside them is found by a scan too.
    fn velocities<R: Read>(
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        h: &Header,
        mut frame: Option<&mut Frame>,
    ) -> Result<(), Error> {
        // The line after the coordinates: its first letter, or None when it is blank.
        let kind = |l: &[u8]| trim(l).first().map(u8::to_ascii_lowercase);
        let p = lines.pos();
        let Some((_, sep)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(());
        };
        let mut sep = kind(sep);
        if sep == Some(b'l') {
            // Lattice velocities and vectors: the initialisation line, 3 velocities, 3 vectors.
            for k in 0..7 {
                need_line(
                    lines,
                    ctx,
                    &format!("{} more lattice velocity lines", 7 - k),
                )?;
            }
            let p = lines.pos();
            match lines.next_line().map_err(|e| ctx.io(p, e))? {
                Some((_, l)) => sep = kind(l),
                None => return Ok(()),
            }
        }
        if sep.is_none() {
            // A volumetric file (CHGCAR, LOCPOT, …): a blank line, then a grid line. Its grids
            // are walked, values parsed when reading (counted by a scan).
            let p = lines.pos();
            if let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? {
                if let Some(dims) = crate::chgcar::grid_dims(line) {
                    let budget = crate::volume::Budget::unknown();
                    crate::chgcar::check_dims(ctx, pos, line, dims, &budget)?;
                    let walk = crate::chgcar::Walk {
                        dims,
                        n_atoms: h.n,
                        scale: 1.0,
                        parse: frame.is_some(),
                    };
                    return walk.grids(lines, ctx, &budget, None);
                }
                lines.unread(pos);
            }
        }
        let direct = sep == Some(b'd');
        let known = matches!(sep, None | Some(b'd' | b'c' | b'k'));
        if let Some(f) = frame.as_deref_mut() {
            f.velocities.reserve(h.n.min(ctx.reserve));
        }
        for i in 0..h.n {
            let (pos, line) = if i == 0 {
                // The first velocity line: three numbers, else no velocities are written.
                let p = lines.pos();
                match lines.next_line().map_err(|e| ctx.io(p, e))? {
                    Some((pos, line)) if known && three(line).is_ok() => (pos, line),
                    _ => return Ok(()),
                }
            } else {
                need_line(lines, ctx, &format!("{} more velocity lines", h.n - i))?
            };
            let Some(f) = frame.as_deref_mut() else {
                continue;
            };
            let v =
                three(line).map_err(|t| ctx.parse(pos, line, t, "3 velocity numbers (Å/fs)"))?;
            let v = if direct {
                frac_to_cartesian(&h.lattice, v)
            } else {
                v
            };
            let v = v.map(|x| (x * PS_PER_FS) as f32);
            if v.iter().any(|x| !x.is_finite()) {
                return Err(ctx.parse(pos, line, trim(line), "a velocity within f32 range"));
            }
            f.velocities.push(v);
        }
        Ok(())
    }
}

fn frac_to_cartesian(m: &[[f64; 3]; 3], f: [f64; 3]) -> [f64; 3] {
    let mut out = [0f64; 3];
    for (k, o) in out.iter_mut().enumerate() {
        *o = f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k];
    }
    out
}

impl Vasp {
    /// Reads a frame's header (or the kept one) and its coordinates into `frame`, nothing after
    /// them; `None` at the end of the data.
    fn structure<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<Option<(Arc<Header>, Mode)>, Error> {
        let Some((h, mode)) = self.start(lines, ctx)? else {
            return Ok(None);
        };
        frame.comment.push_str(&h.comment);
        frame.cell = Some(h.cell);
        frame.step = mode.step;
        let n = h.n.min(ctx.reserve);
        frame.positions.reserve(n);
        frame.names.reserve(n);
        frame.types.reserve(n);
        frame.elements.reserve(n);
        frame.ids.reserve(n);
        let mut i = 0usize;
        for (s, &count) in h.counts.iter().enumerate() {
            let (ty, name, element) = h.species[s];
            for _ in 0..count {
                let (pos, line) =
                    need_line(lines, ctx, &format!("{} more coordinate lines", h.n - i))?;
                let v = three(line).map_err(|f| {
                    ctx.parse(
                        pos,
                        line,
                        f,
                        "3 coordinates (Direct: fractions; Cartesian: Å)",
                    )
                })?;
                let x = if mode.cartesian {
                    [v[0] * h.scale[0], v[1] * h.scale[1], v[2] * h.scale[2]]
                } else {
                    frac_to_cartesian(&h.lattice, v)
                };
                frame.positions.push(x.map(|c| c as f32));
                frame.names.push(name);
                frame.types.push(ty);
                frame.elements.push(element);
                i += 1;
                frame.ids.push(i as i64);
            }
        }
        Ok(Some((h, mode)))
    }
}

/// Reads one POSCAR block (header and coordinates, nothing after them) into `frame`, cleared
/// by the caller: the structure of a VASP volumetric file. False at the end of the data.
pub(crate) fn read_structure<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    frame: &mut Frame,
) -> Result<bool, Error> {
    Ok(Vasp::default().structure(lines, ctx, frame)?.is_some())
}

impl TextFormat for Vasp {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        let Some((h, mode)) = self.structure(lines, ctx, frame)? else {
            return Ok(false);
        };
        if !mode.configuration {
            Vasp::velocities(lines, ctx, &h, Some(frame))?;
            Vasp::rest(lines, ctx)?;
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some((h, mode)) = self.start(lines, ctx)? else {
            return Ok(false);
        };
        let p = lines.pos();
        let missing = lines.skip_lines(h.n).map_err(|e| ctx.io(p, e))?;
        if missing > 0 {
            return Err(ctx.truncated(lines.pos(), format!("{missing} more coordinate lines")));
        }
        if !mode.configuration {
            Vasp::velocities(lines, ctx, &h, None)?;
            Vasp::rest(lines, ctx)?;
        }
        Ok(true)
    }
}

//! Quantum ESPRESSO pw.x files: the output of a run (`Format::EspressoOut`: `.pwo`, or an
//! `.out` whose first lines hold pw.x's `Program PWSCF` banner), every ionic step of an `scf`,
//! `relax`, `vc-relax`, `md` or `vc-md` run a frame, and the input (`Format::EspressoIn`:
//! `.pwi`, or an `.in` whose first line that is not blank or a comment opens the `&CONTROL` or
//! `&SYSTEM` namelist), one frame.
//!
//! # The output: which steps are frames
//! A *configuration* is a run's starting geometry (the header after the banner) or an
//! `ATOMIC_POSITIONS` block (with the `CELL_PARAMETERS` block before it in a variable-cell run,
//! and in molecular dynamics the `Entering Dynamics` lines before both, which give the time). A
//! configuration is a frame when *results* follow it before the next configuration: the
//! `!    total energy` line, `Forces acting on atoms`, `total   stress`, `Magnetic moment per
//! site`, `End of self-consistent calculation` or `End of band structure calculation`. That is
//! ASE's rule (`ase.io.read(path, index=':')`, `read_espresso_out` with `results_required`),
//! and the frames are the same:
//! - `scf`: one frame, the header's geometry;
//! - `relax`: the header's geometry and each BFGS step's positions; the positions between
//!   `Begin final coordinates` and `End final coordinates` repeat the last step's and have no
//!   results of their own: not a frame;
//! - `vc-relax`: the same, but pw.x then runs a final scf at the relaxed structure with the
//!   G-vectors of the final cell (`Final scf calculation at the relaxed structure`): the final
//!   coordinates have results and are a frame, the last, with the geometry of the one before it
//!   and that scf's energy, forces and stress (so 6 BFGS steps give 8 frames);
//! - `md`, `vc-md`: the header's geometry and each step's, except the positions pw.x prints
//!   after its last step, which it computes no results for.
//!
//! Several runs in one file (outputs concatenated) are read one after another: each banner
//! starts a run with its own header. Lines are matched at their start, where pw.x writes them
//! (the blocks at column 0, the rest after indentation); ASE finds its markers anywhere in a
//! line, and so takes pw.x's message about a card without units (`DEPRECATED: no units
//! specified in ATOMIC_POSITIONS card`) for a positions block and fails.
//!
//! # What a frame holds
//! - Positions (Å) from the header's `site n. ... positions (alat units)` table times
//!   `celldm(1)` (the lattice parameter alat, printed with more digits than `lattice parameter
//!   (alat)`), or from an `ATOMIC_POSITIONS` block in its units: `alat` (times the
//!   `CELL_PARAMETERS (alat= …)` value when the block has one, else celldm(1)), `bohr`,
//!   `angstrom`, `crystal` (fractions of the frame's cell). With `ibrav` ≠ 0 the header still
//!   prints Cartesian positions and the cell vectors (`crystal axes`), so every lattice reads
//!   alike. `if_pos` flags after the coordinates are read past.
//! - The cell: the step's `CELL_PARAMETERS` block (`alat= …`, `bohr` or `angstrom`), else the
//!   run header's crystal axes (ASE's rule), periodic along all three vectors. A left-handed
//!   set of vectors, which pw.x accepts, is an error (a [`UnitCell`] is right-handed).
//! - Names: the species labels (`Fe1`, `O_u`); elements from the header's species table (the
//!   element each label's pseudopotential is for), else from the label as ASE reads one (the
//!   first two letters if they are a symbol, else the first: `Fe1` iron, `O_u` oxygen), else
//!   unknown.
//! - Forces from `Forces acting on atoms (cartesian axes, Ry/au)` as the properties `fx fy fz`
//!   in eV/Å (the names a LAMMPS dump's force columns have: `--arrows f` draws them).
//! - Magnetic moments of a spin-polarised run (`nspin = 2`) from `Magnetic moment per site` as
//!   the property `magmom` (μB; the name the ASE .traj reader gives them): the `magn:` column
//!   of pw.x 6.7's lines (`atom:    1    charge:    6.2918    magn:    3.3015    constr:
//!   0.0000`), or `magn=` of later versions' (`atom      1 (R=0.190)  charge=  6.3520  magn=
//!   2.2160`). pw.x prints a block after each step's scf (and every `report` iterations when
//!   asked): the step's last block is its moments. ASE 3.29 takes each line's last field, in
//!   6.7's format the constraint (`constr:`), so its moments of these files are all 0. An
//!   input's `starting_magnetization(i)` is a starting guess, not a moment: not read.
//! - The energy (`!    total energy`, the first of the step, as ASE takes it) in eV and the
//!   stress (`total   stress`, its Ry/bohr³ columns) in eV/Å³ with ASE's sign (the negative
//!   of pw.x's), in the frame's comment as extended XYZ writes them: `energy=-212.3134
//!   stress="sxx sxy sxz syx syy syz szx szy szz"`, so `--label '{title}'` shows them.
//! - [`Frame::step`]: the configuration's number in its run (0 the header's, k the k-th
//!   `ATOMIC_POSITIONS`: in molecular dynamics the iteration pw.x prints); [`Frame::time`]
//!   (ps) in molecular dynamics, as pw.x prints it with `Entering Dynamics` (`time = …
//!   pico-seconds`): md prints the time after the step, and its starting geometry (followed by
//!   `Molecular Dynamics Calculation`) is at 0; vc-md prints the time before the step's move,
//!   and its starting geometry has none.
//!
//! # The input
//! Namelists (`&CONTROL`, `&SYSTEM`, … closed by `/`; `key = value` pairs separated by commas
//! or line ends, `!` comments, quoted strings, reals with a Fortran exponent such as `1.0d-8`)
//! then cards. From `&SYSTEM`: `ibrav`, `celldm(1..6)` (celldm(1) in bohr; b/a, c/a and
//! cosines) or `A`, `B`, `C` (Å) with `cosAB`, `cosAC`, `cosBC`, `nat`, `ntyp`. Cards: `ATOMIC_SPECIES` (ntyp lines: label, mass, pseudopotential file; the
//! element from the label as above, else from the file's name, `Fe.pbe-….UPF`),
//! `ATOMIC_POSITIONS` (nat lines in alat, bohr, angstrom or crystal units; none is alat, pw.x's
//! deprecated default; `crystal_sg` is refused; coordinates may be expressions as pw.x allows:
//! `1/3`, `2*0.25`, `(1+2)/3^2`), `CELL_PARAMETERS` (3 lines in alat, bohr or angstrom; none is
//! bohr without a lattice parameter, else alat, as pw.x and ASE read it). Other cards
//! (`K_POINTS`, `OCCUPATIONS`, `CONSTRAINTS`, …) are read past. The cell by `ibrav`, as pw.x
//! 6.7's `latgen` builds it (INPUT_PW, `ibrav`; vectors as rows; a = celldm(1) or A, b = a
//! celldm(2) or B, c = a celldm(3) or C; cos α, cos β, cos γ the cosines of the angles between
//! b and c, a and c, a and b):
//!
//! | ibrav | lattice | v1, v2, v3 |
//! |---|---|---|
//! | 0 | from `CELL_PARAMETERS` | |
//! | 1 | simple cubic | (a,0,0), (0,a,0), (0,0,a) |
//! | 2 | face-centred cubic | (a/2)(−1,0,1), (a/2)(0,1,1), (a/2)(−1,1,0) |
//! | 3 | body-centred cubic | (a/2)(1,1,1), (a/2)(−1,1,1), (a/2)(−1,−1,1) |
//! | −3 | bcc, more symmetric axes | (a/2)(−1,1,1), (a/2)(1,−1,1), (a/2)(1,1,−1) |
//! | 4 | hexagonal | (a,0,0), (−a/2,a√3/2,0), (0,0,c) |
//! | 5 | trigonal R, 3-fold axis z | a(tx,−ty,tz), a(0,2ty,tz), a(−tx,−ty,tz) |
//! | −5 | trigonal R, 3-fold axis (111) | (u,v,v), (v,u,v), (v,v,u) |
//! | 6 | simple tetragonal | (a,0,0), (0,a,0), (0,0,c) |
//! | 7 | body-centred tetragonal | (a/2,−a/2,c/2), (a/2,a/2,c/2), (−a/2,−a/2,c/2) |
//! | 8 | simple orthorhombic | (a,0,0), (0,b,0), (0,0,c) |
//! | 9 | base-centred orthorhombic (C) | (a/2,b/2,0), (−a/2,b/2,0), (0,0,c) |
//! | −9 | the same, other axes | (a/2,−b/2,0), (a/2,b/2,0), (0,0,c) |
//! | 91 | base-centred orthorhombic (A) | (a,0,0), (0,b/2,−c/2), (0,b/2,c/2) |
//! | 10 | face-centred orthorhombic | (a/2,0,c/2), (a/2,b/2,0), (0,b/2,c/2) |
//! | 11 | body-centred orthorhombic | (a/2,b/2,c/2), (−a/2,b/2,c/2), (−a/2,−b/2,c/2) |
//! | 12 | monoclinic, unique axis c | (a,0,0), (b cos γ,b sin γ,0), (0,0,c) |
//! | −12 | monoclinic, unique axis b | (a,0,0), (0,b,0), (c cos β,0,c sin β) |
//! | 13 | base-centred monoclinic, axis c | (a/2,0,−c/2), (b cos γ,b sin γ,0), (a/2,0,c/2) |
//! | −13 | base-centred monoclinic, axis b | (a/2,b/2,0), (−a/2,b/2,0), (c cos β,0,c sin β) |
//! | 14 | triclinic | (a,0,0), (b cos γ,b sin γ,0), (c cos β, c(cos α − cos β cos γ)/sin γ, c√(1 + 2 cos α cos β cos γ − cos²α − cos²β − cos²γ)/sin γ) |
//!
//! With celldm(4) = cos γ: tx = √((1−cos γ)/2), ty = √((1−cos γ)/6), tz = √((1+2 cos γ)/3);
//! u = a(√(1+2 cos γ) − 2√(1−cos γ))/3, v = a(√(1+2 cos γ) + √(1−cos γ))/3. The cosines are
//! celldm(4) (cos γ) for ±5, 12, 13; celldm(5) (cos β) for −12, −13; celldm(4, 5, 6) (cos α,
//! cos β, cos γ) for 14; 0 when not given. With A, pw.x's `abc2celldm` fills those slots from
//! cosAB (±5, 12, 13), cosAC (−12, −13) or cosBC, cosAC, cosAB (14), and the lattice reads
//! nothing else: a cosine meant for another lattice is ignored, as pw.x ignores it. pw.x's
//! bounds are errors at the parameter's token (at `ibrav` when it is missing): b/a, c/a > 0
//! where used, cos γ in (−1/2, 1) for ±5, every cosine used in (−1, 1), and for 14 a positive
//! volume. Any other ibrav is an error naming it. (−13 is pw.x 6.7's definition: until QE
//! 6.4.1 its v1 and v2 were today's −v2 and v1, and pw.x 6.7 warns `BEWARE: axis for
//! ibrav=-13 changed` in its output.)
//!
//! With ibrav = 0 and a cell in bohr or angstrom, alat is the first vector's length (pw.x's
//! rule; ASE refuses alat positions then). Both celldm and A, or a lattice parameter with a
//! cell in bohr or angstrom, are refused, as pw.x refuses them.
//!
//! # Units
//! Bohr and Rydberg are ASE's espresso module's (`create_units('2006')`, CODATA 2006): bohr =
//! 0.52917720859 Å, Ry = 13.60569193 eV, so that energies, forces and stresses agree with
//! ASE's reading to rounding. pw.x 6.7 itself uses CODATA 2018 (QE 6.7 `Modules/constants.f90`:
//! bohr 0.529177210903 Å, as its data file shows: an A of 5.3 Å is 10.01554846052 bohr there),
//! and so does the crate's `crate::cube::BOHR`: a length pw.x gives in bohr reads here 4.4·10⁻⁹
//! relative shorter than pw.x meant it, an energy 8.8·10⁻⁸ relative smaller. Lengths given in
//! Å (positions, `A`, `CELL_PARAMETERS angstrom`) come back as given either way.
//!
//! # Damage and memory
//! Errors name the file, frame, line and byte and what was expected there. Nothing is sized
//! from a count in the file (`number of atoms/cell`, `nat`, `ntyp`): atoms are pushed as their
//! lines are read, reserving at most the text reader's bound (one atom per 8 bytes of the
//! file, at most 2^16). A block cut short (positions, cell, forces, stress, the header) is an
//! [`Error::Truncated`]. Every step of a run prints the results its first step printed (energy,
//! forces, stress): a step without one is damaged, an error at the next step's first line. A
//! run must end with pw.x's `JOB DONE.`: a file that ends without it, after a step's results
//! or inside the step after, is cut (the next frame's [`Error::Truncated`], or this frame's
//! when it lacks a result the run's first step had); under `allow_truncated` the complete
//! frames are kept.
//! A run that stopped with pw.x's `Error in routine` message says so in that error.
//!
//! # References
//! - Quantum ESPRESSO 6.7 `PW/Doc/INPUT_PW` (namelists, cards, ibrav conventions, units),
//!   `Modules/latgen.f90` (`latgen_lib`, `abc2celldm`) and `PW/src/report_mag.f90`; the outputs
//!   read here were written by pw.x 6.7MaX.
//! - ASE 3.29 `ase/io/espresso.py` (`read_espresso_out`, `read_espresso_in`), what the tests
//!   compare with; it reads ibrav = 0 inputs only, so every other lattice is checked against
//!   the geometry pw.x printed for it and the one in its data file (all digits).

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label, MAX_COORDINATE, UnitCell};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos, need_line_with};
use std::collections::BTreeMap;
use std::io::Read;

/// Å per bohr, pw.x 6.7's (QE `BOHR_RADIUS_ANGS`, CODATA 2006).
const BOHR: f64 = 0.529_177_208_59;

/// eV per Ry, pw.x 6.7's (QE `RYTOEV`: `HARTREE_SI / ELECTRONVOLT_SI / 2`, CODATA 2006).
const RY: f64 = 4.359_743_94e-18 / 1.602_176_487e-19 / 2.0;

/// True when one of the lines of `head` (a file's first bytes) starts, after indentation, with
/// pw.x's banner `Program PWSCF`.
pub(crate) fn is_output(head: &[u8]) -> bool {
    head.split(|b| *b == b'\n')
        .any(|l| trim(l).starts_with(b"Program PWSCF"))
}

/// True when the first line of `head` that is not blank or a comment (`!`, `#`) opens pw.x's
/// `&CONTROL` or `&SYSTEM` namelist (any letter case).
pub(crate) fn is_input(head: &[u8]) -> bool {
    let first = head
        .split(|b| *b == b'\n')
        .map(trim)
        .find(|l| !l.is_empty() && l[0] != b'!' && l[0] != b'#');
    first.is_some_and(|l| {
        let name = fields(l).next().unwrap_or(b"");
        name.eq_ignore_ascii_case(b"&control") || name.eq_ignore_ascii_case(b"&system")
    })
}

/// The element a species label names, as ASE's `label_to_symbol` reads pw.x's labels (a
/// symbol, or a symbol followed by a digit, a letter, `_` or `-`: `Fe`, `Fe1`, `O_u`, `Ob`):
/// its first two letters when they are an element's symbol, else its first letter.
fn label_element(label: &[u8]) -> Option<Element> {
    let sym = |b: &[u8]| {
        b.iter()
            .all(u8::is_ascii_alphabetic)
            .then(|| Element::from_symbol(std::str::from_utf8(b).ok()?))
            .flatten()
    };
    label
        .get(..2)
        .and_then(sym)
        .or_else(|| label.get(..1).and_then(sym))
}

/// A Fortran real: a decimal number whose exponent letter may be `d`, `D`, `q` or `Q` (`1.0d-8`).
fn fortran_f64(t: &[u8]) -> Option<f64> {
    if let Some(v) = parse_f64(t) {
        return Some(v);
    }
    let k = t
        .iter()
        .position(|b| matches!(b, b'd' | b'D' | b'q' | b'Q'))?;
    let mut s = t.to_vec();
    s[k] = b'e';
    parse_f64(&s)
}

/// A coordinate as pw.x reads one: a number, or a simple algebraic expression of numbers with
/// `+ - * /`, `^` (power), parentheses and signs (`1/3`, `-2*0.25`, `(1+2)/3^2`). At most 64
/// nested parentheses or signs.
fn coordinate(t: &[u8]) -> Option<f64> {
    if let Some(v) = fortran_f64(t) {
        return Some(v);
    }
    let mut e = Expr {
        s: t,
        i: 0,
        depth: 0,
    };
    let v = e.sum()?;
    (e.i == t.len() && v.is_finite()).then_some(v)
}

/// A recursive-descent reader of [`coordinate`]'s expressions.
struct Expr<'a> {
    s: &'a [u8],
    i: usize,
    depth: u32,
}

impl Expr<'_> {
    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    /// sum := product (('+' | '-') product)*
    fn sum(&mut self) -> Option<f64> {
        let mut v = self.product()?;
        while let Some(op @ (b'+' | b'-')) = self.peek() {
            self.i += 1;
            let w = self.product()?;
            v = if op == b'+' { v + w } else { v - w };
        }
        Some(v)
    }

    /// product := unary (('*' | '/') unary)*
    fn product(&mut self) -> Option<f64> {
        let mut v = self.unary()?;
        while let Some(op @ (b'*' | b'/')) = self.peek() {
            self.i += 1;
            let w = self.unary()?;
            v = if op == b'*' { v * w } else { v / w };
        }
        Some(v)
    }

    /// unary := ('+' | '-') unary | power
    fn unary(&mut self) -> Option<f64> {
        self.depth += 1;
        if self.depth > 64 {
            return None;
        }
        let v = match self.peek()? {
            b'+' => {
                self.i += 1;
                self.unary()
            }
            b'-' => {
                self.i += 1;
                self.unary().map(|v| -v)
            }
            _ => self.power(),
        };
        self.depth -= 1;
        v
    }

    /// power := atom ('^' unary)?
    fn power(&mut self) -> Option<f64> {
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.i += 1;
            return Some(base.powf(self.unary()?));
        }
        Some(base)
    }

    /// atom := '(' sum ')' | number
    fn atom(&mut self) -> Option<f64> {
        if self.peek()? == b'(' {
            self.i += 1;
            let v = self.sum()?;
            if self.peek()? != b')' {
                return None;
            }
            self.i += 1;
            return Some(v);
        }
        let start = self.i;
        let s = self.s;
        let digits = |i: &mut usize| {
            while s.get(*i).is_some_and(|b| b.is_ascii_digit() || *b == b'.') {
                *i += 1;
            }
        };
        digits(&mut self.i);
        if self.i > start && matches!(self.peek(), Some(b'e' | b'E' | b'd' | b'D' | b'q' | b'Q')) {
            let mut j = self.i + 1;
            if matches!(s.get(j), Some(b'+' | b'-')) {
                j += 1;
            }
            if s.get(j).is_some_and(u8::is_ascii_digit) {
                self.i = j;
                digits(&mut self.i);
            }
        }
        fortran_f64(&s[start..self.i])
    }
}

/// The units of an `ATOMIC_POSITIONS` or `CELL_PARAMETERS` block.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Units {
    /// Times the lattice parameter; in an output's `CELL_PARAMETERS (alat= x)`, x bohr.
    Alat(Option<f64>),
    Bohr,
    Angstrom,
    /// Fractions of the cell vectors.
    Crystal,
    /// Wyckoff positions (`crystal_sg`): refused.
    CrystalSg,
    /// No units given.
    Default,
}

/// The keyword and units of a block's first line: `ATOMIC_POSITIONS (crystal)`,
/// `CELL_PARAMETERS {alat}`, `CELL_PARAMETERS (alat= 10.20000000)`, `K_POINTS automatic`.
/// `None` for units not known.
fn block_head(line: &[u8]) -> (&[u8], Option<Units>) {
    let t = trim(line);
    let key = card_key(t);
    let rest: Vec<u8> = t[key.len()..]
        .iter()
        .filter(|b| !matches!(b, b'(' | b')' | b'{' | b'}' | b' ' | b'\t'))
        .map(u8::to_ascii_lowercase)
        .collect();
    let units = match rest.as_slice() {
        b"" => Some(Units::Default),
        b"alat" => Some(Units::Alat(None)),
        b"bohr" => Some(Units::Bohr),
        b"angstrom" => Some(Units::Angstrom),
        b"crystal" => Some(Units::Crystal),
        b"crystal_sg" => Some(Units::CrystalSg),
        r => r
            .strip_prefix(b"alat=")
            .and_then(fortran_f64)
            .filter(|a| *a > 0.0)
            .map(|a| Units::Alat(Some(a))),
    };
    (key, units)
}

/// A block's keyword: its first line up to white space or its units (`K_POINTS`,
/// `ATOMIC_POSITIONS` of `ATOMIC_POSITIONS{crystal}`).
fn card_key(line: &[u8]) -> &[u8] {
    let t = trim(line);
    let end = t
        .iter()
        .position(|b| matches!(b, b' ' | b'\t' | b'(' | b'{'))
        .unwrap_or(t.len());
    &t[..end]
}

/// An error at `token`, a part of `line` (which starts at `pos`), with what was found spelled
/// out (`found`) rather than the token's text.
fn error_at(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    token: &[u8],
    expected: &'static str,
    found: String,
) -> Error {
    match ctx.parse(pos, line, token, expected) {
        Error::Parse { at, .. } => Error::Parse {
            at,
            expected,
            found,
        },
        other => other,
    }
}

/// The cell of three row vectors (Å), or the error at `line` (which starts at `pos`).
fn cell_of(ctx: &Ctx, pos: Pos, line: &[u8], m: [[f64; 3]; 3]) -> Result<UnitCell, Error> {
    UnitCell::from_matrix(m).map_err(|_| {
        error_at(
            ctx,
            pos,
            line,
            trim(line),
            "cell vectors of a right-handed cell with volume > 0, each at most 1e7 Å long (pw.x \
             also accepts a left-handed set: list the vectors in another order)",
            format!("{m:?} Å"),
        )
    })
}

/// Exactly three numbers in `part`, a sub-slice of `line` (which starts at `pos`; errors point
/// into it), read by `read`; a `!` or `#` comment may follow.
fn three(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    part: &[u8],
    read: fn(&[u8]) -> Option<f64>,
    expected: &'static str,
) -> Result<[f64; 3], Error> {
    let mut v = [0.0; 3];
    let mut f = fields(part);
    for x in &mut v {
        let t = f
            .next()
            .ok_or_else(|| ctx.parse(pos, line, trim(part), expected))?;
        *x = read(t).ok_or_else(|| ctx.parse(pos, line, t, expected))?;
    }
    if let Some(t) = f.next().filter(|t| !matches!(t[0], b'!' | b'#')) {
        return Err(ctx.parse(pos, line, t, expected));
    }
    Ok(v)
}

/// An atom line of an `ATOMIC_POSITIONS` block: its label and coordinates (in the block's
/// units). `if_pos` flags (three 0 or 1) may follow, and a `!` or `#` comment.
fn atom_line<'a>(ctx: &Ctx, pos: Pos, line: &'a [u8]) -> Result<(&'a [u8], [f64; 3]), Error> {
    const ATOM: &str = "an atom line: a species label, x y z (numbers or expressions such as \
                        1/3), and optionally three if_pos flags (0 or 1)";
    let mut f = fields(line);
    let label = f.next().ok_or_else(|| ctx.parse(pos, line, line, ATOM))?;
    if coordinate(label).is_some() {
        return Err(ctx.parse(pos, line, label, ATOM));
    }
    let mut x = [0.0; 3];
    for c in &mut x {
        let t = f
            .next()
            .ok_or_else(|| ctx.parse(pos, line, trim(line), ATOM))?;
        *c = coordinate(t).ok_or_else(|| ctx.parse(pos, line, t, ATOM))?;
    }
    let mut flags = 0;
    for t in f {
        if matches!(t[0], b'!' | b'#') {
            break;
        }
        if flags == 3 || !matches!(t, b"0" | b"1") {
            return Err(ctx.parse(pos, line, t, ATOM));
        }
        flags += 1;
    }
    if flags != 0 && flags != 3 {
        return Err(ctx.parse(pos, line, trim(line), ATOM));
    }
    Ok((label, x))
}

/// A species: its label and element.
type Species = (Label, Element);

/// The element of the atom labelled `label` in `species`, or the error at its line.
fn species_of(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    label: &[u8],
    species: &[Species],
    expected: &'static str,
) -> Result<Species, Error> {
    species
        .iter()
        .find(|s| s.0.as_bytes() == label)
        .copied()
        .ok_or_else(|| ctx.parse(pos, line, label, expected))
}

/// Cartesian position (Å) of `x` given in `units`: `alat` in Å, `cell` the frame's (rows, Å).
fn cartesian(units: Units, x: [f64; 3], alat: f64, cell: &[[f64; 3]; 3]) -> [f64; 3] {
    match units {
        Units::Alat(_) | Units::Default => x.map(|v| v * alat),
        Units::Bohr => x.map(|v| v * BOHR),
        Units::Angstrom => x,
        Units::Crystal | Units::CrystalSg => {
            std::array::from_fn(|k| x[0] * cell[0][k] + x[1] * cell[1][k] + x[2] * cell[2][k])
        }
    }
}

/// Checks a Cartesian position (Å) and adds the atom to `frame`.
fn push_atom(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    frame: Option<&mut Frame>,
    (name, element): Species,
    p: [f64; 3],
) -> Result<(), Error> {
    if p.iter().any(|v| v.is_nan() || v.abs() > MAX_COORDINATE) {
        return Err(ctx.parse(pos, line, trim(line), crate::cursor::IN_BOUNDS));
    }
    if let Some(f) = frame {
        f.positions.push(p.map(|v| v as f32));
        f.names.push(name);
        f.elements.push(element);
    }
    Ok(())
}

// ------------------------------------------------------------------------------------------
// The output
// ------------------------------------------------------------------------------------------

/// What a line of pw.x's output is, by its start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mark {
    /// `Program PWSCF`: a run starts.
    Banner,
    /// `Entering Dynamics`: a molecular-dynamics step's configuration starts.
    Dynamics,
    /// `CELL_PARAMETERS` at column 0.
    Cell,
    /// `ATOMIC_POSITIONS` at column 0.
    Positions,
    /// `!    total energy` at column 0.
    Energy,
    /// `Forces acting on atoms`.
    Forces,
    /// `total   stress`.
    Stress,
    /// `Magnetic moment per site` (a spin-polarised run's moments).
    Moments,
    /// `End of self-consistent calculation`, `End of band structure calculation`: results not
    /// read.
    Result,
    /// `Molecular Dynamics Calculation`: the first step of a molecular-dynamics run.
    Md,
    /// `JOB DONE.`: the run's last line.
    Done,
    /// `Error in routine`: pw.x stopped on an error.
    Failed,
    /// Anything else.
    Other,
}

impl Mark {
    /// Starts a configuration (ends the step before it).
    fn starts(self) -> bool {
        matches!(
            self,
            Mark::Banner | Mark::Dynamics | Mark::Cell | Mark::Positions
        )
    }
}

/// A block keyword at column 0, followed by nothing, white space or its units.
fn column0(line: &[u8], key: &[u8]) -> bool {
    line.starts_with(key)
        && matches!(
            line.get(key.len()),
            None | Some(b' ' | b'\t' | b'(' | b'{' | b'\r')
        )
}

fn mark(line: &[u8]) -> Mark {
    match line.first() {
        Some(b'A') if column0(line, b"ATOMIC_POSITIONS") => return Mark::Positions,
        Some(b'C') if column0(line, b"CELL_PARAMETERS") => return Mark::Cell,
        Some(b'!') if line.starts_with(b"!    total energy") => return Mark::Energy,
        _ => {}
    }
    let t = trim(line);
    let is = |p: &[u8]| t.starts_with(p);
    match t.first() {
        Some(b'P') if is(b"Program PWSCF") => Mark::Banner,
        Some(b'E') if is(b"Entering Dynamics") => Mark::Dynamics,
        Some(b'E') if is(b"End of self-consistent calculation") => Mark::Result,
        Some(b'E') if is(b"End of band structure calculation") => Mark::Result,
        Some(b'E') if is(b"Error in routine") => Mark::Failed,
        Some(b'F') if is(b"Forces acting on atoms") => Mark::Forces,
        Some(b't') if is(b"total   stress") => Mark::Stress,
        Some(b'M') if is(b"Magnetic moment per site") => Mark::Moments,
        Some(b'M') if is(b"Molecular Dynamics Calculation") => Mark::Md,
        Some(b'J') if t == b"JOB DONE." => Mark::Done,
        _ => Mark::Other,
    }
}

/// What a run's header gives every step of it.
#[derive(Clone, Debug)]
struct Run {
    /// celldm(1) in Å.
    alat: f64,
    /// The crystal axes (rows, Å).
    axes: [[f64; 3]; 3],
    /// `number of atoms/cell`.
    nat: usize,
    species: Vec<Species>,
    /// The results the run's first frame held, once something followed them in the file: what
    /// a last frame the file ends after must hold to be whole.
    expected: Option<Blocks>,
}

/// Which results a step printed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Blocks {
    energy: bool,
    forces: bool,
    stress: bool,
    /// Any result, those not read included.
    any: bool,
}

impl Blocks {
    /// The first of `expected`'s blocks this step lacks: what it is, and what the error of a
    /// step that ends without it expects.
    fn missing(self, expected: Blocks) -> Option<(&'static str, &'static str)> {
        if expected.energy && !self.energy {
            Some((
                "the step's '!    total energy' line",
                "the step's '!    total energy' line before the next step, as the run's first \
                 step has one",
            ))
        } else if expected.forces && !self.forces {
            Some((
                "the step's forces ('Forces acting on atoms')",
                "the step's forces ('Forces acting on atoms') before the next step, as the \
                 run's first step has them",
            ))
        } else if expected.stress && !self.stress {
            Some((
                "the step's stress ('total   stress')",
                "the step's stress ('total   stress') before the next step, as the run's \
                 first step has it",
            ))
        } else {
            None
        }
    }
}

/// A frame met: the byte offset of its run's banner and its step in the run.
#[derive(Clone, Copy, Debug)]
struct Seen {
    run: u64,
    step: i64,
}

/// The lines after a configuration, up to the next one or the end of the data.
struct Tail {
    blocks: Blocks,
    /// `JOB DONE.` stood among them.
    done: bool,
    /// `Molecular Dynamics Calculation` stood among them.
    md: bool,
    /// Where the data ended, if it did.
    end: Option<Pos>,
    /// Else the line that starts the next configuration, where it stands.
    next: Option<(Pos, Vec<u8>)>,
    /// pw.x's `Error in routine` line, if one stood among them.
    failed: Option<(u64, String)>,
}

/// The pw.x output parser; it keeps what later frames need from earlier ones.
#[derive(Default)]
pub(crate) struct PwOut {
    /// The runs by the byte offset of their banner.
    runs: BTreeMap<u64, Run>,
    /// Every frame met so far, in order (frames are met in order, reading or scanning).
    seen: Vec<Seen>,
    /// The frame whose results the data ends after, and whether `JOB DONE.` followed them.
    last: Option<(usize, bool)>,
}

impl FrameWalk for PwOut {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        self.frame(lines, ctx, frame)
    }

    fn end(&mut self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        match self.last {
            Some((k, false)) if k + 1 == ctx.frame => Err(ctx.truncated(
                at,
                "the next ionic step or the end of the run (pw.x ends its output with JOB DONE.)"
                    .into(),
            )),
            _ => Ok(()),
        }
    }
}

impl PwOut {
    /// Walks frame `ctx.frame`: the configurations from the next line on, up to the first that
    /// has results, which it reads with them into `frame` (when given); `Ok(false)` when none
    /// has (the data ends after the run's last positions, which have none).
    fn frame<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        let k = ctx.frame;
        let (mut run, mut step) = match k.checked_sub(1).map(|j| self.seen.get(j)) {
            None => (None, 0),
            Some(Some(s)) => (Some(s.run), s.step),
            Some(None) => {
                let p = lines.pos();
                return Err(ctx.parse(p, b"", b"", "the file's earlier frames, read first"));
            }
        };
        // Frame 0: the first line before the banner, if any (for the error of a file without).
        let mut before: Option<(Pos, Vec<u8>)> = None;
        loop {
            // The next configuration (at frame 0, after whatever precedes the banner).
            let (pos, m) = loop {
                let p = lines.pos();
                let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                    return match (run, before) {
                        (Some(_), _) => Ok(false),
                        (None, Some((pos, line))) => Err(ctx.parse(
                            pos,
                            &line,
                            trim(&line),
                            "pw.x's 'Program PWSCF' banner in the file (a Quantum ESPRESSO \
                             pw.x output)",
                        )),
                        (None, None) => {
                            Err(ctx.truncated(p, "pw.x's 'Program PWSCF' banner".into()))
                        }
                    };
                };
                let m = mark(line);
                if m.starts() {
                    lines.unread(pos);
                    break (pos, m);
                }
                if run.is_some() {
                    return Err(ctx.parse(
                        pos,
                        line,
                        trim(line),
                        "a step's configuration: ATOMIC_POSITIONS, CELL_PARAMETERS or Entering \
                         Dynamics",
                    ));
                }
                if before.is_none() && !trim(line).is_empty() {
                    before = Some((pos, line.to_vec()));
                }
            };
            if let Some(f) = frame.as_deref_mut() {
                f.clear();
            }
            let at = if m == Mark::Banner {
                lines.next_line().map_err(|e| ctx.io(pos, e))?;
                let r = header(lines, ctx, frame.as_deref_mut())?;
                self.runs.entry(pos.byte).or_insert(r);
                run = Some(pos.byte);
                step = 0;
                pos.byte
            } else {
                let known = run.and_then(|k| self.runs.get(&k).map(|r| (k, r)));
                let Some((at, r)) = known else {
                    let (_, line) = lines
                        .next_line()
                        .map_err(|e| ctx.io(pos, e))?
                        .unwrap_or((pos, b""));
                    return Err(ctx.parse(
                        pos,
                        line,
                        trim(line),
                        "pw.x's 'Program PWSCF' banner and its run header before the first \
                         step",
                    ));
                };
                step += 1;
                let time = config(lines, ctx, r, frame.as_deref_mut())?;
                if let Some(f) = frame.as_deref_mut() {
                    f.time = time;
                }
                at
            };
            let (nat, expected) = self
                .runs
                .get(&at)
                .map_or((0, None), |r| (r.nat, r.expected));
            let tail = results(lines, ctx, nat, frame.as_deref_mut())?;
            if !tail.blocks.any {
                // Not a frame (relax's final coordinates, the positions after md's last step).
                match tail.end {
                    None => continue,
                    Some(_) if tail.done => return Ok(false),
                    Some(end) => {
                        return Err(ctx.truncated(end, cut_step(&tail, "the step's results")));
                    }
                }
            }
            // Every step of a run prints what its first step printed: a step without it was
            // cut, or damaged.
            if let Some((what, expected)) = expected.and_then(|e| tail.blocks.missing(e)) {
                return Err(match (&tail.next, tail.end) {
                    (Some((pos, line)), _) => ctx.parse(*pos, line, trim(line), expected),
                    (None, Some(end)) if tail.done => ctx.parse(end, b"", b"", expected),
                    (None, end) => ctx.truncated(end.unwrap_or_default(), cut_step(&tail, what)),
                });
            }
            if let Some(r) = self.runs.get_mut(&at)
                && r.expected.is_none()
                && (tail.end.is_none() || tail.done)
            {
                r.expected = Some(tail.blocks);
            }
            if tail.end.is_some() {
                self.last = Some((k, tail.done));
            }
            if let Some(f) = frame {
                f.step = Some(step);
                if step == 0 && tail.md {
                    f.time = Some(0.0);
                }
            }
            let seen = Seen { run: at, step };
            match self.seen.get_mut(k) {
                Some(s) => *s = seen,
                None => self.seen.push(seen),
            }
            return Ok(true);
        }
    }
}

/// The run header after the banner, up to and with its positions table: the run, and the
/// starting geometry into `frame`.
fn header<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    mut frame: Option<&mut Frame>,
) -> Result<Run, Error> {
    const BEFORE: &str = "the run header's positions table ('site n. ... positions (alat \
                              units)') before the first step";
    const NEEDS: &str = "the header's celldm(1), number of atoms/cell and crystal axes \
                             before its positions table";
    let mut celldm = None;
    let mut nat = None;
    let mut axes = None;
    let mut species = Vec::new();
    loop {
        let (pos, line) = need_line_with(lines, ctx, &|| {
            "the run header, up to its positions table ('site n. ... positions (alat units)')"
                .into()
        })?;
        let m = mark(line);
        if m.starts() {
            return Err(ctx.parse(pos, line, trim(line), BEFORE));
        }
        if m == Mark::Failed {
            return Err(ctx.parse(pos, line, trim(line), BEFORE));
        }
        let t = trim(line);
        if let Some(rest) = t.strip_prefix(b"celldm(1)=") {
            let v = fields(rest).next().unwrap_or(rest);
            let a = fortran_f64(v).filter(|a| *a > 0.0 && a * BOHR <= MAX_COORDINATE);
            celldm = Some(a.ok_or_else(|| {
                ctx.parse(pos, line, v, "celldm(1) > 0 (bohr), the lattice parameter")
            })?);
        } else if t.starts_with(b"number of atoms/cell") {
            let v = fields(t).last().unwrap_or(t);
            let n = parse_usize(v).filter(|n| *n > 0);
            nat = Some(n.ok_or_else(|| ctx.parse(pos, line, v, "an atom count ≥ 1"))?);
        } else if t.starts_with(b"crystal axes:") {
            let mut m = [[0.0; 3]; 3];
            let mut last = (pos, Vec::new());
            for (r, row) in m.iter_mut().enumerate() {
                let (pos, line) =
                    need_line_with(lines, ctx, &|| format!("{} more crystal axes", 3 - r))?;
                *row = parenthesised(ctx, pos, line, "a crystal axis: a(i) = ( x y z )")?;
                last = (pos, line.to_vec());
            }
            axes = Some((m, last.0, last.1));
        } else if t.starts_with(b"atomic species") && t.ends_with(b"pseudopotential") {
            species.clear();
            loop {
                let (pos, line) =
                    need_line_with(lines, ctx, &|| "the species table's lines".into())?;
                if trim(line).is_empty() {
                    break;
                }
                species.push(species_row(ctx, pos, line)?);
            }
        } else if t.starts_with(b"site n.") && t.ends_with(b"positions (alat units)") {
            let (Some(celldm), Some(nat), Some((m, apos, aline))) = (celldm, nat, axes) else {
                return Err(ctx.parse(pos, line, t, NEEDS));
            };
            let alat = celldm * BOHR;
            let axes = m.map(|row| row.map(|v| v * alat));
            let cell = cell_of(ctx, apos, &aline, axes)?;
            if let Some(f) = frame.as_deref_mut() {
                f.cell = Some(cell);
                f.reserve_named(nat.min(ctx.reserve));
            }
            for i in 0..nat {
                let (pos, line) = need_line_with(lines, ctx, &|| {
                    format!("{} more lines of the header's positions table", nat - i)
                })?;
                let (label, x) = tau_line(ctx, pos, line)?;
                let s = atom_species(ctx, pos, line, label, &species)?;
                let p = x.map(|v| v * alat);
                push_atom(ctx, pos, line, frame.as_deref_mut(), s, p)?;
            }
            return Ok(Run {
                alat,
                axes,
                nat,
                species,
                expected: None,
            });
        }
    }
}

/// The species of a label in a run: from its species table, or from the label when the header
/// has none.
fn atom_species(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    label: &[u8],
    species: &[Species],
) -> Result<Species, Error> {
    if species.is_empty() {
        let name = Label::from_utf8(label)
            .ok_or_else(|| ctx.parse(pos, line, label, "a species label of at most 15 bytes"))?;
        return Ok((name, label_element(label).unwrap_or(Element::UNKNOWN)));
    }
    species_of(
        ctx,
        pos,
        line,
        label,
        species,
        "a species label of the run header's species table",
    )
}

/// A row of the header's species table: `label valence mass element( weight)`.
fn species_row(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<Species, Error> {
    const ROW: &str = "a species table row: label, valence, mass and the pseudopotential's \
                       element (Si( 1.00))";
    let f: Vec<&[u8]> = fields(line).take(4).collect();
    let [label, valence, mass, psd] = f[..] else {
        return Err(ctx.parse(pos, line, trim(line), ROW));
    };
    for t in [valence, mass] {
        fortran_f64(t).ok_or_else(|| ctx.parse(pos, line, t, ROW))?;
    }
    let name = Label::from_utf8(label).ok_or_else(|| ctx.parse(pos, line, label, ROW))?;
    let psd = &psd[..psd.iter().position(|b| *b == b'(').unwrap_or(psd.len())];
    let e = std::str::from_utf8(psd)
        .ok()
        .and_then(Element::from_symbol)
        .or_else(|| label_element(label))
        .unwrap_or(Element::UNKNOWN);
    Ok((name, e))
}

/// Three numbers between parentheses after the line's `=`: `a(1) = ( -0.5 0.0 0.5 )`.
fn parenthesised(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    expected: &'static str,
) -> Result<[f64; 3], Error> {
    let eq = line.iter().position(|b| *b == b'=');
    let inner = eq
        .map(|e| trim(&line[e + 1..]))
        .and_then(|r| r.strip_prefix(b"(").and_then(|r| r.strip_suffix(b")")));
    let inner = inner.ok_or_else(|| ctx.parse(pos, line, trim(line), expected))?;
    three(ctx, pos, line, inner, fortran_f64, expected)
}

/// A row of the header's positions table: `1  Si  tau(   1) = (   0.0  0.0  0.0  )` (QE 4:
/// `1  Si  28.0860  tau(    1) = (…)`).
fn tau_line<'a>(ctx: &Ctx, pos: Pos, line: &'a [u8]) -> Result<(&'a [u8], [f64; 3]), Error> {
    const TAU: &str = "a positions table row: site, label, tau(n) = ( x y z ) in alat units";
    let eq = line.iter().position(|b| *b == b'=').unwrap_or(line.len());
    let mut left = fields(&line[..eq]);
    let label = left
        .nth(1)
        .ok_or_else(|| ctx.parse(pos, line, trim(line), TAU))?;
    // QE 4 wrote the species' mass between the label and `tau(`.
    let tau = left.find(|t| parse_f64(t).is_none());
    if !tau.is_some_and(|t| t.starts_with(b"tau(")) {
        return Err(ctx.parse(pos, line, trim(line), TAU));
    }
    Ok((label, parenthesised(ctx, pos, line, TAU)?))
}

/// A step's configuration from its first line on (`Entering Dynamics`, `CELL_PARAMETERS` or
/// `ATOMIC_POSITIONS`): the atoms and cell into `frame`; the time (ps) when `Entering
/// Dynamics` gives it.
fn config<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    run: &Run,
    mut frame: Option<&mut Frame>,
) -> Result<Option<f64>, Error> {
    let mut time = None;
    let mut card: Option<([[f64; 3]; 3], Option<f64>)> = None;
    let mut cell_line = None;
    loop {
        let (pos, line) = need_line_with(lines, ctx, &|| {
            "the step's ATOMIC_POSITIONS block (the run stops before it)".into()
        })?;
        match mark(line) {
            Mark::Dynamics if time.is_none() && card.is_none() => {
                time = Some(dynamics_time(line));
            }
            Mark::Cell if card.is_none() => {
                let (_, units) = block_head(line);
                let unit = match units {
                    Some(Units::Alat(Some(a))) => a * BOHR,
                    Some(Units::Bohr) => BOHR,
                    Some(Units::Angstrom) => 1.0,
                    _ => {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "CELL_PARAMETERS (alat= x), (bohr) or (angstrom)",
                        ));
                    }
                };
                let alat = matches!(units, Some(Units::Alat(_))).then_some(unit);
                let mut m = [[0.0; 3]; 3];
                for (r, row) in m.iter_mut().enumerate() {
                    let (pos, line) = need_line_with(lines, ctx, &|| {
                        format!("{} more CELL_PARAMETERS lines", 3 - r)
                    })?;
                    let v = three(
                        ctx,
                        pos,
                        line,
                        line,
                        fortran_f64,
                        "a cell vector: 3 numbers",
                    )?;
                    *row = v.map(|x| x * unit);
                    if r == 2 {
                        cell_line = Some((pos, line.to_vec()));
                    }
                }
                card = Some((m, alat));
            }
            Mark::Positions => {
                let (_, units) = block_head(line);
                let units = match units {
                    Some(
                        u @ (Units::Alat(None) | Units::Bohr | Units::Angstrom | Units::Crystal),
                    ) => u,
                    Some(Units::Default) => Units::Alat(None),
                    _ => {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "ATOMIC_POSITIONS (alat), (bohr), (angstrom) or (crystal)",
                        ));
                    }
                };
                let (cell, alat) = match card {
                    Some((m, a)) => (m, a.unwrap_or(run.alat)),
                    None => (run.axes, run.alat),
                };
                let unit_cell = match &cell_line {
                    Some((p, l)) => cell_of(ctx, *p, l, cell)?,
                    None => cell_of(ctx, pos, line, cell)?,
                };
                if let Some(f) = frame.as_deref_mut() {
                    f.cell = Some(unit_cell);
                    f.reserve_named(run.nat.min(ctx.reserve));
                }
                for i in 0..run.nat {
                    let (pos, line) = need_line_with(lines, ctx, &|| {
                        format!("{} more ATOMIC_POSITIONS lines", run.nat - i)
                    })?;
                    if mark(line) != Mark::Other {
                        return Err(ctx.parse(
                            pos,
                            line,
                            trim(line),
                            "as many ATOMIC_POSITIONS lines as the header's number of atoms/cell",
                        ));
                    }
                    let (label, x) = atom_line(ctx, pos, line)?;
                    let s = atom_species(ctx, pos, line, label, &run.species)?;
                    let p = cartesian(units, x, alat, &cell);
                    push_atom(ctx, pos, line, frame.as_deref_mut(), s, p)?;
                }
                return Ok(time.flatten());
            }
            Mark::Other | Mark::Md => {
                // `time = 0.0010 pico-seconds` on the line after `Entering Dynamics`.
                if time == Some(None) {
                    time = Some(dynamics_time(line));
                }
            }
            _ => {
                return Err(ctx.parse(
                    pos,
                    line,
                    trim(line),
                    "the step's ATOMIC_POSITIONS block after its Entering Dynamics and \
                     CELL_PARAMETERS lines",
                ));
            }
        }
    }
}

/// The time (ps) in `Entering Dynamics:    iteration =     1  time = 0.0010 pico-seconds`
/// or the line after it, as pw.x writes it; `None` where it is not found.
fn dynamics_time(line: &[u8]) -> Option<f64> {
    let f: Vec<&[u8]> = fields(line).collect();
    let k = f.iter().position(|t| *t == b"time")?;
    (f.get(k + 1) == Some(&&b"="[..]) && f.get(k + 3) == Some(&&b"pico-seconds"[..]))
        .then(|| parse_f64(f.get(k + 2)?))
        .flatten()
}

/// The lines after a configuration up to the next (left unread) or the end of the data: the
/// results into `frame`.
fn results<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    nat: usize,
    mut frame: Option<&mut Frame>,
) -> Result<Tail, Error> {
    let mut tail = Tail {
        blocks: Blocks::default(),
        done: false,
        md: false,
        end: None,
        next: None,
        failed: None,
    };
    let mut energy = None;
    let mut stress = None;
    let mut moments: Option<Vec<f32>> = None;
    loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            tail.end = Some(p);
            break;
        };
        let m = mark(line);
        if m.starts() {
            tail.next = Some((pos, line.to_vec()));
            lines.unread(pos);
            break;
        }
        match m {
            Mark::Energy => {
                tail.blocks.any = true;
                if !tail.blocks.energy {
                    energy = Some(total_energy(ctx, pos, line)?);
                    tail.blocks.energy = true;
                }
            }
            Mark::Forces => {
                tail.blocks.any = true;
                if !tail.blocks.forces {
                    forces(lines, ctx, nat, frame.as_deref_mut())?;
                    tail.blocks.forces = true;
                }
            }
            Mark::Stress => {
                tail.blocks.any = true;
                if !tail.blocks.stress {
                    stress = Some(stress_block(lines, ctx)?);
                    tail.blocks.stress = true;
                }
            }
            Mark::Moments => {
                // pw.x prints them after each scf of the step (every `report` iterations, and
                // at convergence): the step's last block holds its moments.
                tail.blocks.any = true;
                moments = Some(moment_block(lines, ctx, nat)?);
            }
            Mark::Result => tail.blocks.any = true,
            Mark::Md => tail.md = true,
            Mark::Done => tail.done = true,
            Mark::Failed => {
                tail.failed = Some((pos.line, String::from_utf8_lossy(trim(line)).into_owned()));
            }
            _ => {}
        }
    }
    if let Some(f) = frame {
        if let Some(m) = moments {
            *f.property_mut("magmom") = m;
        }
        let mut comment = Vec::new();
        if let Some(e) = energy {
            comment.push(format!("energy={e}"));
        }
        if let Some(s) = stress {
            let s: Vec<String> = s.iter().flatten().map(f64::to_string).collect();
            comment.push(format!("stress=\"{}\"", s.join(" ")));
        }
        f.comment = comment.join(" ");
    }
    Ok(tail)
}

/// What a cut step's error expects: `what`, and why the data ends (pw.x's error, if it printed
/// one).
fn cut_step(tail: &Tail, what: &str) -> String {
    match &tail.failed {
        Some((line, text)) => {
            format!("{what}: pw.x stopped with an error at line {line}: {text}")
        }
        None => {
            format!("{what} (the run stops before its end: pw.x ends its output with JOB DONE.)")
        }
    }
}

/// The energy (eV) of `!    total energy              =     -15.60475144 Ry`.
fn total_energy(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<f64, Error> {
    const ENERGY: &str = "the total energy: '!    total energy = E Ry'";
    let f: Vec<&[u8]> = fields(line).collect();
    match f[..] {
        [.., b"=", e, b"Ry"] => fortran_f64(e)
            .map(|e| e * RY)
            .filter(|e| e.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, e, ENERGY)),
        _ => Err(ctx.parse(pos, line, trim(line), ENERGY)),
    }
}

/// The `nat` lines after `Forces acting on atoms` (blank lines before them passed over):
/// `atom    1 type  1   force =     0.075    0.008   -0.038` (Ry/bohr), as `fx fy fz` (eV/Å).
fn forces<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    nat: usize,
    mut frame: Option<&mut Frame>,
) -> Result<(), Error> {
    const FORCE: &str = "a force line: atom n type t force = fx fy fz (Ry/bohr), one per atom";
    let mut i = 0;
    while i < nat {
        let (pos, line) = need_line_with(lines, ctx, &|| format!("{} more force lines", nat - i))?;
        let t = trim(line);
        if t.is_empty() && i == 0 {
            continue;
        }
        if !t.starts_with(b"atom") {
            return Err(ctx.parse(pos, line, t, FORCE));
        }
        let eq = line.iter().position(|b| *b == b'=').unwrap_or(line.len());
        let rest = line.get(eq + 1..).unwrap_or(b"");
        let v = three(ctx, pos, line, rest, fortran_f64, FORCE)?;
        let v = v.map(|x| (x * RY / BOHR) as f32);
        if v.iter().any(|x| !x.is_finite()) {
            return Err(ctx.parse(pos, line, t, "forces within f32 range"));
        }
        if let Some(f) = frame.as_deref_mut() {
            for (c, key) in ["fx", "fy", "fz"].into_iter().enumerate() {
                f.property_mut(key).push(v[c]);
            }
        }
        i += 1;
    }
    Ok(())
}

/// The `nat` lines after `Magnetic moment per site:`, the moments (μB) of a spin-polarised run:
/// `atom:    1    charge:    6.2918    magn:    3.3015    constr:    0.0000` (pw.x 6.7) or
/// `atom      1 (R=0.190)  charge=  6.3520  magn=  2.2160` (pw.x 6.8 and later).
fn moment_block<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    nat: usize,
) -> Result<Vec<f32>, Error> {
    const MOMENT: &str = "a moment line: atom n … magn: m (or magn= m), one per atom";
    let mut out = Vec::with_capacity(nat.min(ctx.reserve));
    while out.len() < nat {
        let (pos, line) = need_line_with(lines, ctx, &|| {
            format!("{} more lines of the magnetic moments", nat - out.len())
        })?;
        let t = trim(line);
        if t.is_empty() && out.is_empty() {
            continue;
        }
        if !t.starts_with(b"atom") {
            return Err(ctx.parse(pos, line, t, MOMENT));
        }
        let f: Vec<&[u8]> = fields(t).collect();
        let k = f
            .iter()
            .position(|x| x.starts_with(b"magn:") || x.starts_with(b"magn="))
            .ok_or_else(|| ctx.parse(pos, line, t, MOMENT))?;
        let value = match &f[k][5..] {
            b"" => f.get(k + 1).copied().unwrap_or(b""),
            glued => glued,
        };
        let m = fortran_f64(value)
            .map(|m| m as f32)
            .filter(|m| m.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, value, MOMENT))?;
        out.push(m);
    }
    Ok(out)
}

/// The three lines after `total   stress  (Ry/bohr**3)  (kbar)  P= …`: the stress tensor (its
/// first three columns, Ry/bohr³) in eV/Å³ with ASE's sign.
fn stress_block<R: Read>(lines: &mut LineReader<R>, ctx: &Ctx) -> Result<[[f64; 3]; 3], Error> {
    const STRESS: &str = "a stress line: 3 numbers (Ry/bohr³), then 3 (kbar)";
    let mut s = [[0.0; 3]; 3];
    for (r, row) in s.iter_mut().enumerate() {
        let (pos, line) = need_line_with(lines, ctx, &|| format!("{} more stress lines", 3 - r))?;
        let f: Vec<&[u8]> = fields(line).collect();
        if f.len() != 6 {
            return Err(ctx.parse(pos, line, trim(line), STRESS));
        }
        for (c, x) in row.iter_mut().enumerate() {
            let v = fortran_f64(f[c]).ok_or_else(|| ctx.parse(pos, line, f[c], STRESS))?;
            *x = -v * RY / (BOHR * BOHR * BOHR);
        }
    }
    Ok(s)
}

// ------------------------------------------------------------------------------------------
// The input
// ------------------------------------------------------------------------------------------

/// A value of the `&SYSTEM` namelist and where it stands (its token's position and bytes).
#[derive(Clone, Debug)]
struct Value {
    pos: Pos,
    text: Vec<u8>,
}

/// The pw.x input parser (one frame: the whole file).
#[derive(Default)]
pub(crate) struct PwIn;

impl FrameWalk for PwIn {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        if ctx.frame > 0 {
            return Ok(false);
        }
        read_input(lines, ctx, frame)?;
        Ok(true)
    }
}

/// The cards pw.x and cp.x know: a line starting with one starts that card.
const CARDS: [&[u8]; 17] = [
    b"ATOMIC_SPECIES",
    b"ATOMIC_POSITIONS",
    b"K_POINTS",
    b"ADDITIONAL_K_POINTS",
    b"CELL_PARAMETERS",
    b"REF_CELL_PARAMETERS",
    b"CONSTRAINTS",
    b"OCCUPATIONS",
    b"ATOMIC_VELOCITIES",
    b"ATOMIC_FORCES",
    b"SOLVENTS",
    b"HUBBARD",
    b"TOTAL_CHARGE",
    b"AUTOPILOT",
    b"PLOT_WANNIER",
    b"WANNIER_AC",
    b"DIPOLE",
];

/// True for a blank line or a comment line (`!`, `#`).
fn is_comment(line: &[u8]) -> bool {
    matches!(trim(line).first(), None | Some(b'!' | b'#'))
}

/// A card's first line, where it stands, and its units.
struct Card {
    pos: Pos,
    line: Vec<u8>,
    units: Units,
}

/// An `ATOMIC_POSITIONS` line: where it stands, its bytes, where its label ends and its
/// coordinates (in the card's units).
struct AtomLine {
    pos: Pos,
    line: Vec<u8>,
    label_end: usize,
    x: [f64; 3],
}

/// The namelists' `&SYSTEM` values: key (lower case, spaces removed) to its last value.
type System = BTreeMap<Vec<u8>, Value>;

/// Reads the whole input: namelists, then cards; the frame into `frame`.
fn read_input<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    mut frame: Option<&mut Frame>,
) -> Result<(), Error> {
    let mut system: Option<(Pos, System)> = None;
    // The namelists.
    let first_card = loop {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(
                p,
                "the cards after the namelists (ATOMIC_SPECIES, ATOMIC_POSITIONS, …)".into(),
            ));
        };
        if is_comment(line) {
            continue;
        }
        let t = trim(line);
        if t[0] != b'&' {
            break (pos, line.to_vec());
        }
        let name = fields(t).next().unwrap_or(t);
        let is_system = name.eq_ignore_ascii_case(b"&system");
        let start = (name.as_ptr() as usize - line.as_ptr() as usize) + name.len();
        let name = String::from_utf8_lossy(name).into_owned();
        let mut values = System::new();
        let mut open = namelist_line(ctx, pos, line, start, &mut values)?;
        while open {
            let (pos, line) = need_line_with(lines, ctx, &|| {
                format!("the '/' that closes the namelist {name}")
            })?;
            open = namelist_line(ctx, pos, line, 0, &mut values)?;
        }
        if is_system && system.is_none() {
            system = Some((pos, values));
        }
    };
    let Some((system_pos, system)) = system else {
        let (pos, line) = (first_card.0, &first_card.1[..]);
        return Err(ctx.parse(
            pos,
            line,
            trim(line),
            "the &SYSTEM namelist before the cards",
        ));
    };
    // The cards.
    let mut species: Option<Vec<(Species, Vec<u8>)>> = None;
    let mut atoms: Option<(Card, Vec<AtomLine>)> = None;
    let mut cell: Option<(Card, [[f64; 3]; 3])> = None;
    let ntyp = count(ctx, &system, system_pos, b"ntyp", "ntyp ≥ 1 in &SYSTEM")?;
    let nat = count(ctx, &system, system_pos, b"nat", "nat ≥ 1 in &SYSTEM")?;
    let mut pending = Some(first_card);
    loop {
        let (pos, line) = match pending.take() {
            Some(l) => l,
            None => {
                let p = lines.pos();
                match lines.next_line().map_err(|e| ctx.io(p, e))? {
                    None => break,
                    Some((pos, line)) => (pos, line.to_vec()),
                }
            }
        };
        if is_comment(&line) {
            continue;
        }
        let (key, units) = block_head(&line);
        let known = CARDS.iter().any(|c| c.eq_ignore_ascii_case(key));
        if !known {
            return Err(ctx.parse(
                pos,
                &line,
                trim(&line),
                "a card: ATOMIC_SPECIES, ATOMIC_POSITIONS, CELL_PARAMETERS, K_POINTS… (after \
                 ATOMIC_SPECIES its ntyp lines, after ATOMIC_POSITIONS its nat lines)",
            ));
        }
        const TWICE: &str = "each of ATOMIC_SPECIES, ATOMIC_POSITIONS and CELL_PARAMETERS once";
        if key.eq_ignore_ascii_case(b"ATOMIC_SPECIES") {
            if species.is_some() {
                return Err(ctx.parse(pos, &line, key, TWICE));
            }
            let mut list = Vec::new();
            for i in 0..ntyp {
                let (pos, line) = card_line(lines, ctx, i, ntyp, "ATOMIC_SPECIES")?;
                list.push(species_line(ctx, pos, &line)?);
            }
            species = Some(list);
        } else if key.eq_ignore_ascii_case(b"ATOMIC_POSITIONS") {
            if atoms.is_some() {
                return Err(ctx.parse(pos, &line, key, TWICE));
            }
            let units = match units {
                Some(Units::CrystalSg) => {
                    return Err(ctx.parse(
                        pos,
                        &line,
                        trim(&line),
                        "ATOMIC_POSITIONS in alat, bohr, angstrom or crystal units (crystal_sg, \
                         Wyckoff positions of a space group, is not read)",
                    ));
                }
                Some(
                    u @ (Units::Alat(None)
                    | Units::Bohr
                    | Units::Angstrom
                    | Units::Crystal
                    | Units::Default),
                ) => u,
                _ => {
                    return Err(ctx.parse(
                        pos,
                        &line,
                        trim(&line),
                        "ATOMIC_POSITIONS alat, bohr, angstrom or crystal",
                    ));
                }
            };
            let mut list = Vec::new();
            for i in 0..nat {
                let (pos, line) = card_line(lines, ctx, i, nat, "ATOMIC_POSITIONS")?;
                let (label, x) = atom_line(ctx, pos, &line)?;
                let n = label.len();
                let label = label.as_ptr() as usize - line.as_ptr() as usize;
                list.push(AtomLine {
                    pos,
                    line: line.clone(),
                    label_end: label + n,
                    x,
                });
            }
            atoms = Some((Card { pos, line, units }, list));
        } else if key.eq_ignore_ascii_case(b"CELL_PARAMETERS") {
            if cell.is_some() {
                return Err(ctx.parse(pos, &line, key, TWICE));
            }
            let units = match units {
                Some(u @ (Units::Alat(None) | Units::Bohr | Units::Angstrom | Units::Default)) => u,
                _ => {
                    return Err(ctx.parse(
                        pos,
                        &line,
                        trim(&line),
                        "CELL_PARAMETERS alat, bohr or angstrom",
                    ));
                }
            };
            let mut m = [[0.0; 3]; 3];
            for (r, row) in m.iter_mut().enumerate() {
                let (pos, line) = card_line(lines, ctx, r, 3, "CELL_PARAMETERS")?;
                *row = three(
                    ctx,
                    pos,
                    &line,
                    &line,
                    coordinate,
                    "a cell vector: 3 numbers",
                )?;
            }
            cell = Some((Card { pos, line, units }, m));
        } else {
            // Another card: its lines up to the next card are not read.
            loop {
                let p = lines.pos();
                let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                    break;
                };
                let key = card_key(line);
                if !is_comment(line) && CARDS.iter().any(|c| c.eq_ignore_ascii_case(key)) {
                    pending = Some((pos, line.to_vec()));
                    break;
                }
            }
        }
    }
    let end = lines.pos();
    let Some(species) = species else {
        return Err(ctx.truncated(end, "the ATOMIC_SPECIES card".into()));
    };
    let Some((card, list)) = atoms else {
        return Err(ctx.truncated(end, "the ATOMIC_POSITIONS card".into()));
    };
    // The cell and the lattice parameter.
    let (m, alat, unit_cell) = lattice(ctx, &system, system_pos, cell)?;
    if let Some(f) = frame.as_deref_mut() {
        f.cell = Some(unit_cell);
        f.reserve_named(list.len());
    }
    let species: Vec<Species> = species.into_iter().map(|(s, _)| s).collect();
    for AtomLine {
        pos,
        line,
        label_end,
        x,
    } in &list
    {
        let label = fields(&line[..*label_end]).next().unwrap_or(b"");
        let s = species_of(
            ctx,
            *pos,
            line,
            label,
            &species,
            "a species label of the ATOMIC_SPECIES card",
        )?;
        let p = cartesian(card.units, *x, alat, &m);
        push_atom(ctx, *pos, line, frame.as_deref_mut(), s, p)?;
    }
    Ok(())
}

/// The `i`-th of `n` data lines of the card `card` (blank and comment lines passed over).
fn card_line<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    i: usize,
    n: usize,
    card: &'static str,
) -> Result<(Pos, Vec<u8>), Error> {
    loop {
        let (pos, line) = need_line_with(lines, ctx, &|| format!("{} more {card} lines", n - i))?;
        if is_comment(line) {
            continue;
        }
        let key = card_key(line);
        if CARDS.iter().any(|c| c.eq_ignore_ascii_case(key)) {
            let expected = match card {
                "ATOMIC_SPECIES" => "ntyp ATOMIC_SPECIES lines (ntyp in &SYSTEM)",
                "ATOMIC_POSITIONS" => "nat ATOMIC_POSITIONS lines (nat in &SYSTEM)",
                _ => "3 CELL_PARAMETERS lines",
            };
            return Err(ctx.parse(pos, line, key, expected));
        }
        return Ok((pos, line.to_vec()));
    }
}

/// An `ATOMIC_SPECIES` line: `label mass pseudopotential-file`.
fn species_line(ctx: &Ctx, pos: Pos, line: &[u8]) -> Result<(Species, Vec<u8>), Error> {
    const SPECIES: &str = "a species line: label, mass and pseudopotential file";
    let f: Vec<&[u8]> = fields(line).take(3).collect();
    let [label, mass, pseudo] = f[..] else {
        return Err(ctx.parse(pos, line, trim(line), SPECIES));
    };
    fortran_f64(mass).ok_or_else(|| ctx.parse(pos, line, mass, SPECIES))?;
    let name = Label::from_utf8(label).ok_or_else(|| ctx.parse(pos, line, label, SPECIES))?;
    let stem = &pseudo[..pseudo
        .iter()
        .position(|b| matches!(b, b'.' | b'_' | b'-'))
        .unwrap_or(pseudo.len())];
    let from_file = || {
        std::str::from_utf8(stem)
            .ok()
            .and_then(Element::from_symbol)
    };
    let e = label_element(label)
        .or_else(from_file)
        .unwrap_or(Element::UNKNOWN);
    Ok(((name, e), pseudo.to_vec()))
}

/// A count of `&SYSTEM` (`nat`, `ntyp`): an integer ≥ 1.
fn count(
    ctx: &Ctx,
    system: &System,
    at: Pos,
    key: &[u8],
    expected: &'static str,
) -> Result<usize, Error> {
    match system.get(key) {
        None => Err(ctx.parse(at, b"&SYSTEM", b"&SYSTEM", expected)),
        Some(v) => parse_usize(&v.text)
            .filter(|n| *n >= 1)
            .ok_or_else(|| ctx.parse(v.pos, &v.text, &v.text, expected)),
    }
}

/// A real of `&SYSTEM`, if given.
fn real(ctx: &Ctx, system: &System, key: &[u8]) -> Result<Option<f64>, Error> {
    match system.get(key) {
        None => Ok(None),
        Some(v) => fortran_f64(&v.text)
            .map(Some)
            .ok_or_else(|| ctx.parse(v.pos, &v.text, &v.text, "a real number")),
    }
}

/// The lattices pw.x 6.7 builds from `ibrav` (QE `Modules/latgen.f90`), by name.
fn lattice_name(ibrav: i64) -> Option<&'static str> {
    Some(match ibrav {
        1 => "simple cubic",
        2 => "face-centred cubic",
        3 | -3 => "body-centred cubic",
        4 => "hexagonal",
        5 | -5 => "trigonal R",
        6 => "simple tetragonal",
        7 => "body-centred tetragonal",
        8 => "simple orthorhombic",
        9 | -9 => "base-centred orthorhombic (C)",
        91 => "base-centred orthorhombic (A)",
        10 => "face-centred orthorhombic",
        11 => "body-centred orthorhombic",
        12 | -12 => "monoclinic",
        13 | -13 => "base-centred monoclinic",
        14 => "triclinic",
        _ => return None,
    })
}

/// One of pw.x's cell parameters celldm(2..6) for the lattice: its value (0 when not given, as
/// pw.x's default) and the token that gave it, if one did.
#[derive(Clone, Copy)]
struct Param<'a> {
    value: f64,
    from: Option<&'a Value>,
}

/// The cell (rows, Å), the lattice parameter alat (Å) for positions in alat units and the
/// cell checked, from ibrav and its parameters or `CELL_PARAMETERS`.
fn lattice(
    ctx: &Ctx,
    system: &System,
    system_pos: Pos,
    cell: Option<(Card, [[f64; 3]; 3])>,
) -> Result<([[f64; 3]; 3], f64, UnitCell), Error> {
    let Some(ibrav) = system.get(&b"ibrav"[..]) else {
        return Err(ctx.parse(system_pos, b"&SYSTEM", b"&SYSTEM", "ibrav in &SYSTEM"));
    };
    let n = parse_i64(&ibrav.text)
        .ok_or_else(|| ctx.parse(ibrav.pos, &ibrav.text, &ibrav.text, "ibrav: an integer"))?;
    // Every real of &SYSTEM the lattice may use, read (and so checked) whether used or not.
    let mut given = BTreeMap::new();
    for key in [
        "celldm(1)",
        "celldm(2)",
        "celldm(3)",
        "celldm(4)",
        "celldm(5)",
        "celldm(6)",
        "a",
        "b",
        "c",
        "cosab",
        "cosac",
        "cosbc",
    ] {
        if let Some(v) = real(ctx, system, key.as_bytes())? {
            given.insert(key, (v, &system[key.as_bytes()]));
        }
    }
    let param = |key: &str| {
        given.get(key).map_or(
            Param {
                value: 0.0,
                from: None,
            },
            |&(value, v)| Param {
                value,
                from: Some(v),
            },
        )
    };
    let nonzero = |key: &str| given.get(key).map(|g| g.0).filter(|x| *x != 0.0);
    let (c1, abc) = (nonzero("celldm(1)"), nonzero("a"));
    if c1.is_some() && abc.is_some() {
        return Err(ctx.parse(
            system_pos,
            b"&SYSTEM",
            b"&SYSTEM",
            "celldm(1) or A in &SYSTEM, not both (pw.x refuses both)",
        ));
    }
    // alat (Å).
    let alat = c1.map(|x| x * BOHR).or(abc);
    if n == 0 {
        let Some((Card { pos, line, units }, m)) = cell else {
            return Err(ctx.parse(
                ibrav.pos,
                &ibrav.text,
                &ibrav.text,
                "a CELL_PARAMETERS card with ibrav = 0",
            ));
        };
        let unit = match (units, alat) {
            (Units::Alat(_) | Units::Default, Some(a)) => a,
            (Units::Alat(_), None) => {
                return Err(ctx.parse(
                    pos,
                    &line,
                    trim(&line),
                    "celldm(1) or A in &SYSTEM for CELL_PARAMETERS in alat units",
                ));
            }
            (Units::Bohr | Units::Angstrom, Some(_)) => {
                return Err(ctx.parse(
                    pos,
                    &line,
                    trim(&line),
                    "CELL_PARAMETERS alat (or no units) when &SYSTEM gives celldm(1) or A (pw.x \
                     refuses the lattice parameter given twice)",
                ));
            }
            (Units::Angstrom, None) => 1.0,
            _ => BOHR,
        };
        let m = m.map(|row| row.map(|x| x * unit));
        // pw.x's alat without a lattice parameter: the first vector's length.
        let alat = alat.unwrap_or_else(|| m[0].iter().map(|x| x * x).sum::<f64>().sqrt());
        return Ok((m, alat, cell_of(ctx, pos, &line, m)?));
    }
    if let Some((Card { pos, line, .. }, _)) = cell {
        return Err(ctx.parse(
            pos,
            &line,
            trim(&line),
            "no CELL_PARAMETERS with ibrav ≠ 0 (pw.x builds the cell from ibrav and refuses both)",
        ));
    }
    const IBRAV: &str = "ibrav 0 (with CELL_PARAMETERS), 1, 2, 3, -3, 4, 5, -5, 6, 7, 8, 9, -9, \
                         91, 10, 11, 12, -12, 13, -13 or 14 (the lattices of pw.x 6.7)";
    let Some(name) = lattice_name(n) else {
        return Err(error_at(
            ctx,
            ibrav.pos,
            &ibrav.text,
            &ibrav.text,
            IBRAV,
            format!("ibrav = {n}"),
        ));
    };
    let Some(a) = alat.filter(|a| *a > 0.0) else {
        return Err(ctx.parse(
            ibrav.pos,
            &ibrav.text,
            &ibrav.text,
            "celldm(1) or A > 0 in &SYSTEM: the lattice parameter ibrav needs",
        ));
    };
    // celldm(2..6) as pw.x's abc2celldm makes them from A, B, C, cosAB, cosAC, cosBC: b/a, c/a,
    // then the cosines in the slots this ibrav reads (celldm(4) = cos γ for 5, -5, 12, 13;
    // celldm(5) = cos β for -12, -13; cos α, cos β, cos γ for 14); other slots are 0.
    let p: [Param; 5] = if abc.is_some() {
        let ratio = |key: &str| {
            let q = param(key);
            Param {
                value: q.value / a,
                ..q
            }
        };
        let zero = Param {
            value: 0.0,
            from: None,
        };
        let (c4, c5, c6) = match n {
            14 => (param("cosbc"), param("cosac"), param("cosab")),
            -12 | -13 => (zero, param("cosac"), zero),
            5 | -5 | 12 | 13 => (param("cosab"), zero, zero),
            _ => (zero, zero, zero),
        };
        [ratio("b"), ratio("c"), c4, c5, c6]
    } else {
        std::array::from_fn(|k| {
            param(
                [
                    "celldm(2)",
                    "celldm(3)",
                    "celldm(4)",
                    "celldm(5)",
                    "celldm(6)",
                ][k],
            )
        })
    };
    // A parameter the lattice needs, within pw.x's bounds, or the error at its token (at ibrav
    // when it is not given).
    let need = |k: usize, ok: fn(f64) -> bool, expected: &'static str| -> Result<f64, Error> {
        let q = p[k - 2];
        if ok(q.value) {
            return Ok(q.value);
        }
        Err(match q.from {
            Some(v) => ctx.parse(v.pos, &v.text, &v.text, expected),
            None => error_at(
                ctx,
                ibrav.pos,
                &ibrav.text,
                &ibrav.text,
                expected,
                format!("ibrav = {n} ({name}) without it"),
            ),
        })
    };
    const B: &str = "celldm(2) (b/a) or B > 0 in &SYSTEM, which this ibrav needs";
    const C: &str = "celldm(3) (c/a) or C > 0 in &SYSTEM, which this ibrav needs";
    let positive = |x: f64| x > 0.0;
    let cosine = |x: f64| x.abs() < 1.0;
    let ba = || need(2, positive, B);
    let ca = || need(3, positive, C);
    let h = a / 2.0;
    // The vectors of QE's latgen (INPUT_PW, `ibrav`), in Å.
    let m = match n {
        1 => [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]],
        2 => [[-h, 0.0, h], [0.0, h, h], [-h, h, 0.0]],
        3 => [[h, h, h], [-h, h, h], [-h, -h, h]],
        -3 => [[-h, h, h], [h, -h, h], [h, h, -h]],
        4 => {
            let c = a * ca()?;
            [
                [a, 0.0, 0.0],
                [-h, a * 3f64.sqrt() / 2.0, 0.0],
                [0.0, 0.0, c],
            ]
        }
        5 | -5 => {
            let g = need(
                4,
                |x| x > -0.5 && x < 1.0,
                "celldm(4) (cos γ; cosAB with A) in (-1/2, 1) for ibrav = 5 or -5",
            )?;
            if n == 5 {
                // Three-fold axis along z.
                let tx = ((1.0 - g) / 2.0).sqrt();
                let ty = ((1.0 - g) / 6.0).sqrt();
                let tz = ((1.0 + 2.0 * g) / 3.0).sqrt();
                [
                    [a * tx, -a * ty, a * tz],
                    [0.0, 2.0 * a * ty, a * tz],
                    [-a * tx, -a * ty, a * tz],
                ]
            } else {
                // Three-fold axis along (1,1,1).
                let (t1, t2) = ((1.0 + 2.0 * g).sqrt(), (1.0 - g).sqrt());
                let u = a * (t1 - 2.0 * t2) / 3.0;
                let v = a * (t1 + t2) / 3.0;
                [[u, v, v], [v, u, v], [v, v, u]]
            }
        }
        6 => [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a * ca()?]],
        7 => {
            let hc = h * ca()?;
            [[h, -h, hc], [h, h, hc], [-h, -h, hc]]
        }
        8 => [[a, 0.0, 0.0], [0.0, a * ba()?, 0.0], [0.0, 0.0, a * ca()?]],
        9 | -9 => {
            let (hb, c) = (h * ba()?, a * ca()?);
            if n == 9 {
                [[h, hb, 0.0], [-h, hb, 0.0], [0.0, 0.0, c]]
            } else {
                [[h, -hb, 0.0], [h, hb, 0.0], [0.0, 0.0, c]]
            }
        }
        91 => {
            let (hb, hc) = (h * ba()?, h * ca()?);
            [[a, 0.0, 0.0], [0.0, hb, -hc], [0.0, hb, hc]]
        }
        10 => {
            let (hb, hc) = (h * ba()?, h * ca()?);
            [[h, 0.0, hc], [h, hb, 0.0], [0.0, hb, hc]]
        }
        11 => {
            let (hb, hc) = (h * ba()?, h * ca()?);
            [[h, hb, hc], [-h, hb, hc], [-h, -hb, hc]]
        }
        12 | 13 => {
            let (b, c) = (a * ba()?, a * ca()?);
            let g = need(
                4,
                cosine,
                "celldm(4) (cos γ; cosAB with A) in (-1, 1) for ibrav = 12 or 13",
            )?;
            let v2 = [b * g, b * (1.0 - g * g).sqrt(), 0.0];
            if n == 12 {
                [[a, 0.0, 0.0], v2, [0.0, 0.0, c]]
            } else {
                [[h, 0.0, -c / 2.0], v2, [h, 0.0, c / 2.0]]
            }
        }
        -12 | -13 => {
            let (b, c) = (a * ba()?, a * ca()?);
            let beta = need(
                5,
                cosine,
                "celldm(5) (cos β; cosAC with A) in (-1, 1) for ibrav = -12 or -13",
            )?;
            let v3 = [c * beta, 0.0, c * (1.0 - beta * beta).sqrt()];
            if n == -12 {
                [[a, 0.0, 0.0], [0.0, b, 0.0], v3]
            } else {
                [[h, b / 2.0, 0.0], [-h, b / 2.0, 0.0], v3]
            }
        }
        _ => {
            // 14, triclinic.
            let (b, c) = (a * ba()?, a * ca()?);
            let al = need(
                4,
                cosine,
                "celldm(4) (cos α; cosBC with A) in (-1, 1) for ibrav = 14",
            )?;
            let be = need(
                5,
                cosine,
                "celldm(5) (cos β; cosAC with A) in (-1, 1) for ibrav = 14",
            )?;
            let ga = need(
                6,
                cosine,
                "celldm(6) (cos γ; cosAB with A) in (-1, 1) for ibrav = 14",
            )?;
            let sin_ga = (1.0 - ga * ga).sqrt();
            let term = 1.0 + 2.0 * al * be * ga - al * al - be * be - ga * ga;
            if term < 0.0 {
                return Err(error_at(
                    ctx,
                    ibrav.pos,
                    &ibrav.text,
                    &ibrav.text,
                    "cosines of the three angles of a cell with volume > 0 (1 + 2 cos α cos β \
                     cos γ − cos²α − cos²β − cos²γ > 0) for ibrav = 14",
                    format!("cos α {al}, cos β {be}, cos γ {ga}"),
                ));
            }
            [
                [a, 0.0, 0.0],
                [b * ga, b * sin_ga, 0.0],
                [
                    c * be,
                    c * (al - be * ga) / sin_ga,
                    c * (term / (1.0 - ga * ga)).sqrt(),
                ],
            ]
        }
    };
    Ok((m, a, cell_of(ctx, ibrav.pos, &ibrav.text, m)?))
}

/// One line of a namelist from byte `start` on: its `key = value` pairs into `values`; false
/// when the namelist closes on it (`/`, or `&end`).
fn namelist_line(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    start: usize,
    values: &mut System,
) -> Result<bool, Error> {
    const PAIR: &str = "key = value pairs, or the '/' that closes the namelist (an array's \
                        further values after a comma are not read: write key(i) = value)";
    let mut i = start;
    let at = |k: usize| Pos {
        line: pos.line,
        byte: pos.byte + k as u64,
    };
    loop {
        while i < line.len() && matches!(line[i], b' ' | b'\t' | b',' | b'\r') {
            i += 1;
        }
        if i == line.len() || line[i] == b'!' {
            return Ok(true);
        }
        if line[i] == b'/' {
            return Ok(false);
        }
        if line[i..].len() >= 4 && line[i..i + 4].eq_ignore_ascii_case(b"&end") {
            return Ok(false);
        }
        // The key, up to '='.
        let k0 = i;
        while i < line.len() && !matches!(line[i], b'=' | b',' | b'/' | b'!') {
            i += 1;
        }
        if i == line.len() || line[i] != b'=' {
            return Err(ctx.parse(pos, line, trim(&line[k0..i]), PAIR));
        }
        let key: Vec<u8> = line[k0..i]
            .iter()
            .filter(|b| !b.is_ascii_whitespace())
            .map(u8::to_ascii_lowercase)
            .collect();
        if key.is_empty() {
            return Err(ctx.parse(pos, line, &line[k0..=i], PAIR));
        }
        i += 1;
        while i < line.len() && matches!(line[i], b' ' | b'\t') {
            i += 1;
        }
        // The value: a quoted string, or up to white space, ',', '/' or '!'.
        let v0 = i;
        match line.get(i) {
            Some(&q @ (b'\'' | b'"')) => {
                let close = line[i + 1..].iter().position(|b| *b == q);
                let Some(close) = close else {
                    return Err(ctx.parse(pos, line, &line[i..], "a closing quote"));
                };
                i += close + 2;
            }
            _ => {
                while i < line.len()
                    && !matches!(line[i], b' ' | b'\t' | b',' | b'/' | b'!' | b'\r')
                {
                    i += 1;
                }
            }
        }
        if i == v0 {
            return Err(ctx.parse(pos, line, &line[k0..i], PAIR));
        }
        values.insert(
            key,
            Value {
                pos: at(v0),
                text: line[v0..i].to_vec(),
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_elements_as_ase_reads_them() {
        let sym = |l: &str| label_element(l.as_bytes()).map(|e| e.symbol());
        assert_eq!(sym("Fe1"), Some("Fe"));
        assert_eq!(sym("O_u"), Some("O"));
        assert_eq!(sym("O_up"), Some("O"));
        assert_eq!(sym("C-h"), Some("C"));
        assert_eq!(sym("Si"), Some("Si"));
        assert_eq!(sym("SI"), Some("Si"));
        assert_eq!(sym("Ob"), Some("O"));
        assert_eq!(sym("1a"), None);
    }

    #[test]
    fn expressions_as_pw_reads_coordinates() {
        let v = |s: &str| coordinate(s.as_bytes());
        assert_eq!(v("1/3"), Some(1.0 / 3.0));
        assert_eq!(v("-0.25"), Some(-0.25));
        assert_eq!(v("1.0d-1"), Some(0.1));
        assert_eq!(v("2*0.25"), Some(0.5));
        assert_eq!(v("(1+2)/3^2"), Some(3.0 / 9.0));
        assert_eq!(v("-2^2"), Some(-4.0));
        assert_eq!(v("2^-1"), Some(0.5));
        assert_eq!(v("1e-3*2"), Some(0.002));
        assert_eq!(v("1/0"), None);
        assert_eq!(v("(1"), None);
        assert_eq!(v("1+"), None);
        assert_eq!(v("abc"), None);
        assert_eq!(v(&"(".repeat(100)), None);
        assert_eq!(v(&"-".repeat(100)), None);
    }

    #[test]
    fn block_heads() {
        assert_eq!(
            block_head(b"ATOMIC_POSITIONS {crystal}"),
            (&b"ATOMIC_POSITIONS"[..], Some(Units::Crystal))
        );
        assert_eq!(
            block_head(b"CELL_PARAMETERS (alat= 10.20000000)"),
            (&b"CELL_PARAMETERS"[..], Some(Units::Alat(Some(10.2))))
        );
        assert_eq!(block_head(b"ATOMIC_POSITIONS").1, Some(Units::Default));
        assert_eq!(block_head(b"K_POINTS automatic").1, None);
    }

    #[test]
    fn sniffing() {
        assert!(is_output(
            b"\n     Program PWSCF v.6.7MaX starts on  7Dec2026\n"
        ));
        assert!(!is_output(b"Entering Gaussian System\n"));
        assert!(is_input(
            b"! a comment\n\n &control\n calculation='scf'\n/\n"
        ));
        assert!(is_input(b"&SYSTEM ibrav=2 /\n"));
        assert!(!is_input(b"&INPUTPH\n/\n"));
        assert!(!is_input(b"units real\n"));
    }
}

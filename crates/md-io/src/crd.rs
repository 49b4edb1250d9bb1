//! CHARMM coordinate files (`.crd`, `.cor`): the card (text) format of CHARMM's `WRITE COOR
//! CARD`, also written by CHARMM-GUI, MDAnalysis and ParmEd. One frame per title block: a file
//! that is several CRD files concatenated is a trajectory of their frames.
//!
//! A frame is title lines starting with `*` (the last is usually a lone `*`), an atom-count line
//! and one line per atom, in fixed columns (Fortran formats as CHARMM's io.doc gives them):
//!
//! - standard: count `(I5)`, atoms `(2I5,1X,A4,1X,A4,3F10.5,1X,A4,1X,A4,F10.5)`;
//! - extended, when the count line is `N  EXT` (CHARMM writes it past 99,999 atoms or with
//!   `EXTEnded`): count `(I10,2X,A)`, atoms `(2I10,2X,A8,2X,A8,3F20.10,2X,A8,2X,A8,F20.10)`.
//!
//! The atom fields, in order: atom number (kept as the id), residue number RESNO (counted from
//! the system's first residue), residue name, atom name, x y z (Å), segment id (SEGID, into
//! [`Frame::segments`](crate::Frame::segments)), residue id RESID (a string within the segment,
//! usually the residue's number in its chain), and the weighting array WMAIN (the `wmain`
//! property, what CHARMM's `scalar wmain` and `prop wmain` name; MDAnalysis reads it as
//! `tempfactors`). Each column is read by position, so a name may fill its field; a number
//! field must hold a number and nothing else, or the line is an error naming the column.
//!
//! **Residue numbers.** [`Frame::res_ids`](crate::Frame::res_ids) is RESID when it is an
//! integer (an insertion letter after the digits, `36A`, is dropped), as MDAnalysis's `resids`
//! and VMD's `resid` are; where RESID holds no number (blank, or a name such as `A1`), the atom
//! gets its RESNO, which always is one. The title lines, `*` removed and joined by spaces, are
//! the frame's comment. A frame whose segment ids are all blank has no segment column.
//! Elements are guessed from the atom and residue names
//! ([`crate::elements::guess_element`]).
//!
//! The count is checked against the atom lines, both ways: the file ending first is a cut
//! frame ([`Error::Truncated`]), and a title line (`*`) where an atom line should be says that
//! the count is larger than the frame. Nothing is reserved from the count beyond what the
//! file's size can hold.
//!
//! A `.crd` file may instead be an AMBER ASCII trajectory, which has no `*` title:
//! [`crate::Trajectory::open`] reads a `.crd` as CHARMM only when its first non-blank line
//! starts with `*`.
//!
//! # References
//! - CHARMM documentation, io.doc, "Reading coordinates": the card coordinate file format
//!   (title, NATOM, `ATOMNO RESNO RES TYPE X Y Z SEGID RESID Weighting`), and the EXTEnded
//!   format of `WRITE COOR CARD`.

use crate::elements::guess_element;
use crate::error::Error;
use crate::frame::{Frame, Label};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, res_number, span, trim};
use crate::text::{Ctx, LineReader, Pos, TextFormat, need_line};
use std::io::Read;

/// The CHARMM CRD parser.
#[derive(Default)]
pub(crate) struct Crd;

/// One layout's columns, 0-based `[start, end)`, and what an error names them.
struct Layout {
    atom: (usize, usize),
    resno: (usize, usize),
    res: (usize, usize),
    name: (usize, usize),
    /// Start and width of x; y and z follow.
    xyz: (usize, usize),
    segid: (usize, usize),
    resid: (usize, usize),
    weight: (usize, usize),
    what: [&'static str; 8],
}

/// `(2I5,1X,A4,1X,A4,3F10.5,1X,A4,1X,A4,F10.5)`.
const STANDARD: Layout = Layout {
    atom: (0, 5),
    resno: (5, 10),
    res: (11, 15),
    name: (16, 20),
    xyz: (20, 10),
    segid: (51, 55),
    resid: (56, 60),
    weight: (60, 70),
    what: [
        "an atom number in columns 1-5",
        "a residue number in columns 6-10",
        "a residue name in columns 12-15",
        "an atom name in columns 17-20",
        "3 coordinates (Å) in columns 21-50",
        "a segment id in columns 52-55",
        "a residue id in columns 57-60",
        "a weighting (WMAIN) in columns 61-70",
    ],
};

/// `(2I10,2X,A8,2X,A8,3F20.10,2X,A8,2X,A8,F20.10)`.
const EXTENDED: Layout = Layout {
    atom: (0, 10),
    resno: (10, 20),
    res: (22, 30),
    name: (32, 40),
    xyz: (40, 20),
    segid: (102, 110),
    resid: (112, 120),
    weight: (120, 140),
    what: [
        "an atom number in columns 1-10",
        "a residue number in columns 11-20",
        "a residue name in columns 23-30",
        "an atom name in columns 33-40",
        "3 coordinates (Å) in columns 41-100",
        "a segment id in columns 103-110",
        "a residue id in columns 113-120",
        "a weighting (WMAIN) in columns 121-140",
    ],
};

/// True for a title line: `*` first (after any indentation).
fn is_title(line: &[u8]) -> bool {
    trim(line).first() == Some(&b'*')
}

/// Reads the title lines and the count line of the frame starting at the next line: `None`
/// when the data ends first, else the atom count and whether the layout is extended. The
/// titles go to `comment` when given.
fn header<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    mut comment: Option<&mut String>,
) -> Result<Option<(usize, bool)>, Error> {
    let p = lines.pos();
    let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
        return Ok(None);
    };
    if !is_title(line) {
        return Err(ctx.parse(pos, line, trim(line), "a title line starting with '*'"));
    }
    let mut title = line;
    loop {
        if let Some(c) = comment.as_deref_mut() {
            let t = trim(&trim(title)[1..]);
            if !t.is_empty() {
                if !c.is_empty() {
                    c.push(' ');
                }
                c.push_str(&String::from_utf8_lossy(t));
            }
        }
        let (pos, line) = need_line(lines, ctx, "the atom count line after the title")?;
        if is_title(line) {
            title = line;
            continue;
        }
        let mut f = fields(line);
        let what = "the number of atoms ('N' or 'N  EXT')";
        let Some(count) = f.next() else {
            return Err(ctx.parse(pos, line, line, what));
        };
        let n = parse_usize(count).ok_or_else(|| ctx.parse(pos, line, count, what))?;
        let ext = match f.next() {
            None => false,
            Some(t) if t.eq_ignore_ascii_case(b"EXT") => true,
            Some(t) => return Err(ctx.parse(pos, line, t, what)),
        };
        if let Some(t) = f.next() {
            return Err(ctx.parse(pos, line, t, what));
        }
        return Ok(Some((n, ext)));
    }
}

/// The error for a title line met where atom line `i` of `n` should be: the count is larger
/// than the frame.
fn early_title(ctx: &Ctx, pos: Pos, line: &[u8]) -> Error {
    ctx.parse(
        pos,
        line,
        trim(line),
        "another atom line (the count line gives more atoms than the frame has)",
    )
}

/// A label field: trimmed, no blank inside, at most [`Label::CAPACITY`] bytes of UTF-8.
fn label(ctx: &Ctx, pos: Pos, line: &[u8], f: &[u8], what: &'static str) -> Result<Label, Error> {
    if f.contains(&b' ') || f.contains(&b'\t') {
        return Err(ctx.parse(pos, line, f, what));
    }
    Label::from_utf8(f).ok_or_else(|| ctx.parse(pos, line, f, what))
}

/// Parses one atom line in layout `l` into `frame`.
fn atom(ctx: &Ctx, pos: Pos, line: &[u8], l: &Layout, frame: &mut Frame) -> Result<(), Error> {
    let field = |(a, b): (usize, usize)| trim(span(line, a, b));
    let id_f = field(l.atom);
    let id = parse_i64(id_f).ok_or_else(|| ctx.parse(pos, line, id_f, l.what[0]))?;
    let resno_f = field(l.resno);
    let resno = parse_i64(resno_f).ok_or_else(|| ctx.parse(pos, line, resno_f, l.what[1]))?;
    let res = label(ctx, pos, line, field(l.res), l.what[2])?;
    let name = label(ctx, pos, line, field(l.name), l.what[3])?;
    let (x0, w) = l.xyz;
    let mut xyz = [0f32; 3];
    for (k, x) in xyz.iter_mut().enumerate() {
        let f = field((x0 + k * w, x0 + (k + 1) * w));
        *x = parse_f64(f)
            .map(|v| v as f32)
            .filter(|v| v.is_finite())
            .ok_or_else(|| ctx.parse(pos, line, f, l.what[4]))?;
    }
    let segment = label(ctx, pos, line, field(l.segid), l.what[5])?;
    let resid_f = field(l.resid);
    if resid_f.contains(&b' ') {
        return Err(ctx.parse(pos, line, resid_f, l.what[6]));
    }
    let resid = res_number(resid_f).unwrap_or(resno);
    let w_f = field(l.weight);
    let weight = parse_f64(w_f)
        .map(|v| v as f32)
        .filter(|v| v.is_finite())
        .ok_or_else(|| ctx.parse(pos, line, w_f, l.what[7]))?;
    frame.positions.push(xyz);
    frame.elements.push(guess_element(&name, Some(&res), None));
    frame.names.push(name);
    frame.res_names.push(res);
    frame.res_ids.push(resid);
    frame.ids.push(id);
    frame.segments.push(segment);
    frame.property_mut("wmain").push(weight);
    Ok(())
}

impl TextFormat for Crd {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        let Some((n, ext)) = header(lines, ctx, Some(&mut frame.comment))? else {
            return Ok(false);
        };
        let layout = if ext { &EXTENDED } else { &STANDARD };
        let reserve = n.min(ctx.reserve);
        frame.positions.reserve(reserve);
        frame.property_mut("wmain").reserve(reserve);
        for i in 0..n {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Err(ctx.truncated(p, format!("{} more atom lines of {n}", n - i)));
            };
            if is_title(line) {
                return Err(early_title(ctx, pos, line));
            }
            atom(ctx, pos, line, layout, frame)?;
        }
        if frame.segments.iter().all(|s| s.is_empty()) {
            frame.segments.clear();
        }
        Ok(true)
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        let Some((n, _)) = header(lines, ctx, None)? else {
            return Ok(false);
        };
        for i in 0..n {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                return Err(ctx.truncated(p, format!("{} more atom lines of {n}", n - i)));
            };
            if is_title(line) {
                return Err(early_title(ctx, pos, line));
            }
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use crate::{Format, Frame, Trajectory};
    use std::io::Cursor;

    fn read(text: &str) -> Result<Vec<Frame>, crate::Error> {
        let mut t = Trajectory::from_reader(Cursor::new(text.to_string()), Format::CharmmCrd, "t")?;
        let mut out = Vec::new();
        let mut f = Frame::new();
        while t.read_next(&mut f)? {
            out.push(f.clone());
        }
        Ok(out)
    }

    /// A standard atom line, as CHARMM's format writes it: atom and residue numbers, residue
    /// and atom names, position, segment and residue ids, weighting.
    fn std_line(
        (k, resno): (usize, usize),
        (res, name): (&str, &str),
        x: [f64; 3],
        (seg, resid): (&str, &str),
        w: f64,
    ) -> String {
        format!(
            "{k:5}{resno:5} {res:<4} {name:<4}{:10.5}{:10.5}{:10.5} {seg:<4} {resid:<4}{w:10.5}\n",
            x[0], x[1], x[2]
        )
    }

    #[test]
    fn standard_and_extended_frames() {
        let mut text = String::from("* TWO ATOMS\n*\n    2\n");
        text += &std_line((1, 1), ("TIP3", "OH2"), [1.0, 2.0, 3.0], ("WAT", "7"), 0.5);
        text += &std_line(
            (2, 1),
            ("TIP3", "H1"),
            [-1.0, -2.5, 0.25],
            ("WAT", "7A"),
            1.0,
        );
        text += "* SECOND\n         1  EXT\n";
        text += &format!(
            "{:10}{:10}  {:<8}  {:<8}{:20.10}{:20.10}{:20.10}  {:<8}  {:<8}{:20.10}\n",
            1, 1, "NA", "NA", 10.0, 20.0, 30.0, "IONS", "B1", 2.0
        );
        let f = read(&text).unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].comment, "TWO ATOMS");
        assert_eq!(f[0].positions, [[1.0, 2.0, 3.0], [-1.0, -2.5, 0.25]]);
        assert_eq!(f[0].names[0], "OH2");
        assert_eq!(f[0].res_ids, [7, 7]);
        assert_eq!(f[0].segments[1], "WAT");
        assert_eq!(f[0].property("wmain"), Some(&[0.5, 1.0][..]));
        assert_eq!(f[0].elements[0].symbol(), "O");
        assert_eq!(f[1].positions, [[10.0, 20.0, 30.0]]);
        // RESID `B1` is no number: the cumulative residue number stands in.
        assert_eq!(f[1].res_ids, [1]);
        assert_eq!(f[1].segments[0], "IONS");
        assert_eq!(f[1].property("wmain"), Some(&[2.0][..]));
        assert_eq!(f[1].elements[0].symbol(), "Na");
    }

    #[test]
    fn count_larger_than_the_frame_names_the_title_line() {
        let mut text = String::from("* A\n    2\n");
        text += &std_line((1, 1), ("TIP3", "OH2"), [1.0, 2.0, 3.0], ("WAT", "1"), 0.0);
        text += "* B\n    1\n";
        let e = read(&text).unwrap_err().to_string();
        assert!(e.starts_with("t: frame 0, line 4, byte "), "{e}");
        assert!(e.contains("more atoms than the frame has"), "{e}");
    }
}

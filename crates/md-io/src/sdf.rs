//! MDL molfiles and SD files (`.mol`, `.sdf`, `.sd`): the small-molecule format RDKit, Open
//! Babel, docking programs (AutoDock Vina through Meeko, GNINA, Glide exports) and PubChem
//! write. Each record is a frame: a multi-conformer file is a trajectory of one molecule, a
//! library of molecules one frame per molecule (atom counts may differ between frames).
//!
//! # What is read
//! A record is a three-line header (the first line, the molecule's name, becomes the frame's
//! comment), a counts line, the connection table, `M  END`, then, in an SD file, data items up
//! to a `$$$$` line. Both connection-table versions are read:
//! - **V2000** (the counts line's `V2000`, or no version): atom and bond counts in columns 1-3
//!   and 4-6; atom lines with x, y, z in columns 1-10, 11-20, 21-30 (Å) and the element symbol
//!   in columns 32-34; bond lines with the two atom numbers in columns 1-3 and 4-6 and the bond
//!   type in columns 7-9.
//! - **V3000** (`V3000` in the counts line; RDKit writes it past 999 atoms): `M  V30` lines,
//!   a `-` at a line's end continuing it on the next; `COUNTS na nb`, the `ATOM` block
//!   (`index type x y z ...`) and the `BOND` block (`index order atom atom ...`), bonds naming
//!   atoms by their index; other blocks (`SGROUP`, `COLLECTION`) are skipped.
//!
//! Each atom's name is its element symbol (molfiles have no atom names; PyMOL names them so
//! too), its id its number in the file. Bonds go to [`Frame::bonds`] (sorted, each once) with
//! their types in [`Frame::bond_orders`] (1-3, 4 aromatic, a query type 0). Formal charges
//! become the `charge` property (in e, integers; the property MOL2's and PQR's partial charges
//! fill) when some atom of the record is charged: in V2000 the `M  CHG` lines, which replace
//! every atom line's charge code (columns 37-39: 1-3 for +3..+1, 5-7 for -1..-3) as the CTfile
//! specification and RDKit have it, else those codes; in V3000 the atom's `CHG=`. Isotopes,
//! radicals are not kept. Data items: `step` and `time` (ps), which our SD writer writes,
//! become [`Frame::step`] and [`Frame::time`] (a value that is no number is left out); every
//! other item whose name is a key (letters, digits, `_`, `-`, `.`: GNINA's `minimizedAffinity`
//! and `CNNscore`, RDKit properties) and whose value is one line becomes a `KEY=value` pair on
//! the comment's second line, for [`Frame::comment_value`] and `--label '{minimizedAffinity}'`
//! (items named otherwise, and values of several lines, are left out). A symbol that is no element (`R#`, `*`, `A`, a
//! list) is an unknown element.
//!
//! # Damage
//! Errors name the file, frame, line and byte: a counts line without two counts, an atom line
//! whose coordinates or charge code are not numbers, an `M  CHG` line that is not a count
//! and as many atom number and charge pairs of the record, a bond naming an atom the record does not have (or one
//! atom twice), a record cut before its `M  END` (a truncation, so `allow_truncated` keeps the
//! records before it), and the marks of a damaged record end: a `$$$$` before `M  END`, or an
//! `M  END` or counts line before `$$$$` (two records are never read as one). Counts reserve room for at most as many atoms as the file's size allows.
//!
//! # References
//! - BIOVIA, "CTfile Formats" (2020): the V2000 and V3000 connection tables, SD files.

use std::fmt::Write as _;
use std::io::Read;

use crate::elements::Element;
use crate::error::Error;
use crate::frame::{Frame, Label};
use crate::parse::{fields, parse_f64, parse_i64, parse_usize, span, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};

/// The SD file / molfile parser.
#[derive(Default)]
pub(crate) struct Sdf;

/// The next line, or a truncation error saying what was expected.
fn need<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: impl FnOnce() -> String,
) -> Result<(Pos, &'a [u8]), Error> {
    let p = lines.pos();
    match lines.next_line().map_err(|e| ctx.io(p, e))? {
        Some(l) => Ok(l),
        None => Err(ctx.truncated(p, expected())),
    }
}

/// One atom into `frame`.
fn push_atom(frame: &mut Frame, xyz: [f32; 3], symbol: &[u8], id: i64) {
    let element = std::str::from_utf8(symbol)
        .ok()
        .and_then(Element::from_symbol)
        .unwrap_or(Element::UNKNOWN);
    frame.positions.push(xyz);
    frame.elements.push(element);
    frame
        .names
        .push(Label::from_utf8(symbol).unwrap_or_else(|| Label::new("?").expect("fits")));
    frame.ids.push(id);
}

/// The bond `a`-`b` (0-based) of a record of `n` atoms, or an error at `token`.
fn bond(a: usize, b: usize, n: usize, err: impl FnOnce() -> Error) -> Result<[u32; 2], Error> {
    if a == b || a >= n || b >= n {
        return Err(err());
    }
    Ok([a.min(b) as u32, a.max(b) as u32])
}

/// A coordinate field: a finite number.
fn coordinate(f: &[u8]) -> Option<f32> {
    parse_f64(f).map(|v| v as f32).filter(|v| v.is_finite())
}

impl FrameWalk for Sdf {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        // Header: name, program line, comment. Blank lines and then the end of the data are
        // the end of the file, not a cut record (writers end files with a newline or two).
        let mut blank = true;
        let mut title = None;
        for k in 0..3 {
            let p = lines.pos();
            let Some((_, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if blank {
                    return Ok(false);
                }
                return Err(ctx.truncated(p, "the rest of the molfile header".into()));
            };
            blank &= trim(line).is_empty();
            if k == 0 {
                title = Some(String::from_utf8_lossy(trim(line)).into_owned());
            }
        }
        let p = lines.pos();
        let Some((pos, counts)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            if blank {
                return Ok(false);
            }
            return Err(ctx.truncated(p, "the counts line".into()));
        };
        let v3000 = trim(span(counts, 33, 39)).eq_ignore_ascii_case(b"V3000");
        let count = |a, b, what| {
            let f = trim(span(counts, a, b));
            parse_usize(f).ok_or_else(|| ctx.parse(pos, counts, f, what))
        };
        let (n_atoms, n_bonds) = if v3000 {
            (0, 0)
        } else {
            (
                count(0, 3, "the atom count in columns 1-3")?,
                count(3, 6, "the bond count in columns 4-6")?,
            )
        };
        if let Some(f) = frame.as_deref_mut() {
            f.comment = title.unwrap_or_default();
        }
        let mut charges = Vec::new();
        let bonds = if v3000 {
            v3000_table(lines, ctx, frame.as_deref_mut(), &mut charges)?
        } else {
            v2000_table(
                lines,
                ctx,
                frame.as_deref_mut(),
                n_atoms,
                n_bonds,
                &mut charges,
            )?
        };
        // Properties up to M  END, then data items up to $$$$ (or the end of a molfile).
        // A damaged 'M  END' or '$$$$' must not merge two records into one: the other record's
        // marks met first are errors.
        let mut chg_seen = false;
        loop {
            let (pos, line) = need(lines, ctx, || "the properties block's 'M  END'".into())?;
            if line.starts_with(b"M  END") {
                break;
            }
            if !v3000 && let Some(rest) = line.strip_prefix(b"M  CHG") {
                // The first M  CHG line of a record replaces every atom line's charge code.
                if !chg_seen {
                    charges.fill(0);
                    chg_seen = true;
                }
                m_chg(rest, &mut charges)
                    .ok_or_else(|| ctx.parse(pos, line, line, M_CHG_EXPECTED))?;
            }
            if trim(line) == b"$$$$" {
                return Err(ctx.parse(pos, line, line, "'M  END' closing the properties block"));
            }
        }
        // The data items: `step` and `time` into the frame, other items as comment pairs (an
        // item's value when it is one line; a multi-line value is left out).
        let (mut item, mut step, mut time) = (None, None, None);
        let mut pairs: Vec<(String, String)> = Vec::new();
        // An item's one-line value read, and whether more lines followed it.
        let mut pending: Option<(String, String, bool)> = None;
        loop {
            let p = lines.pos();
            let line = match lines.next_line().map_err(|e| ctx.io(p, e))? {
                None => break,
                Some((_, line)) if trim(line) == b"$$$$" => break,
                Some((pos, line)) => {
                    let t = trim(line);
                    if t == b"M  END" || t.ends_with(b"V2000") || t.ends_with(b"V3000") {
                        return Err(ctx.parse(pos, line, line, "'$$$$' ending the record first"));
                    }
                    t
                }
            };
            if let Some((key, value, more)) = pending.take() {
                match (line.is_empty(), more) {
                    (true, false) => pairs.push((key, value)),
                    (true, true) => {}
                    (false, _) => pending = Some((key, value, true)),
                }
                continue;
            }
            match item.take() {
                Some(Item::Step) => step = parse_i64(line),
                Some(Item::Time) => time = parse_f64(line).filter(|v| v.is_finite()),
                Some(Item::Other(key)) if !line.is_empty() => {
                    let value = String::from_utf8_lossy(line).into_owned();
                    // A value with a double quote cannot be a pair's: left out as a long one.
                    pending = Some((key, value, line.contains(&b'"')));
                }
                Some(Item::Other(_)) => {}
                None => item = data_header(line),
            }
        }
        if let Some((key, value, false)) = pending {
            pairs.push((key, value));
        }
        if let Some(f) = frame {
            f.step = step;
            f.time = time;
            for (k, (key, value)) in pairs.iter().enumerate() {
                f.comment.push(if k == 0 { '\n' } else { ' ' });
                if value.contains([' ', '\t']) {
                    let _ = write!(f.comment, "{key}=\"{value}\"");
                } else {
                    let _ = write!(f.comment, "{key}={value}");
                }
            }
            crate::frame::set_ordered_bonds(f, bonds);
            if charges.iter().any(|&q| q != 0) {
                f.properties.push(crate::frame::Property {
                    name: "charge".into(),
                    values: charges.iter().map(|&q| q as f32).collect(),
                });
            }
        }
        Ok(true)
    }
}

/// The data items a frame keeps.
enum Item {
    Step,
    Time,
    /// Another item whose name is a comment key.
    Other(String),
}

/// Which kept item a data header line opens: `> <step>`, `> <time>` or another item named as
/// a comment key is (a letter or `_`, then letters, digits, `_`, `-`, `.`), also with the extra
/// space, a registry number or a `DT` field number other programs add (`>  <time>  (1)`).
fn data_header(line: &[u8]) -> Option<Item> {
    let rest = line.strip_prefix(b">")?;
    let open = rest.iter().position(|&b| b == b'<')?;
    let name = &rest[open + 1..];
    let close = name.iter().position(|&b| b == b'>')?;
    let name = &name[..close];
    let key = Frame::is_comment_key(name);
    match name {
        b"step" => Some(Item::Step),
        b"time" => Some(Item::Time),
        _ if key => Some(Item::Other(String::from_utf8_lossy(name).into_owned())),
        _ => None,
    }
}

const M_CHG_EXPECTED: &str =
    "'M  CHG' with a count of 1-8 and as many atom numbers of this record and charges";

/// The pairs of an `M  CHG` line (`rest`: the text after `M  CHG`) into `charges`; `None`
/// when it is not a count of 1-8 and that many atom numbers of the record and charges.
fn m_chg(rest: &[u8], charges: &mut [i32]) -> Option<()> {
    let mut w = fields(rest);
    let n = parse_usize(w.next()?).filter(|n| (1..=8).contains(n))?;
    for _ in 0..n {
        let atom = parse_usize(w.next()?).filter(|&a| a >= 1 && a <= charges.len())?;
        let q = parse_i64(w.next()?).and_then(|q| i32::try_from(q).ok())?;
        charges[atom - 1] = q;
    }
    w.next().is_none().then_some(())
}

/// The charge of a V2000 atom line's charge code (columns 37-39; blank is 0): 1-3 are +3..+1,
/// 5-7 are -1..-3, 4 a doublet radical (no charge); `None` for anything else.
fn charge_code(f: &[u8]) -> Option<i32> {
    if f.is_empty() {
        return Some(0);
    }
    match parse_usize(f)? {
        c @ 1..=3 => Some(4 - c as i32),
        c @ 5..=7 => Some(4 - c as i32),
        0 | 4 => Some(0),
        _ => None,
    }
}

/// An MDL bond type as a [`Frame::bond_orders`] value: 1-3 as they are, 4 aromatic, query
/// types (5-8) and anything else 0.
fn mdl_order(t: &[u8]) -> u8 {
    match parse_usize(trim(t)) {
        Some(o @ 1..=4) => o as u8,
        _ => 0,
    }
}

/// The V2000 atom and bond blocks; the bonds (0-based pairs) with their orders.
fn v2000_table<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    mut frame: Option<&mut Frame>,
    n_atoms: usize,
    n_bonds: usize,
    charges: &mut Vec<i32>,
) -> Result<Vec<([u32; 2], u8)>, Error> {
    charges.reserve(n_atoms.min(ctx.reserve));
    if let Some(f) = frame.as_deref_mut() {
        f.positions.reserve(n_atoms.min(ctx.reserve));
    }
    for i in 0..n_atoms {
        let (pos, line) = need(lines, ctx, || format!("{} more atom lines", n_atoms - i))?;
        let mut xyz = [0f32; 3];
        for (k, x) in xyz.iter_mut().enumerate() {
            let f = trim(span(line, 10 * k, 10 * k + 10));
            *x = coordinate(f).ok_or_else(|| {
                ctx.parse(pos, line, f, "x, y, z (Å) in columns 1-10, 11-20, 21-30")
            })?;
        }
        let symbol = trim(span(line, 31, 34));
        if symbol.is_empty() {
            return Err(ctx.parse(pos, line, line, "an element symbol in columns 32-34"));
        }
        let code = trim(span(line, 36, 39));
        charges.push(
            charge_code(code)
                .ok_or_else(|| ctx.parse(pos, line, code, "a charge code 0-7 in columns 37-39"))?,
        );
        if let Some(f) = frame.as_deref_mut() {
            push_atom(f, xyz, symbol, i as i64 + 1);
        }
    }
    let mut bonds = Vec::with_capacity(n_bonds.min(ctx.reserve));
    for i in 0..n_bonds {
        let (pos, line) = need(lines, ctx, || format!("{} more bond lines", n_bonds - i))?;
        let (fa, fb) = (trim(span(line, 0, 3)), trim(span(line, 3, 6)));
        let what = "two atom numbers of this record in columns 1-3 and 4-6";
        let (a, b) = match (parse_usize(fa), parse_usize(fb)) {
            (Some(a), Some(b)) if a >= 1 && b >= 1 => (a - 1, b - 1),
            _ => return Err(ctx.parse(pos, line, span(line, 0, 6), what)),
        };
        let pair = bond(a, b, n_atoms, || {
            ctx.parse(pos, line, span(line, 0, 6), what)
        })?;
        bonds.push((pair, mdl_order(span(line, 6, 9))));
    }
    Ok(bonds)
}

/// One logical `M  V30` line: the text after the prefix, continuation lines joined.
fn v30_line<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    expected: &'static str,
    out: &mut Vec<u8>,
) -> Result<Pos, Error> {
    out.clear();
    let (first, line) = need(lines, ctx, || expected.into())?;
    let Some(rest) = line.strip_prefix(b"M  V30 ") else {
        return Err(ctx.parse(first, line, line, "an 'M  V30' line of the V3000 table"));
    };
    out.extend_from_slice(rest);
    while out.last() == Some(&b'-') {
        out.pop();
        let (pos, line) = need(lines, ctx, || "the continued 'M  V30' line".into())?;
        let Some(rest) = line.strip_prefix(b"M  V30 ") else {
            return Err(ctx.parse(pos, line, line, "the continued 'M  V30' line"));
        };
        out.extend_from_slice(rest);
    }
    Ok(first)
}

/// The V3000 connection table up to `M  V30 END CTAB`; the bonds (0-based pairs) with their
/// orders.
fn v3000_table<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    mut frame: Option<&mut Frame>,
    charges: &mut Vec<i32>,
) -> Result<Vec<([u32; 2], u8)>, Error> {
    let mut text = Vec::new();
    // Errors point at the logical line's start: a joined line is no slice of the file.
    let at = |pos: Pos, text: &[u8], expected: &'static str| ctx.parse(pos, text, text, expected);
    let (mut n_atoms, mut n_bonds) = (None, 0usize);
    let mut index_of: Vec<(usize, u32)> = Vec::new();
    let mut bonds = Vec::new();
    loop {
        let pos = v30_line(lines, ctx, "the V3000 table's 'M  V30 END CTAB'", &mut text)?;
        /// What a logical line of the table starts.
        enum Line {
            End,
            Atoms,
            Bonds,
            Other,
        }
        let line = {
            let mut words = fields(&text);
            match (words.next(), words.next()) {
                (Some(b"END"), Some(b"CTAB")) => Line::End,
                (Some(b"COUNTS"), Some(na)) => {
                    let nb = words.next().unwrap_or(b"0");
                    match (parse_usize(na), parse_usize(nb)) {
                        (Some(a), Some(b)) => (n_atoms, n_bonds) = (Some(a), b),
                        _ => return Err(at(pos, &text, "COUNTS with the atom and bond counts")),
                    }
                    Line::Other
                }
                (Some(b"BEGIN"), Some(b"ATOM")) => Line::Atoms,
                (Some(b"BEGIN"), Some(b"BOND")) => Line::Bonds,
                _ => Line::Other,
            }
        };
        match line {
            Line::End => break,
            Line::Atoms => {
                let n = n_atoms.ok_or_else(|| at(pos, &text, "COUNTS before the atom block"))?;
                if let Some(f) = frame.as_deref_mut() {
                    f.positions.reserve(n.min(ctx.reserve));
                }
                for k in 0..n {
                    let pos = v30_line(lines, ctx, "an atom line of the V3000 table", &mut text)?;
                    let w: Vec<&[u8]> = fields(&text).take(5).collect();
                    let what = "an atom: index, type, x, y, z (Å)";
                    let [idx, symbol, x, y, z] = w[..] else {
                        return Err(at(pos, &text, what));
                    };
                    let (Some(idx), Some(x), Some(y), Some(z)) = (
                        parse_usize(idx),
                        coordinate(x),
                        coordinate(y),
                        coordinate(z),
                    ) else {
                        return Err(at(pos, &text, what));
                    };
                    // The atom's CHG=, among the keywords after the atom-atom mapping.
                    let mut q = 0;
                    for w in fields(&text).skip(6) {
                        if let Some(v) = w.strip_prefix(b"CHG=") {
                            q = parse_i64(v)
                                .and_then(|q| i32::try_from(q).ok())
                                .ok_or_else(|| at(pos, &text, "CHG= with an integer charge"))?;
                        }
                    }
                    charges.push(q);
                    index_of.push((idx, k as u32));
                    if let Some(f) = frame.as_deref_mut() {
                        push_atom(f, [x, y, z], symbol, idx as i64);
                    }
                }
                v30_end(lines, ctx, &mut text, b"ATOM")?;
                index_of.sort_unstable();
                if index_of.windows(2).any(|w| w[0].0 == w[1].0) {
                    return Err(at(pos, &text, "atom indices each used once"));
                }
            }
            Line::Bonds => {
                let n = n_atoms.unwrap_or(0);
                bonds.reserve(n_bonds.min(ctx.reserve));
                for _ in 0..n_bonds {
                    let pos = v30_line(lines, ctx, "a bond line of the V3000 table", &mut text)?;
                    let w: Vec<&[u8]> = fields(&text).take(4).collect();
                    let what = "a bond: index, order and two atom indices of this record";
                    let atom = |f: &[u8]| {
                        let i = parse_usize(f)?;
                        let k = index_of.binary_search_by_key(&i, |e| e.0).ok()?;
                        Some(index_of[k].1 as usize)
                    };
                    let (Some(a), Some(b)) = (
                        w.get(2).and_then(|f| atom(f)),
                        w.get(3).and_then(|f| atom(f)),
                    ) else {
                        return Err(at(pos, &text, what));
                    };
                    let pair = bond(a, b, n, || at(pos, &text, what))?;
                    bonds.push((pair, w.get(1).map_or(0, |t| mdl_order(t))));
                }
                v30_end(lines, ctx, &mut text, b"BOND")?;
            }
            // Other blocks and lines (SGROUP, COLLECTION, 3D) are skipped line by line.
            Line::Other => {}
        }
    }
    Ok(bonds)
}

/// The `M  V30 END <block>` line closing a block.
fn v30_end<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    text: &mut Vec<u8>,
    block: &[u8],
) -> Result<(), Error> {
    let pos = v30_line(lines, ctx, "the end of the V3000 block", text)?;
    let mut w = fields(text);
    if (w.next(), w.next()) != (Some(&b"END"[..]), Some(block)) {
        return Err(ctx.parse(
            pos,
            text,
            text,
            "the END line after the block's counted lines",
        ));
    }
    Ok(())
}

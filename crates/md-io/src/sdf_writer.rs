//! MDL SD files written ([`SdfWriter`], [`crate::Format::Sdf`]: `.sdf`, `.sd`, `.mol`): one
//! molfile record per frame, each ended by `$$$$`, for RDKit, Open Babel, PyMOL, ChimeraX and
//! the docking programs. Our reader (src/sdf.rs) reads every file written here back to the
//! same elements, positions (to the 4 decimals written), bonds and bond orders.
//!
//! # What is written
//! Per frame, as RDKit writes a molfile:
//! - **Header**: the title line is the frame's comment, its first line with control
//!   characters made blanks and cut to the 80 characters a molfile line may hold (our reader
//!   gives it back as the comment). A frame without a comment is titled with the output
//!   file's stem (`poses` for `poses.sdf`; `texmap` when it has none): a blank title line is
//!   valid, but our reader, like others that pass over blank lines between records, would take
//!   it for one; the program line
//!   `  texmap            3D` (program name in columns 3-10; the date columns 11-20 left
//!   blank, so that the same input always gives the same bytes; `3D` in columns 21-22); an
//!   empty comment line.
//! - **Connection table**: V2000 when the frame has at most 999 atoms and 999 bonds (the
//!   counts line's 3-digit fields) and its coordinates fit V2000's columns with a blank between
//!   them (x from -9999.9999 to 99999.9999 Å, y and z from -999.9999 to 9999.9999: RDKit reads
//!   two fields that touch as one number), else V3000 (`M  V30` lines, as RDKit writes past 999
//!   atoms, continued with `-` past 80 characters; read by RDKit, Open Babel, ChimeraX and our
//!   reader). So no finite frame is refused. Atoms are numbered 1, 2, ... in frame order (ids
//!   are not kept). Positions in Å with 4 decimals (`%10.4f` in V2000).
//! - **Element symbol**: the frame's element, else one guessed from the atom and residue names
//!   ([`crate::elements::guess_element`]), else `*` (an unknown atom: RDKit's and Open Babel's
//!   atomic number 0; our reader's unknown element).
//! - **Formal charges**: from the `charge` property when every one of the frame's values is an
//!   integer in -15..=15 (a file's formal charges); partial charges (MOL2, PDBQT, PQR, a
//!   force field's) are not formal charges and are not written. In V2000 both the atom line's
//!   charge code (for -3..=3) and `M  CHG` lines (which RDKit and the CTfile specification
//!   prefer); in V3000 `CHG=`.
//! - **Bonds** ([`Frame::bonds`]) with their types from [`Frame::bond_orders`]: 1, 2, 3, 4
//!   ([`crate::BOND_AROMATIC`]) as they are, 0 (a query or unknown type) as 8 ("any"); single
//!   (1) when the frame has bonds but no orders. A frame without bonds is written without
//!   bonds: a molfile of bare atoms. (`texmap convert` gives an SD file the topology's bonds, or
//!   bonds by distance, when the frame has none.)
//! - **Data items** after `M  END`: `> <step>` and `> <time>` (ps) when the frame has them,
//!   and, for a docked pose whose title is AutoDock Vina's `VINA RESULT: score ...` (our PDBQT
//!   reader's), `> <minimizedAffinity>` with the score in kcal/mol, as smina and GNINA name it;
//!   and one item per `KEY=value` pair on the comment's lines after the title (the data items
//!   our reader keeps there).
//!
//! Not written: cells, velocities, atom names, residues, chains, ids, other properties,
//! isotopes, stereo flags.
//!
//! # References
//! - BIOVIA, "CTfile Formats" (2020): the header block, V2000 counts, atom, bond and `M  CHG`
//!   lines, the V3000 CTAB, SD file data items.

use std::fmt::Write as _;
use std::io::{self, Write};

use crate::elements::Element;
use crate::frame::{BOND_AROMATIC, Frame};

/// Writes frames as SD file records (see the module doc).
pub(crate) struct SdfWriter<W> {
    pub out: W,
    /// The title of a frame without a comment: the file's stem.
    untitled: String,
}

/// The most atoms and bonds a V2000 counts line holds.
const V2000_MAX: usize = 999;

/// True when x fits `%10.4f` and y and z fit 9 columns (a blank before each: RDKit reads a
/// field that runs into the next as one number), as f64 so that no rounding is missed.
fn fits_v2000(p: [f32; 3]) -> bool {
    (-9999.99994..=99999.99994).contains(&(p[0] as f64))
        && p[1..]
            .iter()
            .all(|&v| (-999.99994..=9999.99994).contains(&(v as f64)))
}

/// Appends the logical V3000 line `text` to `s`: `M  V30 ` lines of at most 80 characters,
/// each but the last ending in the continuation mark `-`.
fn v30(s: &mut String, text: &str) {
    let mut rest = text;
    while rest.len() > 72 {
        // ASCII only: every cut is a character boundary.
        let (head, tail) = rest.split_at(72);
        s.push_str("M  V30 ");
        s.push_str(head);
        s.push_str("-\n");
        rest = tail;
    }
    s.push_str("M  V30 ");
    s.push_str(rest);
    s.push('\n');
}

/// The element symbol written for atom `i`.
fn symbol(frame: &Frame, i: usize) -> &'static str {
    let e = crate::pdb::written_element(frame, i);
    if e == Element::UNKNOWN {
        "*"
    } else {
        e.symbol()
    }
}

/// The formal charges: the `charge` property when every value is an integer in -15..=15.
fn formal_charges(frame: &Frame) -> Option<Vec<i32>> {
    let q = frame.property("charge")?;
    if q.len() != frame.n_atoms() {
        return None;
    }
    q.iter()
        .map(|&v| (v.fract() == 0.0 && (-15.0..=15.0).contains(&v)).then_some(v as i32))
        .collect()
}

/// The V2000 atom-line charge code of `q` (0 when only `M  CHG` can say it).
fn charge_code(q: i32) -> i32 {
    match q {
        1..=3 => 4 - q,
        -3..=-1 => 4 - q,
        _ => 0,
    }
}

/// The MDL bond type of bond `k`.
fn bond_type(frame: &Frame, k: usize) -> u8 {
    match frame.bond_orders.get(k) {
        None => 1,
        Some(&o @ (1..=3 | BOND_AROMATIC)) => o,
        Some(_) => 8,
    }
}

/// A title line: `text`'s first line, control characters as blanks, at most 80 bytes.
fn title_line(text: &str) -> String {
    let first = text.lines().next().unwrap_or("");
    let mut t = String::new();
    for c in first.chars() {
        let c = if c.is_control() { ' ' } else { c };
        if t.len() + c.len_utf8() > 80 {
            break;
        }
        t.push(c);
    }
    t.trim_end().to_string()
}

/// The score of a Vina pose's title `VINA RESULT: score rmsd_lb rmsd_ub`.
fn vina_score(title: &str) -> Option<&str> {
    let rest = title.strip_prefix("VINA RESULT:")?;
    let score = rest.split_whitespace().next()?;
    score.parse::<f64>().ok().filter(|v| v.is_finite())?;
    Some(score)
}

impl<W: Write> SdfWriter<W> {
    /// Writes to `out`, a file named `name` (its stem titles frames without a comment).
    pub fn new(out: W, name: &str) -> Self {
        let stem = std::path::Path::new(name)
            .file_stem()
            .map(|s| title_line(&s.to_string_lossy()))
            .unwrap_or_default();
        let untitled = if stem.is_empty() {
            "texmap".to_string()
        } else {
            stem
        };
        SdfWriter { out, untitled }
    }

    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        let mut s = String::with_capacity(80 * (frame.n_atoms() + frame.bonds.len() + 8));
        let mut title = title_line(&frame.comment);
        if title.is_empty() {
            title.clone_from(&self.untitled);
        }
        s.push_str(&title);
        s.push_str("\n  texmap            3D\n\n");
        let charges = formal_charges(frame);
        let q = |i: usize| charges.as_ref().map_or(0, |c| c[i]);
        let (na, nb) = (frame.n_atoms(), frame.bonds.len());
        let v2000 =
            na <= V2000_MAX && nb <= V2000_MAX && frame.positions.iter().all(|&p| fits_v2000(p));
        if v2000 {
            let _ = writeln!(s, "{na:>3}{nb:>3}  0  0  0  0  0  0  0  0999 V2000");
            for (i, p) in frame.positions.iter().enumerate() {
                // + 0.0: -0.0 is written 0.0000.
                let p = p.map(|x| x + 0.0);
                let _ = writeln!(
                    s,
                    "{:>10.4}{:>10.4}{:>10.4} {:<3} 0{:>3}  0  0  0  0  0  0  0  0  0  0",
                    p[0],
                    p[1],
                    p[2],
                    symbol(frame, i),
                    charge_code(q(i))
                );
            }
            for (k, b) in frame.bonds.iter().enumerate() {
                let (a, c) = (b[0] + 1, b[1] + 1);
                let _ = writeln!(s, "{a:>3}{c:>3}{:>3}  0", bond_type(frame, k));
            }
            let charged: Vec<(usize, i32)> = (0..na)
                .map(|i| (i + 1, q(i)))
                .filter(|c| c.1 != 0)
                .collect();
            for chunk in charged.chunks(8) {
                let _ = write!(s, "M  CHG{:>3}", chunk.len());
                for (i, c) in chunk {
                    let _ = write!(s, " {i:>3} {c:>3}");
                }
                s.push('\n');
            }
        } else {
            s.push_str("  0  0  0  0  0  0  0  0  0  0999 V3000\n");
            s.push_str("M  V30 BEGIN CTAB\n");
            let _ = writeln!(s, "M  V30 COUNTS {na} {nb} 0 0 0");
            s.push_str("M  V30 BEGIN ATOM\n");
            let mut line = String::new();
            for (i, p) in frame.positions.iter().enumerate() {
                let p = p.map(|x| x + 0.0);
                line.clear();
                let _ = write!(
                    line,
                    "{} {} {:.4} {:.4} {:.4} 0",
                    i + 1,
                    symbol(frame, i),
                    p[0],
                    p[1],
                    p[2]
                );
                if q(i) != 0 {
                    let _ = write!(line, " CHG={}", q(i));
                }
                v30(&mut s, &line);
            }
            s.push_str("M  V30 END ATOM\n");
            s.push_str("M  V30 BEGIN BOND\n");
            for (k, b) in frame.bonds.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "M  V30 {} {} {} {}",
                    k + 1,
                    bond_type(frame, k),
                    b[0] + 1,
                    b[1] + 1
                );
            }
            s.push_str("M  V30 END BOND\n");
            s.push_str("M  V30 END CTAB\n");
        }
        s.push_str("M  END\n");
        if let Some(step) = frame.step {
            let _ = write!(s, "> <step>\n{step}\n\n");
        }
        if let Some(time) = frame.time {
            let _ = write!(s, "> <time>\n{time}\n\n");
        }
        // The comment's pairs after its title line (our reader's data items), then a Vina
        // score from the title.
        let mut written: Vec<&str> = vec!["step", "time"];
        let rest = frame.comment.split_once('\n').map_or("", |(_, r)| r);
        for (key, value) in crate::xyz::key_values(rest.as_bytes()) {
            let (Ok(key), Ok(value)) = (std::str::from_utf8(key), std::str::from_utf8(value))
            else {
                continue;
            };
            if !value.is_empty() && !written.contains(&key) {
                let _ = write!(s, "> <{key}>\n{value}\n\n");
                written.push(key);
            }
        }
        if let Some(score) = vina_score(&title)
            && !written.contains(&"minimizedAffinity")
        {
            let _ = write!(s, "> <minimizedAffinity>\n{score}\n\n");
        }
        s.push_str("$$$$\n");
        self.out.write_all(s.as_bytes())
    }

    pub fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

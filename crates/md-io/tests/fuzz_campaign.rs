//! The fuzz campaign of every md-io reader (harness: tests/support/campaign.rs): each fixture of
//! tests/data (written by MDAnalysis, ASE, LAMMPS, OVITO, gemmi, PDB2PQR, ParmEd and the wwPDB;
//! see the READMEs there) and the DCD and
//! XTC our writers make, cut at every record boundary and at seeded offsets, with seeded bit
//! flips and byte replacements, header fields set to extremes, CRLF and NUL for text. Every
//! mutant is read twice, strict and with `allow_truncated`, through the public API (open,
//! `n_frames`, streaming, random access), and must end in `Ok` or an error naming the file and
//! the place, under a heap cap of 64 × its size + 1 MiB, without a panic.
//!
//! The record boundaries and header fields are found here by walking each format's structure
//! (Fortran record markers, XTC byte counts, TRR block sizes, the NetCDF header, the GSD index,
//! LAMMPS binary dump headers and chunks, line ends, numeric tokens), not by the readers under
//! test.
//!
//! Run with `cargo test -p texmap-md-io --test suite fuzz_campaign:: -- --nocapture` to see the table:
//! mutants per family and per outcome, the slowest run and the largest heap peak.

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;

use support::campaign::{Cuts, Field, Fixture, Settings, Verdict, line_starts, run_campaign};
use support::lammps_bin::{Layout, rewrite, walk, walk_bare};
use texmap_md_io::{Error, Format, Frame, MAX_COORDINATE, ReadOptions, Trajectory, Writer};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

/// An error is located if it names the file and a byte or line (and the frame, when it came
/// from reading frame `frame`).
fn located(e: &Error, name: &str, frame: Option<usize>) -> Verdict {
    let kind = match e {
        Error::Parse { .. } => "Parse",
        Error::Truncated { .. } => "Truncated",
        Error::Io { .. } => "Io",
        other => return Verdict::Broken(format!("error without a place: {other}")),
    };
    let Some(at) = e.location() else {
        return Verdict::Broken(format!("no location: {e}"));
    };
    if &*at.file != name || !e.to_string().starts_with(name) {
        return Verdict::Broken(format!("error does not name the file: {e}"));
    }
    if at.byte.is_none() && at.line.is_none() {
        return Verdict::Broken(format!("error names no byte or line: {e}"));
    }
    if let Some(k) = frame
        && at.frame != Some(k)
    {
        return Verdict::Broken(format!("reading frame {k} gave an error for another: {e}"));
    }
    Verdict::Located(kind)
}

/// Reads a mutant through the public API: open, count, stream (also when the count failed: a
/// caller may stream without counting), then random access.
fn read(format: Format, name: &str, bytes: &[u8], opts: ReadOptions) -> Verdict {
    let mut t = match Trajectory::from_reader_with(Cursor::new(bytes), format, name, opts) {
        Ok(t) => t,
        Err(e) => return located(&e, name, None),
    };
    let count = t.n_frames();
    if let Err(e) = &count {
        // A count that fails names the frame it could not pass.
        if let Verdict::Broken(why) = located(e, name, None) {
            return Verdict::Broken(format!("n_frames: {why}"));
        }
        if e.location().is_some_and(|at| at.frame.is_none()) {
            return Verdict::Broken(format!("n_frames error without a frame: {e}"));
        }
    }
    let mut f = Frame::new();
    let mut k = 0;
    loop {
        match t.read_next(&mut f) {
            Ok(true) => {
                if let Err(why) = f.check() {
                    return Verdict::Broken(format!("frame {k} breaks an invariant: {why}"));
                }
                let limit = MAX_COORDINATE as f32;
                if f.positions
                    .iter()
                    .flatten()
                    .any(|v| v.is_nan() || v.abs() > limit)
                {
                    return Verdict::Broken(format!("frame {k} has a coordinate beyond 1e7 Å"));
                }
                k += 1;
                if let Ok(n) = count
                    && k > n
                {
                    return Verdict::Broken(format!("more frames streamed than n_frames {n}"));
                }
            }
            Ok(false) => break,
            Err(e) => {
                // The count checks structure, streaming also content: it may stop earlier,
                // never later than the frame the count could not pass.
                if let Err(c) = &count
                    && c.location()
                        .and_then(|at| at.frame)
                        .is_some_and(|cf| k > cf)
                {
                    return Verdict::Broken(format!(
                        "n_frames failed with {c}, streaming with {e}"
                    ));
                }
                return located(&e, name, Some(k));
            }
        }
    }
    let n = match count {
        Ok(n) => n,
        Err(e) => return Verdict::Broken(format!("n_frames failed ({e}) but streaming did not")),
    };
    if k != n {
        return Verdict::Broken(format!("{k} frames streamed, n_frames said {n}"));
    }
    // Frames that streamed read again by index.
    for i in [n.saturating_sub(1), 0] {
        if i < n
            && let Err(e) = t.read_frame(i, &mut f)
        {
            return Verdict::Broken(format!("frame {i} streamed but not by index: {e}"));
        }
    }
    Verdict::Ok { frames: n }
}

/// Strict, then lenient: the strict verdict is tallied; the lenient one must not break the
/// contract, and must agree wherever strict reading succeeded.
fn run(format: Format) -> impl Fn(&Fixture, &[u8]) -> Verdict {
    let base = base_options(format);
    move |fx, bytes| {
        let strict = read(format, &fx.name, bytes, base.clone());
        let lenient = read(format, &fx.name, bytes, base.clone().allow_truncated(true));
        // A cut of a file whose frame ends are known keeps exactly the complete frames under
        // allow_truncated (XTC and TRR cannot open without one complete frame).
        if let Cuts::FrameEnds(ends) = &fx.cuts
            && bytes.len() < fx.bytes.len()
            && fx.bytes.starts_with(bytes)
        {
            let complete = ends.iter().filter(|&&e| e > 0 && e <= bytes.len()).count();
            match &lenient {
                Verdict::Ok { frames } if *frames == complete => {}
                Verdict::Located(_) if complete == 0 => {}
                other => {
                    return Verdict::Broken(format!(
                        "allow_truncated kept {other:?}, {complete} frames are complete"
                    ));
                }
            }
        }
        match (&strict, lenient) {
            (_, Verdict::Broken(why)) => Verdict::Broken(format!("allow_truncated: {why}")),
            (Verdict::Ok { frames: a }, Verdict::Ok { frames: b }) if *a != b => {
                Verdict::Broken(format!("strict read {a} frames, allow_truncated {b}"))
            }
            (Verdict::Ok { .. }, Verdict::Located(kind)) => {
                Verdict::Broken(format!("strict read it, allow_truncated failed: {kind}"))
            }
            _ => strict,
        }
    }
}

/// The options a format's fixtures are read with: an AMBER ASCII trajectory needs its
/// topology's atom count (the fixtures': 66).
fn base_options(format: Format) -> ReadOptions {
    if format == Format::AmberTrj {
        ReadOptions::new().atoms(66)
    } else {
        ReadOptions::new()
    }
}

fn frames_of(format: Format, bytes: &[u8]) -> usize {
    Trajectory::from_reader_with(Cursor::new(bytes), format, "good", base_options(format))
        .unwrap()
        .n_frames()
        .unwrap()
}

fn le32(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

fn be32(b: &[u8], at: usize) -> usize {
    u32::from_be_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

/// DCD (32-bit little-endian markers): every record's start and end; header control words,
/// NTITLE, NATOM and frame 0's first cell and coordinate values as fields.
fn dcd_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let mut boundaries = vec![0];
    let mut records = Vec::new();
    let mut at = 0;
    while at + 4 <= bytes.len() {
        let len = le32(&bytes, at);
        records.push(at);
        at += 8 + len;
        boundaries.extend([at - 4 - len, at - 4, at]);
    }
    assert_eq!(at, bytes.len(), "{name}: records tile the file");
    // Records: header, title, atoms, then frames (no fixed atoms in these files).
    let (title, natom, frame0) = (records[1], records[2], records[3]);
    let mut fields = vec![
        ("first marker", Field::I32Le(0)),
        ("NSET", Field::I32Le(8)),
        ("DELTA", Field::F32Le(8 + 36)),
        ("NAMNF", Field::I32Le(8 + 32)),
        ("cell flag", Field::I32Le(8 + 40)),
        ("4D flag", Field::I32Le(8 + 44)),
        ("CHARMM version", Field::I32Le(8 + 76)),
        ("title marker", Field::I32Le(title)),
        ("NTITLE", Field::I32Le(title + 4)),
        ("NATOM marker", Field::I32Le(natom)),
        ("NATOM", Field::I32Le(natom + 4)),
        ("frame 0 first marker", Field::I32Le(frame0)),
        ("frame 0 cell A", Field::F64Le(frame0 + 4)),
        ("frame 0 cell gamma", Field::F64Le(frame0 + 12)),
    ];
    if le32(&bytes, frame0) == 48 {
        fields.push(("frame 0 x[0]", Field::F32Le(frame0 + 56 + 4)));
    }
    Fixture {
        frames: frames_of(Format::Dcd, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::Declared,
        fields,
        text: false,
    }
}

/// XTC (magic 1995, compressed frames): each frame's start, header, prelude, byte count and
/// end; the header values of the first and last frame as fields.
fn xtc_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let mut starts = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        assert!(be32(&bytes, at + 4) > 9, "{name}: compressed frames only");
        starts.push(at);
        at += 92 + be32(&bytes, at + 88).div_ceil(4) * 4;
    }
    assert_eq!(at, bytes.len(), "{name}: frames tile the file");
    let mut ends: Vec<usize> = starts[1..].to_vec();
    ends.extend([0, bytes.len()]);
    let boundaries = starts
        .iter()
        .flat_map(|&s| [s, s + 56, s + 88, s + 92])
        .chain(ends.iter().copied())
        .collect();
    let mut fields = Vec::new();
    for s in [starts[0], *starts.last().unwrap()] {
        fields.extend([
            ("magic", Field::I32Be(s)),
            ("natoms", Field::I32Be(s + 4)),
            ("step", Field::I32Be(s + 8)),
            ("time", Field::F32Be(s + 12)),
            ("box xx", Field::F32Be(s + 16)),
            ("natoms again", Field::I32Be(s + 52)),
            ("both atom counts", Field::I32BeTwice(s + 4, s + 52)),
            ("precision", Field::F32Be(s + 56)),
            ("minint x", Field::I32Be(s + 60)),
            ("maxint z", Field::I32Be(s + 80)),
            ("smallidx", Field::I32Be(s + 84)),
            ("byte count", Field::I32Be(s + 88)),
        ]);
    }
    Fixture {
        frames: frames_of(Format::Xtc, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::FrameEnds(ends),
        fields,
        text: false,
    }
}

/// TRR (single precision, a box in every frame): each frame's start, header end and block
/// ends; the sizes, atom count, step, time and box of frame 0 as fields.
fn trr_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let mut boundaries = vec![0];
    let mut ends = vec![0];
    let mut at = 0;
    while at < bytes.len() {
        let size = |k: usize| be32(&bytes, at + 24 + 4 * k);
        let header = 24 + 13 * 4 + 2 * 4;
        let mut p = at + header;
        boundaries.extend([at, p]);
        for k in [2, 3, 4, 7, 8, 9] {
            p += size(k);
            boundaries.push(p);
        }
        at = p;
        ends.push(at);
    }
    assert_eq!(at, bytes.len(), "{name}: frames tile the file");
    let fields = vec![
        ("magic", Field::I32Be(0)),
        ("version", Field::I32Be(4)),
        ("box size", Field::I32Be(32)),
        ("x size", Field::I32Be(52)),
        ("v size", Field::I32Be(56)),
        ("f size", Field::I32Be(60)),
        ("natoms", Field::I32Be(64)),
        ("step", Field::I32Be(68)),
        ("time", Field::F32Be(76)),
        ("box xx", Field::F32Be(84)),
    ];
    Fixture {
        frames: frames_of(Format::Trr, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::FrameEnds(ends),
        fields,
        text: false,
    }
}

/// AMBER NetCDF (CDF-1 or CDF-2): the header walked here (names, attribute values, variable
/// entries); every list and variable entry start, the header end and each record variable's
/// slice of every record as boundaries; numrecs, the dimension lengths, every variable's type,
/// size and begin, and frame 0's first coordinate as fields.
fn netcdf_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let offset64 = bytes[3] == 2;
    let mut p = 8;
    let mut boundaries = vec![0, 4, 8];
    let mut fields = vec![("magic", Field::I32Be(0)), ("numrecs", Field::I32Be(4))];
    let padded = |n: usize| n.div_ceil(4) * 4;
    let name_at = |p: &mut usize| {
        let n = be32(&bytes, *p);
        *p += 4 + padded(n);
    };
    let type_size = |t: usize| [0, 1, 1, 2, 4, 4, 8][t];
    // Dimensions.
    let n_dims = be32(&bytes, p + 4);
    fields.push(("dimension count", Field::I32Be(p + 4)));
    p += 8;
    let mut dim_len = Vec::new();
    for _ in 0..n_dims {
        boundaries.push(p);
        name_at(&mut p);
        fields.push(("dimension length", Field::I32Be(p)));
        dim_len.push(be32(&bytes, p));
        p += 4;
    }
    let attrs = |p: &mut usize, fields: &mut Vec<(&'static str, Field)>, b: &mut Vec<usize>| {
        let n = be32(&bytes, *p + 4);
        fields.push(("attribute count", Field::I32Be(*p + 4)));
        *p += 8;
        for _ in 0..n {
            b.push(*p);
            name_at(p);
            let t = be32(&bytes, *p);
            fields.push(("attribute value count", Field::I32Be(*p + 4)));
            let count = be32(&bytes, *p + 4);
            *p += 8 + padded(count * type_size(t));
        }
    };
    attrs(&mut p, &mut fields, &mut boundaries);
    let n_vars = be32(&bytes, p + 4);
    fields.push(("variable count", Field::I32Be(p + 4)));
    p += 8;
    // (begin, one record's bytes, is a record variable)
    let mut vars = Vec::new();
    for _ in 0..n_vars {
        boundaries.push(p);
        name_at(&mut p);
        let rank = be32(&bytes, p);
        fields.push(("variable rank", Field::I32Be(p)));
        let dims: Vec<usize> = (0..rank).map(|k| be32(&bytes, p + 4 + 4 * k)).collect();
        p += 4 + 4 * rank;
        attrs(&mut p, &mut fields, &mut boundaries);
        let t = be32(&bytes, p);
        fields.push(("variable type", Field::I32Be(p)));
        fields.push(("variable vsize", Field::I32Be(p + 4)));
        let begin = if offset64 {
            fields.push(("variable begin (high)", Field::I32Be(p + 8)));
            fields.push(("variable begin (low)", Field::I32Be(p + 12)));
            let b = u64::from_be_bytes(bytes[p + 8..p + 16].try_into().unwrap()) as usize;
            p += 16;
            b
        } else {
            fields.push(("variable begin", Field::I32Be(p + 8)));
            let b = be32(&bytes, p + 8);
            p += 12;
            b
        };
        let record = dims.first().is_some_and(|d| dim_len[*d] == 0);
        let size = dims
            .iter()
            .skip(record as usize)
            .map(|d| dim_len[*d])
            .product::<usize>()
            * type_size(t);
        vars.push((begin, size, record));
    }
    boundaries.push(p);
    let rec: Vec<_> = vars.iter().filter(|v| v.2).collect();
    let recsize: usize = rec.iter().map(|v| padded(v.1)).sum();
    let frames = frames_of(Format::Netcdf, &bytes);
    for k in 0..frames {
        for v in &rec {
            boundaries.extend([v.0 + k * recsize, v.0 + k * recsize + v.1]);
        }
    }
    let first = rec.iter().map(|v| v.0).min().unwrap();
    fields.push(("frame 0 x of atom 0", Field::F32Be(first)));
    assert_eq!(
        first + frames * recsize,
        bytes.len(),
        "{name}: records tile the file"
    );
    Fixture {
        frames,
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::Declared,
        fields,
        text: false,
    }
}

/// HOOMD-blue GSD (little-endian, a 256-byte header, an index of 32-byte entries, a namelist),
/// walked by tests/support/gsd_index.rs (not by the reader): the header's fields, the blocks'
/// ends and every chunk's start and end as boundaries; the header's counts and versions, the
/// fields of the first entries and of frame 0's position entry, and frame 0's particle count,
/// first coordinate and box as fields.
fn gsd_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    let (index, slots) = (u64_at(8), u64_at(16));
    let (names_at, segments) = (u64_at(24), u64_at(32));
    let mut boundaries = vec![0, 8, 40, 48, 112, 176, 256];
    boundaries.extend([
        index,
        index + 32 * slots,
        names_at,
        names_at + 64 * segments,
    ]);
    let mut fields = vec![
        ("index location", Field::I32Le(8)),
        ("index entries", Field::I32Le(16)),
        ("index entries (high)", Field::I32Le(20)),
        ("namelist location", Field::I32Le(24)),
        ("namelist segments", Field::I32Le(32)),
        ("schema version", Field::I32Le(40)),
        ("file format version", Field::I32Le(44)),
    ];
    let chunks = support::gsd_index::chunks(&bytes);
    for (k, c) in chunks.iter().enumerate() {
        boundaries.extend([c.location, c.location + c.bytes()]);
        let frame0 = c.frame == 0;
        if k < 3 || k == chunks.len() - 1 || (frame0 && c.name == "particles/position") {
            let at = c.entry;
            fields.extend([
                ("entry frame", Field::I32Le(at)),
                ("entry N", Field::I32Le(at + 8)),
                ("entry location", Field::I32Le(at + 16)),
                ("entry location (high)", Field::I32Le(at + 20)),
                ("entry M", Field::I32Le(at + 24)),
                ("entry id and type", Field::I32Le(at + 28)),
            ]);
        }
        let loc = c.location;
        match c.name.as_str() {
            "particles/N" | "bonds/N" if frame0 => fields.push(("a count", Field::I32Le(loc))),
            "particles/position" if frame0 => fields.push(("x of particle 0", Field::F32Le(loc))),
            "configuration/box" if frame0 => fields.push(("box Lx", Field::F32Le(loc))),
            _ => {}
        }
    }
    Fixture {
        frames: frames_of(Format::Gsd, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::Declared,
        fields,
        text: false,
    }
}

/// LAMMPS binary dump as LAMMPS writes it (revision 2, walked by tests/support/lammps_bin.rs,
/// not by the reader): every header field's start, each chunk's count and values and each
/// frame's end as boundaries; the header fields of the first and last frame (the low half of
/// the i64 ones), the first chunk's count and first value as fields.
fn lammps_bin_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let frames = walk(&bytes);
    let mut boundaries = vec![0];
    let mut ends = vec![0];
    for f in &frames {
        boundaries.extend([
            f.start,
            f.endian,
            f.step,
            f.natoms,
            f.triclinic,
            f.box_at,
            f.size_one,
            f.units,
            f.time_flag,
            f.columns,
            f.nchunk,
            f.end,
        ]);
        for &(count, values, _) in &f.chunks {
            boundaries.extend([count, values]);
        }
        ends.push(f.end);
    }
    let mut fields = Vec::new();
    for f in [&frames[0], frames.last().unwrap()] {
        fields.extend([
            ("magic length", Field::I32Le(f.start)),
            ("endian flag", Field::I32Le(f.endian)),
            ("revision", Field::I32Le(f.revision)),
            ("timestep", Field::I32Le(f.step)),
            ("natoms", Field::I32Le(f.natoms)),
            ("triclinic flag", Field::I32Le(f.triclinic)),
            ("boundary xlo", Field::I32Le(f.boundary)),
            ("box xlo", Field::F64Le(f.box_at)),
            ("box xhi", Field::F64Le(f.box_at + 8)),
            ("size_one", Field::I32Le(f.size_one)),
            ("units length", Field::I32Le(f.units)),
            ("columns length", Field::I32Le(f.columns)),
            ("nchunk", Field::I32Le(f.nchunk)),
        ]);
        if let Some(t) = f.time {
            fields.push(("time", Field::F64Le(t)));
        }
        if let Some(&(count, values, n)) = f.chunks.first() {
            fields.push(("chunk 0 count", Field::I32Le(count)));
            if n > 0 {
                fields.push(("atom 0 first value", Field::F64Le(values)));
            }
        }
    }
    Fixture {
        frames: frames_of(Format::LammpsBin, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::FrameEnds(ends),
        fields,
        text: false,
    }
}

/// A LAMMPS binary dump in an older LAMMPS's layout (no magic header, no names: `dump atom`'s
/// default columns are assumed), little-endian: each frame's chunk count and end as boundaries,
/// frame 0's header fields as fields.
fn lammps_bin_bare_fixture(name: &str, bytes: Vec<u8>) -> Fixture {
    let frames = walk_bare(&bytes);
    let mut boundaries = vec![0];
    let mut ends = vec![0];
    for &(end, nchunk) in &frames {
        boundaries.extend([nchunk, nchunk + 4, end]);
        ends.push(end);
    }
    let fields = vec![
        ("timestep", Field::I32Le(0)),
        ("natoms", Field::I32Le(8)),
        ("triclinic flag", Field::I32Le(16)),
        ("boundary xlo", Field::I32Le(20)),
        ("box xlo", Field::F64Le(44)),
        ("size_one", Field::I32Le(frames[0].1 - 4)),
        ("nchunk", Field::I32Le(frames[0].1)),
        ("chunk 0 count", Field::I32Le(frames[0].1 + 4)),
        ("atom 0 xs", Field::F64Le(frames[0].1 + 8 + 16)),
    ];
    Fixture {
        frames: frames_of(Format::LammpsBin, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::FrameEnds(ends),
        fields,
        text: false,
    }
}

/// A text file: every line start as a boundary, its first 16 numeric tokens (counts, box,
/// coordinates) as fields.
fn text_fixture(name: &str, format: Format) -> Fixture {
    let bytes = data(name);
    let boundaries = line_starts(&bytes);
    let mut fields = Vec::new();
    let mut i = 0;
    while i < bytes.len() && fields.len() < 16 {
        let start_of_token = i == 0 || bytes[i - 1].is_ascii_whitespace();
        if start_of_token && (bytes[i].is_ascii_digit() || bytes[i] == b'-') {
            let end = (i..bytes.len())
                .find(|&j| bytes[j].is_ascii_whitespace())
                .unwrap_or(bytes.len());
            if std::str::from_utf8(&bytes[i..end])
                .ok()
                .and_then(|t| t.parse::<f64>().ok())
                .is_some()
            {
                fields.push(("number", Field::Text(i, end)));
            }
            i = end;
        } else {
            i += 1;
        }
    }
    Fixture {
        frames: frames_of(format, &bytes),
        name: name.into(),
        bytes,
        boundaries,
        cuts: Cuts::Unchecked,
        fields,
        text: true,
    }
}

/// What our writers make of the MDAnalysis XTC's frames (DCD with cells, XTC compressed).
fn ours(format: Format) -> Vec<u8> {
    let good = data("xtc_mda.xtc");
    let mut t = Trajectory::from_reader(Cursor::new(&good[..]), Format::Xtc, "x").unwrap();
    let mut w = Writer::new(Cursor::new(Vec::new()), format, "ours").unwrap();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        w.write_frame(&f).unwrap();
    }
    w.finish().unwrap().into_inner()
}

fn campaign(reader: &str, format: Format, fixtures: Vec<Fixture>) {
    let tally = run_campaign(reader, &fixtures, &Settings::default(), &run(format));
    println!("{}", tally.report());
    assert!(tally.mutants > 0);
    assert!(tally.failures.is_empty(), "{}", tally.report());
}

#[test]
fn dcd_campaign() {
    campaign(
        "DCD",
        Format::Dcd,
        vec![
            dcd_fixture("dcd_mda.dcd", data("dcd_mda.dcd")),
            dcd_fixture("ours.dcd", ours(Format::Dcd)),
        ],
    );
}

#[test]
fn xtc_campaign() {
    campaign(
        "XTC",
        Format::Xtc,
        vec![
            xtc_fixture("xtc_mda.xtc", data("xtc_mda.xtc")),
            xtc_fixture("ours.xtc", ours(Format::Xtc)),
        ],
    );
}

#[test]
fn trr_campaign() {
    campaign(
        "TRR",
        Format::Trr,
        vec![trr_fixture("trr_mda.trr", data("trr_mda.trr"))],
    );
}

/// LAMMPS binary dumps written by LAMMPS (tests/data/lammps_bin/gen.sh): 2 chunks per frame,
/// a triclinic box with a changing atom count (one frame empty), dump atom's scaled columns;
/// and dump atom's frames in an older LAMMPS's layout, both byte orders.
#[test]
fn lammps_bin_campaign() {
    let bin = |name: &str| data(&format!("lammps_bin/{name}"));
    let atom = bin("atom_np1.bin");
    let bare_le = rewrite(&atom, Layout::Bare, false);
    let bare_be = rewrite(&atom, Layout::Bare, true);
    let mut be = lammps_bin_bare_fixture("atom_np1_bare_be.bin", bare_le.clone());
    // The same boundaries serve the big-endian twin (same sizes); its fields are big-endian.
    be.bytes = bare_be;
    be.fields = vec![
        ("natoms", Field::I32Be(12)),
        ("triclinic flag", Field::I32Be(16)),
        ("size_one", Field::I32Be(be.boundaries[1] - 4)),
        ("nchunk", Field::I32Be(be.boundaries[1])),
    ];
    campaign(
        "LAMMPS binary dump",
        Format::LammpsBin,
        vec![
            lammps_bin_fixture("custom_np2.bin", bin("custom_np2.bin")),
            lammps_bin_fixture("tri_np2.bin", bin("tri_np2.bin")),
            lammps_bin_fixture("atom_np1.bin", atom),
            lammps_bin_bare_fixture("atom_np1_bare.bin", bare_le),
            be,
        ],
    );
}

#[test]
fn netcdf_campaign() {
    campaign(
        "AMBER NetCDF",
        Format::Netcdf,
        vec![
            netcdf_fixture("amber_mda.ncdf", data("amber_mda.ncdf")),
            netcdf_fixture("amber_scipy_cdf1.nc", data("amber_scipy_cdf1.nc")),
        ],
    );
}

#[test]
fn gsd_campaign() {
    campaign(
        "HOOMD GSD",
        Format::Gsd,
        vec![
            gsd_fixture("hoomd_tri.gsd", data("gsd/hoomd_tri.gsd")),
            gsd_fixture("hoomd_2d.gsd", data("gsd/hoomd_2d.gsd")),
            gsd_fixture("hoomd_v1.gsd", data("gsd/hoomd_v1.gsd")),
        ],
    );
}

#[test]
fn xyz_campaign() {
    let files = ["ase_ext.xyz", "ase_plain.xyz"];
    let fx = files.map(|f| text_fixture(f, Format::Xyz));
    campaign("XYZ", Format::Xyz, fx.into());
}

#[test]
fn pdb_campaign() {
    let files = ["mda_multi.pdb", "mda_noelem.pdb"];
    let fx = files.map(|f| text_fixture(f, Format::Pdb));
    campaign("PDB", Format::Pdb, fx.into());
}

#[test]
fn mmcif_campaign() {
    let files = ["gemmi_multi.cif", "gemmi_topo.cif", "1uqc.cif"];
    let fx = files.map(|f| text_fixture(f, Format::Mmcif));
    campaign("PDBx/mmCIF", Format::Mmcif, fx.into());
}

/// BinaryCIF from three writers (biotite compressed, biotite with every encoding, Mol*'s
/// cif2bcif): a cut is always an error (the document is one MessagePack value), a flip an error
/// or a file read whole.
#[test]
fn bcif_campaign() {
    let files = [
        "bcif/biotite_gemmi_multi.bcif",
        "bcif/biotite_gemmi_multi_encodings.bcif",
        "bcif/molstar_gemmi_multi.bcif",
    ];
    let fx = files.map(|name| {
        let bytes = data(name);
        let n = bytes.len();
        Fixture {
            name: name.to_string(),
            boundaries: (0..60).map(|k| k * n / 60).collect(),
            bytes,
            frames: 3,
            cuts: Cuts::Declared,
            fields: Vec::new(),
            text: false,
        }
    });
    campaign("BinaryCIF", Format::Bcif, fx.into());
}

#[test]
fn gro_campaign() {
    let files = ["mda_vel.gro", "py_prec5.gro"];
    let fx = files.map(|f| text_fixture(f, Format::Gro));
    campaign("GRO", Format::Gro, fx.into());
}

#[test]
fn lammps_campaign() {
    let files = [
        "lmp_tri.lammpstrj",
        "lmp_scaled.lammpstrj",
        "lmp_color.lammpstrj",
        "lmp_color_dot.lammpstrj",
        "ovito_color.lammpstrj",
    ];
    let fx = files.map(|f| text_fixture(f, Format::LammpsDump));
    campaign("LAMMPS dump", Format::LammpsDump, fx.into());
}

#[test]
fn vasp_campaign() {
    let files = [
        "vasp/XDATCAR_pmg",
        "vasp/XDATCAR_ase",
        "vasp/CONTCAR_ase_vel.vasp",
        "vasp/POSCAR_pmg_vel",
        "volume/CHGCAR_small",
    ];
    let fx = files.map(|f| text_fixture(f, Format::Vasp));
    campaign("VASP", Format::Vasp, fx.into());
}

#[test]
fn cube_campaign() {
    let files = ["volume/ase_small.cube"];
    let fx = files.map(|f| text_fixture(f, Format::Cube));
    campaign("Gaussian cube", Format::Cube, fx.into());
}

#[test]
fn xsf_campaign() {
    let files = [
        "xsf/ase_anim_fixed.axsf",
        "xsf/ase_anim_cell.axsf",
        "xsf/ase_anim_molecule.axsf",
        "xsf/ase_grid_small.xsf",
        "xsf/pmg_grids.xsf",
    ];
    let fx = files.map(|f| text_fixture(f, Format::Xsf));
    campaign("XCrySDen XSF", Format::Xsf, fx.into());
}

#[test]
fn lammps_data_campaign() {
    let files = [
        "lammps_data/ase_atomic_tri.data",
        "lammps_data/ase_full.data",
        "lammps_data/mda_full_tri.data",
        "replicate/water.data",
    ];
    let fx = files.map(|f| text_fixture(f, Format::LammpsData));
    campaign("LAMMPS data", Format::LammpsData, fx.into());
}

#[test]
fn crystal_cif_campaign() {
    let files = ["crystal/cod_9001665.cif", "crystal/two_blocks.cif"];
    let fx = files.map(|f| text_fixture(f, Format::CrystalCif));
    campaign("crystallographic CIF", Format::CrystalCif, fx.into());
}

#[test]
fn amber_ascii_campaign() {
    let files = ["amber_ascii/box.mdcrd", "amber_ascii/nobox.mdcrd"];
    let fx = files.map(|f| text_fixture(f, Format::AmberTrj));
    campaign("AMBER mdcrd", Format::AmberTrj, fx.into());
    let files = ["amber_ascii/vel_box.rst7", "amber_ascii/odd.inpcrd"];
    let fx = files.map(|f| text_fixture(f, Format::AmberRestart));
    campaign("AMBER restart", Format::AmberRestart, fx.into());
}

#[test]
fn charmm_crd_campaign() {
    let files = ["mda_two.crd", "mda_chains.crd"];
    let fx = files.map(|f| text_fixture(f, Format::CharmmCrd));
    campaign("CHARMM CRD", Format::CharmmCrd, fx.into());
}

#[test]
fn pqr_campaign() {
    let files = [
        "parmed_models.pqr",
        "pdb2pqr_amber.pqr",
        "pdb2pqr_chains.pqr",
        "mda_chains.pqr",
    ];
    let fx = files.map(|f| text_fixture(f, Format::Pqr));
    campaign("PQR", Format::Pqr, fx.into());
}

#[test]
fn pdbqt_campaign() {
    let files = ["pdbqt/poses.pdbqt", "pdbqt/ligand.pdbqt"];
    let fx = files.map(|f| text_fixture(f, Format::Pdbqt));
    campaign("PDBQT", Format::Pdbqt, fx.into());
}

#[test]
fn namdbin_campaign() {
    let fx = ["namd/topo_mda.coor", "namd/topo_mda_be.coor"].map(|name| {
        let bytes = data(name);
        let len = bytes.len();
        let big = name.ends_with("_be.coor");
        Fixture {
            frames: frames_of(Format::NamdBin, &bytes),
            name: name.into(),
            bytes,
            boundaries: vec![0, 4, 4 + 24 * 33, len],
            // The count must match the length: any cut is an error.
            cuts: Cuts::Declared,
            fields: vec![(
                "NATOM",
                if big {
                    Field::I32Be(0)
                } else {
                    Field::I32Le(0)
                },
            )]
            .into_iter()
            .chain((!big).then_some(("x[0]", Field::F64Le(4))))
            .collect(),
            text: false,
        }
    });
    campaign("NAMD binary", Format::NamdBin, fx.into());
}

#[test]
fn tpr_campaign() {
    // GROMACS 2022's layout (the body's size declared: any cut is an error) and 4.0.7's
    // (XDR throughout, no size: a cut in the run parameters, which are not read, still reads).
    let fx = [
        ("tpr/dummy_2022-rc1.tpr", 52, 212, Cuts::Declared),
        ("tpr/vsites_4.0.7.tpr", 36, 196, Cuts::Unchecked),
    ]
    .map(|(name, natoms, symbols, cuts)| {
        let bytes = data(name);
        let len = bytes.len();
        Fixture {
            frames: frames_of(Format::Tpr, &bytes),
            name: name.into(),
            bytes,
            boundaries: vec![0, natoms, symbols, len],
            cuts,
            fields: vec![
                ("natoms", Field::I32Be(natoms)),
                ("symbols", Field::I32Be(symbols)),
            ],
            text: false,
        }
    });
    campaign("GROMACS tpr", Format::Tpr, fx.into());
}

#[test]
fn ase_traj_campaign() {
    // The offsets table sits at the end: any cut is an error. The counts are int64s; their low
    // halves are set to extremes (item count, table position).
    let fx = ["asetraj/cu_md.traj", "asetraj/mixed.traj"].map(|name| {
        let bytes = data(name);
        let len = bytes.len();
        Fixture {
            frames: frames_of(Format::AseTraj, &bytes),
            name: name.into(),
            bytes,
            boundaries: vec![0, 8, 24, 48, len],
            cuts: Cuts::Declared,
            fields: vec![
                ("nitems", Field::I32Le(32)),
                ("offsets position", Field::I32Le(40)),
            ],
            text: false,
        }
    });
    campaign("ASE trajectory", Format::AseTraj, fx.into());
}

#[test]
fn tinker_campaign() {
    let files = ["tinker/water_box.arc", "tinker/caffeine.txyz"];
    let fx = files.map(|f| text_fixture(f, Format::Tinker));
    campaign("Tinker", Format::Tinker, fx.into());
}

/// pw.x 6.7's outputs (a relax, a vc-relax, an md and a vc-md run, a spin-polarised relax with
/// magnetic moments) and inputs (hexagonal, bcc and triclinic lattices with crystal positions,
/// ibrav 0 with alat positions).
#[test]
fn espresso_campaign() {
    let files = [
        "espresso/si_relax.pwo",
        "espresso/si_vcrelax.pwo",
        "espresso/si_md.pwo",
        "espresso/si_vcmd.pwo",
        "espresso/fe_relax_mag.pwo",
    ];
    let fx = files.map(|f| text_fixture(f, Format::EspressoOut));
    campaign("Quantum ESPRESSO output", Format::EspressoOut, fx.into());
    let files = [
        "espresso/ibrav4_hex.pwi",
        "espresso/ibrav3_bcc.pwi",
        "espresso/si_md.pwi",
        "espresso/ibrav14_tri.pwi",
    ];
    let fx = files.map(|f| text_fixture(f, Format::EspressoIn));
    campaign("Quantum ESPRESSO input", Format::EspressoIn, fx.into());
}

/// VASP's run outputs: the vasprun.xml and the OUTCAR of a relaxation of bcc Li (three ionic
/// steps, the cell changing; pymatgen's test files).
#[test]
fn vasp_out_campaign() {
    let fx = text_fixture("vasp_out/vasprun_li_relax.xml", Format::VaspXml);
    campaign("VASP vasprun.xml", Format::VaspXml, vec![fx]);
    let fx = text_fixture("vasp_out/OUTCAR_li_relax", Format::Outcar);
    campaign("VASP OUTCAR", Format::Outcar, vec![fx]);
}

#[test]
fn dlpoly_campaign() {
    let files = ["dlpoly/HISTORY", "dlpoly/CONFIG"];
    let fx = files.map(|f| text_fixture(f, Format::DlPoly));
    campaign("DL_POLY", Format::DlPoly, fx.into());
}

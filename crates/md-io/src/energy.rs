//! Energies over time, for plotting: GROMACS energy files (`.edr`, what `gmx energy` reads) and
//! the thermo tables of LAMMPS logs (`log.lammps`), each read into one [`EnergyTable`] of named
//! columns.
//!
//! # GROMACS `.edr`
//! XDR (big-endian), enx file version 5 (what GROMACS writes: 2018 to 2024 at least), single
//! or double precision (told, as pyedr does, by where the frame magic lies after the first
//! frame's first real; checked against each frame's `e_size`):
//!
//! ```text
//! i32 -55555  i32 version (5)  i32 nre  nre x (string name, string unit)
//! frame: real -2e10  i32 -7777777  i32 version  f64 t (ps)  i64 step  i32 nsum  i64 nsteps
//!        f64 dt  i32 nre (0 or the header's)  i32 reserved  i32 nblock
//!        nblock x (i32 id  i32 nsub  nsub x (i32 type  i32 nr))  i32 e_size  i32  i32
//!        nre x (real e [real eav  real esum when nsum > 0])
//!        every subblock's nr values: int, float, char 4 bytes; double, int64 8 bytes;
//!        string: i32 length + 1, then an XDR string
//! ```
//! An XDR string is a u32 byte count and the bytes padded to a multiple of 4. The table has a
//! `Time` column (ps) and one column per term, named and with the unit as the file gives them
//! (the names of `gmx energy`'s legends and pyedr's keys). Frames without energies (distance
//! restraint, orientation restraint or free-energy blocks alone, written between energy frames)
//! are skipped as `gmx energy` and pyedr skip them; blocks are skipped by their declared sizes.
//! Older files (enx versions 1 to 4) are refused with their version; a file that ends after the
//! names, before its first frame, is cut (GROMACS writes the first frame with them and refuses
//! such a file too).
//!
//! # LAMMPS logs
//! Every thermo table of the log: a header line (`Step Temp E_pair ...`: a line of names whose
//! first is `Step`, or any line of names right after a `Per MPI rank memory allocation` line)
//! followed by rows of as many numbers, until `Loop time of`, an `ERROR`, the next run or the
//! end of the file; `thermo_style multi` records (`---- Step N ----- CPU = x (sec) ----` and
//! `Name = value` lines) are tables with the columns `Step`, `CPU` and the names. Lines inside a
//! table that are not rows (`WARNING` lines, `fix print` output) are skipped and counted
//! ([`EnergyTable::skipped_lines`]); a last row cut short at the end of the file (a run killed
//! mid-write: the file's last line has no newline, or is a row with too few numbers; a multi
//! record with fewer names than the one before) is dropped and counted
//! ([`EnergyTable::truncated_rows`]).
//!
//! The runs are joined into one table: a run with the same columns as the one before it
//! continues it, without its first row when that repeats the last step (LAMMPS prints the step
//! a run starts at again; pizza.py's `log` culls it the same way); runs with other columns give
//! the union of the columns, in the order first seen, each row NaN in the columns its run did not
//! print (its rows all kept). Units are not stated in a log: [`EnergyTable::units`] are empty.
//!
//! # Errors
//! A damaged or cut `.edr` is an [`Error`] with the file, frame (counted over every frame,
//! with or without energies) and byte offset, never a panic; no count read from the file sizes
//! an allocation before the bytes left could hold what it claims. A log with no thermo table is
//! an error naming the file.
//!
//! # References
//! - GROMACS `src/gromacs/fileio/enxio.cpp` (`do_enxnms`, `do_eheader`, `do_enx`) and
//!   `gmxfio_xdr.cpp` (how each block data type is written), read, not copied.
//! - pyedr 0.8.0 (`pyedr.py`: `read_edr`, the precision test) and `gmx energy` 2022.5: the
//!   values the tests compare with (tests/data/energy/gen_energy.py).
//! - LAMMPS `python/lammps/formats.py` (`LogFile`), lammps-logfile 1.1.4 (`read_log`) and
//!   pizza.py's `log.py` (duplicate steps culled): how logs are read elsewhere.
//!
//! ```
//! use texmap_md_io::energy;
//! let log = "LAMMPS (29 Sep 2021)\nStep Temp PotEng\n0 3.0 -6.77\n10 2.1 -5.46\nLoop time of 1\n";
//! assert!(energy::is_lammps_log(log.as_bytes()));
//! let table = energy::lammps_log_from_bytes(log.as_bytes(), "log.lammps")?;
//! assert_eq!(table.names, ["Step", "Temp", "PotEng"]);
//! assert_eq!(table.column("Temp"), Some(&[3.0, 2.1][..]));
//! # Ok::<(), texmap_md_io::Error>(())
//! ```

use std::io::{self, BufReader, Read};
use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Location};

/// Named columns of numbers over time, read from an energy file or a log.
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyTable {
    /// The columns' names: `Time` then the terms (`.edr`); the thermo keywords (a log).
    pub names: Vec<String>,
    /// Each column's unit (`ps`, `kJ/mol`, `K`, `bar`, possibly empty); all empty for a log.
    pub units: Vec<String>,
    /// `columns[k][row]`, every column as long as the others; NaN where a row has no value
    /// (a log's run that did not print that column).
    pub columns: Vec<Vec<f64>>,
    /// How many tables the file's runs printed (one for an `.edr`).
    pub runs: usize,
    /// Lines inside a log's tables that were not rows (warnings, `fix print` output).
    pub skipped_lines: usize,
    /// Rows dropped because the file ends inside them (a log whose run was killed mid-write).
    pub truncated_rows: usize,
}

impl EnergyTable {
    /// The number of rows.
    pub fn n_rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// The index of the column `name` (exact), if any.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The column `name` (exact), if any.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.index(name).map(|k| self.columns[k].as_slice())
    }
}

/// Whether the first bytes of a file are a GROMACS energy file's (the magic -55555).
pub fn is_edr(head: &[u8]) -> bool {
    head.get(..4) == Some(&EDR_MAGIC.to_be_bytes()[..])
}

/// Whether the first lines of a file (at most 8, in `head`) name LAMMPS (`LAMMPS (29 Sep
/// 2021)`), as every log LAMMPS writes begins.
pub fn is_lammps_log(head: &[u8]) -> bool {
    head.split(|&b| b == b'\n')
        .take(8)
        .any(|l| l.windows(8).any(|w| w == b"LAMMPS ("))
}

/// Reads a GROMACS energy file (see the module docs).
pub fn read_edr(path: impl AsRef<Path>) -> Result<EnergyTable, Error> {
    let path = path.as_ref();
    let file: Arc<str> = path.display().to_string().into();
    let io_err = |source| Error::Io {
        at: Location::file(&file),
        source,
    };
    let f = std::fs::File::open(path).map_err(io_err)?;
    let len = f.metadata().map_err(io_err)?.len();
    edr_from_reader(BufReader::new(f), len, &file)
}

/// Reads a GROMACS energy file of `len` bytes from `src`; `file` names it in errors.
pub fn edr_from_reader<R: Read>(src: R, len: u64, file: &str) -> Result<EnergyTable, Error> {
    let mut x = Xdr {
        src,
        pos: 0,
        len,
        file: file.into(),
        frame: None,
    };
    let (names, units) = edr_names(&mut x)?;
    let nre = names.len();
    let mut table = EnergyTable {
        names: std::iter::once("Time".to_string()).chain(names).collect(),
        units: std::iter::once("ps".to_string()).chain(units).collect(),
        columns: vec![Vec::new(); nre + 1],
        runs: 1,
        skipped_lines: 0,
        truncated_rows: 0,
    };
    // GROMACS writes the first frame with the names: a file that ends after them is cut.
    x.frame = Some(0);
    x.need(1, "the first energy frame")?;
    let mut double = None;
    let mut energies = Vec::with_capacity(nre);
    let mut frame = 0;
    while x.pos < x.len {
        x.frame = Some(frame);
        if let Some(t) = edr_frame(&mut x, nre, &mut double, &mut energies)? {
            table.columns[0].push(t);
            for (c, &e) in table.columns[1..].iter_mut().zip(&energies) {
                c.push(e);
            }
        }
        frame += 1;
    }
    Ok(table)
}

/// The magic number an energy file starts with.
const EDR_MAGIC: i32 = -55555;
/// The magic number after each frame's first real.
const FRAME_MAGIC: i32 = -7_777_777;
/// The enx file version read.
const ENX_VERSION: i32 = 5;
/// GROMACS's STRLEN: the longest name or unit it reads back.
const MAX_STRING: u32 = 4096;

/// The header: the terms' names and units.
fn edr_names<R: Read>(x: &mut Xdr<R>) -> Result<(Vec<String>, Vec<String>), Error> {
    let magic = x.i32("the energy file magic -55555")?;
    if magic != EDR_MAGIC {
        return Err(x.parse(
            0,
            if magic > 0 {
                "the energy file magic -55555 (a positive count starts the files of GROMACS before 4.1, enx version 1, which are not read)"
            } else {
                "the energy file magic -55555"
            },
            magic.to_string(),
        ));
    }
    let version = x.i32("the enx file version")?;
    if version != ENX_VERSION {
        return Err(x.parse(
            4,
            "enx file version 5 (what GROMACS 2018 to 2024 write)",
            version.to_string(),
        ));
    }
    // Every name and unit takes at least its 4-byte length.
    let nre = x.count(
        "the number of energy terms",
        "a number of energy terms whose names the file can hold",
        8,
    )?;
    let mut names = Vec::with_capacity(nre as usize);
    let mut units = Vec::with_capacity(nre as usize);
    for _ in 0..nre {
        names.push(x.string("an energy term's name")?);
        units.push(x.string("an energy term's unit")?);
    }
    Ok((names, units))
}

/// One frame: its time and, in `energies`, its terms' values, or `None` for a frame without
/// energies. `double` is the file's precision once the first frame has told it.
fn edr_frame<R: Read>(
    x: &mut Xdr<R>,
    nre: usize,
    double: &mut Option<bool>,
    energies: &mut Vec<f64>,
) -> Result<Option<f64>, Error> {
    let start = x.pos;
    // The frame magic follows a 4-byte real (single precision) or an 8-byte one (double): the
    // first frame tells which, the others must agree.
    let (first, magic, real) = match *double {
        Some(d) => {
            let first = x.real(d, "an energy frame's first real")?;
            let magic = x.i32("the energy frame magic -7777777")?;
            (first, magic, if d { 8 } else { 4 })
        }
        None => {
            let a = x.bytes::<4>("an energy frame's first real")?;
            let b = x.bytes::<4>("the energy frame magic -7777777")?;
            let single = f64::from(f32::from_be_bytes(a));
            if single < -1e10 && i32::from_be_bytes(b) == FRAME_MAGIC {
                (single, FRAME_MAGIC, 4)
            } else {
                let mut d = [0; 8];
                d[..4].copy_from_slice(&a);
                d[4..].copy_from_slice(&b);
                let magic = x.i32("the energy frame magic -7777777")?;
                (f64::from_be_bytes(d), magic, 8)
            }
        }
    };
    // (NaN fails the comparison.)
    let starts = first < -1e10 && magic == FRAME_MAGIC;
    if !starts {
        return Err(x.parse(
            start,
            "an energy frame's start (-2e10 as a real, then -7777777)",
            format!("{first:e}, {magic}"),
        ));
    }
    *double = Some(real == 8);
    let at = x.pos;
    let version = x.i32("the frame's enx version")?;
    if version != ENX_VERSION {
        return Err(x.parse(at, "enx frame version 5", version.to_string()));
    }
    let t = x.f64("the frame's time")?;
    let _step = x.i64("the frame's step")?;
    let nsum = x.i32("the frame's sum length (nsum)")?;
    let _nsteps = x.i64("the frame's step count")?;
    let _dt = x.f64("the frame's time step")?;
    let at = x.pos;
    let frame_nre = x.i32("the frame's number of energies")?;
    if frame_nre != 0 && frame_nre as usize != nre {
        return Err(x.parse(
            at,
            "0 energies or as many as the file's header names",
            format!("{frame_nre} (the header names {nre})"),
        ));
    }
    let frame_nre = frame_nre as usize;
    x.i32("a reserved int")?;
    // Every block header and subblock header takes at least 8 bytes.
    let nblock = x.count(
        "the frame's number of blocks",
        "a number of blocks the file can hold",
        8,
    )?;
    // (type, nr) of every subblock, in the order their data follow.
    let mut subs: Vec<(i32, u64)> = Vec::new();
    for _ in 0..nblock {
        x.i32("a block's id")?;
        let nsub = x.count(
            "a block's number of subblocks",
            "a number of subblocks the file can hold",
            8,
        )?;
        for _ in 0..nsub {
            let at = x.pos;
            let kind = x.i32("a subblock's data type")?;
            if !(0..=5).contains(&kind) {
                return Err(x.parse(
                    at,
                    "a subblock data type 0 to 5 (int, float, double, int64, char, string)",
                    kind.to_string(),
                ));
            }
            // Each value takes 4 or 8 bytes; a string at least its two lengths.
            let least = if matches!(kind, 0 | 1 | 4) { 4 } else { 8 };
            let nr = x.count(
                "a subblock's length",
                "a subblock length the file can hold",
                least,
            )?;
            subs.push((kind, nr));
        }
    }
    let at = x.pos;
    let e_size = x.i32("the frame's energy size")?;
    if frame_nre > 0 && e_size as i64 != frame_nre as i64 * 4 * real as i64 {
        return Err(x.parse(
            at,
            "an energy size of 4 reals per term",
            format!("{e_size} for {frame_nre} terms of {real} bytes"),
        ));
    }
    x.i32("a reserved int")?;
    x.i32("a reserved int")?;
    // Each energy; with its average and sum over the last nsum steps when nsum > 0.
    let per_term = if nsum > 0 { 3 } else { 1 };
    x.need((frame_nre * per_term * real) as u64, "the frame's energies")?;
    energies.clear();
    for _ in 0..frame_nre {
        energies.push(x.real(real == 8, "an energy")?);
        if per_term == 3 {
            x.skip(2 * real as u64, "an energy's average and sum")?;
        }
    }
    // The blocks' data, skipped.
    for &(kind, nr) in &subs {
        match kind {
            0 | 1 | 4 => x.skip(4 * nr, "a block's data")?,
            2 | 3 => x.skip(8 * nr, "a block's data")?,
            _ => {
                // Strings: at least 8 bytes each.
                x.need(8 * nr, "a block's strings")?;
                for _ in 0..nr {
                    x.i32("a string's length")?;
                    x.string("a block's string")?;
                }
            }
        }
    }
    Ok((frame_nre > 0).then_some(t))
}

/// An XDR stream of known length, read in order.
struct Xdr<R> {
    src: R,
    /// Bytes read so far.
    pos: u64,
    len: u64,
    file: Arc<str>,
    /// The frame being read (none in the header).
    frame: Option<usize>,
}

impl<R: Read> Xdr<R> {
    fn left(&self) -> u64 {
        self.len - self.pos
    }

    fn location(&self, byte: u64) -> Location {
        Location {
            file: self.file.clone(),
            frame: self.frame,
            line: None,
            byte: Some(byte),
        }
    }

    fn parse(&self, byte: u64, expected: &'static str, found: String) -> Error {
        Error::Parse {
            at: self.location(byte),
            expected,
            found,
        }
    }

    /// An error unless `n` more bytes are left.
    fn need(&self, n: u64, what: &str) -> Result<(), Error> {
        if n > self.left() {
            return Err(Error::Truncated {
                at: self.location(self.pos),
                expected: format!("{what}: {n} bytes, {} left", self.left()),
            });
        }
        Ok(())
    }

    fn io(&self, source: io::Error) -> Error {
        Error::Io {
            at: self.location(self.pos),
            source,
        }
    }

    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N], Error> {
        self.need(N as u64, what)?;
        let mut b = [0; N];
        self.src.read_exact(&mut b).map_err(|e| self.io(e))?;
        self.pos += N as u64;
        Ok(b)
    }

    fn i32(&mut self, what: &str) -> Result<i32, Error> {
        self.bytes::<4>(what).map(i32::from_be_bytes)
    }

    /// A count of things that take at least `least` bytes each: refused (`expected`) when
    /// negative or more than the bytes left could hold.
    fn count(&mut self, what: &str, expected: &'static str, least: u64) -> Result<u64, Error> {
        let at = self.pos;
        let n = self.i32(what)?;
        if n < 0 || n as u64 * least > self.left() {
            return Err(self.parse(at, expected, n.to_string()));
        }
        Ok(n as u64)
    }

    fn i64(&mut self, what: &str) -> Result<i64, Error> {
        self.bytes::<8>(what).map(i64::from_be_bytes)
    }

    fn f64(&mut self, what: &str) -> Result<f64, Error> {
        self.bytes::<8>(what).map(f64::from_be_bytes)
    }

    fn real(&mut self, double: bool, what: &str) -> Result<f64, Error> {
        if double {
            self.f64(what)
        } else {
            self.bytes::<4>(what)
                .map(|b| f64::from(f32::from_be_bytes(b)))
        }
    }

    fn skip(&mut self, n: u64, what: &str) -> Result<(), Error> {
        self.need(n, what)?;
        let copied =
            io::copy(&mut (&mut self.src).take(n), &mut io::sink()).map_err(|e| self.io(e))?;
        if copied != n {
            return Err(self.io(io::ErrorKind::UnexpectedEof.into()));
        }
        self.pos += n;
        Ok(())
    }

    /// An XDR string: a u32 byte count, the bytes, padding to a multiple of 4.
    fn string(&mut self, what: &'static str) -> Result<String, Error> {
        let at = self.pos;
        let n = self.bytes::<4>(what).map(u32::from_be_bytes)?;
        if n > MAX_STRING {
            return Err(self.parse(
                at,
                "a string of at most 4096 bytes",
                format!("{n} bytes ({what})"),
            ));
        }
        let padded = u64::from(n.div_ceil(4) * 4);
        self.need(padded, what)?;
        let mut b = vec![0; padded as usize];
        self.src.read_exact(&mut b).map_err(|e| self.io(e))?;
        self.pos += padded;
        b.truncate(n as usize);
        // C strings: a NUL ends the text.
        if let Some(end) = b.iter().position(|&c| c == 0) {
            b.truncate(end);
        }
        Ok(String::from_utf8_lossy(&b).into_owned())
    }
}

/// Reads a LAMMPS log (see the module docs).
pub fn read_lammps_log(path: impl AsRef<Path>) -> Result<EnergyTable, Error> {
    let path = path.as_ref();
    let file: Arc<str> = path.display().to_string().into();
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        at: Location::file(&file),
        source,
    })?;
    lammps_log_from_bytes(&bytes, &file)
}

/// One thermo table of a log, as printed.
#[derive(Debug, Default)]
struct Run {
    names: Vec<String>,
    /// Rows as wide as `names` (a multi record missing a name has NaN there).
    rows: Vec<Vec<f64>>,
}

/// A line of the log: its text (without the newline) and whether a newline ends it.
struct Line<'a> {
    text: &'a str,
    terminated: bool,
}

/// What a line of a log is, to the table reader.
#[derive(Debug, PartialEq)]
enum Kind {
    /// `Loop time of`, an `ERROR`, `Total wall time`: the end of a table.
    End,
    /// `Per MPI rank memory allocation` (or the older `Memory usage per processor`): a table's
    /// header comes next.
    Memory,
    /// A multi record's first line: its step and CPU time.
    MultiHead(f64, f64),
    /// Numbers only.
    Numbers(usize),
    Blank,
    Other,
}

fn number(word: &str) -> Option<f64> {
    // LAMMPS prints C's "nan", "-nan", "inf"; Rust parses those but not "-nan".
    match word {
        "-nan" | "-NaN" | "-NAN" => Some(f64::NAN),
        _ => word.parse().ok(),
    }
}

fn kind(text: &str) -> Kind {
    let t = text.trim();
    if t.is_empty() {
        return Kind::Blank;
    }
    if t.starts_with("Loop time of") || t.starts_with("ERROR") || t.starts_with("Total wall time") {
        return Kind::End;
    }
    if t.starts_with("Per MPI rank memory allocation")
        || t.starts_with("Memory usage per processor")
    {
        return Kind::Memory;
    }
    if t.starts_with("---")
        && let Some(head) = multi_head(t)
    {
        return Kind::MultiHead(head.0, head.1);
    }
    let mut n = 0;
    for w in t.split_whitespace() {
        if number(w).is_none() {
            return Kind::Other;
        }
        n += 1;
    }
    Kind::Numbers(n)
}

/// `---------------- Step 100 ----- CPU = 0.0008 (sec) ----------------`: (step, CPU).
fn multi_head(t: &str) -> Option<(f64, f64)> {
    let words: Vec<&str> = t
        .split_whitespace()
        .filter(|w| !w.bytes().all(|c| c == b'-'))
        .collect();
    match words.as_slice() {
        ["Step", step, "CPU", "=", cpu, ..] => Some((number(step)?, number(cpu)?)),
        _ => None,
    }
}

/// The `Name = value` pairs of a multi record's line, or `None` if it is not one.
fn multi_pairs(text: &str) -> Option<Vec<(&str, f64)>> {
    let words: Vec<&str> = text.split_whitespace().collect();
    if words.is_empty() || !words.len().is_multiple_of(3) {
        return None;
    }
    words
        .chunks_exact(3)
        .map(|w| {
            if w[1] == "=" {
                Some((w[0], number(w[2])?))
            } else {
                None
            }
        })
        .collect()
}

/// Reads a LAMMPS log's thermo tables from its bytes; `file` names it in errors.
pub fn lammps_log_from_bytes(bytes: &[u8], file: &str) -> Result<EnergyTable, Error> {
    let text = String::from_utf8_lossy(bytes);
    let log = Log::new(&text);
    let mut runs: Vec<Run> = Vec::new();
    let (mut skipped, mut truncated) = (0, 0);
    let mut after_memory = false;
    let mut i = 0;
    while i < log.lines.len() {
        let table = match &log.kinds[i] {
            Kind::Memory => {
                after_memory = true;
                i += 1;
                continue;
            }
            Kind::Blank => {
                i += 1;
                continue;
            }
            Kind::Other if log.lines[i].text.trim_start().starts_with("WARNING") => {
                i += 1;
                continue;
            }
            Kind::MultiHead(..) => Some(log.multi(i)),
            Kind::Other => {
                let names = log.lines[i].text.split_whitespace();
                let (first, width) = (names.clone().next(), names.count());
                ((after_memory || first == Some("Step")) && log.header_has_rows(i, width))
                    .then(|| log.custom(i))
            }
            _ => None,
        };
        after_memory = false;
        match table {
            Some(t) => {
                runs.push(t.run);
                (skipped, truncated) = (skipped + t.skipped, truncated + t.truncated);
                i = t.next;
            }
            None => i += 1,
        }
    }
    runs.retain(|r| !r.rows.is_empty());
    if runs.is_empty() {
        return Err(Error::Parse {
            at: Location::file(&Arc::from(file)),
            expected: "a thermo table (a header such as 'Step Temp E_pair' over rows of numbers, or thermo_style multi records)",
            found: format!("none in {} lines", log.lines.len()),
        });
    }
    Ok(join(runs, skipped, truncated))
}

/// A log's lines, what each is, and the last that is not blank (a row there without a
/// newline, or too short, was cut).
struct Log<'a> {
    lines: Vec<Line<'a>>,
    kinds: Vec<Kind>,
    last: Option<usize>,
}

/// One table read from a log: the run, the line after it, the lines skipped inside it and the
/// rows cut short at the end of the file.
struct Scanned {
    run: Run,
    next: usize,
    skipped: usize,
    truncated: usize,
}

impl<'a> Log<'a> {
    fn new(text: &'a str) -> Log<'a> {
        let mut lines: Vec<Line> = Vec::new();
        let mut rest = text;
        while !rest.is_empty() {
            match rest.find('\n') {
                Some(i) => {
                    lines.push(Line {
                        text: rest[..i].trim_end_matches('\r'),
                        terminated: true,
                    });
                    rest = &rest[i + 1..];
                }
                None => {
                    lines.push(Line {
                        text: rest,
                        terminated: false,
                    });
                    rest = "";
                }
            }
        }
        let kinds: Vec<Kind> = lines.iter().map(|l| kind(l.text)).collect();
        let last = kinds.iter().rposition(|k| *k != Kind::Blank);
        Log { lines, kinds, last }
    }

    /// Whether the file's last line, without its newline, is line `j`.
    fn cut_at(&self, j: usize) -> bool {
        self.last == Some(j) && !self.lines[j].terminated
    }

    /// Whether the header at line `i`, `width` names wide, is followed by a row of as many
    /// numbers before the table could end (looking at most 64 lines ahead, past warnings).
    fn header_has_rows(&self, i: usize, width: usize) -> bool {
        for k in self.kinds.iter().skip(i + 1).take(64) {
            match k {
                Kind::Numbers(n) if *n == width => return true,
                Kind::End | Kind::Memory | Kind::MultiHead(..) => return false,
                _ => {}
            }
        }
        false
    }

    /// A `Step ...` table from its header at line `i`.
    fn custom(&self, i: usize) -> Scanned {
        let lines = &self.lines;
        let mut run = Run {
            names: lines[i]
                .text
                .split_whitespace()
                .map(str::to_string)
                .collect(),
            rows: Vec::new(),
        };
        let width = run.names.len();
        let (mut skipped, mut truncated) = (0, 0);
        let mut j = i + 1;
        while j < lines.len() {
            match &self.kinds[j] {
                Kind::End | Kind::Memory | Kind::MultiHead(..) => break,
                Kind::Blank => {}
                Kind::Numbers(n) => {
                    if self.cut_at(j) || (self.last == Some(j) && *n < width) {
                        truncated += 1;
                    } else if *n == width {
                        run.rows.push(
                            lines[j]
                                .text
                                .split_whitespace()
                                .map(|w| number(w).unwrap_or(f64::NAN))
                                .collect(),
                        );
                    } else {
                        skipped += 1;
                    }
                }
                // The file's last line, cut inside a number ("1.6e", "-"): a row cut short.
                Kind::Other
                    if self.cut_at(j)
                        && lines[j]
                            .text
                            .trim_start()
                            .starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c)) =>
                {
                    truncated += 1;
                }
                Kind::Other => {
                    // A new table's header ends this one.
                    let words: Vec<&str> = lines[j].text.split_whitespace().collect();
                    if words[0] == "Step" && self.header_has_rows(j, words.len()) {
                        break;
                    }
                    skipped += 1;
                }
            }
            j += 1;
        }
        Scanned {
            run,
            next: j,
            skipped,
            truncated,
        }
    }

    /// `thermo_style multi` records from the first head line at `i`.
    fn multi(&self, i: usize) -> Scanned {
        let mut run = Run {
            names: vec!["Step".into(), "CPU".into()],
            rows: Vec::new(),
        };
        let (mut skipped, mut truncated) = (0, 0);
        // The record being read (its values by name), whether the file ends inside it, and
        // the previous record's length.
        let mut record: Vec<(String, f64)> = Vec::new();
        let mut cut = false;
        let mut previous = 0;
        let mut j = i;
        while j < self.lines.len() {
            let end_cut = self.cut_at(j);
            match &self.kinds[j] {
                Kind::End | Kind::Memory => break,
                Kind::MultiHead(step, cpu) => {
                    if !record.is_empty() {
                        previous = record.len();
                        truncated += finish_record(&mut run, &mut record, cut);
                    }
                    record = vec![("Step".into(), *step), ("CPU".into(), *cpu)];
                    cut = end_cut;
                }
                Kind::Blank => {}
                _ => match multi_pairs(self.lines[j].text) {
                    Some(pairs) if !record.is_empty() => {
                        record.extend(pairs.into_iter().map(|(n, v)| (n.to_string(), v)));
                        cut |= end_cut;
                    }
                    _ if end_cut && !record.is_empty() => cut = true,
                    _ => skipped += 1,
                },
            }
            j += 1;
        }
        if !record.is_empty() {
            // At the end of the file, a record shorter than the one before was cut.
            let short = j == self.lines.len() && record.len() < previous;
            truncated += finish_record(&mut run, &mut record, cut || short);
        }
        Scanned {
            run,
            next: j,
            skipped,
            truncated,
        }
    }
}

/// Adds a multi `record` to `run` (a new name becomes a column, NaN in the rows before), or
/// drops it when `cut`; returns the rows dropped.
fn finish_record(run: &mut Run, record: &mut Vec<(String, f64)>, cut: bool) -> usize {
    if cut {
        record.clear();
        return 1;
    }
    let mut row = vec![f64::NAN; run.names.len()];
    for (name, v) in record.drain(..) {
        match run.names.iter().position(|n| *n == name) {
            Some(k) => row[k] = v,
            None => {
                run.names.push(name);
                for r in &mut run.rows {
                    r.push(f64::NAN);
                }
                row.push(v);
            }
        }
    }
    run.rows.push(row);
    0
}

/// The runs as one table (see the module docs).
fn join(runs: Vec<Run>, skipped_lines: usize, truncated_rows: usize) -> EnergyTable {
    let mut names: Vec<String> = Vec::new();
    for r in &runs {
        for n in &r.names {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    let mut columns = vec![Vec::new(); names.len()];
    let n_runs = runs.len();
    let mut previous: Option<&Run> = None;
    for r in &runs {
        let map: Vec<usize> = r
            .names
            .iter()
            .map(|n| {
                names
                    .iter()
                    .position(|m| m == n)
                    .expect("every run's names are in the union")
            })
            .collect();
        // A continuation repeats the step it starts at: drop that row.
        let skip = previous.is_some_and(|p| {
            p.names == r.names
                && p.names.iter().position(|n| n == "Step").is_some_and(|s| {
                    p.rows.last().map(|row| row[s]) == r.rows.first().map(|row| row[s])
                })
        });
        for row in &r.rows[usize::from(skip)..] {
            for c in &mut columns {
                c.push(f64::NAN);
            }
            for (&k, &v) in map.iter().zip(row) {
                *columns[k].last_mut().expect("a row was pushed") = v;
            }
        }
        previous = Some(r);
    }
    EnergyTable {
        units: vec![String::new(); names.len()],
        names,
        columns,
        runs: n_runs,
        skipped_lines,
        truncated_rows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log(text: &str) -> EnergyTable {
        lammps_log_from_bytes(text.as_bytes(), "log.lammps").unwrap()
    }

    #[test]
    fn lammps_numbers_include_c_nan_and_inf() {
        assert!(number("-nan").unwrap().is_nan());
        assert!(number("nan").unwrap().is_nan());
        assert_eq!(number("-inf"), Some(f64::NEG_INFINITY));
        assert_eq!(number("1.5e-3"), Some(1.5e-3));
        assert_eq!(number("Temp"), None);
    }

    #[test]
    fn multi_heads_of_any_dash_count() {
        assert_eq!(
            multi_head(
                "---------------- Step      100 ----- CPU =      0.0008 (sec) ----------------"
            ),
            Some((100.0, 0.0008))
        );
        assert_eq!(
            multi_head(
                "------------ Step              0 ----- CPU =            0 (sec) -------------"
            ),
            Some((0.0, 0.0))
        );
        assert_eq!(multi_head("--------- Section ----"), None);
        assert_eq!(
            multi_pairs("TotEng   =        -2.2976 KinEng   =         2.4204 "),
            Some(vec![("TotEng", -2.2976), ("KinEng", 2.4204)])
        );
        assert_eq!(
            multi_pairs("WARNING: Lost atoms: original 256 current 246"),
            None
        );
        assert_eq!(multi_pairs("a = b"), None);
    }

    #[test]
    fn a_header_after_the_memory_line_needs_no_step() {
        let t = log(
            "Per MPI rank memory allocation (min/avg/max) = 2.6\nTime Temp\n0 2\n0.025 1.9\nLoop time of 1\n",
        );
        assert_eq!(t.names, ["Time", "Temp"]);
        assert_eq!(t.columns, [vec![0.0, 0.025], vec![2.0, 1.9]]);
        // Without it, only a Step header starts a table.
        assert!(lammps_log_from_bytes(b"Time Temp\n0 2\n", "x").is_err());
    }

    #[test]
    fn a_header_without_rows_is_text() {
        let t = log("Step 1: melt\nStep Temp\nWARNING: x\n0 3\nLoop time of 1\n");
        assert_eq!(t.names, ["Step", "Temp"]);
        assert_eq!((t.n_rows(), t.skipped_lines), (1, 1));
    }

    #[test]
    fn cut_rows_at_the_end_are_dropped_and_counted() {
        for (text, rows) in [
            ("Step Temp\n0 3\n10 2.5", 1),
            ("Step Temp\n0 3\n10\n", 1),
            ("Step Temp\n0 3\n10 2.5\n", 2),
            ("Step Temp\n0 3\n1", 1),
            ("Step Temp\n0 3\n10 2.5e", 1),
            ("Step Temp\n0 3\n10 -", 1),
        ] {
            let t = log(text);
            assert_eq!(t.n_rows(), rows, "{text:?}");
            assert_eq!(t.truncated_rows, 2 - rows, "{text:?}");
        }
        // A short row inside the table is skipped, not cut; so is a last warning.
        let t = log("Step Temp\n0 3\n5\n10 2.5\n");
        assert_eq!((t.n_rows(), t.skipped_lines, t.truncated_rows), (2, 1, 0));
        let t = log("Step Temp\n0 3\nWARNING: Lost at");
        assert_eq!((t.n_rows(), t.skipped_lines, t.truncated_rows), (1, 1, 0));
    }

    #[test]
    fn edr_magic_sniff() {
        assert!(is_edr(&[0xff, 0xff, 0x26, 0xfd, 0, 0, 0, 5]));
        assert!(!is_edr(b"LAMMPS ("));
        assert!(!is_edr(&[0xff]));
        assert!(is_lammps_log(b"LAMMPS (29 Sep 2021 - Update 2)\nOMP"));
        assert!(!is_lammps_log(b"Step Temp\n0 1\n"));
    }
}

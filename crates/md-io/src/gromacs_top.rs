//! GROMACS topologies (`.top`, with the `.itp` files they `#include`), as a [`Topology`]: the
//! atoms with their names, types, masses and charges, residues, molecule types and chemical
//! bonds, filled as the `.tpr` reader (module `tpr`) fills them from the run input grompp makes
//! of the same topology, so that `topol.top` and `topol.tpr` give one topology.
//!
//! **Preprocessor.** grompp runs a small C preprocessor first, and so does this reader:
//!
//! - `#include "file"` (or `<file>`) is looked for beside the including file, then in the
//!   directories of [`GromacsTopOptions::include_dirs`] (grompp's `include = -I...`), then in
//!   GROMACS's data directories: each of `GMXLIB` (`:`-separated), `$GMXDATA/top`,
//!   `/usr/share/gromacs/top` and `/usr/local/gromacs/share/gromacs/top`. Includes nest at most
//!   64 deep (an include cycle is an error there) and at most 4096 files are opened in all;
//! - `#define NAME [value]`, `#undef NAME`, and the defines of [`GromacsTopOptions::defines`]
//!   (grompp's `define = -DPOSRES -DFLEXIBLE`); a define with a value replaces the word `NAME`
//!   in the lines that follow, as grompp replaces it;
//! - `#ifdef`, `#ifndef`, `#else`, `#endif`, nested, balanced within each file: an `#else` or
//!   `#endif` without its `#ifdef`, or an `#ifdef` still open at the end of its file, is an
//!   error at its line. Other directives (`#if`, `#error`) are errors, as in grompp;
//! - a line ending in `\` continues on the next (CHARMM's CMAP types); `;` starts a comment.
//!
//! **Sections.** `[ atomtypes ]` gives each type its mass, charge and atomic number (the
//! optional bonded-type and atomic-number columns told apart as grompp tells them: by where the
//! one-letter particle type stands); a type defined twice keeps its last definition, as in
//! grompp (CHARMM's `HEAVY_H`). `[ moleculetype ]` starts a molecule type; its `[ atoms ]`
//! (`nr type resnr residue atom cgnr [charge [mass]]`, numbered 1, 2, ... in order; the charge
//! and mass default to the type's) and the chemical bonds, which are GROMACS's (`IF_CHEMBOND`,
//! the bonds the `.tpr` reader takes): `[ bonds ]` of function types 1-5, 7 and 8 (not the
//! harmonic potential 6, tabulated bonds without connection 9 or restraint potentials 10),
//! `[ constraints ]` of type 1 (type 2 has no connection), `[ polarization ]` of types 1
//! and 2, and
//! `[ settles ]` as the two O–H bonds of the water whose oxygen it names. A new residue starts
//! where the residue number, its insertion letter or the residue name changes, as in grompp.
//! `[ molecules ]` lists the system (`name count`, in order; a name matches its molecule type
//! exactly, else in any case when only one does). `[ intermolecular_interactions ]` bonds
//! number the atoms of the whole system. Every other section (`[ defaults ]`, parameters,
//! pairs, angles, dihedrals, CMAP, exclusions, restraints, virtual sites) is read past.
//!
//! **As the `.tpr`.** Residue numbers, elements (the atom type's atomic number, else the name
//! and mass, a massless site no element), molecule types as segments and `_chain_X` molecule
//! types as chains follow the `.tpr` reader, with the system's molecule blocks merged as grompp
//! merges consecutive entries of one type. What differs: grompp drops the bonds of virtual
//! sites whose construction makes them constant (`-rmvsbds`, topologies built with
//! `pdb2gmx -vsite`), which this reader keeps, and `constraints = h-angles` in the `.mdp` adds
//! constraints grompp stores as bonds.
//!
//! **Bounds.** The system is at most 2^26 atoms and 2^27 bonds (`SOL 1000000000` over a
//! short file is an error, not an allocation); a line at most 16 MiB after its continuations
//! and defines. Errors name the file (the included file, where it is one) and line.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::elements::Element;
use crate::error::{Error, Location};
use crate::frame::Label;
use crate::parse::{fields, parse_f64, parse_i64, trim};
use crate::topology::{LineAt, Lines, Topology, tidy};

/// The most atoms a system may have (as the `.tpr` reader's bound without positions).
const MAX_ATOMS: u64 = 1 << 26;
/// The most bonds a system may have.
const MAX_BONDS: u64 = 1 << 27;
/// How deep includes nest.
const MAX_DEPTH: usize = 64;
/// How many files may be opened in all.
const MAX_OPENS: usize = 4096;
/// The longest line, after continuations and defines.
const MAX_LINE: usize = 1 << 24;

/// How to preprocess a GROMACS topology: what grompp's `define` and `include` options give.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GromacsTopOptions {
    /// Defines, as in an `.mdp` file's `define` (`-DPOSRES`, `POSRES`, `-DNAME=value`; the
    /// `-D` is optional): none by default, as grompp.
    pub defines: Vec<String>,
    /// Directories searched for `#include` files after the including file's own directory and
    /// before GROMACS's data directories (an `.mdp` file's `include = -I...`).
    pub include_dirs: Vec<PathBuf>,
}

/// Reads the GROMACS topology `path` (`.top`, `.itp`, gzip-compressed or not; see the module
/// docs) with its includes, preprocessed with `options`.
///
/// ```no_run
/// use texmap_md_io::{GromacsTopOptions, read_gromacs_top};
/// let options = GromacsTopOptions { defines: vec!["-DPOSRES".into()], ..Default::default() };
/// let t = read_gromacs_top("topol.top", &options)?;
/// println!("{} atoms, {} bonds", t.n_atoms(), t.bonds.len());
/// # Ok::<(), texmap_md_io::Error>(())
/// ```
pub fn read_gromacs_top(
    path: impl AsRef<Path>,
    options: &GromacsTopOptions,
) -> Result<Topology, Error> {
    let path = path.as_ref();
    let name: Arc<str> = path.display().to_string().into();
    let (file, _) = crate::gz::open(path, &name, false)?;
    read_top(file, &name, options)
}

/// Reads a topology from `src`, named `file` (a path: includes are looked for beside it).
pub(crate) fn read_top<R: Read>(
    src: R,
    file: &Arc<str>,
    options: &GromacsTopOptions,
) -> Result<Topology, Error> {
    let dir = Path::new(&**file)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut cpp = Cpp::new(Box::new(src), file.clone(), dir, options);
    let mut p = Parser::default();
    while let Some(line) = cpp.next_line()? {
        p.line(&mut cpp, line)?;
    }
    p.finish(file)
}

fn loc(file: &Arc<str>, l: &LineAt) -> Location {
    Location {
        file: file.clone(),
        frame: None,
        line: Some(l.line),
        byte: Some(l.byte),
    }
}

fn err(file: &Arc<str>, l: &LineAt, expected: &'static str, found: impl Into<String>) -> Error {
    Error::Parse {
        at: loc(file, l),
        expected,
        found: found.into(),
    }
}

/// The state of one `#ifdef` block.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cond {
    /// Its lines are read.
    True,
    /// Its lines are skipped; an `#else` reads the rest.
    False,
    /// Inside a skipped block: skipped whatever its condition and `#else`.
    Ignore,
}

/// One file being read.
struct Source<'a> {
    lines: Lines<Box<dyn Read + 'a>>,
    name: Arc<str>,
    /// Where its includes are looked for first.
    dir: PathBuf,
    /// The open `#ifdef` blocks, with the line and byte of each.
    conds: Vec<(Cond, u64, u64)>,
}

/// A line after the preprocessor: its text, file and place.
struct Line {
    text: Vec<u8>,
    file: Arc<str>,
    at: LineAt,
}

/// grompp's preprocessor: includes, defines and conditional blocks.
struct Cpp<'a> {
    stack: Vec<Source<'a>>,
    defines: HashMap<Vec<u8>, Vec<u8>>,
    /// How many defines have a value (lines are searched for defines only when some have).
    valued: usize,
    /// Searched after the including file's directory.
    dirs: Vec<PathBuf>,
    opens: usize,
}

impl<'a> Cpp<'a> {
    fn new(
        src: Box<dyn Read + 'a>,
        name: Arc<str>,
        dir: PathBuf,
        options: &GromacsTopOptions,
    ) -> Cpp<'a> {
        let mut defines = HashMap::new();
        for d in &options.defines {
            let d = d.trim();
            let d = d.strip_prefix("-D").unwrap_or(d);
            let (k, v) = d.split_once('=').unwrap_or((d, ""));
            if !k.is_empty() {
                defines.insert(k.as_bytes().to_vec(), v.as_bytes().to_vec());
            }
        }
        let mut dirs = options.include_dirs.clone();
        dirs.extend(library_dirs());
        let valued = defines
            .values()
            .filter(|v: &&Vec<u8>| !v.is_empty())
            .count();
        Cpp {
            stack: vec![Source {
                lines: Lines::new(src, name.clone()),
                name,
                dir,
                conds: Vec::new(),
            }],
            defines,
            valued,
            dirs,
            opens: 1,
        }
    }

    /// The next line to parse (directives done, skipped blocks skipped), `None` at the end of
    /// the topology.
    fn next_line(&mut self) -> Result<Option<Line>, Error> {
        loop {
            let Some(top) = self.stack.last_mut() else {
                return Ok(None);
            };
            let Some((raw, at)) = top.lines.next_line()? else {
                if let Some(&(_, line, byte)) = top.conds.last() {
                    return Err(err(
                        &top.name,
                        &LineAt { line, byte },
                        "an #endif closing this #ifdef/#ifndef before the end of its file",
                        "none",
                    ));
                }
                self.stack.pop();
                continue;
            };
            let t = trim(raw);
            if let Some(body) = t.strip_prefix(b"#") {
                let body = body.to_vec();
                let name = top.name.clone();
                self.directive(&body, &name, at)?;
                continue;
            }
            if top.conds.last().is_some_and(|c| c.0 != Cond::True) {
                continue;
            }
            return Ok(Some(Line {
                text: raw.to_vec(),
                file: top.name.clone(),
                at,
            }));
        }
    }

    fn directive(&mut self, body: &[u8], file: &Arc<str>, at: LineAt) -> Result<(), Error> {
        let body = trim(body);
        let split = body
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(body.len());
        let (name, rest) = (&body[..split], trim(&body[split..]));
        let Some(top) = self.stack.last_mut() else {
            return Ok(());
        };
        let skipping = top.conds.last().is_some_and(|c| c.0 != Cond::True);
        let word = fields(rest).next();
        match name {
            b"ifdef" | b"ifndef" => {
                let cond = if skipping {
                    Cond::Ignore
                } else {
                    let Some(word) = word else {
                        return Err(err(file, &at, "a name after #ifdef or #ifndef", "none"));
                    };
                    if self.defines.contains_key(word) == (name == b"ifdef") {
                        Cond::True
                    } else {
                        Cond::False
                    }
                };
                top.conds.push((cond, at.line, at.byte));
            }
            b"else" => match top.conds.last_mut() {
                None => {
                    return Err(err(file, &at, "an #ifdef or #ifndef before #else", "#else"));
                }
                Some(c) => {
                    c.0 = match c.0 {
                        Cond::True => Cond::False,
                        Cond::False => Cond::True,
                        Cond::Ignore => Cond::Ignore,
                    }
                }
            },
            b"endif" => {
                if top.conds.pop().is_none() {
                    return Err(err(
                        file,
                        &at,
                        "an #ifdef or #ifndef before #endif",
                        "#endif",
                    ));
                }
            }
            _ if skipping => {}
            b"include" => {
                let quote = |b: &u8| matches!(b, b'"' | b'<' | b'>');
                let target = rest.iter().position(quote).and_then(|a| {
                    let end = rest[a + 1..].iter().position(quote)?;
                    Some(&rest[a + 1..a + 1 + end])
                });
                let Some(target) = target.filter(|t| !t.is_empty()) else {
                    return Err(err(
                        file,
                        &at,
                        "an #include of a \"file\" or <file>",
                        Error::found(rest),
                    ));
                };
                let target = String::from_utf8_lossy(target).into_owned();
                self.include(&target, file, &at)?;
            }
            b"define" => {
                let Some(word) = word else {
                    return Err(err(file, &at, "a name after #define", "none"));
                };
                let value = trim(&rest[word.len()..]).to_vec();
                self.valued += usize::from(!value.is_empty());
                if let Some(old) = self.defines.insert(word.to_vec(), value) {
                    self.valued -= usize::from(!old.is_empty());
                }
            }
            b"undef" => {
                let Some(word) = word else {
                    return Err(err(file, &at, "a name after #undef", "none"));
                };
                if let Some(old) = self.defines.remove(word) {
                    self.valued -= usize::from(!old.is_empty());
                }
            }
            _ => {
                return Err(err(
                    file,
                    &at,
                    "a directive grompp knows: #include, #define, #undef, #ifdef, #ifndef, #else, #endif",
                    format!("#{}", Error::found(body)),
                ));
            }
        }
        Ok(())
    }

    /// Opens `target`, included from `file` at `at`, and reads it next.
    fn include(&mut self, target: &str, file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        if self.stack.len() >= MAX_DEPTH {
            return Err(err(
                file,
                at,
                "#include files nested at most 64 deep (does a file include itself?)",
                format!("\"{target}\", 64 deep"),
            ));
        }
        if self.opens >= MAX_OPENS {
            return Err(err(
                file,
                at,
                "at most 4096 #include files in all",
                format!("\"{target}\", the 4097th"),
            ));
        }
        let t = Path::new(target);
        let dir = self.stack.last().map(|s| s.dir.clone()).unwrap_or_default();
        let candidates: Vec<PathBuf> = if t.is_absolute() {
            vec![t.to_path_buf()]
        } else {
            std::iter::once(&dir)
                .chain(&self.dirs)
                .map(|d| d.join(t))
                .collect()
        };
        let Some(found) = candidates.iter().find(|p| p.is_file()) else {
            let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            return Err(err(
                file,
                at,
                "an #include file that exists beside the including file or in GROMACS's data directories",
                format!("\"{target}\" (looked for {})", looked.join(", ")),
            ));
        };
        let name: Arc<str> = found.display().to_string().into();
        let handle = std::fs::File::open(found).map_err(|source| Error::Io {
            at: Location::file(&name),
            source,
        })?;
        self.opens += 1;
        self.stack.push(Source {
            lines: Lines::new(Box::new(handle), name.clone()),
            name,
            dir: found.parent().map(Path::to_path_buf).unwrap_or_default(),
            conds: Vec::new(),
        });
        Ok(())
    }

    /// `text` with its defines replaced by their values (words only; up to 8 rounds, for
    /// defines whose values name defines).
    fn expand(&self, text: Vec<u8>, file: &Arc<str>, at: &LineAt) -> Result<Vec<u8>, Error> {
        if self.valued == 0 {
            return Ok(text);
        }
        let is_word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
        let mut text = text;
        for _ in 0..8 {
            let mut out = Vec::with_capacity(text.len());
            let mut changed = false;
            let mut i = 0;
            while i < text.len() {
                if !is_word(text[i]) {
                    out.push(text[i]);
                    i += 1;
                    continue;
                }
                let start = i;
                while i < text.len() && is_word(text[i]) {
                    i += 1;
                }
                let w = &text[start..i];
                match self.defines.get(w) {
                    Some(v) if !v.is_empty() => {
                        out.extend_from_slice(v);
                        changed = true;
                    }
                    _ => out.extend_from_slice(w),
                }
                if out.len() > MAX_LINE {
                    return Err(err(
                        file,
                        at,
                        "a line of at most 16 MiB after its defines are replaced",
                        "a longer one",
                    ));
                }
            }
            text = out;
            if !changed {
                break;
            }
        }
        Ok(text)
    }
}

/// GROMACS's data directories, where force fields are included from.
fn library_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(lib) = std::env::var_os("GMXLIB") {
        dirs.extend(std::env::split_paths(&lib).filter(|p| !p.as_os_str().is_empty()));
    }
    if let Some(data) = std::env::var_os("GMXDATA") {
        dirs.push(PathBuf::from(data).join("top"));
    }
    dirs.push(PathBuf::from("/usr/share/gromacs/top"));
    dirs.push(PathBuf::from("/usr/local/gromacs/share/gromacs/top"));
    dirs
}

/// An `[ atomtypes ]` entry.
struct AtomType {
    mass: f64,
    charge: f64,
    z: i64,
}

/// An atom of a molecule type.
struct Atom {
    name: Label,
    ty: Label,
    residue: usize,
    mass: f32,
    charge: f32,
    element: Element,
}

/// A `[ moleculetype ]`.
struct MolType {
    name: String,
    atoms: Vec<Atom>,
    /// Name, number, insertion letter.
    residues: Vec<(Label, i64, u8)>,
    bonds: Vec<[u32; 2]>,
}

#[derive(Clone, Copy, Default, PartialEq, Eq)]
enum Section {
    /// Before any section, or a section read past.
    #[default]
    Other,
    AtomTypes,
    MoleculeType,
    Atoms,
    Bonds,
    Constraints,
    Polarization,
    Settles,
    Molecules,
}

#[derive(Default)]
struct Parser {
    section: Section,
    types: HashMap<Vec<u8>, AtomType>,
    moltypes: Vec<MolType>,
    /// The molecule type being defined, if any.
    current: Option<usize>,
    /// After `[ intermolecular_interactions ]`: bonds number the system's atoms.
    intermolecular: bool,
    inter_bonds: Vec<[u32; 2]>,
    /// The system: molecule type and count, consecutive entries of one type merged.
    blocks: Vec<(usize, u64)>,
    n_atoms: u64,
    seen_molecules: bool,
}

/// The integer a field starts with (C's `%d`): sign and digits, `None` without digits.
fn leading_int(s: &[u8]) -> Option<i64> {
    let sign = usize::from(matches!(s.first(), Some(b'-' | b'+')));
    let end = s[sign..]
        .iter()
        .position(|b| !b.is_ascii_digit())
        .map_or(s.len(), |k| sign + k);
    if end == sign {
        return None;
    }
    parse_i64(&s[..end])
}

/// A label from a name, cut to [`Label::CAPACITY`] bytes at a character boundary (as the
/// `.tpr` reader cuts the names it reads).
fn label(s: &[u8]) -> Label {
    let s = String::from_utf8_lossy(s);
    let mut end = s.len().min(Label::CAPACITY);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    Label::new(&s[..end]).unwrap_or_default()
}

/// The element of atomic number `z`, or else from the name and mass (as the `.tpr` reader).
fn element(z: i64, name: &[u8], residue: &[u8], mass: f64) -> Element {
    match u8::try_from(z).ok().and_then(Element::from_z) {
        Some(e) => e,
        None if mass < 0.5 => Element::UNKNOWN,
        None => crate::psf::element_of(
            &String::from_utf8_lossy(name),
            &String::from_utf8_lossy(residue),
            mass,
        ),
    }
}

impl Parser {
    fn line(&mut self, cpp: &mut Cpp, first: Line) -> Result<(), Error> {
        let Line { mut text, file, at } = first;
        // Continued lines: a '\' last joins the next line.
        while trim(&text).last() == Some(&b'\\') {
            let end = text.iter().rposition(|&b| b == b'\\').unwrap_or(0);
            text.truncate(end);
            text.push(b' ');
            let Some(next) = cpp.next_line()? else {
                break;
            };
            text.extend_from_slice(&next.text);
            if text.len() > MAX_LINE {
                return Err(err(
                    &file,
                    &at,
                    "a line of at most 16 MiB with its continuations",
                    "a longer one",
                ));
            }
        }
        if let Some(c) = text.iter().position(|&b| b == b';') {
            text.truncate(c);
        }
        let t = trim(&text);
        if t.is_empty() {
            return Ok(());
        }
        if let Some(head) = t.strip_prefix(b"[") {
            let end = head.iter().position(|&b| b == b']').unwrap_or(head.len());
            // Names compare as grompp compares them: in any case, '-' and '_' ignored.
            let name: String = String::from_utf8_lossy(trim(&head[..end]))
                .chars()
                .filter(|c| !matches!(c, '-' | '_'))
                .collect::<String>()
                .to_ascii_lowercase();
            self.section = match name.as_str() {
                "atomtypes" => Section::AtomTypes,
                "moleculetype" => Section::MoleculeType,
                "atoms" => Section::Atoms,
                "bonds" => Section::Bonds,
                "constraints" => Section::Constraints,
                "polarization" => Section::Polarization,
                "settles" => Section::Settles,
                "molecules" => Section::Molecules,
                _ => Section::Other,
            };
            if name == "intermolecularinteractions" {
                self.intermolecular = true;
                self.current = None;
            }
            return Ok(());
        }
        if self.section == Section::Other {
            return Ok(());
        }
        let mut text = cpp.expand(t.to_vec(), &file, &at)?;
        // A define's value may end in a comment: it is one once in the line, as in grompp.
        if let Some(c) = text.iter().position(|&b| b == b';') {
            text.truncate(c);
        }
        let f: Vec<&[u8]> = fields(&text).collect();
        if f.is_empty() {
            return Ok(());
        }
        match self.section {
            Section::Other => Ok(()),
            Section::AtomTypes => self.atomtype(&f, &file, &at),
            Section::MoleculeType => self.moleculetype(&f, &file, &at),
            Section::Atoms => self.atom(&f, &file, &at),
            Section::Bonds | Section::Constraints | Section::Polarization | Section::Settles => {
                self.bond(&f, &file, &at)
            }
            Section::Molecules => self.molecules(&f, &file, &at),
        }
    }

    fn atomtype(&mut self, f: &[&[u8]], file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        const WHAT: &str =
            "an [ atomtypes ] line: name [bonded type] [atomic number] mass charge ptype ...";
        if f.len() < 6 {
            return Err(err(file, at, WHAT, Error::found(&f.join(&b' '))));
        }
        // grompp's rule: where the one-letter particle type stands tells the optional columns.
        let ptype = |s: &[u8]| s.len() == 1 && s[0].is_ascii_alphabetic();
        let (z, mass) = if ptype(f[5]) {
            (Some(f[2]), 3)
        } else if ptype(f[3]) {
            (None, 1)
        } else if f[1].first().is_some_and(u8::is_ascii_alphabetic) {
            (None, 2)
        } else {
            (Some(f[1]), 2)
        };
        let z = match z {
            Some(s) => {
                leading_int(s).ok_or_else(|| err(file, at, "an atomic number", Error::found(s)))?
            }
            None => -1,
        };
        let number =
            |s: &[u8], what| parse_f64(s).ok_or_else(|| err(file, at, what, Error::found(s)));
        let t = AtomType {
            mass: number(f[mass], "an atom type's mass")?,
            charge: number(f[mass + 1], "an atom type's charge")?,
            z,
        };
        self.types.insert(f[0].to_vec(), t);
        Ok(())
    }

    fn moleculetype(&mut self, f: &[&[u8]], file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        let name = String::from_utf8_lossy(f[0]).into_owned();
        if self.moltypes.iter().any(|m| m.name == name) {
            return Err(err(
                file,
                at,
                "a molecule type name not defined before",
                Error::found(f[0]),
            ));
        }
        if self.seen_molecules {
            return Err(err(
                file,
                at,
                "[ moleculetype ] sections before [ molecules ]",
                Error::found(f[0]),
            ));
        }
        self.moltypes.push(MolType {
            name,
            atoms: Vec::new(),
            residues: Vec::new(),
            bonds: Vec::new(),
        });
        self.current = Some(self.moltypes.len() - 1);
        self.intermolecular = false;
        Ok(())
    }

    fn atom(&mut self, f: &[&[u8]], file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        let Some(m) = self.current else {
            return Err(err(
                file,
                at,
                "[ atoms ] inside a [ moleculetype ]",
                Error::found(&f.join(&b' ')),
            ));
        };
        if f.len() < 6 {
            return Err(err(
                file,
                at,
                "an atom line: nr type resnr residue atom cgnr [charge [mass]]",
                Error::found(&f.join(&b' ')),
            ));
        }
        let mol = &mut self.moltypes[m];
        let nr = leading_int(f[0]);
        if nr != Some(mol.atoms.len() as i64 + 1) {
            return Err(err(
                file,
                at,
                "atoms numbered 1, 2, 3, ... in order in their molecule type",
                format!(
                    "{} after {}",
                    String::from_utf8_lossy(f[0]),
                    mol.atoms.len()
                ),
            ));
        }
        let Some(ty) = self.types.get(f[1]) else {
            return Err(err(
                file,
                at,
                "an atom type defined in [ atomtypes ]",
                Error::found(f[1]),
            ));
        };
        // The residue number, with an insertion letter after a digit.
        let r = f[2];
        let (digits, ic) = match r.split_last() {
            Some((&c, rest)) if !c.is_ascii_digit() => (rest, c),
            _ => (r, b' '),
        };
        let resnr = if digits.last().is_some_and(u8::is_ascii_digit) {
            leading_int(digits)
        } else {
            None
        };
        let Some(resnr) = resnr else {
            return Err(err(
                file,
                at,
                "a residue number (an integer, a letter after it allowed)",
                Error::found(r),
            ));
        };
        if leading_int(f[5]).is_none() {
            return Err(err(file, at, "a charge group number", Error::found(f[5])));
        }
        let number = |k: usize, what, default: f64| match f.get(k) {
            None => Ok(default),
            Some(s) => parse_f64(s).ok_or_else(|| err(file, at, what, Error::found(s))),
        };
        let charge = number(6, "a finite charge", ty.charge)?;
        let mass = number(7, "a finite mass", ty.mass)?;
        let z = ty.z;
        let res_name = label(f[3]);
        let same = mol
            .residues
            .last()
            .is_some_and(|&(n, k, c)| n == res_name && k == resnr && c == ic);
        if !same {
            mol.residues.push((res_name, resnr, ic));
        }
        let mass = mass as f32;
        mol.atoms.push(Atom {
            name: label(f[4]),
            ty: label(f[1]),
            residue: mol.residues.len() - 1,
            mass,
            charge: charge as f32,
            element: element(z, f[4], f[3], mass as f64),
        });
        Ok(())
    }

    /// A line of `[ bonds ]`, `[ constraints ]`, `[ polarization ]` or `[ settles ]`.
    fn bond(&mut self, f: &[&[u8]], file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        let settles = self.section == Section::Settles;
        let (n, owner) = if self.intermolecular {
            (self.n_atoms, "the system")
        } else if let Some(m) = self.current {
            (self.moltypes[m].atoms.len() as u64, "its molecule type")
        } else {
            return Err(err(
                file,
                at,
                "bonds inside a [ moleculetype ] or [ intermolecular_interactions ]",
                Error::found(&f.join(&b' ')),
            ));
        };
        let atoms = if settles { 1 } else { 2 };
        let numbers: Option<Vec<i64>> = f.iter().take(atoms).map(|s| leading_int(s)).collect();
        let numbers = numbers.filter(|v| v.len() == atoms);
        let Some(numbers) = numbers else {
            return Err(err(
                file,
                at,
                if settles {
                    "a settles line: the oxygen's atom number, funct, d(OH), d(HH)"
                } else {
                    "a bond line: two atom numbers, then the function type"
                },
                Error::found(&f.join(&b' ')),
            ));
        };
        let funct = f.get(atoms).and_then(|s| leading_int(s)).unwrap_or(1);
        let (chemical, types) = match self.section {
            Section::Bonds => (matches!(funct, 1..=5 | 7 | 8), 10),
            Section::Constraints => (funct == 1, 2),
            Section::Polarization => (matches!(funct, 1 | 2), 3),
            _ => (true, 1),
        };
        if !(1..=types).contains(&funct) {
            return Err(err(
                file,
                at,
                "a function type GROMACS has for this section",
                Error::found(f.get(atoms).copied().unwrap_or_default()),
            ));
        }
        let pairs = if settles {
            let o = numbers[0];
            vec![[o, o.saturating_add(1)], [o, o.saturating_add(2)]]
        } else {
            vec![[numbers[0], numbers[1]]]
        };
        for [a, b] in pairs {
            let inside = |k: i64| k >= 1 && (k as u64) <= n;
            if !inside(a) || !inside(b) {
                return Err(err(
                    file,
                    at,
                    "atom numbers of the bonded atoms' molecule type (1 to its atom count)",
                    format!("{a} and {b}, {owner} having {n} atoms"),
                ));
            }
            if a == b {
                return Err(err(
                    file,
                    at,
                    "a bond between two different atoms",
                    format!("{a} and {b}"),
                ));
            }
            if chemical {
                let bond = [(a - 1) as u32, (b - 1) as u32];
                match self.current {
                    Some(m) if !self.intermolecular => self.moltypes[m].bonds.push(bond),
                    _ => self.inter_bonds.push(bond),
                }
            }
        }
        Ok(())
    }

    fn molecules(&mut self, f: &[&[u8]], file: &Arc<str>, at: &LineAt) -> Result<(), Error> {
        self.seen_molecules = true;
        self.current = None;
        let count = f.get(1).and_then(|s| parse_i64(s)).filter(|&c| c >= 0);
        let Some(count) = count else {
            return Err(err(
                file,
                at,
                "a [ molecules ] line: a molecule type's name and a count of 0 or more",
                Error::found(&f.join(&b' ')),
            ));
        };
        let name = String::from_utf8_lossy(f[0]);
        let exact: Vec<usize> = (0..self.moltypes.len())
            .filter(|&k| self.moltypes[k].name == name)
            .collect();
        let any_case: Vec<usize> = (0..self.moltypes.len())
            .filter(|&k| self.moltypes[k].name.eq_ignore_ascii_case(&name))
            .collect();
        let ty = match (exact.as_slice(), any_case.as_slice()) {
            ([k], _) | ([], [k]) => *k,
            ([], []) => {
                return Err(err(
                    file,
                    at,
                    "the name of a molecule type defined by a [ moleculetype ] section",
                    Error::found(f[0]),
                ));
            }
            _ => {
                return Err(err(
                    file,
                    at,
                    "a name matching one molecule type (several differ from it only in case)",
                    Error::found(f[0]),
                ));
            }
        };
        let per = self.moltypes[ty].atoms.len() as u64;
        if per == 0 {
            return Err(err(
                file,
                at,
                "a molecule type with atoms",
                Error::found(f[0]),
            ));
        }
        let count = count as u64;
        self.n_atoms = self.n_atoms.saturating_add(count.saturating_mul(per));
        if self.n_atoms > MAX_ATOMS {
            return Err(err(
                file,
                at,
                "a system of at most 2^26 atoms",
                format!("{count} × {per} atoms, {} in all so far", self.n_atoms),
            ));
        }
        if count > 0 {
            match self.blocks.last_mut() {
                Some((t, c)) if *t == ty => *c += count,
                _ => self.blocks.push((ty, count)),
            }
        }
        Ok(())
    }

    /// The system, expanded to atoms as the `.tpr` reader expands its molecule blocks.
    fn finish(mut self, file: &Arc<str>) -> Result<Topology, Error> {
        if !self.seen_molecules {
            return Err(Error::Parse {
                at: Location::file(file),
                expected: "a [ molecules ] section listing the system's molecules",
                found: "none".into(),
            });
        }
        let mut n_bonds: u64 = self.inter_bonds.len() as u64;
        for m in &mut self.moltypes {
            tidy(&mut m.bonds);
        }
        for &(ty, count) in &self.blocks {
            n_bonds =
                n_bonds.saturating_add(count.saturating_mul(self.moltypes[ty].bonds.len() as u64));
        }
        if n_bonds > MAX_BONDS {
            return Err(Error::Parse {
                at: Location::file(file),
                expected: "a system of at most 2^27 bonds",
                found: n_bonds.to_string(),
            });
        }
        let natoms = self.n_atoms as usize;
        let single = self.blocks.len() == 1 && self.blocks[0].1 == 1;
        let renumber_max = if single { 0 } else { 1 };
        let mut used = vec![false; self.moltypes.len()];
        for &(ty, _) in &self.blocks {
            used[ty] = true;
        }
        let mut highest = 0;
        for (k, m) in self.moltypes.iter().enumerate() {
            if used[k] && m.residues.len() > renumber_max {
                highest = m.residues.iter().map(|r| r.1).fold(highest, i64::max);
            }
        }
        let chain_of = |name: &str| {
            name.rsplit_once("_chain_")
                .map(|(_, c)| label(c.as_bytes()))
        };
        let has_chains = self
            .moltypes
            .iter()
            .enumerate()
            .any(|(k, m)| used[k] && chain_of(&m.name).is_some());
        let mut names = Vec::with_capacity(natoms);
        let mut types = Vec::with_capacity(natoms);
        let mut res_names = Vec::with_capacity(natoms);
        let mut res_ids = Vec::with_capacity(natoms);
        let mut segments = Vec::with_capacity(natoms);
        let mut chains = Vec::new();
        let mut elements = Vec::with_capacity(natoms);
        let mut masses = Vec::with_capacity(natoms);
        let mut charges = Vec::with_capacity(natoms);
        let mut bonds = Vec::new();
        for &(ty, count) in &self.blocks {
            let m = &self.moltypes[ty];
            let segment = label(m.name.as_bytes());
            let chain = chain_of(&m.name).unwrap_or_default();
            let renumber = m.residues.len() <= renumber_max;
            for _ in 0..count {
                let first = names.len() as u32;
                for a in &m.atoms {
                    let (res_name, resnr, _) = m.residues[a.residue];
                    names.push(a.name);
                    types.push(a.ty);
                    res_names.push(res_name);
                    res_ids.push(if renumber {
                        highest.saturating_add(1 + a.residue as i64)
                    } else {
                        resnr
                    });
                    segments.push(segment);
                    if has_chains {
                        chains.push(chain);
                    }
                    elements.push(a.element);
                    masses.push(a.mass);
                    charges.push(a.charge);
                }
                if renumber {
                    highest = highest.saturating_add(m.residues.len() as i64);
                }
                bonds.extend(m.bonds.iter().map(|b| [b[0] + first, b[1] + first]));
            }
        }
        bonds.extend(self.inter_bonds);
        tidy(&mut bonds);
        let n = names.len();
        let mut t = Topology::from_parts(
            file.clone(),
            names,
            elements,
            types,
            (1..=n as i64).collect(),
            res_names,
            res_ids,
            bonds,
        );
        t.segments = segments;
        t.chains = chains;
        t.charges = charges;
        t.masses = masses;
        Ok(t)
    }
}

//! [`Trajectory`]: one reader for every format, streaming or random access.

use crate::amber::{AmberRestart, AmberTrj};
use crate::crd::Crd;
use crate::crystal_cif::CrystalCif;
use crate::cube::Cube;
use crate::dcd::DcdReader;
use crate::dlpoly::DlPoly;
use crate::error::Error;
use crate::format::Format;
use crate::frame::Frame;
use crate::gro::Gro;
use crate::gsd::GsdReader;
use crate::lammps::Lammps;
use crate::lammps_data::LammpsData;
use crate::mmcif::Mmcif;
use crate::mol2::Mol2;
use crate::namdbin::NamdBinReader;
use crate::netcdf::NetcdfReader;
use crate::pdb::Pdb;
use crate::pqr::Pqr;
use crate::sdf::Sdf;
use crate::text::TextReader;
use crate::tinker::Tinker;
use crate::trr::TrrReader;
use crate::vasp::Vasp;
use crate::xsf::Xsf;
use crate::xtc::XtcReader;
use crate::xyz::Xyz;
use std::fs::File;
use std::io::{Read, Seek};
use std::path::Path;
use std::sync::Arc;

/// The per-format readers: a closed set, dispatched by `match` (see the contract in lib.rs).
enum Reader<R> {
    Xyz(TextReader<R, Xyz>),
    Dcd(DcdReader<R>),
    Xtc(XtcReader<R>),
    Trr(TrrReader<R>),
    Netcdf(NetcdfReader<R>),
    Gsd(GsdReader<R>),
    Pdb(TextReader<R, Pdb>),
    Gro(TextReader<R, Gro>),
    Lammps(TextReader<R, Lammps>),
    LammpsBin(crate::lammps_bin::LammpsBinReader<R>),
    Mmcif(TextReader<R, Mmcif>),
    Sdf(TextReader<R, Sdf>),
    Mol2(TextReader<R, Mol2>),
    Vasp(TextReader<R, Vasp>),
    CrystalCif(TextReader<R, CrystalCif>),
    LammpsData(TextReader<R, LammpsData>),
    Cube(TextReader<R, Cube>),
    NamdBin(NamdBinReader<R>),
    Tinker(TextReader<R, Tinker>),
    DlPoly(TextReader<R, DlPoly>),
    AmberTrj(TextReader<R, AmberTrj>),
    AmberRestart(TextReader<R, AmberRestart>),
    CharmmCrd(TextReader<R, Crd>),
    Pqr(TextReader<R, Pqr>),
    Xsf(TextReader<R, Xsf>),
    EspressoOut(TextReader<R, crate::espresso::PwOut>),
    EspressoIn(TextReader<R, crate::espresso::PwIn>),
    VaspXml(TextReader<R, crate::vasp_out::VaspXml>),
    Outcar(TextReader<R, crate::vasp_out::Outcar>),
    Tpr(crate::tpr::TprReader),
    AseTraj(crate::asetraj::AseTrajReader<R>),
    Bcif(crate::bcif::BcifReader),
}

/// Runs `$body` with `$r` bound to the format's reader, whatever the format.
macro_rules! each_reader {
    ($reader:expr, $r:ident => $body:expr) => {
        match $reader {
            Reader::Xyz($r) => $body,
            Reader::Dcd($r) => $body,
            Reader::Xtc($r) => $body,
            Reader::Trr($r) => $body,
            Reader::Netcdf($r) => $body,
            Reader::Gsd($r) => $body,
            Reader::Pdb($r) => $body,
            Reader::Gro($r) => $body,
            Reader::Lammps($r) => $body,
            Reader::LammpsBin($r) => $body,
            Reader::Mmcif($r) => $body,
            Reader::Sdf($r) => $body,
            Reader::Mol2($r) => $body,
            Reader::Vasp($r) => $body,
            Reader::CrystalCif($r) => $body,
            Reader::LammpsData($r) => $body,
            Reader::Cube($r) => $body,
            Reader::NamdBin($r) => $body,
            Reader::Tinker($r) => $body,
            Reader::DlPoly($r) => $body,
            Reader::AmberTrj($r) => $body,
            Reader::AmberRestart($r) => $body,
            Reader::CharmmCrd($r) => $body,
            Reader::Pqr($r) => $body,
            Reader::Xsf($r) => $body,
            Reader::EspressoOut($r) => $body,
            Reader::EspressoIn($r) => $body,
            Reader::VaspXml($r) => $body,
            Reader::Outcar($r) => $body,
            Reader::Tpr($r) => $body,
            Reader::AseTraj($r) => $body,
            Reader::Bcif($r) => $body,
        }
    };
}

/// Frames read by number: a [`Trajectory`] or a [`crate::Sequence`] of them, for what reads
/// around a frame (smoothing's window, [`crate::smooth`]).
pub trait FrameSource {
    /// Reads frame `n` into `frame`.
    fn read_frame(&mut self, n: usize, frame: &mut Frame) -> Result<(), Error>;
    /// The name errors give.
    fn name(&self) -> &str;
}

impl<R: Read + Seek> FrameSource for Trajectory<R> {
    fn read_frame(&mut self, n: usize, frame: &mut Frame) -> Result<(), Error> {
        Trajectory::read_frame(self, n, frame)
    }
    fn name(&self) -> &str {
        Trajectory::name(self)
    }
}

/// How a [`Trajectory`] treats a file whose end is damaged.
///
/// By default every frame the file announces or starts must be readable: a last frame cut short
/// (a crashed or still-running simulation, a partial copy) is an [`Error::Truncated`] naming the
/// file, the frame, the byte offset where the data ends and what was still expected, from
/// [`Trajectory::n_frames`] as well as from the read that reaches it. Nothing is dropped
/// silently.
///
/// With `allow_truncated` ([`ReadOptions`]) the complete frames are kept and the cut one is dropped
/// *with a warning*: the same error, kept in [`Trajectory::warnings`] for the caller to print,
/// while `n_frames` counts the complete frames and streaming ends after the last of them. A cut
/// mid-line is a cut, not damage: the partial last line a frame fails to parse is reported as
/// the data ending inside the frame, by streaming and by `n_frames` alike. (A partial last line
/// that still parses, such as a number cut to a shorter number with no end of line after it,
/// cannot be told from a file written without a final newline, and is read as it is.) A gzip
/// stream that ends early is read up to the cut, with a warning naming the compressed offset. A PDB
/// or mmCIF model whose atom count differs from model 1's is likewise an error by default and a
/// warning here (the model is passed on as it is). Damage that is not a cut end (a flipped byte, a
/// corrupt header) stays an error either way.
///
/// ```
/// use texmap_md_io::{Format, Frame, ReadOptions, Trajectory};
/// // Two XYZ frames, the second cut after its first atom line.
/// let text = "2\nfirst\nO 0 0 0\nH 1 0 0\n2\nsecond\nO 0 0 0\n";
/// let src = || std::io::Cursor::new(text);
/// let mut strict = Trajectory::from_reader(src(), Format::Xyz, "cut.xyz")?;
/// let e = strict.n_frames().unwrap_err();
/// assert!(e.to_string().starts_with("cut.xyz: frame 1, line 8"), "{e}");
///
/// let opts = ReadOptions::new().allow_truncated(true);
/// let mut lenient = Trajectory::from_reader_with(src(), Format::Xyz, "cut.xyz", opts)?;
/// assert_eq!(lenient.n_frames()?, 1);
/// assert_eq!(lenient.warnings().len(), 1);
/// # Ok::<(), texmap_md_io::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ReadOptions {
    /// Keep the complete frames of a file whose last frame is cut short, with a warning.
    pub allow_truncated: bool,
    /// The atom count, for a format whose files do not hold it (an AMBER ASCII trajectory,
    /// [`Format::AmberTrj`]): the topology's. Other formats ignore it.
    pub atoms: Option<usize>,
    /// The cell angles (degrees) of a box that a file gives as lengths only (an AMBER ASCII
    /// trajectory's three-number box line): the run's, from its topology (a truncated
    /// octahedron's 109.47°, AMBER prmtop `BOX_DIMENSIONS`). Default: right angles.
    pub box_angles: Option<[f64; 3]>,
    /// The column names of a LAMMPS binary dump that does not hold them (from an older LAMMPS:
    /// no magic header, or format revision 1), one per value of an atom, separated by white
    /// space, as `dump custom` lists them: `"id type x y z vx vy vz c_pe"`, OVITO's column
    /// mapping for such files. A file that names its columns ignores them, as other formats
    /// do. Without them such a file of 5 or 8 values per atom is read as `dump atom`'s default
    /// columns (see [`Format::LammpsBin`]).
    pub lammps_columns: Option<Arc<str>>,
}

impl ReadOptions {
    /// The defaults: every damage is an error.
    pub fn new() -> ReadOptions {
        ReadOptions::default()
    }

    /// Sets the `allow_truncated` field.
    pub fn allow_truncated(mut self, yes: bool) -> ReadOptions {
        self.allow_truncated = yes;
        self
    }

    /// Sets the `atoms` field.
    pub fn atoms(mut self, n: usize) -> ReadOptions {
        self.atoms = Some(n);
        self
    }

    /// Sets the `box_angles` field.
    pub fn box_angles(mut self, angles: [f64; 3]) -> ReadOptions {
        self.box_angles = Some(angles);
        self
    }

    /// Sets the `lammps_columns` field.
    pub fn lammps_columns(mut self, names: &str) -> ReadOptions {
        self.lammps_columns = Some(names.into());
        self
    }
}

/// A trajectory file opened for reading.
///
/// Frames are read one at a time into a caller's [`Frame`] ([`Trajectory::read_next`]), so
/// memory does not grow with the number of frames and buffers are reused. Random access
/// ([`Trajectory::read_frame`]) goes through an index of frame starts built lazily: streaming
/// fills it as it goes, and a jump past the known frames scans forward (a line scan for text
/// formats).
///
/// A damaged frame gives an [`Error`] naming the file, the frame and the line / byte offset;
/// every frame before it stays readable.
///
/// Memory: the current frame's buffers, a 1 MiB read chunk for text formats, and the frame
/// index (16 bytes per frame seen: byte offset and line number of its start). A gzip file opened
/// by path is read from its decompressed copy in a temporary file (disk, not memory).
pub struct Trajectory<R: Read + Seek = File> {
    reader: Reader<R>,
    file: Arc<str>,
    format: Format,
    n_atoms: Option<usize>,
    next: usize,
    options: ReadOptions,
    /// What was tolerated under `options`, and the alternate locations an mmCIF read dropped
    /// (each once).
    warnings: Vec<Error>,
    /// The first frame a read found cut (tolerated under `allow_truncated`): frames from it on
    /// do not exist, whatever a scan counted.
    cut_at: Option<usize>,
}

/// The first `n` bytes of `file` (fewer when it is shorter; `name` is what errors call it), the
/// file rewound: what the format decisions below look at.
pub(crate) fn head(file: &mut File, name: &Arc<str>, n: u64) -> Result<Vec<u8>, Error> {
    let io = |source| Error::Io {
        at: crate::error::Location::file(name),
        source,
    };
    let mut head = Vec::new();
    file.take(n).read_to_end(&mut head).map_err(io)?;
    file.rewind().map_err(io)?;
    Ok(head)
}

/// Which CIF `file` (at `path`, named `name` in errors) is: a CIF not named `.mmcif` is
/// PDBx/mmCIF or crystallographic, and its tags tell ([`Format::cif_kind`]) from a larger head
/// than the magic's (a COD file's atom sites follow its bibliography). The file is rewound.
pub(crate) fn cif_kind_of(file: &mut File, path: &Path, name: &Arc<str>) -> Result<Format, Error> {
    let mmcif_named = crate::gz::inner_path(path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mmcif"));
    if mmcif_named {
        return Ok(Format::Mmcif);
    }
    Ok(Format::cif_kind(&head(file, name, Format::CIF_HEAD)?))
}

/// How much of a `.crd` file [`crate::Trajectory::open`] reads to tell what it is.
const CRD_HEAD: u64 = 4096;

/// What `file` (at `path`, named `name` in errors), named as a CHARMM CRD, is: a `.crd` that
/// starts (after blank lines) with a `*` title is CHARMM's ([`Format::is_charmm_crd`]); else
/// AMBER's trajectory or restart by its second line ([`Format::amber_kind`]); else an error. A
/// file with nothing but blank lines in its first [`CRD_HEAD`] bytes is read as CHARMM (an
/// empty file has no frames). `.cor` and a format told by the content are not checked. The
/// file is rewound.
pub(crate) fn crd_kind_of(file: &mut File, path: &Path, name: &Arc<str>) -> Result<Format, Error> {
    let crd_named = crate::gz::inner_path(path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("crd"));
    if !crd_named {
        return Ok(Format::CharmmCrd);
    }
    let head = head(file, name, CRD_HEAD)?;
    if Format::is_charmm_crd(&head) != Some(false) {
        return Ok(Format::CharmmCrd);
    }
    if let Some(amber) = Format::amber_kind(&head) {
        return Ok(amber);
    }
    // Where the first non-blank line starts, for the error.
    let (mut line, mut byte) = (1u64, 0usize);
    for l in head.split(|b| *b == b'\n') {
        if !crate::parse::trim(l).is_empty() {
            let end = (byte + l.len()).min(head.len());
            return Err(Error::Parse {
                at: crate::error::Location {
                    file: name.clone(),
                    frame: None,
                    line: Some(line),
                    byte: Some(byte as u64),
                },
                expected: "a CHARMM coordinate file's title lines starting with '*', or an AMBER \
                           trajectory or restart (a title, then 10F8.3 coordinates or an atom \
                           count); else name the format with --format",
                found: Error::found(&head[byte..end]),
            });
        }
        line += 1;
        byte += l.len() + 1;
    }
    Ok(Format::CharmmCrd)
}

/// Whether `file` is a `.xyz` in Tinker's layout ([`Format::tinker_xyz`]); the file is rewound.
fn is_tinker(file: &mut File, name: &Arc<str>) -> Result<bool, Error> {
    Ok(Format::tinker_xyz(&head(file, name, 4096)?))
}

/// Whether `file` starts with NetCDF-3's magic number; the file is rewound.
fn is_netcdf(file: &mut File, name: &Arc<str>) -> Result<bool, Error> {
    Ok(matches!(
        head(file, name, 4)?.as_slice(),
        b"CDF\x01" | b"CDF\x02"
    ))
}

impl Trajectory<File> {
    /// Opens `path`, telling the format from the extension or else from the first bytes.
    /// A CIF (`.cif`, or first bytes `data_`) is PDBx/mmCIF or crystallographic by its tags
    /// in its first [`Format::CIF_HEAD`] bytes ([`Format::cif_kind`]); `.mmcif` is mmCIF.
    /// A `.crd` is a CHARMM coordinate file when its first non-blank line is a `*` title
    /// ([`Format::is_charmm_crd`]), else an AMBER trajectory or restart by its second line
    /// ([`Format::amber_kind`]), else an error naming that line. An AMBER restart name
    /// (`.rst7`, `.restrt`) over NetCDF bytes is read as NetCDF (pmemd's default restart), and
    /// a `.xyz` in Tinker's layout as Tinker ([`Format::tinker_xyz`]).
    ///
    /// A gzip file (first bytes `1f 8b`, e.g. `1abc.cif.gz`, `run.xyz.gz`) is read decompressed:
    /// its format comes from the name without `.gz`, else from the decompressed first bytes. It
    /// is inflated once into an anonymous temporary file (disk, not memory: the decompressed
    /// size), so byte offsets in later errors count decompressed bytes; damage to the gzip
    /// stream itself is an error here naming the file, "gzip" and the compressed offset (a
    /// stream that just ends early, under `allow_truncated`, a warning: what inflated is read,
    /// and a frame it cuts is dropped as in a cut plain file). A name ending in `.gz` over bytes
    /// that are not gzip is an error.
    pub fn open(path: impl AsRef<Path>) -> Result<Trajectory<File>, Error> {
        Trajectory::open_with(path, ReadOptions::default())
    }

    /// [`Trajectory::open`] with [`ReadOptions`].
    pub fn open_with(
        path: impl AsRef<Path>,
        options: ReadOptions,
    ) -> Result<Trajectory<File>, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        let (mut file, cut) = crate::gz::open(path, &name, options.allow_truncated)?;
        let format = match Format::from_path(path) {
            Some(f) => f,
            None => Format::from_magic(&head(&mut file, &name, 512)?)
                .ok_or(Error::UnknownFormat { file: name.clone() })?,
        };
        let format = match format {
            Format::Mmcif => cif_kind_of(&mut file, path, &name)?,
            Format::CharmmCrd => crd_kind_of(&mut file, path, &name)?,
            // pmemd writes its restarts as NetCDF by default, whatever the name.
            Format::AmberRestart if is_netcdf(&mut file, &name)? => Format::Netcdf,
            // Tinker writes `.xyz` too.
            Format::Xyz if is_tinker(&mut file, &name)? => Format::Tinker,
            // Other programs name files `.traj` too: without ASE's ULM magic, the content
            // tells (else the ASE reader says what it expected).
            Format::AseTraj => {
                let head = head(&mut file, &name, 512)?;
                match Format::from_magic(&head) {
                    Some(f) if !head.starts_with(b"- of Ulm") => f,
                    _ => Format::AseTraj,
                }
            }
            other => other,
        };
        Trajectory::from_reader_with(file, format, &name, options).map(|t| t.with_warning(cut))
    }

    /// Opens `path` as `format`, whatever its extension; a gzip file is read decompressed, as
    /// by [`Trajectory::open`].
    pub fn open_as(path: impl AsRef<Path>, format: Format) -> Result<Trajectory<File>, Error> {
        Trajectory::open_as_with(path, format, ReadOptions::default())
    }

    /// [`Trajectory::open_as`] with [`ReadOptions`].
    pub fn open_as_with(
        path: impl AsRef<Path>,
        format: Format,
        options: ReadOptions,
    ) -> Result<Trajectory<File>, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        let (file, cut) = crate::gz::open(path, &name, options.allow_truncated)?;
        Trajectory::from_reader_with(file, format, &name, options).map(|t| t.with_warning(cut))
    }
}

impl<R: Read + Seek> Trajectory<R> {
    /// Reads `src` as `format`; `name` is what errors call the file.
    pub fn from_reader(src: R, format: Format, name: &str) -> Result<Trajectory<R>, Error> {
        Trajectory::from_reader_with(src, format, name, ReadOptions::default())
    }

    /// [`Trajectory::from_reader`] with [`ReadOptions`].
    pub fn from_reader_with(
        src: R,
        format: Format,
        name: &str,
        options: ReadOptions,
    ) -> Result<Trajectory<R>, Error> {
        let file: Arc<str> = name.into();
        let lenient = options.allow_truncated;
        let reader = match format {
            Format::Xyz => Reader::Xyz(TextReader::new(src, Xyz::default(), file.clone())),
            Format::Dcd => Reader::Dcd(DcdReader::new(src, file.clone())?),
            Format::Xtc => Reader::Xtc(XtcReader::new(src, file.clone())?),
            Format::Trr => Reader::Trr(TrrReader::new(src, file.clone())?),
            Format::Netcdf => Reader::Netcdf(NetcdfReader::new(src, file.clone())?),
            Format::Gsd => Reader::Gsd(GsdReader::new(src, file.clone())?),
            Format::NamdBin => Reader::NamdBin(NamdBinReader::new(src, file.clone())?),
            Format::Tpr => Reader::Tpr(crate::tpr::TprReader::new(src, file.clone())?),
            Format::AseTraj => {
                Reader::AseTraj(crate::asetraj::AseTrajReader::new(src, file.clone())?)
            }
            Format::Tinker => Reader::Tinker(TextReader::new(src, Tinker::default(), file.clone())),
            Format::DlPoly => Reader::DlPoly(TextReader::new(src, DlPoly::default(), file.clone())),
            Format::Pdb => Reader::Pdb(TextReader::new(src, Pdb::new(lenient), file.clone())),
            Format::Pdbqt => Reader::Pdb(TextReader::new(src, Pdb::pdbqt(lenient), file.clone())),
            Format::Gro => Reader::Gro(TextReader::new(src, Gro, file.clone())),
            Format::LammpsDump => {
                Reader::Lammps(TextReader::new(src, Lammps::default(), file.clone()))
            }
            Format::LammpsBin => Reader::LammpsBin(crate::lammps_bin::LammpsBinReader::new(
                src,
                file.clone(),
                options.lammps_columns.clone(),
            )?),
            Format::Mmcif => Reader::Mmcif(TextReader::new(src, Mmcif::new(lenient), file.clone())),
            Format::Bcif => Reader::Bcif(crate::bcif::BcifReader::new(src, file.clone(), lenient)?),
            Format::Sdf => Reader::Sdf(TextReader::new(src, Sdf, file.clone())),
            Format::Mol2 => Reader::Mol2(TextReader::new(src, Mol2::default(), file.clone())),
            Format::Vasp => Reader::Vasp(TextReader::new(src, Vasp::default(), file.clone())),
            Format::CrystalCif => {
                Reader::CrystalCif(TextReader::new(src, CrystalCif::default(), file.clone()))
            }
            Format::LammpsData => {
                Reader::LammpsData(TextReader::new(src, LammpsData::default(), file.clone()))
            }
            Format::Cube => Reader::Cube(TextReader::new(src, Cube, file.clone())),
            Format::AmberTrj => {
                let n = options.atoms.ok_or_else(|| Error::Unsupported {
                    file: file.clone(),
                    what: "reading an AMBER ASCII trajectory without its atom count, which the file does not hold: give the topology (texmap: --topology system.prmtop; the library: ReadOptions::atoms)",
                })?;
                let trj = AmberTrj::new(n, options.box_angles);
                Reader::AmberTrj(TextReader::new(src, trj, file.clone()))
            }
            Format::AmberRestart => {
                Reader::AmberRestart(TextReader::new(src, AmberRestart, file.clone()))
            }
            Format::CharmmCrd => Reader::CharmmCrd(TextReader::new(src, Crd, file.clone())),
            Format::Pqr => Reader::Pqr(TextReader::new(src, Pqr::new(lenient), file.clone())),
            Format::Xsf => Reader::Xsf(TextReader::new(src, Xsf::default(), file.clone())),
            Format::EspressoOut => {
                Reader::EspressoOut(TextReader::new(src, Default::default(), file.clone()))
            }
            Format::EspressoIn => {
                Reader::EspressoIn(TextReader::new(src, Default::default(), file.clone()))
            }
            Format::VaspXml => {
                Reader::VaspXml(TextReader::new(src, Default::default(), file.clone()))
            }
            Format::Outcar => {
                Reader::Outcar(TextReader::new(src, Default::default(), file.clone()))
            }
        };
        Ok(Trajectory {
            reader,
            file,
            format,
            n_atoms: None,
            next: 0,
            options,
            warnings: Vec::new(),
            cut_at: None,
        })
    }

    /// The options the file was opened with.
    pub fn options(&self) -> ReadOptions {
        self.options.clone()
    }

    /// What was tolerated under `allow_truncated` ([`ReadOptions`]) so far (a dropped cut frame,
    /// a PDB or mmCIF model with another atom count), and whatever the options, the alternate
    /// locations of PDBx/mmCIF atoms dropped after the first (one warning per frame, with the
    /// count), each once, in the order met. Display names the file, frame and byte; a caller
    /// prints them as warnings.
    pub fn warnings(&self) -> &[Error] {
        &self.warnings
    }

    /// The warnings kept so far, taken out (a [`crate::Sequence`] keeps a closed part's).
    pub(crate) fn take_warnings(&mut self) -> Vec<Error> {
        std::mem::take(&mut self.warnings)
    }

    /// `self` with `w` (a cut gzip stream read under `allow_truncated`), if any, as its first
    /// warning.
    fn with_warning(mut self, w: Option<Error>) -> Self {
        if let Some(w) = w {
            self.warnings.insert(0, w);
        }
        self
    }

    /// Keeps `w` as a warning unless the same one is kept already.
    fn warn(&mut self, w: Error) {
        let same = |k: &Error| k.location() == w.location() && k.to_string() == w.to_string();
        if !self.warnings.iter().any(same) {
            self.warnings.push(w);
        }
    }

    /// Gathers the PDB, mmCIF and BinaryCIF parsers' warnings.
    fn gather(&mut self) {
        let taken = match &mut self.reader {
            Reader::Pdb(r) => r.format_mut().take_warnings(),
            Reader::Mmcif(r) => r.format_mut().take_warnings(),
            Reader::Bcif(r) => r.take_warnings(),
            Reader::Pqr(r) => r.format_mut().take_warnings(),
            _ => return,
        };
        for w in taken {
            self.warn(w);
        }
    }

    /// Under `allow_truncated`, a cut end is a warning and the complete frames before it are
    /// the whole file: returns that frame count. Any other error is given back.
    fn tolerate(&mut self, e: Error) -> Result<usize, Error> {
        match &e {
            Error::Truncated { at, .. } if self.options.allow_truncated => match at.frame {
                Some(complete) => {
                    self.warn(e);
                    Ok(complete)
                }
                None => Err(e),
            },
            _ => Err(e),
        }
    }

    /// For the frame read last, when it was a TRR frame without positions (left with no atoms):
    /// the velocities and forces it held, which no [`Frame`] can carry without positions. A
    /// converter names them in a warning instead of dropping them in silence.
    pub fn without_positions(&self) -> Option<crate::WithoutPositions> {
        match &self.reader {
            Reader::Trr(r) => r.without_positions(),
            _ => None,
        }
    }

    /// The file's format.
    pub fn format(&self) -> Format {
        self.format
    }

    /// The file's name as errors give it.
    pub fn name(&self) -> &str {
        &self.file
    }

    /// Reads the next frame into `frame` (cleared first); `Ok(false)` after the last frame.
    /// On error `frame` is left empty and the reader stays at the damaged frame.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        let read = each_reader!(&mut self.reader, r => r.read_next(frame));
        self.gather();
        let ok = match read {
            Ok(ok) => ok,
            Err(e) => {
                let complete = self.tolerate(e)?;
                self.cut_at = Some(self.cut_at.map_or(complete, |c| c.min(complete)));
                frame.clear();
                false
            }
        };
        if ok {
            if self.next == 0 {
                self.n_atoms = Some(frame.n_atoms());
            }
            self.next += 1;
        }
        Ok(ok)
    }

    /// Reads frame `n` (0-based) into `frame`; the next `read_next` then reads frame `n + 1`.
    pub fn read_frame(&mut self, n: usize, frame: &mut Frame) -> Result<(), Error> {
        let seek = each_reader!(&mut self.reader, r => r.seek_frame(n));
        self.gather();
        // A scan that met a cut end under `allow_truncated`: frame `n` is past the kept ones.
        let found = match seek {
            Ok(found) => found,
            Err(e) => self.tolerate(e).map(|_| false)?,
        };
        if !found {
            let n_frames = self.n_frames()?;
            return Err(Error::FrameOutOfRange {
                file: self.file.clone(),
                requested: n,
                n_frames,
            });
        }
        self.next = n;
        if !self.read_next(frame)? {
            let n_frames = self.n_frames()?;
            return Err(Error::FrameOutOfRange {
                file: self.file.clone(),
                requested: n,
                n_frames,
            });
        }
        Ok(())
    }

    /// Number of frames. The first call may scan the whole file (once); the read position is
    /// kept.
    ///
    /// A cut last frame is an error naming it (see [`ReadOptions`]), or under `allow_truncated`
    /// a warning, and the complete frames are counted.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        let n = each_reader!(&mut self.reader, r => r.n_frames());
        self.gather();
        let n = n.or_else(|e| self.tolerate(e))?;
        Ok(self.cut_at.map_or(n, |c| n.min(c)))
    }

    /// Number of atoms in the first frame (frames of a LAMMPS dump may differ: use
    /// [`Frame::n_atoms`] per frame). Reads the first frame if none was read; the read position
    /// is kept.
    pub fn n_atoms(&mut self) -> Result<usize, Error> {
        if let Some(n) = self.n_atoms {
            return Ok(n);
        }
        let keep = self.next;
        let mut scratch = Frame::new();
        self.read_frame(0, &mut scratch)?;
        let n = scratch.n_atoms();
        self.n_atoms = Some(n);
        // Back to frame `keep`; when every frame had been read there is no frame `keep` to
        // seek to, so read on to the end instead.
        if !each_reader!(&mut self.reader, r => r.seek_frame(keep))? {
            while each_reader!(&mut self.reader, r => r.read_next(&mut scratch))? {}
        }
        self.next = keep;
        Ok(n)
    }
}

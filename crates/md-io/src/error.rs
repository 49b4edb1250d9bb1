//! The one error type of the crate, and the [`Location`] every reading error carries.
//!
//! Every error that comes from a file names the file, and where known the frame (0-based), the
//! line (1-based, text formats) and the byte offset (0-based, from the start of the file) at which
//! the reader gave up, plus what it expected there and what it found. Display prints all of them:
//!
//! ```text
//! water.xyz: frame 3, line 17, byte 1234: expected 3 coordinates after atom name, found 'x'
//! ```

use std::fmt;
use std::sync::Arc;

/// Where in a file something went wrong. Fields that do not apply (a binary format has no lines)
/// are `None`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// The file's name (or the name given to [`crate::Trajectory::from_reader`]).
    pub file: Arc<str>,
    /// 0-based frame index.
    pub frame: Option<usize>,
    /// 1-based line number (text formats).
    pub line: Option<u64>,
    /// 0-based byte offset from the start of the file; of a gzip file, from the start of its
    /// decompressed bytes, except in an error of the gzip stream itself (the compressed offset).
    pub byte: Option<u64>,
}

impl Location {
    /// A location naming only the file.
    pub fn file(file: &Arc<str>) -> Location {
        Location {
            file: file.clone(),
            ..Location::default()
        }
    }

    /// A location in a text file.
    pub fn text(file: &Arc<str>, frame: usize, line: u64, byte: u64) -> Location {
        Location {
            file: file.clone(),
            frame: Some(frame),
            line: Some(line),
            byte: Some(byte),
        }
    }

    /// A location in a binary file.
    pub fn binary(file: &Arc<str>, frame: usize, byte: u64) -> Location {
        Location {
            file: file.clone(),
            frame: Some(frame),
            line: None,
            byte: Some(byte),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.file)?;
        let mut sep = ": ";
        if let Some(fr) = self.frame {
            write!(f, "{sep}frame {fr}")?;
            sep = ", ";
        }
        if let Some(l) = self.line {
            write!(f, "{sep}line {l}")?;
            sep = ", ";
        }
        if let Some(b) = self.byte {
            write!(f, "{sep}byte {b}")?;
        }
        Ok(())
    }
}

/// Everything that can go wrong reading or writing a trajectory.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// The operating system failed a read, write, seek or open.
    Io {
        at: Location,
        source: std::io::Error,
    },
    /// The content is not what the format says it must be.
    Parse {
        at: Location,
        /// What the reader expected, e.g. "3 coordinates after atom name".
        expected: &'static str,
        /// What it found instead (already shortened to a readable length).
        found: String,
    },
    /// The file ends inside a frame: every frame before `at.frame` is complete and readable.
    Truncated {
        at: Location,
        /// What the reader still needed, e.g. "120 more atom lines".
        expected: String,
    },
    /// The format could be told neither from the extension nor from the first bytes.
    UnknownFormat { file: Arc<str> },
    /// The format cannot do what was asked (e.g. write a format that has no writer).
    Unsupported { file: Arc<str>, what: &'static str },
    /// `read_frame(n)` past the last frame.
    FrameOutOfRange {
        file: Arc<str>,
        requested: usize,
        n_frames: usize,
    },
    /// A frame handed to a writer breaks an invariant of [`crate::Frame`] or of the format
    /// (e.g. `names.len() != positions.len()`, a coordinate that does not fit PDB's columns).
    InvalidFrame {
        file: Arc<str>,
        frame: usize,
        what: String,
    },
    /// A value given to a constructor is out of its domain (e.g. a cell angle of 200°).
    InvalidValue { what: String },
    /// A topology applied to a trajectory frame with another number of atoms.
    TopologyMismatch {
        topology: Arc<str>,
        topology_atoms: usize,
        trajectory: Arc<str>,
        frame: usize,
        frame_atoms: usize,
    },
}

impl Error {
    /// Shortens what was found in a file to at most 40 characters for a readable message.
    pub fn found(bytes: &[u8]) -> String {
        let s = String::from_utf8_lossy(bytes);
        let s = s.trim_end_matches(['\n', '\r']);
        let mut out: String = s.chars().take(40).collect();
        if s.chars().count() > 40 {
            out.push('…');
        }
        out
    }

    /// The location of the error, if it has one.
    pub fn location(&self) -> Option<&Location> {
        match self {
            Error::Io { at, .. } | Error::Parse { at, .. } | Error::Truncated { at, .. } => {
                Some(at)
            }
            _ => None,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { at, source } => write!(f, "{at}: I/O error: {source}"),
            Error::Parse {
                at,
                expected,
                found,
            } => write!(f, "{at}: expected {expected}, found '{found}'"),
            Error::Truncated { at, expected } => {
                write!(f, "{at}: file ends inside the frame: expected {expected}")
            }
            Error::UnknownFormat { file } => write!(
                f,
                "{file}: unknown trajectory format (neither the extension nor the first bytes tell)"
            ),
            Error::Unsupported { file, what } => write!(f, "{file}: unsupported: {what}"),
            Error::FrameOutOfRange {
                file,
                requested,
                n_frames,
            } => write!(
                f,
                "{file}: frame {requested} requested but the file has {n_frames} frames"
            ),
            Error::InvalidFrame { file, frame, what } => {
                write!(f, "{file}: frame {frame} cannot be written: {what}")
            }
            Error::InvalidValue { what } => write!(f, "invalid value: {what}"),
            Error::TopologyMismatch {
                topology,
                trajectory,
                frame,
                frame_atoms: 0,
                ..
            } => write!(
                f,
                "{trajectory}: frame {frame} has no positions, so the topology {topology} has nothing to name (a GROMACS TRR holds such frames, of only velocities or forces, when nstvout or nstfout differs from nstxout; `texmap convert {trajectory} -o positions.trr` keeps the frames with positions)"
            ),
            Error::TopologyMismatch {
                topology,
                topology_atoms,
                trajectory,
                frame,
                frame_atoms,
            } => write!(
                f,
                "{trajectory}: frame {frame} has {frame_atoms} atoms but the topology {topology} has {topology_atoms}: they must describe the same atoms in the same order"
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_frame_line_byte_and_expectation() {
        let file: Arc<str> = "water.xyz".into();
        let e = Error::Parse {
            at: Location::text(&file, 3, 17, 1234),
            expected: "3 coordinates after atom name",
            found: "x".into(),
        };
        assert_eq!(
            e.to_string(),
            "water.xyz: frame 3, line 17, byte 1234: expected 3 coordinates after atom name, found 'x'"
        );
        let e = Error::Truncated {
            at: Location::binary(&file, 2, 99),
            expected: "4 more bytes".into(),
        };
        assert_eq!(
            e.to_string(),
            "water.xyz: frame 2, byte 99: file ends inside the frame: expected 4 more bytes"
        );
    }

    #[test]
    fn found_is_shortened() {
        let long = [b'a'; 100];
        let s = Error::found(&long);
        assert_eq!(s.chars().count(), 41);
        assert_eq!(Error::found(b"abc\r\n"), "abc");
    }
}

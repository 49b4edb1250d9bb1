//! [`Writer`]: one writer for every format that has one.

use crate::dcd::DcdWriter;
use crate::error::{Error, Location};
use crate::format::Format;
use crate::frame::Frame;
use crate::pdb::PdbWriter;
use crate::xtc::XtcWriter;
use crate::xyz::XyzWriter;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;
use std::sync::Arc;

/// The per-format writers: a closed set, dispatched by `match`.
enum WriterKind<W> {
    Xyz(XyzWriter<W>),
    Dcd(DcdWriter<W>),
    Xtc(XtcWriter<W>),
    Pdb(PdbWriter<W>),
}

/// Runs `$body` with `$w` bound to the format's writer, whatever the format.
macro_rules! each_writer {
    ($writer:expr, $w:ident => $body:expr) => {
        match $writer {
            WriterKind::Xyz($w) => $body,
            WriterKind::Dcd($w) => $body,
            WriterKind::Xtc($w) => $body,
            WriterKind::Pdb($w) => $body,
        }
    };
}

/// A trajectory file being written, frame by frame. Call [`Writer::finish`] at the end (it
/// writes the format's trailer, e.g. PDB's END, and flushes); without it a trailer may be missing.
pub struct Writer<W: Write + Seek = BufWriter<File>> {
    kind: WriterKind<W>,
    file: Arc<str>,
    format: Format,
    written: usize,
}

impl Writer<BufWriter<File>> {
    /// Creates (or truncates) `path` and writes `format` to it.
    pub fn create(path: impl AsRef<Path>, format: Format) -> Result<Self, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        let f = File::create(path).map_err(|source| Error::Io {
            at: Location::file(&name),
            source,
        })?;
        Writer::new(BufWriter::with_capacity(1 << 20, f), format, &name)
    }
}

impl<W: Write + Seek> Writer<W> {
    /// Writes `format` to `out`; `name` is what errors call the file.
    pub fn new(out: W, format: Format, name: &str) -> Result<Self, Error> {
        let file: Arc<str> = name.into();
        let kind = match format {
            Format::Xyz => WriterKind::Xyz(XyzWriter { out }),
            Format::Dcd => WriterKind::Dcd(DcdWriter::new(out, file.clone())),
            Format::Xtc => WriterKind::Xtc(XtcWriter::new(out, file.clone(), 1000.0)?),
            Format::Pdb => WriterKind::Pdb(PdbWriter { out, models: 0 }),
            _ => {
                return Err(Error::Unsupported {
                    file,
                    what: "writing this format",
                });
            }
        };
        Ok(Writer {
            kind,
            file,
            format,
            written: 0,
        })
    }

    /// The format being written.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Frames written so far.
    pub fn frames_written(&self) -> usize {
        self.written
    }

    /// Appends one frame, after checking it ([`Frame::check`]).
    pub fn write_frame(&mut self, frame: &Frame) -> Result<(), Error> {
        frame.check().map_err(|what| Error::InvalidFrame {
            file: self.file.clone(),
            frame: self.written,
            what,
        })?;
        // Format limits (e.g. PDB's fixed columns).
        let limits = match &self.kind {
            WriterKind::Pdb(_) => PdbWriter::<W>::check(frame),
            WriterKind::Xyz(_) => XyzWriter::<W>::check(frame),
            _ => Ok(()),
        };
        limits.map_err(|what| Error::InvalidFrame {
            file: self.file.clone(),
            frame: self.written,
            what,
        })?;
        let r = each_writer!(&mut self.kind, w => w.write_frame(frame));
        r.map_err(|source| self.io(source))?;
        self.written += 1;
        Ok(())
    }

    fn io(&self, source: std::io::Error) -> Error {
        Error::Io {
            at: Location {
                file: self.file.clone(),
                frame: Some(self.written),
                line: None,
                byte: None,
            },
            source,
        }
    }

    /// Writes the trailer, flushes, and returns the output.
    pub fn finish(mut self) -> Result<W, Error> {
        let r = each_writer!(&mut self.kind, w => w.finish().and_then(|()| w.out.flush()));
        r.map_err(|source| self.io(source))?;
        Ok(each_writer!(self.kind, w => w.out))
    }
}

//! NAMD binary coordinates (`.coor`: NAMD's `binaryoutput` and restart files, `run.restart.coor`),
//! one frame.
//!
//! The file is a 4-byte atom count N, then N x, y, z triples of 8-byte floats (Å), in the byte
//! order of the machine that wrote it: nothing else, no cell and no names (the PSF gives those;
//! the box is in NAMD's `.xsc`). The order is told by the count: the one reading of it for which
//! `4 + 24·N` is the file's length. A file whose length fits neither reading is damaged (cut or
//! padded) and an error naming the two lengths; a count is never trusted to size anything before
//! the length matches it.
//!
//! # References
//! - NAMD User's Guide, "binaryoutput", "binaryrestart"; NAMD `src/Output.C` (`write_binary_file`).
//! - MDAnalysis `coordinates/NAMDBIN.py`, the reader and writer the tests compare with.

use std::io::{self, Read, Seek, SeekFrom};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_in_bounds, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::Frame;

/// Streaming (one frame) reader of a NAMD binary coordinate file.
pub(crate) struct NamdBinReader<R> {
    src: R,
    file: Arc<str>,
    n_atoms: usize,
    big_endian: bool,
    next: usize,
}

impl<R: Read + Seek> NamdBinReader<R> {
    /// Reads the count and checks it against the file's length.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let io = |byte, source| Error::Io {
            at: Location::binary(&file, 0, byte),
            source,
        };
        let len = src.seek(SeekFrom::End(0)).map_err(|e| io(0, e))?;
        src.seek(SeekFrom::Start(0)).map_err(|e| io(0, e))?;
        let mut head = [0u8; 4];
        if let Err(e) = src.read_exact(&mut head) {
            return Err(match e.kind() {
                io::ErrorKind::UnexpectedEof => Error::Truncated {
                    at: Location::binary(&file, 0, 0),
                    expected: "the 4-byte atom count".into(),
                },
                _ => io(0, e),
            });
        }
        let fits = |n: u32| 4 + 24 * n as u64 == len;
        let (le, be) = (u32::from_le_bytes(head), u32::from_be_bytes(head));
        let (n, big_endian) = if fits(le) {
            (le, false)
        } else if fits(be) {
            (be, true)
        } else {
            return Err(Error::Parse {
                at: Location::binary(&file, 0, 0),
                expected: "an atom count N with 4 + 24·N bytes in the file (NAMD binary coordinates)",
                found: format!(
                    "{le} (little-endian) or {be} (big-endian) atoms, a file of {len} bytes"
                ),
            });
        };
        Ok(NamdBinReader {
            src,
            file,
            n_atoms: n as usize,
            big_endian,
            next: 0,
        })
    }

    /// Reads the next frame (the `Trajectory` contract): the one frame, then the end.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        if self.next > 0 {
            return Ok(false);
        }
        let at = |byte| Location::binary(&self.file, 0, byte);
        self.src
            .seek(SeekFrom::Start(4))
            .map_err(|source| Error::Io { at: at(4), source })?;
        let mut buf = vec![0u8; 24 * self.n_atoms];
        self.src
            .read_exact(&mut buf)
            .map_err(|source| Error::Io { at: at(4), source })?;
        let value = |b: &[u8]| {
            let b: [u8; 8] = b.try_into().unwrap_or([0; 8]);
            if self.big_endian {
                f64::from_be_bytes(b)
            } else {
                f64::from_le_bytes(b)
            }
        };
        frame.positions.extend(buf.chunks_exact(24).map(|c| {
            [
                value(&c[0..8]) as f32,
                value(&c[8..16]) as f32,
                value(&c[16..24]) as f32,
            ]
        }));
        if !all_in_bounds(&frame.positions) {
            let bad = first_out_of_bounds(&frame.positions).unwrap_or(0);
            let e = Error::Parse {
                at: at(4 + 24 * bad as u64),
                expected: IN_BOUNDS,
                found: format!("atom {bad}: {:?}", frame.positions[bad]),
            };
            frame.clear();
            return Err(e);
        }
        self.next = 1;
        Ok(true)
    }

    /// Makes `read_next` read frame `n`: only frame 0 exists.
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        if n == 0 {
            self.next = 0;
            Ok(true)
        } else {
            Ok(false)
        }
    }

    /// One frame.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        Ok(1)
    }
}
